//! The truth cache (issue 31) on the real binary: `spectra truth --truth-cache` renders nothing
//! the second time and only the missing samples with a higher --spp, bit-identical to a render
//! of all of them; a damaged entry is reported, removed and rendered again; `spectra eval
//! --truth-cache` run twice renders no truth the second time and gives the same figures.

use std::path::Path;
use std::process::{Command, Output, Stdio};

fn run(args: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_spectra"));
    c.stdout(Stdio::piped()).stderr(Stdio::piped());
    c.args(args).output().expect("running spectra")
}

/// Runs and returns stderr, failing the test on a non-zero exit.
fn ok(args: &[&str]) -> String {
    let o = run(args);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{args:?}: {err}");
    err
}

fn pixels(p: &Path) -> Vec<[f32; 3]> {
    compare::read_image(p).unwrap().data
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    v.sort();
    v
}

#[test]
fn truth_renders_only_what_the_cache_lacks() {
    let d = tempfile::tempdir().unwrap();
    let cache = d.path().join("cache");
    let c = cache.to_str().unwrap();
    let out = |name: &str| d.path().join(name).to_str().unwrap().to_string();
    let truth = |spp: &str, seed: &str, o: &str, with_cache: bool| {
        let mut v = vec!["truth", "cornell", "--size", "24x16", "--seed", seed, "--spp", spp, "--out", o];
        if with_cache {
            v.extend(["--truth-cache", c]);
        }
        ok(&v)
    };
    let (a, b, c16, f16) = (out("a.exr"), out("b.exr"), out("c16.exr"), out("f16.exr"));
    let e = truth("8", "3", &a, true);
    assert!(e.contains("nothing stored for this render yet") && e.contains("stored 8 samples"), "{e}");
    assert_eq!(entries(&cache).len(), 1);
    let e = truth("8", "3", &b, true);
    assert!(e.contains("all 8 samples from") && e.contains("nothing to render"), "{e}");
    assert!(!e.contains("stored"), "{e}");
    assert_eq!(pixels(Path::new(&a)), pixels(Path::new(&b)));
    let e = truth("16", "3", &c16, true);
    assert!(e.contains("8 of 16 samples from") && e.contains("rendering the other 8"), "{e}");
    truth("16", "3", &f16, false);
    assert_eq!(pixels(Path::new(&c16)), pixels(Path::new(&f16)), "extended ≠ rendered at once");
    assert_eq!(entries(&cache).len(), 2, "{:?}", entries(&cache));
    // Fewer samples than any entry: rendered (a render cannot be cut back), another entry.
    let e = truth("4", "3", &out("four.exr"), true);
    assert!(e.contains("nothing stored"), "{e}");
    // Another seed is another render.
    let e = truth("8", "4", &out("seed4.exr"), true);
    assert!(e.contains("nothing stored"), "{e}");
    assert_eq!(entries(&cache).len(), 4);

    // A damaged entry: reported, removed, the render done again from the next one down.
    let sixteen = entries(&cache).into_iter().find(|n| n.ends_with("-16.truth")).unwrap();
    let p = cache.join(&sixteen);
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
    let again = out("again.exr");
    let e = truth("16", "3", &again, true);
    assert!(e.contains(&sixteen) && e.contains("damaged") && e.contains("removed it"), "{e}");
    assert!(e.contains("8 of 16 samples from"), "{e}");
    assert_eq!(pixels(Path::new(&again)), pixels(Path::new(&f16)));
    assert!(std::fs::read(&p).unwrap().len() == bytes.len(), "the entry is stored again");
    // An entry whose name lies about its samples: the warning names the file it removes.
    let renamed = p.with_file_name(sixteen.replace("-16.", "-12."));
    std::fs::rename(&p, &renamed).unwrap();
    let e = truth("12", "3", &out("twelve.exr"), true);
    let name = renamed.file_name().unwrap().to_str().unwrap();
    assert!(e.contains(name) && e.contains("its name says 12") && e.contains("removed it"), "{e}");
    assert!(e.contains("8 of 12 samples from"), "rendered on from the next entry down: {e}");

    // The cache where the checkpoint goes (`--out`'s name + .checkpoint): refused before any
    // work (it was accepted, and the folder then blocked every later render to that --out).
    // One sample of an 8×8 Cornell into `o` with `cache` as the truth cache: failed?, stderr.
    let attempt = |cache: &str, o: &str| {
        let r = run(&["truth", "cornell", "--size", "8x8", "--spp", "1", "--truth-cache", cache, "--out", o]);
        (!r.status.success(), String::from_utf8_lossy(&r.stderr).to_string())
    };
    let x = out("x.exr");
    let (failed, err) = attempt(&format!("{x}.checkpoint"), &x);
    assert!(failed && err.contains("checkpoint") && err.contains("--truth-cache"), "{err}");
    assert!(!Path::new(&format!("{x}.checkpoint")).exists());

    // Not a directory.
    let file = out("file");
    std::fs::write(&file, "x").unwrap();
    let (failed, err) = attempt(&file, &out("x.exr"));
    assert!(failed && err.contains("--truth-cache") && err.contains("not a directory"), "{err}");
}

#[test]
fn eval_renders_no_truth_the_second_time() {
    let d = tempfile::tempdir().unwrap();
    let cache = d.path().join("cache");
    let dir = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    let eval = |spp: &str, o: &str, with_cache: bool| {
        let mut v = vec![
            "eval",
            "--quick",
            "--scenes",
            "metamerism",
            "--size",
            "16x12",
            "--spp",
            spp,
            "--sweep",
            "4",
            "--out",
            o,
        ];
        if with_cache {
            v.extend(["--truth-cache", cache.to_str().unwrap()]);
        }
        ok(&v)
    };
    let (e1, e2, e3, e4) = (dir("e1"), dir("e2"), dir("e3"), dir("e4"));
    let first = eval("4", &e1, true);
    assert!(first.contains("ground truth: 4 spp rendered, 4 spp rendered"), "{first}");
    let second = eval("4", &e2, true);
    assert!(
        second.contains("ground truth: 4 spp from the cache, 4 spp from the cache; nothing rendered"),
        "{second}"
    );
    assert!(second.contains("jitter truth: 4 spp from the cache; nothing rendered"), "{second}");
    let errors = |o: &str| {
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(Path::new(o).join("results.json")).unwrap())
                .unwrap();
        let c = &j["cases"][0];
        (
            c["noise_floor"].clone(),
            c["modes"].as_array().unwrap().iter().map(|m| m["errors"].clone()).collect::<Vec<_>>(),
        )
    };
    assert_eq!(errors(&e1), errors(&e2));
    let more = eval("8", &e3, true);
    assert!(
        more.contains("ground truth: 4 spp from the cache + 4 rendered, 4 spp from the cache + 4 rendered"),
        "{more}"
    );
    eval("8", &e4, false);
    let truth = |o: &str| pixels(&Path::new(o).join("metamerism_truth.exr"));
    assert_eq!(truth(&e3), truth(&e4), "extended truth ≠ one render");
    assert_eq!(errors(&e3), errors(&e4));
}
