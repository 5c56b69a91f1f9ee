//! The RGB medium's hooks (issue 18) on the GPU against a CPU evaluation of the same model:
//! a white Lambertian wall 3 units away, lit by a point light in the medium, per pixel and per
//! wavelength (N = 1 at a chosen λ, so each pixel is one wavelength's radiance times a known
//! vector). The medium's σ_s(λ), σ_t(λ) come from `RgbMedium::spectra`, the path tracer's
//! function; the medium starts at the eye, as the path tracer's camera rays do (issue 28: the
//! near plane, 0.05 in front, clips surfaces only). The CPU
//! side computes the transmittances from the pixel's geometry and the
//! in-scattering by the same equiangular steps in f64 (and, for the discretisation error,
//! by a converged quadrature of the exact integral).

mod common;

use color::upsample::medium::Attenuation;
use color::{Quadrature, Spectrum, WavelengthRange};
use common::{rel_err, render_custom as render};
use glam::{DVec3, Mat4, Vec2, Vec3, Vec4};
use render::passes::rgb_medium;
use render::{CustomShader, Mode, RenderSettings, SpectralSetup};
use scene::medium::RgbMedium;
use scene::{Camera, Light, Material, Mesh, Scene};

const W: u32 = 24;
const H: u32 = 16;
/// The wall's distance along −z (scene units = metres).
const WALL: f32 = 3.0;
const INTENSITY: f32 = 5.0;

fn light_pos() -> Vec3 {
    Vec3::new(0.8, 0.4, -1.2)
}

fn wall_scene() -> Scene {
    let s = 20.0;
    let mut camera = Camera::look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 1.0);
    camera.yfov = 0.8;
    camera.znear = 0.05;
    camera.zfar = 100.0;
    let mut scene = Scene::empty("test:rgb-medium-wall", camera);
    // Facing +z, at z = −WALL.
    scene.meshes.push(Mesh::quad(Vec3::new(-s, -s, -WALL), Vec3::X * 2.0 * s, Vec3::Y * 2.0 * s, 0));
    // The default material: white, rough, not metallic.
    scene.materials.push(Material { name: "white".into(), ..Default::default() });
    scene.lights.push(Light::point("lamp", light_pos(), INTENSITY));
    scene
}

/// A renderer holding `scene` at the tests' frame size.
fn wall_renderer(scene: &Scene) -> render::Renderer {
    let mut r = common::renderer();
    r.set_scene(scene).unwrap();
    r.resize(W, H).unwrap();
    r
}

/// Unit view direction through pixel (px, py) and the distance to the wall.
fn pixel_ray(camera: &Camera, px: u32, py: u32) -> (DVec3, f64) {
    let proj = Mat4::perspective_rh(camera.yfov, W as f32 / H as f32, camera.znear, camera.zfar);
    let inv = (proj * camera.transform.inverse()).inverse();
    let ndc = Vec2::new(2.0 * (px as f32 + 0.5) / W as f32 - 1.0, 1.0 - 2.0 * (py as f32 + 0.5) / H as f32);
    let far = inv * Vec4::new(ndc.x, ndc.y, 1.0, 1.0);
    let dir = (far.truncate() / far.w - camera.position()).normalize().as_dvec3();
    (dir, WALL as f64 / -dir.z)
}

fn hg(g: f64, cos_t: f64) -> f64 {
    let den = 1.0 + g * g - 2.0 * g * cos_t;
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * den * den.sqrt())
}

/// ∫₀^len hg(θ)·e^{−σ_t·(t + r)}/r² dt for a unit-intensity point light at `light`, ray from
/// the origin along `w`, by `m` equiangular midpoint steps (the GPU's rule).
fn in_scatter(w: DVec3, len: f64, light: DVec3, g: f64, sigma_t: f64, m: u32) -> f64 {
    let t0 = light.dot(w);
    let h = (light - w * t0).length().max(1e-4);
    let (ta, tb) = ((-t0).atan2(h), (len - t0).atan2(h));
    let dth = (tb - ta) / m as f64;
    (0..m)
        .map(|k| {
            let th = ta + (k as f64 + 0.5) * dth;
            let (t, r) = (t0 + h * th.tan(), h / th.cos());
            let wi = (light - w * t) / r;
            hg(g, wi.dot(w)) * (-sigma_t * (t + r)).exp() * dth / h
        })
        .sum()
}

fn medium(absorption: [f64; 3], scattering: [f64; 3], method: Attenuation) -> RgbMedium {
    RgbMedium::new(absorption, scattering, 0.4, 1.0, method).unwrap()
}

