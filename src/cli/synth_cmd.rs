//! `dynrt synth --unit U`: yosys `synth_xilinx -family xc2v` of one geometry unit.

use clap::Args;
use dynrt::emit::GeometryUnit;
use dynrt::fp::Format;
use dynrt::synth::{synth_unit, XC2V6000};

#[derive(Args)]
pub struct SynthArgs {
    /// transform, shared_transform, intersect or raygen.
    #[arg(long)]
    pub unit: GeometryUnit,
    /// Number format eXmY: X exponent bits (2..8), Y mantissa bits (1..23).
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
}

pub fn run(a: SynthArgs) -> anyhow::Result<i32> {
    let work = tempfile::tempdir()?;
    let r = synth_unit(a.unit, a.format, work.path())?;
    let (add, mul, div) = a.unit.paper_operators();
    let u = r.utilization(&XC2V6000);
    println!(
        "{} {} (yosys {}: {})",
        a.unit, a.format, r.yosys_version, r.command
    );
    println!("LUTs        {}", r.total_luts());
    println!("flip-flops  {}", r.flip_flops);
    println!("MULT18X18   {}", r.mult18x18);
    println!("block RAMs  {}", r.block_rams);
    println!("logic depth {} LUT levels", r.logic_depth);
    println!("deepest     {} -> {}", r.deepest_start, r.deepest_end);
    println!("XC2V6000    {u}");
    println!("paper Table 2 operators: {add} add, {mul} mul, {div} div");
    Ok(0)
}
