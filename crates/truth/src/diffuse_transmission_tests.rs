//! `KHR_materials_diffuse_transmission` in the path tracer (`crate::bsdf::DiffuseTransmissionLanes`,
//! `material::diffuse_transmission`): the BSDF against the extension's model written out in f64
//! on both sides of the surface, over a dielectric, a half metal, a specular colour and a sheen;
//! the sampling against its own pdf over the whole sphere; reciprocity; share 0 is no extension
//! to the bit; the vertex's sides (shading and geometric plane); through the integrator, a sheet
//! lit from behind by a directional light (the closed form, under a specular colour, a sheen and
//! a clear coat), a sheet in a uniform surround (the model's albedo on both sides, in f64), a
//! lossless thin shell and a closed volume entered by the diffuse transmission; the textures;
//! and renders without the extension unchanged.

use super::sheen_tests::chi2_per_bin;
use super::tests::{assert_within, d65, estimate, radiance_any_hero};
use super::*;
use crate::bsdf::{DiffuseTransmissionLanes, SheenLanes, SpecularLanes};
use crate::material::TexCoords;
use crate::spectral::XyzSensor;
use crate::testing::{quad, scene_with, sphere};
use crate::upsample::GreyOnly;
use color::{Observer, WavelengthRange};
use glam::{DVec3, Vec2};
use scene::diffuse_transmission::DiffuseTransmission;
use scene::{Emission, Light, LightKind, Material, Texture, TextureRef};
use std::f64::consts::PI;

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

fn lanes(weight: f32, color: Vec4) -> DiffuseTransmissionLanes {
    DiffuseTransmissionLanes { weight, color }
}

fn schlick64(f0: f64, c: f64) -> f64 {
    f0 + (1.0 - f0) * (1.0 - c).max(0.0).powi(5)
}

/// The extension's model at one point, in f64, apart from the tracer's code.
#[derive(Clone, Copy)]
struct Model {
    base: [f64; 4],
    metallic: f64,
    /// The BRDF's α (after the tracer's floor).
    alpha: f64,
    /// diffuseTransmission and diffuseTransmissionColor(λ).
    t: f64,
    color: [f64; 4],
    /// `KHR_materials_specular`: (weight, F0 colour per lane, its largest RGB channel).
    specular: Option<(f64, [f64; 4], f64)>,
    /// `KHR_materials_sheen`: (colour per lane, largest RGB channel, roughness).
    sheen: Option<([f64; 4], f64, f64)>,
}

impl Model {
    /// f(wo, wi) for `wo` above the surface (normal +z) and `wi` on either side: glTF's
    /// fresnel_mix(base = mix(diffuse_brdf(base), diffuse_btdf(colour), t), layer = specular)
    /// mixed with the metal by m, the Fresnel terms at |v·h| with h the half vector of `wo` and
    /// `wi` — mirrored through the surface for a transmitted `wi` — and a sheen over all of it
    /// (the Charlie lobe on the near side only; the scaling min(1 − c·E(n·v), 1 − c·E(|n·l|))).
    fn f(&self, wo: DVec3, wi: DVec3) -> [f64; 4] {
        let transmitted = wi.z < 0.0;
        let l = DVec3::new(wi.x, wi.y, wi.z.abs());
        let (n_v, n_l) = (wo.z, l.z);
        let h = (wo + l).normalize();
        let v_h = wo.dot(h).abs();
        let a2 = self.alpha * self.alpha;
        let t = h.z * h.z * (a2 - 1.0) + 1.0;
        let d = a2 / (PI * t * t);
        let vis =
            0.5 / (n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt() + n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt());
        let m = self.metallic;
        let scaling = self.sheen.map_or(1.0, |(_, c, r)| {
            scene::sheen::albedo_scaling(c, scene::sheen::albedo(n_v, r), scene::sheen::albedo(n_l, r))
        });
        std::array::from_fn(|i| {
            let b = self.base[i];
            let (f_lobe, f_diffuse) = match self.specular {
                None => (schlick64(0.04 * (1.0 - m) + b * m, v_h), schlick64(0.04, v_h)),
                Some((s, f0, f0_max)) => (
                    (1.0 - m) * s * schlick64(f0[i], v_h) + m * schlick64(b, v_h),
                    s * schlick64(f0_max, v_h),
                ),
            };
            if transmitted {
                return scaling * (1.0 - m) * (1.0 - f_diffuse) * self.t * self.color[i] / PI;
            }
            let base = (1.0 - m) * (1.0 - f_diffuse) * (1.0 - self.t) * b / PI + f_lobe * d * vis;
            match self.sheen {
                None => base,
                Some((color, _, r)) => color[i] * scene::sheen::brdf(n_l, n_v, h.z, r) + scaling * base,
            }
        })
    }
}

fn f64s(v: Vec4) -> [f64; 4] {
    v.to_array().map(f64::from)
}

