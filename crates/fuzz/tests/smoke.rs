//! CI: every fuzz target for a bounded time (`FUZZ_SECONDS`, default 3 s each) from its seed
//! corpus, with a fixed seed so a failure reproduces. The long run is
//! `cargo run --release -p fuzz -- all --execs 1000000`.

#[test]
fn every_target_survives_a_short_run() {
    let seconds: f64 = std::env::var("FUZZ_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(3.0);
    std::panic::set_hook(Box::new(|_| {}));
    let mut failures = Vec::new();
    for t in fuzz::TARGETS {
        // The seeds must parse (or be refused) without a panic, and some must be valid, else
        // the corpus is not exercising the parser.
        let r = fuzz::fuzz(t, 7, u64::MAX, seconds);
        assert!(r.execs > 0, "{t}: no executions");
        eprintln!("{t}: {} executions in {seconds} s, {} crashes", r.execs, r.crashes.len());
        for (input, msg) in r.crashes.iter().take(3) {
            failures.push(format!("{t}: {msg} (input of {} bytes)", input.len()));
        }
    }
    let _ = std::panic::take_hook();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Each corpus has at least one seed the parser accepts: a corpus of garbage would only test
/// the first few bytes of each format.
#[test]
fn each_corpus_has_a_valid_seed() {
    for t in fuzz::TARGETS {
        let ok = fuzz::corpus(t).iter().any(|s| match *t {
            "gltf" => scene::load_slice("s.gltf", s, None).is_ok(),
            "coeff" => color::upsample::CoeffTable::from_bytes(s, "s").is_ok(),
            "csv" => scene::spectrum_desc::csv_spectrum("s.csv", s).is_ok(),
            "medium" => truth::Medium::from_json(std::str::from_utf8(s).unwrap(), "m").is_ok(),
            "rgb-medium" => scene::medium::RgbMedium::from_json_str(std::str::from_utf8(s).unwrap()).is_ok(),
            "exr" => compare::decode_image("s.exr", s).is_ok(),
            "spectral-exr" => compare::spectral::decode_spectral_exr("s.exr", s).is_ok(),
            "png" => compare::decode_image("s.png", s).is_ok(),
            "env" => {
                let name = if s.starts_with(b"#?") { "s.hdr" } else { "s.exr" };
                scene::Environment::from_bytes(std::path::Path::new(name), s).is_ok()
            }
            _ => unreachable!(),
        });
        assert!(ok, "{t}: no valid seed in corpus/{t}");
    }
}
