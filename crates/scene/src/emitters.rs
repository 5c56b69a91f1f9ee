//! Emissive surfaces as area lights, for renderers that light with polygons rather than by
//! hitting the surfaces (the rasteriser). The path tracer samples the triangles themselves; both
//! read the same materials, so this is only a regrouping of what the scene already says.
//!
//! Each emissive mesh that no punctual light stands in for (`Light::stands_in_for`) becomes
//! polygons of uniform radiance, one-sided (emitting towards the side its vertex normals point
//! to, as in the path tracer): a mesh of exactly two coplanar triangles forming a convex quad
//! becomes one quad, any other mesh one polygon per triangle. The radiance is the material's
//! `emissive` (× `KHR_materials_emissive_strength`, already applied) times the mean of its
//! emissive texture over the whole image (a textured emitter is approximated by its average).

use glam::Vec3;

use crate::{Emission, Scene, srgb};

/// One emitting polygon (3 or 4 vertices, counter-clockwise seen from the emitting side).
#[derive(Clone, Debug)]
pub struct Emitter {
    /// The mesh it comes from (renderers leave it out of its own shadow map).
    pub mesh: usize,
    pub vertices: Vec<Vec3>,
    /// Radiance: `rgb` × `intensity` (intensity 1), with the material's spectrum if it has one.
    pub emission: Emission,
    /// Unit normal of the emitting side.
    pub normal: Vec3,
    pub area: f32,
}

impl Emitter {
    /// Luminance × area: what the cap on the number of emitters sorts by.
    pub fn power(&self) -> f64 {
        srgb::luminance(self.emission.rgb * self.emission.intensity) * self.area as f64
    }

    pub fn centroid(&self) -> Vec3 {
        self.vertices.iter().sum::<Vec3>() / self.vertices.len() as f32
    }
}

/// Every emitting polygon of `scene`, brightest (by [`Emitter::power`]) first.
pub fn emitters(scene: &Scene) -> Vec<Emitter> {
    let stood_in: Vec<usize> = scene.lights.iter().filter_map(|l| l.stands_in_for).collect();
    let mut out = Vec::new();
    for (mi, mesh) in scene.meshes.iter().enumerate() {
        let Some(mat) = scene.materials.get(mesh.material) else { continue };
        if mat.emissive.max_element() <= 0.0 || stood_in.contains(&mi) {
            continue;
        }
        let mean = mat
            .emissive_texture
            .and_then(|t| scene.textures.get(t.index))
            .map(|t| {
                let n = (t.width as usize * t.height as usize).max(1);
                let sum: Vec3 = t
                    .rgba8
                    .chunks_exact(4)
                    .map(|p| {
                        if t.srgb {
                            srgb::srgb8_to_linear([p[0], p[1], p[2]])
                        } else {
                            Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0
                        }
                    })
                    .sum();
                sum / n as f32
            })
            .unwrap_or(Vec3::ONE);
        let rgb = mat.emissive * mean;
        if rgb.max_element() <= 0.0 {
            continue;
        }
        let emission = Emission { rgb, intensity: 1.0, spectrum: mat.emission_spectrum.clone() };
        let tri = |t: &[u32]| -> Option<[Vec3; 3]> {
            let p = |i: u32| mesh.positions.get(i as usize).copied();
            Some([p(t[0])?, p(t[1])?, p(t[2])?])
        };
        // Which side emits: the side the vertex normals point to (flat meshes: the winding).
        let facing = |t: &[u32], ng: Vec3| -> f32 {
            let n: Vec3 = t.iter().filter_map(|&i| mesh.normals.get(i as usize)).sum();
            if n.dot(ng) < 0.0 { -1.0 } else { 1.0 }
        };
        let tris: Vec<&[u32]> = mesh.indices.chunks_exact(3).collect();
        if let [a, b] = tris[..]
            && let (Some(ta), Some(tb)) = (tri(a), tri(b))
            && let Some(quad) = as_quad(a, b, &ta, &tb)
        {
            let ng = (quad[1] - quad[0]).cross(quad[2] - quad[0]);
            let area = 0.5 * ng.length() + 0.5 * (quad[2] - quad[0]).cross(quad[3] - quad[0]).length();
            if let Some(n) = ng.try_normalize() {
                let s = facing(a, n);
                let mut vertices = quad.to_vec();
                if s < 0.0 {
                    vertices.reverse();
                }
                out.push(Emitter { mesh: mi, vertices, emission: emission.clone(), normal: n * s, area });
                continue;
            }
        }
        for t in tris {
            let Some(v) = tri(t) else { continue };
            let c = (v[1] - v[0]).cross(v[2] - v[0]);
            let Some(n) = c.try_normalize() else { continue };
            let s = facing(t, n);
            let mut vertices = v.to_vec();
            if s < 0.0 {
                vertices.reverse();
            }
            out.push(Emitter {
                mesh: mi,
                vertices,
                emission: emission.clone(),
                normal: n * s,
                area: 0.5 * c.length(),
            });
        }
    }
    out.sort_by(|a, b| b.power().total_cmp(&a.power()));
    out
}

