//! glTF features the tracer honours beyond plain opaque materials (issue 12): `COLOR_0`,
//! `TEXCOORD_1` with `KHR_texture_transform`, single-sided materials, alpha MASK and BLEND (for
//! camera, shadow and emitter rays alike).
//!
//! The scenes are a floor lit by a point light (or a lamp) with a quad between the two; the
//! camera rays start between the quad and the floor and look down, so they see the floor
//! whatever the quad is, and only the shadow rays cross the quad (unless a test says otherwise).

use crate::integrator::Integrator;
use crate::material::{self, PreparedMaterial, TexCoords};
use crate::rng::Sampler;
use crate::spectral::Wavelengths;
use crate::testing::{quad, scene_with};
use crate::upsample::GreyOnly;
use crate::world::World;
use color::{Spectrum, WavelengthRange};
use glam::{Vec2, Vec3, Vec4};
use scene::{
    AlphaMode, Emission, Filter, Light, LightKind, Material, Scene, Texture, TextureRef, TextureTransform,
};

fn d65() -> Spectrum {
    color::illuminant::by_name("D65").unwrap()
}

fn wl() -> Wavelengths {
    Wavelengths(Vec4::new(450.0, 520.0, 590.0, 660.0))
}

fn world(scene: &Scene) -> World<'_> {
    World::new(scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, None).unwrap()
}

fn grey(g: f32) -> Material {
    Material { base_color: Vec4::new(g, g, g, 1.0), ..Default::default() }
}

fn point_light(at: Vec3) -> Light {
    Light {
        name: "p".into(),
        kind: LightKind::Point { position: at, range: None },
        emission: Emission { rgb: Vec3::ONE, intensity: 5.0, spectrum: Some(d65()) },
        stands_in_for: None,
    }
}

/// A floor (material 0) at y = 0 facing up, a quad (material 1, normal `n`) at y = 1, and a
/// point light at y = 2.
fn floor_quad_light(quad_material: Material, n: Vec3) -> Scene {
    scene_with(
        vec![quad(Vec3::ZERO, Vec3::Y, 2.0, 0), quad(Vec3::Y, n, 1.0, 1)],
        vec![grey(0.8), quad_material],
        vec![point_light(Vec3::new(0.0, 2.0, 0.0))],
    )
}

/// Direct light leaving floor point `at` upwards, one path (Lambert, four lanes).
fn floor_radiance(w: &World, at: Vec3, rng: &mut Sampler) -> Vec4 {
    let integ = Integrator { world: w, direct_only: true, max_depth: 4, lambert: true };
    integ.radiance(at + Vec3::Y * 0.5, -Vec3::Y, &wl(), rng)
}

/// Mean and standard error over `n` paths of the first lane.
fn mean_se(n: usize, seed: u64, mut f: impl FnMut(&mut Sampler) -> f32) -> (f64, f64) {
    let mut rng = Sampler::new(seed, 0);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let v = f(&mut rng) as f64;
        s += v;
        s2 += v * v;
    }
    let m = s / n as f64;
    (m, ((s2 / n as f64 - m * m).max(0.0) / (n as f64 - 1.0)).sqrt())
}

fn tex(w: u32, h: u32, px: &[[u8; 4]], mag: Filter) -> Texture {
    Texture {
        name: "t".into(),
        width: w,
        height: h,
        rgba8: px.concat(),
        srgb: false,
        sampler: scene::Sampler { mag, ..Default::default() },
    }
}

