//! The error type of the virtual light stage.

use std::path::PathBuf;

/// Result alias of this crate.
pub type Result<T, E = StageError> = std::result::Result<T, E>;

/// Everything that can go wrong in the stage.
#[derive(Debug, thiserror::Error)]
pub enum StageError {
    /// A configuration value is out of range or unknown.
    #[error("stage configuration: {0}")]
    BadConfig(String),
    /// The output directory holds a capture made with another configuration.
    #[error("{}: holds a capture made with a different configuration ({what}); use another directory", dir.display())]
    ConfigConflict {
        /// The directory.
        dir: PathBuf,
        /// Which field differs.
        what: String,
    },
    /// A request names a view, pose, slot or condition that does not exist.
    #[error("no such {what}: {value}")]
    OutOfRange {
        /// What was asked for.
        what: &'static str,
        /// The value asked for.
        value: String,
    },
    /// Reading or writing files, or an invalid camera or environment.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
}

impl StageError {
    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        match self {
            StageError::Core(e) => e.fault(),
            _ => frf_core::Fault::Usage,
        }
    }
}
