//! A scene uploaded to the GPU: vertex and index buffers holding all meshes (as few as the
//! device's `max_buffer_size` allows; see [`Chunks`]), a bind group per material, and the lights (their per-wavelength spectra are built by the renderer
//! because they depend on the settings).
//!
//! Textures are uploaded with a full mip chain (CPU box filter; sRGB textures are decoded to
//! linear first, so filtering happens in linear space) and sampled through one wgpu sampler per
//! distinct [`scene::Sampler`] (wrap S/T, mag/min filter, mipmaps or level 0 only). Each of a
//! material's five textures has its own sampler, UV set (`TEXCOORD_0`/`_1`) and
//! `KHR_texture_transform` matrix, carried by [`MaterialUniforms`].

use crate::error::{RenderError, Result};
use glam::{Mat3, Vec2, Vec3, Vec4};
use scene::{AlphaMode, LightKind, Scene, TextureRef};
use wgpu::util::DeviceExt;

/// Most lights a scene may have (the shader keeps two floats per light per pixel).
/// `MAX_LIGHTS` in `passes/shading.wgsl` and the media hooks (checked by `layout_tests`).
pub const MAX_LIGHTS: usize = 32;

/// Materials a scene may have: the G-buffer's 16-bit material slot holds index + 1
/// ([`crate::passes::GBUFFER_FORMATS`]).
pub const MAX_MATERIALS: usize = u16::MAX as usize - 1;

/// Interleaved vertex, 72 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// `TEXCOORD_0` (zero when the mesh has none).
    pub uv: [f32; 2],
    /// xyz tangent, w handedness; zero when the mesh has none (no normal mapping then).
    pub tangent: [f32; 4],
    /// `COLOR_0`, linear RGBA (white when the mesh has none); multiplies base colour and alpha.
    pub color: [f32; 4],
    /// `TEXCOORD_1` (zero when the mesh has none).
    pub uv1: [f32; 2],
}

impl Vertex {
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 6] = wgpu::vertex_attr_array![
        0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4, 4 => Float32x4, 5 => Float32x2
    ];

    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &Self::ATTRIBUTES,
        }
    }
}

/// Texture slots of a material, in binding order (textures at bindings 1..=16, their samplers
/// at 17..=32; the order of `TEX_*` in `wgsl/material.wgsl`). Sixteen: WebGPU's guaranteed
/// sampled textures and samplers per stage, which the G-buffer's fragment stage uses up.
pub const TEXTURE_SLOTS: usize = 16;

/// `MaterialUniforms` in `wgsl/material.wgsl` (checked by `layout_tests`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialUniforms {
    pub base_color: [f32; 4],
    /// rgb emissive, w normal scale.
    pub emissive: [f32; 4],
    /// metallic, roughness, 1 with a normal map, occlusion strength (0 without a texture).
    pub params: [f32; 4],
    /// x alpha mode ([`ALPHA_OPAQUE`], [`ALPHA_MASK`], [`ALPHA_BLEND`]), y alpha cutoff, z 1 when
    /// double-sided, w 1 when unlit (`KHR_materials_unlit`).
    pub alpha: [f32; 4],
    /// Per texture slot, two rows of its `KHR_texture_transform` matrix: `(m00, m01, m02, set)`,
    /// `(m10, m11, m12, 0)` with `set` the UV set (0 or 1), so `uv' = M · (u, v, 1)`.
    pub uv: [[f32; 4]; 2 * TEXTURE_SLOTS],
    /// x: the material's index + 1, which the G-buffer writes beside the normal for the shading
    /// pass to find its [`ConstantColour`] coefficients (`material_spectra` in shading.wgsl); yzw
    /// unused.
    pub slot: [u32; 4],
    /// `KHR_materials_iridescence`: x factor (0: no film); y, z, w the film's index and
    /// thickness minimum and maximum in nm, for reference (the shading pass reads them per
    /// material from `MaterialSpectrum::film`; the G-buffer writes the weight and the thickness
    /// texture's G, whose default texture is white: without one the thickness is the maximum,
    /// as the extension says).
    pub film: [f32; 4],
    /// `KHR_materials_transmission`: x the factor (0: opaque; [`transmission`]), which the
    /// transmissive layer's G-buffer writes × the texture's R, beside the volume's thickness
    /// texture's G and the film's two values (`passes::gbuffer::Fourth::Layer`); yzw unused.
    pub transmission: [f32; 4],
    /// `KHR_materials_clearcoat` ([`coat`]): x the strength (0: no coat), y the roughness,
    /// z the coat's normal-map scale, w 1 with a coat normal map; the G-buffer's coat target
    /// holds them × the coat's textures.
    pub coat: [f32; 4],
    /// `KHR_materials_specular` ([`specular`]): x the weight, yzw F0(η) × the colour factor;
    /// the G-buffer's specular target holds min(yzw × the colour texture, 1) and x × the
    /// strength texture's A. (1, F0, F0, F0) without: the plain dielectric.
    pub specular: [f32; 4],
    /// `KHR_materials_sheen` ([`sheen`]): rgb the colour factor, w the roughness factor; the
    /// G-buffer's specular-and-sheen target holds them × the colour texture's RGB and the
    /// roughness texture's A. Zero without (no sheen).
    pub sheen: [f32; 4],
    /// `KHR_materials_anisotropy` ([`anisotropy`]): x the strength (0: none), y and z the
    /// rotation's cosine and sine, w 1 with a texture (read at the transmission's slot, which
    /// an anisotropic material never uses: [`texture_refs`]). Zero without.
    pub anisotropy: [f32; 4],
    /// `KHR_materials_diffuse_transmission` ([`diffuse_transmission`]): rgb the colour factor,
    /// w the factor (0: none), negative where the factor's texture is the colour's and read
    /// from its slot's A ([`diffuse_transmission_slots`]). Zero without.
    pub diffuse_transmission: [f32; 4],
}

pub const ALPHA_OPAQUE: f32 = 0.0;
pub const ALPHA_MASK: f32 = 1.0;
pub const ALPHA_BLEND: f32 = 2.0;

impl MaterialUniforms {
    /// The uniforms of material `m`, number `index` in its scene.
    pub fn new(m: &scene::Material, index: usize) -> Self {
        let (mode, cutoff) = match m.alpha_mode {
            AlphaMode::Opaque => (ALPHA_OPAQUE, 0.0),
            AlphaMode::Mask { cutoff } => (ALPHA_MASK, cutoff),
            AlphaMode::Blend => (ALPHA_BLEND, 0.0),
        };
        let mut uv = [[0f32; 4]; 2 * TEXTURE_SLOTS];
        for (slot, r) in texture_refs(m).iter().enumerate() {
            let matrix = r.and_then(|r| r.transform).map_or(Mat3::IDENTITY, |t| t.matrix());
            let set = r.map_or(0, |r| r.tex_coord) as f32;
            uv[2 * slot] = matrix.row(0).extend(set).to_array();
            uv[2 * slot + 1] = matrix.row(1).extend(0.0).to_array();
        }
        MaterialUniforms {
            base_color: m.base_color.to_array(),
            emissive: m.emissive.extend(m.normal_scale).to_array(),
            params: [
                m.metallic,
                m.roughness,
                m.normal_texture.is_some() as u8 as f32,
                if m.occlusion_texture.is_some() { m.occlusion_strength } else { 0.0 },
            ],
            alpha: [mode, cutoff, m.double_sided as u8 as f32, m.unlit as u8 as f32],
            uv,
            slot: [u32::try_from(index).map_or(u32::MAX, |i| i.saturating_add(1)), 0, 0, 0],
            film: match &m.iridescence {
                Some(f) if !m.unlit => [f.factor, f.ior, f.thickness_min, f.thickness_max],
                _ => [0.0; 4],
            },
            transmission: [transmission(m).map_or(0.0, |t| t.factor), 0.0, 0.0, 0.0],
            coat: coat(m).map_or([0.0; 4], |c| {
                [c.factor, c.roughness, c.normal_scale, c.normal_texture.is_some() as u8 as f32]
            }),
            specular: {
                let f0 = m.dielectric_f0();
                let (w, c) = specular(m).map_or((1.0, glam::Vec3::ONE), |s| (s.factor, s.color));
                [w, f0 * c.x, f0 * c.y, f0 * c.z]
            },
            sheen: sheen(m).map_or([0.0; 4], |sh| sh.color.extend(sh.roughness).to_array()),
            anisotropy: anisotropy(m).map_or([0.0; 4], |a| {
                let (sin, cos) = a.rotation.sin_cos();
                [a.strength, cos, sin, a.texture.is_some() as u8 as f32]
            }),
            diffuse_transmission: diffuse_transmission(m).map_or([0.0; 4], |d| {
                let shared = diffuse_transmission_slots(m).factor_in_color_slot;
                d.color.extend(if shared { -d.factor } else { d.factor }).to_array()
            }),
        }
    }
}

