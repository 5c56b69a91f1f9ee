// Shadow pass: depth only, rendered from one shadow-casting light into one layer of the
// shadow-map array. Prepended: wgsl/material.wgsl (group 1, for MASK and BLEND materials).

struct ShadowLayer {
    view_proj: mat4x4<f32>,
    // x: salt of the stochastic transparency hash (frame index and layer), yzw unused.
    params: vec4<u32>,
};

@group(0) @binding(0) var<uniform> layer: ShadowLayer;

struct ShadowIn {
    @location(0) position: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(4) color: vec4<f32>,
    @location(5) uv1: vec2<f32>,
};

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) uv1: vec2<f32>,
    @location(2) alpha: f32,
};

@vertex
fn vs_shadow(v: ShadowIn) -> ShadowOut {
    var o: ShadowOut;
    o.clip = layer.view_proj * vec4<f32>(v.position, 1.0);
    o.uv = v.uv;
    o.uv1 = v.uv1;
    o.alpha = v.color.a;
    return o;
}

// MASK and BLEND materials: the same coverage as in the G-buffer (base colour × texture ×
// COLOR_0 alpha against the cutoff, or kept with probability alpha), so light passes where the
// camera sees through. Opaque materials use a pipeline without a fragment stage.
@fragment
fn fs_shadow_alpha(v: ShadowOut) {
    let a = textureSample(base_color_tex, base_color_smp, material_uv(TEX_BASE, v.uv, v.uv1)).a
        * material.base_color.a * v.alpha;
    if (alpha_discards(a, v.clip.xy, v.clip.z, layer.params.x)) {
        discard;
    }
}
