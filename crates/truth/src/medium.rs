//! Homogeneous participating media: per-wavelength absorption and scattering coefficients and
//! a phase function, filling the whole scene or an axis-aligned box.
//!
//! The box is a region of space, not a surface: rays cross its faces without refraction
//! (index-matched), which is what the underwater model assumes for water around objects.

use crate::error::{Result, TruthError};
use crate::sampling::Frame;
use crate::spectral::DenseSpectrum;
use color::{Spectrum, WavelengthRange};
use glam::{Vec3, Vec4};
use std::f32::consts::PI;

/// Largest absorption or scattering coefficient accepted (per scene unit): a mean free path of
/// 10⁻⁷ units. Larger finite values (1e38, 1e39) overflow the tracer's f32 transmittance into
/// black or NaN pixels. Ten times the RGB media's bound (`scene::medium::MAX_COEFFICIENT`):
/// their upsampled spectra overshoot their RGB coefficients, by up to 5.5× (test
/// `every_rgb_medium_the_parser_accepts_the_tracer_accepts`), and every RGB medium the parser
/// accepts must be one the tracer accepts, as the real-time renderer does.
pub const MAX_SIGMA: f64 = 1.0e7;

/// Where a medium is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Region {
    /// Everywhere, including around the camera.
    Everywhere,
    /// Inside the box `[min, max]` (world units).
    Box { min: Vec3, max: Vec3 },
}

/// Angular distribution of scattered light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    Isotropic,
    /// Henyey–Greenstein with mean cosine `g` in (−1, 1); g > 0 scatters forward.
    HenyeyGreenstein {
        g: f32,
    },
}

/// A homogeneous medium. Coefficients are per scene unit of length (m⁻¹ when one unit is a
/// metre), as functions of wavelength in nm.
#[derive(Clone, Debug)]
pub struct Medium {
    pub sigma_a: Spectrum,
    pub sigma_s: Spectrum,
    pub phase: Phase,
    pub region: Region,
    /// `Some(n)`: the top face of the `Region::Box` is a flat water surface, index `n` relative
    /// to the air above, with the sky above it (see [`crate::water_surface`]); paths reaching
    /// it from below are Fresnel-reflected or see the sky. `None`: every face is
    /// index-matched (rays cross it unchanged).
    pub surface_ior: Option<f32>,
}

impl Medium {
    /// Checks that the coefficients are finite and non-negative over `range` (1 nm steps) and
    /// that the phase function and region make sense.
    /// Also refuses coefficients above [`MAX_SIGMA`].
    pub fn validate(&self, range: WavelengthRange) -> Result<()> {
        let bad = |s: String| Err(TruthError::BadMedium(s));
        let mut any = false;
        for (name, s) in [("sigma_a", &self.sigma_a), ("sigma_s", &self.sigma_s)] {
            let n = range.width().ceil() as usize;
            for i in 0..=n {
                let l = (range.min + i as f64).min(range.max);
                let v = s.eval(l);
                if !(0.0..=MAX_SIGMA).contains(&v) {
                    return bad(format!(
                        "{name} is {} at {l} nm; coefficients must lie in 0–{MAX_SIGMA:e} per scene unit",
                        color::error::show(v)
                    ));
                }
                any |= v > 0.0;
            }
        }
        // As `--rgb-medium` refuses one (color::upsample::medium): a medium that neither
        // absorbs nor scatters anywhere in the range is almost surely a mistake (a unit, a
        // sampled coefficient outside the range), and it would render as no medium. A water
        // surface on its box still refracts: clear water is a medium then.
        if !any && self.surface_ior.is_none() {
            return bad(format!(
                "sigma_a and sigma_s are zero over {}–{} nm: the medium would do nothing",
                range.min, range.max
            ));
        }
        if let Phase::HenyeyGreenstein { g } = self.phase
            && !(g > -1.0 && g < 1.0)
        {
            return bad(format!("phase: Henyey–Greenstein g = {g} must lie strictly between −1 and 1"));
        }
        if let Region::Box { min, max } = self.region {
            if !min.is_finite() || !max.is_finite() {
                return bad(format!("box: min {min} and max {max} must be finite"));
            }
            // A box of no extent along an axis holds no volume: nothing would be scattered.
            if let Some(axis) = (0..3).find(|&i| min[i] >= max[i]) {
                let name = ["x", "y", "z"][axis];
                return bad(format!(
                    "box: max.{name} = {} is not above min.{name} = {}: the box is empty",
                    max[axis], min[axis]
                ));
            }
        }
        if let Some(n) = self.surface_ior {
            if !(n.is_finite() && n > 1.0) {
                return bad(format!("surface index of refraction {n} must be a finite number > 1"));
            }
            if self.region == Region::Everywhere {
                return bad("a water surface needs a box: it is the box's top face".into());
            }
        }
        Ok(())
    }
}

