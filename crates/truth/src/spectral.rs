//! Hero-wavelength sampling and the conversion of per-wavelength radiance into XYZ.
//!
//! Every path carries four wavelengths: a uniformly chosen hero λ₀ and three more rotated by
//! a quarter of the range each (Wilkie et al. 2014), so one path estimates the spectral
//! integral at four well-spread points. Quantities along the path are [`Vec4`]s, one lane per
//! wavelength.

use color::{Observer, Spectrum, WavelengthRange};
use glam::Vec4;

/// A spectrum resampled on a 1 nm grid covering the render range, for fast lookups in the
/// inner loop. Spectra in spectra are piecewise linear on (mostly) 1 or 5 nm grids, so linear
/// interpolation on integer nanometres reproduces them exactly.
#[derive(Clone, Debug)]
pub struct DenseSpectrum {
    start: f32,
    values: Vec<f32>,
}

impl DenseSpectrum {
    pub fn new(s: &Spectrum, range: WavelengthRange) -> Self {
        Self::from_fn(range, |l| s.eval(l))
    }

    pub fn from_fn(range: WavelengthRange, f: impl Fn(f64) -> f64) -> Self {
        let start = range.min.floor();
        let n = (range.max.ceil() - start) as usize + 2;
        DenseSpectrum { start: start as f32, values: (0..n).map(|i| f(start + i as f64) as f32).collect() }
    }

    #[inline]
    pub fn eval(&self, lambda: f32) -> f32 {
        let x = (lambda - self.start).max(0.0);
        let i = (x as usize).min(self.values.len() - 2);
        let t = x - i as f32;
        self.values[i] * (1.0 - t) + self.values[i + 1] * t
    }

    #[inline]
    pub fn eval4(&self, l: Vec4) -> Vec4 {
        Vec4::new(self.eval(l.x), self.eval(l.y), self.eval(l.z), self.eval(l.w))
    }

    pub fn scaled(mut self, k: f32) -> Self {
        self.values.iter_mut().for_each(|v| *v *= k);
        self
    }
}

/// The four wavelengths of one path, nm.
#[derive(Clone, Copy, Debug)]
pub struct Wavelengths(pub Vec4);

/// Converts radiance samples at hero wavelengths to XYZ with the same normalisation as
/// [`color::SpectralIntegrator::emission`]: XYZ = ∫ cmf(λ)·L(λ) dλ / ∫ ȳ(λ)·W(λ) dλ, with W the
/// scene white, so a surface of reflectance 1 lit by a light of spectrum W (in the same units)
/// has Y = 1, and a D65 light of RGB (1,1,1) gives the same numbers as the RGB renderer.
#[derive(Clone, Debug)]
pub struct XyzSensor {
    range: WavelengthRange,
    /// cmf(λ)·(range width)/k, so that a single wavelength sample is an unbiased estimate.
    cmf: [DenseSpectrum; 3],
}

/// ∫ observer(λ)·s(λ) dλ over `range`, each channel, on a 0.1 nm midpoint grid: fine enough
/// that its quadrature error is far below the tracer's noise.
pub fn observer_integral(observer: &Observer, s: &Spectrum, range: WavelengthRange) -> [f64; 3] {
    let n = (range.width() * 10.0).round().max(1.0) as usize;
    let d = range.width() / n as f64;
    (0..n).fold([0.0; 3], |mut acc, i| {
        let l = range.min + (i as f64 + 0.5) * d;
        let (o, w) = (observer.eval(l), s.eval(l));
        (0..3).for_each(|c| acc[c] += o[c] * w * d);
        acc
    })
}

/// The normalisation of [`XyzSensor`]: the white's second channel (Y for a CIE observer).
fn white_k(observer: &Observer, white: &Spectrum, range: WavelengthRange) -> f64 {
    let k = observer_integral(observer, white, range)[1];
    if k > 0.0 { k } else { 1.0 }
}

