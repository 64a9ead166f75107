//! `FpSqrt`: pipelined `eXmY` square root, exactly rounded (nearest even), equal bit for bit
//! to its golden twin [`Format::sqrt`](crate::fp::Format::sqrt) (src/fp/arith.rs).
//!
//! Algorithm: radix-2 restoring square root, one root bit per pipeline stage. With the biased
//! exponent `e` and the significand `1.f`, the radicand is `1.f` when the unbiased exponent is
//! even (`e` odd, the bias being odd) and `2 * 1.f` otherwise, so it lies in [1, 4), its root in
//! [1, 2) and the result's biased exponent is `(e + bias) >> 1`. The radicand enters the
//! recurrence two bits at a time: with the partial root `q` and remainder `r`, each stage
//! brings down the next bit pair (`r' = 4r + pair`), tries `t = 4q + 1` and sets the next root
//! bit when `r' >= t` (then `r' - t` is kept), the integer form of `(q + 1/2)^2 <= x`. The first
//! root bit is always 1. `S + 1` root bits give the significand and the round bit; the final
//! remainder being nonzero is the sticky bit, so the rounding is exact.
//!
//! Latency `M + 5` clocks (e7m16: 21, e8m23: 28); throughput one
//! root per clock:
//! 1. input registers;
//! 2. unpack, special cases, exponent and the first root bit; registered;
//! 3. .. `S + 2`: the remaining `S` root bits, one per stage;
//! `S + 3`. round to nearest even; registered;
//! `S + 4`. special cases and pack; registered.
//!
//! No range checks are needed: the result exponent lies between a quarter and three quarters of
//! the exponent range, so it never overflows or flushes; and rounding never carries out of the
//! significand, since the largest radicand `4 - 2^(1-M)` has a root below `2 - 2^-(M+1)`, i.e.
//! below the half-way point under 2.
//!
//! Special cases (IEEE, with the flush-to-zero contract): sqrt(+-0) = +-0 (a subnormal operand
//! reads as a zero of its sign), sqrt(+inf) = +inf, and a NaN or any negative nonzero operand
//! (including -inf) gives the canonical NaN.
//!
//! Const parameters, in the order of the other operators (derived widths, checked in
//! `default()`; no `X2`: the exponent arithmetic fits `E` bits): `W = 1+E+M` word, `E` exponent
//! bits, `M` mantissa bits, `S = M+1` significand, `S1 = S+1` radicand, `T = M+5` partial
//! remainder, partial root and radicand bits to come (the remainder needs `S+3` bits).

use rust_hdl::prelude::*;

use super::{bias, const_bits, const_index, inf_word, qnan_word};

/// Latency of [`FpSqrt`] in clocks for a format with `man_bits` stored mantissa bits (one
/// root bit a stage: [`super::div::div_latency`] makes two quotient bits a stage).
pub const fn sqrt_latency(man_bits: u32) -> u32 {
    man_bits + 5
}

