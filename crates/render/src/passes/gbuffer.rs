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
//! ([`GBUFFER_FILM_FORMAT`]), and the clear coat's and the specular's after it ([`Targets`]),
//! built on first use, so that a scene without them samples none of their textures and writes
//! none of their targets. Each set of targets has its output struct and entry points generated
//! ([`Targets::wgsl`]) around gbuffer.wgsl's one function per target.

use super::{
    GBUFFER_COAT_FORMAT, GBUFFER_FILM_ANISOTROPY_FORMAT, GBUFFER_FILM_FORMAT, GBUFFER_FORMATS,
    GBUFFER_LAYER_FORMAT, GBUFFER_SHEEN_FORMAT, GBUFFER_SPECULAR_DT_FORMAT, GBUFFER_SPECULAR_FORMAT,
    SharedLayouts,
};
use crate::error::Result;
use crate::scene_gpu::{self, GpuScene, Vertex};
use crate::shader;
use std::collections::HashMap;

/// `[double_sided][alpha_tested]`.
type Pipelines = [[wgpu::RenderPipeline; 2]; 2];

pub struct GBufferPass {
    pub material_layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    /// Per set of targets, built on first use ([`Self::prepare`]; the plain set at once).
    pipelines: HashMap<Targets, Pipelines>,
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
    /// caller copied into `depth`, into the layer's targets ([`Fourth::Layer`]).
    Transmissive,
}

/// The target after the three every pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Fourth {
    None,
    /// The thin film's values ([`GBUFFER_FILM_FORMAT`]); scenes with a film, a coat or a
    /// specular write it (the shading pass reads the film beside them).
    Film,
    /// The transmissive layer's packed values ([`GBUFFER_LAYER_FORMAT`]: the transmission, the
    /// volume's thickness texture and the film's two values).
    Layer,
}

/// Which targets a G-buffer pass writes, in location order: base, normal (with the slot),
/// emission, then the [`Fourth`], the clear coat's ([`GBUFFER_COAT_FORMAT`]), the specular
/// strength and colour ([`GBUFFER_SPECULAR_FORMAT`], `KHR_materials_specular`) and the sheen
/// ([`GBUFFER_SHEEN_FORMAT`], `KHR_materials_sheen`). An anisotropy (`KHR_materials_anisotropy`)
/// adds no target: it widens the film's to [`GBUFFER_FILM_ANISOTROPY_FORMAT`] (film values in
/// xy, the anisotropy's angle and strength in zw), which the shading pass reads where it reads
/// the film's (no sampled texture to spare there, nor a colour attachment with a sheen here).
/// A diffuse transmission (`KHR_materials_diffuse_transmission`) widens the specular's to
/// [`GBUFFER_SPECULAR_DT_FORMAT`] for the same reasons, and writes it without a specular too.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Targets {
    pub fourth: Fourth,
    pub coat: bool,
    pub specular: bool,
    pub sheen: bool,
    pub anisotropy: bool,
    pub diffuse_transmission: bool,
}

impl Targets {
    pub const PLAIN: Targets = Targets {
        fourth: Fourth::None,
        coat: false,
        specular: false,
        sheen: false,
        anisotropy: false,
        diffuse_transmission: false,
    };

    /// Every set the renderer draws with: a coat comes with the film's or the layer's target
    /// (which the shading pass reads beside it), a specular with the film's (the loader keeps no
    /// specular on see-through materials), a sheen anywhere but the see-through layer's (the
    /// real-time renderer draws no sheen there), an anisotropy with the film's (which it
    /// widens; none in the see-through layer either), a diffuse transmission with the film's
    /// (the specular's, which it widens, comes with the film's; none in the see-through layer).
    pub fn all() -> impl Iterator<Item = Targets> {
        [Fourth::None, Fourth::Film, Fourth::Layer].into_iter().flat_map(|fourth| {
            (0..32u8)
                .map(move |bits| Targets {
                    fourth,
                    coat: bits & 1 != 0,
                    specular: bits & 2 != 0,
                    sheen: bits & 4 != 0,
                    anisotropy: bits & 8 != 0,
                    diffuse_transmission: bits & 16 != 0,
                })
                .filter(|t| {
                    (!t.coat || t.fourth != Fourth::None)
                        && (!t.specular || t.fourth == Fourth::Film)
                        && (!t.sheen || t.fourth != Fourth::Layer)
                        && (!t.anisotropy || t.fourth == Fourth::Film)
                        && (!t.diffuse_transmission || t.fourth == Fourth::Film)
                })
        })
    }

    /// The formats of the targets, in location order.
    pub fn formats(self) -> Vec<wgpu::TextureFormat> {
        let mut f = GBUFFER_FORMATS.to_vec();
        match self.fourth {
            Fourth::None => {}
            Fourth::Film if self.anisotropy => f.push(GBUFFER_FILM_ANISOTROPY_FORMAT),
            Fourth::Film => f.push(GBUFFER_FILM_FORMAT),
            Fourth::Layer => f.push(GBUFFER_LAYER_FORMAT),
        }
        if self.coat {
            f.push(GBUFFER_COAT_FORMAT);
        }
        if self.diffuse_transmission {
            f.push(GBUFFER_SPECULAR_DT_FORMAT);
        } else if self.specular {
            f.push(GBUFFER_SPECULAR_FORMAT);
        }
        if self.sheen {
            f.push(GBUFFER_SHEEN_FORMAT);
        }
        f
    }

