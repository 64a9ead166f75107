//! dynrt: turns a 3D scene into a real-time ray tracing processor after the SaarCOR DynRT
//! prototype (Schmittler et al., Graphics Hardware 2004): synthesizable Verilog, testbenches,
//! memory images and constraints, plus a bit-exact software golden model.
//!
//! Data flows one way (see docs/ARCHITECTURE.md, "Data flow"):
//! `scene -> accel -> layout -> model / hw -> emit -> sim -> compare`, with `synth` beside
//! `sim`. Outside its tests a stage imports only the stages before it: `emit` writes text and
//! runs nothing, `sim` runs the simulators on that text and `synth` runs yosys and nextpnr on
//! it (both through `sim::process`). `fp` (the number format), `units` (the arithmetic
//! sequences the hardware and the golden model share), `input`, `output` and `provenance` serve every stage.
//! `hw` and `model` never import each other: both take their arithmetic from `units`, and
//! they meet in the tests. `flow`, `demo`, `bench` and `stress` drive whole runs and may use
//! any stage; nothing here imports the CLI. Tests may reach later stages to check a stage's
//! output (an `emit` test loads its memory images in a simulator).

pub mod accel;
pub mod bench;
pub mod bundled;
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
pub mod progress;
pub mod provenance;
pub mod report;
pub mod scene;
pub mod sim;
pub mod stress;
pub mod synth;
pub mod tables;
pub mod units;
