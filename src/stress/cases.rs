//! The stress cases. Each builds its scene once, draws its rays once from the seeded generator
//! (so every format sees the same rays), then counts failures per format and for the exact f64
//! caster.
//!
//! A failure is always something exact arithmetic can prove wrong:
//! - a ray from inside a closed mesh, or from outside aimed at an interior point of a convex
//!   mesh, that hits nothing (a leak);
//! - a shadow or mirror ray leaving a convex mesh that hits the mesh itself (acne: a convex
//!   body lies behind the plane of each of its faces, so nothing can be hit);
//! - a pixel of an inside camera that sees nothing, or a shaded colour that is NaN or infinite.

use super::geometry::{self, ExactCaster, TestScene, Tris};
use super::{CaseResult, Limit, StressConfig};
use crate::fp::Format;
use crate::layout::{self, FrameMap, Layout, MemoryConfig, SceneTrees, FRAME};
use crate::model::units::{self, Vec3W};
use crate::model::{Golden, Reference};
use crate::scene::Scene;
use anyhow::Result;
use glam::{DAffine3, DQuat, DVec3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::path::Path;

/// A scene plus its world-space triangles.
pub struct Subject {
    pub name: String,
    pub scene: Scene,
    pub world: Tris,
}

impl Subject {
    pub fn new(dir: &Path, name: &str, tris: &[[DVec3; 3]], s: &TestScene) -> Result<Subject> {
        let scene = geometry::write_scene(dir, name, tris, s)?;
        let world = geometry::world_triangles(&scene);
        Ok(Subject {
            name: name.into(),
            scene,
            world,
        })
    }
}

/// What a case does with its rays.
pub enum Check {
    /// Every ray must hit something.
    MustHit,
    /// Primary rays from outside a convex mesh; the shadow ray (towards the light) of every
    /// lit hit must be free.
    ShadowAcne { light: DVec3 },
    /// Primary rays from outside a convex mesh; every mirror ray must leave it.
    MirrorAcne,
}

/// A set of rays through one subject.
pub struct RayCase {
    pub name: String,
    pub subject: Subject,
    pub rays: Vec<(DVec3, DVec3)>,
    pub check: Check,
    pub limit: Limit,
}

/// Builds the layout of a subject in a format; an error (e.g. a scene the format cannot hold)
/// is returned as text for the table.
pub fn layout_for(scene: &Scene, f: Format) -> std::result::Result<Layout, String> {
    let trees = SceneTrees::build(scene, f).map_err(|e| e.to_string())?;
    layout::build(scene, &trees, 0, &MemoryConfig::default()).map_err(|e| e.to_string())
}

fn w3(f: Format, v: DVec3) -> Vec3W {
    v.to_array().map(|c| f.from_f64(c))
}

/// Runs a ray case in one format (`None` = exact f64) and returns (rays checked, failures).
/// `margin_ulps` is the edge margin in units of 2^-mantissa bits (see [`margin_for`]).
pub fn run_ray_case(
    case: &RayCase,
    format: Option<Format>,
    margin_ulps: f64,
) -> std::result::Result<(u64, u64), String> {
    match format {
        None => Ok(run_exact(case, margin_ulps)),
        Some(f) => {
            let layout = layout_for(&case.subject.scene, f)?;
            let golden = Golden::with_edge_margin(&layout, margin_for(f, margin_ulps));
            Ok(run_golden(case, &golden))
        }
    }
}

/// The absolute edge margin of `ulps` units of a format's spacing at 1 (2^-man_bits).
pub fn margin_for(f: Format, ulps: f64) -> f64 {
    ulps * 2f64.powi(-(f.man_bits as i32))
}

fn run_exact(case: &RayCase, margin_ulps: f64) -> (u64, u64) {
    let caster = ExactCaster::with_margin(&case.subject.world, geometry::f64_margin(margin_ulps));
    let results: Vec<(u64, u64)> = case
        .rays
        .par_iter()
        .map(|&(o, d)| match &case.check {
            Check::MustHit => (1, u64::from(caster.closest(o, d, 0.0).is_none())),
            Check::ShadowAcne { light } => {
                let Some((tri, t)) = caster.closest(o, d, 0.0) else {
                    return (0, 0);
                };
                let p = o + d * t;
                let n = facing_normal(&case.subject.world[tri as usize], d);
                let to_light = *light - p;
                if n.dot(to_light) <= 0.0 {
                    return (0, 0);
                }
                let blocked = caster
                    .closest_skipping(p, to_light, 1e-6, Some(tri))
                    .is_some_and(|(_, t)| t < 1.0);
                (1, u64::from(blocked))
            }
            Check::MirrorAcne => {
                let Some((tri, t)) = caster.closest(o, d, 0.0) else {
                    return (0, 0);
                };
                let p = o + d * t;
                let n = facing_normal(&case.subject.world[tri as usize], d);
                let r = d - n * (2.0 * d.dot(n));
                let hit = caster.closest_skipping(p, r, 1e-6, Some(tri)).is_some();
                (1, u64::from(hit))
            }
        })
        .collect();
    sum(&results)
}

fn facing_normal(t: &[DVec3; 3], d: DVec3) -> DVec3 {
    let n = (t[0] - t[2]).cross(t[1] - t[2]).normalize();
    if n.dot(d) > 0.0 {
        -n
    } else {
        n
    }
}

fn sum(v: &[(u64, u64)]) -> (u64, u64) {
    v.iter().fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// The golden model's rays, secondary rays set up exactly as its shader does.
fn run_golden(case: &RayCase, golden: &Golden) -> (u64, u64) {
    let l = golden.layout();
    let f = l.format;
    let inf = f.infinity(false);
    // The cases' points are in the world; the layout's coordinates start at its origin.
    let origin = DVec3::from_array(l.info.origin);
    let results: Vec<(u64, u64)> = case
        .rays
        .par_iter()
        .map(|&(o, d)| {
            let (o, d) = (w3(f, o - origin), w3(f, d));
            let primary = golden.trace_ray(o, d, 0, inf, None, false).hit;
            match &case.check {
                Check::MustHit => (1, u64::from(primary.is_none())),
                Check::ShadowAcne { light } => {
                    let Some(hit) = primary else { return (0, 0) };
                    let (p, n) = surface(golden, o, d, hit);
                    let to_light = units::sub3(f, w3(f, *light - origin), p);
                    if units::lambert_cosine(f, n, to_light).is_none() {
                        return (0, 0);
                    }
                    let t_min = l.word(FRAME, FrameMap::SHADOW_T_MIN as u32);
                    let skip = Some((hit.instance, hit.triangle));
                    let shadow = golden.trace_ray(p, to_light, t_min, f.one(), skip, true);
                    (1, u64::from(shadow.hit.is_some()))
                }
                Check::MirrorAcne => {
                    let Some(hit) = primary else { return (0, 0) };
                    let (p, n) = surface(golden, o, d, hit);
                    let r = units::reflect(f, d, n);
                    let t_min = l.word(FRAME, FrameMap::MIRROR_T_MIN as u32);
                    let skip = Some((hit.instance, hit.triangle));
                    let bounce = golden.trace_ray(p, r, t_min, inf, skip, false);
                    (1, u64::from(bounce.hit.is_some()))
                }
            }
        })
        .collect();
    sum(&results)
}

/// Hit point and facing unit normal as the golden shader computes them (untransformed
/// subjects only: the acne cases place their mesh without an instance).
fn surface(golden: &Golden, o: Vec3W, d: Vec3W, hit: crate::model::golden::Hit) -> (Vec3W, Vec3W) {
    let f = golden.layout().format;
    let p = units::ray_point(f, o, d, hit.t);
    let (n_obj, _) = golden.layout().triangle_shading(hit.triangle);
    (
        p,
        units::facing_normal(f, units::world_normal(f, n_obj, None), d),
    )
}

/// Renders the subject's camera with the golden model: (pixels, pixels that hit nothing,
/// pixels whose shaded colour has a NaN or infinite channel).
pub fn render_check(golden: &Golden) -> (u64, u64, u64) {
    let l = golden.layout();
    let f = l.format;
    let (w, h) = (l.info.width, l.info.height);
    let v: Vec<(u64, u64)> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let p = golden.pixel(i % w, i / w);
            let bad = p.color.iter().any(|&c| f.is_nan(c) || f.is_inf(c));
            (u64::from(p.hit.is_none()), u64::from(bad))
        })
        .collect();
    let (miss, bad) = sum(&v);
    (u64::from(w * h), miss, bad)
}

