//! Traversal: the trace routine of the microprogram (`model::golden`'s `trace`, `traverse`,
//! `enter_instance` and `test_triangles`, step for step).
//!
//! Object trees are walked by the traversal unit (`hw::TraversalUnit`, per `units::KdWalk`):
//! the thread starts the walk and sleeps until it ends. The unit hands each leaf's list to
//! the triangle tester (`hw::TriangleTester`), whose list unit drops the triangle the query
//! starts on and those in the thread's triangle mailbox and queues the rest; the tester
//! answers the unit with the closest hit, which ends the walk or pops its stack. A shadow
//! query's walk (`KD_ANY_HIT` in its walk word) ends after the first leaf with a hit. A shadow
//! ray has a trace routine of its own ([`Query::Any`]): its origin and direction are the
//! shader's hit point and light vector in the query registers, its range and walk words
//! registers of constants, its skip pair the hit the shader read there, so that the shader
//! moves no register for it.
//!
//! The top-level tree of a scene with instances is walked by the traversal unit too
//! (`kd.start` with `KD_TOP`), on the world ray that `tri.world` gave it (and instance entry)
//! at the trace's start: the unit steps through the inner nodes and stops at each leaf, and
//! the thread, woken, reads the leaf's instance list (`kd.wait`, `kd.leaf`) and enters each
//! instance not yet in the instance mailbox (`tri.enter`: the instance entry unit,
//! `hw::engine::InstanceRays`, transforms the world ray into the object's space through the
//! one TransformUnit and writes it into both coprocessors, and the traversal unit then walks
//! the object from the root the entry read, up to the closest hit so far); the thread sleeps
//! until that walk ends, and after the list sends the closest hit back (`kd.next`), with
//! which the unit ends the walk or pops its top-level stack, as `units::KdWalk` does.
//!
//! Cost (instructions = engine turns): per object walk 2 or 3 (start, wait with the hit flag,
//! and the closest hit's t without a top level), whatever its leaves; a waiting thread sleeps
//! until the walk ends (the tree's nodes and the leaves' triangles cost it no instruction);
//! per top-level leaf 5 (the wait, the list's end, the end check, `kd.next` and the loop's
//! jump) and no instruction per top-level inner node; per instance entered 6 (the list word,
//! its address, the mailbox, `tri.enter`, the walk's wait, the loop) and 4 per instance the
//! mailbox skips, with 1 more per walk of a shadow query (its answer); per trace 3 for the
//! world ray, 1 for the top-level walk's start and 1 for the closest hit's t (none for a
//! shadow ray of one object, whose answer is the walk's hit flag).

use super::asm::Asm;
use super::asm::{Label, Reg, Val};
use super::isa::{Op, TriFn, KD_ANY_HIT, KD_TOP, KD_WALK_ENDED, MAILBOX_INSTANCES};
use super::Gen;
use crate::layout::LISTS;

/// Gives the triangle tester and the traversal unit the ray of the one object (object 0,
/// whose mailbox the query's init emptied).
fn tester_ray(a: &Asm, o: [Reg; 3], d: [Reg; 3]) {
    a.tri_ray(TriFn::RayOxy, o[0], o[1]);
    a.tri_ray(TriFn::RayOzDx, o[2], d[0]);
    a.tri_ray(TriFn::RayDyz, d[1], d[2]);
}

/// What a trace asks for: the closest hit of the query registers (primary and mirror rays),
/// or any hit (a shadow ray: from the hit point in `q_o` along the light's vector in `q_d`,
/// over `[t_min, one]`, both registers of constants).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Query {
    Closest,
    Any { t_min: Reg, one: Reg },
}

/// Where a trace's ray is.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Ray {
    /// A primary ray: ray generation wrote it into both coprocessors and its direction into
    /// the query's direction registers; it starts at the eye (`eye`) at t 0 and skips nothing,
    /// so the trace sets its query from constants and moves no register.
    Primary { eye: [Reg; 3] },
    /// The query registers: origin, direction, t range and skip pair.
    Query,
}

