//! Geometry for the stress cases: closed-mesh checks, points inside a closed mesh, points on
//! its shared edges and vertices, an exact f64 ray caster, and test scenes written to a
//! temporary directory (OBJ + TOML) so they go through the same loader as user scenes.

use crate::accel::kd_tree::{self, KdParams, KdTree};
use crate::accel::{triangle, Ray};
use crate::scene::Scene;
use anyhow::{Context, Result};
use glam::{DAffine3, DVec3};
use rand::Rng;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

/// The f64 caster's margin: 2^-32 in barycentric coordinates whatever the formats use. The
/// yardstick must not leak on exact-edge rays, and Möller-Trumbore's rounding error in u, v
/// grows with the ray's distance over the triangle's size (measured: a margin of 16 * 2^-52
/// still leaks 1000-3000 edge-aimed rays per million on the 6k-20k-triangle public meshes);
/// 2^-32 covers ratios up to about 2^16 and moves silhouettes by nothing a pixel can show.
pub fn f64_margin(_ulps: f64) -> f64 {
    2f64.powi(-32)
}

/// World-space triangles of a test object.
pub type Tris = Vec<[DVec3; 3]>;

/// True when every edge (vertices identified by exact position) is shared by exactly two
/// triangles: a closed 2-manifold surface, which every ray from inside must hit.
pub fn is_closed(tris: &[[DVec3; 3]]) -> bool {
    if tris.is_empty() {
        return false;
    }
    let key = |v: DVec3| v.to_array().map(f64::to_bits);
    let mut edges: HashMap<([u64; 3], [u64; 3]), u32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
            if a == b {
                return false;
            }
            *edges
                .entry(if a < b { (a, b) } else { (b, a) })
                .or_default() += 1;
        }
    }
    edges.values().all(|&n| n == 2)
}

/// The number of triangles a ray from `o` along `d` crosses at t > 0 (brute force, f64).
fn crossings(tris: &[[DVec3; 3]], o: DVec3, d: DVec3) -> usize {
    let ray = Ray::new(o, d);
    tris.iter()
        .filter(|t| triangle::intersect(&ray, t, 1e-12, f64::INFINITY).is_some())
        .count()
}

/// True when `p` is inside the closed mesh: an odd number of crossings along three random
/// directions (all three must agree, so a ray through an edge cannot fool the test).
pub fn is_inside(tris: &[[DVec3; 3]], p: DVec3, rng: &mut impl Rng) -> bool {
    (0..3).all(|_| crossings(tris, p, random_direction(rng)) % 2 == 1)
}

/// Up to `n` points well inside a closed mesh: the bounding-box centre if inside, then random
/// points of the box that are inside and at least `clearance` (a fraction of the box size)
/// away from every vertex.
pub fn inside_points(tris: &[[DVec3; 3]], n: usize, rng: &mut impl Rng) -> Vec<DVec3> {
    let (lo, hi) = bounds(tris);
    let size = (hi - lo).max_element();
    let clearance = 0.02 * size;
    let far_from_vertices = |p: DVec3| tris.iter().flatten().all(|v| (*v - p).length() > clearance);
    let mut out = Vec::new();
    let centre = (lo + hi) * 0.5;
    if is_inside(tris, centre, rng) && far_from_vertices(centre) {
        out.push(centre);
    }
    let mut tries = 0;
    while out.len() < n && tries < 200 * n {
        tries += 1;
        let p = lo + (hi - lo) * DVec3::new(rng.gen(), rng.gen(), rng.gen());
        if far_from_vertices(p) && is_inside(tris, p, rng) {
            out.push(p);
        }
    }
    out
}

pub fn bounds(tris: &[[DVec3; 3]]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for v in tris.iter().flatten() {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    (lo, hi)
}

pub fn random_direction(rng: &mut impl Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// Where a ray is aimed on the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeTarget {
    Vertex,
    EdgeMidpoint,
    EdgePoint,
}

/// A point on a shared feature of a random triangle: a vertex, an edge midpoint, or a random
/// point of an edge (cycling through the three kinds).
pub fn edge_target(tris: &[[DVec3; 3]], i: usize, rng: &mut impl Rng) -> DVec3 {
    let t = &tris[rng.gen_range(0..tris.len())];
    let k = rng.gen_range(0..3);
    let (a, b) = (t[k], t[(k + 1) % 3]);
    match i % 3 {
        0 => a,
        1 => (a + b) * 0.5,
        _ => a + (b - a) * rng.gen::<f64>(),
    }
}

/// An f64 ray caster over world-space triangles: the yardstick ("none at f64").
///
/// Möller-Trumbore with the same kind of edge margin as the golden model's test
/// (`u, v >= -margin`, `u + v <= 1 + margin` in barycentric coordinates): without one, a ray
/// aimed exactly at a shared edge misses both triangles in about one case in ten even in f64,
/// because each triangle's rounding decides alone.
pub struct ExactCaster<'a> {
    tris: &'a [[DVec3; 3]],
    tree: KdTree,
    margin: f64,
}

