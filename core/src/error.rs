//! The error type of `frf-core`, split by who is at fault: a bad file or manifest
//! (the input), a limit the input exceeds, a bad argument (the caller), or I/O.

use std::path::{Path, PathBuf};

/// Who is at fault when something fails: what the program's exit status tells (see
/// [`Fault::exit_code`]), so that a script can tell a mistake in its own call from a
/// damaged file or a machine without a usable GPU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// A bad argument, or input that is well formed but wrong (a size that does not fit, a
    /// pose the field lacks, a scene out of range): the caller can correct it.
    Usage,
    /// A file whose bytes are damaged or truncated, or not of the format it claims.
    Damaged,
    /// The GPU: no adapter that can run the passes, a request it refused, its memory.
    Gpu,
    /// The operating system: a file that cannot be opened, read or written, a full disk.
    Io,
    /// The user interrupted a long run; a rerun resumes it.
    Interrupted,
    /// Another process is writing the same output: nothing is wrong with the request or
    /// the data, and the same command succeeds once the other ends.
    Busy,
    /// The program itself failed (a worker thread panicked, a report that does not
    /// serialize): nothing the caller can correct; a bug to report.
    Internal,
}

impl Fault {
    /// The exit status of a run that failed with this fault: 2 usage (as for a command
    /// line clap refuses), 3 damaged data, 4 GPU, 5 I/O, 75 busy (`EX_TEMPFAIL` of
    /// sysexits.h: try again later), 70 internal (`EX_SOFTWARE`), 130 interrupted (as a shell reports an interrupt). 1
    /// is left for anything else and 101 is a panic's.
    pub fn exit_code(self) -> u8 {
        match self {
            Fault::Usage => 2,
            Fault::Damaged => 3,
            Fault::Gpu => 4,
            Fault::Io => 5,
            Fault::Busy => 75,
            Fault::Internal => 70,
            Fault::Interrupted => 130,
        }
    }
}

/// Result alias of this crate.
pub type Result<T, E = CoreError> = std::result::Result<T, E>;

/// Everything that can go wrong in `frf-core`.
#[derive(Debug, thiserror::Error)]
pub enum CoreError {
    /// Reading or writing a file failed at the operating-system level.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A file exists but its contents are not what its format requires.
    #[error("{}: {problem}", path.display())]
    BadFile {
        /// The file.
        path: PathBuf,
        /// What is wrong, in words.
        problem: String,
    },
    /// An image has other dimensions than the manifest or the caller requires.
    #[error("{}: expected {expected_width}x{expected_height} pixels, got {got_width}x{got_height}", path.display())]
    SizeMismatch {
        /// The file.
        path: PathBuf,
        /// Required width.
        expected_width: usize,
        /// Required height.
        expected_height: usize,
        /// Width found.
        got_width: usize,
        /// Height found.
        got_height: usize,
    },
    /// A manifest field is missing, malformed or inconsistent.
    #[error("{}: {field}: {problem}", path.display())]
    Manifest {
        /// The manifest file.
        path: PathBuf,
        /// The field, as a path such as `cameras[1].world_from_camera[0][2]`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// An input would make the program allocate or compute more than its limits allow.
    #[error("{what}: {problem}")]
    LimitExceeded {
        /// What was too large (usually a file name).
        what: String,
        /// The size found and the limit.
        problem: String,
    },
    /// An output another process is writing (it holds the output's lock).
    #[error("{}: another process is writing it (it holds {}): wait for it to end, or give another output", path.display(), lock.display())]
    Busy {
        /// The output.
        path: PathBuf,
        /// The lock file its writer holds.
        lock: PathBuf,
    },
    /// A path given as an output that cannot be one (a directory, no file name): the
    /// caller's to correct.
    #[error("{}: {problem}", path.display())]
    BadOutput {
        /// The path.
        path: PathBuf,
        /// Why it cannot be written.
        problem: String,
    },
    /// An argument outside what is allowed, named as the user gave it.
    #[error(transparent)]
    Argument(#[from] crate::argument::BadArgument),
    /// A function was called with an argument it cannot accept.
    #[error("invalid argument {what}: {problem}")]
    InvalidArgument {
        /// The argument.
        what: String,
        /// Why it is refused.
        problem: String,
    },
}

impl CoreError {
    /// Who is at fault ([`Fault`]).
    pub fn fault(&self) -> Fault {
        match self {
            CoreError::Io { .. } => Fault::Io,
            CoreError::Busy { .. } => Fault::Busy,
            CoreError::BadFile { .. } => Fault::Damaged,
            CoreError::SizeMismatch { .. }
            | CoreError::Manifest { .. }
            | CoreError::LimitExceeded { .. }
            | CoreError::BadOutput { .. }
            | CoreError::Argument(_)
            | CoreError::InvalidArgument { .. } => Fault::Usage,
        }
    }

    /// An [`CoreError::Io`] error for `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// A [`CoreError::BadFile`] error for `path`.
    pub fn bad_file(path: &Path, problem: impl Into<String>) -> Self {
        Self::BadFile {
            path: path.to_path_buf(),
            problem: problem.into(),
        }
    }

    /// An [`CoreError::InvalidArgument`] error.
    pub fn invalid(what: impl Into<String>, problem: impl Into<String>) -> Self {
        Self::InvalidArgument {
            what: what.into(),
            problem: problem.into(),
        }
    }
}
