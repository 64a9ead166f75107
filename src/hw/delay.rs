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
        // A one-iteration loop: rust-hdl's Verilog cannot index with `N - 1`, but unrolls a
        // loop's bounds. One assignment, not one per stage: in Icarus an output written several
        // times in an evaluation changes several times and wakes its readers each time (a
        // reader that drives `data_in` back through a default and an override then never
        // settles).
        for i in (N - 1)..N {
            self.data_out.next = self.stage[i].q.val();
        }
    }
}

/// [`Delay`] whose length is known only at construction (rust-hdl cannot size an array by an
/// expression of const parameters): pads one operator's latency to another's, e.g. the
/// engine's divider to its long line. Latency `len` clocks (`new(len)`, `len >= 1`),
/// throughput one word per clock. No golden twin: it computes nothing.
#[derive(LogicBlock)]
pub struct DelayLine<D: Synth> {
    pub clock: Signal<In, Clock>,
    pub data_in: Signal<In, D>,
    pub data_out: Signal<Out, D>,
    stage: Vec<DFF<D>>,
}

impl<D: Synth> DelayLine<D> {
    pub fn new(len: usize) -> Self {
        assert!(len >= 1, "DelayLine: at least one register");
        Self {
            clock: Default::default(),
            data_in: Default::default(),
            data_out: Default::default(),
            stage: (0..len).map(|_| Default::default()).collect(),
        }
    }
}

impl<D: Synth> Logic for DelayLine<D> {
    #[hdl_gen]
    fn update(&mut self) {
        for i in 0..self.stage.len() {
            self.stage[i].clock.next = self.clock.val();
        }
        self.stage[0].d.next = self.data_in.val();
        for i in 1..self.stage.len() {
            self.stage[i].d.next = self.stage[i - 1].q.val();
        }
        // The last stage, written once (see `Delay`).
        for i in (self.stage.len() - 1)..self.stage.len() {
            self.data_out.next = self.stage[i].q.val();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `data_out` after each of 10 clocks whose inputs are 1, 2, 3, ...
    fn outputs<B: Block>(
        d: &mut B,
        drive: impl Fn(&mut B, u64, bool),
        out: impl Fn(&B) -> u64,
    ) -> Vec<u64> {
        d.connect_all();
        let mut outs = Vec::new();
        for cycle in 0..10u64 {
            for clk in [false, true] {
                drive(d, cycle + 1, clk);
                for _ in 0..20 {
                    d.update_all();
                    if !d.has_changed() {
                        break;
                    }
                }
            }
            outs.push(out(d));
        }
        outs
    }

    #[test]
    fn output_is_input_n_clocks_earlier() {
        let outs = outputs(
            &mut Delay::<Bits<8>, 3>::default(),
            |d, v, clk| {
                d.data_in.next = v.into();
                d.clock.next = Clock { clk };
            },
            |d| d.data_out.val().to_u64(),
        );
        // After the edge of clock c the input of clock c - 2 is out (value c - 1).
        assert_eq!(outs, vec![0, 0, 1, 2, 3, 4, 5, 6, 7, 8]);
    }

    #[test]
    fn delay_line_is_as_long_as_asked() {
        for len in [1, 4] {
            let outs = outputs(
                &mut DelayLine::<Bits<8>>::new(len),
                |d, v, clk| {
                    d.data_in.next = v.into();
                    d.clock.next = Clock { clk };
                },
                |d| d.data_out.val().to_u64(),
            );
            let want: Vec<u64> = (0..10u64)
                .map(|c| (c + 2).saturating_sub(len as u64))
                .collect();
            assert_eq!(outs, want, "length {len}");
        }
    }
}
