//! `dynrt fp`: runs operand vectors through one floating-point operator, either the generated
//! RTL in a real simulator or the software model.

use anyhow::Context;
use clap::{Args, ValueEnum};
use dynrt::fp::{BinOp, Format};
use dynrt::sim::vectors::{read_vector_file, write_results_atomically};
use dynrt::sim::{self, run_fp_unit, Simulator};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FpEngine {
    Iverilog,
    Verilator,
    Model,
}

#[derive(Args)]
pub struct FpArgs {
    /// add, sub, mul, div, sqrt (of the first word), lt, le or eq.
    #[arg(long, value_parser = parse_op)]
    pub op: BinOp,
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// One vector a line: two hex words `a b` of the format's width.
    #[arg(long)]
    pub vectors: PathBuf,
    /// One hex result a line (0 or 1 for comparisons).
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long, value_enum, default_value = "model")]
    pub sim: FpEngine,
}

fn parse_op(s: &str) -> Result<BinOp, String> {
    BinOp::parse(s).ok_or_else(|| {
        format!("unknown operator `{s}`: expected one of add, sub, mul, div, sqrt, lt, le, eq")
    })
}

pub fn run(a: FpArgs) -> anyhow::Result<i32> {
    let f = a.format;
    dynrt::output::check_output_file(&a.out, "--out")?;
    dynrt::output::check_distinct(&[("--out", &a.out)], &[("--vectors", &a.vectors)])?;
    let vectors = read_vector_file(&a.vectors, f.width())?;
    // An empty file would give an empty result file and a report of 0 vectors: a path mix-up
    // more often than a wish.
    if vectors.is_empty() {
        anyhow::bail!(
            "vector file '{}' holds no vectors; write one vector a line, two hex words `a b` of the format's width",
            a.vectors.display()
        );
    }
    let results: Vec<u32> = match a.sim {
        FpEngine::Model => vectors.iter().map(|&(x, y)| a.op.eval(f, x, y)).collect(),
        FpEngine::Iverilog | FpEngine::Verilator => {
            let simulator = if a.sim == FpEngine::Iverilog {
                Simulator::Icarus
            } else {
                Simulator::Verilator
            };
            let work = tempfile::tempdir().context("creating a work directory")?;
            let run = run_fp_unit(a.op, f, &vectors, simulator, work.path())?;
            eprintln!(
                "{} {}: compiled in {:.1} s, simulated in {:.2} s",
                simulator,
                sim::tool_version(simulator).unwrap_or_default(),
                run.compile_seconds,
                run.run_seconds
            );
            run.results
        }
    };
    let digits = if a.op.is_comparison() {
        1
    } else {
        f.hex_digits()
    };
    write_results_atomically(&a.out, &results, digits)?;
    eprintln!(
        "{} {} vectors through {} {} -> {}",
        vectors.len(),
        f,
        a.op,
        format!("{:?}", a.sim).to_lowercase(),
        a.out.display()
    );
    Ok(0)
}
