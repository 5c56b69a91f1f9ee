//! Bad input must give an error naming the file and the place, never a panic.

use std::path::{Path, PathBuf};

use rand::{Rng, SeedableRng};
use serde_json::{Value, json};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn fixture() -> Value {
    serde_json::from_slice(&std::fs::read(data("textured.gltf")).unwrap()).unwrap()
}

/// Loads `doc` as if it were `broken.gltf` next to the fixtures, expecting an error.
fn error_of(doc: &Value) -> String {
    match scene::load_slice("broken.gltf", doc.to_string().as_bytes(), Some(&data(""))) {
        Ok(_) => panic!("loaded without error"),
        Err(e) => e.to_string(),
    }
}

fn expect(doc: &Value, parts: &[&str]) {
    let e = error_of(doc);
    assert!(e.starts_with("broken.gltf"), "error does not name the file: {e}");
    for p in parts {
        assert!(e.contains(p), "error lacks '{p}': {e}");
    }
}

fn mutate(f: impl FnOnce(&mut Value)) -> Value {
    let mut d = fixture();
    f(&mut d);
    d
}

#[test]
fn garbage_and_truncated_files() {
    let err = scene::load_slice("junk.glb", b"\x00\x01garbage\xff", None).unwrap_err();
    let e = err.to_string();
    assert!(e.contains("junk.glb") && e.contains("not a valid glTF"), "{e}");
    // The cause is in the message, not chained as well: `{:#}` printers would repeat it.
    assert!(std::error::Error::source(&err).is_none(), "{e}");
    let glb = std::fs::read(data("textured.glb")).unwrap();
    let mut bad_magic = glb.clone();
    bad_magic[..4].copy_from_slice(b"gltf");
    let e = scene::load_slice("magic.glb", &bad_magic, None).unwrap_err().to_string();
    assert!(e.contains("magic.glb") && e.contains("'glTF' magic") && !e.contains("line 1"), "{e}");
    for cut in [0, 11, 12, 20, 100, glb.len() / 2, glb.len() - 1] {
        let e = scene::load_slice("cut.glb", &glb[..cut], None).unwrap_err().to_string();
        assert!(e.starts_with("cut.glb"), "cut at {cut}: {e}");
    }
    let text = std::fs::read(data("textured.gltf")).unwrap();
    assert!(scene::load_slice("cut.gltf", &text[..text.len() / 2], Some(&data(""))).is_err());
}

/// A JPEG cut short decodes without complaint (the decoder makes the rest up): refused by
/// name; the whole file loads.
#[test]
fn a_truncated_jpeg_texture_is_refused() {
    let img = image::RgbImage::from_fn(32, 32, |x, y| image::Rgb([(x * 8) as u8, (y * 8) as u8, 128]));
    let mut jpeg = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut jpeg), image::ImageFormat::Jpeg).unwrap();
    use base64::Engine;
    let uri =
        |b: &[u8]| format!("data:image/jpeg;base64,{}", base64::engine::general_purpose::STANDARD.encode(b));
    let whole = mutate(|d| d["images"][0]["uri"] = json!(uri(&jpeg)));
    assert!(scene::load_slice("jpeg.gltf", whole.to_string().as_bytes(), Some(&data(""))).is_ok());
    for cut in [jpeg.len() - 2, jpeg.len() / 2, 700.min(jpeg.len() / 3)] {
        expect(&mutate(|d| d["images"][0]["uri"] = json!(uri(&jpeg[..cut]))), &["images[0]", "truncated"]);
    }
}

#[test]
fn missing_files() {
    expect(&mutate(|d| d["images"][0]["uri"] = json!("nope.png")), &["images[0].uri", "nope.png"]);
    expect(&mutate(|d| d["buffers"][0]["uri"] = json!("nope.bin")), &["buffers[0].uri", "nope.bin"]);
    expect(&mutate(|d| d["images"][1]["uri"] = json!("quad.bin")), &["images[1]", "image"]);
    expect(
        &mutate(|d| d["buffers"][0]["uri"] = json!("https://example.com/a.bin")),
        &["buffers[0].uri", "remote"],
    );
}