/// The material's transmission as the real-time renderer draws it: the transmissive layer
/// (`passes::gbuffer::Layer::Transmissive`) for a lit material with a factor above 0, its thin
/// film, if any, with its textures (the layer's G-buffer holds both).
pub fn transmission(m: &scene::Material) -> Option<&scene::transmission::Transmission> {
    m.transmission.as_ref().filter(|t| !m.unlit && t.factor > 0.0)
}

/// The material's clear coat as the real-time renderer draws it: on lit materials, opaque and
/// see-through (the transmissive layer's G-buffer then writes its coat target too).
pub fn coat(m: &scene::Material) -> Option<&scene::clearcoat::Clearcoat> {
    m.clearcoat.as_ref().filter(|c| !m.unlit && c.factor > 0.0)
}

/// The material's sheen as the real-time renderer draws it: on lit, opaque materials (the
/// transmissive layer's G-buffer has no room for it; such a material is drawn without, and the
/// upload says so).
pub fn sheen(m: &scene::Material) -> Option<&scene::sheen::Sheen> {
    m.sheen.as_ref().filter(|s| !m.unlit && transmission(m).is_none() && !s.is_off())
}

/// The material's anisotropy as the real-time renderer draws it: on lit, opaque materials at a
/// strength above 0 (the transmissive layer's G-buffer has no room for it; such a material is
/// drawn without, and the upload says so).
pub fn anisotropy(m: &scene::Material) -> Option<&scene::anisotropy::Anisotropy> {
    m.anisotropy.as_ref().filter(|a| !m.unlit && transmission(m).is_none() && !a.is_off())
}

/// The material's diffuse transmission as the real-time renderer draws it: on lit, opaque
/// materials at a factor above 0 (the transmissive layer's G-buffer has no room for it; such a
/// material is drawn without, and the upload says so).
pub fn diffuse_transmission(
    m: &scene::Material,
) -> Option<&scene::diffuse_transmission::DiffuseTransmission> {
    m.diffuse_transmission.as_ref().filter(|d| !m.unlit && transmission(m).is_none() && !d.is_off())
}

/// Where a diffuse transmission's two textures go among the slots: the colour's (sRGB; each
/// texture is decoded by its own format) at the volume thickness's slot, which an opaque
/// material never uses; the factor's (A) at the transmission's slot unless an anisotropy's
/// texture is there, or at the colour's when it is the same texture (the extension's packing:
/// colour in RGB, factor in A).
pub struct DiffuseTransmissionSlots {
    /// The texture at the transmission's slot (`TEX_DIFFUSE_TRANSMISSION`).
    pub factor: Option<TextureRef>,
    /// The texture at the volume thickness's slot (`TEX_DIFFUSE_TRANSMISSION_COLOR`).
    pub color: Option<TextureRef>,
    /// The factor's A is read from the colour's slot.
    pub factor_in_color_slot: bool,
    /// The factor's texture found no slot (an anisotropy's texture besides, and no colour
    /// texture that is the same): drawn with the factor alone, and the upload says so.
    pub factor_dropped: bool,
}

pub fn diffuse_transmission_slots(m: &scene::Material) -> DiffuseTransmissionSlots {
    let none = DiffuseTransmissionSlots {
        factor: None,
        color: None,
        factor_in_color_slot: false,
        factor_dropped: false,
    };
    let Some(d) = diffuse_transmission(m) else { return none };
    let Some(ft) = d.texture else { return DiffuseTransmissionSlots { color: d.color_texture, ..none } };
    let anisotropy_texture = anisotropy(m).is_some_and(|a| a.texture.is_some());
    match d.color_texture {
        Some(ct) if ct == ft => {
            DiffuseTransmissionSlots { color: Some(ct), factor_in_color_slot: true, ..none }
        }
        _ if anisotropy_texture => {
            DiffuseTransmissionSlots { color: d.color_texture, factor_dropped: true, ..none }
        }
        ct => DiffuseTransmissionSlots { factor: Some(ft), color: ct, ..none },
    }
}

/// The material's specular strength and colour as the real-time renderer draws them: the
/// loader keeps them only on lit, film-less, opaque materials (`scene::Material::specular`).
pub fn specular(m: &scene::Material) -> Option<&scene::specular::Specular> {
    m.specular.as_ref().filter(|_| !m.unlit && transmission(m).is_none())
}

/// A material's textures in slot order: base colour, metallic-roughness, normal, emissive,
/// occlusion, the film's weight (iridescence texture, R) and thickness (G), the transmission
/// (R) and the volume's thickness (G), the coat's strength (R), roughness (G) and normal map,
/// the specular strength (A) and colour (sRGB), the sheen's colour (sRGB) and roughness (A). The
/// anisotropy's texture (linear; RG the direction, B the strength) takes the transmission's
/// slot: a material has one or the other ([`anisotropy`] is on opaque materials only), and the
/// G-buffer's fragment stage has no 17th texture. A diffuse transmission's textures take the
/// transmission's and the volume thickness's slots ([`diffuse_transmission_slots`]).
pub fn texture_refs(m: &scene::Material) -> [Option<TextureRef>; TEXTURE_SLOTS] {
    let film = m.iridescence.as_ref();
    let t = transmission(m);
    let c = coat(m);
    let dt = diffuse_transmission_slots(m);
    [
        m.base_color_texture,
        m.metallic_roughness_texture,
        m.normal_texture,
        m.emissive_texture,
        m.occlusion_texture,
        film.and_then(|f| f.texture),
        film.and_then(|f| f.thickness_texture),
        t.and_then(|t| t.texture).or_else(|| anisotropy(m).and_then(|a| a.texture)).or(dt.factor),
        t.and_then(|t| t.volume.as_ref()).and_then(|v| v.thickness_texture).or(dt.color),
        c.and_then(|c| c.texture),
        c.and_then(|c| c.roughness_texture),
        c.and_then(|c| c.normal_texture),
        specular(m).and_then(|s| s.texture),
        specular(m).and_then(|s| s.color_texture),
        sheen(m).and_then(|s| s.color_texture),
        sheen(m).and_then(|s| s.roughness_texture),
    ]
}

/// The material bind group's layout (group 1 of the G-buffer and shadow passes): uniforms at
/// 0, the sixteen textures at 1..=16 and their samplers at 17..=32.
pub fn material_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let visibility = wgpu::ShaderStages::FRAGMENT;
    let mut entries = vec![crate::passes::uniform_entry(0, visibility)];
    for slot in 0..TEXTURE_SLOTS as u32 {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1 + slot,
            visibility,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        });
    }
    for slot in 0..TEXTURE_SLOTS as u32 {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 1 + TEXTURE_SLOTS as u32 + slot,
            visibility,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
    }
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("material"),
        entries: &entries,
    })
}

/// `GpuLight` in `wgsl/spectral.wgsl` (checked by `layout_tests`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLight {
    pub pos_kind: [f32; 4],
    pub dir_range: [f32; 4],
    pub cone: [f32; 4],
    pub rgb: [f32; 4],
    /// Spectral modes: XYZ of the light seen by a reflectance of one (the sum of its node
    /// weights), for the terms that do not depend on the surface's reflectance (specular).
    pub xyz: [f32; 4],
    /// Polygon lights (kind 3): the fourth vertex (xyz; a copy of the third for a triangle) and
    /// the vertex count (w).
    pub extra: [f32; 4],
}

