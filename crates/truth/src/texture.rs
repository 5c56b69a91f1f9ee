//! Texture lookups as a GPU sampler does them: the texture's wrap modes (repeat, clamp to
//! edge, mirrored repeat) per axis, bilinear or nearest filtering, and sRGB textures decoded per
//! texel *before* filtering (what an `*_srgb` format does in hardware).
//!
//! A path tracer has no ray footprint, so there is no minification: every lookup uses the
//! sampler's magnification filter (`Sampler::mag`), and mipmaps are not used.

use glam::{Vec2, Vec4};
use scene::{Filter, Texture, Wrap};

/// The four texels a lookup blends, with their weights (a nearest lookup puts its one texel
/// first with weight 1 and the others at weight 0).
pub struct Footprint {
    pub texels: [(u32, u32); 4],
    pub weights: [f32; 4],
}

/// Texel index `i` (any integer) of an axis of `n` texels under `wrap` ([`Wrap::index`]).
#[inline]
fn wrap_index(i: i64, n: i64, wrap: Wrap) -> u32 {
    wrap.index(i, n)
}

/// Which texels surround `uv` (glTF: origin at the image's top-left, v down), wrapped and
/// filtered as the texture's sampler says.
pub fn footprint(tex: &Texture, uv: Vec2) -> Footprint {
    let (w, h) = (tex.width as i64, tex.height as i64);
    let s = &tex.sampler;
    // Far outside [0, 1] every mode repeats or clamps; keep the float→int conversion exact.
    let x = (uv.x * tex.width as f32).clamp(-1e9, 1e9);
    let y = (uv.y * tex.height as f32).clamp(-1e9, 1e9);
    if s.mag == Filter::Nearest {
        let at = (wrap_index(x.floor() as i64, w, s.wrap_s), wrap_index(y.floor() as i64, h, s.wrap_t));
        return Footprint { texels: [at; 4], weights: [1.0, 0.0, 0.0, 0.0] };
    }
    let (x, y) = (x - 0.5, y - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (tx, ty) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (xa, xb) = (wrap_index(x0, w, s.wrap_s), wrap_index(x0 + 1, w, s.wrap_s));
    let (ya, yb) = (wrap_index(y0, h, s.wrap_t), wrap_index(y0 + 1, h, s.wrap_t));
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

fn usable(tex: &Texture) -> bool {
    tex.width > 0 && tex.height > 0 && tex.rgba8.len() >= 4 * tex.width as usize * tex.height as usize
}

/// Filtered RGBA at `uv` (white for an empty or short image).
pub fn sample(tex: &Texture, uv: Vec2) -> Vec4 {
    if !usable(tex) {
        return Vec4::ONE;
    }
    let f = footprint(tex, uv);
    f.texels.iter().zip(f.weights).filter(|(_, w)| *w != 0.0).map(|(&t, w)| texel(tex, t) * w).sum()
}

/// Filtered alpha alone at `uv` (the alpha test in the traversal needs nothing else).
pub fn sample_alpha(tex: &Texture, uv: Vec2) -> f32 {
    if !usable(tex) {
        return 1.0;
    }
    let f = footprint(tex, uv);
    f.texels.iter().zip(f.weights).map(|(&t, w)| texel8(tex, t)[3] as f32 * w).sum::<f32>() / 255.0
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

    fn with(mut t: Texture, wrap_s: Wrap, wrap_t: Wrap, mag: Filter) -> Texture {
        t.sampler = scene::Sampler { wrap_s, wrap_t, mag, ..Default::default() };
        t
    }

    /// A 4×1 ramp 0, 85, 170, 255 read at texel centres outside [0, 1]: repeat starts over,
    /// clamp holds the edge texel, mirrored repeat runs backwards.
    #[test]
    fn wrap_modes_outside_the_unit_square() {
        let ramp = tex(4, 1, &[[0, 0, 0, 255], [85, 0, 0, 255], [170, 0, 0, 255], [255, 0, 0, 255]], false);
        let at = |wrap, u: f32| {
            (sample(&with(ramp.clone(), wrap, Wrap::Repeat, Filter::Linear), Vec2::new(u, 0.5)).x * 255.0)
                .round()
        };
        // Texel centres of the next period (u in 1..2) and of the one before (u in −1..0).
        for (k, u) in [1.125f32, 1.375, 1.625, 1.875].into_iter().enumerate() {
            assert_eq!(at(Wrap::Repeat, u), 85.0 * k as f32, "repeat u={u}");
            assert_eq!(at(Wrap::ClampToEdge, u), 255.0, "clamp u={u}");
            assert_eq!(at(Wrap::MirroredRepeat, u), 255.0 - 85.0 * k as f32, "mirror u={u}");
            let v = u - 2.0;
            assert_eq!(at(Wrap::Repeat, v), 85.0 * k as f32, "repeat u={v}");
            assert_eq!(at(Wrap::ClampToEdge, v), 0.0, "clamp u={v}");
            assert_eq!(at(Wrap::MirroredRepeat, v), 255.0 - 85.0 * k as f32, "mirror u={v}");
        }
        // At the edge u = 1: repeat blends the last and first texels, clamp and mirror do not.
        assert_eq!(at(Wrap::Repeat, 1.0), 128.0);
        assert_eq!(at(Wrap::ClampToEdge, 1.0), 255.0);
        assert_eq!(at(Wrap::MirroredRepeat, 1.0), 255.0);
        // Far away stays finite and in range.
        assert_eq!(at(Wrap::ClampToEdge, 1e12), 255.0);
        assert!((0.0..=255.0).contains(&at(Wrap::MirroredRepeat, -3.3e7)));
    }

    /// Wrap modes are per axis: T clamps while S repeats.
    #[test]
    fn wrap_s_and_t_are_independent() {
        let t = tex(2, 2, &[[0, 0, 0, 255], [255, 0, 0, 255], [0, 255, 0, 255], [255, 255, 0, 255]], false);
        let t = with(t, Wrap::Repeat, Wrap::ClampToEdge, Filter::Nearest);
        let c = sample(&t, Vec2::new(1.25, 7.75));
        assert_eq!((c.x, c.y), (0.0, 1.0), "u repeats to texel 0, v clamps to the last row");
    }

    /// Nearest filtering returns one texel, no blend; alpha alone agrees with the full lookup.
    #[test]
    fn nearest_filter_and_alpha() {
        let t = tex(2, 1, &[[0, 0, 0, 0], [255, 255, 255, 255]], false);
        let n = with(t.clone(), Wrap::Repeat, Wrap::Repeat, Filter::Nearest);
        assert_eq!(sample(&n, Vec2::new(0.49, 0.5)), Vec4::ZERO);
        assert_eq!(sample(&n, Vec2::new(0.51, 0.5)), Vec4::ONE);
        for u in [0.1, 0.4, 0.5, 0.77, -0.3] {
            let uv = Vec2::new(u, 0.5);
            assert!((sample_alpha(&t, uv) - sample(&t, uv).w).abs() < 1e-6);
            assert!((sample_alpha(&n, uv) - sample(&n, uv).w).abs() < 1e-6);
        }
    }
}
