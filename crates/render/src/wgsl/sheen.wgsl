// KHR_materials_sheen (scene::sheen, which the path tracer calls in f64): the Charlie lobe D·V,
// Conty & Kulla's fitted Λ, and the base's albedo scaling, ported as written there (α =
// sheenRoughness², at least SHEEN_MIN_ALPHA). The directional albedo E is scene::sheen's
// table, appended to `coeff_scale` (render::coeff_table::GpuCoeffTable::axes) and interpolated
// as `AlbedoTable::lookup` does. Shading pass only (`HAS_SHEEN`).

const SHEEN_MIN_ALPHA: f32 = 0.07;
const SHEEN_MIN_ROUGHNESS: f32 = 0.26457513;
const SHEEN_TABLE_MU: u32 = 64u;
const SHEEN_TABLE_ROUGHNESS: u32 = 32u;

fn sheen_alpha(roughness: f32) -> f32 {
    let r = clamp(roughness, 0.0, 1.0);
    return max(r * r, SHEEN_MIN_ALPHA);
}

fn sheen_d(alpha: f32, nh: f32) -> f32 {
    let sin2 = max(1.0 - nh * nh, 0.0);
    let inv = 1.0 / alpha;
    return (2.0 + inv) * pow(sin2, 0.5 * inv) / (2.0 * PI);
}

fn sheen_l(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let a = mix(21.5473, 25.3245, t);
    let b = mix(3.82987, 3.32435, t);
    let c = mix(0.19823, 0.16801, t);
    let d = mix(-1.97760, -1.27393, t);
    let e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

// Λ at the cosine `c` (clamped to [0, 1]); both pieces by a select, not a branch.
fn sheen_lambda(c: f32, alpha: f32) -> f32 {
    let x = clamp(c, 0.0, 1.0);
    let low = exp(sheen_l(x, alpha));
    let high = exp(2.0 * sheen_l(0.5, alpha) - sheen_l(1.0 - x, alpha));
    return select(high, low, x < 0.5);
}

// E(μ) at n·v = `mu` for the sheen roughness `roughness`: bilinear in (√μ, roughness) between
// the table's nodes, clamped to the outer ones.
fn sheen_albedo(mu: f32, roughness: f32) -> f32 {
    let n = SHEEN_TABLE_MU * SHEEN_TABLE_ROUGHNESS;
    let first = arrayLength(&coeff_scale) - n;
    let p = clamp(sqrt(clamp(mu, 0.0, 1.0)) * f32(SHEEN_TABLE_MU) - 1.0, 0.0, f32(SHEEN_TABLE_MU - 1u));
    let i0 = min(u32(p), SHEEN_TABLE_MU - 1u);
    let i1 = min(i0 + 1u, SHEEN_TABLE_MU - 1u);
    let s = p - f32(i0);
    let x = (clamp(roughness, SHEEN_MIN_ROUGHNESS, 1.0) - SHEEN_MIN_ROUGHNESS) / (1.0 - SHEEN_MIN_ROUGHNESS);
    let q = clamp(x * f32(SHEEN_TABLE_ROUGHNESS - 1u), 0.0, f32(SHEEN_TABLE_ROUGHNESS - 1u));
    let j0 = min(u32(q), SHEEN_TABLE_ROUGHNESS - 1u);
    let j1 = min(j0 + 1u, SHEEN_TABLE_ROUGHNESS - 1u);
    let t = q - f32(j0);
    let r0 = coeff_scale[first + j0 * SHEEN_TABLE_MU + i0] * (1.0 - s) + coeff_scale[first + j0 * SHEEN_TABLE_MU + i1] * s;
    let r1 = coeff_scale[first + j1 * SHEEN_TABLE_MU + i0] * (1.0 - s) + coeff_scale[first + j1 * SHEEN_TABLE_MU + i1] * s;
    return r0 * (1.0 - t) + r1 * t;
}

// A pixel's sheen: its colour (linear RGB) and roughness, and what every light shares: α,
// c = max3(colour), E(n·v), Λ(n·v) and n·v. `on` false: no sheen (zero colour, unlit, the
// Lambert-only mode).
struct SheenSurface {
    on: bool,
    color: vec3<f32>,
    roughness: f32,
    alpha: f32,
    max_c: f32,
    e_v: f32,
    lambda_v: f32,
    nv: f32,
    // The colour's coefficients (the spectral modes), where it is not the material's constant.
    coeffs: vec3<f32>,
};

fn no_sheen() -> SheenSurface {
    return SheenSurface(false, vec3<f32>(0.0), 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, vec3<f32>(0.0));
}

fn sheen_surface(color: vec3<f32>, roughness: f32, n: vec3<f32>, v: vec3<f32>) -> SheenSurface {
    var sh: SheenSurface;
    sh.color = color;
    sh.roughness = roughness;
    sh.max_c = max(color.r, max(color.g, color.b));
    sh.on = sh.max_c > 0.0;
    sh.alpha = sheen_alpha(roughness);
    sh.nv = max(dot(n, v), 1e-4);
    sh.e_v = sheen_albedo(sh.nv, roughness);
    sh.lambda_v = sheen_lambda(sh.nv, sh.alpha);
    return sh;
}

// One light from the unit direction `wi` whose cosine-weighted irradiance factor is `kd`
// (`LightTerms::kd`): x what the sheen reflects per unit colour, kd·D·V; y the base's share
// min(1 − c·E(n·v), 1 − c·E(n·l)), which scales its diffuse and specular terms.
fn sheen_light(sh: SheenSurface, n: vec3<f32>, v: vec3<f32>, wi: vec3<f32>, kd: f32) -> vec2<f32> {
    let nl = dot(n, wi);
    if (!sh.on || nl <= 0.0) {
        return vec2<f32>(0.0, 1.0);
    }
    let nh = dot(n, normalize(wi + v));
    let lambdas = sh.lambda_v + sheen_lambda(nl, sh.alpha);
    let dv = sheen_d(sh.alpha, nh) / ((1.0 + lambdas) * (4.0 * (sh.nv * nl)));
    let e_l = sheen_albedo(nl, sh.roughness);
    let share = clamp(min(1.0 - sh.max_c * sh.e_v, 1.0 - sh.max_c * e_l), 0.0, 1.0);
    return vec2<f32>(kd * dv, share);
}

// What the environment's base terms keep, 1 − c·E(n·v) (the albedo scaling at the view alone:
// the light's side is spread over the whole sky), and what the sheen reflects of the irradiance
// per unit colour, E(n·v)/π (the radiance around the lobe taken as the cosine-weighted mean).
fn sheen_env(sh: SheenSurface) -> vec2<f32> {
    if (!sh.on) {
        return vec2<f32>(1.0, 0.0);
    }
    return vec2<f32>(clamp(1.0 - sh.max_c * sh.e_v, 0.0, 1.0), sh.e_v / PI);
}
