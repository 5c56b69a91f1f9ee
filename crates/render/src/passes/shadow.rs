//! Shadow maps, one per shadow-casting light: depth rendered from each light into one layer of
//! a depth texture array, sampled with hardware 2×2 comparison filtering in the shading pass
//! (one comparison sample per shadowed light per pixel, no per-wavelength work).
//!
//! Directional lights get an orthographic frustum around the scene bounds; spot lights a
//! perspective frustum of their outer cone; point lights a perspective frustum aimed at the
//! scene's centre (at most 150°: points outside it are treated as lit).
//!
//! Materials: single-sided geometry (glTF `doubleSided: false`) is drawn with the faces that
//! look *towards the light* culled, so a single-sided surface casts a shadow only onto what
//! lies on its front side. This is the convention both renderers share — a single-sided back
//! face is invisible to every ray, and the path tracer's shadow rays start at the shaded point:
//! from there a surface blocks the light only if the point sees its front face, i.e. its back
//! faces the light. (Closed single-sided meshes shadow as before; an inward-facing single-sided
//! room keeps outside light out; a single-sided ground plane does not shadow itself, and
//! objects above it shadow it.) Double-sided geometry is drawn without culling. `MASK` and
//! `BLEND` materials run a fragment stage with the G-buffer's alpha: texels below the cutoff,
//! or the stochastically dropped fraction 1 − alpha of a blended surface, let the light through
//! (see `wgsl/material.wgsl`).
//!
//! Lights are given layers in scene order, skipping those without a usable frustum
//! (degenerate direction); lights beyond [`MAX_SHADOWS`] are **unshadowed**. Stand-in lights
//! (`Light::stands_in_for`) cast shadows like any other, but their own emissive mesh is left
//! out of their map: the lamp they approximate does not occlude itself.

use super::{DEPTH_FORMAT, uniform_entry};
use crate::error::Result;
use crate::scene_gpu::{GpuScene, MAX_LIGHTS};
use crate::shader;
use glam::{Mat4, Vec3};
use scene::LightKind;

/// Shadow map edge length in texels.
pub const SHADOW_SIZE: u32 = 1024;
/// Most lights with a shadow map (layers of the depth array); `MAX_SHADOWS` in `shading.wgsl`
/// (checked by `layout_tests`).
pub const MAX_SHADOWS: usize = 8;
/// `ShadowUniforms::layer_of_light` value for a light without a shadow map.
pub const NO_SHADOW: u32 = u32::MAX;

/// Byte-for-byte `ShadowUniforms` in `shading.wgsl` (checked by `layout_tests`): what the shading pass needs to look a
/// point up in the maps.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowUniforms {
    /// World → clip of each layer's light.
    pub view_proj: [[[f32; 4]; 4]; MAX_SHADOWS],
    /// x: normal-offset bias (world units) of each layer; for an emissive polygon's layer
    /// y and z the frustum's near and far distances and w the radius of the disc of the
    /// polygon's area (the soft shadow's light size, `soft_visibility` in shading.wgsl); zero
    /// for punctual lights (hard shadows).
    pub bias: [[f32; 4]; MAX_SHADOWS],
    /// Layer of light `i` at `[i / 4][i % 4]`, or [`NO_SHADOW`].
    pub layer_of_light: [[u32; 4]; MAX_LIGHTS / 4],
}

/// One layer to render this frame.
#[derive(Clone, Copy, Debug)]
struct Layer {
    /// Index into `GpuScene::draws` (= `Scene::meshes`) left out of this map.
    skip_mesh: Option<usize>,
}

/// Byte-for-byte `ShadowLayer` in `shadow.wgsl` (checked by `layout_tests`): one layer's light
/// and hash salt.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct LayerUniforms {
    pub(crate) view_proj: [[f32; 4]; 4],
    pub(crate) params: [u32; 4],
}

pub struct ShadowPass {
    /// `[double_sided][alpha_tested]`.
    pipelines: [[wgpu::RenderPipeline; 2]; 2],
    /// All layers, for sampling (`texture_depth_2d_array`).
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    /// [`ShadowUniforms`] for the shading pass.
    pub uniforms: wgpu::Buffer,
    /// One single-layer view per layer, for rendering.
    layer_views: Vec<wgpu::TextureView>,
    /// One light view-projection uniform (and its bind group) per layer.
    layer_buffers: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
    /// Layers in use since the last [`Self::update`].
    active: Vec<Layer>,
    /// What the maps hold once the last frame that drew them has been submitted
    /// ([`Self::submitted`]), and what the next [`Self::record`] draws (`None`: the maps already
    /// hold it, so the pass is skipped). Shadow maps depend only on the scene and its lights,
    /// not on the camera: a static scene draws them once.
    drawn: Option<MapsKey>,
    pending: Option<MapsKey>,
}

