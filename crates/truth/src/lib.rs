//! `truth`: a CPU spectral path tracer that renders exactly the [`scene::Scene`] the
//! real-time renderer draws, as ground truth for it.
//!
//! - Camera, lights (point, spot with the glTF cone falloff, directional, emissive meshes) and
//!   the glTF metallic-roughness BRDF follow the glTF specification, as the rasteriser does.
//! - Reflectances are measured spectra where the material has them, otherwise the same
//!   Jakob–Hanika upsampling the renderer uses ([`upsample::RgbToSpectrum`]).
//! - Hero-wavelength sampling (four wavelengths per path), next-event estimation with MIS for
//!   emissive meshes and the environment map ([`env_map`], importance-sampled ∝ luminance),
//!   Russian roulette, a homogeneous participating medium ([`Medium`]).
//! - Output is XYZ with the normalisation of [`color::SpectralIntegrator`]: a perfect white lit
//!   by the scene white has Y = 1, and an RGB (1,1,1) D65 light gives the RGB renderer's values.
//! - Deterministic for a seed (per-pixel random streams), cancellable, reports progress.

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod coat;
pub mod dielectric;
pub mod env_map;
pub mod error;
pub mod export_mitsuba;
pub mod integrator;
pub mod lights;
pub mod material;
pub mod medium;
pub mod medium_file;
pub mod render;
pub mod rng;
pub mod sampling;
pub mod spectral;
pub mod texture;
pub mod upsample;
pub mod water;
pub mod water_surface;
pub mod world;

#[cfg(test)]
mod gltf_features_tests;
#[cfg(test)]
mod near_plane_tests;
#[cfg(test)]
mod rgb_medium_tests;
#[cfg(test)]
mod testing;
#[cfg(test)]
mod transmission_tests;

pub use error::{Result, TruthError};
pub use medium::{Medium, Phase, Region};
pub use render::{Accumulator, Crop, Settings, XyzImage, render, render_pass, render_world};
pub use upsample::RgbToSpectrum;
pub use world::World;
