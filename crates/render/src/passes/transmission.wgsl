// The transmissive layer's shading (KHR_materials_transmission, _volume, _dispersion): appended
// to shading.wgsl. The frame draws a scene with see-through materials in two layers
// (src/passes/gbuffer.rs `Layer`): the opaque one is shaded into `background`; then the
// shading pipeline with HAS_TRANSMISSION runs over the see-through layer's G-buffer, where each
// see-through pixel adds to its own reflection the light of the background where the refracted
// view ray arrives:
//   T·(1 − F(n·v))·(1 − F_exit)·base(λ)·exp(−σ_a(λ)·d)·L_background(λ, where the ray lands),
// with T the transmission factor × texture × (1 − metallic), F Schlick's Fresnel of the
// dielectric at each interface, d the path inside the volume (KHR_materials_volume), σ_a its
// absorption upsampled per channel as a box (as the path tracer upsamples it), and the
// background blurred by the roughness.
// The ray is traced in screen space, twice refracted (two-sided refraction, after Wyman 2005):
// into the volume at the front surface, along the refracted direction to the see-through
// meshes' nearest back face (`back_faces`, src/passes/back_faces.rs), out through it by Snell's
// law, then on through the opaque layer's depth to the first surface it meets, whose shaded
// colour is the background there; a ray that leaves the screen takes the environment's
// radiance in its direction. So a ball of glass shows the inverted image it shows. Where no back
// face lies behind the surface (a single sheet, an open mesh) the old model stands: the ray
// leaves `thickness` along the refracted direction, parallel to the view ray (a slab).
// What the screen does not show (behind the camera, off screen, behind other surfaces, a second
// see-through layer, internal reflections) cannot be refracted; the path tracer traces the
// real interior instead.
// Pixels without a see-through surface in front pass the background through.

@group(1) @binding(10) var background: texture_2d<f32>;
// The see-through meshes' nearest back faces are `aux_map` (shading.wgsl): xyz the outward
// normal, w the linear depth (`linear_depth`; −1 where there is none).
// The opaque layer's depth: what a ray leaving the glass can land on.
@group(1) @binding(12) var opaque_depth: texture_depth_2d;
// The layer's transmission (xy) and film (zw), four 8-bit values (gbuffer.wgsl `with_layer`).
@group(1) @binding(13) var layer_packed: texture_2d<u32>;

fn layer_values(px: vec2<i32>) -> vec4<f32> {
    return unpack4x8unorm(textureLoad(layer_packed, px, 0).x);
}
override HAS_TRANSMISSION: bool = false;
// Some see-through material is thin-walled (`thin_transmission`).
override HAS_THIN_WALLS: bool = true;
// Some see-through material disperses: without, neither mode compiles its extra traces (a CPU
// driver runs a branch's both sides).
override HAS_DISPERSION: bool = true;

// The transmissive layer's shading is drawn over the see-through meshes themselves, not over the
// whole screen (the frame's other pixels already hold the background, copied there): a CPU
// driver runs a fragment shader's every branch, so a full-screen pass cost every pixel the
// whole shading. The G-buffer pass transforms the same vertices the same way (`@invariant`).
@vertex
fn vs_layer(@location(0) position: vec3<f32>) -> LayerOut {
    return LayerOut(frame.view_proj * vec4<f32>(position, 1.0));
}

struct LayerOut {
    @builtin(position) @invariant pos: vec4<f32>,
};

struct Transmissive {
    // Transmission factor × texture R × (1 − metallic): the share of the dielectric's diffuse
    // layer that is a refracted lobe instead.
    weight: f32,
    // Scene units: the volume's thickness × texture G (0: thin-walled).
    thickness: f32,
    ior: f32,
    dispersion: f32,
    absorption: vec3<f32>,
};

fn load_transmissive(px: vec2<i32>, s: GSurface) -> Transmissive {
    let t = layer_values(px).xy;
    let m = material_at(px);
    let w = select(t.x * (1.0 - s.metallic), 0.0, s.unlit || lambert_only());
    return Transmissive(w, m.refraction.z * t.y, m.refraction.x, m.refraction.y, m.absorption.xyz);
}

