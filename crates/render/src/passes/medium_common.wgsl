// Pieces shared by the media hooks (underwater.wgsl, rgb_medium.wgsl): prepended to their
// source by `underwater::shader_with` and `rgb_medium::shader` (MEDIUM_COMMON in custom.rs), so
// the phase function, the path integral and the equiangular steps have one home.

const MEDIUM_INV_4PI: f32 = 0.0795774715459476;

// (1 − e^{−k·d})/k, continuous through k = 0 (where it is d). The subtraction loses what
// exp's error is of 1 − e^{−x}: a driver's exp good to 2⁻²² (an NVIDIA GPU's) gave 2·10⁻⁴ of
// relative error at x = 10⁻³. Below x = 1/8 the Taylor series (Horner, six terms: truncation
// x⁶/5040 < 10⁻⁸) is used instead, and above it the loss is at most 8× exp's error.
fn medium_path_integral(k: vec4<f32>, d: f32) -> vec4<f32> {
    let x = k * d;
    let series = d * (1.0 - x / 2.0 * (1.0 - x / 3.0 * (1.0 - x / 4.0 * (1.0 - x / 5.0 * (1.0 - x / 6.0)))));
    let exact = (1.0 - exp(-x)) / k;
    return select(exact, series, abs(x) < vec4<f32>(0.125));
}

// Henyey–Greenstein phase function (per steradian) at the cosine between the light's
// propagation direction and the scattered direction.
fn medium_hg(g: f32, cos_t: f32) -> f32 {
    let g2 = g * g;
    let den = max(1.0 + g2 - 2.0 * g * cos_t, 1e-6);
    return MEDIUM_INV_4PI * (1.0 - g2) / (den * sqrt(den));
}

// Equiangular steps (Kulla & Fajardo 2012) for a point light at `rel` from the ray's origin
// (any length unit), ray direction `w`, over [0, len] in `m` steps: with t − t0 = h·tan θ the
// light's 1/r² cancels the Jacobian, so the integrand is smooth in θ. `.x` = t0, `.y` = h,
// `.z` = θ at t = 0, `.w` = the step in θ.
fn medium_equiangular(rel: vec3<f32>, w: vec3<f32>, len: f32, m: u32) -> vec4<f32> {
    let t0 = dot(rel, w);
    let h = max(length(rel - w * t0), 1e-4);
    let ta = atan2(-t0, h);
    let tb = atan2(len - t0, h);
    return vec4<f32>(t0, h, ta, (tb - ta) / f32(m));
}

// Step k (midpoint in θ) of `medium_equiangular`'s steps `e`: `.x` = t along the ray, `.y` = r,
// the distance to the light, `.z` = r²·Δθ/h, the length the step stands for times r² (so a
// light's 1/r² times it is the step's weight).
fn medium_equiangular_step(e: vec4<f32>, k: u32) -> vec3<f32> {
    let th = e.z + (f32(k) + 0.5) * e.w;
    let r = e.y / cos(th);
    return vec3<f32>(e.x + e.y * tan(th), r, r * r * e.w / e.y);
}
