//! `dynrt bench precision`: every scene rendered by the golden model in every number format of
//! the sweep and compared with the f64 reference, next to each format's hardware cost.
//!
//! Per (scene, format) row: identical and equivalent hit ratios, PSNR, maximum channel error,
//! mean / maximum relative hit-distance error (`compare`), shadow-acne pixels (shadowed in the
//! golden frame but lit in the reference at a pixel whose primary hit agrees: each frame is
//! rendered with and without shadow rays to tell), and for closed meshes the pixels an inside
//! camera leaks and the leak rate of rays aimed at shared edges ([`crate::stress`]); with an
//! edge margin, what it changes against the exact test (margin 0) ([`MarginChanges`]: the
//! silhouette cost and the cracks closed); the golden model's single-frame run time (rayon-parallel, wall clock: compare formats within one run
//! only) and the datapath cost estimate ([`super::cost`]).
//!
//! [`summarize`] folds the rows into one [`FormatSummary`] per format, [`write_outputs`]
//! writes `precision.csv`, `precision_summary.csv` and the plots (mismatch share against
//! datapath LUTs and against run time, Pareto front marked), [`recommend`] picks the default.

use super::cost::{self, DatapathCost, OpCost, INTERSECT_OPS, TRANSFORM_OPS};
use super::plot::{scatter_with_front, Point};
use crate::compare::{compare_hits, compare_images};
use crate::fp::Format;
use crate::layout::{self, MemoryConfig, SceneTrees};
use crate::model::{render_with, units, Frame, Golden, Reference};
use crate::scene::Scene;
use crate::stress::{cases, geometry};
use anyhow::{Context, Result};
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct SweepConfig {
    /// Scene files (frame 0 of each is rendered).
    pub scenes: Vec<PathBuf>,
    /// A directory of OBJ meshes, each framed automatically (front view, one light).
    pub mesh_dir: Option<PathBuf>,
    pub formats: Vec<Format>,
    pub width: u32,
    pub height: u32,
    /// Edge margin of the unit-triangle test in units of 2^-mantissa bits: by default
    /// `units::EDGE_MARGIN_ULPS`, what the golden model and the hardware compute; 0 is the
    /// exact test.
    pub edge_margin_ulps: f64,
    /// Cost cache (see [`cost::measure_or_load`]) and where yosys works.
    pub cost_csv: PathBuf,
    pub synth_dir: PathBuf,
    /// Synthesize operators missing from the cache (seconds to a minute each).
    pub synthesize: bool,
    pub seed: u64,
    /// Edge-aimed rays per closed mesh.
    pub leak_rays: usize,
}

impl SweepConfig {
    /// The scenes of `scenes_dir` (a folder, or the bundled one `bundled:/`), every format
    /// with hardware operators, 96x72, the hardware's unit-triangle test (edge margin
    /// `units::EDGE_MARGIN_ULPS`), and the operator costs measured once and kept in the
    /// repository (`benches/data/fp_cost_xc2v.csv` beside `scenes_dir`; for the bundled scenes,
    /// or when that file is not there, a copy of the one bundled with the binary in the temp
    /// folder, see [`bundled_cost_csv`]); missing rows are synthesized and appended.
    pub fn new(scenes_dir: &Path) -> Result<SweepConfig> {
        let scenes = crate::bundled::scene_files(scenes_dir)
            .with_context(|| format!("reading {}", scenes_dir.display()))?;
        let beside = scenes_dir
            .parent()
            .unwrap_or(Path::new("."))
            .join("benches/data/fp_cost_xc2v.csv");
        let synth_dir = std::env::temp_dir().join("dynrt-fp-cost");
        let cost_csv = if !crate::bundled::is_bundled(scenes_dir) && beside.is_file() {
            beside
        } else {
            bundled_cost_csv(&synth_dir)?
        };
        Ok(SweepConfig {
            scenes,
            mesh_dir: None,
            formats: crate::hw::fp::supported_formats(),
            width: 96,
            height: 72,
            edge_margin_ulps: f64::from(units::EDGE_MARGIN_ULPS),
            cost_csv,
            synth_dir,
            synthesize: true,
            seed: 6,
            leak_rays: 20_000,
        })
    }
}

/// The operator cost cache bundled with the binary, copied (once) to `dir` under a name
/// that changes with its contents, so that rows synthesized later are appended to a file
/// of this build's costs, never to the repository's or another build's.
pub fn bundled_cost_csv(dir: &Path) -> Result<PathBuf> {
    // FNV-1a: a name that stays the same across Rust versions, unlike std's hasher.
    let hash = crate::bundled::FP_COST_CSV
        .iter()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
        });
    let path = dir.join(format!("fp_cost_xc2v-{hash:016x}.csv"));
    if !path.is_file() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        crate::output::write_atomically(&path, crate::bundled::FP_COST_CSV)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(path)
}

