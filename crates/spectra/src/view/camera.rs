//! Orbit + fly camera controller for `spectra view`.
//!
//! State is a position, a yaw/pitch pair and an orbit distance; the orbit target is
//! `position + forward·distance`. Dragging orbits around the target (the position moves on a
//! sphere), WASD/QE fly (position and target move together), looking (right drag) turns in
//! place (the target moves). Up is always +Y, so a scene camera with roll loses its roll: the
//! glTF cameras this project ships have none.

use glam::{Mat4, Vec3};

/// Pitch stays short of ±90° so `look_to` never gets a forward parallel to up.
const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;
/// Closest orbit distance, as a fraction of the scene size (never zero: the target would be
/// the eye).
const MIN_DISTANCE_FRACTION: f32 = 1e-3;

/// An orbit/fly camera. Angles in radians; yaw 0 looks down −Z (glTF), positive yaw turns left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraController {
    pub position: Vec3,
    pub yaw: f32,
    pub pitch: f32,
    /// Distance from the eye to the orbit target.
    pub distance: f32,
    /// Size of the scene (bounding-box diagonal); scales speeds and the closest distance.
    pub scene_size: f32,
    pub yfov: f32,
    pub znear: f32,
    pub zfar: f32,
    /// The file's orthographic half-extents (xmag, ymag) at the starting orbit distance; zooming
    /// scales them with the distance, as it would the view of a perspective camera.
    pub ortho: Option<(f32, f32)>,
    /// The orbit distance `ortho` belongs to.
    pub ortho_distance: f32,
}

/// Unit forward vector for a yaw/pitch pair (yaw 0, pitch 0 → −Z).
pub fn forward(yaw: f32, pitch: f32) -> Vec3 {
    Vec3::new(-yaw.sin() * pitch.cos(), pitch.sin(), -yaw.cos() * pitch.cos())
}

impl CameraController {
    /// Starts at `camera`, orbiting the point on its view axis nearest to `center` (the scene's
    /// bounding-box centre), so the first drag turns around what the camera was framing.
    pub fn from_camera(camera: &scene::Camera, center: Vec3, scene_size: f32) -> Self {
        let position = camera.position();
        let f = (-camera.transform.z_axis.truncate()).normalize_or(Vec3::NEG_Z);
        let pitch = f.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH);
        let yaw = (-f.x).atan2(-f.z);
        let scene_size = if scene_size.is_finite() && scene_size > 0.0 { scene_size } else { 1.0 };
        let along = (center - position).dot(f);
        let distance = along.max(scene_size * 0.5);
        CameraController {
            position,
            yaw,
            pitch,
            distance,
            scene_size,
            yfov: camera.yfov,
            znear: camera.znear,
            zfar: camera.zfar,
            ortho: camera.ortho,
            ortho_distance: distance,
        }
    }

    pub fn forward(&self) -> Vec3 {
        forward(self.yaw, self.pitch)
    }

    /// Unit vector to the right of the view direction, in the horizontal plane.
    pub fn right(&self) -> Vec3 {
        Vec3::new(self.yaw.cos(), 0.0, -self.yaw.sin())
    }

    pub fn target(&self) -> Vec3 {
        self.position + self.forward() * self.distance
    }

    /// Orbits around the target by the given angle increments (radians): the target stays,
    /// the eye moves on the sphere of radius `distance`.
    pub fn orbit(&mut self, d_yaw: f32, d_pitch: f32) {
        let target = self.target();
        self.yaw = wrap_angle(self.yaw + d_yaw);
        self.pitch = (self.pitch + d_pitch).clamp(-MAX_PITCH, MAX_PITCH);
        self.position = target - self.forward() * self.distance;
    }

    /// Turns the view in place (fly look): the eye stays, the target moves.
    pub fn look(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw = wrap_angle(self.yaw + d_yaw);
        self.pitch = (self.pitch + d_pitch).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the eye toward (positive) or away from the target by a factor of the distance.
    pub fn zoom(&mut self, steps: f32) {
        let target = self.target();
        let min = self.scene_size * MIN_DISTANCE_FRACTION;
        self.distance = (self.distance * 0.9f32.powf(steps)).max(min);
        self.position = target - self.forward() * self.distance;
    }

    /// Flies by `forward`, `right`, `up` units of scene size (WASD/QE × speed × seconds); the
    /// orbit target moves with the eye.
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        self.position += (self.forward() * forward + self.right() * right + Vec3::Y * up) * self.scene_size;
    }

    /// The camera to render (camera-to-world, looking down −Z, +Y up).
    pub fn camera(&self) -> scene::Camera {
        let k = self.distance / self.ortho_distance.max(1e-12);
        scene::Camera {
            ortho: self.ortho.map(|(x, y)| (x * k, y * k)),
            transform: Mat4::look_to_rh(self.position, self.forward(), Vec3::Y).inverse(),
            yfov: self.yfov,
            znear: self.znear,
            zfar: self.zfar,
            aspect: None,
        }
    }
}

