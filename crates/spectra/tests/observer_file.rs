//! `--observer FILE.csv` (issue 33) on the real binary: a CSV holding a built-in camera's
//! samples renders exactly the image of that camera by name, in real time and in the path
//! tracer; a bad file is one error naming the file, row and column, and nothing is written.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra")
}

fn ok(args: &[&str]) -> std::process::Output {
    let out = run(args);
    assert!(out.status.success(), "spectra {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// A fresh directory of this test process's own, one per test (they run in parallel).
fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectra-observer-file-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn p(d: &Path, f: &str) -> String {
    d.join(f).display().to_string()
}

/// ΔE2000 max and linear MAE of `b` against `a`.
fn difference(a: &str, b: &str) -> (f64, f64) {
    let out = ok(&["diff", a, b, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("diff --json");
    (v["delta_e2000"]["max"].as_f64().unwrap(), v["mae_linear"]["mean"].as_f64().unwrap())
}

#[test]
fn a_csv_of_a_built_in_camera_renders_as_that_camera_and_bad_files_are_refused() {
    let d = dir("camera");
    let nikon = color::Observer::nikon_d5100();
    let color::Spectrum::Piecewise { lambda, .. } = &nikon.bar[0] else { panic!("tabulated") };
    let mut csv = String::from("wavelength_nm,r,g,b\n");
    for &l in lambda {
        let v = nikon.eval(l);
        csv.push_str(&format!("{l},{:?},{:?},{:?}\n", v[0], v[1], v[2]));
    }
    let file = p(&d, "nikon.csv");
    std::fs::write(&file, csv).unwrap();
    for (cmd, extra) in [("render", &["--wavelengths", "8"][..]), ("truth", &["--spp", "4"][..])] {
        let by_name = p(&d, &format!("{cmd}-name.exr"));
        let by_file = p(&d, &format!("{cmd}-file.exr"));
        let common = [cmd, "metamerism", "--size", "48x32"];
        let a: Vec<&str> = common
            .iter()
            .copied()
            .chain(extra.iter().copied())
            .chain(["--observer", "nikon_d5100", "--out", &by_name])
            .collect();
        let b: Vec<&str> = common
            .iter()
            .copied()
            .chain(extra.iter().copied())
            .chain(["--observer", &file, "--out", &by_file])
            .collect();
        ok(&a);
        ok(&b);
        let (de, mae) = difference(&by_name, &by_file);
        assert!(
            de == 0.0 && mae == 0.0,
            "{cmd}: the CSV's image differs from the camera's: ΔE max {de}, MAE {mae}"
        );
    }
    // The camera is not the CIE observer: the file is really used.
    let cie = p(&d, "cie.exr");
    ok(&["render", "metamerism", "--size", "48x32", "--wavelengths", "8", "--out", &cie]);
    assert!(difference(&cie, &p(&d, "render-file.exr")).1 > 1e-3);

    let bad = p(&d, "bad.csv");
    std::fs::write(&bad, "400,0.1,0.2\n500,0.1,0.2\n600,0.1,0.2\n").unwrap();
    let out_file = p(&d, "never.exr");
    for (cmd, extra) in [("render", &[][..]), ("truth", &["--spp", "1"][..])] {
        let args: Vec<&str> = [cmd, "metamerism", "--size", "16x16", "--observer", &bad, "--out", &out_file]
            .into_iter()
            .chain(extra.iter().copied())
            .collect();
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{cmd} accepted a bad observer file");
        assert!(
            err.contains("bad.csv") && err.contains("row 1") && err.contains("3 columns"),
            "{cmd}: {err}"
        );
        assert!(!Path::new(&out_file).exists(), "{cmd} wrote an output");
    }

    // A file shorter than the render range (380–730 nm by default) warns; one outside it fails.
    let short = p(&d, "short.csv");
    std::fs::write(&short, "400,0.1,0.2,0.3\n500,0.5,0.6,0.7\n600,0.2,0.1,0.1\n").unwrap();
    let out =
        ok(&["render", "metamerism", "--size", "16x16", "--observer", &short, "--out", &p(&d, "short.png")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("warning: observer file") && err.contains("400–600 nm"), "{err}");
    let far = p(&d, "far.csv");
    std::fs::write(&far, "750,0.1,0.2,0.3\n800,0.5,0.6,0.7\n830,0.2,0.1,0.1\n").unwrap();
    let out = run(&["render", "metamerism", "--size", "16x16", "--observer", &far, "--out", &out_file]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("far.csv") && err.contains("do not overlap the render range"),
        "{err}"
    );
    assert!(!Path::new(&out_file).exists());
    // Kept where an assertion failed, for the files.
    let _ = std::fs::remove_dir_all(&d);
}

/// Found by a sweep of files from elsewhere: CIE 1931 as the CIE publishes it (no header,
/// 1 nm, 360–830 nm, twelve decimals) was taken for a camera — its X, Y, Z white balanced
/// and shown as RGB, ΔE2000 up to 30 from `--observer cie1931` in both renderers — and the
/// same table as a German spreadsheet saves it (BOM, CRLF, semicolons, decimal commas, in
/// percent) was refused. Both now render the built-in's image.
#[test]
fn the_cie_1931_table_from_a_file_renders_as_the_built_in() {
    let d = dir("cie");
    let cie = color::Observer::cie1931();
    let color::Spectrum::Piecewise { lambda, .. } = &cie.bar[0] else { panic!("tabulated") };
    let (mut official, mut excel) =
        (String::new(), String::from("\u{feff}\"Wellenlänge\";\"x\";\"y\";\"z\"\r\n"));
    for &l in lambda {
        let v = cie.eval(l);
        official.push_str(&format!("{l},{:.12},{:.12},{:.12}\n", v[0], v[1], v[2]));
        let pc = |x: f64| format!("{:?}", 100.0 * x).replace('.', ",");
        excel.push_str(&format!("{l};{};{};{}\r\n", pc(v[0]), pc(v[1]), pc(v[2])));
    }
    let files = [(p(&d, "CIE_xyz_1931_2deg.csv"), official), (p(&d, "excel.csv"), excel)];
    for (f, text) in &files {
        std::fs::write(f, text).unwrap();
    }
    for (cmd, extra) in [("render", &["--wavelengths", "8"][..]), ("truth", &["--spp", "4"][..])] {
        let common: Vec<&str> =
            [cmd, "metamerism", "--size", "48x32"].into_iter().chain(extra.iter().copied()).collect();
        let by_name = p(&d, &format!("{cmd}-cie1931.exr"));
        ok(&[&common[..], &["--out", &by_name]].concat());
        for (i, (f, _)) in files.iter().enumerate() {
            let by_file = p(&d, &format!("{cmd}-file{i}.exr"));
            ok(&[&common[..], &["--observer", f, "--out", &by_file]].concat());
            let (de, mae) = difference(&by_name, &by_file);
            assert!(de < 1e-4 && mae < 1e-7, "{cmd} --observer {f}: ΔE max {de}, MAE {mae} from cie1931");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
