//! Build-rate benchmark of the acceleration structures (a measurement, never a test):
//! object-tree build rate (triangles per second) on a mesh file (default: the Stanford bunny of
//! the shared mesh folder) and on a generated terrain heightfield, and top-level rebuild time
//! for random instance boxes (default 1,000 and the paper's SunCOR, 5,622); plus single-thread
//! closest-hit traversal speed on the mesh (the f64 reference's kernel). Prints a table and
//! writes a CSV.
//!
//! So that speed is not bought with a worse tree, every row carries the tree's SAH cost and its
//! traversal statistics: nodes visited and primitives tested per ray, for seeded random rays
//! from around the tree's box towards points inside it ([`random_rays_at`]), closest hit. An
//! object tree's primitives are its triangles; a top level's are its instance boxes, each hit
//! where the ray enters it (the stand-in for the instance's object).
//!
//! Also holds two small geometry sources used by the benchmark and the tests:
//! [`load_obj_triangles`] (positions only, polygons triangulated) and
//! [`heightfield_triangles`].

use super::aabb::Aabb;
use super::kd_traversal::TraversalCounts;
use super::kd_tree::{build_sah, build_sah_boxes, KdParams, KdStats, KdTree};
use super::ray::Ray;
use anyhow::{bail, Context};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Triangles of an OBJ file, in file order (faces triangulated as fans by tobj), all groups.
pub fn load_obj_triangles(path: &Path) -> anyhow::Result<Vec<[DVec3; 3]>> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // Through the bounded reader: a FIFO or a device named `x.obj` in a mesh folder is refused,
    // not read forever; materials are not needed here.
    let text = crate::input::read_text(path, "mesh", crate::input::MAX_MESH_BYTES)?;
    let text = crate::input::normalize_line_endings(&text);
    let (models, _materials) =
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| Ok(Default::default()))
            .with_context(|| format!("cannot read OBJ mesh {}", path.display()))?;
    let mut tris = Vec::new();
    for m in &models {
        let pos = &m.mesh.positions;
        let vertex = |i: u32| -> anyhow::Result<DVec3> {
            let i = i as usize * 3;
            if i + 2 >= pos.len() {
                bail!(
                    "{}: object {:?} refers to vertex {} but has {}",
                    path.display(),
                    m.name,
                    i / 3 + 1,
                    pos.len() / 3
                );
            }
            Ok(DVec3::new(pos[i], pos[i + 1], pos[i + 2]))
        };
        for f in m.mesh.indices.chunks_exact(3) {
            tris.push([vertex(f[0])?, vertex(f[1])?, vertex(f[2])?]);
        }
    }
    Ok(tris)
}

/// A seeded terrain: `side x side` quads (2 triangles each) over `[0, side]^2` in x/z with
/// heights from a few sine octaves plus noise.
pub fn heightfield_triangles(side: usize, seed: u64) -> Vec<[DVec3; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = side + 1;
    let waves: Vec<(f64, f64, f64, f64)> = (0..6)
        .map(|o| {
            let f = 2f64.powi(o) * 0.02;
            (
                rng.gen_range(0.5..1.5) * f,
                rng.gen_range(0.5..1.5) * f,
                rng.gen_range(0.0..6.3),
                side as f64 * 0.05 / 2f64.powi(o),
            )
        })
        .collect();
    let mut h = vec![0.0; n * n];
    for z in 0..n {
        for x in 0..n {
            let mut y = rng.gen_range(-0.05..0.05);
            for &(fx, fz, ph, amp) in &waves {
                y += amp * (fx * x as f64 + ph).sin() * (fz * z as f64 - ph).cos();
            }
            h[z * n + x] = y;
        }
    }
    let p = |x: usize, z: usize| DVec3::new(x as f64, h[z * n + x], z as f64);
    let mut tris = Vec::with_capacity(2 * side * side);
    for z in 0..side {
        for x in 0..side {
            tris.push([p(x, z), p(x + 1, z), p(x + 1, z + 1)]);
            tris.push([p(x, z), p(x + 1, z + 1), p(x, z + 1)]);
        }
    }
    tris
}

/// `count` random boxes in a cube of side 200 with edges 1..8 (instances of a dynamic scene).
pub fn random_instance_boxes(count: usize, seed: u64) -> Vec<Aabb> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let c = DVec3::new(
                rng.gen_range(-100.0..100.0),
                rng.gen_range(-100.0..100.0),
                rng.gen_range(-100.0..100.0),
            );
            let e = DVec3::new(
                rng.gen_range(0.5..4.0),
                rng.gen_range(0.5..4.0),
                rng.gen_range(0.5..4.0),
            );
            Aabb::new(c - e, c + e)
        })
        .collect()
}

