//! `frf eval FIELD --capture CAPTURE`: frames rendered between the grid's views scored
//! against the virtual stage's truth, per interpolation variant (error against run time);
//! `frf eval-ring FIELD --par PAR --stride S`: views held out of a ring of photographs
//! rendered from their neighbours and scored against the photographs.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use frf_core::io::rgba_from;
use frf_core::io::{write_png8_srgb, write_png8_srgba};
use frf_eval::metrics::edge_band_error_rgba;
use frf_eval::ring::{held_out_views, score_held_out};
use frf_eval::scene::{SceneScore, composite_psnr, mean_of, shadow_error, true_composite};
use frf_eval::storage::env_lights_for_view;
use frf_render::composite::{Backdrop, GroundLook};
use frf_render::renderer::SceneShadow;
use frf_render::shadow::{ShadowMaps, traced_shadow};

/// Median-cut lights of the traced-shadow ablation (as `frf render --shadow traced`).
const TRACED_LIGHTS: usize = 256;
use frf_eval::views::{
    EvalCamera, VariantScore, between_view_cameras, evaluate, grid_view_cameras, truth_frame,
};
use frf_reflectance::FieldFile;
use frf_render::morph::Variant;
use frf_render::resident::{Lighting, PoseSource};
use frf_stage::truth::environment_lights;
use rayon::prelude::*;
use serde::Serialize;

use crate::CliResult;
use crate::cmd::args::{CameraArgs, GroundArg, LightingArgs, VariantArg, parse_ground, parse_size};
use crate::cmd::progress::bar;
use crate::cmd::render::{open_renderer, pose_of};

/// Arguments of `frf eval`.
#[derive(Args)]
pub struct EvalArgs {
    /// A field of a virtual-stage capture (`frf stage field` or `frf ingest`), or a scene
    /// file (`.toml`): then frames of its shot are scored against their true composites.
    pub(crate) field: PathBuf,
    /// With a scene: the field to render it from (default: the scene's `field`).
    #[arg(long = "field")]
    pub(crate) scene_field: Option<PathBuf>,
    /// With a scene: frames scored, spread evenly over the shot (default 4); along a
    /// path (`--orbit`, `--camera`, `--suite`): frames of each path (default 8).
    #[arg(long)]
    pub(crate) frames: Option<usize>,
    /// Score frames along a camera path against the truth instead of cameras at quad
    /// centres.
    #[command(flatten)]
    pub(crate) path: CameraArgs,
    /// Score the suite of camera paths people render: inside the cylinder of cameras low
    /// and high, just inside it, outside it, above the top camera and below the bottom one
    /// (`frf_eval::paths`).
    #[arg(long, conflicts_with_all = ["camera", "orbit"])]
    pub(crate) suite: bool,
    /// The error budget of view interpolation: every variant at offsets ¼, ½, ¾ along
    /// rows, columns and toward quad centres (`--cameras` quads each) and at the captured
    /// views, beside the floor of any flow-based morph (true correspondences) and
    /// unstructured lumigraph rendering on the visual hull and on the true surface.
    #[arg(long, conflicts_with_all = ["camera", "orbit", "suite", "shadows"])]
    pub(crate) budget: bool,
    /// With `--budget`: also draw its plot here (`.svg` or `.png`) and its Markdown table
    /// beside it (`.md`).
    #[arg(long, requires = "budget")]
    pub(crate) plot: Option<PathBuf>,
    /// Along a path: frame size `WxH` (default: the field's image size).
    #[arg(long, value_parser = parse_size)]
    pub(crate) size: Option<(u32, u32)>,
    /// The capture the field was made from (its stage renders the truth).
    #[arg(long)]
    pub(crate) capture: PathBuf,
    #[command(flatten)]
    pub(crate) lighting: LightingArgs,
    /// Pose (default: the field's first).
    #[arg(long)]
    pose: Option<u32>,
    /// Cameras at the centres of grid quads, spread around the grid (with `--budget`:
    /// quads per offset).
    #[arg(long, default_value_t = 8)]
    pub(crate) cameras: usize,
    /// Median-cut lights of the environment in the truth renders.
    #[arg(long, default_value_t = 512)]
    pub(crate) lights: usize,
    #[command(flatten)]
    pub(crate) compare: CompareArgs,
    /// Write each camera's truth and renders as PNGs here (with `--budget`, the first
    /// camera's at each offset, every method's; with `--shadows`, also the
    /// relit and the true shadow of the ground patch, seen from above, +x right, +z down).
    #[arg(long)]
    pub(crate) images: Option<PathBuf>,
    /// Also score the subject in a scene: the relit shadow against the true one over the
    /// ground patch, composites over the environment against true composites, and the
    /// matte edges at the captured views.
    #[arg(long)]
    shadows: bool,
    /// Ground of the composites' environment backdrop: `env` or an albedo `A` / `R,G,B`.
    #[arg(long, value_parser = parse_ground, default_value = "env")]
    ground: GroundArg,
}

