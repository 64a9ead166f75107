//! The arithmetic of every hardware unit, written once as sequences of `fp` operations.
//!
//! The golden model calls these with a [`Format`] (values are format words); the processor's
//! microprogram generator calls the same functions with its assembler (values are registers),
//! so the hardware executes the same operations in the same order with the same rounding
//! (docs/ARCHITECTURE.md, "Data flow"). Each hardware unit's tests compare the RTL with these functions.
//! Change an order here and both sides change with it.
//!
//! The decisions (comparisons) around the arithmetic are small and live beside it: the golden
//! model evaluates them with `Format::lt`/`le`/`eq`, the microprogram as branches; the
//! processor's tests compare the two renderers pixel by pixel.
//!
//! Several functions here are also the golden twin of a block in `src/hw/` that computes them
//! in dedicated hardware; each names its block, and the block's file names the function back
//! (the whole list: docs/ARCHITECTURE.md, "Golden twins").

use crate::fp::Format;
use crate::layout::Node;

/// Entries of the per-ray mailboxes (most recently tested ids, first in first out), in the
/// golden model and in the hardware.
pub const MAILBOX_ENTRIES: usize = 8;

/// A ray's mailbox: the ids it tested most recently, first in first out, as the hardware keeps
/// them (the golden model and the engine's twin share it). Golden twin of the mailbox check in
/// [`hw::ListUnit`](crate::hw::ListUnit) (src/hw/list_unit.rs) and of the engine's
/// [`MailboxUnit`](crate::hw::engine::MailboxUnit) (`mbx`, `mbc`; src/hw/engine/mailbox.rs).
#[derive(Clone, Debug, Default)]
pub struct Mailbox {
    ids: [u32; MAILBOX_ENTRIES],
    len: usize,
    next: usize,
}

impl Mailbox {
    pub fn new() -> Self {
        Self::default()
    }
    /// True when `id` was recently tested; otherwise records it.
    pub fn seen(&mut self, id: u32) -> bool {
        if self.ids[..self.len].contains(&id) {
            return true;
        }
        self.ids[self.next] = id;
        self.next = (self.next + 1) % MAILBOX_ENTRIES;
        self.len = (self.len + 1).min(MAILBOX_ENTRIES);
        false
    }
}

/// A 3-vector of format words.
pub type Vec3W = [u32; 3];
/// A 3x4 matrix, row-major: `m00 m01 m02 n0 m10 m11 m12 n1 m20 m21 m22 n2`.
pub type Mat34W = [u32; 12];

/// Something that carries out `fp` operations: [`Format`] computes them; an assembler records
/// them as instructions. Copy, so the sequences below take it by value like a `Format`.
pub trait Arith: Copy {
    /// A value: a format word, or the register holding one.
    type V: Copy;
    fn add(self, a: Self::V, b: Self::V) -> Self::V;
    fn sub(self, a: Self::V, b: Self::V) -> Self::V;
    fn mul(self, a: Self::V, b: Self::V) -> Self::V;
    fn div(self, a: Self::V, b: Self::V) -> Self::V;
    fn sqrt(self, a: Self::V) -> Self::V;
    /// Sign flip (no rounding).
    fn neg(self, a: Self::V) -> Self::V;
    /// A constant format word.
    fn word(self, w: u32) -> Self::V;
    fn format(self) -> Format;
}

impl Arith for Format {
    type V = u32;
    fn add(self, a: u32, b: u32) -> u32 {
        Format::add(self, a, b)
    }
    fn sub(self, a: u32, b: u32) -> u32 {
        Format::sub(self, a, b)
    }
    fn mul(self, a: u32, b: u32) -> u32 {
        Format::mul(self, a, b)
    }
    fn div(self, a: u32, b: u32) -> u32 {
        Format::div(self, a, b)
    }
    fn sqrt(self, a: u32) -> u32 {
        Format::sqrt(self, a)
    }
    fn neg(self, a: u32) -> u32 {
        Format::neg(self, a)
    }
    fn word(self, w: u32) -> u32 {
        w
    }
    fn format(self) -> Format {
        self
    }
}

/// TransformUnit: `x' = ((m00*x + m01*y) + m02*z) + n0` per row for a point; a vector omits
/// the `+ n` step. 9 multiplications and 9 additions for a point (6 for a vector). Golden twin
/// of [`hw::TransformUnit`](crate::hw::TransformUnit) (src/hw/transform.rs) and, per client,
/// of [`hw::SharedTransformUnit`](crate::hw::SharedTransformUnit)
/// (src/hw/transform_arbiter.rs).
pub fn transform<A: Arith>(a: A, m: &[A::V; 12], v: [A::V; 3], point: bool) -> [A::V; 3] {
    let row = |r: usize| transform_row(a, &m[r * 4..r * 4 + 4], v, point);
    [row(0), row(1), row(2)]
}

