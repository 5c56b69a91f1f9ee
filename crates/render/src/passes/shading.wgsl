// Pass 2: spectral (or RGB) shading of the G-buffer into the HDR target.
// Prepended: wgsl/common.wgsl, wgsl/spectral.wgsl, wgsl/environment.wgsl, wgsl/film.wgsl,
// wgsl/custom_api.wgsl,
// then the custom shader.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;

@group(1) @binding(0) var gbuf_base: texture_2d<f32>;
// Normal, roughness and material slot, packed (`gbuffer_normal`, wgsl/common.wgsl).
@group(1) @binding(1) var gbuf_normal: texture_2d<u32>;
@group(1) @binding(2) var gbuf_emission: texture_2d<f32>;
@group(1) @binding(3) var gbuf_depth: texture_depth_2d;
@group(1) @binding(4) var shadow_maps: texture_depth_2d_array;
@group(1) @binding(5) var shadow_sampler: sampler_comparison;

// MAX_LIGHTS, MAX_SHADOWS and NO_SHADOW are the Rust constants of src/scene_gpu.rs and
// src/passes/shadow.rs; src/layout_tests.rs checks them and the structs below.
const MAX_LIGHTS: u32 = 32u;
const MAX_SHADOWS: u32 = 32u;
// Value of `layer_of_light` for a light without a shadow map.
const NO_SHADOW: u32 = 0xffffffffu;

// Features a scene may not need, set per pipeline (`Variant` in src/passes/shading.rs): without
// them the driver compiles the shader without their code.
override HAS_POLYGONS: bool = true;
override HAS_ENV: bool = true;
// A material with a thin film (KHR_materials_iridescence): the G-buffer's film target is read,
// and filmed pixels take the film's Fresnel term (every mode).
override HAS_FILM: bool = true;
// A dielectric whose index is not glTF's 1.5 (KHR_materials_ior): its F0 comes from the
// material's record (every mode reads the G-buffer's material slot then).
override HAS_IOR: bool = true;
// A material with a clear coat (KHR_materials_clearcoat): the G-buffer's coat target is read,
// and coated pixels layer the coat over everything under it (every mode).
override HAS_COAT: bool = true;
// A material with a specular strength or colour (KHR_materials_specular): the G-buffer's
// specular target is read (every mode); a tinted F0 takes the film's per-node path.
override HAS_SPECULAR: bool = true;
// A material with a sheen (KHR_materials_sheen, wgsl/sheen.wgsl): the G-buffer's sheen target is
// read and each light's sheen lobe added, the base scaled by what the sheen leaves (every mode).
override HAS_SHEEN: bool = true;
// A material with an anisotropy (KHR_materials_anisotropy, scene::anisotropy): the film's target
// carries it (gbuffer.wgsl), and the base's specular lobe is anisotropic GGX for every light,
// the environment's lobe and polygon lights' its isotropic stand-in (every mode).
override HAS_ANISOTROPY: bool = true;
// A material with a diffuse transmission (KHR_materials_diffuse_transmission,
// scene::diffuse_transmission): the specular's target carries it (gbuffer.wgsl), the reflected
// diffuse loses its share, and lights and the environment on the far side of the surface reach
// the viewer through its Lambertian lobe (every mode).
override HAS_DIFFUSE_TRANSMISSION: bool = true;

// The diffuse transmission at a pixel: its share t of the diffuse (0: none) and its colour.
struct DiffTrans {
    t: f32,
    color: vec3<f32>,
    // The colour's coefficients (the spectral modes'; fetched once per pixel).
    coeffs: vec3<f32>,
};

fn no_dt() -> DiffTrans {
    return DiffTrans(0.0, vec3<f32>(0.0), vec3<f32>(0.0));
}

// None without diffuse transmissions in the scene, on unlit surfaces and in the Lambert-only
// comparison mode (whose BRDF is the reflected Lambertian alone).
fn load_dt(px: vec2<i32>, s: GSurface) -> DiffTrans {
    if (!HAS_DIFFUSE_TRANSMISSION || s.unlit || lambert_only()) {
        return no_dt();
    }
    let d = vec4<f32>(textureLoad(layer_packed, px, 0) >> vec4<u32>(16u)) * (1.0 / 65535.0);
    if (d.a <= 0.0) {
        return no_dt();
    }
    return DiffTrans(d.a, d.rgb, vec3<f32>(0.0));
}

// What the reflected diffuse keeps: 1 − t (exactly 1 without a diffuse transmission).
fn dt_keep(d: DiffTrans) -> f32 {
    if (!HAS_DIFFUSE_TRANSMISSION) {
        return 1.0;
    }
    return 1.0 - d.t;
}

// One light's transmitted diffuse at a surface whose light is on the far side of n, per unit
// colour: t·(1 − metallic)·(1 − w·F(v·h'))/π·|n·l|·E·visibility, the dielectric's weighting of
// its reflected diffuse with the light mirrored through the surface (h' the half vector of v and
// the mirrored l, as the Khronos sample viewer takes it), times the sheen's albedo scaling at the
// mirrored direction. The shadow lookup is offset towards the far side (−n): the surface does not
// shadow the light that crosses it, what lies between it and the light does. Polygon lights: the
// exact clipped cosine over the polygon on the far side, the Fresnel term at its centroid's
// mirrored direction. Zero where the light is on the near side or does not reach p.
fn dt_light(li: u32, p: vec3<f32>, s: GSurface, v: vec3<f32>, d: DiffTrans, sh: SheenSurface) -> f32 {
    let n = s.normal;
    var wi: vec3<f32>;
    var e = 0.0;
    if (HAS_POLYGONS && u32(lights[li].pos_kind.w) == 3u) {
        if (dot(p - polygon_vertex(li, 0u), polygon_normal(li)) <= 0.0) { return 0.0; }
        let g = polygon_cosine(li, p, ltc_frame(-n, v));
        if (g <= 0.0) { return 0.0; }
        wi = normalize(polygon_centroid(li) - p);
        e = g;
    } else {
        let inc = light_incidence(li, p);
        wi = inc.xyz;
        let nl = dot(n, wi);
        if (nl >= 0.0 || inc.w <= 0.0) { return 0.0; }
        e = -nl * inc.w;
    }
    e *= light_visibility(li, p, -n);
    let lm = wi - 2.0 * dot(n, wi) * n;
    let vh = max(dot(v, normalize(lm + v)), 0.0);
    let fres = pow(1.0 - vh, 5.0);
    var k = e * d.t * (1.0 - s.metallic) * (1.0 - s.spec_w * (s.f0 + (1.0 - s.f0) * fres)) / PI;
    if (HAS_SHEEN && sh.on) {
        k *= sheen_light(sh, n, v, lm, 0.0).y;
    }
    return k;
}

// The environment's transmitted diffuse per unit colour: the irradiance about −n (the far side's
// hemisphere) times t·(1 − metallic)·(1 − w·F̄(n·v))/π, the reflected diffuse's weighting
// (`env_terms_keep`), and the sheen's scaling of the base. Occluded by the material's occlusion
// texture only: the screen-space horizons are the near side's.
fn dt_env(s: GSurface, v: vec3<f32>, d: DiffTrans, sh: SheenSurface) -> vec4<f32> {
    let nv = max(dot(s.normal, v), 1e-4);
    var k = d.t * (1.0 - s.metallic) * (1.0 - s.spec_w * fresnel_diffuse(s.f0, nv)) / PI * s.occlusion;
    if (HAS_SHEEN && sh.on) {
        k *= sheen_env(sh).x;
    }
    return env_irradiance_at(-s.normal) * k;
}

// The anisotropy at a pixel: the unit direction t ⟂ n along which the lobe is stretched and the
// strength s (0: an isotropic lobe).
struct Aniso {
    t: vec3<f32>,
    s: f32,
};

fn no_aniso() -> Aniso {
    return Aniso(vec3<f32>(1.0, 0.0, 0.0), 0.0);
}

// None without anisotropies in the scene, on unlit surfaces and in the Lambert-only comparison
// mode (which has no specular lobe).
fn load_aniso(px: vec2<i32>, s: GSurface) -> Aniso {
    if (!HAS_ANISOTROPY || s.unlit || lambert_only()) {
        return no_aniso();
    }
    let f = textureLoad(gbuf_film, px, 0).zw;
    if (f.y <= 0.0) {
        return no_aniso();
    }
    return Aniso(anisotropy_direction(s.normal, f.x), f.y);
}

// The isotropic lobe that stands in for an anisotropic one where this renderer has no anisotropic
// form (the environment's split sum, its prefiltered radiance and directional albedo alike, and
// polygon lights' LTC): α = √((α_t² + α_b²)/2), the root mean square of the two widths, as a
// perceptual roughness √α. Its directional albedo is the anisotropic lobe's within 0.057 for
// views up to 0.8 rad from n and 0.165 at 1.3 rad, where the lobe's albedo depends on the view's
// azimuth about t (0.52–0.75 at α 0.25, s = 1), which no isotropic stand-in follows (f64
// quadrature at α 0.01, 0.09, 0.25, s 0.5 and 1, azimuths 0, 45°, 90°; the base's own roughness
// was up to 0.47 too high, 0.99 for 0.53). Against the path tracer's lobe on the Khronos assets it
// did better than the Khronos sample viewer's bent normal (docs/realtime-gltf.md, "Anisotropy").
// `roughness` itself without an anisotropy.
fn anisotropy_iso_roughness(a: Aniso, roughness: f32) -> f32 {
    if (!HAS_ANISOTROPY || a.s <= 0.0) {
        return roughness;
    }
    let alpha = max(roughness * roughness, 1e-3);
    let at = alpha + (1.0 - alpha) * a.s * a.s;
    return sqrt(sqrt(0.5 * (at * at + alpha * alpha)));
}

// The sheen at a pixel (gbuffer.wgsl; bound where the see-through layer has its background,
// which a sheen never needs): rgb the colour, a the roughness (scene::sheen).
fn sheen_at(px: vec2<i32>) -> vec4<f32> {
    return textureLoad(background, px, 0);
}

// The pixel's sheen, seen from v: none without sheens in the scene, on unlit surfaces and in
// the Lambert-only comparison mode.
fn load_sheen(px: vec2<i32>, s: GSurface, v: vec3<f32>) -> SheenSurface {
    if (!HAS_SHEEN || s.unlit || lambert_only()) {
        return no_sheen();
    }
    let t = sheen_at(px);
    return sheen_surface(t.rgb, t.a, s.normal, v);
}

// The unit direction from p towards light li (an emissive polygon's centroid: the sheen's
// lobe and share are taken there, the light's irradiance from the polygon's exact form).
fn light_dir(li: u32, p: vec3<f32>) -> vec3<f32> {
    if (HAS_POLYGONS && u32(lights[li].pos_kind.w) == 3u) {
        return normalize(polygon_centroid(li) - p);
    }
    return light_incidence(li, p).xyz;
}

fn shading_env() -> bool {
    return HAS_ENV && env_enabled();
}

// Byte for byte `ShadowUniforms` in src/passes/shadow.rs.
struct ShadowUniforms {
    view_proj: array<mat4x4<f32>, MAX_SHADOWS>,
    // x: normal-offset bias in world units.
    bias: array<vec4<f32>, MAX_SHADOWS>,
    // Shadow-map layer of light i at [i / 4][i % 4], or NO_SHADOW (8 = MAX_LIGHTS / 4).
    layer_of_light: array<vec4<u32>, 8>,
};
@group(1) @binding(6) var<uniform> shadows: ShadowUniforms;
// The films: x weight (0: none), y the thickness between the material's minimum and maximum
// (gbuffer.wgsl); in scenes with an anisotropy z and w its angle and strength (`load_aniso`).
@group(1) @binding(9) var gbuf_film: texture_2d<f32>;
// The coats: normal, roughness and strength, packed as the normal's target (gbuffer.wgsl).
@group(1) @binding(8) var gbuf_coat: texture_2d<u32>;
// The specular at a pixel (gbuffer.wgsl; bound where the see-through layer has its packed
// target, `layer_packed`, which a specular never needs): rgb the F0 colour, a the weight
// (scene::specular).
fn specular_at(px: vec2<i32>) -> vec4<f32> {
    var t = textureLoad(layer_packed, px, 0);
    if (HAS_DIFFUSE_TRANSMISSION) {
        // The high 16 bits are the diffuse transmission's (`load_dt`).
        t &= vec4<u32>(0xffffu);
    }
    return vec4<f32>(t) * (1.0 / 65535.0);
}

// The clear coat at a pixel (KHR_materials_clearcoat; scene::clearcoat holds the rule both
// renderers follow): its normal and roughness, and w = strength·F(|v·n_c|) (Schlick, F0 0.04),
// the coat's share of what leaves the surface — 1 − w of everything under it (reflection,
// emission, what a see-through material transmits) gets through. The weight does not depend on λ, so the coat reflects every
// wavelength of the light alike. None (w = 0) without coats in the scene, on unlit surfaces and
// in the Lambert-only comparison mode (whose BRDF has no Fresnel term).
struct Coat {
    normal: vec3<f32>,
    roughness: f32,
    w: f32,
};

