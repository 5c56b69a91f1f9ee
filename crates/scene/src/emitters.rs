//! Emissive surfaces as area lights, for renderers that light with polygons rather than by
//! hitting the surfaces (the rasteriser). The path tracer samples the triangles themselves; both
//! read the same materials, so this is only a regrouping of what the scene already says.
//!
//! Each emissive mesh that no punctual light stands in for (`Light::stands_in_for`) becomes
//! polygons of uniform radiance, one-sided (emitting towards the side its vertex normals point
//! to, as in the path tracer): a mesh of exactly two coplanar triangles forming a convex quad
//! becomes one quad, any other mesh one polygon per triangle ([`emitters`]). The radiance is the
//! material's `emissive` (× `KHR_materials_emissive_strength`, already applied) times the mean
//! over the polygon of its emissive texture × its alpha coverage (stratified samples of the
//! triangle, [`texture_mean`]); a polygon that emits nothing is left out.
//!
//! A renderer with a light budget takes [`area_lights`]: the polygons as they are when they fit,
//! else clustered — per material (one emission spectrum each), then by position and normal —
//! into at most the budget's lights, each a quad with the cluster's total area, its power-weighted
//! centre and normal, its spread's aspect, and its mean radiance, so that the emitted power
//! (π·L·A per polygon) is kept exactly.

use glam::{Vec2, Vec3, Vec4};

