//! glTF features beyond the basics, each on a small document built here: vertex colours, a second
//! UV set, alpha modes, double-sidedness, samplers, KHR_texture_transform, EXT_mesh_gpu_instancing,
//! KHR_mesh_quantization, EXT_meshopt_compression, points and lines, orthographic cameras and
//! what happens to unsupported extensions — and, for each, the error a bad file gets.

use base64::Engine;
use glam::{Vec2, Vec3, Vec4};
use scene::{AlphaMode, Filter, Scene, TextureTransform, Wrap};
use serde_json::{Value, json};

const I8: u32 = 5120;
const U8: u32 = 5121;
const I16: u32 = 5122;
const U16: u32 = 5123;
const F32: u32 = 5126;

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes))
}

/// The binary part of a test document: buffer views and accessors in one buffer.
#[derive(Clone, Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

fn components(ty: &str) -> usize {
    match ty {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        _ => 4,
    }
}

impl Bin {
    fn view(&mut self, data: &[u8], stride: Option<usize>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()});
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(v);
        self.views.len() - 1
    }

    /// An accessor of `vals` stored as `ctype`; elements padded to 4 bytes as glTF asks of vertex
    /// attributes; min/max written (POSITION needs them).
    fn acc(&mut self, vals: &[f64], ctype: u32, ty: &str, normalized: bool) -> usize {
        let n = components(ty);
        let count = vals.len() / n;
        let csize = match ctype {
            I8 | U8 => 1,
            I16 | U16 => 2,
            _ => 4,
        };
        let elem = n * csize;
        let stride = if ty == "SCALAR" { elem } else { elem.div_ceil(4) * 4 };
        let mut data = Vec::new();
        for e in vals.chunks(n) {
            for &v in e {
                match ctype {
                    I8 => data.push(v as i8 as u8),
                    U8 => data.push(v as u8),
                    I16 => data.extend((v as i16).to_le_bytes()),
                    U16 => data.extend((v as u16).to_le_bytes()),
                    5125 => data.extend((v as u32).to_le_bytes()),
                    _ => data.extend((v as f32).to_le_bytes()),
                }
            }
            data.resize(data.len() + stride - elem, 0);
        }
        let view = self.view(&data, (stride != elem).then_some(stride));
        let mut a = json!({"bufferView": view, "componentType": ctype, "count": count, "type": ty});
        if normalized {
            a["normalized"] = json!(true);
        }
        let lo: Vec<f64> =
            (0..n).map(|c| vals.iter().skip(c).step_by(n).copied().fold(f64::MAX, f64::min)).collect();
        let hi: Vec<f64> =
            (0..n).map(|c| vals.iter().skip(c).step_by(n).copied().fold(f64::MIN, f64::max)).collect();
        a["min"] = json!(lo);
        a["max"] = json!(hi);
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn f32s(&mut self, vals: &[f64], ty: &str) -> usize {
        self.acc(vals, F32, ty, false)
    }

    /// A unit right triangle in the XY plane facing +Z.
    fn triangle(&mut self) -> usize {
        self.f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3")
    }

    /// `doc` completed with the buffer, views and accessors.
    fn finish(self, mut doc: Value) -> Value {
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{"byteLength": self.bytes.len(), "uri": data_uri("application/octet-stream", &self.bytes)}]);
        doc["bufferViews"] = json!(self.views);
        doc["accessors"] = json!(self.accessors);
        if doc.get("scenes").is_none() {
            let n = doc["nodes"].as_array().map_or(0, Vec::len);
            doc["scenes"] = json!([{"nodes": (0..n).collect::<Vec<_>>()}]);
        }
        doc
    }
}

/// A 2×2 RGBA PNG as a data URI.
fn png_uri() -> String {
    let img =
        image::RgbaImage::from_raw(2, 2, vec![255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 9, 9, 9, 9])
            .unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    data_uri("image/png", &out.into_inner())
}

fn load(doc: &Value) -> Result<Scene, String> {
    scene::load_slice("t.gltf", doc.to_string().as_bytes(), None).map_err(|e| e.to_string())
}

fn error(doc: &Value) -> String {
    match load(doc) {
        Ok(_) => panic!("loaded without error"),
        Err(e) => e,
    }
}

fn assert_has(e: &str, parts: &[&str]) {
    for p in parts {
        assert!(e.contains(p), "error lacks '{p}': {e}");
    }
}

/// One node, one mesh of the given primitives, and the given materials and textures.
fn single_mesh(b: Bin, primitives: Value, materials: Value) -> Value {
    let mut doc = json!({
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": primitives}],
        "materials": materials,
    });
    let textures = doc["materials"].to_string().contains("\"index\"");
    if textures {
        doc["images"] = json!([{"uri": png_uri()}]);
        doc["textures"] = json!([{"source": 0}]);
    }
    b.finish(doc)
}

#[test]
fn vertex_colours_and_the_second_uv_set() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let rgba8 =
        b.acc(&[255.0, 0.0, 0.0, 255.0, 0.0, 255.0, 0.0, 51.0, 0.0, 0.0, 255.0, 0.0], U8, "VEC4", true);
    let rgb_f = b.f32s(&[0.5, 0.25, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0], "VEC3");
    let rgba16 =
        b.acc(&[65535.0, 0.0, 0.0, 32768.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 65535.0], U16, "VEC4", true);
    let uv0 = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2");
    let uv1 = b.acc(&[0.0, 0.0, 65535.0, 0.0, 0.0, 65535.0], U16, "VEC2", true);
    let doc = single_mesh(
        b,
        json!([
            {"attributes": {"POSITION": pos, "COLOR_0": rgba8, "TEXCOORD_0": uv0, "TEXCOORD_1": uv1}, "material": 0},
            {"attributes": {"POSITION": pos, "COLOR_0": rgb_f}},
            {"attributes": {"POSITION": pos, "COLOR_0": rgba16}},
        ]),
        json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}},
                "emissiveTexture": {"index": 0}}]),
    );
    let s = load(&doc).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let m = &s.meshes[0];
    assert_eq!(
        m.colors,
        vec![Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, 0.2), Vec4::new(0.0, 0.0, 1.0, 0.0)]
    );
    assert_eq!(m.uvs1, vec![Vec2::ZERO, Vec2::X, Vec2::Y]);
    assert_eq!(m.uvs, vec![Vec2::ZERO, Vec2::X, Vec2::Y]);
    let mat = &s.materials[0];
    assert_eq!(mat.base_color_texture.unwrap().tex_coord, 1);
    assert_eq!(mat.emissive_texture.unwrap().tex_coord, 0);
    // VEC3 colours get alpha 1; 16-bit colours are normalized by 65535.
    assert_eq!(s.meshes[1].colors[0], Vec4::new(0.5, 0.25, 1.0, 1.0));
    let c = s.meshes[2].colors[0];
    assert!((c.w - 32768.0 / 65535.0).abs() < 1e-6 && c.x == 1.0, "{c}");
    // A mesh without COLOR_0 has none (white).
    assert!(scene::builtin("cornell").unwrap().meshes.iter().all(|m| m.colors.is_empty()));
}

