//! The scene description shared by the real-time renderer (`render`) and the ground-truth
//! path tracer (`truth`): both draw exactly this, so their images can be compared.
//!
//! Geometry is flattened to world space at load time (node transforms applied), which is what
//! both consumers want. Spectral data from glTF `extras` is resolved into
//! [`color::Spectrum`] values at load time, so errors surface with the file and field named.

mod accessors;
pub mod anisotropy;
pub mod builtin;
pub mod clearcoat;
mod context;
pub mod diffuse_transmission;
mod draco;
pub mod emission;
pub mod emitters;
pub mod environment;
mod error;
pub mod export;
mod extras;
pub mod film;
pub mod framing;
mod gltf_ext;
mod gltf_file;
mod instancing;
mod ktx2;
pub mod medium;
mod meshopt_decode;
mod pose;
mod primitive;
pub mod sheen;
pub mod sky;
pub mod spec_gloss;
pub mod spectrum_desc;
pub mod specular;
pub mod srgb;
mod tangents;
pub mod transmission;
mod uri;
mod variants;
pub mod vertex;
pub mod water;

use std::path::Path;

use color::Spectrum;
use glam::{Mat4, Vec2, Vec3, Vec4};

pub use builtin::{BUILTIN_NAMES, builtin};
pub use environment::{Environment, EnvironmentError};
pub use error::{Result, SceneError};
pub use export::write_gltf;
pub use gltf_file::{
    AnimationRef, LoadOptions, MAX_EMISSIVE, MAX_FILE_BYTES, MAX_IMAGE_DECODED_BYTES, MAX_IMAGE_DIMENSION,
    MAX_IMAGE_FILE_BYTES, MAX_LIGHT_INTENSITY, MAX_TRIANGLES, load, load_slice, load_slice_with, load_with,
};
pub use pose::MAX_TIME as MAX_ANIMATION_TIME;

/// Loads a scene by built-in name (`cornell`, `colorchecker`, `metamerism`) or, when the
/// argument ends in `.gltf` or `.glb` (any case), from that file.
pub fn load_any(name_or_path: &str) -> Result<Scene> {
    load_any_with(name_or_path, &LoadOptions::default())
}

/// [`load_any`] with options for a file.
pub fn load_any_with(name_or_path: &str, opts: &LoadOptions) -> Result<Scene> {
    let lower = name_or_path.to_ascii_lowercase();
    if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        load_with(Path::new(name_or_path), opts)
    } else {
        builtin(name_or_path)
    }
}

/// A fully loaded scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where the scene came from (a path, or `builtin:NAME`); used in messages.
    pub source: String,
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub lights: Vec<Light>,
    pub camera: Camera,
    pub spectral: SpectralSettings,
    /// Underwater settings (see the underwater issue); `None` for scenes in air.
    pub water: Option<WaterSettings>,
    /// What the loader skipped or approximated (unsupported optional extensions, points and
    /// lines, …), one line each, for the command line to print.
    pub warnings: Vec<String>,
    /// Light arriving from infinitely far away ([`environment`]); from the file's
    /// `extras.environment` or the command line. `None`: no environment light.
    pub environment: Option<Environment>,
    /// A homogeneous medium in RGB filling the scene (`extras.medium`, [`medium::RgbMedium`]);
    /// `None`: clear air. Never together with [`Self::water`].
    pub medium: Option<medium::RgbMedium>,
    /// The files the scene was read from: the glTF file and every file it references (buffers,
    /// images, CSV spectra, environment maps); empty for scenes built in code. A command's
    /// outputs must not overwrite any of them (`color::outfile::check_distinct`).
    pub inputs: Vec<std::path::PathBuf>,
    /// Where the file's origin went: every position here is the file's minus this
    /// ([`Scene::recentre`]; zero unless the scene lay far from its origin). Coordinates given
    /// apart from the scene in its file's frame (`truth --medium`'s box) are moved by it too.
    pub origin: glam::DVec3,
    /// Each of [`Scene::inputs`]'s [`color::input::FileStamp`] when the loader took it (`None`
    /// where it could not be stamped): a record hashing the files afterwards checks that they
    /// are still what was loaded.
    pub input_stamps: Vec<Option<color::input::FileStamp>>,
    /// What the loader was asked to choose among a file's alternatives, resolved against it
    /// (`variant`, `animation`, `time`): with the input files' contents, what identifies the
    /// scene (a ground-truth record made at one moment of an animation must not merge with
    /// another's). Empty when nothing was chosen.
    pub choices: Vec<(String, String)>,
    /// The end of the animation the scene was posed by (its last key, in seconds), `None` at
    /// rest: what `render --times START:end:STEP` reads.
    pub animation_end: Option<f64>,
}

