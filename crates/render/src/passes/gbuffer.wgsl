// Pass 1: rasterise the scene into the G-buffer. Prepended: wgsl/common.wgsl,
// wgsl/material.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
    @location(4) color: vec4<f32>,
    @location(5) uv1: vec2<f32>,
};

struct VertexOut {
    // Invariant: the transmissive layer's shading redraws the see-through meshes with the same
    // transform (`vs_layer` in passes/transmission.wgsl) and keeps the fragments whose depth is
    // not behind the G-buffer's.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) tangent: vec4<f32>,
    @location(3) color: vec4<f32>,
    @location(4) uv1: vec2<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var o: VertexOut;
    o.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    o.normal = v.normal;
    o.uv = v.uv;
    o.tangent = v.tangent;
    o.color = v.color;
    o.uv1 = v.uv1;
    return o;
}

struct GBufferOut {
    // rgb linear base colour, a metallic; a = UNLIT_MARK (negative) marks an unlit surface,
    // whose colour is then in `emission`.
    @location(0) base: vec4<f32>,
    // The unit world normal, the roughness and the material's slot (`gbuffer_pack_normal`).
    @location(1) normal: vec4<u32>,
    // rgb linear emission, a ambient occlusion (glTF occlusionTexture × strength; 1 = none),
    // applied to the environment light only.
    @location(2) emission: vec4<f32>,
};

// The normal n (unit, towards the viewer's side) bent by a tangent-space normal map's texel
// `tn_sample` (0–1 per channel) at `scale`, in the frame of the vertex tangent.
// `n` is already turned to the viewer's side; on a back face the tangent and the bitangent turn
// with it (scene::facing_tangent: all three negated, as the Khronos sample viewer does), so
// that the mapped normal there is the front's negated.
fn normal_mapped(n: vec3<f32>, tangent: vec4<f32>, side: f32, tn_sample: vec3<f32>, scale: f32) -> vec3<f32> {
    let t = normalize(tangent.xyz - n * dot(n, tangent.xyz)) * side;
    let b = cross(n, t) * tangent.w * side;
    var tn = tn_sample * 2.0 - 1.0;
    tn = vec3<f32>(tn.xy * scale, tn.z);
    return normalize(t * tn.x + b * tn.y + n * tn.z);
}

// The face's own normal (unoriented, unnormalised) where a normal map, the base's or the coat's,
// may need it (`facing_viewer`); zero for other materials, which pay nothing more. Taken before
// any discard: derivatives need uniform control flow, and `material` is uniform.
fn face_normal(v: VertexOut) -> vec3<f32> {
    if (material.params.z > 0.5 || material.coat.w > 0.5) {
        let p = world_from_depth(v.clip.xy, v.clip.z, frame);
        return cross(dpdx(p), dpdy(p));
    }
    return vec3<f32>(0.0);
}

// A mapped normal that faces away from the viewer gives way to the face's own normal, turned to
// the viewer: the path tracer's rule (its integrator's shading normal and `World::coat`), so
// that both renderers shade such pixels alike (a strong bump at a grazing view, or a texel whose
// tangent-space z is negative).
fn facing_viewer(n: vec3<f32>, face: vec3<f32>, v: VertexOut) -> vec3<f32> {
    let p = world_from_depth(v.clip.xy, v.clip.z, frame);
    let view = view_origin(v.clip.xy, p, frame) - p;
    if (dot(n, view) > 0.0 || dot(face, face) <= 0.0) {
        return n;
    }
    let f = normalize(face);
    return select(-f, f, dot(f, view) >= 0.0);
}