#[test]
fn unsupported_geometry_and_structure() {
    expect(
        &mutate(
            |d| d["cameras"][0] = json!({"type": "orthographic", "orthographic": {"xmag": 0, "ymag": 1, "znear": 0.1, "zfar": 10}}),
        ),
        &["cameras[0].orthographic", "xmag"],
    );
    expect(
        &mutate(|d| d["extensionsRequired"] = json!(["KHR_materials_volume_scatter"])),
        &["extensionsRequired[0]", "KHR_materials_volume_scatter", "not supported"],
    );
    expect(
        &mutate(|d| d["materials"][0]["normalTexture"]["texCoord"] = json!(1)),
        &["meshes[0].primitives[0]", "materials[0].normalTexture reads TEXCOORD_1", "no TEXCOORD_1"],
    );
    // Wrong indices: caught by validation or by our own checks, named either way.
    expect(&mutate(|d| d["meshes"][0]["primitives"][0]["indices"] = json!(99)), &["indices"]);
    expect(&mutate(|d| d["accessors"][0]["count"] = json!(400)), &["POSITION", "accessors[0]", "overrun"]);
    expect(&mutate(|d| d["accessors"][1]["type"] = json!("VEC2")), &["NORMAL", "accessors[1]"]);
    expect(&mutate(|d| d["buffers"][0]["byteLength"] = json!(100000)), &["buffers[0]", "byteLength"]);
    expect(&mutate(|d| d["bufferViews"][0]["byteStride"] = json!(4)), &["byteStride"]);
    expect(&mutate(|d| d["scenes"] = json!([])), &["scene"]);
    // An index beyond the vertex count: patch the first index of the quad to 9 and embed the
    // buffer as a data URI.
    let mut bin = std::fs::read(data("quad.bin")).unwrap();
    let doc = fixture();
    let off = doc["bufferViews"][3]["byteOffset"].as_u64().unwrap() as usize;
    bin[off..off + 2].copy_from_slice(&9u16.to_le_bytes());
    use base64::Engine;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    expect(
        &mutate(|d| d["buffers"][0]["uri"] = json!(uri)),
        &["meshes[0].primitives[0].indices", "index number 0 is out of range", "4 vertices"],
    );
}

