//! The kd-tree representation shared by object trees and the top-level tree, its parameters,
//! statistics and invariant checks. Built by [`super::sah_builder`], traversed by
//! [`super::kd_traversal`].
//!
//! # Representation (meant to be packed into memory words by the layout stage)
//!
//! `nodes[0]` is the root. An inner node splits its box by the plane `axis = split`; its left
//! child (`coord <= split`) is `nodes[children]` and its right child (`coord >= split`) is
//! `nodes[children + 1]`, so one index addresses both. A leaf lists
//! `prim_indices[first .. first + count]` (primitive ids: triangle indices in the input slice,
//! or instance indices for the top level).
//!
//! # Invariants (checked by [`KdTree::validate`])
//!
//! 1. Every node is reached from the root exactly once; `children > own index` and
//!    `children + 1 < nodes.len()` (so the tree is acyclic and has no shared subtrees).
//! 2. `axis < 3`; `split` is finite and lies strictly inside the node's box along `axis` (the
//!    box follows from `bounds` and the splits above), so both children have positive extent
//!    along `axis` wherever the parent does.
//! 3. Leaves' ranges are disjoint and together cover `prim_indices` exactly (the builder lays
//!    them out in depth-first order); within a leaf, ids are strictly increasing and
//!    `< num_prims`.
//! 4. `depth` is the largest leaf depth (root = 0).
//! 5. (With the primitives, [`KdTree::validate_against`]) every referenced primitive's bounds
//!    touch its leaf's closed box, and every primitive with finite bounds is referenced at least
//!    once.
//!    The builder guarantees the converse as well (a primitive is listed in every leaf whose box
//!    its surface touches), which is what makes traversal exact; the traversal tests check it.

use super::aabb::Aabb;
use super::primitive::{Boxes, KdPrimitives, Triangles};
use crate::fp::Format;
use glam::DVec3;
use thiserror::Error;

/// One kd-tree node; see the module doc for the invariants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KdNode {
    Inner {
        axis: u8,
        split: f64,
        /// Index of the left child; the right child is `children + 1`.
        children: u32,
    },
    Leaf {
        first: u32,
        count: u32,
    },
}

/// A kd-tree over `num_prims` primitives.
#[derive(Clone, Debug, PartialEq)]
pub struct KdTree {
    pub nodes: Vec<KdNode>,
    pub prim_indices: Vec<u32>,
    /// Box of the root: the union of all primitives with finite bounds (EMPTY if none).
    pub bounds: Aabb,
    /// Largest leaf depth (root = 0); a traversal stack needs at most `depth` entries.
    pub depth: u32,
    /// Number of input primitives (ids are `< num_prims`).
    pub num_prims: u32,
}

/// SAH builder parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct KdParams {
    /// Cost of traversing one inner node (SAH `C_t`).
    pub traversal_cost: f64,
    /// Cost of intersecting one primitive (SAH `C_i`).
    pub intersection_cost: f64,
    /// Factor applied to a split's cost when one child is empty (Wald & Havran use 0.8).
    pub empty_bonus: f64,
    /// Depth limit; `None` = `round(8 + 1.3 log2 N)` capped at [`KdParams::AUTO_DEPTH_CAP`].
    pub max_depth: Option<u32>,
    /// Leaves with more primitives than this are split even if the SAH prefers a leaf, as
    /// long as a plane exists that puts fewer primitives on each side (and depth allows).
    pub max_leaf_prims: u32,
    /// Clip straddling primitives to each child ("perfect splits").
    pub clip_splits: bool,
    /// If set, every candidate split position is first rounded into this number format
    /// (`format.to_f64(format.from_f64(p))`: round to nearest even, subnormals flushed to zero,
    /// exactly what the layout stores), and the rounded plane is the one evaluated and used.
    /// The layout then stores the planes exactly, and traversal in that format sees the very
    /// planes the primitives were classified against. Without it, perfect splits produce
    /// planes at clipped coordinates that no reduced format can represent.
    pub split_format: Option<Format>,
    /// Node budget: a tree over `n` primitives gets at most `nodes_per_prim * n` nodes (at
    /// least 1). The builder makes the splits it would make without a budget, those that save
    /// the most SAH cost first, while the budget pays for two more children (built mostly
    /// depth first, see `sah_builder`). `None`: no budget
    /// (the SAH, the leaf size cap and the depth limit alone decide). The default 3 keeps
    /// object trees within 3 nodes per triangle (the Stanford bunny took 19 without it).
    pub nodes_per_prim: Option<u32>,
    /// With `split_format`: wrap the tree in planes just outside its primitives' bounds (the
    /// format values next below and above them, so that no plane coincides with a
    /// primitive), each with an empty leaf outside, out of the node budget. The
    /// hardware starts its walk with the whole ray, not clipped to the root box, so without
    /// them every leaf on the box's surface reaches to infinity for it: cornell's primary rays
    /// tested 14.3 triangles each in the golden model, 3.9 in the f64 reference that clips.
    /// The root box (`KdTree::bounds`) is then a little larger than the primitives' bounds.
    pub root_clip: bool,
}

