//! A fuzz harness for every parser of untrusted input, on stable Rust (no libFuzzer, no
//! nightly): a small mutator over a seed corpus kept in `corpus/<target>/`, each input run under
//! `catch_unwind`. A panic is a failure (the parsers must return errors); memory is bounded by
//! the parsers' own caps, which the runner checks through the process's peak RSS.
//!
//! The mutations are the ones that find bugs in parsers of this kind: bit flips, bytes set to
//! boundary values, 32-bit little-endian integers set to boundary values (GLB/EXR/.coeff
//! headers, accessor data), chunks deleted, duplicated or spliced in from another seed, and, in
//! text, numbers replaced by boundary numbers (0, −1, 2³²−1, 1e38, 1e-300…), which is how a
//! JSON count or factor becomes hostile.
//!
//! `cargo run --release -p fuzz -- TARGET --execs N` runs one target (see docs in the README of
//! this crate's `main.rs`); `cargo test -p fuzz` runs each target for a few seconds.

use std::panic::{AssertUnwindSafe, catch_unwind};

/// The fuzzed parsers.
pub const TARGETS: &[&str] =
    &["gltf", "coeff", "csv", "medium", "rgb-medium", "exr", "spectral-exr", "png", "env"];

/// Runs one input through `target`'s parser. `Err` is fine (refused input); a panic is not.
pub fn run_one(target: &str, data: &[u8]) {
    match target {
        // No base directory: file references are refused, as a scene without a folder's are.
        "gltf" => {
            drop(scene::load_slice("fuzz.gltf", data, None));
            // Posed too, between keys, where a document has animations to sample.
            if data.windows(10).any(|w| w == b"animations") {
                let opts = scene::LoadOptions { time: Some(0.37), ..Default::default() };
                drop(scene::load_slice_with("fuzz.gltf", data, None, &opts));
            }
        }
        "coeff" => drop(color::upsample::CoeffTable::from_bytes(data, "fuzz.coeff")),
        "csv" => drop(scene::spectrum_desc::csv_spectrum("fuzz.csv", data)),
        "medium" => {
            if let Ok(text) = std::str::from_utf8(data)
                && let Ok(m) = truth::Medium::from_json(text, "fuzz.json")
            {
                let _ = m.validate(color::WavelengthRange::VISIBLE);
            }
        }
        "rgb-medium" => {
            if let Ok(text) = std::str::from_utf8(data) {
                drop(scene::medium::RgbMedium::from_json_str(text));
            }
        }
        "exr" => drop(compare::decode_image("fuzz.exr", data)),
        "spectral-exr" => drop(compare::spectral::decode_spectral_exr("fuzz.exr", data)),
        "png" => drop(compare::decode_image("fuzz.png", data)),
        // Environment maps: Radiance (starts with "#?") or OpenEXR.
        "env" => {
            let name = if data.starts_with(b"#?") { "fuzz.hdr" } else { "fuzz.exr" };
            drop(scene::Environment::from_bytes(std::path::Path::new(name), data))
        }
        other => panic!("unknown fuzz target {other}; targets: {TARGETS:?}"),
    }
}

/// Runs `data` through `target`, returning the panic message if it panicked.
pub fn check(target: &str, data: &[u8]) -> Option<String> {
    catch_unwind(AssertUnwindSafe(|| run_one(target, data))).err().map(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "panic".into())
    })
}

/// SplitMix64: deterministic, seedable, no dependency.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 { 0 } else { (self.next_u64() % n as u64) as usize }
    }
}

const BYTES: &[u8] = &[0, 1, 0x7f, 0x80, 0xff, b'-', b'9', b'.', b'e', b'"', b'[', b'{', b','];
const U32S: &[u32] = &[0, 1, 2, 3, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 0xffff, 0x1_0000, 100_000, 16385];
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "255",
    "65536",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "1e38",
    "1e39",
    "-1e38",
    "1e-300",
    "1e308",
    "0.5",
    "-0.0",
    "30000000",
    "16385",
    "100000",
];

