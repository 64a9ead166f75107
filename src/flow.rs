//! The processor flow of one scene: `dynrt rtl` (Verilog, testbench, memory images,
//! constraints) and `dynrt sim` (simulate every frame, compare each with the golden model,
//! measure). Library side, so tests run exactly what the CLI runs.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::emit::constraints::{write_ucf, BoardPins, Port, PortDirection, UcfOptions};
use crate::emit::package;
use crate::emit::processor::{display_mode, ProcessorParams, PROCESSOR_TOP};
use crate::fp::Format;
use crate::hw::engine::engine_period;
use crate::hw::processor::TopPort;
use crate::hw::program::exec::{Machine, RunStats, Write};
use crate::hw::program::isa::MAX_PROGRAM;
use crate::hw::program::{build_program, Program, ProgramConfig};
use crate::hw::traversal_unit::FETCH_CLOCKS_PER_NODE;
use crate::hw::traversal_unit::STACK_LEVELS;
use crate::hw::triangle_tester::CLOCKS_PER_TEST;
use crate::hw::vga::VgaMode;
use crate::layout::{self, Layout, MemoryConfig, SceneTrees};
use crate::model::{self, golden::Golden};
use crate::provenance::GeneratedBy;
use crate::scene::Scene;
use crate::sim::processor::{
    simulate_processor, write_processor_files, ProcessorSim, SimRun, TraceWindow,
};
use crate::sim::Simulator;
use crate::synth::{self, SynthOptions, SynthReport};

/// The target clock of the paper's prototype (XC2V6000-4).
pub const CLOCK_HZ: f64 = 90e6;

/// The layouts of frames `0..frames` (all of an animated scene's frames when `None`).
pub fn scene_layouts(scene: &Scene, f: Format, frames: Option<u32>) -> Result<Vec<Layout>> {
    let trees = SceneTrees::build(scene, f)?;
    let n = frames.unwrap_or(scene.frames).clamp(1, scene.frames.max(1));
    (0..n)
        .map(|k| Ok(layout::build(scene, &trees, k, &MemoryConfig::default())?))
        .collect()
}

/// Most frames one `dynrt rtl` or `dynrt sim` run writes and simulates: each frame is an update
/// of the memory images (several files) and a frame of simulation (seconds in Verilator), so an
/// animation of thousands of frames is a mistake more often than a wish; `--frames N` takes the
/// first N.
pub const MAX_PROCESSOR_FRAMES: u32 = 256;

