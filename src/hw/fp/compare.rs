//! `FpCompare`: pipelined IEEE comparison (`lt`, `le`, `eq`) of two `eXmY` words.
//!
//! Contract (same as `dynrt::fp`): subnormal inputs are read as zeros of their sign
//! (DAZ), `-0 == +0`, and every comparison involving a NaN is false. Golden twin:
//! [`Format::lt`], [`Format::le`], [`Format::eq`] (src/fp/arith.rs), bit for bit.
//!
//! [`Format::lt`]: crate::fp::Format::lt
//! [`Format::le`]: crate::fp::Format::le
//! [`Format::eq`]: crate::fp::Format::eq
//!
//! Latency 2 clocks, throughput one comparison per clock: stage 1 registers the inputs,
//! stage 2 registers the three results. `out_valid` is `in_valid` delayed by 2. The
//! magnitude comparators read the registered words directly; the DAZ zero tests run beside
//! them and only steer their results (clearing a zero operand before comparing put the zero
//! test in front of the carry chain: `in_b.q -> out_lt.q` at 128 MHz on the ECP5, issue 16).
//! The latency stays 2 because the triangle tester's hit merge reads, compares and writes a
//! thread's best hit in 4 clocks (entries closer together take the state from the one ahead).
//!
//! Const parameters: `W = 1 + E + M` (word width), `E` exponent bits, `M` stored mantissa bits.

use rust_hdl::prelude::*;

use super::{const_bits, const_index};

/// Latency of [`FpCompare`] in clocks.
pub const COMPARE_LATENCY: u32 = 2;

#[derive(LogicBlock)]
pub struct FpCompare<const W: usize, const E: usize, const M: usize> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    pub a: Signal<In, Bits<W>>,
    pub b: Signal<In, Bits<W>>,
    pub out_valid: Signal<Out, Bit>,
    pub lt: Signal<Out, Bit>,
    pub le: Signal<Out, Bit>,
    pub eq: Signal<Out, Bit>,
    // Stage 1: input registers.
    in_a: DFF<Bits<W>>,
    in_b: DFF<Bits<W>>,
    in_valid_r: DFF<Bit>,
    // Combinational compare between stage 1 and 2.
    a_zero: Signal<Local, Bit>,
    b_zero: Signal<Local, Bit>,
    a_mag: Signal<Local, Bits<W>>,
    b_mag: Signal<Local, Bits<W>>,
    a_neg: Signal<Local, Bit>,
    b_neg: Signal<Local, Bit>,
    any_nan: Signal<Local, Bit>,
    raw_eq: Signal<Local, Bit>,
    mag_lt_ab: Signal<Local, Bit>,
    mag_lt_ba: Signal<Local, Bit>,
    clean_lt_ab: Signal<Local, Bit>,
    clean_lt_ba: Signal<Local, Bit>,
    is_eq: Signal<Local, Bit>,
    is_lt: Signal<Local, Bit>,
    // Stage 2: output registers.
    out_lt: DFF<Bit>,
    out_le: DFF<Bit>,
    out_eq: DFF<Bit>,
    out_valid_r: DFF<Bit>,
    // Format constants.
    c_man_bits: Constant<Bits<8>>,
    c_sign_pos: Constant<Bits<8>>,
    c_mag_mask: Constant<Bits<W>>,
}

impl<const W: usize, const E: usize, const M: usize> Default for FpCompare<W, E, M> {
    fn default() -> Self {
        assert_eq!(W, 1 + E + M, "FpCompare: W must be 1 + E + M");
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            a: Default::default(),
            b: Default::default(),
            out_valid: Default::default(),
            lt: Default::default(),
            le: Default::default(),
            eq: Default::default(),
            in_a: Default::default(),
            in_b: Default::default(),
            in_valid_r: Default::default(),
            a_zero: Default::default(),
            b_zero: Default::default(),
            a_mag: Default::default(),
            b_mag: Default::default(),
            a_neg: Default::default(),
            b_neg: Default::default(),
            any_nan: Default::default(),
            raw_eq: Default::default(),
            mag_lt_ab: Default::default(),
            mag_lt_ba: Default::default(),
            clean_lt_ab: Default::default(),
            clean_lt_ba: Default::default(),
            is_eq: Default::default(),
            is_lt: Default::default(),
            out_lt: Default::default(),
            out_le: Default::default(),
            out_eq: Default::default(),
            out_valid_r: Default::default(),
            c_man_bits: const_index(M),
            c_sign_pos: const_index(W - 1),
            c_mag_mask: const_bits::<W>((1u64 << (W - 1)) - 1),
        }
    }
}

