//! Loading the hand-written fixtures in `tests/data` (regenerate with `make_fixtures.py`).

use std::path::{Path, PathBuf};

use glam::Vec3;
use scene::{LightKind, SpectralReflectance, emission::spectrum_luminance, load, load_any};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn close(a: Vec3, b: Vec3) -> bool {
    a.abs_diff_eq(b, 1e-5)
}

fn check_textured(s: &scene::Scene) {
    assert_eq!(s.meshes.len(), 2);
    // Quad: scaled ×2 in x, turned 90° about +Y, moved +2 in x: it lies in the plane x = 2
    // facing +X, spanning z ∈ [-2, 2].
    let quad = &s.meshes[0];
    assert!(quad.positions.iter().all(|p| (p.x - 2.0).abs() < 1e-5), "{:?}", quad.positions);
    assert!(
        quad.positions.iter().any(|p| (p.z - 2.0).abs() < 1e-5)
            && quad.positions.iter().any(|p| (p.z + 2.0).abs() < 1e-5)
    );
    assert!(quad.normals.iter().all(|n| close(*n, Vec3::X)));
    // The normal map asked for tangents; the file has none, so MikkTSpace made them: u runs along
    // local +x, which the node turned to world −z.
    assert_eq!(quad.tangents.len(), quad.positions.len());
    for (t, n) in quad.tangents.iter().zip(&quad.normals) {
        assert!(close(t.truncate(), -Vec3::Z), "tangent {t}");
        assert!(t.w.abs() == 1.0 && t.truncate().dot(*n).abs() < 1e-5);
    }
    assert_eq!(quad.indices.len(), 6);
    assert_eq!(quad.material, 0);
    // Triangle without normals: flat normals, +Y after the parent's rotation, no tangents.
    let tri = &s.meshes[1];
    assert_eq!((tri.positions.len(), tri.indices.len()), (3, 3));
    assert!(tri.normals.iter().all(|n| close(*n, Vec3::Y)), "{:?}", tri.normals);
    assert!(tri.tangents.is_empty() && tri.uvs.is_empty());
    let g = (tri.positions[1] - tri.positions[0]).cross(tri.positions[2] - tri.positions[0]).normalize();
    assert!(close(g, Vec3::Y), "winding gives {g}");

    assert_eq!(s.materials.len(), 2);
    let m = &s.materials[0];
    assert_eq!((m.metallic, m.roughness, m.normal_scale), (0.25, 0.5, 0.8));
    assert!(close(m.emissive, Vec3::new(4.0, 2.0, 1.0)), "emissive × strength: {}", m.emissive);
    let base = &s.textures[m.base_color_texture.unwrap().index];
    assert!(base.srgb && (base.width, base.height) == (4, 4));
    assert_eq!(&base.rgba8[..4], &[178, 47, 58, 255]);
    assert_eq!(&base.rgba8[4..8], &[44, 79, 160, 255]);
    let normal = &s.textures[m.normal_texture.unwrap().index];
    assert!(!normal.srgb && (normal.width, normal.height) == (2, 2));
    assert_eq!(&normal.rgba8[..4], &[128, 128, 255, 255]);
    assert!(s.textures[m.emissive_texture.unwrap().index].srgb);
    let Some(SpectralReflectance::Palette(p)) = &m.spectral else { panic!("palette expected") };
    assert_eq!(p.len(), 2);
    assert_eq!(p[0].rgb8, [178, 47, 58]);
    assert_eq!(p[0].spectrum, color::Spectrum::from_table(&color::data::colorchecker::SPECTRA[14]));
    assert!((p[1].spectrum.eval(380.0) - 0.6).abs() < 1e-9 && (p[1].spectrum.eval(780.0) - 0.1).abs() < 1e-9);

    let plain = &s.materials[1];
    let Some(SpectralReflectance::Uniform(r)) = &plain.spectral else { panic!("uniform expected") };
    assert_eq!(*r, color::Spectrum::from_table(&color::data::colorchecker::SPECTRA[19]));
    let y = spectrum_luminance(plain.emission_spectrum.as_ref().unwrap());
    assert!((y - 0.2).abs() < 1e-4, "emission luminance {y} should equal that of emissive 0.2 grey");

    assert!(close(s.camera.position(), Vec3::new(0.0, 1.0, 5.0)));
    assert_eq!(
        (s.camera.yfov, s.camera.znear, s.camera.zfar, s.camera.aspect),
        (0.7, 0.05, 100.0, Some(1.5))
    );

    assert_eq!(s.lights.len(), 3);
    let l = &s.lights[0];
    assert_eq!(l.name, "point");
    assert!(
        matches!(l.kind, LightKind::Point { position, range: None } if close(position, Vec3::new(0.0, 3.0, 0.0)))
    );
    let want = 20.0 * (0.2126 + 0.7152 * 0.9 + 0.0722 * 0.8);
    let got = spectrum_luminance(l.emission.spectrum.as_ref().unwrap());
    assert!((got - want).abs() < 1e-3 * want, "{got} vs {want}");
    let LightKind::Spot { position, direction, inner_cone, outer_cone, range } = s.lights[1].kind else {
        panic!("spot")
    };
    assert!(
        close(position, Vec3::new(1.0, 2.0, 0.0)) && close(direction, -Vec3::Y),
        "{position} {direction}"
    );
    assert_eq!((inner_cone, outer_cone, range), (0.2, 0.6, Some(10.0)));
    assert!(matches!(s.lights[2].kind, LightKind::Directional { direction } if close(direction, -Vec3::Z)));
    assert!(s.lights.iter().all(|l| l.emission.spectrum.is_some() && l.stands_in_for.is_none()));

    assert_eq!(s.spectral.observer.as_deref(), Some("cie1931"));
    assert_eq!(s.spectral.range, Some((380.0, 730.0)));
    assert_eq!(s.spectral.wavelengths, Some(16));
    assert_eq!(s.spectral.white.as_deref(), Some("D65"));
    let w = s.water.as_ref().unwrap();
    assert_eq!((w.water_type.as_str(), w.depth, w.scale, w.sky), ("II", 10.0, 1.0, 0.0));
    assert!(close(w.sun_direction, Vec3::Y));
}

