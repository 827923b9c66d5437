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
    /// A run of `frf report` failed: its command, its exit status and the end of what it
    /// said (its fault is the run's own, read from its status).
    #[error("{command} failed (exit status {}):\n{stderr_tail}", status.map_or("none".into(), |s| s.to_string()))]
    RunFailed {
        /// The run, as its command.
        command: String,
        /// Its exit status (`None`: ended by a signal).
        status: Option<i32>,
        /// The last lines of its standard error.
        stderr_tail: String,
    },
    /// A run's output lacks what the report reads from it (the program's own mistake).
    #[error("{command}: {lacks}")]
    RunOutput {
        /// The run, as its command.
        command: String,
        /// What is missing or unreadable.
        lacks: String,
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
    /// A [`EvalError::RunOutput`] of the run `command`.
    pub fn run(command: impl Into<String>, lacks: impl std::fmt::Display) -> Self {
        EvalError::RunOutput {
            command: command.into(),
            lacks: lacks.to_string(),
        }
    }

    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        match self {
            EvalError::Argument(_) | EvalError::NoTruth(_) => frf_core::Fault::Usage,
            EvalError::RunFailed { status, .. } => match status {
                Some(2) => frf_core::Fault::Usage,
                Some(3) => frf_core::Fault::Damaged,
                Some(4) => frf_core::Fault::Gpu,
                Some(5) => frf_core::Fault::Io,
                Some(75) => frf_core::Fault::Busy,
                Some(130) | None => frf_core::Fault::Interrupted,
                _ => frf_core::Fault::Internal,
            },
            EvalError::RunOutput { .. } | EvalError::Incomplete(_) => frf_core::Fault::Internal,
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
