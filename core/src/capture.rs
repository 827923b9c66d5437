//! A validated capture: the manifest of [`crate::manifest`] turned into typed cameras,
//! lights and slots, with the paths of every frame and the timing of every view.
//! [`Capture::open`] checks the whole manifest and every frame file's header, and
//! names the field or file that is wrong.

use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use crate::camera::{Camera, Intrinsics, Rigid};
use crate::error::{CoreError, Result};
use crate::image::RgbImage;
use crate::io::{image_dimensions, read_rgb_sized_bits};
use crate::light::DirLight;
use crate::manifest::{
    FORMAT, MANIFEST_FILE, Manifest, PatternValues, VERSION, fill_pattern, pattern_placeholders,
};

/// What a slot of the lighting set holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlotKind {
    /// Basis condition (index into [`Capture::conditions`]).
    Basis(usize),
    /// Track frame `T_k`.
    Track(u32),
    /// Matte frame `M_k`.
    Matte(u32),
    /// Not used.
    Unused,
}

/// One slot of the lighting set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slot {
    /// What it holds.
    pub kind: SlotKind,
    /// Time relative to the reference track frame, seconds.
    pub time_offset_s: f64,
}

/// A dome light with the solid angle it stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DomeLight {
    /// Direction and irradiance (world frame).
    pub light: DirLight,
    /// Solid angle of the sphere this light represents, steradians.
    pub solid_angle_sr: f32,
}

/// A basis condition.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// Name.
    pub name: String,
    /// Floor condition (light from the ground)?
    pub floor: bool,
    /// Its lights.
    pub lights: Vec<DomeLight>,
}

/// A track frame and the matte frame that follows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackPair {
    /// `k` of `T_k`.
    pub index: u32,
    /// Slot of `T_k`.
    pub track_slot: usize,
    /// Slot of `M_k`.
    pub matte_slot: usize,
}

/// A validated capture.
#[derive(Debug, Clone)]
pub struct Capture {
    dir: PathBuf,
    manifest: Manifest,
    cameras: Vec<Camera>,
    conditions: Vec<Condition>,
    slots: Vec<Slot>,
    tracks: Vec<TrackPair>,
    reference_track: usize,
}

/// Tolerance on the orthonormality of manifest rotations (6 significant digits).
const ROTATION_TOLERANCE: f32 = 1e-4;

/// The most poses a walk cycle may be cut into (the original: 30; a pose every
/// millisecond of a one-second cycle is 1000): bounds every pose list before it is
/// allocated.
pub const MAX_POSES_PER_CYCLE: u32 = 100_000;

struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn fail(&self, field: impl Into<String>, problem: impl Into<String>) -> CoreError {
        CoreError::Manifest {
            path: self.path.to_path_buf(),
            field: field.into(),
            problem: problem.into(),
        }
    }

    fn finite(&self, field: &str, v: f64) -> Result<()> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.fail(field, format!("{v} is not a finite number")))
        }
    }

    fn positive(&self, field: &str, v: f64) -> Result<()> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(self.fail(field, format!("must be positive, got {v}")))
        }
    }
}

impl Capture {
    /// Reads `DIR/capture.toml`, validates it and checks that every frame and clean
    /// plate exists with the size of its camera.
    pub fn open(dir: &Path) -> Result<Self> {
        let capture = Self::open_manifest(dir)?;
        capture.check_files()?;
        Ok(capture)
    }

    /// Reads and validates `DIR/capture.toml` without looking at the frame files.
    pub fn open_manifest(dir: &Path) -> Result<Self> {
        let path = dir.join(MANIFEST_FILE);
        // A manifest is a page of text; a larger file is something else.
        let text = crate::io::read_text(&path, 64 << 20)?;
        Self::parse_manifest(dir, &text)
    }

