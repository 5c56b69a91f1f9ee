// Pass 4: tone mapping (the exposure is in the HDR values already: `hdr_out`); the sRGB
// encoding is done by the rgba8unorm-srgb target.
// Prepended: wgsl/common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(1) @binding(0) var hdr: texture_2d<f32>;

// Narkowicz 2015 fit of the ACES RRT+ODT (input pre-scaled by 0.6 as in the original post).
fn aces_fitted(x: vec3<f32>) -> vec3<f32> {
    let v = x * 0.6;
    return clamp((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn tonemap(c: vec3<f32>, op: u32) -> vec3<f32> {
    if (op == 1u) {
        return c / (1.0 + c);
    }
    if (op == 2u) {
        return aces_fitted(c);
    }
    return c;
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let c = textureLoad(hdr, vec2<i32>(in.pos.xy), 0).rgb;
    return vec4<f32>(clamp(tonemap(max(c, vec3<f32>(0.0)), frame.tonemap), vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