#[test]
fn bad_uv_sets_and_colours_are_named() {
    let make = |tex: Value, with_uv1: bool, colour_normalized: bool| {
        let mut b = Bin::default();
        let pos = b.triangle();
        let uv = b.f32s(&[0.0; 6], "VEC2");
        let col = b.acc(&[255.0; 12], U8, "VEC4", colour_normalized);
        let mut attrs = json!({"POSITION": pos, "TEXCOORD_0": uv, "COLOR_0": col});
        if with_uv1 {
            attrs["TEXCOORD_1"] = json!(uv);
        }
        single_mesh(
            b,
            json!([{"attributes": attrs, "material": 0}]),
            json!([{"pbrMetallicRoughness": {"baseColorTexture": tex}}]),
        )
    };
    assert!(load(&make(json!({"index": 0, "texCoord": 1}), true, true)).is_ok());
    let e = error(&make(json!({"index": 0, "texCoord": 2}), true, true));
    assert!(
        e.ends_with("materials[0].pbrMetallicRoughness.baseColorTexture.texCoord: 2 is not supported (TEXCOORD_0 and TEXCOORD_1 are)"),
        "{e}"
    );
    let e = error(&make(
        json!({"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 3}}}),
        true,
        true,
    ));
    assert_has(&e, &["baseColorTexture.extensions.KHR_texture_transform.texCoord: 3 is not supported"]);
    let e = error(&make(json!({"index": 0, "texCoord": 1}), false, true));
    assert_has(
        &e,
        &[
            "meshes[0].primitives[0]",
            "materials[0].pbrMetallicRoughness.baseColorTexture reads TEXCOORD_1",
            "no TEXCOORD_1",
        ],
    );
    let e = error(&make(json!({"index": 0}), true, false));
    assert_has(&e, &["accessors[2].normalized", "COLOR_0", "UNSIGNED_BYTE", "must be normalized"]);
}

#[test]
fn alpha_modes_cutoffs_and_double_sidedness() {
    let make = |materials: Value| {
        let mut b = Bin::default();
        let pos = b.triangle();
        let n = materials.as_array().unwrap().len();
        let prims: Vec<Value> = (0..=n)
            .map(|i| {
                if i < n {
                    json!({"attributes": {"POSITION": pos}, "material": i})
                } else {
                    json!({"attributes": {"POSITION": pos}})
                }
            })
            .collect();
        single_mesh(b, json!(prims), materials)
    };
    let s = load(&make(json!([
        {},
        {"alphaMode": "MASK"},
        {"alphaMode": "MASK", "alphaCutoff": 0.25, "doubleSided": true},
        {"alphaMode": "BLEND", "doubleSided": false},
        {"alphaMode": "OPAQUE", "alphaCutoff": 0.9},
    ])))
    .unwrap();
    let modes: Vec<(AlphaMode, bool)> = s.materials.iter().map(|m| (m.alpha_mode, m.double_sided)).collect();
    assert_eq!(
        modes,
        vec![
            (AlphaMode::Opaque, false),
            (AlphaMode::Mask { cutoff: 0.5 }, false),
            (AlphaMode::Mask { cutoff: 0.25 }, true),
            (AlphaMode::Blend, false),
            (AlphaMode::Opaque, false),
            // glTF's default material (for the primitive without one) is single-sided too.
            (AlphaMode::Opaque, false),
        ]
    );
    assert_eq!(s.materials[5].name, "default");
    // Built-in scenes keep their double-sided surfaces.
    assert!(scene::builtin("cornell").unwrap().materials.iter().all(|m| m.double_sided));
    for bad in [json!(-0.5), json!(1e39), json!("half")] {
        let e = error(&make(json!([{"alphaMode": "MASK", "alphaCutoff": bad}])));
        assert_has(&e, &["materials[0].alphaCutoff", "finite number ≥ 0"]);
    }
}

#[test]
fn samplers_wrap_filter_and_textures_stay_shared() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0; 6], "VEC2");
    let mut doc = single_mesh(
        b,
        json!([{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": 0},
               {"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": 1}]),
        json!([
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1}}},
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "emissiveTexture": {"index": 2},
             "occlusionTexture": {"index": 1, "strength": 0.5}},
        ]),
    );
    doc["samplers"] = json!([
        {"wrapS": 33071, "wrapT": 33648, "magFilter": 9728, "minFilter": 9986},
        {"wrapS": 10497, "minFilter": 9729},
    ]);
    doc["textures"] = json!([{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1}, {"source": 0}]);
    let s = load(&doc).unwrap();
    // Texture 0 is shared by both materials; 1 by metallic-roughness and occlusion (both linear).
    assert_eq!(s.textures.len(), 3, "{:?}", s.textures.iter().map(|t| &t.name).collect::<Vec<_>>());
    let (m0, m1) = (&s.materials[0], &s.materials[1]);
    assert_eq!(m0.base_color_texture.unwrap().index, m1.base_color_texture.unwrap().index);
    assert_eq!(m0.metallic_roughness_texture.unwrap().index, m1.occlusion_texture.unwrap().index);
    assert_eq!(m1.occlusion_strength, 0.5);
    let t0 = s.textures[m0.base_color_texture.unwrap().index].sampler;
    assert_eq!(
        (t0.wrap_s, t0.wrap_t, t0.mag, t0.min, t0.mipmaps),
        (Wrap::ClampToEdge, Wrap::MirroredRepeat, Filter::Nearest, Filter::Nearest, true)
    );
    let t1 = s.textures[m0.metallic_roughness_texture.unwrap().index].sampler;
    assert_eq!(
        (t1.wrap_s, t1.wrap_t, t1.mag, t1.min, t1.mipmaps),
        (Wrap::Repeat, Wrap::Repeat, Filter::Linear, Filter::Linear, false)
    );
    // No sampler: glTF's defaults, repeat and linear with mipmaps.
    assert_eq!(s.textures[m1.emissive_texture.unwrap().index].sampler, scene::Sampler::default());
    assert!(scene::Sampler::default().mipmaps);

    let mut bad = doc.clone();
    bad["samplers"][0]["wrapS"] = json!(12345);
    assert_has(
        &error(&bad),
        &["t.gltf: samplers[0].wrapS: 12345 is not a valid value", "33071 CLAMP_TO_EDGE"],
    );
    let mut bad = doc.clone();
    bad["samplers"][1]["minFilter"] = json!(9728.5);
    assert_has(&error(&bad), &["samplers[1].minFilter"]);
}

#[test]
fn texture_transform_on_every_texture_info() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0; 6], "VEC2");
    let tt = |x: Value| json!({"index": 0, "extensions": {"KHR_texture_transform": x}});
    let doc = single_mesh(
        b,
        json!([{"attributes": {"POSITION": pos, "TEXCOORD_0": uv, "TEXCOORD_1": uv, "NORMAL": pos}, "material": 0}]),
        json!([{
            "pbrMetallicRoughness": {
                "baseColorTexture": tt(json!({"offset": [0.5, 0.25], "rotation": 1.5707964, "scale": [2, 3]})),
                "metallicRoughnessTexture": tt(json!({"scale": [4, 4], "texCoord": 1})),
            },
            "normalTexture": tt(json!({"offset": [1, 0]})),
            "occlusionTexture": tt(json!({"rotation": 0.5})),
            "emissiveTexture": tt(json!({})),
        }]),
    );
    let s = load(&doc).unwrap();
    let m = &s.materials[0];
    let base = m.base_color_texture.unwrap();
    let t = base.transform.unwrap();
    assert_eq!(
        t,
        TextureTransform { offset: Vec2::new(0.5, 0.25), rotation: 1.5707964, scale: Vec2::new(2.0, 3.0) }
    );
    // The extension's own example: scale, then rotate, then offset.
    assert!(t.apply(Vec2::new(1.0, 0.0)).abs_diff_eq(Vec2::new(0.5, -1.75), 1e-5), "{}", t.apply(Vec2::X));
    let mr = m.metallic_roughness_texture.unwrap();
    assert_eq!((mr.tex_coord, mr.transform.unwrap().scale), (1, Vec2::splat(4.0)));
    assert_eq!(m.normal_texture.unwrap().transform.unwrap().offset, Vec2::X);
    assert_eq!(m.occlusion_texture.unwrap().transform.unwrap().rotation, 0.5);
    assert_eq!(m.emissive_texture.unwrap().transform, None, "the identity is no transform");
    // Same texture, different transforms: still one decoded texture.
    assert_eq!(s.textures.iter().filter(|t| t.srgb).count(), 1);
}

#[test]
fn gpu_instancing_expands_instances_under_the_node_transform() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let t = b.f32s(&[0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 10.0, 0.0], "VEC3");
    // Instance 1 turned 90° about +Z (short-normalized quaternion), instance 2 scaled by 2.
    let h = 0.70710677 * 32767.0;
    let r = b.acc(&[0.0, 0.0, 0.0, 32767.0, 0.0, 0.0, h, h, 0.0, 0.0, 0.0, 32767.0], I16, "VEC4", true);
    let s = b.f32s(&[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0], "VEC3");
    let doc = b.finish(json!({
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "extensionsRequired": ["EXT_mesh_gpu_instancing"],
        "nodes": [{"mesh": 0, "translation": [0, 0, -5],
                   "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t, "ROTATION": r, "SCALE": s}}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
    }));
    let sc = load(&doc).unwrap();
    assert_eq!(sc.meshes.len(), 3);
    let close = |a: Vec3, b: Vec3| a.abs_diff_eq(b, 1e-3);
    assert!(close(sc.meshes[0].positions[1], Vec3::new(1.0, 0.0, -5.0)), "{:?}", sc.meshes[0].positions);
    assert!(close(sc.meshes[1].positions[1], Vec3::new(10.0, 1.0, -5.0)), "{:?}", sc.meshes[1].positions);
    assert!(close(sc.meshes[2].positions[2], Vec3::new(0.0, 12.0, -5.0)), "{:?}", sc.meshes[2].positions);
    assert!(sc.meshes.iter().all(|m| m.normals.iter().all(|n| close(*n, Vec3::Z))));

    let mut bad = doc.clone();
    bad["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = json!(99);
    assert_has(&error(&bad), &["nodes[0].extensions.EXT_mesh_gpu_instancing.attributes.SCALE", "99"]);
    let mut bad = doc.clone();
    bad["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = json!(r);
    assert_has(&error(&bad), &["SCALE (accessors[2])", "VEC4"]);
}

#[test]
fn instancing_cannot_blow_up_the_triangle_count() {
    // 1000 triangles × 20001 instances: a few hundred kilobytes asking for 20 M triangles.
    let mut b = Bin::default();
    let tris: Vec<f64> =
        (0..1000).flat_map(|i| [i as f64, 0.0, 0.0, i as f64 + 1.0, 0.0, 0.0, i as f64, 1.0, 0.0]).collect();
    let pos = b.f32s(&tris, "VEC3");
    let t = b.f32s(&vec![0.0; 3 * 20_001], "VEC3");
    let doc = b.finish(json!({
        "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": t}}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
    }));
    let e = error(&doc);
    assert_has(
        &e,
        &[
            "t.gltf: nodes[0]",
            "meshes[0].primitives[0] drawn 20001 time(s)",
            "20001000 triangles",
            "20000000",
        ],
    );
}

#[test]
fn quantized_attributes_are_dequantized() {
    let mut b = Bin::default();
    // Positions as plain shorts, scaled back by the node (the usual quantizer output).
    let pos = b.acc(&[0.0, 0.0, 0.0, 1000.0, 0.0, 0.0, 0.0, -1000.0, 0.0], I16, "VEC3", false);
    let nrm = b.acc(&[0.0, 0.0, 127.0, 0.0, 0.0, -128.0, 127.0, 0.0, 0.0], I8, "VEC3", true);
    let uv = b.acc(&[0.0, 255.0, 255.0, 0.0, 128.0, 128.0], U8, "VEC2", true);
    let uv_int = b.acc(&[0.0, 2.0, 4.0, 0.0, 1.0, 1.0], U8, "VEC2", false);
    let tan = b.acc(
        &[32767.0, 0.0, 0.0, 32767.0, 32767.0, 0.0, 0.0, -32767.0, 0.0, 32767.0, 0.0, 32767.0],
        I16,
        "VEC4",
        true,
    );
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_mesh_quantization"],
        "extensionsRequired": ["KHR_mesh_quantization"],
        "nodes": [{"mesh": 0, "scale": [0.001, 0.001, 0.001]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv, "TEXCOORD_1": uv_int, "TANGENT": tan}, "material": 0}]}],
        "materials": [{"normalTexture": {"index": 0}}],
        "images": [{"uri": png_uri()}],
        "textures": [{"source": 0}],
    }));
    let s = load(&doc).unwrap();
    let m = &s.meshes[0];
    assert!(
        m.positions[1].abs_diff_eq(Vec3::X, 1e-6) && m.positions[2].abs_diff_eq(-Vec3::Y, 1e-6),
        "{:?}",
        m.positions
    );
    assert_eq!(m.normals, vec![Vec3::Z, -Vec3::Z, Vec3::X]);
    assert!(
        m.uvs[0].abs_diff_eq(Vec2::new(0.0, 1.0), 1e-6)
            && m.uvs[2].abs_diff_eq(Vec2::splat(128.0 / 255.0), 1e-6)
    );
    assert_eq!(m.uvs1[1], Vec2::new(4.0, 0.0));
    assert_eq!(m.tangents[0], Vec4::new(1.0, 0.0, 0.0, 1.0));
    assert_eq!(m.tangents[1].w, -1.0);

    let mut bad = doc.clone();
    bad["accessors"][nrm].as_object_mut().unwrap().remove("normalized");
    assert_has(&error(&bad), &["t.gltf: accessors[1].normalized", "NORMAL", "BYTE", "must be normalized"]);
    let mut bad = doc.clone();
    bad["accessors"][pos]["componentType"] = json!(5125);
    assert_has(&error(&bad), &["POSITION (accessors[0])", "UNSIGNED_INT"]);
}

