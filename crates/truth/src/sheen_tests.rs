//! `KHR_materials_sheen` in the path tracer (`crate::bsdf::SheenLanes`): the BRDF against the
//! extension's formula written out in f64 (with `scene::sheen`'s f64 functions) over a
//! dielectric, a metal and a half metal; the sampling against its own pdf (histogram, ∫pdf,
//! ∫f·cos); furnaces of a black base under a white and a coloured sheen against
//! `scene::sheen::albedo_integral`, in the BRDF's sampler and through the integrator; the energy
//! of a white sheen over a white Lambertian base; a clear coat over a sheen; the textures; and
//! renders without the extension unchanged to the bit.

use super::tests::{assert_within, d65, estimate, radiance_any_hero, spectrum_at, with_env};
use super::*;
use crate::bsdf::{SheenLanes, SpecularLanes};
use crate::material::TexCoords;
use crate::spectral::XyzSensor;
use crate::testing::{scene_with, sphere};
use crate::upsample::GreyOnly;
use color::{Observer, Spectrum, WavelengthRange};
use glam::Vec2;
use scene::clearcoat::Clearcoat;
use scene::sheen::Sheen;
use scene::{Camera, Material, SpectralReflectance, Texture, TextureRef};
use std::f64::consts::PI;

fn sheen(color: Vec3, roughness: f32) -> Sheen {
    Sheen { color, color_texture: None, roughness, roughness_texture: None }
}

fn lanes(color: Vec4, max_color: f32, roughness: f32) -> SheenLanes {
    SheenLanes { color, max_color, roughness }
}

fn grey(c: f32, roughness: f32) -> SheenLanes {
    lanes(Vec4::splat(c), c, roughness)
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

fn wo_at(mu: f32) -> Vec3 {
    Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu)
}

/// A base that reflects nothing at all: black, dielectric, `KHR_materials_specular` weight 0
/// (no Fresnel reflection either), so only the sheen is left.
fn black_base(roughness: f32) -> Brdf {
    Brdf::new(Vec4::ZERO, 0.0, roughness).with_specular(Some(SpecularLanes {
        weight: 0.0,
        f0: Vec4::splat(0.04),
        f0_max: 0.04,
    }))
}

/// A white Lambertian base inside the glTF BRDF: white dielectric with specular weight 0
/// (f = base/π exactly; `Brdf::lambertian`, the comparison mode, takes no sheen).
fn white_lambertian() -> Brdf {
    Brdf::new(Vec4::ONE, 0.0, 1.0).with_specular(Some(SpecularLanes {
        weight: 0.0,
        f0: Vec4::splat(0.04),
        f0_max: 0.04,
    }))
}

/// glTF's metallic-roughness BRDF in f64, apart from the tracer's code (the normative mix:
/// (1 − Schlick(F0(η)))·base·(1 − m)/π + Schlick(lerp(F0(η), base, m))·D·V, GGX D and the
/// height-correlated Smith V).
fn gltf_base(base: [f64; 4], m: f64, alpha: f64, wo: [f64; 3], wi: [f64; 3]) -> [f64; 4] {
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let hl = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let h = h.map(|x| x / hl);
    let vh = (wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]).abs();
    let x = (1.0 - vh).max(0.0).powi(5);
    let a2 = alpha * alpha;
    let t = h[2] * h[2] * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * t * t);
    let (nv, nl) = (wo[2], wi[2]);
    let v = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    std::array::from_fn(|i| {
        let b = base[i];
        let f0 = 0.04 * (1.0 - m) + b * m;
        (1.0 - (0.04 + 0.96 * x)) * b * (1.0 - m) / PI + (f0 + (1.0 - f0) * x) * d * v
    })
}

/// The extension's f in f64: sheenColor(λ)·D·V + f_base·min(1 − c·E(n·v), 1 − c·E(n·l)),
/// D, V and E by `scene::sheen`'s f64 functions, f_base by [`gltf_base`].
fn reference(
    base: [f64; 4],
    m: f64,
    alpha: f64,
    sh: (Vec4, f32, f32),
    wo: [f64; 3],
    wi: [f64; 3],
) -> [f64; 4] {
    let (color, c, r) = (sh.0.to_array().map(f64::from), f64::from(sh.1), f64::from(sh.2));
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let n_h = h[2] / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let (n_v, n_l) = (wo[2], wi[2]);
    let lobe = scene::sheen::brdf(n_l, n_v, n_h, r);
    let s =
        (1.0 - c * scene::sheen::albedo(n_v, r)).min(1.0 - c * scene::sheen::albedo(n_l, r)).clamp(0.0, 1.0);
    let fb = gltf_base(base, m, alpha, wo, wi);
    std::array::from_fn(|i| color[i] * lobe + fb[i] * s)
}