/// One row of [`transform`]: `row` is `m0 m1 m2 n`.
pub fn transform_row<A: Arith>(a: A, row: &[A::V], v: [A::V; 3], point: bool) -> A::V {
    let s = a.add(
        a.add(a.mul(row[0], v[0]), a.mul(row[1], v[1])),
        a.mul(row[2], v[2]),
    );
    if point {
        a.add(s, row[3])
    } else {
        s
    }
}

/// One pass of the TransformUnit as its hardware computes it, `diagonal` included
/// ([`hw::TransformUnit`](crate::hw::TransformUnit)'s input of that name): each row
/// `((p0 + p1) + p2) + n` with `p_k = m[r][k] * v[k]`, except that in a diagonal pass the
/// products off the diagonal are -0; a vector adds -0 in place of `n`. [`transform`] equals it
/// without `diagonal` (the `+ (-0)` is an exact identity). Golden twin of the unit's passes
/// for shading ([`hw::ShadeUnit`](crate::hw::ShadeUnit), src/hw/shade_unit.rs).
pub fn transform_pass(f: Format, m: &Mat34W, v: Vec3W, point: bool, diagonal: bool) -> Vec3W {
    let neg_zero = f.zero(true);
    std::array::from_fn(|r| {
        let p: [u32; 3] = std::array::from_fn(|k| {
            if diagonal && r != k {
                neg_zero
            } else {
                f.mul(m[r * 4 + k], v[k])
            }
        });
        let s = f.add(f.add(p[0], p[1]), p[2]);
        f.add(s, if point { m[r * 4 + 3] } else { neg_zero })
    })
}

/// The 3x4 of a diagonal pass: `diag` on the diagonal, `offset` in the last column (zeros
/// elsewhere: the pass never reads them).
pub fn diagonal_matrix(diag: Vec3W, offset: Vec3W) -> Mat34W {
    let mut m = [0; 12];
    for r in 0..3 {
        m[r * 4 + r] = diag[r];
        m[r * 4 + 3] = offset[r];
    }
    m
}

/// A colour channel's frame-buffer bytes, `0x00RRGGBB`, as the engine's three `byte`
/// instructions (or the ShadeUnit) pack them with [`channel_byte`].
pub fn pack_channel_bytes(f: Format, c: Vec3W) -> u32 {
    (channel_byte(f, c[0]) << 16) | (channel_byte(f, c[1]) << 8) | channel_byte(f, c[2])
}

/// A light of direct shading: its position and colour words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightWords {
    pub position: Vec3W,
    pub color: Vec3W,
}

/// The frame constants direct shading reads: ambient, background, the lights.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShadingConstants {
    pub ambient: u32,
    pub background: Vec3W,
    pub lights: Vec<LightWords>,
}

/// A hit as direct shading needs it: the ray, the hit's t, the triangle's stored unit normal
/// and the material's diffuse colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceHit {
    pub o: Vec3W,
    pub d: Vec3W,
    pub t: u32,
    pub n: Vec3W,
    pub kd: Vec3W,
}

/// Direct shading of a primary ray without shadows, mirrors or instances, pass for pass as
/// the [`hw::ShadeUnit`](crate::hw::ShadeUnit) (src/hw/shade_unit.rs) computes it: the
/// TransformUnit's passes ([`transform_pass`]) for the hit point `o + t d` (diagonal), `n . d`
/// (a row), the ambient term `kd * ambient` (diagonal); per light `light - p` (diagonal, `-1`
/// times `p` plus the light), `n . L` and `L . L` (two rows), then `sqrt` and `/` for the
/// cosine, `kd * colour` and `acc + (kd colour) cos` (diagonal); the bytes packed. Equal bit
/// for bit to the golden model's shading of the same hit (`model::golden`: [`ray_point`],
/// [`facing_normal`], [`ambient`], [`lambert_cosine`], [`add_light`], [`pack_rgb`]; the test
/// `shading_passes_equal_the_golden_shading`): `x + (-0) = x`, `-1 * x = -x` and the
/// operators' commutativity make each pass the golden operation. `None`: a miss, the
/// background.
pub fn shade_direct(f: Format, k: &ShadingConstants, hit: Option<&SurfaceHit>) -> u32 {
    let Some(h) = hit else {
        return pack_channel_bytes(f, k.background);
    };
    let vector = |m: &Mat34W, v: Vec3W| transform_pass(f, m, v, false, false);
    let diagonal = |diag: Vec3W, v: Vec3W, offset: Option<Vec3W>| {
        let m = diagonal_matrix(diag, offset.unwrap_or([0; 3]));
        transform_pass(f, &m, v, offset.is_some(), true)
    };
    let rows = |r0: Vec3W, r1: Vec3W, v: Vec3W| {
        let m = [r0[0], r0[1], r0[2], 0, r1[0], r1[1], r1[2], 0, 0, 0, 0, 0];
        vector(&m, v)
    };
    let p = diagonal(h.d, [h.t; 3], Some(h.o));
    let along = rows(h.n, [0; 3], h.d)[0];
    let n = if f.lt(0, along) {
        h.n.map(|c| f.neg(c))
    } else {
        h.n
    };
    let mut acc = diagonal(h.kd, [k.ambient; 3], None);
    let minus_one = f.from_int(-1);
    for light in &k.lights {
        let to_light = diagonal([minus_one; 3], p, Some(light.position));
        let [n_dot_l, l_dot_l, _] = rows(n, to_light, to_light);
        if !f.lt(0, n_dot_l) {
            continue;
        }
        let cos = f.div(n_dot_l, f.sqrt(l_dot_l));
        let tint = diagonal(h.kd, light.color, None);
        acc = diagonal(tint, [cos; 3], Some(acc));
    }
    pack_channel_bytes(f, acc)
}

