//! `ResultLine`: carries each instruction from I4 to its write back: its control fields, its
//! pcs, its conditions and its fast result, into which scratch and memory data join on the
//! way. `fdiv` and `fsqrt` go on from there through a long line of `DX` more clocks.
//!
//! Contract: what enters at I4 leaves at the write back [`super::ENGINE_LATENCY`] (12) clocks
//! later; a long instruction's control and pcs leave `DX = long_latency - ENGINE_LATENCY`
//! clocks later still (the scheduler reserved that clock, so no other instruction leaves with
//! it; its conditions and fast result are not used). The fast result of `lds` and `itof` is
//! replaced by the scratch word or the converted word one clock after I4, that of `ld` by the word of its bank's port
//! `mem_latency` clocks after the request (which leaves the engine one clock after I4).
//!
//! Latency: 12 clocks (`fdiv`, `fsqrt`: `12 + DX`). Throughput: one instruction per clock.
//!
//! Golden twin: none (it computes nothing); the engine's twin `hw::program::exec` sees every
//! result at once, and the frames' equality checks that the line keeps each result with its
//! instruction.

use rust_hdl::prelude::*;

use super::{op_code, FastKind, Retiring, MAX_MEM_LATENCY};
use crate::hw::program::isa::{Op, OP_BITS, PC_BITS, REG_BITS};
use crate::hw::Delay;

/// Registers of the fast line up to the last clock a load's data can join (the `0..8`
/// loops of `update` spell it out: rust-hdl's Verilog cannot name Rust constants); `TAIL`
/// more follow.
const FAST_STAGES: usize = 8;
/// Registers of the fast line after the last join, up to the write back.
const TAIL: usize = 4;
/// Clocks from I4 to the write back.
const LINE: usize = FAST_STAGES + TAIL;
/// Clocks from I6 to the write back (the mailbox hit joins there).
const FROM_I6: usize = LINE - 2;

#[derive(LogicBlock)]
pub struct ResultLine<const DX: usize> {
    pub clock: Signal<In, Clock>,
    /// I4: the instruction.
    pub valid: Signal<In, Bit>,
    pub op: Signal<In, Bits<OP_BITS>>,
    pub dst: Signal<In, Bits<REG_BITS>>,
    pub thread: Signal<In, Bits<5>>,
    pub invert: Signal<In, Bit>,
    pub pc: Signal<In, Bits<PC_BITS>>,
    pub target: Signal<In, Bits<PC_BITS>>,
    /// I4: its conditions: a coprocessor wait; the traversal unit or the triangle tester
    /// refused the entry or has not finished; operand A's low bits (`jr`'s target); the
    /// integer compares; the pixels exhausted. I6: the mailbox hit.
    pub is_wait: Signal<In, Bit>,
    pub kd_busy: Signal<In, Bit>,
    pub tri_busy: Signal<In, Bit>,
    pub jr_target: Signal<In, Bits<PC_BITS>>,
    pub int_eq: Signal<In, Bit>,
    pub int_lt: Signal<In, Bit>,
    pub mb_hit: Signal<In, Bit>,
    pub pix_done: Signal<In, Bit>,
    /// I4: the fast result and where a load's data comes from.
    pub fast: Signal<In, Bits<32>>,
    pub kind: Signal<In, FastKind>,
    /// The data that joins: `itof`'s word and the scratch word (I5) and the ports' words.
    pub converted: Signal<In, Bits<32>>,
    pub scratch_data: Signal<In, Bits<32>>,
    pub mem_data: Signal<In, Bits<32>>,
    pub nodes_data: Signal<In, Bits<32>>,
    pub uv_data: Signal<In, Bits<32>>,
    pub t_data: Signal<In, Bits<32>>,

    /// Write back: the instruction leaving the line (from the long line when one leaves it).
    pub retiring: Retiring,

