//! Renderers: the golden model (the hardware's algorithm in `eXmY`, bit-exact with the RTL)
//! and the f64 reference (the accuracy yardstick), and the frame they both produce.

pub mod golden;
pub mod reference;
/// The shared arithmetic sequences (they live beside the golden model and the hardware, see
/// [`crate::units`]).
pub use crate::units;

use crate::layout::Layout;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::Path;

pub use golden::{Golden, RayResult, RayStats};
pub use reference::Reference;

/// The primary hit of a pixel as the hits file reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    pub instance: u32,
    /// Index in the object's triangle list after loading.
    pub triangle: u32,
    /// World-space distance from the eye.
    pub dist: f64,
}

/// A rendered frame: `0x00RRGGBB` per pixel, row 0 at the top, plus primary hits.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u32>,
    pub hits: Vec<Option<HitRecord>>,
    pub stats: RayStats,
}

impl Frame {
    pub(crate) fn from_pixels(
        width: u32,
        height: u32,
        pixels: Vec<(u32, Option<HitRecord>)>,
    ) -> Frame {
        let (rgb, hits) = pixels.into_iter().unzip();
        Frame {
            width,
            height,
            rgb,
            hits,
            stats: RayStats::default(),
        }
    }

    /// Hits as `(instance, triangle, dist)` per pixel, the form `compare` works on.
    pub fn hit_tuples(&self) -> Vec<Option<(i64, i64, f64)>> {
        self.hits
            .iter()
            .map(|h| h.map(|h| (i64::from(h.instance), i64::from(h.triangle), h.dist)))
            .collect()
    }

    pub fn to_image(&self) -> image::RgbImage {
        image::RgbImage::from_fn(self.width, self.height, |x, y| {
            let c = self.rgb[(y * self.width + x) as usize];
            image::Rgb([(c >> 16) as u8, (c >> 8) as u8, c as u8])
        })
    }

    /// Writes the frame as PNG; the file appears complete or not at all.
    pub fn save_png(&self, path: &Path) -> anyhow::Result<()> {
        crate::output::write_png(path, &self.to_image())
    }

    /// The hits file (docs/ARCHITECTURE.md, "Hits files"): `x,y,instance,triangle,dist`.
    pub fn hits_text(&self) -> Vec<u8> {
        let rows: Vec<Vec<String>> = self
            .hits
            .iter()
            .enumerate()
            .map(|(i, h)| {
                let (x, y) = (i as u32 % self.width, i as u32 / self.width);
                let (instance, triangle, dist) = match h {
                    Some(h) => (
                        h.instance.to_string(),
                        h.triangle.to_string(),
                        h.dist.to_string(),
                    ),
                    None => ("-1".into(), "-1".into(), "inf".into()),
                };
                vec![x.to_string(), y.to_string(), instance, triangle, dist]
            })
            .collect();
        crate::tables::csv_text(&["x", "y", "instance", "triangle", "dist"], &rows).into_bytes()
    }

    /// Writes the hits file ([`Frame::hits_text`]) atomically.
    pub fn save_hits(&self, path: &Path) -> anyhow::Result<()> {
        crate::output::write_atomically(path, &self.hits_text())
            .with_context(|| format!("writing {}", path.display()))
    }
}

/// A progress bar over `rows` rows, hidden unless `show`.
pub(crate) fn progress_bar(show: bool, rows: u32, what: &str) -> ProgressBar {
    let bar = if show {
        ProgressBar::new(u64::from(rows))
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{what} {{bar:40}} {{pos}}/{{len}} rows {{elapsed}}"
        ))
        .expect("valid template"),
    );
    bar
}

/// Renders a frame with the golden model, in parallel, with a progress bar when `progress`.
pub fn render_golden(layout: &Layout, progress: bool) -> Frame {
    render_with(&Golden::new(layout), progress)
}

/// Renders a frame with a configured golden model (see [`Golden::with_edge_margin`]).
pub fn render_with(golden: &Golden, progress: bool) -> Frame {
    let layout = golden.layout();
    let (w, h) = (layout.info.width, layout.info.height);
    let f = layout.format;
    let bar = if progress {
        ProgressBar::new(u64::from(h))
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("golden {bar:40} {pos}/{len} rows {elapsed}")
            .expect("valid template"),
    );
    let rows: Vec<Vec<golden::Pixel>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let row = (0..w).map(|x| golden.pixel(x, y)).collect();
            bar.inc(1);
            row
        })
        .collect();
    bar.finish_and_clear();
    let mut stats = RayStats::default();
    let pixels = rows
        .into_iter()
        .flatten()
        .map(|p| {
            stats += p.stats;
            let rec = p.hit.map(|hit| {
                let object = layout.word(
                    crate::layout::INSTANCES,
                    hit.instance * crate::layout::INSTANCE_WORDS as u32
                        + crate::layout::instance_word::OBJECT as u32,
                );
                let object = if layout.info.top_root.is_some() {
                    object as usize
                } else {
                    0
                };
                let len = p
                    .dir
                    .iter()
                    .map(|&c| f.to_f64(c).powi(2))
                    .sum::<f64>()
                    .sqrt();
                HitRecord {
                    instance: hit.instance,
                    triangle: hit.triangle - layout.info.object_first_triangle[object],
                    dist: f.to_f64(hit.t) * len,
                }
            });
            (p.rgb, rec)
        })
        .collect();
    let mut frame = Frame::from_pixels(w, h, pixels);
    frame.stats = stats;
    frame
}
