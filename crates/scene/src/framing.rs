//! Scene bounds and the default camera used when a file has none.

use glam::Vec3;

use crate::{Camera, Mesh, Scene};

/// Vertical field of view of the default camera: 45°, a common "normal lens".
pub const DEFAULT_YFOV: f32 = std::f32::consts::FRAC_PI_4;

/// From the scene's centre towards the default camera (normalised on use): to the right, above
/// and in front (+X, +Y, +Z), a three-quarter view that shows three faces of a box and never
/// sees a flat asset lying in a principal plane edge-on.
pub const DEFAULT_VIEW_DIRECTION: Vec3 = Vec3::new(1.0, 0.6, 1.4);

/// A scene whose depth (z extent) is at most this fraction of its larger side is a board facing
/// ±Z (the Khronos test assets: TextureSettingsTest, VertexColorTest, …): the default camera
/// looks at it head-on from +Z, the glTF front, as their reference screenshots do.
pub const BOARD_DEPTH_RATIO: f32 = 0.2;

/// Axis-aligned bounds of all mesh positions, `None` when there are none.
pub fn bounds(meshes: &[Mesh]) -> Option<(Vec3, Vec3)> {
    let mut it = meshes.iter().flat_map(|m| m.positions.iter().copied());
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

impl Scene {
    /// Axis-aligned world bounds of the geometry.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds(&self.meshes)
    }

    /// Moves a scene that lies far from its file's origin (the centre of its geometry and
    /// camera more than [`FAR_FROM_ORIGIN`] times their extent away: geo-referenced and CAD
    /// exports) so that that centre is the origin, and records the move in
    /// [`Scene::origin`]. Both renderers work in single precision: 10⁴ units out, the real-time
    /// renderer's depth-reconstructed positions and shadow maps lost the scene (89 % black),
    /// 10⁶ out every pixel. Positions, point and spot lights and the camera move; directions do
    /// not. A translation changes no image; a scene near its origin is left exactly as it is.
    pub fn recentre(&mut self) {
        let cam = self.camera.transform.w_axis.truncate();
        let Some((lo, hi)) = self.bounds() else { return };
        let (lo, hi) = (lo.min(cam), hi.max(cam));
        let centre = (lo + hi) * 0.5;
        let extent = (hi - lo).max_element();
        if !(centre.is_finite() && centre.abs().max_element() > FAR_FROM_ORIGIN * extent.max(1e-30)) {
            return;
        }
        for m in &mut self.meshes {
            for p in &mut m.positions {
                *p -= centre;
            }
        }
        for l in &mut self.lights {
            match &mut l.kind {
                crate::LightKind::Point { position, .. } | crate::LightKind::Spot { position, .. } => {
                    *position -= centre
                }
                crate::LightKind::Directional { .. } => {}
            }
        }
        self.camera.transform.w_axis -= centre.extend(0.0);
        self.origin += centre.as_dvec3();
    }
}

/// How far (in multiples of its extent) a scene's centre may lie from its file's origin before
/// [`Scene::recentre`] moves it: beyond that, single precision spends most of its bits on the
/// offset (a ratio of 4 still leaves over 21 of f32's 24 for the scene itself).
pub const FAR_FROM_ORIGIN: f32 = 4.0;

