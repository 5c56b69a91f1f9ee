//! The GPU connection: instance, adapter, device and queue, shared by the renderer and by a
//! window that presents its output.

use crate::error::{NO_ADAPTER_HELP, RenderError, Result};

/// An open GPU device. Create it headless with [`Gpu::headless`], or from parts a windowing
/// layer already made (so the adapter can present to its surface) with [`Gpu::from_adapter`].
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// Features enabled on `device` that the renderer uses when present.
    pub features: wgpu::Features,
}

impl Gpu {
    /// Opens the default adapter without any window system. Honours `WGPU_BACKEND`
    /// (`vulkan`, `gl`, …), `WGPU_ADAPTER_NAME` and `WGPU_POWER_PREF`.
    pub fn headless() -> Result<Self> {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        // GL cannot run the shading pass (see `from_adapter`), so without an explicit
        // WGPU_BACKEND a machine lacking Vulkan gets the install hint, not a GLSL error.
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        descriptor.backends = backends;
        let instance = wgpu::Instance::new(descriptor);
        let adapter =
            pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, None)).map_err(
                |e| RenderError::NoAdapter { backends: format!("{backends:?}"), reason: e.to_string() },
            )?;
        Self::from_adapter(instance, adapter)
    }

    /// Opens a device on `adapter`, enabling the optional features the renderer can use
    /// (timestamp queries, filterable f32 textures).
    pub fn from_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Self> {
        let wanted = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::FLOAT32_FILTERABLE;
        let features = adapter.features() & wanted;
        let info = adapter.get_info();
        if info.backend == wgpu::Backend::Gl {
            // naga cannot translate `textureLoad` on depth textures to GLSL.
            return Err(RenderError::Device {
                adapter: format!("{} (GL)", info.name),
                reason: format!(
                    "the OpenGL backend cannot run spectra's shaders; use Vulkan \
                     (no GPU: apt-get install mesa-vulkan-drivers libvulkan1){}",
                    if std::env::var_os("WGPU_BACKEND").is_some() { ", and unset WGPU_BACKEND" } else { "" }
                ),
            });
        }
        let (device, queue) = pollster::block_on(
            adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("spectra"),
                required_features: features,
                // A coated scene's G-buffer holds 36 bytes a pixel (`passes::COAT_TARGET_BYTES`),
                // past the 32 WebGPU guarantees: ask for what the adapter has.
                required_limits: wgpu::Limits {
                    max_color_attachment_bytes_per_sample: adapter
                        .limits()
                        .max_color_attachment_bytes_per_sample
                        .max(wgpu::Limits::default().max_color_attachment_bytes_per_sample),
                    ..wgpu::Limits::default().using_resolution(adapter.limits())
                },
                ..Default::default()
            }),
        )
        .map_err(|e| RenderError::Device { adapter: info.name.clone(), reason: e.to_string() })?;
        Ok(Gpu { instance, adapter, device, queue, features })
    }

    /// "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)" — for logs and benchmark reports.
    pub fn describe(&self) -> String {
        let i = self.adapter.get_info();
        format!("{} ({:?}, {:?})", i.name, i.backend, i.device_type)
    }

    /// The text shown when no adapter exists; tests print it when they fail for that reason.
    pub fn install_help() -> &'static str {
        NO_ADAPTER_HELP
    }
}

/// A small lookup table (the split-sum table, the LTC table) uploaded as an RGBA16F texture of
/// `layers` layers, `texels` layer major, sampled through a view of dimension `view`.
pub(crate) fn rgba16f_table(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    (width, height, layers): (u32, u32, u32),
    texels: &[[half::f16; 4]],
    view: wgpu::TextureViewDimension,
) -> wgpu::TextureView {
    use wgpu::util::DeviceExt;
    device
        .create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: layers },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(texels),
        )
        .create_view(&wgpu::TextureViewDescriptor { dimension: Some(view), ..Default::default() })
}
