//! Jerlov optical water types and their inherent optical properties.
//!
//! Jerlov classified sea water by how fast daylight fades with depth: five oceanic types
//! (I, IA, IB, II, III, clearest first) and five coastal ones (1C, 3C, 5C, 7C, 9C, increasingly
//! turbid). [`WaterType`] names one of them, or a blend of two neighbours; [`WaterProperties`]
//! gives its absorption a, scattering b, attenuation c = a + b and downwelling diffuse
//! attenuation Kd, all per metre, from the tables in [`crate::data::water`] (provenance and the
//! handling of the published tables' defects are in that file's header and `docs/underwater.md`).
//!
//! **Order and blends.** The types are ordered as [`WaterType::ORDER`]:
//! `I, IA, IB, II, III, 1C, 3C, 5C, 7C, 9C` (Jerlov's own order, oceanic then coastal, roughly
//! increasing turbidity). `NAME.F` means the fraction `0.F` of the way from `NAME` to the next
//! type in that list: `II.5` is halfway between II and III, `III.25` a quarter of the way from
//! III to 1C. Properties blend linearly per wavelength (so c = a + b holds for blends too).
//! The list has N = 10 entries and so N − 1 = 9 intervals; positions run from 0 (I) to 9 (9C),
//! and 9C is exactly the last table (the public demo of Monzón et al. divided by N, which
//! never reaches the last type).

use std::fmt;

use crate::data::water::{SOLONENKO2015, WILLIAMSON2022, WaterTable};
use crate::error::{ColorError, Result};
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN, Spectrum};

/// Which published dataset the coefficients come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WaterSource {
    /// Solonenko & Mobley 2015: all ten types, a and b inverted from Jerlov's Kd, 17 wavelengths
    /// from 300 to 700 nm (extended past 700 nm with pure-water absorption). The default.
    #[default]
    Solonenko2015,
    /// Williamson & Hollins 2022: measured a and b at 1 nm for IB, II, III, 1C, 3C, 5C, with
    /// Jerlov's (1976) Kd. The dataset Monzón et al. 2024 render with.
    Williamson2022,
}

impl WaterSource {
    /// Names accepted by [`WaterSource::parse`].
    pub const NAMES: &'static [&'static str] = &["solonenko2015", "williamson2022"];

    /// `solonenko2015` (or `sm`) / `williamson2022` (or `wh`), case-insensitive.
    pub fn parse(name: &str) -> Result<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "solonenko2015" | "solonenko" | "sm" | "sm2015" => Ok(WaterSource::Solonenko2015),
            "williamson2022" | "williamson" | "wh" | "wh2022" => Ok(WaterSource::Williamson2022),
            _ => Err(ColorError::Unknown {
                kind: "water data source",
                name: name.into(),
                known: Self::NAMES.join(", "),
            }),
        }
    }

    /// The embedded tables of this source, in [`WaterType::ORDER`].
    pub fn tables(self) -> &'static [WaterTable] {
        match self {
            WaterSource::Solonenko2015 => &SOLONENKO2015,
            WaterSource::Williamson2022 => &WILLIAMSON2022,
        }
    }

    fn table(self, name: &str) -> Option<&'static WaterTable> {
        self.tables().iter().find(|t| t.name == name)
    }
}

impl fmt::Display for WaterSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            WaterSource::Solonenko2015 => "solonenko2015",
            WaterSource::Williamson2022 => "williamson2022",
        })
    }
}

/// A Jerlov water type or a blend of two neighbouring types: `t` of the way from
/// `ORDER[lower]` to `ORDER[lower + 1]` (position `lower + t` along [`WaterType::ORDER`],
/// 0 = I … 9 = 9C). The fraction is kept as parsed so that `III.1` prints back as `III.1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaterType {
    lower: usize,
    t: f64,
}

