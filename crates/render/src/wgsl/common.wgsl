// Shared declarations, prepended to every pass's WGSL (naga has no #include).
// `FrameUniforms` is byte for byte `uniforms::FrameUniforms` (src/layout_tests.rs checks it).

struct FrameUniforms {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    // xyz: camera position in world space.
    camera_pos: vec4<f32>,
    // Columns of the XYZ → linear-RGB matrix (white-corrected for the sampled wavelengths).
    xyz_to_rgb: mat3x3<f32>,
    // width, height, 1/width, 1/height of the render target.
    viewport: vec4<f32>,
    // 0 = rgb, 1 = naive, 2 = spectral.
    mode: u32,
    // Number of vec4 wavelength groups (N rounded up to a multiple of 4, divided by 4).
    n_groups: u32,
    n_lights: u32,
    // Linear exposure multiplier (2^EV).
    exposure: f32,
    // 0 = none, 1 = Reinhard, 2 = ACES fitted.
    tonemap: u32,
    // Resolution of the Jakob–Hanika coefficient table.
    table_res: u32,
    // Bit 0: Lambert only (base colour / π, no specular), RenderSettings::lambert.
    // Bit 1: orthographic camera (parallel view rays).
    flags: u32,
    // Salt of the stochastic transparency hash (wgsl/material.wgsl): the frame's number in the
    // accumulated mean, 0 without accumulation.
    frame_index: u32,
    // Added to the material textures' level of detail (RenderSettings::texture_lod_bias).
    lod_bias: f32,
    // Width of each node's band, nm (spectral mode), for the thin film's band mean; 0 elsewhere.
    node_spacing: f32,
    _pad1: u32,
    _pad2: u32,
};

const FLAG_LAMBERT: u32 = 1u;
const FLAG_ORTHO: u32 = 2u;

const MODE_RGB: u32 = 0u;
const MODE_NAIVE: u32 = 1u;
const MODE_SPECTRAL: u32 = 2u;
const PI: f32 = 3.14159265358979;
// The G-buffer's metallic channel of an unlit surface (KHR_materials_unlit): out of [0, 1], so
// shading can tell it apart; its colour is stored as emission.
const UNLIT_MARK: f32 = -1.0;

// Whether a camera depth is the far plane's, where nothing was drawn. The camera's depth is
// reversed, 1 near and 0 far (renderer::projection, passes::FAR_DEPTH): a nearer surface has the
// larger depth.
fn is_far_depth(depth: f32) -> bool {
    return depth <= 0.0;
}

// World position of a pixel from its (reversed) depth, y down in pixel space.
fn world_from_depth(pixel: vec2<f32>, depth: f32, f: FrameUniforms) -> vec3<f32> {
    let ndc = vec2<f32>(pixel.x * f.viewport.z * 2.0 - 1.0, 1.0 - pixel.y * f.viewport.w * 2.0);
    let h = f.inv_view_proj * vec4<f32>(ndc, depth, 1.0);
    return h.xyz / h.w;
}

// Where the view ray through `pixel` that reaches world point `p` starts: the camera position,
// or for an orthographic camera the point of the camera's plane on that (parallel) ray.
fn view_origin(pixel: vec2<f32>, p: vec3<f32>, f: FrameUniforms) -> vec3<f32> {
    let cam = f.camera_pos.xyz;
    if ((f.flags & FLAG_ORTHO) == 0u) {
        return cam;
    }
    let forward = normalize(world_from_depth(pixel, 0.0, f) - world_from_depth(pixel, 1.0, f));
    return p - forward * dot(p - cam, forward);
}

// A triangle that covers the screen; the fullscreen passes draw 3 vertices without buffers.
struct FullscreenOut {
    @builtin(position) pos: vec4<f32>,
};

// What a fragment of the fullscreen triangle receives at pixel `px`, for the compute passes that
// run a fullscreen pass's code over the screen instead (one invocation per pixel, in square
// workgroups of SCREEN_GROUP² = passes::SCREEN_GROUP²).
const SCREEN_GROUP: u32 = 8u;

