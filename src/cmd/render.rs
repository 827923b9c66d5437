//! `frf render INPUT`: frames of walkers relit by an environment, along a camera path,
//! shadowed and composited, on the GPU (or the CPU reference with `--cpu`).
//!
//! INPUT is a scene file (`SCENE.toml`, [`frf_scene`]; flags override it, e.g.
//! `--field F` renders the same scene from another field) or a field file with the scene
//! given by flags (one walker frozen in `--pose`, `--env`, `--orbit` or `--camera`).
//! Either way a plan of what the frames need is made first ([`frf_scene::plan`];
//! `--plan [--json]` prints it and stops, `--explain` measures what it saves), and only
//! that is read, relit and drawn (`--no-plan`: everything). Frames are written as 8-bit
//! sRGB PNG (straight alpha) and linear premultiplied EXR, with EXR layers on request, a
//! contact sheet, an animated preview and `render.json`; `--frames A..B` renders part of
//! a shot (for a farm), and a rerun resumes (`frf_scene::output`).

use std::path::PathBuf;

use clap::Args;
use frf_core::env::EnvSource;
use frf_reflectance::{FieldFile, FieldHeader};
use frf_render::composite::GroundLook;
use frf_scene::explain::explain;
use frf_scene::path::Trajectory;
use frf_scene::plan::{Plan, ShotFrame, frame_range};
use frf_scene::render_shot::{ShotJob, render_to_dir};
use frf_scene::settings::{FlagFiles, RenderSettings};
use frf_scene::shot::ShotOptions;
use frf_scene::{BackdropSpec, FieldLook, Scene, ShadowSpec};
use serde::Serialize;

use crate::CliResult;
use crate::cmd::args::{
    BackdropArg, BackdropArgs, CameraArgs, GroundArg, LightingArgs, ShadowArg, VariantArg,
    parse_size,
};
use frf_core::bars::Bars;

/// Frames along a path of a field render, by default.
const DEFAULT_FRAMES: usize = 36;
/// Memory the resident poses may hold by default, MB.
const DEFAULT_BUDGET_MB: u64 = 4096;

/// Arguments of `frf render`.
#[derive(Args, Serialize, PartialEq)]
pub struct RenderArgs {
    /// A scene file (`.toml`) or a field file (`frf ingest`, `frf stage field`, `frf
    /// ingest-ring`).
    #[serde(serialize_with = "crate::cmd::args::path_text")]
    pub input: PathBuf,
    /// The field (overrides the scene's).
    #[arg(long)]
    #[serde(serialize_with = "crate::cmd::args::opt_path_text")]
    pub field: Option<PathBuf>,
    #[command(flatten)]
    pub lighting: LightingArgs,
    #[command(flatten)]
    pub camera: CameraArgs,
    #[command(flatten)]
    pub scene: BackdropArgs,
    /// Output directory: frame_NNNN.png (8-bit sRGB, straight alpha), frame_NNNN.exr
    /// (linear, premultiplied), contact.png, the animated preview and render.json.
    #[arg(long)]
    #[serde(serialize_with = "crate::cmd::args::opt_path_text")]
    pub out: Option<PathBuf>,
    /// Also write each frame's layers for compositing tools: frame_NNNN_subject.exr
    /// (premultiplied RGBA), frame_NNNN_shadow.exr (relative irradiance of the ground, 1
    /// unshadowed) and frame_NNNN_backdrop.exr.
    #[arg(long)]
    pub layers: bool,
    /// Frame size `WxH` (default: the scene's, else the field's image size).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Frames: `N` (the first N; along a field's path, N frames), or `A..B` (frames A to
    /// B − 1 of a scene, e.g. one task of a farm job).
    #[arg(long)]
    pub frames: Option<String>,
    /// Pose of a field render (default: its first).
    #[arg(long)]
    pub pose: Option<u32>,
    /// Interpolation (default: the scene's, else four-way).
    #[arg(long, value_enum)]
    pub variant: Option<VariantArg>,
    /// Render with the CPU reference instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// Exposure of the PNG frames and previews, stops (default: the scene's, else 0).
    #[arg(long, allow_negative_numbers = true)]
    pub exposure: Option<f32>,
    /// Render every frame again even where the directory holds it.
    #[arg(long)]
    #[serde(skip)]
    pub overwrite: bool,
    /// Print the plan (what the frames need from the field, and what it leaves out) and
    /// stop.
    #[arg(long)]
    #[serde(skip)]
    pub plan: bool,
    /// With `--plan`: as JSON.
    #[arg(long)]
    #[serde(skip)]
    pub json: bool,
    /// Print the plan for a person, with what each saving is worth in seconds, measured
    /// by loading a pose with and without it, and stop.
    #[arg(long)]
    #[serde(skip)]
    pub explain: bool,
    /// Read, relight and draw everything of the poses drawn, not only what the plan says.
    #[arg(long)]
    pub no_plan: bool,
    /// Draw every walker at this level of detail (0: full; each level halves the
    /// captured views' resolution). By default each walker's is chosen from its size in
    /// the frame (full detail with --no-plan).
    #[arg(long, value_parser = clap::value_parser!(u8).range(0..=frf_render::detail::MAX_LEVEL as i64))]
    pub detail: Option<u8>,
    /// Most memory the resident poses may hold together, MB (the least recently used
    /// leave first).
    #[arg(long, default_value_t = DEFAULT_BUDGET_MB, value_parser = clap::value_parser!(u64).range(1..))]
    pub memory_budget: u64,
    /// How far a walker's own light (its heading relative to the light's yaw, degrees;
    /// the probes' weights where it stands) may move before its poses are relit: `DEG` or
    /// `DEG,WEIGHT` (default: the renderer's, `frf_scene::shot::LightTolerance::DEFAULT`;
    /// `0` relights every change).
    #[arg(long, value_parser = crate::cmd::args::parse_light_tolerance)]
    #[serde(skip)]
    pub light_tolerance: Option<frf_scene::shot::LightTolerance>,
    /// Walkers standing between another and a sun do not shade it (an ablation).
    #[arg(long)]
    pub no_walker_shadows: bool,
}

