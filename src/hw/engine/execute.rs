//! `Execute`: the engine's single-clock work at I5. It computes the integer,
//! link, pixel and coprocessor-reading results (the *fast* result), the integer conditions,
//! and the addresses of loads, stores and scratch accesses, and names where a load's data
//! will come from.
//!
//! Contract: from an instruction's `op`, operands `a`, `b`, `imm`, `shift`, `bank` and `pc`
//! at I5: `fast` is `add`/`sub`/`and`/`or`/`xor`/`shr`/`shl` of `a` and `b`, `jal`'s
//! link `pc + 1`, `byte`'s `b << 8` (the unit's byte joins it at the write back), the
//! pixel word, or what `tri.wait`/`tri.hit`/`tri.instance`/`tri.triangle` read from the
//! triangle tester and `kd.wait`/`kd.leaf` from the traversal unit; `kind` says whether the
//! result line fills in a scratch or memory word later (`ld` by its bank, `lds`). `mem_address = (a << shift) + imm` (loads and
//! frame-buffer stores), `scratch_address = a + imm`; `int_eq`, `int_lt`: `a == b`, `a < b`
//! unsigned.
//!
//! Latency: combinational (I5). Throughput: one instruction per clock.
//!
//! Golden twin: `hw::program::exec` (the engine's twin), the same operations per opcode.

use rust_hdl::prelude::*;

use super::{bank, kd_fn, op_code, tri_fn, FastKind};
use crate::hw::program::isa::{KdFn, Op, TriFn, BANK_BITS, OP_BITS, PC_BITS, SHIFT_BITS};
use crate::layout;

#[derive(LogicBlock)]
pub struct Execute<const W: usize> {
    /// I5: the instruction.
    pub op: Signal<In, Bits<OP_BITS>>,
    pub a: Signal<In, Bits<32>>,
    pub b: Signal<In, Bits<32>>,
    pub imm: Signal<In, Bits<32>>,
    pub shift: Signal<In, Bits<SHIFT_BITS>>,
    pub bank: Signal<In, Bits<BANK_BITS>>,
    pub pc: Signal<In, Bits<PC_BITS>>,
    /// Ray generation's pixel word (`PrimaryRays::word`).
    pub pixel: Signal<In, Bits<32>>,
    /// The triangle tester's answers for the thread at I5.
    pub tester_best_t: Signal<In, Bits<W>>,
    pub tester_hit: Signal<In, Bit>,
    pub tester_instance: Signal<In, Bits<32>>,
    pub tester_triangle: Signal<In, Bits<32>>,
    /// The traversal unit's words for the thread at I5: `kd.wait`'s (the top-level leaf's list
    /// start, or after an object walk its hit flag) and `kd.leaf`'s (the list's end).
    pub top_from: Signal<In, Bits<32>>,
    pub top_to: Signal<In, Bits<32>>,
    /// The thread's primary direction (ray generation's answer at I5), for `tri.dir`.
    pub primary_dir: [Signal<In, Bits<W>>; 3],
    pub fast: Signal<Out, Bits<32>>,
    pub kind: Signal<Out, FastKind>,
    pub int_eq: Signal<Out, Bit>,
    pub int_lt: Signal<Out, Bit>,
    pub mem_address: Signal<Out, Bits<32>>,
    pub scratch_address: Signal<Out, Bits<32>>,

    result: Signal<Local, Bits<32>>,
    source: Signal<Local, FastKind>,

    op_add: Constant<Bits<5>>,
    op_sub: Constant<Bits<5>>,
    op_and: Constant<Bits<5>>,
    op_or: Constant<Bits<5>>,
    op_xor: Constant<Bits<5>>,
    op_shr: Constant<Bits<5>>,
    op_shl: Constant<Bits<5>>,
    op_ld: Constant<Bits<5>>,
    op_lds: Constant<Bits<5>>,
    op_jal: Constant<Bits<5>>,
    op_byte: Constant<Bits<5>>,
    op_pixel: Constant<Bits<5>>,
    op_tri: Constant<Bits<5>>,
    op_kd: Constant<Bits<5>>,
    kd_wait: Constant<Bits<32>>,
    kd_leaf: Constant<Bits<32>>,
    tri_wait: Constant<Bits<32>>,
    tri_hit: Constant<Bits<32>>,
    tri_instance: Constant<Bits<32>>,
    tri_triangle: Constant<Bits<32>>,
    tri_dir: Constant<Bits<32>>,
    dir_word: Signal<Local, Bits<W>>,
    c_component: [Constant<Bits<SHIFT_BITS>>; 3],
    bank_nodes: Constant<Bits<3>>,
    bank_a: Constant<Bits<3>>,
    bank_b: Constant<Bits<3>>,
}

