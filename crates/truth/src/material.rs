//! What a surface point looks like at four wavelengths: glTF material inputs resolved through
//! textures, measured spectra where the material has them, Jakob–Hanika upsampling otherwise.

use crate::spectral::DenseSpectrum;
use crate::texture;
use crate::upsample::{self, RgbToSpectrum};
use color::WavelengthRange;
use glam::{Vec2, Vec3, Vec4};
use scene::{Material, SpectralReflectance, Texture, TextureRef};

/// Per-material data precomputed for the inner loop.
pub struct PreparedMaterial {
    uniform: Option<DenseSpectrum>,
    palette: Vec<([u8; 3], DenseSpectrum)>,
}

impl PreparedMaterial {
    pub fn new(m: &Material, range: WavelengthRange) -> Self {
        match &m.spectral {
            Some(SpectralReflectance::Uniform(s)) => {
                PreparedMaterial { uniform: Some(DenseSpectrum::new(s, range)), palette: vec![] }
            }
            Some(SpectralReflectance::Palette(p)) => PreparedMaterial {
                uniform: None,
                palette: p.iter().map(|e| (e.rgb8, DenseSpectrum::new(&e.spectrum, range))).collect(),
            },
            None => PreparedMaterial { uniform: None, palette: vec![] },
        }
    }
}

/// The texture coordinate sets at a surface point (`TEXCOORD_0`, `TEXCOORD_1`); each texture
/// reads the set its [`TextureRef::tex_coord`] names, through its `KHR_texture_transform`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoords(pub [Vec2; 2]);

impl TexCoords {
    /// Both sets at `uv` (tests; meshes with one set).
    pub fn one(uv: Vec2) -> Self {
        TexCoords([uv; 2])
    }

    /// The coordinates texture reference `r` samples at.
    #[inline]
    pub fn at(&self, r: &TextureRef) -> Vec2 {
        let uv = self.0.get(r.tex_coord as usize).copied().unwrap_or(Vec2::ZERO);
        r.transform.map_or(uv, |t| t.apply(uv))
    }
}

/// The texture `r` refers to and the coordinates to read it at.
fn tex<'a>(textures: &'a [Texture], r: &Option<TextureRef>, tc: &TexCoords) -> Option<(&'a Texture, Vec2)> {
    let r = r.as_ref()?;
    let t = textures.get(r.index).filter(|t| t.width > 0 && t.height > 0)?;
    Some((t, tc.at(r)))
}

/// Coverage: base colour alpha × base colour texture alpha × `COLOR_0` alpha (`color.w`).
/// What `alphaMode` MASK compares with the cutoff and BLEND uses as opacity.
pub fn alpha(m: &Material, textures: &[Texture], tc: &TexCoords, color: Vec4) -> f32 {
    let t = tex(textures, &m.base_color_texture, tc).map_or(1.0, |(t, uv)| texture::sample_alpha(t, uv));
    m.base_color.w * t * color.w
}

/// Base colour reflectance at four wavelengths.
///
/// Measured spectra replace the RGB: `Uniform` everywhere, `Palette` per texel (each of the
/// four texels of the bilinear footprint contributes its own spectrum, so the filtering
/// happens in the spectral domain). Everything else is base factor × `COLOR_0` (`color`) ×
/// filtered texture, upsampled. Measured spectra replace the factor and `COLOR_0` too (both are
/// RGB stand-ins for the spectrum); texels the palette does not list keep them.
#[allow(clippy::too_many_arguments)]
pub fn base_reflectance(
    m: &Material,
    pm: &PreparedMaterial,
    textures: &[Texture],
    up: &dyn RgbToSpectrum,
    tc: &TexCoords,
    color: Vec4,
    l: Vec4,
) -> Vec4 {
    if let Some(u) = &pm.uniform {
        return u.eval4(l);
    }
    let factor = m.base_color.truncate() * color.truncate();
    let t = tex(textures, &m.base_color_texture, tc);
    if let (false, Some((t, uv))) = (pm.palette.is_empty(), t) {
        let f = texture::footprint(t, uv);
        let mut acc = Vec4::ZERO;
        for (&at, w) in f.texels.iter().zip(f.weights) {
            if w == 0.0 {
                continue;
            }
            let t8 = texture::texel8(t, at);
            let s = match pm.palette.iter().find(|(k, _)| *k == [t8[0], t8[1], t8[2]]) {
                Some((_, s)) => s.eval4(l),
                None => {
                    let rgb = texture::texel(t, at).truncate() * factor;
                    upsample::reflectance(up, rgb.to_array(), l)
                }
            };
            acc += s * w;
        }
        return acc;
    }
    let rgb = match t {
        Some((t, uv)) => texture::sample(t, uv).truncate() * factor,
        None => factor,
    };
    upsample::reflectance(up, rgb.to_array(), l)
}