/// Every limit of the generated processor checked on the scene alone, before any tree, file or
/// folder is made: threads, SRAM latency, frames per run, the display's largest mode, the
/// memory map's size from counts, and the microprogram's length against the ROM (the program is
/// generated for the scene's features with a worst-case tree, which does not change its length).
/// The kd stack depth needs the trees and is checked by [`generate_rtl`] and
/// [`simulate_scene`] right after they are built.
pub fn preflight(
    scene: &Scene,
    f: Format,
    params: ProcessorParams,
    frames: Option<u32>,
) -> Result<()> {
    use crate::hw::engine::{MAX_MEM_LATENCY, MAX_THREADS};
    let src = scene.source.display();
    anyhow::ensure!(
        (1..=MAX_THREADS as u32).contains(&params.threads),
        "--threads {}: the engine runs 1..={MAX_THREADS} ray threads; use e.g. --threads 32",
        params.threads
    );
    anyhow::ensure!(
        (1..=MAX_MEM_LATENCY).contains(&params.mem_latency),
        "--mem-latency {}: the processor's SRAM read ports take a latency of 1..={MAX_MEM_LATENCY} clocks; use e.g. --mem-latency 2",
        params.mem_latency
    );
    {
        use crate::hw::cache::{cache_shape_supported, MAX_CACHE_SETS, MAX_CACHE_WAYS};
        for (cache, flags, sets, ways, example) in [
            (
                "triangle",
                ["--tri-cache", "--tri-ways"],
                params.tri_cache_sets,
                params.tri_cache_ways,
                "--tri-cache 128 --tri-ways 4",
            ),
            (
                "node",
                ["--node-cache", "--node-ways"],
                params.node_cache_sets,
                params.node_cache_ways,
                "--node-cache 256 --node-ways 2",
            ),
            (
                "instance",
                ["--instance-cache", "--instance-ways"],
                params.instance_cache_sets,
                params.instance_cache_ways,
                "--instance-cache 128 --instance-ways 4",
            ),
        ] {
            let [sets_flag, ways_flag] = flags;
            anyhow::ensure!(
                cache_shape_supported(sets, ways),
                "{sets_flag} {sets} {ways_flag} {ways}: the {cache} cache has a power of two of \
                 sets (or 0 for none) of 1, 2 or {MAX_CACHE_WAYS} ways, at most {MAX_CACHE_SETS} \
                 items (sets times ways); use e.g. {example}"
            );
        }
    }
    if let Some(n) = frames {
        anyhow::ensure!(
            n >= 1 && n <= scene.frames,
            "{src}: --frames {n}, but the scene has {} frame(s); use 1..={}",
            scene.frames,
            scene.frames
        );
    }
    let n = frames.unwrap_or(scene.frames);
    anyhow::ensure!(
        n <= MAX_PROCESSOR_FRAMES,
        "{src}: {n} frames, but one processor run writes and simulates at most {MAX_PROCESSOR_FRAMES}; \
         give --frames N (N <= {MAX_PROCESSOR_FRAMES}) to take the first N"
    );
    display_mode(scene.camera.width, scene.camera.height)
        .with_context(|| format!("{src}: camera resolution"))?;
    layout::check_capacity(scene, &MemoryConfig::default())?;
    let worst = ProgramConfig {
        format: f,
        width: scene.camera.width,
        height: scene.camera.height,
        shadows: scene.render.shadows && !scene.lights.is_empty(),
        reflection_depth: scene.render.reflection_depth,
        light_count: scene.lights.len() as u32,
        top_root: (!scene.is_single_untransformed_object()).then_some(0),
        object_root: 0,
        materials: 0,
        frame_buffer: 0,
        top_stack_base: crate::hw::traversal_unit::DEFAULT_TOP_STACK_BASE,
    };
    let length = |lights: u32| {
        build_program(&ProgramConfig {
            light_count: lights,
            ..worst.clone()
        })
        .code
        .len()
    };
    let needed = length(worst.light_count);
    if needed > MAX_PROGRAM {
        // Each light adds the same code (its shading and shadow ray): the largest count that
        // fits follows from two lengths.
        let (one, two) = (length(1), length(2));
        let per_light = two.saturating_sub(one).max(1);
        let fit = if one > MAX_PROGRAM {
            0
        } else {
            1 + (MAX_PROGRAM - one) / per_light
        };
        anyhow::bail!(
            "{src}: the scene's microprogram needs {needed} instructions, the engine's ROM holds \
             {MAX_PROGRAM}: each of its {} lights adds about {per_light} (shading and shadow ray); \
             with these render settings at most {fit} lights fit, so use at most {fit} lights \
             (or a smaller reflection_depth)",
            scene.lights.len()
        );
    }
    Ok(())
}

/// The processor's top-level ports for the constraints file: the top module's ports
/// ([`crate::hw::processor::Processor::ports`]), its two clocks at the core's and the
/// display's frequencies.
pub fn processor_ports(ports: &[TopPort], display: &VgaMode) -> Vec<Port> {
    ports
        .iter()
        .map(|p| match (p.clock, p.name.as_str()) {
            (true, "vga_clock") => Port::clock(&p.name, display.pixel_clock_hz as f64),
            (true, _) => Port::clock(&p.name, CLOCK_HZ),
            (false, _) => {
                let direction = if p.output {
                    PortDirection::Output
                } else {
                    PortDirection::Input
                };
                Port::io(&p.name, p.bits as u32, direction)
            }
        })
        .collect()
}

