//! Choosing the wavelengths a renderer evaluates, and the quadrature weights that go with them.

use crate::error::{ColorError, Result};
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN};

/// Most bins a spectral image may have (also the most bands a spectral EXR is read with:
/// 1 nm over 360–830 nm is 471).
pub const MAX_BINS: usize = 2048;
/// Most samples of one [`SampledWavelengths::midpoint`] set (0.00035 nm over the visible range).
pub const MAX_SAMPLES: usize = 1_000_000;

/// A closed wavelength interval in nanometres, validated against the observer data range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WavelengthRange {
    pub min: f64,
    pub max: f64,
}

impl WavelengthRange {
    /// The visible range the paper renders by default.
    pub const VISIBLE: WavelengthRange = WavelengthRange { min: 380.0, max: 730.0 };
    /// Narrowest range accepted (nm).
    pub const MIN_WIDTH: f64 = 1.0;
    /// The full range of the CIE observer tables.
    pub const FULL: WavelengthRange = WavelengthRange { min: LAMBDA_MIN, max: LAMBDA_MAX };

    pub fn new(min: f64, max: f64) -> Result<Self> {
        let bad = |why: &str| Err(ColorError::BadRange { min, max, why: why.into() });
        if !(min.is_finite() && max.is_finite()) {
            return bad("bounds must be finite");
        }
        if min >= max {
            return bad("the minimum must be below the maximum");
        }
        // A sliver of a range (500:500.0000001) integrates to nothing: a silent black image.
        if max - min < Self::MIN_WIDTH {
            return bad("the range must be at least 1 nm wide");
        }
        if min < LAMBDA_MIN || max > LAMBDA_MAX {
            return bad("spectra has observer data for 360–830 nm only");
        }
        Ok(WavelengthRange { min, max })
    }

    /// Edges of box bins `width` nm wide from `min`, at most [`MAX_BINS`] of them (the last bin ends at `max`, narrower when
    /// `width` does not divide the range): the bins of a spectral image.
    pub fn bin_edges(&self, width: f64) -> Result<Vec<f64>> {
        if !(width.is_finite() && width > 0.0) {
            return Err(ColorError::BadSpectrum(format!("bin width {width} nm: must be a positive number")));
        }
        // A bin narrower than 1 % of the width at the end is rounding, not a bin.
        let n = ((self.width() / width) - 0.01).ceil().max(1.0);
        // Counted before anything is allocated (1e-9 nm used to ask for terabytes).
        if n > MAX_BINS as f64 {
            return Err(ColorError::BadSpectrum(format!(
                "bin width {width} nm: {n:.0} bins over {}–{} nm; at most {MAX_BINS} (a width of at least {:.4} nm)",
                self.min,
                self.max,
                self.width() / (MAX_BINS as f64 - 1.0)
            )));
        }
        let n = n as usize;
        let mut edges: Vec<f64> = (0..n).map(|i| self.min + i as f64 * width).collect();
        edges.push(self.max);
        Ok(edges)
    }

    /// Parses `380:730` (also accepts `380-730` and `380..730`; a minus sign is a sign only
    /// with the `:` separator, as in `-10:700`, which the range then refuses by its bounds).
    pub fn parse(s: &str) -> Result<Self> {
        let t = s.trim();
        let parts = if t.contains(':') {
            t.split_once(':')
        } else if t.contains("..") {
            t.split_once("..")
        } else {
            t.get(1..).and_then(|rest| rest.find('-')).map(|i| (&t[..=i], &t[i + 2..]))
        };
        let num = |p: &str| p.trim().parse::<f64>().ok();
        match parts.map(|(a, b)| (num(a), num(b))) {
            Some((Some(a), Some(b))) => Self::new(a, b),
            _ => Err(ColorError::BadRangeText(s.to_string())),
        }
    }

    pub fn width(&self) -> f64 {
        self.max - self.min
    }
}

/// Wavelengths with quadrature weights: ∫ f(λ) dλ ≈ Σ f(λᵢ) wᵢ.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledWavelengths {
    pub lambda: Vec<f64>,
    pub weight: Vec<f64>,
}

impl SampledWavelengths {
    /// N equally spaced samples at the centres of N equal bins (the midpoint rule). This is
    /// what the real-time renderer uses: deterministic, so there is no noise, and exact for
    /// integrands that are linear across each bin.
    pub fn midpoint(range: WavelengthRange, n: usize) -> Result<Self> {
        if n == 0 {
            return Err(ColorError::NoSamples);
        }
        // Counted before allocating (`upsample --samples 1e11` aborted asking for 800 GB).
        if n > MAX_SAMPLES {
            return Err(ColorError::BadSpectrum(format!("{n} wavelength samples: at most {MAX_SAMPLES}")));
        }
        let d = range.width() / n as f64;
        Ok(SampledWavelengths {
            lambda: (0..n).map(|i| range.min + (i as f64 + 0.5) * d).collect(),
            weight: vec![d; n],
        })
    }

    /// One jittered sample in each of N equal bins: `u[i]` in [0, 1) places sample i in its bin.
    /// Unbiased for any integrand; averaging many frames converges to the exact integral.
    pub fn stratified(range: WavelengthRange, u: &[f64]) -> Result<Self> {
        let n = u.len();
        if n == 0 {
            return Err(ColorError::NoSamples);
        }
        let d = range.width() / n as f64;
        Ok(SampledWavelengths {
            lambda: u
                .iter()
                .enumerate()
                .map(|(i, &ui)| range.min + (i as f64 + ui.clamp(0.0, 0.999_999_999)) * d)
                .collect(),
            weight: vec![d; n],
        })
    }

