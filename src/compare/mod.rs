//! Comparing frames: the RTL frame against the golden one (must be identical) and the golden
//! frame against the f64 reference (error metrics, diff images).

use anyhow::bail;
use std::path::Path;

/// Error metrics between two images of the same size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageMetrics {
    pub pixels: usize,
    pub differing_pixels: usize,
    /// Largest absolute difference of one 8-bit channel.
    pub max_channel_error: u8,
    /// Peak signal-to-noise ratio in dB over all channels, peak 255 (imageproc's; infinite for
    /// identical images).
    pub psnr_db: f64,
    /// Structural similarity (image-compare's mean SSIM over 8x8 windows, the lowest of the
    /// three channels): 1 for identical images, lower as structure and contrast differ.
    pub ssim: f64,
}

impl ImageMetrics {
    pub fn differing_share(&self) -> f64 {
        self.differing_pixels as f64 / self.pixels.max(1) as f64
    }
    pub fn identical(&self) -> bool {
        self.differing_pixels == 0
    }
}

/// Compares two RGB images pixel by pixel.
pub fn compare_images(a: &image::RgbImage, b: &image::RgbImage) -> anyhow::Result<ImageMetrics> {
    if a.dimensions() != b.dimensions() {
        bail!(
            "the images differ in size: {}x{} and {}x{}",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        );
    }
    let mut differing = 0;
    let mut max_err = 0u8;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let mut differs = false;
        for c in 0..3 {
            let e = pa[c].abs_diff(pb[c]);
            differs |= e != 0;
            max_err = max_err.max(e);
        }
        differing += usize::from(differs);
    }
    let pixels = (a.width() * a.height()) as usize;
    let psnr_db = imageproc::stats::peak_signal_to_noise_ratio(a, b);
    let ssim =
        image_compare::rgb_similarity_structure(&image_compare::Algorithm::MSSIMSimple, a, b)
            .map_err(|e| anyhow::anyhow!("computing the SSIM: {e}"))?
            .score;
    Ok(ImageMetrics {
        pixels,
        differing_pixels: differing,
        max_channel_error: max_err,
        psnr_db,
        ssim,
    })
}

/// One frame of a simulation folder's page ([`sim_page_html`]).
#[derive(Clone, Copy, Debug)]
pub struct PageFrame {
    /// The RTL frame against the golden one.
    pub metrics: ImageMetrics,
    /// `diff<k>.png` was written (the frames differ).
    pub diff: bool,
}

/// `index.html` of a simulation folder: per frame the RTL frame (`frame<k>.png`), the golden
/// frame (`golden<k>.png`) and the diff (`diff<k>.png`, written only when they differ) side
/// by side, magnified without smoothing, with the differing pixels, PSNR and SSIM.
pub fn sim_page_html(title: &str, frames: &[PageFrame]) -> String {
    let esc = |s: &str| {
        s.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
            .replace('"', "&quot;")
    };
    let mut h = format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{0}</title>\n<style>\n\
         body {{ font-family: sans-serif; }}\n\
         figure {{ display: inline-block; margin: 0 1em 1em 0; }}\n\
         img {{ width: 320px; image-rendering: pixelated; border: 1px solid #888; }}\n\
         </style></head><body>\n<h1>{0}</h1>\n",
        esc(title)
    );
    for (k, f) in frames.iter().enumerate() {
        let m = &f.metrics;
        let verdict = if m.identical() {
            "identical to the golden model".to_string()
        } else {
            format!(
                "{} of {} pixels differ, PSNR {:.2} dB, SSIM {:.4}",
                m.differing_pixels, m.pixels, m.psnr_db, m.ssim
            )
        };
        h.push_str(&format!(
            "<h2>frame {k}: {verdict}</h2>\n\
             <figure><img src=\"frame{k}.png\" alt=\"RTL frame {k}\"><figcaption>RTL</figcaption></figure>\n\
             <figure><img src=\"golden{k}.png\" alt=\"golden frame {k}\"><figcaption>golden model</figcaption></figure>\n"
        ));
        if f.diff {
            h.push_str(&format!(
                "<figure><img src=\"diff{k}.png\" alt=\"diff of frame {k}\"><figcaption>diff (x8)</figcaption></figure>\n"
            ));
        } else {
            h.push_str("<figure><figcaption>no diff: every pixel equal</figcaption></figure>\n");
        }
    }
    h.push_str("</body></html>\n");
    h
}

/// A diff image: black where equal, the absolute difference amplified 8x (at least 64 so any
/// difference shows) where not.
pub fn diff_image(a: &image::RgbImage, b: &image::RgbImage) -> image::RgbImage {
    image::RgbImage::from_fn(a.width(), a.height(), |x, y| {
        let (pa, pb) = (a.get_pixel(x, y), b.get_pixel(x, y));
        image::Rgb([0, 1, 2].map(|c| {
            let e = pa[c].abs_diff(pb[c]);
            if e == 0 {
                0
            } else {
                (u16::from(e) * 8).clamp(64, 255) as u8
            }
        }))
    })
}

/// One row of a hits file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRow {
    pub x: u32,
    pub y: u32,
    /// `None` for a miss.
    pub hit: Option<(i64, i64, f64)>,
}