/// `KHR_materials_sheen` is read and checked like the other material extensions: each bad
/// member is one error naming the file and the field; a good one loads, even when required.
#[test]
fn bad_sheen() {
    let sheen = |v: Value| {
        mutate(|d| {
            d["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_materials_sheen"));
            d["extensionsRequired"] = json!(["KHR_materials_sheen"]);
            d["materials"][1]["extensions"] = json!({"KHR_materials_sheen": v});
        })
    };
    let good = sheen(json!({"sheenColorFactor": [0.5, 0.5, 0.5], "sheenRoughnessTexture": {"index": 0}}));
    let s = scene::load_slice("good.gltf", good.to_string().as_bytes(), Some(&data(""))).unwrap();
    assert!(s.materials[1].sheen.is_some(), "{:?}", s.warnings);
    let at = "materials[1].extensions.KHR_materials_sheen";
    let cases = [
        (json!({"sheenColorFactor": [0.5, 1.01, 0.5]}), format!("{at}.sheenColorFactor")),
        (json!({"sheenColorFactor": [-0.5, 0.5, 0.5]}), format!("{at}.sheenColorFactor")),
        (json!({"sheenColorFactor": [0.5, 0.5]}), format!("{at}.sheenColorFactor")),
        (json!({"sheenColorFactor": "white"}), format!("{at}.sheenColorFactor")),
        (
            json!({"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 2}),
            format!("{at}.sheenRoughnessFactor"),
        ),
        (
            json!({"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": null}),
            format!("{at}.sheenRoughnessFactor"),
        ),
        (
            json!({"sheenColorFactor": [1, 1, 1], "sheenColorTexture": {"index": 3}}),
            format!("{at}.sheenColorTexture.index"),
        ),
        (
            json!({"sheenColorFactor": [1, 1, 1], "sheenRoughnessTexture": {"index": 0, "texCoord": -1}}),
            format!("{at}.sheenRoughnessTexture.texCoord"),
        ),
    ];
    for (v, field) in cases {
        expect(&sheen(v), &[&field]);
    }
}

/// `KHR_materials_anisotropy` is read and checked like the other material extensions; its
/// meshes get tangents even without a normal map: MikkTSpace ones on the UV set, or the normal's
/// fallback frame on a mesh without UVs.
#[test]
fn bad_anisotropy() {
    let aniso = |v: Value| {
        mutate(|d| {
            d["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_materials_anisotropy"));
            d["extensionsRequired"] = json!(["KHR_materials_anisotropy"]);
            d["materials"][0]["extensions"]["KHR_materials_anisotropy"] = v;
            // Without its normal map, so that the tangents come from the anisotropy.
            d["materials"][0].as_object_mut().unwrap().remove("normalTexture");
        })
    };
    let load = |d: &Value| scene::load_slice("good.gltf", d.to_string().as_bytes(), Some(&data(""))).unwrap();
    let good = aniso(
        json!({"anisotropyStrength": 0.6, "anisotropyRotation": 1.0, "anisotropyTexture": {"index": 0}}),
    );
    let s = load(&good);
    let a = s.materials[0].anisotropy.as_ref().expect("read");
    assert_eq!((a.strength, a.rotation, a.texture.map(|t| t.tex_coord)), (0.6, 1.0, Some(0)));
    let users: Vec<_> = s.meshes.iter().filter(|m| m.material == 0).collect();
    assert!(!users.is_empty());
    for m in &users {
        assert_eq!(m.tangents.len(), m.positions.len(), "tangents made for the anisotropy");
        for (t, n) in m.tangents.iter().zip(&m.normals) {
            assert!(t.truncate().is_normalized() && t.truncate().dot(*n).abs() < 1e-3, "{t} vs {n}");
        }
    }
    // Strength 0 (the default) is off, whatever else is given.
    assert!(load(&aniso(json!({"anisotropyRotation": 2.0}))).materials[0].anisotropy.is_none());
    // On a mesh without normals or UVs (the fixture's triangle): the fallback frame
    // (scene::fallback_tangent), perpendicular to the (flat) normal.
    let mut no_uv = good.clone();
    no_uv["materials"][1]["extensions"] = json!({"KHR_materials_anisotropy": {"anisotropyStrength": 1.0}});
    let s = load(&no_uv);
    assert!(s.materials[1].anisotropy.is_some());
    for m in s.meshes.iter().filter(|m| m.material == 1) {
        assert!(m.uvs.is_empty());
        assert_eq!(m.tangents.len(), m.positions.len());
        for (t, n) in m.tangents.iter().zip(&m.normals) {
            // Made in the mesh's own frame, then turned with its node as every tangent is.
            assert!(t.truncate().is_normalized() && t.truncate().dot(*n).abs() < 1e-6, "{t} vs {n}");
        }
    }
    // On an unlit material: dropped with a warning naming the material.
    let mut unlit = good.clone();
    unlit["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_materials_unlit"));
    unlit["materials"][0]["extensions"]["KHR_materials_unlit"] = json!({});
    let s = load(&unlit);
    assert!(s.materials[0].anisotropy.is_none());
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("materials[0]") && w.contains("KHR_materials_anisotropy is ignored")),
        "{:?}",
        s.warnings
    );
    let at = "materials[0].extensions.KHR_materials_anisotropy";
    let cases = [
        (json!({"anisotropyStrength": 1.5}), format!("{at}.anisotropyStrength")),
        (json!({"anisotropyStrength": -0.1}), format!("{at}.anisotropyStrength")),
        (json!({"anisotropyStrength": "max"}), format!("{at}.anisotropyStrength")),
        (json!({"anisotropyStrength": 1, "anisotropyRotation": 1e30}), format!("{at}.anisotropyRotation")),
        (json!({"anisotropyStrength": 1, "anisotropyRotation": null}), format!("{at}.anisotropyRotation")),
        (
            json!({"anisotropyStrength": 1, "anisotropyTexture": {"index": 3}}),
            format!("{at}.anisotropyTexture.index"),
        ),
        (
            json!({"anisotropyStrength": 1, "anisotropyTexture": {"index": 0, "texCoord": 1.5}}),
            format!("{at}.anisotropyTexture.texCoord"),
        ),
    ];
    for (v, field) in cases {
        expect(&aniso(v), &[&field]);
    }
}

