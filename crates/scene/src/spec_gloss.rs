//! `KHR_materials_pbrSpecularGlossiness` turned into metallic-roughness at load, so that both
//! renderers keep one material model.
//!
//! The conversion is the one Khronos published with the extension's archive (and that
//! `gltf-transform metalrough` applies): metallic is solved from the perceived brightness of
//! the diffuse and specular colours so that a dielectric (specular ≈ 0.04 grey) keeps its diffuse
//! colour as base colour and a metal (black diffuse) takes its specular colour; roughness is
//! 1 − glossiness. It is exact at those two ends and an approximation between them (a coloured
//! specular on a coloured diffuse has no metallic-roughness equivalent).
//!
//! Textures are converted texel by texel into a new base-colour texture (sRGB, alpha from the
//! diffuse texture) and a new metallic-roughness texture (linear, G roughness, B metallic); a
//! material whose two textures use different UV sets or transforms is converted from the
//! diffuse texture alone, with a warning.

use glam::{Vec3, Vec4};

use crate::srgb;
use crate::{Sampler, Texture};

/// glTF's dielectric F0.
const DIELECTRIC_F0: f32 = 0.04;

/// The metallic-roughness equivalent of one specular-glossiness sample (all linear).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetalRough {
    pub base_color: Vec4,
    pub metallic: f32,
    pub roughness: f32,
}

/// Perceived brightness (the conversion's weights: 0.299, 0.587, 0.114 on squared channels).
fn brightness(c: Vec3) -> f32 {
    (0.299 * c.x * c.x + 0.587 * c.y * c.y + 0.114 * c.z * c.z).sqrt()
}

/// The metallic value for which a base colour can produce both the diffuse and the specular
/// brightness: the positive root of a·m² + b·m + c = 0 (from diffuse = base·(1 − F0)(1 − m)
/// and specular = F0·(1 − m) + base·m, with the diffuse scaled by the energy the specular
/// leaves).
fn solve_metallic(diffuse: f32, specular: f32, one_minus_specular_strength: f32) -> f32 {
    if specular < DIELECTRIC_F0 {
        return 0.0;
    }
    let a = DIELECTRIC_F0;
    let b = diffuse * one_minus_specular_strength / (1.0 - a) + specular - 2.0 * a;
    let c = a - specular;
    let d = (b * b - 4.0 * a * c).max(0.0);
    ((-b + d.sqrt()) / (2.0 * a)).clamp(0.0, 1.0)
}

/// Converts one sample: `diffuse` RGBA, `specular` RGB and `glossiness`, linear, in [0, 1].
pub fn convert(diffuse: Vec4, specular: Vec3, glossiness: f32) -> MetalRough {
    let one_minus = 1.0 - specular.max_element();
    let metallic = solve_metallic(brightness(diffuse.truncate()), brightness(specular), one_minus);
    let eps = 1e-6;
    let from_diffuse = diffuse.truncate() * (one_minus / (1.0 - DIELECTRIC_F0) / (1.0 - metallic).max(eps));
    let from_specular = (specular - Vec3::splat(DIELECTRIC_F0 * (1.0 - metallic))) / metallic.max(eps);
    let base = from_diffuse.lerp(from_specular, metallic * metallic).clamp(Vec3::ZERO, Vec3::ONE);
    MetalRough { base_color: base.extend(diffuse.w), metallic, roughness: (1.0 - glossiness).clamp(0.0, 1.0) }
}

/// One sample of a specular-glossiness texture pair: the factor × the texel (sRGB RGB decoded,
/// alpha linear), or the factor alone.
pub struct Source<'a> {
    pub texture: Option<&'a Texture>,
    pub factor: Vec4,
}

impl Source<'_> {
    /// The value at normalised position (x, y) ∈ [0, 1)² (nearest texel).
    fn at(&self, x: f32, y: f32) -> Vec4 {
        let Some(t) = self.texture else { return self.factor };
        let px = ((x * t.width as f32) as u32).min(t.width - 1);
        let py = ((y * t.height as f32) as u32).min(t.height - 1);
        let i = 4 * (py as usize * t.width as usize + px as usize);
        let p = &t.rgba8[i..i + 4];
        let rgb = if t.srgb {
            srgb::srgb8_to_linear([p[0], p[1], p[2]])
        } else {
            Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0
        };
        rgb.extend(p[3] as f32 / 255.0) * self.factor
    }
}

