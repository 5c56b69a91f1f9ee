//! One glTF primitive → one [`Mesh`]: attributes read and dequantized, triangulation, then the
//! scene's vertex convention ([`Mesh::complete`]: flat normals when the file has none,
//! MikkTSpace tangents when a normal map needs them); [`to_world`] applies a node (or
//! instance) transform.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;

use crate::Mesh;
use crate::accessors::{self, Expect};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::pose::{self, Deform};

/// Triangle list indices for `mode`, from the primitive's indices (or 0..n when unindexed).
fn triangulate(ctx: &Ctx, at: &str, mode: Mode, idx: Vec<u32>) -> Result<Vec<u32>, SceneError> {
    Ok(match mode {
        Mode::Triangles => {
            let n = idx.len() - idx.len() % 3;
            idx[..n].to_vec()
        }
        Mode::TriangleStrip => (2..idx.len())
            .flat_map(|i| {
                if i % 2 == 0 { [idx[i - 2], idx[i - 1], idx[i]] } else { [idx[i - 1], idx[i - 2], idx[i]] }
            })
            .collect(),
        Mode::TriangleFan => (2..idx.len()).flat_map(|i| [idx[i - 1], idx[i], idx[0]]).collect(),
        other => {
            return Err(ctx.invalid(
                at,
                format!("unsupported primitive mode {other:?}: only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN can be rendered"),
            ));
        }
    })
}

/// What the primitive's material asks of its vertex data.
#[derive(Clone, Debug, Default)]
pub(crate) struct Needs {
    /// The tangent frame the material needs ([`crate::Material::tangent_need`]).
    pub tangents: Option<crate::TangentNeed>,
    /// The field of a texture that reads `TEXCOORD_1`, if any (named in the error when the
    /// primitive has none).
    pub set1_user: Option<String>,
}

/// Whether a primitive mode has area (the others are points and lines).
pub(crate) fn is_triangles(mode: Mode) -> bool {
    matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan)
}

/// Builds the mesh of `prim` in its node's local space (see [`to_world`]), morphed by
/// `deform`'s weights; skinned by its joints, the mesh comes out in world space instead.
/// `material` is the index the mesh will use.
pub(crate) fn build(
    ctx: &Ctx,
    at: &str,
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    material: usize,
    needs: &Needs,
    deform: &Deform,
) -> Result<Mesh, SceneError> {
    use gltf::Semantic as S;
    let pos_at = format!("{at}.attributes.POSITION");
    let pos_acc = prim.get(&S::Positions).ok_or_else(|| ctx.invalid(at, "has no POSITION attribute"))?;
    accessors::check(ctx, &pos_at, &pos_acc, &accessors::POSITION, buffers)?;
    let n = pos_acc.count();
    // Each attribute checked (type, range, count), then read as floats, `width` per vertex.
    let attr = |sem: S, name: &str, want: &Expect| -> Result<Option<(Vec<f32>, usize)>, SceneError> {
        let Some(a) = prim.get(&sem) else { return Ok(None) };
        let f = format!("{at}.attributes.{name}");
        accessors::check(ctx, &f, &a, want, buffers)?;
        if a.count() != n {
            return Err(ctx.invalid(at, format!("{name} has {} elements but POSITION has {n}", a.count())));
        }
        Ok(Some((accessors::read_f32(ctx, &f, &a, buffers)?, a.dimensions().multiplicity())))
    };
    let vec2 = |v: Option<(Vec<f32>, usize)>| -> Vec<Vec2> {
        v.map(|(f, _)| f.chunks_exact(2).map(Vec2::from_slice).collect()).unwrap_or_default()
    };
    let vec3 = |v: Option<(Vec<f32>, usize)>| -> Option<Vec<Vec3>> {
        v.map(|(f, _)| f.chunks_exact(3).map(Vec3::from_slice).collect())
    };
    let mut positions =
        vec3(Some((accessors::read_f32(ctx, &pos_at, &pos_acc, buffers)?, 3))).unwrap_or_default();
    let mut normals = vec3(attr(S::Normals, "NORMAL", &accessors::NORMAL)?);
    let mut file_tangents: Vec<Vec4> = attr(S::Tangents, "TANGENT", &accessors::TANGENT)?
        .map(|(f, _)| f.chunks_exact(4).map(Vec4::from_slice).collect())
        .unwrap_or_default();
    let uvs = vec2(attr(S::TexCoords(0), "TEXCOORD_0", &accessors::TEXCOORD)?);
    let uvs1 = vec2(attr(S::TexCoords(1), "TEXCOORD_1", &accessors::TEXCOORD)?);
    let colors: Vec<Vec4> = match attr(S::Colors(0), "COLOR_0", &accessors::COLOR)? {
        Some((f, 3)) => f.chunks_exact(3).map(|c| Vec3::from_slice(c).extend(1.0)).collect(),
        Some((f, _)) => f.chunks_exact(4).map(Vec4::from_slice).collect(),
        None => Vec::new(),
    };
    let raw_idx: Vec<u32> = match prim.indices() {
        Some(a) => {
            let f = format!("{at}.indices");
            accessors::check(ctx, &f, &a, &accessors::INDEX, buffers)?;
            accessors::read_u32(ctx, &f, &a, buffers)?
        }
        None => (0..n as u32).collect(),
    };
    if positions.len() != n || raw_idx.is_empty() {
        return Err(ctx.invalid(at, "the vertex data could not be read from its buffer"));
    }
    // Messages give positions, never the values read: a buffer may be a file that is not the
    // scene's (see `Ctx::resolve`), and its bytes must not be echoed.
    if let Some(k) = raw_idx.iter().position(|&i| i as usize >= n) {
        return Err(ctx.invalid(
            format!("{at}.indices"),
            format!("index number {k} is out of range (not below the {n} vertices)"),
        ));
    }
    if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
        return Err(ctx.invalid(pos_at, format!("position {k} is not finite")));
    }
    if let Some(field) = &needs.set1_user
        && uvs1.is_empty()
    {
        return Err(ctx.invalid(
            at,
            format!("{field} reads TEXCOORD_1, but the primitive has no TEXCOORD_1 attribute"),
        ));
    }
    let mut indices = triangulate(ctx, at, prim.mode(), raw_idx)?;
    if deform.morphs() {
        let v = pose::Vertices {
            positions: &mut positions,
            normals: normals.as_deref_mut(),
            tangents: &mut file_tangents,
        };
        pose::morph(ctx, at, prim, buffers, deform.weights, v)?;
    }
    if let Some(joints) = deform.joints {
        let (m, unweighted) = pose::skin_matrices(ctx, at, prim, buffers, joints, deform.fallback)?;
        deform.unweighted.set(deform.unweighted.get() + unweighted);
        let normals = normals.as_deref_mut().unwrap_or(&mut []);
        pose::apply_skin(&m, &mut positions, normals, &mut file_tangents, &mut indices);
    }
    if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
        return Err(ctx.invalid(at, format!("vertex {k} is not finite once morphed and skinned")));
    }

    let mesh = Mesh {
        colors,
        uvs1,
        positions,
        normals: normals.unwrap_or_default(),
        tangents: file_tangents,
        uvs,
        indices,
        material,
    };
    mesh.complete(needs.tangents).map_err(|m| ctx.invalid(at, m))
}

