//! Emission of Verilog, testbenches and their inputs from the `hw` modules.

pub mod constraints;
pub mod fp_unit;
pub mod fp_unit_run;
pub mod geometry_unit;
pub mod geometry_unit_run;
#[cfg(test)]
mod geometry_unit_tests;
pub mod memory_images;
pub mod processor;
pub mod processor_run;
pub mod stream_bench;
pub mod verilog_tidy;
pub mod vga_timing;

pub use constraints::{
    load_board, parse_board, ucf_text, write_ucf, BoardPins, ClockOffsets, Port, PortDirection,
    PortKind, UcfOptions,
};
pub use fp_unit::{fp_unit_rtl, fp_unit_testbench, fp_units_testbench, FpUnitRtl};
pub use fp_unit_run::{run_fp_unit, run_fp_units, FpUnitRun};
pub use geometry_unit::{geometry_unit_rtl, synth_unit, GeometryUnit, GeometryUnitRtl};
pub use geometry_unit_run::{
    run_intersect, run_raygen, run_shared_transform, run_transform, GeometryRun, IntersectRequest,
    IntersectResult, RayGenFrame, RayGenOutput, TransformRequest, TransformResult,
};
pub use memory_images::{
    bank_extents, bank_file_name, frame_update, read_memh, update_file_name, write_frame_update,
    write_memory_images, BankExtent, WordUpdate,
};
pub use stream_bench::{
    run_stream_bench, stream_bench_verilog, BenchPort, InputStream, OutputSink, StreamBench,
    StreamBenchRun,
};
pub use vga_timing::{run_vga_timing, vga_timing_testbench, vga_timing_verilog, VgaSample};
