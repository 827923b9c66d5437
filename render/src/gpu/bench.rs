//! The GPU interpolation benchmark (`frf bench interp`): one pose, one camera between
//! views, frames of several sizes, and per size the time of a floor pass (one texel
//! fetch and one write per pixel: the least any frame pass can cost on the device) and of
//! the nearest-view, linear-blend, two-way and four-way passes, for every storage format
//! of the pose ([`super::formats`]) and as fragment and compute passes ([`PassKind`]); the
//! CPU reference renders the same frames in the same run. Each GPU combination's frame is
//! compared with the CPU reference's at the first size: a combination is correct when it
//! stays within [`CORRECT_MAX_ABS`] of it.

use frf_core::image::{Image, Rgba};
use serde::Serialize;

use super::Gpu;
use super::bind::{compute_pipeline, full_screen_pipeline};
use super::formats::{FlowFormat, ImageFormat, PoseFormats};
use super::pose::GpuPose;
use super::rebin::{PassKind, Place, RebinPass, SubjectTargets, frame_uniform, workgroups};
use super::timing::{Timestamps, median_min};
use crate::cpu::render_cpu;
use crate::error::Result;
use crate::morph::Variant;
use crate::resident::ResidentPose;
use crate::synthetic::bench_camera;

/// The largest difference from the CPU reference (premultiplied linear RGBA, at the
/// pose's scale) of a combination called correct: the exact twins measure ~1e-6; the
/// hardware's 8-bit filter weights and half-float flows stay near 1e-2 on sharp edges.
pub const CORRECT_MAX_ABS: f64 = 2e-2;

/// The variants timed, after the floor: the renderer's four-way morph last, E06's
/// beside it.
pub const VARIANTS: [Variant; 5] = [
    Variant::Nearest,
    Variant::Linear,
    Variant::TwoWay,
    Variant::FourWayE06,
    Variant::FourWay,
];

/// What to measure.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Frame sizes.
    pub sizes: Vec<(u32, u32)>,
    /// Storage formats.
    pub formats: Vec<PoseFormats>,
    /// Fragment and/or compute.
    pub stages: Vec<PassKind>,
    /// Passes run before timing.
    pub warmup: u32,
    /// Passes timed.
    pub repeats: u32,
    /// Frames the CPU reference renders per variant and size.
    pub cpu_repeats: u32,
    /// The CPU reference renders sizes up to this many pixels.
    pub cpu_max_pixels: u64,
}

/// One GPU measurement.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    /// `floor`, `nearest`, `linear`, `twoway` or `fourway`.
    pub variant: String,
    /// `codes8`, `f16` or `f32`.
    pub flow_format: String,
    /// `codes` or `srgb8`.
    pub image_format: String,
    /// `fragment` or `compute`.
    pub stage: String,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Median time of the pass, ms.
    pub ms_median: f64,
    /// Least time of the pass, ms.
    pub ms_min: f64,
    /// Median against the floor pass's median at the same size and stage.
    pub vs_floor: f64,
    /// Nanoseconds a pixel (median).
    pub ns_per_pixel: f64,
    /// Largest difference from the CPU reference's frame at the first size (`None` for
    /// the floor and at other sizes).
    pub max_abs_vs_cpu: Option<f64>,
}

/// One CPU reference measurement.
#[derive(Debug, Clone, Serialize)]
pub struct CpuRow {
    /// Variant.
    pub variant: String,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Median time of a frame, ms.
    pub ms_median: f64,
    /// Least time of a frame, ms.
    pub ms_min: f64,
    /// Threads of the CPU reference.
    pub threads: usize,
}

/// Bytes a pose holds on the GPU in one storage choice.
#[derive(Debug, Clone, Serialize)]
pub struct PoseBytes {
    /// `image/flow`.
    pub formats: String,
    /// Bytes.
    pub bytes: u64,
}

/// The floor pass's achieved memory bandwidth at one size.
#[derive(Debug, Clone, Serialize)]
pub struct FloorBandwidth {
    /// Fragment or compute.
    pub stage: String,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Bytes read and written a frame (4 read, 16 written a pixel) over its median time,
    /// GB/s.
    pub gb_per_s: f64,
}