/// One scene in one format.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub scene: String,
    pub format: Format,
    pub triangles: usize,
    pub pixels: usize,
    pub identical_hit_ratio: f64,
    pub equivalent_hit_ratio: f64,
    pub psnr_db: f64,
    pub max_channel_error: u8,
    pub mean_rel_dist_error: f64,
    pub max_rel_dist_error: f64,
    pub acne_pixels: usize,
    /// Inside-camera pixels that saw nothing and pixels rendered (closed meshes only).
    pub inside_leaks: Option<(u64, u64)>,
    /// Edge-aimed rays from inside that leaked, and rays cast (closed meshes only).
    pub edge_leaks: Option<(u64, u64)>,
    /// With a non-zero edge margin: the frame against the exact test's.
    pub margin_changes: Option<MarginChanges>,
    pub golden_seconds: f64,
    pub reference_seconds: f64,
    /// Triangles the layout dropped (transform not representable).
    pub dropped_triangles: usize,
    pub datapath: Option<DatapathCost>,
    /// Why a format could not render the scene (the row's error figures are then NaN).
    pub note: String,
}

/// What an edge margin changes in a frame against the exact test (margin 0): pixels whose
/// colour changes, primary hits on another triangle (or hit against miss), and of those the
/// ones that now agree with the f64 reference where they did not (cracks closed) and the
/// reverse (silhouettes grown: a triangle grown by the margin catches a ray that passes just
/// outside it). Agreement is [`compare_hits`]'s equivalence, per pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MarginChanges {
    pub changed_pixels: usize,
    pub changed_hits: usize,
    pub fixed_hits: usize,
    pub broken_hits: usize,
}

impl MarginChanges {
    /// `with`: rendered with the margin; `exact`: margin 0; `reference`: f64.
    pub fn measure(with: &Frame, exact: &Frame, reference: &Frame) -> MarginChanges {
        let (w, e, r) = (
            with.hit_tuples(),
            exact.hit_tuples(),
            reference.hit_tuples(),
        );
        let agrees = |a: &Option<(i64, i64, f64)>, b: &Option<(i64, i64, f64)>| {
            compare_hits(&[*a], &[*b]).is_ok_and(|m| m.equivalent_hits == 1)
        };
        let key = |h: &Option<(i64, i64, f64)>| h.map(|(i, t, _)| (i, t));
        let mut c = MarginChanges::default();
        for i in 0..w.len() {
            c.changed_pixels += usize::from(with.rgb[i] != exact.rgb[i]);
            if key(&w[i]) != key(&e[i]) {
                c.changed_hits += 1;
                match (agrees(&w[i], &r[i]), agrees(&e[i], &r[i])) {
                    (true, false) => c.fixed_hits += 1,
                    (false, true) => c.broken_hits += 1,
                    _ => {}
                }
            }
        }
        c
    }

    fn add(self, o: MarginChanges) -> MarginChanges {
        MarginChanges {
            changed_pixels: self.changed_pixels + o.changed_pixels,
            changed_hits: self.changed_hits + o.changed_hits,
            fixed_hits: self.fixed_hits + o.fixed_hits,
            broken_hits: self.broken_hits + o.broken_hits,
        }
    }
}

/// One scene prepared for the sweep.
struct Subject {
    name: String,
    scene: Scene,
    /// A copy with the camera inside, for closed meshes.
    inside: Option<Scene>,
    /// World triangles, for edge rays (closed meshes).
    closed: Option<geometry::Tris>,
}

