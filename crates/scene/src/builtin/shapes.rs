//! Quads and boxes for the built-in scenes, built directly in world space.

use glam::{Quat, Vec2, Vec3};

use crate::Mesh;

/// A parallelogram with corners `o`, `o+u`, `o+u+v`, `o+v`, facing `u × v`. UVs follow glTF
/// (origin at the image's top-left): `o` is the bottom-left of the texture, `o+u+v` its
/// top-right, so an image appears upright when `u` points right and `v` up.
pub(crate) fn quad(o: Vec3, u: Vec3, v: Vec3, material: usize) -> Mesh {
    let n = u.cross(v).normalize();
    Mesh {
        colors: vec![],
        uvs1: vec![],
        positions: vec![o, o + u, o + u + v, o + v],
        normals: vec![n; 4],
        tangents: Vec::new(),
        uvs: vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)],
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
    }
}

/// Appends `b` to `a` (same material).
pub(crate) fn merge(a: &mut Mesh, b: Mesh) {
    let base = a.positions.len() as u32;
    a.positions.extend(b.positions);
    a.normals.extend(b.normals);
    a.uvs.extend(b.uvs);
    a.indices.extend(b.indices.iter().map(|i| i + base));
}

/// A box standing on the plane y = `base.y`: footprint centred on `base`, `size` = (x, y, z)
/// extents, turned by `yaw` radians about +Y. Faces point outwards, each with the full texture.
pub(crate) fn cuboid(base: Vec3, size: Vec3, yaw: f32, material: usize) -> Mesh {
    let r = Quat::from_rotation_y(yaw);
    let h = size * 0.5;
    let c = base + Vec3::Y * h.y;
    let (x, y, z) = (r * Vec3::X * size.x, Vec3::Y * size.y, r * Vec3::Z * size.z);
    let corner = |sx: f32, sy: f32, sz: f32| c + r * Vec3::new(sx * h.x, sy * h.y, sz * h.z);
    let faces = [
        quad(corner(-1.0, -1.0, 1.0), x, y, material),  // +Z
        quad(corner(1.0, -1.0, -1.0), -x, y, material), // −Z
        quad(corner(1.0, -1.0, 1.0), -z, y, material),  // +X
        quad(corner(-1.0, -1.0, -1.0), z, y, material), // −X
        quad(corner(-1.0, 1.0, 1.0), x, -z, material),  // +Y
        quad(corner(-1.0, -1.0, -1.0), x, z, material), // −Y
    ];
    let mut it = faces.into_iter();
    let mut m = it.next().expect("six faces");
    for f in it {
        merge(&mut m, f);
    }
    m
}

/// A smooth UV sphere: `rings` × `segments` quads sharing their vertices, normals radial (the
/// exact sphere's, as the path tracer's interpolated normals give), counter-clockwise outside.
pub(crate) fn sphere(centre: Vec3, radius: f32, rings: u32, segments: u32, material: usize) -> Mesh {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for i in 0..=rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            positions.push(centre + radius * n);
            normals.push(n);
            uvs.push(Vec2::new(j as f32 / segments as f32, i as f32 / rings as f32));
        }
    }
    let row = segments + 1;
    let mut indices = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (i * row + j, (i + 1) * row + j, (i + 1) * row + j + 1, i * row + j + 1);
            // a and d meet at the top pole, b and c at the bottom one.
            if i + 1 < rings {
                indices.extend_from_slice(&[a, c, b]);
            }
            if i > 0 {
                indices.extend_from_slice(&[a, d, c]);
            }
        }
    }
    Mesh { colors: vec![], uvs1: vec![], positions, normals, tangents: Vec::new(), uvs, indices, material }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_faces_point_outwards_and_wind_counter_clockwise() {
        let b = cuboid(Vec3::new(1.0, 0.0, 2.0), Vec3::new(0.3, 0.5, 0.2), 0.4, 0);
        assert_eq!(b.indices.len(), 36);
        let centre = Vec3::new(1.0, 0.25, 2.0);
        for t in b.indices.chunks_exact(3) {
            let [a, p, q] = [0, 1, 2].map(|k| b.positions[t[k] as usize]);
            let geo = (p - a).cross(q - a).normalize();
            let n = b.normals[t[0] as usize];
            assert!(geo.abs_diff_eq(n, 1e-5), "winding {geo} vs normal {n}");
            assert!(n.dot((a + p + q) / 3.0 - centre) > 0.0, "normal {n} points inwards");
        }
        let (lo, hi) = crate::framing::bounds(std::slice::from_ref(&b)).unwrap();
        assert!((lo.y - 0.0).abs() < 1e-6 && (hi.y - 0.5).abs() < 1e-6);
    }
}
