//! Emission of Verilog, testbenches and their inputs from the `hw` modules.

pub mod fp_unit;
pub mod fp_unit_run;
pub mod verilog_tidy;

pub use fp_unit::{fp_unit_rtl, fp_unit_testbench, fp_units_testbench, FpUnitRtl};
pub use fp_unit_run::{run_fp_unit, run_fp_units, FpUnitRun};
