//! The error type of the reflectance crate, split by who is at fault: a corrupted or
//! truncated field file (with the chunk it concerns), a bad parameter from the caller,
//! or lower-level I/O and decoding.

use std::path::PathBuf;

/// Result alias of this crate.
pub type Result<T, E = ReflectanceError> = std::result::Result<T, E>;

/// Everything that can go wrong in this crate.
#[derive(Debug, thiserror::Error)]
pub enum ReflectanceError {
    /// Coded data is inconsistent (a decoder's private detail; the container wraps it
    /// with the file and chunk, see [`ReflectanceError::BadChunk`]).
    #[error("corrupt data: {0}")]
    Corrupt(String),
    /// A chunk of a field file is damaged or truncated.
    #[error("{}: chunk {chunk}: {problem}", path.display())]
    BadChunk {
        /// The field file.
        path: PathBuf,
        /// Which chunk, e.g. `flow right of pose 0 view (3, 1)`.
        chunk: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The file is not a field file, or its header, index or footer is damaged.
    #[error("{}: {problem}", path.display())]
    BadFile {
        /// The field file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// The caller asked for something absent or impossible.
    #[error("{0}")]
    BadParameter(String),
    /// Images of the wrong size or count.
    #[error("{what}: expected {expected}, got {got}")]
    Mismatch {
        /// What does not match.
        what: String,
        /// What was expected.
        expected: String,
        /// What was found.
        got: String,
    },
    /// Files, images, environments.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
    /// Operating-system I/O on a field file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
}

impl ReflectanceError {
    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        use frf_core::Fault;
        match self {
            ReflectanceError::Corrupt(_)
            | ReflectanceError::BadChunk { .. }
            | ReflectanceError::BadFile { .. } => Fault::Damaged,
            ReflectanceError::BadParameter(_) | ReflectanceError::Mismatch { .. } => Fault::Usage,
            ReflectanceError::Core(e) => e.fault(),
            ReflectanceError::Io { .. } => Fault::Io,
        }
    }
}
