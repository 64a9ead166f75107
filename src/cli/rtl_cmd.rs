//! `dynrt rtl` and `dynrt sim`: the processor of a scene, generated, and simulated frame by
//! frame against the golden model.
use clap::{Args, ValueEnum};
use dynrt::emit::processor::ProcessorParams;
use dynrt::flow;
use dynrt::fp::Format;
use dynrt::output::OutputDir;
use dynrt::provenance::GeneratedBy;
use dynrt::report::{RunSummary, SceneInfo};
use dynrt::sim::processor::TraceWindow;
use dynrt::sim::{Simulator, TraceFormat};
use std::path::PathBuf;

#[derive(Args)]
pub struct RtlArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output folder (created if missing): Verilog, testbench, memory images, reports.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Number format eXmY of the processor's floating point.
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// Ray threads in flight (1..=32).
    #[arg(long, default_value_t = 32)]
    pub threads: u32,
    /// SRAM read latency in clocks (1..=6).
    #[arg(long, default_value_t = 2)]
    pub mem_latency: u32,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Frames of an animated scene (default: all).
    #[arg(long)]
    pub frames: Option<u32>,
    #[command(flatten)]
    pub size: super::SizeArgs,
    /// Also synthesize the processor with yosys (xc2v) and print its resources against an
    /// XC2V6000 (takes minutes).
    #[arg(long)]
    pub synth: bool,
    /// Also synthesize the processor with its hierarchy kept and itemize LUTs, flip-flops,
    /// multipliers and block RAMs per block (three levels down: the coprocessors' units), into
    /// OUT/synth/blocks.md and blocks.csv (about a minute: each block is optimized alone).
    #[arg(long)]
    pub synth_blocks: bool,
    /// Board file (TOML, boards/README.md): pin locations and I/O standards for the UCF
    /// (`rtl` only).
    #[arg(long, value_name = "FILE")]
    pub board: Option<PathBuf>,
    /// Leave the commit out of the generated files' headers, so that files checked into
    /// version control do not change with every commit (`make rtl` uses it).
    #[arg(long)]
    pub stable_header: bool,
    /// Print the run's summary.json on stdout instead of the text report.
    #[arg(long)]
    pub json: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SimKind {
    Iverilog,
    Verilator,
}

/// The waveform formats of `--trace`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TraceArg {
    /// GTKWave's compressed Fast Signal Trace.
    Fst,
    /// Value change dump, text.
    Vcd,
}

#[derive(Args)]
pub struct SimArgs {
    #[command(flatten)]
    pub rtl: RtlArgs,
    /// The simulator: verilator (slow to build, fast to run) or iverilog.
    #[arg(long, value_enum, default_value = "verilator")]
    pub sim: SimKind,
    /// State fps at this clock, MHz (default: the paper's 90 MHz, assumed, not measured).
    #[arg(long, conflicts_with = "timing_report")]
    pub clock: Option<f64>,
    /// State fps at the main clock measured in this report of the same design: `dynrt timing
    /// SCENE`'s timing.csv or a seed's report.json (the slowest seed's clock is taken).
    #[arg(long)]
    pub timing_report: Option<PathBuf>,
    /// Dump every signal's waveforms into OUT/trace.fst or OUT/trace.vcd (`--trace` alone:
    /// fst). A whole frame is large: narrow it with --trace-start/--trace-end (README,
    /// "Waveforms").
    #[arg(long, value_enum, value_name = "FORMAT", num_args = 0..=1, default_missing_value = "fst")]
    pub trace: Option<TraceArg>,
    /// First clock of the waveform window, counted from the start of the run, frame after
    /// frame (default 0).
    #[arg(long, value_name = "CLOCK", requires = "trace")]
    pub trace_start: Option<u64>,
    /// The clock the waveform window ends at (default: the end of the run).
    #[arg(long, value_name = "CLOCK", requires = "trace")]
    pub trace_end: Option<u64>,
}

/// The waveform window of `--trace`, checked.
fn trace_window(a: &SimArgs) -> anyhow::Result<Option<TraceWindow>> {
    let Some(format) = a.trace else {
        return Ok(None);
    };
    let w = TraceWindow {
        format: match format {
            TraceArg::Fst => TraceFormat::Fst,
            TraceArg::Vcd => TraceFormat::Vcd,
        },
        start: a.trace_start.unwrap_or(0),
        end: a.trace_end,
    };
    w.check()?;
    Ok(Some(w))
}

