//! Pass 2a (before the shading, only where a frame has ambient light to occlude): the
//! screen-space occlusion of ambient light per pixel (`occlusion.wgsl`: 8 screen directions × 6
//! depth samples, plus the facet's normal from four neighbours' depths), written to
//! [`OCCLUSION_FORMAT`] for the shading pass to read with one load (`OCCLUSION_MAP`).
//!
//! Its own pass, not a function of the shading: the same work for every mode, done once, and
//! the shading shader — the largest of the frame, largest in the spectral modes — carries
//! neither the search's 52 depth loads (48 samples, 4 neighbours) nor its registers. The value
//! is the one the shading pass computed itself before (the same function on the same depth and
//! normals, stored in f32), so images are unchanged. The transmissive layer, whose depth buffer is its own, still searches
//! in its shading pass.

use super::shading::ShadingStage;
use super::{
    Draw, FullscreenPipeline, ScreenPipeline, SharedLayouts, depth_entry, pipeline_layout, uint_entry,
    view_entry,
};
use crate::error::Result;
use crate::shader;
use crate::targets::Targets;

/// The occlusion per pixel: f32, so that the shading reads exactly what it would have computed.
pub const OCCLUSION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Runs in the shading's stage ([`ShadingStage`]): a compute pass over the screen into the
/// target bound as a storage texture (`occlusion_out`), or a fullscreen triangle drawing into it.
pub struct OcclusionPass {
    input_layout: wgpu::BindGroupLayout,
    pipeline: ScreenPipeline,
}

impl OcclusionPass {
    pub fn new(device: &wgpu::Device, shared: &SharedLayouts, stage: ShadingStage) -> Result<Self> {
        let mut entries = vec![uint_entry(1), depth_entry(3)];
        if stage == ShadingStage::Compute {
            entries.push(super::storage_output_entry(4, OCCLUSION_FORMAT));
        }
        let input_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion inputs"),
            entries: &entries,
        });
        // The compute entry point's output binding is declared only where it is bound.
        let output = match stage {
            ShadingStage::Compute => include_str!("occlusion_compute.wgsl"),
            ShadingStage::Fragment => "",
        };
        let module = shader::compile(
            device,
            "occlusion",
            &[
                shader::COMMON,
                shader::HASH,
                shader::SPECTRAL,
                shader::ENVIRONMENT,
                include_str!("occlusion.wgsl"),
                include_str!("occlusion_pass.wgsl"),
                output,
            ],
        )?;
        let pipeline = shader::checked(device, "occlusion pipeline", || {
            let layout =
                pipeline_layout(device, "occlusion", &[&shared.frame, &input_layout, &shared.spectral]);
            match stage {
                ShadingStage::Compute => {
                    ScreenPipeline::compute(device, "occlusion", &layout, &module, "cs_main", &[])
                }
                ShadingStage::Fragment => ScreenPipeline::Draw(
                    FullscreenPipeline::simple("occlusion", &module, &layout, &[OCCLUSION_FORMAT])
                        .build(device),
                ),
            }
        })?;
        Ok(OcclusionPass { input_layout, pipeline })
    }

    /// Group 1: the G-buffer's normals and depth, and in the compute stage the output.
    pub fn bind_inputs(&self, device: &wgpu::Device, t: &Targets) -> wgpu::BindGroup {
        let mut entries = vec![view_entry(1, &t.gbuffer_views[1]), view_entry(3, &t.depth_view)];
        if let ScreenPipeline::Compute(_) = self.pipeline {
            entries.push(view_entry(4, &t.occlusion_view));
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("occlusion inputs"),
            layout: &self.input_layout,
            entries: &entries,
        })
    }

    /// Records the pass into `draw.target` (the targets' `occlusion_view`); `frame` and
    /// `spectral` are the shared groups 0 and 2 (the frame's camera, the environment's search
    /// radius).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        frame: &wgpu::BindGroup,
        spectral: &wgpu::BindGroup,
        draw: Draw,
    ) {
        let groups = [frame, draw.inputs, spectral];
        self.pipeline.record(encoder, "occlusion", &groups, draw);
    }
}
