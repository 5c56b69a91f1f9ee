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
//! Every light the shading pass sees (at most [`MAX_LIGHTS`]) gets a layer of its own, in scene
//! order, skipping those without a usable frustum (degenerate direction): the emissive polygons'
//! area lights too, each from its centroid along its normal, so that a glowing cube's six faces
//! shadow each in its own direction (sharing one map per mesh, as before, left the walls beside
//! a closed emitter outside its single frustum and lit). The depth array has as many layers as
//! the scene's lights use (one 4 MiB layer for a single light, 128 MiB for 32), made again when
//! a new scene needs another count; a light whose frustum holds nothing its map would draw
//! gets none (nothing can shadow it). Stand-in lights (`Light::stands_in_for`) cast shadows like
//! any other, but their own emissive mesh is left out of their map: the lamp they approximate
//! does not occlude itself.

use super::{DEPTH_FORMAT, uniform_entry};
use crate::error::Result;
use crate::scene_gpu::{GpuScene, MAX_LIGHTS};
use crate::shader;
use glam::{Mat4, Vec3};
use scene::LightKind;

/// Shadow map edge length in texels.
pub const SHADOW_SIZE: u32 = 1024;
/// Most lights with a shadow map (layers of the depth array): every light the shading pass
/// draws. `MAX_SHADOWS` in `shading.wgsl` (checked by `layout_tests`).
pub const MAX_SHADOWS: usize = MAX_LIGHTS;
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
    /// All layers, for sampling (`texture_depth_2d_array`); replaced when a scene needs another
    /// number of layers ([`Self::update`] says so).
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
    /// [`ShadowUniforms`] for the shading pass.
    pub uniforms: wgpu::Buffer,
    /// One single-layer view per layer of the depth array, for rendering.
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
        let module = shader::compile(
            device,
            "shadow",
            &[shader::HASH, shader::MATERIAL, include_str!("shadow.wgsl")],
        )?;
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
        let (view, layer_views) = maps(device, 1);
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
    /// scene generation), `enabled` and the salt ask for. Returns true when the depth array was
    /// made again (another number of layers): bind groups holding [`Self::view`] are stale.
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &GpuScene,
        generation: u64,
        enabled: bool,
        frame_index: u32,
    ) -> bool {
        let salted = scene.draws.iter().any(|d| d.alpha_tested);
        let key = MapsKey { scene: generation, enabled, salt: if salted { frame_index } else { 0 } };
        if self.drawn == Some(key) {
            self.pending = None;
            return false;
        }
        self.pending = Some(key);
        let (uniforms, layers) =
            assign(&scene.lights, &scene.emitters, scene.bounds, &scene.mesh_bounds, enabled);
        let needed = layers.len().max(1);
        let remade = needed != self.layer_views.len();
        if remade {
            (self.view, self.layer_views) = maps(device, needed as u32);
            // The new array holds nothing yet.
            self.drawn = None;
        }
        for (i, (view_proj, (buffer, _))) in
            uniforms.view_proj.iter().zip(&self.layer_buffers).take(layers.len()).enumerate()
        {
            let salt = frame_index.wrapping_mul(MAX_SHADOWS as u32).wrapping_add(i as u32);
            let u = LayerUniforms { view_proj: *view_proj, params: [salt, 0, 0, 0] };
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(&u));
        }
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        self.active = layers;
        remade
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

/// The depth array of `layers` shadow maps: the view the shading pass samples and one view per
/// layer to render into.
fn maps(device: &wgpu::Device, layers: u32) -> (wgpu::TextureView, Vec<wgpu::TextureView>) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("shadow maps"),
        size: wgpu::Extent3d { width: SHADOW_SIZE, height: SHADOW_SIZE, depth_or_array_layers: layers },
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
    let layer_views = (0..layers)
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
    (view, layer_views)
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

