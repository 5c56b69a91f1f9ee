//! Observers from a file (`--observer FILE.csv`, issue 33): a camera's or any other three
//! sensitivity curves, as a CSV of wavelength (nm) and three columns — the layout camera
//! databases and `colour-science` export. Header and `#` comment lines are skipped; commas,
//! semicolons, tabs or spaces separate the fields. Checked, each refusal naming the file, the
//! row and the column: four fields per row, finite numbers, wavelengths increasing strictly,
//! sensitivities ≥ 0, at least three rows, some overlap with 360–830 nm, no column all zero.
//! Outside the file's range the sensitivities are zero; between rows they are linear.

use std::path::Path;

use crate::error::{ColorError, Result};
use crate::observer::Observer;
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN, Spectrum};

/// Whether an `--observer` value names a file rather than a built-in observer.
pub fn is_file_name(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.ends_with(".csv") || lower.ends_with(".txt") || name.contains('/') || name.contains('\\')
}

/// The observer in the CSV file at `path`, named by the path.
pub fn read(path: &Path) -> Result<Observer> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| ColorError::Table(format!("observer file {shown}: cannot read it: {e}")))?;
    parse(&text, &shown)
}

/// The observer in CSV `text`; `source` names it in errors and becomes its name.
pub fn parse(text: &str, source: &str) -> Result<Observer> {
    let bad =
        |row: usize, what: String| ColorError::Table(format!("observer file {source}: row {row}: {what}"));
    let mut lambda = Vec::new();
    let mut columns: [Vec<f64>; 3] = Default::default();
    for (i, line) in text.lines().enumerate() {
        let row = i + 1;
        let line = line.trim().trim_start_matches('\u{feff}');
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        // A header: the first line whose first field is not a number, before any data.
        if lambda.is_empty() && fields.first().is_some_and(|f| f.parse::<f64>().is_err()) {
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
            return Err(whole(format!("column {} is zero at every wavelength", c + 2)));
        }
    }
    let bar = columns.map(|values| Spectrum::piecewise(lambda.clone(), values));
    let [a, b, c] = bar;
    Ok(Observer { name: source.to_string(), bar: [a?, b?, c?] })
}

#[cfg(test)]
mod tests {
    use super::*;

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
    }
}
