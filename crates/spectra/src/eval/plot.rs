//! SVG charts for the report, drawn with `plotters` (no raster fonts or system libraries).

use anyhow::{Result, anyhow};
use plotters::prelude::*;

/// Grouped bar chart: one group per case, one bar per series (mean values).
pub fn bars(title: &str, y_label: &str, groups: &[String], series: &[(&str, Vec<f64>)]) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 380)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let ymax = series.iter().flat_map(|(_, v)| v.iter().copied()).fold(0.0, f64::max).max(1e-6) * 1.15;
        let n = series.len() as f64;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..groups.len() as f64, 0.0..ymax)
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
        for (si, (name, vals)) in series.iter().enumerate() {
            let c = Palette99::pick(si).to_rgba();
            let w = 0.8 / n;
            chart
                .draw_series(vals.iter().enumerate().map(|(gi, v)| {
                    let x0 = gi as f64 + 0.1 + si as f64 * w;
                    Rectangle::new([(x0, 0.0), (x0 + w * 0.9, *v)], c.filled())
                }))
                .map_err(|e| anyhow!("{e}"))?
                .label(*name)
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 10, y + 5)], c.filled()));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// Line chart on a log₂ x axis: `series` of (x, y) points.
pub fn lines(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(&str, Vec<(f64, f64)>)],
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 380)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let pts = series.iter().flat_map(|(_, v)| v.iter().copied());
        let (xmax, ymax) = pts.fold((1.0f64, 0.0f64), |(a, b), (x, y)| (a.max(x), b.max(y)));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((1.0..xmax * 1.2).log_scale(), 0.0..ymax.max(1e-6) * 1.15)
            .map_err(|e| anyhow!("{e}"))?;
        chart.configure_mesh().x_desc(x_label).y_desc(y_label).draw().map_err(|e| anyhow!("{e}"))?;
        for (si, (name, pts)) in series.iter().enumerate() {
            let c = Palette99::pick(si).to_rgba();
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                .map_err(|e| anyhow!("{e}"))?
                .label(*name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 3, c.filled())))
                .map_err(|e| anyhow!("{e}"))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
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
    }
}
