// The benchmark's floor for pass 2: the least a deferred RGB shading pass can do for one light
// (glTF Lambert + GGX of light 0, no shadows, no hooks, no emission). `spectra bench
// --reference` times it in place of the shading pass, so the report can say how far the real
// RGB pass is from it. Prepended: wgsl/common.wgsl, wgsl/spectral.wgsl (for `lights`).

@group(0) @binding(0) var<uniform> frame: FrameUniforms;
@group(1) @binding(0) var gbuf_base: texture_2d<f32>;
@group(1) @binding(1) var gbuf_normal: texture_2d<u32>;
@group(1) @binding(3) var gbuf_depth: texture_depth_2d;

fn shade(in: FullscreenOut) -> vec4<f32> {
    let px = vec2<i32>(in.pos.xy);
    let depth = textureLoad(gbuf_depth, px, 0);
    if (is_far_depth(depth) || frame.n_lights == 0u) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let p = world_from_depth(in.pos.xy, depth, frame);
    let b = textureLoad(gbuf_base, px, 0);
    let nr = textureLoad(gbuf_normal, px, 0);
    let n = gbuffer_normal(nr);
    let roughness = gbuffer_roughness(nr);
    let v = normalize(view_origin(in.pos.xy, p, frame) - p);
    let inc = light_incidence(0u, p);
    let nl = max(dot(n, inc.xyz), 0.0);
    let h = normalize(inc.xyz + v);
    let nv = max(dot(n, v), 1e-4);
    let nh = max(dot(n, h), 0.0);
    let a2 = max(roughness * roughness, 1e-3) * max(roughness * roughness, 1e-3);
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let spec = a2 / (PI * dd * dd) * 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2) + 1e-7);
    let f = 0.04 + 0.96 * pow(1.0 - max(dot(v, h), 0.0), 5.0);
    let rgb = (b.rgb * (1.0 - b.a) * (1.0 - f) / PI + spec * mix(vec3<f32>(f), b.rgb, b.a)) * nl * inc.w;
    return vec4<f32>(rgb * lights[0].rgb.rgb, 1.0);
}

// The entry points of either stage, as the real pass's (shading.wgsl).
@group(1) @binding(14) var shading_out: texture_storage_2d<rgba16float, write>;

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return shade(in);
}

@compute @workgroup_size(SCREEN_GROUP, SCREEN_GROUP)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (all(id.xy < textureDimensions(shading_out))) {
        textureStore(shading_out, id.xy, shade(fullscreen_at(id.xy)));
    }
}
