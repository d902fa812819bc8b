//! The error of building or running a scene.

/// Why a scene could not be loaded, built or run. Its message is one line
/// that names the field and the value at fault.
///
/// ```
/// use topple::rapier::scene::{run_scene, Engine, RunOptions, Scene, SceneError};
/// use topple::rapier::Precision;
/// let scene: Scene = toml::from_str("duration = 1.0\n[solver]\ndt = 0.0").unwrap();
/// let err = run_scene(&scene, Engine::Rapier, Precision::F64, RunOptions::default()).unwrap_err();
/// assert!(matches!(err, SceneError::Invalid(_)));
/// assert!(err.to_string().contains("dt"));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A value of the scene is out of its range or inconsistent.
    #[error("{0}")]
    Invalid(String),
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
    /// An [`SceneError::Invalid`] with this message.
    pub fn invalid(message: impl Into<String>) -> Self {
        SceneError::Invalid(message.into())
    }
}

/// `Result` with a [`SceneError`].
pub type SceneResult<T> = Result<T, SceneError>;
