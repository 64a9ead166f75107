//! Benchmarks that print figures: accuracy of each number format against its hardware cost
//! (`dynrt bench precision`). No timed assertions: figures are measured and written out.
//!
//! - [`cost`]: per-format operator cost from yosys (cached CSV) and the datapath estimate;
//! - [`precision`]: the sweep over scenes and formats, CSV, summaries, recommendation;
//! - [`plot`]: PNG scatter plots with the Pareto front ([`pareto`]).

pub mod cost;
pub mod pareto;
pub mod plot;
pub mod precision;

pub use precision::{
    precision_sweep, recommend, summarize, write_outputs, FormatSummary, Row, SweepConfig,
};
