//! `RayStore`: each thread's object-space ray (o, d) and t_min as the engine hands them to a
//! coprocessor (the triangle tester and the traversal unit each keep one), and the per-thread
//! counters both coprocessors start from.
//!
//! Write side (the engine's I5): `ray_write` with `ray_pair` 0, 1, 2 writes `(o.x, o.y)`,
//! `(o.z, d.x)`, `(d.y, d.z)` of `thread` from `word_a`, `word_b`; `t_min_write` writes t_min
//! from `word_a`; `primary_write` writes the whole ray `(primary_o, primary_d)` of
//! `primary_thread` (a primary ray from ray generation; the engine writes no pair in that
//! clock). Read side: `ray_thread` gives `o`, `d` one clock later; `t_min_thread` gives
//! `t_min` one clock later (block RAMs, one read port each).
//!
//! Latency 1 clock per read; throughput one write and one read of each memory per clock.
//! No golden twin: storage only. The words it keeps are the ray that
//! [`units::triangle_test`](crate::units::triangle_test) and
//! [`units::KdWalk`](crate::units::KdWalk) read.

use rust_hdl::prelude::*;

#[derive(LogicBlock, Default)]
pub struct RayStore<const W: usize> {
    pub clock: Signal<In, Clock>,
    pub thread: Signal<In, Bits<5>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub ray_write: Signal<In, Bit>,
    pub ray_pair: Signal<In, Bits<2>>,
    pub t_min_write: Signal<In, Bit>,
    pub primary_write: Signal<In, Bit>,
    pub primary_thread: Signal<In, Bits<5>>,
    pub primary_o: [Signal<In, Bits<W>>; 3],
    pub primary_d: [Signal<In, Bits<W>>; 3],
    pub ray_thread: Signal<In, Bits<5>>,
    pub o: [Signal<Out, Bits<W>>; 3],
    pub d: [Signal<Out, Bits<W>>; 3],
    pub t_min_thread: Signal<In, Bits<5>>,
    pub t_min: Signal<Out, Bits<W>>,
    /// o.x, o.y, o.z, d.x, d.y, d.z, t_min.
    words: [RAM<Bits<W>, 5>; 7],
}

impl<const W: usize> Logic for RayStore<W> {
    #[hdl_gen]
    fn update(&mut self) {
        for k in 0..7 {
            self.words[k].read_clock.next = self.clock.val();
            self.words[k].write_clock.next = self.clock.val();
            self.words[k].write_address.next = self.thread.val();
            self.words[k].write_enable.next = false;
            self.words[k].write_data.next = self.word_a.val().get_bits::<W>(0);
        }
        if self.ray_write.val() {
            if self.ray_pair.val() == 0 {
                self.words[0].write_enable.next = true;
                self.words[1].write_enable.next = true;
                self.words[1].write_data.next = self.word_b.val().get_bits::<W>(0);
            }
            if self.ray_pair.val() == 1 {
                self.words[2].write_enable.next = true;
                self.words[3].write_enable.next = true;
                self.words[3].write_data.next = self.word_b.val().get_bits::<W>(0);
            }
            if self.ray_pair.val() == 2 {
                self.words[4].write_enable.next = true;
                self.words[5].write_enable.next = true;
                self.words[5].write_data.next = self.word_b.val().get_bits::<W>(0);
            }
        }
        if self.primary_write.val() {
            for k in 0..3 {
                self.words[k].write_address.next = self.primary_thread.val();
                self.words[k].write_enable.next = true;
                self.words[k].write_data.next = self.primary_o[k].val();
                self.words[3 + k].write_address.next = self.primary_thread.val();
                self.words[3 + k].write_enable.next = true;
                self.words[3 + k].write_data.next = self.primary_d[k].val();
            }
        }
        self.words[6].write_enable.next = self.t_min_write.val();
        for k in 0..6 {
            self.words[k].read_address.next = self.ray_thread.val();
        }
        for k in 0..3 {
            self.o[k].next = self.words[k].read_data.val();
            self.d[k].next = self.words[3 + k].read_data.val();
        }
        self.words[6].read_address.next = self.t_min_thread.val();
        self.t_min.next = self.words[6].read_data.val();
    }
}

/// Per-thread counters that start at 0 (nothing pending at power-up).
pub fn zero_counters() -> RAM<Bits<8>, 5> {
    RAM::new(
        (0..32u64)
            .map(|k| (Bits::<5>::from(k), Bits::<8>::from(0u64)))
            .collect(),
    )
}
