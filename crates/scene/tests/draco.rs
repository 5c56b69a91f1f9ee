//! `KHR_draco_mesh_compression` against the uncompressed originals: the Khronos sample models
//! ship each model twice, as plain glTF and as glTF-Draco (made by the Draco tools from the
//! plain file), so the geometry decoded from the Draco bitstream must be the plain geometry up
//! to the quantization the encoder applied. Draco reorders vertices and triangles (and may
//! rotate a triangle's corners, keeping its winding), so the triangles are matched as sets.
//! Fixtures: `tests/data/draco/<Model>/{glTF,glTF-Draco}` (textures stripped; LICENSE.md each).

use std::path::PathBuf;

use glam::{Vec2, Vec3};

/// The fixtures, or `$DRACO_MODELS` when set (see [`every_khronos_draco_model`]).
fn root() -> PathBuf {
    std::env::var_os("DRACO_MODELS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/draco"))
}

fn data(model: &str, variant: &str) -> PathBuf {
    let dir = root().join(model).join(variant);
    std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "gltf"))
        .unwrap()
}

#[derive(Clone, Copy, Debug)]
struct Corner {
    p: Vec3,
    n: Vec3,
    uv: Option<Vec2>,
}

struct Tri {
    material: usize,
    c: [Corner; 3],
    centroid: Vec3,
}

fn triangles(s: &scene::Scene) -> Vec<Tri> {
    let mut out = Vec::new();
    for m in &s.meshes {
        for t in m.indices.chunks_exact(3) {
            let c = std::array::from_fn(|k| {
                let i = t[k] as usize;
                Corner { p: m.positions[i], n: m.normals[i], uv: m.uvs.get(i).copied() }
            });
            let centroid = (c[0].p + c[1].p + c[2].p) / 3.0;
            out.push(Tri { material: m.material, c, centroid });
        }
    }
    out
}

/// The largest differences found between matched triangles, each as a fraction of its scale.
#[derive(Debug, Default)]
struct Worst {
    /// Corner distance over the scene's largest extent.
    position: f32,
    /// Angle between normals, degrees.
    normal_deg: f32,
    /// UV distance over the UVs' largest extent.
    uv: f32,
}

/// Matches each decoded triangle with a plain one (same material, same winding, corners
/// within `tol` of the extent) and returns the worst differences; panics naming the first
/// triangle without a match.
fn compare(model: &str, opts: &scene::LoadOptions, tol: f32) -> Worst {
    let plain = scene::load_with(data(model, "glTF"), opts).unwrap();
    let draco = scene::load_with(data(model, "glTF-Draco"), opts).unwrap_or_else(|e| panic!("{model}: {e}"));
    let (a, b) = (triangles(&plain), triangles(&draco));
    assert_eq!(a.len(), b.len(), "{model}: triangle count");
    assert!(!a.is_empty());
    let (lo, hi) = a
        .iter()
        .flat_map(|t| t.c.map(|c| c.p))
        .fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(p), h.max(p)));
    let extent = (hi - lo).max_element();
    let uvs: Vec<Vec2> = a.iter().flat_map(|t| t.c.iter().filter_map(|c| c.uv)).collect();
    let uv_extent = uvs.iter().fold(Vec2::ZERO, |m, u| m.max(u.abs())).max_element().max(1.0);
    let eps = tol * extent;
    // Plain triangles sorted by centroid x, so that candidates are a window of the list.
    let mut order: Vec<usize> = (0..a.len()).collect();
    order.sort_by(|&i, &j| a[i].centroid.x.total_cmp(&a[j].centroid.x));
    let xs: Vec<f32> = order.iter().map(|&i| a[i].centroid.x).collect();
    let mut used = vec![false; a.len()];
    let mut worst = Worst::default();
    for (ti, t) in b.iter().enumerate() {
        let from = xs.partition_point(|&x| x < t.centroid.x - eps);
        let mut best: Option<(f32, usize, usize)> = None;
        for &i in order[from..].iter().take_while(|&&i| a[i].centroid.x <= t.centroid.x + eps) {
            if used[i] || a[i].material != t.material {
                continue;
            }
            for rot in 0..3 {
                let d = (0..3).map(|k| a[i].c[(k + rot) % 3].p.distance(t.c[k].p)).fold(0.0, f32::max);
                // A triangle smaller than the quantization step may collapse to a point, where
                // every rotation fits: its normals tell the corners apart.
                let turn: f32 =
                    (0..3).map(|k| a[i].c[(k + rot) % 3].n.dot(t.c[k].n).clamp(-1.0, 1.0).acos()).sum();
                let cost = d / eps + turn / std::f32::consts::PI;
                if d <= eps && best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, i, rot));
                }
            }
        }
        let Some((_, i, rot)) = best else {
            panic!("{model}: decoded triangle {ti} {:?} has no plain triangle within {eps}", t.c.map(|c| c.p))
        };
        used[i] = true;
        let d = (0..3).map(|k| a[i].c[(k + rot) % 3].p.distance(t.c[k].p)).fold(0.0, f32::max);
        worst.position = worst.position.max(d / extent);
        for k in 0..3 {
            let (p, q) = (a[i].c[(k + rot) % 3], t.c[k]);
            let ang = p.n.dot(q.n).clamp(-1.0, 1.0).acos().to_degrees();
            worst.normal_deg = worst.normal_deg.max(ang);
            match (p.uv, q.uv) {
                (Some(u), Some(v)) => worst.uv = worst.uv.max(u.distance(v) / uv_extent),
                (None, None) => {}
                _ => panic!("{model}: texture coordinates in one file only"),
            }
        }
    }
    eprintln!("{model} {opts:?}: {} triangles, worst {worst:?}", a.len());
    worst
}

