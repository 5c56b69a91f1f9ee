//! A scene uploaded to the GPU: one vertex and one index buffer for all meshes, a bind group
//! per material, and the lights (their per-wavelength spectra are built by the renderer
//! because they depend on the settings).

use crate::error::{RenderError, Result};
use glam::{Vec2, Vec3, Vec4};
use scene::{LightKind, Scene};
use wgpu::util::DeviceExt;

/// Most lights a scene may have (the shader keeps two floats per light per pixel).
/// Must match `MAX_LIGHTS` in `passes/shading.wgsl`.
pub const MAX_LIGHTS: usize = 32;

/// Interleaved vertex, 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    /// xyz tangent, w handedness; zero when the mesh has none (no normal mapping then).
    pub tangent: [f32; 4],
}

impl Vertex {
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 4] =
        wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x4];

    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &Self::ATTRIBUTES,
        }
    }
}

/// Matches `MaterialUniforms` in `passes/gbuffer.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialUniforms {
    pub base_color: [f32; 4],
    pub emissive: [f32; 4],
    pub params: [f32; 4],
}

/// Matches `GpuLight` in `wgsl/spectral.wgsl`.
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
                // underwater hooks scatter it isotropically instead of as a beam.
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
    pub first_index: u32,
    pub index_count: u32,
    pub base_vertex: i32,
    pub material: usize,
}

pub struct GpuScene {
    pub source: String,
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub draws: Vec<Draw>,
    pub materials: Vec<wgpu::BindGroup>,
    pub lights: Vec<scene::Light>,
    /// Emissive polygons lit with as area lights (after `lights` in the GPU light list), the
    /// brightest that fit in [`MAX_LIGHTS`].
    pub emitters: Vec<scene::emitters::Emitter>,
    /// Emissive polygons left out by the cap, and the fraction of the emitted power they carry.
    pub dropped_emitters: (usize, f64),
    pub camera: scene::Camera,
    /// World-space bounding box of all geometry.
    pub bounds: (Vec3, Vec3),
}

impl GpuScene {
    pub fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        s: &Scene,
    ) -> Result<Self> {
        let bad = |problem: String| RenderError::Scene { source_name: s.source.clone(), problem };
        if s.lights.len() > MAX_LIGHTS {
            return Err(bad(format!(
                "{} lights; the real-time renderer handles at most {MAX_LIGHTS}",
                s.lights.len()
            )));
        }
        let mut vertices: Vec<Vertex> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut draws = Vec::new();
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
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
            for (what, len) in
                [("normals", m.normals.len()), ("uvs", m.uvs.len()), ("tangents", m.tangents.len())]
            {
                if len != 0 && len != n {
                    return Err(bad(format!("mesh {mi} has {n} positions but {len} {what}")));
                }
            }
            let mat = &s.materials[m.material];
            let normals = if m.normals.is_empty() { flat_normals(m) } else { m.normals.clone() };
            let tangents = if !m.tangents.is_empty() {
                m.tangents.clone()
            } else if mat.normal_texture.is_some() && !m.uvs.is_empty() {
                generate_tangents(&m.positions, &normals, &m.uvs, &m.indices)
            } else {
                vec![Vec4::ZERO; n]
            };
            let base = vertices.len();
            for i in 0..n {
                let p = m.positions[i];
                lo = lo.min(p);
                hi = hi.max(p);
                vertices.push(Vertex {
                    position: p.to_array(),
                    normal: normals[i].to_array(),
                    uv: m.uvs.get(i).copied().unwrap_or(Vec2::ZERO).to_array(),
                    tangent: tangents[i].to_array(),
                });
            }
            draws.push(Draw {
                first_index: indices.len() as u32,
                index_count: m.indices.len() as u32,
                base_vertex: base as i32,
                material: m.material,
            });
            indices.extend_from_slice(&m.indices);
        }
        if vertices.is_empty() {
            return Err(bad("the scene has no geometry".into()));
        }
        let mut emitters = scene::emitters::emitters(s);
        let room = MAX_LIGHTS - s.lights.len();
        let dropped_emitters = if emitters.len() > room {
            let total: f64 = emitters.iter().map(|e| e.power()).sum();
            let kept: f64 = emitters[..room].iter().map(|e| e.power()).sum();
            let n = emitters.len() - room;
            emitters.truncate(room);
            (n, if total > 0.0 { 1.0 - kept / total } else { 0.0 })
        } else {
            (0, 0.0)
        };
        let textures = upload_textures(device, queue, s)?;
        let defaults = DefaultTextures::new(device, queue);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let mut materials = Vec::new();
        for m in &s.materials {
            let tex = |r: &Option<scene::TextureRef>, default: &wgpu::TextureView| -> wgpu::TextureView {
                r.map(|r| textures[r.index].clone()).unwrap_or_else(|| default.clone())
            };
            for r in [
                &m.base_color_texture,
                &m.metallic_roughness_texture,
                &m.normal_texture,
                &m.emissive_texture,
                &m.occlusion_texture,
            ]
            .into_iter()
            .flatten()
            {
                if r.index >= textures.len() {
                    return Err(bad(format!(
                        "material '{}' uses texture {} but there are {}",
                        m.name,
                        r.index,
                        textures.len()
                    )));
                }
            }
            let u = MaterialUniforms {
                base_color: m.base_color.to_array(),
                emissive: m.emissive.extend(m.normal_scale).to_array(),
                params: [
                    m.metallic,
                    m.roughness,
                    m.normal_texture.is_some() as u8 as f32,
                    if m.occlusion_texture.is_some() { m.occlusion_strength } else { 0.0 },
                ],
            };
            let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&m.name),
                contents: bytemuck::bytes_of(&u),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let views = [
                tex(&m.base_color_texture, &defaults.white_srgb),
                tex(&m.metallic_roughness_texture, &defaults.white_linear),
                tex(&m.normal_texture, &defaults.flat_normal),
                tex(&m.emissive_texture, &defaults.white_srgb),
                tex(&m.occlusion_texture, &defaults.white_linear),
            ];
            materials.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&m.name),
                layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&views[0]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&views[1]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(&views[2]),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(&views[3]),
                    },
                    wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::Sampler(&sampler) },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(&views[4]),
                    },
                ],
            }));
        }
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        Ok(GpuScene {
            source: s.source.clone(),
            vertices,
            indices,
            draws,
            materials,
            lights: s.lights.clone(),
            emitters,
            dropped_emitters,
            camera: s.camera,
            bounds: (lo, hi),
        })
    }

    /// Records all draws; the caller has set the pipeline and group 0.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, with_materials: bool) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for d in &self.draws {
            if with_materials {
                pass.set_bind_group(1, &self.materials[d.material], &[]);
            }
            pass.draw_indexed(d.first_index..d.first_index + d.index_count, d.base_vertex, 0..1);
        }
    }
}

