//! The report files: `results.json` (every number), `results.csv` (one row per case × mode,
//! plus sweep, frame-time, error-vs-frame-time and jitter rows), SVG charts and `index.html`.
//! Each is written atomically.

use super::{MODES, Results, SPECTRAL_MODES};
use anyhow::{Context, Result};
use color::Quadrature;
use std::fmt::Write as _;
use std::path::Path;

fn put(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    let p = dir.join(name);
    compare::atomic::write_atomic(&p, bytes).with_context(|| format!("writing {}", p.display()))
}

/// Writes everything; `index.html` last.
pub fn write_all(dir: &Path, r: &Results) -> Result<()> {
    put(dir, "results.csv", csv(r).as_bytes())?;
    let ids: Vec<String> = r.cases.iter().map(|c| c.id.clone()).collect();
    let mean = |f: &dyn Fn(&super::ModeResult) -> f64| -> Vec<(&str, Vec<f64>)> {
        MODES
            .iter()
            .enumerate()
            .map(|(i, (_, name))| (*name, r.cases.iter().map(|c| f(&c.modes[i])).collect()))
            .collect()
    };
    let mut de = mean(&|m| m.errors.delta_e2000.mean);
    de.push(("truth noise", r.cases.iter().map(|c| c.noise_floor.delta_e2000.mean).collect()));
    put(
        dir,
        "delta_e.svg",
        super::plot::bars("Mean ΔE2000 against ground truth (lower is better)", "mean ΔE2000", &ids, &de)?
            .as_bytes(),
    )?;
    // Masked numbers only for cases that have a mask: a volumetric case's "masked" bars would
    // repeat its whole-image bars under a title that says otherwise.
    let masked: Vec<&super::CaseResult> = r.cases.iter().filter(|c| has_mask(c)).collect();
    let mut dem: Vec<(&str, Vec<f64>)> = MODES
        .iter()
        .enumerate()
        .map(|(i, (_, name))| {
            (*name, masked.iter().map(|c| c.modes[i].errors.delta_e2000_masked.mean).collect())
        })
        .collect();
    dem.push(("truth noise", masked.iter().map(|c| c.noise_floor.delta_e2000_masked.mean).collect()));
    let masked_ids: Vec<String> = masked.iter().map(|c| c.id.clone()).collect();
    if !masked.is_empty() {
        put(
            dir,
            "delta_e_masked.svg",
            super::plot::bars(
                "Mean ΔE2000 outside the edge mask (cases with direct-lighting truth)",
                "mean ΔE2000",
                &masked_ids,
                &dem,
            )?
            .as_bytes(),
        )?;
    }
    let mae = mean(&|m| m.errors.mae_linear.mean);
    put(
        dir,
        "mae.svg",
        super::plot::bars("Mean absolute error, linear sRGB", "MAE", &ids, &mae)?.as_bytes(),
    )?;
    let rgb = r.frame_times.iter().find(|f| f.mode == "rgb").map(|f| f.median_ms).unwrap_or(0.0);
    let nmax = r.frame_times.iter().filter_map(|f| f.wavelengths).max().unwrap_or(1) as f64;
    let names = series_names();
    let mut ft_series: Vec<(&str, Vec<(f64, f64)>)> = names
        .iter()
        .map(|(mode, q, label)| {
            let pts = r
                .frame_times
                .iter()
                .filter(|f| f.mode == *mode && f.quadrature.as_deref() == Some(q.name()))
                .map(|f| (f.wavelengths.unwrap_or(1) as f64, f.median_ms))
                .collect();
            (label.as_str(), pts)
        })
        .collect();
    ft_series.push(("rgb (independent of N)", vec![(1.0, rgb), (nmax, rgb)]));
    put(
        dir,
        "frame_time.svg",
        super::plot::lines(
            "Frame time against N (median, CPU wall time incl. read-back)",
            "wavelengths N",
            "ms per frame",
            &ft_series,
        )?
        .as_bytes(),
    )?;
    for c in &r.cases {
        put(dir, &sweep_svg_name(&c.id), sweep_chart(c)?.as_bytes())?;
    }
    if let Some(c) = r.cases.first() {
        put(dir, TRADEOFF_SVG, tradeoff_chart(r, c)?.as_bytes())?;
    }
    let js: Vec<(&str, Vec<(f64, f64)>)> = vec![
        (
            "equal spacing, one frame",
            r.jitter.iter().map(|j| (j.total_wavelengths as f64, j.equal_spacing_delta_e)).collect(),
        ),
        (
            "jittered, accumulated",
            r.jitter.iter().map(|j| (j.total_wavelengths as f64, j.jittered_delta_e)).collect(),
        ),
    ];
    put(
        dir,
        "jitter.svg",
        super::plot::lines(
            "Error against total wavelengths: equal spacing vs jittered accumulation",
            "total wavelengths per pixel",
            "mean ΔE2000",
            &js,
        )?
        .as_bytes(),
    )?;
    put(dir, "results.json", serde_json::to_string_pretty(r)?.as_bytes())?;
    put(dir, "index.html", html(r).as_bytes())?;
    Ok(())
}

