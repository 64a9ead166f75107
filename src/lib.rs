//! dynrt: turns a 3D scene into a real-time ray tracing processor after the SaarCOR DynRT
//! prototype (Schmittler et al., Graphics Hardware 2004): synthesizable Verilog, testbenches,
//! memory images and constraints, plus a bit-exact software golden model.
//!
//! Data flows one way (see docs/ARCHITECTURE.md, "Data flow"):
//! `scene -> accel -> layout -> model / hw -> emit -> sim -> compare`.
//! `fp` (the number format) is shared by every stage; nothing here imports the CLI, and `hw`
//! never imports `model` (they meet in tests).

pub mod accel;
pub mod bench;
pub mod compare;
pub mod demo;
pub mod emit;
pub mod flow;
pub mod fp;
pub mod hw;
pub mod input;
pub mod layout;
pub mod model;
pub mod output;
pub mod scene;
pub mod sim;
pub mod stress;
pub mod synth;
pub mod units;
