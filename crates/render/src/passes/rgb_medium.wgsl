// An RGB medium filling the scene (issue 18), installed by `rgb_medium::shader`; the model,
// parameter layout and assumptions are in src/passes/rgb_medium.rs. Prepended:
// medium_common.wgsl.
//
// custom.params[0] = (march steps M (0 = no in-scattering), Henyey–Greenstein g, march length
//                     cap in scene units, 1 = the medium's upsampling is box)
// custom.params[1] = (σ_s R, G, B per scene unit, unused)
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

// Per-pixel, wavelength-independent march, filled once by `rm_prepare` and reused by every
// wavelength group: for light slot j and step k, weight W = phase × visibility × incidence ×
// step length and optical path s (scene units, light → point → camera), so that the light's
// single scattering is σ_s·Σ_k W·e^{−σ_t·s}.
var<private> rm_ready: bool = false;
var<private> rm_n: u32 = 0u;
var<private> rm_steps: u32 = 0u;
var<private> rm_light: array<u32, RM_SS_LIGHTS>;
var<private> rm_w: array<f32, 128>;
var<private> rm_s: array<f32, 128>;
// Where the medium starts along the view ray (scene units from `ctx.origin`): the near plane,
// where the path tracer starts its camera rays (truth::camera), so both see the same path.
var<private> rm_t0: f32 = 0.0;
// The view ray's length through the medium to the surface (0 for the background).
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

fn rm_prepare(ctx: SurfaceContext) {
    if (rm_ready) { return; }
    rm_ready = true;
    let near = world_from_depth(vec2<f32>(ctx.pixel) + 0.5, 0.0, frame);
    rm_t0 = distance(ctx.origin, near);
    if (!ctx.background) {
        rm_t0 = min(rm_t0, ctx.distance);
        rm_d = ctx.distance - rm_t0;
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
    let cam = ctx.origin + w * rm_t0;
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
        }
        rm_light[n] = li;
        n++;
    }
    rm_n = n;
}

// Single scattering of the marched lights along the view ray, in weighted form.
fn rm_in_scatter(ss: vec4<f32>, st: vec4<f32>, group: u32, rgb: bool) -> mat3x4<f32> {
    var total = RM_ZERO;
    for (var j = 0u; j < rm_n; j++) {
        var sum = vec4<f32>(0.0);
        let base = j * RM_MAX_STEPS;
        for (var k = 0u; k < rm_steps; k++) {
            sum = fma(vec4<f32>(rm_w[base + k]), exp(-st * rm_s[base + k]), sum);
        }
        total += s3_scale(rm_emission(rm_light[j], group, rgb), ss * sum);
    }
    return total;
}

// Box media: σ_s(λ)·Σ_k W·e^{−σ_t(λ)·s} = α(λ)·box(σ_t,c·Σ_k W·e^{−σ_t,c·s}) with the albedo α
// smooth (a reflectance through the table), per node.
fn rm_in_scatter_box(lambda: vec4<f32>, group: u32) -> mat3x4<f32> {
    let st = custom.params[2].xyz;
    let alpha = custom_spectra[group * 4u + 2u];
    var total = RM_ZERO;
    for (var j = 0u; j < rm_n; j++) {
        var sum = vec3<f32>(0.0);
        let base = j * RM_MAX_STEPS;
        for (var k = 0u; k < rm_steps; k++) {
            sum = fma(vec3<f32>(rm_w[base + k]), exp(-st * rm_s[base + k]), sum);
        }
        total += s3_scale(rm_emission(rm_light[j], group, false), alpha * rm_box(st * sum, lambda));
    }
    return total;
}

fn rm_shade(radiance: mat3x4<f32>, lambda: vec4<f32>, group: u32, rgb: bool, ctx: SurfaceContext) -> mat3x4<f32> {
    rm_prepare(ctx);
    if (rm_boxed(rgb)) {
        var l = rm_in_scatter_box(lambda, group);
        if (!ctx.background) {
            l += s3_scale(radiance, rm_box(exp(-custom.params[2].xyz * rm_d), lambda));
        }
        return l;
    }
    let k = rm_coefficients(group, rgb);
    var l = rm_in_scatter(k[0], k[1], group, rgb);
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
        return rm_box(rm_transmittance(vec4<f32>(custom.params[2].xyz, 0.0), r).xyz, lambda);
    }
    return rm_transmittance(rm_coefficients(group, false)[1], r);
}

fn custom_light_transmittance_rgb(li: u32, ctx: SurfaceContext) -> vec3<f32> {
    return rm_transmittance(vec4<f32>(custom.params[2].xyz, 0.0), rm_light_distance(li, ctx.world_pos)).rgb;
}

fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    return rm_shade(radiance, lambda, group, false, ctx);
}

fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> {
    let r = mat3x4<f32>(vec4<f32>(radiance, 0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    return rm_shade(r, vec4<f32>(0.0), 0u, true, ctx)[0].rgb;
}
