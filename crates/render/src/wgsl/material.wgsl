// A material (bind group 1 of the G-buffer and shadow passes): factors, sixteen texture slots each
// with its own sampler, UV set and KHR_texture_transform, and the alpha mode. Prepended to
// passes/gbuffer.wgsl and passes/shadow.wgsl.

// Layout matches `MaterialUniforms` in src/scene_gpu.rs.
struct MaterialUniforms {
    base_color: vec4<f32>,
    // rgb emissive (linear, strength applied), w = normal scale.
    emissive: vec4<f32>,
    // x metallic, y roughness, z = 1 when the mesh has tangents and a normal map, w occlusion
    // strength (0 without an occlusion texture).
    params: vec4<f32>,
    // x alpha mode (ALPHA_*), y alpha cutoff, z = 1 when double-sided, w = 1 when unlit.
    alpha: vec4<f32>,
    // Per texture slot (TEX_*), two rows of its UV transform: (m00, m01, m02, UV set),
    // (m10, m11, m12, 0); uv' = M · (u, v, 1).
    uv_rows: array<vec4<f32>, 32>,
    // x: the material's index + 1 (`MaterialUniforms::slot`), written by the G-buffer beside the normal.
    slot: vec4<u32>,
    // KHR_materials_iridescence: x factor (0: none), y film index, z/w thickness min/max (nm).
    film: vec4<f32>,
    // KHR_materials_transmission: x factor (0: opaque).
    transmission: vec4<f32>,
    // KHR_materials_clearcoat: x strength (0: none), y roughness, z normal scale, w = 1 with a
    // coat normal map.
    coat: vec4<f32>,
    // KHR_materials_specular: x the weight, yzw F0(η) × the colour factor; (1, F0, F0, F0)
    // without.
    specular: vec4<f32>,
    // KHR_materials_sheen: rgb the colour factor, w the roughness factor; zero without.
    sheen: vec4<f32>,
    // KHR_materials_anisotropy: x the strength (0: none), y/z the rotation's cosine and sine,
    // w = 1 with a texture (at TEX_ANISOTROPY, the transmission's slot); zero without.
    anisotropy: vec4<f32>,
    // KHR_materials_diffuse_transmission: rgb the colour factor, w the factor (0: none),
    // negative where the factor's texture is read from the colour's slot's A; zero without.
    diffuse_transmission: vec4<f32>,
};

const ALPHA_OPAQUE: u32 = 0u;
const ALPHA_MASK: u32 = 1u;
const ALPHA_BLEND: u32 = 2u;

const TEX_BASE: u32 = 0u;
const TEX_METAL_ROUGH: u32 = 1u;
const TEX_NORMAL: u32 = 2u;
const TEX_EMISSIVE: u32 = 3u;
const TEX_OCCLUSION: u32 = 4u;
const TEX_FILM: u32 = 5u;
const TEX_FILM_THICKNESS: u32 = 6u;
const TEX_TRANSMISSION: u32 = 7u;
// The anisotropy's texture shares the transmission's slot (and binding): only opaque materials
// draw an anisotropy (src/scene_gpu.rs `texture_refs`).
const TEX_ANISOTROPY: u32 = 7u;
const TEX_VOLUME_THICKNESS: u32 = 8u;
// A diffuse transmission's textures take the transmission's and the volume thickness's slots
// (opaque materials only; src/scene_gpu.rs `diffuse_transmission_slots`).
const TEX_DIFFUSE_TRANSMISSION: u32 = 7u;
const TEX_DIFFUSE_TRANSMISSION_COLOR: u32 = 8u;
const TEX_COAT: u32 = 9u;
const TEX_COAT_ROUGH: u32 = 10u;
const TEX_COAT_NORMAL: u32 = 11u;
const TEX_SPECULAR: u32 = 12u;
const TEX_SPECULAR_COLOR: u32 = 13u;
const TEX_SHEEN_COLOR: u32 = 14u;
const TEX_SHEEN_ROUGH: u32 = 15u;