#[test]
fn bad_diffuse_transmission() {
    let ext = "KHR_materials_diffuse_transmission";
    let dt = |v: Value| {
        mutate(|d| {
            d["extensionsUsed"].as_array_mut().unwrap().push(json!(ext));
            d["extensionsRequired"] = json!([ext]);
            d["materials"][0]["extensions"][ext] = v;
        })
    };
    let load = |d: &Value| scene::load_slice("good.gltf", d.to_string().as_bytes(), Some(&data(""))).unwrap();
    let good = dt(json!({
        "diffuseTransmissionFactor": 0.4,
        "diffuseTransmissionTexture": {"index": 0},
        "diffuseTransmissionColorFactor": [1.0, 0.5, 0.25],
        "diffuseTransmissionColorTexture": {"index": 0}
    }));
    let s = load(&good);
    let d = s.materials[0].diffuse_transmission.as_ref().expect("read");
    assert_eq!((d.factor, d.color.to_array()), (0.4, [1.0, 0.5, 0.25]));
    assert!(d.texture.is_some() && d.color_texture.is_some());
    // The colour texture is sRGB colour, the factor's (A channel) data: both read here.
    let defaults = load(&dt(json!({"diffuseTransmissionFactor": 1.0})));
    let d = defaults.materials[0].diffuse_transmission.as_ref().expect("read");
    assert_eq!((d.factor, d.color.to_array()), (1.0, [1.0; 3]));
    // Factor 0 (the default) is off, whatever else is given.
    assert!(
        load(&dt(json!({"diffuseTransmissionColorFactor": [1, 0, 0]}))).materials[0]
            .diffuse_transmission
            .is_none()
    );
    // With a thick volume but no KHR_materials_transmission: drawn thin, and said.
    let mut vol = good.clone();
    vol["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_materials_volume"));
    vol["materials"][0]["extensions"]["KHR_materials_volume"] = json!({"thicknessFactor": 0.5});
    let s2 = load(&vol);
    assert!(s2.materials[0].transmission.is_none() && s2.materials[0].diffuse_transmission.is_some());
    assert!(
        s2.warnings.iter().any(|w| w.contains("materials[0]") && w.contains("drawn as a thin sheet")),
        "{:?}",
        s2.warnings
    );
    vol["materials"][0]["extensions"]["KHR_materials_volume"] = json!({"thicknessFactor": 0});
    assert!(!load(&vol).warnings.iter().any(|w| w.contains("thin sheet")));
    // Exported and read back unchanged.
    let json = scene::export::to_gltf_json(&s).unwrap().to_string();
    let back = scene::load_slice("back.gltf", json.as_bytes(), None).unwrap();
    assert_eq!(back.materials[0].diffuse_transmission, s.materials[0].diffuse_transmission);
    // On an unlit material: dropped with a warning naming the material.
    let mut unlit = good.clone();
    unlit["extensionsUsed"].as_array_mut().unwrap().push(json!("KHR_materials_unlit"));
    unlit["materials"][0]["extensions"]["KHR_materials_unlit"] = json!({});
    let s = load(&unlit);
    assert!(s.materials[0].diffuse_transmission.is_none());
    assert!(
        s.warnings.iter().any(|w| w.contains("materials[0]") && w.contains(&format!("{ext} is ignored"))),
        "{:?}",
        s.warnings
    );
    let at = format!("materials[0].extensions.{ext}");
    let cases = [
        (json!({"diffuseTransmissionFactor": 1.5}), format!("{at}.diffuseTransmissionFactor")),
        (json!({"diffuseTransmissionFactor": -0.1}), format!("{at}.diffuseTransmissionFactor")),
        (json!({"diffuseTransmissionFactor": "half"}), format!("{at}.diffuseTransmissionFactor")),
        (
            json!({"diffuseTransmissionFactor": 1, "diffuseTransmissionColorFactor": [1, 2, 0]}),
            format!("{at}.diffuseTransmissionColorFactor"),
        ),
        (
            json!({"diffuseTransmissionFactor": 1, "diffuseTransmissionColorFactor": [1, 1]}),
            format!("{at}.diffuseTransmissionColorFactor"),
        ),
        (
            json!({"diffuseTransmissionFactor": 1, "diffuseTransmissionTexture": {"index": 3}}),
            format!("{at}.diffuseTransmissionTexture.index"),
        ),
        (
            json!({"diffuseTransmissionFactor": 1, "diffuseTransmissionColorTexture": {"index": 0, "texCoord": -1}}),
            format!("{at}.diffuseTransmissionColorTexture.texCoord"),
        ),
    ];
    for (v, field) in cases {
        expect(&dt(v), &[&field]);
    }
}

