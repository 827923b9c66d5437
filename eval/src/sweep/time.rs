//! The time-between-poses stage of `frf report`: the walk filmed again at three
//! consecutive poses and at every second one of them (cycles repeating exactly, so that
//! only time differs), each ingested with its pose-to-pose flows, and a 60 fps shot over
//! the two pose steps between them (frames at each pose and half-way) scored against the
//! true walker at every frame's instant, morphed in time and at the nearest pose; with
//! what each field costs per cycle of walk.

use std::path::Path;

use crate::shot::ShotReport;
use frf_ingest::pipeline::IngestReport;
use frf_stage::config::StageConfig;

use super::stages::{Sweep, ingest_args, parse, read, s};
use crate::error::Result;

/// The stage's name in the report.
const STAGE: &str = "time between poses";

/// `frf stage` arguments that film `poses` of the capture described by `config` again at
/// `(w, h)` into `out`, cycles repeating exactly.
fn stage_args(config: &StageConfig, poses: &str, (w, h): (u32, u32), out: &Path) -> Vec<String> {
    let mut a = super::capture_size::stage_args(config, 0, (w, h), out);
    let set = |a: &mut Vec<String>, flag: &str, value: &str| {
        if let Some(i) = a.iter().position(|x| x == flag) {
            a[i + 1] = value.to_string();
        }
    };
    set(&mut a, "--poses", poses);
    set(&mut a, "--perturbation", "0");
    a
}

/// The scene of the shot: `field`, from pose `first`'s instant over two pose steps at
/// 60 fps, a still camera between the grid's views, lit by `env`.
fn scene(field: &Path, first: u32, config: &StageConfig, env: &str, (w, h): (u32, u32)) -> String {
    let step = config.gait.cycle_seconds() / config.poses_per_cycle() as f64;
    let start = first as f64 * step;
    format!(
        "field = {field:?}\n[time]\nstart = {start}\nend = {end}\nfps = 60.0\n\
         [output]\nsize = [{w}, {h}]\n[lighting]\nenv = {env:?}\n\
         [camera]\n[[camera.key]]\ntime = {start}\nposition = [0.5, 1.2, 3.2]\n\
         look_at = [0.0, 0.9, 0.0]\nfov_deg = 40.0\n\
         [composite]\nbackdrop = \"none\"\nshadow = \"none\"\n",
        field = s(field),
        end = start + 2.0 * step - 1e-4,
    )
}

impl Sweep<'_> {
    /// The time-between-poses stage (see the module docs).
    pub fn time_between_poses(
        &mut self,
        runs: &Path,
        config: &StageConfig,
        size: (u32, u32),
    ) -> Result<()> {
        let p = self.pose;
        let n = config.poses_per_cycle();
        for (name, every) in [("every pose", 1), ("every second pose", 2)] {
            let poses: Vec<u32> = (0..=2 / every).map(|k| (p + k * every) % n).collect();
            let list = poses
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(",");
            let id = format!("time_{every}");
            let dir = runs.join(&id);
            let staged = self
                .runner
                .run(&id, &stage_args(config, &list, size, &dir), &[&dir])?;
            let (f, json) = (
                runs.join(format!("{id}.frf")),
                runs.join(format!("{id}.json")),
            );
            let extra = ["--pose-flow", "--no-shadows"].map(String::from);
            let a = ingest_args(&s(&dir), &list, "fast", &extra, &f, &json);
            let ingested = self.runner.run(&format!("{id}_ingest"), &a, &[&f, &json])?;
            let r: IngestReport = parse(&read(&json)?, &ingested.command)?;
            let bytes = std::fs::metadata(&f)
                .map_err(|e| frf_core::CoreError::io(&f, e))?
                .len();
            // Bytes per cycle of walk: the field's per pose, times the poses a cycle keeps.
            let per_cycle = bytes as f64 / poses.len() as f64 * (n / every) as f64;
            self.push(
                (STAGE, "poses kept"),
                name,
                "field MB per cycle of walk",
                per_cycle / 1e6,
                r.seconds,
                "ingest",
                every == 1,
                &format!("{}; {}", staged.command, ingested.command),
            );
            for interpolate in ["flow", "nearest"] {
                // A scene file's paths are read relative to its own folder: the field
                // beside it by name, an environment file by its absolute path (relative
                // ones named the field twice over with a relative --out).
                let beside = Path::new(f.file_name().unwrap_or_default());
                let env = match Path::new(&self.env) {
                    e if e.is_file() => s(
                        &std::path::absolute(e).map_err(|err| frf_core::CoreError::io(e, err))?
                    ),
                    _ => self.env.clone(),
                };
                let mut text = scene(beside, p, config, &env, size);
                text = text.replace(
                    "fps = 60.0\n",
                    &format!("fps = 60.0\ninterpolate = \"{interpolate}\"\n"),
                );
                let path = runs.join(format!("{id}_{interpolate}.toml"));
                std::fs::write(&path, text).map_err(|e| frf_core::CoreError::io(&path, e))?;
                let mut a: Vec<String> = [
                    "eval",
                    &s(&path),
                    "--capture",
                    &s(&dir),
                    "--frames",
                    "4",
                    "--lights",
                    "64",
                ]
                .map(String::from)
                .to_vec();
                a.extend(self.cpu.iter().cloned());
                a.push("--json".into());
                let ran = self.runner.run(&format!("{id}_{interpolate}"), &a, &[])?;
                let shot: ShotReport = parse(&ran.stdout, &ran.command)?;
                self.push(
                    (STAGE, "poses kept, between them"),
                    format!("{name}, {interpolate}"),
                    "walker PSNR dB, 60 fps, at and half-way between poses",
                    shot.psnr_subject_mean,
                    shot.seconds_render_mean,
                    "per frame",
                    every == 1 && interpolate == "flow",
                    &ran.command,
                );
            }
        }
        Ok(())
    }
}