/// The clock fps are stated at, in MHz, and where it comes from.
fn fps_clock(a: &SimArgs) -> anyhow::Result<(f64, String)> {
    clock_mhz(a.clock, a.timing_report.as_deref())
}

/// The clock of `--clock MHZ` or `--timing-report FILE` (the paper's 90 MHz, stated as
/// assumed, without either), in MHz, and where it comes from.
pub(super) fn clock_mhz(
    clock: Option<f64>,
    timing_report: Option<&std::path::Path>,
) -> anyhow::Result<(f64, String)> {
    if let Some(mhz) = clock {
        if !(mhz.is_finite() && mhz > 0.0 && mhz <= 1000.0) {
            anyhow::bail!("--clock {mhz}: give the clock in MHz, in (0, 1000], e.g. --clock 90");
        }
        return Ok((mhz, "given with --clock".into()));
    }
    if let Some(path) = timing_report {
        let mhz = dynrt::synth::ecp5::measured_clock_mhz(path).map_err(|m| {
            anyhow::anyhow!("--timing-report: {m} (make one with `dynrt timing SCENE --out DIR`)")
        })?;
        return Ok((
            mhz,
            format!("measured after place and route, {}", path.display()),
        ));
    }
    Ok((
        flow::CLOCK_HZ / 1e6,
        "assumed: the paper's clock, not measured; give --clock or --timing-report".into(),
    ))
}

/// Loads the scene and checks every limit of the processor and the output folder, before
/// anything is written.
fn setup(a: &RtlArgs) -> anyhow::Result<(dynrt::scene::Scene, String, ProcessorParams)> {
    dynrt::output::check_output_dir(&a.out, "--out")?;
    let (width, height) = a.size.width_height();
    let scene = super::render_cmd::load_scene(&a.scene, width, height)?;
    let params = a.cache.params(a.threads, a.mem_latency);
    flow::preflight(&scene, a.format, params, a.frames)?;
    let name = a
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok((scene, name, params))
}

/// The summary of an `rtl` or `sim` run: the scene and the options it ran with.
fn summary(verb: &str, a: &RtlArgs, scene: &dynrt::scene::Scene, name: &str) -> RunSummary {
    let mut s = RunSummary::new(verb, &GeneratedBy::this_run(a.stable_header));
    s.scene = Some(SceneInfo::of(scene, name));
    s.option("format", a.format.to_string())
        .option("threads", a.threads)
        .option("mem_latency", a.mem_latency)
        .option("tri_cache", a.cache.tri_cache)
        .option("tri_ways", a.cache.tri_ways)
        .option("node_cache", a.cache.node_cache)
        .option("node_ways", a.cache.node_ways)
        .option("instance_cache", a.cache.instance_cache)
        .option("instance_ways", a.cache.instance_ways)
        .option("frames", a.frames)
        .option("width", scene.camera.width)
        .option("height", scene.camera.height)
        .option("synth", a.synth)
        .option("synth_blocks", a.synth_blocks);
    s
}

/// What `rtl` generated, for the summary.
fn record_generated(s: &mut RunSummary, r: &flow::RtlReport, threads: u32) {
    s.generated.push(format!(
        "microprogram of {} instructions, {} registers, {} scratch words per thread",
        r.program.code.len(),
        r.program.registers_used,
        r.program.scratch.words
    ));
    s.generated.push(format!(
        "{} frame(s) of memory images; Verilog, testbench, UCF, FuseSoC core, files.f",
        r.frames
    ));
    s.left_out = r.program.left_out.clone();
    s.notes.push(format!(
        "predicted frame 0: {} clocks before coprocessor waits ({threads} threads, a round of {} clocks)",
        r.predicted.rounds * u64::from(r.period),
        r.period
    ));
}

pub fn run_rtl(a: RtlArgs) -> anyhow::Result<i32> {
    let (scene, name, params) = setup(&a)?;
    let mut s = summary("rtl", &a, &scene, &name);
    let generated_by = GeneratedBy::this_run(a.stable_header);
    // The board file is read and checked before anything is written; its pins are checked
    // against the ports when the UCF is written (a failed run leaves nothing behind).
    let board = a
        .board
        .as_deref()
        .map(dynrt::emit::load_board)
        .transpose()?;
    if let Some(b) = &a.board {
        s.option("board", b);
    }
    let out = OutputDir::create(&a.out, "--out")?;
    let r = flow::generate_rtl(
        &scene,
        &name,
        a.format,
        params,
        a.frames,
        &a.out,
        &generated_by,
        board.as_ref(),
    )?;
    record_generated(&mut s, &r, params.threads);
    if !a.json {
        println!("{name}: {}; {} frame(s)", s.generated[0], r.frames);
        for l in &s.left_out {
            println!("left out: {l}");
        }
        println!("{}", s.notes[0]);
        for f in &r.files {
            println!("wrote {}", f.display());
        }
    }
    synthesis(&a, &mut s)?;
    s.write(&a.out, false)?;
    if a.json {
        println!("{}", s.json());
    } else {
        println!("report: {}", a.out.join(dynrt::report::REPORT_MD).display());
    }
    out.keep();
    Ok(0)
}