/// `count` rays from random points on a sphere around `b` towards random points inside it.
pub fn random_rays_at(b: &Aabb, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let radius = b.extent().length();
    (0..count)
        .map(|_| {
            let dir = loop {
                let d = DVec3::new(
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                );
                let l = d.length();
                if l > 1e-3 && l <= 1.0 {
                    break d / l;
                }
            };
            let origin = b.center() + dir * radius;
            let target = b.min + b.extent() * DVec3::new(rng.gen(), rng.gen(), rng.gen());
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    /// Mesh measured as-is (default: the Stanford bunny of [`crate::scene::shared_mesh_dir`]).
    pub mesh: PathBuf,
    /// Terrain quads per side (2 side² triangles; default 256 -> 131,072 triangles).
    pub terrain_side: usize,
    /// Instance counts for the top-level rebuild.
    pub instance_counts: Vec<usize>,
    /// Rays traced against the mesh's tree for the traversal-speed row.
    pub trace_rays: usize,
    /// Rays per tree for the traversal statistics of each row.
    pub stats_rays: usize,
    /// Each case is built this many times; the fastest run is reported.
    pub repeats: usize,
    pub params: KdParams,
    pub out_csv: PathBuf,
}

impl Default for BenchConfig {
    fn default() -> Self {
        Self {
            mesh: crate::scene::shared_mesh_dir().join("stanford-bunny.obj"),
            terrain_side: 256,
            instance_counts: vec![1000, 5622],
            trace_rays: 200_000,
            stats_rays: 20_000,
            repeats: 3,
            params: KdParams::default(),
            out_csv: PathBuf::from("out/bench/accel.csv"),
        }
    }
}

/// One measured case: a build (items = primitives) or a trace (items = rays, closest hit,
/// one thread).
#[derive(Clone, Debug)]
pub struct BenchRow {
    pub case: String,
    /// "build" or "trace".
    pub kind: &'static str,
    pub items: usize,
    /// Fastest run, seconds.
    pub seconds: f64,
    pub items_per_second: f64,
    /// Stats of the tree built or traced.
    pub stats: KdStats,
    /// Its traversal statistics (`BenchConfig::stats_rays` rays, closest hit).
    pub counts: TraversalCounts,
}

/// Traversal statistics of `tree` for `count` seeded rays (see the module doc); `test(prim,
/// ray, t_best)` is where the ray hits a primitive.
fn traversal_counts(
    tree: &KdTree,
    count: usize,
    test: impl Fn(u32, &Ray, f64) -> Option<f64>,
) -> TraversalCounts {
    let mut counts = TraversalCounts::default();
    for ray in random_rays_at(&tree.bounds, count, 3) {
        tree.closest_hit_counted(&ray, 0.0, f64::INFINITY, &mut counts, |p, t_best| {
            test(p, &ray, t_best).map(|t| (t, ()))
        });
    }
    counts
}

/// Traversal statistics of an object tree over `tris`.
fn triangle_counts(tree: &KdTree, tris: &[[DVec3; 3]], count: usize) -> TraversalCounts {
    traversal_counts(tree, count, |p, ray, t_best| {
        super::triangle::intersect(ray, &tris[p as usize], 0.0, t_best).map(|(t, _, _)| t)
    })
}

/// Traversal statistics of a top level over `boxes`.
fn box_counts(tree: &KdTree, boxes: &[Aabb], count: usize) -> TraversalCounts {
    traversal_counts(tree, count, |p, ray, t_best| {
        ray.intersect_aabb(&boxes[p as usize], 0.0, t_best)
            .map(|(t, _)| t)
    })
}

/// The fastest of `repeats` runs of `run` (at least one), seconds, and the last run's result.
fn fastest<T>(repeats: usize, run: &dyn Fn() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut result = None;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        let r = run();
        best = best.min(t.elapsed().as_secs_f64());
        result = Some(r);
    }
    (best, result.expect("at least one run"))
}

/// Runs the benchmark, prints a table and writes `cfg.out_csv` (atomically: a temporary file
/// renamed into place, so a failed run leaves no partial CSV).
pub fn bench_build(cfg: &BenchConfig) -> anyhow::Result<Vec<BenchRow>> {
    let mesh = load_obj_triangles(&cfg.mesh)?;
    let terrain = heightfield_triangles(cfg.terrain_side, 1);
    let mut rows = Vec::new();
    // Times `build` (fastest of `cfg.repeats`); the tree of its last run gives the stats and,
    // through `count`, the traversal statistics.
    let mut measure = |case: String,
                       n: usize,
                       build: &dyn Fn() -> KdTree,
                       count: &dyn Fn(&KdTree) -> TraversalCounts| {
        let (seconds, tree) = fastest(cfg.repeats, build);
        rows.push(BenchRow {
            case,
            kind: "build",
            items: n,
            seconds,
            items_per_second: n as f64 / seconds,
            stats: tree.stats(&cfg.params),
            counts: count(&tree),
        });
    };
    let p = &cfg.params;
    let mesh_name = cfg
        .mesh
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into());
    let mesh_counts = |t: &KdTree| triangle_counts(t, &mesh, cfg.stats_rays);
    measure(
        format!("object {mesh_name}"),
        mesh.len(),
        &|| build_sah(&mesh, p),
        &mesh_counts,
    );
    let unclipped = KdParams {
        clip_splits: false,
        ..p.clone()
    };
    measure(
        format!("object {mesh_name} no-clip"),
        mesh.len(),
        &|| build_sah(&mesh, &unclipped),
        &mesh_counts,
    );
    measure(
        format!("object terrain {0}x{0}", cfg.terrain_side),
        terrain.len(),
        &|| build_sah(&terrain, p),
        &|t| triangle_counts(t, &terrain, cfg.stats_rays),
    );
    for &count in &cfg.instance_counts {
        let boxes = random_instance_boxes(count, 2);
        measure(
            format!("top-level {count} instances"),
            count,
            &|| build_sah_boxes(&boxes, p),
            &|t| box_counts(t, &boxes, cfg.stats_rays),
        );
    }
    // Reference traversal speed: random rays from around the mesh towards points inside it.
    let tree = build_sah(&mesh, p);
    let rays = random_rays_at(&tree.bounds, cfg.trace_rays, 3);
    let (seconds, hits) = fastest(cfg.repeats, &|| {
        rays.iter()
            .filter(|r| {
                tree.closest_triangle_hit(&mesh, r, 0.0, f64::INFINITY)
                    .is_some()
            })
            .count()
    });
    std::hint::black_box(hits);
    rows.push(BenchRow {
        case: format!("trace {mesh_name} closest hit"),
        kind: "trace",
        items: rays.len(),
        seconds,
        items_per_second: rays.len() as f64 / seconds,
        stats: tree.stats(p),
        counts: mesh_counts(&tree),
    });

    println!(
        "{:<33} {:>9} {:>10} {:>14} {:>8} {:>8} {:>6} {:>9} {:>8} {:>10} {:>10}",
        "case",
        "items",
        "ms",
        "items/s",
        "nodes",
        "refs",
        "depth",
        "sah",
        "tris/lf",
        "nodes/ray",
        "tests/ray"
    );
    for r in &rows {
        println!(
            "{:<33} {:>9} {:>10.2} {:>14.0} {:>8} {:>8} {:>6} {:>9.2} {:>8.2} {:>10.2} {:>10.2}",
            r.case,
            r.items,
            r.seconds * 1e3,
            r.items_per_second,
            r.stats.nodes,
            r.stats.references,
            r.stats.depth,
            r.stats.sah_cost,
            r.stats.mean_tris_per_leaf,
            r.counts.nodes_per_ray(),
            r.counts.tests_per_ray()
        );
    }
    write_csv(&cfg.out_csv, &rows)?;
    println!("wrote {}", cfg.out_csv.display());
    Ok(rows)
}

fn write_csv(path: &Path, rows: &[BenchRow]) -> anyhow::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let header = [
        "case",
        "kind",
        "items",
        "seconds",
        "items_per_second",
        "nodes",
        "leaves",
        "empty_leaves",
        "references",
        "depth",
        "sah_cost",
        "max_prims_per_leaf",
        "mean_prims_per_leaf",
        "rays",
        "nodes_per_ray",
        "tests_per_ray",
    ];
    let lines: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let s = &r.stats;
            vec![
                r.case.to_string(),
                r.kind.to_string(),
                r.items.to_string(),
                format!("{:.6}", r.seconds),
                format!("{:.0}", r.items_per_second),
                s.nodes.to_string(),
                s.leaves.to_string(),
                s.empty_leaves.to_string(),
                s.references.to_string(),
                s.depth.to_string(),
                format!("{:.4}", s.sah_cost),
                s.max_tris_per_leaf.to_string(),
                format!("{:.3}", s.mean_tris_per_leaf),
                r.counts.rays.to_string(),
                format!("{:.3}", r.counts.nodes_per_ray()),
                format!("{:.3}", r.counts.tests_per_ray()),
            ]
        })
        .collect();
    crate::output::write_atomically(path, crate::tables::csv_text(&header, &lines).as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}