/// What `frf eval` and `frf eval-ring` compare, on which renderer, and how they report.
#[derive(Args)]
pub(crate) struct CompareArgs {
    /// Variants to compare (default: all four).
    #[arg(long, value_enum, value_delimiter = ',')]
    variants: Vec<VariantArg>,
    /// Also score the four-way morph's ablations (with the occlusion cue; without the
    /// proxy for rays beyond the grid's rows).
    #[arg(long)]
    ablations: bool,
    /// Render with the CPU reference instead of the GPU.
    #[arg(long)]
    pub(crate) cpu: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub(crate) json: bool,
}

impl CompareArgs {
    pub(crate) fn variants(&self) -> Vec<Variant> {
        let mut v: Vec<Variant> = if self.variants.is_empty() {
            Variant::ALL.to_vec()
        } else {
            self.variants.iter().map(|&v| v.into()).collect()
        };
        if self.ablations {
            v.extend(
                Variant::ABLATIONS
                    .iter()
                    .filter(|a| !v.contains(a))
                    .collect::<Vec<_>>(),
            );
        }
        v
    }
}

#[derive(Serialize)]
struct EvalReport {
    field: PathBuf,
    capture: PathBuf,
    env: String,
    pose: u32,
    device: String,
    truth_lights: usize,
    truth_seconds_per_frame: f64,
    cameras: Vec<String>,
    variants: Vec<VariantScore>,
    /// The four-way renderer at captured cameras: the error of relighting and storage.
    at_captured_views: VariantScore,
    /// With `--shadows`: the scene's scores.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    scene: Option<SceneScore>,
}

