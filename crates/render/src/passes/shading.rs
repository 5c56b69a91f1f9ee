//! Pass 2: spectral shading. Per pixel: the Jakob–Hanika coefficients of the base colour and
//! the emission — the material's, fetched once on the CPU (`crate::material_spectra`, found
//! through the G-buffer's material slot) where the colour is constant over the
//! material, else fetched per pixel (manual trilinear over the table in a 3D texture, the axes'
//! intervals from an index, both colours through one call site); then, lights outermost, each
//! light's two BRDF factors (A for the reflectance-weighted part, B for the specular part that
//! carries the light's colour) and `XYZ += A · Σ_g ρ_g · W_g + B · XYZ_light` over the groups of
//! four node wavelengths, with the light's node weights W (which hold its emission, the
//! observer and the quadrature rule, `color::quadrature`); then one pass over the nodes for the
//! environment and a varying emission (a constant one is its XYZ, from the CPU); finally
//! XYZ → linear RGB. Nothing is kept per light, so the pass has no private arrays. Where the
//! base colour is the material's constant one, `Σ_g ρ_g · W_g` of every light and of the
//! environment's basis spectra are read, summed once on the CPU
//! (`crate::material_spectra::reflected_xyz`), and no node loop runs for that pixel.
//!
//! Per node wavelength (one lane of the vec4 ops), for a pixel lit by L lights, without a
//! spectral hook:
//! - sigmoid: 2 fma (polynomial) + clamp (max, min) + fma (1 + x²) + inverseSqrt + mul + fma = 7,
//!   once per light (the reflectance is evaluated where it is used instead of being stored);
//! - lights: 3 fma per light (the X, Y, Z columns of its weights);
//! - loads: λ and 3 weights per light (storage buffers, shared by all pixels).
//!
//! So 10L ALU ops and 4L loads per node. A spectral hook (under water) or the spectral capture
//! needs each node's whole radiance, so that pipeline keeps groups outermost with each light's
//! factors in an array (`shade_nodes`), and the B part goes through the nodes too (+3 fma per
//! light). The fetch (8 texel loads), the BRDF and the shadow lookup (once per light) are per
//! pixel, not per node. RGB mode skips all of it: one pass over the lights.
//!
//! What a frame does not use is not compiled in ([`Variant`]): a CPU driver runs every branch's
//! code, taken or not, and a loop's body at least once (measured: a fetch behind a branch that
//! no pixel takes cost the Cornell box's spectral pass as much as a fetch for every pixel).

use super::custom::CustomShader;
use super::shadow::ShadowPass;
use super::{
    Draw, FullscreenPipeline, HDR_FORMAT, READERS, ScreenPipeline, SharedGroups, SharedLayouts, buffer_entry,
    depth_entry, texture_entry, uniform_entry, view_entry,
};
use crate::error::Result;
use crate::shader;
use crate::targets::Targets;
use std::collections::HashMap;

/// Where the opaque layer's shading runs; the transmissive layer's is always its meshes'
/// fragments. The same WGSL functions either way (`shade_rgb`, `shade_spectral`), and the same
/// images (`tests/shading_stage.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShadingStage {
    /// The fragments of a fullscreen triangle.
    Fragment,
    /// A compute pass over the screen, in workgroups of [`super::SCREEN_GROUP`]² pixels.
    Compute,
}

impl ShadingStage {
    /// A GPU's compute passes run on every shader core, its fragments only on the cores with
    /// raster hardware, which on data-centre GPUs are a small part of them (docs/benchmark.md,
    /// "Shading in a compute pass"); a CPU driver (lavapipe) runs the fragment passes up to
    /// 15 % faster than the compute passes.
    pub fn default_for(adapter: &wgpu::AdapterInfo) -> ShadingStage {
        if adapter.device_type == wgpu::DeviceType::Cpu {
            ShadingStage::Fragment
        } else {
            ShadingStage::Compute
        }
    }

