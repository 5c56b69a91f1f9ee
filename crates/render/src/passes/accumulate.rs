//! Optional pass 3½: temporal accumulation. The running mean of the custom pass's linear HDR
//! output over the frames since the last reset, m_k = m_{k-1} + (x_k − m_{k-1})/k, kept in f32
//! (the previous mean is copied aside each frame rather than ping-ponged: one bind group). Post
//! then tone-maps the mean. With jittered wavelengths (`RenderSettings::jitter`) each frame is an
//! unbiased estimate, so the mean converges to the dense spectral integral.

use super::{
    FullscreenPipeline, HDR_FORMAT, buffer_entry, draw_fullscreen, pipeline_layout, texture_entry,
    uniform_entry, view_entry,
};
use crate::error::Result;
use crate::shader;
use crate::targets::{AccumTargets, Targets};

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
            let layout = pipeline_layout(device, "accumulate", &[&input_layout]);
            FullscreenPipeline {
                targets: &[ACCUM_FORMAT, HDR_FORMAT],
                ..FullscreenPipeline::simple("accumulate", &module, &layout, &[HDR_FORMAT])
            }
            .build(device)
        })?;
        Ok(AccumulatePass { input_layout, uniforms, pipeline })
    }

    /// Sets the weight of the frame about to be recorded: 1/k for the k-th since the reset.
    pub fn set_frame(&self, queue: &wgpu::Queue, k: u32) {
        let w = 1.0 / k.max(1) as f32;
        queue.write_buffer(&self.uniforms, 0, bytemuck::cast_slice(&[w, 0.0, 0.0, 0.0]));
    }

    /// Group 0: the current frame, the previous mean and the weight.
    pub fn bind_inputs(&self, device: &wgpu::Device, t: &Targets, a: &AccumTargets) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulate inputs"),
            layout: &self.input_layout,
            entries: &[
                view_entry(0, &t.hdr_view),
                view_entry(1, &a.accum_prev_view),
                buffer_entry(2, &self.uniforms),
            ],
        })
    }

    /// Copies the current mean aside (`accum` → `accum_prev`, read by `inputs`, from
    /// [`Self::bind_inputs`]), then writes the new mean to `accum` and to `accum_display` (HDR
    /// format, post's input).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, t: &AccumTargets, inputs: &wgpu::BindGroup) {
        encoder.copy_texture_to_texture(
            t.accum.as_image_copy(),
            t.accum_prev.as_image_copy(),
            wgpu::Extent3d { width: t.accum.width(), height: t.accum.height(), depth_or_array_layers: 1 },
        );
        let targets = [&t.accum_view, &t.accum_display_view];
        draw_fullscreen(encoder, "accumulate", &targets, &self.pipeline, &[inputs], None);
    }
}