impl Scene {
    /// A scene with nothing in it yet but the camera, in air, with the default spectral
    /// settings: for scenes built in code (built-ins, tests), which push meshes, materials
    /// and lights into it.
    pub fn empty(source: impl Into<String>, camera: Camera) -> Scene {
        Scene {
            warnings: vec![],
            source: source.into(),
            meshes: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            lights: Vec::new(),
            camera,
            spectral: SpectralSettings::default(),
            water: None,
            environment: None,
            medium: None,
            inputs: Vec::new(),
            origin: glam::DVec3::ZERO,
            input_stamps: Vec::new(),
            choices: Vec::new(),
            animation_end: None,
        }
    }

    /// A warning when measured reflectances (a material's `reflectance` or palette entries given
    /// as samples) end inside the render range `lo`–`hi` nm, where they are taken as zero: a
    /// spectrophotometer's 400–700 nm file made a white tile black at both ends of 380–730 nm
    /// without a word. One line for all of them, naming the first; `None` where all cover it.
    pub fn short_reflectances(&self, lo: f64, hi: f64) -> Option<String> {
        let mut short = Vec::new();
        for m in &self.materials {
            let spectra: Vec<&color::Spectrum> = match &m.spectral {
                Some(SpectralReflectance::Uniform(s)) => vec![s],
                Some(SpectralReflectance::Palette(p)) => p.iter().map(|e| &e.spectrum).collect(),
                None => continue,
            };
            for s in spectra {
                if let color::Spectrum::Piecewise { lambda, .. } = s
                    && let (Some(&a), Some(&b)) = (lambda.first(), lambda.last())
                    && (a > lo || b < hi)
                {
                    short.push((m.name.clone(), a, b));
                }
            }
        }
        let (name, a, b) = short.first()?;
        let fix = "extend the data to the range, or render --range within it";
        Some(match short.len() {
            1 => format!(
                "the measured reflectance of material '{name}' covers {a}–{b} nm, less than the render range \
                 {lo}–{hi} nm: taken as zero outside its data ({fix})"
            ),
            n => format!(
                "{n} measured reflectances cover less than the render range {lo}–{hi} nm (the first, of material \
                 '{name}', covers {a}–{b} nm): taken as zero outside their data ({fix})"
            ),
        })
    }
}

impl Mesh {
    /// A parallelogram with corners `o`, `o+u`, `o+u+v`, `o+v`, facing `u × v`, UVs upright
    /// when `u` points right and `v` up (glTF's top-left origin).
    pub fn quad(o: Vec3, u: Vec3, v: Vec3, material: usize) -> Mesh {
        builtin::shapes::quad(o, u, v, material)
    }

    /// A smooth UV sphere of `rings` × `segments` quads sharing their vertices, normals radial,
    /// counter-clockwise outside (the built-in scenes' spheres).
    pub fn uv_sphere(centre: Vec3, radius: f32, rings: u32, segments: u32, material: usize) -> Mesh {
        builtin::shapes::sphere(centre, radius, rings, segments, material)
    }
}

/// A triangle mesh in world space.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// Unit length, one per position; generated (flat) by the loader when a file has none.
    pub normals: Vec<Vec3>,
    /// xyz tangent, w handedness (glTF convention); empty when the mesh has no normal map.
    pub tangents: Vec<Vec4>,
    /// `TEXCOORD_0`, one per position; empty when the primitive has no texture coordinates.
    pub uvs: Vec<Vec2>,
    /// `TEXCOORD_1`, one per position; empty when the primitive has none. A texture whose
    /// [`TextureRef::tex_coord`] is 1 reads these.
    pub uvs1: Vec<Vec2>,
    /// `COLOR_0` as linear RGBA, one per position; empty = white. Multiplies the base colour
    /// (glTF 2.0 §3.9.2).
    pub colors: Vec<Vec4>,
    /// Triangle list, counter-clockwise front faces.
    pub indices: Vec<u32>,
    pub material: usize,
}

