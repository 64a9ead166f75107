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
//! The top-level tree of a scene with instances is walked here in microcode (state machine
//! per thread, one instruction per engine turn): fetch a node (2 loads), decode it; at an
//! inner node read the world ray's origin and direction along the split axis from scratch
//! (indexed by the axis), pick near and far child, compute `t_split` with the shared
//! `units::split_distance` and visit near, far or both (pushing far on the scratch kd stack);
//! at a leaf enter each instance not yet in the instance mailbox (`tri.enter`: the instance
//! entry unit, `hw::engine::InstanceRays`, transforms the world ray that `tri.world` gave it at
//! the trace's start into the object's space through the one TransformUnit and writes it
//! into both coprocessors; the thread loads the object's root and waits for the ray), then
//! walk the object; then pop the stack until a segment can still hold a closer hit.
//!
//! Cost (instructions = engine turns): per object walk 4 (start, wait, the closest hit's t
//! and flag), whatever its leaves; a waiting thread sleeps until the walk ends (the tree's
//! nodes and the leaves' triangles cost it no instruction); per top-level inner node 15-23,
//! per instance about 17 (the list and the mailbox, the record's address, `tri.enter`, the
//! root, `tri.object`, the wait and the walk); 3 per trace for the world ray.

use super::asm::Asm;
use super::asm::{Label, Reg, Val};
use super::isa::{Op, TriFn, MAILBOX_INSTANCES};
use super::{Gen, STACK_ENTRY_WORDS};
use crate::layout::{instance_word as iw, INSTANCES, LEAF_TAG, LISTS, NODES};
use crate::units;

/// Gives the triangle tester and the traversal unit the ray of the one object (object 0,
/// whose mailbox the query's init emptied).
fn tester_ray(a: &Asm, o: [Reg; 3], d: [Reg; 3]) {
    a.tri_ray(TriFn::RayOxy, o[0], o[1]);
    a.tri_ray(TriFn::RayOzDx, o[2], d[0]);
    a.tri_ray(TriFn::RayDyz, d[1], d[2]);
}

