//! `ResultLine`: carries each instruction from I5 to its write back: its control fields, its
//! pcs, its conditions and its fast result, into which scratch and memory data join on the
//! way. `fdiv` and `fsqrt` go on from there through a long line of `DX` more clocks.
//!
//! Contract: what enters at I5 leaves at the write back [`super::ENGINE_LATENCY`] (9) clocks
//! later; a long instruction's (`fdiv`, `fsqrt`, `byte`) control, pc and fast result (`byte`'s
//! `b << 8`) leave `DX = long_latency - ENGINE_LATENCY` clocks later still (the scheduler reserved that clock, so no other instruction leaves with
//! it). The fast result of `lds` is replaced by the scratch word one clock after I5, that of
//! `ld` by the word of its bank's port `mem_latency` clocks after the request (which leaves
//! the engine one clock after I5).
//!
//! The line decodes the opcode at I6, so that the [`super::WriteBack`] has only the
//! floating-point units' flags and results to add: it leaves with `write` (the op writes a
//! register other than r0, and is not a `pixel` after the last pixel), `source` (which result
//! is written), `cond` (the condition of a branch on an integer compare, the mailbox (its hit
//! joins at I7), the pixels, `jal`, or a coprocessor's refusal), `sel_lt`/`sel_le`/`sel_eq`
//! (a branch on the floating-point compare instead), and the two next pcs, `pc_taken` when the
//! condition holds and `pc_not_taken` when it does not: `target` when the condition differs
//! from `invert`, else `pc + 1`; `jr`'s operand; the pc itself for `halt` and for a refused or
//! pending coprocessor instruction (the thread repeats it on its next turn), which does not
//! retire. A long instruction never branches (both of its pcs are the same).
//!
//! Latency: 9 clocks (`fdiv`, `fsqrt`, `byte`: `9 + DX`). Throughput: one instruction per
//! clock.
//!
//! Golden twin: none (it computes nothing); the engine's twin `hw::program::exec` sees every
//! result at once, and the frames' equality checks that the line keeps each result with its
//! instruction.

use rust_hdl::prelude::*;

use super::{op_code, FastKind, ResultSource, Retiring, MAX_MEM_LATENCY};
use crate::hw::program::isa::{Op, OPS, OP_BITS, PC_BITS, REG_BITS};
use crate::hw::Delay;

/// Registers of the fast line up to the last clock a load's data can join (the `0..8`
/// loops of `update` spell it out: rust-hdl's Verilog cannot name Rust constants); `TAIL`
/// more follow.
const FAST_STAGES: usize = 8;
/// Registers of the fast line after the last join, up to the write back.
const TAIL: usize = 1;
/// Clocks from I5 to the write back.
const LINE: usize = FAST_STAGES + TAIL;
/// Clocks from I6 (the decode) and from I7 (the mailbox hit) to the write back.
const FROM_I6: usize = LINE - 1;
const FROM_I7: usize = LINE - 2;

#[derive(LogicBlock)]
pub struct ResultLine<const DX: usize> {
    pub clock: Signal<In, Clock>,
    /// I5: the instruction.
    pub valid: Signal<In, Bit>,
    pub op: Signal<In, Bits<OP_BITS>>,
    pub dst: Signal<In, Bits<REG_BITS>>,
    pub thread: Signal<In, Bits<5>>,
    pub invert: Signal<In, Bit>,
    pub pc: Signal<In, Bits<PC_BITS>>,
    pub target: Signal<In, Bits<PC_BITS>>,
    /// I5: its conditions: a coprocessor wait; the traversal unit or the triangle tester
    /// refused the entry or has not finished; operand A's low bits (`jr`'s target); the
    /// integer compares; the pixels exhausted. I7: the mailbox hit.
    pub is_wait: Signal<In, Bit>,
    pub kd_busy: Signal<In, Bit>,
    pub tri_busy: Signal<In, Bit>,
    pub jr_target: Signal<In, Bits<PC_BITS>>,
    pub int_eq: Signal<In, Bit>,
    pub int_lt: Signal<In, Bit>,
    pub mb_hit: Signal<In, Bit>,
    pub pix_done: Signal<In, Bit>,
    /// Ray generation refuses the `pixel` (its request slot is taken): the thread repeats it.
    pub pix_busy: Signal<In, Bit>,
    /// I5: the fast result and where a load's data comes from.
    pub fast: Signal<In, Bits<32>>,
    pub kind: Signal<In, FastKind>,
    /// The data that joins: the scratch word (I6) and the ports' words.
    pub scratch_data: Signal<In, Bits<32>>,
    pub mem_data: Signal<In, Bits<32>>,
    pub nodes_data: Signal<In, Bits<32>>,
    pub a_data: Signal<In, Bits<32>>,
    pub b_data: Signal<In, Bits<32>>,

