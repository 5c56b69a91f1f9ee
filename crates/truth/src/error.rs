//! What the path tracer can refuse, each message naming the offending input.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum TruthError {
    #[error("samples per pixel must be at least 1 (got 0)")]
    NoSamples,
    #[error("image size {0}×{1} is invalid: both sides must be at least 1 pixel")]
    BadSize(u32, u32),
    #[error(
        "image size {0}×{1} is too large: at most {max_side} pixels a side and {max_px} pixels (8192×8192) in all",
        max_side = crate::render::MAX_SIDE,
        max_px = crate::render::MAX_PIXELS
    )]
    TooLarge(u32, u32),
    #[error("crop window {0}")]
    BadCrop(String),
    #[error("sample range: {0}")]
    BadSamples(String),
    #[error("spectral output: {0}")]
    BadBands(String),
    #[error("invalid medium: {0}")]
    BadMedium(String),
    #[error("scene '{scene}': {why}")]
    BadScene { scene: String, why: String },
    #[error(transparent)]
    Color(#[from] color::ColorError),
    #[error("rendering was interrupted")]
    Cancelled,
    #[error("writing {path}: {source}")]
    Io { path: String, source: std::io::Error },
}

pub type Result<T, E = TruthError> = std::result::Result<T, E>;
