//! `iridescence`: thin films (`KHR_materials_iridescence`), the wavelength-dependent effect an
//! RGB renderer can only approximate (issue 30).
//!
//! Two rows of four spheres on a neutral floor. Back row: a dark dielectric (ColorChecker
//! black 2, measured) under films of 200, 400, 600 and 800 nm of index 1.33 (water, a soap
//! bubble's), 1.5 (oil), 1.33 and 1.8; front row: gold- and silver-coloured metals under oxide
//! films of 200–600 nm of index 2.0 and 1.8 (anodised titanium, tempered steel). Roughness 0.5, so
//! each highlight spreads over the sphere and shows the film's colours over a range of
//! angles. One D65 spot from above and in front of the camera, one from the side (the eval's
//! `iridescence-f11` case relights both with F11).

use glam::Vec4;

use super::{Showcase, measured_material, patch, patch_index};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Iridescence, Material, Scene};

/// (thickness nm, film IOR) of the back row's dielectric spheres, left to right.
pub const DIELECTRIC_FILMS: [(f32, f32); 4] = [(200.0, 1.33), (400.0, 1.5), (600.0, 1.33), (800.0, 1.8)];

/// (base colour, thickness nm, film IOR) of the front row's metal spheres.
pub const METAL_FILMS: [([f32; 3], f32, f32); 4] = [
    ([1.0, 0.77, 0.34], 200.0, 2.0),
    ([0.95, 0.93, 0.88], 300.0, 2.0),
    ([1.0, 0.77, 0.34], 450.0, 1.8),
    ([0.95, 0.93, 0.88], 600.0, 1.8),
];

fn film(thickness: f32, ior: f32) -> Option<Iridescence> {
    Some(Iridescence {
        factor: 1.0,
        texture: None,
        ior,
        thickness_min: 0.0,
        thickness_max: thickness,
        thickness_texture: None,
    })
}

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let mut stage = Showcase::new(ctx);
    let black = patch(patch_index("black 2 (1.5 D)"));
    for (i, &(d, n)) in DIELECTRIC_FILMS.iter().enumerate() {
        let mut m = measured_material(&format!("dark dielectric, film {d} nm of index {n}"), &black);
        m.roughness = 0.5;
        m.iridescence = film(d, n);
        stage.sphere(0, i, m);
    }
    for (i, &(c, d, n)) in METAL_FILMS.iter().enumerate() {
        let m = Material {
            name: format!("metal, film {d} nm of index {n}"),
            base_color: Vec4::new(c[0], c[1], c[2], 1.0),
            metallic: 1.0,
            roughness: 0.5,
            iridescence: film(d, n),
            ..Material::default()
        };
        stage.sphere(1, i, m);
    }
    // Two D65 spots aimed at the middle of the rows: ≈ π lux there each.
    stage.finish(ctx, ("front spot", "D65"), ("side spot", "D65"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sphere_has_its_film_and_the_spheres_are_closed() {
        let s = build(&Ctx::builtin("iridescence")).unwrap();
        let filmed = s.materials.iter().filter(|m| m.iridescence.is_some()).count();
        assert_eq!(filmed, DIELECTRIC_FILMS.len() + METAL_FILMS.len());
        for m in &s.meshes[..8] {
            assert!(s.materials[m.material].iridescence.is_some());
            assert_eq!(m.indices.len() % 3, 0);
            // Radial unit normals: each position is the centre plus radius × its normal.
            let c = m.positions[0] - m.normals[0] * 0.12;
            for (p, n) in m.positions.iter().zip(&m.normals) {
                assert!((n.length() - 1.0).abs() < 1e-5 && (c + *n * 0.12 - *p).length() < 1e-5);
            }
        }
    }
}