/// The normal transform is a 3x3 (the 3x4 layout without offsets), run as a vector transform.
pub fn transform3<A: Arith>(a: A, m: &[A::V; 9], v: [A::V; 3]) -> [A::V; 3] {
    let row = |r: usize| {
        a.add(
            a.add(a.mul(m[r * 3], v[0]), a.mul(m[r * 3 + 1], v[1])),
            a.mul(m[r * 3 + 2], v[2]),
        )
    };
    [row(0), row(1), row(2)]
}

/// RayGen: the primary ray direction of pixel (x, y) in format words is the camera matrix
/// applied to the point (x, y, 0) (the layout bakes the pixel-centre offsets into the matrix's
/// offset column): the golden twin of [`hw::RayGen`](crate::hw::RayGen) and
/// [`hw::RayGenUnit`](crate::hw::RayGenUnit) (src/hw/raygen.rs), which count the coordinates'
/// floats (equal to `from_int` here), and of the processor's
/// [`hw::engine::PrimaryRays`](crate::hw::engine::PrimaryRays), which sends the request
/// through the triangle tester's TransformUnit.
pub fn primary_direction(f: Format, camera: &Mat34W, x: u32, y: u32) -> Vec3W {
    let coordinate = |i: u32| f.from_int(i64::from(i));
    transform(f, camera, [coordinate(x), coordinate(y), 0], true)
}

/// The result of one unit-triangle test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitHit {
    pub t: u32,
    pub u: u32,
    pub v: u32,
    pub hit: bool,
}

/// The unit-triangle edge margin in units of the format's spacing at 1 (`2^-M`): 64 ulps,
/// 2^-10 at e7m16. Rounding of O' and D' can open a crack along an edge shared by two
/// triangles; growing each triangle by the margin closes it (PRECISION.md measures what it
/// closes and what it adds at silhouettes).
pub const EDGE_MARGIN_ULPS: u32 = 64;

/// The margin of [`EDGE_MARGIN_ULPS`] as a format word ([`hw::IntersectUnit`]'s margin).
///
/// [`hw::IntersectUnit`]: crate::hw::IntersectUnit
pub fn edge_margin(f: Format) -> u32 {
    f.from_f64(f64::from(EDGE_MARGIN_ULPS) * 2f64.powi(-(f.man_bits as i32)))
}

/// The bounds of the unit-triangle test with edge margin `margin`: `u, v >= lo` and
/// `u + v <= hi`, with `lo = -margin` and `hi = 1 + margin` (each rounded once). Constants, so
/// in hardware the margin costs no operator: [`hw::IntersectUnit`](crate::hw::IntersectUnit)
/// (src/hw/intersect.rs) compares with these two words.
pub fn edge_bounds(f: Format, margin: u32) -> (u32, u32) {
    (f.neg(margin), f.add(f.one(), margin))
}

/// IntersectUnit's arithmetic, given the ray already in unit-triangle space (O', D'):
/// `t = -O'z / D'z`, `u = O'x + t*D'x`, `v = O'y + t*D'y` and `u + v`. 1 div, 2 mul, 3 add,
/// in the order of the pipeline of [`hw::IntersectUnit`](crate::hw::IntersectUnit)
/// (src/hw/intersect.rs).
pub fn unit_triangle_coords<A: Arith>(a: A, o: [A::V; 3], d: [A::V; 3]) -> [A::V; 4] {
    let t = unit_triangle_t(a, o[2], d[2]);
    let u = unit_triangle_coord(a, o[0], d[0], t);
    let v = unit_triangle_coord(a, o[1], d[1], t);
    [t, u, v, a.add(u, v)]
}

