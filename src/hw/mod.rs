//! Hardware: rust-hdl modules of the ray tracing processor, one file per unit.
//! They are turned into Verilog by `crate::emit`.

pub mod fp;