    /// Box bands given by their edges (N + 1 strictly increasing values, nm): one sample at each
    /// band's centre, weighted by its width. This is how a spectral image's bins are integrated:
    /// the midpoint rule on the bins, exact when the integrand is constant across each bin.
    pub fn from_edges(edges: &[f64]) -> Result<Self> {
        if edges.len() < 2 {
            return Err(ColorError::NoSamples);
        }
        for (i, e) in edges.windows(2).enumerate() {
            if !(e[0].is_finite() && e[1].is_finite()) || e[1] <= e[0] {
                return Err(ColorError::BadSpectrum(format!(
                    "band {i} spans {}–{} nm: band edges must be finite and strictly increasing",
                    e[0], e[1]
                )));
            }
        }
        Ok(SampledWavelengths {
            lambda: edges.windows(2).map(|e| 0.5 * (e[0] + e[1])).collect(),
            weight: edges.windows(2).map(|e| e[1] - e[0]).collect(),
        })
    }

    pub fn len(&self) -> usize {
        self.lambda.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lambda.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn midpoint_places_bin_centres() {
        let w = SampledWavelengths::midpoint(WavelengthRange::new(400.0, 700.0).unwrap(), 3).unwrap();
        assert_eq!(w.lambda, vec![450.0, 550.0, 650.0]);
        assert_eq!(w.weight, vec![100.0; 3]);
    }

    #[test]
    fn midpoint_integrates_linear_exactly() {
        let r = WavelengthRange::new(380.0, 730.0).unwrap();
        let w = SampledWavelengths::midpoint(r, 7).unwrap();
        let sum: f64 = w.lambda.iter().zip(&w.weight).map(|(l, wt)| (2.0 * l + 1.0) * wt).sum();
        let exact = (730.0f64.powi(2) - 380.0f64.powi(2)) + 350.0;
        assert!((sum - exact).abs() < 1e-9);
    }

    #[test]
    fn bins_and_bands() {
        let e = WavelengthRange::new(360.0, 830.0).unwrap().bin_edges(5.0).unwrap();
        assert_eq!((e.len(), e[0], e[1], e[94]), (95, 360.0, 365.0, 830.0));
        let e = WavelengthRange::new(400.0, 417.0).unwrap().bin_edges(5.0).unwrap();
        assert_eq!(e, vec![400.0, 405.0, 410.0, 415.0, 417.0]);
        assert!(WavelengthRange::VISIBLE.bin_edges(0.0).is_err());
        assert!(WavelengthRange::VISIBLE.bin_edges(-5.0).is_err());
        // Bounded before anything is allocated; the message gives the narrowest width allowed.
        let e = WavelengthRange::VISIBLE.bin_edges(1e-9).unwrap_err().to_string();
        assert!(e.contains("at most 2048") && e.contains("0.1710"), "{e}");
        let w = WavelengthRange::VISIBLE.width() / (MAX_BINS as f64 - 1.0);
        assert!(WavelengthRange::VISIBLE.bin_edges(w).unwrap().len() <= MAX_BINS + 1);
        let w = SampledWavelengths::from_edges(&[400.0, 405.0, 415.0]).unwrap();
        assert_eq!((w.lambda, w.weight), (vec![402.5, 410.0], vec![5.0, 10.0]));
        let m = SampledWavelengths::from_edges(&[400.0, 410.0, 405.0]).unwrap_err().to_string();
        assert!(m.contains("band 1") && m.contains("410–405"), "{m}");
        assert!(SampledWavelengths::from_edges(&[400.0]).is_err());
    }

    #[test]
    fn stratified_stays_in_bins() {
        let r = WavelengthRange::new(400.0, 500.0).unwrap();
        let w = SampledWavelengths::stratified(r, &[0.0, 0.5, 0.999]).unwrap();
        assert!(w.lambda[0] >= 400.0 && w.lambda[0] < 400.0 + 100.0 / 3.0);
        assert!(w.lambda[2] < 500.0);
    }

    #[test]
    fn rejects_bad_ranges_and_zero_samples() {
        assert!(WavelengthRange::new(300.0, 700.0).is_err());
        assert!(WavelengthRange::new(700.0, 400.0).is_err());
        assert!(WavelengthRange::new(400.0, 900.0).is_err());
        assert!(WavelengthRange::new(f64::NAN, 700.0).is_err());
        assert_eq!(SampledWavelengths::midpoint(WavelengthRange::VISIBLE, 0), Err(ColorError::NoSamples));
        assert_eq!(WavelengthRange::parse("380:730").unwrap(), WavelengthRange::VISIBLE);
        assert!(WavelengthRange::parse("380").is_err());
        assert!(WavelengthRange::parse("a:b").is_err());
        assert_eq!(WavelengthRange::parse(" 380-730 ").unwrap(), WavelengthRange::VISIBLE);
        assert_eq!(WavelengthRange::parse("380..730").unwrap(), WavelengthRange::VISIBLE);
        // Text that is no range says so, not "NaN–NaN"; a negative bound is a number, refused
        // by the range's own check.
        let e = WavelengthRange::parse("500").unwrap_err().to_string();
        assert!(e.contains("'500'") && e.contains("MIN:MAX") && !e.contains("NaN"), "{e}");
        assert!(matches!(WavelengthRange::parse("-10:700"), Err(ColorError::BadRange { min: -10.0, .. })));
        assert!(WavelengthRange::parse("-").is_err() && WavelengthRange::parse("").is_err());
    }
}
