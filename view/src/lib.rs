//! `frf view`: a field or a scene looked at interactively, in a window (winit) drawn by
//! the renderer `frf render` uses, with a panel (egui) of every control.
//!
//! - [`camera`]: orbit, dolly, pan, fly, look, field of view; captured views;
//! - [`viewer`]: the state shown and every change to it (keys, mouse, panel and scripts
//!   go through it);
//! - [`script`]: the commands a script runs without a person (tests, figures);
//! - [`record`]: keys set while moving, written as a scene file `frf render` renders;
//! - [`paths`]: the walkers' paths drawn over the frame;
//! - [`timer`]: the GPU time of a frame from timestamp queries;
//! - `app` and `panel`: the window, its event loop and the panel.
//!
//! A frame is drawn into the renderer's kept targets and shown by a present pass
//! ([`frf_render::gpu::present`]): nothing is made or read back per frame; poses are
//! relit only when the light changes ([`frf_scene::shot::Shot::edit`]).

mod app;
pub mod camera;
mod outcome;
mod panel;
pub mod paths;
pub mod record;
pub mod script;
pub mod timer;
pub mod viewer;

use std::path::PathBuf;

use frf_core::env::EnvSource;
use frf_scene::Scene;

/// Errors of the viewer.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// No window system to open a window on.
    #[error(
        "no display to open a window on ({0}); run `frf view` in a desktop session, or under \
         Xvfb: `xvfb-run -a frf view ...`"
    )]
    NoDisplay(String),
    /// The window system failed while the viewer ran.
    #[error("the window system failed: {0}")]
    Window(String),
    /// A script's line is wrong.
    #[error("{}:{line}: {problem}", path.display())]
    Script {
        /// The script.
        path: PathBuf,
        /// 1-based.
        line: usize,
        /// What is wrong.
        problem: String,
    },
    /// A script's command could not be carried out.
    #[error("{}:{line}: {source}", path.display())]
    ScriptFailed {
        /// The script.
        path: PathBuf,
        /// 1-based.
        line: usize,
        /// Why.
        source: Box<ViewError>,
    },
    /// A request the viewer cannot carry out.
    #[error("{0}")]
    Bad(String),
    /// `--record` without a key set.
    #[error(
        "nothing recorded: set camera keys with K (or `key` in a script) before closing the \
         viewer"
    )]
    NothingRecorded,
    /// The recorded scene could not be written.
    #[error("writing the recorded scene: {0}")]
    Record(String),
    /// Rendering failed.
    #[error(transparent)]
    Render(#[from] frf_render::RenderError),
    /// The scene: its file, plan, shot and output.
    #[error(transparent)]
    Scene(#[from] frf_scene::SceneError),
    /// Reading the field failed.
    #[error(transparent)]
    Field(#[from] frf_reflectance::ReflectanceError),
    /// A file or value was refused.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
}

impl ViewError {
    /// Who is at fault (the exit status of `frf view`): no display or a failed window
    /// system is the environment's (I/O), a bad script or request the caller's.
    pub fn fault(&self) -> frf_core::Fault {
        use frf_core::Fault;
        match self {
            ViewError::NoDisplay(_) | ViewError::Window(_) => Fault::Io,
            ViewError::Script { .. }
            | ViewError::Bad(_)
            | ViewError::NothingRecorded
            | ViewError::Record(_) => Fault::Usage,
            ViewError::ScriptFailed { source, .. } => source.fault(),
            ViewError::Render(e) => e.fault(),
            ViewError::Scene(e) => e.fault(),
            ViewError::Field(e) => e.fault(),
            ViewError::Core(e) => e.fault(),
        }
    }
}

/// What `frf view` is asked to show.
pub struct ViewOptions {
    /// The scene (a scene file's, or one made for a field).
    pub scene: Scene,
    /// The field it is drawn from.
    pub field: PathBuf,
    /// Window size, pixels (the frame size while the window keeps it).
    pub size: (u32, u32),
    /// The environments offered besides the scene's.
    pub envs: Vec<EnvSource>,
    /// Commands to run without a person, and the file they were read from.
    pub script: Option<(PathBuf, Vec<script::Line>)>,
    /// Where to write the recorded camera move as a scene file.
    pub record: Option<PathBuf>,
    /// Most bytes the resident poses may hold together.
    pub memory_budget: u64,
    /// Start at the captured view (column 0, middle row) rather than the scene's camera.
    pub start_at_captured_view: bool,
    /// Present frames as fast as they are drawn (to measure), not at the display's rate.
    pub no_vsync: bool,
}

/// How the viewer ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ended {
    /// Asked to quit (Escape, the panel, a script's `quit`, or its end).
    Quit,
    /// The window was closed.
    WindowClosed,
}

/// What a session of the viewer did.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// How it ended.
    pub ended: Ended,
    /// Frames drawn.
    pub frames: u64,
    /// GPU time of the frames timed, milliseconds (timestamp queries; empty without).
    pub gpu_ms: Vec<f64>,
    /// Time between frames shown, milliseconds.
    pub frame_ms: Vec<f64>,
    /// Screenshots written.
    pub screenshots: Vec<PathBuf>,
    /// The recorded scene written, its number of keys, and a note on it.
    pub recorded: Option<(PathBuf, usize, Option<String>)>,
    /// The adapter that drew, in words.
    pub adapter: String,
    /// Poses made resident (read and relit, counting relights for a new light), and the
    /// seconds it took.
    pub residency: (usize, f64),
}

/// Opens the window and runs the viewer until it is closed or a script ends.
pub fn run(options: ViewOptions) -> Result<Outcome, ViewError> {
    app::run(options)
}
