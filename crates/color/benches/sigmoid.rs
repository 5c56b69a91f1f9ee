//! Evaluation throughput of the sigmoid polynomial: `cargo bench -p color --bench sigmoid`.
//! Compares scalar `f64`, plain `f32` arrays (auto-vectorised), `wide::f32x4` and `f32x8`, and a
//! table fetch (trilinear interpolation) per colour.
use std::hint::black_box;

use color::upsample::{CoeffTable, SigmoidPolynomial};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use wide::{f32x4, f32x8};

const N: usize = 1024;

fn eval(c: &mut Criterion) {
    let p = SigmoidPolynomial::new(-2.1e-4, 0.23, -62.0);
    let lambda: Vec<f32> = (0..N).map(|i| 360.0 + 470.0 * i as f32 / N as f32).collect();
    let mut out = vec![0f32; N];
    let mut g = c.benchmark_group("sigmoid_eval");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("scalar_f64", |b| {
        b.iter(|| {
            for (o, l) in out.iter_mut().zip(&lambda) {
                *o = black_box(&p).eval(*l as f64) as f32;
            }
        })
    });
    g.bench_function("array_f32x8_autovec", |b| {
        b.iter(|| {
            for (o, l) in out.chunks_exact_mut(8).zip(lambda.chunks_exact(8)) {
                o.copy_from_slice(&black_box(&p).eval_array::<8>(l.try_into().unwrap()));
            }
        })
    });
    g.bench_function("wide_f32x4", |b| {
        b.iter(|| {
            for (o, l) in out.chunks_exact_mut(4).zip(lambda.chunks_exact(4)) {
                let v = black_box(&p).eval_f32x4(f32x4::from(<[f32; 4]>::try_from(l).unwrap()));
                o.copy_from_slice(&v.to_array());
            }
        })
    });
    g.bench_function("wide_f32x8", |b| {
        b.iter(|| {
            for (o, l) in out.chunks_exact_mut(8).zip(lambda.chunks_exact(8)) {
                let v = black_box(&p).eval_f32x8(f32x8::from(<[f32; 8]>::try_from(l).unwrap()));
                o.copy_from_slice(&v.to_array());
            }
        })
    });
    g.finish();
}

fn fetch(c: &mut Criterion) {
    // A synthetic 64³ table: fetch cost does not depend on the coefficient values.
    let res = 64;
    let scale = (0..res).map(|k| k as f32 / (res - 1) as f32).collect();
    let data = (0..CoeffTable::data_len(res)).map(|i| (i % 97) as f32 * 1e-3).collect();
    let t = CoeffTable { res, scale, chroma: color::upsample::table::uniform_chroma(res), data };
    let colours: Vec<[f64; 3]> =
        (0..N).map(|i| [(i % 13) as f64 / 13.0, (i % 7) as f64 / 7.0, (i % 31) as f64 / 31.0]).collect();
    let mut g = c.benchmark_group("table_fetch");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("fetch_trilinear", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for rgb in &colours {
                s += black_box(&t).fetch(*rgb).c[2];
            }
            s
        })
    });
    g.finish();
}

criterion_group!(benches, eval, fetch);
criterion_main!(benches);
