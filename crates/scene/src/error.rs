//! Everything the scene loader can refuse, each message naming the file and the place in it.

use std::path::PathBuf;

use thiserror::Error;

/// A scene could not be loaded. Every variant names the file (or `builtin:NAME`) and, where it
/// applies, the glTF index or the JSON field (`materials[2].extras.reflectance.sampled`) at fault,
/// so a CLI can print the message as it is.
///
/// The underlying error (I/O, glTF parser) is part of the message and deliberately *not* exposed
/// as [`std::error::Error::source`]: callers that print the whole chain (`anyhow`'s `{:#}`) would
/// otherwise show it twice.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The file (or a file it references) could not be read.
    #[error("{}: cannot read {}: {cause}", path.display(), file.display())]
    Io {
        /// The scene file.
        path: PathBuf,
        /// The file that failed: the scene itself, a buffer, an image or a CSV spectrum.
        file: PathBuf,
        cause: std::io::Error,
    },
    /// The bytes are not a glTF 2.0 document (bad JSON, bad GLB header, failed validation).
    #[error("{}: not a valid glTF 2.0 file: {cause}", path.display())]
    Gltf { path: PathBuf, cause: gltf::Error },
    /// The document parsed but something in it cannot be used; `at` is a glTF path such as
    /// `meshes[0].primitives[1]`.
    #[error("{}: {at}: {message}", path.display())]
    Invalid { path: PathBuf, at: String, message: String },
    /// An `extras` field (spectral additions) is malformed; `field` is its JSON path.
    #[error("{}: {field}: {message}", path.display())]
    Extras { path: PathBuf, field: String, message: String },
    /// A CSV spectrum referenced from `field` has a bad line.
    #[error("{}: {field}: {}: line {line}: {message}", path.display(), csv.display())]
    Csv { path: PathBuf, field: String, csv: PathBuf, line: u64, message: String },
    /// `load_any` got a name that is neither a built-in scene nor a `.gltf`/`.glb` path.
    #[error(
        "unknown built-in scene '{name}'; built-in scenes are: {known} (or give a path ending in .gltf or .glb)"
    )]
    UnknownBuiltin { name: String, known: String },
}

pub type Result<T, E = SceneError> = std::result::Result<T, E>;