impl GpuLight {
    /// Geometry of `light`; `rgb` is the RGB-mode emission (already × intensity).
    pub fn new(light: &scene::Light, rgb: [f64; 3]) -> Self {
        let rgb = [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, 0.0];
        match light.kind {
            LightKind::Directional { direction } => GpuLight {
                pos_kind: direction.normalize().extend(0.0).to_array(),
                // Diffuse sky light under water (scene::sky), drawn as a zenith light: the
                // underwater hooks scatter it isotropically instead of as a beam. y: the
                // angular radius of the disc it stands for (radians; the environment's sun sets
                // it, `Renderer::set_environment`), 0 for a glTF directional light.
                cone: [0.0, 0.0, if scene::sky::is_stand_in(light) { 1.0 } else { 0.0 }, 0.0],
                rgb,
                ..Default::default()
            },
            LightKind::Point { position, range } => GpuLight {
                pos_kind: position.extend(1.0).to_array(),
                dir_range: [0.0, 0.0, 0.0, range.unwrap_or(0.0)],
                rgb,
                ..Default::default()
            },
            LightKind::Spot { position, direction, inner_cone, outer_cone, range } => {
                let (ci, co) = (inner_cone.cos(), outer_cone.cos());
                GpuLight {
                    pos_kind: position.extend(2.0).to_array(),
                    dir_range: direction.normalize().extend(range.unwrap_or(0.0)).to_array(),
                    cone: [co, 1.0 / (ci - co).max(1e-4), 0.0, 0.0],
                    rgb,
                    ..Default::default()
                }
            }
        }
    }
}

impl GpuLight {
    /// An emissive polygon ([`scene::emitters::Emitter`]) as a light of kind 3: vertices in
    /// `pos_kind`, `dir_range`, `cone` and `extra` (xyz), `rgb` its radiance for the RGB mode.
    pub fn polygon(e: &scene::emitters::Emitter, rgb: [f64; 3]) -> Self {
        let v = |i: usize| e.vertices[i.min(e.vertices.len() - 1)];
        GpuLight {
            pos_kind: v(0).extend(3.0).to_array(),
            dir_range: v(1).extend(0.0).to_array(),
            cone: v(2).extend(e.area).to_array(),
            rgb: [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, 0.0],
            xyz: [0.0; 4],
            extra: v(3).extend(e.vertices.len() as f32).to_array(),
        }
    }
}

/// One indexed draw.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    /// The vertex/index buffer pair ([`GpuScene::chunks`]) it reads.
    pub chunk: usize,
    /// The scene mesh it draws (part of: a mesh larger than a buffer is several draws).
    pub mesh: usize,
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
    pub material: usize,
    /// The material's `doubleSided`: back faces are drawn (false: culled).
    pub double_sided: bool,
    /// The material's alpha mode is `Mask` or `Blend`: the fragment shader may discard.
    pub alpha_tested: bool,
    /// The material is see-through ([`transmission`]): drawn in the transmissive layer.
    pub transmissive: bool,
}

/// A vertex buffer and the index buffer whose indices refer to it.
pub struct Chunk {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
}

/// Packs meshes into vertex/index buffer pairs no larger than a byte limit (the device's
/// `max_buffer_size`, 256 MiB by default: 3.7 M vertices of 72 bytes). Whole meshes go in the
/// current pair while they fit; a mesh larger than a pair is cut into runs of triangles, each
/// run with its own copy of the vertices it uses. Each full pair is uploaded at once and its
/// CPU copy dropped, so the upload needs one pair of memory besides the scene.
struct Chunks<'a> {
    device: &'a wgpu::Device,
    max_vertices: usize,
    max_indices: usize,
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
    done: Vec<Chunk>,
}

impl<'a> Chunks<'a> {
    fn new(device: &'a wgpu::Device, max_bytes: u64) -> Self {
        let per = |size: usize| ((max_bytes / size as u64) as usize).max(3);
        Chunks {
            device,
            max_vertices: per(std::mem::size_of::<Vertex>()),
            // Indices are u32, and must stay addressable by `first_index: u32`.
            max_indices: per(4).min(u32::MAX as usize / 3 * 3),
            vertices: Vec::new(),
            indices: Vec::new(),
            done: Vec::new(),
        }
    }

    /// Ends the run of indices from `start` in the open chunk as one draw (none if empty).
    fn close_run(&self, draws: &mut Vec<Draw>, start: u32, template: Draw) {
        let count = self.indices.len() as u32 - start;
        if count > 0 {
            draws.push(Draw {
                chunk: self.done.len(),
                first_index: start,
                index_count: count,
                base_vertex: 0,
                ..template
            });
        }
    }

