//! `frf bench frame`: what one frame of a crowd costs, by number of walkers and by
//! lighting. The scene's first walker is copied onto a square grid (1.2 m apart, centred
//! where it stands), each copy turned by the golden angle from the last so that every
//! walker is relit for a heading of its own (the costly case: walkers of one heading
//! share one relit pose). The lighting is held (`constant`) or turned 15° a frame
//! (`turning`; `--turn-deg` sets the turn: a light turning slower than the shot's light
//! tolerance relights a walker every few frames, [`crate::shot::LightTolerance`]). The walkers stand (`standing`) or walk (`walking`: each from its place
//! along a bend of [`BEND_RADIUS_M`] at the field's gait speed (else
//! [`WALK_SPEED_MPS`]), turning as it goes, so every walker's own light changes every
//! frame; its walk plays as fast as a standing walker's). The frames are spaced ([`Spacing`]) a millisecond of the scene's time
//! apart (`held`: every walker keeps its pose, only the lighting differs) or as the
//! scene's own frames are (`shot`: poses stream in and out as in a render). The shot's
//! plan is made once before the frames, as `frf render` makes it, and is not timed. One
//! frame is drawn first to make the poses resident and is not counted; the medians of
//! the counted frames are reported:
//!
//! - `wall_ms_per_frame`: the frame from start to its pixels read back (with
//!   `--no-readback`, to the device's having drawn it: nothing is copied back);
//! - `gpu_ms_per_frame`: how long the host waited on the device within it (fenced: the
//!   device's work that the host did not overlap; on a software adapter the device is
//!   the host's own cores);
//! - `host_ms_per_frame`: the difference, the host's own work (choosing what to make
//!   resident, projecting the light, recording and submitting the passes, converting the
//!   pixels read back); on a software adapter a submission may run earlier work before
//!   it returns, which then counts here (docs/results/realtime.md measures how much);
//! - `first_frame_ms`: the first frame, not counted (every walker's poses made resident);
//! - `residency_ms_per_frame`: of the host's work, reading and relighting poses (the
//!   light's coefficients for every walker relit, recording its relight): what a turning
//!   light or a walker on a curve costs the host, apart from the frame's own;
//! - `submit_ms_per_frame`: of the host's work, the time inside `queue.submit` (on
//!   lavapipe, which runs the work submitted on the calling thread, the device's work:
//!   the host's own is then `host_ms_per_frame` less this);
//! - `host_cpu_ms_per_frame`: the calling thread's CPU time in the frame outside its
//!   submissions and waits: the host's own work, free of the time other processes took
//!   of a shared machine, which wall times count (work the host hands to other threads
//!   is not in it); where the system does not say, none;
//! - `gpu_timestamps_ms_per_frame`: the device's time in the frame's passes by GPU
//!   timestamp queries, where the adapter has them (`passes` gives each pass's).

use std::time::Instant;

use frf_core::progress::Progress;
use frf_core::thread_clock::thread_cpu;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::gpu::pass_clock::PassTime;
use frf_render::renderer::Device;
use glam::Vec3;
use serde::Serialize;

use super::shot::{Shot, ShotOptions};
use super::{Instance, LightKey, Scene};
use crate::error::Result;
use frf_core::BadArgument;

/// Seconds of the scene's time between two counted frames.
const FRAME_STEP_S: f64 = 1e-3;

/// Degrees a turning light turns a frame, unless told otherwise.
pub const TURN_DEG_PER_FRAME: f32 = 15.0;

/// Metres between walkers on the grid.
const SPACING_M: f32 = 1.2;

/// Radius of the bend a walking walker follows, metres: a turn of 90° over 6 m.
pub const BEND_RADIUS_M: f32 = 6.0 / std::f32::consts::FRAC_PI_2;

/// A walking walker's speed where the field does not know its gait's, metres per second
/// (a brisk walk).
pub const WALK_SPEED_MPS: f32 = 1.4;

/// Whether the benchmark's walkers stand or walk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Motion {
    /// Each on its place of the grid.
    Standing,
    /// Each along a bend from its place ([`BEND_RADIUS_M`], [`WALK_SPEED_MPS`]).
    Walking,
}

