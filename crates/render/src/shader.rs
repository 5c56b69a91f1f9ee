//! WGSL assembly: naga has no `#include`, so each pass's module is its own file with the shared
//! include files concatenated in front of it.

use crate::error::{RenderError, Result};

pub(crate) const COMMON: &str = include_str!("wgsl/common.wgsl");
pub(crate) const SPECTRAL: &str = include_str!("wgsl/spectral.wgsl");
pub(crate) const CUSTOM_API: &str = include_str!("wgsl/custom_api.wgsl");

/// Concatenates `parts` and compiles them, turning validation errors into a [`RenderError`]
/// instead of wgpu's default panic (custom shaders come from users).
pub(crate) fn compile(device: &wgpu::Device, label: &str, parts: &[&str]) -> Result<wgpu::ShaderModule> {
    let source = parts.join("\n");
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    match pollster::block_on(scope.pop()) {
        None => Ok(module),
        Some(e) => Err(RenderError::CustomShader(format!("{label}: {e}"))),
    }
}

/// Runs `f` (pipeline creation) inside a validation error scope.
pub(crate) fn checked<T>(device: &wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = f();
    match pollster::block_on(scope.pop()) {
        None => Ok(value),
        Some(e) => Err(RenderError::Gpu(format!("{what}: {e}"))),
    }
}
