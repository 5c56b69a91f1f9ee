// Thin-film reflectance (KHR_materials_iridescence): `scene::film::reflectance` for the bases
// glTF gives — a real index ≥ 1 (1.5 under a dielectric, a metal's F0 as an index) under a film
// of index ≥ 1, seen from air. Then no interface reflects totally and every cosine is real;
// only the film's round-trip phase δ is complex, and Airy's |r₁₂ + r₂₃e^{iδ}|² / |1 +
// r₁₂r₂₃e^{iδ}|² is (a² + b² + 2ab·cos δ) / (1 + a²b² + 2ab·cos δ) with real amplitudes a, b,
// per polarisation. Four wavelengths at once (a node group); the first interface and the
// film's cosine do not depend on λ. Tested against the Rust (src/film_tests.rs).
fn film_reflectance4(lambda_nm: vec4<f32>, cos_i: f32, thickness_nm: f32, film_ior: f32, base_ior: vec4<f32>) -> vec4<f32> {
    let f = film_amplitudes(lambda_nm, cos_i, thickness_nm, film_ior, base_ior);
    let cd = cos(f.delta);
    return clamp(0.5 * (film_airy(f.a_s, f.b_s, cd) + film_airy(f.a_p, f.b_p, cd)), vec4<f32>(0.0), vec4<f32>(1.0));
}

// The two interfaces' real amplitudes per polarisation (s, p) and the film's round-trip phase.
struct FilmAmplitudes {
    a_s: f32,
    a_p: f32,
    b_s: vec4<f32>,
    b_p: vec4<f32>,
    delta: vec4<f32>,
};

fn film_amplitudes(lambda_nm: vec4<f32>, cos_i: f32, thickness_nm: f32, film_ior: f32, base_ior: vec4<f32>) -> FilmAmplitudes {
    // Not quite grazing: at cos 0 under a film of index 1 both amplitudes would be 0/0.
    let c1 = clamp(cos_i, 1e-6, 1.0);
    let s2 = 1.0 - c1 * c1;
    let n2 = film_ior;
    let n3 = base_ior;
    let c2 = sqrt(max(1.0 - s2 / (n2 * n2), 0.0));
    let c3 = sqrt(max(vec4<f32>(1.0) - s2 / (n3 * n3), vec4<f32>(0.0)));
    return FilmAmplitudes(
        (c1 - n2 * c2) / (c1 + n2 * c2),
        (n2 * c1 - c2) / (n2 * c1 + c2),
        (n2 * c2 - n3 * c3) / (n2 * c2 + n3 * c3),
        (n3 * c2 - n2 * c3) / (n3 * c2 + n2 * c3),
        (4.0 * PI * thickness_nm * n2 * c2) / lambda_nm,
    );
}

// The film's reflectance averaged over each node's band of `spacing_nm`, where the nodes cannot
// resolve its fringes: what the spectral quadrature's nodes must carry. A film's fringes come
// every Δλ ≈ λ²/(2·n·d·cos θ): from about a micrometre they are narrower than the nodes, whose
// samples then alias into false colour (a 3 µm film of index 2 drawn magenta at N = 16, grey in
// the truth). Across the band the phase δ = K/λ runs over δ₀ ± w, w = δ₀·spacing/(2λ)
// (linearised about the node). Per polarisation Airy's R(δ) = 1 − C·P_u(δ), C = (1 − a²)(1 −
// b²)/(1 − u²), u = ab, with P_u(δ) = (1 − u²)/(1 + u² + 2u·cos δ) = 1 + 2 Σ (−u)ᵏ cos kδ; the
// band's mean multiplies harmonic k by sinc kw, taken here as sincᵏ w, which keeps the form:
// P_{u·sinc w}. Exact for the first harmonic and at both ends — the film itself at w = 0, the
// incoherent sum of its two interfaces (what the truth's dense integral sees) as w grows — and
// between within 2e-3 of the exact band mean where the interfaces reflect weakly (|ab| ≤ 0.05:
// dielectric films on glass), within 0.05 where they reflect strongly (a metal base at grazing
// light), where the exact mean (two arctangents per polarisation) cost a filmed scene's
// spectral frame 1.5× here; one sine more than the film at the node (+6 %). A box over the whole band would also flatten fringes the nodes resolve (a
// 300 nm film at N = 8–16, 0.01–0.02 ΔE further from the truth): the window grows from none,
// while the band holds under a quarter of a fringe period (r = w/π), to the whole band from half
// a period (Nyquist).
fn film_band_reflectance4(lambda_nm: vec4<f32>, cos_i: f32, thickness_nm: f32, film_ior: f32, base_ior: vec4<f32>, spacing_nm: f32) -> vec4<f32> {
    let f = film_amplitudes(lambda_nm, cos_i, thickness_nm, film_ior, base_ior);
    let delta = f.delta;
    let w_band = delta * (0.5 * spacing_nm) / lambda_nm;
    let w = w_band * smoothstep(vec4<f32>(0.25), vec4<f32>(0.5), w_band / PI);
    let sinc = select(sin(w) / w, vec4<f32>(1.0), w < vec4<f32>(1e-4));
    let cd = cos(delta);
    let r = 0.5 * (film_damped_airy(f.a_s, f.b_s, cd, sinc) + film_damped_airy(f.a_p, f.b_p, cd, sinc));
    return clamp(r, vec4<f32>(0.0), vec4<f32>(1.0));
}

