//! Writes a stage capture to a directory: the manifest (`capture.toml`), the stage's own
//! configuration (`stage.toml`), every frame and clean plate, and the ground truth:
//!
//! ```text
//! frames/p{pose:02}/v{camera}/u{cycle:02}/s{slot:02}.png   16-bit linear, 12-bit codes x 16
//! clean/v{camera}/s{slot:02}.png                           clean plates
//! truth/alpha/p{pose:02}/v{camera}/u{cycle:02}.png         true alpha at T1 (16-bit)
//! truth/flow/p{pose:02}/v{camera}/u{cycle:02}_{right|left|up|down}.flo      grid flow
//! truth/flow/p{pose:02}/v{camera}/u{cycle:02}_{...}_occ.png                 255 = hidden
//! truth/set_flow/p{pose:02}/v{camera}/u{cycle:02}/s{slot:02}.flo            T1 -> slot
//! preview/set.png, preview/views.png                       contact sheets (8-bit sRGB)
//! ```
//!
//! Work is split into units (one view of one pose, or one camera's clean plates), each
//! written atomically file by file and then marked done in `.progress/`; a rerun on the
//! same directory with the same configuration skips finished units, so an interrupted
//! run resumes where it stopped and never leaves a half-written file under a final name.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use frf_core::atomic::write_bytes_atomic;
use frf_core::capture::Capture;
use frf_core::image::RgbImage;
use frf_core::io::{write_png8_gray, write_png16_gray, write_png16_rgb};
use rayon::prelude::*;

use crate::config::{SetFlowTruth, StageConfig};
use crate::contact;
use crate::error::{Result, StageError};
use crate::rig::{self, StageSlot};
use crate::sensor::MAX_CODE;
use crate::stage::Stage;
use crate::truth::{Neighbour, flow_between};

/// File holding the stage configuration inside a capture directory.
pub const STAGE_FILE: &str = "stage.toml";

/// Path of the true alpha of a view.
pub fn truth_alpha_path(dir: &Path, pose: u32, cycle: usize, camera: usize) -> PathBuf {
    dir.join(format!("truth/alpha/p{pose:02}/v{camera}/u{cycle:02}.png"))
}

fn truth_flow_stem(pose: u32, cycle: usize, camera: usize, n: Neighbour) -> String {
    format!("truth/flow/p{pose:02}/v{camera}/u{cycle:02}_{}", n.name())
}

/// Path of the true flow from a view to a neighbour.
pub fn truth_flow_path(
    dir: &Path,
    pose: u32,
    cycle: usize,
    camera: usize,
    n: Neighbour,
) -> PathBuf {
    dir.join(truth_flow_stem(pose, cycle, camera, n) + ".flo")
}

/// Path of the occlusion mask of a true neighbour flow.
pub fn truth_occlusion_path(
    dir: &Path,
    pose: u32,
    cycle: usize,
    camera: usize,
    n: Neighbour,
) -> PathBuf {
    dir.join(truth_flow_stem(pose, cycle, camera, n) + "_occ.png")
}

/// Path of the true flow from T1 to slot `slot` of a set.
pub fn truth_set_flow_path(
    dir: &Path,
    pose: u32,
    cycle: usize,
    camera: usize,
    slot: usize,
) -> PathBuf {
    dir.join(format!(
        "truth/set_flow/p{pose:02}/v{camera}/u{cycle:02}/s{slot:02}.flo"
    ))
}

/// What [`write_capture`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WriteReport {
    /// Units rendered in this run.
    pub units_rendered: usize,
    /// Units found finished and skipped.
    pub units_skipped: usize,
    /// Wall-clock seconds of this run.
    pub seconds: f64,
    /// Bytes of the whole capture directory afterwards.
    pub bytes: u64,
}

