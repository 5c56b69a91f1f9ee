//! Prints `scene::film::reflectance` for each line of stdin, `λ_nm cos_i thickness_nm film_ior
//! base_n base_k` (for tools/check_film.py, which compares with a transfer-matrix oracle).

use std::io::{BufRead, Write};

fn main() {
    let stdin = std::io::stdin();
    let mut out = std::io::BufWriter::new(std::io::stdout());
    for (i, line) in stdin.lock().lines().enumerate() {
        let line = line.expect("reading stdin");
        let v: Vec<f64> = line.split_whitespace().map(|x| x.parse().expect("a number")).collect();
        let [l, c, d, nf, n, k] = v[..] else {
            eprintln!("line {}: want 6 numbers, got {}", i + 1, v.len());
            std::process::exit(2);
        };
        let r = scene::film::reflectance(l, c, d, nf, num_complex::Complex64::new(n, k));
        writeln!(out, "{r:.17e}").expect("writing stdout");
    }
}
