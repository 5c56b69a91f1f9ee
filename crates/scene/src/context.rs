//! Where a scene comes from, so that every error can name the file and resolve relative paths.

use std::path::{Path, PathBuf};

use crate::error::SceneError;

/// The file being loaded and the directory its relative URIs are resolved against.
#[derive(Clone, Debug)]
pub(crate) struct Ctx {
    pub path: PathBuf,
    /// `None` for built-in scenes: they reference no files.
    pub dir: Option<PathBuf>,
}

impl Ctx {
    pub fn file(path: &Path) -> Self {
        let dir = path
            .parent()
            .map(|p| if p.as_os_str().is_empty() { PathBuf::from(".") } else { p.to_path_buf() });
        Ctx { path: path.to_path_buf(), dir }
    }

    pub fn builtin(name: &str) -> Self {
        Ctx { path: PathBuf::from(format!("builtin:{name}")), dir: None }
    }

    pub fn extras(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Extras { path: self.path.clone(), field: field.into(), message: message.into() }
    }

    pub fn invalid(&self, at: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid { path: self.path.clone(), at: at.into(), message: message.into() }
    }

    pub fn io(&self, file: &Path, source: std::io::Error) -> SceneError {
        SceneError::Io { path: self.path.clone(), file: file.to_path_buf(), cause: source }
    }

    /// Resolves a relative reference (already percent-decoded) against the scene's directory.
    /// `at` names the referring field for the error when the scene has no directory.
    pub fn resolve(&self, at: &str, rel: &str) -> Result<PathBuf, SceneError> {
        match &self.dir {
            Some(d) => Ok(d.join(rel)),
            None => {
                Err(self.invalid(at, format!("'{rel}' is a file reference, but this scene has no directory")))
            }
        }
    }
}
