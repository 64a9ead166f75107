//! `dynrt paper-scenes`: writes the scene files of the paper's Table 3 (`scenes/paper/`).

use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct PaperScenesArgs {
    /// Folder for the scene files (created if missing).
    #[arg(long, default_value = "scenes/paper")]
    pub out: PathBuf,
}

pub fn run(a: PaperScenesArgs) -> anyhow::Result<i32> {
    dynrt::output::check_output_dir(&a.out, "--out")?;
    std::fs::create_dir_all(&a.out)
        .map_err(|e| anyhow::anyhow!("creating {}: {e}", a.out.display()))?;
    let files: Vec<(PathBuf, String)> = dynrt::scene::paper::suite_files()
        .into_iter()
        .map(|(name, text)| (a.out.join(name), text))
        .collect();
    let refs: Vec<(&std::path::Path, &[u8])> = files
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_bytes()))
        .collect();
    dynrt::output::write_all_atomically(&refs)?;
    for (p, _) in &files {
        println!("wrote {}", p.display());
    }
    Ok(0)
}