    /// Parses and validates the text of `DIR/capture.toml` (the files are not checked).
    pub fn parse_manifest(dir: &Path, text: &str) -> Result<Self> {
        let path = dir.join(MANIFEST_FILE);
        let manifest: Manifest = toml::from_str(text).map_err(|e| {
            // What kind of mistake it is: only a file TOML cannot read is a syntax error.
            let message = e.message();
            let field = if message.starts_with("missing field") {
                "(a section or key is missing)"
            } else if message.starts_with("unknown field") {
                "(a key the format does not have)"
            } else if message.starts_with("invalid") {
                "(a value of the wrong type or length)"
            } else {
                "(syntax)"
            };
            CoreError::Manifest {
                path,
                field: field.into(),
                problem: e.to_string().trim().to_string(),
            }
        })?;
        Self::from_manifest(dir, manifest)
    }

    /// Validates a manifest for a capture rooted at `dir` (the files are not checked).
    pub fn from_manifest(dir: &Path, manifest: Manifest) -> Result<Self> {
        let path = dir.join(MANIFEST_FILE);
        let c = Check { path: &path };
        if manifest.format != FORMAT {
            return Err(c.fail(
                "format",
                format!("{:?}, expected {FORMAT:?}", manifest.format),
            ));
        }
        if manifest.version != VERSION {
            return Err(c.fail(
                "version",
                format!(
                    "version {} is not supported (this build reads {VERSION})",
                    manifest.version
                ),
            ));
        }
        check_timing(&c, &manifest)?;
        let cameras = check_cameras(&c, &manifest)?;
        let conditions = check_conditions(&c, &manifest)?;
        let (slots, tracks, reference_track) = check_schedule(&c, &manifest, conditions.len())?;
        check_files_spec(&c, &manifest)?;
        for (i, f) in manifest.filmed.iter().enumerate() {
            if !manifest.timing.poses.contains(&f.pose) {
                return Err(c.fail(
                    format!("filmed[{i}].pose"),
                    format!("pose {} is not in timing.poses", f.pose),
                ));
            }
            if let Some(v) = f.views.iter().find(|v| {
                v[0] as usize >= manifest.turntable.azimuth_deg.len()
                    || v[1] as usize >= cameras.len()
            }) {
                return Err(c.fail(
                    format!("filmed[{i}].views"),
                    format!("view {v:?} is outside the grid"),
                ));
            }
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            manifest,
            cameras,
            conditions,
            slots,
            tracks,
            reference_track,
        })
    }

    /// Whether view `(cycle, camera)` of `pose` was filmed (every view of a captured pose
    /// unless the manifest lists the filmed views).
    pub fn is_filmed(&self, pose: u32, cycle: usize, camera: usize) -> bool {
        if !self.manifest.timing.poses.contains(&pose) {
            return false;
        }
        if self.manifest.filmed.is_empty() {
            return true;
        }
        self.manifest
            .filmed
            .iter()
            .filter(|f| f.pose == pose)
            .any(|f| f.views.contains(&[cycle as u32, camera as u32]))
    }

    /// Checks that every frame and clean plate exists and has its camera's size,
    /// reading only file headers. Names the first bad file.
    pub fn check_files(&self) -> Result<()> {
        let mut jobs = Vec::new();
        for &pose in &self.manifest.timing.poses {
            for cycle in 0..self.cycles() {
                for camera in 0..self.cameras.len() {
                    if !self.is_filmed(pose, cycle, camera) {
                        continue;
                    }
                    for slot in 0..self.slots.len() {
                        jobs.push((Some((pose, cycle)), camera, slot));
                    }
                }
            }
        }
        for camera in 0..self.cameras.len() {
            for slot in 0..self.slots.len() {
                jobs.push((None, camera, slot));
            }
        }
        let first_error = jobs
            .par_iter()
            .map(|&(pc, camera, slot)| {
                let path = match pc {
                    Some((pose, cycle)) => self.frame_path(pose, cycle, camera, slot),
                    None => self.clean_plate_path(camera, slot),
                };
                self.check_frame_file(&path, camera)
            })
            .find_first(|r| r.is_err());
        first_error.unwrap_or(Ok(()))
    }

    fn check_frame_file(&self, path: &Path, camera: usize) -> Result<()> {
        let cam = &self.cameras[camera];
        let (w, h) = image_dimensions(path)?;
        if (w, h) != (cam.width as usize, cam.height as usize) {
            return Err(CoreError::SizeMismatch {
                path: path.to_path_buf(),
                expected_width: cam.width as usize,
                expected_height: cam.height as usize,
                got_width: w,
                got_height: h,
            });
        }
        Ok(())
    }

    /// The capture directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The manifest as read.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// Number of cycles (horizontal views).
    pub fn cycles(&self) -> usize {
        self.manifest.turntable.azimuth_deg.len()
    }

    /// The cameras (vertical views), world frame, lowest first.
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// The basis conditions.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// The slots of one lighting set.
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }

    /// Track frames with their matte frames, by track index.
    pub fn tracks(&self) -> &[TrackPair] {
        &self.tracks
    }

    /// The reference track pair (`T1` in the original), which sets the time of a pose.
    pub fn reference_track(&self) -> TrackPair {
        self.tracks[self.reference_track]
    }

    /// The slot holding basis condition `condition`.
    pub fn basis_slot(&self, condition: usize) -> Option<usize> {
        self.slots
            .iter()
            .position(|s| s.kind == SlotKind::Basis(condition))
    }

    /// The captured poses.
    pub fn poses(&self) -> &[u32] {
        &self.manifest.timing.poses
    }

    /// Time of pose `pose`'s reference track frame since the start of its cycle, seconds.
    pub fn pose_time_s(&self, pose: u32) -> f64 {
        pose as f64 / self.manifest.timing.set_rate_hz
    }

    /// Turntable angle (radians) for cycle `cycle` at `time_in_cycle_s` seconds into it.
    pub fn turntable_angle(&self, cycle: usize, time_in_cycle_s: f64) -> f32 {
        let t = &self.manifest.turntable;
        let deg = t.azimuth_deg[cycle]
            + t.degrees_per_cycle * time_in_cycle_s / self.manifest.timing.cycle_seconds;
        deg.to_radians() as f32
    }

    /// Turntable angle of view `(cycle, ·)` of pose `pose` at its reference time.
    pub fn view_angle(&self, cycle: usize, pose: u32) -> f32 {
        self.turntable_angle(cycle, self.pose_time_s(pose))
    }

    /// Camera `camera` as seen from the subject frame in cycle `cycle` at pose `pose`'s
    /// reference time: the world camera rotated by `-θ` ([`crate::conventions`]).
    pub fn subject_camera(&self, cycle: usize, camera: usize, pose: u32) -> Camera {
        let theta = self.view_angle(cycle, pose);
        self.cameras[camera].transformed(&Rigid::rotation_y(-theta))
    }

    /// Path of a frame file.
    pub fn frame_path(&self, pose: u32, cycle: usize, camera: usize, slot: usize) -> PathBuf {
        let values = PatternValues {
            pose,
            cycle: cycle as u32,
            camera: camera as u32,
            slot: slot as u32,
        };
        self.dir
            .join(fill_pattern(&self.manifest.files.frame, &values))
    }

    /// Path of a clean-plate file.
    pub fn clean_plate_path(&self, camera: usize, slot: usize) -> PathBuf {
        let values = PatternValues {
            camera: camera as u32,
            slot: slot as u32,
            ..Default::default()
        };
        self.dir
            .join(fill_pattern(&self.manifest.files.clean_plate, &values))
    }

    fn load_scaled(&self, path: &Path, camera: usize) -> Result<RgbImage> {
        let cam = &self.cameras[camera];
        let (mut img, bits) = read_rgb_sized_bits(path, cam.width as usize, cam.height as usize)?;
        let is_float = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("hdr"));
        if !is_float {
            let full_scale = self.manifest.files.full_scale;
            if full_scale > 255.0 && bits < 16 {
                return Err(CoreError::bad_file(
                    path,
                    format!(
                        "{bits} bits per channel where the capture declares 16-bit frames \
                         (files.full_scale = {full_scale}): re-export it as 16-bit PNG"
                    ),
                ));
            }
            let k = (65535.0 / full_scale) as f32;
            if k != 1.0 {
                for p in img.pixels_mut() {
                    *p = p.map(|c| c * k);
                }
            }
        }
        Ok(img)
    }

    /// Loads a frame as linear RGB.
    pub fn load_frame(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        slot: usize,
    ) -> Result<RgbImage> {
        self.load_scaled(&self.frame_path(pose, cycle, camera, slot), camera)
    }

    /// Loads a clean plate as linear RGB.
    pub fn load_clean_plate(&self, camera: usize, slot: usize) -> Result<RgbImage> {
        self.load_scaled(&self.clean_plate_path(camera, slot), camera)
    }

    /// Writes a manifest to `DIR/capture.toml` atomically.
    pub fn write_manifest(dir: &Path, manifest: &Manifest) -> Result<()> {
        let path = dir.join(MANIFEST_FILE);
        let text =
            toml::to_string(manifest).map_err(|e| CoreError::invalid("manifest", e.to_string()))?;
        crate::atomic::write_bytes_atomic(&path, text.as_bytes())
    }
}

