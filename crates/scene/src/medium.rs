//! A homogeneous participating medium described in RGB, as artists and glTF files describe one:
//! absorption and scattering coefficients per metre, or an attenuation colour reached at a
//! distance (KHR_materials_volume's `attenuationColor` / `attenuationDistance`) with a
//! single-scattering albedo, plus a Henyey–Greenstein `g`. It fills the whole scene (fog, or
//! the water around an underwater camera).
//!
//! The spectral renderers turn it into σ_a(λ), σ_s(λ) with [`color::upsample::medium`]
//! (docs/rgb-media.md says which upsampling and why). The JSON form, used by the scene's
//! `extras.medium` and by `spectra truth --rgb-medium`:
//!
//! ```json
//! {"absorption": [0.02, 0.05, 0.1], "scattering": [0.3, 0.3, 0.3], "g": 0.3, "scale": 1}
//! {"attenuation_color": [0.8, 0.6, 0.5], "attenuation_distance": 4, "albedo": [0.9, 0.9, 0.9]}
//! ```
//!
//! RGB is linear, in the scene's colour space (glTF: linear sRGB / Rec.709 primaries).
//! Coefficients are per metre and `attenuation_distance` is in metres; `scale` is metres per
//! scene unit (default 1, as for `extras.water`); `g` defaults to 0 (isotropic); `albedo`
//! defaults to 0 (absorbing only); `upsampling` is `"box"` (default), `"transmittance"` or
//! `"unbounded"`.

use color::Spectrum;
use color::error::show;
use color::upsample::CoeffTable;
use color::upsample::medium::Attenuation;
use serde_json::{Map, Value};

/// Largest coefficient accepted, per metre and per scene unit (the path tracer's
/// `truth::medium::MAX_SIGMA`: a mean free path of a micrometre).
pub const MAX_COEFFICIENT: f64 = 1.0e6;

/// A homogeneous medium in RGB. Construct with [`RgbMedium::new`] or [`RgbMedium::from_json`],
/// which validate.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbMedium {
    /// Absorption coefficient σ_a per metre, linear RGB.
    pub absorption: [f64; 3],
    /// Scattering coefficient σ_s per metre, linear RGB.
    pub scattering: [f64; 3],
    /// Henyey–Greenstein mean cosine, in (−1, 1).
    pub g: f64,
    /// Metres per scene unit.
    pub scale: f64,
    /// How the RGB coefficients become spectra.
    pub upsampling: Attenuation,
}

/// What is wrong with a medium: the JSON field (`absorption`, `g`, …) and why.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldError {
    pub field: String,
    pub why: String,
}

impl std::fmt::Display for FieldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.field, self.why)
    }
}

impl std::error::Error for FieldError {}

