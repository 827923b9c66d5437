//! `frf view INPUT`: a field or a scene in a window ([`frf_view`]). A field is shown as
//! one walker at the origin, its walk playing from pose 0, lit by the first `--env`
//! (else the built-in sky) over that environment with its shadow, the camera at a
//! captured view; a scene file as written. `--script` runs commands without a person,
//! `--record` writes the camera keys set as a scene file for `frf render`.

use std::path::PathBuf;

use clap::Args;
use frf_core::env::EnvSource;
use frf_reflectance::FieldFile;
use frf_render::morph::Variant;
use frf_scene::{FieldLook, Scene};
use frf_view::ViewOptions;

use crate::CliResult;
use crate::cmd::args::{
    FloorArg, SunSpec, VariantArg, parse_env, parse_size, parse_sun, parse_turn,
};

/// Memory the resident poses may hold by default, MB.
const DEFAULT_BUDGET_MB: u64 = 2048;
/// Frames per second of a recorded move of a field.
const RECORD_FPS: f64 = 24.0;

/// Arguments of `frf view`.
#[derive(Args)]
pub struct ViewArgs {
    /// A field file, or a scene file (`.toml`).
    pub input: PathBuf,
    /// The field (overrides the scene's).
    #[arg(long)]
    pub field: Option<PathBuf>,
    /// Environments to offer (repeat): `.hdr`/`.exr` files, `sky`, `uniform`. A field is
    /// lit by the first (default: the built-in sky).
    #[arg(long, value_parser = parse_env)]
    pub env: Vec<EnvSource>,
    /// Yaw of a field's environment, degrees.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = parse_turn)]
    pub yaw: f64,
    /// What lights a field's subject from below.
    #[arg(long, value_enum, default_value = "env")]
    pub floor: FloorArg,
    /// A sun added to a field's environment (alone with `--env none`), turned with it:
    /// `AZIMUTH,ELEVATION[,DIAMETER[,ILLUMINANCE]]`, as `frf render --sun` (a scene file
    /// names its own in `lighting.sun`).
    #[arg(long, value_parser = parse_sun, allow_hyphen_values = true, value_name = "AZ,EL[,DIAM[,E]]")]
    pub sun: Option<SunSpec>,
    /// Window size `WxH` (the frame size while the window keeps it).
    #[arg(long, value_parser = parse_size, default_value = "960x540")]
    pub size: (u32, u32),
    /// Interpolation to start with (default: the scene's, else four-way).
    #[arg(long, value_enum)]
    pub variant: Option<VariantArg>,
    /// Run the commands of FILE without a person, then close (`--help` lists them).
    #[arg(long, value_name = "FILE", long_help = frf_view::script::help())]
    pub script: Option<PathBuf>,
    /// When the viewer closes, write the camera keys set (K) as a scene file that `frf
    /// render FILE --out DIR` renders.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Most memory the resident poses may hold together, MB.
    #[arg(long, default_value_t = DEFAULT_BUDGET_MB, value_parser = clap::value_parser!(u64).range(1..))]
    pub memory_budget: u64,
    /// Draw frames as fast as possible, not at the display's rate (to measure).
    #[arg(long)]
    pub no_vsync: bool,
    /// Print what the session measured as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The scene of a field: one walker at the origin walking from pose 0.
fn field_scene(args: &ViewArgs, field: &FieldFile) -> CliResult<Scene> {
    let h = field.header();
    let env = args.env.first().cloned().unwrap_or(EnvSource::Sky);
    let look = FieldLook {
        sun: args.sun.as_ref().map(SunSpec::sun).transpose()?,
        ..FieldLook::viewer(env, args.yaw, args.floor.into())
    };
    // The walk plays from pose 0.
    Ok(Scene {
        end: h.cycle_seconds,
        fps: RECORD_FPS,
        size: Some(args.size),
        variant: args.variant.map_or(Variant::FourWay, Into::into),
        ..Scene::of_field(&args.input, h, 0, look)
    })
}

/// Runs `frf view`.
pub fn run(args: ViewArgs) -> CliResult {
    let is_scene = Scene::is_scene_file(&args.input);
    let script = match &args.script {
        Some(p) => Some((p.clone(), frf_view::script::load(p)?)),
        None => None,
    };
    if is_scene && args.sun.is_some() {
        return Err("--sun lights a field; a scene file names its sun in [lighting.sun]".into());
    }
    let (scene, field_path) = if is_scene {
        let (mut scene, field) = Scene::load_overridden(&args.input, None, args.field.as_deref())?;
        if let Some(v) = args.variant {
            scene.variant = v.into();
        }
        (scene, field)
    } else {
        let field_path = args.field.clone().unwrap_or_else(|| args.input.clone());
        let field = FieldFile::open(&field_path)?;
        (field_scene(&args, &field)?, field_path)
    };
    frf_render::resident::check_renderable(&FieldFile::open(&field_path)?)?;
    let mut envs = args.env.clone();
    for e in [EnvSource::Sky, EnvSource::Uniform] {
        if !envs.contains(&e) {
            envs.push(e);
        }
    }
    envs.retain(|e| *e != EnvSource::None);
    let outcome = frf_view::run(ViewOptions {
        scene,
        field: field_path,
        size: args.size,
        envs,
        script,
        record: args.record.clone(),
        memory_budget: args.memory_budget.saturating_mul(1_000_000),
        start_at_captured_view: !is_scene,
        no_vsync: args.no_vsync,
    })?;
    for line in outcome.summary() {
        eprintln!("{line}");
    }
    if args.json {
        println!("{}", outcome.json());
    }
    Ok(())
}
