//! Pass 3 and the custom-shader extension point.
//!
//! A [`CustomShader`] is WGSL source that defines any of these hooks (each one it leaves out is
//! the identity from `custom_hooks.wgsl`):
//!
//! ```wgsl
//! // Pass 2, every mode, once per pixel before the other pass-2 hooks (ctx.normal set on a
//! // surface): wavelength-independent work the per-group and per-light hooks share:
//! fn custom_prepare(ctx: SurfaceContext)
//! // Pass 2, spectral & naive modes, once per group of four node wavelengths, before
//! // integration; radiance[c] is channel c's (X, Y, Z) weighted node radiance:
//! fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32>
//! // Pass 2, rgb mode, once per pixel:
//! fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32>
//! // Pass 3, every mode, once per pixel on the HDR linear-sRGB colour:
//! fn custom_pixel(hdr: vec4<f32>, ctx: SurfaceContext) -> vec4<f32>
//! // Pass 2, every mode, per light on a lit surface: a factor on the light's direct light:
//! fn custom_light_surface(li: u32, ctx: SurfaceContext) -> f32
//! // Pass 2, irradiance a medium brings to the surface (weighted form; rgb: linear sRGB), as
//! // seen from the camera; reflected with the diffuse lobe and added after the hooks above:
//! fn custom_irradiance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32>
//! fn custom_irradiance_rgb(ctx: SurfaceContext) -> vec3<f32>
//! // Pass 2, a wavelength-dependent factor on light li's direct light at the surface (a
//! // medium's transmittance between the light and the surface): per group of four node
//! // wavelengths in spectral & naive modes, per channel in rgb mode:
//! fn custom_light_transmittance(li: u32, lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32>
//! fn custom_light_transmittance_rgb(li: u32, ctx: SurfaceContext) -> vec3<f32>
//! ```
//!
//! Inputs available to the hooks (see `wgsl/custom_api.wgsl` and `wgsl/spectral.wgsl`):
//! - `ctx: SurfaceContext` — world position, unit normal, unit view direction (camera → pixel;
//!   the camera's forward axis for an orthographic camera), the view ray's `origin` (the camera
//!   position, or its plane's point on the pixel's ray when orthographic) and the distance from
//!   it, `background` flag, pixel coordinates. Background pixels are
//!   shaded too (radiance 0 before the hook), so fog or water can add in-scattered light.
//! - `custom.params` — sixteen floats from [`CustomShader::params`].
//! - `custom_spectra[group * 4 + s]` — spectrum `s` (< 4) of [`CustomShader::spectra`] sampled
//!   at the four wavelengths of `group` (re-sampled by the renderer whenever the wavelengths
//!   change); spectra `s ≥ 4` (tables) at `custom_spectra[s * frame.n_groups + group]`. A
//!   `Spectrum::Constant` fills all four lanes, which is how the RGB hook reads a table.
//! - `wavelengths[group]` — node λ and the white's node weights; `light_w(li, group,
//!   frame.n_groups)` — a light's node weights; `s3_scale`, `s3_xyz` for weighted radiance;
//!   `frame` — matrices, camera, mode, `n_groups`; `gbuf_depth`/`gbuf_normal` in pass 3 (the
//!   normal packed with the roughness and the material's slot: read it with
//!   `gbuffer_normal(textureLoad(gbuf_normal, px, 0))`, or take `ctx.normal`).
//!
//! The pass-2 hooks are compiled into both stages of the shading pass
//! ([`super::shading::ShadingStage`]: a compute pass over the screen on GPUs, a fullscreen
//! triangle's fragments on CPU drivers), so they must be valid in a compute shader: no
//! derivatives (`dpdx`, `fwidth`), no implicitly-levelled `textureSample`, no `discard`.
//!
//! Weighted radiance: the renderer integrates `XYZ = Σ_nodes ρ(λᵢ)·W_{l,i}` with node weights
//! W that carry the light, the observer and the quadrature rule ([`color::quadrature`]). A
//! spectral hook therefore sees, per channel, the node radiance already multiplied by its
//! weight; a smooth wavelength-dependent factor multiplies it node by node, and light added
//! along a ray is a light's weights times a smooth factor. Under the prefiltered rule a light's
//! lines are then integrated exactly even through the hook.
//!
//! Radiance units: the HDR values are linear sRGB where a white diffuse surface under a
//! 1-lux white directional light at normal incidence is 1/π.

use super::{
    Draw, FullscreenPipeline, HDR_FORMAT, SharedGroups, SharedLayouts, depth_entry, draw_fullscreen,
    pipeline_layout, texture_entry, view_entry,
};
use crate::error::{RenderError, Result};
use crate::shader;
use crate::targets::Targets;
use color::Spectrum;

