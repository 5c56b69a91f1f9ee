//! glTF extensions: which are implemented, what happens to the others, and the checks that read
//! the document's JSON directly — before the `gltf` crate validates it, so that our message names
//! the real problem ("Draco compression is not supported; decompress with …") rather than a
//! symptom of it ("accessors[0].bufferView: Missing data"), and for extension objects the crate
//! does not parse (`KHR_texture_transform` on every textureInfo, `EXT_mesh_gpu_instancing`).

use glam::Vec2;
use serde_json::Value;

use crate::TextureTransform;
use crate::context::Ctx;
use crate::error::SceneError;

/// Extensions whose meaning the loader implements; a file may require any of them.
pub(crate) const SUPPORTED: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
    "KHR_mesh_quantization",
    "EXT_mesh_gpu_instancing",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "KHR_draco_mesh_compression",
    "KHR_materials_unlit",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_iridescence",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_dispersion",
    "KHR_materials_clearcoat",
    "KHR_materials_specular",
    "KHR_materials_sheen",
    "KHR_materials_anisotropy",
    "KHR_materials_diffuse_transmission",
    "EXT_texture_webp",
    "KHR_texture_basisu",
    "KHR_materials_variants",
    "KHR_animation_pointer",
    "KHR_node_visibility",
];

/// The extensions that give a texture an image in another format than its `source`, in the order
/// the loader prefers them when a texture has several, with what they hold. WebP comes first:
/// the renderers decode every texture to RGBA8 anyway, so Basis Universal's GPU-memory saving
/// buys nothing here, while its block codecs lose more of the authored image than WebP at the
/// usual settings (ETC1S most; lossless WebP nothing).
pub(crate) const IMAGE_EXTENSIONS: [(&str, &str); 2] =
    [("EXT_texture_webp", "WebP"), ("KHR_texture_basisu", "KTX2")];

/// Extensions one renderer draws and the other ignores: a file may use them optionally (with a
/// warning saying which renderer ignores what) but not require them. None at present.
const PARTLY_SUPPORTED: &[&str] = &[];

pub(crate) const DDS: &str = "re-export the file with PNG or JPEG textures";

/// An image format recognised by its first bytes that the loader cannot decode, with what to do.
/// (KTX2 is decoded: `crate::ktx2`.)
pub(crate) fn undecodable_image(bytes: &[u8]) -> Option<(&'static str, &'static str)> {
    if bytes.starts_with(b"DDS ") { Some(("DDS", DDS)) } else { None }
}

/// An unsupported extension: what a file loses when it is ignored (optional), and what to do
/// when the file requires it.
fn unsupported(ext: &str) -> (&'static str, &'static str) {
    match ext {
        "MSFT_texture_dds" => ("its DDS textures are not decoded; the PNG/JPEG fallbacks are used", DDS),
        "KHR_materials_volume_scatter" => (
            "the volume's scattering is ignored; it only absorbs (KHR_materials_volume)",
            "this renderer has no scattering inside a volume",
        ),
        "KHR_xmp_json_ld" | "KHR_xmp" => ("", ""),
        _ => ("it is ignored", ""),
    }
}

/// `KHR_node_visibility`'s `visible` of node `ni` (default true; a value that is not a boolean
/// is an error naming it).
pub(crate) fn node_visible(ctx: &Ctx, raw: &Value, ni: usize) -> Result<bool, SceneError> {
    match raw.pointer(&format!("/nodes/{ni}/extensions/KHR_node_visibility/visible")) {
        None => Ok(true),
        Some(Value::Bool(b)) => Ok(*b),
        Some(v) => Err(ctx.invalid(
            format!("nodes[{ni}].extensions.KHR_node_visibility.visible"),
            format!("{v} is not true or false"),
        )),
    }
}

/// The document without its animation channels that target no node (`KHR_animation_pointer`'s),
/// or `None` when it has none.
pub(crate) fn without_pointer_channels(raw: &Value) -> Option<Value> {
    let has = |c: &Value| c.pointer("/target/node").is_some();
    let any = raw
        .get("animations")?
        .as_array()?
        .iter()
        .any(|a| a.get("channels").and_then(Value::as_array).is_some_and(|cs| !cs.iter().all(has)));
    if !any {
        return None;
    }
    let mut cleaned = raw.clone();
    for a in cleaned.get_mut("animations")?.as_array_mut()? {
        if let Some(cs) = a.get_mut("channels").and_then(Value::as_array_mut) {
            cs.retain(has);
        }
    }
    Some(cleaned)
}

fn strings(v: Option<&Value>) -> impl Iterator<Item = &str> {
    v.and_then(Value::as_array).into_iter().flatten().filter_map(Value::as_str)
}