// 1 / (λ_F⁻² − λ_C⁻²), nm²: the dispersion extension's Cauchy coefficient B per (n_d − 1)/V_d.
const ABBE_K: f32 = 1.0 / (1.0 / (486.13 * 486.13) - 1.0 / (656.27 * 656.27));

// The extension's index at λ (nm) for index n_d at the d line and dispersion D = 20/V_d
// (`scene::transmission::abbe_ior`, which the path tracer calls).
fn abbe_ior(n_d: f32, dispersion: f32, lambda: f32) -> f32 {
    if (dispersion <= 0.0) {
        return n_d;
    }
    let b = (n_d - 1.0) * dispersion / 20.0 * ABBE_K;
    let a = n_d - b / (587.56 * 587.56);
    return max(a + b / (lambda * lambda), 1.0);
}

// A depth that grows linearly along any ray: the clip w of a perspective camera (its view
// depth), 1 − the clip z of an orthographic one (whose depth is reversed, as every camera's).
// The back-face pass stores the same.
fn linear_depth(c: vec4<f32>) -> f32 {
    return select(c.w, 1.0 - c.z, (frame.flags & FLAG_ORTHO) != 0u);
}

// Pixel coordinates of clip-space point c (in front of the camera).
fn clip_to_pixel(c: vec4<f32>) -> vec2<f32> {
    let ndc = c.xy / c.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * frame.viewport.x, (0.5 - ndc.y * 0.5) * frame.viewport.y);
}

fn on_screen(px: vec2<f32>) -> bool {
    return all(px >= vec2<f32>(0.0)) && all(px < frame.viewport.xy);
}

// Marching steps along the refracted ray inside the volume, and along the ray that leaves it.
const INSIDE_STEPS: u32 = 8u;
const OUTSIDE_STEPS: u32 = 16u;
const REFINE_STEPS: u32 = 5u;

// Whether the point at clip position c (on the refracted ray inside a volume) has left it: off
// screen, outside the see-through meshes' silhouette, or behind the nearest back face there.
fn left_volume(c: vec4<f32>) -> bool {
    let q = clip_to_pixel(c);
    let b = textureLoad(aux_map, vec2<i32>(clamp(q, vec2<f32>(0.0), frame.viewport.xy - 1.0)), 0);
    return c.w <= 0.0 || !on_screen(q) || b.w < 0.0 || linear_depth(c) >= b.w;
}

// Where the view ray leaves the see-through surface's volume, and in which direction.
struct Exit {
    pos: vec3<f32>,
    dir: vec3<f32>,
    // 1 − F at the exit interface (1 where no back face was found).
    share: f32,
    // Path length inside the volume (the Beer–Lambert distance).
    length: f32,
    // Whether a back face was found (else the slab model).
    traced: bool,
};

