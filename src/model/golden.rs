//! The golden model: the hardware's algorithm in `eXmY` arithmetic, reading only the layout.
//!
//! Per pixel: RayGen builds the primary ray; the traversal walks the top-level kd-tree (absent
//! for a scene of one untransformed object), enters each instance it reaches by transforming
//! the ray into object space with the TransformUnit, walks the object tree with a bounded
//! stack, skips triangles its mailbox has already tested, and tests triangles by transforming
//! the ray into unit-triangle space and running the IntersectUnit. The shader adds ambient and
//! Lambert terms per light, casts a shadow ray per light (any hit ends it), and a mirror ray up
//! to the reflection depth. Every operation is one of the shared sequences in
//! [`super::units`].
//!
//! Secondary rays start on a surface. Two things keep them off it: the originating triangle
//! (instance and triangle id) is never tested, and t starts at the layout's small positive
//! `SHADOW_T_MIN` / `MIRROR_T_MIN` so a neighbouring triangle across an edge is not hit at the
//! origin either.

use super::units::{self, Vec3W, Visit};
use crate::fp::Format;
use crate::layout::{instance_word as iw, FrameMap, Layout, Node, FRAME, INSTANCES, LISTS};

pub use super::units::{Mailbox, MAILBOX_ENTRIES};

/// The closest hit found so far.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hit {
    pub t: u32,
    pub instance: u32,
    /// Global triangle index (see the layout).
    pub triangle: u32,
}

/// Work done for one pixel, counted per unit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayStats {
    pub rays: u64,
    pub traversal_steps: u64,
    pub leaves: u64,
    pub instance_entries: u64,
    pub triangle_tests: u64,
    pub mailbox_skips: u64,
    pub transforms: u64,
    pub shadow_rays: u64,
    pub mirror_rays: u64,
}

impl std::ops::AddAssign for RayStats {
    fn add_assign(&mut self, o: RayStats) {
        self.rays += o.rays;
        self.traversal_steps += o.traversal_steps;
        self.leaves += o.leaves;
        self.instance_entries += o.instance_entries;
        self.triangle_tests += o.triangle_tests;
        self.mailbox_skips += o.mailbox_skips;
        self.transforms += o.transforms;
        self.shadow_rays += o.shadow_rays;
        self.mirror_rays += o.mirror_rays;
    }
}

/// What the golden model computes for one pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pixel {
    /// Frame-buffer word `0x00RRGGBB`.
    pub rgb: u32,
    /// The shaded colour before packing (format words): the stress suite checks that no NaN
    /// or infinity reaches a pixel, which packing (NaN to 0) would hide.
    pub color: Vec3W,
    /// Primary ray direction (world space, format words).
    pub dir: Vec3W,
    pub hit: Option<Hit>,
    pub stats: RayStats,
}

/// One ray query.
#[derive(Clone, Copy)]
struct Query {
    o: Vec3W,
    d: Vec3W,
    t_min: u32,
    t_max: u32,
    /// The (instance, triangle) the ray starts on.
    skip: Option<(u32, u32)>,
    /// Stop at the first hit (shadow rays).
    any: bool,
}

/// The golden renderer of one frame's layout.
pub struct Golden<'a> {
    layout: &'a Layout,
    f: Format,
    /// Edge margin of the unit-triangle test (a format word): [`units::edge_margin`] unless
    /// a study sets another with [`Golden::with_edge_margin`] (0 = the exact test).
    edge_margin: u32,
}

/// The outcome of one ray traced with [`Golden::trace_ray`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayResult {
    pub hit: Option<Hit>,
    pub stats: RayStats,
}

impl<'a> Golden<'a> {
    pub fn new(layout: &'a Layout) -> Self {
        Golden {
            layout,
            f: layout.format,
            edge_margin: units::edge_margin(layout.format),
        }
    }

    /// A golden model whose unit-triangle test accepts `u, v >= -margin` and
    /// `u + v <= 1 + margin` (margin in unit-triangle coordinates, rounded to the format).
    /// What the hardware computes only for the default margin (`units::edge_margin`).
    pub fn with_edge_margin(layout: &'a Layout, margin: f64) -> Self {
        Golden {
            edge_margin: layout.format.from_f64(margin.abs()),
            ..Golden::new(layout)
        }
    }

