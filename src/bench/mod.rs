//! Benchmarks: speed, size and error measured on this machine and written as CSV and
//! Markdown tables under a report directory. Nothing here asserts timings; tests check only
//! that the figures are computed from real runs.

pub mod fp;
pub mod scenes;
pub mod table;