/// The BSDF cases the tests run over: (name, the tracer's BSDF, the model).
fn cases() -> Vec<(&'static str, Brdf, Model)> {
    let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
    let color = Vec4::new(0.9, 0.7, 0.2, 0.5);
    let make = |name, m: f32, r: f32, t: f32, sp: Option<SpecularLanes>, sh: Option<SheenLanes>| {
        let b = Brdf::new(base, m, r)
            .with_specular(sp)
            .with_sheen(sh)
            .with_diffuse_transmission(Some(lanes(t, color)));
        let model = Model {
            base: f64s(base),
            metallic: f64::from(m),
            alpha: f64::from(b.alpha),
            t: f64::from(t),
            color: f64s(color),
            specular: sp.map(|s| (f64::from(s.weight), f64s(s.f0), f64::from(s.f0_max))),
            sheen: sh.map(|s| (f64s(s.color), f64::from(s.max_color), f64::from(s.roughness))),
        };
        (name, b, model)
    };
    let sp = SpecularLanes { weight: 0.7, f0: Vec4::new(0.9, 0.6, 0.2, 0.05), f0_max: 0.95 };
    let sh = SheenLanes { color: Vec4::new(0.9, 0.6, 0.3, 0.2), max_color: 0.95, roughness: 0.5 };
    vec![
        make("dielectric", 0.0, 0.5, 0.4, None, None),
        make("all transmitted, smooth", 0.0, 0.2, 1.0, None, None),
        make("half metal", 0.5, 0.7, 0.6, None, None),
        make("specular colour", 0.2, 0.4, 0.5, Some(sp), None),
        make("sheen", 0.0, 0.5, 0.5, None, Some(sh)),
    ]
}

/// Random pairs: `wo` above the surface, `wi` on either side, |cos θ| from 0.02; fixed seed.
fn random_pairs(n: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = Sampler::new(23, 7);
    let mut d = |sign: f32| {
        let [a, b] = rng.next2();
        let c = 0.02 + 0.98 * a;
        let w = dir(c.acos(), 2.0 * std::f32::consts::PI * b);
        Vec3::new(w.x, w.y, w.z * sign)
    };
    (0..n)
        .map(|k| {
            let wo = d(1.0);
            (wo, d(if k % 2 == 0 { 1.0 } else { -1.0 }))
        })
        .collect()
}

/// `Brdf::eval` with a diffuse transmission is the model in f64 on both sides (relative error
/// < 10⁻⁵ on the far side, < 10⁻⁴ on the near; < 2·10⁻⁴ with a sheen, whose albedo table the
/// tracer reads in f32) at 400 random pairs, half of them transmitted; a `wo` below the surface gives 0, and without the
/// extension a far-side `wi` gives 0 as before.
#[test]
fn the_bsdf_is_the_extensions_model() {
    let pairs = random_pairs(400);
    for (name, b, model) in cases() {
        // The far side is this extension's arithmetic alone (10⁻⁵); the near side holds the
        // GGX lobe, whose D cancels in f32 near a mirror (4·10⁻⁵ at α = 0.04, as the BRDF's own
        // tests allow for), and a sheen's f32 albedo table (2·10⁻⁴, as sheen_tests allows).
        let tol = |below: bool| match (model.sheen.is_some(), below) {
            (true, _) => 2e-4,
            (false, true) => 1e-5,
            (false, false) => 1e-4,
        };
        let mut worst = [0.0f64; 2];
        for &(wo, wi) in &pairs {
            let (got, want) = (b.eval(wo, wi), model.f(wo.as_dvec3(), wi.as_dvec3()));
            for i in 0..4 {
                let e = (f64::from(got[i]) - want[i]).abs() / want[i].max(1e-3);
                let side = (wi.z < 0.0) as usize;
                worst[side] = worst[side].max(e);
                assert!(
                    e < tol(wi.z < 0.0),
                    "{name} {wo} {wi} lane {i}: {} vs the model's {}",
                    got[i],
                    want[i]
                );
            }
        }
        assert_eq!(b.eval(Vec3::new(0.3, 0.2, -0.5).normalize(), dir(0.4, 1.0)), Vec4::ZERO);
        let plain = Brdf { diffuse_transmission: None, ..b };
        assert_eq!(plain.eval(dir(0.4, 1.0), Vec3::new(0.3, 0.2, -0.5).normalize()), Vec4::ZERO);
        println!("{name}: worst relative error {:.2e} reflected, {:.2e} transmitted", worst[0], worst[1]);
    }
}

/// Reciprocity: f(wo, wi) = f(wi, wo) for both above, and f(wo, wi) = f(−wi, −wo) across (the
/// same pair seen from the other side, where the frame turns with the viewer), to f32 round-off.
#[test]
fn the_bsdf_is_reciprocal() {
    let mut worst = 0.0f32;
    for (name, b, _) in cases() {
        for &(wo, wi) in &random_pairs(200) {
            let (f, g) = if wi.z > 0.0 {
                (b.eval(wo, wi), b.eval(wi, wo))
            } else {
                (b.eval(wo, wi), b.eval(-wi, -wo))
            };
            let e = ((f - g).abs() / f.max(Vec4::splat(1e-20))).max_element();
            worst = worst.max(e);
            assert!(e < 1e-5, "{name} {wo} {wi}: {f} vs {g}");
        }
    }
    println!("reciprocity: worst relative difference {worst:.2e}");
}

/// Share 0 is no extension at all (`with_diffuse_transmission` drops it: eval, pdf, samples and
/// the albedo estimate are the plain BRDF's to the bit), and Lambert, the comparison mode, takes
/// none.
#[test]
fn share_zero_is_the_plain_brdf() {
    let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
    for (m, r) in [(0.0, 0.5), (0.4, 0.2), (1.0, 0.7)] {
        let plain = Brdf::new(base, m, r);
        let off = plain.with_diffuse_transmission(Some(lanes(0.0, Vec4::ONE)));
        assert!(off.diffuse_transmission.is_none());
        let mut rng = Sampler::new(5, 2);
        for &(wo, wi) in &random_pairs(200) {
            assert_eq!(off.eval(wo, wi), plain.eval(wo, wi));
            assert_eq!(off.pdf(wo, wi), plain.pdf(wo, wi));
            let (u0, u) = (rng.uniform(), rng.next2());
            let (a, c) = (plain.sample(wo, u0, u), off.sample(wo, u0, u));
            assert_eq!(a.map(|x| (x.wi, x.f, x.pdf)), c.map(|x| (x.wi, x.f, x.pdf)));
            assert_eq!(off.albedo_estimate(wo.z), plain.albedo_estimate(wo.z));
        }
    }
    assert!(
        Brdf::lambertian(base)
            .with_diffuse_transmission(Some(lanes(1.0, Vec4::ONE)))
            .diffuse_transmission
            .is_none()
    );
}