/// Reads a hits file (`x,y,instance,triangle,dist`), naming the file and line of any error.
/// Every pixel of a `width x height` frame must appear exactly once (in any order; the rows
/// come back in frame order, y then x); a miss is `-1,-1,inf` (or any negative instance), a hit
/// has a triangle index >= 0 and a finite distance >= 0.
pub fn read_hits(path: &Path) -> anyhow::Result<Vec<HitRow>> {
    let text = crate::input::read_text(path, "hits file", crate::input::MAX_TABLE_BYTES)?;
    let text = crate::input::normalize_line_endings(&text);
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim() == "x,y,instance,triangle,dist" => {}
        _ => bail!(
            "{}: line 1: expected the header `x,y,instance,triangle,dist`",
            path.display()
        ),
    }
    let mut rows = Vec::new();
    let mut line_of = std::collections::HashMap::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let bad =
            |what: &str| anyhow::anyhow!("{}: line {}: {what}: `{line}`", path.display(), i + 1);
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 5 {
            return Err(bad("expected 5 comma-separated fields"));
        }
        let x: u32 = fields[0]
            .parse()
            .map_err(|_| bad("x is not a pixel coordinate"))?;
        let y: u32 = fields[1]
            .parse()
            .map_err(|_| bad("y is not a pixel coordinate"))?;
        if x >= crate::scene::MAX_RESOLUTION || y >= crate::scene::MAX_RESOLUTION {
            return Err(bad(&format!(
                "pixel beyond the largest frame ({0}x{0})",
                crate::scene::MAX_RESOLUTION
            )));
        }
        let instance: i64 = fields[2]
            .parse()
            .map_err(|_| bad("instance is not an integer"))?;
        let triangle: i64 = fields[3]
            .parse()
            .map_err(|_| bad("triangle is not an integer"))?;
        let dist: f64 = fields[4].parse().map_err(|_| bad("dist is not a number"))?;
        let hit = if instance < 0 {
            None
        } else {
            if triangle < 0 {
                return Err(bad("a hit (instance >= 0) needs a triangle index >= 0"));
            }
            if !(dist.is_finite() && dist >= 0.0) {
                return Err(bad(
                    "a hit's dist must be a finite distance >= 0 (a miss is `-1,-1,inf`)",
                ));
            }
            Some((instance, triangle, dist))
        };
        if let Some(first) = line_of.insert((x, y), i + 1) {
            return Err(bad(&format!(
                "pixel ({x}, {y}) appears twice (first on line {first}); each pixel has one row"
            )));
        }
        rows.push(HitRow { x, y, hit });
    }
    if rows.is_empty() {
        bail!(
            "{}: no rows after the header; a hits file has one row per pixel",
            path.display()
        );
    }
    let width = rows.iter().map(|r| r.x).max().unwrap_or(0) as usize + 1;
    let height = rows.iter().map(|r| r.y).max().unwrap_or(0) as usize + 1;
    if width * height != rows.len() {
        bail!(
            "{}: {} rows, but its pixels span {width}x{height} = {}; a hits file has one row for every pixel of the frame",
            path.display(),
            rows.len(),
            width * height
        );
    }
    rows.sort_by_key(|r| (r.y, r.x));
    Ok(rows)
}

/// The share of pixels whose primary hit may differ from the f64 reference's in each format
/// before a frame is suspect: four times the mean mismatch measured for the nearest measured
/// format with no more mantissa bits (PRECISION.md, margin 64: e5m10 8.25%, e6m14 0.458%,
/// e7m16 0.089%, e7m18 0.019%, e8m23 0.014%), and at least 1% (a frame of a few thousand pixels
/// has silhouettes where any format may differ); below e5m10 nothing is measured, and 50% is
/// taken, enough to tell a format that cannot hold the scene.
pub fn expected_mismatch_bound(f: crate::fp::Format) -> f64 {
    let measured: [(u32, f64); 5] = [
        (23, 0.00014),
        (18, 0.00019),
        (16, 0.00089),
        (14, 0.00458),
        (10, 0.0825),
    ];
    match measured.iter().find(|(m, _)| f.man_bits >= *m) {
        Some((_, share)) => (4.0 * share).max(0.01),
        None => 0.5,
    }
}