/// glTF metallic-roughness material plus spectral additions.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Linear RGBA factor.
    pub base_color: Vec4,
    pub base_color_texture: Option<TextureRef>,
    pub metallic: f32,
    pub roughness: f32,
    /// glTF layout: B = metallic, G = roughness.
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    /// glTF `occlusionTexture` (R channel, linear): the author's baked ambient occlusion. The
    /// real-time renderer darkens its environment light with it (glTF: "indirect lighting");
    /// the path tracer traces occlusion and ignores it.
    pub occlusion_texture: Option<TextureRef>,
    pub occlusion_strength: f32,
    /// Linear RGB, already multiplied by `KHR_materials_emissive_strength`.
    pub emissive: Vec3,
    pub emissive_texture: Option<TextureRef>,
    /// glTF `alphaMode` with `alphaCutoff`; the alpha is base colour alpha × texture alpha ×
    /// `COLOR_0` alpha.
    pub alpha_mode: AlphaMode,
    /// glTF `doubleSided`: back faces are drawn (normal flipped towards the viewer) only when
    /// true; single-sided back faces are culled by the rasteriser and not hit by the tracer.
    pub double_sided: bool,
    /// Measured reflectance spectra that override the RGB base colour for ground truth.
    pub spectral: Option<SpectralReflectance>,
    /// Spectral radiance of the emission, scaled so its luminance equals that of `emissive`
    /// (same convention as [`Emission`]); `None` = upsample `emissive` as RGB.
    pub emission_spectrum: Option<Spectrum>,
    /// `KHR_materials_unlit`: the surface shows its base colour (factor × texture × `COLOR_0`)
    /// whatever the lighting, and reflects nothing. Both renderers draw it as an emitter whose
    /// RGB is the base colour, upsampled like every RGB emission (the illuminant variant, so
    /// white is the scene's white); it does not light other surfaces in real time, and in the
    /// path tracer only through paths that hit it (it is not a light source).
    pub unlit: bool,
    /// `KHR_materials_iridescence`: a thin dielectric film over the surface ([`film`]).
    pub iridescence: Option<Iridescence>,
    /// `KHR_materials_ior`: the dielectric's index of refraction (glTF's default 1.5), which
    /// sets its normal-incidence reflectance F0 = ((η − 1)/(η + 1))² ([`Material::dielectric_f0`])
    /// and the index under a thin film.
    pub ior: f32,
    /// `KHR_materials_transmission` (with `_volume` and `_dispersion`): a see-through
    /// dielectric ([`transmission`]); `None` when the factor is 0 (opaque).
    pub transmission: Option<transmission::Transmission>,
    /// `KHR_materials_clearcoat`: a clear coat over the whole material ([`clearcoat`]); `None`
    /// when its factor is 0.
    pub clearcoat: Option<clearcoat::Clearcoat>,
    /// `KHR_materials_specular`: the dielectric's specular strength and F0 colour
    /// ([`specular`]); `None` when absent or at its defaults, and on unlit, filmed and
    /// see-through materials (dropped there with a warning).
    pub specular: Option<specular::Specular>,
    /// `KHR_materials_sheen`: a layer of fibres over the whole material ([`sheen`]); `None`
    /// when absent or off (a zero `sheenColorFactor`, the extension's default, disables the
    /// layer whatever its textures hold), and on unlit and specular-glossiness materials, which
    /// the extension excludes (dropped there with a warning). It may sit with a coat, a
    /// specular, a transmission or a film.
    pub sheen: Option<sheen::Sheen>,
    /// `KHR_materials_anisotropy`: the specular lobe stretched along a direction in the tangent
    /// frame ([`anisotropy`]); `None` when absent or at strength 0, and on unlit and
    /// specular-glossiness materials (dropped there with a warning). Meshes with it get
    /// tangents ([`Material::tangent_set`]).
    pub anisotropy: Option<anisotropy::Anisotropy>,
    /// `KHR_materials_diffuse_transmission`: part of the dielectric's diffuse light passed to
    /// the other side of the surface ([`diffuse_transmission`]); `None` when absent or at factor
    /// 0, and on unlit and specular-glossiness materials (dropped there with a warning).
    pub diffuse_transmission: Option<diffuse_transmission::DiffuseTransmission>,
}

