//! Errors of the compare crate. Every variant that concerns a file names it, so the binary can
//! print the message as is.

use std::path::PathBuf;

/// Result alias for this crate.
pub type Result<T> = std::result::Result<T, CompareError>;

#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// The file could not be opened, read, created or renamed.
    // The cause is part of the message rather than a `#[source]`, so anyhow's `{:#}` chain
    // does not print it twice.
    #[error("{path}: {error}")]
    Io { path: PathBuf, error: std::io::Error },
    /// The extension is not one we read or write.
    #[error("{path}: unsupported image extension {ext:?} (supported: .exr, .png)")]
    UnsupportedExtension { path: PathBuf, ext: String },
    /// The bytes are not a valid image of the format the extension promises.
    #[error("{path}: not a valid {format} image: {reason}")]
    Decode { path: PathBuf, format: &'static str, reason: String },
    /// An EXR file lacks the R, G or B channel.
    #[error("{path}: missing channel(s) {missing} (the file has: {present})")]
    MissingChannels { path: PathBuf, missing: String, present: String },
    /// Encoding failed before anything was written.
    #[error("{path}: cannot encode {format}: {reason}")]
    Encode { path: PathBuf, format: &'static str, reason: String },
    /// A pixel is NaN or infinite where a finite value is required.
    #[error("{what}: pixel ({x}, {y}) is not finite: {value:?}")]
    NonFinite { what: String, x: u32, y: u32, value: [f32; 3] },
    /// Two images hold different parts of their frames (EXR data and display windows) that
    /// cannot be lined up pixel for pixel.
    #[error("{0}")]
    Misplaced(String),
    /// Two images that must match in size do not.
    #[error("image sizes differ: reference is {}×{}, test is {}×{}", reference.0, reference.1, test.0, test.1)]
    SizeMismatch { reference: (u32, u32), test: (u32, u32) },
    /// Width × height does not match the pixel count, or a dimension is zero.
    #[error("invalid image: {0}")]
    InvalidImage(String),
    /// A caller-supplied option is out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
}

impl CompareError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        CompareError::Io { path: path.into(), error: source }
    }
}
