//! Test helper: clocks a pipelined operator in rust-hdl's own simulation (settling the
//! combinational logic after every edge, as rust-hdl's `Simulation` does) and collects its
//! valid outputs in order. rust-hdl's simulation is only a quick check: the generated Verilog
//! in Icarus and Verilator is the proof (see `crate::sim::fp_unit`).

use rust_hdl::prelude::*;

fn settle<U: Block>(unit: &mut U) {
    for _ in 0..10_000 {
        unit.update_all();
        if !unit.has_changed() {
            return;
        }
    }
    panic!("combinational logic does not settle");
}

/// Feeds `vectors` one per clock and returns the results in arrival order, checking that
/// each arrives exactly `latency` clocks after its input.
pub(crate) fn run_pipelined<U: Block>(
    mut unit: U,
    vectors: &[(u32, u32)],
    latency: usize,
    set_clock: impl Fn(&mut U, bool),
    set_inputs: impl Fn(&mut U, bool, u32, u32),
    outputs: impl Fn(&U) -> (bool, u32),
) -> Vec<u32> {
    unit.connect_all();
    let mut results = Vec::new();
    let total = vectors.len() + latency + 2;
    for cycle in 0..total {
        match vectors.get(cycle) {
            Some(&(a, b)) => set_inputs(&mut unit, true, a, b),
            None => set_inputs(&mut unit, false, 0, 0),
        }
        set_clock(&mut unit, false);
        settle(&mut unit);
        set_clock(&mut unit, true);
        settle(&mut unit);
        // After the rising edge of clock `cycle`, the input of clock `cycle + 1 - latency`
        // is at the output.
        let (valid, value) = outputs(&unit);
        let expect_valid = cycle + 1 >= latency && cycle + 1 - latency < vectors.len();
        assert_eq!(valid, expect_valid, "out_valid at clock {cycle}");
        if valid {
            results.push(value);
        }
    }
    results
}

/// Compares `got` with the model, printing the first mismatches.
pub(crate) fn assert_matches_model(
    what: &str,
    vectors: &[(u32, u32)],
    got: &[u32],
    model: impl Fn(u32, u32) -> u32,
) {
    assert_eq!(got.len(), vectors.len(), "{what}: result count");
    let mut bad = 0;
    for (i, (&(a, b), &r)) in vectors.iter().zip(got).enumerate() {
        let want = model(a, b);
        if r != want {
            if bad < 10 {
                eprintln!("{what}: vector {i}: a={a:#x} b={b:#x} got {r:#x} want {want:#x}");
            }
            bad += 1;
        }
    }
    assert_eq!(
        bad,
        0,
        "{what}: {bad} of {} results differ from the model",
        got.len()
    );
}
