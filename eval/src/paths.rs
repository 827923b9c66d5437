//! The camera paths people render, scored: any trajectory (`frf eval --orbit` or
//! `--camera`), and a named suite of orbits placed against the capture's own cylinder of
//! cameras, so that each exercises one way of leaving the grid's quad centres.
//!
//! The suite is measured from the pose's cameras: `R` the bottom row's distance from the
//! vertical axis, `y0` its height (the capture cameras look at the subject's centre from
//! it), `y1` the top row's height. Every orbit looks at `(0, y0, 0)`, loops once, with a
//! vertical field of view of 35°:
//!
//! | name          | radius  | height            | what it tests                           |
//! |---------------|---------|-------------------|-----------------------------------------|
//! | `inside-low`  | 0.67 R  | y0 + 0.3 m        | inside the cylinder: rays below the grid |
//! | `inside-high` | 0.55 R  | y1 − 0.2 m        | inside, high: rays above and below       |
//! | `near`        | 0.97 R  | (y0 + y1) / 2     | just inside the cameras                 |
//! | `outside`     | 1.6 R   | (y0 + y1) / 2     | outside, inside the rows                |
//! | `above`       | 0.9 R   | y1 + 1 m          | above the top camera, looking down      |
//! | `below`       | R       | y0 − 0.6 m        | below the bottom camera, looking up     |
//!
//! For the stage's rig (4.5 m, rows at 0°, 17° and 34° about a target 0.9 m up) the first
//! is the orbit of radius 3 m at 1.2 m on which the seam at the neck was seen.

use std::path::{Path, PathBuf};

use frf_core::io::write_png8_srgba;
use frf_core::light::DirLight;
use frf_render::geometry::PoseGeometry;
use frf_render::morph::Variant;
use frf_render::renderer::Renderer;
use frf_scene::path::{Orbit, Trajectory};
use frf_stage::Stage;
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::{EvalError, Result};
use crate::metrics::max_row_jump;
use crate::views::{EvalCamera, ReportHeader, VariantScore, evaluate, truth_frames};
use crate::views::{TABLE_HEADER, table_row};
use frf_core::progress::Progress;

/// A named trajectory of the suite.
#[derive(Debug, Clone)]
pub struct NamedPath {
    /// Name in reports.
    pub name: &'static str,
    /// What it tests.
    pub about: &'static str,
    /// The trajectory.
    pub trajectory: Trajectory,
}

/// Vertical field of view of the suite's orbits, degrees.
const SUITE_FOV_DEG: f32 = 35.0;

/// `R`, `y0` and `y1` of a pose's grid (see the module docs).
fn rig(geometry: &PoseGeometry) -> Result<(f32, f32, f32)> {
    let row = |v: usize| -> Vec<Vec3> {
        (0..geometry.columns)
            .map(|u| geometry.cameras[geometry.view(u, v)].centre())
            .collect()
    };
    if geometry.columns == 0 || geometry.rows == 0 || geometry.cameras.is_empty() {
        return Err(EvalError::NoTruth("a pose without cameras".into()));
    }
    let (bottom, top) = (row(0), row(geometry.rows - 1));
    let n = bottom.len() as f32;
    let radius = bottom
        .iter()
        .map(|c| (c.x * c.x + c.z * c.z).sqrt())
        .sum::<f32>()
        / n;
    let y0 = bottom.iter().map(|c| c.y).sum::<f32>() / n;
    let y1 = top.iter().map(|c| c.y).sum::<f32>() / top.len() as f32;
    if !(radius.is_finite() && radius > 1e-3 && y0.is_finite() && y1.is_finite()) {
        return Err(EvalError::NoTruth(format!(
            "a grid of radius {radius} m, rows at {y0} and {y1} m"
        )));
    }
    Ok((radius, y0, y1))
}

