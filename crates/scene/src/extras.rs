//! The spectral additions a scene carries in glTF `extras`, parsed strictly: an unknown key is an
//! error naming it, because a misspelt `reflectence` silently ignored would make ground truth
//! quietly wrong.

use color::{Observer, Spectrum, WavelengthRange};
use glam::Vec3;
use serde_json::{Map, Value};

use crate::context::Ctx;
use crate::error::SceneError;
use crate::spectrum_desc;
use crate::{MAX_SKY, PaletteEntry, SpectralReflectance, SpectralSettings, WaterSettings};

/// Parses raw `extras` JSON at `at` (e.g. `materials[3]`) into an object, `None` when absent.
pub(crate) fn object(
    ctx: &Ctx,
    at: &str,
    raw: &gltf::json::Extras,
) -> Result<Option<Map<String, Value>>, SceneError> {
    let Some(raw) = raw else { return Ok(None) };
    let v: Value =
        serde_json::from_str(raw.get()).map_err(|e| ctx.extras(format!("{at}.extras"), e.to_string()))?;
    match v {
        Value::Object(m) => Ok(Some(m)),
        Value::Null => Ok(None),
        other => Err(ctx.extras(format!("{at}.extras"), format!("expected an object, got {other}"))),
    }
}

fn check_keys(ctx: &Ctx, at: &str, map: &Map<String, Value>, allowed: &[&str]) -> Result<(), SceneError> {
    match map.keys().find(|k| !allowed.contains(&k.as_str())) {
        Some(k) => {
            Err(ctx.extras(format!("{at}.{k}"), format!("unknown key; allowed here: {}", allowed.join(", "))))
        }
        None => Ok(()),
    }
}

/// Material extras: `reflectance` or `reflectance_palette`, and `emission`.
#[derive(Default)]
pub(crate) struct MaterialExtras {
    pub reflectance: Option<SpectralReflectance>,
    /// Emission spectral shape, not yet scaled to the emissive colour.
    pub emission: Option<Spectrum>,
}

/// Reflectances must be physical: within [0, 1] wherever the observer sees.
fn check_reflectance(ctx: &Ctx, field: &str, s: &Spectrum) -> Result<(), SceneError> {
    let (lo, hi) = (color::spectrum::LAMBDA_MIN, color::spectrum::LAMBDA_MAX);
    let max = s.max_value(lo, hi);
    let min = -s.scaled(-1.0).max_value(lo, hi);
    // Written so that NaN fails too.
    if !(min >= 0.0 && max <= 1.0) {
        return Err(ctx.extras(
            field,
            format!("a reflectance must lie in [0, 1], this one spans {min:.4}–{max:.4} over {lo}–{hi} nm"),
        ));
    }
    Ok(())
}

pub(crate) fn material(ctx: &Ctx, at: &str, map: &Map<String, Value>) -> Result<MaterialExtras, SceneError> {
    let at = format!("{at}.extras");
    check_keys(ctx, &at, map, &["reflectance", "reflectance_palette", "emission"])?;
    let mut out = MaterialExtras::default();
    if map.contains_key("reflectance") && map.contains_key("reflectance_palette") {
        return Err(ctx.extras(&at, "give either reflectance or reflectance_palette, not both"));
    }
    if let Some(v) = map.get("reflectance") {
        let f = format!("{at}.reflectance");
        let s = spectrum_desc::resolve(ctx, &f, v)?;
        check_reflectance(ctx, &f, &s)?;
        out.reflectance = Some(SpectralReflectance::Uniform(s));
    }
    if let Some(v) = map.get("reflectance_palette") {
        let f = format!("{at}.reflectance_palette");
        let arr = v
            .as_array()
            .ok_or_else(|| ctx.extras(&f, "expected an array of {\"rgb8\": [r, g, b], \"spectrum\": ...}"))?;
        if arr.is_empty() {
            return Err(ctx.extras(&f, "the palette is empty"));
        }
        let mut entries: Vec<PaletteEntry> = Vec::with_capacity(arr.len());
        for (i, e) in arr.iter().enumerate() {
            let ef = format!("{f}[{i}]");
            let m = e
                .as_object()
                .ok_or_else(|| ctx.extras(&ef, "expected {\"rgb8\": [r, g, b], \"spectrum\": ...}"))?;
            check_keys(ctx, &ef, m, &["rgb8", "spectrum"])?;
            let rgb8 = rgb8(m.get("rgb8")).map_err(|msg| ctx.extras(format!("{ef}.rgb8"), msg))?;
            if let Some(j) = entries.iter().position(|p| p.rgb8 == rgb8) {
                return Err(
                    ctx.extras(format!("{ef}.rgb8"), format!("{rgb8:?} is already used by entry {j}"))
                );
            }
            let sf = format!("{ef}.spectrum");
            let s = spectrum_desc::resolve(
                ctx,
                &sf,
                m.get("spectrum").ok_or_else(|| ctx.extras(&sf, "missing"))?,
            )?;
            check_reflectance(ctx, &sf, &s)?;
            entries.push(PaletteEntry { rgb8, spectrum: s });
        }
        out.reflectance = Some(SpectralReflectance::Palette(entries));
    }
    if let Some(v) = map.get("emission") {
        out.emission = Some(spectrum_desc::resolve(ctx, &format!("{at}.emission"), v)?);
    }
    Ok(out)
}

