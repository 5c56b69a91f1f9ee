//! Spectral integration into tristimulus values.

use crate::error::Result;
use crate::observer::Observer;
use crate::spectrum::Spectrum;
use crate::wavelengths::{SampledWavelengths, WavelengthRange};

/// Precomputed quadrature weights `wᵢ = s̄(λᵢ)·E(λᵢ)·Δλᵢ / k` for one observer, illuminant and set
/// of wavelengths, so that integrating a reflectance is one dot product per channel. `k` makes
/// the perfect white (reflectance 1) come out with Y = 1 on these same wavelengths, so a
/// constant spectrum integrates to exactly the illuminant's white whatever N is.
///
/// The real-time renderer uploads exactly these weights; they are never recomputed per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralIntegrator {
    pub lambda: Vec<f64>,
    pub weights: Vec<[f64; 3]>,
}

impl SpectralIntegrator {
    /// Reflectance integrator: XYZ of a surface of reflectance r(λ) under `illuminant`.
    pub fn reflectance(observer: &Observer, illuminant: &Spectrum, wl: &SampledWavelengths) -> Self {
        let mut weights: Vec<[f64; 3]> = wl
            .lambda
            .iter()
            .zip(&wl.weight)
            .map(|(&l, &dl)| observer.eval(l).map(|c| c * illuminant.eval(l) * dl))
            .collect();
        let y: f64 = weights.iter().map(|w| w[1]).sum();
        if y > 0.0 {
            for w in &mut weights {
                *w = w.map(|c| c / y);
            }
        }
        SpectralIntegrator { lambda: wl.lambda.clone(), weights }
    }

    /// Emission integrator: XYZ of a radiance spectrum L(λ), scaled by `1/k` where k = ∫ȳ(λ)·E(λ)dλ of `white`
    /// over the same wavelengths. Using the same `white` as [`Self::reflectance`] makes a
    /// light of spectrum `white` seen directly equal the white of a reflectance 1 lit by it.
    pub fn emission(observer: &Observer, white: &Spectrum, wl: &SampledWavelengths) -> Self {
        let k: f64 =
            wl.lambda.iter().zip(&wl.weight).map(|(&l, &dl)| observer.eval(l)[1] * white.eval(l) * dl).sum();
        let k = if k > 0.0 { k } else { 1.0 };
        let weights =
            wl.lambda.iter().zip(&wl.weight).map(|(&l, &dl)| observer.eval(l).map(|c| c * dl / k)).collect();
        SpectralIntegrator { lambda: wl.lambda.clone(), weights }
    }

    /// Dense reference integrator: CIE 1931-style 1 nm midpoint grid over `range`.
    pub fn reference(observer: &Observer, illuminant: &Spectrum, range: WavelengthRange) -> Result<Self> {
        let n = range.width().round().max(1.0) as usize;
        Ok(Self::reflectance(observer, illuminant, &SampledWavelengths::midpoint(range, n)?))
    }

    /// Integrates values already sampled at [`Self::lambda`].
    #[inline]
    pub fn integrate_samples(&self, values: &[f64]) -> [f64; 3] {
        debug_assert_eq!(values.len(), self.weights.len());
        let mut xyz = [0.0; 3];
        for (v, w) in values.iter().zip(&self.weights) {
            xyz[0] += v * w[0];
            xyz[1] += v * w[1];
            xyz[2] += v * w[2];
        }
        xyz
    }

    /// Integrates a function of wavelength.
    #[inline]
    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for (&l, w) in self.lambda.iter().zip(&self.weights) {
            let v = f(l);
            xyz[0] += v * w[0];
            xyz[1] += v * w[1];
            xyz[2] += v * w[2];
        }
        xyz
    }

    /// XYZ of the perfect reflector (the integrator's white point).
    pub fn white(&self) -> [f64; 3] {
        self.integrate(|_| 1.0)
    }
}

/// CIE xy chromaticity of an XYZ triple.
pub fn xyz_to_xy(xyz: [f64; 3]) -> [f64; 2] {
    let s = xyz[0] + xyz[1] + xyz[2];
    [xyz[0] / s, xyz[1] / s]
}

/// XYZ with Y = 1 of a chromaticity.
pub fn xy_to_xyz(xy: [f64; 2]) -> [f64; 3] {
    [xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::illuminant;

    fn white_point(obs: &Observer, ill: &str) -> [f64; 3] {
        let i = SpectralIntegrator::reference(obs, &illuminant::by_name(ill).unwrap(), WavelengthRange::FULL)
            .unwrap();
        i.white()
    }

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < tol, "{a:?} vs {b:?}");
        }
    }

    // Published white points: CIE 015:2018 Table 11.4 (2°) and 11.5 (10°), and ASTM E308.
    #[test]
    fn published_white_points() {
        let o2 = Observer::cie1931();
        let o10 = Observer::cie1964();
        close(white_point(&o2, "D65"), [0.95047, 1.0, 1.08883], 1e-4);
        close(white_point(&o2, "D50"), [0.96422, 1.0, 0.82521], 1e-4);
        close(white_point(&o2, "A"), [1.09850, 1.0, 0.35585], 1e-4);
        close(white_point(&o10, "D65"), [0.94811, 1.0, 1.07304], 1e-4);
        close(white_point(&o10, "A"), [1.11144, 1.0, 0.35200], 1e-4);
    }

    #[test]
    fn constant_spectrum_is_white_for_any_n() {
        let o = Observer::cie1931();
        let d65 = illuminant::by_name("D65").unwrap();
        for n in [1, 3, 16, 64] {
            let wl = SampledWavelengths::midpoint(WavelengthRange::VISIBLE, n).unwrap();
            let i = SpectralIntegrator::reflectance(&o, &d65, &wl);
            assert!((i.integrate(|_| 0.5)[1] - 0.5).abs() < 1e-12);
        }
    }
}
