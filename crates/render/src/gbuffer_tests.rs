//! The G-buffer's packed normal target (`gbuffer_pack_normal` and its readers in
//! wgsl/common.wgsl) on the GPU: the normal comes back within 7·10⁻⁵ rad everywhere on the
//! sphere (the three f16 components it replaced rounded by up to 2.4·10⁻⁴ each), the roughness
//! as the nearest f16 (every f16 of the normal range exactly), and the material's slot exactly
//! over its whole range.
//!
//! The bound: each octahedral coordinate is rounded by at most half a step, 1/65534; the
//! unpacked vector's three components then move by at most √6/65534 together, and its length is
//! least, 1/√3, at the faces' centres (|x| = |y| = |z|), so the direction turns by at most
//! √18/65534 = 6.5·10⁻⁵ rad, plus f32 rounding.

use crate::gpu::Gpu;

/// Directions: a Fibonacci sphere, the axes, the octahedron's edges and folds (where the lower
/// hemisphere's mapping turns over), and points a hair off them.
fn directions() -> Vec<[f64; 3]> {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let n = 20_000;
    for i in 0..n {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let a = i as f64 * 2.399_963_229_728_653;
        v.push([r * a.cos(), r * a.sin(), z]);
    }
    for a in [-1.0, -1e-7, 0.0, 1e-7, 1.0] {
        for b in [-1.0, -1e-7, 0.0, 1e-7, 1.0] {
            for c in [-1.0, -1e-7, 0.0, 1e-7, 1.0] {
                v.push([a, b, c]);
            }
        }
    }
    v.into_iter()
        .filter_map(|d| {
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            (l > 0.5).then(|| [d[0] / l, d[1] / l, d[2] / l])
        })
        .collect()
}

#[test]
fn the_packed_normal_roughness_and_slot_come_back() {
    let dirs = directions();
    let slots = [0u32, 1, 2, 255, 256, 2048, 2049, 40_000, crate::scene_gpu::MAX_MATERIALS as u32 + 1];
    // (x, y, z, roughness) per case, the slot from the case's index.
    let args: Vec<[f32; 4]> =
        dirs.iter().enumerate().map(|(i, d)| [d[0] as f32, d[1] as f32, d[2] as f32, roughness(i)]).collect();
    let gpu = Gpu::headless().unwrap_or_else(|e| panic!("{e}\n{}", Gpu::install_help()));
    let (device, queue) = (&gpu.device, &gpu.queue);
    let slot_list = slots.iter().map(|s| format!("{s}u")).collect::<Vec<_>>().join(", ");
    let src = format!(
        "{}\n@group(0) @binding(0) var<storage, read> args: array<vec4<f32>>;\n\
         @group(0) @binding(1) var<storage, read_write> r_out: array<vec4<f32>>;\n\
         const SLOTS = array<u32, {}>({slot_list});\n\
         @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
         if (id.x >= arrayLength(&args)) {{ return; }}\n\
         let a = args[id.x];\n\
         let t = gbuffer_pack_normal(a.xyz, a.w, SLOTS[id.x % {}u]);\n\
         let n = gbuffer_normal(t);\n\
         r_out[2u * id.x] = vec4<f32>(n, gbuffer_roughness(t));\n\
         r_out[2u * id.x + 1u] = vec4<f32>(f32(gbuffer_slot(t)), 0.0, 0.0, 0.0);\n}}\n",
        crate::shader::COMMON,
        slots.len(),
        slots.len(),
    );
    let bytes = crate::compute_tests::run_on(
        device,
        queue,
        src,
        args.len(),
        (args.len() * 32) as u64,
        bytemuck::cast_slice(&args),
    );
    let out: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();
    let (mut worst_angle, mut worst_dir) = (0.0f64, [0.0; 3]);
    let mut worst_roughness = 0.0f64;
    for (i, (d, a)) in dirs.iter().zip(&args).enumerate() {
        let n = out[2 * i];
        let cross = [
            d[1] * f64::from(n[2]) - d[2] * f64::from(n[1]),
            d[2] * f64::from(n[0]) - d[0] * f64::from(n[2]),
            d[0] * f64::from(n[1]) - d[1] * f64::from(n[0]),
        ];
        let dot = d[0] * f64::from(n[0]) + d[1] * f64::from(n[1]) + d[2] * f64::from(n[2]);
        let angle = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt().atan2(dot);
        if angle > worst_angle || angle.is_nan() {
            (worst_angle, worst_dir) = (if angle.is_nan() { f64::INFINITY } else { angle }, *d);
        }
        // The axes (a flat floor, a wall, a test chart facing the camera) come back exactly.
        if d.iter().filter(|c| c.abs() == 1.0).count() == 1 {
            assert!(angle == 0.0, "axis {d:?} came back as {n:?}");
        }
        let rel = (f64::from(n[3]) - f64::from(a[3])).abs() / f64::from(a[3]);
        if a[3] >= 2f32.powi(-14) {
            worst_roughness = worst_roughness.max(rel);
        } else {
            assert_eq!(n[3], 0.0, "roughness {} below f16's normal range", a[3]);
        }
        if i % 2 == 1 && a[3] >= 2f32.powi(-14) {
            assert_eq!(n[3], a[3], "roughness {} is an f16 and should come back exactly", a[3]);
        }
        assert_eq!(out[2 * i + 1][0], slots[i % slots.len()] as f32, "slot of case {i}");
    }
    eprintln!(
        "packed G-buffer normal over {} directions: worst {worst_angle:.2e} rad at {worst_dir:?}; roughness worst relative {worst_roughness:.2e}",
        dirs.len()
    );
    assert!(worst_angle <= 7e-5, "normal off by {worst_angle} rad at {worst_dir:?}");
    // Half an f16 step: 2⁻¹¹ of the value.
    assert!(worst_roughness <= 2f64.powi(-11), "roughness off by {worst_roughness} (relative)");
}

/// Roughness of case i: thousandths, and f16 values over [0, 1] (what the f16 channel held).
fn roughness(i: usize) -> f32 {
    if i.is_multiple_of(2) {
        (i / 2 % 1001) as f32 / 1000.0
    } else {
        // f16 bit patterns from 0 to 0x3c00 (1.0, the first odd case), spread over the odd cases.
        let bits = if i == 1 { 0x3c00 } else { (i / 2 * 7) % 0x3c01 };
        f16_bits_to_f32(bits as u16)
    }
}

fn f16_bits_to_f32(h: u16) -> f32 {
    let e = (h >> 10) & 0x1f;
    let m = f32::from(h & 0x3ff);
    if e == 0 { m * 2f32.powi(-24) } else { (1.0 + m / 1024.0) * 2f32.powi(i32::from(e) - 15) }
}
