//! `frf stage`: renders a synthetic capture with the virtual light stage, and
//! `frf stage truth`: renders the ground-truth image of a capture's pose from any camera
//! under any HDR environment or basis combination.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, Subcommand};
use frf_core::env::EnvSource;
use frf_core::io::{write_exr_rgba, write_png8_srgba};
use frf_stage::truth::DEFAULT_ENVIRONMENT_LIGHTS;
use frf_stage::truth_shot::{TruthCamera, TruthLight, parse_basis};
use frf_stage::{Gait, Preset, SetFlowTruth, StageConfig};

use crate::CliResult;
use crate::cmd::args::{parse_env, parse_point, parse_size, poses_arg};
use frf_core::bars::bar;

/// Arguments of `frf stage`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct StageArgs {
    #[command(subcommand)]
    command: Option<StageCommand>,
    #[command(flatten)]
    capture: CaptureArgs,
}

#[derive(Subcommand)]
enum StageCommand {
    /// Render the true image and alpha of a pose from any camera under any lighting.
    Truth(TruthArgs),
    /// Build the oracle field of a capture from its ground truth (a perfect ingest).
    Field(crate::cmd::stage_field::FieldArgs),
    /// Error of relighting through the 26-condition basis, per environment.
    ProjectionError(crate::cmd::stage_field::ProjectionArgs),
    /// Compression ratio and relit PSNR of the basis images over JPEG quality.
    CodecCurve(crate::cmd::stage_field::CodecArgs),
}

#[derive(Args)]
struct CaptureArgs {
    /// Size preset: tiny (64x90, seconds), small (160x224, the demo), paper (320x448).
    #[arg(long, value_enum, default_value = "tiny")]
    preset: Preset,
    /// Output capture directory (created; a rerun with the same settings resumes).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed of the cycle-to-cycle perturbations and sensor noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Walking or running.
    #[arg(long, value_enum, default_value = "walk")]
    gait: Gait,
    /// Poses to render, e.g. `0,1` or `0..4` (default: the preset's).
    #[arg(long)]
    poses: Option<String>,
    /// Which true flows from T1 to the other slots of each set to write.
    #[arg(long, value_enum)]
    set_flow: Option<SetFlowTruth>,
    /// Film only the poses and views this scene file needs (with all its frames); with
    /// `--poses`, of those poses (a scene that morphs between poses draws its frames
    /// between the ones kept).
    #[arg(long = "for", value_name = "SCENE")]
    for_scene: Option<PathBuf>,
    /// Image size `WxH` instead of the preset's (the cameras keep their field of view).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Each basis condition is lit by an `N x N` grid of lights over its cell of the
    /// sphere (default: the preset's; fewer is faster, with harder shadows).
    #[arg(long)]
    lights_per_axis: Option<u32>,
    /// Render without sensor noise (quantization remains).
    #[arg(long)]
    no_noise: bool,
    /// Scale of the cycle-to-cycle perturbations of pose and position (1 = the documented
    /// amounts; 0 = every cycle repeats exactly, which isolates interpolation error).
    #[arg(long, default_value_t = 1.0)]
    perturbation: f32,
}

#[derive(Args)]
struct TruthArgs {
    /// A capture directory written by `frf stage`.
    #[arg(long)]
    capture: PathBuf,
    /// Pose to render (default: the capture's first).
    #[arg(long)]
    pose: Option<u32>,
    /// Render the walker at this instant of its cycle instead, seconds (pose `k` is at
    /// `k / 30` s; between two poses it is in between). `--view` still takes the camera of
    /// `--pose`.
    #[arg(long, allow_negative_numbers = true)]
    time: Option<f64>,
    /// Use the camera of capture view `U,V` (as seen from the subject).
    #[arg(long, conflicts_with_all = ["eye", "look_at"])]
    view: Option<String>,
    /// Virtual camera centre `x,y,z`, metres, subject frame.
    #[arg(long, requires = "look_at", value_parser = parse_point, allow_hyphen_values = true)]
    eye: Option<[f32; 3]>,
    /// Point the virtual camera looks at, `x,y,z`.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    look_at: Option<[f32; 3]>,
    /// Vertical field of view, degrees.
    #[arg(long, default_value_t = 27.5)]
    fov: f32,
    /// Output size `WxH` (default: the capture's).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// HDR environment (latitude-longitude .hdr or .exr), subject frame; `sky` for the
    /// built-in one, `uniform` for a white furnace.
    #[arg(long, conflicts_with = "basis", value_parser = parse_env)]
    env: Option<EnvSource>,
    /// Yaw of the environment, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::cmd::args::parse_turn)]
    yaw: f64,
    /// Median-cut lights the environment is reduced to.
    #[arg(long, default_value_t = DEFAULT_ENVIRONMENT_LIGHTS)]
    lights: usize,
    /// Basis weights `condition=weight,...` (e.g. `0=1,5=0.5`).
    #[arg(long)]
    basis: Option<String>,
    /// Turntable angle for basis lighting, degrees.
    #[arg(long, default_value_t = 0.0)]
    turntable: f32,
    /// Output: `.exr` (linear premultiplied RGBA) or `.png` (8-bit sRGB with alpha).
    #[arg(long)]
    out: PathBuf,
    /// Exposure multiplier for PNG output.
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
}

