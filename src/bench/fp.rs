//! `dynrt bench fp`: per operator and format, the pipeline latency, the Virtex-II resources
//! and logic depth from `yosys synth_xilinx -family xc2v`, and the operations per second of
//! the generated RTL simulated in Verilator (a testbench streaming one vector per clock, so
//! this measures the simulator's speed on the unit, file I/O included).

use super::table::Table;
use crate::emit::fp_unit_rtl;
use crate::fp::{vectors, BinOp, Format};
use crate::sim::{run_fp_unit, Simulator};
use crate::synth::{synth_xc2v, SynthReport};
use anyhow::{bail, Context};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;

/// One operator in one format.
#[derive(Clone, Debug)]
pub struct FpUnitRow {
    pub op: BinOp,
    pub format: Format,
    pub latency: u32,
    pub synth: SynthReport,
    /// Simulated operations per second in Verilator (None when not measured).
    pub verilator_ops_per_second: Option<f64>,
    pub vectors: usize,
}

/// The operators whose hardware differs: add and sub share one unit, lt, le and eq another,
/// so one of each is enough for resources.
pub const DISTINCT_OPS: [BinOp; 5] = [BinOp::Add, BinOp::Mul, BinOp::Div, BinOp::Sqrt, BinOp::Lt];

/// Synthesizes and simulates every operator of `ops` in every format of `formats`; `vectors`
/// random operand pairs per Verilator run (0 skips the simulation). Results are checked
/// against the software model, so a wrong unit fails the benchmark instead of being timed.
pub fn bench_fp(
    ops: &[BinOp],
    formats: &[Format],
    vectors: usize,
    work_dir: &Path,
) -> anyhow::Result<Vec<FpUnitRow>> {
    let bar = ProgressBar::new((ops.len() * formats.len()) as u64);
    bar.set_style(
        ProgressStyle::with_template("bench fp {bar:30} {pos}/{len} {msg}")
            .expect("valid template"),
    );
    let mut rows = Vec::new();
    for &format in formats {
        for &op in ops {
            bar.set_message(format!("{op} {format}"));
            let unit = fp_unit_rtl(op, format)?;
            let dir = work_dir.join(&unit.top);
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            let file = dir.join(format!("{}.v", unit.top));
            std::fs::write(&file, &unit.verilog)
                .with_context(|| format!("writing {}", file.display()))?;
            let synth = synth_xc2v(&[file], &unit.top, &dir)?;
            let verilator_ops_per_second = if vectors > 0 {
                let pairs = vectors::random_pairs(format, 0xB3_7C4, vectors);
                let run = run_fp_unit(
                    op,
                    format,
                    &pairs,
                    Simulator::Verilator,
                    &dir.join("verilator"),
                )?;
                let want: Vec<u32> = pairs.iter().map(|&(a, b)| op.eval(format, a, b)).collect();
                if let Some(i) = (0..want.len()).find(|&i| want[i] != run.results[i]) {
                    bail!(
                        "{op} {format}: RTL gives {:x} for {:x?}, the model {:x}",
                        run.results[i],
                        pairs[i],
                        want[i]
                    );
                }
                Some(vectors as f64 / run.run_seconds)
            } else {
                None
            };
            rows.push(FpUnitRow {
                op,
                format,
                latency: unit.latency,
                synth,
                verilator_ops_per_second,
                vectors,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    Ok(rows)
}

pub fn fp_table(rows: &[FpUnitRow]) -> Table {
    let mut t = Table::new(&[
        "operator",
        "format",
        "latency (cycles)",
        "LUTs",
        "flip-flops",
        "MULT18X18",
        "logic depth (LUT levels)",
        "Verilator Mops/s",
    ]);
    for r in rows {
        let name = match r.op {
            BinOp::Add | BinOp::Sub => "add/sub",
            BinOp::Lt | BinOp::Le | BinOp::Eq => "compare",
            op => op.name(),
        };
        t.push(vec![
            name.to_string(),
            r.format.to_string(),
            r.latency.to_string(),
            r.synth.luts.to_string(),
            r.synth.flip_flops.to_string(),
            r.synth.mult18x18.to_string(),
            r.synth.logic_depth.to_string(),
            r.verilator_ops_per_second
                .map_or("-".into(), |v| format!("{:.2}", v / 1e6)),
        ]);
    }
    t
}