impl Motion {
    /// Its name in tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Motion::Standing => "standing",
            Motion::Walking => "walking",
        }
    }
}

/// A frame's lighting in the benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightMode {
    /// The scene's first lighting key, held.
    Constant,
    /// The first key turned a further 15° every frame.
    Turning,
}

impl LightMode {
    /// Its name in tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            LightMode::Constant => "constant",
            LightMode::Turning => "turning",
        }
    }
}

/// How far apart the counted frames are in the scene's time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Spacing {
    /// A millisecond: every walker keeps its pose, only the lighting changes.
    Held,
    /// The scene's own frame interval: poses stream in as a shot's do.
    Shot,
}

/// What `frf bench frame` runs.
#[derive(Debug, Clone)]
pub struct FrameBenchOptions {
    /// How far apart the frames are.
    pub spacing: Spacing,
    /// Walker counts.
    pub walkers: Vec<usize>,
    /// Lightings.
    pub lights: Vec<LightMode>,
    /// Degrees a turning light turns a frame.
    pub turn_deg: f32,
    /// Standing, walking, or both.
    pub motions: Vec<Motion>,
    /// Frames counted per row (after one not counted).
    pub frames: usize,
    /// Frame size.
    pub size: (u32, u32),
    /// How shots are rendered (memory budget, plan).
    pub shot: ShotOptions,
    /// Read each frame's pixels back (else only wait until it is drawn).
    pub readback: bool,
    /// Render on the CPU reference.
    pub cpu: bool,
}

impl FrameBenchOptions {
    /// Refuses counts no run can use.
    pub fn check(&self) -> Result<()> {
        if let Some(&w) = self.walkers.iter().find(|&&w| w == 0 || w > 10_000) {
            return Err(BadArgument::new("--walkers", w, "1 to 10000 walkers").into());
        }
        if self.walkers.is_empty() {
            return Err(BadArgument::new("--walkers", "(none)", "at least one count").into());
        }
        if !(self.turn_deg > 0.0 && self.turn_deg <= 180.0) {
            return Err(
                BadArgument::new("--turn-deg", self.turn_deg, "above 0 to 180 degrees").into(),
            );
        }
        if self.frames == 0 || self.frames > 10_000 {
            return Err(BadArgument::new("--frames", self.frames, "1 to 10000 frames").into());
        }
        Ok(())
    }
}

/// One row: a walker count under one lighting.
#[derive(Debug, Clone, Serialize)]
pub struct FrameBenchRow {
    /// Walkers drawn.
    pub walkers: usize,
    /// `constant` or `turning`.
    pub light: LightMode,
    /// `standing` or `walking`.
    pub motion: Motion,
    /// Median host work per frame (wall less waits on the device), ms.
    pub host_ms_per_frame: f64,
    /// Median wait on the device per frame (fenced), ms.
    pub gpu_ms_per_frame: f64,
    /// Median host work per frame reading and relighting poses (part of
    /// `host_ms_per_frame`), ms.
    pub residency_ms_per_frame: f64,
    /// Median time per frame inside `queue.submit` (part of `host_ms_per_frame`), ms:
    /// on a software adapter that runs the work submitted on the calling thread
    /// (lavapipe), the device's work too.
    pub submit_ms_per_frame: f64,
    /// Median CPU time per frame of the calling thread outside its submissions and
    /// waits on the device, ms (see the module docs; `None` where the system does not
    /// say).
    pub host_cpu_ms_per_frame: Option<f64>,
    /// Median frame, ms.
    pub wall_ms_per_frame: f64,
    /// The first frame (not counted in the medians), ms: every walker's poses read,
    /// decoded, uploaded and lit before it is drawn (what a shot or the viewer waits
    /// for before its first picture).
    pub first_frame_ms: f64,
    /// Median device time in the frame's passes by GPU timestamps, ms (`None` where the
    /// adapter has no timestamp queries, and on the CPU).
    pub gpu_timestamps_ms_per_frame: Option<f64>,
    /// Poses relit per counted frame (mean).
    pub relights_per_frame: f64,
    /// Most bytes resident at once, MB.
    pub peak_resident_mb: f64,
    /// Per pass, its median device time per counted frame by GPU timestamps (empty where
    /// the adapter has none, and on the CPU).
    pub passes: Vec<PassTime>,
}

