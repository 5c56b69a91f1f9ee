//! Independent check of the light-field table (`scene::water::light_field`) against the path
//! tracer (`truth`): the radiance a camera sees in an empty water column, at a few depths,
//! directions and wavelengths, computed
//!
//! - (truth) by `truth::integrator::Integrator::radiance` in the same medium `spectra truth`
//!   builds (`truth::water::medium`: a slab from the surface to 5000 m below the camera, Fresnel
//!   surface, uniform sky through Snell's window), with the built-in `underwater` scene's sun and
//!   sky and no geometry but a 2 cm black quad 4 km down (the tracer wants one triangle; it
//!   subtends 1e-11 sr); every path is independent, so the standard error is the sample one;
//! - (table) from the table the real-time pass uses (`render::passes::underwater::
//!   light_field_table`, default options): `∫₀ᵈ J(z0 − t·ω_y, ω)·e^{−c·t} dt` in closed form per
//!   depth segment (`light_field::ray_integral`), plus the single scattering of the unscattered
//!   sun beam the table leaves out (`single::beam`), plus, for rays that reach the surface, the
//!   sky through Snell's window and the Fresnel-reflected (totally reflected outside the window)
//!   downward radiance just below the surface, itself from the table, all attenuated by e^{−c·d}.
//!
//! Directions are on the table's nodes (the nearest elevation node, sun azimuth 0° or 180°), so the
//! table's angular interpolation plays no part; wavelengths are on its 20 nm nodes.
//!
//! `cargo run --release -p spectra --example lf_column -- --out lf.csv` (options: `--types`,
//! `--depths`, `--paths`, `--photons-hi`, `--seed`, `--truth-csv`, `--z-max`);
//! `tools/lf_column_plot.py` plots the CSV.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Parser;
use glam::{DVec3, Vec3, Vec4};
use render::passes::underwater::{self, Options};
use scene::water::fresnel::{mean_transmittance, transmittance_up};
use scene::water::light_field::{self, LightFieldTable, ray_integral};
use scene::water::{WATER_IOR, WaterMedium, single};
use truth::World;
use truth::integrator::Integrator;
use truth::rng::Sampler;
use truth::spectral::Wavelengths;

