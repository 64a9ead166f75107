//! Drives the real HDL simulators: Icarus Verilog 11 (`iverilog` + `vvp`) and Verilator 5.006.
//!
//! Contract: [`run`] compiles a self-checking / self-dumping testbench (`SimJob::top` is the
//! testbench module) and runs it with `work_dir` as the current directory, so relative
//! `$fopen` / `$readmemh` paths in the testbench resolve against `work_dir`. Compile and run are
//! timed separately. Every failure is a [`ToolError`]: the binary is missing (with the install
//! hint), the design does not compile (quoting the tool's first error lines, with the first
//! error's file and line), the simulation exits non-zero (quoting its last lines), or it
//! exceeds `SimJob::timeout` (the process group is killed). Each job builds into its own fresh
//! directory inside `work_dir`, so jobs sharing a `work_dir` never clobber each other; or,
//! with `SimJob::reuse_build`, into one kept folder per top and simulator that a job with the
//! same inputs runs again without compiling.
//! [`compile`] + [`CompiledSim::run`] split the two steps, to run one build many times.
//!
//! [`lint`] runs `verilator --lint-only -Wall` and returns structured warnings; [`vectors`]
//! reads and writes the hex vector files of the `dynrt fp` CLI contract.
//!
//! On top of [`run`], the runners of what `crate::emit` writes: [`stream_bench`] (the
//! streaming testbench every pipelined unit is checked with), [`fp_unit`] and
//! [`geometry_unit`] (one operator or geometry unit on a list of inputs), [`vga_timing`] and
//! [`processor`] (the whole processor on a scene's frames).

mod error;
pub mod fp_unit;
pub mod geometry_unit;
mod lint;
pub mod process;
pub mod processor;
pub mod stream_bench;
pub mod vectors;
pub mod vga_timing;

pub(crate) use error::error_excerpt;
pub use error::{SourceLocation, ToolError};
pub use fp_unit::{run_fp_unit, run_fp_units, FpUnitRun};
pub use geometry_unit::{
    run_intersect, run_raygen, run_shared_transform, run_transform, GeometryRun, IntersectRequest,
    IntersectResult, RayGenFrame, RayGenOutput, TransformRequest, TransformResult,
};
pub use lint::{lint, lint_with_timeout, LintReport, LintWarning};
pub use stream_bench::{run_stream_bench, StreamBenchRun};
pub use vga_timing::{run_vga_timing, VgaSample};

use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::str::FromStr;
use std::time::Duration;

use process::{describe_status, run_tool};

/// How long [`tool_version`] and other trivial tool queries may take.
const QUERY_TIMEOUT: Duration = Duration::from_secs(30);

/// Which simulator runs a job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Simulator {
    /// Icarus Verilog: `iverilog -g2012` then `vvp`. Fast to compile, slow to run.
    Icarus,
    /// Verilator 5 with `--binary --timing`: slow to compile, fast to run.
    Verilator,
}

impl Simulator {
    pub const ALL: [Simulator; 2] = [Simulator::Icarus, Simulator::Verilator];

    /// The CLI name, also the name of the compiler binary.
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Icarus => "iverilog",
            Simulator::Verilator => "verilator",
        }
    }
}

impl fmt::Display for Simulator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Simulator {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "iverilog" | "icarus" => Ok(Simulator::Icarus),
            "verilator" => Ok(Simulator::Verilator),
            other => Err(format!(
                "unknown simulator `{other}`: expected `iverilog` or `verilator`"
            )),
        }
    }
}

/// The simulator's version number, e.g. "11.0" for Icarus, "5.006" for Verilator.
pub fn tool_version(sim: Simulator) -> Result<String, ToolError> {
    let (binary, flag, marker) = match sim {
        Simulator::Icarus => ("iverilog", "-V", "version"),
        Simulator::Verilator => ("verilator", "--version", "Verilator"),
    };
    let out = run_tool(
        binary,
        "asking its version",
        Command::new(binary).arg(flag),
        QUERY_TIMEOUT,
    )?;
    // `iverilog -V` prints "Icarus Verilog version 11.0 (stable) ()" and then complains that
    // no source was given; only the first line matters.
    version_after(&out.combined(), marker).ok_or_else(|| ToolError::Parse {
        tool: binary.to_string(),
        message: format!(
            "no version number after `{marker}` in: {}",
            out.combined().lines().next().unwrap_or("")
        ),
    })
}