use crate::{AlphaMode, Emission, Scene, Texture, TextureRef, Wrap, srgb};

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
        let texture = mat.emissive_texture.and_then(|r| scene.textures.get(r.index).map(|t| (r, t)));
        // Coverage (what the path tracer's rays stop at, `truth::World::coverage`): the base
        // colour's alpha × its texture's × COLOR_0's, tested against the cutoff (MASK) or taken
        // as opacity (BLEND). An emitter cut away or see-through emits that much less; before,
        // one of alpha 0 lit the scene in real time and not in the path tracer.
        let base_texture = match mat.alpha_mode {
            AlphaMode::Opaque => None,
            _ => mat.base_color_texture.and_then(|r| scene.textures.get(r.index).map(|t| (r, t))),
        };
        let varying_alpha = mat.alpha_mode != AlphaMode::Opaque
            && (base_texture.is_some() || mesh.colors.iter().any(|c| c.w != 1.0));
        let coverage_of = |a: f32| match mat.alpha_mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask { cutoff } => f32::from(u8::from(a >= cutoff)),
            AlphaMode::Blend => a.clamp(0.0, 1.0),
        };
        let constant_coverage = coverage_of(mat.base_color.w);
        let uvs = |r: &TextureRef| if r.tex_coord == 1 { &mesh.uvs1 } else { &mesh.uvs };
        let uv_of = |r: &TextureRef, i: u32| {
            let uv = uvs(r).get(i as usize).copied().unwrap_or(Vec2::ZERO);
            r.transform.map_or(uv, |tf| tf.apply(uv))
        };
        // The polygon's radiance: the factor × the mean over the polygon of its texture ×
        // coverage (sampled together: a cut-out decal's bright parts may be where it is cut).
        let radiance = |idx: &[u32]| -> Vec3 {
            if texture.is_none() && !varying_alpha {
                return mat.emissive * constant_coverage;
            }
            let p = |i: u32| mesh.positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
            // A quad's two triangles, each weighted by its area.
            let halves: Vec<[u32; 3]> = match idx {
                [a, b, c] => vec![[*a, *b, *c]],
                [a, b, c, d] => vec![[*a, *b, *c], [*a, *c, *d]],
                _ => vec![],
            };
            let (mut sum, mut area) = (Vec3::ZERO, 0.0f32);
            for t in halves {
                let w = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).length().max(1e-30);
                let emit = texture.map(|(r, tex)| (tex, t.map(|i| uv_of(&r, i))));
                let base = base_texture.map(|(r, tex)| (tex, t.map(|i| uv_of(&r, i))));
                let colour_alpha = |b: [f32; 3]| {
                    let c = |i: u32| mesh.colors.get(i as usize).map_or(1.0, |c| c.w);
                    b[0] * c(t[0]) + b[1] * c(t[1]) + b[2] * c(t[2])
                };
                let mean = triangle_mean(emit, base, |texel_e, texel_b, b| {
                    let e = texel_e.map_or(Vec3::ONE, |t| t.truncate());
                    if mat.alpha_mode == AlphaMode::Opaque {
                        return e;
                    }
                    let a = mat.base_color.w * texel_b.map_or(1.0, |t| t.w) * colour_alpha(b);
                    e * coverage_of(a)
                });
                sum += w * mean;
                area += w;
            }
            mat.emissive * (sum / area.max(1e-30))
        };
        let emission = |rgb: Vec3| Emission { rgb, intensity: 1.0, spectrum: mat.emission_spectrum.clone() };
        let tri = |t: &[u32]| -> Option<[Vec3; 3]> {
            let p = |i: u32| mesh.positions.get(i as usize).copied();
            Some([p(t[0])?, p(t[1])?, p(t[2])?])
        };
        // Which side emits: the side the vertex normals point to (flat meshes: the winding).
        // A single-sided material is seen only from its winding's front, so one whose normals
        // point the other way emits where nothing sees it, and where the path tracer's rays
        // pass through it: nothing (it lit the scene in real time only).
        let facing = |t: &[u32], ng: Vec3| -> Option<f32> {
            let n: Vec3 = t.iter().filter_map(|&i| mesh.normals.get(i as usize)).sum();
            if n.dot(ng) < 0.0 { mat.double_sided.then_some(-1.0) } else { Some(1.0) }
        };
        let tris: Vec<&[u32]> = mesh.indices.chunks_exact(3).collect();
        if let [a, b] = tris[..]
            && let (Some(ta), Some(tb)) = (tri(a), tri(b))
            && let Some((quad, corners)) = as_quad(a, b, &ta, &tb)
        {
            let rgb = radiance(&corners);
            let ng = (quad[1] - quad[0]).cross(quad[2] - quad[0]);
            let area = 0.5 * ng.length() + 0.5 * (quad[2] - quad[0]).cross(quad[3] - quad[0]).length();
            if rgb.max_element() <= 0.0 {
                continue;
            }
            if let Some(n) = ng.try_normalize() {
                let Some(s) = facing(a, n) else { continue };
                let mut vertices = quad.to_vec();
                if s < 0.0 {
                    vertices.reverse();
                }
                out.push(Emitter { mesh: mi, vertices, emission: emission(rgb), normal: n * s, area });
                continue;
            }
        }
        for t in tris {
            let Some(v) = tri(t) else { continue };
            let rgb = radiance(t);
            if rgb.max_element() <= 0.0 {
                continue;
            }
            let c = (v[1] - v[0]).cross(v[2] - v[0]);
            let Some(n) = c.try_normalize() else { continue };
            let Some(s) = facing(t, n) else { continue };
            let mut vertices = v.to_vec();
            if s < 0.0 {
                vertices.reverse();
            }
            out.push(Emitter {
                mesh: mi,
                vertices,
                emission: emission(rgb),
                normal: n * s,
                area: 0.5 * c.length(),
            });
        }
    }
    out.sort_by(|a, b| b.power().total_cmp(&a.power()));
    out
}

/// Two triangles sharing an edge, coplanar, forming a convex quad: its four corners in the
/// winding of the first triangle, and their vertex indices.
fn as_quad(a: &[u32], b: &[u32], ta: &[Vec3; 3], tb: &[Vec3; 3]) -> Option<([Vec3; 4], [u32; 4])> {
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
    let corners = [a[l], a[(l + 1) % 3], b[e], a[(l + 2) % 3]];
    (0..4).all(|i| turn(i) > 0.0).then_some((q, corners))
}

/// The mean colour (linear) of texture `t` over the triangle with texture coordinates `uv`:
/// nearest texels at stratified points of the triangle (their number grows with the texels it
/// covers, 16 to 4096), wrapped as the texture's sampler says. The path tracer reads the texture
/// at every hit; this is what a polygon of uniform radiance can carry of it.
pub fn texture_mean(t: &Texture, uv: [Vec2; 3]) -> Vec3 {
    triangle_mean(Some((t, uv)), None, |e, _, _| e.map_or(Vec3::ONE, |t| t.truncate()))
}