/// `COLOR_0` multiplies the base colour per channel (red × cyan is black, not a third of a
/// grey), and its alpha multiplies the alpha; the surface point interpolates it.
#[test]
fn vertex_colour_multiplies_base_colour() {
    let red = Material { base_color: Vec4::new(1.0, 0.0, 0.0, 0.8), ..Default::default() };
    let pm = PreparedMaterial::new(&red, WavelengthRange::VISIBLE);
    let refl =
        |c: Vec4| material::base_reflectance(&red, &pm, &[], &GreyOnly, &TexCoords::default(), c, wl().0);
    assert!((refl(Vec4::ONE) - Vec4::splat(1.0 / 3.0)).abs().max_element() < 1e-4);
    assert!(refl(Vec4::new(0.0, 1.0, 1.0, 1.0)).max_element() < 1e-4);
    assert!(
        (material::alpha(&red, &[], &TexCoords::default(), Vec4::new(1.0, 1.0, 1.0, 0.5)) - 0.4).abs() < 1e-6
    );

    let mut floor = quad(Vec3::ZERO, Vec3::Y, 1.0, 0);
    floor.colors = vec![Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, 1.0), Vec4::ZERO, Vec4::ZERO];
    let scene = scene_with(vec![floor], vec![Material::default()], vec![]);
    let w = world(&scene);
    // Halfway along the edge from vertex 0 to vertex 1 (triangle 0 = vertices 0, 1, 2).
    let s = w.point_on(0, 0.5, 0.0);
    assert!((s.color - Vec4::new(0.5, 0.5, 0.0, 1.0)).abs().max_element() < 1e-6, "{}", s.color);

    // Through the integrator: a white floor coloured (1, 0.5, 0) reflects half as much as white
    // under GreyOnly (mean of the RGB), exactly.
    let lit = |colors: Vec<Vec4>| {
        let mut floor = quad(Vec3::ZERO, Vec3::Y, 2.0, 0);
        floor.colors = colors;
        let scene = scene_with(vec![floor], vec![grey(0.9)], vec![point_light(Vec3::new(0.0, 2.0, 0.0))]);
        floor_radiance(&world(&scene), Vec3::new(0.2, 0.0, 0.1), &mut Sampler::new(1, 1))
    };
    let (white, coloured) = (lit(vec![]), lit(vec![Vec4::new(1.0, 0.5, 0.0, 1.0); 4]));
    assert!(white.x > 0.0 && (coloured / white - Vec4::splat(0.5)).abs().max_element() < 1e-4);
}

/// A texture on `TEXCOORD_1` reads the second UV set, through its `KHR_texture_transform`;
/// the surface point carries both sets.
#[test]
fn texcoord1_and_transform_select_texels() {
    let ramp = tex(
        4,
        1,
        &[[0, 0, 0, 255], [85, 85, 85, 255], [170, 170, 170, 255], [255, 255, 255, 255]],
        Filter::Nearest,
    );
    let tc = TexCoords([Vec2::new(0.3, 0.5), Vec2::new(0.2, 0.5)]);
    let value = |r: TextureRef| {
        let m = Material { base_color_texture: Some(r), ..Default::default() };
        let pm = PreparedMaterial::new(&m, WavelengthRange::VISIBLE);
        let g = material::base_reflectance(
            &m,
            &pm,
            std::slice::from_ref(&ramp),
            &GreyOnly,
            &tc,
            Vec4::ONE,
            wl().0,
        )
        .x;
        (g * 255.0).round()
    };
    let shift = Some(TextureTransform { offset: Vec2::new(0.5, 0.0), rotation: 0.0, scale: Vec2::ONE });
    assert_eq!(value(TextureRef { index: 0, tex_coord: 0, transform: None }), 85.0);
    assert_eq!(value(TextureRef { index: 0, tex_coord: 1, transform: None }), 0.0);
    assert_eq!(value(TextureRef { index: 0, tex_coord: 0, transform: shift }), 255.0);
    assert_eq!(value(TextureRef { index: 0, tex_coord: 1, transform: shift }), 170.0);
    // Rotation and scale as `TextureTransform::apply` defines them.
    let turn = TextureTransform {
        offset: Vec2::ZERO,
        rotation: std::f32::consts::FRAC_PI_2,
        scale: Vec2::splat(2.0),
    };
    let r = TextureRef { index: 0, tex_coord: 1, transform: Some(turn) };
    assert_eq!(tc.at(&r), turn.apply(Vec2::new(0.2, 0.5)));

    let mut m = quad(Vec3::ZERO, Vec3::Y, 1.0, 0);
    m.uvs1 = vec![Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0), Vec2::new(4.0, 2.0), Vec2::new(0.0, 2.0)];
    let scene = scene_with(vec![m], vec![Material::default()], vec![]);
    let s = world(&scene).point_on(0, 0.5, 0.25);
    assert!((s.tc.0[1] - Vec2::new(3.0, 0.5)).length() < 1e-6, "{:?}", s.tc);
    assert!((s.tc.0[0] - Vec2::new(0.75, 0.75)).length() < 1e-6, "{:?}", s.tc);
}