#[test]
fn meshopt_compressed_views_are_decoded() {
    // Source data: a quad with float positions and u16 indices.
    let positions: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let idx = [0u32, 1, 2, 0, 2, 3];
    let vbytes: Vec<[u8; 12]> = positions
        .iter()
        .map(|p| p.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>().try_into().unwrap())
        .collect();
    let venc = meshopt::encode_vertex_buffer(&vbytes).unwrap();
    let ienc = meshopt::encode_index_buffer(&idx, 4).unwrap();
    let mut compressed = venc.clone();
    while !compressed.len().is_multiple_of(4) {
        compressed.push(0);
    }
    let ioff = compressed.len();
    compressed.extend(&ienc);
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_meshopt_compression"],
        "extensionsRequired": ["EXT_meshopt_compression"],
        "buffers": [
            {"byteLength": compressed.len(), "uri": data_uri("application/octet-stream", &compressed)},
            {"byteLength": 48 + 12, "extensions": {"EXT_meshopt_compression": {"fallback": true}}},
        ],
        "bufferViews": [
            {"buffer": 1, "byteOffset": 0, "byteLength": 48, "byteStride": 12,
             "extensions": {"EXT_meshopt_compression": {"buffer": 0, "byteLength": venc.len(), "byteStride": 12, "count": 4, "mode": "ATTRIBUTES"}}},
            {"buffer": 1, "byteOffset": 48, "byteLength": 12,
             "extensions": {"EXT_meshopt_compression": {"buffer": 0, "byteOffset": ioff, "byteLength": ienc.len(), "byteStride": 2, "count": 6, "mode": "TRIANGLES"}}},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": F32, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": U16, "count": 6, "type": "SCALAR"},
        ],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "scenes": [{"nodes": [0]}],
    });
    let s = load(&doc).unwrap();
    let m = &s.meshes[0];
    // Flat normals un-index the quad: corners in index order.
    let want: Vec<Vec3> = idx.iter().map(|&i| Vec3::from(positions[i as usize])).collect();
    assert_eq!(m.positions, want);

    let mut bad = doc.clone();
    bad["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteStride"] = json!(6);
    assert_has(&error(&bad), &["bufferViews[0].extensions.EXT_meshopt_compression", "byteStride"]);
    let mut bad = doc.clone();
    bad["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["mode"] = json!("SOUP");
    assert_has(&error(&bad), &["EXT_meshopt_compression.mode", "SOUP"]);
    let mut bad = doc.clone();
    bad["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteLength"] = json!(3);
    assert_has(&error(&bad), &["bufferViews[1].extensions.EXT_meshopt_compression", "cannot be decoded"]);
    let mut bad = doc.clone();
    bad["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = json!(5);
    assert_has(&error(&bad), &["count 5 × byteStride 12 exceeds the view's byteLength 48"]);
    let mut bad = doc.clone();
    bad["buffers"][1]["byteLength"] = json!(1u64 << 40);
    assert_has(&error(&bad), &["buffers[1].byteLength"]);
}

/// `KHR_meshopt_compression`: the Khronos extension reads as EXT_meshopt_compression does, and
/// adds version 1 of the attribute codec and the COLOR filter (YCoCg), here on a COLOR_0 of
/// normalized bytes; COLOR under the EXT name, or both names on one view, are errors.
#[test]
fn khr_meshopt_compression_adds_the_color_filter_and_codec_version_1() {
    let positions: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let colors: [[f32; 4]; 3] = [[1.0, 0.0, 0.0, 1.0], [0.2, 0.6, 0.9, 0.5], [0.05, 0.95, 0.3, 0.0]];
    let vbytes: Vec<[u8; 12]> = positions
        .iter()
        .map(|p| p.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>().try_into().unwrap())
        .collect();
    let venc = meshopt::encode_vertex_buffer_level(&vbytes, 2, Some(1)).unwrap();
    assert_eq!(meshopt::decode_vertex_version(&venc), Some(1));
    let cfilt: Vec<[u8; 4]> = meshopt::encode_filter_color(&colors, 8);
    let cenc = meshopt::encode_vertex_buffer_level(&cfilt, 2, Some(1)).unwrap();
    let mut compressed = venc.clone();
    compressed.resize(compressed.len().div_ceil(4) * 4, 0);
    let coff = compressed.len();
    compressed.extend(&cenc);
    let ext = "KHR_meshopt_compression";
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": [ext],
        "extensionsRequired": [ext],
        "buffers": [
            {"byteLength": compressed.len(), "uri": data_uri("application/octet-stream", &compressed)},
            {"byteLength": 36 + 12, "extensions": {ext: {"fallback": true}}},
        ],
        "bufferViews": [
            {"buffer": 1, "byteOffset": 0, "byteLength": 36, "byteStride": 12,
             "extensions": {ext: {"buffer": 0, "byteLength": venc.len(), "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"}}},
            {"buffer": 1, "byteOffset": 36, "byteLength": 12, "byteStride": 4,
             "extensions": {ext: {"buffer": 0, "byteOffset": coff, "byteLength": cenc.len(), "byteStride": 4, "count": 3, "mode": "ATTRIBUTES", "filter": "COLOR"}}},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": F32, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": U8, "normalized": true, "count": 3, "type": "VEC4"},
        ],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}}]}],
        "scenes": [{"nodes": [0]}],
    });
    let s = load(&doc).unwrap();
    let m = &s.meshes[0];
    assert_eq!(m.positions, positions.map(Vec3::from));
    for (got, want) in m.colors.iter().zip(colors) {
        // 8-bit YCoCg: within two steps of a byte per channel.
        assert!((*got - Vec4::from(want)).abs().max_element() <= 2.0 / 255.0, "{got} vs {want:?}");
    }
    // Without the filter the bytes are YCoCg, not the colours: the check above can fail.
    let mut raw = doc.clone();
    raw["bufferViews"][1]["extensions"][ext].as_object_mut().unwrap().remove("filter");
    let unfiltered = load(&raw).unwrap();
    assert!((unfiltered.meshes[0].colors[1] - Vec4::from(colors[1])).abs().max_element() > 0.05);

    let mut bad = doc.clone();
    let text = bad.to_string().replace(ext, "EXT_meshopt_compression");
    bad = serde_json::from_str(&text).unwrap();
    assert_has(
        &error(&bad),
        &["bufferViews[1].extensions.EXT_meshopt_compression.filter", "COLOR", "KHR_meshopt_compression"],
    );
    let mut bad = doc.clone();
    let both = bad["bufferViews"][0]["extensions"][ext].clone();
    bad["bufferViews"][0]["extensions"]["EXT_meshopt_compression"] = both;
    assert_has(&error(&bad), &["bufferViews[0].extensions", "both"]);
}

#[test]
fn unsupported_extensions_refuse_or_warn_with_what_to_do() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let base = b.finish(
        json!({"nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}]}),
    );

    // Draco (tests/draco.rs decodes the real thing): a view that holds no Draco bitstream is an
    // error naming the extension and the view, before validation can complain about the data
    // the accessor lacks.
    let mut d = base.clone();
    d["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    d["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    d["accessors"][0].as_object_mut().unwrap().remove("bufferView");
    d["meshes"][0]["primitives"][0]["extensions"] =
        json!({"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}});
    let e = error(&d);
    assert_has(
        &e,
        &[
            "meshes[0].primitives[0].extensions.KHR_draco_mesh_compression",
            "bufferViews[0]",
            "cannot be decoded",
        ],
    );
    assert!(!e.contains("Missing data"), "{e}");
    // Draco used with the uncompressed data kept: read from it, exact, without a warning.
    let mut d = base.clone();
    d["extensionsUsed"] =
        json!(["KHR_draco_mesh_compression", "KHR_materials_volume_scatter", "KHR_interactivity"]);
    d["meshes"][0]["primitives"][0]["extensions"] =
        json!({"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}});
    let s = load(&d).unwrap();
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
    assert!(
        s.warnings[0].starts_with("KHR_materials_volume_scatter is not supported: ")
            && s.warnings[0].contains("scattering is ignored")
    );
    // A KTX2 file given as an ordinary image (no extension at all) goes to the KTX2 decoder
    // (tests/ktx2.rs), which names what is wrong with this one.
    let mut d = base.clone();
    let ktx2 = b"\xabKTX 20\xbb\r\n\x1a\n and then some";
    d["images"] = json!([{"uri": data_uri("image/ktx2", ktx2)}]);
    d["textures"] = json!([{"source": 0}]);
    d["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    d["meshes"][0]["primitives"][0]["material"] = json!(0);
    assert_has(&error(&d), &["images[0]: the KTX2 file ends inside its header"]);
    // A required material extension: refused, naming it.
    let mut d = base.clone();
    d["extensionsRequired"] = json!(["KHR_texture_transform", "KHR_materials_volume_scatter"]);
    assert_has(&error(&d), &["extensionsRequired[1]", "KHR_materials_volume_scatter"]);
    // Found by a sweep: an extension used but missing from extensionsUsed was ignored without
    // a warning. Extras are not extensions.
    let mut d = base.clone();
    d["materials"] =
        json!([{"extensions": {"KHR_materials_volume_scatter": {"multiscatterColor": [0.5, 0.5, 0.5]}}}]);
    d["asset"]["extras"] = json!({"extensions": {"KHR_materials_anisotropy": {}}});
    d["meshes"][0]["primitives"][0]["material"] = json!(0);
    let s = load(&d).unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings[0].starts_with("KHR_materials_volume_scatter is not supported"), "{:?}", s.warnings);
}

#[test]
fn points_and_lines_are_skipped_with_a_warning() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let line = b.acc(&[0.0, 1.0, 1.0, 2.0], U8, "SCALAR", false);
    let doc = b.finish(json!({
        "nodes": [{"mesh": 0}, {"mesh": 0}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": pos}, "mode": 0},
            {"attributes": {"POSITION": pos}, "indices": line, "mode": 1},
            {"attributes": {"POSITION": pos}, "mode": 5},
            {"attributes": {"POSITION": pos}, "mode": 3},
        ]}],
    }));
    let s = load(&doc).unwrap();
    // The strip primitive of each of the two nodes.
    assert_eq!(s.meshes.len(), 2);
    assert_eq!(s.meshes[0].indices.len(), 3);
    // One warning per primitive, not per node that draws it.
    assert_eq!(s.warnings.len(), 3, "{:?}", s.warnings);
    assert!(s.warnings[1].starts_with("meshes[0].primitives[1]: mode Lines"), "{:?}", s.warnings);
    // A mesh of lines only: its node draws nothing, and cannot be a stand-in's mesh.
    let mut d = doc.clone();
    d["meshes"][0]["primitives"] = json!([{"attributes": {"POSITION": pos}, "mode": 1}]);
    let s = load(&d).unwrap();
    assert!(s.meshes.is_empty() && s.warnings.len() == 2, "{:?}", s.warnings);
    assert!(s.warnings[1].starts_with("the scene has no triangles to draw"), "{:?}", s.warnings);
}

/// Found by a sweep: `KHR_materials_transmission` given as an array was ignored (the glass
/// drawn opaque, exit 0). A material extension that is not an object is refused by its field.
#[test]
fn a_material_extension_that_is_not_an_object_is_refused() {
    let mut b = Bin::default();
    let pos = b.triangle();
    for (ext, value) in [("KHR_materials_transmission", json!([1.0])), ("KHR_materials_ior", json!(1.5))] {
        let doc = b.clone().finish(json!({
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "material": 0}]}],
            "materials": [{"extensions": {ext: value}}],
        }));
        assert_has(&error(&doc), &[&format!("materials[0].extensions.{ext}"), "must be an object"]);
    }
}