/// The mean of `f` over a triangle, at stratified points (as [`texture_mean`]: as many as the
/// larger texture footprint asks, 16 to 4096): `f` takes the nearest texel (linear RGB, alpha)
/// of each texture given (`None` without one) and the point's barycentrics.
fn triangle_mean(
    a: Option<(&Texture, [Vec2; 3])>,
    b: Option<(&Texture, [Vec2; 3])>,
    f: impl Fn(Option<Vec4>, Option<Vec4>, [f32; 3]) -> Vec3,
) -> Vec3 {
    fn usable(x: Option<(&Texture, [Vec2; 3])>) -> Option<(&Texture, [Vec2; 3])> {
        x.filter(|(t, _)| {
            t.width > 0 && t.height > 0 && t.rgba8.len() >= 4 * t.width as usize * t.height as usize
        })
    }
    let (a, b) = (usable(a), usable(b));
    let footprint = |x: Option<(&Texture, [Vec2; 3])>| {
        x.map_or(0.0, |(t, uv)| {
            let size = Vec2::new(t.width as f32, t.height as f32);
            0.5 * ((uv[1] - uv[0]) * size).perp_dot((uv[2] - uv[0]) * size).abs()
        })
    };
    let k = (footprint(a).max(footprint(b)).sqrt().ceil() as usize).clamp(4, 64);
    let texel = |x: Option<(&Texture, [Vec2; 3])>, s: f32, r: f32| {
        x.map(|(t, uv)| {
            let (w, h) = (t.width as usize, t.height as usize);
            let at = uv[0] + s * (uv[1] - uv[0]) + r * (uv[2] - uv[0]);
            let wrap = |i: i64, n: usize, mode: Wrap| mode.index(i, n as i64) as usize;
            let x = wrap((at.x * w as f32).clamp(-1e9, 1e9).floor() as i64, w, t.sampler.wrap_s);
            let y = wrap((at.y * h as f32).clamp(-1e9, 1e9).floor() as i64, h, t.sampler.wrap_t);
            let o = 4 * (y * w + x);
            let px = [t.rgba8[o], t.rgba8[o + 1], t.rgba8[o + 2]];
            let rgb = if t.srgb {
                srgb::srgb8_to_linear(px)
            } else {
                Vec3::new(px[0] as f32, px[1] as f32, px[2] as f32) / 255.0
            };
            rgb.extend(t.rgba8[o + 3] as f32 / 255.0)
        })
    };
    // The centroids of the k² congruent triangles the triangle divides into (k(k+1)/2 upright,
    // k(k−1)/2 inverted): equal areas, so an unweighted mean. (Folding a k × k grid of the unit
    // square onto it put k samples on the hypotenuse: a bias of order 1/k, 12 % of a half-cut
    // quad at k = 4.)
    let mut sum = Vec3::ZERO;
    let mut at = |s: f32, r: f32| sum += f(texel(a, s, r), texel(b, s, r), [1.0 - s - r, s, r]);
    let kf = k as f32;
    for i in 0..k {
        for j in 0..k - i {
            at((i as f32 + 1.0 / 3.0) / kf, (j as f32 + 1.0 / 3.0) / kf);
            if i + j + 1 < k {
                at((i as f32 + 2.0 / 3.0) / kf, (j as f32 + 2.0 / 3.0) / kf);
            }
        }
    }
    sum / (k * k) as f32
}

/// The emissive surfaces as at most `budget` lights ([`area_lights`]).
#[derive(Clone, Debug, Default)]
pub struct AreaLights {
    /// Brightest first.
    pub lights: Vec<Emitter>,
    /// The emitting polygons they stand for ([`emitters`]).
    pub polygons: usize,
    /// Whether polygons were merged into clusters.
    pub clustered: bool,
    /// The share of the emitted power left out (only when there are more emitting materials
    /// than the budget).
    pub dropped_power: f64,
}

