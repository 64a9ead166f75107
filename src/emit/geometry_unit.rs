//! Verilog of the geometry units (`crate::hw::TransformUnit`, `SharedTransformUnit`,
//! `IntersectUnit`, `RayGenUnit`) with clean top modules, and their synthesis report.
//!
//! [`geometry_unit_rtl`] produces one self-contained file: rust-hdl's flat output renamed to
//! `<top>_core` (as for the fp operators, see `fp_unit`) and a top `<unit>_<format>` (e.g.
//! `intersect_e7m16`) with one readable port per word:
//! - `transform`: `in_valid, m_0..m_11` (row-major 3x4), `x, y, z, point, diagonal, tag[15:0]` ->
//!   `out_valid, r_x, r_y, r_z, out_tag`;
//! - `shared_transform`: per client `c` in 0..4: `c<c>_valid`, `c<c>_ready` (out),
//!   `c<c>_m_0..11, c<c>_x, _y, _z, c<c>_point, c<c>_thread[7:0]` -> `out_valid,
//!   out_client[1:0], out_thread[7:0], r_x, r_y, r_z`;
//! - `intersect`: `in_valid, o_x, o_y, o_z, d_x, d_y, d_z, t_min, t_max, tag[15:0]` ->
//!   `out_valid, t, u, v, hit, out_tag`;
//! - `raygen`: `start, width[15:0], height[15:0], camera_0..11, eye_x, _y, _z, thread_valid,
//!   thread_id[7:0]` -> `thread_ready, active, issued_valid, issued_x, issued_y,
//!   issued_thread, out_valid, out_thread, dir_x, _y, _z, origin_x, _y, _z`.
//!
//! The file passes `verilator --lint-only -Wall` with the documented waiver block around the
//! generated core (see [`CORE_WAIVER`]). `crate::synth::geometry_unit::synth_unit` runs
//! `yosys synth_xilinx -family xc2v` on it (out of context: no I/O pads), the library side of
//! `dynrt synth --unit`.

use std::fmt::Write as _;

use anyhow::{Context, Result};
use rust_hdl::prelude::*;

use super::stream_bench::BenchPort;
use super::verilog_tidy::{merge_identical_modules, rename_rust_hdl_names};
use crate::dispatch_geometry_format;
use crate::fp::Format;
use crate::hw::transform_arbiter::THREAD_BITS;
use crate::hw::{
    intersect_latency, IntersectUnit, RayGenUnit, SharedTransformUnit, TransformUnit,
    SHARED_TRANSFORM_LATENCY, TAG_BITS, TRANSFORM_LATENCY,
};

/// The geometry units that can be emitted and synthesized on their own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GeometryUnit {
    /// The 3x4 transformation pipeline alone (tagged requests).
    Transform,
    /// The transformation unit behind its 4-client round-robin arbiter.
    SharedTransform,
    /// The unit-triangle intersection test.
    Intersect,
    /// Ray generation with its own transformation unit.
    RayGen,
}

impl GeometryUnit {
    pub const ALL: [GeometryUnit; 4] = [
        GeometryUnit::Transform,
        GeometryUnit::SharedTransform,
        GeometryUnit::Intersect,
        GeometryUnit::RayGen,
    ];

    /// The CLI name (`dynrt synth --unit NAME`), also the top module's prefix.
    pub fn name(self) -> &'static str {
        match self {
            GeometryUnit::Transform => "transform",
            GeometryUnit::SharedTransform => "shared_transform",
            GeometryUnit::Intersect => "intersect",
            GeometryUnit::RayGen => "raygen",
        }
    }

    /// The paper's Table 2 operator count for the unit: (add, mul, div).
    pub fn paper_operators(self) -> (u32, u32, u32) {
        match self {
            GeometryUnit::Transform | GeometryUnit::SharedTransform | GeometryUnit::RayGen => {
                (9, 9, 0)
            }
            GeometryUnit::Intersect => (3, 2, 1),
        }
    }
}

impl std::str::FromStr for GeometryUnit {
    type Err = anyhow::Error;
    fn from_str(s: &str) -> Result<Self> {
        GeometryUnit::ALL
            .into_iter()
            .find(|u| u.name() == s.trim())
            .with_context(|| {
                format!(
                    "unknown unit `{s}`: expected one of {}",
                    GeometryUnit::ALL.map(|u| u.name()).join(", ")
                )
            })
    }
}

impl std::fmt::Display for GeometryUnit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One geometry unit's Verilog.
#[derive(Debug, Clone)]
pub struct GeometryUnitRtl {
    pub unit: GeometryUnit,
    pub format: Format,
    /// Top module name, `<unit>_<format>`.
    pub top: String,
    pub verilog: String,
    /// Clocks from a taken request to its result.
    pub latency: u32,
    /// The top's ports (`clock` first).
    pub ports: Vec<BenchPort>,
}