/// A triangle primitive of fewer indices than a triangle (TRIANGLES with 1–2, a strip or fan
/// with 2) is skipped with a warning: the real-time renderer panicked uploading its empty mesh,
/// and the path tracer drew the scene black without a word.
#[test]
fn primitives_of_no_triangle_are_skipped_with_a_warning() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let two = b.acc(&[0.0, 1.0], U8, "SCALAR", false);
    let doc = b.finish(json!({
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": pos}, "indices": two, "mode": 4},
            {"attributes": {"POSITION": pos}, "indices": two, "mode": 5},
            {"attributes": {"POSITION": pos}, "indices": two, "mode": 6},
        ]}],
    }));
    let s = load(&doc).unwrap();
    assert!(s.meshes.is_empty(), "{} meshes", s.meshes.len());
    assert_eq!(s.warnings.len(), 4, "{:?}", s.warnings);
    for (i, mode) in ["Triangles", "TriangleStrip", "TriangleFan"].iter().enumerate() {
        assert!(
            s.warnings[i].starts_with(&format!(
                "meshes[0].primitives[{i}]: mode {mode} with 2 index(es) makes no triangle"
            )),
            "{:?}",
            s.warnings
        );
    }
    // Beside a real triangle, only the short primitive goes.
    let mut d = doc.clone();
    d["meshes"][0]["primitives"] = json!([
        {"attributes": {"POSITION": pos}, "indices": two, "mode": 4},
        {"attributes": {"POSITION": pos}, "mode": 4},
    ]);
    let s = load(&d).unwrap();
    assert_eq!((s.meshes.len(), s.warnings.len()), (1, 1), "{:?}", s.warnings);
}

#[test]
fn orthographic_cameras_are_read() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let doc = b.finish(json!({
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 1.5, "znear": 0, "zfar": 10}}],
    }));
    let s = load(&doc).unwrap();
    let c = s.camera;
    assert_eq!((c.ortho, c.znear, c.zfar), (Some((2.0, 1.5)), 0.0, 10.0));
    assert!(c.position().abs_diff_eq(Vec3::new(0.0, 0.0, 3.0), 1e-6));
    assert!(s.warnings.is_empty());
    for (o, field) in [
        (json!({"xmag": 0, "ymag": 1, "znear": 0, "zfar": 1}), "xmag"),
        (json!({"xmag": 1, "ymag": 1, "znear": 2, "zfar": 1}), "zfar"),
        // Issue 29: a tiny magnification rendered NaN, a huge aspect black in real time only.
        (json!({"xmag": 1e-30, "ymag": 1, "znear": 0, "zfar": 1}), "xmag"),
        (json!({"xmag": 1e30, "ymag": 1e-30, "znear": 0, "zfar": 1}), "between"),
    ] {
        let mut d = doc.clone();
        d["cameras"][0]["orthographic"] = o;
        assert_has(&error(&d), &["cameras[0].orthographic", field]);
    }
}

/// A near plane far smaller than the far plane is more than a depth buffer resolves (issue 29:
/// znear 1e-6 rendered wrong in real time, 1e-8 black). The far plane is drawn at the scene's
/// farthest point then (nothing lies beyond it), and only where that is still too far for the
/// near plane do both renderers clip at zfar × 1e-6, with a warning naming the camera; at the
/// ratio the built-ins use nothing changes. A far plane beyond anything a scene can hold (1e20
/// made every real-time pixel one grey: its squared distance left f32) is drawn at 1e10; a near
/// plane there is refused.
#[test]
fn tiny_near_planes_are_raised_for_both_renderers_with_a_warning() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let cam = |znear: f64, zfar: f64, yfov: f64| json!([{"type": "perspective", "perspective": {"yfov": yfov, "znear": znear, "zfar": zfar}}]);
    let mut doc = b.finish(json!({
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "cameras": cam(1e-8, 1000.0, 0.8),
    }));
    // The farthest corner of the triangle's bounds, (1, 1, 0), from the camera at z = 3.
    let reach = 11f32.sqrt();
    let s = load(&doc).unwrap();
    assert_eq!(s.camera.znear, 1e-8);
    assert!((s.camera.zfar - 1.01 * reach).abs() < 1e-5, "{} vs {reach}", s.camera.zfar);
    assert!((s.camera.clip_near() - 1.01e-6 * reach).abs() < 1e-9, "{}", s.camera.clip_near());
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert!(s.warnings[0].contains("cameras[0]") && s.warnings[0].contains("znear"), "{:?}", s.warnings);
    // Fitting the far plane is enough: no near plane moves, no warning.
    for (znear, zfar) in [(1e-4, 1e9), (0.01, 1e20), (0.01, 1e38)] {
        doc["cameras"] = cam(znear, zfar, 0.8);
        let s = load(&doc).unwrap();
        assert!(s.warnings.is_empty(), "{znear} {zfar}: {:?}", s.warnings);
        assert_eq!(s.camera.clip_near(), znear as f32);
        let want = (znear / 1e-6).max(1.01 * f64::from(reach));
        assert!((f64::from(s.camera.zfar) / want - 1.0).abs() < 1e-6, "{znear} {zfar}: {}", s.camera.zfar);
    }
    // Unchanged at a ratio a depth buffer resolves.
    doc["cameras"] = cam(0.01, 1000.0, 0.8);
    let s = load(&doc).unwrap();
    assert!(s.warnings.is_empty() && s.camera.clip_near() == 0.01 && s.camera.zfar == 1000.0);
    doc["cameras"] = cam(1e30, 1e38, 0.8);
    assert_has(&error(&doc), &["cameras[0]", "znear 1e30", "clips everything"]);
    doc["cameras"] = cam(0.01, 1000.0, 1e-30);
    assert_has(&error(&doc), &["cameras[0]", "yfov"]);
}

#[test]
fn unlit_materials_load_as_unlit_without_emission_and_round_trip() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_unlit"],
        "extensionsRequired": ["KHR_materials_unlit"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "material": 0}, {"attributes": {"POSITION": pos}, "material": 1}]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1.0, 1.0]}, "emissiveFactor": [1.0, 1.0, 1.0],
             "extensions": {"KHR_materials_unlit": {}}},
            {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1.0, 1.0]}}
        ],
    }));
    let s = load(&doc).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let (u, lit) = (&s.materials[0], &s.materials[1]);
    assert!(u.unlit && !lit.unlit);
    assert_eq!(u.base_color, Vec4::new(0.5, 0.25, 1.0, 1.0));
    // Its emission would make it a light source: dropped, as the extension's shading ignores it.
    assert_eq!(u.emissive, Vec3::ZERO);
    let back =
        scene::load_slice("t.gltf", scene::export::to_gltf_json(&s).unwrap().to_string().as_bytes(), None)
            .unwrap();
    assert!(back.materials[0].unlit && !back.materials[1].unlit);
}