#[derive(Parser)]
struct Args {
    /// Jerlov types, comma separated.
    #[arg(long, default_value = "IB,3C", value_delimiter = ',')]
    types: Vec<String>,
    /// Camera depths (m), comma separated.
    #[arg(long, default_value = "1,5,20", value_delimiter = ',')]
    depths: Vec<f64>,
    /// Path-traced paths per (type, depth, direction, group of four wavelengths).
    #[arg(long, default_value_t = 200_000)]
    paths: u64,
    /// Photons of a second, finer table (0: none), to tell the default table's own noise from
    /// a bias of the method.
    #[arg(long, default_value_t = 80_000)]
    photons_hi: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Take the truth (and its σ) from this earlier output instead of tracing it again (to
    /// compare another table against the same truth).
    #[arg(long)]
    truth_csv: Option<PathBuf>,
    /// Depth range of the tables (m) instead of the real-time pass's (`light_field_range`), to
    /// see what the depth discretisation does (the nodes scale with it).
    #[arg(long)]
    z_max: Option<f64>,
    /// Close the column with an unbounded grey Lambertian sea floor this far below the camera
    /// (m): the truth gets a 20 km floor quad, the tables are the floored ones (the real-time
    /// pass's table over a sea floor). Not with `--z-max`.
    #[arg(long, conflicts_with = "z_max")]
    floor_below: Option<f64>,
    /// The floor's albedo (with `--floor-below`).
    #[arg(long, default_value_t = 0.3)]
    floor_albedo: f64,
    /// Instead of radiance along directions: the diffuse irradiance (everything but the sun's
    /// unscattered beam) on small surfaces at the camera's depth facing up, sideways (towards,
    /// away from and across the sun) and down — the truth as π × the mean radiance over
    /// cosine-distributed directions around the normal, the table's
    /// `LightFieldTable::irradiance_at` (what the real-time pass lights surfaces with).
    #[arg(long)]
    irradiance: bool,
    /// Output CSV.
    #[arg(long)]
    out: PathBuf,
}

/// (name, angle of the normal from straight up in degrees, azimuth from the sun's in degrees).
const NORMALS: [(&str, f64, f64); 6] = [
    ("up", 0.0, 0.0),
    ("side_sun", 90.0, 0.0),
    ("side_across", 90.0, 90.0),
    ("side_anti", 90.0, 180.0),
    ("down45_sun", 135.0, 0.0),
    ("down", 180.0, 0.0),
];

/// Wavelength groups traced together (hero-wavelength MIS over the four), on the table's nodes.
const GROUPS: [[f32; 4]; 2] = [[400.0, 480.0, 560.0, 640.0], [440.0, 520.0, 600.0, 680.0]];

/// (name, angle from straight up in degrees — snapped to the nearest elevation node —, azimuth
/// from the sun's in degrees).
const DIRECTIONS: [(&str, f64, f64); 7] = [
    ("up", 0.0, 0.0),
    ("up60_anti", 60.0, 180.0),
    ("horiz_sun", 90.0, 0.0),
    ("horiz_anti", 90.0, 180.0),
    ("down45_sun", 135.0, 0.0),
    ("down45_anti", 135.0, 180.0),
    ("down", 180.0, 0.0),
];

fn main() -> Result<()> {
    let args = Args::parse();
    if args.paths == 0 {
        bail!("--paths must be > 0");
    }
    let reuse = args.truth_csv.as_deref().map(read_truth).transpose()?;
    let base = scene::builtin("underwater").context("the built-in underwater scene")?;
    let settings0 = base.water.clone().context("the underwater scene has water settings")?;
    let mut out = String::from(if args.irradiance {
        "type,depth_m,normal,theta_deg,phi_deg,lambda_nm,truth,truth_se,table,table_hi,ratio,ratio_se,ratio_hi\n"
    } else {
        "type,depth_m,direction,theta_deg,phi_deg,lambda_nm,truth,truth_se,table,table_hi,\
         table_diffuse,table_beam,table_surface,ratio,ratio_se,ratio_hi\n"
    });
    for ty in &args.types {
        for &depth in &args.depths {
            let settings =
                scene::WaterSettings { water_type: ty.clone(), depth: depth as f32, ..settings0.clone() };
            let mut medium =
                WaterMedium::from_settings(&settings).with_context(|| format!("water {ty} {depth} m"))?;
            if let Some(below) = args.floor_below {
                let r = args.floor_albedo;
                if !(below > 0.0 && (0.0..=1.0).contains(&r)) {
                    bail!("--floor-below must be > 0 and --floor-albedo in [0, 1]");
                }
                medium.floor = Some(scene::water::floor::SeaFloor {
                    below_camera: below,
                    rgb: [r; 3],
                    albedo: color::Spectrum::Constant(r),
                    extent: None,
                });
            }
            let mut sc = base.clone();
            sc.water = Some(settings);
            scene::sky::sync(&mut sc).map_err(anyhow::Error::msg)?;
            let cam = sc.camera.position();
            sc.meshes = vec![match args.floor_below {
                None => quad(cam - Vec3::Y * 4000.0, 0.01),
                Some(below) => quad(cam - Vec3::Y * below as f32, 10_000.0),
            }];
            // A plain grey material: the scene's first one is the sand, whose texture would
            // scale the floor's albedo.
            let r = if args.floor_below.is_some() { args.floor_albedo as f32 } else { 0.0 };
            sc.materials = vec![scene::Material {
                name: "floor".into(),
                base_color: glam::Vec4::new(r, r, r, 1.0),
                ..Default::default()
            }];
            let water = truth::water::medium(&medium, cam);
            let white = color::illuminant::by_name("D65")?;
            let up = truth::upsample::GreyOnly;
            let world = World::new(&sc, &up, &white, color::WavelengthRange::VISIBLE, Some(&water))?;
            // Lambertian, as the table's floor (the tiny black quad reflects nothing either way).
            let integ = Integrator { world: &world, direct_only: false, max_depth: 100_000, lambert: true };
            let sun = &world.delta_lights[0];
            let opts = Options::default();
            let solve = |o: &Options| -> Result<std::sync::Arc<LightFieldTable>> {
                Ok(match args.z_max {
                    None => underwater::light_field_table(&medium, o)?,
                    Some(z) => {
                        let key = scene::water::light_field::LightFieldKey {
                            z_max: z,
                            ..underwater::light_field_key(&medium, o)
                        };
                        let dir = color::upsample::cache::cache_dir().ok();
                        let cancel = std::sync::atomic::AtomicBool::new(false);
                        std::sync::Arc::new(LightFieldTable::cached(
                            &key,
                            dir.as_deref(),
                            &|_, _| {},
                            &cancel,
                        )?)
                    }
                })
            };
            let table = solve(&opts)?;
            let hi = (args.photons_hi > 0)
                .then(|| solve(&Options { photons: args.photons_hi, ..opts }))
                .transpose()?;
            let to_sun = medium.sun_dir_underwater().as_dvec3();
            let sun_h = DVec3::new(to_sun.x, 0.0, to_sun.z).normalize();
            let side = DVec3::Y.cross(sun_h);
            if args.irradiance {
                for (ni, &(name, th, ph)) in NORMALS.iter().enumerate() {
                    let (th, ph) = (th.to_radians(), ph.to_radians());
                    let n =
                        (sun_h * (th.sin() * ph.cos()) + DVec3::Y * th.cos() + side * (th.sin() * ph.sin()))
                            .normalize();
                    for (gi, group) in GROUPS.iter().enumerate() {
                        let seed = args.seed.wrapping_mul(1_000_003) ^ ((gi as u64) << 8 | (64 + ni) as u64);
                        let (mean, se) = trace_irradiance(&integ, cam, n, *group, args.paths, seed);
                        for (lane, &lambda) in group.iter().enumerate() {
                            let lambda = lambda as f64;
                            let s = sun.spectrum.eval(lambda as f32) as f64;
                            let t = s * table.irradiance_at(depth, n, sun_h, lambda);
                            let t_hi = hi.as_ref().map(|h| s * h.irradiance_at(depth, n, sun_h, lambda));
                            let truth = mean[lane];
                            out += &format!(
                                "{ty},{depth},{name},{:.0},{:.0},{lambda:.0},{truth:.6e},{:.3e},{t:.6e},{},{:.5},{:.5},{}\n",
                                th.to_degrees(),
                                ph.to_degrees(),
                                se[lane],
                                t_hi.map_or(String::new(), |x| format!("{x:.6e}")),
                                t / truth,
                                t / truth * se[lane] / truth,
                                t_hi.map_or(String::new(), |x| format!("{:.5}", x / truth)),
                            );
                        }
                    }
                    eprintln!("{ty} {depth} m irradiance {name}: done");
                }
                continue;
            }
            for (di, &(name, th, ph)) in DIRECTIONS.iter().enumerate() {
                // Snapped to the nearest elevation node (the nodes are warped towards the horizon).
                let th = light_field::elevation_angle(
                    light_field::elevation_coord(th.to_radians()).round() as usize
                );
                let ph = ph.to_radians();
                let v = (sun_h * (th.sin() * ph.cos()) + DVec3::Y * th.cos() + side * (th.sin() * ph.sin()))
                    .normalize();
                for (gi, group) in GROUPS.iter().enumerate() {
                    let seed = args.seed.wrapping_mul(1_000_003) ^ ((gi as u64) << 8 | di as u64);
                    let (mean, se) = match &reuse {
                        Some(m) => {
                            let mut mean = [0.0; 4];
                            let mut se = [0.0; 4];
                            for (j, &l) in group.iter().enumerate() {
                                let k = format!("{ty},{depth},{name},{l:.0}");
                                let Some(&(t, s)) = m.get(&k) else {
                                    bail!("--truth-csv has no row for {k} (type,depth,direction,λ)")
                                };
                                (mean[j], se[j]) = (t, s);
                            }
                            (mean, se)
                        }
                        None => trace(&integ, cam, v.as_vec3(), *group, args.paths, seed),
                    };
                    for (lane, &lambda) in group.iter().enumerate() {
                        let lambda = lambda as f64;
                        let s = sun.spectrum.eval(lambda as f32) as f64;
                        let [d, b, su] = predict(&table, &medium, v, sun_h, lambda);
                        let t = s * (d + b + su);
                        let t_hi = hi.as_ref().map(|h| {
                            let [d, b, su] = predict(h, &medium, v, sun_h, lambda);
                            s * (d + b + su)
                        });
                        let truth = mean[lane];
                        let ratio = t / truth;
                        out += &format!(
                            "{ty},{depth},{name},{:.0},{:.0},{lambda:.0},{truth:.6e},{:.3e},{t:.6e},{},{:.6e},{:.6e},{:.6e},{ratio:.5},{:.5},{}\n",
                            th.to_degrees(),
                            ph.to_degrees(),
                            se[lane],
                            t_hi.map_or(String::new(), |x| format!("{x:.6e}")),
                            s * d,
                            s * b,
                            s * su,
                            ratio * se[lane] / truth,
                            t_hi.map_or(String::new(), |x| format!("{:.5}", x / truth)),
                        );
                    }
                }
                eprintln!("{ty} {depth} m {name}: done");
            }
        }
    }
    let mut f =
        std::fs::File::create(&args.out).with_context(|| format!("writing {}", args.out.display()))?;
    f.write_all(out.as_bytes())?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

/// (truth, σ) by "type,depth,direction,λ" from an earlier output of this example.
fn read_truth(path: &std::path::Path) -> Result<std::collections::HashMap<String, (f64, f64)>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut m = std::collections::HashMap::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let bad = || format!("{} line {}: expected this example's CSV columns", path.display(), i + 1);
        if f.len() < 8 {
            bail!(bad());
        }
        let t: f64 = f[6].parse().with_context(bad)?;
        let s: f64 = f[7].parse().with_context(bad)?;
        m.insert(format!("{},{},{},{}", f[0], f[1], f[2], f[5]), (t, s));
    }
    Ok(m)
}

