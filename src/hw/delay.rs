//! `Delay<D, N>`: a fixed shift register of `N >= 1` registers. `data_out` is `data_in` of
//! `N` clocks earlier (every register starts at zero). The pipelined units use it to carry
//! operands, tags and valid bits alongside the floating-point operators so that everything a
//! later stage needs arrives in the same clock.
//!
//! Latency `N` clocks, throughput one word per clock. No golden twin: it computes nothing.

use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct Delay<D: Synth, const N: usize> {
    pub clock: Signal<In, Clock>,
    pub data_in: Signal<In, D>,
    pub data_out: Signal<Out, D>,
    stage: [DFF<D>; N],
}

impl<D: Synth, const N: usize> Default for Delay<D, N> {
    fn default() -> Self {
        assert!(N >= 1, "Delay: at least one register");
        Self {
            clock: Default::default(),
            data_in: Default::default(),
            data_out: Default::default(),
            stage: std::array::from_fn(|_| Default::default()),
        }
    }
}

impl<D: Synth, const N: usize> Logic for Delay<D, N> {
    #[hdl_gen]
    fn update(&mut self) {
        for i in 0..N {
            self.stage[i].clock.next = self.clock.val();
        }
        self.stage[0].d.next = self.data_in.val();
        for i in 1..N {
            self.stage[i].d.next = self.stage[i - 1].q.val();
        }
        // The last write wins: the last stage (rust-hdl's Verilog cannot index with `N - 1`).
        for i in 0..N {
            self.data_out.next = self.stage[i].q.val();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_is_input_n_clocks_earlier() {
        let mut d = Delay::<Bits<8>, 3>::default();
        d.connect_all();
        let mut outs = Vec::new();
        for cycle in 0..10u64 {
            d.data_in.next = (cycle + 1).into();
            for clk in [false, true] {
                d.clock.next = Clock { clk };
                for _ in 0..20 {
                    d.update_all();
                    if !d.has_changed() {
                        break;
                    }
                }
            }
            outs.push(d.data_out.val().to_u64());
        }
        // After the edge of clock c the input of clock c - 2 is out (value c - 1).
        assert_eq!(outs, vec![0, 0, 1, 2, 3, 4, 5, 6, 7, 8]);
    }
}