#[test]
fn specular_glossiness_materials_are_converted_to_metallic_roughness() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let sg = |x: Value| json!({"extensions": {"KHR_materials_pbrSpecularGlossiness": x}});
    let prim = |m: usize| json!({"attributes": {"POSITION": pos}, "material": m});
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_pbrSpecularGlossiness"],
        "extensionsRequired": ["KHR_materials_pbrSpecularGlossiness"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1), prim(2)]}],
        "materials": [
            // Copper: black diffuse, coloured specular, glossy.
            sg(json!({"diffuseFactor": [0.0, 0.0, 0.0, 1.0], "specularFactor": [0.95, 0.64, 0.54], "glossinessFactor": 0.8})),
            // A dielectric: diffuse colour, 0.04 grey specular.
            sg(json!({"diffuseFactor": [0.5, 0.2, 0.1, 0.7], "specularFactor": [0.04, 0.04, 0.04], "glossinessFactor": 0.25})),
            // Textured: both textures on the same UVs.
            sg(json!({"diffuseTexture": {"index": 0}, "specularGlossinessTexture": {"index": 0},
                      "specularFactor": [0.04, 0.04, 0.04]})),
        ],
    }));
    doc["images"] = json!([{"uri": png_uri()}]);
    doc["textures"] = json!([{"source": 0}]);
    let s = load(&doc).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let (cu, die, tex) = (&s.materials[0], &s.materials[1], &s.materials[2]);
    assert!((cu.metallic - 1.0).abs() < 1e-4 && (cu.roughness - 0.2).abs() < 1e-6, "{cu:?}");
    assert!(cu.base_color.abs_diff_eq(Vec4::new(0.95, 0.64, 0.54, 1.0), 1e-4), "{cu:?}");
    assert!(die.metallic.abs() < 1e-6 && (die.roughness - 0.75).abs() < 1e-6, "{die:?}");
    assert!(die.base_color.abs_diff_eq(Vec4::new(0.5, 0.2, 0.1, 0.7), 1e-4), "{die:?}");
    // The textured one gets two new textures (base colour sRGB, metallic-roughness linear) at
    // the source's size, with the factors folded into them.
    let (b, mr) = (tex.base_color_texture.unwrap(), tex.metallic_roughness_texture.unwrap());
    let (bt, mt) = (&s.textures[b.index], &s.textures[mr.index]);
    assert!(bt.srgb && !mt.srgb && (bt.width, bt.height, mt.width, mt.height) == (2, 2, 2, 2));
    assert_eq!((tex.base_color, tex.metallic, tex.roughness), (Vec4::ONE, 1.0, 1.0));
    // Texel 0 of png_uri is opaque red: base red, alpha 255, glossiness 1 → roughness 0.
    assert_eq!(&bt.rgba8[0..4], &[255, 0, 0, 255]);
    assert_eq!((mt.rgba8[1], mt.rgba8[2]), (0, 0));
    // Texel 1 is green with alpha 128: glossiness 128/255 → roughness 127/255.
    assert_eq!(mt.rgba8[5], 127);

    // Out-of-range factors are named.
    let mut bad = doc.clone();
    bad["materials"][0]["extensions"]["KHR_materials_pbrSpecularGlossiness"]["glossinessFactor"] = json!(1.5);
    assert_has(
        &error(&bad),
        &["materials[0].extensions.KHR_materials_pbrSpecularGlossiness.glossinessFactor", "[0, 1]"],
    );
    let mut bad = doc.clone();
    bad["materials"][2]["extensions"]["KHR_materials_pbrSpecularGlossiness"]["diffuseTexture"]["index"] =
        json!(7);
    assert_has(&error(&bad), &["diffuseTexture.index", "no texture"]);
}

#[test]
fn iridescence_is_read_with_its_defaults_and_bad_values_are_named() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let ir = |x: Value| json!({"extensions": {"KHR_materials_iridescence": x}});
    let prim = |m: usize| json!({"attributes": {"POSITION": pos}, "material": m});
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_iridescence"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1), prim(2)]}],
        "materials": [
            ir(json!({"iridescenceFactor": 1.0})),
            ir(json!({"iridescenceFactor": 0.5, "iridescenceIor": 1.8, "iridescenceThicknessMinimum": 200,
                      "iridescenceThicknessMaximum": 800, "iridescenceTexture": {"index": 0},
                      "iridescenceThicknessTexture": {"index": 0}})),
            // The extension's default factor is 0: no film.
            ir(json!({"iridescenceIor": 1.5})),
        ],
    }));
    doc["images"] = json!([{"uri": png_uri()}]);
    doc["textures"] = json!([{"source": 0}]);
    let s = load(&doc).unwrap();
    // Both renderers draw films: no warning, and a file may require the extension.
    let said = s.warnings.join("\n");
    assert!(!said.contains("KHR_materials_iridescence"), "{said}");
    let mut required = doc.clone();
    required["extensionsRequired"] = json!(["KHR_materials_iridescence"]);
    assert!(load(&required).unwrap().materials[0].iridescence.is_some());
    let d = s.materials[0].iridescence.as_ref().expect("a film");
    assert_eq!((d.factor, d.ior, d.thickness_min, d.thickness_max), (1.0, 1.3, 100.0, 400.0));
    assert!(d.texture.is_none() && d.thickness_texture.is_none());
    // Without a thickness texture the film is the maximum thick.
    assert_eq!(d.thickness(Some(0.0)), 400.0);
    let t = s.materials[1].iridescence.as_ref().unwrap();
    assert_eq!((t.factor, t.ior, t.thickness_min, t.thickness_max), (0.5, 1.8, 200.0, 800.0));
    let tex = &s.textures[t.thickness_texture.unwrap().index];
    assert!(!tex.srgb, "film textures are data");
    assert_eq!(t.thickness(Some(0.25)), 350.0);
    assert!(s.materials[2].iridescence.is_none());

    let bad = |key: &str, v: Value, parts: &[&str]| {
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_iridescence"][key] = v;
        assert_has(&error(&d), parts);
    };
    let at = "materials[1].extensions.KHR_materials_iridescence";
    bad(
        "iridescenceThicknessMinimum",
        json!(900),
        &[&format!("{at}.iridescenceThicknessMinimum"), "minimum ≤ maximum"],
    );
    bad(
        "iridescenceThicknessMaximum",
        json!(-5),
        &[&format!("{at}.iridescenceThicknessMaximum"), "thickness in nm"],
    );
    bad("iridescenceIor", json!(0.9), &[&format!("{at}.iridescenceIor"), "[1, 10]"]);
    bad("iridescenceIor", json!("1.3"), &[&format!("{at}.iridescenceIor"), "index of refraction"]);
    bad("iridescenceFactor", json!(1.5), &[&format!("{at}.iridescenceFactor"), "[0, 1]"]);
    bad("iridescenceThicknessMaximum", json!(1e9), &[&format!("{at}.iridescenceThicknessMaximum"), "100000"]);
    bad(
        "iridescenceTexture",
        json!({"index": 7}),
        &[&format!("{at}.iridescenceTexture.index"), "no texture"],
    );
}

#[test]
fn clearcoat_is_read_with_its_defaults_and_bad_values_are_named() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2");
    let cc = |x: Value| json!({"extensions": {"KHR_materials_clearcoat": x}});
    let prim = |m: usize| json!({"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": m});
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_clearcoat"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1), prim(2)]}],
        "materials": [
            cc(json!({"clearcoatFactor": 1.0})),
            cc(json!({"clearcoatFactor": 0.5, "clearcoatRoughnessFactor": 0.25,
                      "clearcoatTexture": {"index": 0}, "clearcoatRoughnessTexture": {"index": 0},
                      "clearcoatNormalTexture": {"index": 0, "scale": 0.5}})),
            // The extension's default factor is 0: no coat.
            cc(json!({"clearcoatRoughnessFactor": 0.5})),
        ],
    }));
    doc["images"] = json!([{"uri": png_uri()}]);
    doc["textures"] = json!([{"source": 0}]);
    let s = load(&doc).unwrap();
    // Both renderers draw the coat: no warning, and a file may require the extension.
    let said = s.warnings.join("\n");
    assert!(!said.contains("KHR_materials_clearcoat"), "{said}");
    let mut required = doc.clone();
    required["extensionsRequired"] = json!(["KHR_materials_clearcoat"]);
    assert!(load(&required).unwrap().materials[0].clearcoat.is_some());
    let c = s.materials[0].clearcoat.as_ref().expect("a coat");
    assert_eq!((c.factor, c.roughness, c.normal_scale), (1.0, 0.0, 1.0));
    assert!(c.texture.is_none() && c.roughness_texture.is_none() && c.normal_texture.is_none());
    let t = s.materials[1].clearcoat.as_ref().unwrap();
    assert_eq!((t.factor, t.roughness, t.normal_scale), (0.5, 0.25, 0.5));
    assert!(!s.textures[t.texture.unwrap().index].srgb, "coat textures are data");
    assert_eq!((t.weight_at(Some(0.5)), t.roughness_at(Some(0.5))), (0.25, 0.125));
    assert!(s.materials[2].clearcoat.is_none());
    // The coat's normal map alone makes the mesh's tangents.
    for m in &s.meshes {
        assert_eq!(m.tangents.is_empty(), m.material != 1, "tangents for the coat's normal map alone");
    }

    let bad = |key: &str, v: Value, parts: &[&str]| {
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_clearcoat"][key] = v;
        assert_has(&error(&d), parts);
    };
    let at = "materials[1].extensions.KHR_materials_clearcoat";
    bad("clearcoatFactor", json!(1.5), &[&format!("{at}.clearcoatFactor"), "[0, 1]"]);
    bad("clearcoatFactor", json!("1"), &[&format!("{at}.clearcoatFactor"), "[0, 1]"]);
    bad("clearcoatRoughnessFactor", json!(-0.1), &[&format!("{at}.clearcoatRoughnessFactor"), "[0, 1]"]);
    bad("clearcoatTexture", json!({"index": 7}), &[&format!("{at}.clearcoatTexture.index"), "no texture"]);
    bad(
        "clearcoatNormalTexture",
        json!({"index": 0, "scale": "big"}),
        &[&format!("{at}.clearcoatNormalTexture.scale"), "finite"],
    );
    let mut d = doc.clone();
    d["materials"][0]["extensions"]["KHR_materials_clearcoat"] = json!(1);
    assert_has(&error(&d), &["materials[0].extensions.KHR_materials_clearcoat", "object"]);
    // The extension excludes unlit materials: an unlit surface reflects nothing, coat included.
    let mut d = doc.clone();
    d["materials"][0]["extensions"]["KHR_materials_unlit"] = json!({});
    assert!(load(&d).unwrap().materials[0].clearcoat.is_none());
}

#[test]
fn clearcoat_survives_export() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_clearcoat"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "material": 0}]}],
        "materials": [{"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.75,
                       "clearcoatRoughnessFactor": 0.3}}}],
    }));
    let s = load(&doc).unwrap();
    let back =
        scene::load_slice("t.gltf", scene::export::to_gltf_json(&s).unwrap().to_string().as_bytes(), None)
            .unwrap();
    assert_eq!(back.materials[0].clearcoat, s.materials[0].clearcoat);
    assert!(s.materials[0].clearcoat.is_some());
}

