//! Structure-aware glTF: `arbitrary` builds a document that parses as JSON and mostly as glTF —
//! meshes with accessors into one embedded buffer, materials, a node tree, a camera, lights,
//! the extensions and `extras` spectra reads — with hostile numbers and counts where the fuzzer
//! puts them, so that coverage reaches the loader's checks past the JSON parser (the byte-level
//! target mostly dies there). A panic is a crash; an error is a refused input.
#![no_main]
use arbitrary::Arbitrary;
use base64::Engine;
use serde_json::{Value, json};

#[derive(Arbitrary, Debug)]
struct Doc {
    positions: Vec<[f32; 3]>,
    indices: Vec<u16>,
    normals: bool,
    uvs: Option<Vec<[f32; 2]>>,
    colors: Option<Vec<[f32; 4]>>,
    tangents: bool,
    /// Added to each accessor's count (a count past the buffer, or 0).
    count_delta: i8,
    byte_offset: u8,
    mode: Option<u8>,
    materials: Vec<Mat>,
    nodes: Vec<Node>,
    camera: Option<Cam>,
    lights: Vec<Light>,
    extras: Option<Extras>,
}

#[derive(Arbitrary, Debug)]
struct Mat {
    base: [f32; 4],
    metallic: f32,
    roughness: f32,
    emissive: [f32; 3],
    emissive_strength: Option<f32>,
    alpha: u8,
    cutoff: f32,
    double_sided: bool,
    unlit: bool,
    normal_scale: Option<f32>,
    reflectance_blackbody: Option<f64>,
}

#[derive(Arbitrary, Debug)]
struct Node {
    translation: Option<[f32; 3]>,
    rotation: Option<[f32; 4]>,
    scale: Option<[f32; 3]>,
    matrix: Option<[f32; 16]>,
    mesh: bool,
    camera: bool,
    light: Option<u8>,
    children: Vec<u8>,
}

#[derive(Arbitrary, Debug)]
enum Cam {
    Perspective { yfov: f32, znear: f32, zfar: Option<f32>, aspect: Option<f32> },
    Orthographic { xmag: f32, ymag: f32, znear: f32, zfar: f32 },
}

#[derive(Arbitrary, Debug)]
struct Light {
    kind: u8,
    color: [f32; 3],
    intensity: f32,
    range: Option<f32>,
    inner: f32,
    outer: f32,
}

#[derive(Arbitrary, Debug)]
struct Extras {
    wavelengths: Option<u32>,
    range: Option<[f64; 2]>,
    water: Option<(u8, f64, [f32; 3], f64, f64)>,
    medium: Option<([f64; 3], [f64; 3], f64, f64)>,
}

const ALPHA_MODES: [&str; 3] = ["OPAQUE", "MASK", "BLEND"];

fn n(x: f32) -> Value {
    // JSON has no NaN or ∞: those become the largest finite numbers, still hostile.
    if x.is_nan() {
        json!(0)
    } else if x.is_infinite() {
        json!(x.signum() * f32::MAX)
    } else {
        json!(x)
    }
}
fn n64(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { json!(0) }
}
fn arr(v: &[f32]) -> Value {
    Value::Array(v.iter().map(|&x| n(x)).collect())
}

