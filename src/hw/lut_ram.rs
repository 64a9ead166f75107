//! `LutRam`: a small RAM with an asynchronous (combinational) read port and a synchronous
//! write port, the shape of the distributed RAM in the LUTs of an FPGA (ECP5 `DPR16X4`,
//! Virtex-II `RAM16X1D`).
//!
//! Why: rust-hdl's `RAM` registers its read, so a lookup whose result must reach a block RAM's
//! address in the same clock has to wait a clock. The engine's fetch reads a thread's pc here
//! and addresses the instruction ROM with it in one clock, so that the ROM's word can be
//! registered before it addresses the register file (a block RAM's 5.8 ns clock-to-out routed
//! straight to another block RAM's address was the processor's critical path at 78.0 MHz,
//! issue 16), at no cost in clocks.
//!
//! Contract: `read_data` is the word at `read_address` in the same clock, as the last clock
//! edge left it; a write with `write_enable` stores `write_data` at `write_address` on the
//! clock's rising edge. Words start as given to [`LutRam::new`] (the rest zero).
//!
//! Latency: 0 clocks (read), 1 clock (write). Throughput: one read and one write per clock.
//!
//! Golden twin: none; it stores words.

use std::collections::BTreeMap;

use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct LutRam<D: Synth, const N: usize> {
    pub read_address: Signal<In, Bits<N>>,
    pub read_data: Signal<Out, D>,
    pub write_clock: Signal<In, Clock>,
    pub write_address: Signal<In, Bits<N>>,
    pub write_data: Signal<In, D>,
    pub write_enable: Signal<In, bool>,
    // (rust-hdl's derive skips fields named with a leading underscore: the simulation store)
    _words: Box<BTreeMap<Bits<N>, D>>,
}

impl<D: Synth, const N: usize> LutRam<D, N> {
    /// A RAM holding `words` (address to word; absent addresses hold zero).
    pub fn new(words: BTreeMap<Bits<N>, D>) -> Self {
        Self {
            read_address: Default::default(),
            read_data: Default::default(),
            write_clock: Default::default(),
            write_address: Default::default(),
            write_data: Default::default(),
            write_enable: Default::default(),
            _words: Box::new(words),
        }
    }
}

impl<D: Synth, const N: usize> Logic for LutRam<D, N> {
    fn update(&mut self) {
        if self.write_clock.pos_edge() && self.write_enable.val() {
            self._words
                .insert(self.write_address.val(), self.write_data.val());
        }
        self.read_data.next = *self
            ._words
            .get(&self.read_address.val())
            .unwrap_or(&D::default());
    }

    fn connect(&mut self) {
        self.read_data.connect();
    }

    fn hdl(&self) -> Verilog {
        let init = (0..1usize << N)
            .map(|a| {
                let word = self
                    ._words
                    .get(&Bits::<N>::from(a as u64))
                    .copied()
                    .unwrap_or_default();
                format!("   mem[{a}] = {};\n", word.verilog())
            })
            .collect::<String>();
        Verilog::Custom(format!(
            "\
reg[{top}:0] mem[{last}:0];

initial begin
{init}end

always @(*) begin
   read_data = mem[read_address];
end

always @(posedge write_clock) begin
   if (write_enable) begin
      mem[write_address] <= write_data;
   end
end
",
            top = D::BITS - 1,
            last = (1usize << N) - 1,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::{clock_cycle, settle};

    #[derive(LogicBlock)]
    struct Bench {
        clock: Signal<In, Clock>,
        ram: LutRam<Bits<8>, 3>,
    }

    impl Logic for Bench {
        #[hdl_gen]
        fn update(&mut self) {
            self.ram.write_clock.next = self.clock.val();
        }
    }

    fn bench() -> Bench {
        let words = (0..8u64).map(|a| (Bits::<3>::from(a), Bits::<8>::from(100 + a)));
        let mut b = Bench {
            clock: Default::default(),
            ram: LutRam::new(words.collect()),
        };
        b.connect_all();
        b
    }

    #[test]
    fn a_read_shows_the_word_in_the_clock_of_its_address() {
        let mut b = bench();
        for a in [5u64, 0, 7, 2] {
            b.ram.read_address.next = a.into();
            settle(&mut b);
            assert_eq!(b.ram.read_data.val(), Bits::<8>::from(100 + a), "word {a}");
        }
    }

    #[test]
    fn a_write_shows_after_its_clock_edge_and_not_before() {
        let mut b = bench();
        b.ram.read_address.next = 3.into();
        b.ram.write_address.next = 3.into();
        b.ram.write_data.next = 42.into();
        b.ram.write_enable.next = true;
        settle(&mut b);
        assert_eq!(
            b.ram.read_data.val(),
            Bits::<8>::from(103),
            "before the edge"
        );
        clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
        b.ram.write_enable.next = false;
        settle(&mut b);
        assert_eq!(b.ram.read_data.val(), Bits::<8>::from(42), "after the edge");
    }

    #[test]
    fn the_verilog_reads_combinationally_and_starts_with_the_words() {
        let v = match bench().ram.hdl() {
            Verilog::Custom(text) => text,
            _ => panic!("LutRam writes its own Verilog"),
        };
        assert!(
            v.contains("always @(*) begin\n   read_data = mem[read_address];"),
            "{v}"
        );
        assert!(v.contains("mem[7] = 8'h6b;"), "{v}");
    }
}