/// Möller-Trumbore with an edge margin; (t, u, v) for t in [t_min, t_max).
pub fn intersect_with_margin(
    ray: &Ray,
    tri: &[DVec3; 3],
    t_min: f64,
    t_max: f64,
    margin: f64,
) -> Option<f64> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri[0];
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if !(u >= -margin && v >= -margin && u + v <= 1.0 + margin) {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t >= t_min && t < t_max).then_some(t)
}

impl<'a> ExactCaster<'a> {
    /// A caster with the default margin of [`f64_margin`].
    pub fn new(tris: &'a [[DVec3; 3]]) -> Self {
        Self::with_margin(tris, f64_margin(0.0))
    }
    pub fn with_margin(tris: &'a [[DVec3; 3]], margin: f64) -> Self {
        ExactCaster {
            tris,
            tree: kd_tree::build_sah(tris, &KdParams::default()),
            margin,
        }
    }
    /// The closest hit (triangle, t) with t in (t_min, inf).
    pub fn closest(&self, o: DVec3, d: DVec3, t_min: f64) -> Option<(u32, f64)> {
        self.closest_skipping(o, d, t_min, None)
    }
    /// The closest hit, never testing triangle `skip` (a secondary ray's own triangle).
    pub fn closest_skipping(
        &self,
        o: DVec3,
        d: DVec3,
        t_min: f64,
        skip: Option<u32>,
    ) -> Option<(u32, f64)> {
        let ray = Ray::new(o, d);
        self.tree.closest_hit(&ray, t_min, f64::INFINITY, |p, tb| {
            if Some(p) == skip {
                return None;
            }
            intersect_with_margin(&ray, &self.tris[p as usize], t_min, tb, self.margin)
        })
    }
}

/// The world-space triangles of every instance of a scene at frame 0.
pub fn world_triangles(scene: &Scene) -> Tris {
    let mut out = Vec::new();
    for inst in &scene.instances {
        let m = inst.object_to_world(0);
        out.extend(
            scene.objects[inst.object]
                .triangles
                .iter()
                .map(|t| t.map(|v| m.transform_point3(v))),
        );
    }
    out
}

/// Settings of a generated test scene.
#[derive(Clone, Debug)]
pub struct TestScene {
    pub eye: DVec3,
    pub look_at: DVec3,
    pub fov_y: f64,
    pub width: u32,
    pub height: u32,
    pub light: Option<DVec3>,
    pub shadows: bool,
    pub reflection_depth: u32,
    pub mirror: f64,
    /// Place the mesh through an instance with this (translate, rotate degrees, scale);
    /// `None` leaves it untransformed (no top-level tree).
    pub instance: Option<([f64; 3], [f64; 3], [f64; 3])>,
}

impl Default for TestScene {
    fn default() -> Self {
        TestScene {
            eye: DVec3::new(0.0, 0.0, 4.0),
            look_at: DVec3::ZERO,
            fov_y: 40.0,
            width: 32,
            height: 24,
            light: None,
            shadows: false,
            reflection_depth: 0,
            mirror: 0.0,
            instance: None,
        }
    }
}

