//! The error type of the renderer.

/// Result alias of this crate.
pub type Result<T, E = RenderError> = std::result::Result<T, E>;

/// Everything that can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A parameter is out of range (camera path, size, frames, pose).
    #[error("{0}")]
    BadParameter(String),
    /// No GPU adapter, or the GPU failed.
    #[error("GPU: {0}")]
    Gpu(String),
    /// The field file.
    #[error(transparent)]
    Field(#[from] frf_reflectance::ReflectanceError),
    /// Images, cameras, environments.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
}