/// The sweep's series in report order: (mode, quadrature, "ours, midpoint").
fn series_names() -> Vec<(&'static str, Quadrature, String)> {
    SPECTRAL_MODES
        .iter()
        .flat_map(|(_, m)| Quadrature::ALL.iter().map(move |q| (*m, *q, format!("{m}, {}", q.name()))))
        .collect()
}

/// File name of a case's ΔE-vs-N chart.
pub fn sweep_svg_name(id: &str) -> String {
    format!("sweep_{id}.svg")
}

/// File name of the error-vs-frame-time chart.
pub const TRADEOFF_SVG: &str = "error_vs_frame_time.svg";

/// The N values a case's sweep measured, ascending.
fn sweep_counts(c: &super::CaseResult) -> Vec<usize> {
    let mut ns: Vec<usize> = c.sweep.iter().map(|p| p.wavelengths).collect();
    ns.sort_unstable();
    ns.dedup();
    ns
}

fn rgb_mean(c: &super::CaseResult) -> Option<f64> {
    c.modes.iter().find(|m| m.mode == "rgb").map(|m| m.errors.delta_e2000.mean)
}

/// Mean ΔE2000 against N for one case: one line per mode × quadrature, rgb (which has no N) as
/// a horizontal line across the swept N.
fn sweep_chart(c: &super::CaseResult) -> Result<String> {
    let ns = sweep_counts(c);
    let names = series_names();
    let mut series: Vec<(&str, Vec<(f64, f64)>)> = names
        .iter()
        .map(|(mode, q, label)| {
            let pts = ns
                .iter()
                .filter_map(|&n| c.sweep_point(mode, q.name(), n).map(|p| (n as f64, p.delta_e2000_mean)))
                .collect();
            (label.as_str(), pts)
        })
        .collect();
    let (lo, hi) = (ns.first().copied().unwrap_or(1) as f64, ns.last().copied().unwrap_or(1) as f64);
    if let Some(rgb) = rgb_mean(c) {
        series.push(("rgb (no N)", vec![(lo, rgb), (hi, rgb)]));
    }
    super::plot::lines(
        &format!("{}: mean ΔE2000 against N (truth noise {:.3})", c.id, c.noise_floor.delta_e2000.mean),
        "wavelengths N (log scale)",
        "mean ΔE2000",
        &series,
    )
}

/// Mean ΔE2000 of the frame-time case against median frame time: the curve N is chosen from.
fn tradeoff_chart(r: &Results, c: &super::CaseResult) -> Result<String> {
    let names = series_names();
    let mut series: Vec<super::plot::LabelledSeries> = names
        .iter()
        .map(|(mode, q, label)| {
            let pts = r
                .tradeoff
                .iter()
                .filter(|p| p.mode == *mode && p.quadrature.as_deref() == Some(q.name()))
                .map(|p| (p.median_ms, p.delta_e2000_mean, format!("{}", p.wavelengths.unwrap_or(0))))
                .collect();
            (label.as_str(), pts)
        })
        .collect();
    if let Some(p) = r.tradeoff.iter().find(|p| p.mode == "rgb") {
        series.push(("rgb", vec![(p.median_ms, p.delta_e2000_mean, "rgb".into())]));
    }
    super::plot::labelled_lines(
        &format!("{}: mean ΔE2000 against frame time (labels: N)", c.id),
        &format!("median ms per frame at {}×{}", r.budget.bench_width, r.budget.bench_height),
        &format!("mean ΔE2000 at {}×{}", c.width, c.height),
        &series,
    )
}

/// The first line of results.csv (also how an earlier evaluation's file is told from others).
pub const CSV_HEADER: &str = "case,transport,width,height,truth_spp,mode,wavelengths,quadrature,de_mean,de_median,de_p95,de_max,mae_mean,de_mean_masked,mae_mean_masked,masked_fraction\n";