/// Identity hooks.
pub const DEFAULT_HOOKS: &str = include_str!("custom_hooks.wgsl");

/// WGSL shared by the media hooks (`underwater`, `rgb_medium`): the Henyey–Greenstein phase
/// function, the path integral (1 − e^{−k·d})/k and equiangular steps for point lights. Each
/// medium's shader source starts with it.
pub const MEDIUM_COMMON: &str = include_str!("medium_common.wgsl");

/// The hook names, in the order `custom_hooks.wgsl` defines them.
const HOOKS: [&str; 11] = [
    "custom_prepare",
    "custom_spectral",
    "custom_rgb",
    "custom_pixel",
    "custom_light_surface",
    "custom_irradiance",
    "custom_irradiance_rgb",
    "custom_light_transmittance",
    "custom_light_transmittance_rgb",
    "custom_env_transmittance",
    "custom_env_transmittance_rgb",
];

/// User code for the extension point.
#[derive(Clone, Debug, PartialEq)]
pub struct CustomShader {
    /// WGSL defining any of `custom_spectral`, `custom_rgb` and `custom_pixel`.
    pub source: String,
    /// Free parameters, `custom.params[i / 4][i % 4]` in WGSL.
    pub params: [f32; 16],
    /// Up to four spectra the hooks need per wavelength (absorption, scattering, …).
    pub spectra: Vec<Spectrum>,
    /// Values of the source's pipeline-overridable constants (`override NAME: T;`) by name:
    /// fixed per shader, unlike `params`, so the driver compiles untaken branches away.
    pub constants: Vec<(String, f64)>,
}

/// Most spectra a custom shader can ask for: the first four at `custom_spectra[group * 4 + s]`,
/// the rest (tables, e.g. the underwater light field) at `custom_spectra[s * n_groups + group]`.
pub const MAX_CUSTOM_SPECTRA: usize = 32768;

impl Default for CustomShader {
    fn default() -> Self {
        CustomShader { source: String::new(), params: [0.0; 16], spectra: Vec::new(), constants: Vec::new() }
    }
}

impl CustomShader {
    pub fn new(source: impl Into<String>) -> Self {
        CustomShader { source: source.into(), ..Default::default() }
    }

    /// Whether the source defines the hook `name`.
    pub fn defines(&self, name: &str) -> bool {
        defines(&self.source, name)
    }

    /// Whether the shading pass runs its general node loop for these hooks (`CUSTOM_SPECTRAL`:
    /// the spectral hook or a light or environment transmittance is the user's).
    pub fn spectral(&self) -> bool {
        ["custom_spectral", "custom_light_transmittance", "custom_light_transmittance_rgb"]
            .iter()
            .chain(&["custom_env_transmittance", "custom_env_transmittance_rgb"])
            .any(|name| self.defines(name))
    }

    /// The source as the passes compile it: the user's code, the identity definition of each
    /// hook it leaves out, `CUSTOM_SPECTRAL` (whether the spectral hook or the light
    /// transmittance is the user's: the shading loop skips the hook, and carries the specular
    /// term outside the nodes, when neither is), `CUSTOM_LIGHT_T` and `CUSTOM_ENV_T` (whether
    /// the shading loop calls the light- and environment-transmittance hooks).
    pub fn assembled(&self) -> String {
        let mut out = self.source.clone();
        for name in HOOKS {
            if !self.defines(name) {
                out.push('\n');
                out.push_str(default_hook(name));
            }
        }
        // A per-light or environment spectral factor needs the specular term inside the nodes too.
        let transmittance =
            self.defines("custom_light_transmittance") || self.defines("custom_light_transmittance_rgb");
        let env_transmittance =
            self.defines("custom_env_transmittance") || self.defines("custom_env_transmittance_rgb");
        let spectral = self.spectral();
        debug_assert_eq!(spectral, self.defines("custom_spectral") || transmittance || env_transmittance);
        out.push_str(&format!("\nconst CUSTOM_SPECTRAL: bool = {spectral};\n"));
        out.push_str(&format!("const CUSTOM_LIGHT_T: bool = {transmittance};\n"));
        out.push_str(&format!("const CUSTOM_ENV_T: bool = {env_transmittance};\n"));
        // The irradiance hooks come as a pair; either one turns on the diffuse term's code.
        let irradiance = self.irradiance();
        out.push_str(&format!("const CUSTOM_IRRADIANCE: bool = {irradiance};\n"));
        out
    }