/// Runs `frf stage`.
pub fn run(args: StageArgs) -> CliResult {
    match args.command {
        Some(StageCommand::Truth(t)) => truth(t),
        Some(StageCommand::Field(a)) => crate::cmd::stage_field::field(a),
        Some(StageCommand::ProjectionError(a)) => crate::cmd::stage_field::projection(a),
        Some(StageCommand::CodecCurve(a)) => crate::cmd::stage_field::codec(a),
        None => capture(args.capture),
    }
}

fn capture(args: CaptureArgs) -> CliResult {
    let out = args.out.ok_or("frf stage: --out DIR is required")?;
    let mut config = StageConfig::preset(args.preset);
    config.seed = args.seed;
    config.gait = args.gait;
    if let Some(p) = &args.poses {
        config.poses = poses_arg("--poses", p)?;
    }
    if let Some(s) = args.set_flow {
        config.set_flow_truth = s;
    }
    config.noise = !args.no_noise;
    if let Some((w, h)) = args.size {
        (config.width, config.height) = (w, h);
    }
    if let Some(n) = args.lights_per_axis {
        config.lights_per_axis = n;
    }
    if let Some(scene) = &args.for_scene {
        // Plan on every pose of the cycle (or on the poses `--poses` keeps: a scene that
        // morphs between poses then draws its frames between those), then film what the
        // plan keeps.
        let mut all = config.clone();
        if args.poses.is_none() {
            all.poses = (0..all.poses_per_cycle()).collect();
        }
        let stage = frf_stage::Stage::new(all)?;
        let capture = frf_core::capture::Capture::from_manifest(&out, stage.manifest())?;
        let plan = crate::cmd::for_scene::plan(scene, &capture, None)?;
        println!("{}", plan.summary());
        config.poses = plan.poses.iter().map(|p| p.pose).collect();
        config.filmed = plan.filmed(stage.cameras().len());
    }
    config.perturbation = args.perturbation;
    let stage = frf_stage::Stage::new(config)?;
    let bar = bar("stage: views rendered");
    let report = frf_stage::write_capture(&stage, &out, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    println!("{}", report.describe(&stage, &out));
    Ok(())
}

fn truth(args: TruthArgs) -> CliResult {
    let stage = frf_stage::open_stage(&args.capture)?;
    let config = stage.config();
    let pose = args.pose.unwrap_or(config.poses[0]);
    if pose >= config.poses_per_cycle() {
        let allowed = format!("a pose of the cycle's {}", config.poses_per_cycle());
        return Err(frf_core::BadArgument::new("--pose", pose, allowed).into());
    }
    let camera = match (&args.view, args.eye) {
        (Some(view), _) => {
            let (u, v) = view
                .split_once(',')
                .and_then(|(u, v)| Some((u.trim().parse().ok()?, v.trim().parse().ok()?)))
                .ok_or_else(|| format!("--view {view:?}: expected U,V"))?;
            TruthCamera::View(u, v)
        }
        (None, Some(eye)) => TruthCamera::Eye {
            eye,
            look_at: args.look_at.unwrap_or([0.0, 0.9, 0.0]),
            fov_deg: args.fov,
            size: args.size.unwrap_or((config.width, config.height)),
        },
        (None, None) => return Err("give --view U,V or --eye and --look-at".into()),
    };
    let light = match (&args.env, &args.basis) {
        (Some(source), _) => TruthLight::Environment {
            env: source
                .load_required("a truth image needs lighting, or --basis")?
                .rotated(frf_core::light::turn_radians(args.yaw)),
            name: source.to_string(),
            lights: args.lights,
        },
        (None, Some(spec)) => TruthLight::Basis {
            weights: parse_basis(spec, stage.basis().len())?,
            turntable_deg: args.turntable,
        },
        (None, None) => return Err("give --env FILE or --basis c=w,...".into()),
    };
    let start = Instant::now();
    let shot = stage.truth_shot(pose, camera, &light, args.time)?;
    let is_exr = args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_exr {
        write_exr_rgba(&args.out, &shot.rgba)?;
    } else {
        write_png8_srgba(&args.out, &shot.rgba, args.exposure)?;
    }
    let c = &shot.camera;
    println!(
        "truth image of pose {pose}, {}x{}, under {} ({} lights): {}",
        c.width,
        c.height,
        shot.what,
        shot.lights,
        args.out.display()
    );
    println!("subject coverage (mean alpha): {:.3}", shot.coverage);
    println!("render time: {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}
