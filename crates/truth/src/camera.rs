//! The pinhole camera, exactly as the rasteriser projects: glTF camera space (looking down
//! −Z, +Y up), vertical field of view, aspect ratio of the output image.

use glam::{Vec2, Vec3};
use scene::Camera;

#[derive(Clone, Copy, Debug)]
pub struct PinholeCamera {
    origin: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    width: f32,
    height: f32,
}

impl PinholeCamera {
    pub fn new(cam: &Camera, width: u32, height: u32) -> Self {
        let t = cam.transform;
        let tan = (cam.yfov * 0.5).tan();
        let aspect = width as f32 / height as f32;
        PinholeCamera {
            origin: t.transform_point3(Vec3::ZERO),
            // Scale in the transform must not change the field of view: normalise the axes.
            right: t.transform_vector3(Vec3::X).normalize() * tan * aspect,
            up: t.transform_vector3(Vec3::Y).normalize() * tan,
            forward: t.transform_vector3(-Vec3::Z).normalize(),
            width: width as f32,
            height: height as f32,
        }
    }

    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// Unit direction through image position `p` in pixels (origin top-left, y down).
    pub fn direction(&self, p: Vec2) -> Vec3 {
        let x = 2.0 * p.x / self.width - 1.0;
        let y = 1.0 - 2.0 * p.y / self.height;
        (self.forward + self.right * x + self.up * y).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_looks_at_target_and_edges_span_the_fov() {
        let cam = Camera::look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 0.8);
        let c = PinholeCamera::new(&cam, 200, 100);
        assert!((c.direction(Vec2::new(100.0, 50.0)) - (-Vec3::Z)).length() < 1e-6);
        let top = c.direction(Vec2::new(100.0, 0.0));
        assert!((top.angle_between(-Vec3::Z) - 0.4).abs() < 1e-5 && top.y > 0.0);
        let right = c.direction(Vec2::new(200.0, 50.0));
        assert!(right.x > 0.0 && ((right.x / -right.z) - 2.0 * 0.4f32.tan()).abs() < 1e-5);
    }
}