/// What determines the shadow maps' content.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapsKey {
    /// The renderer's scene generation (any new scene or environment).
    pub scene: u64,
    pub enabled: bool,
    /// The stochastic transparency's salt (the frame index), where an alpha-tested material
    /// casts shadows; 0 otherwise.
    pub salt: u32,
}

impl ShadowPass {
    /// `material_layout`: the material bind group's (group 1), shared with the G-buffer pass.
    pub fn new(device: &wgpu::Device, material_layout: &wgpu::BindGroupLayout) -> Result<Self> {
        let module = shader::compile(device, "shadow", &[shader::MATERIAL, include_str!("shadow.wgsl")])?;
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow light"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT)],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&light_layout), Some(material_layout)],
            immediate_size: 0,
        });
        let pipeline = |double_sided: bool, alpha: bool| {
            shader::checked(device, "shadow pipeline", || {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("shadow"),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_shadow"),
                        compilation_options: Default::default(),
                        buffers: &[Some(crate::scene_gpu::Vertex::layout())],
                    },
                    // Single-sided: keep only faces whose back is towards the light (module docs).
                    primitive: wgpu::PrimitiveState {
                        cull_mode: if double_sided { None } else { Some(wgpu::Face::Front) },
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: wgpu::DepthBiasState { constant: 2, slope_scale: 2.0, clamp: 0.0 },
                    }),
                    multisample: Default::default(),
                    fragment: alpha.then(|| wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs_shadow_alpha"),
                        compilation_options: Default::default(),
                        targets: &[],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            })
        };
        let pipelines = [
            [pipeline(false, false)?, pipeline(false, true)?],
            [pipeline(true, false)?, pipeline(true, true)?],
        ];
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d {
                width: SHADOW_SIZE,
                height: SHADOW_SIZE,
                depth_or_array_layers: MAX_SHADOWS as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("shadow maps"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let layer_views = (0..MAX_SHADOWS as u32)
            .map(|layer| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow map layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let layer_buffers = (0..MAX_SHADOWS)
            .map(|_| {
                let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("shadow light view-projection"),
                    size: std::mem::size_of::<LayerUniforms>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadow light"),
                    layout: &light_layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
                });
                (buffer, bind_group)
            })
            .collect();
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow uniforms"),
            size: std::mem::size_of::<ShadowUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        Ok(ShadowPass {
            pipelines,
            view,
            sampler,
            uniforms,
            layer_views,
            layer_buffers,
            active: Vec::new(),
            drawn: None,
            pending: None,
        })
    }

    /// Chooses the shadowed lights of `scene` (none when `enabled` is false), uploads their
    /// matrices for the shadow and shading passes. `frame_index` salts the stochastic
    /// transparency of `BLEND` materials (as in the G-buffer).
    /// Nothing is uploaded or drawn when the maps already hold what `generation` (the renderer's
    /// scene generation), `enabled` and the salt ask for.
    pub fn update(
        &mut self,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        generation: u64,
        enabled: bool,
        frame_index: u32,
    ) {
        let salted = scene.draws.iter().any(|d| d.alpha_tested);
        let key = MapsKey { scene: generation, enabled, salt: if salted { frame_index } else { 0 } };
        if self.drawn == Some(key) {
            self.pending = None;
            return;
        }
        self.pending = Some(key);
        let (uniforms, layers) = assign(&scene.lights, &scene.emitters, scene.bounds, enabled);
        for (i, (view_proj, (buffer, _))) in
            uniforms.view_proj.iter().zip(&self.layer_buffers).take(layers.len()).enumerate()
        {
            let salt = frame_index.wrapping_mul(MAX_SHADOWS as u32).wrapping_add(i as u32);
            let u = LayerUniforms { view_proj: *view_proj, params: [salt, 0, 0, 0] };
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(&u));
        }
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        self.active = layers;
    }

    /// Renders every layer chosen by the last [`Self::update`], each cleared to "far" (fully
    /// lit) first. With no layer in use one empty pass still runs so that the timestamps
    /// measure something.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        if self.pending.is_none() {
            // The maps hold this frame's shadows already: only the timestamps.
            if let Some(t) = timestamps {
                encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("shadow (maps unchanged, skipped)"),
                    timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                        query_set: t.query_set,
                        beginning_of_pass_write_index: t.beginning_of_pass_write_index,
                        end_of_pass_write_index: t.end_of_pass_write_index,
                    }),
                });
            }
            return;
        }
        let n = self.active.len().max(1);
        for i in 0..n {
            // The first pass writes the start timestamp, the last one the end; the passes
            // between write none (wgpu rejects timestamp writes with neither index).
            let ts = timestamps.as_ref().and_then(|t| layer_timestamps(t, i, n));
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.layer_views[i],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: ts,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let Some(layer) = self.active.get(i) else { continue };
            pass.set_bind_group(0, &self.layer_buffers[i].1, &[]);
            let mut current = None;
            for d in &scene.draws {
                if layer.skip_mesh == Some(d.mesh) {
                    continue;
                }
                let key = (d.double_sided as usize, d.alpha_tested as usize);
                if current != Some(key) {
                    pass.set_pipeline(&self.pipelines[key.0][key.1]);
                    current = Some(key);
                }
                scene.draw_one(&mut pass, d);
            }
        }
    }

    /// The frame recorded since the last [`Self::update`] was submitted: its maps are current.
    /// (Until then a failed frame leaves them to be drawn again.)
    pub fn submitted(&mut self) {
        if let Some(key) = self.pending.take() {
            self.drawn = Some(key);
        }
    }
}

