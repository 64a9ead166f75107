//! Runs the generated processor on a scene's frames in Icarus or Verilator: writes the RTL,
//! the testbench and the memory images into a directory, simulates, and reads back every
//! frame buffer and the cycle counters.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};

use crate::emit::memory_images::{write_frame_update, write_memory_images};
use crate::emit::package::cocotb_files;
use crate::emit::processor::{
    display_mode, processor_rtl, processor_testbench, ProcessorParams, TestbenchFrames,
    TRACE_DEFINE,
};
use crate::hw::processor::TopPort;
use crate::hw::program::Program;
use crate::layout::Layout;
use crate::output::write_atomically;
use crate::provenance::GeneratedBy;
use crate::sim::{self, SimJob, Simulator, TraceFormat, VerilatorBuild};

/// One simulated frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SimFrame {
    /// `0x00RRGGBB` per pixel, row by row.
    pub pixels: Vec<u32>,
    pub cycles: u64,
    pub instructions: u64,
    /// Clocks in which the TransformUnit, the IntersectUnit took an input.
    pub transform_busy: u64,
    pub intersect_busy: u64,
    /// Clocks in which the traversal unit started a node decision.
    pub traversal_busy: u64,
    /// Clocks in which ray generation's, instance entry's and shading's (world normals)
    /// requests took the TransformUnit.
    pub raygen_busy: u64,
    pub instance_busy: u64,
    pub shading_busy: u64,
    /// Triangle tests whose words came from the triangle cache, and from banks 2 and 3.
    pub tri_cache_hits: u64,
    pub tri_cache_misses: u64,
    pub node_cache_hits: u64,
    pub node_cache_misses: u64,
    pub instance_cache_hits: u64,
    pub instance_cache_misses: u64,
    /// Thread-clocks waiting for an issue slot and asleep in a coprocessor wait: the bits of
    /// the scheduler's `ready` and `asleep` masks, added up every clock of the frame.
    pub ready_thread_clocks: u64,
    pub asleep_thread_clocks: u64,
    /// Words read from each bank (`layout::BANK_NAMES`), counted by the testbench's memory.
    pub bank_reads: [u64; 6],
}

/// What a processor simulation produced.
#[derive(Clone, Debug)]
pub struct ProcessorSim {
    pub frames: Vec<SimFrame>,
    pub compile_seconds: f64,
    pub run_seconds: f64,
    /// The build folder of an earlier run with the same Verilog was run again.
    pub reused_build: bool,
    pub tool_version: String,
    /// With [`SimRun::trace`]: the waveform file written.
    pub trace: Option<PathBuf>,
    /// With `capture_vga`: the visible pixels of the display's next frame after the last
    /// rendered one, `0xRRGGBB` in raster order.
    pub vga: Option<Vec<u32>>,
}