fn rgb8(v: Option<&Value>) -> Result<[u8; 3], String> {
    let bad = || "expected three integers 0–255".to_string();
    let arr = v.and_then(Value::as_array).ok_or_else(bad)?;
    if arr.len() != 3 {
        return Err(bad());
    }
    let mut out = [0u8; 3];
    for (o, x) in out.iter_mut().zip(arr) {
        *o = x.as_u64().filter(|&n| n <= 255).ok_or_else(bad)? as u8;
    }
    Ok(out)
}

/// Light extras: `spectrum` (a shape, scaled later to the light's RGB × intensity) and
/// `stands_in_for` (the index of the node whose emissive mesh this light approximates).
#[derive(Default)]
pub(crate) struct LightExtras {
    pub spectrum: Option<Spectrum>,
    pub stands_in_for_node: Option<usize>,
}

pub(crate) fn light(ctx: &Ctx, at: &str, map: &Map<String, Value>) -> Result<LightExtras, SceneError> {
    let at = format!("{at}.extras");
    check_keys(ctx, &at, map, &["spectrum", "stands_in_for"])?;
    let spectrum =
        map.get("spectrum").map(|v| spectrum_desc::resolve(ctx, &format!("{at}.spectrum"), v)).transpose()?;
    let stands_in_for_node = map
        .get("stands_in_for")
        .map(|v| {
            v.as_u64().map(|n| n as usize).ok_or_else(|| {
                ctx.extras(format!("{at}.stands_in_for"), format!("expected a node index, got {v}"))
            })
        })
        .transpose()?;
    Ok(LightExtras { spectrum, stands_in_for_node })
}

/// Scene-level extras (root, asset or scene): `spectra`, `water`, `environment` and `medium`.
#[derive(Default)]
pub(crate) struct SceneExtras {
    pub spectral: SpectralSettings,
    pub water: Option<WaterSettings>,
    pub environment: Option<crate::Environment>,
    pub medium: Option<crate::medium::RgbMedium>,
}

/// The keys [`scene`] reads.
pub(crate) const SCENE_KEYS: &[&str] = &["spectra", "water", "environment", "medium"];

/// Edit distance, for telling a misspelt key from someone else's metadata.
fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// `asset.extras` is where tools put their own metadata (Sketchfab and the Khronos samples:
/// `author`, `license`, `source`, `title`): keep our keys and near-misses of them (so a typo is
/// still an error naming it), drop the rest.
pub(crate) fn without_metadata(map: Map<String, Value>, ours: &[&str]) -> Map<String, Value> {
    map.into_iter()
        .filter(|(k, _)| {
            let lower = k.to_ascii_lowercase();
            ours.iter().any(|o| distance(&lower, o) <= 2)
        })
        .collect()
}

