//! The passes, one file each with its WGSL beside it, plus the bind-group layouts several
//! passes share.
//!
//! Frame order: shadow (depth from each shadow-casting light, one layer each) → G-buffer →
//! (occlusion, only where the frame has ambient light to occlude) → spectral shading → custom → (accumulate, only with `Renderer::set_accumulation`) → post.
//! The occlusion and the shading's opaque layer are compute passes over the screen on a GPU and
//! fullscreen triangles on a CPU driver (`shading::ShadingStage`). Bind groups: 0 = frame uniforms, 1 = pass inputs, 2 =
//! per-wavelength data and the coefficient table, 3 = the custom shader's parameters.

pub mod accumulate;
pub mod back_faces;
pub mod custom;
pub mod gbuffer;
pub mod occlusion;
pub mod post;
pub mod rgb_medium;
pub mod shading;
pub mod shadow;
pub mod underwater;

/// The stages that read the passes' inputs: the fragment shaders of the draws, and the compute
/// passes that run a fullscreen pass's code over the screen (the shading's opaque layer).
pub(crate) const READERS: wgpu::ShaderStages =
    wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);
/// Side of the square workgroups of those compute passes (`SCREEN_GROUP` in wgsl/common.wgsl;
/// src/layout_tests.rs checks it): 8 × 8 pixels.
pub const SCREEN_GROUP: u32 = 8;

/// HDR colour targets (shading output, custom output).
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The largest finite value of [`HDR_FORMAT`], where the passes clamp what they write
/// (`hdr_out` in wgsl/common.wgsl) rather than store ∞.
pub const HDR_MAX: f32 = 65504.0;

/// How many pixels of a read-back HDR image reached [`HDR_MAX`] in some channel (clipped: the
/// true value is larger), for the caller to warn about.
pub fn hdr_clipped(pixels: &[[f32; 4]]) -> usize {
    pixels.iter().filter(|p| p[..3].iter().any(|c| c.abs() >= HDR_MAX)).count()
}
/// The smallest normal value of [`HDR_FORMAT`], 2⁻¹⁴: below it a half float keeps fewer
/// significant bits the smaller the value, and below 2⁻²⁴ (6·10⁻⁸) none.
pub const HDR_MIN_NORMAL: f32 = 6.103_515_6e-5;

/// The brightest channel of a read-back HDR image when even it lies below [`HDR_MIN_NORMAL`]
/// (the whole image quantised to a few levels, or 0), for the caller to warn about: a higher
/// exposure (applied before the target) would have kept it. `None` for an image with a brighter
/// pixel, or none.
pub fn hdr_too_dim(pixels: &[[f32; 4]]) -> Option<f32> {
    let max =
        pixels.iter().flat_map(|p| &p[..3]).filter(|c| c.is_finite()).fold(0.0f32, |m, c| m.max(c.abs()));
    (!pixels.is_empty() && max < HDR_MIN_NORMAL).then_some(max)
}

#[test]
fn dim_images_are_told_from_lit_ones() {
    assert_eq!(hdr_too_dim(&[]), None);
    assert_eq!(hdr_too_dim(&[[0.0; 4]; 3]), Some(0.0));
    assert_eq!(hdr_too_dim(&[[1e-7, 0.0, 3e-5, 1.0], [0.0; 4]]), Some(3e-5));
    assert_eq!(hdr_too_dim(&[[1e-7, 0.0, 3e-5, 1.0], [0.0, 0.5, 0.0, 1.0]]), None);
    assert_eq!(hdr_too_dim(&[[HDR_MIN_NORMAL, 0.0, 0.0, 1.0]]), None);
    // The constant is the format's: 2⁻¹⁴ is a normal half float, the next value down is not.
    assert_eq!(HDR_MIN_NORMAL, 2f32.powi(-14));
}

/// G-buffer colour targets: base colour + metallic, normal + roughness + the material's slot
/// (packed: `gbuffer_pack_normal` in wgsl/common.wgsl), emission. The slot (the material's
/// index + 1, 0 where no surface is) is 16 bits, so a scene has at most
/// [`crate::scene_gpu::MAX_MATERIALS`].
pub const GBUFFER_FORMATS: [wgpu::TextureFormat; 3] =
    [wgpu::TextureFormat::Rgba16Float, wgpu::TextureFormat::Rgba16Uint, wgpu::TextureFormat::Rgba16Float];
