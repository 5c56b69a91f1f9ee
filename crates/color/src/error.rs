use thiserror::Error;

/// Everything the colour core can refuse. Messages name the offending value so a CLI can print
/// them as they are.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ColorError {
    #[error("wavelength range {min}–{max} nm is invalid: {why}")]
    BadRange { min: f64, max: f64, why: String },
    #[error("wavelength range '{0}': expected MIN:MAX in nm, e.g. 380:730")]
    BadRangeText(String),
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

/// `x` as an error message shows a value: as Rust writes it where that is short, in exponent
/// form outside 1e-4…1e15 (Rust writes 1e300 as 301 digits).
pub fn show(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn values_in_messages_stay_short() {
        assert_eq!(super::show(1e300), "1e300");
        assert_eq!(super::show(-2.5e-9), "-2.5e-9");
        assert_eq!(super::show(0.05), "0.05");
        assert_eq!(super::show(f64::NAN), "NaN");
        assert_eq!(super::show(123456.0), "123456");
    }
}