fn no_coat() -> Coat {
    return Coat(vec3<f32>(0.0, 0.0, 1.0), 0.0, 0.0);
}

fn load_coat(px: vec2<i32>, v: vec3<f32>, unlit: bool) -> Coat {
    if (!HAS_COAT || unlit || lambert_only()) {
        return no_coat();
    }
    let t = textureLoad(gbuf_coat, px, 0);
    // The strength is a 16-bit fraction where the normal's target has the slot.
    let strength = f32(gbuffer_slot(t)) * (1.0 / 65535.0);
    if (strength <= 0.0) {
        return no_coat();
    }
    let n = gbuffer_normal(t);
    let m = 1.0 - min(abs(dot(n, v)), 1.0);
    let m2 = m * m;
    return Coat(n, gbuffer_roughness(t), strength * (0.04 + 0.96 * m2 * m2 * m));
}

// The coat's reflection of the environment per unit strength of w: the prefiltered radiance
// along its mirror direction at its roughness, times the split sum's directional albedo of a
// lobe without Fresnel term (A + B; the Fresnel term is in w).
fn env_coat(c: Coat, v: vec3<f32>) -> vec4<f32> {
    let l = env_lobes(c.normal, v, c.roughness);
    return l.spec * (l.ab.x + l.ab.y);
}

// The spectral capture (`Renderer::set_spectral_capture`, `spectra render --spectral-out`): per
// pixel and group of four nodes, each node's radiance in weighted form summed over X, Y and Z
// (`capture[pixel * n_groups + group]`); the host divides by the observer's sum at the node.
// Written only by the pipeline with CAPTURE set (below); otherwise a dummy buffer is bound.
@group(1) @binding(7) var<storage, read_write> capture: array<vec4<f32>>;

fn capture_group(px: vec2<i32>, g: u32, m: mat3x4<f32>) {
    let pixel = u32(px.y) * u32(frame.viewport.x) + u32(px.x);
    capture[pixel * frame.n_groups + g] = m[0] + m[1] + m[2];
}

// Fraction of a light that reaches `p` according to its shadow map `layer` (1 outside the
// light's frustum): one hardware 2×2 comparison sample, or for an emissive polygon's layer
// (whose light has a size) the percentage-closer soft shadow of `soft_visibility`.
fn shadow_visibility(layer: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let b = shadows.bias[layer];
    let s = shadows.view_proj[layer] * vec4<f32>(p + n * b.x, 1.0);
    if (s.w <= 0.0) { return 1.0; }
    let ndc = s.xyz / s.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || ndc.z > 1.0 || ndc.z < 0.0) {
        return 1.0;
    }
    if (HAS_POLYGONS && b.w > 0.0) {
        return soft_visibility(layer, p + n * b.x, n, uv, ndc.z, s.w, b);
    }
    return textureSampleCompareLevel(shadow_maps, shadow_sampler, uv, i32(layer), ndc.z);
}

// tan(½ · 150°): the emissive polygons' shadow frusta (src/passes/shadow.rs `EMITTER_FOV`).
const EMITTER_TAN_HALF_FOV: f32 = 3.7320508;
// Depth texels read in the blocker search (8 measured worse: block ΔE2000 0.44 against 0.24
// for the side-1 light of the lighting test), and comparison samples averaged over the penumbra.
const BLOCKER_SAMPLES: u32 = 16u;
const SOFT_SAMPLES: u32 = 16u;

// Point k of n on a Vogel spiral over the unit disc, turned by `turn` radians.
fn spiral(k: u32, n: u32, turn: f32) -> vec2<f32> {
    let r = sqrt((f32(k) + 0.5) / f32(n));
    let a = f32(k) * 2.3999632 + turn;
    return r * vec2<f32>(cos(a), sin(a));
}

// Map coordinates and depth of world point q in shadow layer `layer`.
fn shadow_coords(layer: u32, q: vec3<f32>) -> vec3<f32> {
    let s = shadows.view_proj[layer] * vec4<f32>(q, 1.0);
    let ndc = s.xyz / s.w;
    return vec3<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z);
}

// Percentage-closer soft shadows (Fernando 2005) for a light of radius b.w (the disc of the
// polygon's area) at the apex of a perspective shadow map whose depth range is b.y … b.z: the
// mean depth of the blockers that can hide some of the disc from the receiver (world point q
// with normal n, map coordinates uv, map depth z, depth d_r) sets the penumbra,
// (R / 2·tan ½fov)·(1/d_b − 1/d_r) in map units, over which comparison samples are averaged.
// Each sample compares with the receiver's own plane at its offset (receiver-plane depth bias),
// so a surface seen obliquely from the light does not shadow itself.
fn soft_visibility(layer: u32, q: vec3<f32>, n: vec3<f32>, uv: vec2<f32>, z: f32, d_r: f32, b: vec4<f32>) -> f32 {
    let near = b.y;
    let far = b.z;
    let size = vec2<f32>(textureDimensions(shadow_maps).xy);
    // The receiver's plane in map space: depth as a linear function of the map offset.
    var t1 = cross(n, vec3<f32>(0.0, 1.0, 0.0));
    if (dot(t1, t1) < 1e-6) { t1 = cross(n, vec3<f32>(1.0, 0.0, 0.0)); }
    t1 = normalize(t1);
    let t2 = cross(n, t1);
    let step = 1e-3 * d_r;
    let c1 = shadow_coords(layer, q + t1 * step) - vec3<f32>(uv, z);
    let c2 = shadow_coords(layer, q + t2 * step) - vec3<f32>(uv, z);
    let det = c1.x * c2.y - c1.y * c2.x;
    var grad = vec2<f32>(0.0);
    if (abs(det) > 1e-12) {
        // dz/duv = (dz along t1, t2) · J⁻¹ with J the map offsets of t1 and t2.
        grad = vec2<f32>(c1.z * c2.y - c2.z * c1.y, c2.z * c1.x - c1.z * c2.x) / det;
    }
    // A texel's depth error on the plane, and the comparison's margin.
    let margin = 2.0 * (abs(grad.x) + abs(grad.y)) / size.x;
    let scale = b.w / (2.0 * EMITTER_TAN_HALF_FOV);
    // Blockers nearer the light than a quarter of the receiver's depth are not searched for.
    let search = min(scale * 3.0 / d_r, 0.2);
    // The pattern turned per pixel: noise where one pattern for all pixels shows its 16 samples
    // as blocks (measured: block ΔE2000 0.27 against 0.24 for this, side-1 light below).
    let turn = 6.2831853 * hash2_unit(bitcast<vec2<u32>>(uv * size), 0x50f70000u + frame.frame_index).x;
    var blockers = 0.0;
    var depth_sum = 0.0;
    let count = select(BLOCKER_SAMPLES, 1u, search * size.x < 1.0);
    for (var k = 0u; k < count; k++) {
        let off = spiral(k, count, turn) * search;
        let texel = vec2<i32>(clamp(uv + off, vec2<f32>(0.0), vec2<f32>(0.99999)) * size);
        let zb = textureLoad(shadow_maps, texel, i32(layer), 0);
        if (zb < z + dot(grad, off) - margin) {
            blockers += 1.0;
            depth_sum += near * far / (far - zb * (far - near));
        }
    }
    if (blockers == 0.0) { return 1.0; }
    let d_b = depth_sum / blockers;
    let radius = min(scale * max(1.0 / d_b - 1.0 / d_r, 0.0), 0.2);
    let taps = select(SOFT_SAMPLES, 1u, radius * size.x < 1.0);
    var lit = 0.0;
    for (var k = 0u; k < taps; k++) {
        let off = spiral(k, taps, turn) * radius;
        lit += textureSampleCompareLevel(shadow_maps, shadow_sampler, uv + off, i32(layer), z + dot(grad, off) - margin);
    }
    return lit / f32(taps);
}

// Fraction of light `li` that reaches `p` (offset along `n` against acne; zero for points in
// a medium): its shadow map, or 1 for a light without one. Part of the custom-shader API.
fn light_visibility(li: u32, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let layer = shadows.layer_of_light[li / 4u][li % 4u];
    if (layer == NO_SHADOW) { return 1.0; }
    return shadow_visibility(layer, p, n);
}

fn lambert_only() -> bool {
    return (frame.flags & FLAG_LAMBERT) != 0u;
}

// One light's geometry at a surface: radiance = E·(kd·(1 − F)·c_diff/π + ks·F) with F the
// Fresnel term at v·h — kd the cosine-weighted irradiance factor, ks that times the GGX
// distribution and visibility (D·V). Zero for a light that does not reach p.
struct LightTerms {
    kd: f32,
    ks: f32,
    vh: f32,
    // The clear coat's lobe (`Coat`): its D·V·cos·E per unit w, as `ks` without the coat's
    // Fresnel term (which is in w). Zero without a coat.
    kc: f32,
};

// GGX's distribution D and height-correlated Smith visibility V of a lobe of perceptual
// roughness `roughness` about n, seen from v, lit from wi with nl = n·wi > 0 (h the half vector). A directional
// light that stands for a disc of angular radius ρ (the environment's sun; 0 otherwise) widens
// the lobe by the disc's image in half-vector space, an ellipse of semi-axes ρ/2 and
// ρ/(2 n·v), taken as the round one of its area, radius ρ/(2√(n·v)), and added in quadrature
// (the widths of a lobe convolved with the disc). A mirror then shows the disc at its own
// radiance at the lobe's peak, where a delta light squeezes it into a point ~ρ²/4α² as bright;
// rough lobes are left as they are, and D stays normalised (energy kept). Scenes without such a
// light take the branch never (bit-identical images).
fn ggx_dv(n: vec3<f32>, v: vec3<f32>, h: vec3<f32>, nl: f32, roughness: f32, rho: f32) -> vec2<f32> {
    let nv = max(dot(n, v), 1e-4);
    let nh = max(dot(n, h), 0.0);
    let alpha0 = max(roughness * roughness, 1e-3);
    var alpha = alpha0;
    if (rho > 0.0) {
        alpha = min(sqrt(alpha0 * alpha0 + rho * rho / (4.0 * nv)), 1.0);
    }
    let a2 = alpha * alpha;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let dist = a2 / (PI * dd * dd);
    let vis = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));
    return vec2<f32>(dist, vis);
}

// `ggx_dv` of an anisotropic lobe (scene::anisotropy): α_t = mix(α, 1, s²) along t, α_b = α
// across it (α the floored isotropic width), D and the height-correlated V of anisotropic GGX;
// a sun's disc widens both widths as it widens α.
fn ggx_dv_aniso(n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, h: vec3<f32>, nl: f32, roughness: f32, rho: f32, a: Aniso) -> vec2<f32> {
    let nv = max(dot(n, v), 1e-4);
    let nh = max(dot(n, h), 0.0);
    let alpha = max(roughness * roughness, 1e-3);
    var at = alpha + (1.0 - alpha) * a.s * a.s;
    var ab = alpha;
    if (rho > 0.0) {
        let w2 = rho * rho / (4.0 * nv);
        at = min(sqrt(at * at + w2), 1.0);
        ab = min(sqrt(ab * ab + w2), 1.0);
    }
    let b = cross(n, a.t);
    let a2 = at * ab;
    // 1/(π·α_t·α_b·((t·h/α_t)² + (b·h/α_b)² + (n·h)²)²), in the form that keeps f32 in range.
    let f = vec3<f32>(ab * dot(a.t, h), at * dot(b, h), a2 * nh);
    let w2 = a2 / dot(f, f);
    let dist = a2 * w2 * w2 / PI;
    let gv = nl * length(vec3<f32>(at * dot(a.t, v), ab * dot(b, v), nv));
    let gl = nv * length(vec3<f32>(at * dot(a.t, l), ab * dot(b, l), nl));
    return vec2<f32>(dist, 0.5 / (gv + gl));
}

