//! `underwater`: a patch of sea floor seen by a diver 1.2 m above it — a sand texture, a
//! ColorChecker board (the chart at 4× size with its measured palette), a striped textured crate
//! and two measured-reflectance blocks — lit by the D65 sun refracted through a flat surface.
//! The scene carries `WaterSettings` (Jerlov IB, camera 10 m deep, metres as scene units, a
//! clear maritime sky of [`SKY`] × the sun, hence a second, stand-in light), so
//! `spectra render underwater` draws it under water without flags; `--water`/`--depth` override.
//!
//! Sizes are real-world metres so the water's per-metre coefficients act at the right scale:
//! the chart is 2–3 m from the camera, the sand runs out to 30 m where it fades into the water.

use glam::{Vec3, Vec4};

use super::colorchecker::{chart_texture, patch_texels};
use super::{empty, light_emission, measured_material, patch, patch_index, shapes};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::water::WaterMedium;
use crate::{
    Camera, Light, LightKind, Material, PaletteEntry, Scene, SpectralReflectance, Texture, TextureRef,
    WaterSettings,
};

/// Default water of the scene.
pub const WATER_TYPE: &str = "IB";
/// Default camera depth, metres.
pub const DEPTH: f32 = 10.0;
/// Direction towards the sun above the water (≈ 34° from the zenith).
pub const SUN: Vec3 = Vec3::new(0.45, 0.8, 0.3);
/// Diffuse sky irradiance just below the surface, as a multiple of the sun's there
/// (`WaterSettings::sky`). From the clear-sky model SPCTRAL2 (Bird & Riordan 1986, via pvlib)
/// for this sun (34° from the zenith) over the sea with aerosol optical depth 0.1 at 500 nm (a
/// typical clear maritime value): sky/sun = 0.160 above the surface in luminance, 0.153 below
/// it (the uniform sky keeps T̄ = 0.932 of its light through the surface, this sun T = 0.977);
/// 0.106 for aerosol optical depth 0.05 and 0.252 for 0.2. `python3 tools/sky_ratio.py`
/// prints the table.
pub const SKY: f32 = 0.15;

/// Sand: a 64² sRGB texture of grains around a pale sandy colour, from an integer hash so it is
/// identical on every machine.
fn sand_texture() -> Texture {
    let n = 64u32;
    let mut rgba = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let mut h = x.wrapping_mul(0x9E37_79B1) ^ y.wrapping_mul(0x85EB_CA77);
            h ^= h >> 15;
            h = h.wrapping_mul(0x2C1B_3C6D);
            h ^= h >> 12;
            // Ripples across x plus ±8 % grain noise.
            let ripple = 0.06 * ((y as f32) * 0.7).sin();
            let k = 1.0 + ripple + ((h & 0xFF) as f32 / 255.0 - 0.5) * 0.16;
            for c in [196.0f32, 180.0, 140.0] {
                rgba.push((c * k).clamp(0.0, 255.0) as u8);
            }
            rgba.push(255);
        }
    }
    Texture { sampler: Default::default(), name: "sand".into(), width: n, height: n, rgba8: rgba, srgb: true }
}

/// Orange and white stripes, like a marker buoy.
fn stripe_texture() -> Texture {
    let n = 32u32;
    let mut rgba = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for _x in 0..n {
            let px: [u8; 4] = if (y / 4) % 2 == 0 { [235, 110, 20, 255] } else { [235, 235, 230, 255] };
            rgba.extend_from_slice(&px);
        }
    }
    Texture {
        sampler: Default::default(),
        name: "stripes".into(),
        width: n,
        height: n,
        rgba8: rgba,
        srgb: true,
    }
}