impl Camera {
    /// The default camera: looks at the centre of `bounds` from [`DEFAULT_VIEW_DIRECTION`]
    /// (above, front, right) — or head-on from +Z for a board facing ±Z ([`BOARD_DEPTH_RATIO`]) —
    /// far enough that the bounding sphere fits the vertical field of view with 10% margin, +Y
    /// up, 45°. Near and far planes enclose the sphere. With no geometry: at the origin looking
    /// down −Z.
    pub fn framing(bounds: Option<(Vec3, Vec3)>) -> Camera {
        let Some((lo, hi)) = bounds else {
            return Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, DEFAULT_YFOV);
        };
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-3);
        let dist = 1.1 * radius / (DEFAULT_YFOV * 0.5).sin();
        let size = hi - lo;
        let board = size.z <= BOARD_DEPTH_RATIO * size.x.max(size.y);
        let dir = if board { Vec3::Z } else { DEFAULT_VIEW_DIRECTION.normalize() };
        let mut cam = Camera::look_at(centre + dir * dist, centre, Vec3::Y, DEFAULT_YFOV);
        cam.znear = ((dist - radius) * 0.5).max(dist * 1e-3);
        cam.zfar = (dist + radius) * 2.0;
        cam
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_camera_sees_every_corner() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -3.0), Vec3::new(2.0, 5.0, 1.0));
        let cam = Camera::framing(Some((lo, hi)));
        let view = cam.transform.inverse();
        let half = (cam.yfov * 0.5).tan();
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let v = view.transform_point3(c);
            let depth = -v.z;
            assert!(depth > cam.znear && depth < cam.zfar, "corner {c} at depth {depth}");
            assert!(v.y.abs() / depth < half && v.x.abs() / depth < half, "corner {c} outside a square view");
        }
    }

    #[test]
    fn default_camera_never_sees_a_flat_asset_edge_on() {
        let to_eye = |lo: Vec3, hi: Vec3| {
            let cam = Camera::framing(Some((lo, hi)));
            let d = (cam.position() - (lo + hi) * 0.5).normalize();
            // Looking at the centre, +Y up.
            assert!(cam.transform.transform_vector3(-Vec3::Z).abs_diff_eq(-d, 1e-5));
            assert!(cam.transform.transform_vector3(Vec3::X).y.abs() < 1e-5);
            d
        };
        // Lying in XZ facing +Y (TwoSidedPlane), in YZ facing +X, and a box: three-quarter view
        // from above, front and right.
        for (lo, hi, normal) in [
            (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::Y),
            (Vec3::new(0.0, -1.0, -1.0), Vec3::new(0.0, 1.0, 1.0), Vec3::X),
            (Vec3::ZERO, Vec3::ONE, Vec3::ONE.normalize()),
        ] {
            let d = to_eye(lo, hi);
            assert!(d.dot(normal) > 0.3, "{normal}: seen at a grazing angle from {d}");
            assert!(d.x > 0.0 && d.y > 0.0 && d.z > 0.0, "{d}");
        }
        // A board facing +Z (the test assets): head-on.
        let d = to_eye(Vec3::new(-5.0, -5.0, -0.15), Vec3::new(5.0, 4.5, 0.1));
        assert!(d.abs_diff_eq(Vec3::Z, 1e-6), "{d}");
        assert!(Camera::framing(None).position() == Vec3::ZERO);
    }

    /// A scene far from its file's origin is moved to it (both renderers in f32 lost it: the
    /// real-time one drew it black 10⁶ units out), with everything positional and the move
    /// recorded; one near its origin is left bit for bit.
    #[test]
    fn a_far_scene_is_recentred_and_a_near_one_left_alone() {
        let near = crate::builtin("cornell").unwrap();
        let mut same = near.clone();
        same.recentre();
        assert_eq!(same.origin, glam::DVec3::ZERO);
        assert_eq!(same.meshes[0].positions, near.meshes[0].positions);
        let shift = Vec3::new(1.0e6, -2.0e5, 3.0e6);
        let mut far = near.clone();
        for m in &mut far.meshes {
            for p in &mut m.positions {
                *p += shift;
            }
        }
        for l in &mut far.lights {
            if let crate::LightKind::Point { position, .. } | crate::LightKind::Spot { position, .. } =
                &mut l.kind
            {
                *position += shift;
            }
        }
        far.camera.transform.w_axis += shift.extend(0.0);
        far.recentre();
        let moved = far.origin.as_vec3();
        assert!((moved - shift).abs().max_element() < 10.0, "{moved}");
        // Relative positions as the file had them, within its own f32 precision at 3e6 (0.25).
        let (a, b) = (
            near.camera.position() - near.meshes[0].positions[0],
            far.camera.position() - far.meshes[0].positions[0],
        );
        assert!((a - b).abs().max_element() < 0.5, "{a} {b}");
        assert!(far.bounds().unwrap().1.abs().max_element() < 10.0);
        for (l0, l1) in near.lights.iter().zip(&far.lights) {
            if let (
                crate::LightKind::Point { position: p0, .. },
                crate::LightKind::Point { position: p1, .. },
            ) = (&l0.kind, &l1.kind)
            {
                assert!((*p1 + moved - shift - *p0).abs().max_element() < 0.5);
            }
        }
    }
}
