//! Where a scene comes from, so that every error can name the file and resolve relative paths.

use std::path::{Component, Path, PathBuf};

use crate::error::SceneError;

/// The file being loaded and the directory its relative URIs are resolved against.
#[derive(Clone, Debug)]
pub(crate) struct Ctx {
    pub path: PathBuf,
    /// `None` for built-in scenes: they reference no files.
    pub dir: Option<PathBuf>,
    /// Whether file references may leave `dir` (`--allow-outside-scene-dir`).
    pub allow_outside: bool,
    /// Every file read so far: the scene file, then each reference as it is resolved
    /// ([`crate::Scene::inputs`]).
    pub inputs: std::cell::RefCell<Vec<PathBuf>>,
    /// Each input's [`color::input::FileStamp`] when it was taken ([`crate::Scene::input_stamps`]).
    pub stamps: std::cell::RefCell<Vec<Option<color::input::FileStamp>>>,
}

impl Ctx {
    pub fn file(path: &Path) -> Self {
        let dir = path
            .parent()
            .map(|p| if p.as_os_str().is_empty() { PathBuf::from(".") } else { p.to_path_buf() });
        Ctx {
            path: path.to_path_buf(),
            dir,
            allow_outside: false,
            inputs: vec![path.to_path_buf()].into(),
            stamps: vec![color::input::stamp(path)].into(),
        }
    }

    pub fn builtin(name: &str) -> Self {
        Ctx {
            path: PathBuf::from(format!("builtin:{name}")),
            dir: None,
            allow_outside: false,
            inputs: Vec::new().into(),
            stamps: Vec::new().into(),
        }
    }

    pub fn extras(&self, field: impl Into<String>, message: impl std::fmt::Display) -> SceneError {
        SceneError::Extras { path: self.path.clone(), field: field.into(), message: message.to_string() }
    }

    pub fn invalid(&self, at: impl Into<String>, message: impl std::fmt::Display) -> SceneError {
        SceneError::Invalid { path: self.path.clone(), at: at.into(), message: message.to_string() }
    }

    pub fn io(&self, file: &Path, source: std::io::Error) -> SceneError {
        SceneError::Io { path: self.path.clone(), file: file.to_path_buf(), cause: source }
    }

    /// Resolves a relative reference (already percent-decoded) against the scene's directory.
    /// `at` names the referring field for the error.
    ///
    /// Unless `allow_outside` is set, the reference must stay inside the scene's folder: no
    /// absolute path, no `..` component, and no symlink that resolves outside the folder. A scene
    /// downloaded from anywhere must not be able to read (and leak into a render or a message)
    /// files such as `~/.ssh/id_ed25519` or `/etc/shadow`. The rule is in docs/scene-format.md.
    pub fn resolve(&self, at: &str, rel: &str) -> Result<PathBuf, SceneError> {
        let Some(d) = &self.dir else {
            return Err(
                self.invalid(at, format!("'{rel}' is a file reference, but this scene has no directory"))
            );
        };
        if self.allow_outside {
            let p = d.join(rel);
            self.inputs.borrow_mut().push(p.clone());
            self.stamps.borrow_mut().push(color::input::stamp(&p));
            return Ok(p);
        }
        let refuse = |why: &str| {
            self.invalid(
                at,
                format!(
                    "'{rel}' {why}; file references must stay inside the scene's folder \
                     (--allow-outside-scene-dir lifts this)"
                ),
            )
        };
        let p = Path::new(rel);
        if p.has_root() || p.components().any(|c| matches!(c, Component::Prefix(_) | Component::RootDir)) {
            return Err(refuse("is an absolute path"));
        }
        if p.components().any(|c| c == Component::ParentDir) {
            return Err(refuse("contains '..'"));
        }
        let joined = d.join(p);
        // Symlinks: compare where the file really is with where the folder really is. A file
        // that does not exist yet is left for the read to report.
        if let (Ok(real), Ok(root)) = (joined.canonicalize(), d.canonicalize())
            && !real.starts_with(&root)
        {
            return Err(refuse("resolves (through a symbolic link) outside the folder"));
        }
        self.inputs.borrow_mut().push(joined.clone());
        self.stamps.borrow_mut().push(color::input::stamp(&joined));
        Ok(joined)
    }
}
