//! `dynrt demo`: the main job on a scene (default: the bundled Cornell box).

use clap::Args;
use dynrt::demo::{default_scene, run_demo, DemoConfig};
use dynrt::fp::Format;
use std::path::PathBuf;

#[derive(Args)]
pub struct DemoArgs {
    /// Scene file (default: scenes/cornell.toml).
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
}

pub fn run(a: DemoArgs) -> anyhow::Result<i32> {
    // The default is relative to the repository: elsewhere say what to give instead.
    if a.scene.is_none() && !default_scene().is_file() {
        anyhow::bail!(
            "the default scene {} is not here (dynrt runs outside the repository); give a scene file, e.g. dynrt demo ~/dynrt/scenes/cornell.toml",
            default_scene().display()
        );
    }
    let config = DemoConfig {
        scene: a.scene.unwrap_or_else(|| default_scene().to_path_buf()),
        format: a.format,
        out: a.out,
        vectors: a.vectors,
        generated_by: dynrt::provenance::GeneratedBy::this_run(false),
    };
    let r = run_demo(&config)?;
    println!("{}", r.summary);
    println!("report: {}", r.report.display());
    Ok(if r.ok { 0 } else { super::EXIT_DIFFERS })
}