/// The first step of [`unit_triangle_coords`]: `t = -O'z / D'z`. In hardware: the sign flip
/// and the [`FpDiv`](crate::hw::fp::FpDiv) at the head of
/// [`hw::IntersectUnit`](crate::hw::IntersectUnit) (src/hw/intersect.rs).
pub fn unit_triangle_t<A: Arith>(a: A, o_z: A::V, d_z: A::V) -> A::V {
    a.div(a.neg(o_z), d_z)
}

/// `u = O'x + t*D'x` (or `v` from the y components), as [`unit_triangle_coords`] computes it
/// and [`hw::IntersectUnit`](crate::hw::IntersectUnit)'s products and adders after the divider.
pub fn unit_triangle_coord<A: Arith>(a: A, o: A::V, d: A::V, t: A::V) -> A::V {
    a.add(o, a.mul(t, d))
}

/// IntersectUnit: a hit when `lo <= u`, `lo <= v`, `u + v <= hi` and `t_min < t < t_max`
/// ([`unit_triangle_coords`], bounds from [`edge_bounds`] with the default [`edge_margin`]).
/// NaN fails every comparison, so a ray parallel to the triangle (D'z = 0) or any NaN or
/// infinity never hits. Golden twin of [`hw::IntersectUnit`](crate::hw::IntersectUnit)
/// (src/hw/intersect.rs).
pub fn intersect(f: Format, o: Vec3W, d: Vec3W, t_min: u32, t_max: u32) -> UnitHit {
    intersect_with_margin(f, o, d, t_min, t_max, edge_margin(f))
}

/// The triangle tester's test ([`hw::TriangleTester`](crate::hw::TriangleTester),
/// src/hw/triangle_tester.rs, whose golden twin this is): the ray into the triangle's unit space
/// through the transformation unit (a point, then a vector), then [`intersect`] with no upper
/// bound. The tester keeps the closest hit with [`closer_hit`] against the best so far, which
/// is the golden model's test with `t_max` = the best t: `t < best_t` and `t < +inf` hold
/// together exactly when `t < best_t`, since `best_t <= +inf`.
pub fn triangle_test(f: Format, m: &Mat34W, o: Vec3W, d: Vec3W, t_min: u32) -> UnitHit {
    let o = transform(f, m, o, true);
    let d = transform(f, m, d, false);
    intersect(f, o, d, t_min, f.infinity(false))
}

/// Whether a [`triangle_test`] result replaces the best hit so far (the first of equal ts
/// stays, as in the golden model's list order): the golden twin of the hit merge in
/// [`hw::TriangleTester`](crate::hw::TriangleTester) (src/hw/triangle_tester.rs).
pub fn closer_hit(f: Format, r: &UnitHit, best_t: u32) -> bool {
    r.hit && f.lt(r.t, best_t)
}

/// The unit-triangle test with edge margin `margin` (a format word; 0 is the exact test).
/// Grows every triangle by `margin` in unit-triangle coordinates (a fraction of its size).
pub fn intersect_with_margin(
    f: Format,
    o: Vec3W,
    d: Vec3W,
    t_min: u32,
    t_max: u32,
    margin: u32,
) -> UnitHit {
    let (lo, hi) = edge_bounds(f, margin);
    let [t, u, v, uv] = unit_triangle_coords(f, o, d);
    let inside = f.le(lo, u) && f.le(lo, v) && f.le(uv, hi);
    let hit = inside && f.lt(t_min, t) && f.lt(t, t_max);
    UnitHit { t, u, v, hit }
}

/// Which children of an inner kd node a ray segment [t_min, t_max] visits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visit {
    /// Only the near child, with the whole segment.
    Near,
    /// Only the far child, with the whole segment.
    Far,
    /// The near child with [t_min, t_split], then the far child with [t_split, t_max].
    Both { t_split: u32 },
}

/// The traversal unit's arithmetic: the distance `(split - o) / d` to a split plane (the
/// `FpAddSub` and `FpDiv` of [`hw::TraversalUnit`](crate::hw::TraversalUnit)'s decision
/// pipeline, src/hw/traversal_unit.rs).
pub fn split_distance<A: Arith>(a: A, o: A::V, d: A::V, split: A::V) -> A::V {
    a.div(a.sub(split, o), d)
}

