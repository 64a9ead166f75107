//! `dynrt bench trees`: the size and quality of the kd-trees with and without the node budget
//! (`KdParams::nodes_per_prim`), per public mesh and per bundled scene: triangles, nodes, nodes
//! per triangle, SAH cost, and the f64 reference traversal's nodes visited and triangle tests
//! per ray.
//!
//! - A mesh (an OBJ of the shared mesh folder) is measured with seeded random rays from around
//!   its box towards points inside it ([`crate::accel::bench::random_rays_at`]), closest hit;
//!   its layout nodes are those of a one-object scene of it.
//! - A scene is measured with its camera's primary rays of frame 0 at its own resolution
//!   through the reference renderer's two levels ([`Reference::primary_counts`]: nodes of the
//!   top-level and object trees together); its nodes are those of its object trees (the
//!   top-level tree is rebuilt per frame), in f64 and as the layout builds them (split planes
//!   rounded into e7m16).

use super::table::Table;
use crate::accel::bench::{load_obj_triangles, random_rays_at};
use crate::accel::kd_traversal::TraversalCounts;
use crate::accel::kd_tree::{build_sah, KdParams, KdStats};
use crate::fp::Format;
use crate::layout::SceneTrees;
use crate::model::Reference;
use crate::scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Rays per mesh.
pub const MESH_RAYS: usize = 20_000;

/// One case (mesh or scene) under one set of parameters.
#[derive(Clone, Debug)]
pub struct TreeRow {
    pub case: String,
    /// "mesh" or "scene".
    pub kind: &'static str,
    /// "none" or "N per triangle".
    pub budget: String,
    pub triangles: usize,
    /// Object-tree nodes (summed over a scene's objects), f64.
    pub nodes: usize,
    /// Object-tree nodes in the layout (e7m16 split planes), or why there is no layout.
    pub layout_nodes: Result<usize, String>,
    /// SAH cost of the largest object's tree.
    pub sah_cost: f64,
    /// Deepest object tree.
    pub depth: u32,
    /// Triangle references in the leaves (summed).
    pub references: usize,
    /// Seconds to build the f64 object trees.
    pub build_seconds: f64,
    pub counts: TraversalCounts,
}

impl TreeRow {
    pub fn nodes_per_triangle(&self) -> f64 {
        self.nodes as f64 / self.triangles.max(1) as f64
    }
}

fn budget_name(p: &KdParams) -> String {
    p.nodes_per_prim
        .map_or_else(|| "none".into(), |k| format!("{k} per triangle"))
}

