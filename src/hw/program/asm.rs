//! The assembler the microprogram is written with: labels, registers, and [`Arith`] over
//! registers, so the shared arithmetic sequences of `crate::units` emit the instructions that
//! compute them.
//!
//! Registers come from a pool. Every value an [`Arith`] operation produces is a temporary;
//! [`Asm::keep`] makes one a named register the caller frees, [`Asm::end_temps`] returns all
//! other temporaries to the pool. Constants are immediates where the instruction can take one.

use std::cell::RefCell;

use super::isa::{Instr, KdFn, Op, TriFn, REGISTERS};
use crate::fp::Format;
use crate::units::Arith;

/// A register number (`Reg::ZERO` always reads 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Reg(pub u8);

impl Reg {
    pub const ZERO: Reg = Reg(0);
}

/// An operand: a register or a constant word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Val {
    R(Reg),
    K(u32),
}

impl From<Reg> for Val {
    fn from(r: Reg) -> Val {
        Val::R(r)
    }
}

/// A position in the program, bound once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Label(usize);

struct State {
    code: Vec<Instr>,
    /// The routine each instruction belongs to (for traces and statistics).
    sections: Vec<&'static str>,
    section: &'static str,
    labels: Vec<Option<u16>>,
    fixups: Vec<(usize, Label)>,
    /// Instructions whose immediate is a label's address ([`Asm::mov_label`]).
    address_fixups: Vec<(usize, Label)>,
    free: Vec<Reg>,
    temps: Vec<Reg>,
    /// Registers that hold a constant for the whole program ([`Asm::keep_constant`]).
    constants: Vec<(u32, Reg)>,
}

/// The assembler. Shared (`&Asm`) so that it can be the `Arith` of the unit sequences.
pub struct Asm {
    format: Format,
    state: RefCell<State>,
}

/// An assembled program.
#[derive(Clone, Debug)]
pub struct Assembled {
    pub code: Vec<Instr>,
    pub sections: Vec<&'static str>,
}

impl Asm {
    pub fn new(format: Format) -> Self {
        Asm {
            format,
            state: RefCell::new(State {
                code: Vec::new(),
                sections: Vec::new(),
                section: "init",
                labels: Vec::new(),
                fixups: Vec::new(),
                address_fixups: Vec::new(),
                // Lowest numbers first.
                free: (1..REGISTERS).rev().map(|r| Reg(r as u8)).collect(),
                temps: Vec::new(),
                constants: Vec::new(),
            }),
        }
    }

    pub fn format(&self) -> Format {
        self.format
    }

    /// Names the routine the next instructions belong to.
    pub fn section(&self, name: &'static str) {
        self.state.borrow_mut().section = name;
    }

    /// A named register, freed by [`Asm::free`].
    pub fn reg(&self) -> Reg {
        self.state
            .borrow_mut()
            .free
            .pop()
            .expect("microprogram needs more registers than the engine has")
    }

    pub fn regs<const N: usize>(&self) -> [Reg; N] {
        [(); N].map(|_| self.reg())
    }

    pub fn free(&self, r: Reg) {
        let mut s = self.state.borrow_mut();
        debug_assert!(r != Reg::ZERO && !s.free.contains(&r));
        s.free.push(r);
    }

    fn temp(&self) -> Reg {
        let r = self.reg();
        self.state.borrow_mut().temps.push(r);
        r
    }

    /// Makes a temporary a named register (so [`Asm::end_temps`] keeps it); constants are put
    /// in a fresh register.
    pub fn keep(&self, v: Val) -> Reg {
        match v {
            Val::R(r) => {
                let mut s = self.state.borrow_mut();
                if let Some(i) = s.temps.iter().position(|&t| t == r) {
                    s.temps.swap_remove(i);
                    r
                } else {
                    drop(s);
                    let k = self.reg();
                    self.mov(k, v);
                    k
                }
            }
            Val::K(_) => {
                let k = self.reg();
                self.mov(k, v);
                k
            }
        }
    }

    /// The number of instructions so far.
    pub fn len(&self) -> usize {
        self.state.borrow().code.len()
    }