    /// `SPECTRA_SHADING_STAGE` (`compute` or `fragment`) where it is set, else
    /// [`Self::default_for`] the adapter: how every command (render, eval, view, bench) can be
    /// run in either stage.
    pub fn from_env(adapter: &wgpu::AdapterInfo) -> crate::Result<ShadingStage> {
        match std::env::var("SPECTRA_SHADING_STAGE") {
            Err(_) => Ok(Self::default_for(adapter)),
            Ok(v) => Self::parse(&v).ok_or_else(|| {
                crate::RenderError::Settings(format!(
                    "SPECTRA_SHADING_STAGE must be compute or fragment, got {v:?}"
                ))
            }),
        }
    }

    /// The stage [`Self::name`] names.
    pub fn parse(name: &str) -> Option<ShadingStage> {
        [ShadingStage::Fragment, ShadingStage::Compute].into_iter().find(|s| s.name() == name)
    }

    /// The name `spectra bench --shading-stage` takes and prints.
    pub fn name(self) -> &'static str {
        match self {
            ShadingStage::Fragment => "fragment",
            ShadingStage::Compute => "compute",
        }
    }
}

pub struct ShadingPass {
    pub input_layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    stage: ShadingStage,
    /// The RGB mode's entry points: the compute pass's and the fragment shader.
    rgb_entry: (&'static str, &'static str),
    /// Bound as the compute pass's output where the pass draws instead (its fragment stage, the
    /// transmissive layer): the target it draws into cannot be bound too.
    unused_output: wgpu::TextureView,
    /// Whether the module declares the [`Variant`] overrides (the reference shader does not).
    has_variants: bool,
    /// Built on first use, per variant and entry point (`true`: RGB mode). RGB has its own
    /// entry point so that the JIT-compiled RGB shader carries none of the spectral path's loops
    /// (a CPU driver paid for them even when a uniform branch skipped them).
    pipelines: HashMap<(Variant, bool), ScreenPipeline>,
    current: (Variant, bool),
    /// The custom hooks' pipeline-overridable constants ([`CustomShader::constants`]).
    hook_constants: Vec<(String, f64)>,
}

/// What a frame needs of the shading pass beyond punctual lights: each feature is a
/// pipeline-overridable constant, so a frame without it runs a shader compiled without its code
/// (on a CPU driver an untaken uniform branch still cost: polygon lights and the environment took
/// the RGB pass of a punctual-only scene from 97 to 187 ms at 1280×720; the capture, naive and
/// emission branches cost the spectral pass as much again).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Variant {
    /// Emissive polygons among the lights (`HAS_POLYGONS`).
    pub polygons: bool,
    /// An environment light (`HAS_ENV`).
    pub environment: bool,
    /// A material that emits or is unlit (`HAS_EMISSION`; every mode).
    pub emission: bool,
    /// A material that glows with a measured spectrum (`HAS_EMISSION_SPECTRA`; every mode).
    pub emission_spectra: bool,
    /// Box upsampling instead of the sigmoid (`NAIVE`: the naive mode).
    pub naive: bool,
    /// The frame writes the spectral capture (`CAPTURE`).
    pub capture: bool,
    /// Some material's base colour varies over its surface, so the spectral mode fetches its
    /// coefficients per pixel (`FETCH_BASE`); the others come from the CPU.
    pub fetch_base: bool,
    /// The same for emission (`FETCH_EMISSION`).
    pub fetch_emission: bool,
    /// Some material has a thin film (`HAS_FILM`): the G-buffer's film target is read and
    /// filmed pixels take the film's Fresnel term (all modes).
    pub film: bool,
    /// Some material has a clear coat (`HAS_COAT`, `KHR_materials_clearcoat`): the G-buffer's
    /// coat target is read and coated pixels layer the coat over the rest (all modes).
    pub coat: bool,
    /// Some dielectric's index is not 1.5 (`HAS_IOR`, `KHR_materials_ior`): F0 per material.
    pub ior: bool,
    /// Some material has a specular strength or colour (`HAS_SPECULAR`,
    /// `KHR_materials_specular`): the G-buffer's specular target is read (all modes).
    pub specular: bool,
    /// Some opaque material has a sheen (`HAS_SHEEN`, `KHR_materials_sheen`): the G-buffer's
    /// sheen target is read and each light's sheen lobe added (all modes).
    pub sheen: bool,
    /// Some opaque material has an anisotropy (`HAS_ANISOTROPY`, `KHR_materials_anisotropy`):
    /// the film's target carries it, and the base's specular lobe is anisotropic (all modes).
    pub anisotropy: bool,
    /// Some opaque material has a diffuse transmission (`HAS_DIFFUSE_TRANSMISSION`,
    /// `KHR_materials_diffuse_transmission`): the specular's target carries it, and each light
    /// behind the surface and the environment there reach the viewer through it (all modes).
    pub diffuse_transmission: bool,
    /// The transmissive layer's shading (`HAS_TRANSMISSION`, passes/transmission.wgsl): the
    /// G-buffer is the see-through layer's, `background` the opaque layer's shaded image.
    pub transmission: bool,
    /// Some see-through material is thin-walled (`HAS_THIN_WALLS`): the lights behind it shine
    /// through (`thin_transmission`).
    pub thin_walls: bool,
    /// Some see-through material disperses (`HAS_DISPERSION`): only then are the refraction's
    /// per-channel (RGB) or per-node (spectral) traces compiled in.
    pub dispersion: bool,
    /// The environment's basis spectra that its coefficients use (`ENV_BASES`, 1..=4;
    /// `environment::SpectralBasis::used` in the spectral mode): the per-node environment
    /// weights of the others are not read.
    pub env_bases: u32,
    /// The ambient light's occlusion comes from the occlusion pass (`OCCLUSION_MAP`,
    /// `passes::occlusion`) instead of being searched in this pass.
    pub occlusion_map: bool,
}