/// (pixels, misses) of the f64 reference for the same camera.
pub fn reference_misses(scene: &Scene) -> (u64, u64) {
    let frame = Reference::new(scene).render(0);
    let miss = frame.hits.iter().filter(|h| h.is_none()).count() as u64;
    (frame.hits.len() as u64, miss)
}

// ---- ray generators -------------------------------------------------------------------

/// Rays from points inside a closed mesh towards its vertices, edge midpoints and random edge
/// points (the places where two unit-triangle tests must agree).
pub fn edge_rays(world: &[[DVec3; 3]], n: usize, rng: &mut ChaCha8Rng) -> Vec<(DVec3, DVec3)> {
    let origins = geometry::inside_points(world, 8, rng);
    if origins.is_empty() {
        return vec![];
    }
    (0..n)
        .map(|i| {
            let o = origins[i % origins.len()];
            (o, geometry::edge_target(world, i, rng) - o)
        })
        .collect()
}

/// Rays from outside aimed at random interior points of a convex mesh (from a sphere of
/// radius 3x the mesh's size around its centre).
pub fn interior_rays(world: &[[DVec3; 3]], n: usize, rng: &mut ChaCha8Rng) -> Vec<(DVec3, DVec3)> {
    let (lo, hi) = geometry::bounds(world);
    let (c, size) = ((lo + hi) * 0.5, (hi - lo).max_element());
    (0..n)
        .map(|_| {
            // A random convex combination of a triangle's points is inside the convex hull.
            let t = &world[rng.gen_range(0..world.len())];
            let u = &world[rng.gen_range(0..world.len())];
            let a: f64 = rng.gen_range(0.05..0.95);
            let target = (t[0] + t[1] + t[2]) / 3.0 * a + (u[0] + u[1] + u[2]) / 3.0 * (1.0 - a);
            let o = c + geometry::random_direction(rng) * (3.0 * size);
            (o, target - o)
        })
        .collect()
}

