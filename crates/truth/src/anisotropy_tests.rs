//! `KHR_materials_anisotropy` in the path tracer (`Brdf::with_anisotropy`,
//! `material::anisotropy_frame`): the BRDF against the extension's lobe in f64
//! (`scene::anisotropy`) times the Fresnel term over a metal, a dielectric and a half metal; the
//! sampling against its own pdf (histogram, ∫pdf, each sample's value and pdf); reciprocity; the
//! isotropic limit; a furnace of a white metal against a quadrature of `scene::anisotropy::lobe`;
//! and renders: unchanged without the extension, changed with it, and oriented as the extension
//! says (the highlight along the direction, the rotation counter-clockwise from the tangent
//! towards the bitangent).

use super::sheen_tests::{binned_pdf, chi2_per_bin, random_pairs, sampled_bins};
use super::tests::{assert_within, estimate};
use super::*;
use crate::testing::{quad, scene_with};
use scene::anisotropy::{self as an, Anisotropy};
use scene::{Camera, Material};
use std::f64::consts::PI;

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

fn schlick64(f0: f64, c: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - c).max(0.0).powi(5)
}

/// The (roughness, strength) pairs the BRDF tests run over: from a near mirror across to fully
/// stretched.
const CASES: [(f32, f32); 6] = [(0.1, 0.8), (0.2, 0.5), (0.3, 1.0), (0.45, 0.3), (0.6, 0.9), (0.9, 1.0)];

/// The glTF BRDF with the extension's lobe, in f64 apart from the tracer's code:
/// (1 − m)·(1 − F_d)·base/π + F·D·V, F_d = Schlick(0.04), F = Schlick(lerp(0.04, base, m)) at v·h,
/// D·V = `scene::anisotropy::lobe` with (α_t, α_b) = `scene::anisotropy::alphas(α, s)`, α the
/// BRDF's (floored) isotropic α, in the frame whose x axis is the direction.
fn reference(base: Vec4, m: f32, alpha: f32, s: f32, wo: Vec3, wi: Vec3) -> [f64; 4] {
    let (v, l) = (wo.as_dvec3(), wi.as_dvec3());
    let (at, ab) = an::alphas(f64::from(alpha), f64::from(s));
    let lobe = an::lobe(at, ab, l, v);
    let v_h = v.dot((l + v).normalize()).abs();
    let m = f64::from(m);
    std::array::from_fn(|i| {
        let b = f64::from(base[i]);
        let f = schlick64(0.04 * (1.0 - m) + b * m, v_h);
        (1.0 - m) * (1.0 - schlick64(0.04, v_h)) * b / PI + f * lobe
    })
}

fn brdf(base: Vec4, m: f32, r: f32, s: f32) -> Brdf {
    Brdf::new(base, m, r).with_anisotropy(Some(s))
}

/// `Brdf::eval` with an anisotropy is the extension's formula in f64 (relative error < 10⁻⁴)
/// at 300 random direction pairs, over a metal (F0 = base colour), a dielectric and a half
/// metal, for the [`CASES`]; below the horizon it is zero.
#[test]
fn the_brdf_is_the_extensions_formula() {
    let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
    let pairs = random_pairs(300);
    let mut worst = 0.0f64;
    for m in [1.0, 0.0, 0.5] {
        for (r, s) in CASES {
            let b = brdf(base, m, r, s);
            let (ax, ay) = b.alphas.expect("anisotropic");
            assert!(ax > ay && ay == b.alpha, "r {r} s {s}: α {:?}", b.alphas);
            for &(wo, wi) in &pairs {
                let (got, want) = (b.eval(wo, wi), reference(base, m, b.alpha, s, wo, wi));
                for i in 0..4 {
                    let e = (f64::from(got[i]) - want[i]).abs() / want[i];
                    worst = worst.max(e);
                    assert!(e < 1e-4, "m {m} r {r} s {s} {wo} {wi} lane {i}: {} vs {}", got[i], want[i]);
                }
            }
            let below = Vec3::new(0.3, 0.2, -0.5).normalize();
            assert_eq!(b.eval(dir(0.4, 1.0), below), Vec4::ZERO);
            assert_eq!(b.eval(below, dir(0.4, 1.0)), Vec4::ZERO);
        }
    }
    println!("anisotropic BRDF vs the extension's f64 lobe: worst relative error {worst:.2e}");
}

