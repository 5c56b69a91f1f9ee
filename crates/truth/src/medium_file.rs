//! The JSON form of a [`Medium`] (for `spectra truth --medium FILE`):
//!
//! ```json
//! { "sigma_a": 0.05,
//!   "sigma_s": { "wavelengths": [380, 550, 730], "values": [0.2, 0.1, 0.05] },
//!   "phase": { "hg": 0.8 },
//!   "box": { "min": [-1, -1, -1], "max": [1, 1, 1] } }
//! ```
//!
//! Coefficients are per scene unit, as a number (constant) or sampled (nm, linear
//! interpolation, zero outside). `phase` is `"isotropic"` or `{"hg": g}` (default isotropic);
//! without `box` the medium fills the scene. Unknown keys are errors, so typos are caught.

use crate::error::{Result, TruthError};
use crate::medium::{Medium, Phase, Region};
use color::Spectrum;
use glam::Vec3;
use serde_json::Value;

fn bad(origin: &str, why: String) -> TruthError {
    TruthError::BadMedium(format!("{origin}: {why}"))
}

/// An unknown key of the object `v` at `at` (the top level's are checked in `from_json`): a
/// typo inside `phase`, `box` or a sampled coefficient was accepted without a word.
fn only_keys(origin: &str, at: &str, v: &Value, known: &[&str]) -> Result<()> {
    if let Some(k) = v.as_object().and_then(|o| o.keys().find(|k| !known.contains(&k.as_str()))) {
        return Err(bad(origin, format!("unknown key \"{at}.{k}\" (known: {})", known.join(", "))));
    }
    Ok(())
}

fn spectrum(origin: &str, key: &str, v: Option<&Value>) -> Result<Spectrum> {
    let v = v.ok_or_else(|| bad(origin, format!("missing \"{key}\"")))?;
    if let Some(x) = v.as_f64() {
        return Ok(Spectrum::Constant(x));
    }
    only_keys(origin, key, v, &["wavelengths", "values"])?;
    let nums = |k: &str| -> Result<Vec<f64>> {
        v.get(k)
            .and_then(Value::as_array)
            .ok_or_else(|| {
                bad(
                    origin,
                    format!("\"{key}\" must be a number or {{\"wavelengths\": [..], \"values\": [..]}}"),
                )
            })?
            .iter()
            .map(|x| x.as_f64().ok_or_else(|| bad(origin, format!("\"{key}.{k}\" holds a non-number {x}"))))
            .collect()
    };
    Spectrum::piecewise(nums("wavelengths")?, nums("values")?)
        .map_err(|e| bad(origin, format!("\"{key}\": {e}")))
}

fn vec3(origin: &str, key: &str, v: Option<&Value>) -> Result<Vec3> {
    let a = v.and_then(Value::as_array).filter(|a| a.len() == 3);
    let a = a.ok_or_else(|| bad(origin, format!("\"box.{key}\" must be [x, y, z]")))?;
    let f = |i: usize| {
        let x = a[i].as_f64().ok_or_else(|| bad(origin, format!("\"box.{key}\" must hold numbers")))?;
        // The tracer's coordinates are f32: 1e39 would become infinite there.
        if !(x.is_finite() && x.abs() <= MAX_COORDINATE) {
            return Err(bad(
                origin,
                format!("\"box.{key}\"[{i}] = {x:e}: box coordinates must lie within ±{MAX_COORDINATE:e}"),
            ));
        }
        Ok(x as f32)
    };
    Ok(Vec3::new(f(0)?, f(1)?, f(2)?))
}

/// Largest box coordinate accepted (scene units): far beyond any scene, and finite in f32 with
/// room for the ray arithmetic.
pub const MAX_COORDINATE: f64 = 1.0e30;

/// Largest `--medium` file read (bytes); a sampled coefficient at 0.1 nm steps is far below it.
pub const MAX_MEDIUM_FILE_BYTES: u64 = 1 << 20;

impl Medium {
    /// Reads and parses a medium file (only a regular file, at most [`MAX_MEDIUM_FILE_BYTES`]).
    pub fn read(path: &std::path::Path) -> Result<Medium> {
        let origin = path.display().to_string();
        let text = color::input::read_regular_string(path, MAX_MEDIUM_FILE_BYTES)
            .map_err(|e| bad(&origin, format!("cannot read: {e}")))?;
        Self::from_json(&text, &origin)
    }