    pub fn layout(&self) -> &'a Layout {
        self.layout
    }

    /// Traces one world-space ray `o + t d`, t in (t_min, t_max), exactly as the renderer
    /// traces its rays (closest hit, or the first hit found when `any`), optionally skipping one
    /// (instance, global triangle). For stress tests and studies of single rays.
    pub fn trace_ray(
        &self,
        o: Vec3W,
        d: Vec3W,
        t_min: u32,
        t_max: u32,
        skip: Option<(u32, u32)>,
        any: bool,
    ) -> RayResult {
        let mut stats = RayStats::default();
        let q = Query {
            o,
            d,
            t_min,
            t_max,
            skip,
            any,
        };
        let hit = self.trace(q, &mut stats);
        RayResult { hit, stats }
    }

    fn frame_words<const N: usize>(&self, addr: usize) -> [u32; N] {
        self.layout.words::<N>(FRAME, addr)
    }

    /// The primary ray of pixel (x, y), counted in `stats`.
    fn primary_query(&self, x: u32, y: u32, stats: &mut RayStats) -> Query {
        let f = self.f;
        let camera = self.frame_words::<12>(FrameMap::CAMERA);
        stats.transforms += 1;
        Query {
            o: self.frame_words::<3>(FrameMap::EYE),
            d: units::primary_direction(f, &camera, x, y),
            t_min: 0,
            t_max: f.infinity(false),
            skip: None,
            any: false,
        }
    }

    /// Renders pixel (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> Pixel {
        let mut stats = RayStats::default();
        let query = self.primary_query(x, y, &mut stats);
        let (color, hit) = self.shade(query, 0, &mut stats);
        Pixel {
            rgb: units::pack_rgb(self.f, color),
            color,
            dir: query.d,
            hit,
            stats,
        }
    }

    /// Traces only the primary ray of pixel (x, y) (closest hit, no shading): the traversal
    /// work that the tree's shape decides.
    pub fn primary_ray(&self, x: u32, y: u32) -> RayResult {
        let mut stats = RayStats::default();
        let query = self.primary_query(x, y, &mut stats);
        let hit = self.trace(query, &mut stats);
        RayResult { hit, stats }
    }

    /// Traces a ray and shades what it hits; returns the colour and the hit.
    fn shade(&self, q: Query, depth: u32, stats: &mut RayStats) -> (Vec3W, Option<Hit>) {
        let f = self.f;
        let Some(hit) = self.trace(q, stats) else {
            return (self.frame_words::<3>(FrameMap::BACKGROUND), None);
        };
        let l = self.layout;
        let p = units::ray_point(f, q.o, q.d, hit.t);
        let (n_obj, material) = l.triangle_shading(hit.triangle);
        let normal_matrix = l.info.top_root.map(|_| {
            stats.transforms += 1;
            let base = hit.instance as usize * crate::layout::INSTANCE_WORDS + iw::NORMAL_MATRIX;
            l.words::<9>(INSTANCES, base)
        });
        let n_world = units::world_normal(f, n_obj, normal_matrix.as_ref());
        let n = units::facing_normal(f, n_world, q.d);
        let (kd, mirror) = l.material(material);

        let mut acc = units::ambient(f, kd, self.frame_words::<1>(FrameMap::AMBIENT)[0]);
        let shadow_t_min = self.frame_words::<1>(FrameMap::SHADOW_T_MIN)[0];
        for light in 0..l.info.light_count as usize {
            let base = FrameMap::LIGHTS + light * crate::layout::LIGHT_WORDS;
            let position = self.frame_words::<3>(base);
            let color = self.frame_words::<3>(base + 3);
            let to_light = units::sub3(f, position, p);
            let Some(cos) = units::lambert_cosine(f, n, to_light) else {
                continue;
            };
            if l.info.shadows {
                stats.shadow_rays += 1;
                let shadow = Query {
                    o: p,
                    d: to_light,
                    t_min: shadow_t_min,
                    t_max: f.one(),
                    skip: Some((hit.instance, hit.triangle)),
                    any: true,
                };
                if self.trace(shadow, stats).is_some() {
                    continue;
                }
            }
            acc = units::add_light(f, acc, kd, color, cos);
        }
        if depth < l.info.reflection_depth && f.lt(0, mirror) {
            stats.mirror_rays += 1;
            let r = units::reflect(f, q.d, n);
            let bounce = Query {
                o: p,
                d: r,
                t_min: self.frame_words::<1>(FrameMap::MIRROR_T_MIN)[0],
                t_max: f.infinity(false),
                skip: Some((hit.instance, hit.triangle)),
                any: false,
            };
            let (reflected, _) = self.shade(bounce, depth + 1, stats);
            acc = units::mix_mirror(f, acc, reflected, mirror);
        }
        (acc, Some(hit))
    }

    /// Closest hit (or any hit for `q.any`) of a world-space ray.
    fn trace(&self, q: Query, stats: &mut RayStats) -> Option<Hit> {
        stats.rays += 1;
        let l = self.layout;
        let mut best = None;
        match l.info.top_root {
            None => {
                let mut mailbox = Mailbox::new();
                self.traverse(
                    l.info.object_root,
                    q,
                    &mut best,
                    stats,
                    &mut |golden, list, count, best, stats| {
                        golden.test_triangles(0, q, list, count, &mut mailbox, best, stats)
                    },
                );
            }
            Some(root) => {
                let mut instances = Mailbox::new();
                self.traverse(
                    root,
                    q,
                    &mut best,
                    stats,
                    &mut |golden, list, count, best, stats| {
                        for k in 0..count {
                            let instance = l.word(LISTS, list + k);
                            if instances.seen(instance) {
                                stats.mailbox_skips += 1;
                                continue;
                            }
                            if golden.enter_instance(instance, q, best, stats) {
                                return true;
                            }
                        }
                        false
                    },
                );
            }
        }
        best
    }

    /// Transforms the ray into the instance's object space and traverses its tree. Affine maps
    /// keep the ray parameter t, so object-space hits compare directly with world ones.
    fn enter_instance(
        &self,
        instance: u32,
        q: Query,
        best: &mut Option<Hit>,
        stats: &mut RayStats,
    ) -> bool {
        let f = self.f;
        let l = self.layout;
        stats.instance_entries += 1;
        stats.transforms += 2;
        let base = instance as usize * crate::layout::INSTANCE_WORDS;
        let to_object = l.words::<12>(INSTANCES, base + iw::WORLD_TO_OBJECT);
        let root = l.word(INSTANCES, (base + iw::ROOT) as u32);
        let local = Query {
            o: units::transform(f, &to_object, q.o, true),
            d: units::transform(f, &to_object, q.d, false),
            ..q
        };
        let mut mailbox = Mailbox::new();
        self.traverse(
            root,
            local,
            best,
            stats,
            &mut |golden, list, count, best, stats| {
                golden.test_triangles(instance, local, list, count, &mut mailbox, best, stats)
            },
        )
    }

    /// Tests the triangles of one leaf; true when an any-hit query is answered.
    #[allow(clippy::too_many_arguments)]
    fn test_triangles(
        &self,
        instance: u32,
        q: Query,
        list: u32,
        count: u32,
        mailbox: &mut Mailbox,
        best: &mut Option<Hit>,
        stats: &mut RayStats,
    ) -> bool {
        let f = self.f;
        let l = self.layout;
        for k in 0..count {
            let triangle = l.word(LISTS, list + k);
            if q.skip == Some((instance, triangle)) {
                continue;
            }
            if mailbox.seen(triangle) {
                stats.mailbox_skips += 1;
                continue;
            }
            stats.triangle_tests += 1;
            stats.transforms += 2;
            let m = l.triangle_transform(triangle);
            let o = units::transform(f, &m, q.o, true);
            let d = units::transform(f, &m, q.d, false);
            let t_max = best.map_or(q.t_max, |b| b.t);
            let r = units::intersect_with_margin(f, o, d, q.t_min, t_max, self.edge_margin);
            if r.hit {
                *best = Some(Hit {
                    t: r.t,
                    instance,
                    triangle,
                });
                if q.any {
                    return true;
                }
            }
        }
        false
    }

    /// Front-to-back kd traversal from `root`; `leaf` handles each leaf's list and returns true
    /// to stop (an any-hit query answered). Returns that stop flag.
    fn traverse(
        &self,
        root: u32,
        q: Query,
        best: &mut Option<Hit>,
        stats: &mut RayStats,
        leaf: &mut dyn FnMut(&Self, u32, u32, &mut Option<Hit>, &mut RayStats) -> bool,
    ) -> bool {
        let f = self.f;
        // The hardware's stack holds one entry per tree level: a ray pushes at most once per
        // inner node on its way down, so the deepest tree bounds it.
        let capacity = self
            .layout
            .info
            .object_depth
            .max(self.layout.info.top_depth) as usize;
        let mut stack: Vec<(u32, u32, u32)> = Vec::with_capacity(capacity);
        let (mut node, mut lo, mut hi) = (root, q.t_min, best.map_or(q.t_max, |b| b.t));
        loop {
            match self.layout.node(node) {
                Node::Inner { axis, split, left } => {
                    stats.traversal_steps += 1;
                    let (near_is_left, visit) =
                        units::traversal_step(f, q.o[axis], q.d[axis], split, lo, hi);
                    let (near, far) = if near_is_left {
                        (left, left + 1)
                    } else {
                        (left + 1, left)
                    };
                    match visit {
                        Visit::Near => node = near,
                        Visit::Far => node = far,
                        Visit::Both { t_split } => {
                            assert!(
                                stack.len() < capacity,
                                "traversal stack overflow: the layout's depth is wrong"
                            );
                            stack.push((far, t_split, hi));
                            node = near;
                            hi = t_split;
                        }
                    }
                    continue;
                }
                Node::Leaf { list, count } => {
                    stats.leaves += 1;
                    if leaf(self, list, count, best, stats) {
                        return true;
                    }
                    if best.is_some_and(|b| f.le(b.t, hi)) {
                        return false;
                    }
                }
            }
            match stack.pop() {
                Some((n, l, h)) => {
                    if best.is_some_and(|b| f.lt(b.t, l)) {
                        return false;
                    }
                    (node, lo, hi) = (n, l, h);
                }
                None => return false,
            }
        }
    }
}