/// Verilator warnings waived around the rust-hdl generated core, and why: rust-hdl writes
/// 32-bit literals, mask-style casts and full-width intermediates whose widths Verilog resolves
/// as intended (WIDTH; the tests compare the file bit for bit with the model in Icarus and
/// Verilator); it writes one module per instance, all in one file (DECLFILENAME); the units
/// leave some outputs of their sub-operators unread (each operator's own `out_valid` when one
/// valid bit serves a whole stage, the comparators' unused `eq`/`lt`/`le`) and constant
/// sub-operator inputs make some bits of them unused (UNUSEDSIGNAL).
pub const CORE_WAIVER: [&str; 3] = ["WIDTH", "DECLFILENAME", "UNUSEDSIGNAL"];

/// A port of the top and the core port it connects to.
struct TopPort {
    port: BenchPort,
    core: String,
}

fn input(name: impl Into<String>, width: u32, core: impl Into<String>) -> TopPort {
    TopPort {
        port: BenchPort::input(name, width),
        core: core.into(),
    }
}

fn output(name: impl Into<String>, width: u32, core: impl Into<String>) -> TopPort {
    TopPort {
        port: BenchPort::output(name, width),
        core: core.into(),
    }
}

const XYZ: [&str; 3] = ["x", "y", "z"];

fn top_ports(unit: GeometryUnit, w: u32) -> Vec<TopPort> {
    let tag = TAG_BITS as u32;
    let thread = THREAD_BITS as u32;
    let mut p = vec![input("clock", 1, "clock")];
    match unit {
        GeometryUnit::Transform => {
            p.push(input("in_valid", 1, "in_valid"));
            for k in 0..12 {
                p.push(input(format!("m_{k}"), w, format!("m__{k}")));
            }
            for (k, c) in XYZ.iter().enumerate() {
                p.push(input(*c, w, format!("v__{k}")));
            }
            p.push(input("point", 1, "point"));
            p.push(input("diagonal", 1, "diagonal"));
            p.push(input("tag", tag, "tag"));
            p.push(output("out_valid", 1, "out_valid"));
            for (k, c) in XYZ.iter().enumerate() {
                p.push(output(format!("r_{c}"), w, format!("result__{k}")));
            }
            p.push(output("out_tag", tag, "out_tag"));
        }
        GeometryUnit::SharedTransform => {
            for c in 0..4 {
                p.push(input(format!("c{c}_valid"), 1, format!("req_valid__{c}")));
                p.push(output(format!("c{c}_ready"), 1, format!("req_ready__{c}")));
                for k in 0..12 {
                    p.push(input(
                        format!("c{c}_m_{k}"),
                        w,
                        format!("req_m__{}", 12 * c + k),
                    ));
                }
                for (k, x) in XYZ.iter().enumerate() {
                    p.push(input(
                        format!("c{c}_{x}"),
                        w,
                        format!("req_v__{}", 3 * c + k),
                    ));
                }
                p.push(input(format!("c{c}_point"), 1, format!("req_point__{c}")));
                p.push(input(
                    format!("c{c}_thread"),
                    thread,
                    format!("req_thread__{c}"),
                ));
            }
            p.push(output("out_valid", 1, "out_valid"));
            p.push(output("out_client", 2, "out_client"));
            p.push(output("out_thread", thread, "out_thread"));
            for (k, c) in XYZ.iter().enumerate() {
                p.push(output(format!("r_{c}"), w, format!("result__{k}")));
            }
        }
        GeometryUnit::Intersect => {
            p.push(input("in_valid", 1, "in_valid"));
            for (k, c) in XYZ.iter().enumerate() {
                p.push(input(format!("o_{c}"), w, format!("o__{k}")));
            }
            for (k, c) in XYZ.iter().enumerate() {
                p.push(input(format!("d_{c}"), w, format!("d__{k}")));
            }
            p.push(input("t_min", w, "t_min"));
            p.push(input("t_max", w, "t_max"));
            p.push(input("tag", tag, "tag"));
            p.push(output("out_valid", 1, "out_valid"));
            p.push(output("t", w, "t"));
            p.push(output("u", w, "u"));
            p.push(output("v", w, "v"));
            p.push(output("hit", 1, "hit"));
            p.push(output("out_tag", tag, "out_tag"));
        }
        GeometryUnit::RayGen => {
            p.push(input("start", 1, "start"));
            p.push(input("width", 16, "width"));
            p.push(input("height", 16, "height"));
            for k in 0..12 {
                p.push(input(format!("camera_{k}"), w, format!("camera__{k}")));
            }
            for (k, c) in XYZ.iter().enumerate() {
                p.push(input(format!("eye_{c}"), w, format!("eye__{k}")));
            }
            p.push(input("thread_valid", 1, "thread_valid"));
            p.push(input("thread_id", thread, "thread_id"));
            p.push(output("thread_ready", 1, "thread_ready"));
            p.push(output("active", 1, "active"));
            p.push(output("issued_valid", 1, "issued_valid"));
            p.push(output("issued_x", 16, "issued_x"));
            p.push(output("issued_y", 16, "issued_y"));
            p.push(output("issued_thread", thread, "issued_thread"));
            p.push(output("out_valid", 1, "out_valid"));
            p.push(output("out_thread", thread, "out_thread"));
            for (k, c) in XYZ.iter().enumerate() {
                p.push(output(format!("dir_{c}"), w, format!("dir__{k}")));
            }
            for (k, c) in XYZ.iter().enumerate() {
                p.push(output(format!("origin_{c}"), w, format!("origin__{k}")));
            }
        }
    }
    p
}

