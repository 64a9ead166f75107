//! Synthesis with Yosys 0.23 for Virtex-II (`synth_xilinx -family xc2v`), reporting cell counts,
//! logic depth and device utilization.
//!
//! Contract: [`synth_xc2v`] runs `read_verilog -sv SOURCES; synth_xilinx -family xc2v -flatten
//! -top TOP -nowidelut; stat; write_json` in `work_dir` (see [`SynthOptions`]) (script, log, `stat` text and netlist stay there
//! for inspection) under a time limit, and reads the cell counts from the flattened netlist.
//! `-flatten` makes the counts whole-design totals and lets the depth analysis see every path.
//! [`synth_xc2v_blocks`] runs the same script without `-flatten` and itemizes the resources per
//! block instance ([`blocks`]): each block is optimized on its own, so the sum is above the
//! flattened total, which optimizes across block boundaries (the processor at stop 34: 22,880
//! LUTs against 17,371); its rows are for shares.
//! Yosys marks xc2v support EXPERIMENTAL; it maps products to `MULT18X18` (17x17 -> 1,
//! 24x24 -> 4 plus adders), registers to `FD*`, logic to `LUT1`..`LUT4` + `MUXF5`..`MUXF8`,
//! adders to `MUXCY`/`XORCY`, memories to `RAMB16_*`. Logic depth is defined in [`depth`].
//!
//! Placed-and-routed timing (ECP5, nextpnr) is [`ecp5`]; its report is read in
//! [`nextpnr_report`] and tabled in [`timing_table`].

pub mod blocks;
mod depth;
pub mod device;
pub mod ecp5;
pub mod geometry_unit;
pub mod nextpnr_report;
pub mod timing_table;

pub use device::{FpgaDevice, Utilization, XC2V6000};
pub use geometry_unit::synth_unit;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::sim::ToolError;

/// Options of one synthesis run.
#[derive(Debug, Clone)]
pub struct SynthOptions {
    /// Kill yosys after this long.
    pub timeout: Duration,
    /// Insert I/O buffers (IBUF/OBUF/BUFG) as for a top-level chip design; `false` passes
    /// `-noiopad -noclkbuf` for out-of-context measurement of a block.
    pub io_pads: bool,
    /// Let ABC build 5..8-input functions from LUT4s + MUXF5..MUXF8 (yosys's default). Off by
    /// default (`-nowidelut`): yosys 0.23's xc2v wide-LUT mapping bloats logic badly. Measured:
    /// a 64-bit XOR tree takes 144 LUT4 + 135 MUXF with it, 21 LUT4 (the optimum) without;
    /// a shifter + leading-zero count + compare block takes 528 LUTs + 476 MUXF with it,
    /// 331 LUTs without. The LUT counts without it are the ones comparable with ISE's.
    pub wide_luts: bool,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            timeout: Duration::from_secs(1800),
            io_pads: true,
            wide_luts: false,
        }
    }
}

/// Cell counts and depth of a design after `synth_xilinx -family xc2v`.
#[derive(Debug, Clone)]
pub struct SynthReport {
    pub top: String,
    /// The `synth_xilinx` command as run.
    pub command: String,
    pub yosys_version: String,
    /// Logic LUTs: `LUT1`..`LUT6` plus `INV` (an inverter occupies a LUT).
    pub luts: u64,
    /// Count per LUT type (`LUT1`..`LUT6`, `INV`).
    pub lut_types: BTreeMap<String, u64>,
    /// LUTs used as distributed RAM or shift registers (`RAM16X1S` = 1, `RAM32X1S` = 2,
    /// `RAM16X1D` = 2, `SRL16*` = 1, ...).
    pub lut_ram_luts: u64,
    /// `FD*` cells.
    pub flip_flops: u64,
    /// `MULT18X18*` cells.
    pub mult18x18: u64,
    /// `RAMB16*` cells (18-Kbit block RAMs).
    pub block_rams: u64,
    /// `MUXF5`..`MUXF8` cells.
    pub muxf: u64,
    /// Carry-chain cells: `MUXCY`, `XORCY`, `MULT_AND`.
    pub carry: u64,
    /// Longest register-to-register (or port) path in LUT levels; see [`depth`].
    pub logic_depth: u32,
    /// Longest path in logic cells of any kind (LUT, MUXF, carry, multiplier).
    pub path_cells: u32,
    /// Where the path of `logic_depth` LUT levels starts and ends: registers, memories or ports
    /// as block paths (e.g. `core.mid_norm.q`); see [`depth`].
    pub deepest_start: String,
    pub deepest_end: String,
    /// Every cell type and its count.
    pub all_cells: BTreeMap<String, u64>,
    /// Yosys's `stat` output.
    pub stat_text: String,
    /// Wall time of the yosys run, seconds.
    pub seconds: f64,
    /// The flattened netlist (`write_json`).
    pub netlist_json: PathBuf,
}

