//! Colour science for spectra: spectral data, observers, illuminants, colour spaces,
//! CIELAB and CIEDE2000, and RGB→spectrum upsampling. No GPU code lives here; the renderer
//! and the path tracer both build on it.

pub mod data;
pub mod error;
pub mod illuminant;
pub mod observer;
pub mod spectrum;
pub mod water;
pub mod wavelengths;
pub mod xyz;

pub use error::{ColorError, Result};
pub use observer::Observer;
pub use spectrum::Spectrum;
pub use wavelengths::{SampledWavelengths, WavelengthRange};
pub use xyz::SpectralIntegrator;