/// With `--synth`: synthesizes the processor, prints the report (unless `--json`) and puts it
/// in the summary.
fn synthesis(a: &RtlArgs, s: &mut RunSummary) -> anyhow::Result<()> {
    if a.synth {
        let report = flow::synthesize_processor(&a.out)?.to_string();
        if !a.json {
            println!("{report}");
        }
        s.notes.extend(report.lines().map(str::to_string));
    }
    if a.synth_blocks {
        let report = flow::synthesize_processor_blocks(&a.out)?;
        let text = format!(
            "{} per block (yosys {}: {}, {:.1} s; each block optimized on its own):\n{}",
            report.top,
            report.yosys_version,
            report.command,
            report.seconds,
            report.markdown()
        );
        if !a.json {
            println!("{text}");
        }
        s.notes.extend(text.lines().map(str::to_string));
    }
    Ok(())
}

pub fn run_sim(a: SimArgs) -> anyhow::Result<i32> {
    anyhow::ensure!(
        a.rtl.board.is_none(),
        "--board: dynrt sim writes no constraints; give the board to dynrt rtl"
    );
    let (scene, name, params) = setup(&a.rtl)?;
    let threads = params.threads;
    let (mhz, clock_source) = fps_clock(&a)?;
    let trace = trace_window(&a)?;
    let out = OutputDir::create(&a.rtl.out, "--out")?;
    let sim = match a.sim {
        SimKind::Iverilog => Simulator::Icarus,
        SimKind::Verilator => Simulator::Verilator,
    };
    let generated_by = GeneratedBy::this_run(a.rtl.stable_header);
    let mut s = summary("sim", &a.rtl, &scene, &name);
    s.option("sim", sim.name()).option("clock_mhz", mhz);
    if let Some(t) = &trace {
        s.option("trace", t.format.extension())
            .option("trace_start", t.start)
            .option("trace_end", t.end);
    }
    let r = flow::simulate_scene(
        &scene,
        &name,
        a.rtl.format,
        params,
        a.rtl.frames,
        sim,
        trace,
        &a.rtl.out,
        &generated_by,
    )?;
    s.tools
        .insert(sim.name().to_string(), r.tool_version.clone());
    s.left_out = r.left_out.clone();
    let mut text = vec![format!("{name} in {} ({}):", sim.name(), r.tool_version)];
    text.push(format!("  fps at {mhz:.1} MHz ({clock_source})"));
    for l in &r.left_out {
        text.push(format!("  left out: {l}"));
    }
    for (k, f) in r.frames.iter().enumerate() {
        s.add_frame(f.result(k, sim.name().to_string()));
        text.push(format!(
            "  frame {k}: {} cycles, {} instructions, {:.1} cycles per primary ray, {:.1} fps at {mhz:.1} MHz ({:.2} fps at 512x384): {}",
            f.cycles,
            f.instructions,
            f.cycles_per_ray(),
            f.fps_at(mhz * 1e6),
            f.fps_512x384_at(mhz * 1e6),
            if f.differing_pixels == 0 {
                "identical to the golden model".to_string()
            } else {
                format!("{} pixels DIFFER from the golden model", f.differing_pixels)
            }
        ));
        for m in &f.mismatches {
            text.push(format!(
                "    pixel ({}, {}): rtl {:06x}, golden {:06x}, engine twin {:06x}; golden {}",
                m.x, m.y, m.rtl, m.golden, m.twin, m.golden_trace
            ));
        }
    }
    let shares: Vec<String> = r
        .section_shares()
        .iter()
        .map(|(s, v)| format!("{s} {:.0}%", 100.0 * v))
        .collect();
    let [triangles, raygen, instances, shading, intersect, traversal] =
        r.frames[0].unit_busy_shares();
    let notes = [
        format!("fps at {mhz:.1} MHz ({clock_source})"),
        format!(
            "busy (frame 0): TransformUnit {:.1}% (triangle tests {:.1}%, ray generation {:.1}%, \
             instance entry {:.1}%, shading {:.1}%), IntersectUnit {:.1}%, traversal unit {:.1}% \
             of the clocks",
            100.0 * (triangles + raygen + instances + shading),
            100.0 * triangles,
            100.0 * raygen,
            100.0 * instances,
            100.0 * shading,
            100.0 * intersect,
            100.0 * traversal
        ),
        {
            let f = &r.frames[0];
            let banks: Vec<String> = dynrt::layout::BANK_NAMES
                .iter()
                .zip(f.bank_reads)
                .enumerate()
                .map(|(b, (name, reads))| {
                    format!(
                        "{b} {name} {:.1} ({:.0}% of the clocks)",
                        reads as f64 / f.pixels as f64,
                        100.0 * reads as f64 / f.cycles.max(1) as f64
                    )
                })
                .collect();
            format!(
                "memory (frame 0): words read per primary ray from bank {} (banks 1, 4 and 5 \
                 share a port); {:.2} GB/s at {mhz:.1} MHz with the frame buffer's writes",
                banks.join(", "),
                f.memory_bytes_per_second_at(mhz * 1e6) / 1e9
            )
        },
        cache_line(
            "triangle",
            a.rtl.cache.tri_cache,
            a.rtl.cache.tri_ways,
            (r.frames[0].tri_cache_hits, r.frames[0].tri_cache_misses),
            "triangle tests",
            "banks 2 and 3",
        ),
        cache_line(
            "node",
            a.rtl.cache.node_cache,
            a.rtl.cache.node_ways,
            (r.frames[0].node_cache_hits, r.frames[0].node_cache_misses),
            "object-tree nodes",
            "bank 0",
        ),
        cache_line(
            "instance",
            a.rtl.cache.instance_cache,
            a.rtl.cache.instance_ways,
            (
                r.frames[0].instance_cache_hits,
                r.frames[0].instance_cache_misses,
            ),
            "instance records",
            "bank 4",
        ),
        format!("engine issue slots by routine: {}", shares.join(", ")),
        {
            let [ready, asleep, rest] = r.frames[0].thread_shares(threads);
            format!(
                "threads (frame 0): {:.0}% of the thread-clocks waiting for an issue slot, {:.0}% \
                 asleep in a coprocessor wait, {:.0}% with an instruction in the pipeline (or \
                 halted)",
                100.0 * ready,
                100.0 * asleep,
                100.0 * rest
            )
        },
        format!(
            "simulated {:.0} cycles/s ({}, run {:.1} s)",
            r.simulated_cycles_per_second(),
            if r.reused_build {
                "the build of the last run reused".to_string()
            } else {
                format!("compile {:.1} s", r.compile_seconds)
            },
            r.run_seconds
        ),
    ];
    text.extend(notes[1..].iter().map(|n| format!("  {n}")));
    s.notes.extend(notes);
    if let (Some(path), Some(t)) = (&r.trace, &trace) {
        let note = format!(
            "waveforms of clocks {} to {}: {}",
            t.start,
            t.end.map_or("the end".to_string(), |e| e.to_string()),
            path.display()
        );
        text.push(format!("  {note}"));
        s.notes.push(note);
    }
    if !a.rtl.json {
        println!("{}", text.join("\n"));
    }
    synthesis(&a.rtl, &mut s)?;
    s.write(&a.rtl.out, true)?;
    // A mismatch is a result, with its diff images and traces: keep them.
    out.keep();
    if a.rtl.json {
        println!("{}", s.json());
    } else if r.identical() {
        println!("every pixel of every frame is identical");
    } else {
        println!(
            "MISMATCH: diff images and traces in {}",
            a.rtl.out.display()
        );
    }
    Ok(if r.identical() {
        0
    } else {
        super::EXIT_DIFFERS
    })
}

/// `dynrt sim`'s line for one cache in frame 0: its sets (and ways if more than one), the
/// lookups that hit and those that read `bank`.
fn cache_line(
    cache: &str,
    sets: u32,
    ways: u32,
    (hits, misses): (u64, u64),
    items: &str,
    bank: &str,
) -> String {
    let shape = match ways {
        1 => format!("{sets} sets"),
        _ => format!("{sets} sets of {ways} ways"),
    };
    let lookups = hits + misses;
    if lookups == 0 {
        return format!("{cache} cache (frame 0): {shape}, no {items} looked up");
    }
    format!(
        "{cache} cache (frame 0): {shape}, {hits} of {lookups} {items} hit ({:.1}%), {misses} \
         read {bank}",
        100.0 * hits as f64 / lookups as f64
    )
}
