// Pass 3: the per-pixel custom hook. Prepended: wgsl/common.wgsl, wgsl/spectral.wgsl,
// wgsl/custom_api.wgsl, then the custom shader.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(1) @binding(0) var hdr_in: texture_2d<f32>;
@group(1) @binding(1) var gbuf_normal: texture_2d<f32>;
@group(1) @binding(2) var gbuf_depth: texture_depth_2d;

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.pos.xy);
    let depth = textureLoad(gbuf_depth, px, 0);
    let background = depth >= 1.0;
    let p = world_from_depth(in.pos.xy, depth, frame);
    let to_p = p - frame.camera_pos.xyz;
    var ctx: SurfaceContext;
    ctx.world_pos = p;
    ctx.view_dir = normalize(to_p);
    ctx.distance = select(length(to_p), 0.0, background);
    ctx.background = background;
    ctx.pixel = vec2<u32>(px);
    ctx.normal = select(normalize(textureLoad(gbuf_normal, px, 0).xyz), vec3<f32>(0.0), background);
    return custom_pixel(textureLoad(hdr_in, px, 0), ctx);
}
