//! The error type of the renderer.

/// Result alias of this crate.
pub type Result<T, E = RenderError> = std::result::Result<T, E>;

/// Everything that can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// An argument outside what is allowed, named as the user gave it.
    #[error(transparent)]
    Argument(#[from] frf_core::BadArgument),
    /// Two things that must agree in size do not (a plate and its camera).
    #[error("{what}: expected {expected}, got {got}")]
    Mismatch {
        /// What does not match.
        what: String,
        /// What was expected.
        expected: String,
        /// What was found.
        got: String,
    },
    /// The shot needs a view the field does not hold (a field made for another scene).
    #[error(
        "{}: the shot needs view ({u}, {v}) of pose {pose}, which this field does not hold \
         (a field made for another scene: ingest the capture with --for this scene)",
        field.display()
    )]
    ViewNotHeld {
        /// The field file.
        field: std::path::PathBuf,
        /// The pose.
        pose: u32,
        /// The view's column.
        u: usize,
        /// The view's row.
        v: usize,
    },
    /// A field of photographs (one lighting condition, no reflectance basis) asked to
    /// be relit.
    #[error(
        "the field holds {conditions} lighting condition(s), photographs rather than a \
         reflectance basis: it cannot be relit; use --env none"
    )]
    NotRelightable {
        /// Its lighting conditions.
        conditions: usize,
    },
    /// A field the renderer cannot draw from any camera (one column of views: nothing to
    /// interpolate between).
    #[error("{}: {what}", field.display())]
    NotRenderable {
        /// The field file.
        field: std::path::PathBuf,
        /// What it is and why it cannot be drawn.
        what: String,
    },
    /// A camera stored in the field that is not a camera.
    #[error("a camera of the field: {0}")]
    BadCamera(String),
    /// A call the renderer's state does not allow (a pose resident on one device given
    /// to the other, a frame with no walker): the program's own mistake.
    #[error("{0}")]
    Misuse(String),
    /// No GPU adapter that can run the passes (what each lacks), or the GPU misbehaved.
    #[error("GPU: {0}")]
    Gpu(String),
    /// A request to wgpu failed: opening the device, waiting on it, mapping a buffer.
    #[error("GPU: {operation}: {source}")]
    Wgpu {
        /// What the renderer was doing.
        operation: &'static str,
        /// wgpu's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The GPU refused a request (a wgpu validation error).
    #[error("GPU refused a request while {operation}: {message}")]
    GpuValidation {
        /// What the renderer was doing.
        operation: &'static str,
        /// wgpu's description.
        message: String,
    },
    /// The GPU ran out of memory.
    #[error("GPU out of memory while {operation}: {message}")]
    GpuOutOfMemory {
        /// What the renderer was doing.
        operation: &'static str,
        /// wgpu's description.
        message: String,
    },
    /// The field file.
    #[error(transparent)]
    Field(#[from] frf_reflectance::ReflectanceError),
    /// Images, cameras, environments.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
}

impl RenderError {
    /// Who is at fault ([`frf_core::Fault`]).
    pub fn fault(&self) -> frf_core::Fault {
        use frf_core::Fault;
        match self {
            RenderError::Argument(_)
            | RenderError::Mismatch { .. }
            | RenderError::ViewNotHeld { .. }
            | RenderError::NotRelightable { .. }
            | RenderError::NotRenderable { .. } => Fault::Usage,
            RenderError::BadCamera(_) => Fault::Damaged,
            RenderError::Misuse(_) => Fault::Internal,
            RenderError::Gpu(_)
            | RenderError::Wgpu { .. }
            | RenderError::GpuValidation { .. }
            | RenderError::GpuOutOfMemory { .. } => Fault::Gpu,
            RenderError::Field(e) => e.fault(),
            RenderError::Core(e) => e.fault(),
        }
    }
}
