// The environment light (src/environment.rs, src/env_gpu.rs): K = 4 coefficient maps whose
// coefficients multiply the basis spectra's node weights. Bind group 2, after the spectral data.

// `EnvUniforms` is byte for byte `env_gpu::EnvUniforms` (src/layout_tests.rs checks it).
struct EnvUniforms {
    // XYZ of each basis spectrum seen by a reflectance of one (spectral and naive modes).
    totals: array<vec4<f32>, 4>,
    // x: rotation about +Y (radians), y: coarsest mip level, z: intensity, w: world radius of
    // the screen-space occlusion search (0 = no occlusion).
    params: vec4<f32>,
    // x: 1 when there is an environment, y: 1 when it is the background.
    flags: vec4<u32>,
};

// Node weights of basis spectrum j for group g at env_weights[j * n_groups + g].
@group(2) @binding(5) var<storage, read> env_weights: array<mat3x4<f32>>;
// Radiance coefficients, prefiltered: mip level m for GGX roughness m / (levels − 1).
@group(2) @binding(6) var env_radiance: texture_2d<f32>;
// Irradiance coefficients E(n) = ∫ L max(n·l, 0) dl.
@group(2) @binding(7) var env_irradiance: texture_2d<f32>;
// Split-sum table: (A, B) at (n·v, roughness).
@group(2) @binding(8) var env_lut: texture_2d<f32>;
@group(2) @binding(9) var env_sampler: sampler;
@group(2) @binding(10) var<uniform> env: EnvUniforms;

const ENV_LUT_SIZE: f32 = 32.0;

fn env_enabled() -> bool {
    return env.flags.x != 0u;
}

