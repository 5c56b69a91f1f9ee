//! `KHR_materials_clearcoat` in the estimator: a furnace against the extension's mix with
//! the coat's albedo by quadrature, emission under a coat, the coated vertex's sampling against
//! its own value and pdf, and the coat's normal map acting on the coat alone.

use super::tests::{assert_within, d65, estimate, radiance_any_hero, spectrum_at, with_env};
use super::*;
use crate::spectral::XyzSensor;
use crate::testing::{quad, scene_with, sphere};
use crate::upsample::GreyOnly;
use color::{Observer, Spectrum, WavelengthRange};
use glam::Vec2;
use scene::clearcoat::Clearcoat;
use scene::{Material, SpectralReflectance, Texture, TextureRef};

fn coat(factor: f32, roughness: f32) -> Clearcoat {
    Clearcoat {
        factor,
        texture: None,
        roughness,
        roughness_texture: None,
        normal_texture: None,
        normal_scale: 1.0,
    }
}

/// The extension's layering weight, written out: clearcoat · (0.04 + 0.96·(1 − |V·N_c|)⁵).
fn coat_weight(factor: f64, cos: f64) -> f64 {
    factor * (0.04 + 0.96 * (1.0 - cos.abs()).powi(5))
}

/// Directional albedo ∫ D·G₂/(4·cos θ_o·cos θ_i)·cos θ_i dω_i of the coat's BRDF at
/// cos θ_o = `c`: GGX D and the height-correlated Smith G₂ = 1/(1 + Λ_o + Λ_i) in its Λ form,
/// by midpoint quadrature in cos θ_i and φ (the integrand is even in φ: half the circle, twice),
/// in f64, apart from the tracer's code.
fn coat_albedo(alpha: f64, c: f64) -> f64 {
    coat_albedo_masked(alpha, c, true)
}

/// [`coat_albedo`], or without G₂ (`masking` false) for the closed-form check.
fn coat_albedo_masked(alpha: f64, c: f64, masking: bool) -> f64 {
    use std::f64::consts::PI;
    let a2 = alpha * alpha;
    let lambda = |z: f64| 0.5 * ((1.0 + a2 * (1.0 - z * z) / (z * z)).sqrt() - 1.0);
    let so = (1.0 - c * c).max(0.0).sqrt();
    let (nt, np) = (1000, 400);
    let mut sum = 0.0;
    for i in 0..nt {
        let ci = (i as f64 + 0.5) / nt as f64;
        let si = (1.0 - ci * ci).sqrt();
        for j in 0..np {
            let phi = PI * (j as f64 + 0.5) / np as f64;
            let h = [so + si * phi.cos(), si * phi.sin(), c + ci];
            let n_h2 = h[2] * h[2] / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
            let t = n_h2 * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * t * t);
            let g2 = if masking { 1.0 / (1.0 + lambda(c) + lambda(ci)) } else { 1.0 };
            sum += d * g2 / (4.0 * c * ci) * ci;
        }
    }
    sum * (2.0 * PI / np as f64) / nt as f64
}

/// The coat quadrature is right where it is known. Seen head-on, without masking, it is the
/// share of GGX microfacet normals within 45° of the normal (beyond, the reflection goes
/// below the horizon): tan²45°/(α² + tan²45°) = 1/(1 + α²), 0.941 at α = 0.25 (GGX's long
/// tail); masking takes more (2.5 % more at α = 0.25, the furnace's rough coat), and a
/// near-mirror keeps (almost) all.
#[test]
fn coat_albedo_quadrature_checks_out() {
    for alpha in [0.1, 0.25, 0.5] {
        let (open, closed) = (coat_albedo_masked(alpha, 1.0, false), 1.0 / (1.0 + alpha * alpha));
        println!(
            "α {alpha}: head-on {open:.6} unmasked (closed form {closed:.6}), {:.6} masked",
            coat_albedo(alpha, 1.0)
        );
        assert!((open - closed).abs() < 5e-4, "α {alpha}: {open} vs {closed}");
        let masked = coat_albedo(alpha, 1.0);
        assert!(masked < open && masked > 0.8 * open, "α {alpha}: {masked} vs {open}");
    }
    assert!((coat_albedo(0.02, 0.8) - 1.0).abs() < 2e-3, "{}", coat_albedo(0.02, 0.8));
}