// The refracted ray r1 from the front surface point p (pixel `pix`) marched to the nearest back
// face: the first step whose point lies behind that face, then bisection; refracted out there
// (total internal reflection: reflected, and taken as leaving). No back face behind p: the slab
// model, `thickness` along r1 and out parallel to the view ray (thickness 0, thin-walled:
// straight through).
fn volume_exit(pix: vec2<f32>, p: vec3<f32>, n: vec3<f32>, view_dir: vec3<f32>, ior: f32, thickness: f32) -> Exit {
    if (thickness <= 0.0) {
        return Exit(p, view_dir, 1.0, 0.0, false);
    }
    let eta = max(ior, 1.0);
    let r1 = refract(view_dir, n, 1.0 / eta);
    let slab = Exit(p + r1 * thickness, view_dir, 1.0, thickness, false);
    let own = textureLoad(aux_map, vec2<i32>(pix), 0);
    let cp = frame.view_proj * vec4<f32>(p, 1.0);
    let depth_p = linear_depth(cp);
    // The depth gap to the back face seen through this pixel sets the search's reach (a ray
    // bent off the view ray crosses more than the gap, at most the volume's thickness).
    let gap = own.w - depth_p;
    if (own.w < 0.0 || gap <= 1e-5 * depth_p) {
        return slab;
    }
    let dc = frame.view_proj * vec4<f32>(r1, 0.0);
    // A thickness far beyond what the mesh can hold (10⁶, which glTF allows) spread the steps
    // so wide that the first one left the volume far behind its back face (drawn black): the
    // thickness widens the reach by at most 64 gaps (8 changed the glass scene at silhouettes).
    let along_gap = gap / max(linear_depth(dc), 1e-3);
    let reach = 2.0 * max(along_gap, min(thickness, 64.0 * along_gap));
    var lo = 0.0;
    var hi = -1.0;
    for (var i = 1u; i <= INSIDE_STEPS; i++) {
        let t = reach * f32(i) / f32(INSIDE_STEPS);
        if (left_volume(cp + dc * t)) {
            hi = t;
            break;
        }
        lo = t;
    }
    if (hi < 0.0) {
        hi = reach;
    }
    for (var i = 0u; i < REFINE_STEPS; i++) {
        let t = 0.5 * (lo + hi);
        if (left_volume(cp + dc * t)) {
            hi = t;
        } else {
            lo = t;
        }
    }
    // The normal of the back face the ray was last inside of.
    let c = cp + dc * lo;
    let q = clamp(clip_to_pixel(c), vec2<f32>(0.0), frame.viewport.xy - 1.0);
    var nb = textureLoad(aux_map, vec2<i32>(q), 0).xyz;
    if (dot(nb, r1) <= 0.0) {
        nb = own.xyz;
    }
    let t = 0.5 * (lo + hi);
    var r2 = refract(r1, -nb, eta);
    var share = 1.0;
    if (dot(r2, r2) == 0.0) {
        r2 = reflect(r1, -nb);
    } else {
        // Schlick at the air side's cosine (the larger angle), as at the front.
        let f0 = ((eta - 1.0) * (eta - 1.0)) / ((eta + 1.0) * (eta + 1.0));
        share = 1.0 - (f0 + (1.0 - f0) * pow(1.0 - clamp(dot(r2, nb), 0.0, 1.0), 5.0));
    }
    return Exit(p + r1 * t, r2, share, t, true);
}

// What the ray leaving the volume meets: its pixel in the opaque layer (the first sample behind
// the opaque depth, refined by bisection), or (−1, −1) when it leaves the screen or reaches
// only the sky. The march is uniform in screen space, up to where the ray leaves the screen
// or comes close to the camera plane.
fn landing_pixel(e: Exit) -> vec2<f32> {
    let c0 = frame.view_proj * vec4<f32>(e.pos, 1.0);
    let dc = frame.view_proj * vec4<f32>(e.dir, 0.0);
    if (c0.w <= 0.0) {
        return vec2<f32>(-1.0);
    }
    // Far enough to reach the screen's edge or the horizon; stop short of the camera plane.
    var len = 1e3 * max(linear_depth(c0), 1e-3);
    if (dc.w < 0.0) {
        len = min(len, 0.99 * (c0.w - 1e-3 * c0.w) / -dc.w);
    }
    let c1 = c0 + dc * len;
    let s0 = clip_to_pixel(c0);
    let s1 = clip_to_pixel(c1);
    let z0 = c0.z / c0.w;
    let z1 = c1.z / c1.w;
    // The screen-space segment clipped to the viewport: k ∈ [0, k_end].
    let d = s1 - s0;
    var k_end = 1.0;
    for (var a = 0u; a < 2u; a++) {
        if (d[a] > 0.0) {
            k_end = min(k_end, (frame.viewport[a] - 0.5 - s0[a]) / d[a]);
        } else if (d[a] < 0.0) {
            k_end = min(k_end, (0.5 - s0[a]) / d[a]);
        }
    }
    if (k_end <= 0.0) {
        return vec2<f32>(-1.0);
    }
    // A sample stops the march when the ray is behind the opaque surface there, or when it
    // has passed from over a surface to over the sky (it crossed that surface's far edge, or
    // dipped below it in between: the bisection tells which).
    var lo = 0.0;
    var hi = -1.0;
    var over_surface = false;
    for (var i = 1u; i <= OUTSIDE_STEPS; i++) {
        // Denser near the exit, where a surface close to the glass is met at a steep angle.
        let u = f32(i) / f32(OUTSIDE_STEPS);
        let k = k_end * u * u;
        let depth = textureLoad(opaque_depth, vec2<i32>(mix(s0, s1, k)), 0);
        let sky = is_far_depth(depth);
        if ((!sky && mix(z0, z1, k) <= depth) || (sky && over_surface)) {
            hi = k;
            break;
        }
        over_surface = !sky;
        lo = k;
    }
    if (hi < 0.0) {
        return vec2<f32>(-1.0);
    }
    for (var i = 0u; i < REFINE_STEPS; i++) {
        let k = 0.5 * (lo + hi);
        let depth = textureLoad(opaque_depth, vec2<i32>(mix(s0, s1, k)), 0);
        if (is_far_depth(depth) || mix(z0, z1, k) <= depth) {
            hi = k;
        } else {
            lo = k;
        }
    }
    let depth = textureLoad(opaque_depth, vec2<i32>(mix(s0, s1, hi)), 0);
    if (is_far_depth(depth)) {
        return vec2<f32>(-1.0);
    }
    return mix(s0, s1, hi);
}

