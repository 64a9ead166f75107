//! `dynrt compare`: error metrics between two images (and their hits files). Like
//! OpenImageIO's `idiff`, it exits with status 1 when a difference passes a threshold given
//! with `--fail-psnr` or `--fail-pixels` (docs/ARCHITECTURE.md, "Command line"); without a
//! threshold it only reports.

use anyhow::Context;
use clap::Args;
use dynrt::compare;
use std::path::PathBuf;

#[derive(Args)]
#[command(
    after_help = "Examples:\n  dynrt compare out/sim/frame0.png out/sim/golden0.png --fail-pixels 0\n  \
dynrt compare golden.png reference.png --fail-psnr 40 --out out/diff --json\n\n\
Exit status: 0 within the thresholds (or none given), 1 a threshold failed, 2 bad input."
)]
pub struct CompareArgs {
    /// First image (PNG).
    pub a: PathBuf,
    /// Second image (PNG), of the same size.
    pub b: PathBuf,
    /// Output folder (created if missing) for diff.png, the amplified absolute difference;
    /// without it nothing is written.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The diff image as a file of its own (the older form of --out).
    #[arg(long, value_name = "FILE", hide = true, conflicts_with = "out")]
    pub diff: Option<PathBuf>,
    /// Hits files of A and B: adds the identical-hit ratio and distance errors.
    #[arg(long, num_args = 2, value_names = ["HITS_A", "HITS_B"])]
    pub hits: Option<Vec<PathBuf>>,
    /// Exit with status 1 when the PSNR is below DB (identical images have an infinite PSNR).
    #[arg(long, value_name = "DB")]
    pub fail_psnr: Option<f64>,
    /// Exit with status 1 when more than N pixels differ (0: any differing pixel fails).
    #[arg(long, value_name = "N")]
    pub fail_pixels: Option<usize>,
    /// Print the metrics as one JSON object on stdout instead of the text table.
    #[arg(long)]
    pub json: bool,
}

/// The thresholds of `a` that `m` fails, each as a sentence.
fn failed_thresholds(a: &CompareArgs, m: &compare::ImageMetrics) -> Vec<String> {
    let mut failed = Vec::new();
    if let Some(db) = a.fail_psnr {
        if m.psnr_db < db {
            failed.push(format!(
                "PSNR {:.2} dB is below --fail-psnr {db}",
                m.psnr_db
            ));
        }
    }
    if let Some(n) = a.fail_pixels {
        if m.differing_pixels > n {
            failed.push(format!(
                "{} pixels differ, more than --fail-pixels {n}",
                m.differing_pixels
            ));
        }
    }
    failed
}

fn open(p: &std::path::Path) -> anyhow::Result<image::RgbImage> {
    let bytes = dynrt::input::read_bytes(p, "image", dynrt::input::MAX_IMAGE_BYTES)?;
    Ok(image::load_from_memory(&bytes)
        .with_context(|| format!("image '{}' cannot be decoded (PNG expected)", p.display()))?
        .to_rgb8())
}

pub fn run(a: CompareArgs) -> anyhow::Result<i32> {
    if let Some(db) = a.fail_psnr {
        anyhow::ensure!(
            !db.is_nan(),
            "--fail-psnr {db}: give a PSNR in dB, e.g. --fail-psnr 40"
        );
    }
    let diff = match (&a.out, &a.diff) {
        (Some(dir), _) => {
            dynrt::output::check_output_dir(dir, "--out")?;
            Some(("--out", dir.join("diff.png")))
        }
        (None, Some(file)) => {
            dynrt::output::check_output_file(file, "--diff")?;
            Some(("--diff", file.clone()))
        }
        (None, None) => None,
    };
    if let Some((flag, d)) = &diff {
        let mut inputs: Vec<(&str, &std::path::Path)> = vec![("image A", &a.a), ("image B", &a.b)];
        if let Some(h) = &a.hits {
            inputs.extend([("HITS_A", h[0].as_path()), ("HITS_B", h[1].as_path())]);
        }
        dynrt::output::check_distinct(&[(flag, d)], &inputs)?;
    }
    // Every input is read and checked before anything is computed or written.
    let hits = match &a.hits {
        Some(h) => {
            let ra = compare::read_hits(&h[0])?;
            let rb = compare::read_hits(&h[1])?;
            let size = |r: &[compare::HitRow]| r.last().map_or((0, 0), |l| (l.x + 1, l.y + 1));
            if size(&ra) != size(&rb) {
                anyhow::bail!(
                    "hits files {} ({}x{}) and {} ({}x{}) are of frames of different sizes; compare hits of the same frame",
                    h[0].display(), size(&ra).0, size(&ra).1, h[1].display(), size(&rb).0, size(&rb).1
                );
            }
            Some((ra, rb))
        }
        None => None,
    };
    let (ia, ib) = (open(&a.a)?, open(&a.b)?);
    let m = compare::compare_images(&ia, &ib)
        .with_context(|| format!("comparing {} with {}", a.a.display(), a.b.display()))?;
    let hit_metrics = match &hits {
        Some((ra, rb)) => Some(compare::compare_hits(
            &ra.iter().map(|r| r.hit).collect::<Vec<_>>(),
            &rb.iter().map(|r| r.hit).collect::<Vec<_>>(),
        )?),
        None => None,
    };
    if let Some((_, d)) = &diff {
        let out = a
            .out
            .as_deref()
            .map(|o| dynrt::output::OutputDir::create(o, "--out"))
            .transpose()?;
        dynrt::output::write_png(d, &compare::diff_image(&ia, &ib))?;
        if let Some(o) = out {
            o.keep();
        }
    }
    let failed = failed_thresholds(&a, &m);
    if a.json {
        let mut j = serde_json::json!({
            "a": a.a,
            "b": a.b,
            "pixels": m.pixels,
            "differing_pixels": m.differing_pixels,
            "max_channel_error": m.max_channel_error,
            // JSON has no infinity: identical images give null.
            "psnr_db": m.psnr_db.is_finite().then_some(m.psnr_db),
            "ssim": m.ssim,
            "diff": diff.as_ref().map(|(_, d)| d),
            "failed": failed,
            "pass": failed.is_empty(),
        });
        if let Some(hm) = &hit_metrics {
            j["hits"] = serde_json::json!({
                "pixels": hm.pixels,
                "identical_hits": hm.identical_hits,
                "mean_rel_dist_error": hm.mean_rel_dist_error,
                "max_rel_dist_error": hm.max_rel_dist_error,
            });
        }
        println!("{j:#}");
    } else {
        println!("pixels           {}", m.pixels);
        println!(
            "differing pixels {} ({:.4}%)",
            m.differing_pixels,
            100.0 * m.differing_share()
        );
        println!("max channel err  {}", m.max_channel_error);
        println!("PSNR             {:.2} dB", m.psnr_db);
        println!("SSIM             {:.4}", m.ssim);
        if let Some(hm) = &hit_metrics {
            println!(
                "identical hits   {} of {} ({:.4}%)",
                hm.identical_hits,
                hm.pixels,
                100.0 * hm.identical_ratio()
            );
            println!(
                "rel dist error   mean {:.3e} max {:.3e}",
                hm.mean_rel_dist_error, hm.max_rel_dist_error
            );
        }
        if let Some((_, d)) = &diff {
            println!("diff image       {}", d.display());
        }
        for f in &failed {
            println!("FAIL: {f}");
        }
    }
    if failed.is_empty() {
        Ok(0)
    } else {
        Ok(super::EXIT_DIFFERS)
    }
}