/// A warning when the golden frame's primary hits differ from the f64 reference's by more than
/// the format's norm ([`expected_mismatch_bound`]): the values of the scene do not suit the
/// format (the RTL still matches the golden model, so only the reference shows it).
pub fn golden_warning(f: crate::fp::Format, hits: &HitMetrics) -> Option<String> {
    let differing = 1.0 - hits.equivalent_ratio();
    let bound = expected_mismatch_bound(f);
    (differing > bound).then(|| {
        format!(
            "the golden model's primary hits in {f} differ from the f64 reference's in {:.2}% of the pixels \
             ({} of {}), more than the {:.2}% expected of {f}: the scene's values do not suit the format \
             (try a format with more mantissa or exponent bits, e.g. --format e8m23, or smaller coordinates)",
            100.0 * differing,
            hits.pixels - hits.equivalent_hits,
            hits.pixels,
            100.0 * bound
        )
    })
}

/// Agreement of two hits files of the same frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitMetrics {
    pub pixels: usize,
    /// Pixels where both miss, or both hit the same instance and triangle.
    pub identical_hits: usize,
    /// Identical hits plus ties: different triangles hit at the same distance (within
    /// [`TIE_TOLERANCE`] relative), where the ray passes through a shared edge or vertex.
    pub equivalent_hits: usize,
    /// Mean and maximum relative distance error over pixels that hit the same triangle.
    pub mean_rel_dist_error: f64,
    pub max_rel_dist_error: f64,
}

/// Relative distance within which hits on different triangles count as the same surface point.
pub const TIE_TOLERANCE: f64 = 1e-5;

impl HitMetrics {
    pub fn identical_ratio(&self) -> f64 {
        self.identical_hits as f64 / self.pixels.max(1) as f64
    }
    pub fn equivalent_ratio(&self) -> f64 {
        self.equivalent_hits as f64 / self.pixels.max(1) as f64
    }
}

