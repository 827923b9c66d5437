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
    /// An argument outside what is allowed, named as the user gave it.
    #[error(transparent)]
    Argument(#[from] frf_core::BadArgument),
    /// A pose the field (or the capture) does not hold.
    #[error(
        "{}pose {pose} is not in the {within} (it holds {held})",
        file.as_ref().map_or(String::new(), |p| format!("{}: ", p.display()))
    )]
    NoSuchPose {
        /// The field file, where known.
        file: Option<PathBuf>,
        /// `field` or `capture`.
        within: &'static str,
        /// The pose asked for.
        pose: u32,
        /// The poses it holds, listed (`none` when it holds none).
        held: String,
    },
    /// Something asked of a field that it does not hold (a chunk, a view, any pose).
    #[error("{}: {what}", file.display())]
    Missing {
        /// The field file.
        file: PathBuf,
        /// What it lacks.
        what: String,
    },
    /// Parts of a field that cannot be merged.
    #[error("{}: {problem}", part.display())]
    Incompatible {
        /// The part that does not fit the others.
        part: PathBuf,
        /// Why, and what to do.
        problem: String,
    },
    /// Values that are not finite, or overflow.
    #[error("{what} is not finite")]
    NonFinite {
        /// The value and where, e.g. `coefficient [inf, 0, 0]`.
        what: String,
    },
    /// A codec failed where its input was valid (compression, JPEG encoding, JSON): the
    /// program's own failure.
    #[error("{what}: {problem}")]
    Codec {
        /// The codec.
        what: &'static str,
        /// Its message.
        problem: String,
    },
    /// A call this crate's state does not allow (a writer finished, a chunk written
    /// twice, nothing to encode): the program's own mistake.
    #[error("{0}")]
    Misuse(String),
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
            ReflectanceError::Argument(_)
            | ReflectanceError::NoSuchPose { .. }
            | ReflectanceError::Missing { .. }
            | ReflectanceError::Incompatible { .. }
            | ReflectanceError::NonFinite { .. }
            | ReflectanceError::Mismatch { .. } => Fault::Usage,
            ReflectanceError::Codec { .. } | ReflectanceError::Misuse(_) => Fault::Internal,
            ReflectanceError::Core(e) => e.fault(),
            ReflectanceError::Io { .. } => Fault::Io,
        }
    }
}
