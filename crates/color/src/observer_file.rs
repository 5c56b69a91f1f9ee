//! Observers from a file (`--observer FILE`, issue 33): a camera's or any other three
//! sensitivity curves, as
//! - a CSV of wavelength (nm) and three columns — the layout camera databases and
//!   `colour-science` export. Header and `#` comment lines are skipped; commas, semicolons, tabs
//!   or spaces separate the fields;
//! - the Academy's rawtoaces camera JSON (AcademySoftwareFoundation/rawtoaces-data,
//!   `schema/spectral_1.0.0.json`): `spectral_data.index.main` names the channels (R, G and B
//!   are taken by name), `spectral_data.data.main` maps each wavelength to its values.
//!
//! Checked, each refusal naming the file and the row (CSV) or the wavelength's entry (JSON) and
//! the column: finite numbers, wavelengths increasing strictly (CSV) or distinct (JSON),
//! sensitivities ≥ 0, at least three samples, some overlap with 360–830 nm, no channel all zero.
//! Outside the file's range the sensitivities are zero; between samples they are linear.

use std::path::Path;

use crate::error::{ColorError, Result};
use crate::observer::Observer;
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN, Spectrum};

/// Largest observer file read, bytes (a 1 nm table over 360–830 nm is ~20 kB; rawtoaces JSON
/// files ~10 kB).
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// Whether an `--observer` value names a file rather than a built-in observer: a path, or a
/// name with an extension (no built-in name has a dot; `obs.png` holding a CSV was looked up
/// as an unknown built-in).
pub fn is_file_name(name: &str) -> bool {
    name.contains('.') || name.contains('/') || name.contains('\\')
}

/// The observer in the file at `path` (JSON when it ends in `.json` or starts with `{`, else
/// CSV), named by the path.
pub fn read(path: &Path) -> Result<Observer> {
    let shown = path.display().to_string();
    // A regular file of bounded size: a FIFO or a device (/dev/zero) would hang or exhaust memory.
    let text = crate::input::read_regular_string(path, MAX_FILE_BYTES)
        .map_err(|e| ColorError::Table(format!("observer file {shown}: cannot read it: {e}")))?;
    let json = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"))
        || text.trim_start_matches('\u{feff}').trim_start().starts_with('{');
    if json { parse_json(&text, &shown) } else { parse(&text, &shown) }
}

/// The observer in CSV `text`; `source` names it in errors and becomes its name.
pub fn parse(text: &str, source: &str) -> Result<Observer> {
    let bad =
        |row: usize, what: String| ColorError::Table(format!("observer file {source}: row {row}: {what}"));
    let mut lambda = Vec::new();
    let mut columns: [Vec<f64>; 3] = Default::default();
    let mut first = true;
    for (i, line) in text.lines().enumerate() {
        let row = i + 1;
        let line = line.trim().trim_start_matches('\u{feff}');
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        // Fields may be quoted, as spreadsheets export them ("360","0.0001",…).
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .map(|f| f.trim_matches('"'))
            .filter(|f| !f.is_empty())
            .collect();
        // A header: the first line, if its first field is not a number. (Every such line was
        // taken for one, so that a file of text ended as "0 data rows" naming no row.)
        if std::mem::take(&mut first) && fields.first().is_some_and(|f| f.parse::<f64>().is_err()) {
            continue;
        }
        if fields.len() != 4 {
            return Err(bad(
                row,
                format!("{} columns; expected 4 (wavelength in nm and three sensitivities)", fields.len()),
            ));
        }
        let mut nums = [0.0f64; 4];
        for (c, f) in fields.iter().enumerate() {
            nums[c] = match f.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                _ => return Err(bad(row, format!("column {}: '{f}' is not a finite number", c + 1))),
            };
        }
        if let Some(&prev) = lambda.last()
            && nums[0] <= prev
        {
            return Err(bad(
                row,
                format!("column 1: wavelength {} nm after {prev} nm; wavelengths must increase", nums[0]),
            ));
        }
        for (c, &v) in nums.iter().enumerate().skip(1) {
            if v < 0.0 {
                return Err(bad(row, format!("column {}: sensitivity {v} is negative", c + 1)));
            }
        }
        lambda.push(nums[0]);
        for (col, &v) in columns.iter_mut().zip(&nums[1..]) {
            col.push(v);
        }
    }
    finish(lambda, columns, source, |c| format!("column {}", c + 2))
}