    fn flush(&mut self) {
        if self.indices.is_empty() {
            return;
        }
        let n = self.done.len();
        let vertices = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(&format!("vertices {n}")),
            contents: bytemuck::cast_slice(&self.vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let indices = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(&format!("indices {n}")),
            contents: bytemuck::cast_slice(&self.indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        self.done.push(Chunk { vertices, indices });
        self.vertices = Vec::new();
        self.indices = Vec::new();
    }

    /// Adds one mesh (`template` gives the material flags); returns its draws.
    fn add(&mut self, vertices: Vec<Vertex>, indices: &[u32], template: Draw) -> Vec<Draw> {
        // A mesh of no triangles (a scene built in code; the glTF loader skips them) draws
        // nothing, and would name a chunk that `finish` never makes.
        if indices.is_empty() {
            return Vec::new();
        }
        let fits = |c: &Self| {
            c.vertices.len() + vertices.len() <= c.max_vertices
                && c.indices.len() + indices.len() <= c.max_indices
        };
        if !fits(self) {
            self.flush();
        }
        if fits(self) {
            let d = Draw {
                chunk: self.done.len(),
                first_index: self.indices.len() as u32,
                index_count: indices.len() as u32,
                base_vertex: self.vertices.len() as i32,
                ..template
            };
            self.vertices.extend_from_slice(&vertices);
            self.indices.extend_from_slice(indices);
            return vec![d];
        }
        // Larger than a whole pair: triangle runs, vertices remapped per pair.
        const NONE: u32 = u32::MAX;
        let mut remap = vec![NONE; vertices.len()];
        let mut touched: Vec<u32> = Vec::new();
        let mut draws = Vec::new();
        let mut start = 0u32;
        for tri in indices.chunks_exact(3) {
            let new_vertices = tri.iter().filter(|&&v| remap[v as usize] == NONE).count();
            if self.vertices.len() + new_vertices > self.max_vertices
                || self.indices.len() + 3 > self.max_indices
            {
                self.close_run(&mut draws, start, template);
                self.flush();
                for v in touched.drain(..) {
                    remap[v as usize] = NONE;
                }
                start = 0;
            }
            for &v in tri {
                if remap[v as usize] == NONE {
                    remap[v as usize] = self.vertices.len() as u32;
                    self.vertices.push(vertices[v as usize]);
                    touched.push(v);
                }
                self.indices.push(remap[v as usize]);
            }
        }
        self.close_run(&mut draws, start, template);
        draws
    }

    fn finish(mut self) -> Vec<Chunk> {
        self.flush();
        self.done
    }
}

pub struct GpuScene {
    pub source: String,
    /// Vertex/index buffer pairs, each within the device's `max_buffer_size`.
    pub chunks: Vec<Chunk>,
    pub draws: Vec<Draw>,
    pub materials: Vec<wgpu::BindGroup>,
    pub lights: Vec<scene::Light>,
    /// Emissive surfaces lit with as area lights (after `lights` in the GPU light list): the
    /// emitting polygons, or clusters of them when they are more than fit in [`MAX_LIGHTS`]
    /// (`scene::emitters::area_lights`).
    pub emitters: Vec<scene::emitters::Emitter>,
    /// The emitting polygons they stand for, and the fraction of the emitted power left out
    /// (only with more emitting materials than lights fit).
    pub emitter_polygons: (usize, f64),
    pub camera: scene::Camera,
    /// World-space bounding box of all geometry.
    pub bounds: (Vec3, Vec3),
    /// Per scene mesh, its world-space bounding box (empty, min > max, for a mesh without
    /// positions).
    pub mesh_bounds: Vec<(Vec3, Vec3)>,
    /// What the upload had to change to fit the device (textures downscaled, …).
    pub warnings: Vec<String>,
    /// Whether any material emits or is unlit (its colour is drawn as emission): without one the
    /// shading pass is compiled without its emission terms.
    pub has_emission: bool,
    /// Per material, the G-buffer colours that do not vary over its surface.
    pub constant_colours: Vec<ConstantColour>,
    /// Per material that emits with a measured spectrum (`extras.emission`; not unlit), its
    /// name and spectrum: its surface glows with that spectrum at the luminance of its
    /// emissive colour in every mode (`MaterialSpectrum::emission`, `HAS_EMISSION_SPECTRA`), as
    /// the path tracer draws it.
    pub emission_spectra: Vec<Option<(String, color::Spectrum)>>,
    /// Whether some material's base colour (`.0`) or emission (`.1`) varies over its surface,
    /// so that the spectral shading pass needs its per-pixel fetch for it.
    pub varying_colours: (bool, bool),
    /// Whether some material has a thin film (`KHR_materials_iridescence` with a factor above
    /// 0): only then do the G-buffer and shading passes carry the film's code and target.
    pub has_film: bool,
    /// Whether some opaque material has a clear coat ([`coat`]): only then do the G-buffer and
    /// shading passes carry the coat's code and target.
    pub has_coat: bool,
    /// Whether some see-through material has one: the same for the transmissive layer.
    pub has_transmission_coat: bool,
    /// Whether some opaque material has a specular strength or colour ([`specular`]): only then
    /// do the G-buffer and shading passes carry its target and code.
    pub has_specular: bool,
    /// Whether some opaque material has a sheen ([`sheen`]): only then does the G-buffer write
    /// it and the shading pass compile it (`HAS_SHEEN`).
    pub has_sheen: bool,
    /// Whether some opaque material has an anisotropy ([`anisotropy`]): only then does the
    /// G-buffer write it (beside the film's values) and the shading pass compile it
    /// (`HAS_ANISOTROPY`).
    pub has_anisotropy: bool,
    /// Whether some opaque material has a diffuse transmission ([`diffuse_transmission`]): only
    /// then does the G-buffer write it (beside the specular's values, in the specular's target
    /// widened) and the shading pass compile it (`HAS_DIFFUSE_TRANSMISSION`).
    pub has_diffuse_transmission: bool,
    /// Whether some (lit) material's dielectric index is not glTF's 1.5 (`KHR_materials_ior`):
    /// only then does the shading pass read F0 per material.
    pub has_ior: bool,
    /// Per material, its film's index and thickness minimum and maximum in nm (`[1, 0, 0]`
    /// without a film) and its dielectric's F0 (`scene::dielectric_f0`), for
    /// `MaterialSpectrum::film`.
    pub material_films: Vec<[f32; 4]>,
    /// Whether some material is see-through ([`transmission`]): only then is the transmissive
    /// layer drawn and shaded.
    pub has_transmission: bool,
    /// Whether some see-through material has a thin film: only then does the transmissive
    /// layer's shading carry the film's code.
    pub has_transmission_film: bool,
    /// Whether some see-through material is thin-walled (no volume): only then does the
    /// transmissive layer's shading carry the light from behind (`thin_transmission`).
    pub has_thin_walls: bool,
    /// Whether some see-through material disperses (a volume with `KHR_materials_dispersion`):
    /// only then does the layer's shading carry the per-channel and per-node refraction.
    pub has_dispersion: bool,
    /// Per material, `MaterialSpectrum::refraction` and `::absorption` ([`refraction_record`]).
    pub material_refraction: Vec<[[f32; 4]; 2]>,
}

/// A material's base colour and emission where they do not vary over its surface (no texture,
/// no vertex colours on any mesh that uses it), as the G-buffer would hold them but in f32: the
/// G-buffer's f16 rounds them, and by the driver's rule (toward zero on lavapipe, to nearest
/// elsewhere), so the exact colours make the same coefficients on every device, the ones the
/// path tracer's colours give. The spectral shading pass takes these colours' coefficients from
/// the CPU (`crate::material_spectra`) instead of fetching them per pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ConstantColour {
    pub base: Option<[f32; 3]>,
    pub emission: Option<[f32; 3]>,
    /// `KHR_materials_specular`'s F0 colour min(F0(η)·colour, 1) where it has no colour
    /// texture (`scene::specular`; the G-buffer's specular target before its 16-bit rounding).
    pub specular: Option<[f32; 3]>,
    /// `KHR_materials_sheen`'s colour where it has no colour texture.
    pub sheen: Option<[f32; 3]>,
}

impl ConstantColour {
    /// Material `m`'s constant colours; `vertex_coloured`: some mesh with `COLOR_0` uses it.
    pub fn of(m: &scene::Material, vertex_coloured: bool) -> Self {
        let base =
            (m.base_color_texture.is_none() && !vertex_coloured).then(|| m.base_color.truncate().to_array());
        if m.unlit {
            // The G-buffer stores an unlit surface's colour as emission and black as its base.
            return ConstantColour {
                base: base.map(|_| [0.0; 3]),
                emission: base,
                specular: None,
                sheen: None,
            };
        }
        // A texture times a zero (or negative) factor emits nothing anywhere.
        let constant_emission = m.emissive_texture.is_none() || m.emissive.max_element() <= 0.0;
        // In f32 as `MaterialUniforms::specular` and the G-buffer make it.
        let f0 = m.dielectric_f0();
        let specular = specular(m)
            .filter(|s| s.color_texture.is_none())
            .map(|s| [s.color.x, s.color.y, s.color.z].map(|c| (f0 * c).min(1.0)));
        let sheen = sheen(m).filter(|s| s.color_texture.is_none()).map(|s| s.color.to_array());
        ConstantColour { base, emission: constant_emission.then(|| m.emissive.to_array()), specular, sheen }
    }
}

impl GpuScene {
    pub fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        s: &Scene,
    ) -> Result<Self> {
        Self::upload_with_buffer_limit(device, queue, layout, s, device.limits().max_buffer_size)
    }

