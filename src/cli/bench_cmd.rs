//! `dynrt bench`: measurements written as CSV and Markdown under `--out`.

use clap::{Args, Subcommand};
use dynrt::bench;
use dynrt::fp::Format;
use dynrt::provenance::GeneratedBy;
use dynrt::report::RunSummary;
use std::path::PathBuf;

#[derive(Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: BenchWhat,
    /// Report directory.
    #[arg(long, default_value = "out/bench", global = true)]
    pub out: PathBuf,
    /// Folder of the scenes that `precision`, `scenes` and `trees` measure by default
    /// (default: the scenes bundled with the binary, the repository's scenes/ as it was built;
    /// `dynrt scenes export DIR` writes them out). `precision` reads its operator cost cache
    /// from benches/data/ beside the folder when there is one.
    #[arg(long, value_name = "DIR", global = true)]
    pub scenes_dir: Option<PathBuf>,
    /// Print the run's summary.json on stdout (with the table's rows under "rows") and
    /// nothing else; progress and messages go to stderr.
    #[arg(long, global = true)]
    pub json: bool,
}

#[derive(Subcommand)]
pub enum BenchWhat {
    /// FP operators: latency, yosys xc2v resources and depth, Verilator operations per second.
    Fp {
        /// Formats to measure (comma-separated); default: the paper's e7m16 and IEEE e8m23.
        #[arg(long, value_delimiter = ',', default_values = ["e7m16", "e8m23"])]
        formats: Vec<Format>,
        /// Random vectors per Verilator run (0: skip simulation).
        #[arg(long, default_value_t = 200_000)]
        vectors: usize,
    },
    /// Number formats: error against the f64 reference versus hardware cost and run time, with
    /// the Pareto front (CSV + PNG plots).
    Precision {
        /// Edge margin of the unit-triangle test, in units of 2^-mantissa bits (default: the
        /// hardware's, `units::EDGE_MARGIN_ULPS`; 0 = the exact test).
        #[arg(long, default_value_t = dynrt::units::EDGE_MARGIN_ULPS as f64)]
        margin: f64,
        /// Directory of public OBJ meshes to add to the bundled scenes.
        #[arg(long)]
        meshes: Option<PathBuf>,
        /// Override every scene's frame size, e.g. 64x48.
        #[arg(long = "size", alias = "resolution", value_name = "WxH", value_parser = super::parse_size)]
        resolution: Option<(u32, u32)>,
    },
    /// Bundled scenes: tree build rate, layout size, golden and reference speed, golden error.
    Scenes {
        /// Scene files; default: every scene of --scenes-dir (the bundled scenes).
        scenes: Vec<PathBuf>,
        /// Number formats to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values = ["e7m16", "e8m23"])]
        formats: Vec<Format>,
        /// Override every scene's frame size, e.g. 128x96.
        #[arg(long = "size", alias = "resolution", value_name = "WxH", value_parser = super::parse_size)]
        resolution: Option<(u32, u32)>,
    },
    /// The paper's Table 3 scenes (scenes/paper/): golden frames, memory against the six
    /// 4 MB banks, the processor in Verilator for the scenes that fit, fps beside the paper's.
    Paper {
        /// Folder of the suite's scene files (default: the suite bundled with the binary,
        /// bundled:/paper; `dynrt paper-scenes` writes them).
        #[arg(long, value_name = "DIR")]
        scenes: Option<PathBuf>,
        /// Only these scenes (file stems, comma-separated), e.g. scene6,castle.
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Frame size of the golden frames and memory maps (default: the paper's 512x384).
        #[arg(long = "size", alias = "resolution", value_name = "WxH", value_parser = super::parse_size)]
        resolution: Option<(u32, u32)>,
        /// Frame size of the processor's Verilator runs, the same view (default: the golden
        /// frames'); fps are always stated for 512x384 at the run's cycles per pixel.
        #[arg(long = "sim-size", alias = "sim-resolution", value_name = "WxH", value_parser = super::parse_size)]
        sim_resolution: Option<(u32, u32)>,
        /// Leave the processor's Verilator runs out.
        #[arg(long)]
        no_sim: bool,
        /// State fps at this clock, MHz (default: the paper's 90 MHz, assumed).
        #[arg(long, conflicts_with = "timing_report")]
        clock: Option<f64>,
        /// State fps at the clock measured in this `dynrt timing` report (timing.csv).
        #[arg(long)]
        timing_report: Option<PathBuf>,
    },
    /// kd-trees with and without the node budget: nodes per triangle, SAH cost, nodes visited
    /// and triangle tests per ray of the f64 reference (out/bench/trees.csv and .md).
    Trees {
        /// Scene files; default: every scene of --scenes-dir (the bundled scenes).
        scenes: Vec<PathBuf>,
        /// Directory of public OBJ meshes (default: the shared mesh folder).
        #[arg(long)]
        meshes: Option<PathBuf>,
    },
}

/// The folder of scenes to measure: `--scenes-dir` when given (it must be a folder), else
/// the scenes bundled with the binary.
fn scenes_dir(dir: Option<&std::path::Path>) -> anyhow::Result<PathBuf> {
    let Some(dir) = dir else {
        return Ok(dynrt::bundled::dir(""));
    };
    anyhow::ensure!(
        dynrt::bundled::is_dir(dir),
        "--scenes-dir '{}' is not a folder of scene files; give the folder of your scene files, or leave --scenes-dir out for the scenes bundled with dynrt",
        dir.display()
    );
    Ok(dir.to_path_buf())
}

/// Prints `line` on stdout unless the run prints JSON (then on stderr, to keep stdout one
/// JSON document).
fn say(json: bool, line: &str) {
    if json {
        super::log_line(line);
    } else {
        println!("{line}");
    }
}

/// The rows of a CSV table as JSON objects keyed by its header (numbers as numbers, `true` and
/// `false` as booleans), but the cells of `text_columns` as text: a version such as yosys
/// "0.70" read as a number would print as 0.7.
pub(crate) fn csv_rows_json(csv_text: &str, text_columns: &[&str]) -> serde_json::Value {
    let mut r = csv::Reader::from_reader(csv_text.as_bytes());
    let header: Vec<String> = match r.headers() {
        Ok(h) => h.iter().map(str::to_string).collect(),
        Err(_) => return serde_json::Value::Array(Vec::new()),
    };
    let rows = r
        .records()
        .filter_map(Result::ok)
        .map(|rec| {
            let m: serde_json::Map<String, serde_json::Value> = header
                .iter()
                .zip(rec.iter())
                .map(|(k, v)| {
                    let cell = if text_columns.contains(&k.as_str()) {
                        v.into()
                    } else {
                        cell_json(v)
                    };
                    (k.clone(), cell)
                })
                .collect();
            serde_json::Value::Object(m)
        })
        .collect();
    serde_json::Value::Array(rows)
}

/// A CSV cell as JSON: an integer, a finite number or a boolean when it reads as one, else
/// the text.
fn cell_json(v: &str) -> serde_json::Value {
    if let Ok(b) = v.parse::<bool>() {
        return b.into();
    }
    if let Ok(i) = v.parse::<i64>() {
        return i.into();
    }
    match v.parse::<f64>() {
        Ok(f) if f.is_finite() => f.into(),
        _ => v.into(),
    }
}

pub fn run(a: BenchArgs) -> anyhow::Result<i32> {
    dynrt::output::check_output_dir(&a.out, "--out")?;
    let verb = match &a.what {
        BenchWhat::Fp { .. } => "bench fp",
        BenchWhat::Precision { .. } => "bench precision",
        BenchWhat::Scenes { .. } => "bench scenes",
        BenchWhat::Paper { .. } => "bench paper",
        BenchWhat::Trees { .. } => "bench trees",
    };
    // The folder's summary.json and report.md describe its latest bench run (every bench
    // writes its own tables beside them).
    let mut s = RunSummary::new(verb, &GeneratedBy::this_run(false));
    let json = a.json;
    let scenes_dir_arg = a.scenes_dir.as_deref();
    // The rows of the command's table, for --json.
    let rows: serde_json::Value;
    match a.what {
        BenchWhat::Fp { formats, vectors } => {
            let work = tempfile::tempdir()?;
            let measured =
                bench::fp::bench_fp(&bench::fp::DISTINCT_OPS, &formats, vectors, work.path())?;
            let t = bench::fp::fp_table(&measured);
            t.save(&a.out, "fp")?;
            say(json, t.to_markdown().trim_end());
            rows = csv_rows_json(&t.to_csv(), &[]);
            s.option(
                "formats",
                formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
            )
            .option("vectors", vectors);
            s.details_md = t.to_markdown();
            if let Some(r) = measured.first() {
                say(
                    json,
                    &format!("yosys: {} ({})", r.synth.yosys_version, r.synth.command),
                );
                s.tools
                    .insert("yosys".into(), r.synth.yosys_version.clone());
            }
        }
        BenchWhat::Precision {
            margin,
            meshes,
            resolution,
        } => {
            let dir = scenes_dir(scenes_dir_arg)?;
            let mut c = bench::SweepConfig::new(&dir)?;
            c.edge_margin_ulps = margin;
            c.mesh_dir = meshes;
            if let Some((w, h)) = resolution {
                (c.width, c.height) = (w, h);
            }
            let measured = bench::precision_sweep(&c, &mut |l| super::log_line(l))?;
            for p in bench::write_outputs(&measured, &a.out)? {
                say(json, &format!("wrote {}", p.display()));
            }
            let summary = bench::summarize(&measured);
            let csv = bench::precision::summary_csv(&summary);
            say(json, csv.trim_end());
            rows = csv_rows_json(&csv, &[]);
            s.option("margin", margin)
                .option("scenes_dir", &dir)
                .option("resolution", resolution.map(|(w, h)| format!("{w}x{h}")));
            s.details_md = format!("## Summary (CSV)\n\n```\n{csv}```\n");
            if let Some(r) = bench::recommend(&summary, 1e-3, 100.0) {
                say(json, &format!("recommended: {}", r.format));
                s.notes.push(format!("recommended format: {}", r.format));
            }
        }
        BenchWhat::Scenes {
            scenes,
            formats,
            resolution,
        } => {
            let scenes = if scenes.is_empty() {
                bench::scenes::bundled_scenes(&scenes_dir(scenes_dir_arg)?)?
            } else {
                scenes
            };
            let measured = bench::scenes::bench_scenes(&scenes, &formats, resolution)?;
            let t = bench::scenes::scenes_table(&measured);
            t.save(&a.out, "scenes")?;
            say(json, t.to_markdown().trim_end());
            rows = csv_rows_json(&t.to_csv(), &[]);
            s.option("scenes", &scenes)
                .option(
                    "formats",
                    formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
                )
                .option("resolution", resolution.map(|(w, h)| format!("{w}x{h}")));
            s.details_md = t.to_markdown();
        }
        BenchWhat::Paper {
            scenes,
            only,
            resolution,
            sim_resolution,
            no_sim,
            clock,
            timing_report,
        } => {
            let (mhz, clock_source) = super::rtl_cmd::clock_mhz(clock, timing_report.as_deref())?;
            let scenes = scenes.unwrap_or_else(|| dynrt::bundled::dir("paper"));
            let o = bench::paper::Options {
                scenes: &scenes,
                only: &only,
                resolution,
                sim_resolution: sim_resolution.or(resolution),
                sim: !no_sim,
                stdout: !json,
            };
            let (md, differs) = bench::paper::run(&o, &a.out, mhz, &clock_source)?;
            s.option("scenes", &scenes)
                .option("only", &only)
                .option("resolution", resolution.map(|(w, h)| format!("{w}x{h}")))
                .option(
                    "sim_resolution",
                    sim_resolution.map(|(w, h)| format!("{w}x{h}")),
                )
                .option("sim", !no_sim)
                .option("clock_mhz", mhz);
            s.notes
                .push(format!("fps at {mhz:.1} MHz ({clock_source})"));
            s.details_md = md;
            rows = std::fs::read_to_string(a.out.join("paper.csv"))
                .map(|t| csv_rows_json(&t, &[]))
                .unwrap_or_default();
            if differs {
                s.pass = false;
                s.notes
                    .push("a processor frame differs from the golden model".into());
                s.write(&a.out, false)?;
                if json {
                    print_json(&s, rows);
                }
                say(
                    json,
                    "MISMATCH: a processor frame differs from the golden model",
                );
                return Ok(super::EXIT_DIFFERS);
            }
        }
        BenchWhat::Trees { scenes, meshes } => {
            let scenes = if scenes.is_empty() {
                bench::scenes::bundled_scenes(&scenes_dir(scenes_dir_arg)?)?
            } else {
                scenes
            };
            let meshes = meshes.unwrap_or_else(dynrt::scene::shared_mesh_dir);
            let measured = bench::trees::bench_trees(&bench::trees::mesh_files(&meshes)?, &scenes)?;
            let t = bench::trees::trees_table(&measured);
            t.save(&a.out, "trees")?;
            say(json, t.to_markdown().trim_end());
            rows = csv_rows_json(&t.to_csv(), &[]);
            s.option("scenes", &scenes).option("meshes", &meshes);
            s.details_md = t.to_markdown();
        }
    }
    s.write(&a.out, false)?;
    if json {
        print_json(&s, rows);
    } else {
        println!("written to {}", a.out.display());
    }
    Ok(0)
}

/// Prints the run's summary.json with the table's rows added under "rows".
fn print_json(s: &RunSummary, rows: serde_json::Value) {
    let mut j = serde_json::to_value(s).expect("a run summary serializes");
    j["rows"] = rows;
    println!(
        "{}",
        serde_json::to_string_pretty(&j).expect("JSON serializes")
    );
}
