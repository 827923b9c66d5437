//! The arguments of `frf eval` and `frf eval-ring`, and what they compare.

use std::path::PathBuf;

use clap::Args;
use frf_render::morph::Variant;

use crate::cmd::args::{CameraArgs, GroundArg, LightingArgs, VariantArg, parse_ground, parse_size};

/// Arguments of `frf eval`.
#[derive(Args)]
pub struct EvalArgs {
    /// A field of a virtual-stage capture (`frf stage field` or `frf ingest`), or a scene
    /// file (`.toml`): then frames of its shot are scored against their true composites.
    pub field: PathBuf,
    /// With a scene: the field to render it from (default: the scene's `field`).
    #[arg(long = "field")]
    pub scene_field: Option<PathBuf>,
    /// With a scene: frames scored, spread evenly over the shot (default 4); along a
    /// path (`--orbit`, `--camera`, `--suite`): frames of each path (default 8).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Score frames along a camera path against the truth instead of cameras at quad
    /// centres.
    #[command(flatten)]
    pub path: CameraArgs,
    /// Score the suite of camera paths people render: inside the cylinder of cameras low
    /// and high, just inside it, outside it, above the top camera and below the bottom one
    /// (`frf_eval::paths`).
    #[arg(long, conflicts_with_all = ["camera", "orbit"])]
    pub suite: bool,
    /// The error budget of view interpolation: every variant at offsets ¼, ½, ¾ along
    /// rows, columns and toward quad centres (`--cameras` quads each) and at the captured
    /// views, beside the floor of any flow-based morph (true correspondences) and
    /// unstructured lumigraph rendering on the visual hull and on the true surface.
    #[arg(long, conflicts_with_all = ["camera", "orbit", "suite", "shadows"])]
    pub budget: bool,
    /// The error budget of ingest: the capture's pose ingested as `frf ingest` does (with
    /// the settings below), and again with one component at a time taken from the stage's
    /// truth (mattes, registration, sensor noise, the basis images, horizontal flows,
    /// vertical flows, the codec; all of them: the oracle field), each field scored at the
    /// captured views and at quad centres (`--cameras` each), beside FIELD itself.
    #[arg(long, conflicts_with_all = ["camera", "orbit", "suite", "shadows", "budget"])]
    pub ingest_budget: bool,
    /// Hard light at the captured views (`--cameras`), in one run: the field's sun (`--sun`,
    /// or one found in the map) relit by its views' fitted normals with the hull's cast
    /// shadows, as renders do, against the same sun relit by the basis alone (as fields
    /// without normals are), both against the truth (`frf_eval::sun_fit`); `--images`
    /// writes each view's truth and both renders
    #[arg(long, conflicts_with_all = ["camera", "orbit", "suite", "shadows", "budget", "ingest_budget"])]
    pub sun_fit: bool,
    /// With `--ingest-budget`: keep its fields in this directory, and reuse them when it
    /// holds them for the same capture, pose and settings (another environment costs only
    /// the renders); by default they are made in a temporary directory and removed.
    #[arg(long, requires = "ingest_budget")]
    pub fields: Option<PathBuf>,
    /// With `--ingest-budget`: how its fields are ingested (as `frf ingest`).
    #[command(flatten)]
    pub method: crate::cmd::ingest::IngestMethodArgs,
    /// With `--budget` or `--ingest-budget`: also draw its plot here (`.svg` or `.png`)
    /// and its Markdown table beside it (`.md`).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Along a path: frame size `WxH` (default: the field's image size).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// The capture the field was made from (its stage renders the truth).
    #[arg(long)]
    pub capture: PathBuf,
    #[command(flatten)]
    pub lighting: LightingArgs,
    /// Pose (default: the field's first).
    #[arg(long)]
    pub pose: Option<u32>,
    /// Cameras at the centres of grid quads, spread around the grid (with `--budget`:
    /// quads per offset).
    #[arg(long, default_value_t = 8)]
    pub cameras: usize,
    /// Median-cut lights of the environment in the truth renders.
    #[arg(long, default_value_t = 512)]
    pub lights: usize,
    /// With a scene: the instant of the walk the truth shows, the frame's own (`instant`:
    /// a frame between two captured poses is judged against the walker in between) or the
    /// drawn pose's (`pose`: the error of the view alone).
    #[arg(long, value_enum, default_value = "instant")]
    pub truth_at: frf_eval::shot::TruthAt,
    /// With a scene: how far a walker's own light may move before its poses are relit
    /// (as `frf render --light-tolerance`).
    #[arg(long, value_parser = crate::cmd::args::parse_light_tolerance)]
    pub light_tolerance: Option<frf_scene::shot::LightTolerance>,
    /// With a scene of one walker: also score the same walker standing at the origin,
    /// seen by the same camera and lit by the same light in its own frame, at each frame
    /// (what walking a path costs against walking on the spot).
    #[arg(long)]
    pub standing: bool,
    /// With a scene: walkers standing between another and a sun do not shade it (the
    /// ablation of walker-on-walker shadows).
    #[arg(long)]
    pub no_walker_shadows: bool,
    #[command(flatten)]
    pub compare: CompareArgs,
    /// Write each camera's truth and renders as PNGs here (with `--budget`, the first
    /// camera's at each offset, every method's; with `--shadows`, also the
    /// relit and the true shadow of the ground patch, seen from above, +x right, +z down).
    #[arg(long)]
    pub images: Option<PathBuf>,
    /// Also score the subject in a scene: the relit shadow against the true one over the
    /// ground patch, composites over the environment against true composites, and the
    /// matte edges at the captured views.
    #[arg(long)]
    pub shadows: bool,
    /// Ground of the composites' environment backdrop: `env` or an albedo `A` / `R,G,B`.
    #[arg(long, value_parser = parse_ground, default_value = "env")]
    pub ground: GroundArg,
}

/// What `frf eval` and `frf eval-ring` compare, on which renderer, and how they report.
#[derive(Args)]
pub struct CompareArgs {
    /// Variants to compare (default: all four).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub variants: Vec<VariantArg>,
    /// Also score the four-way morph's ablations (with the occlusion cue; without the
    /// proxy for rays beyond the grid's rows).
    #[arg(long)]
    pub ablations: bool,
    /// Render with the CPU reference instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

impl CompareArgs {
    pub fn variants(&self) -> Vec<Variant> {
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

/// Arguments of `frf eval-ring`.
#[derive(Args)]
pub struct RingEvalArgs {
    /// A field made by `frf ingest-ring --stride S` from the same ring.
    pub field: PathBuf,
    /// The ring's calibration (Middlebury `*_par.txt`).
    #[arg(long)]
    pub par: PathBuf,
    /// The stride the field was ingested with: the view halfway between two kept views
    /// is rendered (2: view i from i±1; 4: from i±2; 3: view i+1 from i and i+3); any
    /// stride from 2 and any number of views.
    #[arg(long)]
    pub stride: usize,
    #[command(flatten)]
    pub compare: CompareArgs,
}
