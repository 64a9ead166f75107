//! PNG scatter plots of error against cost, with the Pareto front drawn as a line and its
//! points filled, each point labelled with its format.
//!
//! Text is drawn with plotters' `ab_glyph` backend and DejaVu Sans embedded from the `dejavu`
//! crate, not with the `ttf` backend: that one asks fontconfig for a system font and cannot draw
//! a single label on a machine without fonts (CI containers), so the plots would fail there.

use super::pareto::pareto_front;
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

pub(super) fn register_font() {
    FONT.call_once(|| {
        // The font is a valid TTF shipped in the crate; failure would be a packaging bug.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// One point: its label, cost (x) and error (y).
#[derive(Clone, Debug)]
pub struct Point {
    pub label: String,
    pub cost: f64,
    pub error: f64,
}

/// Scatter plot of `points` (x linear, y logarithmic when `log_y`) with the Pareto front
/// marked, written atomically as PNG to `path`.
pub fn scatter_with_front(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[Point],
    log_y: bool,
) -> Result<()> {
    register_font();
    let pts: Vec<&Point> = points
        .iter()
        .filter(|p| p.cost.is_finite() && p.error.is_finite())
        .collect();
    if pts.is_empty() {
        return Err(anyhow!(
            "{title}: no point with a finite cost and error to plot"
        ));
    }
    let front = pareto_front(&pts.iter().map(|p| (p.cost, p.error)).collect::<Vec<_>>());
    let (w, h) = (960u32, 640u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let xmax = pts.iter().map(|p| p.cost).fold(0.0, f64::max) * 1.1;
        let xmin = pts.iter().map(|p| p.cost).fold(f64::INFINITY, f64::min) * 0.9;
        // Log axes cannot show zero errors: those are drawn at the floor.
        let floor = pts
            .iter()
            .map(|p| p.error)
            .filter(|&e| e > 0.0)
            .fold(f64::INFINITY, f64::min)
            .min(1.0)
            / 3.0;
        let y = |e: f64| if log_y { e.max(floor) } else { e };
        let ymax = pts.iter().map(|p| y(p.error)).fold(0.0, f64::max) * 1.5;
        let ymin = if log_y { floor * 0.8 } else { 0.0 };
        let mut b = ChartBuilder::on(&root);
        b.caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(80);
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(x_label)
                    .y_desc(y_label)
                    .label_style(("sans-serif", 14))
                    .draw()
                    .map_err(|e| anyhow!("{e}"))?;
                chart
                    .draw_series(front.windows(2).map(|w| {
                        let (a, b) = (pts[w[0]], pts[w[1]]);
                        PathElement::new(
                            vec![(a.cost, y(a.error)), (b.cost, y(b.error))],
                            RED.stroke_width(2),
                        )
                    }))
                    .map_err(|e| anyhow!("{e}"))?;
                for (i, p) in pts.iter().enumerate() {
                    let on = front.contains(&i);
                    let style = if on {
                        RED.filled()
                    } else {
                        BLUE.mix(0.6).filled()
                    };
                    // Labels alternate above and below their point so neighbours overlap less.
                    let offset = if i % 2 == 0 { (6, -16) } else { (6, 4) };
                    let marker = EmptyElement::at((p.cost, y(p.error)))
                        + Circle::new((0, 0), if on { 6 } else { 4 }, style)
                        + Text::new(
                            p.label.clone(),
                            offset,
                            ("sans-serif", 13).into_font().color(&BLACK),
                        );
                    chart
                        .draw_series(std::iter::once(marker))
                        .map_err(|e| anyhow!("{e}"))?;
                }
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((xmin, ymax))
                            + Text::new(
                                "red: Pareto front".to_string(),
                                (10, 6),
                                ("sans-serif", 14).into_font().color(&RED),
                            ),
                    ))
                    .map_err(|e| anyhow!("{e}"))?;
            }};
        }
        if log_y {
            draw!(b
                .build_cartesian_2d(xmin..xmax, (ymin..ymax).log_scale())
                .map_err(|e| anyhow!("{e}"))?);
        } else {
            draw!(b
                .build_cartesian_2d(xmin..xmax, ymin..ymax)
                .map_err(|e| anyhow!("{e}"))?);
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).context("plot buffer size")?;
    crate::output::write_png(path, &img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plot_is_written_with_labels_drawn_from_the_embedded_font() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("plot.png");
        let pts: Vec<Point> = [(100.0, 0.5), (200.0, 0.01), (300.0, 0.0), (250.0, 0.2)]
            .iter()
            .enumerate()
            .map(|(i, &(c, e))| Point {
                label: format!("e7m{}", 10 + i),
                cost: c,
                error: e,
            })
            .collect();
        scatter_with_front(&p, "error vs cost", "LUTs", "mismatch", &pts, true).unwrap();
        let img = image::open(&p).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (960, 640));
        // Red front markers and black text pixels must both be present.
        let red = img
            .pixels()
            .filter(|p| p[0] > 200 && p[1] < 60 && p[2] < 60)
            .count();
        let dark = img
            .pixels()
            .filter(|p| p[0] < 60 && p[1] < 60 && p[2] < 60)
            .count();
        assert!(red > 50, "front drawn: {red} red pixels");
        assert!(dark > 200, "labels and axes drawn: {dark} dark pixels");
        // Without a font no text would be drawn: compare with the same plot with empty labels.
        let p2 = dir.path().join("nolabels.png");
        let bare: Vec<Point> = pts
            .iter()
            .map(|p| Point {
                label: String::new(),
                ..p.clone()
            })
            .collect();
        scatter_with_front(&p2, "", "", "", &bare, true).unwrap();
        let img2 = image::open(&p2).unwrap().to_rgb8();
        let dark2 = img2
            .pixels()
            .filter(|p| p[0] < 60 && p[1] < 60 && p[2] < 60)
            .count();
        assert!(
            dark > dark2 + 100,
            "text adds dark pixels: {dark} vs {dark2}"
        );
    }
}