impl SynthReport {
    /// All LUTs the design occupies: logic plus distributed RAM / shift registers.
    pub fn total_luts(&self) -> u64 {
        self.luts + self.lut_ram_luts
    }

    pub fn utilization(&self, device: &FpgaDevice) -> Utilization {
        Utilization {
            device: *device,
            luts_percent: device::percent(self.total_luts(), device.luts),
            flip_flops_percent: device::percent(self.flip_flops, device.flip_flops),
            mult18x18_percent: device::percent(self.mult18x18, device.mult18x18),
            block_rams_percent: device::percent(self.block_rams, device.block_rams),
        }
    }

    /// Count of one cell type (0 if absent).
    pub fn cells(&self, cell_type: &str) -> u64 {
        self.all_cells.get(cell_type).copied().unwrap_or(0)
    }
}

impl fmt::Display for SynthReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} (yosys {}: {}, {:.1} s)",
            self.top, self.yosys_version, self.command, self.seconds
        )?;
        writeln!(
            f,
            "  LUTs {} (+{} as RAM/SRL)  FFs {}  MULT18X18 {}  RAMB16 {}  MUXF {}  carry {}",
            self.luts,
            self.lut_ram_luts,
            self.flip_flops,
            self.mult18x18,
            self.block_rams,
            self.muxf,
            self.carry
        )?;
        writeln!(
            f,
            "  logic depth {} LUT levels ({} cells on the longest path), deepest from {} to {}",
            self.logic_depth, self.path_cells, self.deepest_start, self.deepest_end
        )?;
        write!(f, "  {}", self.utilization(&XC2V6000))
    }
}

/// Yosys's version number, e.g. "0.23".
pub fn yosys_version() -> Result<String, ToolError> {
    let out = crate::sim::process::run_tool(
        "yosys",
        "asking its version",
        Command::new("yosys").arg("-V"),
        Duration::from_secs(30),
    )?;
    crate::sim::version_after(&out.combined(), "Yosys").ok_or_else(|| ToolError::Parse {
        tool: "yosys".into(),
        message: format!("no version in `{}`", out.combined().trim()),
    })
}

/// Synthesizes `top` from `sources` for Virtex-II with default options.
pub fn synth_xc2v(
    sources: &[PathBuf],
    top: &str,
    work_dir: &Path,
) -> Result<SynthReport, ToolError> {
    synth_xc2v_with(sources, top, work_dir, &SynthOptions::default())
}

pub fn synth_xc2v_with(
    sources: &[PathBuf],
    top: &str,
    work_dir: &Path,
    options: &SynthOptions,
) -> Result<SynthReport, ToolError> {
    let run = run_yosys(sources, top, work_dir, options, true)?;
    let module = run
        .netlist
        .modules
        .get(top)
        .ok_or_else(|| ToolError::Parse {
            tool: "yosys".into(),
            message: format!("{} has no module `{top}`", run.json_file.display()),
        })?;
    let deepest = depth::longest_paths(module).map_err(|m| ToolError::Parse {
        tool: "yosys".into(),
        message: format!("netlist of `{top}`: {m}"),
    })?;
    let mut all_cells = BTreeMap::new();
    for c in module.cells.values() {
        *all_cells.entry(c.cell_type.clone()).or_insert(0u64) += 1;
    }
    Ok(summarize(
        top,
        run.command,
        run.yosys_version,
        all_cells,
        deepest,
        run.stat_text,
        run.seconds,
        run.json_file,
    ))
}

/// Synthesizes `top` like [`synth_xc2v_with`] but keeps the hierarchy, and itemizes the
/// resources of every block instance down to `max_depth` levels below the top.
pub fn synth_xc2v_blocks(
    sources: &[PathBuf],
    top: &str,
    work_dir: &Path,
    options: &SynthOptions,
    max_depth: usize,
) -> Result<blocks::BlockReport, ToolError> {
    let run = run_yosys(sources, top, work_dir, options, false)?;
    let rows = blocks::itemize(&run.netlist, top, max_depth).map_err(|m| ToolError::Parse {
        tool: "yosys".into(),
        message: format!("{}: {m}", run.json_file.display()),
    })?;
    Ok(blocks::BlockReport {
        top: top.to_string(),
        command: run.command,
        yosys_version: run.yosys_version,
        rows,
        seconds: run.seconds,
    })
}