    /// [`Self::upload`] with vertex/index buffers of at most `max_buffer_bytes` (tests lower
    /// it to exercise the splitting of large meshes on small scenes).
    pub fn upload_with_buffer_limit(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        s: &Scene,
        max_buffer_bytes: u64,
    ) -> Result<Self> {
        let max_buffer_bytes = max_buffer_bytes.min(device.limits().max_buffer_size);
        // Normals and tangents as the scene's convention has them (flat normals when a mesh
        // has none, MikkTSpace tangents for normal maps), the same the path tracer reads.
        let completed = s.completed();
        let s: &Scene = &completed;
        let bad = |problem: String| RenderError::Scene { source_name: s.source.clone(), problem };
        if s.lights.len() > MAX_LIGHTS {
            return Err(bad(format!(
                "{} lights; the real-time renderer handles at most {MAX_LIGHTS}",
                s.lights.len()
            )));
        }
        if s.materials.len() > MAX_MATERIALS {
            return Err(bad(format!(
                "{} materials; the real-time renderer handles at most {MAX_MATERIALS}",
                s.materials.len()
            )));
        }
        let mut chunks = Chunks::new(device, max_buffer_bytes);
        let mut draws = Vec::new();
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let mut mesh_bounds = Vec::with_capacity(s.meshes.len());
        for (mi, m) in s.meshes.iter().enumerate() {
            let n = m.positions.len();
            if m.material >= s.materials.len() {
                return Err(bad(format!(
                    "mesh {mi} uses material {} but there are {}",
                    m.material,
                    s.materials.len()
                )));
            }
            if m.indices.len() % 3 != 0 {
                return Err(bad(format!("mesh {mi} has {} indices, not a multiple of 3", m.indices.len())));
            }
            if let Some(&i) = m.indices.iter().find(|&&i| i as usize >= n) {
                return Err(bad(format!("mesh {mi} index {i} is out of range ({n} vertices)")));
            }
            for (what, len) in [
                ("normals", m.normals.len()),
                ("uvs", m.uvs.len()),
                ("tangents", m.tangents.len()),
                ("uvs1", m.uvs1.len()),
                ("colors", m.colors.len()),
            ] {
                if len != 0 && len != n {
                    return Err(bad(format!("mesh {mi} has {n} positions but {len} {what}")));
                }
            }
            let mat = &s.materials[m.material];
            let mut vertices = Vec::with_capacity(n);
            let (mut mesh_lo, mut mesh_hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for i in 0..n {
                let p = m.positions[i];
                mesh_lo = mesh_lo.min(p);
                mesh_hi = mesh_hi.max(p);
                vertices.push(Vertex {
                    position: p.to_array(),
                    normal: m.normals.get(i).copied().unwrap_or(Vec3::Z).to_array(),
                    uv: m.uvs.get(i).copied().unwrap_or(Vec2::ZERO).to_array(),
                    // Zero without a normal map (or one lacking the UV set to orient it): the
                    // shader leaves the normal unmapped.
                    tangent: m.tangents.get(i).copied().unwrap_or(Vec4::ZERO).to_array(),
                    color: m.colors.get(i).copied().unwrap_or(Vec4::ONE).to_array(),
                    uv1: m.uvs1.get(i).copied().unwrap_or(Vec2::ZERO).to_array(),
                });
            }
            lo = lo.min(mesh_lo);
            hi = hi.max(mesh_hi);
            mesh_bounds.push((mesh_lo, mesh_hi));
            let template = Draw {
                chunk: 0,
                mesh: mi,
                first_index: 0,
                index_count: 0,
                base_vertex: 0,
                material: m.material,
                double_sided: mat.double_sided,
                alpha_tested: mat.alpha_mode != AlphaMode::Opaque,
                transmissive: transmission(mat).is_some(),
            };
            draws.extend(chunks.add(vertices, &m.indices, template));
        }
        let chunks = chunks.finish();
        if chunks.is_empty() {
            // Nothing to rasterise: the frame is the sky (as the path tracer draws it), and the
            // bounds that size shadow maps and the occlusion radius are a point.
            (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
        }
        // One light kept for an environment's sun (`Renderer::set_environment`).
        let reserved = s.lights.len() + usize::from(s.environment.is_some());
        let area = scene::emitters::area_lights(s, MAX_LIGHTS.saturating_sub(reserved));
        let emitter_polygons = (area.polygons, area.dropped_power);
        let emitters = area.lights;
        let mut warnings = Vec::new();
        // A see-through material's sheen and anisotropy have no room in the transmissive layer's
        // G-buffer.
        type Has = fn(&scene::Material) -> bool;
        let layers: [(&str, &str, Has); 3] = [
            ("KHR_materials_sheen", "without its sheen", |m| m.sheen.as_ref().is_some_and(|sh| !sh.is_off())),
            ("KHR_materials_anisotropy", "with an isotropic specular lobe", |m| {
                m.anisotropy.as_ref().is_some_and(|a| !a.is_off())
            }),
            ("KHR_materials_diffuse_transmission", "without its diffuse transmission", |m| {
                m.diffuse_transmission.as_ref().is_some_and(|d| !d.is_off())
            }),
        ];
        for (ext, drawn, has) in layers {
            let names: Vec<String> = s
                .materials
                .iter()
                .filter(|m| has(m) && !m.unlit && transmission(m).is_some())
                .map(|m| format!("'{}'", m.name))
                .collect();
            if !names.is_empty() {
                warnings.push(format!(
                    "{ext} on a see-through material is not drawn by the real-time renderer (material{} {}): \
                     drawn {drawn}; the path tracer (`spectra truth`) draws it",
                    if names.len() > 1 { "s" } else { "" },
                    names.join(", ")
                ));
            }
        }
        // Nor has the G-buffer's fragment stage a 17th texture slot for a third texture beside
        // an anisotropy's (`diffuse_transmission_slots`).
        for m in s.materials.iter().filter(|m| diffuse_transmission_slots(m).factor_dropped) {
            warnings.push(format!(
                "KHR_materials_diffuse_transmission's diffuseTransmissionTexture on material '{}' is not \
                 drawn by the real-time renderer beside an anisotropy texture unless it is the \
                 diffuseTransmissionColorTexture too: drawn with its factor alone; the path tracer \
                 (`spectra truth`) draws it",
                m.name
            ));
        }
        let textures = upload_textures(device, queue, s, &mut warnings)?;
        let defaults = DefaultTextures::new(device, queue);
        let mut samplers = SamplerCache::default();
        let mut materials = Vec::new();
        for (index, m) in s.materials.iter().enumerate() {
            let refs = texture_refs(m);
            for r in refs.iter().flatten() {
                if r.index >= textures.len() {
                    return Err(bad(format!(
                        "material '{}' uses texture {} but there are {}",
                        m.name,
                        r.index,
                        textures.len()
                    )));
                }
                if r.tex_coord > 1 {
                    return Err(bad(format!(
                        "material '{}' reads texture {} from TEXCOORD_{}; only TEXCOORD_0 and TEXCOORD_1 \
                         are supported",
                        m.name, r.index, r.tex_coord
                    )));
                }
            }
            if let AlphaMode::Mask { cutoff } = m.alpha_mode
                && !cutoff.is_finite()
            {
                return Err(bad(format!("material '{}' has alpha cutoff {cutoff}", m.name)));
            }
            let u = MaterialUniforms::new(m, index);
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&m.name),
                contents: bytemuck::bytes_of(&u),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            // Per slot, what a material without the texture reads (typed: a slot added without
            // its fallback does not compile).
            let fallback: [&wgpu::TextureView; TEXTURE_SLOTS] = [
                &defaults.white_srgb,
                &defaults.white_linear,
                &defaults.flat_normal,
                &defaults.white_srgb,
                &defaults.white_linear,
                &defaults.white_linear,
                &defaults.white_linear,
                &defaults.white_linear,
                &defaults.white_linear,
                &defaults.white_linear,
                &defaults.white_linear,
                &defaults.flat_normal,
                &defaults.white_linear,
                &defaults.white_srgb,
                &defaults.white_srgb,
                &defaults.white_linear,
            ];
            let views: Vec<wgpu::TextureView> = refs
                .iter()
                .zip(fallback)
                .map(|(r, d)| r.map_or_else(|| d.clone(), |r| textures[r.index].clone()))
                .collect();
            let sampler_list: Vec<wgpu::Sampler> = refs
                .iter()
                .map(|r| {
                    samplers
                        .get(device, r.map_or_else(scene::Sampler::default, |r| s.textures[r.index].sampler))
                })
                .collect();
            let mut entries = vec![wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }];
            for (slot, v) in views.iter().enumerate() {
                entries.push(wgpu::BindGroupEntry {
                    binding: 1 + slot as u32,
                    resource: wgpu::BindingResource::TextureView(v),
                });
            }
            for (slot, smp) in sampler_list.iter().enumerate() {
                entries.push(wgpu::BindGroupEntry {
                    binding: 1 + (TEXTURE_SLOTS + slot) as u32,
                    resource: wgpu::BindingResource::Sampler(smp),
                });
            }
            materials.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&m.name),
                layout,
                entries: &entries,
            }));
        }
        let constant_colours: Vec<ConstantColour> = s
            .materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                ConstantColour::of(
                    m,
                    s.meshes.iter().any(|mesh| mesh.material == i && !mesh.colors.is_empty()),
                )
            })
            .collect();
        let emission_spectra: Vec<_> = s
            .materials
            .iter()
            .map(|m| {
                let glows = !m.unlit && m.emissive.max_element() > 0.0;
                m.emission_spectrum.clone().filter(|_| glows).map(|sp| (m.name.clone(), sp))
            })
            .collect();
        Ok(GpuScene {
            source: s.source.clone(),
            chunks,
            draws,
            materials,
            lights: s.lights.clone(),
            emitters,
            emitter_polygons,
            camera: s.camera,
            bounds: (lo, hi),
            mesh_bounds,
            warnings,
            has_emission: s.materials.iter().any(|m| m.unlit || m.emissive.max_element() > 0.0),
            varying_colours: (
                constant_colours.iter().any(|c| c.base.is_none()),
                // A measured spectrum is not upsampled: no fetch for it.
                constant_colours
                    .iter()
                    .zip(&emission_spectra)
                    .any(|(c, measured)| c.emission.is_none() && measured.is_none()),
            ),
            constant_colours,
            emission_spectra,
            has_film: s
                .materials
                .iter()
                .any(|m| !m.unlit && m.iridescence.as_ref().is_some_and(|f| f.factor > 0.0)),
            has_coat: s.materials.iter().any(|m| coat(m).is_some() && transmission(m).is_none()),
            has_transmission_coat: s.materials.iter().any(|m| coat(m).is_some() && transmission(m).is_some()),
            has_ior: s.materials.iter().any(|m| !m.unlit && m.ior != 1.5),
            has_specular: s.materials.iter().any(|m| specular(m).is_some()),
            has_sheen: s.materials.iter().any(|m| sheen(m).is_some()),
            has_anisotropy: s.materials.iter().any(|m| anisotropy(m).is_some()),
            has_diffuse_transmission: s.materials.iter().any(|m| diffuse_transmission(m).is_some()),
            has_transmission: s.materials.iter().any(|m| transmission(m).is_some()),
            has_transmission_film: s
                .materials
                .iter()
                .any(|m| transmission(m).is_some() && m.iridescence.as_ref().is_some_and(|f| f.factor > 0.0)),
            has_thin_walls: s.materials.iter().any(|m| transmission(m).is_some_and(|t| t.volume.is_none())),
            has_dispersion: s.materials.iter().any(|m| transmission(m).is_some_and(|t| t.disperses())),
            material_refraction: s.materials.iter().map(refraction_record).collect(),
            material_films: s
                .materials
                .iter()
                .map(|m| {
                    let [a, b, c] = m
                        .iridescence
                        .as_ref()
                        .map_or([1.0, 0.0, 0.0], |f| [f.ior, f.thickness_min, f.thickness_max]);
                    [a, b, c, m.dielectric_f0()]
                })
                .collect(),
        })
    }

    /// Records draw `d` with its material at group 1 and its buffers; the caller has set the
    /// pipeline. (Setting the buffers per draw costs little: a scene has few chunks and
    /// draws, and it keeps the passes unaware of the chunking.)
    /// Records draw `d`'s geometry only: its buffers, no material (for passes whose group 1 is
    /// their own, the transmissive layer's shading).
    pub fn draw_geometry(&self, pass: &mut wgpu::RenderPass<'_>, d: &Draw) {
        let c = &self.chunks[d.chunk];
        pass.set_vertex_buffer(0, c.vertices.slice(..));
        pass.set_index_buffer(c.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(d.first_index..d.first_index + d.index_count, d.base_vertex, 0..1);
    }

    pub fn draw_one(&self, pass: &mut wgpu::RenderPass<'_>, d: &Draw) {
        let c = &self.chunks[d.chunk];
        pass.set_vertex_buffer(0, c.vertices.slice(..));
        pass.set_index_buffer(c.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_bind_group(1, &self.materials[d.material], &[]);
        pass.draw_indexed(d.first_index..d.first_index + d.index_count, d.base_vertex, 0..1);
    }
}

/// One wgpu sampler per distinct [`scene::Sampler`].
#[derive(Default)]
struct SamplerCache {
    samplers: Vec<(scene::Sampler, wgpu::Sampler)>,
}

impl SamplerCache {
    fn get(&mut self, device: &wgpu::Device, s: scene::Sampler) -> wgpu::Sampler {
        if let Some((_, found)) = self.samplers.iter().find(|(k, _)| *k == s) {
            return found.clone();
        }
        let address = |w: scene::Wrap| match w {
            scene::Wrap::Repeat => wgpu::AddressMode::Repeat,
            scene::Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
            scene::Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
        };
        let filter = |f: scene::Filter| match f {
            scene::Filter::Nearest => wgpu::FilterMode::Nearest,
            scene::Filter::Linear => wgpu::FilterMode::Linear,
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material"),
            address_mode_u: address(s.wrap_s),
            address_mode_v: address(s.wrap_t),
            mag_filter: filter(s.mag),
            min_filter: filter(s.min),
            // glTF's mipmapped minification filters differ in how levels are blended as well;
            // the scene keeps only whether mipmaps are used, so levels are always blended
            // (trilinear). Without mipmaps only level 0 is read.
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            lod_max_clamp: if s.mipmaps { 32.0 } else { 0.0 },
            ..Default::default()
        });
        self.samplers.push((s, sampler.clone()));
        sampler
    }
}

