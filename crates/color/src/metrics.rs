//! Image-level error metrics over pixel lists.

/// Mean absolute error over all pixels and channels.
///
/// Returns `None` if the slices differ in length or are empty: an error metric over nothing is
/// not zero, it is undefined.
pub fn mae(a: &[[f64; 3]], b: &[[f64; 3]]) -> Option<f64> {
    if a.len() != b.len() || a.is_empty() {
        return None;
    }
    let sum: f64 =
        a.iter().zip(b).map(|(p, q)| (p[0] - q[0]).abs() + (p[1] - q[1]).abs() + (p[2] - q[2]).abs()).sum();
    Some(sum / (3 * a.len()) as f64)
}

/// Summary statistics of a per-pixel error: mean, median, 95th and 99th percentile, max.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Stats {
    pub mean: f64,
    pub median: f64,
    pub p95: f64,
    pub p99: f64,
    pub max: f64,
}

impl Stats {
    /// Percentiles use the nearest-rank definition on the sorted values. `None` when empty or
    /// when any value is NaN.
    pub fn of(values: &[f64]) -> Option<Stats> {
        if values.is_empty() || values.iter().any(|v| v.is_nan()) {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let rank = |p: f64| v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
        Some(Stats {
            mean: v.iter().sum::<f64>() / v.len() as f64,
            median: rank(0.5),
            p95: rank(0.95),
            p99: rank(0.99),
            max: v[v.len() - 1],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mae_by_hand() {
        assert!((mae(&[[0.0, 0.5, 1.0]], &[[0.3, 0.5, 0.7]]).unwrap() - 0.2).abs() < 1e-15);
        assert_eq!(mae(&[], &[]), None);
        assert_eq!(mae(&[[0.0; 3]], &[]), None);
    }

    #[test]
    fn stats_nearest_rank() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = Stats::of(&v).unwrap();
        assert_eq!((s.mean, s.median, s.p95, s.p99, s.max), (50.5, 50.0, 95.0, 99.0, 100.0));
        assert!(Stats::of(&[1.0, f64::NAN]).is_none());
    }
}