/// Rays along the axes and inside the coordinate planes (zero direction components), from
/// inside points moved exactly onto the kd split planes of the subject's e8m23 layout.
pub fn axis_rays(subject: &Subject, n: usize, rng: &mut ChaCha8Rng) -> Vec<(DVec3, DVec3)> {
    let origins = geometry::inside_points(&subject.world, 8, rng);
    let splits: Vec<(usize, f64)> = match layout_for(&subject.scene, Format::E8M23) {
        Ok(l) => (0..(l.banks[layout::NODES].len() / layout::NODE_WORDS) as u32)
            .filter_map(|i| match l.node(i) {
                layout::Node::Inner { axis, split, .. } => {
                    Some((axis, Format::E8M23.to_f64(split)))
                }
                _ => None,
            })
            .collect(),
        Err(_) => vec![],
    };
    let mut out = Vec::new();
    if origins.is_empty() {
        return out;
    }
    let mut tries = 0;
    while out.len() < n && tries < 50 * n {
        tries += 1;
        let mut o = origins[rng.gen_range(0..origins.len())];
        if !splits.is_empty() && rng.gen_bool(0.7) {
            let (axis, split) = splits[rng.gen_range(0..splits.len())];
            let mut moved = o;
            moved[axis] = split;
            if geometry::is_inside(&subject.world, moved, rng) {
                o = moved;
            }
        }
        let axis = rng.gen_range(0..3);
        let mut d = DVec3::ZERO;
        d[axis] = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
        if rng.gen_bool(0.5) {
            // In a coordinate plane: one zero component.
            let other = (axis + 1 + rng.gen_range(0..2)) % 3;
            d[other] = rng.gen_range(-1.0..1.0);
        }
        out.push((o, d));
    }
    out
}

/// Nearly tangent rays: aimed from outside at points just below the surface of a convex mesh
/// (depth 1e-3 of its size), at 0.5..5 degrees to the face.
pub fn grazing_rays(world: &[[DVec3; 3]], n: usize, rng: &mut ChaCha8Rng) -> Vec<(DVec3, DVec3)> {
    let (lo, hi) = geometry::bounds(world);
    let size = (hi - lo).max_element();
    (0..n)
        .map(|_| {
            let t = &world[rng.gen_range(0..world.len())];
            let (mut a, mut b): (f64, f64) = (rng.gen(), rng.gen());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let q = t[2] + (t[0] - t[2]) * a + (t[1] - t[2]) * b;
            let n = (t[0] - t[2]).cross(t[1] - t[2]).normalize();
            let target = q - n * (1e-3 * size);
            let tangent = (geometry::random_direction(rng).cross(n)).normalize();
            let angle = rng.gen_range(0.5f64..5.0).to_radians();
            let d = tangent * angle.cos() - n * angle.sin();
            (target - d * (2.0 * size), d)
        })
        .collect()
}