#[test]
fn loads_textured_gltf_with_external_files_and_data_uri() {
    let s = load(data("textured.gltf")).unwrap();
    assert!(s.source.ends_with("textured.gltf"));
    check_textured(&s);
}

#[test]
fn loads_the_same_scene_from_glb() {
    let s = load(data("textured.glb")).unwrap();
    check_textured(&s);
    let g = load(data("textured.gltf")).unwrap();
    for (a, b) in s.textures.iter().zip(&g.textures) {
        assert_eq!(a.rgba8, b.rgba8);
    }
}

#[test]
fn load_any_dispatches_on_extension() {
    assert_eq!(load_any("cornell").unwrap().source, "builtin:cornell");
    assert_eq!(load_any("Cornell").unwrap().source, "builtin:cornell");
    assert!(load_any(data("textured.GLB").to_str().unwrap()).is_err(), "no such file (case differs)");
    assert!(load_any(data("textured.glb").to_str().unwrap()).is_ok());
    let e = load_any("textured").unwrap_err().to_string();
    assert!(e.contains("cornell, colorchecker, metamerism") && e.contains(".gltf"), "{e}");
    let e = load_any("/nonexistent/scene.gltf").unwrap_err().to_string();
    assert!(e.contains("/nonexistent/scene.gltf") && e.contains("cannot read"), "{e}");
}