/// index.html's title element (also how an earlier evaluation's page is told from others).
pub const HTML_TITLE: &str = "<title>spectra evaluation</title>";

/// Every number as CSV sections separated by a blank line.
pub fn csv(r: &Results) -> String {
    let mut s = String::from(CSV_HEADER);
    for c in &r.cases {
        let rows =
            c.modes.iter().map(|m| (m.mode.as_str(), m.wavelengths, m.quadrature.as_deref(), &m.errors));
        for (mode, n, q, e) in rows.chain(std::iter::once(("truth_noise", None, None, &c.noise_floor))) {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                c.id,
                c.transport,
                c.width,
                c.height,
                c.truth_spp,
                mode,
                n.map(|n| n.to_string()).unwrap_or_default(),
                q.unwrap_or_default(),
                e.delta_e2000.mean,
                e.delta_e2000.median,
                e.delta_e2000.p95,
                e.delta_e2000.max,
                e.mae_linear.mean,
                e.delta_e2000_masked.mean,
                e.mae_linear_masked.mean,
                c.masked_fraction
            );
        }
    }
    s.push_str("\nsweep_case,mode,quadrature,wavelengths,de_mean,de_mean_masked,mae_mean\n");
    for c in &r.cases {
        for p in &c.sweep {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{}",
                c.id,
                p.mode,
                p.quadrature,
                p.wavelengths,
                p.delta_e2000_mean,
                p.delta_e2000_masked_mean,
                p.mae_linear_mean
            );
        }
    }
    s.push_str("\nframe_time_mode,wavelengths,quadrature,median_ms\n");
    for f in &r.frame_times {
        let _ = writeln!(
            s,
            "{},{},{},{}",
            f.mode,
            f.wavelengths.map(|n| n.to_string()).unwrap_or_default(),
            f.quadrature.as_deref().unwrap_or_default(),
            f.median_ms
        );
    }
    s.push_str("\ntradeoff_mode,wavelengths,quadrature,median_ms,de_mean\n");
    for p in &r.tradeoff {
        let _ = writeln!(
            s,
            "{},{},{},{},{}",
            p.mode,
            p.wavelengths.map(|n| n.to_string()).unwrap_or_default(),
            p.quadrature.as_deref().unwrap_or_default(),
            p.median_ms,
            p.delta_e2000_mean
        );
    }
    s.push_str("\njitter_total_wavelengths,frames,equal_spacing_de_mean,jittered_de_mean\n");
    for j in &r.jitter {
        let _ = writeln!(
            s,
            "{},{},{},{}",
            j.total_wavelengths, j.frames, j.equal_spacing_delta_e, j.jittered_delta_e
        );
    }
    s
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The headline table (mean ΔE2000, whole image / masked) as Markdown, for the README.
pub fn markdown_table(r: &Results) -> String {
    let mut s = String::from(
        "| case | N, quadrature (ours, naive) | ours ΔE00 | naive ΔE00 | rgb ΔE00 | truth noise ΔE00 | ours / naive / rgb, edge-masked |\n|---|---|---|---|---|---|---|\n",
    );
    for c in &r.cases {
        let m = |i: usize| c.modes[i].errors.delta_e2000.mean;
        let k = |i: usize| c.modes[i].errors.delta_e2000_masked.mean;
        let masked = if has_mask(c) {
            format!("{:.3} / {:.3} / {:.3}", k(0), k(1), k(2))
        } else {
            "– (volumetric truth, no mask)".into()
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {masked} |",
            c.id,
            headline_config(c),
            m(0),
            m(1),
            m(2),
            c.noise_floor.delta_e2000.mean,
        );
    }
    s
}

/// The sweep of every case as Markdown: one table per case, N in columns, mean ΔE2000.
pub fn markdown_sweep(r: &Results) -> String {
    let mut s = String::new();
    for c in &r.cases {
        let ns = sweep_counts(c);
        let _ = write!(
            s,
            "\n{} (mean ΔE2000; rgb {}, truth noise {:.3})\n\n| mode, quadrature |",
            c.id,
            rgb_mean(c).map(|v| format!("{v:.3}")).unwrap_or("–".into()),
            c.noise_floor.delta_e2000.mean
        );
        for n in &ns {
            let _ = write!(s, " N={n} |");
        }
        s.push_str("\n|---|");
        s.push_str(&"---|".repeat(ns.len()));
        s.push('\n');
        for (mode, q, label) in series_names() {
            let _ = write!(s, "| {label} |");
            for &n in &ns {
                match c.sweep_point(mode, q.name(), n) {
                    Some(p) => {
                        let _ = write!(s, " {:.3} |", p.delta_e2000_mean);
                    }
                    None => s.push_str(" – |"),
                }
            }
            s.push('\n');
        }
    }
    s
}

