//! See-through materials (KHR_materials_transmission, _volume) in the real-time renderer, against
//! analytic values: an orthographic camera looks straight at a pane (so n·v = 1 and the
//! refracted ray goes straight on) in front of an unlit background of colour C, with no light:
//! the pane shows T·(1 − F0)·base·exp(−σ_a·d)·C, F0 = ((η − 1)/(η + 1))², in the RGB and spectral
//! modes (in the spectral one for grey bases and absorption, whose spectra are flat; the naive
//! mode's boxes do not round-trip a colour, so it is checked for linearity); beside the pane the
//! background passes unchanged (the same pixel values as without the pane); a transmission of 0
//! is an opaque pane; under dispersion the RGB mode refracts its channels apart and the
//! spectral mode its node groups, while without it they stay together.

mod common;

use color::quadrature::Quadrature;
use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings, Renderer};
use scene::transmission::{Transmission, Volume};
use scene::{Camera, Material, Mesh, Scene, SpectralSettings};

const W: u32 = 40;
const H: u32 = 32;
const BG: [f32; 3] = [0.8, 0.45, 0.2];

fn settings(mode: Mode) -> RenderSettings {
    RenderSettings { mode, wavelengths: 16, shadows: false, ..Default::default() }
}

/// The background (an unlit quad at z = −1 filling the view, colour `BG`, a black stripe down
/// the middle for the refraction tests) and a pane in the middle half of the view at z = 0
/// (none when `pane` is `None`).
fn scene(pane: Option<Material>, stripe: bool) -> Scene {
    let mut s = Scene {
        warnings: vec![],
        source: "test:transmission".into(),
        meshes: vec![],
        materials: vec![],
        textures: vec![],
        lights: vec![],
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::Y, 0.5),
        spectral: SpectralSettings::default(),
        water: None,
        environment: None,
        medium: None,
        inputs: vec![],
        origin: glam::DVec3::ZERO,
        input_stamps: vec![],
        choices: vec![],
        animation_end: None,
    };
    let bg = Material {
        name: "background".into(),
        base_color: Vec4::new(BG[0], BG[1], BG[2], 1.0),
        unlit: true,
        ..Default::default()
    };
    s.materials.push(bg);
    s.materials.push(Material {
        name: "stripe".into(),
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        unlit: true,
        ..Default::default()
    });
    s.meshes.push(Mesh::quad(Vec3::new(-4.0, -4.0, -1.0), Vec3::X * 8.0, Vec3::Y * 8.0, 0));
    if stripe {
        s.meshes.push(Mesh::quad(Vec3::new(-0.05, -4.0, -0.99), Vec3::X * 0.1, Vec3::Y * 8.0, 1));
    }
    if let Some(m) = pane {
        s.materials.push(m);
        s.meshes.push(Mesh::quad(Vec3::new(-0.5, -0.4, 0.0), Vec3::X, Vec3::Y * 0.8, 2));
    }
    s.camera = common::front_ortho_camera();
    s
}

fn glass(base: f32, ior: f32, transmission: f32, volume: Option<Volume>, dispersion: f32) -> Material {
    Material {
        name: "glass".into(),
        base_color: Vec4::new(base, base, base, 1.0),
        metallic: 0.0,
        roughness: 0.0,
        ior,
        transmission: Some(Transmission { factor: transmission, texture: None, volume, dispersion }),
        ..Default::default()
    }
}

fn render(r: &mut Renderer, s: &Scene, mode: Mode) -> Vec<[f64; 3]> {
    r.set_scene(s).unwrap();
    r.resize(W, H).unwrap();
    r.render(&s.camera, &settings(mode)).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

const CENTRE: (u32, u32) = (W / 2 + 5, H / 2);
const BESIDE: (u32, u32) = (2, 2);

fn at(img: &[[f64; 3]], (x, y): (u32, u32)) -> [f64; 3] {
    img[(y * W + x) as usize]
}

fn f0(ior: f64) -> f64 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

fn close(got: [f64; 3], want: [f64; 3], tol: f64, what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= tol * want[c].abs().max(0.05),
            "{what}: channel {c} {} vs {} (all {got:?} vs {want:?})",
            got[c],
            want[c]
        );
    }
}

#[test]
fn a_clear_pane_lets_through_what_its_surface_does_not_reflect() {
    let mut r = renderer();
    for mode in [Mode::Rgb, Mode::Spectral] {
        let bare = render(&mut r, &scene(None, false), mode);
        let bg = at(&bare, CENTRE);
        // The spectral modes upsample the unlit colour and convert back: C to their round trip.
        close(bg, BG.map(f64::from), 5e-3, &format!("{mode:?} background"));
        for (ior, t, base) in [(1.5, 1.0, 1.0), (1.33, 0.6, 1.0), (2.0, 1.0, 0.5)] {
            let img = render(&mut r, &scene(Some(glass(base, ior, t, None, 0.0)), false), mode);
            let k = f64::from(t) * (1.0 - f0(f64::from(ior))) * f64::from(base);
            close(at(&img, CENTRE), bg.map(|c| k * c), 3e-3, &format!("{mode:?} η {ior} T {t} base {base}"));
            // Beside the pane the background is what it was, to the bit.
            assert_eq!(at(&img, BESIDE), at(&bare, BESIDE), "{mode:?}: the background changed");
        }
        // No transmission: an opaque (unlit, so black) pane.
        let opaque = render(&mut r, &scene(Some(glass(1.0, 1.5, 0.0, None, 0.0)), false), mode);
        close(at(&opaque, CENTRE), [0.0; 3], 1e-6, &format!("{mode:?} opaque"));
    }
}