/// The matrix from the tracer's tristimulus values to linear sRGB ([`color::film`], the
/// convention the real-time renderer and `compare` share): a non-CIE observer is balanced by
/// its response to the RGB white — the colour space's illuminant at the scene white's
/// luminance, which an RGB (1, 1, 1) light emits — in the sensor's units.
pub fn display_matrix(
    observer: &Observer,
    white: &Spectrum,
    range: WavelengthRange,
    view: color::film::CameraView,
) -> color::Result<glam::DMat3> {
    let rgb_white = color::RgbColorSpace::srgb()
        .emission_white(white, |s| crate::lights::y_integral(&|l| s.eval(l), range));
    let k = white_k(observer, white, range);
    let response = observer_integral(observer, &rgb_white, range).map(|v| v / k);
    color::film::to_linear_srgb(observer, response, &rgb_white, view)
}

impl XyzSensor {
    pub fn new(observer: &Observer, white: &Spectrum, range: WavelengthRange) -> Self {
        let k = white_k(observer, white, range);
        let scale = range.width() / k;
        let cmf = [0, 1, 2].map(|c| DenseSpectrum::from_fn(range, |l| observer.eval(l)[c] * scale));
        XyzSensor { range, cmf }
    }

    pub fn range(&self) -> WavelengthRange {
        self.range
    }

    /// The hero wavelength at `u` and its three rotations.
    pub fn sample(&self, u: f32) -> Wavelengths {
        let (lo, w) = (self.range.min as f32, self.range.width() as f32);
        let at = |k: f32| {
            let x = u + k * 0.25;
            lo + (if x >= 1.0 { x - 1.0 } else { x }) * w
        };
        Wavelengths(Vec4::new(at(0.0), at(1.0), at(2.0), at(3.0)))
    }

    /// XYZ estimate of one path's radiance: the mean over its four wavelengths of
    /// cmf(λ)·L(λ)/p(λ) (p uniform), normalised by k.
    pub fn to_xyz(&self, wl: &Wavelengths, radiance: Vec4) -> [f64; 3] {
        [0, 1, 2].map(|c| (self.cmf[c].eval4(wl.0) * radiance).element_sum() as f64 * 0.25)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::{SampledWavelengths, SpectralIntegrator, illuminant};

    #[test]
    fn dense_matches_source() {
        let d65 = illuminant::by_name("D65").unwrap();
        let d = DenseSpectrum::new(&d65, WavelengthRange::VISIBLE);
        for l in [380.0, 412.5, 555.0, 729.9, 730.0] {
            assert!((d.eval(l as f32) as f64 - d65.eval(l)).abs() < 1e-3 * d65.eval(l).max(1.0), "{l}");
        }
    }

    #[test]
    fn wavelengths_rotate_over_the_range() {
        let s = XyzSensor::new(&Observer::cie1931(), &Spectrum::Constant(1.0), WavelengthRange::VISIBLE);
        let w = s.sample(0.9).0;
        assert!((w.x - (380.0 + 0.9 * 350.0)).abs() < 1e-3);
        assert!((w.y - (380.0 + 0.15 * 350.0)).abs() < 1e-3);
        for l in w.to_array() {
            assert!((380.0..730.0).contains(&l));
        }
    }

    /// Averaging the one-path estimator over a fine grid of hero wavelengths must equal the
    /// dense integrator in `color` (the same normalisation the real-time renderer uses).
    #[test]
    fn estimator_matches_color_integrator() {
        let obs = Observer::cie1931();
        let d65 = illuminant::by_name("D65").unwrap();
        let f11 = illuminant::by_name("F11").unwrap();
        let r = WavelengthRange::VISIBLE;
        let sensor = XyzSensor::new(&obs, &d65, r);
        let n = 20000;
        let mut acc = [0.0f64; 3];
        for i in 0..n {
            let wl = sensor.sample((i as f32 + 0.5) / n as f32);
            let xyz =
                sensor.to_xyz(&wl, Vec4::from_array(wl.0.to_array().map(|l| f11.eval(l as f64) as f32)));
            (0..3).for_each(|c| acc[c] += xyz[c] / n as f64);
        }
        let dense = SampledWavelengths::midpoint(r, 3500).unwrap();
        let want = SpectralIntegrator::emission(&obs, &d65, &dense).integrate(|l| f11.eval(l));
        for c in 0..3 {
            assert!((acc[c] - want[c]).abs() < 2e-3 * want[c].abs().max(0.1), "{acc:?} vs {want:?}");
        }
    }
}