/// White furnace of a coated sphere (convex: every reflection escapes) in a uniform
/// environment of radiance Le: at each pixel the radiance is
/// Le·((1 − w)·A_base + w·A_coat), w = clearcoat·F(|V·N|) at that pixel's normal, A_base the
/// base BRDF's albedo and A_coat the coat's (1 smooth, by quadrature rough). The base is
/// coloured and the coat grey, so the lanes differ. Each pixel centre's ray, 3000 paths, within
/// 5 standard errors per lane.
#[test]
fn coated_sphere_furnace_is_the_extensions_mix_pixel_by_pixel() {
    let base = Spectrum::piecewise(vec![380.0, 550.0, 730.0], vec![0.15, 0.6, 0.3]).unwrap();
    let (metallic, roughness, factor) = (0.0, 0.6, 0.8f32);
    for coat_roughness in [0.0f32, 0.5] {
        let mat = Material {
            metallic,
            roughness,
            spectral: Some(SpectralReflectance::Uniform(base.clone())),
            clearcoat: Some(coat(factor, coat_roughness)),
            ..Default::default()
        };
        let mut scene = with_env(
            scene_with(vec![sphere(Vec3::ZERO, 1.0, 48, 0)], vec![mat], vec![]),
            scene::Environment::uniform(Vec3::ONE),
        );
        scene.camera = scene::Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.8);
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only: false, max_depth: 1000, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
        let le = spectrum_at(&d65(), &wl);
        let brdf = Brdf::new(spectrum_at(&base, &wl), metallic, roughness);
        let (w, h) = (16u32, 16u32);
        let cam = crate::camera::RayCamera::new(&scene.camera, w, h);
        let (mut pixels, mut worst_z, mut lift) = (0, 0.0f32, 0.0f32);
        for i in 0..w * h {
            let r = cam.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
            let Some(hit) = world.geometry.intersect(r.o, r.d, f32::INFINITY) else { continue };
            // Flat facets: the normal is the hit triangle's.
            let cos = world.surface(&hit).ng.dot(-r.d);
            let wt = coat_weight(f64::from(factor), f64::from(cos)) as f32;
            let a_coat = if coat_roughness == 0.0 {
                1.0
            } else {
                coat_albedo(f64::from(coat_roughness * coat_roughness), f64::from(cos)) as f32
            };
            let a_base = crate::testing::directional_albedo(&brdf, cos);
            let want = le * (a_base * (1.0 - wt) + Vec4::splat(wt * a_coat));
            let (m, se) = estimate(3000, |rng| radiance_any_hero(&integ, r.o, r.d, &wl, rng));
            assert_within(m, se, want, &format!("coat roughness {coat_roughness}, pixel {i}, cos {cos:.3}"));
            pixels += 1;
            worst_z = worst_z.max(((m - want).abs() / se.max(Vec4::splat(1e-12))).max_element());
            lift = lift.max(((want - le * a_base) / (le * a_base)).max_element());
        }
        println!(
            "coated sphere furnace, coat roughness {coat_roughness}: {pixels} pixels, worst lane {worst_z:.2} \
             standard errors from the mix; the coat lifts a pixel by up to {:.0} %",
            lift * 100.0
        );
        assert!(pixels > 60, "{pixels} pixels on the sphere");
    }
}