/// What an unlit surface (`KHR_materials_unlit`) shows, as linear RGB: base factor × `COLOR_0`
/// × texture, the colour a lit surface's reflectance would have had.
pub fn unlit_rgb(m: &Material, textures: &[Texture], tc: &TexCoords, color: Vec4) -> Vec3 {
    let factor = m.base_color.truncate() * color.truncate();
    match tex(textures, &m.base_color_texture, tc) {
        Some((t, uv)) => texture::sample(t, uv).truncate() * factor,
        None => factor,
    }
}

/// (metallic, roughness) with the texture applied (glTF: B = metallic, G = roughness).
pub fn metallic_roughness(m: &Material, textures: &[Texture], tc: &TexCoords) -> (f32, f32) {
    match tex(textures, &m.metallic_roughness_texture, tc) {
        Some((t, uv)) => {
            let s = texture::sample(t, uv);
            (m.metallic * s.z, m.roughness * s.y)
        }
        None => (m.metallic, m.roughness),
    }
}

/// The transmission weight (`KHR_materials_transmission`: factor × texture R) at a surface
/// point; `None` for an opaque material or where it is 0.
pub fn transmission(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<f32> {
    let t = m.transmission.as_ref()?;
    let w = match tex(textures, &t.texture, tc) {
        Some((x, uv)) => t.factor * texture::sample(x, uv).x,
        None => t.factor,
    };
    (w > 0.0).then_some(w.min(1.0))
}

/// The absorption coefficient per scene unit inside material `m`'s volume
/// (`KHR_materials_volume`), linear RGB, as the RGB media have it
/// (`scene::transmission::Volume::medium`); `None` when it is clear or has no volume.
pub fn volume_absorption(m: &Material) -> Option<[f64; 3]> {
    let md = m.transmission.as_ref()?.volume.as_ref()?.medium()?;
    // The spectral side upsamples it by boxes (`absorption_at`): the default upsampling of
    // every RGB medium, which the real-time renderer's box per node matches.
    debug_assert_eq!(md.upsampling, color::upsample::medium::Attenuation::Box);
    Some(md.absorption)
}

/// σ_a(λ) at four wavelengths of the RGB absorption `sigma` upsampled as a box per channel
/// (`color::upsample::medium::Attenuation::Box`, the default for RGB media).
pub fn absorption_at(sigma: [f64; 3], l: Vec4) -> Vec4 {
    let b = color::upsample::boxes::BoxSpectrum { rgb: sigma };
    Vec4::from_array(l.to_array().map(|x| b.eval(f64::from(x)) as f32))
}

/// The thin film (`KHR_materials_iridescence`) at a surface point: its weight (factor ×
/// texture R) and the film (thickness from the thickness texture's G); `None` without one or
/// where its weight is 0.
pub fn film(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<(f32, scene::film::Film)> {
    let ir = m.iridescence.as_ref()?;
    let weight = match tex(textures, &ir.texture, tc) {
        Some((t, uv)) => ir.factor * texture::sample(t, uv).x,
        None => ir.factor,
    };
    if weight <= 0.0 {
        return None;
    }
    let g = tex(textures, &ir.thickness_texture, tc).map(|(t, uv)| texture::sample(t, uv).y);
    let film = scene::film::Film { thickness_nm: f64::from(ir.thickness(g)), ior: f64::from(ir.ior) };
    Some((weight, film))
}

/// Linear emissive RGB (factor × sRGB-decoded texture).
pub fn emissive_rgb(m: &Material, textures: &[Texture], tc: &TexCoords) -> Vec3 {
    match tex(textures, &m.emissive_texture, tc) {
        Some((t, uv)) => m.emissive * texture::sample(t, uv).truncate(),
        None => m.emissive,
    }
}

/// The shading normal after the normal map; `n` is the interpolated vertex normal and
/// `tangent` (xyz, w = handedness) the interpolated tangent.
pub fn mapped_normal(
    m: &Material,
    textures: &[Texture],
    tc: &TexCoords,
    n: Vec3,
    tangent: Option<glam::Vec4>,
) -> Vec3 {
    normal_from_map(textures, &m.normal_texture, m.normal_scale, tc, n, tangent)
}

/// The clear coat (`KHR_materials_clearcoat`) at a surface point: its strength (factor ×
/// texture R) and perceptual roughness (factor × texture G); `None` without one, where the
/// strength is 0, or on an unlit material (which reflects nothing).
pub fn clearcoat(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<(f32, f32)> {
    let c = m.clearcoat.as_ref().filter(|_| !m.unlit)?;
    let r = tex(textures, &c.texture, tc).map(|(t, uv)| texture::sample(t, uv).x);
    let strength = c.weight_at(r);
    if strength <= 0.0 {
        return None;
    }
    let g = tex(textures, &c.roughness_texture, tc).map(|(t, uv)| texture::sample(t, uv).y);
    Some((strength, c.roughness_at(g)))
}

/// `KHR_materials_specular` at a surface point: the weight s (factor × texture A) and the F0
/// colour min(F0(η)·colour, 1) (`scene::specular::f0_color`, colour = factor × the colour
/// texture's RGB, linear), both read as the clear coat's textures are; `None` without one or
/// on an unlit material (the loader drops it on filmed and see-through ones).
pub fn specular(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<(f32, Vec3)> {
    let sp = m.specular.as_ref().filter(|_| !m.unlit)?;
    let a = tex(textures, &sp.texture, tc).map(|(t, uv)| texture::sample(t, uv).w);
    let rgb = tex(textures, &sp.color_texture, tc).map(|(t, uv)| texture::sample(t, uv).truncate());
    let f0 = scene::dielectric_f0(m.ior.max(1.0));
    Some((sp.weight_at(a), scene::specular::f0_color(f0, sp.color_at(rgb))))
}

/// `KHR_materials_sheen` at a surface point: the sheen colour (factor × the colour texture's
/// RGB, sRGB-decoded as the other colour textures are) and the perceptual sheen roughness
/// (factor × the roughness texture's A), both read as the specular's textures are
/// (`scene::sheen::Sheen::{color_at, roughness_at}`); `None` without one, where the layer is
/// off (a zero colour factor, or a colour that is black at this point) or on an unlit material.
pub fn sheen(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<(Vec3, f32)> {
    let sh = m.sheen.as_ref().filter(|s| !m.unlit && !s.is_off())?;
    let rgb = tex(textures, &sh.color_texture, tc).map(|(t, uv)| texture::sample(t, uv).truncate());
    let color = sh.color_at(rgb);
    if color.max_element() <= 0.0 {
        return None;
    }
    let a = tex(textures, &sh.roughness_texture, tc).map(|(t, uv)| texture::sample(t, uv).w);
    Some((color, sh.roughness_at(a)))
}

/// `KHR_materials_diffuse_transmission` at a surface point: the share t (factor × the
/// texture's A, linear) and the colour (factor × the colour texture's RGB, sRGB-decoded as the
/// other colour textures are), as `scene::diffuse_transmission::DiffuseTransmission::{factor_at,
/// color_at}` combine them; `None` without one, where t is 0 (a zero factor, or a texel of
/// alpha 0) or on an unlit material (the loader drops it there and on spec-gloss ones).
pub fn diffuse_transmission(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<(f32, Vec3)> {
    let dt = m.diffuse_transmission.as_ref().filter(|d| !m.unlit && !d.is_off())?;
    let a = tex(textures, &dt.texture, tc).map(|(t, uv)| texture::sample(t, uv).w);
    let weight = dt.factor_at(a);
    if weight <= 0.0 {
        return None;
    }
    let rgb = tex(textures, &dt.color_texture, tc).map(|(t, uv)| texture::sample(t, uv).truncate());
    Some((weight, dt.color_at(rgb)))
}

/// `KHR_materials_anisotropy` at a surface point: the direction in the tangent frame (unit) and
/// the strength, from the anisotropy texture's RGB (linear data) as `scene::anisotropy::
/// Anisotropy::at` reads it; `None` without one, at strength 0 (`is_off`) or on an unlit
/// material (the loader drops it there).
pub fn anisotropy(m: &Material, textures: &[Texture], tc: &TexCoords) -> Option<(Vec2, f32)> {
    let an = m.anisotropy.as_ref().filter(|a| !m.unlit && !a.is_off())?;
    let rgb = tex(textures, &an.texture, tc).map(|(t, uv)| texture::sample(t, uv).truncate());
    Some(an.at(rgb))
}

/// The shading frame of an anisotropic lobe at shading normal `n` (after the normal map):
/// x along the anisotropy direction t = normalize(d.x·t₀ + d.y·b₀), y along b = n × t. (t₀, b₀)
/// is the tangent frame the normal map uses (`tangent`'s xyz projected to the plane of `n`,
/// b₀ = n × t₀ × handedness), so that both renderers orient the direction alike; a point
/// without a tangent takes `scene::fallback_tangent(n)`.
pub fn anisotropy_frame(n: Vec3, tangent: Option<Vec4>, d: Vec2) -> crate::sampling::Frame {
    use crate::sampling::Frame;
    let tan = tangent.unwrap_or_else(|| scene::fallback_tangent(n));
    let f0 = Frame::from_normal_tangent(n, tan.truncate(), if tan.w < 0.0 { -1.0 } else { 1.0 });
    let t = (f0.t * d.x + f0.b * d.y).normalize_or_zero();
    Frame::from_normal_tangent(n, if t == Vec3::ZERO { f0.t } else { t }, 1.0)
}

/// The coat's normal: its own normal map in the base's tangent frame, or `n` (the interpolated
/// normal, not the base's normal map) without one.
pub fn coat_normal(
    m: &Material,
    textures: &[Texture],
    tc: &TexCoords,
    n: Vec3,
    tangent: Option<glam::Vec4>,
) -> Vec3 {
    match &m.clearcoat {
        Some(c) => normal_from_map(textures, &c.normal_texture, c.normal_scale, tc, n, tangent),
        None => n,
    }
}

/// `n` perturbed by the tangent-space normal map `map` scaled by `scale` in x and y.
fn normal_from_map(
    textures: &[Texture],
    map: &Option<TextureRef>,
    scale: f32,
    tc: &TexCoords,
    n: Vec3,
    tangent: Option<glam::Vec4>,
) -> Vec3 {
    let (Some((t, uv)), Some(tan)) = (tex(textures, map, tc), tangent) else { return n };
    let s = texture::sample(t, uv);
    let mut v = Vec3::new(2.0 * s.x - 1.0, 2.0 * s.y - 1.0, 2.0 * s.z - 1.0);
    v.x *= scale;
    v.y *= scale;
    let f =
        crate::sampling::Frame::from_normal_tangent(n, tan.truncate(), if tan.w < 0.0 { -1.0 } else { 1.0 });
    let out = f.to_world(v).normalize_or_zero();
    if out == Vec3::ZERO { n } else { out }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::upsample::GreyOnly;
    use color::Spectrum;
    use scene::PaletteEntry;

    fn l() -> Vec4 {
        Vec4::new(420.0, 500.0, 580.0, 660.0)
    }

    #[test]
    fn uniform_spectrum_replaces_base_colour() {
        let s = Spectrum::piecewise(vec![380.0, 730.0], vec![0.2, 0.9]).unwrap();
        let m = Material { spectral: Some(SpectralReflectance::Uniform(s.clone())), ..Default::default() };
        let pm = PreparedMaterial::new(&m, WavelengthRange::VISIBLE);
        let r = base_reflectance(&m, &pm, &[], &GreyOnly, &TexCoords::default(), Vec4::ONE, l());
        for (a, b) in r.to_array().iter().zip(l().to_array()) {
            assert!((*a as f64 - s.eval(b as f64)).abs() < 1e-5);
        }
    }

    #[test]
    fn palette_matches_texels_and_falls_back_to_upsampling() {
        let t = Texture {
            sampler: Default::default(),
            name: "p".into(),
            width: 2,
            height: 1,
            rgba8: vec![10, 20, 30, 255, 255, 255, 255, 255],
            srgb: true,
        };
        let m = Material {
            base_color_texture: Some(TextureRef { transform: None, index: 0, tex_coord: 0 }),
            spectral: Some(SpectralReflectance::Palette(vec![PaletteEntry {
                rgb8: [10, 20, 30],
                spectrum: Spectrum::Constant(0.3),
            }])),
            ..Default::default()
        };
        let pm = PreparedMaterial::new(&m, WavelengthRange::VISIBLE);
        let at = |u: f32| {
            let tc = TexCoords::one(Vec2::new(u, 0.5));
            base_reflectance(&m, &pm, std::slice::from_ref(&t), &GreyOnly, &tc, Vec4::ONE, l())
        };
        assert!((at(0.25) - Vec4::splat(0.3)).abs().max_element() < 1e-5);
        assert!((at(0.75) - Vec4::ONE).abs().max_element() < 1e-5);
        assert!((at(0.5) - Vec4::splat(0.65)).abs().max_element() < 1e-5);
    }

    #[test]
    fn flat_normal_map_keeps_the_normal() {
        let t = Texture {
            sampler: Default::default(),
            name: "n".into(),
            width: 1,
            height: 1,
            rgba8: vec![128, 128, 255, 255],
            srgb: false,
        };
        let m = Material {
            normal_texture: Some(TextureRef { transform: None, index: 0, tex_coord: 0 }),
            ..Default::default()
        };
        let n = mapped_normal(
            &m,
            &[t],
            &TexCoords::default(),
            Vec3::Y,
            Some(glam::Vec4::new(1.0, 0.0, 0.0, 1.0)),
        );
        assert!((n - Vec3::Y).length() < 0.01);
    }
}