/// What `dynrt rtl` wrote.
#[derive(Debug)]
pub struct RtlReport {
    pub program: Program,
    pub frames: usize,
    pub files: Vec<PathBuf>,
    /// The twin's prediction of frame 0 (cycles = rounds x period).
    pub predicted: RunStats,
    pub period: u32,
}

/// What both `dynrt rtl` and `dynrt sim` start from: the frames' layouts, the scene's
/// microprogram, the engine twin's run of frame 0 and the engine's rotation period.
struct Prepared {
    layouts: Vec<Layout>,
    program: Program,
    twin: RunStats,
    period: u32,
}

fn prepare(
    scene: &Scene,
    f: Format,
    params: ProcessorParams,
    frames: Option<u32>,
) -> Result<Prepared> {
    preflight(scene, f, params, frames)?;
    crate::progress::report("building the kd-trees and memory layouts");
    let layouts = scene_layouts(scene, f, frames)?;
    check_stack_depths(&layouts)?;
    let program = build_program(&ProgramConfig::from_layout(&layouts[0]));
    let twin = Machine::new(&program, &layouts[0])
        .run_frame(params.threads as usize)
        .context("the engine's twin failed on frame 0 (a generator bug)")?
        .stats;
    Ok(Prepared {
        layouts,
        program,
        twin,
        period: engine_period(params.threads),
    })
}

/// Twice the clocks the frame would take if the engine and the coprocessors took turns (they
/// overlap, so a frame within it is never cut short; a hung one stops).
fn cycle_limit(predicted: &RunStats, period: u32) -> u64 {
    let engine = predicted.rounds * u64::from(period);
    let tester = predicted.triangle_tests * u64::from(CLOCKS_PER_TEST);
    let traversal = predicted.kd_nodes * u64::from(FETCH_CLOCKS_PER_NODE);
    2 * (engine + tester + traversal) + 100_000
}

