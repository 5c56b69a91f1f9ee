//! Pass 1: rasterise the scene into the G-buffer — depth, base colour × texture × `COLOR_0`
//! (+ metallic), normal (normal-mapped through tangents, + roughness), and emission.
//!
//! Four pipelines, chosen per draw: single-sided materials cull back faces (glTF
//! `doubleSided: false`), double-sided ones do not and flip the normal of back faces towards
//! the viewer; `MASK` and `BLEND` materials use the fragment entry point that may discard
//! (below the cutoff, or stochastically for `BLEND`, see `wgsl/material.wgsl`), opaque ones one
//! without discard so that early depth testing stays on.

use super::{DEPTH_FORMAT, GBUFFER_FORMATS, SharedLayouts};
use crate::error::Result;
use crate::scene_gpu::{self, GpuScene, Vertex};
use crate::shader;

pub struct GBufferPass {
    pub material_layout: wgpu::BindGroupLayout,
    /// `[double_sided][alpha_tested]`.
    pipelines: [[wgpu::RenderPipeline; 2]; 2],
}

impl GBufferPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        let material_layout = scene_gpu::material_layout(device);
        let module = shader::compile(
            device,
            "gbuffer",
            &[shader::COMMON, shader::MATERIAL, include_str!("gbuffer.wgsl")],
        )?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[Some(&shared.frame), Some(&material_layout)],
            immediate_size: 0,
        });
        let targets = GBUFFER_FORMATS.map(|format| {
            Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
        });
        let pipeline = |double_sided: bool, alpha: bool| {
            shader::checked(device, "gbuffer pipeline", || {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("gbuffer"),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[Some(Vertex::layout())],
                    },
                    primitive: wgpu::PrimitiveState {
                        cull_mode: if double_sided { None } else { Some(wgpu::Face::Back) },
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some(if alpha { "fs_alpha" } else { "fs_main" }),
                        compilation_options: Default::default(),
                        targets: &targets,
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
        Ok(GBufferPass { material_layout, pipelines })
    }

    /// Clears and fills `colour` (the three G-buffer targets) and `depth`.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour: [&wgpu::TextureView; 3],
        depth: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
        scene: &GpuScene,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let attachments = colour.map(|view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
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
        pass.set_bind_group(0, frame, &[]);
        let mut current = None;
        for d in &scene.draws {
            let key = (d.double_sided as usize, d.alpha_tested as usize);
            if current != Some(key) {
                pass.set_pipeline(&self.pipelines[key.0][key.1]);
                current = Some(key);
            }
            scene.draw_one(&mut pass, d);
        }
    }
}
