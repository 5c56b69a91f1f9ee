//! WGSL assembly: naga has no `#include`, so each pass's module is its own file with the shared
//! include files concatenated in front of it.

use crate::error::{RenderError, Result};

pub(crate) const COMMON: &str = include_str!("wgsl/common.wgsl");
pub(crate) const SPECTRAL: &str = include_str!("wgsl/spectral.wgsl");
pub(crate) const ENVIRONMENT: &str = include_str!("wgsl/environment.wgsl");
pub(crate) const CUSTOM_API: &str = include_str!("wgsl/custom_api.wgsl");
/// `pcg_hash` and friends: integer hashes, identical on every driver.
pub(crate) const HASH: &str = include_str!("wgsl/hash.wgsl");
/// Needs [`HASH`] before it.
pub(crate) const MATERIAL: &str = include_str!("wgsl/material.wgsl");
/// Thin-film interference: `scene::film` in WGSL, and the RGB mode's Belcour–Barla film.
pub(crate) const FILM: &str = include_str!("wgsl/film.wgsl");
/// `KHR_materials_sheen` (shading pass).
pub(crate) const SHEEN: &str = include_str!("wgsl/sheen.wgsl");

/// Concatenates `parts` and compiles them, turning validation errors into a [`RenderError`]
/// instead of wgpu's default panic (custom shaders come from users).
pub(crate) fn compile(device: &wgpu::Device, label: &str, parts: &[&str]) -> Result<wgpu::ShaderModule> {
    let source = parts.join("\n");
    checked(device, label, || {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        })
    })
    .map_err(|e| match e {
        RenderError::Gpu(m) => RenderError::CustomShader(m),
        other => other,
    })
}

/// Runs `f` (pipeline creation) inside validation, internal (shader translation) and
/// out-of-memory error scopes, so that none of them reaches wgpu's panicking default handler.
pub(crate) fn checked<T>(device: &wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T> {
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let value = f();
    let errors = [memory, internal, validation].map(|scope| pollster::block_on(scope.pop()));
    match errors.into_iter().flatten().next() {
        None => Ok(value),
        Some(e) => Err(RenderError::Gpu(format!("{what}: {}", describe(&e)))),
    }
}

/// A wgpu error on one line (its `Display` already lists the causes, over several lines).
pub(crate) fn describe(e: &wgpu::Error) -> String {
    e.to_string().split_whitespace().collect::<Vec<_>>().join(" ")
}