/// Writes the processor for `scene` into `out`: `rtl/`, `testbench/`, `mem/`, `cocotb/`,
/// `constraints/dynrt.ucf`, `program.lst` (the microprogram listing), the FuseSoC core
/// `dynrt_processor.core`, `files.f`, `PORTS.md`, frame 0's banks as raw binary in `bin/`
/// and the golden frames `golden<k>.hex`; the generated text files start with
/// `generated_by`'s header. With a `board` (boards/README.md), the UCF places the ports on its
/// pins.
#[allow(clippy::too_many_arguments)]
pub fn generate_rtl(
    scene: &Scene,
    name: &str,
    f: Format,
    params: ProcessorParams,
    frames: Option<u32>,
    out: &Path,
    generated_by: &GeneratedBy,
    board: Option<&BoardPins>,
) -> Result<RtlReport> {
    let Prepared {
        layouts,
        program,
        twin: predicted,
        period,
    } = prepare(scene, f, params, frames)?;
    crate::progress::report("writing the Verilog, testbench and memory images");
    let written = write_processor_files(
        &program,
        &layouts,
        params,
        name,
        cycle_limit(&predicted, period),
        out,
        generated_by,
    )?;
    let constraints = out.join("constraints");
    std::fs::create_dir_all(&constraints)
        .with_context(|| format!("creating {}", constraints.display()))?;
    let ucf = constraints.join("dynrt.ucf");
    let info = &layouts[0].info;
    let display = display_mode(info.width, info.height)?;
    write_ucf(
        &ucf,
        &processor_ports(&written.ports, &display),
        &UcfOptions {
            generated_by: generated_by.clone(),
            board: board.cloned(),
            ..UcfOptions::default()
        },
    )?;
    let listing = out.join("program.lst");
    crate::output::write_atomically(&listing, program.listing().as_bytes())
        .with_context(|| format!("writing {}", listing.display()))?;
    // The golden frames, as the testbench dumps its own (for the cocotb test and any other
    // testbench that checks the processor: `cmp frame<k>.hex golden<k>.hex`).
    let mut goldens = Vec::new();
    for (k, l) in layouts.iter().enumerate() {
        let path = out.join(format!("golden{k}.hex"));
        crate::output::write_atomically(
            &path,
            frame_hex(&model::render_golden(l, false).rgb).as_bytes(),
        )
        .with_context(|| format!("writing {}", path.display()))?;
        goldens.push(path);
    }
    let relative = |p: &Path| {
        p.strip_prefix(out)
            .unwrap_or(p)
            .to_string_lossy()
            .into_owned()
    };
    let (rtl, tb) = (relative(&written.rtl), relative(&written.testbench));
    let mem: Vec<String> = written.mem.iter().map(|p| relative(p)).collect();
    let description = format!(
        "dynrt ray tracing processor for scene {name}: format {f}, {}x{} pixels, {} threads, SRAM read latency {}, {} frame(s)",
        info.width,
        info.height,
        params.threads,
        params.mem_latency,
        layouts.len()
    );
    let core = out.join(package::CORE_FILE);
    let files_f = out.join(package::FILES_F);
    let core_text = package::fusesoc_core(
        &package::CoreFiles {
            scene_name: name,
            description: &description,
            rtl: &rtl,
            testbench: &tb,
            mem: &mem,
        },
        generated_by,
    );
    let list_text = package::files_f(&[rtl, tb], generated_by);
    let ports_md = out.join("PORTS.md");
    let ports_text = package::ports_md(
        &written.ports,
        params.mem_latency,
        &written.frames,
        generated_by,
    );
    let bin_dir = out.join("bin");
    let bins: Vec<(PathBuf, Vec<u8>)> = layouts[0]
        .banks
        .iter()
        .enumerate()
        .map(|(b, words)| {
            let name = crate::emit::bank_file_name(b).replace(".hex", ".bin");
            (bin_dir.join(name), package::bank_bin(words))
        })
        .collect();
    let mut writes: Vec<(&Path, &[u8])> = vec![
        (&core, core_text.as_bytes()),
        (&files_f, list_text.as_bytes()),
        (&ports_md, ports_text.as_bytes()),
    ];
    writes.extend(bins.iter().map(|(p, b)| (p.as_path(), b.as_slice())));
    crate::output::write_all_atomically(&writes)?;
    Ok(RtlReport {
        program,
        frames: layouts.len(),
        files: vec![
            written.rtl,
            written.testbench,
            ucf,
            listing,
            out.join("mem"),
            core,
            files_f,
            ports_md,
            bin_dir,
            out.join("cocotb"),
        ]
        .into_iter()
        .chain(goldens)
        .collect(),
        predicted,
        period,
    })
}

/// Synthesizes the processor that `generate_rtl` or `simulate_scene` wrote into `out` with
/// yosys for Virtex-II, out of context (no I/O pads: the ports go to the board's SRAMs and the
/// host), into `out/synth/`. Takes minutes: the whole processor, flattened.
pub fn synthesize_processor(out: &Path) -> Result<SynthReport> {
    let rtl = out.join("rtl").join(format!("{PROCESSOR_TOP}.v"));
    let options = SynthOptions {
        io_pads: false,
        ..SynthOptions::default()
    };
    Ok(synth::synth_xc2v_with(
        &[rtl],
        PROCESSOR_TOP,
        &out.join("synth"),
        &options,
    )?)
}

/// Synthesizes the processor in `out` like [`synthesize_processor`] but with its hierarchy
/// kept, and itemizes its resources per block down to the coprocessors' units (three levels:
/// `engine.tester.transform_unit`), into
/// `out/synth/` (`blocks.md`, `blocks.csv` beside yosys's files). About a minute: no
/// flattening, each block is optimized alone.
pub fn synthesize_processor_blocks(out: &Path) -> Result<synth::blocks::BlockReport> {
    let rtl = out.join("rtl").join(format!("{PROCESSOR_TOP}.v"));
    let options = SynthOptions {
        io_pads: false,
        ..SynthOptions::default()
    };
    let dir = out.join("synth");
    let report = synth::synth_xc2v_blocks(&[rtl], PROCESSOR_TOP, &dir, &options, 3)?;
    std::fs::write(dir.join("blocks.md"), report.markdown())?;
    std::fs::write(dir.join("blocks.csv"), report.csv())?;
    Ok(report)
}