    /// Write back: the instruction leaving the line (from the long line when one leaves it).
    pub retiring: Retiring,

    /// I6: the instruction as it entered.
    valid_i6: DFF<Bit>,
    op_i6: DFF<Bits<OP_BITS>>,
    dst_i6: DFF<Bits<REG_BITS>>,
    thread_i6: DFF<Bits<5>>,
    invert_i6: DFF<Bit>,
    pc_i6: DFF<Bits<PC_BITS>>,
    pc_plus_one_i6: DFF<Bits<PC_BITS>>,
    target_i6: DFF<Bits<PC_BITS>>,
    is_wait_i6: DFF<Bit>,
    kd_busy_i6: DFF<Bit>,
    tri_busy_i6: DFF<Bit>,
    jr_target_i6: DFF<Bits<PC_BITS>>,
    int_eq_i6: DFF<Bit>,
    int_lt_i6: DFF<Bit>,
    pix_done_i6: DFF<Bit>,
    pix_busy_i6: DFF<Bit>,
    /// I6: the decode.
    is_long: Signal<Local, Bit>,
    is_mbx: Signal<Local, Bit>,
    halts: Signal<Local, Bit>,
    repeats: Signal<Local, Bit>,
    keeps_pc: Signal<Local, Bit>,
    cond_i6: Signal<Local, Bit>,
    pc_other: Signal<Local, Bits<PC_BITS>>,
    pc_target: Signal<Local, Bits<PC_BITS>>,
    pc_next: Signal<Local, Bits<PC_BITS>>,
    source_i6: Signal<Local, ResultSource>,
    /// I7: the condition but the mailbox's, and whether the mailbox's counts.
    cond_i7: DFF<Bit>,
    is_mbx_i7: DFF<Bit>,
    /// The decoded instruction on its way to the write back.
    valid_line: Delay<Bit, FROM_I6>,
    is_long_line: Delay<Bit, FROM_I6>,
    dst_line: Delay<Bits<REG_BITS>, FROM_I6>,
    thread_line: Delay<Bits<5>, FROM_I6>,
    write_line: Delay<Bit, FROM_I6>,
    source_line: Delay<ResultSource, FROM_I6>,
    cond_line: Delay<Bit, FROM_I7>,
    sel_lt_line: Delay<Bit, FROM_I6>,
    sel_le_line: Delay<Bit, FROM_I6>,
    sel_eq_line: Delay<Bit, FROM_I6>,
    pc_taken_line: Delay<Bits<PC_BITS>, FROM_I6>,
    pc_not_taken_line: Delay<Bits<PC_BITS>, FROM_I6>,
    halt_line: Delay<Bit, FROM_I6>,
    retired_line: Delay<Bit, FROM_I6>,
    wait_pending_line: Delay<Bit, FROM_I6>,
    /// The fast result and its source, a register per clock up to the last join.
    fast_line: [DFF<Bits<32>>; FAST_STAGES],
    kind_line: [DFF<FastKind>; FAST_STAGES],
    fast_tail: Delay<Bits<32>, TAIL>,
    /// The long line of `fdiv`, `fsqrt` and `byte`.
    long_valid: Delay<Bit, DX>,
    long_dst: Delay<Bits<REG_BITS>, DX>,
    long_thread: Delay<Bits<5>, DX>,
    long_write: Delay<Bit, DX>,
    long_source: Delay<ResultSource, DX>,
    long_pc: Delay<Bits<PC_BITS>, DX>,
    /// `byte`'s fast result (`b << 8`), which the colour unit's byte joins at the write back.
    long_fast: Delay<Bits<32>, DX>,