    /// Takes every register named by the instructions from `start` on out of the pool for
    /// good: a routine's registers, kept away from its callers' live values.
    pub fn reserve_registers_of(&self, start: usize) {
        let mut s = self.state.borrow_mut();
        let named: std::collections::BTreeSet<u8> = s.code[start..]
            .iter()
            .flat_map(|i| [i.dst, i.a, if i.b_imm { 0 } else { i.b }])
            .collect();
        s.free.retain(|r| !named.contains(&r.0));
        s.temps.retain(|r| !named.contains(&r.0));
    }

    /// Returns every temporary to the pool.
    pub fn end_temps(&self) {
        let mut s = self.state.borrow_mut();
        let t = std::mem::take(&mut s.temps);
        s.free.extend(t);
    }

    pub fn label(&self) -> Label {
        let mut s = self.state.borrow_mut();
        s.labels.push(None);
        Label(s.labels.len() - 1)
    }

    pub fn bind(&self, l: Label) {
        let mut s = self.state.borrow_mut();
        assert!(s.labels[l.0].is_none(), "label bound twice");
        s.labels[l.0] = Some(s.code.len() as u16);
    }

    /// A label bound here.
    pub fn here(&self) -> Label {
        let l = self.label();
        self.bind(l);
        l
    }

    pub fn emit(&self, i: Instr) {
        let mut s = self.state.borrow_mut();
        let section = s.section;
        s.code.push(i);
        s.sections.push(section);
    }

    fn emit_to(&self, mut i: Instr, target: Label) {
        let at = self.state.borrow().code.len();
        i.target = 0;
        self.emit(i);
        self.state.borrow_mut().fixups.push((at, target));
    }

    /// Puts `k` in a register for the rest of the program: an operation whose first operand
    /// is `k` reads it there (the first operand cannot be an immediate), as does a
    /// coprocessor's operand ([`Asm::kept_constant`]). For the program's start, before any
    /// branch.
    pub fn keep_constant(&self, k: u32) {
        let r = self.keep(Val::K(k));
        self.state.borrow_mut().constants.push((k, r));
    }

    /// The register [`Asm::keep_constant`] keeps `k` in.
    pub fn kept_constant(&self, k: u32) -> Option<Reg> {
        let s = self.state.borrow();
        s.constants.iter().find(|c| c.0 == k).map(|c| c.1)
    }

    /// An instruction reading `a` and `b` (a constant `b` becomes the immediate; a constant
    /// `a` is loaded into a temporary first).
    fn operands(&self, op: Op, a: Val, b: Val) -> Instr {
        let kept = |k: u32| self.kept_constant(k);
        let a = match a {
            Val::R(r) => r,
            Val::K(0) => Reg::ZERO,
            Val::K(k) if kept(k).is_some() => kept(k).unwrap(),
            Val::K(k) => {
                let t = self.temp();
                self.emit(Instr {
                    dst: t.0,
                    b_imm: true,
                    imm: k,
                    ..Instr::new(Op::Or)
                });
                t
            }
        };
        let mut i = Instr {
            a: a.0,
            ..Instr::new(op)
        };
        match b {
            Val::R(r) => i.b = r.0,
            Val::K(k) => {
                i.b_imm = true;
                i.imm = k;
            }
        }
        i
    }

    /// `dst = a op b`.
    pub fn op_to(&self, op: Op, dst: Reg, a: Val, b: Val) {
        let mut i = self.operands(op, a, b);
        i.dst = dst.0;
        self.emit(i);
    }

    /// `a op b` into a new temporary.
    pub fn op(&self, op: Op, a: Val, b: Val) -> Val {
        let i = self.operands(op, a, b);
        let t = self.temp();
        self.emit(Instr { dst: t.0, ..i });
        Val::R(t)
    }

    pub fn mov(&self, dst: Reg, v: Val) {
        match v {
            Val::R(r) if r == dst => {}
            Val::R(_) => self.op_to(Op::Or, dst, v, Val::K(0)),
            Val::K(k) => self.op_to(Op::Or, dst, Val::K(0), Val::K(k)),
        }
    }

    pub fn mov3(&self, dst: [Reg; 3], v: [Val; 3]) {
        for i in 0..3 {
            self.mov(dst[i], v[i]);
        }
    }