/// Two triangles sharing an edge, coplanar, forming a convex quad: its four corners in the
/// winding of the first triangle.
fn as_quad(a: &[u32], b: &[u32], ta: &[Vec3; 3], tb: &[Vec3; 3]) -> Option<[Vec3; 4]> {
    // The vertex of b not in a, and where a's shared edge is.
    let extra: Vec<usize> = (0..3).filter(|&i| !a.contains(&b[i])).collect();
    let [e] = extra[..] else { return None };
    let lone: Vec<usize> = (0..3).filter(|&i| !b.contains(&a[i])).collect();
    let [l] = lone[..] else { return None };
    // a = (l, l+1, l+2): the shared edge is (l+1, l+2); the quad is l, l+1, extra, l+2.
    let q = [ta[l], ta[(l + 1) % 3], tb[e], ta[(l + 2) % 3]];
    let n = (q[1] - q[0]).cross(q[3] - q[0]);
    let scale = (q[2] - q[0]).length().max(1e-20);
    if n.length() <= 0.0 || (n.normalize().dot(q[2] - q[0]) / scale).abs() > 1e-4 {
        return None;
    }
    // Convex: every corner turns the same way.
    let turn = |i: usize| (q[(i + 1) % 4] - q[i]).cross(q[(i + 2) % 4] - q[(i + 1) % 4]).dot(n);
    (0..4).all(|i| turn(i) > 0.0).then_some(q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Material, Mesh};
    use glam::{Vec2, Vec4};

    fn scene_with(mesh: Mesh, emissive: Vec3) -> Scene {
        let mut s = crate::builtin::empty(
            &crate::context::Ctx::builtin("t"),
            crate::Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0),
        );
        s.materials.push(Material { emissive, base_color: Vec4::ONE, ..Default::default() });
        s.meshes.push(mesh);
        s
    }

    fn quad_mesh(flip: bool) -> Mesh {
        let positions = vec![
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let n = if flip { Vec3::Y } else { Vec3::NEG_Y };
        Mesh {
            colors: vec![],
            uvs1: vec![],
            positions,
            normals: vec![n; 4],
            tangents: vec![],
            uvs: vec![Vec2::ZERO; 4],
            indices: vec![0, 1, 2, 0, 2, 3],
            material: 0,
        }
    }

    #[test]
    fn a_two_triangle_ceiling_is_one_quad_facing_its_normals() {
        let e = emitters(&scene_with(quad_mesh(false), Vec3::splat(2.0)));
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].vertices.len(), 4);
        assert!((e[0].area - 1.0).abs() < 1e-6);
        assert!((e[0].normal - Vec3::NEG_Y).length() < 1e-6, "{}", e[0].normal);
        let n = (e[0].vertices[1] - e[0].vertices[0]).cross(e[0].vertices[2] - e[0].vertices[0]);
        assert!(n.dot(Vec3::NEG_Y) > 0.0, "winding follows the emitting side");
        let up = emitters(&scene_with(quad_mesh(true), Vec3::splat(2.0)));
        assert!((up[0].normal - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn dark_and_stood_in_meshes_are_not_emitters() {
        assert!(emitters(&scene_with(quad_mesh(false), Vec3::ZERO)).is_empty());
        // The built-in Cornell box's lamp has a point-light stand-in.
        assert!(emitters(&crate::builtin("cornell").unwrap()).is_empty());
    }
}
