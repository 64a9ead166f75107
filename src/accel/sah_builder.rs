//! The O(N log N) SAH kd-tree builder of Wald & Havran, "On building fast kd-trees for ray
//! tracing, and on doing that in O(N log N)" (IEEE RT 2006), generic over [`KdPrimitives`].
//!
//! - Each node holds, per axis, an event list sorted by (position, kind) with kinds
//!   End < Planar < Start: a primitive spanning `[a, b]` on the axis gives Start at `a` and
//!   End at `b`; a flat one (`a == b`) gives one Planar event. The lists are sorted once at the
//!   root.
//! - One sweep per axis evaluates every event position strictly inside the node's box with the
//!   SAH `λ (C_t + C_i (P_L N_L + P_R N_R))`, `λ = empty_bonus` if a side is empty; primitives
//!   lying in the plane go to whichever side is cheaper.
//! - The best plane splits the node if it is cheaper than a leaf (`C_i N`), or if the leaf would
//!   exceed `max_leaf_prims` and some plane separates primitives; never below the depth limit.
//!   Without a node budget the tree is built depth first. Under one (`nodes_per_prim`) it is
//!   the tree best split first (the largest SAH saving) makes until the budget is spent,
//!   renumbered into the depth-first order; built best first for the top splits, then depth
//!   first below them, pruned at a guessed saving and checked by replaying best first's
//!   order on the savings found (`Builder::finish_pruned`).
//! - With `root_clip`, the tree sits below a chain of planes at the primitives' bounds that
//!   cut off empty space, for a walk that does not clip rays to the root box.
//! - Primitives are classified left / right / both from the split axis' events; the lists are
//!   split in linear time keeping their order. With `clip_splits` the "both" primitives are
//!   clipped to each child box and only their new events are sorted and merged in, so the total
//!   stays O(N log N).
//!
//! - With `split_format` the candidate planes are the event positions rounded into the
//!   hardware number format (a plane that rounds onto or outside the node's box is skipped),
//!   each scored once with the exact counts of the rounded plane, so that the SAH sees the
//!   split the classification makes (scoring a rounded plane with the counts of the position
//!   it came from let slivers that separate nothing look cheap and grew the layout's trees to
//!   16 nodes per triangle).
//!
//! Deterministic: no parallelism, ties broken by axis, position and primitive id.
//! Primitives with non-finite bounds are left out of the tree.
//!
//! Constant factors (profiled with callgrind on the Stanford bunny; each kept the trees bit
//! for bit, see the test `trees_are_those_of_the_builder_before_the_speed_ups`): an event
//! stores its position as order-preserving bits, so sorting and merging compare one integer;
//! the f64 sweep is compiled apart from the rounded one; the lists are split without a branch
//! on the side of each event; the clipped primitives' events are merged in by binary search
//! and block moves; boxes (the top level), whose clipping changes only the split axis, keep
//! their events on the other two axes instead of having them clipped, sorted and merged anew;
//! the root's lists are radix sorted; the pruned finish replays best first by selection on
//! the path minimum of the savings rather than with a heap, and turns the candidates a round
//! left out back into lists only for a round that needs them.

use super::aabb::Aabb;
use super::kd_tree::{KdNode, KdParams, KdTree};
use super::primitive::KdPrimitives;

const END: u8 = 0;
const PLANAR: u8 = 1;
const START: u8 = 2;

const SIDE_BOTH: u8 = 0;
const SIDE_LEFT: u8 = 1;
const SIDE_RIGHT: u8 = 2;

#[derive(Clone, Copy, Debug)]
struct Event {
    /// The position as [`ordered_bits`]: sorting and merging compare integers.
    key: u64,
    kind: u8,
    prim: u32,
}