/// What one yosys run left: the command, the `stat` text and the netlist.
struct YosysRun {
    command: String,
    yosys_version: String,
    stat_text: String,
    netlist: depth::Netlist,
    json_file: PathBuf,
    seconds: f64,
}

fn run_yosys(
    sources: &[PathBuf],
    top: &str,
    work_dir: &Path,
    options: &SynthOptions,
    flatten: bool,
) -> Result<YosysRun, ToolError> {
    if sources.is_empty() {
        return Err(ToolError::BadJob(format!(
            "synthesis of `{top}`: no source files"
        )));
    }
    if top.is_empty()
        || !top
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$')
    {
        return Err(ToolError::BadJob(format!(
            "synthesis: `{top}` is not a plain Verilog module name"
        )));
    }
    let yosys_version = yosys_version()?;
    std::fs::create_dir_all(work_dir).map_err(|e| ToolError::Io {
        context: format!("cannot create {}", work_dir.display()),
        source: e,
    })?;
    let abs = |p: &Path| {
        std::path::absolute(p).map_err(|e| ToolError::Io {
            context: format!("cannot resolve {}", p.display()),
            source: e,
        })
    };
    let work_dir = abs(work_dir)?;
    let mut read = String::from("read_verilog -sv");
    for s in sources {
        if !s.is_file() {
            return Err(ToolError::BadJob(format!(
                "synthesis of `{top}`: source file {} does not exist",
                s.display()
            )));
        }
        let path = abs(s)?;
        let text = path.to_string_lossy().into_owned();
        if text.contains(|c: char| c.is_whitespace() || c == '"' || c == ';') {
            return Err(ToolError::BadJob(format!(
                "synthesis of `{top}`: yosys scripts cannot name {text} (whitespace, quote or ';' in the path); move the file"
            )));
        }
        read.push(' ');
        read.push_str(&text);
    }
    let stem = format!(
        "synth_{}{}",
        top.replace('$', "_"),
        if flatten { "" } else { "_blocks" }
    );
    let stat_file = work_dir.join(format!("{stem}.stat.txt"));
    let json_file = work_dir.join(format!("{stem}.json"));
    let log_file = work_dir.join(format!("{stem}.log"));
    let script_file = work_dir.join(format!("{stem}.ys"));
    for stale in [&stat_file, &json_file] {
        let _ = std::fs::remove_file(stale);
    }
    let mut command = format!(
        "synth_xilinx -family xc2v{} -top {top}",
        if flatten { " -flatten" } else { "" }
    );
    if !options.io_pads {
        command.push_str(" -noiopad -noclkbuf");
    }
    if !options.wide_luts {
        command.push_str(" -nowidelut");
    }
    let script = format!(
        "{read}\n\
         {command}\n\
         tee -q -o {stat} stat\n\
         write_json {json}\n",
        stat = stat_file.display(),
        json = json_file.display(),
    );
    std::fs::write(&script_file, &script).map_err(|e| ToolError::Io {
        context: format!("cannot write {}", script_file.display()),
        source: e,
    })?;

    let mut cmd = Command::new("yosys");
    cmd.current_dir(&work_dir)
        .arg("-q")
        .arg("-l")
        .arg(&log_file)
        .arg("-s")
        .arg(&script_file);
    let out = crate::sim::process::run_tool(
        "yosys",
        &format!("synthesizing `{top}`"),
        &mut cmd,
        options.timeout,
    )?;
    if !out.status.success() || !json_file.is_file() {
        let log = std::fs::read_to_string(&log_file).unwrap_or_default();
        let text = crate::sim::process::combine(&out.combined(), &log);
        let (excerpt, location) = crate::sim::error_excerpt(&text, 10);
        return Err(ToolError::Compile {
            tool: "yosys".into(),
            top: top.to_string(),
            location,
            excerpt,
        });
    }
    let stat_text = std::fs::read_to_string(&stat_file).unwrap_or_default();
    let json = std::fs::read(&json_file).map_err(|e| ToolError::Io {
        context: format!("cannot read {}", json_file.display()),
        source: e,
    })?;
    let netlist: depth::Netlist = serde_json::from_slice(&json).map_err(|e| ToolError::Parse {
        tool: "yosys".into(),
        message: format!("{}: {e}", json_file.display()),
    })?;
    Ok(YosysRun {
        command,
        yosys_version,
        stat_text,
        netlist,
        json_file,
        seconds: out.seconds,
    })
}

