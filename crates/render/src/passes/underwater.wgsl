// Underwater hooks (Monzón et al. 2024), installed by `underwater::shader`. See
// src/passes/underwater.rs for the model, the parameter layout and the assumptions; the CPU
// reference of every formula is `scene::water`.
//
// custom.params[0] = (camera depth z0 m, metres per scene unit, 0, 0)
// custom.params[1..4] = c, Kd, b at the RGB mode's three wavelengths (xyz)
// custom_spectra[g * 4 + 0..3] = b, c, Kd at the group's wavelengths

const UW_INV_4PI: f32 = 0.0795774715459476;
// Must match MAX_LIGHTS in src/scene_gpu.rs.
const UW_MAX_LIGHTS: u32 = 32u;

// (1 − e^{−k·d})/k, continuous through k = 0 (where it is d). The series is used where the
// subtraction would lose f32 digits; its truncation error is below (k·d)³/24·d < 1e-10·d.
fn uw_path_integral4(k: vec4<f32>, d: f32) -> vec4<f32> {
    let x = k * d;
    let series = d * (1.0 - 0.5 * x + x * x / 6.0);
    let exact = (1.0 - exp(-x)) / k;
    return select(exact, series, abs(x) < vec4<f32>(1e-3));
}

fn uw_path_integral3(k: vec3<f32>, d: f32) -> vec3<f32> {
    let x = k * d;
    let series = d * (1.0 - 0.5 * x + x * x / 6.0);
    let exact = (1.0 - exp(-x)) / k;
    return select(exact, series, abs(x) < vec3<f32>(1e-3));
}

// Downwelling irradiance just below the surface: every directional light's emission times the
// cosine of its direction with the downward vertical (point and spot lights do not reach the
// surface's light field).
fn uw_e0_spectral(g: u32) -> vec4<f32> {
    var e = vec4<f32>(0.0);
    let ng = frame.n_groups;
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        let l = lights[li].pos_kind;
        if (u32(l.w) == 0u) {
            e = fma(vec4<f32>(max(-l.y, 0.0)), light_spectra[li * ng + g], e);
        }
    }
    return e;
}

fn uw_e0_rgb() -> vec3<f32> {
    var e = vec3<f32>(0.0);
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        let l = lights[li].pos_kind;
        if (u32(l.w) == 0u) {
            e = fma(vec3<f32>(max(-l.y, 0.0)), lights[li].rgb.rgb, e);
        }
    }
    return e;
}

fn custom_spectral(lambda: vec4<f32>, radiance: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> {
    let z0 = custom.params[0].x;
    let scale = custom.params[0].y;
    let b = custom_spectra[group * 4u + 0u];
    let c = custom_spectra[group * 4u + 1u];
    let kd = custom_spectra[group * 4u + 2u];
    let wy = ctx.view_dir.y;
    // k = c + Kd·cosθ with cosθ = −ω_y.
    let k = c - kd * wy;
    let ms = b * uw_e0_spectral(group) * UW_INV_4PI * exp(-kd * z0);
    if (ctx.background) {
        // Nothing hit: an upward ray ends at the surface, any other runs forever (k ≥ c > 0).
        if (wy > 0.0) {
            return ms * uw_path_integral4(k, z0 / wy);
        }
        return ms / k;
    }
    let d = ctx.distance * scale;
    let zs = max(z0 - d * wy, 0.0);
    return fma(radiance, exp(-kd * zs) * exp(-c * d), ms * uw_path_integral4(k, d));
}

fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> {
    let z0 = custom.params[0].x;
    let scale = custom.params[0].y;
    let c = custom.params[1].xyz;
    let kd = custom.params[2].xyz;
    let b = custom.params[3].xyz;
    let wy = ctx.view_dir.y;
    let k = c - kd * wy;
    let ms = b * uw_e0_rgb() * UW_INV_4PI * exp(-kd * z0);
    if (ctx.background) {
        if (wy > 0.0) {
            return ms * uw_path_integral3(k, z0 / wy);
        }
        return ms / k;
    }
    let d = ctx.distance * scale;
    let zs = max(z0 - d * wy, 0.0);
    return fma(radiance, exp(-kd * zs) * exp(-c * d), ms * uw_path_integral3(k, d));
}

fn custom_pixel(hdr: vec4<f32>, ctx: SurfaceContext) -> vec4<f32> {
    return hdr;
}