/// The timestamp writes of shadow pass `i` of `n`: the begin index on the first, the end index
/// on the last, `None` for a pass between them (wgpu rejects writes with neither index).
fn layer_timestamps<'a>(
    t: &wgpu::RenderPassTimestampWrites<'a>,
    i: usize,
    n: usize,
) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
    let (begin, end) = layer_indices(t.beginning_of_pass_write_index, t.end_of_pass_write_index, i, n)?;
    Some(wgpu::RenderPassTimestampWrites {
        query_set: t.query_set,
        beginning_of_pass_write_index: begin,
        end_of_pass_write_index: end,
    })
}

/// The (begin, end) query indices shadow pass `i` of `n` writes, `None` when it writes neither.
fn layer_indices(
    begin: Option<u32>,
    end: Option<u32>,
    i: usize,
    n: usize,
) -> Option<(Option<u32>, Option<u32>)> {
    let begin = begin.filter(|_| i == 0);
    let end = end.filter(|_| i + 1 == n);
    (begin.is_some() || end.is_some()).then_some((begin, end))
}

/// Gives the first [`MAX_SHADOWS`] lights that have a frustum a layer each, in scene order.
fn assign(
    lights: &[scene::Light],
    emitters: &[scene::emitters::Emitter],
    bounds: (Vec3, Vec3),
    enabled: bool,
) -> (ShadowUniforms, Vec<Layer>) {
    let mut u = ShadowUniforms {
        view_proj: [Mat4::IDENTITY.to_cols_array_2d(); MAX_SHADOWS],
        bias: [[0.0; 4]; MAX_SHADOWS],
        layer_of_light: [[NO_SHADOW; 4]; MAX_LIGHTS / 4],
    };
    let mut layers = Vec::new();
    if !enabled {
        return (u, layers);
    }
    for (li, light) in lights.iter().enumerate().take(MAX_LIGHTS) {
        if layers.len() == MAX_SHADOWS {
            break;
        }
        let Some((view_proj, bias)) = light_view_proj(light, bounds) else { continue };
        let layer = layers.len();
        u.view_proj[layer] = view_proj.to_cols_array_2d();
        u.bias[layer][0] = bias;
        u.layer_of_light[li / 4][li % 4] = layer as u32;
        layers.push(Layer { skip_mesh: light.stands_in_for });
    }
    // Emissive polygons follow the punctual lights in the GPU list: each shadowed from its
    // centroid, looking along its normal (150° wide), without its own mesh — when they all fit.
    let in_list = emitters.len().min(MAX_LIGHTS.saturating_sub(lights.len()));
    if in_list <= MAX_SHADOWS - layers.len() {
        for (ei, e) in emitters.iter().enumerate().take(in_list) {
            let li = lights.len() + ei;
            let Some((view_proj, bias)) = emitter_view_proj(e, bounds) else { continue };
            let layer = layers.len();
            u.view_proj[layer] = view_proj.to_cols_array_2d();
            let (near, far) = emitter_depth_range(e, bounds);
            u.bias[layer] = [bias, near, far, (e.area.max(0.0) / std::f32::consts::PI).sqrt()];
            u.layer_of_light[li / 4][li % 4] = layer as u32;
            layers.push(Layer { skip_mesh: Some(e.mesh) });
        }
        return (u, layers);
    }
    // More area lights than maps: the lights of one emitting mesh share a map from the mesh's
    // emitting centre (`mesh_view_proj`), brightest meshes first, so that a few glowing objects
    // cut into many lights (a cube's six faces, a sphere's clusters) are all shadowed instead
    // of the first eight lights only — unshadowed lights leak through walls.
    let mut meshes: Vec<(usize, Vec<usize>, f64)> = Vec::new();
    for (ei, e) in emitters.iter().enumerate().take(in_list) {
        match meshes.iter_mut().find(|m| m.0 == e.mesh) {
            Some(m) => {
                m.1.push(ei);
                m.2 += e.power();
            }
            None => meshes.push((e.mesh, vec![ei], e.power())),
        }
    }
    meshes.sort_by(|a, b| b.2.total_cmp(&a.2));
    for (mesh, members, _) in meshes {
        if layers.len() == MAX_SHADOWS {
            break;
        }
        let group: Vec<&scene::emitters::Emitter> = members.iter().map(|&ei| &emitters[ei]).collect();
        let Some((view_proj, bias, near, far, radius)) = mesh_view_proj(&group, bounds) else { continue };
        let layer = layers.len();
        u.view_proj[layer] = view_proj.to_cols_array_2d();
        u.bias[layer] = [bias, near, far, radius];
        for ei in members {
            let li = lights.len() + ei;
            u.layer_of_light[li / 4][li % 4] = layer as u32;
        }
        layers.push(Layer { skip_mesh: Some(mesh) });
    }
    (u, layers)
}

