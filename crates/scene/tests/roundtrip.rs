//! Built-in scenes written as glTF and loaded back must be the same scene: a test of the exporter
//! and, on larger inputs than the fixtures, of the loader.

use color::Spectrum;
use glam::{Vec2, Vec4};
use scene::{
    AlphaMode, Filter, LightKind, Sampler, Scene, SpectralReflectance, TextureRef, TextureTransform, Wrap,
    builtin, emission::spectrum_luminance,
};

fn same_shape(a: &Spectrum, b: &Spectrum) {
    // The loader rescales spectra to the light's luminance: compare at 10 nm, relative.
    let (ya, yb) = (spectrum_luminance(a), spectrum_luminance(b));
    assert!((ya - yb).abs() <= 1e-5 * ya.abs().max(1e-12), "luminance {ya} vs {yb}");
    for l in (380..=780).step_by(10) {
        let (x, y) = (a.eval(l as f64), b.eval(l as f64));
        assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-9), "at {l} nm: {x} vs {y}");
    }
}

fn compare(a: &Scene, b: &Scene) {
    assert_eq!(a.meshes.len(), b.meshes.len());
    for (m, n) in a.meshes.iter().zip(&b.meshes) {
        assert_eq!(m.positions, n.positions);
        assert_eq!(m.uvs, n.uvs);
        assert_eq!(m.uvs1, n.uvs1);
        assert_eq!(m.colors, n.colors);
        assert_eq!(m.indices, n.indices);
        assert_eq!(m.material, n.material);
        for (p, q) in m.normals.iter().zip(&n.normals) {
            assert!(p.abs_diff_eq(*q, 1e-6));
        }
    }
    assert_eq!(a.materials.len(), b.materials.len());
    for (m, n) in a.materials.iter().zip(&b.materials) {
        assert_eq!(m.name, n.name);
        assert!(m.base_color.abs_diff_eq(n.base_color, 1e-7));
        assert!(
            m.emissive.abs_diff_eq(n.emissive, 1e-5 * m.emissive.max_element().max(1.0)),
            "{} vs {}",
            m.emissive,
            n.emissive
        );
        assert_eq!((m.metallic, m.roughness), (n.metallic, n.roughness));
        assert_eq!(m.base_color_texture, n.base_color_texture);
        assert_eq!(m.metallic_roughness_texture, n.metallic_roughness_texture);
        assert_eq!(m.normal_texture, n.normal_texture);
        assert_eq!(m.emissive_texture, n.emissive_texture);
        assert_eq!((m.occlusion_texture, m.occlusion_strength), (n.occlusion_texture, n.occlusion_strength));
        assert_eq!((m.alpha_mode, m.double_sided), (n.alpha_mode, n.double_sided), "material {}", m.name);
        match (&m.spectral, &n.spectral) {
            (Some(SpectralReflectance::Uniform(s)), Some(SpectralReflectance::Uniform(t))) => {
                assert_eq!(s, t)
            }
            (Some(SpectralReflectance::Palette(p)), Some(SpectralReflectance::Palette(q))) => {
                assert_eq!(p.len(), q.len());
                for (e, f) in p.iter().zip(q) {
                    assert_eq!((e.rgb8, &e.spectrum), (f.rgb8, &f.spectrum));
                }
            }
            (None, None) => {}
            other => panic!("material {}: {other:?}", m.name),
        }
        match (&m.emission_spectrum, &n.emission_spectrum) {
            (Some(s), Some(t)) => same_shape(s, t),
            (None, None) => {}
            _ => panic!("emission spectrum lost"),
        }
    }
    assert_eq!(a.textures.len(), b.textures.len());
    for (t, u) in a.textures.iter().zip(&b.textures) {
        assert_eq!((t.width, t.height, t.srgb, t.sampler), (u.width, u.height, u.srgb, u.sampler));
        assert_eq!(t.rgba8, u.rgba8);
    }
    assert_eq!(a.lights.len(), b.lights.len());
    for (l, k) in a.lights.iter().zip(&b.lights) {
        assert_eq!(l.name, k.name);
        assert_eq!(l.stands_in_for, k.stands_in_for);
        same_shape(l.emission.spectrum.as_ref().unwrap(), k.emission.spectrum.as_ref().unwrap());
        match (&l.kind, &k.kind) {
            (
                LightKind::Spot { position: p, direction: d, .. },
                LightKind::Spot { position: q, direction: e, .. },
            ) => {
                assert!(p.abs_diff_eq(*q, 1e-5) && d.abs_diff_eq(*e, 1e-5), "{p} {d} vs {q} {e}");
            }
            (LightKind::Directional { direction: d }, LightKind::Directional { direction: e }) => {
                assert!(d.abs_diff_eq(*e, 1e-5))
            }
            (LightKind::Point { position: p, .. }, LightKind::Point { position: q, .. }) => {
                assert!(p.abs_diff_eq(*q, 1e-5))
            }
            other => panic!("light kind changed: {other:?}"),
        }
    }
    assert!(a.camera.transform.abs_diff_eq(b.camera.transform, 1e-5));
    assert_eq!(
        (a.camera.yfov, a.camera.aspect, a.camera.ortho),
        (b.camera.yfov, b.camera.aspect, b.camera.ortho)
    );
    assert_eq!(a.spectral.white, b.spectral.white);
    // Water, including the sky (whose stand-in light is not written but made again on load).
    let w = |s: &Scene| s.water.as_ref().map(|w| (w.water_type.clone(), w.depth, w.scale, w.sky));
    assert_eq!(w(a), w(b));
    assert_eq!(a.medium, b.medium);
}