/// Random direction pairs above the surface, cos θ from 0.02 to 1 (grazing, where the sheen
/// lives, included), fixed seed.
pub(super) fn random_pairs(n: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = Sampler::new(11, 5);
    let mut d = || {
        let [a, b] = rng.next2();
        let c = 0.02 + 0.98 * a;
        dir(c.acos(), 2.0 * std::f32::consts::PI * b)
    };
    (0..n).map(|_| (d(), d())).collect()
}

/// `Brdf::eval` with a sheen is the extension's formula in f64 (relative error < 2·10⁻⁴, floor
/// 10⁻³ of the value's scale) at 200 random direction pairs, over a dielectric, a metal and a
/// half metal, for grey and coloured sheens of roughness from below the clamp to 1; without a
/// sheen (and with a black one) it is the plain BRDF to the bit; below the horizon it is zero.
#[test]
fn the_brdf_is_the_extensions_formula() {
    let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
    let pairs = random_pairs(200);
    let mut worst = 0.0f64;
    for (m, r) in [(0.0f32, 0.5f32), (1.0, 0.3), (0.5, 0.7)] {
        let plain = Brdf::new(base, m, r);
        for sh in [
            (Vec4::new(0.9, 0.6, 0.3, 0.1), 0.95f32, 0.3f32),
            (Vec4::splat(1.0), 1.0, 0.1),
            (Vec4::splat(0.5), 0.5, 0.6),
            (Vec4::new(0.05, 0.2, 0.7, 0.9), 0.85, 1.0),
        ] {
            let b = plain.with_sheen(Some(lanes(sh.0, sh.1, sh.2)));
            assert!(b.sheen.is_some());
            for &(wo, wi) in &pairs {
                let got = b.eval(wo, wi);
                let want = reference(
                    base.to_array().map(f64::from),
                    m.into(),
                    b.alpha.into(),
                    sh,
                    wo.to_array().map(f64::from),
                    wi.to_array().map(f64::from),
                );
                let scale = want.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
                for i in 0..4 {
                    let e = (f64::from(got[i]) - want[i]).abs() / want[i].abs().max(1e-3 * scale);
                    worst = worst.max(e);
                    assert!(
                        e < 2e-4,
                        "m {m} sheen {sh:?}, wo {wo} wi {wi}, lane {i}: {} vs {}",
                        got[i],
                        want[i]
                    );
                }
                assert_eq!(plain.with_sheen(None).eval(wo, wi).to_array(), plain.eval(wo, wi).to_array());
                let black = plain.with_sheen(Some(lanes(Vec4::ZERO, 0.0, 0.5)));
                assert!(black.sheen.is_none());
                assert_eq!(black.eval(wo, wi).to_array(), plain.eval(wo, wi).to_array());
                assert_eq!(black.pdf(wo, wi), plain.pdf(wo, wi));
                let below = Vec3::new(wi.x, wi.y, -wi.z);
                assert_eq!(b.eval(wo, below), Vec4::ZERO);
                assert_eq!(b.pdf(wo, below), 0.0);
            }
        }
    }
    println!("sheen BRDF vs the f64 formula: worst relative error {worst:.2e}");
    // Lambert (the comparison mode) takes no sheen.
    assert!(Brdf::lambertian(base).with_sheen(Some(grey(1.0, 0.5))).sheen.is_none());
}

/// Without the extension the BRDF samples exactly as before: `sample` with and without a
/// `None` sheen (and a black one, dropped) draws the same directions, values and pdfs, bit for
/// bit, over random wo and random numbers.
#[test]
fn without_a_sheen_sampling_is_unchanged() {
    let mut rng = Sampler::new(2, 9);
    for (m, r) in [(0.0f32, 0.5f32), (1.0, 0.2), (0.4, 0.8)] {
        let plain = Brdf::new(Vec4::new(0.7, 0.4, 0.2, 0.9), m, r);
        let off = plain.with_sheen(Some(lanes(Vec4::ZERO, 0.0, 0.4)));
        for (wo, _) in random_pairs(500) {
            let (ul, u) = (rng.uniform(), rng.next2());
            let (a, b) = (plain.sample(wo, ul, u), off.sample(wo, ul, u));
            assert_eq!(a.is_some(), b.is_some());
            if let (Some(a), Some(b)) = (a, b) {
                assert_eq!((a.wi, a.f, a.pdf), (b.wi, b.f, b.pdf));
            }
            assert_eq!(plain.albedo_estimate(wo.z), off.albedo_estimate(wo.z));
        }
    }
}