/// A coated lamp seen head-on in a black world shows its emission through 1 − clearcoat·0.04
/// (F(1) = 0.04), whatever the coat's roughness.
#[test]
fn a_coated_emitter_seen_head_on_emits_one_minus_the_coat_weight() {
    let lamp =
        |c: Option<Clearcoat>| Material { emissive: Vec3::splat(0.8), clearcoat: c, ..Default::default() };
    let radiance = |c: Option<Clearcoat>| {
        let scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Z, 1.0, 0)], vec![lamp(c)], vec![]);
        let world = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, None).unwrap();
        let integ = Integrator { world: &world, direct_only: false, max_depth: 100, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), world.units.range).sample(0.4);
        let mut rng = Sampler::new(5, 0);
        let l: Vec<Vec4> =
            (0..16).map(|_| integ.radiance(Vec3::new(0.1, -0.2, 2.0), -Vec3::Z, &wl, &mut rng)).collect();
        // Nothing but the lamp itself is in view or lit: every path returns the same.
        assert!(l.iter().all(|x| *x == l[0]), "{l:?}");
        l[0]
    };
    let bare = radiance(None);
    assert!(bare.min_element() > 0.0);
    for (factor, roughness) in [(1.0f32, 0.0f32), (0.6, 0.3), (0.25, 1.0)] {
        let got = radiance(Some(coat(factor, roughness)));
        let want = bare * (1.0 - factor * 0.04);
        println!("coated lamp, clearcoat {factor}: {got} = {:.6} × uncoated", got.x / bare.x);
        assert!((got - want).abs().max_element() <= 1e-6 * want.max_element(), "{factor}: {got} vs {want}");
    }
}

