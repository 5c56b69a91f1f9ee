// The occlusion pass: the screen-space horizons of occlusion.wgsl per pixel, written for the
// shading pass to read (one load) in every mode. Its inputs are the G-buffer's, at the shading
// pass's binding numbers, so that occlusion.wgsl's functions read the same textures. Prepended:
// wgsl/common.wgsl, wgsl/hash.wgsl, wgsl/spectral.wgsl, wgsl/environment.wgsl (for `env`),
// occlusion.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(1) @binding(1) var gbuf_normal: texture_2d<u32>;
@group(1) @binding(3) var gbuf_depth: texture_depth_2d;

fn occlusion_at(in: FullscreenOut) -> vec4<f32> {
    let px = vec2<i32>(in.pos.xy);
    let depth = textureLoad(gbuf_depth, px, 0);
    if (is_far_depth(depth)) {
        return vec4<f32>(1.0);
    }
    // The position and normal exactly as the shading pass has them (`surface_context`,
    // `load_surface`), so that the value it reads is the one it would have computed.
    let p = world_from_depth(in.pos.xy, depth, frame);
    let n = gbuffer_normal(textureLoad(gbuf_normal, px, 0));
    return vec4<f32>(env_occlusion(in.pos.xy, p, n));
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return occlusion_at(in);
}