/// Frames a mesh: camera in front (+z) at 2.2 sizes, light up and to the right.
fn mesh_subject(
    dir: &Path,
    path: &Path,
    cfg: &SweepConfig,
    rng: &mut ChaCha8Rng,
) -> Result<Subject> {
    // The scene text is parsed relative to `dir`, so it must name the mesh absolutely.
    let path =
        &std::path::absolute(path).with_context(|| format!("mesh path {}", path.display()))?;
    let tris = geometry::load_mesh(path)?;
    let (lo, hi) = geometry::bounds(&tris);
    let (c, s) = ((lo + hi) * 0.5, (hi - lo).max_element());
    let name = path
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned();
    let toml = |eye: DVec3, look: DVec3| {
        format!(
            "[camera]\neye = [{:?}, {:?}, {:?}]\nlook_at = [{:?}, {:?}, {:?}]\nup = [0.0, 1.0, 0.0]\n\
             fov_y = 40.0\nwidth = {}\nheight = {}\n\n[render]\nshadows = true\n\n\
             [[lights]]\nposition = [{:?}, {:?}, {:?}]\n\n[[objects]]\nname = \"{name}\"\nmesh = {:?}\n",
            eye.x, eye.y, eye.z, look.x, look.y, look.z, cfg.width, cfg.height,
            c.x + s, c.y + 2.0 * s, c.z + 1.5 * s,
            path.display().to_string()
        )
    };
    let eye = c + DVec3::new(0.6 * s, 0.4 * s, 2.2 * s);
    let scene = Scene::from_toml_str(&toml(eye, c), dir, &format!("{name}.toml"))
        .with_context(|| format!("framing mesh {}", path.display()))?;
    let closed = geometry::is_closed(&tris);
    let inside = if closed {
        geometry::inside_points(&tris, 1, rng).first().map(|&p| {
            let look = p + geometry::random_direction(rng);
            Scene::from_toml_str(&toml(p, look), dir, &format!("{name}_inside.toml"))
        })
    } else {
        None
    };
    Ok(Subject {
        name,
        scene,
        inside: inside.transpose()?,
        closed: closed.then_some(tris),
    })
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let v = f();
    (v, t.elapsed().as_secs_f64())
}

/// Pixels shadowed in the golden frame but lit in the reference, where both hit the same
/// triangle (a shadowed pixel is one whose colour changes when shadow rays are switched off).
fn acne_pixels(g_on: &Frame, g_off: &Frame, r_on: &Frame, r_off: &Frame) -> usize {
    (0..g_on.rgb.len())
        .filter(|&i| {
            let same_hit = match (g_on.hits[i], r_on.hits[i]) {
                (Some(a), Some(b)) => (a.instance, a.triangle) == (b.instance, b.triangle),
                _ => false,
            };
            same_hit && g_on.rgb[i] != g_off.rgb[i] && r_on.rgb[i] == r_off.rgb[i]
        })
        .count()
}