/// Gives every light that has a frustum a layer, in scene order: the punctual lights, then the
/// emissive polygons that follow them in the GPU list (at most [`MAX_LIGHTS`] in all) — except
/// a light whose frustum holds no mesh that its map would draw (`mesh_bounds`, per scene mesh):
/// nothing can shadow it, so it is lit without a map (an emissive helmet's own clusters, whose
/// mesh their maps leave out, would read 32 empty layers per pixel).
fn assign(
    lights: &[scene::Light],
    emitters: &[scene::emitters::Emitter],
    bounds: (Vec3, Vec3),
    mesh_bounds: &[(Vec3, Vec3)],
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
        let Some((view_proj, bias)) = light_view_proj(light, bounds) else { continue };
        if !casts(view_proj, light.stands_in_for, mesh_bounds) {
            continue;
        }
        let layer = layers.len();
        u.view_proj[layer] = view_proj.to_cols_array_2d();
        u.bias[layer][0] = bias;
        u.layer_of_light[li / 4][li % 4] = layer as u32;
        layers.push(Layer { skip_mesh: light.stands_in_for });
    }
    // Each emissive polygon shadowed from its centroid, looking along its normal (150° wide),
    // without its own mesh.
    let in_list = emitters.len().min(MAX_LIGHTS.saturating_sub(lights.len()));
    for (ei, e) in emitters.iter().enumerate().take(in_list) {
        let li = lights.len() + ei;
        let Some((view_proj, bias)) = emitter_view_proj(e, bounds) else { continue };
        if !casts(view_proj, Some(e.mesh), mesh_bounds) {
            continue;
        }
        let layer = layers.len();
        u.view_proj[layer] = view_proj.to_cols_array_2d();
        let (near, far) = emitter_depth_range(e, bounds);
        u.bias[layer] = [bias, near, far, (e.area.max(0.0) / std::f32::consts::PI).sqrt()];
        u.layer_of_light[li / 4][li % 4] = layer as u32;
        layers.push(Layer { skip_mesh: Some(e.mesh) });
    }
    (u, layers)
}

/// Whether some mesh but `skip` has a bounding box that is not wholly outside the clip volume
/// of `view_proj` (wgpu's: −w ≤ x, y ≤ w, 0 ≤ z ≤ w): what the map would draw.
fn casts(view_proj: Mat4, skip: Option<usize>, mesh_bounds: &[(Vec3, Vec3)]) -> bool {
    mesh_bounds.iter().enumerate().any(|(mi, &(lo, hi))| {
        if Some(mi) == skip || lo.cmpgt(hi).any() {
            return false;
        }
        let corners: [glam::Vec4; 8] = std::array::from_fn(|k| {
            let c = Vec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo);
            view_proj * c.extend(1.0)
        });
        let outside = |f: &dyn Fn(glam::Vec4) -> bool| corners.iter().all(|&c| f(c));
        !(outside(&|c| c.x > c.w)
            || outside(&|c| c.x < -c.w)
            || outside(&|c| c.y > c.w)
            || outside(&|c| c.y < -c.w)
            || outside(&|c| c.z > c.w)
            || outside(&|c| c.z < 0.0))
    })
}

/// Half the diagonal of the scene's bounds, which sizes every shadow frustum, texel and bias.
/// Not floored at any fixed size (it was at 10⁻³: a scene 10⁻⁶ across had a bias larger than
/// itself and its lamp's shadows drew nothing); only a point-like scene gets a nonzero floor.
fn scene_radius(bounds: (Vec3, Vec3)) -> f32 {
    ((bounds.1 - bounds.0).length() * 0.5).max(1e-30)
}

