//! Pass 4: tone mapping (none / Reinhard / ACES fitted; the exposure, ×2^EV, is in the HDR
//! values already, applied as they were written) and sRGB encoding
//! (by the `Rgba8UnormSrgb` target's store). EXR output skips this pass's result and reads the
//! linear HDR target instead.

use super::{
    Draw, FullscreenPipeline, LDR_FORMAT, SharedLayouts, draw_fullscreen, pipeline_layout, texture_entry,
    view_entry,
};
use crate::error::Result;
use crate::shader;

pub struct PostPass {
    pub input_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl PostPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("post inputs"),
            entries: &[texture_entry(0)],
        });
        let module = shader::compile(device, "post", &[shader::COMMON, include_str!("post.wgsl")])?;
        let pipeline = shader::checked(device, "post pipeline", || {
            let layout = pipeline_layout(device, "post", &[&shared.frame, &input_layout]);
            FullscreenPipeline::simple("post", &module, &layout, &[LDR_FORMAT]).build(device)
        })?;
        Ok(PostPass { input_layout, pipeline })
    }

    /// Group 1: the linear HDR image to tone-map.
    pub fn bind_inputs(
        &self,
        device: &wgpu::Device,
        hdr: &wgpu::TextureView,
        label: &str,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &self.input_layout,
            entries: &[view_entry(0, hdr)],
        })
    }

    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, frame: &wgpu::BindGroup, draw: Draw) {
        let groups = [frame, draw.inputs];
        draw_fullscreen(encoder, "post", &[draw.target], &self.pipeline, &groups, draw.timestamps);
    }
}