/// Runs the sweep; `log` gets a line per scene and format.
pub fn precision_sweep(config: &SweepConfig, log: &mut dyn FnMut(&str)) -> Result<Vec<Row>> {
    let costs: Vec<OpCost> = cost::measure_or_load(
        &config.formats,
        &config.cost_csv,
        &config.synth_dir,
        config.synthesize,
        log,
    )?;
    let tmp = tempfile::tempdir().context("creating a temporary directory for mesh scenes")?;
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let mut subjects = Vec::new();
    for path in &config.scenes {
        let mut scene = Scene::load(path).with_context(|| format!("loading {}", path.display()))?;
        scene.set_resolution(config.width, config.height)?;
        let name = path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        subjects.push(Subject {
            name,
            scene,
            inside: None,
            closed: None,
        });
    }
    if let Some(dir) = &config.mesh_dir {
        let mut objs: Vec<PathBuf> = std::fs::read_dir(dir)
            .with_context(|| format!("reading mesh directory {}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "obj"))
            .collect();
        objs.sort();
        for p in objs {
            subjects.push(mesh_subject(tmp.path(), &p, config, &mut rng)?);
        }
    }

    let mut rows = Vec::new();
    let mut steps = crate::progress::Steps::new(subjects.len() * config.formats.len());
    for sub in &subjects {
        let reference = Reference::new(&sub.scene);
        let (r_on, reference_seconds) = timed(|| reference.render(0));
        let shadows = sub.scene.render.shadows && !sub.scene.lights.is_empty();
        let r_off = shadows.then(|| {
            let mut s = sub.scene.clone();
            s.render.shadows = false;
            Reference::new(&s).render(0)
        });
        let edge_case = sub.closed.as_ref().map(|tris| {
            let world = tris.clone();
            let rays = cases::edge_rays(&world, config.leak_rays, &mut rng);
            (world, rays)
        });
        for &f in &config.formats {
            steps.start(&format!("{} {f}", sub.name));
            let mut row = Row {
                scene: sub.name.clone(),
                format: f,
                triangles: sub.scene.instanced_triangle_count(),
                pixels: r_on.rgb.len(),
                identical_hit_ratio: f64::NAN,
                equivalent_hit_ratio: f64::NAN,
                psnr_db: f64::NAN,
                max_channel_error: 255,
                mean_rel_dist_error: f64::NAN,
                max_rel_dist_error: f64::NAN,
                acne_pixels: 0,
                inside_leaks: None,
                edge_leaks: None,
                margin_changes: None,
                golden_seconds: f64::NAN,
                reference_seconds,
                dropped_triangles: 0,
                datapath: DatapathCost::estimate(f, &costs, &[TRANSFORM_OPS, INTERSECT_OPS]),
                note: String::new(),
            };
            let built = SceneTrees::build(&sub.scene, f).and_then(|t| {
                let l = layout::build(&sub.scene, &t, 0, &MemoryConfig::default())?;
                Ok((t, l))
            });
            let (trees, mut lay) = match built {
                Ok(x) => x,
                Err(e) => {
                    row.note = e.to_string();
                    log(&format!("{} {f}: refused: {e}", sub.name));
                    rows.push(row);
                    continue;
                }
            };
            row.dropped_triangles = trees.dropped_count();
            let margin = cases::margin_for(f, config.edge_margin_ulps);
            let (g_on, secs) =
                timed(|| render_with(&Golden::with_edge_margin(&lay, margin), false));
            row.golden_seconds = secs;
            let im = compare_images(&g_on.to_image(), &r_on.to_image())?;
            let hm = compare_hits(&g_on.hit_tuples(), &r_on.hit_tuples())?;
            row.identical_hit_ratio = hm.identical_ratio();
            row.equivalent_hit_ratio = hm.equivalent_ratio();
            row.psnr_db = im.psnr_db;
            row.max_channel_error = im.max_channel_error;
            row.mean_rel_dist_error = hm.mean_rel_dist_error;
            row.max_rel_dist_error = hm.max_rel_dist_error;
            if margin != 0.0 {
                let exact = render_with(&Golden::with_edge_margin(&lay, 0.0), false);
                row.margin_changes = Some(MarginChanges::measure(&g_on, &exact, &r_on));
            }
            if let Some(r_off) = &r_off {
                lay.info.shadows = false;
                let g_off = render_with(&Golden::with_edge_margin(&lay, margin), false);
                row.acne_pixels = acne_pixels(&g_on, &g_off, &r_on, r_off);
            }
            if let Some(inside) = &sub.inside {
                if let Ok(l) = cases::layout_for(inside, f) {
                    let (px, miss, _) = cases::render_check(&Golden::with_edge_margin(&l, margin));
                    row.inside_leaks = Some((miss, px));
                }
            }
            if let Some((world, rays)) = &edge_case {
                let subject = cases::Subject {
                    name: sub.name.clone(),
                    scene: sub.scene.clone(),
                    world: world.clone(),
                };
                let case = cases::RayCase {
                    name: "edge_rays".into(),
                    subject,
                    rays: rays.clone(),
                    check: cases::Check::MustHit,
                    limit: crate::stress::Limit::Watertight,
                };
                row.edge_leaks = cases::run_ray_case(&case, Some(f), config.edge_margin_ulps)
                    .ok()
                    .map(|(rays, leaked)| (leaked, rays));
            }
            log(&format!(
                "{} {f}: identical {:.4} equivalent {:.4} PSNR {:.1} dB acne {} golden {:.2} s",
                sub.name,
                row.identical_hit_ratio,
                row.equivalent_hit_ratio,
                row.psnr_db,
                row.acne_pixels,
                secs
            ));
            rows.push(row);
        }
    }
    steps.finish();
    Ok(rows)
}

fn opt_pair(p: Option<(u64, u64)>) -> (String, String) {
    p.map_or((String::new(), String::new()), |(a, b)| {
        (a.to_string(), b.to_string())
    })
}

/// The rows as CSV.
pub fn rows_csv(rows: &[Row]) -> String {
    let header = [
        "scene",
        "format",
        "triangles",
        "pixels",
        "identical_hit_ratio",
        "equivalent_hit_ratio",
        "psnr_db",
        "max_channel_error",
        "mean_rel_dist_error",
        "max_rel_dist_error",
        "acne_pixels",
        "inside_leaked_pixels",
        "inside_pixels",
        "edge_leaked_rays",
        "edge_rays",
        "margin_changed_pixels",
        "margin_changed_hits",
        "margin_fixed_hits",
        "margin_broken_hits",
        "golden_seconds",
        "reference_seconds",
        "dropped_triangles",
        "datapath_luts",
        "datapath_flip_flops",
        "datapath_mult18x18",
        "note",
    ];
    let lines: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let (il, ip) = opt_pair(r.inside_leaks);
            let (el, er) = opt_pair(r.edge_leaks);
            let (mp, mh, mf, mb) = r.margin_changes.map_or(Default::default(), |c| {
                (
                    c.changed_pixels.to_string(),
                    c.changed_hits.to_string(),
                    c.fixed_hits.to_string(),
                    c.broken_hits.to_string(),
                )
            });
            let (l, ff, m) = datapath_fields(r.datapath);
            vec![
                r.scene.clone(),
                r.format.to_string(),
                r.triangles.to_string(),
                r.pixels.to_string(),
                format!("{:.6}", r.identical_hit_ratio),
                format!("{:.6}", r.equivalent_hit_ratio),
                format!("{:.3}", r.psnr_db),
                r.max_channel_error.to_string(),
                format!("{:.3e}", r.mean_rel_dist_error),
                format!("{:.3e}", r.max_rel_dist_error),
                r.acne_pixels.to_string(),
                il,
                ip,
                el,
                er,
                mp,
                mh,
                mf,
                mb,
                format!("{:.4}", r.golden_seconds),
                format!("{:.4}", r.reference_seconds),
                r.dropped_triangles.to_string(),
                l,
                ff,
                m,
                r.note.clone(),
            ]
        })
        .collect();
    crate::tables::csv_text(&header, &lines)
}