/// The observer in rawtoaces camera JSON `text` (`spectral_data.index.main` and
/// `spectral_data.data.main`); `source` names it in errors and becomes its name.
pub fn parse_json(text: &str, source: &str) -> Result<Observer> {
    let err = |what: String| ColorError::Table(format!("observer file {source}: {what}"));
    let doc = crate::input::json_value(text).map_err(|e| err(format!("not valid JSON: {e}")))?;
    let field = |path: &[&str]| -> Result<&serde_json::Value> {
        let mut v = &doc;
        for (i, key) in path.iter().enumerate() {
            v = v.get(key).ok_or_else(|| err(format!("field {} is missing", path[..=i].join("."))))?;
        }
        Ok(v)
    };
    let index: Vec<String> = field(&["spectral_data", "index", "main"])?
        .as_array()
        .ok_or_else(|| err("field spectral_data.index.main is not a list of channel names".into()))?
        .iter()
        .map(|c| c.as_str().map(str::to_string))
        .collect::<Option<_>>()
        .ok_or_else(|| err("field spectral_data.index.main holds a name that is not a string".into()))?;
    let channels: [usize; 3] = {
        let mut at = [0usize; 3];
        for (slot, name) in at.iter_mut().zip(["R", "G", "B"]) {
            *slot = index.iter().position(|c| c.eq_ignore_ascii_case(name)).ok_or_else(|| {
                err(format!(
                    "field spectral_data.index.main: no channel '{name}' (it names {}); a camera needs R, G and B",
                    if index.is_empty() { "none".to_string() } else { index.join(", ") }
                ))
            })?;
        }
        at
    };
    let data = field(&["spectral_data", "data", "main"])?
        .as_object()
        .ok_or_else(|| err("field spectral_data.data.main is not an object of wavelength → values".into()))?;
    let mut rows: Vec<(f64, [f64; 3])> = Vec::with_capacity(data.len());
    for (key, values) in data {
        let at = |what: String| err(format!("spectral_data.data.main entry \"{key}\": {what}"));
        let l = match key.trim().parse::<f64>() {
            Ok(l) if l.is_finite() => l,
            _ => return Err(at("the wavelength is not a finite number".into())),
        };
        let list = values.as_array().ok_or_else(|| at("the values are not a list".into()))?;
        if list.len() != index.len() {
            return Err(at(format!("{} values for the {} channels of the index", list.len(), index.len())));
        }
        let mut v = [0.0; 3];
        for (c, (&i, name)) in channels.iter().zip(["R", "G", "B"]).enumerate() {
            v[c] = match list[i].as_f64() {
                Some(x) if x.is_finite() && x >= 0.0 => x,
                Some(x) if x.is_finite() => {
                    return Err(at(format!("channel {name}: sensitivity {x} is negative")));
                }
                _ => return Err(at(format!("channel {name}: {} is not a finite number", list[i]))),
            };
        }
        rows.push((l, v));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(w) = rows.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(err(format!("spectral_data.data.main: wavelength {} nm is given twice", w[0].0)));
    }
    let lambda = rows.iter().map(|r| r.0).collect();
    let columns = [0, 1, 2].map(|c| rows.iter().map(|r| r.1[c]).collect());
    finish(lambda, columns, source, |c| format!("channel {}", ["R", "G", "B"][c]))
}

/// The checks on the whole file and the observer, shared by both formats.
/// Bounds of an observer file's largest value (see `finish`).
pub const MIN_LARGEST: f64 = 1e-30;
pub const MAX_LARGEST: f64 = 1e30;