/// Everything measured.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// The adapter, in words.
    pub adapter: String,
    /// Its backend.
    pub backend: String,
    /// Its driver, as the adapter says.
    pub driver: String,
    /// How passes were timed: `gpu-timestamps` or `fenced-wall`.
    pub clock: String,
    /// GPU rows.
    pub rows: Vec<BenchRow>,
    /// CPU reference rows.
    pub cpu_rows: Vec<CpuRow>,
    /// Bytes of the pose in the default storage.
    pub bytes_per_pose: u64,
    /// Bytes of the pose in each storage measured.
    pub bytes_per_pose_by_format: Vec<PoseBytes>,
    /// The floor pass's bandwidth per size.
    pub floor_bandwidth: Vec<FloorBandwidth>,
    /// The fastest correct four-way combination at the largest size: `image/flow stage`.
    pub fastest_correct_fourway: Option<String>,
}

/// The frame sizes measured by default: 640x400 to 4K.
pub const DEFAULT_SIZES: [(u32, u32); 4] = [(640, 400), (1280, 800), (1920, 1080), (3840, 2160)];

impl BenchOptions {
    /// Refuses sizes outside 1 to 16384 pixels a side (`--size`) and no repeat
    /// (`--repeats`).
    pub fn check(&self) -> Result<()> {
        let bad = |&(w, h): &(u32, u32)| w == 0 || h == 0 || w > 16384 || h > 16384;
        if let Some(&(w, h)) = self.sizes.iter().find(|s| bad(s)) {
            let size = format!("{w}x{h}");
            return Err(
                frf_core::BadArgument::new("--size", size, "1 to 16384 pixels a side").into(),
            );
        }
        if self.repeats == 0 {
            return Err(frf_core::BadArgument::new("--repeats", 0, "at least 1").into());
        }
        Ok(())
    }
}

/// The floor pass's pipelines (`shaders/floor.wgsl`).
struct FloorPass {
    layout: wgpu::BindGroupLayout,
    fragment: wgpu::RenderPipeline,
    compute: wgpu::ComputePipeline,
}

impl FloorPass {
    fn new(device: &wgpu::Device, rebin: &RebinPass) -> Self {
        let module = super::shaders::module(device, "floor", super::shaders::FLOOR);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("floor"),
            entries: &[super::bind::storage::<u32>(
                0,
                true,
                wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            )],
        });
        let fragment = full_screen_pipeline(
            device,
            "floor",
            &[&rebin.frame_layout, &layout],
            &module,
            "fs_floor",
            1,
        );
        let compute = compute_pipeline(
            device,
            "floor",
            &[&rebin.compute_layout, &layout],
            &module,
            "cs_floor",
        );
        Self {
            layout,
            fragment,
            compute,
        }
    }
}

/// Bytes of `pose` stored as `formats`.
fn pose_bytes(pose: &ResidentPose, formats: PoseFormats) -> u64 {
    let g = &pose.geometry;
    let texels = g.crop.texels() as u64;
    let codes = g.resident_bytes();
    let flows = texels * g.flow_layer_count.max(1) as u64;
    codes - 2 * flows + formats.flow.texel_bytes() * flows
}