/// Reciprocity: f(wo, wi) = f(wi, wo) to f32 round-off (the two v·h differ in the last bits).
#[test]
fn the_brdf_is_reciprocal() {
    let base = Vec4::new(0.9, 0.5, 0.2, 0.7);
    let mut worst = 0.0f32;
    for m in [0.0, 0.4, 1.0] {
        for (r, s) in CASES {
            let b = brdf(base, m, r, s);
            for &(a, c) in &random_pairs(100) {
                let (f, g) = (b.eval(a, c), b.eval(c, a));
                let e = ((f - g).abs() / f.max(Vec4::splat(1e-20))).max_element();
                worst = worst.max(e);
                assert!(e < 1e-5, "m {m} r {r} s {s}: {f} vs {g}");
            }
        }
    }
    println!("reciprocity: worst relative difference {worst:.2e}");
}

/// The isotropic limit: strength 0 is no anisotropy at all (`alphas` `None`: the isotropic code
/// path, so eval, pdf and samples are the plain BRDF's to the bit), and the anisotropic
/// formulas themselves at α_x = α_y are the isotropic ones to f32 round-off (relative 10⁻⁴),
/// sampling the same directions bit for bit.
#[test]
fn strength_zero_is_the_isotropic_brdf() {
    let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
    let mut worst = 0.0f32;
    for m in [0.0, 0.5, 1.0] {
        for r in [0.05, 0.3, 0.7, 1.0] {
            let plain = Brdf::new(base, m, r);
            let off = plain.with_anisotropy(Some(0.0));
            assert!(off.alphas.is_none() && plain.with_anisotropy(None).alphas.is_none());
            let forced = Brdf { alphas: Some((plain.alpha, plain.alpha)), ..plain };
            let mut rng = Sampler::new(5, 1);
            for &(wo, wi) in &random_pairs(200) {
                assert_eq!(off.eval(wo, wi), plain.eval(wo, wi));
                assert_eq!(off.pdf(wo, wi), plain.pdf(wo, wi));
                let (u0, u) = (rng.uniform(), rng.next2());
                let (a, b) = (plain.sample(wo, u0, u), off.sample(wo, u0, u));
                assert_eq!(a.as_ref().map(|x| (x.wi, x.f, x.pdf)), b.as_ref().map(|x| (x.wi, x.f, x.pdf)));
                let c = forced.sample(wo, u0, u);
                assert_eq!(a.as_ref().map(|x| x.wi), c.as_ref().map(|x| x.wi), "r {r}");
                let (f, g) = (plain.eval(wo, wi), forced.eval(wo, wi));
                let (p, q) = (plain.pdf(wo, wi), forced.pdf(wo, wi));
                let e = ((f - g).abs() / f.max(Vec4::splat(1e-20))).max_element().max((p - q).abs() / p);
                worst = worst.max(e);
                // Near a mirror (α = 0.0025) the isotropic D's 1 + n·h²(α² − 1) cancels: 2·10⁻⁵.
                assert!(e < 1e-4, "m {m} r {r}: {f} vs {g}, pdf {p} vs {q}");
            }
        }
    }
    // A lambertian comparison BRDF takes none.
    assert!(Brdf::lambertian(base).with_anisotropy(Some(1.0)).alphas.is_none());
    println!(
        "anisotropic formulas at α_x = α_y vs the isotropic ones: worst relative difference {worst:.2e}"
    );
}

