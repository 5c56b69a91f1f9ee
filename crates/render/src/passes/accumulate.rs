//! Optional pass 3½: temporal accumulation. The running mean of the custom pass's linear HDR
//! output over the frames since the last reset, m_k = m_{k-1} + (x_k − m_{k-1})/k, kept in f32
//! (the previous mean is copied aside each frame rather than ping-ponged: one bind group). Post
//! then tone-maps the mean. With jittered wavelengths (`RenderSettings::jitter`) each frame is an
//! unbiased estimate, so the mean converges to the dense spectral integral.

use super::{HDR_FORMAT, texture_entry, uniform_entry};
use crate::error::Result;
use crate::shader;

/// The accumulated mean's format: f32 so that rounding does not build up over many frames.
pub const ACCUM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

pub struct AccumulatePass {
    /// Group 0: the current HDR frame, the previous mean, the weight uniform.
    pub input_layout: wgpu::BindGroupLayout,
    /// `[weight, 0, 0, 0]`, rewritten every accumulated frame.
    pub uniforms: wgpu::Buffer,
    pipeline: wgpu::RenderPipeline,
}

impl AccumulatePass {
    pub fn new(device: &wgpu::Device) -> Result<Self> {
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("accumulate inputs"),
            entries: &[texture_entry(0), texture_entry(1), uniform_entry(2, wgpu::ShaderStages::FRAGMENT)],
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulate uniforms"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let module =
            shader::compile(device, "accumulate", &[shader::COMMON, include_str!("accumulate.wgsl")])?;
        let pipeline = shader::checked(device, "accumulate pipeline", || {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("accumulate"),
                bind_group_layouts: &[Some(&input_layout)],
                immediate_size: 0,
            });
            let target = |format| {
                Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
            };
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("accumulate"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[target(ACCUM_FORMAT), target(HDR_FORMAT)],
                }),
                multiview_mask: None,
                cache: None,
            })
        })?;
        Ok(AccumulatePass { input_layout, uniforms, pipeline })
    }

    /// Sets the weight of the frame about to be recorded: 1/k for the k-th since the reset.
    pub fn set_frame(&self, queue: &wgpu::Queue, k: u32) {
        let w = 1.0 / k.max(1) as f32;
        queue.write_buffer(&self.uniforms, 0, bytemuck::cast_slice(&[w, 0.0, 0.0, 0.0]));
    }

    /// Copies the current mean aside (`mean` → `prev`, read by `inputs`), then writes the new
    /// mean to `mean` and to `display` (HDR format, post's input).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mean: &wgpu::Texture,
        prev: &wgpu::Texture,
        mean_view: &wgpu::TextureView,
        display_view: &wgpu::TextureView,
        inputs: &wgpu::BindGroup,
    ) {
        encoder.copy_texture_to_texture(
            mean.as_image_copy(),
            prev.as_image_copy(),
            wgpu::Extent3d { width: mean.width(), height: mean.height(), depth_or_array_layers: 1 },
        );
        let attachment = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("accumulate"),
            color_attachments: &[attachment(mean_view), attachment(display_view)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, inputs, &[]);
        pass.draw(0..3, 0..1);
    }
}
