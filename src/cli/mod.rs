//! Argument parsing (clap) and dispatch of the `dynrt` verbs. Errors are printed as one clear
//! message (with its causes) and give a non-zero exit status.

mod bench_cmd;
mod compare_cmd;
mod demo_cmd;
mod emit_fp_cmd;
mod fp_cmd;
mod info_cmd;
mod paper_scenes_cmd;
mod render_cmd;
mod rtl_cmd;
mod scenes_cmd;
mod stress_cmd;
mod synth_cmd;
mod timing_cmd;

use clap::{Args, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "dynrt",
    version,
    about = "Generates a SaarCOR DynRT-style ray tracing processor from a 3D scene",
    after_help = "Examples:\n  \
dynrt rtl scenes/tiny.toml --out out/tiny        # Verilog, testbench, images, FuseSoC core\n  \
dynrt sim scenes/cornell.toml --out out/cornell  # simulate and compare with the golden model\n  \
dynrt compare a.png b.png --fail-pixels 0        # exit 1 when any pixel differs\n  \
dynrt info                                       # versions of dynrt and its tools\n  \
dynrt completions bash > ~/.local/share/bash-completion/completions/dynrt\n\n\
Exit status: 0 success, 1 frames or results differ, 2 usage error or bad input, 3 a tool or \
the machine failed (a simulator missing, a timeout, a full disk), 128+N after signal N."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The main job on a scene: golden vs reference, FP operators simulated and checked; report.
    #[command(
        after_help = "Examples:\n  dynrt demo                                 # the bundled Cornell box, every check, out/demo\n  dynrt demo scenes/mirror.toml --out out/mirror\n  dynrt demo bundled:/tiny.toml --json"
    )]
    Demo(demo_cmd::DemoArgs),
    /// Render one frame with the golden model (eXmY) or the f64 reference.
    #[command(
        after_help = "Examples:\n  dynrt render scenes/cornell.toml --out out/render --hits   # frame0.png, hits0.csv\n  dynrt render scenes/dynamic.toml --frame 3 --model reference --size 128x96 --out out/ref"
    )]
    Render(render_cmd::RenderArgs),
    /// Error metrics between two images (and hits files); writes a diff image.
    Compare(compare_cmd::CompareArgs),
    /// Measure speed, area and error; CSV and Markdown reports under --out.
    #[command(
        after_help = "Examples:\n  dynrt bench scenes --formats e7m16 --out out/bench       # the bundled scenes\n  dynrt bench precision --size 64x48 --scenes-dir my_scenes\n  dynrt bench scenes bundled:/tiny.toml --size 8x6 --json"
    )]
    Bench(bench_cmd::BenchArgs),
    /// Write the Verilog and testbenches of every FP operator of a format.
    #[command(
        after_help = "Examples:\n  dynrt emit-fp --format e8m23 --out out/fp   # out/fp/rtl/*.v, out/fp/testbench/tb_*.v"
    )]
    EmitFp(emit_fp_cmd::EmitFpArgs),
    /// The seeded numerical stress suite; exits non-zero when an invariant breaks.
    #[command(
        after_help = "Examples:\n  dynrt stress --formats e7m16 --rays 2000 --out out/stress\n  dynrt stress --margins 0,64 --json"
    )]
    Stress(stress_cmd::StressArgs),
    /// yosys synth_xilinx -family xc2v of one geometry unit: resources and logic depth.
    #[command(after_help = "Examples:\n  dynrt synth --unit intersect --format e7m16")]
    Synth(synth_cmd::SynthArgs),
    /// Placed-and-routed timing (ECP5, nextpnr, out of context) of units alone or of the whole
    /// processor of scenes: fmax per clock, critical paths, utilization; timing.md/.csv.
    #[command(
        after_help = "Examples:\n  dynrt timing --unit add,mul --freq 120\n  dynrt timing scenes/cornell.toml --seeds 1,2,3 --out out/timing"
    )]
    Timing(timing_cmd::TimingArgs),
    /// The scenes bundled with the binary: list their paths (bundled:/NAME) or write them out.
    #[command(
        after_help = "Examples:\n  dynrt scenes list\n  dynrt scenes export my_scenes     # my_scenes/cornell.toml, my_scenes/meshes/, ...\n  dynrt render bundled:/tiny.toml --out out/tiny"
    )]
    Scenes(scenes_cmd::ScenesArgs),
    /// Write the scene files of the paper's Table 3 (scenes/paper/).
    #[command(after_help = "Examples:\n  dynrt paper-scenes --out scenes/paper")]
    PaperScenes(paper_scenes_cmd::PaperScenesArgs),
    /// Write the ray tracing processor of a scene: Verilog, testbench, memory images, UCF.
    #[command(
        after_help = "Examples:\n  dynrt rtl scenes/tiny.toml --out out/tiny\n  dynrt rtl scenes/cornell.toml --out out/cornell --board my_board.toml --synth"
    )]
    Rtl(rtl_cmd::RtlArgs),
    /// Generate, simulate (Icarus or Verilator) and compare every frame with the golden model.
    #[command(
        after_help = "Examples:\n  dynrt sim scenes/tiny.toml --out out/tiny --sim iverilog --size 8x6\n  dynrt sim scenes/cornell.toml --out out/cornell --trace fst --trace-start 1000 --trace-end 5000"
    )]
    Sim(rtl_cmd::SimArgs),
    /// Run operand vectors through one floating-point operator (RTL or software model).
    #[command(
        after_help = "Examples:\n  dynrt fp --op div --vectors v.hex --out out/fp --sim verilator   # out/fp/results.hex"
    )]
    Fp(fp_cmd::FpArgs),
    /// The versions of dynrt and of every tool it finds (simulators, yosys, nextpnr, FuseSoC,
    /// cocotb).
    Info(info_cmd::InfoArgs),
    /// Print a shell completion script, e.g. `dynrt completions bash >
    /// ~/.local/share/bash-completion/completions/dynrt`.
    #[command(
        after_help = "Examples:\n  dynrt completions bash > ~/.local/share/bash-completion/completions/dynrt"
    )]
    Completions(CompletionsArgs),
}

