//! Pass 4: exposure (×2^EV), tone mapping (none / Reinhard / ACES fitted) and sRGB encoding
//! (by the `Rgba8UnormSrgb` target's store). EXR output skips this pass's result and reads the
//! linear HDR target instead.

use super::{LDR_FORMAT, SharedLayouts, draw_fullscreen, fullscreen_pipeline, texture_entry};
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
            fullscreen_pipeline(
                device,
                "post",
                &module,
                &[Some(&shared.frame), Some(&input_layout)],
                LDR_FORMAT,
            )
        })?;
        Ok(PostPass { input_layout, pipeline })
    }

    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
        inputs: &wgpu::BindGroup,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        draw_fullscreen(encoder, "post", target, &self.pipeline, &[frame, inputs], timestamps);
    }
}
