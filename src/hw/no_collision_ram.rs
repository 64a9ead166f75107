//! `NoCollisionRam`: a block RAM, one synchronous read port and one write port, whose owner
//! never uses the word read from an address in the clock that writes that address.
//!
//! Why: rust-hdl's `RAM` reads the old word when both ports meet on one address (read
//! first). An ECP5 DP16KD leaves that collision undefined, so yosys emulates read-first: it
//! delays the write by a clock and adds a bypass, whose address compare sat between the
//! instruction ROM's output and the register file's select register: the processor's
//! critical path at 83.0 MHz (`rom_ctl -> regs_b`, issue 16). The Verilog here marks the
//! memory `no_rw_check` (yosys then builds the plain block RAM) and, for simulation, reads an
//! unknown word (`'x`) on a collision, so that Icarus shows where an owner breaks the
//! contract instead of the old word hiding it.
//!
//! Contract: ports, latency (the word one clock after its address) and throughput (one read
//! and one write per clock) as rust-hdl's `RAM`, both ports on one clock; a read of the
//! address written in the same clock returns an undefined word (old in the Rust simulation,
//! `'x` in Icarus, whatever the block RAM gives in silicon). A RAM made with
//! [`NoCollisionRam::decoding`] holds `2^bits` words and decodes only the addresses' low
//! `bits` (an owner whose addresses use fewer than `N` bits puts the unused ones on top), so
//! that it takes only the block RAMs its words need.
//!
//! Golden twin: none; it stores words. Its owners say why they never use a colliding read.

use std::collections::BTreeMap;

use rust_hdl::prelude::*;

#[derive(LogicBlock, Default)]
pub struct NoCollisionRam<D: Synth, const N: usize> {
    pub read_address: Signal<In, Bits<N>>,
    pub read_clock: Signal<In, Clock>,
    pub read_data: Signal<Out, D>,
    pub write_address: Signal<In, Bits<N>>,
    pub write_clock: Signal<In, Clock>,
    pub write_data: Signal<In, D>,
    pub write_enable: Signal<In, bool>,
    // (rust-hdl's derive skips fields named with a leading underscore: the simulation store)
    _words: Box<BTreeMap<Bits<N>, D>>,
    // The address bits decoded (0: all `N`).
    _decoded: usize,
}

impl<D: Synth, const N: usize> NoCollisionRam<D, N> {
    /// A RAM of `2^bits` words that decodes only the addresses' low `bits` (`bits <= N`).
    pub fn decoding(bits: usize) -> Self {
        assert!((1..=N).contains(&bits));
        Self {
            _decoded: bits,
            ..Default::default()
        }
    }

    fn decoded_bits(&self) -> usize {
        if self._decoded == 0 {
            N
        } else {
            self._decoded
        }
    }

    /// The word `address` reaches.
    fn word(&self, address: Bits<N>) -> Bits<N> {
        Bits::from((address.index() & ((1usize << self.decoded_bits()) - 1)) as u64)
    }
}

impl<D: Synth, const N: usize> Logic for NoCollisionRam<D, N> {
    fn update(&mut self) {
        if self.read_clock.pos_edge() {
            self.read_data.next = *self
                ._words
                .get(&self.word(self.read_address.val()))
                .unwrap_or(&D::default());
        }
        if self.write_clock.pos_edge() && self.write_enable.val() {
            let at = self.word(self.write_address.val());
            self._words.insert(at, self.write_data.val());
        }
    }

    fn connect(&mut self) {
        self.read_data.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(format!(
            "\
(* no_rw_check *)
reg[{top}:0] mem[{last}:0];

always @(posedge read_clock) begin
`ifdef SYNTHESIS
   read_data <= mem[read_address[{used}:0]];
`else
   // The owner never uses a word read in the clock that writes its address.
   read_data <= (write_enable && read_address[{used}:0] == write_address[{used}:0])
      ? {bits}'bx : mem[read_address[{used}:0]];
`endif
end

always @(posedge write_clock) begin
   if (write_enable) begin
      mem[write_address[{used}:0]] <= write_data;
   end
end
",
            top = D::BITS - 1,
            bits = D::BITS,
            last = (1usize << self.decoded_bits()) - 1,
            used = self.decoded_bits() - 1,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::{clock_cycle, settle};

    #[derive(LogicBlock, Default)]
    struct Bench {
        clock: Signal<In, Clock>,
        ram: NoCollisionRam<Bits<8>, 4>,
    }

    impl Logic for Bench {
        #[hdl_gen]
        fn update(&mut self) {
            self.ram.read_clock.next = self.clock.val();
            self.ram.write_clock.next = self.clock.val();
        }
    }

    #[test]
    fn a_written_word_reads_back_a_clock_after_its_address() {
        let mut b = Bench::default();
        b.connect_all();
        for k in 0..16u64 {
            b.ram.write_enable.next = true;
            b.ram.write_address.next = k.into();
            b.ram.write_data.next = (3 * k + 1).into();
            clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
        }
        b.ram.write_enable.next = false;
        for k in (0..16u64).rev() {
            b.ram.read_address.next = k.into();
            clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
            settle(&mut b);
            assert_eq!(
                b.ram.read_data.val(),
                Bits::<8>::from(3 * k + 1),
                "word {k}"
            );
        }
    }

    #[test]
    fn the_verilog_marks_collisions_unchecked_for_synthesis_and_unknown_in_simulation() {
        let v = match NoCollisionRam::<Bits<32>, 13>::default().hdl() {
            Verilog::Custom(text) => text,
            _ => panic!("NoCollisionRam writes its own Verilog"),
        };
        assert!(
            v.contains("(* no_rw_check *)\nreg[31:0] mem[8191:0];"),
            "{v}"
        );
        assert!(v.contains("32'bx : mem[read_address[12:0]]"), "{v}");
    }

    #[test]
    fn a_ram_decoding_fewer_bits_holds_fewer_words_and_ignores_the_top_bits() {
        let v = match NoCollisionRam::<Bits<32>, 13>::decoding(11).hdl() {
            Verilog::Custom(text) => text,
            _ => panic!("NoCollisionRam writes its own Verilog"),
        };
        assert!(v.contains("reg[31:0] mem[2047:0];"), "{v}");
        assert!(v.contains("mem[write_address[10:0]] <= write_data;"), "{v}");

        let mut b = Bench {
            clock: Default::default(),
            ram: NoCollisionRam::decoding(2),
        };
        b.connect_all();
        b.ram.write_enable.next = true;
        b.ram.write_address.next = 0b1101.into();
        b.ram.write_data.next = 77.into();
        clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
        b.ram.write_enable.next = false;
        b.ram.read_address.next = 0b0001.into();
        clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
        settle(&mut b);
        assert_eq!(b.ram.read_data.val(), Bits::<8>::from(77));
    }
}
