//! Errors in what a user wrote: what is wrong, in which file, at which line
//! and column. The scene loader raises them while it reads a scene, extract
//! while it builds the scene's modules and animates it.

use crate::world::ModuleSpec;
use radiant_core::ParamError;
use radiant_core::params::Location;
use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with a scene file or a file it references.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The scene file (or the referenced file) at fault.
    pub file: PathBuf,
    /// The place in `file`, when known.
    pub location: Option<Location>,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl SceneError {
    /// An error at `location` in `file`.
    pub fn new(file: &Path, location: Option<Location>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            location,
            message: message.into(),
        }
    }

    /// Attaches a module's parameter error to `file`.
    pub fn from_param(file: &Path, err: ParamError) -> Self {
        Self::new(file, err.location, err.message)
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.location {
            Some(l) => write!(
                f,
                "{}:{}:{}: {}",
                self.file.display(),
                l.line,
                l.column,
                self.message
            ),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for SceneError {}

/// Turns a registry error about module `spec` into a scene error.
pub(crate) fn module_error(
    file: &Path,
    spec: &ModuleSpec,
    err: radiant_core::registry::BuildError,
) -> SceneError {
    use radiant_core::registry::BuildError;
    match err {
        BuildError::UnknownType { .. } => SceneError::new(file, spec.location, err.to_string()),
        BuildError::Params(p) => SceneError::new(file, p.location.or(spec.location), p.message),
    }
}