#[test]
fn stand_in_lights_resolve_to_the_mesh_of_their_node() {
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data("textured.gltf")).unwrap()).unwrap();
    // Node 2 is the triangle, whose material emits; it is the second mesh of the traversal.
    doc["extensions"]["KHR_lights_punctual"]["lights"][1]["extras"]["stands_in_for"] = serde_json::json!(2);
    let s = scene::load_slice("standin.gltf", doc.to_string().as_bytes(), Some(&data(""))).unwrap();
    assert_eq!(s.lights[1].stands_in_for, Some(1));
    assert_eq!(s.lights[0].stands_in_for, None);
}

#[test]
fn default_camera_frames_a_scene_without_one() {
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data("textured.gltf")).unwrap()).unwrap();
    doc["nodes"][3].as_object_mut().unwrap().remove("camera");
    let s = scene::load_slice("nocam.gltf", doc.to_string().as_bytes(), Some(&data(""))).unwrap();
    let (lo, hi) = s.bounds().unwrap();
    let v = s.camera.transform.inverse().transform_point3((lo + hi) * 0.5);
    assert!(v.x.abs() < 1e-4 && v.y.abs() < 1e-4 && v.z < 0.0, "centre at {v} in view space");
}

/// A normal-map scale so large that normalize((n.xy·scale, n.z)) leaves f32 made NaN normals in
/// both renderers (issue 29): refused, naming the field.
#[test]
fn absurd_normal_scales_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["base.png", "normal.png", "quad.bin", "reflectance.csv", "spectrum.csv"] {
        std::fs::copy(data(f), dir.path().join(f)).unwrap();
    }
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("textured.gltf")).unwrap()).unwrap();
    let i =
        doc["materials"].as_array().unwrap().iter().position(|m| m.get("normalTexture").is_some()).unwrap();
    for (scale, ok) in [(2.0, true), (-1000.0, true), (-1e30, false), (1001.0, false)] {
        doc["materials"][i]["normalTexture"]["scale"] = serde_json::json!(scale);
        let p = dir.path().join("t.gltf");
        std::fs::write(&p, serde_json::to_string(&doc).unwrap()).unwrap();
        match load(&p) {
            Ok(_) => assert!(ok, "scale {scale} accepted"),
            Err(e) => {
                assert!(!ok, "scale {scale}: {e}");
                assert!(e.to_string().contains("normalTexture.scale"), "{e}");
            }
        }
    }
}

/// Measured reflectances that end inside the render range are zero there: one warning line says
/// so (a spectrophotometer's 400–700 nm file turned a white tile black at both ends of the default
/// 380–730 nm without a word).
#[test]
fn reflectances_short_of_the_render_range_are_named() {
    let cc = scene::builtin("colorchecker").unwrap();
    // N. Ohta's patches cover 380–780 nm.
    assert_eq!(cc.short_reflectances(380.0, 730.0), None);
    assert_eq!(cc.short_reflectances(400.0, 700.0), None);
    let w = cc.short_reflectances(360.0, 830.0).expect("a warning below 380 nm");
    assert!(
        w.starts_with("24 measured reflectances") && w.contains("380–780 nm") && w.contains("360–830"),
        "{w}"
    );

    let mut s = scene::Scene::empty("test", cc.camera);
    let tile = |spectrum| scene::Material {
        name: "tile".into(),
        spectral: Some(SpectralReflectance::Uniform(spectrum)),
        ..Default::default()
    };
    s.materials.push(tile(color::Spectrum::Constant(0.9)));
    assert_eq!(s.short_reflectances(380.0, 730.0), None, "a constant covers every range");
    s.materials.push(tile(color::Spectrum::piecewise(vec![400.0, 700.0], vec![0.9, 0.9]).unwrap()));
    let w = s.short_reflectances(380.0, 730.0).expect("a warning for 400–700 nm");
    assert!(w.contains("material 'tile' covers 400–700 nm") && w.contains("380–730 nm"), "{w}");
    assert_eq!(s.short_reflectances(400.0, 700.0), None);
}
