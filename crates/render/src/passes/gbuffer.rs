//! Pass 1: rasterise the scene into the G-buffer — depth, base colour × texture × `COLOR_0`
//! (+ metallic), normal (normal-mapped through tangents, + roughness), and emission.
//!
//! Four pipelines, chosen per draw: single-sided materials cull back faces (glTF
//! `doubleSided: false`), double-sided ones do not and flip the normal of back faces towards
//! the viewer; `MASK` and `BLEND` materials use the fragment entry point that may discard
//! (below the cutoff, or stochastically for `BLEND`, see `wgsl/material.wgsl`), opaque ones one
//! without discard so that early depth testing stays on. Every mode writes the same three
//! targets (the material's slot travels with the normal: `gbuffer_pack_normal` in
//! wgsl/common.wgsl); a scene with a thin film adds a fourth, the film's values
//! ([`GBUFFER_FILM_FORMAT`]), built on first use, so that a scene without one samples no film
//! texture and writes no film target.

use super::{
    GBUFFER_COAT_FORMAT, GBUFFER_FILM_FORMAT, GBUFFER_FORMATS, GBUFFER_LAYER_FORMAT, GBUFFER_SPECULAR_FORMAT,
    SharedLayouts,
};
use crate::error::Result;
use crate::scene_gpu::{self, GpuScene, Vertex};
use crate::shader;

/// `[double_sided][alpha_tested]`.
type Pipelines = [[wgpu::RenderPipeline; 2]; 2];

pub struct GBufferPass {
    pub material_layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    pipelines: Pipelines,
    /// With the film, for scenes with a thin film ([`Self::prepare`]).
    film_pipelines: Option<Pipelines>,
    /// The transmissive layer's ([`Targets::Layer`]).
    layer_pipelines: Option<Pipelines>,
    /// With the film and the coat, for scenes with a clear coat ([`Targets::Coat`]).
    coat_pipelines: Option<Pipelines>,
    /// The transmissive layer's with the coat ([`Targets::LayerCoat`]).
    layer_coat_pipelines: Option<Pipelines>,
    /// With the film and the specular ([`Targets::FilmSpec`]).
    spec_pipelines: Option<Pipelines>,
    /// With the film, the coat and the specular ([`Targets::CoatSpec`]).
    coat_spec_pipelines: Option<Pipelines>,
}

/// Which draws a G-buffer pass rasterises. A scene with see-through materials is drawn in two
/// layers: the opaque one, shaded into the background image, then the transmissive one over a
/// copy of its depth (so that it keeps only see-through surfaces in front of the opaque ones),
/// whose shading refracts into that background (`passes::shading`, `HAS_TRANSMISSION`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layer {
    /// Every draw, see-through ones as opaque (scenes without them; frames that cannot draw
    /// the second layer).
    All,
    /// Every draw but the see-through ones.
    Opaque,
    /// Only the see-through ones, depth-tested against the opaque layer's depth, which the
    /// caller copied into `depth`, into [`Targets::Layer`].
    Transmissive,
}

/// Which targets a G-buffer pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Targets {
    /// Base, normal (with the material's slot), emission.
    Plain,
    /// And the film.
    Film,
    /// And the film and the clear coat ([`GBUFFER_COAT_FORMAT`]).
    Coat,
    /// The transmissive layer's ([`Targets::Layer`]) and the clear coat.
    LayerCoat,
    /// And in four packed channels the transmission factor × texture, the volume's thickness
    /// texture and the film's two values: the transmissive layer's.
    Layer,
    /// [`Targets::Film`] and the specular strength and colour ([`GBUFFER_SPECULAR_FORMAT`],
    /// `KHR_materials_specular`).
    FilmSpec,
    /// [`Targets::Coat`] and the specular.
    CoatSpec,
}

