//! Tangent generation for normal-mapped meshes that ship without tangents, with MikkTSpace
//! (what the glTF specification asks for, and what normal-map bakers assume).

use bevy_mikktspace::{Geometry, TangentSpace, generate_tangents};
use glam::{Vec2, Vec3, Vec4};

struct Soup<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    uvs: &'a [Vec2],
    indices: &'a [u32],
    out: Vec<Vec4>,
}

impl Soup<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.indices[face * 3 + vert] as usize
    }
}

impl Geometry for Soup<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.vertex(face, vert)].to_array()
    }
    fn set_tangent(&mut self, t: Option<TangentSpace>, face: usize, vert: usize) {
        // Degenerate faces with no neighbours get no tangent space; any frame orthogonal to the
        // normal is as good as another there.
        let n = self.normals[self.vertex(face, vert)];
        let t = t
            .map(|t| Vec4::from_array(t.tangent_encoded()))
            .unwrap_or_else(|| n.any_orthonormal_vector().extend(1.0));
        self.out[face * 3 + vert] = t;
    }
}

/// MikkTSpace tangents for an indexed triangle mesh, one per face corner (`indices[k]` gets
/// `result[k]`): MikkTSpace works per corner, so the caller un-indexes the mesh to use them.
pub(crate) fn generate(positions: &[Vec3], normals: &[Vec3], uvs: &[Vec2], indices: &[u32]) -> Vec<Vec4> {
    let mut soup = Soup { positions, normals, uvs, indices, out: vec![Vec4::ZERO; indices.len()] };
    // The crate's error type has no variants today; should one appear, fall back to arbitrary
    // frames orthogonal to the normals rather than fail the load.
    if generate_tangents(&mut soup).is_err() {
        for (t, i) in soup.out.iter_mut().zip(indices) {
            *t = normals[*i as usize].any_orthonormal_vector().extend(1.0);
        }
    }
    soup.out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_in_xy_with_u_along_x_has_tangent_x() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let n = [Vec3::Z; 4];
        let uv = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
        let t = generate(&p, &n, &uv, &[0, 1, 2, 0, 2, 3]);
        assert_eq!(t.len(), 6);
        for t in t {
            assert!(t.truncate().abs_diff_eq(Vec3::X, 1e-5), "{t}");
            // glTF's v runs down the image, here along −y; the bitangent cross(n, t)·w must
            // follow increasing v, and cross(z, x) = +y, so w = −1.
            assert_eq!(t.w, -1.0, "{t}");
        }
    }
}