// `alpha_test`: the pipeline of MASK and BLEND materials (discards); opaque materials use one
// without discard, which keeps early depth testing.
fn gbuffer(v: VertexOut, front: bool, face: vec3<f32>, alpha_test: bool) -> GBufferOut {
    // Every texture is sampled before the discard (derivatives need uniform control flow).
    let base = textureSampleBias(base_color_tex, base_color_smp, material_uv(TEX_BASE, v.uv, v.uv1), frame.lod_bias)
        * material.base_color * v.color;
    let mr = textureSampleBias(metal_rough_tex, metal_rough_smp, material_uv(TEX_METAL_ROUGH, v.uv, v.uv1), frame.lod_bias);
    var emissive = textureSampleBias(emissive_tex, emissive_smp, material_uv(TEX_EMISSIVE, v.uv, v.uv1), frame.lod_bias).rgb
        * material.emissive.rgb;
    let tn_sample = textureSampleBias(normal_tex, normal_smp, material_uv(TEX_NORMAL, v.uv, v.uv1), frame.lod_bias).xyz;
    let occlusion = textureSampleBias(occlusion_tex, occlusion_smp, material_uv(TEX_OCCLUSION, v.uv, v.uv1), frame.lod_bias).r;
    if (alpha_test && alpha_discards(base.a, v.clip.xy, v.clip.z, frame.frame_index)) {
        discard;
    }
    // Single-sided materials are drawn with back faces culled; double-sided ones get the
    // normal flipped towards the viewer on back faces (glTF doubleSided).
    let side = select(-1.0, 1.0, front);
    var n = normalize(v.normal) * side;
    if (material.params.z > 0.5 && dot(v.tangent.xyz, v.tangent.xyz) > 0.0) {
        n = facing_viewer(normal_mapped(n, v.tangent, side, tn_sample, material.emissive.w), face, v);
    }
    // Emission is one-sided, towards the vertex normals, as the path tracer's and the polygon
    // lights' (docs/environment.md): the back of a double-sided lamp glowed here and was black
    // there. Only emissive materials (uniform per draw) compute the side.
    if (any(material.emissive.rgb > vec3<f32>(0.0))) {
        let p = world_from_depth(v.clip.xy, v.clip.z, frame);
        if (dot(v.normal, view_origin(v.clip.xy, p, frame) - p) <= 0.0) {
            emissive = vec3<f32>(0.0);
        }
    }
    var o: GBufferOut;
    o.base = vec4<f32>(base.rgb, clamp(material.params.x * mr.b, 0.0, 1.0));
    o.normal = gbuffer_pack_normal(n, clamp(material.params.y * mr.g, 0.0, 1.0), material.slot.x);
    let ao = 1.0 + material.params.w * (occlusion - 1.0);
    o.emission = vec4<f32>(emissive, clamp(ao, 0.0, 1.0));
    if (material.alpha.w > 0.5) {
        // KHR_materials_unlit: the base colour is what the surface shows; it reflects nothing.
        o.base = vec4<f32>(0.0, 0.0, 0.0, UNLIT_MARK);
        o.emission = vec4<f32>(base.rgb, 1.0);
    }
    return o;
}

// The extra targets' values, each sampled by one function and written by another
// (passes/gbuffer.rs `Targets::wgsl` generates each set's output struct and entry points, which
// sample every texture before `gbuffer`'s discard: derivatives need uniform control flow).

// Scenes with a thin film (KHR_materials_iridescence), a coat or a specular write the film's
// values, in RGB mode as in the spectral ones: x weight (factor × texture R; 0: no film), y the
// thickness texture's G, where the thickness lies between the material's minimum and maximum.
fn film_values(v: VertexOut) -> vec2<f32> {
    let weight = textureSampleBias(film_tex, film_smp, material_uv(TEX_FILM, v.uv, v.uv1), frame.lod_bias).r * material.film.x;
    let t = textureSampleBias(film_thickness_tex, film_thickness_smp, material_uv(TEX_FILM_THICKNESS, v.uv, v.uv1), frame.lod_bias).g;
    return vec2<f32>(clamp(weight, 0.0, 1.0), clamp(t, 0.0, 1.0));
}

fn film_target(o: GBufferOut, f: vec2<f32>) -> vec2<f32> {
    // An unlit surface (UNLIT_MARK) reflects nothing, so it has no film either.
    return select(f, vec2<f32>(0.0), o.base.a < 0.0);
}

// The transmissive layer (passes/gbuffer.rs `Fourth::Layer`): the film's values beside the
// see-through material's own, packed in one 32-bit target (`layer_values` in the shading pass) —
// x the transmission factor × its texture's R, y the volume's thickness texture's G (the share of
// the thickness factor), z and w the film's weight and thickness fraction as `film_values`.
fn transmission_values(v: VertexOut) -> vec2<f32> {
    let t = textureSampleBias(transmission_tex, transmission_smp, material_uv(TEX_TRANSMISSION, v.uv, v.uv1), frame.lod_bias).r * material.transmission.x;
    let d = textureSampleBias(volume_thickness_tex, volume_thickness_smp, material_uv(TEX_VOLUME_THICKNESS, v.uv, v.uv1), frame.lod_bias).g;
    return vec2<f32>(clamp(t, 0.0, 1.0), clamp(d, 0.0, 1.0));
}

