//! Writes a prepared scene in a form `tools/mitsuba_compare.py` turns into a Mitsuba 3 scene:
//! one binary PLY per mesh (world space, as loaded), textures as binary PPM, and
//! `scene.json` with the camera, materials, lights and every spectrum sampled at 1 nm.
//!
//! Spectra are written in tracer units (see [`crate::lights`]) together with `k_white`
//! (∫ȳ·W dλ over the range), so the consumer can convert to its own radiance normalisation.
//! Anything without a faithful Mitsuba equivalent (spot lights' glTF cone, palettes, emissive
//! textures, alpha modes, single-sided materials, vertex colours, samplers) is listed under `"unsupported"` rather than silently approximated.
//! The BSDF beyond the base colour — metallic-roughness, thin films, transmission, clear coats
//! (with a coat's dimming of the emission under it), `KHR_materials_specular`,
//! `KHR_materials_sheen`, `KHR_materials_anisotropy`, `KHR_materials_diffuse_transmission` — is
//! not listed: the comparison renders ours with `--lambert`, which
//! drops all of it too, so both sides see the same Lambertian scene.

use crate::error::{Result, TruthError};
use crate::world::World;
use glam::{Vec3, Vec4};
use scene::{LightKind, Scene, SpectralReflectance};
use serde_json::{Value, json};
use std::fs;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

fn io(path: &Path) -> impl Fn(std::io::Error) -> TruthError + '_ {
    move |source| TruthError::Io { path: path.display().to_string(), source }
}

fn sampled(world: &World, f: impl Fn(f32) -> f32) -> Value {
    let r = world.units.range;
    let (lo, hi) = (r.min.ceil() as i32, r.max.floor() as i32);
    let l: Vec<i32> = (lo..=hi).collect();
    json!({ "wavelengths": l, "values": l.iter().map(|&x| f(x as f32)).collect::<Vec<f32>>() })
}