/// What `frf bench frame` measured.
#[derive(Debug, Clone, Serialize)]
pub struct FrameBenchReport {
    /// What rendered.
    pub device: String,
    /// How `gpu_ms_per_frame` was measured.
    pub gpu_clock: &'static str,
    /// How the rows' `passes` were measured (`gpu-timestamps`, or `none`).
    pub pass_clock: &'static str,
    /// How far apart the counted frames were.
    pub spacing: Spacing,
    /// Degrees the turning light turned a frame.
    pub turn_deg_per_frame: f32,
    /// Degrees a walker's light could turn before its poses were relit
    /// ([`crate::shot::LightTolerance`]).
    pub light_tolerance_deg: f32,
    /// Whether each frame's pixels were read back (else each frame was waited for
    /// where it was drawn).
    pub readback: bool,
    /// Frame size.
    pub size: (u32, u32),
    /// Frames counted per row.
    pub frames: usize,
    /// The rows.
    pub rows: Vec<FrameBenchRow>,
}

impl FrameBenchReport {
    /// The rows as a table, with the ratios the targets read.
    pub fn table(&self) -> String {
        let spacing = match self.spacing {
            Spacing::Held => "1 ms apart, poses held",
            Spacing::Shot => "spaced as the shot's",
        };
        let readback = if self.readback {
            "read back"
        } else {
            "not read back"
        };
        let mut out = format!(
            "{} at {}x{}, {} frames a row, {spacing}, {readback}, a turning light {}° a \
             frame, relit past {}° (medians; gpu = fenced wait on the device)\n",
            self.device,
            self.size.0,
            self.size.1,
            self.frames,
            self.turn_deg_per_frame,
            self.light_tolerance_deg
        );
        out += "walkers  light     motion     host ms (relighting, submit, own cpu)  gpu ms  \
                wall ms  relit/frame  peak MB  first ms\n";
        for r in &self.rows {
            let cpu = r
                .host_cpu_ms_per_frame
                .map_or_else(|| "-".to_string(), |c| format!("{c:.1}"));
            out += &format!(
                "{:>7}  {:<8} {:<9} {:>8.1} {:>10.1} {:>9.1} {:>8} {:>7.1} {:>8.1} {:>12.1} \
                 {:>8.1} {:>9.1}\n",
                r.walkers,
                r.light.name(),
                r.motion.name(),
                r.host_ms_per_frame,
                r.residency_ms_per_frame,
                r.submit_ms_per_frame,
                cpu,
                r.gpu_ms_per_frame,
                r.wall_ms_per_frame,
                r.relights_per_frame,
                r.peak_resident_mb,
                r.first_frame_ms
            );
        }
        if self.rows.iter().any(|r| !r.passes.is_empty()) {
            out += "device ms per frame by pass (GPU timestamps, medians; passes and \
                    dispatches per frame), and in all:\n";
            for r in &self.rows {
                let passes: Vec<String> = r
                    .passes
                    .iter()
                    .map(|p| format!("{} {:.1} ({}/{})", p.pass, p.ms, p.passes, p.dispatches))
                    .collect();
                out += &format!(
                    "{:>7}  {:<8} {:<9} {}; all {:.1}\n",
                    r.walkers,
                    r.light.name(),
                    r.motion.name(),
                    passes.join(", "),
                    r.gpu_timestamps_ms_per_frame.unwrap_or(f64::NAN)
                );
                let untimed: usize = r.passes.iter().map(|p| p.untimed).sum();
                if untimed > 0 {
                    out += &format!(
                        "warning: {} walkers, {} light: {untimed} passes a frame past the pass \
                         clock's capacity were not timed; the times above under-count them\n",
                        r.walkers,
                        r.light.name()
                    );
                }
            }
        }
        let row = |w: usize, l: LightMode, m: Motion| {
            (self.rows.iter()).find(|r| r.walkers == w && r.light == l && r.motion == m)
        };
        let find = |w: usize, l: LightMode| row(w, l, Motion::Standing);
        for r in &self.rows {
            if r.light == LightMode::Turning
                && r.motion == Motion::Standing
                && let Some(c) = find(r.walkers, LightMode::Constant)
            {
                out += &format!(
                    "{} walkers: turning / constant light, wall per frame: {:.2}x\n",
                    r.walkers,
                    r.wall_ms_per_frame / c.wall_ms_per_frame
                );
            }
            if r.motion == Motion::Walking
                && let Some(c) = row(r.walkers, r.light, Motion::Standing)
            {
                out += &format!(
                    "{} walkers, {} light: walking / standing, wall per frame: {:.2}x\n",
                    r.walkers,
                    r.light.name(),
                    r.wall_ms_per_frame / c.wall_ms_per_frame
                );
            }
        }
        if let (Some(lo), Some(hi)) = (
            self.rows.iter().min_by_key(|r| r.walkers),
            self.rows.iter().max_by_key(|r| r.walkers),
        ) && hi.walkers > lo.walkers
        {
            for light in [LightMode::Constant, LightMode::Turning] {
                if let (Some(a), Some(b)) = (find(lo.walkers, light), find(hi.walkers, light)) {
                    let own = |r: &FrameBenchRow| r.host_ms_per_frame - r.submit_ms_per_frame;
                    let cpu = match (b.host_cpu_ms_per_frame, a.host_cpu_ms_per_frame) {
                        (Some(b), Some(a)) => format!("; its own CPU time: {:.2}x", b / a),
                        _ => String::new(),
                    };
                    out += &format!(
                        "{light} light: host per frame at {} walkers / at {}: {:.2}x \
                         (less its submissions: {:.2}x{cpu})\n",
                        b.walkers,
                        a.walkers,
                        b.host_ms_per_frame / a.host_ms_per_frame,
                        own(b) / own(a),
                        light = light.name()
                    );
                }
            }
        }
        out
    }
}

