//! `frf bench interp`: the GPU interpolation benchmark ([`frf_render::gpu::bench`]) on a
//! field's pose or on the synthetic pose of the original's shape; `frf bench frame`:
//! what a crowd's frame costs by walkers and lighting ([`frf_scene::bench_frame`]). Each
//! prints a table, or JSON.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use frf_reflectance::FieldFile;
use frf_render::gpu::Gpu;
use frf_render::gpu::bench::{BenchOptions, DEFAULT_SIZES, all_formats, run};
use frf_render::gpu::formats::PoseFormats;
use frf_render::gpu::rebin::PassKind;
use frf_render::resident::{Lighting, PoseSource, ResidentPose};
use frf_render::synthetic::synthetic_pose;

use super::args::{LightingArgs, parse_size};
use crate::CliResult;
use frf_core::bars::{Bars, bar};
use frf_scene::Scene;
use frf_scene::bench_frame::{FrameBenchOptions, LightMode, Motion, Spacing, run_frame_bench};
use frf_scene::shot::ShotOptions;
use frf_scene::text::{Counts, parse_counts, parse_megapixels};

/// `frf bench ...`.
#[derive(Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: BenchCommand,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Time per frame of the floor pass and every interpolation, every storage format,
    /// fragment and compute, several sizes; the CPU reference in the same run.
    Interp(InterpArgs),
    /// Host, GPU and wall time per frame of a scene's first walker copied 1, 10, 40, 100
    /// times, under a constant and a turning light.
    Frame(FrameArgs),
}

/// Which lightings `frf bench frame` times.
#[derive(Clone, Copy, ValueEnum)]
enum LightArg {
    /// The scene's first lighting key, held.
    Constant,
    /// Turned 15 degrees a frame (`--turn-deg`).
    Turning,
    /// Both.
    Both,
}