    /// The bytes a pixel's targets take where it is past WebGPU's guaranteed 32 (the device
    /// asks for what the adapter allows), and the extensions that need them.
    fn bytes_needed(self) -> Option<(u32, String)> {
        // Base, normal and emission; the film's or the layer's 4.
        let mut bytes = 8 + 8 + 8 + if self.fourth == Fourth::None { 0 } else { 4 };
        let mut what = Vec::new();
        if self.anisotropy {
            bytes += super::ANISOTROPY_TARGET_BYTES;
            what.push("an anisotropy (KHR_materials_anisotropy)");
        }
        if self.coat {
            bytes += 8;
            what.push("a clear coat (KHR_materials_clearcoat)");
        }
        if self.specular {
            bytes += 8;
            what.push("a specular colour (KHR_materials_specular)");
        }
        if self.diffuse_transmission {
            bytes += super::DIFFUSE_TRANSMISSION_TARGET_BYTES + if self.specular { 0 } else { 8 };
            what.push("a diffuse transmission (KHR_materials_diffuse_transmission)");
        }
        if self.sheen {
            bytes += super::SHEEN_TARGET_BYTES;
            what.push("a sheen (KHR_materials_sheen)");
        }
        (bytes > 32).then(|| (bytes, what.join(" and ")))
    }

    fn name(self) -> String {
        let fourth = match self.fourth {
            Fourth::None => "plain",
            Fourth::Film => "film",
            Fourth::Layer => "layer",
        };
        format!(
            "{fourth}{}{}{}{}{}",
            if self.coat { "_coat" } else { "" },
            if self.specular { "_spec" } else { "" },
            if self.sheen { "_sheen" } else { "" },
            if self.anisotropy { "_aniso" } else { "" },
            if self.diffuse_transmission { "_dt" } else { "" }
        )
    }

    /// The fragment entry point writing these targets, with or without the alpha test.
    fn entry(self, alpha: bool) -> String {
        format!("fs_{}_{}", self.name(), if alpha { "alpha" } else { "main" })
    }

    /// The output struct and the two entry points (opaque, alpha-tested) of these targets:
    /// every texture is sampled before `gbuffer`, whose discard would leave later samples'
    /// derivatives undefined, and each extra target is its own function's (gbuffer.wgsl).
    fn wgsl(self) -> String {
        let name = self.name();
        let mut fields = vec![
            "@location(0) base: vec4<f32>".to_string(),
            "@location(1) normal: vec4<u32>".into(),
            "@location(2) emission: vec4<f32>".into(),
        ];
        let mut samples = Vec::new();
        let mut writes = Vec::new();
        match self.fourth {
            Fourth::None => {}
            Fourth::Film if self.anisotropy => {
                fields.push(format!("@location({}) film: vec4<f32>", fields.len()));
                samples.push("let f = film_values(v);");
                samples.push("let an = anisotropy_values(v);");
                writes.push("r.film = vec4<f32>(film_target(o, f), anisotropy_target(o, an, v, front));");
            }
            Fourth::Film => {
                fields.push(format!("@location({}) film: vec2<f32>", fields.len()));
                samples.push("let f = film_values(v);");
                writes.push("r.film = film_target(o, f);");
            }
            Fourth::Layer => {
                fields.push(format!("@location({}) layer: u32", fields.len()));
                samples.push("let t = transmission_values(v);");
                samples.push("let f = film_values(v);");
                writes.push("r.layer = layer_target(o, t, f);");
            }
        }
        if self.coat {
            fields.push(format!("@location({}) coat: vec4<u32>", fields.len()));
            samples.push("let c = coat_sample(v);");
            writes.push("r.coat = coat_target(o, c, v, front, face);");
        }
        if self.diffuse_transmission {
            fields.push(format!("@location({}) specular: vec4<u32>", fields.len()));
            if self.specular {
                samples.push("let sp = specular_values(v);");
            } else {
                samples.push("let sp = vec4<u32>(0u);");
            }
            samples.push("let dt = diffuse_transmission_values(v);");
            writes.push("r.specular = sp | (diffuse_transmission_target(o, dt) << vec4<u32>(16u));");
        } else if self.specular {
            fields.push(format!("@location({}) specular: vec4<u32>", fields.len()));
            samples.push("let sp = specular_values(v);");
            writes.push("r.specular = sp;");
        }
        if self.sheen {
            fields.push(format!("@location({}) sheen: vec4<f32>", fields.len()));
            samples.push("let sh = sheen_values(v);");
            writes.push("r.sheen = sheen_target(o, sh);");
        }
        let mut out = format!("struct GBufferOut_{name} {{\n    {},\n}};\n", fields.join(",\n    "));
        for alpha in [false, true] {
            out.push_str(&format!(
                "@fragment\nfn {}(v: VertexOut, @builtin(front_facing) front: bool) -> GBufferOut_{name} {{\n",
                self.entry(alpha)
            ));
            // The face normal first: like the samples, before `gbuffer`'s discard.
            let head = ["let face = face_normal(v);"];
            for line in head
                .into_iter()
                .chain(samples.iter().copied())
                .chain([format!("let o = gbuffer(v, front, face, {alpha});").as_str()])
            {
                out.push_str(&format!("    {line}\n"));
            }
            out.push_str(&format!("    var r: GBufferOut_{name};\n    r.base = o.base;\n    r.normal = o.normal;\n    r.emission = o.emission;\n"));
            for line in &writes {
                out.push_str(&format!("    {line}\n"));
            }
            out.push_str("    return r;\n}\n");
        }
        out
    }
}

