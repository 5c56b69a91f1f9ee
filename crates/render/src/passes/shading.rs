//! Pass 2: spectral shading. Per pixel: fetch the Jakob–Hanika coefficients of the base colour
//! (manual trilinear over the table in a 3D texture), then for each group of four wavelengths
//! evaluate the reflectance, multiply by each light's sampled emission and the BRDF, add
//! emission (illuminant-variant upsampling), call the custom spectral hook and accumulate XYZ
//! with the observer×Δλ weights; finally XYZ → linear RGB into the HDR target.
//!
//! Per wavelength (one lane of a vec4 op each): sigmoid 6 (2 fma polynomial, clamp 2, fma,
//! inverseSqrt, mul, fma — counted as 6 with the clamp's min/max as 2), 2 fma per light, 1 fma
//! to combine, 3 dot-product lanes (≈ 3 fma) for XYZ, plus 1 load of λ, 3 of weights and
//! 1 per light. With one light: ≈ 12 ALU ops and 5 loads per wavelength. The BRDF itself is
//! evaluated once per light per pixel, not per wavelength.

use super::{HDR_FORMAT, SharedLayouts, depth_entry, fullscreen_pass, fullscreen_pipeline, texture_entry};
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
                depth_entry(4),
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
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
        let mut pass = fullscreen_pass(encoder, "shading", target, timestamps);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(1, inputs, &[]);
        pass.set_bind_group(2, spectral, &[]);
        pass.set_bind_group(3, custom, &[]);
        pass.draw(0..3, 0..1);
    }
}
