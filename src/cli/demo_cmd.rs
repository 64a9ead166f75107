//! `dynrt demo`: the main job on a scene (default: the Cornell box bundled with the binary).

use clap::Args;
use dynrt::demo::{default_scene, run_demo, DemoConfig};
use dynrt::fp::Format;
use std::path::PathBuf;

#[derive(Args)]
pub struct DemoArgs {
    /// Scene file (default: the bundled Cornell box, bundled:/cornell.toml; any bundled scene
    /// is named bundled:NAME, see `dynrt scenes list`).
    pub scene: Option<PathBuf>,
    /// Number format eXmY: X exponent bits (2..8), Y mantissa bits (1..23).
    #[arg(long, default_value = "e7m16")]
    pub format: Format,
    /// Output folder (created if missing): frames, diff image, reports.
    #[arg(long, value_name = "DIR", default_value = "out/demo")]
    pub out: PathBuf,
    /// Random vectors per operator and simulator.
    #[arg(long, default_value_t = 20_000)]
    pub vectors: usize,
    /// Frame size of the golden model and the Verilator run, e.g. 16x12 (default: the
    /// scene's); the small Icarus frame is 4x3 or this, whichever is smaller.
    #[arg(long, value_name = "WxH", value_parser = super::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Print the run's summary.json on stdout instead of the one-line summary.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: DemoArgs) -> anyhow::Result<i32> {
    let config = DemoConfig {
        scene: a.scene.unwrap_or_else(default_scene),
        format: a.format,
        out: a.out,
        vectors: a.vectors,
        size: a.size,
        generated_by: dynrt::provenance::GeneratedBy::this_run(false),
    };
    let r = run_demo(&config)?;
    if a.json {
        println!("{}", r.json);
    } else {
        println!("{}", r.summary);
        println!("report: {}", r.report.display());
    }
    Ok(if r.ok { 0 } else { super::EXIT_DIFFERS })
}
