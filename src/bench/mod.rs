//! Benchmarks: speed, size, hardware cost and error measured on this machine and written as
//! CSV, Markdown and PNG reports. Nothing here asserts timings.
//!
//! - [`fp`]: FP operators' latency, yosys xc2v resources and Verilator speed (`dynrt bench fp`);
//! - [`scenes`]: per bundled scene, tree build, layout size, renderer speed and golden error
//!   (`dynrt bench scenes`);
//! - [`paper`]: the scenes of the paper's Table 3, golden frames, memory against the banks,
//!   the processor's Verilator runs and fps beside the paper's (`dynrt bench paper`);
//! - [`trees`]: kd-tree size and traversal work with and without the node budget
//!   (`dynrt bench trees`);
//! - [`cost`]: per-format operator cost from yosys (cached CSV) and the datapath estimate;
//! - [`precision`]: the sweep over scenes and formats, CSV, summaries, recommendation
//!   (`dynrt bench precision`);
//! - [`plot`]: PNG scatter plots with the Pareto front ([`pareto`]);
//! - [`table`]: CSV and Markdown tables.

pub mod cost;
pub mod fp;
pub mod paper;
pub mod pareto;
pub mod plot;
pub mod precision;
pub mod scenes;
pub mod table;
pub mod trees;

pub use precision::{
    precision_sweep, recommend, summarize, write_outputs, FormatSummary, Row, SweepConfig,
};
