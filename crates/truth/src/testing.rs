//! Small scenes built in code for the tests.

use glam::{Mat4, Vec3, Vec4};
use scene::{Camera, Light, Material, Mesh, Scene, SpectralSettings};

pub fn scene_with(meshes: Vec<Mesh>, materials: Vec<Material>, lights: Vec<Light>) -> Scene {
    Scene {
        warnings: vec![],
        source: "test".into(),
        meshes,
        materials,
        textures: vec![],
        lights,
        camera: Camera {
            ortho: None,
            transform: Mat4::IDENTITY,
            yfov: 0.8,
            znear: 0.01,
            zfar: 100.0,
            aspect: None,
        },
        spectral: SpectralSettings::default(),
        water: None,
        environment: None,
        medium: None,
        inputs: vec![],
        origin: glam::DVec3::ZERO,
        input_stamps: vec![],
        choices: vec![],
        animation_end: None,
    }
}

/// An axis-aligned box of half-size `h` around the origin, faces wound (and normals pointing)
/// inwards, so it is an enclosure seen from inside.
pub fn inward_box(h: f32, material: usize) -> Mesh {
    let mut m = Mesh { material, ..Default::default() };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = -sign * Vec3::from_array(std::array::from_fn(|i| if i == axis { 1.0 } else { 0.0 }));
            let c = -n * h;
            let u = Vec3::from_array(std::array::from_fn(|i| if i == (axis + 1) % 3 { h } else { 0.0 }));
            let v = n.cross(u);
            let base = m.positions.len() as u32;
            for p in [c - u - v, c + u - v, c + u + v, c - u + v] {
                m.positions.push(p);
                m.normals.push(n);
            }
            // Counter-clockwise seen from the side n points to.
            m.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    m
}

/// A quad with normal `n` (CCW seen from n), centre `c`, half-extent `h`.
pub fn quad(c: Vec3, n: Vec3, h: f32, material: usize) -> Mesh {
    let f = crate::sampling::Frame::from_normal(n.normalize());
    let (u, v) = (f.t * h, f.b * h);
    Mesh {
        positions: vec![c - u - v, c + u - v, c + u + v, c - u + v],
        normals: vec![f.n; 4],
        uvs: vec![
            glam::Vec2::new(0.0, 1.0),
            glam::Vec2::new(1.0, 1.0),
            glam::Vec2::new(1.0, 0.0),
            glam::Vec2::ZERO,
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
        ..Default::default()
    }
}

/// A UV sphere of radius `r` around `c`, `n` segments around and `n/2` from pole to pole,
/// wound counter-clockwise seen from outside, with no vertex normals (flat shading: the
/// shading normal is the geometric one, so a white Lambertian sphere conserves energy exactly).
pub fn sphere(c: Vec3, r: f32, n: u32, material: usize) -> Mesh {
    let rows = n / 2;
    let mut m = Mesh { material, ..Default::default() };
    for i in 0..=rows {
        let theta = std::f32::consts::PI * i as f32 / rows as f32;
        for j in 0..=n {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
            let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            m.positions.push(c + d * r);
        }
    }
    for i in 0..rows {
        for j in 0..n {
            let (a, b) = (i * (n + 1) + j, (i + 1) * (n + 1) + j);
            // (a+1 − a) × (b − a) ∝ ∂φ × ∂θ, which points outwards (the test below checks).
            if i > 0 {
                m.indices.extend([a, a + 1, b]);
            }
            if i + 1 < rows {
                m.indices.extend([a + 1, b + 1, b]);
            }
        }
    }
    m
}

#[test]
fn sphere_faces_outwards() {
    let m = sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, 16, 0);
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
        let n = (b - a).cross(c - a);
        assert!(n.length() > 0.0);
        assert!(n.dot((a + b + c) / 3.0 - Vec3::new(1.0, 2.0, 3.0)) > 0.0, "{t:?}");
    }
}

/// The extension tests' stage (specular, sheen): `materials[0]` on a sphere of radius 0.8 at
/// the origin, `materials[1]` on a floor under it, a point light above and in front, and a
/// uniform sky of 0.3, seen from the front.
pub fn sphere_on_floor(materials: Vec<Material>) -> Scene {
    let meshes = vec![sphere(Vec3::ZERO, 0.8, 16, 0), quad(Vec3::new(0.0, -0.8, 0.0), Vec3::Y, 3.0, 1)];
    let light = Light {
        name: "p".into(),
        kind: scene::LightKind::Point { position: Vec3::new(1.0, 2.0, 1.5), range: None },
        emission: scene::Emission { rgb: Vec3::ONE, intensity: 3.0, spectrum: None },
        stands_in_for: None,
    };
    let mut s = scene_with(meshes, materials, vec![light]);
    s.environment = Some(scene::Environment::uniform(Vec3::splat(0.3)));
    s.camera = Camera::look_at(Vec3::new(0.0, 0.7, 3.0), Vec3::ZERO, Vec3::Y, 0.9);
    s
}

/// [`sphere_on_floor`] with the extension tests' two materials: a coloured part-metal sphere
/// (base (0.8, 0.5, 0.2), metallic 0.4, roughness 0.35) and a grey floor (0.6, roughness 0.7),
/// each given the extension under test by `extend`.
pub fn two_materials_on_floor(extend: impl Fn(&mut Material)) -> Scene {
    let mut materials = vec![
        Material {
            base_color: Vec4::new(0.8, 0.5, 0.2, 1.0),
            metallic: 0.4,
            roughness: 0.35,
            ..Default::default()
        },
        Material { base_color: Vec4::new(0.6, 0.6, 0.6, 1.0), roughness: 0.7, ..Default::default() },
    ];
    materials.iter_mut().for_each(extend);
    sphere_on_floor(materials)
}

/// The directional albedo of `b` at cos θ_o = `c`, ∫ f·cos θ_i over the hemisphere by a midpoint
/// rule (600 × 300) of the tracer's own eval: what a furnace around the BRDF reflects.
pub fn directional_albedo(b: &crate::bsdf::Brdf, c: f32) -> Vec4 {
    hemisphere_albedo(b, Vec3::new((1.0 - c * c).max(0.0).sqrt(), 0.0, c), 600, 300)
}

/// ∫ f(wo, wi)·cos θ_i over the hemisphere by a midpoint rule of `nt` cos θ_i × `np` φ cells
/// (independent of the sampler).
pub fn hemisphere_albedo(b: &crate::bsdf::Brdf, wo: Vec3, nt: u32, np: u32) -> Vec4 {
    let mut a = Vec4::ZERO;
    for i in 0..nt {
        let ci = (i as f32 + 0.5) / nt as f32;
        let si = (1.0 - ci * ci).sqrt();
        for j in 0..np {
            let phi = 2.0 * std::f32::consts::PI * (j as f32 + 0.5) / np as f32;
            a += b.eval(wo, Vec3::new(si * phi.cos(), si * phi.sin(), ci)) * ci;
        }
    }
    a * (2.0 * std::f32::consts::PI / (nt * np) as f32)
}

/// A 16×12 render of `scene` at 8 samples a pixel (seed 3) with grey upsampling, Lambert-only or
/// not.
pub fn small_render(scene: &Scene, lambert: bool) -> crate::XyzImage {
    let st = crate::render::Settings { seed: 3, lambert, ..crate::render::Settings::new(16, 12, 8).unwrap() };
    crate::render::render(scene, &crate::upsample::GreyOnly, &st, &Default::default(), &|_| {}).unwrap()
}
