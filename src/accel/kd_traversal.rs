//! Front-to-back kd-tree traversal in f64 (the reference renderer's), with a stack.
//!
//! Contract: [`KdTree::closest_hit`] returns the primitive with the smallest hit parameter in
//! `[t_min, t_max)` that the caller's test reports (ties: the first one found), and
//! [`KdTree::any_hit`] returns as soon as any primitive reports a hit (shadow rays). Both are
//! exact with respect to the caller's test as long as every primitive is listed in every leaf
//! its surface touches (which the builder guarantees), because:
//!
//! - child intervals are closed: a ray crossing a split plane at `t_split` visits the near
//!   child on `[t_near, t_split]` and the far one on `[t_split, t_far]`, and whenever
//!   `t_split` equals either end both children are visited; a ray lying in a split plane
//!   (direction component 0, origin on the plane) visits both children; zero direction
//!   components never divide;
//! - hits are not restricted to the current leaf's interval (a hit found early but lying
//!   farther on is kept); stack entries that start beyond the best hit are skipped, which
//!   ends the traversal once the best hit lies within the leaves already visited;
//! - rounding never loses a cell: the root box is grown by a relative `REL_SLACK` (1e-9) and
//!   every plane crossing `t_split` is treated as uncertain by `1e-9 (|t_split| +
//!   (|o| + |split|) / |d|)`, far above the rounding error of `t_split` and of a hit's `t`
//!   near the plane; within that slack both children are visited, so a ray through a vertex
//!   or an edge that rounding could place on either side of a plane sees both cells.
//!
//! The stack holds at most `depth` entries.

use super::kd_tree::{KdNode, KdTree};
use super::ray::Ray;
use super::triangle;
use glam::DVec3;

/// Relative slack of every interval decision (see the module doc).
const REL_SLACK: f64 = 1e-9;

/// Work of traversals (summed over rays): nodes visited (inner nodes and leaves) and primitive
/// tests made (after the mailbox).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraversalCounts {
    pub rays: u64,
    pub nodes: u64,
    pub tests: u64,
}

impl TraversalCounts {
    pub fn add(&mut self, other: &TraversalCounts) {
        self.rays += other.rays;
        self.nodes += other.nodes;
        self.tests += other.tests;
    }

    /// Nodes visited per ray (0 without rays).
    pub fn nodes_per_ray(&self) -> f64 {
        self.nodes as f64 / self.rays.max(1) as f64
    }

    /// Primitive tests per ray (0 without rays).
    pub fn tests_per_ray(&self) -> f64 {
        self.tests as f64 / self.rays.max(1) as f64
    }
}

/// A closest hit with a caller-defined payload (e.g. barycentrics, or the instance's triangle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdHit<P> {
    pub prim: u32,
    pub t: f64,
    pub payload: P,
}

/// A closest triangle hit: triangle id, ray parameter and barycentrics (hit point
/// `(1-u-v) A + u B + v C`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub prim: u32,
    pub t: f64,
    pub u: f64,
    pub v: f64,
}

/// The last few primitives tested along one ray. Re-testing a primitive can never change the
/// result (the segment of interest only shrinks), so skipping recent ones is pure savings; it
/// matters for the top level, where one test is a whole object traversal and an instance box
/// spans many leaves.
struct Mailbox {
    ids: [u32; 8],
    next: usize,
}

impl Mailbox {
    fn new() -> Self {
        Self {
            ids: [u32::MAX; 8],
            next: 0,
        }
    }

    /// True if `id` was tested recently; otherwise remembers it.
    fn seen(&mut self, id: u32) -> bool {
        if self.ids.contains(&id) {
            return true;
        }
        self.ids[self.next] = id;
        self.next = (self.next + 1) % self.ids.len();
        false
    }
}

/// Traversal stack: inline for the depths the builder produces by default, growing beyond.
struct Stack {
    inline: [(u32, f64, f64); 48],
    len: usize,
    spill: Vec<(u32, f64, f64)>,
}

impl Stack {
    fn new() -> Self {
        Self {
            inline: [(0, 0.0, 0.0); 48],
            len: 0,
            spill: Vec::new(),
        }
    }
    fn push(&mut self, e: (u32, f64, f64)) {
        if self.len < self.inline.len() {
            self.inline[self.len] = e;
            self.len += 1;
        } else {
            self.spill.push(e);
        }
    }
    fn pop(&mut self) -> Option<(u32, f64, f64)> {
        if let Some(e) = self.spill.pop() {
            return Some(e);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.inline[self.len])
    }
}

