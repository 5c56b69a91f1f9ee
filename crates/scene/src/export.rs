//! Writing a [`Scene`] as a self-contained `.gltf` (buffers and PNG images as data URIs) with
//! the spectral extras of `docs/scene-format.md`, so built-in scenes can be opened and edited in
//! other tools and loaded back unchanged.
//!
//! Geometry is already in world space, so every mesh gets its own node with no transform.
//! Spectra are written as `{"sampled": ...}` (blackbodies as `{"blackbody": K}`), which the loader
//! rescales to the same luminance on the way back.

use std::io::Write;
use std::path::Path;

use base64::Engine;
use color::Spectrum;
use glam::{Quat, Vec3};
use serde_json::{Value, json};

use crate::error::SceneError;
use crate::{AlphaMode, Filter, LightKind, Sampler, Scene, SpectralReflectance, Texture, Wrap};

fn spectrum_json(s: &Spectrum) -> Value {
    match s {
        Spectrum::Constant(c) => {
            json!({"sampled": {"wavelengths": [color::spectrum::LAMBDA_MIN, color::spectrum::LAMBDA_MAX], "values": [c, c]}})
        }
        Spectrum::Blackbody { kelvin, .. } => json!({"blackbody": kelvin}),
        Spectrum::Piecewise { lambda, values } => {
            json!({"sampled": {"wavelengths": lambda, "values": values}})
        }
    }
}

/// A glTF sampler object; mipmapped minification is written as the `*_MIPMAP_LINEAR` filters.
fn sampler_json(s: &Sampler) -> Value {
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => 10497,
        Wrap::ClampToEdge => 33071,
        Wrap::MirroredRepeat => 33648,
    };
    let mag = match s.mag {
        Filter::Nearest => 9728,
        Filter::Linear => 9729,
    };
    let min = match (s.min, s.mipmaps) {
        (Filter::Nearest, false) => 9728,
        (Filter::Linear, false) => 9729,
        (Filter::Nearest, true) => 9986,
        (Filter::Linear, true) => 9987,
    };
    json!({"wrapS": wrap(s.wrap_s), "wrapT": wrap(s.wrap_t), "magFilter": mag, "minFilter": min})
}

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes))
}

/// Why a scene cannot be written as glTF.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("mesh {0} is empty")]
    EmptyMesh(usize),
    #[error("texture '{name}' has {bytes} bytes for {width}×{height}")]
    TextureSize { name: String, bytes: usize, width: u32, height: u32 },
    #[error("texture '{name}': encoding PNG: {cause}")]
    Png { name: String, cause: image::ImageError },
}

fn png(t: &Texture) -> Result<Vec<u8>, ExportError> {
    let img = image::RgbaImage::from_raw(t.width, t.height, t.rgba8.clone()).ok_or_else(|| {
        ExportError::TextureSize {
            name: t.name.clone(),
            bytes: t.rgba8.len(),
            width: t.width,
            height: t.height,
        }
    })?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|cause| ExportError::Png { name: t.name.clone(), cause })?;
    Ok(out.into_inner())
}