/// The scene a field render's flags describe: one walker frozen in `pose`.
fn scene_of_flags(args: &RenderArgs, h: &FieldHeader, pose: u32) -> CliResult<Scene> {
    let source = args.lighting.source()?.clone();
    let backdrop = match args.scene.backdrop {
        BackdropArg::None => BackdropSpec::None,
        BackdropArg::Env => BackdropSpec::Environment(match args.scene.ground {
            GroundArg::Env => GroundLook::Environment,
            GroundArg::Albedo(a) => GroundLook::Albedo(a),
        }),
        BackdropArg::Plate => BackdropSpec::Plate(
            args.scene
                .plate
                .clone()
                .ok_or("--backdrop plate needs --plate IMAGE")?,
        ),
    };
    if matches!(backdrop, BackdropSpec::Environment(_)) && source == EnvSource::None {
        return Err("--backdrop env needs an environment (--env FILE|sky|uniform)".into());
    }
    let trajectory = args.camera.trajectory()?;
    if matches!(backdrop, BackdropSpec::Plate(_))
        && !matches!(&trajectory, Trajectory::Path(p) if p.keys.len() == 1)
    {
        return Err("--backdrop plate: the plate's camera is a --camera path of one key".into());
    }
    let look = FieldLook {
        env: source,
        yaw_deg: args.lighting.yaw,
        sun: args.lighting.sun()?,
        floor: args.lighting.floor.into(),
        camera: trajectory,
        backdrop,
        shadow: match args.scene.shadow {
            ShadowArg::Maps => ShadowSpec::Maps,
            ShadowArg::Traced => ShadowSpec::Traced,
            ShadowArg::None => ShadowSpec::None,
        },
    };
    Ok(Scene::of_field(&args.input, h, pose, look))
}

/// The scene of the arguments: the file with its overrides, or the flags.
fn scene_of(args: &RenderArgs) -> CliResult<(Scene, PathBuf)> {
    if !Scene::is_scene_file(&args.input) {
        let field = args.field.clone().unwrap_or_else(|| args.input.clone());
        let f = FieldFile::open(&field)?;
        let pose = f.pose_or_first(args.pose)?;
        return Ok((scene_of_flags(args, f.header(), pose)?, field));
    }
    if args.camera.camera.is_some() || args.camera.orbit.is_some() || args.pose.is_some() {
        return Err(format!(
            "{}: a scene file gives the camera and the walk; --camera, --orbit and --pose are for field renders",
            args.input.display()
        )
        .into());
    }
    if args.lighting.yaw != 0.0 {
        return Err(format!(
            "{}: --yaw is for field renders; a scene's lighting keys give the yaw (`yaw_deg`)",
            args.input.display()
        )
        .into());
    }
    let env = args.lighting.env.as_ref();
    let (mut scene, field) = Scene::load_overridden(&args.input, env, args.field.as_deref())?;
    // A sun given by flag replaces the scene's (or adds one), said so, never ignored.
    if let Some(sun) = args.lighting.sun()? {
        eprintln!(
            "--sun: {}",
            match scene.sun {
                Some(_) => "replaces the scene's sun",
                None => "added to the scene's lighting",
            }
        );
        scene.sun = Some(sun);
    }
    Ok((scene, field))
}

