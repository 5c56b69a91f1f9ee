//! The per-frame uniform block shared by every pass (`FrameUniforms` in `wgsl/common.wgsl`).

/// Byte-for-byte the WGSL struct (checked by `layout_tests`); `mat3x3<f32>` columns are padded
/// to 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    pub view_proj: [[f32; 4]; 4],
    pub inv_view_proj: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    pub xyz_to_rgb: [[f32; 4]; 3],
    pub viewport: [f32; 4],
    pub mode: u32,
    pub n_groups: u32,
    pub n_lights: u32,
    pub exposure: f32,
    pub tonemap: u32,
    pub table_res: u32,
    /// Bit 0: Lambert only (`RenderSettings::lambert`); bit 1: orthographic camera.
    pub flags: u32,
    /// Salt of the stochastic (`BLEND`) transparency hash: the frame's number in the running
    /// mean when accumulating, 0 otherwise (the same noise every frame).
    pub frame_index: u32,
    /// Added to the level of detail of every material texture read (`RenderSettings::texture_lod_bias`).
    pub lod_bias: f32,
    /// The width of each node's band in nm (range / N) in spectral mode, where a thin film's
    /// nodes carry its mean over the band (`film_band_reflectance4`); 0 elsewhere (the naive
    /// mode point-samples, as the paper's baseline does).
    pub node_spacing: f32,
    pub _pad: [u32; 2],
}
