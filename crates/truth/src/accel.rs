//! Ray–scene intersection: every triangle of the scene in one compressed wide BVH (`obvhs`
//! CWBVH, built with PLOC), with a Möller–Trumbore test on our own vertex copies.

use bvh_glam::Vec3A;
use glam::Vec3;
use obvhs::{BvhBuildParams, aabb::Aabb, cwbvh::CwBvh, cwbvh::builder::build_cwbvh, ray::Ray};
use scene::Scene;
use std::time::Duration;

/// [`Geometry::filter`] bit: the material is single-sided (glTF `doubleSided: false`).
pub const SINGLE_SIDED: u8 = 1;
/// [`Geometry::filter`] bit: the material's alpha mode is `Mask` or `Blend`.
pub const NOT_OPAQUE: u8 = 2;

/// A triangle's place in the scene.
#[derive(Clone, Copy, Debug)]
pub struct TriRef {
    pub mesh: u32,
    /// Offset of its first index in `mesh.indices`.
    pub first: u32,
}

/// The closest hit: distance and barycentrics of vertices 1 and 2.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f32,
    pub tri: u32,
    pub b1: f32,
    pub b2: f32,
}

pub struct Geometry {
    pub refs: Vec<TriRef>,
    pub verts: Vec<[Vec3; 3]>,
    /// Per triangle: [`SINGLE_SIDED`] | [`NOT_OPAQUE`] from its material; 0 (opaque,
    /// double-sided) triangles never call the filter of [`Geometry::intersect_filtered`].
    pub filter: Vec<u8>,
    any_filtered: bool,
    bvh: Option<CwBvh>,
    /// The power of two the BVH's space is scaled by (1 for a scene at least a unit across):
    /// its traversal skips boxes nearer than 10⁻⁴ along the ray (obvhs's `EPSILON`), which hid
    /// every surface of a scene smaller than that. Scaling by a power of two is exact, so the
    /// triangles are tested unscaled and the hits are the same bits.
    scale: f32,
    /// The largest side of the triangles' bounding box (0 without triangles).
    pub size: f32,
}

/// [`Geometry::scale`] for a scene whose bounding box's largest side is `size`: the smallest
/// power of two that brings it to 1 or more, within f32's exponents; 1 at `size` ≥ 1.
fn bvh_scale(size: f32) -> f32 {
    if !(size > 0.0 && size < 1.0) {
        return 1.0;
    }
    (-size.log2().floor()).clamp(0.0, 100.0).exp2()
}

fn v3a(v: Vec3) -> Vec3A {
    Vec3A::new(v.x, v.y, v.z)
}

/// The box the BVH builder gets for triangle `i`: each of its six sides pushed out by its own
/// pseudo-random 0–10⁻⁴ of the box's size (at least a few f32 ulps of its coordinates, so that
/// the growth survives rounding), conservative for the traversal. PLOC pairs neighbours that
/// choose each other as the cheapest merge; among exact ties (a mesh duplicated in place, a
/// deep chain of nodes on one spot) every cluster chose the same side, one pair merged per
/// pass, and the build was quadratic (8 000 copies of a box 53 s, 20 000 not done in 5 min)
/// and its tree as deep as the copies were many. With six independent growths a neighbour's
/// union is rarely tied with another's, so pairs form at the usual rate; the BVH is a hair
/// looser.
fn build_box(i: usize, v: &[Vec3; 3]) -> Aabb {
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    let magnitude = lo.abs().max(hi.abs()).max_element();
    let step = ((hi - lo).max_element() * 1e-4).max(magnitude * 8e-7).max(1e-30);
    // SplitMix64 of the index: deterministic, so the same scene builds the same BVH; six
    // 10-bit fractions from one draw.
    let mut z = (i as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    let u = |k: u32| step * (((z >> (10 * k)) & 1023) as f32 + 1.0) / 1024.0;
    Aabb { min: v3a(lo - Vec3::new(u(0), u(1), u(2))), max: v3a(hi + Vec3::new(u(3), u(4), u(5))) }
}

/// The direction the BVH traverses with: exact zeros become ±1e-30 (sign kept). An exactly
/// axis-aligned ray has infinite reciprocals, and the traversal then misses flat geometry
/// (a floor seen straight down); the triangle test still uses the exact direction.
fn traversal_dir(d: Vec3) -> Vec3A {
    let f = |c: f32| if c == 0.0 { 1e-30f32.copysign(c) } else { c };
    Vec3A::new(f(d.x), f(d.y), f(d.z))
}

/// Möller–Trumbore: (t, b1, b2) if the ray hits within (0, tmax).
#[inline]
pub fn intersect_triangle(v: &[Vec3; 3], o: Vec3, d: Vec3, tmax: f32) -> Option<(f32, f32, f32)> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - v[0];
    let b1 = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qv = tv.cross(e1);
    let b2 = d.dot(qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > 0.0 && t < tmax).then_some((t, b1, b2))
}