/// The thin film per pixel (written only when the scene has one): weight and where the
/// thickness lies between the material's minimum and maximum (f16: exact at the ends, 2⁻¹¹ of
/// the range near the maximum; the thickness texture itself has 8 bits); the film's index and
/// thickness range are the material's (`MaterialSpectrum::film`).
/// Two channels: the colour attachments of a sample may hold 32 bytes (WebGPU's guarantee),
/// and the layer's target below takes the place of this one beside the other three's 24.
pub const GBUFFER_FILM_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;
/// The film's target of scenes with `KHR_materials_anisotropy` (`passes::gbuffer::Targets::anisotropy`):
/// xy the film's values as [`GBUFFER_FILM_FORMAT`], z the anisotropy direction's angle about the
/// normal in half turns from a frame the normal alone sets (`anisotropy_angle` in
/// wgsl/common.wgsl; f16: 1.5·10⁻³ rad at worst), w its strength. A target of its own would be
/// a ninth colour attachment beside a coat, a specular and a sheen, and a 17th sampled texture
/// in the shading stage; widened, the film's costs 4 bytes more a pixel and is read where it was.
pub const GBUFFER_FILM_ANISOTROPY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The bytes a pixel an anisotropy adds to the G-buffer's targets.
pub const ANISOTROPY_TARGET_BYTES: u32 = 4;
/// The transmissive layer's fourth G-buffer target: transmission, volume thickness, and the
/// film's weight and thickness (`passes::gbuffer::Fourth::Layer`), each in [0, 1] and from
/// 8-bit textures, packed by `pack4x8unorm`: the colour attachments may hold 32 bytes a pixel,
/// the other three take 24, and WebGPU counts an Rgba8Unorm target as 8.
pub const GBUFFER_LAYER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The clear coat per pixel (written only when the scene has one, beside the film's target):
/// the coat's normal, roughness and strength packed as the normal's target is
/// (`gbuffer_pack_normal`, the strength in place of the slot as 16-bit unorm). Its 8 bytes
/// take the colour attachments to 36 a pixel, past WebGPU's guaranteed 32: the device asks
/// for what the adapter allows ([`COAT_TARGET_BYTES`]; Vulkan's is 128).
pub const GBUFFER_COAT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Uint;
/// Bytes a pixel of a coated scene's G-buffer targets: base, normal, emission, film, coat.
pub const COAT_TARGET_BYTES: u32 = 8 + 8 + 8 + 4 + 8;
/// `KHR_materials_specular` per pixel (written only when the scene has it, after the film's and
/// the coat's targets): the F0 colour min(F0(η)·colour, 1) and the weight (`scene::specular`),
/// each a 16-bit fraction (to 1.5·10⁻⁵; the textures have 8 bits). Unsigned integers: the
/// shading pass reads it where the see-through layer's packed target is bound (`specular_at`).
pub const GBUFFER_SPECULAR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Uint;
/// Bytes a pixel of the G-buffer targets with the specular's: 36 beside the film's, 44 with
/// the coat's too (past WebGPU's guaranteed 32, as the coat's).
pub const SPECULAR_TARGET_BYTES: u32 = 8 + 8 + 8 + 4 + 8;
pub const COAT_SPECULAR_TARGET_BYTES: u32 = COAT_TARGET_BYTES + 8;
/// `KHR_materials_sheen` per pixel (written only when the scene has it, after every other
/// target): rgb the sheen colour (linear), a its roughness (`scene::sheen`). Float: the shading
/// pass reads it where the see-through layer's background is bound (`sheen_at`), which a sheen
/// never needs (the real-time renderer draws no sheen on see-through materials).
pub const GBUFFER_SHEEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The specular's target of scenes with `KHR_materials_diffuse_transmission`
/// (`passes::gbuffer::Targets::diffuse_transmission`), written whether or not the scene has a
/// specular: each channel's low 16 bits the specular's as [`GBUFFER_SPECULAR_FORMAT`], the high
/// 16 bits the diffuse transmission's colour (rgb, linear) and factor (a) as 16-bit fractions. A
/// target of its own would be a ninth colour attachment beside a coat, a specular and a sheen,
/// and a 17th sampled texture in the shading stage; widened, the specular's (unsigned integers
/// either way: the same binding) is read where it was.
pub const GBUFFER_SPECULAR_DT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// The bytes a pixel a diffuse transmission adds to the G-buffer's targets: the widened
/// specular's 16, or 8 where the scene has a specular's already; and the film's 4 where the
/// scene has none (the specular's target comes with the film's).
pub const DIFFUSE_TRANSMISSION_TARGET_BYTES: u32 = 8;
/// Bytes a pixel of the G-buffer targets with the sheen's: 8 more than without it.
pub const SHEEN_TARGET_BYTES: u32 = 8;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The camera's depth where nothing is drawn, what its depth targets are cleared to: depth is
/// reversed (1 near, 0 far; [`crate::renderer::projection`]), so a nearer surface has the
/// larger depth and passes [`NEARER`]. The shaders' `is_far_depth` knows the same. (Shadow maps
/// keep the usual order: their range is a thousandfold, not a millionfold.)
pub const FAR_DEPTH: f32 = 0.0;
/// The camera's depth test (reversed depth, see [`FAR_DEPTH`]).
pub const NEARER: wgpu::CompareFunction = wgpu::CompareFunction::Greater;

/// A [`DEPTH_FORMAT`] depth test with `compare`, writing depth when `write`.
pub fn depth_state(compare: wgpu::CompareFunction, write: bool) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}
/// Display output: the hardware does the sRGB encoding on store.
pub const LDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Layouts shared between passes.
pub struct SharedLayouts {
    /// Group 0: `FrameUniforms`.
    pub frame: wgpu::BindGroupLayout,
    /// Group 2: wavelengths, lights, light spectra, coefficient table, table scale.
    pub spectral: wgpu::BindGroupLayout,
    /// Group 3: custom uniforms and spectra.
    pub custom: wgpu::BindGroupLayout,
}