/// A single-sided quad seen from behind is not there for camera rays (what lies behind it
/// shows) nor for shadow rays; double-sided it is drawn and casts its shadow.
#[test]
fn single_sided_back_faces_are_invisible() {
    // Camera rays: a black quad facing away from the camera, a lamp behind it.
    let lamp = Material { emissive: Vec3::ONE, ..Default::default() };
    for (double_sided, facing_camera, want_lamp) in
        [(false, false, true), (true, false, false), (false, true, false), (true, true, false)]
    {
        let black =
            Material { base_color: Vec4::new(0.0, 0.0, 0.0, 1.0), double_sided, ..Default::default() };
        let n = if facing_camera { Vec3::Z } else { -Vec3::Z };
        let scene = scene_with(
            vec![quad(Vec3::ZERO, n, 1.0, 0), quad(-Vec3::Z, Vec3::Z, 2.0, 1)],
            vec![black, lamp.clone()],
            vec![],
        );
        let w = world(&scene);
        let integ = Integrator { world: &w, direct_only: false, max_depth: 8, lambert: true };
        let l = integ.radiance(Vec3::new(0.1, 0.2, 3.0), -Vec3::Z, &wl(), &mut Sampler::new(2, 0));
        let lamp_l = w.emitted(&w.point_on(2, 0.3, 0.3), Vec3::Z, wl().0);
        let want = if want_lamp { lamp_l } else { Vec4::ZERO };
        assert_eq!(l, want, "double-sided {double_sided}, facing the camera {facing_camera}");
        let hit = w.intersect(Vec3::new(0.1, 0.2, 3.0), -Vec3::Z, f32::INFINITY, 0).unwrap();
        assert_eq!(hit.t > 3.5, want_lamp);
    }

    // Shadow rays run from the floor up to the light: a single-sided quad facing the light is
    // seen from behind by them and casts no shadow; facing the floor (or double-sided) it does.
    let at = Vec3::new(0.2, 0.0, -0.1);
    let reference =
        floor_radiance(&world(&floor_quad_light(grey(0.0), Vec3::Y)), at, &mut Sampler::new(1, 1));
    let unblocked = {
        let scene = scene_with(
            vec![quad(Vec3::ZERO, Vec3::Y, 2.0, 0)],
            vec![grey(0.8)],
            vec![point_light(Vec3::new(0.0, 2.0, 0.0))],
        );
        floor_radiance(&world(&scene), at, &mut Sampler::new(1, 1))
    };
    assert_eq!(reference, Vec4::ZERO, "double-sided quad shadows the floor");
    assert!(unblocked.x > 0.0);
    for (n, lit) in [(Vec3::Y, true), (-Vec3::Y, false)] {
        let single = Material { double_sided: false, ..grey(0.0) };
        let l = floor_radiance(&world(&floor_quad_light(single, n)), at, &mut Sampler::new(1, 1));
        assert_eq!(l, if lit { unblocked } else { Vec4::ZERO }, "single-sided quad with normal {n}");
    }
}

/// An alpha-masked quad (left half of its texture transparent) between a point light and the
/// floor: light passes through the cut-out, unchanged, and nowhere else; camera rays see
/// through the cut-out too. Alpha = texture × factor × `COLOR_0`: the same cut-out made by
/// vertex alpha 0.6 against a cutoff of 0.5 keeps the quad opaque, by 0.4 removes it.
#[test]
fn alpha_mask_lets_light_through_its_cut_out() {
    let cutout = tex(2, 1, &[[255, 255, 255, 0], [255, 255, 255, 255]], Filter::Nearest);
    let masked = Material {
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        base_color_texture: Some(TextureRef::new(0)),
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..Default::default()
    };
    let mut scene = floor_quad_light(masked.clone(), -Vec3::Y);
    scene.textures = vec![cutout];
    let mut open = scene.clone();
    open.meshes.truncate(1);
    let (w, w_open) = (world(&scene), world(&open));
    let (mut seen_cut, mut seen_solid) = (false, false);
    for x in [-0.6f32, -0.3, 0.3, 0.6] {
        for z in [-0.4f32, 0.4] {
            let at = Vec3::new(x, 0.0, z);
            // Which half of the texture lies above this point (the quad's UV orientation is
            // whatever `quad` makes it).
            let to_light = (Vec3::new(0.0, 2.0, 0.0) - at).normalize();
            let h = w.geometry.intersect(at + to_light * 0.1, to_light, f32::INFINITY).unwrap();
            let cut = w.surface(&h).tc.0[0].x < 0.5;
            (seen_cut, seen_solid) = (seen_cut || cut, seen_solid || !cut);
            let l = floor_radiance(&w, at, &mut Sampler::new(1, 1));
            let free = floor_radiance(&w_open, at, &mut Sampler::new(1, 1));
            assert!(free.x > 0.0);
            assert_eq!(l, if cut { free } else { Vec4::ZERO }, "at {at}, cut-out {cut}");
            // A camera ray from above the quad, straight down to the same point (it crosses the
            // quad in the same half as the shadow ray does).
            let from_above = w.intersect(at + Vec3::Y * 1.5, -Vec3::Y, f32::INFINITY, 0).unwrap();
            assert_eq!(from_above.t > 1.0, cut, "camera ray at {at}");
        }
    }
    assert!(seen_cut && seen_solid);

    // Vertex alpha against the cutoff, no texture.
    for (a, lit) in [(0.6, false), (0.4, true)] {
        let m = Material { alpha_mode: AlphaMode::Mask { cutoff: 0.5 }, ..grey(0.0) };
        let mut scene = floor_quad_light(m, -Vec3::Y);
        scene.meshes[1].colors = vec![Vec4::new(1.0, 1.0, 1.0, a); 4];
        let l = floor_radiance(&world(&scene), Vec3::new(0.1, 0.0, 0.1), &mut Sampler::new(1, 1));
        assert_eq!(l.x > 0.0, lit, "vertex alpha {a}");
    }
}

