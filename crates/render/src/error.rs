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
    #[error("colour data: {0}")]
    Color(#[from] color::ColorError),
    #[error("GPU error: {0}")]
    Gpu(String),
    #[error("reading back from the GPU failed: {0}")]
    Readback(String),
    /// The process's cancellation token ([`color::cancel`]) was set while waiting for the GPU.
    #[error("interrupted")]
    Cancelled,
}

pub type Result<T, E = RenderError> = std::result::Result<T, E>;
