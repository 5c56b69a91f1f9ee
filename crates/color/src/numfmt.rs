//! How messages write a number a user gave or a bound they must keep: as one would type it.
//! `{}` writes 1e300 with three hundred digits and `{:e}` writes −1 as "-1e0"; this writes
//! plain decimals where they are short and exponent form where they are not.

/// `x` as one would type it: "-1", "0.5", "250", "1e-4", "1e20", "inf", "NaN".
pub fn short(x: f64) -> String {
    if x == 0.0 || (1e-3..1e4).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn numbers_read_as_typed() {
        for (x, want) in [
            (-1.0, "-1"),
            (0.0, "0"),
            (0.5, "0.5"),
            (250.0, "250"),
            (9999.5, "9999.5"),
            (1e4, "1e4"),
            (1e-4, "1e-4"),
            (1e-310, "1e-310"),
            (-2.5e20, "-2.5e20"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(short(x), want);
        }
    }
}