#[test]
fn iridescence_survives_export() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_iridescence"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "material": 0}]}],
        "materials": [{"extensions": {"KHR_materials_iridescence": {"iridescenceFactor": 0.75, "iridescenceIor": 1.6,
                       "iridescenceThicknessMinimum": 50, "iridescenceThicknessMaximum": 650}}}],
    }));
    let s = load(&doc).unwrap();
    let back =
        scene::load_slice("t.gltf", scene::export::to_gltf_json(&s).unwrap().to_string().as_bytes(), None)
            .unwrap();
    assert_eq!(back.materials[0].iridescence, s.materials[0].iridescence);
    assert!(s.materials[0].iridescence.is_some());
}

/// `KHR_materials_ior`: the index sets the dielectric's F0 (glTF's 0.04 exactly at the
/// default 1.5), survives export, and a value outside [1, 10000] is an error naming the field;
/// 0, the extension's specular-glossiness compatibility mode (an infinite index, Fresnel term
/// 1), is read as the largest index (f0 0.9996), and large ones are accepted (both were refused
/// above 10; found by a sweep).
#[test]
fn index_of_refraction_is_read_checked_and_exported() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let prim = |m: usize| json!({"attributes": {"POSITION": pos}, "material": m});
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_ior"],
        "extensionsRequired": ["KHR_materials_ior"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1)]}],
        "materials": [{"extensions": {"KHR_materials_ior": {"ior": 2.0}}}, {"extensions": {"KHR_materials_ior": {}}}],
    }));
    let s = load(&doc).unwrap();
    assert!(!s.warnings.join("\n").contains("KHR_materials_ior"), "{:?}", s.warnings);
    assert_eq!((s.materials[0].ior, s.materials[1].ior), (2.0, 1.5));
    assert!((s.materials[0].dielectric_f0() - 1.0 / 9.0).abs() < 1e-7);
    assert_eq!(s.materials[1].dielectric_f0(), 0.04);
    let back =
        scene::load_slice("t.gltf", scene::export::to_gltf_json(&s).unwrap().to_string().as_bytes(), None)
            .unwrap();
    assert_eq!((back.materials[0].ior, back.materials[1].ior), (2.0, 1.5));
    for v in [json!(0.9), json!(1e5), json!("1.4"), json!(-1), json!(1e-9)] {
        let mut d = doc.clone();
        d["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = v.clone();
        let e = load(&d).unwrap_err().to_string();
        assert!(
            e.contains("materials[0].extensions.KHR_materials_ior.ior") && e.contains("[1, 10000]"),
            "{v}: {e}"
        );
    }
    for (v, ior) in [(json!(0), scene::MAX_IOR), (json!(20), 20.0), (json!(1000), 1000.0)] {
        let mut d = doc.clone();
        d["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = v.clone();
        let m = &load(&d).unwrap().materials[0];
        assert_eq!(m.ior, ior, "{v}");
    }
    let mut d = doc.clone();
    d["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = json!(0);
    assert!(load(&d).unwrap().materials[0].dielectric_f0() > 0.999);
}

/// `KHR_materials_transmission` with `_volume` and `_dispersion`: read with their defaults
/// (thickness 0 is thin-walled, no attenuation distance is a clear interior), kept through
/// export, and every bad value named with its field; nothing is loaded then.
#[test]
fn transmission_volume_and_dispersion_are_read_checked_and_exported() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let prim = |m: usize| json!({"attributes": {"POSITION": pos}, "material": m});
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_dispersion"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1), prim(2), prim(3)]}],
        "images": [{"uri": png_uri()}],
        "textures": [{"source": 0}],
        "materials": [
            {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}},
            {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5, "transmissionTexture": {"index": 0}},
                            "KHR_materials_volume": {"thicknessFactor": 0.2, "attenuationDistance": 0.5,
                                                     "attenuationColor": [0.9, 0.5, 0.1], "thicknessTexture": {"index": 0}},
                            "KHR_materials_dispersion": {"dispersion": 0.36},
                            "KHR_materials_ior": {"ior": 2.42}}},
            {"extensions": {"KHR_materials_transmission": {}}},
            {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_volume": {}}},
        ],
    }));
    let s = load(&doc).unwrap();
    assert!(!s.warnings.join("\n").contains("KHR_materials_"), "{:?}", s.warnings);
    let mut required = doc.clone();
    required["extensionsRequired"] = required["extensionsUsed"].clone();
    assert!(load(&required).unwrap().materials[1].transmission.is_some());
    let thin = s.materials[0].transmission.as_ref().expect("transmissive");
    assert_eq!(
        (thin.factor, thin.volume.is_none(), thin.dispersion, thin.disperses()),
        (1.0, true, 0.0, false)
    );
    let gem = s.materials[1].transmission.as_ref().unwrap();
    let v = gem.volume.as_ref().expect("a volume");
    assert_eq!((gem.factor, gem.dispersion, v.thickness, v.attenuation_distance), (0.5, 0.36, 0.2, 0.5));
    assert_eq!(v.attenuation_color, [0.9, 0.5, 0.1]);
    assert!(gem.texture.is_some() && v.thickness_texture.is_some() && gem.disperses() && v.absorbs());
    // The default factor is 0: opaque. A volume of thickness 0 is thin-walled.
    assert!(s.materials[2].transmission.is_none());
    assert!(s.materials[3].transmission.as_ref().unwrap().volume.is_none());
    let back =
        scene::load_slice("t.gltf", scene::export::to_gltf_json(&s).unwrap().to_string().as_bytes(), None)
            .unwrap();
    for i in 0..4 {
        assert_eq!(back.materials[i].transmission, s.materials[i].transmission, "material {i}");
    }
    let bad = |ext: &str, key: &str, v: Value, parts: &[&str]| {
        let mut d = doc.clone();
        d["materials"][1]["extensions"][ext][key] = v.clone();
        let e = load(&d).unwrap_err();
        let at = format!("materials[1].extensions.{ext}.{key}");
        assert!(e.contains(&at), "{key} = {v}: {e}");
        assert_has(&e, parts);
    };
    for v in [json!(-0.1), json!(1.5), json!("1")] {
        bad("KHR_materials_transmission", "transmissionFactor", v, &["[0, 1]"]);
    }
    bad("KHR_materials_volume", "thicknessFactor", json!(-1), &["thickness"]);
    bad("KHR_materials_volume", "attenuationDistance", json!(0), &["> 0"]);
    bad("KHR_materials_volume", "attenuationDistance", json!(-2), &["> 0"]);
    bad("KHR_materials_volume", "attenuationColor", json!([1.2, 0.5, 0.5]), &["[0, 1]"]);
    bad("KHR_materials_volume", "attenuationColor", json!([0.5, 0.5]), &["three numbers"]);
    bad("KHR_materials_dispersion", "dispersion", json!(-0.5), &["Abbe number must be > 0"]);
    bad("KHR_materials_dispersion", "dispersion", json!(1e9), &["[0, 20]"]);
    bad("KHR_materials_transmission", "transmissionTexture", json!({"index": 7}), &["no texture"]);
    // Without transmission too (accepted silently; found by a sweep): read and validated.
    for (ext, key, v, part) in [
        ("KHR_materials_dispersion", "dispersion", json!(-1), "Abbe number must be > 0"),
        ("KHR_materials_volume", "thicknessFactor", json!(-1), "thickness"),
    ] {
        let mut d = doc.clone();
        d["materials"][0]["extensions"] = json!({ ext: { key: v } });
        let e = load(&d).unwrap_err();
        assert!(e.contains(&format!("materials[0].extensions.{ext}.{key}")), "{e}");
        assert_has(&e, &[part]);
        d["materials"][0]["extensions"][ext][key] = json!(0.5);
        assert!(load(&d).unwrap().materials[0].transmission.is_none());
    }
}

/// Clip planes that leave out the whole scene (a scene shrunk by a node's scale keeps its
/// camera's planes, which glTF does not scale) are said, naming the camera; the frame was the
/// background alone, without a word. A camera that sees part of the scene is not.
#[test]
fn clip_planes_that_leave_out_the_whole_scene_are_warned_about() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let cam = |znear: f64, zfar: f64| json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": znear, "zfar": zfar}}]);
    // The triangle lies in z = 0, 3 units before the camera.
    let mut doc = b.finish(json!({
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "cameras": cam(5.0, 100.0),
    }));
    let s = load(&doc).unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert_has(&s.warnings[0], &["cameras[0]", "nearer than the near plane", "znear 5", "nothing is drawn"]);
    doc["cameras"] = cam(0.1, 2.0);
    let s = load(&doc).unwrap();
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert_has(&s.warnings[0], &["cameras[0]", "beyond the far plane", "zfar 2", "nothing is drawn"]);
    for (znear, zfar) in [(0.1, 100.0), (2.9, 100.0), (0.1, 3.1)] {
        doc["cameras"] = cam(znear, zfar);
        assert!(load(&doc).unwrap().warnings.is_empty(), "{znear} {zfar}");
    }
}

/// An extension's textureInfo takes its texCoord as the core one does: a non-negative integer.
/// -1, 1.5 and "1" were read as TEXCOORD_0 without a word, and 2³² was named as 4294967295.
#[test]
fn extension_textures_reject_a_tex_coord_that_is_not_a_set_index() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2");
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_clearcoat"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": 0}]}],
        "materials": [{"extensions": {
            "KHR_materials_specular": {"specularTexture": {"index": 0, "texCoord": 0}},
            "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatTexture": {"index": 0}},
        }}],
    }));
    doc["images"] = json!([{"uri": png_uri()}]);
    doc["textures"] = json!([{"source": 0}]);
    assert!(load(&doc).unwrap().materials[0].specular.is_some());
    for (ext, key) in
        [("KHR_materials_specular", "specularTexture"), ("KHR_materials_clearcoat", "clearcoatTexture")]
    {
        for (v, shown) in [
            (json!(-1), "-1"),
            (json!(1.5), "1.5"),
            (json!("1"), "\"1\""),
            (json!(4_294_967_296u64), "4294967296"),
        ] {
            let mut d = doc.clone();
            d["materials"][0]["extensions"][ext][key]["texCoord"] = v;
            assert_has(&error(&d), &[&format!("materials[0].extensions.{ext}.{key}.texCoord"), shown]);
        }
    }
}