/// The naive mode's boxes do not reproduce a colour (its known round-trip error, docs), so its
/// pane is checked for what must still hold: linear in the transmission and the base, and
/// the same absorption as the RGB mode's for a grey volume.
#[test]
fn the_naive_pane_is_linear_in_its_transmission() {
    let mut r = renderer();
    let full = render(&mut r, &scene(Some(glass(1.0, 1.5, 1.0, None, 0.0)), false), Mode::Naive);
    let part = render(&mut r, &scene(Some(glass(0.5, 1.5, 0.6, None, 0.0)), false), Mode::Naive);
    close(at(&part, CENTRE), at(&full, CENTRE).map(|c| 0.3 * c), 3e-3, "naive T 0.6 base 0.5");
}

/// The volume's absorption: after thickness d the attenuation colour c reached at distance d₀
/// is c^(d/d₀) per channel (KHR_materials_volume), exactly in RGB mode, and in the spectral
/// ones for a grey c (a flat box spectrum).
#[test]
fn a_volume_absorbs_by_beers_law() {
    let mut r = renderer();
    let vol = |c: [f32; 3]| Volume {
        thickness: 0.3,
        thickness_texture: None,
        attenuation_color: c,
        attenuation_distance: 0.2,
    };
    for mode in [Mode::Rgb, Mode::Spectral] {
        let bare = render(&mut r, &scene(None, false), mode);
        let bg = at(&bare, CENTRE);
        let grey = render(&mut r, &scene(Some(glass(1.0, 1.5, 1.0, Some(vol([0.5; 3])), 0.0)), false), mode);
        let k = (1.0 - f0(1.5)) * 0.5f64.powf(0.3 / 0.2);
        close(at(&grey, CENTRE), bg.map(|c| k * c), 3e-3, &format!("{mode:?} grey volume"));
        if mode == Mode::Rgb {
            let c = [0.9f32, 0.5, 0.2];
            let img = render(&mut r, &scene(Some(glass(1.0, 1.5, 1.0, Some(vol(c)), 0.0)), false), mode);
            let want: [f64; 3] = std::array::from_fn(|i| (1.0 - f0(1.5)) * f64::from(c[i]).powf(1.5) * bg[i]);
            close(at(&img, CENTRE), want, 3e-3, "rgb coloured volume");
        }
    }
}

/// A coloured volume in the spectral mode: its absorption is a box per channel (as the path
/// tracer upsamples it), whose steps at 490 and 585 nm the renderer integrates exactly — the
/// box in the white's band-split weights — instead of sampling it at the nodes, which at N = 8
/// (44 nm apart) smears each step over the nodes around it. Against an independent CPU
/// evaluation of both at N = 8 and a dense one (N = 256).
#[test]
fn a_coloured_volume_integrates_its_box_absorption_exactly() {
    let mut r = renderer();
    let table = table();
    // Green bottle glass, 1.5 attenuation distances thick: steps of ×5 and ×7 at the edges.
    let c = [0.3f32, 0.75, 0.35];
    let vol =
        Volume { thickness: 0.3, thickness_texture: None, attenuation_color: c, attenuation_distance: 0.2 };
    let boxed = c.map(|v| f64::from(v).powf(1.5));
    let bg = BG.map(f64::from);
    let light = color::illuminant::by_name("D65").unwrap();
    let dense =
        CpuSpectral::new(256, Quadrature::Prefiltered, &light, 1.0).emitter_through_box(&table, bg, boxed);
    let k = 1.0 - f0(1.5);
    for n in [8usize, 16] {
        let cpu = CpuSpectral::new(n, Quadrature::Prefiltered, &light, 1.0);
        let exact = cpu.emitter_through_box(&table, bg, boxed).map(|v| k * v);
        let at_nodes = cpu.emitter_through_box_at_nodes(&table, bg, boxed).map(|v| k * v);
        let s = scene(Some(glass(1.0, 1.5, 1.0, Some(vol.clone()), 0.0)), false);
        r.set_scene(&s).unwrap();
        r.resize(W, H).unwrap();
        let st = RenderSettings { wavelengths: n, ..settings(Mode::Spectral) };
        r.render(&s.camera, &st).unwrap();
        let img: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
        let got = at(&img, CENTRE);
        let dense_k = dense.map(|v| k * v);
        let err = |a: [f64; 3]| (0..3).map(|i| (a[i] - dense_k[i]).abs()).fold(0.0, f64::max);
        println!(
            "N = {n}: GPU {got:?}, CPU band-split {exact:?}, CPU at the nodes {at_nodes:?}, dense {dense_k:?}; \
             worst channel error against dense: GPU {:.2e}, at the nodes {:.2e}",
            err(got),
            err(at_nodes)
        );
        close(got, exact, 3e-3, &format!("N = {n}: the GPU against the CPU band-split integral"));
        // What the exactness buys: closer to the dense integral than node sampling, by a margin.
        assert!(
            err(got) < 0.5 * err(at_nodes),
            "N = {n}: GPU off the dense integral by {:.2e}, node sampling by {:.2e}",
            err(got),
            err(at_nodes)
        );
    }
}

