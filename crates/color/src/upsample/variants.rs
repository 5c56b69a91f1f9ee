//! pbrt-v4-style spectra built on a reflectance table: unbounded RGB and illuminants.
//!
//! A reflectance table covers RGB in [0, 1]. For values above 1 (albedo-like data that is
//! not a reflectance, or radiance) pbrt-v4 scales the colour into the table's range:
//! `scale = 2·max(rgb)`, the table is looked up at `rgb / scale` (largest channel ½, away from
//! the extreme spectra near 1), and the spectrum is `scale · s(λ)`. An illuminant additionally
//! multiplies by the colour space's illuminant spectrum, so that RGB (1, 1, 1) emits exactly
//! that illuminant (D65 for sRGB) rather than an equal-energy spectrum.

use crate::error::Result;
use crate::spectrum::Spectrum;
use crate::upsample::sigmoid::SigmoidPolynomial;
use crate::upsample::table::{CoeffTable, check_rgb};

/// pbrt-v4's split of a colour of any magnitude into `scale · rgb'`: `scale = 2·max(rgb)` and
/// `rgb' = rgb / scale` (largest channel ½, negative channels clamped to 0), so a reflectance
/// table looked up at `rgb'` times `scale` is the colour's spectrum. `None` for black (and an
/// all-NaN colour): the spectrum is 0. The one place this convention is written; the
/// real-time renderer, the path tracer and the environment maps all split emission with it.
pub fn unbounded_split(rgb: [f64; 3]) -> Option<(f64, [f64; 3])> {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m.is_nan() || m <= 0.0 {
        return None;
    }
    let scale = 2.0 * m;
    Some((scale, rgb.map(|c| (c / scale).max(0.0))))
}

/// `scale · s(λ)`: any non-negative RGB, including values above 1.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct UnboundedSpectrum {
    pub poly: SigmoidPolynomial,
    pub scale: f64,
}

impl UnboundedSpectrum {
    /// pbrt-v4's construction; black gets scale 0 (the spectrum is exactly 0).
    pub fn new(table: &CoeffTable, rgb: [f64; 3]) -> Result<Self> {
        check_rgb(rgb)?;
        Ok(Self::clamped(table, rgb))
    }

    /// As [`Self::new`] for emission, which is not validated here: negative channels count as
    /// 0 and black or NaN gives the zero spectrum.
    pub fn clamped(table: &CoeffTable, rgb: [f64; 3]) -> Self {
        match unbounded_split(rgb) {
            Some((scale, c)) => UnboundedSpectrum { poly: table.fetch(c), scale },
            None => UnboundedSpectrum { poly: table.fetch([0.0; 3]), scale: 0.0 },
        }
    }

    #[inline]
    pub fn eval(&self, lambda: f64) -> f64 {
        self.scale * self.poly.eval(lambda)
    }
}

/// `scale · s(λ) · E(λ)` with `E` the colour space's illuminant: an emitter whose colour,
/// integrated with [`crate::SpectralIntegrator::emission`] against `E` as white, is the RGB.
#[derive(Clone, Debug, PartialEq)]
pub struct IlluminantSpectrum {
    pub unbounded: UnboundedSpectrum,
    pub illuminant: Spectrum,
}

impl IlluminantSpectrum {
    pub fn new(table: &CoeffTable, rgb: [f64; 3], illuminant: Spectrum) -> Result<Self> {
        Ok(IlluminantSpectrum { unbounded: UnboundedSpectrum::new(table, rgb)?, illuminant })
    }

    #[inline]
    pub fn eval(&self, lambda: f64) -> f64 {
        self.unbounded.eval(lambda) * self.illuminant.eval(lambda)
    }
}
