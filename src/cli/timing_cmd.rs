//! `dynrt timing`: placed-and-routed timing on an ECP5 (LFE5UM-85F, speed 6, out of context) of
//! FP operators and geometry units alone (`--unit add,mul,transform,...`) and of the whole
//! processor of scenes (`dynrt timing SCENE...`), with `dynrt::synth::ecp5`.
//!
//! Contract: every name, the format, the clock constraint, the seeds and the scenes are checked,
//! and the tools looked up, before anything runs. Each design gets a folder under `--out` (its
//! Verilog, yosys log and netlist, `seed<S>/report.json` and `seed<S>/nextpnr.log`), and
//! `timing.md` and `timing.csv` in `--out` are rewritten after each design, so a long run that
//! is stopped keeps what it measured. A design whose flow fails is reported and the others still
//! run; the exit status is then 1.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;
use dynrt::emit::processor::{ProcessorParams, PROCESSOR_TOP};
use dynrt::emit::{fp_unit_rtl, geometry_unit_rtl, GeometryUnit};
use dynrt::flow;
use dynrt::fp::{BinOp, Format};
use dynrt::synth::ecp5::{self, Ecp5Options};
use dynrt::synth::timing_table::{self, DesignTiming, PROCESSOR_KIND};

#[derive(Args)]
pub struct TimingArgs {
    /// Scene files (TOML): the whole processor of each (place and route takes about half an
    /// hour per design).
    pub scenes: Vec<PathBuf>,
    /// Units alone, comma-separated: FP operators add, sub, mul, div, sqrt, lt, le, eq; geometry
    /// units transform, shared_transform, intersect, raygen.
    #[arg(long, value_delimiter = ',')]
    pub unit: Vec<String>,
    /// Number format eXmY: X exponent bits (2..8), Y mantissa bits (1..23).
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// Clock constraint for every clock of the design, MHz.
    #[arg(long, default_value_t = 90.0)]
    pub freq: f64,
    /// nextpnr placer seeds, comma-separated: one place and route each, and their spread.
    #[arg(long, value_delimiter = ',', default_values = ["1"])]
    pub seeds: Vec<u64>,
    /// Ray threads of the processor (1..=32).
    #[arg(long, default_value_t = 32)]
    pub threads: u32,
    /// SRAM read latency of the processor in clocks (1..=6).
    #[arg(long, default_value_t = 2)]
    pub mem_latency: u32,
    #[command(flatten)]
    pub cache: super::CacheArgs,
    /// Report directory: timing.md, timing.csv and a folder per design.
    #[arg(long, default_value = "out/timing")]
    pub out: PathBuf,
    /// Print the result as one JSON document on stdout (the rows of timing.csv under "rows",
    /// the designs that failed under "failed"); the per-design lines go to stderr.
    #[arg(long)]
    pub json: bool,
}

enum Design {
    Fp(BinOp),
    Geometry(GeometryUnit),
    Processor {
        path: PathBuf,
        name: String,
        scene: Box<dynrt::scene::Scene>,
    },
}

fn parse_unit(name: &str) -> anyhow::Result<Design> {
    let name = name.trim();
    if let Some(op) = BinOp::parse(name) {
        return Ok(Design::Fp(op));
    }
    if let Ok(u) = name.parse::<GeometryUnit>() {
        return Ok(Design::Geometry(u));
    }
    bail!(
        "unknown unit `{name}`: expected an FP operator ({}) or a geometry unit ({}); for the \
         whole processor give a scene file instead, e.g. `dynrt timing scenes/cornell.toml`",
        BinOp::ALL.map(|o| o.name()).join(", "),
        GeometryUnit::ALL.map(|u| u.name()).join(", ")
    )
}