fn stem(path: &Path) -> String {
    path.file_stem().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// Object-tree nodes of `scene`'s layout in `format`.
fn layout_nodes(scene: &Scene, format: Format, params: &KdParams) -> Result<usize, String> {
    SceneTrees::build_with(scene, format, params)
        .map(|l| l.trees.iter().map(|t| t.nodes.len()).sum())
        .map_err(|e| e.to_string())
}

/// Measures one mesh under `params` (its layout's trees in `format`).
pub fn mesh_row(path: &Path, params: &KdParams, format: Format) -> anyhow::Result<TreeRow> {
    let tris = load_obj_triangles(path)?;
    // The scene text is parsed relative to the mesh's folder; it names the mesh absolutely.
    let abs = std::path::absolute(path)?;
    let dir = abs.parent().unwrap_or(Path::new("."));
    let toml = format!(
        "[camera]\neye = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 40.0\nwidth = 8\nheight = 6\n\n\
         [[objects]]\nname = \"mesh\"\nmesh = {:?}\n",
        abs.display().to_string()
    );
    let scene = Scene::from_toml_str(&toml, dir, "mesh.toml")?;
    let t0 = Instant::now();
    let tree = build_sah(&tris, params);
    let build_seconds = t0.elapsed().as_secs_f64();
    let s: KdStats = tree.stats(params);
    let mut counts = TraversalCounts::default();
    for ray in random_rays_at(&tree.bounds, MESH_RAYS, 3) {
        tree.closest_hit_counted(&ray, 0.0, f64::INFINITY, &mut counts, |p, tb| {
            crate::accel::triangle::intersect(&ray, &tris[p as usize], 0.0, tb)
                .map(|(t, _, _)| (t, ()))
        });
    }
    Ok(TreeRow {
        case: stem(path),
        kind: "mesh",
        budget: budget_name(params),
        triangles: tris.len(),
        nodes: s.nodes,
        layout_nodes: layout_nodes(&scene, format, params),
        sah_cost: s.sah_cost,
        depth: s.depth,
        references: s.references,
        build_seconds,
        counts,
    })
}

/// Measures one scene under `params` (the layout's trees in `format`).
pub fn scene_row(path: &Path, params: &KdParams, format: Format) -> anyhow::Result<TreeRow> {
    let scene = Scene::load(path)?;
    let t0 = Instant::now();
    let reference = Reference::with_params(&scene, params.clone());
    let build_seconds = t0.elapsed().as_secs_f64();
    let counts = reference.primary_counts(0);
    let trees = reference.trees();
    let stats: Vec<KdStats> = trees.iter().map(|t| t.stats(params)).collect();
    let largest = (0..trees.len())
        .max_by_key(|&i| trees[i].num_prims)
        .map_or(0.0, |i| stats[i].sah_cost);
    Ok(TreeRow {
        case: stem(path),
        kind: "scene",
        budget: budget_name(params),
        triangles: scene.triangle_count(),
        nodes: stats.iter().map(|s| s.nodes).sum(),
        layout_nodes: layout_nodes(&scene, format, params),
        sah_cost: largest,
        depth: stats.iter().map(|s| s.depth).max().unwrap_or(0),
        references: stats.iter().map(|s| s.references).sum(),
        build_seconds,
        counts,
    })
}

/// Every mesh of `meshes` and every scene of `scenes`, without a node budget and with the
/// default parameters.
pub fn bench_trees(meshes: &[PathBuf], scenes: &[PathBuf]) -> anyhow::Result<Vec<TreeRow>> {
    let after = KdParams::default();
    let before = KdParams {
        nodes_per_prim: None,
        ..after.clone()
    };
    let mut rows = Vec::new();
    for m in meshes {
        for p in [&before, &after] {
            rows.push(mesh_row(m, p, Format::E7M16)?);
        }
    }
    for s in scenes {
        for p in [&before, &after] {
            rows.push(scene_row(s, p, Format::E7M16)?);
        }
    }
    Ok(rows)
}

/// The OBJ files of `dir`, sorted by name.
pub fn mesh_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| anyhow::anyhow!("reading mesh directory {}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .collect();
    v.sort();
    Ok(v)
}

pub fn trees_table(rows: &[TreeRow]) -> Table {
    let mut t = Table::new(&[
        "case",
        "kind",
        "node budget",
        "triangles",
        "nodes",
        "nodes per triangle",
        "layout nodes (e7m16)",
        "SAH cost",
        "depth",
        "references per triangle",
        "rays",
        "nodes per ray",
        "triangle tests per ray",
        "build ms",
    ]);
    for r in rows {
        t.push(vec![
            r.case.clone(),
            r.kind.into(),
            r.budget.clone(),
            r.triangles.to_string(),
            r.nodes.to_string(),
            format!("{:.2}", r.nodes_per_triangle()),
            match &r.layout_nodes {
                Ok(n) => format!("{n} ({:.2})", *n as f64 / r.triangles.max(1) as f64),
                Err(e) => format!("none: {e}"),
            },
            format!("{:.2}", r.sah_cost),
            r.depth.to_string(),
            format!("{:.2}", r.references as f64 / r.triangles.max(1) as f64),
            r.counts.rays.to_string(),
            format!("{:.2}", r.counts.nodes_per_ray()),
            format!("{:.2}", r.counts.tests_per_ray()),
            format!("{:.1}", r.build_seconds * 1e3),
        ]);
    }
    t
}