impl WaterType {
    /// Jerlov's types in blending order.
    pub const ORDER: [&'static str; 10] = ["I", "IA", "IB", "II", "III", "1C", "3C", "5C", "7C", "9C"];

    fn known() -> String {
        format!(
            "{} (blend neighbours with NAME.F, e.g. II.5 = halfway from II to III)",
            Self::ORDER.join(", ")
        )
    }

    fn unknown(name: &str) -> ColorError {
        ColorError::Unknown { kind: "Jerlov water type", name: name.into(), known: Self::known() }
    }

    /// Parses `II`, `3C` (case-insensitive) or a blend `II.5` / `1C.25`. A blend past the last
    /// type (`9C.5`) and anything else is an error that lists the valid names.
    pub fn parse(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_uppercase();
        let (name, frac) = match t.split_once('.') {
            None => (t.as_str(), 0.0),
            Some((name, digits)) => {
                if digits.is_empty() || !digits.bytes().all(|c| c.is_ascii_digit()) {
                    return Err(Self::unknown(s));
                }
                let f: f64 = format!("0.{digits}").parse().map_err(|_| Self::unknown(s))?;
                (name, f)
            }
        };
        let i = Self::ORDER.iter().position(|n| *n == name).ok_or_else(|| Self::unknown(s))?;
        if i == Self::ORDER.len() - 1 && frac > 0.0 {
            return Err(ColorError::Unknown {
                kind: "Jerlov water type",
                name: s.into(),
                known: format!("{}; 9C is the last type, so it cannot be blended further", Self::known()),
            });
        }
        // So many nines that the fraction rounds to 1 (`II.99999999999999999`): that is the next
        // type, named as such (it rendered III labelled "II.1").
        if frac >= 1.0 {
            return Ok(WaterType { lower: i + 1, t: 0.0 });
        }
        Ok(WaterType { lower: i, t: frac })
    }

    /// A type by position along [`Self::ORDER`] (0 = I, 9 = 9C); fractional positions blend.
    pub fn from_position(position: f64) -> Result<Self> {
        let last = (Self::ORDER.len() - 1) as f64;
        if !(position.is_finite() && (0.0..=last).contains(&position)) {
            return Err(Self::unknown(&format!("position {position}")));
        }
        let lower = position.floor() as usize;
        Ok(WaterType { lower, t: position - lower as f64 })
    }

    /// Position along [`Self::ORDER`].
    pub fn position(self) -> f64 {
        self.lower as f64 + self.t
    }

    /// The two types this one lies between and the weight of the second: `(lower, upper, t)`
    /// with `t` in [0, 1). There are N − 1 intervals for N types, so the last type (9C) is
    /// reachable and is its own upper neighbour.
    pub fn neighbours(self) -> (&'static str, &'static str, f64) {
        let hi = (self.lower + 1).min(Self::ORDER.len() - 1);
        (Self::ORDER[self.lower], Self::ORDER[hi], self.t)
    }

    /// Coefficients of this type from `source`. Errors if the source lacks a type the blend
    /// needs (Williamson & Hollins have no I, IA, 7C or 9C).
    pub fn properties(self, source: WaterSource) -> Result<WaterProperties> {
        let (lo, hi, t) = self.neighbours();
        let need = |name: &str| {
            source.table(name).ok_or_else(|| ColorError::Unknown {
                kind: "water type for this data source",
                name: format!("{self} ({name} in {source})"),
                known: source.tables().iter().map(|t| t.name).collect::<Vec<_>>().join(", "),
            })
        };
        let a = need(lo)?;
        if t == 0.0 {
            return Ok(WaterProperties::from_tables(a, a, 0.0));
        }
        let b = need(hi)?;
        Ok(WaterProperties::from_tables(a, b, t))
    }
}

impl fmt::Display for WaterType {
    /// The canonical name: `II`, or `II.5` for blends (shortest decimal form).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (lo, _, t) = self.neighbours();
        if t == 0.0 {
            return f.write_str(lo);
        }
        let frac = format!("{t}");
        write!(f, "{lo}.{}", frac.trim_start_matches("0."))
    }
}

impl std::str::FromStr for WaterType {
    type Err = ColorError;
    fn from_str(s: &str) -> Result<Self> {
        Self::parse(s)
    }
}

