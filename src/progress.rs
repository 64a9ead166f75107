//! Progress of long runs: the stage a run is in (trees, Verilog, compiling, simulating,
//! comparing), the testbench's heartbeat while a simulator runs (`dynrt-heartbeat` lines,
//! streamed from its output), and for runs of many like steps (the precision sweep, the stress
//! suite) how many of how many are done. The library only reports; whoever installed a
//! listener (the CLI, with indicatif on a terminal) shows it. Without a listener nothing happens.

use std::sync::OnceLock;

/// What a run reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    /// A stage begins, or a heartbeat within one (`frame K: C cycles, R rays`).
    Stage(&'a str),
    /// `done` of `total` like steps are finished; `next` is the one starting.
    Step {
        done: u64,
        total: u64,
        next: &'a str,
    },
}

type Listener = Box<dyn Fn(Event) + Send + Sync>;

static LISTENER: OnceLock<Listener> = OnceLock::new();

/// Installs the listener (once; later calls are ignored).
pub fn listen(f: impl Fn(Event) + Send + Sync + 'static) {
    let _ = LISTENER.set(Box::new(f));
}

/// Reports a stage or a heartbeat.
pub fn report(message: &str) {
    if let Some(f) = LISTENER.get() {
        f(Event::Stage(message));
    }
}

/// Reports that `done` of `total` steps are finished and `next` starts (the last report of a
/// run has `done == total`).
pub fn step(done: usize, total: usize, next: &str) {
    if let Some(f) = LISTENER.get() {
        f(Event::Step {
            done: done as u64,
            total: total as u64,
            next,
        });
    }
}

/// The steps of one run, each reported as it starts ([`step`]) and all of them at the end.
pub struct Steps {
    done: usize,
    total: usize,
}

impl Steps {
    pub fn new(total: usize) -> Steps {
        Steps { done: 0, total }
    }

    /// The step before (if any) is finished and `what` starts.
    pub fn start(&mut self, what: &str) {
        step(self.done, self.total, what);
        self.done += 1;
    }

    /// Every step is finished.
    pub fn finish(self) {
        step(self.total, self.total, "done");
    }
}

/// The prefix of the testbench's heartbeat lines (`+heartbeat=N`: every N clocks,
/// `dynrt-heartbeat frame K: C cycles, R rays`).
pub const HEARTBEAT: &str = "dynrt-heartbeat ";

/// What the listener of this test binary saw: the library's tests share one listener (there is
/// one per process), and each looks for its own reports among everyone's.
#[cfg(test)]
pub(crate) fn seen_in_tests() -> Vec<String> {
    static SEEN: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    listen(|e| {
        let line = match e {
            Event::Stage(m) => m.to_string(),
            Event::Step { done, total, next } => format!("step {done}/{total}: {next}"),
        };
        SEEN.lock().unwrap_or_else(|p| p.into_inner()).push(line);
    });
    SEEN.lock().unwrap_or_else(|p| p.into_inner()).clone()
}
