//! `WriteBack`: the engine's last stage. It chooses an instruction's result and its thread's
//! next pc, and says what the scheduler and the counters need to know, one clock later.
//!
//! Contract: for the instruction leaving the [`super::ResultLine`] (decoded there: see its
//! contract) and the floating-point units' results of the same clock: `data` is the result
//! its `source` names (`sum`, `product`, `quotient`, `root`, the fast result, or the fast
//! result with the colour unit's byte in its low bits); the condition is `cond` or the
//! compare flag a `sel_*` names, and the next pc `pc_taken` when it holds, else
//! `pc_not_taken`; `write`, `halt`, `retired` (every instruction but a coprocessor
//! instruction repeated; the twin never repeats) and `wait_pending` (a wait not answered yet,
//! for the scheduler) pass through.
//!
//! Latency: 1 clock: every output is a register, so the register file, the pc store and the
//! scheduler see the write back (`valid`, `thread`, `dst` with the rest) the clock after the
//! instruction leaves the result line; the result and condition select in between would leave
//! no room for their block-RAM and wake-up logic in the same clock. Only the floating-point
//! flags and results arrive in the clock of the choice; the opcode was decoded in the line.
//! Throughput: one instruction per clock.
//!
//! Golden twin: `hw::program::exec` (the engine's twin): the same result, condition and next
//! pc per opcode.

use rust_hdl::prelude::*;

use super::{ResultSource, RetiringIn};
use crate::hw::program::isa::{PC_BITS, REG_BITS};

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
    pub thread_mask: Signal<Out, Bits<32>>,
    pub dst: Signal<Out, Bits<REG_BITS>>,
    pub write: Signal<Out, Bit>,
    pub data: Signal<Out, Bits<32>>,
    pub next_pc: Signal<Out, Bits<PC_BITS>>,
    pub halt: Signal<Out, Bit>,
    pub retired: Signal<Out, Bit>,
    pub wait_pending: Signal<Out, Bit>,

    taken: Signal<Local, Bit>,
    result: Signal<Local, Bits<32>>,
    valid_r: DFF<Bit>,
    thread_r: DFF<Bits<5>>,
    /// The thread, one-hot, for the scheduler (see `Scheduler::wb_thread_mask`).
    thread_mask_r: DFF<Bits<32>>,
    dst_r: DFF<Bits<REG_BITS>>,
    write_r: DFF<Bit>,
    data_r: DFF<Bits<32>>,
    next_pc_r: DFF<Bits<PC_BITS>>,
    halt_r: DFF<Bit>,
    retired_r: DFF<Bit>,
    wait_pending_r: DFF<Bit>,
    c_one: Constant<Bits<32>>,
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
            thread_mask: Default::default(),
            dst: Default::default(),
            write: Default::default(),
            data: Default::default(),
            next_pc: Default::default(),
            halt: Default::default(),
            retired: Default::default(),
            wait_pending: Default::default(),
            taken: Default::default(),
            result: Default::default(),
            valid_r: Default::default(),
            thread_r: Default::default(),
            thread_mask_r: Default::default(),
            dst_r: Default::default(),
            write_r: Default::default(),
            data_r: Default::default(),
            next_pc_r: Default::default(),
            halt_r: Default::default(),
            retired_r: Default::default(),
            wait_pending_r: Default::default(),
            c_one: Constant::new(1u64.into()),
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
            thread_mask_r,
            dst_r,
            write_r,
            data_r,
            next_pc_r,
            halt_r,
            retired_r,
            wait_pending_r
        );
        self.taken.next = self.retiring.cond.val()
            | (self.retiring.sel_lt.val() & self.lt.val())
            | (self.retiring.sel_le.val() & self.le.val())
            | (self.retiring.sel_eq.val() & self.eq.val());
        self.next_pc_r.d.next = self.retiring.pc_not_taken.val();
        if self.taken.val() {
            self.next_pc_r.d.next = self.retiring.pc_taken.val();
        }

        self.result.next = self.retiring.fast.val();
        match self.retiring.source.val() {
            ResultSource::Fast => {}
            ResultSource::Sum => {
                self.result.next = bit_cast::<32, W>(self.sum.val());
            }
            ResultSource::Product => {
                self.result.next = bit_cast::<32, W>(self.product.val());
            }
            ResultSource::Quotient => {
                self.result.next = bit_cast::<32, W>(self.quotient.val());
            }
            ResultSource::Root => {
                self.result.next = bit_cast::<32, W>(self.root.val());
            }
            ResultSource::Byte => {
                self.result.next =
                    self.retiring.fast.val() | bit_cast::<32, 8>(self.colour_byte.val());
            }
        }

        self.valid_r.d.next = self.retiring.valid.val();
        self.thread_r.d.next = self.retiring.thread.val();
        self.thread_mask_r.d.next = self.c_one.val() << self.retiring.thread.val();
        self.dst_r.d.next = self.retiring.dst.val();
        self.data_r.d.next = self.result.val();
        self.write_r.d.next = self.retiring.write.val();
        self.halt_r.d.next = self.retiring.halt.val();
        self.retired_r.d.next = self.retiring.retired.val();
        self.wait_pending_r.d.next = self.retiring.wait_pending.val();

        self.valid.next = self.valid_r.q.val();
        self.thread.next = self.thread_r.q.val();
        self.thread_mask.next = self.thread_mask_r.q.val();
        self.dst.next = self.dst_r.q.val();
        self.write.next = self.write_r.q.val();
        self.data.next = self.data_r.q.val();
        self.next_pc.next = self.next_pc_r.q.val();
        self.halt.next = self.halt_r.q.val();
        self.retired.next = self.retired_r.q.val();
        self.wait_pending.next = self.wait_pending_r.q.val();
    }
}
