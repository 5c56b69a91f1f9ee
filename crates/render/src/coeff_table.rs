//! The Jakob–Hanika coefficient table on the GPU: one `rgba32float` 3D texture of
//! res × res × 3·res texels (x = i, y = j, z = l·res + k; rgb = c0, c1, c2) and a storage
//! buffer with the table's non-uniform z axis.
//!
//! The shader interpolates by hand with `textureLoad` (8 loads, once per pixel): exact in
//! f32 and identical to the CPU `CoeffTable::fetch`, and independent of
//! `FLOAT32_FILTERABLE`, which hardware-filtered lookups would need.

use color::upsample::CoeffTable;
use wgpu::util::DeviceExt;

pub struct GpuCoeffTable {
    pub res: u32,
    pub view: wgpu::TextureView,
    pub scale: wgpu::Buffer,
}

impl GpuCoeffTable {
    pub fn upload(device: &wgpu::Device, queue: &wgpu::Queue, table: &CoeffTable) -> Self {
        let res = table.res;
        let texels: Vec<[f32; 4]> = table.data.chunks_exact(3).map(|c| [c[0], c[1], c[2], 0.0]).collect();
        debug_assert_eq!(texels.len(), 3 * res * res * res);
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("jakob-hanika coefficients"),
                size: wgpu::Extent3d {
                    width: res as u32,
                    height: res as u32,
                    depth_or_array_layers: 3 * res as u32,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: wgpu::TextureFormat::Rgba32Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&texels),
        );
        let scale = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("coefficient scale"),
            contents: bytemuck::cast_slice(&table.scale),
            usage: wgpu::BufferUsages::STORAGE,
        });
        GpuCoeffTable { res: res as u32, view: texture.create_view(&Default::default()), scale }
    }
}