/// View-projection from the light and a normal-offset bias (world units), or `None` when the
/// light cannot cast a shadow map (degenerate geometry).
pub fn light_view_proj(light: &scene::Light, bounds: (Vec3, Vec3)) -> Option<(Mat4, f32)> {
    let centre = (bounds.0 + bounds.1) * 0.5;
    let radius = scene_radius(bounds);
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
            let d = if dist > 1e-4 * radius { to_centre / dist } else { Vec3::NEG_Y };
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
    let radius = scene_radius(bounds);
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
    let radius = scene_radius(bounds);
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
    fn every_light_with_a_frustum_gets_a_layer_in_order() {
        let bounds = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let sun = LightKind::Directional { direction: Vec3::NEG_Y };
        let degenerate = LightKind::Directional { direction: Vec3::ZERO };
        let mut lights = vec![light(degenerate, None), light(sun.clone(), Some(3))];
        lights.extend((2..MAX_LIGHTS).map(|_| light(sun.clone(), None)));
        let (u, layers) = assign(&lights, &[], bounds, &[bounds], true);
        let layer = |i: usize| u.layer_of_light[i / 4][i % 4];
        assert_eq!(layer(0), NO_SHADOW, "no frustum, no map");
        assert_eq!(
            (1..MAX_LIGHTS).map(layer).collect::<Vec<_>>(),
            (0..MAX_LIGHTS as u32 - 1).collect::<Vec<_>>()
        );
        assert_eq!(layers.len(), MAX_LIGHTS - 1);
        assert_eq!(layers[0].skip_mesh, Some(3), "a stand-in skips its own mesh");
        assert!(layers[1..].iter().all(|l| l.skip_mesh.is_none()));
        let (u, layers) = assign(&lights, &[], bounds, &[bounds], false);
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
    fn each_face_of_a_glowing_cube_looks_its_own_way() {
        let bounds = (Vec3::splat(-10.0), Vec3::splat(10.0));
        let normals = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
        // Five glowing cubes (EmissiveStrengthTest) after two punctual lights: 32 lights.
        let mut emitters = Vec::new();
        for (mesh, x) in [-6.0f32, -3.0, 0.0, 3.0, 6.0].into_iter().enumerate() {
            for n in normals {
                emitters.push(face(mesh, Vec3::new(x, 0.0, 0.0), n, (1u32 << mesh) as f32));
            }
        }
        let sun = LightKind::Directional { direction: Vec3::NEG_Y };
        let lights = vec![light(sun.clone(), None), light(sun, None)];
        // The five cubes' meshes and the walled bays around them (mesh 5).
        let mut meshes: Vec<_> = [-6.0f32, -3.0, 0.0, 3.0, 6.0]
            .map(|x| (Vec3::new(x - 0.5, -0.5, -0.5), Vec3::new(x + 0.5, 0.5, 0.5)))
            .to_vec();
        meshes.push(bounds);
        let (u, layers) = assign(&lights, &emitters, bounds, &meshes, true);
        let layer = |i: usize| u.layer_of_light[i / 4][i % 4];
        assert_eq!(layers.len(), MAX_LIGHTS, "a map per light");
        for (ei, e) in emitters.iter().enumerate() {
            let l = layer(2 + ei) as usize;
            assert_eq!(l, 2 + ei, "light {ei}");
            assert_eq!(layers[l].skip_mesh, Some(e.mesh), "light {ei} leaves its own cube out");
            // The face's frustum looks along its normal: a point in front of the face projects
            // to the map's centre, at the depth between near and far.
            let m = Mat4::from_cols_array_2d(&u.view_proj[l]);
            let front = m.project_point3(e.centroid() + e.normal * 2.0);
            assert!(front.x.abs() < 1e-3 && front.y.abs() < 1e-3, "light {ei}: {front}");
            assert!(front.z > 0.0 && front.z < 1.0, "light {ei}: {front}");
            // Its light size is the disc of its own area.
            assert!((u.bias[l][3] - (1.0 / std::f32::consts::PI).sqrt()).abs() < 1e-6);
        }
        // Emitters beyond the GPU's light list have neither a light nor a map.
        let mut more = emitters.clone();
        more.extend(emitters[..4].iter().cloned());
        let (_, layers) = assign(&lights, &more, bounds, &meshes, true);
        assert_eq!(layers.len(), MAX_LIGHTS);
    }

    #[test]
    fn a_light_with_nothing_to_shadow_it_has_no_map() {
        let bounds = (Vec3::splat(-10.0), Vec3::splat(10.0));
        let up = face(0, Vec3::ZERO, Vec3::Y, 1.0);
        let box_at = |y: f32| (Vec3::new(-1.0, y, -1.0), Vec3::new(1.0, y + 1.0, 1.0));
        let layers = |meshes: &[(Vec3, Vec3)]| assign(&[], std::slice::from_ref(&up), bounds, meshes, true);
        // Only the emitter's own mesh: its map would be empty.
        assert!(layers(&[box_at(-0.5)]).1.is_empty());
        // A box above the upward face is in its frustum; one below it is not.
        assert_eq!(layers(&[box_at(-0.5), box_at(3.0)]).1.len(), 1);
        assert!(layers(&[box_at(-0.5), box_at(-5.0)]).1.is_empty());
        // An empty mesh casts nothing.
        let empty = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        assert!(layers(&[box_at(-0.5), empty]).1.is_empty());
        let (u, _) = layers(&[box_at(-0.5)]);
        assert_eq!(u.layer_of_light[0][0], NO_SHADOW);
    }
}
