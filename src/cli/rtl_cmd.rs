//! `dynrt rtl` and `dynrt sim`: the processor of a scene, generated, and simulated frame by
//! frame against the golden model.
use clap::{Args, ValueEnum};
use dynrt::emit::processor::ProcessorParams;
use dynrt::flow;
use dynrt::fp::Format;
use dynrt::output::OutputDir;
use dynrt::sim::Simulator;
use std::path::PathBuf;

#[derive(Args)]
pub struct RtlArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// Ray threads in flight (1..=32).
    #[arg(long, default_value_t = 32)]
    pub threads: u32,
    /// SRAM read latency in clocks (1..=6).
    #[arg(long, default_value_t = 2)]
    pub mem_latency: u32,
    /// Frames of an animated scene (default: all).
    #[arg(long)]
    pub frames: Option<u32>,
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    /// Also synthesize the processor with yosys (xc2v) and print its resources against an
    /// XC2V6000 (takes minutes).
    #[arg(long)]
    pub synth: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SimKind {
    Iverilog,
    Verilator,
}

#[derive(Args)]
pub struct SimArgs {
    #[command(flatten)]
    pub rtl: RtlArgs,
    #[arg(long, value_enum, default_value = "verilator")]
    pub sim: SimKind,
    /// State fps at this clock, MHz (default: the paper's 90 MHz, assumed, not measured).
    #[arg(long, conflicts_with = "timing_report")]
    pub clock: Option<f64>,
    /// State fps at the main clock measured in this report of the same design: `dynrt timing
    /// SCENE`'s timing.csv or a seed's report.json (the slowest seed's clock is taken).
    #[arg(long)]
    pub timing_report: Option<PathBuf>,
}

/// The clock fps are stated at, in MHz, and where it comes from.
fn fps_clock(a: &SimArgs) -> anyhow::Result<(f64, String)> {
    if let Some(mhz) = a.clock {
        if !(mhz.is_finite() && mhz > 0.0 && mhz <= 1000.0) {
            anyhow::bail!("--clock {mhz}: give the clock in MHz, in (0, 1000], e.g. --clock 90");
        }
        return Ok((mhz, "given with --clock".into()));
    }
    if let Some(path) = &a.timing_report {
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
    let scene = super::render_cmd::load_scene(&a.scene, a.width, a.height)?;
    let params = ProcessorParams {
        threads: a.threads,
        mem_latency: a.mem_latency,
    };
    flow::preflight(&scene, a.format, params, a.frames)?;
    let name = a
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok((scene, name, params))
}

pub fn run_rtl(a: RtlArgs) -> anyhow::Result<i32> {
    let (scene, name, params) = setup(&a)?;
    let out = OutputDir::create(&a.out, "--out")?;
    let r = flow::generate_rtl(&scene, &name, a.format, params, a.frames, &a.out)?;
    println!(
        "{name}: microprogram of {} instructions, {} registers, {} scratch words per thread; {} frame(s)",
        r.program.code.len(),
        r.program.registers_used,
        r.program.scratch.words,
        r.frames
    );
    for l in &r.program.left_out {
        println!("left out: {l}");
    }
    println!(
        "predicted frame 0: {} clocks before coprocessor waits ({} threads, a round of {} clocks)",
        r.predicted.rounds * u64::from(r.period),
        params.threads,
        r.period
    );
    for f in &r.files {
        println!("wrote {}", f.display());
    }
    print_synthesis(&a)?;
    out.keep();
    Ok(0)
}

fn print_synthesis(a: &RtlArgs) -> anyhow::Result<()> {
    if a.synth {
        println!("{}", flow::synthesize_processor(&a.out)?);
    }
    Ok(())
}

pub fn run_sim(a: SimArgs) -> anyhow::Result<i32> {
    let (scene, name, params) = setup(&a.rtl)?;
    let (mhz, clock_source) = fps_clock(&a)?;
    let out = OutputDir::create(&a.rtl.out, "--out")?;
    let sim = match a.sim {
        SimKind::Iverilog => Simulator::Icarus,
        SimKind::Verilator => Simulator::Verilator,
    };
    let r = flow::simulate_scene(
        &scene,
        &name,
        a.rtl.format,
        params,
        a.rtl.frames,
        sim,
        &a.rtl.out,
    )?;
    println!("{name} in {} ({}):", sim.name(), r.tool_version);
    println!("  fps at {mhz:.1} MHz ({clock_source})");
    for l in &r.left_out {
        println!("  left out: {l}");
    }
    for (k, f) in r.frames.iter().enumerate() {
        println!(
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
        );
        for m in &f.mismatches {
            println!(
                "    pixel ({}, {}): rtl {:06x}, golden {:06x}, engine twin {:06x}; golden {}",
                m.x, m.y, m.rtl, m.golden, m.twin, m.golden_trace
            );
        }
    }
    let shares: Vec<String> = r
        .section_shares()
        .iter()
        .map(|(s, v)| format!("{s} {:.0}%", 100.0 * v))
        .collect();
    let [transform, intersect, traversal] = r.frames[0].unit_busy_shares();
    println!(
        "  busy (frame 0): TransformUnit {:.1}%, IntersectUnit {:.1}%, traversal unit {:.1}% of the clocks",
        100.0 * transform,
        100.0 * intersect,
        100.0 * traversal
    );
    println!("  engine issue slots by routine: {}", shares.join(", "));
    println!(
        "  simulated {:.0} cycles/s (compile {:.1} s, run {:.1} s)",
        r.simulated_cycles_per_second(),
        r.compile_seconds,
        r.run_seconds
    );
    print_synthesis(&a.rtl)?;
    // A mismatch is a result, with its diff images and traces: keep them.
    out.keep();
    if r.identical() {
        println!("every pixel of every frame is identical");
        Ok(0)
    } else {
        println!(
            "MISMATCH: diff images and traces in {}",
            a.rtl.out.display()
        );
        Ok(super::EXIT_DIFFERS)
    }
}