/// Writes everything a simulation of `layouts` (frame 0, 1, ...) needs into `dir`: the
/// processor Verilog (`rtl/dynrt_processor.v`), the testbench (`testbench/tb.v`), the
/// memory images (`mem/`) and the cocotb test (`cocotb/`).
pub fn write_processor_files(
    program: &Program,
    layouts: &[Layout],
    params: ProcessorParams,
    scene_name: &str,
    cycle_limit: u64,
    dir: &Path,
    generated_by: &GeneratedBy,
) -> Result<ProcessorFiles> {
    let first = layouts.first().context("no frame to simulate")?;
    let (rtl_dir, tb_dir, mem_dir) = (dir.join("rtl"), dir.join("testbench"), dir.join("mem"));
    for d in [&rtl_dir, &tb_dir, &mem_dir] {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    let rtl = processor_rtl(program, params, scene_name, generated_by)?;
    let rtl_path = rtl_dir.join(format!("{}.v", crate::emit::processor::PROCESSOR_TOP));
    write_atomically(&rtl_path, rtl.verilog.as_bytes())
        .with_context(|| format!("writing {}", rtl_path.display()))?;
    let mut mem = write_memory_images(first, &mem_dir, generated_by)?;
    let mut updates = Vec::new();
    for (k, pair) in layouts.windows(2).enumerate() {
        let files = write_frame_update(&pair[0], &pair[1], k as u32 + 1, &mem_dir, generated_by)?;
        mem.extend(files.iter().map(|(_, p)| p.clone()));
        updates.push(
            files
                .into_iter()
                .map(|(bank, p)| {
                    (
                        bank,
                        p.file_name()
                            .unwrap_or_default()
                            .to_string_lossy()
                            .into_owned(),
                    )
                })
                .collect(),
        );
    }
    let mut bank_words = [0usize; 6];
    for l in layouts {
        for (b, w) in bank_words.iter_mut().enumerate() {
            *w = (*w).max(l.banks[b].len());
        }
    }
    let frames = TestbenchFrames {
        bank_words,
        updates,
        frame_buffer: first.info.frame_buffer,
        pixels: first.info.width * first.info.height,
        cycle_limit,
        vga: display_mode(first.info.width, first.info.height)?,
    };
    let cocotb_dir = dir.join("cocotb");
    std::fs::create_dir_all(&cocotb_dir)
        .with_context(|| format!("cannot create {}", cocotb_dir.display()))?;
    for (name, text) in cocotb_files(params.mem_latency, &frames, generated_by) {
        let p = cocotb_dir.join(name);
        write_atomically(&p, text.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    let tb_path = tb_dir.join("tb.v");
    write_atomically(
        &tb_path,
        processor_testbench(params, &frames, &rtl.ports, generated_by)?.as_bytes(),
    )
    .with_context(|| format!("writing {}", tb_path.display()))?;
    Ok(ProcessorFiles {
        rtl: rtl_path,
        testbench: tb_path,
        mem,
        ports: rtl.ports,
        frames,
    })
}

/// What [`write_processor_files`] wrote: the two Verilog files, the memory images (frame 0's
/// banks, then the frames' updates), and the processor's top ports (for the constraints
/// file).
#[derive(Clone, Debug)]
pub struct ProcessorFiles {
    pub rtl: PathBuf,
    pub testbench: PathBuf,
    pub mem: Vec<PathBuf>,
    pub ports: Vec<TopPort>,
    /// What the testbench knows about the frames (bank sizes, updates, frame buffer).
    pub frames: TestbenchFrames,
}

/// How to run a processor simulation.
#[derive(Clone, Copy, Debug)]
pub struct SimRun {
    pub sim: Simulator,
    /// Clocks a frame may take before the testbench stops with a timeout error.
    pub cycle_limit: u64,
    /// Also capture one frame of the display's output after the last rendered frame (about
    /// 420,000 pixel clocks: minutes in Icarus).
    pub capture_vga: bool,
    /// Dump the waveforms of every signal for a window of clocks.
    pub trace: Option<TraceWindow>,
}

/// Waveforms of a window of clocks: the testbench counts clocks from the start of the run
/// (frame after frame) and dumps from the rising edge that begins clock `start` to the one
/// that begins clock `end` (the end of the run without `end`). In the testbench's time, clock
/// `c` begins at `10 * c - 5` ns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceWindow {
    pub format: TraceFormat,
    pub start: u64,
    pub end: Option<u64>,
}

impl TraceWindow {
    /// The file the waveforms go to, in the simulation's folder.
    pub fn file_name(&self) -> String {
        format!("trace.{}", self.format.extension())
    }

    /// Refuses an empty window, naming the flags.
    pub fn check(&self) -> Result<()> {
        if let Some(end) = self.end {
            if end <= self.start {
                bail!(
                    "--trace-end {end} is not after --trace-start {}: give a window of at least one clock, e.g. --trace-start {} --trace-end {}",
                    self.start,
                    self.start,
                    self.start + 1000
                );
            }
        }
        Ok(())
    }
}

/// Simulates the processor for `program` on `layouts` as `run` says, in `dir`. The build
/// folder `dir/build_tb_<simulator>` is kept and reused while the Verilog does not change.
pub fn simulate_processor(
    program: &Program,
    layouts: &[Layout],
    params: ProcessorParams,
    scene_name: &str,
    run: SimRun,
    dir: &Path,
    generated_by: &GeneratedBy,
) -> Result<ProcessorSim> {
    let SimRun {
        sim,
        cycle_limit,
        capture_vga,
        trace,
    } = run;
    if let Some(t) = &trace {
        t.check()?;
    }
    let files = write_processor_files(
        program,
        layouts,
        params,
        scene_name,
        cycle_limit,
        dir,
        generated_by,
    )?;
    for k in 0..layouts.len() {
        let _ = std::fs::remove_file(dir.join(format!("frame{k}.hex")));
    }
    let vga_path = dir.join("vga.hex");
    let _ = std::fs::remove_file(&vga_path);
    // An earlier run's waveforms in either format would pass for this run's.
    for format in [TraceFormat::Vcd, TraceFormat::Fst] {
        let _ = std::fs::remove_file(dir.join(format!("trace.{}", format.extension())));
    }
    let mut job = SimJob::new(dir, vec![files.rtl, files.testbench], "tb")
        .timeout(Duration::from_secs(3600))
        .verilator_build(VerilatorBuild::Fast)
        .reuse_build(true)
        .trace(trace.map(|t| t.format));
    if capture_vga {
        job = job.plusarg("vga");
    }
    if let Some(t) = &trace {
        job = job
            .define(TRACE_DEFINE, None)
            .plusarg(format!("trace={}", t.file_name()))
            .plusarg(format!("trace_start={}", t.start));
        if let Some(end) = t.end {
            job = job.plusarg(format!("trace_end={end}"));
        }
    }
    // A heartbeat every few seconds of either simulator (Icarus runs the processor at
    // 150-400 clocks/s, Verilator at about 250k).
    job = job.plusarg(match sim {
        Simulator::Icarus => "heartbeat=2000",
        Simulator::Verilator => "heartbeat=1000000",
    });
    let timeout = |detail: &str| {
        anyhow::anyhow!(
            "{}: the processor did not finish a frame within {cycle_limit} clocks (the \
             testbench's limit; a hung thread or a limit too small for the scene):\n{}",
            sim.name(),
            detail.trim()
        )
    };
    // The testbench ends a timed-out run with $fatal, so the tool reports a failure.
    crate::progress::report(&format!("compiling the processor for {}", sim.name()));
    let compiled = sim::compile(sim, &job)?;
    crate::progress::report(&format!(
        "simulating {} frame(s) in {}",
        layouts.len(),
        sim.name()
    ));
    let run = match compiled.run(&job.plusargs, job.timeout) {
        Ok(run) => run,
        Err(e) if e.to_string().contains("TIMEOUT") => return Err(timeout(&e.to_string())),
        Err(e) => return Err(e.into()),
    };
    let out = format!("{}{}", run.stdout, run.stderr);
    if out.contains("TIMEOUT") {
        return Err(timeout(&out));
    }
    let pixels = (layouts[0].info.width * layouts[0].info.height) as usize;
    let mut frames = Vec::new();
    for k in 0..layouts.len() {
        let hex = dir.join(format!("frame{k}.hex"));
        let text = std::fs::read_to_string(&hex).with_context(|| {
            format!(
                "{}: no frame buffer dump {} (simulator output:\n{})",
                sim.name(),
                hex.display(),
                out.trim()
            )
        })?;
        let px = parse_hex_words(&text, &hex)?;
        if px.len() != pixels {
            bail!("{}: {} pixels, expected {pixels}", hex.display(), px.len());
        }
        let stats_path = dir.join(format!("frame{k}.stats"));
        let stats = std::fs::read_to_string(&stats_path)
            .with_context(|| format!("cannot read {}", stats_path.display()))?;
        let nums: Vec<u64> = stats
            .split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect();
        if nums.len() != 22 {
            bail!(
                "{}: expected `cycles instructions transform_busy intersect_busy traversal_busy \
                 raygen_busy instance_busy shading_busy ready_clocks asleep_clocks reads0 reads1 \
                 reads2 reads3 reads4 reads5 tri_cache_hits tri_cache_misses node_cache_hits \
                 node_cache_misses instance_cache_hits instance_cache_misses`, \
                 got `{}`",
                stats_path.display(),
                stats.trim()
            );
        }
        frames.push(SimFrame {
            pixels: px,
            cycles: nums[0],
            instructions: nums[1],
            transform_busy: nums[2],
            intersect_busy: nums[3],
            traversal_busy: nums[4],
            raygen_busy: nums[5],
            instance_busy: nums[6],
            shading_busy: nums[7],
            ready_thread_clocks: nums[8],
            asleep_thread_clocks: nums[9],
            bank_reads: std::array::from_fn(|b| nums[10 + b]),
            tri_cache_hits: nums[16],
            tri_cache_misses: nums[17],
            node_cache_hits: nums[18],
            node_cache_misses: nums[19],
            instance_cache_hits: nums[20],
            instance_cache_misses: nums[21],
        });
    }
    let vga = if capture_vga {
        let mode = display_mode(layouts[0].info.width, layouts[0].info.height)?;
        let text = std::fs::read_to_string(&vga_path).with_context(|| {
            format!(
                "{}: no display capture {} (simulator output:\n{})",
                sim.name(),
                vga_path.display(),
                out.trim()
            )
        })?;
        let px = parse_hex_words(&text, &vga_path)?;
        let want = (mode.h_visible * mode.v_visible) as usize;
        if px.len() != want {
            bail!(
                "{}: {} pixels, expected {want}",
                vga_path.display(),
                px.len()
            );
        }
        Some(px)
    } else {
        None
    };
    let trace = match trace {
        Some(t) => {
            let path = dir.join(t.file_name());
            if !path.is_file() {
                let clocks: u64 = frames.iter().map(|f| f.cycles).sum();
                bail!(
                    "--trace-start {}: the run ended before that clock, so no waveforms were \
                     written (its frames took {clocks} clocks in all); give a start below {clocks}",
                    t.start
                );
            }
            Some(path)
        }
        None => None,
    };
    Ok(ProcessorSim {
        frames,
        vga,
        trace,
        compile_seconds: run.compile_seconds,
        run_seconds: run.run_seconds,
        reused_build: run.reused_build,
        tool_version: sim::tool_version(sim).unwrap_or_default(),
    })
}

/// One hex word a line, as the testbench writes its dumps.
fn parse_hex_words(text: &str, path: &Path) -> Result<Vec<u32>> {
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            u32::from_str_radix(l.trim(), 16).with_context(|| {
                format!(
                    "{} line {}: `{l}` is not a hex word (X in the frame buffer?)",
                    path.display(),
                    i + 1
                )
            })
        })
        .collect()
}
