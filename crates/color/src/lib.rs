//! Colour science for spectra: spectral data, observers, illuminants, colour spaces,
//! CIELAB and CIEDE2000, and RGB→spectrum upsampling. No GPU code lives here; the renderer
//! and the path tracer both build on it.

pub mod cancel;
pub mod colorspace;
pub mod data;
pub mod delta_e;
pub mod error;
pub mod film;
pub mod illuminant;
pub mod input;
pub mod lab;
pub mod metrics;
pub mod observer;
pub mod observer_file;
pub mod outfile;
pub mod progress;
pub mod quadrature;
pub mod signature;
pub mod spectrum;
pub mod table_text;
pub mod upsample;
pub mod water;
pub mod wavelengths;
pub mod xyz;

pub use colorspace::RgbColorSpace;
pub use delta_e::ciede2000;
pub use error::{ColorError, Result};
pub use lab::{lab_to_xyz, xyz_to_lab};
pub use observer::Observer;
pub use quadrature::Quadrature;
pub use spectrum::Spectrum;
pub use wavelengths::{SampledWavelengths, WavelengthRange};
pub use xyz::SpectralIntegrator;