/// One differing pixel, with what the golden model and the engine's twin computed for it.
#[derive(Debug, Clone)]
pub struct Mismatch {
    pub frame: usize,
    pub x: u32,
    pub y: u32,
    pub rtl: u32,
    pub golden: u32,
    /// The twin's word for the pixel (equal to `golden` unless the program is wrong).
    pub twin: u32,
    /// The golden model's account: hit and shaded colour.
    pub golden_trace: String,
    /// Every register write of the twin for this pixel: `pc routine instruction -> value`.
    pub twin_trace: Vec<String>,
}

/// Measured figures of one simulated frame.
#[derive(Debug, Clone)]
pub struct FrameReport {
    pub cycles: u64,
    pub instructions: u64,
    /// Clocks in which the triangle tester's TransformUnit, IntersectUnit took an input.
    pub transform_busy: u64,
    pub intersect_busy: u64,
    /// Clocks in which the traversal unit started a node decision.
    pub traversal_busy: u64,
    /// Clocks in which ray generation's, instance entry's and shading's (world normals)
    /// requests took the TransformUnit.
    pub raygen_busy: u64,
    pub instance_busy: u64,
    pub shading_busy: u64,
    /// Thread-clocks waiting for an issue slot and asleep in a coprocessor wait.
    pub ready_thread_clocks: u64,
    pub asleep_thread_clocks: u64,
    /// Words read from each bank (`layout::BANK_NAMES`).
    pub bank_reads: [u64; 6],
    /// Triangle tests whose words came from the triangle cache, and from banks 2 and 3.
    pub tri_cache_hits: u64,
    pub tri_cache_misses: u64,
    pub node_cache_hits: u64,
    pub node_cache_misses: u64,
    /// Instance entries (and world normals) whose record came from the instance cache, and
    /// from bank 4.
    pub instance_cache_hits: u64,
    pub instance_cache_misses: u64,
    pub pixels: u64,
    pub mismatches: Vec<Mismatch>,
    pub differing_pixels: usize,
}

impl FrameReport {
    /// The frame's entry in a run's summary (`report::RunSummary::add_frame`).
    pub fn result(&self, frame: usize, simulator: String) -> crate::report::FrameResult {
        crate::report::FrameResult {
            frame,
            simulator,
            cycles: self.cycles,
            instructions: self.instructions,
            rays: self.pixels,
            cycles_per_ray: self.cycles_per_ray(),
            differing_pixels: self.differing_pixels,
            pass: self.differing_pixels == 0,
        }
    }
    pub fn cycles_per_ray(&self) -> f64 {
        self.cycles as f64 / self.pixels as f64
    }
    /// Frames per second at the paper's 90 MHz (an assumed clock; see [`Self::fps_at`]).
    pub fn fps(&self) -> f64 {
        self.fps_at(CLOCK_HZ)
    }
    /// Frames per second at a clock of `hz`.
    pub fn fps_at(&self, hz: f64) -> f64 {
        hz / self.cycles as f64
    }
    /// Shares of the frame's clocks in which the TransformUnit (for triangle tests, for ray
    /// generation, for instance entry, for shading), the IntersectUnit and the traversal
    /// unit's decision took an input.
    pub fn unit_busy_shares(&self) -> [f64; 6] {
        let c = self.cycles.max(1) as f64;
        [
            self.transform_busy,
            self.raygen_busy,
            self.instance_busy,
            self.shading_busy,
            self.intersect_busy,
            self.traversal_busy,
        ]
        .map(|n| n as f64 / c)
    }
    /// 32-bit words the frame moved over the memory ports: every bank's reads and the frame
    /// buffer's writes (one a pixel).
    pub fn memory_words(&self) -> u64 {
        self.bank_reads.iter().sum::<u64>() + self.pixels
    }
    /// Bytes of [`Self::memory_words`] per second at a clock of `hz`.
    pub fn memory_bytes_per_second_at(&self, hz: f64) -> f64 {
        4.0 * self.memory_words() as f64 * self.fps_at(hz)
    }
    /// Shares of the frame's thread-clocks (`threads` x cycles): waiting for an issue slot,
    /// asleep in a coprocessor wait, and the rest (an instruction in the engine's pipeline,
    /// or halted at the frame's end).
    pub fn thread_shares(&self, threads: u32) -> [f64; 3] {
        let total = (u64::from(threads) * self.cycles).max(1) as f64;
        let ready = self.ready_thread_clocks as f64 / total;
        let asleep = self.asleep_thread_clocks as f64 / total;
        [ready, asleep, 1.0 - ready - asleep]
    }
    /// Frames per second at 90 MHz for 512x384 at this scene's cycles per primary ray.
    pub fn fps_512x384(&self) -> f64 {
        self.fps_512x384_at(CLOCK_HZ)
    }
    /// Frames per second at a clock of `hz` for 512x384 at this scene's cycles per primary ray.
    pub fn fps_512x384_at(&self, hz: f64) -> f64 {
        hz / (self.cycles_per_ray() * 512.0 * 384.0)
    }
}

