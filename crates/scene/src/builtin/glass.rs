//! `glass`: see-through dielectrics (`KHR_materials_transmission`, `_volume`, `_dispersion`,
//! `_ior`), where light is refracted, absorbed and dispersed by wavelength (issue 30).
//!
//! Four spheres on a floor tiled with measured ColorChecker patches (the refraction shows a
//! coloured, structured background, as a textured floor would): clear crown glass (index 1.5),
//! a strongly dispersive flint (1.7, dispersion 1, an Abbe number of 20), a green absorbing glass
//! (attenuation colour (0.3, 0.75, 0.35) at 0.1 units, bottle glass) and a frosted one
//! (roughness 0.3). One D65 spot from above and in front. The volumes' thickness (the real-time
//! renderer's refraction offset) is the sphere's diameter; the path tracer traces the interior.
//!
//! A spot light is a point: no path from it through the glass to the floor can be sampled by a
//! path tracer, so neither renderer draws the caustics under the spheres (the shadow map stops
//! that light too); what the comparison measures is the refracted view of the lit floor and the
//! glass's own reflections.

use glam::{Vec3, Vec4};

use super::{empty, light_emission, measured_material, patch, patch_index, shapes};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::transmission::{Transmission, Volume};
use crate::{Camera, Light, LightKind, Material, Scene};

/// The floor's tiles, by ColorChecker name, row after row (a 4 × 4 repeating pattern).
const TILES: [&str; 8] = [
    "neutral 8 (.23 D)",
    "red",
    "neutral 5 (.70 D)",
    "blue",
    "yellow",
    "neutral 3.5 (1.05 D)",
    "green",
    "cyan",
];

/// Sphere radius, scene units.
pub const RADIUS: f32 = 0.12;

fn glass(name: &str, ior: f32, roughness: f32, color: [f32; 3], distance: f32, dispersion: f32) -> Material {
    Material {
        name: name.into(),
        base_color: Vec4::ONE,
        metallic: 0.0,
        roughness,
        ior,
        transmission: Some(Transmission {
            factor: 1.0,
            texture: None,
            volume: Some(Volume {
                thickness: 2.0 * RADIUS,
                thickness_texture: None,
                attenuation_color: color,
                attenuation_distance: distance,
            }),
            dispersion,
        }),
        ..Material::default()
    }
}

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let camera =
        Camera::look_at(Vec3::new(0.0, 0.55, 1.45), Vec3::new(0.0, 0.1, 0.0), Vec3::Y, 38f32.to_radians());
    let mut s = empty(ctx, camera);
    for name in TILES {
        s.materials.push(measured_material(&format!("floor tile ({name})"), &patch(patch_index(name))));
    }
    let (n, size) = (12usize, 0.2f32);
    let start = -0.5 * n as f32 * size;
    for i in 0..n {
        for j in 0..n {
            let o = Vec3::new(start + i as f32 * size, 0.0, -start - j as f32 * size);
            let tile = (i % 4 + 4 * (j % 2)) % TILES.len();
            s.meshes.push(shapes::quad(o, Vec3::X * size, -Vec3::Z * size, tile));
        }
    }
    let spheres = [
        glass("clear crown glass (index 1.5)", 1.5, 0.0, [1.0; 3], f32::INFINITY, 0.0),
        glass("dispersive flint (index 1.7, Abbe number 20)", 1.7, 0.0, [1.0; 3], f32::INFINITY, 1.0),
        glass("green bottle glass", 1.52, 0.0, [0.3, 0.75, 0.35], 0.1, 0.0),
        glass("frosted glass (roughness 0.3)", 1.5, 0.3, [1.0; 3], f32::INFINITY, 0.0),
    ];
    for (i, m) in spheres.into_iter().enumerate() {
        s.materials.push(m);
        let x = (i as f32 - 1.5) * 0.3;
        s.meshes.push(shapes::sphere(Vec3::new(x, RADIUS, 0.0), RADIUS, 14, 22, s.materials.len() - 1));
    }
    let d65 = color::illuminant::by_name("D65").map_err(|e| ctx.invalid("D65", e.to_string()))?;
    let (position, target) = (Vec3::new(0.3, 1.4, 1.0), Vec3::new(0.0, 0.0, -0.1));
    let to = target - position;
    s.lights.push(Light {
        name: "spot".into(),
        kind: LightKind::Spot {
            position,
            direction: to.normalize(),
            inner_cone: 45f32.to_radians(),
            outer_cone: 70f32.to_radians(),
            range: None,
        },
        // ≈ π lux at the target.
        emission: light_emission(ctx, "spot", &d65, std::f32::consts::PI * to.length_squared())?,
        stands_in_for: None,
    });
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_closed_glass_spheres_on_a_tiled_floor() {
        let s = build(&Ctx::builtin("glass")).unwrap();
        let glass: Vec<_> = s.materials.iter().filter_map(|m| m.transmission.as_ref()).collect();
        assert_eq!(glass.len(), 4);
        assert!(glass.iter().all(|t| t.volume.is_some()));
        assert_eq!(glass.iter().filter(|t| t.disperses()).count(), 1);
        assert_eq!(glass.iter().filter(|t| t.volume.as_ref().unwrap().absorbs()).count(), 1);
        for m in s.meshes.iter().filter(|m| s.materials[m.material].transmission.is_some()) {
            // Closed: every edge (by its end points, the seam's vertices being repeated) is
            // shared by exactly two triangles.
            let key = |i: u32| (m.positions[i as usize] * 1e5).round().to_array().map(|c| c as i64);
            let mut edges = std::collections::HashMap::new();
            for t in m.indices.chunks(3) {
                for k in 0..3 {
                    let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
                    *edges.entry(if a < b { (a, b) } else { (b, a) }).or_insert(0) += 1;
                }
            }
            assert!(edges.values().all(|&c| c == 2), "an open sphere");
        }
    }
}
