// An RGB medium filling the scene (issue 18), installed by `rgb_medium::shader`; the model,
// parameter layout and assumptions are in src/passes/rgb_medium.rs. Prepended:
// medium_common.wgsl.
//
// custom.params[0] = (march steps M (0 = no in-scattering), Henyey–Greenstein g, march length
//                     cap in scene units, 1 = the medium's upsampling is box)
// custom.params[1] = (σ_s R, G, B per scene unit, 1 = multiple scattering on)
// custom.params[2] = (σ_t R, G, B per scene unit, unused)
// custom.params[3] = (the box bands' edges: blue|green, green|red (nm), unused, unused)
// custom_spectra[g * 4 + 0, 1] = σ_s, σ_t upsampled by the medium's method (spectral mode)
// custom_spectra[g * 4 + 2] = the albedo σ_s/σ_t of the box-upsampled medium
//
// Coefficients are vec4: the group's four node wavelengths, or (R, G, B, 0) in rgb mode, and
// light is in weighted form (mat3x4, custom_hooks.wgsl), so every mode runs the same code.
//
// Box media (naive mode; spectral mode with box upsampling): σ_t(λ) is a step function, and so
// is every transmittance e^{−σ_t(λ)·s} — the box spectrum of the per-channel e^{−σ_t,c·s}. A
// step sampled at the nodes moves to the nearest node (up to 28 % of the red channel through
// an optical depth of 2 at N = 16, docs/rgb-media.md), so these media take each node's value
// as the mean of the box spectrum over the node's footprint (its share of each band, `rm_box`)
// and compute the exponentials per channel.

// MAX_LIGHTS in src/scene_gpu.rs (checked by src/layout_tests.rs).
const RM_MAX_LIGHTS: u32 = 32u;
// Lights with in-scattering (the first non-directional ones) and march steps: SS_LIGHTS and
// MAX_STEPS in rgb_medium.rs (checked by src/layout_tests.rs).
const RM_SS_LIGHTS: u32 = 4u;
const RM_MAX_STEPS: u32 = 32u;
const RM_ZERO: mat3x4<f32> = mat3x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));

// Per-pixel, wavelength-independent march, filled once by `rm_prepare` (from `custom_prepare`,
// before the hooks that read it) and reused by every
// wavelength group: for light slot j and step k, weight W = phase × visibility × incidence ×
// step length and optical path s (scene units, light → point → camera), so that the light's
// single scattering is σ_s·Σ_k W·e^{−σ_t·s}.
var<private> rm_n: u32 = 0u;
var<private> rm_steps: u32 = 0u;
var<private> rm_light: array<u32, RM_SS_LIGHTS>;
var<private> rm_w: array<f32, 128>;
var<private> rm_s: array<f32, 128>;
// For the multiple scattering (below): the step's distance to the light, its length (scene
// units) and each slot's mean intensity over the sphere relative to the light's intensity.
var<private> rm_r: array<f32, 128>;
var<private> rm_dt: array<f32, 128>;
var<private> rm_iavg: array<f32, RM_SS_LIGHTS>;
// The view ray's length through the medium to the surface (0 for the background). The medium
// starts at the eye (`ctx.origin`), as the path tracer's camera rays do (truth::camera): the
// near plane clips surfaces, not the medium.
var<private> rm_d: f32 = 0.0;

// (σ_s, σ_t) of the group (spectral mode, smooth upsampling) or, in rgb mode, of the three
// channels.
fn rm_coefficients(group: u32, rgb: bool) -> mat2x4<f32> {
    if (rgb) {
        return mat2x4<f32>(vec4<f32>(custom.params[1].xyz, 0.0), vec4<f32>(custom.params[2].xyz, 0.0));
    }
    return mat2x4<f32>(custom_spectra[group * 4u], custom_spectra[group * 4u + 1u]);
}

// Whether the group is drawn as a box medium (see the top of the file).
fn rm_boxed(rgb: bool) -> bool {
    return !rgb && (frame.mode == MODE_NAIVE || custom.params[0].w > 0.5);
}

// The fraction of each node's footprint (the node spacing, centred on the node) above `edge`;
// a point test with one node.
fn rm_above(lambda: vec4<f32>, edge: f32) -> vec4<f32> {
    let w0 = wavelengths[0].lambda;
    let dl = w0.y - w0.x;
    if (dl <= 0.0) {
        return select(vec4<f32>(0.0), vec4<f32>(1.0), lambda >= vec4<f32>(edge));
    }
    return clamp((lambda + 0.5 * dl - edge) / dl, vec4<f32>(0.0), vec4<f32>(1.0));
}