impl GBufferPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts) -> Result<Self> {
        let material_layout = scene_gpu::material_layout(device);
        let entry_points: String = Targets::all().map(Targets::wgsl).collect();
        let module = shader::compile(
            device,
            "gbuffer",
            &[shader::COMMON, shader::HASH, shader::MATERIAL, include_str!("gbuffer.wgsl"), &entry_points],
        )?;
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[Some(&shared.frame), Some(&material_layout)],
            immediate_size: 0,
        });
        let pipelines = HashMap::from([(Targets::PLAIN, build(device, &module, &layout, Targets::PLAIN)?)]);
        Ok(GBufferPass { material_layout, module, layout, pipelines })
    }

    /// Builds the pipelines for `targets` unless they exist.
    pub fn prepare(&mut self, device: &wgpu::Device, targets: Targets) -> Result<()> {
        if self.pipelines.contains_key(&targets) {
            return Ok(());
        }
        if let Some((need, what)) = targets.bytes_needed() {
            let have = device.limits().max_color_attachment_bytes_per_sample;
            if have < need {
                return Err(crate::error::RenderError::Gpu(format!(
                    "a scene with {what} needs G-buffer targets of {need} bytes a pixel; this GPU's hold {have}"
                )));
            }
        }
        let built = build(device, &self.module, &self.layout, targets)?;
        self.pipelines.insert(targets, built);
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
        let pipelines =
            self.pipelines.get(&targets).unwrap_or_else(|| panic!("prepare({targets:?}) before recording"));
        debug_assert_eq!(colour.len(), targets.formats().len(), "{targets:?}");
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

/// The four pipelines (single/double-sided × opaque/alpha-tested) writing `which` targets.
fn build(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    which: Targets,
) -> Result<Pipelines> {
    let targets: Vec<_> = which
        .formats()
        .into_iter()
        .map(|format| {
            Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL })
        })
        .collect();
    let pipeline = |double_sided: bool, alpha: bool| {
        let entry = which.entry(alpha);
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
                    entry_point: Some(&entry),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every set's generated entry points parse, write one output per format in location order,
    /// with the scalar kind the format stores (a float output into a float target, `u32` into an
    /// unsigned one).
    #[test]
    fn generated_entry_points_write_each_target_in_order() {
        let all: Vec<Targets> = Targets::all().collect();
        assert_eq!(all.len(), 36, "{all:?}");
        let entry_points: String = all.iter().map(|t| t.wgsl()).collect();
        let source =
            [shader::COMMON, shader::HASH, shader::MATERIAL, include_str!("gbuffer.wgsl"), &entry_points]
                .join("\n");
        let module =
            naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        for t in all {
            let formats = t.formats();
            let bytes: u32 = formats.iter().map(|f| f.target_pixel_byte_cost().unwrap()).sum();
            match t.bytes_needed() {
                Some((need, _)) => assert_eq!(need, bytes, "{t:?}"),
                None => assert!(bytes <= 32, "{t:?}: {bytes}"),
            }
            for alpha in [false, true] {
                let name = t.entry(alpha);
                let ep =
                    module.entry_points.iter().find(|e| e.name == name).unwrap_or_else(|| panic!("{name}"));
                let result = ep.function.result.as_ref().expect("an output struct");
                let naga::TypeInner::Struct { members, .. } = &module.types[result.ty].inner else {
                    panic!("{name}: not a struct");
                };
                assert_eq!(members.len(), formats.len(), "{name}");
                for (i, (m, format)) in members.iter().zip(&formats).enumerate() {
                    let location = match m.binding {
                        Some(naga::Binding::Location { location, .. }) => location,
                        ref other => panic!("{name} member {i}: {other:?}"),
                    };
                    assert_eq!(location, i as u32, "{name} member {i}");
                    let kind = match module.types[m.ty].inner {
                        naga::TypeInner::Scalar(s) | naga::TypeInner::Vector { scalar: s, .. } => s.kind,
                        ref other => panic!("{name} member {i}: {other:?}"),
                    };
                    let uint = matches!(format.sample_type(None, None), Some(wgpu::TextureSampleType::Uint));
                    assert_eq!(
                        kind == naga::ScalarKind::Uint,
                        uint,
                        "{name} member {i}: {kind:?} into {format:?}"
                    );
                }
            }
        }
    }
}
