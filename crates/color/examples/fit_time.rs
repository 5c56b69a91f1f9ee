//! Fits a table and writes it, nothing else, so that `/usr/bin/time` measures the fit alone
//! (tools/rgb2spec_compare.sh runs it beside rgb2spec_opt):
//! `cargo run --release -p color --example fit_time -- SPACE RES OUT.coeff [default|unrefined|rgb2spec]`.
//! `default` = what `upsample::table` caches (spectra grid, clamp 10⁴, one refinement sweep);
//! `unrefined` = the same fit without the refinement; `rgb2spec` = rgb2spec's grid and clamp.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        return Err("usage: fit_time SPACE RES OUT.coeff [default|unrefined|rgb2spec]".into());
    }
    let space = color::RgbColorSpace::by_name(&a[1])?;
    let res: usize = a[2].parse().map_err(|e| format!("RES {:?}: {e}", a[2]))?;
    let bar = color::progress::Silent;
    let flag = color::upsample::interrupt_flag();
    let table = match a.get(4).map(|s| s.as_str()).unwrap_or("default") {
        "default" => color::upsample::fit_default_res(&space, res, &bar)?,
        "unrefined" => {
            color::upsample::fit_table_with(&space, &color::upsample::FitOptions::spectra(res), &bar, flag)?
        }
        "rgb2spec" => {
            color::upsample::fit_table_with(&space, &color::upsample::FitOptions::new(res), &bar, flag)?
        }
        m => return Err(format!("unknown mode {m:?} (default|unrefined|rgb2spec)").into()),
    };
    table.write(std::path::Path::new(&a[3]))?;
    Ok(())
}