/// Compares hit lists given per pixel in the same order.
pub fn compare_hits(
    a: &[Option<(i64, i64, f64)>],
    b: &[Option<(i64, i64, f64)>],
) -> anyhow::Result<HitMetrics> {
    if a.len() != b.len() {
        bail!(
            "the hits files cover different pixel counts: {} and {}",
            a.len(),
            b.len()
        );
    }
    let (mut same, mut ties, mut n_dist, mut sum, mut max) = (0, 0, 0, 0.0, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        match (x, y) {
            (None, None) => same += 1,
            (Some((ia, ta, da)), Some((ib, tb, db))) if (ia, ta) != (ib, tb) => {
                ties += usize::from((da - db).abs() <= TIE_TOLERANCE * db.abs());
            }
            (Some((ia, ta, da)), Some((ib, tb, db))) if ia == ib && ta == tb => {
                same += 1;
                let rel = (da - db).abs() / db.abs().max(f64::MIN_POSITIVE);
                n_dist += 1;
                sum += rel;
                max = max.max(rel);
            }
            _ => {}
        }
    }
    Ok(HitMetrics {
        pixels: a.len(),
        identical_hits: same,
        equivalent_hits: same + ties,
        mean_rel_dist_error: if n_dist > 0 { sum / n_dist as f64 } else { 0.0 },
        max_rel_dist_error: max,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_known_differences() {
        let a = image::RgbImage::from_pixel(4, 2, image::Rgb([10, 20, 30]));
        let mut b = a.clone();
        b.put_pixel(1, 1, image::Rgb([10, 24, 30]));
        b.put_pixel(3, 0, image::Rgb([7, 20, 30]));
        let m = compare_images(&a, &b).unwrap();
        assert_eq!(
            (m.pixels, m.differing_pixels, m.max_channel_error),
            (8, 2, 4)
        );
        // MSE = (16 + 9) / 24 over the 24 subpixels: 47.95 dB.
        let want = 10.0 * (255.0f64.powi(2) / (25.0 / 24.0)).log10();
        assert!((m.psnr_db - want).abs() < 1e-12, "{} dB", m.psnr_db);
        assert!((m.psnr_db - 47.9535).abs() < 1e-4, "{} dB", m.psnr_db);
        assert_eq!(compare_images(&a, &a).unwrap().psnr_db, f64::INFINITY);
        let d = diff_image(&a, &b);
        assert_eq!(d.get_pixel(1, 1).0, [0, 64, 0]);
        assert_eq!(d.get_pixel(0, 0).0, [0, 0, 0]);
        let small = image::RgbImage::new(2, 2);
        assert!(compare_images(&a, &small)
            .unwrap_err()
            .to_string()
            .contains("differ in size"));
    }

    /// A seeded test image with structure: gradients and a checkerboard.
    fn pattern() -> image::RgbImage {
        image::RgbImage::from_fn(64, 48, |x, y| {
            let check = if (x / 8 + y / 8) % 2 == 0 { 60 } else { 0 };
            image::Rgb([(x * 3) as u8 + check, (y * 4) as u8 + check, 128])
        })
    }

    #[test]
    fn the_sim_page_shows_each_frame_its_golden_frame_and_a_diff_where_they_differ() {
        let a = pattern();
        let mut b = a.clone();
        b.get_pixel_mut(3, 4)[1] ^= 0x40;
        let frames = [
            PageFrame {
                metrics: compare_images(&a, &a).unwrap(),
                diff: false,
            },
            PageFrame {
                metrics: compare_images(&a, &b).unwrap(),
                diff: true,
            },
        ];
        let h = sim_page_html("a<b> in verilator", &frames);
        assert!(h.contains("<title>a&lt;b&gt; in verilator</title>"), "{h}");
        for src in [
            "frame0.png",
            "golden0.png",
            "frame1.png",
            "golden1.png",
            "diff1.png",
        ] {
            assert!(h.contains(&format!("src=\"{src}\"")), "{src}");
        }
        assert!(
            !h.contains("diff0.png"),
            "no diff image for an identical frame"
        );
        assert!(h.contains("frame 0: identical"));
        assert!(h.contains("frame 1: 1 of 3072 pixels differ"), "{h}");
        assert!(h.contains("SSIM 0.99"), "{h}");
    }

    #[test]
    fn ssim_is_one_for_identical_images_and_falls_with_distortion() {
        use rand::{Rng, SeedableRng};
        let a = pattern();
        assert_eq!(compare_images(&a, &a).unwrap().ssim, 1.0);
        // Noise of +-24 on every channel, seeded.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut noisy = a.clone();
        for p in noisy.pixels_mut() {
            for c in 0..3 {
                p[c] = (i32::from(p[c]) + rng.gen_range(-24..=24)).clamp(0, 255) as u8;
            }
        }
        let n = compare_images(&a, &noisy).unwrap();
        // A blur keeps the mean but loses the checkerboard's edges.
        let blurred = image::imageops::blur(&a, 2.0);
        let b = compare_images(&a, &blurred).unwrap();
        // One pixel off by one: almost no structure lost.
        let mut one = a.clone();
        one.get_pixel_mut(10, 10)[0] ^= 1;
        let o = compare_images(&a, &one).unwrap();
        assert!(o.ssim < 1.0 && o.ssim > 0.999, "{o:?}");
        assert!(n.ssim < 0.9 && b.ssim < 0.95, "noise {n:?}, blur {b:?}");
        assert!(n.ssim < o.ssim && b.ssim < o.ssim);
    }

    #[test]
    fn hit_agreement_counts_same_triangle_or_both_miss() {
        let a = [
            None,
            Some((0, 5, 2.0)),
            Some((1, 5, 2.0)),
            Some((0, 3, 4.0)),
        ];
        let b = [None, Some((0, 5, 2.5)), Some((0, 5, 2.0)), None];
        let m = compare_hits(&a, &b).unwrap();
        assert_eq!(m.identical_hits, 2);
        assert!((m.max_rel_dist_error - 0.2).abs() < 1e-12);
    }

    #[test]
    fn hits_file_errors_name_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.csv");
        std::fs::write(
            &p,
            "x,y,instance,triangle,dist\n0,0,1,2,3.5\n1,0,-1,-1,inf\n2,0,zz,1,1\n",
        )
        .unwrap();
        let err = read_hits(&p).unwrap_err().to_string();
        assert!(
            err.contains("h.csv") && err.contains("line 4") && err.contains("instance"),
            "{err}"
        );
        std::fs::write(
            &p,
            "x,y,instance,triangle,dist\n0,0,1,2,3.5\n1,0,-1,-1,inf\n",
        )
        .unwrap();
        let rows = read_hits(&p).unwrap();
        assert_eq!(rows[0].hit, Some((1, 2, 3.5)));
        assert_eq!(rows[1].hit, None);
    }
}