fn check_timing(c: &Check, m: &Manifest) -> Result<()> {
    let t = &m.timing;
    c.positive("timing.cycle_seconds", t.cycle_seconds)?;
    c.positive("timing.set_rate_hz", t.set_rate_hz)?;
    c.positive("timing.frame_rate_hz", t.frame_rate_hz)?;
    if let Some(v) = t.gait_speed_mps {
        c.finite("timing.gait_speed_mps", v)?;
        if v < 0.0 {
            return Err(c.fail(
                "timing.gait_speed_mps",
                format!("a belt speed cannot be negative, got {v}"),
            ));
        }
    }
    if t.poses_per_cycle == 0 || t.poses_per_cycle > MAX_POSES_PER_CYCLE {
        return Err(c.fail(
            "timing.poses_per_cycle",
            format!("must be 1 to {MAX_POSES_PER_CYCLE}"),
        ));
    }
    if t.poses.is_empty() {
        return Err(c.fail("timing.poses", "no poses listed"));
    }
    for (i, &p) in t.poses.iter().enumerate() {
        if p >= t.poses_per_cycle {
            return Err(c.fail(
                format!("timing.poses[{i}]"),
                format!(
                    "pose {p} does not exist in a cycle of {} poses",
                    t.poses_per_cycle
                ),
            ));
        }
        if t.poses[..i].contains(&p) {
            return Err(c.fail(
                format!("timing.poses[{i}]"),
                format!("pose {p} listed twice"),
            ));
        }
    }
    let tt = &m.turntable;
    if tt.azimuth_deg.is_empty() {
        return Err(c.fail("turntable.azimuth_deg", "no cycles listed"));
    }
    for (i, &a) in tt.azimuth_deg.iter().enumerate() {
        c.finite(&format!("turntable.azimuth_deg[{i}]"), a)?;
    }
    c.finite("turntable.degrees_per_cycle", tt.degrees_per_cycle)
}