/// Primary rays from a camera position outside a convex mesh at random points of its surface.
pub fn surface_rays(
    world: &[[DVec3; 3]],
    eye: DVec3,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<(DVec3, DVec3)> {
    (0..n)
        .map(|_| {
            let t = &world[rng.gen_range(0..world.len())];
            let (mut a, mut b): (f64, f64) = (rng.gen(), rng.gen());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            let q = t[2] + (t[0] - t[2]) * a + (t[1] - t[2]) * b;
            (eye, q - eye)
        })
        .collect()
}

/// The affine map used by the instanced variants (rotation, non-uniform scale, offset).
pub const INSTANCE: ([f64; 3], [f64; 3], [f64; 3]) =
    ([0.3, -0.2, 0.1], [30.0, 45.0, 10.0], [0.8, 1.1, 0.9]);

/// A mesh scaled by `s` and moved by `t` (baked into the vertices).
pub fn placed(tris: &[[DVec3; 3]], s: DVec3, t: DVec3) -> Tris {
    geometry::transformed(
        tris,
        &DAffine3::from_scale_rotation_translation(s, DQuat::IDENTITY, t),
    )
}

/// Rows for one ray case across formats and edge margins (the exact caster once).
pub fn ray_case_rows(case: &RayCase, config: &StressConfig) -> Vec<CaseResult> {
    runs(config)
        .into_iter()
        .map(|(f, margin)| {
            let mut row = CaseResult::new(&case.name, &case.subject.name, f, margin, case.limit);
            match run_ray_case(case, f, margin) {
                Ok((rays, failures)) => {
                    row.rays = rays;
                    row.failures = failures;
                }
                Err(e) => row.note = format!("refused: {e}"),
            }
            row.finish()
        })
        .collect()
}

/// (format, margin) pairs of a run: the exact caster once, then every format at every margin.
fn runs(config: &StressConfig) -> Vec<(Option<Format>, f64)> {
    let mut v = vec![(None, 0.0)];
    for &f in &config.formats {
        for &m in &config.edge_margins {
            v.push((Some(f), m));
        }
    }
    v
}

/// Rows for several cameras inside a closed mesh, summed into one row per format and margin:
/// every pixel must hit, no colour may be NaN/inf. `cameras` are (eye, look_at) pairs placed
/// into the subject's scene (its resolution and settings are kept); the kd-trees are built once
/// per format, as they do not depend on the camera.
pub fn inside_camera_rows(
    subject: &Subject,
    cameras: &[(DVec3, DVec3)],
    config: &StressConfig,
    case: &str,
    limit: Limit,
) -> Vec<CaseResult> {
    let scenes: Vec<Scene> = cameras
        .iter()
        .map(|&(eye, look_at)| {
            let mut s = subject.scene.clone();
            s.camera.eye = eye;
            s.camera.look_at = look_at;
            s
        })
        .collect();
    let mut trees: Option<(Format, std::result::Result<SceneTrees, String>)> = None;
    runs(config)
        .into_iter()
        .map(|(f, margin)| {
            let mut row = CaseResult::new(case, &subject.name, f, margin, limit);
            let Some(f) = f else {
                for s in &scenes {
                    let (px, miss) = reference_misses(s);
                    row.rays += px;
                    row.failures += miss;
                }
                return row.finish();
            };
            if trees.as_ref().is_none_or(|(g, _)| *g != f) {
                let built = SceneTrees::build(&subject.scene, f).map_err(|e| e.to_string());
                trees = Some((f, built));
            }
            let Some((_, Ok(t))) = &trees else {
                if let Some((_, Err(e))) = &trees {
                    row.note = format!("refused: {e}");
                }
                return row.finish();
            };
            for s in &scenes {
                match layout::build(s, t, 0, &MemoryConfig::default()) {
                    Ok(l) => {
                        let g = Golden::with_edge_margin(&l, margin_for(f, margin));
                        let (px, miss, bad) = render_check(&g);
                        row.rays += px;
                        row.failures += miss;
                        row.nonfinite += bad;
                    }
                    Err(e) => {
                        row.note = format!("refused: {e}");
                        break;
                    }
                }
            }
            row.finish()
        })
        .collect()
}

/// Rows for a camera inside a closed mesh: every pixel must hit, no colour may be NaN/inf.
pub fn camera_rows(
    subject: &Subject,
    config: &StressConfig,
    case: &str,
    limit: Limit,
) -> Vec<CaseResult> {
    runs(config)
        .into_iter()
        .map(|(f, margin)| {
            let mut row = CaseResult::new(case, &subject.name, f, margin, limit);
            match f {
                None => {
                    (row.rays, row.failures) = reference_misses(&subject.scene);
                }
                Some(f) => match layout_for(&subject.scene, f) {
                    Ok(l) => {
                        let g = Golden::with_edge_margin(&l, margin_for(f, margin));
                        let (px, miss, bad) = render_check(&g);
                        (row.rays, row.failures, row.nonfinite) = (px, miss, bad);
                    }
                    Err(e) => row.note = format!("refused: {e}"),
                },
            }
            row.finish()
        })
        .collect()
}
