//! Emission of Verilog, testbenches and their inputs from the `hw` modules.

pub mod fp_unit;

pub use fp_unit::{fp_unit_rtl, fp_unit_testbench, FpUnitRtl};