/// Every emitting polygon of `scene` ([`emitters`]) when they are at most `budget`; else
/// clusters of them — the budget shared by the materials in proportion to their power (at least
/// one each; the dimmest materials are left out, and counted in `dropped_power`, only when there
/// are more of them than the budget), each material's polygons split in two along the widest
/// axis of their positions and normals, the cluster of most power × spread first, until its share
/// is reached — each cluster one quad keeping its total area and power.
pub fn area_lights(scene: &Scene, budget: usize) -> AreaLights {
    let all = emitters(scene);
    let polygons = all.len();
    if polygons <= budget {
        return AreaLights { lights: all, polygons, clustered: false, dropped_power: 0.0 };
    }
    let total: f64 = all.iter().map(Emitter::power).sum();
    // Per material: one emission spectrum each.
    let mut groups: Vec<(usize, Vec<Emitter>)> = Vec::new();
    for e in all {
        let m = scene.meshes[e.mesh].material;
        match groups.iter_mut().find(|g| g.0 == m) {
            Some(g) => g.1.push(e),
            None => groups.push((m, vec![e])),
        }
    }
    let power = |g: &[Emitter]| g.iter().map(Emitter::power).sum::<f64>();
    groups.sort_by(|a, b| power(&b.1).total_cmp(&power(&a.1)));
    let mut dropped = 0.0;
    if groups.len() > budget {
        dropped = groups[budget..].iter().map(|g| power(&g.1)).sum::<f64>();
        groups.truncate(budget);
    }
    // Shares: one each, the rest by largest remainder of power, never more than a group has.
    let kept: f64 = groups.iter().map(|g| power(&g.1)).sum();
    let mut share: Vec<usize> = vec![1; groups.len()];
    let spare = budget.saturating_sub(groups.len());
    let want: Vec<f64> =
        groups.iter().map(|g| if kept > 0.0 { spare as f64 * power(&g.1) / kept } else { 0.0 }).collect();
    for (s, w) in share.iter_mut().zip(&want) {
        *s += w.floor() as usize;
    }
    let mut order: Vec<usize> = (0..groups.len()).collect();
    order.sort_by(|&a, &b| (want[b] - want[b].floor()).total_cmp(&(want[a] - want[a].floor())));
    let mut left = budget.saturating_sub(share.iter().sum());
    while left > 0 {
        let before = left;
        for &i in &order {
            if left > 0 && share[i] < groups[i].1.len() {
                share[i] += 1;
                left -= 1;
            }
        }
        if left == before {
            break;
        }
    }
    let mut lights = Vec::new();
    for ((_, g), k) in groups.into_iter().zip(share) {
        let k = k.min(g.len());
        lights.extend(split(g, k).into_iter().map(merge));
    }
    lights.sort_by(|a, b| b.power().total_cmp(&a.power()));
    AreaLights {
        lights,
        polygons,
        clustered: true,
        dropped_power: if total > 0.0 { dropped / total } else { 0.0 },
    }
}

/// A polygon's place for clustering: its centroid (over `scale`, the group's size) and its
/// normal at half weight (opposite normals are as far apart as the group is wide).
fn feature(e: &Emitter, scale: f32) -> [f32; 6] {
    let c = e.centroid() / scale;
    let n = 0.5 * e.normal;
    [c.x, c.y, c.z, n.x, n.y, n.z]
}

/// `g` in `k` clusters: the cluster of most power × extent split at its median along its widest
/// feature axis, until there are `k` (or no cluster has two polygons).
fn split(g: Vec<Emitter>, k: usize) -> Vec<Vec<Emitter>> {
    let (lo, hi) = g
        .iter()
        .flat_map(|e| e.vertices.iter())
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    let scale = (hi - lo).length().max(1e-12);
    type Item = ([f32; 6], f64, Emitter);
    // The widest axis of a cluster's features, and its width.
    let extent = |c: &[Item]| -> (usize, f32) {
        let mut lo = [f32::INFINITY; 6];
        let mut hi = [f32::NEG_INFINITY; 6];
        for (f, ..) in c {
            for a in 0..6 {
                lo[a] = lo[a].min(f[a]);
                hi[a] = hi[a].max(f[a]);
            }
        }
        (0..6).map(|a| (a, hi[a] - lo[a])).fold((0, 0.0), |b, x| if x.1 > b.1 { x } else { b })
    };
    let cost = |c: &[Item]| -> f64 {
        if c.len() < 2 {
            -1.0
        } else {
            c.iter().map(|i| i.1).sum::<f64>().max(1e-30) * f64::from(extent(c).1)
        }
    };
    let items: Vec<Item> = g.into_iter().map(|e| (feature(&e, scale), e.power(), e)).collect();
    let mut clusters: Vec<(f64, Vec<Item>)> = vec![(cost(&items), items)];
    while clusters.len() < k {
        let Some(i) = (0..clusters.len()).max_by(|&a, &b| clusters[a].0.total_cmp(&clusters[b].0)) else {
            break;
        };
        if clusters[i].1.len() < 2 {
            break;
        }
        let (_, mut c) = clusters.swap_remove(i);
        let (axis, _) = extent(&c);
        c.sort_by(|a, b| a.0[axis].total_cmp(&b.0[axis]));
        let rest = c.split_off(c.len() / 2);
        clusters.push((cost(&c), c));
        clusters.push((cost(&rest), rest));
    }
    clusters.into_iter().map(|(_, c)| c.into_iter().map(|i| i.2).collect()).collect()
}