#[derive(LogicBlock)]
pub struct FpSqrt<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const T: usize,
> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    pub a: Signal<In, Bits<W>>,
    pub out_valid: Signal<Out, Bit>,
    pub result: Signal<Out, Bits<W>>,
    // Stage 1: input registers.
    in_a: DFF<Bits<W>>,
    in_valid_r: DFF<Bit>,
    // Unpack (combinational).
    exp_a: Signal<Local, Bits<E>>,
    sign_a: Signal<Local, Bit>,
    zero_a: Signal<Local, Bit>,
    inf_a: Signal<Local, Bit>,
    nan_a: Signal<Local, Bit>,
    sig_a: Signal<Local, Bits<S1>>,
    radicand: Signal<Local, Bits<S1>>,
    exp_half: Signal<Local, Bits<E>>,
    first_rem: Signal<Local, Bits<T>>,
    // Root stages: stage i holds the root and the remainder after bit i, and in `rest` the
    // radicand bits still to come (zeros below the radicand), the next pair at the top.
    rem: [DFF<Bits<T>>; S],
    root: [DFF<Bits<T>>; S],
    rest: [DFF<Bits<T>>; S],
    exp: [DFF<Bits<E>>; S],
    sign: [DFF<Bit>; S],
    nan: [DFF<Bit>; S],
    inf: [DFF<Bit>; S],
    zero: [DFF<Bit>; S],
    valid: [DFF<Bit>; S],
    // The last root stage, feeding rounding directly.
    last_rem: DFF<Bits<T>>,
    last_root: DFF<Bits<S>>,
    last_exp: DFF<Bits<E>>,
    last_sign: DFF<Bit>,
    last_nan: DFF<Bit>,
    last_inf: DFF<Bit>,
    last_zero: DFF<Bit>,
    last_valid: DFF<Bit>,
    // Round and pack (combinational).
    round_up: Signal<Local, Bit>,
    sign_word: Signal<Local, Bits<W>>,
    packed_word: Signal<Local, Bits<W>>,
    // Stage S + 3: rounded result registers.
    rnd_man: DFF<Bits<M>>,
    rnd_exp: DFF<Bits<E>>,
    rnd_sign: DFF<Bit>,
    rnd_nan: DFF<Bit>,
    rnd_inf: DFF<Bit>,
    rnd_zero: DFF<Bit>,
    rnd_valid: DFF<Bit>,
    // Output registers.
    out_result: DFF<Bits<W>>,
    out_valid_r: DFF<Bit>,
    // Format constants.
    c_man_bits: Constant<Bits<8>>,
    c_sign_pos: Constant<Bits<8>>,
    c_pair_pos: Constant<Bits<8>>,
    c_hidden: Constant<Bits<S1>>,
    c_half_bias: Constant<Bits<E>>,
    c_rest_shift: Constant<Bits<8>>,
    c_pair_shift: Constant<Bits<8>>,
    c_one: Constant<Bits<T>>,
    c_one_s: Constant<Bits<S>>,
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
        const T: usize,
    > Default for FpSqrt<W, E, M, S, S1, T>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && T == M + 5);
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            a: Default::default(),
            out_valid: Default::default(),
            result: Default::default(),
            in_a: Default::default(),
            in_valid_r: Default::default(),
            exp_a: Default::default(),
            sign_a: Default::default(),
            zero_a: Default::default(),
            inf_a: Default::default(),
            nan_a: Default::default(),
            sig_a: Default::default(),
            radicand: Default::default(),
            exp_half: Default::default(),
            first_rem: Default::default(),
            rem: std::array::from_fn(|_| Default::default()),
            root: std::array::from_fn(|_| Default::default()),
            rest: std::array::from_fn(|_| Default::default()),
            exp: std::array::from_fn(|_| Default::default()),
            sign: std::array::from_fn(|_| Default::default()),
            nan: std::array::from_fn(|_| Default::default()),
            inf: std::array::from_fn(|_| Default::default()),
            zero: std::array::from_fn(|_| Default::default()),
            valid: std::array::from_fn(|_| Default::default()),
            last_rem: Default::default(),
            last_root: Default::default(),
            last_exp: Default::default(),
            last_sign: Default::default(),
            last_nan: Default::default(),
            last_inf: Default::default(),
            last_zero: Default::default(),
            last_valid: Default::default(),
            round_up: Default::default(),
            sign_word: Default::default(),
            packed_word: Default::default(),
            rnd_man: Default::default(),
            rnd_exp: Default::default(),
            rnd_sign: Default::default(),
            rnd_nan: Default::default(),
            rnd_inf: Default::default(),
            rnd_zero: Default::default(),
            rnd_valid: Default::default(),
            out_result: Default::default(),
            out_valid_r: Default::default(),
            c_man_bits: const_index(M),
            c_sign_pos: const_index(W - 1),
            c_pair_pos: const_index(S - 1),
            c_hidden: const_bits::<S1>(1 << M),
            c_half_bias: const_bits::<E>(bias(E) >> 1),
            // Puts radicand bit S - 2 (the top of the second pair) at bit T - 1.
            c_rest_shift: const_index(T - 1 - (S - 2)),
            c_pair_shift: const_index(T - 2),
            c_one: const_bits::<T>(1),
            c_one_s: const_bits::<S>(1),
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
        const T: usize,
    > Logic for FpSqrt<W, E, M, S, S1, T>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            in_a,
            in_valid_r,
            last_rem,
            last_root,
            last_exp,
            last_sign,
            last_nan,
            last_inf,
            last_zero,
            last_valid,
            rnd_man,
            rnd_exp,
            rnd_sign,
            rnd_nan,
            rnd_inf,
            rnd_zero,
            rnd_valid,
            out_result,
            out_valid_r
        );
        for i in 0..S {
            self.rem[i].clock.next = self.clock.val();
            self.root[i].clock.next = self.clock.val();
            self.rest[i].clock.next = self.clock.val();
            self.exp[i].clock.next = self.clock.val();
            self.sign[i].clock.next = self.clock.val();
            self.nan[i].clock.next = self.clock.val();
            self.inf[i].clock.next = self.clock.val();
            self.zero[i].clock.next = self.clock.val();
            self.valid[i].clock.next = self.clock.val();
        }
        // Stage 1.
        self.in_a.d.next = self.a.val();
        self.in_valid_r.d.next = self.in_valid.val();

        // Unpack; a zero exponent field is a zero of the operand's sign (DAZ).
        self.exp_a.next = self
            .in_a
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index());
        self.sign_a.next = self.in_a.q.val().get_bit(self.c_sign_pos.val().index());
        self.zero_a.next = self.exp_a.val() == 0;
        self.inf_a.next = (self.exp_a.val().all()) & (self.in_a.q.val().get_bits::<M>(0) == 0);
        self.nan_a.next = (self.exp_a.val().all()) & (self.in_a.q.val().get_bits::<M>(0).any());
        self.sig_a.next =
            bit_cast::<S1, M>(self.in_a.q.val().get_bits::<M>(0)) | self.c_hidden.val();
        // The bias is odd: an even biased exponent is an odd power of two, folded into the
        // radicand so the exponent halves exactly.
        self.radicand.next = self.sig_a.val() << 1;
        if self.exp_a.val().get_bit(0) {
            self.radicand.next = self.sig_a.val();
        }
        // (e + bias) >> 1 without a carry out, the bias being odd.
        self.exp_half.next =
            ((self.exp_a.val() >> 1) + self.c_half_bias.val()) + self.exp_a.val().get_bit(0);
        // The top bit pair is 01, 10 or 11, so the first root bit is 1 and its trial value 1.
        self.first_rem.next = bit_cast::<T, 2>(
            self.radicand
                .val()
                .get_bits::<2>(self.c_pair_pos.val().index()),
        ) - self.c_one.val();

        // Stage 2: root bit 0 (always 1) and the flags.
        self.rem[0].d.next = self.first_rem.val();
        self.root[0].d.next = self.c_one.val();
        self.rest[0].d.next = bit_cast::<T, S1>(self.radicand.val()) << self.c_rest_shift.val();
        self.exp[0].d.next = self.exp_half.val();
        self.sign[0].d.next = self.sign_a.val();
        self.nan[0].d.next = self.nan_a.val() | (self.sign_a.val() & (!self.zero_a.val()));
        self.inf[0].d.next = self.inf_a.val();
        self.zero[0].d.next = self.zero_a.val();
        self.valid[0].d.next = self.in_valid_r.q.val();

        // Stages 3 ..= S + 1: one root bit each. The next bit pair is brought down (wiring
        // only: the remainder's two low bits are zero after the shift) and the trial value for
        // root q is 4q + 1. (No casts in the loops: rust-hdl evaluates a cast's width outside
        // the unrolled loop, so the root and the radicand bits are kept at the remainder's
        // width.)
        for i in 1..S {
            if ((self.rem[i - 1].q.val() << 2)
                | (self.rest[i - 1].q.val() >> self.c_pair_shift.val()))
                >= ((self.root[i - 1].q.val() << 2) | self.c_one.val())
            {
                self.rem[i].d.next = ((self.rem[i - 1].q.val() << 2)
                    | (self.rest[i - 1].q.val() >> self.c_pair_shift.val()))
                    - ((self.root[i - 1].q.val() << 2) | self.c_one.val());
                self.root[i].d.next = (self.root[i - 1].q.val() << 1) | self.c_one.val();
            } else {
                self.rem[i].d.next = (self.rem[i - 1].q.val() << 2)
                    | (self.rest[i - 1].q.val() >> self.c_pair_shift.val());
                self.root[i].d.next = self.root[i - 1].q.val() << 1;
            }
            self.rest[i].d.next = self.rest[i - 1].q.val() << 2;
            self.exp[i].d.next = self.exp[i - 1].q.val();
            self.sign[i].d.next = self.sign[i - 1].q.val();
            self.nan[i].d.next = self.nan[i - 1].q.val();
            self.inf[i].d.next = self.inf[i - 1].q.val();
            self.zero[i].d.next = self.zero[i - 1].q.val();
            self.valid[i].d.next = self.valid[i - 1].q.val();
        }
        // Stage S + 2: the round bit; the remainder is kept for the sticky bit. The root's top
        // bit (the hidden 1) is shifted out. (A one-pass loop because rust-hdl evaluates array
        // indices only from loop variables.)
        for i in (S - 1)..S {
            if ((self.rem[i].q.val() << 2) | (self.rest[i].q.val() >> self.c_pair_shift.val()))
                >= ((self.root[i].q.val() << 2) | self.c_one.val())
            {
                self.last_rem.d.next = ((self.rem[i].q.val() << 2)
                    | (self.rest[i].q.val() >> self.c_pair_shift.val()))
                    - ((self.root[i].q.val() << 2) | self.c_one.val());
                self.last_root.d.next =
                    (self.root[i].q.val().get_bits::<S>(0) << 1) | self.c_one_s.val();
            } else {
                self.last_rem.d.next =
                    (self.rem[i].q.val() << 2) | (self.rest[i].q.val() >> self.c_pair_shift.val());
                self.last_root.d.next = self.root[i].q.val().get_bits::<S>(0) << 1;
            }
            self.last_exp.d.next = self.exp[i].q.val();
            self.last_sign.d.next = self.sign[i].q.val();
            self.last_nan.d.next = self.nan[i].q.val();
            self.last_inf.d.next = self.inf[i].q.val();
            self.last_zero.d.next = self.zero[i].q.val();
            self.last_valid.d.next = self.valid[i].q.val();
        }

        // Round: root bits M..1 are the stored mantissa, bit 0 the round bit. The increment
        // never carries out (see the module comment).
        self.round_up.next = self.last_root.q.val().get_bit(0)
            & ((self.last_rem.q.val().any()) | self.last_root.q.val().get_bit(1));
        self.rnd_man.d.next = self.last_root.q.val().get_bits::<M>(1) + self.round_up.val();
        self.rnd_exp.d.next = self.last_exp.q.val();
        self.rnd_sign.d.next = self.last_sign.q.val();
        self.rnd_nan.d.next = self.last_nan.q.val();
        self.rnd_inf.d.next = self.last_inf.q.val();
        self.rnd_zero.d.next = self.last_zero.q.val();
        self.rnd_valid.d.next = self.last_valid.q.val();

        self.sign_word.next = 0.into();
        if self.rnd_sign.q.val() {
            self.sign_word.next = self.c_sign_bit.val();
        }
        self.packed_word.next = (bit_cast::<W, E>(self.rnd_exp.q.val()) << self.c_man_bits.val())
            | bit_cast::<W, M>(self.rnd_man.q.val());

        // Output stage.
        if self.rnd_nan.q.val() {
            self.out_result.d.next = self.c_qnan.val();
        } else if self.rnd_inf.q.val() {
            self.out_result.d.next = self.c_inf.val();
        } else if self.rnd_zero.q.val() {
            self.out_result.d.next = self.sign_word.val();
        } else {
            self.out_result.d.next = self.packed_word.val();
        }
        self.out_valid_r.d.next = self.rnd_valid.q.val();
        self.result.next = self.out_result.q.val();
        self.out_valid.next = self.out_valid_r.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::{vectors, Format};
    use crate::hw::fp::test_harness::{assert_matches_model, run_pipelined};

    fn check<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const T: usize,
    >(
        f: Format,
        seed: u64,
        n: usize,
    ) {
        println!("seed {seed}");
        let mut v = vectors::random_pairs(f, seed, n);
        v.extend(vectors::edge_cases(f).into_iter().map(|a| (a, 0)));
        let got = run_pipelined(
            FpSqrt::<W, E, M, S, S1, T>::default(),
            &v,
            sqrt_latency(M as u32) as usize,
            |u, c| u.clock.next = Clock { clk: c },
            |u, valid, a, _| {
                u.in_valid.next = valid;
                u.a.next = (a as u64).into();
            },
            |u| (u.out_valid.val(), u.result.val().to_u64() as u32),
        );
        assert_matches_model(&format!("sqrt {f}"), &v, &got, |a, _| f.sqrt(a));
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e5m10() {
        check::<16, 5, 10, 11, 12, 15>(Format::E5M10, 311, 300);
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        check::<24, 7, 16, 17, 18, 21>(Format::E7M16, 312, 200);
    }

    /// The module comment's claim that rounding never carries out of the significand, checked
    /// on the model for every format: the largest radicand (odd unbiased exponent, all-ones
    /// mantissa) has an all-ones root mantissa, and its exponent is the radicand's halved.
    #[test]
    fn largest_radicand_does_not_round_up_to_two() {
        for f in crate::hw::fp::supported_formats() {
            let b = bias(f.exp_bits as usize) as u32;
            // Biased exponent even = unbiased odd: the radicand is 2 * 1.11..1.
            let e = b + 1;
            let a = (e << f.man_bits) | f.man_mask();
            let r = f.sqrt(a);
            assert_eq!(r & f.man_mask(), f.man_mask(), "{f}: sqrt({a:#x}) = {r:#x}");
            assert_eq!(f.exp_field(r), (e + b) >> 1, "{f}: sqrt({a:#x}) = {r:#x}");
        }
    }
}