    /// Parses the JSON form; `origin` (a file name) prefixes every error. Values are checked
    /// by [`Medium::validate`] at render time, against the render's wavelength range.
    pub fn from_json(text: &str, origin: &str) -> Result<Medium> {
        let v = color::input::json_value(text).map_err(|e| bad(origin, format!("not valid JSON: {e}")))?;
        let obj = v.as_object().ok_or_else(|| bad(origin, "expected a JSON object".into()))?;
        if let Some(k) = obj.keys().find(|k| !["sigma_a", "sigma_s", "phase", "box"].contains(&k.as_str())) {
            return Err(bad(origin, format!("unknown key \"{k}\" (known: sigma_a, sigma_s, phase, box)")));
        }
        let phase = match obj.get("phase") {
            None => Phase::Isotropic,
            Some(Value::String(s)) if s == "isotropic" => Phase::Isotropic,
            Some(p) => {
                match only_keys(origin, "phase", p, &["hg"]).map(|_| p.get("hg").and_then(Value::as_f64))? {
                    // Checked here, as written: as f32 0.99999999999 is 1, refused below as "g = 1".
                    Some(g) if !(g > -1.0 && g < 1.0 && (g as f32).abs() < 1.0) => {
                        return Err(bad(
                            origin,
                            format!(
                                "\"phase.hg\" = {g}: the Henyey–Greenstein g must lie strictly between −1 and 1 (as a 32-bit float)"
                            ),
                        ));
                    }
                    Some(g) => Phase::HenyeyGreenstein { g: g as f32 },
                    None => {
                        return Err(bad(
                            origin,
                            format!("\"phase\" must be \"isotropic\" or {{\"hg\": g}}, got {p}"),
                        ));
                    }
                }
            }
        };
        let region = match obj.get("box") {
            None => Region::Everywhere,
            Some(b) => {
                only_keys(origin, "box", b, &["min", "max"])?;
                Region::Box {
                    min: vec3(origin, "min", b.get("min"))?,
                    max: vec3(origin, "max", b.get("max"))?,
                }
            }
        };
        Ok(Medium {
            sigma_a: spectrum(origin, "sigma_a", obj.get("sigma_a"))?,
            sigma_s: spectrum(origin, "sigma_s", obj.get("sigma_s"))?,
            phase,
            region,
            surface_ior: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::WavelengthRange;

    #[cfg(unix)]
    #[test]
    fn devices_are_not_read() {
        // The old `read_to_string` read /dev/zero until memory ran out.
        let e = Medium::read(std::path::Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("a device"), "{e}");
    }

    #[test]
    fn parses_the_documented_form() {
        let m = Medium::from_json(
            r#"{"sigma_a": 0.05, "sigma_s": {"wavelengths": [380, 730], "values": [0.2, 0.1]},
                "phase": {"hg": 0.8}, "box": {"min": [-1, -1, -1], "max": [1, 2, 3]}}"#,
            "m.json",
        )
        .unwrap();
        assert_eq!(m.phase, Phase::HenyeyGreenstein { g: 0.8 });
        assert_eq!(m.region, Region::Box { min: Vec3::splat(-1.0), max: Vec3::new(1.0, 2.0, 3.0) });
        assert!((m.sigma_s.eval(555.0) - 0.15).abs() < 1e-12);
        assert!(m.validate(WavelengthRange::VISIBLE).is_ok());
    }

    #[test]
    fn errors_name_the_file_and_problem() {
        let e = |t: &str| Medium::from_json(t, "water.json").unwrap_err().to_string();
        assert!(e("{").contains("water.json") && e("{").contains("JSON"));
        assert!(e(r#"{"sigma_s": 1}"#).contains("sigma_a"));
        assert!(e(r#"{"sigma_a": 1, "sigma_s": 1, "phaze": "isotropic"}"#).contains("phaze"));
        assert!(e(r#"{"sigma_a": 1, "sigma_s": 1, "phase": {"g": 1}}"#).contains("phase"));
        let neg = Medium::from_json(r#"{"sigma_a": -1, "sigma_s": 1}"#, "w.json").unwrap();
        assert!(neg.validate(WavelengthRange::VISIBLE).unwrap_err().to_string().contains("sigma_a"));
    }

    /// Values the f32 tracer cannot hold are refused as written, naming the field (they used
    /// to read "box [-inf, -1, -1]..[inf, 1, 1]" and "g = 1").
    /// Found by a sweep: unknown keys inside `phase`, `box` and a sampled coefficient were
    /// accepted (the docs promise that unknown keys are errors, typos caught).
    #[test]
    fn unknown_keys_inside_the_objects_are_errors() {
        for (text, key) in [
            (r#"{"sigma_a": 0, "sigma_s": 1, "phase": {"hg": 0.5, "extra": 1}}"#, "phase.extra"),
            (r#"{"sigma_a": 0, "sigma_s": 1, "box": {"min": [0, 0, 0], "max": [1, 1, 1], "x": 1}}"#, "box.x"),
            (
                r#"{"sigma_a": {"wavelengths": [400, 700], "values": [1, 1], "unit": "m"}, "sigma_s": 1}"#,
                "sigma_a.unit",
            ),
        ] {
            let e = Medium::from_json(text, "m.json").unwrap_err().to_string();
            assert!(e.contains("m.json") && e.contains(&format!("unknown key \"{key}\"")), "{e}");
        }
    }

    #[test]
    fn values_beyond_f32_name_their_field() {
        let e = |t: &str| Medium::from_json(t, "w.json").unwrap_err().to_string();
        let m = e(r#"{"sigma_a": 1, "sigma_s": 0, "box": {"min": [-1e39, -1, -1], "max": [1, 1, 1]}}"#);
        assert!(m.contains("w.json") && m.contains("\"box.min\"[0]") && m.contains("-1e39"), "{m}");
        let m = e(r#"{"sigma_a": 1, "sigma_s": 0, "phase": {"hg": 0.99999999999}}"#);
        assert!(m.contains("\"phase.hg\" = 0.99999999999"), "{m}");
        let flat = Medium::from_json(
            r#"{"sigma_a": 1, "sigma_s": 0, "box": {"min": [1, 1, 1], "max": [2, 0, 2]}}"#,
            "w.json",
        )
        .unwrap();
        let m = flat.validate(WavelengthRange::VISIBLE).unwrap_err().to_string();
        assert!(m.contains("box") && m.contains("max") && m.contains("y"), "{m}");
        let huge = Medium::from_json(r#"{"sigma_a": 1e300, "sigma_s": 0}"#, "w.json").unwrap();
        let m = huge.validate(WavelengthRange::VISIBLE).unwrap_err().to_string();
        assert!(m.contains("1e300") && m.len() < 200, "{m}");
    }
}
