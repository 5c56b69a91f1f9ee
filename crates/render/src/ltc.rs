//! Linearly transformed cosines (Heitz, Dupuy, Hill, Neubelt 2016): the specular lobe of the
//! glTF BRDF over a polygon light, for `polygon_terms` in passes/shading.wgsl.
//!
//! The lobe D·V·(n·l) (GGX, height-correlated Smith; the path tracer's, `truth::bsdf`) at view
//! cosine n·v and roughness r is approximated, up to its albedo, by a clamped cosine whose
//! directions are transformed by a 3×3 matrix M. Its integral over a polygon is the cosine's
//! over the polygon transformed by M⁻¹, which Lambert's formula gives exactly (the same clipped
//! edge sum as the diffuse term). The table (`data/ltc_ggx.bin`, fitted by `tools/fit_ltc.py`
//! to this renderer's own lobe) holds per cell M⁻¹ in the frame (t₁, n × t₁, n) with t₁ the
//! view direction's tangent part, and the lobe's split-sum albedo (A, B): ∫ f·cos·F =
//! F0·A + B for Schlick's F.
//!
//! Cells: roughness r = i / 63 (columns) and t = j / 63 (rows) with n·v = 1 − t², at texel
//! centres, so that a bilinear sample at ((63·r + ½) / 64, (63·t + ½) / 64) interpolates them.

use half::f16;

/// Cells per axis.
pub const SIZE: usize = 64;

static DATA: &[u8] = include_bytes!("../data/ltc_ggx.bin");

/// One cell: M⁻¹'s entries (0,0), (0,2), (2,0), (2,2) divided by its (1,1) (the others are
/// zero; the transformed cosine does not change when M⁻¹ is scaled), and the lobe's (A, B).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    pub minv: [f32; 4],
    pub a: f32,
    pub b: f32,
}

/// The table's cells, row (t) major.
pub fn cells() -> Vec<Cell> {
    assert_eq!(DATA.len(), SIZE * SIZE * 8 * 4, "data/ltc_ggx.bin: 64 × 64 cells of 8 f32");
    DATA.chunks_exact(32)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]]);
            Cell { minv: [f(0), f(1), f(2), f(3)], a: f(4), b: f(5) }
        })
        .collect()
}

/// The table as a two-layer RGBA16F texture (layer 0: M⁻¹, layer 1: (A, B, 0, 0)), sampled
/// bilinearly by the shading pass.
pub fn upload(device: &wgpu::Device, queue: &wgpu::Queue) -> wgpu::TextureView {
    let cells = cells();
    let h = f16::from_f32;
    let mut texels: Vec<[f16; 4]> = cells.iter().map(|c| c.minv.map(h)).collect();
    texels.extend(cells.iter().map(|c| [h(c.a), h(c.b), f16::ZERO, f16::ZERO]));
    let size = SIZE as u32;
    crate::gpu::rgba16f_table(
        device,
        queue,
        "linearly transformed cosines",
        (size, size, 2),
        &texels,
        wgpu::TextureViewDimension::D2Array,
    )
}

/// The table bilinearly interpolated at (roughness, n·v), as the shader samples it (in f32).
pub fn lookup(cells: &[Cell], roughness: f32, nv: f32) -> Cell {
    let x = roughness.clamp(0.0, 1.0) * (SIZE - 1) as f32;
    let y = (1.0 - nv.clamp(0.0, 1.0)).sqrt() * (SIZE - 1) as f32;
    let (x0, y0) = ((x.floor() as usize).min(SIZE - 2), (y.floor() as usize).min(SIZE - 2));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |i: usize, j: usize| cells[j * SIZE + i];
    let mix = |a: Cell, b: Cell, t: f32| Cell {
        minv: std::array::from_fn(|k| a.minv[k] + (b.minv[k] - a.minv[k]) * t),
        a: a.a + (b.a - a.a) * t,
        b: a.b + (b.b - a.b) * t,
    };
    mix(mix(at(x0, y0), at(x0 + 1, y0), fx), mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), fx), fy)
}