/// The sheen colour per lane: a grey colour is the constant (the table is not asked), a
/// coloured one the table's reflectance at each lane, as the base colour's; c is the RGB's
/// largest channel.
#[test]
fn the_sheen_colour_is_upsampled_as_a_reflectance() {
    struct Refuses;
    impl crate::RgbToSpectrum for Refuses {
        fn coefficients(&self, rgb: [f32; 3]) -> [f32; 3] {
            panic!("asked to upsample {rgb:?}")
        }
    }
    let l = Vec4::new(420.0, 500.0, 580.0, 660.0);
    let g = SheenLanes::new(Vec3::splat(0.63), 0.4, &Refuses, l);
    assert_eq!(g, lanes(Vec4::splat(0.63), 0.63, 0.4));
    let table = color::upsample::table("srgb").expect("the sRGB table");
    let rgb = Vec3::new(0.9, 0.5, 0.2);
    let c = SheenLanes::new(rgb, 0.7, table.as_ref(), l);
    assert_eq!(c.color, crate::upsample::reflectance(table.as_ref(), rgb.to_array(), l));
    assert_eq!((c.max_color, c.roughness), (0.9, 0.7));
    assert!(c.color.x < c.color.w, "not orange: {}", c.color);
}

/// `n` samples of `b` at `wo`, each carrying exactly `eval`'s and `pdf`'s values, counted in the
/// `nc` × `np` (cos θ, φ) bins of [`binned_pdf`]: the counts, how many samples were returned and
/// the mean of f·cos/pdf over all `n`.
pub(super) fn sampled_bins(
    b: &Brdf,
    wo: Vec3,
    (nc, np): (usize, usize),
    n: usize,
    rng: &mut Sampler,
    name: &str,
) -> (Vec<u32>, usize, Vec4) {
    let mut counts = vec![0u32; nc * np];
    let (mut est, mut returned) = (Vec4::ZERO, 0usize);
    for _ in 0..n {
        let Some(x) = b.sample(wo, rng.uniform(), rng.next2()) else { continue };
        assert_eq!((x.f, x.pdf), (b.eval(wo, x.wi), b.pdf(wo, x.wi)), "{name}");
        returned += 1;
        est += x.f * x.wi.z / x.pdf;
        let ci = ((x.wi.z * nc as f32) as usize).min(nc - 1);
        let phi = x.wi.y.atan2(x.wi.x).rem_euclid(2.0 * std::f32::consts::PI);
        let pj = ((phi / (2.0 * std::f32::consts::PI) * np as f32) as usize).min(np - 1);
        counts[ci * np + pj] += 1;
    }
    (counts, returned, est / n as f32)
}

/// Pearson's χ² per bin of `counts` (of `n` samples) against the expected shares, over the bins
/// that expect at least 20 samples, the number of those bins and the worst one's deviation in
/// standard deviations; where the pdf says nearly nothing lands, nearly nothing may.
pub(super) fn chi2_per_bin(counts: &[u32], expected: &[f64], n: usize, what: &str) -> (f64, usize, f64) {
    let (mut chi2, mut dof, mut z_max) = (0.0f64, 0usize, 0.0f64);
    for (o, e) in counts.iter().zip(expected) {
        let (e, o) = (e * n as f64, f64::from(*o));
        if e >= 20.0 {
            chi2 += (o - e).powi(2) / e;
            dof += 1;
            z_max = z_max.max((o - e).abs() / e.sqrt());
        } else {
            assert!(o <= e + 5.0 * e.sqrt() + 10.0, "{what}: {o} samples where {e} expected");
        }
    }
    (chi2 / dof as f64, dof, z_max)
}

/// Quadrature of the pdf over the hemisphere of `wo` in (cos θ, φ) cells: the expected share
/// of samples in each of `nc` × `np` bins (sub-sampled `k` × `k` by the midpoint rule).
pub(super) fn binned_pdf(b: &Brdf, wo: Vec3, nc: usize, np: usize, k: usize) -> Vec<f64> {
    let mut bins = vec![0.0f64; nc * np];
    let (dc, dp) = (1.0 / (nc * k) as f64, 2.0 * PI / (np * k) as f64);
    for i in 0..nc * k {
        let c = (i as f64 + 0.5) * dc;
        let s = (1.0 - c * c).sqrt();
        for j in 0..np * k {
            let phi = (j as f64 + 0.5) * dp;
            let wi = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
            bins[(i / k) * np + j / k] += f64::from(b.pdf(wo, wi)) * dc * dp;
        }
    }
    bins
}