impl SharedLayouts {
    pub fn new(device: &wgpu::Device) -> Self {
        let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[uniform_entry(
                0,
                wgpu::ShaderStages::VERTEX_FRAGMENT.union(wgpu::ShaderStages::COMPUTE),
            )],
        });
        let spectral = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("spectral"),
            entries: &[
                storage_entry(0),
                storage_entry(1),
                storage_entry(2),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: READERS,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D3,
                        multisampled: false,
                    },
                    count: None,
                },
                storage_entry(4),
                // The environment (wgsl/environment.wgsl).
                storage_entry(5),
                filterable_entry(6),
                filterable_entry(7),
                filterable_entry(8),
                wgpu::BindGroupLayoutEntry {
                    binding: 9,
                    visibility: READERS,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                uniform_entry(10, READERS),
                storage_entry(11),
                // The polygon lights' linearly transformed cosines (src/ltc.rs).
                wgpu::BindGroupLayoutEntry {
                    binding: 12,
                    visibility: READERS,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let custom = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("custom"),
            entries: &[uniform_entry(0, READERS), storage_entry(1)],
        });
        SharedLayouts { frame, spectral, custom }
    }

    /// Group 0 over the frame-uniform buffer.
    pub fn frame_group(&self, device: &wgpu::Device, uniforms: &wgpu::Buffer) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &self.frame,
            entries: &[buffer_entry(0, uniforms)],
        })
    }

    /// Group 2.
    pub fn spectral_group(&self, device: &wgpu::Device, i: &SpectralInputs) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("spectral"),
            layout: &self.spectral,
            entries: &[
                buffer_entry(0, i.wavelengths),
                buffer_entry(1, i.lights),
                buffer_entry(2, i.light_weights),
                view_entry(3, i.table),
                buffer_entry(4, i.table_scale),
                buffer_entry(5, i.env_weights),
                view_entry(6, i.env_radiance),
                view_entry(7, i.env_irradiance),
                view_entry(8, i.env_lut),
                wgpu::BindGroupEntry { binding: 9, resource: wgpu::BindingResource::Sampler(i.env_sampler) },
                buffer_entry(10, i.env_uniforms),
                buffer_entry(11, i.material_spectra),
                view_entry(12, i.ltc),
            ],
        })
    }

    /// Group 3: the custom uniforms (`CustomUniforms`) and the sampled custom spectra.
    pub fn custom_group(
        &self,
        device: &wgpu::Device,
        uniforms: &wgpu::Buffer,
        spectra: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("custom"),
            layout: &self.custom,
            entries: &[buffer_entry(0, uniforms), buffer_entry(1, spectra)],
        })
    }
}