/// ∫ max(z, 0) / π over the polygon `vertices` (directions from the shading point, any
/// length, in a frame whose z is the cosine's axis), clipped to z > 0: Lambert's formula, as
/// `polygon_form_factor` in shading.wgsl evaluates it.
pub fn form_factor(vertices: &[glam::Vec3]) -> f32 {
    let edge = |a: glam::Vec3, b: glam::Vec3| {
        let (ua, ub) = (a.normalize(), b.normalize());
        let c = ua.cross(ub);
        let s = c.length();
        if s <= 1e-7 { 0.0 } else { s.atan2(ua.dot(ub)) * c.z / s }
    };
    let n = vertices.len();
    let (mut sum, mut crossings, mut above) = (0.0, 0, 0);
    let (mut exit, mut entry) = (glam::Vec3::ZERO, glam::Vec3::ZERO);
    for i in 0..n {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        if a.z > 0.0 {
            above += 1;
        }
        if a.z > 0.0 && b.z > 0.0 {
            sum += edge(a, b);
        } else if a.z > 0.0 {
            exit = a + (b - a) * (a.z / (a.z - b.z));
            sum += edge(a, exit);
            crossings += 1;
        } else if b.z > 0.0 {
            entry = a + (b - a) * (a.z / (a.z - b.z));
            sum += edge(entry, b);
            crossings += 1;
        }
    }
    if above == 0 {
        return 0.0;
    }
    if crossings == 2 {
        sum += edge(exit, entry);
    }
    0.5 * sum.abs() / std::f32::consts::PI
}

/// M⁻¹ of a cell as a matrix (rows and columns as in the module's docs).
pub fn minv_matrix(c: &Cell) -> glam::Mat3 {
    let [m00, m02, m20, m22] = c.minv;
    glam::Mat3::from_cols(glam::Vec3::new(m00, 0.0, m20), glam::Vec3::Y, glam::Vec3::new(m02, 0.0, m22))
}