impl GBufferPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        let material_layout = scene_gpu::material_layout(device);
        let module = shader::compile(
            device,
            "gbuffer",
            &[shader::COMMON, shader::HASH, shader::MATERIAL, include_str!("gbuffer.wgsl")],
        )?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[Some(&shared.frame), Some(&material_layout)],
            immediate_size: 0,
        });
        let pipelines = build(device, &module, &layout, Targets::Plain)?;
        Ok(GBufferPass {
            material_layout,
            module,
            layout,
            pipelines,
            film_pipelines: None,
            layer_pipelines: None,
            coat_pipelines: None,
            layer_coat_pipelines: None,
            spec_pipelines: None,
            coat_spec_pipelines: None,
        })
    }

    /// Builds the pipelines for `targets` unless they exist.
    pub fn prepare(&mut self, device: &wgpu::Device, targets: Targets) -> Result<()> {
        let slot = match targets {
            Targets::Plain => return Ok(()),
            Targets::Film => &mut self.film_pipelines,
            Targets::Layer => &mut self.layer_pipelines,
            Targets::Coat | Targets::LayerCoat | Targets::FilmSpec | Targets::CoatSpec => {
                let have = device.limits().max_color_attachment_bytes_per_sample;
                let (need, what) = match targets {
                    Targets::FilmSpec => {
                        (super::SPECULAR_TARGET_BYTES, "a specular colour (KHR_materials_specular)")
                    }
                    Targets::CoatSpec => (
                        super::COAT_SPECULAR_TARGET_BYTES,
                        "a clear coat and a specular colour (KHR_materials_clearcoat, KHR_materials_specular)",
                    ),
                    _ => (super::COAT_TARGET_BYTES, "a clear coat (KHR_materials_clearcoat)"),
                };
                if have < need {
                    return Err(crate::error::RenderError::Gpu(format!(
                        "a scene with {what} needs G-buffer targets of {need} bytes a pixel; this GPU's hold {have}"
                    )));
                }
                match targets {
                    Targets::Coat => &mut self.coat_pipelines,
                    Targets::LayerCoat => &mut self.layer_coat_pipelines,
                    Targets::FilmSpec => &mut self.spec_pipelines,
                    _ => &mut self.coat_spec_pipelines,
                }
            }
        };
        if slot.is_none() {
            *slot = Some(build(device, &self.module, &self.layout, targets)?);
        }
        Ok(())
    }

    /// Records the pass into `colour`: the three G-buffer targets and those of `targets`
    /// (prepared: [`Self::prepare`]).
    #[allow(clippy::too_many_arguments)] // a pass's inputs, each its own kind
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: Targets,
        colour: &[&wgpu::TextureView],
        depth: &wgpu::TextureView,
        frame: &wgpu::BindGroup,
        scene: &GpuScene,
        layer: Layer,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let pipelines = match targets {
            Targets::Plain => Some(&self.pipelines),
            Targets::Film => self.film_pipelines.as_ref(),
            Targets::Layer => self.layer_pipelines.as_ref(),
            Targets::Coat => self.coat_pipelines.as_ref(),
            Targets::LayerCoat => self.layer_coat_pipelines.as_ref(),
            Targets::FilmSpec => self.spec_pipelines.as_ref(),
            Targets::CoatSpec => self.coat_spec_pipelines.as_ref(),
        };
        let pipelines = pipelines.unwrap_or_else(|| panic!("prepare({targets:?}) before recording"));
        debug_assert_eq!(colour.len(), formats(targets).len(), "{targets:?}");
        let attachments: Vec<_> = colour
            .iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: if layer == Layer::Transmissive {
                        wgpu::LoadOp::Load
                    } else {
                        wgpu::LoadOp::Clear(super::FAR_DEPTH)
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, frame, &[]);
        let mut current = None;
        for d in &scene.draws {
            match layer {
                Layer::Opaque if d.transmissive => continue,
                Layer::Transmissive if !d.transmissive => continue,
                _ => {}
            }
            let key = (d.double_sided as usize, d.alpha_tested as usize);
            if current != Some(key) {
                pass.set_pipeline(&pipelines[key.0][key.1]);
                current = Some(key);
            }
            scene.draw_one(&mut pass, d);
        }
    }
}

/// The formats of the targets `which` names, in location order.
pub fn formats(which: Targets) -> &'static [wgpu::TextureFormat] {
    const B: wgpu::TextureFormat = GBUFFER_FORMATS[0];
    const N: wgpu::TextureFormat = GBUFFER_FORMATS[1];
    const E: wgpu::TextureFormat = GBUFFER_FORMATS[2];
    match which {
        Targets::Plain => &GBUFFER_FORMATS,
        Targets::Film => &[B, N, E, GBUFFER_FILM_FORMAT],
        Targets::Layer => &[B, N, E, GBUFFER_LAYER_FORMAT],
        Targets::Coat => &[B, N, E, GBUFFER_FILM_FORMAT, GBUFFER_COAT_FORMAT],
        Targets::LayerCoat => &[B, N, E, GBUFFER_LAYER_FORMAT, GBUFFER_COAT_FORMAT],
        Targets::FilmSpec => &[B, N, E, GBUFFER_FILM_FORMAT, GBUFFER_SPECULAR_FORMAT],
        Targets::CoatSpec => &[B, N, E, GBUFFER_FILM_FORMAT, GBUFFER_COAT_FORMAT, GBUFFER_SPECULAR_FORMAT],
    }
}

/// The four pipelines (single/double-sided × opaque/alpha-tested) writing `which` targets.
fn build(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    which: Targets,
) -> Result<Pipelines> {
    let targets: Vec<_> = formats(which)
        .iter()
        .map(|&format| {
            Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
        })
        .collect();
    let pipeline = |double_sided: bool, alpha: bool| {
        let entry = match (alpha, which) {
            (false, Targets::Plain) => "fs_main",
            (true, Targets::Plain) => "fs_alpha",
            (false, Targets::Film) => "fs_main_film",
            (true, Targets::Film) => "fs_alpha_film",
            (false, Targets::Layer) => "fs_main_layer",
            (true, Targets::Layer) => "fs_alpha_layer",
            (false, Targets::Coat) => "fs_main_coat",
            (true, Targets::Coat) => "fs_alpha_coat",
            (false, Targets::LayerCoat) => "fs_main_layer_coat",
            (true, Targets::LayerCoat) => "fs_alpha_layer_coat",
            (false, Targets::FilmSpec) => "fs_main_spec",
            (true, Targets::FilmSpec) => "fs_alpha_spec",
            (false, Targets::CoatSpec) => "fs_main_coat_spec",
            (true, Targets::CoatSpec) => "fs_alpha_coat_spec",
        };
        shader::checked(device, "gbuffer pipeline", || {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("gbuffer"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(Vertex::layout())],
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: if double_sided { None } else { Some(wgpu::Face::Back) },
                    ..Default::default()
                },
                depth_stencil: Some(super::depth_state(super::NEARER, true)),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    };
    Ok([[pipeline(false, false)?, pipeline(false, true)?], [pipeline(true, false)?, pipeline(true, true)?]])
}