impl WriteReport {
    /// The run for a person: the capture written to `out` by `stage`, the work done and
    /// its size.
    pub fn describe(&self, stage: &Stage, out: &Path) -> String {
        let mut lines = Vec::new();
        let c = stage.config();
        lines.push(format!(
            "capture written to {}: {}x{} pixels, {} cycles x {} cameras, {} poses, 33 frames per set",
            out.display(),
            c.width,
            c.height,
            c.cycles,
            stage.cameras().len(),
            c.poses.len()
        ));
        lines.push(format!(
            "work units (one view of one pose, or one camera's clean plates): {} rendered, {} already done",
            self.units_rendered, self.units_skipped
        ));
        lines.push(format!("wall time of this run: {:.1} s", self.seconds));
        lines.push(format!(
            "capture size on disk: {:.1} MB",
            self.bytes as f64 / 1e6
        ));
        lines.join("\n")
    }
}

#[derive(Debug, Clone, Copy)]
enum Unit {
    Clean {
        camera: usize,
    },
    View {
        pose: u32,
        cycle: usize,
        camera: usize,
    },
}

impl Unit {
    fn marker(&self, dir: &Path) -> PathBuf {
        let name = match *self {
            Unit::Clean { camera } => format!("clean_v{camera}"),
            Unit::View {
                pose,
                cycle,
                camera,
            } => format!("p{pose:02}_v{camera}_u{cycle:02}"),
        };
        dir.join(".progress").join(name)
    }
}

/// Frames hold 12-bit codes in the top bits of 16: the value written is `code x 16`,
/// which the manifest declares with `full_scale = 65520`.
fn stored(img: &RgbImage) -> RgbImage {
    let k = MAX_CODE * 16.0 / 65535.0;
    img.map(|p| p.map(|v| v * k))
}

fn check_or_write_config(stage: &Stage, dir: &Path) -> Result<()> {
    let path = dir.join(STAGE_FILE);
    let ours = toml::to_string(stage.config()).map_err(|e| StageError::BadConfig(e.to_string()))?;
    if let Ok(text) = std::fs::read_to_string(&path) {
        let theirs: StageConfig = toml::from_str(&text).map_err(|e| {
            frf_core::CoreError::bad_file(&path, format!("not a stage configuration: {e}"))
        })?;
        if &theirs != stage.config() {
            let a: toml::Table = toml::from_str(&ours).unwrap_or_default();
            let b: toml::Table = toml::from_str(&text).unwrap_or_default();
            let what = a
                .iter()
                .find(|(k, v)| b.get(*k) != Some(v))
                .map(|(k, _)| k.clone())
                .unwrap_or_else(|| "unknown field".into());
            return Err(StageError::ConfigConflict {
                dir: dir.to_path_buf(),
                what,
            });
        }
        return Ok(());
    }
    write_bytes_atomic(&path, ours.as_bytes())?;
    Ok(())
}

/// Reads the stage configuration of a capture directory written by [`write_capture`].
pub fn read_stage_config(dir: &Path) -> Result<StageConfig> {
    let path = dir.join(STAGE_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| frf_core::CoreError::io(&path, e))?;
    toml::from_str(&text).map_err(|e| {
        StageError::Core(frf_core::CoreError::bad_file(
            &path,
            format!("not a stage configuration: {e}"),
        ))
    })
}

