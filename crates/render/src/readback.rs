//! Headless readback of textures and buffers.

use crate::error::{RenderError, Result};

/// Waits for the GPU to finish all submitted work, in slices short enough that Ctrl-C
/// ([`color::cancel`]) is seen within a fraction of a second even when one frame takes tens of
/// seconds (a 4096² frame on a software rasteriser); then returns [`RenderError::Cancelled`].
pub fn wait(device: &wgpu::Device) -> Result<()> {
    loop {
        if color::cancel::is_cancelled() {
            return Err(RenderError::Cancelled);
        }
        let slice = wgpu::PollType::Wait {
            submission_index: None,
            timeout: Some(std::time::Duration::from_millis(50)),
        };
        match device.poll(slice) {
            Ok(_) => return Ok(()),
            Err(wgpu::PollError::Timeout) => continue,
            Err(e) => return Err(RenderError::Readback(e.to_string())),
        }
    }
}

/// Maps `buffer` for reading, waits, and hands its bytes to `f`.
pub(crate) fn map_buffer<T>(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    f: impl FnOnce(&[u8]) -> T,
) -> Result<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    wait(device)?;
    rx.recv()
        .map_err(|e| RenderError::Readback(e.to_string()))?
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    let value = {
        let view = buffer.get_mapped_range(..).map_err(|e| RenderError::Readback(e.to_string()))?;
        f(&view)
    };
    buffer.unmap();
    Ok(value)
}

/// Bytes of one read-back slice: a band of whole rows at most this large is copied and mapped
/// at a time, so an image larger than the device's `max_buffer_size` (6000² RGBA f16 is 288 MB,
/// lavapipe's limit 256 MiB) is read in several bands, and memory stays bounded besides the
/// output itself.
pub(crate) const READBACK_BAND_BYTES: u64 = 64 << 20;

/// Copies a whole 2D texture with `bytes_per_pixel` into tightly packed rows, in bands of rows
/// no larger than [`READBACK_BAND_BYTES`] and the device's buffer limit.
pub(crate) fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_pixel: u32,
) -> Result<Vec<u8>> {
    read_texture_banded(device, queue, texture, bytes_per_pixel, READBACK_BAND_BYTES)
}

pub(crate) fn read_texture_banded(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_pixel: u32,
    band_bytes: u64,
) -> Result<Vec<u8>> {
    let (w, h) = (texture.width(), texture.height());
    let row = w as u64 * bytes_per_pixel as u64;
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;
    let padded = row.div_ceil(align) * align;
    let limit = band_bytes.min(device.limits().max_buffer_size);
    let band_rows = (limit / padded).clamp(1, h as u64) as u32;
    let mut out = Vec::with_capacity((row * h as u64) as usize);
    let mut y0 = 0;
    while y0 < h {
        // lavapipe's vkQueueSubmit blocks until the frame in flight is done: wait for it here,
        // where Ctrl-C is seen, not inside the submit, where it is not.
        wait(device)?;
        let rows = band_rows.min(h - y0);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: padded * rows as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: y0, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d { width: w, height: rows, depth_or_array_layers: 1 },
        );
        queue.submit([encoder.finish()]);
        map_buffer(device, &buffer, |bytes| {
            for y in 0..rows as usize {
                let start = y * padded as usize;
                out.extend_from_slice(&bytes[start..start + row as usize]);
            }
        })?;
        y0 += rows;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image read in bands of one row (as one larger than the device's buffer limit is)
    /// comes back identical to one read whole.
    #[test]
    fn banded_readback_is_exact() {
        let gpu = crate::Gpu::headless().unwrap_or_else(|e| panic!("{e}\n{}", crate::Gpu::install_help()));
        let (w, h) = (67u32, 13u32);
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("banded readback test"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let data: Vec<u8> = (0..w * h * 4).map(|i| (i * 7 % 251) as u8).collect();
        gpu.queue.write_texture(
            texture.as_image_copy(),
            &data,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(w * 4), rows_per_image: Some(h) },
            texture.size(),
        );
        let whole = read_texture(&gpu.device, &gpu.queue, &texture, 4).unwrap();
        let banded = read_texture_banded(&gpu.device, &gpu.queue, &texture, 4, 1).unwrap();
        let fives = read_texture_banded(&gpu.device, &gpu.queue, &texture, 4, 5 * 512).unwrap();
        assert_eq!(whole, data);
        assert_eq!(banded, data);
        assert_eq!(fives, data);
    }
}
