use thiserror::Error;

/// Everything the colour core can refuse. Messages name the offending value so a CLI can print
/// them as they are.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ColorError {
    #[error("wavelength range {min}–{max} nm is invalid: {why}")]
    BadRange { min: f64, max: f64, why: String },
    #[error("the number of wavelength samples must be at least 1 (got 0)")]
    NoSamples,
    #[error("invalid spectrum: {0}")]
    BadSpectrum(String),
    #[error("unknown {kind} '{name}'; known: {known}")]
    Unknown { kind: &'static str, name: String, known: String },
    #[error("invalid RGB value ({0}, {1}, {2}): components must be finite and non-negative")]
    BadRgb(f64, f64, f64),
    #[error("{0}")]
    Table(String),
}

pub type Result<T, E = ColorError> = std::result::Result<T, E>;