/// Coordinates beyond what single precision renders (the path tracer's hierarchy panicked at
/// 10²⁵) are refused once the node transforms are applied, naming the node and what lies out.
#[test]
fn coordinates_beyond_single_precision() {
    expect(
        &mutate(|d| d["nodes"][1]["scale"] = json!([1e12, 1, 1])),
        &["nodes[1]", "meshes[0].primitives[0]", "beyond ±1e9 scene units"],
    );
    expect(
        &mutate(|d| d["nodes"][0]["translation"] = json!([2e9, 0, 0])),
        &["nodes[1]", "beyond ±1e9 scene units"],
    );
    expect(&mutate(|d| d["nodes"][3]["translation"] = json!([0, 1, 5e9])), &["cameras[0]", "beyond ±1e9"]);
    expect(
        &mutate(|d| d["nodes"][4]["translation"] = json!([0, -3e9, 0])),
        &["nodes[4]", "lights[0]", "beyond ±1e9"],
    );
    // Large but within: loads.
    let big = mutate(|d| d["nodes"][0]["translation"] = json!([1e8, 0, 0]));
    assert!(scene::load_slice("big.gltf", big.to_string().as_bytes(), Some(&data(""))).is_ok());
}

#[test]
fn bad_extras() {
    expect(
        &mutate(|d| d["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"]["spectrum"] = json!("D42")),
        &["KHR_lights_punctual.lights[0].extras.spectrum", "D42", "D65"],
    );
    expect(
        &mutate(|d| {
            d["extensions"]["KHR_lights_punctual"]["lights"][2]["extras"]["spectrum"]["sampled"]["wavelengths"] =
                json!([380, 550, 550])
        }),
        &["lights[2].extras.spectrum.sampled.wavelengths", "increase strictly"],
    );
    expect(
        &mutate(|d| {
            d["materials"][0]["extras"]["reflectance_palette"][1]["spectrum"] =
                json!({"csv": "bad_value.csv"})
        }),
        &["bad_value.csv", "line 4", "materials[0].extras.reflectance_palette[1].spectrum.csv"],
    );
    expect(
        &mutate(|d| d["materials"][1]["extras"]["reflectence"] = json!("D65")),
        &["materials[1].extras.reflectence", "unknown key"],
    );
    expect(
        &mutate(|d| d["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"]["colour"] = json!(1)),
        &["lights[0].extras.colour", "unknown key"],
    );
    let light0 = |d: &mut Value, v: Value| {
        d["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"]["stands_in_for"] = v
    };
    expect(
        &mutate(|d| light0(d, json!(3))),
        &["lights[0].extras.stands_in_for", "node 3 is not a mesh node"],
    );
    expect(&mutate(|d| light0(d, json!("quad"))), &["lights[0].extras.stands_in_for", "node index"]);
    expect(
        &mutate(|d| {
            light0(d, json!(2));
            d["materials"][1]["emissiveFactor"] = json!([0, 0, 0]);
            d["materials"][1]["extras"].as_object_mut().unwrap().remove("emission");
        }),
        &["lights[0].extras.stands_in_for", "does not emit"],
    );
    // asset.extras carries other tools' metadata (author, license): ignored, but a near-miss of a
    // key we read is still a typo to report.
    let mut d = fixture();
    d["asset"]["extras"] = json!({"author": "someone", "license": "CC-BY-4.0", "title": "t"});
    assert!(scene::load_slice("meta.gltf", d.to_string().as_bytes(), Some(&data(""))).is_ok());
    expect(
        &mutate(|d| d["asset"]["extras"] = json!({"author": "a", "watr": {}})),
        &["asset.extras.watr", "unknown key"],
    );
    expect(
        &mutate(|d| d["extras"]["spectra"]["wavelenghts"] = json!(8)),
        &["root.extras.spectra.wavelenghts", "unknown key"],
    );
    expect(
        &mutate(|d| d["extras"]["spectra"]["range"] = json!([300, 900])),
        &["root.extras.spectra.range", "360–830"],
    );
    expect(
        &mutate(|d| d["extras"]["spectra"]["observer"] = json!("cie2030")),
        &["spectra.observer", "cie2030"],
    );
    expect(&mutate(|d| d["extras"]["spectra"]["wavelengths"] = json!(0)), &["spectra.wavelengths"]);
    // An observer file is a file reference like any other: confined to the scene's folder.
    expect(
        &mutate(|d| d["extras"]["spectra"]["observer"] = json!("/etc/passwd.csv")),
        &["spectra.observer", "absolute path", "inside the scene's folder"],
    );
    expect(
        &mutate(|d| d["extras"]["spectra"]["observer"] = json!("../../Cargo.toml.csv")),
        &["spectra.observer", "'..'"],
    );
    expect(
        &mutate(|d| d["extras"]["spectra"]["observer"] = json!("no_such_camera.csv")),
        &["spectra.observer", "no_such_camera.csv", "cannot read"],
    );
    expect(
        &mutate(|d| d["extras"]["water"] = json!({"type": "I", "depth": 3})),
        &["scenes[0].extras.water", "root.extras"],
    );
    expect(
        &mutate(|d| d["scenes"][0]["extras"]["water"]["sun_direction"] = json!([0, -1, 0])),
        &["water.sun_direction", "horizon"],
    );
    expect(
        &mutate(|d| d["scenes"][0]["extras"]["water"]["sun_direction"] = json!([0, 0, 0])),
        &["water.sun_direction", "[0, 0, 0]"],
    );
    // Huge but valid: straight up the diagonal, not "below the horizon" (issue 29).
    let doc = mutate(|d| d["scenes"][0]["extras"]["water"]["sun_direction"] = json!([1e38, 1e38, 1e38]));
    let s = scene::load_slice("huge.gltf", doc.to_string().as_bytes(), Some(&data("")));
    assert!(s.is_ok(), "{:?}", s.err());
    expect(
        &mutate(|d| {
            d["scenes"][0]["extras"]["water"].as_object_mut().unwrap().remove("type").map(|_| ()).unwrap()
        }),
        &["water.type", "required"],
    );
    expect(&mutate(|d| d["scenes"][0]["extras"]["water"]["sky"] = json!(-0.1)), &["water.sky", "0 ..= 10"]);
    expect(&mutate(|d| d["scenes"][0]["extras"]["water"]["sky"] = json!(10.5)), &["water.sky", "10.5"]);
    expect(&mutate(|d| d["scenes"][0]["extras"]["water"]["sky"] = json!("blue")), &["water.sky", "number"]);
    expect(
        &mutate(|d| d["materials"][1]["extras"]["reflectance"] = json!("D65")),
        &["materials[1].extras.reflectance", "[0, 1]"],
    );
    expect(
        &mutate(|d| d["materials"][1]["extras"]["reflectance_palette"] = json!([])),
        &["materials[1].extras", "not both"],
    );
    expect(
        &mutate(|d| d["materials"][0]["extras"]["reflectance_palette"][1]["rgb8"] = json!([178, 47, 58])),
        &["reflectance_palette[1].rgb8", "already used"],
    );
    expect(
        &mutate(|d| d["materials"][0]["extras"]["reflectance_palette"][0]["rgb8"] = json!([1, 2, 300])),
        &["rgb8", "0–255"],
    );
    expect(
        &mutate(|d| {
            d["materials"][1]["extras"] =
                json!({"reflectance_palette": [{"rgb8": [1, 2, 3], "spectrum": {"colorchecker": 1}}]})
        }),
        &["materials[1].extras.reflectance_palette", "baseColorTexture"],
    );
    expect(
        &mutate(|d| d["materials"][1]["emissiveFactor"] = json!([0, 0, 0])),
        &["materials[1].extras.emission", "zero"],
    );
    // Unlit drops the factor: said so, not that the file's factor is zero (found by a sweep).
    expect(
        &mutate(|d| d["materials"][1]["extensions"] = json!({"KHR_materials_unlit": {}})),
        &["materials[1].extras.emission", "unlit"],
    );
    expect(
        &mutate(|d| d["materials"][1]["extras"] = json!(["not", "an", "object"])),
        &["materials[1].extras", "object"],
    );
}

