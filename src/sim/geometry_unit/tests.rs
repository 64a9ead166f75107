//! Bit-exactness of the generated geometry units against the golden model's unit sequences
//! (`crate::units`), in Icarus and Verilator, plus lint. One simulator build per
//! unit, format and simulator; every vector streams through it.
//!
//! Vectors: seeded random words and geometric cases, plus the hard ones: unit-triangle
//! transforms of real mesh triangles (`../shared/scenes/meshes/*.obj`, the slivers and
//! near-degenerate ones first) rounded as the layout rounds them, with rays aimed at their
//! vertices, edge midpoints and centroids, rays lying in the triangle plane (edge-on) and
//! grazing it; rays in unit-triangle space landing exactly on edges and vertices and on the
//! edge margin's bounds (`lo = -margin`, `hi = 1 + margin`, and one word either side);
//! D'z = +-0; huge and tiny coordinates; NaN and infinity.

use std::path::{Path, PathBuf};

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::fp::vectors;
use crate::layout::unit_triangle_transform;
use crate::sim;
use crate::units;
use rust_hdl::prelude::*;

/// A random word: a third uniform bit patterns, a third edge cases, a third "geometric" values
/// (magnitudes 2^-8..2^8, either sign).
fn random_word(f: Format, rng: &mut ChaCha8Rng, edges: &[u32]) -> u32 {
    match rng.gen_range(0..3) {
        0 => rng.gen::<u32>() & f.word_mask(),
        1 => edges[rng.gen_range(0..edges.len())],
        _ => geometric(f, rng, 8),
    }
}

/// A value with magnitude in 2^-spread .. 2^spread and random sign, rounded to `f`.
fn geometric(f: Format, rng: &mut ChaCha8Rng, spread: i32) -> u32 {
    let x = rng.gen_range(1.0..2.0) * 2f64.powi(rng.gen_range(-spread..=spread));
    f.from_f64(if rng.gen_bool(0.5) { -x } else { x })
}

fn word(f: Format, x: f64) -> u32 {
    f.from_f64(x)
}

fn vec_words(f: Format, v: DVec3) -> [u32; 3] {
    [f.from_f64(v.x), f.from_f64(v.y), f.from_f64(v.z)]
}

/// The layout's rounding of an affine map: row-major 3x4, each entry rounded once.
fn matrix_words(f: Format, m: &glam::DAffine3) -> [u32; 12] {
    let mut w = [0; 12];
    for r in 0..3 {
        let row = m.matrix3.row(r);
        w[r * 4] = f.from_f64(row.x);
        w[r * 4 + 1] = f.from_f64(row.y);
        w[r * 4 + 2] = f.from_f64(row.z);
        w[r * 4 + 3] = f.from_f64(m.translation[r]);
    }
    w
}

fn meshes_dir() -> PathBuf {
    crate::scene::shared_mesh_dir()
}

/// Triangles of every mesh in ../shared/scenes/meshes: per mesh the `slivers` worst-shaped
/// (smallest area over longest edge squared, degenerate ones included) and `random` others.
fn mesh_triangles(slivers: usize, random: usize, seed: u64) -> Vec<[DVec3; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(meshes_dir())
        .expect("../shared/scenes/meshes")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no meshes in {}", meshes_dir().display());
    let mut out = Vec::new();
    for path in paths {
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj(&path, &options).unwrap();
        let mut tris = Vec::new();
        for model in models {
            let p = &model.mesh.positions;
            let v = |i: u32| {
                let i = i as usize * 3;
                DVec3::new(p[i] as f64, p[i + 1] as f64, p[i + 2] as f64)
            };
            for t in model.mesh.indices.chunks_exact(3) {
                tris.push([v(t[0]), v(t[1]), v(t[2])]);
            }
        }
        let quality = |t: &[DVec3; 3]| {
            let area = (t[1] - t[0]).cross(t[2] - t[0]).length();
            let longest = (t[1] - t[0])
                .length_squared()
                .max((t[2] - t[0]).length_squared())
                .max((t[2] - t[1]).length_squared());
            if longest == 0.0 {
                0.0
            } else {
                area / longest
            }
        };
        let mut order: Vec<usize> = (0..tris.len()).collect();
        order.sort_by(|&a, &b| quality(&tris[a]).total_cmp(&quality(&tris[b])));
        out.extend(order.iter().take(slivers).map(|&i| tris[i]));
        for _ in 0..random {
            out.push(tris[rng.gen_range(0..tris.len())]);
        }
    }
    out
}

/// World-space rays at a triangle: at each vertex, each edge midpoint, the centroid, a random
/// interior point; one lying in the triangle's plane along an edge (edge-on) and one grazing
/// it. Returns (origin, direction) pairs.
fn rays_at(t: &[DVec3; 3], rng: &mut ChaCha8Rng) -> Vec<(DVec3, DVec3)> {
    let [a, b, c] = *t;
    let n = (b - a).cross(c - a);
    let n = if n.length() > 0.0 {
        n.normalize()
    } else {
        DVec3::Z
    };
    let size = (b - a).length().max((c - a).length()).max(1e-3);
    let eye = (a + b + c) / 3.0
        + n * size * rng.gen_range(0.5..4.0)
        + DVec3::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), 0.3) * size * 0.5;
    let (r1, r2): (f64, f64) = (rng.gen(), rng.gen());
    let (r1, r2) = if r1 + r2 > 1.0 {
        (1.0 - r1, 1.0 - r2)
    } else {
        (r1, r2)
    };
    let targets = [
        a,
        b,
        c,
        (a + b) / 2.0,
        (b + c) / 2.0,
        (c + a) / 2.0,
        (a + b + c) / 3.0,
        a + (b - a) * r1 + (c - a) * r2,
    ];
    let mut rays: Vec<(DVec3, DVec3)> = targets.iter().map(|&p| (eye, p - eye)).collect();
    // Edge-on: starts on the plane outside the triangle and runs along it.
    rays.push((a - (b - a), b - a));
    // Grazing: almost parallel to the plane.
    rays.push((eye, (b - a) - n * size * 1e-4));
    rays
}

/// The model's intersect inputs for a world-space ray and a triangle, through the same
/// transform sequence the hardware uses.
fn unit_space_request(
    f: Format,
    m: &[u32; 12],
    o: DVec3,
    d: DVec3,
    t_min: u32,
    t_max: u32,
) -> ([u32; 3], [u32; 3], u32, u32) {
    let o2 = units::transform(f, m, vec_words(f, o), true);
    let d2 = units::transform(f, m, vec_words(f, d), false);
    (o2, d2, t_min, t_max)
}

// ---------------------------------------------------------------------------------------
// Transform