// Image coordinates of a world direction (scene::environment's convention: u = ½ + φ/2π with
// φ = atan2(x, −z) − rotation, v = θ/π from +Y).
fn env_uv(d: vec3<f32>) -> vec2<f32> {
    let phi = atan2(d.x, -d.z) - env.params.x;
    return vec2<f32>(fract(phi / (2.0 * PI) + 0.5), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

// Coefficients of the radiance arriving from direction d (unfiltered: the background).
fn env_background(d: vec3<f32>) -> vec4<f32> {
    return textureSampleLevel(env_radiance, env_sampler, env_uv(d), 0.0) * env.params.z;
}

// What the environment contributes at a surface, as two coefficient vectors: `a` multiplies
// the reflectance ρ(λ) (diffuse, and metals' tinted specular), `b` does not (dielectric and
// edge specular), like `factors_of` for a punctual light.
struct EnvTerms {
    a: vec4<f32>,
    b: vec4<f32>,
    // The part of `b` that the dielectric's F0 multiplies, per unit F0: a tinted specular
    // colour's reflectance F0(λ) takes it in place of the F0 that `b` was made with.
    f0: vec4<f32>,
};

// The environment's two lobes at a surface, before any material weighs them: the irradiance
// coefficients, the prefiltered radiance around the mirror direction, the split-sum factors
// (A, B) of the specular lobe's directional albedo F0·A + B, and n·v.
struct EnvLobes {
    irr: vec4<f32>,
    spec: vec4<f32>,
    ab: vec2<f32>,
    nv: f32,
};

fn env_lobes(n: vec3<f32>, v: vec3<f32>, roughness: f32) -> EnvLobes {
    var l: EnvLobes;
    let k = env.params.z;
    l.nv = max(dot(n, v), 1e-4);
    let r = reflect(-v, n);
    let half_texel = 0.5 / ENV_LUT_SIZE;
    let lut_uv = clamp(vec2<f32>(l.nv, roughness), vec2<f32>(half_texel), vec2<f32>(1.0 - half_texel));
    l.ab = textureSampleLevel(env_lut, env_sampler, lut_uv, 0.0).xy;
    l.irr = textureSampleLevel(env_irradiance, env_sampler, env_uv(n), 0.0) * k;
    l.spec = textureSampleLevel(env_radiance, env_sampler, env_uv(r), roughness * env.params.y) * k;
    return l;
}

// The irradiance coefficients at normal n (`EnvLobes::irr` alone).
fn env_irradiance_at(n: vec3<f32>) -> vec4<f32> {
    if (!env_enabled()) {
        return vec4<f32>(0.0);
    }
    return textureSampleLevel(env_irradiance, env_sampler, env_uv(n), 0.0) * env.params.z;
}

fn env_terms(n: vec3<f32>, v: vec3<f32>, metallic: f32, roughness: f32, lambert: bool, f0: f32, w: f32) -> EnvTerms {
    return env_terms_keep(n, v, metallic, roughness, lambert, f0, 1.0, w);
}

// `env_terms` with the diffuse layer scaled by `keep` (a see-through dielectric's diffuse is
// 1 − its transmission, wgsl/transmission.wgsl); `keep` = 1 leaves every product exact. `w` is
// the dielectric's specular weight (KHR_materials_specular; 1 without, exact too).
fn env_terms_keep(n: vec3<f32>, v: vec3<f32>, metallic: f32, roughness: f32, lambert: bool, f0: f32, keep: f32, w: f32) -> EnvTerms {
    var t: EnvTerms;
    if (!env_enabled()) {
        return t;
    }
    if (lambert) {
        t.a = textureSampleLevel(env_irradiance, env_sampler, env_uv(n), 0.0) * env.params.z / PI;
        return t;
    }
    let l = env_lobes(n, v, roughness);
    // The dielectric specular lobe's directional albedo, and what the diffuse layer loses: the
    // Fresnel term averaged over the light it receives (`fresnel_diffuse`), not the lobe's
    // albedo, which counts the lobe's own energy loss (at F0 = 1 it left diffuse light).
    let f_d = w * (f0 * l.ab.x + l.ab.y);
    let lost = w * fresnel_diffuse(f0, l.nv);
    t.a = (1.0 - metallic) * (1.0 - lost) / PI * keep * l.irr + metallic * l.ab.x * l.spec;
    t.b = ((1.0 - metallic) * f_d + metallic * l.ab.y) * l.spec;
    t.f0 = (1.0 - metallic) * w * l.ab.x * l.spec;
    return t;
}

// Schlick's Fresnel term F(v·h) = F0 + (1 − F0)(1 − v·h)⁵ averaged over cosine-weighted light
// directions l (h the half vector of v and l) at view cosine n·v: what a Lambertian layer under
// the dielectric loses of light arriving from all sides, F0 + (1 − F0)·Φ(n·v). Φ is a degree-4
// fit in x = 1 − n·v of the integral (max error 1.2·10⁻⁵; Φ(1) = 8·10⁻⁵, Φ(0) = 0.028), so that
// in a uniform environment the diffuse is the path tracer's (1 − F(v·h)) integrated.
fn fresnel_diffuse(f0: f32, nv: f32) -> f32 {
    let x = 1.0 - clamp(nv, 0.0, 1.0);
    let phi = (((8.8794866e-3 * x + 7.9300251e-3) * x + 9.2339051e-3) * x + 2.0339718e-3) * x + 8.1711100e-5;
    return f0 + (1.0 - f0) * phi;
}

// How many basis spectra the environment's texels use (src/environment.rs,
// `SpectralBasis::used`; 1 for an environment of one spectral shape such as the default sky):
// the coefficients after them are zero, so their node weights are not read.
override ENV_BASES: u32 = 4u;

// Node weights of coefficients c for group g: Σ_j c_j · B_{j,g}.
fn env_w(c: vec4<f32>, g: u32, n_groups: u32) -> mat3x4<f32> {
    var m = env_weights[g] * c.x;
    if (ENV_BASES > 1u) {
        m += env_weights[n_groups + g] * c.y;
    }
    if (ENV_BASES > 2u) {
        m += env_weights[2u * n_groups + g] * c.z;
    }
    if (ENV_BASES > 3u) {
        m += env_weights[3u * n_groups + g] * c.w;
    }
    return m;
}

// XYZ of coefficients c seen by a reflectance of one.
fn env_xyz(c: vec4<f32>) -> vec3<f32> {
    return env.totals[0].xyz * c.x + env.totals[1].xyz * c.y + env.totals[2].xyz * c.z + env.totals[3].xyz * c.w;
}
