//! Port bundles shared by the processor's blocks: one definition of each kind of port, so that a
//! port renamed or widened in one block is a compile error in every block that meets it.
//!
//! Directions are those of the block that *drives* the request (the master); a block that
//! passes a child's port through to its own links the two (`SramRead::link`).

use rust_hdl::prelude::*;

use crate::layout::{self, BANKS};

/// The banks on the engine's shared memory bus (lists, instances, frame), as a mask of
/// [`CoprocessorPort::load_banks`]: the others have their coprocessor's own port.
pub const SHARED_BUS_BANKS: u64 =
    (1 << layout::LISTS) | (1 << layout::INSTANCES) | (1 << layout::FRAME);

/// A read port of an SRAM bank: a request (`read`, `addr`) per clock; `rdata` is the word
/// requested exactly `mem_latency` clocks earlier (the board's SRAMs, or a testbench's).
#[derive(LogicInterface, Default)]
pub struct SramRead {
    pub read: Signal<Out, Bit>,
    pub addr: Signal<Out, Bits<24>>,
    pub rdata: Signal<In, Bits<32>>,
}

/// A read port shared by several banks: [`SramRead`] with the bank number (`layout`'s bank
/// numbers) beside the address.
#[derive(LogicInterface, Default)]
pub struct BankedSramRead {
    pub read: Signal<Out, Bit>,
    pub bank: Signal<Out, Bits<3>>,
    pub addr: Signal<Out, Bits<24>>,
    pub rdata: Signal<In, Bits<32>>,
}

/// The frame-buffer write port: one word per clock while `write` is set.
#[derive(LogicInterface, Default)]
pub struct FrameBufferWrite {
    pub write: Signal<Out, Bit>,
    pub addr: Signal<Out, Bits<24>>,
    pub data: Signal<Out, Bits<32>>,
}

/// The engine's side of a coprocessor (the traversal unit, the triangle tester), seen from the
/// coprocessor: at I5 the engine writes a ray word pair (`ray_write`, `ray_pair`: which pair,
/// `word_a`, `word_b`) or offers an entry (`enqueue`) for `thread`; `full` refuses the entry
/// (the thread repeats it). At I4 the engine asks whether `query_thread`'s work is `pending`
/// (a wait). `done` and `done_thread` report a finished piece of work, which wakes a sleeping
/// waiter. `load_*` is the engine's registered load request (a load of the coprocessor's bank
/// goes out on the coprocessor's own port, in the clocks the coprocessor leaves free):
/// `load_banks` bit k is high in the clock the engine loads bank k, one flip-flop a bank, so
/// that a coprocessor yields its port on one flip-flop's output rather than on a decode of
/// the bank number (that decode, fanned out to every port, was the processor's critical path
/// at 89.3 MHz).
#[derive(LogicInterface, Default)]
pub struct CoprocessorPort {
    pub thread: Signal<In, Bits<5>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub ray_write: Signal<In, Bit>,
    pub ray_pair: Signal<In, Bits<2>>,
    pub enqueue: Signal<In, Bit>,
    pub full: Signal<Out, Bit>,
    pub query_thread: Signal<In, Bits<5>>,
    pub pending: Signal<Out, Bit>,
    pub done: Signal<Out, Bit>,
    pub done_thread: Signal<Out, Bits<5>>,
    pub load_banks: Signal<In, Bits<BANKS>>,
    pub load_addr: Signal<In, Bits<24>>,
}

/// The display's ports: its pixel clock and reset, its read port on the frame-buffer bank
/// (one clock of latency) and the monitor's signals.
#[derive(LogicInterface, Default)]
pub struct VgaPort {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, Bit>,
    pub fb_addr: Signal<Out, Bits<24>>,
    pub fb_data: Signal<In, Bits<32>>,
    pub hsync: Signal<Out, Bit>,
    pub vsync: Signal<Out, Bit>,
    pub rgb: Signal<Out, Bits<24>>,
    pub frame_start: Signal<Out, Bit>,
}