/// Runs `frf eval`.
pub fn run(args: EvalArgs) -> CliResult {
    if args
        .field
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    {
        return crate::cmd::eval_shot::run(&args);
    }
    let field = FieldFile::open(&args.field)?;
    let h = field.header();
    let pose = pose_of(h, args.pose, &args.field)?;
    let (lighting, env) = args.lighting.lighting(h.conditions.len())?;
    let env = env.ok_or("frf eval needs an environment (the truth is relit by it)")?;
    if !(1..=65536).contains(&args.lights) {
        return Err(format!("--lights {} (1 to 65536)", args.lights).into());
    }
    let stage = frf_stage::open_stage(&args.capture)?;
    if !stage.config().poses.contains(&pose) {
        return Err(format!(
            "{}: pose {pose} is not in the capture",
            args.capture.display()
        )
        .into());
    }
    let source = PoseSource::load(&field, pose, &lighting)?;
    if args.budget {
        return crate::cmd::eval_budget::run(&args, &source, &stage, &env, pose);
    }
    if args.suite || args.path.orbit.is_some() || args.path.camera.is_some() {
        return crate::cmd::eval_paths::run(&args, &source, &stage, &env);
    }
    let cameras = between_view_cameras(&source.geometry, args.cameras)?;
    let at_views = grid_view_cameras(&source.geometry, args.cameras)?;
    let lights = environment_lights(&env, args.lights);
    let truth_bar = bar("truth frames");
    let start = Instant::now();
    let all: Vec<&EvalCamera> = cameras.iter().chain(&at_views).collect();
    truth_bar.set_length(all.len() as u64);
    let mut truths = all
        .par_iter()
        .map(|c| {
            let t = truth_frame(&stage, pose, &c.camera, &lights);
            truth_bar.inc(1);
            t
        })
        .collect::<Result<Vec<_>, _>>()?;
    let truth_seconds = start.elapsed().as_secs_f64() / all.len() as f64;
    let truths_at_views = truths.split_off(cameras.len());
    truth_bar.finish_and_clear();

    let mut renderer = open_renderer(&source, args.compare.cpu)?;
    let variants = args.compare.variants();
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (i, t) in truths.iter().enumerate() {
            write_png8_srgba(&dir.join(format!("camera{i:02}_truth.png")), t, 1.0)?;
        }
    }
    let bar = bar("rendered frames");
    bar.set_length((cameras.len() * variants.len()) as u64);
    let scores = evaluate(&renderer, &cameras, &truths, &variants, &mut |i, v, img| {
        bar.inc(1);
        if let Some(dir) = &args.images {
            write_png8_srgba(
                &dir.join(format!("camera{i:02}_{}.png", v.name())),
                img,
                1.0,
            )?;
        }
        Ok(())
    })?;
    bar.finish_and_clear();
    let mut floor = evaluate(
        &renderer,
        &at_views,
        &truths_at_views,
        &[Variant::FourWay],
        &mut |_, _, _| Ok(()),
    )?
    .remove(0);
    floor.name = "at the captured views".into();
    let scene = if args.shadows {
        let ground = match args.ground {
            GroundArg::Env => GroundLook::Environment,
            GroundArg::Albedo(a) => GroundLook::Albedo(a),
        };
        let backdrop = Backdrop::environment(env.clone(), ground);
        let maps = ShadowMaps::load(&field, pose)?;
        // The ablation first: the environment's lights traced against the hull.
        let hull = field.hull(pose)?;
        let hull_iou = hull
            .as_ref()
            .map(|h| h.iou(&stage.true_occupancy(pose, h.grid())));
        let (shadow_mae_traced, traced_seconds) = match (hull, &maps) {
            (Some(hull), Some(m)) => {
                let t = Instant::now();
                let traced = traced_shadow(&hull, &env.median_cut(TRACED_LIGHTS), m.spec.ground);
                let seconds = t.elapsed().as_secs_f64();
                (
                    Some(shadow_error(&traced, &stage, pose, &lights)),
                    Some(seconds),
                )
            }
            _ => (None, None),
        };
        let t = Instant::now();
        renderer.set_scene(
            backdrop.clone(),
            maps.as_ref().map_or(SceneShadow::None, SceneShadow::Maps),
        )?;
        let scene_seconds = t.elapsed().as_secs_f64();
        let relit = renderer.relit_shadow()?;
        let shadow_mae = relit
            .as_ref()
            .map(|r| shadow_error(r, &stage, pose, &lights));
        if let (Some(dir), Some(r)) = (&args.images, &relit) {
            let truth = stage.true_ground_shadow(pose, &lights, &r.ground);
            write_png8_srgb(&dir.join("shadow_relit.png"), &r.image, 1.0)?;
            write_png8_srgb(&dir.join("shadow_truth.png"), &truth, 1.0)?;
        }
        let scene_bar = crate::cmd::progress::bar("composites");
        scene_bar.set_length(cameras.len() as u64);
        let mut composite_seconds = 0.0;
        let psnrs = cameras
            .iter()
            .zip(&truths)
            .map(|(c, truth)| {
                let t = Instant::now();
                let frame = renderer.render_frame(&c.camera, Variant::FourWay, false)?;
                composite_seconds += t.elapsed().as_secs_f64();
                let t = true_composite(&stage, pose, &c.camera, truth.clone(), &lights, &backdrop)?;
                scene_bar.inc(1);
                Ok(composite_psnr(&t, &frame.composite))
            })
            .collect::<CliResult<Vec<f64>>>()?;
        scene_bar.finish_and_clear();
        let mut dark = Vec::new();
        let mut bright = Vec::new();
        for c in &at_views {
            // The walker of that view's cycle as filmed, lit as the renderer relit it.
            let (u, v) = c.view.ok_or("a captured-view camera without its view")?;
            let t = stage.true_view_image(
                pose,
                u,
                v,
                &env_lights_for_view(&stage, &lights, pose, u),
            )?;
            let truth = &rgba_from(&t.color, &t.alpha)?;
            let (img, _) = renderer.render(&c.camera, Variant::FourWay)?;
            let e = edge_band_error_rgba(truth, &img);
            dark.push(e.map(|e| e.dark));
            bright.push(e.map(|e| e.bright));
        }
        let (dark, bright) = (mean_of(dark.into_iter()), mean_of(bright.into_iter()));
        Some(SceneScore {
            hull_iou,
            shadow_mae,
            shadow_mae_traced,
            psnr_composite: psnrs.iter().sum::<f64>() / psnrs.len().max(1) as f64,
            scene_seconds,
            traced_seconds,
            seconds_per_composite: composite_seconds / psnrs.len().max(1) as f64,
            edge_band_mae_dark: dark,
            edge_band_mae_bright: bright,
            edge_band_mae: mean_of([dark, bright].into_iter()),
            psnr_composite_per_camera: psnrs,
        })
    } else {
        None
    };
    eprintln!(
        "{} pose {pose} under {} (truth: {} median-cut lights, {:.2} s/frame on the CPU), {} \
         cameras at quad centres, {}:",
        args.field.display(),
        args.lighting.source()?,
        args.lights,
        truth_seconds,
        cameras.len(),
        renderer.device()
    );
    eprintln!("{}", crate::cmd::eval_paths::TABLE_HEADER);
    for s in scores.iter().chain([&floor]) {
        eprintln!("{}", crate::cmd::eval_paths::table_row(s));
    }
    if let Some(s) = &scene {
        let f = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.4}"));
        eprintln!(
            "scene: hull IoU {}, shadow MAE {} (relit maps against the true relative irradiance, {} m \
             patch; traced against the hull instead: {}), composite PSNR {:.2} dB (four-way, over the environment), edge-band \
             error {} over black / {} over bright (at the captured views)",
            f(s.hull_iou),
            f(s.shadow_mae),
            ShadowMaps::load(&field, pose)?.map_or(0.0, |m| m.spec.ground.extent_m),
            f(s.shadow_mae_traced),
            s.psnr_composite,
            f(s.edge_band_mae_dark),
            f(s.edge_band_mae_bright)
        );
    }
    if args.compare.json {
        let report = EvalReport {
            field: args.field.clone(),
            capture: args.capture.clone(),
            env: args.lighting.source()?.to_string(),
            pose,
            device: renderer.device().to_string(),
            truth_lights: args.lights,
            truth_seconds_per_frame: truth_seconds,
            cameras: cameras.iter().map(|c| c.name.clone()).collect(),
            variants: scores,
            at_captured_views: floor,
            scene: scene.clone(),
        };
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(())
}

