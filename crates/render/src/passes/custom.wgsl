// Pass 3: the per-pixel custom hook. Prepended: wgsl/common.wgsl, wgsl/spectral.wgsl,
// wgsl/custom_api.wgsl, then the custom shader.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(1) @binding(0) var hdr_in: texture_2d<f32>;
@group(1) @binding(1) var gbuf_normal: texture_2d<u32>;
@group(1) @binding(2) var gbuf_depth: texture_depth_2d;

// Pass 3 has no shadow maps: every light counts as unoccluded here (the custom-shader API's
// `light_visibility` is only meaningful in the pass-2 hooks).
fn light_visibility(li: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    return 1.0;
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.pos.xy);
    var ctx = surface_context(in.pos.xy, textureLoad(gbuf_depth, px, 0), frame);
    if (!ctx.background) {
        ctx.normal = gbuffer_normal(textureLoad(gbuf_normal, px, 0));
    }
    // The hook sees radiance: the target holds it times the exposure (`hdr_out`).
    let held = textureLoad(hdr_in, px, 0);
    let c = custom_pixel(vec4<f32>(held.rgb / frame.exposure, held.a), ctx);
    return vec4<f32>(hdr_out(c.rgb, frame.exposure).rgb, c.a);
}