/// A clear thick pane of index 1.5 and `dispersion`, tilted about y so that the refracted ray
/// leans sideways, over the stripe.
fn tilted_pane(dispersion: f32) -> Scene {
    let vol = Volume {
        thickness: 0.6,
        thickness_texture: None,
        attenuation_color: [1.0; 3],
        attenuation_distance: f32::INFINITY,
    };
    let mut s = scene(Some(glass(1.0, 1.5, 1.0, Some(vol), dispersion)), true);
    let m = s.meshes.last_mut().unwrap();
    let rot = glam::Quat::from_rotation_y(0.7);
    for p in &mut m.positions {
        *p = rot * *p;
    }
    for n in &mut m.normals {
        *n = rot * *n;
    }
    s
}

/// Dispersion: a tilted thick pane over a black stripe shifts the stripe by refraction. With a
/// dispersion of 0 every channel (RGB) or the whole spectrum (spectral) is shifted alike, so the
/// image near the stripe keeps the background's hue (each pixel a multiple of C); with a strong
/// dispersion the channels or node groups shift apart and colour fringes appear.
#[test]
fn dispersion_refracts_the_colours_apart() {
    let mut r = renderer();
    let tilted = tilted_pane;
    for mode in [Mode::Rgb, Mode::Spectral] {
        let fringe = |img: &[[f64; 3]]| {
            // Largest departure from the background's hue across the pane's middle row.
            (W / 2 - 8..W / 2 + 8)
                .map(|x| {
                    let p = at(img, (x, H / 2));
                    let s = p[0] / f64::from(BG[0]);
                    (0..3).map(|c| (p[c] - s * f64::from(BG[c])).abs()).fold(0.0, f64::max)
                })
                .fold(0.0, f64::max)
        };
        // The stripe itself moves: refraction, not a see-through overlay.
        let darkest = |img: &[[f64; 3]]| {
            (W / 2 - 10..W / 2 + 10)
                .min_by(|&a, &b| at(img, (a, H / 2))[1].total_cmp(&at(img, (b, H / 2))[1]))
                .unwrap()
        };
        let straight = darkest(&render(&mut r, &scene(None, true), mode));
        let bent = render(&mut r, &tilted(0.0), mode);
        assert!(darkest(&bent).abs_diff(straight) >= 2, "{mode:?}: the stripe did not move ({straight})");
        let plain = fringe(&bent);
        let dispersed = fringe(&render(&mut r, &tilted(8.0), mode));
        assert!(plain < 0.02, "{mode:?}: fringes without dispersion ({plain})");
        assert!(dispersed > 0.1, "{mode:?}: no fringes with dispersion ({dispersed})");
    }
}

/// Dispersion at every node count: the spectral mode refracts each node on its own up to
/// N = 8 (one direction per group of four left N ≤ 4 with a single index for the whole
/// spectrum — no fringe at all where the RGB mode's three channels split — and N = 8 with two
/// blocks of colour), pairs up to 16, groups beyond. The fringe across the tilted dispersive
/// pane: present from N = 2 on (at N = 4 it was 0.03 of the dense one), and from N = 5 on
/// within a third of the dense (N = 64) one (at N = 5 it was a quarter of it).
#[test]
fn dispersion_fringes_at_every_node_count() {
    let mut r = renderer();
    let s = tilted_pane(8.0);
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    // The colour across the pane's middle row: each pixel's chroma (largest minus smallest
    // channel over their sum), summed.
    let fringe = |r: &mut Renderer, n: usize| {
        r.render(&s.camera, &RenderSettings { wavelengths: n, ..settings(Mode::Spectral) }).unwrap();
        let img: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
        let row: Vec<[f64; 3]> = (W / 2 - 8..W / 2 + 8).map(|x| at(&img, (x, H / 2))).collect();
        // Against the background's hue as this N draws it (beside the pane): what refraction
        // without dispersion leaves, at any N.
        let bg = at(&img, BESIDE);
        row.iter()
            .map(|p| {
                let k = p[0] / bg[0];
                (0..3).map(|c| (p[c] - k * bg[c]).abs()).fold(0.0, f64::max)
            })
            .sum::<f64>()
    };
    let dense = fringe(&mut r, 64);
    for n in [2usize, 3, 4, 5, 8, 12, 16, 32] {
        let f = fringe(&mut r, n);
        println!("N = {n}: fringe {f:.3} (N = 64: {dense:.3})");
        assert!(f > 0.25 * dense, "N = {n}: fringe {f:.3} against {dense:.3} at N = 64");
        if n >= 5 {
            assert!((f - dense).abs() < dense / 3.0, "N = {n}: fringe {f:.3} against {dense:.3} at N = 64");
        }
    }
}

