//! `WriteBack`: the engine's last stage. It chooses an instruction's result and its thread's
//! next pc, and says what the scheduler and the counters need to know, one clock later.
//!
//! Contract: for the instruction leaving the [`super::ResultLine`] (`valid`, `op`, ...) and
//! the floating-point units' results of the same clock: `data` is the result its opcode names
//! (`sum` for `fadd`/`fsub`, `product`, `quotient`, `root`, the fast result, or for `byte`
//! the fast result with the unit's byte in its low bits); `write` is set for the ops that
//! write (`Op::writes`) a destination other than r0, and not for a `pixel` once the pixels are
//! exhausted. The condition is the compare flag, integer compare, mailbox hit, pixels
//! exhausted, "always" (`jal`) or the coprocessor's refusal (`tri`, `kd`) the opcode names;
//! the next pc is the target when the condition differs from `invert`, else `pc + 1`; `jr`
//! jumps to its operand; `halt` and a refused or pending coprocessor instruction keep the pc
//! (the thread repeats it on its next turn). `retired` counts every instruction but those
//! repeats (the twin never repeats); `wait_pending` tells the scheduler that a wait is not
//! answered yet.
//!
//! Latency: 1 clock: every output is a register, so the register file, the pc store and the
//! scheduler see the write back (`valid`, `thread`, `dst` with the rest) the clock after the
//! instruction leaves the result line; the result and condition select in between would leave
//! no room for their block-RAM and wake-up logic in the same clock. Throughput: one
//! instruction per clock.
//!
//! Golden twin: `hw::program::exec` (the engine's twin): the same result, condition and next
//! pc per opcode.

use rust_hdl::prelude::*;

use super::{op_code, RetiringIn};
use crate::hw::program::isa::{Op, OPS, PC_BITS, REG_BITS};

#[derive(LogicBlock)]
pub struct WriteBack<const W: usize> {
    pub clock: Signal<In, Clock>,
    /// The instruction leaving the result line.
    pub retiring: RetiringIn,
    /// The floating-point units' results of this clock.
    pub sum: Signal<In, Bits<W>>,
    pub product: Signal<In, Bits<W>>,
    pub quotient: Signal<In, Bits<W>>,
    pub root: Signal<In, Bits<W>>,
    pub lt: Signal<In, Bit>,
    pub le: Signal<In, Bit>,
    pub eq: Signal<In, Bit>,
    pub colour_byte: Signal<In, Bits<8>>,

    /// The clock after the instruction left the line: it, its thread and destination.
    pub valid: Signal<Out, Bit>,
    pub thread: Signal<Out, Bits<5>>,
    pub dst: Signal<Out, Bits<REG_BITS>>,
    pub write: Signal<Out, Bit>,
    pub data: Signal<Out, Bits<32>>,
    pub next_pc: Signal<Out, Bits<PC_BITS>>,
    pub halt: Signal<Out, Bit>,
    pub retired: Signal<Out, Bit>,
    pub wait_pending: Signal<Out, Bit>,

    cond: Signal<Local, Bit>,
    repeats: Signal<Local, Bit>,
    pc: Signal<Local, Bits<PC_BITS>>,
    result: Signal<Local, Bits<32>>,
    valid_r: DFF<Bit>,
    thread_r: DFF<Bits<5>>,
    dst_r: DFF<Bits<REG_BITS>>,
    write_r: DFF<Bit>,
    data_r: DFF<Bits<32>>,
    next_pc_r: DFF<Bits<PC_BITS>>,
    halt_r: DFF<Bit>,
    retired_r: DFF<Bit>,
    wait_pending_r: DFF<Bit>,

    op_fadd: Constant<Bits<5>>,
    op_fsub: Constant<Bits<5>>,
    op_fmul: Constant<Bits<5>>,
    op_fdiv: Constant<Bits<5>>,
    op_fsqrt: Constant<Bits<5>>,
    op_bflt: Constant<Bits<5>>,
    op_bfle: Constant<Bits<5>>,
    op_bfeq: Constant<Bits<5>>,
    op_beq: Constant<Bits<5>>,
    op_bltu: Constant<Bits<5>>,
    op_jal: Constant<Bits<5>>,
    op_jr: Constant<Bits<5>>,
    op_mbx: Constant<Bits<5>>,
    op_pixel: Constant<Bits<5>>,
    op_halt: Constant<Bits<5>>,
    op_tri: Constant<Bits<5>>,
    op_kd: Constant<Bits<5>>,
    op_byte: Constant<Bits<5>>,
    /// Bit `op` set for every op that writes `dst` (`Op::writes`).
    op_writes: Constant<Bits<32>>,
}