/// The shadow frustum shared by the area lights of one emitting mesh: a 150° perspective from
/// their power-weighted centre, looking along their power-weighted mean normal (an open emitter,
/// e.g. a panel) or, where the normals cancel (a closed one: a cube, a sphere), towards the
/// scene's centre; with the map's bias, depth range and the light's radius for the soft shadows
/// (the disc of the mesh's projected area: total area / π for an open emitter, / 4π for a closed
/// one, as a sphere's).
fn mesh_view_proj(
    group: &[&scene::emitters::Emitter],
    bounds: (Vec3, Vec3),
) -> Option<(Mat4, f32, f32, f32, f32)> {
    let centre = (bounds.0 + bounds.1) * 0.5;
    let radius = ((bounds.1 - bounds.0).length() * 0.5).max(1e-3);
    let texel = 2.0 * radius / SHADOW_SIZE as f32;
    let power: f64 = group.iter().map(|e| e.power()).sum();
    let weight = |e: &scene::emitters::Emitter| {
        if power > 0.0 { (e.power() / power) as f32 } else { 1.0 / group.len() as f32 }
    };
    let eye = group.iter().map(|e| e.centroid() * weight(e)).sum::<Vec3>();
    let mean_normal = group.iter().map(|e| e.normal * weight(e)).sum::<Vec3>();
    let area: f32 = group.iter().map(|e| e.area.max(0.0)).sum();
    let closed = mean_normal.length() < 0.5;
    let d = if closed {
        (centre - eye).try_normalize().unwrap_or(Vec3::NEG_Y)
    } else {
        mean_normal.try_normalize()?
    };
    let up = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let far = (eye - centre).length() + radius * 2.0;
    let near = far * 1e-3;
    let view = Mat4::look_at_rh(eye, eye + d, up);
    let disc = (area / if closed { 4.0 * std::f32::consts::PI } else { std::f32::consts::PI }).sqrt();
    Some((Mat4::perspective_rh(EMITTER_FOV, 1.0, near, far) * view, texel * 1.5, near, far, disc))
}