impl Default for KdParams {
    fn default() -> Self {
        Self {
            traversal_cost: 1.0,
            intersection_cost: 1.5,
            empty_bonus: 0.8,
            max_depth: None,
            max_leaf_prims: 32,
            clip_splits: true,
            split_format: None,
            nodes_per_prim: Some(3),
            root_clip: false,
        }
    }
}

impl KdParams {
    /// Cap on the automatic depth limit (bounds the hardware traversal stack).
    pub const AUTO_DEPTH_CAP: u32 = 32;

    /// Depth limit for `n` primitives.
    pub fn depth_limit(&self, n: usize) -> u32 {
        self.max_depth.unwrap_or_else(|| {
            let auto = (8.0 + 1.3 * (n.max(1) as f64).log2()).round() as u32;
            auto.min(Self::AUTO_DEPTH_CAP)
        })
    }

    /// Node budget of a tree over `n` primitives (`u64::MAX` without one).
    pub fn node_budget(&self, n: usize) -> u64 {
        self.nodes_per_prim
            .map_or(u64::MAX, |k| (u64::from(k) * n as u64).max(1))
    }
}

/// Tree statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct KdStats {
    /// SAH cost of the tree: `C_t * sum_inner SA(n)/SA(root) + C_i * sum_leaf count * SA(n)/SA(root)`
    /// (no empty bonus). A single leaf costs `C_i * N`.
    pub sah_cost: f64,
    pub depth: u32,
    pub nodes: usize,
    pub leaves: usize,
    pub empty_leaves: usize,
    pub max_tris_per_leaf: usize,
    /// Mean primitives per non-empty leaf.
    pub mean_tris_per_leaf: f64,
    /// Total primitive references (`prim_indices.len()`).
    pub references: usize,
}

/// A broken kd-tree invariant (numbers refer to the module doc).
#[derive(Debug, Error, PartialEq)]
pub enum KdTreeError {
    #[error("kd-tree has no nodes (invariant 1)")]
    NoNodes,
    #[error("node {node}: children index {children} out of order or out of range (invariant 1)")]
    BadChildren { node: usize, children: u32 },
    #[error("node {node} is reached {times} times from the root (invariant 1)")]
    Reached { node: usize, times: usize },
    #[error(
        "node {node}: axis {axis} / split {split} not strictly inside [{lo}, {hi}] (invariant 2)"
    )]
    BadSplit {
        node: usize,
        axis: u8,
        split: f64,
        lo: f64,
        hi: f64,
    },
    #[error("leaf {node}: range {first}+{count} breaks the tiling of prim_indices (invariant 3)")]
    BadLeafRange { node: usize, first: u32, count: u32 },
    #[error("leaf {node}: primitive id {prim} out of range or not increasing (invariant 3)")]
    BadPrim { node: usize, prim: u32 },
    #[error("depth field {stored} differs from the largest leaf depth {actual} (invariant 4)")]
    BadDepth { stored: u32, actual: u32 },
    #[error("leaf {node}: bounds of primitive {prim} do not touch the leaf box (invariant 5)")]
    PrimOutsideLeaf { node: usize, prim: u32 },
    #[error("primitive {prim} has finite bounds but is in no leaf (invariant 5)")]
    PrimMissing { prim: u32 },
    #[error("tree is over {tree} primitives but {given} were given (invariant 5)")]
    PrimCount { tree: u32, given: usize },
}