/// The `nc` (cos θ from −1 to 1) × `np` (φ) cell of `w`.
fn sphere_bin(w: Vec3, nc: usize, np: usize) -> usize {
    let ci = (((w.z + 1.0) * 0.5 * nc as f32) as usize).min(nc - 1);
    let phi = w.y.atan2(w.x).rem_euclid(2.0 * std::f32::consts::PI);
    let pj = ((phi / (2.0 * std::f32::consts::PI) * np as f32) as usize).min(np - 1);
    ci * np + pj
}

/// The pdf's quadrature over each cell of the whole sphere (`k` × `k` midpoints a cell), and
/// ∫f·|cos| over the sphere by the same midpoints (independent of the sampler).
fn sphere_quadrature(b: &Brdf, wo: Vec3, nc: usize, np: usize, k: usize) -> (Vec<f64>, Vec4) {
    let mut bins = vec![0.0f64; nc * np];
    let mut alb = [0.0f64; 4];
    let (dc, dp) = (2.0 / (nc * k) as f64, 2.0 * PI / (np * k) as f64);
    for i in 0..nc * k {
        let c = -1.0 + (i as f64 + 0.5) * dc;
        let s = (1.0 - c * c).sqrt();
        for j in 0..np * k {
            let phi = (j as f64 + 0.5) * dp;
            let wi = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
            bins[(i / k) * np + j / k] += f64::from(b.pdf(wo, wi)) * dc * dp;
            let f = b.eval(wo, wi);
            for (a, v) in alb.iter_mut().zip(f.to_array()) {
                *a += f64::from(v) * c.abs() * dc * dp;
            }
        }
    }
    (bins, Vec4::from_array(alb.map(|v| v as f32)))
}

/// The BSDF samples its own pdf over the whole sphere: 400 000 samples in 24 (cos θ in [−1, 1])
/// × 24 (φ) cells against the pdf's quadrature per cell (χ² per cell, worst cell in standard
/// deviations), ∫pdf over the sphere against the fraction of samples returned (GGX reflections
/// below the horizon are lost), the mean of f·|cos|/pdf against ∫f·|cos| by quadrature, each
/// sample carrying exactly `eval`'s and `pdf`'s values, and the far side drawn with the
/// probability the pdf gives it. The [`cases`] at 0.3 and 1.2 rad, and a black transmission
/// colour (never drawn: its lobe is 0).
#[test]
fn sampling_matches_its_pdf() {
    let mut all = cases();
    let black = Brdf::new(Vec4::splat(0.6), 0.0, 0.5).with_diffuse_transmission(Some(lanes(0.5, Vec4::ZERO)));
    let black_model = all[0].2;
    all.push(("black transmission colour", black, black_model));
    let (nc, np) = (24, 24);
    let (mut worst_chi2, mut worst_z, mut worst_ip, mut worst_est) = (0.0f64, 0.0f64, 0.0f64, 0.0f32);
    for (name, b, _) in all {
        for theta in [0.3f32, 1.2] {
            let wo = dir(theta, 0.0);
            let (expected, ialb) = sphere_quadrature(&b, wo, nc, np, 16);
            let ip: f64 = expected.iter().sum();
            let ip_below: f64 = expected[..nc / 2 * np].iter().sum();
            let mut rng = Sampler::new(31, 9);
            let n = 400_000usize;
            let mut counts = vec![0u32; nc * np];
            let (mut est, mut returned, mut below) = (Vec4::ZERO, 0usize, 0usize);
            for _ in 0..n {
                let Some(x) = b.sample(wo, rng.uniform(), rng.next2()) else { continue };
                assert_eq!((x.f, x.pdf), (b.eval(wo, x.wi), b.pdf(wo, x.wi)), "{name}");
                returned += 1;
                below += (x.wi.z < 0.0) as usize;
                est += x.f * x.wi.z.abs() / x.pdf;
                counts[sphere_bin(x.wi, nc, np)] += 1;
            }
            est /= n as f32;
            let (frac, frac_below) = (returned as f64 / n as f64, below as f64 / n as f64);
            let what = format!("{name} θ {theta}");
            let (chi2, dof, z_max) = chi2_per_bin(&counts, &expected, n, &what);
            println!(
                "{what}: χ²/cell {chi2:.3} over {dof} cells, worst {z_max:.2} σ; ∫pdf {ip:.4} vs returned {frac:.4}, far side {ip_below:.4} vs {frac_below:.4}; ∫f·|cos| {ialb} vs sampled {est}"
            );
            assert!(chi2 < 1.35, "{what}: χ²/cell {chi2}");
            assert!(z_max < 5.0, "{what}: a cell {z_max} σ off");
            assert!(ip <= 1.0 + 1e-3 && (ip - frac).abs() < 5e-3, "{what}: ∫pdf = {ip}, sampled {frac}");
            assert!((ip_below - frac_below).abs() < 5e-3, "{what}: far side {ip_below} vs {frac_below}");
            assert!((est - ialb).abs().max_element() < 0.01, "{what}: {est} vs {ialb}");
            worst_chi2 = worst_chi2.max(chi2);
            worst_z = worst_z.max(z_max);
            worst_ip = worst_ip.max((ip - frac).abs());
            worst_est = worst_est.max((est - ialb).abs().max_element());
        }
    }
    println!(
        "diffuse transmission sampling: worst χ²/cell {worst_chi2:.3}, worst cell {worst_z:.2} σ, |∫pdf − returned| ≤ {worst_ip:.1e}, |sampled − ∫f·|cos|| ≤ {worst_est:.1e}"
    );
}