/// One traversal step (traversal unit): `t_split` ([`split_distance`]) along the node's axis,
/// and the near child is the one holding the origin (on the plane, the one the ray heads
/// into). Returns whether the near child is the left (below) one, and which children to
/// visit. 1 add (sub), 1 div, comparisons: one inner node of
/// [`hw::TraversalUnit`](crate::hw::TraversalUnit) (src/hw/traversal_unit.rs).
pub fn traversal_step(
    f: Format,
    o: u32,
    d: u32,
    split: u32,
    t_min: u32,
    t_max: u32,
) -> (bool, Visit) {
    let near_is_left = f.lt(o, split) || (f.eq(o, split) && f.le(d, 0));
    if f.eq(d, 0) {
        return (near_is_left, Visit::Near);
    }
    let t_split = split_distance(f, o, d, split);
    let visit = if f.lt(t_max, t_split) || f.le(t_split, 0) {
        Visit::Near
    } else if f.lt(t_split, t_min) {
        Visit::Far
    } else {
        Visit::Both { t_split }
    };
    (near_is_left, visit)
}

/// Where a [`KdWalk`] stopped: at a leaf (its list in bank 1), or at the end of the walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KdStop {
    Leaf { list: u32, count: u32 },
    Finished,
}

/// The traversal unit's walk of one kd tree, resumable at each leaf: `model::golden`'s
/// `traverse` with [`traversal_step`], which the golden model runs in one loop and the
/// hardware runs between the thread's leaves. The engine's twin and the unit's tests share it:
/// the golden twin of [`hw::TraversalUnit`](crate::hw::TraversalUnit)
/// (src/hw/traversal_unit.rs).
#[derive(Clone, Debug, Default)]
pub struct KdWalk {
    node: u32,
    lo: u32,
    hi: u32,
    stack: Vec<(u32, u32, u32)>,
    /// The segment end of the leaf handed out last.
    leaf_hi: u32,
}

impl KdWalk {
    /// Walks from `root` with the segment `[t_min, t_max]` to the first leaf. `fetch` reads a
    /// node; `max_depth` bounds the stack.
    pub fn start(
        f: Format,
        ray: (Vec3W, Vec3W),
        root: u32,
        (t_min, t_max): (u32, u32),
        max_depth: usize,
        fetch: impl FnMut(u32) -> Result<Node, String>,
    ) -> Result<(KdWalk, KdStop), String> {
        let mut walk = KdWalk {
            node: root,
            lo: t_min,
            hi: t_max,
            ..KdWalk::default()
        };
        let stop = walk.to_leaf(f, ray, max_depth, fetch)?;
        Ok((walk, stop))
    }

    /// Goes on after the last leaf, whose closest hit so far is `best_t` (when `hit`): ends
    /// when the hit lies in that leaf's segment, the stack is empty, or the popped segment
    /// starts behind the hit.
    pub fn next(
        &mut self,
        f: Format,
        ray: (Vec3W, Vec3W),
        (best_t, hit): (u32, bool),
        max_depth: usize,
        fetch: impl FnMut(u32) -> Result<Node, String>,
    ) -> Result<KdStop, String> {
        if hit && f.le(best_t, self.leaf_hi) {
            return Ok(KdStop::Finished);
        }
        match self.stack.pop() {
            Some((_, lo, _)) if hit && f.lt(best_t, lo) => Ok(KdStop::Finished),
            Some((node, lo, hi)) => {
                (self.node, self.lo, self.hi) = (node, lo, hi);
                self.to_leaf(f, ray, max_depth, fetch)
            }
            None => Ok(KdStop::Finished),
        }
    }

    fn to_leaf(
        &mut self,
        f: Format,
        (o, d): (Vec3W, Vec3W),
        max_depth: usize,
        mut fetch: impl FnMut(u32) -> Result<Node, String>,
    ) -> Result<KdStop, String> {
        loop {
            match fetch(self.node)? {
                Node::Inner { axis, split, left } => {
                    let (near_is_left, visit) =
                        traversal_step(f, o[axis], d[axis], split, self.lo, self.hi);
                    let (near, far) = if near_is_left {
                        (left, left + 1)
                    } else {
                        (left + 1, left)
                    };
                    self.node = match visit {
                        Visit::Near => near,
                        Visit::Far => far,
                        Visit::Both { t_split } => {
                            if self.stack.len() >= max_depth {
                                return Err(format!("kd stack deeper than {max_depth} levels"));
                            }
                            self.stack.push((far, t_split, self.hi));
                            self.hi = t_split;
                            near
                        }
                    };
                }
                Node::Leaf { list, count } => {
                    self.leaf_hi = self.hi;
                    return Ok(KdStop::Leaf { list, count });
                }
            }
        }
    }
}

/// `a . b` as `(ax*bx + ay*by) + az*bz`.
pub fn dot<A: Arith>(a: A, x: [A::V; 3], y: [A::V; 3]) -> A::V {
    a.add(
        a.add(a.mul(x[0], y[0]), a.mul(x[1], y[1])),
        a.mul(x[2], y[2]),
    )
}