/// Light sampling sees the coat over a lamp too: a floor lit by a lamp (clearcoat 1) from
/// an oblique angle receives ∫ Le·(1 − F(cos θ_lamp))·f·cos θ·cos θ_lamp/r² dA (quadrature over
/// the lamp), with next-event estimation and the floor's BRDF sampling weighed by MIS.
#[test]
fn a_coated_lamp_lights_through_its_coat() {
    let lamp = Material { emissive: Vec3::splat(5.0), clearcoat: Some(coat(1.0, 0.2)), ..Default::default() };
    let floor = Material {
        spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.5))),
        roughness: 1.0,
        ..Default::default()
    };
    let (c, h) = (Vec3::new(0.0, 1.0, 0.0), 0.4);
    let scene = scene_with(
        vec![quad(c, -Vec3::Y, h, 0), quad(Vec3::ZERO, Vec3::Y, 10.0, 1)],
        vec![lamp, floor],
        vec![],
    );
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.5);
    let p = Vec3::new(1.6, 0.0, 0.3);
    let o = p + Vec3::new(0.3, 0.5, 0.1);
    let wo = (o - p).normalize();
    let brdf = Brdf::new(Vec4::splat(0.5), 0.0, 1.0);
    let frame = crate::sampling::Frame::from_normal(Vec3::Y);
    let n = 400;
    let (mut e, mut e_bare) = (0.0f64, 0.0f64);
    for i in 0..n {
        for j in 0..n {
            let q = c + Vec3::new(
                -h + 2.0 * h * (i as f32 + 0.5) / n as f32,
                0.0,
                -h + 2.0 * h * (j as f32 + 0.5) / n as f32,
            );
            let v = q - p;
            let r2 = v.length_squared();
            let wi = v / r2.sqrt();
            let f = brdf.eval(frame.to_local(wo), frame.to_local(wi)).x;
            let da = (2.0 * h as f64 / n as f64).powi(2);
            let g = f64::from(f * wi.y * wi.y / r2) * da;
            e += g * (1.0 - coat_weight(1.0, f64::from(wi.y)));
            e_bare += g;
        }
    }
    let le = world.units.rgb(Vec3::splat(5.0), &GreyOnly, wl.0);
    let want = le * e as f32;
    let (m, se) = estimate(20_000, |rng| integ.radiance(o, (p - o).normalize(), &wl, rng));
    println!(
        "floor under a coated lamp: {:.5} ± {:.5} of Le, quadrature {:.5} (uncoated {:.5})",
        m.x / le.x,
        se.x / le.x,
        e,
        e_bare
    );
    assert_within(m, se, want, "floor under a coated lamp");
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// The coated vertex samples what it evaluates: over the sphere (quadrature) its pdf
/// integrates to the fraction of samples it returns, the mean of its sample weights f·|cos|/pdf
/// is the quadrature's ∫ f·|cos|, and every sample carries exactly the value and pdf
/// `Vertex::eval` gives its direction (what MIS weighs it with). Opaque and see-through bases
/// (rough and thin glass), coats along and tilted from the shading normal.
#[test]
fn the_coated_vertex_samples_its_value_and_pdf() {
    use crate::dielectric::Dielectric;
    let frame = Frame::from_normal(Vec3::Z);
    let glass = |thin: bool| Dielectric {
        tint: Vec4::new(0.9, 0.7, 0.5, 1.0),
        alpha: 0.3,
        eta: 1.5,
        thin,
        film: None,
    };
    // (name, base BRDF, see-through part and its weight, coat roughness, coat normal)
    type Case = (&'static str, Brdf, Option<(Dielectric, f32)>, f32, Vec3);
    let cases: [Case; 4] = [
        ("dielectric", Brdf::new(Vec4::new(0.8, 0.3, 0.1, 0.5), 0.0, 0.5), None, 0.4, Vec3::Z),
        (
            "metal, tilted coat",
            Brdf::new(Vec4::new(0.9, 0.6, 0.3, 0.8), 1.0, 0.3),
            None,
            0.5,
            Vec3::new(0.25, 0.1, 1.0),
        ),
        ("glass", Brdf::new(Vec4::ONE, 0.0, 0.3), Some((glass(false), 0.8)), 0.4, Vec3::new(-0.2, 0.0, 1.0)),
        ("thin glass", Brdf::new(Vec4::ONE, 0.0, 0.3), Some((glass(true), 1.0)), 0.6, Vec3::Z),
    ];
    for (name, brdf, glass, coat_roughness, nc) in cases {
        for theta in [0.3f32, 1.1] {
            let wo = dir(theta, 0.4);
            let nc = nc.normalize();
            let a = brdf.albedo_estimate(wo.z);
            let c = Coat::new(0.9, coat_roughness, nc, wo)
                .balanced(glass.map_or(a, |(_, wt)| a * (1.0 - wt) + wt));
            let vtx = Vertex::Surface { brdf, frame, ng: Vec3::Z, glass, coat: Some(c) };
            let (ip, if_) = sphere_integrals(&vtx, wo);
            let mut rng = Sampler::new(7, 1);
            let n = 200_000;
            let (mut est, mut returned) = (Vec4::ZERO, 0);
            for _ in 0..n {
                let Some(x) = vtx.sample_coated(wo, &mut rng) else { continue };
                returned += 1;
                est += x.weight;
                let (f, p) = vtx.eval(wo, x.wi);
                assert_eq!((x.pdf, x.weight), (p, f / p), "{name}: a sample off its own value and pdf");
                assert_eq!(x.crossed, x.wi.z < 0.0);
            }
            est /= n as f32;
            let frac = returned as f64 / n as f64;
            let what = format!("{name} θ {theta} (coat sampled with p = {:.3}, w = {:.3})", c.p, c.weight);
            println!("{what}: ∫pdf {ip:.4} vs returned {frac:.4}; ∫f·cos {if_} vs sampled {est}");
            assert!(ip <= 1.0 + 2e-3 && (ip - frac).abs() < 0.01, "{what}: ∫pdf = {ip}, sampled {frac}");
            assert!((est - if_).abs().max_element() < 0.01, "{what}: {est} vs {if_}");
        }
    }
}

/// A smooth coat's normal map moves the coat's mirror reflection and nothing else; the base's
/// normal map moves the base and not the coat. A floor (rough white-ish base, clearcoat 1,
/// roughness 0) seen at 30° from its normal, a lamp where the mirror about a normal tilted 20°
/// (by a one-texel normal map) sends the view, 40° from the plain mirror, direct light only.
/// With the coat's map the pixel is (1 − w)·B + w·Le, B the base lit about the geometric
/// normal (quadrature over the lamp) and w the weight at the tilted normal; without maps
/// (1 − w₀)·B; with the same map as the base's normal map instead, (1 − w₀)·B_tilted, no
/// reflection: the coat keeps the interpolated normal.
#[test]
fn the_coats_normal_map_moves_the_coat_alone() {
    let beta = 20f32.to_radians();
    let v = Vec3::new(beta.sin(), 0.0, beta.cos());
    let texel = v.to_array().map(|x| ((x + 1.0) * 0.5 * 255.0).round() as u8);
    let texture = Texture {
        sampler: Default::default(),
        name: "tilt".into(),
        width: 1,
        height: 1,
        rgba8: vec![texel[0], texel[1], texel[2], 255],
        srgb: false,
    };
    // Where the tracer's decoding puts it: the floor's tangent frame is (x, −z, y).
    let t = texel.map(|b| 2.0 * f32::from(b) / 255.0 - 1.0);
    let tilted = (Vec3::X * t[0] - Vec3::Z * t[1] + Vec3::Y * t[2]).normalize();
    let map = Some(TextureRef { index: 0, tex_coord: 0, transform: None });
    let theta = 30f32.to_radians();
    let wo = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    let r = 2.0 * wo.dot(tilted) * tilted - wo;
    let (lamp_c, h) = (r * 2.0, 0.5);
    let mut floor = quad(Vec3::ZERO, Vec3::Y, 5.0, 0);
    let fr = Frame::from_normal(Vec3::Y);
    assert!((fr.t - Vec3::X).length() < 1e-6 && (fr.b + Vec3::Z).length() < 1e-6);
    floor.tangents = vec![fr.t.extend(1.0); 4];
    let base = Brdf::new(Vec4::splat(0.5), 0.0, 0.8);
    // B about normal `n`: ∫ f·cos θ_n·cos θ_lamp/r² dA over the lamp, per unit Le.
    let lit = |n: Vec3| {
        let f = Frame::from_normal(n);
        let lf = Frame::from_normal(-r);
        let k = 300;
        let mut b = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let (a, c) =
                    ((i as f32 + 0.5) / k as f32 * 2.0 - 1.0, (j as f32 + 0.5) / k as f32 * 2.0 - 1.0);
                let q = lamp_c + lf.t * (a * h) + lf.b * (c * h);
                let d2 = q.length_squared();
                let wi = q / d2.sqrt();
                let li = f.to_local(wi);
                if li.z <= 0.0 || wi.y <= 0.0 {
                    continue;
                }
                let g = base.eval(f.to_local(wo), li).x * li.z * r.dot(wi) / d2;
                b += f64::from(g) * f64::from(2.0 * h / k as f32).powi(2);
            }
        }
        b as f32
    };
    let (b_geo, b_tilt) = (lit(Vec3::Y), lit(tilted));
    let (w_tilt, w_geo) =
        (coat_weight(1.0, f64::from(wo.dot(tilted))) as f32, coat_weight(1.0, f64::from(wo.y)) as f32);
    let render = |base_map: bool, coat_map: bool| {
        let floor_mat = Material {
            spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.5))),
            roughness: 0.8,
            normal_texture: if base_map { map } else { None },
            clearcoat: Some(Clearcoat {
                normal_texture: if coat_map { map } else { None },
                ..coat(1.0, 0.0)
            }),
            ..Default::default()
        };
        let lamp = Material { emissive: Vec3::ONE, ..Default::default() };
        let mut scene =
            scene_with(vec![floor.clone(), quad(lamp_c, -r, h, 1)], vec![floor_mat, lamp], vec![]);
        scene.textures = vec![texture.clone()];
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.45);
        let le = world.units.rgb(Vec3::ONE, &GreyOnly, wl.0);
        let (m, se) = estimate(40_000, |rng| integ.radiance(wo * 1.5, -wo, &wl, rng));
        (m / le, se / le)
    };
    let cases = [
        ("coat map", false, true, (1.0 - w_tilt) * b_geo + w_tilt, (1.0 - w_tilt) * b_tilt + w_tilt),
        ("no map", false, false, (1.0 - w_geo) * b_geo, (1.0 - w_geo) * b_tilt),
        ("base map", true, false, (1.0 - w_geo) * b_tilt, (1.0 - w_tilt) * b_tilt + w_tilt),
    ];
    for (name, base_map, coat_map, want, wrong) in cases {
        let (m, se) = render(base_map, coat_map);
        println!(
            "{name}: {:.5} ± {:.5} (want {want:.5}; B {b_geo:.5} about the normal, {b_tilt:.5} about the map; \
             w {w_geo:.4} / {w_tilt:.4})",
            m.x, se.x
        );
        assert_within(m, se, Vec4::splat(want), name);
        // The alternative (base and coat sharing one normal) is far outside the noise.
        assert!(
            ((m - Vec4::splat(wrong)).abs() - se * 10.0).min_element() > 0.0,
            "{name}: also near {wrong}"
        );
    }
}

