//! `FirstReady`: the scheduler's choice of the next thread, the highest set bit of
//! `preferred` if it has one, else of `others`, one-hot.
//!
//! Contract: `found` is set when either word has a bit set; `onehot` then has exactly the
//! chosen bit and `number` its index (0-31, whichever word it came from); with no bit set
//! both are zero. The scheduler passes the ready threads below its round-robin pointer as
//! `preferred` and all ready threads as `others`, and registers both forms: the one-hot for
//! its own bookkeeping, the number for the pc store's address.
//!
//! Structure: a search for the highest set bit of the 64-bit `{preferred, others}` in groups
//! of four, not a chain of 64 priority multiplexers: whether a group has a bit set, whether
//! any higher group has (spread down one, two, four, eight and sixteen groups), and whether a
//! higher bit of the same group has; the chosen bit is the one whose group is the first and
//! who is first in its group. It settles in about six levels of logic, where the chain took
//! eleven (the scheduler's pick was among the processor's slowest paths). The number comes
//! from the same first group: its group's number (an OR over the groups) and, beside it, the
//! position of the highest bit within the group (one level from the group's four bits,
//! chosen by the first group): a level or two more than the one-hot, here, where an encode
//! of the registered one-hot sat in front of the pc store's read on the processor's slowest
//! placed path (86.3 MHz: the encode, the pc store and the epoch check, 9.6 ns of routing).
//!
//! Latency: combinational (the scheduler registers the choice). Throughput: one choice per
//! clock. Golden twin: none (it computes no ray arithmetic); the test below checks it against
//! [`first_ready`], the highest set bit in plain Rust.

use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct FirstReady {
    pub preferred: Signal<In, Bits<32>>,
    pub others: Signal<In, Bits<32>>,
    pub found: Signal<Out, Bit>,
    pub onehot: Signal<Out, Bits<32>>,
    pub number: Signal<Out, Bits<5>>,

    both: Signal<Local, Bits<64>>,
    spread: Signal<Local, Bits<64>>,
    /// At the lowest bit of each group of four: the group has a bit set; a higher group has.
    group_any: Signal<Local, Bits<64>>,
    above_1: Signal<Local, Bits<64>>,
    above_2: Signal<Local, Bits<64>>,
    above_4: Signal<Local, Bits<64>>,
    above_8: Signal<Local, Bits<64>>,
    above_16: Signal<Local, Bits<64>>,
    /// The first group, at its lowest bit and spread over its four.
    group_first: Signal<Local, Bits<64>>,
    group_mask: Signal<Local, Bits<64>>,
    /// A higher bit of the same group is set.
    higher_in_group: Signal<Local, Bits<64>>,
    first: Signal<Local, Bits<64>>,
    /// At the lowest bit of each group: bit 1 and bit 0 of the position of the group's
    /// highest set bit.
    position_hi: Signal<Local, Bits<64>>,
    position_lo: Signal<Local, Bits<64>>,
    number_bits: [Signal<Local, Bit>; 5],

    /// The lowest bit of every group of four; the bits of a group with three and with two
    /// bits above them in the group.
    c_group_low: Constant<Bits<64>>,
    c_below_3: Constant<Bits<64>>,
    c_below_2: Constant<Bits<64>>,
    /// The lowest bit of every group whose number (0-15) has bit `k` set.
    c_group_number_bit: [Constant<Bits<64>>; 3],
}

impl Default for FirstReady {
    fn default() -> Self {
        Self {
            preferred: Default::default(),
            others: Default::default(),
            found: Default::default(),
            onehot: Default::default(),
            number: Default::default(),
            both: Default::default(),
            spread: Default::default(),
            group_any: Default::default(),
            above_1: Default::default(),
            above_2: Default::default(),
            above_4: Default::default(),
            above_8: Default::default(),
            above_16: Default::default(),
            group_first: Default::default(),
            group_mask: Default::default(),
            higher_in_group: Default::default(),
            first: Default::default(),
            position_hi: Default::default(),
            position_lo: Default::default(),
            number_bits: Default::default(),
            c_group_low: Constant::new(0x1111_1111_1111_1111u64.into()),
            c_below_3: Constant::new(0x7777_7777_7777_7777u64.into()),
            c_below_2: Constant::new(0x3333_3333_3333_3333u64.into()),
            c_group_number_bit: std::array::from_fn(|k| {
                Constant::new(
                    (0..16u64)
                        .filter(|g| g >> k & 1 == 1)
                        .fold(0u64, |m, g| m | 1 << (4 * g))
                        .into(),
                )
            }),
        }
    }
}

