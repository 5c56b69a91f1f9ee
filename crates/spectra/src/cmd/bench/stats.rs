//! Statistics for `spectra bench`: percentiles of frame times and the least-squares cost per
//! wavelength.

/// The `p`-th percentile (0–100) of `samples`, linearly interpolated between closest ranks
/// (the definition of NumPy's default `percentile`), so the 50th is the usual median.
/// `None` for no samples or a NaN among them.
pub fn percentile(samples: &[f64], p: f64) -> Option<f64> {
    if samples.is_empty() || samples.iter().any(|v| v.is_nan()) || !(0.0..=100.0).contains(&p) {
        return None;
    }
    let mut v = samples.to_vec();
    v.sort_by(f64::total_cmp);
    let pos = p / 100.0 * (v.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    Some(v[lo] + (v[hi] - v[lo]) * (pos - lo as f64))
}

/// Median, 10th and 90th percentile of one series of frame times.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    pub median: f64,
    pub p10: f64,
    pub p90: f64,
}

impl Summary {
    pub fn of(samples: &[f64]) -> Option<Self> {
        Some(Summary {
            median: percentile(samples, 50.0)?,
            p10: percentile(samples, 10.0)?,
            p90: percentile(samples, 90.0)?,
        })
    }
}

/// Ordinary least-squares line `y = intercept + slope·x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination (1 = every point on the line).
    pub r2: f64,
}

/// Fits a line through `(x, y)` points; `None` with fewer than two distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<LineFit> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx <= 0.0 || !sxx.is_finite() {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    // All y equal: the horizontal line explains everything there is.
    let r2 = if syy > 0.0 { (sxy * sxy) / (sxx * syy) } else { 1.0 };
    Some(LineFit { slope, intercept, r2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_match_numpy_linear() {
        // numpy.percentile([1,2,3,4,10], [10,50,90]) = [1.4, 3.0, 7.6]
        let v = [4.0, 1.0, 10.0, 3.0, 2.0];
        assert!((percentile(&v, 10.0).unwrap() - 1.4).abs() < 1e-12);
        assert_eq!(percentile(&v, 50.0), Some(3.0));
        assert!((percentile(&v, 90.0).unwrap() - 7.6).abs() < 1e-12);
        // Even count: the median is the mean of the middle two.
        assert_eq!(percentile(&[1.0, 2.0, 3.0, 5.0], 50.0), Some(2.5));
        assert_eq!(percentile(&[7.0], 90.0), Some(7.0));
        assert_eq!(percentile(&[], 50.0), None);
        assert_eq!(percentile(&[1.0, f64::NAN], 50.0), None);
        assert_eq!(percentile(&[1.0], 101.0), None);
    }

    #[test]
    fn summary_is_robust_to_an_outlier() {
        let mut v: Vec<f64> = (0..101).map(|i| 20.0 + i as f64 * 0.01).collect();
        v[17] = 5000.0; // one stalled frame
        let s = Summary::of(&v).unwrap();
        assert!((s.median - 20.51).abs() < 0.02, "{s:?}");
        assert!(s.p10 < s.median && s.median < s.p90 && s.p90 < 21.1, "{s:?}");
    }

    #[test]
    fn line_fit_recovers_known_line() {
        // ms = 19 + 5.5·N, the shape measured on lavapipe, with symmetric noise.
        let ns = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0];
        let noise = [0.3, -0.3, 0.2, -0.2, 0.1, -0.1, 0.0];
        let pts: Vec<(f64, f64)> = ns.iter().zip(noise).map(|(&n, e)| (n, 19.0 + 5.5 * n + e)).collect();
        let f = fit_line(&pts).unwrap();
        assert!((f.slope - 5.5).abs() < 0.01, "{f:?}");
        assert!((f.intercept - 19.0).abs() < 0.3, "{f:?}");
        assert!(f.r2 > 0.999);
        let exact = fit_line(&[(1.0, 3.0), (3.0, 7.0)]).unwrap();
        assert_eq!((exact.slope, exact.intercept, exact.r2), (2.0, 1.0, 1.0));
        assert_eq!(fit_line(&[(2.0, 1.0), (2.0, 5.0)]), None);
        assert_eq!(fit_line(&[(2.0, 1.0)]), None);
        assert_eq!(fit_line(&[(1.0, 4.0), (2.0, 4.0)]).unwrap().slope, 0.0);
    }
}