/// View-projection from the light and a normal-offset bias (world units), or `None` when the
/// light cannot cast a shadow map (degenerate geometry).
pub fn light_view_proj(light: &scene::Light, bounds: (Vec3, Vec3)) -> Option<(Mat4, f32)> {
    let centre = (bounds.0 + bounds.1) * 0.5;
    let radius = ((bounds.1 - bounds.0).length() * 0.5).max(1e-3);
    let up_for = |dir: Vec3| if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let texel = 2.0 * radius / SHADOW_SIZE as f32;
    match light.kind {
        LightKind::Directional { direction } => {
            let d = direction.try_normalize()?;
            let eye = centre - d * radius * 2.0;
            let view = Mat4::look_at_rh(eye, centre, up_for(d));
            let proj = Mat4::orthographic_rh(-radius, radius, -radius, radius, radius * 0.5, radius * 3.5);
            Some((proj * view, texel * 1.5))
        }
        LightKind::Spot { position, direction, outer_cone, .. } => {
            let d = direction.try_normalize()?;
            let fov = (2.0 * outer_cone + 0.1).clamp(0.1, 150f32.to_radians());
            let far = (position - centre).length() + radius * 2.0;
            let view = Mat4::look_at_rh(position, position + d, up_for(d));
            Some((Mat4::perspective_rh(fov, 1.0, far * 1e-3, far) * view, texel * 1.5))
        }
        LightKind::Point { position, .. } => {
            let to_centre = centre - position;
            let dist = to_centre.length();
            let d = if dist > 1e-4 { to_centre / dist } else { Vec3::NEG_Y };
            let fov = if dist > radius { 2.2 * (radius / dist).asin() } else { 150f32.to_radians() };
            let fov = fov.clamp(0.1, 150f32.to_radians());
            let far = dist + radius * 2.0;
            let view = Mat4::look_at_rh(position, position + d, up_for(d));
            Some((Mat4::perspective_rh(fov, 1.0, far * 1e-3, far) * view, texel * 1.5))
        }
    }
}

/// The shadow frustum of an emissive polygon: a 150° perspective from its centroid along its
/// emitting normal (what lies outside it is treated as lit); the shading pass softens its
/// shadows by the polygon's size (`soft_visibility` in shading.wgsl, from `ShadowUniforms::bias`).
pub fn emitter_view_proj(e: &scene::emitters::Emitter, bounds: (Vec3, Vec3)) -> Option<(Mat4, f32)> {
    let radius = ((bounds.1 - bounds.0).length() * 0.5).max(1e-3);
    let texel = 2.0 * radius / SHADOW_SIZE as f32;
    let d = e.normal.try_normalize()?;
    let up = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let eye = e.centroid() + d * (1e-4 * radius);
    let (near, far) = emitter_depth_range(e, bounds);
    let view = Mat4::look_at_rh(eye, eye + d, up);
    Some((Mat4::perspective_rh(EMITTER_FOV, 1.0, near, far) * view, texel * 1.5))
}

/// The field of view of an emissive polygon's shadow frustum.
pub const EMITTER_FOV: f32 = 150.0 * std::f32::consts::PI / 180.0;

/// Near and far distances of an emissive polygon's shadow frustum.
fn emitter_depth_range(e: &scene::emitters::Emitter, bounds: (Vec3, Vec3)) -> (f32, f32) {
    let centre = (bounds.0 + bounds.1) * 0.5;
    let radius = ((bounds.1 - bounds.0).length() * 0.5).max(1e-3);
    let d = e.normal.try_normalize().unwrap_or(Vec3::Y);
    let eye = e.centroid() + d * (1e-4 * radius);
    let far = (eye - centre).length() + radius * 2.0;
    (far * 1e-3, far)
}

// `layer_of_light` packs four lights per vec4<u32>.
const _: () = assert!(MAX_LIGHTS.is_multiple_of(4));

#[cfg(test)]
mod tests {
    use super::*;

    fn light(kind: LightKind, stands_in_for: Option<usize>) -> scene::Light {
        scene::Light {
            name: "l".into(),
            kind,
            emission: scene::Emission { rgb: Vec3::ONE, intensity: 1.0, spectrum: None },
            stands_in_for,
        }
    }

    #[test]
    fn only_the_first_and_last_layer_write_timestamps() {
        let (b, e) = (Some(0), Some(1));
        assert_eq!(layer_indices(b, e, 0, 1), Some((b, e)), "one pass writes both");
        assert_eq!(layer_indices(b, e, 0, 2), Some((b, None)));
        assert_eq!(layer_indices(b, e, 1, 2), Some((None, e)));
        for n in 3..=MAX_SHADOWS {
            let writes: Vec<_> = (0..n).map(|i| layer_indices(b, e, i, n)).collect();
            assert_eq!(writes[0], Some((b, None)), "n = {n}");
            assert_eq!(writes[n - 1], Some((None, e)), "n = {n}");
            assert!(writes[1..n - 1].iter().all(Option::is_none), "n = {n}: {writes:?}");
        }
        assert_eq!(layer_indices(None, None, 0, 1), None);
    }