/// Refuses a file that requires an extension the loader does not implement, with what to do.
pub(crate) fn check_required(ctx: &Ctx, raw: &Value) -> Result<(), SceneError> {
    for (i, ext) in strings(raw.get("extensionsRequired")).enumerate() {
        if SUPPORTED.contains(&ext) {
            continue;
        }
        let (_, what_to_do) = unsupported(ext);
        let advice = if what_to_do.is_empty() { String::new() } else { format!("; {what_to_do}") };
        return Err(ctx.invalid(
            format!("extensionsRequired[{i}]"),
            format!("the file requires {ext}, which is not supported{advice}"),
        ));
    }
    Ok(())
}

/// One line for each extension the file uses (optionally) that the loader ignores, naming what
/// is lost.
pub(crate) fn warnings(raw: &Value) -> Vec<String> {
    let required: Vec<&str> = strings(raw.get("extensionsRequired")).collect();
    // Those the file lists, then those it uses without listing them (a file that forgets
    // `extensionsUsed` lost its clearcoat or sheen without a word).
    let mut used: Vec<&str> = strings(raw.get("extensionsUsed")).collect();
    fn found<'a>(v: &'a Value, out: &mut Vec<&'a str>) {
        match v {
            Value::Object(o) => {
                for (k, x) in o {
                    match (k.as_str(), x) {
                        ("extras", _) => {}
                        ("extensions", Value::Object(e)) => {
                            for (name, inner) in e {
                                if !out.contains(&name.as_str()) {
                                    out.push(name);
                                }
                                found(inner, out);
                            }
                        }
                        _ => found(x, out),
                    }
                }
            }
            Value::Array(a) => a.iter().for_each(|x| found(x, out)),
            _ => {}
        }
    }
    found(raw, &mut used);
    used.into_iter()
        .filter(|e| !SUPPORTED.contains(e) && !required.contains(e))
        .filter_map(|e| {
            let (lost, _) = unsupported(e);
            let how = if PARTLY_SUPPORTED.contains(&e) { "only partly supported" } else { "not supported" };
            (!lost.is_empty()).then(|| format!("{e} is {how}: {lost}"))
        })
        .collect()
}

/// Checks of the raw JSON that must come before validation (see the module documentation):
/// compressed geometry or textures without an uncompressed fallback, sampler enums and alpha
/// cutoffs.
pub(crate) fn precheck(ctx: &Ctx, raw: &Value) -> Result<(), SceneError> {
    check_required(ctx, raw)?;
    let arr = |k: &str| raw.get(k).and_then(Value::as_array).map(Vec::as_slice).unwrap_or_default();
    for (ti, t) in arr("textures").iter().enumerate() {
        if t.get("source").is_some() {
            continue;
        }
        if t.pointer("/extensions/MSFT_texture_dds").is_some() {
            return Err(ctx.invalid(
                format!("textures[{ti}]"),
                format!("its only image is in MSFT_texture_dds, which is not supported; {DDS}"),
            ));
        }
    }
    for (si, s) in arr("samplers").iter().enumerate() {
        let fields: [(&str, &[(u64, &str)]); 4] = [
            ("wrapS", &[(33071, "CLAMP_TO_EDGE"), (33648, "MIRRORED_REPEAT"), (10497, "REPEAT")]),
            ("wrapT", &[(33071, "CLAMP_TO_EDGE"), (33648, "MIRRORED_REPEAT"), (10497, "REPEAT")]),
            ("magFilter", &[(9728, "NEAREST"), (9729, "LINEAR")]),
            (
                "minFilter",
                &[
                    (9728, "NEAREST"),
                    (9729, "LINEAR"),
                    (9984, "NEAREST_MIPMAP_NEAREST"),
                    (9985, "LINEAR_MIPMAP_NEAREST"),
                    (9986, "NEAREST_MIPMAP_LINEAR"),
                    (9987, "LINEAR_MIPMAP_LINEAR"),
                ],
            ),
        ];
        for (f, allowed) in fields {
            let Some(v) = s.get(f) else { continue };
            if !v.as_u64().is_some_and(|x| allowed.iter().any(|(a, _)| *a == x)) {
                let names: Vec<String> = allowed.iter().map(|(n, s)| format!("{n} {s}")).collect();
                return Err(ctx.invalid(
                    format!("samplers[{si}].{f}"),
                    format!("{v} is not a valid value ({})", names.join(", ")),
                ));
            }
        }
    }
    for (mi, m) in arr("materials").iter().enumerate() {
        if let Some(v) = m.get("alphaCutoff")
            && !v.as_f64().is_some_and(|c| c >= 0.0 && (c as f32).is_finite())
        {
            return Err(ctx.invalid(
                format!("materials[{mi}].alphaCutoff"),
                format!("must be a finite number ≥ 0, got {v}"),
            ));
        }
    }
    Ok(())
}

