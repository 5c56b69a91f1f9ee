// Copies the renderer's display image (same size as the window) onto the swap-chain image.
// The source is sRGB-encoded rgba8 read as linear by the sampler-free load; the target view is
// an sRGB format, so the hardware re-encodes and the bytes on screen equal the bytes of
// `spectra render` / the screenshot.

@group(0) @binding(0) var src: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle covering the viewport.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(src));
    let xy = clamp(vec2<i32>(p.xy), vec2<i32>(0), size - 1);
    return vec4<f32>(textureLoad(src, xy, 0).rgb, 1.0);
}
