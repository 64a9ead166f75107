//! Runs the VGA timing generator's Verilog (`crate::emit::vga_timing`) in Icarus or
//! Verilator: reset for 3 clocks, then one [`VgaSample`] per clock for `cycles` clocks,
//! written by the testbench to `vga.out.hex` and read back.

use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::emit::vga_timing::{vga_timing_testbench, vga_timing_verilog};
use crate::hw::vga::VgaMode;
use crate::sim::{self, SimJob, Simulator};

/// The outputs of the timing generator in one clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VgaSample {
    pub hsync: bool,
    pub vsync: bool,
    pub blank: bool,
    pub border: bool,
    pub frame_start: bool,
    pub x: u32,
    pub y: u32,
    pub fb_addr: u32,
}

/// Writes the generator and the testbench into `work_dir`, simulates `cycles` clocks after
/// reset in `simulator`, and returns the samples (the first is the clock after reset falls,
/// which shows pixel (0, 0)).
pub fn run_vga_timing(
    mode: &VgaMode,
    fb_width: u32,
    fb_height: u32,
    fb_base: u32,
    cycles: u64,
    simulator: Simulator,
    work_dir: &Path,
) -> Result<Vec<VgaSample>> {
    let name = "vga_timing";
    let rtl = vga_timing_verilog(mode, fb_width, fb_height, fb_base, name)?;
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("cannot create {}", work_dir.display()))?;
    let dut = work_dir.join(format!("{name}.v"));
    let tb = work_dir.join(format!("tb_{name}.v"));
    std::fs::write(&dut, rtl).with_context(|| format!("cannot write {}", dut.display()))?;
    std::fs::write(&tb, vga_timing_testbench(name, mode, cycles))
        .with_context(|| format!("cannot write {}", tb.display()))?;
    let out = work_dir.join("vga.out.hex");
    let _ = std::fs::remove_file(&out);
    let ran = sim::run(simulator, &SimJob::new(work_dir, vec![dut, tb], "tb"))?;
    let text = std::fs::read_to_string(&out).with_context(|| {
        format!(
            "{simulator} wrote no {}; its output:\n{}{}",
            out.display(),
            ran.stdout,
            ran.stderr
        )
    })?;
    let mut samples = Vec::with_capacity(cycles as usize);
    for (i, line) in text.lines().enumerate() {
        let v = line
            .split_whitespace()
            .map(|w| u32::from_str_radix(w, 16))
            .collect::<Result<Vec<u32>, _>>()
            .with_context(|| format!("{}:{}: `{line}` is not hex", out.display(), i + 1))?;
        if v.len() != 8 {
            bail!("{}:{}: expected 8 fields: `{line}`", out.display(), i + 1);
        }
        samples.push(VgaSample {
            hsync: v[0] != 0,
            vsync: v[1] != 0,
            blank: v[2] != 0,
            border: v[3] != 0,
            frame_start: v[4] != 0,
            x: v[5],
            y: v[6],
            fb_addr: v[7],
        });
    }
    if samples.len() as u64 != cycles {
        bail!(
            "{simulator}: {} samples of {cycles} in {}",
            samples.len(),
            out.display()
        );
    }
    Ok(samples)
}

#[cfg(test)]
mod tests;