fn upload_textures(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    s: &Scene,
    warnings: &mut Vec<String>,
) -> Result<Vec<wgpu::TextureView>> {
    let max = device.limits().max_texture_dimension_2d;
    s.textures
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let expected = t.width as usize * t.height as usize * 4;
            if t.width == 0 || t.height == 0 || t.rgba8.len() != expected {
                return Err(RenderError::Scene {
                    source_name: s.source.clone(),
                    problem: format!(
                        "texture {i} '{}' is {}×{} but has {} bytes (expected {expected})",
                        t.name,
                        t.width,
                        t.height,
                        t.rgba8.len()
                    ),
                });
            }
            let shrunk = fit_texture(t.width, t.height, &t.rgba8, t.srgb, max);
            let (width, height, rgba8) = match &shrunk {
                Some((w, h, data)) => {
                    warnings.push(format!(
                        "texture {i} '{}' is {}×{}, larger than this GPU's limit of {max} a side: \
                         downscaled to {w}×{h}",
                        t.name, t.width, t.height
                    ));
                    (*w, *h, data.as_slice())
                }
                None => (t.width, t.height, t.rgba8.as_slice()),
            };
            let texture = if t.srgb {
                srgb8_as_linear_f16(device, queue, &t.name, width, height, rgba8, UPLOAD_SLICE_BYTES)
            } else {
                linear8_mipmapped(device, queue, &t.name, width, height, rgba8, UPLOAD_SLICE_BYTES)
            };
            Ok(texture.create_view(&Default::default()))
        })
        .collect()
}

/// An RGBA8 image halved (box filter, in linear light for sRGB data) until both sides are at
/// most `max`; `None` when it fits already. Halving keeps the aspect ratio (to the rounding of
/// odd sides) and filters every source texel.
pub fn fit_texture(
    width: u32,
    height: u32,
    rgba8: &[u8],
    srgb: bool,
    max: u32,
) -> Option<(u32, u32, Vec<u8>)> {
    if width <= max && height <= max {
        return None;
    }
    let decode: Vec<f32> = (0..=255u8)
        .map(
            |v| if srgb { color::colorspace::srgb_decode(v as f64 / 255.0) as f32 } else { v as f32 / 255.0 },
        )
        .collect();
    let encode = |v: f32, c: usize| {
        let v = v.clamp(0.0, 1.0) as f64;
        let e = if srgb && c < 3 { color::colorspace::srgb_encode(v) } else { v };
        (e * 255.0).round() as u8
    };
    let (mut w, mut h, mut data) = (width, height, rgba8.to_vec());
    while w > max || h > max {
        let level = downsample(w, h, |x, y| {
            let i = 4 * (y as usize * w as usize + x as usize);
            std::array::from_fn(
                |c| if c < 3 { decode[data[i + c] as usize] } else { data[i + 3] as f32 / 255.0 },
            )
        });
        data = level.iter().flat_map(|t| std::array::from_fn::<u8, 4, _>(|c| encode(t[c], c))).collect();
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
    Some((w, h, data))
}

pub(crate) fn rgba8_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    data: &[u8],
) -> wgpu::TextureView {
    texture_with_mips(device, queue, label, width, height, 1, format, data)
}

/// A sampled texture from `data`: `mips` levels of layer 0, level by level (wgpu's
/// `LayerMajor` order), tightly packed.
#[allow(clippy::too_many_arguments)]
fn texture_with_mips(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    width: u32,
    height: u32,
    mips: u32,
    format: wgpu::TextureFormat,
    data: &[u8],
) -> wgpu::TextureView {
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        data,
    );
    texture.create_view(&Default::default())
}

/// Number of levels of a full mip chain down to 1×1.
pub fn mip_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// The next mip level of a `width × height` image whose texel (x, y) is `texel(x, y)`: each
/// texel of the half-size level (rounded down, at least 1) is the mean of the source texels its
/// footprint touches (2×2 for even sizes; odd sizes widen the footprint to 3, overlapping).
pub fn downsample(width: u32, height: u32, texel: impl Fn(u32, u32) -> [f32; 4] + Sync) -> Vec<[f32; 4]> {
    use rayon::prelude::*;
    let (dw, dh) = ((width / 2).max(1), (height / 2).max(1));
    let span = |i: u32, src: u32, dst: u32| {
        let a = (i as u64 * src as u64 / dst as u64) as u32;
        let b = ((i as u64 + 1) * src as u64).div_ceil(dst as u64) as u32;
        a..b.max(a + 1).min(src)
    };
    (0..dh)
        .into_par_iter()
        .flat_map_iter(|y| {
            let texel = &texel;
            (0..dw).map(move |x| {
                let mut sum = [0f32; 4];
                let mut n = 0u32;
                for sy in span(y, height, dh) {
                    for sx in span(x, width, dw) {
                        let t = texel(sx, sy);
                        (0..4).for_each(|c| sum[c] += t[c]);
                        n += 1;
                    }
                }
                sum.map(|v| v / n as f32)
            })
        })
        .collect()
}