    #[test]
    fn layers_go_to_lights_in_order_up_to_the_maximum() {
        let bounds = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let sun = LightKind::Directional { direction: Vec3::NEG_Y };
        let degenerate = LightKind::Directional { direction: Vec3::ZERO };
        let mut lights = vec![light(degenerate, None), light(sun.clone(), Some(3))];
        lights.extend((0..MAX_SHADOWS).map(|_| light(sun.clone(), None)));
        let (u, layers) = assign(&lights, &[], bounds, true);
        let layer = |i: usize| u.layer_of_light[i / 4][i % 4];
        assert_eq!(layer(0), NO_SHADOW, "no frustum, no map");
        assert_eq!(
            (1..=MAX_SHADOWS).map(layer).collect::<Vec<_>>(),
            (0..MAX_SHADOWS as u32).collect::<Vec<_>>()
        );
        assert_eq!(layer(MAX_SHADOWS + 1), NO_SHADOW, "beyond the maximum");
        assert_eq!(layers.len(), MAX_SHADOWS);
        assert_eq!(layers[0].skip_mesh, Some(3), "a stand-in skips its own mesh");
        assert!(layers[1..].iter().all(|l| l.skip_mesh.is_none()));
        let (u, layers) = assign(&lights, &[], bounds, false);
        assert!(layers.is_empty() && u.layer_of_light.iter().flatten().all(|&l| l == NO_SHADOW));
    }

    /// A unit square face of cube `mesh` centred at `c` with outward normal `n`.
    fn face(mesh: usize, c: Vec3, n: Vec3, strength: f32) -> scene::emitters::Emitter {
        let t = if n.y.abs() > 0.9 { Vec3::X } else { Vec3::Y };
        let b = n.cross(t);
        let p = c + n * 0.5;
        scene::emitters::Emitter {
            mesh,
            vertices: vec![
                p - t * 0.5 - b * 0.5,
                p + t * 0.5 - b * 0.5,
                p + t * 0.5 + b * 0.5,
                p - t * 0.5 + b * 0.5,
            ],
            emission: scene::Emission { rgb: Vec3::ONE, intensity: strength, spectrum: None },
            normal: n,
            area: 1.0,
        }
    }

    #[test]
    fn area_lights_that_outnumber_the_maps_share_one_per_mesh() {
        let bounds = (Vec3::splat(-10.0), Vec3::splat(10.0));
        let normals = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
        // Five glowing cubes of strengths 1, 2, 4, 8, 16 (EmissiveStrengthTest): 30 lights.
        let mut emitters = Vec::new();
        for (mesh, x) in [-6.0f32, -3.0, 0.0, 3.0, 6.0].into_iter().enumerate() {
            for n in normals {
                emitters.push(face(mesh, Vec3::new(x, 0.0, 0.0), n, (1u32 << mesh) as f32));
            }
        }
        let (u, layers) = assign(&[], &emitters, bounds, true);
        let layer = |i: usize| u.layer_of_light[i / 4][i % 4];
        assert_eq!(layers.len(), 5, "one map per cube");
        for (ei, e) in emitters.iter().enumerate() {
            let l = layer(ei) as usize;
            assert_ne!(l as u32, NO_SHADOW, "light {ei} unshadowed");
            assert_eq!(layers[l].skip_mesh, Some(e.mesh), "light {ei} shares its own cube's map");
        }
        // Brightest cube first; the closed cube's radius is the sphere of its six faces' area.
        assert_eq!(layer(24), 0);
        assert!((u.bias[0][3] - (6.0 / (4.0 * std::f32::consts::PI)).sqrt()).abs() < 1e-6);
        // Sixteen two-sided emitters (32 lights): the eight brightest get maps, the rest none.
        let many: Vec<_> = (0..16)
            .flat_map(|mesh| {
                [Vec3::X, Vec3::NEG_X]
                    .map(|n| face(mesh, Vec3::new(mesh as f32 - 8.0, 0.0, 0.0), n, 1.0 + mesh as f32))
            })
            .collect();
        let (u, layers) = assign(&[], &many, bounds, true);
        assert_eq!(layers.len(), MAX_SHADOWS);
        let layer = |i: usize| u.layer_of_light[i / 4][i % 4];
        assert_eq!((layer(0), layer(1)), (NO_SHADOW, NO_SHADOW), "the dimmest emitter's lights");
        assert_eq!((layer(30), layer(31)), (0, 0), "the brightest's share the first map");
        // Few enough lights keep a map each (as before).
        let (_, layers) = assign(&[], &emitters[..6], bounds, true);
        assert_eq!(layers.len(), 6);
    }
}