/// `KHR_materials_specular`: read with its defaults (a material at them has none), textures as
/// data (the strength's A) and sRGB colour, bad values named by field; dropped with a warning
/// where the renderers draw the reflection from the index alone (a film, a transmission), and
/// on unlit materials, which the extension excludes; survives export.
#[test]
fn specular_is_read_with_its_defaults_and_bad_values_are_named() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2");
    let sp = |x: Value| json!({"extensions": {"KHR_materials_specular": x}});
    let prim = |m: usize| json!({"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": m});
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_specular"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1), prim(2)]}],
        "materials": [
            sp(json!({"specularFactor": 0.25})),
            sp(json!({"specularColorFactor": [25.0, 0.5, 0.0],
                      "specularTexture": {"index": 0}, "specularColorTexture": {"index": 0}})),
            sp(json!({"specularFactor": 1.0, "specularColorFactor": [1.0, 1.0, 1.0]})),
        ],
    }));
    doc["images"] = json!([{"uri": png_uri()}]);
    doc["textures"] = json!([{"source": 0}]);
    let s = load(&doc).unwrap();
    let said = s.warnings.join("\n");
    assert!(!said.contains("KHR_materials_specular"), "{said}");
    let mut required = doc.clone();
    required["extensionsRequired"] = json!(["KHR_materials_specular"]);
    assert!(load(&required).unwrap().materials[0].specular.is_some());
    let a = s.materials[0].specular.as_ref().expect("a specular");
    assert_eq!((a.factor, a.color), (0.25, Vec3::ONE));
    let t = s.materials[1].specular.as_ref().unwrap();
    assert_eq!((t.factor, t.color), (1.0, Vec3::new(25.0, 0.5, 0.0)));
    assert!(!s.textures[t.texture.unwrap().index].srgb, "the strength is data");
    assert!(s.textures[t.color_texture.unwrap().index].srgb, "the colour is sRGB");
    assert!(s.materials[2].specular.is_none(), "defaults change nothing");
    assert_eq!(scene::specular::f0_color(s.materials[1].dielectric_f0(), t.color), Vec3::new(1.0, 0.02, 0.0));

    let bad = |key: &str, v: Value, parts: &[&str]| {
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_specular"][key] = v;
        assert_has(&error(&d), parts);
    };
    let at = "materials[1].extensions.KHR_materials_specular";
    bad("specularFactor", json!(1.5), &[&format!("{at}.specularFactor"), "[0, 1]"]);
    bad("specularFactor", json!("1"), &[&format!("{at}.specularFactor"), "[0, 1]"]);
    bad(
        "specularColorFactor",
        json!([1.0, -0.1, 1.0]),
        &[&format!("{at}.specularColorFactor"), "three numbers"],
    );
    bad("specularColorFactor", json!([1.0, 1.0]), &[&format!("{at}.specularColorFactor"), "three numbers"]);
    bad(
        "specularColorFactor",
        json!([1.0, 1.0, 1e300]),
        &[&format!("{at}.specularColorFactor"), "three numbers"],
    );
    bad("specularTexture", json!({"index": 7}), &[&format!("{at}.specularTexture.index"), "no texture"]);
    // Excluded: unlit (silently, as the coat), a film or a transmission (with a warning).
    let mut d = doc.clone();
    d["materials"][0]["extensions"]["KHR_materials_unlit"] = json!({});
    assert!(load(&d).unwrap().materials[0].specular.is_none());
    for (ext, v) in [
        ("KHR_materials_iridescence", json!({"iridescenceFactor": 1.0})),
        ("KHR_materials_transmission", json!({"transmissionFactor": 1.0})),
    ] {
        let mut d = doc.clone();
        d["materials"][0]["extensions"][ext] = v;
        let s = load(&d).unwrap();
        assert!(s.materials[0].specular.is_none(), "{ext}");
        let said = s.warnings.join("\n");
        assert!(
            said.contains("materials[0]") && said.contains("KHR_materials_specular is ignored"),
            "{said}"
        );
    }
    let back =
        scene::load_slice("t.gltf", scene::export::to_gltf_json(&s).unwrap().to_string().as_bytes(), None)
            .unwrap();
    assert_eq!(back.materials[0].specular, s.materials[0].specular);
}

/// `KHR_materials_sheen`: read with its defaults (a zero colour, the default, turns the layer
/// off: none), the colour texture as sRGB colour and the roughness texture as data, each with
/// its UV set and transform; bad values named by field; dropped with a warning on unlit and
/// specular-glossiness materials, which the extension excludes, and kept beside a coat, a
/// specular, a transmission and a film; survives export.
#[test]
fn sheen_is_read_with_its_defaults_and_bad_values_are_named() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2");
    let sh = |x: Value| json!({"extensions": {"KHR_materials_sheen": x}});
    let prim = |m: usize| json!({"attributes": {"POSITION": pos, "TEXCOORD_0": uv, "TEXCOORD_1": uv}, "material": m});
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_sheen", "KHR_texture_transform"],
        "extensionsRequired": ["KHR_materials_sheen"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim(0), prim(1), prim(2), prim(3), prim(4)]}],
        "materials": [
            sh(json!({"sheenColorFactor": [0.5, 0.25, 1.0], "sheenRoughnessFactor": 0.75,
                      "sheenColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                          {"offset": [0.5, 0.0], "scale": [2.0, 2.0]}}},
                      "sheenRoughnessTexture": {"index": 0, "texCoord": 1}})),
            // Only a colour: roughness 0, no textures; an unknown member is ignored.
            sh(json!({"sheenColorFactor": [1, 1, 1], "sheenTexture": {"index": 0}})),
            // The defaults: a zero colour, no layer.
            sh(json!({})),
            // A zero colour turns the layer off whatever the rest says.
            sh(json!({"sheenColorFactor": [0, 0, 0], "sheenRoughnessFactor": 1.0,
                      "sheenColorTexture": {"index": 0}})),
            // Beside every other layer it may sit with.
            json!({"extensions": {
                "KHR_materials_sheen": {"sheenColorFactor": [0.1, 0.2, 0.3], "sheenRoughnessFactor": 0.5},
                "KHR_materials_clearcoat": {"clearcoatFactor": 1.0},
                "KHR_materials_specular": {"specularFactor": 0.5},
                "KHR_materials_transmission": {"transmissionFactor": 1.0},
                "KHR_materials_iridescence": {"iridescenceFactor": 1.0},
            }}),
        ],
    }));
    doc["images"] = json!([{"uri": png_uri()}]);
    doc["textures"] = json!([{"source": 0}]);
    let s = load(&doc).unwrap();
    let said = s.warnings.join("\n");
    assert!(!said.contains("KHR_materials_sheen"), "{said}");
    let a = s.materials[0].sheen.as_ref().expect("a sheen");
    assert_eq!((a.color, a.roughness), (Vec3::new(0.5, 0.25, 1.0), 0.75));
    let (c, r) = (a.color_texture.unwrap(), a.roughness_texture.unwrap());
    assert!(s.textures[c.index].srgb, "the colour is sRGB");
    assert!(!s.textures[r.index].srgb, "the roughness (A) is data");
    assert_ne!(c.index, r.index);
    assert_eq!(c.tex_coord, 0);
    assert_eq!(
        c.transform,
        Some(TextureTransform { offset: Vec2::new(0.5, 0.0), rotation: 0.0, scale: Vec2::splat(2.0) })
    );
    assert_eq!((r.tex_coord, r.transform), (1, None));
    let d = s.materials[1].sheen.as_ref().expect("a sheen");
    let white = scene::sheen::Sheen {
        color: Vec3::ONE,
        color_texture: None,
        roughness: 0.0,
        roughness_texture: None,
    };
    assert_eq!(d, &white, "defaults besides the colour");
    assert!(s.materials[2].sheen.is_none(), "the default colour is zero: no layer");
    assert!(s.materials[3].sheen.is_none(), "a zero colour turns the layer off");
    let all = &s.materials[4];
    assert_eq!(all.sheen.as_ref().map(|x| (x.color, x.roughness)), Some((Vec3::new(0.1, 0.2, 0.3), 0.5)));
    assert!(all.clearcoat.is_some() && all.transmission.is_some() && all.iridescence.is_some());

    let at = "materials[0].extensions.KHR_materials_sheen";
    let bad = |key: &str, v: Value, parts: &[&str]| {
        let mut d = doc.clone();
        d["materials"][0]["extensions"]["KHR_materials_sheen"][key] = v;
        assert_has(&error(&d), parts);
    };
    let color = format!("{at}.sheenColorFactor");
    for v in [
        json!([1.5, 0.5, 0.5]),
        json!([0.5, -0.1, 0.5]),
        json!([0.5, 0.5, 1e300]),
        json!([0.5, 0.5]),
        json!([0.5, 0.5, 0.5, 1.0]),
        json!([0.5, f64::NAN, 0.5]),
        json!([0.5, "0.5", 0.5]),
        json!("0.5"),
        json!(0.5),
    ] {
        bad("sheenColorFactor", v, &[&color, "three numbers in [0, 1]"]);
    }
    let rough = format!("{at}.sheenRoughnessFactor");
    for v in [json!(1.5), json!(-0.25), json!(f64::NAN), json!("0.5"), json!([0.5])] {
        bad("sheenRoughnessFactor", v, &[&rough, "[0, 1]"]);
    }
    for key in ["sheenColorTexture", "sheenRoughnessTexture"] {
        bad(key, json!({"index": 7}), &[&format!("{at}.{key}.index"), "no texture"]);
        bad(key, json!({"index": "0"}), &[&format!("{at}.{key}.index"), "no texture"]);
        for (v, shown) in [(json!(-1), "-1"), (json!(1.5), "1.5"), (json!("1"), "\"1\""), (json!(2), "2")] {
            bad(key, json!({"index": 0, "texCoord": v}), &[&format!("{at}.{key}.texCoord"), shown]);
        }
        bad(
            key,
            json!({"index": 0, "extensions": {"KHR_texture_transform": {"scale": [1]}}}),
            &[&format!("{at}.{key}.extensions.KHR_texture_transform.scale")],
        );
    }
    // The roughness texture reads TEXCOORD_1: a mesh without one is refused, naming it.
    let mut d = doc.clone();
    d["meshes"][0]["primitives"][0]["attributes"].as_object_mut().unwrap().remove("TEXCOORD_1");
    assert_has(&error(&d), &["meshes[0].primitives[0]", &format!("{at}.sheenRoughnessTexture")]);

    // Excluded: unlit and specular-glossiness materials, with one warning naming the material.
    for (ext, v, what) in [
        ("KHR_materials_unlit", json!({}), "unlit"),
        ("KHR_materials_pbrSpecularGlossiness", json!({"glossinessFactor": 0.5}), "specular-glossiness"),
    ] {
        let mut d = doc.clone();
        d["materials"][1]["name"] = json!("velvet");
        d["materials"][1]["extensions"][ext] = v;
        let s = load(&d).unwrap();
        assert!(s.materials[1].sheen.is_none(), "{ext}");
        assert!(s.materials[0].sheen.is_some(), "{ext}");
        let w: Vec<_> = s.warnings.iter().filter(|w| w.contains("KHR_materials_sheen")).collect();
        assert_eq!(w.len(), 1, "{ext}: {:?}", s.warnings);
        assert!(
            w[0].starts_with("materials[1] ('velvet'): KHR_materials_sheen is ignored")
                && w[0].contains(ext)
                && w[0].contains(what),
            "{}",
            w[0]
        );
    }
    // A sheen that is off loses nothing there: no warning. Nor does a dropped sheen's texture
    // on TEXCOORD_1 ask the mesh for one.
    let mut d = doc.clone();
    d["materials"][2]["extensions"]["KHR_materials_unlit"] = json!({});
    d["materials"][0]["extensions"]["KHR_materials_unlit"] = json!({});
    d["meshes"][0]["primitives"][0]["attributes"].as_object_mut().unwrap().remove("TEXCOORD_1");
    let s = load(&d).unwrap();
    assert_eq!(
        s.warnings.iter().filter(|w| w.contains("KHR_materials_sheen")).count(),
        1,
        "{:?}",
        s.warnings
    );
    assert!(s.warnings.iter().any(|w| w.starts_with("materials[0] (")), "{:?}", s.warnings);

    // Export: the factors, textures, UV sets and transforms come back as they were.
    let s = load(&doc).unwrap();
    let out = scene::export::to_gltf_json(&s).unwrap();
    let used: Vec<&str> =
        out["extensionsUsed"].as_array().unwrap().iter().filter_map(Value::as_str).collect();
    assert!(used.contains(&"KHR_materials_sheen") && used.contains(&"KHR_texture_transform"), "{used:?}");
    assert!(out["materials"][2]["extensions"].get("KHR_materials_sheen").is_none());
    let back = scene::load_slice("t.gltf", out.to_string().as_bytes(), None).unwrap();
    for (i, (m, n)) in s.materials.iter().zip(&back.materials).enumerate() {
        assert_eq!(m.sheen, n.sheen, "material {i}");
    }
    let (bc, br) = {
        let x = back.materials[0].sheen.as_ref().unwrap();
        (x.color_texture.unwrap(), x.roughness_texture.unwrap())
    };
    assert!(back.textures[bc.index].srgb && !back.textures[br.index].srgb);
    // A scene without a sheen does not list the extension.
    let mut plain = s.clone();
    plain.materials.iter_mut().for_each(|m| m.sheen = None);
    let out = scene::export::to_gltf_json(&plain).unwrap();
    assert!(!out["extensionsUsed"].to_string().contains("KHR_materials_sheen"));
}