/// Random damage to a valid GLB and to the JSON of a valid glTF: every outcome must be `Ok` or
/// `Err`; a panic fails the test. Seeded, so a failure reproduces.
#[test]
fn random_damage_never_panics() {
    let seed = std::env::var("SCENE_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(0x5ce7e);
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    // More rounds for a local soak: SCENE_FUZZ_ROUNDS=100000 SCENE_FUZZ_SEED=7 cargo test -p scene --test errors
    let rounds: usize = std::env::var("SCENE_FUZZ_ROUNDS").ok().and_then(|s| s.parse().ok()).unwrap_or(400);
    let glb = std::fs::read(data("textured.glb")).unwrap();
    for _ in 0..rounds {
        let mut b = glb.clone();
        for _ in 0..rng.random_range(1..6) {
            let i = rng.random_range(0..b.len());
            b[i] = rng.random();
        }
        if rng.random_bool(0.2) {
            b.truncate(rng.random_range(0..b.len()));
        }
        let _ = scene::load_slice("fuzz.glb", &b, None);
    }
    // Replace numbers in the JSON with hostile ones: wrong indices, zero, negative, huge.
    let doc = fixture();
    let mut paths = Vec::new();
    collect_numbers(&doc, &mut Vec::new(), &mut paths);
    let hostile = [
        json!(0),
        json!(-1),
        json!(1),
        json!(3),
        json!(7),
        json!(255),
        json!(65537),
        json!(4294967295u64),
        json!(1e30),
        json!(0.5),
    ];
    for _ in 0..rounds {
        let mut d = doc.clone();
        for _ in 0..rng.random_range(1..3) {
            let p = &paths[rng.random_range(0..paths.len())];
            *pointer_mut(&mut d, p) = hostile[rng.random_range(0..hostile.len())].clone();
        }
        let _ = scene::load_slice("fuzz.gltf", d.to_string().as_bytes(), Some(&data("")));
    }
    // Replace any value (not only numbers) with one of another shape, or delete an object key.
    let mut paths = Vec::new();
    collect_values(&doc, &mut Vec::new(), &mut paths);
    let shapes = [
        json!(null),
        json!("x"),
        json!({}),
        json!([]),
        json!([0]),
        json!(true),
        json!("D65"),
        json!({"csv": "quad.bin"}),
    ];
    for _ in 0..rounds {
        let mut d = doc.clone();
        for _ in 0..rng.random_range(1..3) {
            let p = &paths[rng.random_range(0..paths.len())];
            let (last, parent) = p.split_last().unwrap();
            match pointer_mut(&mut d, parent) {
                Value::Object(m) if rng.random_bool(0.5) => {
                    m.remove(last);
                }
                Value::Object(m) => {
                    m.insert(last.clone(), shapes[rng.random_range(0..shapes.len())].clone());
                }
                Value::Array(a) => {
                    if let Some(x) = last.parse::<usize>().ok().and_then(|i| a.get_mut(i)) {
                        *x = shapes[rng.random_range(0..shapes.len())].clone();
                    }
                }
                _ => {}
            }
        }
        let _ = scene::load_slice("fuzz.gltf", d.to_string().as_bytes(), Some(&data("")));
    }
}

fn collect_values(v: &Value, at: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    if !at.is_empty() {
        out.push(at.clone());
    }
    match v {
        Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| {
            at.push(i.to_string());
            collect_values(x, at, out);
            at.pop();
        }),
        Value::Object(m) => m.iter().for_each(|(k, x)| {
            at.push(k.clone());
            collect_values(x, at, out);
            at.pop();
        }),
        _ => {}
    }
}