    /// `dst = v` for a temporary `v` that dies here: the instruction that computed it writes
    /// `dst` instead, without a move, when that is the same program. It is when the
    /// instruction is plain arithmetic or a load and the last write of `v`, and the code since
    /// runs straight (no branch, jump or label) and neither reads `v` nor touches `dst`.
    /// Otherwise a move.
    pub fn assign(&self, dst: Reg, v: Val) {
        if let Val::R(t) = v {
            let mut s = self.state.borrow_mut();
            let len = s.code.len();
            let producer = s.code.iter().rposition(|i| i.op.writes() && i.dst == t.0);
            if let Some(k) = producer.filter(|_| t != dst && s.temps.contains(&t)) {
                let plain = |i: &Instr| !i.op.branches() && !i.invert && i.op != Op::Jr;
                let reads = |i: &Instr, r: Reg| i.a == r.0 || (!i.b_imm && i.b == r.0);
                let later = &s.code[k + 1..];
                let labelled = s
                    .labels
                    .iter()
                    .flatten()
                    .any(|&p| (k + 1..=len).contains(&(p as usize)));
                let retargetable = s.code[k].op.computes();
                if retargetable
                    && plain(&s.code[k])
                    && !labelled
                    && later.iter().all(|i| {
                        plain(i)
                            && !reads(i, t)
                            && !reads(i, dst)
                            && !(i.op.writes() && i.dst == dst.0)
                    })
                {
                    s.code[k].dst = dst.0;
                    return;
                }
            }
        }
        self.mov(dst, v)
    }

    /// [`Asm::assign`] of three values.
    pub fn assign3(&self, dst: [Reg; 3], v: [Val; 3]) {
        for i in 0..3 {
            self.assign(dst[i], v[i]);
        }
    }

    /// `dst = bank[(a << shift) + offset]`.
    pub fn load_to(&self, dst: Reg, bank: usize, a: Val, shift: u8, offset: u32) {
        let mut i = self.operands(Op::Ld, a, Val::K(0));
        i.b_imm = false;
        i.imm = offset;
        i.dst = dst.0;
        i.shift = shift;
        i.bank = bank as u8;
        self.emit(i);
    }

    /// A temporary loaded from `bank[(a << shift) + offset]`.
    pub fn load(&self, bank: usize, a: Val, shift: u8, offset: u32) -> Val {
        let t = self.temp();
        self.load_to(t, bank, a, shift, offset);
        Val::R(t)
    }

    pub fn load_n<const N: usize>(&self, bank: usize, a: Val, shift: u8, offset: u32) -> [Val; N] {
        std::array::from_fn(|k| self.load(bank, a, shift, offset + k as u32))
    }

    /// `frame[(a << shift) + offset] = data`.
    pub fn store_frame(&self, a: Val, shift: u8, offset: u32, data: Reg) {
        let mut i = self.operands(Op::St, a, Val::R(data));
        i.imm = offset;
        i.shift = shift;
        self.emit(i);
    }

    pub fn scratch_load_to(&self, dst: Reg, a: Val, offset: u32) {
        let mut i = self.operands(Op::Lds, a, Val::K(0));
        i.b_imm = false;
        i.imm = offset;
        i.dst = dst.0;
        self.emit(i);
    }

    pub fn scratch_store(&self, a: Val, offset: u32, data: Val) {
        let data = match data {
            Val::R(r) => r,
            k => {
                let t = self.temp();
                self.mov(t, k);
                t
            }
        };
        let mut i = self.operands(Op::Sts, a, Val::R(data));
        i.imm = offset;
        self.emit(i);
    }

    /// Branch to `target` when `cond(a, b) != invert` (`cond` one of the branch ops).
    pub fn branch(&self, cond: Op, a: Val, b: Val, invert: bool, target: Label) {
        debug_assert!(matches!(
            cond,
            Op::BFlt | Op::BFle | Op::BFeq | Op::Beq | Op::Bltu
        ));
        let mut i = self.operands(cond, a, b);
        i.invert = invert;
        self.emit_to(i, target);
    }

    pub fn jump(&self, target: Label) {
        self.emit_to(Instr::new(Op::Jal), target);
    }

    /// Calls `target`, the return address in `link`.
    pub fn call(&self, link: Reg, target: Label) {
        self.emit_to(
            Instr {
                dst: link.0,
                ..Instr::new(Op::Jal)
            },
            target,
        );
    }

    /// `dst = ` the address of `target`: a return address for a routine entered by a jump,
    /// when the call cannot sit just before where it returns to.
    pub fn mov_label(&self, dst: Reg, target: Label) {
        let at = self.len();
        self.mov(dst, Val::K(0));
        debug_assert_eq!(self.len(), at + 1);
        self.state.borrow_mut().address_fixups.push((at, target));
    }