/// At the vertex a direction is transmitted only where it is on the far side of both the
/// shading and the geometric plane, as for the dielectric's transmission: with the shading
/// normal tilted 0.3 rad from the geometric one, directions between the two planes give 0
/// (value and pdf) on either side.
#[test]
fn the_vertex_transmits_across_both_planes() {
    let b = cases()[0].1;
    let ng = Vec3::Z;
    let ns = dir(0.3, 0.0);
    let frame = Frame::from_normal(ns);
    let wo = dir(0.2, 2.0);
    // Below the shading plane, above the geometric one, and the mirror case.
    let between = [dir(1.5, std::f32::consts::PI), dir(1.7, 0.0)];
    for wi in between {
        assert!((frame.to_local(wi).z > 0.0) != (ng.dot(wi) > 0.0), "{wi} is not between the planes");
        assert_eq!(eval_base(&b, &frame, ng, &None, wo, wi), (Vec4::ZERO, 0.0), "{wi}");
    }
    let across = dir(2.5, 1.0);
    let (f, p) = eval_base(&b, &frame, ng, &None, wo, across);
    let li = frame.to_local(across);
    assert!(li.z < 0.0 && p > 0.0);
    assert_eq!(f, b.eval(frame.to_local(wo), li) * -li.z);
    assert_eq!(p, b.pdf(frame.to_local(wo), li));
}

/// A directional light of `intensity` (D65, luminance-matched: intensity × D65 in tracer units)
/// travelling along `direction`.
fn sun(direction: Vec3, intensity: f32) -> Light {
    Light {
        name: "sun".into(),
        kind: LightKind::Directional { direction },
        emission: Emission { rgb: Vec3::ONE, intensity, spectrum: Some(d65()) },
        stands_in_for: None,
    }
}

fn dt(factor: f32, color: Vec3) -> DiffuseTransmission {
    DiffuseTransmission { factor, texture: None, color: Vec3::splat(1.0) * color, color_texture: None }
}

/// A thin sheet (the plane z = 0, double-sided unless said) lit only by a directional light from
/// behind, seen from the front: the radiance is E·|cos θ_l|·f_t(wo, wi), f_t the model's
/// (1 − m)·(1 − F_d')·t·colour/π under the specular colour, the sheen's scaling and the clear
/// coat's 1 − w(n·v) (`scene::clearcoat::layer_weight`). Nothing else lights the sheet and its
/// one vertex sees the delta light by next-event estimation alone, so each path returns the value
/// itself: within 2·10⁻⁵ relative, with all bounces and direct-only, double- and single-sided.
/// Mirrored (seen from the back, lit from the front) a double-sided sheet returns the same, its
/// frame and coat turned to the viewer; a single-sided one is not there (0).
#[test]
fn a_sheet_lit_from_behind_transmits_the_closed_form() {
    let (base, t, colour, r) = (0.5f32, 0.6f32, 0.7f32, 0.5f32);
    let plain = Material {
        base_color: Vec4::new(base, base, base, 1.0),
        roughness: r,
        double_sided: true,
        diffuse_transmission: Some(dt(t, Vec3::splat(colour))),
        ..Default::default()
    };
    let model = |m: f64| Model {
        base: [f64::from(base); 4],
        metallic: m,
        alpha: f64::from(r * r),
        t: f64::from(t),
        color: [f64::from(colour); 4],
        specular: None,
        sheen: None,
    };
    let specular =
        scene::specular::Specular { factor: 0.5, texture: None, color: Vec3::ONE, color_texture: None };
    let sheen = scene::sheen::Sheen {
        color: Vec3::splat(0.8),
        color_texture: None,
        roughness: 0.5,
        roughness_texture: None,
    };
    let coat = scene::clearcoat::Clearcoat {
        factor: 0.8,
        texture: None,
        roughness: 0.2,
        roughness_texture: None,
        normal_texture: None,
        normal_scale: 1.0,
    };
    let cases: Vec<(&str, Material, Model, f32)> = vec![
        ("dielectric", plain.clone(), model(0.0), 0.0),
        ("half metal", Material { metallic: 0.5, ..plain.clone() }, model(0.5), 0.0),
        ("single-sided", Material { double_sided: false, ..plain.clone() }, model(0.0), 0.0),
        (
            "specular 0.5",
            Material { specular: Some(specular), ..plain.clone() },
            Model { specular: Some((0.5, [0.04; 4], 0.04)), ..model(0.0) },
            0.0,
        ),
        (
            "sheen 0.8",
            Material { sheen: Some(sheen), ..plain.clone() },
            Model { sheen: Some(([0.8; 4], 0.8, 0.5)), ..model(0.0) },
            0.0,
        ),
        ("clear coat 0.8", Material { clearcoat: Some(coat), ..plain.clone() }, model(0.0), 0.8),
    ];
    let light_dir = Vec3::new(0.3, -0.2, 1.0).normalize();
    let e = 5.0f32;
    let range = WavelengthRange::VISIBLE;
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.6);
    let d65_lanes = Vec4::from_array(wl.0.to_array().map(|l| d65().eval(f64::from(l)) as f32));
    let mut worst = 0.0f32;
    // The whole arrangement mirrored through the sheet: seen from its back, lit from its front.
    let mirrored = |v: Vec3, side: f32| Vec3::new(v.x, v.y, v.z * side);
    for (name, mat, model, coat) in cases {
        let single = !mat.double_sided;
        for side in [1.0f32, -1.0] {
            let sun_dir = mirrored(light_dir, side);
            let scene =
                scene_with(vec![quad(Vec3::ZERO, Vec3::Z, 2.0, 0)], vec![mat.clone()], vec![sun(sun_dir, e)]);
            let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
            for view in [dir(0.2, 1.0), dir(1.0, 2.5)] {
                let o = Vec3::new(0.1, -0.2, 0.0) + mirrored(view, side) * 2.0;
                let wi = -light_dir;
                let f = model.f(view.as_dvec3(), wi.as_dvec3());
                let w = f64::from(scene::clearcoat::layer_weight(coat, view.z));
                let want = Vec4::from_array(
                    f.map(|v| (v * (1.0 - w) * f64::from(light_dir.z) * f64::from(e)) as f32),
                ) * d65_lanes;
                // A single-sided sheet's back is not there: the ray passes and meets nothing.
                let want = if single && side < 0.0 { Vec4::ZERO } else { want };
                for direct_only in [false, true] {
                    let integ = Integrator { world: &world, direct_only, max_depth: 10, lambert: false };
                    let mut rng = Sampler::new(3, 1);
                    let got = integ.radiance(o, -mirrored(view, side), &wl, &mut rng);
                    let err = ((got - want).abs() / want.max(Vec4::splat(1e-30))).max_element();
                    worst = worst.max(err);
                    println!(
                        "{name}, side {side}, view θ {:.1}, direct only {direct_only}: {got} vs {want} ({err:.1e})",
                        view.z.acos()
                    );
                    assert!(
                        err < 2e-5,
                        "{name}, side {side}, direct only {direct_only}: {got} vs the closed form {want}"
                    );
                }
            }
        }
    }
    println!("sheet lit from behind: worst relative error {worst:.2e}");
}

