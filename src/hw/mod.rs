//! Hardware: rust-hdl modules of the ray tracing processor, one file per unit.
//! They are turned into Verilog by `crate::emit`.
//!
//! Geometry units (the paper's Table 2 counts in brackets): [`TransformUnit`] (9 mul, 9 add),
//! shared by several clients through [`SharedTransformUnit`]'s round-robin arbiter;
//! [`IntersectUnit`] (1 div, 2 mul, 3 add, plus 5 comparators); [`RayGen`], the ray-generation
//! client of the transform unit.
//!
//! Display: [`VgaTiming`], the VGA sync and frame-buffer address generator in the pixel clock
//! domain (modes [`VgaMode::VGA_640X480_60`], [`VgaMode::XGA_1024X768_60`]), and
//! [`VgaDisplay`], which reads the frame buffer with it and drives the monitor.

pub mod cache;
pub mod channel_byte;
pub mod delay;
pub mod display;
pub mod engine;
pub mod fp;
pub mod geometry_formats;
pub mod intersect;
pub mod list_unit;
pub mod lut_ram;
pub mod no_collision_ram;
pub mod ports;
pub mod processor;
pub mod ray_store;
pub mod raygen;
pub mod shade_unit;
#[cfg(test)]
pub(crate) mod sim_harness;
pub mod sync_fifo;
pub mod transform;
pub mod transform_arbiter;
pub mod traversal_unit;
pub mod triangle_tester;
pub mod vga;

pub use channel_byte::{ChannelByte, CHANNEL_BYTE_LATENCY};
pub use delay::{Delay, DelayLine};
pub use display::VgaDisplay;
pub use intersect::{intersect_latency, IntersectUnit};
pub use list_unit::ListUnit;
pub use lut_ram::LutRam;
pub use no_collision_ram::NoCollisionRam;
pub use raygen::{RayGen, RayGenUnit};
pub use shade_unit::{ShadeConfig, ShadeUnit};
pub use sync_fifo::SyncFifo;
pub use transform::{TransformUnit, TRANSFORM_LATENCY};
pub use transform_arbiter::{SharedTransformUnit, SHARED_TRANSFORM_LATENCY, TRANSFORM_CLIENTS};
pub use traversal_unit::TraversalUnit;
pub use triangle_tester::TriangleTester;
pub use vga::{VgaError, VgaMode, VgaPlacement, VgaTiming};

/// Width of the tag that travels with every request through a geometry unit (client id and
/// thread id; the unit only carries it).
pub const TAG_BITS: usize = 16;
pub mod program;
