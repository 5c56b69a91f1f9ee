//! The scene's vertex convention, written once for the loader and both renderers: every mesh
//! has unit normals, and a normal-mapped mesh has tangents. glTF 2.0 (§3.7.2.1, "Meshes"):
//! "When normals are not specified, client implementations MUST calculate flat normals and the
//! provided tangents (if present) MUST be ignored"; "When tangents are not specified, client
//! implementations SHOULD calculate tangents using default MikkTSpace algorithms". The loader
//! applies it to every primitive; the renderers take [`Scene::completed`], so a scene built in
//! code without normals is drawn faceted by both, exactly as the same mesh loaded from glTF.

use std::borrow::Cow;

use glam::Vec3;

use crate::{Mesh, Scene, TangentNeed, tangents};

/// A normal map on a UV set the mesh does not have (nothing to orient its tangents by).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "its material has a normal map on TEXCOORD_{set} but the primitive has no TEXCOORD_{set} to orient it"
)]
pub struct MissingUvError {
    pub set: u32,
}

fn corners<T: Copy>(v: &[T], idx: &[u32]) -> Vec<T> {
    if v.is_empty() { Vec::new() } else { idx.iter().map(|&i| v[i as usize]).collect() }
}

impl Mesh {
    /// Un-indexed: one vertex per triangle corner (what flat normals and MikkTSpace's
    /// per-corner tangents need).
    fn unindexed(self) -> Mesh {
        let idx = &self.indices;
        Mesh {
            positions: corners(&self.positions, idx),
            normals: corners(&self.normals, idx),
            tangents: corners(&self.tangents, idx),
            uvs: corners(&self.uvs, idx),
            uvs1: corners(&self.uvs1, idx),
            colors: corners(&self.colors, idx),
            indices: (0..idx.len() as u32).collect(),
            material: self.material,
        }
    }

    /// The mesh with the vertex convention of this module applied: flat normals when it has
    /// none (its tangents dropped), normals made unit length, and MikkTSpace tangents on the
    /// UV set of `need` when its material needs a tangent frame ([`Material::tangent_need`])
    /// and the mesh has no tangents, or [`crate::fallback_tangent`]s where that set is missing
    /// and not required (tangents are dropped when nothing needs them). Indices must be in
    /// range. The error is for the caller to place: a normal map whose UV set the mesh lacks.
    pub fn complete(self, need: Option<TangentNeed>) -> Result<Mesh, MissingUvError> {
        let mut mesh = if self.normals.is_empty() {
            let mut m = Mesh { tangents: Vec::new(), ..self }.unindexed();
            m.normals = m
                .positions
                .chunks_exact(3)
                .flat_map(|t| {
                    let f = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                    // A degenerate triangle has no area to shade; any unit normal will do.
                    [if f == Vec3::ZERO { Vec3::Z } else { f }; 3]
                })
                .collect();
            m
        } else {
            self
        };
        // Files carry un-normalised or zero normals surprisingly often. A zero (or non-finite)
        // one takes the area-weighted normal of the triangles that use the vertex, so that it
        // faces as its surface does (a fixed +Z made a zero-normal lamp emit sideways in the
        // path tracer and down in real time); +Z only where those have no area either.
        if mesh.normals.iter().any(|n| n.try_normalize().is_none()) {
            let mut faces = vec![Vec3::ZERO; mesh.normals.len()];
            for t in mesh.indices.chunks_exact(3) {
                let p = |i: u32| mesh.positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
                let f = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
                if f.is_finite() {
                    for &i in t {
                        if let Some(v) = faces.get_mut(i as usize) {
                            *v += f;
                        }
                    }
                }
            }
            for (nrm, f) in mesh.normals.iter_mut().zip(&faces) {
                if nrm.try_normalize().is_none() {
                    *nrm = f.try_normalize().unwrap_or(Vec3::Z);
                }
            }
        }
        for nrm in &mut mesh.normals {
            *nrm = nrm.try_normalize().unwrap_or(Vec3::Z);
        }
        match need {
            Some(TangentNeed { set, uv_required }) if mesh.tangents.is_empty() => {
                let uv = if set == 1 { &mesh.uvs1 } else { &mesh.uvs };
                if uv.is_empty() {
                    if uv_required {
                        return Err(MissingUvError { set });
                    }
                    mesh.tangents = mesh.normals.iter().map(|&n| crate::fallback_tangent(n)).collect();
                    return Ok(mesh);
                }
                let t = tangents::generate(&mesh.positions, &mesh.normals, uv, &mesh.indices);
                mesh = mesh.unindexed();
                mesh.tangents = t;
            }
            Some(_) => {}
            None => mesh.tangents.clear(),
        }
        Ok(mesh)
    }