/// The ray one traversal level walks: registers, and where scratch holds a copy for the
/// axis-indexed reads.
#[derive(Clone, Copy)]
struct LevelRay {
    o: [Reg; 3],
    d: [Reg; 3],
    scratch: u32,
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
        let world = LevelRay {
            o: s.q_o,
            d: s.q_d,
            scratch: self.scratch.ray_top,
        };
        a.tri_queue(TriFn::Init, s.q_t_min, s.q_t_max);
        // The triangle a secondary ray starts on is never tested (primary rays skip none, so
        // a scene without secondary rays never names one).
        if self.secondary_rays() {
            a.tri_queue(TriFn::Skip, s.skip_instance, s.skip_triangle);
        }
        match self.c.top_root {
            Some(root) => {
                // The closest hit so far bounds every instance's walk.
                a.mov(s.best_t, s.q_t_max.into());
                a.mov(s.sp, Val::K(self.scratch.stack));
                self.store_ray(world);
                // The world ray instance entry transforms.
                for (pair, [x, y]) in [
                    [world.o[0], world.o[1]],
                    [world.o[2], world.d[0]],
                    [world.d[1], world.d[2]],
                ]
                .into_iter()
                .enumerate()
                {
                    a.tri_world(pair as u8, x, y);
                }
                a.mailbox_clear(MAILBOX_INSTANCES);
                self.traverse(Val::K(root), world, done);
            }
            None => {
                // Traced in line, the trace is the primary ray's, which ray generation has
                // written into both coprocessors already.
                if routine {
                    tester_ray(a, world.o, world.d);
                }
                self.walk_object(Val::K(self.c.object_root), s.q_t_max, done);
            }
        }
        a.bind(done);
        a.section("trace");
        if self.c.top_root.is_some() {
            a.tri_read(TriFn::Instance, s.best_instance);
        }
        a.tri_read(TriFn::Triangle, s.best_triangle);
        if routine {
            a.ret(s.link);
        }
    }

    fn store_ray(&self, ray: LevelRay) {
        for k in 0..3 {
            self.asm
                .scratch_store(Val::K(0), ray.scratch + k as u32, ray.o[k].into());
            self.asm
                .scratch_store(Val::K(0), ray.scratch + 3 + k as u32, ray.d[k].into());
        }
    }

    /// An object's kd tree, walked by the traversal unit from `root`, which hands each leaf's
    /// triangles to the triangle tester and goes on with its closest hit by itself; the
    /// thread sleeps until the walk ends and reads the hit. An answered any-hit query jumps to
    /// `answered`. `t_max` bounds the walk's segment.
    fn walk_object(&self, root: Val, t_max: Reg, answered: Label) {
        let a = self.asm;
        let s = &self.s;
        a.section("traversal");
        // A shadow query's walk ends at its first hit (`q_any` is `KD_ANY_HIT` or 0).
        let from = match (root, self.c.shadows) {
            (Val::K(0), false) => Reg::ZERO,
            (Val::K(0), true) => s.q_any,
            (Val::R(r), false) => r,
            (root, true) => a.keep(a.op(Op::Or, s.q_any.into(), root)),
            (k, false) => a.keep(k),
        };
        a.kd_start(from, t_max);
        a.kd_wait();
        a.section("intersect");
        a.tri_wait(s.best_t);
        if !self.hit_by_t() {
            a.tri_read(TriFn::Hit, s.hit);
        }
        if self.c.shadows {
            // A shadow query is answered by any hit.
            let closest = a.label();
            a.branch(Op::Beq, s.hit.into(), Val::K(0), false, closest);
            a.branch(Op::Beq, s.q_any.into(), Val::K(0), true, answered);
            a.bind(closest);
        }
        if from != Reg::ZERO && from != s.q_any && Val::R(from) != root {
            a.free(from);
        }
    }

    /// Front-to-back traversal of the top-level tree from `root` in microcode; an answered
    /// any-hit query jumps to `answered`.
    fn traverse(&self, root: Val, ray: LevelRay, answered: Label) {
        let a = self.asm;
        let s = &self.s;
        a.section("traversal");
        let [node, lo, hi, base] = a.regs::<4>();
        let far = a.reg();
        a.mov(node, root);
        a.mov(lo, s.q_t_min.into());
        a.mov(hi, s.best_t.into());
        a.mov(base, s.sp.into());
        let (top, leaf, pop, finished) = (a.label(), a.label(), a.label(), a.label());
        a.bind(top);
        a.section("traversal");
        let w0 = a.keep(a.load(NODES, node.into(), 1, 0));
        let w1 = a.keep(a.load(NODES, node.into(), 1, 1));
        let tag = a.keep(a.op(Op::Shr, w0.into(), Val::K(30)));
        a.branch(Op::Beq, tag.into(), Val::K(LEAF_TAG), false, leaf);
        // Inner node: `tag` is the axis, `w1` the split plane.
        let left = a.op(Op::And, w0.into(), Val::K(0x3fff_ffff));
        let [o, d] = a.regs::<2>();
        a.scratch_load_to(o, tag.into(), ray.scratch);
        a.scratch_load_to(d, tag.into(), ray.scratch + 3);
        // Near child: the one holding the origin (on the plane, the one the ray heads into).
        // The decision code is emitted once per near side, so that the children are `left`
        // and `left + 1` without registers to hold near and far.
        let near_left = a.label();
        a.branch(Op::BFlt, o.into(), w1.into(), false, near_left);
        let near_right = a.label();
        a.branch(Op::BFeq, o.into(), w1.into(), true, near_right);
        a.branch(Op::BFle, d.into(), Val::K(0), false, near_left);
        for (side, near_is_left) in [(near_right, false), (near_left, true)] {
            a.bind(side);
            let child = |to: Reg, near: bool| {
                if near == near_is_left {
                    a.mov(to, left);
                } else {
                    a.op_to(Op::Add, to, left, Val::K(1));
                }
            };
            let (go_near, go_far) = (a.label(), a.label());
            a.branch(Op::BFeq, d.into(), Val::K(0), false, go_near);
            let t_split = units::split_distance(a, o.into(), d.into(), w1.into());
            a.branch(Op::BFlt, hi.into(), t_split, false, go_near);
            a.branch(Op::BFle, t_split, Val::K(0), false, go_near);
            a.branch(Op::BFlt, t_split, lo.into(), false, go_far);
            // Both: push (far, t_split, hi), go near with [lo, t_split].
            child(far, false);
            a.scratch_store(s.sp.into(), 0, far.into());
            a.scratch_store(s.sp.into(), 1, t_split);
            a.scratch_store(s.sp.into(), 2, hi.into());
            a.op_to(Op::Add, s.sp, s.sp.into(), Val::K(STACK_ENTRY_WORDS));
            child(node, true);
            a.mov(hi, t_split);
            a.jump(top);
            a.bind(go_near);
            child(node, true);
            a.jump(top);
            a.bind(go_far);
            child(node, false);
            a.jump(top);
        }
        a.end_temps();

        // Leaf: `w0`'s payload is the list address, `w1` the count.
        a.bind(leaf);
        let list = a.keep(a.op(Op::And, w0.into(), Val::K(0x3fff_ffff)));
        let end = a.keep(a.op(Op::Add, list.into(), w1.into()));
        for r in [w0, w1, tag, o, d] {
            a.free(r);
        }
        self.instance_list(list, end, answered);
        a.free(list);
        a.free(end);
        a.section("traversal");
        // A hit inside the segment just searched is the closest.
        a.branch(Op::Beq, s.hit.into(), Val::K(0), false, pop);
        a.branch(Op::BFle, s.best_t.into(), hi.into(), false, finished);
        a.bind(pop);
        a.branch(Op::Beq, s.sp.into(), base.into(), false, finished);
        a.op_to(Op::Sub, s.sp, s.sp.into(), Val::K(STACK_ENTRY_WORDS));
        a.scratch_load_to(node, s.sp.into(), 0);
        a.scratch_load_to(lo, s.sp.into(), 1);
        a.scratch_load_to(hi, s.sp.into(), 2);
        a.branch(Op::Beq, s.hit.into(), Val::K(0), false, top);
        a.branch(Op::BFlt, s.best_t.into(), lo.into(), false, finished);
        a.jump(top);
        a.bind(finished);
        a.mov(s.sp, base.into());
        for r in [node, lo, hi, base, far] {
            a.free(r);
        }
    }

    /// The instances of a top-level leaf, `list..end` in bank 1.
    fn instance_list(&self, list: Reg, end: Reg, answered: Label) {
        let a = self.asm;
        let s = &self.s;
        a.section("instances");
        let [p, instance] = a.regs::<2>();
        a.mov(p, list.into());
        let (next, done) = (a.label(), a.label());
        a.bind(next);
        a.section("instances");
        a.branch(Op::Beq, p.into(), end.into(), false, done);
        a.load_to(instance, LISTS, p.into(), 0, 0);
        a.op_to(Op::Add, p, p.into(), Val::K(1));
        a.mailbox_check(MAILBOX_INSTANCES, instance, next);
        // Instance entry (`hw::engine::InstanceRays`): the world ray in the instance's object
        // space becomes the thread's ray in both coprocessors; the wait waits for it.
        let record = a.keep(self.instance_record(instance));
        a.tri_enter(record);
        let root = a.keep(a.load(INSTANCES, record.into(), 0, iw::ROOT as u32));
        a.free(record);
        a.tri_queue(TriFn::Object, instance, Reg::ZERO);
        a.tri_wait(Reg::ZERO);
        self.walk_object(root.into(), s.best_t, answered);
        a.free(root);
        a.jump(next);
        a.bind(done);
        a.free(p);
        a.free(instance);
    }

    /// `instance * INSTANCE_WORDS` (24 = 16 + 8).
    pub(super) fn instance_record(&self, instance: Reg) -> Val {
        let a = self.asm;
        debug_assert_eq!(crate::layout::INSTANCE_WORDS, 24);
        let x16 = a.op(Op::Shl, instance.into(), Val::K(4));
        let x8 = a.op(Op::Shl, instance.into(), Val::K(3));
        a.op(Op::Add, x16, x8)
    }
}