/// The BRDF with a sheen samples its own pdf: a histogram of 400 000 samples in 12 × 24
/// (cos θ, φ) bins against the pdf's quadrature over each bin (χ² per bin and the worst bin in
/// standard deviations), ∫pdf over the hemisphere against the fraction of samples returned (GGX
/// reflections below the horizon are lost), the mean of f·cos/pdf against ∫f·cos by
/// quadrature, and each sample's value and pdf exactly `eval`'s and `pdf`'s. Sheen over a
/// dielectric, a metal (no cosine lobe of its own), a half metal and a black base (the sheen
/// drawn at the 0.95 cap), at 0.3 and 1.2 rad.
#[test]
fn sampling_with_a_sheen_matches_its_pdf() {
    let base = Vec4::new(0.8, 0.6, 0.3, 0.9);
    let cases = [
        ("dielectric", Brdf::new(base, 0.0, 0.5), lanes(Vec4::new(0.9, 0.6, 0.3, 0.2), 0.95, 0.5)),
        ("metal", Brdf::new(base, 1.0, 0.3), grey(0.7, 0.3)),
        ("half metal", Brdf::new(base, 0.5, 0.6), grey(0.4, 1.0)),
        ("black base", black_base(0.5), grey(1.0, 0.3)),
    ];
    let (mut worst_chi2, mut worst_z, mut worst_ip, mut worst_est) = (0.0f64, 0.0f64, 0.0f64, 0.0f32);
    for (name, plain, sh) in cases {
        let b = plain.with_sheen(Some(sh));
        for theta in [0.3f32, 1.2] {
            let wo = dir(theta, 0.0);
            let (nc, np) = (12, 24);
            let expected = binned_pdf(&b, wo, nc, np, 24);
            let ip: f64 = expected.iter().sum();
            // ∫ f·cos by quadrature.
            let (nt, nphi) = (600, 300);
            let mut ialb = Vec4::ZERO;
            for i in 0..nt {
                let c = (i as f32 + 0.5) / nt as f32;
                for j in 0..nphi {
                    let wi = dir(c.acos(), 2.0 * std::f32::consts::PI * (j as f32 + 0.5) / nphi as f32);
                    ialb += b.eval(wo, wi) * c;
                }
            }
            ialb *= 2.0 * std::f32::consts::PI / (nt * nphi) as f32;
            let mut rng = Sampler::new(17, 3);
            let n = 400_000usize;
            let (counts, returned, est) = sampled_bins(&b, wo, (nc, np), n, &mut rng, name);
            let frac = returned as f64 / n as f64;
            let (chi2, dof, z_max) = chi2_per_bin(&counts, &expected, n, &format!("{name} θ {theta}"));
            let what = format!("{name} θ {theta} (sheen drawn with p = {:.3})", b.p_sheen(wo.z));
            println!(
                "{what}: χ²/bin {chi2:.3} over {dof} bins, worst bin {z_max:.2} σ; ∫pdf {ip:.4} vs returned {frac:.4}; ∫f·cos {ialb} vs sampled {est}"
            );
            assert!(chi2 < 1.35, "{what}: χ²/bin {chi2}");
            assert!(z_max < 5.0, "{what}: a bin {z_max} σ off");
            assert!(ip <= 1.0 + 1e-3 && (ip - frac).abs() < 5e-3, "{what}: ∫pdf = {ip}, sampled {frac}");
            assert!((est - ialb).abs().max_element() < 0.01, "{what}: {est} vs {ialb}");
            worst_chi2 = worst_chi2.max(chi2);
            worst_z = worst_z.max(z_max);
            worst_ip = worst_ip.max((ip - frac).abs());
            worst_est = worst_est.max((est - ialb).abs().max_element());
        }
    }
    println!(
        "sheen sampling: worst χ²/bin {worst_chi2:.3}, worst bin {worst_z:.2} σ, |∫pdf − returned| ≤ {worst_ip:.1e}, |sampled − ∫f·cos| ≤ {worst_est:.1e}"
    );
}

