//! `SyncFifo`: a first-in first-out queue of `2^N` words in one clock domain, clock for clock
//! the queue of rust-hdl's `SynchronousFIFO` (the same RAM, pointers and flag timing), with its
//! `empty` flag held in a flip-flop instead of compared from the pointers in every clock.
//!
//! Why: a pop decided from `empty` runs on through the next read address into the RAM and
//! its output register. With `empty` compared from the pointers (two LUT levels on the ECP5)
//! ahead of that decision, the traversal unit's fetch queues were the processor's critical
//! path at 87.3 MHz (`loop_fifo.read_address -> loop_fifo.data_out`, 11.45 ns of which
//! 9.3 ns routing; issue 16). The flag's next value is selected from two compares of
//! registers, so nothing before the pop decision is compared.
//!
//! Contract (rust-hdl's): `data_out` is the oldest word while `empty` is low; `read` pops it
//! (ignored when empty) and the next word shows in the next clock. `write` pushes `data_in`
//! unless `full`; a pushed word can be popped two clocks later (`empty` falls then). `full`
//! comes from the pointers as in rust-hdl (no path of ours starts at it). rust-hdl's
//! `almost_*`, `underflow` and `overflow` are left out: no block of ours reads them.
//!
//! Latency: 2 clocks from push to pop; throughput one push and one pop per clock.
//! Golden twin: none; it moves words. Its test runs it beside rust-hdl's `SynchronousFIFO`.

use rust_hdl::prelude::*;

#[derive(LogicBlock, Default)]
pub struct SyncFifo<D: Synth, const N: usize, const NP1: usize> {
    pub clock: Signal<In, Clock>,
    pub read: Signal<In, Bit>,
    pub data_out: Signal<Out, D>,
    pub empty: Signal<Out, Bit>,
    pub write: Signal<In, Bit>,
    pub data_in: Signal<In, D>,
    pub full: Signal<Out, Bit>,
    ram: RAM<D, N>,
    /// Pointers with a wrap bit (`NP1 = N + 1`); the write pointer also a clock late, since a
    /// word is popped no earlier than a clock after the RAM stored it.
    read_address: DFF<Bits<NP1>>,
    write_address: DFF<Bits<NP1>>,
    write_address_delayed: DFF<Bits<NP1>>,
    /// `read_address != write_address_delayed`, registered (zero at power-up: empty).
    filled: DFF<Bit>,
    read_next: Signal<Local, Bits<NP1>>,
    pop: Signal<Local, Bit>,
    push: Signal<Local, Bit>,
}

impl<D: Synth, const N: usize, const NP1: usize> Logic for SyncFifo<D, N, NP1> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            read_address,
            write_address,
            write_address_delayed,
            filled
        );
        self.ram.read_clock.next = self.clock.val();
        self.ram.write_clock.next = self.clock.val();

        self.empty.next = !self.filled.q.val();
        self.full.next = self.filled.q.val()
            & (bit_cast::<N, NP1>(self.read_address.q.val())
                == bit_cast::<N, NP1>(self.write_address.q.val()));
        self.pop.next = self.read.val() & self.filled.q.val();
        self.push.next = self.write.val() & (!self.full.val());

        self.ram.write_enable.next = self.push.val();
        self.ram.write_address.next = bit_cast::<N, NP1>(self.write_address.q.val());
        self.ram.write_data.next = self.data_in.val();
        self.write_address.d.next = self.write_address.q.val();
        if self.push.val() {
            self.write_address.d.next = self.write_address.q.val() + 1;
        }
        self.write_address_delayed.d.next = self.write_address.q.val();

        // The RAM registers its read: address the word after the popped one in the clock of
        // the pop, so that it shows in the next clock.
        self.read_next.next = self.read_address.q.val() + 1;
        self.ram.read_address.next = bit_cast::<N, NP1>(self.read_address.q.val());
        self.read_address.d.next = self.read_address.q.val();
        self.filled.d.next = self.read_address.q.val() != self.write_address.q.val();
        if self.pop.val() {
            self.ram.read_address.next = bit_cast::<N, NP1>(self.read_next.val());
            self.read_address.d.next = self.read_next.val();
            self.filled.d.next = self.read_next.val() != self.write_address.q.val();
        }
        self.data_out.next = self.ram.read_data.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::{clock_cycle, settle};
    use rand::{Rng, SeedableRng};

    #[derive(LogicBlock, Default)]
    struct Pair {
        clock: Signal<In, Clock>,
        ours: SyncFifo<Bits<8>, 3, 4>,
        theirs: SynchronousFIFO<Bits<8>, 3, 4, 1>,
    }

    impl Logic for Pair {
        #[hdl_gen]
        fn update(&mut self) {
            clock!(self, clock, ours, theirs);
        }
    }

    /// rust-hdl simulation, 4,000 clocks of random pushes and pops (some into a full queue,
    /// some from an empty one): `empty`, `full` and every word popped are those of rust-hdl's
    /// `SynchronousFIFO` in every clock, and the queue goes both empty and full.
    #[test]
    fn every_clock_equals_rust_hdls_synchronous_fifo() {
        let seed = 30;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut u = Pair::default();
        u.connect_all();
        let (mut was_full, mut popped) = (0, 0);
        for clock in 0..4000 {
            // Phases of mostly pushing and mostly popping, so that both ends are reached.
            let push_bias = if (clock / 200) % 2 == 0 { 0.8 } else { 0.3 };
            let write = rng.gen_bool(push_bias);
            let read = rng.gen_bool(1.0 - push_bias + 0.1);
            let word: u64 = rng.gen_range(0..256);
            for f in [&mut u.ours.write, &mut u.theirs.write] {
                f.next = write;
            }
            for f in [&mut u.ours.read, &mut u.theirs.read] {
                f.next = read;
            }
            for f in [&mut u.ours.data_in, &mut u.theirs.data_in] {
                f.next = word.into();
            }
            u.clock.next = Clock { clk: false };
            settle(&mut u);
            assert_eq!(
                u.ours.empty.val(),
                u.theirs.empty.val(),
                "clock {clock}: empty"
            );
            assert_eq!(
                u.ours.full.val(),
                u.theirs.full.val(),
                "clock {clock}: full"
            );
            if !u.theirs.empty.val() {
                assert_eq!(
                    u.ours.data_out.val(),
                    u.theirs.data_out.val(),
                    "clock {clock}: head"
                );
                popped += usize::from(read);
            }
            was_full += usize::from(u.theirs.full.val());
            clock_cycle(&mut u, |u, c| u.clock.next = Clock { clk: c });
        }
        assert!(was_full > 50, "the queue was full in {was_full} clocks");
        assert!(popped > 1000, "{popped} words popped");
    }
}