fn check_cameras(c: &Check, m: &Manifest) -> Result<Vec<Camera>> {
    if m.cameras.is_empty() {
        return Err(c.fail("cameras", "no cameras"));
    }
    let max = crate::io::limits::MAX_DIMENSION;
    m.cameras
        .iter()
        .enumerate()
        .map(|(i, cam)| {
            let f = |name: &str| format!("cameras[{i}].{name}");
            if cam.width == 0 || cam.height == 0 || cam.width > max || cam.height > max {
                return Err(c.fail(
                    f("width"),
                    format!("{}x{} outside 1..={max} per side", cam.width, cam.height),
                ));
            }
            c.positive(&f("fx"), cam.fx)?;
            c.positive(&f("fy"), cam.fy)?;
            c.finite(&f("cx"), cam.cx)?;
            c.finite(&f("cy"), cam.cy)?;
            for (r, row) in cam.world_from_camera.iter().enumerate() {
                for (k, &v) in row.iter().enumerate() {
                    c.finite(&format!("cameras[{i}].world_from_camera[{r}][{k}]"), v)?;
                }
            }
            let w = &cam.world_from_camera;
            let col = |k: usize| Vec3::new(w[0][k] as f32, w[1][k] as f32, w[2][k] as f32);
            let pose = Rigid {
                rotation: Mat3::from_cols(col(0), col(1), col(2)),
                translation: col(3),
            };
            pose.validate(ROTATION_TOLERANCE)
                .map_err(|p| c.fail(f("world_from_camera"), p))?;
            Ok(Camera {
                width: cam.width,
                height: cam.height,
                intrinsics: Intrinsics {
                    fx: cam.fx as f32,
                    fy: cam.fy as f32,
                    cx: cam.cx as f32,
                    cy: cam.cy as f32,
                },
                world_from_camera: pose,
            })
        })
        .collect()
}