impl<const W: usize> Default for Execute<W> {
    fn default() -> Self {
        Self {
            op: Default::default(),
            a: Default::default(),
            b: Default::default(),
            imm: Default::default(),
            shift: Default::default(),
            bank: Default::default(),
            pc: Default::default(),
            pixel: Default::default(),
            tester_best_t: Default::default(),
            tester_hit: Default::default(),
            tester_instance: Default::default(),
            tester_triangle: Default::default(),
            top_from: Default::default(),
            top_to: Default::default(),
            primary_dir: Default::default(),
            fast: Default::default(),
            kind: Default::default(),
            int_eq: Default::default(),
            int_lt: Default::default(),
            mem_address: Default::default(),
            scratch_address: Default::default(),
            result: Default::default(),
            source: Default::default(),
            op_add: op_code(Op::Add),
            op_sub: op_code(Op::Sub),
            op_and: op_code(Op::And),
            op_or: op_code(Op::Or),
            op_xor: op_code(Op::Xor),
            op_shr: op_code(Op::Shr),
            op_shl: op_code(Op::Shl),
            op_ld: op_code(Op::Ld),
            op_lds: op_code(Op::Lds),
            op_jal: op_code(Op::Jal),
            op_byte: op_code(Op::Byte),
            op_pixel: op_code(Op::Pixel),
            op_tri: op_code(Op::Tri),
            op_kd: op_code(Op::Kd),
            kd_wait: kd_fn(KdFn::Wait),
            kd_leaf: kd_fn(KdFn::Leaf),
            tri_wait: tri_fn(TriFn::Wait),
            tri_hit: tri_fn(TriFn::Hit),
            tri_instance: tri_fn(TriFn::Instance),
            tri_triangle: tri_fn(TriFn::Triangle),
            tri_dir: tri_fn(TriFn::Dir),
            dir_word: Default::default(),
            c_component: std::array::from_fn(|k| Constant::new((k as u64).into())),
            bank_nodes: bank(layout::NODES),
            bank_a: bank(layout::TRIANGLES_A),
            bank_b: bank(layout::TRIANGLES_B),
        }
    }
}

impl<const W: usize> Logic for Execute<W> {
    #[hdl_gen]
    fn update(&mut self) {
        self.int_eq.next = self.a.val() == self.b.val();
        self.int_lt.next = self.a.val() < self.b.val();
        self.mem_address.next = (self.a.val() << self.shift.val()) + self.imm.val();
        self.scratch_address.next = self.a.val() + self.imm.val();

        // Settled in locals and given to the outputs once (they leave the block).
        self.source.next = FastKind::Computed;
        self.result.next = 0.into();
        if self.op.val() == self.op_ld.val() {
            self.source.next = FastKind::Memory;
            if self.bank.val() == self.bank_a.val() {
                self.source.next = FastKind::TrianglesA;
            }
            if self.bank.val() == self.bank_b.val() {
                self.source.next = FastKind::TrianglesB;
            }
            if self.bank.val() == self.bank_nodes.val() {
                self.source.next = FastKind::Nodes;
            }
        }
        if self.op.val() == self.op_lds.val() {
            self.source.next = FastKind::Scratch;
        }
        if self.op.val() == self.op_jal.val() {
            self.result.next = bit_cast::<32, PC_BITS>(self.pc.val() + 1);
        }
        if self.op.val() == self.op_byte.val() {
            self.result.next = self.b.val() << 8;
        }
        if self.op.val() == self.op_pixel.val() {
            self.result.next = self.pixel.val();
        }
        if self.op.val() == self.op_tri.val() {
            if self.imm.val() == self.tri_wait.val() {
                self.result.next = bit_cast::<32, W>(self.tester_best_t.val());
            }
            if self.imm.val() == self.tri_hit.val() {
                self.result.next = bit_cast::<32, 1>(self.tester_hit.val().into());
            }
            if self.imm.val() == self.tri_instance.val() {
                self.result.next = self.tester_instance.val();
            }
            if self.imm.val() == self.tri_triangle.val() {
                self.result.next = self.tester_triangle.val();
            }
        }
        if self.op.val() == self.op_kd.val() {
            if self.imm.val() == self.kd_wait.val() {
                self.result.next = self.top_from.val();
            }
            if self.imm.val() == self.kd_leaf.val() {
                self.result.next = self.top_to.val();
            }
        }
        // `tri.dir`: the primary direction's component named by the shift field.
        self.dir_word.next = self.primary_dir[0].val();
        for k in 0..3 {
            if self.shift.val() == self.c_component[k].val() {
                self.dir_word.next = self.primary_dir[k].val();
            }
        }
        if (self.op.val() == self.op_tri.val()) & (self.imm.val() == self.tri_dir.val()) {
            self.result.next = bit_cast::<32, W>(self.dir_word.val());
        }
        // The ops are exclusive, so this order only decides which result sits nearest the
        // output: the integer ALU's last, the adders' carry chains at the very end (with them
        // first, an operand's path into the result line had 27 levels: 86.2 MHz placed).
        if self.op.val() == self.op_and.val() {
            self.result.next = self.a.val() & self.b.val();
        }
        if self.op.val() == self.op_or.val() {
            self.result.next = self.a.val() | self.b.val();
        }
        if self.op.val() == self.op_xor.val() {
            self.result.next = self.a.val() ^ self.b.val();
        }
        if self.op.val() == self.op_shr.val() {
            self.result.next = self.a.val() >> self.b.val().get_bits::<5>(0);
        }
        if self.op.val() == self.op_shl.val() {
            self.result.next = self.a.val() << self.b.val().get_bits::<5>(0);
        }
        if self.op.val() == self.op_sub.val() {
            self.result.next = self.a.val() - self.b.val();
        }
        if self.op.val() == self.op_add.val() {
            self.result.next = self.a.val() + self.b.val();
        }
        self.fast.next = self.result.val();
        self.kind.next = self.source.val();
    }
}