/// What group 2 binds (`wgsl/spectral.wgsl`, `wgsl/environment.wgsl`).
pub struct SpectralInputs<'a> {
    pub wavelengths: &'a wgpu::Buffer,
    pub lights: &'a wgpu::Buffer,
    pub light_weights: &'a wgpu::Buffer,
    /// The coefficient table (3D texture) and its scale.
    pub table: &'a wgpu::TextureView,
    pub table_scale: &'a wgpu::Buffer,
    pub env_weights: &'a wgpu::Buffer,
    pub env_radiance: &'a wgpu::TextureView,
    pub env_irradiance: &'a wgpu::TextureView,
    pub env_lut: &'a wgpu::TextureView,
    pub env_sampler: &'a wgpu::Sampler,
    pub env_uniforms: &'a wgpu::Buffer,
    /// Per material, the coefficients of its constant colours (src/material_spectra.rs).
    pub material_spectra: &'a wgpu::Buffer,
    /// The linearly transformed cosines of the polygon lights' specular lobe (src/ltc.rs).
    pub ltc: &'a wgpu::TextureView,
}

pub(crate) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub(crate) fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: READERS,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A non-filterable 2D float texture (G-buffer inputs are read with textureLoad).
pub fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_2d_entry(binding, wgpu::TextureSampleType::Float { filterable: false })
}

pub(crate) fn filterable_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_2d_entry(binding, wgpu::TextureSampleType::Float { filterable: true })
}

pub(crate) fn depth_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_2d_entry(binding, wgpu::TextureSampleType::Depth)
}

/// A 2D unsigned-integer texture (material slots, packed values).
pub(crate) fn uint_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_2d_entry(binding, wgpu::TextureSampleType::Uint)
}

/// A 2D texture of `sample_type` read by the fragment or compute stage.
fn texture_2d_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: READERS,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// The bind groups the fullscreen passes of one frame share: group 0 (frame uniforms), 2
/// (per-wavelength data) and 3 (the custom shader's parameters and spectra).
pub struct SharedGroups<'a> {
    pub frame: &'a wgpu::BindGroup,
    pub spectral: &'a wgpu::BindGroup,
    pub custom: &'a wgpu::BindGroup,
}

/// Where a fullscreen pass draws, with its own inputs (group 1, built by the pass's
/// `bind_inputs`) and optional timestamps.
pub struct Draw<'a, 'q> {
    pub target: &'a wgpu::TextureView,
    pub inputs: &'a wgpu::BindGroup,
    pub timestamps: Option<wgpu::RenderPassTimestampWrites<'q>>,
}

/// A pipeline that draws one fullscreen triangle without vertex buffers: the shading, custom,
/// post and accumulation passes, and the viewer's blit.
pub struct FullscreenPipeline<'a> {
    pub label: &'a str,
    pub module: &'a wgpu::ShaderModule,
    pub layout: &'a wgpu::PipelineLayout,
    /// Vertex entry point: `vs_fullscreen` (`wgsl/common.wgsl`) unless the module has its own.
    pub vertex: &'a str,
    pub fragment: &'a str,
    /// One colour target per format, written without blending.
    pub targets: &'a [wgpu::TextureFormat],
    /// Values of the fragment shader's pipeline-overridable constants.
    pub constants: &'a [(&'a str, f64)],
}