/// The anisotropic BRDF samples its own pdf: a histogram of 400 000 samples in 12 × 24
/// (cos θ, φ) bins against the pdf's quadrature over each bin (χ² per bin, worst bin in standard
/// deviations); ∫pdf over the hemisphere ≤ 1 and equal to the fraction of samples returned (GGX
/// reflections below the horizon are lost); each sample's value and pdf exactly `eval`'s and
/// `pdf`'s. A metal (pure visible-normal sampling), a dielectric and a half metal with a sheen,
/// views along neither axis.
#[test]
fn sampling_matches_its_pdf() {
    let base = Vec4::new(0.8, 0.6, 0.3, 0.9);
    let cases = [
        ("metal", brdf(base, 1.0, 0.3, 0.8)),
        ("metal, near mirror across", brdf(base, 1.0, 0.15, 1.0)),
        ("dielectric", brdf(base, 0.0, 0.5, 1.0)),
        (
            "half metal with a sheen",
            Brdf::new(base, 0.5, 0.25)
                .with_sheen(Some(crate::bsdf::SheenLanes {
                    color: Vec4::splat(0.5),
                    max_color: 0.5,
                    roughness: 0.5,
                }))
                .with_anisotropy(Some(0.6)),
        ),
    ];
    let (mut worst_chi2, mut worst_z, mut worst_ip) = (0.0f64, 0.0f64, 0.0f64);
    for (name, b) in cases {
        assert!(b.alphas.is_some());
        for (theta, phi) in [(0.4f32, 0.6f32), (1.2, 2.0)] {
            let wo = dir(theta, phi);
            let (nc, np) = (12, 24);
            let expected = binned_pdf(&b, wo, nc, np, 24);
            let ip: f64 = expected.iter().sum();
            let mut rng = Sampler::new(23, 7);
            let n = 400_000usize;
            let (counts, returned, _) = sampled_bins(&b, wo, (nc, np), n, &mut rng, name);
            let frac = returned as f64 / n as f64;
            let (chi2, dof, z_max) = chi2_per_bin(&counts, &expected, n, &format!("{name} θ {theta}"));
            let what = format!("{name} θ {theta} φ {phi}");
            println!(
                "{what}: χ²/bin {chi2:.3} over {dof} bins, worst bin {z_max:.2} σ; ∫pdf {ip:.4} vs returned {frac:.4}"
            );
            assert!(chi2 < 1.35, "{what}: χ²/bin {chi2}");
            assert!(z_max < 5.0, "{what}: a bin {z_max} σ off");
            assert!(ip <= 1.0 + 1e-3 && (ip - frac).abs() < 5e-3, "{what}: ∫pdf = {ip}, sampled {frac}");
            worst_chi2 = worst_chi2.max(chi2);
            worst_z = worst_z.max(z_max);
            worst_ip = worst_ip.max((ip - frac).abs());
        }
    }
    println!(
        "anisotropic sampling: worst χ²/bin {worst_chi2:.3}, worst bin {worst_z:.2} σ, |∫pdf − returned| ≤ {worst_ip:.1e}"
    );
}

/// Furnace: a white anisotropic metal's directional albedo by the tracer's sampler (200 000
/// samples, f·cos/pdf, lost samples 0) is the f64 quadrature of `scene::anisotropy::lobe`·cos
/// within 5 standard errors (+ 10⁻³ for the quadrature), along, across and between the axes,
/// near normal and at grazing views.
#[test]
fn a_white_anisotropic_metal_reflects_the_lobes_albedo() {
    for (r, s) in [(0.3, 1.0), (0.5, 0.6), (0.2, 0.8)] {
        let b = brdf(Vec4::ONE, 1.0, r, s);
        let (at, ab) = an::alphas(f64::from(b.alpha), f64::from(s));
        for (theta, phi) in [(0.2f32, 0.3f32), (0.9, 1.2), (1.3, 0.0), (1.3, std::f32::consts::FRAC_PI_2)] {
            let wo = dir(theta, phi);
            let want = an::albedo(at, ab, wo.as_dvec3(), 1500) as f32;
            let mut rng = Sampler::new(3, 9);
            let (mean, se) = estimate(200_000, |_| match b.sample(wo, rng.uniform(), rng.next2()) {
                Some(x) => x.f * x.wi.z / x.pdf,
                None => Vec4::ZERO,
            });
            println!("r {r} s {s} θ {theta} φ {phi}: sampled {} ± {}, quadrature {want}", mean.x, se.x);
            let what = format!("r {r} s {s} θ {theta} φ {phi}");
            assert_within(mean, se + Vec4::splat(2e-4), Vec4::splat(want), &what);
            assert!(want <= 1.0 + 1e-3, "{what}: albedo {want}");
        }
    }
}

/// The material `two_materials_on_floor`'s sphere and floor get, `an` on both.
fn two_material_scene(an: Option<Anisotropy>) -> scene::Scene {
    crate::testing::two_materials_on_floor(|m| m.anisotropy = an.clone())
}

fn aniso(strength: f32, rotation: f32) -> Anisotropy {
    Anisotropy { strength, rotation, texture: None }
}

/// Renders: an anisotropy of strength 0 renders to the same bits as none (whatever its
/// texture); `--lambert` ignores the extension; otherwise it shows, and the image is finite.
#[test]
fn without_the_extension_renders_are_unchanged() {
    let plain = crate::testing::small_render(&two_material_scene(None), false);
    let off = Anisotropy {
        texture: Some(scene::TextureRef { index: 0, tex_coord: 0, transform: None }),
        ..aniso(0.0, 0.4)
    };
    assert!(crate::testing::small_render(&two_material_scene(Some(off)), false).xyz == plain.xyz);
    let on = two_material_scene(Some(aniso(1.0, 0.3)));
    assert!(
        crate::testing::small_render(&on, true).xyz
            == crate::testing::small_render(&two_material_scene(None), true).xyz
    );
    let lit = crate::testing::small_render(&on, false);
    println!("image mean with an anisotropy {:?}, without {:?}", lit.mean(), plain.mean());
    assert!(lit.xyz != plain.xyz && lit.dropped == 0);
    assert!(lit.xyz.iter().flatten().all(|v| v.is_finite()));
}

