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
    /// Output folder (created if missing): the operators' Verilog in rtl/, a testbench each in
    /// testbench/ (each reads vectors.hex, writes results.hex).
    #[arg(long, value_name = "DIR", default_value = "out/fp")]
    pub out: PathBuf,
    /// Folder for the Verilog instead of --out's rtl/ (the repository keeps it apart from the
    /// testbenches: `make rtl` writes rtl_out/fp).
    #[arg(long, value_name = "DIR", hide = true)]
    pub rtl: Option<PathBuf>,
    /// Folder for the testbenches instead of --out's testbench/ (`make rtl`: testbench/fp).
    #[arg(long, value_name = "DIR", hide = true)]
    pub testbench: Option<PathBuf>,
    /// Number of vectors the testbenches read.
    #[arg(long, default_value_t = 1000)]
    pub vectors: usize,
    /// Leave the commit out of the files' headers (for files checked into version control;
    /// `make rtl` uses it).
    #[arg(long)]
    pub stable_header: bool,
}

pub fn run(a: EmitFpArgs) -> anyhow::Result<i32> {
    let (rtl_dir, rtl_flag) = match &a.rtl {
        Some(d) => (d.clone(), "--rtl"),
        None => (a.out.join("rtl"), "--out"),
    };
    let (tb_dir, tb_flag) = match &a.testbench {
        Some(d) => (d.clone(), "--testbench"),
        None => (a.out.join("testbench"), "--out"),
    };
    dynrt::output::check_output_dir(&rtl_dir, rtl_flag)?;
    dynrt::output::check_output_dir(&tb_dir, tb_flag)?;
    // Only when --out holds a part does it exist: `--rtl A --testbench B` writes nothing there.
    let out = (a.rtl.is_none() || a.testbench.is_none())
        .then(|| dynrt::output::OutputDir::create(&a.out, "--out"))
        .transpose()?;
    let rtl_out = dynrt::output::OutputDir::create(&rtl_dir, rtl_flag)?;
    let tb_out = dynrt::output::OutputDir::create(&tb_dir, tb_flag)?;
    let header = dynrt::provenance::GeneratedBy::this_run(a.stable_header).comment("//");
    for op in BinOp::ALL {
        let unit = fp_unit_rtl(op, a.format)?;
        let rtl = rtl_dir.join(format!("{}.v", unit.top));
        write_atomically(&rtl, format!("{header}{}", unit.verilog).as_bytes())
            .with_context(|| format!("writing {}", rtl.display()))?;
        let tb = fp_unit_testbench(
            &unit,
            a.format,
            a.vectors,
            "vectors.hex",
            super::fp_cmd::RESULTS,
        );
        let tb_path = tb_dir.join(format!("tb_{}.v", unit.top));
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
    rtl_out.keep();
    tb_out.keep();
    if let Some(o) = out {
        o.keep();
    }
    Ok(0)
}