/// Directional albedo by the BRDF's own sampler: mean and standard error (per lane) of
/// f·cos/pdf over `n` samples from `wo`, a fixed seed.
fn sampled_albedo(b: &Brdf, wo: Vec3, n: usize, seed: u64) -> (Vec4, Vec4) {
    let mut rng = Sampler::new(seed, 1);
    estimate(n, |_| match b.sample(wo, rng.uniform(), rng.next2()) {
        Some(x) => x.f * x.wi.z / x.pdf,
        None => Vec4::ZERO,
    })
}

/// Furnace of the lobe: a base that reflects nothing under a white sheen (colour 1). Its
/// directional albedo by the BRDF's sampler (200 000 samples, fixed seed) is
/// `scene::sheen::albedo_integral(μ, r)` within 5 standard errors, for μ from 0.05 to 1 and
/// roughness 0.3, 0.6, 1.0; `albedo_estimate` is the table's E. A coloured sheen (0.9, 0.5, 0.2)
/// through the sRGB table reflects its upsampled colour times E at each lane (the same draws:
/// exactly the white estimate times the lane's colour, within f32 round-off).
#[test]
fn a_white_sheen_over_nothing_reflects_its_albedo() {
    let table = color::upsample::table("srgb").expect("the sRGB table");
    let l = Vec4::new(430.0, 510.0, 590.0, 670.0);
    let orange = SheenLanes::new(Vec3::new(0.9, 0.5, 0.2), 0.0, table.as_ref(), l);
    let (mut worst, mut n_cases) = (0.0f32, 0u64);
    for r in [0.3f32, 0.6, 1.0] {
        for mu in [0.05f32, 0.2, 0.5, 0.8, 1.0] {
            let wo = wo_at(mu);
            let b = black_base(0.5).with_sheen(Some(grey(1.0, r)));
            let want = scene::sheen::albedo_integral(f64::from(mu), f64::from(r)) as f32;
            // A stream of its own per case: independent trials.
            let seed = 100 + n_cases;
            let (m, se) = sampled_albedo(&b, wo, 200_000, seed);
            assert_within(m, se, Vec4::splat(want), &format!("white sheen r {r} μ {mu}"));
            let z = (m.x - want) / se.x;
            worst = worst.max(z.abs());
            n_cases += 1;
            let table_e = scene::sheen::albedo_f32(mu, r);
            assert!(
                (b.albedo_estimate(mu) - table_e).abs() <= 1e-6,
                "estimate {} vs E {table_e}",
                b.albedo_estimate(mu)
            );
            println!(
                "white sheen r {r}, μ {mu}: sampled {:.5} ± {:.5}, albedo_integral {want:.5} ({z:+.2} σ)",
                m.x, se.x
            );
            // The coloured sheen, each lane its colour times the white albedo.
            let c = black_base(0.5).with_sheen(Some(SheenLanes { roughness: r, ..orange }));
            let (mc, sec) = sampled_albedo(&c, wo, 200_000, seed);
            assert_within(mc, sec, orange.color * want, &format!("orange sheen r {r} μ {mu}"));
            assert!(
                (mc - orange.color * m.x).abs().max_element() <= 1e-4 * m.x,
                "{mc} vs {} × {}",
                orange.color,
                m.x
            );
        }
    }
    println!(
        "sheen furnace over nothing: {n_cases} (μ, roughness) cases, worst {worst:.2} standard errors; orange lanes {} ({l} nm)",
        orange.color
    );
}