// `a`: the base's anisotropy (`load_aniso`; not the coat's lobe, which stays isotropic). A
// polygon light's LTC lobe stays isotropic, at the anisotropic lobe's stand-in roughness
// (`anisotropy_iso_roughness`).
fn light_terms(li: u32, p: vec3<f32>, n: vec3<f32>, v: vec3<f32>, roughness: f32, a: Aniso, c: Coat) -> LightTerms {
    if (HAS_POLYGONS && u32(lights[li].pos_kind.w) == 3u) {
        var t = polygon_terms(li, p, n, v, anisotropy_iso_roughness(a, roughness));
        if (HAS_COAT && c.w > 0.0) {
            t.kc = polygon_coat(li, p, c, v);
        }
        return t;
    }
    let inc = light_incidence(li, p);
    let wi = inc.xyz;
    var atten = inc.w;
    let nl = dot(n, wi);
    // The coat's normal may face a light the base's (normal-mapped) one does not, and back.
    var nlc = 0.0;
    if (HAS_COAT && c.w > 0.0) {
        nlc = dot(c.normal, wi);
    }
    if ((nl <= 0.0 && nlc <= 0.0) || atten <= 0.0) { return LightTerms(0.0, 0.0, 1.0, 0.0); }
    atten *= light_visibility(li, p, n);
    let rho = select(0.0, lights[li].cone.y, u32(lights[li].pos_kind.w) == 0u);
    let h = normalize(wi + v);
    var kc = 0.0;
    if (HAS_COAT && nlc > 0.0) {
        let g = ggx_dv(c.normal, v, h, nlc, c.roughness, rho);
        kc = nlc * atten * g.x * g.y;
    }
    if (HAS_COAT && nl <= 0.0) {
        return LightTerms(0.0, 0.0, 1.0, kc);
    }
    let k = nl * atten;
    if (lambert_only()) {
        return LightTerms(k, 0.0, 1.0, 0.0);
    }
    let vh = max(dot(v, h), 0.0);
    var g: vec2<f32>;
    if (HAS_ANISOTROPY && a.s > 0.0) {
        g = ggx_dv_aniso(n, v, wi, h, nl, roughness, rho, a);
    } else {
        g = ggx_dv(n, v, h, nl, roughness, rho);
    }
    return LightTerms(k, k * g.x * g.y, vh, kc);
}

// Wavelength-independent part of one light's contribution: radiance = E(λ)·(ρ(λ)·A + B),
// where ρ is the base-colour reflectance. This folds Lambert + GGX (glTF metallic-roughness,
// Schlick Fresnel, height-correlated Smith) into two scalars so that the per-wavelength loop
// costs two fma per light.
// `w` is the dielectric's specular weight (KHR_materials_specular; 1 without), which scales its
// Fresnel term for the lobe and for what the diffuse loses alike (an untinted F0).
fn factors_of(t: LightTerms, metallic: f32, f0: f32, w: f32) -> vec2<f32> {
    if (lambert_only()) {
        return vec2<f32>(t.kd / PI, 0.0);
    }
    let fres = pow(1.0 - t.vh, 5.0);
    let f_dielectric = w * (f0 + (1.0 - f0) * fres);
    let a = t.kd * (1.0 - metallic) * (1.0 - f_dielectric) / PI + t.ks * metallic * (1.0 - fres);
    let b = t.ks * ((1.0 - metallic) * f_dielectric + metallic * fres);
    return vec2<f32>(a, b);
}

// ∫ max(z, 0) dl over polygon light li seen from p, with the polygon's vertices taken to
// m·(vertex − p) and clipped to z > 0 (Lambert's formula, exact). With m the world-to-shading
// frame (z = n) this is the irradiance per unit radiance E/L; with M⁻¹ of the specular lobe's
// linearly transformed cosine (src/ltc.rs) composed in, π times the lobe's share over the light.
fn polygon_cosine(li: u32, p: vec3<f32>, m: mat3x3<f32>) -> f32 {
    // Clipped edge by edge as the polygon is walked (no local array: a dynamically indexed one
    // cost the RGB pass 1.7× on a CPU driver even for scenes without polygon lights). An edge
    // leaving the hemisphere records its exit point, one entering it its entry point; the clipped
    // polygon closes with the edge from exit to entry along the plane.
    let count = polygon_count(li);
    var sum = 0.0;
    var exit_pt = vec3<f32>(0.0);
    var entry_pt = vec3<f32>(0.0);
    var crossings = 0u;
    var above = 0u;
    var a = m * (polygon_vertex(li, 0u) - p);
    for (var i = 0u; i < count; i++) {
        let b = m * (polygon_vertex(li, (i + 1u) % count) - p);
        let da = a.z;
        let db = b.z;
        if (da > 0.0) { above++; }
        if (da > 0.0 && db > 0.0) {
            sum += edge_integral(a, b);
        } else if (da > 0.0) {
            exit_pt = a + (b - a) * (da / (da - db));
            sum += edge_integral(a, exit_pt);
            crossings++;
        } else if (db > 0.0) {
            entry_pt = a + (b - a) * (da / (da - db));
            sum += edge_integral(entry_pt, b);
            crossings++;
        }
        a = b;
    }
    if (above == 0u) { return 0.0; }
    if (crossings == 2u) {
        sum += edge_integral(exit_pt, entry_pt);
    }
    return 0.5 * abs(sum);
}

// One edge's term of Lambert's formula: the angle it subtends times the z of its plane's
// normal.
fn edge_integral(a: vec3<f32>, b: vec3<f32>) -> f32 {
    let ua = normalize(a);
    let ub = normalize(b);
    let c = cross(ua, ub);
    let s = length(c);
    if (s <= 1e-7) { return 0.0; }
    return atan2(s, dot(ua, ub)) * c.z / s;
}

// Linearly transformed cosines (src/ltc.rs): per (roughness, √(1 − n·v)) cell, layer 0 holds
// the specular lobe's M⁻¹ entries (0,0), (0,2), (2,0), (2,2) over its (1,1), layer 1 the lobe's
// split-sum albedo (A, B).
@group(2) @binding(12) var ltc_table: texture_2d_array<f32>;

// `light_terms` for a polygon light (an emissive surface, src/scene_gpu.rs): diffuse exactly
// (the clipped cosine over the polygon), specular by linearly transformed cosines (Heitz et al.
// 2016: the GGX lobe's integral over the polygon, with the Fresnel term the lobe's mean, so
// that `factors_of` weighs it by F0·A + B); shadowed by one shadow map from the centroid.
fn polygon_terms(li: u32, p: vec3<f32>, n: vec3<f32>, v: vec3<f32>, roughness: f32) -> LightTerms {
    let none = LightTerms(0.0, 0.0, 1.0, 0.0);
    let ln = polygon_normal(li);
    // One-sided: nothing reaches points behind the emitting side.
    if (dot(p - polygon_vertex(li, 0u), ln) <= 0.0) { return none; }
    let to_local = ltc_frame(n, v);
    let g = polygon_cosine(li, p, to_local);
    if (g <= 0.0) { return none; }
    let vis = light_visibility(li, p, n);
    if (lambert_only()) {
        return LightTerms(g * vis, 0.0, 1.0, 0.0);
    }
    let lobe = ltc_lobe(roughness, dot(n, v));
    let share = polygon_cosine(li, p, lobe.minv * to_local) / PI;
    let albedo = lobe.ab.x + lobe.ab.y;
    // The lobe's mean Schlick weight B / (A + B) as the (1 − v·h)⁵ of one half vector.
    let fres = select(0.0, lobe.ab.y / albedo, albedo > 0.0);
    return LightTerms(vis * g, vis * share * albedo, 1.0 - pow(fres, 0.2), 0.0);
}

// The shading frame (t1, n × t1, n) as a world-to-local matrix, t1 towards the viewer: the LTC
// table's frame.
fn ltc_frame(n: vec3<f32>, v: vec3<f32>) -> mat3x3<f32> {
    var t1 = v - n * dot(n, v);
    if (dot(t1, t1) < 1e-12) {
        t1 = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9) ;
        t1 -= n * dot(n, t1);
    }
    t1 = normalize(t1);
    return transpose(mat3x3<f32>(t1, cross(n, t1), n));
}

// The GGX lobe of perceptual `roughness` seen at n·v = `nv` as a linearly transformed cosine
// (src/ltc.rs): M⁻¹, and the split sum's A and B of the lobe.
struct LtcLobe {
    minv: mat3x3<f32>,
    ab: vec2<f32>,
};

fn ltc_lobe(roughness: f32, nv: f32) -> LtcLobe {
    let cells = f32(LTC_SIZE - 1u);
    let half_texel = 0.5 / f32(LTC_SIZE);
    let uv = vec2<f32>(clamp(roughness, 0.0, 1.0), sqrt(1.0 - clamp(nv, 0.0, 1.0))) * (cells / f32(LTC_SIZE)) + half_texel;
    let c = textureSampleLevel(ltc_table, env_sampler, uv, 0, 0.0);
    let ab = textureSampleLevel(ltc_table, env_sampler, uv, 1, 0.0).xy;
    let minv = mat3x3<f32>(vec3<f32>(c.x, 0.0, c.z), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(c.y, 0.0, c.w));
    return LtcLobe(minv, ab);
}

// The coat's lobe over polygon light li (`LightTerms::kc`): the LTC integral of a lobe of the
// coat's roughness about its normal, shadowed as the base's terms are.
fn polygon_coat(li: u32, p: vec3<f32>, c: Coat, v: vec3<f32>) -> f32 {
    let n = c.normal;
    if (dot(p - polygon_vertex(li, 0u), polygon_normal(li)) <= 0.0) { return 0.0; }
    let to_local = ltc_frame(n, v);
    if (polygon_cosine(li, p, to_local) <= 0.0) { return 0.0; }
    let lobe = ltc_lobe(c.roughness, dot(n, v));
    return light_visibility(li, p, n) * polygon_cosine(li, p, lobe.minv * to_local) / PI * (lobe.ab.x + lobe.ab.y);
}

// Cells per axis of `ltc_table` (src/ltc.rs `SIZE`).
const LTC_SIZE: u32 = 64u;

// How much of the ambient light (the environment, a medium's diffuse irradiance) reaches the
// surface: the material's occlusion texture times the screen-space horizons.
// With `OCCLUSION_MAP` the horizons come from the occlusion pass (passes/occlusion.rs), which
// ran them over the same depth and normals before this pass; the transmissive layer, whose
// depth is its own, searches them here.
override OCCLUSION_MAP: bool = false;
// Binding 11 holds the see-through meshes' back faces in the transmissive layer's pass
// (transmission.wgsl) and the occlusion pass's output in the opaque pass: the two came to share
// a slot when the pass sampled the 16 textures per stage that WebGPU guarantees (15 since the
// material slot moved into the normal's target).
@group(1) @binding(11) var aux_map: texture_2d<f32>;

fn ambient_visibility(pix: vec2<f32>, p: vec3<f32>, s: GSurface) -> f32 {
    if (OCCLUSION_MAP) {
        return s.occlusion * textureLoad(aux_map, vec2<i32>(pix), 0).x;
    }
    return s.occlusion * env_occlusion(pix, p, s.normal);
}

// What the G-buffer holds for one pixel.
struct GSurface {
    base: vec3<f32>,
    emission: vec3<f32>,
    normal: vec3<f32>,
    metallic: f32,
    roughness: f32,
    // The material's ambient occlusion (glTF occlusionTexture), for ambient light only (the environment, a medium's irradiance).
    occlusion: f32,
    // KHR_materials_unlit: only `emission` (its base colour) leaves the surface.
    unlit: bool,
    // The dielectric's normal-incidence reflectance (KHR_materials_ior; glTF's 0.04 at 1.5);
    // with KHR_materials_specular the largest channel of its F0 colour, which sets what the
    // diffuse loses (and the whole F0 where the colour is grey).
    f0: f32,
    // KHR_materials_specular's weight (1 without).
    spec_w: f32,
};

fn load_surface(px: vec2<i32>) -> GSurface {
    let b = textureLoad(gbuf_base, px, 0);
    let nr = textureLoad(gbuf_normal, px, 0);
    let e = textureLoad(gbuf_emission, px, 0);
    var f0 = vec2<f32>(0.0, 1.0);
    if (HAS_SPECULAR) {
        let sp = specular_at(px);
        f0 = vec2<f32>(max(sp.r, max(sp.g, sp.b)), sp.a);
    } else {
        f0.x = surface_f0(px);
    }
    return GSurface(b.rgb, e.rgb, gbuffer_normal(nr), max(b.a, 0.0), gbuffer_roughness(nr), e.a, b.a < 0.0, f0.x, f0.y);
}

// The index of the material's record (src/material_spectra.rs) at pixel px, by its slot.
fn material_index(px: vec2<i32>) -> u32 {
    let slot = gbuffer_slot(textureLoad(gbuf_normal, px, 0));
    return min(max(slot, 1u) - 1u, arrayLength(&material_spectra) - 1u);
}

fn material_at(px: vec2<i32>) -> MaterialSpectrum {
    return material_spectra[material_index(px)];
}

fn surface_f0(px: vec2<i32>) -> f32 {
    if (!HAS_IOR) {
        return 0.04;
    }
    return material_at(px).film.w;
}