fn upload_textures(device: &wgpu::Device, queue: &wgpu::Queue, s: &Scene) -> Result<Vec<wgpu::TextureView>> {
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
            if t.srgb {
                Ok(srgb8_as_linear_f16(device, queue, &t.name, t.width, t.height, &t.rgba8))
            } else {
                Ok(rgba8_texture(
                    device,
                    queue,
                    &t.name,
                    t.width,
                    t.height,
                    wgpu::TextureFormat::Rgba8Unorm,
                    &t.rgba8,
                ))
            }
        })
        .collect()
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
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
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

/// An sRGB-encoded RGBA8 image decoded exactly on the CPU into linear `Rgba16Float`.
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
) -> wgpu::TextureView {
    let lut: Vec<half::f16> =
        (0..=255u8).map(|v| half::f16::from_f64(color::colorspace::srgb_decode(v as f64 / 255.0))).collect();
    let texels: Vec<half::f16> = rgba8
        .chunks_exact(4)
        .flat_map(|p| {
            [
                lut[p[0] as usize],
                lut[p[1] as usize],
                lut[p[2] as usize],
                half::f16::from_f32(p[3] as f32 / 255.0),
            ]
        })
        .collect();
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(&texels),
    );
    texture.create_view(&Default::default())
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

/// Per-vertex normals from face normals (area-weighted), for meshes that come without.
fn flat_normals(m: &scene::Mesh) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; m.positions.len()];
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
        let f = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += f;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Y)).collect()
}

/// Tangents from UV derivatives, accumulated per vertex and Gram–Schmidt orthogonalised, for
/// normal-mapped meshes that come without tangents.
fn generate_tangents(p: &[Vec3], n: &[Vec3], uv: &[Vec2], indices: &[u32]) -> Vec<Vec4> {
    let mut t = vec![Vec3::ZERO; p.len()];
    let mut b = vec![Vec3::ZERO; p.len()];
    for tri in indices.chunks_exact(3) {
        let [i0, i1, i2] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let (e1, e2) = (p[i1] - p[i0], p[i2] - p[i0]);
        let (d1, d2) = (uv[i1] - uv[i0], uv[i2] - uv[i0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-12 {
            continue;
        }
        let r = 1.0 / det;
        let tu = (e1 * d2.y - e2 * d1.y) * r;
        let tv = (e2 * d1.x - e1 * d2.x) * r;
        for i in [i0, i1, i2] {
            t[i] += tu;
            b[i] += tv;
        }
    }
    (0..p.len())
        .map(|i| {
            let ortho = (t[i] - n[i] * n[i].dot(t[i])).normalize_or_zero();
            let w = if n[i].cross(ortho).dot(b[i]) < 0.0 { -1.0 } else { 1.0 };
            ortho.extend(w)
        })
        .collect()
}