/// Energy: a white sheen (colour 1) over a white Lambertian base. The sampled directional
/// albedo (100 000 samples) is E(μ) + 2∫₀¹ s(μ, u)·u du in f64 (E by `albedo_integral`, s by
/// `albedo_scaling` with the table's E, as the BRDF uses it; 4000 midpoint cells) within 5
/// standard errors, and at most 1 within noise: the table's E between nodes is off by up to
/// 6·10⁻³ (`scene::sheen`), which lets the total reach 1.0036; 4·10⁻³ is allowed.
#[test]
fn a_white_sheen_over_a_white_lambertian_keeps_energy() {
    let (mut top, mut top_at) = (0.0f32, (0.0, 0.0));
    for r in [0.0f32, 0.3, 0.6, 1.0] {
        for mu in [0.02f32, 0.1, 0.3, 0.6, 1.0] {
            let b = white_lambertian().with_sheen(Some(grey(1.0, r)));
            let (m, se) =
                sampled_albedo(&b, wo_at(mu), 100_000, u64::from((r * 10.0) as u8) * 10 + (mu * 50.0) as u64);
            let (mu64, r64) = (f64::from(mu), f64::from(r));
            let e_v = scene::sheen::albedo(mu64, r64);
            let n = 4000;
            let base: f64 = (0..n)
                .map(|k| {
                    let u = (k as f64 + 0.5) / n as f64;
                    scene::sheen::albedo_scaling(1.0, e_v, scene::sheen::albedo(u, r64)) * u
                })
                .sum::<f64>()
                * 2.0
                / n as f64;
            let want = (scene::sheen::albedo_integral(mu64, r64) + base) as f32;
            println!(
                "white sheen r {r} over white Lambert, μ {mu}: sampled {:.5} ± {:.5}, formula {want:.5}",
                m.x, se.x
            );
            assert_within(m, se, Vec4::splat(want), &format!("r {r} μ {mu}"));
            assert!(want <= 1.004, "r {r} μ {mu}: {want}");
            assert!(m.x <= 1.004 + 5.0 * se.x, "r {r} μ {mu}: {} ± {}", m.x, se.x);
            if m.x > top {
                (top, top_at) = (m.x, (mu, r));
            }
            // The estimate the coat weighs against: E + (1 − E)·1 for a white base.
            assert!((b.albedo_estimate(mu) - 1.0).abs() < 1e-6);
        }
    }
    println!("white sheen over white Lambert: largest sampled albedo {top:.5} at (μ, roughness) {top_at:?}");
}

/// The path tracer's radiance off a black sphere (nothing reflects but the sheen) under a
/// white sheen of roughness 0.5 in a uniform white surround: at each pixel centre (2000 paths,
/// a stream each) Le·E(cos θ) with E by `albedo_integral` at the pixel's facet, within 5
/// standard errors per lane; a sheen colour of 0.4 reflects 0.4 of it.
#[test]
fn a_sheened_black_sphere_in_a_furnace_reflects_the_sheens_albedo() {
    let roughness = 0.5f32;
    for c in [1.0f32, 0.4] {
        let mat = Material {
            spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.0))),
            specular: Some(scene::specular::Specular {
                factor: 0.0,
                texture: None,
                color: Vec3::ONE,
                color_texture: None,
            }),
            sheen: Some(sheen(Vec3::splat(c), roughness)),
            ..Default::default()
        };
        let mut scene = with_env(
            scene_with(vec![sphere(Vec3::ZERO, 1.0, 48, 0)], vec![mat], vec![]),
            scene::Environment::uniform(Vec3::ONE),
        );
        scene.camera = Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.7);
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only: false, max_depth: 100, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
        let le = world.units.rgb(Vec3::ONE, &GreyOnly, wl.0);
        let (w, h) = (8u32, 8u32);
        let cam = crate::camera::RayCamera::new(&scene.camera, w, h);
        let (mut n, mut worst) = (0, 0.0f32);
        for i in 0..w * h {
            let r = cam.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
            let Some(hit) = world.geometry.intersect(r.o, r.d, f32::INFINITY) else { continue };
            let cos = f64::from(world.surface(&hit).ng.dot(-r.d));
            let want = le * (c * scene::sheen::albedo_integral(cos, f64::from(roughness)) as f32);
            let mut rng = Sampler::new(42, u64::from(i));
            let (m, se) = estimate(2000, |_| radiance_any_hero(&integ, r.o, r.d, &wl, &mut rng));
            assert_within(m, se, want, &format!("sheen {c}, pixel {i}, cos {cos:.3}"));
            worst = worst.max(((m - want).abs() / se.max(Vec4::splat(1e-12))).max_element());
            n += 1;
        }
        println!(
            "sheened black sphere furnace, colour {c}: {n} pixels, worst lane {worst:.2} standard errors"
        );
        assert!(n > 30, "{n} pixels on the sphere");
    }
}

