//! The sea floor under the camera, as the real-time light-field model sees it
//! ([`super::light_field::Floor`]): a flat Lambertian bottom at the depth of the surface straight
//! below the camera, with that surface's diffuse albedo.
//!
//! Why the real-time model needs it: in all but the clearest water the floor lights the water
//! from below — the light it reflects is scattered forward towards a camera looking down, back
//! onto the floor, and reflected down again by the surface (total internal reflection) — so the
//! column's light field near the bottom is far brighter than a bottomless column's. The path
//! tracer needs nothing of this: it traces the real geometry.
//!
//! The floor is found by casting a ray straight down from the camera through the scene's
//! triangles (world space): its depth is the hit's, its albedo the hit material's base colour
//! (factor × the mean of its base-colour texture, or its measured spectrum), upsampled like
//! every reflectance. A scene whose camera looks over something other than the floor (a rock,
//! a wreck) gets that object's depth and colour: the model assumes the column's bottom is
//! uniform, and that is the local guess. Nothing below the camera → a bottomless column.

use glam::Vec3;

use crate::{Scene, SpectralReflectance};
use color::Spectrum;

/// The floor under the camera: depth below the camera (m) and albedo.
#[derive(Clone, Debug, PartialEq)]
pub struct SeaFloor {
    /// Metres from the camera down to the floor (≥ 0).
    pub below_camera: f64,
    /// Diffuse albedo (linear sRGB), for messages.
    pub rgb: [f64; 3],
    /// Diffuse albedo spectrum.
    pub albedo: Spectrum,
    /// Horizontal extent (scene units: min x, min z, max x, max z) of the mesh the floor was
    /// found on; `None` = unbounded. The real-time pass shows the floor in the surface's mirror
    /// only where the mirrored view lands inside it.
    pub extent: Option<[f32; 4]>,
}

/// Nearest triangle hit straight down from `origin`: distance (scene units) and mesh index.
fn cast_down(scene: &Scene, origin: Vec3) -> Option<(f32, usize)> {
    let mut best: Option<(f32, usize)> = None;
    for (mi, mesh) in scene.meshes.iter().enumerate() {
        for tri in mesh.indices.chunks_exact(3) {
            let p = |i: u32| mesh.positions.get(i as usize).copied();
            let (Some(a), Some(b), Some(c)) = (p(tri[0]), p(tri[1]), p(tri[2])) else { continue };
            // Möller–Trumbore with direction −Y, both faces.
            let (e1, e2) = (b - a, c - a);
            let d = Vec3::NEG_Y;
            let pv = d.cross(e2);
            let det = e1.dot(pv);
            if det.abs() < 1e-12 {
                continue;
            }
            let tv = origin - a;
            let u = tv.dot(pv) / det;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let qv = tv.cross(e1);
            let v = d.dot(qv) / det;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            let t = e2.dot(qv) / det;
            if t > 0.0 && t.is_finite() && best.is_none_or(|b| t < b.0) {
                best = Some((t, mi));
            }
        }
    }
    best
}

/// Mean linear RGB of a texture's texels (sRGB-decoded when the texture is sRGB).
fn texture_mean(scene: &Scene, index: usize) -> Option<[f64; 3]> {
    let t = scene.textures.get(index)?;
    let n = (t.width as usize) * (t.height as usize);
    if n == 0 || t.rgba8.len() < 4 * n {
        return None;
    }
    let mut lut = [0.0f64; 256];
    for (i, x) in lut.iter_mut().enumerate() {
        let v = i as f64 / 255.0;
        *x = if t.srgb { crate::srgb::decode(v) } else { v };
    }
    let mut sum = [0.0f64; 3];
    for px in t.rgba8.chunks_exact(4).take(n) {
        for ch in 0..3 {
            sum[ch] += lut[px[ch] as usize];
        }
    }
    Some(sum.map(|s| s / n as f64))
}

/// The sea floor's albedo needs the sRGB upsampling table, which could not be had.
#[derive(Debug, thiserror::Error)]
#[error("sea floor albedo: the sRGB upsampling table: {0}")]
pub struct FloorTableError(pub color::ColorError);

/// The floor straight below the scene's camera, or `None` when nothing is below it (or the
/// camera has no finite position). `scale` is metres per scene unit.
pub fn below_camera(scene: &Scene, scale: f64) -> Result<Option<SeaFloor>, FloorTableError> {
    let origin = scene.camera.transform.w_axis.truncate();
    if !origin.is_finite() {
        return Ok(None);
    }
    let Some((t, mi)) = cast_down(scene, origin) else { return Ok(None) };
    let mesh = &scene.meshes[mi];
    let Some(material) = scene.materials.get(mesh.material) else { return Ok(None) };
    let base = material.base_color;
    let tex =
        material.base_color_texture.as_ref().and_then(|r| texture_mean(scene, r.index)).unwrap_or([1.0; 3]);
    let rgb = [0, 1, 2].map(|c| (base[c] as f64 * tex[c]).clamp(0.0, 1.0));
    let albedo = match &material.spectral {
        Some(SpectralReflectance::Uniform(s)) => s.clone(),
        _ => {
            let table = color::upsample::cache::table("srgb").map_err(FloorTableError)?;
            let poly = table.fetch(rgb);
            Spectrum::Piecewise {
                lambda: (0..=47).map(|i| 360.0 + 10.0 * i as f64).collect(),
                values: (0..=47).map(|i| poly.eval(360.0 + 10.0 * i as f64)).collect(),
            }
        }
    };
    let extent = mesh
        .positions
        .iter()
        .fold([f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY], |b, p| {
            [b[0].min(p.x), b[1].min(p.z), b[2].max(p.x), b[3].max(p.z)]
        });
    Ok(Some(SeaFloor { below_camera: t as f64 * scale, rgb, albedo, extent: Some(extent) }))
}
