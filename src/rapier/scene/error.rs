//! The error of building or running a scene.

use crate::input::InputError;

/// Why a scene could not be loaded, built or run. Its message is one line
/// that names the field and the value at fault; a value out of its range
/// carries the structured [`InputError`] (field, value, allowed range).
///
/// ```
/// use topple::rapier::scene::{check_scene, Scene, SceneError};
/// let scene: Scene = toml::from_str("duration = 1.0\n[solver]\ndt = 0.0").unwrap();
/// let err = SceneError::from(check_scene(&scene).unwrap_err());
/// let SceneError::Invalid(e) = &err else { panic!("{err}") };
/// assert_eq!((e.field.as_str(), e.value.as_str()), ("solver.dt", "0"));
/// assert!(err.to_string().starts_with("solver.dt = 0: allowed"));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A value of the scene is out of its range: the field, the value as
    /// given and the allowed range.
    #[error("{0}")]
    Invalid(#[from] InputError),
    /// The scene names something it does not define or leaves out what a
    /// shape needs (an unknown material, a box without `size`): the message
    /// says which.
    #[error("{0}")]
    Inconsistent(String),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A scene file is not valid TOML for the format.
    #[error("{message}")]
    Parse {
        /// The file.
        path: std::path::PathBuf,
        /// `FILE:LINE:COLUMN: what is wrong`, on one line.
        message: String,
    },
    /// The run asks for a Rapier build that this build of topple does not
    /// compile (cargo features `f32` and `f64`).
    #[error("precision {}: topple was built without its cargo feature `{}`", .0.name(), .0.name())]
    NotBuilt(crate::rapier::Precision),
}

impl SceneError {
    /// A [`SceneError::Inconsistent`] with this message (for a value out
    /// of its range, use [`SceneError::Invalid`] with an [`InputError`]).
    pub fn invalid(message: impl Into<String>) -> Self {
        SceneError::Inconsistent(message.into())
    }
}

/// `Result` with a [`SceneError`].
pub type SceneResult<T> = Result<T, SceneError>;
