//! Traversal: the trace routine of the microprogram (`model::golden`'s `trace`, `traverse`,
//! `enter_instance` and `test_triangles`, step for step).
//!
//! Object trees are walked by the traversal unit (`hw::TraversalUnit`, per `units::KdWalk`):
//! the thread starts the walk and sleeps until it ends. The unit hands each leaf's list to
//! the triangle tester (`hw::TriangleTester`), whose list unit drops the triangle the query
//! starts on and those in the thread's triangle mailbox and queues the rest; the tester
//! answers the unit with the closest hit, which ends the walk or pops its stack. A shadow
//! query's walk (`q_any`) ends after the first leaf with a hit.
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
//! mailbox skips, with 2 more per walk of a shadow query (its answer); per trace 3 for the
//! world ray, 2 for the top-level walk's start and 1 for the closest hit's t.

use super::asm::Asm;
use super::asm::{Label, Reg, Val};
use super::isa::{Op, TriFn, KD_TOP, KD_WALK_ENDED, MAILBOX_INSTANCES};
use super::Gen;
use crate::layout::LISTS;

/// Gives the triangle tester and the traversal unit the ray of the one object (object 0,
/// whose mailbox the query's init emptied).
fn tester_ray(a: &Asm, o: [Reg; 3], d: [Reg; 3]) {
    a.tri_ray(TriFn::RayOxy, o[0], o[1]);
    a.tri_ray(TriFn::RayOzDx, o[2], d[0]);
    a.tri_ray(TriFn::RayDyz, d[1], d[2]);
}

impl Gen<'_> {
    /// The trace routine: closest hit (or any hit when `q_any` is set) of the query registers;
    /// gives `hit`, `best_t`, `best_triangle` and (in a scene with a top level)
    /// `best_instance`, and returns through `link` when `routine` (else it is in line).
    pub(super) fn trace_routine(&self, routine: bool) {
        let a = self.asm;
        let s = &self.s;
        a.section("trace");
        let done = a.label();
        // A walk of the one object writes the hit flag; a top level may enter no instance.
        if self.c.top_root.is_some() {
            a.mov(s.hit, Val::K(0));
        }
        let world = (s.q_o, s.q_d);
        a.tri_queue(TriFn::Init, s.q_t_min, s.q_t_max);
        // The triangle a secondary ray starts on is never tested (primary rays skip none, so
        // a scene without secondary rays never names one).
        if self.secondary_rays() {
            a.tri_queue(TriFn::Skip, s.skip_instance, s.skip_triangle);
        }
        match self.c.top_root {
            Some(root) => {
                // The world ray that the top-level walk and instance entry transform.
                for (pair, [x, y]) in [
                    [world.0[0], world.0[1]],
                    [world.0[2], world.1[0]],
                    [world.1[1], world.1[2]],
                ]
                .into_iter()
                .enumerate()
                {
                    a.tri_world(pair as u8, x, y);
                }
                a.mailbox_clear(MAILBOX_INSTANCES);
                self.traverse(root, done);
            }
            None => {
                // Traced in line, the trace is the primary ray's, which ray generation has
                // written into both coprocessors already.
                if routine {
                    tester_ray(a, world.0, world.1);
                }
                let from = self.walk_root(Val::K(self.c.object_root));
                self.walk_object(from, s.q_t_max, done);
                self.free_root(from);
                a.section("intersect");
                a.tri_wait(s.best_t);
            }
        }
        a.bind(done);
        a.section("trace");
        if self.c.top_root.is_some() {
            // The instances' walks leave the closest hit in the tester.
            a.tri_wait(s.best_t);
            a.tri_read(TriFn::Instance, s.best_instance);
        }
        a.tri_read(TriFn::Triangle, s.best_triangle);
        if routine {
            a.ret(s.link);
        }
    }

    /// The word `kd.start` walks an object with: `root` (a node, or `KD_ENTERED`), and for a
    /// shadow query (`q_any` is `KD_ANY_HIT` or 0) the flag that ends it at its first hit.
    fn walk_root(&self, root: Val) -> Reg {
        let a = self.asm;
        let s = &self.s;
        match (root, self.c.shadows) {
            (Val::K(0), false) => Reg::ZERO,
            (Val::K(0), true) => s.q_any,
            (Val::R(r), false) => r,
            (root, true) => a.keep(a.op(Op::Or, s.q_any.into(), root)),
            (k, false) => a.keep(k),
        }
    }

    /// An object's kd tree, walked by the traversal unit from `from` (see `walk_root`), which
    /// hands each leaf's triangles to the triangle tester and goes on with its closest hit by
    /// itself; the thread sleeps until the walk ends and reads the hit flag. An answered
    /// any-hit query jumps to `answered`. `t_max` bounds the walk's segment.
    fn walk_object(&self, from: Reg, t_max: Reg, answered: Label) {
        let a = self.asm;
        a.section("traversal");
        a.kd_start(from, t_max);
        self.walk_end(answered);
    }

    /// Sleeps until the thread's object walk ends and reads its hit flag; an answered any-hit
    /// query jumps to `answered`.
    fn walk_end(&self, answered: Label) {
        let a = self.asm;
        let s = &self.s;
        a.kd_wait(if self.hit_by_t() { Reg::ZERO } else { s.hit });
        if self.c.shadows {
            // A shadow query is answered by any hit.
            let closest = a.label();
            a.branch(Op::Beq, s.hit.into(), Val::K(0), false, closest);
            a.branch(Op::Beq, s.q_any.into(), Val::K(0), true, answered);
            a.bind(closest);
        }
    }

    /// Frees a register `walk_root` kept.
    fn free_root(&self, from: Reg) {
        if from != Reg::ZERO && from != self.s.q_any {
            self.asm.free(from);
        }
    }

    /// The top-level tree from `root`, walked front to back by the traversal unit, which
    /// stops at each leaf for the thread to walk its instances; an answered any-hit query
    /// jumps to `answered` (and leaves the unit's walk stopped at its leaf).
    fn traverse(&self, root: u32, answered: Label) {
        let a = self.asm;
        let s = &self.s;
        a.section("traversal");
        let [list, end] = a.regs::<2>();
        let top = a.keep(Val::K(root | KD_TOP));
        a.kd_start(top, s.q_t_max);
        a.free(top);
        // Each instance's walk answers a shadow query with its first hit.
        let walk = self.walk_root(Val::K(0));
        let (leaf, finished) = (a.label(), a.label());
        a.bind(leaf);
        a.section("traversal");
        a.kd_wait(list);
        a.branch(Op::Beq, list.into(), Val::K(KD_WALK_ENDED), false, finished);
        a.kd_leaf(end);
        self.instance_list(list, end, walk, answered);
        a.section("traversal");
        a.kd_next();
        a.jump(leaf);
        a.bind(finished);
        a.free(list);
        a.free(end);
        self.free_root(walk);
    }

    /// The instances of a top-level leaf, `list..end` in bank 1 (`list` moves on to `end`;
    /// the traversal unit stops only at leaves with instances), each entered and walked with
    /// `tri.enter` (`walk`: see `walk_root`).
    fn instance_list(&self, list: Reg, end: Reg, walk: Reg, answered: Label) {
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
        self.walk_end(answered);
        a.section("instances");
        a.bind(seen);
        a.branch(Op::Beq, p.into(), end.into(), true, next);
        a.free(instance);
    }
}
