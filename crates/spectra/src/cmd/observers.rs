//! `spectra observers`: every built-in observer and camera `--observer` takes, with what its
//! channels mean, the wavelengths its data covers and where it comes from.

use anyhow::Result;
use color::Observer;
use color::observer::ObserverKind;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Print JSON (a list of objects: name, kind, from_nm, to_nm, source) instead of a table.
    #[arg(long)]
    pub json: bool,
}

fn kind_name(k: ObserverKind) -> &'static str {
    match k {
        ObserverKind::CieXyz => "CIE XYZ",
        ObserverKind::CameraRgb => "camera RGB",
        ObserverKind::Receptors => "receptors",
    }
}

pub fn run(a: Args) -> Result<()> {
    let mut rows = Vec::new();
    for name in Observer::names() {
        let o = Observer::by_name(name)?;
        let (from, to) = o.support().unwrap_or((f64::NAN, f64::NAN));
        rows.push((name, kind_name(o.kind()), from, to, Observer::source(name).unwrap_or_default()));
    }
    if a.json {
        let v: Vec<_> = rows
            .iter()
            .map(|(n, k, f, t, s)| serde_json::json!({"name": n, "kind": k, "from_nm": f, "to_nm": t, "source": s}))
            .collect();
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    // The name column as wide as the longest name (arashi_vision_insta360_x5 overflowed 24).
    let w = rows.iter().map(|r| r.0.chars().count()).max().unwrap_or(0).max(4);
    println!("{:<w$} {:<11} {:>11}  source", "name", "kind", "data (nm)");
    for (n, k, f, t, s) in &rows {
        println!("{n:<w$} {k:<11} {:>11}  {s}", format!("{f:.0}–{t:.0}"));
    }
    println!(
        "\nor a file: --observer my_camera.csv (wavelength and three columns) or a rawtoaces camera .json \
         (docs/cameras.md)"
    );
    Ok(())
}