fn fmt3(v: [f64; 3]) -> String {
    // `{:?}` prints the shortest text that reads back as the same f64.
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

/// Writes `tris` as an OBJ and a scene TOML into `dir` and loads the scene. Vertices are
/// written as the shortest text of their f64 and read back as f64, so the scene holds `tris`
/// exactly; world-space geometry is taken from the returned scene ([`world_triangles`]).
pub fn write_scene(dir: &Path, name: &str, tris: &[[DVec3; 3]], s: &TestScene) -> Result<Scene> {
    let mut obj = String::new();
    for t in tris {
        for v in t {
            writeln!(obj, "v {:?} {:?} {:?}", v.x, v.y, v.z)?;
        }
    }
    for i in 0..tris.len() {
        writeln!(obj, "f {} {} {}", 3 * i + 1, 3 * i + 2, 3 * i + 3)?;
    }
    let obj_path = dir.join(format!("{name}.obj"));
    std::fs::write(&obj_path, obj).with_context(|| format!("writing {}", obj_path.display()))?;
    let mut toml = format!(
        "[camera]\neye = {}\nlook_at = {}\nup = [0.0, 1.0, 0.0]\nfov_y = {:?}\nwidth = {}\nheight = {}\n\n\
         [render]\nshadows = {}\nreflection_depth = {}\nambient = 0.1\nbackground = [0.0, 0.0, 0.0]\n\n",
        fmt3(s.eye.to_array()),
        fmt3(s.look_at.to_array()),
        s.fov_y,
        s.width,
        s.height,
        s.shadows,
        s.reflection_depth
    );
    if let Some(l) = s.light {
        toml += &format!("[[lights]]\nposition = {}\n\n", fmt3(l.to_array()));
    }
    toml += &format!(
        "[[objects]]\nname = \"mesh\"\nmesh = {:?}\nmirror = {:?}\n\n",
        obj_path.display().to_string(),
        s.mirror
    );
    if let Some((t, r, sc)) = s.instance {
        toml += &format!(
            "[[instances]]\nobject = \"mesh\"\ntranslate = {}\nrotate = {}\nscale = {}\n",
            fmt3(t),
            fmt3(r),
            fmt3(sc)
        );
    }
    Scene::from_toml_str(&toml, dir, &format!("{name}.toml"))
        .with_context(|| format!("stress scene `{name}`"))
}

/// A subdivided icosahedron of radius 1 at the origin (the generator's sphere).
pub fn icosphere(subdivisions: u32) -> Result<Tris> {
    let toml = format!(
        "[camera]\neye = [0.0, 0.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         fov_y = 40.0\nwidth = 4\nheight = 4\n\n[[objects]]\nname = \"s\"\n\
         generate = {{ kind = \"sphere\", subdivisions = {subdivisions} }}\n"
    );
    let s = Scene::from_toml_str(&toml, Path::new("."), "icosphere.toml")?;
    Ok(s.objects[0].triangles.clone())
}

/// The 12 triangles of an axis-aligned box centred at the origin.
pub fn box_mesh(size: DVec3) -> Tris {
    let h = size * 0.5;
    let c = |x: f64, y: f64, z: f64| DVec3::new(x * h.x, y * h.y, z * h.z);
    let quads = [
        [
            c(-1., -1., -1.),
            c(-1., 1., -1.),
            c(1., 1., -1.),
            c(1., -1., -1.),
        ],
        [
            c(-1., -1., 1.),
            c(1., -1., 1.),
            c(1., 1., 1.),
            c(-1., 1., 1.),
        ],
        [
            c(-1., -1., -1.),
            c(-1., -1., 1.),
            c(-1., 1., 1.),
            c(-1., 1., -1.),
        ],
        [
            c(1., -1., -1.),
            c(1., 1., -1.),
            c(1., 1., 1.),
            c(1., -1., 1.),
        ],
        [
            c(-1., -1., -1.),
            c(1., -1., -1.),
            c(1., -1., 1.),
            c(-1., -1., 1.),
        ],
        [
            c(-1., 1., -1.),
            c(-1., 1., 1.),
            c(1., 1., 1.),
            c(1., 1., -1.),
        ],
    ];
    quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect()
}

/// Applies an affine map to every vertex.
pub fn transformed(tris: &[[DVec3; 3]], m: &DAffine3) -> Tris {
    tris.iter()
        .map(|t| t.map(|v| m.transform_point3(v)))
        .collect()
}

/// Loads an OBJ's triangles through the scene loader (no copy of the file is made).
pub fn load_mesh(path: &Path) -> Result<Tris> {
    let toml = format!(
        "[camera]\neye = [0.0, 0.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         fov_y = 40.0\nwidth = 4\nheight = 4\n\n[[objects]]\nname = \"m\"\nmesh = {:?}\n",
        path.display().to_string()
    );
    let s = Scene::from_toml_str(&toml, Path::new("."), "mesh.toml")
        .with_context(|| format!("loading {}", path.display()))?;
    Ok(s.objects[0].triangles.clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn closed_meshes_are_told_from_open_ones() {
        let b = box_mesh(DVec3::ONE);
        assert!(is_closed(&b));
        assert!(!is_closed(&b[1..]), "a box with a missing triangle is open");
        assert!(is_closed(&icosphere(2).unwrap()));
    }

    #[test]
    fn inside_points_are_inside_and_outside_points_are_not() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let b = box_mesh(DVec3::new(2.0, 1.0, 0.5));
        assert!(is_inside(&b, DVec3::new(0.9, 0.4, 0.2), &mut rng));
        assert!(!is_inside(&b, DVec3::new(1.1, 0.0, 0.0), &mut rng));
        let pts = inside_points(&b, 5, &mut rng);
        assert_eq!(pts.len(), 5);
        for p in pts {
            assert!(p.abs().cmple(DVec3::new(1.0, 0.5, 0.25)).all(), "{p}");
        }
    }

    #[test]
    fn written_scenes_load_the_same_triangles() {
        let dir = tempfile::tempdir().unwrap();
        let tris = icosphere(1).unwrap();
        let s = write_scene(dir.path(), "ball", &tris, &TestScene::default()).unwrap();
        // The OBJ loader reads f64: the scene holds the very vertices written.
        assert_eq!(s.objects[0].triangles, tris);
        assert_eq!(world_triangles(&s), tris);
        assert!(s.is_single_untransformed_object());
        let caster = ExactCaster::new(&tris);
        assert!(caster.closest(DVec3::ZERO, DVec3::X, 0.0).is_some());
        assert!(caster.closest(DVec3::splat(3.0), DVec3::X, 0.0).is_none());
    }
}