/// Keeps yaw in (−π, π] so it does not lose precision after many turns.
fn wrap_angle(a: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let w = (a + PI).rem_euclid(TAU) - PI;
    if w <= -PI { w + TAU } else { w }
}

/// Centre and diagonal of the axis-aligned box around every vertex of the scene.
pub fn scene_bounds(scene: &scene::Scene) -> (Vec3, f32) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in scene.meshes.iter().flat_map(|m| m.positions.iter()) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if lo.x > hi.x {
        return (Vec3::ZERO, 1.0);
    }
    ((lo + hi) * 0.5, (hi - lo).length())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
        (a - b).length() <= eps
    }

    fn cam(eye: Vec3, target: Vec3) -> scene::Camera {
        scene::Camera::look_at(eye, target, Vec3::Y, 0.8)
    }

    #[test]
    fn forward_convention_matches_gltf() {
        assert!(close(forward(0.0, 0.0), Vec3::NEG_Z, 1e-6));
        // Positive yaw turns left (counter-clockwise seen from above): −Z → −X.
        assert!(close(forward(std::f32::consts::FRAC_PI_2, 0.0), Vec3::NEG_X, 1e-6));
        assert!(close(forward(0.0, 0.5), Vec3::new(0.0, 0.5f32.sin(), -0.5f32.cos()), 1e-6));
    }

    #[test]
    fn starts_exactly_at_the_scene_camera() {
        for (eye, target) in [
            (Vec3::new(0.0, 1.0, 4.0), Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::new(3.0, 2.0, -1.0), Vec3::new(-1.0, 0.5, 2.0)),
            (Vec3::new(-2.0, 5.0, 1.0), Vec3::ZERO),
        ] {
            let c = cam(eye, target);
            let ctl = CameraController::from_camera(&c, target, 2.0);
            let back = ctl.camera();
            for (a, b) in back.transform.to_cols_array().iter().zip(c.transform.to_cols_array()) {
                assert!((a - b).abs() < 1e-5, "{:?} vs {:?}", back.transform, c.transform);
            }
            // The orbit target is the framed point (it lies on the view axis).
            assert!(close(ctl.target(), target, 1e-4), "{} vs {target}", ctl.target());
        }
    }

    #[test]
    fn an_orthographic_camera_stays_orthographic_and_zoom_scales_it() {
        let target = Vec3::ZERO;
        let mut c = cam(Vec3::new(0.0, 0.0, 4.0), target);
        c.ortho = Some((2.0, 1.0));
        let mut ctl = CameraController::from_camera(&c, target, 2.0);
        assert_eq!(ctl.camera().ortho, Some((2.0, 1.0)));
        ctl.orbit(0.3, 0.1);
        assert_eq!(ctl.camera().ortho, Some((2.0, 1.0)));
        ctl.zoom(1.0);
        let (x, y) = ctl.camera().ortho.unwrap();
        assert!((x - 1.8).abs() < 1e-5 && (y - 0.9).abs() < 1e-5, "{x} {y}");
        assert_eq!(CameraController::from_camera(&cam(Vec3::Z, target), target, 2.0).camera().ortho, None);
    }

    #[test]
    fn orbit_keeps_target_and_distance() {
        let target = Vec3::new(0.5, 1.0, -0.25);
        let mut ctl = CameraController::from_camera(&cam(Vec3::new(0.5, 1.0, 4.0), target), target, 2.0);
        let d0 = ctl.position.distance(target);
        for (dy, dp) in [(0.3, 0.1), (-1.7, 0.4), (2.5, -0.9), (0.0, 3.0)] {
            ctl.orbit(dy, dp);
            assert!(close(ctl.target(), target, 1e-4));
            assert!((ctl.position.distance(target) - d0).abs() < 1e-4);
            // The rendered camera looks at the target.
            let c = ctl.camera();
            let f = -c.transform.z_axis.truncate();
            assert!(close(f, (target - c.position()).normalize(), 1e-4));
        }
        // Pitch is clamped short of the pole, so the view matrix stays well defined.
        assert!(ctl.pitch <= MAX_PITCH && ctl.camera().transform.is_finite());
    }

    #[test]
    fn quarter_orbit_moves_eye_a_quarter_turn() {
        let mut ctl =
            CameraController::from_camera(&cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO), Vec3::ZERO, 1.0);
        ctl.orbit(std::f32::consts::FRAC_PI_2, 0.0);
        // Looking down −X now, so the eye sits on +X.
        assert!(close(ctl.position, Vec3::new(5.0, 0.0, 0.0), 1e-4), "{}", ctl.position);
    }

    #[test]
    fn fly_moves_along_view_axes() {
        let mut ctl =
            CameraController::from_camera(&cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO), Vec3::ZERO, 2.0);
        let t0 = ctl.target();
        ctl.fly(0.5, 0.0, 0.0); // forward half a scene size = 1 unit
        assert!(close(ctl.position, Vec3::new(0.0, 0.0, 4.0), 1e-5));
        ctl.fly(0.0, 1.0, 0.25);
        assert!(close(ctl.position, Vec3::new(2.0, 0.5, 4.0), 1e-5));
        // The target travels with the eye.
        assert!(close(ctl.target() - t0, Vec3::new(2.0, 0.5, -1.0), 1e-5));
    }

    #[test]
    fn look_turns_in_place_and_zoom_approaches_target() {
        let mut ctl =
            CameraController::from_camera(&cam(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO), Vec3::ZERO, 1.0);
        ctl.look(0.4, -0.2);
        assert!(close(ctl.position, Vec3::new(0.0, 0.0, 5.0), 1e-6));
        assert!((ctl.pitch + 0.2).abs() < 1e-6);
        let target = ctl.target();
        ctl.zoom(1.0);
        assert!(close(ctl.target(), target, 1e-4));
        assert!((ctl.distance - 4.5).abs() < 1e-4);
        for _ in 0..1000 {
            ctl.zoom(1.0);
        }
        assert!(ctl.distance >= 1.0 * MIN_DISTANCE_FRACTION && ctl.camera().transform.is_finite());
    }

    #[test]
    fn yaw_wraps() {
        for a in [-10.0f32, -3.5, 0.0, 3.2, 7.0, 100.0] {
            let w = wrap_angle(a);
            assert!(w > -std::f32::consts::PI - 1e-6 && w <= std::f32::consts::PI + 1e-6);
            assert!((w.sin() - a.sin()).abs() < 1e-4 && (w.cos() - a.cos()).abs() < 1e-4);
        }
    }

    #[test]
    fn bounds_of_builtin_cornell() {
        let s = scene::load_any("cornell").unwrap();
        let (c, d) = scene_bounds(&s);
        assert!(c.is_finite() && d > 0.0);
        let empty = scene::Scene { meshes: vec![], ..s };
        assert_eq!(scene_bounds(&empty), (Vec3::ZERO, 1.0));
    }
}
