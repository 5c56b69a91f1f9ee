//! The environment's GPU resources: prefiltered coefficient maps (one set per coefficient
//! space: RGB for the rgb and naive modes, the PCA basis for spectral), the split-sum table, a
//! sampler and the per-frame uniforms. See [`crate::environment`] for what the maps hold.

use crate::environment::{self, EnvMaps, LUT_SIZE, Map, SpectralBasis};
use color::upsample::CoeffTable;
use glam::Vec4;
use half::f16;
use wgpu::util::DeviceExt;

/// Per-frame environment parameters. `EnvUniforms` in `wgsl/environment.wgsl` (checked by
/// `layout_tests`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct EnvUniforms {
    /// XYZ of each basis spectrum seen by a reflectance of one (Σ of its node weights); the
    /// spectral and naive modes' background and specular. w unused.
    pub totals: [[f32; 4]; 4],
    /// Rotation about +Y (radians), the coarsest mip level's index, intensity, and the world
    /// radius of the screen-space occlusion search (0 = off).
    pub params: [f32; 4],
    /// x: 1 when there is an environment; y: 1 when it is drawn as the background.
    pub flags: [u32; 4],
}

/// The textures of one coefficient space.
pub struct EnvTextures {
    pub radiance: wgpu::TextureView,
    pub irradiance: wgpu::TextureView,
    pub max_lod: f32,
    /// What the textures' values are multiplied by to give the coefficients (a power of two, 1
    /// for every map whose values fit; see [`texture_scale`]).
    pub scale: f32,
}

/// The largest magnitude the half-float maps hold: a quarter of f16's largest finite value
/// (65504), so that nothing the sampler mixes from them overflows.
pub const F16_SAFE: f32 = 16384.0;

/// The power of two by which the maps' values are divided before they are stored as f16, so that
/// none exceeds [`F16_SAFE`]: outdoor HDRIs with an unclipped sun reach 10⁴–10⁵ per texel, and a
/// spectral coefficient or an irradiance is larger still (π·L, the basis' normalisation), where
/// f16 would hold ∞ (and ∞·0 = NaN in the shader). A power of two divides exactly, so a map
/// that fits (scale 1) is stored bit for bit as before, and the f16's relative precision is the
/// same at any scale; what it loses is texels below 2⁻¹⁴·scale, ~10⁻⁹ of the brightest, whose
/// precision degrades (kept in f32 instead where that matters: [`loses_darks`]).
pub fn texture_scale(maps: &EnvMaps) -> f32 {
    let max = maps
        .radiance
        .iter()
        .chain(std::iter::once(&maps.irradiance))
        .flat_map(|m| m.texels.iter())
        .map(|t| t.abs().max_element())
        .fold(0.0f32, f32::max);
    if max <= F16_SAFE {
        return 1.0;
    }
    // Finite for any map of finite texels (scene::environment::MAX_RADIANCE keeps the sums so).
    let k = (max.min(f32::MAX) / F16_SAFE).log2().ceil();
    let scale = k.exp2();
    if max / scale > F16_SAFE { scale * 2.0 } else { scale }
}

/// An environment on the GPU (or the black stand-in when the scene has none).
pub struct GpuEnvironment {
    /// The scene's environment (intensity and rotation are read every frame).
    pub source: Option<scene::Environment>,
    rgb_map: Option<Map>,
    pub rgb: EnvTextures,
    /// Built on first use in spectral mode.
    pub spectral: Option<(SpectralBasis, EnvTextures)>,
    pub lut: wgpu::TextureView,
    pub sampler: wgpu::Sampler,
}

/// Whether a map that needed [`texture_scale`] (a very bright sun) would lose texels that are
/// not negligible to half-float: any texel whose largest component, divided by the scale,
/// falls below f16's smallest normal number (2⁻¹⁴), where its relative precision degrades and,
/// under 2⁻²⁵, it becomes zero. Measured: a 0.5 sky beside one 10¹² texel was drawn black.
pub fn loses_darks(maps: &EnvMaps, scale: f32) -> bool {
    let floor = scale * 2f32.powi(-14);
    scale > 1.0
        && maps.radiance.iter().chain(std::iter::once(&maps.irradiance)).flat_map(|m| m.texels.iter()).any(
            |t| {
                let v = t.abs().max_element();
                v > 0.0 && v < floor
            },
        )
}

fn upload_map(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    levels: &[Map],
    scale: f32,
    format: wgpu::TextureFormat,
) -> wgpu::TextureView {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: levels[0].width, height: levels[0].height, depth_or_array_layers: 1 },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let wide = format == wgpu::TextureFormat::Rgba32Float;
    for (mip, level) in levels.iter().enumerate() {
        let data: Vec<u8> = if wide {
            bytemuck::cast_slice(&level.texels.iter().map(|t| (*t / scale).to_array()).collect::<Vec<_>>())
                .to_vec()
        } else {
            let half: Vec<[f16; 4]> =
                level.texels.iter().map(|t| (*t / scale).to_array().map(f16::from_f32)).collect();
            bytemuck::cast_slice(&half).to_vec()
        };
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: mip as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(if wide { 16 } else { 8 } * level.width),
                rows_per_image: Some(level.height),
            },
            wgpu::Extent3d { width: level.width, height: level.height, depth_or_array_layers: 1 },
        );
    }
    texture.create_view(&Default::default())
}