/// `scene` with its first walker copied `n` times on a grid, standing or walking as
/// `motion` says, lit as `light` says (turning `turn_deg` a frame) for `frames` frames
/// from its start.
pub fn bench_scene(
    scene: &Scene,
    n: usize,
    (light, turn_deg, motion, speed): (LightMode, f32, Motion, f32),
    (frames, spacing): (usize, Spacing),
) -> Scene {
    let mut s = scene.clone();
    let first = &scene.instances[0];
    let side = (n as f32).sqrt().ceil() as usize;
    let centre = (side as f32 - 1.0) * 0.5;
    let step = match spacing {
        Spacing::Held => FRAME_STEP_S,
        Spacing::Shot => 1.0 / scene.fps,
    };
    let span = (frames + 1) as f64 * step;
    s.instances = (0..n)
        .map(|k| {
            let position = first.position
                + Vec3::new(
                    ((k % side) as f32 - centre) * SPACING_M,
                    0.0,
                    ((k / side) as f32 - centre) * SPACING_M,
                );
            let heading = first.heading + k as f32 * 137.507_77_f32.to_radians();
            match motion {
                Motion::Standing => Instance::standing(position, heading, first.time_offset),
                Motion::Walking => walking(
                    position,
                    (heading, speed),
                    (scene.start, span),
                    first.time_offset,
                ),
            }
        })
        .collect();
    let key = scene.lighting[0].clone();
    s.start = scene.start;
    s.fps = 1.0 / step;
    s.end = scene.start + span;
    s.lighting = match light {
        LightMode::Constant => vec![LightKey {
            time: scene.start,
            ..key
        }],
        LightMode::Turning => vec![
            LightKey {
                time: scene.start,
                ..key.clone()
            },
            LightKey {
                time: s.end,
                yaw_deg: key.yaw_deg + f64::from(turn_deg) * (frames + 1) as f64,
                ..key
            },
        ],
    };
    s
}

