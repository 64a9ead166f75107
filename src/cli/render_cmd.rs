//! `dynrt render`: one frame of a scene with the golden model or the f64 reference.

use clap::{Args, ValueEnum};
use dynrt::fp::Format;
use dynrt::layout::{self, MemoryConfig, SceneTrees};
use dynrt::model::{self, Reference};
use dynrt::scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelKind {
    Golden,
    Reference,
}

#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// golden: the eXmY model the hardware matches bit for bit; reference: f64.
    #[arg(long, value_enum, default_value = "golden")]
    pub model: ModelKind,
    /// Number format eXmY of the golden model.
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// Frame of an animated scene (0-based).
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    #[command(flatten)]
    pub size: super::SizeArgs,
    /// Output folder (created if missing): frame<N>.png, and hits<N>.csv with --hits.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Also write the primary hit of every pixel (CSV: x,y,instance,triangle,dist) as
    /// hits<N>.csv into --out; `--hits FILE`, the older form, writes it to FILE instead.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    pub hits: Option<Option<PathBuf>>,
    /// Print the result as one JSON document on stdout (model, format, scene, size, frame,
    /// rays that hit, seconds, files) instead of the one-line summary.
    #[arg(long)]
    pub json: bool,
}

/// Loads a scene and applies a resolution override (checked like the scene's own).
pub fn load_scene(
    path: &std::path::Path,
    width: Option<u32>,
    height: Option<u32>,
) -> anyhow::Result<Scene> {
    let mut scene = Scene::load(path)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    scene.set_resolution(
        width.unwrap_or(scene.camera.width),
        height.unwrap_or(scene.camera.height),
    )?;
    Ok(scene)
}

pub fn run(a: RenderArgs) -> anyhow::Result<i32> {
    // `--out IMG.png` was the image itself before --out became a folder on every command: an
    // old script would otherwise get a folder named like an image.
    if a.out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        && !a.out.is_dir()
    {
        anyhow::bail!(
            "--out '{}' names an image, but --out is the folder render writes into (frame{}.png, hits{}.csv with --hits); name a folder, e.g. --out out/render",
            a.out.display(),
            a.frame,
            a.frame
        );
    }
    dynrt::output::check_output_dir(&a.out, "--out")?;
    let png_path = a.out.join(format!("frame{}.png", a.frame));
    let hits_path = match &a.hits {
        None => None,
        Some(None) => Some(a.out.join(format!("hits{}.csv", a.frame))),
        Some(Some(h)) => {
            dynrt::output::check_output_file(h, "--hits")?;
            Some(h.clone())
        }
    };
    let mut outputs: Vec<(&str, &std::path::Path)> = vec![("--out", &png_path)];
    if let Some(h) = &hits_path {
        outputs.push(("--hits", h));
    }
    dynrt::output::check_distinct(&outputs, &[("the scene", &a.scene)])?;
    let (width, height) = a.size.width_height();
    let scene = load_scene(&a.scene, width, height)?;
    if a.frame >= scene.frames {
        anyhow::bail!(
            "{}: frame {} does not exist; the scene has {} frame(s) (0..{})",
            a.scene.display(),
            a.frame,
            scene.frames,
            scene.frames
        );
    }
    let mut start = Instant::now();
    let frame = match a.model {
        ModelKind::Golden => {
            let trees = SceneTrees::build(&scene, a.format)?;
            if trees.dropped_count() > 0 {
                eprintln!(
                    "warning: {} triangle(s) dropped: their unit-triangle transforms overflow {}",
                    trees.dropped_count(),
                    a.format
                );
            }
            let layout = layout::build(&scene, &trees, a.frame, &MemoryConfig::default())?;
            let sizes: Vec<String> = layout
                .used_words()
                .iter()
                .zip(layout::BANK_NAMES)
                .map(|(w, n)| format!("{n} {:.1} KiB", *w as f64 * 4.0 / 1024.0))
                .collect();
            eprintln!(
                "layout {:.1} KiB: {}",
                layout.total_bytes() as f64 / 1024.0,
                sizes.join(", ")
            );
            eprintln!("trees and layout {:.3} s", start.elapsed().as_secs_f64());
            start = Instant::now();
            let golden = model::render_golden(&layout, true);
            // The RTL matches the golden model whatever the format does to the scene; only the
            // f64 reference shows a format that cannot hold it.
            let reference = Reference::new(&scene).render(a.frame);
            let hits = dynrt::compare::compare_hits(&golden.hit_tuples(), &reference.hit_tuples())?;
            if let Some(w) = dynrt::compare::golden_warning(a.format, &hits) {
                eprintln!("warning: {}: {w}", a.scene.display());
            }
            golden
        }
        ModelKind::Reference => {
            let reference = Reference::new(&scene);
            eprintln!("trees {:.3} s", start.elapsed().as_secs_f64());
            start = Instant::now();
            reference.render_with_progress(a.frame, true)
        }
    };
    let secs = start.elapsed().as_secs_f64();
    let png = dynrt::output::png_bytes(&frame.to_image())?;
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&png_path, &png)];
    let hits_text = frame.hits_text();
    if let Some(h) = &hits_path {
        files.push((h, &hits_text));
    }
    let out = dynrt::output::OutputDir::create(&a.out, "--out")?;
    dynrt::output::write_all_atomically(&files)?;
    out.keep();
    let pixels = u64::from(frame.width) * u64::from(frame.height);
    let hits = frame.hits.iter().filter(|h| h.is_some()).count();
    let model = match a.model {
        ModelKind::Golden => "golden",
        ModelKind::Reference => "reference",
    };
    let number_format = if a.model == ModelKind::Golden {
        a.format.to_string()
    } else {
        "f64".into()
    };
    if a.json {
        let mut written = vec![png_path.display().to_string()];
        written.extend(hits_path.iter().map(|h| h.display().to_string()));
        let j = serde_json::json!({
            "verb": "render",
            "dynrt_version": env!("CARGO_PKG_VERSION"),
            "scene": scene.source,
            "model": model,
            "format": number_format,
            "frame": a.frame,
            "width": frame.width,
            "height": frame.height,
            "pixels": pixels,
            "primary_hits": hits,
            "seconds": secs,
            "primary_rays_per_second": pixels as f64 / secs,
            "files": written,
        });
        println!("{}", serde_json::to_string_pretty(&j)?);
        return Ok(0);
    }
    println!(
        "{model} {}x{} frame {} ({number_format}): {} of {} primary rays hit, frame {:.3} s, {:.3} M primary rays/s -> {}",
        frame.width,
        frame.height,
        a.frame,
        hits,
        pixels,
        secs,
        pixels as f64 / secs / 1e6,
        png_path.display()
    );
    Ok(0)
}