/// The frames of `scene` the arguments ask for, of `size`.
fn frames_of(
    args: &RenderArgs,
    scene: &Scene,
    size: (u32, u32),
    field_render: bool,
) -> CliResult<(Vec<ShotFrame>, usize)> {
    if field_render {
        let n = match &args.frames {
            Some(s) => s
                .parse::<usize>()
                .map_err(|_| format!("--frames {s:?}: a field render takes a count of frames"))?,
            None => DEFAULT_FRAMES,
        };
        let frames = scene.frozen_frames(n, size)?;
        return Ok((frames, n));
    }
    let total = scene.frame_times().len();
    let range = frame_range(args.frames.as_deref(), total)?;
    Ok((scene.shot_frames(range.start..range.end, size)?, total))
}

/// `--plan [--json]`: the plan printed.
fn print_plan(plan: &Plan, json: bool) -> CliResult {
    match json {
        true => println!("{}", serde_json::to_string_pretty(&plan.report())?),
        false => println!("{}", plan.describe()),
    }
    Ok(())
}

/// Runs `frf render`.
pub fn run(args: RenderArgs) -> CliResult {
    let (mut scene, field_path) = scene_of(&args)?;
    let field_render = !Scene::is_scene_file(&args.input);
    let ground = matches!(
        scene.floor,
        frf_reflectance::project::FloorModel::LambertianGround { .. }
    );
    if let Some(note) = scene.sun.and_then(|s| s.below_horizon(ground)) {
        eprintln!("{note}");
    }
    if let Some(v) = args.variant {
        scene.variant = v.into();
    }
    if let Some(e) = args.exposure {
        scene.exposure = e;
    }
    frf_core::argument::within("--exposure", scene.exposure, -30.0, 30.0, "stops")?;
    scene.layers |= args.layers;
    let field = FieldFile::open(&field_path)?;
    frf_render::resident::check_renderable(&field)?;
    let h = field.header();
    let size = scene.frame_size(args.size, (h.width, h.height))?;
    let (frames, total) = frames_of(&args, &scene, size, field_render)?;
    if args.plan || args.explain {
        let plan = Plan::new(&scene, &field, &frames)?;
        if args.explain {
            print_plan(&plan, false)?;
            if let Some(e) = explain(&scene, &field, &plan, args.cpu)? {
                println!("{}", e.describe(&plan));
            }
            return Ok(());
        }
        return print_plan(&plan, args.json);
    }
    let out_dir = args.out.clone().ok_or("give --out DIR (or --plan)")?;
    let flagged = FlagFiles {
        input: &args.input,
        camera: args.camera.camera.as_deref(),
        plate: args.scene.plate.as_deref(),
        env: match &args.lighting.env {
            Some(EnvSource::File(p)) => Some(p),
            _ => None,
        },
    };
    let args_json = serde_json::to_value(&args)?;
    let settings = RenderSettings::new((args_json, flagged), &scene, &field, !field_render, size)?;

    let job = ShotJob {
        scene: &scene,
        field: &field,
        field_path: &field_path,
        frames: &frames,
        total,
        size,
        out_dir: &out_dir,
        settings: &settings,
        overwrite: args.overwrite,
    };
    let options = ShotOptions {
        memory_budget: args.memory_budget.saturating_mul(1_000_000),
        planned: !args.no_plan,
        traced_lights: args.scene.shadow_lights,
        detail: args.detail,
        light_tolerance: args
            .light_tolerance
            .unwrap_or(frf_scene::shot::LightTolerance::DEFAULT),
        walker_shadows: !args.no_walker_shadows,
    };
    let summary = render_to_dir(&job, args.cpu, options, &Bars::default(), &mut |line| {
        eprintln!("{line}")
    })?;
    eprintln!("{summary}");
    Ok(())
}
