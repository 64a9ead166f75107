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
    /// The operation (sqrt takes the first word of each vector).
    #[arg(long, value_parser = op_parser())]
    pub op: BinOp,
    /// Number format eXmY: X exponent bits (2..8), Y mantissa bits (1..23).
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// One vector a line: two hex words `a b` of the format's width.
    #[arg(long)]
    pub vectors: PathBuf,
    /// Output folder (created if missing): results.hex, one hex result a line (0 or 1 for
    /// comparisons).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Who computes: the operator's RTL in iverilog or verilator, or the software model.
    #[arg(long, value_enum, default_value = "model")]
    pub sim: FpEngine,
}

/// The results file in --out: the name the operator testbenches write (`dynrt emit-fp`).
pub(crate) const RESULTS: &str = "results.hex";

/// Every operation of [`BinOp::ALL`] as a possible value, so that `--help`, the error for an
/// unknown name and the shell completions list them all.
fn op_parser() -> impl clap::builder::TypedValueParser<Value = BinOp> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(BinOp::ALL.map(BinOp::name))
        .try_map(|name| BinOp::parse(&name).ok_or_else(|| format!("unknown operation `{name}`")))
}

pub fn run(a: FpArgs) -> anyhow::Result<i32> {
    let f = a.format;
    dynrt::output::check_output_dir(&a.out, "--out")?;
    let results_path = a.out.join(RESULTS);
    dynrt::output::check_distinct(&[("--out", &results_path)], &[("--vectors", &a.vectors)])?;
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
    let out = dynrt::output::OutputDir::create(&a.out, "--out")?;
    write_results_atomically(&results_path, &results, digits)?;
    out.keep();
    eprintln!(
        "{} {} vectors through {} {} -> {}",
        vectors.len(),
        f,
        a.op,
        format!("{:?}", a.sim).to_lowercase(),
        results_path.display()
    );
    Ok(0)
}
