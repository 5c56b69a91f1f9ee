//! Light normalisation: how a light's spectrum and its glTF RGB × intensity agree.
//!
//! glTF gives a light as linear-sRGB `color` × `intensity` (candela, or lux for directional
//! lights). A spectrum from `extras.spectrum` only says the *shape* of the emission, so it is
//! scaled at load time until its luminance equals the luminance of `color × intensity`:
//!
//! ```text
//! ∫ S(λ) ȳ(λ) dλ  =  intensity × (0.2126 R + 0.7152 G + 0.0722 B)
//! ```
//!
//! with ȳ the CIE 1931 2° luminous efficiency, λ in nm, integrated at 1 nm over 360–830 nm.
//! There is no 683 lm/W and no white normalisation: the light's tristimulus value is simply
//! `XYZ = ∫ S(λ) (x̄, ȳ, z̄) dλ`, on the same scale as `color × intensity` converted to XYZ.
//! A D65-shaped spectrum on a white `[1, 1, 1]` light therefore has exactly the XYZ of that RGB
//! light, and RGB rendering of a spectral light uses [`Emission::linear_srgb`], the spectrum's own
//! colour at that luminance (an F11 or LED light keeps its tint in the RGB baseline).

use color::{Observer, SampledWavelengths, Spectrum, WavelengthRange};
use glam::Vec3;

use crate::{Emission, srgb};

/// The 1 nm midpoint grid over the whole observer range used for every emission integral.
fn grid() -> SampledWavelengths {
    let r = WavelengthRange::FULL;
    SampledWavelengths::midpoint(r, r.width().round() as usize).expect("FULL range is valid and non-empty")
}

/// `∫ S(λ) (x̄, ȳ, z̄)(λ) dλ` with the CIE 1931 2° observer at 1 nm over 360–830 nm.
pub fn spectrum_xyz(s: &Spectrum) -> [f64; 3] {
    let obs = Observer::cie1931();
    let wl = grid();
    let mut xyz = [0.0; 3];
    for (&l, &dl) in wl.lambda.iter().zip(&wl.weight) {
        let v = s.eval(l) * dl;
        let bar = obs.eval(l);
        for k in 0..3 {
            xyz[k] += v * bar[k];
        }
    }
    xyz
}

/// Luminance `∫ S ȳ dλ` of a spectrum in the convention above.
pub fn spectrum_luminance(s: &Spectrum) -> f64 {
    spectrum_xyz(s)[1]
}

/// Why a spectrum cannot be a light's; the caller places it at the field it came from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EmissionError {
    #[error("an emission spectrum cannot be negative (minimum {min} over {lo}–{hi} nm)")]
    Negative { min: f64, lo: f64, hi: f64 },
    #[error("the spectrum has no luminance over {lo}–{hi} nm, so it cannot be scaled to the light's")]
    NoLuminance { lo: f64, hi: f64 },
    #[error("the RGB colour × intensity has invalid luminance {0}")]
    BadTarget(f64),
    #[error("the spectrum has no luminance, so it has no colour to give the light")]
    NoColour,
}

/// The factor both renderers scale a measured spectrum by for the render range `range` (nm):
/// `want / y`, with `y` its luminance inside the range by the renderer's own integral and
/// `want` the luminance it must have there (that of `rgb × intensity`, in the renderer's
/// units). A spectrum with no luminance inside the range cannot have it: an error (the
/// caller names the light or material), where either renderer would draw it dark. Whether the
/// light shines at all is `rgb_luminance` (that of `rgb × intensity`, independent of the
/// range): `want` is not, as a renderer whose unit carries the white's luminance in the range
/// (the path tracer's) has `want` = 0 where the white is zero too, and drew such a lamp black
/// where the other renderer refused it.
pub fn range_scale(y: f64, want: f64, rgb_luminance: f64, range: (f64, f64)) -> Result<f64, String> {
    if y.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        if rgb_luminance > 0.0 || want > 0.0 {
            return Err(format!(
                "its emission spectrum has no luminance inside the render range {}–{} nm (it is \
                 zero or outside it there); widen --range or fix the spectrum",
                range.0, range.1
            ));
        }
        return Ok(0.0);
    }
    Ok(want / y)
}