    pub fn ret(&self, link: Reg) {
        self.emit(Instr {
            a: link.0,
            ..Instr::new(Op::Jr)
        });
    }

    /// Branch to `seen` when `id` is in mailbox `which`, else record it.
    pub fn mailbox_check(&self, which: u32, id: Reg, seen: Label) {
        self.emit_to(
            Instr {
                a: id.0,
                imm: which,
                ..Instr::new(Op::Mbx)
            },
            seen,
        );
    }

    /// `tri.<f> a, b` for a function that neither queues nor writes (the ray words).
    pub fn tri_ray(&self, f: TriFn, a: Reg, b: Reg) {
        debug_assert!(matches!(f, TriFn::RayOxy | TriFn::RayOzDx | TriFn::RayDyz));
        self.coprocessor(Op::Tri, f as u32, Reg::ZERO, a, b);
    }

    /// Queues `f` (`Init`, `List`, `Object` or `Skip`) with operands `a`, `b` (the engine
    /// offers it again on the thread's next turns while the queue is full).
    pub fn tri_queue(&self, f: TriFn, a: Reg, b: Reg) {
        debug_assert!(f.queues());
        self.coprocessor(Op::Tri, f as u32, Reg::ZERO, a, b);
    }

    /// The world ray's words `2 pair`, `2 pair + 1` (of `o.x o.y o.z d.x d.y d.z`) = `a`, `b`,
    /// for instance entry.
    pub fn tri_world(&self, pair: u8, a: Reg, b: Reg) {
        self.emit(Instr {
            a: a.0,
            b: b.0,
            imm: TriFn::World as u32,
            shift: pair,
            ..Instr::new(Op::Tri)
        });
    }

    /// Enters `instance` and walks its object (`TriFn::Enter`): the world ray in its object
    /// space becomes the thread's ray in both coprocessors, the traversal unit walks the
    /// object from its root up to the last answer, answering any hit when `walk` has
    /// `KD_ANY_HIT` (repeated while refused; a `kd.wait` waits for the walk's end).
    pub fn tri_enter(&self, instance: Reg, walk: Reg) {
        self.coprocessor(Op::Tri, TriFn::Enter as u32, Reg::ZERO, instance, walk);
    }

    /// The world normal of `instance`'s normal matrix times `(x, y, z)` (`TriFn::Normal`):
    /// `x`, `y` as world words 0 and 1, then the request; `tri.dir` reads it after a wait.
    pub fn tri_normal(&self, instance: Reg, [x, y, z]: [Reg; 3]) {
        self.tri_world(0, x, y);
        self.coprocessor(Op::Tri, TriFn::Normal as u32, Reg::ZERO, instance, z);
    }

    /// Shades the thread's finished query into the frame buffer's word `address` (before the
    /// frame buffer's base) in the ShadeUnit (`TriFn::Shade`; repeated while refused).
    pub fn tri_shade(&self, address: Val) {
        let mut i = self.operands(Op::Tri, address, Val::R(Reg::ZERO));
        i.imm = TriFn::Shade as u32;
        self.emit(i);
    }

    /// Waits until the thread's queued entries are done; `dst` = the best t.
    pub fn tri_wait(&self, dst: Reg) {
        self.coprocessor(Op::Tri, TriFn::Wait as u32, dst, Reg::ZERO, Reg::ZERO);
    }

    /// `dst` = the tester's `Hit`, `Instance` or `Triangle` (after a wait).
    pub fn tri_read(&self, f: TriFn, dst: Reg) {
        debug_assert!(matches!(f, TriFn::Hit | TriFn::Instance | TriFn::Triangle));
        self.coprocessor(Op::Tri, f as u32, dst, Reg::ZERO, Reg::ZERO);
    }

    /// Ray generation's camera words `2 pair`, `2 pair + 1` = `a`, `b`.
    pub fn tri_camera(&self, pair: u8, a: Reg, b: Reg) {
        self.emit(Instr {
            a: a.0,
            b: b.0,
            imm: TriFn::Camera as u32,
            shift: pair,
            ..Instr::new(Op::Tri)
        });
    }

