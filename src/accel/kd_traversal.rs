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
//!   farther on is kept); stack entries that start at or beyond the best hit are skipped,
//!   which ends the traversal once the best hit lies within the leaves already visited.
//!
//! The stack holds at most `depth` entries.

use super::kd_tree::{KdNode, KdTree};
use super::ray::Ray;

/// A closest hit with a caller-defined payload (e.g. barycentrics, or the instance's triangle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdHit<P> {
    pub prim: u32,
    pub t: f64,
    pub payload: P,
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
    /// leaves starting at or after it are skipped (return `-inf` to stop).
    pub fn traverse_leaves(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut visit: impl FnMut(&[u32], f64, f64) -> f64,
    ) {
        let Some((mut tn, mut tf)) = ray.intersect_aabb(&self.bounds, t_min, t_max) else {
            return;
        };
        let mut t_end = t_max;
        let mut stack = Stack::new();
        let mut node = 0u32;
        loop {
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
                    if t_split > tf {
                        node = first;
                    } else if t_split < tn {
                        node = second;
                    } else {
                        stack.push((second, t_split, tf));
                        node = first;
                        tf = t_split;
                    }
                }
                KdNode::Leaf { first, count } => {
                    let new_end = visit(self.leaf_prims(first, count), tn, tf);
                    if new_end < t_end {
                        t_end = new_end;
                    }
                    // Pending entries start at or after this leaf's end, except the second
                    // child of a plane the ray lies in; so rather than stopping once
                    // `t_end <= tf`, skip every entry that starts at or after `t_end`.
                    loop {
                        let Some((n, a, b)) = stack.pop() else {
                            return;
                        };
                        if a < t_end {
                            node = n;
                            tn = a;
                            tf = b.min(t_end);
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
        mut test: impl FnMut(u32, f64) -> Option<(f64, H)>,
    ) -> Option<KdHit<H>> {
        let mut best: Option<KdHit<H>> = None;
        let mut t_best = t_max;
        self.traverse_leaves(ray, t_min, t_max, |prims, _, _| {
            for &p in prims {
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

    /// Any hit in `[t_min, t_max)` (shadow rays): stops at the first primitive whose test
    /// reports one, and returns it.
    pub fn any_hit(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        mut test: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<u32> {
        let mut found = None;
        self.traverse_leaves(ray, t_min, t_max, |prims, _, _| {
            for &p in prims {
                if let Some(t) = test(p, t_max) {
                    if t >= t_min && t < t_max {
                        found = Some(p);
                        return f64::NEG_INFINITY;
                    }
                }
            }
            t_max
        });
        found
    }
}