// Diffuse radiance per unit irradiance arriving from all sides (the hooks' medium
// irradiance): the Lambertian layer under the dielectric coat, (1 − metallic)·(1 − F̄)/π with
// F̄ = F0 + (1 − F0)/21 the cosine-weighted hemispherical mean of Schlick's Fresnel (the
// per-light term uses the Fresnel of its own half vector instead). Unlit surfaces: 0.
fn diffuse_lobe(s: GSurface) -> f32 {
    if (s.unlit) { return 0.0; }
    if (lambert_only()) { return 1.0 / PI; }
    return (1.0 - s.metallic) * (1.0 - s.spec_w * (s.f0 + (1.0 - s.f0) / 21.0)) / PI;
}

// The thin film at a pixel (KHR_materials_iridescence): how much of the Fresnel term is the
// film's (0: none), its thickness and index. None without films in the scene, on unlit
// surfaces, and in the Lambert-only comparison mode (whose BRDF has no Fresnel term).
struct FilmSurface {
    weight: f32,
    thickness_nm: f32,
    ior: f32,
    // The dielectric base's F0 and index (glTF's 0.04 and 1.5 without KHR_materials_ior).
    f0: f32,
    base_ior: f32,
    // KHR_materials_specular (never with a film: the loader drops it there): rgb the F0
    // colour, a the weight; `tinted` where the colour is not grey, whose Fresnel term then
    // depends on λ and takes this path; `spec_c` its coefficients (the spectral modes'
    // `spec_coeffs`).
    spec: vec4<f32>,
    tinted: bool,
    spec_c: vec3<f32>,
};

fn no_film() -> FilmSurface {
    return FilmSurface(0.0, 0.0, 1.0, 0.04, 1.5, vec4<f32>(0.04, 0.04, 0.04, 1.0), false, vec3<f32>(0.0));
}

// Whether a pixel's Fresnel term depends on λ: a film, or a tinted specular colour.
fn is_filmed(f: FilmSurface) -> bool {
    return (HAS_FILM && f.weight > 0.0) || (HAS_SPECULAR && f.tinted);
}

// The tinted specular's F0 at group g's nodes: its colour's reflectance spectrum, made as the
// base colour's is (zero where it is not tinted).
fn spec_nodes(f: FilmSurface, g: u32) -> vec4<f32> {
    if (!HAS_SPECULAR || !f.tinted) {
        return vec4<f32>(0.0);
    }
    return node_reflectance(f.spec_c, f.spec.rgb, g);
}

// The sheen colour's reflectance at group g's nodes, made as the base colour's is.
fn sheen_nodes(sh: SheenSurface, g: u32) -> vec4<f32> {
    return node_reflectance(sh.coeffs, sh.color, g);
}

// The diffuse transmission colour's reflectance at group g's nodes, made as the base colour's is.
fn dt_nodes(d: DiffTrans, g: u32) -> vec4<f32> {
    return node_reflectance(d.coeffs, d.color, g);
}

// The spectral modes' coefficients of a tinted specular colour (fetched per pixel: the colour
// may come from a texture).
fn spec_coeffs(f: FilmSurface) -> vec3<f32> {
    if (!HAS_SPECULAR || !f.tinted || NAIVE) {
        return vec3<f32>(0.0);
    }
    return fetch_coeffs(f.spec.rgb, frame.table_res);
}

fn load_film(px: vec2<i32>) -> FilmSurface {
    var r = no_film();
    if (lambert_only()) {
        return r;
    }
    if (HAS_SPECULAR) {
        r.spec = specular_at(px);
        r.tinted = r.spec.r != r.spec.g || r.spec.g != r.spec.b;
    }
    if (!HAS_FILM) {
        return r;
    }
    var f = textureLoad(gbuf_film, px, 0);
    let mat = material_at(px);
    if (HAS_TRANSMISSION) {
        // The see-through layer's film is packed beside its transmission.
        f = vec4<f32>(layer_values(px).zw, 0.0, 0.0);
    }
    let m = mat.film;
    var f0 = 0.04;
    var base_ior = 1.5;
    if (HAS_IOR) {
        f0 = m.w;
        base_ior = film_ior_from_f0(vec4<f32>(f0)).x;
    }
    return FilmSurface(f.x, mix(m.y, m.z, f.y), max(m.x, 1.0), f0, base_ior, r.spec, r.tinted, vec3<f32>(0.0));
}

// The Fresnel terms under a film at four node wavelengths and the cosine c: the dielectric
// base's (index 1.5 and F0 0.04 unless KHR_materials_ior says otherwise) and the metal's (its reflectance ρ(λ) as F0, the
// extension's convention), each Schlick's blended with the film's exact reflectance
// (wgsl/film.wgsl) by the film's weight — the truth's `Brdf::fresnel`, per node.
// A tinted specular (KHR_materials_specular, `f0n` its F0 at the nodes) instead: the
// dielectric's w·(F0(λ) + (1 − F0(λ))(1 − c)⁵), and what the diffuse keeps by the largest
// channel of the F0 colour, 1 − w·(F0_max + (1 − F0_max)(1 − c)⁵) (scene::specular).
struct FilmFresnel {
    dielectric: vec4<f32>,
    metal: vec4<f32>,
    diffuse: vec4<f32>,
};

fn film_fresnel(f: FilmSurface, rho: vec4<f32>, metallic: f32, lambda: vec4<f32>, c: f32, f0n: vec4<f32>) -> FilmFresnel {
    let fres = pow(1.0 - clamp(c, 0.0, 1.0), 5.0);
    var r: FilmFresnel;
    if (HAS_SPECULAR && f.tinted) {
        // (No film here: the loader keeps no specular on a filmed material.)
        let f0_max = max(f.spec.r, max(f.spec.g, f.spec.b));
        r.dielectric = f.spec.w * (f0n + (1.0 - f0n) * fres);
        r.diffuse = vec4<f32>(1.0 - f.spec.w * (f0_max + (1.0 - f0_max) * fres));
        if (metallic > 0.0) {
            r.metal = rho + (1.0 - rho) * fres;
        }
        return r;
    }
    r.dielectric = mix(vec4<f32>(f.f0 + (1.0 - f.f0) * fres),
        film_band_reflectance4(lambda, c, f.thickness_nm, f.ior, vec4<f32>(f.base_ior), frame.node_spacing), f.weight);
    r.diffuse = 1.0 - r.dielectric;
    if (metallic > 0.0) {
        r.metal = mix(rho + (1.0 - rho) * fres,
            film_band_reflectance4(lambda, c, f.thickness_nm, f.ior, film_ior_from_f0(rho), frame.node_spacing), f.weight);
    }
    return r;
}

// One light's radiance over E(λ) at a filmed surface, per node: the factors of `factors_of`
// with the film's Fresnel terms, which depend on λ.
fn film_light_node(t: LightTerms, f: FilmSurface, rho: vec4<f32>, metallic: f32, lambda: vec4<f32>, f0n: vec4<f32>) -> vec4<f32> {
    let fr = film_fresnel(f, rho, metallic, lambda, t.vh, f0n);
    let spec = (1.0 - metallic) * fr.dielectric + metallic * fr.metal;
    return t.kd * (1.0 - metallic) / PI * fr.diffuse * rho + t.ks * spec;
}

// The environment at a filmed surface, per node: what multiplies the irradiance's node weights
// and what multiplies the prefiltered radiance's (`env_terms` with the film's Fresnel terms at
// n·v: each lobe's directional albedo F0·A + B becomes the film's R(n·v)·(A + B), blended by
// the weight — Fresnel at n·v, the split sum's own approximation).
struct FilmEnvNode {
    irr: vec4<f32>,
    spec: vec4<f32>,
};

fn film_env_node(l: EnvLobes, f: FilmSurface, rho: vec4<f32>, metallic: f32, lambda: vec4<f32>, f0n: vec4<f32>) -> FilmEnvNode {
    let a = l.ab.x;
    let b = l.ab.y;
    if (HAS_SPECULAR && f.tinted) {
        // A tinted specular: w·(F0(λ)·A + B) for the lobe, the largest channel's for the diffuse.
        let f0_max = max(f.spec.r, max(f.spec.g, f.spec.b));
        var fm = vec4<f32>(0.0);
        if (metallic > 0.0) {
            fm = rho * a + b;
        }
        let keep = 1.0 - f.spec.w * fresnel_diffuse(f0_max, l.nv);
        return FilmEnvNode(vec4<f32>((1.0 - metallic) / PI * keep) * rho, (1.0 - metallic) * f.spec.w * (f0n * a + b) + metallic * fm);
    }
    var fd = mix(vec4<f32>(f.f0 * a + b), film_band_reflectance4(lambda, l.nv, f.thickness_nm, f.ior, vec4<f32>(f.base_ior), frame.node_spacing) * (a + b), f.weight);
    var fm = vec4<f32>(0.0);
    if (metallic > 0.0) {
        fm = mix(rho * a + b, film_band_reflectance4(lambda, l.nv, f.thickness_nm, f.ior, film_ior_from_f0(rho), frame.node_spacing) * (a + b), f.weight);
    }
    return FilmEnvNode((1.0 - metallic) / PI * (1.0 - fd) * rho, (1.0 - metallic) * fd + metallic * fm);
}

// RGB mode's film (the extension's Belcour–Barla evaluation in RGB, wgsl/film.wgsl): the
// dielectric and metal Fresnel terms at cosine c, blended with Schlick's by the weight.
// A tinted specular instead: the dielectric's w·(F0c + (1 − F0c)(1 − c)⁵) per channel; the
// third column is what the diffuse keeps (by the largest channel for a tinted specular).
fn film_fresnel_rgb(f: FilmSurface, base: vec3<f32>, metallic: f32, c: f32) -> mat3x3<f32> {
    let fres = pow(1.0 - clamp(c, 0.0, 1.0), 5.0);
    if (HAS_SPECULAR && f.tinted) {
        let f0_max = max(f.spec.r, max(f.spec.g, f.spec.b));
        let fd = f.spec.w * (f.spec.rgb + (1.0 - f.spec.rgb) * fres);
        let fm = base + (1.0 - base) * fres;
        return mat3x3<f32>(fd, fm, vec3<f32>(1.0 - f.spec.w * (f0_max + (1.0 - f0_max) * fres)));
    }
    var fm = vec3<f32>(0.0);
    if (metallic > 0.0) {
        fm = mix(base + (1.0 - base) * fres, film_rgb(c, f.thickness_nm, f.ior, base), f.weight);
    }
    let fd = mix(vec3<f32>(f.f0 + (1.0 - f.f0) * fres), film_rgb(c, f.thickness_nm, f.ior, vec3<f32>(f.f0)), f.weight);
    return mat3x3<f32>(fd, fm, 1.0 - fd);
}