// Linear RGB of what a ray leaving the volume sees: the background where it lands (blurred by
// the roughness), else the environment's radiance in its direction (black without one) times
// `env_t`, what a medium's hooks let through of it (the background has had them already: in a
// medium filling the scene the environment was drawn at full strength through the glass).
// w is 1 where the ray took the environment (the spectral loop lets a hook's per-node
// transmittance through there instead of `env_t`).
fn seen_through(e: Exit, roughness: f32, env_t: vec3<f32>) -> vec4<f32> {
    let at = landing_pixel(e);
    if (at.x >= 0.0) {
        return vec4<f32>(background_at(at, roughness), 0.0);
    }
    if (!shading_env() || env.flags.y == 0u) {
        return vec4<f32>(0.0);
    }
    if (frame.mode == MODE_RGB) {
        return vec4<f32>(env_background(e.dir).rgb * env_t, 1.0);
    }
    return vec4<f32>(frame.xyz_to_rgb * env_xyz(env_background(e.dir)) * env_t, 1.0);
}

// The light arriving at the front surface through the volume, at index `ior`, before the base
// colour and the front interface: (rgb of the background, then w = the exit's 1 − F), and the
// path length inside in `length`.
struct Through {
    rgb: vec3<f32>,
    share: f32,
    length: f32,
    // Whether the ray left the screen for the environment (`seen_through`'s w).
    sky: bool,
};

fn through_volume(pix: vec2<f32>, p: vec3<f32>, s: GSurface, view_dir: vec3<f32>, ior: f32, thickness: f32, env_t: vec3<f32>) -> Through {
    let e = volume_exit(pix, p, s.normal, view_dir, ior, thickness);
    if (!e.traced) {
        // The slab model: the background behind the offset exit point, as seen from the camera.
        var at = pix;
        if (thickness > 0.0) {
            let clip = frame.view_proj * vec4<f32>(e.pos, 1.0);
            if (clip.w > 0.0) {
                at = clip_to_pixel(clip);
            }
        }
        return Through(background_at(at, s.roughness), 1.0, thickness, false);
    }
    let seen = seen_through(e, s.roughness, env_t);
    return Through(seen.rgb, e.share, e.length, seen.w > 0.0);
}

// Taps of the roughness blur: the centre and two rings of six.
const BLUR_TAPS: u32 = 13u;

// The background around pixel `at`, blurred over a disc whose radius grows with α = roughness²
// (a tenth of the image height at α = 1): a rough surface refracts a cone, not a ray. As
// radiance: the target holds it times the exposure (`hdr_out`).
fn background_at(at: vec2<f32>, roughness: f32) -> vec3<f32> {
    let inv = frame.viewport.zw;
    let radius = 0.1 * roughness * roughness * frame.viewport.y;
    if (radius < 0.5) {
        return textureSampleLevel(background, env_sampler, clamp(at * inv, vec2<f32>(0.0), vec2<f32>(1.0)), 0.0).rgb / frame.exposure;
    }
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < BLUR_TAPS; i++) {
        var o = vec2<f32>(0.0);
        if (i > 0u) {
            let ring = select(1.0, 0.5, i > 6u);
            let a = f32(i) * (PI / 3.0) + select(0.0, PI / 6.0, i > 6u);
            o = ring * radius * vec2<f32>(cos(a), sin(a));
        }
        sum += textureSampleLevel(background, env_sampler, clamp((at + o) * inv, vec2<f32>(0.0), vec2<f32>(1.0)), 0.0).rgb;
    }
    return sum / (f32(BLUR_TAPS) * frame.exposure);
}

