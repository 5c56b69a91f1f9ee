//! The Jakob–Hanika coefficient table on the GPU: one `rgba32float` 3D texture of
//! res × res × 3·res texels (x = i, y = j, z = l·res + k; rgb = c0, c1, c2) and a storage
//! buffer with the table's axes and the chroma weight's constants ([`GpuCoeffTable::axes`]).
//!
//! The shader interpolates by hand with `textureLoad` (8 loads, once per pixel): exact in
//! f32 and identical to the CPU `CoeffTable::fetch`, and independent of
//! `FLOAT32_FILTERABLE`, which hardware-filtered lookups would need.

use color::upsample::CoeffTable;
use wgpu::util::DeviceExt;

pub struct GpuCoeffTable {
    pub res: u32,
    pub view: wgpu::TextureView,
    /// `coeff_scale` in WGSL, from [`GpuCoeffTable::axes`].
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
            label: Some("coefficient table axes"),
            contents: bytemuck::cast_slice(&Self::axes(table)),
            usage: wgpu::BufferUsages::STORAGE,
        });
        GpuCoeffTable { res: res as u32, view: texture.create_view(&Default::default()), scale }
    }

    /// What the shader's `coeff_scale` holds: the brightness levels (`res`), the chroma nodes
    /// (`res`), the chroma weight's [`CHROMA_WARP`] and [`CHROMA_WARP_SLOPE`], then each axis's
    /// interval index ([`interval_index`], [`AXIS_INDEX`] entries: brightness, then chroma),
    /// then the sheen's albedo table (`scene::sheen::AlbedoTable`, μ fastest), so
    /// the WGSL fetch takes the table's grids and the weight's constants from the CPU side and
    /// cannot drift from `CoeffTable::fetch`.
    ///
    /// [`CHROMA_WARP`]: color::upsample::table::CHROMA_WARP
    /// [`CHROMA_WARP_SLOPE`]: color::upsample::table::CHROMA_WARP_SLOPE
    pub fn axes(table: &CoeffTable) -> Vec<f32> {
        use color::upsample::table::{CHROMA_WARP, CHROMA_WARP_SLOPE};
        let mut v = table.scale.clone();
        v.extend_from_slice(&table.chroma);
        v.extend_from_slice(&[CHROMA_WARP, CHROMA_WARP_SLOPE]);
        v.extend(interval_index(&table.scale).into_iter().map(|i| i as f32));
        v.extend(interval_index(&table.chroma).into_iter().map(|i| i as f32));
        // Last, `KHR_materials_sheen`'s directional-albedo table (wgsl/sheen.wgsl
        // `sheen_albedo`, found from the end), so that both renderers read scene::sheen's values.
        v.extend(scene::sheen::albedo_table().values_f32());
        v
    }
}

/// Entries of an axis's interval index (`AXIS_INDEX` in wgsl/spectral.wgsl; a power of two, so
/// that `floor(v · AXIS_INDEX) / AXIS_INDEX` is exact and never above `v`).
pub const AXIS_INDEX: usize = 1024;

/// Entry m: the interval of `axis` (increasing, at least 2 nodes) that holds m / [`AXIS_INDEX`],
/// as the fetch numbers intervals (the largest n with `axis[n] <= t`, within 0 ..= len − 2). The
/// shader starts there and steps up while the next node is still at or below its value, which
/// reaches the binary search's interval in at most the nodes inside one entry's width (one on
/// spectra's grids at 64³; a few next to black on rgb2spec's double smoothstep) instead of
/// log₂(res) dependent loads.
pub fn interval_index(axis: &[f32]) -> Vec<u32> {
    let last = axis.len().saturating_sub(2);
    (0..AXIS_INDEX)
        .map(|m| {
            let t = m as f32 / AXIS_INDEX as f32;
            (axis.partition_point(|&a| a <= t).max(1) - 1).min(last) as u32
        })
        .collect()
}

