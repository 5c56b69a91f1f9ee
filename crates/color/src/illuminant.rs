//! Named illuminants.

use crate::data::illuminants;
use crate::error::{ColorError, Result};
use crate::spectrum::Spectrum;

/// Looks up a CIE illuminant by name: `A`, `D50`, `D60`, `D65`, `E`, `F1`–`F12`, `LED-B1`…
/// (case-insensitive), or a blackbody as `blackbody:3200` / `3200K`. Relative spectral power, as tabulated
/// (D-series are 100 at 560 nm).
pub fn by_name(name: &str) -> Result<Spectrum> {
    let lower = name.trim().to_ascii_lowercase();
    if let Some((_, t)) = illuminants::ALL.iter().find(|(n, _)| n.to_ascii_lowercase() == lower) {
        return Ok(Spectrum::from_table(t));
    }
    let kelvin = lower.strip_prefix("blackbody:").or_else(|| lower.strip_suffix('k'));
    if let Some(k) = kelvin.and_then(|k| k.trim().parse::<f64>().ok()) {
        return Spectrum::blackbody(k);
    }
    Err(ColorError::Unknown {
        kind: "illuminant",
        name: name.into(),
        known: names().join(", ") + ", blackbody:<kelvin>",
    })
}

/// Every tabulated illuminant name.
pub fn names() -> Vec<&'static str> {
    illuminants::ALL.iter().map(|(n, _)| *n).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups() {
        assert!(by_name("d65").is_ok());
        assert!(by_name("F11").is_ok());
        assert!(by_name("LED-B3").is_ok());
        assert!(matches!(by_name("3200K").unwrap(), Spectrum::Blackbody { .. }));
        // A "1K" white renders black; 1e-300 K gave NaN.
        for bad in ["1K", "blackbody:1e-300", "blackbody:1e300"] {
            assert!(by_name(bad).unwrap_err().to_string().contains("500"), "{bad}");
        }
        assert!(matches!(by_name("blackbody:6500").unwrap(), Spectrum::Blackbody { .. }));
        let e = by_name("D42").unwrap_err().to_string();
        assert!(e.contains("D42") && e.contains("D65"), "{e}");
    }
}
