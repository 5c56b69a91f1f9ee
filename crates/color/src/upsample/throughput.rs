//! Evaluation throughput of the sigmoid polynomial: scalar `f64` against `f32` plain arrays
//! (left to the auto-vectoriser), `wide::f32x4` and `wide::f32x8`. Used by
//! `spectra upsample --bench`; `benches/sigmoid.rs` measures the same with criterion.

use std::hint::black_box;
use std::time::Instant;

use wide::{f32x4, f32x8};

use crate::upsample::sigmoid::SigmoidPolynomial;

/// Samples per second on one thread for each path, evaluating `n` wavelengths `reps` times.
pub fn measure(p: &SigmoidPolynomial, n: usize, reps: usize) -> Vec<(&'static str, f64)> {
    let n = n.max(8) / 8 * 8;
    let lambda: Vec<f32> = (0..n).map(|i| 360.0 + 470.0 * i as f32 / n as f32).collect();
    let mut out = vec![0f32; n];
    let mut results = Vec::new();
    let mut time = |name: &'static str, f: &mut dyn FnMut(&mut [f32])| {
        f(&mut out);
        let t0 = Instant::now();
        for _ in 0..reps {
            f(&mut out);
        }
        results.push((name, (n * reps) as f64 / t0.elapsed().as_secs_f64()));
        black_box(&out);
    };
    time("scalar f64", &mut |out| {
        for (o, l) in out.iter_mut().zip(&lambda) {
            *o = black_box(p).eval(*l as f64) as f32;
        }
    });
    time("f32 arrays of 8 (auto-vectorised)", &mut |out| {
        for (o, l) in out.chunks_exact_mut(8).zip(lambda.chunks_exact(8)) {
            o.copy_from_slice(&black_box(p).eval_array::<8>(l.try_into().unwrap()));
        }
    });
    time("f32x4 (wide)", &mut |out| {
        for (o, l) in out.chunks_exact_mut(4).zip(lambda.chunks_exact(4)) {
            let v = black_box(p).eval_f32x4(f32x4::from(<[f32; 4]>::try_from(l).unwrap()));
            o.copy_from_slice(&v.to_array());
        }
    });
    time("f32x8 (wide)", &mut |out| {
        for (o, l) in out.chunks_exact_mut(8).zip(lambda.chunks_exact(8)) {
            let v = black_box(p).eval_f32x8(f32x8::from(<[f32; 8]>::try_from(l).unwrap()));
            o.copy_from_slice(&v.to_array());
        }
    });
    results
}