/// A 2×1 lossless WebP of `rgba` as a data URI (the `image` crate's encoder).
fn webp_uri(rgba: [u8; 8]) -> String {
    let img = image::RgbaImage::from_raw(2, 1, rgba.to_vec()).unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::WebP).unwrap();
    data_uri("image/webp", &out.into_inner())
}

/// EXT_texture_webp: the WebP image is preferred to the PNG/JPEG fallback in `source`, a texture
/// may have only the WebP image, a file may require the extension; a WebP image given as an
/// ordinary image decodes too; a bad index and a damaged WebP are named.
#[test]
fn webp_textures_are_decoded() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let uv = b.f32s(&[0.0; 6], "VEC2");
    let mut doc = single_mesh(
        b,
        json!([{"attributes": {"POSITION": pos, "TEXCOORD_0": uv}, "material": 0}]),
        json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]),
    );
    let webp = [200, 10, 20, 255, 30, 220, 40, 128];
    doc["extensionsUsed"] = json!(["EXT_texture_webp"]);
    doc["extensionsRequired"] = json!(["EXT_texture_webp"]);
    doc["images"] = json!([{"uri": png_uri()}, {"uri": webp_uri(webp)}]);
    doc["textures"] = json!([{"source": 0, "extensions": {"EXT_texture_webp": {"source": 1}}}]);
    let texels = |doc: &Value| {
        let s = load(doc).unwrap();
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        let t = &s.textures[s.materials[0].base_color_texture.unwrap().index];
        ((t.width, t.height), t.rgba8.clone())
    };
    assert_eq!(texels(&doc), ((2, 1), webp.to_vec()), "the WebP image, not the PNG fallback");
    // Only the WebP image.
    let mut only = doc.clone();
    only["textures"][0].as_object_mut().unwrap().remove("source");
    assert_eq!(texels(&only), ((2, 1), webp.to_vec()));
    // A WebP image as a texture's plain source.
    let mut plain = doc.clone();
    plain["textures"] = json!([{"source": 1}]);
    assert_eq!(texels(&plain), ((2, 1), webp.to_vec()));
    // A bad index, a missing one, a damaged image.
    let at = "textures[0].extensions.EXT_texture_webp.source";
    for v in [json!(7), json!(-1), json!("1")] {
        let mut bad = only.clone();
        bad["textures"][0]["extensions"]["EXT_texture_webp"]["source"] = v;
        assert_has(&error(&bad), &[at, "is not the index of one of the file's 2 images"]);
    }
    let mut bad = only.clone();
    bad["textures"][0]["extensions"]["EXT_texture_webp"] = json!({});
    assert_has(&error(&bad), &[at, "is missing"]);
    let mut bad = only.clone();
    bad["images"][1]["uri"] = json!(data_uri("image/webp", b"RIFF\x1a\0\0\0WEBPVP8L\x0d\0\0\0 not a webp"));
    assert_has(&error(&bad), &["images[1]", "cannot"]);
}

/// KHR_materials_variants: without a choice the primitives' own materials, and a warning naming
/// the variants; `--variant NAME` (exact, else any case) draws each primitive's mapped material
/// where a mapping names it, its own elsewhere; an unknown name lists the file's variants; bad
/// indices are named.
#[test]
fn material_variants_are_chosen_by_name() {
    let mut b = Bin::default();
    let pos = b.triangle();
    let mut doc = single_mesh(
        b,
        json!([{"attributes": {"POSITION": pos}, "material": 0,
                "extensions": {"KHR_materials_variants": {"mappings": [
                    {"material": 1, "variants": [0, 2]}, {"material": 2, "variants": [1]}]}}},
               {"attributes": {"POSITION": pos}, "material": 0}]),
        json!([{"name": "plain"}, {"name": "red"}, {"name": "blue"}]),
    );
    doc["extensionsUsed"] = json!(["KHR_materials_variants"]);
    doc["extensions"] = json!({"KHR_materials_variants": {"variants": [{"name": "Midnight"}, {"name": "beach"}, {"name": "street"}]}});
    let drawn = |variant: Option<&str>| -> Result<(Vec<String>, Vec<String>), String> {
        let opts = scene::LoadOptions { variant: variant.map(String::from), ..Default::default() };
        let s = scene_with_options(&doc, &opts)?;
        Ok((s.meshes.iter().map(|m| s.materials[m.material].name.clone()).collect(), s.warnings.clone()))
    };
    let (names, warnings) = drawn(None).unwrap();
    assert_eq!(names, ["plain", "plain"]);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("'Midnight', 'beach' and 'street'") && warnings[0].contains("--variant"));
    for (v, want) in [("Midnight", "red"), ("midnight", "red"), ("beach", "blue"), ("street", "red")] {
        let (names, warnings) = drawn(Some(v)).unwrap();
        assert_eq!(names, [want, "plain"], "{v}");
        assert!(warnings.is_empty(), "{warnings:?}");
    }
    assert_has(&drawn(Some("night")).unwrap_err(), &["--variant night", "'Midnight', 'beach' and 'street'"]);
    let at = "meshes[0].primitives[0].extensions.KHR_materials_variants.mappings";
    let mut bad = doc.clone();
    bad["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][1]["material"] =
        json!(3);
    assert_has(&error(&bad), &[&format!("{at}[1].material"), "3 materials"]);
    let mut bad = doc.clone();
    bad["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][0]["variants"][1] =
        json!(5);
    assert_has(&error(&bad), &[&format!("{at}[0].variants[1]"), "3 variants"]);
    let mut bad = doc.clone();
    bad["extensions"]["KHR_materials_variants"]["variants"][1] = json!({});
    assert_has(&error(&bad), &["extensions.KHR_materials_variants.variants[1].name"]);
    // A file without variants, asked for one.
    let mut none = doc.clone();
    none.as_object_mut().unwrap().remove("extensions");
    none["meshes"][0]["primitives"][0].as_object_mut().unwrap().remove("extensions");
    let opts = scene::LoadOptions { variant: Some("red".into()), ..Default::default() };
    assert_has(&scene_with_options(&none, &opts).unwrap_err(), &["--variant red", "no material variants"]);
}

/// `doc` written to a temporary file and loaded with `opts` (variants are a file-load option).
fn scene_with_options(doc: &Value, opts: &scene::LoadOptions) -> Result<Scene, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    scene::load_with(&path, opts).map_err(|e| e.to_string())
}
