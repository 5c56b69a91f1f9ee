//! `colorchecker`: the 24-patch ColorChecker Classic as one sRGB texture on a 0.36 × 0.24 m quad,
//! with each patch's measured reflectance attached as a palette entry keyed by its texel value,
//! lit head-on by a D65 directional light.
//!
//! Texels: each patch is [`PATCH`]² texels inside a [`CELL`]² cell whose border is black
//! (`[0, 0, 0]`, not in the palette, so it falls back to upsampling like any unlisted texel).
//! The patch value is the 8-bit sRGB of the measured spectrum under D65 (CIE 1931, 1 nm),
//! clipped to the sRGB gamut (cyan is slightly outside it).

use glam::Vec3;

use super::{dir, empty, light_emission, measured_material, patch, reflectance_rgb, shapes};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Camera, Light, LightKind, PaletteEntry, Scene, SpectralReflectance, Texture, TextureRef, srgb};

/// Texels per cell side.
pub const CELL: u32 = 16;
/// Texels per patch side (centred in its cell).
pub const PATCH: u32 = 12;
/// Chart layout, columns × rows.
pub const GRID: (u32, u32) = (6, 4);

/// The 8-bit sRGB texel value of every patch, chart order.
pub fn patch_texels() -> [[u8; 3]; 24] {
    std::array::from_fn(|i| srgb::linear_to_srgb8(reflectance_rgb(&patch(i))))
}

/// The chart texture (RGBA8, sRGB-encoded).
pub fn chart_texture() -> Texture {
    let texels = patch_texels();
    let (w, h) = (GRID.0 * CELL, GRID.1 * CELL);
    let mut rgba = vec![0u8; (w * h * 4) as usize];
    let margin = (CELL - PATCH) / 2;
    for y in 0..h {
        for x in 0..w {
            let (cx, cy, ix, iy) = (x / CELL, y / CELL, x % CELL, y % CELL);
            let inside = (margin..margin + PATCH).contains(&ix) && (margin..margin + PATCH).contains(&iy);
            let rgb = if inside { texels[(cy * GRID.0 + cx) as usize] } else { [0, 0, 0] };
            let o = ((y * w + x) * 4) as usize;
            rgba[o..o + 3].copy_from_slice(&rgb);
            rgba[o + 3] = 255;
        }
    }
    Texture {
        sampler: Default::default(),
        name: "ColorChecker Classic (sRGB, D65)".into(),
        width: w,
        height: h,
        rgba8: rgba,
        srgb: true,
    }
}

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let (cw, ch) = (0.36f32, 0.24f32);
    // 0.6 m away with the chart's width (plus margin) filling the height, so it fits any
    // aspect ratio ≥ 1 and a square one too.
    let yfov = 2.0 * (0.2f32 / 0.6).atan();
    let mut s = empty(ctx, Camera::look_at(Vec3::new(0.0, 0.0, 0.6), Vec3::ZERO, Vec3::Y, yfov));
    s.camera.aspect = Some(1.5);

    let texels = patch_texels();
    if let Some(i) = (1..24).find(|&i| texels[..i].contains(&texels[i])) {
        return Err(
            ctx.invalid("palette", format!("patch {} has the same 8-bit colour as an earlier one", i + 1))
        );
    }
    let palette = (0..24).map(|i| PaletteEntry { rgb8: texels[i], spectrum: patch(i) }).collect();
    s.textures.push(chart_texture());
    let mut chart = measured_material("ColorChecker Classic", &patch(0));
    chart.base_color = glam::Vec4::ONE;
    chart.base_color_texture = Some(TextureRef { transform: None, index: 0, tex_coord: 0 });
    chart.spectral = Some(SpectralReflectance::Palette(palette));
    s.materials.push(chart);
    s.meshes.push(shapes::quad(Vec3::new(-cw * 0.5, -ch * 0.5, 0.0), Vec3::X * cw, Vec3::Y * ch, 0));

    // Light from slightly above the camera. Irradiance on the chart = intensity × cosθ; make it π
    // lux so a perfect diffuse white would have radiance 1.
    let direction = dir(0.0, -0.25, -1.0);
    let intensity = std::f32::consts::PI / direction.dot(-Vec3::Z);
    let d65 = color::illuminant::by_name("D65").map_err(|e| ctx.invalid("light", e.to_string()))?;
    s.lights.push(Light {
        name: "D65 sun".into(),
        kind: LightKind::Directional { direction },
        emission: light_emission(ctx, "light", &d65, intensity)?,
        stands_in_for: None,
    });
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_cells_hold_the_palette_values() {
        let t = chart_texture();
        let texels = patch_texels();
        let at = |x: u32, y: u32| {
            let o = ((y * t.width + x) * 4) as usize;
            [t.rgba8[o], t.rgba8[o + 1], t.rgba8[o + 2]]
        };
        // Centre of the first cell (dark skin, top-left) and of the last (black, bottom-right).
        assert_eq!(at(CELL / 2, CELL / 2), texels[0]);
        assert_eq!(at(t.width - CELL / 2, t.height - CELL / 2), texels[23]);
        assert_eq!(at(0, 0), [0, 0, 0]);
        // White patch (19th, row 4 col 1) is light and neutral.
        let w = texels[18];
        assert!(w.iter().all(|&c| c > 235) && w[0].abs_diff(w[2]) < 4, "{w:?}");
    }
}