/// Runs the benchmark of `scene` on `field` (see the module docs), one progress step a
/// frame.
pub fn run_frame_bench<R: ReadAt>(
    scene: &Scene,
    field: &FieldFile<R>,
    options: &FrameBenchOptions,
    progress: &dyn Progress,
) -> Result<FrameBenchReport> {
    options.check()?;
    // Counts the device cannot draw are refused before any is drawn.
    let device = Device::open(options.cpu)?;
    if let Some(most) = device.max_walkers()
        && let Some(&n) = options.walkers.iter().find(|&&n| n > most)
    {
        return Err(BadArgument::new(
            "--walkers",
            n,
            format!("at most {most} walkers a frame on {}", device.name()),
        )
        .into());
    }
    drop(device);
    let rows_wanted = options.walkers.len() * options.lights.len() * options.motions.len();
    progress.phase("frames", rows_wanted * (options.frames + 1));
    let mut rows = Vec::with_capacity(rows_wanted);
    let mut device_name = String::new();
    let mut pass_clock = "none";
    let modes: Vec<(LightMode, Motion)> = (options.lights.iter())
        .flat_map(|&l| options.motions.iter().map(move |&m| (l, m)))
        .collect();
    let speed = crate::Gait::of_field(field)?
        .speed_mps()
        .map_or(WALK_SPEED_MPS, |v| v as f32);
    for &n in &options.walkers {
        for &(light, motion) in &modes {
            let s = bench_scene(
                scene,
                n,
                (light, options.turn_deg, motion, speed),
                (options.frames, options.spacing),
            );
            let frames = s.shot_frames(0..options.frames + 1, options.size)?;
            let device = Device::open(options.cpu)?;
            device_name = device.name();
            if let Device::Gpu(gpu) = &device
                && gpu.clock_passes()
            {
                pass_clock = "gpu-timestamps";
            }
            let mut shot = Shot::new(&s, field, device, &frames, options.shot)?;
            let mut wall = Vec::new();
            let mut waited = Vec::new();
            let mut residency = Vec::new();
            let mut submitting = Vec::new();
            let mut own_cpu = Vec::new();
            let mut passes: Vec<Vec<PassTime>> = Vec::new();
            let mut relights = 0;
            let mut first = 0.0;
            for (k, f) in frames.iter().enumerate() {
                let before = waited_on(shot.render_device());
                let submitted_before = submitted_on(shot.render_device());
                let resident_before = shot.counters().residency_seconds;
                let device_cpu_before = device_cpu_on(shot.render_device());
                let cpu_before = thread_cpu();
                let t = Instant::now();
                let made = if options.readback {
                    shot.render(f, false)?.made_resident.len()
                } else {
                    shot.draw_unread(f)?.len()
                };
                let w = t.elapsed().as_secs_f64() * 1e3;
                let cpu = thread_cpu().zip(cpu_before).map(|(after, before)| {
                    let device = device_cpu_on(shot.render_device()) - device_cpu_before;
                    (after.saturating_sub(before).as_secs_f64() - device).max(0.0) * 1e3
                });
                // The frame's waits, counted before the pass times are read: reading them
                // waits on the device again, outside the frame's wall time (counting
                // that wait made the host's share negative on a loaded machine).
                let frame_waited = (waited_on(shot.render_device()) - before) * 1e3;
                let times = pass_times(shot.render_device())?;
                if k == 0 {
                    first = w;
                } else {
                    wall.push(w);
                    waited.push(frame_waited);
                    residency.push((shot.counters().residency_seconds - resident_before) * 1e3);
                    submitting.push((submitted_on(shot.render_device()) - submitted_before) * 1e3);
                    own_cpu.extend(cpu);
                    relights += made;
                    passes.push(times);
                }
                progress.step();
            }
            let host: Vec<f64> = wall.iter().zip(&waited).map(|(w, g)| w - g).collect();
            rows.push(FrameBenchRow {
                walkers: n,
                light,
                motion,
                host_ms_per_frame: median(&host),
                gpu_ms_per_frame: median(&waited),
                residency_ms_per_frame: median(&residency),
                submit_ms_per_frame: median(&submitting),
                host_cpu_ms_per_frame: (!own_cpu.is_empty()).then(|| median(&own_cpu)),
                wall_ms_per_frame: median(&wall),
                first_frame_ms: first,
                gpu_timestamps_ms_per_frame: (pass_clock == "gpu-timestamps").then(|| {
                    let sums: Vec<f64> = passes
                        .iter()
                        .map(|f| f.iter().map(|p| p.ms).sum())
                        .collect();
                    median(&sums)
                }),
                relights_per_frame: relights as f64 / options.frames as f64,
                peak_resident_mb: shot.counters().peak_resident_bytes as f64 / 1e6,
                passes: median_passes(&passes),
            });
        }
    }
    Ok(FrameBenchReport {
        device: device_name,
        gpu_clock: "fenced-wall",
        pass_clock,
        spacing: options.spacing,
        turn_deg_per_frame: options.turn_deg,
        light_tolerance_deg: options.shot.light_tolerance.heading.to_degrees(),
        readback: options.readback,
        size: options.size,
        frames: options.frames,
        rows,
    })
}

