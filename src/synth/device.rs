//! FPGA capacities, for turning synthesis cell counts into utilization percentages.
//!
//! Figures for the XC2V6000 (the SaarCOR DynRT prototype's chip) are from Xilinx DS031,
//! "Virtex-II Platform FPGAs: Complete Data Sheet", Module 1, Table 1: a 96 x 88 CLB array of
//! 33,792 slices (1,056 Kbit distributed RAM), 144 18x18 multiplier blocks, 144 18-Kbit block
//! SelectRAMs (2,592 Kbit), 12 DCMs, 1,104 user I/O. Each slice holds two 4-input LUTs and two
//! storage elements, hence 67,584 of each.

use std::fmt;

/// Resources of one FPGA.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FpgaDevice {
    pub name: &'static str,
    pub slices: u64,
    /// 4-input LUTs (two per slice).
    pub luts: u64,
    /// Flip-flops / latches (two per slice).
    pub flip_flops: u64,
    /// 18x18 multiplier blocks.
    pub mult18x18: u64,
    /// 18-Kbit block RAMs.
    pub block_rams: u64,
}

/// Xilinx Virtex-II XC2V6000 (DS031 Table 1).
pub const XC2V6000: FpgaDevice = FpgaDevice {
    name: "XC2V6000",
    slices: 33_792,
    luts: 67_584,
    flip_flops: 67_584,
    mult18x18: 144,
    block_rams: 144,
};

/// Share of a device a design uses, in percent (may exceed 100: the design does not fit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Utilization {
    pub device: FpgaDevice,
    pub luts_percent: f64,
    pub flip_flops_percent: f64,
    pub mult18x18_percent: f64,
    pub block_rams_percent: f64,
}

impl Utilization {
    pub fn fits(&self) -> bool {
        [
            self.luts_percent,
            self.flip_flops_percent,
            self.mult18x18_percent,
            self.block_rams_percent,
        ]
        .iter()
        .all(|&p| p <= 100.0)
    }
}

impl fmt::Display for Utilization {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: LUTs {:.2}%, FFs {:.2}%, MULT18X18 {:.2}%, RAMB16 {:.2}%",
            self.device.name,
            self.luts_percent,
            self.flip_flops_percent,
            self.mult18x18_percent,
            self.block_rams_percent
        )
    }
}

pub(crate) fn percent(used: u64, available: u64) -> f64 {
    if available == 0 {
        return if used == 0 { 0.0 } else { f64::INFINITY };
    }
    100.0 * used as f64 / available as f64
}
