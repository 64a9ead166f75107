//! `dynrt compare`: error metrics between two images (and their hits files).

use anyhow::Context;
use clap::Args;
use dynrt::compare;
use std::path::PathBuf;

#[derive(Args)]
pub struct CompareArgs {
    pub a: PathBuf,
    pub b: PathBuf,
    /// Write a diff image (amplified absolute difference).
    #[arg(long)]
    pub diff: Option<PathBuf>,
    /// Hits files of A and B: adds the identical-hit ratio and distance errors.
    #[arg(long, num_args = 2, value_names = ["HITS_A", "HITS_B"])]
    pub hits: Option<Vec<PathBuf>>,
}

fn open(p: &std::path::Path) -> anyhow::Result<image::RgbImage> {
    let bytes = dynrt::input::read_bytes(p, "image", dynrt::input::MAX_IMAGE_BYTES)?;
    Ok(image::load_from_memory(&bytes)
        .with_context(|| format!("image '{}' cannot be decoded (PNG expected)", p.display()))?
        .to_rgb8())
}

pub fn run(a: CompareArgs) -> anyhow::Result<i32> {
    if let Some(d) = &a.diff {
        dynrt::output::check_output_file(d, "--diff")?;
        let mut inputs: Vec<(&str, &std::path::Path)> = vec![("image A", &a.a), ("image B", &a.b)];
        if let Some(h) = &a.hits {
            inputs.extend([("HITS_A", h[0].as_path()), ("HITS_B", h[1].as_path())]);
        }
        dynrt::output::check_distinct(&[("--diff", d)], &inputs)?;
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
    println!("pixels           {}", m.pixels);
    println!(
        "differing pixels {} ({:.4}%)",
        m.differing_pixels,
        100.0 * m.differing_share()
    );
    println!("max channel err  {}", m.max_channel_error);
    println!("PSNR             {:.2} dB", m.psnr_db);
    if let Some((ra, rb)) = &hits {
        let hm = compare::compare_hits(
            &ra.iter().map(|r| r.hit).collect::<Vec<_>>(),
            &rb.iter().map(|r| r.hit).collect::<Vec<_>>(),
        )?;
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
    if let Some(d) = &a.diff {
        dynrt::output::write_png(d, &compare::diff_image(&ia, &ib))?;
        println!("diff image       {}", d.display());
    }
    Ok(0)
}
