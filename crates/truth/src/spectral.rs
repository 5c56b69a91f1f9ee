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

/// The observer as the tracer samples it: its three functions on the 1 nm grid of
/// [`DenseSpectrum`], in f64. Linear between integer nanometres it is the observer itself for
/// data on an integer grid; for data elsewhere (500.5 nm) or ending inside the range (a step to
/// zero, which the grid ramps over 1 nm) it differs slightly, and the normalisation must see
/// what the paths see — integrated against the exact data instead, a white furnace under a
/// 500–510 nm box observer came out 1.09, under CIE 1931 cut at 420 nm 1.055.
struct SampledObserver {
    start: f64,
    values: Vec<[f64; 3]>,
}

impl SampledObserver {
    fn new(observer: &Observer, range: WavelengthRange) -> Self {
        let start = range.min.floor();
        let n = (range.max.ceil() - start) as usize + 2;
        SampledObserver { start, values: (0..n).map(|i| observer.eval(start + i as f64)).collect() }
    }

    fn eval(&self, lambda: f64) -> [f64; 3] {
        let x = (lambda - self.start).max(0.0);
        let i = (x as usize).min(self.values.len() - 2);
        let t = x - i as f64;
        let (a, b) = (self.values[i], self.values[i + 1]);
        [0, 1, 2].map(|c| a[c] * (1.0 - t) + b[c] * t)
    }

    /// ∫ observer(λ)·s(λ) dλ over `range`, each channel, on a 0.1 nm midpoint grid: fine
    /// enough that its quadrature error is far below the tracer's noise.
    fn integral(&self, s: &Spectrum, range: WavelengthRange) -> [f64; 3] {
        let n = (range.width() * 10.0).round().max(1.0) as usize;
        let d = range.width() / n as f64;
        (0..n).fold([0.0; 3], |mut acc, i| {
            let l = range.min + (i as f64 + 0.5) * d;
            let (o, w) = (self.eval(l), s.eval(l));
            (0..3).for_each(|c| acc[c] += o[c] * w * d);
            acc
        })
    }

    /// The normalisation of [`XyzSensor`]: the white's second channel (Y for a CIE observer).
    fn white_k(&self, white: &Spectrum, range: WavelengthRange) -> f64 {
        let k = self.integral(white, range)[1];
        if k > 0.0 { k } else { 1.0 }
    }
}

/// The matrix from the tracer's tristimulus values to linear sRGB ([`color::film`], the
/// convention the real-time renderer and `compare` share): balanced by the observer's response
/// to the RGB white — the colour space's illuminant at the scene white's luminance, which an
/// RGB (1, 1, 1) light emits — integrated over the render range in the sensor's units (for a
/// CIE observer a diagonal in XYZ onto sRGB's white, for any other von Kries).
pub fn display_matrix(
    observer: &Observer,
    white: &Spectrum,
    range: WavelengthRange,
    view: color::film::CameraView,
) -> color::Result<glam::DMat3> {
    let rgb_white = color::RgbColorSpace::srgb()
        .emission_white(white, |s| crate::lights::y_integral(&|l| s.eval(l), range));
    let sampled = SampledObserver::new(observer, range);
    let k = sampled.white_k(white, range);
    let response = sampled.integral(&rgb_white, range).map(|v| v / k);
    color::film::to_linear_srgb(observer, response, &rgb_white, view)
}

impl XyzSensor {
    pub fn new(observer: &Observer, white: &Spectrum, range: WavelengthRange) -> Self {
        let sampled = SampledObserver::new(observer, range);
        let scale = range.width() / sampled.white_k(white, range);
        let cmf = [0, 1, 2].map(|c| DenseSpectrum {
            start: sampled.start as f32,
            values: sampled.values.iter().map(|v| (v[c] * scale) as f32).collect(),
        });
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

    /// Found by a sweep: an observer file whose data end inside the range (a step to zero) or
    /// lie between integer nanometres saw a white furnace at 1.09 (a 500–510 nm box), 1.055
    /// (CIE 1931 cut at 420 nm), 0.992 (500.5–509.5): the paths sample the observer on the
    /// 1 nm grid, the normalisation integrated the exact data. The white is 1 whatever the file.
    #[test]
    fn the_white_is_one_under_any_observer_file() {
        let mut cut = String::from("nm,x,y,z\n");
        for l in (420..=780).step_by(5) {
            let v = Observer::cie1931().eval(l as f64);
            cut.push_str(&format!("{l},{},{},{}\n", v[0], v[1], v[2]));
        }
        let files = [
            ("box", "500,1,1,1\n505,1,1,1\n510,1,1,1\n".to_string()),
            ("half", "500.5,1,1,1\n505,1,1,1\n509.5,1,1,1\n".to_string()),
            ("cut", cut),
        ];
        let r = WavelengthRange::VISIBLE;
        for (name, text) in files {
            let obs = color::observer_file::parse(&text, name).unwrap();
            for white in [Spectrum::Constant(1.0), illuminant::by_name("D65").unwrap()] {
                let sensor = XyzSensor::new(&obs, &white, r);
                let n = 200_000;
                let mut y = 0.0f64;
                for i in 0..n {
                    let wl = sensor.sample((i as f32 + 0.5) / n as f32);
                    let l = Vec4::from_array(wl.0.to_array().map(|l| white.eval(l as f64) as f32));
                    y += sensor.to_xyz(&wl, l)[1] / n as f64;
                }
                assert!((y - 1.0).abs() < 2e-3, "{name}: white Y {y}");
            }
        }
    }
}