/// A mesh the tracer cannot build triangles from, named by its index in the scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    #[error("mesh {mesh} has {count} indices, not a multiple of 3")]
    Indices { mesh: usize, count: usize },
    #[error("mesh {mesh} uses material {material} of {count}")]
    Material { mesh: usize, material: usize, count: usize },
    #[error("mesh {mesh} triangle {triangle} indexes past its {vertices} vertices")]
    Index { mesh: usize, triangle: usize, vertices: usize },
}

impl Geometry {
    /// Flattens every mesh's triangles and builds the BVH. Triangles referring to vertices a
    /// mesh does not have are an error naming the mesh, not a panic.
    pub fn new(scene: &Scene) -> Result<Self, GeometryError> {
        let mut refs = Vec::new();
        let mut verts = Vec::new();
        let mut filter = Vec::new();
        for (mi, m) in scene.meshes.iter().enumerate() {
            if m.indices.len() % 3 != 0 {
                return Err(GeometryError::Indices { mesh: mi, count: m.indices.len() });
            }
            if m.material >= scene.materials.len() {
                return Err(GeometryError::Material {
                    mesh: mi,
                    material: m.material,
                    count: scene.materials.len(),
                });
            }
            let mat = &scene.materials[m.material];
            // KHR_materials_volume: "the doubleSided property has no effect on volume
            // boundaries" — a ray inside must find the way out through the back faces (culled,
            // a single-sided glass cube passed 0.42 of its backdrop instead of 0.92).
            let volume = mat.transmission.as_ref().is_some_and(|t| t.volume.is_some());
            let flags = if mat.double_sided || volume { 0 } else { SINGLE_SIDED }
                | if mat.alpha_mode == scene::AlphaMode::Opaque { 0 } else { NOT_OPAQUE };
            for (k, c) in m.indices.chunks_exact(3).enumerate() {
                let p = |i: u32| m.positions.get(i as usize).copied();
                let (Some(a), Some(b), Some(cc)) = (p(c[0]), p(c[1]), p(c[2])) else {
                    return Err(GeometryError::Index { mesh: mi, triangle: k, vertices: m.positions.len() });
                };
                // Zero-area triangles can never be hit; dropping them keeps light sampling valid.
                if (b - a).cross(cc - a).length_squared() == 0.0 {
                    continue;
                }
                refs.push(TriRef { mesh: mi as u32, first: (3 * k) as u32 });
                verts.push([a, b, cc]);
                filter.push(flags);
            }
        }
        let (lo, hi) = verts
            .iter()
            .flatten()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let size = if verts.is_empty() { 0.0 } else { (hi - lo).max_element() };
        let scale = bvh_scale(size);
        let bvh = (!verts.is_empty()).then(|| {
            let boxes: Vec<Aabb> =
                verts.iter().enumerate().map(|(i, v)| build_box(i, &v.map(|p| p * scale))).collect();
            build_cwbvh(&boxes, BvhBuildParams::medium_build(), &mut Duration::default())
        });
        let any_filtered = filter.iter().any(|&f| f != 0);
        Ok(Geometry { refs, verts, filter, any_filtered, bvh, scale, size })
    }

    pub fn len(&self) -> usize {
        self.verts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.verts.is_empty()
    }

    /// Closest hit along `o + t·d`, t in (0, tmax), with every triangle taken as there.
    pub fn intersect(&self, o: Vec3, d: Vec3, tmax: f32) -> Option<Hit> {
        self.intersect_filtered(o, d, tmax, |_, _, _| true)
    }

    /// Whether anything blocks the open segment `o + t·d`, t in (0, tmax), every triangle taken
    /// as there.
    pub fn occluded(&self, o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.occluded_filtered(o, d, tmax, |_, _, _| true)
    }