/// A square quad facing up at `c`, half-width `h`: the tracer's only triangle pair — 2 cm and
/// out of every path's way, or the sea floor.
fn quad(c: Vec3, h: f32) -> scene::Mesh {
    scene::Mesh {
        positions: vec![
            c + Vec3::new(-h, 0.0, -h),
            c + Vec3::new(-h, 0.0, h),
            c + Vec3::new(h, 0.0, h),
            c + Vec3::new(h, 0.0, -h),
        ],
        normals: vec![Vec3::Y; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        material: 0,
        ..Default::default()
    }
}

/// Mean and standard error per lane of `n` independent samples, each drawn on its own stream
/// over the available threads: `pre` draws what the sample needs before the hero rotation,
/// `post` evaluates it for the four wavelengths rotated so the hero takes every lane in turn
/// (as `truth::water`'s closed-form test does), which keeps every lane's estimate unbiased.
fn lane_means<T>(
    wl: [f32; 4],
    n: u64,
    seed: u64,
    pre: &(dyn Fn(&mut Sampler) -> T + Sync),
    post: &(dyn Fn(&mut Sampler, T, &Wavelengths) -> [f64; 4] + Sync),
) -> ([f64; 4], [f64; 4]) {
    let threads = std::thread::available_parallelism().map_or(2, |x| x.get()) as u64;
    let parts: Vec<([f64; 4], [f64; 4])> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    let (mut sum, mut sq) = ([0.0f64; 4], [0.0f64; 4]);
                    let mut i = t;
                    while i < n {
                        let mut rng = Sampler::new(seed, i);
                        let x0 = pre(&mut rng);
                        let k = ((rng.uniform() * 4.0) as usize).min(3);
                        let rot = Wavelengths(Vec4::from_array(std::array::from_fn(|j| wl[(j + k) % 4])));
                        let r = post(&mut rng, x0, &rot);
                        for j in 0..4 {
                            let x = r[(j + 4 - k) % 4];
                            sum[j] += x;
                            sq[j] += x * x;
                        }
                        i += threads;
                    }
                    (sum, sq)
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().expect("tracing thread")).collect()
    });
    let nf = n as f64;
    let mut mean = [0.0; 4];
    let mut se = [0.0; 4];
    for j in 0..4 {
        let (s, q): (f64, f64) = parts.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0[j], b + p.1[j]));
        mean[j] = s / nf;
        se[j] = ((q / nf - mean[j] * mean[j]).max(0.0) / (nf - 1.0).max(1.0)).sqrt();
    }
    (mean, se)
}

