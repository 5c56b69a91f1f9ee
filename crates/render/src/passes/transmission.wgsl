// The transmissive layer's shading (KHR_materials_transmission, _volume, _dispersion): appended
// to shading.wgsl. The frame draws a scene with see-through materials in two layers
// (src/passes/gbuffer.rs `Layer`): the opaque one is shaded into `background`; then the
// shading pipeline with HAS_TRANSMISSION runs over the see-through layer's G-buffer, where each
// see-through pixel adds to its own reflection the light of the background where the refracted
// view ray leaves the surface:
//   T·(1 − F(n·v))·base(λ)·exp(−σ_a(λ)·d)·L_background(λ, exit point),
// with T the transmission factor × texture × (1 − metallic), F Schlick's Fresnel of the
// dielectric at n·v, d the volume's thickness (KHR_materials_volume; 0: thin-walled, straight
// through), σ_a its absorption upsampled per channel as a box (as the path tracer upsamples it),
// and the background blurred by the roughness. What the screen does not show (behind the
// camera, off screen, the surface's own back) cannot be refracted: the exit point is clamped to
// the screen; the path tracer traces the real interior instead.
// Pixels without a see-through surface in front pass the background through.

@group(1) @binding(10) var background: texture_2d<f32>;
override HAS_TRANSMISSION: bool = false;

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
    let t = textureLoad(gbuf_film, px, 0).xy;
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

// Where (pixels) the view ray refracted at p with index `ior` leaves a volume `thickness` deep:
// a thin wall (thickness 0) does not bend it.
fn exit_pixel(pix: vec2<f32>, p: vec3<f32>, n: vec3<f32>, view_dir: vec3<f32>, ior: f32, thickness: f32) -> vec2<f32> {
    if (thickness <= 0.0) {
        return pix;
    }
    let r = refract(view_dir, n, 1.0 / max(ior, 1.0));
    let clip = frame.view_proj * vec4<f32>(p + r * thickness, 1.0);
    if (clip.w <= 0.0) {
        return pix;
    }
    let ndc = clip.xy / clip.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * frame.viewport.x, (0.5 - ndc.y * 0.5) * frame.viewport.y);
}

// Taps of the roughness blur: the centre and two rings of six.
const BLUR_TAPS: u32 = 13u;

// The background around pixel `at`, blurred over a disc whose radius grows with α = roughness²
// (a tenth of the image height at α = 1): a rough surface refracts a cone, not a ray.
fn background_at(at: vec2<f32>, roughness: f32) -> vec3<f32> {
    let inv = frame.viewport.zw;
    let radius = 0.1 * roughness * roughness * frame.viewport.y;
    if (radius < 0.5) {
        return textureSampleLevel(background, env_sampler, clamp(at * inv, vec2<f32>(0.0), vec2<f32>(1.0)), 0.0).rgb;
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
    return sum / f32(BLUR_TAPS);
}

// What the see-through surface lets through of the light behind it, before the base colour
// and the absorption: T·(1 − F(n·v)).
fn transmitted_share(s: GSurface, tr: Transmissive, v: vec3<f32>) -> f32 {
    let nv = max(dot(s.normal, v), 0.0);
    let f = s.f0 + (1.0 - s.f0) * pow(1.0 - nv, 5.0);
    return tr.weight * (1.0 - f);
}

// RGB mode: the background behind the surface, tinted by the base colour and the absorption
// per channel; under dispersion the Khronos viewer's three indices (n_d ∓ half the spread
// (n_d − 1)/V_d) refract red, green and blue apart.
fn transmitted_rgb(pix: vec2<f32>, ctx: SurfaceContext, s: GSurface, tr: Transmissive) -> vec3<f32> {
    let k = transmitted_share(s, tr, -ctx.view_dir);
    if (k <= 0.0) {
        return vec3<f32>(0.0);
    }
    let p = ctx.world_pos;
    var bg: vec3<f32>;
    if (tr.dispersion > 0.0 && tr.thickness > 0.0) {
        let half_spread = (tr.ior - 1.0) * 0.025 * tr.dispersion;
        bg.r = background_at(exit_pixel(pix, p, s.normal, ctx.view_dir, tr.ior - half_spread, tr.thickness), s.roughness).r;
        bg.g = background_at(exit_pixel(pix, p, s.normal, ctx.view_dir, tr.ior, tr.thickness), s.roughness).g;
        bg.b = background_at(exit_pixel(pix, p, s.normal, ctx.view_dir, tr.ior + half_spread, tr.thickness), s.roughness).b;
    } else {
        bg = background_at(exit_pixel(pix, p, s.normal, ctx.view_dir, tr.ior, tr.thickness), s.roughness);
    }
    return k * s.base * exp(-tr.absorption * tr.thickness) * bg;
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

// Spectral and naive modes: XYZ of the transmitted light, node by node — the base colour's
// reflectance (coefficients `c_base`), the absorption exp(−σ_a(λ)·d) (a box spectrum per channel,
// exactly the box of the per-channel exp(−σ·d)) and the background's spectrum. Under dispersion
// each group of four nodes refracts with the index at its mean wavelength: N/4 directions,
// each one background read and coefficient fetch; without, one of each for the pixel.
fn transmitted_xyz(pix: vec2<f32>, ctx: SurfaceContext, s: GSurface, tr: Transmissive, c_base: vec3<f32>) -> vec3<f32> {
    let k = transmitted_share(s, tr, -ctx.view_dir);
    if (k <= 0.0) {
        return vec3<f32>(0.0);
    }
    let p = ctx.world_pos;
    let att = exp(-tr.absorption * tr.thickness);
    let ng = frame.n_groups;
    let disperses = tr.dispersion > 0.0 && tr.thickness > 0.0;
    var bg = vec3<f32>(0.0);
    var c_bg = vec4<f32>(0.0);
    if (!disperses) {
        bg = background_at(exit_pixel(pix, p, s.normal, ctx.view_dir, tr.ior, tr.thickness), s.roughness);
        c_bg = background_coeffs(bg);
    }
    var xyz = vec3<f32>(0.0);
    for (var g = 0u; g < ng; g++) {
        if (disperses) {
            let l = wavelengths[g].lambda;
            let ior = abbe_ior(tr.ior, tr.dispersion, 0.25 * (l.x + l.y + l.z + l.w));
            bg = background_at(exit_pixel(pix, p, s.normal, ctx.view_dir, ior, tr.thickness), s.roughness);
            c_bg = background_coeffs(bg);
        }
        let rho = node_reflectance(c_base, s.base, g);
        xyz += (k * rho * box4(att, g) * background_nodes(bg, c_bg, g)) * white_weights(g);
    }
    return xyz;
}
