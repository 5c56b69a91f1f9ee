//! Observers from a file (`--observer FILE`, issue 33): a camera's or any other three
//! sensitivity curves, as
//! - a CSV of wavelength (nm) and three columns — the layout camera databases and
//!   `colour-science` export, read as [`crate::table_text`] reads every table (a header,
//!   `#` comments, semicolons, tabs, commas or spaces, decimal commas, UTF-16, any line ends;
//!   docs/cameras.md);
//! - the Academy's rawtoaces camera JSON (AcademySoftwareFoundation/rawtoaces-data,
//!   `schema/spectral_1.0.0.json`): `spectral_data.index.main` names the channels (R, G and B
//!   are taken by name), `spectral_data.data.main` maps each wavelength to its values.
//!
//! Checked, each refusal naming the file and the row (CSV) or the wavelength's entry (JSON) and
//! the column: finite numbers, no empty cell, wavelengths increasing strictly (CSV) or distinct
//! (JSON), sensitivities ≥ 0 (rounding noise of 10⁻⁹ of the largest aside), at least three
//! samples, some overlap with 360–830 nm, no channel all zero. Outside the file's range the
//! sensitivities are zero; between samples they are linear. A file holding a CIE observer's
//! functions gives CIE XYZ ([`cie_twin`]); any other is shown as a camera.

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
    let bytes = crate::input::read_regular(path, MAX_FILE_BYTES)
        .map_err(|e| ColorError::Table(format!("observer file {shown}: cannot read it: {e}")))?;
    let text = crate::table_text::decode(&bytes);
    let json = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"))
        || text.trim_start_matches('\u{feff}').trim_start().starts_with('{');
    if json { parse_json(&text, &shown) } else { parse(&text, &shown) }
}

/// A field as it may be shown in an error: control characters escaped, at most 40 characters
/// (the file may not be a table at all).
fn shown_field(f: &str) -> String {
    let s: String = f.chars().take(40).collect::<String>().escape_debug().to_string();
    if f.chars().count() > 40 { format!("{s}…") } else { s }
}