/// Snell's law in vector form (unit `d`, `n` facing against `d`), `None` past the critical angle.
fn snell(d: glam::DVec3, n: glam::DVec3, eta: f64) -> Option<glam::DVec3> {
    let c = -n.dot(d);
    let k = 1.0 - eta * eta * (1.0 - c * c);
    (k >= 0.0).then(|| eta * d + (eta * c - k.sqrt()) * n)
}

/// A closed glass volume refracts twice, as a ball lens: behind a glass ball of index 1.5 the
/// background's plane lies beyond the focus, so a stripe right of the axis shows through the
/// ball's left half (inverted and magnified). The columns of the ball's middle row that show
/// the stripe are those where an exact ray trace (two refractions by Snell's law through the
/// exact sphere, f64) lands on it, to within a column at each edge of the run, in RGB and
/// spectral modes.
#[test]
fn a_glass_ball_inverts_what_lies_behind_it() {
    const BW: u32 = 160;
    const BH: u32 = 32;
    let (radius, ior, stripe) = (0.3f64, 1.5f64, (0.1f64, 0.2f64));
    let mut s = scene(None, false);
    s.materials.push(Material {
        name: "stripe right of the axis".into(),
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        unlit: true,
        ..Default::default()
    });
    s.meshes.push(Mesh::quad(
        Vec3::new(stripe.0 as f32, -4.0, -0.99),
        Vec3::X * (stripe.1 - stripe.0) as f32,
        Vec3::Y * 8.0,
        2,
    ));
    let vol = Volume {
        thickness: 2.0 * radius as f32,
        thickness_texture: None,
        attenuation_color: [1.0; 3],
        attenuation_distance: f32::INFINITY,
    };
    s.materials.push(glass(1.0, ior as f32, 1.0, Some(vol), 0.0));
    s.meshes.push(Mesh::uv_sphere(Vec3::ZERO, radius as f32, 48, 96, 3));
    s.camera.ortho = Some((1.0, 0.2));
    let y = 0.0;
    // Column x's centre in the scene, and where the view ray through it lands on the background.
    let scene_x = |col: u32| -1.0 + 2.0 * (f64::from(col) + 0.5) / f64::from(BW);
    let landing = |x: f64| -> Option<f64> {
        use glam::DVec3;
        let (o, d) = (DVec3::new(x, y, 2.0), DVec3::new(0.0, 0.0, -1.0));
        let b = o.dot(d);
        let disc = b * b - (o.length_squared() - radius * radius);
        if disc <= 0.0 {
            return None;
        }
        let p = o + d * (-b - disc.sqrt());
        let r1 = snell(d, p / radius, 1.0 / ior)?;
        // From inside: the far root.
        let b = p.dot(r1);
        let q = p + r1 * (-b + (b * b - (p.length_squared() - radius * radius)).sqrt());
        let r2 = snell(r1, -q / radius, ior)?;
        (r2.z < 0.0).then(|| q.x + r2.x * (-1.0 - q.z) / r2.z)
    };
    let mut r = renderer();
    for mode in [Mode::Rgb, Mode::Spectral] {
        r.set_scene(&s).unwrap();
        r.resize(BW, BH).unwrap();
        r.render(&s.camera, &settings(mode)).unwrap();
        let img: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
        let row = BH / 2;
        let (mut want, mut got) = (Vec::new(), Vec::new());
        for col in 0..BW {
            let x = scene_x(col);
            // The rim (beyond 0.9 R) is left out: there the mesh's facets and the Fresnel term
            // decide more than the refraction does; so are rays that land off screen.
            if x.abs() > 0.9 * radius {
                continue;
            }
            // Screen-space refraction sees only what the screen shows; near its edge the rays
            // are steep enough that the facets' normals swing the landing point off it.
            let Some(l) = landing(x).filter(|l| l.abs() < 0.8) else { continue };
            if (stripe.0..stripe.1).contains(&l) {
                want.push(col);
            }
            let g = at_w(&img, BW, (col, row))[1];
            if g < 0.5 * 0.96 * 0.96 * f64::from(BG[1]) * 0.5 {
                got.push(col);
            }
        }
        assert!(!want.is_empty() && want.iter().all(|&c| scene_x(c) < 0.0), "the trace: {want:?}");
        let (w0, w1) = (want[0], *want.last().unwrap());
        let (g0, g1) = (got.first().copied(), got.last().copied());
        assert!(
            g0.is_some_and(|g| g.abs_diff(w0) <= 1) && g1.is_some_and(|g| g.abs_diff(w1) <= 1),
            "{mode:?}: the stripe shows in columns {got:?}, the trace says {want:?}"
        );
        // Without the ball's second refraction (a slab) it would show right of the axis.
        assert!(got.iter().all(|&c| scene_x(c) < 0.0), "{mode:?}: not inverted: {got:?}");
    }
}

