//! Pass 2: spectral shading. Per pixel: fetch the Jakob–Hanika coefficients of the base colour
//! (manual trilinear over the table in a 3D texture) and each light's two BRDF factors (A for
//! the reflectance-weighted part, B for the specular part that carries the light's colour);
//! then for each group of four node wavelengths evaluate the reflectance ρ and accumulate
//! `XYZ += ρ · Σ_l A_l·W_l` with the lights' node weights W (which hold emission, observer and
//! quadrature rule, `color::quadrature`); the B part is each light's XYZ once per pixel; add
//! emission (illuminant-variant upsampling, the white's node weights); finally XYZ → linear RGB.
//!
//! Per node wavelength (one lane of the vec4 ops), for a pixel lit by L lights, without a
//! spectral hook:
//! - sigmoid: 2 fma (polynomial) + clamp (max, min) + fma (1 + x²) + inverseSqrt + mul + fma = 7;
//! - lights: 3 fma per light (the X, Y, Z columns of its weights);
//! - XYZ: 3 mul-adds (ρ · accumulated weights);
//! - loads: λ and 3 weights per light (storage buffers, shared by all pixels).
//!
//! So 10 + 3L ALU ops and 1 + 3L loads per node (13 and 4 with one light), against the paper's
//! midpoint layout before it (11 + 2L ops, 4 + L loads: 13 and 5 with one light): the same
//! with one light, one fma and two loads more per extra light, whichever rule made the
//! weights. With a spectral hook (under water) the B part goes through the nodes too (+3 fma
//! per light) so that the hook can attenuate it. Emissive pixels add a second sigmoid and 3
//! mul-adds. The coefficient fetch (8 texel loads, trilinear, binary search over the z axis),
//! the BRDF and the shadow lookup (once per light) are per pixel, not per node. RGB mode skips
//! all of it: one pass over the lights, no per-light arrays.

use super::{
    HDR_FORMAT, SharedLayouts, depth_entry, draw_fullscreen, fullscreen_pipeline_entry, texture_entry,
    uniform_entry,
};
use crate::error::Result;
use crate::shader;

pub struct ShadingPass {
    pub input_layout: wgpu::BindGroupLayout,
    /// Spectral and naive modes (`fs_main`).
    pipeline: wgpu::RenderPipeline,
    /// RGB mode (`fs_rgb`): its own entry point, so that the JIT-compiled RGB shader carries
    /// none of the spectral path's per-light arrays and loops (a CPU driver paid for them even
    /// when a uniform branch skipped them).
    rgb_pipeline: wgpu::RenderPipeline,
}

impl ShadingPass {
    /// Builds the pipeline with `custom_source` (the custom hooks) compiled in.
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts, custom_source: &str) -> Result<Self> {
        Self::build(
            device,
            shared,
            &[
                shader::COMMON,
                shader::SPECTRAL,
                shader::ENVIRONMENT,
                shader::CUSTOM_API,
                custom_source,
                include_str!("shading.wgsl"),
            ],
            "fs_rgb",
        )
    }

    /// The benchmark's minimal single-light RGB shader (`shading_reference.wgsl`) with the same
    /// inputs, to time in place of the real pass ([`crate::Renderer::set_reference_shading`]).
    pub fn reference(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        Self::build(
            device,
            shared,
            &[shader::COMMON, shader::SPECTRAL, include_str!("shading_reference.wgsl")],
            "fs_main",
        )
    }

    fn build(
        device: &wgpu::Device,
        shared: &SharedLayouts,
        sources: &[&str],
        rgb_entry: &str,
    ) -> Result<Self> {
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
        let module = shader::compile(device, "shading", sources)?;
        let layouts =
            [Some(&shared.frame), Some(&input_layout), Some(&shared.spectral), Some(&shared.custom)];
        let pipeline = shader::checked(device, "shading pipeline", || {
            fullscreen_pipeline_entry(device, "shading", &module, &layouts, HDR_FORMAT, "fs_main")
        })?;
        let rgb_pipeline = shader::checked(device, "shading pipeline (rgb)", || {
            fullscreen_pipeline_entry(device, "shading rgb", &module, &layouts, HDR_FORMAT, rgb_entry)
        })?;
        Ok(ShadingPass { input_layout, pipeline, rgb_pipeline })
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
        rgb: bool,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        draw_fullscreen(
            encoder,
            "shading",
            target,
            if rgb { &self.rgb_pipeline } else { &self.pipeline },
            &[frame, inputs, spectral, custom],
            timestamps,
        );
    }
}