/// The observer in CSV `text`; `source` names it in errors and becomes its name.
pub fn parse(text: &str, source: &str) -> Result<Observer> {
    let bad =
        |row: usize, what: String| ColorError::Table(format!("observer file {source}: row {row}: {what}"));
    let mut lambda = Vec::new();
    let mut rows = Vec::new();
    let mut columns: [Vec<f64>; 3] = Default::default();
    for r in crate::table_text::rows(text, 4) {
        let r = r.map_err(|e| {
            use crate::table_text::TableError as T;
            let what = match &e {
                T::Columns { found, .. } => {
                    let hint = if *found > 8 {
                        "; one row per wavelength is expected (sensitivities given as rows, as in Jiang et al.'s \
                         camera database, must be turned into columns: tools/camspec_to_csv.py)"
                    } else {
                        ""
                    };
                    format!(
                        "{found} column{}; expected 4 (wavelength in nm and three sensitivities){hint}",
                        if *found == 1 { "" } else { "s" }
                    )
                }
                T::Empty { column, .. } => {
                    format!("column {column} is empty (write 0 where a sensitivity is zero)")
                }
                T::NotANumber { column, field, .. } => {
                    format!("column {column}: '{}' is not a finite number", shown_field(field))
                }
            };
            bad(e.line(), what)
        })?;
        let (row, nums) = (r.line, r.values);
        if let Some(&prev) = lambda.last()
            && nums[0] <= prev
        {
            return Err(bad(
                row,
                format!("column 1: wavelength {} nm after {prev} nm; wavelengths must increase", nums[0]),
            ));
        }
        lambda.push(nums[0]);
        rows.push(row);
        for (col, &v) in columns.iter_mut().zip(&nums[1..]) {
            col.push(v);
        }
    }
    finish(lambda, columns, source, |c| format!("column {}", c + 2), |i| format!("row {}", rows[i]))
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
    let mut rows: Vec<(f64, [f64; 3], &String)> = Vec::with_capacity(data.len());
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
                Some(x) if x.is_finite() => x,
                _ => return Err(at(format!("channel {name}: {} is not a finite number", list[i]))),
            };
        }
        rows.push((l, v, key));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    if let Some(w) = rows.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(err(format!("spectral_data.data.main: wavelength {} nm is given twice", w[0].0)));
    }
    let lambda = rows.iter().map(|r| r.0).collect();
    let columns = [0, 1, 2].map(|c| rows.iter().map(|r| r.1[c]).collect());
    finish(
        lambda,
        columns,
        source,
        |c| format!("channel {}", ["R", "G", "B"][c]),
        |i| format!("spectral_data.data.main entry \"{}\"", rows[i].2),
    )
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
    place: impl Fn(usize) -> String,
) -> Result<Observer> {
    let whole = |what: String| ColorError::Table(format!("observer file {source}: {what}"));
    // Negative sensitivities are refused, but not rounding noise: colour-science's CIE 1931 and
    // 1964 tables, and so spectra's own built-ins written out, hold z̄ values of −3·10⁻²² and
    // −1.4·10⁻²⁰ where the CIE's are 0, and such a file was refused.
    let largest = columns.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for i in 0..lambda.len() {
        for (c, col) in columns.iter().enumerate() {
            if col[i] < -NEGATIVE_NOISE * largest {
                return Err(whole(format!(
                    "{}: {}: sensitivity {} is negative (sensitivities with negative lobes, such as the CIE 1931 \
                     RGB colour-matching functions, are not supported: use a non-negative transform of them, such as XYZ)",
                    place(i),
                    column_name(c),
                    col[i]
                )));
            }
        }
    }
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

/// How far (a share of each channel's peak) a file's samples may lie from a CIE observer's,
/// each channel scaled by its own factor, for the file to be that observer (see [`cie_twin`]).
/// The CIE's 5 nm tables with four decimals lie within 5·10⁻⁵; no camera comes near it.
pub const CIE_TWIN_TOLERANCE: f64 = 1e-4;

/// The CIE observer whose colour-matching functions an observer from a file holds, if any: at
/// every sample of the file in 360–830 nm, each channel within [`CIE_TWIN_TOLERANCE`] of its
/// peak of that observer's x̄, ȳ or z̄ times a positive factor of its own (percent, or ȳ scaled
/// to another peak, are the same observer: the renderers scale each of X, Y and Z by the
/// white). Such a file gives CIE XYZ and is shown as the built-in is; any other file is shown as
/// a camera. (Every file was: the CIE's own CSV of CIE 1931 gave an image ΔE2000 up to 30 from
/// `--observer cie1931`, XYZ white balanced and shown as RGB.)
pub fn cie_twin(o: &Observer) -> Option<&'static str> {
    let Spectrum::Piecewise { lambda, .. } = &o.bar[0] else { return None };
    let at: Vec<f64> = lambda.iter().copied().filter(|l| (LAMBDA_MIN..=LAMBDA_MAX).contains(l)).collect();
    if at.len() < 3 {
        return None;
    }
    let twin = |cie: &Observer| {
        (0..3).all(|c| {
            let f: Vec<f64> = at.iter().map(|&l| o.bar[c].eval(l)).collect();
            let b: Vec<f64> = at.iter().map(|&l| cie.bar[c].eval(l)).collect();
            let bb: f64 = b.iter().map(|v| v * v).sum();
            let k = f.iter().zip(&b).map(|(f, b)| f * b).sum::<f64>() / bb;
            let peak = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            bb > 0.0
                && k > 0.0
                && peak > 0.0
                && f.iter().zip(&b).all(|(f, b)| (f - k * b).abs() <= CIE_TWIN_TOLERANCE * peak)
        })
    };
    [
        ("cie1931", Observer::cie1931()),
        ("cie1964", Observer::cie1964()),
        ("cie2015_2", Observer::cie2015_2()),
        ("cie2015_10", Observer::cie2015_10()),
    ]
    .into_iter()
    .find_map(|(name, cie)| twin(&cie).then_some(name))
}