// What light `li` brings through a thin-walled see-through surface from behind it, per unit of
// its irradiance and of the base colour (the tint): the path tracer's thin sheet
// (truth::dielectric) has for transmission lobe its reflection lobe mirrored through the
// surface, with 1 − F of the light — which is the reflection of the mirrored view off the
// surface turned over (normal −n), so `light_terms` gives it, LTC for polygon lights included,
// and the shadow map is read on the far side. Zero on a volume (a light behind it lies behind
// its far side too, whose shadow stops it in the path tracer as well), for lights in front, and
// for emissive polygons: an emitter behind the surface is in the background the refracted view
// ray already reads (`transmitted_xyz`), blurred by the roughness — counted once.
fn thin_transmission(li: u32, p: vec3<f32>, s: GSurface, v: vec3<f32>, tr: Transmissive) -> f32 {
    if (!HAS_THIN_WALLS || tr.weight <= 0.0 || tr.thickness > 0.0 || u32(lights[li].pos_kind.w) == 3u) {
        return 0.0;
    }
    let n = s.normal;
    let t = light_terms(li, p, -n, v - 2.0 * dot(n, v) * n, s.roughness, no_aniso(), no_coat());
    let f = s.f0 + (1.0 - s.f0) * pow(1.0 - t.vh, 5.0);
    return tr.weight * t.ks * (1.0 - f);
}

// What the see-through surface lets through of the light behind it, before the base colour
// and the absorption: T·(1 − F(n·v)).
fn transmitted_share(s: GSurface, tr: Transmissive, v: vec3<f32>) -> f32 {
    let nv = max(dot(s.normal, v), 0.0);
    let f = s.f0 + (1.0 - s.f0) * pow(1.0 - nv, 5.0);
    return tr.weight * (1.0 - f);
}

// RGB mode: the light through the surface, tinted by the base colour and the absorption per
// channel; under dispersion the Khronos viewer's three indices (n_d ∓ half the spread
// (n_d − 1)/V_d) refract red, green and blue apart, each traced on its own.
// Under a thin film the share is 1 − the film's Fresnel term (what it does not reflect it
// transmits, as the path tracer's interface does), per channel.
fn transmitted_rgb(pix: vec2<f32>, ctx: SurfaceContext, s: GSurface, tr: Transmissive, film: FilmSurface) -> vec3<f32> {
    let k = transmitted_share(s, tr, -ctx.view_dir);
    if (k <= 0.0) {
        return vec3<f32>(0.0);
    }
    var k3 = vec3<f32>(k);
    if (HAS_FILM && film.weight > 0.0) {
        k3 = tr.weight * (1.0 - film_fresnel_rgb(film, s.base, 0.0, max(dot(s.normal, -ctx.view_dir), 0.0))[0]);
    }
    let p = ctx.world_pos;
    var env_t = vec3<f32>(1.0);
    if (CUSTOM_ENV_T) {
        env_t = custom_env_transmittance_rgb(ctx);
    }
    var light: vec3<f32>;
    if (disperses(tr)) {
        let half_spread = (tr.ior - 1.0) * 0.025 * tr.dispersion;
        for (var c = 0; c < 3; c++) {
            let th = through_volume(pix, p, s, ctx.view_dir, tr.ior + f32(c - 1) * half_spread, tr.thickness, env_t);
            light[c] = th.rgb[c] * th.share * exp(-tr.absorption[c] * th.length);
        }
    } else {
        let th = through_volume(pix, p, s, ctx.view_dir, tr.ior, tr.thickness, env_t);
        light = th.rgb * th.share * exp(-tr.absorption * th.length);
    }
    return k3 * s.base * light;
}