/// A BLEND quad of alpha 0.5 between a point light and the floor lets through half the light
/// on average (each shadow ray passes with probability 0.5); seen through the quad as well
/// (camera ray and shadow ray each pass independently) the floor gets a quarter. Alpha from the
/// factor or from `COLOR_0`, alike.
#[test]
fn alpha_blend_transmits_in_proportion() {
    let at = Vec3::new(0.1, 0.0, 0.2);
    let free = {
        let scene = scene_with(
            vec![quad(Vec3::ZERO, Vec3::Y, 2.0, 0)],
            vec![grey(0.8)],
            vec![point_light(Vec3::new(0.0, 2.0, 0.0))],
        );
        floor_radiance(&world(&scene), at, &mut Sampler::new(1, 1)).x as f64
    };
    let blend = Material { alpha_mode: AlphaMode::Blend, ..grey(0.0) };
    let variants = [
        (Material { base_color: Vec4::new(0.0, 0.0, 0.0, 0.5), ..blend.clone() }, vec![]),
        (blend, vec![Vec4::new(1.0, 1.0, 1.0, 0.5); 4]),
    ];
    for (k, (m, colors)) in variants.into_iter().enumerate() {
        let mut scene = floor_quad_light(m, -Vec3::Y);
        scene.meshes[1].colors = colors;
        let w = world(&scene);
        assert!(w.stochastic);
        let (below, se) = mean_se(4000, 7 + k as u64, |rng| floor_radiance(&w, at, rng).x);
        assert!((below - 0.5 * free).abs() <= 5.0 * se, "variant {k}: {below} ± {se} vs {}", 0.5 * free);
        let integ = Integrator { world: &w, direct_only: true, max_depth: 4, lambert: true };
        let (above, se) =
            mean_se(4000, 9 + k as u64, |rng| integ.radiance(at + Vec3::Y * 1.5, -Vec3::Y, &wl(), rng).x);
        assert!((above - 0.25 * free).abs() <= 5.0 * se, "variant {k}: {above} ± {se} vs {}", 0.25 * free);
        // Reproducible: the decisions come from the path's sampler.
        let one = |seed| floor_radiance(&w, at, &mut Sampler::new(seed, 3));
        assert_eq!(one(5), one(5));
    }
}

/// A BLEND lamp of alpha 0.5 lights the floor half as much as the opaque lamp: light sampling
/// weights its points by their coverage and BRDF-sampled rays pass through it half the time,
/// and MIS combines the two unbiasedly.
#[test]
fn alpha_blend_emitter_emits_in_proportion() {
    let lit = |alpha_mode, seed| {
        let lamp = Material {
            base_color: Vec4::new(0.0, 0.0, 0.0, 0.5),
            emissive: Vec3::ONE,
            alpha_mode,
            ..Default::default()
        };
        let scene = scene_with(
            vec![quad(Vec3::ZERO, Vec3::Y, 2.0, 0), quad(Vec3::Y, -Vec3::Y, 0.5, 1)],
            vec![grey(0.8), lamp],
            vec![],
        );
        let w = world(&scene);
        mean_se(6000, seed, |rng| floor_radiance(&w, Vec3::new(0.3, 0.0, 0.0), rng).x)
    };
    let (opaque, se_o) = lit(AlphaMode::Opaque, 1);
    let (half, se_h) = lit(AlphaMode::Blend, 2);
    assert!(opaque > 0.0);
    let tol = 5.0 * (se_h * se_h + 0.25 * se_o * se_o).sqrt();
    assert!((half - 0.5 * opaque).abs() <= tol, "{half} vs {} ± {tol}", 0.5 * opaque);
}

