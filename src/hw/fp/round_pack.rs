//! `FpRoundPack`: the last two stages of [`super::FpMul`] and [`super::FpDiv`], which round a
//! significand to nearest even and pack the word.
//!
//! Contract: the parent drives the truncated significand `sig` (hidden bit at `M`), whether it
//! is all ones (`sig_ones`: the parent may know it a clock ahead), whether it rounds up
//! (`round_up`: round bit and (sticky or lsb), decided by the parent), the biased
//! exponent `exp` in `X2`-bit two's complement (unbounded: it may be negative or beyond the
//! largest), the sign and the special-case flags `nan`, `inf`, `zero` (exclusive of a normal
//! result, `nan` first). `result` is the packed word: the canonical NaN; a signed infinity for
//! `inf` or an exponent past the largest after rounding; a signed zero for `zero` or an exponent
//! below 1 after rounding (FTZ, tininess after rounding); else the rounded number.
//!
//! Golden twin: `Format::round_pack` (src/fp/format.rs), the single rounding step of every
//! software operation.
//!
//! Latency 2 clocks (round and its carry into the exponent, registered; range check and pack,
//! registered), throughput one word per clock. The carry into the exponent is read off the
//! significand (all ones and rounding up) beside the rounding increment, not from its carry
//! out: the exponent's add no longer waits for the increment's carry chain (`prod.q ->
//! exp_negative`, 125.6 MHz on the ECP5 in `FpMul`: issue 16), and the carry selects the
//! incremented exponent rather than feeding an add.
//!
//! Const parameters as the parent's: `W = 1+E+M`, `S = M+1`, `S1 = S+1`, `X2 = E+2`.

use rust_hdl::prelude::*;

use super::{const_bits, const_index, inf_word, qnan_word};

/// Clocks from the inputs to `result`.
pub const ROUND_PACK_LATENCY: u32 = 2;

