//! What a stage capture is made of: preset sizes, seed, gait, sampling and noise. The
//! whole configuration is written beside the capture (`stage.toml`), so that the ground
//! truth of any capture can be re-rendered later from the directory alone.

use serde::{Deserialize, Serialize};

use crate::error::{Result, StageError};
use crate::gait::Gait;
use crate::rig::Exposure;

/// The named presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Preset {
    /// About 64x90 pixels, all 36x3 views, 2 poses: for tests and CI, seconds.
    Tiny,
    /// 160x224, all views, 2 poses: for the demo.
    Small,
    /// 320x448 as the original, all views, 2 poses by default.
    Paper,
}

impl Preset {
    /// Parses `tiny`, `small` or `paper`.
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "tiny" => Ok(Preset::Tiny),
            "small" => Ok(Preset::Small),
            "paper" => Ok(Preset::Paper),
            other => Err(StageError::BadConfig(format!(
                "unknown preset {other:?}; expected tiny, small or paper"
            ))),
        }
    }
}

/// Which true flows from the reference track frame to the other slots of a set to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SetFlowTruth {
    /// To every slot of the set.
    All,
    /// To the other track frames only (what basis registration estimates).
    Track,
    /// None (they can still be computed with the library).
    None,
}

fn exposure_of_older_captures() -> Exposure {
    Exposure::Dome
}

/// Everything that determines a stage capture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageConfig {
    /// The preset this configuration came from.
    pub preset: Preset,
    /// Seed of every random choice (perturbations, sensor noise).
    pub seed: u64,
    /// Walking or running.
    pub gait: Gait,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Number of cycles (horizontal views); 36 in the original.
    pub cycles: u32,
    /// The poses (lighting sets of the cycle) rendered.
    pub poses: Vec<u32>,
    /// Supersampling: `n x n` rays per pixel.
    pub samples_per_axis: u32,
    /// Each basis condition is an `n x n` grid of lights over its cell of the sphere.
    pub lights_per_axis: u32,
    /// Scale of the cycle-to-cycle perturbations (1 = the documented amounts, 0 = none).
    pub perturbation: f32,
    /// Whether frames get sensor noise (shot and read noise) before 12-bit quantization.
    pub noise: bool,
    /// Which reference-to-slot flows to write as ground truth.
    pub set_flow_truth: SetFlowTruth,
    /// How bright each condition's lights are (a `stage.toml` without it: [`Exposure::Dome`]).
    #[serde(default = "exposure_of_older_captures")]
    pub exposure: Exposure,
    /// The views filmed per pose, when not every view (a capture made for one scene:
    /// `frf stage --for SCENE`); empty: all.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filmed: Vec<frf_core::manifest::FilmedSpec>,
}

impl StageConfig {
    /// The configuration of a preset.
    pub fn preset(preset: Preset) -> Self {
        let (width, height, poses, lights_per_axis) = match preset {
            Preset::Tiny => (64, 90, vec![0, 1], 2),
            Preset::Small => (160, 224, vec![0, 1], 3),
            Preset::Paper => (320, 448, vec![0, 1], 4),
        };
        Self {
            preset,
            seed: 1,
            gait: Gait::Walk,
            width,
            height,
            cycles: 36,
            poses,
            samples_per_axis: 2,
            lights_per_axis,
            perturbation: 1.0,
            noise: true,
            set_flow_truth: SetFlowTruth::Track,
            exposure: Exposure::Equal,
            filmed: Vec::new(),
        }
    }

    /// Poses in one cycle: the cycle's duration times the 30 Hz set rate.
    pub fn poses_per_cycle(&self) -> u32 {
        (self.gait.cycle_seconds() * crate::rig::SET_RATE_HZ).round() as u32
    }

    /// Checks that the configuration is renderable, naming the first bad field.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(StageError::BadConfig(m));
        if !(8..=4096).contains(&self.width) || !(8..=4096).contains(&self.height) {
            return bad(format!(
                "image size {}x{} outside 8..=4096",
                self.width, self.height
            ));
        }
        if !(1..=360).contains(&self.cycles) {
            return bad(format!("cycles {} outside 1..=360", self.cycles));
        }
        if self.poses.is_empty() {
            return bad("no poses to render".into());
        }
        for f in &self.filmed {
            if !self.poses.contains(&f.pose) {
                return bad(format!(
                    "filmed views of pose {}, which is not rendered",
                    f.pose
                ));
            }
            if let Some(v) = f.views.iter().find(|v| {
                v[0] >= self.cycles || v[1] >= crate::rig::CAMERA_ELEVATIONS_DEG.len() as u32
            }) {
                return bad(format!(
                    "filmed view {v:?} of pose {} is outside the grid",
                    f.pose
                ));
            }
        }
        let per_cycle = self.poses_per_cycle();
        if let Some(p) = self.poses.iter().find(|&&p| p >= per_cycle) {
            return bad(format!(
                "pose {p} does not exist: a cycle has {per_cycle} poses"
            ));
        }
        if !(1..=8).contains(&self.samples_per_axis) {
            return bad(format!(
                "samples_per_axis {} outside 1..=8",
                self.samples_per_axis
            ));
        }
        if !(1..=8).contains(&self.lights_per_axis) {
            return bad(format!(
                "lights_per_axis {} outside 1..=8",
                self.lights_per_axis
            ));
        }
        if !(self.perturbation.is_finite() && (0.0..=10.0).contains(&self.perturbation)) {
            return bad(format!("perturbation {} outside 0..=10", self.perturbation));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_absurd_values_are_not() {
        for p in [Preset::Tiny, Preset::Small, Preset::Paper] {
            StageConfig::preset(p).validate().unwrap();
        }
        let mut c = StageConfig::preset(Preset::Tiny);
        c.poses = vec![99];
        assert!(c.validate().unwrap_err().to_string().contains("pose 99"));
        let mut c = StageConfig::preset(Preset::Tiny);
        c.perturbation = f32::NAN;
        let e = c.validate().unwrap_err().to_string();
        assert!(
            e.contains("perturbation NaN") && e.contains("0..=10"),
            "{e}"
        );
        let e = Preset::parse("huge").unwrap_err().to_string();
        assert!(
            e.contains(r#"unknown preset "huge""#) && e.contains("tiny"),
            "{e}"
        );
    }
}