impl FullscreenPipeline<'_> {
    /// `module`'s `fs_main` into one `format` target, with the vertex shader of `common.wgsl`.
    pub fn simple<'a>(
        label: &'a str,
        module: &'a wgpu::ShaderModule,
        layout: &'a wgpu::PipelineLayout,
        format: &'a [wgpu::TextureFormat; 1],
    ) -> FullscreenPipeline<'a> {
        FullscreenPipeline {
            label,
            module,
            layout,
            vertex: "vs_fullscreen",
            fragment: "fs_main",
            targets: format,
            constants: &[],
        }
    }

    pub fn build(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        let targets: Vec<_> = self
            .targets
            .iter()
            .map(|&format| {
                Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
            })
            .collect();
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(self.layout),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some(self.vertex),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fragment),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: self.constants,
                    ..Default::default()
                },
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// The pipeline layout of bind groups `layouts` (group i at index i).
pub fn pipeline_layout(
    device: &wgpu::Device,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let layouts: Vec<_> = layouts.iter().map(|l| Some(*l)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    })
}

/// Records one full-screen triangle that overwrites `targets` (cleared to black first) with
/// `groups` bound in order (group i at index i).
pub fn draw_fullscreen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    targets: &[&wgpu::TextureView],
    pipeline: &wgpu::RenderPipeline,
    groups: &[&wgpu::BindGroup],
    timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
) {
    let attachments: Vec<_> = targets
        .iter()
        .map(|&view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &attachments,
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (index, group) in groups.iter().enumerate() {
        pass.set_bind_group(index as u32, *group, &[]);
    }
    pass.draw(0..3, 0..1);
}

/// A fullscreen pass's pipeline in either stage ([`shading::ShadingStage`]): a compute pass over
/// the screen that writes its target as a storage texture (bound in its inputs), or a draw (the
/// fullscreen triangle; the shading's transmissive layer draws its meshes).
pub enum ScreenPipeline {
    Compute(wgpu::ComputePipeline),
    Draw(wgpu::RenderPipeline),
}

impl ScreenPipeline {
    /// The compute stage's pipeline of `module`'s `entry` with `constants`.
    pub fn compute(
        device: &wgpu::Device,
        label: &str,
        layout: &wgpu::PipelineLayout,
        module: &wgpu::ShaderModule,
        entry: &str,
        constants: &[(&str, f64)],
    ) -> ScreenPipeline {
        ScreenPipeline::Compute(device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            cache: None,
        }))
    }

    /// Records the pass over `draw.target` with `groups` bound in order (group i at index i):
    /// the fullscreen triangle, or one invocation per pixel in [`SCREEN_GROUP`]² workgroups.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        groups: &[&wgpu::BindGroup],
        draw: Draw,
    ) {
        match self {
            ScreenPipeline::Draw(pipeline) => {
                draw_fullscreen(encoder, label, &[draw.target], pipeline, groups, draw.timestamps)
            }
            ScreenPipeline::Compute(pipeline) => dispatch_screen(encoder, label, pipeline, groups, draw),
        }
    }
}

/// The compute stage's output binding: `format`, written.
pub(crate) fn storage_output_entry(binding: u32, format: wgpu::TextureFormat) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
        count: None,
    }
}

fn dispatch_screen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    groups: &[&wgpu::BindGroup],
    draw: Draw,
) {
    let timestamps = draw.timestamps.map(|t| wgpu::ComputePassTimestampWrites {
        query_set: t.query_set,
        beginning_of_pass_write_index: t.beginning_of_pass_write_index,
        end_of_pass_write_index: t.end_of_pass_write_index,
    });
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some(label),
        timestamp_writes: timestamps,
    });
    pass.set_pipeline(pipeline);
    for (index, group) in groups.iter().enumerate() {
        pass.set_bind_group(index as u32, *group, &[]);
    }
    let size = draw.target.texture().size();
    pass.dispatch_workgroups(size.width.div_ceil(SCREEN_GROUP), size.height.div_ceil(SCREEN_GROUP), 1);
}

/// A bind-group entry for a texture view.
pub(crate) fn view_entry(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(view) }
}

/// A bind-group entry for a whole buffer.
pub(crate) fn buffer_entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
}