/// Spectral or naive mode at the single wavelength `lambda` (a 1 nm range, midpoint rule).
fn one_wavelength(mode: Mode, lambda: f64) -> RenderSettings {
    RenderSettings {
        mode,
        quadrature: Quadrature::Midpoint,
        wavelengths: 1,
        range: WavelengthRange::new(lambda - 0.5, lambda + 0.5).unwrap(),
        shadows: false,
        lambert: true,
        ..Default::default()
    }
}

/// Every pixel, every mode's wavelengths: wet = dry·e^{−σ_t·(d − near + r_light)} + E·unit·σ_s·∫…,
/// to 1e-3 of the pixel (the budget of the f16 HDR target, as for the underwater hooks).
#[test]
fn rgb_medium_hooks_match_the_cpu_model_to_1e_3() {
    let scene = wall_scene();
    let mut r = wall_renderer(&scene);
    let table = common::table();
    let light = light_pos().as_dvec3();
    let g = 0.4;
    let (mut worst, mut n) = (0.0f64, 0usize);
    let mut check = |got: [f64; 3], want: [f64; 3], what: &dyn Fn() -> String| {
        assert!(got.iter().all(|v| v.is_finite()), "{}: NaN/∞ pixel {got:?}", what());
        let e = rel_err(got, want);
        assert!(e <= 1e-3, "{}: gpu {got:?} cpu {want:?} (relative error {e:.2e})", what());
        worst = worst.max(e);
        n += 1;
    };
    let media = [
        ("absorbing, unbounded", medium([0.3, 0.15, 0.05], [0.0; 3], Attenuation::Unbounded), 0),
        ("scattering, unbounded", medium([0.3, 0.15, 0.05], [0.2, 0.25, 0.3], Attenuation::Unbounded), 16),
        ("scattering, box", medium([0.05, 0.1, 0.4], [0.3, 0.2, 0.1], Attenuation::Box), 24),
    ];
    for (name, m, steps) in &media {
        let shader =
            rgb_medium::shader(m, &table, &rgb_medium::Options { steps: *steps, multiple: false }).unwrap();
        let (sa, ss) = m.spectra(&table).unwrap();
        let boxed = RgbMedium { upsampling: Attenuation::Box, ..m.clone() };
        let (sa_box, ss_box) = boxed.spectra(&table).unwrap();
        for (mode, lambda) in [
            (Mode::Spectral, 440.0),
            (Mode::Spectral, 530.0),
            (Mode::Spectral, 610.0),
            (Mode::Spectral, 680.0),
            (Mode::Naive, 450.0),
            (Mode::Naive, 620.0),
        ] {
            let settings = one_wavelength(mode, lambda);
            let dry = render(&mut r, &scene, &settings, CustomShader::default());
            let wet = render(&mut r, &scene, &settings, shader.clone());
            let (a, s): (&Spectrum, &Spectrum) =
                if mode == Mode::Naive { (&sa_box, &ss_box) } else { (&sa, &ss) };
            let (sig_s, sig_t) = (s.eval(lambda), a.eval(lambda) + s.eval(lambda));
            let setup = SpectralSetup::new(&settings).unwrap();
            let unit = setup.xyz_to_rgb * DVec3::from(setup.integrator.integrate_samples(&[1.0]));
            let e = setup.light_samples(&scene.lights[0].emission, mode, &table).unwrap()[0];
            for py in 0..H {
                for px in 0..W {
                    let (w, d) = pixel_ray(&scene.camera, px, py);
                    let hit = w * d;
                    let t = (-sig_t * (d + (light - hit).length())).exp();
                    let ls = if *steps > 0 { sig_s * in_scatter(w, d, light, g, sig_t, *steps) } else { 0.0 };
                    let i = (py * W + px) as usize;
                    let want = DVec3::from(common::rgb_of(&dry[i])) * t + unit * (e * ls);
                    let what = || format!("{name}, {} λ={lambda} pixel ({px},{py})", mode.name());
                    check(common::rgb_of(&wet[i]), want.to_array(), &what);
                }
            }
        }
        // RGB mode: the RGB coefficients per channel; the light's colour is its rgb × intensity.
        let settings =
            RenderSettings { mode: Mode::Rgb, shadows: false, lambert: true, ..Default::default() };
        let dry = render(&mut r, &scene, &settings, CustomShader::default());
        let wet = render(&mut r, &scene, &settings, shader.clone());
        let sig_t = m.extinction();
        for py in 0..H {
            for px in 0..W {
                let (w, d) = pixel_ray(&scene.camera, px, py);
                let path = d + (light - w * d).length();
                let i = (py * W + px) as usize;
                let dry_rgb = common::rgb_of(&dry[i]);
                let want: [f64; 3] = std::array::from_fn(|c| {
                    let ls = if *steps > 0 {
                        m.scattering[c] * in_scatter(w, d, light, g, sig_t[c], *steps) * INTENSITY as f64
                    } else {
                        0.0
                    };
                    dry_rgb[c] * (-sig_t[c] * path).exp() + ls
                });
                let what = || format!("{name}, rgb pixel ({px},{py})");
                check(common::rgb_of(&wet[i]), want, &what);
            }
        }
    }
    eprintln!("RGB medium GPU vs CPU: worst relative error {worst:.2e} over {n} pixel-wavelengths");
    assert!(n > 3000, "{n}");
}