impl Variant {
    /// Everything compiled in: right for any scene in the spectral mode without a capture.
    pub const ALL: Variant = Variant {
        polygons: true,
        environment: true,
        emission: true,
        emission_spectra: true,
        naive: false,
        capture: false,
        fetch_base: true,
        fetch_emission: true,
        film: true,
        coat: true,
        ior: true,
        specular: true,
        sheen: true,
        anisotropy: true,
        diffuse_transmission: true,
        transmission: false,
        thin_walls: true,
        dispersion: true,
        env_bases: crate::environment::K as u32,
        occlusion_map: false,
    };

    /// The constants this variant sets. The RGB entry point reads only the scene's (polygons,
    /// environment, emission, film, ior, specular, sheen, anisotropy, diffuse transmission, transmission, thin walls, dispersion) and the occlusion's; its
    /// pipelines are keyed by [`Self::rgb`].
    fn constants(&self) -> [(&'static str, f64); 20] {
        let b = |v: bool| f64::from(u8::from(v));
        [
            ("HAS_POLYGONS", b(self.polygons)),
            ("HAS_ENV", b(self.environment)),
            ("HAS_EMISSION", b(self.emission)),
            ("HAS_EMISSION_SPECTRA", b(self.emission_spectra)),
            ("NAIVE", b(self.naive)),
            ("CAPTURE", b(self.capture)),
            ("FETCH_BASE", b(self.fetch_base)),
            ("FETCH_EMISSION", b(self.fetch_emission)),
            ("HAS_FILM", b(self.film)),
            ("HAS_COAT", b(self.coat)),
            ("HAS_IOR", b(self.ior)),
            ("HAS_SPECULAR", b(self.specular)),
            ("HAS_SHEEN", b(self.sheen)),
            ("HAS_ANISOTROPY", b(self.anisotropy)),
            ("HAS_DIFFUSE_TRANSMISSION", b(self.diffuse_transmission)),
            ("HAS_TRANSMISSION", b(self.transmission)),
            ("HAS_THIN_WALLS", b(self.thin_walls)),
            ("HAS_DISPERSION", b(self.dispersion)),
            ("ENV_BASES", f64::from(self.env_bases)),
            ("OCCLUSION_MAP", b(self.occlusion_map)),
        ]
    }

    /// What the RGB entry point depends on (the scene's features and the occlusion's source),
    /// the rest at its defaults.
    fn rgb(self) -> Variant {
        Variant {
            polygons: self.polygons,
            environment: self.environment,
            emission: self.emission,
            emission_spectra: self.emission_spectra,
            film: self.film,
            coat: self.coat,
            ior: self.ior,
            specular: self.specular,
            sheen: self.sheen,
            anisotropy: self.anisotropy,
            diffuse_transmission: self.diffuse_transmission,
            transmission: self.transmission,
            thin_walls: self.thin_walls,
            dispersion: self.dispersion,
            occlusion_map: self.occlusion_map,
            ..Variant::ALL
        }
    }
}

/// The shading module's parts in order, with `hooks` the custom shader as assembled
/// ([`CustomShader::assembled`]); `layout_tests` parses the same.
pub(crate) fn sources(hooks: &str) -> [&str; 11] {
    [
        shader::COMMON,
        shader::HASH,
        shader::SPECTRAL,
        shader::ENVIRONMENT,
        shader::FILM,
        shader::SHEEN,
        shader::CUSTOM_API,
        hooks,
        include_str!("shading.wgsl"),
        include_str!("occlusion.wgsl"),
        include_str!("transmission.wgsl"),
    ]
}

impl ShadingPass {
    /// Builds the pipeline with `custom` (the custom hooks) compiled in, the opaque layer's shading
    /// running in `stage`.
    pub fn new(
        device: &wgpu::Device,
        shared: &SharedLayouts,
        custom: &CustomShader,
        stage: ShadingStage,
    ) -> Result<Self> {
        Self::build(
            device,
            shared,
            &sources(&custom.assembled()),
            stage,
            ("cs_rgb", "fs_rgb"),
            true,
            custom.constants.clone(),
        )
    }

