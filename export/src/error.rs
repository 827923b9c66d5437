//! Errors of the export, naming the file and the problem.

use std::path::PathBuf;

/// What went wrong exporting or reading an export.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The field could not be read.
    #[error(transparent)]
    Reflectance(#[from] frf_reflectance::ReflectanceError),
    /// A core error (files, images).
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
    /// The field lacks what the export needs.
    #[error("the field cannot be exported: {0}")]
    Field(String),
    /// A bad option.
    #[error("{0}")]
    Option(String),
    /// A file that is not a readable export.
    #[error("{file}: {problem}")]
    BadFile {
        /// The file.
        file: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
}

impl ExportError {
    /// Who is at fault.
    pub fn fault(&self) -> frf_core::Fault {
        match self {
            Self::Reflectance(e) => e.fault(),
            Self::Core(e) => e.fault(),
            Self::Field(_) => frf_core::Fault::Usage,
            Self::BadFile { .. } => frf_core::Fault::Damaged,
            Self::Option(_) => frf_core::Fault::Usage,
        }
    }
}

/// Results of the export.
pub type Result<T> = std::result::Result<T, ExportError>;