impl KdTree {
    /// Visits the leaves the ray segment `[t_min, t_max]` passes through, front to back.
    /// `visit(prims, t_near, t_far)` gets the leaf's primitives and the ray's parameter interval
    /// inside the leaf, and returns the (possibly lowered) end of the segment of interest:
    /// leaves starting at or after it are skipped (return `-inf` to stop). Returns the number
    /// of nodes visited (inner nodes and leaves).
    pub fn traverse_leaves(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut visit: impl FnMut(&[u32], f64, f64) -> f64,
    ) -> u64 {
        // Rounding must never lose a cell the ray touches, so all interval decisions are
        // widened by a relative slack (see the module doc).
        let scale = self
            .bounds
            .min
            .abs()
            .max(self.bounds.max.abs())
            .max_element();
        let root = self.bounds.expanded(scale * REL_SLACK);
        let Some((mut tn, mut tf)) = ray.intersect_aabb(&root, t_min, t_max) else {
            return 0;
        };
        let mut t_end = t_max;
        let mut stack = Stack::new();
        let mut node = 0u32;
        let mut visited = 0u64;
        loop {
            visited += 1;
            match self.nodes[node as usize] {
                KdNode::Inner {
                    axis,
                    split,
                    children,
                } => {
                    let a = axis as usize;
                    let (o, d) = (ray.origin[a], ray.dir[a]);
                    let (left, right) = (children, children + 1);
                    if d == 0.0 {
                        // The ray's coordinate is exactly `o` for every t: no rounding here.
                        if o < split {
                            node = left;
                        } else if o > split {
                            node = right;
                        } else {
                            stack.push((right, tn, tf));
                            node = left;
                        }
                        continue;
                    }
                    // The side the ray is on before crossing the plane.
                    let (first, second) = if d > 0.0 {
                        (left, right)
                    } else {
                        (right, left)
                    };
                    let t_split = (split - o) / d;
                    // Bound on the rounding error of t_split (and of a hit's t near the plane).
                    let slack = REL_SLACK * (t_split.abs() + (o.abs() + split.abs()) / d.abs());
                    if t_split - slack > tf {
                        node = first;
                    } else if t_split + slack < tn {
                        node = second;
                    } else {
                        // NaN-free even for huge t_split: f64::max/min ignore a NaN operand.
                        stack.push((second, tn.max(t_split - slack), tf));
                        node = first;
                        tf = tf.min(t_split + slack);
                    }
                }
                KdNode::Leaf { first, count } => {
                    let new_end = visit(self.leaf_prims(first, count), tn, tf);
                    if new_end < t_end {
                        t_end = new_end;
                    }
                    if t_end == f64::NEG_INFINITY {
                        return visited;
                    }
                    // Pending entries start at or after this leaf's end, except the second
                    // child of a plane the ray lies in; so rather than stopping once
                    // `t_end <= tf`, skip every entry that starts after `t_end`.
                    let limit = if t_end.is_finite() {
                        t_end + REL_SLACK * t_end.abs()
                    } else {
                        t_end
                    };
                    loop {
                        let Some((n, a, b)) = stack.pop() else {
                            return visited;
                        };
                        if a <= limit {
                            node = n;
                            tn = a;
                            tf = b.min(limit);
                            break;
                        }
                    }
                }
            }
        }
    }

    /// Closest hit with a payload. `test(prim, t_best)` reports a hit of `prim` at some
    /// `t` in `[t_min, t_best)` as `Some((t, payload))`.
    pub fn closest_hit_with<H>(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        test: impl FnMut(u32, f64) -> Option<(f64, H)>,
    ) -> Option<KdHit<H>> {
        self.closest_hit_counted(ray, t_min, t_max, &mut TraversalCounts::default(), test)
    }