/// "N = 16, prefiltered": what the headline's spectral modes ran with in a case.
fn headline_config(c: &super::CaseResult) -> String {
    c.modes
        .iter()
        .find(|m| m.wavelengths.is_some())
        .map(|m| format!("N = {}, {}", m.wavelengths.unwrap_or(0), m.quadrature.as_deref().unwrap_or("?")))
        .unwrap_or_else(|| "–".into())
}

/// Whether the case's masked numbers mean anything (volumetric truths get no edge mask).
fn has_mask(c: &super::CaseResult) -> bool {
    c.transport != "volumetric"
}

/// "W×H, S spp" of the cases with the given transport, if any (sizes differ per kind of case).
fn budget_of(r: &Results, transport: &str) -> Option<String> {
    let c = r.cases.iter().find(|c| c.transport == transport)?;
    Some(format!("{} spp, {}×{}", c.truth_spp, c.width, c.height))
}

/// A case's sweep: a table (rows mode × quadrature, columns N) and its ΔE-vs-N chart.
fn sweep_html(h: &mut String, c: &super::CaseResult) {
    let ns = sweep_counts(c);
    if ns.is_empty() {
        return;
    }
    let noise = c.noise_floor.delta_e2000.mean;
    let rgb = rgb_mean(c);
    let _ = write!(
        h,
        "<h3>{id}: mean ΔE2000 against N, both quadratures</h3><p>Same truth as above. Green: below rgb \
         ({rgb}) by more than the truth noise ({noise:.3}). Masked means and MAE per point are in results.json \
         and results.csv.</p><table><tr><th>mode, quadrature</th>",
        id = esc(&c.id),
        rgb = rgb.map(|v| format!("{v:.3}")).unwrap_or("–".into()),
    );
    for n in &ns {
        let _ = write!(h, "<th>N={n}</th>");
    }
    h.push_str("</tr>");
    for (mode, q, label) in series_names() {
        let _ = write!(h, "<tr><td>{}</td>", esc(&label));
        for &n in &ns {
            match c.sweep_point(mode, q.name(), n) {
                Some(p) => {
                    let beats = rgb.is_some_and(|g| p.delta_e2000_mean + noise < g);
                    let cls = if beats { " class=\"best\"" } else { "" };
                    let _ = write!(h, "<td{cls}>{:.3}</td>", p.delta_e2000_mean);
                }
                None => h.push_str("<td>–</td>"),
            }
        }
        h.push_str("</tr>");
    }
    let span = ns.len();
    if let Some(g) = rgb {
        let _ = write!(h, "<tr><td>rgb (no N)</td><td colspan=\"{span}\">{g:.3}</td></tr>");
    }
    let _ = write!(h, "<tr><td>truth noise</td><td colspan=\"{span}\">{noise:.3}</td></tr></table>");
    let _ = write!(h, "<img src=\"{}\" alt=\"mean ΔE2000 against N\">", esc(&sweep_svg_name(&c.id)));
}

/// The error-vs-frame-time section: chart and table.
fn tradeoff_html(h: &mut String, r: &Results) {
    let Some(c) = r.cases.first() else { return };
    let _ = write!(
        h,
        "<h2>Error against frame time: choosing N</h2><p>Case {id}: median frame time at {bw}×{bh} (table above) \
         beside mean ΔE2000 against truth at {w}×{h} (the sweep), for every N that was both timed and swept. \
         A configuration is worth using only if no other one is both faster and closer to truth.</p>\
         <img src=\"{svg}\" alt=\"mean ΔE2000 against frame time\"><table><tr><th>mode</th><th>quadrature</th>\
         <th>N</th><th>median ms</th><th>mean ΔE00</th></tr>",
        id = esc(&c.id),
        bw = r.budget.bench_width,
        bh = r.budget.bench_height,
        w = c.width,
        h = c.height,
        svg = TRADEOFF_SVG,
    );
    for p in &r.tradeoff {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.3}</td></tr>",
            esc(&p.mode),
            p.quadrature.as_deref().unwrap_or("–"),
            p.wavelengths.map(|n| n.to_string()).unwrap_or("–".into()),
            p.median_ms,
            p.delta_e2000_mean
        );
    }
    h.push_str("</table>");
}