/// A negative value no further below zero than this share of a file's largest value is
/// rounding noise, read as it is (see `finish`).
pub const NEGATIVE_NOISE: f64 = 1e-9;

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

    /// Every sample of `o` (its first channel's wavelengths), as `row` formats them.
    fn table(o: &Observer, row: impl Fn(f64, [f64; 3]) -> String) -> String {
        let Spectrum::Piecewise { lambda, .. } = &o.bar[0] else { panic!("tabulated") };
        lambda.iter().map(|&l| row(l, o.eval(l))).collect()
    }

    /// Found by a sweep of files from elsewhere: CIE 1931 written as a spreadsheet writes it was
    /// refused or misread — decimal commas after semicolons ("7 columns"), classic Mac line
    /// ends ("0 data rows"), a Windows-1252 or UTF-16 export ("not valid UTF-8"), and the
    /// built-in's own values (colour-science's, whose z̄ is −3·10⁻²² at 651 nm) as "negative".
    /// Each now reads as the built-in, percent included, and is CIE XYZ (it was a camera).
    #[test]
    fn cie_1931_from_spreadsheets_and_databases_reads_as_the_built_in() {
        let cie = Observer::cie1931();
        let plain = table(&cie, |l, v| format!("{l},{:?},{:?},{:?}\n", v[0], v[1], v[2]));
        let comma = |x: f64| format!("{x:?}").replace('.', ",");
        let variants: Vec<(&str, Vec<u8>, f64)> = vec![
            ("cie.csv", plain.clone().into_bytes(), 1.0),
            (
                "bom_crlf.csv",
                format!("\u{feff}\"nm\",\"x\",\"y\",\"z\"\r\n{}\r\n\r\n", plain.replace('\n', "\r\n"))
                    .into_bytes(),
                1.0,
            ),
            ("mac.csv", format!("wavelength,x,y,z\r{}", plain.replace('\n', "\r")).into_bytes(), 1.0),
            (
                "excel_de.csv",
                table(&cie, |l, v| {
                    format!("{l};\"{}\";\"{}\";\"{}\"\r\n", comma(v[0]), comma(v[1]), comma(v[2]))
                })
                .into_bytes(),
                1.0,
            ),
            (
                "tabs_decimal_comma.txt",
                table(&cie, |l, v| format!("{l}\t{}\t{}\t{}\n", comma(v[0]), comma(v[1]), comma(v[2])))
                    .into_bytes(),
                1.0,
            ),
            (
                "percent.csv",
                table(&cie, |l, v| format!("{l},{:?},{:?},{:?}\n", 100.0 * v[0], 100.0 * v[1], 100.0 * v[2]))
                    .into_bytes(),
                100.0,
            ),
            ("latin1.csv", [b"Wellenl\xe4nge,x\xaf 2\xb0,y,z\n".as_slice(), plain.as_bytes()].concat(), 1.0),
            (
                "utf16.txt",
                [0xffu8, 0xfe]
                    .into_iter()
                    .chain(
                        format!("nm\tx\ty\tz\r\n{}", plain.replace(',', "\t"))
                            .encode_utf16()
                            .flat_map(u16::to_le_bytes),
                    )
                    .collect(),
                1.0,
            ),
        ];
        let dir = tempfile::tempdir().unwrap();
        for (name, bytes, scale) in variants {
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).unwrap();
            let o = read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
            for i in 0..=470 {
                let l = 360.0 + i as f64;
                let (a, b) = (o.eval(l), cie.eval(l));
                for c in 0..3 {
                    assert!(
                        (a[c] / scale - b[c]).abs() <= 1e-15 * scale.max(1.0),
                        "{name}: {l} nm: {a:?} vs {b:?}"
                    );
                }
            }
            assert_eq!(o.kind(), crate::observer::ObserverKind::CieXyz, "{name}");
            assert_eq!(cie_twin(&o), Some("cie1931"), "{name}");
        }
    }

    /// Only the CIE observers' functions are CIE XYZ: CIE 1964 is, each channel scaled its own
    /// way too; a 5 nm subsample is; every camera, the ACES RICD (XYZ mixed) and the cone
    /// fundamentals are not.
    #[test]
    fn only_cie_functions_in_a_file_are_xyz() {
        let write = |o: &Observer, k: [f64; 3]| {
            table(o, |l, v| format!("{l},{:?},{:?},{:?}\n", k[0] * v[0], k[1] * v[1], k[2] * v[2]))
        };
        let o = parse(&write(&Observer::cie1964(), [2.0, 0.5, 3.0]), "c.csv").unwrap();
        assert_eq!((o.kind(), cie_twin(&o)), (crate::observer::ObserverKind::CieXyz, Some("cie1964")));
        let five: String =
            write(&Observer::cie1931(), [1.0; 3]).lines().step_by(5).map(|l| format!("{l}\n")).collect();
        assert_eq!(cie_twin(&parse(&five, "5nm.csv").unwrap()), Some("cie1931"));
        for name in Observer::names().into_iter().filter(|n| !n.starts_with("cie")) {
            let o = parse(&write(&Observer::by_name(name).unwrap(), [1.0; 3]), "f.csv").unwrap();
            assert_eq!(cie_twin(&o), None, "{name}");
            assert_eq!(o.kind(), crate::observer::ObserverKind::CameraRgb, "{name}");
        }
    }

    /// Found by a sweep: runs of separators were one separator, so an empty cell shifted the
    /// columns after it (`400,0.1,,0.2,0.3` read as 0.1, 0.2, 0.3), a decimal comma was a
    /// separator (`400;0,5;1` read as 0, 5, 1) and so was a comma inside quotes. Empty cells are
    /// named; a spreadsheet's trailing separators are not cells.
    #[test]
    fn empty_cells_and_decimal_commas_are_not_separators() {
        let e = parse("400,0.1,,0.2,0.3\n500,1,1,1,1\n600,1,1,1,1\n", "e.csv").unwrap_err().to_string();
        assert!(e.contains("e.csv: row 1: 5 columns"), "{e}");
        let e = parse("400,1,1,1\n500,,0.3,0.1\n600,1,1,1\n", "e.csv").unwrap_err().to_string();
        assert!(e.contains("row 2: column 2 is empty"), "{e}");
        let e = parse("400,1,1,1\n620,0.5,0.3,\n", "cvrl.csv").unwrap_err().to_string();
        assert!(e.contains("row 2: column 4 is empty"), "{e}");
        for text in ["400;0,5;1\n500;0,7;1\n600;1,2;1\n", "400,\"0,5\",1\n500,\"0,7\",1\n600,\"1,2\",1\n"] {
            let e = parse(text, "d.csv").unwrap_err().to_string();
            assert!(e.contains("row 1: 3 columns"), "{text:?}: {e}");
        }
        let o = parse("400,1,2,3,,\n500;1;2;3;;\n600\t1\t2\t3\t\n", "t.csv").unwrap();
        assert_eq!(o.eval(500.0), [1.0, 2.0, 3.0]);
        // A field shown in an error cannot write to the terminal.
        let e = parse("400,1,1,1\n500,\u{1b}[2J,1,1\n", "x.csv").unwrap_err().to_string();
        assert!(e.contains("\\u{1b}[2J") && !e.contains('\u{1b}'), "{e}");
    }

    /// Rounding noise below zero is not a negative sensitivity (the built-ins hold it); a
    /// negative lobe is refused, saying which functions have them.
    #[test]
    fn rounding_noise_is_not_a_negative_lobe() {
        assert!(parse("400,1,1,1\n500,1,-1e-21,1\n600,1,1,1\n", "n.csv").is_ok());
        let e = parse("400,1,1,1\n500,1,-0.01,1\n600,1,1,1\n", "rgb.csv").unwrap_err().to_string();
        assert!(
            e.contains("rgb.csv: row 2: column 3: sensitivity -0.01 is negative")
                && e.contains("CIE 1931 RGB"),
            "{e}"
        );
        let j = json(r#"["R", "G", "B"]"#, r#""400": [1, 1, 1], "500": [1, -1e-21, 1], "600": [1, 1, 1]"#);
        assert!(parse_json(&j, "n.json").is_ok());
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
