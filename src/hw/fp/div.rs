//! `FpDiv`: pipelined `eXmY` divider, exactly rounded (nearest even), equal bit for bit to its
//! golden twin [`Format::div`](crate::fp::Format::div) (src/fp/arith.rs).
//!
//! Algorithm: restoring division, two quotient bits per pipeline stage. The dividend
//! significand is doubled when it is smaller than the divisor's, so the quotient lies in [1, 2)
//! and its first bit is always 1. `S + 1` quotient bits give the significand and the round bit
//! (for an odd `S` the stages make one bit more, which joins the sticky bit); the final partial
//! remainder being nonzero is the sticky bit, so the rounding is exact. A stage takes the
//! doubled remainder `x` (below `2d` for the divisor `d`) and decides both bits at once from
//! three comparisons side by side, `x >= d`, `2x >= 3d` and `2x >= d` (with `3d` formed once
//! per division): the first bit is `x >= d`, the second `2(x - d) >= d` or `2x >= d` after it.
//! One carry chain and a four-way select deep, where two restoring steps in a row would be two
//! chains; the latency halves (e7m16: 21 -> 13 clocks), and with it the traversal unit's node
//! decision and the intersection's latency, which a thread waits for.
//!
//! Latency `ceil(S / 2) + 4` clocks (e7m16: 13, e8m23: 16), throughput one quotient per clock:
//! 1. input registers;
//! 2. unpack, special cases, exponent difference, `3d` and the first quotient bit; registered;
//! 3. .. `ceil(S / 2) + 1`: two quotient bits each;
//! `ceil(S / 2) + 2`: the last two, the round bit and the sticky bit; registered;
//! `ceil(S / 2) + 3`. round to nearest even; registered;
//! `ceil(S / 2) + 4`. overflow to infinity / flush below the smallest normal to a signed zero,
//!    pack; registered (these two stages are the shared [`FpRoundPack`]).
//!
//! Special cases (IEEE): 0/0 and inf/inf are NaN, finite nonzero / 0 is a signed infinity,
//! x/inf is a signed zero; the sign is the xor of the operand signs.
//!
//! Const parameters (derived widths, checked in `default()`): `W = 1+E+M` word, `E` exponent
//! bits, `M` mantissa bits, `S = M+1` significand, `S1 = S+1` partial remainder and rounded
//! significand, `X2 = E+2` two's complement working exponent. The stages hold the remainder,
//! quotient, divisor and `3d` in `W` bits (`W >= S + 4`; the bits above each one's width are
//! constant zeros, which synthesis removes).

use rust_hdl::prelude::*;

use super::round_pack::ROUND_PACK_LATENCY;
use super::{bias, const_bits, const_index, FpRoundPack};

/// Quotient stages of a format with `man_bits` stored mantissa bits: the first bit's, then
/// two bits each for the other `S = man_bits + 1` (the last of them also making the sticky
/// bit).
const fn quotient_stages(man_bits: u32) -> u32 {
    1 + (man_bits + 2) / 2
}

/// Latency of [`FpDiv`] in clocks for a format with `man_bits` stored mantissa bits: input
/// registers, the quotient stages, then rounding and packing.
pub const fn div_latency(man_bits: u32) -> u32 {
    1 + quotient_stages(man_bits) + ROUND_PACK_LATENCY
}