/// The first whitespace-separated word after `marker` that starts with a digit.
pub(crate) fn version_after(text: &str, marker: &str) -> Option<String> {
    text.lines().find_map(|line| {
        let pos = line.find(marker)?;
        line[pos + marker.len()..]
            .split_whitespace()
            .next()
            .filter(|w| w.starts_with(|c: char| c.is_ascii_digit()))
            .map(str::to_string)
    })
}

/// The waveform file format of a traced simulation ([`SimJob::trace`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TraceFormat {
    /// Value change dump (IEEE 1364): text, read by every waveform viewer, large.
    Vcd,
    /// GTKWave's Fast Signal Trace: compressed, 10-50x smaller than VCD.
    Fst,
}

impl TraceFormat {
    /// The file extension (and the CLI name).
    pub fn extension(self) -> &'static str {
        match self {
            TraceFormat::Vcd => "vcd",
            TraceFormat::Fst => "fst",
        }
    }
}

/// One simulation: sources, testbench top, where to run, how long it may take.
#[derive(Debug, Clone)]
pub struct SimJob {
    /// Current directory of the simulation; build products go in a fresh subdirectory.
    pub work_dir: PathBuf,
    /// Verilog / SystemVerilog sources (relative paths are taken from the caller's cwd).
    pub sources: Vec<PathBuf>,
    /// The testbench module.
    pub top: String,
    /// `` `define`` macros: (name, optional value).
    pub defines: Vec<(String, Option<String>)>,
    /// Run-time `+plusargs` (without the leading '+').
    pub plusargs: Vec<String>,
    /// `` `include`` search directories.
    pub include_dirs: Vec<PathBuf>,
    /// Limit for running the compiled simulation.
    pub timeout: Duration,
    /// Limit for compiling (Verilator's C++ build of a large design takes minutes).
    pub compile_timeout: Duration,
    /// Parallel C++ compile jobs for Verilator (`-j`).
    pub verilator_jobs: u32,
    /// How hard g++ optimises the Verilator model.
    pub verilator_build: VerilatorBuild,
    /// Build into `work_dir/build_<top>_<simulator>` and keep it: a later job with the same
    /// inputs (simulator and its version, sources' contents, defines, include folders, build
    /// profile) runs the kept build without compiling ([`CompiledSim::reused`]). Off: a fresh
    /// build folder per job.
    pub reuse_build: bool,
    /// Build and run so that the testbench's `$dumpfile`/`$dumpvars` write this format:
    /// Verilator is built with `--trace` or `--trace-fst`; Icarus's `vvp` gets `-fst` for FST
    /// (it writes VCD without). `None`: Verilator ignores the dump calls, and runs at full
    /// speed.
    pub trace: Option<TraceFormat>,
}

/// C++ optimisation of a Verilator model: a trade of build time against run time.
///
/// Verilator's own makefile compiles the model with `OPT_FAST=-Os` and its runtime library
/// (verilated.cpp, verilated_timing.cpp: most of a small design's build time) with
/// `OPT_GLOBAL=-Os`, and those flags come after `-CFLAGS`, so `-CFLAGS -O1` has no effect;
/// the profiles set the make variables instead. Measured in CPU seconds (user+sys of verilator,
/// make and g++; wall times on the shared 2-core machine vary 2x with load):
///
/// | design                                   | default -Os | `Quick` | `Fast` |
/// |------------------------------------------|-------------|---------|--------|
/// | 8-bit adder testbench: build             | 5.4-5.7     | 3.5-4.3 | 5.4-5.7|
/// | 300-stage 24-bit multiply pipeline: build| 6.0         | 4.1     | 7.5    |
/// | same, run 200k cycles                    | 0.06        | 0.11    | 0.04   |
///
/// Most of a small design's build is Verilator's runtime library, which `Quick` compiles at
/// -O0; `Fast` pays ~2 s more per build for a model that runs ~2.5x faster than `Quick`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VerilatorBuild {
    /// `OPT_FAST=-O1 OPT_SLOW=-O0 OPT_GLOBAL=-O0`: for unit tests and short runs.
    #[default]
    Quick,
    /// `OPT_FAST=-O2 OPT_SLOW=-O1 OPT_GLOBAL=-O2`: for long runs (whole frames).
    Fast,
}