pub(crate) fn scene(
    ctx: &Ctx,
    at: &str,
    map: &Map<String, Value>,
    out: &mut SceneExtras,
) -> Result<(), SceneError> {
    let at = format!("{at}.extras");
    check_keys(ctx, &at, map, SCENE_KEYS)?;
    if let Some(v) = map.get("spectra") {
        out.spectral = spectra(ctx, &format!("{at}.spectra"), v)?;
    }
    if let Some(v) = map.get("water") {
        out.water = Some(water(ctx, &format!("{at}.water"), v)?);
    }
    if let Some(v) = map.get("environment") {
        out.environment = environment(ctx, &format!("{at}.environment"), v)?;
    }
    if let Some(v) = map.get("medium") {
        let m = crate::medium::RgbMedium::from_json(v).map_err(|e| {
            let field =
                if e.field == "medium" { format!("{at}.medium") } else { format!("{at}.medium.{}", e.field) };
            ctx.extras(field, e.why)
        })?;
        out.medium = Some(m);
    }
    Ok(())
}

/// `"environment": "default"`, `"none"`, or `{"file": "sky.hdr", "intensity": 1, "rotation": 0}`
/// (file relative to the scene, rotation in degrees about +Y; `"file": "default"` also works).
fn environment(ctx: &Ctx, at: &str, v: &Value) -> Result<Option<crate::Environment>, SceneError> {
    use crate::Environment;
    let named = |name: &str, f: &str| -> Result<Option<Environment>, SceneError> {
        match name {
            "default" => Ok(Some(Environment::default_sky())),
            "none" => Ok(None),
            rel => {
                let path = ctx.resolve(f, rel)?;
                Environment::load(&path).map(Some).map_err(|e| ctx.extras(f, e.to_string()))
            }
        }
    };
    if let Some(name) = v.as_str() {
        return match name {
            "default" | "none" => named(name, at),
            _ => Err(ctx.extras(
                at,
                format!("expected \"default\", \"none\" or an object with a file, got \"{name}\""),
            )),
        };
    }
    let map =
        v.as_object().ok_or_else(|| ctx.extras(at, "expected \"default\", \"none\" or {\"file\": …}"))?;
    check_keys(ctx, at, map, &["file", "intensity", "rotation"])?;
    let ff = format!("{at}.file");
    let file = map
        .get("file")
        .and_then(Value::as_str)
        .ok_or_else(|| ctx.extras(&ff, "required: an equirectangular .hdr or .exr, relative to the scene"))?;
    let Some(mut env) = named(file, &ff)? else { return Ok(None) };
    if let Some(k) = map.get("intensity") {
        let f = format!("{at}.intensity");
        env = env.with_intensity(finite(ctx, &f, k)?).map_err(|e| ctx.extras(&f, e.message))?;
    }
    if let Some(r) = map.get("rotation") {
        let f = format!("{at}.rotation");
        env = env.with_rotation_degrees(finite(ctx, &f, r)?).map_err(|e| ctx.extras(&f, e.message))?;
    }
    Ok(Some(env))
}

fn spectra(ctx: &Ctx, at: &str, v: &Value) -> Result<SpectralSettings, SceneError> {
    let map = v.as_object().ok_or_else(|| ctx.extras(at, "expected an object"))?;
    check_keys(ctx, at, map, &["observer", "range", "wavelengths", "white"])?;
    let mut s = SpectralSettings::default();
    let string = |k: &str| -> Result<Option<String>, SceneError> {
        map.get(k)
            .map(|x| {
                x.as_str()
                    .map(str::to_string)
                    .ok_or_else(|| ctx.extras(format!("{at}.{k}"), "expected a string"))
            })
            .transpose()
    };
    if let Some(o) = string("observer")? {
        let f = format!("{at}.observer");
        // A file is a file reference like any other: beside the scene, confined to its folder
        // (not read from wherever the command runs, nor from anywhere on the machine).
        let o = if color::observer_file::is_file_name(&o) {
            let p = ctx.resolve(&f, o.trim())?;
            p.to_str().map(str::to_string).ok_or_else(|| ctx.extras(&f, "the file's path is not UTF-8"))?
        } else {
            o
        };
        Observer::by_name(&o).map_err(|e| ctx.extras(&f, e.to_string()))?;
        s.observer = Some(o);
    }
    if let Some(w) = string("white")? {
        color::illuminant::by_name(&w).map_err(|e| ctx.extras(format!("{at}.white"), e.to_string()))?;
        s.white = Some(w);
    }
    if let Some(r) = map.get("range") {
        let f = format!("{at}.range");
        let pair = r.as_array().filter(|a| a.len() == 2).and_then(|a| Some((a[0].as_f64()?, a[1].as_f64()?)));
        let (lo, hi) = pair.ok_or_else(|| ctx.extras(&f, "expected [min, max] in nm"))?;
        WavelengthRange::new(lo, hi).map_err(|e| ctx.extras(&f, e.to_string()))?;
        s.range = Some((lo as f32, hi as f32));
    }
    if let Some(n) = map.get("wavelengths") {
        let f = format!("{at}.wavelengths");
        let n = n
            .as_u64()
            .filter(|&n| (1..=u32::MAX as u64).contains(&n))
            .ok_or_else(|| ctx.extras(&f, format!("expected a whole number of samples ≥ 1, got {n}")))?;
        s.wavelengths = Some(n as u32);
    }
    Ok(s)
}