/// The specular lobe's integral over a polygon (vertices relative to the shading point, in the
/// frame (t₁, n × t₁, n)) by the table: ∫ D·V·(n·l) dl over it with Fresnel F0.
pub fn polygon_specular(cells: &[Cell], roughness: f32, nv: f32, f0: f32, vertices: &[glam::Vec3]) -> f32 {
    let c = lookup(cells, roughness, nv);
    let m = minv_matrix(&c);
    let t: Vec<glam::Vec3> = vertices.iter().map(|&v| m * v).collect();
    form_factor(&t) * (f0 * c.a + c.b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn the_table_is_finite_and_its_albedo_at_most_one() {
        for (k, c) in cells().iter().enumerate() {
            assert!(c.minv.iter().all(|v| v.is_finite()), "cell {k}: {c:?}");
            assert!(c.a >= 0.0 && c.b >= 0.0 && c.a + c.b <= 1.0 + 1e-3, "cell {k}: {c:?}");
        }
    }

    /// The lobe D·V·(n·l) with Schlick's F (truth::bsdf's specular term), exactly.
    fn lobe(l: Vec3, v: Vec3, roughness: f32, f0: f32) -> f64 {
        let (nl, nv) = (l.z as f64, v.z as f64);
        if nl <= 0.0 {
            return 0.0;
        }
        let alpha = ((roughness * roughness) as f64).max(1e-3);
        let a2 = alpha * alpha;
        let h = (l + v).normalize();
        let nh = h.z as f64;
        let dd = nh * nh * (a2 - 1.0) + 1.0;
        let d = a2 / (std::f64::consts::PI * dd * dd);
        let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
        let vh = (v.dot(h) as f64).clamp(0.0, 1.0);
        let f = f0 as f64 + (1.0 - f0 as f64) * (1.0 - vh).powi(5);
        d * vis * nl * f
    }

    /// ∫ lobe dl over the parallelogram o + s·u + t·v (s, t ∈ [0, 1]) by the midpoint rule
    /// on `n`² points (dl = |cos θ'| dA / d²).
    fn exact(o: Vec3, u: Vec3, w: Vec3, v: Vec3, roughness: f32, f0: f32, n: usize) -> f64 {
        let normal = u.cross(w);
        let area = normal.length() as f64;
        let normal = normal.normalize();
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let p = o + u * ((i as f32 + 0.5) / n as f32) + w * ((j as f32 + 0.5) / n as f32);
                let d2 = p.length_squared() as f64;
                let l = p.normalize();
                let cos = normal.dot(l).abs() as f64;
                sum += lobe(l, v, roughness, f0) * cos / d2;
            }
        }
        sum * area / (n * n) as f64
    }

    /// The table against the lobe it stands for: squares of light around the mirror direction
    /// and beside it, over roughness and view angle, as `polygon_terms` uses them, with F0 = 1
    /// (the fit itself) and 0.04 (also the split of Fresnel into F0·A + B). Errors relative to
    /// the lobe's albedo (what a highlight's brightness is measured in). Squares that reach
    /// below the horizon are left out: the transformed cosine is clipped to its own hemisphere,
    /// not the surface's, so a light straddling the horizon gets some of the lobe's tail that
    /// is not there (up to 13 % of the albedo at 80° for a square of 28° there).
    #[test]
    fn polygon_integrals_match_the_lobe() {
        for (f0, degrees, bound) in
            [(1.0f32, 60.0, 0.015f64), (1.0, 75.0, 0.06), (0.04, 60.0, 0.07), (0.04, 75.0, 0.3)]
        {
            let worst = polygon_errors(f0, degrees);
            eprintln!("F0 {f0}, view at {degrees}°: worst error {worst:.4} of the lobe's albedo");
            assert!(worst < bound, "F0 {f0}, {degrees}°: worst error {worst:.4} of the albedo");
        }
    }

    /// The worst error over the cases whose view angle is `degrees`, or below it.
    fn polygon_errors(f0: f32, degrees: f32) -> f64 {
        let cells = cells();
        let mut worst = 0.0f64;
        let mut report = Vec::new();
        for &roughness in &[0.2f32, 0.35, 0.5, 0.75, 1.0] {
            for deg in [0.0f32, 30.0, 60.0, 75.0].into_iter().filter(|&d| d <= degrees) {
                let th = deg.to_radians();
                let v = Vec3::new(th.sin(), 0.0, th.cos());
                let mirror = Vec3::new(-v.x, 0.0, v.z);
                for &(shift, size) in &[(0.0f32, 0.3f32), (0.0, 1.0), (0.4, 0.5), (-0.3, 0.3)] {
                    // A square facing the point, 2 units away along the mirror direction
                    // turned by `shift` radians about y.
                    let dir = glam::Quat::from_rotation_y(shift) * mirror;
                    let c = dir * 2.0;
                    let u = dir.cross(Vec3::Y).normalize() * size;
                    let w = u.cross(dir).normalize() * size;
                    let o = c - 0.5 * (u + w);
                    let quad = [o, o + u, o + u + w, o + w];
                    if quad.iter().any(|q| q.z <= 0.0) {
                        continue;
                    }
                    let e = exact(o, u, w, v, roughness, f0, 320);
                    let nv = v.z.max(1e-4);
                    let ltc = polygon_specular(&cells, roughness, nv, f0, &quad) as f64;
                    let albedo = {
                        let c = lookup(&cells, roughness, nv);
                        (f0 * c.a + c.b) as f64
                    };
                    let err = (ltc - e).abs() / albedo;
                    report.push(format!("r {roughness} θ {deg}° shift {shift} size {size}: exact {e:.5} ltc {ltc:.5} (err {err:.4} of albedo {albedo:.4})"));
                    worst = worst.max(err);
                }
            }
        }
        eprintln!("{}", report.join("\n"));
        worst
    }

    #[test]
    fn a_polygon_around_the_whole_hemisphere_has_form_factor_one() {
        // A huge square just above the horizon plane covers the hemisphere.
        let q = [
            Vec3::new(-1e4, -1e4, 1.0),
            Vec3::new(1e4, -1e4, 1.0),
            Vec3::new(1e4, 1e4, 1.0),
            Vec3::new(-1e4, 1e4, 1.0),
        ];
        let f = form_factor(&q);
        assert!((f - 1.0).abs() < 1e-3, "{f}");
    }
}