/// The point `o + t*d`, per component `o + t*d`.
pub fn ray_point<A: Arith>(a: A, o: [A::V; 3], d: [A::V; 3], t: A::V) -> [A::V; 3] {
    [0, 1, 2].map(|i| a.add(o[i], a.mul(t, d[i])))
}

/// `b - a` per component.
pub fn sub3<A: Arith>(a: A, y: [A::V; 3], x: [A::V; 3]) -> [A::V; 3] {
    [0, 1, 2].map(|i| a.sub(y[i], x[i]))
}

/// Shader: `n / sqrt(n.n)` as one reciprocal and three products. The layout stores unit
/// normals, so only a normal that went through an instance's normal matrix needs it (a scene
/// without instances shades with the stored normal: 10 operations fewer per hit).
pub fn unit_length<A: Arith>(a: A, n: [A::V; 3]) -> [A::V; 3] {
    let inv_len = a.div(a.word(a.format().one()), a.sqrt(dot(a, n, n)));
    n.map(|c| a.mul(c, inv_len))
}

/// Shader: the unit normal `n` facing the incoming ray: flipped when `0 < n . d` (it points
/// along the ray).
pub fn facing_normal(f: Format, n: Vec3W, ray_dir: Vec3W) -> Vec3W {
    if f.lt(0, dot(f, n, ray_dir)) {
        n.map(|c| f.neg(c))
    } else {
        n
    }
}

/// Shader: the world-space unit normal of a hit on a triangle whose stored (object-space,
/// unit) normal is `n_obj`: through the instance's normal matrix `normal_matrix` and
/// [`unit_length`] when there is one, else the stored normal as it is.
pub fn world_normal(f: Format, n_obj: Vec3W, normal_matrix: Option<&[u32; 9]>) -> Vec3W {
    match normal_matrix {
        Some(m) => unit_length(f, transform3(f, m, n_obj)),
        None => n_obj,
    }
}

/// Shader: the Lambert cosine `(n . L) / sqrt(L . L)` from `n . L` ([`dot`]) once it is known
/// to be positive.
pub fn lambert_from_dot<A: Arith>(a: A, n_dot_l: A::V, to_light: [A::V; 3]) -> A::V {
    a.div(n_dot_l, a.sqrt(dot(a, to_light, to_light)))
}

/// Shader: the Lambert cosine of a light seen along `to_light` (not normalized) from a surface
/// with unit normal `n`, or `None` when the light is behind (`!(0 < n . L)`).
pub fn lambert_cosine(f: Format, n: Vec3W, to_light: Vec3W) -> Option<u32> {
    let n_dot_l = dot(f, n, to_light);
    if !f.lt(0, n_dot_l) {
        return None;
    }
    Some(lambert_from_dot(f, n_dot_l, to_light))
}

/// Shader: `acc + (kd * light) * cos` per channel.
pub fn add_light<A: Arith>(
    a: A,
    acc: [A::V; 3],
    kd: [A::V; 3],
    light: [A::V; 3],
    cos: A::V,
) -> [A::V; 3] {
    [0, 1, 2].map(|i| a.add(acc[i], a.mul(a.mul(kd[i], light[i]), cos)))
}

/// Shader: the ambient term `kd * ambient` per channel.
pub fn ambient<A: Arith>(a: A, kd: [A::V; 3], ambient: A::V) -> [A::V; 3] {
    kd.map(|c| a.mul(c, ambient))
}

/// Shader: the mirror direction `d - (2 (d . n)) n` for a unit normal `n`.
pub fn reflect<A: Arith>(a: A, d: [A::V; 3], n: [A::V; 3]) -> [A::V; 3] {
    let k = a.mul(a.word(a.format().from_int(2)), dot(a, d, n));
    [0, 1, 2].map(|i| a.sub(d[i], a.mul(k, n[i])))
}

/// Shader: `(1 - m) * local + m * reflected` per channel.
pub fn mix_mirror<A: Arith>(a: A, local: [A::V; 3], reflected: [A::V; 3], m: A::V) -> [A::V; 3] {
    let keep = a.sub(a.word(a.format().one()), m);
    [0, 1, 2].map(|i| a.add(a.mul(keep, local[i]), a.mul(m, reflected[i])))
}

/// Shader: a colour channel already clamped to [0, 1], scaled by 255 (one rounding) and
/// rounded to an integer by adding `2^M`: the sum's spacing is 1, so the adder's round to
/// nearest even does the integer rounding, and the word's low 8 bits are the channel byte
/// (`Format::to_u8` after its clamp; `M >= 8`). In hardware: the `FpMul` and `FpAddSub` of
/// [`hw::ChannelByte`](crate::hw::ChannelByte).
pub fn channel_byte_word<A: Arith>(a: A, clamped: A::V) -> A::V {
    let f = a.format();
    let scaled = a.mul(clamped, a.word(f.from_int(255)));
    a.add(scaled, a.word(f.from_int(1i64 << f.man_bits)))
}