/// Inherent optical properties of a water body, per metre, as continuous spectra over
/// 360–830 nm.
///
/// Beyond the last tabulated wavelength (800 nm) the values are held constant up to 830 nm,
/// where the CIE observers are below 1e-4 of their peak; below 360 nm nothing is needed.
#[derive(Clone, Debug, PartialEq)]
pub struct WaterProperties {
    /// Absorption coefficient a (1/m).
    pub a: Spectrum,
    /// Scattering coefficient b (1/m).
    pub b: Spectrum,
    /// Beam attenuation c = a + b (1/m).
    pub c: Spectrum,
    /// Downwelling diffuse attenuation Kd (1/m).
    pub kd: Spectrum,
}

impl WaterProperties {
    /// Linear blend `(1 − t)·lo + t·hi` on the union of the two tables' wavelengths.
    fn from_tables(lo: &WaterTable, hi: &WaterTable, t: f64) -> Self {
        let mut lambda: Vec<f64> = lo.lambda.iter().chain(hi.lambda).copied().collect();
        lambda.sort_by(f64::total_cmp);
        lambda.dedup();
        if *lambda.last().unwrap_or(&0.0) < LAMBDA_MAX {
            lambda.push(LAMBDA_MAX);
        }
        let interp = |lam: &[f64], v: &[f64], x: f64| {
            // Clamp to the table: values are held beyond its ends (see the type docs).
            let x = x.clamp(lam[0], lam[lam.len() - 1]);
            let i = lam.partition_point(|&l| l <= x).clamp(1, lam.len() - 1);
            let u = (x - lam[i - 1]) / (lam[i] - lam[i - 1]);
            v[i - 1] * (1.0 - u) + v[i] * u
        };
        let blend = |pick: fn(&WaterTable) -> &'static [f64]| -> Vec<f64> {
            lambda
                .iter()
                .map(|&x| (1.0 - t) * interp(lo.lambda, pick(lo), x) + t * interp(hi.lambda, pick(hi), x))
                .collect()
        };
        let a = blend(|w| w.a);
        let b = blend(|w| w.b);
        let kd = blend(|w| w.kd);
        let c: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a + b).collect();
        let mk = |v: Vec<f64>| Spectrum::Piecewise { lambda: lambda.clone(), values: v };
        WaterProperties { a: mk(a), b: mk(b), c: mk(c), kd: mk(kd) }
    }

    /// Shorthand for `WaterType::parse(name)?.properties(WaterSource::default())`.
    pub fn jerlov(name: &str) -> Result<Self> {
        WaterType::parse(name)?.properties(WaterSource::default())
    }

    /// `(a, b, c, Kd)` at `lambda` nm.
    pub fn at(&self, lambda: f64) -> [f64; 4] {
        [self.a.eval(lambda), self.b.eval(lambda), self.c.eval(lambda), self.kd.eval(lambda)]
    }

    /// Checks that every coefficient is finite and non-negative and that c > 0 over the
    /// observer range at 1 nm, naming the first offending wavelength. Embedded data always
    /// passes; user-supplied properties may not.
    pub fn validate(&self) -> Result<()> {
        let n = (LAMBDA_MAX - LAMBDA_MIN) as usize;
        for i in 0..=n {
            let l = LAMBDA_MIN + i as f64;
            let [a, b, c, kd] = self.at(l);
            for (name, v) in [("a", a), ("b", b), ("Kd", kd)] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(ColorError::BadSpectrum(format!(
                        "water {name} at {l} nm is {v}; it must be finite and non-negative"
                    )));
                }
            }
            if c.is_nan() || c <= 0.0 {
                return Err(ColorError::BadSpectrum(format!(
                    "water attenuation c = a + b at {l} nm is {c}; it must be positive (a + b = 0 \
                     means no medium at all)"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::water::SOLONENKO2015_MODIFIED;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-12)
    }

    #[test]
    fn every_type_is_positive_and_finite_over_the_visible() {
        for src in [WaterSource::Solonenko2015, WaterSource::Williamson2022] {
            for t in src.tables() {
                let p = WaterType::parse(t.name).unwrap().properties(src).unwrap();
                p.validate().unwrap();
                for l in 400..=700 {
                    let [a, b, c, kd] = p.at(l as f64);
                    assert!(
                        a > 0.0 && b > 0.0 && kd > 0.0 && a.is_finite() && b.is_finite() && kd.is_finite()
                    );
                    assert!(close(c, a + b, 1e-14), "{} {l}", t.name);
                }
            }
        }
        assert_eq!(SOLONENKO2015.len(), 10);
        assert_eq!(WILLIAMSON2022.len(), 6);
    }

    // Published cells of Solonenko & Mobley 2015 Tables 4–8 (per metre), as printed.
    #[test]
    fn reproduces_solonenko_mobley_table_cells() {
        let cells = [
            ("I", 450.0, 0.018, 0.00381, 0.022),
            ("I", 600.0, 0.228, 0.00122, 0.233),
            ("II", 400.0, 0.0355, 0.616, 0.0846),
            ("II", 500.0, 0.0288, 0.421, 0.0641),
            ("5C", 450.0, 0.297, 1.87, 0.535),
            ("9C", 500.0, 0.543, 3.67, 1.0),
            ("9C", 600.0, 0.39, 2.69, 0.72),
        ];
        for (name, l, a, b, kd) in cells {
            let p = WaterProperties::jerlov(name).unwrap();
            let [pa, pb, pc, pk] = p.at(l);
            assert!(pa == a && pb == b && pk == kd, "{name} {l}: {pa} {pb} {pk}");
            assert!(close(pc, a + b, 1e-12));
        }
    }

    // Williamson & Hollins 2022 (Dstl dataset) cells and Jerlov 1976 Kd cells.
    #[test]
    fn reproduces_williamson_hollins_and_jerlov_cells() {
        let wh = |n: &str| WaterType::parse(n).unwrap().properties(WaterSource::Williamson2022).unwrap();
        let (iii, c5, ii) = (wh("III"), wh("5C"), wh("II"));
        assert_eq!((iii.a.eval(440.0), iii.b.eval(440.0)), (0.121, 0.312));
        assert_eq!((iii.a.eval(650.0), iii.b.eval(650.0)), (0.351, 0.271));
        assert_eq!((c5.a.eval(550.0), c5.b.eval(550.0)), (0.159, 1.19));
        assert_eq!((ii.kd.eval(450.0), ii.kd.eval(550.0)), (0.068, 0.089));
    }

    #[test]
    fn duplicated_rows_are_replaced_not_copied() {
        // DATA.md §1: 5C 600–700 nm repeated the 300–400 nm rows (a = 0.66 at 400 nm etc.).
        let p = WaterProperties::jerlov("5C").unwrap();
        assert_eq!(p.b.eval(600.0), 1.1468);
        assert_eq!(p.kd.eval(700.0), 0.8);
        for l in [600.0, 625.0, 650.0, 675.0, 700.0] {
            assert!(p.kd.eval(l) > p.a.eval(l), "Kd must exceed a at {l}");
            assert!(p.a.eval(l) < 0.7 && p.a.eval(l) > 0.2, "a({l}) = {}", p.a.eval(l));
        }
        assert_eq!(SOLONENKO2015_MODIFIED.len(), 21);
        assert!(
            SOLONENKO2015_MODIFIED
                .iter()
                .all(|(t, l, _, _)| (*t == "3C" && *l >= 675.0) || (*t == "5C" && *l >= 600.0))
        );
    }

    #[test]
    fn extension_past_700_nm_follows_pure_water() {
        let p = WaterProperties::jerlov("II").unwrap();
        // Pure water absorbs strongly past 700 nm: a must rise, and stay positive up to 830 nm.
        assert!(p.a.eval(750.0) > 2.0 * p.a.eval(700.0));
        assert_eq!(p.b.eval(750.0), p.b.eval(700.0));
        assert!(p.kd.eval(830.0) > 0.0 && p.kd.eval(830.0) == p.kd.eval(800.0));
        // Kd/a is held at its 700 nm value.
        assert!(close(p.kd.eval(760.0) / p.a.eval(760.0), p.kd.eval(700.0) / p.a.eval(700.0), 1e-9));
    }

    #[test]
    fn parse_names_blends_and_errors() {
        assert_eq!(WaterType::parse("II").unwrap().position(), 3.0);
        assert_eq!(WaterType::parse(" 3c ").unwrap().position(), 6.0);
        assert_eq!(WaterType::parse("II.5").unwrap().position(), 3.5);
        assert_eq!(WaterType::parse("1C.25").unwrap().position(), 5.25);
        assert_eq!(WaterType::parse("9C").unwrap().position(), 9.0);
        for (s, canon) in [
            ("II.5", "II.5"),
            ("ia", "IA"),
            ("9C", "9C"),
            ("III.25", "III.25"),
            ("II.50", "II.5"),
            ("III.1", "III.1"),
            ("II.99999999999999999", "III"),
        ] {
            assert_eq!(WaterType::parse(s).unwrap().to_string(), canon);
            assert_eq!(WaterType::parse(canon).unwrap(), WaterType::parse(s).unwrap());
        }
        for bad in ["IV", "", "II.", "II.x", "9C.5", "2C", "II.-5", "II.5.5"] {
            let e = WaterType::parse(bad).unwrap_err().to_string();
            assert!(e.contains("IA") && e.contains("9C"), "{bad}: {e}");
        }
        assert!(WaterType::from_position(9.5).is_err());
        assert!(WaterType::from_position(f64::NAN).is_err());
        let e =
            WaterType::parse("I").unwrap().properties(WaterSource::Williamson2022).unwrap_err().to_string();
        assert!(e.contains("IB") && e.contains("williamson2022"), "{e}");
        assert!(WaterSource::parse("SM").is_ok());
        assert!(WaterSource::parse("hydrolight").unwrap_err().to_string().contains("solonenko2015"));
    }

    #[test]
    fn blends_lie_between_neighbours_and_move_monotonically() {
        for src in [WaterSource::Solonenko2015, WaterSource::Williamson2022] {
            let names: Vec<&str> = src.tables().iter().map(|t| t.name).collect();
            for pair in names.windows(2) {
                let lo_pos = WaterType::parse(pair[0]).unwrap().position();
                let hi_pos = WaterType::parse(pair[1]).unwrap().position();
                if hi_pos - lo_pos != 1.0 {
                    continue; // not neighbours in ORDER
                }
                let at = |t: f64| WaterType::from_position(lo_pos + t).unwrap().properties(src).unwrap();
                let steps: Vec<WaterProperties> = (0..=10).map(|k| at(k as f64 / 10.0 * 0.999_999)).collect();
                let end = WaterType::parse(pair[1]).unwrap().properties(src).unwrap();
                for l in (400..=700).step_by(5).map(f64::from) {
                    for q in 0..4 {
                        let v: Vec<f64> = steps.iter().map(|p| p.at(l)[q]).collect();
                        let (v0, v1) = (v[0], end.at(l)[q]);
                        let up = v1 >= v0;
                        for w in v.windows(2) {
                            assert!(if up { w[1] >= w[0] - 1e-12 } else { w[1] <= w[0] + 1e-12 });
                        }
                        // Halfway is the mean of the neighbours.
                        let mid = at(0.5).at(l)[q];
                        assert!(close(mid, 0.5 * (v0 + v1), 1e-12), "{pair:?} {l} q{q}");
                    }
                }
            }
        }
    }

    #[test]
    fn validate_rejects_zero_attenuation_and_nan() {
        let p = WaterProperties::jerlov("II").unwrap();
        let zero = WaterProperties {
            a: Spectrum::Constant(0.0),
            b: Spectrum::Constant(0.0),
            c: Spectrum::Constant(0.0),
            ..p.clone()
        };
        assert!(zero.validate().unwrap_err().to_string().contains("a + b"));
        let nan = WaterProperties { kd: Spectrum::Constant(f64::NAN), ..p };
        assert!(nan.validate().unwrap_err().to_string().contains("Kd"));
    }
}
