//! `dense:N`: the Cornell box with a faceted sphere of about N triangles, for measuring how
//! both renderers cope with large meshes (issue 14: a 5-million-triangle mesh must render in
//! real time and in the path tracer).
//!
//! The sphere is flat-shaded with three vertices of its own per triangle, as glTF exporters
//! write hard-edged meshes: 5 M triangles are 15 M vertices, 1.08 GB of GPU vertex data, four
//! times wgpu's default `max_buffer_size`, so the real-time upload must split it.

use glam::Vec3;

use super::cornell;
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Mesh, Scene};

/// The most triangles `dense:N` builds (~3 GB for the scene alone at the cap).
pub const MAX_TRIANGLES: u64 = 50_000_000;

/// The scene for `dense:N` (`N` with optional `_` separators, or `5M`/`200k`).
pub(crate) fn build(ctx: &Ctx, n: &str) -> Result<Scene, SceneError> {
    let triangles = parse_count(n).filter(|t| (1..=MAX_TRIANGLES).contains(t)).ok_or_else(|| {
        ctx.invalid("dense:N", format!("'{n}': N must be a triangle count from 1 to {MAX_TRIANGLES}"))
    })?;
    let mut s = cornell::build(ctx)?;
    s.meshes.push(sphere(Vec3::new(0.0, 0.42, 0.1), 0.11, triangles as usize, 0));
    Ok(s)
}

fn parse_count(n: &str) -> Option<u64> {
    let n = n.trim().replace('_', "");
    let (digits, scale) = match n.to_ascii_lowercase().chars().last()? {
        'k' => (&n[..n.len() - 1], 1_000.0),
        'm' => (&n[..n.len() - 1], 1_000_000.0),
        _ => (&n[..], 1.0),
    };
    let v = digits.parse::<f64>().ok()? * scale;
    (v.is_finite() && v >= 1.0).then_some(v.round() as u64)
}

/// A UV sphere of `rings × segments` quads (two triangles each, about `triangles` in all),
/// flat-shaded: every triangle has its own three vertices and its face normal.
pub(crate) fn sphere(centre: Vec3, radius: f32, triangles: usize, material: usize) -> Mesh {
    let rings = ((triangles as f64 / 4.0).sqrt().round() as usize).max(2);
    let segments = (triangles / (2 * rings)).max(3);
    let point = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        let phi = std::f32::consts::TAU * j as f32 / segments as f32;
        centre + radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let quads = rings * segments;
    let mut positions = Vec::with_capacity(quads * 6);
    let mut normals = Vec::with_capacity(quads * 6);
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1));
            // Counter-clockwise seen from outside; the poles' degenerate triangles stay (a
            // real mesh has some too).
            for tri in [[a, c, b], [a, d, c]] {
                let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
                let radial = (tri[0] + tri[1] + tri[2]) / 3.0 - centre;
                // At the poles a triangle collapses to rounding error and its cross product
                // points anywhere: use the radial direction there.
                let n = if n.dot(radial) > 0.0 { n.normalize() } else { radial.normalize() };
                positions.extend_from_slice(&tri);
                normals.extend_from_slice(&[n; 3]);
            }
        }
    }
    let indices = (0..positions.len() as u32).collect();
    Mesh {
        positions,
        normals,
        tangents: Vec::new(),
        uvs: Vec::new(),
        uvs1: Vec::new(),
        colors: Vec::new(),
        indices,
        material,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_parse_and_the_sphere_faces_out() {
        assert_eq!(parse_count("5M"), Some(5_000_000));
        assert_eq!(parse_count("200k"), Some(200_000));
        assert_eq!(parse_count("1_000"), Some(1000));
        assert_eq!(parse_count("x"), None);
        let m = sphere(Vec3::ZERO, 1.0, 10_000, 0);
        let t = m.indices.len() / 3;
        assert!((9_000..=11_000).contains(&t), "{t}");
        assert_eq!(m.positions.len(), m.indices.len());
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(p.dot(*n) > 0.0);
        }
        let e = crate::builtin("dense:0").unwrap_err().to_string();
        assert!(e.contains("dense:N"), "{e}");
        let s = crate::builtin("dense:2k").unwrap();
        assert_eq!(s.source, "builtin:dense:2k");
    }
}
