//! Continuous spectral distributions: measured tables, constants and blackbodies.

use crate::data::SampledTable;
use crate::error::{ColorError, Result};

/// Lowest wavelength for which spectra has observer data (nm).
pub const LAMBDA_MIN: f64 = 360.0;
/// Highest wavelength for which spectra has observer data (nm).
pub const LAMBDA_MAX: f64 = 830.0;
/// Coolest blackbody accepted (K): a dull red glow; cooler ones emit nothing visible.
pub const BLACKBODY_MIN_KELVIN: f64 = 500.0;
/// Hottest blackbody accepted (K).
pub const BLACKBODY_MAX_KELVIN: f64 = 1.0e6;

/// A spectral distribution over wavelength in nanometres.
///
/// Piecewise spectra interpolate linearly between samples and are zero outside them, like
/// [`SampledTable`]; this is what measured data means, and it is what pbrt's
/// `PiecewiseLinearSpectrum` does too.
#[derive(Clone, Debug, PartialEq)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f64),
    /// Planck's law at `kelvin`, normalised so that its peak is 1.
    Blackbody { kelvin: f64, norm: f64 },
    /// Samples at strictly increasing wavelengths.
    Piecewise { lambda: Vec<f64>, values: Vec<f64> },
}

/// Planck's law: spectral radiance of a blackbody at `lambda_nm` and `kelvin` (W·sr⁻¹·m⁻³).
pub fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = lambda_nm * 1e-9;
    2.0 * H * C * C / (l.powi(5) * ((H * C / (l * KB * kelvin)).exp_m1()))
}

impl Spectrum {
    /// A blackbody emitter, normalised to a peak of 1 (Wien's displacement law gives the peak).
    pub fn blackbody(kelvin: f64) -> Result<Self> {
        // Below the range the visible emission underflows relative to the peak (a "1K" white
        // renders black, 1e-300 K gives NaN); above it the shape no longer changes.
        if !(BLACKBODY_MIN_KELVIN..=BLACKBODY_MAX_KELVIN).contains(&kelvin) {
            return Err(ColorError::BadSpectrum(format!(
                "blackbody temperature must be {BLACKBODY_MIN_KELVIN}–{BLACKBODY_MAX_KELVIN} K, got {kelvin}"
            )));
        }
        let peak_nm = 2.897_771_955e6 / kelvin;
        Ok(Spectrum::Blackbody { kelvin, norm: 1.0 / planck(peak_nm, kelvin) })
    }

    /// A sampled spectrum; wavelengths must be finite and strictly increasing, values finite.
    pub fn piecewise(lambda: Vec<f64>, values: Vec<f64>) -> Result<Self> {
        if lambda.len() != values.len() {
            return Err(ColorError::BadSpectrum(format!(
                "{} wavelengths but {} values",
                lambda.len(),
                values.len()
            )));
        }
        if lambda.len() < 2 {
            return Err(ColorError::BadSpectrum("needs at least two samples".into()));
        }
        if let Some(w) = lambda
            .windows(2)
            .find(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) || !w[0].is_finite())
        {
            return Err(ColorError::BadSpectrum(format!(
                "wavelengths must increase strictly: {} then {}",
                w[0], w[1]
            )));
        }
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(ColorError::BadSpectrum(format!("value {v} is not finite")));
        }
        Ok(Spectrum::Piecewise { lambda, values })
    }

    /// An owned copy of an embedded table.
    pub fn from_table(t: &SampledTable) -> Self {
        let lambda = (0..t.values.len()).map(|i| t.start + t.step * i as f64).collect();
        Spectrum::Piecewise { lambda, values: t.values.to_vec() }
    }

    /// Value at `lambda` nanometres.
    pub fn eval(&self, lambda: f64) -> f64 {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::Blackbody { kelvin, norm } => planck(lambda, *kelvin) * norm,
            Spectrum::Piecewise { lambda: l, values: v } => {
                if lambda.is_nan() || lambda < l[0] || lambda > l[l.len() - 1] {
                    return 0.0;
                }
                let i = l.partition_point(|&x| x <= lambda).clamp(1, l.len() - 1);
                let t = (lambda - l[i - 1]) / (l[i] - l[i - 1]);
                v[i - 1] * (1.0 - t) + v[i] * t
            }
        }
    }

    /// This spectrum multiplied by `k`.
    pub fn scaled(&self, k: f64) -> Self {
        match self {
            Spectrum::Constant(c) => Spectrum::Constant(c * k),
            Spectrum::Blackbody { kelvin, norm } => Spectrum::Blackbody { kelvin: *kelvin, norm: norm * k },
            Spectrum::Piecewise { lambda, values } => {
                Spectrum::Piecewise { lambda: lambda.clone(), values: values.iter().map(|v| v * k).collect() }
            }
        }
    }

    /// Largest value over `[lo, hi]` at 1 nm resolution.
    pub fn max_value(&self, lo: f64, hi: f64) -> f64 {
        let n = (hi - lo).ceil() as usize;
        (0..=n).map(|i| self.eval(lo + i as f64)).fold(f64::MIN, f64::max)
    }

    /// Resamples onto `lambda`, for upload to a GPU buffer.
    pub fn sample(&self, lambda: &[f64]) -> Vec<f64> {
        lambda.iter().map(|&l| self.eval(l)).collect()
    }
}

impl From<&SampledTable> for Spectrum {
    fn from(t: &SampledTable) -> Self {
        Spectrum::from_table(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_interpolates_and_is_zero_outside() {
        let s = Spectrum::piecewise(vec![400.0, 500.0, 600.0], vec![0.0, 1.0, 0.5]).unwrap();
        assert_eq!(s.eval(450.0), 0.5);
        assert_eq!(s.eval(550.0), 0.75);
        assert_eq!(s.eval(600.0), 0.5);
        assert_eq!(s.eval(399.0), 0.0);
        assert_eq!(s.eval(601.0), 0.0);
    }

    #[test]
    fn piecewise_rejects_bad_input() {
        assert!(Spectrum::piecewise(vec![400.0, 400.0], vec![1.0, 1.0]).is_err());
        assert!(Spectrum::piecewise(vec![400.0], vec![1.0]).is_err());
        assert!(Spectrum::piecewise(vec![400.0, 500.0], vec![1.0]).is_err());
        assert!(Spectrum::piecewise(vec![400.0, 500.0], vec![1.0, f64::NAN]).is_err());
    }

    #[test]
    fn blackbody_peaks_at_wien() {
        let b = Spectrum::blackbody(5000.0).unwrap();
        let peak = 2.897_771_955e6 / 5000.0;
        assert!((b.eval(peak) - 1.0).abs() < 1e-12);
        assert!(b.eval(peak - 20.0) < 1.0 && b.eval(peak + 20.0) < 1.0);
        assert!(Spectrum::blackbody(-1.0).is_err());
    }
}