// RGB mode: one pass over the lights, nothing kept. Its own entry points (pipelines of their
// own), so that RGB pays only for what RGB needs.
fn shade_rgb(in: FullscreenOut) -> vec4<f32> {
    let px = vec2<i32>(in.pos.xy);
    if (HAS_TRANSMISSION && gbuffer_slot(textureLoad(gbuf_normal, px, 0)) == 0u) {
        return textureLoad(background, px, 0);
    }
    var ctx = surface_context(in.pos.xy, textureLoad(gbuf_depth, px, 0), frame);
    var rgb = vec3<f32>(0.0);
    var through = vec3<f32>(0.0);
    // Loaded once: the hook's irradiance below reads it too.
    var s: GSurface;
    var coat = no_coat();
    if (!ctx.background) {
        s = load_surface(px);
        ctx.normal = s.normal;
    }
    custom_prepare(ctx);
    if (!ctx.background) {
        var keep = 1.0;
        var tr = Transmissive(0.0, 0.0, 1.5, 0.0, vec3<f32>(0.0));
        let film = load_film(px);
        let filmed = is_filmed(film);
        if (HAS_TRANSMISSION) {
            tr = load_transmissive(px, s);
            keep = 1.0 - tr.weight;
            through = transmitted_rgb(in.pos.xy, ctx, s, tr, film);
        }
        var sum_a = vec3<f32>(0.0);
        var sum_b = vec3<f32>(0.0);
        // What the coat reflects, per unit w.
        var sum_c = vec3<f32>(0.0);
        coat = load_coat(px, -ctx.view_dir, s.unlit);
        let sh = load_sheen(px, s, -ctx.view_dir);
        let an = load_aniso(px, s);
        let dt = load_dt(px, s);
        // What the diffuse transmission lets through, per unit colour.
        var sum_dt = vec3<f32>(0.0);
        // What the sheen reflects, per unit colour.
        var sum_sheen = vec3<f32>(0.0);
        let n_lit = select(min(frame.n_lights, MAX_LIGHTS), 0u, s.unlit);
        for (var li = 0u; li < n_lit; li++) {
            var e = lights[li].rgb.rgb;
            if (CUSTOM_LIGHT_T) {
                e *= custom_light_transmittance_rgb(li, ctx);
            }
            var t = light_terms(li, ctx.world_pos, s.normal, -ctx.view_dir, s.roughness, an, coat);
            let k = custom_light_surface(li, ctx);
            t.kd *= k;
            t.ks *= k;
            if (HAS_SHEEN && sh.on) {
                // The sheen's lobe, and the base under it scaled by what it leaves.
                let q = sheen_light(sh, s.normal, -ctx.view_dir, light_dir(li, ctx.world_pos), t.kd);
                t.kd *= q.y;
                t.ks *= q.y;
                sum_sheen = fma(vec3<f32>(q.x), e, sum_sheen);
            }
            if (HAS_COAT) {
                sum_c = fma(vec3<f32>(t.kc * k), e, sum_c);
            }
            if (HAS_DIFFUSE_TRANSMISSION && dt.t > 0.0) {
                t.kd *= dt_keep(dt);
                sum_dt = fma(vec3<f32>(dt_light(li, ctx.world_pos, s, -ctx.view_dir, dt, sh) * k), e, sum_dt);
            }
            // Light from behind a thin-walled see-through surface, tinted by the base colour.
            var behind = 0.0;
            if (HAS_TRANSMISSION) {
                t.kd *= keep;
                behind = thin_transmission(li, ctx.world_pos, s, -ctx.view_dir, tr) * k;
            }
            if (filmed) {
                // The film's Fresnel terms are colours: the whole reflection goes into sum_b.
                let fr = film_fresnel_rgb(film, s.base, s.metallic, t.vh);
                let spec = (1.0 - s.metallic) * fr[0] + s.metallic * fr[1];
                let r = (t.kd * (1.0 - s.metallic) / PI * fr[2] + behind) * s.base + t.ks * spec;
                sum_b = fma(r, e, sum_b);
            } else {
                var f = factors_of(t, s.metallic, s.f0, s.spec_w);
                f.x += behind;
                sum_a = fma(vec3<f32>(f.x), e, sum_a);
                sum_b = fma(vec3<f32>(f.y), e, sum_b);
            }
        }
        rgb = fma(s.base, sum_a, sum_b);
        if (HAS_SHEEN) {
            rgb = fma(sh.color, sum_sheen, rgb);
        }
        if (HAS_DIFFUSE_TRANSMISSION) {
            rgb = fma(dt.color, sum_dt, rgb);
        }
        if (HAS_EMISSION) {
            // Without emission in the scene, and without ambient light (whose occlusion shares
            // the texel), the emission target is not read.
            var e = s.emission;
            // Only a glowing pixel reads its material's record (the RGB mode reads it for
            // nothing else; a GPU branches past it elsewhere).
            if (HAS_EMISSION_SPECTRA && max(e.r, max(e.g, e.b)) > 0.0) {
                let me = measured_emission(px, e);
                e = select(e, me.value, me.on);
            }
            rgb += e;
        }
        if (shading_env() && !s.unlit) {
            var et: EnvTerms;
            if (HAS_TRANSMISSION && !filmed) {
                et = env_terms_keep(s.normal, -ctx.view_dir, s.metallic, s.roughness, lambert_only(), s.f0, keep, s.spec_w);
            } else if (!filmed) {
                et = env_terms_keep(s.normal, -ctx.view_dir, s.metallic, anisotropy_iso_roughness(an, s.roughness), lambert_only(), s.f0, dt_keep(dt), s.spec_w);
            } else {
                var l = env_lobes(s.normal, -ctx.view_dir, anisotropy_iso_roughness(an, s.roughness));
                l.irr *= dt_keep(dt);
                let a = l.ab.x;
                let b = l.ab.y;
                var fd: vec3<f32>;
                var fd_keep: vec3<f32>;
                var fm = vec3<f32>(0.0);
                if (HAS_SPECULAR && film.tinted) {
                    // A tinted specular: w·(F0c·A + B), the diffuse by the largest channel.
                    let f0_max = max(film.spec.r, max(film.spec.g, film.spec.b));
                    fd = film.spec.w * (film.spec.rgb * a + b);
                    fd_keep = vec3<f32>(1.0 - film.spec.w * fresnel_diffuse(f0_max, l.nv));
                    if (s.metallic > 0.0) {
                        fm = s.base * a + b;
                    }
                } else {
                    fd = mix(vec3<f32>(film.f0 * a + b), film_rgb(l.nv, film.thickness_nm, film.ior, vec3<f32>(film.f0)) * (a + b), film.weight);
                    fd_keep = 1.0 - fd;
                    if (s.metallic > 0.0) {
                        fm = mix(s.base * a + b, film_rgb(l.nv, film.thickness_nm, film.ior, s.base) * (a + b), film.weight);
                    }
                }
                et.a = vec4<f32>(0.0);
                et.b = vec4<f32>((1.0 - s.metallic) / PI * fd_keep * keep * s.base * l.irr.rgb
                    + ((1.0 - s.metallic) * fd + s.metallic * fm) * l.spec.rgb, 0.0);
            }
            let vis = ambient_visibility(in.pos.xy, ctx.world_pos, s);
            var env_rgb = (s.base * et.a.rgb + et.b.rgb) * vis;
            if (HAS_SHEEN && sh.on) {
                let q = sheen_env(sh);
                env_rgb = env_rgb * q.x + sh.color * (q.y * vis) * env_irradiance_at(s.normal).rgb;
            }
            var coat_env = vec3<f32>(0.0);
            if (HAS_COAT && coat.w > 0.0) {
                coat_env = env_coat(coat, -ctx.view_dir).rgb * vis;
            }
            if (HAS_DIFFUSE_TRANSMISSION && dt.t > 0.0) {
                env_rgb += dt.color * dt_env(s, -ctx.view_dir, dt, sh).rgb;
            }
            if (CUSTOM_ENV_T) {
                let t = custom_env_transmittance_rgb(ctx);
                env_rgb *= t;
                coat_env *= t;
            }
            rgb += env_rgb;
            sum_c += coat_env;
        }
        if (HAS_COAT && coat.w > 0.0) {
            rgb = rgb * (1.0 - coat.w) + sum_c * coat.w;
        }
    } else if (shading_env() && env.flags.y != 0u) {
        rgb = env_background(ctx.view_dir).rgb;
    }
    var out = custom_rgb(rgb, ctx) + through * (1.0 - coat.w);
    if (CUSTOM_IRRADIANCE && !ctx.background) {
        let lobe = diffuse_lobe(s) * (1.0 - coat.w);
        if (lobe > 0.0) {
            out += s.base * (lobe * ambient_visibility(in.pos.xy, ctx.world_pos, s)) * custom_irradiance_rgb(ctx);
        }
    }
    return hdr_out(out, frame.exposure);
}

// The spectral entry point's pipeline constants (`Variant` in src/passes/shading.rs), so that a
// frame's shader holds only the code its settings use: box upsampling instead of the
// Jakob–Hanika sigmoid (the naive mode), the spectral capture, and emission (no emissive or
// unlit material in the scene: no emission fetch and no emission term per node; the RGB entry
// point reads HAS_EMISSION too).
override NAIVE: bool = false;
override CAPTURE: bool = false;
override HAS_EMISSION: bool = true;
// Whether some material's base colour (FETCH_BASE) or emission (FETCH_EMISSION) varies over its
// surface (a texture, vertex colours): only then is the per-pixel coefficient fetch compiled in.
override FETCH_BASE: bool = true;
override FETCH_EMISSION: bool = true;
// Whether some material glows with a measured spectrum (`measured_emission`).
override HAS_EMISSION_SPECTRA: bool = false;

// sRGB's luminance row (`scene::srgb::luminance`): a measured emission's scale.
const SRGB_Y: vec3<f32> = vec3<f32>(0.2126729, 0.7151522, 0.0721750);

// The emission of a pixel whose material glows with a measured spectrum
// (`MaterialSpectrum::emission` w = −2; the path tracer's `emitted`): the spectrum at the
// luminance `k` of the pixel's emissive colour — the XYZ (RGB in the RGB mode) `value`, and in
// the spectral modes the node weights per unit luminance at light_weights[index + group].
// `on` is false elsewhere, where the emission is upsampled from its RGB as usual.
struct MeasuredEmission {
    on: bool,
    k: f32,
    index: u32,
    value: vec3<f32>,
};

// Whether a surface of constant emission `size` (any measure of it: the material's own value)
// is seen from its emitting side: the G-buffer writes zero emission on its back (one-sided, as
// the path tracer's), and the constant's value comes from the material, not the G-buffer. An
// emission too small for f16 (its smallest subnormal) cannot say, and counts as seen.
fn emitter_seen(gbuffer_emission: vec3<f32>, size: f32) -> bool {
    return max(gbuffer_emission.r, max(gbuffer_emission.g, gbuffer_emission.b)) > 0.0 || size < 1e-7;
}

fn measured_emission(px: vec2<i32>, emission: vec3<f32>) -> MeasuredEmission {
    if (!HAS_EMISSION_SPECTRA) {
        return MeasuredEmission(false, 0.0, 0u, vec3<f32>(0.0));
    }
    let m = material_at(px);
    if (m.emission.w > -1.5) {
        return MeasuredEmission(false, 0.0, 0u, vec3<f32>(0.0));
    }
    // A constant emission's own luminance (x ≥ 0), exact where the G-buffer's f16 is not; none
    // where the G-buffer says the surface is seen from behind (`emitter_seen`).
    let k = select(dot(emission, SRGB_Y), select(0.0, m.emission.x, emitter_seen(emission, m.emission.x)), m.emission.x >= 0.0);
    return MeasuredEmission(true, k, u32(m.emission_xyz.w), m.emission_xyz.xyz * k);
}

// The reflectance at group g's four nodes: the sigmoid of the base colour's coefficients `c`,
// or in the naive mode the box of the band each node falls in.
fn node_reflectance(c: vec3<f32>, base: vec3<f32>, g: u32) -> vec4<f32> {
    if (NAIVE) {
        return box4(base, g);
    }
    return sigmoid4(c, wavelengths[g].lambda);
}

// Emission at group g's nodes ("illuminant" upsampling: scale·sigmoid(rgb / scale), see
// `surface_coeffs`); zero where `scale` is zero.
fn node_emission(c: vec3<f32>, scale: f32, emission: vec3<f32>, g: u32) -> vec4<f32> {
    if (NAIVE) {
        return box4(emission, g);
    }
    return scale * sigmoid4(c, wavelengths[g].lambda);
}

// Each material's coefficients of its constant colours (src/material_spectra.rs:
// `MaterialSpectrum`, byte for byte), fetched once on the CPU, found by the G-buffer's slot
// (`material_index`).
struct MaterialSpectrum {
    // The base colour's coefficients; w = 1 when the colour is constant over the material.
    base: vec4<f32>,
    // Coefficients of emission / scale and w = scale (0: no emission), or w = −1 when the
    // emission varies over the material.
    emission: vec4<f32>,
    // The constant emission's XYZ at this frame's nodes (what the node loop would add up).
    emission_xyz: vec4<f32>,
    // The thin film (KHR_materials_iridescence): x its index (1 without a film), y and z its
    // thickness minimum and maximum, nm; w the dielectric's F0 (KHR_materials_ior).
    film: vec4<f32>,
    // A see-through material: x its index at the d line, y its dispersion (20 / Abbe number),
    // z its volume's thickness in scene units (0: thin-walled).
    refraction: vec4<f32>,
    // Its interior's absorption per scene unit, linear RGB (a box spectrum per node).
    absorption: vec4<f32>,
    // KHR_materials_specular's F0 colour where constant: its coefficients, w = 1 (else 0).
    specular: vec4<f32>,
    // KHR_materials_sheen's colour where constant: its coefficients, w = 1 (else 0).
    sheen: vec4<f32>,
};
@group(2) @binding(11) var<storage, read> material_spectra: array<MaterialSpectrum>;

// A pixel's coefficients: the base colour's, and the emission's with its scale in w; and
// where the emission is the material's constant one, its XYZ at the frame's nodes (zero
// elsewhere), which spares the node loop its emission term.
struct SurfaceCoeffs {
    base: vec3<f32>,
    emission: vec4<f32>,
    emission_known: bool,
    emission_xyz: vec3<f32>,
    // Whether the base colour is the material's constant one, and where in `light_weights`
    // what it reflects under each light and the environment's basis spectra starts
    // (`material_spectra::reflected_xyz`): such a pixel needs no node loop for them.
    base_known: bool,
    reflected: u32,
    // The same for a constant specular F0 colour (KHR_materials_specular): where its block of
    // reflected XYZs starts, after every material's base colour's; 0 where it is not constant.
    spec_reflected: u32,
    // And for a constant sheen colour (KHR_materials_sheen), after the specular's block.
    sheen_reflected: u32,
};

// Entries of the reflected XYZs per material: a column per shaded light, three to an entry,
// then the environment's (`material_spectra::reflected_stride`).
fn reflected_stride() -> u32 {
    return (min(frame.n_lights, MAX_LIGHTS) + 2u) / 3u + 1u;
}