/// A sheet lit by an area light behind it, seen from the front: next-event estimation to the
/// lamp across the sheet and BSDF sampling into the far side, weighed by MIS, return
/// ∫_lamp f_t(wo, wi)·Le·|cos θ_i|·cos θ_l/d² dA, the model's BTDF integrated over the lamp by an
/// f64 midpoint rule (400 × 400). The lamp reflects nothing (black, specular weight 0), so no
/// other light reaches the sheet. 20 000 paths per view, 5 standard errors per lane; with a sheen
/// too (its scaling at |n·l| varies over the lamp).
#[test]
fn a_sheet_lit_by_a_lamp_behind_it_transmits_the_lamps_integral() {
    let (t, colour, r) = (0.7f32, 0.8f32, 0.4f32);
    let sheet = Material {
        base_color: Vec4::new(0.3, 0.3, 0.3, 1.0),
        roughness: r,
        double_sided: true,
        diffuse_transmission: Some(dt(t, Vec3::splat(colour))),
        ..Default::default()
    };
    let lamp = Material {
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        emissive: Vec3::ONE,
        specular: Some(scene::specular::Specular {
            factor: 0.0,
            texture: None,
            color: Vec3::ONE,
            color_texture: None,
        }),
        ..Default::default()
    };
    let model = Model {
        base: [0.3; 4],
        metallic: 0.0,
        alpha: f64::from(r * r),
        t: f64::from(t),
        color: [f64::from(colour); 4],
        specular: None,
        sheen: None,
    };
    let sheen = scene::sheen::Sheen {
        color: Vec3::splat(0.9),
        color_texture: None,
        roughness: 0.3,
        roughness_texture: None,
    };
    let cases = [
        ("dielectric", sheet.clone(), model),
        (
            "sheen",
            Material { sheen: Some(sheen), ..sheet.clone() },
            Model { sheen: Some(([0.9; 4], 0.9, 0.3)), ..model },
        ),
    ];
    let (lamp_z, lamp_h) = (-1.0f64, 0.5f64);
    let range = WavelengthRange::VISIBLE;
    for (name, mat, model) in cases {
        let meshes = vec![
            quad(Vec3::ZERO, Vec3::Z, 2.0, 0),
            quad(Vec3::new(0.0, 0.0, lamp_z as f32), Vec3::Z, lamp_h as f32, 1),
        ];
        let scene = scene_with(meshes, vec![mat, lamp.clone()], vec![]);
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only: false, max_depth: 100, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.4);
        let le = world.units.rgb(Vec3::ONE, &GreyOnly, wl.0);
        let p = Vec3::new(0.15, -0.1, 0.0);
        for (k, view) in [dir(0.3, 0.5), dir(1.1, 3.0)].into_iter().enumerate() {
            let wo = view.as_dvec3();
            let n = 400;
            let da = (2.0 * lamp_h / n as f64).powi(2);
            let mut sum = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let q = DVec3::new(
                        -lamp_h + (i as f64 + 0.5) * 2.0 * lamp_h / n as f64,
                        -lamp_h + (j as f64 + 0.5) * 2.0 * lamp_h / n as f64,
                        lamp_z,
                    );
                    let to = q - p.as_dvec3();
                    let d2 = to.length_squared();
                    let wi = to / d2.sqrt();
                    sum += model.f(wo, wi)[0] * wi.z.abs() * wi.z.abs() / d2 * da;
                }
            }
            let want = le * sum as f32;
            let o = p + view * 2.0;
            let mut rng = Sampler::new(12, k as u64);
            let (m, se) = estimate(20_000, |_| radiance_any_hero(&integ, o, -view, &wl, &mut rng));
            println!(
                "{name}, view θ {:.1}: {:.5} ± {:.5} vs the lamp's integral {sum:.5} (× Le)",
                view.z.acos(),
                m.x / le.x,
                se.x / le.x
            );
            assert_within(m, se, want, &format!("{name}, view {k}"));
        }
    }
}

