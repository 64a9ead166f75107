//! `FpUnits`: the engine's floating-point units (add/sub, multiply, divide, square root,
//! compare, the colour-channel byte), fed every clock from I5, and the delays that bring each
//! result to the write back.
//!
//! Contract: operands `a`, `b` (and `sub` for `fsub`) given at I5 come out at the write back,
//! [`super::ENGINE_LATENCY`] clocks later: `sum`, `product`, the compare flags `lt`, `le`,
//! `eq`; `quotient`, `root` and `colour_byte` (`ChannelByte`) come
//! [`super::long_latency`]`(M)` clocks later, the clock the long line writes them back. Every
//! unit takes an input every clock whether the instruction uses it or not; the write back
//! picks the one its opcode names.
//!
//! Latency: `ENGINE_LATENCY` (9) clocks (`quotient`, `root`, `colour_byte`: `M + 6`).
//! Throughput: one
//! operation per clock.
//!
//! Golden twin: each operator's own (`Format::add`, `sub`, `mul`, `div`, `sqrt`, `lt`, `le`,
//! `eq` in `crate::fp::arith`, and `units::channel_byte`), as the engine's twin
//! (`hw::program::exec`) runs them for `fadd`, `fsub`, `fmul`, `fdiv`, `fsqrt`, the float
//! branches and `byte`.

use rust_hdl::prelude::*;

use super::ENGINE_LATENCY;
use crate::hw::fp::add_sub::ADD_SUB_LATENCY;
use crate::hw::fp::compare::COMPARE_LATENCY;
use crate::hw::fp::div::div_latency;
use crate::hw::fp::mul::MUL_LATENCY;
use crate::hw::fp::{FpAddSub, FpCompare, FpDiv, FpMul, FpSqrt};
use crate::hw::{ChannelByte, CHANNEL_BYTE_LATENCY};

/// Each delay brings its unit's result to the write back at `ENGINE_LATENCY`.
const ADD_DELAY: usize = (ENGINE_LATENCY - ADD_SUB_LATENCY) as usize;
const MUL_DELAY: usize = (ENGINE_LATENCY - MUL_LATENCY) as usize;
/// The comparator's operands wait a clock in registers of their own (`cmp_a`, `cmp_b`).
const CMP_DELAY: usize = (ENGINE_LATENCY - 1 - COMPARE_LATENCY) as usize;