fn core_verilog<U: Block>(mut uut: U) -> String {
    uut.connect_all();
    generate_verilog(&uut)
}

fn transform_core<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DL: usize,
>() -> String {
    core_verilog(TransformUnit::<W, E, M, S, S1, X2, T, P>::default())
}

fn shared_transform_core<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DL: usize,
>() -> String {
    core_verilog(SharedTransformUnit::<W, E, M, S, S1, X2, T, P>::default())
}

fn intersect_core<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DL: usize,
>() -> String {
    core_verilog(IntersectUnit::<W, E, M, S, S1, X2, T, P, DL>::default())
}

fn raygen_core<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DL: usize,
>() -> String {
    core_verilog(RayGenUnit::<W, E, M, S, S1, X2, T, P>::default())
}

/// The Verilog of `unit` in `fmt`. Fails with the list of supported formats for a format
/// without hardware.
pub fn geometry_unit_rtl(unit: GeometryUnit, fmt: Format) -> Result<GeometryUnitRtl> {
    let top = format!("{}_{}", unit.name(), fmt);
    let core_name = format!("{top}_core");
    let core = match unit {
        GeometryUnit::Transform => dispatch_geometry_format!(fmt, transform_core())?,
        GeometryUnit::SharedTransform => dispatch_geometry_format!(fmt, shared_transform_core())?,
        GeometryUnit::Intersect => dispatch_geometry_format!(fmt, intersect_core())?,
        GeometryUnit::RayGen => dispatch_geometry_format!(fmt, raygen_core())?,
    };
    let core = merge_identical_modules(&rename_rust_hdl_names(&core, &core_name));
    let latency = match unit {
        GeometryUnit::Intersect => intersect_latency(fmt),
        GeometryUnit::SharedTransform => SHARED_TRANSFORM_LATENCY,
        _ => TRANSFORM_LATENCY,
    };
    let ports = top_ports(unit, fmt.width());
    let (add, mul, div) = unit.paper_operators();
    let mut header = String::new();
    writeln!(
        header,
        "// {top}: dynrt geometry unit `{}` in format {fmt} (generated by dynrt).\n\
         // Latency {latency} clocks, one operation per clock. Paper Table 2: {add} add, \
         {mul} mul, {div} div.",
        unit.name()
    )?;
    let mut lint_off = String::new();
    let mut lint_on = String::new();
    for w in CORE_WAIVER {
        writeln!(lint_off, "/* verilator lint_off {w} */")?;
        writeln!(lint_on, "/* verilator lint_on {w} */")?;
    }
    let decls = ports
        .iter()
        .map(|p| {
            let dir = if p.port.output { "output" } else { "input" };
            let range = if p.port.width > 1 {
                format!("[{}:0] ", p.port.width - 1)
            } else {
                String::new()
            };
            format!("    {dir} wire {range}{}", p.port.name)
        })
        .collect::<Vec<_>>()
        .join(",\n");
    let conns = ports
        .iter()
        .map(|p| format!(".{}({})", p.core, p.port.name))
        .collect::<Vec<_>>()
        .join(",\n        ");
    let verilog = format!(
        "{header}\n\
         // Waiver for the rust-hdl generated core below (see dynrt::emit::geometry_unit::\n\
         // CORE_WAIVER): rust-hdl's literal and cast widths (WIDTH), one module per instance\n\
         // in one file (DECLFILENAME), sub-operator outputs a stage does not read\n\
         // (UNUSEDSIGNAL).\n\
         {lint_off}{core}\n{lint_on}\n\
         module {top}(\n{decls}\n);\n    \
         {core_name} core(\n        {conns}\n    );\n\
         endmodule\n"
    );
    Ok(GeometryUnitRtl {
        unit,
        format: fmt,
        top,
        verilog,
        latency,
        ports: ports.into_iter().map(|p| p.port).collect(),
    })
}