fn textured(name: &str, index: usize) -> Material {
    Material {
        name: name.into(),
        base_color: Vec4::ONE,
        base_color_texture: Some(TextureRef { transform: None, index, tex_coord: 0 }),
        roughness: 1.0,
        ..Material::default()
    }
}

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let camera = Camera::look_at(Vec3::new(0.0, 1.2, 3.2), Vec3::new(0.0, 0.5, 0.0), Vec3::Y, 0.9);
    let mut s = empty(ctx, camera);
    s.camera.aspect = Some(1.5);
    s.camera.zfar = 200.0;

    // Textures: 0 sand, 1 chart, 2 stripes.
    s.textures.push(sand_texture());
    s.textures.push(chart_texture());
    s.textures.push(stripe_texture());

    // Materials: 0 sand, 1 chart, 2 crate, 3 grey rock, 4 orange block.
    s.materials.push(textured("sand", 0));
    let texels = patch_texels();
    let palette = (0..24).map(|i| PaletteEntry { rgb8: texels[i], spectrum: patch(i) }).collect();
    let mut chart = textured("ColorChecker Classic", 1);
    chart.spectral = Some(SpectralReflectance::Palette(palette));
    s.materials.push(chart);
    s.materials.push(textured("striped crate", 2));
    s.materials.push(measured_material("rock (neutral 5)", &patch(patch_index("neutral 5 (.70 D)"))));
    s.materials.push(measured_material("coral (orange)", &patch(patch_index("orange"))));

    // Sea floor, 60 × 60 m, facing up.
    let half = 30.0;
    s.meshes.push(shapes::quad(
        Vec3::new(-half, 0.0, half),
        Vec3::X * 2.0 * half,
        Vec3::NEG_Z * 2.0 * half,
        0,
    ));
    // The chart, 1.44 × 0.96 m, leaning back 15° towards the camera, bottom edge 0.1 m up.
    let (cw, ch) = (0.36 * 4.0, 0.24 * 4.0);
    let tilt = 15f32.to_radians();
    let up = Vec3::new(0.0, tilt.cos(), -tilt.sin()) * ch;
    s.meshes.push(shapes::quad(Vec3::new(-cw * 0.5, 0.1, 0.0), Vec3::X * cw, up, 1));
    s.meshes.push(shapes::cuboid(Vec3::new(-1.6, 0.0, 0.6), Vec3::new(0.6, 0.6, 0.6), 0.5, 2));
    s.meshes.push(shapes::cuboid(Vec3::new(1.5, 0.0, 0.3), Vec3::new(0.8, 0.45, 0.7), -0.4, 3));
    s.meshes.push(shapes::cuboid(Vec3::new(0.9, 0.0, -2.5), Vec3::new(0.5, 1.0, 0.5), 0.2, 4));

    let settings = WaterSettings {
        water_type: WATER_TYPE.into(),
        depth: DEPTH,
        sun_direction: SUN.normalize(),
        scale: 1.0,
        sky: SKY,
    };
    let medium = WaterMedium::from_settings(&settings).map_err(|e| ctx.invalid("water", e.to_string()))?;
    // The sun as it reaches the sea floor: refracted at the surface. Irradiance π lux on a plane
    // facing it, so a perfect white facing the sun would have radiance 1 before attenuation.
    let direction = -medium.sun_dir_underwater();
    let d65 = color::illuminant::by_name("D65").map_err(|e| ctx.invalid("light", e.to_string()))?;
    s.lights.push(Light {
        name: "sun (refracted)".into(),
        kind: LightKind::Directional { direction },
        emission: light_emission(ctx, "light", &d65, std::f32::consts::PI)?,
        stands_in_for: None,
    });
    s.water = Some(settings);
    crate::sky::sync(&mut s).map_err(|m| ctx.invalid("water.sky", m))?;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn underwater_scene_has_water_and_a_refracted_sun() {
        let s = crate::builtin("underwater").unwrap();
        let w = s.water.as_ref().unwrap();
        assert_eq!((w.water_type.as_str(), w.depth, w.scale), (WATER_TYPE, DEPTH, 1.0));
        let LightKind::Directional { direction } = s.lights[0].kind else { panic!("directional sun") };
        // Snell: sin θw = sin θa / 1.34, with θa the sun's zenith angle above water.
        let sun = SUN.normalize();
        let sin_air = (1.0 - sun.y * sun.y).sqrt();
        let sin_water = (1.0 - direction.y * direction.y).sqrt();
        assert!((sin_water - sin_air / 1.34).abs() < 1e-5, "{sin_water} vs {}", sin_air / 1.34);
        assert!(direction.y < 0.0);
        // Everything stands on or above the sea floor, under the camera's water surface.
        let (lo, _) = crate::framing::bounds(&s.meshes).unwrap();
        assert!(lo.y.abs() < 1e-6, "{lo}");
        assert_eq!(s.textures.len(), 3);
    }
}
