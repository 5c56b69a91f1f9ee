//! Experiments behind docs/upsampling.md: fits a table, prints the fit time and the round trip
//! (10⁵ colours) before and after each refinement sweep.
//! `cargo run --release -p color --example fit -- SPACE RES OUT.coeff [SWEEPS]`
//! Environment: `ZGRID` = rgb2spec (default: its double smoothstep and clamp 200) | ss1 (spectra)
//! | uniform | pow2 | pow3 | mix; `XGRID` = uniform (default, rgb2spec's chroma grid) | spectra
//! (`fit::spectra_chroma`, the default tables'); `MAXC` coefficient clamp; `RSAMP`, `RTHR` refinement samples
//! per axis and threshold, `RSTEPS` Gauss–Newton steps per node, `RGIVE` its `give_up`, `RSOLID` (set) keeps the refinement's
//! samples inside the object-colour solid however far off (`RefineOptions::keep_solid`).
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let space = color::RgbColorSpace::by_name(&a[1])?;
    let res: usize = a[2].parse()?;
    let t0 = std::time::Instant::now();
    let mut opt = color::upsample::FitOptions::new(res);
    let g = std::env::var("ZGRID").unwrap_or_default();
    let n = (res - 1) as f64;
    let ss = color::upsample::fit::smoothstep;
    match g.as_str() {
        "uniform" => opt.scale = (0..res).map(|k| k as f64 / n).collect(),
        "ss1" => opt.scale = (0..res).map(|k| ss(k as f64 / n)).collect(),
        "pow2" => opt.scale = (0..res).map(|k| (k as f64 / n).powi(2)).collect(),
        "pow3" => opt.scale = (0..res).map(|k| (k as f64 / n).powi(3)).collect(),
        "mix" => {
            opt.scale = (0..res)
                .map(|k| {
                    let t = k as f64 / n;
                    0.5 * ss(ss(t)) + 0.5 * t.powi(2)
                })
                .collect()
        }
        _ => {}
    }
    if std::env::var("XGRID").is_ok_and(|x| x == "spectra") {
        opt.chroma = color::upsample::fit::spectra_chroma(res);
    }
    if let Ok(m) = std::env::var("MAXC") {
        opt.max_coeff = m.parse()?;
    }
    let mut t = color::upsample::fit_table_with(
        &space,
        &opt,
        &indicatif::ProgressBar::hidden(),
        color::upsample::interrupt_flag(),
    )?;
    eprintln!("fit {res}^3 {}: {:.2} s", space.name, t0.elapsed().as_secs_f64());
    let r = color::upsample::roundtrip::roundtrip_table(&t, &space, 100_000, 1)?;
    println!("{}", serde_json::to_string(&r)?);
    let sweeps: usize = a.get(4).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let model = color::upsample::fit::LabModel::new(&space)?;
    for s in 0..sweeps {
        let t1 = std::time::Instant::now();
        let mut opt = color::upsample::refine::RefineOptions { sweeps: 1, ..Default::default() };
        if let Ok(v) = std::env::var("RSAMP") {
            opt.samples_per_axis = v.parse()?;
        }
        if let Ok(v) = std::env::var("RTHR") {
            opt.threshold = v.parse()?;
        }
        if let Ok(v) = std::env::var("RSTEPS") {
            opt.steps = v.parse()?;
        }
        opt.keep_solid = std::env::var_os("RSOLID").is_some();
        if let Ok(v) = std::env::var("RGIVE") {
            opt.give_up = v.parse()?;
        }
        let n = color::upsample::refine::refine_table(
            &mut t,
            &model,
            &opt,
            &indicatif::ProgressBar::hidden(),
            color::upsample::interrupt_flag(),
        )?;
        let r = color::upsample::roundtrip::roundtrip_table(&t, &space, 100_000, 1)?;
        eprintln!("sweep {s}: {n} nodes in {:.2} s", t1.elapsed().as_secs_f64());
        println!("{}", serde_json::to_string(&r)?);
    }
    t.write(std::path::Path::new(&a[3]))?;
    let r = color::upsample::roundtrip::roundtrip_table(&t, &space, 100_000, 1)?;
    println!("{}", serde_json::to_string(&r)?);
    Ok(())
}