/// What `dynrt sim` measured.
#[derive(Debug)]
pub struct SimReport {
    pub simulator: Simulator,
    pub tool_version: String,
    pub frames: Vec<FrameReport>,
    pub twin: RunStats,
    pub period: u32,
    pub compile_seconds: f64,
    pub run_seconds: f64,
    /// The simulator's build of an earlier run in `out` was reused (nothing compiled).
    pub reused_build: bool,
    pub program_len: usize,
    pub left_out: Vec<String>,
    /// With a trace window: the waveform file.
    pub trace: Option<PathBuf>,
}

impl SimReport {
    pub fn identical(&self) -> bool {
        self.frames.iter().all(|f| f.differing_pixels == 0)
    }
    pub fn simulated_cycles_per_second(&self) -> f64 {
        self.frames.iter().map(|f| f.cycles).sum::<u64>() as f64 / self.run_seconds.max(1e-9)
    }
    /// Share of the clocks in which the engine issued to each routine (frame 0's twin run).
    pub fn section_shares(&self) -> Vec<(&'static str, f64)> {
        let cycles = self.frames[0].cycles.max(1) as f64;
        self.twin
            .per_section
            .iter()
            .map(|(s, n)| (*s, *n as f64 / cycles))
            .collect()
    }
}

/// Generates, simulates and compares every frame of `scene` with the golden model; writes
/// `frame<k>.png`, `golden<k>.png` and `golden<k>.hex` (the golden frame as the testbench
/// dumps `frame<k>.hex`, for other testbenches to check against). On a mismatch writes
/// `diff<k>.png` and a trace of the first differing pixels into `out`; `index.html` shows the
/// RTL, golden and diff images of every frame side by side. With `trace`, the
/// waveforms of that window of clocks go to `out/trace.<vcd|fst>`.
#[allow(clippy::too_many_arguments)]
pub fn simulate_scene(
    scene: &Scene,
    name: &str,
    f: Format,
    params: ProcessorParams,
    frames: Option<u32>,
    sim: Simulator,
    trace: Option<TraceWindow>,
    out: &Path,
    generated_by: &GeneratedBy,
) -> Result<SimReport> {
    let Prepared {
        layouts,
        program,
        twin,
        period,
    } = prepare(scene, f, params, frames)?;
    remove_stale_mismatches(out)?;
    let run: ProcessorSim = simulate_processor(
        &program,
        &layouts,
        params,
        name,
        SimRun {
            sim,
            cycle_limit: cycle_limit(&twin, period),
            capture_vga: false,
            trace,
        },
        out,
        generated_by,
    )?;
    let mut reports = Vec::new();
    let mut page = Vec::new();
    for (k, (l, fr)) in layouts.iter().zip(&run.frames).enumerate() {
        crate::progress::report(&format!("comparing frame {k} with the golden model"));
        let golden = model::render_golden(l, false);
        let (w, h) = (l.info.width, l.info.height);
        let rtl_frame = model::Frame {
            rgb: fr.pixels.clone(),
            ..golden.clone()
        };
        rtl_frame.save_png(&out.join(format!("frame{k}.png")))?;
        golden.save_png(&out.join(format!("golden{k}.png")))?;
        let golden_hex = out.join(format!("golden{k}.hex"));
        crate::output::write_atomically(&golden_hex, frame_hex(&golden.rgb).as_bytes())
            .with_context(|| format!("writing {}", golden_hex.display()))?;
        let differing: Vec<usize> = (0..(w * h) as usize)
            .filter(|&i| fr.pixels[i] != golden.rgb[i])
            .collect();
        page.push(crate::compare::PageFrame {
            metrics: crate::compare::compare_images(&rtl_frame.to_image(), &golden.to_image())?,
            diff: !differing.is_empty(),
        });
        let mut mismatches = Vec::new();
        if !differing.is_empty() {
            let diff = crate::compare::diff_image(&rtl_frame.to_image(), &golden.to_image());
            crate::output::write_png(&out.join(format!("diff{k}.png")), &diff)?;
            let m = Machine::new(&program, l);
            let g = Golden::new(l);
            for &i in differing.iter().take(3) {
                let (x, y) = (i as u32 % w, i as u32 / w);
                let (twin_rgb, _, writes) = m.run_pixel(x, y, true)?;
                let p = g.pixel(x, y);
                mismatches.push(Mismatch {
                    frame: k,
                    x,
                    y,
                    rtl: fr.pixels[i],
                    golden: golden.rgb[i],
                    twin: twin_rgb,
                    golden_trace: format!(
                        "hit {:?}, colour {:?}",
                        p.hit,
                        p.color.map(|c| f.to_f64(c))
                    ),
                    twin_trace: writes.iter().map(|w| describe(&program, f, w)).collect(),
                });
            }
            let trace = out.join(format!("mismatch{k}.txt"));
            let text: String = mismatches
                .iter()
                .map(|m| {
                    format!(
                        "pixel ({}, {}): rtl {:06x}, golden {:06x}, twin {:06x}\ngolden: {}\n{}\n\n",
                        m.x,
                        m.y,
                        m.rtl,
                        m.golden,
                        m.twin,
                        m.golden_trace,
                        m.twin_trace.join("\n")
                    )
                })
                .collect();
            crate::output::write_atomically(&trace, text.as_bytes())
                .with_context(|| format!("writing {}", trace.display()))?;
        }
        reports.push(FrameReport {
            cycles: fr.cycles,
            instructions: fr.instructions,
            transform_busy: fr.transform_busy,
            intersect_busy: fr.intersect_busy,
            traversal_busy: fr.traversal_busy,
            raygen_busy: fr.raygen_busy,
            instance_busy: fr.instance_busy,
            shading_busy: fr.shading_busy,
            ready_thread_clocks: fr.ready_thread_clocks,
            asleep_thread_clocks: fr.asleep_thread_clocks,
            bank_reads: fr.bank_reads,
            tri_cache_hits: fr.tri_cache_hits,
            tri_cache_misses: fr.tri_cache_misses,
            node_cache_hits: fr.node_cache_hits,
            node_cache_misses: fr.node_cache_misses,
            instance_cache_hits: fr.instance_cache_hits,
            instance_cache_misses: fr.instance_cache_misses,
            pixels: u64::from(w * h),
            differing_pixels: differing.len(),
            mismatches,
        });
    }
    let html = out.join("index.html");
    let title = format!(
        "{name} in {}: the RTL frames and the golden model's",
        sim.name()
    );
    crate::output::write_atomically(
        &html,
        crate::compare::sim_page_html(&title, &page).as_bytes(),
    )
    .with_context(|| format!("writing {}", html.display()))?;
    Ok(SimReport {
        simulator: sim,
        tool_version: run.tool_version,
        frames: reports,
        twin,
        period,
        compile_seconds: run.compile_seconds,
        run_seconds: run.run_seconds,
        reused_build: run.reused_build,
        program_len: program.code.len(),
        left_out: program.left_out.clone(),
        trace: run.trace,
    })
}