/// What the Draco tools' default quantization allows: positions on a grid of 2¹¹ steps over the
/// model's extent (the coarsest default, `draco_encoder -qp 11`; at most half a step per axis,
/// √3/2 of a step apart), normals on an 8-bit octahedral grid (a step of about 1.4°), texture
/// coordinates 10 bits.
const POSITION_TOL: f32 = 1.0 / 2048.0;
const NORMAL_TOL_DEG: f32 = 2.0;
const UV_TOL: f32 = 1.0 / 1024.0;

fn check(model: &str, opts: &scene::LoadOptions) {
    let w = compare(model, opts, POSITION_TOL);
    assert!(w.normal_deg <= NORMAL_TOL_DEG, "{model}: normals differ by {}°", w.normal_deg);
    assert!(w.uv <= UV_TOL, "{model}: texture coordinates differ by {} of their extent", w.uv);
}

#[test]
fn draco_models_decode_to_their_uncompressed_originals() {
    for model in ["Box", "Avocado", "CesiumMilkTruck", "MorphPrimitivesTest", "RiggedSimple", "RiggedFigure"]
    {
        check(model, &scene::LoadOptions::default());
    }
}

/// Every model in `$DRACO_MODELS` that has both variants: the Khronos sample models'
/// fifteen glTF-Draco ones, extracted with `tools/draco_models.py OUT` (textures stripped).
/// `DRACO_MODELS=OUT cargo test --release -p scene --test draco -- --ignored --nocapture`
#[test]
#[ignore = "needs the Khronos sample models (tools/draco_models.py)"]
fn every_khronos_draco_model() {
    assert!(std::env::var_os("DRACO_MODELS").is_some(), "set DRACO_MODELS");
    let mut models: Vec<String> = std::fs::read_dir(root())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|m| root().join(m).join("glTF-Draco").is_dir() && root().join(m).join("glTF").is_dir())
        .collect();
    models.sort();
    assert!(!models.is_empty());
    for m in &models {
        check(m, &scene::LoadOptions::default());
    }
}

/// Joints and weights are Draco generic attributes (UNSIGNED_SHORT joints, quantized float
/// weights): a skinned model posed mid-animation moves by them.
#[test]
fn draco_skins_pose_as_the_originals() {
    for (model, time) in [("RiggedSimple", 1.25), ("RiggedFigure", 0.6)] {
        let opts = scene::LoadOptions { time: Some(time), ..Default::default() };
        check(model, &opts);
    }
}

/// Morph targets stay uncompressed accessors in the original vertex order, which the Draco
/// tools keep for such primitives: the file's weight (0.5, `meshes[0].weights`) must move the
/// decoded vertices where it moves the plain ones, and the move must be there to see.
#[test]
fn draco_morph_targets_apply_to_the_decoded_vertices() {
    check("MorphPrimitivesTest", &scene::LoadOptions::default());
    let file = data("MorphPrimitivesTest", "glTF-Draco");
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    assert_eq!(json["meshes"][0]["weights"], serde_json::json!([0.5]));
    json["meshes"][0]["weights"] = serde_json::json!([0.0]);
    let unweighted = tempfile::tempdir().unwrap();
    let copy = unweighted.path().join("unweighted.gltf");
    std::fs::write(&copy, json.to_string()).unwrap();
    std::fs::copy(
        file.with_file_name("MorphPrimitivesTest.bin"),
        unweighted.path().join("MorphPrimitivesTest.bin"),
    )
    .unwrap();
    let (a, b) = (scene::load(&file).unwrap(), scene::load(&copy).unwrap());
    let moved = a
        .meshes
        .iter()
        .zip(&b.meshes)
        .flat_map(|(m, n)| m.positions.iter().zip(&n.positions))
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max);
    assert!(moved > 0.05, "the weight moves no vertex ({moved})");
}

