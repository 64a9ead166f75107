//! The bundle between the engine's [`ResultLine`](super::ResultLine) and its [`WriteBack`](super::WriteBack).

use rust_hdl::prelude::*;

use super::ResultSource;
use crate::hw::program::isa::{PC_BITS, REG_BITS};

/// The instruction leaving the [`ResultLine`](super::ResultLine) for the
/// [`WriteBack`](super::WriteBack), decoded: whether and from which source it writes its
/// destination; its condition (`cond`, or the floating-point compare flag one of `sel_lt`,
/// `sel_le`, `sel_eq` names) and its next pc when the condition holds and when not; whether it
/// is `halt`, retires, or is a coprocessor wait not answered yet; its fast result.
#[derive(LogicInterface, Default)]
#[join = "RetiringIn"]
pub struct Retiring {
    pub valid: Signal<Out, Bit>,
    pub dst: Signal<Out, Bits<REG_BITS>>,
    pub thread: Signal<Out, Bits<5>>,
    pub write: Signal<Out, Bit>,
    pub source: Signal<Out, ResultSource>,
    pub cond: Signal<Out, Bit>,
    pub sel_lt: Signal<Out, Bit>,
    pub sel_le: Signal<Out, Bit>,
    pub sel_eq: Signal<Out, Bit>,
    pub pc_taken: Signal<Out, Bits<PC_BITS>>,
    pub pc_not_taken: Signal<Out, Bits<PC_BITS>>,
    pub halt: Signal<Out, Bit>,
    pub retired: Signal<Out, Bit>,
    pub wait_pending: Signal<Out, Bit>,
    pub fast: Signal<Out, Bits<32>>,
}

/// [`Retiring`] as the [`WriteBack`](super::WriteBack) takes it.
#[derive(LogicInterface, Default)]
#[join = "Retiring"]
pub struct RetiringIn {
    pub valid: Signal<In, Bit>,
    pub dst: Signal<In, Bits<REG_BITS>>,
    pub thread: Signal<In, Bits<5>>,
    pub write: Signal<In, Bit>,
    pub source: Signal<In, ResultSource>,
    pub cond: Signal<In, Bit>,
    pub sel_lt: Signal<In, Bit>,
    pub sel_le: Signal<In, Bit>,
    pub sel_eq: Signal<In, Bit>,
    pub pc_taken: Signal<In, Bits<PC_BITS>>,
    pub pc_not_taken: Signal<In, Bits<PC_BITS>>,
    pub halt: Signal<In, Bit>,
    pub retired: Signal<In, Bit>,
    pub wait_pending: Signal<In, Bit>,
    pub fast: Signal<In, Bits<32>>,
}