/// Largest index of refraction a material may give (diamond is 2.42; KHR_materials_ior sets no
/// bound, and tools write large ones to make a surface all specular): f0 is 0.9996 there, and
/// the refraction's arithmetic stays far inside f32. `KHR_materials_ior`'s special value 0 (the
/// specular-glossiness compatibility mode, an infinite index) is read as this.
pub const MAX_IOR: f32 = 1.0e4;

/// A dielectric's normal-incidence reflectance from air, ((η − 1)/(η + 1))²: exactly glTF's
/// constant 0.04 at its default η = 1.5 (so that files without `KHR_materials_ior` keep the
/// f32 value both renderers always used). One home for both renderers.
pub fn dielectric_f0(ior: f32) -> f32 {
    if ior == 1.5 {
        return 0.04;
    }
    let r = (ior - 1.0) / (ior + 1.0);
    r * r
}

impl Material {
    /// The dielectric's normal-incidence reflectance from air ([`dielectric_f0`]).
    pub fn dielectric_f0(&self) -> f32 {
        dielectric_f0(self.ior)
    }

    /// What tangent frame the material's meshes need, if any: a normal map's (the base's, or
    /// the coat's, which shares it) on that map's UV set, else an anisotropy's on its texture's
    /// set (TEXCOORD_0 without one).
    pub fn tangent_need(&self) -> Option<TangentNeed> {
        let map = self.normal_texture.or(self.clearcoat.as_ref().and_then(|c| c.normal_texture));
        if let Some(t) = map {
            return Some(TangentNeed { set: t.tex_coord, uv_required: true });
        }
        let a = self.anisotropy.as_ref()?;
        Some(TangentNeed { set: a.texture.map_or(0, |t| t.tex_coord), uv_required: false })
    }
}

/// The tangent frame a mesh's material needs ([`Material::tangent_need`]): MikkTSpace tangents
/// on UV set `set` when the mesh has none. A normal map cannot be oriented without that set
/// (`uv_required`: the loader refuses the file); an anisotropy direction can, by the tangent
/// [`fallback_tangent`] makes from the normal alone, the same in both renderers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TangentNeed {
    pub set: u32,
    pub uv_required: bool,
}

/// The tangent frame of a double-sided surface seen from `side` (+1 its front, −1 its back) as
/// glTF's Khronos sample viewer turns it: on a back face the normal, the tangent and the
/// bitangent are all negated, so that a normal map's normal there is the exact opposite of the
/// front's (the same bump seen from behind) and an anisotropy's direction keeps its axis. With
/// the normal flipped, b = n × t · w stays −b when the handedness w flips with the tangent:
/// both renderers pass the vertex tangent through this (the real-time renderer's
/// `normal_mapped` and `anisotropy_target` in passes/gbuffer.wgsl by the same rule).
pub fn facing_tangent(tangent: Vec4, side: f32) -> Vec4 {
    tangent * side
}

/// A unit tangent perpendicular to unit normal `n` that depends on `n` alone (Duff et al. 2017's
/// branchless basis), with handedness +1: the frame of meshes whose anisotropy has no UV set to
/// orient it. The loader makes it from the mesh's own normals, before its node's transform,
/// which then turns it as it turns every tangent (a brushed part keeps its grain when moved).
pub fn fallback_tangent(n: Vec3) -> Vec4 {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x).extend(1.0)
}

/// `KHR_materials_iridescence` of a material: a thin dielectric film whose interference
/// reflectance ([`film::reflectance`]) replaces the specular Fresnel term in proportion to
/// `factor` (× the texture's R channel), over the dielectric base (index 1.5, F0 0.04) and the
/// metallic one (its base colour as F0).
#[derive(Clone, Debug, PartialEq)]
pub struct Iridescence {
    /// `iridescenceFactor` in [0, 1].
    pub factor: f32,
    /// `iridescenceTexture`: R multiplies `factor`.
    pub texture: Option<TextureRef>,
    /// `iridescenceIor`: the film's index (≥ 1).
    pub ior: f32,
    /// `iridescenceThicknessMinimum` / `Maximum`, nm: the thickness is
    /// min + (max − min) × the thickness texture's G channel, or `thickness_max` without one.
    pub thickness_min: f32,
    pub thickness_max: f32,
    pub thickness_texture: Option<TextureRef>,
}

