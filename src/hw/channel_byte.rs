//! `ChannelByte`: a colour channel's byte for the frame buffer, the engine's `byte`
//! instruction. Golden twin: [`units::channel_byte`] (src/units.rs; equal to
//! `Format::to_u8`), bit for bit: the word is clamped to [0, 1] on its bits
//! ([`units::clamp_unit_word`]: sign, zero, subnormal or NaN give +0; above the encoding of 1
//! gives 1), multiplied by 255 in an [`FpMul`] and rounded to an integer by adding `2^M` in an
//! [`FpAddSub`] ([`units::channel_byte_word`]); the sum's low 8 bits are the byte.
//!
//! The clamp is applied after the multiplier, not before it: the word itself is multiplied,
//! and the clamp's decision (+0 or 1) travels beside the multiplier to replace the product
//! by +0 or by 255 (which is 1 x 255, exactly). The same bytes, but the word's compares no
//! longer sit between the engine's operand register and the multiplier's input registers
//! (`fp_units.a -> byte_unit.scale.in_a`, the processor's critical path at 80.8 MHz: issue
//! 16).
//!
//! [`units::channel_byte`]: crate::units::channel_byte
//! [`units::clamp_unit_word`]: crate::units::clamp_unit_word
//! [`units::channel_byte_word`]: crate::units::channel_byte_word
//!
//! Latency [`CHANNEL_BYTE_LATENCY`] (12) from `in_valid` to `out_valid`, one word per clock;
//! the clamp's decision is registered as the word enters the multiplier.

use rust_hdl::prelude::*;

use super::fp::add_sub::ADD_SUB_LATENCY;
use super::fp::mul::MUL_LATENCY;
use super::fp::{const_bits, FpAddSub, FpMul};
use super::Delay;
use crate::fp::Format;

/// Clocks from `in_valid` to `out_valid`.
pub const CHANNEL_BYTE_LATENCY: u32 = MUL_LATENCY + ADD_SUB_LATENCY;

#[derive(LogicBlock)]
pub struct ChannelByte<
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
    pub in_valid: Signal<In, Bit>,
    pub word: Signal<In, Bits<W>>,
    pub out_valid: Signal<Out, Bit>,
    /// The byte (`byte` is a SystemVerilog keyword).
    pub result: Signal<Out, Bits<8>>,
    /// The clamp's decision: bit 0 the word gives +0, bit 1 it gives 1.
    clamp: Signal<Local, Bits<2>>,
    clamp_line: Delay<Bits<2>, { MUL_LATENCY as usize }>,
    scale: FpMul<W, E, M, S, S1, X2, P>,
    round: FpAddSub<W, E, M, S, S1, X2, T>,
    /// The sign bit, the exponent field's mask, 1.0, 255.0 and `2^M` (the rounding addend).
    c_sign: Constant<Bits<W>>,
    c_exp_mask: Constant<Bits<W>>,
    c_man_mask: Constant<Bits<W>>,
    c_one: Constant<Bits<W>>,
    c_255: Constant<Bits<W>>,
    c_round: Constant<Bits<W>>,
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
    > Default for ChannelByte<W, E, M, S, S1, X2, T, P>
{
    fn default() -> Self {
        assert!(
            W == 1 + E + M && M >= 8,
            "ChannelByte: the byte needs M >= 8"
        );
        let f = Format::new(E as u32, M as u32).expect("ChannelByte: a supported format");
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            word: Default::default(),
            out_valid: Default::default(),
            result: Default::default(),
            clamp: Default::default(),
            clamp_line: Default::default(),
            scale: Default::default(),
            round: Default::default(),
            c_sign: const_bits::<W>(1 << (W - 1)),
            c_exp_mask: const_bits::<W>(((1 << E) - 1) << M),
            c_man_mask: const_bits::<W>((1 << M) - 1),
            c_one: const_bits::<W>(f.one().into()),
            c_255: const_bits::<W>(f.from_int(255).into()),
            c_round: const_bits::<W>(f.from_int(1 << M).into()),
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
    > Logic for ChannelByte<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        self.scale.clock.next = self.clock.val();
        self.round.clock.next = self.clock.val();
        self.clamp_line.clock.next = self.clock.val();
        // Negative, zero or subnormal (exponent field 0), NaN: +0. Positive non-NaN words
        // compare as unsigned integers.
        if ((self.word.val() & self.c_sign.val()) != 0)
            | ((self.word.val() & self.c_exp_mask.val()) == 0)
            | (((self.word.val() & self.c_exp_mask.val()) == self.c_exp_mask.val())
                & ((self.word.val() & self.c_man_mask.val()) != 0))
        {
            self.clamp.next = 1.into();
        } else if self.word.val() > self.c_one.val() {
            self.clamp.next = 2.into();
        } else {
            self.clamp.next = 0.into();
        }
        self.clamp_line.data_in.next = self.clamp.val();
        self.scale.in_valid.next = self.in_valid.val();
        self.scale.a.next = self.word.val();
        self.scale.b.next = self.c_255.val();
        self.round.in_valid.next = self.scale.out_valid.val();
        self.round.a.next = self.scale.result.val();
        if self.clamp_line.data_out.val().get_bit(0) {
            self.round.a.next = 0.into();
        } else if self.clamp_line.data_out.val().get_bit(1) {
            self.round.a.next = self.c_255.val();
        }
        self.round.b.next = self.c_round.val();
        self.round.sub.next = false;
        self.out_valid.next = self.round.out_valid.val();
        self.result.next = self.round.result.val().get_bits::<8>(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::fp::test_harness::{assert_matches_model, run_pipelined};
    use crate::units;
    use rand::{Rng, SeedableRng};

    fn check<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    >(
        f: Format,
        seed: u64,
    ) {
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let one = f.one();
        // The clamp's edges with both signs, words in [0, 1] (every byte), and random words.
        let edges = [
            0,
            1,
            one - 1,
            one,
            one + 1,
            f.infinity(false),
            f.nan(),
            1 << M,
        ];
        let words: Vec<(u32, u32)> = edges
            .into_iter()
            .flat_map(|w| [w, w | 1 << (W - 1)])
            .chain((0..256).map(|k| f.from_f64((k as f64 + 0.5) / 255.0)))
            .chain((0..2000).map(|k| {
                if k % 4 == 0 {
                    rng.gen::<u32>() & f.word_mask()
                } else {
                    rng.gen_range(0..=one)
                }
            }))
            .map(|w| (w, 0))
            .collect();
        let got = run_pipelined(
            ChannelByte::<W, E, M, S, S1, X2, T, P>::default(),
            &words,
            CHANNEL_BYTE_LATENCY as usize,
            |u, c| u.clock.next = Clock { clk: c },
            |u, valid, w, _| {
                u.in_valid.next = valid;
                u.word.next = (w as u64).into();
            },
            |u| (u.out_valid.val(), u.result.val().to_u64() as u32),
        );
        assert_matches_model(&format!("byte {f}"), &words, &got, |w, _| {
            units::channel_byte(f, w)
        });
    }

    #[test]
    fn rust_hdl_simulation_matches_channel_byte() {
        check::<24, 7, 16, 17, 18, 9, 21, 34>(Format::E7M16, 61);
        check::<16, 5, 10, 11, 12, 7, 15, 22>(Format::parse("e5m10").unwrap(), 62);
    }
}
