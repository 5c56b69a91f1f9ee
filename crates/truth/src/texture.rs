//! Texture lookups as a GPU sampler does them: repeat wrapping, bilinear filtering, and sRGB
//! textures decoded per texel *before* filtering (what an `*_srgb` format does in hardware).

use glam::{Vec2, Vec4};
use scene::Texture;

/// The four texels a bilinear lookup blends, with their weights.
pub struct Footprint {
    pub texels: [(u32, u32); 4],
    pub weights: [f32; 4],
}

/// Which texels surround `uv` (glTF: origin at the image's top-left, v down).
pub fn footprint(tex: &Texture, uv: Vec2) -> Footprint {
    let (w, h) = (tex.width as i64, tex.height as i64);
    let x = uv.x * tex.width as f32 - 0.5;
    let y = uv.y * tex.height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (tx, ty) = (x - x0, y - y0);
    let wrap = |v: f32, n: i64| ((v as i64).rem_euclid(n)) as u32;
    let (xa, xb) = (wrap(x0, w), wrap(x0 + 1.0, w));
    let (ya, yb) = (wrap(y0, h), wrap(y0 + 1.0, h));
    Footprint {
        texels: [(xa, ya), (xb, ya), (xa, yb), (xb, yb)],
        weights: [(1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty],
    }
}

/// The raw 8-bit RGBA of one texel.
#[inline]
pub fn texel8(tex: &Texture, (x, y): (u32, u32)) -> [u8; 4] {
    let i = 4 * (y as usize * tex.width as usize + x as usize);
    [tex.rgba8[i], tex.rgba8[i + 1], tex.rgba8[i + 2], tex.rgba8[i + 3]]
}

/// A texel as floats: RGB sRGB-decoded when the texture is sRGB; alpha always linear.
#[inline]
pub fn texel(tex: &Texture, at: (u32, u32)) -> Vec4 {
    let t = texel8(tex, at);
    let c = |v: u8| {
        let v = v as f32 / 255.0;
        if tex.srgb { srgb_decode(v) } else { v }
    };
    Vec4::new(c(t[0]), c(t[1]), c(t[2]), t[3] as f32 / 255.0)
}

/// Bilinearly filtered RGBA at `uv`.
pub fn sample(tex: &Texture, uv: Vec2) -> Vec4 {
    if tex.width == 0 || tex.height == 0 || tex.rgba8.len() < 4 * (tex.width * tex.height) as usize {
        return Vec4::ONE;
    }
    let f = footprint(tex, uv);
    f.texels.iter().zip(f.weights).map(|(&t, w)| texel(tex, t) * w).sum()
}

/// IEC 61966-2-1 decoding: the colour crate's curve, in the tracer's f32.
#[inline]
pub fn srgb_decode(v: f32) -> f32 {
    color::colorspace::srgb_decode(v as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex(w: u32, h: u32, px: &[[u8; 4]], srgb: bool) -> Texture {
        Texture {
            sampler: Default::default(),
            name: "t".into(),
            width: w,
            height: h,
            rgba8: px.concat(),
            srgb,
        }
    }

    #[test]
    fn texel_centres_are_exact_and_midpoints_blend() {
        let t = tex(2, 1, &[[0, 0, 0, 255], [255, 255, 255, 255]], false);
        assert!((sample(&t, Vec2::new(0.25, 0.5)).x - 0.0).abs() < 1e-6);
        assert!((sample(&t, Vec2::new(0.75, 0.5)).x - 1.0).abs() < 1e-6);
        assert!((sample(&t, Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
        // Repeat wrapping: u = 0 is halfway between the last and first texel.
        assert!((sample(&t, Vec2::new(0.0, 0.5)).x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn srgb_is_decoded_before_filtering() {
        let t = tex(2, 1, &[[0, 0, 0, 255], [188, 188, 188, 255]], true);
        let mid = sample(&t, Vec2::new(0.5, 0.5)).x;
        assert!((mid - 0.5 * srgb_decode(188.0 / 255.0)).abs() < 1e-6);
        assert!((srgb_decode(188.0 / 255.0) - 0.5029).abs() < 1e-3);
    }
}