// The background colour's coefficients for the illuminant upsampling every RGB emission gets
// (s·sigmoid(rgb / s), s = 2·max; w = s): one fetch. The naive mode uses boxes instead.
fn background_coeffs(bg: vec3<f32>) -> vec4<f32> {
    let m = max(bg.r, max(bg.g, bg.b));
    if (NAIVE || m <= 0.0) {
        return vec4<f32>(0.0);
    }
    let c = fetch_coeffs_two(bg / (2.0 * m), true, vec3<f32>(0.0), false, frame.table_res).a;
    return vec4<f32>(c, 2.0 * m);
}

// The background's spectrum at group g's nodes.
fn background_nodes(bg: vec3<f32>, c: vec4<f32>, g: u32) -> vec4<f32> {
    if (NAIVE) {
        return box4(bg, g);
    }
    return c.w * sigmoid4(c.xyz, wavelengths[g].lambda);
}

// Spectral and naive modes: the transmitted light, node by node — the base colour's
// reflectance (coefficients `c_base`), the absorption exp(−σ_a(λ)·d) (a box spectrum per channel,
// exactly the box of the per-channel exp(−σ·d)) and the spectrum of what the ray meets. The
// spectral mode integrates the absorption's steps exactly (`box_white_weights`: the smooth
// factors at the nodes, the box in the weights); the naive mode samples every box at the nodes,
// as it does its reflectances. Under dispersion each group of four nodes is traced with the
// index at its mean wavelength: N/4 directions, each a trace, a background read and a
// coefficient fetch (a trace per node cost the glass scene's spectral frame 1.1–1.25× at
// N = 16 and changed its error by 0.003 ΔE at N = 8); without, one of each for the pixel
// (`transmitted_pixel`), which `transmitted_nodes` reuses for every group.
struct TransmittedPixel {
    // T·(1 − F(n·v)): nothing is transmitted where it is 0.
    k: f32,
    // Without dispersion: what the ray meets, and its coefficients (`background_coeffs`).
    th: Through,
    c_bg: vec4<f32>,
};

fn disperses(tr: Transmissive) -> bool {
    return HAS_DISPERSION && tr.dispersion > 0.0 && tr.thickness > 0.0;
}

fn transmitted_pixel(pix: vec2<f32>, ctx: SurfaceContext, s: GSurface, tr: Transmissive) -> TransmittedPixel {
    var tp = TransmittedPixel(transmitted_share(s, tr, -ctx.view_dir), Through(vec3<f32>(0.0), 0.0, 0.0, false), vec4<f32>(0.0));
    if (tp.k > 0.0 && !disperses(tr)) {
        tp.th = through_volume(pix, ctx.world_pos, s, ctx.view_dir, tr.ior, tr.thickness, vec3<f32>(1.0));
        tp.c_bg = background_coeffs(tp.th.rgb);
    }
    return tp;
}

// Group g's transmitted light: `light` at the nodes, times the absorption box `att` (per
// channel) in the weights (`transmitted_xyz`, `transmitted_weighted`); `sky` where the ray met
// the environment. Under dispersion each lane has its own ray (`dispersion_span`): its
// absorption per band in `att_r`, `att_g`, `att_b` and `sky_lanes` (`att` and `sky` unused).
struct TransmittedNodes {
    light: vec4<f32>,
    att: vec3<f32>,
    sky: bool,
    lanes: bool,
    att_r: vec4<f32>,
    att_g: vec4<f32>,
    att_b: vec4<f32>,
    sky_lanes: vec4<bool>,
};

// Nodes that share a refraction direction under dispersion: each node its own up to N = 8
// (two groups), pairs up to N = 16, the group's four beyond — at least five directions from
// N = 5 on. One direction per group left N ≤ 4 without any dispersion (one index for the
// whole spectrum: no fringe where the RGB mode's three channels split) and N = 8 with two
// blocks of colour whose fringes were 56 % more saturated than the truth's.
fn dispersion_span() -> u32 {
    return select(select(4u, 2u, frame.n_groups <= 4u), 1u, frame.n_groups <= 2u);
}