fn html(r: &Results) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        r#"<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">{HTML_TITLE}
<style>body{{font-family:sans-serif;margin:20px;max-width:1360px}}table{{border-collapse:collapse;margin:8px 0}}
td,th{{border:1px solid #bbb;padding:3px 8px;text-align:right}}th{{background:#eee}}td:first-child{{text-align:left}}
.row{{display:flex;gap:8px;flex-wrap:wrap}}figure{{margin:0}}figcaption{{font-size:13px;text-align:center}}
img.px{{image-rendering:pixelated;width:256px}}img.hm{{height:256px}}.best{{font-weight:bold;color:#060}}</style></head><body>
<h1>spectra evaluation{q}</h1>
<p>Ground truth: the CPU spectral path tracer{direct}{vol}. <b>ours</b> = Jakob–Hanika spectral upsampling, <b>naive</b> = box upsampling, <b>rgb</b> = classic RGB
shading. Errors are per-pixel CIEDE2000 (CIELAB white Y = 1) and MAE of linear sRGB. The <i>truth noise</i> row is two
truth renders with different seeds: differences below it are Monte-Carlo noise. The edge mask removes pixels whose 3×3
neighbourhood in the truth image varies in luminance by more than {ec:.0}% (shadow and silhouette edges where shadow maps and
ray tracing differ geometrically, but also texture edges); both whole-image and masked numbers are shown.</p>
<p><b>Machine:</b> {m}<br><b>Adapter:</b> {a}<br><b>Run time:</b> {t:.0} s</p>
"#,
        q = if r.quick { " (--quick)" } else { "" },
        direct = budget_of(r, "direct")
            .map(|b| format!(
                "; ordinary cases: direct lighting only, {b}, with the same punctual lights as the real-time renderer"
            ))
            .unwrap_or_default(),
        vol = budget_of(r, "volumetric")
            .map(|b| format!(
                "; underwater cases: full volumetric path tracing of the water, {b}, no edge mask (see the note)"
            ))
            .unwrap_or_default(),
        ec = r.edge_contrast * 100.0,
        m = esc(&r.machine),
        a = esc(&r.adapter),
        t = r.seconds
    );
    for n in &r.notes {
        let _ = write!(h, "<p><b>Note:</b> {}</p>", esc(n));
    }
    h.push_str(
        "<h2>Mean errors</h2><p>ours and naive at each case's N with the renderer's default quadrature (column \
         “N, quadrature”); every N in both quadratures is in the sweep under each case. Green: the lowest \
         mean ΔE00, below every other mode's by more than the truth noise.</p>\
         <table><tr><th>case</th><th>N, quadrature</th>",
    );
    for (_, n) in MODES {
        let _ = write!(h, "<th>{n} ΔE00</th>");
    }
    h.push_str("<th>truth noise ΔE00</th>");
    for (_, n) in MODES {
        let _ = write!(h, "<th>{n} ΔE00 masked</th>");
    }
    h.push_str("<th>masked px</th>");
    for (_, n) in MODES {
        let _ = write!(h, "<th>{n} MAE</th>");
    }
    h.push_str("</tr>");
    for c in &r.cases {
        // A lead smaller than the truth's own noise is no lead (as in the sweep's tables).
        let noise = c.noise_floor.delta_e2000.mean;
        let mean = |i: usize| c.modes[i].errors.delta_e2000.mean;
        let best =
            (0..c.modes.len()).find(|&i| (0..c.modes.len()).all(|j| j == i || mean(i) + noise < mean(j)));
        let _ = write!(h, "<tr><td>{}</td><td>{}</td>", esc(&c.id), esc(&headline_config(c)));
        for (i, m) in c.modes.iter().enumerate() {
            let cls = if Some(i) == best { " class=\"best\"" } else { "" };
            let _ = write!(h, "<td{cls}>{:.3}</td>", m.errors.delta_e2000.mean);
        }
        let _ = write!(h, "<td>{:.3}</td>", c.noise_floor.delta_e2000.mean);
        for m in &c.modes {
            if has_mask(c) {
                let _ = write!(h, "<td>{:.3}</td>", m.errors.delta_e2000_masked.mean);
            } else {
                h.push_str("<td>–</td>");
            }
        }
        if has_mask(c) {
            let _ = write!(h, "<td>{:.1}%</td>", c.masked_fraction * 100.0);
        } else {
            h.push_str("<td>no mask</td>");
        }
        for m in &c.modes {
            let _ = write!(h, "<td>{:.4}</td>", m.errors.mae_linear.mean);
        }
        h.push_str("</tr>");
    }
    h.push_str("</table>");
    h.push_str(r#"<p><img src="delta_e.svg" alt="mean ΔE2000 bar chart"><br>"#);
    if r.cases.iter().any(has_mask) {
        h.push_str(r#"<img src="delta_e_masked.svg" alt="masked ΔE2000 bar chart"><br>"#);
    }
    h.push_str(r#"<img src="mae.svg" alt="MAE bar chart"></p>"#);
    for c in &r.cases {
        let _ = write!(
            h,
            "<h2>{}</h2><p>{} — {}×{}, truth {} spp ({}), truth noise ΔE00 {:.3}</p><div class=\"row\">",
            esc(&c.id),
            esc(&c.title),
            c.width,
            c.height,
            c.truth_spp,
            if has_mask(c) { "direct lighting" } else { "volumetric" },
            c.noise_floor.delta_e2000.mean
        );
        let _ = write!(
            h,
            "<figure><img class=\"px\" src=\"{}\"><figcaption>ground truth</figcaption></figure>",
            esc(&c.truth_image)
        );
        for m in &c.modes {
            let _ = write!(
                h,
                "<figure><img class=\"px\" src=\"{}\"><figcaption>{}{}{} — ΔE00 {:.3}</figcaption></figure>",
                esc(&m.image),
                esc(&m.mode),
                m.wavelengths.map(|n| format!(" N={n}")).unwrap_or_default(),
                m.quadrature.as_deref().map(|q| format!(", {}", esc(q))).unwrap_or_default(),
                m.errors.delta_e2000.mean
            );
        }
        h.push_str("</div><div class=\"row\">");
        for m in &c.modes {
            let _ = write!(
                h,
                "<figure><img class=\"hm\" src=\"{}\"><figcaption>{} ΔE2000 heat map</figcaption></figure>",
                esc(&m.heatmap),
                esc(&m.mode)
            );
        }
        h.push_str("</div><div class=\"row\">");
        for m in &c.modes {
            let _ = write!(
                h,
                "<figure><img class=\"px\" src=\"{}\"><figcaption>{} LDR-FLIP map (magma, 0–1) — mean LDR-FLIP {:.4}, HDR-FLIP {:.4}</figcaption></figure>",
                esc(&m.flip_map),
                esc(&m.mode),
                m.flip_mean,
                m.flip_hdr_mean
            );
        }
        h.push_str("</div>");
        sweep_html(&mut h, c);
    }
    let _ = write!(
        h,
        r#"<h2>Frame time against N (paper Fig. 4)</h2><p>Scene {}, {}×{}, median of {} frames, CPU wall time from submission to finished read-back.</p><img src="frame_time.svg" alt="frame time plot"><table><tr><th>mode</th><th>quadrature</th><th>N</th><th>median ms</th></tr>"#,
        esc(&r.frame_time_scene),
        r.budget.bench_width,
        r.budget.bench_height,
        r.budget.bench_frames
    );
    for f in &r.frame_times {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td></tr>",
            f.mode,
            f.quadrature.as_deref().unwrap_or("–"),
            f.wavelengths.map(|n| n.to_string()).unwrap_or("–".into()),
            f.median_ms
        );
    }
    h.push_str("</table>");
    tradeoff_html(&mut h, r);
    let _ = write!(
        h,
        r#"<h2>Beyond the paper: jittered wavelengths with temporal accumulation</h2><p>Scene {}, range {:.0}–{:.0} nm (truth over the same range), ours with the {} quadrature. Equal spacing renders all N wavelengths in one frame; jittered renders {} per frame at a stratified random offset and averages the frames (each frame normalised by dense integrals, so the mean is unbiased). The viewer does the same live: <code>spectra view</code>, key J / “accumulate (jittered λ)”.</p><img src="jitter.svg" alt="jitter plot"><table><tr><th>total N</th><th>frames</th><th>equal spacing ΔE00</th><th>jittered ΔE00</th></tr>"#,
        esc(&r.jitter_scene),
        r.jitter_range[0],
        r.jitter_range[1],
        esc(&r.jitter_quadrature),
        r.budget.jitter_per_frame
    );
    for j in &r.jitter {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td></tr>",
            j.total_wavelengths, j.frames, j.equal_spacing_delta_e, j.jittered_delta_e
        );
    }
    h.push_str("</table><p>All numbers: <a href=\"results.json\">results.json</a>, <a href=\"results.csv\">results.csv</a>.</p></body></html>\n");
    h
}
