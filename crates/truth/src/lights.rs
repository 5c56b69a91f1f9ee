//! Light sources in the tracer's radiometric units.
//!
//! Units: a spectral quantity L(λ) here is in "white-normalised" units — the sensor divides by
//! k = ∫ȳ·W for the scene white W — so a light whose spectrum is W itself with glTF intensity 1
//! produces Y = 1 where the RGB renderer produces luminance 1. RGB emission (1,1,1)·I becomes
//! I·W̃(λ), W̃ the colour space's illuminant rescaled to the luminance of W, so RGB lights
//! agree with the RGB renderer exactly in luminance and (for a D65 white) in colour.

use crate::spectral::DenseSpectrum;
use crate::upsample::{self, RgbToSpectrum};
use color::{Observer, Spectrum, WavelengthRange};
use glam::{Vec3, Vec4};
use scene::{Emission, Light, LightKind};

/// Relative luminance of a linear sRGB colour (`scene::srgb::luminance`, the one definition).
pub fn luminance(rgb: Vec3) -> f32 {
    scene::srgb::luminance(rgb) as f32
}

/// ∫ ȳ(λ)·s(λ) dλ over the range (CIE 1931, 0.1 nm midpoint rule).
pub fn y_integral(s: &dyn Fn(f64) -> f64, range: WavelengthRange) -> f64 {
    let obs = Observer::cie1931();
    let n = (range.width() * 10.0).round() as usize;
    let d = range.width() / n as f64;
    (0..n)
        .map(|i| {
            let l = range.min + (i as f64 + 0.5) * d;
            obs.eval(l)[1] * s(l) * d
        })
        .sum()
}

/// Everything needed to turn emission descriptions into spectra in tracer units.
pub struct EmissionUnits {
    pub range: WavelengthRange,
    /// The RGB colour space's illuminant, scaled to the luminance of the scene white.
    pub rgb_illuminant: DenseSpectrum,
    /// ∫ȳ·W (CIE 1931) of the scene white.
    pub k_white: f64,
}

impl EmissionUnits {
    pub fn new(white: &Spectrum, range: WavelengthRange) -> Self {
        let k_white = y_integral(&|l| white.eval(l), range);
        let ill = color::colorspace::RgbColorSpace::srgb()
            .emission_white(white, |s| y_integral(&|l| s.eval(l), range));
        EmissionUnits { range, rgb_illuminant: DenseSpectrum::new(&ill, range), k_white }
    }

    /// The emitted spectrum of a light. With a measured spectrum: its shape, scaled so its
    /// CIE 1931 luminance is that of rgb × intensity (the convention of [`scene::Emission`]);
    /// otherwise the illuminant upsampling of rgb × intensity.
    /// A measured spectrum with no luminance inside the range is an error (`scene::emission::range_scale`,
    /// the real-time renderer's rule): the caller names the light or material.
    pub fn light(&self, e: &Emission, up: &dyn RgbToSpectrum) -> Result<DenseSpectrum, String> {
        let rgb = e.rgb * e.intensity;
        Ok(match &e.spectrum {
            Some(s) => {
                let y = y_integral(&|l| s.eval(l), self.range);
                let target = luminance(rgb) as f64 * self.k_white;
                let k = scene::emission::range_scale(
                    y,
                    target,
                    luminance(rgb) as f64,
                    (self.range.min, self.range.max),
                )?;
                DenseSpectrum::new(s, self.range).scaled(k as f32)
            }
            None => {
                // One table fetch; the shape is then a closed form in λ.
                let Some((scale, c)) = upsample::emission_coeffs(up, rgb.to_array()) else {
                    return Ok(DenseSpectrum::from_fn(self.range, |_| 0.0));
                };
                DenseSpectrum::from_fn(self.range, |l| {
                    let s = upsample::eval4(c, Vec4::splat(l as f32)).x * scale;
                    (s * self.rgb_illuminant.eval(l as f32)) as f64
                })
            }
        })
    }

    /// Emission of an RGB radiance (emissive materials) at four wavelengths.
    pub fn rgb(&self, rgb: Vec3, up: &dyn RgbToSpectrum, l: Vec4) -> Vec4 {
        upsample::emission_shape(up, rgb.to_array(), l) * self.rgb_illuminant.eval4(l)
    }
}

/// A point, spot or directional light prepared for next-event estimation.
pub struct DeltaLight {
    pub kind: LightKind,
    pub spectrum: DenseSpectrum,
    /// Spot cone: cd·scale + offset, clamped and squared (KHR_lights_punctual).
    spot_scale: f32,
    spot_offset: f32,
}