/// The white furnace of a sheet: a double-sided sheet (white base, white transmission colour,
/// roughness 0.5, t = 0.5) in a uniform white surround, so lit from both sides and seeing nothing
/// but the surround, returns Le·A(θ), A the model's albedo over the whole sphere by an f64
/// quadrature. The diffuse transmission moves light between the sides and changes nothing else:
/// A is the plain white dielectric's albedo (the far side's integral is the near side's mirrored),
/// which the quadrature checks too. 20 000 paths per view, 5 standard errors per lane.
#[test]
fn a_white_sheet_in_a_furnace_returns_the_models_albedo() {
    let (t, r) = (0.5f32, 0.5f32);
    let mat = Material {
        roughness: r,
        double_sided: true,
        diffuse_transmission: Some(dt(t, Vec3::ONE)),
        ..Default::default()
    };
    let mut scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Z, 2.0, 0)], vec![mat], vec![]);
    scene.environment = Some(scene::Environment::uniform(Vec3::ONE));
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 100, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
    let le = world.units.rgb(Vec3::ONE, &GreyOnly, wl.0);
    let model = Model {
        base: [1.0; 4],
        metallic: 0.0,
        alpha: f64::from(r * r),
        t: f64::from(t),
        color: [1.0; 4],
        specular: None,
        sheen: None,
    };
    let opaque = Model { t: 0.0, ..model };
    for theta in [0.3f64, 0.9, 1.3] {
        let wo = DVec3::new(theta.sin(), 0.0, theta.cos());
        // Midpoints in cos θ and φ on each side.
        let (nt, np) = (1000, 400);
        let (mut near, mut far, mut plain) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..nt {
            let c = (i as f64 + 0.5) / nt as f64;
            let s = (1.0 - c * c).sqrt();
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                let w = DVec3::new(s * phi.cos(), s * phi.sin(), c);
                let dw = c * 2.0 * PI / (nt * np) as f64;
                near += model.f(wo, w)[0] * dw;
                far += model.f(wo, DVec3::new(w.x, w.y, -c))[0] * dw;
                plain += opaque.f(wo, w)[0] * dw;
            }
        }
        let a = near + far;
        assert!((a - plain).abs() < 1e-9, "θ {theta}: {a} vs the opaque white dielectric's {plain}");
        let view = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
        let o = Vec3::new(0.2, 0.1, 0.0) + view * 2.0;
        let mut rng = Sampler::new(8, (theta * 10.0) as u64);
        let (m, se) = estimate(20_000, |_| radiance_any_hero(&integ, o, -view, &wl, &mut rng));
        let want = le * a as f32;
        println!(
            "white sheet, θ {theta}: {:.5} ± {:.5} vs Le·A {:.5} (A = {near:.5} reflected + {far:.5} transmitted)",
            m.x / le.x,
            se.x / le.x,
            a
        );
        assert_within(m, se, want, &format!("white sheet θ {theta}"));
    }
}

/// A white diffuse BSDF without a Fresnel term (specular weight 0: f = (1 − t)/π on the near
/// side, t/π on the far) returns everything, so a closed thin shell of it in a uniform surround —
/// light crossing it any number of times, inside and out — has radiance Le everywhere. A closed
/// volume (`KHR_materials_volume`, with a transmission factor of 10⁻⁶ so that the volume exists)
/// is entered by the diffuse transmission: clear, it changes nothing (Le); absorbing (1 % left
/// after 10⁻³ of the radius), what crosses in never comes out (5·10⁻⁸ survives a chord of the
/// cosine lobe) and the shell returns (1 − t)·Le. 4000 paths at each of the sphere's pixels
/// (8 × 8, 5 standard errors per lane).
#[test]
fn a_lossless_shell_and_a_volume_entered_by_the_diffuse_transmission() {
    let t = 0.4f32;
    let lossless = Material {
        double_sided: true,
        specular: Some(scene::specular::Specular {
            factor: 0.0,
            texture: None,
            color: Vec3::ONE,
            color_texture: None,
        }),
        diffuse_transmission: Some(dt(t, Vec3::ONE)),
        ..Default::default()
    };
    let volume = |distance: f32| scene::transmission::Transmission {
        factor: 1e-6,
        texture: None,
        volume: Some(scene::transmission::Volume {
            thickness: 1.0,
            thickness_texture: None,
            attenuation_color: [0.01; 3],
            attenuation_distance: distance,
        }),
        dispersion: 0.0,
    };
    let cases = [
        ("thin shell", lossless.clone(), 1.0f32),
        ("clear volume", Material { transmission: Some(volume(f32::INFINITY)), ..lossless.clone() }, 1.0),
        ("absorbing volume", Material { transmission: Some(volume(1e-3)), ..lossless.clone() }, 1.0 - t),
    ];
    for (name, mat, share) in cases {
        shell_in_a_furnace(name, mat, |_| share);
    }
}