/// Every level after the first of a full mip chain, from level 0's `texel(x, y)`.
pub fn mip_chain(width: u32, height: u32, texel: impl Fn(u32, u32) -> [f32; 4] + Sync) -> Vec<Vec<[f32; 4]>> {
    let mut levels = Vec::new();
    for_each_mip(width, height, texel, |_, _, _, level| levels.push(level.to_vec()));
    levels
}

/// [`mip_chain`]'s levels handed to `f` one at a time (`f(mip, width, height, texels)`), each
/// made from the one before and dropped after the next: at most two levels are held, not all.
pub fn for_each_mip(
    width: u32,
    height: u32,
    texel: impl Fn(u32, u32) -> [f32; 4] + Sync,
    mut f: impl FnMut(u32, u32, u32, &[[f32; 4]]),
) {
    let mut prev: Option<Vec<[f32; 4]>> = None;
    let (mut w, mut h) = (width, height);
    for mip in 1..mip_count(width, height) {
        let next = match &prev {
            None => downsample(w, h, &texel),
            Some(prev) => downsample(w, h, |x, y| prev[(y * w + x) as usize]),
        };
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
        f(mip, w, h, &next);
        prev = Some(next);
    }
}

/// Bytes written to a texture between waits for the GPU. `write_texture` keeps a staging copy
/// of what it is given until a submission carrying it completes, so a whole mip chain written at
/// once was held three times (the CPU's copy, the staging one, the texture): an 8192² colour
/// texture took 1.7 GB of memory while it loaded.
const UPLOAD_SLICE_BYTES: usize = 64 << 20;

/// A texture with a full mip chain, written band of rows by band of rows.
struct MipUpload<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    texture: wgpu::Texture,
    texel_bytes: u32,
    /// [`UPLOAD_SLICE_BYTES`]; tests make it small to cut every level into many bands.
    slice: usize,
    pending: usize,
}

impl<'a> MipUpload<'a> {
    fn new(
        device: &'a wgpu::Device,
        queue: &'a wgpu::Queue,
        label: &str,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
        slice: usize,
    ) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: mip_count(width, height),
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            // COPY_SRC for the test that reads every level back.
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let texel_bytes = format.block_copy_size(None).expect("an uncompressed colour format");
        MipUpload { device, queue, texture, texel_bytes, slice, pending: 0 }
    }

    /// Writes level `mip` (`width` × `height`) in bands of rows, `band(rows)` giving each
    /// band's tightly packed bytes.
    fn level(&mut self, mip: u32, width: u32, height: u32, band: impl Fn(std::ops::Range<u32>) -> Vec<u8>) {
        let row_bytes = (width * self.texel_bytes) as usize;
        let rows = (self.slice / row_bytes).clamp(1, height as usize) as u32;
        for y0 in (0..height).step_by(rows as usize) {
            let y1 = (y0 + rows).min(height);
            let data = band(y0..y1);
            debug_assert_eq!(data.len(), row_bytes * (y1 - y0) as usize);
            self.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: mip,
                    origin: wgpu::Origin3d { x: 0, y: y0, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                &data,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row_bytes as u32),
                    rows_per_image: Some(y1 - y0),
                },
                wgpu::Extent3d { width, height: y1 - y0, depth_or_array_layers: 1 },
            );
            self.pending += data.len();
            if self.pending >= self.slice {
                self.flush();
            }
        }
    }

    /// Submits the writes so far and waits for them, which frees their staging copies.
    fn flush(&mut self) {
        self.queue.submit(std::iter::empty());
        // A failed wait (a lost device) shows in the frame that follows, with its own error.
        let _ = self.device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None });
        self.pending = 0;
    }

    fn finish(mut self) -> wgpu::Texture {
        if self.pending > 0 {
            self.flush();
        }
        self.texture
    }
}

/// A linear (non-colour) RGBA8 image as `Rgba8Unorm` with a box-filtered mip chain.
fn linear8_mipmapped(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    width: u32,
    height: u32,
    rgba8: &[u8],
    slice: usize,
) -> wgpu::Texture {
    let texel = |x: u32, y: u32| {
        let i = 4 * (y * width + x) as usize;
        std::array::from_fn(|c| rgba8[i + c] as f32 / 255.0)
    };
    let mut up = MipUpload::new(device, queue, label, width, height, wgpu::TextureFormat::Rgba8Unorm, slice);
    let row = 4 * width as usize;
    up.level(0, width, height, |r| rgba8[r.start as usize * row..r.end as usize * row].to_vec());
    for_each_mip(width, height, texel, |mip, w, h, level| {
        up.level(mip, w, h, |r| {
            level[(r.start * w) as usize..(r.end * w) as usize]
                .iter()
                .flat_map(|t| t.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8))
                .collect()
        });
    });
    up.finish()
}

/// An sRGB-encoded RGBA8 image decoded exactly on the CPU into linear `Rgba16Float`, with a mip
/// chain box-filtered in linear space (alpha filtered as is, not premultiplied).
///
/// Why not `Rgba8UnormSrgb`: drivers may decode sRGB approximately (llvmpipe's decode is off
/// by up to ~0.4 % here, a uniform ΔE2000 ≈ 0.2 on every textured surface), and the spectral
/// upsampling should see the asset's true colours. Filtering still happens in linear space.
fn srgb8_as_linear_f16(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    width: u32,
    height: u32,
    rgba8: &[u8],
    slice: usize,
) -> wgpu::Texture {
    let lut: Vec<f32> =
        (0..=255u8).map(|v| color::colorspace::srgb_decode(v as f64 / 255.0) as f32).collect();
    let texel = |x: u32, y: u32| {
        let i = 4 * (y * width + x) as usize;
        let p = &rgba8[i..i + 4];
        [lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize], p[3] as f32 / 255.0]
    };
    let lut16: Vec<half::f16> =
        (0..=255u8).map(|v| half::f16::from_f64(color::colorspace::srgb_decode(v as f64 / 255.0))).collect();
    let mut up = MipUpload::new(device, queue, label, width, height, wgpu::TextureFormat::Rgba16Float, slice);
    let row = 4 * width as usize;
    up.level(0, width, height, |r| {
        let texels: Vec<half::f16> = rgba8[r.start as usize * row..r.end as usize * row]
            .chunks_exact(4)
            .flat_map(|p| {
                [
                    lut16[p[0] as usize],
                    lut16[p[1] as usize],
                    lut16[p[2] as usize],
                    half::f16::from_f32(p[3] as f32 / 255.0),
                ]
            })
            .collect();
        bytemuck::cast_slice(&texels).to_vec()
    });
    for_each_mip(width, height, texel, |mip, w, h, level| {
        up.level(mip, w, h, |r| {
            let texels: Vec<half::f16> = level[(r.start * w) as usize..(r.end * w) as usize]
                .iter()
                .flat_map(|t| t.map(half::f16::from_f32))
                .collect();
            bytemuck::cast_slice(&texels).to_vec()
        });
    });
    up.finish()
}

/// 1×1 textures standing in for absent material textures (the factors then apply alone).
struct DefaultTextures {
    white_srgb: wgpu::TextureView,
    white_linear: wgpu::TextureView,
    flat_normal: wgpu::TextureView,
}

impl DefaultTextures {
    fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let white = [255u8; 4];
        DefaultTextures {
            white_srgb: rgba8_texture(
                device,
                queue,
                "white",
                1,
                1,
                wgpu::TextureFormat::Rgba8UnormSrgb,
                &white,
            ),
            white_linear: rgba8_texture(
                device,
                queue,
                "white",
                1,
                1,
                wgpu::TextureFormat::Rgba8Unorm,
                &white,
            ),
            flat_normal: rgba8_texture(
                device,
                queue,
                "flat normal",
                1,
                1,
                wgpu::TextureFormat::Rgba8Unorm,
                &[128, 128, 255, 255],
            ),
        }
    }
}