/// Builds the glTF JSON document for `scene`.
pub fn to_gltf_json(scene: &Scene) -> Result<Value, ExportError> {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push =
        |bytes: &[u8], target: u32, count: usize, ctype: u32, ty: &str, minmax: Option<(Vec3, Vec3)>| {
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            views.push(
                json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(), "target": target}),
            );
            bin.extend_from_slice(bytes);
            let mut a =
                json!({"bufferView": views.len() - 1, "componentType": ctype, "count": count, "type": ty});
            if let Some((lo, hi)) = minmax {
                a["min"] = json!(lo.to_array());
                a["max"] = json!(hi.to_array());
            }
            accessors.push(a);
            accessors.len() - 1
        };
    const F32: u32 = 5126;
    const U32: u32 = 5125;
    let floats = |v: &mut dyn Iterator<Item = f32>| v.flat_map(f32::to_le_bytes).collect::<Vec<u8>>();

    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for (i, m) in scene.meshes.iter().enumerate() {
        if m.positions.is_empty() || m.indices.is_empty() {
            return Err(ExportError::EmptyMesh(i));
        }
        let (lo, hi) = crate::framing::bounds(std::slice::from_ref(m)).expect("non-empty");
        let n = m.positions.len();
        let mut attrs = serde_json::Map::new();
        let pos = floats(&mut m.positions.iter().flat_map(|p| p.to_array()));
        attrs.insert("POSITION".into(), json!(push(&pos, 34962, n, F32, "VEC3", Some((lo, hi)))));
        let nrm = floats(&mut m.normals.iter().flat_map(|p| p.to_array()));
        attrs.insert("NORMAL".into(), json!(push(&nrm, 34962, n, F32, "VEC3", None)));
        if !m.uvs.is_empty() {
            let uv = floats(&mut m.uvs.iter().flat_map(|p| p.to_array()));
            attrs.insert("TEXCOORD_0".into(), json!(push(&uv, 34962, n, F32, "VEC2", None)));
        }
        if !m.uvs1.is_empty() {
            let uv = floats(&mut m.uvs1.iter().flat_map(|p| p.to_array()));
            attrs.insert("TEXCOORD_1".into(), json!(push(&uv, 34962, n, F32, "VEC2", None)));
        }
        if !m.colors.is_empty() {
            let c = floats(&mut m.colors.iter().flat_map(|p| p.to_array()));
            attrs.insert("COLOR_0".into(), json!(push(&c, 34962, n, F32, "VEC4", None)));
        }
        if !m.tangents.is_empty() {
            let t = floats(&mut m.tangents.iter().flat_map(|p| p.to_array()));
            attrs.insert("TANGENT".into(), json!(push(&t, 34962, n, F32, "VEC4", None)));
        }
        let idx: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let ia = push(&idx, 34963, m.indices.len(), U32, "SCALAR", None);
        meshes.push(json!({"primitives": [{"attributes": attrs, "indices": ia, "material": m.material}]}));
        nodes.push(json!({"name": format!("mesh {i}"), "mesh": i}));
    }

    let mut images = Vec::new();
    let mut samplers: Vec<Value> = Vec::new();
    let mut textures = Vec::new();
    for (i, t) in scene.textures.iter().enumerate() {
        images.push(json!({"name": t.name, "uri": data_uri("image/png", &png(t)?)}));
        let s = sampler_json(&t.sampler);
        let si = samplers.iter().position(|x| *x == s).unwrap_or_else(|| {
            samplers.push(s);
            samplers.len() - 1
        });
        textures.push(json!({"source": i, "sampler": si}));
    }
    let mut uses_transform = false;
    let mut tex = |r: &crate::TextureRef| {
        let mut j = json!({"index": r.index, "texCoord": r.tex_coord});
        if let Some(t) = &r.transform {
            uses_transform = true;
            j["extensions"] = json!({"KHR_texture_transform": {
                "offset": t.offset.to_array(), "rotation": t.rotation, "scale": t.scale.to_array()}});
        }
        j
    };

    let mut materials = Vec::new();
    for m in &scene.materials {
        let mut pbr = json!({"baseColorFactor": m.base_color.to_array(), "metallicFactor": m.metallic, "roughnessFactor": m.roughness});
        if let Some(t) = &m.base_color_texture {
            pbr["baseColorTexture"] = tex(t);
        }
        if let Some(t) = &m.metallic_roughness_texture {
            pbr["metallicRoughnessTexture"] = tex(t);
        }
        let mut j = json!({"name": m.name, "pbrMetallicRoughness": pbr, "doubleSided": m.double_sided});
        match m.alpha_mode {
            AlphaMode::Opaque => {}
            AlphaMode::Mask { cutoff } => {
                j["alphaMode"] = json!("MASK");
                j["alphaCutoff"] = json!(cutoff);
            }
            AlphaMode::Blend => j["alphaMode"] = json!("BLEND"),
        }
        if let Some(t) = &m.normal_texture {
            j["normalTexture"] = tex(t);
            j["normalTexture"]["scale"] = json!(m.normal_scale);
        }
        if let Some(t) = &m.occlusion_texture {
            j["occlusionTexture"] = tex(t);
            j["occlusionTexture"]["strength"] = json!(m.occlusion_strength);
        }
        // glTF caps emissiveFactor at 1; the rest goes into the strength extension.
        let strength = m.emissive.max_element();
        if strength > 0.0 {
            j["emissiveFactor"] = json!((m.emissive / strength.max(1.0)).to_array());
            if strength > 1.0 {
                j["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": strength}});
            }
        }
        if let Some(t) = &m.emissive_texture {
            j["emissiveTexture"] = tex(t);
        }
        if m.unlit {
            j["extensions"]["KHR_materials_unlit"] = json!({});
        }
        if let Some(ir) = &m.iridescence {
            let mut e = json!({
                "iridescenceFactor": ir.factor,
                "iridescenceIor": ir.ior,
                "iridescenceThicknessMinimum": ir.thickness_min,
                "iridescenceThicknessMaximum": ir.thickness_max,
            });
            if let Some(t) = &ir.texture {
                e["iridescenceTexture"] = tex(t);
            }
            if let Some(t) = &ir.thickness_texture {
                e["iridescenceThicknessTexture"] = tex(t);
            }
            j["extensions"]["KHR_materials_iridescence"] = e;
        }
        if let Some(c) = &m.clearcoat {
            let mut e = json!({
                "clearcoatFactor": c.factor,
                "clearcoatRoughnessFactor": c.roughness,
            });
            if let Some(t) = &c.texture {
                e["clearcoatTexture"] = tex(t);
            }
            if let Some(t) = &c.roughness_texture {
                e["clearcoatRoughnessTexture"] = tex(t);
            }
            if let Some(t) = &c.normal_texture {
                e["clearcoatNormalTexture"] = tex(t);
                e["clearcoatNormalTexture"]["scale"] = json!(c.normal_scale);
            }
            j["extensions"]["KHR_materials_clearcoat"] = e;
        }
        if let Some(sp) = &m.specular {
            let mut e = json!({ "specularFactor": sp.factor, "specularColorFactor": sp.color.to_array() });
            if let Some(t) = &sp.texture {
                e["specularTexture"] = tex(t);
            }
            if let Some(t) = &sp.color_texture {
                e["specularColorTexture"] = tex(t);
            }
            j["extensions"]["KHR_materials_specular"] = e;
        }
        if let Some(sh) = &m.sheen {
            let mut e =
                json!({ "sheenColorFactor": sh.color.to_array(), "sheenRoughnessFactor": sh.roughness });
            if let Some(t) = &sh.color_texture {
                e["sheenColorTexture"] = tex(t);
            }
            if let Some(t) = &sh.roughness_texture {
                e["sheenRoughnessTexture"] = tex(t);
            }
            j["extensions"]["KHR_materials_sheen"] = e;
        }
        if let Some(d) = &m.diffuse_transmission {
            let mut e = json!({
                "diffuseTransmissionFactor": d.factor,
                "diffuseTransmissionColorFactor": d.color.to_array()
            });
            if let Some(t) = &d.texture {
                e["diffuseTransmissionTexture"] = tex(t);
            }
            if let Some(t) = &d.color_texture {
                e["diffuseTransmissionColorTexture"] = tex(t);
            }
            j["extensions"]["KHR_materials_diffuse_transmission"] = e;
        }
        if let Some(an) = &m.anisotropy {
            let mut e = json!({ "anisotropyStrength": an.strength, "anisotropyRotation": an.rotation });
            if let Some(t) = &an.texture {
                e["anisotropyTexture"] = tex(t);
            }
            j["extensions"]["KHR_materials_anisotropy"] = e;
        }
        if m.ior != 1.5 {
            j["extensions"]["KHR_materials_ior"] = json!({ "ior": m.ior });
        }
        if let Some(t) = &m.transmission {
            let mut e = json!({ "transmissionFactor": t.factor });
            if let Some(x) = &t.texture {
                e["transmissionTexture"] = tex(x);
            }
            j["extensions"]["KHR_materials_transmission"] = e;
            if let Some(v) = &t.volume {
                let mut e =
                    json!({ "thicknessFactor": v.thickness, "attenuationColor": v.attenuation_color });
                if v.attenuation_distance.is_finite() {
                    e["attenuationDistance"] = json!(v.attenuation_distance);
                }
                if let Some(x) = &v.thickness_texture {
                    e["thicknessTexture"] = tex(x);
                }
                j["extensions"]["KHR_materials_volume"] = e;
            }
            if t.dispersion > 0.0 {
                j["extensions"]["KHR_materials_dispersion"] = json!({ "dispersion": t.dispersion });
            }
        }
        let mut extras = serde_json::Map::new();
        match &m.spectral {
            Some(SpectralReflectance::Uniform(s)) => {
                extras.insert("reflectance".into(), spectrum_json(s));
            }
            Some(SpectralReflectance::Palette(p)) => {
                let entries: Vec<Value> = p
                    .iter()
                    .map(|e| json!({"rgb8": e.rgb8, "spectrum": spectrum_json(&e.spectrum)}))
                    .collect();
                extras.insert("reflectance_palette".into(), json!(entries));
            }
            None => {}
        }
        if let Some(s) = &m.emission_spectrum {
            extras.insert("emission".into(), spectrum_json(s));
        }
        if !extras.is_empty() {
            j["extras"] = Value::Object(extras);
        }
        materials.push(j);
    }

    let mut lights = Vec::new();
    // Sky stand-ins are derived from `water.sky`; the loader makes them again.
    for (i, l) in scene.lights.iter().filter(|l| !crate::sky::is_stand_in(l)).enumerate() {
        let e = &l.emission;
        let mut j = json!({"name": l.name, "color": e.rgb.to_array(), "intensity": e.intensity});
        let (pos, dir) = match l.kind {
            LightKind::Point { position, range } => {
                j["type"] = json!("point");
                if let Some(r) = range {
                    j["range"] = json!(r);
                }
                (position, -Vec3::Z)
            }
            LightKind::Spot { position, direction, inner_cone, outer_cone, range } => {
                j["type"] = json!("spot");
                j["spot"] = json!({"innerConeAngle": inner_cone, "outerConeAngle": outer_cone});
                if let Some(r) = range {
                    j["range"] = json!(r);
                }
                (position, direction)
            }
            LightKind::Directional { direction } => {
                j["type"] = json!("directional");
                (Vec3::ZERO, direction)
            }
        };
        let mut extras = serde_json::Map::new();
        if let Some(s) = &e.spectrum {
            extras.insert("spectrum".into(), spectrum_json(s));
        }
        if let Some(m) = l.stands_in_for {
            // Mesh i is node i (see above).
            extras.insert("stands_in_for".into(), json!(m));
        }
        if !extras.is_empty() {
            j["extras"] = Value::Object(extras);
        }
        lights.push(j);
        let rot = Quat::from_rotation_arc(-Vec3::Z, dir.normalize());
        nodes.push(json!({"name": l.name, "translation": pos.to_array(), "rotation": rot.to_array(),
            "extensions": {"KHR_lights_punctual": {"light": i}}}));
    }

    let c = &scene.camera;
    let (_, rot, pos) = c.transform.to_scale_rotation_translation();
    let camera = match c.ortho {
        Some((xmag, ymag)) => json!({"type": "orthographic",
            "orthographic": {"xmag": xmag, "ymag": ymag, "znear": c.znear, "zfar": c.zfar}}),
        None => {
            let mut persp = json!({"yfov": c.yfov, "znear": c.znear, "zfar": c.zfar});
            if let Some(a) = c.aspect {
                persp["aspectRatio"] = json!(a);
            }
            json!({"type": "perspective", "perspective": persp})
        }
    };
    nodes.push(
        json!({"name": "camera", "camera": 0, "translation": pos.to_array(), "rotation": rot.to_array()}),
    );

    let mut scene_extras = serde_json::Map::new();
    let sp = &scene.spectral;
    let mut spectra = serde_json::Map::new();
    if let Some(o) = &sp.observer {
        spectra.insert("observer".into(), json!(o));
    }
    if let Some((lo, hi)) = sp.range {
        spectra.insert("range".into(), json!([lo, hi]));
    }
    if let Some(n) = sp.wavelengths {
        spectra.insert("wavelengths".into(), json!(n));
    }
    if let Some(w) = &sp.white {
        spectra.insert("white".into(), json!(w));
    }
    if !spectra.is_empty() {
        scene_extras.insert("spectra".into(), Value::Object(spectra));
    }
    if let Some(w) = &scene.water {
        scene_extras.insert(
            "water".into(),
            json!({
                "type": w.water_type,
                "depth": w.depth,
                "sun_direction": w.sun_direction.to_array(),
                "scale": w.scale,
                "sky": w.sky,
            }),
        );
    }
    if let Some(m) = &scene.medium {
        scene_extras.insert(
            "medium".into(),
            json!({
                "absorption": m.absorption,
                "scattering": m.scattering,
                "g": m.g,
                "scale": m.scale,
                "upsampling": m.upsampling.name(),
            }),
        );
    }

    let mut extensions_used =
        vec!["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_unlit"];
    if scene.materials.iter().any(|m| m.ior != 1.5) {
        extensions_used.push("KHR_materials_ior");
    }
    if scene.materials.iter().any(|m| m.clearcoat.is_some()) {
        extensions_used.push("KHR_materials_clearcoat");
    }
    if scene.materials.iter().any(|m| m.specular.is_some()) {
        extensions_used.push("KHR_materials_specular");
    }
    if scene.materials.iter().any(|m| m.sheen.is_some()) {
        extensions_used.push("KHR_materials_sheen");
    }
    if scene.materials.iter().any(|m| m.anisotropy.is_some()) {
        extensions_used.push("KHR_materials_anisotropy");
    }
    if scene.materials.iter().any(|m| m.diffuse_transmission.is_some()) {
        extensions_used.push("KHR_materials_diffuse_transmission");
    }
    if scene.materials.iter().any(|m| m.iridescence.is_some()) {
        extensions_used.push("KHR_materials_iridescence");
    }
    let transmissive = || scene.materials.iter().filter_map(|m| m.transmission.as_ref());
    if transmissive().next().is_some() {
        extensions_used.push("KHR_materials_transmission");
    }
    if transmissive().any(|t| t.volume.is_some()) {
        extensions_used.push("KHR_materials_volume");
    }
    if transmissive().any(|t| t.dispersion > 0.0) {
        extensions_used.push("KHR_materials_dispersion");
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": format!("spectra scene exporter (from {})", scene.source)},
        "extensionsUsed": extensions_used,
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [camera],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len(), "uri": data_uri("application/octet-stream", &bin)}],
    });
    if !images.is_empty() {
        doc["images"] = json!(images);
        doc["textures"] = json!(textures);
        doc["samplers"] = json!(samplers);
    }
    if uses_transform {
        doc["extensionsUsed"].as_array_mut().expect("written above").push(json!("KHR_texture_transform"));
    }
    if !scene_extras.is_empty() {
        doc["scenes"][0]["extras"] = Value::Object(scene_extras);
    }
    Ok(doc)
}

/// Writes `scene` to `path` as a self-contained `.gltf`. The file appears complete or not at all
/// (written to a temporary file in the same directory, then renamed).
pub fn write_gltf(scene: &Scene, path: &Path) -> Result<(), SceneError> {
    let invalid =
        |m: String| SceneError::Invalid { path: path.to_path_buf(), at: "export".into(), message: m };
    let doc = to_gltf_json(scene).map_err(|e| invalid(e.to_string()))?;
    let text = serde_json::to_string_pretty(&doc).map_err(|e| invalid(e.to_string()))?;
    let io = |e| SceneError::Io { path: path.to_path_buf(), file: path.to_path_buf(), cause: e };
    color::outfile::write_atomic_with(path, |f| {
        f.write_all(text.as_bytes())?;
        f.write_all(b"\n")
    })
    .map_err(io)
}