/// A clear coat over a sheen: the coat layers over the sheened base exactly as over any base.
/// A sphere (coloured rough dielectric, grey sheen 0.8 of roughness 0.4, smooth clearcoat 0.8)
/// in a uniform surround reflects Le·((1 − w)·A + w) at each pixel, w = 0.8·F(cos) and A the
/// sheened base's albedo by quadrature (3000 paths a pixel, 5 standard errors); and the coated
/// vertex over a sheened base samples its own value and pdf (∫pdf = returned, mean weight =
/// ∫f·|cos|, each sample exactly `Vertex::eval`'s), its coat probability balanced against the
/// albedo estimate with the sheen in it.
#[test]
fn a_coat_over_a_sheen_layers_as_over_any_base() {
    let base = Spectrum::piecewise(vec![380.0, 550.0, 730.0], vec![0.15, 0.6, 0.3]).unwrap();
    let (roughness, factor, sheen_c, sheen_r) = (0.6f32, 0.8f32, 0.8f32, 0.4f32);
    let mat = Material {
        roughness,
        spectral: Some(SpectralReflectance::Uniform(base.clone())),
        clearcoat: Some(Clearcoat {
            factor,
            texture: None,
            roughness: 0.0,
            roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
        }),
        sheen: Some(sheen(Vec3::splat(sheen_c), sheen_r)),
        ..Default::default()
    };
    let mut scene = with_env(
        scene_with(vec![sphere(Vec3::ZERO, 1.0, 48, 0)], vec![mat], vec![]),
        scene::Environment::uniform(Vec3::ONE),
    );
    scene.camera = Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.8);
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 1000, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
    let le = spectrum_at(&d65(), &wl);
    let brdf = Brdf::new(spectrum_at(&base, &wl), 0.0, roughness).with_sheen(Some(grey(sheen_c, sheen_r)));
    let plain = Brdf::new(spectrum_at(&base, &wl), 0.0, roughness);
    let (w, h) = (8u32, 8u32);
    let cam = crate::camera::RayCamera::new(&scene.camera, w, h);
    let (mut pixels, mut worst, mut change) = (0, 0.0f32, 0.0f32);
    for i in 0..w * h {
        let r = cam.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
        let Some(hit) = world.geometry.intersect(r.o, r.d, f32::INFINITY) else { continue };
        let cos = world.surface(&hit).ng.dot(-r.d);
        let wt = factor * (0.04 + 0.96 * (1.0 - cos.abs()).powi(5));
        let a = crate::testing::directional_albedo(&brdf, cos);
        let want = le * (a * (1.0 - wt) + Vec4::splat(wt));
        let (m, se) = estimate(3000, |rng| radiance_any_hero(&integ, r.o, r.d, &wl, rng));
        assert_within(m, se, want, &format!("coat over sheen, pixel {i}, cos {cos:.3}"));
        worst = worst.max(((m - want).abs() / se.max(Vec4::splat(1e-12))).max_element());
        let without = le * (crate::testing::directional_albedo(&plain, cos) * (1.0 - wt) + Vec4::splat(wt));
        change = change.max(((want - without) / without).abs().max_element());
        pixels += 1;
    }
    println!(
        "coat over a sheen, furnace: {pixels} pixels, worst lane {worst:.2} standard errors; the sheen changes a pixel by up to {:.0} %",
        change * 100.0
    );
    assert!(pixels > 30 && change > 0.05, "{pixels} pixels, change {change}");

    // The coated vertex over a sheened base samples what it evaluates.
    let frame = Frame::from_normal(Vec3::Z);
    for (name, b) in [
        ("dielectric", Brdf::new(Vec4::new(0.8, 0.3, 0.1, 0.5), 0.0, 0.5)),
        ("metal", Brdf::new(Vec4::new(0.9, 0.6, 0.3, 0.8), 1.0, 0.3)),
    ] {
        let b = b.with_sheen(Some(lanes(Vec4::new(0.2, 0.5, 0.9, 0.7), 0.9, 0.5)));
        for theta in [0.3f32, 1.1] {
            let wo = dir(theta, 0.4);
            let c = Coat::new(0.9, 0.4, Vec3::new(0.15, 0.0, 1.0).normalize(), wo)
                .balanced(b.albedo_estimate(wo.z));
            let vtx = Vertex::Surface { brdf: b, frame, ng: Vec3::Z, glass: None, coat: Some(c) };
            let (ip, if_) = super::coat_tests::sphere_integrals(&vtx, wo);
            let mut rng = Sampler::new(7, 1);
            let n = 200_000;
            let (mut est, mut returned) = (Vec4::ZERO, 0);
            for _ in 0..n {
                let Some(x) = vtx.sample_coated(wo, &mut rng) else { continue };
                returned += 1;
                est += x.weight;
                let (f, p) = vtx.eval(wo, x.wi);
                assert_eq!((x.pdf, x.weight), (p, f / p), "{name}: a sample off its own value and pdf");
            }
            est /= n as f32;
            let frac = returned as f64 / n as f64;
            let what =
                format!("coat over a sheened {name}, θ {theta} (coat p = {:.3}, w = {:.3})", c.p, c.weight);
            println!("{what}: ∫pdf {ip:.4} vs returned {frac:.4}; ∫f·cos {if_} vs sampled {est}");
            assert!(ip <= 1.0 + 2e-3 && (ip - frac).abs() < 0.01, "{what}: ∫pdf = {ip}, sampled {frac}");
            assert!((est - if_).abs().max_element() < 0.01, "{what}: {est} vs {if_}");
        }
    }
}