fn transmitted_nodes(pix: vec2<f32>, ctx: SurfaceContext, s: GSurface, tr: Transmissive, c_base: vec3<f32>, film: FilmSurface, tp: TransmittedPixel, g: u32) -> TransmittedNodes {
    let rho = node_reflectance(c_base, s.base, g);
    var kn = vec4<f32>(tp.k);
    if (HAS_FILM && film.weight > 0.0) {
        // Under a thin film: 1 − its Fresnel term per node (`film_fresnel`'s dielectric).
        let nv = max(dot(s.normal, -ctx.view_dir), 0.0);
        kn = tr.weight * (1.0 - film_fresnel(film, rho, 0.0, wavelengths[g].lambda, nv, vec4<f32>(0.0)).dielectric);
    }
    if (disperses(tr)) {
        // A ray per run of `span` lanes, at the run's mean wavelength.
        let l = wavelengths[g].lambda;
        let span = dispersion_span();
        let lane = vec4<u32>(0u, 1u, 2u, 3u);
        var seen = vec4<f32>(0.0);
        var t = TransmittedNodes(vec4<f32>(0.0), vec3<f32>(0.0), false, true, vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<bool>(false));
        for (var k = 0u; k < 4u; k += span) {
            let run = lane >= vec4<u32>(k) & lane < vec4<u32>(k + span);
            let mean = dot(select(vec4<f32>(0.0), l, run), vec4<f32>(1.0)) / f32(span);
            let th = through_volume(pix, ctx.world_pos, s, ctx.view_dir, abbe_ior(tr.ior, tr.dispersion, mean), tr.thickness, vec3<f32>(1.0));
            let a = exp(-tr.absorption * th.length);
            seen = select(seen, th.share * background_nodes(th.rgb, background_coeffs(th.rgb), g), run);
            t.att_r = select(t.att_r, vec4<f32>(a.r), run);
            t.att_g = select(t.att_g, vec4<f32>(a.g), run);
            t.att_b = select(t.att_b, vec4<f32>(a.b), run);
            t.sky_lanes = select(t.sky_lanes, vec4<bool>(th.sky), run);
        }
        t.light = kn * rho * seen;
        return t;
    }
    let th = tp.th;
    let att = exp(-tr.absorption * th.length);
    let light = kn * th.share * rho * background_nodes(th.rgb, tp.c_bg, g);
    return TransmittedNodes(light, att, th.sky, false, vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<bool>(false));
}

// The white's node weights with the absorption folded in (see `box_white_weights`), per lane
// where the lanes took rays of their own.
fn transmitted_weights(t: TransmittedNodes, g: u32) -> mat3x4<f32> {
    if (!t.lanes) {
        if (NAIVE) {
            return s3_scale(white_weights(g), box4(t.att, g));
        }
        return box_white_weights(t.att, g);
    }
    let w = wavelengths[g];
    if (NAIVE) {
        return s3_scale(white_weights(g), t.att_r * w.band_r + t.att_g * w.band_g + t.att_b * w.band_b);
    }
    return s3_scale(w.band_white_r, t.att_r) + s3_scale(w.band_white_g, t.att_g) + s3_scale(w.band_white_b, t.att_b);
}

// XYZ of the transmitted light (the direct spectral loop).
fn transmitted_xyz(pix: vec2<f32>, ctx: SurfaceContext, s: GSurface, tr: Transmissive, c_base: vec3<f32>, film: FilmSurface) -> vec3<f32> {
    let tp = transmitted_pixel(pix, ctx, s, tr);
    if (tp.k <= 0.0) {
        return vec3<f32>(0.0);
    }
    var xyz = vec3<f32>(0.0);
    for (var g = 0u; g < frame.n_groups; g++) {
        let t = transmitted_nodes(pix, ctx, s, tr, c_base, film, tp, g);
        if (t.lanes) {
            xyz += t.light * transmitted_weights(t, g);
        } else if (NAIVE) {
            xyz += (t.light * box4(t.att, g)) * white_weights(g);
        } else {
            xyz += t.light * box_white_weights(t.att, g);
        }
    }
    return xyz;
}

// The same in weighted form (the general node loop, which hooks transform and the capture stores).
fn transmitted_weighted(t: TransmittedNodes, g: u32) -> mat3x4<f32> {
    if (t.lanes) {
        return s3_scale(transmitted_weights(t, g), t.light);
    }
    if (NAIVE) {
        return s3_scale(white_weights(g), t.light * box4(t.att, g));
    }
    return s3_scale(box_white_weights(t.att, g), t.light);
}