/// A walker starting at `position` facing `heading`, walking a bend of [`BEND_RADIUS_M`]
/// to its left at `speed` (metres per second) over `span` seconds from `start`, its walk
/// `time_offset` ahead.
fn walking(
    position: Vec3,
    (heading, speed): (f32, f32),
    (start, span): (f64, f64),
    time_offset: f64,
) -> Instance {
    let turn = glam::Quat::from_rotation_y(heading);
    let keys = (0..=4)
        .map(|j| {
            let t = span * j as f64 / 4.0;
            let angle = speed * t as f32 / BEND_RADIUS_M;
            // Along +x, bending toward -z (its left), in the walker's own frame.
            let local = Vec3::new(angle.sin(), 0.0, angle.cos() - 1.0) * BEND_RADIUS_M;
            let mut p = position + turn * local;
            p.y = 0.0;
            crate::walk::WalkKey {
                time: start + t,
                position: p,
                heading: None,
            }
        })
        .collect();
    match crate::walk::WalkPath::new(keys) {
        Ok(path) => Instance::walking(path, time_offset),
        // A span too short to move: standing.
        Err(_) => Instance::standing(position, heading, time_offset),
    }
}

/// Seconds the host has waited on `device` so far (none on the CPU).
fn waited_on(device: &Device) -> f64 {
    match device {
        Device::Gpu(gpu) => gpu.waited().as_secs_f64(),
        Device::Cpu => 0.0,
    }
}

/// CPU seconds the threads that submitted to `device` or waited on it spent doing so
/// (none on the CPU).
fn device_cpu_on(device: &Device) -> f64 {
    match device {
        Device::Gpu(gpu) => gpu.submitted_and_waited_cpu().as_secs_f64(),
        Device::Cpu => 0.0,
    }
}

/// Seconds `device` has spent submitting so far (none on the CPU).
fn submitted_on(device: &Device) -> f64 {
    match device {
        Device::Gpu(gpu) => gpu.submitted().as_secs_f64(),
        Device::Cpu => 0.0,
    }
}

/// The device time of each pass since the last call (none on the CPU).
fn pass_times(device: &Device) -> Result<Vec<PassTime>> {
    Ok(match device {
        Device::Gpu(gpu) => gpu.pass_times()?,
        Device::Cpu => Vec::new(),
    })
}

/// Per pass (in the order first seen), the median over `frames` of its time per frame
/// (0 in a frame without it) and the mean count.
fn median_passes(frames: &[Vec<PassTime>]) -> Vec<PassTime> {
    let mut names: Vec<String> = Vec::new();
    for f in frames {
        for p in f {
            if !names.contains(&p.pass) {
                names.push(p.pass.clone());
            }
        }
    }
    names
        .into_iter()
        .map(|name| {
            let of = |f: &Vec<PassTime>| f.iter().find(|p| p.pass == name).cloned();
            let ms: Vec<f64> = frames.iter().map(|f| of(f).map_or(0.0, |p| p.ms)).collect();
            let count: usize = frames.iter().map(|f| of(f).map_or(0, |p| p.passes)).sum();
            let sum = |get: fn(&PassTime) -> usize| -> usize {
                frames.iter().map(|f| of(f).map_or(0, |p| get(&p))).sum()
            };
            let (dispatches, untimed) = (sum(|p| p.dispatches), sum(|p| p.untimed));
            PassTime {
                passes: count / frames.len().max(1),
                dispatches: dispatches / frames.len().max(1),
                untimed: untimed.div_ceil(frames.len().max(1)),
                ms: median(&ms),
                pass: name,
            }
        })
        .collect()
}

/// The median of `v` (NaN when empty).
fn median(v: &[f64]) -> f64 {
    frf_render::gpu::timing::median_min(v).0
}