fn finish(
    lambda: Vec<f64>,
    columns: [Vec<f64>; 3],
    source: &str,
    column_name: impl Fn(usize) -> String,
) -> Result<Observer> {
    let whole = |what: String| ColorError::Table(format!("observer file {source}: {what}"));
    if lambda.len() < 3 {
        return Err(whole(format!("{} data rows; at least 3 are needed", lambda.len())));
    }
    let (lo, hi) = (lambda[0], lambda[lambda.len() - 1]);
    if hi <= LAMBDA_MIN || lo >= LAMBDA_MAX {
        return Err(whole(format!(
            "its wavelengths {lo}–{hi} nm do not overlap {LAMBDA_MIN}–{LAMBDA_MAX} nm (are they in nm?)"
        )));
    }
    for (c, col) in columns.iter().enumerate() {
        if col.iter().all(|&v| v == 0.0) {
            return Err(whole(format!("{} is zero at every wavelength", column_name(c))));
        }
    }
    // The renderers normalise an observer by its response to the white, so its scale is free;
    // but a scale far from 1 leaves the range where that response and the per-wavelength
    // weights are finite and normal (values of 10⁻³¹⁰ made the path tracer's image NaN).
    let largest = columns.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(MIN_LARGEST..=MAX_LARGEST).contains(&largest) {
        return Err(whole(format!(
            "its largest value is {largest:e}; scale the file so that it lies within {MIN_LARGEST:e}…{MAX_LARGEST:e} \
             (only the functions' shape matters)"
        )));
    }
    // Each channel is normalised by its own response to the white, which a channel far weaker
    // than the others takes out of f32's range in the renderers' sums (channels of 10²⁰ and
    // 10⁻²⁰ made the path tracer's image NaN and the real-time one ±65504). No real observer or
    // camera has channels 10¹² apart.
    for (c, col) in columns.iter().enumerate() {
        let peak = col.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak < largest * MIN_CHANNEL_SHARE {
            return Err(whole(format!(
                "{} peaks at {peak:e}, below {MIN_CHANNEL_SHARE:e} of the largest value {largest:e}: a channel \
                 that weak cannot be normalised (scale the columns to comparable peaks)",
                column_name(c)
            )));
        }
    }
    let bar = columns.map(|values| Spectrum::piecewise(lambda.clone(), values));
    let [a, b, c] = bar;
    Ok(Observer { name: source.to_string(), bar: [a?, b?, c?] })
}