fn ply(m: &scene::Mesh) -> Vec<u8> {
    let has_n = m.normals.len() == m.positions.len();
    let has_uv = m.uvs.len() == m.positions.len();
    let mut h = format!("ply\nformat binary_little_endian 1.0\nelement vertex {}\n", m.positions.len());
    h += "property float x\nproperty float y\nproperty float z\n";
    if has_n {
        h += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if has_uv {
        h += "property float u\nproperty float v\n";
    }
    h += &format!(
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.indices.len() / 3
    );
    let mut b = h.into_bytes();
    for i in 0..m.positions.len() {
        let mut put = |v: &[f32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
        put(&m.positions[i].to_array());
        if has_n {
            put(&m.normals[i].to_array());
        }
        if has_uv {
            put(&m.uvs[i].to_array());
        }
    }
    for t in m.indices.chunks_exact(3) {
        b.push(3);
        t.iter().for_each(|&i| b.extend_from_slice(&(i as i32).to_le_bytes()));
    }
    b
}

/// A scene with large textures or meshes takes seconds to write; Ctrl-C meanwhile ends it here,
/// where dropping the temporary directory removes it, rather than by the forced exit, which
/// left the directory behind.
fn stop_if_cancelled(cancel: &AtomicBool) -> Result<()> {
    if cancel.load(Ordering::Relaxed) { Err(TruthError::Cancelled) } else { Ok(()) }
}

fn ppm(t: &scene::Texture) -> Vec<u8> {
    let mut b = format!("P6\n{} {}\n255\n", t.width, t.height).into_bytes();
    for px in t.rgba8.chunks_exact(4) {
        b.extend_from_slice(&px[..3]);
    }
    b
}

/// Exports `world` for a `width`×`height` render into the directory `dir`, which must not
/// exist yet (it is written under a temporary name and renamed, so it is never half there).
/// Returns the list of unsupported features it left out. Stops with [`TruthError::Cancelled`]
/// between files once `cancel` is set (the binary passes [`color::cancel::token`]), removing
/// what it wrote.
pub fn export(
    world: &World,
    width: u32,
    height: u32,
    dir: &Path,
    cancel: &AtomicBool,
) -> Result<Vec<String>> {
    if dir.exists() {
        return Err(TruthError::Io {
            path: dir.display().to_string(),
            source: std::io::Error::new(std::io::ErrorKind::AlreadyExists, "already exists; remove it first"),
        });
    }
    // An unpredictable private directory (mkdtemp) is filled, then renamed into place: a
    // predictable name made with `create_dir_all` would follow a symlink planted there.
    let tmp = color::outfile::temp_dir_next_to(dir).map_err(io(dir))?;
    let unsupported = write_all(world, width, height, tmp.path(), cancel)?;
    stop_if_cancelled(cancel)?;
    color::outfile::persist_dir(tmp, dir).map_err(io(dir))?;
    Ok(unsupported)
}

fn write_all(world: &World, width: u32, height: u32, dir: &Path, cancel: &AtomicBool) -> Result<Vec<String>> {
    let scene: &Scene = &world.scene;
    let mut unsupported = Vec::new();

    let cam = &scene.camera;
    let origin = cam.transform.transform_point3(Vec3::ZERO);
    let forward = cam.transform.transform_vector3(-Vec3::Z).normalize();
    let up = cam.transform.transform_vector3(Vec3::Y).normalize();

    for (i, t) in scene.textures.iter().enumerate() {
        stop_if_cancelled(cancel)?;
        let p = dir.join(format!("texture_{i}.ppm"));
        fs::write(&p, ppm(t)).map_err(io(&p))?;
    }

    let materials: Vec<Value> = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let reflectance = match (&m.spectral, m.base_color_texture) {
                (Some(SpectralReflectance::Uniform(s)), _) => {
                    json!({ "spectrum": sampled(world, |l| s.eval(l as f64) as f32) })
                }
                (Some(SpectralReflectance::Palette(_)), _) => {
                    unsupported.push(format!("material {i} '{}': palette reflectance (exported as its RGB texture)", m.name));
                    json!({ "texture": format!("texture_{}.ppm", m.base_color_texture.map_or(0, |t| t.index)) })
                }
                (None, Some(t)) => {
                    if m.base_color.truncate() != Vec3::ONE {
                        unsupported.push(format!("material {i} '{}': base colour factor × texture", m.name));
                    }
                    json!({ "texture": format!("texture_{}.ppm", t.index) })
                }
                (None, None) => json!({ "rgb": m.base_color.truncate().clamp(Vec3::ZERO, Vec3::ONE).to_array() }),
            };
            if m.normal_texture.is_some() {
                unsupported.push(format!("material {i} '{}': normal map", m.name));
            }
            if m.emissive_texture.is_some() {
                unsupported.push(format!("material {i} '{}': emissive texture", m.name));
            }
            if m.unlit {
                unsupported.push(format!("material {i} '{}': unlit (KHR_materials_unlit)", m.name));
            }
            if m.alpha_mode != scene::AlphaMode::Opaque {
                unsupported.push(format!("material {i} '{}': alpha mode {:?}", m.name, m.alpha_mode));
            }
            if !m.double_sided {
                unsupported.push(format!("material {i} '{}': single-sided (back faces invisible)", m.name));
            }
            let refs = [m.base_color_texture, m.metallic_roughness_texture, m.normal_texture, m.emissive_texture];
            for r in refs.iter().flatten() {
                if r.tex_coord != 0 || r.transform.is_some() {
                    unsupported.push(format!("material {i} '{}': TEXCOORD_{} / texture transform", m.name, r.tex_coord));
                }
                if scene.textures.get(r.index).is_some_and(|t| t.sampler != scene::Sampler::default()) {
                    unsupported.push(format!("material {i} '{}': texture sampler {}", m.name, r.index));
                }
            }
            let emission = (m.emissive != Vec3::ZERO).then(|| match &world.emission_spectra[i] {
                Some(s) => sampled(world, |l| s.eval(l)),
                None => sampled(world, |l| world.units.rgb(m.emissive, world.upsampler, Vec4::splat(l)).x),
            });
            json!({
                "name": m.name, "reflectance": reflectance, "metallic": m.metallic,
                "roughness": m.roughness, "emission": emission,
            })
        })
        .collect();

    let mut meshes = Vec::new();
    for (i, m) in scene.meshes.iter().enumerate() {
        if m.indices.is_empty() {
            continue;
        }
        if !m.colors.is_empty() {
            unsupported.push(format!("mesh {i}: vertex colours (COLOR_0)"));
        }
        stop_if_cancelled(cancel)?;
        let p = dir.join(format!("mesh_{i}.ply"));
        fs::write(&p, ply(m)).map_err(io(&p))?;
        meshes.push(json!({ "ply": format!("mesh_{i}.ply"), "material": m.material }));
    }

    let mut lights = Vec::new();
    let mut delta = world.delta_lights.iter();
    for l in scene.lights.iter().filter(|l| l.stands_in_for.is_none()) {
        let Some(d) = delta.next() else { break };
        let spectrum = sampled(world, |x| d.spectrum.eval(x));
        match l.kind {
            LightKind::Point { position, range } => {
                if range.is_some() {
                    unsupported.push(format!("light '{}': range window", l.name));
                }
                lights
                    .push(json!({ "type": "point", "position": position.to_array(), "intensity": spectrum }));
            }
            LightKind::Directional { direction } => {
                lights.push(json!({ "type": "directional", "direction": direction.to_array(), "irradiance": spectrum }));
            }
            LightKind::Spot { .. } => {
                unsupported.push(format!("light '{}': spot cone (glTF falloff)", l.name))
            }
        }
    }

    if cam.ortho.is_some() {
        unsupported.push("orthographic camera (exported with the perspective fov)".into());
    }
    if world.surface.is_some() {
        unsupported.push("water surface (Fresnel, TIR) and the sky seen through it".into());
    }
    if world.medium.is_some() {
        // Mitsuba's sensors would also start their rays on `near_clip`, skipping the medium in
        // front of it, where ours attenuate from the eye (truth::camera).
        unsupported.push("participating medium (not exported)".into());
    }
    if let Some(env) = &world.env_map {
        unsupported.push(format!("environment map ({})", env.env.source));
    }
    let white = &world.units;
    let doc = json!({
        "source": scene.source,
        "width": width, "height": height,
        "range": [white.range.min, white.range.max],
        "k_white": white.k_white,
        "camera": {
            "origin": origin.to_array(), "target": (origin + forward).to_array(), "up": up.to_array(),
            "fov_y_deg": cam.yfov.to_degrees(),
            // Surfaces nearer than this along the view axis are clipped, as `RayCamera` does.
            "near_clip": cam.clip_near().max(0.0) * cam.transform.transform_vector3(-Vec3::Z).length(),
            "far_clip": cam.zfar * cam.transform.transform_vector3(-Vec3::Z).length(),
        },
        "materials": materials, "meshes": meshes, "lights": lights,
        "medium": world.medium.is_some(),
        "unsupported": unsupported,
    });
    let p = dir.join("scene.json");
    fs::write(&p, serde_json::to_string_pretty(&doc).expect("JSON values serialise")).map_err(io(&p))?;
    Ok(unsupported)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{quad, scene_with};
    use crate::upsample::GreyOnly;
    use color::WavelengthRange;

    #[test]
    fn writes_ply_json_and_refuses_existing_dirs() {
        let lamp = scene::Material { emissive: Vec3::splat(2.0), ..Default::default() };
        let s = scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 1.0, 0)], vec![lamp], vec![]);
        let d65 = color::illuminant::by_name("D65").unwrap();
        let w = World::new(&s, &GreyOnly, &d65, WavelengthRange::VISIBLE, None).unwrap();
        let base = std::env::temp_dir().join(format!("truth-export-{}", std::process::id()));
        let _ = fs::remove_dir_all(&base);
        fs::create_dir_all(&base).unwrap();
        let dir = base.join("out");
        // Cancelled, it stops and leaves nothing, not even its temporary directory.
        assert!(matches!(export(&w, 16, 8, &dir, &AtomicBool::new(true)), Err(TruthError::Cancelled)));
        assert_eq!(fs::read_dir(&base).unwrap().count(), 0);
        let go = AtomicBool::new(false);
        assert!(export(&w, 16, 8, &dir, &go).unwrap().is_empty());
        let doc: Value = serde_json::from_str(&fs::read_to_string(dir.join("scene.json")).unwrap()).unwrap();
        assert_eq!(doc["meshes"][0]["ply"], "mesh_0.ply");
        assert!((doc["camera"]["near_clip"].as_f64().unwrap() - 0.01).abs() < 1e-9);
        let e = &doc["materials"][0]["emission"]["values"];
        // Grey RGB 2 under a D65 white is 2·D65: 2 × 100 at 560 nm.
        assert!((e[560 - 380].as_f64().unwrap() - 200.0).abs() < 1.0, "{}", e[180]);
        let ply = fs::read(dir.join("mesh_0.ply")).unwrap();
        assert!(ply.starts_with(b"ply\nformat binary_little_endian"));
        assert!(export(&w, 16, 8, &dir, &go).is_err());
        fs::remove_dir_all(&base).unwrap();
    }
}