/// Writes the design's Verilog under `dir` and returns (display name, kind, source, top).
fn emit(
    d: &Design,
    f: Format,
    params: ProcessorParams,
    dir: &Path,
) -> anyhow::Result<(String, &'static str, PathBuf, String)> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let write = |top: &str, verilog: &str| -> anyhow::Result<PathBuf> {
        let path = dir.join(format!("{top}.v"));
        std::fs::write(&path, verilog)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(path)
    };
    Ok(match d {
        Design::Fp(op) => {
            let u = fp_unit_rtl(*op, f)?;
            let src = write(&u.top, &u.verilog)?;
            (format!("fp {} {f}", op.name()), "fp operator", src, u.top)
        }
        Design::Geometry(g) => {
            let u = geometry_unit_rtl(*g, f)?;
            let src = write(&u.top, &u.verilog)?;
            (format!("{g} {f}"), "geometry unit", src, u.top)
        }
        Design::Processor { name, scene, .. } => {
            let gen = dir.join("generated");
            flow::generate_rtl(
                scene,
                name,
                f,
                params,
                None,
                &gen,
                &dynrt::provenance::GeneratedBy::this_run(false),
                None,
            )?;
            let src = gen.join("rtl").join(format!("{PROCESSOR_TOP}.v"));
            (
                format!("{name} ({} threads, {f})", params.threads),
                PROCESSOR_KIND,
                src,
                PROCESSOR_TOP.to_string(),
            )
        }
    })
}

fn folder(d: &Design, f: Format) -> String {
    match d {
        Design::Fp(op) => format!("fp_{}_{f}", op.name()),
        Design::Geometry(g) => format!("{g}_{f}"),
        Design::Processor { name, .. } => format!("processor_{name}"),
    }
}

pub fn run(a: TimingArgs) -> anyhow::Result<i32> {
    if a.unit.is_empty() && a.scenes.is_empty() {
        bail!(
            "nothing to measure: give --unit NAME[,NAME...] (e.g. --unit add) and/or scene files \
             (e.g. scenes/cornell.toml)"
        );
    }
    let options = Ecp5Options {
        freq_mhz: a.freq,
        seeds: a.seeds.clone(),
        ..Ecp5Options::default()
    };
    ecp5::check_options(&options)?;
    let params = a.cache.params(a.threads, a.mem_latency);
    let mut designs = Vec::new();
    for u in &a.unit {
        designs.push(parse_unit(u)?);
    }
    for path in &a.scenes {
        // The scene's errors name its file; the processor's limits are checked before any
        // tool runs, as `dynrt rtl` does.
        let scene = super::render_cmd::load_scene(path, None, None)?;
        flow::preflight(&scene, a.format, params, None)?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());
        designs.push(Design::Processor {
            path: path.clone(),
            name,
            scene: Box::new(scene),
        });
    }
    let mut folders: Vec<String> = designs.iter().map(|d| folder(d, a.format)).collect();
    folders.sort();
    if let Some(w) = folders.windows(2).find(|w| w[0] == w[1]) {
        bail!(
            "`{}` is asked for twice; name each unit and scene once",
            w[0]
        );
    }
    dynrt::output::check_output_dir(&a.out, "--out")?;
    let tools = ecp5::timing_tools()?;
    let say = |text: &str| {
        if a.json {
            super::log_line(text.trim_end());
        } else {
            println!("{}", text.trim_end());
        }
    };
    say(&format!(
        "ECP5 timing ({}, out of context, {} MHz, seeds {}): yosys {}, nextpnr-ecp5 {}",
        ecp5::DEVICE,
        a.freq,
        a.seeds
            .iter()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(","),
        tools.yosys_version,
        tools.nextpnr_version
    ));
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("creating --out '{}'", a.out.display()))?;
    // The binary's own path depends on the target directory; the verb and its arguments are
    // what reproduces the table.
    let command = std::iter::once("dynrt".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ");
    let mut done: Vec<DesignTiming> = Vec::new();
    let mut failed = Vec::new();
    for d in &designs {
        let dir = a.out.join(folder(d, a.format));
        let result = emit(d, a.format, params, &dir).and_then(|(name, kind, src, top)| {
            let r = ecp5::ecp5_timing(&[src], &top, &dir, &options)?;
            Ok(DesignTiming {
                name,
                kind: kind.to_string(),
                report: r,
            })
        });
        match result {
            Ok(t) => {
                say(&design_text(&t));
                done.push(t);
                write_tables(&a.out, &done, &command)?;
            }
            Err(e) => {
                let what = match d {
                    Design::Processor { path, .. } => path.display().to_string(),
                    _ => folder(d, a.format),
                };
                eprintln!("error: {what}: {e:#}");
                failed.push(what);
            }
        }
    }
    if !done.is_empty() {
        say(&format!(
            "wrote {} and {}",
            a.out.join("timing.md").display(),
            a.out.join("timing.csv").display()
        ));
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&timing_json(&done, &failed, &a, &tools))?
        );
    }
    if failed.is_empty() {
        Ok(0)
    } else {
        eprintln!("timing failed for: {}", failed.join(", "));
        Ok(1)
    }
}