/// Shader: a colour channel clamped to [0, 1] (NaN, negatives, zeros and subnormals give
/// +0, everything above 1 gives 1), on the bits alone: for positive non-NaN words the unsigned
/// order of the encodings is the order of the values, so the hardware needs no comparator
/// (`Format::to_u8`'s clamp, exhaustively tested). In hardware: the combinational clamp in
/// front of [`hw::ChannelByte`](crate::hw::ChannelByte)'s multiplier.
pub fn clamp_unit_word(f: Format, w: u32) -> u32 {
    if f.sign_of(w) || f.is_zero(w) || f.is_nan(w) {
        0
    } else if w > f.one() {
        f.one()
    } else {
        w
    }
}

/// Shader: the byte of a colour channel, `Format::to_u8` as the hardware computes it (the
/// engine's `byte` instruction): [`clamp_unit_word`], then [`channel_byte_word`]'s low 8 bits.
/// Golden twin of [`hw::ChannelByte`](crate::hw::ChannelByte) (src/hw/channel_byte.rs).
pub fn channel_byte(f: Format, w: u32) -> u32 {
    channel_byte_word(f, clamp_unit_word(f, w)) & 0xff
}

/// The frame-buffer word `0x00RRGGBB` of a colour.
pub fn pack_rgb(f: Format, c: Vec3W) -> u32 {
    let [r, g, b] = c.map(|x| u32::from(f.to_u8(x)));
    (r << 16) | (g << 8) | b
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    // TransformUnit passes and direct shading.

    /// A word for the pass tests: mostly values of magnitude 2^-6..2^6, else zeros of both
    /// signs, infinities, NaN and uniform bit patterns (subnormals among them).
    fn pass_word(f: Format, rng: &mut ChaCha8Rng) -> u32 {
        match rng.gen_range(0..16) {
            0 => f.zero(rng.gen_bool(0.5)),
            1 => f.infinity(rng.gen_bool(0.5)),
            2 => f.nan(),
            3 => rng.gen::<u32>() & f.word_mask(),
            _ => crate::hw::sim_harness::random_word(f, rng),
        }
    }

    #[test]
    fn a_pass_without_diagonal_is_the_transform() {
        let seed = 71;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for f in [Format::E7M16, Format::E8M23, Format::E5M10] {
            for _ in 0..20_000 {
                let m: Mat34W = std::array::from_fn(|_| pass_word(f, &mut rng));
                let v: Vec3W = std::array::from_fn(|_| pass_word(f, &mut rng));
                let point = rng.gen_bool(0.5);
                assert_eq!(
                    transform_pass(f, &m, v, point, false),
                    transform(f, &m, v, point),
                    "{f} {m:x?} {v:x?} {point}"
                );
            }
        }
    }

    #[test]
    fn a_diagonal_pass_is_per_component() {
        let seed = 72;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for f in [Format::E7M16, Format::E8M23, Format::E5M10] {
            for _ in 0..20_000 {
                let mut w = || pass_word(f, &mut rng);
                let (d, v, o) = ([w(), w(), w()], [w(), w(), w()], [w(), w(), w()]);
                let m = diagonal_matrix(d, o);
                let point = transform_pass(f, &m, v, true, true);
                let vector = transform_pass(f, &m, v, false, true);
                for r in 0..3 {
                    assert_eq!(
                        point[r],
                        f.add(o[r], f.mul(v[r], d[r])),
                        "{f} point row {r}"
                    );
                    assert_eq!(vector[r], f.mul(d[r], v[r]), "{f} vector row {r}");
                }
                // -1 times p plus the light is the light minus p.
                let minus =
                    transform_pass(f, &diagonal_matrix([f.from_int(-1); 3], o), v, true, true);
                assert_eq!(minus, sub3(f, o, v), "{f}");
            }
        }
    }

    /// The golden model's direct shading of a hit (`model::golden`'s `shade` without shadows,
    /// mirrors or instances), spelled with its own sequences.
    fn golden_direct(f: Format, k: &ShadingConstants, hit: Option<&SurfaceHit>) -> u32 {
        let Some(h) = hit else {
            return pack_rgb(f, k.background);
        };
        let p = ray_point(f, h.o, h.d, h.t);
        let n = facing_normal(f, h.n, h.d);
        let mut acc = ambient(f, h.kd, k.ambient);
        for light in &k.lights {
            let to_light = sub3(f, light.position, p);
            if let Some(cos) = lambert_cosine(f, n, to_light) {
                acc = add_light(f, acc, h.kd, light.color, cos);
            }
        }
        pack_rgb(f, acc)
    }

    #[test]
    fn shading_passes_equal_the_golden_shading() {
        let seed = 73;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for f in [Format::E7M16, Format::E8M23, Format::E5M10] {
            let mut lit = 0;
            for case in 0..20_000 {
                // Scene-like values most of the time (a unit normal, colours in [0, 1], a
                // light above), any words in one case of four.
                let wild = case % 4 == 0;
                let mut w = |lo: f64, hi: f64| {
                    if wild {
                        pass_word(f, &mut rng)
                    } else {
                        f.from_f64(rng.gen_range(lo..hi))
                    }
                };
                let n = [w(-1.0, 1.0), w(-1.0, 1.0), w(-1.0, 1.0)];
                let hit = SurfaceHit {
                    o: [w(-2.0, 2.0), w(-2.0, 2.0), w(-5.0, -3.0)],
                    d: [w(-1.0, 1.0), w(-1.0, 1.0), w(0.5, 1.0)],
                    t: w(0.0, 8.0),
                    n,
                    kd: [w(0.0, 1.0), w(0.0, 1.0), w(0.0, 1.0)],
                };
                let lights = (0..case % 4)
                    .map(|_| LightWords {
                        position: [w(-3.0, 3.0), w(2.0, 4.0), w(-3.0, 3.0)],
                        color: [w(0.0, 1.0), w(0.0, 1.0), w(0.0, 1.0)],
                    })
                    .collect();
                let k = ShadingConstants {
                    ambient: w(0.0, 0.3),
                    background: [w(0.0, 1.0), w(0.0, 1.0), w(0.0, 1.0)],
                    lights,
                };
                let hit = (case % 7 != 0).then_some(&hit);
                let got = shade_direct(f, &k, hit);
                assert_eq!(got, golden_direct(f, &k, hit), "{f} case {case}");
                lit += usize::from(got != pack_rgb(f, k.background) && hit.is_some());
            }
            // The comparison saw shaded surfaces, not only backgrounds and black.
            assert!(lit > 5_000, "{f}: {lit}");
        }
    }

    // Channel bytes.

    #[test]
    fn channel_byte_equals_to_u8_on_every_word() {
        // Every word of the 16- and 24-bit formats; binary32 on a seeded sample and its edges.
        for f in [Format::E5M10, Format::E7M16] {
            for w in 0..1u32 << f.width() {
                assert_eq!(channel_byte(f, w), u32::from(f.to_u8(w)), "{f} word {w:#x}");
            }
        }
        let f = Format::E8M23;
        let seed = 41;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let edges = [
            0,
            f.one(),
            f.one() + 1,
            f.one() - 1,
            f.infinity(false),
            f.nan(),
        ];
        // Half the sample in [0, 1], where every byte is made.
        let sample = (0..1_000_000).map(|k| match k % 2 {
            0 => rng.gen_range(0..=f.one()),
            _ => rng.gen::<u32>(),
        });
        for w in edges
            .into_iter()
            .flat_map(|w| [w, w | f.sign_mask()])
            .chain(sample)
        {
            assert_eq!(channel_byte(f, w), u32::from(f.to_u8(w)), "{f} word {w:#x}");
        }
    }

    // Edge margins.

    #[test]
    fn margin_zero_is_the_exact_test_and_a_margin_only_adds_hits_near_edges() {
        let seed = 61;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for f in [Format::E7M16, Format::E8M23, Format::E5M10] {
            // Wide enough that random rays land in it often.
            let margin = f.from_f64(0.05);
            let (mut added, mut near_edge) = (0, 0);
            for _ in 0..20_000 {
                let mut w = || f.from_f64(rng.gen_range(-2.0..2.0));
                let (o, d) = ([w(), w(), w()], [w(), w(), w()]);
                let inf = f.infinity(false);
                let exact = intersect_with_margin(f, o, d, 0, inf, 0);
                let wide = intersect_with_margin(f, o, d, 0, inf, margin);
                assert_eq!((wide.t, wide.u, wide.v), (exact.t, exact.u, exact.v));
                assert!(wide.hit || !exact.hit, "a margin never loses a hit");
                if wide.hit && !exact.hit {
                    added += 1;
                    let (u, v) = (f.to_f64(wide.u), f.to_f64(wide.v));
                    let m = f.to_f64(margin);
                    // Only points within the margin of the triangle's edges are added.
                    assert!(u < 0.0 || v < 0.0 || u + v > 1.0);
                    assert!(u >= -m && v >= -m && u + v <= 1.0 + 2.0 * m, "{u} {v}");
                    near_edge += 1;
                }
            }
            println!("{f}: margin adds {added} hits, all within it of an edge ({near_edge})");
            assert!(
                added > 0,
                "{f}: random rays must sometimes land in the margin"
            );
        }
    }
}
