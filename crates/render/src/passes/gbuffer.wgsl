// Pass 1: rasterise the scene into the G-buffer. Prepended: wgsl/common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;

// Layout matches `MaterialUniforms` in src/scene_gpu.rs.
struct MaterialUniforms {
    base_color: vec4<f32>,
    // rgb emissive (linear, strength applied), w = normal scale.
    emissive: vec4<f32>,
    // x metallic, y roughness, z = 1 when the mesh has tangents and a normal map, w occlusion
    // strength (0 without an occlusion texture).
    params: vec4<f32>,
};

@group(1) @binding(0) var<uniform> material: MaterialUniforms;
@group(1) @binding(1) var base_color_tex: texture_2d<f32>;
@group(1) @binding(2) var metal_rough_tex: texture_2d<f32>;
@group(1) @binding(3) var normal_tex: texture_2d<f32>;
@group(1) @binding(4) var emissive_tex: texture_2d<f32>;
@group(1) @binding(5) var material_sampler: sampler;
@group(1) @binding(6) var occlusion_tex: texture_2d<f32>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) tangent: vec4<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var o: VertexOut;
    o.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    o.normal = v.normal;
    o.uv = v.uv;
    o.tangent = v.tangent;
    return o;
}

struct GBufferOut {
    // rgb linear base colour, a metallic.
    @location(0) base: vec4<f32>,
    // xyz unit world normal, w roughness.
    @location(1) normal: vec4<f32>,
    // rgb linear emission, a ambient occlusion (glTF occlusionTexture × strength; 1 = none),
    // applied to the environment light only.
    @location(2) emission: vec4<f32>,
};

@fragment
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> GBufferOut {
    let base = textureSample(base_color_tex, material_sampler, v.uv) * material.base_color;
    let mr = textureSample(metal_rough_tex, material_sampler, v.uv);
    let emissive = textureSample(emissive_tex, material_sampler, v.uv).rgb * material.emissive.rgb;
    // Surfaces are drawn two-sided (Cornell-style scenes are seen from inside): flip the
    // normal towards the viewer on back faces.
    let side = select(-1.0, 1.0, front);
    var n = normalize(v.normal) * side;
    if (material.params.z > 0.5 && dot(v.tangent.xyz, v.tangent.xyz) > 0.0) {
        let t = normalize(v.tangent.xyz - n * dot(n, v.tangent.xyz)) * side;
        let b = cross(n, t) * v.tangent.w;
        var tn = textureSample(normal_tex, material_sampler, v.uv).xyz * 2.0 - 1.0;
        tn = vec3<f32>(tn.xy * material.emissive.w, tn.z);
        n = normalize(t * tn.x + b * tn.y + n * tn.z);
    }
    var o: GBufferOut;
    o.base = vec4<f32>(base.rgb, clamp(material.params.x * mr.b, 0.0, 1.0));
    o.normal = vec4<f32>(n, clamp(material.params.y * mr.g, 0.0, 1.0));
    let ao = 1.0 + material.params.w * (textureSample(occlusion_tex, material_sampler, v.uv).r - 1.0);
    o.emission = vec4<f32>(emissive, clamp(ao, 0.0, 1.0));
    return o;
}
