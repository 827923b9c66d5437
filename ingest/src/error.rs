//! The error type of ingest.

/// Result alias of this crate.
pub type Result<T, E = IngestError> = std::result::Result<T, E>;

/// Everything that can go wrong in ingest.
#[derive(Debug, thiserror::Error)]
pub enum IngestError {
    /// An argument outside what is allowed, named as the user gave it.
    #[error(transparent)]
    Argument(#[from] frf_core::BadArgument),
    /// Two inputs that must agree in size do not.
    #[error("{what}: expected {expected}, got {got}")]
    Mismatch {
        /// What does not match.
        what: String,
        /// What was expected.
        expected: String,
        /// What was found.
        got: String,
    },
    /// An input image holds a value that is not finite.
    #[error("{what} holds a non-finite value at pixel ({}, {})", at.0, at.1)]
    NonFinite {
        /// The image.
        what: String,
        /// The pixel.
        at: (usize, usize),
    },
    /// Input from which nothing can be solved (cameras that form no ring, a plane
    /// through the camera, track frames at one time, no view to ingest).
    #[error("{0}")]
    Degenerate(String),
    /// A pose of a resumed ingest was made with other settings.
    #[error(
        "{}: pose {pose} was ingested with {was}, this run asks for {wanted}; use the same settings or remove {}",
        part.display(),
        parts.display()
    )]
    SettingsChanged {
        /// The pose's part file.
        part: std::path::PathBuf,
        /// The pose.
        pose: u32,
        /// Its settings.
        was: String,
        /// This run's.
        wanted: String,
        /// The directory of the parts, to remove to start afresh.
        parts: std::path::PathBuf,
    },
    /// The program failed (a report that does not serialize).
    #[error("{0}")]
    Internal(String),
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
    /// A [`IngestError::Mismatch`] of image sizes: `what` is `got` (width, height) where
    /// `expected` was expected.
    pub fn sizes(what: &str, expected: (usize, usize), got: (usize, usize)) -> Self {
        IngestError::Mismatch {
            what: what.to_string(),
            expected: format!("{}x{}", expected.0, expected.1),
            got: format!("{}x{}", got.0, got.1),
        }
    }

    /// Who is at fault ([`frf_core::Fault`]); a failed evaluation is the caller's (its
    /// truth does not fit the capture).
    pub fn fault(&self) -> frf_core::Fault {
        use frf_core::Fault;
        match self {
            IngestError::Argument(_)
            | IngestError::Mismatch { .. }
            | IngestError::NonFinite { .. }
            | IngestError::Degenerate(_)
            | IngestError::SettingsChanged { .. }
            | IngestError::Evaluation(_) => Fault::Usage,
            IngestError::Internal(_) => Fault::Internal,
            IngestError::Interrupted => Fault::Interrupted,
            IngestError::Core(e) => e.fault(),
            IngestError::Reflectance(e) => e.fault(),
            IngestError::Flow(e) => e.fault(),
        }
    }
}
