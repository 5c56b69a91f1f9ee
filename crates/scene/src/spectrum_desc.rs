//! `SpectrumDesc`: the JSON a scene uses to name a spectrum, resolved to a [`Spectrum`].
//!
//! Forms (see `docs/scene-format.md`):
//! - `"D65"`, `"F11"`, `"LED-B3"`, `"3200K"`: a named illuminant ([`color::illuminant::by_name`]);
//! - `{"blackbody": 3200}`: Planck's law at 3200 K;
//! - `{"sampled": {"wavelengths": [..], "values": [..]}}`: nm, strictly increasing;
//! - `{"csv": "path.csv"}`: two columns λ (nm), value, read by [`color::table_text`] (a
//!   header line, `#` comments, semicolons, tabs or spaces, decimal commas, UTF-16); relative
//!   to the glTF file;
//! - `{"colorchecker": "red"}` or `{"colorchecker": 15}`: a ColorChecker Classic patch by name
//!   (case-insensitive; a unique prefix such as `"white"` is enough) or 1-based chart index.
//!
//! Objects must have exactly one key, so a typo is an error rather than a silently different
//! spectrum.

use color::Spectrum;
use color::data::colorchecker;
use serde_json::Value;

use crate::context::Ctx;
use crate::error::SceneError;

/// Parses and resolves a SpectrumDesc found at JSON path `field`, refusing one that evaluates
/// to NaN or infinity anywhere in 360–830 nm (range checks such as [0, 1] for a reflectance
/// compare with `max`, which skips NaN, so they cannot be relied on to catch it).
pub(crate) fn resolve(ctx: &Ctx, field: &str, v: &Value) -> Result<Spectrum, SceneError> {
    let s = resolve_unchecked(ctx, field, v)?;
    let (lo, hi) = (color::spectrum::LAMBDA_MIN, color::spectrum::LAMBDA_MAX);
    let steps = (hi - lo).round() as usize;
    if let Some(l) = (0..=steps).map(|i| lo + i as f64).find(|&l| !s.eval(l).is_finite()) {
        return Err(ctx.extras(field, format!("the spectrum is not finite at {l} nm")));
    }
    Ok(s)
}

fn resolve_unchecked(ctx: &Ctx, field: &str, v: &Value) -> Result<Spectrum, SceneError> {
    let err = |f: &str, m: String| ctx.extras(f, m);
    match v {
        Value::String(name) => color::illuminant::by_name(name).map_err(|e| err(field, e.to_string())),
        Value::Object(map) => {
            if map.len() != 1 {
                let keys: Vec<&str> = map.keys().map(String::as_str).collect();
                return Err(err(
                    field,
                    format!(
                        "a spectrum object needs exactly one of the keys blackbody, sampled, csv, colorchecker; got [{}]",
                        keys.join(", ")
                    ),
                ));
            }
            let (key, inner) = map.iter().next().expect("one entry");
            let sub = format!("{field}.{key}");
            match key.as_str() {
                "blackbody" => {
                    let k = inner
                        .as_f64()
                        .ok_or_else(|| err(&sub, format!("expected kelvin as a number, got {inner}")))?;
                    Spectrum::blackbody(k).map_err(|e| err(&sub, e.to_string()))
                }
                "sampled" => sampled(ctx, &sub, inner),
                "csv" => {
                    let rel = inner
                        .as_str()
                        .ok_or_else(|| err(&sub, format!("expected a file path string, got {inner}")))?;
                    let file = ctx.resolve(&sub, rel)?;
                    read_csv(ctx, &sub, &file)
                }
                "colorchecker" => {
                    let i = colorchecker_index(inner).map_err(|m| err(&sub, m.to_string()))?;
                    Ok(Spectrum::from_table(&colorchecker::SPECTRA[i]))
                }
                other => Err(err(
                    &sub,
                    format!(
                        "unknown spectrum kind '{other}'; expected blackbody, sampled, csv or colorchecker"
                    ),
                )),
            }
        }
        other => Err(err(field, format!("expected an illuminant name or a spectrum object, got {other}"))),
    }
}

fn numbers(ctx: &Ctx, field: &str, v: Option<&Value>) -> Result<Vec<f64>, SceneError> {
    let arr = v.and_then(Value::as_array).ok_or_else(|| ctx.extras(field, "expected an array of numbers"))?;
    arr.iter()
        .enumerate()
        .map(|(i, x)| {
            x.as_f64().filter(|f| f.is_finite()).ok_or_else(|| {
                ctx.extras(format!("{field}[{i}]"), format!("expected a finite number, got {x}"))
            })
        })
        .collect()
}

