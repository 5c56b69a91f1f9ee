//! Experiments behind docs/upsampling.md: fits a table, prints the fit time and the round trip
//! (10⁵ colours) before and after each refinement sweep.
//! `cargo run --release -p color --example fit -- SPACE RES OUT.coeff [SWEEPS]`
//! Environment: `ZGRID` = rgb2spec (default: its double smoothstep and clamp 200) | ss1 (spectra)
//! | uniform | pow2 | pow3 | mix; `XGRID` = uniform (default, rgb2spec's chroma grid) | spectra
//! (`fit::spectra_chroma`, the default tables') | pull:C:P[:C1] (node i at t − C·t(1 − t)^P + C1·t^P(1 − t),
//! t = i/(res − 1); spectra is pull:0.5:3:0.5); `MAXC` coefficient clamp; `RSAMP`, `RTHR` refinement samples
//! per axis and threshold, `RSTEPS` Gauss–Newton steps per node, `RGIVE` its `give_up`, `RSOLID` (set) keeps the refinement's
//! samples inside the object-colour solid however far off (`RefineOptions::keep_solid`), `RROBUST` σ of
//! the robust loss (`RefineOptions::robust`), `RSELF` the weight of a node's own colour
//! (`RefineOptions::own_weight`), `RCAP` its cap (`RefineOptions::own_cap`).
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
    match std::env::var("XGRID").unwrap_or_default().split(':').collect::<Vec<_>>()[..] {
        ["spectra"] => opt.chroma = color::upsample::fit::spectra_chroma(res),
        ["pull", c, p] | ["pull", c, p, _] => {
            let (c, p): (f64, i32) = (c.parse()?, p.parse()?);
            let c1: f64 = std::env::var("XGRID").unwrap().split(':').nth(3).unwrap_or("0").parse()?;
            opt.chroma = (0..res)
                .map(|i| i as f64 / n)
                .map(|t| t - c * t * (1.0 - t).powi(p) + c1 * t.powi(p) * (1.0 - t))
                .collect();
        }
        _ => {}
    }
    if let Ok(m) = std::env::var("MAXC") {
        opt.max_coeff = m.parse()?;
    }
    let mut t = color::upsample::fit_table_with(
        &space,
        &opt,
        &color::progress::Silent,
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
        if let Ok(v) = std::env::var("RCAP") {
            opt.own_cap = v.parse()?;
        }
        if let Ok(v) = std::env::var("RSELF") {
            opt.own_weight = v.parse()?;
        }
        if let Ok(v) = std::env::var("RROBUST") {
            opt.robust = v.parse()?;
        }
        if let Ok(v) = std::env::var("RGIVE") {
            opt.give_up = v.parse()?;
        }
        let n = color::upsample::refine::refine_table(
            &mut t,
            &model,
            &opt,
            &color::progress::Silent,
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
