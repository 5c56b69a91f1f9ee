//! Shadow map for the main light: depth rendered from the light, sampled with hardware 2×2
//! comparison filtering in the shading pass.
//!
//! Directional lights get an orthographic frustum around the scene bounds; spot lights a
//! perspective frustum of their outer cone; point lights a perspective frustum aimed at the
//! scene's centre (at most 150°: points outside it are treated as lit).

use super::{DEPTH_FORMAT, SharedLayouts};
use crate::error::Result;
use crate::scene_gpu::GpuScene;
use crate::shader;
use glam::{Mat4, Vec3};
use scene::LightKind;

/// Shadow map edge length in texels.
pub const SHADOW_SIZE: u32 = 1024;

pub struct ShadowPass {
    pipeline: wgpu::RenderPipeline,
    pub view: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        let module = shader::compile(device, "shadow", &[shader::COMMON, include_str!("shadow.wgsl")])?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow"),
            bind_group_layouts: &[Some(&shared.frame)],
            immediate_size: 0,
        });
        let pipeline = shader::checked(device, "shadow pipeline", || {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_shadow"),
                    compilation_options: Default::default(),
                    buffers: &[Some(crate::scene_gpu::Vertex::layout())],
                },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: wgpu::DepthBiasState { constant: 2, slope_scale: 2.0, clamp: 0.0 },
                }),
                multisample: Default::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        })?;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow map"),
            size: wgpu::Extent3d { width: SHADOW_SIZE, height: SHADOW_SIZE, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        Ok(ShadowPass { pipeline, view: texture.create_view(&Default::default()), sampler })
    }

    /// Clears the map to "far" (fully lit), then draws the scene when `scene` is given.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        frame: &wgpu::BindGroup,
        scene: Option<&GpuScene>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(scene) = scene {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, frame, &[]);
            scene.draw(&mut pass, false);
        }
    }
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