fn sampled(ctx: &Ctx, field: &str, v: &Value) -> Result<Spectrum, SceneError> {
    let map = v
        .as_object()
        .ok_or_else(|| ctx.extras(field, "expected {\"wavelengths\": [...], \"values\": [...]}"))?;
    if let Some(k) = map.keys().find(|k| *k != "wavelengths" && *k != "values") {
        return Err(ctx.extras(format!("{field}.{k}"), "unknown key; expected wavelengths and values"));
    }
    let wf = format!("{field}.wavelengths");
    let lambda = numbers(ctx, &wf, map.get("wavelengths"))?;
    let values = numbers(ctx, &format!("{field}.values"), map.get("values"))?;
    check_increasing(&lambda).map_err(|m| ctx.extras(&wf, m))?;
    Spectrum::piecewise(lambda, values).map_err(|e| ctx.extras(field, e.to_string()))
}

fn check_increasing(lambda: &[f64]) -> Result<(), String> {
    match lambda.windows(2).position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater)) {
        Some(i) => Err(format!(
            "wavelengths must increase strictly: [{}] = {} is followed by [{}] = {}",
            i,
            lambda[i],
            i + 1,
            lambda[i + 1]
        )),
        None => Ok(()),
    }
}

/// A ColorChecker patch reference that names no patch.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PatchError {
    #[error("patch number {0} is outside 1–24")]
    OutOfRange(u64),
    #[error("expected a patch name or number 1–24, got {0}")]
    NotAPatch(Value),
    #[error("unknown ColorChecker patch '{0}'; patches are: {names}", names = colorchecker::NAMES.join(", "))]
    Unknown(String),
    #[error("'{name}' matches several ColorChecker patches ({}); be more specific", matches.join(", "))]
    Ambiguous { name: String, matches: Vec<&'static str> },
}

/// Index (0-based) of a ColorChecker patch given as a name or a 1-based number.
pub fn colorchecker_index(v: &Value) -> Result<usize, PatchError> {
    if let Some(n) = v.as_u64() {
        return if (1..=24).contains(&n) { Ok(n as usize - 1) } else { Err(PatchError::OutOfRange(n)) };
    }
    let Some(name) = v.as_str() else {
        return Err(PatchError::NotAPatch(v.clone()));
    };
    let want = name.trim().to_ascii_lowercase();
    if let Some(i) = colorchecker::NAMES.iter().position(|n| n.eq_ignore_ascii_case(&want)) {
        return Ok(i);
    }
    let hits: Vec<usize> =
        (0..24).filter(|&i| colorchecker::NAMES[i].to_ascii_lowercase().starts_with(&want)).collect();
    match hits.as_slice() {
        [i] if !want.is_empty() => Ok(*i),
        [] | [_] => Err(PatchError::Unknown(name.to_string())),
        many => Err(PatchError::Ambiguous {
            name: name.to_string(),
            matches: many.iter().map(|&i| colorchecker::NAMES[i]).collect(),
        }),
    }
}

/// Largest CSV spectrum file read (bytes): a spectrum sampled every 0.01 nm over 200–2000 nm
/// is well under it.
pub const MAX_CSV_BYTES: u64 = 16 << 20;

/// Reads a two-column CSV spectrum; errors carry the line number.
pub(crate) fn read_csv(ctx: &Ctx, field: &str, file: &std::path::Path) -> Result<Spectrum, SceneError> {
    let bytes = color::input::read_regular(file, MAX_CSV_BYTES)
        .map_err(|e| ctx.extras(field, format!("cannot read {}: {e}", file.display())))?;
    parse_csv(ctx, field, file, &bytes)
}

/// Parses the bytes of a CSV spectrum `name` as a scene's `{"csv": …}` would (for tools and the
/// fuzz harness); the error is the one-line message a scene would give.
pub fn csv_spectrum(name: &str, bytes: &[u8]) -> Result<Spectrum, SceneError> {
    let ctx = Ctx::builtin("csv");
    parse_csv(&ctx, "csv", std::path::Path::new(name), bytes)
}

