//! One interface over the upsampling methods the evaluation compares.

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use crate::colorspace::RgbColorSpace;
use crate::error::{ColorError, Result};
use crate::upsample::boxes::BoxSpectrum;
use crate::upsample::sigmoid::SigmoidPolynomial;
use crate::upsample::smits::SmitsSpectrum;
use crate::upsample::table::{CoeffTable, check_rgb};

/// Which RGB → reflectance method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Jakob & Hanika 2019 sigmoid polynomials from a coefficient table.
    Jakob,
    /// Smits 1999 seven-spectrum basis.
    Smits,
    /// One box per channel ([`crate::upsample::boxes`]).
    Box,
}

impl Method {
    pub const ALL: [Method; 3] = [Method::Jakob, Method::Smits, Method::Box];
    pub const NAMES: [&'static str; 3] = ["jakob", "smits", "box"];

    pub fn name(self) -> &'static str {
        match self {
            Method::Jakob => "jakob",
            Method::Smits => "smits",
            Method::Box => "box",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = ColorError;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "jakob" | "jakob2019" | "jh" | "sigmoid" => Ok(Method::Jakob),
            "smits" | "smits1999" => Ok(Method::Smits),
            "box" | "boxes" => Ok(Method::Box),
            _ => Err(ColorError::Unknown {
                kind: "upsampling method",
                name: s.into(),
                known: Method::NAMES.join(", "),
            }),
        }
    }
}

/// A reflectance produced by any method; evaluates at λ in nanometres.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum Reflectance {
    Jakob(SigmoidPolynomial),
    Smits(SmitsSpectrum),
    Box(BoxSpectrum),
}

impl Reflectance {
    #[inline]
    pub fn eval(&self, lambda: f64) -> f64 {
        match self {
            Reflectance::Jakob(p) => p.eval(lambda),
            Reflectance::Smits(s) => s.eval(lambda),
            Reflectance::Box(b) => b.eval(lambda),
        }
    }
}

/// RGB reflectance → spectral reflectance.
pub trait Upsampler: Send + Sync {
    /// The method this is.
    fn method(&self) -> Method;
    /// Spectrum of a linear RGB reflectance in [0, 1]; NaN, negative or above-1 input is an error.
    fn reflectance(&self, rgb: [f64; 3]) -> Result<Reflectance>;
}

fn check_unit(rgb: [f64; 3]) -> Result<()> {
    check_rgb(rgb)?;
    if rgb.iter().any(|&v| v > 1.0) {
        return Err(ColorError::Table(format!(
            "RGB ({}, {}, {}) is not a reflectance: components must be at most 1",
            rgb[0], rgb[1], rgb[2]
        )));
    }
    Ok(())
}

/// Jakob–Hanika through a coefficient table.
pub struct Jakob(pub Arc<CoeffTable>);

impl Upsampler for Jakob {
    fn method(&self) -> Method {
        Method::Jakob
    }
    fn reflectance(&self, rgb: [f64; 3]) -> Result<Reflectance> {
        check_unit(rgb)?;
        Ok(Reflectance::Jakob(self.0.fetch(rgb)))
    }
}

/// Smits 1999.
pub struct Smits;

impl Upsampler for Smits {
    fn method(&self) -> Method {
        Method::Smits
    }
    fn reflectance(&self, rgb: [f64; 3]) -> Result<Reflectance> {
        check_unit(rgb)?;
        Ok(Reflectance::Smits(SmitsSpectrum::from_rgb(rgb)))
    }
}

/// Box per channel.
pub struct BoxBasis;

impl Upsampler for BoxBasis {
    fn method(&self) -> Method {
        Method::Box
    }
    fn reflectance(&self, rgb: [f64; 3]) -> Result<Reflectance> {
        check_unit(rgb)?;
        Ok(Reflectance::Box(BoxSpectrum { rgb }))
    }
}

/// The upsampler for `method` in `space` (Jakob loads or fits the space's table through
/// [`crate::upsample::table()`]).
pub fn upsampler(method: Method, space: &RgbColorSpace) -> Result<Box<dyn Upsampler>> {
    Ok(match method {
        Method::Jakob => Box::new(Jakob(crate::upsample::table_for(space)?)),
        Method::Smits => Box::new(Smits),
        Method::Box => Box::new(BoxBasis),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses() {
        assert_eq!("Jakob".parse::<Method>().unwrap(), Method::Jakob);
        assert_eq!("smits".parse::<Method>().unwrap(), Method::Smits);
        assert_eq!("box".parse::<Method>().unwrap(), Method::Box);
        let e = "rgb".parse::<Method>().unwrap_err().to_string();
        assert!(e.contains("rgb") && e.contains("jakob, smits, box"), "{e}");
        for m in Method::ALL {
            assert_eq!(m.to_string().parse::<Method>().unwrap(), m);
        }
    }

    #[test]
    fn baselines_refuse_bad_rgb() {
        for u in [&Smits as &dyn Upsampler, &BoxBasis] {
            assert!(matches!(u.reflectance([f64::NAN, 0.0, 0.0]), Err(ColorError::BadRgb(..))));
            assert!(matches!(u.reflectance([0.0, -0.5, 0.0]), Err(ColorError::BadRgb(..))));
            assert!(u.reflectance([0.0, 1.5, 0.0]).is_err());
            assert!(u.reflectance([0.2, 0.5, 1.0]).is_ok());
        }
    }
}