fn write_tables(out: &Path, done: &[DesignTiming], command: &str) -> anyhow::Result<()> {
    dynrt::output::write_atomically(
        &out.join("timing.md"),
        timing_table::markdown(done, command).as_bytes(),
    )?;
    dynrt::output::write_atomically(&out.join("timing.csv"), timing_table::csv(done).as_bytes())?;
    Ok(())
}

/// The lines printed for one measured design.
fn design_text(t: &DesignTiming) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let r = &t.report;
    let _ = writeln!(
        out,
        "{} (yosys {:.0} s, place and route {:.0} s over {} seed(s)):",
        t.name,
        r.synth_seconds,
        r.pnr_seconds(),
        r.runs.len()
    );
    for run in &r.runs {
        for c in &run.report.clocks {
            let path = run.report.critical_path(&c.clock).map_or(String::new(), |p| {
                format!(
                    "; critical path {} -> {}: {} logic levels ({} carry), {:.2} ns logic + {:.2} ns routing",
                    p.start.block, p.end.block, p.logic_levels, p.carry_cells, p.logic_ns, p.routing_ns
                )
            });
            let _ = writeln!(
                out,
                "  seed {}: {} {:.1} MHz ({} at {} MHz){path}",
                run.seed,
                c.clock,
                c.achieved_mhz,
                if c.met() { "met" } else { "FAILS" },
                c.constraint_mhz
            );
        }
        let _ = writeln!(
            out,
            "  seed {}: LUT4 {}, FF {}, DP16KD {}, MULT18X18D {} ({})",
            run.seed,
            run.report.used("TRELLIS_COMB"),
            run.report.used("TRELLIS_FF"),
            run.report.used("DP16KD"),
            run.report.used("MULT18X18D"),
            run.report_json.display()
        );
    }
    if r.runs.len() > 1 {
        for clock in r.clocks() {
            if let Some(s) = r.fmax_spread(&clock) {
                let _ = writeln!(
                    out,
                    "  {clock} over the seeds: min {:.1}, median {:.1}, max {:.1} MHz",
                    s.min, s.median, s.max
                );
            }
        }
    }
    out
}

/// The `--json` document: what was asked, the tools, the rows of timing.csv, what failed.
fn timing_json(
    done: &[DesignTiming],
    failed: &[String],
    a: &TimingArgs,
    tools: &ecp5::TimingTools,
) -> serde_json::Value {
    let files = ["timing.md", "timing.csv"].map(|f| a.out.join(f).display().to_string());
    serde_json::json!({
        "verb": "timing",
        "pass": failed.is_empty(),
        "dynrt_version": env!("CARGO_PKG_VERSION"),
        "device": ecp5::DEVICE,
        "freq_mhz": a.freq,
        "format": a.format.to_string(),
        "seeds": a.seeds,
        "tools": { "yosys": tools.yosys_version, "nextpnr-ecp5": tools.nextpnr_version },
        "rows": super::bench_cmd::csv_rows_json(&timing_table::csv(done), &["yosys", "nextpnr"]),
        "failed": failed,
        "files": files,
    })
}