fn at_w(img: &[[f64; 3]], w: u32, (x, y): (u32, u32)) -> [f64; 3] {
    img[(y * w + x) as usize]
}

/// A see-through material's thin film (KHR_materials_iridescence on a transmissive material) is
/// drawn in real time: under a light shining along the view onto a rough grey pane, its
/// reflection takes the film's colour (a 300 nm film of index 1.33 over the pane's 1.5), in RGB
/// (the extension's Belcour–Barla film) and spectral (the exact film per node) modes; a film of
/// factor 0 is no film, to the bit; half the factor gives a different image.
#[test]
fn a_see_through_film_colours_the_reflection() {
    let film = |factor: f32| {
        let mut m = glass(0.5, 1.5, 0.5, None, 0.0);
        m.roughness = 0.4;
        m.iridescence = Some(scene::Iridescence {
            factor,
            texture: None,
            ior: 1.33,
            thickness_min: 100.0,
            thickness_max: 300.0,
            thickness_texture: None,
        });
        let mut s = scene(Some(m), false);
        s.lights.push(scene::Light {
            name: "along the view".into(),
            kind: scene::LightKind::Directional { direction: Vec3::NEG_Z },
            emission: scene::Emission { rgb: Vec3::ONE, intensity: 2.0, spectrum: None },
            stands_in_for: None,
        });
        s
    };
    let mut r = renderer();
    for mode in [Mode::Rgb, Mode::Spectral] {
        let plain = {
            let mut s = film(0.0);
            s.materials[2].iridescence = None;
            at(&render(&mut r, &s, mode), CENTRE)
        };
        let zero = at(&render(&mut r, &film(0.0), mode), CENTRE);
        let full = at(&render(&mut r, &film(1.0), mode), CENTRE);
        let half = at(&render(&mut r, &film(0.5), mode), CENTRE);
        assert_eq!(zero, plain, "{mode:?}: a film of factor 0");
        let hue = |p: [f64; 3]| p.map(|c| c / (p[0] + p[1] + p[2]));
        let shift = (0..3).map(|c| (hue(full)[c] - hue(plain)[c]).abs()).fold(0.0, f64::max);
        assert!(shift > 0.02, "{mode:?}: the film does not colour the reflection ({plain:?} → {full:?})");
        assert_ne!(half, full, "{mode:?}: the film's factor is not used");
        // Its textures are drawn too: a weight texture of 128/255 is about the half factor, and
        // a thickness texture of 0 puts the film at its minimum thickness, another colour.
        let mut textured = |rg: [u8; 2]| {
            let mut s = film(1.0);
            s.textures.push(scene::Texture {
                sampler: Default::default(),
                name: "film".into(),
                width: 2,
                height: 2,
                rgba8: [rg[0], rg[1], 0, 255].repeat(4),
                srgb: false,
            });
            let t = Some(scene::TextureRef { transform: None, index: 0, tex_coord: 0 });
            let f = s.materials[2].iridescence.as_mut().unwrap();
            (f.texture, f.thickness_texture) = (t, t);
            at(&render(&mut r, &s, mode), CENTRE)
        };
        let weighted = textured([128, 255]);
        for c in 0..3 {
            assert!(
                (weighted[c] - half[c]).abs() <= 0.02 * half[c],
                "{mode:?}: a film texture of weight ½ gives {weighted:?}, the factor ½ {half:?}"
            );
        }
        let thin = textured([255, 0]);
        let shift = (0..3).map(|c| (hue(thin)[c] - hue(full)[c]).abs()).fold(0.0, f64::max);
        assert!(shift > 0.01, "{mode:?}: the thickness texture is not used ({full:?} → {thin:?})");
    }
}

/// A clear pane of index 1.5 under a film of index 1.8, 100–380 nm thick.
fn filmed_pane() -> Material {
    let mut m = glass(1.0, 1.5, 1.0, None, 0.0);
    m.iridescence = Some(scene::Iridescence {
        factor: 1.0,
        texture: None,
        ior: 1.8,
        thickness_min: 100.0,
        thickness_max: 380.0,
        thickness_texture: None,
    });
    m
}