#[derive(LogicBlock)]
pub struct FpRoundPack<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    pub sig: Signal<In, Bits<S>>,
    pub sig_ones: Signal<In, Bit>,
    pub round_up: Signal<In, Bit>,
    pub exp: Signal<In, Bits<X2>>,
    pub sign: Signal<In, Bit>,
    pub nan: Signal<In, Bit>,
    pub inf: Signal<In, Bit>,
    pub zero: Signal<In, Bit>,
    pub out_valid: Signal<Out, Bit>,
    pub result: Signal<Out, Bits<W>>,
    // Round (combinational).
    sig_rounded: Signal<Local, Bits<S1>>,
    carry: Signal<Local, Bit>,
    exp_final: Signal<Local, Bits<X2>>,
    exp_up: Signal<Local, Bits<X2>>,
    // Rounded result registers.
    rnd_sig: DFF<Bits<S1>>,
    rnd_exp: DFF<Bits<X2>>,
    rnd_sign: DFF<Bit>,
    rnd_nan: DFF<Bit>,
    rnd_inf: DFF<Bit>,
    rnd_zero: DFF<Bit>,
    rnd_valid: DFF<Bit>,
    // Range check and pack (combinational).
    exp_negative: Signal<Local, Bit>,
    sign_word: Signal<Local, Bits<W>>,
    packed_word: Signal<Local, Bits<W>>,
    // Output registers.
    out_result: DFF<Bits<W>>,
    out_valid_r: DFF<Bit>,
    // Format constants.
    c_man_bits: Constant<Bits<8>>,
    c_exp_sign_pos: Constant<Bits<8>>,
    c_exp_max: Constant<Bits<X2>>,
    c_qnan: Constant<Bits<W>>,
    c_inf: Constant<Bits<W>>,
    c_sign_bit: Constant<Bits<W>>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
    > Default for FpRoundPack<W, E, M, S, S1, X2>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2);
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            sig: Default::default(),
            round_up: Default::default(),
            sig_ones: Default::default(),
            exp: Default::default(),
            sign: Default::default(),
            nan: Default::default(),
            inf: Default::default(),
            zero: Default::default(),
            out_valid: Default::default(),
            result: Default::default(),
            sig_rounded: Default::default(),
            carry: Default::default(),
            exp_final: Default::default(),
            exp_up: Default::default(),
            rnd_sig: Default::default(),
            rnd_exp: Default::default(),
            rnd_sign: Default::default(),
            rnd_nan: Default::default(),
            rnd_inf: Default::default(),
            rnd_zero: Default::default(),
            rnd_valid: Default::default(),
            exp_negative: Default::default(),
            sign_word: Default::default(),
            packed_word: Default::default(),
            out_result: Default::default(),
            out_valid_r: Default::default(),
            c_man_bits: const_index(M),
            c_exp_sign_pos: const_index(X2 - 1),
            c_exp_max: const_bits::<X2>((1 << E) - 1),
            c_qnan: const_bits::<W>(qnan_word(E, M)),
            c_inf: const_bits::<W>(inf_word(E, M)),
            c_sign_bit: const_bits::<W>(1 << (W - 1)),
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
    > Logic for FpRoundPack<W, E, M, S, S1, X2>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            rnd_sig,
            rnd_exp,
            rnd_sign,
            rnd_nan,
            rnd_inf,
            rnd_zero,
            rnd_valid,
            out_result,
            out_valid_r
        );
        // A carry out of rounding leaves the mantissa field zero and bumps the exponent. The
        // increment carries out exactly when the significand is all ones and rounds up: bit
        // `S` of `sig_rounded`, formed without the increment's chain.
        self.sig_rounded.next = bit_cast::<S1, S>(self.sig.val()) + self.round_up.val();
        self.carry.next = self.sig_ones.val() & self.round_up.val();
        // The exponent's increment starts at `exp`, and the carry only picks it: an add of the
        // carry put the increment's chain behind the rounding decision
        // (`div.last_sticky -> pack.rnd_exp`, the processor's critical path at 79.8 MHz).
        self.exp_up.next = self.exp.val() + 1;
        self.exp_final.next = self.exp.val();
        if self.carry.val() {
            self.exp_final.next = self.exp_up.val();
        }
        // Registered: the rounded significand and exponent (splits the logic depth).
        self.rnd_sig.d.next = self.sig_rounded.val();
        self.rnd_exp.d.next = self.exp_final.val();
        self.rnd_sign.d.next = self.sign.val();
        self.rnd_nan.d.next = self.nan.val();
        self.rnd_inf.d.next = self.inf.val();
        self.rnd_zero.d.next = self.zero.val();
        self.rnd_valid.d.next = self.in_valid.val();

        self.exp_negative.next = self
            .rnd_exp
            .q
            .val()
            .get_bit(self.c_exp_sign_pos.val().index());
        self.sign_word.next = 0.into();
        if self.rnd_sign.q.val() {
            self.sign_word.next = self.c_sign_bit.val();
        }
        self.packed_word.next = (bit_cast::<W, E>(self.rnd_exp.q.val().get_bits::<E>(0))
            << self.c_man_bits.val())
            | bit_cast::<W, M>(self.rnd_sig.q.val().get_bits::<M>(0));

        // Output stage.
        if self.rnd_nan.q.val() {
            self.out_result.d.next = self.c_qnan.val();
        } else if self.rnd_inf.q.val()
            | ((!self.exp_negative.val()) & (self.rnd_exp.q.val() >= self.c_exp_max.val()))
        {
            self.out_result.d.next = self.c_inf.val() | self.sign_word.val();
        } else if self.rnd_zero.q.val() | (self.exp_negative.val() | (self.rnd_exp.q.val() == 0)) {
            self.out_result.d.next = self.sign_word.val();
        } else {
            self.out_result.d.next = self.packed_word.val() | self.sign_word.val();
        }
        self.out_valid_r.d.next = self.rnd_valid.q.val();
        self.result.next = self.out_result.q.val();
        self.out_valid.next = self.out_valid_r.q.val();
    }
}