/// The weakest channel's peak an observer file may have, as a share of its largest value.
pub const MIN_CHANNEL_SHARE: f64 = 1e-12;

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by a sweep: `--observer obs.png` (a CSV under another extension) was looked up as
    /// an unknown built-in name; any name with an extension or a path is a file.
    #[test]
    fn names_with_an_extension_or_a_path_are_files() {
        for f in ["obs.png", "obs.csv", "my.data.txt", "./obs", "dir/obs", "c:\\obs"] {
            assert!(is_file_name(f), "{f}");
        }
        for n in ["cie1931", "canon_eos_r5", "nikon", "2015"] {
            assert!(!is_file_name(n), "{n}");
        }
        assert!(Observer::by_name("missing.png").unwrap_err().to_string().contains("missing.png"));
    }

    /// Found by a sweep: channels peaking at 10²⁰ and 10⁻²⁰ passed every check and made the
    /// path tracer's image NaN and the real-time one ±65504; a channel 10¹² below the largest
    /// is refused by name, in CSV and JSON alike.
    #[test]
    fn a_channel_far_weaker_than_the_others_is_refused() {
        let rows = |g: f64| -> String { (0..5).map(|i| format!("{},1,{g:e},0.5\n", 400 + 50 * i)).collect() };
        assert!(parse(&rows(1e-11), "ok.csv").is_ok());
        let e = parse(&rows(1e-13), "weak.csv").unwrap_err().to_string();
        assert!(e.contains("weak.csv") && e.contains("column 3") && e.contains("peaks at"), "{e}");
    }

    /// A FIFO or a device is refused at once (it blocked, or /dev/zero was read until memory
    /// ran out), and so is a file past the size cap.
    #[cfg(unix)]
    #[test]
    fn only_regular_files_of_bounded_size_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("cam.csv");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let t = std::time::Instant::now();
        let e = read(&fifo).unwrap_err().to_string();
        assert!(e.contains("cam.csv") && e.contains("FIFO"), "{e}");
        assert!(t.elapsed().as_secs() < 5);
        let e = read(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("device"), "{e}");
        let big = dir.path().join("big.csv");
        std::fs::File::create(&big).unwrap().set_len(MAX_FILE_BYTES + 1).unwrap();
        assert!(read(&big).unwrap_err().to_string().contains("larger than"));
    }

    /// Found by a sweep: CIE 1931 × 10⁻³¹⁰ made the path tracer's image NaN (its white
    /// overflowed the normalisation); a file whose values are that far from 1 is refused,
    /// naming the file.
    #[test]
    fn values_far_from_one_are_refused() {
        for (scale, ok) in [(1e-310, false), (1e-31, false), (1e-29, true), (1e29, true), (1e31, false)] {
            let text: String = (0..5)
                .map(|i| format!("{},{:e},{:e},{:e}\n", 400 + 50 * i, scale, 0.5 * scale, scale))
                .collect();
            match parse(&text, "tiny.csv") {
                Ok(_) => assert!(ok, "{scale:e} accepted"),
                Err(e) => {
                    assert!(!ok, "{scale:e}: {e}");
                    let e = e.to_string();
                    assert!(e.contains("tiny.csv") && e.contains("largest value"), "{e}");
                }
            }
        }
    }

    /// Found by a sweep: a spreadsheet's quoted CSV was read as header lines only ("0 data
    /// rows", no row named). Quotes are taken off; only the first line may be a header.
    #[test]
    fn quoted_fields_are_numbers_and_only_the_first_line_is_a_header() {
        let quoted = "\"nm\",\"r\",\"g\",\"b\"\n\"400\",\"1\",\"0\",\"0\"\n\"500\",\"0\",\"1\",\"0\"\n\"600\",\"0\",\"0\",\"1\"\n";
        let o = parse(quoted, "q.csv").unwrap();
        assert_eq!(o.eval(500.0), [0.0, 1.0, 0.0]);
        let e = parse("nm,r,g,b\nunits,x,y,z\n400,1,0,0\n", "two.csv").unwrap_err().to_string();
        assert!(e.contains("two.csv") && e.contains("row 2") && e.contains("column 1"), "{e}");
    }

    /// A CSV holding a built-in camera's samples is that camera.
    #[test]
    fn a_csv_of_a_built_in_camera_is_that_camera() {
        let nikon = Observer::nikon_d5100();
        let Spectrum::Piecewise { lambda, .. } = &nikon.bar[0] else { panic!() };
        let mut csv = String::from("wavelength,r,g,b\n# NPL, Darrodi et al. 2015\n");
        for &l in lambda {
            let v = nikon.eval(l);
            csv.push_str(&format!("{l},{:?},{:?},{:?}\n", v[0], v[1], v[2]));
        }
        let o = parse(&csv, "nikon.csv").unwrap();
        assert_eq!(o.bar, nikon.bar);
        assert_eq!(o.name, "nikon.csv");
    }

    #[test]
    fn separators_headers_and_comments() {
        let o = parse("\u{feff}nm;x;y;z\n400 0.1 0.2 0.3\n500\t0.5\t0.6\t0.7\n  \n600,0.2,0.1,0.0\n", "t")
            .unwrap();
        assert_eq!(o.eval(500.0), [0.5, 0.6, 0.7]);
        assert_eq!(o.eval(450.0), [0.3, 0.4, 0.5]);
        assert_eq!(o.eval(399.0), [0.0; 3]);
    }

    #[test]
    fn bad_files_are_errors_naming_the_row_and_column() {
        let cases = [
            ("400,1,2\n500,1,2\n600,1,2\n", "row 1: 3 columns"),
            ("400,1,2,3\n390,1,2,3\n600,1,2,3\n", "row 2: column 1: wavelength 390"),
            ("400,1,2,3\n500,NaN,2,3\n600,1,2,3\n", "row 2: column 2: 'NaN'"),
            ("400,1,2,3\n500,1,-2,3\n600,1,2,3\n", "row 2: column 3: sensitivity -2 is negative"),
            ("400,1,2,3\n500,1,2,3\n", "2 data rows"),
            ("0.4,1,2,3\n0.5,1,2,3\n0.6,1,2,3\n", "do not overlap"),
            ("400,1,0,3\n500,1,0,3\n600,1,0,3\n", "column 3 is zero"),
            ("400,1,2,3\n500,1,x,3\n600,1,2,3\n", "row 2: column 3: 'x'"),
        ];
        for (text, want) in cases {
            let e = parse(text, "cam.csv").unwrap_err().to_string();
            assert!(e.contains("observer file cam.csv") && e.contains(want), "{text:?}: {e}");
        }
        let e = read(Path::new("/nonexistent/cam.csv")).unwrap_err().to_string();
        assert!(e.contains("/nonexistent/cam.csv") && e.contains("cannot read"), "{e}");
        let e = read(Path::new("/nonexistent/cam.json")).unwrap_err().to_string();
        assert!(e.contains("/nonexistent/cam.json") && e.contains("cannot read"), "{e}");
    }

    fn json(index: &str, rows: &str) -> String {
        format!(
            r#"{{"header": {{"license": "Apache-2.0"}}, "spectral_data": {{"units": "relative",
               "index": {{"main": {index}}}, "data": {{"main": {{{rows}}}}}}}}}"#
        )
    }

    /// The rawtoaces layout: channels taken by name in any order, wavelengths in any order.
    #[test]
    fn rawtoaces_json() {
        let o = parse_json(
            &json(
                r#"["B", "G", "R"]"#,
                r#""500": [0.7, 0.6, 0.5], "400": [0.3, 0.2, 0.1], "600": [0.0, 0.1, 0.2]"#,
            ),
            "cam.json",
        )
        .unwrap();
        assert_eq!(o.eval(400.0), [0.1, 0.2, 0.3]);
        assert_eq!(o.eval(500.0), [0.5, 0.6, 0.7]);
        assert_eq!(o.eval(700.0), [0.0; 3]);
        assert_eq!(o.name, "cam.json");
    }

    #[test]
    fn bad_json_is_an_error_naming_the_field_and_the_entry() {
        let rows = r#""400": [1, 2, 3], "500": [1, 2, 3], "600": [1, 2, 3]"#;
        let cases = [
            ("{".to_string(), "not valid JSON"),
            (r#"{"spectral_data": {}}"#.to_string(), "field spectral_data.index is missing"),
            (
                json(r#"["R", "G"]"#, r#""400": [1, 2], "500": [1, 2], "600": [1, 2]"#),
                "no channel 'B' (it names R, G)",
            ),
            (
                json(r#"["R", "G", "B"]"#, r#""400": [1, 2, 3], "500": [1, 2], "600": [1, 2, 3]"#),
                "entry \"500\": 2 values",
            ),
            (
                json(r#"["R", "G", "B"]"#, r#""400": [1, 2, 3], "x": [1, 2, 3], "600": [1, 2, 3]"#),
                "entry \"x\": the wavelength",
            ),
            (
                json(r#"["R", "G", "B"]"#, r#""400": [1, -2, 3], "500": [1, 2, 3], "600": [1, 2, 3]"#),
                "entry \"400\": channel G: sensitivity -2",
            ),
            (
                json(r#"["R", "G", "B"]"#, r#""400": [1, 2, null], "500": [1, 2, 3], "600": [1, 2, 3]"#),
                "channel B: null",
            ),
            (
                json(r#"["R", "G", "B"]"#, r#""400": [1, 2, 3], "400.0": [1, 2, 3], "600": [1, 2, 3]"#),
                "400 nm is given twice",
            ),
            (
                // The same key twice: serde_json's map kept the last, silently.
                json(r#"["R", "G", "B"]"#, r#""400": [9, 9, 9], "400": [1, 2, 3], "600": [1, 2, 3]"#),
                "the key \"400\" is given twice",
            ),
            (json(r#"["R", "G", "B"]"#, r#""400": [1, 2, 3], "500": [1, 2, 3]"#), "2 data rows"),
            (
                json(r#"["R", "G", "B"]"#, r#""400": [1, 0, 3], "500": [1, 0, 3], "600": [1, 0, 3]"#),
                "channel G is zero",
            ),
        ];
        for (text, want) in cases {
            let e = parse_json(&text, "cam.json").unwrap_err().to_string();
            assert!(e.contains("observer file cam.json") && e.contains(want), "{text}: {e}");
        }
        assert!(parse_json(&json(r#"["R", "G", "B"]"#, rows), "cam.json").is_ok());
    }
}