/// What a clear film on a see-through pane does not reflect it transmits (as the path tracer's
/// interface now does): in a white furnace (a white sky, a white backdrop) the filmed pane
/// vanishes. The transmitted share was 1 − Schlick's F while the reflection took the film's,
/// so the pane showed the film's colour over white.
#[test]
fn a_filmed_pane_in_a_white_furnace_vanishes() {
    let mut s = scene(Some(filmed_pane()), false);
    s.materials[0].base_color = Vec4::ONE;
    s.environment = Some(scene::Environment::uniform(Vec3::ONE));
    let mut r = renderer();
    for mode in [Mode::Rgb, Mode::Spectral] {
        r.set_scene(&s).unwrap();
        r.resize(W, H).unwrap();
        r.render(&s.camera, &RenderSettings { env_occlusion: false, ..settings(mode) }).unwrap();
        let img: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
        close(at(&img, CENTRE), [1.0; 3], 0.02, &format!("{mode:?}: the filmed pane in the furnace"));
    }
}

/// Found by a sweep: a closed volume whose thickness far exceeds the mesh (10⁶, accepted by
/// glTF) was drawn black — the search for its back face took steps so wide that the first left
/// the volume far behind. The mesh's own back face bounds the search now: the ball looks as it
/// does at its true thickness.
#[test]
fn a_volume_thicker_than_its_mesh_is_still_drawn() {
    let ball = |thickness: f32| {
        let mut s = scene(None, false);
        let vol = Volume {
            thickness,
            thickness_texture: None,
            attenuation_color: [1.0; 3],
            attenuation_distance: f32::INFINITY,
        };
        s.materials.push(glass(1.0, 1.5, 1.0, Some(vol), 0.0));
        s.meshes.push(Mesh::uv_sphere(Vec3::ZERO, 0.3, 24, 48, 2));
        s
    };
    let mut r = renderer();
    for mode in [Mode::Rgb, Mode::Spectral] {
        let true_size = at(&render(&mut r, &ball(0.6), mode), (W / 2, H / 2));
        let huge = at(&render(&mut r, &ball(1e6), mode), (W / 2, H / 2));
        close(huge, true_size, 0.05, &format!("{mode:?}: thickness 10⁶ vs 0.6"));
    }
}

/// The exposure is applied as the frame is written (before the half float), and the
/// see-through layer reads the opaque layer back from that target: it takes the exposure out
/// again, so that behind the pane, as beside it, the frame is 2^EV times the unexposed one.
#[test]
fn the_exposure_scales_what_is_seen_through_a_pane_like_the_rest() {
    let mut r = renderer();
    let s = scene(Some(glass(1.0, 1.5, 1.0, None, 0.0)), false);
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    for mode in [Mode::Rgb, Mode::Spectral] {
        let frame = |r: &mut Renderer, ev: f32| {
            r.render(&s.camera, &RenderSettings { exposure_ev: ev, ..settings(mode) }).unwrap();
            r.read_hdr().unwrap().iter().map(rgb_of).collect::<Vec<_>>()
        };
        let (plain, exposed) = (frame(&mut r, 0.0), frame(&mut r, 3.0));
        for at_px in [CENTRE, BESIDE] {
            // Two f16 roundings (lavapipe truncates): two units in the last place.
            close(
                at(&exposed, at_px),
                at(&plain, at_px).map(|c| 8.0 * c),
                2.0 / 1024.0,
                &format!("{mode:?} {at_px:?}"),
            );
        }
    }
}

/// The glass panes and ball the general node loop is checked on: a clear pane, a green volume,
/// a dispersive volume over the stripe, a filmed pane, a thin wall with a lamp behind it, and
/// a glass ball (traced to its back faces).
fn general_loop_scenes() -> Vec<(&'static str, Scene)> {
    let vol = |c: [f32; 3], thickness: f32| Volume {
        thickness,
        thickness_texture: None,
        attenuation_color: c,
        attenuation_distance: 0.2,
    };
    let filmed = filmed_pane();
    let mut thin = scene(Some(glass(0.8, 1.5, 0.7, None, 0.0)), false);
    thin.materials[2].roughness = 0.4;
    thin.lights.push(scene::Light::point("behind", Vec3::new(0.1, 0.0, -0.5), 2.0));
    let mut ball = scene(None, true);
    ball.materials.push(glass(1.0, 1.5, 1.0, Some(vol([0.6, 0.9, 0.7], 0.6)), 0.0));
    ball.meshes.push(Mesh::uv_sphere(Vec3::ZERO, 0.3, 24, 48, 2));
    vec![
        ("clear pane", scene(Some(glass(1.0, 1.5, 1.0, None, 0.0)), false)),
        ("green volume", scene(Some(glass(1.0, 1.5, 1.0, Some(vol([0.3, 0.75, 0.35], 0.3)), 0.0)), false)),
        ("dispersive volume", scene(Some(glass(1.0, 1.7, 1.0, Some(vol([1.0; 3], 0.6)), 1.0)), true)),
        ("filmed pane", scene(Some(filmed), false)),
        ("thin wall, lamp behind", thin),
        ("glass ball", ball),
    ]
}

fn frame(r: &mut Renderer, s: &Scene, st: &RenderSettings) -> Vec<[f64; 3]> {
    r.render(&s.camera, st).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

fn worst_relative(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / a[c].abs().max(b[c].abs()).max(0.05)))
        .fold(0.0, f64::max)
}