fn transform_random(f: Format, n: usize, seed: u64) -> Vec<TransformRequest> {
    println!("transform {f}: seed {seed}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let edges = vectors::edge_cases(f);
    (0..n)
        .map(|i| {
            let geometric_only = rng.gen_bool(0.5);
            let mut w = || {
                if geometric_only {
                    geometric(f, &mut rng, 6)
                } else {
                    random_word(f, &mut rng, &edges)
                }
            };
            let m: [u32; 12] = std::array::from_fn(|_| w());
            let v: [u32; 3] = std::array::from_fn(|_| w());
            TransformRequest {
                m,
                v,
                point: rng.gen_bool(0.5),
                diagonal: rng.gen_ratio(1, 4),
                tag: i as u16,
            }
        })
        .collect()
}

/// Unit-triangle transforms of mesh triangles applied to ray origins and directions;
/// cancellations (m0 x = -m1 y exactly, signed zeros), overflow, huge and tiny values.
fn transform_hard(f: Format, seed: u64) -> Vec<TransformRequest> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    let mut push = |m: [u32; 12], v: [u32; 3], point: bool| {
        out.push(TransformRequest {
            m,
            v,
            point,
            diagonal: false,
            tag: 0,
        })
    };
    for t in mesh_triangles(20, 10, seed) {
        let m = matrix_words(f, &unit_triangle_transform(&t));
        for (o, d) in rays_at(&t, &mut rng) {
            push(m, vec_words(f, o), true);
            push(m, vec_words(f, d), false);
        }
    }
    let big = f.max_finite(false);
    let tiny = f.min_normal(false);
    let one = f.one();
    let neg = |w: u32| w ^ f.sign_mask();
    for &(a, b) in &[
        (one, one),
        (big, big),
        (tiny, tiny),
        (big, tiny),
        (word(f, 3.0), word(f, 1.0 / 3.0)),
    ] {
        // Row sums that cancel exactly, with every sign of zero.
        for signs in 0..16u32 {
            let s = |k: u32, w: u32| if signs >> k & 1 == 1 { neg(w) } else { w };
            let m = [
                s(0, a),
                neg(s(0, a)),
                s(1, 0),
                s(2, 0),
                s(1, b),
                s(3, b),
                s(2, b),
                neg(s(3, 0)),
                s(3, big),
                s(0, big),
                s(1, tiny),
                s(2, tiny),
            ];
            push(m, [b, b, a], true);
            push(m, [s(1, b), b, s(2, a)], false);
            push(m, [0, neg(0), s(3, 0)], true);
        }
    }
    // Infinities times zeros, NaN payloads.
    let inf = f.infinity(false);
    push(
        [inf, 0, 0, 0, 0, inf, 0, 0, 0, 0, inf, 0],
        [0, one, neg(0)],
        true,
    );
    push([one; 12], [inf, neg(inf), one], false);
    push([one; 12], [f.nan() | 1, one, one], true);
    for (i, r) in out.iter_mut().enumerate() {
        r.tag = (i as u16).wrapping_mul(7919);
    }
    out
}

fn check_transform(f: Format, reqs: &[TransformRequest], got: &[TransformResult], what: &str) {
    assert_eq!(got.len(), reqs.len(), "{what}: result count");
    let mut bad = 0;
    for (i, (q, r)) in reqs.iter().zip(got).enumerate() {
        let want = units::transform_pass(f, &q.m, q.v, q.point, q.diagonal);
        if r.r != want || r.tag != q.tag {
            if bad < 5 {
                eprintln!(
                    "{what} #{i}: m={:x?} v={:x?} point={} tag {:#x}: got {:x?} tag {:#x}, want {:x?}",
                    q.m, q.v, q.point, q.tag, r.r, r.tag, want
                );
            }
            bad += 1;
        }
    }
    assert_eq!(bad, 0, "{what}: {bad} of {} results differ", reqs.len());
}

fn transform_case(f: Format, n_random: usize, seed: u64, sim: Simulator) {
    let mut reqs = transform_random(f, n_random, seed);
    let hard = transform_hard(f, seed + 1);
    let n_hard = hard.len();
    reqs.extend(hard);
    // Bubbles in the stream: every 50th request comes after 1..3 idle clocks.
    let mut rng = ChaCha8Rng::seed_from_u64(seed + 2);
    let gaps: Vec<u32> = (0..reqs.len())
        .map(|i| if i % 50 == 49 { rng.gen_range(1..4) } else { 0 })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let run = run_transform(f, &reqs, &gaps, sim, dir.path()).unwrap();
    println!(
        "{sim} transform {f}: {} random + {n_hard} hard: compile {:.1} s, run {:.1} s",
        n_random, run.compile_seconds, run.run_seconds
    );
    check_transform(f, &reqs, &run.results, &format!("{sim} transform {f}"));
}

/// Icarus and Verilator simulate the same Verilog: Verilator carries the 100k random cases,
/// Icarus the first 4,000 of them plus every hard case, to show that the result does not
/// depend on the simulator at a small share of its CI time (Icarus runs about 300 cases/s).
const ICARUS_CASES: usize = 4_000;
/// The same for binary32 (Verilator: 100k).
const ICARUS_CASES_E8M23: usize = 2_000;

#[test]
fn transform_e7m16_icarus() {
    transform_case(Format::E7M16, ICARUS_CASES, 4001, Simulator::Icarus);
}

#[test]
fn transform_e7m16_verilator() {
    transform_case(Format::E7M16, 100_000, 4001, Simulator::Verilator);
}

#[test]
fn transform_e8m23_icarus() {
    transform_case(Format::E8M23, ICARUS_CASES_E8M23, 4002, Simulator::Icarus);
}

#[test]
fn transform_e8m23_verilator() {
    transform_case(Format::E8M23, 100_000, 4002, Simulator::Verilator);
}

// ---------------------------------------------------------------------------------------
// Shared transform: arbitration

