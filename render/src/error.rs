//! The error type of the renderer.

/// Result alias of this crate.
pub type Result<T, E = RenderError> = std::result::Result<T, E>;

/// Everything that can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A parameter is out of range (camera path, size, frames, pose).
    #[error("{0}")]
    BadParameter(String),
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
            RenderError::BadParameter(_) => Fault::Usage,
            RenderError::Gpu(_)
            | RenderError::Wgpu { .. }
            | RenderError::GpuValidation { .. }
            | RenderError::GpuOutOfMemory { .. } => Fault::Gpu,
            RenderError::Field(e) => e.fault(),
            RenderError::Core(e) => e.fault(),
        }
    }
}