/// The general node loop (groups outermost, for the spectral capture and for spectral hooks)
/// draws the see-through layer as the plain loop does — it drew see-through materials opaque —
/// and the capture holds the layer's light: the same image with the capture on, and with an
/// identity spectral hook, in the spectral and naive modes.
#[test]
fn the_general_node_loop_draws_the_see_through_layer_as_the_plain_loop() {
    let identity = "fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, \
                    ctx: SurfaceContext) -> mat3x4<f32> { return radiance; }";
    let mut r = renderer();
    r.resize(W, H).unwrap();
    for (name, s) in general_loop_scenes() {
        r.set_scene(&s).unwrap();
        for mode in [Mode::Spectral, Mode::Naive] {
            let st = RenderSettings { wavelengths: 8, ..settings(mode) };
            r.set_spectral_capture(true);
            let captured = frame(&mut r, &s, &st);
            let cap = r.read_spectral_capture().unwrap();
            r.set_spectral_capture(false);
            let plain = frame(&mut r, &s, &st);
            r.set_custom_shader(render::CustomShader::new(identity)).unwrap();
            let hooked = frame(&mut r, &s, &st);
            r.set_custom_shader(render::CustomShader::default()).unwrap();
            let (wc, wh) = (worst_relative(&plain, &captured), worst_relative(&plain, &hooked));
            println!("{name}, {mode:?}: capture loop vs plain {wc:.2e}, identity hook vs plain {wh:.2e}");
            // The see-through pixel is the background's light through the glass, not the
            // opaque surface (black: the scene has no light on it but the lamp behind the wall).
            let centre = at(&plain, CENTRE);
            assert!(centre.iter().sum::<f64>() > 0.05, "{name}, {mode:?}: the glass is dark: {centre:?}");
            assert!(wc < 2e-3, "{name}, {mode:?}: the capture's loop draws the layer differently ({wc})");
            assert!(wh < 2e-3, "{name}, {mode:?}: a spectral hook's loop draws the layer differently ({wh})");
            let i = (CENTRE.1 * W + CENTRE.0) as usize * cap.lambda.len();
            let nodes = &cap.data[i..i + cap.lambda.len()];
            assert!(nodes.iter().all(|v| v.is_finite() && *v > 0.0), "{name}, {mode:?}: captured {nodes:?}");
            if name == "clear pane" && mode == Mode::Spectral {
                // The pane's nodes are the background's beside it times T·(1 − F0) (the naive
                // mode's boxes do not round-trip the background's colour).
                let j = (BESIDE.1 * W + BESIDE.0) as usize * cap.lambda.len();
                for (n, (a, b)) in nodes.iter().zip(&cap.data[j..j + cap.lambda.len()]).enumerate() {
                    let ratio = f64::from(*a) / f64::from(*b);
                    assert!(
                        (ratio - (1.0 - f0(1.5))).abs() < 2e-3,
                        "{mode:?}: node {n}: pane / background {ratio}"
                    );
                }
            }
        }
    }
}

/// A spectral hook acts on the light between the camera and what it sees: at a see-through
/// pixel on the pane's own light only, since the background seen through it has had the hook
/// already. A hook that halves everything halves the pane (T·(1 − F0)·½·C where the mode
/// round-trips a colour), not quarters it (applied twice), nor draws it opaque, as the spectral
/// modes did; in every mode (the RGB mode has always layered the glass).
#[test]
fn a_hook_acts_once_on_what_is_seen_through_a_pane() {
    let half = "fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, \
                ctx: SurfaceContext) -> mat3x4<f32> { return s3_scale(radiance, vec4<f32>(0.5)); }\n\
                fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> { return 0.5 * radiance; }";
    let mut r = renderer();
    r.resize(W, H).unwrap();
    let bare = scene(None, false);
    let pane = scene(Some(glass(1.0, 1.5, 1.0, None, 0.0)), false);
    let k = 1.0 - f0(1.5);
    for mode in [Mode::Rgb, Mode::Spectral, Mode::Naive] {
        let st = RenderSettings { wavelengths: 8, ..settings(mode) };
        r.set_scene(&bare).unwrap();
        let bg = at(&frame(&mut r, &bare, &st), CENTRE);
        r.set_scene(&pane).unwrap();
        let plain = at(&frame(&mut r, &pane, &st), CENTRE);
        r.set_custom_shader(render::CustomShader::new(half)).unwrap();
        let img = frame(&mut r, &pane, &st);
        r.set_scene(&bare).unwrap();
        let halved_bg = frame(&mut r, &bare, &st);
        r.set_custom_shader(render::CustomShader::default()).unwrap();
        println!("{mode:?}: pane {plain:?}, halved {:?}", at(&img, CENTRE));
        close(at(&halved_bg, CENTRE), bg.map(|c| 0.5 * c), 2e-3, &format!("{mode:?}: the hook halves"));
        close(at(&img, CENTRE), plain.map(|c| 0.5 * c), 3e-3, &format!("{mode:?}: the halved pane"));
        if mode != Mode::Naive {
            close(at(&img, CENTRE), bg.map(|c| 0.5 * k * c), 3e-3, &format!("{mode:?}: T(1 − F0)·½C"));
        }
        assert_eq!(at(&img, BESIDE), at(&halved_bg, BESIDE), "{mode:?}: beside the pane");
    }
}