    /// [`KdTree::closest_hit_with`], adding its nodes and tests (one ray) to `counts`.
    pub fn closest_hit_counted<H>(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        counts: &mut TraversalCounts,
        mut test: impl FnMut(u32, f64) -> Option<(f64, H)>,
    ) -> Option<KdHit<H>> {
        let mut best: Option<KdHit<H>> = None;
        let mut t_best = t_max;
        let mut mailbox = Mailbox::new();
        let mut tests = 0;
        counts.rays += 1;
        counts.nodes += self.traverse_leaves(ray, t_min, t_max, |prims, _, _| {
            for &p in prims {
                if mailbox.seen(p) {
                    continue;
                }
                tests += 1;
                if let Some((t, payload)) = test(p, t_best) {
                    if t >= t_min && t < t_best {
                        t_best = t;
                        best = Some(KdHit {
                            prim: p,
                            t,
                            payload,
                        });
                    }
                }
            }
            t_best
        });
        counts.tests += tests;
        best
    }

    /// Closest hit: `test(prim, t_best)` returns the hit parameter of `prim` if it is in
    /// `[t_min, t_best)`. Returns `(prim, t)`.
    pub fn closest_hit(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut test: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<(u32, f64)> {
        self.closest_hit_with(ray, t_min, t_max, |p, tb| test(p, tb).map(|t| (t, ())))
            .map(|h| (h.prim, h.t))
    }

    /// Closest hit over triangles (the tree must have been built from `tris`), with the
    /// barycentrics of [`triangle::intersect`]: the reference renderer's object-space query.
    pub fn closest_triangle_hit(
        &self,
        tris: &[[DVec3; 3]],
        ray: &Ray,
        t_min: f64,
        t_max: f64,
    ) -> Option<TriangleHit> {
        self.closest_hit_with(ray, t_min, t_max, |p, tb| {
            triangle::intersect(ray, &tris[p as usize], t_min, tb).map(|(t, u, v)| (t, (u, v)))
        })
        .map(|h| TriangleHit {
            prim: h.prim,
            t: h.t,
            u: h.payload.0,
            v: h.payload.1,
        })
    }

    /// Any triangle hit in `[t_min, t_max)` (shadow rays against an object tree).
    pub fn any_triangle_hit(
        &self,
        tris: &[[DVec3; 3]],
        ray: &Ray,
        t_min: f64,
        t_max: f64,
    ) -> Option<u32> {
        self.any_hit(ray, t_min, t_max, |p, tb| {
            triangle::intersect(ray, &tris[p as usize], t_min, tb).map(|h| h.0)
        })
    }

    /// Any hit in `[t_min, t_max)` (shadow rays): stops at the first primitive whose test
    /// reports one, and returns it.
    pub fn any_hit(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        test: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<u32> {
        self.any_hit_counted(ray, t_min, t_max, &mut TraversalCounts::default(), test)
    }

    /// [`KdTree::any_hit`], adding its nodes and tests (one ray) to `counts`.
    pub fn any_hit_counted(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        counts: &mut TraversalCounts,
        mut test: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<u32> {
        let mut found = None;
        let mut mailbox = Mailbox::new();
        let mut tests = 0;
        counts.rays += 1;
        counts.nodes += self.traverse_leaves(ray, t_min, t_max, |prims, _, _| {
            for &p in prims {
                if mailbox.seen(p) {
                    continue;
                }
                tests += 1;
                if let Some(t) = test(p, t_max) {
                    if t >= t_min && t < t_max {
                        found = Some(p);
                        return f64::NEG_INFINITY;
                    }
                }
            }
            t_max
        });
        counts.tests += tests;
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::kd_tree::{build_sah, KdParams};
    use crate::accel::primitive::Triangles;
    use crate::accel::test_meshes::*;
    use std::collections::BTreeMap;

    /// kd closest hit and any hit against brute force, with and without split clipping.
    fn check_against_brute_force(name: &str, tris: &[[DVec3; 3]], per_kind: usize, seed: u64) {
        let variants: Vec<KdParams> = [true, false]
            .map(|clip| KdParams {
                clip_splits: clip,
                ..KdParams::default()
            })
            .into();
        check_variants(name, tris, per_kind, seed, &variants);
    }

    fn check_variants(
        name: &str,
        tris: &[[DVec3; 3]],
        per_kind: usize,
        seed: u64,
        variants: &[KdParams],
    ) {
        println!("mesh {name}: {} triangles, ray seed {seed}", tris.len());
        for params in variants {
            let clip = params.clip_splits;
            let tree = build_sah(tris, params);
            tree.validate_against(&Triangles(tris))
                .unwrap_or_else(|e| panic!("{name} {params:?}: {e}"));
            let rays = ray_set(tris, &tree, per_kind, seed);
            let mut per_kind_counts: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
            let mut failures = Vec::new();
            for (i, &(kind, ray)) in rays.iter().enumerate() {
                let test = |p: u32, tb: f64| {
                    triangle::intersect(&ray, &tris[p as usize], 0.0, tb).map(|h| h.0)
                };
                let kd = tree.closest_hit(&ray, 0.0, f64::INFINITY, test);
                let bf = brute_closest(tris, &ray, 0.0, f64::INFINITY);
                let th = tree.closest_triangle_hit(tris, &ray, 0.0, f64::INFINITY);
                assert_eq!(
                    th.map(|h| (h.prim, h.t)),
                    kd,
                    "closest_triangle_hit differs"
                );
                if let Some(h) = th {
                    let (t, u, v) =
                        triangle::intersect(&ray, &tris[h.prim as usize], 0.0, f64::INFINITY)
                            .unwrap();
                    assert_eq!((h.t, h.u, h.v), (t, u, v));
                }
                let entry = per_kind_counts.entry(kind).or_default();
                entry.0 += 1;
                entry.1 += bf.is_some() as usize;
                let agree = match (kd, bf) {
                    (None, None) => true,
                    (Some((kp, kt)), Some((bp, bt))) => {
                        kp == bp || (kt - bt).abs() <= 1e-9 * bt.abs()
                    }
                    _ => false,
                };
                if !agree {
                    failures.push(format!("ray {i} ({kind}) {ray:?}: kd {kd:?} brute {bf:?}"));
                }
                // Any hit up to just before / just after the closest hit, or unbounded.
                let limit = match bf {
                    Some((_, t)) if i % 2 == 0 => t * (1.0 - 1e-6),
                    Some((_, t)) => t * (1.0 + 1e-6) + 1e-12,
                    None => f64::INFINITY,
                };
                let any = tree.any_hit(&ray, 0.0, limit, |p, tb| {
                    triangle::intersect(&ray, &tris[p as usize], 0.0, tb).map(|h| h.0)
                });
                let bf_any = brute_closest(tris, &ray, 0.0, limit);
                assert_eq!(
                    tree.any_triangle_hit(tris, &ray, 0.0, limit).is_some(),
                    any.is_some()
                );
                if let Some(p) = any {
                    assert!(
                        triangle::intersect(&ray, &tris[p as usize], 0.0, limit).is_some(),
                        "any_hit returned a triangle that does not hit"
                    );
                }
                if any.is_some() != bf_any.is_some() {
                    failures.push(format!(
                        "ray {i} ({kind}) {ray:?} any_hit to {limit}: kd {any:?} brute {bf_any:?}"
                    ));
                }
            }
            println!(
                "  clip={clip}: {} rays (kind: rays, brute-force hits) {per_kind_counts:?}",
                rays.len()
            );
            let hits: usize = per_kind_counts.values().map(|c| c.1).sum();
            assert!(
                hits * 5 > rays.len(),
                "{name}: only {hits} of {} rays hit; the test would prove little",
                rays.len()
            );
            assert!(
                failures.is_empty(),
                "{name} clip={clip}: {} disagreements, first: {:#?}",
                failures.len(),
                &failures[..failures.len().min(5)]
            );
        }
    }

    #[test]
    fn sphere_matches_brute_force() {
        check_against_brute_force("sphere(3)", &sphere(3), 300, 1);
    }

    #[test]
    fn soup_matches_brute_force() {
        check_against_brute_force("soup", &soup(3000, 2), 300, 2);
    }

    #[test]
    fn quad_lattice_matches_brute_force() {
        check_against_brute_force("quad lattice", &quad_lattice(6), 400, 3);
    }

    #[test]
    fn woody_matches_brute_force() {
        check_against_brute_force("woody", &public_mesh("woody.obj"), 200, 4);
    }

    #[test]
    fn cow_matches_brute_force() {
        check_against_brute_force("cow", &public_mesh("cow.obj"), 150, 5);
    }

    #[test]
    fn teapot_matches_brute_force() {
        check_against_brute_force("teapot", &public_mesh("teapot.obj"), 150, 6);
    }

    #[test]
    fn fandisk_matches_brute_force() {
        check_against_brute_force("fandisk", &public_mesh("fandisk.obj"), 100, 7);
    }

    /// Splits rounded into a reduced number format (as the layout stores them) are exactly
    /// representable there, and traversal stays exact.
    #[test]
    fn rounded_splits_match_brute_force() {
        use crate::fp::Format;
        for format in [Format::E7M16, Format::new(5, 6).unwrap()] {
            let params = KdParams {
                split_format: Some(format),
                ..KdParams::default()
            };
            for (name, tris) in [("sphere(3)", sphere(3)), ("cow", public_mesh("cow.obj"))] {
                let tree = build_sah(&tris, &params);
                let planes = split_planes(&tree);
                assert!(planes.len() > 100);
                for (_, s) in planes {
                    assert_eq!(format.to_f64(format.from_f64(s)), s, "{format:?}");
                }
                check_variants(name, &tris, 100, 12, std::slice::from_ref(&params));
            }
        }
    }

    #[test]
    fn degenerate_inputs_match_brute_force() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let cases: Vec<(&str, Vec<[DVec3; 3]>)> = vec![
            ("one triangle", vec![tri]),
            ("200 identical triangles", vec![tri; 200]),
            (
                "coplanar soup",
                soup(500, 9)
                    .into_iter()
                    .map(|t| t.map(|v| DVec3::new(v.x, v.y, 0.5)))
                    .collect(),
            ),
        ];
        for (name, tris) in cases {
            check_against_brute_force(name, &tris, 100, 8);
        }
    }

    /// The builder's real correctness property, checked directly: a triangle that reaches
    /// into the interior of a leaf box is listed in that leaf.
    #[test]
    fn leaves_list_every_triangle_entering_them() {
        use crate::accel::primitive::clip_triangle_bounds;
        for (name, tris) in [
            ("sphere(2)", sphere(2)),
            ("soup", soup(400, 11)),
            ("quad lattice", quad_lattice(4)),
        ] {
            for clip in [true, false] {
                let params = KdParams {
                    clip_splits: clip,
                    ..KdParams::default()
                };
                let tree = build_sah(&tris, &params);
                for leaf in tree.leaves() {
                    let inner = {
                        let shrink = leaf.bounds.extent() * 1e-9;
                        crate::accel::Aabb::new(leaf.bounds.min + shrink, leaf.bounds.max - shrink)
                    };
                    let listed = tree.leaf_prims(leaf.first, leaf.count);
                    for (i, tri) in tris.iter().enumerate() {
                        if clip_triangle_bounds(tri, &inner).is_some() {
                            assert!(
                                listed.contains(&(i as u32)),
                                "{name} clip={clip}: triangle {i} enters leaf {} {:?} but is not listed",
                                leaf.node,
                                leaf.bounds
                            );
                        }
                    }
                }
            }
        }
    }

    /// A primitive listed in many leaves is tested once per ray (mailbox).
    #[test]
    fn mailbox_tests_each_primitive_once() {
        use crate::accel::kd_tree::build_sah_boxes;
        use crate::accel::Aabb;
        let mut boxes = vec![Aabb::new(DVec3::ZERO, DVec3::new(100.0, 1.0, 1.0))];
        for i in 0..5 {
            let x = 10.0 + 20.0 * i as f64;
            boxes.push(Aabb::new(
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x + 1.0, 1.0, 1.0),
            ));
        }
        let tree = build_sah_boxes(&boxes, &KdParams::default());
        let listed = tree.prim_indices.iter().filter(|&&p| p == 0).count();
        assert!(
            listed > 2,
            "the big box should span several leaves: {tree:?}"
        );
        let ray = Ray::new(DVec3::new(-1.0, 0.5, 0.5), DVec3::X);
        let mut calls = vec![0; boxes.len()];
        let hit = tree.closest_hit(&ray, 0.0, f64::INFINITY, |p, _| {
            calls[p as usize] += 1;
            None
        });
        assert_eq!(hit, None);
        assert_eq!(calls, vec![1; boxes.len()]);
    }

    #[test]
    fn empty_tree_is_never_hit() {
        let tree = build_sah(&[], &KdParams::default());
        tree.validate().unwrap();
        let ray = Ray::new(DVec3::ZERO, DVec3::X);
        assert_eq!(
            tree.closest_hit(&ray, 0.0, f64::INFINITY, |_, _| Some(1.0)),
            None
        );
        assert_eq!(
            tree.any_hit(&ray, 0.0, f64::INFINITY, |_, _| Some(1.0)),
            None
        );
    }
}