/// Arguments of `frf eval-ring`.
#[derive(Args)]
pub struct RingEvalArgs {
    /// A field made by `frf ingest-ring --stride S` from the same ring.
    field: PathBuf,
    /// The ring's calibration (Middlebury `*_par.txt`).
    #[arg(long)]
    par: PathBuf,
    /// The stride the field was ingested with: the view halfway between two kept views
    /// is rendered (2: view i from i±1; 4: from i±2; 3: view i+1 from i and i+3); any
    /// stride from 2 and any number of views.
    #[arg(long)]
    stride: usize,
    #[command(flatten)]
    compare: CompareArgs,
}

/// Runs `frf eval-ring`.
pub fn run_ring(args: RingEvalArgs) -> CliResult {
    let field = FieldFile::open(&args.field)?;
    let (views, cameras, _) = frf_ingest::ring::ring_views(&args.par)?;
    let s = args.stride;
    let wraps = field.header().wraps;
    if s < 2 || views.len().div_ceil(s) != field.header().columns {
        return Err(format!(
            "{}: {} views do not come from {} views at stride {s}",
            args.field.display(),
            field.header().columns,
            views.len()
        )
        .into());
    }
    let held = held_out_views(views.len(), s, wraps)?;
    let source = PoseSource::load(&field, 0, &Lighting::Unlit)?;
    let renderer = open_renderer(&source, args.compare.cpu)?;
    let scores = score_held_out(&renderer, &views, &cameras, &held, &args.compare.variants())?;
    eprintln!(
        "{}: {} held-out views, each rendered from the kept views either side ({} apart, \
         the last gap {}), {}:",
        args.field.display(),
        held.len(),
        s,
        if wraps {
            format!("{} apart", views.len() - (views.len() - 1) / s * s)
        } else {
            "open".into()
        },
        renderer.device()
    );
    eprintln!(
        "{:<18} {:>17} {:>17} {:>9}",
        "variant", "PSNR silhouette", "SSIM silhouette", "s/frame"
    );
    for r in &scores {
        eprintln!(
            "{:<18} {:>14.2} dB {:>17.4} {:>9.4}",
            r.name, r.psnr_silhouette, r.ssim_silhouette, r.seconds_per_frame
        );
    }
    if args.compare.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "field": args.field,
                "par": args.par,
                "stride": s,
                "device": renderer.device(),
                "variants": scores,
            }))?
        );
    }
    Ok(())
}