/// How far the equiangular steps are from the exact integral for this scene (figures for
/// docs/rgb-media.md): relative error of the in-scattering over every pixel, against 20,000
/// steps, which must agree with 40,000 to 1e-6.
#[test]
fn equiangular_steps_against_the_converged_integral() {
    let scene = wall_scene();
    let light = light_pos().as_dvec3();
    for sigma_t in [0.2, 0.5, 2.0] {
        let mut worst = [0.0f64; 3];
        for py in 0..H {
            for px in 0..W {
                let (w, d) = pixel_ray(&scene.camera, px, py);
                let exact = in_scatter(w, d, light, 0.4, sigma_t, 20_000);
                let finer = in_scatter(w, d, light, 0.4, sigma_t, 40_000);
                assert!((exact - finer).abs() <= 1e-6 * exact, "{exact} {finer}");
                for (i, m) in [8, 16, 32].into_iter().enumerate() {
                    let e = (in_scatter(w, d, light, 0.4, sigma_t, m) - exact).abs() / exact;
                    worst[i] = worst[i].max(e);
                }
            }
        }
        eprintln!(
            "σ_t {sigma_t}: worst relative error of 8 / 16 / 32 steps: {:.1e} / {:.1e} / {:.1e}",
            worst[0], worst[1], worst[2]
        );
        assert!(worst[1] < 1e-2, "16 steps: {worst:?}");
    }
}

/// K(x) of the once-collided fluence, the fit the shader uses (docs/rgb-media.md).
fn k_fit(x: f64) -> f64 {
    std::f64::consts::PI.powi(2) / 4.0 * (-x).exp() * (1.0 + x * (4.25339 + 0.713143 * x)).powf(-0.418368)
}

/// ν with α·atanh(ν) = ν (0 < α < 1), by bisection.
fn case_nu(alpha: f64) -> f64 {
    let (mut lo, mut hi) = (1e-12f64, 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if alpha * mid.atanh() > mid { hi = mid } else { lo = mid }
    }
    0.5 * (lo + hi)
}

/// The multiple-scattering model of docs/rgb-media.md for one wavelength or channel, per unit
/// intensity: (in-scattering along the view by the GPU's equiangular steps, single scattering
/// with the light leg through σ_t' included; irradiance on the wall at `hit`).
#[allow(clippy::too_many_arguments)] // the model's own inputs, named as in the docs
fn multiple_cpu(
    w: DVec3,
    len: f64,
    light: DVec3,
    hit: DVec3,
    g: f64,
    ss: f64,
    st: f64,
    m: u32,
) -> (f64, f64) {
    let sa = st - ss;
    let (ssr, str_) = (ss * (1.0 - g), sa + ss * (1.0 - g));
    let nu = case_nu(ssr / str_);
    let kappa = nu * str_;
    let c2 = (ssr / str_).powi(2) * kappa * kappa / sa;
    let phi = |r: f64| (ssr * k_fit(str_ * r) + c2 * (-kappa * r).exp()) / r;
    let t0 = light.dot(w);
    let h = (light - w * t0).length().max(1e-4);
    let (ta, tb) = ((-t0).atan2(h), (len - t0).atan2(h));
    let dth = (tb - ta) / m as f64;
    let view: f64 = (0..m)
        .map(|k| {
            let th = ta + (k as f64 + 0.5) * dth;
            let (t, r) = (t0 + h * th.tan(), h / th.cos());
            let wi = (light - w * t) / r;
            let single = ss * hg(g, wi.dot(w)) * (-st * t - (st - g * ss) * r).exp() * dth / h;
            let dt = r * r * dth / h;
            single + ssr / (4.0 * std::f64::consts::PI) * phi(r) * dt * (-st * t).exp()
        })
        .sum();
    let to_l = light - hit;
    let r = to_l.length();
    let c = to_l.z / r;
    let flux = (1.0 / (3.0 * str_) * (kappa + 1.0 / r)).min(1.0);
    (view, phi(r) * (0.25 + 0.5 * c * flux).max(0.0))
}