/// The textures at a hit: the colour from the colour texture's RGB (sRGB-decoded), the
/// roughness from the roughness texture's A (linear), times the factors — one image serving
/// both, as glTF files often share it; a zero factor, a texel black in RGB, an unlit material
/// and no extension give none.
#[test]
fn the_textures_scale_colour_and_roughness() {
    let tex = |rgba: [u8; 4], srgb: bool| Texture {
        sampler: Default::default(),
        name: "t".into(),
        width: 1,
        height: 1,
        rgba8: rgba.to_vec(),
        srgb,
    };
    let r = |index| Some(TextureRef { index, tex_coord: 0, transform: None });
    let m = Material {
        sheen: Some(Sheen {
            color: Vec3::new(0.5, 1.0, 0.8),
            color_texture: r(0),
            roughness: 0.9,
            roughness_texture: r(0),
        }),
        ..Default::default()
    };
    let tc = TexCoords::one(Vec2::splat(0.5));
    let textures = [tex([255, 128, 64, 100], true), tex([0, 0, 0, 255], true)];
    let (color, rough) = material::sheen(&m, &textures, &tc).unwrap();
    let dec = |v: u8| crate::texture::srgb_decode(f32::from(v) / 255.0);
    let want = Vec3::new(0.5 * dec(255), dec(128), 0.8 * dec(64));
    assert!((color - want).abs().max_element() < 1e-6, "{color} vs {want}");
    assert!((rough - 0.9 * 100.0 / 255.0).abs() < 1e-6, "{rough}");
    println!("sheen textures: colour {color} (want {want}), roughness {rough:.5}");
    // Separate textures: the roughness reads its own A, the colour its own RGB.
    let split = Material {
        sheen: Some(Sheen { color_texture: r(1), roughness_texture: r(0), ..m.sheen.clone().unwrap() }),
        ..Default::default()
    };
    assert_eq!(material::sheen(&split, &textures, &tc), None, "a black texel turns the sheen off there");
    let split = Material {
        sheen: Some(Sheen { color_texture: None, roughness_texture: r(0), ..m.sheen.clone().unwrap() }),
        ..Default::default()
    };
    let (c2, r2) = material::sheen(&split, &textures, &tc).unwrap();
    assert_eq!((c2, r2), (Vec3::new(0.5, 1.0, 0.8), 0.9 * (100.0 / 255.0)));
    let off = Material { sheen: Some(Sheen { color: Vec3::ZERO, ..m.sheen.clone().unwrap() }), ..m.clone() };
    assert_eq!(material::sheen(&off, &textures, &tc), None);
    assert_eq!(material::sheen(&Material { unlit: true, ..m.clone() }, &textures, &tc), None);
    assert_eq!(material::sheen(&Material::default(), &textures, &tc), None);
}

/// The extension tests' sphere on a floor (`testing::two_materials_on_floor`), `sh` on both.
fn two_material_scene(sh: Option<Sheen>) -> scene::Scene {
    crate::testing::two_materials_on_floor(|m| m.sheen = sh.clone())
}

/// Renders: a sheen that is off (colour factor 0, whatever its texture) renders to the same
/// bits as none; `--lambert` ignores the extension; otherwise a sheen shows.
#[test]
fn without_the_extension_renders_are_unchanged() {
    let plain = crate::testing::small_render(&two_material_scene(None), false);
    let off = Sheen {
        color: Vec3::ZERO,
        color_texture: Some(TextureRef { index: 0, tex_coord: 0, transform: None }),
        roughness: 0.5,
        roughness_texture: None,
    };
    assert!(crate::testing::small_render(&two_material_scene(Some(off)), false).xyz == plain.xyz);
    let on = two_material_scene(Some(sheen(Vec3::new(0.9, 0.7, 0.8), 0.5)));
    assert!(
        crate::testing::small_render(&on, true).xyz
            == crate::testing::small_render(&two_material_scene(None), true).xyz
    );
    let lit = crate::testing::small_render(&on, false);
    let (a, b) = (plain.mean(), lit.mean());
    println!("image mean with a sheen {b:?}, without {a:?}");
    assert!(lit.xyz != plain.xyz);
}
