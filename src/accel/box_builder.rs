//! The SAH kd-tree over boxes (the top level over instance world bounds, rebuilt every
//! frame): the tree [`super::sah_builder`] builds over [`super::primitive::Boxes`], bit for
//! bit, with a layout of its own for boxes.
//!
//! What makes the same tree: a box clipped to a node's box is the box clamped to it, so a
//! box that straddles a split keeps its events on both sides unchanged; the f64 sweep never
//! scores a position outside the node's box (where clamping would have moved it), and the
//! rounded sweep clamps the positions it reads. Everything else is the general builder's:
//! the event order (position, then End < Planar < Start, then box id), the sweep's arithmetic
//! and tie-breaks, the classification, and best split first under the node budget with the
//! same heap keys and tie-breaks, renumbered into the depth-first order.
//!
//! What makes it faster (the general builder took 10.2-10.5 ms for 5,622 boxes; figures in
//! the README's "kd-tree build"): no clipping, merging or event structs; each node's events
//! are two arrays (positions and tags: kind and box id in one `u32`) per axis, split into the
//! children by one branch-free pass that writes every event to both and keeps it where its
//! box goes; buffers come from a pool by size class; the f64 sweep scores an axis in two
//! passes without branches on the data ([`Builder::sweep_unflat`]); and best first pops
//! every split itself (its frontier of lists fits the caches for a top level, so the general
//! builder's pruned depth-first finish does not pay). One core; the sweeps (about 40%) and the
//! list splits (about 20%) are what is left.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::aabb::Aabb;
use super::kd_tree::{KdNode, KdParams, KdTree};
use super::sah_builder::{depth_first_order, from_ordered_bits, ordered_bits};
use crate::fp::Format;

/// Event kinds in a tag's top bits, in the lists' order at one position.
const END: u32 = 0;
const PLANAR: u32 = 1;
const START: u32 = 2;
const KIND_SHIFT: u32 = 30;
/// Box ids below this fit a tag.
pub(super) const MAX_BOXES: usize = 1 << KIND_SHIFT;
const ID_MASK: u32 = (1 << KIND_SHIFT) - 1;

/// Where a box goes in a split: bit 0 left, bit 1 right.
const LEFT: u8 = 1;
const RIGHT: u8 = 2;
const BOTH: u8 = 3;

/// A node's events: per axis, in `pos[start..ends[axis]]` (`start` the previous axis' end),
/// sorted by position, kind, id. `pos` and `tag` may be longer (pooled buffers).
#[derive(Default)]
struct Lists {
    pos: Vec<f64>,
    tag: Vec<u32>,
    ends: [usize; 3],
}

impl Lists {
    fn axis(&self, axis: usize) -> (&[f64], &[u32]) {
        let start = if axis == 0 { 0 } else { self.ends[axis - 1] };
        let end = self.ends[axis];
        (&self.pos[start..end], &self.tag[start..end])
    }
}

/// A split plane with the boxes it puts on each side.
#[derive(Clone, Copy, Debug)]
struct Plane {
    cost: f64,
    axis: usize,
    pos: f64,
    planar_left: bool,
    left: usize,
    right: usize,
}

/// A node waiting in best first's heap.
struct Candidate {
    node: usize,
    voxel: Aabb,
    lists: Lists,
    depth: u32,
    plane: Plane,
}

/// The best planes of one node's sweeps so far (as the general builder's `PlaneSearch`).
struct Search {
    n: usize,
    best: Option<Plane>,
    /// Whether the leaf-size cap applies, and with it `best_separating`: the best plane that
    /// leaves fewer than `n` boxes on each side.
    track_separating: bool,
    best_separating: Option<Plane>,
}