/// Runs the benchmark on `gpu` with `pose` (relit on the CPU; uploaded in every format).
pub fn run(
    gpu: &Gpu,
    pose: &ResidentPose,
    options: &BenchOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<BenchReport> {
    let info = gpu.adapter_report();
    // The CPU reference first: its frames at the first size are the yardstick.
    let (cpu_rows, reference) = cpu_reference(pose, options, progress)?;
    let (mut rows, floor_bandwidth) = floor_rows(gpu, pose, options, progress)?;
    let largest = options
        .sizes
        .iter()
        .copied()
        .max_by_key(|s| u64::from(s.0) * u64::from(s.1));
    let mut fastest: Option<(f64, String)> = None;
    for &formats in &options.formats {
        let pass = RebinPass::new(&gpu.device, formats);
        let gpu_pose = gpu.upload_resident(pose, &pass.pose)?;
        for &size in &options.sizes {
            let camera = bench_camera(size)?;
            let targets = SubjectTargets::new(&gpu.device, &pass, size, 1, 1);
            let drawn = Drawn {
                gpu,
                pass: &pass,
                targets: &targets,
                pose: &gpu_pose,
                size,
            };
            for &stage in &options.stages {
                let floor_ms = rows
                    .iter()
                    .find(|r| {
                        r.variant == "floor"
                            && r.stage == stage.name()
                            && (r.width, r.height) == size
                    })
                    .map_or(f64::NAN, |r| r.ms_median);
                for v in VARIANTS {
                    progress(&format!(
                        "{} {} {} {}x{}",
                        v.name(),
                        formats.name(),
                        stage.name(),
                        size.0,
                        size.1
                    ));
                    targets.write_frames(&gpu.queue, &[frame_uniform(Some(&gpu_pose), &camera, v)]);
                    let times = gpu.time_passes(options.warmup, options.repeats, &mut |e, t| {
                        drawn.record(e, (stage, v), t)
                    })?;
                    let timing = median_min(&times);
                    let error = match reference.iter().find(|(rv, _)| *rv == v) {
                        Some((_, cpu)) if Some(size) == options.sizes.first().copied() => {
                            Some(drawn.max_abs_error((stage, v), cpu)?)
                        }
                        _ => None,
                    };
                    let r = row(v.name(), formats, stage, size, timing, floor_ms, error);
                    if v == Variant::FourWay && Some(size) == largest {
                        let correct = rows
                            .iter()
                            .chain(std::iter::once(&r))
                            .filter(|x| {
                                x.variant == "fourway"
                                    && x.image_format == formats.image.name()
                                    && x.flow_format == formats.flow.name()
                                    && x.stage == stage.name()
                            })
                            .all(|x| x.max_abs_vs_cpu.is_none_or(|e| e <= CORRECT_MAX_ABS));
                        let name = format!("{} {}", formats.name(), stage.name());
                        if correct && fastest.as_ref().is_none_or(|(t, _)| r.ms_median < *t) {
                            fastest = Some((r.ms_median, name));
                        }
                    }
                    rows.push(r);
                }
            }
        }
    }
    Ok(BenchReport {
        adapter: info.name.clone(),
        backend: info.backend.clone(),
        driver: info.driver.clone().trim().to_string(),
        clock: gpu.clock().name().to_string(),
        rows,
        cpu_rows,
        bytes_per_pose: pose_bytes(pose, PoseFormats::DEFAULT),
        bytes_per_pose_by_format: options
            .formats
            .iter()
            .map(|&f| PoseBytes {
                formats: f.name(),
                bytes: pose_bytes(pose, f),
            })
            .collect(),
        floor_bandwidth,
        fastest_correct_fourway: fastest.map(|f| f.1),
    })
}

/// A variant's frame drawn by the CPU reference.
type ReferenceFrame = (Variant, Image<Rgba>);

/// The CPU reference's rows at every size of at most `options.cpu_max_pixels`, and its
/// frames at the first size (the yardstick of the GPU's error), per variant.
fn cpu_reference(
    pose: &ResidentPose,
    options: &BenchOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<CpuRow>, Vec<ReferenceFrame>)> {
    let first_size = options.sizes.first().copied();
    let mut cpu_rows = Vec::new();
    let mut reference = Vec::new();
    for &size in &options.sizes {
        if u64::from(size.0) * u64::from(size.1) > options.cpu_max_pixels {
            continue;
        }
        let camera = bench_camera(size)?;
        for v in VARIANTS {
            progress(&format!("CPU reference {} {}x{}", v.name(), size.0, size.1));
            let mut times = Vec::new();
            let mut frame = None;
            for _ in 0..options.cpu_repeats.max(1) {
                let start = std::time::Instant::now();
                let (img, _) = render_cpu(pose, &camera, v);
                times.push(start.elapsed().as_secs_f64() * 1e3);
                frame = Some(img);
            }
            let (ms_median, ms_min) = median_min(&times);
            cpu_rows.push(CpuRow {
                variant: v.name().to_string(),
                width: size.0,
                height: size.1,
                ms_median,
                ms_min,
                threads: rayon::current_num_threads(),
            });
            if Some(size) == first_size
                && let Some(f) = frame
            {
                reference.push((v, f));
            }
        }
    }
    Ok((cpu_rows, reference))
}

/// The floor's rows (once per size and stage, on the codes' texture) and its bandwidth.
fn floor_rows(
    gpu: &Gpu,
    pose: &ResidentPose,
    options: &BenchOptions,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<BenchRow>, Vec<FloorBandwidth>)> {
    let mut rows = Vec::new();
    let mut floor_bandwidth = Vec::new();
    let codes_pass = RebinPass::new(&gpu.device, PoseFormats::DEFAULT);
    let codes_pose = gpu.upload_resident(pose, &codes_pass.pose)?;
    let floor = FloorPass::new(&gpu.device, &codes_pass);
    let floor_group = floor_bind_group(gpu, &floor, &codes_pose)?;
    for &size in &options.sizes {
        let camera = bench_camera(size)?;
        let targets = SubjectTargets::new(&gpu.device, &codes_pass, size, 1, 1);
        targets.write_frames(
            &gpu.queue,
            &[frame_uniform(Some(&codes_pose), &camera, Variant::Nearest)],
        );
        for &stage in &options.stages {
            progress(&format!("floor {} {}x{}", stage.name(), size.0, size.1));
            let times = gpu.time_passes(options.warmup, options.repeats, &mut |e, t| {
                record_floor(&floor, &targets, &floor_group, stage, size, e, t)
            })?;
            let (median, min) = median_min(&times);
            let pixels = f64::from(size.0) * f64::from(size.1);
            floor_bandwidth.push(FloorBandwidth {
                stage: stage.name().to_string(),
                width: size.0,
                height: size.1,
                gb_per_s: pixels * 20.0 / (median * 1e-3) / 1e9,
            });
            rows.push(row(
                "floor",
                PoseFormats::DEFAULT,
                stage,
                size,
                (median, min),
                median,
                None,
            ));
        }
    }
    Ok((rows, floor_bandwidth))
}

/// One frame pass drawn whole into its targets: a resident pose at a size.
struct Drawn<'a> {
    gpu: &'a Gpu,
    pass: &'a RebinPass,
    targets: &'a SubjectTargets,
    pose: &'a GpuPose,
    size: (u32, u32),
}