fn fullscreen_at(px: vec2<u32>) -> FullscreenOut {
    var o: FullscreenOut;
    o.pos = vec4<f32>(vec2<f32>(px) + 0.5, 0.0, 1.0);
    return o;
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> FullscreenOut {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var o: FullscreenOut;
    o.pos = vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
    return o;
}

// The HDR targets are half floats (passes::HDR_FORMAT). A brighter value (a sun seen directly,
// emission of thousands) would be stored as ∞ by drivers that round to nearest and turn NaN in
// later arithmetic; clamped, it saturates at f16's largest finite value, which the host counts
// and reports (`render::passes::hdr_clipped`). Not a NaN filter: what clamp does with a NaN is
// the driver's, and a NaN is a bug to find, not to hide.
// The exposure (2^EV, `FrameUniforms::exposure`) is applied here, before the half float, not
// after it: f16 keeps nothing below 6e-8 (and is coarse below 6.1e-5) nor above 65504, so a scene
// in other units than the target's can still be brought into its range by the exposure.
// Whatever reads the target back as radiance (the see-through layer's background, the custom
// pass) divides the exposure out again.
const HDR_MAX: f32 = 65504.0;
fn hdr_out(c: vec3<f32>, exposure: f32) -> vec4<f32> {
    return vec4<f32>(clamp(c * exposure, vec3<f32>(-HDR_MAX), vec3<f32>(HDR_MAX)), 1.0);
}

// The G-buffer's second target (passes::GBUFFER_FORMATS[1], Rgba16Uint): the unit normal in
// octahedral form, each coordinate in 16 bits (at most 6.5·10⁻⁵ rad off, src/gbuffer_tests.rs;
// the three f16 components it replaced were each rounded by up to 2.4·10⁻⁴), the roughness as
// the f16 it was (`gbuffer_f16_unit`), and the material's slot
// (`MaterialUniforms::slot`: its index + 1, 0 where no surface is), which the spectral modes,
// films and indices of refraction read. One 8-byte target for the three in every mode: the
// spectral G-buffer used to write the slot to a fourth target, and a fourth target (32-bit
// then) made its pass 14 % slower than RGB's on an H200 (docs/benchmark.md).
fn gbuffer_pack_normal(n: vec3<f32>, roughness: f32, slot: u32) -> vec4<u32> {
    var o = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if (n.z < 0.0) {
        o = (1.0 - abs(o.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), o >= vec2<f32>(0.0));
    }
    // q = 32767·(o + 1): the steps are 1/32767, and 0 and ±1 (the axes) are exact.
    let q = vec2<u32>(round((clamp(o, vec2<f32>(-1.0), vec2<f32>(1.0)) + 1.0) * 32767.0));
    return vec4<u32>(q, gbuffer_f16_unit(roughness), slot);
}

// x in [0, 1] as f16 bits, rounded to nearest even as pack2x16float does, with what lies below
// f16's normal range (2⁻¹⁴) flushed to 0 (a roughness that small is a mirror either way: the
// GGX width is clamped below 2⁻⁵). In integer arithmetic: pack2x16float and unpack2x16float
// cost a CPU driver 2–3 ms each of a 1280×720 RGB frame of 67 ms.
fn gbuffer_f16_unit(x: f32) -> u32 {
    let b = bitcast<u32>(clamp(x, 0.0, 1.0));
    if (b < 0x38800000u) { return 0u; }
    return ((b + 0x0fffu + ((b >> 13u) & 1u)) >> 13u) - (112u << 10u);
}

fn gbuffer_normal(t: vec4<u32>) -> vec3<f32> {
    let o = vec2<f32>(t.xy) * (1.0 / 32767.0) - 1.0;
    var n = vec3<f32>(o, 1.0 - abs(o.x) - abs(o.y));
    let f = max(-n.z, 0.0);
    n.x += select(f, -f, n.x >= 0.0);
    n.y += select(f, -f, n.y >= 0.0);
    return normalize(n);
}

fn gbuffer_roughness(t: vec4<u32>) -> f32 {
    let h = t.z;
    return select(0.0, bitcast<f32>((h << 13u) + (112u << 23u)), h != 0u);
}

fn gbuffer_slot(t: vec4<u32>) -> u32 {
    return t.w;
}

// KHR_materials_anisotropy's direction in the G-buffer (the fourth target's z,
// passes::GBUFFER_FILM_ANISOTROPY_FORMAT): a unit t ⟂ n as its angle about n from
// `canonical_tangent(n)`, in half turns, in [0, 1] (t and −t are the same lobe). Both passes take
// n as `gbuffer_normal` decodes it from the same bits, so that the frame is the same in both.
// `canonical_tangent` is scene::fallback_tangent (Duff et al. 2017's branchless basis).
fn canonical_tangent(n: vec3<f32>) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

fn anisotropy_angle(n: vec3<f32>, t: vec3<f32>) -> f32 {
    let e1 = canonical_tangent(n);
    let x = atan2(dot(t, cross(n, e1)), dot(t, e1)) * (1.0 / PI);
    return select(x, x + 1.0, x < 0.0);
}

fn anisotropy_direction(n: vec3<f32>, angle: f32) -> vec3<f32> {
    let e1 = canonical_tangent(n);
    let phi = angle * PI;
    return normalize(cos(phi) * e1 + sin(phi) * cross(n, e1));
}
