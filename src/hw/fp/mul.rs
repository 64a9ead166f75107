//! `FpMul`: pipelined `eXmY` multiplier, exactly rounded (nearest even), equal bit for bit to
//! its golden twin [`Format::mul`](crate::fp::Format::mul) (src/fp/arith.rs).
//!
//! Latency 4 clocks, throughput one product per clock:
//! 1. input registers;
//! 2. unpack, special cases (NaN, infinity, zero with DAZ), exponent sum, and the significand
//!    product from the [`SigMul`] leaf, registered;
//! 3. normalize (product in [1, 4)), round to nearest even on `S` bits with an unbounded
//!    exponent; registered;
//! 4. overflow to infinity / flush results below the smallest normal to a signed zero, pack;
//!    registered (the rounding of 3 and all of 4 are the shared [`FpRoundPack`]).
//!
//! Const parameters (derived widths, checked in `default()`): `W = 1+E+M` word, `E` exponent
//! bits, `M` mantissa bits, `S = M+1` significand, `S1 = S+1` rounded significand with carry,
//! `X2 = E+2` two's complement working exponent, `P = 2S` product.

use rust_hdl::prelude::*;

use super::round_pack::ROUND_PACK_LATENCY;
use super::{bias, const_bits, const_index, FpRoundPack, SigMul};

/// Latency of [`FpMul`] in clocks: input registers, the product, then rounding and packing.
pub const MUL_LATENCY: u32 = 2 + ROUND_PACK_LATENCY;

#[derive(LogicBlock)]
pub struct FpMul<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const P: usize,
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
    multiplier: SigMul<S, P>,
    // Stage 2 registers.
    prod: DFF<Bits<P>>,
    exp_sum: DFF<Bits<X2>>,
    sign: DFF<Bit>,
    nan: DFF<Bit>,
    inf: DFF<Bit>,
    zero: DFF<Bit>,
    valid2: DFF<Bit>,
    // Normalize, round, pack (combinational).
    prod_top: Signal<Local, Bit>,
    prod_norm: Signal<Local, Bits<P>>,
    sig: Signal<Local, Bits<S>>,
    round_bit: Signal<Local, Bit>,
    sticky: Signal<Local, Bit>,
    round_up: Signal<Local, Bit>,
    // Stages 3 and 4.
    pack: FpRoundPack<W, E, M, S, S1, X2>,
    // Format constants.
    c_man_bits: Constant<Bits<8>>,
    c_sign_pos: Constant<Bits<8>>,
    c_hidden: Constant<Bits<S>>,
    c_bias: Constant<Bits<X2>>,
    c_prod_top: Constant<Bits<8>>,
    c_sig_pos: Constant<Bits<8>>,
    c_round_pos: Constant<Bits<8>>,
    c_sticky_mask: Constant<Bits<P>>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const P: usize,
    > Default for FpMul<W, E, M, S, S1, X2, P>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && P == 2 * S);
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
            multiplier: Default::default(),
            prod: Default::default(),
            exp_sum: Default::default(),
            sign: Default::default(),
            nan: Default::default(),
            inf: Default::default(),
            zero: Default::default(),
            valid2: Default::default(),
            prod_top: Default::default(),
            prod_norm: Default::default(),
            sig: Default::default(),
            round_bit: Default::default(),
            sticky: Default::default(),
            round_up: Default::default(),
            pack: Default::default(),
            c_man_bits: const_index(M),
            c_sign_pos: const_index(W - 1),
            c_hidden: const_bits::<S>(1 << M),
            c_bias: const_bits::<X2>(bias(E)),
            c_prod_top: const_index(P - 1),
            c_sig_pos: const_index(S),
            c_round_pos: const_index(S - 1),
            c_sticky_mask: const_bits::<P>((1 << (S - 1)) - 1),
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
        const P: usize,
    > Logic for FpMul<W, E, M, S, S1, X2, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, in_a, in_b, in_valid_r, prod, exp_sum, sign, nan, inf, zero, valid2
        );
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
        self.multiplier.a.next =
            bit_cast::<S, M>(self.in_a.q.val().get_bits::<M>(0)) | self.c_hidden.val();
        self.multiplier.b.next =
            bit_cast::<S, M>(self.in_b.q.val().get_bits::<M>(0)) | self.c_hidden.val();

        // Stage 2.
        self.prod.d.next = self.multiplier.p.val();
        self.exp_sum.d.next = (bit_cast::<X2, E>(self.exp_a.val())
            + bit_cast::<X2, E>(self.exp_b.val()))
            - self.c_bias.val();
        self.sign.d.next = self.in_a.q.val().get_bit(self.c_sign_pos.val().index())
            ^ self.in_b.q.val().get_bit(self.c_sign_pos.val().index());
        self.nan.d.next = (self.nan_a.val() | self.nan_b.val())
            | ((self.zero_a.val() & self.inf_b.val()) | (self.inf_a.val() & self.zero_b.val()));
        self.inf.d.next = self.inf_a.val() | self.inf_b.val();
        self.zero.d.next = self.zero_a.val() | self.zero_b.val();
        self.valid2.d.next = self.in_valid_r.q.val();

        // Normalize the product (in [1, 4)) so that its leading one is the top bit.
        self.prod_top.next = self.prod.q.val().get_bit(self.c_prod_top.val().index());
        self.prod_norm.next = self.prod.q.val();
        if !self.prod_top.val() {
            self.prod_norm.next = self.prod.q.val() << 1;
        }
        self.sig.next = self
            .prod_norm
            .val()
            .get_bits::<S>(self.c_sig_pos.val().index());
        self.round_bit.next = self.prod_norm.val().get_bit(self.c_round_pos.val().index());
        self.sticky.next = (self.prod_norm.val() & self.c_sticky_mask.val()).any();
        self.round_up.next = self.round_bit.val() & (self.sticky.val() | self.sig.val().get_bit(0));
        // Stages 3 and 4: round and pack.
        self.pack.clock.next = self.clock.val();
        self.pack.in_valid.next = self.valid2.q.val();
        self.pack.sig.next = self.sig.val();
        self.pack.sig_ones.next = self.sig.val().all();
        self.pack.round_up.next = self.round_up.val();
        self.pack.exp.next = self.exp_sum.q.val() + self.prod_top.val();
        self.pack.sign.next = self.sign.q.val();
        self.pack.nan.next = self.nan.q.val();
        self.pack.inf.next = self.inf.q.val();
        self.pack.zero.next = self.zero.q.val();
        self.result.next = self.pack.result.val();
        self.out_valid.next = self.pack.out_valid.val();
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
        const X2: usize,
        const P: usize,
    >(
        f: Format,
        seed: u64,
        n: usize,
    ) {
        println!("seed {seed}");
        let v = vectors::random_pairs(f, seed, n);
        let got = run_pipelined(
            FpMul::<W, E, M, S, S1, X2, P>::default(),
            &v,
            MUL_LATENCY as usize,
            |u, c| u.clock.next = Clock { clk: c },
            |u, valid, a, b| {
                u.in_valid.next = valid;
                u.a.next = (a as u64).into();
                u.b.next = (b as u64).into();
            },
            |u| (u.out_valid.val(), u.result.val().to_u64() as u32),
        );
        assert_matches_model(&format!("mul {f}"), &v, &got, |a, b| f.mul(a, b));
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        check::<24, 7, 16, 17, 18, 9, 34>(Format::E7M16, 101, 400);
    }

    #[test]
    fn rust_hdl_simulation_matches_model_e8m23() {
        check::<32, 8, 23, 24, 25, 10, 48>(Format::E8M23, 102, 400);
    }
}
