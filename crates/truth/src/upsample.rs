//! RGB → spectrum for the path tracer: reflectances and RGB light emission.
//!
//! The tracer needs one operation from the Jakob–Hanika machinery: the sigmoid-polynomial
//! coefficients of an RGB reflectance. It is behind a trait so the tracer can be tested
//! without a 9 MB table, and so any table `color::upsample` provides plugs in unchanged.

use glam::Vec4;

/// RGB reflectance → coefficients (c0, c1, c2) of s(λ) = S((c0·λ + c1)·λ + c2), λ in nm.
pub trait RgbToSpectrum: Send + Sync {
    /// `rgb` is linear, in [0, 1] (callers clamp).
    fn coefficients(&self, rgb: [f32; 3]) -> [f32; 3];
}

impl RgbToSpectrum for color::upsample::CoeffTable {
    fn coefficients(&self, rgb: [f32; 3]) -> [f32; 3] {
        self.fetch(rgb.map(|c| c as f64)).to_f32()
    }
}

/// The Jakob–Hanika sigmoid S(x) = ½ + x / (2·√(1 + x²)); 0 and 1 at ∓∞.
#[inline]
pub fn sigmoid(x: f32) -> f32 {
    // Clamped so x² stays finite; at |x| = 1e18 the result is 0 or 1 to f32 precision.
    let x = x.clamp(-1e18, 1e18);
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

/// Evaluates the reflectance spectrum of `c` at four wavelengths.
#[inline]
pub fn eval4(c: [f32; 3], l: Vec4) -> Vec4 {
    let x = (Vec4::splat(c[0]) * l + Vec4::splat(c[1])) * l + Vec4::splat(c[2]);
    Vec4::new(sigmoid(x.x), sigmoid(x.y), sigmoid(x.z), sigmoid(x.w))
}

/// A reflectance RGB at four wavelengths (clamped to [0, 1] first: the tables cover the cube).
pub fn reflectance(up: &dyn RgbToSpectrum, rgb: [f32; 3], l: Vec4) -> Vec4 {
    eval4(up.coefficients(rgb.map(|c| c.clamp(0.0, 1.0))), l)
}

/// The spectral shape of an RGB emitter, before multiplication by the colour space's
/// illuminant: an RGB of any magnitude is written scale·s(λ) with s the reflectance fit of
/// rgb/scale ([`color::upsample::variants::unbounded_split`], the "unbounded" form pbrt-v4
/// also uses), so (1,1,1) becomes exactly the illuminant itself.
pub fn emission_shape(up: &dyn RgbToSpectrum, rgb: [f32; 3], l: Vec4) -> Vec4 {
    match emission_coeffs(up, rgb) {
        Some((scale, c)) => eval4(c, l) * scale,
        None => Vec4::ZERO,
    }
}

/// The scale and sigmoid coefficients of [`emission_shape`], for callers that evaluate the
/// shape many times; `None` for black.
pub fn emission_coeffs(up: &dyn RgbToSpectrum, rgb: [f32; 3]) -> Option<(f32, [f32; 3])> {
    let (scale, c) = color::upsample::variants::unbounded_split(rgb.map(f64::from))?;
    Some((scale as f32, up.coefficients(c.map(|v| v as f32))))
}

/// An exact upsampler for greys only (a flat spectrum is a constant sigmoid), used by tests
/// that must not depend on a fitted table. Coloured inputs are averaged to grey.
#[derive(Clone, Copy, Debug, Default)]
pub struct GreyOnly;

impl RgbToSpectrum for GreyOnly {
    fn coefficients(&self, rgb: [f32; 3]) -> [f32; 3] {
        let g = ((rgb[0] + rgb[1] + rgb[2]) / 3.0) as f64;
        // Invert S: x = (2g − 1)/√(1 − (2g − 1)²), infinite at the ends.
        let y = 2.0 * g - 1.0;
        let x = if y >= 1.0 {
            f32::INFINITY
        } else if y <= -1.0 {
            f32::NEG_INFINITY
        } else {
            (y / (1.0 - y * y).sqrt()) as f32
        };
        [0.0, 0.0, x]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_round_trips() {
        let l = Vec4::new(400.0, 500.0, 600.0, 700.0);
        for g in [0.0, 0.18, 0.5, 0.9, 1.0] {
            let s = reflectance(&GreyOnly, [g; 3], l);
            assert!((s - Vec4::splat(g)).abs().max_element() < 1e-5, "{g}: {s}");
        }
        let e = emission_shape(&GreyOnly, [3.0; 3], l);
        assert!((e - Vec4::splat(3.0)).abs().max_element() < 1e-5);
        assert_eq!(emission_shape(&GreyOnly, [0.0; 3], l), Vec4::ZERO);
    }
}
