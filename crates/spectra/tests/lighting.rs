//! Lighting real assets end to end, on the real binary: scenes lit only by an emissive surface or
//! only by an environment must agree between the real-time renderer and the path tracer (direct
//! lighting, block means against the tracer's noise), and a scene without lights is never black.

use std::path::{Path, PathBuf};
use std::process::Command;

fn spectra(args: &[&str]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra");
    assert!(out.status.success(), "spectra {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectra-lighting-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn p(d: &Path, f: &str) -> String {
    d.join(f).display().to_string()
}

/// Mean block ΔE2000 of `test` against `reference` (8×8 blocks).
fn block_de(reference: &str, test: &str) -> f64 {
    let out = spectra(&["diff", reference, test, "--block", "8", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("diff --json");
    v["delta_e2000"]["mean"].as_f64().unwrap_or_else(|| panic!("no delta_e2000.mean in {v}"))
}

/// The built-in Cornell box without the point light that stands in for its lamp: lit only by the
/// emissive ceiling quad, in real time as in the path tracer.
#[test]
fn an_emissive_ceiling_lights_the_box_in_real_time_as_in_truth() {
    let d = dir("lamp");
    let mut s = scene::builtin("cornell").unwrap();
    s.lights.clear();
    let file = d.join("lamp.gltf");
    scene::write_gltf(&s, &file).unwrap();
    let f = file.display().to_string();
    let (truth, rt) = (p(&d, "truth.exr"), p(&d, "rt.exr"));
    spectra(&["truth", &f, "--direct-only", "--spp", "256", "--size", "96x96", "--out", &truth]);
    let out = spectra(&["render", &f, "--size", "96x96", "--out", &rt]);
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(note.contains("emissive polygon light"), "{note}");
    assert!(!note.contains("default environment"), "a lamp lights the box: {note}");
    let de = block_de(&truth, &rt);
    assert!(de <= 3.0, "block-mean ΔE2000 {de:.2} > 3");
    eprintln!("emissive ceiling, spectral vs truth (direct): block-mean ΔE2000 {de:.3}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A UV sphere of `rings` × `segments` quads (two triangles each, one at the poles).
fn sphere(centre: glam::Vec3, r: f32, rings: u32, segments: u32, material: usize) -> scene::Mesh {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let ph = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
            let n = glam::Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin());
            positions.push(centre + r * n);
            normals.push(n);
        }
    }
    let mut indices = Vec::new();
    let row = segments + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b) = (i * row + j, (i + 1) * row + j);
            if i > 0 {
                indices.extend([a, a + 1, b]);
            }
            if i + 1 < rings {
                indices.extend([a + 1, b + 1, b]);
            }
        }
    }
    let n = positions.len();
    scene::Mesh {
        positions,
        normals,
        uvs: vec![glam::Vec2::ZERO; n],
        uvs1: vec![],
        tangents: vec![],
        colors: vec![],
        indices,
        material,
    }
}