    /// The closest hit along `o + t·d`, t in (0, tmax), that `pass(tri, b1, b2)` accepts; hits it
    /// rejects are as if the triangle were not there. `pass` is asked only about triangles marked
    /// nonzero [`Geometry::filter`]; a scene without any traverses exactly as without a filter.
    pub fn intersect_filtered(
        &self,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        mut pass: impl FnMut(u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let s = self.scale;
        let ray = Ray::new(v3a(o * s), traversal_dir(d), 0.0, tmax * s);
        let mut best: Option<Hit> = None;
        let mut hit = obvhs::ray::RayHit::none();
        let any = self.any_filtered;
        bvh.ray_traverse(ray, &mut hit, |r, id| {
            let tri = bvh.primitive_indices[id];
            match intersect_triangle(&self.verts[tri as usize], o, d, r.tmax / s) {
                Some((t, b1, b2)) if !(any && self.filter[tri as usize] != 0) || pass(tri, b1, b2) => {
                    best = Some(Hit { t, tri, b1, b2 });
                    t * s
                }
                _ => f32::INFINITY,
            }
        });
        best
    }

    /// Whether a hit that `pass` accepts lies on the open segment `o + t·d`, t in (0, tmax)
    /// (the same filter as [`Geometry::intersect_filtered`]).
    pub fn occluded_filtered(
        &self,
        o: Vec3,
        d: Vec3,
        tmax: f32,
        mut pass: impl FnMut(u32, f32, f32) -> bool,
    ) -> bool {
        let Some(bvh) = self.bvh.as_ref() else { return false };
        let s = self.scale;
        let ray = Ray::new(v3a(o * s), traversal_dir(d), 0.0, tmax * s);
        let any = self.any_filtered;
        !bvh.ray_traverse_miss(ray, |r, id| {
            let tri = bvh.primitive_indices[id];
            match intersect_triangle(&self.verts[tri as usize], o, d, r.tmax / s) {
                Some((t, b1, b2)) if !(any && self.filter[tri as usize] != 0) || pass(tri, b1, b2) => t * s,
                _ => f32::INFINITY,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Sampler;

    fn soup(n: usize, seed: u64) -> Scene {
        let mut s = Sampler::new(seed, 0);
        let mut mesh = scene::Mesh::default();
        for i in 0..n {
            let c = Vec3::new(s.uniform(), s.uniform(), s.uniform()) * 10.0;
            for _ in 0..3 {
                mesh.positions.push(c + Vec3::new(s.uniform(), s.uniform(), s.uniform()) - 0.5);
            }
            mesh.indices.extend([3 * i as u32, 3 * i as u32 + 1, 3 * i as u32 + 2]);
        }
        crate::testing::scene_with(vec![mesh], vec![scene::Material::default()], vec![])
    }

    /// The BVH must return exactly what testing every triangle returns.
    #[test]
    fn bvh_agrees_with_brute_force() {
        let scene = soup(2000, 3);
        let g = Geometry::new(&scene).unwrap();
        let mut s = Sampler::new(9, 1);
        for _ in 0..2000 {
            let o = Vec3::new(s.uniform(), s.uniform(), s.uniform()) * 14.0 - 2.0;
            let d = (Vec3::new(s.uniform(), s.uniform(), s.uniform()) - 0.5).normalize();
            let brute = g
                .verts
                .iter()
                .enumerate()
                .filter_map(|(i, v)| intersect_triangle(v, o, d, f32::INFINITY).map(|h| (h.0, i)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let got = g.intersect(o, d, f32::INFINITY);
            match (brute, got) {
                (None, None) => {}
                (Some((t, i)), Some(h)) => assert!(h.tri as usize == i || (h.t - t).abs() < 1e-5),
                other => panic!("mismatch {other:?}"),
            }
            assert_eq!(g.occluded(o, d, 1e30), brute.is_some());
            if let Some((t, _)) = brute {
                assert!(!g.occluded(o, d, t * 0.999));
            }
        }
    }

    /// The same soup scaled by 2⁻²⁴ (11 units across become 7·10⁻⁷) is hit by the same rays,
    /// scaled, at the same triangles and barycentrics, to the bit: obvhs skips boxes nearer than
    /// 10⁻⁴ along the ray, which hid every surface of a scene smaller than that, so the BVH's
    /// space is scaled by a power of two (`Geometry::scale`).
    #[test]
    fn a_tiny_scene_is_hit_as_its_unit_sized_copy() {
        let unit = soup(500, 4);
        let k = (-24f32).exp2();
        let mut tiny = unit.clone();
        for p in &mut tiny.meshes[0].positions {
            *p *= k;
        }
        let (g, gt) = (Geometry::new(&unit).unwrap(), Geometry::new(&tiny).unwrap());
        let mut s = Sampler::new(2, 7);
        let mut hits = 0;
        for _ in 0..2000 {
            // Aimed into the soup, from inside and outside it.
            let o = Vec3::new(s.uniform(), s.uniform(), s.uniform()) * 14.0 - 2.0;
            let d = (Vec3::new(s.uniform(), s.uniform(), s.uniform()) * 10.0 - o).normalize();
            let (a, b) = (g.intersect(o, d, f32::INFINITY), gt.intersect(o * k, d, f32::INFINITY));
            match (a, b) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert_eq!((a.tri, a.t * k, a.b1, a.b2), (b.tri, b.t, b.b1, b.b2));
                    assert!(!gt.occluded(o * k, d, b.t * 0.999) && gt.occluded(o * k, d, b.t * 1.001));
                    hits += 1;
                }
                other => panic!("unit-sized and tiny copies differ: {other:?}"),
            }
        }
        assert!(hits > 400, "{hits} hits");
    }

    /// A mesh duplicated in place thousands of times (careless exports; a deep chain of nodes
    /// on one spot): the build took quadratic time (8 000 copies of a box 53 s) as PLOC paired
    /// one tied cluster per pass; the boxes' random growth breaks the ties. Hits stay exact.
    #[test]
    fn duplicated_geometry_builds_and_hits_as_brute_force() {
        let one = soup(4, 5);
        let mut mesh = scene::Mesh::default();
        let copies = 6000;
        for k in 0..copies {
            mesh.positions.extend(&one.meshes[0].positions);
            mesh.indices.extend(one.meshes[0].indices.iter().map(|i| i + 12 * k));
        }
        let scene = crate::testing::scene_with(vec![mesh], vec![scene::Material::default()], vec![]);
        let g = Geometry::new(&scene).unwrap();
        assert_eq!(g.len(), 4 * copies as usize);
        let mut s = Sampler::new(2, 1);
        for _ in 0..300 {
            let o = Vec3::new(s.uniform(), s.uniform(), s.uniform()) * 14.0 - 2.0;
            let d = (Vec3::new(s.uniform(), s.uniform(), s.uniform()) - 0.5).normalize();
            let brute = g.verts[..4]
                .iter()
                .filter_map(|v| intersect_triangle(v, o, d, f32::INFINITY).map(|h| h.0))
                .min_by(f32::total_cmp);
            let got = g.intersect(o, d, f32::INFINITY).map(|h| h.t);
            assert_eq!(got, brute);
        }
        // Conservative: every box holds its triangle, and tied triangles get distinct boxes.
        let v = g.verts[0];
        let (a, b) = (build_box(0, &v), build_box(1, &v));
        for p in v {
            assert!(a.min.cmple(v3a(p)).all() && a.max.cmpge(v3a(p)).all());
        }
        assert_ne!(a.half_area(), b.half_area());
    }

    /// Large triangles (which the builder pre-splits) in a closed box, rays from wall to wall.
    #[test]
    fn bvh_agrees_on_large_triangles() {
        let scene = crate::testing::scene_with(
            vec![
                crate::testing::inward_box(1.0, 0),
                crate::testing::quad(Vec3::new(0.0, 0.99, 0.0), -Vec3::Y, 0.2, 0),
            ],
            vec![scene::Material::default()],
            vec![],
        );
        let g = Geometry::new(&scene).unwrap();
        let mut s = Sampler::new(4, 2);
        let mut misses = 0;
        for _ in 0..20000 {
            let o = Vec3::new(s.uniform(), s.uniform(), s.uniform()) * 1.98 - 0.99;
            let d = (Vec3::new(s.uniform(), s.uniform(), s.uniform()) - 0.5).normalize();
            let brute = g
                .verts
                .iter()
                .enumerate()
                .filter_map(|(i, v)| intersect_triangle(v, o, d, f32::INFINITY).map(|h| (h.0, i)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let got = g.intersect(o, d, f32::INFINITY);
            match (brute, got) {
                (Some((t, _)), Some(h)) => assert!((h.t - t).abs() < 1e-5, "{t} vs {}", h.t),
                (Some(_), None) => misses += 1,
                other => panic!("mismatch {other:?}"),
            }
        }
        assert_eq!(misses, 0, "BVH missed {misses} of 20000 rays inside a closed box");
    }

    /// Rays along the axes onto flat quads (zero-thickness bounds): straight down onto a floor
    /// was a miss before `traversal_dir`.
    #[test]
    fn axis_aligned_rays_hit_flat_quads() {
        for n in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            let scene = crate::testing::scene_with(
                vec![crate::testing::quad(-n, n, 1.0, 0)],
                vec![scene::Material::default()],
                vec![],
            );
            let g = Geometry::new(&scene).unwrap();
            let o = Vec3::new(0.3, 0.2, 0.1) * (Vec3::ONE - n.abs());
            let h =
                g.intersect(o, -n, f32::INFINITY).unwrap_or_else(|| panic!("missed the quad along {}", -n));
            assert!((h.t - 1.0).abs() < 1e-6, "{}", h.t);
            assert!(g.occluded(o, -n, 2.0));
        }
    }

    #[test]
    fn bad_indices_are_an_error() {
        let mesh =
            scene::Mesh { positions: vec![Vec3::ZERO; 3], indices: vec![0, 1, 7], ..Default::default() };
        let s = crate::testing::scene_with(vec![mesh], vec![scene::Material::default()], vec![]);
        assert!(Geometry::new(&s).err().unwrap().to_string().contains("indexes past"));
    }
}