fn layer_target(o: GBufferOut, t: vec2<f32>, f: vec2<f32>) -> u32 {
    return pack4x8unorm(vec4<f32>(t, film_target(o, f)));
}

// Scenes with a clear coat (KHR_materials_clearcoat) add its per-pixel values after the film's
// or the layer's: the coat's own normal — its normal map in the vertex tangents' frame, or the
// interpolated normal (not the base's normal map), as the extension says —, its roughness and
// its strength, packed as the normal's target is (the strength as a 16-bit fraction where the
// slot is).
struct CoatSample {
    strength: f32,
    roughness: f32,
    tn: vec3<f32>,
};

fn coat_sample(v: VertexOut) -> CoatSample {
    let c = textureSampleBias(coat_tex, coat_smp, material_uv(TEX_COAT, v.uv, v.uv1), frame.lod_bias).r;
    let r = textureSampleBias(coat_rough_tex, coat_rough_smp, material_uv(TEX_COAT_ROUGH, v.uv, v.uv1), frame.lod_bias).g;
    let tn = textureSampleBias(coat_normal_tex, coat_normal_smp, material_uv(TEX_COAT_NORMAL, v.uv, v.uv1), frame.lod_bias).xyz;
    return CoatSample(clamp(c * material.coat.x, 0.0, 1.0), clamp(r * material.coat.y, 0.0, 1.0), tn);
}

fn coat_target(o: GBufferOut, c: CoatSample, v: VertexOut, front: bool, face: vec3<f32>) -> vec4<u32> {
    let side = select(-1.0, 1.0, front);
    var n = normalize(v.normal) * side;
    if (material.coat.w > 0.5 && dot(v.tangent.xyz, v.tangent.xyz) > 0.0) {
        n = facing_viewer(normal_mapped(n, v.tangent, side, c.tn, material.coat.z), face, v);
    }
    // An unlit surface (UNLIT_MARK) reflects nothing: no coat.
    let strength = select(c.strength, 0.0, o.base.a < 0.0);
    return gbuffer_pack_normal(n, c.roughness, u32(round(strength * 65535.0)));
}

// Scenes with KHR_materials_specular add its per-pixel values after the film's (and the
// coat's) targets (passes/gbuffer.rs `Targets::specular`): rgb the F0
// colour min(F0(η)·colour factor·colour texture, 1), a the weight (factor × strength texture's
// A) — scene::specular. Materials without the extension write the plain dielectric's
// (F0, F0, F0, 1); unlit surfaces reflect nothing, whatever is written.
// 16-bit fractions (passes/mod.rs GBUFFER_SPECULAR_FORMAT).
fn specular_values(v: VertexOut) -> vec4<u32> {
    let a = textureSampleBias(specular_tex, specular_smp, material_uv(TEX_SPECULAR, v.uv, v.uv1), frame.lod_bias).a;
    let c = textureSampleBias(specular_color_tex, specular_color_smp, material_uv(TEX_SPECULAR_COLOR, v.uv, v.uv1), frame.lod_bias).rgb;
    let sp = vec4<f32>(min(material.specular.yzw * c, vec3<f32>(1.0)), clamp(material.specular.x * a, 0.0, 1.0));
    return vec4<u32>(round(clamp(sp, vec4<f32>(0.0), vec4<f32>(1.0)) * 65535.0));
}

// Scenes with KHR_materials_sheen add it after every other target (passes/gbuffer.rs
// `Targets::sheen`): rgb the colour (factor × colour texture, sRGB-decoded), a the roughness
// (factor × roughness texture's A) — scene::sheen. Materials without one write a zero colour.
fn sheen_values(v: VertexOut) -> vec4<f32> {
    let c = textureSampleBias(sheen_color_tex, sheen_color_smp, material_uv(TEX_SHEEN_COLOR, v.uv, v.uv1), frame.lod_bias).rgb;
    let r = textureSampleBias(sheen_rough_tex, sheen_rough_smp, material_uv(TEX_SHEEN_ROUGH, v.uv, v.uv1), frame.lod_bias).a;
    return clamp(vec4<f32>(material.sheen.rgb * c, material.sheen.w * r), vec4<f32>(0.0), vec4<f32>(1.0));
}

fn sheen_target(o: GBufferOut, sh: vec4<f32>) -> vec4<f32> {
    // An unlit surface (UNLIT_MARK) reflects nothing: no sheen.
    return select(sh, vec4<f32>(0.0), o.base.a < 0.0);
}