fn is_lut(t: &str) -> bool {
    t == "INV" || (t.starts_with("LUT") && t[3..].parse::<u32>().is_ok())
}

/// The resources a set of Virtex-II primitives takes (the columns of the device's budget).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Resources {
    /// Logic LUTs (`LUT1`..`LUT6`, `INV`).
    pub luts: u64,
    /// LUTs used as distributed RAM or shift registers.
    pub lut_ram_luts: u64,
    pub flip_flops: u64,
    pub mult18x18: u64,
    pub block_rams: u64,
}

impl Resources {
    /// The resources of `count` cells of each primitive type.
    pub fn of_cells(cells: &BTreeMap<String, u64>) -> Self {
        let mut r = Resources::default();
        for (t, &n) in cells {
            r.add_cell(t, n);
        }
        r
    }

    /// Adds `n` cells of primitive type `t` (types that are none of the columns add nothing).
    pub fn add_cell(&mut self, t: &str, n: u64) {
        if is_lut(t) {
            self.luts += n;
        } else if t.starts_with("SRL") || depth::is_distributed_ram(t) {
            self.lut_ram_luts += lut_ram_size(t) * n;
        } else if depth::is_flip_flop(t) {
            self.flip_flops += n;
        } else if t.starts_with("MULT18X18") {
            self.mult18x18 += n;
        } else if t.starts_with("RAMB16") {
            self.block_rams += n;
        }
    }

    pub fn add(&mut self, other: &Resources) {
        self.luts += other.luts;
        self.lut_ram_luts += other.lut_ram_luts;
        self.flip_flops += other.flip_flops;
        self.mult18x18 += other.mult18x18;
        self.block_rams += other.block_rams;
    }

    /// All LUTs: logic plus distributed RAM / shift registers.
    pub fn total_luts(&self) -> u64 {
        self.luts + self.lut_ram_luts
    }
}

/// LUTs a distributed RAM or shift-register primitive occupies on Virtex-II.
fn lut_ram_size(t: &str) -> u64 {
    if t.starts_with("SRL") {
        return 1;
    }
    // RAM<depth>X<width><S|D>: 16 entries per LUT; dual-port doubles it.
    let Some(rest) = t.strip_prefix("RAM") else {
        return 0;
    };
    let Some((d, tail)) = rest.split_once('X') else {
        return 0;
    };
    let (Ok(depth), Some(w_end)) = (d.parse::<u64>(), tail.find(|c: char| !c.is_ascii_digit()))
    else {
        return 0;
    };
    let width: u64 = tail[..w_end].parse().unwrap_or(1);
    let dual = if tail[w_end..].starts_with('D') { 2 } else { 1 };
    depth.div_ceil(16) * width * dual
}

#[allow(clippy::too_many_arguments)]
fn summarize(
    top: &str,
    command: String,
    yosys_version: String,
    all_cells: BTreeMap<String, u64>,
    deepest: depth::Depth,
    stat_text: String,
    seconds: f64,
    netlist_json: PathBuf,
) -> SynthReport {
    let sum = |pred: &dyn Fn(&str) -> bool| -> u64 {
        all_cells
            .iter()
            .filter(|(t, _)| pred(t))
            .map(|(_, n)| n)
            .sum()
    };
    let lut_types = all_cells
        .iter()
        .filter(|(t, _)| is_lut(t))
        .map(|(t, n)| (t.clone(), *n))
        .collect();
    let r = Resources::of_cells(&all_cells);
    SynthReport {
        top: top.to_string(),
        command,
        yosys_version,
        luts: r.luts,
        lut_types,
        lut_ram_luts: r.lut_ram_luts,
        flip_flops: r.flip_flops,
        mult18x18: r.mult18x18,
        block_rams: r.block_rams,
        muxf: sum(&|t| t.starts_with("MUXF")),
        carry: sum(&|t| matches!(t, "MUXCY" | "XORCY" | "MULT_AND")),
        logic_depth: deepest.logic_depth,
        path_cells: deepest.path_cells,
        deepest_start: deepest.start,
        deepest_end: deepest.end,
        all_cells,
        stat_text,
        seconds,
        netlist_json,
    }
}

#[cfg(test)]
mod tests;
