//! Progress of long runs: the stage a run is in (trees, Verilog, compiling, simulating,
//! comparing) and the testbench's heartbeat while a simulator runs (`dynrt-heartbeat` lines,
//! streamed from its output). The library only reports; whoever installed a listener (the
//! CLI, with an indicatif spinner on a terminal) shows it. Without a listener nothing happens.

use std::sync::OnceLock;

type Listener = Box<dyn Fn(&str) + Send + Sync>;

static LISTENER: OnceLock<Listener> = OnceLock::new();

/// Installs the listener (once; later calls are ignored).
pub fn listen(f: impl Fn(&str) + Send + Sync + 'static) {
    let _ = LISTENER.set(Box::new(f));
}

/// Reports a stage or a heartbeat.
pub fn report(message: &str) {
    if let Some(f) = LISTENER.get() {
        f(message);
    }
}

/// The prefix of the testbench's heartbeat lines (`+heartbeat=N`: every N clocks,
/// `dynrt-heartbeat frame K: C cycles, R rays`).
pub const HEARTBEAT: &str = "dynrt-heartbeat ";