#[derive(LogicBlock)]
pub struct FpUnits<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
> {
    pub clock: Signal<In, Clock>,
    /// I5: the operands; `sub`: the adder subtracts.
    pub a: Signal<In, Bits<W>>,
    pub b: Signal<In, Bits<W>>,
    pub sub: Signal<In, Bit>,
    /// Write back.
    pub sum: Signal<Out, Bits<W>>,
    pub product: Signal<Out, Bits<W>>,
    pub quotient: Signal<Out, Bits<W>>,
    pub root: Signal<Out, Bits<W>>,
    pub lt: Signal<Out, Bit>,
    pub le: Signal<Out, Bit>,
    pub eq: Signal<Out, Bit>,
    pub colour_byte: Signal<Out, Bits<8>>,

    add: FpAddSub<W, E, M, S, S1, X2, T>,
    mul: FpMul<W, E, M, S, S1, X2, P>,
    div: FpDiv<W, E, M, S, S1, X2>,
    sqrt: FpSqrt<W, E, M, S, S1, T>,
    cmp: FpCompare<W, E, M>,
    /// The comparator's own copy of the operands, a clock late: every unit's input registers
    /// hold the same words, so synthesis merges them into one set that fans out to all six
    /// units and shares their logic (the comparator's NaN tests with the square root's);
    /// placed and routed, that put 8.6-9.5 ns of routing on `operand -> cmp.out_le` (82.5 /
    /// 88.6 MHz at stop 36). Behind a register of its own the comparator's inputs are its
    /// alone. The comparator has 10 clocks of slack before the write back.
    cmp_a: DFF<Bits<W>>,
    cmp_b: DFF<Bits<W>>,
    byte_unit: ChannelByte<W, E, M, S, S1, X2, T, P>,
    // Each delay brings its unit's result to the write back at `ENGINE_LATENCY` (9): 9 - 8
    // for the adder, 9 - 4 for the multiplier, 9 - 1 - 2 for the comparator; the square root
    // (`M + 5`) writes back one clock later, at `long_latency`, the divider (`div_latency`)
    // and `ChannelByte` (12) as many later as that takes.
    add_delay: crate::hw::Delay<Bits<W>, ADD_DELAY>,
    mul_delay: crate::hw::Delay<Bits<W>, MUL_DELAY>,
    div_delay: crate::hw::DelayLine<Bits<W>>,
    sqrt_delay: crate::hw::Delay<Bits<W>, 1>,
    byte_delay: crate::hw::DelayLine<Bits<8>>,
    lt_delay: crate::hw::Delay<Bit, CMP_DELAY>,
    le_delay: crate::hw::Delay<Bit, CMP_DELAY>,
    eq_delay: crate::hw::Delay<Bit, CMP_DELAY>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > Default for FpUnits<W, E, M, S, S1, X2, T, P>
{
    fn default() -> Self {
        Self {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            sub: Default::default(),
            sum: Default::default(),
            product: Default::default(),
            quotient: Default::default(),
            root: Default::default(),
            lt: Default::default(),
            le: Default::default(),
            eq: Default::default(),
            colour_byte: Default::default(),
            add: Default::default(),
            mul: Default::default(),
            div: Default::default(),
            sqrt: Default::default(),
            cmp: Default::default(),
            cmp_a: Default::default(),
            cmp_b: Default::default(),
            byte_unit: Default::default(),
            add_delay: Default::default(),
            mul_delay: Default::default(),
            div_delay: crate::hw::DelayLine::new(
                (super::long_latency(M as u32) - div_latency(M as u32)) as usize,
            ),
            byte_delay: crate::hw::DelayLine::new(
                (super::long_latency(M as u32) - CHANNEL_BYTE_LATENCY) as usize,
            ),
            sqrt_delay: Default::default(),
            lt_delay: Default::default(),
            le_delay: Default::default(),
            eq_delay: Default::default(),
        }
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > Logic for FpUnits<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        clock!(
            self, clock, add, mul, div, sqrt, cmp, cmp_a, cmp_b, byte_unit, add_delay, mul_delay,
            div_delay, sqrt_delay, byte_delay, lt_delay, le_delay, eq_delay
        );
        self.add.a.next = self.a.val();
        self.add.b.next = self.b.val();
        self.add.sub.next = self.sub.val();
        self.add.in_valid.next = true;
        self.mul.a.next = self.a.val();
        self.mul.b.next = self.b.val();
        self.mul.in_valid.next = true;
        self.div.a.next = self.a.val();
        self.div.b.next = self.b.val();
        self.div.in_valid.next = true;
        self.sqrt.a.next = self.a.val();
        self.sqrt.in_valid.next = true;
        self.cmp_a.d.next = self.a.val();
        self.cmp_b.d.next = self.b.val();
        self.cmp.a.next = self.cmp_a.q.val();
        self.cmp.b.next = self.cmp_b.q.val();
        self.cmp.in_valid.next = true;
        self.byte_unit.word.next = self.a.val();
        self.byte_unit.in_valid.next = true;

        self.add_delay.data_in.next = self.add.result.val();
        self.mul_delay.data_in.next = self.mul.result.val();
        self.div_delay.data_in.next = self.div.result.val();
        self.sqrt_delay.data_in.next = self.sqrt.result.val();
        self.lt_delay.data_in.next = self.cmp.lt.val();
        self.le_delay.data_in.next = self.cmp.le.val();
        self.eq_delay.data_in.next = self.cmp.eq.val();
        self.sum.next = self.add_delay.data_out.val();
        self.product.next = self.mul_delay.data_out.val();
        self.quotient.next = self.div_delay.data_out.val();
        self.root.next = self.sqrt_delay.data_out.val();
        self.lt.next = self.lt_delay.data_out.val();
        self.le.next = self.le_delay.data_out.val();
        self.eq.next = self.eq_delay.data_out.val();
        self.byte_delay.data_in.next = self.byte_unit.result.val();
        self.colour_byte.next = self.byte_delay.data_out.val();
    }
}
