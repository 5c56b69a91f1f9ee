//! The WGSL thin film (wgsl/film.wgsl) against `scene::film` (issue 30: the GPU per-node value
//! equals the CPU one to 1e-3), on the glTF bases: 1.5 and metals' F0 as an index, films of
//! index 1.2–2.0 and 0–1200 nm, 380–780 nm, 0–89°.

use crate::gpu::Gpu;
use wgpu::util::DeviceExt;

/// (λ, cos θ, thickness, film IOR, base IOR) cases and their f64 reflectance.
fn cases() -> Vec<([f32; 5], f64)> {
    let mut v = Vec::new();
    let bases: Vec<f64> =
        [0.04, 0.02, 0.3, 0.6, 0.9, 0.9999].iter().map(|&f0| scene::film::ior_from_f0(f0)).collect();
    for lambda in [380.0, 455.0, 550.0, 633.0, 780.0] {
        for deg in [0.0f64, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0] {
            for d in [0.0, 1.0, 120.0, 275.0, 400.0, 777.0, 1200.0] {
                for nf in [1.2, 1.33, 1.5, 2.0] {
                    for &nb in &bases {
                        let c = deg.to_radians().cos();
                        let film = scene::film::Film { thickness_nm: d, ior: nf };
                        let r = film.over_dielectric(lambda, c, nb);
                        v.push(([lambda as f32, c as f32, d as f32, nf as f32, nb as f32], r));
                    }
                }
            }
        }
    }
    v
}

#[test]
fn wgsl_film_matches_the_cpu() {
    let cases = cases();
    let gpu = Gpu::headless().unwrap_or_else(|e| panic!("{e}\n{}", Gpu::install_help()));
    let (device, queue) = (&gpu.device, &gpu.queue);
    let src = format!(
        "{}\n{}\n@group(0) @binding(0) var<storage, read> args: array<f32>;\n\
         @group(0) @binding(1) var<storage, read_write> r_out: array<f32>;\n\
         @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         if (id.x >= arrayLength(&r_out)) {{ return; }}\n\
         let i = 5u * id.x;\n\
         r_out[id.x] = film_reflectance(args[i], args[i + 1u], args[i + 2u], args[i + 3u], args[i + 4u]);\n}}\n",
        crate::shader::COMMON,
        crate::shader::FILM,
    );
    let args: Vec<f32> = cases.iter().flat_map(|(a, _)| *a).collect();
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&args),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes =
        crate::compute_tests::run(device, queue, src, cases.len(), (cases.len() * 4) as u64, |p, output| {
            vec![device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &p.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
                ],
            })]
        });
    let out: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
    let mut worst = (0.0f64, [0.0f32; 5]);
    for ((a, cpu), gpu) in cases.iter().zip(&out) {
        let e = (f64::from(*gpu) - cpu).abs();
        if e > worst.0 || !gpu.is_finite() {
            worst = (if gpu.is_finite() { e } else { f64::INFINITY }, *a);
        }
    }
    eprintln!(
        "WGSL film vs scene::film over {} cases: max |ΔR| {:.2e} at {:?}",
        cases.len(),
        worst.0,
        worst.1
    );
    assert!(worst.0 <= 1e-3, "WGSL film vs CPU: |ΔR| {} at (λ, cos, d, film, base) {:?}", worst.0, worst.1);
}
