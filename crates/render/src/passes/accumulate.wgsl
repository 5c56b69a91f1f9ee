// Optional pass between custom and post: the running mean of the linear HDR image over frames.
// Prepended: wgsl/common.wgsl.

struct AccumUniforms {
    // 1/k for the k-th frame since the last reset (1 on the first, which discards `prev`).
    weight: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var prev: texture_2d<f32>;
@group(0) @binding(2) var<uniform> accum: AccumUniforms;

struct AccumOut {
    // The new mean in f32 (next frame's `prev`): an f16 mean would drift by rounding each frame.
    @location(0) mean: vec4<f32>,
    // The same mean in the HDR format, which post reads like the custom pass's output.
    @location(1) display: vec4<f32>,
};

@fragment
fn fs_main(in: FullscreenOut) -> AccumOut {
    let p = vec2<i32>(in.pos.xy);
    let cur = textureLoad(hdr, p, 0);
    var m = cur;
    // Branch rather than mix() with weight 1: a stale NaN/inf in `prev` must not survive a reset.
    if (accum.weight < 1.0) {
        let old = textureLoad(prev, p, 0);
        m = old + (cur - old) * accum.weight;
    }
    var o: AccumOut;
    o.mean = m;
    o.display = m;
    return o;
}