/// LUTs, flip-flops and multipliers of a datapath estimate, empty without one.
fn datapath_fields(d: Option<DatapathCost>) -> (String, String, String) {
    d.map_or((String::new(), String::new(), String::new()), |d| {
        (
            d.luts.to_string(),
            d.flip_flops.to_string(),
            d.mult18x18.to_string(),
        )
    })
}

/// The sweep folded per format (over the scenes every format rendered).
#[derive(Clone, Debug, PartialEq)]
pub struct FormatSummary {
    pub format: Format,
    /// Scenes summarized: those every format of the sweep rendered, so that formats are
    /// compared on the same scenes.
    pub scenes: usize,
    /// Scenes the format could not lay out.
    pub refused: usize,
    /// Of those, refused for another reason than the memory size (e.g. a scene beyond the
    /// format's range): such a format cannot be the default.
    pub refused_other: usize,
    /// Mean over scenes of 1 - equivalent hit ratio: primary hits on a different surface.
    pub mean_mismatch: f64,
    pub worst_mismatch: f64,
    pub mean_identical: f64,
    pub mean_psnr_db: f64,
    pub min_psnr_db: f64,
    pub acne_pixels: usize,
    pub pixels: usize,
    /// Leaked / cast over every closed mesh (inside cameras; edge-aimed rays).
    pub inside_leaks: (u64, u64),
    pub edge_leaks: (u64, u64),
    /// Summed over the scenes (zero without an edge margin).
    pub margin_changes: MarginChanges,
    pub golden_seconds: f64,
    pub datapath: Option<DatapathCost>,
}

impl FormatSummary {
    pub fn inside_leak_ppm(&self) -> f64 {
        self.inside_leaks.0 as f64 * 1e6 / self.inside_leaks.1.max(1) as f64
    }
    pub fn edge_leak_ppm(&self) -> f64 {
        self.edge_leaks.0 as f64 * 1e6 / self.edge_leaks.1.max(1) as f64
    }
}

/// One summary per format, in the order of first appearance.
pub fn summarize(rows: &[Row]) -> Vec<FormatSummary> {
    let mut formats: Vec<Format> = Vec::new();
    for r in rows {
        if !formats.contains(&r.format) {
            formats.push(r.format);
        }
    }
    let common = |scene: &str| {
        rows.iter()
            .filter(|r| r.scene == scene)
            .all(|r| r.note.is_empty())
    };
    formats
        .into_iter()
        .map(|f| {
            let all: Vec<&Row> = rows.iter().filter(|r| r.format == f).collect();
            let ok: Vec<&Row> = all.iter().copied().filter(|r| common(&r.scene)).collect();
            let n = ok.len().max(1) as f64;
            let mismatch = |r: &Row| 1.0 - r.equivalent_hit_ratio;
            let sum2 = |g: &dyn Fn(&Row) -> Option<(u64, u64)>| {
                ok.iter()
                    .filter_map(|r| g(r))
                    .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
            };
            FormatSummary {
                format: f,
                scenes: ok.len(),
                refused: all.iter().filter(|r| !r.note.is_empty()).count(),
                refused_other: all
                    .iter()
                    .filter(|r| !r.note.is_empty() && !r.note.contains("does not fit the memory"))
                    .count(),
                mean_mismatch: ok.iter().map(|r| mismatch(r)).sum::<f64>() / n,
                worst_mismatch: ok.iter().map(|r| mismatch(r)).fold(0.0, f64::max),
                mean_identical: ok.iter().map(|r| r.identical_hit_ratio).sum::<f64>() / n,
                // Identical images have infinite PSNR: cap at 100 dB for the mean.
                mean_psnr_db: ok.iter().map(|r| r.psnr_db.min(100.0)).sum::<f64>() / n,
                min_psnr_db: ok.iter().map(|r| r.psnr_db).fold(f64::INFINITY, f64::min),
                acne_pixels: ok.iter().map(|r| r.acne_pixels).sum(),
                pixels: ok.iter().map(|r| r.pixels).sum(),
                inside_leaks: sum2(&|r| r.inside_leaks),
                edge_leaks: sum2(&|r| r.edge_leaks),
                margin_changes: ok
                    .iter()
                    .filter_map(|r| r.margin_changes)
                    .fold(MarginChanges::default(), MarginChanges::add),
                golden_seconds: ok.iter().map(|r| r.golden_seconds).sum(),
                datapath: all.first().and_then(|r| r.datapath),
            }
        })
        .collect()
}