/// Applies a node transform: positions by the matrix, normals by its inverse transpose,
/// tangents by its linear part with handedness flipped and winding reversed when it mirrors.
pub(crate) fn to_world(mesh: &mut Mesh, world: Mat4) {
    let lin = Mat3::from_mat4(world);
    let det = lin.determinant();
    let normal_m = if det.abs() > f32::MIN_POSITIVE { lin.inverse().transpose() } else { lin };
    for p in &mut mesh.positions {
        *p = world.transform_point3(*p);
    }
    for n in &mut mesh.normals {
        *n = (normal_m * *n).try_normalize().unwrap_or(Vec3::Z);
    }
    let sign = if det < 0.0 { -1.0 } else { 1.0 };
    for t in &mut mesh.tangents {
        let x = (lin * t.truncate()).try_normalize().unwrap_or(Vec3::X);
        *t = x.extend(if t.w < 0.0 { -sign } else { sign });
    }
    if det < 0.0 {
        for tri in mesh.indices.chunks_exact_mut(3) {
            tri.swap(1, 2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirroring_flips_winding_and_handedness() {
        let mut m = Mesh {
            colors: vec![],
            uvs1: vec![],
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 3],
            uvs: vec![Vec2::ZERO; 3],
            indices: vec![0, 1, 2],
            material: 0,
        };
        to_world(&mut m, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        assert_eq!(m.indices, vec![0, 2, 1]);
        assert_eq!(m.tangents[0], Vec4::new(-1.0, 0.0, 0.0, -1.0));
        // Geometric normal of the re-wound triangle agrees with the transformed shading normal.
        let p = &m.positions;
        let g = (p[2] - p[0]).cross(p[1] - p[0]).normalize();
        assert!(g.abs_diff_eq(m.normals[0], 1e-6), "{g} vs {}", m.normals[0]);
    }

    #[test]
    fn strips_and_fans_triangulate() {
        let c = Ctx::builtin("t");
        assert_eq!(
            triangulate(&c, "p", Mode::TriangleStrip, vec![0, 1, 2, 3]).unwrap(),
            vec![0, 1, 2, 2, 1, 3]
        );
        assert_eq!(
            triangulate(&c, "p", Mode::TriangleFan, vec![0, 1, 2, 3]).unwrap(),
            vec![1, 2, 0, 2, 3, 0]
        );
        let e = triangulate(&c, "meshes[0].primitives[0]", Mode::Lines, vec![0, 1]).unwrap_err().to_string();
        assert!(e.contains("meshes[0].primitives[0]") && e.contains("Lines"), "{e}");
    }
}
