//! Errors the renderer can report.

use thiserror::Error;

/// The message for a machine without any usable adapter; it says what to install.
pub const NO_ADAPTER_HELP: &str = "no GPU adapter found: install a GPU driver, or the software Vulkan driver: \
     apt-get install mesa-vulkan-drivers libvulkan1";

/// Everything the renderer can refuse, with the offending value named.
#[derive(Debug, Error)]
pub enum RenderError {
    /// No adapter for the requested backends (`WGPU_BACKEND` narrows them).
    #[error("{NO_ADAPTER_HELP} (backends tried: {backends}; wgpu said: {reason})")]
    NoAdapter { backends: String, reason: String },
    #[error("could not open the GPU device on '{adapter}': {reason}")]
    Device { adapter: String, reason: String },
    #[error("invalid render settings: {0}")]
    Settings(String),
    #[error("scene '{source_name}': {problem}")]
    Scene { source_name: String, problem: String },
    #[error("custom shader does not compile: {0}")]
    CustomShader(String),
    /// The message carries the cause's text, so the cause is not chained as well (`{:#}`
    /// printers would repeat it).
    #[error("colour data: {0}")]
    Color(color::ColorError),
    #[error("GPU error: {0}")]
    Gpu(String),
    #[error("reading back from the GPU failed: {0}")]
    Readback(String),
    /// The process's cancellation token ([`color::cancel`]) was set while waiting for the GPU.
    #[error("interrupted")]
    Cancelled,
}

impl From<color::ColorError> for RenderError {
    fn from(e: color::ColorError) -> Self {
        RenderError::Color(e)
    }
}

/// A colour error is shown once, not once more as its own cause.
#[test]
fn a_colour_error_is_not_its_own_cause() {
    let e = RenderError::from(color::ColorError::NoSamples);
    assert!(e.to_string().contains("at least 1"), "{e}");
    assert!(std::error::Error::source(&e).is_none());
}

pub type Result<T, E = RenderError> = std::result::Result<T, E>;