/// The bits of `pos` mapped so that their unsigned order is `f64::total_cmp` order: negative
/// numbers with all bits flipped (a larger magnitude sorts first), others with the sign bit set
/// (above every negative).
pub(super) fn ordered_bits(pos: f64) -> u64 {
    let bits = pos.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

impl Event {
    fn new(pos: f64, kind: u8, prim: u32) -> Event {
        Event {
            key: ordered_bits(pos),
            kind,
            prim,
        }
    }

    /// The position (inverse of [`ordered_bits`]).
    fn pos(&self) -> f64 {
        f64::from_bits(if self.key >> 63 == 1 {
            self.key & !(1 << 63)
        } else {
            !self.key
        })
    }

    /// One integer whose order is the event lists' order: position, then kind, then
    /// primitive.
    fn sort_key(&self) -> u128 {
        (u128::from(self.key) << 64) | (u128::from(self.kind) << 32) | u128::from(self.prim)
    }
}

type Events = [Vec<Event>; 3];

/// Filler of event buffers before they are written.
const PAD_EVENT: Event = Event {
    key: 0,
    kind: END,
    prim: 0,
};

/// `list[..kept]` and `new` are sorted; merges `new` in so that `list[..kept + new.len()]` is
/// sorted, and truncates `list` to that length. From the back, each new event's place found by
/// binary search and the events after it moved as one block: the new events are few and
/// spread over the list, and comparing every moved event cost more than the rest of the split.
fn merge_into_tail(list: &mut Vec<Event>, kept: usize, new: &[Event]) {
    let mut end = kept;
    for (j, e) in new.iter().enumerate().rev() {
        let key = e.sort_key();
        let at = list[..end].partition_point(|x| x.sort_key() < key);
        list.copy_within(at..end, at + j + 1);
        list[at + j] = *e;
        end = at;
    }
    list.truncate(kept + new.len());
}

/// Sorts the root's events of one axis, pushed in primitive order, into the lists' order
/// ([`Event::sort_key`]) by a least significant digit first radix sort: its passes are stable,
/// so sorting by kind and then by position leaves the events of a position and kind in
/// primitive order. Comparison sorts spent 5% of the bunny's build on these three lists.
fn sort_root_events(list: &mut Vec<Event>) {
    const BITS: u32 = 11;
    const BUCKETS: usize = 1 << BITS;
    // The digits, least significant first: the kind, then the position 11 bits at a time.
    let digit = |e: &Event, d: usize| {
        if d == 0 {
            usize::from(e.kind)
        } else {
            (e.key >> ((d as u32 - 1) * BITS)) as usize & (BUCKETS - 1)
        }
    };
    let passes = 1 + 64usize.div_ceil(BITS as usize);
    let mut counts = vec![[0usize; BUCKETS]; passes];
    for e in list.iter() {
        for (d, c) in counts.iter_mut().enumerate() {
            c[digit(e, d)] += 1;
        }
    }
    let mut buffer = vec![PAD_EVENT; list.len()];
    for (d, c) in counts.iter_mut().enumerate() {
        // A digit every event shares orders nothing.
        if c.contains(&list.len()) {
            continue;
        }
        let mut at = 0;
        for k in c.iter_mut() {
            (*k, at) = (at, at + *k);
        }
        for e in list.iter() {
            let b = &mut c[digit(e, d)];
            buffer[*b] = *e;
            *b += 1;
        }
        std::mem::swap(list, &mut buffer);
    }
}

/// Appends the events of one primitive with bounds `b`.
fn push_events(events: &mut Events, prim: u32, b: &Aabb) {
    for (axis, list) in events.iter_mut().enumerate() {
        // `+ 0.0` turns -0.0 into +0.0 so that equal positions also sort as equal.
        let (lo, hi) = (b.min[axis] + 0.0, b.max[axis] + 0.0);
        if lo == hi {
            list.push(Event::new(lo, PLANAR, prim));
        } else {
            list.push(Event::new(lo, START, prim));
            list.push(Event::new(hi, END, prim));
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Plane {
    cost: f64,
    axis: usize,
    pos: f64,
    planar_left: bool,
}

/// The best planes a node's sweeps have found so far.
struct PlaneSearch {
    /// Primitives in the node.
    n: usize,
    best: Option<Plane>,
    /// Whether the leaf-size cap applies (`n > max_leaf_prims`), and with it the search for
    /// `best_separating`.
    track_separating: bool,
    /// Best plane that leaves fewer than `n` primitives on each side.
    best_separating: Option<Plane>,
}

struct Builder<'a, P: KdPrimitives> {
    prims: &'a P,
    params: &'a KdParams,
    depth_limit: u32,
    side: Vec<u8>,
    nodes: Vec<KdNode>,
    prim_indices: Vec<u32>,
    depth: u32,
    /// Event lists of finished nodes, kept for reuse (most nodes are small, and allocating
    /// their lists cost more than filling them).
    pool: Vec<Events>,
    /// The straddling primitives of the node being split.
    both: Vec<u32>,
    /// [`Builder::build_node`] splits no node that would make `nodes` longer than this; it
    /// sets `over_budget` instead and stops.
    node_cap: usize,
    over_budget: bool,
    /// Set when a straddling primitive touched neither child (conservative clipping makes
    /// this all but impossible): the pruned best-first build then falls back, since it
    /// takes a collapsed node's primitives from the leaves below it.
    lost_prim: bool,
    /// [`Builder::build_best_first`] pops every split itself (the reference the tests
    /// compare the pruned finish with).
    plain_best_first: bool,
    /// Whether the budget stopped [`Builder::build_best_first`] (candidates were left).
    budget_bound: bool,
}

/// Lists longer than this are freed rather than pooled (a handful of nodes near the root; the
/// pool then holds at most a few lists per level of the tree).
const POOL_MAX_EVENTS: usize = 1 << 12;

/// Builds a kd-tree over `prims` (see the module doc).
pub fn build<P: KdPrimitives>(prims: &P, params: &KdParams) -> KdTree {
    build_in_order(prims, params, false)
}

/// [`build`]; `best_first_only` makes every split under a node budget best first, without
/// the pruned depth-first finish (the reference the tests compare it with).
fn build_in_order<P: KdPrimitives>(prims: &P, params: &KdParams, best_first_only: bool) -> KdTree {
    let n = prims.len();
    let mut events: Events = [
        Vec::with_capacity(2 * n),
        Vec::with_capacity(2 * n),
        Vec::with_capacity(2 * n),
    ];
    let mut bounds = Aabb::EMPTY;
    let mut count = 0;
    for i in 0..n {
        let b = prims.bounds(i);
        if !b.is_finite() || b.is_empty() {
            continue;
        }
        bounds = bounds.union(&b);
        push_events(&mut events, i as u32, &b);
        count += 1;
    }
    for list in events.iter_mut() {
        sort_root_events(list);
    }
    let mut builder = Builder {
        prims,
        params,
        depth_limit: params.depth_limit(count),
        side: vec![SIDE_BOTH; n],
        nodes: vec![KdNode::Leaf { first: 0, count: 0 }],
        prim_indices: Vec::new(),
        depth: 0,
        pool: Vec::new(),
        both: Vec::new(),
        node_cap: usize::MAX,
        over_budget: false,
        lost_prim: false,
        plain_best_first: false,
        budget_bound: false,
    };
    let budget = params.node_budget(count);
    let (clips, root_box) = match params.split_format {
        Some(f) if params.root_clip && count > 0 => root_clips(f, &bounds),
        _ => (Vec::new(), bounds),
    };
    // A tree too small to pay for the planes goes without them.
    let chain = 2 * clips.len() as u64;
    let (clips, root_box) = if budget == u64::MAX || budget > chain {
        (clips, root_box)
    } else {
        (Vec::new(), bounds)
    };
    // What the planes kept cost (none when they were left out: the whole budget is the tree's).
    let chain = 2 * clips.len() as u64;
    let mut node = 0;
    for &(axis, pos, empty_below) in &clips {
        let plane = Plane {
            cost: 0.0,
            axis,
            pos,
            planar_left: false,
        };
        let children = builder.split_node(node, &plane);
        node = if empty_below { children + 1 } else { children };
    }
    // Below the planes the tree is built in the primitives' bounds, not in the slightly larger
    // box between the planes: the candidate planes lie strictly inside the bounds, as without
    // the planes. In the larger box a split could fall on the bounds themselves (a box
    // scene's faces) and put a plane back on the geometry.
    let voxel = bounds;
    let depth = clips.len() as u32;
    // The planes do not count against the depth the SAH tree may reach.
    builder.depth_limit += depth;
    builder.depth = depth;
    if budget == u64::MAX {
        builder.build_node(node, voxel, events, count, depth);
    } else {
        // Depth first while the tree fits the budget (the tree is then the one best first
        // would build, which makes every split the unbudgeted builder makes); best first only
        // once the budget binds. Best first keeps the lists of the whole frontier and visits
        // nodes out of order: it built the unbudgeted terrain's f64 tree about 3x slower.
        let budget = budget - chain;
        builder.plain_best_first = best_first_only;
        builder.build_best_first(node, voxel, events, count, depth, budget);
        if !builder.budget_bound {
            // The tree the depth-first build makes, whose clip planes' empty leaves start at
            // 0 (renumbered, they start where the primitives before them end): the layout
            // of a tree within its budget stays what it was.
            let mut at = 0;
            for &(_, _, empty_below) in &clips {
                let KdNode::Inner { children, .. } = builder.nodes[at] else {
                    break;
                };
                let (empty, next) = if empty_below {
                    (children as usize, children as usize + 1)
                } else {
                    (children as usize + 1, children as usize)
                };
                builder.nodes[empty] = KdNode::Leaf { first: 0, count: 0 };
                at = next;
            }
        }
    }
    KdTree {
        nodes: builder.nodes,
        prim_indices: builder.prim_indices,
        bounds: root_box,
        depth: builder.depth,
        num_prims: n as u32,
    }
}

/// The planes of [`KdParams::root_clip`] around `bounds` as (axis, position, whether the empty
/// leaf is below it), and the root box that holds them strictly inside. An axis along which
/// the rounded bounds are flat gets none.
///
/// Each plane lies strictly outside the bounds: the format value next below (above) the
/// bounds, not the bounds rounded outward, which are the bounds themselves when they are
/// representable. A plane on the bounds coincides with the faces of a box-shaped scene, and
/// the traversal sends a ray whose origin lies on a plane and that runs in it (or heads
/// outward) to the plane's empty side only ([`crate::units::traversal_step`]): such rays,
/// from points on a face, missed the adjacent faces they graze (the stress suite's axis rays
/// from origins on the box's faces, 42 of 3000 at e7m16 and e8m23). One step outside, every
/// origin within the bounds lies strictly on the tree's side of every plane, so the planes
/// send its ray into the tree first, as without them.
fn root_clips(f: crate::fp::Format, bounds: &Aabb) -> (Vec<(usize, f64, bool)>, Aabb) {
    let mut clips = Vec::new();
    let mut outer = *bounds;
    for axis in 0..3 {
        let (min, max) = (bounds.min[axis], bounds.max[axis]);
        if !(f.round_down(min) < f.round_up(max)) {
            continue;
        }
        let (lo, hi) = (f.below(min), f.above(max));
        let margin = (hi - lo) / 1024.0;
        let (out_lo, out_hi) = (lo - margin, hi + margin);
        if !(out_lo < lo && lo < hi && hi < out_hi) {
            continue;
        }
        outer.min[axis] = out_lo;
        outer.max[axis] = out_hi;
        clips.push((axis, lo, true));
        clips.push((axis, hi, false));
    }
    (clips, outer)
}

/// [`Builder::build_best_first`] pops `1 / PRUNE_TOP_SHARE` of the splits itself before it
/// guesses the saving of its last split and finishes pruned depth first.
const PRUNE_TOP_SHARE: usize = 256;
/// Fewer splits than this at the top are too few to guess from (small trees).
const PRUNE_MIN_TOP_POPS: usize = 32;

/// A guess somewhat below the saving of the last of `total_pops` best-first splits, from the
/// smallest savings after a quarter of the first `top_pops` splits and after all of them: the
/// number of splits saving at least `t` taken to fall as a power of `t`, and halved for a
/// margin. Negative infinity (no pruning) where that says nothing.
fn pruning_threshold(quarter: f64, lowest: f64, top_pops: usize, total_pops: usize) -> f64 {
    if !(lowest > 0.0 && quarter > lowest && quarter.is_finite()) {
        return f64::NEG_INFINITY;
    }
    // splits(t) ~ t^-alpha: four times the splits at `lowest` as at `quarter`.
    let alpha = 4f64.ln() / (quarter / lowest).ln();
    let guess = lowest * (total_pops as f64 / top_pops as f64).powf(-1.0 / alpha);
    if guess.is_finite() && guess > 0.0 {
        0.5 * guess
    } else {
        f64::NEG_INFINITY
    }
}

/// The candidates a pruned round left out, their lists copied into one buffer so that theirs
/// go back to the pool at once (kept apart, they drained it: the terrain's 131,072 triangles
/// built 40% slower).
#[derive(Default)]
struct LeftOut {
    events: Vec<Event>,
    /// Each candidate with its lists' lengths (`events` holds them one after the other).
    candidates: Vec<(Candidate, [usize; 3])>,
}

impl LeftOut {
    fn push(&mut self, c: &Candidate) {
        for list in &c.events {
            self.events.extend_from_slice(list);
        }
        let lens = [0, 1, 2].map(|a| c.events[a].len());
        let shell = Candidate {
            events: Default::default(),
            ..*c
        };
        self.candidates.push((shell, lens));
    }

    fn into_candidates<P: KdPrimitives>(self, builder: &mut Builder<P>) -> Vec<Candidate> {
        let mut at = 0;
        let mut out = Vec::with_capacity(self.candidates.len());
        for (mut c, lens) in self.candidates {
            c.events = builder.fresh();
            for (list, len) in c.events.iter_mut().zip(lens) {
                list.extend_from_slice(&self.events[at..at + len]);
                at += len;
            }
            out.push(c);
        }
        out
    }
}

/// A node waiting to be split: its lists and the plane its split would use.
struct Candidate {
    node: usize,
    voxel: Aabb,
    events: Events,
    n: usize,
    depth: u32,
    plane: Plane,
}

/// The inverse of [`ordered_bits`].
pub(super) fn from_ordered_bits(key: u64) -> f64 {
    f64::from_bits(if key >> 63 == 1 {
        key & !(1 << 63)
    } else {
        !key
    })
}

/// Renumbers a tree into the order [`Builder::build_node`] creates it in: depth first, left
/// before right, each node's children allocated when it is split, leaves' primitives laid out
/// in that order.
pub(super) fn depth_first_order(nodes: &[KdNode], prims: &[u32]) -> (Vec<KdNode>, Vec<u32>) {
    let (nodes, prims, _) = depth_first_order_kept(nodes, prims, None);
    (nodes, prims)
}

/// [`depth_first_order`], with the inner nodes that `keep` does not hold made leaves of the
/// primitives of the leaves below them (sorted, each once); also returns the depth of the
/// deepest leaf.
fn depth_first_order_kept(
    nodes: &[KdNode],
    prims: &[u32],
    keep: Option<&[bool]>,
) -> (Vec<KdNode>, Vec<u32>, u32) {
    fn gather(nodes: &[KdNode], prims: &[u32], old: usize, out: &mut Vec<u32>) {
        match nodes[old] {
            KdNode::Inner { children, .. } => {
                gather(nodes, prims, children as usize, out);
                gather(nodes, prims, children as usize + 1, out);
            }
            KdNode::Leaf { first, count } => {
                out.extend_from_slice(&prims[first as usize..(first + count) as usize]);
            }
        }
    }
    #[allow(clippy::too_many_arguments)]
    fn visit(
        nodes: &[KdNode],
        prims: &[u32],
        keep: Option<&[bool]>,
        old: usize,
        new: usize,
        depth: u32,
        max_depth: &mut u32,
        out: &mut (Vec<KdNode>, Vec<u32>),
    ) {
        match nodes[old] {
            KdNode::Inner { .. } if keep.is_some_and(|k| !k[old]) => {
                let f = out.1.len();
                gather(nodes, prims, old, &mut out.1);
                out.1[f..].sort_unstable();
                let mut w = f;
                for r in f..out.1.len() {
                    if w == f || out.1[r] != out.1[w - 1] {
                        out.1[w] = out.1[r];
                        w += 1;
                    }
                }
                out.1.truncate(w);
                out.0[new] = KdNode::Leaf {
                    first: f as u32,
                    count: (w - f) as u32,
                };
                *max_depth = (*max_depth).max(depth);
            }
            KdNode::Inner {
                axis,
                split,
                children,
            } => {
                let c = out.0.len();
                out.0[new] = KdNode::Inner {
                    axis,
                    split,
                    children: c as u32,
                };
                out.0.push(KdNode::Leaf { first: 0, count: 0 });
                out.0.push(KdNode::Leaf { first: 0, count: 0 });
                let d = depth + 1;
                visit(nodes, prims, keep, children as usize, c, d, max_depth, out);
                visit(
                    nodes,
                    prims,
                    keep,
                    children as usize + 1,
                    c + 1,
                    d,
                    max_depth,
                    out,
                );
            }
            KdNode::Leaf { first, count } => {
                let f = out.1.len();
                out.1
                    .extend_from_slice(&prims[first as usize..(first + count) as usize]);
                out.0[new] = KdNode::Leaf {
                    first: f as u32,
                    count,
                };
                *max_depth = (*max_depth).max(depth);
            }
        }
    }
    let mut out = (
        Vec::with_capacity(nodes.len()),
        Vec::with_capacity(prims.len()),
    );
    out.0.push(KdNode::Leaf { first: 0, count: 0 });
    let mut max_depth = 0;
    visit(nodes, prims, keep, 0, 0, 0, &mut max_depth, &mut out);
    (out.0, out.1, max_depth)
}

impl<P: KdPrimitives> Builder<'_, P> {
    /// The plane to split `node` at, with its lists back; or `None`, the node made a leaf.
    fn plane_or_leaf(
        &mut self,
        node: usize,
        voxel: &Aabb,
        events: Events,
        n: usize,
        depth: u32,
    ) -> Option<(Plane, Events)> {
        let plane = if n == 0 || depth >= self.depth_limit {
            None
        } else {
            self.choose_plane(voxel, &events, n)
        };
        let Some(plane) = plane else {
            self.make_leaf(node, &events, depth);
            self.recycle(events);
            return None;
        };
        Some((plane, events))
    }

    /// Builds the subtree at `node` depth first, unless a split would exceed `node_cap`:
    /// then sets `over_budget` and leaves the tree unfinished.
    fn build_node(&mut self, node: usize, voxel: Aabb, events: Events, n: usize, depth: u32) {
        if self.over_budget {
            self.recycle(events);
            return;
        }
        let Some((plane, events)) = self.plane_or_leaf(node, &voxel, events, n, depth) else {
            return;
        };
        if self.nodes.len() + 2 > self.node_cap {
            self.over_budget = true;
            self.recycle(events);
            return;
        }
        let (vl, vr) = voxel.split(plane.axis, plane.pos);
        let (left, nl, right, nr) = self.split_events(events, &plane, &vl, &vr);
        let children = self.split_node(node, &plane);
        // Build the left subtree while the right lists wait; depth-first keeps memory
        // proportional to one root-to-leaf path of lists.
        self.build_node(children, vl, left, nl, depth + 1);
        self.build_node(children + 1, vr, right, nr, depth + 1);
    }

    /// Turns `node` into an inner node at `plane` with two new (leaf) children; returns the
    /// left child's index.
    fn split_node(&mut self, node: usize, plane: &Plane) -> usize {
        let children = self.nodes.len();
        self.nodes[node] = KdNode::Inner {
            axis: plane.axis as u8,
            split: plane.pos,
            children: children as u32,
        };
        self.nodes.push(KdNode::Leaf { first: 0, count: 0 });
        self.nodes.push(KdNode::Leaf { first: 0, count: 0 });
        children
    }

    /// Builds the tree within `budget` nodes, best split first: the splits the unbudgeted
    /// builder would make, in the order of the SAH cost they save (the node's share of the
    /// root's area times leaf cost minus split cost), as long as the budget pays for two more
    /// children. A proportional split of the budget among children, tried before, left budget
    /// unused on one side while the other ran short, and its trees cost more (the cow's SAH
    /// cost 45.55 against 44.90). With budget to spare the tree is the unbudgeted one bit for
    /// bit (renumbered into its depth-first order).
    fn build_best_first(
        &mut self,
        node: usize,
        voxel: Aabb,
        events: Events,
        n: usize,
        depth: u32,
        budget: u64,
    ) {
        let mut heap = std::collections::BinaryHeap::new();
        let mut waiting: Vec<Option<Candidate>> = Vec::new();
        let root_area = voxel.surface_area();
        self.consider(
            node,
            voxel,
            events,
            n,
            depth,
            root_area,
            &mut heap,
            &mut waiting,
        );
        let mut used = 1;
        // The splits the budget pays for (`used + 2 <= budget` before each).
        let total_pops = (budget.saturating_sub(1) / 2) as usize;
        let top_pops = (total_pops / PRUNE_TOP_SHARE).max((total_pops / 16).min(512));
        let mut pops = 0;
        // The smallest saving popped after a quarter of `top_pops`, and after all of them.
        let (mut quarter, mut lowest) = (f64::INFINITY, f64::INFINITY);
        loop {
            if pops == top_pops
                && top_pops >= PRUNE_MIN_TOP_POPS
                && used + 2 <= budget
                && !self.plain_best_first
            {
                // The guess first, a lower one, then none but a cap at the budget (a tree
                // the budget does not bind wants every split there is); each round goes on
                // from the candidates the one before left out. If all fail, best first goes
                // on.
                let guess = pruning_threshold(quarter, lowest, top_pops, total_pops);
                let rounds = [(guess, 4), (guess / 16.0, 4), (f64::NEG_INFINITY, 1)];
                let r = self.finish_pruned(&heap, &waiting, used, budget, root_area, &rounds);
                if r {
                    return;
                }
            }
            if used + 2 > budget {
                break;
            }
            let Some((key, _, i)) = heap.pop() else { break };
            lowest = lowest.min(from_ordered_bits(key));
            pops += 1;
            if pops == top_pops / 4 {
                quarter = lowest;
            }
            let c: Candidate = waiting[i].take().expect("a candidate is split once");
            let (vl, vr) = c.voxel.split(c.plane.axis, c.plane.pos);
            let (left, nl, right, nr) = self.split_events(c.events, &c.plane, &vl, &vr);
            let children = self.split_node(c.node, &c.plane);
            used += 2;
            let d = c.depth + 1;
            self.consider(
                children,
                vl,
                left,
                nl,
                d,
                root_area,
                &mut heap,
                &mut waiting,
            );
            self.consider(
                children + 1,
                vr,
                right,
                nr,
                d,
                root_area,
                &mut heap,
                &mut waiting,
            );
        }
        self.budget_bound = !heap.is_empty();
        for c in waiting.into_iter().flatten() {
            self.make_leaf(c.node, &c.events, c.depth);
            self.recycle(c.events);
        }
        let (nodes, prims) = depth_first_order(&self.nodes, &self.prim_indices);
        self.nodes = nodes;
        self.prim_indices = prims;
    }

    /// Finishes [`Builder::build_best_first`] from the state its heap and candidates are in,
    /// with the locality of the depth-first build (best first keeps a whole frontier of lists
    /// and splits them out of order: the same tree took it 2.3 times as long as depth first).
    ///
    /// Best first splits a node exactly when the smallest saving on its path from the root
    /// is high enough: the savings it pops, taken as that minimum, never rise, so it splits
    /// every node whose minimum is above that of its last split before any other. So below
    /// each candidate the tree is built depth first, splitting only nodes whose saving is at
    /// least a round's threshold and recording every candidate's saving; best first's order
    /// is then replayed on the recorded savings (the same heap, keys and tie-breaks), and the
    /// nodes it does not split are made leaves of the primitives of the leaves below them.
    /// If the replay wants a split the threshold left out, the next round goes on from the
    /// candidates left out with its lower threshold. Returns false, the builder as it was,
    /// if the rounds run out, the pruned tree outgrows a round's cap (`cap` times the budget
    /// left), or a primitive was lost to clipping; the tree is otherwise best first's bit
    /// for bit.
    fn finish_pruned(
        &mut self,
        heap: &std::collections::BinaryHeap<(u64, std::cmp::Reverse<usize>, usize)>,
        waiting: &[Option<Candidate>],
        used: u64,
        budget: u64,
        root_area: f64,
        rounds: &[(f64, usize)],
    ) -> bool {
        let (nodes0, prims0, depth0) = (self.nodes.len(), self.prim_indices.len(), self.depth);
        self.over_budget = false;
        self.lost_prim = false;
        // The heap key of every candidate the pruned build evaluates.
        let mut keys: Vec<Option<u64>> = vec![None; nodes0];
        // The splits made so far (and clip planes); the rounds split the candidates among
        // nodes0 too.
        let made: Vec<bool> = self
            .nodes
            .iter()
            .map(|n| matches!(n, KdNode::Inner { .. }))
            .collect();
        let mut built = false;
        // The candidates the last round left out, for the next one.
        let mut left_out = LeftOut::default();
        for (round, &(threshold, cap)) in rounds.iter().enumerate() {
            // Overshooting the budget costs little (a threshold at half the right one grew
            // the bunny's tree by a fifth); beyond the cap the guess was far off.
            self.node_cap = nodes0.saturating_add(cap.saturating_mul((budget - used) as usize));
            // Lists are made of the left out ones only for a round that needs them (the
            // first usually succeeds: making them anyway cost the bunny's build 5%).
            let seeds: Vec<Candidate> = if round == 0 {
                waiting
                    .iter()
                    .flatten()
                    .map(|c| Candidate {
                        events: c.events.clone(),
                        ..*c
                    })
                    .collect()
            } else {
                std::mem::take(&mut left_out).into_candidates(self)
            };
            for c in seeds {
                let saving = self.saving(&c.voxel, c.n, &c.plane, root_area);
                self.build_pruned(
                    c,
                    saving,
                    threshold,
                    root_area,
                    &mut keys,
                    Some(&mut left_out),
                );
            }
            if self.over_budget || self.lost_prim {
                break;
            }
            // The pruned tree's splits with two more children fit the budget: best first
            // makes them all (they save at least `threshold`) and then one it left out, if
            // there is one; if there is none, the tree is the unbudgeted one.
            let fits = (self.nodes.len() - nodes0) as u64 + used + 2 <= budget;
            let keep = match (fits, left_out.candidates.is_empty()) {
                (true, false) => None,
                (true, true) => {
                    self.budget_bound = false;
                    Some(
                        self.nodes
                            .iter()
                            .map(|n| matches!(n, KdNode::Inner { .. }))
                            .collect(),
                    )
                }
                (false, _) => self.replay(heap, waiting, used, budget, &made, &keys),
            };
            if let Some(keep) = keep {
                let (nodes, prims, depth) =
                    depth_first_order_kept(&self.nodes, &self.prim_indices, Some(&keep));
                self.nodes = nodes;
                self.prim_indices = prims;
                self.depth = depth0.max(depth);
                built = true;
                break;
            }
        }
        self.node_cap = usize::MAX;
        self.over_budget = false;
        if !built {
            self.nodes.truncate(nodes0);
            for c in waiting.iter().flatten() {
                self.nodes[c.node] = KdNode::Leaf { first: 0, count: 0 };
            }
            self.prim_indices.truncate(prims0);
            self.depth = depth0;
        }
        built
    }

    /// Best first's remaining splits replayed on the savings the pruned build recorded: which
    /// nodes it splits (`made`: those it made before, and clip planes), or `None` if it wants
    /// a split the pruned build left out.
    fn replay(
        &mut self,
        heap: &std::collections::BinaryHeap<(u64, std::cmp::Reverse<usize>, usize)>,
        waiting: &[Option<Candidate>],
        mut used: u64,
        budget: u64,
        made: &[bool],
        keys: &[Option<u64>],
    ) -> Option<Vec<bool>> {
        let mut keep = made.to_vec();
        keep.resize(self.nodes.len(), false);
        if let Some(splits) = self.replay_by_path_minimum(heap, waiting, used, budget, keys) {
            for v in splits? {
                keep[v] = true;
            }
            return Some(keep);
        }
        let mut heap = heap.clone();
        let mut node_of: Vec<usize> = waiting
            .iter()
            .map(|c| c.as_ref().map_or(usize::MAX, |c| c.node))
            .collect();
        while used + 2 <= budget {
            let Some((_, _, i)) = heap.pop() else { break };
            let v = node_of[i];
            let KdNode::Inner { children, .. } = self.nodes[v] else {
                return None;
            };
            keep[v] = true;
            used += 2;
            for c in [children as usize, children as usize + 1] {
                if let Some(key) = keys[c] {
                    let j = node_of.len();
                    heap.push((key, std::cmp::Reverse(j), j));
                    node_of.push(c);
                }
            }
        }
        self.budget_bound = !heap.is_empty();
        Some(keep)
    }

    /// [`Builder::replay`]'s splits without its heap, where they follow from the savings alone:
    /// `Some(None)` if best first wants a split the pruned build left out, `None` if this
    /// cannot tell (the heap then decides). Its pops cost the bunny's build 6% (cache misses
    /// over a frontier of some 50,000 candidates).
    ///
    /// Each node's path minimum (the smallest saving from the heap's candidate down to it)
    /// never rises from one pop to the next: a popped node's is at most its key, the heap's
    /// largest, and at most its parent's, popped before every later pop. So best first's
    /// next `k` pops are the `k` candidates of the highest path minimum, unless the `k`-th
    /// ties with one left out, which only the heap's tie-break can settle.
    fn replay_by_path_minimum(
        &mut self,
        heap: &std::collections::BinaryHeap<(u64, std::cmp::Reverse<usize>, usize)>,
        waiting: &[Option<Candidate>],
        used: u64,
        budget: u64,
        keys: &[Option<u64>],
    ) -> Option<Option<Vec<usize>>> {
        // (path minimum, node) of every candidate the replay could pop.
        let mut found: Vec<(u64, usize)> = Vec::new();
        let mut stack: Vec<(u64, usize)> = heap
            .iter()
            .map(|&(key, _, i)| (key, waiting[i].as_ref().expect("in the heap").node))
            .collect();
        while let Some((e, v)) = stack.pop() {
            found.push((e, v));
            if let KdNode::Inner { children, .. } = self.nodes[v] {
                for c in [children as usize, children as usize + 1] {
                    if let Some(key) = keys[c] {
                        stack.push((e.min(key), c));
                    }
                }
            }
        }
        let pops = ((budget - used) / 2) as usize;
        if pops < found.len() && pops > 0 {
            found.select_nth_unstable_by(pops - 1, |a, b| b.0.cmp(&a.0));
            let cut = found[pops - 1].0;
            if found[pops..].iter().any(|f| f.0 == cut) {
                return None;
            }
        }
        let split = &found[..pops.min(found.len())];
        if split
            .iter()
            .any(|&(_, v)| !matches!(self.nodes[v], KdNode::Inner { .. }))
        {
            return Some(None);
        }
        // Candidates are left over exactly when the heap would be left non-empty.
        self.budget_bound = found.len() > pops;
        Some(Some(split.iter().map(|&(_, v)| v).collect()))
    }

    /// The subtree of a candidate (`plane`, `saving`) depth first, splitting the nodes whose
    /// saving is at least `threshold` (see [`Builder::finish_pruned`]) and recording the heap
    /// key of every candidate in `keys`.
    #[allow(clippy::too_many_arguments)]
    fn build_pruned(
        &mut self,
        c: Candidate,
        saving: f64,
        threshold: f64,
        root_area: f64,
        keys: &mut Vec<Option<u64>>,
        mut left_out: Option<&mut LeftOut>,
    ) {
        // `!(a >= b)`: a NaN saving is not split either.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        let below = !(saving >= threshold);
        if self.over_budget || below || self.nodes.len() + 2 > self.node_cap {
            if !below && !self.over_budget {
                self.over_budget = true;
            }
            if !self.over_budget {
                self.make_leaf(c.node, &c.events, c.depth);
                if let Some(out) = left_out {
                    out.push(&c);
                }
            }
            self.recycle(c.events);
            return;
        }
        let (vl, vr) = c.voxel.split(c.plane.axis, c.plane.pos);
        let (left, nl, right, nr) = self.split_events(c.events, &c.plane, &vl, &vr);
        let children = self.split_node(c.node, &c.plane);
        keys.resize(self.nodes.len(), None);
        let depth = c.depth + 1;
        for (child, voxel, events, n) in [(children, vl, left, nl), (children + 1, vr, right, nr)] {
            if let Some((plane, events)) = self.plane_or_leaf(child, &voxel, events, n, depth) {
                let s = self.saving(&voxel, n, &plane, root_area);
                keys[child] = Some(ordered_bits(s));
                let child = Candidate {
                    node: child,
                    voxel,
                    events,
                    n,
                    depth,
                    plane,
                };
                self.build_pruned(
                    child,
                    s,
                    threshold,
                    root_area,
                    keys,
                    left_out.as_deref_mut(),
                );
            }
        }
    }

    /// What splitting a candidate saves: its share of the root's area times its leaf cost
    /// minus its split cost (the best-first order).
    fn saving(&self, voxel: &Aabb, n: usize, plane: &Plane, root_area: f64) -> f64 {
        let prob = if root_area > 0.0 {
            voxel.surface_area() / root_area
        } else {
            1.0
        };
        prob * (self.params.intersection_cost * n as f64 - plane.cost)
    }

    /// Makes `node` a leaf, or a candidate for [`Builder::build_best_first`] if the
    /// unbudgeted builder would split it.
    #[allow(clippy::too_many_arguments)]
    fn consider(
        &mut self,
        node: usize,
        voxel: Aabb,
        events: Events,
        n: usize,
        depth: u32,
        root_area: f64,
        heap: &mut std::collections::BinaryHeap<(u64, std::cmp::Reverse<usize>, usize)>,
        waiting: &mut Vec<Option<Candidate>>,
    ) {
        let Some((plane, events)) = self.plane_or_leaf(node, &voxel, events, n, depth) else {
            return;
        };
        let saving = self.saving(&voxel, n, &plane, root_area);
        let i = waiting.len();
        heap.push((ordered_bits(saving), std::cmp::Reverse(i), i));
        waiting.push(Some(Candidate {
            node,
            voxel,
            events,
            n,
            depth,
            plane,
        }));
    }

    /// Empty event lists, from the pool when it has some.
    fn fresh(&mut self) -> Events {
        self.pool.pop().unwrap_or_default()
    }

    /// Returns small lists to the pool.
    fn recycle(&mut self, mut events: Events) {
        if events.iter().all(|l| l.capacity() <= POOL_MAX_EVENTS) {
            for l in events.iter_mut() {
                l.clear();
            }
            self.pool.push(events);
        }
    }

    fn make_leaf(&mut self, node: usize, events: &Events, depth: u32) {
        let first = self.prim_indices.len();
        // Every primitive has exactly one Start or Planar event per axis.
        self.prim_indices
            .extend(events[0].iter().filter(|e| e.kind != END).map(|e| e.prim));
        self.prim_indices[first..].sort_unstable();
        self.nodes[node] = KdNode::Leaf {
            first: first as u32,
            count: (self.prim_indices.len() - first) as u32,
        };
        self.depth = self.depth.max(depth);
    }

    /// The plane to split at, or `None` for a leaf.
    // `!(a < b)` deliberately treats NaN as "no".
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn choose_plane(&self, voxel: &Aabb, events: &Events, n: usize) -> Option<Plane> {
        let area = voxel.surface_area();
        if !(area > 0.0) {
            return None;
        }
        let mut search = PlaneSearch {
            n,
            best: None,
            track_separating: n > self.params.max_leaf_prims as usize,
            best_separating: None,
        };
        for (axis, list) in events.iter().enumerate() {
            // One sweep per number format, so that the f64 sweep does not test for rounding at
            // every event.
            match self.params.split_format {
                None => self.sweep(axis, list, voxel, 1.0 / area, &mut search, |p| p),
                Some(f) => self.sweep(axis, list, voxel, 1.0 / area, &mut search, |p| {
                    f.to_f64(f.from_f64(p))
                }),
            }
        }
        let leaf_cost = self.params.intersection_cost * n as f64;
        match search.best {
            Some(b) if b.cost < leaf_cost => Some(b),
            _ if search.track_separating => search.best_separating,
            _ => None,
        }
    }

    /// Scores the candidate planes of one axis (`list` is its sorted event list) into `search`.
    ///
    /// Candidate planes are the event positions rounded by `round` (into the split format;
    /// rounding is monotonic, so they come in order). Each is scored with the exact counts of
    /// the rounded plane: at an event position with that position's events, between two event
    /// positions with the counts of that gap.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn sweep(
        &self,
        axis: usize,
        list: &[Event],
        voxel: &Aabb,
        inv_area: f64,
        search: &mut PlaneSearch,
        round: impl Fn(f64) -> f64,
    ) {
        let (lo, hi) = (voxel.min[axis], voxel.max[axis]);
        if !(lo < hi) {
            return;
        }
        let e = voxel.extent();
        let (e1, e2) = (e[(axis + 1) % 3], e[(axis + 2) % 3]);
        let (cap, ring) = (e1 * e2, e1 + e2);
        let ct = self.params.traversal_cost;
        let ci = self.params.intersection_cost;
        let bonus = self.params.empty_bonus;
        // Counts go through i64: converting a signed integer is one instruction, an unsigned
        // 64-bit one a sequence, and this runs for every candidate plane.
        let cost = |pl: f64, pr: f64, nl: usize, nr: usize| {
            let c = ct + ci * (pl * nl as i64 as f64 + pr * nr as i64 as f64);
            if nl == 0 || nr == 0 {
                c * bonus
            } else {
                c
            }
        };
        // Scores the plane at `p` with `nl` / `nr` primitives strictly left / right of it and
        // `planars` lying in it, which go to the cheaper side.
        let mut consider = |p: f64, nl: usize, nr: usize, planars: usize| {
            if !(lo < p && p < hi) {
                return;
            }
            let pl = 2.0 * (cap + (p - lo) * ring) * inv_area;
            let pr = 2.0 * (cap + (hi - p) * ring) * inv_area;
            let cr = cost(pl, pr, nl, nr + planars);
            // Without primitives in the plane both sides cost the same.
            let (c, planar_left) = if planars == 0 {
                (cr, false)
            } else {
                let cl = cost(pl, pr, nl + planars, nr);
                if cl < cr {
                    (cl, true)
                } else {
                    (cr, false)
                }
            };
            let plane = Plane {
                cost: c,
                axis,
                pos: p,
                planar_left,
            };
            if search.best.is_none_or(|b| c < b.cost) {
                search.best = Some(plane);
            }
            if search.track_separating {
                let (left_n, right_n) = if planar_left {
                    (nl + planars, nr)
                } else {
                    (nl, nr + planars)
                };
                let n = search.n;
                if left_n < n && right_n < n && search.best_separating.is_none_or(|b| c < b.cost) {
                    search.best_separating = Some(plane);
                }
            }
        };
        // `last` is the last plane scored; `pending` a rounded plane beyond the events swept
        // so far.
        let (mut nl, mut nr) = (0usize, search.n);
        let mut last = f64::NEG_INFINITY;
        let mut pending: Option<f64> = None;
        let mut i = 0;
        while i < list.len() {
            let (key, p) = (list[i].key, list[i].pos());
            if let Some(c) = pending.filter(|&c| c < p) {
                consider(c, nl, nr, 0);
                last = c;
                pending = None;
            }
            // Counts of End, Planar and Start events at `p`.
            let (mut ends, mut planars, mut starts) = (0, 0, 0);
            // (Positions are never -0.0, so equal keys are equal positions.)
            while i < list.len() && list[i].key == key {
                let kind = list[i].kind;
                ends += usize::from(kind == END);
                planars += usize::from(kind == PLANAR);
                starts += usize::from(kind == START);
                i += 1;
            }
            let r = round(p);
            if r > last {
                if r < p {
                    // In the gap before `p`.
                    consider(r, nl, nr, 0);
                    last = r;
                } else if r == p {
                    consider(p, nl, nr - planars - ends, planars);
                    last = p;
                    pending = None;
                } else {
                    pending = Some(r);
                }
            }
            nr -= planars + ends;
            nl += starts + planars;
        }
        if let Some(c) = pending {
            consider(c, nl, nr, 0);
        }
    }

    /// Classifies the node's primitives against `plane` and returns the children's sorted
    /// event lists and primitive counts.
    fn split_events(
        &mut self,
        events: Events,
        plane: &Plane,
        vl: &Aabb,
        vr: &Aabb,
    ) -> (Events, usize, Events, usize) {
        let s = plane.pos;
        // One pass over the split axis' list classifies every primitive: a Start at or after
        // the plane puts it right; one before it makes it straddle until an End at or before
        // the plane (which comes later in the list) puts it left.
        let (mut nl, mut nr) = (0, 0);
        let mut both = std::mem::take(&mut self.both);
        both.clear();
        for e in &events[plane.axis] {
            let side = &mut self.side[e.prim as usize];
            let pos = e.pos();
            match e.kind {
                START if pos >= s => {
                    *side = SIDE_RIGHT;
                    nr += 1;
                }
                START => {
                    *side = SIDE_BOTH;
                    both.push(e.prim);
                }
                END if pos <= s => {
                    *side = SIDE_LEFT;
                    nl += 1;
                }
                PLANAR => {
                    if pos < s || (pos == s && plane.planar_left) {
                        *side = SIDE_LEFT;
                        nl += 1;
                    } else {
                        *side = SIDE_RIGHT;
                        nr += 1;
                    }
                }
                _ => {}
            }
        }
        // Those that ended before the plane are left, not straddling.
        both.retain(|&p| self.side[p as usize] == SIDE_BOTH);
        let clip = self.params.clip_splits;
        // Straddling primitives clipped to each child; their events are sorted separately and
        // merged in (there are few of them, so sorting them keeps the build O(N log N)).
        let mut new_left = self.fresh();
        let mut new_right = self.fresh();
        if clip {
            for &p in &both {
                let mut touched = false;
                if let Some(b) = self.prims.clipped_bounds(p as usize, vl) {
                    push_events(&mut new_left, p, &b);
                    nl += 1;
                    touched = true;
                }
                if let Some(b) = self.prims.clipped_bounds(p as usize, vr) {
                    push_events(&mut new_right, p, &b);
                    nr += 1;
                    touched = true;
                }
                self.lost_prim |= !touched;
            }
            for axis in 0..3 {
                if P::CLIPPING_KEEPS_OTHER_AXES && axis != plane.axis {
                    // The clipped bounds are the old ones on this axis: the primitives keep
                    // their events, on both sides (below).
                    new_left[axis].clear();
                    new_right[axis].clear();
                } else {
                    new_left[axis].sort_unstable_by_key(Event::sort_key);
                    new_right[axis].sort_unstable_by_key(Event::sort_key);
                }
            }
        } else {
            nl += both.len();
            nr += both.len();
        }
        self.both = both;
        let mut left = self.fresh();
        let mut right = self.fresh();
        // Whether an event of a primitive on each side goes to the left / right child's lists
        // (indexed by side); straddlers' own events go to both only without clipping.
        for axis in 0..3 {
            let both_too =
                usize::from(!clip || (P::CLIPPING_KEEPS_OTHER_AXES && axis != plane.axis));
            let to_left = [both_too, 1, 0];
            let to_right = [both_too, 0, 1];
            let list = &events[axis];
            // Every event is written to both lists and kept where its primitive goes: no
            // branch on the (unpredictable) side.
            let (l, r) = (&mut left[axis], &mut right[axis]);
            l.clear();
            l.resize(list.len() + new_left[axis].len(), PAD_EVENT);
            r.clear();
            r.resize(list.len() + new_right[axis].len(), PAD_EVENT);
            let (mut il, mut ir) = (0, 0);
            for e in list {
                let side = self.side[e.prim as usize] as usize;
                l[il] = *e;
                r[ir] = *e;
                il += to_left[side];
                ir += to_right[side];
            }
            merge_into_tail(l, il, &new_left[axis]);
            merge_into_tail(r, ir, &new_right[axis]);
        }
        self.recycle(new_left);
        self.recycle(new_right);
        self.recycle(events);
        (left, nl, right, nr)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::kd_tree::{build_sah, build_sah_boxes, KdTreeError};
    use crate::accel::primitive::{Boxes, Triangles};
    use crate::accel::test_meshes::*;
    use glam::DVec3;

    fn meshes() -> Vec<(&'static str, Vec<[DVec3; 3]>)> {
        vec![
            ("sphere(3)", sphere(3)),
            ("soup", soup(3000, 2)),
            ("quad lattice", quad_lattice(6)),
            ("woody", public_mesh("woody.obj")),
            ("cow", public_mesh("cow.obj")),
            ("teapot", public_mesh("teapot.obj")),
            ("fandisk", public_mesh("fandisk.obj")),
        ]
    }

    #[test]
    fn sah_cost_beats_a_single_leaf_and_trees_are_valid() {
        for (name, tris) in meshes() {
            assert!(tris.len() > 64);
            for clip in [true, false] {
                let params = KdParams {
                    clip_splits: clip,
                    ..KdParams::default()
                };
                let tree = build_sah(&tris, &params);
                tree.validate_against(&Triangles(&tris)).unwrap();
                let s = tree.stats(&params);
                let leaf_cost = params.intersection_cost * tris.len() as f64;
                println!("{name} ({} tris) clip={clip}: {s:?}", tris.len());
                assert!(
                    s.sah_cost < leaf_cost,
                    "{name}: SAH cost {} not below a single leaf's {leaf_cost}",
                    s.sah_cost
                );
                assert!(s.depth <= params.depth_limit(tris.len()));
                assert_eq!(s.references, tree.prim_indices.len());
                assert!(s.references >= tris.len());
            }
        }
    }

    #[test]
    fn builder_is_deterministic() {
        for (name, tris) in meshes() {
            let p = KdParams::default();
            assert_eq!(build_sah(&tris, &p), build_sah(&tris, &p), "{name}");
        }
    }

    /// The layout, and with it the golden model's and the hardware's frames, depends on the
    /// trees bit for bit: the builder's speed-ups (one-key event order, one sweep per number
    /// format, branch-free list split, block merge of clipped events) must build the very
    /// trees of the builder before them. The fingerprints (and node counts) were taken from
    /// that builder (commit b1e6984), whose node arrays the new one was also compared with
    /// node by node on every public mesh while it was written. They were retaken when the node
    /// budget went from a proportional split among children to best split first: the budget
    /// binds on all of these trees, and the new ones differ on purpose (lower SAH cost, e.g.
    /// the cow's 45.55 -> 44.90; `a_budget_that_does_not_bind_changes_nothing` checks that
    /// the order of the splits alone changes nothing).
    #[test]
    fn trees_are_those_of_the_builder_before_the_speed_ups() {
        let defaults = KdParams::default();
        let e7m16 = KdParams {
            split_format: Some(crate::fp::Format::E7M16),
            ..KdParams::default()
        };
        let unclipped = KdParams {
            clip_splits: false,
            ..KdParams::default()
        };
        let cases: [(&str, &KdParams, u64, usize); 9] = [
            ("cow.obj", &defaults, 0x6b01_3afa_2388_345e, 17411),
            ("cow.obj", &e7m16, 0xd411_1681_93d6_bfe6, 17411),
            ("cow.obj", &unclipped, 0x354f_7b7f_3e4f_c8f3, 17411),
            ("teapot.obj", &defaults, 0xd2ac_4efe_d908_25ca, 18959),
            ("teapot.obj", &e7m16, 0xd9f8_b066_09d5_6811, 18959),
            ("teapot.obj", &unclipped, 0x5ad7_d3a1_c714_6c9f, 18959),
            ("fandisk.obj", &defaults, 0xba8c_9e3f_e553_115d, 38837),
            ("fandisk.obj", &e7m16, 0xb038_1e86_cd58_9492, 38837),
            ("fandisk.obj", &unclipped, 0x613e_37a7_162a_00b0, 38837),
        ];
        let mut wrong = Vec::new();
        for (mesh, params, want, nodes) in cases {
            let tree = build_sah(&public_mesh(mesh), params);
            let got = (tree.fingerprint(), tree.nodes.len());
            if got != (want, nodes) {
                wrong.push(format!("{mesh} {params:?}: {:#x} {}", got.0, got.1));
            }
        }
        // The top level over the benchmark's 5,622 instance boxes (seed 2).
        let boxes = crate::accel::bench::random_instance_boxes(5622, 2);
        let tree = build_sah_boxes(&boxes, &defaults);
        let got = (tree.fingerprint(), tree.nodes.len());
        if got != (0xa867_610a_7a3d_1352, 16865) {
            wrong.push(format!("top level: {:#x} {}", got.0, got.1));
        }
        assert!(wrong.is_empty(), "{wrong:#?}");
    }

    #[test]
    fn degenerate_inputs_give_valid_trees() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let p = DVec3::new(0.3, -2.0, 5.0);
        let nan = DVec3::new(f64::NAN, 0.0, 0.0);
        let mut with_nan = sphere(1);
        with_nan.insert(7, [nan, DVec3::X, DVec3::Y]);
        let cases: Vec<(&str, Vec<[DVec3; 3]>)> = vec![
            ("no triangles", vec![]),
            ("one triangle", vec![tri]),
            ("identical triangles", vec![tri; 300]),
            (
                "coplanar triangles",
                soup(400, 3)
                    .into_iter()
                    .map(|t| t.map(|v| DVec3::new(v.x, 2.0, v.z)))
                    .collect(),
            ),
            ("point triangles", vec![[p; 3]; 50]),
            (
                "collinear triangles",
                (0..60)
                    .map(|i| {
                        let x = i as f64 * 0.1;
                        [
                            DVec3::new(x, 1.0, 1.0),
                            DVec3::new(x + 0.5, 1.0, 1.0),
                            DVec3::new(x + 0.2, 1.0, 1.0),
                        ]
                    })
                    .collect(),
            ),
            ("a NaN triangle among good ones", with_nan),
        ];
        for (name, tris) in cases {
            for clip in [true, false] {
                let params = KdParams {
                    clip_splits: clip,
                    ..KdParams::default()
                };
                let tree = build_sah(&tris, &params);
                tree.validate_against(&Triangles(&tris))
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                println!("{name} clip={clip}: {:?}", tree.stats(&params));
            }
        }
        // The NaN triangle is left out, everything else is referenced (checked above).
        let mut with_nan = sphere(1);
        with_nan.insert(7, [nan, DVec3::X, DVec3::Y]);
        assert!(!build_sah(&with_nan, &KdParams::default())
            .prim_indices
            .contains(&7));
        // Boxes: none, identical, flat.
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        let flat = Aabb::new(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0));
        for boxes in [vec![], vec![b; 100], vec![flat; 10], vec![b, flat]] {
            let tree = build_sah_boxes(&boxes, &KdParams::default());
            tree.validate_against(&Boxes(&boxes)).unwrap();
        }
    }

    /// Two far-apart clusters: the root must cut the empty gap between them.
    #[test]
    fn root_split_lies_in_the_gap_between_clusters() {
        let a = soup(100, 4);
        let b: Vec<_> = soup(100, 5)
            .into_iter()
            .map(|t| t.map(|v| v + DVec3::new(10.0, 0.0, 0.0)))
            .collect();
        let max_a = a.iter().flatten().map(|v| v.x).fold(f64::MIN, f64::max);
        let min_b = b.iter().flatten().map(|v| v.x).fold(f64::MAX, f64::min);
        let tris: Vec<_> = a.into_iter().chain(b).collect();
        let tree = build_sah(&tris, &KdParams::default());
        match tree.nodes[0] {
            KdNode::Inner { axis, split, .. } => {
                assert_eq!(axis, 0);
                assert!(
                    split >= max_a && split <= min_b,
                    "split {split} not in [{max_a}, {min_b}]"
                );
            }
            n => panic!("root is {n:?}"),
        }
    }

    /// The default node budget holds every tree to 3 nodes per triangle, in f64 and with planes
    /// rounded into the paper's format, where the SAH alone takes more.
    #[test]
    fn node_budget_keeps_three_nodes_per_triangle() {
        let cases = [
            ("sphere(5)", sphere(5)),
            (
                "terrain 64x64",
                crate::accel::bench::heightfield_triangles(64, 1),
            ),
            ("soup", soup(3000, 2)),
        ];
        for (name, tris) in cases {
            let unlimited = KdParams {
                nodes_per_prim: None,
                ..KdParams::default()
            };
            let free = build_sah(&tris, &unlimited).nodes.len();
            for format in [None, Some(crate::fp::Format::E7M16)] {
                let params = KdParams {
                    split_format: format,
                    ..KdParams::default()
                };
                let tree = build_sah(&tris, &params);
                tree.validate_against(&Triangles(&tris)).unwrap();
                let per_tri = tree.nodes.len() as f64 / tris.len() as f64;
                println!(
                    "{name} {format:?}: {per_tri:.3} nodes per triangle ({free} without a budget)"
                );
                assert!(per_tri <= 3.0, "{name} {format:?}: {per_tri}");
                // The budget is spent where the SAH wants it, not left unused.
                if free > 3 * tris.len() {
                    assert!(tree.nodes.len() + 2 > 3 * tris.len(), "{name} {format:?}");
                }
            }
            if name != "terrain 64x64" {
                assert!(
                    free > 3 * tris.len(),
                    "{name}: the budget is not what limits"
                );
            }
        }
    }

    /// With budget to spare the best-first build is the depth-first one, node for node; and
    /// a budget that binds gives the tree of best first alone.
    #[test]
    fn a_budget_that_does_not_bind_changes_nothing() {
        for (name, tris) in meshes() {
            let free = KdParams {
                nodes_per_prim: None,
                ..KdParams::default()
            };
            let ample = KdParams {
                nodes_per_prim: Some(1000),
                ..KdParams::default()
            };
            let tree = build_sah(&tris, &free);
            assert_eq!(tree, build_sah(&tris, &ample), "{name}");
            assert_eq!(
                tree,
                build_in_order(&Triangles(&tris), &ample, true),
                "{name}"
            );
            for per_prim in [1, 2, 3] {
                let tight = KdParams {
                    nodes_per_prim: Some(per_prim),
                    ..KdParams::default()
                };
                assert_eq!(
                    build_sah(&tris, &tight),
                    build_in_order(&Triangles(&tris), &tight, true),
                    "{name} {per_prim}"
                );
            }
            // Wrapped in the root clip's planes too, whose empty leaves start at 0 in the
            // depth-first build (the layout's node bank holds that field).
            let clipped = |nodes_per_prim| KdParams {
                nodes_per_prim,
                split_format: Some(crate::fp::Format::E7M16),
                root_clip: true,
                ..KdParams::default()
            };
            let tree = build_sah(&tris, &clipped(None));
            assert_eq!(tree, build_sah(&tris, &clipped(Some(1000))), "{name} clip");
            assert_eq!(
                tree,
                build_in_order(&Triangles(&tris), &clipped(Some(1000)), true),
                "{name} clip"
            );
        }
    }

    /// The pruned depth-first finish of the budgeted build is best first's tree bit for bit,
    /// whichever of its rounds succeeds: budgets that bind hard, loosely and not at all, on
    /// triangles with and without clipping and rounding, and on boxes.
    #[test]
    fn pruned_finish_is_best_first() {
        let mut cases: Vec<(String, Vec<[DVec3; 3]>)> = vec![
            ("sphere(5)".into(), sphere(5)),
            (
                "terrain 48x48".into(),
                crate::accel::bench::heightfield_triangles(48, 3),
            ),
        ];
        cases.extend(
            meshes()
                .into_iter()
                .map(|(name, tris)| (name.to_string(), tris)),
        );
        for (name, tris) in &cases {
            for per_prim in [1, 2, 3, 5, 8] {
                for (clip, format) in [
                    (true, None),
                    (false, None),
                    (true, Some(crate::fp::Format::E7M16)),
                ] {
                    let params = KdParams {
                        nodes_per_prim: Some(per_prim),
                        clip_splits: clip,
                        split_format: format,
                        ..KdParams::default()
                    };
                    let tree = build_sah(tris, &params);
                    assert_eq!(
                        tree,
                        build_in_order(&Triangles(tris), &params, true),
                        "{name} {per_prim} {clip} {format:?}"
                    );
                }
            }
        }
        for count in [300, 2000, 5622] {
            let boxes = crate::accel::bench::random_instance_boxes(count, 7);
            for per_prim in [1, 3, 6] {
                let params = KdParams {
                    nodes_per_prim: Some(per_prim),
                    ..KdParams::default()
                };
                let tree = build_sah_boxes(&boxes, &params);
                tree.validate_against(&Boxes(&boxes)).unwrap();
                assert_eq!(
                    tree,
                    build_in_order(&Boxes(&boxes), &params, true),
                    "{count} boxes {per_prim}"
                );
            }
        }
    }

    /// The bundled terrain's object tree (131,072 triangles; the default budget of 3 nodes per
    /// triangle does not bind, 2.70) is the same tree unbudgeted, under the budget ([`build`]:
    /// best first for the top splits, then depth first) and best first alone: the budget's
    /// rounds change the order of the splits, never a tree it does not bind. (Their times:
    /// `cargo run --release --example kd_build_time -- 3 terrain`.)
    #[test]
    fn a_tree_the_budget_does_not_bind_is_the_unbudgeted_tree() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/terrain.toml");
        let scene = crate::scene::Scene::load(&path).unwrap();
        let tris = &scene.objects[0].triangles;
        let free = KdParams {
            nodes_per_prim: None,
            ..KdParams::default()
        };
        let budget = KdParams::default();
        let unbudgeted = build(&Triangles(tris), &free);
        assert!(unbudgeted.nodes.len() < 3 * tris.len());
        assert_eq!(unbudgeted, build(&Triangles(tris), &budget));
        assert_eq!(unbudgeted, build_in_order(&Triangles(tris), &budget, true));
    }

    /// The root clip: six planes one format step outside the bounds, each with an
    /// empty leaf outside, paid for by the budget; the tree below is still exact (invariant 5)
    /// and the walk of a ray outside the bounds ends in empty leaves only.
    #[test]
    fn root_clip_wraps_the_tree_in_the_rounded_bounds() {
        let f = crate::fp::Format::E7M16;
        let tris = public_mesh("cow.obj");
        let plain = KdParams {
            split_format: Some(f),
            ..KdParams::default()
        };
        let clipped = KdParams {
            root_clip: true,
            ..plain.clone()
        };
        let tree = build_sah(&tris, &clipped);
        tree.validate_against(&Triangles(&tris)).unwrap();
        assert!(tree.nodes.len() <= 3 * tris.len());
        let b = build_sah(&tris, &plain).bounds;
        let mut node = 0;
        for i in 0..6 {
            let KdNode::Inner {
                axis,
                split,
                children,
            } = tree.nodes[node]
            else {
                panic!("clip plane {i} missing");
            };
            let (a, c) = (axis as usize, children as usize);
            let (below, want, next) = if i % 2 == 0 {
                (c, f.below(b.min[a]), c + 1)
            } else {
                (c + 1, f.above(b.max[a]), c)
            };
            // Strictly outside the bounds, one step beyond them rounded outward at most.
            assert!(want < b.min[a] || want > b.max[a], "plane {i}");
            assert!(
                want >= f.below(f.round_down(b.min[a])) && want <= f.above(f.round_up(b.max[a])),
                "plane {i}"
            );
            assert_eq!((a, split), (i / 2, want), "plane {i}");
            assert!(
                matches!(tree.nodes[below], KdNode::Leaf { count: 0, .. }),
                "plane {i}: the outside is not an empty leaf"
            );
            node = next;
        }
        // Too small a budget for the planes: none, and the tree gets the whole budget (the
        // planes' cost was taken from it, 3 - 6 overflowed).
        let one = vec![tris[0]];
        assert_eq!(build_sah(&one, &clipped).nodes.len(), 1);
        let two = vec![
            [
                DVec3::ZERO,
                DVec3::new(1.0, 0.1, 0.2),
                DVec3::new(0.1, 1.0, 0.3),
            ],
            [
                DVec3::new(5.0, 5.0, 5.0),
                DVec3::new(6.0, 5.1, 5.2),
                DVec3::new(5.1, 6.0, 5.3),
            ],
        ];
        let tree = build_sah(&two, &clipped);
        tree.validate_against(&Triangles(&two)).unwrap();
        let n = tree.nodes.len();
        assert!(n > 1 && n <= 6, "{n} nodes: {tree:?}");
        assert!(
            !matches!(tree.nodes[0], KdNode::Inner { split, .. } if split < 0.0 || split > 6.0),
            "no planes: {tree:?}"
        );
    }

    /// Rounded split planes are scored with the counts of the rounded plane: the tree in e7m16
    /// is about as big as the f64 one (scored with the counts of the unrounded position, the
    /// cow's was twice as big, 16.9 nodes per triangle against 8.4).
    #[test]
    fn rounded_planes_are_scored_with_their_own_counts() {
        let tris = public_mesh("cow.obj");
        let f64_params = KdParams {
            nodes_per_prim: None,
            ..KdParams::default()
        };
        let rounded = KdParams {
            split_format: Some(crate::fp::Format::E7M16),
            ..f64_params.clone()
        };
        let exact = build_sah(&tris, &f64_params);
        let tree = build_sah(&tris, &rounded);
        tree.validate_against(&Triangles(&tris)).unwrap();
        let (a, b) = (exact.nodes.len() as f64, tree.nodes.len() as f64);
        println!("cow: {a} nodes in f64, {b} in e7m16");
        assert!(b < 1.1 * a, "{b} nodes in e7m16 against {a} in f64");
    }

    #[test]
    fn depth_limit() {
        let p = KdParams::default();
        assert_eq!(p.depth_limit(0), 8);
        assert_eq!(p.depth_limit(1), 8);
        assert_eq!(p.depth_limit(1024), 21);
        assert_eq!(p.depth_limit(1 << 30), KdParams::AUTO_DEPTH_CAP);
        let tris = sphere(3);
        for d in [0, 1, 4] {
            let params = KdParams {
                max_depth: Some(d),
                ..KdParams::default()
            };
            let tree = build_sah(&tris, &params);
            tree.validate_against(&Triangles(&tris)).unwrap();
            assert_eq!(
                tree.depth, d,
                "the sphere is worth splitting down to the limit"
            );
        }
    }

    /// With intersections almost free the SAH wants one leaf; the leaf-size cap must still
    /// split separable triangles into leaves of at most `max_leaf_prims`.
    #[test]
    fn leaf_size_cap_forces_splits() {
        let tris: Vec<_> = (0..200)
            .map(|i| {
                let x = i as f64;
                [
                    DVec3::new(x, 0.0, 0.0),
                    DVec3::new(x + 0.5, 0.0, 0.0),
                    DVec3::new(x, 1.0, 0.5),
                ]
            })
            .collect();
        let cheap = KdParams {
            intersection_cost: 0.001,
            max_leaf_prims: 1000,
            ..KdParams::default()
        };
        let tree = build_sah(&tris, &cheap);
        assert_eq!(tree.nodes.len(), 1, "SAH alone keeps one leaf");
        let capped = KdParams {
            max_leaf_prims: 8,
            ..cheap
        };
        let tree = build_sah(&tris, &capped);
        tree.validate_against(&Triangles(&tris)).unwrap();
        let s = tree.stats(&capped);
        assert!(s.max_tris_per_leaf <= 8, "{s:?}");
        // Identical triangles cannot be separated: one leaf, no endless splitting.
        let same = vec![tris[0]; 50];
        let tree = build_sah(&same, &capped);
        assert_eq!(tree.nodes.len(), 1);
    }

    #[test]
    fn validate_detects_broken_trees() {
        let tris = sphere(2);
        let good = build_sah(&tris, &KdParams::default());
        good.validate_against(&Triangles(&tris)).unwrap();
        let inner = good
            .nodes
            .iter()
            .position(|n| matches!(n, KdNode::Inner { .. }))
            .unwrap();
        let leaf = good
            .nodes
            .iter()
            .position(|n| matches!(n, KdNode::Leaf { count, .. } if *count > 1))
            .unwrap();

        let mut t = good.clone();
        if let KdNode::Inner { split, .. } = &mut t.nodes[inner] {
            *split = 1e6;
        }
        assert!(matches!(t.validate(), Err(KdTreeError::BadSplit { .. })));

        let mut t = good.clone();
        if let KdNode::Inner { children, .. } = &mut t.nodes[inner] {
            *children = inner as u32;
        }
        assert!(matches!(t.validate(), Err(KdTreeError::BadChildren { .. })));

        let mut t = good.clone();
        let last_inner = t
            .nodes
            .iter()
            .rposition(|n| matches!(n, KdNode::Inner { .. }))
            .unwrap();
        let KdNode::Inner { children: c, .. } = t.nodes[last_inner] else {
            unreachable!()
        };
        if let KdNode::Inner { children, .. } = &mut t.nodes[inner] {
            *children = c; // two parents share a pair of children
        }
        assert!(matches!(
            t.validate(),
            Err(KdTreeError::Reached { .. }) | Err(KdTreeError::BadChildren { .. })
        ));

        let mut t = good.clone();
        if let KdNode::Leaf { first, .. } = &mut t.nodes[leaf] {
            *first += 1;
        }
        assert!(matches!(
            t.validate(),
            Err(KdTreeError::BadLeafRange { .. })
        ));

        let mut t = good.clone();
        if let KdNode::Leaf { first, .. } = t.nodes[leaf] {
            t.prim_indices[first as usize] = t.num_prims;
        }
        assert!(matches!(t.validate(), Err(KdTreeError::BadPrim { .. })));

        let mut t = good.clone();
        t.depth += 1;
        assert!(matches!(t.validate(), Err(KdTreeError::BadDepth { .. })));

        // Triangle 0 renamed to a far-away triangle in every leaf: it is outside the leaves
        // that list it, and triangle 0 itself ends up missing.
        let mut t = good.clone();
        let mut moved = tris.clone();
        moved[0] = [
            DVec3::splat(50.0),
            DVec3::splat(51.0),
            DVec3::new(50.0, 51.0, 50.0),
        ];
        assert!(matches!(
            t.validate_against(&Triangles(&moved)),
            Err(KdTreeError::PrimOutsideLeaf { prim: 0, .. })
        ));
        for p in t.prim_indices.iter_mut() {
            if *p == 0 {
                *p = 1;
            }
        }
        // (Leaves may now hold 1 twice, which `validate` reports first.)
        assert!(t.validate_against(&Triangles(&tris)).is_err());
        assert_eq!(
            good.validate_against(&Triangles(&tris[1..])),
            Err(KdTreeError::PrimCount {
                tree: tris.len() as u32,
                given: tris.len() - 1
            })
        );
    }
}