    /// `dst` = component `k` of the thread's primary direction (after a `tri.wait`).
    pub fn tri_dir(&self, k: u8, dst: Reg) {
        self.emit(Instr {
            dst: dst.0,
            imm: TriFn::Dir as u32,
            shift: k,
            ..Instr::new(Op::Tri)
        });
    }

    /// Offers `kd.start a, b` (root, t_max) to the traversal unit (again while refused).
    pub fn kd_start(&self, a: Reg, b: Reg) {
        self.coprocessor(Op::Kd, KdFn::Start as u32, Reg::ZERO, a, b);
    }

    /// Waits for the traversal unit's walk to end or (a top-level walk) to reach a leaf;
    /// `dst` = the query's hit flag after an object walk, the leaf's list address or
    /// `isa::KD_WALK_ENDED` after a top-level walk.
    pub fn kd_wait(&self, dst: Reg) {
        self.coprocessor(Op::Kd, KdFn::Wait as u32, dst, Reg::ZERO, Reg::ZERO);
    }

    /// Offers `kd.next`: the top-level walk goes on after its leaf.
    pub fn kd_next(&self) {
        self.coprocessor(Op::Kd, KdFn::Next as u32, Reg::ZERO, Reg::ZERO, Reg::ZERO);
    }

    /// `dst` = the top-level leaf's list end.
    pub fn kd_leaf(&self, dst: Reg) {
        self.coprocessor(Op::Kd, KdFn::Leaf as u32, dst, Reg::ZERO, Reg::ZERO);
    }

    /// A coprocessor instruction: function `function`, operands `a`, `b`, result `dst`.
    fn coprocessor(&self, op: Op, function: u32, dst: Reg, a: Reg, b: Reg) {
        self.emit(Instr {
            dst: dst.0,
            a: a.0,
            b: b.0,
            imm: function,
            ..Instr::new(op)
        });
    }

    pub fn mailbox_clear(&self, which: u32) {
        self.emit(Instr {
            imm: which,
            ..Instr::new(Op::Mbc)
        });
    }

    /// `dst = (y << s) | x` of the next pixel (`ProgramConfig::pixel_shift`), or branch to
    /// `done`.
    pub fn next_pixel(&self, dst: Reg, done: Label) {
        self.emit_to(
            Instr {
                dst: dst.0,
                ..Instr::new(Op::Pixel)
            },
            done,
        );
    }

    pub fn halt(&self) {
        self.emit(Instr::new(Op::Halt));
    }

    /// Resolves the labels.
    pub fn finish(self) -> Assembled {
        let s = self.state.into_inner();
        // A program longer than the ROM is returned whole: `flow::preflight` refuses its scene
        // with the reason, and the engine refuses to build it.
        let mut code = s.code;
        let address = |l: Label| s.labels[l.0].expect("label never bound");
        for &(at, l) in &s.fixups {
            code[at].target = address(l);
        }
        for &(at, l) in &s.address_fixups {
            code[at].imm = address(l) as u32;
        }
        fold_jumps(&mut code);
        Assembled {
            code,
            sections: s.sections,
        }
    }
}

impl<'a> Arith for &'a Asm {
    type V = Val;
    fn add(self, a: Val, b: Val) -> Val {
        commutative(self, Op::FAdd, a, b)
    }
    fn sub(self, a: Val, b: Val) -> Val {
        self.op(Op::FSub, a, b)
    }
    fn mul(self, a: Val, b: Val) -> Val {
        commutative(self, Op::FMul, a, b)
    }
    fn div(self, a: Val, b: Val) -> Val {
        self.op(Op::FDiv, a, b)
    }
    fn sqrt(self, a: Val) -> Val {
        self.op(Op::FSqrt, a, Val::K(0))
    }
    fn neg(self, a: Val) -> Val {
        match a {
            Val::K(k) => Val::K(self.format.neg(k)),
            r => self.op(Op::Xor, r, Val::K(1 << (self.format.width() - 1))),
        }
    }
    fn word(self, w: u32) -> Val {
        Val::K(w)
    }
    fn format(self) -> Format {
        self.format
    }
}

/// Folds each plain jump (`jal r0`) into the instruction before it when that one can carry
/// it, so that the thread spends no turn on the jump. The `jal` stays where it was: branches
/// elsewhere may still land on it.
fn fold_jumps(code: &mut [Instr]) {
    for at in 1..code.len() {
        let (before, jump) = (code[at - 1], code[at]);
        if jump.op == Op::Jal && jump.dst == 0 && before.op.can_jump_after() && !before.invert {
            code[at - 1].invert = true;
            code[at - 1].target = jump.target;
        }
    }
}