    valid_line: Delay<Bit, LINE>,
    op_line: Delay<Bits<OP_BITS>, LINE>,
    dst_line: Delay<Bits<REG_BITS>, LINE>,
    thread_line: Delay<Bits<5>, LINE>,
    invert_line: Delay<Bit, LINE>,
    next_line: Delay<Bits<PC_BITS>, LINE>,
    target_line: Delay<Bits<PC_BITS>, LINE>,
    wait_line: Delay<Bit, LINE>,
    kd_busy_line: Delay<Bit, LINE>,
    tri_busy_line: Delay<Bit, LINE>,
    jr_target_line: Delay<Bits<PC_BITS>, LINE>,
    int_eq_line: Delay<Bit, LINE>,
    int_lt_line: Delay<Bit, LINE>,
    mb_hit_line: Delay<Bit, FROM_I6>,
    pix_done_line: Delay<Bit, LINE>,
    /// The fast result and its source, a register per clock up to the last join.
    fast_line: [DFF<Bits<32>>; FAST_STAGES],
    kind_line: [DFF<FastKind>; FAST_STAGES],
    fast_tail: Delay<Bits<32>, TAIL>,
    /// The long line of `fdiv` and `fsqrt`.
    long_valid: Delay<Bit, DX>,
    long_op: Delay<Bits<OP_BITS>, DX>,
    long_dst: Delay<Bits<REG_BITS>, DX>,
    long_thread: Delay<Bits<5>, DX>,
    long_invert: Delay<Bit, DX>,
    long_next: Delay<Bits<PC_BITS>, DX>,
    long_target: Delay<Bits<PC_BITS>, DX>,
    is_long: Signal<Local, Bit>,

    c_mem_latency: Constant<Bits<8>>,
    c_index: [Constant<Bits<8>>; FAST_STAGES],
    op_fdiv: Constant<Bits<5>>,
    op_fsqrt: Constant<Bits<5>>,
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
            fast: Default::default(),
            kind: Default::default(),
            converted: Default::default(),
            scratch_data: Default::default(),
            mem_data: Default::default(),
            nodes_data: Default::default(),
            uv_data: Default::default(),
            t_data: Default::default(),
            retiring: Default::default(),
            valid_line: Default::default(),
            op_line: Default::default(),
            dst_line: Default::default(),
            thread_line: Default::default(),
            invert_line: Default::default(),
            next_line: Default::default(),
            target_line: Default::default(),
            wait_line: Default::default(),
            kd_busy_line: Default::default(),
            tri_busy_line: Default::default(),
            jr_target_line: Default::default(),
            int_eq_line: Default::default(),
            int_lt_line: Default::default(),
            mb_hit_line: Default::default(),
            pix_done_line: Default::default(),
            fast_line: Default::default(),
            kind_line: Default::default(),
            fast_tail: Default::default(),
            long_valid: Default::default(),
            long_op: Default::default(),
            long_dst: Default::default(),
            long_thread: Default::default(),
            long_invert: Default::default(),
            long_next: Default::default(),
            long_target: Default::default(),
            is_long: Default::default(),
            c_mem_latency: Constant::new(u64::from(mem_latency).into()),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
            op_fdiv: op_code(Op::FDiv),
            op_fsqrt: op_code(Op::FSqrt),
        }
    }
}

