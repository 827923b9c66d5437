//! The capture manifest (`capture.toml`): everything ingest needs to know about a
//! lighting-dome capture, so that a real capture with another layout needs no code
//! change. These are the raw serde types, as written in the file; [`crate::capture`]
//! validates them into typed geometry and names the field that is wrong.
//!
//! A capture holds, for every captured pose `p`, cycle `u` and camera `v`, one lighting
//! set: the frames of [`Manifest::schedule`] in order. Each slot of the schedule is a
//! basis condition, a track frame `T_k`, a matte frame `M_k` or unused, and has a time
//! offset relative to the reference track frame. Clean plates (the same set without the
//! actor) exist for every camera and slot.
//!
//! ```toml
//! format = "frf-capture"
//! version = 1
//! [timing]          # cycle_seconds, poses_per_cycle, set_rate_hz, frame_rate_hz, poses, reference_track, gait_speed_mps (optional)
//! [turntable]       # azimuth_deg = [one per cycle], degrees_per_cycle
//! [[cameras]]       # name, width, height, fx, fy, cx, cy, world_from_camera = 3x4 rows
//! [[conditions]]    # name, floor, lights = [{ direction, intensity, solid_angle_sr }]
//! [[schedule]]      # kind = "basis" | "track" | "matte" | "unused", condition | index, time_offset_s
//! [files]           # frame = "frames/p{pose:02}/...", clean_plate = "...", full_scale = 65535
//! [[filmed]]        # optional: pose, views = [[cycle, camera], ...] (a partial capture)
//! ```

use serde::{Deserialize, Serialize};

/// The value of [`Manifest::format`].
pub const FORMAT: &str = "frf-capture";
/// The manifest version this code reads and writes.
pub const VERSION: u32 = 1;
/// File name of the manifest inside a capture directory.
pub const MANIFEST_FILE: &str = "capture.toml";

/// The whole manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// Free text: where the capture comes from.
    #[serde(default)]
    pub description: String,
    /// Timing of cycles, sets and frames.
    pub timing: Timing,
    /// The turntable.
    pub turntable: Turntable,
    /// The fixed cameras, lowest first (vertical view index `v`).
    pub cameras: Vec<CameraSpec>,
    /// The lighting basis conditions.
    pub conditions: Vec<ConditionSpec>,
    /// The slots of one lighting set, in capture order.
    pub schedule: Vec<SlotSpec>,
    /// Where the frame files are.
    pub files: FileSpec,
    /// The views filmed, per pose, when not every view of every pose was (a capture
    /// made for one scene); empty: every view of every pose in `timing.poses`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filmed: Vec<FilmedSpec>,
}

/// The views filmed of one pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilmedSpec {
    /// The pose.
    pub pose: u32,
    /// The views `[cycle, camera]` filmed.
    pub views: Vec<[u32; 2]>,
}

/// Timing of the capture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timing {
    /// Duration of one walk cycle, seconds (one turntable step).
    pub cycle_seconds: f64,
    /// Lighting sets per cycle; pose `p` is set `p` of the cycle.
    pub poses_per_cycle: u32,
    /// Lighting sets per second (30 in the original).
    pub set_rate_hz: f64,
    /// Frames per second of the cameras (990 in the original).
    pub frame_rate_hz: f64,
    /// The poses present in this capture.
    pub poses: Vec<u32>,
    /// Index `k` of the reference track frame `T_k` that the set is registered to
    /// (`1`, the middle one, in the original).
    pub reference_track: u32,
    /// Speed of the treadmill's belt, metres per second: how fast a planted foot moves
    /// backward in the subject frame, so that a walker moved along a path advances its
    /// gait by the distance walked. Absent when not known (older and real captures).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gait_speed_mps: Option<f64>,
}

/// The turntable under the treadmill.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Turntable {
    /// Turntable angle at the start of each cycle, degrees; one entry per cycle, so its
    /// length is the number of horizontal views.
    pub azimuth_deg: Vec<f64>,
    /// Rotation during one cycle, degrees (the turntable turns continuously).
    pub degrees_per_cycle: f64,
}

/// One fixed camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Name, for messages.
    pub name: String,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels (pixel centres at integers).
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// Rows of the 3x4 matrix `[R | t]` mapping camera to world coordinates (metres).
    pub world_from_camera: [[f64; 4]; 3],
}

/// One lighting basis condition: a group of dome lights fired together.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConditionSpec {
    /// Name, for messages.
    pub name: String,
    /// Whether this is a floor condition (simulating light from a lit ground plane).
    #[serde(default)]
    pub floor: bool,
    /// The lights of the condition.
    pub lights: Vec<LightSpec>,
}

/// One dome light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Direction from the subject toward the light, world frame (normalized on load).
    pub direction: [f64; 3],
    /// RGB irradiance at normal incidence that the light delivers to the subject.
    pub intensity: [f64; 3],
    /// Solid angle of the part of the sphere this light stands for, steradians.
    pub solid_angle_sr: f64,
}