@group(1) @binding(0) var<uniform> material: MaterialUniforms;
@group(1) @binding(1) var base_color_tex: texture_2d<f32>;
@group(1) @binding(2) var metal_rough_tex: texture_2d<f32>;
@group(1) @binding(3) var normal_tex: texture_2d<f32>;
@group(1) @binding(4) var emissive_tex: texture_2d<f32>;
@group(1) @binding(5) var occlusion_tex: texture_2d<f32>;
@group(1) @binding(6) var film_tex: texture_2d<f32>;
@group(1) @binding(7) var film_thickness_tex: texture_2d<f32>;
@group(1) @binding(8) var transmission_tex: texture_2d<f32>;
@group(1) @binding(9) var volume_thickness_tex: texture_2d<f32>;
@group(1) @binding(10) var coat_tex: texture_2d<f32>;
@group(1) @binding(11) var coat_rough_tex: texture_2d<f32>;
@group(1) @binding(12) var coat_normal_tex: texture_2d<f32>;
@group(1) @binding(13) var specular_tex: texture_2d<f32>;
@group(1) @binding(14) var specular_color_tex: texture_2d<f32>;
@group(1) @binding(15) var sheen_color_tex: texture_2d<f32>;
@group(1) @binding(16) var sheen_rough_tex: texture_2d<f32>;
@group(1) @binding(17) var base_color_smp: sampler;
@group(1) @binding(18) var metal_rough_smp: sampler;
@group(1) @binding(19) var normal_smp: sampler;
@group(1) @binding(20) var emissive_smp: sampler;
@group(1) @binding(21) var occlusion_smp: sampler;
@group(1) @binding(22) var film_smp: sampler;
@group(1) @binding(23) var film_thickness_smp: sampler;
@group(1) @binding(24) var transmission_smp: sampler;
@group(1) @binding(25) var volume_thickness_smp: sampler;
@group(1) @binding(26) var coat_smp: sampler;
@group(1) @binding(27) var coat_rough_smp: sampler;
@group(1) @binding(28) var coat_normal_smp: sampler;
@group(1) @binding(29) var specular_smp: sampler;
@group(1) @binding(30) var specular_color_smp: sampler;
@group(1) @binding(31) var sheen_color_smp: sampler;
@group(1) @binding(32) var sheen_rough_smp: sampler;

// The texture coordinates of slot `slot`: its UV set, transformed.
fn material_uv(slot: u32, uv0: vec2<f32>, uv1: vec2<f32>) -> vec2<f32> {
    let r0 = material.uv_rows[2u * slot];
    let r1 = material.uv_rows[2u * slot + 1u];
    let uv = vec3<f32>(select(uv0, uv1, r0.w > 0.5), 1.0);
    return vec2<f32>(dot(r0.xyz, uv), dot(r1.xyz, uv));
}

// A uniform number in [0, 1) from a pixel, its depth (so that stacked surfaces are
// independent) and a salt (the frame index when accumulating, and the shadow layer).
fn coverage_hash(pixel: vec2<f32>, depth: f32, salt: u32) -> f32 {
    let p = vec2<u32>(pixel);
    let h = pcg_hash(p.x ^ pcg_hash(p.y ^ pcg_hash(salt ^ pcg_hash(bitcast<u32>(depth)))));
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// Whether a fragment of coverage `alpha` (base colour × texture × COLOR_0 alpha) is absent:
// MASK below the cutoff; BLEND stochastically, kept with probability alpha (hashed: the same
// pixel, depth and salt always give the same answer).
fn alpha_discards(alpha: f32, pixel: vec2<f32>, depth: f32, salt: u32) -> bool {
    let mode = u32(material.alpha.x + 0.5);
    if (mode == ALPHA_MASK) {
        return alpha < material.alpha.y;
    }
    if (mode == ALPHA_BLEND) {
        return coverage_hash(pixel, depth, salt) >= alpha;
    }
    return false;
}