fn upload_maps(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, maps: &EnvMaps) -> EnvTextures {
    let scale = texture_scale(maps);
    // A map whose range half-float cannot hold (a sun 10⁹ times its sky) is stored in f32 where
    // the device filters it; every other map stays f16, as before, at half the bandwidth.
    let (scale, format) =
        if loses_darks(maps, scale) && device.features().contains(wgpu::Features::FLOAT32_FILTERABLE) {
            (1.0, wgpu::TextureFormat::Rgba32Float)
        } else {
            (scale, wgpu::TextureFormat::Rgba16Float)
        };
    EnvTextures {
        radiance: upload_map(device, queue, &format!("{label} radiance"), &maps.radiance, scale, format),
        irradiance: upload_map(
            device,
            queue,
            &format!("{label} irradiance"),
            std::slice::from_ref(&maps.irradiance),
            scale,
            format,
        ),
        max_lod: (maps.radiance.len() - 1) as f32,
        scale,
    }
}

impl GpuEnvironment {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, env: Option<&scene::Environment>) -> Self {
        let black = Map { width: 2, height: 1, texels: vec![Vec4::ZERO; 2] };
        let (rgb_map, maps) = match env {
            Some(e) => {
                let m = environment::rgb_map(e);
                let maps = environment::prefilter(&m);
                (Some(m), maps)
            }
            None => (None, EnvMaps { radiance: vec![black.clone()], irradiance: black }),
        };
        let rgb = upload_maps(device, queue, "environment (rgb)", &maps);
        let lut: Vec<[f16; 4]> = environment::brdf_lut()
            .into_iter()
            .map(|ab| [f16::from_f32(ab[0]), f16::from_f32(ab[1]), f16::ZERO, f16::ZERO])
            .collect();
        let lut = crate::gpu::rgba16f_table(
            device,
            queue,
            "split-sum table",
            (LUT_SIZE, LUT_SIZE, 1),
            &lut,
            wgpu::TextureViewDimension::D2,
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        GpuEnvironment { source: env.cloned(), rgb_map, rgb, spectral: None, lut, sampler }
    }

    /// Builds the spectral maps if the scene has an environment and they are not built yet.
    pub fn ensure_spectral(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, table: &CoeffTable) {
        if self.spectral.is_some() {
            return;
        }
        let Some(m) = &self.rgb_map else { return };
        let (basis, coeffs) = environment::spectral_basis(m, table);
        let maps = environment::prefilter(&coeffs);
        self.spectral = Some((basis, upload_maps(device, queue, "environment (spectral)", &maps)));
    }

    /// The frame's uniforms for `totals` (XYZ per basis spectrum) and an occlusion search radius
    /// in world units (0 = no screen-space occlusion).
    pub fn uniforms(&self, totals: [[f32; 4]; 4], spectral: bool, occlusion_radius: f32) -> EnvUniforms {
        // Without an environment the radius still serves the other ambient term, a medium's
        // diffuse irradiance (the underwater hook), which the same horizons occlude.
        let Some(env) = &self.source else {
            return EnvUniforms { params: [0.0, 0.0, 0.0, occlusion_radius], ..EnvUniforms::default() };
        };
        let t = self.textures(spectral);
        EnvUniforms {
            totals,
            // The maps' scale rides on the intensity: the shader multiplies every sample by it.
            params: [env.rotation, t.max_lod, env.intensity * t.scale, occlusion_radius],
            flags: [1, 1, 0, 0],
        }
    }

    /// How many of the spectral basis' components the coefficient maps use
    /// ([`SpectralBasis::used`]); all K before the basis is built.
    pub fn spectral_bases(&self) -> usize {
        self.spectral.as_ref().map_or(environment::K, |(b, _)| b.used)
    }

    /// The textures for `spectral` (PCA basis) or RGB coefficients.
    pub fn textures(&self, spectral: bool) -> &EnvTextures {
        match (&self.spectral, spectral) {
            (Some((_, t)), true) => t,
            _ => &self.rgb,
        }
    }

    pub fn storage(device: &wgpu::Device, weights: &[crate::spectral_data::GroupWeights]) -> wgpu::Buffer {
        let fallback = [[[0f32; 4]; 3]];
        let w = if weights.is_empty() { &fallback[..] } else { weights };
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment basis weights"),
            contents: bytemuck::cast_slice(w),
            usage: wgpu::BufferUsages::STORAGE,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn maps(max: f32) -> EnvMaps {
        let m = |v: f32| Map { width: 2, height: 1, texels: vec![Vec4::new(0.5, -v, 0.0, 1.0), Vec4::ONE] };
        EnvMaps { radiance: vec![m(max), m(max / 2.0)], irradiance: m(1.0) }
    }

    /// Maps that fit are stored as before (scale 1); brighter ones are divided by the smallest
    /// power of two that brings every value, negative coefficients included, within F16_SAFE.
    #[test]
    fn texture_scale_is_the_smallest_power_of_two_that_fits() {
        for (max, want) in
            [(1.0, 1.0), (F16_SAFE, 1.0), (F16_SAFE * 1.0001, 2.0), (1e5, 8.0), (1e15 * 50.0, 2f32.powi(42))]
        {
            let s = texture_scale(&maps(max));
            assert_eq!(s, want, "max {max}");
            assert!(max / s <= F16_SAFE && (max / s > F16_SAFE / 2.0 || s == 1.0), "max {max}: scale {s}");
            assert!(f16::from_f32(max / s).is_finite());
        }
    }
}