/// The summaries as CSV.
pub fn summary_csv(s: &[FormatSummary]) -> String {
    let header = [
        "format",
        "width_bits",
        "scenes",
        "refused",
        "refused_other",
        "mean_mismatch",
        "worst_mismatch",
        "mean_identical",
        "mean_psnr_db",
        "min_psnr_db",
        "acne_pixels",
        "pixels",
        "inside_leak_ppm",
        "edge_leak_ppm",
        "margin_changed_pixels",
        "margin_changed_hits",
        "margin_fixed_hits",
        "margin_broken_hits",
        "golden_seconds",
        "datapath_luts",
        "datapath_flip_flops",
        "datapath_mult18x18",
    ];
    let lines: Vec<Vec<String>> = s
        .iter()
        .map(|x| {
            let (l, ff, m) = datapath_fields(x.datapath);
            vec![
                x.format.to_string(),
                x.format.width().to_string(),
                x.scenes.to_string(),
                x.refused.to_string(),
                x.refused_other.to_string(),
                format!("{:.6}", x.mean_mismatch),
                format!("{:.6}", x.worst_mismatch),
                format!("{:.6}", x.mean_identical),
                format!("{:.2}", x.mean_psnr_db),
                format!("{:.2}", x.min_psnr_db),
                x.acne_pixels.to_string(),
                x.pixels.to_string(),
                format!("{:.1}", x.inside_leak_ppm()),
                format!("{:.1}", x.edge_leak_ppm()),
                x.margin_changes.changed_pixels.to_string(),
                x.margin_changes.changed_hits.to_string(),
                x.margin_changes.fixed_hits.to_string(),
                x.margin_changes.broken_hits.to_string(),
                format!("{:.3}", x.golden_seconds),
                l,
                ff,
                m,
            ]
        })
        .collect();
    crate::tables::csv_text(&header, &lines)
}

/// The cheapest format (datapath LUTs) that refused no scene but for its size, whose inside
/// cameras leak at most `max_leak_ppm`, and whose mean mismatch is at most
/// `max_excess_mismatch` above the most accurate format's (that floor is what the golden
/// model's algorithm differs from the f64 reference by at any precision: ties, silhouettes).
pub fn recommend(
    s: &[FormatSummary],
    max_excess_mismatch: f64,
    max_leak_ppm: f64,
) -> Option<&FormatSummary> {
    let floor = s
        .iter()
        .filter(|x| x.refused_other == 0)
        .map(|x| x.mean_mismatch)
        .fold(f64::INFINITY, f64::min);
    s.iter()
        .filter(|x| {
            x.refused_other == 0
                && x.mean_mismatch <= floor + max_excess_mismatch
                && x.inside_leak_ppm() <= max_leak_ppm
                && x.datapath.is_some()
        })
        .min_by_key(|x| x.datapath.map_or(u64::MAX, |d| d.luts))
}

