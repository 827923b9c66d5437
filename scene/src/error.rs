//! The error type of scenes: each fault in its class. A scene file's mistakes name the
//! file, the field and its line; a camera path's, its key; a bad argument names itself
//! as the user gave it ([`frf_core::BadArgument`]); a field that lacks what the frames
//! need says what to ingest; the renderer's, the field's and the files' errors pass
//! through.

use std::path::PathBuf;

use frf_core::Fault;

/// Result alias of this crate.
pub type Result<T, E = SceneError> = std::result::Result<T, E>;

/// Everything that can go wrong with a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A field of a scene file holds a value it cannot take.
    #[error("scene {}: {field} ({place}): {problem}", path.display())]
    File {
        /// The scene file.
        path: PathBuf,
        /// The field, e.g. `camera.orbit.fov_deg`.
        field: String,
        /// Where: `line N`, or `(not given)`.
        place: String,
        /// What is wrong and what is allowed.
        problem: String,
    },
    /// A scene file that is not TOML of the scene's shape.
    #[error("scene {}{line}: {problem}", path.display())]
    Syntax {
        /// The scene file.
        path: PathBuf,
        /// ` (line N)`, or empty where the parser gives no place.
        line: String,
        /// The parser's message.
        problem: String,
    },
    /// A key of a camera path refused.
    #[error("key {key}: {problem}")]
    CameraKey {
        /// The key's index in the path.
        key: usize,
        /// What is wrong and what is allowed.
        problem: String,
    },
    /// A camera path file refused.
    #[error("camera path {}: {problem}", path.display())]
    CameraPath {
        /// The file.
        path: PathBuf,
        /// Why: its syntax, or a key refused.
        problem: String,
    },
    /// A scene that names no field, given none on the command line.
    #[error("{}: no field (give field = \"...\" or --field)", scene.display())]
    NoField {
        /// The scene file.
        scene: PathBuf,
    },
    /// The field lacks what the scene's frames need (views, pose-to-pose flows).
    #[error("{}: {problem}", field.display())]
    FieldLacks {
        /// The field file.
        field: PathBuf,
        /// What is missing and how to make a field that holds it.
        problem: String,
    },
    /// An output directory that cannot take this render.
    #[error("{}: {problem}", dir.display())]
    Output {
        /// The directory given with `--out`.
        dir: PathBuf,
        /// Why, and what to do.
        problem: String,
    },
    /// The poses a frame needs do not fit the memory budget.
    #[error(
        "frame {frame} needs {needed_mb:.1} MB of resident poses, more than the memory budget of {budget_mb:.1} MB (--memory-budget)"
    )]
    MemoryBudget {
        /// The frame.
        frame: usize,
        /// What its poses hold, MB.
        needed_mb: f64,
        /// The budget, MB.
        budget_mb: f64,
    },
    /// A call the scene's state does not allow (a frame not planned, a live frame on the
    /// CPU): the program's own mistake.
    #[error("{0}")]
    Misuse(&'static str),
    /// The program failed (a worker panicked, a report that does not serialize).
    #[error("{0}")]
    Internal(String),
    /// An argument outside what is allowed.
    #[error(transparent)]
    Argument(#[from] frf_core::BadArgument),
    /// The renderer.
    #[error(transparent)]
    Render(#[from] frf_render::RenderError),
    /// The field file.
    #[error(transparent)]
    Field(#[from] frf_reflectance::ReflectanceError),
    /// Images, cameras, environments, files.
    #[error(transparent)]
    Core(#[from] frf_core::CoreError),
    /// A sprite sheet's option out of range (`crate::sprites`).
    #[error("{0}")]
    Sprites(String),
}

impl SceneError {
    /// Who is at fault ([`Fault`]).
    pub fn fault(&self) -> Fault {
        match self {
            SceneError::File { .. }
            | SceneError::Syntax { .. }
            | SceneError::CameraKey { .. }
            | SceneError::CameraPath { .. }
            | SceneError::NoField { .. }
            | SceneError::FieldLacks { .. }
            | SceneError::Output { .. }
            | SceneError::MemoryBudget { .. }
            | SceneError::Sprites(_)
            | SceneError::Argument(_) => Fault::Usage,
            SceneError::Misuse(_) | SceneError::Internal(_) => Fault::Internal,
            SceneError::Render(e) => e.fault(),
            SceneError::Field(e) => e.fault(),
            SceneError::Core(e) => e.fault(),
        }
    }
}