#[test]
fn an_rgb_medium_survives_a_round_trip() {
    let dir = std::env::temp_dir().join(format!("spectra-scene-medium-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut a = builtin("cornell").unwrap();
    a.medium = Some(
        scene::medium::RgbMedium::from_json_str(
            r#"{"absorption": [0.1, 0.25, 0.3], "scattering": [0.7, 0.6, 0.5], "g": -0.3, "scale": 0.01,
                "upsampling": "unbounded"}"#,
        )
        .unwrap(),
    );
    let path = dir.join("fog.gltf");
    scene::write_gltf(&a, &path).unwrap();
    let b = scene::load(&path).unwrap();
    assert!(b.medium.is_some());
    compare(&a, &b);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn builtins_survive_a_gltf_round_trip() {
    let dir = std::env::temp_dir().join(format!("spectra-scene-roundtrip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in scene::BUILTIN_NAMES {
        let a = builtin(name).unwrap();
        let path = dir.join(format!("{name}.gltf"));
        scene::write_gltf(&a, &path).unwrap();
        let b = scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        compare(&a, &b);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// What the built-ins do not use, set on one: vertex colours, a second UV set, alpha modes,
/// single-sided materials, samplers, texture transforms, an occlusion map, an orthographic camera.
#[test]
fn gltf_material_and_vertex_features_survive_a_round_trip() {
    let mut a = builtin("colorchecker").unwrap();
    for (i, m) in a.meshes.iter_mut().enumerate() {
        let n = m.positions.len();
        m.colors = (0..n).map(|k| Vec4::new(k as f32 / n as f32, 0.5, 1.0, 0.25 * (i % 4) as f32)).collect();
        m.uvs1 = (0..n).map(|k| Vec2::new(k as f32, -(k as f32))).collect();
    }
    assert!(!a.textures.is_empty());
    a.textures[0].sampler = Sampler {
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::MirroredRepeat,
        mag: Filter::Nearest,
        min: Filter::Linear,
        mipmaps: false,
    };
    let t = a.materials.iter().find_map(|m| m.base_color_texture).unwrap();
    let modes = [AlphaMode::Mask { cutoff: 0.3 }, AlphaMode::Blend, AlphaMode::Opaque];
    for (i, m) in a.materials.iter_mut().enumerate() {
        m.alpha_mode = modes[i % 3];
        m.double_sided = i % 2 == 0;
    }
    let transform =
        TextureTransform { offset: Vec2::new(0.5, -1.0), rotation: 0.25, scale: Vec2::new(2.0, 0.5) };
    // Occlusion is linear data: its own texture (textures are sRGB or not as a whole).
    let mut ao = a.textures[t.index].clone();
    (ao.srgb, ao.name) = (false, "occlusion".into());
    a.textures.push(ao);
    let index = a.textures.len() - 1;
    assert_eq!(index, 1, "the loader numbers textures in order of first use");
    a.materials[0].occlusion_texture = Some(TextureRef { index, tex_coord: 1, transform: Some(transform) });
    a.materials[0].occlusion_strength = 0.75;
    a.camera.ortho = Some((3.0, 2.0));
    a.camera.aspect = Some(1.5);
    let dir = std::env::temp_dir().join(format!("spectra-scene-features-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("features.gltf");
    scene::write_gltf(&a, &path).unwrap();
    let b = scene::load(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    // The exported file is ordinary glTF for other tools: an orthographic camera has no yfov.
    let mut b2 = b.clone();
    b2.camera.yfov = a.camera.yfov;
    compare(&a, &b2);
    assert!(b.warnings.is_empty(), "{:?}", b.warnings);
}
