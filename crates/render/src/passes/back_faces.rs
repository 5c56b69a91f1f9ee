//! The see-through layer's back faces: the see-through meshes rasterised once more with their
//! front faces culled, keeping the nearest back face per pixel — its outward normal and linear
//! depth ([`BACK_FACES_FORMAT`]). The transmissive layer's shading (passes/transmission.wgsl)
//! marches the refracted view ray to that surface and refracts it out there, so that a glass
//! ball shows the inverted image a ball of glass shows. Drawn only in frames with see-through
//! materials, after their G-buffer layer.
//!
//! Inputs: the frame uniforms, the see-through draws' vertices. Outputs: the back-face target
//! (cleared to w = −1: no back face) and its own depth.

use super::{SharedLayouts, depth_state, pipeline_layout};
use crate::error::Result;
use crate::scene_gpu::{GpuScene, Vertex};
use crate::shader;

/// xyz outward normal, w linear depth: f32, since depths are compared along a ray inside a
/// volume a few millimetres deep.
pub const BACK_FACES_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

pub struct BackFacesPass {
    pipeline: wgpu::RenderPipeline,
}

impl BackFacesPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        let module =
            shader::compile(device, "back faces", &[shader::COMMON, include_str!("back_faces.wgsl")])?;
        let pipeline = shader::checked(device, "back-face pipeline", || {
            let layout = pipeline_layout(device, "back faces", &[&shared.frame]);
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("back faces"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_back"),
                    compilation_options: Default::default(),
                    buffers: &[Some(Vertex::layout())],
                },
                primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Front), ..Default::default() },
                depth_stencil: Some(depth_state(super::NEARER, true)),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_back"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: BACK_FACES_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        })?;
        Ok(BackFacesPass { pipeline })
    }

    /// Records the see-through draws of `scene` into `target` over `depth` (both cleared).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
        scene: &GpuScene,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("back faces"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.0, g: 0.0, b: 0.0, a: -1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(super::FAR_DEPTH),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        for d in scene.draws.iter().filter(|d| d.transmissive) {
            scene.draw_geometry(&mut pass, d);
        }
    }
}