// One polarisation of `film_band_reflectance4`: 1 − C·P_{u·sinc}(δ); `film_airy` at sinc 1.
fn film_damped_airy(a: f32, b: vec4<f32>, cd: vec4<f32>, sinc: vec4<f32>) -> vec4<f32> {
    let v = a * b * sinc;
    let den = 1.0 + v * v + 2.0 * v * cd;
    let num = (1.0 - a * a) * (1.0 - b * b) * (1.0 - v * v) / max(1.0 - a * a * b * b, vec4<f32>(1e-12));
    // den ≥ (1 − |v|)², zero only when both interfaces reflect totally: total then.
    return select(1.0 - num / den, vec4<f32>(1.0), den <= vec4<f32>(1e-20));
}

fn film_airy(a: f32, b: vec4<f32>, cd: vec4<f32>) -> vec4<f32> {
    let ab2 = 2.0 * a * b * cd;
    let num = a * a + b * b + ab2;
    let den = 1.0 + a * a * b * b + ab2;
    // den ≥ (1 − |ab|)², zero only when both interfaces reflect totally: total then.
    return select(num / den, vec4<f32>(1.0), den <= vec4<f32>(1e-20));
}

// The index of a base whose normal-incidence reflectance is f0 (`scene::film::ior_from_f0`).
fn film_ior_from_f0(f0: vec4<f32>) -> vec4<f32> {
    let s = sqrt(clamp(f0, vec4<f32>(0.0), vec4<f32>(0.9999)));
    return (1.0 + s) / (1.0 - s);
}

// The RGB mode's film: the extension's own RGB evaluation (Belcour & Barla 2017, "A Practical
// Extension to Microfacet Theory for the Modeling of Varying Iridescence"): Schlick interfaces,
// the Airy series to its second order, each order's spectral integral in closed form from
// Gaussian fits of the colour-matching functions' Fourier transform, then XYZ → linear sRGB.
// What an RGB renderer can do; the spectral modes evaluate the exact film per node instead.
// `base_f0`: the base's normal-incidence reflectance per channel (glTF's 0.04 for the dielectric).

// XYZ → linear sRGB, the colour crate's (from the sRGB primaries and D65); src/film_tests.rs
// checks that they agree.
const FILM_XYZ_TO_SRGB: mat3x3<f32> = mat3x3<f32>(
    vec3<f32>(3.2409699, -0.9692436, 0.0556301),
    vec3<f32>(-1.5373832, 1.8759675, -0.2039770),
    vec3<f32>(-0.4986108, 0.0415551, 1.0569715),
);

// The colour-matching functions' Fourier transform at optical path difference `opd_nm` with
// phase shifts `shift` per channel (Belcour & Barla's supplemental fit: a Gaussian per X, Y, Z,
// a second one for X's short-wave lobe), normalised so that zero path difference is Y = 1.
fn film_sensitivity(opd_nm: f32, shift: vec3<f32>) -> vec3<f32> {
    let phase = 2.0 * PI * opd_nm * 1e-9;
    let amp = vec3<f32>(5.4856e-13, 4.4201e-13, 5.2481e-13);
    let freq = vec3<f32>(1.6810e6, 1.7953e6, 2.2084e6);
    let spread = vec3<f32>(4.3278e9, 9.3046e9, 6.6121e9);
    var xyz = amp * sqrt(2.0 * PI * spread) * cos(freq * phase + shift) * exp(-phase * phase * spread);
    xyz.x += 9.7470e-14 * sqrt(2.0 * PI * 4.5282e9) * cos(2.2399e6 * phase + shift.x) * exp(-4.5282e9 * phase * phase);
    return FILM_XYZ_TO_SRGB * (xyz / 1.0685e-7);
}

fn film_schlick(f0: vec3<f32>, c: f32) -> vec3<f32> {
    return f0 + (1.0 - f0) * pow(1.0 - clamp(c, 0.0, 1.0), 5.0);
}

fn film_rgb(cos_i: f32, thickness_nm: f32, film_ior: f32, base_f0: vec3<f32>) -> vec3<f32> {
    // A film that thins to nothing takes the outside's index, so that it vanishes.
    let n2 = mix(1.0, film_ior, smoothstep(0.0, 0.03, thickness_nm));
    let c1 = clamp(cos_i, 0.0, 1.0);
    let s2 = (1.0 - c1 * c1) / (n2 * n2);
    if (s2 >= 1.0) {
        return vec3<f32>(1.0);
    }
    let c2 = sqrt(1.0 - s2);
    // Air → film: reflected and transmitted (both ways) energy; the phase on reflection inside
    // the film is π (it is denser than air).
    let r0 = ((n2 - 1.0) / (n2 + 1.0)) * ((n2 - 1.0) / (n2 + 1.0));
    let r12 = film_schlick(vec3<f32>(r0), c1).x;
    let t121 = 1.0 - r12;
    let phi21 = select(PI, 0.0, n2 < 1.0);
    // Film → base, with the base's index from its F0; phase π where the base is the thinner.
    let s = sqrt(clamp(base_f0, vec3<f32>(0.0), vec3<f32>(0.9999)));
    let n3 = (1.0 + s) / (1.0 - s);
    let f23 = ((n3 - n2) / (n3 + n2)) * ((n3 - n2) / (n3 + n2));
    let r23 = film_schlick(f23, c2);
    let phi23 = select(vec3<f32>(0.0), vec3<f32>(PI), n3 < vec3<f32>(n2));
    let opd = 2.0 * n2 * thickness_nm * c2;
    let phi = vec3<f32>(phi21) + phi23;
    let r123 = clamp(r12 * r23, vec3<f32>(1e-5), vec3<f32>(0.9999));
    let amp = sqrt(r123);
    let rs = t121 * t121 * r23 / (1.0 - r123);
    var i = vec3<f32>(r12) + rs;
    var cm = rs - t121;
    for (var m = 1; m <= 2; m++) {
        cm *= amp;
        i += cm * 2.0 * film_sensitivity(f32(m) * opd, f32(m) * phi);
    }
    return max(i, vec3<f32>(0.0));
}
