//! `dynrt bench scenes`: per bundled scene and number format, the kd-tree build rate, the
//! layout size, golden and reference speed, and the golden model's error against the f64
//! reference.

use super::table::Table;
use crate::compare::{compare_hits, compare_images};
use crate::fp::Format;
use crate::layout::{self, MemoryConfig, SceneTrees, BANK_NAMES};
use crate::model::{render_golden, Reference};
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One measured scene and format.
#[derive(Clone, Debug)]
pub struct SceneRow {
    pub scene: String,
    pub format: Format,
    pub width: u32,
    pub height: u32,
    pub triangles: usize,
    pub instances: usize,
    pub tree_build_seconds: f64,
    pub layout_bytes: Vec<usize>,
    pub golden_seconds: f64,
    /// All rays the golden model traced (primary, shadow, mirror).
    pub golden_rays: u64,
    pub reference_seconds: f64,
    pub identical_hits: f64,
    pub equivalent_hits: f64,
    pub psnr_db: f64,
    pub max_channel_error: u8,
    pub mean_rel_dist_error: f64,
}

impl SceneRow {
    pub fn primary_rays(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }
}

/// Measures `scenes` in `formats` (frame 0, each scene's own resolution unless overridden).
pub fn bench_scenes(
    scenes: &[PathBuf],
    formats: &[Format],
    resolution: Option<(u32, u32)>,
) -> anyhow::Result<Vec<SceneRow>> {
    let mut rows = Vec::new();
    for path in scenes {
        let mut scene = Scene::load(path)?;
        if let Some((w, h)) = resolution {
            scene.set_resolution(w, h)?;
        }
        let name = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        let reference = Reference::new(&scene);
        let t0 = Instant::now();
        let ref_frame = reference.render(0);
        let reference_seconds = t0.elapsed().as_secs_f64();
        for &format in formats {
            let t0 = Instant::now();
            let trees = SceneTrees::build(&scene, format)?;
            let tree_build_seconds = t0.elapsed().as_secs_f64();
            let l = layout::build(&scene, &trees, 0, &MemoryConfig::default())?;
            let t0 = Instant::now();
            let g = render_golden(&l, false);
            let golden_seconds = t0.elapsed().as_secs_f64();
            let img = compare_images(&g.to_image(), &ref_frame.to_image())?;
            let hits = compare_hits(&g.hit_tuples(), &ref_frame.hit_tuples())?;
            rows.push(SceneRow {
                scene: name.clone(),
                format,
                width: scene.camera.width,
                height: scene.camera.height,
                triangles: scene.triangle_count(),
                instances: scene.instances.len(),
                tree_build_seconds,
                layout_bytes: l.used_words().iter().map(|w| w * 4).collect(),
                golden_seconds,
                golden_rays: g.stats.rays,
                reference_seconds,
                identical_hits: hits.identical_ratio(),
                equivalent_hits: hits.equivalent_ratio(),
                psnr_db: img.psnr_db,
                max_channel_error: img.max_channel_error,
                mean_rel_dist_error: hits.mean_rel_dist_error,
            });
        }
    }
    Ok(rows)
}

/// The rows as a table (render times exclude building the trees).
pub fn scenes_table(rows: &[SceneRow]) -> Table {
    let mut t = Table::new(&[
        "scene",
        "format",
        "resolution",
        "triangles",
        "instances",
        "tree build (ktri/s)",
        "layout (KiB)",
        "largest bank",
        "golden (Mrays/s, all rays)",
        "golden (Mprimary/s)",
        "reference (Mprimary/s)",
        "identical hits %",
        "equivalent hits %",
        "PSNR dB",
        "max channel error",
        "mean rel dist error",
    ]);
    for r in rows {
        let (bank, bytes) = r
            .layout_bytes
            .iter()
            .enumerate()
            .max_by_key(|&(_, b)| *b)
            .map_or((0, 0), |(i, b)| (i, *b));
        t.push(vec![
            r.scene.clone(),
            r.format.to_string(),
            format!("{}x{}", r.width, r.height),
            r.triangles.to_string(),
            r.instances.to_string(),
            format!("{:.0}", r.triangles as f64 / r.tree_build_seconds / 1e3),
            format!(
                "{:.0}",
                r.layout_bytes.iter().sum::<usize>() as f64 / 1024.0
            ),
            format!("{} {:.0} KiB", BANK_NAMES[bank], bytes as f64 / 1024.0),
            format!("{:.3}", r.golden_rays as f64 / r.golden_seconds / 1e6),
            format!("{:.3}", r.primary_rays() as f64 / r.golden_seconds / 1e6),
            format!("{:.3}", r.primary_rays() as f64 / r.reference_seconds / 1e6),
            format!("{:.3}", 100.0 * r.identical_hits),
            format!("{:.3}", 100.0 * r.equivalent_hits),
            if r.psnr_db.is_finite() {
                format!("{:.1}", r.psnr_db)
            } else {
                "inf".into()
            },
            r.max_channel_error.to_string(),
            format!("{:.2e}", r.mean_rel_dist_error),
        ]);
    }
    t
}

/// The scenes under `dir` (every `*.toml`; `bundled:/` for the ones bundled with the
/// binary), sorted by name.
pub fn bundled_scenes(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    crate::bundled::scene_files(dir)
}