/// The skip pair's word no instance and no triangle has.
pub(super) const NO_HIT: u32 = u32::MAX;

impl Gen<'_> {
    /// The words `kd.start` (one object) and `tri.enter` (under a top level) walk an object
    /// with, which the program keeps in registers from its start: the object's root (none
    /// under a top level) and, with shadows, the same with [`KD_ANY_HIT`].
    pub(super) fn walk_words(&self) -> Vec<u32> {
        let root = self.walk_root();
        let mut words = vec![root];
        if self.c.shadows {
            words.push(root | KD_ANY_HIT);
        }
        words.retain(|&w| w != 0);
        words
    }

    /// The root an object walk names: the one object's, or none under a top level (the
    /// entered object's, which the traversal unit keeps).
    fn walk_root(&self) -> u32 {
        match self.c.top_root {
            Some(_) => 0,
            None => self.c.object_root,
        }
    }

    /// The walk word of [`Self::walk_words`] for `query`.
    fn walk_word(&self, query: Query) -> Reg {
        let root = self.walk_root();
        let any = if query == Query::Closest {
            0
        } else {
            KD_ANY_HIT
        };
        match root | any {
            0 => Reg::ZERO,
            w => self
                .asm
                .kept_constant(w)
                .expect("walk words are kept from the start"),
        }
    }

    /// The trace of `ray`: its closest hit, or any hit (`query`); gives `hit` (where the
    /// shader reads the flag) and `best_t`, and returns through `link` when `routine` (else it
    /// is in line). The hit's instance and triangle stay in the tester. Returns where a primary
    /// ray enters the routine, after the words it brings itself: its query (from
    /// [`Self::trace_query`]) and, for one object, its ray (ray generation's).
    pub(super) fn trace_routine(&self, routine: bool, query: Query, ray: Ray) -> Label {
        let a = self.asm;
        let s = &self.s;
        let done = a.label();
        let primary_entry = a.label();
        let t_max = self.trace_query(query, ray);
        let walk = self.walk_word(query);
        match self.c.top_root {
            Some(root) => {
                a.bind(primary_entry);
                // The world ray that the top-level walk and instance entry transform.
                let o = match ray {
                    Ray::Primary { eye } => eye,
                    Ray::Query => s.q_o,
                };
                for (pair, [x, y]) in [[o[0], o[1]], [o[2], s.q_d[0]], [s.q_d[1], s.q_d[2]]]
                    .into_iter()
                    .enumerate()
                {
                    a.tri_world(pair as u8, x, y);
                }
                a.mailbox_clear(MAILBOX_INSTANCES);
                self.traverse(root, t_max, walk, query, done);
                a.bind(done);
                a.section("trace");
                // The instances' walks leave the closest hit in the tester.
                a.tri_wait(s.best_t);
            }
            None => {
                // A primary ray is in both coprocessors already (ray generation wrote it).
                if ray == Ray::Query {
                    tester_ray(a, s.q_o, s.q_d);
                }
                a.bind(primary_entry);
                a.section("traversal");
                a.kd_start(walk, t_max);
                // One object's any-hit walk ends at its first hit by itself.
                self.walk_end(query, None);
                if query == Query::Closest {
                    a.section("intersect");
                    a.tri_wait(s.best_t);
                }
                a.bind(done);
            }
        }
        if routine {
            a.section("trace");
            a.ret(s.link);
        }
        primary_entry
    }

    /// A trace's query in the tester: its t range and (with secondary rays) the hit it starts
    /// on, which it skips (a primary ray: from 0, skipping the pair no hit has). Returns the
    /// register holding the range's end, where the walk stops too.
    pub(super) fn trace_query(&self, query: Query, ray: Ray) -> Reg {
        let a = self.asm;
        let s = &self.s;
        a.section("trace");
        let (t_min, t_max) = match (query, ray) {
            (Query::Closest, Ray::Query) => (s.q_t_min, s.q_t_max),
            (Query::Closest, Ray::Primary { .. }) => (Reg::ZERO, s.q_t_max),
            (Query::Any { t_min, one }, _) => (t_min, one),
        };
        a.tri_queue(TriFn::Init, t_min, t_max);
        // The triangle a secondary ray starts on is never tested (primary rays skip none, so
        // a scene without secondary rays never names one).
        if self.secondary_rays() {
            let (instance, triangle) = match ray {
                Ray::Primary { .. } => (self.no_hit(), self.no_hit()),
                Ray::Query => (s.skip_instance, s.skip_triangle),
            };
            a.tri_queue(TriFn::Skip, instance, triangle);
        }
        t_max
    }

    /// The register holding [`NO_HIT`], kept from the program's start in a scene with
    /// secondary rays.
    pub(super) fn no_hit(&self) -> Reg {
        self.asm
            .kept_constant(NO_HIT)
            .expect("kept at the program's start")
    }

    /// Sleeps until the thread's object walk ends and reads its hit flag (where the shader or
    /// an any-hit query reads it); an any-hit query with a hit jumps to `answered` (a walk
    /// under a top level, whose instance loop that ends).
    fn walk_end(&self, query: Query, answered: Option<Label>) {
        let a = self.asm;
        let s = &self.s;
        let any = query != Query::Closest;
        a.kd_wait(if any || !self.hit_by_t() {
            s.hit
        } else {
            Reg::ZERO
        });
        if let (true, Some(answered)) = (any, answered) {
            a.branch(Op::Beq, s.hit.into(), Val::K(0), true, answered);
        }
    }

    /// The top-level tree from `root` up to `t_max`, walked front to back by the traversal
    /// unit, which stops at each leaf for the thread to walk its instances with `walk` (see
    /// `walk_word`); an answered any-hit query jumps to `answered` (and leaves the unit's
    /// walk stopped at its leaf).
    fn traverse(&self, root: u32, t_max: Reg, walk: Reg, query: Query, answered: Label) {
        let a = self.asm;
        a.section("traversal");
        let [list, end] = a.regs::<2>();
        let top = a
            .kept_constant(root | KD_TOP)
            .expect("kept at the program's start");
        a.kd_start(top, t_max);
        let (leaf, finished) = (a.label(), a.label());
        a.bind(leaf);
        a.section("traversal");
        a.kd_wait(list);
        a.branch(Op::Beq, list.into(), Val::K(KD_WALK_ENDED), false, finished);
        a.kd_leaf(end);
        self.instance_list(list, end, walk, query, answered);
        a.section("traversal");
        a.kd_next();
        a.jump(leaf);
        a.bind(finished);
        a.free(list);
        a.free(end);
    }

    /// The instances of a top-level leaf, `list..end` in bank 1 (`list` moves on to `end`;
    /// the traversal unit stops only at leaves with instances), each entered and walked with
    /// `tri.enter` (`walk`: see `walk_word`).
    fn instance_list(&self, list: Reg, end: Reg, walk: Reg, query: Query, answered: Label) {
        let a = self.asm;
        a.section("instances");
        let (p, instance) = (list, a.reg());
        let (next, seen) = (a.label(), a.label());
        a.bind(next);
        a.section("instances");
        a.load_to(instance, LISTS, p.into(), 0, 0);
        a.op_to(Op::Add, p, p.into(), Val::K(1));
        a.mailbox_check(MAILBOX_INSTANCES, instance, seen);
        // Instance entry (`hw::engine::InstanceRays`) writes the world ray in the instance's
        // object space into both coprocessors and the object's root into the traversal unit,
        // which then walks it; the thread sleeps until the walk ends.
        a.tri_enter(instance, walk);
        a.section("traversal");
        self.walk_end(query, Some(answered));
        a.section("instances");
        a.bind(seen);
        a.branch(Op::Beq, p.into(), end.into(), true, next);
        a.free(instance);
    }
}
