//! Test geometry and brute-force references shared by the accel tests: generated meshes
//! (subdivided sphere, triangle soup, a lattice of axis-aligned quads lying exactly on split
//! planes), the shared public meshes, ray sets that stress kd traversal, and brute-force
//! closest / any hit over all triangles.

use super::aabb::Aabb;
use super::bench::load_obj_triangles;
use super::kd_tree::{KdNode, KdTree};
use super::ray::Ray;
use super::triangle;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Icosahedron subdivided `levels` times, projected on the unit sphere (20 * 4^levels tris).
pub fn sphere(levels: u32) -> Vec<[DVec3; 3]> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[DVec3; 3]> = faces.iter().map(|f| f.map(|i| v[i])).collect();
    for _ in 0..levels {
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = ((a + b) * 0.5).normalize();
                let bc = ((b + c) * 0.5).normalize();
                let ca = ((c + a) * 0.5).normalize();
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    tris
}

/// `n` random triangles of size up to ~0.3 in the unit cube.
pub fn soup(n: usize, seed: u64) -> Vec<[DVec3; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let c = DVec3::new(rng.gen(), rng.gen(), rng.gen());
            [0; 3].map(|_| {
                c + DVec3::new(
                    rng.gen_range(-0.15..0.15),
                    rng.gen_range(-0.15..0.15),
                    rng.gen_range(-0.15..0.15),
                )
            })
        })
        .collect()
}

/// A lattice of unit quads (two triangles each) on every integer plane x = i, y = i, z = i
/// inside `[0, n]^3`, with every other quad left out so that rays get through: almost every
/// triangle lies exactly on a candidate split plane, and many share edges.
pub fn quad_lattice(n: usize) -> Vec<[DVec3; 3]> {
    let mut tris = Vec::new();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for i in 0..=n {
            for a in 0..n {
                for b in 0..n {
                    if (i + a + b + axis) % 2 == 0 {
                        continue;
                    }
                    let corner = |da: usize, db: usize| {
                        let mut p = DVec3::ZERO;
                        p[axis] = i as f64;
                        p[u] = (a + da) as f64;
                        p[v] = (b + db) as f64;
                        p
                    };
                    tris.push([corner(0, 0), corner(1, 0), corner(1, 1)]);
                    tris.push([corner(0, 0), corner(1, 1), corner(0, 1)]);
                }
            }
        }
    }
    tris
}

/// One of the shared public meshes; a missing file is a broken machine, so fail loudly.
pub fn public_mesh(name: &str) -> Vec<[DVec3; 3]> {
    let dir = crate::scene::shared_mesh_dir();
    let path = dir.join(name);
    assert!(
        path.exists(),
        "public test mesh {} is missing: every machine of this project has \
         {}; restore it from its SOURCES.md",
        path.display(),
        dir.display()
    );
    let tris = load_obj_triangles(&path).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(!tris.is_empty(), "{} has no triangles", path.display());
    tris
}

/// Brute-force closest hit in `[t_min, t_max)`: `(triangle, t)`, first index on exact ties.
pub fn brute_closest(tris: &[[DVec3; 3]], ray: &Ray, t_min: f64, t_max: f64) -> Option<(u32, f64)> {
    let mut best: Option<(u32, f64)> = None;
    for (i, tri) in tris.iter().enumerate() {
        if let Some((t, _, _)) = triangle::intersect(ray, tri, t_min, t_max) {
            if best.is_none_or(|(_, bt)| t < bt) {
                best = Some((i as u32, t));
            }
        }
    }
    best
}

/// All split planes of a tree as (axis, position).
pub fn split_planes(tree: &KdTree) -> Vec<(usize, f64)> {
    tree.nodes
        .iter()
        .filter_map(|n| match *n {
            KdNode::Inner { axis, split, .. } => Some((axis as usize, split)),
            _ => None,
        })
        .collect()
}

fn random_dir(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let d = DVec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        if d.length_squared() > 1e-4 {
            return d;
        }
    }
}

fn random_point(rng: &mut ChaCha8Rng, b: &Aabb) -> DVec3 {
    b.min + b.extent() * DVec3::new(rng.gen(), rng.gen(), rng.gen())
}

const AXES: [DVec3; 6] = [
    DVec3::X,
    DVec3::NEG_X,
    DVec3::Y,
    DVec3::NEG_Y,
    DVec3::Z,
    DVec3::NEG_Z,
];

/// A labelled ray set: from outside towards the mesh, axis-parallel, starting inside the
/// bounds, with an origin coordinate exactly on a split plane (in that plane, across it, and
/// axis-parallel along it), aimed exactly at vertices, and origins on integer coordinates (the
/// quad lattice's planes and edges).
pub fn ray_set(
    tris: &[[DVec3; 3]],
    tree: &KdTree,
    per_kind: usize,
    seed: u64,
) -> Vec<(&'static str, Ray)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let b = tree.bounds;
    // Grown equally on all axes so that flat meshes still get rays from off their plane.
    let big = b.expanded(0.5 * b.extent().max_element() + 0.5);
    let planes = split_planes(tree);
    let mut rays = Vec::new();
    for _ in 0..per_kind {
        let o = random_point(&mut rng, &big);
        let target = random_point(&mut rng, &b);
        rays.push(("outside->inside", Ray::new(o, target - o)));

        let o = random_point(&mut rng, &big);
        rays.push(("axis-parallel", Ray::new(o, AXES[rng.gen_range(0..6)])));

        let o = random_point(&mut rng, &b);
        rays.push(("inside", Ray::new(o, random_dir(&mut rng))));

        if !planes.is_empty() {
            let (axis, s) = planes[rng.gen_range(0..planes.len())];
            let mut o = random_point(&mut rng, &b);
            o[axis] = s;
            rays.push(("on split plane", Ray::new(o, random_dir(&mut rng))));
            let mut d = random_dir(&mut rng);
            d[axis] = 0.0;
            rays.push(("in split plane", Ray::new(o, d)));
            let mut d = AXES[rng.gen_range(0..6)];
            if d[axis] != 0.0 {
                d = AXES[(2 * axis + 2) % 6];
            }
            rays.push(("axis-parallel in split plane", Ray::new(o, d)));
            let mut o2 = random_point(&mut rng, &big);
            o2[axis] = s;
            rays.push(("outside, on split plane", Ray::new(o2, target - o2)));
        }

        let v = tris[rng.gen_range(0..tris.len())][rng.gen_range(0..3)];
        let o = random_point(&mut rng, &big);
        rays.push(("at a vertex", Ray::new(o, v - o)));

        let o = random_point(&mut rng, &big).round();
        rays.push((
            "integer origin, axis",
            Ray::new(o, AXES[rng.gen_range(0..6)]),
        ));
        rays.push(("integer origin", Ray::new(o, random_dir(&mut rng))));
    }
    rays
}