#[test]
fn nan_alpha_cutoff_is_an_error() {
    let m = Material { alpha_mode: AlphaMode::Mask { cutoff: f32::NAN }, ..Default::default() };
    let scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 1.0, 0)], vec![m], vec![]);
    let e = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, None).err().unwrap();
    assert!(e.to_string().contains("alpha cutoff"), "{e}");
}

#[test]
fn unlit_surfaces_emit_their_base_colour_and_reflect_nothing() {
    // A grey unlit quad at y = 1 under the point light, seen from above: its colour × COLOR_0,
    // upsampled as RGB emission, whatever the light; with every bounce allowed, the path ends
    // on it (nothing reflected, so no noise at all).
    let unlit = Material { unlit: true, ..grey(0.5) };
    let mut s = floor_quad_light(unlit, Vec3::Y);
    s.meshes[1].colors = vec![Vec4::new(1.2, 1.2, 1.2, 1.0); s.meshes[1].positions.len()];
    let mut dark = s.clone();
    dark.lights.clear();
    let expected = {
        let w = world(&s);
        w.units.rgb(Vec3::splat(0.6), &GreyOnly, wl().0)
    };
    for scene in [&s, &dark] {
        let w = world(scene);
        let integ = Integrator { world: &w, direct_only: false, max_depth: 8, lambert: false };
        let mut rng = Sampler::new(7, 0);
        for _ in 0..16 {
            let l = integ.radiance(Vec3::new(0.1, 1.5, 0.2), -Vec3::Y, &wl(), &mut rng);
            assert!((l - expected).abs().max_element() < 1e-5 * expected.max_element(), "{l} vs {expected}");
        }
    }
    // Not a light source: next-event estimation never samples it.
    assert_eq!(world(&dark).emitters.pmf.iter().sum::<f32>(), 0.0);
}

/// `KHR_materials_iridescence` reaches the BRDF with each lane's wavelength: a black
/// dielectric floor under a point light, seen at 45°, reflects only its specular lobe, so the
/// film's direct radiance over the plain floor's is, lane by lane, the film's reflectance over
/// Schlick's at v·h — and a factor of 0 is no film at all.
#[test]
fn iridescence_replaces_the_specular_fresnel_per_wavelength() {
    let film = scene::Iridescence {
        factor: 1.0,
        texture: None,
        ior: 1.33,
        thickness_min: 100.0,
        thickness_max: 380.0,
        thickness_texture: None,
    };
    let floor = |ir: Option<scene::Iridescence>| Material {
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        roughness: 0.5,
        iridescence: ir,
        ..Default::default()
    };
    let render = |m: Material| {
        let s = scene_with(
            vec![quad(Vec3::ZERO, Vec3::Y, 4.0, 0)],
            vec![m],
            vec![point_light(Vec3::new(0.0, 2.0, 0.0))],
        );
        let w = world(&s);
        let integ = Integrator { world: &w, direct_only: true, max_depth: 4, lambert: false };
        let o = Vec3::new(1.0, 1.0, 0.0);
        integ.radiance(o, -o.normalize(), &wl(), &mut Sampler::new(1, 0))
    };
    let plain = render(floor(None));
    let with = render(floor(Some(film.clone())));
    assert_eq!(render(floor(Some(scene::Iridescence { factor: 0.0, ..film.clone() }))), plain);
    let v = Vec3::new(1.0, 1.0, 0.0).normalize();
    let v_h = v.dot((v + Vec3::Y).normalize()) as f64;
    let schlick = 0.04 + 0.96 * (1.0 - v_h).powi(5);
    for i in 0..4 {
        let r = scene::film::reflectance(
            f64::from(wl().0[i]),
            v_h,
            380.0,
            1.33,
            num_complex::Complex64::new(1.5, 0.0),
        );
        let got = f64::from(with[i] / plain[i]);
        assert!((got - r / schlick).abs() < 1e-4 * (r / schlick), "lane {i}: {got} vs {}", r / schlick);
    }
    assert!(plain.min_element() > 0.0);
}