impl Medium {
    /// A scene's RGB medium ([`scene::medium::RgbMedium`]) as the tracer's spectral medium,
    /// filling the scene: σ_a(λ), σ_s(λ) per scene unit upsampled through `table` (the scene
    /// colour space's Jakob–Hanika table) by the medium's own method (docs/rgb-media.md).
    pub fn from_rgb(m: &scene::medium::RgbMedium, table: &color::upsample::CoeffTable) -> Result<Medium> {
        let (sigma_a, sigma_s) =
            m.spectra(table).map_err(|e| TruthError::BadMedium(format!("upsampling the RGB medium: {e}")))?;
        Ok(Medium {
            sigma_a,
            sigma_s,
            phase: if m.g == 0.0 { Phase::Isotropic } else { Phase::HenyeyGreenstein { g: m.g as f32 } },
            region: Region::Everywhere,
            surface_ior: None,
        })
    }
}

/// A validated medium prepared for the inner loop.
#[derive(Clone, Debug)]
pub struct PreparedMedium {
    sigma_a: DenseSpectrum,
    sigma_s: DenseSpectrum,
    pub phase: Phase,
    pub region: Region,
}

impl PreparedMedium {
    pub fn new(m: &Medium, range: WavelengthRange) -> Result<Self> {
        m.validate(range)?;
        Ok(PreparedMedium {
            sigma_a: DenseSpectrum::new(&m.sigma_a, range),
            sigma_s: DenseSpectrum::new(&m.sigma_s, range),
            phase: m.phase,
            region: m.region,
        })
    }

    /// (σs, σt) at four wavelengths.
    #[inline]
    pub fn coefficients(&self, l: Vec4) -> (Vec4, Vec4) {
        let s = self.sigma_s.eval4(l);
        (s, s + self.sigma_a.eval4(l))
    }

    /// The part `[t0, t1]` of the ray segment `[0, tmax]` inside the medium, if any.
    pub fn overlap(&self, o: Vec3, d: Vec3, tmax: f32) -> Option<(f32, f32)> {
        match self.region {
            Region::Everywhere => Some((0.0, tmax)),
            Region::Box { min, max } => {
                let inv = d.recip();
                let ta = (min - o) * inv;
                let tb = (max - o) * inv;
                // NaN (0·∞ on a face-parallel ray) must not widen the interval: max/min ignore it.
                let t0 = ta.min(tb).max_element().max(0.0);
                let t1 = ta.max(tb).min_element().min(tmax);
                (t0 < t1).then_some((t0, t1))
            }
        }
    }
}

/// Phase function value for the angle between the incoming propagation direction `wi_prop`
/// (where the light travels) and the outgoing direction `wo`: cosθ = wi_prop·wo.
pub fn phase_eval(p: Phase, cos_theta: f32) -> f32 {
    match p {
        Phase::Isotropic => 1.0 / (4.0 * PI),
        Phase::HenyeyGreenstein { g } => {
            // 1 + g² − 2g·cosθ as two terms of one sign, in f64: the plain sum cancels to zero or
            // below near g = −1 and cosθ = −1 (or +1, +1), where f32 made the value inf or NaN
            // (g = −0.9999 dropped paths as non-finite).
            let (g, c) = (f64::from(g), f64::from(cos_theta).clamp(-1.0, 1.0));
            let d = if g < 0.0 {
                (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + c)
            } else {
                (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c)
            };
            ((1.0 - g) * (1.0 + g) / (4.0 * std::f64::consts::PI * d * d.sqrt())) as f32
        }
    }
}

