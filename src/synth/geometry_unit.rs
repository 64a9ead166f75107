//! Synthesis of one geometry unit (`crate::emit::geometry_unit`) for Virtex-II, out of
//! context: the library side of `dynrt synth --unit`.

use std::path::Path;

use anyhow::{bail, Context, Result};

use super::{synth_xc2v_with, SynthOptions, SynthReport};
use crate::emit::geometry_unit::{geometry_unit_rtl, GeometryUnit};
use crate::fp::Format;

/// Synthesizes `unit` in `fmt` for Virtex-II (`yosys synth_xilinx -family xc2v`, out of
/// context: no I/O pads), in `work_dir` (created; the Verilog, script, log and netlist stay
/// there). The library side of `dynrt synth --unit transform|intersect|raygen [--format]`.
pub fn synth_unit(unit: GeometryUnit, fmt: Format, work_dir: &Path) -> Result<SynthReport> {
    let rtl = geometry_unit_rtl(unit, fmt)?;
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("cannot create {}", work_dir.display()))?;
    let path = work_dir.join(format!("{}.v", rtl.top));
    std::fs::write(&path, &rtl.verilog)
        .with_context(|| format!("cannot write {}", path.display()))?;
    let options = SynthOptions {
        io_pads: false,
        ..Default::default()
    };
    let report = synth_xc2v_with(&[path], &rtl.top, &work_dir.join("yosys"), &options)?;
    if report.top != rtl.top {
        bail!("yosys reported top {} for {}", report.top, rtl.top);
    }
    Ok(report)
}