/// Replaces one number in `text` (if any) by a boundary number.
fn mutate_number(rng: &mut Rng, data: &mut Vec<u8>) -> bool {
    let starts: Vec<usize> = (0..data.len())
        .filter(|&i| data[i].is_ascii_digit() && (i == 0 || !data[i - 1].is_ascii_alphanumeric()))
        .collect();
    if starts.is_empty() {
        return false;
    }
    let s = starts[rng.below(starts.len())];
    let s = if s > 0 && data[s - 1] == b'-' { s - 1 } else { s };
    let mut e = s + 1;
    while e < data.len() && (data[e].is_ascii_digit() || b".eE+-".contains(&data[e])) {
        e += 1;
    }
    let n = NUMBERS[rng.below(NUMBERS.len())].as_bytes();
    data.splice(s..e, n.iter().copied());
    true
}

/// One to four random mutations of `data`; `other` is another seed to splice from.
pub fn mutate(rng: &mut Rng, data: &mut Vec<u8>, other: &[u8]) {
    for _ in 0..1 + rng.below(4) {
        let len = data.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                data[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                data[i] = BYTES[rng.below(BYTES.len())];
            }
            2 if len >= 4 => {
                let i = rng.below(len - 3);
                data[i..i + 4].copy_from_slice(&U32S[rng.below(U32S.len())].to_le_bytes());
            }
            3 if len > 0 => {
                let a = rng.below(len);
                let b = (a + 1 + rng.below(64)).min(len);
                data.drain(a..b);
            }
            4 if len > 0 => {
                let a = rng.below(len);
                let b = (a + 1 + rng.below(64)).min(len);
                let chunk = data[a..b].to_vec();
                let at = rng.below(len + 1);
                data.splice(at..at, chunk);
            }
            5 if !other.is_empty() => {
                let a = rng.below(other.len());
                let b = (a + 1 + rng.below(256)).min(other.len());
                let at = rng.below(len + 1);
                let end = (at + rng.below(256)).min(len);
                data.splice(at..end, other[a..b].iter().copied());
            }
            6 | 7 => {
                if !mutate_number(rng, data) && len > 0 {
                    let i = rng.below(len);
                    data[i] = data[i].wrapping_add(1);
                }
            }
            _ => data.push(rng.next_u64() as u8),
        }
    }
    // Inputs stay small (≤ 1 MB, the size the acceptance criterion talks about).
    data.truncate(1 << 20);
}

/// The seed corpus of `target`, from `corpus/<target>/` in this crate.
pub fn corpus(target: &str) -> Vec<Vec<u8>> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus").join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    files.sort();
    files.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// What a run did.
#[derive(Debug, Default)]
pub struct Report {
    pub execs: u64,
    /// (input, panic message) of each crash.
    pub crashes: Vec<(Vec<u8>, String)>,
}

/// Runs `target` from its corpus until `execs` inputs or `seconds` have passed (whichever is
/// first). Crashing inputs are collected, not retried; interesting growth is not tracked (no
/// coverage feedback on stable), so each input is a mutation of a seed.
pub fn fuzz(target: &str, seed: u64, execs: u64, seconds: f64) -> Report {
    fuzz_with(target, seed, execs, seconds, None)
}

/// [`fuzz`], writing each input to `current` before running it when given: an abort (a failed
/// allocation, a stack overflow) cannot be caught, and this leaves the input that caused it.
pub fn fuzz_with(
    target: &str,
    seed: u64,
    execs: u64,
    seconds: f64,
    current: Option<&std::path::Path>,
) -> Report {
    let seeds = corpus(target);
    assert!(!seeds.is_empty(), "no seeds for {target}");
    let mut rng = Rng(seed);
    let mut report = Report::default();
    let start = std::time::Instant::now();
    // Seeds themselves, then random bytes, then mutations.
    let mut queue: Vec<Vec<u8>> = seeds.clone();
    queue.extend((0..16).map(|n| (0..n * 16).map(|_| rng.next_u64() as u8).collect()));
    while report.execs < execs && start.elapsed().as_secs_f64() < seconds {
        let input = queue.pop().unwrap_or_else(|| {
            let mut d = seeds[rng.below(seeds.len())].clone();
            let other = &seeds[rng.below(seeds.len())];
            mutate(&mut rng, &mut d, other);
            d
        });
        if let Some(p) = current {
            std::fs::write(p, &input).expect("writing the current input");
        }
        if let Some(msg) = check(target, &input) {
            report.crashes.push((input, msg));
        }
        report.execs += 1;
    }
    report
}