    /// Whether the shader defines the irradiance hooks (`CUSTOM_IRRADIANCE`): light from all
    /// sides, which the shading occludes like the environment's.
    pub(crate) fn irradiance(&self) -> bool {
        self.defines("custom_irradiance") || self.defines("custom_irradiance_rgb")
    }

    /// [`Self::constants`] as wgpu takes them.
    pub(crate) fn constant_pairs(&self) -> Vec<(&str, f64)> {
        self.constants.iter().map(|(name, value)| (name.as_str(), *value)).collect()
    }

    pub(crate) fn validate(&self) -> Result<()> {
        if self.spectra.len() > MAX_CUSTOM_SPECTRA {
            return Err(RenderError::CustomShader(format!(
                "{} spectra given, at most {MAX_CUSTOM_SPECTRA} are supported",
                self.spectra.len()
            )));
        }
        Ok(())
    }
}

/// `fn NAME` followed by optional white space and `(`.
fn defines(source: &str, name: &str) -> bool {
    let pat = format!("fn {name}");
    source.match_indices(&pat).any(|(i, _)| source[i + pat.len()..].trim_start().starts_with('('))
}

/// The identity definition of hook `name` from `custom_hooks.wgsl`.
fn default_hook(name: &str) -> &'static str {
    let start = DEFAULT_HOOKS.find(&format!("fn {name}(")).expect("custom_hooks.wgsl defines every hook");
    let len = DEFAULT_HOOKS[start..].find("\n}").expect("hooks end with a closing brace") + 2;
    &DEFAULT_HOOKS[start..start + len]
}

/// `CustomUniforms` in `wgsl/custom_api.wgsl` (checked by `layout_tests`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CustomUniforms {
    pub params: [f32; 16],
    pub n_spectra: u32,
    pub _pad: [u32; 3],
}

pub struct CustomPass {
    pub input_layout: wgpu::BindGroupLayout,
    /// `None` when `custom_pixel` is the identity: the pass is skipped, the shading pass
    /// writing its output target directly ([`Self::skipped`]).
    pipeline: Option<wgpu::RenderPipeline>,
}

impl CustomPass {
    /// Builds the pipeline with `custom` (the hooks) compiled in.
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts, custom: &CustomShader) -> Result<Self> {
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("custom inputs"),
            entries: &[texture_entry(0), super::uint_entry(1), depth_entry(2)],
        });
        if !custom.defines("custom_pixel") {
            return Ok(CustomPass { input_layout, pipeline: None });
        }
        let module = shader::compile(
            device,
            "custom",
            &[
                shader::COMMON,
                shader::SPECTRAL,
                shader::CUSTOM_API,
                &custom.assembled(),
                include_str!("custom.wgsl"),
            ],
        )?;
        let pipeline = shader::checked(device, "custom pipeline", || {
            let layout = pipeline_layout(
                device,
                "custom",
                &[&shared.frame, &input_layout, &shared.spectral, &shared.custom],
            );
            let constants = custom.constant_pairs();
            FullscreenPipeline {
                constants: &constants,
                ..FullscreenPipeline::simple("custom", &module, &layout, &[HDR_FORMAT])
            }
            .build(device)
        })?;
        Ok(CustomPass { input_layout, pipeline: Some(pipeline) })
    }

    /// Whether the pass is the identity and skipped: the shading pass then renders into the
    /// custom pass's output (`Targets::hdr`), and a frame saves a full-screen read and write.
    pub fn skipped(&self) -> bool {
        self.pipeline.is_none()
    }

    /// Group 1: the shading pass's output, the G-buffer normals and the depth.
    pub fn bind_inputs(&self, device: &wgpu::Device, t: &Targets) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("custom inputs"),
            layout: &self.input_layout,
            entries: &[
                view_entry(0, &t.hdr_shaded_view),
                view_entry(1, &t.gbuffer_views[1]),
                view_entry(2, &t.depth_view),
            ],
        })
    }

    /// Records the pass; when it is skipped, only its timestamps (an empty compute pass, so
    /// that the per-pass timings read about zero for it).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, shared: &SharedGroups, draw: Draw) {
        let Some(pipeline) = &self.pipeline else {
            if let Some(t) = draw.timestamps {
                let writes = wgpu::ComputePassTimestampWrites {
                    query_set: t.query_set,
                    beginning_of_pass_write_index: t.beginning_of_pass_write_index,
                    end_of_pass_write_index: t.end_of_pass_write_index,
                };
                encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("custom (identity, skipped)"),
                    timestamp_writes: Some(writes),
                });
            }
            return;
        };
        let groups = [shared.frame, draw.inputs, shared.spectral, shared.custom];
        draw_fullscreen(encoder, "custom", &[draw.target], pipeline, &groups, draw.timestamps);
    }
}