impl<const W: usize, const E: usize, const M: usize> Logic for FpCompare<W, E, M> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            in_a,
            in_b,
            in_valid_r,
            out_lt,
            out_le,
            out_eq,
            out_valid_r
        );
        self.in_a.d.next = self.a.val();
        self.in_b.d.next = self.b.val();
        self.in_valid_r.d.next = self.in_valid.val();

        // DAZ: a zero exponent field means zero, and zero compares without its sign. A word
        // read as zero compares as the all-zero word; any other word has a nonzero exponent
        // field, so its magnitude is above zero. The raw comparisons below are therefore
        // those of the cleared words except where a zero is involved, which the zero flags
        // decide.
        self.a_zero.next = self
            .in_a
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index())
            == 0;
        self.b_zero.next = self
            .in_b
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index())
            == 0;
        self.a_mag.next = self.in_a.q.val() & self.c_mag_mask.val();
        self.b_mag.next = self.in_b.q.val() & self.c_mag_mask.val();
        self.a_neg.next =
            self.in_a.q.val().get_bit(self.c_sign_pos.val().index()) & !self.a_zero.val();
        self.b_neg.next =
            self.in_b.q.val().get_bit(self.c_sign_pos.val().index()) & !self.b_zero.val();
        // A NaN has the exponent field all ones and a nonzero mantissa.
        self.any_nan.next = ((self
            .in_a
            .q
            .val()
            .get_bits::<E>(self.c_man_bits.val().index()))
        .all()
            & (self.in_a.q.val().get_bits::<M>(0).any()))
            | ((self
                .in_b
                .q
                .val()
                .get_bits::<E>(self.c_man_bits.val().index()))
            .all()
                & (self.in_b.q.val().get_bits::<M>(0).any()));
        self.raw_eq.next = self.in_a.q.val() == self.in_b.q.val();
        self.mag_lt_ab.next = self.a_mag.val() < self.b_mag.val();
        self.mag_lt_ba.next = self.b_mag.val() < self.a_mag.val();
        // Cleared words: equal when both are zero, unequal when one is, else the raw words.
        self.is_eq.next = self.raw_eq.val();
        if self.a_zero.val() | self.b_zero.val() {
            self.is_eq.next = self.a_zero.val() & self.b_zero.val();
        }
        // |a| < |b| of the cleared words: 0 < |b| when only a is zero, false when b is.
        self.clean_lt_ab.next = self.mag_lt_ab.val();
        self.clean_lt_ba.next = self.mag_lt_ba.val();
        if self.a_zero.val() | self.b_zero.val() {
            self.clean_lt_ab.next = !self.b_zero.val();
            self.clean_lt_ba.next = !self.a_zero.val();
        }
        if self.a_neg.val() ^ self.b_neg.val() {
            self.is_lt.next = self.a_neg.val();
        } else if self.a_neg.val() {
            self.is_lt.next = self.clean_lt_ba.val();
        } else {
            self.is_lt.next = self.clean_lt_ab.val();
        }

        self.out_eq.d.next = self.is_eq.val() & !self.any_nan.val();
        self.out_lt.d.next = self.is_lt.val() & !self.any_nan.val();
        self.out_le.d.next = (self.is_lt.val() | self.is_eq.val()) & !self.any_nan.val();
        self.out_valid_r.d.next = self.in_valid_r.q.val();
        self.lt.next = self.out_lt.q.val();
        self.le.next = self.out_le.q.val();
        self.eq.next = self.out_eq.q.val();
        self.out_valid.next = self.out_valid_r.q.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::{vectors, Format};
    use crate::hw::fp::test_harness::{assert_matches_model, run_pipelined};

    fn check<const W: usize, const E: usize, const M: usize>(f: Format, seed: u64, n: usize) {
        println!("seed {seed}");
        let v = vectors::random_pairs(f, seed, n);
        // The three results packed as bits lt, le, eq.
        let got = run_pipelined(
            FpCompare::<W, E, M>::default(),
            &v,
            COMPARE_LATENCY as usize,
            |u, c| u.clock.next = Clock { clk: c },
            |u, valid, a, b| {
                u.in_valid.next = valid;
                u.a.next = (a as u64).into();
                u.b.next = (b as u64).into();
            },
            |u| {
                let bits =
                    u32::from(u.lt.val()) << 2 | u32::from(u.le.val()) << 1 | u32::from(u.eq.val());
                (u.out_valid.val(), bits)
            },
        );
        assert_matches_model(&format!("compare {f}"), &v, &got, |a, b| {
            u32::from(f.lt(a, b)) << 2 | u32::from(f.le(a, b)) << 1 | u32::from(f.eq(a, b))
        });
    }

    #[test]
    fn rust_hdl_simulation_matches_model() {
        check::<24, 7, 16>(Format::E7M16, 401, 500);
        check::<32, 8, 23>(Format::E8M23, 402, 500);
    }
}
