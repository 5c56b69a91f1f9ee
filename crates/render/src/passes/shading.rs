//! Pass 2: spectral shading. Per pixel: fetch the Jakob–Hanika coefficients of the base colour
//! (manual trilinear over the table in a 3D texture), then for each group of four wavelengths
//! evaluate the reflectance, multiply by each light's sampled emission and the BRDF, add
//! emission (illuminant-variant upsampling), call the custom spectral hook and accumulate XYZ
//! with the observer×Δλ weights; finally XYZ → linear RGB into the HDR target.
//!
//! Per wavelength (one lane of the vec4 ops), for a pixel lit by L lights:
//! - sigmoid: 2 fma (polynomial) + clamp (max, min) + fma (1 + x²) + inverseSqrt + mul + fma = 7;
//! - lights: 2 fma per light (ρ-weighted and ρ-independent accumulators);
//! - combine: 1 fma; XYZ: 3 dot-product lanes (≈ 3 mul-adds);
//! - loads: λ, 3 weights and 1 emission value per light (storage buffers, shared by all pixels).
//!
//! So 11 + 2L ALU ops and 4 + L loads per wavelength (13 and 5 with one light); emissive pixels
//! add a second sigmoid (+9). The coefficient fetch (8 texel loads, trilinear, binary search over
//! the z axis), the BRDF and the shadow lookup (once per light: one hardware 2×2 comparison
//! sample in that light's layer of the shadow-map array) are per pixel, not per wavelength.

use super::{
    HDR_FORMAT, SharedLayouts, depth_entry, draw_fullscreen, fullscreen_pipeline, texture_entry,
    uniform_entry,
};
use crate::error::Result;
use crate::shader;

pub struct ShadingPass {
    pub input_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl ShadingPass {
    /// Builds the pipeline with `custom_source` (the custom hooks) compiled in.
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts, custom_source: &str) -> Result<Self> {
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shading inputs"),
            entries: &[
                texture_entry(0),
                texture_entry(1),
                texture_entry(2),
                depth_entry(3),
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
                uniform_entry(6, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let module = shader::compile(
            device,
            "shading",
            &[
                shader::COMMON,
                shader::SPECTRAL,
                shader::CUSTOM_API,
                custom_source,
                include_str!("shading.wgsl"),
            ],
        )?;
        let pipeline = shader::checked(device, "shading pipeline", || {
            fullscreen_pipeline(
                device,
                "shading",
                &module,
                &[Some(&shared.frame), Some(&input_layout), Some(&shared.spectral), Some(&shared.custom)],
                HDR_FORMAT,
            )
        })?;
        Ok(ShadingPass { input_layout, pipeline })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
        inputs: &wgpu::BindGroup,
        spectral: &wgpu::BindGroup,
        custom: &wgpu::BindGroup,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        draw_fullscreen(
            encoder,
            "shading",
            target,
            &self.pipeline,
            &[frame, inputs, spectral, custom],
            timestamps,
        );
    }
}