// Scenes with KHR_materials_anisotropy write it beside the film's values, in the fourth target
// widened to four channels (passes/gbuffer.rs `Targets::anisotropy`, GBUFFER_FILM_ANISOTROPY_FORMAT):
// z the direction's angle (`anisotropy_angle`, wgsl/common.wgsl), w the strength s (0: none) —
// scene::anisotropy's convention: the texture's RG (linear, [0, 1] → [−1, 1]) rotated by the
// rotation, in the vertex tangent frame about the shading normal, t0 = normalize(T − n·(n·T)),
// b0 = n × t0 · T.w; s = strength × the texture's B. The texture is read at the transmission's
// slot (TEX_ANISOTROPY), which an anisotropic material never has.
fn anisotropy_values(v: VertexOut) -> vec3<f32> {
    let c = textureSampleBias(transmission_tex, transmission_smp, material_uv(TEX_ANISOTROPY, v.uv, v.uv1), frame.lod_bias).rgb;
    // Without a texture: direction (1, 0), strength factor 1.
    return select(vec3<f32>(1.0, 0.5, 1.0), c, material.anisotropy.w > 0.5);
}

fn anisotropy_target(o: GBufferOut, c: vec3<f32>, v: VertexOut, front: bool) -> vec2<f32> {
    let s = clamp(material.anisotropy.x * c.b, 0.0, 1.0);
    // An unlit surface (UNLIT_MARK) reflects nothing: no anisotropy.
    if (s <= 0.0 || o.base.a < 0.0) {
        return vec2<f32>(0.0);
    }
    // The normal as the shading pass will decode it.
    let n = gbuffer_normal(o.normal);
    // Meshes of anisotropic materials carry tangents (MikkTSpace or scene::fallback_tangent);
    // on a back face the frame turns with the normal (scene::facing_tangent), so that the
    // direction keeps its axis on both sides.
    var tangent = v.tangent * select(-1.0, 1.0, front);
    if (dot(tangent.xyz, tangent.xyz) <= 0.0) {
        tangent = vec4<f32>(canonical_tangent(n), 1.0);
    }
    let t0 = normalize(tangent.xyz - n * dot(n, tangent.xyz));
    let b0 = cross(n, t0) * tangent.w;
    let cr = material.anisotropy.y;
    let sr = material.anisotropy.z;
    let d0 = c.rg * 2.0 - 1.0;
    var d = vec2<f32>(cr * d0.x - sr * d0.y, sr * d0.x + cr * d0.y);
    // A zero direction reads as the rotated tangent (scene::anisotropy::Anisotropy::at).
    d = select(vec2<f32>(cr, sr), d, dot(d, d) > 1e-12);
    let t = normalize(d.x * t0 + d.y * b0);
    return vec2<f32>(anisotropy_angle(n, t), s);
}

// Scenes with KHR_materials_diffuse_transmission write it in the high 16 bits of the specular's
// target (passes/gbuffer.rs `Targets::diffuse_transmission`, GBUFFER_SPECULAR_DT_FORMAT): rgb the
// colour (factor × the colour texture's RGB, sRGB-decoded), a the factor (× the factor texture's
// A) — scene::diffuse_transmission — as 16-bit fractions. Materials without one write zero.
fn diffuse_transmission_values(v: VertexOut) -> vec4<f32> {
    let d = material.diffuse_transmission;
    let c = textureSampleBias(volume_thickness_tex, volume_thickness_smp, material_uv(TEX_DIFFUSE_TRANSMISSION_COLOR, v.uv, v.uv1), frame.lod_bias);
    let a = textureSampleBias(transmission_tex, transmission_smp, material_uv(TEX_DIFFUSE_TRANSMISSION, v.uv, v.uv1), frame.lod_bias).a;
    // A negative factor: its texture is the colour's (the extension's packing: RGB and A).
    let t = abs(d.w) * select(a, c.a, d.w < 0.0);
    return clamp(vec4<f32>(d.rgb * c.rgb, t), vec4<f32>(0.0), vec4<f32>(1.0));
}

fn diffuse_transmission_target(o: GBufferOut, dt: vec4<f32>) -> vec4<u32> {
    // An unlit surface (UNLIT_MARK) transmits nothing.
    let d = select(dt, vec4<f32>(0.0), o.base.a < 0.0);
    return vec4<u32>(round(d * 65535.0));
}