/// Removes the `diff<k>.png` and `mismatch<k>.txt` of an earlier run in `out`, so that only
/// this run's mismatches are there afterwards.
fn remove_stale_mismatches(out: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let numbered = |prefix: &str, ext: &str| {
            name.strip_prefix(prefix)
                .and_then(|r| r.strip_suffix(ext))
                .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
        };
        if numbered("diff", ".png") || numbered("mismatch", ".txt") {
            std::fs::remove_file(e.path())
                .with_context(|| format!("removing the stale {}", e.path().display()))?;
        }
    }
    Ok(())
}

/// A frame as the testbench dumps it (`frame<k>.hex`): one `rrggbb` word a line, raster order.
pub fn frame_hex(rgb: &[u32]) -> String {
    rgb.iter()
        .map(|p| format!("{:06x}\n", p & 0xff_ffff))
        .collect()
}

fn describe(p: &Program, f: Format, w: &Write) -> String {
    format!(
        "{:4} {:<10} {:<44} r{} = {:#010x} ({})",
        w.pc,
        p.sections[w.pc as usize],
        p.code[w.pc as usize].to_string(),
        w.reg,
        w.value,
        f.to_f64(w.value)
    )
}

/// The traversal unit's stack holds every walk's pushes: an object walk's from entry 0, a
/// top-level walk's from the processor's `top_stack_base`, the scene's deepest object tree
/// (`ProgramConfig::top_stack_base`, the same in every frame: the object trees do not
/// change), so the two trees' depths must fit the stack together.
fn check_stack_depths(layouts: &[Layout]) -> Result<()> {
    let deepest = |depth: fn(&Layout) -> u32| layouts.iter().map(depth).max().unwrap_or(0);
    let (object, top) = (
        deepest(|l| l.info.object_depth),
        deepest(|l| l.info.top_depth),
    );
    if layouts.iter().any(|l| l.info.top_root.is_some()) {
        let base = layouts
            .iter()
            .map(|l| crate::hw::program::top_stack_base(&l.info))
            .max()
            .unwrap_or(1);
        anyhow::ensure!(
            object <= base && base as usize + top as usize <= STACK_LEVELS,
            "the scene's deepest object kd tree has {object} levels and its top-level tree \
             {top}: the traversal unit's stack holds {STACK_LEVELS} for both together: use \
             fewer triangles per object or fewer instances"
        );
    } else {
        anyhow::ensure!(
            object as usize <= STACK_LEVELS,
            "the scene's deepest object kd tree has {object} levels; the traversal unit's stack \
             holds {STACK_LEVELS}: use fewer triangles per object or split the mesh into \
             instances"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's Quake3-p (17 objects under a top level) has an object tree 33 levels deep,
    /// past the half of the stack a fixed split gave the object walks: the processor's split
    /// follows the deepest object tree, so the scene is accepted, with the top-level walk's
    /// stack starting at that depth; moving the object trees' depth past what the stack
    /// leaves the top level is refused.
    #[test]
    fn the_stack_split_follows_the_deepest_object_tree() {
        let f = Format::E7M16;
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper/quake3_p.toml");
        let scene = Scene::load(&path).unwrap();
        let trees = SceneTrees::build(&scene, f).unwrap();
        let lay = layout::build(&scene, &trees, 0, &MemoryConfig::default()).unwrap();
        assert!(lay.info.top_root.is_some());
        assert!(
            lay.info.object_depth > 32,
            "depth {}",
            lay.info.object_depth
        );
        check_stack_depths(std::slice::from_ref(&lay)).unwrap();
        let config = ProgramConfig::from_layout(&lay);
        assert_eq!(config.top_stack_base, lay.info.object_depth);
        let mut deep = lay.clone();
        deep.info.object_depth = (STACK_LEVELS as u32) - lay.info.top_depth + 1;
        let err = check_stack_depths(&[deep]).unwrap_err().to_string();
        assert!(err.contains("for both together"), "{err}");
    }
}