/// Incident light at a point from a delta light.
pub struct DeltaSample {
    /// Unit direction from the point towards the light.
    pub wi: Vec3,
    /// Distance to the light (∞ for directional).
    pub dist: f32,
    /// Irradiance factor at normal incidence per unit spectrum: 1/d² × falloffs.
    pub scale: f32,
}

impl DeltaLight {
    pub fn new(l: &Light, spectrum: DenseSpectrum) -> Self {
        let (mut spot_scale, mut spot_offset) = (0.0, 1.0);
        if let LightKind::Spot { inner_cone, outer_cone, .. } = l.kind {
            let (ci, co) = (inner_cone.cos(), outer_cone.cos());
            spot_scale = 1.0 / (ci - co).max(0.001);
            spot_offset = -co * spot_scale;
        }
        DeltaLight { kind: l.kind.clone(), spectrum, spot_scale, spot_offset }
    }

    /// KHR_lights_punctual's recommended range window (smooth to zero at `range`).
    fn window(range: Option<f32>, d: f32) -> f32 {
        match range {
            Some(r) if r > 0.0 => (1.0 - (d / r).powi(4)).clamp(0.0, 1.0).powi(2),
            _ => 1.0,
        }
    }

    pub fn sample(&self, p: Vec3) -> Option<DeltaSample> {
        match self.kind {
            LightKind::Directional { direction } => {
                Some(DeltaSample { wi: -direction.normalize(), dist: f32::INFINITY, scale: 1.0 })
            }
            LightKind::Point { position, range } => {
                let v = position - p;
                let d2 = v.length_squared();
                let d = d2.sqrt();
                (d > 0.0).then(|| DeltaSample { wi: v / d, dist: d, scale: Self::window(range, d) / d2 })
            }
            LightKind::Spot { position, direction, range, .. } => {
                let v = position - p;
                let d2 = v.length_squared();
                let d = d2.sqrt();
                if d == 0.0 {
                    return None;
                }
                let wi = v / d;
                let cd = direction.normalize().dot(-wi);
                let a = (cd * self.spot_scale + self.spot_offset).clamp(0.0, 1.0);
                let a = a * a;
                (a > 0.0).then(|| DeltaSample { wi, dist: d, scale: a * Self::window(range, d) / d2 })
            }
        }
    }
}

/// Discrete distribution over emissive triangles, proportional to area × emitted luminance.
pub struct EmitterDistribution {
    /// (triangle index, cumulative probability up to and including it).
    cdf: Vec<(u32, f32)>,
    /// Selection probability per scene triangle (0 for non-emitters).
    pub pmf: Vec<f32>,
}

