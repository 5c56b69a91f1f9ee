//! Fresnel transmission through the flat water surface, shared by the path-traced water
//! (`truth::water_surface`) and the real-time pass's surface seen from below
//! (`render::passes::underwater`, tested against [`super::single::surface_from_below`]).

/// Unpolarised Fresnel reflectance for light in a medium of index `n_i` meeting a flat interface
/// to index `n_t` at cosine `cos_i` (≥ 0) from the normal; 1 under total internal reflection.
pub fn fresnel_reflectance(cos_i: f64, n_i: f64, n_t: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// T(θ) for light leaving water of index `n` into air at cosine `cos_w` to the vertical
/// (0 outside Snell's window). By reciprocity it equals the transmittance air → water of the
/// refracted direction.
pub fn transmittance_up(cos_w: f64, n: f64) -> f64 {
    1.0 - fresnel_reflectance(cos_w, n, 1.0)
}

/// T̄ = 2∫₀¹ T(μ) μ dμ: the fraction of a uniform sky's irradiance that crosses a flat surface of
/// relative index `n`, T(μ) the air → water transmittance at cosine μ. Midpoint rule on 20,000
/// cells in μ, where T is smooth (in μ² it has a square-root cusp at grazing): error ~1e-9.
pub fn mean_transmittance(n: f64) -> f64 {
    let k = 20_000;
    (0..k)
        .map(|i| {
            let mu = (i as f64 + 0.5) / k as f64;
            2.0 * mu * (1.0 - fresnel_reflectance(mu, 1.0, n))
        })
        .sum::<f64>()
        / k as f64
}