// What the pixel's material reflects under light li, when `SurfaceCoeffs::base_known`.
fn reflected_light(sc: SurfaceCoeffs, li: u32) -> vec3<f32> {
    return light_weights[sc.reflected + li / 3u][li % 3u].xyz;
}

// What it reflects of the environment's coefficients c.
fn reflected_env(sc: SurfaceCoeffs, c: vec4<f32>) -> vec3<f32> {
    return c * light_weights[sc.reflected + reflected_stride() - 1u];
}

// What a constant specular F0 colour reflects under light li and of the environment's
// coefficients c (`SurfaceCoeffs::spec_reflected` ≠ 0).
fn reflected_spec_light(sc: SurfaceCoeffs, li: u32) -> vec3<f32> {
    return light_weights[sc.spec_reflected + li / 3u][li % 3u].xyz;
}

fn reflected_spec_env(sc: SurfaceCoeffs, c: vec4<f32>) -> vec3<f32> {
    return c * light_weights[sc.spec_reflected + reflected_stride() - 1u];
}

// The same for a constant sheen colour (`SurfaceCoeffs::sheen_reflected` ≠ 0).
fn reflected_sheen_light(sc: SurfaceCoeffs, li: u32) -> vec3<f32> {
    return light_weights[sc.sheen_reflected + li / 3u][li % 3u].xyz;
}

fn reflected_sheen_env(sc: SurfaceCoeffs, c: vec4<f32>) -> vec3<f32> {
    return c * light_weights[sc.sheen_reflected + reflected_stride() - 1u];
}

// The spectral mode's coefficients at pixel `px`: the material's precomputed ones where its
// colours are constant, else fetched from the G-buffer's colours. Emission is upsampled with the
// "illuminant" variant, s·sigmoid(rgb / s)·white(λ) with s = 2·max(rgb), so that an emissive
// (1, 1, 1) is exactly the white illuminant; a surface that emits nothing is not fetched.
fn surface_coeffs(px: vec2<i32>, s: GSurface) -> SurfaceCoeffs {
    let index = material_index(px);
    let m = material_spectra[index];
    let base_known = !FETCH_BASE || m.base.w != 0.0;
    let reflected = frame.n_lights * frame.n_groups + index * reflected_stride();
    var spec_reflected = 0u;
    if (HAS_SPECULAR && m.specular.w != 0.0) {
        spec_reflected = reflected + arrayLength(&material_spectra) * reflected_stride();
    }
    var sheen_reflected = 0u;
    if (HAS_SHEEN && m.sheen.w != 0.0) {
        sheen_reflected = reflected + 2u * arrayLength(&material_spectra) * reflected_stride();
    }
    var base = m.base.xyz;
    // A constant emission (w = its scale ≥ 0) where the surface is seen from its emitting side.
    let em_seen = emitter_seen(s.emission, m.emission.w);
    var emission = select(vec4<f32>(0.0), m.emission, m.emission.w >= 0.0 && em_seen);
    // A scene whose colours are all constant has no fetch compiled in.
    if (FETCH_BASE || (HAS_EMISSION && FETCH_EMISSION)) {
        let base_known = m.base.w != 0.0;
        let em_known = m.emission.w >= 0.0;
        let em_max = max(s.emission.r, max(s.emission.g, s.emission.b));
        let scale = select(0.0, 2.0 * em_max, em_max > 0.0);
        let fetched = fetch_coeffs_two(
            s.base,
            FETCH_BASE && !base_known,
            s.emission / max(scale, 1e-30),
            HAS_EMISSION && FETCH_EMISSION && !em_known && em_max > 0.0,
            frame.table_res,
        );
        base = select(fetched.a, base, base_known);
        emission = select(vec4<f32>(fetched.b, scale), emission, em_known);
    }
    if (!HAS_EMISSION) {
        return SurfaceCoeffs(base, vec4<f32>(0.0), true, vec3<f32>(0.0), base_known, reflected, spec_reflected, sheen_reflected);
    }
    let known = m.emission.w >= 0.0;
    return SurfaceCoeffs(base, emission, known, select(vec3<f32>(0.0), m.emission_xyz.xyz, known && em_seen), base_known, reflected, spec_reflected, sheen_reflected);
}