    /// Whether the renderers could read this mesh at all (indices in range, whole triangles,
    /// one attribute per position); the renderers report the problem when it cannot.
    fn is_well_formed(&self, materials: usize) -> bool {
        let n = self.positions.len();
        self.material < materials
            && self.indices.len().is_multiple_of(3)
            && self.indices.iter().all(|&i| (i as usize) < n)
            && [self.normals.len(), self.tangents.len(), self.uvs.len(), self.uvs1.len(), self.colors.len()]
                .iter()
                .all(|&l| l == 0 || l == n)
    }
}

impl Scene {
    /// The tangent frame a mesh's material needs ([`Material::tangent_need`]), unless it is a
    /// normal map's whose UV set the mesh lacks (the loader refuses such a file; a scene built
    /// in code keeps it unoriented as before).
    fn tangent_need(&self, m: &Mesh) -> Option<TangentNeed> {
        let need = self.materials.get(m.material)?.tangent_need()?;
        let uv = if need.set == 1 { &m.uvs1 } else { &m.uvs };
        (!uv.is_empty() || !need.uv_required).then_some(need)
    }

    /// The scene with the vertex convention ([`Mesh::complete`]) applied to every mesh that
    /// lacks normals or the tangents its normal map needs; borrowed when none does (every
    /// loaded scene). What both renderers draw, so neither repairs meshes its own way.
    pub fn completed(&self) -> Cow<'_, Scene> {
        let needs = |m: &Mesh| {
            m.is_well_formed(self.materials.len())
                && (m.normals.is_empty() || (m.tangents.is_empty() && self.tangent_need(m).is_some()))
        };
        if !self.meshes.iter().any(needs) {
            return Cow::Borrowed(self);
        }
        let mut s = self.clone();
        s.meshes = self
            .meshes
            .iter()
            .map(|m| {
                if !needs(m) {
                    return m.clone();
                }
                // `complete` fails only for a normal map whose UV set is missing, which
                // `tangent_need` rules out; the mesh is kept as it is should that change.
                m.clone().complete(self.tangent_need(m)).unwrap_or_else(|_| m.clone())
            })
            .collect();
        Cow::Owned(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by a sweep: a lamp whose file gave zero normals faced +Z (a fixed stand-in), so the
    /// path tracer emitted it sideways and the real-time renderer (its winding) down. A zero
    /// normal now takes its triangles' normal; a scaled one is made unit; a degenerate
    /// triangle's vertex still gets a unit normal.
    #[test]
    fn zero_normals_face_as_their_triangles_do() {
        let quad = Mesh {
            positions: vec![
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::new(0.0, 1.0, 1.0),
            ],
            normals: vec![Vec3::ZERO, Vec3::ZERO, Vec3::new(0.0, -3.0, 0.0), Vec3::splat(f32::NAN)],
            indices: vec![0, 1, 2, 0, 2, 3],
            ..Default::default()
        };
        let m = quad.complete(None).unwrap();
        for n in &m.normals {
            assert!((*n - Vec3::NEG_Y).length() < 1e-6, "{n}");
        }
        let point = Mesh {
            positions: vec![Vec3::ZERO; 3],
            normals: vec![Vec3::ZERO; 3],
            indices: vec![0, 1, 2],
            ..Default::default()
        };
        assert!(point.complete(None).unwrap().normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-6));
    }
}