/// Thickest film a material may describe, nm. Interference colours fade out beyond a few
/// micrometres (white light's coherence length), and the phase 4π·η·d/λ must stay exact in
/// the real-time renderer's f32.
pub const MAX_FILM_THICKNESS_NM: f32 = 100_000.0;

/// Largest film index accepted (diamond is 2.4; no film material is near this).
pub const MAX_FILM_IOR: f32 = 10.0;

impl Iridescence {
    /// The film thickness at a point whose thickness texture reads `g` (G channel, 0–1).
    pub fn thickness(&self, g: Option<f32>) -> f32 {
        match g {
            Some(g) if self.thickness_texture.is_some() => {
                self.thickness_min + (self.thickness_max - self.thickness_min) * g.clamp(0.0, 1.0)
            }
            _ => self.thickness_max,
        }
    }
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: Vec4::ONE,
            base_color_texture: None,
            metallic: 0.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            alpha_mode: AlphaMode::Opaque,
            // Built-in scenes are seen from inside (Cornell boxes); glTF files say what they are
            // (glTF's own default is false).
            double_sided: true,
            spectral: None,
            emission_spectrum: None,
            unlit: false,
            iridescence: None,
            ior: 1.5,
            transmission: None,
            clearcoat: None,
            specular: None,
            sheen: None,
            anisotropy: None,
            diffuse_transmission: None,
        }
    }
}

/// glTF `alphaMode`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum AlphaMode {
    /// Alpha ignored.
    #[default]
    Opaque,
    /// Fully opaque where alpha ≥ cutoff, absent elsewhere (foliage, cut-outs).
    Mask { cutoff: f32 },
    /// Alpha is coverage: a fraction `alpha` of the light is stopped by the surface (decals,
    /// glass-like see-through geometry without refraction).
    Blend,
}

/// `KHR_texture_transform`: uv' = T(offset) · R(rotation) · S(scale) · uv.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureTransform {
    pub offset: Vec2,
    /// Radians, counter-clockwise in UV space.
    pub rotation: f32,
    pub scale: Vec2,
}

impl TextureTransform {
    /// The 3×3 matrix of the extension's definition (column-major, for `uv' = M · (u, v, 1)`).
    pub fn matrix(&self) -> glam::Mat3 {
        let (s, c) = self.rotation.sin_cos();
        let t = glam::Mat3::from_cols(Vec3::X, Vec3::Y, self.offset.extend(1.0));
        let r = glam::Mat3::from_cols(Vec3::new(c, -s, 0.0), Vec3::new(s, c, 0.0), Vec3::Z);
        let sc = glam::Mat3::from_diagonal(self.scale.extend(1.0));
        t * r * sc
    }

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        (self.matrix() * uv.extend(1.0)).truncate()
    }
}

/// Texture wrap mode (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    #[default]
    Repeat,
    ClampToEdge,
    MirroredRepeat,
}

impl Wrap {
    /// Texel index `i` (any integer) of an axis of `n` texels under this mode: what a GPU
    /// sampler addresses (the path tracer's lookups and the emitters' texture means use it).
    #[inline]
    pub fn index(self, i: i64, n: i64) -> u32 {
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::ClampToEdge => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let k = i.rem_euclid(2 * n);
                if k < n { k } else { 2 * n - 1 - k }
            }
        }) as u32
    }
}

/// Texture filter (glTF sampler `magFilter`/`minFilter`; mipmapped minification filters are
/// `Linear`/`Nearest` with [`Sampler::mipmaps`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    Nearest,
    #[default]
    Linear,
}

/// How a texture is sampled (glTF `samplers[i]`; the defaults are glTF's: repeat, linear,
/// mipmapped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    pub mag: Filter,
    pub min: Filter,
    pub mipmaps: bool,
}

impl Default for Sampler {
    fn default() -> Self {
        Sampler {
            wrap_s: Wrap::Repeat,
            wrap_t: Wrap::Repeat,
            mag: Filter::Linear,
            min: Filter::Linear,
            mipmaps: true,
        }
    }
}

/// Measured reflectance attached to a material.
#[derive(Clone, Debug)]
pub enum SpectralReflectance {
    /// One spectrum for the whole material (multiplied by nothing: it replaces base colour).
    Uniform(Spectrum),
    /// A palette keyed by the 8-bit sRGB texel value of the base-colour texture: a texel
    /// whose value equals `rgb8` uses `spectrum`; other texels fall back to upsampling.
    Palette(Vec<PaletteEntry>),
}