/// Arguments of `frf bench frame`.
#[derive(Args)]
struct FrameArgs {
    /// The scene file.
    scene: PathBuf,
    /// The field (default: the one the scene names).
    #[arg(long)]
    field: Option<PathBuf>,
    /// Walker counts, comma-separated.
    #[arg(long, default_value = "1,10,40,100", value_parser = parse_counts)]
    walkers: Counts,
    /// Lightings timed.
    #[arg(long, value_enum, default_value = "both")]
    light: LightArg,
    /// Degrees a turning light turns a frame (a light turning less than the shots' light
    /// tolerance, 2°, relights each walker every few frames).
    #[arg(long, default_value_t = frf_scene::bench_frame::TURN_DEG_PER_FRAME)]
    turn_deg: f32,
    /// How far a walker's light may turn before its poses are relit, as `frf render
    /// --light-tolerance` (default: the renderer's; `0` relights every change).
    #[arg(long, value_parser = crate::cmd::args::parse_light_tolerance)]
    light_tolerance: Option<frf_scene::shot::LightTolerance>,
    /// Walkers standing, walking a bend (their own light changes every frame), or both.
    #[arg(long, value_enum, default_value = "standing")]
    motion: MotionArg,
    /// Frames counted per row (one more is drawn first, not counted).
    #[arg(long, default_value_t = 6)]
    frames: usize,
    /// How far apart the frames are: `held` (1 ms: every walker keeps its pose, only the
    /// light changes) or `shot` (the scene's frame interval: poses stream in as in a render).
    #[arg(long, value_enum, default_value = "held")]
    spacing: Spacing,
    /// Frame size, WxH (default: the scene's, else the field's).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Most memory the resident poses may hold together, MB.
    #[arg(long, default_value_t = 4096, value_parser = clap::value_parser!(u64).range(1..))]
    memory_budget: u64,
    /// Draw each frame and wait for it without reading its pixels back (a frame shown
    /// where it is drawn, as a viewer shows it): the wall time is then the frame's
    /// without the copy to the host and its conversion.
    #[arg(long)]
    no_readback: bool,
    /// Render on the CPU reference.
    #[arg(long)]
    cpu: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// `--motion`.
#[derive(Clone, Copy, ValueEnum)]
enum MotionArg {
    /// On their places of the grid.
    Standing,
    /// Along a bend from there.
    Walking,
    /// Both.
    Both,
}

/// Which storage formats to time.
#[derive(Clone, Copy, ValueEnum)]
enum FormatsArg {
    /// Every image and flow format.
    All,
    /// The renderer's default only.
    Default,
}

/// Which stages to time.
#[derive(Clone, Copy, ValueEnum)]
enum StagesArg {
    /// Fragment and compute.
    Both,
    /// Fragment only.
    Fragment,
    /// Compute only.
    Compute,
}

/// Arguments of `frf bench interp`.
#[derive(Args)]
struct InterpArgs {
    /// A field to take the pose from (default: a synthetic pose of the original's shape,
    /// 36 x 3 views of 320 x 448).
    #[arg(long)]
    field: Option<PathBuf>,
    /// The field's pose.
    #[arg(long, default_value_t = 0)]
    pose: u32,
    #[command(flatten)]
    lighting: LightingArgs,
    /// Frame sizes, WxH (repeatable; default 0.26, 1, 2 and 8 megapixels).
    #[arg(long = "size", value_parser = parse_size)]
    sizes: Vec<(u32, u32)>,
    /// Storage formats timed.
    #[arg(long, value_enum, default_value = "all")]
    formats: FormatsArg,
    /// Stages timed.
    #[arg(long, value_enum, default_value = "both")]
    stages: StagesArg,
    /// Passes run before timing each combination.
    #[arg(long, default_value_t = 3)]
    warmup: u32,
    /// Passes timed per combination.
    #[arg(long, default_value_t = 20)]
    repeats: u32,
    /// Frames the CPU reference renders per variant and size.
    #[arg(long, default_value_t = 3)]
    cpu_repeats: u32,
    /// The CPU reference renders sizes up to this many megapixels (0: none).
    #[arg(long, default_value_t = 2.1, allow_negative_numbers = true, value_parser = parse_megapixels)]
    cpu_max_mp: f64,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs `frf bench`.
pub fn run_bench(args: BenchArgs) -> CliResult {
    match args.what {
        BenchCommand::Interp(a) => interp(a),
        BenchCommand::Frame(a) => frame(a),
    }
}

fn frame(args: FrameArgs) -> CliResult {
    let (scene, field_path) = Scene::load_overridden(&args.scene, None, args.field.as_deref())?;
    let field = FieldFile::open(&field_path)?;
    frf_render::resident::check_renderable(&field)?;
    let h = field.header();
    let size = scene.frame_size(args.size, (h.width, h.height))?;
    let options = FrameBenchOptions {
        walkers: args.walkers.0,
        lights: match args.light {
            LightArg::Constant => vec![LightMode::Constant],
            LightArg::Turning => vec![LightMode::Turning],
            LightArg::Both => vec![LightMode::Constant, LightMode::Turning],
        },
        turn_deg: args.turn_deg,
        motions: match args.motion {
            MotionArg::Standing => vec![Motion::Standing],
            MotionArg::Walking => vec![Motion::Walking],
            MotionArg::Both => vec![Motion::Standing, Motion::Walking],
        },
        frames: args.frames,
        spacing: args.spacing,
        size,
        shot: ShotOptions {
            memory_budget: args.memory_budget.saturating_mul(1_000_000),
            planned: true,
            traced_lights: 256,
            detail: None,
            light_tolerance: args
                .light_tolerance
                .unwrap_or(frf_scene::shot::LightTolerance::DEFAULT),
            walker_shadows: true,
        },
        readback: !args.no_readback,
        cpu: args.cpu,
    };
    let report = run_frame_bench(&scene, &field, &options, &Bars::default())?;
    eprint!("{}", report.table());
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}

fn interp(args: InterpArgs) -> CliResult {
    let source = match &args.field {
        Some(path) => {
            let field = FieldFile::open(path)?;
            frf_render::resident::check_renderable(&field)?;
            let conditions = field.header().conditions.len();
            let lighting = match args.lighting.env {
                Some(_) => args.lighting.lighting(conditions)?.0,
                None => Lighting::Unlit,
            };
            // Its errors name the pose.
            PoseSource::load(&field, args.pose, &lighting)
                .map_err(crate::context::context(path.display().to_string()))?
        }
        None => synthetic_pose()?,
    };
    let pose = ResidentPose::relight_cpu(&source);
    if let Some((k, (w, h))) = frf_core::argument::given_twice(&args.sizes) {
        let allowed = format!("each size once (given again at place {k}; it was timed twice)");
        return Err(frf_core::BadArgument::new("--size", format!("{w}x{h}"), allowed).into());
    }
    let sizes = if args.sizes.is_empty() {
        DEFAULT_SIZES.to_vec()
    } else {
        args.sizes.clone()
    };
    let options = BenchOptions {
        sizes,
        formats: match args.formats {
            FormatsArg::All => all_formats(),
            FormatsArg::Default => vec![PoseFormats::DEFAULT],
        },
        stages: match args.stages {
            StagesArg::Both => PassKind::ALL.to_vec(),
            StagesArg::Fragment => vec![PassKind::Fragment],
            StagesArg::Compute => vec![PassKind::Compute],
        },
        warmup: args.warmup,
        repeats: args.repeats,
        cpu_repeats: args.cpu_repeats,
        cpu_max_pixels: (args.cpu_max_mp * 1e6) as u64,
    };
    options.check()?;
    let gpu = Gpu::new()?;
    let progress = bar("benchmark");
    let report = run(&gpu, &pose, &options, &mut |m| {
        progress.set_message(m.to_string())
    })?;
    progress.finish_and_clear();
    eprintln!("{}", report.table(args.field.is_some()));
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}