/// A copy of the Box's Draco file in a temporary folder, its JSON changed by `edit` and its
/// bitstream by `bits`.
fn edited_box(
    edit: impl FnOnce(&mut serde_json::Value),
    bits: impl FnOnce(&mut Vec<u8>),
) -> Result<scene::Scene, String> {
    let file = data("Box", "glTF-Draco");
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    let mut bin = std::fs::read(file.with_file_name("Box.bin")).unwrap();
    edit(&mut json);
    bits(&mut bin);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("Box.gltf"), json.to_string()).unwrap();
    std::fs::write(dir.path().join("Box.bin"), bin).unwrap();
    scene::load(dir.path().join("Box.gltf")).map_err(|e| e.to_string())
}

fn refused(r: Result<scene::Scene, String>, parts: &[&str]) {
    let Err(e) = r else { panic!("loaded; expected an error naming {parts:?}") };
    assert!(!e.contains('\n'), "one line: {e}");
    for p in parts {
        assert!(e.contains(p), "{p:?} not in: {e}");
    }
}

#[test]
fn bad_draco_data_is_named() {
    let ext = "meshes[0].primitives[0].extensions.KHR_draco_mesh_compression";
    // The bitstream cut short.
    refused(
        edited_box(|j| j["bufferViews"][0]["byteLength"] = serde_json::json!(60), |_| {}),
        &[ext, "bufferViews[0]", "cannot be decoded"],
    );
    // An attribute id the bitstream does not have.
    refused(
        edited_box(
            |j| {
                j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] =
                    serde_json::json!(7)
            },
            |_| {},
        ),
        &[&format!("{ext}.attributes.NORMAL"), "7 names no attribute"],
    );
    // An attribute the primitive does not have.
    refused(
        edited_box(
            |j| {
                j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["TEXCOORD_0"] =
                    serde_json::json!(0)
            },
            |_| {},
        ),
        &[&format!("{ext}.attributes.TEXCOORD_0"), "does not have"],
    );
    // Accessors that disagree with the decoded data.
    let normal = |j: &serde_json::Value| {
        j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"].as_u64().unwrap() as usize
    };
    refused(
        edited_box(
            |j| {
                let a = normal(j);
                j["accessors"][a]["count"] = serde_json::json!(23)
            },
            |_| {},
        ),
        &[".count", "23, but its Draco attribute decodes 24 vertices"],
    );
    refused(
        edited_box(
            |j| {
                let a = normal(j);
                j["accessors"][a]["type"] = serde_json::json!("VEC2")
            },
            |_| {},
        ),
        &[".type", "has 2 components, but its Draco attribute has 3"],
    );
    refused(
        edited_box(
            |j| {
                let i = j["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
                j["accessors"][i]["count"] = serde_json::json!(30)
            },
            |_| {},
        ),
        &["30, but the Draco data decodes 12 triangles (36 indices)"],
    );
    // Strips: Draco holds triangles (4) or points (0).
    refused(
        edited_box(|j| j["meshes"][0]["primitives"][0]["mode"] = serde_json::json!(5), |_| {}),
        &["meshes[0].primitives[0].mode"],
    );
}

/// Damaged bitstreams (every byte in turn set to each of a few values, and cut at every
/// length) decode or fail with an error; none panics or hangs. The fuzz target's glTF corpus
/// goes much further (crates/fuzz).
#[test]
fn damaged_draco_bitstreams_fail_cleanly() {
    let file = data("Box", "glTF-Draco");
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    let view = &json["bufferViews"][0];
    let (off, len) =
        (view["byteOffset"].as_u64().unwrap_or(0) as usize, view["byteLength"].as_u64().unwrap() as usize);
    let (mut ok, mut err) = (0, 0);
    for i in off..off + len {
        for v in [0u8, 1, 0x7f, 0x80, 0xff] {
            let r = edited_box(|_| {}, |b| b[i] = v);
            if r.is_ok() { ok += 1 } else { err += 1 }
        }
    }
    for cut in 0..len {
        let r = edited_box(|j| j["bufferViews"][0]["byteLength"] = serde_json::json!(cut), |_| {});
        assert!(r.is_err(), "cut at {cut} of {len}");
    }
    eprintln!("{ok} damaged bitstreams decoded, {err} refused");
    assert!(err > 0);
}