/// A white anisotropic metal floor (y = 0, 4 × 4) with tangent `tangent` everywhere, seen from
/// straight above by a camera whose image x is world +x and image y world +z, lit by a point
/// light at the camera; direct light only, 64 × 64 at 16 samples a pixel.
fn floor_render(tangent: Vec4, a: Anisotropy) -> crate::XyzImage {
    let mut floor = quad(Vec3::ZERO, Vec3::Y, 2.0, 0);
    floor.tangents = vec![tangent; 4];
    let m = Material {
        base_color: Vec4::ONE,
        metallic: 1.0,
        roughness: 0.3,
        anisotropy: Some(a),
        ..Default::default()
    };
    lit_floor(floor, m, vec![], 64, 16)
}

/// `floor` of material `m` (textures `textures`) seen from straight above by a camera whose
/// image x is world +x and image y world +z, lit by a point light at the camera; direct light
/// only, `size` × `size` at `spp` samples a pixel.
fn lit_floor(
    floor: scene::Mesh,
    m: Material,
    textures: Vec<scene::Texture>,
    size: u32,
    spp: u32,
) -> crate::XyzImage {
    let light = scene::Light {
        name: "p".into(),
        kind: scene::LightKind::Point { position: Vec3::new(0.0, 3.0, 0.0), range: None },
        emission: scene::Emission { rgb: Vec3::ONE, intensity: 10.0, spectrum: None },
        stands_in_for: None,
    };
    let mut s = scene_with(vec![floor], vec![m], vec![light]);
    s.textures = textures;
    s.camera = Camera::look_at(Vec3::new(0.0, 3.0, 0.0), Vec3::ZERO, -Vec3::Z, 1.2);
    let st = crate::render::Settings {
        seed: 3,
        direct_only: true,
        ..crate::render::Settings::new(size, size, spp).unwrap()
    };
    crate::render::render(&s, &crate::upsample::GreyOnly, &st, &Default::default(), &|_| {}).unwrap()
}

/// The highlight's spread along the image's x and y and along its diagonals: the
/// luminance-weighted second moments about its centroid, (var x, var y, var along x = y,
/// var along x = −y).
fn spread(img: &crate::XyzImage) -> [f64; 4] {
    let (w, h) = (img.width as usize, img.height as usize);
    let (mut s, mut sx, mut sy) = (0.0f64, 0.0, 0.0);
    for (i, p) in img.xyz.iter().enumerate() {
        let y = f64::from(p[1]);
        s += y;
        sx += y * (i % w) as f64;
        sy += y * (i / w) as f64;
    }
    let (cx, cy) = (sx / s, sy / s);
    let mut m = [0.0f64; 4];
    for (i, p) in img.xyz.iter().enumerate() {
        let y = f64::from(p[1]) / s;
        let (dx, dy) = ((i % w) as f64 - cx, (i / w) as f64 - cy);
        m[0] += y * dx * dx;
        m[1] += y * dy * dy;
        m[2] += y * (dx + dy).powi(2) * 0.5;
        m[3] += y * (dx - dy).powi(2) * 0.5;
    }
    assert!(h > 0 && (cx - w as f64 / 2.0).abs() < 2.0 && (cy - h as f64 / 2.0).abs() < 2.0, "{cx}, {cy}");
    m
}

/// Relative mean absolute difference of two images' Y.
fn rel_diff(a: &crate::XyzImage, b: &crate::XyzImage) -> f64 {
    let (mut d, mut s) = (0.0f64, 0.0f64);
    for (p, q) in a.xyz.iter().zip(&b.xyz) {
        d += f64::from((p[1] - q[1]).abs());
        s += f64::from(p[1]);
    }
    d / s
}