/// One quad for a cluster: its total area, its radiance the area-weighted mean (the power
/// π·L·A summed), centred at the power-weighted centroid, facing the power-weighted normal, its
/// sides in the ratio of the cluster's spread along its principal axes (at most 8:1). A cluster of
/// one polygon is that polygon.
fn merge(mut c: Vec<Emitter>) -> Emitter {
    if c.len() == 1 {
        return c.pop().expect("one");
    }
    let area: f32 = c.iter().map(|e| e.area).sum();
    let rgb = c.iter().map(|e| e.emission.rgb * e.area).sum::<Vec3>() / area.max(1e-30);
    let weight = |e: &Emitter| (e.power() as f32).max(0.0) + 1e-30 * e.area;
    let wsum: f32 = c.iter().map(weight).sum();
    let centre = c.iter().map(|e| e.centroid() * weight(e)).sum::<Vec3>() / wsum;
    let brightest = c.iter().max_by(|a, b| a.power().total_cmp(&b.power())).expect("two or more");
    let normal =
        c.iter().map(|e| e.normal * weight(e)).sum::<Vec3>().try_normalize().unwrap_or(brightest.normal);
    // The spread in the quad's plane: second moments of the polygons' vertices.
    let t1 = normal.any_orthonormal_vector();
    let t2 = normal.cross(t1);
    let (mut sxx, mut sxy, mut syy, mut wt) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
    for e in &c {
        let w = e.area / e.vertices.len() as f32;
        for v in &e.vertices {
            let d = *v - centre;
            let (x, y) = (d.dot(t1), d.dot(t2));
            sxx += w * x * x;
            sxy += w * x * y;
            syy += w * y * y;
            wt += w;
        }
    }
    let (sxx, sxy, syy) = (sxx / wt.max(1e-30), sxy / wt.max(1e-30), syy / wt.max(1e-30));
    let half_tr = 0.5 * (sxx + syy);
    let root = (0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy).sqrt();
    let (l1, l2) = (half_tr + root, (half_tr - root).max(0.0));
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let u = (t1 * angle.cos() + t2 * angle.sin()).normalize();
    let v = normal.cross(u);
    let aspect = if l2 > 0.0 { (l1 / l2).sqrt().clamp(1.0, 8.0) } else { 8.0 };
    let a = (area * aspect).sqrt();
    let b = area / a;
    let corner = |su: f32, sv: f32| centre + u * (0.5 * a * su) + v * (0.5 * b * sv);
    Emitter {
        mesh: brightest.mesh,
        vertices: vec![corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)],
        emission: Emission { rgb, intensity: 1.0, spectrum: brightest.emission.spectrum.clone() },
        normal,
        area,
    }
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
        // Normals against the winding: a double-sided quad emits towards its normals; a
        // single-sided one is seen only from its winding's front, where it does not emit (the
        // path tracer's rays pass through its back): no light.
        let mut scene = scene_with(quad_mesh(true), Vec3::splat(2.0));
        scene.materials[0].double_sided = true;
        let up = emitters(&scene);
        assert!((up[0].normal - Vec3::Y).length() < 1e-6);
        scene.materials[0].double_sided = false;
        assert!(emitters(&scene).is_empty());
        let mut m = quad_mesh(true);
        m.indices = vec![0, 1, 2];
        scene.meshes[0] = m;
        assert!(emitters(&scene).is_empty(), "one triangle");
    }

    /// An emitter cut away by alpha (MASK below the cutoff, BLEND at 0) lit the scene in real
    /// time but not in the path tracer, whose rays pass where it is not there: its radiance is
    /// now its mean coverage × emission, sampled together over the polygon.
    #[test]
    fn an_emitter_emits_as_much_as_its_alpha_covers() {
        let rgb = |alpha: f32, mode: AlphaMode| {
            let mut scene = scene_with(quad_mesh(false), Vec3::splat(2.0));
            scene.materials[0].base_color.w = alpha;
            scene.materials[0].alpha_mode = mode;
            emitters(&scene).first().map_or(Vec3::ZERO, |e| e.emission.rgb)
        };
        assert_eq!(rgb(0.0, AlphaMode::Opaque), Vec3::splat(2.0), "opaque ignores alpha");
        assert_eq!(rgb(0.0, AlphaMode::Blend), Vec3::ZERO);
        assert_eq!(rgb(0.25, AlphaMode::Blend), Vec3::splat(0.5));
        assert_eq!(rgb(0.4, AlphaMode::Mask { cutoff: 0.5 }), Vec3::ZERO);
        assert_eq!(rgb(0.6, AlphaMode::Mask { cutoff: 0.5 }), Vec3::splat(2.0));
        // A mask texture cutting the left half, and an emissive texture bright only there: the
        // two sampled together leave nothing; sampled apart they would leave a quarter.
        let tex = |name: &str, left: [u8; 4], right: [u8; 4]| Texture {
            name: name.into(),
            width: 2,
            height: 1,
            rgba8: [left, right].concat(),
            srgb: false,
            sampler: Default::default(),
        };
        let mut m = quad_mesh(false);
        m.uvs = vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
        let mut scene = scene_with(m, Vec3::ONE);
        scene.textures.push(tex("cut", [255, 255, 255, 0], [255, 255, 255, 255]));
        scene.textures.push(tex("glow", [255, 255, 255, 255], [0, 0, 0, 255]));
        scene.materials[0].base_color_texture = Some(TextureRef::new(0));
        scene.materials[0].emissive_texture = Some(TextureRef::new(1));
        scene.materials[0].alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
        assert!(emitters(&scene).is_empty());
        // The glow on the kept half: half the quad's mean.
        scene.textures[1] = tex("glow", [0, 0, 0, 255], [255, 255, 255, 255]);
        let e = emitters(&scene)[0].emission.rgb;
        assert!((e - Vec3::splat(0.5)).abs().max_element() < 0.02, "{e}");
        // COLOR_0's alpha counts too.
        scene.materials[0].base_color_texture = None;
        scene.materials[0].emissive_texture = None;
        scene.materials[0].alpha_mode = AlphaMode::Blend;
        scene.meshes[0].colors = vec![Vec4::new(1.0, 1.0, 1.0, 0.5); 4];
        let e = emitters(&scene)[0].emission.rgb;
        assert!((e - Vec3::splat(0.5)).abs().max_element() < 1e-6, "{e}");
    }

    /// A glowing sphere of 2 400 triangles in 8 lights: every bit of its area and power kept,
    /// each light a quad facing its normal (counter-clockwise seen from it), spread over the
    /// sphere (the lights' normals cover both hemispheres).
    #[test]
    fn many_triangles_cluster_into_the_budget_keeping_area_and_power() {
        let mesh = crate::builtin::shapes::sphere(Vec3::new(0.0, 1.0, 0.0), 0.5, 30, 40, 0);
        let scene = scene_with(mesh, Vec3::new(3.0, 2.0, 1.0));
        let polys = emitters(&scene);
        assert_eq!(polys.len(), 30 * 40 * 2 - 2 * 40);
        let (area, power): (f32, f64) =
            (polys.iter().map(|e| e.area).sum(), polys.iter().map(|e| e.power()).sum());
        let lights = area_lights(&scene, 8);
        assert!(lights.clustered && lights.lights.len() == 8 && lights.polygons == polys.len());
        assert_eq!(lights.dropped_power, 0.0);
        let a2: f32 = lights.lights.iter().map(|e| e.area).sum();
        let p2: f64 = lights.lights.iter().map(|e| e.power()).sum();
        assert!(
            (a2 / area - 1.0).abs() < 1e-5 && (p2 / power - 1.0).abs() < 1e-5,
            "{a2}/{area} {p2}/{power}"
        );
        for l in &lights.lights {
            assert_eq!(l.vertices.len(), 4);
            let v = &l.vertices;
            let n = (v[1] - v[0]).cross(v[2] - v[0]);
            assert!(n.dot(l.normal) > 0.0 && (l.normal.length() - 1.0).abs() < 1e-5);
            assert!((0.5 * n.length() * 2.0 / l.area - 1.0).abs() < 1e-4, "a quad of the cluster's area");
            assert!(
                (l.centroid() - Vec3::new(0.0, 1.0, 0.0)).length() < 0.5 + 1e-3,
                "inside the sphere's bounds"
            );
        }
        assert!(
            lights.lights.iter().any(|l| l.normal.y > 0.3) && lights.lights.iter().any(|l| l.normal.y < -0.3)
        );
        // Within the budget nothing is merged.
        let all = area_lights(&scene, polys.len());
        assert!(!all.clustered && all.lights.len() == polys.len());
    }

    /// The budget shared by material power: with more materials than lights the dimmest are
    /// left out and their share of the power reported.
    #[test]
    fn the_budget_is_shared_by_material_and_the_left_out_power_is_counted() {
        let mut scene =
            scene_with(crate::builtin::shapes::sphere(Vec3::ZERO, 0.5, 8, 8, 0), Vec3::splat(4.0));
        for (k, e) in [(1usize, 1.0f32), (2, 0.5)] {
            scene.materials.push(Material {
                emissive: Vec3::splat(e),
                base_color: Vec4::ONE,
                ..Default::default()
            });
            scene.meshes.push(crate::builtin::shapes::sphere(Vec3::X * 2.0 * k as f32, 0.5, 8, 8, k));
        }
        let total: f64 = emitters(&scene).iter().map(|e| e.power()).sum();
        let l = area_lights(&scene, 6);
        assert_eq!(l.lights.len(), 6);
        assert_eq!(l.dropped_power, 0.0);
        let kept: f64 = l.lights.iter().map(|e| e.power()).sum();
        assert!((kept / total - 1.0).abs() < 1e-5);
        // The brightest material gets most of the lights.
        let per = |m: usize| l.lights.iter().filter(|e| scene.meshes[e.mesh].material == m).count();
        assert!(per(0) >= per(1) && per(1) >= per(2) && per(2) >= 1, "{} {} {}", per(0), per(1), per(2));
        let two = area_lights(&scene, 2);
        assert_eq!(two.lights.len(), 2);
        let dim: f64 =
            emitters(&scene).iter().filter(|e| scene.meshes[e.mesh].material == 2).map(|e| e.power()).sum();
        assert!((two.dropped_power - dim / total).abs() < 1e-9, "{}", two.dropped_power);
    }

    /// A textured emitter's polygons carry their own part of the texture: a quad mapped to the
    /// black half of a black-and-white image emits nothing and is left out.
    #[test]
    fn each_polygon_takes_its_own_part_of_the_emissive_texture() {
        let t = Texture {
            name: "bw".into(),
            width: 2,
            height: 1,
            rgba8: vec![0, 0, 0, 255, 255, 255, 255, 255],
            srgb: true,
            sampler: Default::default(),
        };
        let tri = |u0: f32, u1: f32| [Vec2::new(u0, 0.0), Vec2::new(u1, 0.0), Vec2::new(u0, 1.0)];
        assert_eq!(texture_mean(&t, tri(0.0, 0.5)), Vec3::ZERO);
        assert_eq!(texture_mean(&t, tri(0.5, 1.0)), Vec3::ONE);
        let whole = texture_mean(&t, [Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)]);
        assert!(whole.x > 0.2 && whole.x < 0.8, "{whole}");
        let mut m = quad_mesh(false);
        m.uvs = vec![Vec2::new(0.0, 0.0), Vec2::new(0.5, 0.0), Vec2::new(0.5, 1.0), Vec2::new(0.0, 1.0)];
        let mut scene = scene_with(m, Vec3::ONE);
        scene.textures.push(t);
        scene.materials[0].emissive_texture = Some(TextureRef::new(0));
        assert!(emitters(&scene).is_empty());
        let mut m = quad_mesh(false);
        m.uvs = vec![Vec2::new(0.5, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.5, 1.0)];
        scene.meshes[0] = m;
        assert_eq!(emitters(&scene)[0].emission.rgb, Vec3::ONE);
    }

    #[test]
    fn dark_and_stood_in_meshes_are_not_emitters() {
        assert!(emitters(&scene_with(quad_mesh(false), Vec3::ZERO)).is_empty());
        // The built-in Cornell box's lamp has a point-light stand-in.
        assert!(emitters(&crate::builtin("cornell").unwrap()).is_empty());
    }
}