/// Base-colour (sRGB) and metallic-roughness (linear) textures converted texel by texel from a
/// diffuse and a specular-glossiness source, at the larger source's resolution; the sampler is
/// the diffuse texture's (else the other's).
pub fn convert_textures(name: &str, diffuse: &Source, spec_gloss: &Source) -> (Texture, Texture) {
    let dims = |s: &Source| s.texture.map_or((1, 1), |t| (t.width, t.height));
    let (dw, dh) = dims(diffuse);
    let (sw, sh) = dims(spec_gloss);
    let (w, h) = if dw as u64 * dh as u64 >= sw as u64 * sh as u64 { (dw, dh) } else { (sw, sh) };
    let sampler: Sampler = diffuse.texture.or(spec_gloss.texture).map(|t| t.sampler).unwrap_or_default();
    let n = w as usize * h as usize;
    let (mut base, mut mr) = (Vec::with_capacity(4 * n), Vec::with_capacity(4 * n));
    for y in 0..h {
        for x in 0..w {
            let (u, v) = ((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let sg = spec_gloss.at(u, v);
            let c = convert(diffuse.at(u, v), sg.truncate(), sg.w);
            let b = srgb::linear_to_srgb8(c.base_color.truncate().as_dvec3());
            base.extend_from_slice(&[
                b[0],
                b[1],
                b[2],
                (c.base_color.w.clamp(0.0, 1.0) * 255.0).round() as u8,
            ]);
            let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            mr.extend_from_slice(&[0, q(c.roughness), q(c.metallic), 255]);
        }
    }
    let texture = |suffix: &str, rgba8: Vec<u8>, srgb: bool| Texture {
        name: format!("{name} ({suffix} from specular-glossiness)"),
        width: w,
        height: h,
        rgba8,
        srgb,
        sampler,
    };
    (texture("base colour", base, true), texture("metallic-roughness", mr, false))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-4
    }

    #[test]
    fn a_dielectric_keeps_its_diffuse_colour() {
        let d = Vec4::new(0.6, 0.3, 0.1, 0.5);
        let m = convert(d, Vec3::splat(0.04), 0.7);
        assert!(close(m.metallic, 0.0), "{m:?}");
        assert!(m.base_color.abs_diff_eq(d, 1e-4), "{m:?}");
        assert!(close(m.roughness, 0.3));
    }

    #[test]
    fn a_metal_takes_its_specular_colour() {
        let s = Vec3::new(0.95, 0.64, 0.54);
        let m = convert(Vec4::new(0.0, 0.0, 0.0, 1.0), s, 1.0);
        assert!(close(m.metallic, 1.0), "{m:?}");
        assert!(m.base_color.truncate().abs_diff_eq(s, 1e-4), "{m:?}");
        assert!(close(m.roughness, 0.0));
    }

    #[test]
    fn in_between_stays_in_range_and_specular_below_f0_is_dielectric() {
        for (d, s) in [(0.5, 0.5), (0.2, 0.9), (1.0, 1.0), (0.0, 0.0), (1.0, 0.02)] {
            let m = convert(Vec4::new(d, d, d, 1.0), Vec3::splat(s), 0.5);
            assert!((0.0..=1.0).contains(&m.metallic), "{d} {s}: {m:?}");
            assert!(m.base_color.min_element() >= 0.0 && m.base_color.max_element() <= 1.0, "{m:?}");
            if s < DIELECTRIC_F0 {
                assert_eq!(m.metallic, 0.0);
            }
        }
    }

    #[test]
    fn textures_convert_texel_by_texel_at_the_larger_resolution() {
        let tex = |w: u32, h: u32, px: Vec<u8>, srgb: bool| Texture {
            name: "t".into(),
            width: w,
            height: h,
            rgba8: px,
            srgb,
            sampler: Sampler::default(),
        };
        // Diffuse 2×1: red dielectric | black; spec-gloss 1×1 factor-scaled per side below.
        let diffuse = tex(2, 1, vec![255, 0, 0, 200, 0, 0, 0, 255], true);
        let sg = tex(1, 1, vec![255, 255, 255, 128], true);
        let (base, mr) = convert_textures(
            "m",
            &Source { texture: Some(&diffuse), factor: Vec4::ONE },
            &Source { texture: Some(&sg), factor: Vec4::new(0.04, 0.04, 0.04, 1.0) },
        );
        assert_eq!((base.width, base.height, mr.width, mr.height), (2, 1, 2, 1));
        assert!(base.srgb && !mr.srgb);
        // Left: dielectric red, alpha kept, roughness 1 − 128/255.
        assert_eq!(&base.rgba8[0..4], &[255, 0, 0, 200]);
        assert_eq!(mr.rgba8[1], 127);
        assert_eq!(mr.rgba8[2], 0);
    }
}