/// The Cornell box lit only by a glowing sphere of 1 472 triangles (issue 34): far more than the
/// renderer's 32 lights, so they are clustered into area lights that keep all of the emitted
/// power; real time agrees with the path tracer as for the box's own ceiling lamp (block-mean
/// ΔE2000 1.89 when written). Before, the 32 brightest triangles were kept and 96.7 % of the
/// power left out: 20.2.
#[test]
fn a_glowing_sphere_of_many_triangles_lights_the_box_as_in_truth() {
    let d = dir("sphere");
    let mut s = scene::builtin("cornell").unwrap();
    s.lights.clear();
    let lamp = s.meshes.iter().position(|m| s.materials[m.material].emissive.max_element() > 0.0).unwrap();
    let (lo, hi) = s.bounds().unwrap();
    let c = 0.5 * (lo + hi) + glam::Vec3::new(0.0, 0.25 * (hi.y - lo.y), 0.0);
    let material = s.meshes[lamp].material;
    s.materials[material].emissive *= 0.15;
    s.meshes[lamp] = sphere(c, 0.12 * (hi.y - lo.y), 24, 32, material);
    let file = d.join("sphere.gltf");
    scene::write_gltf(&s, &file).unwrap();
    let f = file.display().to_string();
    let (truth, rt) = (p(&d, "truth.exr"), p(&d, "rt.exr"));
    spectra(&["truth", &f, "--direct-only", "--spp", "256", "--size", "96x96", "--out", &truth]);
    let out = spectra(&["render", &f, "--size", "96x96", "--out", &rt]);
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("32 emissive area lights: 1472 emitting polygons clustered, all of their power"),
        "{note}"
    );
    let de = block_de(&truth, &rt);
    eprintln!(
        "glowing sphere (1472 triangles → 32 lights), spectral vs truth (direct): block-mean ΔE2000 {de:.3}"
    );
    assert!(de <= 3.0, "block-mean ΔE2000 {de:.2} > 3");
    if std::env::var_os("SPECTRA_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// Spheres on a ColorChecker floor (the built-in glass scene made opaque, its spot light off)
/// under rooitou_park, whose low sun gives 65 % of its light: real time lights with the sun as a
/// shadowed directional light and the rest of the map (issue 34 item 1), so the spheres' shadows
/// fall where the path tracer's do. Against `--no-env-sun` (the whole map, unshadowed) and the
/// truth (direct lighting).
#[test]
fn an_hdr_sun_casts_shadows_in_real_time_as_in_truth() {
    let d = dir("sun");
    let mut s = scene::builtin("glass").unwrap();
    s.lights.clear();
    for m in &mut s.materials {
        m.transmission = None;
    }
    let file = d.join("spheres.gltf");
    scene::write_gltf(&s, &file).unwrap();
    let f = file.display().to_string();
    let hdr = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/environments/rooitou_park.hdr");
    let truth = p(&d, "truth.exr");
    spectra(&[
        "truth",
        &f,
        "--env",
        hdr,
        "--direct-only",
        "--spp",
        "256",
        "--size",
        "96x72",
        "--out",
        &truth,
    ]);
    let mut de = Vec::new();
    for extra in [&[][..], &["--no-env-sun"][..]] {
        let rt = p(&d, &format!("rt{}.exr", extra.len()));
        let mut a = vec!["render", &f, "--env", hdr, "--size", "96x72", "--out", &rt];
        a.extend(extra);
        spectra(&a);
        de.push(block_de(&truth, &rt));
    }
    eprintln!(
        "spheres under rooitou_park, spectral vs truth (direct): block-mean ΔE2000 {:.3} with the sun as a light, {:.3} without",
        de[0], de[1]
    );
    assert!(de[0] < de[1], "the sun as a light did not bring real time closer: {de:?}");
    if std::env::var_os("SPECTRA_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// The ColorChecker without its light: the default environment lights it (with a note), and an
/// HDR environment too; the real-time renderer (rgb and spectral) agrees with the path tracer's
/// direct lighting. A flat chart sees the whole sky, so the real-time renderer's missing
/// environment shadowing does not enter.
#[test]
fn a_chart_without_lights_is_lit_by_the_environment_as_in_truth() {
    let d = dir("env");
    let mut s = scene::builtin("colorchecker").unwrap();
    s.lights.clear();
    let file = d.join("chart.gltf");
    scene::write_gltf(&s, &file).unwrap();
    let f = file.display().to_string();
    let hdr = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/environments/rooitou_park.hdr");
    for env in [None, Some(hdr)] {
        let mut extra: Vec<&str> = vec![];
        if let Some(e) = env {
            extra.extend(["--env", e]);
        }
        let truth = p(&d, "truth.exr");
        let mut a = vec!["truth", &f, "--direct-only", "--spp", "256", "--size", "96x64", "--out", &truth];
        a.extend(&extra);
        let out = spectra(&a);
        let note = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(note.contains("default environment"), env.is_none(), "{note}");
        for mode in ["rgb", "spectral"] {
            let rt = p(&d, &format!("{mode}.exr"));
            let mut a = vec!["render", &f, "--mode", mode, "--size", "96x64", "--out", &rt];
            a.extend(&extra);
            spectra(&a);
            let de = block_de(&truth, &rt);
            eprintln!("chart, environment {env:?}, {mode} vs truth (direct): block-mean ΔE2000 {de:.3}");
            assert!(de <= 1.5, "{mode}, environment {env:?}: block-mean ΔE2000 {de:.2} > 1.5");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Outdoor HDRIs with an unclipped sun reach 10⁴–10⁵ per texel, more than a half float holds
/// once upsampled and prefiltered (issue 29: a uniform sky of 300 made the object NaN, 1000 every
/// pixel). Under a uniform sky of 1000 and a sky of 1 with one 10⁵ sun texel, every mode renders
/// finite images at intensity 1, and with the intensity brought into range the chart (flat:
/// it sees the whole sky, so the missing environment shadowing does not enter) agrees with the
/// path tracer's direct lighting.
#[test]
fn bright_environments_render_finite_and_as_in_truth() {
    let d = dir("bright");
    let mut s = scene::builtin("colorchecker").unwrap();
    s.lights.clear();
    let file = d.join("chart.gltf");
    scene::write_gltf(&s, &file).unwrap();
    let f = file.display().to_string();
    let (w, h) = (64u32, 32u32);
    let sky = |value: f32, sun: Option<(u32, u32, f32)>| {
        let mut data = vec![[value; 3]; (w * h) as usize];
        if let Some((x, y, v)) = sun {
            data[(y * w + x) as usize] = [v; 3];
        }
        compare::image::Image::new(w, h, data).unwrap()
    };
    // The sun 40° up, in front of the chart and to its side.
    let cases =
        [("uniform1000", sky(1000.0, None), "0.001"), ("sun1e5", sky(1.0, Some((28, 9, 1e5))), "0.01")];
    for (name, img, intensity) in cases {
        let env = p(&d, &format!("{name}.exr"));
        compare::io::write_image(&env, &img, Default::default()).unwrap();
        for mode in ["spectral", "rgb", "naive"] {
            let rt = p(&d, &format!("{name}-{mode}-full.exr"));
            spectra(&["render", &f, "--mode", mode, "--env", &env, "--size", "48x32", "--out", &rt]);
            let px = compare::io::read_image(&rt).unwrap();
            let bad = px.data.iter().filter(|p| !p.iter().all(|c| c.is_finite())).count();
            assert_eq!(bad, 0, "{name}, {mode}, intensity 1: {bad} non-finite pixels");
        }
        let truth = p(&d, &format!("{name}-truth.exr"));
        let t = [
            "truth",
            &f,
            "--direct-only",
            "--spp",
            "256",
            "--size",
            "96x64",
            "--env",
            &env,
            "--env-intensity",
            intensity,
            "--out",
            &truth,
        ];
        spectra(&t);
        for mode in ["spectral", "rgb"] {
            let rt = p(&d, &format!("{name}-{mode}.exr"));
            spectra(&[
                "render",
                &f,
                "--mode",
                mode,
                "--env",
                &env,
                "--env-intensity",
                intensity,
                "--size",
                "96x64",
                "--out",
                &rt,
            ]);
            let de = block_de(&truth, &rt);
            eprintln!(
                "chart under {name} × {intensity}, {mode} vs truth (direct): block-mean ΔE2000 {de:.3}"
            );
            assert!(de <= 2.0, "{name}, {mode}: block-mean ΔE2000 {de:.2} > 2");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A missing, corrupt or non-HDR environment is an error naming the file, for both renderers,
/// and no output is written.
#[test]
fn bad_environment_files_are_errors_naming_the_file() {
    let d = dir("bad");
    let corrupt = d.join("corrupt.hdr");
    std::fs::write(&corrupt, b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n\x01\x02").unwrap();
    let png = d.join("sky.png");
    std::fs::write(&png, b"\x89PNG\r\n\x1a\n").unwrap();
    let missing = d.join("missing.hdr");
    for bad in [&corrupt, &png, &missing] {
        let b = bad.display().to_string();
        for cmd in ["render", "truth"] {
            let out_file = d.join(format!("{cmd}.exr"));
            let o = out_file.display().to_string();
            let out = Command::new(env!("CARGO_BIN_EXE_spectra"))
                .args([cmd, "cornell", "--env", &b, "--size", "16x16", "--out", &o])
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{cmd} --env {b} succeeded");
            let name = bad.file_name().unwrap().to_string_lossy();
            assert!(err.contains(name.as_ref()), "{cmd} --env {b}: {err}");
            assert!(!err.contains("panicked"), "{err}");
            assert!(!out_file.exists(), "{cmd} wrote {o} despite the error");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A horizontal square of side 2·`half` at height `y`, facing `up` (+Y) or down.
fn square(centre: glam::Vec3, half_x: f32, half_z: f32, up: bool, material: usize) -> scene::Mesh {
    let (x, z) = (glam::Vec3::X * half_x, glam::Vec3::Z * half_z);
    let positions = vec![centre - x - z, centre + x - z, centre + x + z, centre - x + z];
    let n = if up { glam::Vec3::Y } else { -glam::Vec3::Y };
    // Counter-clockwise seen from the side the normal points to.
    let indices = if up { vec![0, 2, 1, 0, 3, 2] } else { vec![0, 1, 2, 0, 2, 3] };
    scene::Mesh {
        positions,
        normals: vec![n; 4],
        uvs: vec![glam::Vec2::ZERO; 4],
        uvs1: vec![],
        tangents: vec![],
        colors: vec![],
        indices,
        material,
    }
}

/// Writes `s` to NAME.gltf in `d` and renders it at 96×64 without an environment, in the path
/// tracer (direct lighting, 256 spp) and in real time: the two EXR files.
fn truth_and_render(d: &Path, s: &scene::Scene, name: &str) -> (String, String) {
    let file = d.join(format!("{name}.gltf"));
    scene::write_gltf(s, &file).unwrap();
    let f = file.display().to_string();
    let (truth, rt) = (p(d, &format!("{name}-truth.exr")), p(d, &format!("{name}-rt.exr")));
    let size = ["--size", "96x64", "--env", "none"];
    spectra(&[&["truth", &f, "--direct-only", "--spp", "256", "--out", &truth][..], &size].concat());
    spectra(&[&["render", &f, "--out", &rt][..], &size].concat());
    (truth, rt)
}

/// Mean luminance (Rec. 709 Y of linear sRGB) of `test` and `reference` over the pixels where
/// the reference is at least half as bright as its 98th percentile: the highlight.
fn highlight_luminance(reference: &str, test: &str) -> (f64, f64, usize) {
    let y = |p: [f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
    let r = compare::io::read_image(reference).unwrap();
    let t = compare::io::read_image(test).unwrap();
    let (w, h) = r.size();
    let ys: Vec<f64> =
        (0..h).flat_map(|j| (0..w).map(move |i| (i, j))).map(|(i, j)| y(r.get(i, j))).collect();
    let mut sorted = ys.clone();
    sorted.sort_by(f64::total_cmp);
    let threshold = 0.5 * sorted[(0.98 * (sorted.len() - 1) as f64) as usize];
    let (mut sr, mut st, mut n) = (0.0, 0.0, 0usize);
    for j in 0..h {
        for i in 0..w {
            if ys[(j * w + i) as usize] >= threshold {
                sr += ys[(j * w + i) as usize];
                st += y(t.get(i, j));
                n += 1;
            }
        }
    }
    (st / n as f64, sr / n as f64, n)
}

/// LTC (issue 34 item 3): a rough GGX plane under a rectangular light (1.2 × 0.6, 1 above the
/// plane), the highlight's mean luminance in real time against the path tracer's (direct
/// lighting), over roughness, material and view angle (the highlight seen at about 41° and 66°
/// from the normal). Within 3 %, except a rough metal (0.75) seen at grazing angles, where the
/// transformed cosine cannot follow a lobe cut by the horizon (+5.9 % when written; the
/// representative-point specular it replaced gave 10–85 % of the truth's highlight here).
#[test]
fn a_rough_plane_under_a_rectangular_light_has_the_truths_highlight() {
    let d = dir("ltc");
    let cameras = [
        ("41°", glam::Vec3::new(0.0, 2.0, 0.6), glam::Vec3::new(0.0, 0.0, -1.1)),
        ("66°", glam::Vec3::new(0.0, 0.8, 2.0), glam::Vec3::new(0.0, 0.0, -0.2)),
    ];
    let materials = [(1.0f32, 0.9f32, 0.3f32), (1.0, 0.9, 0.5), (1.0, 0.9, 0.75), (0.0, 0.2, 0.4)];
    let mut failures = Vec::new();
    for (view, eye, target) in cameras {
        let camera = scene::Camera::look_at(eye, target, glam::Vec3::Y, 40f32.to_radians());
        for (k, &(metallic, base, roughness)) in materials.iter().enumerate() {
            let mut s = scene::Scene::empty("ltc test", camera);
            s.materials.push(scene::Material {
                name: "plane".into(),
                base_color: glam::Vec4::new(base, base, base, 1.0),
                metallic,
                roughness,
                ..Default::default()
            });
            s.materials.push(scene::Material {
                name: "light".into(),
                base_color: glam::Vec4::new(0.0, 0.0, 0.0, 1.0),
                emissive: glam::Vec3::splat(3.0),
                ..Default::default()
            });
            s.meshes.push(square(glam::Vec3::ZERO, 3.0, 3.0, true, 0));
            s.meshes.push(square(glam::Vec3::new(0.0, 1.0, -2.0), 0.6, 0.3, false, 1));
            let (truth, rt) = truth_and_render(&d, &s, &format!("plane-{}-{k}", &view[..2]));
            let (ours, theirs, n) = highlight_luminance(&truth, &rt);
            let ratio = ours / theirs;
            eprintln!(
                "view {view}, metallic {metallic} base {base} roughness {roughness}: highlight ({n} px) real time {ours:.4} / truth {theirs:.4} = {ratio:.4}"
            );
            let bound = if view == "66°" && roughness > 0.7 { 0.07 } else { 0.03 };
            if (ratio - 1.0).abs() > bound {
                failures.push(format!(
                    "view {view}, roughness {roughness}, metallic {metallic}: ratio {ratio:.4}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
    if std::env::var_os("SPECTRA_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// A clear coat (`KHR_materials_clearcoat`) under the same rectangular light, in each renderer
/// against itself: a mirror-white metal of the coat's roughness (the coat's own lobe, F = 1)
/// beside a black metal (no diffuse, F0 = 0) under a coat of that roughness. Over the metal's
/// highlight the coated plane must be w = F(|v·n|) of it, pixel by pixel — the coat's weighting
/// — in real time (the coat's lobe by the polygon lights' LTC, about its own normal) as in the
/// path tracer, whatever each one's error on the lobe itself (the LTC's at grazing views,
/// which the test above bounds). The black base's own grazing Fresnel adds a little (+2–3 %).
#[test]
fn a_coat_under_a_rectangular_light_weighs_its_lobe_by_its_fresnel_term() {
    let d = dir("ltc-coat");
    let y = |p: [f32; 3]| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
    for (view, eye, target) in [
        ("41°", glam::Vec3::new(0.0, 2.0, 0.6), glam::Vec3::new(0.0, 0.0, -1.1)),
        ("66°", glam::Vec3::new(0.0, 0.8, 2.0), glam::Vec3::new(0.0, 0.0, -0.2)),
    ] {
        let camera = scene::Camera::look_at(eye, target, glam::Vec3::Y, 40f32.to_radians());
        for roughness in [0.25f32, 0.45] {
            let mut images = Vec::new();
            for coated in [false, true] {
                let mut s = scene::Scene::empty("coat weighting test", camera);
                s.materials.push(scene::Material {
                    name: "plane".into(),
                    base_color: glam::Vec4::splat(if coated { 0.0 } else { 1.0 }),
                    metallic: 1.0,
                    roughness: if coated { 0.9 } else { roughness },
                    clearcoat: coated.then_some(scene::clearcoat::Clearcoat {
                        factor: 1.0,
                        texture: None,
                        roughness,
                        roughness_texture: None,
                        normal_texture: None,
                        normal_scale: 1.0,
                    }),
                    ..Default::default()
                });
                s.materials.push(scene::Material {
                    name: "light".into(),
                    base_color: glam::Vec4::new(0.0, 0.0, 0.0, 1.0),
                    emissive: glam::Vec3::splat(3.0),
                    ..Default::default()
                });
                s.meshes.push(square(glam::Vec3::ZERO, 3.0, 3.0, true, 0));
                s.meshes.push(square(glam::Vec3::new(0.0, 1.0, -2.0), 0.6, 0.3, false, 1));
                let name = format!("w-{}-{roughness}-{coated}", &view[..2]);
                let (truth, rt) = truth_and_render(&d, &s, &name);
                images.push([truth, rt].map(|f| compare::io::read_image(&f).unwrap()));
            }
            let (w, h) = images[0][0].size();
            // The view ray through each pixel's centre (the renderers' perspective camera).
            let proj =
                glam::Mat4::perspective_rh(camera.yfov, w as f32 / h as f32, camera.znear, camera.zfar);
            let inv = (proj * camera.transform.inverse()).inverse();
            let fresnel_w = |i: u32, j: u32| {
                let ndc = glam::Vec2::new(
                    (i as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                    1.0 - (j as f32 + 0.5) / h as f32 * 2.0,
                );
                let dir =
                    (inv.project_point3(ndc.extend(1.0)) - inv.project_point3(ndc.extend(0.5))).normalize();
                f64::from(scene::clearcoat::layer_weight(1.0, dir.y.abs()))
            };
            // The bare lobe's highlight in the truth.
            let lobe: Vec<f64> = (0..h)
                .flat_map(|j| (0..w).map(move |i| (i, j)))
                .map(|(i, j)| y(images[0][0].get(i, j)))
                .collect();
            let mut sorted = lobe.clone();
            sorted.sort_by(f64::total_cmp);
            let threshold = 0.5 * sorted[(0.98 * (sorted.len() - 1) as f64) as usize];
            for (k, who) in ["truth", "real time"].iter().enumerate() {
                let (mut sum, mut n) = (0.0, 0usize);
                for j in 0..h {
                    for i in 0..w {
                        if lobe[(j * w + i) as usize] >= threshold {
                            let bare = y(images[0][k].get(i, j));
                            sum += y(images[1][k].get(i, j)) / bare / fresnel_w(i, j);
                            n += 1;
                        }
                    }
                }
                let ratio = sum / n as f64;
                eprintln!(
                    "view {view}, coat roughness {roughness}, {who}: coated / bare lobe / w over {n} px = {ratio:.4}"
                );
                assert!(n > 100, "{n} highlight pixels");
                assert!((ratio - 1.0).abs() < 0.05, "view {view}, roughness {roughness}, {who}: {ratio:.4}");
            }
        }
    }
    if std::env::var_os("SPECTRA_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// An axis-aligned box standing on y = 0 (outward faces, flat normals).
fn cube(centre: glam::Vec3, half: f32, material: usize) -> scene::Mesh {
    let mut m = scene::Mesh {
        positions: vec![],
        normals: vec![],
        uvs: vec![],
        uvs1: vec![],
        tangents: vec![],
        colors: vec![],
        indices: vec![],
        material,
    };
    let c = centre + glam::Vec3::Y * half;
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = glam::Vec3::ZERO;
            n[axis] = sign;
            let (u, v) = (n.any_orthonormal_vector(), n.cross(n.any_orthonormal_vector()));
            let base = m.positions.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                m.positions.push(c + half * (n + a * u + b * v));
                m.normals.push(n);
                m.uvs.push(glam::Vec2::ZERO);
            }
            // u × v = n: counter-clockwise seen from outside.
            m.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    m
}

/// Soft shadows (issue 34 item 3): a box on a grey floor under a rectangular light, real time
/// (percentage-closer soft shadows from the light's size) against the path tracer (direct
/// lighting), for a small and a large light: block-mean ΔE2000 over the image 0.099 and 0.238
/// when written, where the hard shadows from the light's centroid they replaced gave 0.214 and
/// 0.582 (the bounds fail for those).
#[test]
fn a_box_under_a_rectangular_light_casts_the_truths_penumbra() {
    let d = dir("pcss");
    let camera = scene::Camera::look_at(
        glam::Vec3::new(0.0, 2.2, 1.6),
        glam::Vec3::new(0.0, 0.0, 0.2),
        glam::Vec3::Y,
        45f32.to_radians(),
    );
    for (k, (half, bound)) in [(0.15f32, 0.15), (0.5, 0.4)].into_iter().enumerate() {
        let mut s = scene::Scene::empty("pcss test", camera);
        s.materials.push(scene::Material {
            name: "floor".into(),
            base_color: glam::Vec4::new(0.5, 0.5, 0.5, 1.0),
            metallic: 0.0,
            roughness: 1.0,
            ..Default::default()
        });
        s.materials.push(scene::Material {
            name: "light".into(),
            base_color: glam::Vec4::new(0.0, 0.0, 0.0, 1.0),
            emissive: glam::Vec3::splat(0.6 / (half * half)),
            ..Default::default()
        });
        s.meshes.push(square(glam::Vec3::ZERO, 3.0, 3.0, true, 0));
        s.meshes.push(cube(glam::Vec3::new(0.0, 0.0, 0.0), 0.2, 0));
        s.meshes.push(square(glam::Vec3::new(0.0, 1.2, -0.4), half, half, false, 1));
        let (truth, rt) = truth_and_render(&d, &s, &format!("box{k}"));
        let de = block_de(&truth, &rt);
        eprintln!(
            "box under a light of side {}: real time vs truth (direct) block-mean ΔE2000 {de:.3}",
            2.0 * half
        );
        assert!(de <= bound, "light of side {}: block-mean ΔE2000 {de:.3} > {bound}", 2.0 * half);
    }
    if std::env::var_os("SPECTRA_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// A thin-walled see-through pane (KHR_materials_transmission without a volume) glows where a
/// point light behind it shines through, as in the path tracer: its transmission lobe is the
/// reflection lobe mirrored through the pane (a lamp's shade lit from inside). The highlight's
/// mean luminance, real time over truth (direct lighting), across roughness and tint; without
/// the light from behind the real-time pane is black there.
#[test]
fn a_thin_pane_lit_from_behind_glows_as_in_truth() {
    let d = dir("backlit");
    let camera = scene::Camera::look_at(
        glam::Vec3::new(0.0, 2.2, 1.4),
        glam::Vec3::new(0.0, 0.5, 0.0),
        glam::Vec3::Y,
        45f32.to_radians(),
    );
    let mut failures = Vec::new();
    for (k, &(roughness, tint)) in [(0.3f32, [1.0f32, 1.0, 1.0]), (0.6, [1.0, 0.6, 0.3])].iter().enumerate() {
        let mut s = scene::Scene::empty("backlit pane", camera);
        s.materials.push(scene::Material {
            name: "pane".into(),
            base_color: glam::Vec4::new(tint[0], tint[1], tint[2], 1.0),
            roughness,
            transmission: Some(scene::transmission::Transmission {
                factor: 1.0,
                texture: None,
                volume: None,
                dispersion: 0.0,
            }),
            ..Default::default()
        });
        s.meshes.push(square(glam::Vec3::new(0.0, 0.5, 0.0), 1.5, 1.5, true, 0));
        s.lights.push(scene::Light::point("below", glam::Vec3::new(0.0, 0.1, -0.2), 1.0));
        let (truth, rt) = truth_and_render(&d, &s, &format!("pane-{k}"));
        let rgb = p(&d, &format!("pane-{k}-rgb.exr"));
        let f = p(&d, &format!("pane-{k}.gltf"));
        spectra(&["render", &f, "--mode", "rgb", "--size", "96x64", "--env", "none", "--out", &rgb]);
        for (mode, image) in [("spectral", &rt), ("rgb", &rgb)] {
            let (ours, theirs, n) = highlight_luminance(&truth, image);
            let ratio = ours / theirs;
            let de = block_de(&truth, image);
            eprintln!(
                "backlit pane, {mode}, roughness {roughness}, tint {tint:?}: highlight ({n} px) real time {ours:.4} / truth {theirs:.4} = {ratio:.4}; block ΔE2000 {de:.3}"
            );
            if (ratio - 1.0).abs() > 0.05 || de > 1.0 {
                failures
                    .push(format!("{mode}, roughness {roughness}: ratio {ratio:.4}, block ΔE2000 {de:.3}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
    if std::env::var_os("SPECTRA_KEEP").is_none() {
        let _ = std::fs::remove_dir_all(&d);
    }
}

/// A scene lit below the half-float HDR target's range renders banded or black in real time;
/// `render` says so (it used to write the black image silently), and not for a lit scene.
#[test]
fn a_scene_too_dim_for_the_hdr_target_is_warned_about() {
    let d = dir("dim");
    let mut s = scene::builtin("cornell").unwrap();
    for l in &mut s.lights {
        l.emission.intensity *= 1e-9;
    }
    for m in &mut s.materials {
        m.emissive *= 1e-9;
    }
    let dim = p(&d, "dim.gltf");
    scene::write_gltf(&s, Path::new(&dim)).unwrap();
    for (scene, dim_expected) in [(dim.as_str(), true), ("cornell", false)] {
        let out = spectra(&["render", scene, "--size", "16x12", "--env", "none", "--out", &p(&d, "o.exr")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.contains("half-float"), dim_expected, "{scene}: {err}");
        assert!(!dim_expected || err.contains("--exposure"), "the remedy is named: {err}");
    }
    // The remedy works: the exposure is applied before the half float, so +30 EV renders the
    // dim scene as cornell times 1e-9 · 2^30, without the warning.
    let mean = |args: &[&str], name: &str| {
        let o = p(&d, name);
        let out = spectra(&[args, &["--size", "16x12", "--env", "none", "--out", &o]].concat());
        assert!(out.status.success());
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        let img = compare::io::read_image(Path::new(&o)).unwrap();
        let sum: f64 = img.data.iter().flat_map(|px| px.map(f64::from)).sum();
        (sum / img.data.len() as f64, err)
    };
    let (exposed, err) = mean(&["render", &dim, "--exposure", "30"], "e.exr");
    let (bright, _) = mean(&["render", "cornell"], "c.exr");
    assert!(!err.contains("half-float"), "{err}");
    let want = bright * 1e-9 * 2f64.powi(30);
    assert!((exposed - want).abs() < 2e-3 * want, "mean {exposed} at +30 EV, want {want}");
    let _ = std::fs::remove_dir_all(&d);
}

/// An environment scaled to nothing is named as the reason for the black image (the warning
/// said the scene had no environment and suggested dropping `--env none`), and the HDR floor's
/// warning does not follow it.
#[test]
fn an_environment_scaled_to_zero_is_the_reason_given() {
    let d = dir("env-zero");
    let mut s = scene::builtin("cornell").unwrap();
    s.lights.clear();
    for m in &mut s.materials {
        m.emissive = glam::Vec3::ZERO;
        m.emission_spectrum = None;
    }
    let unlit = p(&d, "unlit.gltf");
    scene::write_gltf(&s, Path::new(&unlit)).unwrap();
    let out = spectra(&[
        "render",
        &unlit,
        "--size",
        "16x12",
        "--env",
        "default",
        "--env-intensity",
        "-0",
        "--out",
        &p(&d, "o.exr"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("scaled to 0 by --env-intensity") && !err.contains("drop --env none"), "{err}");
    assert!(!err.contains("half-float") && !err.contains("× -0"), "{err}");
    // A map black in every texel is named as the reason too (the warning said there was no
    // environment and suggested giving one).
    let black = p(&d, "black.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
    bytes.extend([0u8; 4 * 8]);
    std::fs::write(&black, bytes).unwrap();
    let out = spectra(&["render", &unlit, "--size", "16x12", "--env", &black, "--out", &p(&d, "b.exr")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("black.hdr) is black in every texel") && !err.contains("drop --env none"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The built-in Cornell box (about 1 unit across) 2·10⁴ units from its file's origin (a root
/// node's translation, as a geo-referenced export has it) renders as at the origin: the
/// real-time renderer drew such a scene 89 % black in single precision until the loader moved
/// it back (`Scene::recentre`).
#[test]
fn a_scene_far_from_its_origin_renders_as_at_the_origin() {
    let d = dir("far");
    let s = scene::builtin("cornell").unwrap();
    let near = d.join("near.gltf");
    scene::write_gltf(&s, &near).unwrap();
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&near).unwrap()).unwrap();
    let roots = doc["scenes"][0]["nodes"].clone();
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.push(serde_json::json!({"translation": [1.0e4, -5.0e3, 2.0e4], "children": roots}));
    let root = nodes.len() - 1;
    doc["scenes"][0]["nodes"] = serde_json::json!([root]);
    let far = d.join("far.gltf");
    std::fs::write(&far, doc.to_string()).unwrap();
    let (a, b) = (p(&d, "near.exr"), p(&d, "far.exr"));
    spectra(&["render", near.to_str().unwrap(), "--size", "48x48", "--out", &a]);
    spectra(&["render", far.to_str().unwrap(), "--size", "48x48", "--out", &b]);
    // The file's own f32 positions at 2·10⁴ are 0.002 apart: the box moves by that, no more.
    let de = block_de(&a, &b);
    assert!(de < 0.5, "block-mean ΔE2000 {de:.3} between the box at the origin and 2·10⁴ units out");
    let _ = std::fs::remove_dir_all(&d);
}

/// The Cornell box lit by its emissive ceiling alone (radiance does not depend on the scene's
/// size) scaled by 2⁻²⁰ (a micrometre-sized scene in metres) renders as at its own size in both
/// renderers: the path tracer offset every ray origin by at least 10⁻⁴ units, which put every
/// bounce outside so small a scene (`World::offset_floor`).
#[test]
fn a_tiny_scene_renders_as_at_its_own_size() {
    let d = dir("tiny");
    let mut s = scene::builtin("cornell").unwrap();
    s.lights.clear();
    let unit = d.join("unit.gltf");
    scene::write_gltf(&s, &unit).unwrap();
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&unit).unwrap()).unwrap();
    let roots = doc["scenes"][0]["nodes"].clone();
    let nodes = doc["nodes"].as_array_mut().unwrap();
    let k = (-20f32).exp2();
    nodes.push(serde_json::json!({"scale": [k, k, k], "children": roots}));
    let root = nodes.len() - 1;
    doc["scenes"][0]["nodes"] = serde_json::json!([root]);
    // glTF does not scale a camera's clip planes with its node.
    let persp = &mut doc["cameras"][0]["perspective"];
    for plane in ["znear", "zfar"] {
        persp[plane] = serde_json::json!(persp[plane].as_f64().unwrap() * f64::from(k));
    }
    let tiny = d.join("tiny.gltf");
    std::fs::write(&tiny, doc.to_string()).unwrap();
    let (u, t) = (unit.to_str().unwrap(), tiny.to_str().unwrap());
    for (what, args) in [
        ("truth", vec!["truth", "--spp", "64", "--size", "48x48"]),
        ("render", vec!["render", "--size", "48x48"]),
    ] {
        let (a, b) = (p(&d, &format!("{what}-unit.exr")), p(&d, &format!("{what}-tiny.exr")));
        for (file, out) in [(u, &a), (t, &b)] {
            let mut v = args.clone();
            v.insert(1, file);
            v.extend(["--out", out.as_str()]);
            spectra(&v);
        }
        let de = block_de(&a, &b);
        eprintln!("{what}: block-mean ΔE2000 {de:.3} between the box at its size and at 2^-20");
        assert!(de < 0.5, "{what}: block-mean ΔE2000 {de:.3} between the box at its size and at 2^-20");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// The Cornell box through a camera whose near plane is 10⁻⁴ (far plane 100, the smallest ratio
/// a camera is drawn with) renders as through one with an ordinary near plane: with depth in
/// the usual order its positions rebuilt from depth were millimetres off at the box (6·10⁻⁸ of
/// depth there is 5 mm of distance), and its shadows and occlusion streaked; reversed depth
/// keeps them to 10⁻⁷ of the distance (`render::renderer::projection`).
#[test]
fn a_tiny_near_plane_renders_as_an_ordinary_one() {
    let d = dir("near");
    let mut s = scene::builtin("cornell").unwrap();
    let mut files = vec![];
    for (name, znear) in [("ordinary", 0.1f32), ("tiny", 1e-4)] {
        s.camera.znear = znear;
        s.camera.zfar = 100.0;
        let f = d.join(format!("{name}.gltf"));
        scene::write_gltf(&s, &f).unwrap();
        files.push(f.display().to_string());
    }
    for env in ["none", "default"] {
        let (a, b) = (p(&d, &format!("ordinary-{env}.exr")), p(&d, &format!("tiny-{env}.exr")));
        for (f, out) in [(&files[0], &a), (&files[1], &b)] {
            let out = spectra(&["render", f, "--env", env, "--size", "64x64", "--out", out]);
            assert!(!String::from_utf8_lossy(&out.stderr).contains("clip at"), "the near plane was moved");
        }
        let de = block_de(&a, &b);
        eprintln!("--env {env}: block-mean ΔE2000 {de:.4} between znear 0.1 and 1e-4");
        assert!(de < 0.05, "--env {env}: block-mean ΔE2000 {de:.4} between znear 0.1 and 1e-4");
    }
    let _ = std::fs::remove_dir_all(&d);
}
