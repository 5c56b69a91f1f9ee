//! One glTF primitive → one world-space [`Mesh`]: triangulation, flat normals when the file has
//! none, MikkTSpace tangents when a normal map needs them, and the node transform applied.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Mode;

use crate::accessors::{self, Expect};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Mesh, tangents};

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

fn accessor<'a>(
    ctx: &Ctx,
    at: &str,
    acc: Option<gltf::Accessor<'a>>,
    want: &Expect,
    buffers: &[Vec<u8>],
) -> Result<Option<gltf::Accessor<'a>>, SceneError> {
    if let Some(a) = &acc {
        accessors::check(ctx, at, a, want, buffers)?;
    }
    Ok(acc)
}

/// Builds the world-space mesh of `prim` under node transform `world`. `material` is the index
/// the mesh will use; `needs_tangents` is set when that material has a normal map.
pub(crate) fn build(
    ctx: &Ctx,
    at: &str,
    prim: &gltf::Primitive,
    world: Mat4,
    buffers: &[Vec<u8>],
    material: usize,
    needs_tangents: bool,
) -> Result<Mesh, SceneError> {
    use gltf::Semantic as S;
    let pos_acc = accessor(
        ctx,
        &format!("{at}.attributes.POSITION"),
        prim.get(&S::Positions),
        &accessors::POSITION,
        buffers,
    )?
    .ok_or_else(|| ctx.invalid(at, "has no POSITION attribute"))?;
    let n_acc = accessor(
        ctx,
        &format!("{at}.attributes.NORMAL"),
        prim.get(&S::Normals),
        &accessors::NORMAL,
        buffers,
    )?;
    let t_acc = accessor(
        ctx,
        &format!("{at}.attributes.TANGENT"),
        prim.get(&S::Tangents),
        &accessors::TANGENT,
        buffers,
    )?;
    let uv_acc = accessor(
        ctx,
        &format!("{at}.attributes.TEXCOORD_0"),
        prim.get(&S::TexCoords(0)),
        &accessors::TEXCOORD,
        buffers,
    )?;
    let i_acc = accessor(ctx, &format!("{at}.indices"), prim.indices(), &accessors::INDEX, buffers)?;
    let n = pos_acc.count();
    for (name, a) in [("NORMAL", &n_acc), ("TANGENT", &t_acc), ("TEXCOORD_0", &uv_acc)] {
        if let Some(a) = a
            && a.count() != n
        {
            return Err(ctx.invalid(at, format!("{name} has {} elements but POSITION has {n}", a.count())));
        }
    }

    let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let short = |what: &str| ctx.invalid(at, format!("{what} could not be read from its buffer"));
    let positions: Vec<Vec3> =
        reader.read_positions().ok_or_else(|| short("POSITION"))?.map(Vec3::from).collect();
    let normals: Option<Vec<Vec3>> = match &n_acc {
        Some(_) => Some(reader.read_normals().ok_or_else(|| short("NORMAL"))?.map(Vec3::from).collect()),
        None => None,
    };
    let file_tangents: Option<Vec<Vec4>> = match &t_acc {
        Some(_) => Some(reader.read_tangents().ok_or_else(|| short("TANGENT"))?.map(Vec4::from).collect()),
        None => None,
    };
    let uvs: Vec<Vec2> = match &uv_acc {
        Some(_) => {
            reader.read_tex_coords(0).ok_or_else(|| short("TEXCOORD_0"))?.into_f32().map(Vec2::from).collect()
        }
        None => Vec::new(),
    };
    let raw_idx: Vec<u32> = match &i_acc {
        Some(_) => reader.read_indices().ok_or_else(|| short("indices"))?.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if positions.len() != n || raw_idx.is_empty() {
        return Err(short("the vertex data"));
    }
    if let Some(bad) = raw_idx.iter().find(|&&i| i as usize >= n) {
        return Err(
            ctx.invalid(format!("{at}.indices"), format!("index {bad} is out of range for {n} vertices"))
        );
    }
    if let Some(p) = positions.iter().find(|p| !p.is_finite()) {
        return Err(ctx.invalid(format!("{at}.attributes.POSITION"), format!("non-finite position {p}")));
    }
    let mut indices = triangulate(ctx, at, prim.mode(), raw_idx)?;

    let mut mesh = match normals {
        Some(normals) => {
            let tangents = file_tangents.unwrap_or_default();
            Mesh { colors: vec![], uvs1: vec![], positions, normals, tangents, uvs, indices, material }
        }
        None => {
            // glTF: without normals, flat normals. Each triangle needs its own vertices.
            let corner = |i: &u32| *i as usize;
            let p: Vec<Vec3> = indices.iter().map(|i| positions[corner(i)]).collect();
            let uv: Vec<Vec2> =
                if uvs.is_empty() { Vec::new() } else { indices.iter().map(|i| uvs[corner(i)]).collect() };
            let nrm: Vec<Vec3> = p
                .chunks_exact(3)
                .flat_map(|t| {
                    let f = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                    // A degenerate triangle has no area to shade; any unit normal will do.
                    [if f == Vec3::ZERO { Vec3::Z } else { f }; 3]
                })
                .collect();
            indices = (0..p.len() as u32).collect();
            // File tangents were per original vertex; flat shading re-indexed, so regenerate.
            Mesh {
                colors: vec![],
                uvs1: vec![],
                positions: p,
                normals: nrm,
                tangents: Vec::new(),
                uvs: uv,
                indices,
                material,
            }
        }
    };
    for nrm in &mut mesh.normals {
        // Files carry un-normalised or zero normals surprisingly often.
        *nrm = nrm.try_normalize().unwrap_or(Vec3::Z);
    }
    if needs_tangents && mesh.tangents.is_empty() {
        if mesh.uvs.is_empty() {
            return Err(ctx.invalid(
                at,
                "its material has a normal map but the primitive has no TEXCOORD_0 to orient it",
            ));
        }
        let (p, nrm, uv, t, idx) =
            tangents::generate(&mesh.positions, &mesh.normals, &mesh.uvs, &mesh.indices);
        mesh = Mesh {
            colors: vec![],
            uvs1: vec![],
            positions: p,
            normals: nrm,
            tangents: t,
            uvs: uv,
            indices: idx,
            material,
        };
    }
    if !needs_tangents {
        mesh.tangents.clear();
    }
    to_world(&mut mesh, world);
    Ok(mesh)
}

/// Applies a node transform: positions by the matrix, normals by its inverse transpose,
/// tangents by its linear part with handedness flipped and winding reversed when it mirrors.
fn to_world(mesh: &mut Mesh, world: Mat4) {
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