fn collect_numbers(v: &Value, at: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Number(_) => out.push(at.clone()),
        Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| {
            at.push(i.to_string());
            collect_numbers(x, at, out);
            at.pop();
        }),
        Value::Object(m) => m.iter().for_each(|(k, x)| {
            at.push(k.clone());
            collect_numbers(x, at, out);
            at.pop();
        }),
        _ => {}
    }
}

/// The value at `path`; paths come from the undamaged document, so an earlier edit in the same
/// round may have removed part of one: then the deepest surviving value is returned.
fn pointer_mut<'a>(v: &'a mut Value, path: &[String]) -> &'a mut Value {
    let mut cur = v;
    for k in path {
        let has = match &*cur {
            Value::Array(a) => k.parse::<usize>().is_ok_and(|i| i < a.len()),
            Value::Object(m) => m.contains_key(k),
            _ => false,
        };
        if !has {
            break;
        }
        cur = match cur {
            Value::Array(a) => &mut a[k.parse::<usize>().unwrap()],
            Value::Object(m) => m.get_mut(k).unwrap(),
            _ => unreachable!(),
        };
    }
    cur
}

/// `extras.medium` (an RGB medium, issue 18): loads; each bad field is named with its place;
/// water and a medium together are refused.
#[test]
fn rgb_medium_extras() {
    let with_medium = |m: Value| {
        mutate(|d| {
            d["scenes"][0]["extras"].as_object_mut().unwrap().remove("water");
            d["scenes"][0]["extras"]["medium"] = m;
        })
    };
    let doc = with_medium(json!({"absorption": [0.1, 0.2, 0.3], "scattering": [0.5, 0.5, 0.5], "g": 0.4}));
    let s = scene::load_slice("ok.gltf", doc.to_string().as_bytes(), Some(&data(""))).unwrap();
    let m = s.medium.expect("the medium");
    assert_eq!((m.absorption, m.scattering, m.g), ([0.1, 0.2, 0.3], [0.5; 3], 0.4));
    expect(
        &with_medium(json!({"absorption": [0.1, -0.2, 0.3]})),
        &["scenes[0].extras.medium.absorption", "green"],
    );
    expect(
        &with_medium(json!({"absorption": [0.1, 0.2, 0.3], "g": 1.0})),
        &["scenes[0].extras.medium.g", "−1 and 1"],
    );
    expect(
        &with_medium(
            json!({"attenuation_color": [1, 0.5, 0.5], "attenuation_distance": 2, "albedo": [0.8, 0.8, 0.8]}),
        ),
        &["scenes[0].extras.medium.albedo", "extinction is zero"],
    );
    expect(&with_medium(json!("fog")), &["scenes[0].extras.medium", "object"]);
    expect(
        &mutate(|d| d["extras"]["medium"] = json!({"absorption": [1, 1, 1]})),
        &["extras.medium", "not both"],
    );
}
