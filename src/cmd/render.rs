//! `frf render FIELD --env ENV --camera PATH.toml|--orbit R,H[,SWEEP] --out DIR`: frames
//! of a pose of a field, relit by an environment, along a camera path, on the GPU (or the
//! CPU reference with `--cpu`). Each frame is written as an 8-bit sRGB PNG with straight
//! alpha and a linear premultiplied EXR, with a contact sheet of up to 12 frames over
//! gray (`contact.png`); a rerun with the same settings resumes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use frf_core::atomic::write_bytes_atomic;
use frf_core::contact;
use frf_core::image::{Image, RgbImage, Rgba};
use frf_core::io::{write_exr_rgb, write_exr_rgba, write_png8_srgb, write_png8_srgba};
use frf_reflectance::{FieldFile, FieldHeader};
use frf_render::cpu::FrameStats;
use frf_render::gpu::Gpu;
use frf_render::morph::Variant;
use frf_render::path::Trajectory;
use frf_render::renderer::Renderer;
use frf_render::renderer::SceneShadow;
use frf_render::resident::PoseSource;
use serde::Serialize;

use crate::CliResult;
use crate::cmd::args::{BackdropArgs, CameraArgs, LightingArgs, ShadowArg, VariantArg, parse_size};
use crate::cmd::progress::bar;

/// Makes `source` resident on the GPU, or for the CPU reference when `cpu`.
pub fn open_renderer(source: &PoseSource, cpu: bool) -> CliResult<Renderer> {
    let gpu = if cpu { None } else { Some(Gpu::new()?) };
    Ok(Renderer::new(source, gpu)?)
}

/// The requested pose, or the field's first.
pub fn pose_of(header: &FieldHeader, requested: Option<u32>, field: &Path) -> CliResult<u32> {
    let pose = requested
        .or_else(|| header.poses.first().map(|p| p.pose))
        .ok_or_else(|| format!("{}: the field holds no pose", field.display()))?;
    Ok(pose)
}

/// Arguments of `frf render`.
#[derive(Args, Serialize, PartialEq)]
pub struct RenderArgs {
    /// A field file (`frf ingest`, `frf stage field` or `frf ingest-ring`).
    pub field: PathBuf,
    #[command(flatten)]
    pub lighting: LightingArgs,
    #[command(flatten)]
    pub camera: CameraArgs,
    #[command(flatten)]
    pub scene: BackdropArgs,
    /// Output directory: frame_NNNN.png (8-bit sRGB, straight alpha) and frame_NNNN.exr
    /// (linear, premultiplied), and render.json (the settings and the report).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write each frame's layers for compositing tools: frame_NNNN_subject.exr
    /// (premultiplied RGBA), frame_NNNN_shadow.exr (relative irradiance of the ground, 1
    /// unshadowed) and frame_NNNN_backdrop.exr.
    #[arg(long)]
    pub layers: bool,
    /// Frame size `WxH` (default: the field's image size).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Number of frames along the path.
    #[arg(long, default_value_t = 36)]
    pub frames: usize,
    /// Pose of the field (default: its first).
    #[arg(long)]
    pub pose: Option<u32>,
    /// Interpolation.
    #[arg(long, value_enum, default_value = "fourway")]
    pub variant: VariantArg,
    /// Render with the CPU reference instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// Exposure of the PNG frames, stops (the EXR frames are not scaled).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Render every frame again even where the directory holds it.
    #[arg(long)]
    #[serde(skip)]
    pub overwrite: bool,
}

/// The report written to `render.json`.
#[derive(Serialize)]
struct Report<'a> {
    settings: &'a RenderArgs,
    device: String,
    pose: u32,
    crop: [u32; 4],
    lighting_skipped_conditions: Vec<String>,
    images_combined: usize,
    images_total: usize,
    resident_bytes: u64,
    resident_seconds: f64,
    frames_rendered: usize,
    frames_resumed: usize,
    seconds_per_frame_mean: f64,
    seconds_per_frame_median: f64,
    seconds_first_frame: f64,
    pixels_inside: usize,
    pixels_clamped_above: usize,
    pixels_clamped_below: usize,
    pixels_missed: usize,
}