impl VerilatorBuild {
    fn make_flags(self) -> [&'static str; 3] {
        match self {
            VerilatorBuild::Quick => ["OPT_FAST=-O1", "OPT_SLOW=-O0", "OPT_GLOBAL=-O0"],
            VerilatorBuild::Fast => ["OPT_FAST=-O2", "OPT_SLOW=-O1", "OPT_GLOBAL=-O2"],
        }
    }
}

impl SimJob {
    /// A job with defaults: 10 min run limit, 30 min compile limit, Verilator `-j 2`, `Quick`.
    pub fn new(
        work_dir: impl Into<PathBuf>,
        sources: Vec<PathBuf>,
        top: impl Into<String>,
    ) -> SimJob {
        SimJob {
            work_dir: work_dir.into(),
            sources,
            top: top.into(),
            defines: Vec::new(),
            plusargs: Vec::new(),
            include_dirs: Vec::new(),
            timeout: Duration::from_secs(600),
            compile_timeout: Duration::from_secs(1800),
            verilator_jobs: 2,
            verilator_build: VerilatorBuild::Quick,
            reuse_build: false,
            trace: None,
        }
    }

    /// See [`SimJob::trace`].
    pub fn trace(mut self, format: Option<TraceFormat>) -> SimJob {
        self.trace = format;
        self
    }

    /// See [`SimJob::reuse_build`].
    pub fn reuse_build(mut self, reuse: bool) -> SimJob {
        self.reuse_build = reuse;
        self
    }

    pub fn timeout(mut self, timeout: Duration) -> SimJob {
        self.timeout = timeout;
        self
    }

    pub fn define(mut self, name: impl Into<String>, value: Option<String>) -> SimJob {
        self.defines.push((name.into(), value));
        self
    }

    pub fn plusarg(mut self, arg: impl Into<String>) -> SimJob {
        self.plusargs.push(arg.into());
        self
    }

    pub fn verilator_build(mut self, build: VerilatorBuild) -> SimJob {
        self.verilator_build = build;
        self
    }
}

/// What a finished simulation produced.
#[derive(Debug, Clone)]
pub struct SimRun {
    pub simulator: Simulator,
    /// Wall time of compilation (iverilog, or verilator + make + g++), seconds.
    pub compile_seconds: f64,
    /// Wall time of the simulation run, seconds.
    pub run_seconds: f64,
    pub stdout: String,
    pub stderr: String,
    /// The directory holding this job's build products (vvp file or Verilator obj_dir).
    pub build_dir: PathBuf,
    /// The build of an earlier job was reused (see [`SimJob::reuse_build`]).
    pub reused_build: bool,
}

/// Compiles and runs `job` in `sim`. See the module doc for the contract.
pub fn run(sim: Simulator, job: &SimJob) -> Result<SimRun, ToolError> {
    compile(sim, job)?.run(&job.plusargs, job.timeout)
}

/// A compiled simulation, ready to run any number of times (e.g. once per frame with
/// different plusargs) without paying for compilation again.
#[derive(Debug, Clone)]
pub struct CompiledSim {
    pub simulator: Simulator,
    pub top: String,
    /// The directory the simulation runs in (relative testbench paths resolve here).
    pub work_dir: PathBuf,
    /// This build's own directory inside `work_dir`.
    pub build_dir: PathBuf,
    /// The vvp file (Icarus) or the model executable (Verilator).
    pub artifact: PathBuf,
    pub compile_seconds: f64,
    /// Everything the compiler printed (Verilator's warnings land here).
    pub compile_log: String,
    /// The build of an earlier job with the same inputs was run, nothing was compiled.
    pub reused: bool,
    /// The waveform format the testbench's dump calls write (see [`SimJob::trace`]).
    pub trace: Option<TraceFormat>,
}