/// A sphere of radius 1 (flat facets) of `mat` in a uniform white surround, seen at 8 × 8 pixel
/// centres: each pixel on it returns Le·`share(cos θ)`, θ between the ray and its facet, within 5
/// standard errors per lane over 4000 paths.
fn shell_in_a_furnace(name: &str, mat: Material, share: impl Fn(f32) -> f32) {
    let range = WavelengthRange::VISIBLE;
    let mut scene = scene_with(vec![sphere(Vec3::ZERO, 1.0, 32, 0)], vec![mat], vec![]);
    scene.environment = Some(scene::Environment::uniform(Vec3::ONE));
    scene.camera = scene::Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.7);
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 200, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
    let le = world.units.rgb(Vec3::ONE, &GreyOnly, wl.0);
    let (w, h) = (8u32, 8u32);
    let cam = crate::camera::RayCamera::new(&scene.camera, w, h);
    let (mut n, mut worst, mut sum, mut sum_want) = (0, 0.0f32, 0.0f32, 0.0f32);
    for i in 0..w * h {
        let r = cam.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
        let Some(hit) = world.geometry.intersect(r.o, r.d, f32::INFINITY) else { continue };
        let want = le * share(world.surface(&hit).ng.dot(-r.d).abs());
        let mut rng = Sampler::new(77, u64::from(i));
        let (m, se) = estimate(4000, |_| radiance_any_hero(&integ, r.o, r.d, &wl, &mut rng));
        assert_within(m, se, want, &format!("{name}, pixel {i}"));
        worst = worst.max(((m - want).abs() / se.max(Vec4::splat(1e-12))).max_element());
        sum += m.x / le.x;
        sum_want += want.x / le.x;
        n += 1;
    }
    assert!(n > 20, "{n} pixels on the sphere");
    println!(
        "{name}: {n} pixels, mean {:.5} (want {:.5}), worst lane {worst:.2} standard errors",
        sum / n as f32,
        sum_want / n as f32
    );
}

/// With `KHR_materials_transmission` the specular transmission takes its share T first:
/// f = (1 − T)·(the diffuse BRDF and BTDF) + T·(the dielectric). A smooth see-through shell
/// (T = 0.5, roughness 0) whose diffuse part is lossless (white, specular weight 0, t = 0.6) loses
/// nothing, thin: Le at every pixel. Around an absorbing volume, everything that crosses in, by
/// refraction or diffuse transmission, is lost, and a pixel returns
/// Le·((1 − T)·(1 − t) + T·F(cos θ)), F the exact Fresnel reflectance of the index 1.5
/// (`scene::transmission::fresnel_dielectric`) the smooth interface reflects.
#[test]
fn with_a_specular_transmission_each_takes_its_share() {
    let (tr, t) = (0.5f32, 0.6f32);
    let transmission = |distance: f32, volume: bool| scene::transmission::Transmission {
        factor: tr,
        texture: None,
        volume: volume.then_some(scene::transmission::Volume {
            thickness: 1.0,
            thickness_texture: None,
            attenuation_color: [0.01; 3],
            attenuation_distance: distance,
        }),
        dispersion: 0.0,
    };
    let mat = |tx| Material {
        roughness: 0.0,
        double_sided: true,
        specular: Some(scene::specular::Specular {
            factor: 0.0,
            texture: None,
            color: Vec3::ONE,
            color_texture: None,
        }),
        diffuse_transmission: Some(dt(t, Vec3::ONE)),
        transmission: Some(tx),
        ..Default::default()
    };
    shell_in_a_furnace("smooth see-through thin shell", mat(transmission(f32::INFINITY, false)), |_| 1.0);
    shell_in_a_furnace("smooth see-through absorbing volume", mat(transmission(1e-3, true)), |c| {
        let f = scene::transmission::fresnel_dielectric(f64::from(c), 1.5) as f32;
        (1.0 - tr) * (1.0 - t) + tr * f
    });
}

/// The textures at a hit: the share from the share texture's A (linear) and the colour from the
/// colour texture's RGB (sRGB-decoded), times the factors; a texel of alpha 0, a zero factor, an
/// unlit material and no extension give none.
#[test]
fn the_textures_scale_share_and_colour() {
    let tex = |rgba: [u8; 4]| Texture {
        sampler: Default::default(),
        name: "t".into(),
        width: 1,
        height: 1,
        rgba8: rgba.to_vec(),
        srgb: true,
    };
    let r = |index| Some(TextureRef { index, tex_coord: 0, transform: None });
    let m = Material {
        diffuse_transmission: Some(DiffuseTransmission {
            factor: 0.8,
            texture: r(0),
            color: Vec3::new(0.5, 1.0, 0.8),
            color_texture: r(0),
        }),
        ..Default::default()
    };
    let tc = TexCoords::one(Vec2::splat(0.5));
    let textures = [tex([255, 128, 64, 100]), tex([10, 20, 30, 0])];
    let (share, color) = material::diffuse_transmission(&m, &textures, &tc).unwrap();
    let dec = |v: u8| crate::texture::srgb_decode(f32::from(v) / 255.0);
    let want = Vec3::new(0.5 * dec(255), dec(128), 0.8 * dec(64));
    assert!((color - want).abs().max_element() < 1e-6, "{color} vs {want}");
    assert!((share - 0.8 * 100.0 / 255.0).abs() < 1e-6, "{share}");
    let dtm = m.diffuse_transmission.clone().unwrap();
    let zero_alpha = Material {
        diffuse_transmission: Some(DiffuseTransmission { texture: r(1), ..dtm.clone() }),
        ..m.clone()
    };
    assert_eq!(material::diffuse_transmission(&zero_alpha, &textures, &tc), None);
    let off =
        Material { diffuse_transmission: Some(DiffuseTransmission { factor: 0.0, ..dtm }), ..m.clone() };
    assert_eq!(material::diffuse_transmission(&off, &textures, &tc), None);
    assert_eq!(material::diffuse_transmission(&Material { unlit: true, ..m.clone() }, &textures, &tc), None);
    assert_eq!(material::diffuse_transmission(&Material::default(), &textures, &tc), None);
}