/// The suite of paths for a pose's grid (see the module docs).
pub fn suite(geometry: &PoseGeometry) -> Result<Vec<NamedPath>> {
    let (r, y0, y1) = rig(geometry)?;
    let mid = 0.5 * (y0 + y1);
    let orbit = |radius: f32, height: f32| {
        Trajectory::Orbit(Orbit {
            radius,
            height,
            start_deg: 0.0,
            sweep_deg: 360.0,
            look_at: Vec3::new(0.0, y0, 0.0),
            fov_deg: SUITE_FOV_DEG,
        })
    };
    Ok(vec![
        NamedPath {
            name: "inside-low",
            about: "inside the cylinder, low: rays below the grid",
            trajectory: orbit(0.67 * r, y0 + 0.3),
        },
        NamedPath {
            name: "inside-high",
            about: "inside the cylinder, high: rays above and below the grid",
            trajectory: orbit(0.55 * r, y1 - 0.2),
        },
        NamedPath {
            name: "near",
            about: "just inside the cameras",
            trajectory: orbit(0.97 * r, mid),
        },
        NamedPath {
            name: "outside",
            about: "outside the cameras, between the rows",
            trajectory: orbit(1.6 * r, mid),
        },
        NamedPath {
            name: "above",
            about: "above the top camera, looking down",
            trajectory: orbit(0.9 * r, y1 + 1.0),
        },
        NamedPath {
            name: "below",
            about: "below the bottom camera, looking up",
            trajectory: orbit(r, y0 - 0.6),
        },
    ])
}

/// One path scored.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PathScore {
    /// Its name.
    pub name: String,
    /// What it tests.
    pub about: String,
    /// The truth's largest row-to-row jump, per frame (the scale of a seam).
    pub truth_max_row_jump: Vec<f64>,
    /// Each variant.
    pub variants: Vec<VariantScore>,
}

/// What `frf eval --json` prints along paths.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PathsReport {
    /// What was rendered, and how the truth was made.
    #[serde(flatten)]
    pub header: ReportHeader,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Frames of each path.
    pub frames_per_path: usize,
    /// Each path.
    pub paths: Vec<PathScore>,
    /// Per variant: the mean over the paths of their mean subject PSNR, dB.
    pub mean_psnr_subject: Vec<(String, f64)>,
}

/// What to evaluate along paths.
pub struct PathOptions<'a> {
    /// The field's path, the capture's and the environment's name, for the report.
    pub names: (PathBuf, PathBuf, String),
    /// Frames of each path.
    pub frames: usize,
    /// Frame size.
    pub size: (u32, u32),
    /// Variants.
    pub variants: &'a [Variant],
    /// The truth's lights.
    pub lights: &'a [DirLight],
    /// Median-cut lights asked for (the report's `truth_lights`).
    pub light_count: usize,
    /// Write every frame and its truth as PNGs here.
    pub images: Option<&'a Path>,
}

/// Renders `paths` of pose `pose` with every variant and scores them against the
/// stage's truth.
pub fn evaluate_paths(
    renderer: &Renderer,
    stage: &Stage,
    pose: u32,
    paths: &[NamedPath],
    options: &PathOptions,
    progress: &dyn Progress,
) -> Result<PathsReport> {
    let (w, h) = options.size;
    let mut scores = Vec::new();
    let mut truth_seconds = 0.0;
    for p in paths {
        let cameras: Vec<EvalCamera> = p
            .trajectory
            .cameras(options.frames, w, h)?
            .into_iter()
            .enumerate()
            .map(|(i, camera)| EvalCamera {
                name: format!("{} frame {i}", p.name),
                camera,
                view: None,
            })
            .collect();
        progress.phase(&format!("{}: truth frames", p.name), cameras.len());
        let all: Vec<_> = cameras.iter().map(|c| c.camera).collect();
        let (truths, seconds) = truth_frames(stage, pose, &all, options.lights, progress)?;
        truth_seconds += seconds;
        progress.finish();
        progress.phase(
            &format!("{}: rendered frames", p.name),
            cameras.len() * options.variants.len(),
        );
        let variant_scores = evaluate(
            renderer,
            &cameras,
            &truths,
            options.variants,
            &mut |i, v, img| {
                progress.step();
                if let Some(dir) = options.images {
                    let name = format!("{}_{i:02}_{}.png", p.name, v.name());
                    write_png8_srgba(&dir.join(name), img, 1.0)?;
                }
                Ok(())
            },
        )?;
        progress.finish();
        if let Some(dir) = options.images {
            for (i, t) in truths.iter().enumerate() {
                let name = format!("{}_{i:02}_truth.png", p.name);
                write_png8_srgba(&dir.join(name), t, 1.0)?;
            }
        }
        scores.push(PathScore {
            name: p.name.to_string(),
            about: p.about.to_string(),
            truth_max_row_jump: truths.iter().map(max_row_jump).collect(),
            variants: variant_scores,
        });
    }
    let mean_psnr_subject: Vec<(String, f64)> = options
        .variants
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let m = scores
                .iter()
                .map(|p| p.variants[k].psnr_subject)
                .sum::<f64>()
                / scores.len().max(1) as f64;
            (v.name().to_string(), m)
        })
        .collect();
    let truth_frames = (paths.len() * options.frames).max(1) as f64;
    let (field, capture, env) = options.names.clone();
    Ok(PathsReport {
        header: ReportHeader {
            field,
            capture,
            env,
            pose,
            device: renderer.device(),
            truth_lights: options.light_count,
            truth_seconds_per_frame: truth_seconds / truth_frames,
        },
        width: w,
        height: h,
        frames_per_path: options.frames,
        paths: scores,
        mean_psnr_subject,
    })
}