impl Search {
    /// Scores the plane at `p` with `nl` / `nr` boxes strictly left / right of it and
    /// `planars` lying in it (they go to the cheaper side). `pl` / `pr` are the sides'
    /// areas relative to the node's.
    #[allow(clippy::too_many_arguments)]
    fn consider(
        &mut self,
        params: &KdParams,
        axis: usize,
        p: f64,
        pl: f64,
        pr: f64,
        nl: usize,
        nr: usize,
        planars: usize,
    ) {
        let cost = |nl: usize, nr: usize| {
            // Through i64, as the general builder (the same rounding).
            let c = params.traversal_cost
                + params.intersection_cost * (pl * nl as i64 as f64 + pr * nr as i64 as f64);
            if nl == 0 || nr == 0 {
                c * params.empty_bonus
            } else {
                c
            }
        };
        let cr = cost(nl, nr + planars);
        let (cost, planar_left) = if planars == 0 {
            (cr, false)
        } else {
            let cl = cost(nl + planars, nr);
            if cl < cr {
                (cl, true)
            } else {
                (cr, false)
            }
        };
        let (left, right) = if planar_left {
            (nl + planars, nr)
        } else {
            (nl, nr + planars)
        };
        let plane = Plane {
            cost,
            axis,
            pos: p,
            planar_left,
            left,
            right,
        };
        if self.best.is_none_or(|b| cost < b.cost) {
            self.best = Some(plane);
        }
        if self.track_separating
            && left < self.n
            && right < self.n
            && self.best_separating.is_none_or(|b| cost < b.cost)
        {
            self.best_separating = Some(plane);
        }
    }
}

struct Builder<'a> {
    params: &'a KdParams,
    depth_limit: u32,
    root_area: f64,
    /// Where each box of the node being split goes (`LEFT`, `RIGHT`, `BOTH`).
    side: Vec<u8>,
    nodes: Vec<KdNode>,
    prim_indices: Vec<u32>,
    depth: u32,
    /// Finished nodes' buffers by size class: `pool[c]` holds buffers of at least `2^c`
    /// events.
    pool: Vec<Vec<Lists>>,
    /// [`Builder::sweep_unflat`]'s buffer.
    costs: Vec<f64>,
}

/// Builds the kd-tree over `boxes` that [`super::sah_builder::build`] builds over
/// [`super::primitive::Boxes`], without [`KdParams::root_clip`] (the caller's to check) and
/// for fewer than [`MAX_BOXES`] boxes.
pub(super) fn build(boxes: &[Aabb], params: &KdParams) -> KdTree {
    let n = boxes.len();
    assert!(n < MAX_BOXES, "{n} boxes");
    let mut bounds = Aabb::EMPTY;
    let mut count = 0;
    let mut events: [Vec<(u64, u32)>; 3] = Default::default();
    for (i, b) in boxes.iter().enumerate() {
        if !b.is_finite() || b.is_empty() {
            continue;
        }
        bounds = bounds.union(b);
        count += 1;
        for (axis, list) in events.iter_mut().enumerate() {
            // `+ 0.0` turns -0.0 into +0.0 so that equal positions also sort as equal.
            let (lo, hi) = (b.min[axis] + 0.0, b.max[axis] + 0.0);
            let id = i as u32;
            if lo == hi {
                list.push((ordered_bits(lo), PLANAR << KIND_SHIFT | id));
            } else {
                list.push((ordered_bits(lo), START << KIND_SHIFT | id));
                list.push((ordered_bits(hi), END << KIND_SHIFT | id));
            }
        }
    }
    let mut lists = Lists {
        pos: Vec::with_capacity(6 * count),
        tag: Vec::with_capacity(6 * count),
        ends: [0; 3],
    };
    for (axis, list) in events.iter_mut().enumerate() {
        sort_events(list);
        for &(key, tag) in list.iter() {
            lists.pos.push(from_ordered_bits(key));
            lists.tag.push(tag);
        }
        lists.ends[axis] = lists.pos.len();
    }
    let mut builder = Builder {
        params,
        depth_limit: params.depth_limit(count),
        root_area: bounds.surface_area(),
        side: vec![BOTH; n],
        nodes: vec![KdNode::Leaf { first: 0, count: 0 }],
        prim_indices: Vec::new(),
        depth: 0,
        pool: Vec::new(),
        costs: Vec::new(),
    };
    builder.build_best_first(bounds, lists, count, params.node_budget(count));
    let (nodes, prim_indices) = depth_first_order(&builder.nodes, &builder.prim_indices);
    KdTree {
        nodes,
        prim_indices,
        bounds,
        depth: builder.depth,
        num_prims: n as u32,
    }
}