fn err(field: &str, why: impl Into<String>) -> FieldError {
    FieldError { field: field.into(), why: why.into() }
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

fn check_coefficients(field: &str, v: [f64; 3]) -> Result<(), FieldError> {
    for (c, x) in CHANNELS.iter().zip(v) {
        // `contains` is false for NaN.
        if !(0.0..=MAX_COEFFICIENT).contains(&x) {
            return Err(err(
                field,
                format!(
                    "the {c} coefficient is {}; coefficients must be finite, ≥ 0 and ≤ {MAX_COEFFICIENT:e} per metre",
                    show(x)
                ),
            ));
        }
    }
    Ok(())
}

impl RgbMedium {
    /// Validates: coefficients finite, non-negative and at most [`MAX_COEFFICIENT`], not all
    /// zero; `g` in (−1, 1); `scale` finite and positive.
    pub fn new(
        absorption: [f64; 3],
        scattering: [f64; 3],
        g: f64,
        scale: f64,
        upsampling: Attenuation,
    ) -> Result<Self, FieldError> {
        check_coefficients("absorption", absorption)?;
        check_coefficients("scattering", scattering)?;
        if absorption.iter().chain(&scattering).all(|&x| x == 0.0) {
            return Err(err(
                "absorption",
                "absorption and scattering are all zero: the medium would do nothing",
            ));
        }
        // Also as the f32 both renderers use: 0.999999999 rounds to 1, which the tracer refused later.
        if !(g > -1.0 && g < 1.0 && (g as f32).abs() < 1.0) {
            return Err(err(
                "g",
                format!("the Henyey–Greenstein g = {} must lie strictly between −1 and 1", show(g)),
            ));
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(err(
                "scale",
                format!("metres per scene unit must be a finite number > 0, got {}", show(scale)),
            ));
        }
        if absorption.iter().chain(&scattering).any(|&x| x * scale > MAX_COEFFICIENT) {
            return Err(err(
                "scale",
                format!(
                    "{} m per unit makes a coefficient above {MAX_COEFFICIENT:e} per scene unit",
                    show(scale)
                ),
            ));
        }
        Ok(RgbMedium { absorption, scattering, g, scale, upsampling })
    }

    /// From KHR_materials_volume's attenuation colour (in (0, 1] per channel, the transmittance
    /// after `distance` metres) and a single-scattering albedo in [0, 1]: σ_t = −ln(colour) /
    /// distance, σ_s = albedo·σ_t, σ_a = σ_t − σ_s. A channel with no extinction (colour 1) and
    /// a non-zero albedo is an error: it asks for scattering that cannot happen.
    pub fn from_attenuation(
        color: [f64; 3],
        distance: f64,
        albedo: [f64; 3],
        g: f64,
        scale: f64,
        upsampling: Attenuation,
    ) -> Result<Self, FieldError> {
        for (c, x) in CHANNELS.iter().zip(color) {
            if !(x > 0.0 && x <= 1.0) {
                return Err(err(
                    "attenuation_color",
                    format!("the {c} component is {}; a transmittance colour must lie in (0, 1]", show(x)),
                ));
            }
        }
        if !(distance.is_finite() && distance > 0.0) {
            return Err(err(
                "attenuation_distance",
                format!("must be a finite distance > 0 m, got {}", show(distance)),
            ));
        }
        for (c, x) in CHANNELS.iter().zip(albedo) {
            if !(0.0..=1.0).contains(&x) {
                return Err(err(
                    "albedo",
                    format!("the {c} component is {}; an albedo must lie in [0, 1]", show(x)),
                ));
            }
        }
        if color == [1.0; 3] {
            return Err(err("attenuation_color", "all components are 1: nothing would be attenuated"));
        }
        let sigma_t = color.map(|c| -c.ln() / distance);
        for i in 0..3 {
            if sigma_t[i] == 0.0 && albedo[i] > 0.0 {
                return Err(err(
                    "albedo",
                    format!(
                        "the {} albedo is {} but the {} extinction is zero (attenuation_color {} = 1): scattering needs extinction",
                        CHANNELS[i], albedo[i], CHANNELS[i], CHANNELS[i]
                    ),
                ));
            }
        }
        let scattering: [f64; 3] = std::array::from_fn(|i| albedo[i] * sigma_t[i]);
        let absorption: [f64; 3] = std::array::from_fn(|i| sigma_t[i] - scattering[i]);
        // Only the distance can make finite colours' coefficients too large.
        Self::new(absorption, scattering, g, scale, upsampling).map_err(|e| match e.field.as_str() {
            "absorption" | "scattering" => FieldError { field: "attenuation_distance".into(), why: e.why },
            _ => e,
        })
    }

    /// Parses the JSON form (module docs). Unknown keys are errors.
    pub fn from_json(v: &Value) -> Result<Self, FieldError> {
        const KEYS: [&str; 8] = [
            "absorption",
            "scattering",
            "attenuation_color",
            "attenuation_distance",
            "albedo",
            "g",
            "scale",
            "upsampling",
        ];
        let map: &Map<String, Value> = v.as_object().ok_or_else(|| err("medium", "expected an object"))?;
        if let Some(k) = map.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return Err(err(k, format!("unknown key; allowed: {}", KEYS.join(", "))));
        }
        let number = |k: &str| -> Result<Option<f64>, FieldError> {
            map.get(k)
                .map(|x| x.as_f64().ok_or_else(|| err(k, format!("expected a number, got {x}"))))
                .transpose()
        };
        let rgb = |k: &str| -> Result<Option<[f64; 3]>, FieldError> {
            let Some(x) = map.get(k) else { return Ok(None) };
            let a = x
                .as_array()
                .filter(|a| a.len() == 3)
                .ok_or_else(|| err(k, format!("expected three numbers [r, g, b], got {x}")))?;
            let mut out = [0.0; 3];
            for (o, y) in out.iter_mut().zip(a) {
                *o =
                    y.as_f64().ok_or_else(|| err(k, format!("expected three numbers [r, g, b], got {x}")))?;
            }
            Ok(Some(out))
        };
        let g = number("g")?.unwrap_or(0.0);
        let scale = number("scale")?.unwrap_or(1.0);
        let upsampling = match map.get("upsampling") {
            None => Attenuation::DEFAULT,
            Some(Value::String(s)) => Attenuation::parse(s).map_err(|e| err("upsampling", e.to_string()))?,
            Some(x) => return Err(err("upsampling", format!("expected a name, got {x}"))),
        };
        let coefficients = map.contains_key("absorption") || map.contains_key("scattering");
        let colour = map.contains_key("attenuation_color") || map.contains_key("attenuation_distance");
        match (coefficients, colour) {
            (true, true) => Err(err(
                "attenuation_color",
                "give either absorption/scattering coefficients or attenuation_color + attenuation_distance, not both",
            )),
            (true, false) => {
                if map.contains_key("albedo") {
                    return Err(err(
                        "albedo",
                        "albedo goes with attenuation_color; with coefficients give scattering",
                    ));
                }
                Self::new(
                    rgb("absorption")?.unwrap_or([0.0; 3]),
                    rgb("scattering")?.unwrap_or([0.0; 3]),
                    g,
                    scale,
                    upsampling,
                )
            }
            (false, true) => {
                let c = rgb("attenuation_color")?
                    .ok_or_else(|| err("attenuation_color", "required with attenuation_distance"))?;
                let d = number("attenuation_distance")?
                    .ok_or_else(|| err("attenuation_distance", "required with attenuation_color (metres)"))?;
                Self::from_attenuation(c, d, rgb("albedo")?.unwrap_or([0.0; 3]), g, scale, upsampling)
            }
            (false, false) => Err(err(
                "absorption",
                "missing: give absorption and/or scattering (per metre), or attenuation_color + attenuation_distance",
            )),
        }
    }

    /// Parses JSON text (a `--rgb-medium` argument or file).
    pub fn from_json_str(text: &str) -> Result<Self, FieldError> {
        let v = color::input::json_value(text).map_err(|e| err("medium", format!("not valid JSON: {e}")))?;
        Self::from_json(&v)
    }

    /// σ_a + σ_s per metre.
    pub fn extinction(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.absorption[i] + self.scattering[i])
    }

    /// A warning when this medium, filling `scene`, leaves it dark: the environment and
    /// directional lights are infinitely far, so none of their light reaches into a medium
    /// without end that has extinction in every channel (both renderers, docs/rgb-media.md); a
    /// scene lit by them alone is black but for what glows. `None` when a point or spot light,
    /// or an emissive surface bright enough to light it, is there, or nothing lights it at all
    /// (the loader says so already).
    pub fn unlit_warning(&self, scene: &crate::Scene) -> Option<String> {
        if self.extinction().iter().any(|&k| k <= 0.0) {
            return None;
        }
        let sources = crate::environment::LightSources::of(scene);
        let reaches = scene.lights.iter().any(|l| !matches!(l.kind, crate::LightKind::Directional { .. }));
        if reaches || sources.emitters_light() {
            return None;
        }
        let suns = scene.lights.len();
        let what = match (sources.environment, suns > 0) {
            (true, true) => "the environment and directional lights",
            (true, false) => "the environment",
            (false, true) => "directional lights",
            (false, false) => return None,
        };
        Some(format!(
            "warning: {}: lit by {what} alone, whose light does not reach into the RGB medium (it fills \
             the scene and has extinction in every channel): the image will be black but for what \
             glows; add a point, spot or area light, or leave the medium out",
            scene.source
        ))
    }

    /// (σ_a(λ), σ_s(λ)) per *scene unit*, upsampled through `table` (the scene colour space's
    /// Jakob–Hanika table) by [`Self::upsampling`].
    pub fn spectra(&self, table: &CoeffTable) -> color::Result<(Spectrum, Spectrum)> {
        let k = self.scale;
        let (a, s) = color::upsample::medium::medium(
            table,
            self.absorption.map(|x| x * k),
            self.scattering.map(|x| x * k),
            self.upsampling,
        )?;
        Ok((a, s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(json: &str) -> FieldError {
        RgbMedium::from_json_str(json).unwrap_err()
    }

    /// What Windows Notepad writes (a byte-order mark first) is read; a key given twice is
    /// refused (the last one won, silently); numbers in messages stay short.
    #[test]
    fn a_bom_is_read_a_repeated_key_refused_and_numbers_short() {
        assert!(RgbMedium::from_json_str("\u{feff}{\"absorption\": [0.1, 0.2, 0.3]}").is_ok());
        let dup = e(r#"{"absorption": [0.1, 0.2, 0.3], "absorption": [1, 1, 1]}"#);
        assert!(dup.to_string().contains("\"absorption\" is given twice"), "{dup}");
        for (json, shown) in [
            (r#"{"absorption": [1, 1, 1], "scale": 1e300}"#, "1e300 m per unit"),
            (
                r#"{"attenuation_color": [0.5, 0.5, 0.5], "attenuation_distance": 1e-300}"#,
                "is 6.931471805599452e299",
            ),
        ] {
            let m = e(json).to_string();
            assert!(m.contains(shown) && m.len() < 200, "{m}");
        }
    }

    #[test]
    fn parses_both_forms() {
        let m =
            RgbMedium::from_json_str(r#"{"absorption": [0.1, 0.2, 0.3], "scattering": [1, 1, 1], "g": 0.5}"#)
                .unwrap();
        assert_eq!(m.extinction(), [1.1, 1.2, 1.3]);
        assert_eq!((m.g, m.scale, m.upsampling), (0.5, 1.0, Attenuation::DEFAULT));
        let k = RgbMedium::from_json_str(
            r#"{"attenuation_color": [0.5, 0.25, 1], "attenuation_distance": 2, "albedo": [0.5, 1, 0],
                "upsampling": "unbounded", "scale": 0.5}"#,
        )
        .unwrap();
        let l2 = std::f64::consts::LN_2;
        let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!(close(k.extinction(), [l2 / 2.0, l2, 0.0]), "{:?}", k.extinction());
        assert!(close(k.scattering, [l2 / 4.0, l2, 0.0]));
        assert_eq!((k.scale, k.upsampling), (0.5, Attenuation::Unbounded));
    }

    /// A medium without end keeps the environment and suns out (docs/rgb-media.md): a scene lit
    /// by them alone is warned about, one with a light inside, or a channel the medium leaves
    /// clear, is not.
    #[test]
    fn a_scene_lit_only_from_infinity_is_warned_about() {
        let fog = RgbMedium::from_json_str(r#"{"absorption": [0.1, 0.2, 0.3]}"#).unwrap();
        let mut s = crate::builtin("cornell").unwrap();
        assert!(fog.unlit_warning(&s).is_none(), "the box's lamp lights it");
        s.lights.clear();
        s.materials.iter_mut().for_each(|m| m.emissive = glam::Vec3::ZERO);
        assert!(fog.unlit_warning(&s).is_none(), "nothing lights it: the loader's warning");
        let mut sky = s.clone();
        sky.environment = Some(crate::environment::Environment::default_sky());
        let w = fog.unlit_warning(&sky).unwrap();
        assert!(w.contains("the environment alone") && w.contains("black"), "{w}");
        let mut sun = s.clone();
        sun.lights.push(crate::environment::default_sun_under_water());
        assert!(fog.unlit_warning(&sun).unwrap().contains("directional lights alone"));
        let clear_blue = RgbMedium::from_json_str(r#"{"absorption": [0.1, 0.2, 0]}"#).unwrap();
        assert!(clear_blue.unlit_warning(&sky).is_none());
        let mut lamp = sky.clone();
        lamp.lights.push(crate::Light {
            name: "lamp".into(),
            kind: crate::LightKind::Point { position: glam::Vec3::ZERO, range: None },
            emission: crate::Emission { rgb: glam::Vec3::ONE, intensity: 1.0, spectrum: None },
            stands_in_for: None,
        });
        assert!(fog.unlit_warning(&lamp).is_none());
    }

    /// Every bad input names its field.
    #[test]
    fn bad_input_names_the_field() {
        let cases = [
            (r#"{"absorption": [-0.1, 0, 0]}"#, "absorption", "red"),
            (r#"{"scattering": [0, 1e300, 0]}"#, "scattering", "green"),
            (r#"{"absorption": [0, 0, 0], "scattering": [0, 0, 0]}"#, "absorption", "all zero"),
            (r#"{"absorption": [1, 1, 1], "g": 1}"#, "g", "between"),
            (r#"{"absorption": [1, 1, 1], "g": -1.5}"#, "g", "between"),
            (r#"{"absorption": [1, 1, 1], "g": 0.999999999}"#, "g", "between"),
            (r#"{"absorption": [1, 1, 1], "scale": 0}"#, "scale", "> 0"),
            (r#"{"absorption": [1, 1]}"#, "absorption", "three numbers"),
            (r#"{"absorption": [1, "x", 1]}"#, "absorption", "three numbers"),
            (r#"{"absorbtion": [1, 1, 1]}"#, "absorbtion", "unknown key"),
            (r#"{"absorption": [1, 1, 1], "upsampling": "spline"}"#, "upsampling", "box"),
            (
                r#"{"attenuation_color": [1, 0.5, 0.5], "attenuation_distance": 1, "albedo": [0.5, 0.5, 0.5]}"#,
                "albedo",
                "extinction is zero",
            ),
            (
                r#"{"attenuation_color": [0, 0.5, 0.5], "attenuation_distance": 1}"#,
                "attenuation_color",
                "(0, 1]",
            ),
            (
                r#"{"attenuation_color": [1.2, 0.5, 0.5], "attenuation_distance": 1}"#,
                "attenuation_color",
                "(0, 1]",
            ),
            (
                r#"{"attenuation_color": [0.5, 0.5, 0.5], "attenuation_distance": -2}"#,
                "attenuation_distance",
                "> 0",
            ),
            (r#"{"attenuation_color": [0.5, 0.5, 0.5]}"#, "attenuation_distance", "required"),
            (
                r#"{"attenuation_color": [0.5, 0.5, 0.5], "attenuation_distance": 1, "albedo": [2, 0, 0]}"#,
                "albedo",
                "[0, 1]",
            ),
            (
                r#"{"attenuation_color": [1, 1, 1], "attenuation_distance": 1}"#,
                "attenuation_color",
                "nothing",
            ),
            (
                r#"{"attenuation_color": [0.5, 0.5, 0.5], "attenuation_distance": 1e-9}"#,
                "attenuation_distance",
                "≤",
            ),
            (
                r#"{"absorption": [1, 1, 1], "attenuation_color": [0.5, 0.5, 0.5]}"#,
                "attenuation_color",
                "not both",
            ),
            (r#"{"g": 0.5}"#, "absorption", "missing"),
            (r#"[1, 2]"#, "medium", "object"),
            (r#"{"#, "medium", "JSON"),
        ];
        for (json, field, why) in cases {
            let x = e(json);
            assert_eq!(x.field, field, "{json}: {x}");
            assert!(x.why.contains(why), "{json}: {x}");
        }
        // NaN cannot be written in JSON; the constructor refuses it.
        let n = RgbMedium::new([f64::NAN, 0.0, 0.0], [0.0; 3], 0.0, 1.0, Attenuation::DEFAULT).unwrap_err();
        assert_eq!(n.field, "absorption");
        let n = RgbMedium::new([1.0; 3], [0.0; 3], f64::NAN, 1.0, Attenuation::DEFAULT).unwrap_err();
        assert_eq!(n.field, "g");
    }
}