#[derive(Args)]
struct CompletionsArgs {
    /// The shell the script is for.
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

/// Writes the completion script of `shell` for the whole command tree to stdout.
fn completions(a: CompletionsArgs) -> anyhow::Result<i32> {
    use clap::CommandFactory;
    clap_complete::generate(
        a.shell,
        &mut Cli::command(),
        "dynrt",
        &mut std::io::stdout(),
    );
    Ok(0)
}

/// `WIDTHxHEIGHT` in pixels, e.g. `128x96`: the one resolution syntax of every command.
pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}`: expected WIDTHxHEIGHT such as 128x96"))?;
    Ok((
        w.parse()
            .map_err(|_| format!("`{w}` is not a width in pixels"))?,
        h.parse()
            .map_err(|_| format!("`{h}` is not a height in pixels"))?,
    ))
}

/// The frame size of `render`, `rtl` and `sim`: `--size WxH`, or the `--width`/`--height` of
/// older scripts (hidden from the help; either one alone keeps the scene's other number).
#[derive(Args, Clone, Copy, Debug)]
pub struct SizeArgs {
    /// Frame size in pixels, e.g. 64x48 (default: the scene's [camera] width and height).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// The frame's width alone (the older spelling of --size's first number).
    #[arg(long, hide = true, conflicts_with = "size")]
    pub width: Option<u32>,
    /// The frame's height alone (the older spelling of --size's second number).
    #[arg(long, hide = true, conflicts_with = "size")]
    pub height: Option<u32>,
}

impl SizeArgs {
    /// The width and the height asked for, each `None` to keep the scene's.
    pub fn width_height(&self) -> (Option<u32>, Option<u32>) {
        match self.size {
            Some((w, h)) => (Some(w), Some(h)),
            None => (self.width, self.height),
        }
    }
}

/// The shapes of the processor's three read-only caches (`rtl`, `sim` and `timing`): sets and
/// ways of each, the paper's 512 items direct mapped by default.
#[derive(Args, Clone, Copy, Debug)]
pub struct CacheArgs {
    /// Sets of the triangle cache in front of banks 2 and 3 (a power of two, sets times
    /// --tri-ways at most 512, the paper's 512 items; 0 for none).
    #[arg(long, value_name = "SETS", default_value_t = 512)]
    pub tri_cache: u32,
    /// Ways of the triangle cache (1, 2 or 4, e.g. --tri-cache 128 --tri-ways 4). A write
    /// fills the ways in turn.
    #[arg(long, value_name = "WAYS", default_value_t = 1)]
    pub tri_ways: u32,
    /// Sets of the node cache in front of bank 0 (the same rule with --node-ways; 0 for
    /// none). It keeps the object trees' nodes (the top level's are rewritten between
    /// frames) and is off at --mem-latency 1.
    #[arg(long, value_name = "SETS", default_value_t = 512)]
    pub node_cache: u32,
    /// Ways of the node cache (1, 2 or 4). A fill takes the ways in turn.
    #[arg(long, value_name = "WAYS", default_value_t = 1)]
    pub node_ways: u32,
    /// Sets of the instance cache in front of bank 4 (the same rule with --instance-ways; 0
    /// for none). It is flushed as each frame starts (the host rewrites the instances'
    /// records between frames).
    #[arg(long, value_name = "SETS", default_value_t = 512)]
    pub instance_cache: u32,
    /// Ways of the instance cache (1, 2 or 4, e.g. --instance-cache 256 --instance-ways 2).
    /// A miss fills its set's ways in turn.
    #[arg(long, value_name = "WAYS", default_value_t = 1)]
    pub instance_ways: u32,
}

impl CacheArgs {
    /// The processor with `threads` ray threads, SRAM latency `mem_latency` and these caches.
    pub fn params(&self, threads: u32, mem_latency: u32) -> dynrt::hw::processor::ProcessorParams {
        dynrt::hw::processor::ProcessorParams {
            threads,
            mem_latency,
            tri_cache_sets: self.tri_cache,
            tri_cache_ways: self.tri_ways,
            node_cache_sets: self.node_cache,
            node_cache_ways: self.node_ways,
            instance_cache_sets: self.instance_cache,
            instance_cache_ways: self.instance_ways,
        }
    }
}

/// Runs the command line and returns the process exit status.
pub fn run() -> i32 {
    let cli = Cli::parse();
    if let Err(e) = dynrt::sim::process::forward_signals() {
        eprintln!(
            "warning: cannot take Ctrl-C and SIGTERM to end the simulators dynrt starts: {e}"
        );
    }
    let spinner = progress_spinner();
    let result = match cli.command {
        Command::Render(a) => render_cmd::run(a),
        Command::Compare(a) => compare_cmd::run(a),
        Command::Fp(a) => fp_cmd::run(a),
        Command::Bench(a) => bench_cmd::run(a),
        Command::Demo(a) => demo_cmd::run(a),
        Command::Stress(a) => stress_cmd::run(a),
        Command::Synth(a) => synth_cmd::run(a),
        Command::Timing(a) => timing_cmd::run(a),
        Command::EmitFp(a) => emit_fp_cmd::run(a),
        Command::Rtl(a) => rtl_cmd::run_rtl(a),
        Command::Sim(a) => rtl_cmd::run_sim(a),
        Command::Info(a) => info_cmd::run(a),
        Command::PaperScenes(a) => paper_scenes_cmd::run(a),
        Command::Scenes(a) => scenes_cmd::run(a),
        Command::Completions(a) => completions(a),
    };
    spinner.finish_and_clear();
    match result {
        Ok(code) => code,
        Err(e) => {
            dynrt::sim::process::wait_if_interrupted();
            eprintln!("error: {e:#}");
            if disk_full(&e) {
                eprintln!(
                    "the disk is full: free space in the output's file system or name an output elsewhere, then run again"
                );
            }
            exit_code_of(&e)
        }
    }
}

/// The one progress display of a run (stderr), also the way [`log_line`] prints around it.
static PROGRESS: std::sync::OnceLock<indicatif::ProgressBar> = std::sync::OnceLock::new();

/// A spinner on stderr that shows the library's progress reports (stages, the testbench's
/// heartbeat) with the time since the last stage began, and runs of like steps (the precision
/// sweep, the stress suite) as N of total with the time left; indicatif draws nothing when
/// stderr is not a terminal, so logs and tests see no spinner.
fn progress_spinner() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(stage_style());
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let shown = bar.clone();
    dynrt::progress::listen(move |e| show_progress(&shown, e));
    let _ = PROGRESS.set(bar.clone());
    bar
}

fn stage_style() -> indicatif::ProgressStyle {
    indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner())
}

fn step_style() -> indicatif::ProgressStyle {
    indicatif::ProgressStyle::with_template(
        "{spinner} {pos} of {len}, about {eta} left ({elapsed}): {msg}",
    )
    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner())
}

/// Shows one progress report on `bar`.
fn show_progress(bar: &indicatif::ProgressBar, e: dynrt::progress::Event) {
    use dynrt::progress::Event;
    match e {
        // A heartbeat continues its stage.
        Event::Stage(m) if m.starts_with("frame ") => bar.set_message(format!("simulating {m}")),
        Event::Stage(m) => {
            if bar.length().is_some() {
                bar.unset_length();
                bar.set_style(stage_style());
            }
            bar.reset_elapsed();
            bar.set_message(m.to_string());
        }
        Event::Step { done, total, next } => {
            // A new run of steps: the estimate starts from its first step, not from whatever
            // ran before it (cost synthesis, a stage).
            if bar.length() != Some(total) || done == 0 {
                bar.set_style(step_style());
                bar.set_length(total);
                bar.reset();
            }
            bar.set_position(done);
            bar.set_message(next.to_string());
        }
    }
}

/// Prints a log line on stderr without tearing the progress display.
pub(crate) fn log_line(line: &str) {
    match PROGRESS.get() {
        Some(bar) => bar.suspend(|| eprintln!("{line}")),
        None => eprintln!("{line}"),
    }
}

/// Exit status when a command ran into results that differ (frames, vectors, invariants).
pub const EXIT_DIFFERS: i32 = 1;
/// Exit status of a usage error or bad input (scene, mesh, arguments, paths); clap uses it too.
pub const EXIT_USAGE: i32 = 2;
/// Exit status when a tool or the machine failed (a simulator missing, a timeout, a full disk).
pub const EXIT_TOOL: i32 = 3;

/// Whether `io` says the disk or the quota is full. The kind is asked as well as the OS code:
/// tempfile wraps the OS error with its path, and the wrapper keeps only the kind.
fn is_disk_full(io: &std::io::Error) -> bool {
    matches!(io.raw_os_error(), Some(libc::ENOSPC | libc::EDQUOT))
        || matches!(
            io.kind(),
            std::io::ErrorKind::StorageFull | std::io::ErrorKind::QuotaExceeded
        )
}

/// Whether the machine, not the input, failed a write or read: a full disk, an I/O error.
fn machine_failed(io: &std::io::Error) -> bool {
    is_disk_full(io) || io.raw_os_error() == Some(libc::EIO)
}

/// Whether the error chain holds a full disk or quota.
fn disk_full(e: &anyhow::Error) -> bool {
    e.chain()
        .any(|c| c.downcast_ref::<std::io::Error>().is_some_and(is_disk_full))
}

/// [`EXIT_TOOL`] when a tool error or a failure of the machine is in the chain, else
/// [`EXIT_USAGE`].
fn exit_code_of(e: &anyhow::Error) -> i32 {
    let tool = e.chain().any(|c| {
        c.downcast_ref::<dynrt::sim::ToolError>().is_some()
            || c.downcast_ref::<std::io::Error>()
                .is_some_and(machine_failed)
    });
    if tool {
        EXIT_TOOL
    } else {
        EXIT_USAGE
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    /// Every subcommand and every argument of every subcommand, with its path.
    fn walk(cmd: &clap::Command, path: &str, missing: &mut Vec<String>) {
        for arg in cmd.get_arguments() {
            let id = arg.get_id().as_str();
            // clap's own --help and --version carry their help text.
            if matches!(id, "help" | "version") {
                continue;
            }
            if arg.get_help().is_none() && arg.get_long_help().is_none() {
                missing.push(format!("{path} {id}"));
            }
        }
        for sub in cmd.get_subcommands() {
            if sub.get_about().is_none() && sub.get_name() != "help" {
                missing.push(format!("{path} {} (the command)", sub.get_name()));
            }
            walk(sub, &format!("{path} {}", sub.get_name()), missing);
        }
    }

    #[test]
    fn every_command_and_every_flag_has_a_help_text() {
        let cmd = Cli::command();
        cmd.clone().debug_assert();
        let mut missing = Vec::new();
        walk(&cmd, "dynrt", &mut missing);
        assert!(
            missing.is_empty(),
            "without help text:\n{}",
            missing.join("\n")
        );
    }

    #[test]
    fn steps_show_as_n_of_total_and_stages_as_a_spinner_again() {
        use dynrt::progress::Event;
        let bar = indicatif::ProgressBar::hidden();
        let step = |done, next| {
            show_progress(
                &bar,
                Event::Step {
                    done,
                    total: 7,
                    next,
                },
            )
        };
        show_progress(&bar, Event::Stage("building the kd-trees"));
        assert_eq!(bar.length(), None);
        step(0, "acne: box");
        step(3, "scale: far_small");
        assert_eq!((bar.position(), bar.length()), (3, Some(7)));
        assert_eq!(bar.message(), "scale: far_small");
        // A heartbeat keeps the count; a new stage drops it.
        show_progress(&bar, Event::Stage("frame 0: 10 cycles, 1 rays"));
        assert_eq!(bar.length(), Some(7));
        show_progress(&bar, Event::Stage("comparing"));
        assert_eq!(bar.length(), None);
        // A second run of steps counts from its own start.
        step(0, "again");
        assert_eq!((bar.position(), bar.length()), (0, Some(7)));
    }

    #[test]
    fn every_command_shows_examples_in_its_help() {
        let cmd = Cli::command();
        let without: Vec<&str> = cmd
            .get_subcommands()
            .filter(|c| c.get_name() != "help")
            .filter(|c| {
                !c.get_after_help()
                    .is_some_and(|h| h.to_string().contains("\n  dynrt "))
            })
            .map(|c| c.get_name())
            .collect();
        assert!(without.is_empty(), "no examples: {without:?}");
    }

    #[test]
    fn a_full_disk_is_the_machines_failure_even_when_wrapped_with_its_path() {
        // What tempfile returns when the disk fills: the kind kept, the OS code lost in the
        // wrapper that adds the path.
        let wrapped = std::io::Error::new(
            std::io::ErrorKind::StorageFull,
            "No space left on device (os error 28) at path x",
        );
        let e = anyhow::Error::new(wrapped).context("writing x");
        assert!(disk_full(&e));
        assert_eq!(exit_code_of(&e), EXIT_TOOL);
        let os = anyhow::Error::new(std::io::Error::from_raw_os_error(libc::ENOSPC));
        assert_eq!(exit_code_of(&os), EXIT_TOOL);
        // A folder the user may not write to is a bad path, not a broken machine.
        let denied = anyhow::Error::new(std::io::Error::from_raw_os_error(libc::EACCES))
            .context("writing x");
        assert!(!disk_full(&denied));
        assert_eq!(exit_code_of(&denied), EXIT_USAGE);
    }
}
