//! The error type of ingest.

/// Result alias of this crate.
pub type Result<T, E = IngestError> = std::result::Result<T, E>;

/// Everything that can go wrong in ingest.
#[derive(Debug, thiserror::Error)]
pub enum IngestError {
    /// A parameter is out of range or inconsistent with the capture.
    #[error("{0}")]
    BadParameter(String),
    /// The user asked to stop; finished poses are kept and a rerun resumes.
    #[error("interrupted: finished poses are kept, run the same command again to resume")]
    Interrupted,
    /// Reading the capture, images or environments.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
    /// The evaluator judging the ingest against a ground truth failed.
    #[error("evaluation against the ground truth: {0}")]
    Evaluation(crate::evidence::EvaluationError),
    /// The field file and codecs.
    #[error(transparent)]
    Reflectance(#[from] frf_reflectance::ReflectanceError),
    /// Optical flow.
    #[error(transparent)]
    Flow(#[from] frf_flow::FlowError),
}

impl IngestError {
    /// Who is at fault ([`frf_core::Fault`]); a failed evaluation is the caller's (its
    /// truth does not fit the capture).
    pub fn fault(&self) -> frf_core::Fault {
        use frf_core::Fault;
        match self {
            IngestError::BadParameter(_) | IngestError::Evaluation(_) => Fault::Usage,
            IngestError::Interrupted => Fault::Interrupted,
            IngestError::Core(e) => e.fault(),
            IngestError::Reflectance(e) => e.fault(),
            IngestError::Flow(e) => e.fault(),
        }
    }
}