#[derive(Clone, Debug)]
pub struct PaletteEntry {
    pub rgb8: [u8; 3],
    pub spectrum: Spectrum,
}

/// A texture reference with its UV set and optional `KHR_texture_transform`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    pub index: usize,
    /// 0 = `TEXCOORD_0` ([`Mesh::uvs`]), 1 = `TEXCOORD_1` ([`Mesh::uvs1`]).
    pub tex_coord: u32,
    pub transform: Option<TextureTransform>,
}

impl TextureRef {
    pub fn new(index: usize) -> Self {
        TextureRef { index, tex_coord: 0, transform: None }
    }
}

/// An RGBA8 image. `srgb` says whether the RGB channels are sRGB-encoded (base colour,
/// emissive) or linear data (normals, metallic-roughness).
#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
    pub srgb: bool,
    pub sampler: Sampler,
}

/// A light's emission: RGB (linear sRGB, the glTF way) and optionally a spectrum.
///
/// Convention: when `spectrum` is given it is scaled so that its CIE 1931 luminance equals
/// the luminance of `rgb × intensity`; RGB rendering then uses the spectrum's own linear
/// sRGB colour at that luminance. See `docs/scene-format.md`.
#[derive(Clone, Debug)]
pub struct Emission {
    pub rgb: Vec3,
    pub intensity: f32,
    pub spectrum: Option<Spectrum>,
}

#[derive(Clone, Debug)]
pub enum LightKind {
    /// Intensity in candela (glTF), at `position`.
    Point { position: Vec3, range: Option<f32> },
    /// Cone around `direction` (unit, pointing away from the light).
    Spot { position: Vec3, direction: Vec3, inner_cone: f32, outer_cone: f32, range: Option<f32> },
    /// Illuminance in lux arriving along `direction` (unit, pointing away from the light).
    Directional { direction: Vec3 },
}

#[derive(Clone, Debug)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    pub emission: Emission,
    /// `Some(i)`: this punctual light is a stand-in for the emissive geometry `meshes[i]` (the
    /// same lamp), for renderers that cannot light with emissive surfaces. A renderer that
    /// samples emissive meshes as lights (the path tracer) must skip it, or the lamp would count
    /// twice; a renderer that only shades punctual lights uses it and draws `meshes[i]` merely
    /// as a glowing surface. In glTF: light `extras.stands_in_for` = the index of the node
    /// holding the emissive mesh (it resolves to that node's first primitive).
    /// `Some(`[`sky::SKY_STAND_IN`]`)`: the diffuse sky under water (see [`sky`]), not a mesh;
    /// derived from `WaterSettings::sky`, never written to files.
    pub stands_in_for: Option<usize>,
}

impl Light {
    /// A point light of white RGB emission (`rgb` 1, no spectrum) with `intensity` at
    /// `position`, without a range.
    pub fn point(name: &str, position: Vec3, intensity: f32) -> Self {
        Light {
            name: name.into(),
            kind: LightKind::Point { position, range: None },
            emission: Emission { rgb: Vec3::ONE, intensity, spectrum: None },
            stands_in_for: None,
        }
    }
}

/// A perspective pinhole camera.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Camera-to-world transform (glTF convention: looks down −Z, +Y up).
    pub transform: Mat4,
    /// Vertical field of view, radians.
    pub yfov: f32,
    pub znear: f32,
    pub zfar: f32,
    /// Width / height the scene was authored for; renderers use their own target's aspect.
    pub aspect: Option<f32>,
    /// `Some((xmag, ymag))`: an orthographic camera of half-width xmag and half-height ymag
    /// (glTF); `yfov` is then unused.
    pub ortho: Option<(f32, f32)>,
}