/// One slot of the lighting set, as written in the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlotSpec {
    /// `"basis"`, `"track"`, `"matte"` or `"unused"`.
    pub kind: String,
    /// For `basis`: index into [`Manifest::conditions`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub condition: Option<usize>,
    /// For `track` and `matte`: the index `k` of `T_k` / `M_k`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub index: Option<u32>,
    /// Time of the frame relative to the reference track frame, seconds.
    pub time_offset_s: f64,
}

/// Where the files are, relative to the capture directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileSpec {
    /// Pattern of frame files with the placeholders `{pose}`, `{cycle}`, `{camera}` and
    /// `{slot}`, each optionally zero-padded as `{pose:02}`.
    pub frame: String,
    /// Pattern of clean-plate files with `{camera}` and `{slot}`.
    pub clean_plate: String,
    /// The stored value that means linear 1.0 (65535 for 16-bit PNG).
    pub full_scale: f64,
}

/// A frame-file pattern's placeholders and their values.
#[derive(Debug, Clone, Copy, Default)]
pub struct PatternValues {
    /// Pose index.
    pub pose: u32,
    /// Cycle (horizontal view) index.
    pub cycle: u32,
    /// Camera (vertical view) index.
    pub camera: u32,
    /// Slot index within the set.
    pub slot: u32,
}

/// Placeholder names a pattern may use.
pub const PLACEHOLDERS: [&str; 4] = ["pose", "cycle", "camera", "slot"];

/// Parses a pattern into literal text and placeholders; returns the placeholder names
/// used, or what is wrong with it.
pub fn pattern_placeholders(pattern: &str) -> Result<Vec<&str>, String> {
    let mut names = Vec::new();
    let mut rest = pattern;
    while let Some(open) = rest.find('{') {
        let close = rest[open..]
            .find('}')
            .ok_or_else(|| format!("unclosed '{{' in {pattern:?}"))?;
        let inner = &rest[open + 1..open + close];
        let (name, width) = inner.split_once(':').unwrap_or((inner, ""));
        if !PLACEHOLDERS.contains(&name) {
            return Err(format!(
                "unknown placeholder {{{name}}} in {pattern:?}; known: pose, cycle, camera, slot"
            ));
        }
        if !width.is_empty() && (!width.starts_with('0') || width.parse::<u8>().is_err()) {
            return Err(format!(
                "bad width {width:?} in {{{inner}}}: use e.g. {{{name}:03}}"
            ));
        }
        names.push(name);
        rest = &rest[open + close + 1..];
    }
    if rest.contains('}') {
        return Err(format!("unmatched '}}' in {pattern:?}"));
    }
    Ok(names)
}

/// Fills a pattern (already checked by [`pattern_placeholders`]).
pub fn fill_pattern(pattern: &str, values: &PatternValues) -> String {
    let mut out = String::with_capacity(pattern.len() + 8);
    let mut rest = pattern;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else {
            break;
        };
        let inner = &rest[open + 1..open + close];
        let (name, width) = inner.split_once(':').unwrap_or((inner, ""));
        let value = match name {
            "pose" => values.pose,
            "cycle" => values.cycle,
            "camera" => values.camera,
            _ => values.slot,
        };
        let width: usize = width.parse().unwrap_or(0);
        out.push_str(&format!("{value:0width$}"));
        rest = &rest[open + close + 1..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_fill_with_padding() {
        let v = PatternValues {
            pose: 3,
            cycle: 12,
            camera: 1,
            slot: 7,
        };
        assert_eq!(
            fill_pattern("f/p{pose:03}/u{cycle}_v{camera}/s{slot:02}.png", &v),
            "f/p003/u12_v1/s07.png"
        );
        assert_eq!(
            pattern_placeholders("a{pose}{slot:02}").unwrap(),
            vec!["pose", "slot"]
        );
        let e = pattern_placeholders("a{poze}").unwrap_err().to_string();
        assert!(
            e.contains("unknown placeholder {poze}") && e.contains("a{poze}"),
            "{e}"
        );
        let e = pattern_placeholders("a{pose").unwrap_err().to_string();
        assert!(e.contains("unclosed") && e.contains(r#""a{pose""#), "{e}");
        let e = pattern_placeholders("a{pose:x}").unwrap_err().to_string();
        assert!(
            e.contains(r#"bad width "x""#) && e.contains("{pose:x}"),
            "{e}"
        );
        let e = pattern_placeholders("a}").unwrap_err().to_string();
        assert!(e.contains("unmatched '}'") && e.contains(r#""a}""#), "{e}");
    }

    #[test]
    fn the_belt_speed_is_optional_in_the_timing() {
        let older = "cycle_seconds = 1.0\nposes_per_cycle = 30\nset_rate_hz = 30.0\n\
                     frame_rate_hz = 990.0\nposes = [0]\nreference_track = 1\n";
        let t: Timing = toml::from_str(older).expect("an older timing reads");
        assert_eq!(t.gait_speed_mps, None);
        assert!(
            !toml::to_string(&t)
                .expect("writes")
                .contains("gait_speed_mps")
        );
        let t: Timing = toml::from_str(&format!("{older}gait_speed_mps = 1.05\n")).expect("reads");
        assert_eq!(t.gait_speed_mps, Some(1.05));
    }
}