impl Logic for FirstReady {
    #[hdl_gen]
    fn update(&mut self) {
        self.both.next = (bit_cast::<64, 32>(self.preferred.val()) << 32)
            | bit_cast::<64, 32>(self.others.val());
        self.spread.next = self.both.val() | (self.both.val() >> 1);
        self.group_any.next =
            (self.spread.val() | (self.spread.val() >> 2)) & self.c_group_low.val();
        self.above_1.next = self.group_any.val() >> 4;
        self.above_2.next = self.above_1.val() | (self.above_1.val() >> 4);
        self.above_4.next = self.above_2.val() | (self.above_2.val() >> 8);
        self.above_8.next = self.above_4.val() | (self.above_4.val() >> 16);
        self.above_16.next = self.above_8.val() | (self.above_8.val() >> 32);
        self.group_first.next = self.group_any.val() & (!self.above_16.val());
        self.group_mask.next = self.group_first.val()
            | (self.group_first.val() << 1)
            | (self.group_first.val() << 2)
            | (self.group_first.val() << 3);
        self.higher_in_group.next = ((self.both.val() >> 1) & self.c_below_3.val())
            | ((self.both.val() >> 2) & self.c_below_2.val())
            | ((self.both.val() >> 3) & self.c_group_low.val());
        self.first.next = self.both.val() & (!self.higher_in_group.val()) & self.group_mask.val();
        self.onehot.next = self.first.val().get_bits::<32>(0) | self.first.val().get_bits::<32>(32);
        self.found.next = self.both.val() != 0;

        // The number: the first group's number (bits 4..2; bit 5, which word, is dropped) and
        // the position of the highest bit in it (bits 1..0).
        self.position_hi.next =
            ((self.both.val() >> 2) | (self.both.val() >> 3)) & self.c_group_low.val();
        self.position_lo.next = ((self.both.val() >> 3)
            | ((!(self.both.val() >> 2)) & (self.both.val() >> 1)))
            & self.c_group_low.val();
        self.number_bits[0].next = (self.group_first.val() & self.position_lo.val()) != 0;
        self.number_bits[1].next = (self.group_first.val() & self.position_hi.val()) != 0;
        for k in 0..3 {
            self.number_bits[k + 2].next =
                (self.group_first.val() & self.c_group_number_bit[k].val()) != 0;
        }
        self.number.next = bit_cast::<5, 1>(self.number_bits[0].val().into())
            | (bit_cast::<5, 1>(self.number_bits[1].val().into()) << 1)
            | (bit_cast::<5, 1>(self.number_bits[2].val().into()) << 2)
            | (bit_cast::<5, 1>(self.number_bits[3].val().into()) << 3)
            | (bit_cast::<5, 1>(self.number_bits[4].val().into()) << 4);
    }
}

/// What [`FirstReady`] chooses: the highest set bit of `preferred`, else of `others`.
#[cfg(test)]
fn first_ready(preferred: u32, others: u32) -> Option<u32> {
    [preferred, others]
        .into_iter()
        .find(|&w| w != 0)
        .map(|w| 31 - w.leading_zeros())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::settle;
    use rand::{Rng, SeedableRng};

    #[test]
    fn chooses_the_highest_preferred_else_the_highest_other() {
        let mut unit = FirstReady::default();
        unit.connect_all();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(16);
        // Every single bit in either word, both words empty, and random words of few and of
        // many bits (the scheduler's `preferred` is a subset of `others`, but the block does
        // not rely on it).
        let singles = (0..32).flat_map(|k| [(1u32 << k, 0), (0, 1u32 << k), (1 << k, 1 << k)]);
        let random = (0..3000).map(|k| {
            let sparse =
                |r: &mut rand_chacha::ChaCha8Rng| r.gen::<u32>() & r.gen::<u32>() & r.gen::<u32>();
            match k % 3 {
                0 => (sparse(&mut rng), sparse(&mut rng)),
                1 => (0, rng.gen()),
                _ => (rng.gen(), rng.gen()),
            }
        });
        for (preferred, others) in [(0, 0)].into_iter().chain(singles).chain(random) {
            unit.preferred.next = u64::from(preferred).into();
            unit.others.next = u64::from(others).into();
            settle(&mut unit);
            let want = first_ready(preferred, others);
            let case = format!("preferred {preferred:#010x}, others {others:#010x}");
            assert_eq!(unit.found.val(), want.is_some(), "{case}");
            assert_eq!(
                unit.onehot.val().to_u64(),
                want.map_or(0, |k| 1u64 << k),
                "{case}"
            );
            assert_eq!(
                unit.number.val().to_u64(),
                want.map_or(0, u64::from),
                "{case}"
            );
        }
    }
}