/// The multiple-scattering term on the GPU against the CPU model, every pixel, spectral at
/// two wavelengths and rgb per channel: wet = dry·e^{−σ_t·(d − near) − σ_t'·r_light} + I·view
/// + (1/π)·E·e^{−σ_t·(d − near)} (white Lambertian wall), to 1e-3 of the pixel.
#[test]
fn rgb_medium_multiple_scattering_matches_the_cpu_model_to_1e_3() {
    let scene = wall_scene();
    let mut r = wall_renderer(&scene);
    let table = common::table();
    let light = light_pos().as_dvec3();
    let g = 0.4;
    let m = medium([0.3, 0.15, 0.05], [0.2, 0.25, 0.3], Attenuation::Unbounded);
    let steps = 16;
    let shader = rgb_medium::shader(&m, &table, &rgb_medium::Options { steps, multiple: true }).unwrap();
    let (sa, ss) = m.spectra(&table).unwrap();
    let (mut worst, mut n, mut ms_share) = (0.0f64, 0usize, 0.0f64);
    let inv_pi = std::f64::consts::FRAC_1_PI;
    let mut check = |got: [f64; 3], want: [f64; 3], what: &dyn Fn() -> String| {
        assert!(got.iter().all(|v| v.is_finite()), "{}: NaN/∞ pixel {got:?}", what());
        let e = rel_err(got, want);
        assert!(e <= 1e-3, "{}: gpu {got:?} cpu {want:?} (relative error {e:.2e})", what());
        worst = worst.max(e);
        n += 1;
    };
    for lambda in [450.0, 620.0] {
        let settings = one_wavelength(Mode::Spectral, lambda);
        let dry = render(&mut r, &scene, &settings, CustomShader::default());
        let wet = render(&mut r, &scene, &settings, shader.clone());
        let (sig_s, sig_t) = (ss.eval(lambda), sa.eval(lambda) + ss.eval(lambda));
        let setup = SpectralSetup::new(&settings).unwrap();
        let unit = setup.xyz_to_rgb * DVec3::from(setup.integrator.integrate_samples(&[1.0]));
        let e = setup.light_samples(&scene.lights[0].emission, Mode::Spectral, &table).unwrap()[0];
        for py in 0..H {
            for px in 0..W {
                let (w, d) = pixel_ray(&scene.camera, px, py);
                let hit = w * d;
                let view_t = (-sig_t * d).exp();
                let t = view_t * (-(sig_t - g * sig_s) * (light - hit).length()).exp();
                let (view, irr) = multiple_cpu(w, d, light, hit, g, sig_s, sig_t, steps);
                let i = (py * W + px) as usize;
                let want =
                    DVec3::from(common::rgb_of(&dry[i])) * t + unit * (e * (view + inv_pi * irr * view_t));
                ms_share = ms_share.max(inv_pi * irr * view_t * e * unit.y / want.y);
                check(common::rgb_of(&wet[i]), want.to_array(), &|| {
                    format!("spectral λ={lambda} pixel ({px},{py})")
                });
            }
        }
    }
    let settings = RenderSettings { mode: Mode::Rgb, shadows: false, lambert: true, ..Default::default() };
    let dry = render(&mut r, &scene, &settings, CustomShader::default());
    let wet = render(&mut r, &scene, &settings, shader.clone());
    let sig_t = m.extinction();
    for py in 0..H {
        for px in 0..W {
            let (w, d) = pixel_ray(&scene.camera, px, py);
            let hit = w * d;
            let i = (py * W + px) as usize;
            let dry_rgb = common::rgb_of(&dry[i]);
            let want: [f64; 3] = std::array::from_fn(|c| {
                let (s, st) = (m.scattering[c], sig_t[c]);
                let view_t = (-st * d).exp();
                let t = view_t * (-(st - g * s) * (light - hit).length()).exp();
                let (view, irr) = multiple_cpu(w, d, light, hit, g, s, st, steps);
                dry_rgb[c] * t + INTENSITY as f64 * (view + inv_pi * irr * view_t)
            });
            check(common::rgb_of(&wet[i]), want, &|| format!("rgb pixel ({px},{py})"));
        }
    }
    eprintln!(
        "RGB medium multiple scattering GPU vs CPU: worst relative error {worst:.2e} over {n} pixel-wavelengths \
         (the surface term up to {:.0} % of a pixel)",
        100.0 * ms_share
    );
    assert!(n > 1000 && ms_share > 0.05, "{n} {ms_share}");
}

