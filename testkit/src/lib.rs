//! Test fixtures shared by the workspace's tests and benches, built once per process.
//!
//! [`tiny_field`]: the virtual stage's tiny preset (64x90, 36x3 views), pose 0, without
//! cycle-to-cycle perturbation (every cycle repeats, so the truth between views is what
//! interpolation should reach), and its oracle field ([`frf_eval::oracle`]: true flows,
//! noise-free basis images, JPEG quality 95, predicted flow codes, visual hull and shadow
//! maps carved from the true mattes with ingest's defaults). Its directory holds
//! the stage's configuration, so it serves as the `--capture` of `frf eval`. Building it
//! takes about 10 s on two cores.
//!
//! [`tiny_two_poses`]: the same stage's poses 0 and 3 and their oracle field with the true
//! flows between them.
//!
//! [`cpu_flag`]: whether command-line tests must render on the CPU reference.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use frf_core::env::EnvMap;
use frf_eval::oracle::{OracleOptions, write_oracle_field};
use frf_ingest::shadows::ShadowOptions;
use frf_reflectance::FieldFile;
use frf_reflectance::project::FloorModel;
use frf_render::resident::{Lighting, PoseSource};
use frf_stage::{Preset, SetFlowTruth, Stage, StageConfig};

/// `Some("--cpu")` when command-line tests must render with the CPU reference: only when
/// no GPU adapter opens and `FRF_SKIP_GPU=1` says the machine has none on purpose. With
/// an adapter the GPU path runs whatever the variable says (it excuses a missing adapter,
/// it does not hide a present one); without one and without the variable, the tests fail
/// saying what to install.
pub fn cpu_flag() -> Option<&'static str> {
    static ADAPTER: OnceLock<Result<(), String>> = OnceLock::new();
    let adapter = ADAPTER.get_or_init(|| {
        frf_render::gpu::Gpu::new()
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    match adapter {
        Ok(()) => None,
        Err(_) if std::env::var("FRF_SKIP_GPU").is_ok_and(|v| v == "1") => Some("--cpu"),
        Err(e) => panic!(
            "no GPU adapter ({e}): install mesa-vulkan-drivers, or set FRF_SKIP_GPU=1 to test the CPU path alone"
        ),
    }
}

/// The tiny stage and its oracle field (see the crate docs).
pub struct TinyField {
    dir: tempfile::TempDir,
    /// The stage the field was made from.
    pub stage: Stage,
    /// The field file.
    pub field: PathBuf,
}

impl TinyField {
    /// The directory holding the stage's configuration (a capture for `frf eval`).
    pub fn capture(&self) -> &Path {
        self.dir.path()
    }

    /// Pose 0 of the field loaded under `env` (the floor conditions lit by the
    /// environment's lower hemisphere), ready to make resident.
    ///
    /// # Panics
    /// If the field cannot be read: a test that needs it fails.
    pub fn source(&self, env: &EnvMap) -> PoseSource {
        let field = FieldFile::open(&self.field).expect("the tiny field opens");
        let lighting = Lighting::Environment {
            env: env.clone(),
            floor: FloorModel::Environment,
        };
        PoseSource::load(&field, 0, &lighting).expect("pose 0 of the tiny field loads")
    }

    /// A scratch directory inside the fixture's, created empty, for one test's outputs.
    pub fn scratch(&self, name: &str) -> PathBuf {
        let path = self.dir.path().join("scratch").join(name);
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("a scratch directory in the fixture's");
        path
    }
}

/// The configuration of [`tiny_field`]'s stage.
pub fn tiny_config() -> StageConfig {
    let mut c = StageConfig::preset(Preset::Tiny);
    c.poses = vec![0];
    c.perturbation = 0.0;
    c.set_flow_truth = SetFlowTruth::None;
    c
}

/// The tiny stage's poses 0 and 3 and their oracle field with the true flows between
/// them (`pose_flows`), built on first use: the walk between poses, exported or drawn.
///
/// # Panics
/// If the fixture cannot be built: a test that needs it fails.
pub fn tiny_two_poses() -> &'static TinyField {
    static FIXTURE: OnceLock<TinyField> = OnceLock::new();
    FIXTURE.get_or_init(|| build(vec![0, 3], true))
}

/// The tiny stage's oracle field, built on first use (see the crate docs).
///
/// # Panics
/// If the fixture cannot be built: a test that needs it fails.
pub fn tiny_field() -> &'static TinyField {
    static FIXTURE: OnceLock<TinyField> = OnceLock::new();
    FIXTURE.get_or_init(|| build(vec![0], false))
}

/// The tiny stage of `poses` and its oracle field (with pose flows when `pose_flows`).
fn build(poses: Vec<u32>, pose_flows: bool) -> TinyField {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut config = tiny_config();
    config.poses = poses.clone();
    std::fs::write(
        dir.path().join(frf_stage::writer::STAGE_FILE),
        toml::to_string(&config).expect("the configuration serializes"),
    )
    .expect("the stage configuration is written");
    let stage = Stage::new(config).expect("the tiny preset is valid");
    let field = dir.path().join("tiny.frf");
    let options = OracleOptions {
        poses,
        jpeg_quality: 95,
        predict_flow: true,
        shadows: Some(ShadowOptions::default()),
        pose_flows,
    };
    write_oracle_field(&stage, &field, &options, &|_, _| {})
        .expect("the tiny oracle field is written");
    TinyField { dir, stage, field }
}