    c_mem_latency: Constant<Bits<8>>,
    c_index: [Constant<Bits<8>>; FAST_STAGES],
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

impl<const DX: usize> ResultLine<DX> {
    /// The line of an engine whose memory answers `mem_latency` clocks after a request.
    pub fn new(mem_latency: u32) -> Self {
        assert!((1..=MAX_MEM_LATENCY).contains(&mem_latency));
        // A load's data joins at stage `mem_latency + 1 <= FAST_STAGES - 1`.
        assert!(MAX_MEM_LATENCY as usize + 1 < FAST_STAGES);
        assert_eq!(LINE as u32, super::ENGINE_LATENCY);
        Self {
            clock: Default::default(),
            valid: Default::default(),
            op: Default::default(),
            dst: Default::default(),
            thread: Default::default(),
            invert: Default::default(),
            pc: Default::default(),
            target: Default::default(),
            is_wait: Default::default(),
            kd_busy: Default::default(),
            tri_busy: Default::default(),
            jr_target: Default::default(),
            int_eq: Default::default(),
            int_lt: Default::default(),
            mb_hit: Default::default(),
            pix_done: Default::default(),
            pix_busy: Default::default(),
            fast: Default::default(),
            kind: Default::default(),
            scratch_data: Default::default(),
            mem_data: Default::default(),
            nodes_data: Default::default(),
            a_data: Default::default(),
            b_data: Default::default(),
            retiring: Default::default(),
            valid_i6: Default::default(),
            op_i6: Default::default(),
            dst_i6: Default::default(),
            thread_i6: Default::default(),
            invert_i6: Default::default(),
            pc_i6: Default::default(),
            pc_plus_one_i6: Default::default(),
            target_i6: Default::default(),
            is_wait_i6: Default::default(),
            kd_busy_i6: Default::default(),
            tri_busy_i6: Default::default(),
            jr_target_i6: Default::default(),
            int_eq_i6: Default::default(),
            int_lt_i6: Default::default(),
            pix_done_i6: Default::default(),
            pix_busy_i6: Default::default(),
            is_long: Default::default(),
            is_mbx: Default::default(),
            halts: Default::default(),
            repeats: Default::default(),
            keeps_pc: Default::default(),
            cond_i6: Default::default(),
            pc_other: Default::default(),
            pc_target: Default::default(),
            pc_next: Default::default(),
            source_i6: Default::default(),
            cond_i7: Default::default(),
            is_mbx_i7: Default::default(),
            valid_line: Default::default(),
            is_long_line: Default::default(),
            dst_line: Default::default(),
            thread_line: Default::default(),
            write_line: Default::default(),
            source_line: Default::default(),
            cond_line: Default::default(),
            sel_lt_line: Default::default(),
            sel_le_line: Default::default(),
            sel_eq_line: Default::default(),
            pc_taken_line: Default::default(),
            pc_not_taken_line: Default::default(),
            halt_line: Default::default(),
            retired_line: Default::default(),
            wait_pending_line: Default::default(),
            fast_line: Default::default(),
            kind_line: Default::default(),
            fast_tail: Default::default(),
            long_valid: Default::default(),
            long_dst: Default::default(),
            long_thread: Default::default(),
            long_write: Default::default(),
            long_source: Default::default(),
            long_pc: Default::default(),
            long_fast: Default::default(),
            c_mem_latency: Constant::new(u64::from(mem_latency).into()),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
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

impl<const DX: usize> Logic for ResultLine<DX> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            valid_i6,
            op_i6,
            dst_i6,
            thread_i6,
            invert_i6,
            pc_i6,
            pc_plus_one_i6,
            target_i6,
            is_wait_i6,
            kd_busy_i6,
            tri_busy_i6,
            jr_target_i6,
            int_eq_i6,
            int_lt_i6,
            pix_done_i6,
            pix_busy_i6,
            cond_i7,
            is_mbx_i7
        );
        clock!(
            self,
            clock,
            valid_line,
            is_long_line,
            dst_line,
            thread_line,
            write_line,
            source_line,
            cond_line,
            sel_lt_line,
            sel_le_line,
            sel_eq_line,
            pc_taken_line,
            pc_not_taken_line,
            halt_line,
            retired_line,
            wait_pending_line,
            fast_tail,
            long_valid,
            long_dst,
            long_thread,
            long_write,
            long_source,
            long_pc,
            long_fast
        );
        for k in 0..8 {
            self.fast_line[k].clock.next = self.clock.val();
            self.kind_line[k].clock.next = self.clock.val();
        }
        // I5: the instruction into registers (its conditions arrive late in the clock).
        self.valid_i6.d.next = self.valid.val();
        self.op_i6.d.next = self.op.val();
        self.dst_i6.d.next = self.dst.val();
        self.thread_i6.d.next = self.thread.val();
        self.invert_i6.d.next = self.invert.val();
        self.pc_i6.d.next = self.pc.val();
        self.pc_plus_one_i6.d.next = self.pc.val() + 1;
        self.target_i6.d.next = self.target.val();
        self.is_wait_i6.d.next = self.is_wait.val();
        self.kd_busy_i6.d.next = self.kd_busy.val();
        self.tri_busy_i6.d.next = self.tri_busy.val();
        self.jr_target_i6.d.next = self.jr_target.val();
        self.int_eq_i6.d.next = self.int_eq.val();
        self.int_lt_i6.d.next = self.int_lt.val();
        self.pix_done_i6.d.next = self.pix_done.val();
        self.pix_busy_i6.d.next = self.pix_busy.val();

        // I6: decode.
        self.is_long.next = (self.op_i6.q.val() == self.op_fdiv.val())
            | (self.op_i6.q.val() == self.op_fsqrt.val())
            | (self.op_i6.q.val() == self.op_byte.val());
        self.is_mbx.next = self.op_i6.q.val() == self.op_mbx.val();
        self.halts.next = self.op_i6.q.val() == self.op_halt.val();
        // A coprocessor refused the entry (queue full) or has not finished (a wait); ray
        // generation refused the pixel.
        self.repeats.next = ((self.op_i6.q.val() == self.op_tri.val()) & self.tri_busy_i6.q.val())
            | ((self.op_i6.q.val() == self.op_kd.val()) & self.kd_busy_i6.q.val())
            | ((self.op_i6.q.val() == self.op_pixel.val()) & self.pix_busy_i6.q.val());
        self.keeps_pc.next = self.halts.val() | self.repeats.val();
        self.cond_i6.next = ((self.op_i6.q.val() == self.op_beq.val()) & self.int_eq_i6.q.val())
            | ((self.op_i6.q.val() == self.op_bltu.val()) & self.int_lt_i6.q.val())
            | ((self.op_i6.q.val() == self.op_pixel.val()) & self.pix_done_i6.q.val())
            | (self.op_i6.q.val() == self.op_jal.val())
            | self.repeats.val();
        // The next pc when the condition holds (`pc_target`) and when not (`pc_next`), unless
        // the op sets it whatever the condition (`pc_other`).
        self.pc_target.next = self.target_i6.q.val();
        self.pc_next.next = self.pc_plus_one_i6.q.val();
        if self.invert_i6.q.val() {
            self.pc_target.next = self.pc_plus_one_i6.q.val();
            self.pc_next.next = self.target_i6.q.val();
        }
        self.pc_other.next = self.jr_target_i6.q.val();
        if self.keeps_pc.val() {
            self.pc_other.next = self.pc_i6.q.val();
        }
        if self.keeps_pc.val() | (self.op_i6.q.val() == self.op_jr.val()) {
            self.pc_target.next = self.pc_other.val();
            self.pc_next.next = self.pc_other.val();
        }
        self.source_i6.next = ResultSource::Fast;
        if (self.op_i6.q.val() == self.op_fadd.val()) | (self.op_i6.q.val() == self.op_fsub.val()) {
            self.source_i6.next = ResultSource::Sum;
        }
        if self.op_i6.q.val() == self.op_fmul.val() {
            self.source_i6.next = ResultSource::Product;
        }
        if self.op_i6.q.val() == self.op_fdiv.val() {
            self.source_i6.next = ResultSource::Quotient;
        }
        if self.op_i6.q.val() == self.op_fsqrt.val() {
            self.source_i6.next = ResultSource::Root;
        }
        if self.op_i6.q.val() == self.op_byte.val() {
            self.source_i6.next = ResultSource::Byte;
        }
        self.valid_line.data_in.next = self.valid_i6.q.val();
        self.is_long_line.data_in.next = self.is_long.val();
        self.dst_line.data_in.next = self.dst_i6.q.val();
        self.thread_line.data_in.next = self.thread_i6.q.val();
        // `pixel` writes nothing once the frame's pixels are exhausted, nor when refused.
        self.write_line.data_in.next = self.valid_i6.q.val()
            & (self.dst_i6.q.val() != 0)
            & self.op_writes.val().get_bit(self.op_i6.q.val().index())
            & (!((self.op_i6.q.val() == self.op_pixel.val())
                & (self.pix_done_i6.q.val() | self.pix_busy_i6.q.val())));
        self.source_line.data_in.next = self.source_i6.val();
        self.sel_lt_line.data_in.next = self.op_i6.q.val() == self.op_bflt.val();
        self.sel_le_line.data_in.next = self.op_i6.q.val() == self.op_bfle.val();
        self.sel_eq_line.data_in.next = self.op_i6.q.val() == self.op_bfeq.val();
        self.pc_taken_line.data_in.next = self.pc_target.val();
        self.pc_not_taken_line.data_in.next = self.pc_next.val();
        self.halt_line.data_in.next = self.halts.val();
        self.retired_line.data_in.next = self.valid_i6.q.val() & (!self.repeats.val());
        // Only the coprocessor waits set `is_wait`, and their condition is `repeats`.
        self.wait_pending_line.data_in.next = self.repeats.val() & self.is_wait_i6.q.val();
        self.cond_i7.d.next = self.cond_i6.val();
        self.is_mbx_i7.d.next = self.is_mbx.val();

        // I7: the mailbox's hit.
        self.cond_line.data_in.next =
            self.cond_i7.q.val() | (self.is_mbx_i7.q.val() & self.mb_hit.val());

        // The fast line: scratch data at I6, memory data at I6 + latency.
        self.fast_line[0].d.next = self.fast.val();
        self.kind_line[0].d.next = self.kind.val();
        for k in 1..8 {
            self.fast_line[k].d.next = self.fast_line[k - 1].q.val();
            self.kind_line[k].d.next = self.kind_line[k - 1].q.val();
        }
        if self.kind_line[0].q.val() == FastKind::Scratch {
            self.fast_line[1].d.next = self.scratch_data.val();
        }
        for k in 1..7 {
            if self.c_mem_latency.val() == self.c_index[k].val() {
                if self.kind_line[k].q.val() == FastKind::Memory {
                    self.fast_line[k + 1].d.next = self.mem_data.val();
                }
                if self.kind_line[k].q.val() == FastKind::TrianglesA {
                    self.fast_line[k + 1].d.next = self.a_data.val();
                }
                if self.kind_line[k].q.val() == FastKind::TrianglesB {
                    self.fast_line[k + 1].d.next = self.b_data.val();
                }
                if self.kind_line[k].q.val() == FastKind::Nodes {
                    self.fast_line[k + 1].d.next = self.nodes_data.val();
                }
            }
        }
        self.fast_tail.data_in.next = self.fast_line[7].q.val();

        // `fdiv`, `fsqrt` and `byte` go on into the long line and leave from there.
        self.long_valid.data_in.next =
            self.valid_line.data_out.val() & self.is_long_line.data_out.val();
        self.long_dst.data_in.next = self.dst_line.data_out.val();
        self.long_thread.data_in.next = self.thread_line.data_out.val();
        self.long_write.data_in.next = self.write_line.data_out.val();
        self.long_source.data_in.next = self.source_line.data_out.val();
        self.long_pc.data_in.next = self.pc_not_taken_line.data_out.val();
        self.long_fast.data_in.next = self.fast_tail.data_out.val();
        if self.long_valid.data_out.val() {
            self.retiring.valid.next = true;
            self.retiring.dst.next = self.long_dst.data_out.val();
            self.retiring.thread.next = self.long_thread.data_out.val();
            self.retiring.write.next = self.long_write.data_out.val();
            self.retiring.source.next = self.long_source.data_out.val();
            self.retiring.cond.next = false;
            self.retiring.sel_lt.next = false;
            self.retiring.sel_le.next = false;
            self.retiring.sel_eq.next = false;
            self.retiring.pc_taken.next = self.long_pc.data_out.val();
            self.retiring.pc_not_taken.next = self.long_pc.data_out.val();
            self.retiring.halt.next = false;
            self.retiring.retired.next = true;
            self.retiring.wait_pending.next = false;
        } else {
            self.retiring.valid.next =
                self.valid_line.data_out.val() & (!self.is_long_line.data_out.val());
            self.retiring.dst.next = self.dst_line.data_out.val();
            self.retiring.thread.next = self.thread_line.data_out.val();
            self.retiring.write.next =
                self.write_line.data_out.val() & (!self.is_long_line.data_out.val());
            self.retiring.source.next = self.source_line.data_out.val();
            self.retiring.cond.next = self.cond_line.data_out.val();
            self.retiring.sel_lt.next = self.sel_lt_line.data_out.val();
            self.retiring.sel_le.next = self.sel_le_line.data_out.val();
            self.retiring.sel_eq.next = self.sel_eq_line.data_out.val();
            self.retiring.pc_taken.next = self.pc_taken_line.data_out.val();
            self.retiring.pc_not_taken.next = self.pc_not_taken_line.data_out.val();
            self.retiring.halt.next = self.halt_line.data_out.val();
            self.retiring.retired.next =
                self.retired_line.data_out.val() & (!self.is_long_line.data_out.val());
            self.retiring.wait_pending.next = self.wait_pending_line.data_out.val();
        }
        self.retiring.fast.next = self.fast_tail.data_out.val();
        if self.long_valid.data_out.val() {
            self.retiring.fast.next = self.long_fast.data_out.val();
        }
    }
}