/// A material's refraction for the shading pass: (index at the d line, dispersion (20 / Abbe
/// number), thickness in scene units (0: thin-walled), 0) and the interior's absorption
/// coefficient per scene unit in linear RGB (0 when clear; w unused), which the spectral modes upsample
/// as a box spectrum per channel: `color::upsample::medium::Attenuation::DEFAULT`, the path
/// tracer's upsampling of the same `scene::transmission::Volume::medium`.
pub fn refraction_record(m: &scene::Material) -> [[f32; 4]; 2] {
    let Some(t) = transmission(m) else { return [[m.ior, 0.0, 0.0, 0.0], [0.0; 4]] };
    let (thickness, sigma) = match &t.volume {
        Some(v) => (v.thickness, v.medium().map_or([0.0; 3], |md| md.absorption.map(|a| a as f32))),
        None => (0.0, [0.0; 3]),
    };
    let dispersion = if t.disperses() { t.dispersion } else { 0.0 };
    [[m.ior, dispersion, thickness, 0.0], [sigma[0], sigma[1], sigma[2], 0.0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every level of a texture, tightly packed, level after level.
    fn read_levels(gpu: &crate::Gpu, texture: &wgpu::Texture, texel_bytes: u32) -> Vec<Vec<u8>> {
        (0..texture.mip_level_count())
            .map(|mip| {
                let (w, h) = ((texture.width() >> mip).max(1), (texture.height() >> mip).max(1));
                let row = w * texel_bytes;
                let padded =
                    row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
                let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: None,
                    size: (padded * h) as u64,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                encoder.copy_texture_to_buffer(
                    wgpu::TexelCopyTextureInfo { mip_level: mip, ..texture.as_image_copy() },
                    wgpu::TexelCopyBufferInfo {
                        buffer: &buffer,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(padded),
                            rows_per_image: Some(h),
                        },
                    },
                    wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                );
                gpu.queue.submit([encoder.finish()]);
                crate::readback::map_buffer(&gpu.device, &buffer, |b| {
                    b.chunks(padded as usize).flat_map(|r| r[..row as usize].to_vec()).collect()
                })
                .unwrap()
            })
            .collect()
    }

    /// Textures are written in bands of rows, level by level, to bound the memory a large one
    /// takes while it loads: cut into bands of one row, or of a few, every level holds exactly
    /// what the whole chain built in memory and written at once holds (what the upload did
    /// before), for both formats and odd sizes.
    #[test]
    fn banded_texture_upload_is_the_whole_chain() {
        let gpu = crate::Gpu::headless().unwrap_or_else(|e| panic!("{e}\n{}", crate::Gpu::install_help()));
        let (w, h) = (67u32, 13u32);
        let rgba8: Vec<u8> = (0..w * h * 4).map(|i| (i * 97 % 251) as u8).collect();
        let texel = |x: u32, y: u32| -> [f32; 4] {
            let i = 4 * (y * w + x) as usize;
            std::array::from_fn(|c| rgba8[i + c] as f32 / 255.0)
        };
        // The whole chain, as the upload built it before.
        let mut linear = vec![rgba8.clone()];
        linear.extend(mip_chain(w, h, texel).iter().map(|l| {
            l.iter().flat_map(|t| t.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)).collect::<Vec<u8>>()
        }));
        let decode = |v: u8| color::colorspace::srgb_decode(v as f64 / 255.0);
        let srgb_texel = |x: u32, y: u32| -> [f32; 4] {
            let i = 4 * (y * w + x) as usize;
            std::array::from_fn(
                |c| if c < 3 { decode(rgba8[i + c]) as f32 } else { rgba8[i + 3] as f32 / 255.0 },
            )
        };
        let level0: Vec<half::f16> = rgba8
            .chunks_exact(4)
            .flat_map(|p| {
                [0, 1, 2, 3].map(|c| {
                    if c < 3 {
                        half::f16::from_f64(decode(p[c]))
                    } else {
                        half::f16::from_f32(p[3] as f32 / 255.0)
                    }
                })
            })
            .collect();
        let mut srgb = vec![bytemuck::cast_slice::<half::f16, u8>(&level0).to_vec()];
        srgb.extend(mip_chain(w, h, srgb_texel).iter().map(|l| {
            let t: Vec<half::f16> = l.iter().flat_map(|t| t.map(half::f16::from_f32)).collect();
            bytemuck::cast_slice::<half::f16, u8>(&t).to_vec()
        }));
        assert_eq!(linear.len(), 7);
        for slice in [1, 3 * 67 * 8, UPLOAD_SLICE_BYTES] {
            let t = linear8_mipmapped(&gpu.device, &gpu.queue, "test", w, h, &rgba8, slice);
            assert_eq!(read_levels(&gpu, &t, 4), linear, "linear, slices of {slice} bytes");
            let t = srgb8_as_linear_f16(&gpu.device, &gpu.queue, "test", w, h, &rgba8, slice);
            assert_eq!(read_levels(&gpu, &t, 8), srgb, "sRGB, slices of {slice} bytes");
        }
    }

    #[test]
    fn vertex_is_72_bytes() {
        // (`MaterialUniforms` is checked against the WGSL by `layout_tests`.)
        assert_eq!(std::mem::size_of::<Vertex>(), 72);
    }

    #[test]
    fn uv_rows_hold_the_transform_and_the_uv_set() {
        let t = scene::TextureTransform {
            offset: Vec2::new(0.25, 0.5),
            rotation: 0.3,
            scale: Vec2::new(2.0, 3.0),
        };
        let m = scene::Material {
            emissive_texture: Some(TextureRef { index: 0, tex_coord: 1, transform: Some(t) }),
            alpha_mode: AlphaMode::Mask { cutoff: 0.25 },
            ..Default::default()
        };
        let u = MaterialUniforms::new(&m, 0);
        assert_eq!(u.alpha, [ALPHA_MASK, 0.25, 1.0, 0.0]);
        let uv = Vec2::new(0.7, -0.2);
        let (r0, r1) = (Vec4::from(u.uv[6]), Vec4::from(u.uv[7]));
        let got = Vec2::new(r0.truncate().dot(uv.extend(1.0)), r1.truncate().dot(uv.extend(1.0)));
        assert!((got - t.apply(uv)).length() < 1e-6, "{got} vs {}", t.apply(uv));
        assert_eq!(r0.w, 1.0, "TEXCOORD_1");
        // Slots without a texture: identity on TEXCOORD_0.
        assert_eq!(u.uv[0], [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(u.uv[1], [0.0, 1.0, 0.0, 0.0]);
    }

    /// A texture wider than the device limit (16385×2 used to panic in wgpu) is halved until it
    /// fits, averaging in linear light.
    #[test]
    fn oversized_textures_are_halved_to_the_limit() {
        assert!(fit_texture(4, 4, &[0; 64], true, 4).is_none());
        let (w, h) = (16385u32, 2u32);
        // Alternating black and white columns: linear mean 0.5, sRGB-encoded 188.
        let data: Vec<u8> =
            (0..w * h).flat_map(|i| if i % 2 == 0 { [0, 0, 0, 255] } else { [255, 255, 255, 255] }).collect();
        let (fw, fh, out) = fit_texture(w, h, &data, true, 16384).unwrap();
        assert_eq!((fw, fh, out.len()), (8192, 1, 8192 * 4));
        assert!(out.chunks_exact(4).all(|p| (187..=189).contains(&p[0]) && p[3] == 255), "{:?}", &out[..8]);
        let (_, _, lin) = fit_texture(w, h, &data, false, 16384).unwrap();
        assert!(lin.chunks_exact(4).all(|p| (127..=128).contains(&p[0])), "{:?}", &lin[..8]);
        let (fw, fh, _) = fit_texture(40_000, 1, &vec![7; 160_000], false, 8192).unwrap();
        assert_eq!((fw, fh), (5000, 1));
    }

    #[test]
    fn mip_chains_box_filter_down_to_one_texel() {
        assert_eq!(mip_count(1, 1), 1);
        assert_eq!(mip_count(64, 32), 7);
        assert_eq!(mip_count(5, 3), 3);
        // A 4×2 image: level 1 is 2×1 of 2×2 means, level 2 the mean of all.
        let img = [[0.0f32, 1.0, 2.0, 3.0], [4.0, 5.0, 6.0, 7.0]];
        let levels = mip_chain(4, 2, |x, y| [img[y as usize][x as usize]; 4]);
        assert_eq!(levels.len(), 2);
        assert_eq!(levels[0], vec![[2.5; 4], [4.5; 4]]);
        assert_eq!(levels[1], vec![[3.5; 4]]);
        // Odd sizes: every source texel contributes (3 → 1 averages all three).
        let levels = mip_chain(3, 1, |x, _| [x as f32; 4]);
        assert_eq!(levels, vec![vec![[1.0; 4]]]);
    }
}
