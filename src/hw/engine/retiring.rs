//! The bundle between the engine's [`ResultLine`](super::ResultLine) and its [`WriteBack`](super::WriteBack).

use rust_hdl::prelude::*;

use crate::hw::program::isa::{OP_BITS, PC_BITS, REG_BITS};

/// The instruction leaving the [`ResultLine`](super::ResultLine) for the [`WriteBack`](super::WriteBack): its control fields,
/// `pc + 1` and the branch target, its conditions (a coprocessor wait; the traversal unit or
/// the triangle tester refused or has not finished; `jr`'s target; the integer compares; the
/// mailbox hit; the pixels exhausted) and its fast result.
#[derive(LogicInterface, Default)]
#[join = "RetiringIn"]
pub struct Retiring {
    pub valid: Signal<Out, Bit>,
    pub op: Signal<Out, Bits<OP_BITS>>,
    pub dst: Signal<Out, Bits<REG_BITS>>,
    pub thread: Signal<Out, Bits<5>>,
    pub invert: Signal<Out, Bit>,
    pub pc_plus_one: Signal<Out, Bits<PC_BITS>>,
    pub target: Signal<Out, Bits<PC_BITS>>,
    pub is_wait: Signal<Out, Bit>,
    pub kd_busy: Signal<Out, Bit>,
    pub tri_busy: Signal<Out, Bit>,
    pub jr_target: Signal<Out, Bits<PC_BITS>>,
    pub int_eq: Signal<Out, Bit>,
    pub int_lt: Signal<Out, Bit>,
    pub mb_hit: Signal<Out, Bit>,
    pub pix_done: Signal<Out, Bit>,
    pub fast: Signal<Out, Bits<32>>,
}

/// [`Retiring`] as the [`WriteBack`](super::WriteBack) takes it.
#[derive(LogicInterface, Default)]
#[join = "Retiring"]
pub struct RetiringIn {
    pub valid: Signal<In, Bit>,
    pub op: Signal<In, Bits<OP_BITS>>,
    pub dst: Signal<In, Bits<REG_BITS>>,
    pub thread: Signal<In, Bits<5>>,
    pub invert: Signal<In, Bit>,
    pub pc_plus_one: Signal<In, Bits<PC_BITS>>,
    pub target: Signal<In, Bits<PC_BITS>>,
    pub is_wait: Signal<In, Bit>,
    pub kd_busy: Signal<In, Bit>,
    pub tri_busy: Signal<In, Bit>,
    pub jr_target: Signal<In, Bits<PC_BITS>>,
    pub int_eq: Signal<In, Bit>,
    pub int_lt: Signal<In, Bit>,
    pub mb_hit: Signal<In, Bit>,
    pub pix_done: Signal<In, Bit>,
    pub fast: Signal<In, Bits<32>>,
}
