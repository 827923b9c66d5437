//! The error type of the evaluation.

/// Result alias of this crate.
pub type Result<T, E = EvalError> = std::result::Result<T, E>;

/// Everything that can go wrong while judging results against the truth.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// An argument outside what is allowed, named as the user gave it.
    #[error(transparent)]
    Argument(#[from] frf_core::BadArgument),
    /// What was asked has no truth to compare with (a scene of several walkers, an
    /// unlit scene, a pose the capture did not film, a grid with no quad).
    #[error("{0}")]
    NoTruth(String),
    /// A run of `frf report` failed, or its output lacks what the report reads.
    #[error("{run}: {problem}")]
    Run {
        /// The run, as its command.
        run: String,
        /// What went wrong.
        problem: String,
    },
    /// A report missing rows of some stage.
    #[error("the report is incomplete:\n{}", .0.join("\n"))]
    Incomplete(Vec<String>),
    /// A plot could not be drawn or written.
    #[error("plot: {0}")]
    Plot(String),
    /// A call the evaluation's state does not allow (nothing to score, no layers
    /// returned): the program's own mistake.
    #[error("{0}")]
    Misuse(String),
    /// Images, cameras, environments, files.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
    /// The virtual stage (ground truth).
    #[error(transparent)]
    Stage(#[from] frf_stage::StageError),
    /// The field file and codecs.
    #[error(transparent)]
    Reflectance(#[from] frf_reflectance::ReflectanceError),
    /// Ingest.
    #[error(transparent)]
    Ingest(#[from] frf_ingest::IngestError),
    /// Rendering.
    #[error(transparent)]
    Render(#[from] frf_render::RenderError),
    /// The scene: its file, plan, shot and output.
    #[error(transparent)]
    Scene(#[from] frf_scene::SceneError),
}

impl EvalError {
    /// A [`EvalError::Run`] of the run `run`.
    pub fn run(run: impl Into<String>, problem: impl std::fmt::Display) -> Self {
        EvalError::Run {
            run: run.into(),
            problem: problem.to_string(),
        }
    }

    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        match self {
            EvalError::Argument(_) | EvalError::NoTruth(_) | EvalError::Run { .. } => {
                frf_core::Fault::Usage
            }
            EvalError::Incomplete(_) => frf_core::Fault::Internal,
            EvalError::Plot(_) => frf_core::Fault::Io,
            EvalError::Misuse(_) => frf_core::Fault::Internal,
            EvalError::Core(e) => e.fault(),
            EvalError::Stage(e) => e.fault(),
            EvalError::Reflectance(e) => e.fault(),
            EvalError::Ingest(e) => e.fault(),
            EvalError::Render(e) => e.fault(),
            EvalError::Scene(e) => e.fault(),
        }
    }
}