/// The `KHR_texture_transform` of a textureInfo (`info` is its JSON object, `at` its path):
/// the transform (`None` when absent or the identity) and the `texCoord` override, if any.
pub(crate) fn texture_transform(
    ctx: &Ctx,
    at: &str,
    info: Option<&Value>,
) -> Result<(Option<TextureTransform>, Option<u32>), SceneError> {
    let Some(ext) = info.and_then(|i| i.pointer("/extensions/KHR_texture_transform")) else {
        return Ok((None, None));
    };
    let at = format!("{at}.extensions.KHR_texture_transform");
    let bad =
        |k: &str, what: &str| ctx.invalid(format!("{at}.{k}"), format!("must be {what}, got {}", ext[k]));
    let pair = |k: &str, default: Vec2| -> Result<Vec2, SceneError> {
        let Some(v) = ext.get(k) else { return Ok(default) };
        match v.as_array().map(|a| a.iter().map(Value::as_f64).collect::<Vec<_>>()).as_deref() {
            Some([Some(x), Some(y)]) if (*x as f32).is_finite() && (*y as f32).is_finite() => {
                Ok(Vec2::new(*x as f32, *y as f32))
            }
            _ => Err(bad(k, "two finite numbers")),
        }
    };
    let offset = pair("offset", Vec2::ZERO)?;
    let scale = pair("scale", Vec2::ONE)?;
    let rotation = match ext.get("rotation") {
        None => 0.0,
        Some(v) => v
            .as_f64()
            .map(|r| r as f32)
            .filter(|r| r.is_finite())
            .ok_or_else(|| bad("rotation", "a finite number"))?,
    };
    let tex_coord = match ext.get("texCoord") {
        None => None,
        Some(v) => Some(
            v.as_u64()
                .and_then(|t| u32::try_from(t).ok())
                .ok_or_else(|| bad("texCoord", "a non-negative integer"))?,
        ),
    };
    let t = TextureTransform { offset, rotation, scale };
    let identity = offset == Vec2::ZERO && rotation == 0.0 && scale == Vec2::ONE;
    Ok(((!identity).then_some(t), tex_coord))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn optional_extensions_warn_required_ones_refuse_with_advice() {
        let raw = json!({
            "extensionsUsed": ["KHR_materials_volume_scatter", "KHR_materials_sheen", "KHR_texture_transform", "KHR_xmp_json_ld"],
            "extensionsRequired": ["MSFT_texture_dds"],
        });
        let w = warnings(&raw);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("KHR_materials_volume_scatter") && w[0].contains("ignored"), "{w:?}");
        let e = check_required(&Ctx::builtin("t"), &raw).unwrap_err().to_string();
        assert!(e.contains("extensionsRequired[0]") && e.contains("MSFT_texture_dds"), "{e}");
        assert!(e.contains("re-export the file with PNG or JPEG textures"), "{e}");
        // Sheen, anisotropy and diffuse transmission are read (the loader stores them for the
        // renderers): a file may require them.
        for ext in ["KHR_materials_sheen", "KHR_materials_anisotropy", "KHR_materials_diffuse_transmission"] {
            let raw = json!({"extensionsUsed": [ext], "extensionsRequired": [ext]});
            assert!(warnings(&raw).is_empty());
            assert!(check_required(&Ctx::builtin("t"), &raw).is_ok());
        }
    }

    #[test]
    fn texture_transform_parses_and_names_bad_fields() {
        let c = Ctx::builtin("t");
        let info = json!({"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 1.5, "texCoord": 1}}});
        let (t, tc) = texture_transform(&c, "m", Some(&info)).unwrap();
        let t = t.unwrap();
        assert_eq!((t.offset, t.rotation, t.scale, tc), (Vec2::new(0.5, 0.0), 1.5, Vec2::ONE, Some(1)));
        let identity = json!({"extensions": {"KHR_texture_transform": {}}});
        assert_eq!(texture_transform(&c, "m", Some(&identity)).unwrap(), (None, None));
        let bad = json!({"extensions": {"KHR_texture_transform": {"scale": [1]}}});
        let e = texture_transform(&c, "materials[0].normalTexture", Some(&bad)).unwrap_err().to_string();
        assert!(e.contains("materials[0].normalTexture.extensions.KHR_texture_transform.scale"), "{e}");
    }
}
