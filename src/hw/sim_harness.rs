//! Test helper for rust-hdl's own simulation of the geometry units: one clock cycle with the
//! combinational logic settled after each edge (as rust-hdl's `Simulation` does), and random
//! words for quick checks. A quick check only: the generated Verilog in Icarus and Verilator
//! is the proof (`crate::sim::geometry_unit`, its tests).

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rust_hdl::prelude::*;

use crate::fp::Format;

pub(crate) fn settle<U: Block>(unit: &mut U) {
    for _ in 0..10_000 {
        unit.update_all();
        if !unit.has_changed() {
            return;
        }
    }
    panic!("combinational logic does not settle");
}

/// One clock: inputs already set; falling then rising edge, settled after each.
pub(crate) fn clock_cycle<U: Block>(unit: &mut U, set_clock: impl Fn(&mut U, bool)) {
    set_clock(unit, false);
    settle(unit);
    set_clock(unit, true);
    settle(unit);
}

/// A value of magnitude 2^-6 .. 2^6 with random sign, or (one in eight) a uniform bit pattern.
pub(crate) fn random_word(f: Format, rng: &mut ChaCha8Rng) -> u32 {
    if rng.gen_ratio(1, 8) {
        return rng.gen::<u32>() & f.word_mask();
    }
    let x = rng.gen_range(1.0..2.0) * 2f64.powi(rng.gen_range(-6..=6));
    f.from_f64(if rng.gen_bool(0.5) { -x } else { x })
}