/// Samples a new propagation direction given the current one; returns (dir, pdf = phase value).
pub fn phase_sample(p: Phase, dir: Vec3, u: [f32; 2]) -> (Vec3, f32) {
    let cos_theta = match p {
        Phase::Isotropic => 1.0 - 2.0 * u[0],
        Phase::HenyeyGreenstein { g } if g.abs() < 1e-3 => 1.0 - 2.0 * u[0],
        Phase::HenyeyGreenstein { g } => {
            // In f64, for the same cancellation as `phase_eval`'s near |g| = 1.
            let (g, u) = (f64::from(g), f64::from(u[0]));
            let s = (1.0 - g) * (1.0 + g) / (1.0 + g - 2.0 * g * u);
            (((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)) as f32
        }
    };
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    let f = Frame::from_normal(dir);
    let w = f.to_world(Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta));
    (w, phase_eval(p, cos_theta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hg_is_normalised_and_has_mean_cosine_g() {
        for g in [-0.6, 0.0, 0.3, 0.9] {
            let p = Phase::HenyeyGreenstein { g };
            let n = 200_000;
            let (mut norm, mut mean) = (0.0f64, 0.0f64);
            for i in 0..n {
                let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                let v = phase_eval(p, c as f32) as f64 * 2.0 * std::f64::consts::PI * 2.0 / n as f64;
                norm += v;
                mean += v * c;
            }
            assert!((norm - 1.0).abs() < 1e-3, "g={g}: ∫p = {norm}");
            assert!((mean - g as f64).abs() < 2e-3, "g={g}: mean cos = {mean}");
        }
    }

    /// Found by a sweep: g = −0.9999 (accepted: |g| < 1) made f32's 1 + g² − 2g·cosθ cancel
    /// to zero or below, and the tracer dropped paths as non-finite. Finite and positive over
    /// the whole accepted range, and equal to the f64 formula.
    #[test]
    fn hg_is_finite_and_positive_next_to_g_one() {
        for g in [-0.9999999f32, -0.99999, -0.9999, 0.9999, 0.99999, 0.9999999] {
            let p = Phase::HenyeyGreenstein { g };
            for i in 0..=2000 {
                let c = -1.0 + 2.0 * i as f32 / 2000.0;
                let v = phase_eval(p, c);
                assert!(v.is_finite() && v > 0.0, "g {g} cos {c}: {v}");
                let (g64, c64) = (g as f64, c as f64);
                let want = (1.0 - g64 * g64)
                    / (4.0 * std::f64::consts::PI * (1.0 + g64 * g64 - 2.0 * g64 * c64).powf(1.5));
                assert!((v as f64 - want).abs() <= 1e-3 * want, "g {g} cos {c}: {v} vs {want}");
            }
            for i in 0..1000 {
                let (w, pdf) = phase_sample(p, Vec3::Z, [(i as f32 + 0.5) / 1000.0, 0.3]);
                assert!(w.is_finite() && pdf.is_finite() && pdf > 0.0, "g {g}: {w} {pdf}");
            }
        }
    }

    #[test]
    fn hg_sampling_matches_its_pdf() {
        // The sampled cosines must have mean g.
        let g = 0.7;
        let p = Phase::HenyeyGreenstein { g };
        let n = 100_000;
        let mut m = 0.0f64;
        for i in 0..n {
            let (w, pdf) = phase_sample(p, Vec3::Z, [(i as f32 + 0.5) / n as f32, 0.3]);
            assert!((pdf - phase_eval(p, w.z)).abs() <= 1e-3 * pdf);
            m += w.z as f64;
        }
        assert!((m / n as f64 - g as f64).abs() < 2e-3);
    }

    #[test]
    fn validation_rejects_bad_media() {
        let r = WavelengthRange::VISIBLE;
        let ok = Medium {
            sigma_a: Spectrum::Constant(0.1),
            sigma_s: Spectrum::Constant(0.2),
            phase: Phase::HenyeyGreenstein { g: 0.5 },
            region: Region::Everywhere,
            surface_ior: None,
        };
        assert!(ok.validate(r).is_ok());
        let neg = Medium { sigma_a: Spectrum::Constant(-0.1), ..ok.clone() };
        assert!(neg.validate(r).unwrap_err().to_string().contains("sigma_a"));
        let nan = Medium { sigma_s: Spectrum::Constant(f64::NAN), ..ok.clone() };
        assert!(nan.validate(r).is_err());
        let g = Medium { phase: Phase::HenyeyGreenstein { g: 1.0 }, ..ok.clone() };
        assert!(g.validate(r).is_err());
        let b = Medium { region: Region::Box { min: Vec3::ONE, max: Vec3::ZERO }, ..ok.clone() };
        assert!(b.validate(r).is_err());
        // Flat or a point: no volume (accepted silently before; found by a sweep).
        for max in [Vec3::new(1.0, 1.0, 2.0), Vec3::ONE] {
            let flat = Medium { region: Region::Box { min: Vec3::ONE, max }, ..ok.clone() };
            let e = flat.validate(r).unwrap_err().to_string();
            assert!(e.contains("box") && e.contains("empty"), "{e}");
        }
        // Zero everywhere in the range (--rgb-medium refused it; --medium drew no medium).
        let none =
            Medium { sigma_a: Spectrum::Constant(0.0), sigma_s: Spectrum::Constant(0.0), ..ok.clone() };
        let e = none.validate(r).unwrap_err().to_string();
        assert!(e.contains("zero over 380–730 nm"), "{e}");
        let outside = Spectrum::piecewise(vec![800.0, 820.0], vec![1.0, 1.0]).unwrap();
        assert!(
            Medium { sigma_s: outside.clone(), sigma_a: Spectrum::Constant(0.0), ..ok.clone() }
                .validate(r)
                .is_err()
        );
        let inside = Medium { sigma_s: outside, ..ok.clone() };
        assert!(inside.validate(r).is_ok());
        let no_box = Medium { surface_ior: Some(1.34), ..ok.clone() };
        assert!(no_box.validate(r).unwrap_err().to_string().contains("box"));
        let slab = Region::Box { min: Vec3::ZERO, max: Vec3::ONE };
        let bad_n = Medium { surface_ior: Some(0.9), region: slab, ..ok.clone() };
        assert!(bad_n.validate(r).unwrap_err().to_string().contains("0.9"));
        assert!(Medium { surface_ior: Some(1.34), region: slab, ..ok }.validate(r).is_ok());
    }

    #[test]
    fn box_overlap() {
        let m = PreparedMedium::new(
            &Medium {
                sigma_a: Spectrum::Constant(1.0),
                sigma_s: Spectrum::Constant(0.0),
                phase: Phase::Isotropic,
                region: Region::Box { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) },
                surface_ior: None,
            },
            WavelengthRange::VISIBLE,
        )
        .unwrap();
        assert_eq!(m.overlap(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, 100.0), Some((4.0, 6.0)));
        assert_eq!(m.overlap(Vec3::ZERO, Vec3::X, 0.5), Some((0.0, 0.5)));
        assert_eq!(m.overlap(Vec3::new(-5.0, 3.0, 0.0), Vec3::X, 100.0), None);
    }

    /// Every RGB medium the scene's parser accepts (coefficients up to its bound) is one the
    /// tracer accepts, whatever its upsampling: the spectra overshoot their RGB coefficients
    /// (a red-only 9e5 "unbounded" peaks at 1.02e6), which the tracer used to refuse while the
    /// real-time renderer drew them.
    #[test]
    fn every_rgb_medium_the_parser_accepts_the_tracer_accepts() {
        use color::upsample::medium::Attenuation;
        use scene::medium::{MAX_COEFFICIENT, RgbMedium};
        let table = color::upsample::table("srgb").unwrap();
        let top = MAX_COEFFICIENT;
        let mut worst = 0.0f64;
        let mut rgbs = vec![];
        for c in 1..8u32 {
            let v = [0, 1, 2].map(|i| if c >> i & 1 == 1 { top } else { 0.0 });
            rgbs.push(v);
            rgbs.push(v.map(|x| x * 0.9));
            rgbs.push(v.map(|x| if x > 0.0 { x } else { top * 0.01 }));
        }
        let mut seed = 7u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200 {
            rgbs.push([next(), next(), next()].map(|u| top * u * u));
        }
        for method in [Attenuation::DEFAULT, Attenuation::TRANSMITTANCE, Attenuation::Unbounded] {
            for v in &rgbs {
                for (a, s) in [(*v, [0.0; 3]), ([0.0; 3], *v)] {
                    let m = RgbMedium::new(a, s, 0.0, 1.0, method).unwrap();
                    let medium = Medium::from_rgb(&m, &table).unwrap();
                    for l in 360..=830 {
                        let peak = medium.sigma_a.eval(l as f64).max(medium.sigma_s.eval(l as f64));
                        worst = worst.max(peak / v.iter().copied().fold(0.0, f64::max));
                    }
                    medium
                        .validate(WavelengthRange::FULL)
                        .unwrap_or_else(|e| panic!("{method:?} {v:?}: {e}"));
                }
            }
        }
        eprintln!("largest upsampled coefficient / largest RGB coefficient: {worst:.4}");
    }
}
