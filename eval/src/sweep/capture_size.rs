//! The capture-size knob of `frf report`: the same stage capture filmed again at smaller
//! image sizes (halvings of the capture's own, down to 32 pixels a side; a half of the
//! small preset is about the tiny preset's size), each ingested with the default settings
//! and scored along the frame-size orbit at the original capture's size against its truth.
//! Its time is the whole ingest of one pose, which is what filming smaller saves.

use std::path::Path;

use frf_stage::config::StageConfig;

/// The smallest side a re-filmed capture may have (the flow's pyramid needs a few levels).
const MIN_SIDE: u32 = 32;

/// Smaller sizes to film the capture at, largest first: halvings of `(w, h)` (one in the
/// quick sweep, two otherwise) whose sides stay at least [`MIN_SIDE`].
pub fn smaller_sizes(w: u32, h: u32, quick: bool) -> Vec<(u32, u32)> {
    let halvings = if quick { 1 } else { 2 };
    (1..=halvings)
        .map(|k| (w >> k, h >> k))
        .filter(|&(sw, sh)| sw.min(sh) >= MIN_SIDE)
        .collect()
}

/// `frf stage` arguments that film pose `pose` of the capture described by `config` again
/// at `(w, h)` into `out`: the same preset, seed, gait, lights, perturbation and noise,
/// without the set-flow truth (ingest and the novel-view score do not read it).
pub fn stage_args(config: &StageConfig, pose: u32, (w, h): (u32, u32), out: &Path) -> Vec<String> {
    let name = |v: serde_json::Value| v.as_str().unwrap_or_default().to_string();
    let mut a: Vec<String> = vec![
        "stage".into(),
        "--preset".into(),
        name(serde_json::json!(config.preset)),
        "--seed".into(),
        config.seed.to_string(),
        "--gait".into(),
        name(serde_json::json!(config.gait)),
        "--poses".into(),
        pose.to_string(),
        "--size".into(),
        format!("{w}x{h}"),
        "--lights-per-axis".into(),
        config.lights_per_axis.to_string(),
        "--perturbation".into(),
        config.perturbation.to_string(),
        "--set-flow".into(),
        "none".into(),
    ];
    if !config.noise {
        a.push("--no-noise".into());
    }
    a.extend(["--out".into(), out.display().to_string()]);
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_halve_down_to_the_smallest_side() {
        assert_eq!(smaller_sizes(160, 224, false), vec![(80, 112), (40, 56)]);
        assert_eq!(smaller_sizes(160, 224, true), vec![(80, 112)]);
        assert_eq!(smaller_sizes(64, 90, false), vec![(32, 45)]);
        assert!(smaller_sizes(32, 45, true).is_empty());
    }

    #[test]
    fn stage_arguments_repeat_the_capture_settings() {
        let mut config = StageConfig::preset(frf_stage::config::Preset::Small);
        config.seed = 7;
        config.gait = frf_stage::gait::Gait::Run;
        config.noise = false;
        let a = stage_args(&config, 1, (80, 112), Path::new("/x"));
        let joined = a.join(" ");
        for part in [
            "--preset small",
            "--seed 7",
            "--gait run",
            "--poses 1",
            "--size 80x112",
            "--no-noise",
            "--out /x",
        ] {
            assert!(joined.contains(part), "{joined}");
        }
    }
}