fn build(d: &Doc) -> Value {
    let mut buf: Vec<u8> = vec![0; d.byte_offset as usize % 16];
    let mut views = vec![];
    let mut accessors = vec![];
    let count = |len: usize| (len as i64 + d.count_delta as i64).max(0);
    let mut push = |bytes: Vec<u8>, len: usize, ty: &str, comp: u32, buf: &mut Vec<u8>| -> usize {
        while buf.len() % 4 != 0 {
            buf.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": buf.len(), "byteLength": bytes.len()}));
        buf.extend(bytes);
        accessors.push(
            json!({"bufferView": views.len() - 1, "componentType": comp, "count": count(len), "type": ty}),
        );
        accessors.len() - 1
    };
    let pos: Vec<[f32; 3]> = d.positions.iter().take(64).copied().collect();
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let p = push(f32s(&pos.concat()), pos.len(), "VEC3", 5126, &mut buf);
    let mut attrs = json!({"POSITION": p});
    if d.normals {
        let nrm: Vec<f32> = pos.iter().flat_map(|q| [q[1], q[2], q[0]]).collect();
        attrs["NORMAL"] = json!(push(f32s(&nrm), pos.len(), "VEC3", 5126, &mut buf));
    }
    if let Some(uv) = &d.uvs {
        let uv: Vec<[f32; 2]> = uv.iter().take(64).copied().collect();
        attrs["TEXCOORD_0"] = json!(push(f32s(&uv.concat()), uv.len(), "VEC2", 5126, &mut buf));
    }
    if let Some(c) = &d.colors {
        let c: Vec<[f32; 4]> = c.iter().take(64).copied().collect();
        attrs["COLOR_0"] = json!(push(f32s(&c.concat()), c.len(), "VEC4", 5126, &mut buf));
    }
    if d.tangents {
        let t: Vec<f32> = pos.iter().flat_map(|q| [q[2], q[0], q[1], 1.0]).collect();
        attrs["TANGENT"] = json!(push(f32s(&t), pos.len(), "VEC4", 5126, &mut buf));
    }
    let idx: Vec<u16> = d.indices.iter().take(192).copied().collect();
    let ib = push(idx.iter().flat_map(|i| i.to_le_bytes()).collect(), idx.len(), "SCALAR", 5123, &mut buf);
    let mut prim = json!({"attributes": attrs, "indices": ib});
    if let Some(m) = d.mode {
        prim["mode"] = json!(m % 8);
    }
    if !d.materials.is_empty() {
        prim["material"] = json!(0);
    }
    let materials: Vec<Value> = d
        .materials
        .iter()
        .take(4)
        .map(|m| {
            let mut j = json!({
                "pbrMetallicRoughness": {"baseColorFactor": arr(&m.base), "metallicFactor": n(m.metallic), "roughnessFactor": n(m.roughness)},
                "emissiveFactor": arr(&m.emissive),
                "alphaMode": ALPHA_MODES[m.alpha as usize % 3],
                "alphaCutoff": n(m.cutoff),
                "doubleSided": m.double_sided,
            });
            let mut ext = serde_json::Map::new();
            if let Some(s) = m.emissive_strength {
                ext.insert("KHR_materials_emissive_strength".into(), json!({"emissiveStrength": n(s)}));
            }
            if m.unlit {
                ext.insert("KHR_materials_unlit".into(), json!({}));
            }
            if !ext.is_empty() {
                j["extensions"] = Value::Object(ext);
            }
            if let Some(s) = m.normal_scale {
                // A texture index past the document: refused, or read with the scale.
                j["normalTexture"] = json!({"index": 0, "scale": n(s)});
            }
            if let Some(t) = m.reflectance_blackbody {
                j["extras"] = json!({"reflectance": {"blackbody": n64(t)}});
            }
            j
        })
        .collect();
    let nodes: Vec<Value> = d
        .nodes
        .iter()
        .take(8)
        .map(|nd| {
            let mut j = json!({});
            if let Some(t) = nd.translation {
                j["translation"] = arr(&t);
            }
            if let Some(r) = nd.rotation {
                j["rotation"] = arr(&r);
            }
            if let Some(s) = nd.scale {
                j["scale"] = arr(&s);
            }
            if let Some(m) = nd.matrix {
                j["matrix"] = arr(&m);
            }
            if nd.mesh {
                j["mesh"] = json!(0);
            }
            if nd.camera && d.camera.is_some() {
                j["camera"] = json!(0);
            }
            if let Some(l) = nd.light {
                j["extensions"] =
                    json!({"KHR_lights_punctual": {"light": l as usize % d.lights.len().max(1)}});
            }
            if !nd.children.is_empty() {
                j["children"] = Value::Array(nd.children.iter().take(4).map(|&c| json!(c % 9)).collect());
            }
            j
        })
        .collect();
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": buf.len(), "uri": format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&buf))}],
        "bufferViews": views,
        "accessors": accessors,
        "meshes": [{"primitives": [prim]}],
        "nodes": nodes,
        "scenes": [{"nodes": (0..d.nodes.len().min(8)).collect::<Vec<_>>()}],
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_unlit"],
    });
    if !materials.is_empty() {
        doc["materials"] = Value::Array(materials);
    }
    if let Some(c) = &d.camera {
        doc["cameras"] = json!([match c {
            Cam::Perspective { yfov, znear, zfar, aspect } => {
                let mut p = json!({"yfov": n(*yfov), "znear": n(*znear)});
                if let Some(f) = zfar {
                    p["zfar"] = n(*f);
                }
                if let Some(a) = aspect {
                    p["aspectRatio"] = n(*a);
                }
                json!({"type": "perspective", "perspective": p})
            }
            Cam::Orthographic { xmag, ymag, znear, zfar } => json!({"type": "orthographic",
                "orthographic": {"xmag": n(*xmag), "ymag": n(*ymag), "znear": n(*znear), "zfar": n(*zfar)}}),
        }]);
    }
    if !d.lights.is_empty() {
        let lights: Vec<Value> = d
            .lights
            .iter()
            .take(4)
            .map(|l| {
                let kind = ["point", "spot", "directional"][l.kind as usize % 3];
                let mut j = json!({"type": kind, "color": arr(&l.color), "intensity": n(l.intensity)});
                if let Some(r) = l.range {
                    j["range"] = n(r);
                }
                if kind == "spot" {
                    j["spot"] = json!({"innerConeAngle": n(l.inner), "outerConeAngle": n(l.outer)});
                }
                j
            })
            .collect();
        doc["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
    }
    if let Some(e) = &d.extras {
        let mut x = json!({});
        if let Some(w) = e.wavelengths {
            x["spectra"] = json!({"wavelengths": w});
        }
        if let Some(r) = e.range {
            x["spectra"]["range"] = json!([n64(r[0]), n64(r[1])]);
        }
        if let Some((t, depth, sun, scale, sky)) = e.water {
            let ty =
                ["I", "IA", "IB", "II", "III", "1C", "3C", "5C", "7C", "9C", "II.5", "XX"][t as usize % 12];
            x["water"] = json!({"type": ty, "depth": n64(depth), "sun_direction": arr(&sun), "scale": n64(scale), "sky": n64(sky)});
        }
        if let Some((a, s, g, scale)) = e.medium {
            x["medium"] =
                json!({"absorption": a.map(n64), "scattering": s.map(n64), "g": n64(g), "scale": n64(scale)});
        }
        doc["scenes"][0]["extras"] = x;
    }
    doc
}

libfuzzer_sys::fuzz_target!(|d: Doc| {
    let text = build(&d).to_string();
    fuzz::run_one("gltf", text.as_bytes());
});
