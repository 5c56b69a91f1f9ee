//! SVG charts for the report, drawn with `plotters` (no raster fonts or system libraries).

use anyhow::{Result, anyhow};
use plotters::prelude::*;

/// Chart size in SVG pixels, and the width of the legend column on its right: the legend sits
/// beside the plot, never over bars or lines (whatever the data's shape).
const SIZE: (u32, u32) = (900, 380);
const LEGEND_W: u32 = 190;

/// How a legend entry is marked.
#[derive(Clone, Copy)]
enum Mark {
    Box,
    Line,
}

/// Draws the legend into its own column: one row per series, colour from `Palette99` in order.
fn legend(area: &DrawingArea<SVGBackend, plotters::coord::Shift>, names: &[&str], mark: Mark) -> Result<()> {
    for (i, name) in names.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        let y = 60 + 22 * i as i32;
        match mark {
            Mark::Box => area.draw(&Rectangle::new([(8, y - 6), (20, y + 6)], c.filled())),
            Mark::Line => area.draw(&PathElement::new(vec![(4, y), (24, y)], c.stroke_width(2))),
        }
        .map_err(|e| anyhow!("{e}"))?;
        area.draw(&Text::new(name.to_string(), (30, y - 7), ("sans-serif", 13)))
            .map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}

/// Grouped bar chart: one group per case, one bar per series (mean values).
pub fn bars(title: &str, y_label: &str, groups: &[String], series: &[(&str, Vec<f64>)]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let (plot, side) = root.split_horizontally(SIZE.0 - LEGEND_W);
        let ymax = series.iter().flat_map(|(_, v)| v.iter().copied()).fold(0.0, f64::max).max(1e-6) * 1.1;
        let n = series.len() as f64;
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..groups.len().max(1) as f64, 0.0..ymax)
            .map_err(|e| anyhow!("{e}"))?;
        let g = groups.to_vec();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(groups.len() * 2 + 1)
            .x_label_formatter(&|x| {
                let i = x.floor() as usize;
                if (x - x.floor() - 0.5).abs() < 0.01 && i < g.len() { g[i].clone() } else { String::new() }
            })
            .y_desc(y_label)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        for (si, (_, vals)) in series.iter().enumerate() {
            let c = Palette99::pick(si).to_rgba();
            let w = 0.8 / n;
            chart
                .draw_series(vals.iter().enumerate().map(|(gi, v)| {
                    let x0 = gi as f64 + 0.1 + si as f64 * w;
                    Rectangle::new([(x0, 0.0), (x0 + w * 0.9, *v)], c.filled())
                }))
                .map_err(|e| anyhow!("{e}"))?;
        }
        legend(&side, &series.iter().map(|s| s.0).collect::<Vec<_>>(), Mark::Box)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// Line chart on a log x axis with ticks at the data's own x values (N = 1, 2, 4, …), so the
/// axis reads as the measured configurations rather than a decade grid. Ticks closer than
/// [`MIN_TICK_GAP`] of the axis to the previous one are dropped, so a dense sweep
/// (N = 16, 18, 20, …) does not print its labels over each other.
pub fn lines(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(&str, Vec<(f64, f64)>)],
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let (plot, side) = root.split_horizontally(SIZE.0 - LEGEND_W);
        let mut xs: Vec<f64> =
            series.iter().flat_map(|(_, v)| v.iter().map(|p| p.0)).filter(|x| *x > 0.0).collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        let (xmin, xmax) = (xs.first().copied().unwrap_or(1.0), xs.last().copied().unwrap_or(1.0));
        let xs = thin_log_ticks(&xs, (xmax * 1.15 / (xmin / 1.15)).ln());
        let ymax = series.iter().flat_map(|(_, v)| v.iter().map(|p| p.1)).fold(0.0, f64::max);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .margin_right(20)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (xmin / 1.15..xmax * 1.15).log_scale().with_key_points(xs),
                0.0..ymax.max(1e-6) * 1.1,
            )
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_label_formatter(&|x| format!("{x:.0}"))
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        for (si, (_, pts)) in series.iter().enumerate() {
            let c = Palette99::pick(si).to_rgba();
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 3, c.filled())))
                .map_err(|e| anyhow!("{e}"))?;
        }
        legend(&side, &series.iter().map(|s| s.0).collect::<Vec<_>>(), Mark::Line)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// Smallest distance between two labelled ticks, as a fraction of the axis.
const MIN_TICK_GAP: f64 = 0.035;