impl Drawn<'_> {
    /// Records the frame pass as `stage` into `encoder`, timed by `timestamps`.
    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (stage, variant): (PassKind, Variant),
        timestamps: Timestamps,
    ) {
        let whole = crate::footprint::PixelBox::whole(self.size.0, self.size.1);
        self.pass.record(
            encoder,
            self.targets,
            (0, Place::FRAME),
            &self.pose.bind_group,
            (stage, variant),
            whole,
            timestamps,
            false,
        )
    }

    /// The largest absolute difference of any channel of the frame drawn as `stage` from
    /// the CPU reference's `cpu`.
    fn max_abs_error(
        &self,
        (stage, variant): (PassKind, Variant),
        cpu: &Image<Rgba>,
    ) -> Result<f64> {
        let gpu = self.gpu;
        let mut e = gpu.device.create_command_encoder(&Default::default());
        self.record(&mut e, (stage, variant), None);
        let copied = gpu.copy_rgba(&mut e, self.targets.texture(), self.size);
        gpu.submit([e.finish()]);
        let img = gpu.read_rgba(&copied)?;
        Ok(img
            .pixels()
            .iter()
            .zip(cpu.pixels())
            .flat_map(|(a, b)| (0..4).map(move |k| f64::from((a[k] - b[k]).abs())))
            .fold(0.0, f64::max))
    }
}