impl EmitterDistribution {
    pub fn new(weights: impl Iterator<Item = f32>, n_tris: usize) -> Self {
        let mut pmf = vec![0.0f32; n_tris];
        let mut cdf = Vec::new();
        let mut total = 0.0f64;
        for (i, w) in weights.enumerate() {
            if w > 0.0 && w.is_finite() {
                total += w as f64;
                cdf.push((i as u32, total as f32));
                pmf[i] = w;
            }
        }
        if total > 0.0 {
            cdf.iter_mut().for_each(|c| c.1 = (c.1 as f64 / total) as f32);
            pmf.iter_mut().for_each(|p| *p = (*p as f64 / total) as f32);
            if let Some(last) = cdf.last_mut() {
                last.1 = 1.0;
            }
        }
        EmitterDistribution { cdf, pmf }
    }

    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// A triangle and its probability.
    pub fn sample(&self, u: f32) -> Option<(u32, f32)> {
        let i = self.cdf.partition_point(|c| c.1 <= u).min(self.cdf.len().checked_sub(1)?);
        let tri = self.cdf[i].0;
        Some((tri, self.pmf[tri as usize]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::upsample::GreyOnly;

    #[test]
    fn d65_white_rgb_light_is_d65_with_unit_luminance() {
        let d65 = color::illuminant::by_name("D65").unwrap();
        let u = EmissionUnits::new(&d65, WavelengthRange::VISIBLE);
        let e = Emission { rgb: Vec3::ONE, intensity: 2.0, spectrum: None };
        let s = u.light(&e, &GreyOnly).unwrap();
        let y = y_integral(&|l| s.eval(l as f32) as f64, WavelengthRange::VISIBLE) / u.k_white;
        assert!((y - 2.0).abs() < 1e-3, "{y}");
        assert!((s.eval(560.0) as f64 - 2.0 * d65.eval(560.0)).abs() < 1e-2);
    }

    #[test]
    fn measured_spectrum_gets_the_rgb_luminance() {
        let d65 = color::illuminant::by_name("D65").unwrap();
        let u = EmissionUnits::new(&d65, WavelengthRange::VISIBLE);
        let f11 = color::illuminant::by_name("F11").unwrap();
        let e = Emission { rgb: Vec3::new(1.0, 0.5, 0.2), intensity: 3.0, spectrum: Some(f11) };
        let s = u.light(&e, &GreyOnly).unwrap();
        let y = y_integral(&|l| s.eval(l as f32) as f64, WavelengthRange::VISIBLE) / u.k_white;
        let want = 3.0 * (0.2126 + 0.7152 * 0.5 + 0.0722 * 0.2);
        assert!((y - want).abs() < 2e-3 * want, "{y} vs {want}");
    }

    /// A spectrum with no luminance inside the range is refused, as the real-time renderer
    /// refuses it (`scene::emission::range_scale`): it drew an all-black image.
    #[test]
    fn a_spectrum_outside_the_range_is_an_error_unless_the_light_is_dark() {
        let d65 = color::illuminant::by_name("D65").unwrap();
        let u = EmissionUnits::new(&d65, WavelengthRange::VISIBLE);
        let ir = Spectrum::piecewise(vec![790.0, 800.0, 810.0], vec![0.0, 1.0, 0.0]).unwrap();
        let e = Emission { rgb: Vec3::ONE, intensity: 2.0, spectrum: Some(ir) };
        let err = u.light(&e, &GreyOnly).unwrap_err();
        assert!(err.contains("380–730") && err.contains("--range"), "{err}");
        let dark = Emission { intensity: 0.0, ..e };
        assert_eq!(u.light(&dark, &GreyOnly).unwrap().eval(550.0), 0.0);
    }

    /// Where the white itself is zero (D65 is tabulated to 780 nm), the light's target
    /// luminance in the path tracer's units is zero too: a D65 lamp rendered over 790–830 nm
    /// was drawn black without a word where the real-time renderer refused it.
    #[test]
    fn a_lamp_whose_white_is_zero_in_the_range_is_refused_as_in_real_time() {
        let d65 = color::illuminant::by_name("D65").unwrap();
        let range = WavelengthRange::new(790.0, 830.0).unwrap();
        let u = EmissionUnits::new(&d65, range);
        assert_eq!(u.k_white, 0.0);
        let lamp = Emission { rgb: Vec3::ONE, intensity: 40.0, spectrum: Some(d65.clone()) };
        let err = u.light(&lamp, &GreyOnly).unwrap_err();
        assert!(err.contains("790–830") && err.contains("--range"), "{err}");
        let dark = Emission { intensity: 0.0, ..lamp };
        assert_eq!(u.light(&dark, &GreyOnly).unwrap().eval(800.0), 0.0);
    }

    #[test]
    fn spot_cone_follows_gltf() {
        let l = Light {
            name: "s".into(),
            kind: LightKind::Spot {
                position: Vec3::ZERO,
                direction: -Vec3::Y,
                inner_cone: 0.2,
                outer_cone: 0.4,
                range: None,
            },
            emission: Emission { rgb: Vec3::ONE, intensity: 1.0, spectrum: None },
            stands_in_for: None,
        };
        let d = DeltaLight::new(&l, DenseSpectrum::from_fn(WavelengthRange::VISIBLE, |_| 1.0));
        let at = |a: f32| {
            d.sample(Vec3::new(a.tan(), -1.0, 0.0)).map_or(0.0, |s| s.scale * (1.0 + a.tan().powi(2)))
        };
        assert!((at(0.1) - 1.0).abs() < 1e-4);
        assert_eq!(at(0.45), 0.0);
        let mid = at(0.3);
        let t = (0.3f32.cos() - 0.4f32.cos()) / (0.2f32.cos() - 0.4f32.cos());
        assert!((mid - t * t).abs() < 1e-4);
    }

    #[test]
    fn emitter_distribution_is_proportional() {
        let d = EmitterDistribution::new([0.0, 1.0, 0.0, 3.0].into_iter(), 4);
        assert_eq!(d.pmf, vec![0.0, 0.25, 0.0, 0.75]);
        assert_eq!(d.sample(0.1).unwrap().0, 1);
        assert_eq!(d.sample(0.3).unwrap().0, 3);
        assert_eq!(d.sample(0.99999).unwrap().0, 3);
        assert!(EmitterDistribution::new([0.0].into_iter(), 1).sample(0.5).is_none());
    }
}
