//! Emission: the text the tools read, from the `hw` modules and the layout. Verilog (tidied
//! rust-hdl output under clean top modules), testbenches, `$readmemh` memory images, UCF
//! constraints, and the FuseSoC core and file list of the processor (`package`). Nothing here runs a tool: running the text is `crate::sim` (simulators) and
//! `crate::synth` (yosys, nextpnr).

pub mod constraints;
pub mod fp_unit;
pub mod geometry_unit;
pub mod memory_images;
pub mod package;
pub mod processor;
pub mod stream_bench;
pub mod verilog_tidy;
pub mod vga_timing;

pub use constraints::{
    load_board, parse_board, ucf_text, write_ucf, BoardPins, ClockOffsets, Port, PortDirection,
    PortKind, UcfOptions,
};
pub use fp_unit::{fp_unit_rtl, fp_unit_testbench, fp_units_testbench, FpUnitRtl};
pub use geometry_unit::{geometry_unit_rtl, GeometryUnit, GeometryUnitRtl};
pub use memory_images::{
    bank_extents, bank_file_name, frame_update, read_memh, update_file_name, write_frame_update,
    write_memory_images, BankExtent, WordUpdate,
};
pub use stream_bench::{stream_bench_verilog, BenchPort, InputStream, OutputSink, StreamBench};
pub use vga_timing::{vga_timing_testbench, vga_timing_verilog};