/// Builds an object kd-tree over triangles with the SAH (see [`super::sah_builder`]).
pub fn build_sah(tris: &[[DVec3; 3]], params: &KdParams) -> KdTree {
    super::sah_builder::build(&Triangles(tris), params)
}

/// Builds a kd-tree over boxes (the top-level tree over instance world bounds): the tree of
/// [`super::sah_builder`], built by [`super::box_builder`] (without a root clip, which only
/// the general builder makes).
pub fn build_sah_boxes(boxes: &[Aabb], params: &KdParams) -> KdTree {
    let root_clip = params.root_clip && params.split_format.is_some();
    if root_clip || boxes.len() >= super::box_builder::MAX_BOXES {
        super::sah_builder::build(&Boxes(boxes), params)
    } else {
        super::box_builder::build(boxes, params)
    }
}

/// A leaf as seen by a walk from the root.
#[derive(Clone, Copy, Debug)]
pub struct LeafInfo {
    pub node: usize,
    pub bounds: Aabb,
    pub depth: u32,
    pub first: u32,
    pub count: u32,
}

impl KdTree {
    /// FNV-1a over a tree's nodes (axis, split bits, children; leaf ranges) and primitive
    /// lists: equal fingerprints mean the same tree bit for bit (the builder's tests hold
    /// those of earlier builders' trees; `examples/kd_build_time.rs` prints it).
    pub fn fingerprint(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |x: u64| {
            for b in x.to_le_bytes() {
                h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
            }
        };
        for node in &self.nodes {
            match *node {
                KdNode::Inner {
                    axis,
                    split,
                    children,
                } => {
                    eat(u64::from(axis));
                    eat(split.to_bits());
                    eat(u64::from(children));
                }
                KdNode::Leaf { first, count } => {
                    eat(3);
                    eat(u64::from(first));
                    eat(u64::from(count));
                }
            }
        }
        for &p in &self.prim_indices {
            eat(u64::from(p));
        }
        h
    }

    /// Primitive ids of a leaf's range.
    pub fn leaf_prims(&self, first: u32, count: u32) -> &[u32] {
        &self.prim_indices[first as usize..(first + count) as usize]
    }

