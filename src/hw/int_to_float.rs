//! `UIntToFloat`: a 16-bit unsigned integer to an `eXmY` word, combinational, equal to
//! `Format::from_int` for every value below `2^(M+1)` (where the conversion is exact: all
//! 16-bit values for e7m16 and e8m23, values below 2048 for e5m10), which covers pixel
//! coordinates of every supported format at the paper's 1024x768.
//!
//! A four-level leading-zero shifter (8, 4, 2, 1) normalizes the value; the shift amounts give
//! the exponent, the bits below the leading one the mantissa. Zero gives +0.
//!
//! Latency 0 (combinational: the unit around it registers), throughput one value per clock.
//! Golden twin: [`Format::from_int`](crate::fp::Format::from_int) (src/fp/format.rs), which
//! the golden model's `units::primary_direction` calls for the pixel coordinates.

use rust_hdl::prelude::*;

use super::fp::{bias, const_bits, const_index};

#[derive(LogicBlock)]
pub struct UIntToFloat<const W: usize, const E: usize, const M: usize> {
    pub value: Signal<In, Bits<16>>,
    pub word: Signal<Out, Bits<W>>,
    /// The value shifted left by 8, 4, 2, 1 where its top bits are zero.
    norm: [Signal<Local, Bits<16>>; 5],
    /// `bias + 15` minus the shifts so far.
    exp: [Signal<Local, Bits<E>>; 5],
    fraction: Signal<Local, Bits<32>>,
    c_shift: [Constant<Bits<8>>; 4],
    c_shift_e: [Constant<Bits<E>>; 4],
    c_top_mask: [Constant<Bits<16>>; 4],
    c_exp_top: Constant<Bits<E>>,
    c_man_bits: Constant<Bits<8>>,
    c_fraction_pos: Constant<Bits<8>>,
    c_fraction_shift: Constant<Bits<8>>,
}

impl<const W: usize, const E: usize, const M: usize> Default for UIntToFloat<W, E, M> {
    fn default() -> Self {
        assert!(W == 1 + E + M && M <= 32);
        assert!(
            bias(E) + 15 < (1 << E) - 1,
            "UIntToFloat: 2^15 must be finite"
        );
        let shifts = [8u64, 4, 2, 1];
        Self {
            value: Default::default(),
            word: Default::default(),
            norm: Default::default(),
            exp: Default::default(),
            fraction: Default::default(),
            c_shift: shifts.map(|s| const_index(s as usize)),
            c_shift_e: shifts.map(const_bits::<E>),
            // The top `s` bits of a 16-bit value.
            c_top_mask: shifts.map(|s| const_bits::<16>(((1 << s) - 1) << (16 - s))),
            c_exp_top: const_bits::<E>(bias(E) + 15),
            c_man_bits: const_index(M),
            c_fraction_pos: const_index(32 - M),
            // Bits 14..0 of the normalized value (below the leading one) to the top of 32.
            c_fraction_shift: const_index(17),
        }
    }
}

impl<const W: usize, const E: usize, const M: usize> Logic for UIntToFloat<W, E, M> {
    #[hdl_gen]
    fn update(&mut self) {
        self.norm[0].next = self.value.val();
        self.exp[0].next = self.c_exp_top.val();
        for i in 0..4 {
            self.norm[i + 1].next = self.norm[i].val();
            self.exp[i + 1].next = self.exp[i].val();
            if (self.norm[i].val() & self.c_top_mask[i].val()) == 0 {
                self.norm[i + 1].next = self.norm[i].val() << self.c_shift[i].val();
                self.exp[i + 1].next = self.exp[i].val() - self.c_shift_e[i].val();
            }
        }
        self.fraction.next = bit_cast::<32, 16>(self.norm[4].val()) << self.c_fraction_shift.val();
        self.word.next = (bit_cast::<W, E>(self.exp[4].val()) << self.c_man_bits.val())
            | bit_cast::<W, M>(
                self.fraction
                    .val()
                    .get_bits::<M>(self.c_fraction_pos.val().index()),
            );
        if self.value.val() == 0 {
            self.word.next = 0.into();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;

    fn check<const W: usize, const E: usize, const M: usize>(f: Format, limit: u32) {
        let mut u = UIntToFloat::<W, E, M>::default();
        u.connect_all();
        for x in (0..limit)
            .step_by(1)
            .filter(|x| x % 7 == 0 || *x < 300 || x.is_power_of_two())
        {
            u.value.next = (x as u64).into();
            for _ in 0..50 {
                u.update_all();
                if !u.has_changed() {
                    break;
                }
            }
            assert_eq!(
                u.word.val().to_u64() as u32,
                f.from_int(x as i64),
                "{f}: {x}"
            );
        }
    }

    #[test]
    fn matches_from_int_where_exact() {
        check::<24, 7, 16>(Format::E7M16, 1 << 16);
        check::<32, 8, 23>(Format::E8M23, 1 << 16);
        check::<16, 5, 10>(Format::parse("e5m10").unwrap(), 2048);
    }
}