/// Compiles `job` in `sim` into a fresh build directory inside `job.work_dir` (or reuses the
/// kept one, see [`SimJob::reuse_build`]).
pub fn compile(sim: Simulator, job: &SimJob) -> Result<CompiledSim, ToolError> {
    let prepared = prepare(job, sim)?;
    let stamp_path = prepared.build_dir.join(BUILD_STAMP);
    let stamp = if job.reuse_build {
        let stamp = build_stamp(sim, job, &prepared)?;
        let artifact = artifact_path(sim, job, &prepared.build_dir);
        if artifact.is_file()
            && std::fs::read_to_string(&stamp_path).ok().as_deref() == Some(&stamp)
        {
            return Ok(CompiledSim {
                simulator: sim,
                top: job.top.clone(),
                work_dir: prepared.work_dir,
                build_dir: prepared.build_dir,
                artifact,
                compile_seconds: 0.0,
                compile_log: String::new(),
                reused: true,
                trace: job.trace,
            });
        }
        // Stale or half-built: start clean, so that no old object survives a change.
        let _ = std::fs::remove_dir_all(&prepared.build_dir);
        std::fs::create_dir_all(&prepared.build_dir).map_err(|e| ToolError::Io {
            context: format!("cannot create {}", prepared.build_dir.display()),
            source: e,
        })?;
        Some(stamp)
    } else {
        None
    };
    let compiled = match sim {
        Simulator::Icarus => compile_icarus(job, prepared),
        Simulator::Verilator => compile_verilator(job, prepared),
    }?;
    if let Some(stamp) = stamp {
        std::fs::write(&stamp_path, stamp).map_err(|e| ToolError::Io {
            context: format!("writing {}", stamp_path.display()),
            source: e,
        })?;
    }
    Ok(compiled)
}

/// The file in a kept build folder that says what it was built from.
const BUILD_STAMP: &str = "dynrt-build-inputs";

/// The vvp file or the Verilator model of `job` in `build_dir`.
fn artifact_path(sim: Simulator, job: &SimJob, build_dir: &Path) -> PathBuf {
    match sim {
        Simulator::Icarus => build_dir.join(format!("{}.vvp", job.top)),
        Simulator::Verilator => build_dir.join(format!("V{}", job.top)),
    }
}

/// What a build depends on, as text: the simulator and its version, the build settings, and
/// of each source its path, length and 64-bit FNV-1a hash, without the source's provenance
/// header ([`without_provenance`]).
fn build_stamp(sim: Simulator, job: &SimJob, p: &Prepared) -> Result<String, ToolError> {
    let mut stamp = format!(
        "{sim} {}\ntop {}\ndefines {:?}\nincludes {:?}\nverilator {:?} -j{}\ntrace {:?}\n",
        tool_version(sim)?,
        job.top,
        job.defines,
        p.include_dirs,
        job.verilator_build,
        job.verilator_jobs,
        job.trace
    );
    for s in &p.sources {
        let bytes = std::fs::read(s).map_err(|e| ToolError::Io {
            context: format!("reading {}", s.display()),
            source: e,
        })?;
        let bytes = without_provenance(&bytes);
        let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        stamp.push_str(&format!("{} {} {hash:016x}\n", s.display(), bytes.len()));
    }
    Ok(stamp)
}

/// `source` without the provenance header dynrt writes at the top of a generated file (the
/// comment lines of [`crate::provenance::GeneratedBy::comment`]): it names the command line,
/// which changes with every flag (a new `--trace-start`, another `--out`), and a comment
/// changes nothing a simulator builds.
fn without_provenance(source: &[u8]) -> &[u8] {
    let first = format!("// {}", crate::provenance::HEADER_PREFIX);
    if !source.starts_with(first.as_bytes()) {
        return source;
    }
    let mut rest = source;
    while rest.starts_with(first.as_bytes()) || rest.starts_with(b"// command: ") {
        rest = match rest.iter().position(|&b| b == b'\n') {
            Some(end) => &rest[end + 1..],
            None => &[],
        };
    }
    rest
}