impl BenchReport {
    /// The report as a table for a person (`field`: the pose came from a field, else it
    /// is the synthetic one).
    pub fn table(&self, field: bool) -> String {
        let r = self;
        let mut lines = Vec::new();

        lines.push(format!(
            "{} ({}, {}; timed by {}); pose: {}, {:.1} MB resident as codes/codes8",
            r.adapter,
            r.backend,
            r.driver,
            r.clock,
            if field {
                "the field's"
            } else {
                "synthetic, 36 x 3 views of 320 x 448"
            },
            r.bytes_per_pose as f64 / 1e6
        ));
        lines.push(format!(
            "{:<8} {:<7} {:<7} {:<8} {:>10} {:>10} {:>10} {:>9} {:>8} {:>11}",
            "variant",
            "image",
            "flow",
            "stage",
            "size",
            "median ms",
            "min ms",
            "x floor",
            "ns/px",
            "max |Δ| cpu"
        ));
        for x in &r.rows {
            lines.push(format!(
                "{:<8} {:<7} {:<7} {:<8} {:>10} {:>10.4} {:>10.4} {:>9.2} {:>8.2} {:>11}",
                x.variant,
                x.image_format,
                x.flow_format,
                x.stage,
                format!("{}x{}", x.width, x.height),
                x.ms_median,
                x.ms_min,
                x.vs_floor,
                x.ns_per_pixel,
                x.max_abs_vs_cpu
                    .map_or("".to_string(), |e| format!("{e:.2e}"))
            ));
        }
        for x in &r.cpu_rows {
            lines.push(format!(
                "CPU reference ({} threads) {:<8} {}x{}: {:.2} ms median, {:.2} ms min",
                x.threads, x.variant, x.width, x.height, x.ms_median, x.ms_min
            ));
        }
        for b in &r.floor_bandwidth {
            lines.push(format!(
                "floor {} {}x{}: {:.1} GB/s achieved (4 B read + 16 B written a pixel)",
                b.stage, b.width, b.height, b.gb_per_s
            ));
        }
        if let Some(f) = &r.fastest_correct_fourway {
            lines.push(format!("fastest correct four-way at the largest size: {f}"));
        }
        lines.join("\n")
    }
}

fn row(
    variant: &str,
    formats: PoseFormats,
    stage: PassKind,
    size: (u32, u32),
    (ms_median, ms_min): (f64, f64),
    floor_ms: f64,
    max_abs_vs_cpu: Option<f64>,
) -> BenchRow {
    BenchRow {
        variant: variant.to_string(),
        flow_format: formats.flow.name().to_string(),
        image_format: formats.image.name().to_string(),
        stage: stage.name().to_string(),
        width: size.0,
        height: size.1,
        ms_median,
        ms_min,
        vs_floor: ms_median / floor_ms,
        ns_per_pixel: ms_median * 1e6 / (f64::from(size.0) * f64::from(size.1)),
        max_abs_vs_cpu,
    }
}

fn floor_bind_group(gpu: &Gpu, floor: &FloorPass, pose: &GpuPose) -> Result<wgpu::BindGroup> {
    let range = pose.prelit_range().ok_or_else(|| {
        crate::RenderError::Misuse("the floor pass reads pre-lit codes, not a texture".into())
    })?;
    Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("floor"),
        layout: &floor.layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: range.page().as_entire_binding(),
        }],
    }))
}

fn record_floor(
    floor: &FloorPass,
    targets: &SubjectTargets,
    group: &wgpu::BindGroup,
    stage: PassKind,
    size: (u32, u32),
    encoder: &mut wgpu::CommandEncoder,
    timestamps: Timestamps,
) {
    match stage {
        PassKind::Fragment => {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("floor"),
                color_attachments: &[super::bind::loaded(targets.page_view(0))],
                depth_stencil_attachment: None,
                timestamp_writes: super::timing::render_pass_writes(timestamps),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&floor.fragment);
            pass.set_bind_group(0, targets.fragment_group(0), &[]);
            pass.set_bind_group(1, group, &[]);
            pass.draw(0..3, 0..1);
        }
        PassKind::Compute => {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("floor"),
                timestamp_writes: super::timing::compute_pass_writes(timestamps),
            });
            pass.set_pipeline(&floor.compute);
            pass.set_bind_group(0, targets.compute_group(0), &[]);
            pass.set_bind_group(1, group, &[]);
            let (x, y) = workgroups(size);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

/// Every storage combination.
pub fn all_formats() -> Vec<PoseFormats> {
    ImageFormat::ALL
        .iter()
        .flat_map(|&image| FlowFormat::ALL.map(|flow| PoseFormats { image, flow }))
        .collect()
}