/// Smallest znear / zfar a perspective camera is drawn with: the real-time renderer's 32-bit
/// depth buffer resolves positions to ~0.1 % down to a ratio of 10⁻⁷ (measured on the Cornell
/// box, docs/limits.md), and below that the image is wrong (10⁻⁸: 13 % darker; 10⁻⁹: black). A
/// smaller znear is raised to zfar × this, with a warning, for both renderers
/// ([`Camera::clip_near`]).
pub const MIN_NEAR_FAR_RATIO: f32 = 1e-6;
/// Orthographic magnifications (|xmag|, |ymag|) accepted, in scene units: outside it the
/// projection's 1/mag and the image's aspect xmag/ymag leave f32.
pub const ORTHO_MAG_RANGE: (f32, f32) = (1e-6, 1e6);
/// Narrowest vertical field of view accepted, radians (the projection holds 1/tan(yfov/2)).
pub const MIN_YFOV: f32 = 1e-5;
/// Largest world coordinate a loaded scene may have, in scene units (|x|, |y|, |z| of every
/// vertex, camera and light once their nodes' transforms are applied): the renderers work in
/// single precision, and far out the path tracer's hierarchy and intersections fail (a panic
/// at 10²⁵, wrong images at 10¹²). The path tracer renders the Khronos Duck (±1 unit) scaled
/// to span ±10¹⁰ units as at its own size (ΔE2000 ≤ 0.005 in every pixel; docs/scene-format.md
/// gives the commands): the bound leaves a factor 10.
pub const MAX_COORDINATE: f32 = 1e9;
/// The farthest clipping distance the renderers draw, in scene units: farther than any two
/// points of a scene can lie apart (2√3 × [`MAX_COORDINATE`]), and far enough below f32's
/// range that a point on the far plane can be squared (its distance to the eye). A file's
/// larger zfar is drawn here (nothing is lost); a larger znear is refused.
pub const MAX_CLIP_DISTANCE: f32 = 1e10;
/// Largest |normalTexture.scale| accepted.
pub const MAX_NORMAL_SCALE: f32 = 1000.0;

impl Camera {
    /// The near plane both renderers clip surfaces at: `znear`, or for a perspective camera at
    /// least `zfar` × [`MIN_NEAR_FAR_RATIO`] (one home for the depth-precision rule, so the path
    /// tracer clips where the rasteriser can).
    pub fn clip_near(&self) -> f32 {
        if self.ortho.is_some() { self.znear } else { self.znear.max(self.zfar * MIN_NEAR_FAR_RATIO) }
    }

    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, yfov: f32) -> Self {
        Camera {
            transform: Mat4::look_at_rh(eye, target, up).inverse(),
            yfov,
            znear: 0.01,
            zfar: 1000.0,
            aspect: None,
            ortho: None,
        }
    }

    pub fn position(&self) -> Vec3 {
        self.transform.w_axis.truncate()
    }
}

/// The reference white of a scene that names none (`spectra.white`).
pub const DEFAULT_WHITE: &str = "D65";

/// Spectral rendering defaults carried by the scene (the CLI overrides them).
#[derive(Clone, Debug, Default)]
pub struct SpectralSettings {
    /// Observer name for `color::Observer::by_name`.
    pub observer: Option<String>,
    /// Wavelength range in nm.
    pub range: Option<(f32, f32)>,
    /// Number of wavelength samples.
    pub wavelengths: Option<u32>,
    /// The illuminant whose white is the reference white for XYZ → RGB (default D65).
    pub white: Option<String>,
}

impl SpectralSettings {
    /// The reference white's name: `spectra.white`, else [`DEFAULT_WHITE`]. Both renderers
    /// take the scene's white from here (the loader checked that the name resolves).
    pub fn white_name(&self) -> &str {
        self.white.as_deref().unwrap_or(DEFAULT_WHITE)
    }
}

/// Underwater settings, validated by the underwater work.
#[derive(Clone, Debug)]
pub struct WaterSettings {
    /// Jerlov type name, e.g. `II`, `3C`, or a blend like `II.5`.
    pub water_type: String,
    /// Camera depth below the surface, metres.
    pub depth: f32,
    /// Unit direction towards the sun (above water).
    pub sun_direction: Vec3,
    /// Metres per scene unit.
    pub scale: f32,
    /// Diffuse sky light, as a multiple of the sun's: the sky's downwelling irradiance just
    /// below the surface is `sky` × the sun's there (emission × cosine of its refracted
    /// direction to the vertical), with the sun's spectrum (a simplification both renderers
    /// share). 0 = no sky; glTF `extras.water.sky`, 0 ≤ sky ≤ [`MAX_SKY`].
    pub sky: f32,
}

/// Largest accepted [`WaterSettings::sky`]: even under overcast skies the diffuse light is a few
/// times the (weakened) direct sun, not tens of times, so a larger value is a typo.
pub const MAX_SKY: f32 = 10.0;
