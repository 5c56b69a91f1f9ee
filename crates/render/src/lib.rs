//! Real-time spectral deferred rendering with wgpu.
//!
//! Four passes (plus one shadow map per light): G-buffer → spectral shading → custom → post.
//! The shading pass turns each pixel's RGB base colour into a Jakob–Hanika sigmoid spectrum,
//! evaluates it at N node wavelengths, and integrates it with a Lambert + GGX BRDF against each
//! light's precomputed node weights (light × observer × quadrature rule, prefiltered by default:
//! `color::quadrature`) into XYZ and linear sRGB. Three modes switch per frame: `rgb` (classic,
//! baseline; its own shading entry point), `naive` (box upsampling) and `spectral`.
//!
//! Conventions (so that `spectral` equals `rgb` for diffuse surfaces under D65-white lights):
//! lights without a spectrum are upsampled with the "illuminant" variant (`s·ρ(rgb/s)·D65`,
//! `s = 2·max`), spectral lights are scaled to the luminance of their `rgb × intensity`, the
//! emission weights give D65 a luminance of 1, and the XYZ → RGB matrix is corrected so that
//! the sampled D65 maps exactly to the sRGB white.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let scene: scene::Scene = unimplemented!();
//! let mut r = render::Renderer::new()?;
//! r.set_scene(&scene)?;
//! r.resize(64, 64)?;
//! r.render(&scene.camera, &render::RenderSettings::default())?;
//! let rgba8 = r.read_ldr()?;
//! # Ok(()) }
//! ```

pub mod coeff_table;
#[cfg(test)]
mod compute_tests;
pub mod env_gpu;
pub mod environment;
pub mod error;
#[cfg(test)]
mod film_tests;
#[cfg(test)]
mod gbuffer_tests;
pub mod gpu;
#[cfg(test)]
mod layout_tests;
pub mod ltc;
pub mod material_spectra;
pub mod passes;
mod readback;
pub mod renderer;
pub mod scene_gpu;
pub mod settings;
mod shader;
pub mod spectral_data;
pub mod targets;
pub mod timing;
pub mod uniforms;

pub use error::{NO_ADAPTER_HELP, RenderError, Result};
pub use gpu::Gpu;
pub use passes::custom::CustomShader;
pub use passes::shading::ShadingStage;
pub use renderer::{Renderer, SpectralCapture};
pub use settings::{Mode, RenderSettings, Tonemap};
pub use spectral_data::SpectralSetup;
pub use timing::PassTimings;