/// The environment is infinitely far: in a medium without end none of its light reaches a
/// surface wherever σ_t > 0, as in the path tracer. The wall lit by a uniform environment only:
/// in rgb mode a medium that is clear in blue keeps blue exactly (the dry render) and takes
/// red and green to zero; in spectral and naive modes a medium that absorbs at every wavelength
/// leaves the wall black. Before the environment-transmittance hooks the wall kept the
/// environment's light, attenuated only along the view.
/// The same through glass: the RGB mode's see-through layer shows, where a refracted ray
/// leaves the screen, the environment in its direction — which in a medium without end must
/// pass the medium's hooks too (a glass ball under a uniform sky lit some pixels at full
/// strength: the Khronos AttenuationTest under `--rgb-medium` had four such pixels, up to 0.23).
#[test]
fn the_environment_does_not_reach_through_glass_into_a_medium_without_end() {
    let mut camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0);
    camera.yfov = 0.9;
    let mut scene = Scene::empty("test:rgb-medium-glass", camera);
    scene.meshes.push(Mesh::uv_sphere(Vec3::ZERO, 1.0, 24, 48, 0));
    scene.materials.push(Material {
        name: "glass".into(),
        base_color: Vec4::ONE,
        roughness: 0.0,
        ior: 1.5,
        transmission: Some(scene::transmission::Transmission {
            factor: 1.0,
            texture: None,
            volume: Some(scene::transmission::Volume {
                thickness: 2.0,
                thickness_texture: None,
                attenuation_color: [1.0; 3],
                attenuation_distance: f32::INFINITY,
            }),
            dispersion: 0.0,
        }),
        ..Default::default()
    });
    scene.environment = Some(scene::Environment::uniform(Vec3::ONE));
    let mut r = wall_renderer(&scene);
    let table = common::table();
    let rgb = RenderSettings { mode: Mode::Rgb, shadows: false, ..Default::default() };
    let dry = render(&mut r, &scene, &rgb, CustomShader::default());
    let lit = dry.iter().filter(|p| p[0] > 0.1).count();
    assert!(lit > 100, "the dry ball shows the sky through it ({lit} pixels)");
    let absorbing = medium([0.3, 0.15, 0.05], [0.0; 3], Attenuation::Unbounded);
    let wet = render(
        &mut r,
        &scene,
        &rgb,
        rgb_medium::shader(&absorbing, &table, &rgb_medium::Options::default()).unwrap(),
    );
    let worst = wet.iter().map(|p| p[0].max(p[1]).max(p[2])).fold(0.0f32, f32::max);
    assert!(worst < 1e-6, "light through the glass from an environment the medium absorbs: {worst}");
}

#[test]
fn the_environment_does_not_reach_into_a_medium_without_end() {
    let mut scene = wall_scene();
    scene.lights.clear();
    scene.environment = Some(scene::Environment::uniform(Vec3::ONE));
    let mut r = wall_renderer(&scene);
    let table = common::table();
    let opts = rgb_medium::Options::default();
    let rgb = RenderSettings { mode: Mode::Rgb, shadows: false, lambert: true, ..Default::default() };
    let dry = render(&mut r, &scene, &rgb, CustomShader::default());
    let clear_blue = medium([0.3, 0.15, 0.0], [0.0; 3], Attenuation::Unbounded);
    let wet = render(&mut r, &scene, &rgb, rgb_medium::shader(&clear_blue, &table, &opts).unwrap());
    for (i, (w, d)) in wet.iter().zip(&dry).enumerate() {
        assert!(d[2] > 0.1, "pixel {i}: the dry wall is lit by the environment ({d:?})");
        assert!(w[0].abs() < 1e-6 && w[1].abs() < 1e-6, "pixel {i}: red/green through the medium {w:?}");
        assert!((w[2] - d[2]).abs() <= 1e-3 * d[2], "pixel {i}: blue {} vs dry {}", w[2], d[2]);
    }
    let absorbing = medium([0.3, 0.15, 0.05], [0.0; 3], Attenuation::Unbounded);
    for mode in [Mode::Spectral, Mode::Naive] {
        let s = RenderSettings { mode, shadows: false, lambert: true, ..Default::default() };
        let wet = render(&mut r, &scene, &s, rgb_medium::shader(&absorbing, &table, &opts).unwrap());
        for (i, w) in wet.iter().enumerate() {
            assert!(w[..3].iter().all(|v| v.abs() < 1e-6), "{mode:?} pixel {i}: {w:?}");
        }
    }
}