/// Mean radiance and its standard error per lane over `n` independent paths along `v`.
fn trace(integ: &Integrator, o: Vec3, v: Vec3, wl: [f32; 4], n: u64, seed: u64) -> ([f64; 4], [f64; 4]) {
    lane_means(wl, n, seed, &|_| (), &|rng, (), rot| {
        integ.radiance(o, v, rot, rng).to_array().map(|x| x as f64)
    })
}

/// Diffuse irradiance on a surface at `o` facing `n`: π × the mean radiance arriving along
/// cosine-distributed directions around n (the integrator's radiance excludes the sun's delta
/// beam at `o` itself, as the table does), per lane with its standard error.
fn trace_irradiance(
    integ: &Integrator,
    o: Vec3,
    n: DVec3,
    wl: [f32; 4],
    paths: u64,
    seed: u64,
) -> ([f64; 4], [f64; 4]) {
    let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t = n.cross(a).normalize();
    let b = n.cross(t);
    let direction = |rng: &mut Sampler| {
        let (u1, u2) = (rng.uniform() as f64, rng.uniform() as f64);
        let (r, phi) = (u1.sqrt(), 2.0 * std::f64::consts::PI * u2);
        (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
    };
    lane_means(wl, paths, seed, &direction, &|rng, v, rot| {
        integ.radiance(o, v.as_vec3(), rot, rng).to_array().map(|x| std::f64::consts::PI * x as f64)
    })
}

/// The table's radiance along `v` from the camera's depth, per unit sun irradiance E⊥:
/// [diffuse (∫J), the sun beam's single scattering, what comes through or off the surface].
fn predict(t: &LightFieldTable, m: &WaterMedium, v: DVec3, sun_h: DVec3, lambda: f64) -> [f64; 3] {
    let k = m.coefficients(lambda);
    let g = Options::default().phase_g as f64;
    let to_sun = m.sun_dir_underwater().as_dvec3();
    let z0 = m.depth;
    let floor = m.floor.as_ref();
    let d = if v.y > 1e-9 {
        z0 / v.y
    } else if let Some(f) = floor.filter(|_| v.y < -1e-9) {
        f.below_camera / -v.y
    } else {
        f64::INFINITY
    };
    // View rays: c minus the forward cone's scattering, as the real-time pass.
    let cv = underwater::light_field_key(m, &Options::default()).view_attenuation(k.a, k.b);
    let diffuse = ray_integral(&t.j_column(v, sun_h, lambda), t.z_max, cv, z0, v.y, d);
    let beam = single::beam_view(k.b, k.c, cv, g, to_sun, 1.0, v, z0, d);
    if let Some(f) = floor.filter(|_| v.y < -1e-9) {
        // The Lambertian floor lit by the table's downwelling irradiance, per unit sun E⊥.
        let e_d = t.attenuation(t.z_max, lambda) * to_sun.y * (1.0 + m.sky);
        let seen = f.albedo.eval(lambda) / std::f64::consts::PI * e_d * (-cv * d).exp();
        return [diffuse, beam, seen];
    }
    let surface = if d.is_finite() {
        let n = WATER_IOR;
        let tr = transmittance_up(v.y, n);
        // Uniform sky of irradiance sky·μ below the surface: L_air = sky·μ/(π·T̄), seen as
        // L_air·T·n² through the window (truth::water_surface).
        let sky = m.sky * to_sun.y / (std::f64::consts::PI * mean_transmittance(n)) * tr * n * n;
        let mirror = DVec3::new(v.x, -v.y, v.z);
        if floor.is_some() {
            // The floored table's own reflection (water and floor), as the real-time pass reads it.
            return [diffuse, beam, (sky + t.surface_at(v, sun_h, lambda, true)) * (-cv * d).exp()];
        }
        let below =
            ray_integral(&t.j_column(mirror, sun_h, lambda), t.z_max, cv, 0.0, mirror.y, f64::INFINITY)
                + single::beam_view(k.b, k.c, cv, g, to_sun, 1.0, mirror, 0.0, f64::INFINITY);
        (sky + (1.0 - tr) * below) * (-cv * d).exp()
    } else {
        0.0
    };
    [diffuse, beam, surface]
}