/// The interval the shader finds for `v` from the index: [`interval_index`]'s entry, then the
/// steps up (the CPU mirror of `find_interval` in wgsl/spectral.wgsl, for the tests).
pub fn indexed_interval(axis: &[f32], index: &[u32], v: f32) -> usize {
    let vv = if v > 0.0 { v.min(1.0) } else { 0.0 };
    let mut i = index[((vv * AXIS_INDEX as f32) as usize).min(AXIS_INDEX - 1)] as usize;
    while i < axis.len() - 2 && axis[i + 1] <= v {
        i += 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The indexed search finds the binary search's interval (the largest node at or below the
    /// value, clamped to the last interval) on spectra's grids and rgb2spec's, at every node, on
    /// both sides of it, and between, including values outside [0, 1] and NaN.
    #[test]
    fn indexed_interval_equals_the_binary_search() {
        use color::upsample::fit::{rgb2spec_scale, spectra_chroma, spectra_scale, uniform_chroma};
        let res = 64;
        for axis in [spectra_scale(res), spectra_chroma(res), rgb2spec_scale(res), uniform_chroma(res)] {
            let axis: Vec<f32> = axis.iter().map(|&a| a as f32).collect();
            let index = interval_index(&axis);
            let binary = |v: f32| axis.partition_point(|&a| a <= v).clamp(1, res - 1) - 1;
            let mut values = vec![-1.0, 0.0, 1.0, 2.0, f32::NAN, f32::MIN_POSITIVE, 1e-9];
            for &a in &axis {
                values.extend([a, a.next_up(), a.next_down(), a * 1.0001 + 1e-7]);
            }
            values.extend((0..=20_000).map(|i| i as f32 / 20_000.0));
            for v in values {
                let want = if v.is_nan() { 0 } else { binary(v) };
                assert_eq!(indexed_interval(&axis, &index, v), want, "v = {v}");
            }
        }
    }
    use crate::gpu::Gpu;
    use color::upsample::adversarial::{AdversarialOptions, adversarial_set};
    use color::upsample::fit::{LabModel, nm_to_normalised};

    /// The WGSL `fetch_coeffs` (f32, textureLoad) against the CPU `CoeffTable::fetch` on the
    /// adversarial set of the sRGB table: corners, edges, faces, greys down to 10⁻⁶, the 3 %
    /// next to black and white, and the worst colours the search finds. The brightness weight
    /// is σ⁻¹-space in both; a mismatch in it would show at the dark greys first.
    #[test]
    fn gpu_fetch_matches_cpu_on_the_adversarial_set() {
        let table = color::upsample::table("srgb").expect("the sRGB table");
        let space = color::RgbColorSpace::srgb();
        let colours: Vec<[f32; 4]> = adversarial_set(&table, &space, &AdversarialOptions::default())
            .unwrap()
            .into_iter()
            .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32, 0.0])
            .collect();
        let gpu = Gpu::headless().unwrap_or_else(|e| panic!("{e}\n{}", Gpu::install_help()));
        let (device, queue) = (&gpu.device, &gpu.queue);
        let coeff = GpuCoeffTable::upload(device, queue, &table);
        let src = format!(
            "{}\n{}\n@group(2) @binding(10) var<storage, read> rgb_in: array<vec4<f32>>;\n\
             @group(2) @binding(11) var<storage, read_write> c_out: array<vec4<f32>>;\n\
             @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
             if (id.x >= arrayLength(&rgb_in)) {{ return; }}\n\
             c_out[id.x] = vec4<f32>(fetch_coeffs(rgb_in[id.x].xyz, {}u), 0.0);\n}}\n",
            crate::shader::COMMON,
            crate::shader::SPECTRAL,
            table.res
        );
        let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&colours),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let bytes = crate::compute_tests::run(
            device,
            queue,
            src,
            colours.len(),
            (colours.len() * 16) as u64,
            |p, output| {
                let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: None,
                    layout: &p.get_bind_group_layout(2),
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: wgpu::BindingResource::TextureView(&coeff.view),
                        },
                        wgpu::BindGroupEntry { binding: 4, resource: coeff.scale.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 10, resource: input.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 11, resource: output.as_entire_binding() },
                    ],
                });
                let empty = |g: u32| {
                    device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: None,
                        layout: &p.get_bind_group_layout(g),
                        entries: &[],
                    })
                };
                vec![empty(0), empty(1), bind]
            },
        );
        let out: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        let model = LabModel::new(&space).unwrap();
        let mut worst = (0.0f64, [0.0f32; 4]);
        for (rgb, g) in colours.iter().zip(&out) {
            let cpu = table.fetch([rgb[0] as f64, rgb[1] as f64, rgb[2] as f64]).c;
            let gpu = [g[0] as f64, g[1] as f64, g[2] as f64];
            let lab = |c: [f64; 3]| model.lab_of_xyz(model.xyz(nm_to_normalised(c)));
            let de = color::ciede2000(lab(cpu), lab(gpu));
            if de > worst.0 {
                worst = (de, *rgb);
            }
        }
        assert!(worst.0 <= 1e-3, "GPU vs CPU fetch: ΔE2000 {} at RGB {:?}", worst.0, worst.1);
    }
}