    /// The benchmark's minimal single-light RGB shader (`shading_reference.wgsl`) with the same
    /// inputs, to time in place of the real pass ([`crate::Renderer::set_reference_shading`]).
    pub fn reference(device: &wgpu::Device, shared: &SharedLayouts, stage: ShadingStage) -> Result<Self> {
        Self::build(
            device,
            shared,
            &[shader::COMMON, shader::SPECTRAL, include_str!("shading_reference.wgsl")],
            stage,
            ("cs_main", "fs_main"),
            false,
            Vec::new(),
        )
    }

    fn build(
        device: &wgpu::Device,
        shared: &SharedLayouts,
        sources: &[&str],
        stage: ShadingStage,
        rgb_entry: (&'static str, &'static str),
        has_variants: bool,
        hook_constants: Vec<(String, f64)>,
    ) -> Result<Self> {
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shading inputs"),
            entries: &[
                texture_entry(0),
                // The normal, roughness and material slot (`gbuffer_normal` and its siblings).
                super::uint_entry(1),
                texture_entry(2),
                depth_entry(3),
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: READERS,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: READERS,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
                uniform_entry(6, READERS),
                // The spectral capture (`capture` in shading.wgsl).
                wgpu::BindGroupLayoutEntry {
                    binding: 7,
                    visibility: READERS,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                // The coats (`gbuf_coat`).
                super::uint_entry(8),
                // The films (`gbuf_film`).
                texture_entry(9),
                // The transmissive layer's background (`background`, transmission.wgsl), its
                // back faces (`back_faces`) and the opaque layer's depth (`opaque_depth`).
                super::filterable_entry(10),
                texture_entry(11),
                super::depth_entry(12),
                // The transmissive layer's transmission and film, packed (`layer_packed`); the
                // opaque layer's specular strength and colour (`specular_at`), which the
                // see-through one never has: a sampled texture of its own would be the 17th of
                // the stage, past WebGPU's guaranteed 16.
                super::uint_entry(13),
                // The opaque layer's shaded image (`shading_out`).
                super::storage_output_entry(14, HDR_FORMAT),
            ],
        });
        let module = shader::compile(device, "shading", sources)?;
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shading"),
            bind_group_layouts: &[
                Some(&shared.frame),
                Some(&input_layout),
                Some(&shared.spectral),
                Some(&shared.custom),
            ],
            immediate_size: 0,
        });
        let unused_output = crate::targets::target(
            device,
            (1, 1),
            "shading output (unused)",
            HDR_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
        )
        .1;
        let mut pass = ShadingPass {
            input_layout,
            module,
            pipeline_layout,
            stage,
            rgb_entry,
            unused_output,
            has_variants,
            pipelines: HashMap::new(),
            current: (Variant::ALL, false),
            hook_constants,
        };
        // Built now so that a shader error shows when the pass is made, not at the first frame.
        pass.select(device, Variant::ALL, true)?;
        pass.select(device, Variant::ALL, false)?;
        Ok(pass)
    }

    /// Makes `variant` the pipeline [`Self::record`] uses, with the RGB-mode entry point when
    /// `rgb`, compiling it the first time.
    pub fn select(&mut self, device: &wgpu::Device, variant: Variant, rgb: bool) -> Result<()> {
        let variant = match (self.has_variants, rgb) {
            (false, _) => Variant::ALL,
            (true, true) => variant.rgb(),
            (true, false) => variant,
        };
        let key = (variant, rgb);
        if !self.pipelines.contains_key(&key) {
            let own = variant.constants();
            let constants: Vec<(&str, f64)> = if self.has_variants { own.to_vec() } else { Vec::new() }
                .into_iter()
                .chain(self.hook_constants.iter().map(|(name, value)| (name.as_str(), *value)))
                .collect();
            // The compute pass's entry point and the fragment shader's.
            let (label, (screen_entry, fragment_entry)) = if rgb {
                ("shading pipeline (rgb)", self.rgb_entry)
            } else {
                ("shading pipeline", ("cs_main", "fs_main"))
            };
            let pipeline = shader::checked(device, label, || {
                if variant.transmission {
                    return ScreenPipeline::Draw(self.layer_pipeline(device, fragment_entry, &constants));
                }
                if self.stage == ShadingStage::Fragment {
                    return ScreenPipeline::Draw(
                        FullscreenPipeline {
                            fragment: fragment_entry,
                            constants: &constants,
                            ..FullscreenPipeline::simple(
                                label,
                                &self.module,
                                &self.pipeline_layout,
                                &[HDR_FORMAT],
                            )
                        }
                        .build(device),
                    );
                }
                ScreenPipeline::compute(
                    device,
                    label,
                    &self.pipeline_layout,
                    &self.module,
                    screen_entry,
                    &constants,
                )
            })?;
            self.pipelines.insert(key, pipeline);
        }
        self.current = key;
        Ok(())
    }

    /// The transmissive layer's pipeline: the see-through meshes redrawn (`vs_layer`) over the
    /// frame that holds the background, keeping only fragments not behind the layer's depth (its
    /// own surfaces; read-only), so that only see-through pixels run the shading.
    fn layer_pipeline(
        &self,
        device: &wgpu::Device,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> wgpu::RenderPipeline {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shading pipeline (transmissive layer)"),
            layout: Some(&self.pipeline_layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_layer"),
                compilation_options: Default::default(),
                buffers: &[Some(crate::scene_gpu::Vertex::layout())],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(super::depth_state(wgpu::CompareFunction::GreaterEqual, false)),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
                targets: &[Some(wgpu::ColorTargetState {
                    format: HDR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// Records the transmissive layer's shading with the pipeline `key` (a [`Variant`] with
    /// `transmission`): the see-through draws of `scene` over `target`, which already holds the
    /// opaque layer, depth-tested against `depth` (the layer's, also bound in `inputs`).
    #[allow(clippy::too_many_arguments)] // a pass's inputs, each its own kind
    pub fn record_layer(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        shared: &SharedGroups,
        draw: Draw,
        depth: &wgpu::TextureView,
        scene: &crate::scene_gpu::GpuScene,
        key: (Variant, bool),
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shading (transmissive layer)"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: draw.target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: None,
                stencil_ops: None,
            }),
            timestamp_writes: draw.timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let ScreenPipeline::Draw(pipeline) = &self.pipelines[&key] else {
            unreachable!("the layer's key is a transmission variant")
        };
        pass.set_pipeline(pipeline);
        for (i, g) in [shared.frame, draw.inputs, shared.spectral, shared.custom].into_iter().enumerate() {
            pass.set_bind_group(i as u32, g, &[]);
        }
        for d in scene.draws.iter().filter(|d| d.transmissive) {
            scene.draw_geometry(&mut pass, d);
        }
    }

    /// Group 1: the G-buffer, its depth, the shadow maps, `capture` as the spectral capture
    /// buffer (a dummy when not capturing), and `output`, where the pass writes (`Draw::target`
    /// must be its view).
    pub fn bind_inputs(
        &self,
        device: &wgpu::Device,
        t: &Targets,
        shadow: &ShadowPass,
        capture: &wgpu::Buffer,
        output: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        let g = &t.gbuffer_views;
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shading inputs"),
            layout: &self.input_layout,
            entries: &[
                view_entry(0, &g[0]),
                view_entry(1, &g[1]),
                view_entry(2, &g[2]),
                view_entry(3, &t.depth_view),
                view_entry(4, &shadow.view),
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Sampler(&shadow.sampler),
                },
                buffer_entry(6, &shadow.uniforms),
                buffer_entry(7, capture),
                view_entry(8, &t.gbuffer_coat_view),
                // The film's values (with an anisotropy's where the scene has one).
                view_entry(9, t.film_view()),
                // The sheen (`sheen_at`; the transmissive layer's background there). Not read
                // outside the transmissive layer: any texture of its kind the pass does not write.
                view_entry(10, &t.gbuffer_sheen_view),
                // The occlusion pass's output (`aux_map`, read with `OCCLUSION_MAP`).
                view_entry(11, &t.occlusion_view),
                view_entry(12, &t.depth_view),
                // The specular's values (with a diffuse transmission's where the scene has one).
                view_entry(13, t.specular_view()),
                view_entry(14, output),
            ],
        })
    }

    /// [`Self::bind_inputs`] with each output the frame may shade into: `t.hdr` (index 0,
    /// where the custom pass is skipped) and `t.hdr_shaded` (1, the custom pass's input); in
    /// the fragment stage, which draws into them, neither.
    pub fn bind_both(
        &self,
        device: &wgpu::Device,
        t: &Targets,
        shadow: &ShadowPass,
        capture: &wgpu::Buffer,
    ) -> [wgpu::BindGroup; 2] {
        let outputs = match self.stage {
            ShadingStage::Compute => [&t.hdr_view, &t.hdr_shaded_view],
            ShadingStage::Fragment => [&self.unused_output; 2],
        };
        outputs.map(|output| self.bind_inputs(device, t, shadow, capture, output))
    }

    /// Group 1 of the transmissive layer: its G-buffer (the fourth target, transmission and
    /// film packed, at 13) and depth, the shadow maps, the
    /// opaque layer's shaded image as the background and its depth `opaque_depth`, and the
    /// see-through meshes' back faces (at 11, `aux_map`; the layer searches its own occlusion).
    pub fn bind_layer_inputs(
        &self,
        device: &wgpu::Device,
        layer: &crate::targets::LayerTargets,
        opaque_depth: &wgpu::TextureView,
        shadow: &ShadowPass,
        capture: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let g = &layer.gbuffer_views;
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shading inputs (transmissive layer)"),
            layout: &self.input_layout,
            entries: &[
                view_entry(0, &g[0]),
                view_entry(1, &g[1]),
                view_entry(2, &g[2]),
                view_entry(3, &layer.depth_view),
                view_entry(4, &shadow.view),
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::Sampler(&shadow.sampler),
                },
                buffer_entry(6, &shadow.uniforms),
                buffer_entry(7, capture),
                view_entry(8, &g[4]),
                // The layer's film is in `layer_packed`: any float texture here.
                view_entry(9, &g[0]),
                view_entry(10, &layer.background_view),
                view_entry(11, &layer.back_faces_view),
                view_entry(12, opaque_depth),
                view_entry(13, &g[3]),
                // The layer draws into its target.
                view_entry(14, &self.unused_output),
            ],
        })
    }

    /// Whether the pass lights with ambient light, and so reads the occlusion pass's output
    /// (the benchmark's reference shader does not).
    pub fn reads_occlusion(&self) -> bool {
        self.has_variants
    }

    /// Where the opaque layer's shading runs.
    pub fn stage(&self) -> ShadingStage {
        self.stage
    }

    /// The pipeline [`Self::select`] made current, for [`Self::record_with`].
    pub fn current(&self) -> (Variant, bool) {
        self.current
    }

    /// Records the pass with the pipeline [`Self::select`] chose.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, shared: &SharedGroups, draw: Draw) {
        self.record_with(encoder, shared, draw, self.current);
    }

    /// Records the pass with the pipeline `key` ([`Self::current`] after its `select`).
    pub fn record_with(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        shared: &SharedGroups,
        draw: Draw,
        key: (Variant, bool),
    ) {
        let groups = [shared.frame, draw.inputs, shared.spectral, shared.custom];
        self.pipelines[&key].record(encoder, "shading", &groups, draw);
    }
}
