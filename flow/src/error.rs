//! The error type of `frf-flow`, split by who is at fault: the caller's images or flow
//! fields (wrong size, empty, not finite), the caller's parameters, a benchmark
//! directory without usable sequences, or the file system (via [`CoreError`]).

use std::path::PathBuf;

use frf_core::CoreError;

/// Result alias of this crate.
pub type Result<T, E = FlowError> = std::result::Result<T, E>;

/// Everything that can go wrong in `frf-flow`.
#[derive(Debug, thiserror::Error)]
pub enum FlowError {
    /// Two inputs that must have the same dimensions do not.
    #[error("{what}: expected {}x{} pixels, got {}x{}", expected.0, expected.1, got.0, got.1)]
    SizeMismatch {
        /// Which input has the wrong size.
        what: &'static str,
        /// Required `(width, height)`.
        expected: (usize, usize),
        /// `(width, height)` found.
        got: (usize, usize),
    },
    /// An input has no pixels.
    #[error("{what} is empty ({width}x{height} pixels)")]
    EmptyImage {
        /// Which input.
        what: &'static str,
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
    },
    /// An input holds NaN or an infinity.
    #[error("{what}: pixel ({x}, {y}) is not finite (NaN or infinity)")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Column of the first offending pixel.
        x: usize,
        /// Row of the first offending pixel.
        y: usize,
    },
    /// A parameter is outside the range the estimator accepts.
    #[error("invalid parameter {name} = {value}: {expected}")]
    InvalidParameter {
        /// The parameter's name, as in [`crate::FlowParams`].
        name: &'static str,
        /// The value given, printed.
        value: String,
        /// The accepted range, in words.
        expected: &'static str,
    },
    /// An error metric was asked for but no pixel has known ground truth inside the mask.
    #[error("no pixel has known ground truth inside the mask: the error is undefined")]
    NoValidPixels,
    /// A benchmark directory holds no sequence in a layout this crate reads.
    #[error("{}: {problem}", dir.display())]
    Dataset {
        /// The directory.
        dir: PathBuf,
        /// What was expected and not found.
        problem: String,
    },
    /// A file of another size than the first image's (the second image, a starting
    /// flow).
    #[error(
        "{} is {}x{} but {} is {}x{}: {what}",
        path.display(), size.0, size.1, first.display(), first_size.0, first_size.1
    )]
    NotSameSize {
        /// What must hold: `the two images must be the same size`.
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// Its size.
        size: (usize, usize),
        /// The first image.
        first: PathBuf,
        /// Its size.
        first_size: (usize, usize),
    },
    /// Reading or writing a file failed (see [`CoreError`]).
    #[error(transparent)]
    Core(#[from] CoreError),
}

impl FlowError {
    /// An [`FlowError::InvalidParameter`] for `name`.
    pub(crate) fn parameter(
        name: &'static str,
        value: impl std::fmt::Display,
        expected: &'static str,
    ) -> Self {
        Self::InvalidParameter {
            name,
            value: value.to_string(),
            expected,
        }
    }
}

impl FlowError {
    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        match self {
            FlowError::Core(e) => e.fault(),
            _ => frf_core::Fault::Usage,
        }
    }
}