impl<const DX: usize> Logic for ResultLine<DX> {
    #[hdl_gen]
    fn update(&mut self) {
        clock!(
            self,
            clock,
            valid_line,
            op_line,
            dst_line,
            thread_line,
            invert_line,
            next_line,
            target_line,
            wait_line,
            kd_busy_line,
            tri_busy_line,
            jr_target_line,
            int_eq_line,
            int_lt_line,
            mb_hit_line,
            pix_done_line,
            fast_tail,
            long_valid,
            long_op,
            long_dst,
            long_thread,
            long_invert,
            long_next,
            long_target
        );
        for k in 0..8 {
            self.fast_line[k].clock.next = self.clock.val();
            self.kind_line[k].clock.next = self.clock.val();
        }
        self.valid_line.data_in.next = self.valid.val();
        self.op_line.data_in.next = self.op.val();
        self.dst_line.data_in.next = self.dst.val();
        self.thread_line.data_in.next = self.thread.val();
        self.invert_line.data_in.next = self.invert.val();
        self.next_line.data_in.next = self.pc.val() + 1;
        self.target_line.data_in.next = self.target.val();
        self.wait_line.data_in.next = self.is_wait.val();
        self.kd_busy_line.data_in.next = self.kd_busy.val();
        self.tri_busy_line.data_in.next = self.tri_busy.val();
        self.jr_target_line.data_in.next = self.jr_target.val();
        self.int_eq_line.data_in.next = self.int_eq.val();
        self.int_lt_line.data_in.next = self.int_lt.val();
        self.mb_hit_line.data_in.next = self.mb_hit.val();
        self.pix_done_line.data_in.next = self.pix_done.val();

        // The fast line: scratch data at I5, memory data at I5 + latency.
        self.fast_line[0].d.next = self.fast.val();
        self.kind_line[0].d.next = self.kind.val();
        for k in 1..8 {
            self.fast_line[k].d.next = self.fast_line[k - 1].q.val();
            self.kind_line[k].d.next = self.kind_line[k - 1].q.val();
        }
        if self.kind_line[0].q.val() == FastKind::Converted {
            self.fast_line[1].d.next = self.converted.val();
        }
        if self.kind_line[0].q.val() == FastKind::Scratch {
            self.fast_line[1].d.next = self.scratch_data.val();
        }
        for k in 1..7 {
            if self.c_mem_latency.val() == self.c_index[k].val() {
                if self.kind_line[k].q.val() == FastKind::Memory {
                    self.fast_line[k + 1].d.next = self.mem_data.val();
                }
                if self.kind_line[k].q.val() == FastKind::TrianglesUv {
                    self.fast_line[k + 1].d.next = self.uv_data.val();
                }
                if self.kind_line[k].q.val() == FastKind::TrianglesT {
                    self.fast_line[k + 1].d.next = self.t_data.val();
                }
                if self.kind_line[k].q.val() == FastKind::Nodes {
                    self.fast_line[k + 1].d.next = self.nodes_data.val();
                }
            }
        }
        self.fast_tail.data_in.next = self.fast_line[7].q.val();

        // `fdiv` and `fsqrt` go on into the long line and leave from there.
        self.is_long.next = (self.op_line.data_out.val() == self.op_fdiv.val())
            | (self.op_line.data_out.val() == self.op_fsqrt.val());
        self.long_valid.data_in.next = self.valid_line.data_out.val() & self.is_long.val();
        self.long_op.data_in.next = self.op_line.data_out.val();
        self.long_dst.data_in.next = self.dst_line.data_out.val();
        self.long_thread.data_in.next = self.thread_line.data_out.val();
        self.long_invert.data_in.next = self.invert_line.data_out.val();
        self.long_next.data_in.next = self.next_line.data_out.val();
        self.long_target.data_in.next = self.target_line.data_out.val();
        if self.long_valid.data_out.val() {
            self.retiring.valid.next = true;
            self.retiring.op.next = self.long_op.data_out.val();
            self.retiring.dst.next = self.long_dst.data_out.val();
            self.retiring.thread.next = self.long_thread.data_out.val();
            self.retiring.invert.next = self.long_invert.data_out.val();
            self.retiring.pc_plus_one.next = self.long_next.data_out.val();
            self.retiring.target.next = self.long_target.data_out.val();
        } else {
            self.retiring.valid.next = self.valid_line.data_out.val() & (!self.is_long.val());
            self.retiring.op.next = self.op_line.data_out.val();
            self.retiring.dst.next = self.dst_line.data_out.val();
            self.retiring.thread.next = self.thread_line.data_out.val();
            self.retiring.invert.next = self.invert_line.data_out.val();
            self.retiring.pc_plus_one.next = self.next_line.data_out.val();
            self.retiring.target.next = self.target_line.data_out.val();
        }
        self.retiring.is_wait.next = self.wait_line.data_out.val();
        self.retiring.kd_busy.next = self.kd_busy_line.data_out.val();
        self.retiring.tri_busy.next = self.tri_busy_line.data_out.val();
        self.retiring.jr_target.next = self.jr_target_line.data_out.val();
        self.retiring.int_eq.next = self.int_eq_line.data_out.val();
        self.retiring.int_lt.next = self.int_lt_line.data_out.val();
        self.retiring.mb_hit.next = self.mb_hit_line.data_out.val();
        self.retiring.pix_done.next = self.pix_done_line.data_out.val();
        self.retiring.fast.next = self.fast_tail.data_out.val();
    }
}