impl CompiledSim {
    /// Runs the compiled simulation from `work_dir` with `+plusargs`, killing it after
    /// `timeout`.
    pub fn run(&self, plusargs: &[String], timeout: Duration) -> Result<SimRun, ToolError> {
        let (tool, mut cmd) = match self.simulator {
            Simulator::Icarus => {
                let mut c = Command::new("vvp");
                // -n: $stop ends the run instead of dropping into the interactive prompt.
                c.arg("-n").arg(&self.artifact);
                // An extended argument (after the file): $dumpfile writes FST, not VCD.
                if self.trace == Some(TraceFormat::Fst) {
                    c.arg("-fst");
                }
                ("vvp".to_string(), c)
            }
            Simulator::Verilator => (format!("V{}", self.top), Command::new(&self.artifact)),
        };
        cmd.current_dir(&self.work_dir);
        for arg in plusargs {
            cmd.arg(format!("+{arg}"));
        }
        let stage = format!("simulating `{}`", self.top);
        let ran = run_tool(&tool, &stage, &mut cmd, timeout)?;
        if !ran.status.success() {
            return Err(run_failed(&tool, &self.top, &ran.status, &ran.combined()));
        }
        Ok(SimRun {
            simulator: self.simulator,
            compile_seconds: self.compile_seconds,
            run_seconds: ran.seconds,
            stdout: ran.stdout,
            stderr: ran.stderr,
            build_dir: self.build_dir.clone(),
            reused_build: self.reused,
        })
    }
}

struct Prepared {
    work_dir: PathBuf,
    sources: Vec<PathBuf>,
    include_dirs: Vec<PathBuf>,
    build_dir: PathBuf,
}

fn prepare(job: &SimJob, sim: Simulator) -> Result<Prepared, ToolError> {
    if job.sources.is_empty() {
        return Err(ToolError::BadJob(format!(
            "simulation of `{}` has no source files",
            job.top
        )));
    }
    if !is_identifier(&job.top) {
        return Err(ToolError::BadJob(format!(
            "`{}` is not a Verilog module name (letters, digits, '_', '$'; not starting with a digit)",
            job.top
        )));
    }
    std::fs::create_dir_all(&job.work_dir).map_err(|e| ToolError::Io {
        context: format!("cannot create work directory {}", job.work_dir.display()),
        source: e,
    })?;
    let work_dir = absolute(&job.work_dir)?;
    let mut sources = Vec::with_capacity(job.sources.len());
    for s in &job.sources {
        if !s.is_file() {
            return Err(ToolError::BadJob(format!(
                "source file {} does not exist (simulation of `{}`)",
                s.display(),
                job.top
            )));
        }
        sources.push(absolute(s)?);
    }
    let include_dirs = job
        .include_dirs
        .iter()
        .map(|d| absolute(d))
        .collect::<Result<Vec<_>, _>>()?;
    let build_dir = if job.reuse_build {
        work_dir.join(format!(
            "build_{}_{}",
            job.top.replace('$', "_"),
            sim.name()
        ))
    } else {
        tempfile::Builder::new()
            .prefix(&format!("build_{}_", job.top.replace('$', "_")))
            .tempdir_in(&work_dir)
            .map_err(|e| ToolError::Io {
                context: format!("cannot create a build directory in {}", work_dir.display()),
                source: e,
            })?
            .keep()
    };
    Ok(Prepared {
        work_dir,
        sources,
        include_dirs,
        build_dir,
    })
}

fn absolute(p: &Path) -> Result<PathBuf, ToolError> {
    std::path::absolute(p).map_err(|e| ToolError::Io {
        context: format!("cannot resolve path {}", p.display()),
        source: e,
    })
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$')
}

fn define_arg(name: &str, value: &Option<String>) -> String {
    match value {
        Some(v) => format!("{name}={v}"),
        None => name.to_string(),
    }
}

fn compile_error(tool: &str, top: &str, output: &str) -> ToolError {
    if let Some(problem) = error::environment_problem(output) {
        return ToolError::Environment {
            tool: tool.to_string(),
            stage: format!("building `{top}`"),
            problem,
            excerpt: process::last_lines(output, 6),
        };
    }
    let (excerpt, location) = error::error_excerpt(output, 10);
    ToolError::Compile {
        tool: tool.to_string(),
        top: top.to_string(),
        location,
        excerpt,
    }
}

fn run_failed(tool: &str, top: &str, status: &std::process::ExitStatus, output: &str) -> ToolError {
    ToolError::Run {
        tool: tool.to_string(),
        top: top.to_string(),
        status: describe_status(status),
        excerpt: process::last_lines(output, 15),
    }
}

