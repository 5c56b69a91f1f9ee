//! Coefficients for many colours through a table, for the oracle scripts in `tools/`:
//! `cargo run --release -p color --example fetch_batch -- FILE.coeff < rgb.txt` reads one
//! "R G B" per line and prints "c0 c1 c2" (nanometre coefficients, `CoeffTable::fetch`).
use std::io::{BufRead, Write};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: fetch_batch FILE.coeff < rgb.txt")?;
    let t = color::upsample::CoeffTable::read(std::path::Path::new(&path))?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for (n, line) in std::io::stdin().lock().lines().enumerate() {
        let line = line?;
        let v: Vec<f64> = line.split_whitespace().map(str::parse).collect::<Result<_, _>>()?;
        let rgb: [f64; 3] = v.as_slice().try_into().map_err(|_| format!("line {}: expected R G B", n + 1))?;
        let c = t.fetch_checked(rgb)?.c;
        writeln!(out, "{:.9e} {:.9e} {:.9e}", c[0], c[1], c[2])?;
    }
    Ok(())
}