/// Scales `shape` so that its luminance equals that of `rgb × intensity`.
///
/// Errors when the shape has no luminance to scale or a negative value somewhere, since
/// neither can be a light.
pub fn normalise(shape: &Spectrum, rgb: Vec3, intensity: f32) -> Result<Spectrum, EmissionError> {
    let lo = color::spectrum::LAMBDA_MIN;
    let hi = color::spectrum::LAMBDA_MAX;
    let min = -Spectrum::max_value(&shape.scaled(-1.0), lo, hi);
    if min < 0.0 {
        return Err(EmissionError::Negative { min, lo, hi });
    }
    let y = spectrum_luminance(shape);
    if !(y > 0.0 && y.is_finite()) {
        return Err(EmissionError::NoLuminance { lo, hi });
    }
    let target = srgb::luminance(rgb) * intensity as f64;
    if !(target.is_finite() && target >= 0.0) {
        return Err(EmissionError::BadTarget(target));
    }
    Ok(shape.scaled(target / y))
}

impl Emission {
    /// An emission from RGB and intensity, with an optional spectral *shape* that is scaled
    /// per the module convention. The caller attaches errors to a field.
    pub fn new(rgb: Vec3, intensity: f32, shape: Option<&Spectrum>) -> Result<Self, EmissionError> {
        let spectrum = shape.map(|s| normalise(s, rgb, intensity)).transpose()?;
        Ok(Emission { rgb, intensity, spectrum })
    }

    /// A light of spectral `shape` and luminance `luminance`, with the shape's own linear sRGB
    /// chromaticity (negative components of out-of-gamut lights clipped) at luminance 1 as its
    /// glTF colour, so that `rgb × intensity` and the scaled spectrum describe the same light as
    /// closely as RGB can. The built-in scenes and the evaluation's relit charts use it.
    pub fn of_shape(shape: &Spectrum, luminance: f32) -> Result<Self, EmissionError> {
        let xyz = spectrum_xyz(shape);
        if !(xyz[1] > 0.0 && xyz[1].is_finite()) {
            return Err(EmissionError::NoColour);
        }
        let rgb = srgb::xyz_to_linear(xyz.map(|c| c / xyz[1])).max(glam::DVec3::ZERO).as_vec3();
        Emission::new(rgb / srgb::luminance(rgb) as f32, luminance, Some(shape))
    }

    /// CIE XYZ of the emission: `∫ S x̄ȳz̄ dλ` for a spectral light, else `rgb × intensity`
    /// converted from linear sRGB.
    pub fn xyz(&self) -> [f64; 3] {
        match &self.spectrum {
            Some(s) => spectrum_xyz(s),
            None => (srgb::rgb_to_xyz_matrix() * (self.rgb * self.intensity).as_dvec3()).to_array(),
        }
    }

    /// What an RGB renderer should use as this light's colour × intensity: `rgb × intensity`,
    /// or for a spectral light the spectrum's own linear sRGB (same luminance, the spectrum's
    /// chromaticity; components may be slightly negative for lights outside the sRGB gamut).
    pub fn linear_srgb(&self) -> Vec3 {
        match &self.spectrum {
            Some(s) => srgb::xyz_to_linear(spectrum_xyz(s)).as_vec3(),
            None => self.rgb * self.intensity,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::illuminant;

    #[test]
    fn scaled_spectrum_has_the_rgb_luminance() {
        let f11 = illuminant::by_name("F11").unwrap();
        let e = Emission::new(Vec3::new(1.0, 0.5, 0.25), 7.0, Some(&f11)).unwrap();
        let want = 7.0 * (0.2126 * 1.0 + 0.7152 * 0.5 + 0.0722 * 0.25);
        assert!((spectrum_luminance(e.spectrum.as_ref().unwrap()) - want).abs() < 1e-3 * want);
        assert!((e.xyz()[1] - want).abs() < 1e-3 * want);
    }

    #[test]
    fn d65_light_matches_white_rgb() {
        // A D65 shape on a white light must come out as the same XYZ as the RGB light itself:
        // that is what lets RGB and spectral renders be compared.
        let d65 = illuminant::by_name("D65").unwrap();
        let e = Emission::new(Vec3::ONE, 3.0, Some(&d65)).unwrap();
        let rgb = e.linear_srgb();
        for c in rgb.to_array() {
            assert!((c - 3.0).abs() < 3.0 * 2e-3, "{rgb}");
        }
    }

    #[test]
    fn refuses_dark_and_negative_shapes() {
        let dark = Spectrum::piecewise(vec![900.0, 1000.0], vec![1.0, 1.0]).unwrap();
        assert!(Emission::new(Vec3::ONE, 1.0, Some(&dark)).unwrap_err().to_string().contains("no luminance"));
        let neg = Spectrum::piecewise(vec![400.0, 700.0], vec![1.0, -1.0]).unwrap();
        assert!(Emission::new(Vec3::ONE, 1.0, Some(&neg)).unwrap_err().to_string().contains("negative"));
    }
}
