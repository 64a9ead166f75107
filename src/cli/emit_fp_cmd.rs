//! `dynrt emit-fp`: writes the Verilog of every floating-point operator of a format, and a
//! testbench for each, into directories (`make rtl` regenerates rtl_out/fp and testbench/fp).

use anyhow::Context;
use clap::Args;
use dynrt::emit::{fp_unit_rtl, fp_unit_testbench};
use dynrt::fp::{BinOp, Format};
use dynrt::output::write_atomically;
use std::path::PathBuf;

#[derive(Args)]
pub struct EmitFpArgs {
    /// Number format eXmY: X exponent bits (2..8), Y mantissa bits (1..23).
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// Directory for the operators' Verilog.
    #[arg(long, default_value = "rtl_out/fp")]
    pub rtl: PathBuf,
    /// Directory for the testbenches (each reads vectors.hex, writes results.hex).
    #[arg(long, default_value = "testbench/fp")]
    pub testbench: PathBuf,
    /// Number of vectors the testbenches read.
    #[arg(long, default_value_t = 1000)]
    pub vectors: usize,
    /// Leave the commit out of the files' headers (for files checked into version control;
    /// `make rtl` uses it).
    #[arg(long)]
    pub stable_header: bool,
}

pub fn run(a: EmitFpArgs) -> anyhow::Result<i32> {
    dynrt::output::check_output_dir(&a.rtl, "--rtl")?;
    dynrt::output::check_output_dir(&a.testbench, "--testbench")?;
    let header = dynrt::provenance::GeneratedBy::this_run(a.stable_header).comment("//");
    for op in BinOp::ALL {
        let unit = fp_unit_rtl(op, a.format)?;
        let rtl = a.rtl.join(format!("{}.v", unit.top));
        write_atomically(&rtl, format!("{header}{}", unit.verilog).as_bytes())
            .with_context(|| format!("writing {}", rtl.display()))?;
        let tb = fp_unit_testbench(&unit, a.format, a.vectors, "vectors.hex", "results.hex");
        let tb_path = a.testbench.join(format!("tb_{}.v", unit.top));
        write_atomically(&tb_path, format!("{header}{tb}").as_bytes())
            .with_context(|| format!("writing {}", tb_path.display()))?;
        println!(
            "{} (latency {}) -> {}, {}",
            unit.top,
            unit.latency,
            rtl.display(),
            tb_path.display()
        );
    }
    Ok(0)
}