/// Every client requests every clock (full load) and, in a second phase, with random gaps;
/// no request is lost, each client's results come back in its order with its thread ids, the
/// values equal the model, and under full load the grants rotate 0, 1, 2, 3.
fn shared_case(f: Format, per_client: usize, seed: u64, sim: Simulator) {
    println!("shared transform {f}: seed {seed}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // The shared unit's clients ask for full passes only.
    let reqs: Vec<TransformRequest> = transform_random(f, 4 * per_client, seed + 1)
        .into_iter()
        .map(|r| TransformRequest {
            diagonal: false,
            ..r
        })
        .collect();
    let clients: [Vec<(u32, TransformRequest)>; 4] = std::array::from_fn(|c| {
        reqs[c * per_client..(c + 1) * per_client]
            .iter()
            .enumerate()
            .map(|(i, r)| {
                // First half: full load; second half: random gaps.
                let gap = if i < per_client / 2 {
                    0
                } else {
                    rng.gen_range(0..6)
                };
                let mut r = *r;
                r.tag = rng.gen_range(0..256);
                (gap, r)
            })
            .collect()
    });
    let dir = tempfile::tempdir().unwrap();
    let run = run_shared_transform(f, &clients, sim, dir.path()).unwrap();
    println!(
        "{sim} shared transform {f}: 4 x {per_client}: compile {:.1} s, run {:.1} s",
        run.compile_seconds, run.run_seconds
    );
    let got = &run.results;
    assert_eq!(
        got.len(),
        4 * per_client,
        "no request lost, none duplicated"
    );
    // Full load: the first 4 * (per_client / 2) results rotate over the clients, starting
    // after client 0 (the arbiter's reset state is "client 0 taken last").
    for (i, r) in got.iter().take(4 * (per_client / 2)).enumerate() {
        assert_eq!(
            r.client as usize,
            (i + 1) % 4,
            "{sim}: round robin at result {i}"
        );
    }
    for c in 0..4 {
        let mine: Vec<&TransformResult> = got.iter().filter(|r| r.client as usize == c).collect();
        assert_eq!(mine.len(), per_client, "{sim}: client {c} result count");
        let sent: Vec<TransformRequest> = clients[c].iter().map(|&(_, r)| r).collect();
        let mine: Vec<TransformResult> = mine.into_iter().copied().collect();
        check_transform(
            f,
            &sent,
            &mine,
            &format!("{sim} shared transform {f} client {c}"),
        );
    }
}

#[test]
fn shared_transform_arbitration_icarus() {
    shared_case(Format::E7M16, 1000, 4101, Simulator::Icarus);
}

#[test]
fn shared_transform_arbitration_verilator() {
    shared_case(Format::E7M16, 5000, 4101, Simulator::Verilator);
}

// ---------------------------------------------------------------------------------------
// Intersect

fn intersect_random(f: Format, n: usize, seed: u64) -> Vec<IntersectRequest> {
    println!("intersect {f}: seed {seed}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let edges = vectors::edge_cases(f);
    (0..n)
        .map(|i| {
            let (o, d, t_min, t_max) = if rng.gen_bool(0.25) {
                let mut w = || random_word(f, &mut rng, &edges);
                ([w(), w(), w()], [w(), w(), w()], w(), w())
            } else {
                // A ray from above or below the unit triangle's plane towards it, hitting about
                // half the time.
                let oz: f64 = rng.gen_range(0.1..4.0) * if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
                let target = (rng.gen_range(-0.5..1.5), rng.gen_range(-0.5..1.5));
                let o = (rng.gen_range(-2.0..2.0), rng.gen_range(-2.0..2.0), oz);
                let d = (
                    target.0 - o.0,
                    target.1 - o.1,
                    -oz * rng.gen_range(0.2..3.0),
                );
                let t_min = if rng.gen_bool(0.5) {
                    0.0
                } else {
                    rng.gen_range(0.0..0.6)
                };
                let t_max = if rng.gen_bool(0.5) {
                    f64::INFINITY
                } else {
                    rng.gen_range(0.3..3.0)
                };
                (
                    [word(f, o.0), word(f, o.1), word(f, o.2)],
                    [word(f, d.0), word(f, d.1), word(f, d.2)],
                    word(f, t_min),
                    word(f, t_max),
                )
            };
            IntersectRequest {
                o,
                d,
                t_min,
                t_max,
                tag: i as u16,
            }
        })
        .collect()
}

/// Mesh triangles (slivers first) with rays at vertices, edges, centroid, edge-on and grazing;
/// unit-space rays landing exactly on edges and vertices, and exactly on and one word either
/// side of the edge margin's bounds; D'z = +-0; huge and tiny values; t exactly at t_min or
/// t_max.
fn intersect_hard(f: Format, seed: u64) -> Vec<IntersectRequest> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    let inf = f.infinity(false);
    let mut push = |(o, d, t_min, t_max): ([u32; 3], [u32; 3], u32, u32)| {
        out.push(IntersectRequest {
            o,
            d,
            t_min,
            t_max,
            tag: 0,
        })
    };
    for t in mesh_triangles(40, 20, seed) {
        let m = matrix_words(f, &unit_triangle_transform(&t));
        for (o, d) in rays_at(&t, &mut rng) {
            push(unit_space_request(f, &m, o, d, 0, inf));
            push(unit_space_request(
                f,
                &m,
                o,
                d,
                word(f, 1e-3),
                word(f, 0.999),
            ));
        }
    }
    let neg = |w: u32| w ^ f.sign_mask();
    let z = |x: f64| word(f, x);
    // Exactly on edges and vertices: O' above (u0, v0), D' straight down, or slanted so that
    // u = O'x + t D'x lands exactly on the edge value.
    let on_edges = [
        (0.0, 0.0),
        (1.0, 0.0),
        (0.0, 1.0),
        (0.5, 0.5),
        (0.25, 0.75),
        (0.0, 0.5),
        (0.5, 0.0),
        (-0.0, 0.5),
        (0.5, -0.0),
        (1.0, 1.0),
        (0.75, 0.25),
        (0.125, 0.875),
    ];
    for &(u0, v0) in &on_edges {
        for height in [1.0, 2.0, 0.5, -1.0] {
            for dz in [-1.0, -2.0, 1.0, -0.25] {
                push(([z(u0), z(v0), z(height)], [0, neg(0), z(dz)], 0, inf));
                // Slanted: t = height / -dz, O'x = u0 - t * 0.5 with D'x = 0.5.
                let t = height / -dz;
                push((
                    [z(u0 - t * 0.5), z(v0 + t * 0.25), z(height)],
                    [z(0.5), z(-0.25), z(dz)],
                    0,
                    inf,
                ));
                // t exactly at the ends of the range.
                push(([z(u0), z(v0), z(height)], [0, 0, z(dz)], z(t), inf));
                push(([z(u0), z(v0), z(height)], [0, 0, z(dz)], 0, z(t)));
            }
        }
    }
    // Parallel rays: D'z = +0 and -0, with O'z zero (t = NaN) or not (t = inf).
    for dz in [0, neg(0)] {
        for oz in [0, neg(0), z(1.0), z(-1.0)] {
            push(([z(0.25), z(0.25), oz], [z(0.1), z(0.1), dz], neg(inf), inf));
        }
    }
    // Huge and tiny coordinates, infinities, NaNs.
    let big = f.max_finite(false);
    let tiny = f.min_normal(false);
    for &(a, b) in &[
        (big, tiny),
        (tiny, big),
        (big, big),
        (tiny, tiny),
        (inf, z(1.0)),
        (z(1.0), inf),
    ] {
        for s in 0..8u32 {
            let sg = |k: u32, w: u32| if s >> k & 1 == 1 { neg(w) } else { w };
            push((
                [sg(0, a), sg(1, b), sg(2, a)],
                [sg(1, b), sg(2, a), sg(0, b)],
                0,
                inf,
            ));
            push((
                [z(0.25), z(0.25), sg(0, a)],
                [sg(1, a), sg(2, b), sg(0, b)],
                neg(inf),
                inf,
            ));
        }
    }
    // Exactly on the edge margin's bounds (lo = -margin, hi = 1 + margin) and one word either
    // side of them.
    for (req, _) in crate::hw::intersect::edge_bound_cases(f) {
        push(req);
    }
    push(([f.nan(), z(0.2), z(1.0)], [0, 0, z(-1.0)], 0, inf));
    push(([z(0.2), z(0.2), z(1.0)], [0, 0, z(-1.0)], f.nan(), inf));
    push(([z(0.2), z(0.2), z(1.0)], [0, 0, z(-1.0)], 0, f.nan()));
    for (i, r) in out.iter_mut().enumerate() {
        r.tag = (i as u16).wrapping_mul(31337);
    }
    out
}

fn check_intersect(f: Format, reqs: &[IntersectRequest], got: &[IntersectResult], what: &str) {
    assert_eq!(got.len(), reqs.len(), "{what}: result count");
    let mut bad = 0;
    let mut hits = 0;
    for (i, (q, r)) in reqs.iter().zip(got).enumerate() {
        let want = units::intersect(f, q.o, q.d, q.t_min, q.t_max);
        hits += usize::from(want.hit);
        let same = r.t == want.t && r.u == want.u && r.v == want.v && r.hit == want.hit;
        if !same || r.tag != q.tag {
            if bad < 5 {
                eprintln!("{what} #{i}: {q:x?}: got {r:x?}, want {want:x?}");
            }
            bad += 1;
        }
    }
    println!("{what}: {hits} hits in {} tests", reqs.len());
    assert!(
        hits > reqs.len() / 20,
        "{what}: the vectors should hit often"
    );
    assert_eq!(bad, 0, "{what}: {bad} of {} results differ", reqs.len());
}

fn intersect_case(f: Format, n_random: usize, seed: u64, sim: Simulator) {
    let mut reqs = intersect_random(f, n_random, seed);
    let hard = intersect_hard(f, seed + 1);
    let n_hard = hard.len();
    reqs.extend(hard);
    let dir = tempfile::tempdir().unwrap();
    let run = run_intersect(f, &reqs, sim, dir.path()).unwrap();
    println!(
        "{sim} intersect {f}: {n_random} random + {n_hard} hard: compile {:.1} s, run {:.1} s",
        run.compile_seconds, run.run_seconds
    );
    check_intersect(f, &reqs, &run.results, &format!("{sim} intersect {f}"));
}

/// [`ICARUS_CASES`] random plus every hard case.
#[test]
fn intersect_e7m16_icarus() {
    intersect_case(Format::E7M16, ICARUS_CASES, 4201, Simulator::Icarus);
}

#[test]
fn intersect_e7m16_verilator() {
    intersect_case(Format::E7M16, 100_000, 4201, Simulator::Verilator);
}

#[test]
fn intersect_e8m23_icarus() {
    intersect_case(Format::E8M23, ICARUS_CASES_E8M23, 4202, Simulator::Icarus);
}

#[test]
fn intersect_e8m23_verilator() {
    intersect_case(Format::E8M23, 100_000, 4202, Simulator::Verilator);
}

// ---------------------------------------------------------------------------------------
// Ray generation

/// Cameras of real scenes (the layout's words) at several sizes, and odd ones.
fn raygen_frames(f: Format, sizes: &[(u16, u16)]) -> Vec<RayGenFrame> {
    use crate::layout::{self, FrameMap, MemoryConfig, SceneTrees, FRAME};
    use crate::scene::Scene;
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut frames = Vec::new();
    for (i, &(w, h)) in sizes.iter().enumerate() {
        let name = ["tiny.toml", "cornell.toml"][i % 2];
        let text = std::fs::read_to_string(scenes.join(name)).unwrap();
        let text = text
            .lines()
            .map(|l| {
                if l.starts_with("width") {
                    format!("width = {w}")
                } else if l.starts_with("height") {
                    format!("height = {h}")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let scene = Scene::from_toml_str(&text, &scenes, scenes.join(name)).unwrap();
        let trees = SceneTrees::build(&scene, f).unwrap();
        let lay = layout::build(&scene, &trees, 0, &MemoryConfig::ADM_XRC_II).unwrap();
        frames.push(RayGenFrame {
            width: w,
            height: h,
            camera: lay.words::<12>(FRAME, FrameMap::CAMERA),
            eye: lay.words::<3>(FRAME, FrameMap::EYE),
        });
    }
    frames
}

fn raygen_case(f: Format, sizes: &[(u16, u16)], seed: u64, sim: Simulator) {
    println!("raygen {f}: seed {seed}");
    let frames = raygen_frames(f, sizes);
    let pixels: usize = sizes.iter().map(|&(w, h)| w as usize * h as usize).sum();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Threads mostly come every clock, sometimes after a pause.
    let gaps: Vec<u32> = (0..pixels)
        .map(|_| {
            if rng.gen_bool(0.05) {
                rng.gen_range(1..5)
            } else {
                0
            }
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let run = run_raygen(f, &frames, &gaps, sim, dir.path()).unwrap();
    println!(
        "{sim} raygen {f}: {pixels} pixels in {} frames: compile {:.1} s, run {:.1} s",
        frames.len(),
        run.compile_seconds,
        run.run_seconds
    );
    let out = &run.results;
    assert_eq!(out.issued.len(), pixels, "{sim}: issued count");
    assert_eq!(out.rays.len(), pixels, "{sim}: ray count");
    let mut i = 0;
    let mut bad = 0;
    for fr in &frames {
        for y in 0..fr.height {
            for x in 0..fr.width {
                let (ix, iy, thread) = out.issued[i];
                assert_eq!((ix, iy), (x, y), "{sim}: pixel order at ray {i}");
                assert_eq!(thread as usize, i % 32, "{sim}: thread of ray {i}");
                let (t, d, o) = out.rays[i];
                let want = units::primary_direction(f, &fr.camera, x as u32, y as u32);
                if t != thread || d != want || o != fr.eye {
                    if bad < 5 {
                        eprintln!(
                            "{sim} raygen {f} pixel ({x}, {y}): got thread {t} dir {d:x?} origin {o:x?}, want {thread} {want:x?} {:x?}",
                            fr.eye
                        );
                    }
                    bad += 1;
                }
                i += 1;
            }
        }
    }
    assert_eq!(bad, 0, "{sim} raygen {f}: {bad} of {pixels} rays differ");
}

#[test]
fn raygen_e7m16_icarus() {
    raygen_case(
        Format::E7M16,
        &[(16, 12), (40, 30), (3, 1), (1, 5)],
        4301,
        Simulator::Icarus,
    );
}

#[test]
fn raygen_e7m16_verilator() {
    raygen_case(
        Format::E7M16,
        &[(16, 12), (400, 256), (3, 1), (1, 5)],
        4301,
        Simulator::Verilator,
    );
}

#[test]
fn raygen_e8m23_both() {
    for sim in Simulator::ALL {
        raygen_case(Format::E8M23, &[(64, 48), (7, 3)], 4302, sim);
    }
}

// ---------------------------------------------------------------------------------------
// The processor's ray generation: `engine::PrimaryRays` on a TransformUnit

/// `engine::PrimaryRays` with a TransformUnit on its client port, as the triangle tester
/// serves it in the processor: the unit takes the request in the clocks `take` is high (the
/// clocks a test's launch leaves free) and its results come back tagged with the thread.
/// `issued` marks the clock a `pixel` is handed out.
#[derive(LogicBlock)]
struct PrimaryRaysBench<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
> {
    pub clock: Signal<In, Clock>,
    pub frame_start: Signal<In, Bit>,
    pub camera_write: Signal<In, Bit>,
    pub camera_pair: Signal<In, Bits<3>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub offer: Signal<In, Bit>,
    pub thread: Signal<In, Bits<5>>,
    pub take: Signal<In, Bit>,
    pub issued: Signal<Out, Bit>,
    pub word: Signal<Out, Bits<32>>,
    pub issued_thread: Signal<Out, Bits<5>>,
    pub primary_write: Signal<Out, Bit>,
    pub primary_thread: Signal<Out, Bits<5>>,
    pub primary_o: [Signal<Out, Bits<W>>; 3],
    pub primary_d: [Signal<Out, Bits<W>>; 3],
    pub done_mask: Signal<Out, Bits<32>>,
    rays: crate::hw::engine::PrimaryRays<W, E, M>,
    unit: crate::hw::TransformUnit<W, E, M, S, S1, X2, T, P>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > PrimaryRaysBench<W, E, M, S, S1, X2, T, P>
{
    fn new(config: &crate::hw::program::ProgramConfig) -> Self {
        Self {
            clock: Default::default(),
            frame_start: Default::default(),
            camera_write: Default::default(),
            camera_pair: Default::default(),
            word_a: Default::default(),
            word_b: Default::default(),
            offer: Default::default(),
            thread: Default::default(),
            take: Default::default(),
            issued: Default::default(),
            word: Default::default(),
            issued_thread: Default::default(),
            primary_write: Default::default(),
            primary_thread: Default::default(),
            primary_o: Default::default(),
            primary_d: Default::default(),
            done_mask: Default::default(),
            rays: crate::hw::engine::PrimaryRays::new(config),
            unit: Default::default(),
        }
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > Logic for PrimaryRaysBench<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        self.rays.clock.next = self.clock.val();
        self.unit.clock.next = self.clock.val();
        self.rays.frame_start.next = self.frame_start.val();
        self.rays.camera_write.next = self.camera_write.val();
        self.rays.camera_pair.next = self.camera_pair.val();
        self.rays.word_a.next = self.word_a.val();
        self.rays.word_b.next = self.word_b.val();
        self.rays.offer.next = self.offer.val();
        self.rays.thread.next = self.thread.val();
        self.rays.query_thread.next = 0.into();
        self.issued.next = self.offer.val() & !self.rays.refused.val() & !self.rays.exhausted.val();
        self.word.next = self.rays.word.val();
        self.issued_thread.next = self.thread.val();

        self.rays.gen_take.next = self.take.val();
        // No world normals in this bench: the direction store keeps the primary rays'.
        self.rays.normal_write.next = false;
        self.rays.normal_thread.next = 0.into();
        for k in 0..3 {
            self.rays.normal[k].next = 0.into();
        }
        self.unit.in_valid.next = self.rays.gen_valid.val() & self.take.val();
        for k in 0..12 {
            self.unit.m[k].next = self.rays.gen_m[k].val();
        }
        for k in 0..3 {
            self.unit.v[k].next = self.rays.gen_v[k].val();
        }
        self.unit.point.next = true;
        self.unit.diagonal.next = false;
        self.unit.tag.next = bit_cast::<16, 5>(self.rays.gen_thread.val());
        self.rays.gen_out_valid.next = self.unit.out_valid.val();
        self.rays.gen_out_thread.next = self.unit.out_tag.val().get_bits::<5>(0);
        for k in 0..3 {
            self.rays.gen_out_dir[k].next = self.unit.result[k].val();
            self.primary_o[k].next = self.rays.primary_o[k].val();
            self.primary_d[k].next = self.rays.primary_d[k].val();
        }
        self.primary_write.next = self.rays.primary_write.val();
        self.primary_thread.next = self.rays.primary_thread.val();
        self.done_mask.next = self.rays.done_mask.val();
    }
}

/// The ports of a bench whose unit writes whole rays: the clock, `inputs` and `outputs`, and
/// the ray's `{ray}_write`, `{ray}_thread`, `{ray}_o__k`, `{ray}_d__k` (24 bits) and
/// `done_mask`; with the fields of the rays' sink (thread, origin, direction, wake-up).
fn ray_bench_ports(
    inputs: &[(&str, u32)],
    outputs: &[(&str, u32)],
    ray: &str,
) -> (Vec<crate::emit::stream_bench::BenchPort>, Vec<String>) {
    use crate::emit::stream_bench::BenchPort;
    let words: Vec<String> = ["o", "d"]
        .iter()
        .flat_map(|v| (0..3).map(move |k| format!("{ray}_{v}__{k}")))
        .collect();
    let thread = format!("{ray}_thread");
    let ports = [BenchPort::input("clock", 1)]
        .into_iter()
        .chain(inputs.iter().map(|&(n, w)| BenchPort::input(n, w)))
        .chain(outputs.iter().map(|&(n, w)| BenchPort::output(n, w)))
        .chain([
            BenchPort::output(format!("{ray}_write"), 1),
            BenchPort::output(thread.clone(), 5),
            BenchPort::output("done_mask", 32),
        ])
        .chain(words.iter().map(|n| BenchPort::output(n.clone(), 24)))
        .collect();
    let fields = [thread]
        .into_iter()
        .chain(words)
        .chain(["done_mask".to_string()])
        .collect();
    (ports, fields)
}

/// PrimaryRays' generated Verilog in `sim`, e7m16, on a frame of the Cornell box's camera:
/// the camera written a pair of words a clock, a frame start, then threads 0..32 in turn
/// offering `pixel`s (sometimes after a pause) while the unit takes requests in random
/// clocks. Asserts: every pixel is handed out once, in raster order, with its word; each
/// thread's ray is written whole with the eye as origin and `units::primary_direction` of its
/// pixel as direction, in the order the pixels were handed out, with the thread's bit as
/// wake-up.
fn primary_rays_case(width: u16, height: u16, seed: u64, sim: Simulator) {
    use crate::emit::stream_bench::{InputStream, OutputSink, StreamBench};
    use crate::emit::verilog_tidy::{merge_identical_modules, rename_rust_hdl_names};
    use crate::hw::program::ProgramConfig;
    use crate::sim::stream_bench::run_stream_bench;
    assert_eq!(crate::hw::TAG_BITS, 16, "the bench's tag cast");
    let f = Format::E7M16;
    let frame = raygen_frames(f, &[(width, height)])[0];
    let config = ProgramConfig::frame_only(f, width.into(), height.into());
    let shift = config.pixel_shift();
    let mut uut = PrimaryRaysBench::<24, 7, 16, 17, 18, 9, 21, 34>::new(&config);
    uut.connect_all();
    let top = "primary_rays_bench";
    let verilog = merge_identical_modules(&rename_rust_hdl_names(&generate_verilog(&uut), top));

    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let pixels = usize::from(width) * usize::from(height);
    // The camera and eye words (the 16th word is unused), then the frame start.
    let words: Vec<u32> = frame.camera.iter().chain(&frame.eye).copied().collect();
    let word = |k: usize| u64::from(words.get(k).copied().unwrap_or(0));
    let mut control: Vec<(u32, Vec<u64>)> = (0..8)
        .map(|pair| {
            (
                0,
                vec![0, 1, pair as u64, word(2 * pair), word(2 * pair + 1)],
            )
        })
        .collect();
    control.push((0, vec![1, 0, 0, 0, 0]));
    control.push((0, vec![0, 0, 0, 0, 0]));
    let offers = (0..pixels)
        .map(|i| {
            let gap = if i == 0 {
                12
            } else if rng.gen_bool(0.1) {
                rng.gen_range(1..6)
            } else {
                0
            };
            (gap, vec![(i % 32) as u64])
        })
        .collect();
    let mut takes: Vec<(u32, Vec<u64>)> = (0..4 * pixels)
        .map(|_| (0, vec![u64::from(rng.gen_bool(0.5))]))
        .collect();
    takes.push((0, vec![1]));
    let (ports, ray_fields) = ray_bench_ports(
        &[
            ("frame_start", 1),
            ("camera_write", 1),
            ("camera_pair", 3),
            ("word_a", 32),
            ("word_b", 32),
            ("offer", 1),
            ("thread", 5),
            ("take", 1),
        ],
        &[("issued", 1), ("word", 32), ("issued_thread", 5)],
        "primary",
    );
    let bench = StreamBench {
        dut: top.into(),
        ports,
        streams: vec![
            InputStream {
                name: "control".into(),
                fields: [
                    "frame_start",
                    "camera_write",
                    "camera_pair",
                    "word_a",
                    "word_b",
                ]
                .map(String::from)
                .to_vec(),
                valid: None,
                ready: None,
                lines: control,
            },
            InputStream {
                name: "offers".into(),
                fields: vec!["thread".into()],
                valid: Some("offer".into()),
                ready: Some("issued".into()),
                lines: offers,
            },
            InputStream {
                name: "takes".into(),
                fields: vec!["take".into()],
                valid: None,
                ready: None,
                lines: takes,
            },
        ],
        sinks: vec![
            OutputSink {
                name: "issued".into(),
                valid: "issued".into(),
                fields: vec!["word".into(), "issued_thread".into()],
                expected: pixels,
            },
            OutputSink {
                name: "rays".into(),
                valid: "primary_write".into(),
                fields: ray_fields,
                expected: pixels,
            },
        ],
        max_cycles: 20 * pixels as u64 + 1000,
    };
    let dir = tempfile::tempdir().unwrap();
    let run = run_stream_bench(&bench, &verilog, sim, dir.path()).unwrap();
    println!(
        "{sim} primary rays {width}x{height}: compile {:.1} s, run {:.1} s",
        run.compile_seconds, run.run_seconds
    );
    let (issued, rays) = (&run.sinks[0], &run.sinks[1]);
    assert_eq!(issued.len(), pixels, "{sim}: pixels handed out");
    assert_eq!(rays.len(), pixels, "{sim}: rays written");
    let mut bad = 0;
    for (i, (given, ray)) in issued.iter().zip(rays).enumerate() {
        let (x, y) = (
            (i % usize::from(width)) as u32,
            (i / usize::from(width)) as u32,
        );
        assert_eq!(
            given[0],
            u64::from(y << shift | x),
            "{sim}: word of pixel {i}"
        );
        assert_eq!(given[1], (i % 32) as u64, "{sim}: thread of pixel {i}");
        let thread = given[1];
        let want_d = units::primary_direction(f, &frame.camera, x, y);
        let got_o: Vec<u32> = ray[1..4].iter().map(|&w| w as u32).collect();
        let got_d: Vec<u32> = ray[4..7].iter().map(|&w| w as u32).collect();
        if ray[0] != thread || got_o != frame.eye || got_d != want_d || ray[7] != 1 << thread {
            if bad < 5 {
                eprintln!(
                    "{sim} pixel ({x}, {y}): got thread {} o {got_o:x?} d {got_d:x?} wake-up {:x}, want {thread} {:x?} {want_d:x?} {:x}",
                    ray[0], ray[7], frame.eye, 1u64 << thread
                );
            }
            bad += 1;
        }
    }
    assert_eq!(bad, 0, "{sim}: {bad} of {pixels} primary rays differ");
}

#[test]
fn primary_rays_e7m16_icarus() {
    primary_rays_case(40, 30, 3401, Simulator::Icarus);
}

#[test]
fn primary_rays_e7m16_verilator() {
    primary_rays_case(64, 48, 3402, Simulator::Verilator);
}

// ---------------------------------------------------------------------------------------
// The processor's instance entry: `engine::InstanceRays` on a TransformUnit and a bank 4

/// Words of the instance bank the instance-entry bench holds (16 records).
const ENTRY_BANK_WORDS: usize = 16 * crate::layout::INSTANCE_WORDS;

/// `engine::InstanceRays` with a TransformUnit on its client port (taking requests in the
/// clocks `take` is high) and bank 4 as a ROM behind two registers (SRAM latency 2) on a bus
/// that is free in the clocks `free` is high. World words (`world_*`) and entries
/// (`enter_*`; a normal's when `normal` is high, with its z on `nz`) come in on separate
/// ports; the unit sees one at a time, as from the engine.
#[derive(LogicBlock)]
struct InstanceRaysBench<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
> {
    pub clock: Signal<In, Clock>,
    pub world_write: Signal<In, Bit>,
    pub world_pair: Signal<In, Bits<2>>,
    pub world_thread: Signal<In, Bits<5>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub enter: Signal<In, Bit>,
    pub enter_thread: Signal<In, Bits<5>>,
    pub instance_id: Signal<In, Bits<24>>,
    pub normal: Signal<In, Bit>,
    pub nz: Signal<In, Bits<32>>,
    pub take: Signal<In, Bit>,
    pub free: Signal<In, Bit>,
    pub accepted: Signal<Out, Bit>,
    pub normal_write: Signal<Out, Bit>,
    pub ray_write: Signal<Out, Bit>,
    pub ray_thread: Signal<Out, Bits<5>>,
    pub ray_o: [Signal<Out, Bits<W>>; 3],
    pub ray_d: [Signal<Out, Bits<W>>; 3],
    pub done_mask: Signal<Out, Bits<32>>,
    pub root_write: Signal<Out, Bit>,
    pub root_thread: Signal<Out, Bits<5>>,
    pub root: Signal<Out, Bits<26>>,
    /// A read in a clock the bus was not free (never).
    pub busy_read: Signal<Out, Bit>,
    /// The instance cache's lookups.
    pub cache_hit: Signal<Out, Bit>,
    pub cache_miss: Signal<Out, Bit>,
    entries: crate::hw::engine::InstanceRays<W>,
    unit: crate::hw::TransformUnit<W, E, M, S, S1, X2, T, P>,
    bank: ROM<Bits<32>, 9>,
    data_1: DFF<Bits<32>>,
    data_2: DFF<Bits<32>>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > InstanceRaysBench<W, E, M, S, S1, X2, T, P>
{
    fn new(bank: &[u32], cache_sets: u32, cache_ways: u32) -> Self {
        assert!(bank.len() <= 512);
        Self {
            clock: Default::default(),
            world_write: Default::default(),
            world_pair: Default::default(),
            world_thread: Default::default(),
            word_a: Default::default(),
            word_b: Default::default(),
            enter: Default::default(),
            enter_thread: Default::default(),
            instance_id: Default::default(),
            normal: Default::default(),
            nz: Default::default(),
            take: Default::default(),
            free: Default::default(),
            accepted: Default::default(),
            normal_write: Default::default(),
            ray_write: Default::default(),
            ray_thread: Default::default(),
            ray_o: Default::default(),
            ray_d: Default::default(),
            done_mask: Default::default(),
            root_write: Default::default(),
            root_thread: Default::default(),
            root: Default::default(),
            busy_read: Default::default(),
            cache_hit: Default::default(),
            cache_miss: Default::default(),
            entries: crate::hw::engine::InstanceRays::new(2, true, cache_sets, cache_ways),
            unit: Default::default(),
            bank: ROM::new(crate::hw::engine::word_map(
                bank.iter().map(|&w| Bits::<32>::from(u64::from(w))),
            )),
            data_1: Default::default(),
            data_2: Default::default(),
        }
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > Logic for InstanceRaysBench<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, data_1, data_2);
        self.entries.clock.next = self.clock.val();
        self.unit.clock.next = self.clock.val();
        self.entries.frame_start.next = false;
        self.entries.world_write.next = self.world_write.val();
        self.entries.world_pair.next = self.world_pair.val();
        self.entries.word_a.next = self.word_a.val();
        self.entries.word_b.next = self.nz.val();
        if self.world_write.val() {
            self.entries.word_b.next = self.word_b.val();
        }
        self.entries.thread.next = self.enter_thread.val();
        if self.world_write.val() {
            self.entries.thread.next = self.world_thread.val();
        }
        self.entries.offer.next = self.enter.val() & (!self.world_write.val());
        self.entries.offer_normal.next = self.normal.val();
        self.entries.instance_id.next = self.instance_id.val();
        self.accepted.next =
            self.enter.val() & (!self.world_write.val()) & (!self.entries.refused.val());
        self.entries.query_thread.next = 0.into();

        self.entries.bus_free.next = self.free.val();
        self.busy_read.next = self.entries.read.val() & (!self.free.val());
        self.bank.address.next = self.entries.addr.val().get_bits::<9>(0);
        self.data_1.d.next = self.bank.data.val();
        self.data_2.d.next = self.data_1.q.val();
        self.entries.rdata.next = self.data_2.q.val();

        self.entries.gen_take.next = self.take.val();
        self.unit.in_valid.next = self.entries.gen_valid.val() & self.take.val();
        for k in 0..12 {
            self.unit.m[k].next = self.entries.gen_m[k].val();
        }
        for k in 0..3 {
            self.unit.v[k].next = self.entries.gen_v[k].val();
        }
        self.unit.point.next = self.entries.gen_point.val();
        self.unit.diagonal.next = false;
        self.unit.tag.next = bit_cast::<16, 5>(self.entries.gen_thread.val())
            | (bit_cast::<16, 1>(self.entries.gen_direction.val().into()) << 5)
            | (bit_cast::<16, 1>(self.entries.gen_normal.val().into()) << 6);
        self.entries.out_valid.next = self.unit.out_valid.val();
        self.entries.out_thread.next = self.unit.out_tag.val().get_bits::<5>(0);
        self.entries.out_direction.next = self.unit.out_tag.val().get_bit(5);
        self.entries.out_normal.next = self.unit.out_tag.val().get_bit(6);
        for k in 0..3 {
            self.entries.out_v[k].next = self.unit.result[k].val();
            self.ray_o[k].next = self.entries.ray_o[k].val();
            self.ray_d[k].next = self.entries.ray_d[k].val();
        }
        self.ray_write.next = self.entries.ray_write.val();
        self.normal_write.next = self.entries.normal_write.val();
        self.ray_thread.next = self.entries.ray_thread.val();
        self.done_mask.next = self.entries.done_mask.val();
        self.root_write.next = self.entries.root_write.val();
        self.root_thread.next = self.entries.root_thread.val();
        self.root.next = self.entries.root.val();
        self.cache_hit.next = self.entries.cache_hit.val();
        self.cache_miss.next = self.entries.cache_miss.val();
    }
}

/// InstanceRays' generated Verilog in `sim`, e7m16: every thread's world ray written (random
/// words), then `entries` entries of threads 0..32 in turn into random instances of a bank
/// of random words, offered again while refused, the unit taking requests and the bus free in
/// random clocks; four in ten are normals' (`tri.normal`, a random z). Asserts: each entry's
/// ray is written whole for its thread, in entry order, as `units::transform` of the thread's
/// world origin (a point) and direction (a vector) by the record's world-to-object words,
/// with the thread's bit as wake-up, and its root (the record's root word's 26 bits) given
/// for its thread; each normal is `units::transform3` of the record's normal matrix and the
/// thread's world words 0, 1 and its z, in order, with the wake-up; no read goes out on a
/// busy bus; the instance cache (`cache_sets` sets of `cache_ways` ways, one frame, room for
/// every record and kind) misses once for each record and kind entered and hits for every
/// other entry.
fn instance_rays_case(entries: usize, seed: u64, sim: Simulator, cache_sets: u32, cache_ways: u32) {
    use crate::emit::stream_bench::{InputStream, OutputSink, StreamBench};
    use crate::emit::verilog_tidy::{merge_identical_modules, rename_rust_hdl_names};
    use crate::layout::{instance_word, INSTANCE_WORDS};
    use crate::sim::stream_bench::run_stream_bench;
    let f = Format::E7M16;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let bank: Vec<u32> = (0..ENTRY_BANK_WORDS)
        .map(|_| geometric(f, &mut rng, 4))
        .collect();
    let world: Vec<[u32; 6]> = (0..32)
        .map(|_| std::array::from_fn(|_| word(f, rng.gen_range(-4.0..4.0))))
        .collect();
    let mut uut =
        InstanceRaysBench::<24, 7, 16, 17, 18, 9, 21, 34>::new(&bank, cache_sets, cache_ways);
    uut.connect_all();
    let top = "instance_rays_bench";
    let verilog = merge_identical_modules(&rename_rust_hdl_names(&generate_verilog(&uut), top));

    let mut writes: Vec<(u32, Vec<u64>)> = (0..96)
        .map(|k| {
            let (thread, pair) = (k / 3, k % 3);
            let w = |i: usize| u64::from(world[thread][2 * pair + i]);
            (0, vec![1, pair as u64, thread as u64, w(0), w(1)])
        })
        .collect();
    writes.push((0, vec![0, 0, 0, 0, 0]));
    let records: Vec<usize> = (0..entries).map(|_| rng.gen_range(0..16)).collect();
    // A normal's z, or none for an entry.
    let normal_z: Vec<Option<u32>> = (0..entries)
        .map(|_| rng.gen_bool(0.4).then(|| word(f, rng.gen_range(-1.0..1.0))))
        .collect();
    let offers = records
        .iter()
        .zip(&normal_z)
        .enumerate()
        .map(|(i, (&r, z))| {
            let gap = if i == 0 { 100 } else { rng.gen_range(0..4) };
            let (normal, z) = (u64::from(z.is_some()), u64::from(z.unwrap_or(0)));
            (gap, vec![(i % 32) as u64, r as u64, normal, z])
        })
        .collect();
    let entered = normal_z.iter().filter(|z| z.is_none()).count();
    let kinds: std::collections::BTreeSet<(usize, bool)> = records
        .iter()
        .zip(&normal_z)
        .map(|(&r, z)| (r, z.is_some()))
        .collect();
    let random_bits = |rng: &mut ChaCha8Rng, n: usize| -> Vec<(u32, Vec<u64>)> {
        let mut bits: Vec<(u32, Vec<u64>)> = (0..n)
            .map(|_| (0, vec![u64::from(rng.gen_bool(0.5))]))
            .collect();
        bits.push((0, vec![1]));
        bits
    };
    let takes = random_bits(&mut rng, 40 * entries);
    let frees = random_bits(&mut rng, 40 * entries);
    let (ports, ray_fields) = ray_bench_ports(
        &[
            ("world_write", 1),
            ("world_pair", 2),
            ("world_thread", 5),
            ("word_a", 32),
            ("word_b", 32),
            ("enter", 1),
            ("enter_thread", 5),
            ("instance_id", 24),
            ("normal", 1),
            ("nz", 32),
            ("take", 1),
            ("free", 1),
        ],
        &[
            ("accepted", 1),
            ("normal_write", 1),
            ("busy_read", 1),
            ("root_write", 1),
            ("root_thread", 5),
            ("root", 26),
            ("cache_hit", 1),
            ("cache_miss", 1),
        ],
        "ray",
    );
    let stream = |name: &str, fields: &[&str], lines| InputStream {
        name: name.into(),
        fields: fields.iter().map(|s| s.to_string()).collect(),
        valid: None,
        ready: None,
        lines,
    };
    let bench = StreamBench {
        dut: top.into(),
        ports,
        streams: vec![
            stream(
                "world",
                &[
                    "world_write",
                    "world_pair",
                    "world_thread",
                    "word_a",
                    "word_b",
                ],
                writes,
            ),
            InputStream {
                valid: Some("enter".into()),
                ready: Some("accepted".into()),
                ..stream(
                    "entries",
                    &["enter_thread", "instance_id", "normal", "nz"],
                    offers,
                )
            },
            stream("takes", &["take"], takes),
            stream("frees", &["free"], frees),
        ],
        sinks: vec![
            OutputSink {
                name: "rays".into(),
                valid: "ray_write".into(),
                fields: ray_fields.clone(),
                expected: entered,
            },
            OutputSink {
                name: "roots".into(),
                valid: "root_write".into(),
                fields: vec!["root_thread".into(), "root".into()],
                expected: entered,
            },
            OutputSink {
                name: "normals".into(),
                valid: "normal_write".into(),
                fields: ray_fields,
                expected: entries - entered,
            },
            OutputSink {
                name: "busy_reads".into(),
                valid: "busy_read".into(),
                fields: vec!["busy_read".into()],
                expected: 0,
            },
            OutputSink {
                name: "hits".into(),
                valid: "cache_hit".into(),
                fields: vec!["cache_hit".into()],
                expected: entries - kinds.len(),
            },
            OutputSink {
                name: "misses".into(),
                valid: "cache_miss".into(),
                fields: vec!["cache_miss".into()],
                expected: kinds.len(),
            },
        ],
        max_cycles: 40 * entries as u64 + 1000,
    };
    let dir = tempfile::tempdir().unwrap();
    let run = run_stream_bench(&bench, &verilog, sim, dir.path()).unwrap();
    println!(
        "{sim} instance entry, {entries} entries: compile {:.1} s, run {:.1} s",
        run.compile_seconds, run.run_seconds
    );
    let (rays, roots, normals, busy_reads) =
        (&run.sinks[0], &run.sinks[1], &run.sinks[2], &run.sinks[3]);
    assert!(busy_reads.is_empty(), "{sim}: reads on a busy bus");
    assert_eq!(
        (run.sinks[4].len(), run.sinks[5].len()),
        (entries - kinds.len(), kinds.len()),
        "{sim}: instance cache hits and misses"
    );
    assert_eq!(rays.len(), entered, "{sim}: rays written");
    // The entries (not normals): their index (the thread is `i % 32`) and record.
    let enters: Vec<(usize, usize)> = records
        .iter()
        .zip(&normal_z)
        .enumerate()
        .filter(|(_, (_, z))| z.is_none())
        .map(|(i, (&r, _))| (i, r))
        .collect();
    let want_roots: Vec<Vec<u64>> = enters
        .iter()
        .map(|&(i, r)| {
            let root = bank[r * INSTANCE_WORDS + instance_word::ROOT] & ((1 << 26) - 1);
            vec![(i % 32) as u64, u64::from(root)]
        })
        .collect();
    assert_eq!(roots, &want_roots, "{sim}: roots given");
    let want_normals: Vec<Vec<u64>> = records
        .iter()
        .zip(&normal_z)
        .enumerate()
        .filter_map(|(i, (&r, z))| {
            let thread = i % 32;
            let at = r * INSTANCE_WORDS + instance_word::NORMAL_MATRIX;
            let m: &[u32; 9] = bank[at..at + 9].try_into().unwrap();
            let n = units::transform3(f, m, [world[thread][0], world[thread][1], (*z)?]);
            // The bench's ray ports: thread, o (not written for a normal), d, wake-up.
            Some(
                [thread as u64]
                    .into_iter()
                    .chain([0u64; 3])
                    .chain(n.map(u64::from))
                    .chain([1 << thread])
                    .collect(),
            )
        })
        .collect();
    let got_normals: Vec<Vec<u64>> = normals
        .iter()
        .map(|v| [&v[..1], &[0, 0, 0][..], &v[4..]].concat())
        .collect();
    assert_eq!(got_normals, want_normals, "{sim}: world normals");
    let mut bad = 0;
    for (ray, &(i, r)) in rays.iter().zip(&enters) {
        let thread = i % 32;
        let at = r * INSTANCE_WORDS + instance_word::WORLD_TO_OBJECT;
        let m: units::Mat34W = bank[at..at + 12].try_into().unwrap();
        let [ox, oy, oz, dx, dy, dz] = world[thread];
        let want_o = units::transform(f, &m, [ox, oy, oz], true);
        let want_d = units::transform(f, &m, [dx, dy, dz], false);
        let got_o: Vec<u32> = ray[1..4].iter().map(|&w| w as u32).collect();
        let got_d: Vec<u32> = ray[4..7].iter().map(|&w| w as u32).collect();
        if ray[0] != thread as u64 || got_o != want_o || got_d != want_d || ray[7] != 1 << thread {
            if bad < 5 {
                eprintln!(
                    "{sim} entry {i}: got thread {} o {got_o:x?} d {got_d:x?} wake-up {:x}, want {thread} {want_o:x?} {want_d:x?}",
                    ray[0], ray[7]
                );
            }
            bad += 1;
        }
    }
    assert_eq!(bad, 0, "{sim}: {bad} of {entries} entered rays differ");
}

/// Icarus with the default cache (512 sets of one way); Verilator with 8 sets of 4 ways, where
/// the 32 records and kinds (16 records, an entry's and a normal's) fill every way of every
/// set (set `{instance[7:0], normal} & 7`: four a set).
#[test]
fn instance_rays_e7m16_icarus() {
    instance_rays_case(120, 3501, Simulator::Icarus, 512, 1);
}

#[test]
fn instance_rays_e7m16_verilator() {
    instance_rays_case(400, 3502, Simulator::Verilator, 8, 4);
}

// ---------------------------------------------------------------------------------------
// Lint

/// `verilator --lint-only -Wall` is clean on every unit in e7m16 and e8m23 (with the waiver
/// block documented in `CORE_WAIVER` around the generated core, none on the tops).
#[test]
fn verilator_lint_wall_is_clean() {
    let dir = tempfile::tempdir().unwrap();
    for f in [Format::E7M16, Format::E8M23] {
        for unit in GeometryUnit::ALL {
            let rtl = geometry_unit_rtl(unit, f).unwrap();
            let path = dir.path().join(format!("{}.v", rtl.top));
            std::fs::write(&path, &rtl.verilog).unwrap();
            let report = sim::lint(&[path], &rtl.top).unwrap();
            assert!(report.is_clean(), "{}: {report}", rtl.top);
        }
    }
}