/// Keeps the sorted `xs` that lie at least [`MIN_TICK_GAP`] of a log axis spanning `span` (in
/// natural log units) to the right of the last kept one.
fn thin_log_ticks(xs: &[f64], span: f64) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for &x in xs {
        if out.last().is_none_or(|&l| (x / l).ln() >= MIN_TICK_GAP * span) {
            out.push(x);
        }
    }
    out
}

/// A named series of points (x, y) each with a label printed beside it.
pub type LabelledSeries<'a> = (&'a str, Vec<(f64, f64, String)>);

/// Line chart on linear axes whose points carry a label (here: N beside each frame time), for
/// curves that are not functions of a shared x such as error against frame time.
pub fn labelled_lines(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[LabelledSeries],
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let (plot, side) = root.split_horizontally(SIZE.0 - LEGEND_W);
        let pts = || series.iter().flat_map(|(_, v)| v.iter());
        let xmin = pts().map(|p| p.0).fold(f64::INFINITY, f64::min);
        let xmax = pts().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
        let (xmin, xmax) = if xmin.is_finite() { (xmin, xmax) } else { (0.0, 1.0) };
        let pad = ((xmax - xmin) * 0.08).max(1e-3 * xmax.abs()).max(1e-6);
        let ymax = pts().map(|p| p.1).fold(0.0, f64::max);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .margin_right(20)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((xmin - pad).max(0.0)..xmax + pad, 0.0..ymax.max(1e-6) * 1.1)
            .map_err(|e| anyhow!("{e}"))?;
        chart.configure_mesh().x_desc(x_label).y_desc(y_label).draw().map_err(|e| anyhow!("{e}"))?;
        for (si, (_, pts)) in series.iter().enumerate() {
            let c = Palette99::pick(si).to_rgba();
            // Darker than the line: the palette's light colours (yellow) are unreadable as text.
            let (r, g, b) = Palette99::pick(si).rgb();
            let ink = RGBColor((r as f32 * 0.6) as u8, (g as f32 * 0.6) as u8, (b as f32 * 0.6) as u8);
            chart
                .draw_series(LineSeries::new(pts.iter().map(|p| (p.0, p.1)), c.stroke_width(2)))
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .draw_series(pts.iter().map(|p| {
                    EmptyElement::at((p.0, p.1))
                        + Circle::new((0, 0), 3, c.filled())
                        + Text::new(p.2.clone(), (4, -14), ("sans-serif", 11).into_font().color(&ink))
                }))
                .map_err(|e| anyhow!("{e}"))?;
        }
        legend(&side, &series.iter().map(|s| s.0).collect::<Vec<_>>(), Mark::Line)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    #[test]
    fn charts_are_svg_with_labels() {
        let b = super::bars("t", "ΔE", &["a".into(), "b".into()], &[("ours", vec![1.0, 2.0])]).unwrap();
        assert!(b.starts_with("<svg") && b.contains("ours"));
        let l = super::lines("t", "N", "ms", &[("rgb", vec![(1.0, 2.0), (4.0, 3.0)])]).unwrap();
        assert!(l.contains("<svg") && l.contains("rgb"));
        // Ticks at the data's x values only, labelled as integers.
        let texts: Vec<&str> =
            l.split("</text>").filter_map(|t| t.rsplit_once('>')).map(|(_, s)| s.trim()).collect();
        assert!(texts.contains(&"1") && texts.contains(&"4") && !texts.contains(&"3"), "{texts:?}");
    }

    #[test]
    fn dense_log_ticks_are_thinned_but_sparse_ones_kept() {
        let xs = [4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 24.0, 32.0, 48.0, 64.0, 256.0];
        let span = (256.0f64 / 4.0).ln();
        let kept = super::thin_log_ticks(&xs, span);
        assert!(kept.len() < xs.len() && kept.contains(&4.0) && kept.contains(&256.0), "{kept:?}");
        for w in kept.windows(2) {
            assert!((w[1] / w[0]).ln() >= super::MIN_TICK_GAP * span, "{kept:?}");
        }
        let pow2 = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0];
        assert_eq!(super::thin_log_ticks(&pow2, 64f64.ln()), pow2);
    }

    #[test]
    fn labelled_lines_print_their_labels() {
        let l = super::labelled_lines(
            "t",
            "ms",
            "ΔE",
            &[("ours, prefiltered", vec![(10.0, 1.5, "N=4".into()), (20.0, 1.2, "N=16".into())])],
        )
        .unwrap();
        assert!(
            l.contains("<svg") && l.contains("N=4") && l.contains("N=16") && l.contains("ours, prefiltered")
        );
    }
}