impl PathsReport {
    /// The scores for a person: per path a line per variant (with its largest row jump),
    /// then the mean over the paths.
    pub fn describe(&self) -> String {
        let mut lines = Vec::new();
        for p in &self.paths {
            let jump = p.truth_max_row_jump.iter().cloned().fold(0.0, f64::max);
            lines.push(format!(
                "{} ({}; the truth's largest row jump {jump:.3}):",
                p.name, p.about
            ));
            lines.push(format!("  {TABLE_HEADER}"));
            for s in &p.variants {
                let worst = s.frames.iter().map(|f| f.max_row_jump).fold(0.0, f64::max);
                lines.push(format!("  {}  row jump {worst:.3}", table_row(s)));
            }
        }
        if self.paths.len() > 1 {
            lines.push("mean subject PSNR over the paths:".to_string());
            for (name, m) in &self.mean_psnr_subject {
                lines.push(format!("  {name:<21} {m:.2} dB"));
            }
        }
        lines.join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use frf_core::camera::Camera;
    use frf_render::geometry::Crop;

    #[test]
    fn the_suite_sits_where_its_names_say_on_a_stage_like_grid() {
        let mut cameras = Vec::new();
        for u in 0..36 {
            for e in [0.0f32, 17.0, 34.0] {
                let d = frf_core::light::direction_from_azimuth_elevation(
                    -(u as f32 * 10.0).to_radians(),
                    e.to_radians(),
                );
                let eye = Vec3::new(0.0, 0.9, 0.0) + d * 4.5;
                cameras.push(
                    Camera::look_at(eye, Vec3::new(0.0, 0.9, 0.0), Vec3::Y, 0.5, 32, 48).unwrap(),
                );
            }
        }
        let crop = Crop {
            x0: 0,
            y0: 0,
            width: 32,
            height: 48,
        };
        let g = PoseGeometry::new(0, 36, 3, true, (32, 48), crop, cameras, |_, _| false);
        let paths = suite(&g).unwrap();
        let at = |name: &str| match paths.iter().find(|p| p.name == name).unwrap().trajectory {
            Trajectory::Orbit(o) => o,
            _ => unreachable!(),
        };
        let low = at("inside-low");
        assert!((low.radius - 3.015).abs() < 0.01 && (low.height - 1.2).abs() < 1e-3);
        assert!(at("above").height > 0.9 + 4.5 * 34f32.to_radians().sin());
        assert!(at("below").height < 0.9);
        assert!(at("outside").radius > 4.5 && at("near").radius < 4.5);
        // Each path renders: its cameras are valid.
        for p in &paths {
            assert_eq!(p.trajectory.cameras(4, 32, 24).unwrap().len(), 4);
        }
    }
}