#[derive(LogicBlock)]
pub struct FpDiv<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    pub a: Signal<In, Bits<W>>,
    pub b: Signal<In, Bits<W>>,
    pub out_valid: Signal<Out, Bit>,
    pub result: Signal<Out, Bits<W>>,
    // Stage 1: input registers.
    in_a: DFF<Bits<W>>,
    in_b: DFF<Bits<W>>,
    in_valid_r: DFF<Bit>,
    // Unpack (combinational).
    exp_a: Signal<Local, Bits<E>>,
    exp_b: Signal<Local, Bits<E>>,
    zero_a: Signal<Local, Bit>,
    zero_b: Signal<Local, Bit>,
    inf_a: Signal<Local, Bit>,
    inf_b: Signal<Local, Bit>,
    nan_a: Signal<Local, Bit>,
    nan_b: Signal<Local, Bit>,
    sig_a: Signal<Local, Bits<S1>>,
    sig_b: Signal<Local, Bits<S1>>,
    a_below_b: Signal<Local, Bit>,
    // The first remainder for either dividend, formed beside the compare that picks one.
    rem_first: Signal<Local, Bits<S1>>,
    rem_first_doubled: Signal<Local, Bits<S1>>,
    // Quotient stages (`ceil(S / 2)` of them; rust-hdl sizes a `Vec` at construction, which an
    // array of a length computed from `S` cannot be): stage i holds the remainder after its
    // bits, already doubled.
    rem: Vec<DFF<Bits<W>>>,
    quo: Vec<DFF<Bits<W>>>,
    divisor: Vec<DFF<Bits<W>>>,
    divisor3: Vec<DFF<Bits<W>>>,
    exp: Vec<DFF<Bits<X2>>>,
    sign: Vec<DFF<Bit>>,
    nan: Vec<DFF<Bit>>,
    inf: Vec<DFF<Bit>>,
    zero: Vec<DFF<Bit>>,
    valid: Vec<DFF<Bit>>,
    // The last quotient stage, feeding rounding directly: its quotient bits (with the extra
    // one of an odd `S`) and whether its remainder is nonzero, decided beside the
    // comparisons. Only the sticky bit is kept: the round decision then starts from registers,
    // not behind an `S1`-wide zero test (`last_rem -> pack`, 81.9 MHz on the ECP5: issue 16).
    last_full: Signal<Local, Bits<W>>,
    last_rest: Signal<Local, Bit>,
    last_sticky: DFF<Bit>,
    last_quo: DFF<Bits<S1>>,
    /// The significand is all ones, known before the round's register: its `S`-wide AND in
    /// front of the rounding carry left the round's exponent select 9-10 ns of routing
    /// (`div.last_quo -> div.pack.rnd_exp`, 88.2 MHz in cornell's processor on the ECP5).
    last_sig_ones: DFF<Bit>,
    last_exp: DFF<Bits<X2>>,
    last_sign: DFF<Bit>,
    last_nan: DFF<Bit>,
    last_inf: DFF<Bit>,
    last_zero: DFF<Bit>,
    last_valid: DFF<Bit>,
    // The round decision (combinational).
    sig: Signal<Local, Bits<S>>,
    round_up: Signal<Local, Bit>,
    // The last two stages.
    pack: FpRoundPack<W, E, M, S, S1, X2>,
    // Format constants.
    c_man_bits: Constant<Bits<8>>,
    c_sign_pos: Constant<Bits<8>>,
    c_hidden: Constant<Bits<S1>>,
    c_bias: Constant<Bits<X2>>,
    c_bias_less_one: Constant<Bits<X2>>,
    c_one: Constant<Bits<W>>,
    c_two: Constant<Bits<W>>,
    c_three: Constant<Bits<W>>,
    /// Quotient bits past the round bit (1 for an odd `S`), the significand's place above
    /// them and the round bit, and their mask.
    c_extra: Constant<Bits<8>>,
    c_extra_sig: Constant<Bits<8>>,
    c_extra_mask: Constant<Bits<W>>,
    c_rem_mask: Constant<Bits<W>>,
    /// `3d < 2^(S + 2)`: the mask tells synthesis the bits above are zero.
    c_d3_mask: Constant<Bits<W>>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
    > Default for FpDiv<W, E, M, S, S1, X2>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && W >= S + 4);
        // Stage 2 and the two-bit stages before the last.
        let stages = quotient_stages(M as u32) as usize - 1;
        let extra = 2 * stages + 1 - (S + 1);
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            a: Default::default(),
            b: Default::default(),
            out_valid: Default::default(),
            result: Default::default(),
            in_a: Default::default(),
            in_b: Default::default(),
            in_valid_r: Default::default(),
            exp_a: Default::default(),
            exp_b: Default::default(),
            zero_a: Default::default(),
            zero_b: Default::default(),
            inf_a: Default::default(),
            inf_b: Default::default(),
            nan_a: Default::default(),
            nan_b: Default::default(),
            sig_a: Default::default(),
            sig_b: Default::default(),
            a_below_b: Default::default(),
            rem_first: Default::default(),
            rem_first_doubled: Default::default(),
            rem: (0..stages).map(|_| Default::default()).collect(),
            quo: (0..stages).map(|_| Default::default()).collect(),
            divisor: (0..stages).map(|_| Default::default()).collect(),
            divisor3: (0..stages).map(|_| Default::default()).collect(),
            exp: (0..stages).map(|_| Default::default()).collect(),
            sign: (0..stages).map(|_| Default::default()).collect(),
            nan: (0..stages).map(|_| Default::default()).collect(),
            inf: (0..stages).map(|_| Default::default()).collect(),
            zero: (0..stages).map(|_| Default::default()).collect(),
            valid: (0..stages).map(|_| Default::default()).collect(),
            last_full: Default::default(),
            last_rest: Default::default(),
            last_sticky: Default::default(),
            last_quo: Default::default(),
            last_sig_ones: Default::default(),
            last_exp: Default::default(),
            last_sign: Default::default(),
            last_nan: Default::default(),
            last_inf: Default::default(),
            last_zero: Default::default(),
            last_valid: Default::default(),
            sig: Default::default(),
            round_up: Default::default(),
            pack: Default::default(),
            c_man_bits: const_index(M),
            c_sign_pos: const_index(W - 1),
            c_hidden: const_bits::<S1>(1 << M),
            c_bias: const_bits::<X2>(bias(E)),
            c_bias_less_one: const_bits::<X2>(bias(E) - 1),
            c_one: const_bits::<W>(1),
            c_two: const_bits::<W>(2),
            c_three: const_bits::<W>(3),
            c_extra: const_index(extra),
            c_extra_sig: const_index(extra + 1),
            c_extra_mask: const_bits::<W>((1 << extra) - 1),
            c_rem_mask: const_bits::<W>((1 << S1) - 1),
            c_d3_mask: const_bits::<W>((1 << (S + 2)) - 1),
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
    > Logic for FpDiv<W, E, M, S, S1, X2>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            in_a,
            in_b,
            in_valid_r,
            last_sticky,
            last_quo,
            last_sig_ones,
            last_exp,
            last_sign,
            last_nan,
            last_inf,
            last_zero,
            last_valid
        );
        for i in 0..self.rem.len() {
            self.rem[i].clock.next = self.clock.val();
            self.quo[i].clock.next = self.clock.val();
            self.divisor[i].clock.next = self.clock.val();
            self.divisor3[i].clock.next = self.clock.val();
            self.exp[i].clock.next = self.clock.val();
            self.sign[i].clock.next = self.clock.val();
            self.nan[i].clock.next = self.clock.val();
            self.inf[i].clock.next = self.clock.val();
            self.zero[i].clock.next = self.clock.val();
            self.valid[i].clock.next = self.clock.val();
        }
        // Stage 1.
        self.in_a.d.next = self.a.val();
        self.in_b.d.next = self.b.val();
        self.in_valid_r.d.next = self.in_valid.val();

        // Unpack; a zero exponent field is zero (DAZ).
        self.exp_a.next = self
            .in_a
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index());
        self.exp_b.next = self
            .in_b
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index());
        self.zero_a.next = self.exp_a.val() == 0;
        self.zero_b.next = self.exp_b.val() == 0;
        self.inf_a.next = (self.exp_a.val().all()) & (self.in_a.q.val().get_bits::<M>(0) == 0);
        self.inf_b.next = (self.exp_b.val().all()) & (self.in_b.q.val().get_bits::<M>(0) == 0);
        self.nan_a.next = (self.exp_a.val().all()) & (self.in_a.q.val().get_bits::<M>(0).any());
        self.nan_b.next = (self.exp_b.val().all()) & (self.in_b.q.val().get_bits::<M>(0).any());
        self.sig_a.next =
            bit_cast::<S1, M>(self.in_a.q.val().get_bits::<M>(0)) | self.c_hidden.val();
        self.sig_b.next =
            bit_cast::<S1, M>(self.in_b.q.val().get_bits::<M>(0)) | self.c_hidden.val();
        // Doubling a smaller dividend puts the quotient in [1, 2): its first bit is 1. Both
        // first remainders are formed beside the compare (the compare's carry chain in front
        // of the subtraction's was the unit's critical path, 28 carries: issue 16).
        self.a_below_b.next = self.sig_a.val() < self.sig_b.val();
        self.rem_first.next = self.sig_a.val() - self.sig_b.val();
        self.rem_first_doubled.next = (self.sig_a.val() << 1) - self.sig_b.val();

        // Stage 2: quotient bit 0 (always 1), `3d` and the flags.
        self.rem[0].d.next = bit_cast::<W, S1>(self.rem_first.val() << 1);
        if self.a_below_b.val() {
            self.rem[0].d.next = bit_cast::<W, S1>(self.rem_first_doubled.val() << 1);
        }
        self.quo[0].d.next = self.c_one.val();
        self.divisor[0].d.next = bit_cast::<W, S1>(self.sig_b.val());
        self.divisor3[0].d.next = (bit_cast::<W, S1>(self.sig_b.val())
            + (bit_cast::<W, S1>(self.sig_b.val()) << 1))
            & self.c_d3_mask.val();
        self.exp[0].d.next = (bit_cast::<X2, E>(self.exp_a.val())
            - bit_cast::<X2, E>(self.exp_b.val()))
            + self.c_bias.val();
        if self.a_below_b.val() {
            self.exp[0].d.next = (bit_cast::<X2, E>(self.exp_a.val())
                - bit_cast::<X2, E>(self.exp_b.val()))
                + self.c_bias_less_one.val();
        }
        self.sign[0].d.next = self.in_a.q.val().get_bit(self.c_sign_pos.val().index())
            ^ self.in_b.q.val().get_bit(self.c_sign_pos.val().index());
        self.nan[0].d.next = (self.nan_a.val() | self.nan_b.val())
            | ((self.zero_a.val() & self.zero_b.val()) | (self.inf_a.val() & self.inf_b.val()));
        self.inf[0].d.next = self.inf_a.val() | self.zero_b.val();
        self.zero[0].d.next = self.zero_a.val() | self.inf_b.val();
        self.valid[0].d.next = self.in_valid_r.q.val();

        // Two quotient bits a stage, from the doubled remainder x: `x >= d` (then the next
        // remainder is `2(x - d)`, whose bit is `2x >= 3d`), else `2x >= d`. The new doubled
        // remainder stays below `2d`: its bits above `S1` are masked off as the constant zeros
        // they are (`2x` and `3d` need `W` bits; rust-hdl casts no array element in a loop).
        // Each comparison is its difference's sign bit (the operands are below `2^(W-1)`; a
        // shift, since Verilog selects no bit of an expression), so
        // a stage has three subtractors and no comparator of its own: comparisons beside them
        // made the divider 1,813 LUTs in yosys xc2v, 1,004 with one bit a stage.
        for i in 1..self.rem.len() {
            if !((self.rem[i - 1].q.val() - self.divisor[i - 1].q.val()) >> self.c_sign_pos.val())
                .any()
            {
                if !(((self.rem[i - 1].q.val() << 1) - self.divisor3[i - 1].q.val())
                    >> self.c_sign_pos.val())
                .any()
                {
                    self.rem[i].d.next =
                        (((self.rem[i - 1].q.val() << 1) - self.divisor3[i - 1].q.val()) << 1)
                            & self.c_rem_mask.val();
                    self.quo[i].d.next = (self.quo[i - 1].q.val() << 2) | self.c_three.val();
                } else {
                    self.rem[i].d.next = ((self.rem[i - 1].q.val() - self.divisor[i - 1].q.val())
                        << 2)
                        & self.c_rem_mask.val();
                    self.quo[i].d.next = (self.quo[i - 1].q.val() << 2) | self.c_two.val();
                }
            } else if !(((self.rem[i - 1].q.val() << 1) - self.divisor[i - 1].q.val())
                >> self.c_sign_pos.val())
            .any()
            {
                self.rem[i].d.next =
                    (((self.rem[i - 1].q.val() << 1) - self.divisor[i - 1].q.val()) << 1)
                        & self.c_rem_mask.val();
                self.quo[i].d.next = (self.quo[i - 1].q.val() << 2) | self.c_one.val();
            } else {
                self.rem[i].d.next = (self.rem[i - 1].q.val() << 2) & self.c_rem_mask.val();
                self.quo[i].d.next = self.quo[i - 1].q.val() << 2;
            }
            self.divisor[i].d.next = self.divisor[i - 1].q.val();
            self.divisor3[i].d.next = self.divisor3[i - 1].q.val();
            self.exp[i].d.next = self.exp[i - 1].q.val();
            self.sign[i].d.next = self.sign[i - 1].q.val();
            self.nan[i].d.next = self.nan[i - 1].q.val();
            self.inf[i].d.next = self.inf[i - 1].q.val();
            self.zero[i].d.next = self.zero[i - 1].q.val();
            self.valid[i].d.next = self.valid[i - 1].q.val();
        }
        // The last stage: its two bits as above, and whether the remainder after them is
        // nonzero, each case's from its own comparison (equality with what it subtracts). (A
        // one-pass loop because rust-hdl evaluates array indices only from loop variables.)
        for i in (self.rem.len() - 1)..self.rem.len() {
            if !((self.rem[i].q.val() - self.divisor[i].q.val()) >> self.c_sign_pos.val()).any() {
                if !(((self.rem[i].q.val() << 1) - self.divisor3[i].q.val())
                    >> self.c_sign_pos.val())
                .any()
                {
                    self.last_full.next = (self.quo[i].q.val() << 2) | self.c_three.val();
                    self.last_rest.next = (self.rem[i].q.val() << 1) != self.divisor3[i].q.val();
                } else {
                    self.last_full.next = (self.quo[i].q.val() << 2) | self.c_two.val();
                    self.last_rest.next = self.rem[i].q.val() != self.divisor[i].q.val();
                }
            } else if !(((self.rem[i].q.val() << 1) - self.divisor[i].q.val())
                >> self.c_sign_pos.val())
            .any()
            {
                self.last_full.next = (self.quo[i].q.val() << 2) | self.c_one.val();
                self.last_rest.next = (self.rem[i].q.val() << 1) != self.divisor[i].q.val();
            } else {
                self.last_full.next = self.quo[i].q.val() << 2;
                self.last_rest.next = self.rem[i].q.val().any();
            }
            self.last_exp.d.next = self.exp[i].q.val();
            self.last_sign.d.next = self.sign[i].q.val();
            self.last_nan.d.next = self.nan[i].q.val();
            self.last_inf.d.next = self.inf[i].q.val();
            self.last_zero.d.next = self.zero[i].q.val();
            self.last_valid.d.next = self.valid[i].q.val();
        }
        // Significand and round bit above the extra bit, which is sticky.
        self.last_quo.d.next = self
            .last_full
            .val()
            .get_bits::<S1>(self.c_extra.val().index());
        self.last_sig_ones.d.next = self
            .last_full
            .val()
            .get_bits::<S>(self.c_extra_sig.val().index())
            .all();
        self.last_sticky.d.next =
            self.last_rest.val() | (self.last_full.val() & self.c_extra_mask.val()).any();

        // Round: quotient bits S..1 are the significand, bit 0 the round bit.
        self.sig.next = self.last_quo.q.val().get_bits::<S>(1);
        self.round_up.next = self.last_quo.q.val().get_bit(0)
            & (self.last_sticky.q.val() | self.sig.val().get_bit(0));
        // The last two stages.
        self.pack.clock.next = self.clock.val();
        self.pack.in_valid.next = self.last_valid.q.val();
        self.pack.sig.next = self.sig.val();
        self.pack.sig_ones.next = self.last_sig_ones.q.val();
        self.pack.round_up.next = self.round_up.val();
        self.pack.exp.next = self.last_exp.q.val();
        self.pack.sign.next = self.last_sign.q.val();
        self.pack.nan.next = self.last_nan.q.val();
        self.pack.inf.next = self.last_inf.q.val();
        self.pack.zero.next = self.last_zero.q.val();
        self.result.next = self.pack.result.val();
        self.out_valid.next = self.pack.out_valid.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::{vectors, Format};
    use crate::hw::fp::test_harness::{assert_matches_model, run_pipelined};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn check<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
    >(
        f: Format,
        v: &[(u32, u32)],
    ) {
        let got = run_pipelined(
            FpDiv::<W, E, M, S, S1, X2>::default(),
            v,
            div_latency(M as u32) as usize,
            |u, c| u.clock.next = Clock { clk: c },
            |u, valid, a, b| {
                u.in_valid.next = valid;
                u.a.next = (a as u64).into();
                u.b.next = (b as u64).into();
            },
            |u| (u.out_valid.val(), u.result.val().to_u64() as u32),
        );
        assert_matches_model(&format!("div {f}"), v, &got, |a, b| f.div(a, b));
    }

    /// Divisions whose quotient is exact (the final remainder zero): by powers of two, and
    /// multiples of 3 by 1.5, with random signs and exponents near the bias. Each of the last
    /// stage's four cases then has a zero remainder to tell from a nonzero one, and an odd `S`
    /// an extra quotient bit of 0.
    fn exact_quotients(f: Format, seed: u64, n: usize) -> Vec<(u32, u32)> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let bias = (1u32 << (f.exp_bits - 1)) - 1;
        let word = |sign: bool, exp: u32, man: u32| {
            (u32::from(sign) << (f.exp_bits + f.man_bits)) | (exp << f.man_bits) | man
        };
        (0..n)
            .map(|k| {
                let exp = |rng: &mut ChaCha8Rng| bias - 3 + rng.gen_range(0..7);
                let b_man = if k % 2 == 0 { 0 } else { 1 << (f.man_bits - 1) };
                // 3x for a significand x of M - 1 fraction bits has M + 1 bits and its low
                // two zero: x 2^M = 2^M + 4q.
                let a_man = if k % 2 == 0 {
                    rng.gen::<u32>() & f.man_mask()
                } else {
                    let q = rng.gen::<u32>() & (f.man_mask() >> 2);
                    let prod = 3 * ((1 << f.man_bits) + 4 * q);
                    // In [3 * 2^M, 3 * 2^(M+1)): normalized to [2^(M+1), 2^(M+2)) over 2.
                    if prod >> (f.man_bits + 2) == 0 {
                        (prod >> 1) & f.man_mask()
                    } else {
                        (prod >> 2) & f.man_mask()
                    }
                };
                let a = word(rng.gen(), exp(&mut rng), a_man);
                let b = word(rng.gen(), exp(&mut rng), b_man);
                assert_eq!(f.mul(f.div(a, b), b), a, "not exact: {a:#x} / {b:#x}");
                (a, b)
            })
            .collect()
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e5m10() {
        check::<16, 5, 10, 11, 12, 7>(
            Format::E5M10,
            &vectors::random_pairs(Format::E5M10, 301, 600),
        );
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        check::<24, 7, 16, 17, 18, 9>(
            Format::E7M16,
            &vectors::random_pairs(Format::E7M16, 302, 600),
        );
    }

    /// An even `S` (24): the stages make exactly the significand and round bits.
    #[test]
    fn rust_hdl_simulation_matches_model_e8m23() {
        check::<32, 8, 23, 24, 25, 10>(
            Format::E8M23,
            &vectors::random_pairs(Format::E8M23, 303, 600),
        );
    }

    #[test]
    fn exact_quotients_have_no_sticky_bit() {
        check::<16, 5, 10, 11, 12, 7>(Format::E5M10, &exact_quotients(Format::E5M10, 304, 200));
        check::<24, 7, 16, 17, 18, 9>(Format::E7M16, &exact_quotients(Format::E7M16, 305, 200));
        check::<32, 8, 23, 24, 25, 10>(Format::E8M23, &exact_quotients(Format::E8M23, 306, 200));
    }
}
