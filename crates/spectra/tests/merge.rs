//! `spectra truth` chunks and crops, and `spectra merge` (issue 31), on the real binary: chunks
//! merged are the render of all their samples, tiles stitched are the full render, and
//! anything else is refused naming the file and the mismatch, with nothing written. CPU only.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn spectra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra")
}

fn ok(args: &[&str]) {
    let out = spectra(args);
    assert!(out.status.success(), "spectra {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

fn refused(args: &[&str], parts: &[&str]) {
    let out = spectra(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "spectra {args:?}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(lines.len(), 1, "one error line: {err}");
    for p in parts {
        assert!(lines[0].contains(p), "'{p}' missing: {err}");
    }
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectra-merge-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Largest per-pixel relative difference between two images of `n` values a pixel: a pixel's
/// largest difference over its largest value (a channel near zero, where RGB cancels, is
/// measured against the pixel, not against itself).
fn worst(got: &[f32], want: &[f32], n: usize) -> f64 {
    assert_eq!(got.len(), want.len());
    got.chunks(n)
        .zip(want.chunks(n))
        .map(|(g, w)| {
            let d = g.iter().zip(w).map(|(a, b)| (f64::from(*a) - f64::from(*b)).abs()).fold(0.0, f64::max);
            let m = w.iter().map(|b| f64::from(b.abs())).fold(0.0, f64::max);
            if m > 0.0 { d / m } else { d }
        })
        .fold(0.0, f64::max)
}

fn rgb(p: &Path) -> Vec<f32> {
    compare::read_image(p).unwrap().data.into_iter().flatten().collect()
}

fn bands(p: &Path) -> Vec<f32> {
    compare::read_spectral_exr(p).unwrap().data
}

/// Four chunks merged equal one render of all their samples, for the colour and the spectral
/// output, direct and full transport, dry and under water.
#[test]
fn chunks_merge_into_one_render() {
    let d = tmp("chunks");
    let cases: [(&str, &[&str]); 3] =
        [("cornell", &["--direct-only"]), ("cornell", &[]), ("underwater", &["--max-depth", "8"])];
    for (k, (scene, extra)) in cases.iter().enumerate() {
        let base = |spp: &str, out: &Path, sp: &Path| -> Vec<String> {
            let size = if *scene == "underwater" { "12x8" } else { "24x16" };
            let mut v: Vec<String> = ["truth", scene, "--size", size, "--spp", spp, "--seed", "3"]
                .iter()
                .map(|x| x.to_string())
                .collect();
            v.extend(extra.iter().map(|x| x.to_string()));
            v.extend([
                "--out".into(),
                s(out).into(),
                "--spectral-out".into(),
                s(sp).into(),
                "--spectral-bin".into(),
                "25".into(),
            ]);
            v
        };
        let (full, full_s) = (d.join(format!("full{k}.exr")), d.join(format!("full{k}-s.exr")));
        let args = base("12", &full, &full_s);
        ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let mut chunks = Vec::new();
        let mut chunks_s = Vec::new();
        for i in 0..4 {
            let (c, cs) = (d.join(format!("c{k}-{i}.exr")), d.join(format!("c{k}-{i}-s.exr")));
            let mut args = base("3", &c, &cs);
            args.extend(["--chunk".into(), format!("{i}/4")]);
            ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
            chunks.push(c);
            chunks_s.push(cs);
        }
        let (m, ms) = (d.join(format!("m{k}.exr")), d.join(format!("m{k}-s.exr")));
        let mut margs: Vec<&str> = vec!["merge"];
        margs.extend(chunks.iter().rev().map(|p| s(p)));
        margs.extend(["--out", s(&m)]);
        ok(&margs);
        let mut margs: Vec<&str> = vec!["merge"];
        margs.extend(chunks_s.iter().map(|p| s(p)));
        margs.extend(["--out", s(&ms)]);
        ok(&margs);
        let nb = compare::read_spectral_exr(&ms).unwrap().bands();
        let (wr, ws) = (worst(&rgb(&m), &rgb(&full), 3), worst(&bands(&ms), &bands(&full_s), nb));
        eprintln!(
            "{scene} {extra:?}: 4 chunks vs one render: worst relative difference rgb {wr:e}, bands {ws:e}"
        );
        assert!(wr <= 1e-6 && ws <= 1e-6, "{scene} {extra:?}: rgb {wr:e}, bands {ws:e}");
        let frame = compare::read_exr_frame(&m).unwrap();
        assert_eq!(frame.get("spectra.samples"), Some("0..12"));
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A 2 × 2 tiling of crops, stitched, is the full render (bit for bit: each pixel draws the
/// same samples); the crop's EXR sits in the full frame.
#[test]
fn crops_stitch_into_the_full_render() {
    let d = tmp("crops");
    let full = d.join("full.exr");
    let base = ["truth", "cornell", "--size", "20x14", "--spp", "4", "--seed", "1"];
    fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        base.iter().chain(extra).copied().collect()
    }
    ok(&with(&base, &["--out", s(&full)]));
    let mut tiles = Vec::new();
    for (i, c) in ["0,0,11,6", "11,0,9,6", "0,6,11,8", "11,6,9,8"].iter().enumerate() {
        let t = d.join(format!("t{i}.exr"));
        ok(&with(&base, &["--crop", c, "--out", s(&t)]));
        tiles.push(t);
    }
    let f = compare::read_exr_frame(&tiles[3]).unwrap();
    assert_eq!((f.display, f.origin), ((20, 14), (11, 6)));
    assert_eq!(compare::read_image(&tiles[3]).unwrap().size(), (9, 8));
    let m = d.join("m.exr");
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(tiles.iter().map(|p| s(p)));
    args.extend(["--out", s(&m)]);
    ok(&args);
    assert_eq!(rgb(&m), rgb(&full), "stitched tiles are the full render, bit for bit");
    let _ = std::fs::remove_dir_all(&d);
}

/// What does not merge is refused with one line naming the file and the mismatch; nothing is
/// written.
#[test]
fn mixtures_are_refused() {
    let d = tmp("bad");
    let p = |n: &str| d.join(n);
    let r = |scene: &str, extra: &[&str], out: &Path| {
        let mut a = vec!["truth", scene, "--size", "12x8", "--spp", "2"];
        a.extend(extra);
        a.extend(["--out", s(out)]);
        ok(&a);
    };
    r("cornell", &["--chunk", "0/2"], &p("a.exr"));
    r("cornell", &["--chunk", "1/2"], &p("b.exr"));
    r("colorchecker", &["--chunk", "1/2"], &p("other.exr"));
    r("cornell", &["--chunk", "1/2", "--seed", "7"], &p("seed.exr"));
    r("cornell", &["--sample-offset", "1"], &p("overlap.exr"));
    r("cornell", &["--crop", "0,0,6,8", "--chunk", "1/2"], &p("left.exr"));
    let out = p("m.exr");
    let m = |inputs: &[&str], parts: &[&str]| {
        let mut a = vec!["merge"];
        a.extend(inputs);
        a.extend(["--out", s(&out)]);
        refused(&a, parts);
        assert!(!out.exists(), "nothing written");
    };
    m(&[s(&p("a.exr")), s(&p("other.exr"))], &["other.exr", "a different render", "a.exr"]);
    m(&[s(&p("a.exr")), s(&p("seed.exr"))], &["seed.exr", "seed is 0 there and 7 here"]);
    m(&[s(&p("a.exr")), s(&p("overlap.exr"))], &["overlap.exr", "1..3", "overlap", "0..2"]);
    m(&[s(&p("a.exr")), s(&p("a.exr"))], &["a.exr", "overlap"]);
    m(&[s(&p("a.exr")), s(&p("left.exr"))], &["left.exr", "samples"]);
    // Truncated, and foreign (an EXR without the record).
    let bytes = std::fs::read(p("b.exr")).unwrap();
    std::fs::write(p("cut.exr"), &bytes[..bytes.len() / 2]).unwrap();
    m(&[s(&p("a.exr")), s(&p("cut.exr"))], &["cut.exr"]);
    let img = compare::Image::new(12, 8, vec![[0.5; 3]; 96]).unwrap();
    compare::write_image(p("plain.exr"), &img, Default::default()).unwrap();
    m(&[s(&p("a.exr")), s(&p("plain.exr"))], &["plain.exr", "not a spectra truth render"]);
    // Found by a sweep: a chunk holding a NaN (a truth render never writes one: it drops
    // non-finite samples) merged silently into a NaN pixel.
    let mut img = compare::read_image(p("b.exr")).unwrap();
    img.data[13] = [f32::NAN, 0.0, 0.0];
    compare::write_exr_framed(p("nan.exr"), &img, &compare::read_exr_frame(p("b.exr")).unwrap()).unwrap();
    m(&[s(&p("a.exr")), s(&p("nan.exr"))], &["nan.exr", "pixel (1, 1) is not finite"]);
    // Found by a sweep: one character of a header edited (b.exr's samples 2..4 made 2..3)
    // merged with the wrong weight; the record's check refuses it.
    let mut bytes = std::fs::read(p("b.exr")).unwrap();
    let at = bytes.windows(4).position(|w| w == b"2..4").expect("b.exr's sample range");
    bytes[at + 3] = b'3';
    std::fs::write(p("edited.exr"), &bytes).unwrap();
    m(&[s(&p("a.exr")), s(&p("edited.exr"))], &["edited.exr", "spectra.check", "edited or damaged"]);
    // Tiles that leave a gap: the message names them.
    r("cornell", &["--crop", "8,0,4,8", "--chunk", "1/2"], &p("right.exr"));
    m(&[s(&p("left.exr")), s(&p("right.exr"))], &["left.exr", "right.exr", "do not cover a rectangle"]);
    // The output may not be an input; a crop outside the frame is refused before rendering.
    let a = p("a.exr");
    refused(&["merge", s(&a), s(&p("b.exr")), "--out", s(&a)], &["--out", "input"]);
    refused(
        &["truth", "cornell", "--size", "12x8", "--crop", "8,0,6,8", "--out", s(&out)],
        &["crop", "8,0,6,8", "12×8"],
    );
    refused(&["truth", "cornell", "--chunk", "4/4", "--out", s(&out)], &["--chunk", "4/4"]);
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// Found by a sweep: a file name outside Latin-1 (`sky–dusk.hdr`, `камера/cam.csv`) let the
/// render run to its end and then refused to write it (the record could not be stored); the
/// record's `×` was a Latin-1 byte that OpenEXR's Python bindings refuse to open; and one
/// observer file under two paths refused to merge. Now the record is UTF-8 and names an
/// observer file by its name.
#[test]
fn the_record_holds_any_script_and_names_an_observer_file_without_its_folder() {
    let d = tmp("script");
    let hdr = d.join("sky–dusk.hdr");
    std::fs::copy(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/environments/rooitou_park.hdr"), &hdr)
        .unwrap();
    let (a, b) = (d.join("камера"), d.join("other"));
    for dir in [&a, &b] {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join("cam.csv"), "380,1,0,0\n580,0,1,0\n780,0,0,1\n").unwrap();
    }
    let chunk = |k: &str, obs: &Path, out: &Path| {
        ok(&[
            "truth",
            "cornell",
            "--size",
            "12x8",
            "--spp",
            "4",
            "--chunk",
            k,
            "--env",
            s(&hdr),
            "--observer",
            s(obs),
            "--out",
            s(out),
        ])
    };
    let (c0, c1, m) = (d.join("c0.exr"), d.join("c1.exr"), d.join("m.exr"));
    chunk("0/2", &a.join("cam.csv"), &c0);
    chunk("1/2", &b.join("cam.csv"), &c1);
    let frame = compare::read_exr_frame(&c0).unwrap();
    let env = frame.get("spectra.setting.environment").unwrap();
    assert!(env.starts_with("sky–dusk.hdr × "), "{env}");
    let obs = frame.get("spectra.setting.observer").unwrap();
    assert!(obs.starts_with("cam.csv "), "{obs}");
    // UTF-8 on disk: the en dash's three bytes, not a Latin-1 stand-in.
    let bytes = std::fs::read(&c0).unwrap();
    assert!(bytes.windows(3).any(|w| w == "–".as_bytes()));
    ok(&["merge", s(&c0), s(&c1), "--out", s(&m)]);
    // Other functions under the same name are another observer.
    std::fs::write(b.join("cam.csv"), "380,1,0,0\n580,0,1,0\n780,0,0,0.5\n").unwrap();
    chunk("1/2", &b.join("cam.csv"), &c1);
    refused(&["merge", s(&c0), s(&c1), "--out", s(&m)], &["c1.exr", "observer"]);
    let _ = std::fs::remove_dir_all(&d);
}

/// Found by a sweep: a texture changed between two chunks was refused as "the scene's input
/// file 2", leaving the user to count. The refusal names the file.
#[test]
fn a_changed_input_is_named() {
    let d = tmp("named");
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../scene/tests/data/");
    for f in ["textured.gltf", "quad.bin", "base.png", "normal.png", "reflectance.csv", "spectrum.csv"] {
        std::fs::copy(format!("{data}{f}"), d.join(f)).unwrap();
    }
    let scene = d.join("textured.gltf");
    let chunk = |k: &str, out: &Path| {
        ok(&["truth", s(&scene), "--size", "8x6", "--spp", "2", "--chunk", k, "--out", s(out)]);
    };
    let (c0, c1) = (d.join("c0.exr"), d.join("c1.exr"));
    chunk("0/2", &c0);
    let mut png = std::fs::read(d.join("base.png")).unwrap();
    // A byte in the IEND chunk's CRC would fail decoding; append a harmless trailing byte.
    png.push(0);
    std::fs::write(d.join("base.png"), png).unwrap();
    chunk("1/2", &c1);
    refused(
        &["merge", s(&c0), s(&c1), "--out", s(&d.join("m.exr"))],
        &["c1.exr", "base.png", "content hash"],
    );
    // A renamed copy of the scene: its name is what differs, not its contents (the message
    // said "the contents … differ" and showed one hash twice; found by a sweep).
    std::fs::copy(&scene, d.join("renamed.gltf")).unwrap();
    let c2 = d.join("c2.exr");
    ok(&[
        "truth",
        s(&d.join("renamed.gltf")),
        "--size",
        "8x6",
        "--spp",
        "2",
        "--chunk",
        "1/2",
        "--out",
        s(&c2),
    ]);
    let c3 = d.join("c3.exr");
    chunk("0/2", &c3);
    refused(
        &["merge", s(&c3), s(&c2), "--out", s(&d.join("m.exr"))],
        &["the name of input file 0", "textured.gltf there", "renamed.gltf here"],
    );
    let _ = std::fs::remove_dir_all(&d);
}