fn compile_icarus(job: &SimJob, p: Prepared) -> Result<CompiledSim, ToolError> {
    let vvp_file = p.build_dir.join(format!("{}.vvp", job.top));
    let mut compile = Command::new("iverilog");
    compile
        .current_dir(&p.work_dir)
        .args(["-g2012", "-s", &job.top, "-o"])
        .arg(&vvp_file);
    for (name, value) in &job.defines {
        compile.arg(format!("-D{}", define_arg(name, value)));
    }
    for dir in &p.include_dirs {
        compile.arg("-I").arg(dir);
    }
    compile.args(&p.sources);
    let stage = format!("compiling `{}`", job.top);
    let built = run_tool("iverilog", &stage, &mut compile, job.compile_timeout)?;
    if !built.status.success() || !vvp_file.is_file() {
        return Err(compile_error("iverilog", &job.top, &built.combined()));
    }
    Ok(CompiledSim {
        simulator: Simulator::Icarus,
        top: job.top.clone(),
        work_dir: p.work_dir,
        build_dir: p.build_dir,
        artifact: vvp_file,
        compile_seconds: built.seconds,
        compile_log: built.combined(),
        reused: false,
        trace: job.trace,
    })
}

fn compile_verilator(job: &SimJob, p: Prepared) -> Result<CompiledSim, ToolError> {
    let exe_name = format!("V{}", job.top);
    let mut compile = Command::new("verilator");
    compile
        .current_dir(&p.work_dir)
        // --binary (new in 5.x) = --main --exe --build; --timing lets testbenches use delays
        // and event controls, which Verilator 5 runs as C++20 coroutines.
        .args(["--binary", "--timing"])
        .arg("-j")
        .arg(job.verilator_jobs.max(1).to_string())
        .args(["--top-module", &job.top])
        // Warnings are the linter's business (see `lint`); they must not stop a simulation.
        .arg("-Wno-fatal")
        // X assignments (case defaults, out-of-range) become constants: faster, deterministic.
        .args(["--x-assign", "fast"])
        .arg("--Mdir")
        .arg(&p.build_dir)
        .args(["-o", &exe_name]);
    for flag in job.verilator_build.make_flags() {
        compile.args(["-MAKEFLAGS", flag]);
    }
    match job.trace {
        Some(TraceFormat::Vcd) => compile.arg("--trace"),
        Some(TraceFormat::Fst) => compile.arg("--trace-fst"),
        None => &mut compile,
    };
    for (name, value) in &job.defines {
        compile.arg(format!("-D{}", define_arg(name, value)));
    }
    for dir in &p.include_dirs {
        compile.arg(format!("+incdir+{}", dir.display()));
    }
    compile.args(&p.sources);
    let stage = format!("compiling `{}`", job.top);
    let built = run_tool("verilator", &stage, &mut compile, job.compile_timeout)?;
    let exe = p.build_dir.join(&exe_name);
    if !built.status.success() || !exe.is_file() {
        return Err(compile_error("verilator", &job.top, &built.combined()));
    }
    Ok(CompiledSim {
        simulator: Simulator::Verilator,
        top: job.top.clone(),
        work_dir: p.work_dir,
        build_dir: p.build_dir,
        artifact: exe,
        compile_seconds: built.seconds,
        compile_log: built.combined(),
        reused: false,
        trace: job.trace,
    })
}

#[cfg(test)]
mod tests;

/// The project's FuseSoC and cocotb environment (`make deps`), in the source tree dynrt was
/// built from.
pub const EDA_VENV: &str = ".venv-eda";

/// A tool of [`EDA_VENV`] (`fusesoc`, `cocotb-config`, `python`).
pub fn eda_tool(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(EDA_VENV)
        .join("bin")
        .join(name)
}

/// The first word that starts with a digit in what `binary args` prints (`fusesoc
/// --version`: "2.4.7").
pub fn any_tool_version(binary: &Path, args: &[&str]) -> Result<String, ToolError> {
    let name = binary
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let out = run_tool(
        &name,
        "asking its version",
        Command::new(binary).args(args),
        QUERY_TIMEOUT,
    )?;
    out.combined()
        .split_whitespace()
        .find(|w| w.starts_with(|c: char| c.is_ascii_digit()))
        .map(|w| w.trim_end_matches([',', ')']).to_string())
        .ok_or_else(|| ToolError::Parse {
            tool: name,
            message: format!("no version number in: {}", out.combined().trim()),
        })
}