/// Writes `precision.csv`, `precision_summary.csv`, `mismatch_vs_luts.png`,
/// `mismatch_vs_time.png` and `psnr_loss_vs_luts.png` into `out_dir` (the LUT plots only
/// when cost figures exist); returns the paths written.
pub fn write_outputs(rows: &[Row], out_dir: &Path) -> Result<Vec<PathBuf>> {
    let s = summarize(rows);
    let w = |name: &str, text: String| -> Result<PathBuf> {
        let p = out_dir.join(name);
        crate::output::write_atomically(&p, text.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
        Ok(p)
    };
    let mut out = vec![
        w("precision.csv", rows_csv(rows))?,
        w("precision_summary.csv", summary_csv(&s))?,
    ];
    let pts =
        |x: &dyn Fn(&FormatSummary) -> f64, y: &dyn Fn(&FormatSummary) -> f64| -> Vec<Point> {
            s.iter()
                .map(|v| Point {
                    label: v.format.to_string(),
                    cost: x(v),
                    error: y(v),
                })
                .collect()
        };
    let luts = |v: &FormatSummary| v.datapath.map_or(f64::NAN, |d| d.luts as f64);
    let plots: [(&str, &str, &str, &str, Vec<Point>, bool); 3] = [
        (
            "mismatch_vs_luts.png",
            "Primary-hit mismatch vs datapath cost (transform + intersection, xc2v)",
            "datapath LUTs (yosys, estimated from operator counts)",
            "mean share of pixels hitting another surface than f64",
            pts(&luts, &|v| v.mean_mismatch),
            true,
        ),
        (
            "mismatch_vs_time.png",
            "Primary-hit mismatch vs golden-model run time",
            "golden model seconds, all scenes",
            "mean share of pixels hitting another surface than f64",
            pts(&|v| v.golden_seconds, &|v| v.mean_mismatch),
            true,
        ),
        (
            "psnr_loss_vs_luts.png",
            "Image error vs datapath cost",
            "datapath LUTs (yosys, estimated from operator counts)",
            "100 dB - mean PSNR (lower is better)",
            pts(&luts, &|v| 100.0 - v.mean_psnr_db),
            false,
        ),
    ];
    for (name, title, xl, yl, p, log_y) in plots {
        // No cost figures (cache empty, synthesis off): no LUT plot rather than an empty one.
        if !p.iter().any(|p| p.cost.is_finite() && p.error.is_finite()) {
            continue;
        }
        let path = out_dir.join(name);
        scatter_with_front(&path, title, xl, yl, &p, log_y)?;
        out.push(path);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scene: &str, f: &str, eq: f64, luts: u64) -> Row {
        let format = Format::parse(f).unwrap();
        Row {
            scene: scene.into(),
            format,
            triangles: 10,
            pixels: 100,
            identical_hit_ratio: eq,
            equivalent_hit_ratio: eq,
            psnr_db: 40.0,
            max_channel_error: 3,
            mean_rel_dist_error: 0.0,
            max_rel_dist_error: 0.0,
            acne_pixels: 1,
            inside_leaks: Some((1, 1000)),
            edge_leaks: None,
            margin_changes: None,
            golden_seconds: 0.5,
            reference_seconds: 0.1,
            dropped_triangles: 0,
            datapath: Some(DatapathCost {
                format,
                luts,
                flip_flops: 0,
                mult18x18: 0,
            }),
            note: String::new(),
        }
    }

    #[test]
    fn summaries_average_over_scenes_and_the_cheapest_good_format_is_recommended() {
        let rows = vec![
            row("a", "e5m10", 0.90, 100),
            row("b", "e5m10", 0.80, 100),
            row("a", "e7m16", 0.999, 300),
            row("b", "e7m16", 0.997, 300),
            row("a", "e8m23", 1.0, 900),
            row("b", "e8m23", 1.0, 900),
        ];
        let mut rows = rows;
        // A scene one format cannot hold is left out of every format's summary.
        let mut big = row("c", "e5m10", 0.0, 100);
        big.note = "scene `c` does not fit the memory: ...".into();
        rows.push(big);
        rows.push(row("c", "e7m16", 0.0, 300));
        let s = summarize(&rows);
        assert_eq!(s.len(), 3);
        assert_eq!((s[0].scenes, s[0].refused, s[0].refused_other), (2, 1, 0));
        assert_eq!(s[1].scenes, 2, "scene c is not common to every format");
        assert!((s[0].mean_mismatch - 0.15).abs() < 1e-12);
        assert!((s[0].worst_mismatch - 0.2).abs() < 1e-12);
        assert_eq!(s[1].acne_pixels, 2);
        assert_eq!(s[1].inside_leaks, (2, 2000));
        // Mismatch above the floor (e8m23, 0): e5m10 0.15, e7m16 0.002.
        let pick =
            |excess: f64, leak: f64| recommend(&s, excess, leak).map(|x| x.format.to_string());
        assert_eq!(pick(0.01, 1e4).as_deref(), Some("e7m16"));
        assert_eq!(
            pick(0.2, 1e4).as_deref(),
            Some("e5m10"),
            "a memory refusal does not disqualify"
        );
        assert_eq!(pick(0.0, 1e4).as_deref(), Some("e8m23"));
        let csv = summary_csv(&s);
        let fields = |i: usize| csv.lines().nth(i).unwrap().split(',').count();
        assert_eq!(
            fields(0),
            fields(1),
            "header and rows have the same columns"
        );
        assert!(
            recommend(&s, 0.01, 100.0).is_none(),
            "1000 ppm leaks exceed 100"
        );
        let csv = rows_csv(&rows);
        assert_eq!(csv.lines().count(), 9);
        assert!(csv
            .lines()
            .nth(3)
            .unwrap()
            .starts_with("a,e7m16,10,100,0.999000"));
    }

    #[test]
    fn margin_changes_count_closed_cracks_and_grown_silhouettes() {
        use crate::model::HitRecord;
        let hit = |triangle: u32, dist: f64| {
            Some(HitRecord {
                instance: 0,
                triangle,
                dist,
            })
        };
        let frame = |hits: Vec<Option<HitRecord>>, rgb: Vec<u32>| Frame {
            width: hits.len() as u32,
            height: 1,
            rgb,
            hits,
            stats: Default::default(),
        };
        // Pixel 0: unchanged. 1: a crack closed (miss -> the reference's triangle). 2: a
        // silhouette grown (the reference misses). 3: a tie at an edge (another triangle at the
        // same distance: changed, neither fixed nor broken). 4: same hit, other colour.
        let reference = frame(
            vec![hit(1, 2.0), hit(2, 3.0), None, hit(4, 5.0), hit(5, 1.0)],
            vec![0; 5],
        );
        let exact = frame(
            vec![hit(1, 2.0), None, None, hit(4, 5.0), hit(5, 1.0)],
            vec![0, 0, 0, 7, 0],
        );
        let with = frame(
            vec![
                hit(1, 2.0),
                hit(2, 3.0),
                hit(3, 4.0),
                hit(6, 5.0),
                hit(5, 1.0),
            ],
            vec![0, 9, 9, 7, 1],
        );
        let c = MarginChanges::measure(&with, &exact, &reference);
        assert_eq!(
            c,
            MarginChanges {
                changed_pixels: 3,
                changed_hits: 3,
                fixed_hits: 1,
                broken_hits: 1
            }
        );
    }

    #[test]
    fn a_mesh_given_by_a_relative_path_is_framed() {
        // Tests run in the crate root; the framed scene is parsed relative to a temp dir.
        let dir = tempfile::tempdir().unwrap();
        let c = SweepConfig::new(Path::new("scenes")).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let s = mesh_subject(
            dir.path(),
            Path::new("scenes/meshes/pyramid.obj"),
            &c,
            &mut rng,
        )
        .unwrap_or_else(|e| panic!("{e:#}"));
        assert_eq!(s.name, "pyramid");
        assert!(s.scene.triangle_count() > 0);
    }

    #[test]
    fn a_small_sweep_measures_a_bundled_scene_and_writes_csv_and_plots() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let dir = tempfile::tempdir().unwrap();
        let mut c = SweepConfig::new(&root.join("scenes")).unwrap();
        c.scenes = vec![root.join("scenes/cornell.toml")];
        c.formats = vec![Format::parse("e5m10").unwrap(), Format::E8M23];
        c.width = 32;
        c.height = 24;
        c.synthesize = false;
        c.cost_csv = dir.path().join("none.csv");
        crate::progress::seen_in_tests();
        let rows = precision_sweep(&c, &mut |_| {}).unwrap();
        assert_eq!(rows.len(), 2);
        // Each scene and format is a step of the progress display, counted against the total.
        let seen = crate::progress::seen_in_tests();
        for want in [
            "step 0/2: cornell e5m10",
            "step 1/2: cornell e8m23",
            "step 2/2: done",
        ] {
            assert!(seen.iter().any(|l| l == want), "no `{want}` in {seen:?}");
        }
        let (narrow, wide) = (&rows[0], &rows[1]);
        assert!(wide.equivalent_hit_ratio > 0.99, "{wide:?}");
        assert!(
            wide.psnr_db > narrow.psnr_db,
            "e8m23 must beat e5m10: {wide:?} {narrow:?}"
        );
        assert!(wide.golden_seconds > 0.0 && wide.datapath.is_none());
        // The hardware's margin by default, measured against the exact test.
        assert_eq!(c.edge_margin_ulps, f64::from(units::EDGE_MARGIN_ULPS));
        let changes = wide.margin_changes.expect("margin changes are measured");
        assert!(changes.changed_hits * 50 <= wide.pixels, "{changes:?}");
        assert!(changes.fixed_hits + changes.broken_hits <= changes.changed_hits);
        // Without costs there is no LUT plot, but the CSVs and the run-time plot are written.
        let written = write_outputs(&rows, dir.path()).unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                "precision.csv",
                "precision_summary.csv",
                "mismatch_vs_time.png"
            ]
        );
    }
}