fn parse_csv(ctx: &Ctx, field: &str, file: &std::path::Path, bytes: &[u8]) -> Result<Spectrum, SceneError> {
    let csv_err = |line: u64, message: String| SceneError::Csv {
        path: ctx.path.clone(),
        field: field.to_string(),
        csv: file.to_path_buf(),
        line,
        message,
    };
    // Read as observer files are (`color::table_text`), so a spectrophotometer's or a
    // spreadsheet's export reads the same whichever file it is given as.
    let text = color::table_text::decode(bytes);
    let (mut lambda, mut values, mut lines) = (Vec::new(), Vec::new(), Vec::new());
    for row in color::table_text::rows(&text, 2) {
        let row = row.map_err(|e| {
            use color::table_text::TableError as T;
            // Which column, not its text: the file may not be a spectrum at all (a mistyped or
            // hostile reference), and its content must not be echoed.
            let col = |c: usize| if c == 1 { "1 (wavelength)" } else { "2 (value)" };
            let message = match e {
                T::Columns { found, .. } => {
                    format!("expected 2 columns (wavelength in nm, value), found {found}")
                }
                T::Empty { column, .. } => format!("column {} is empty", col(column)),
                T::NotANumber { column, .. } => format!("column {} is not a finite number", col(column)),
            };
            csv_err(e.line() as u64, message)
        })?;
        lambda.push(row.values[0]);
        values.push(row.values[1]);
        lines.push(row.line as u64);
    }
    if lambda.len() < 2 {
        return Err(csv_err(
            lines.last().copied().unwrap_or(1),
            format!("needs at least two rows of data, found {}", lambda.len()),
        ));
    }
    if let Some(i) =
        lambda.windows(2).position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
    {
        return Err(csv_err(
            lines[i + 1],
            format!("wavelengths must increase strictly: {} follows {}", lambda[i + 1], lambda[i]),
        ));
    }
    Spectrum::piecewise(lambda, values).map_err(|e| csv_err(1, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn ctx() -> Ctx {
        Ctx::file(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/x.gltf").as_path())
    }

    #[test]
    fn every_form_resolves() {
        let c = ctx();
        assert!(resolve(&c, "f", &json!("F11")).is_ok());
        assert!(matches!(resolve(&c, "f", &json!({"blackbody": 3200})).unwrap(), Spectrum::Blackbody { .. }));
        let s = resolve(
            &c,
            "f",
            &json!({"sampled": {"wavelengths": [400, 500, 600], "values": [0.1, 0.5, 0.2]}}),
        )
        .unwrap();
        assert_eq!(s.eval(450.0), 0.3);
        let red = resolve(&c, "f", &json!({"colorchecker": "Red"})).unwrap();
        assert_eq!(red, resolve(&c, "f", &json!({"colorchecker": 15})).unwrap());
        assert_eq!(red, Spectrum::from_table(&colorchecker::SPECTRA[14]));
        let white = resolve(&c, "f", &json!({"colorchecker": "white"})).unwrap();
        assert_eq!(white, Spectrum::from_table(&colorchecker::SPECTRA[18]));
        let csv = resolve(&c, "f", &json!({"csv": "spectrum.csv"})).unwrap();
        assert_eq!(csv.eval(500.0), 0.5);
    }

    fn msg(v: serde_json::Value) -> String {
        resolve(&ctx(), "materials[0].extras.reflectance", &v).unwrap_err().to_string()
    }

    #[test]
    fn bad_descs_name_the_field() {
        let e = msg(json!("D42"));
        assert!(
            e.contains("materials[0].extras.reflectance") && e.contains("D42") && e.contains("D65"),
            "{e}"
        );
        let e = msg(json!({"sampled": {"wavelengths": [400, 500, 500], "values": [1, 1, 1]}}));
        assert!(e.contains("sampled.wavelengths") && e.contains("increase strictly"), "{e}");
        let e = msg(json!({"sampled": {"wavelengths": [400, 500], "values": [1, 1], "scale": 2}}));
        assert!(e.contains("sampled.scale") && e.contains("unknown key"), "{e}");
        let e = msg(json!({"blackbody": -5}));
        assert!(e.contains("blackbody") && e.contains("500–1000000 K"), "{e}");
        let e = msg(json!({"colorchecker": 25}));
        assert!(e.contains("1–24"), "{e}");
        let e = msg(json!({"colorchecker": "neutral"}));
        assert!(e.contains("several"), "{e}");
        let e = msg(json!({"blackbody": 3000, "csv": "a.csv"}));
        assert!(e.contains("exactly one"), "{e}");
        let e = msg(json!({"gaussian": 500}));
        assert!(e.contains("unknown spectrum kind"), "{e}");
        let e = msg(json!(5));
        assert!(e.contains("expected an illuminant name"), "{e}");
    }

    /// The spectrum every export below holds: 400, 500, 600 nm → 0.1, 0.5, 0.25.
    fn three() -> Spectrum {
        Spectrum::piecewise(vec![400.0, 500.0, 600.0], vec![0.1, 0.5, 0.25]).unwrap()
    }

    fn utf16le(text: &str) -> Vec<u8> {
        [0xffu8, 0xfe].into_iter().chain(text.encode_utf16().flat_map(u16::to_le_bytes)).collect()
    }

    /// A measured spectrum as instruments and spreadsheets export it was refused (the `csv`
    /// crate split on commas only: `400;0,1` was one field, a tab- or space-separated file one
    /// column, a UTF-16 file not text) or, with a decimal comma after a comma-free separator,
    /// misread. It is read as observer files are (`color::table_text`).
    #[test]
    fn csv_spectra_as_other_tools_write_them() {
        let exports: Vec<(&str, Vec<u8>)> = vec![
            // A spectrophotometer's export in a European locale: header, semicolons, decimal
            // commas, CRLF.
            ("xrite_de.csv", b"Wellenl\xe4nge [nm];Remission\r\n400;0,1\r\n500;0,5\r\n600;0,25\r\n".to_vec()),
            // A spreadsheet's "Unicode text": UTF-16 LE with a BOM, tab-separated.
            ("unicode.txt", utf16le("\u{3bb} (nm)\tR\r\n400\t0,1\r\n500\t0,5\r\n600\t0,25\r\n")),
            // Tab-separated with a point, classic Mac OS line ends (CR alone).
            ("mac.txt", b"nm\tR\r400\t0.1\r500\t0.5\r600\t0.25\r".to_vec()),
            // Quoted fields with a UTF-8 BOM, a decimal comma inside quotes.
            (
                "quoted.csv",
                "\u{feff}\"nm\",\"R\"\r\n\"400\",\"0,1\"\n\"500\",\"0,5\"\n\"600\",\"0,25\"\n".into(),
            ),
            // Comments, a blank line, trailing separators (a spreadsheet's empty columns).
            (
                "comments.csv",
                b"# measured 2024-05-01\nnm;R;;\n400;0,1;;\n\n# lamp warm\n500;0,5;\n600;0,25;;\n".to_vec(),
            ),
            // A fixed-width table.
            ("fixed.txt", b"  nm      R\n 400   0.10\n 500   0.50\n 600   0.25\n".to_vec()),
        ];
        for (name, bytes) in exports {
            let s = csv_spectrum(name, &bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(s, three(), "{name}");
        }
        // Through a scene, from a file beside it.
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.txt"), utf16le("nm\tR\n400\t0,1\n500\t0,5\n600\t0,25\n")).unwrap();
        let c = Ctx::file(&dir.path().join("s.gltf"));
        assert_eq!(resolve(&c, "f", &json!({"csv": "r.txt"})).unwrap(), three());
    }

    /// An empty cell is named by its line (a run of separators was one separator, so
    /// `400;;0,1` shifted the value into the wavelength's place); a field's text is never
    /// echoed, since the file may not be a spectrum at all.
    #[test]
    fn csv_empty_cells_and_bad_lines_are_named() {
        let cases: [(&[u8], &str); 6] = [
            (b"nm;R\n400;0,1\n500;\n600;0,25\n", "line 3: column 2 (value) is empty"),
            (b"400,0.1\n,0.5\n600,0.25\n", "line 2: column 1 (wavelength) is empty"),
            (b"400;;0,1\n500;0,5\n", "line 1: expected 2 columns (wavelength in nm, value), found 3"),
            (b"400\t0.1\r\n500\tsecret\r\n", "line 2: column 2 (value) is not a finite number"),
            (b"400,0.1\r500,0.5\r450,0.3\r", "line 3: wavelengths must increase strictly"),
            (b"nm,R\n# none\n400,0.1\n", "line 3: needs at least two rows of data, found 1"),
        ];
        for (bytes, want) in cases {
            let e = csv_spectrum("m.csv", bytes).unwrap_err().to_string();
            assert!(e.contains("m.csv") && e.contains(want) && !e.contains("secret"), "{bytes:?}: {e}");
            assert!(matches!(csv_spectrum("m.csv", bytes), Err(SceneError::Csv { .. })));
        }
    }

    #[test]
    fn csv_errors_carry_line_numbers() {
        let e = msg(json!({"csv": "bad_value.csv"}));
        assert!(
            e.contains("bad_value.csv: line 4")
                && e.contains("column 2 (value) is not a finite number")
                && !e.contains("abc"),
            "{e}"
        );
        let e = msg(json!({"csv": "not_increasing.csv"}));
        assert!(e.contains("line 3") && e.contains("increase strictly"), "{e}");
        let e = msg(json!({"csv": "missing.csv"}));
        assert!(
            e.contains("reflectance.csv") && e.contains("missing.csv") && e.contains("cannot read"),
            "{e}"
        );
    }
}
