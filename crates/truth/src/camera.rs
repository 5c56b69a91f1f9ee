//! The camera, exactly as the rasteriser projects: glTF camera space (looking down −Z, +Y up),
//! the aspect ratio of the output image, and either a pinhole (vertical field of view) or an
//! orthographic projection (glTF `orthographic`: parallel rays along −Z).
//!
//! Rays start at the eye (orthographic: on the camera's plane), so a medium around the camera
//! attenuates and scatters over the whole view ray; the near and far planes clip *surfaces*
//! only ([`CameraRay::t_near`], [`CameraRay::t_far`]), as the rasteriser's clipping does.

use glam::{Vec2, Vec3};
use scene::Camera;

#[derive(Clone, Copy, Debug)]
pub struct RayCamera {
    origin: Vec3,
    /// Half the image plane's width and height: at unit distance for a pinhole, in scene
    /// units for an orthographic camera.
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    ortho: bool,
    /// Distance along `forward` of the near clipping plane (glTF `znear` × the transform's
    /// scale, as the rasteriser's view matrix applies it): surfaces in front of it are not seen,
    /// so geometry the rasteriser clips (a cockpit around the camera) is not seen here either.
    near: f32,
    /// Distance along `forward` of the far clipping plane (glTF `zfar`, likewise): surfaces
    /// beyond it are not seen, the background is, as in the rasteriser.
    far: f32,
    width: f32,
    height: f32,
}

/// A camera ray: from the eye (or the orthographic camera's plane) along the unit direction
/// `d`; surfaces closer than `t_near` or farther than `t_far` along it are clipped by the near
/// and far planes, media are not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRay {
    pub o: Vec3,
    pub d: Vec3,
    pub t_near: f32,
    pub t_far: f32,
}

impl RayCamera {
    /// Orthographic cameras span ±ymag vertically and ±ymag × (width / height) horizontally:
    /// the output's aspect wins, as for the pinhole's field of view, so an image of aspect
    /// xmag / ymag spans exactly ±xmag.
    pub fn new(cam: &Camera, width: u32, height: u32) -> Self {
        let t = cam.transform;
        let aspect = width as f32 / height as f32;
        // Scale in the transform must change neither the field of view nor the orthographic
        // extent: normalise the axes.
        let (half_h, ortho) = match cam.ortho {
            Some((_, ymag)) => (ymag.abs(), true),
            None => ((cam.yfov * 0.5).tan(), false),
        };
        let scale = t.transform_vector3(-Vec3::Z).length();
        let near = cam.clip_near().max(0.0) * scale;
        let far = cam.zfar * scale;
        RayCamera {
            near: if near.is_finite() { near } else { 0.0 },
            far: if far > near { far } else { f32::INFINITY },
            origin: t.transform_point3(Vec3::ZERO),
            right: t.transform_vector3(Vec3::X).normalize() * half_h * aspect,
            up: t.transform_vector3(Vec3::Y).normalize() * half_h,
            forward: t.transform_vector3(-Vec3::Z).normalize(),
            ortho,
            width: width as f32,
            height: height as f32,
        }
    }

    /// The ray through image position `p` in pixels (origin top-left, y down).
    pub fn ray(&self, p: Vec2) -> CameraRay {
        let x = 2.0 * p.x / self.width - 1.0;
        let y = 1.0 - 2.0 * p.y / self.height;
        if self.ortho {
            CameraRay {
                o: self.origin + self.right * x + self.up * y,
                d: self.forward,
                t_near: self.near,
                t_far: self.far,
            }
        } else {
            let d = (self.forward + self.right * x + self.up * y).normalize();
            // The clipping planes are planes: farther along the oblique rays.
            let k = d.dot(self.forward);
            CameraRay { o: self.origin, d, t_near: self.near / k, t_far: self.far / k }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    #[test]
    fn centre_looks_at_target_and_edges_span_the_fov() {
        let cam = Camera::look_at(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 0.8);
        let c = RayCamera::new(&cam, 200, 100);
        let dir = |p| c.ray(p).d;
        // Rays start at the eye; the near plane (look_at's znear is 0.01) is where they cross
        // the plane 0.01 in front of it.
        let r = c.ray(Vec2::new(3.0, 7.0));
        assert_eq!(r.o, Vec3::new(0.0, 1.0, 5.0));
        assert!(((r.d * r.t_near).dot(-Vec3::Z) - 0.01).abs() < 1e-7);
        assert!(r.t_near > 0.01);
        assert!((c.ray(Vec2::new(100.0, 50.0)).t_near - 0.01).abs() < 1e-7);
        assert!((dir(Vec2::new(100.0, 50.0)) - (-Vec3::Z)).length() < 1e-6);
        let top = dir(Vec2::new(100.0, 0.0));
        assert!((top.angle_between(-Vec3::Z) - 0.4).abs() < 1e-5 && top.y > 0.0);
        let right = dir(Vec2::new(200.0, 50.0));
        assert!(right.x > 0.0 && ((right.x / -right.z) - 2.0 * 0.4f32.tan()).abs() < 1e-5);
    }

    /// Orthographic rays are parallel to the camera's −Z and their origins cover ±xmag × ±ymag
    /// of the camera plane (image aspect = xmag / ymag), scale in the transform ignored.
    #[test]
    fn orthographic_rays_are_parallel_and_span_the_magnification() {
        let (xmag, ymag) = (3.0, 1.5);
        let mut cam = Camera::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::new(1.0, 2.0, 0.0), Vec3::Y, 0.8);
        cam.transform *= Mat4::from_scale(Vec3::splat(2.0));
        cam.ortho = Some((xmag, ymag));
        cam.znear = 0.0;
        let c = RayCamera::new(&cam, 200, 100);
        for p in [Vec2::ZERO, Vec2::new(200.0, 100.0), Vec2::new(37.0, 81.0), Vec2::new(100.0, 50.0)] {
            let CameraRay { o, d, t_near, .. } = c.ray(p);
            assert!((d - (-Vec3::Z)).length() < 1e-6, "{d}");
            assert!((o.z - 5.0).abs() < 1e-5);
            assert_eq!(t_near, 0.0);
        }
        let o = |x, y| c.ray(Vec2::new(x, y)).o;
        assert!((o(100.0, 50.0) - Vec3::new(1.0, 2.0, 5.0)).length() < 1e-5);
        assert!((o(0.0, 0.0) - Vec3::new(1.0 - xmag, 2.0 + ymag, 5.0)).length() < 1e-5);
        assert!((o(200.0, 100.0) - Vec3::new(1.0 + xmag, 2.0 - ymag, 5.0)).length() < 1e-5);
        // A square image keeps ymag and narrows to ±ymag horizontally.
        let sq = RayCamera::new(&cam, 64, 64);
        assert!((sq.ray(Vec2::new(64.0, 0.0)).o - Vec3::new(1.0 + ymag, 2.0 + ymag, 5.0)).length() < 1e-5);
        // The near plane, scaled like the rasteriser's view matrix scales it: 0.5 × 2 in front;
        // the ray still starts on the camera's plane.
        cam.znear = 0.5;
        let near = RayCamera::new(&cam, 200, 100).ray(Vec2::new(37.0, 81.0));
        assert!((near.o.z - 5.0).abs() < 1e-5 && (near.t_near - 1.0).abs() < 1e-6);
    }
}