fn write_view(
    stage: &Stage,
    dir: &Path,
    capture: &Capture,
    pose: u32,
    cycle: usize,
    camera: usize,
) -> Result<()> {
    let mut reference = None;
    for slot in 0..stage.schedule().len() {
        let (rendered, exposed) = stage.capture(pose, cycle, camera, slot)?;
        write_png16_rgb(
            &capture.frame_path(pose, cycle, camera, slot),
            &stored(&exposed),
        )?;
        if slot == rig::REFERENCE_SLOT {
            reference = Some(rendered);
        }
    }
    let reference = reference.expect("the schedule has a reference slot");
    write_png16_gray(
        &truth_alpha_path(dir, pose, cycle, camera),
        &reference.alpha,
    )?;
    for n in Neighbour::ALL {
        let Some((u2, v2)) = n.of(cycle, camera, stage.cycles(), stage.cameras().len(), true)
        else {
            continue;
        };
        let to = stage.view_setup(pose, u2, v2, 0.0)?;
        let truth = flow_between(&reference.surface, &to);
        frf_core::flo::write_flo(&truth_flow_path(dir, pose, cycle, camera, n), &truth.flow)?;
        write_png8_gray(
            &truth_occlusion_path(dir, pose, cycle, camera, n),
            &truth.occluded,
        )?;
    }
    for (slot, kind) in stage.schedule().iter().enumerate() {
        let wanted = match stage.config().set_flow_truth {
            SetFlowTruth::All => slot != rig::REFERENCE_SLOT,
            SetFlowTruth::Track => {
                matches!(kind, StageSlot::Track(_)) && slot != rig::REFERENCE_SLOT
            }
            SetFlowTruth::None => false,
        };
        if wanted {
            let to = stage.view_setup(pose, cycle, camera, rig::slot_time_offset_s(slot))?;
            let truth = flow_between(&reference.surface, &to);
            frf_core::flo::write_flo(
                &truth_set_flow_path(dir, pose, cycle, camera, slot),
                &truth.flow,
            )?;
        }
    }
    Ok(())
}

fn dir_bytes(dir: &Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => dir_bytes(&e.path()),
            Ok(_) => e.metadata().map(|m| m.len()).unwrap_or(0),
            Err(_) => 0,
        })
        .sum()
}

/// Renders and writes the whole capture of `stage` into `dir`, resuming a previous run
/// with the same configuration. `progress(done, total)` is called after each unit.
pub fn write_capture(
    stage: &Stage,
    dir: &Path,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<WriteReport> {
    let start = Instant::now();
    std::fs::create_dir_all(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    check_or_write_config(stage, dir)?;
    let manifest = stage.manifest();
    Capture::write_manifest(dir, &manifest)?;
    let capture = Capture::from_manifest(dir, manifest)?;

    let mut units: Vec<Unit> = (0..stage.cameras().len())
        .map(|camera| Unit::Clean { camera })
        .collect();
    for &pose in &stage.config().poses {
        for camera in 0..stage.cameras().len() {
            for cycle in 0..stage.cycles() {
                if !capture.is_filmed(pose, cycle, camera) {
                    continue;
                }
                units.push(Unit::View {
                    pose,
                    cycle,
                    camera,
                });
            }
        }
    }
    let total = units.len();
    let (todo, done): (Vec<Unit>, Vec<Unit>) =
        units.into_iter().partition(|u| !u.marker(dir).exists());
    let finished = AtomicUsize::new(done.len());
    progress(done.len(), total);
    todo.par_iter().try_for_each(|unit| -> Result<()> {
        match *unit {
            Unit::Clean { camera } => {
                for slot in 0..stage.schedule().len() {
                    let plate = stage.clean_plate(camera, slot)?;
                    write_png16_rgb(&capture.clean_plate_path(camera, slot), &stored(&plate))?;
                }
            }
            Unit::View {
                pose,
                cycle,
                camera,
            } => write_view(stage, dir, &capture, pose, cycle, camera)?,
        }
        write_bytes_atomic(&unit.marker(dir), b"done\n")?;
        progress(finished.fetch_add(1, Ordering::Relaxed) + 1, total);
        Ok(())
    })?;
    contact::write_previews(&capture, dir)?;
    Ok(WriteReport {
        units_rendered: todo.len(),
        units_skipped: done.len(),
        seconds: start.elapsed().as_secs_f64(),
        bytes: dir_bytes(dir),
    })
}

/// Opens the stage of a capture directory written by [`write_capture`].
pub fn open_stage(dir: &Path) -> Result<Stage> {
    Stage::new(read_stage_config(dir)?)
}