/// The orientation: on a floor lit from the camera, the highlight stretches along the tangent
/// (world x: image x) and, rotated by π/2, across it; rotating `anisotropyRotation` by π/2
/// is the same as turning the tangent a quarter turn (to world z), and by π/4 the same as turning
/// it an eighth of a turn towards the bitangent b₀ = n × t₀ (−z here, handedness +1; the image's
/// x = −y diagonal), not away from it; handedness −1 turns it the other way.
#[test]
fn the_highlight_stretches_along_the_rotated_tangent() {
    let (x, z) = (Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 0.0, 1.0, 1.0));
    let along = floor_render(x, aniso(0.8, 0.0));
    let m = spread(&along);
    println!("tangent x: spread {m:?}");
    assert!(m[0] > 3.0 * m[1], "not stretched along x: {m:?}");
    let turned = floor_render(x, aniso(0.8, std::f32::consts::FRAC_PI_2));
    let m = spread(&turned);
    println!("tangent x, rotation π/2: spread {m:?}");
    assert!(m[1] > 3.0 * m[0], "not stretched along y: {m:?}");
    let other = floor_render(z, aniso(0.8, 0.0));
    let (same, differ) = (rel_diff(&turned, &other), rel_diff(&turned, &along));
    println!("rotation π/2 vs the tangent turned to z: {same:.2e}; vs unrotated: {differ:.2e}");
    assert!(same < 1e-4 && differ > 0.3, "{same} {differ}");

    let eighth = floor_render(x, aniso(0.8, std::f32::consts::FRAC_PI_4));
    let m = spread(&eighth);
    println!("tangent x, rotation π/4: spread {m:?}");
    assert!(m[3] > 3.0 * m[2], "not stretched along x = −y: {m:?}");
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let towards_b = floor_render(Vec4::new(h, 0.0, -h, 1.0), aniso(0.8, 0.0));
    let away = floor_render(Vec4::new(h, 0.0, h, 1.0), aniso(0.8, 0.0));
    let (same, differ) = (rel_diff(&eighth, &towards_b), rel_diff(&eighth, &away));
    println!("rotation π/4 vs the tangent turned towards b₀: {same:.2e}; away from it: {differ:.2e}");
    assert!(same < 1e-4 && differ > 0.3, "{same} {differ}");
    let mirrored = floor_render(Vec4::new(1.0, 0.0, 0.0, -1.0), aniso(0.8, std::f32::consts::FRAC_PI_4));
    assert!(rel_diff(&mirrored, &away) < 1e-4);
}

/// A white metal floor (y = 0, 4 × 4), normal-mapped by one texel tilted towards +t and +b and
/// brushed at rotation π/4 (strength 0.8), rendered by [`lit_floor`] at 48 × 48, 8 samples. `back`: the floor is built facing down (normals −y) and seen from above, its back
/// face, with `tangent` as given; otherwise it faces up with tangent (1, 0, 0, 1).
fn mapped_floor_render(back: Option<Vec4>) -> crate::XyzImage {
    let mut floor = quad(Vec3::ZERO, if back.is_some() { -Vec3::Y } else { Vec3::Y }, 2.0, 0);
    floor.tangents = vec![back.unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0)); 4];
    let m = Material {
        base_color: Vec4::ONE,
        metallic: 1.0,
        roughness: 0.3,
        double_sided: true,
        normal_texture: Some(scene::TextureRef { index: 0, tex_coord: 0, transform: None }),
        anisotropy: Some(aniso(0.8, std::f32::consts::FRAC_PI_4)),
        ..Default::default()
    };
    // Tilted by about 35° towards t and b alike: (0.5, 0.5, 0.71) encoded in 8 bits.
    let tilt = scene::Texture {
        sampler: Default::default(),
        name: "tilt".into(),
        width: 1,
        height: 1,
        rgba8: vec![191, 191, 218, 255],
        srgb: false,
    };
    lit_floor(floor, m, vec![tilt], 48, 8)
}

/// A double-sided surface seen from behind turns its whole tangent frame with its normal
/// (`scene::facing_tangent`, the Khronos viewer's rule): its back face draws as the same surface
/// built facing the viewer with normal, tangent and bitangent negated (tangent (−t, −w)), normal
/// map and anisotropy direction alike. Turning only some of them (the tangent without its
/// handedness: the bitangent kept) mirrors the tilt and the direction, and shows.
#[test]
fn a_back_face_turns_its_tangent_frame_with_its_normal() {
    let front = mapped_floor_render(None);
    let back = mapped_floor_render(Some(Vec4::new(-1.0, 0.0, 0.0, -1.0)));
    let mirrored = mapped_floor_render(Some(Vec4::new(-1.0, 0.0, 0.0, 1.0)));
    let (same, differ) = (rel_diff(&front, &back), rel_diff(&front, &mirrored));
    println!("back face vs front: {same:.2e}; with the bitangent kept: {differ:.2e}");
    assert!(front.dropped == 0 && back.dropped == 0);
    assert!(same < 1e-3 && differ > 0.2, "{same} {differ}");
}