/// The environment seen through glass under a medium's environment transmittance: where a ray
/// through the glass leaves the screen the RGB mode multiplies the sky by it per channel
/// (`seen_through`'s `env_t`), the spectral loop per node. A glass ball before a grey sky (every
/// refracted ray leaves for the sky) with a grey transmittance of 0.4: the ball's centre, the
/// sky through it and its reflection, is 0.4 times what it is without the hook, and the two
/// modes agree pixel by pixel (flat spectra) — beside the ball too, where the sky reaches the
/// hook as the radiance it acts on in both modes (the spectral modes gave it none: black).
#[test]
fn the_environment_through_glass_takes_the_hooks_transmittance_in_every_mode() {
    let t = "fn custom_env_transmittance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> \
             { return vec4<f32>(0.4); }\n\
             fn custom_env_transmittance_rgb(ctx: SurfaceContext) -> vec3<f32> { return vec3<f32>(0.4); }";
    let mut s = scene(None, false);
    s.meshes.clear();
    let vol = Volume {
        thickness: 0.6,
        thickness_texture: None,
        attenuation_color: [1.0; 3],
        attenuation_distance: f32::INFINITY,
    };
    s.materials.push(glass(1.0, 1.5, 1.0, Some(vol), 0.0));
    s.meshes.push(Mesh::uv_sphere(Vec3::ZERO, 0.3, 24, 48, 2));
    s.environment = Some(scene::Environment::uniform(Vec3::splat(0.6)));
    let mut r = renderer();
    r.resize(W, H).unwrap();
    r.set_scene(&s).unwrap();
    let mut images = vec![];
    let mut ball = vec![];
    let centre = (W / 2, H / 2);
    for mode in [Mode::Rgb, Mode::Spectral] {
        let st = RenderSettings { env_occlusion: false, ..settings(mode) };
        let plain = frame(&mut r, &s, &st);
        // The ball's pixels: those that are not the sky's value (the corner's).
        ball = plain.iter().map(|p| (p[1] - plain[0][1]).abs() > 1e-3).collect();
        r.set_custom_shader(render::CustomShader::new(t)).unwrap();
        let img = frame(&mut r, &s, &st);
        r.set_custom_shader(render::CustomShader::default()).unwrap();
        let (p, c) = (at(&plain, centre), at(&img, centre));
        println!("{mode:?}: the ball's centre {p:?} → {c:?}");
        close(c, p.map(|v| 0.4 * v), 3e-3, &format!("{mode:?}: the sky through the ball"));
        close(img[0], [0.6; 3], 3e-3, &format!("{mode:?}: the sky beside the ball"));
        images.push(img);
    }
    assert!(ball.iter().filter(|&&b| b).count() > 50, "the ball covers too few pixels");
    let worst = worst_relative(&images[0], &images[1]);
    println!("spectral against RGB, worst pixel {worst:.2e}");
    assert!(worst < 5e-3, "spectral and RGB differ by {worst}");
}

/// A clear coat (KHR_materials_clearcoat) on a see-through pane: what is seen through it is
/// kept by 1 − w, w = clearcoat·F(|v·n|) = 0.04·clearcoat head-on (the orthographic camera
/// looks along the pane's normal); with no light and no sky the coat reflects nothing. In the
/// RGB and spectral modes and through the general node loop (the capture).
#[test]
fn a_coated_pane_keeps_one_minus_the_coats_weight_of_what_is_seen_through_it() {
    let mut r = renderer();
    for (mode, capture) in [(Mode::Rgb, false), (Mode::Spectral, false), (Mode::Spectral, true)] {
        r.set_spectral_capture(capture);
        let bare = render(&mut r, &scene(Some(glass(1.0, 1.5, 1.0, None, 0.0)), false), mode);
        for strength in [1.0f32, 0.5] {
            let mut pane = glass(1.0, 1.5, 1.0, None, 0.0);
            pane.clearcoat = Some(scene::clearcoat::Clearcoat {
                factor: strength,
                texture: None,
                roughness: 0.2,
                roughness_texture: None,
                normal_texture: None,
                normal_scale: 1.0,
            });
            let img = render(&mut r, &scene(Some(pane), false), mode);
            let keep = 1.0 - 0.04 * f64::from(strength);
            close(
                at(&img, CENTRE),
                at(&bare, CENTRE).map(|c| keep * c),
                1e-3,
                &format!("{mode:?} capture {capture} clearcoat {strength}"),
            );
            assert_eq!(at(&img, BESIDE), at(&bare, BESIDE), "{mode:?}: the background changed");
        }
    }
    r.set_spectral_capture(false);
}