/// A commutative operation with a constant first operand swaps it into the immediate (IEEE
/// addition and multiplication are commutative bit for bit, NaN payloads included, since
/// every NaN is the canonical one).
fn commutative(asm: &Asm, op: Op, a: Val, b: Val) -> Val {
    match (a, b) {
        (Val::K(_), Val::R(_)) => asm.op(op, b, a),
        _ => asm.op(op, a, b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plain_jump_folds_into_the_instruction_before_it_but_not_into_a_branch() {
        let a = Asm::new(Format::E7M16);
        a.section("test");
        let (top, out) = (a.label(), a.label());
        let r = a.reg();
        a.bind(top);
        a.op_to(Op::Add, r, r.into(), Val::K(1)); // 0: add, then jump @0
        a.jump(top); // 1: kept for branches that land on it
        a.branch(Op::Beq, r.into(), Val::K(9), false, out); // 2
        a.jump(top); // 3: a branch cannot carry it
        a.bind(out);
        a.halt(); // 4
        let code = a.finish().code;
        assert!(code[0].jumps_after() && code[0].target == 0, "{}", code[0]);
        assert_eq!(
            code[0].to_string(),
            format!("add r{0}, r{0}, #0x1; jump @0", r.0)
        );
        assert_eq!((code[1].op, code[1].target), (Op::Jal, 0));
        assert!(!code[2].jumps_after() && !code[2].invert && code[2].target == 4);
        assert!(!code[4].jumps_after());
    }

    #[test]
    fn a_label_address_is_the_bound_instruction_and_a_jump_after_it_folds() {
        let a = Asm::new(Format::E7M16);
        let (routine, back) = (a.label(), a.label());
        let link = a.reg();
        a.halt(); // 0
        a.mov_label(link, back); // 1: link = 4, then jump @5
        a.jump(routine); // 2
        a.halt(); // 3
        a.bind(back);
        a.halt(); // 4
        a.bind(routine);
        a.ret(link); // 5
        let code = a.finish().code;
        assert_eq!((code[1].op, code[1].dst, code[1].imm), (Op::Or, link.0, 4));
        assert!(code[1].b_imm && code[1].a == 0);
        assert!(code[1].jumps_after() && code[1].target == 5, "{}", code[1]);
    }

    #[test]
    fn assign_writes_the_destination_directly_only_when_that_is_the_same_program() {
        let f = Format::E7M16;
        // Straight code: the add writes `d` itself, no move.
        let a = Asm::new(f);
        let [x, d] = a.regs::<2>();
        let t = a.add(x.into(), Val::K(f.one()));
        a.assign(d, t);
        let code = a.finish().code;
        assert_eq!(code.len(), 1);
        assert_eq!((code[0].op, code[0].dst), (Op::FAdd, d.0));

        // `d` read between the add and the assignment: the add must not overwrite it early.
        let a = Asm::new(f);
        let [x, d, e] = a.regs::<3>();
        let t = a.add(x.into(), Val::K(f.one()));
        a.mov(e, d.into());
        a.assign(d, t);
        let code = a.finish().code;
        assert_eq!(code.len(), 3);
        assert_ne!(code[0].dst, d.0);
        assert_eq!((code[2].op, code[2].dst), (Op::Or, d.0));

        // A label between them (another path reaches the assignment): a move.
        let a = Asm::new(f);
        let [x, d] = a.regs::<2>();
        let t = a.add(x.into(), Val::K(f.one()));
        let join = a.here();
        a.assign(d, t);
        a.jump(join);
        let code = a.finish().code;
        assert_eq!(code[1].op, Op::Or, "{}", code[1]);
        assert_ne!(code[0].dst, d.0);

        // A branch between them: a move.
        let a = Asm::new(f);
        let [x, d] = a.regs::<2>();
        let out = a.label();
        let t = a.add(x.into(), Val::K(f.one()));
        a.branch(Op::Beq, x.into(), Val::K(0), false, out);
        a.assign(d, t);
        a.bind(out);
        a.halt();
        let code = a.finish().code;
        assert_eq!((code[2].op, code[2].dst), (Op::Or, d.0));
    }
}