/// The colour is upsampled exactly as the base colour is: the same lanes for the same RGB.
#[test]
fn the_colour_is_upsampled_as_the_base_colour() {
    let table = color::upsample::table("srgb").expect("the sRGB table");
    let l = Vec4::new(430.0, 510.0, 590.0, 670.0);
    let rgb = Vec3::new(0.9, 0.5, 0.2);
    let lanes = DiffuseTransmissionLanes::new(0.5, rgb, table.as_ref(), l);
    let m = Material { base_color: rgb.extend(1.0), ..Default::default() };
    let pm = crate::material::PreparedMaterial::new(&m, WavelengthRange::VISIBLE);
    let base = material::base_reflectance(&m, &pm, &[], table.as_ref(), &TexCoords::default(), Vec4::ONE, l);
    assert_eq!(lanes.color, base);
    assert!(lanes.color.x < lanes.color.w, "not orange: {}", lanes.color);
}

fn two_material_scene(d: Option<DiffuseTransmission>) -> scene::Scene {
    crate::testing::two_materials_on_floor(|m| m.diffuse_transmission = d.clone())
}

/// Renders: a diffuse transmission that is off (factor 0, whatever its texture) renders to the
/// same bits as none; `--lambert` ignores the extension; otherwise it shows.
#[test]
fn without_the_extension_renders_are_unchanged() {
    let plain = crate::testing::small_render(&two_material_scene(None), false);
    let off = DiffuseTransmission {
        factor: 0.0,
        texture: Some(TextureRef { index: 0, tex_coord: 0, transform: None }),
        color: Vec3::new(0.9, 0.2, 0.2),
        color_texture: None,
    };
    assert!(crate::testing::small_render(&two_material_scene(Some(off)), false).xyz == plain.xyz);
    let on = two_material_scene(Some(dt(0.7, Vec3::new(0.9, 0.6, 0.3))));
    assert!(
        crate::testing::small_render(&on, true).xyz
            == crate::testing::small_render(&two_material_scene(None), true).xyz
    );
    let lit = crate::testing::small_render(&on, false);
    println!("image mean with a diffuse transmission {:?}, without {:?}", lit.mean(), plain.mean());
    assert!(lit.xyz != plain.xyz);
}

/// `--direct-only`: past its one bounce a path goes on through refractions only, and a diffuse
/// transmission is a bounce. A mirror floor under a thin see-through sheet (T = 0.5, smooth) with
/// a diffuse transmission (t = 0.8) in a white sky, seen from between them: the path bounces off
/// the mirror and passes the sheet by refraction alone, Le·T·(1 − F(cos θ)) (F by Fresnel's
/// equations, within 0.5 % as the see-through test allows for the mirror's lobe), to the bit what
/// the sheet without the extension passes; with all bounces the diffuse transmission changes
/// the light between the sheet and the mirror (by more than 5 standard errors).
#[test]
fn direct_only_passes_a_sheet_by_refraction_alone() {
    let sheet = |d: Option<DiffuseTransmission>| Material {
        roughness: 0.0,
        double_sided: true,
        transmission: Some(scene::transmission::Transmission {
            factor: 0.5,
            texture: None,
            volume: None,
            dispersion: 0.0,
        }),
        diffuse_transmission: d,
        ..Default::default()
    };
    let mirror = Material { metallic: 1.0, roughness: 0.0, ..Default::default() };
    let range = WavelengthRange::VISIBLE;
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.35);
    let render = |d: Option<DiffuseTransmission>, direct_only: bool, theta: f32| {
        let meshes =
            vec![quad(Vec3::ZERO, Vec3::Y, 50.0, 0), quad(Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 50.0, 1)];
        let mut scene = scene_with(meshes, vec![mirror.clone(), sheet(d)], vec![]);
        scene.environment = Some(scene::Environment::uniform(Vec3::ONE));
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only, max_depth: 100, lambert: false };
        let d = Vec3::new(theta.sin(), -theta.cos(), 0.0);
        let o = Vec3::new(0.0, 0.5, 0.0) - d * 0.5;
        estimate(40_000, |rng| radiance_any_hero(&integ, o, d, &wl, rng))
    };
    let le = world_le(&wl);
    for theta in [0.2f32, 0.9] {
        let c = f64::from(theta.cos());
        let f = scene::transmission::fresnel_dielectric(c, 1.5);
        let want = (0.5 * (1.0 - f)) as f32;
        let (m, se) = render(Some(dt(0.8, Vec3::ONE)), true, theta);
        let plain = render(None, true, theta);
        let got = m.x / le.x;
        println!("direct only, θ {theta}: {got:.5} ± {:.5} (want {want:.5})", se.x / le.x);
        assert!((got - want).abs() < 0.005 + 5.0 * se.x / le.x, "θ {theta}: {got} vs {want}");
        assert_eq!((m, se), plain, "θ {theta}: the diffuse transmission counted after the bounce");
        let (all, all_se) = render(Some(dt(0.8, Vec3::ONE)), false, theta);
        let (all_plain, plain_se) = render(None, false, theta);
        println!(
            "all bounces, θ {theta}: {:.5} ± {:.5}, without it {:.5} ± {:.5}",
            all.x / le.x,
            all_se.x / le.x,
            all_plain.x / le.x,
            plain_se.x / le.x
        );
        let sigma = (all_se.x * all_se.x + plain_se.x * plain_se.x).sqrt();
        assert!((all.x - all_plain.x).abs() > 5.0 * sigma, "θ {theta}: all bounces {all} vs {all_plain}");
    }
}

/// The white sky's radiance at the lanes of `wl`.
fn world_le(wl: &crate::spectral::Wavelengths) -> Vec4 {
    let mut scene = scene_with(vec![], vec![], vec![]);
    scene.environment = Some(scene::Environment::uniform(Vec3::ONE));
    let world = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, None).unwrap();
    world.units.rgb(Vec3::ONE, &GreyOnly, wl.0)
}
