//! The error type of the evaluation.

/// Result alias of this crate.
pub type Result<T, E = EvalError> = std::result::Result<T, E>;

/// Everything that can go wrong while judging results against the truth.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// A parameter is out of range or inconsistent with the capture or field.
    #[error("{0}")]
    BadParameter(String),
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
    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        match self {
            EvalError::BadParameter(_) => frf_core::Fault::Usage,
            EvalError::Core(e) => e.fault(),
            EvalError::Stage(e) => e.fault(),
            EvalError::Reflectance(e) => e.fault(),
            EvalError::Ingest(e) => e.fault(),
            EvalError::Render(e) => e.fault(),
            EvalError::Scene(e) => e.fault(),
        }
    }
}
