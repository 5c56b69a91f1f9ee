// Thin-film reflectance (KHR_materials_iridescence): `scene::film::reflectance` for the bases
// glTF gives — a real index ≥ 1 (1.5 under a dielectric, a metal's F0 as an index) under a film
// of index ≥ 1, seen from air. Then no interface reflects totally and every cosine is real;
// only the film's round-trip phase δ is complex, and Airy's |r₁₂ + r₂₃e^{iδ}|² / |1 +
// r₁₂r₂₃e^{iδ}|² is (a² + b² + 2ab·cos δ) / (1 + a²b² + 2ab·cos δ) with real amplitudes a, b,
// for both polarisations at once (x: s, y: p). Tested against the Rust (src/film_tests.rs).
fn film_reflectance(lambda_nm: f32, cos_i: f32, thickness_nm: f32, film_ior: f32, base_ior: f32) -> f32 {
    let c1 = clamp(cos_i, 0.0, 1.0);
    let s2 = 1.0 - c1 * c1;
    let n2 = film_ior;
    let n3 = base_ior;
    let c2 = sqrt(max(1.0 - s2 / (n2 * n2), 0.0));
    let c3 = sqrt(max(1.0 - s2 / (n3 * n3), 0.0));
    let a = vec2<f32>((c1 - n2 * c2) / (c1 + n2 * c2), (n2 * c1 - c2) / (n2 * c1 + c2));
    let b = vec2<f32>((n2 * c2 - n3 * c3) / (n2 * c2 + n3 * c3), (n3 * c2 - n2 * c3) / (n3 * c2 + n2 * c3));
    let cd = vec2<f32>(cos(4.0 * PI * thickness_nm * n2 * c2 / lambda_nm));
    let ab2 = 2.0 * a * b * cd;
    let num = a * a + b * b + ab2;
    let den = 1.0 + a * a * b * b + ab2;
    // den ≥ (1 − |ab|)², zero only at grazing incidence under a film of index 1: total there.
    let r = select(num / den, vec2<f32>(1.0), den <= vec2<f32>(1e-20));
    return clamp(0.5 * (r.x + r.y), 0.0, 1.0);
}

// The index of a base whose normal-incidence reflectance is f0 (`scene::film::ior_from_f0`).
fn film_ior_from_f0(f0: f32) -> f32 {
    let s = sqrt(clamp(f0, 0.0, 0.9999));
    return (1.0 + s) / (1.0 - s);
}