// The box spectrum of per-channel values v at the group's nodes, each the mean over its
// footprint.
fn rm_box(v: vec3<f32>, lambda: vec4<f32>) -> vec4<f32> {
    let gr = rm_above(lambda, custom.params[3].y);
    let bg = rm_above(lambda, custom.params[3].x);
    return v.r * gr + v.g * (bg - gr) + v.b * (vec4<f32>(1.0) - bg);
}

// Where the medium sees light `li` from: its position, a polygon's centroid.
fn rm_light_pos(li: u32) -> vec3<f32> {
    if (u32(lights[li].pos_kind.w) == 3u) {
        return polygon_centroid(li);
    }
    return lights[li].pos_kind.xyz;
}

fn rm_emission(li: u32, group: u32, rgb: bool) -> mat3x4<f32> {
    if (rgb) {
        return mat3x4<f32>(vec4<f32>(lights[li].rgb.rgb, 0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    }
    return light_w(li, group, frame.n_groups);
}

// Φ/(4π·I): a light's mean intensity over the sphere relative to what `light_incidence` calls
// its intensity — 1 for a point light; a spot light's cone (taken halfway between its inner
// and outer edges) over the sphere; a polygon's L·area·cos emitted into a hemisphere, πLA/4π.
fn rm_mean_intensity(li: u32) -> f32 {
    let kind = u32(lights[li].pos_kind.w);
    if (kind == 2u) {
        let c = clamp(lights[li].cone.x + 0.5 / max(lights[li].cone.y, 1e-6), -1.0, 1.0);
        return 0.5 * (1.0 - c);
    }
    if (kind == 3u) {
        return 0.25;
    }
    return 1.0;
}

fn custom_prepare(ctx: SurfaceContext) {
    rm_prepare(ctx);
}

fn rm_prepare(ctx: SurfaceContext) {
    if (!ctx.background) {
        rm_d = ctx.distance;
    }
    let m = min(u32(custom.params[0].x), RM_MAX_STEPS);
    rm_steps = m;
    if (m == 0u) { return; }
    let g = custom.params[0].y;
    let cap = custom.params[0].z;
    // A background ray runs until the medium has swallowed everything (the cap: a few
    // optical depths of the clearest wavelength).
    let len = select(min(rm_d, cap), cap, ctx.background);
    let w = ctx.view_dir;
    let cam = ctx.origin;
    var n = 0u;
    for (var li = 0u; li < min(frame.n_lights, RM_MAX_LIGHTS); li++) {
        if (n == RM_SS_LIGHTS) { break; }
        // Directional light does not reach into a medium without end (as in the path tracer).
        if (u32(lights[li].pos_kind.w) == 0u) { continue; }
        let eq = medium_equiangular(rm_light_pos(li) - cam, w, len, m);
        for (var k = 0u; k < m; k++) {
            let st = medium_equiangular_step(eq, k);
            let x = cam + w * st.x;
            let inc = light_incidence(li, x);
            let v = light_visibility(li, x, vec3<f32>(0.0));
            rm_w[n * RM_MAX_STEPS + k] = medium_hg(g, dot(inc.xyz, w)) * v * inc.w * st.z;
            rm_s[n * RM_MAX_STEPS + k] = st.x + st.y;
            rm_r[n * RM_MAX_STEPS + k] = st.y;
            rm_dt[n * RM_MAX_STEPS + k] = st.z;
        }
        rm_iavg[n] = rm_mean_intensity(li);
        rm_light[n] = li;
        n++;
    }
    rm_n = n;
}

// Single scattering of the marched lights along the view ray, in weighted form.
fn rm_in_scatter(ss: vec4<f32>, st: vec4<f32>, group: u32, rgb: bool) -> mat3x4<f32> {
    let stl = rm_light_extinction(ss, st);
    var total = RM_ZERO;
    for (var j = 0u; j < rm_n; j++) {
        var sum = vec4<f32>(0.0);
        let base = j * RM_MAX_STEPS;
        for (var k = 0u; k < rm_steps; k++) {
            let r = rm_r[base + k];
            sum = fma(vec4<f32>(rm_w[base + k]), exp(-st * (rm_s[base + k] - r) - stl * r), sum);
        }
        total += s3_scale(rm_emission(rm_light[j], group, rgb), ss * sum);
    }
    return total;
}

// Box media: σ_s(λ)·Σ_k W·e^{−σ_t(λ)·s} = α(λ)·box(σ_t,c·Σ_k W·e^{−σ_t,c·s}) with the albedo α
// smooth (a reflectance through the table), per node.
fn rm_in_scatter_box(lambda: vec4<f32>, group: u32) -> mat3x4<f32> {
    let st = custom.params[2].xyz;
    let stl = rm_light_extinction(vec4<f32>(custom.params[1].xyz, 0.0), vec4<f32>(st, 0.0)).xyz;
    let alpha = custom_spectra[group * 4u + 2u];
    var total = RM_ZERO;
    for (var j = 0u; j < rm_n; j++) {
        var sum = vec3<f32>(0.0);
        let base = j * RM_MAX_STEPS;
        for (var k = 0u; k < rm_steps; k++) {
            let r = rm_r[base + k];
            sum = fma(vec3<f32>(rm_w[base + k]), exp(-st * (rm_s[base + k] - r) - stl * r), sum);
        }
        total += s3_scale(rm_emission(rm_light[j], group, false), alpha * rm_box(st * sum, lambda));
    }
    return total;
}

// ---- Multiple scattering (docs/rgb-media.md, "Multiple scattering") ----
//
// What single scattering leaves out is the light that has collided at least once: its
// fluence φ_c around each light, in a medium without end, scattered once more towards the
// camera along the view ray (isotropically: light that has collided is spread over all
// directions) and falling on surfaces. φ_c is modelled per wavelength (or channel) for a
// point source of intensity I (Φ = 4πI) as
//
//   φ_c(r) = I·σ_s·K(σ_t·r)/r + I·(α²/σ_a)·κ²·e^{−κr}/r
//
// - first term: the once-collided fluence of isotropic scattering, exact up to K's fit:
//   K(x) = ∫₀¹ e^{−x/u}·ln((1+u)/(1−u)) du/u, K(0) = π²/4 (fitted within 3.5 % on
//   0 ≤ x ≤ 20 by (π²/4)·e^{−x}/(1 + 4.2534x + 0.71314x²)^0.41837);
// - second term: all higher orders, with their exact total ∫φ dV = Φ·α²/σ_a (each collision
//   keeps a fraction α of the power, and fluence integrates to power over σ_t) spread as
//   e^{−κr}/r, the far-field shape of the transport solution: κ = ν·σ_t with α·atanh(ν) = ν
//   (the asymptotic decay of isotropic scattering, diffusion's √(3σ_aσ_t) as α → 1), in
//   the similarity-reduced medium σ_s' = σ_s·(1 − g), σ_t' = σ_a + σ_s' for anisotropic
//   scattering: all of φ_c is that medium's (isotropic) collided light, and the light
//   scattered forward travels on with the direct light, extinguished by σ_t'
//   (`rm_light_extinction`). The view ray keeps σ_t: the halo that forward scattering
//   spreads around what the camera sees is left out, so images stay sharp.
//
// A surface facing the light at cosine c receives E = φ_c·(1/4 + c·min(D·(κ + 1/r), 1)/2)
// (an isotropic field's φ/4 plus half the diffusion flux J = −D·∇φ, D = 1/(3σ_t')).

const RM_PI2_4: f32 = 2.4674011002723395;

fn rm_k(x: vec4<f32>) -> vec4<f32> {
    return RM_PI2_4 * exp(-x) * pow(1.0 + x * (4.25339 + 0.713143 * x), vec4<f32>(-0.418368));
}

// ν with α·atanh(ν) = ν, per lane: Newton in u = atanh(ν) from the right of the root (the
// function αu − tanh u is convex for u > 0, so the iterates fall monotonically onto it),
// starting at the smaller of diffusion's √(3(1 − α)) and 1/α.
fn rm_nu(alpha: vec4<f32>) -> vec4<f32> {
    let a = clamp(alpha, vec4<f32>(1e-4), vec4<f32>(0.9999));
    let nd = min(sqrt(3.0 * (1.0 - a)), vec4<f32>(0.99999));
    var u = min(0.5 * log((1.0 + nd) / (1.0 - nd)), 1.0 / a);
    for (var i = 0; i < 12; i++) {
        let t = tanh(u);
        u = max(u - (a * u - t) / (a - 1.0 + t * t), vec4<f32>(1e-6));
    }
    return tanh(u);
}

// The per-wavelength constants of φ_c in the reduced medium: σ_s', σ_t', α'²κ²/σ_a, κ, D.
struct RmMs {
    c1: vec4<f32>,
    st: vec4<f32>,
    c2: vec4<f32>,
    kappa: vec4<f32>,
    diff: vec4<f32>,
};

fn rm_ms_constants(ss: vec4<f32>, st: vec4<f32>) -> RmMs {
    let g = custom.params[0].y;
    let sa = max(st - ss, vec4<f32>(0.0));
    let ssr = ss * (1.0 - g);
    let str = sa + ssr;
    let ar = select(vec4<f32>(0.0), ssr / str, str > vec4<f32>(0.0));
    let nu = rm_nu(ar);
    let kappa = nu * str;
    // κ²/σ_a, continuous into a conservative medium (σ_a → 0), where it is 3σ_t'.
    let k2a = select(nu * nu * str * str / max(sa, vec4<f32>(1e-30)), 3.0 * str, sa <= 1e-5 * st);
    var m: RmMs;
    m.c1 = ssr;
    m.st = str;
    m.c2 = ar * ar * k2a;
    m.kappa = kappa;
    m.diff = 1.0 / max(3.0 * str, vec4<f32>(1e-30));
    return m;
}

// φ_c(r)/I.
fn rm_phi(m: RmMs, r: f32) -> vec4<f32> {
    let rr = max(r, 1e-4);
    return (m.c1 * rm_k(m.st * rr) + m.c2 * exp(-m.kappa * rr)) / rr;
}

// Per marched light j: σ_s'/(4π)·∫ φ_c(r(t))/I·e^{−σ_t·t} dt along the view ray.
fn rm_ms_view(j: u32, m: RmMs, st: vec4<f32>) -> vec4<f32> {
    var sum = vec4<f32>(0.0);
    let base = j * RM_MAX_STEPS;
    for (var k = 0u; k < rm_steps; k++) {
        let r = rm_r[base + k];
        let t = rm_s[base + k] - r;
        sum = fma(rm_phi(m, r) * rm_dt[base + k], exp(-st * t), sum);
    }
    return m.c1 * MEDIUM_INV_4PI * rm_iavg[j] * sum;
}

// Per marched light j: the irradiance φ_c brings to the surface at p with normal n, over I.
fn rm_ms_surface(j: u32, m: RmMs, p: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let to_l = rm_light_pos(rm_light[j]) - p;
    let r = max(length(to_l), 1e-4);
    let c = dot(n, to_l) / r;
    let flux = min(m.diff * (m.kappa + 1.0 / r), vec4<f32>(1.0));
    return rm_iavg[j] * rm_phi(m, r) * max(0.25 + 0.5 * c * flux, vec4<f32>(0.0));
}

fn rm_multiple() -> bool {
    return u32(custom.params[0].x) > 0u && custom.params[1].w > 0.5;
}

// The extinction on the light's leg of every path (to a surface, to a marched step): with
// multiple scattering σ_t' = σ_t − g·σ_s, the similarity-reduced medium's, where the light
// scattered forward (the part g of the phase function that HG concentrates ahead) counts as
// still on its way; the collided light of the reduced medium is then φ_c (below). Without,
// σ_t: single scattering as the path tracer's --direct-only computes it.
fn rm_light_extinction(ss: vec4<f32>, st: vec4<f32>) -> vec4<f32> {
    if (custom.params[1].w > 0.5 && u32(custom.params[0].x) > 0u) {
        return max(st - custom.params[0].y * ss, vec4<f32>(0.0));
    }
    return st;
}

// Σ over the marched lights of emission × per-lane factor, either along the view or on the
// surface (`surface`), for coefficients (ss, st) per lane; box media take per-channel
// coefficients and give each node its footprint's mean.
fn rm_ms_total(ss: vec4<f32>, st: vec4<f32>, lambda: vec4<f32>, group: u32, rgb: bool, boxed: bool,
               surface: bool, ctx: SurfaceContext) -> mat3x4<f32> {
    var total = RM_ZERO;
    let m = rm_ms_constants(ss, st);
    for (var j = 0u; j < rm_n; j++) {
        var f: vec4<f32>;
        if (surface) {
            f = rm_ms_surface(j, m, ctx.world_pos, ctx.normal) * exp(-st * rm_d);
        } else {
            f = rm_ms_view(j, m, st);
        }
        if (boxed) {
            f = rm_box(f.xyz, lambda);
        }
        total += s3_scale(rm_emission(rm_light[j], group, rgb), f);
    }
    return total;
}

fn rm_ms_coefficients(group: u32, rgb: bool) -> mat2x4<f32> {
    if (rm_boxed(rgb)) {
        return mat2x4<f32>(vec4<f32>(custom.params[1].xyz, 0.0), vec4<f32>(custom.params[2].xyz, 0.0));
    }
    return rm_coefficients(group, rgb);
}

fn custom_irradiance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    if (!rm_multiple() || ctx.background) {
        return RM_ZERO;
    }
    let k = rm_ms_coefficients(group, false);
    return rm_ms_total(k[0], k[1], lambda, group, false, rm_boxed(false), true, ctx);
}

fn custom_irradiance_rgb(ctx: SurfaceContext) -> vec3<f32> {
    if (!rm_multiple() || ctx.background) {
        return vec3<f32>(0.0);
    }
    let k = rm_coefficients(0u, true);
    return rm_ms_total(k[0], k[1], vec4<f32>(0.0), 0u, true, false, true, ctx)[0].rgb;
}

fn rm_shade(radiance: mat3x4<f32>, lambda: vec4<f32>, group: u32, rgb: bool, ctx: SurfaceContext) -> mat3x4<f32> {
    var ms = RM_ZERO;
    if (rm_multiple()) {
        let km = rm_ms_coefficients(group, rgb);
        ms = rm_ms_total(km[0], km[1], lambda, group, rgb, rm_boxed(rgb), false, ctx);
    }
    if (rm_boxed(rgb)) {
        var l = rm_in_scatter_box(lambda, group) + ms;
        if (!ctx.background) {
            l += s3_scale(radiance, rm_box(exp(-custom.params[2].xyz * rm_d), lambda));
        }
        return l;
    }
    let k = rm_coefficients(group, rgb);
    var l = rm_in_scatter(k[0], k[1], group, rgb) + ms;
    if (!ctx.background) {
        l += s3_scale(radiance, exp(-k[1] * rm_d));
    }
    return l;
}

// Where light `li` comes from, for a point p: its distance, or −1 for a directional light
// (which does not reach into a medium without end, as in the path tracer).
fn rm_light_distance(li: u32, p: vec3<f32>) -> f32 {
    if (u32(lights[li].pos_kind.w) == 0u) {
        return -1.0;
    }
    return distance(rm_light_pos(li), p);
}

// e^{−σ_t·r} from light `li` to p (0 for a directional light wherever σ_t > 0).
fn rm_transmittance(st: vec4<f32>, r: f32) -> vec4<f32> {
    if (r < 0.0) {
        return select(vec4<f32>(1.0), vec4<f32>(0.0), st > vec4<f32>(0.0));
    }
    return exp(-st * r);
}

fn custom_light_transmittance(li: u32, lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> {
    let r = rm_light_distance(li, ctx.world_pos);
    if (rm_boxed(false)) {
        let k = rm_light_extinction(vec4<f32>(custom.params[1].xyz, 0.0), vec4<f32>(custom.params[2].xyz, 0.0));
        return rm_box(rm_transmittance(k, r).xyz, lambda);
    }
    let k = rm_coefficients(group, false);
    return rm_transmittance(rm_light_extinction(k[0], k[1]), r);
}

fn custom_light_transmittance_rgb(li: u32, ctx: SurfaceContext) -> vec3<f32> {
    let k = rm_coefficients(0u, true);
    return rm_transmittance(rm_light_extinction(k[0], k[1]), rm_light_distance(li, ctx.world_pos)).rgb;
}

// The environment is infinitely far: a medium without end lets none of its light reach a
// surface wherever σ_t > 0 (as the path tracer; the background is extinguished by the view
// attenuation). Extinction σ_t, not the similarity-reduced one: the light is removed, not
// scattered within the medium's own term.
fn custom_env_transmittance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> {
    if (rm_boxed(false)) {
        return rm_box(rm_transmittance(vec4<f32>(custom.params[2].xyz, 0.0), -1.0).xyz, lambda);
    }
    return rm_transmittance(rm_coefficients(group, false)[1], -1.0);
}

fn custom_env_transmittance_rgb(ctx: SurfaceContext) -> vec3<f32> {
    return rm_transmittance(rm_coefficients(0u, true)[1], -1.0).rgb;
}

fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    return rm_shade(radiance, lambda, group, false, ctx);
}

fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> {
    let r = mat3x4<f32>(vec4<f32>(radiance, 0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    return rm_shade(r, vec4<f32>(0.0), 0u, true, ctx)[0].rgb;
}