// Spectral and naive modes.
fn shade_spectral(in: FullscreenOut) -> vec4<f32> {
    let px = vec2<i32>(in.pos.xy);
    if (HAS_TRANSMISSION && gbuffer_slot(textureLoad(gbuf_normal, px, 0)) == 0u) {
        return textureLoad(background, px, 0);
    }
    if (CUSTOM_SPECTRAL || CAPTURE) {
        return hdr_out(shade_nodes(in), frame.exposure);
    }
    var ctx = surface_context(in.pos.xy, textureLoad(gbuf_depth, px, 0), frame);
    let has_env = shading_env();
    if (ctx.background) {
        if (has_env && env.flags.y != 0u) {
            return hdr_out(frame.xyz_to_rgb * env_xyz(env_background(ctx.view_dir)), frame.exposure);
        }
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    // Lights outermost: each light's factors are used as soon as they are computed, so nothing
    // per light is kept (a private array per light cost a CPU driver its zero-initialisation and
    // memory traffic on every pixel); a varying reflectance is kept for the first four groups
    // (below) and re-evaluated per light past them (7 operations per node).
    let p = ctx.world_pos;
    var s = load_surface(px);
    // A measured emission is added as its XYZ; its RGB is not upsampled.
    let me = measured_emission(px, s.emission);
    if (me.on) {
        s.emission = vec3<f32>(0.0);
    }
    ctx.normal = s.normal;
    custom_prepare(ctx);
    let v = -ctx.view_dir;
    let ng = frame.n_groups;
    var sc = SurfaceCoeffs(vec3<f32>(0.0), vec4<f32>(0.0), false, vec3<f32>(0.0), false, 0u, 0u, 0u);
    if (!NAIVE) {
        sc = surface_coeffs(px, s);
    }
    let c_base = sc.base;
    // A constant colour's reflected XYZs are read, not looped for (a loop that no pixel of a
    // group runs costs nothing even where both sides of a branch are executed).
    let known = !NAIVE && sc.base_known;
    let ng_unknown = select(ng, 0u, known);
    var xyz = vec3<f32>(0.0);
    let n_lights = select(min(frame.n_lights, MAX_LIGHTS), 0u, s.unlit);
    var film = load_film(px);
    // A thin film makes the whole Fresnel term depend on λ: such a pixel goes through the
    // nodes per light. A tinted specular F0 colour makes only one term of it depend on λ, and
    // linearly (F0(λ) times a factor): that term has its own sum, read from the CPU's where
    // the colour is constant (`reflected_spec_light`), else over the colour's nodes.
    let filmed = HAS_FILM && film.weight > 0.0;
    // Each extension's set-up under its constant as a whole: a scene without it compiles none of
    // it (measured: left to the conditions' constants, lavapipe kept 5 % of the shading pass of
    // scenes without either).
    var tinted = false;
    var spec_known = false;
    var ng_spec = 0u;
    if (HAS_SPECULAR) {
        tinted = film.tinted;
        spec_known = tinted && sc.spec_reflected != 0u;
        ng_spec = select(0u, ng, tinted && !spec_known);
        // A loop of none or one trip, not a branch, which a CPU driver would run for every pixel.
        for (var i = select(0u, 1u, ng_spec > 0u && !NAIVE); i > 0u; i--) {
            film.spec_c = fetch_coeffs(film.spec.rgb, frame.table_res);
        }
    }
    // A varying colour's reflectance at the first four groups (N ≤ 16) once per pixel, in four
    // registers, instead of once per light and group (a sigmoid per node against three selects
    // per group); a filmed pixel has its own loop. Loops, not branches, bound by the group
    // count: a CPU driver, which runs both sides of a branch, stops a loop early, and no private
    // array is indexed.
    var r0 = vec4<f32>(0.0);
    var r1 = vec4<f32>(0.0);
    var r2 = vec4<f32>(0.0);
    var r3 = vec4<f32>(0.0);
    let ng_kept = select(min(ng_unknown, 4u), 0u, n_lights == 0u || filmed);
    for (var g = 0u; g < ng_kept; g++) {
        let r = node_reflectance(c_base, s.base, g);
        r0 = select(r0, r, g == 0u);
        r1 = select(r1, r, g == 1u);
        r2 = select(r2, r, g == 2u);
        r3 = select(r3, r, g == 3u);
    }
    var tr = Transmissive(0.0, 0.0, 1.5, 0.0, vec3<f32>(0.0));
    if (HAS_TRANSMISSION) {
        tr = load_transmissive(px, s);
    }
    let keep = 1.0 - tr.weight;
    let coat = load_coat(px, v, s.unlit);
    let an = load_aniso(px, s);
    // The sheen's colour is a reflectance too (its lobe is the colour times a factor): summed
    // per light from the CPU's XYZs where constant, else over its nodes (fetched once).
    var sh = no_sheen();
    var ng_sheen = 0u;
    var sheen_known = false;
    if (HAS_SHEEN) {
        sh = load_sheen(px, s, v);
        sheen_known = sh.on && sc.sheen_reflected != 0u;
        ng_sheen = select(0u, ng, sh.on && !sheen_known);
        for (var i = select(0u, 1u, ng_sheen > 0u && !NAIVE); i > 0u; i--) {
            sh.coeffs = fetch_coeffs(sh.color, frame.table_res);
        }
    }
    // The diffuse transmission's colour is a reflectance too: summed per light over its nodes
    // (fetched once).
    var dt = no_dt();
    var ng_dt = 0u;
    if (HAS_DIFFUSE_TRANSMISSION) {
        dt = load_dt(px, s);
        ng_dt = select(0u, ng, dt.t > 0.0);
        for (var i = select(0u, 1u, ng_dt > 0u && !NAIVE); i > 0u; i--) {
            dt.coeffs = fetch_coeffs(dt.color, frame.table_res);
        }
    }
    // What the coat reflects, per unit w: each light's XYZ once (it does not depend on ρ).
    var coat_xyz = vec3<f32>(0.0);
    for (var li = 0u; li < n_lights; li++) {
        var t = light_terms(li, p, s.normal, v, s.roughness, an, coat);
        let k = custom_light_surface(li, ctx);
        t.kd *= k;
        t.ks *= k;
        if (HAS_SHEEN && sh.on) {
            let q = sheen_light(sh, s.normal, v, light_dir(li, p), t.kd);
            t.kd *= q.y;
            t.ks *= q.y;
            var rs = vec3<f32>(0.0);
            if (sheen_known) {
                rs = reflected_sheen_light(sc, li);
            }
            for (var g = 0u; g < ng_sheen; g++) {
                rs += sheen_nodes(sh, g) * light_w(li, g, ng);
            }
            xyz = fma(vec3<f32>(q.x), rs, xyz);
        }
        if (HAS_COAT) {
            coat_xyz = fma(vec3<f32>(t.kc * k), lights[li].xyz.xyz, coat_xyz);
        }
        if (HAS_DIFFUSE_TRANSMISSION && ng_dt > 0u) {
            t.kd *= dt_keep(dt);
            let kt = dt_light(li, p, s, v, dt, sh) * k;
            var rt = vec3<f32>(0.0);
            for (var g = 0u; g < ng_dt; g++) {
                rt += dt_nodes(dt, g) * light_w(li, g, ng);
            }
            xyz = fma(vec3<f32>(kt), rt, xyz);
        }
        // Light from behind a thin-walled see-through surface, tinted like the reflectance.
        var through = 0.0;
        if (HAS_TRANSMISSION) {
            t.kd *= keep;
            through = thin_transmission(li, p, s, v, tr) * k;
        }
        if (filmed) {
            // Under a film the specular part depends on λ too: all of it through the nodes.
            for (var g = 0u; g < ng; g++) {
                let rho = node_reflectance(c_base, s.base, g);
                xyz += (film_light_node(t, film, rho, s.metallic, wavelengths[g].lambda, spec_nodes(film, g)) + through * rho) * light_w(li, g, ng);
            }
        } else {
            var f = factors_of(t, s.metallic, s.f0, s.spec_w);
            f.x += through;
            if (HAS_SPECULAR && tinted) {
                // The dielectric lobe's w·(F0(λ) + (1 − F0(λ))·(1 − v·h)⁵): its F0(λ)·w·(1 − (1 −
                // v·h)⁵) part on its own, the rest (and the metal's edge) in f.y. The diffuse
                // keeps what f.x gives it, by the largest channel (s.f0).
                let fres = pow(1.0 - t.vh, 5.0);
                f.y = t.ks * fres * ((1.0 - s.metallic) * s.spec_w + s.metallic);
                var rs = vec3<f32>(0.0);
                if (spec_known) {
                    rs = reflected_spec_light(sc, li);
                }
                for (var g = 0u; g < ng_spec; g++) {
                    rs += spec_nodes(film, g) * light_w(li, g, ng);
                }
                xyz = fma(vec3<f32>(t.ks * (1.0 - s.metallic) * s.spec_w * (1.0 - fres)), rs, xyz);
            }
            // The specular part does not depend on the reflectance: the light's XYZ once.
            // A branch, not a select, which would load for every pixel: a textured material's
            // pixels skip the load where the GPU branches per material.
            var reflected = vec3<f32>(0.0);
            if (known) {
                reflected = reflected_light(sc, li);
            }
            for (var g = 0u; g < ng_kept; g++) {
                let r = select(select(r0, r1, g == 1u), select(r2, r3, g == 3u), g >= 2u);
                reflected += r * light_w(li, g, ng);
            }
            for (var g = 4u; g < ng_unknown; g++) {
                reflected += node_reflectance(c_base, s.base, g) * light_w(li, g, ng);
            }
            xyz = fma(vec3<f32>(f.x), reflected, fma(vec3<f32>(f.y), lights[li].xyz.xyz, xyz));
        }
    }
    // Ambient light (environment, a hook's irradiance) and emission: one more pass over the nodes.
    var vis = 1.0;
    if ((has_env || CUSTOM_IRRADIANCE) && !s.unlit) {
        vis = ambient_visibility(in.pos.xy, p, s);
    }
    var et: EnvTerms;
    var lobes: EnvLobes;
    let film_env = filmed && has_env;
    if (has_env && !s.unlit) {
        if (film_env) {
            lobes = env_lobes(s.normal, v, anisotropy_iso_roughness(an, s.roughness));
            // A see-through surface's diffuse layer is what its transmission leaves.
            lobes.irr *= vis * keep;
            lobes.irr *= dt_keep(dt);
            lobes.spec *= vis;
            if (HAS_SHEEN && sh.on) {
                let q = sheen_env(sh);
                lobes.irr *= q.x;
                lobes.spec *= q.x;
            }
        } else {
            if (HAS_TRANSMISSION) {
                et = env_terms_keep(s.normal, v, s.metallic, s.roughness, lambert_only(), s.f0, keep, s.spec_w);
            } else {
                et = env_terms_keep(s.normal, v, s.metallic, anisotropy_iso_roughness(an, s.roughness), lambert_only(), s.f0, dt_keep(dt), s.spec_w);
            }
            et.a *= vis;
            et.b *= vis;
            if (HAS_SHEEN && sh.on) {
                let q = sheen_env(sh);
                et.a *= q.x;
                et.b *= q.x;
                et.f0 *= q.x;
            }
            if (HAS_SPECULAR && tinted) {
                // As per light: the lobe's F0 part by the colour's reflectance, not F0_max.
                et.f0 *= vis;
                et.b -= s.f0 * et.f0;
                if (spec_known) {
                    xyz += reflected_spec_env(sc, et.f0);
                }
                for (var g = 0u; g < ng_spec; g++) {
                    xyz += spec_nodes(film, g) * env_w(et.f0, g, ng);
                }
            }
            xyz += env_xyz(et.b);
        }
        if (HAS_COAT && coat.w > 0.0) {
            coat_xyz += env_xyz(env_coat(coat, v)) * vis;
        }
        if (HAS_DIFFUSE_TRANSMISSION && ng_dt > 0u) {
            let c = dt_env(s, v, dt, sh);
            for (var g = 0u; g < ng_dt; g++) {
                xyz += dt_nodes(dt, g) * env_w(c, g, ng);
            }
        }
        if (HAS_SHEEN && sh.on) {
            // The sheen's reflection of the irradiance, E(n·v)/π of it per unit colour.
            let c = env_irradiance_at(s.normal) * (sheen_env(sh).y * vis);
            if (sheen_known) {
                xyz += reflected_sheen_env(sc, c);
            }
            for (var g = 0u; g < ng_sheen; g++) {
                xyz += sheen_nodes(sh, g) * env_w(c, g, ng);
            }
        }
    }
    let lobe = diffuse_lobe(s) * vis;
    // Emission known for the whole material is added as its XYZ; only a varying (textured) one
    // goes through the nodes, and in the naive mode every one.
    let em = sc.emission;
    let em_scale = select(em.w, 0.0, sc.emission_known);
    let em_nodes = HAS_EMISSION && (NAIVE || FETCH_EMISSION);
    xyz += sc.emission_xyz;
    if (HAS_EMISSION_SPECTRA) {
        xyz += me.value;
    }
    let env_known = known && has_env && !s.unlit && !film_env;
    if (env_known) {
        xyz += reflected_env(sc, et.a);
    }
    // The loop is needed for what the reflected XYZs do not hold: a varying colour, a film, a
    // varying emission, a hook's irradiance.
    var ng_rest = ng;
    if (!em_nodes && !CUSTOM_IRRADIANCE) {
        ng_rest = select(ng, 0u, known && !film_env);
    }
    for (var g = 0u; g < ng_rest; g++) {
        let rho = node_reflectance(c_base, s.base, g);
        if (film_env) {
            let fe = film_env_node(lobes, film, rho, s.metallic, wavelengths[g].lambda, spec_nodes(film, g));
            xyz += fe.irr * env_w(lobes.irr, g, ng) + fe.spec * env_w(lobes.spec, g, ng);
        } else if (has_env && !env_known) {
            xyz += rho * env_w(et.a, g, ng);
        }
        if (em_nodes) {
            xyz += node_emission(em.xyz, em_scale, s.emission, g) * white_weights(g);
        }
        if (CUSTOM_IRRADIANCE && lobe > 0.0) {
            xyz += s3_xyz(s3_scale(custom_irradiance(wavelengths[g].lambda, g, ctx), rho * lobe));
        }
    }
    if (HAS_COAT && coat.w > 0.0) {
        xyz = xyz * (1.0 - coat.w) + coat_xyz * coat.w;
    }
    if (HAS_TRANSMISSION) {
        xyz += transmitted_xyz(in.pos.xy, ctx, s, tr, c_base, film) * (1.0 - coat.w);
    }
    return hdr_out(frame.xyz_to_rgb * xyz, frame.exposure);
}

// One light at a pixel for the general loop: its terms, what multiplies ρ (`a`, with a thin
// wall's light from behind) and what does not (`b`); a filmed pixel uses the terms (and `a`
// for the light from behind) instead. `sheen`: what multiplies the sheen colour's reflectance.
struct NodeLight {
    t: LightTerms,
    a: f32,
    b: f32,
    sheen: f32,
};

// Under a coat (`Coat`), what lies beneath is scaled by 1 − w and the coat's lobe, which does
// not depend on ρ, joins `b` (a filmed pixel's `b` is the coat's alone).
// A diffuse transmission (`dt`) takes its share of the reflected diffuse here; what it lets
// through is the caller's (`dt_light`).
fn node_light(li: u32, p: vec3<f32>, s: GSurface, ctx: SurfaceContext, tr: Transmissive, filmed: bool, c: Coat, sh: SheenSurface, an: Aniso, dt: DiffTrans) -> NodeLight {
    var t = light_terms(li, p, s.normal, -ctx.view_dir, s.roughness, an, c);
    let k = custom_light_surface(li, ctx);
    t.kd *= k;
    t.ks *= k;
    var sheen = 0.0;
    if (HAS_SHEEN && sh.on) {
        let q = sheen_light(sh, s.normal, -ctx.view_dir, light_dir(li, p), t.kd);
        t.kd *= q.y;
        t.ks *= q.y;
        sheen = q.x;
    }
    if (HAS_DIFFUSE_TRANSMISSION && dt.t > 0.0) {
        t.kd *= dt_keep(dt);
    }
    var coat_b = 0.0;
    if (HAS_COAT && c.w > 0.0) {
        t.kd *= 1.0 - c.w;
        t.ks *= 1.0 - c.w;
        coat_b = t.kc * k * c.w;
        sheen *= 1.0 - c.w;
    }
    var through = 0.0;
    if (HAS_TRANSMISSION) {
        t.kd *= (1.0 - tr.weight);
        through = thin_transmission(li, p, s, -ctx.view_dir, tr) * k * (1.0 - c.w);
    }
    if (filmed) {
        return NodeLight(t, through, coat_b, sheen);
    }
    let f = factors_of(t, s.metallic, s.f0, s.spec_w);
    var a = f.x;
    if (HAS_TRANSMISSION) {
        a += through;
    }
    return NodeLight(t, a, f.y + coat_b, sheen);
}

// Light `li`'s part of group g in weighted form, into the general loop's accumulators.
fn add_node_light(acc_a: ptr<function, mat3x4<f32>>, acc_b: ptr<function, mat3x4<f32>>, acc_f: ptr<function, mat3x4<f32>>,
    nl: NodeLight, li: u32, g: u32, lambda: vec4<f32>, rho: vec4<f32>, film: FilmSurface, metallic: f32, ctx: SurfaceContext) {
    var w = light_w(li, g, frame.n_groups);
    if (CUSTOM_LIGHT_T) {
        w = s3_scale(w, custom_light_transmittance(li, lambda, g, ctx));
    }
    if (is_filmed(film)) {
        *acc_f += s3_scale(w, film_light_node(nl.t, film, rho, metallic, lambda, spec_nodes(film, g)));
        if (HAS_TRANSMISSION) {
            *acc_f += s3_scale(w, nl.a * rho);
        }
        if (HAS_COAT) {
            *acc_b += w * nl.b;
        }
    } else {
        *acc_a += w * nl.a;
        *acc_b += w * nl.b;
    }
}

// The general spectral loop, groups outermost, for what needs each node's whole radiance: a
// spectral hook (which transforms it) and the capture (which stores it). Returns linear RGB.
fn shade_nodes(in: FullscreenOut) -> vec3<f32> {
    let px = vec2<i32>(in.pos.xy);
    var ctx = surface_context(in.pos.xy, textureLoad(gbuf_depth, px, 0), frame);
    let background = ctx.background;
    let p = ctx.world_pos;

    var base = vec3<f32>(0.0);
    var emission = vec3<f32>(0.0);
    var n_lights = 0u;
    var lobe = 0.0;
    // The spectral loop reads each light's factors once per wavelength group.
    var fa: array<f32, MAX_LIGHTS>;
    var fb: array<f32, MAX_LIGHTS>;
    // The environment's coefficients (src/environment.rs): `a` multiplies ρ, `b` does not.
    var et: EnvTerms;
    let has_env = shading_env();
    // A filmed pixel keeps each light's terms instead (its Fresnel term depends on λ), and the
    // environment's lobes.
    var film = no_film();
    var ft: array<LightTerms, MAX_LIGHTS>;
    var lobes: EnvLobes;
    var metallic = 0.0;
    // Loaded once: the coefficients below are fetched from it too.
    var s: GSurface;
    // The see-through layer (transmission.wgsl): its diffuse layer is what its transmission
    // leaves (`keep`), a thin wall lets lights behind it through (in `fa` beside the rest, or
    // alone for a filmed pixel), and the light through it is added per group after the hook,
    // which the background it reads has had already.
    var tr = Transmissive(0.0, 0.0, 1.5, 0.0, vec3<f32>(0.0));
    var me = MeasuredEmission(false, 0.0, 0u, vec3<f32>(0.0));
    // The coat (`Coat`): what lies beneath is kept by 1 − w (`under`); the coat's environment
    // lobe, w times, in `coat_env`.
    var coat = no_coat();
    var under = 1.0;
    var coat_env = vec4<f32>(0.0);
    // The sheen (KHR_materials_sheen): per light what its colour's reflectance multiplies in
    // `fsh`, the environment's in `sheen_env_c`, both under the coat.
    var sh = no_sheen();
    var fsh: array<f32, MAX_LIGHTS>;
    var sheen_env_c = vec4<f32>(0.0);
    var an = no_aniso();
    // The diffuse transmission (KHR_materials_diffuse_transmission): per light what its colour's
    // reflectance multiplies in `fdt`, the environment's in `dt_env_c`, both under the coat.
    var dt = no_dt();
    var fdt: array<f32, MAX_LIGHTS>;
    var dt_env_c = vec4<f32>(0.0);
    if (!background) {
        s = load_surface(px);
        an = load_aniso(px, s);
        coat = load_coat(px, -ctx.view_dir, s.unlit);
        under = 1.0 - coat.w;
        if (HAS_SHEEN) {
            sh = load_sheen(px, s, -ctx.view_dir);
            if (sh.on && !NAIVE) {
                sh.coeffs = fetch_coeffs(sh.color, frame.table_res);
            }
        }
        // A measured emission goes through its own node weights; its RGB is not upsampled.
        me = measured_emission(px, s.emission);
        if (me.on) {
            s.emission = vec3<f32>(0.0);
        }
        film = load_film(px);
        film.spec_c = spec_coeffs(film);
        metallic = s.metallic;
        if (HAS_TRANSMISSION) {
            tr = load_transmissive(px, s);
        }
        if (HAS_COAT && me.on) {
            me.k *= under;
        }
        if (HAS_DIFFUSE_TRANSMISSION) {
            dt = load_dt(px, s);
            if (dt.t > 0.0 && !NAIVE) {
                dt.coeffs = fetch_coeffs(dt.color, frame.table_res);
            }
        }
        let keep = 1.0 - tr.weight;
        var vis = 1.0;
        if ((has_env || CUSTOM_IRRADIANCE) && !s.unlit) {
            vis = ambient_visibility(in.pos.xy, p, s);
        }
        if (has_env && !s.unlit) {
            if (is_filmed(film)) {
                lobes = env_lobes(s.normal, -ctx.view_dir, anisotropy_iso_roughness(an, s.roughness));
                lobes.irr *= vis * dt_keep(dt);
                lobes.spec *= vis;
                if (HAS_TRANSMISSION) {
                    lobes.irr *= keep;
                }
                if (HAS_COAT) {
                    lobes.irr *= under;
                    lobes.spec *= under;
                }
                if (HAS_SHEEN && sh.on) {
                    let q = sheen_env(sh).x;
                    lobes.irr *= q;
                    lobes.spec *= q;
                }
            } else {
                if (HAS_TRANSMISSION) {
                    et = env_terms_keep(s.normal, -ctx.view_dir, s.metallic, s.roughness, lambert_only(), s.f0, keep, s.spec_w);
                } else {
                    et = env_terms_keep(s.normal, -ctx.view_dir, s.metallic, anisotropy_iso_roughness(an, s.roughness), lambert_only(), s.f0, dt_keep(dt), s.spec_w);
                }
                et.a *= vis;
                et.b *= vis;
                if (HAS_COAT) {
                    et.a *= under;
                    et.b *= under;
                }
                if (HAS_SHEEN && sh.on) {
                    let q = sheen_env(sh).x;
                    et.a *= q;
                    et.b *= q;
                }
            }
            if (HAS_COAT && coat.w > 0.0) {
                coat_env = env_coat(coat, -ctx.view_dir) * (vis * coat.w);
            }
            if (HAS_SHEEN && sh.on) {
                sheen_env_c = env_irradiance_at(s.normal) * (sheen_env(sh).y * vis * under);
            }
            if (HAS_DIFFUSE_TRANSMISSION && dt.t > 0.0) {
                dt_env_c = dt_env(s, -ctx.view_dir, dt, sh) * under;
            }
        }
        base = s.base;
        emission = s.emission;
        ctx.normal = s.normal;
        // The hook's irradiance is ambient light too: occluded like the environment.
        lobe = diffuse_lobe(s) * vis * under;
    }
    custom_prepare(ctx);
    if (!background) {
        n_lights = select(min(frame.n_lights, MAX_LIGHTS), 0u, s.unlit);
        for (var li = 0u; li < n_lights; li++) {
            let nl = node_light(li, p, s, ctx, tr, is_filmed(film), coat, sh, an, dt);
            ft[li] = nl.t;
            fa[li] = nl.a;
            fb[li] = nl.b;
            if (HAS_SHEEN) {
                fsh[li] = nl.sheen;
            }
            if (HAS_DIFFUSE_TRANSMISSION) {
                fdt[li] = select(0.0, dt_light(li, p, s, -ctx.view_dir, dt, sh) * custom_light_surface(li, ctx) * under, dt.t > 0.0);
            }
        }
    }
    let filmed = is_filmed(film);

    var c_base = vec3<f32>(0.0);
    var em = vec4<f32>(0.0);
    if (!background && !NAIVE) {
        let sc = surface_coeffs(px, s);
        c_base = sc.base;
        em = sc.emission;
    }
    if (background && !CUSTOM_SPECTRAL) {
        if (has_env && env.flags.y != 0u) {
            let bg = env_background(ctx.view_dir);
            if (CAPTURE) {
                for (var g = 0u; g < frame.n_groups; g++) {
                    capture_group(px, g, env_w(bg, g, frame.n_groups));
                }
            }
            return frame.xyz_to_rgb * env_xyz(bg);
        }
        // The capture buffer is cleared before the frame: nothing to write.
        return vec3<f32>(0.0);
    }
    // A background pixel under a spectral hook: the sky is the radiance the hook receives, as
    // `custom_rgb` receives it in the RGB mode (it received none: a hook that only attenuates
    // drew a black sky in the spectral modes). The media's hooks replace a background's radiance.
    let sky = background && has_env && env.flags.y != 0u;
    var sky_c = vec4<f32>(0.0);
    if (sky) {
        sky_c = env_background(ctx.view_dir);
    }
    let ng = frame.n_groups;
    var tp = TransmittedPixel(0.0, Through(vec3<f32>(0.0), 0.0, 0.0, false), vec4<f32>(0.0));
    if (HAS_TRANSMISSION) {
        tp = transmitted_pixel(in.pos.xy, ctx, s, tr);
    }
    var xyz = vec3<f32>(0.0);
    // Without a spectral hook (capturing) the specular terms need no nodes for XYZ: each
    // light's XYZ once; the capture still takes them per node.
    if (!CUSTOM_SPECTRAL && (!filmed || HAS_COAT)) {
        // (A filmed pixel's `fb` is its coat's.)
        for (var li = 0u; li < n_lights; li++) {
            xyz = fma(vec3<f32>(fb[li]), lights[li].xyz.xyz, xyz);
        }
        if (has_env && !filmed) {
            xyz += env_xyz(et.b);
        }
        if (HAS_COAT) {
            xyz += env_xyz(coat_env);
        }
    }
    let zero = mat3x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var g = 0u; g < ng; g++) {
        let lambda = wavelengths[g].lambda;
        let rho = node_reflectance(c_base, base, g);
        // Σ_l a_l·W_l and Σ_l b_l·W_l: three fma each per light and group.
        var acc_a = zero;
        var acc_b = zero;
        // A filmed pixel's reflection, all of it (it is not a multiple of ρ).
        var acc_f = zero;
        for (var li = 0u; li < n_lights; li++) {
            let nl = NodeLight(ft[li], fa[li], fb[li], 0.0);
            add_node_light(&acc_a, &acc_b, &acc_f, nl, li, g, lambda, rho, film, metallic, ctx);
        }
        // The sheen's lobe under every light and the environment, times its colour's reflectance.
        var acc_s = zero;
        var s_nodes = vec4<f32>(0.0);
        if (HAS_SHEEN && sh.on) {
            s_nodes = sheen_nodes(sh, g);
            for (var li = 0u; li < n_lights; li++) {
                var w = light_w(li, g, ng);
                if (CUSTOM_LIGHT_T) {
                    w = s3_scale(w, custom_light_transmittance(li, lambda, g, ctx));
                }
                acc_s += w * fsh[li];
            }
            if (has_env) {
                var ws = env_w(sheen_env_c, g, ng);
                if (CUSTOM_ENV_T) {
                    ws = s3_scale(ws, custom_env_transmittance(lambda, g, ctx));
                }
                acc_s += ws;
            }
        }
        // The diffuse transmission's lobe under every light behind and the environment there,
        // times its colour's reflectance.
        var acc_t = zero;
        var t_nodes = vec4<f32>(0.0);
        if (HAS_DIFFUSE_TRANSMISSION && dt.t > 0.0) {
            t_nodes = dt_nodes(dt, g);
            for (var li = 0u; li < n_lights; li++) {
                var w = light_w(li, g, ng);
                if (CUSTOM_LIGHT_T) {
                    w = s3_scale(w, custom_light_transmittance(li, lambda, g, ctx));
                }
                acc_t += w * fdt[li];
            }
            if (has_env) {
                var wt = env_w(dt_env_c, g, ng);
                if (CUSTOM_ENV_T) {
                    wt = s3_scale(wt, custom_env_transmittance(lambda, g, ctx));
                }
                acc_t += wt;
            }
        }
        if (has_env && !background) {
            if (filmed) {
                let fe = film_env_node(lobes, film, rho, metallic, lambda, spec_nodes(film, g));
                var wi = s3_scale(env_w(lobes.irr, g, ng), fe.irr);
                var ws = s3_scale(env_w(lobes.spec, g, ng), fe.spec);
                if (CUSTOM_ENV_T) {
                    let t = custom_env_transmittance(lambda, g, ctx);
                    wi = s3_scale(wi, t);
                    ws = s3_scale(ws, t);
                }
                acc_f += wi + ws;
            } else {
                var wa = env_w(et.a, g, ng);
                var wb = env_w(et.b, g, ng);
                if (CUSTOM_ENV_T) {
                    let t = custom_env_transmittance(lambda, g, ctx);
                    wa = s3_scale(wa, t);
                    wb = s3_scale(wb, t);
                }
                acc_a += wa;
                acc_b += wb;
            }
            if (HAS_COAT && coat.w > 0.0) {
                var wc = env_w(coat_env, g, ng);
                if (CUSTOM_ENV_T) {
                    wc = s3_scale(wc, custom_env_transmittance(lambda, g, ctx));
                }
                acc_b += wc;
            }
        }
        // This group's whole radiance in weighted form.
        var part = s3_scale(acc_a, rho) + acc_b;
        if (HAS_SHEEN) {
            part += s3_scale(acc_s, s_nodes);
        }
        if (HAS_DIFFUSE_TRANSMISSION) {
            part += s3_scale(acc_t, t_nodes);
        }
        if (filmed) {
            part += acc_f;
        }
        if (HAS_EMISSION) {
            part += s3_scale(white_weights(g), node_emission(em.xyz, em.w, emission, g) * under);
        }
        var measured = mat3x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
        if (HAS_EMISSION_SPECTRA && me.on) {
            measured = light_weights[me.index + g] * me.k;
            part += measured;
        }
        if (sky) {
            part += env_w(sky_c, g, ng);
        }
        if (CUSTOM_SPECTRAL) {
            part = custom_spectral(lambda, part, g, ctx);
            xyz += s3_xyz(part);
        } else {
            // The specular terms are in xyz already (a filmed pixel has them in acc_f).
            xyz += rho * acc_a;
            if (HAS_SHEEN) {
                xyz += s_nodes * acc_s;
            }
            if (HAS_DIFFUSE_TRANSMISSION) {
                xyz += t_nodes * acc_t;
            }
            if (filmed) {
                xyz += s3_xyz(acc_f);
            }
            if (HAS_EMISSION) {
                xyz += node_emission(em.xyz, em.w, emission, g) * under * white_weights(g);
            }
            if (HAS_EMISSION_SPECTRA) {
                xyz += s3_xyz(measured);
            }
        }
        if (CUSTOM_IRRADIANCE && lobe > 0.0) {
            let irr = s3_scale(custom_irradiance(lambda, g, ctx), rho * lobe);
            xyz += s3_xyz(irr);
            part += irr;
        }
        if (HAS_TRANSMISSION && tp.k > 0.0) {
            let tn = transmitted_nodes(in.pos.xy, ctx, s, tr, c_base, film, tp, g);
            var through = transmitted_weighted(tn, g) * under;
            if (CUSTOM_ENV_T && (tn.sky || any(tn.sky_lanes))) {
                // What the hooks let through of the environment (`seen_through` took none).
                let sky = select(vec4<bool>(tn.sky), tn.sky_lanes, tn.lanes);
                through = s3_scale(through, select(vec4<f32>(1.0), custom_env_transmittance(lambda, g, ctx), sky));
            }
            xyz += s3_xyz(through);
            part += through;
        }
        if (CAPTURE) {
            capture_group(px, g, part);
        }
    }
    return frame.xyz_to_rgb * xyz;
}

// The entry points. The opaque layer is shaded by a compute pass over the screen (`cs_*`, into
// `shading_out`), the transmissive layer by its meshes' fragments (`fs_*`, see
// transmission.wgsl): the same functions either way. A compute pass runs on every shader core,
// where fragments run only on those with raster hardware — on some GPUs a small part of them
// (docs/benchmark.md, "Shading in a compute pass").
@group(1) @binding(14) var shading_out: texture_storage_2d<rgba16float, write>;

@fragment
fn fs_rgb(in: FullscreenOut) -> @location(0) vec4<f32> {
    return shade_rgb(in);
}

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    return shade_spectral(in);
}

@compute @workgroup_size(SCREEN_GROUP, SCREEN_GROUP)
fn cs_rgb(@builtin(global_invocation_id) id: vec3<u32>) {
    if (all(id.xy < textureDimensions(shading_out))) {
        textureStore(shading_out, id.xy, shade_rgb(fullscreen_at(id.xy)));
    }
}

@compute @workgroup_size(SCREEN_GROUP, SCREEN_GROUP)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (all(id.xy < textureDimensions(shading_out))) {
        textureStore(shading_out, id.xy, shade_spectral(fullscreen_at(id.xy)));
    }
}