/// Sorts one axis' (position key, tag) pairs into the lists' order by a least significant
/// digit first radix sort on the key (stable, so the pairs of one key stay in push order:
/// Start before End of a box, boxes by id) and a last pass on the kind.
fn sort_events(list: &mut Vec<(u64, u32)>) {
    const BITS: u32 = 11;
    const BUCKETS: usize = 1 << BITS;
    // The key 11 bits at a time, then the kind.
    let passes = 64usize.div_ceil(BITS as usize) + 1;
    let kind_pass = passes - 1;
    let digit = |e: &(u64, u32), d: usize| {
        if d == kind_pass {
            (e.1 >> KIND_SHIFT) as usize
        } else {
            (e.0 >> (d as u32 * BITS)) as usize & (BUCKETS - 1)
        }
    };
    let mut counts = vec![[0usize; BUCKETS]; passes];
    for e in list.iter() {
        for (d, c) in counts.iter_mut().enumerate() {
            c[digit(e, d)] += 1;
        }
    }
    let mut buffer = vec![(0, 0); list.len()];
    // By key first, kind last: the kind pass must come before the key passes, so that the
    // key passes (stable) keep the kinds of one key in order: End < Planar < Start.
    let order = std::iter::once(kind_pass).chain(0..kind_pass);
    for d in order {
        let c = &mut counts[d];
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

/// The index and value of the first lowest of `costs` (none a NaN; infinity if empty), in
/// four independent minima and a search for the first equal one.
fn first_lowest(costs: &[f64]) -> (usize, f64) {
    let mut m = [f64::INFINITY; 4];
    let chunks = costs.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..4 {
            m[k] = if c[k] < m[k] { c[k] } else { m[k] };
        }
    }
    for &c in rest {
        m[0] = if c < m[0] { c } else { m[0] };
    }
    let low = m
        .into_iter()
        .fold(f64::INFINITY, |a, b| if b < a { b } else { a });
    (costs.iter().position(|&c| c == low).unwrap_or(0), low)
}

impl Builder<'_> {
    /// Best split first (the general builder's `build_best_first` without its pruned
    /// finish): the splits the unbudgeted builder would make, the largest SAH saving first,
    /// while the budget pays for two more children; heap ties go to the candidate found
    /// first.
    fn build_best_first(&mut self, voxel: Aabb, lists: Lists, n: usize, budget: u64) {
        let mut heap = BinaryHeap::new();
        // Every candidate is a node: at most the budget, and the unbudgeted tree's nodes.
        // (A split candidate's lists are taken, the rest stays: moving whole candidates in
        // and out cost more.)
        let mut waiting: Vec<Candidate> = Vec::with_capacity(budget.min(8 * n as u64 + 1) as usize);
        self.consider(0, voxel, lists, n, 0, &mut heap, &mut waiting);
        let mut used = 1;
        while used + 2 <= budget {
            let Some((_, _, i)) = heap.pop() else { break };
            let c = &mut waiting[i];
            let lists = std::mem::take(&mut c.lists);
            let (node, voxel, depth, plane) = (c.node, c.voxel, c.depth, c.plane);
            let (vl, vr) = voxel.split(plane.axis, plane.pos);
            let (left, right) = self.split_lists(lists, &plane);
            let children = self.nodes.len();
            self.nodes[node] = KdNode::Inner {
                axis: plane.axis as u8,
                split: plane.pos,
                children: children as u32,
            };
            self.nodes.push(KdNode::Leaf { first: 0, count: 0 });
            self.nodes.push(KdNode::Leaf { first: 0, count: 0 });
            used += 2;
            let d = depth + 1;
            let (nl, nr) = (plane.left, plane.right);
            self.consider(children, vl, left, nl, d, &mut heap, &mut waiting);
            self.consider(children + 1, vr, right, nr, d, &mut heap, &mut waiting);
        }
        for c in &waiting {
            // (Split candidates' nodes are inner nodes.)
            if matches!(self.nodes[c.node], KdNode::Leaf { .. }) {
                self.make_leaf(c.node, &c.lists, c.depth);
            }
        }
    }

    /// Makes `node` a leaf, or a candidate if the unbudgeted builder would split it.
    #[allow(clippy::too_many_arguments)]
    fn consider(
        &mut self,
        node: usize,
        voxel: Aabb,
        lists: Lists,
        n: usize,
        depth: u32,
        heap: &mut BinaryHeap<(u64, Reverse<usize>, usize)>,
        waiting: &mut Vec<Candidate>,
    ) {
        let plane = if n == 0 || depth >= self.depth_limit {
            None
        } else {
            self.choose_plane(&voxel, &lists, n)
        };
        let Some(plane) = plane else {
            self.make_leaf(node, &lists, depth);
            self.recycle(lists);
            return;
        };
        // What the split saves: the node's share of the root's area times its leaf cost
        // minus its split cost.
        let prob = if self.root_area > 0.0 {
            voxel.surface_area() / self.root_area
        } else {
            1.0
        };
        let saving = prob * (self.params.intersection_cost * n as f64 - plane.cost);
        let i = waiting.len();
        heap.push((ordered_bits(saving), Reverse(i), i));
        waiting.push(Candidate {
            node,
            voxel,
            lists,
            depth,
            plane,
        });
    }

    fn make_leaf(&mut self, node: usize, lists: &Lists, depth: u32) {
        let first = self.prim_indices.len();
        // Every box has one Start or Planar event per axis.
        let (_, tags) = lists.axis(0);
        self.prim_indices.extend(
            tags.iter()
                .filter(|&&t| t >> KIND_SHIFT != END)
                .map(|&t| t & ID_MASK),
        );
        self.prim_indices[first..].sort_unstable();
        self.nodes[node] = KdNode::Leaf {
            first: first as u32,
            count: (self.prim_indices.len() - first) as u32,
        };
        self.depth = self.depth.max(depth);
    }

    /// The plane to split at, or `None` for a leaf (the general builder's `choose_plane`).
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn choose_plane(&mut self, voxel: &Aabb, lists: &Lists, n: usize) -> Option<Plane> {
        let area = voxel.surface_area();
        if !(area > 0.0) {
            return None;
        }
        let mut search = Search {
            n,
            best: None,
            track_separating: n > self.params.max_leaf_prims as usize,
            best_separating: None,
        };
        let mut costs = std::mem::take(&mut self.costs);
        for axis in 0..3 {
            let (pos, tag) = lists.axis(axis);
            match self.params.split_format {
                None => {
                    let inv_area = 1.0 / area;
                    if !self.sweep_unflat(axis, pos, tag, voxel, inv_area, &mut search, &mut costs)
                    {
                        self.sweep(axis, pos, tag, voxel, inv_area, &mut search);
                    }
                }
                Some(f) => {
                    self.sweep_rounded(f, axis, pos, tag, voxel, 1.0 / area, &mut search);
                }
            }
        }
        self.costs = costs;
        let leaf_cost = self.params.intersection_cost * n as f64;
        match search.best {
            Some(b) if b.cost < leaf_cost => Some(b),
            _ if search.track_separating => search.best_separating,
            _ => None,
        }
    }

    /// Scores every event position strictly inside the node's box on one axis.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn sweep(
        &self,
        axis: usize,
        pos: &[f64],
        tag: &[u32],
        voxel: &Aabb,
        inv_area: f64,
        search: &mut Search,
    ) {
        let (lo, hi) = (voxel.min[axis], voxel.max[axis]);
        if !(lo < hi) {
            return;
        }
        let e = voxel.extent();
        let (e1, e2) = (e[(axis + 1) % 3], e[(axis + 2) % 3]);
        let (cap, ring) = (e1 * e2, e1 + e2);
        let (mut nl, mut nr) = (0usize, search.n);
        let mut i = 0;
        while i < pos.len() {
            let p = pos[i];
            // Counts of End, Planar and Start events at `p`.
            let (mut ends, mut planars, mut starts) = (0, 0, 0);
            loop {
                let kind = tag[i] >> KIND_SHIFT;
                ends += usize::from(kind == END);
                planars += usize::from(kind == PLANAR);
                starts += usize::from(kind == START);
                i += 1;
                if i == pos.len() || pos[i] != p {
                    break;
                }
            }
            if lo < p && p < hi {
                let pl = 2.0 * (cap + (p - lo) * ring) * inv_area;
                let pr = 2.0 * (cap + (hi - p) * ring) * inv_area;
                let right = nr - planars - ends;
                search.consider(self.params, axis, p, pl, pr, nl, right, planars);
            }
            nr -= planars + ends;
            nl += starts + planars;
        }
    }

    /// [`Builder::sweep`] for an axis without Planar events (boxes that are not flat on
    /// it, the usual case), in two passes without branches on the data: the cost of every
    /// event's plane strictly inside the node's box into `costs`, then the first of the
    /// lowest. (One pass that kept the best as it went waited on every comparison, or, with
    /// branches, mispredicted the kinds and the updates.) Returns false, `search` as it was,
    /// if it meets a Planar event, if the lowest lies at a position shared by several events
    /// (where [`Builder::sweep`] scores one plane with the counts found at the position's
    /// last End), or if `inv_area` is not finite (costs that are not numbers, which the
    /// first-found rule of [`Builder::sweep`] treats apart).
    // Compiled apart: inlined into `choose_plane` its loop kept a count in memory.
    #[inline(never)]
    #[allow(clippy::neg_cmp_op_on_partial_ord, clippy::too_many_arguments)]
    fn sweep_unflat(
        &self,
        axis: usize,
        pos: &[f64],
        tag: &[u32],
        voxel: &Aabb,
        inv_area: f64,
        search: &mut Search,
        costs: &mut Vec<f64>,
    ) -> bool {
        let (lo, hi) = (voxel.min[axis], voxel.max[axis]);
        if !(lo < hi) {
            return true;
        }
        if !inv_area.is_finite() || !(hi - lo).is_finite() {
            return false;
        }
        let e = voxel.extent();
        let (e1, e2) = (e[(axis + 1) % 3], e[(axis + 2) % 3]);
        let (cap, ring) = (e1 * e2, e1 + e2);
        let (ct, ci) = (self.params.traversal_cost, self.params.intersection_cost);
        // The bonus as a factor (`c * 1.0` is `c`).
        let factor = [1.0, self.params.empty_bonus];
        // The events strictly inside the box: `pos[a..b]`.
        // (Few events lie outside: straddlers of splits on this axis.)
        let a = pos.iter().position(|&p| p > lo).unwrap_or(pos.len());
        let b = pos.iter().rposition(|&p| p < hi).map_or(0, |i| i + 1);
        if a >= b {
            return !tag.iter().any(|&t| t >> KIND_SHIFT == PLANAR);
        }
        // Boxes starting before the event, and not ending at or before it.
        let starts_before = |i: usize| {
            tag[..i]
                .iter()
                .map(|&t| usize::from(t >> KIND_SHIFT == START))
                .sum::<usize>()
        };
        let nl0 = starts_before(a);
        let (mut nl, mut nr) = (nl0 as i64, (search.n - (a - nl0)) as i64);
        costs.clear();
        for (&p, &t) in pos[a..b].iter().zip(&tag[a..b]) {
            let kind = t >> KIND_SHIFT;
            if kind == PLANAR {
                return false;
            }
            // `kind >> 1` is 1 for a Start, 0 for an End.
            let start = i64::from(kind >> 1);
            nr -= 1 - start;
            let pl = 2.0 * (cap + (p - lo) * ring) * inv_area;
            let pr = 2.0 * (cap + (hi - p) * ring) * inv_area;
            let c = ct + ci * (pl * nl as f64 + pr * nr as f64);
            costs.push(c * factor[usize::from((nl == 0) | (nr == 0))]);
            nl += start;
        }
        if tag[..a]
            .iter()
            .chain(&tag[b..])
            .any(|&t| t >> KIND_SHIFT == PLANAR)
        {
            return false;
        }
        // The plane at event `i`, with the counts there; `None` at a shared position.
        let plane = |i: usize, cost: f64| {
            let p = pos[i];
            if (i > 0 && pos[i - 1] == p) || pos.get(i + 1) == Some(&p) {
                return None;
            }
            let left = starts_before(i);
            let start = usize::from(tag[i] >> KIND_SHIFT == START);
            Some(Plane {
                cost,
                axis,
                pos: p,
                planar_left: false,
                left,
                right: search.n - (i + 1 - left - start),
            })
        };
        let (i, c) = first_lowest(costs);
        let best = search.best.is_none_or(|b| c < b.cost);
        let best = if best { Some(plane(a + i, c)) } else { None };
        let mut separating = None;
        if search.track_separating {
            // Fewer than `n` on each side: from the first End to the last Start.
            let first_end = tag.iter().position(|&t| t >> KIND_SHIFT == END);
            let last_start = tag.iter().rposition(|&t| t >> KIND_SHIFT == START);
            if let (Some(first_end), Some(last_start)) = (first_end, last_start) {
                let (from, to) = (first_end.max(a), last_start.min(b - 1));
                if from <= to {
                    // The lowest of all, if it separates, is the lowest that separates.
                    let (i, c) = if (from..=to).contains(&(a + i)) {
                        (a + i - from, c)
                    } else {
                        first_lowest(&costs[from - a..=to - a])
                    };
                    if search.best_separating.is_none_or(|s| c < s.cost) {
                        separating = Some(plane(from + i, c));
                    }
                }
            }
        }
        if matches!(best, Some(None)) || matches!(separating, Some(None)) {
            return false;
        }
        if let Some(b) = best.flatten() {
            search.best = Some(b);
        }
        if let Some(s) = separating.flatten() {
            search.best_separating = Some(s);
        }
        true
    }

    /// [`Builder::sweep`] with the candidate planes rounded into `f` (the general builder's
    /// rounded sweep): each rounded plane scored once with its own counts, at an event
    /// position with that position's events, between two with the counts of the gap. With
    /// `clip_splits` positions are read clamped to the node's box (where clipping puts
    /// them: they could round into it).
    #[allow(clippy::too_many_arguments, clippy::neg_cmp_op_on_partial_ord)]
    fn sweep_rounded(
        &self,
        f: Format,
        axis: usize,
        pos: &[f64],
        tag: &[u32],
        voxel: &Aabb,
        inv_area: f64,
        search: &mut Search,
    ) {
        let (lo, hi) = (voxel.min[axis], voxel.max[axis]);
        if !(lo < hi) {
            return;
        }
        let e = voxel.extent();
        let (e1, e2) = (e[(axis + 1) % 3], e[(axis + 2) % 3]);
        let (cap, ring) = (e1 * e2, e1 + e2);
        let clamp = self.params.clip_splits;
        let at = |p: f64| if clamp { p.max(lo).min(hi) } else { p };
        let n = search.n;
        let mut consider = |p: f64, nl: usize, nr: usize, planars: usize| {
            if lo < p && p < hi {
                let pl = 2.0 * (cap + (p - lo) * ring) * inv_area;
                let pr = 2.0 * (cap + (hi - p) * ring) * inv_area;
                search.consider(self.params, axis, p, pl, pr, nl, nr, planars);
            }
        };
        // `last` is the last plane scored; `pending` a rounded plane beyond the events swept
        // so far.
        let (mut nl, mut nr) = (0usize, n);
        let mut last = f64::NEG_INFINITY;
        let mut pending: Option<f64> = None;
        let mut i = 0;
        while i < pos.len() {
            let p = at(pos[i]);
            if let Some(c) = pending.filter(|&c| c < p) {
                consider(c, nl, nr, 0);
                last = c;
                pending = None;
            }
            let (mut ends, mut planars, mut starts) = (0, 0, 0);
            while i < pos.len() && at(pos[i]) == p {
                let kind = tag[i] >> KIND_SHIFT;
                ends += usize::from(kind == END);
                planars += usize::from(kind == PLANAR);
                starts += usize::from(kind == START);
                i += 1;
            }
            let r = f.to_f64(f.from_f64(p));
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

    /// The children's lists: each box classified from the split axis' events (a Start at or
    /// after the plane puts it right, one before it makes it straddle until an End at or
    /// before the plane puts it left; a Planar goes by its side or `planar_left`), then
    /// every event written to both children's buffers and kept where its box goes (no
    /// branch on the unpredictable side).
    fn split_lists(&mut self, lists: Lists, plane: &Plane) -> (Lists, Lists) {
        let s = plane.pos;
        let (pos, tag) = lists.axis(plane.axis);
        // The new side by kind and by the event's position below, on or above the plane
        // (0: keep the side a Start gave).
        let on = if plane.planar_left { LEFT } else { RIGHT };
        let table: [[u8; 3]; 3] = [
            [LEFT, LEFT, 0],      // End
            [LEFT, on, RIGHT],    // Planar
            [BOTH, RIGHT, RIGHT], // Start
        ];
        for (&p, &t) in pos.iter().zip(tag) {
            let side = &mut self.side[(t & ID_MASK) as usize];
            let at = usize::from(p >= s) + usize::from(p > s);
            let new = table[(t >> KIND_SHIFT) as usize][at];
            *side = new | (*side & u8::from(new == 0).wrapping_neg());
        }
        // A box has at most two events per axis; one more slot takes the last write of an
        // event that goes to the other side.
        let mut left = self.fresh(6 * plane.left + 1);
        let mut right = self.fresh(6 * plane.right + 1);
        let (mut il, mut ir) = (0, 0);
        let mut start = 0;
        for axis in 0..3 {
            let end = lists.ends[axis];
            for (&p, &t) in lists.pos[start..end].iter().zip(&lists.tag[start..end]) {
                let side = self.side[(t & ID_MASK) as usize];
                left.pos[il] = p;
                left.tag[il] = t;
                right.pos[ir] = p;
                right.tag[ir] = t;
                il += usize::from(side & LEFT);
                ir += usize::from(side >> 1);
            }
            left.ends[axis] = il;
            right.ends[axis] = ir;
            start = end;
        }
        self.recycle(lists);
        (left, right)
    }

    /// Buffers for at least `len` events, from the pool when it has some.
    fn fresh(&mut self, len: usize) -> Lists {
        let class = len.max(1).next_power_of_two().trailing_zeros() as usize;
        // A buffer up to four times as large will do (fewer allocations).
        for c in class..(class + 3).min(self.pool.len()) {
            if let Some(lists) = self.pool[c].pop() {
                return lists;
            }
        }
        Lists {
            pos: vec![0.0; 1 << class],
            tag: vec![0; 1 << class],
            ends: [0; 3],
        }
    }

    fn recycle(&mut self, lists: Lists) {
        // The largest class whose size the buffers hold.
        let class = (usize::BITS - 1 - lists.pos.len().max(1).leading_zeros()) as usize;
        if self.pool.len() <= class {
            self.pool.resize_with(class + 1, Vec::new);
        }
        self.pool[class].push(lists);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::primitive::Boxes;
    use crate::accel::sah_builder;
    use glam::DVec3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Seeded random boxes, and boxes that take the slow paths: on an integer grid (shared
    /// faces, so shared event positions), flat on an axis (Planar events), duplicates, a
    /// non-finite one (left out).
    fn awkward_boxes(seed: u64) -> Vec<Aabb> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut boxes = crate::accel::bench::random_instance_boxes(1500, seed);
        for i in 0..400 {
            let c = DVec3::new(
                rng.gen_range(-20..20) as f64,
                rng.gen_range(-20..20) as f64,
                rng.gen_range(-20..20) as f64,
            );
            let e = match i % 4 {
                0 => DVec3::new(2.0, 0.0, 1.0),
                1 => DVec3::new(0.0, 0.0, 3.0),
                _ => DVec3::new(1.0, 2.0, 1.0),
            };
            boxes.push(Aabb::new(c, c + e));
        }
        for i in 0..50 {
            boxes.push(boxes[i * 7]);
        }
        boxes.push(Aabb::new(DVec3::ZERO, DVec3::new(f64::NAN, 1.0, 1.0)));
        boxes
    }

    /// The general builder's tree, bit for bit (nodes, leaves, bounds, depth), under the
    /// parameters the top level is built with (f64 and rounded into e7m16), budgets that
    /// bind hard, loosely and not at all, with and without clipping; on the benchmark's
    /// boxes and on boxes that take every slow path.
    #[test]
    fn same_tree_as_the_general_builder() {
        let cases = [
            (
                "benchmark 5622",
                crate::accel::bench::random_instance_boxes(5622, 2),
            ),
            (
                "random 700",
                crate::accel::bench::random_instance_boxes(700, 31),
            ),
            ("awkward", awkward_boxes(32)),
            ("none", Vec::new()),
            ("one", vec![Aabb::new(DVec3::ZERO, DVec3::ONE)]),
            ("identical", vec![Aabb::new(DVec3::ZERO, DVec3::ONE); 60]),
        ];
        for (name, boxes) in &cases {
            for nodes_per_prim in [Some(1), Some(3), Some(6), None] {
                for split_format in [None, Some(crate::fp::Format::E7M16)] {
                    for clip_splits in [true, false] {
                        let params = KdParams {
                            nodes_per_prim,
                            split_format,
                            clip_splits,
                            ..KdParams::default()
                        };
                        let tree = build(boxes, &params);
                        tree.validate_against(&Boxes(boxes)).unwrap();
                        assert_eq!(
                            tree,
                            sah_builder::build(&Boxes(boxes), &params),
                            "{name} {params:?}"
                        );
                    }
                }
            }
        }
    }

    /// The leaf-size cap's separating planes, where the SAH alone wants a leaf.
    #[test]
    fn same_tree_under_the_leaf_size_cap() {
        let boxes = awkward_boxes(33);
        for max_leaf_prims in [4, 32] {
            let params = KdParams {
                intersection_cost: 0.01,
                max_leaf_prims,
                ..KdParams::default()
            };
            let tree = build(&boxes, &params);
            assert!(tree.nodes.len() > 1, "the cap splits");
            assert_eq!(tree, sah_builder::build(&Boxes(&boxes), &params));
        }
    }

    /// The root's events in the lists' order: position, then End < Planar < Start, then id.
    #[test]
    fn root_events_are_sorted_by_position_kind_and_id() {
        let mut rng = ChaCha8Rng::seed_from_u64(34);
        let mut list: Vec<(u64, u32)> = (0..5000)
            .map(|i| {
                let pos = f64::from(rng.gen_range(-40i32..40)) * 0.5;
                (
                    ordered_bits(pos + 0.0),
                    rng.gen_range(0..3u32) << KIND_SHIFT | i,
                )
            })
            .collect();
        let mut want = list.clone();
        want.sort_by_key(|&(key, tag)| (key, tag >> KIND_SHIFT, tag & ID_MASK));
        sort_events(&mut list);
        assert_eq!(list, want);
    }
}