    /// Calls `f(node, box, depth)` for every node, parents before children.
    pub fn walk(&self, mut f: impl FnMut(usize, &Aabb, u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, self.bounds, 0u32)];
        while let Some((n, b, d)) = stack.pop() {
            f(n, &b, d);
            if let KdNode::Inner {
                axis,
                split,
                children,
            } = self.nodes[n]
            {
                let c = children as usize;
                if c + 1 < self.nodes.len() && c > n && axis < 3 {
                    let (l, r) = b.split(axis as usize, split);
                    stack.push((c + 1, r, d + 1));
                    stack.push((c, l, d + 1));
                }
            }
        }
    }

    /// All leaves with their boxes, in walk order.
    pub fn leaves(&self) -> Vec<LeafInfo> {
        let mut out = Vec::new();
        self.walk(|n, b, d| {
            if let KdNode::Leaf { first, count } = self.nodes[n] {
                out.push(LeafInfo {
                    node: n,
                    bounds: *b,
                    depth: d,
                    first,
                    count,
                });
            }
        });
        out
    }

    /// Checks invariants 1-4 of the module doc.
    pub fn validate(&self) -> Result<(), KdTreeError> {
        if self.nodes.is_empty() {
            return Err(KdTreeError::NoNodes);
        }
        let n = self.nodes.len();
        for (i, node) in self.nodes.iter().enumerate() {
            if let KdNode::Inner { children, .. } = *node {
                if (children as usize) <= i || children as usize + 1 >= n {
                    return Err(KdTreeError::BadChildren { node: i, children });
                }
            }
        }
        let mut reached = vec![0usize; n];
        let mut max_depth = 0;
        let mut bad = None;
        let mut leaves = Vec::new();
        self.walk(|i, b, d| {
            reached[i] += 1;
            match self.nodes[i] {
                KdNode::Inner { axis, split, .. } => {
                    let ok = axis < 3 && split.is_finite() && {
                        let a = axis as usize;
                        // A flat (or empty, for 0 primitives) box can hold no split.
                        b.min[a] < split && split < b.max[a]
                    };
                    if !ok && bad.is_none() {
                        let a = (axis as usize).min(2);
                        bad = Some(KdTreeError::BadSplit {
                            node: i,
                            axis,
                            split,
                            lo: b.min[a],
                            hi: b.max[a],
                        });
                    }
                }
                KdNode::Leaf { first, count } => {
                    max_depth = max_depth.max(d);
                    leaves.push((i, first, count));
                }
            }
        });
        if let Some(e) = bad {
            return Err(e);
        }
        if let Some((i, &times)) = reached.iter().enumerate().find(|(_, &t)| t != 1) {
            return Err(KdTreeError::Reached { node: i, times });
        }
        leaves.sort_by_key(|l| (l.1, l.2));
        let mut next = 0u64;
        for &(i, first, count) in &leaves {
            if first as u64 != next || first as u64 + count as u64 > self.prim_indices.len() as u64
            {
                return Err(KdTreeError::BadLeafRange {
                    node: i,
                    first,
                    count,
                });
            }
            next += count as u64;
            let prims = self.leaf_prims(first, count);
            for (j, &p) in prims.iter().enumerate() {
                if p >= self.num_prims || (j > 0 && prims[j - 1] >= p) {
                    return Err(KdTreeError::BadPrim { node: i, prim: p });
                }
            }
        }
        if next != self.prim_indices.len() as u64 {
            let &(i, first, count) = leaves.last().expect("a tree has a leaf");
            return Err(KdTreeError::BadLeafRange {
                node: i,
                first,
                count,
            });
        }
        if max_depth != self.depth {
            return Err(KdTreeError::BadDepth {
                stored: self.depth,
                actual: max_depth,
            });
        }
        Ok(())
    }

    /// Checks invariants 1-5 against the primitives the tree was built from.
    pub fn validate_against<P: KdPrimitives>(&self, prims: &P) -> Result<(), KdTreeError> {
        self.validate()?;
        if prims.len() != self.num_prims as usize {
            return Err(KdTreeError::PrimCount {
                tree: self.num_prims,
                given: prims.len(),
            });
        }
        let mut seen = vec![false; prims.len()];
        for leaf in self.leaves() {
            for &p in self.leaf_prims(leaf.first, leaf.count) {
                seen[p as usize] = true;
                if !prims.bounds(p as usize).overlaps(&leaf.bounds) {
                    return Err(KdTreeError::PrimOutsideLeaf {
                        node: leaf.node,
                        prim: p,
                    });
                }
            }
        }
        for (p, &s) in seen.iter().enumerate() {
            if !s && prims.bounds(p).is_finite() {
                return Err(KdTreeError::PrimMissing { prim: p as u32 });
            }
        }
        Ok(())
    }

    /// Statistics; `params` supplies the SAH cost constants.
    pub fn stats(&self, params: &KdParams) -> KdStats {
        let root_area = self.bounds.surface_area();
        // A root without area (no primitives, or all on one line) makes every node as likely
        // as the root.
        let prob = |b: &Aabb| {
            if root_area > 0.0 {
                b.surface_area() / root_area
            } else {
                1.0
            }
        };
        let mut s = KdStats {
            sah_cost: 0.0,
            depth: self.depth,
            nodes: self.nodes.len(),
            leaves: 0,
            empty_leaves: 0,
            max_tris_per_leaf: 0,
            mean_tris_per_leaf: 0.0,
            references: self.prim_indices.len(),
        };
        self.walk(|n, b, _| match self.nodes[n] {
            KdNode::Inner { .. } => s.sah_cost += params.traversal_cost * prob(b),
            KdNode::Leaf { count, .. } => {
                s.sah_cost += params.intersection_cost * count as f64 * prob(b);
                s.leaves += 1;
                if count == 0 {
                    s.empty_leaves += 1;
                }
                s.max_tris_per_leaf = s.max_tris_per_leaf.max(count as usize);
            }
        });
        let full = s.leaves - s.empty_leaves;
        if full > 0 {
            s.mean_tris_per_leaf = s.references as f64 / full as f64;
        }
        s
    }
}