fn check_conditions(c: &Check, m: &Manifest) -> Result<Vec<Condition>> {
    if m.conditions.is_empty() {
        return Err(c.fail("conditions", "no basis conditions"));
    }
    let mut total_solid_angle = 0.0;
    let conditions = m
        .conditions
        .iter()
        .enumerate()
        .map(|(i, cond)| {
            if cond.lights.is_empty() {
                return Err(c.fail(
                    format!("conditions[{i}].lights"),
                    "a condition needs lights",
                ));
            }
            let lights = cond
                .lights
                .iter()
                .enumerate()
                .map(|(l, light)| {
                    let f = |name: &str| format!("conditions[{i}].lights[{l}].{name}");
                    for (k, &v) in light.direction.iter().enumerate() {
                        c.finite(&format!("{}[{k}]", f("direction")), v)?;
                    }
                    for (k, &v) in light.intensity.iter().enumerate() {
                        c.finite(&format!("{}[{k}]", f("intensity")), v)?;
                        if v < 0.0 {
                            return Err(c.fail(format!("{}[{k}]", f("intensity")), "negative"));
                        }
                    }
                    c.positive(&f("solid_angle_sr"), light.solid_angle_sr)?;
                    total_solid_angle += light.solid_angle_sr;
                    let d = Vec3::new(
                        light.direction[0] as f32,
                        light.direction[1] as f32,
                        light.direction[2] as f32,
                    );
                    if d.length() < 1e-6 {
                        return Err(c.fail(f("direction"), "zero vector"));
                    }
                    Ok(DomeLight {
                        light: DirLight {
                            direction: d.normalize(),
                            irradiance: light.intensity.map(|v| v as f32),
                        },
                        solid_angle_sr: light.solid_angle_sr as f32,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(Condition {
                name: cond.name.clone(),
                floor: cond.floor,
                lights,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    // The regions of all lights tile at most the sphere (1e-3 slack for rounding).
    let sphere = 4.0 * std::f64::consts::PI;
    if total_solid_angle > sphere * (1.0 + 1e-3) {
        return Err(c.fail(
            "conditions",
            format!("lights cover {total_solid_angle:.3} sr, more than the sphere's {sphere:.3}"),
        ));
    }
    Ok(conditions)
}

fn check_schedule(
    c: &Check,
    m: &Manifest,
    n_conditions: usize,
) -> Result<(Vec<Slot>, Vec<TrackPair>, usize)> {
    if m.schedule.is_empty() {
        return Err(c.fail("schedule", "empty lighting set"));
    }
    let mut slots = Vec::with_capacity(m.schedule.len());
    for (i, s) in m.schedule.iter().enumerate() {
        let f = |name: &str| format!("schedule[{i}].{name}");
        c.finite(&f("time_offset_s"), s.time_offset_s)?;
        let need_index = |what: &str| {
            s.index
                .ok_or_else(|| c.fail(f("index"), format!("a {what} slot needs an index")))
        };
        let kind = match s.kind.as_str() {
            "basis" => {
                let cond = s
                    .condition
                    .ok_or_else(|| c.fail(f("condition"), "a basis slot needs a condition"))?;
                if cond >= n_conditions {
                    return Err(c.fail(
                        f("condition"),
                        format!("condition {cond} does not exist ({n_conditions} conditions)"),
                    ));
                }
                SlotKind::Basis(cond)
            }
            "track" => SlotKind::Track(need_index("track")?),
            "matte" => SlotKind::Matte(need_index("matte")?),
            "unused" => SlotKind::Unused,
            other => {
                return Err(c.fail(
                    f("kind"),
                    format!("unknown slot kind {other:?}; expected basis, track, matte or unused"),
                ));
            }
        };
        slots.push(Slot {
            kind,
            time_offset_s: s.time_offset_s,
        });
    }
    for cond in 0..n_conditions {
        let n = slots
            .iter()
            .filter(|s| s.kind == SlotKind::Basis(cond))
            .count();
        if n != 1 {
            return Err(c.fail(
                "schedule",
                format!("basis condition {cond} appears in {n} slots, expected exactly 1"),
            ));
        }
    }
    let mut tracks = Vec::new();
    for (slot, s) in slots.iter().enumerate() {
        if let SlotKind::Track(k) = s.kind {
            if tracks.iter().any(|t: &TrackPair| t.index == k) {
                return Err(c.fail(
                    format!("schedule[{slot}].index"),
                    format!("track {k} twice"),
                ));
            }
            let matte = slots
                .iter()
                .enumerate()
                .skip(slot + 1)
                .find(|(_, m)| m.kind == SlotKind::Matte(k))
                .map(|(i, _)| i)
                .ok_or_else(|| {
                    c.fail(
                        format!("schedule[{slot}]"),
                        format!("track frame T{k} has no matte frame M{k} after it"),
                    )
                })?;
            tracks.push(TrackPair {
                index: k,
                track_slot: slot,
                matte_slot: matte,
            });
        }
    }
    tracks.sort_by_key(|t| t.index);
    let reference = m.timing.reference_track;
    let reference_track = tracks
        .iter()
        .position(|t| t.index == reference)
        .ok_or_else(|| {
            c.fail(
                "timing.reference_track",
                format!("no track frame T{reference} in the schedule"),
            )
        })?;
    Ok((slots, tracks, reference_track))
}

fn check_files_spec(c: &Check, m: &Manifest) -> Result<()> {
    c.positive("files.full_scale", m.files.full_scale)?;
    for (field, pattern, required) in [
        (
            "files.frame",
            &m.files.frame,
            &["pose", "cycle", "camera", "slot"][..],
        ),
        (
            "files.clean_plate",
            &m.files.clean_plate,
            &["camera", "slot"][..],
        ),
    ] {
        let names = pattern_placeholders(pattern).map_err(|p| c.fail(field, p))?;
        for r in required {
            if !names.contains(r) {
                return Err(c.fail(field, format!("pattern {pattern:?} lacks {{{r}}}")));
            }
        }
        let p = Path::new(pattern.as_str());
        if p.is_absolute() || p.components().any(|c| c == std::path::Component::ParentDir) {
            return Err(c.fail(field, "must be a path inside the capture directory"));
        }
    }
    Ok(())
}