impl<const W: usize> Default for WriteBack<W> {
    fn default() -> Self {
        Self {
            clock: Default::default(),
            retiring: Default::default(),
            sum: Default::default(),
            product: Default::default(),
            quotient: Default::default(),
            root: Default::default(),
            lt: Default::default(),
            le: Default::default(),
            eq: Default::default(),
            colour_byte: Default::default(),
            valid: Default::default(),
            thread: Default::default(),
            dst: Default::default(),
            write: Default::default(),
            data: Default::default(),
            next_pc: Default::default(),
            halt: Default::default(),
            retired: Default::default(),
            wait_pending: Default::default(),
            cond: Default::default(),
            repeats: Default::default(),
            pc: Default::default(),
            result: Default::default(),
            valid_r: Default::default(),
            thread_r: Default::default(),
            dst_r: Default::default(),
            write_r: Default::default(),
            data_r: Default::default(),
            next_pc_r: Default::default(),
            halt_r: Default::default(),
            retired_r: Default::default(),
            wait_pending_r: Default::default(),
            op_fadd: op_code(Op::FAdd),
            op_fsub: op_code(Op::FSub),
            op_fmul: op_code(Op::FMul),
            op_fdiv: op_code(Op::FDiv),
            op_fsqrt: op_code(Op::FSqrt),
            op_bflt: op_code(Op::BFlt),
            op_bfle: op_code(Op::BFle),
            op_bfeq: op_code(Op::BFeq),
            op_beq: op_code(Op::Beq),
            op_bltu: op_code(Op::Bltu),
            op_jal: op_code(Op::Jal),
            op_jr: op_code(Op::Jr),
            op_mbx: op_code(Op::Mbx),
            op_pixel: op_code(Op::Pixel),
            op_halt: op_code(Op::Halt),
            op_tri: op_code(Op::Tri),
            op_kd: op_code(Op::Kd),
            op_byte: op_code(Op::Byte),
            op_writes: Constant::new(
                OPS.iter()
                    .filter(|o| o.writes())
                    .fold(0u64, |m, &o| m | 1 << (o as u64))
                    .into(),
            ),
        }
    }
}

impl<const W: usize> Logic for WriteBack<W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            valid_r,
            thread_r,
            dst_r,
            write_r,
            data_r,
            next_pc_r,
            halt_r,
            retired_r,
            wait_pending_r
        );
        self.cond.next = false;
        if self.retiring.op.val() == self.op_bflt.val() {
            self.cond.next = self.lt.val();
        }
        if self.retiring.op.val() == self.op_bfle.val() {
            self.cond.next = self.le.val();
        }
        if self.retiring.op.val() == self.op_bfeq.val() {
            self.cond.next = self.eq.val();
        }
        if self.retiring.op.val() == self.op_beq.val() {
            self.cond.next = self.retiring.int_eq.val();
        }
        if self.retiring.op.val() == self.op_bltu.val() {
            self.cond.next = self.retiring.int_lt.val();
        }
        if self.retiring.op.val() == self.op_mbx.val() {
            self.cond.next = self.retiring.mb_hit.val();
        }
        if self.retiring.op.val() == self.op_pixel.val() {
            self.cond.next = self.retiring.pix_done.val();
        }
        if self.retiring.op.val() == self.op_jal.val() {
            self.cond.next = true;
        }
        if self.retiring.op.val() == self.op_tri.val() {
            self.cond.next = self.retiring.tri_busy.val();
        }
        if self.retiring.op.val() == self.op_kd.val() {
            self.cond.next = self.retiring.kd_busy.val();
        }
        // A coprocessor refused the entry (queue full) or has not finished (a wait).
        self.repeats.next = ((self.retiring.op.val() == self.op_tri.val())
            | (self.retiring.op.val() == self.op_kd.val()))
            & self.cond.val();

        if self.cond.val() != self.retiring.invert.val() {
            self.pc.next = self.retiring.target.val();
        } else {
            self.pc.next = self.retiring.pc_plus_one.val();
        }
        if self.retiring.op.val() == self.op_jr.val() {
            self.pc.next = self.retiring.jr_target.val();
        }
        if (self.retiring.op.val() == self.op_halt.val()) | self.repeats.val() {
            // A halted thread keeps its pc; a repeat comes back to it on the next turn.
            self.pc.next = self.retiring.pc_plus_one.val() - 1;
        }

        self.result.next = self.retiring.fast.val();
        if (self.retiring.op.val() == self.op_fadd.val())
            | (self.retiring.op.val() == self.op_fsub.val())
        {
            self.result.next = bit_cast::<32, W>(self.sum.val());
        }
        if self.retiring.op.val() == self.op_fmul.val() {
            self.result.next = bit_cast::<32, W>(self.product.val());
        }
        if self.retiring.op.val() == self.op_fdiv.val() {
            self.result.next = bit_cast::<32, W>(self.quotient.val());
        }
        if self.retiring.op.val() == self.op_fsqrt.val() {
            self.result.next = bit_cast::<32, W>(self.root.val());
        }
        if self.retiring.op.val() == self.op_byte.val() {
            self.result.next = self.retiring.fast.val() | bit_cast::<32, 8>(self.colour_byte.val());
        }

        self.valid_r.d.next = self.retiring.valid.val();
        self.thread_r.d.next = self.retiring.thread.val();
        self.dst_r.d.next = self.retiring.dst.val();
        self.next_pc_r.d.next = self.pc.val();
        self.data_r.d.next = self.result.val();
        self.halt_r.d.next = self.retiring.op.val() == self.op_halt.val();
        // `pixel` writes nothing once the frame's pixels are exhausted.
        self.write_r.d.next = self.retiring.valid.val()
            & (self.retiring.dst.val() != 0)
            & self.op_writes.val().get_bit(self.retiring.op.val().index())
            & (!((self.retiring.op.val() == self.op_pixel.val()) & self.retiring.pix_done.val()));
        self.retired_r.d.next = self.retiring.valid.val() & (!self.repeats.val());
        self.wait_pending_r.d.next = self.cond.val() & self.retiring.is_wait.val();

        self.valid.next = self.valid_r.q.val();
        self.thread.next = self.thread_r.q.val();
        self.dst.next = self.dst_r.q.val();
        self.write.next = self.write_r.q.val();
        self.data.next = self.data_r.q.val();
        self.next_pc.next = self.next_pc_r.q.val();
        self.halt.next = self.halt_r.q.val();
        self.retired.next = self.retired_r.q.val();
        self.wait_pending.next = self.wait_pending_r.q.val();
    }
}
