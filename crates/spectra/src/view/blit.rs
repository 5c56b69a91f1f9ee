//! Puts the renderer's output texture on the window: one full-screen triangle.
//!
//! A texture copy would do if the swap chain accepted `Rgba8UnormSrgb`, but X11/Vulkan surfaces
//! usually offer only BGRA, so the pixels are passed through a shader instead.

/// The blit pipeline for one surface format.
pub struct Blit {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl Blit {
    pub fn new(device: &wgpu::Device, target: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("view blit"),
            source: wgpu::ShaderSource::Wgsl(include_str!("blit.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view blit"),
            entries: &[render::passes::texture_entry(0)],
        });
        let pl = render::passes::pipeline_layout(device, "view blit", &[&layout]);
        let pipeline = render::passes::FullscreenPipeline {
            label: "view blit",
            module: &module,
            layout: &pl,
            vertex: "vs",
            fragment: "fs",
            targets: &[target],
            constants: &[],
        }
        .build(device);
        Blit { pipeline, layout }
    }

    /// Records a pass that clears `target` and draws `source` over it.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::TextureView,
        target: &wgpu::TextureView,
    ) {
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("view blit"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(source),
            }],
        });
        render::passes::draw_fullscreen(
            encoder,
            "view blit",
            &[target],
            &self.pipeline,
            &[&bind_group],
            None,
        );
    }
}