/// Frames on the contact sheet (evenly spaced).
const SHEET_FRAMES: usize = 12;

/// Premultiplied RGBA over a mid-gray backdrop, for the contact sheet.
fn over_gray(img: &Image<Rgba>) -> RgbImage {
    let gray = 0.18;
    Image::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get(x, y);
        let a = p[3].clamp(0.0, 1.0);
        [0, 1, 2].map(|c| p[c] + (1.0 - a) * gray)
    })
}

fn frame_path(dir: &Path, i: usize, ext: &str) -> PathBuf {
    dir.join(format!("frame_{i:04}.{ext}"))
}

fn layer_path(dir: &Path, i: usize, layer: &str) -> PathBuf {
    dir.join(format!("frame_{i:04}_{layer}.exr"))
}

/// Runs `frf render`.
pub fn run(args: RenderArgs) -> CliResult {
    let field = FieldFile::open(&args.field)?;
    let h = field.header();
    let pose = pose_of(h, args.pose, &args.field)?;
    let (lighting, env) = args.lighting.lighting(h.conditions.len())?;
    let backdrop = args.scene.backdrop(env.as_ref())?;
    let (shadow_maps, traced) = args.scene.shadow(&field, pose, env.as_ref())?;
    let trajectory = args.camera.trajectory()?;
    let (width, height) = match args.scene.plate_size(&backdrop) {
        Some(size) => {
            if !matches!(&trajectory, Trajectory::Path(p) if p.keys.len() == 1) {
                return Err(
                    "--backdrop plate: the plate's camera is a --camera path of one key".into(),
                );
            }
            size
        }
        None => args.size.unwrap_or((h.width, h.height)),
    };
    let cameras = trajectory.cameras(args.frames, width, height)?;
    if !args.exposure.is_finite() || args.exposure.abs() > 30.0 {
        return Err(format!("--exposure {} stops is outside [-30, 30]", args.exposure).into());
    }

    // A directory of a different render is not resumed into.
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("output directory {}: {e}", args.out.display()))?;
    let settings_path = args.out.join("settings.json");
    let settings = serde_json::to_string_pretty(&args)?;
    let resume =
        !args.overwrite && std::fs::read_to_string(&settings_path).is_ok_and(|s| s == settings);
    if !resume && !args.overwrite && frame_path(&args.out, 0, "png").exists() {
        return Err(format!(
            "{} holds frames of a render with other settings; use --overwrite or another --out",
            args.out.display()
        )
        .into());
    }
    write_bytes_atomic(&settings_path, settings.as_bytes())?;

    let start = Instant::now();
    let source = PoseSource::load(&field, pose, &lighting)?;
    let mut renderer = open_renderer(&source, args.cpu)?;
    let had_maps = shadow_maps.is_some();
    let shadow = match (&shadow_maps, traced) {
        (Some(m), _) => SceneShadow::Maps(m),
        (None, Some(t)) => SceneShadow::Relit(t),
        (None, None) => SceneShadow::None,
    };
    renderer.set_scene(backdrop, shadow)?;
    let resident_seconds = start.elapsed().as_secs_f64();
    let c = source.geometry.crop;
    eprintln!(
        "{}: pose {pose}, {}x{} views, crop {}x{} at ({}, {}) of {}x{}",
        args.field.display(),
        h.columns,
        h.rows,
        c.width,
        c.height,
        c.x0,
        c.y0,
        h.width,
        h.height
    );
    let plan = &source.plan;
    eprintln!(
        "lighting: {} of {} basis images combined; conditions left out (zero weight): {}",
        plan.images_combined,
        plan.images_total,
        if plan.skipped_conditions.is_empty() {
            "none".to_string()
        } else {
            plan.skipped_conditions.join(", ")
        }
    );
    eprintln!(
        "{}: pose resident in {:.2} MB, loaded and relit in {resident_seconds:.2} s",
        renderer.device(),
        renderer.resident_bytes() as f64 / 1e6
    );
    eprintln!(
        "scene: backdrop {:?}, shadow {}",
        args.scene.backdrop,
        match (renderer.has_shadow(), args.scene.shadow) {
            (true, ShadowArg::Maps) => "relit from the pose's maps",
            (true, _) => "traced against the pose's visual hull",
            (false, ShadowArg::None) => "left out (--shadow none)",
            (false, _) if !had_maps => "none (the field holds no shadow maps)",
            (false, _) => "none (no environment to relight it with)",
        }
    );

    let scale = 2f32.powf(args.exposure);
    let variant = Variant::from(args.variant);
    let bar = bar("frames");
    bar.set_length(cameras.len() as u64);
    let mut times = Vec::new();
    let mut totals = FrameStats::default();
    let mut resumed = 0;
    let sheet_every = cameras.len().div_ceil(SHEET_FRAMES).max(1);
    let mut sheet = Vec::new();
    for (i, cam) in cameras.iter().enumerate() {
        let (png, exr) = (
            frame_path(&args.out, i, "png"),
            frame_path(&args.out, i, "exr"),
        );
        if resume && png.exists() && exr.exists() {
            resumed += 1;
            bar.inc(1);
            continue;
        }
        let t = Instant::now();
        let frame = renderer.render_frame(cam, variant, args.layers)?;
        times.push(t.elapsed().as_secs_f64());
        let (img, stats) = (frame.composite, frame.stats);
        totals.inside += stats.inside;
        totals.clamped_above += stats.clamped_above;
        totals.clamped_below += stats.clamped_below;
        totals.missed += stats.missed;
        if let Some(l) = &frame.layers {
            write_exr_rgba(&layer_path(&args.out, i, "subject"), &l.subject)?;
            write_exr_rgb(&layer_path(&args.out, i, "shadow"), &l.shadow)?;
            write_exr_rgba(&layer_path(&args.out, i, "backdrop"), &l.backdrop)?;
        }
        write_exr_rgba(&exr, &img)?;
        write_png8_srgba(&png, &img, scale)?;
        if i % sheet_every == 0 {
            sheet.push(over_gray(&img));
        }
        bar.inc(1);
    }
    bar.finish_and_clear();

    let mean = times.iter().sum::<f64>() / times.len().max(1) as f64;
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let report = Report {
        settings: &args,
        device: renderer.device().to_string(),
        pose,
        crop: [c.x0, c.y0, c.width, c.height],
        lighting_skipped_conditions: plan.skipped_conditions.clone(),
        images_combined: plan.images_combined,
        images_total: plan.images_total,
        resident_bytes: renderer.resident_bytes(),
        resident_seconds,
        frames_rendered: times.len(),
        frames_resumed: resumed,
        seconds_per_frame_mean: mean,
        seconds_per_frame_median: median,
        seconds_first_frame: times.first().copied().unwrap_or(0.0),
        pixels_inside: totals.inside,
        pixels_clamped_above: totals.clamped_above,
        pixels_clamped_below: totals.clamped_below,
        pixels_missed: totals.missed,
    };
    if !sheet.is_empty() {
        let columns = sheet.len().min(SHEET_FRAMES / 2);
        write_png8_srgb(
            &args.out.join("contact.png"),
            &contact::sheet(&sheet, columns),
            scale,
        )?;
    }
    write_bytes_atomic(
        &args.out.join("render.json"),
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )?;
    eprintln!(
        "{} frames of {width}x{height} ({}, {}) in {}: {median:.3} s/frame median, {mean:.3} \
         mean, first {:.3} (includes pipeline set-up){}",
        times.len(),
        variant.name(),
        args.env_name(),
        args.out.display(),
        report.seconds_first_frame,
        if resumed > 0 {
            format!("; {resumed} frames were already there (resumed)")
        } else {
            String::new()
        }
    );
    let all = (totals.inside + totals.clamped_above + totals.clamped_below + totals.missed).max(1);
    let pct = |n: usize| 100.0 * n as f64 / all as f64;
    eprintln!(
        "pixels: {:.1} % re-binned inside the grid, {:.1} % clamped to the top row (rays above \
         the grid), {:.1} % clamped to the bottom row, {:.1} % missed (no view; transparent)",
        pct(totals.inside),
        pct(totals.clamped_above),
        pct(totals.clamped_below),
        pct(totals.missed)
    );
    Ok(())
}

impl RenderArgs {
    fn env_name(&self) -> String {
        format!("env {}", self.lighting.env)
    }
}
