//! `cargo run --release -p fuzz -- TARGET [--execs N] [--seconds S] [--seed K]`
//!
//! Fuzzes one parser (gltf, coeff, csv, medium, rgb-medium, exr, png; `all` for each in turn) and prints
//! executions, time, crashes and the process's peak resident memory. Crashing inputs are
//! written to `crates/fuzz/crashes/<target>-<n>.bin` and the exit status is 1; each belongs in
//! a regression test once fixed; `TARGET --replay FILE` runs one input uncaught, for a backtrace.
//! `--keep-current` writes each input to `crashes/<target>-current.bin` before running it, so
//! an abort (a failed allocation) leaves its input behind. The acceptance run is
//! `--execs 1000000` per target.

use std::time::Instant;

fn peak_rss_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let get = |k: &str| args.iter().position(|a| a == k).and_then(|i| args.get(i + 1));
    let target = args.first().map(String::as_str).unwrap_or("all");
    let execs: u64 = get("--execs").map_or(1_000_000, |v| v.parse().expect("--execs N"));
    let seconds: f64 = get("--seconds").map_or(f64::INFINITY, |v| v.parse().expect("--seconds S"));
    let seed: u64 = get("--seed").map_or(1, |v| v.parse().expect("--seed K"));
    if let Some(file) = get("--replay") {
        // One input, panics not caught: for a backtrace (RUST_BACKTRACE=1).
        fuzz::run_one(target, &std::fs::read(file).expect("--replay FILE"));
        println!("{target}: {file}: no panic");
        return;
    }
    // Panics are caught and reported; the default hook would print each one.
    std::panic::set_hook(Box::new(|_| {}));
    let targets: Vec<&str> = if target == "all" { fuzz::TARGETS.to_vec() } else { vec![target] };
    let mut failed = false;
    for t in targets {
        let start = Instant::now();
        let current = args.iter().any(|a| a == "--keep-current").then(|| {
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("crashes");
            std::fs::create_dir_all(&dir).unwrap();
            dir.join(format!("{t}-current.bin"))
        });
        let r = fuzz::fuzz_with(t, seed, execs, seconds, current.as_deref());
        let secs = start.elapsed().as_secs_f64();
        println!(
            "{t}: {} executions in {secs:.1} s ({:.0}/s), {} crashes, peak RSS so far {} MiB",
            r.execs,
            r.execs as f64 / secs,
            r.crashes.len(),
            peak_rss_kib().map_or("?".into(), |k| (k / 1024).to_string())
        );
        if !r.crashes.is_empty() {
            failed = true;
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("crashes");
            std::fs::create_dir_all(&dir).unwrap();
            for (i, (input, msg)) in r.crashes.iter().enumerate().take(20) {
                let p = dir.join(format!("{t}-{i}.bin"));
                std::fs::write(&p, input).unwrap();
                println!("  crash {}: {msg}", p.display());
            }
        }
    }
    std::process::exit(i32::from(failed));
}