fn finite(ctx: &Ctx, f: &str, v: &Value) -> Result<f32, SceneError> {
    v.as_f64()
        .filter(|x| x.is_finite())
        .map(|x| x as f32)
        .ok_or_else(|| ctx.extras(f, format!("expected a number, got {v}")))
}

fn water(ctx: &Ctx, at: &str, v: &Value) -> Result<WaterSettings, SceneError> {
    let map = v.as_object().ok_or_else(|| ctx.extras(at, "expected an object"))?;
    check_keys(ctx, at, map, &["type", "depth", "sun_direction", "scale", "sky"])?;
    let tf = format!("{at}.type");
    let water_type = map
        .get("type")
        .and_then(Value::as_str)
        .filter(|s| !s.trim().is_empty())
        .ok_or_else(|| ctx.extras(&tf, "required: a Jerlov water type name such as \"II\" or \"3C\""))?
        .to_string();
    let df = format!("{at}.depth");
    let depth = finite(
        ctx,
        &df,
        map.get("depth").ok_or_else(|| ctx.extras(&df, "required: camera depth in metres"))?,
    )?;
    if depth < 0.0 {
        return Err(ctx.extras(&df, format!("depth below the surface must be ≥ 0 m, got {depth}")));
    }
    let sf = format!("{at}.sun_direction");
    let sun = match map.get("sun_direction") {
        None => Vec3::Y,
        Some(d) => {
            let a =
                d.as_array().filter(|a| a.len() == 3).ok_or_else(|| ctx.extras(&sf, "expected [x, y, z]"))?;
            let v = Vec3::new(finite(ctx, &sf, &a[0])?, finite(ctx, &sf, &a[1])?, finite(ctx, &sf, &a[2])?);
            // Scaled first: [1e38, 1e38, 1e38] overflowed the length and read as "below the horizon".
            let big = v.abs().max_element();
            if big == 0.0 {
                return Err(ctx.extras(&sf, "the sun direction is [0, 0, 0]: give a direction (+y up)"));
            }
            let n = (v / big).normalize();
            if n.y <= 0.0 {
                return Err(ctx.extras(&sf, format!("the sun must be above the horizon (+y up), got {v}")));
            }
            n
        }
    };
    let cf = format!("{at}.scale");
    let scale = map.get("scale").map(|s| finite(ctx, &cf, s)).transpose()?.unwrap_or(1.0);
    if scale <= 0.0 {
        return Err(ctx.extras(&cf, format!("metres per scene unit must be > 0, got {scale}")));
    }
    let kf = format!("{at}.sky");
    let sky = map.get("sky").map(|s| finite(ctx, &kf, s)).transpose()?.unwrap_or(0.0);
    if !(0.0..=MAX_SKY).contains(&sky) {
        return Err(ctx.extras(
            &kf,
            format!("sky irradiance as a multiple of the sun's must lie in 0 ..= {MAX_SKY}, got {sky}"),
        ));
    }
    Ok(WaterSettings { water_type, depth, sun_direction: sun, scale, sky })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metadata_is_dropped_but_misspellings_are_kept() {
        let m: Map<String, Value> = serde_json::from_str(
            r#"{"author": "x", "license": "y", "title": "z", "spectra": {}, "Watre": 1, "enviroment": 2}"#,
        )
        .unwrap();
        let kept: Vec<String> = without_metadata(m, SCENE_KEYS).keys().cloned().collect();
        assert_eq!(kept, ["Watre", "enviroment", "spectra"]);
        assert_eq!(distance("reflectence", "reflectance"), 1);
    }
}