/// `--lambert`, the Mitsuba comparison's mode, replaces the whole glTF material by Lambert and
/// drops the coat with the rest (as it drops thin films and transmission), its dimming of
/// emission included: a coated scene renders exactly as the uncoated one there, so the Mitsuba
/// export, which writes the base alone, stays like for like. Without it the coat shows.
#[test]
fn lambert_mode_has_no_coat() {
    use crate::render::{Settings, render};
    let image = |c: Option<Clearcoat>, lambert: bool| {
        let materials = vec![
            Material { clearcoat: c.clone(), ..Default::default() },
            Material { emissive: Vec3::splat(2.0), clearcoat: c, ..Default::default() },
        ];
        let meshes = vec![sphere(Vec3::ZERO, 1.0, 16, 0), quad(Vec3::new(0.0, 0.0, 2.0), Vec3::Z, 0.3, 1)];
        let mut scene =
            with_env(scene_with(meshes, materials, vec![]), scene::Environment::uniform(Vec3::splat(0.5)));
        scene.camera = scene::Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.8);
        let st = Settings { lambert, seed: 1, ..Settings::new(12, 12, 4).unwrap() };
        render(&scene, &GreyOnly, &st, &std::sync::atomic::AtomicBool::new(false), &|_| {}).unwrap().xyz
    };
    let coated = Some(coat(1.0, 0.0));
    assert!(image(coated.clone(), true) == image(None, true));
    assert!(image(coated, false) != image(None, false));
}

/// ∫ pdf dω and ∫ f dω over the whole sphere of incoming directions at a vertex seen from `wo`,
/// by the midpoint rule on 1200 × 400 cells in (cos θ, φ): what its sampling should return
/// (the fraction of samples kept, and their mean weight).
pub(super) fn sphere_integrals(vtx: &Vertex, wo: Vec3) -> (f64, Vec4) {
    let (nt, np) = (1200, 400);
    let (mut ip, mut if_) = (0.0f64, Vec4::ZERO);
    for i in 0..nt {
        let z = -1.0 + 2.0 * (i as f32 + 0.5) / nt as f32;
        let s = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..np {
            let phi = 2.0 * std::f32::consts::PI * (j as f32 + 0.5) / np as f32;
            let (f, p) = vtx.eval(wo, Vec3::new(s * phi.cos(), s * phi.sin(), z));
            ip += f64::from(p);
            if_ += f;
        }
    }
    let dw = (2.0 / nt as f32) * (2.0 * std::f32::consts::PI / np as f32);
    (ip * f64::from(dw), if_ * dw)
}
