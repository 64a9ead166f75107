//! `dynrt scenes`: the scenes bundled with the binary, listed or written out as files.

use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Args)]
pub struct ScenesArgs {
    #[command(subcommand)]
    pub what: ScenesWhat,
}

#[derive(Subcommand)]
pub enum ScenesWhat {
    /// Print the path of every bundled file (give a scene's path to any command).
    List,
    /// Write every bundled file into DIR (scenes, meshes/, paper/); nothing is overwritten.
    Export {
        /// Folder to write into (created if missing).
        dir: PathBuf,
    },
}

pub fn run(a: ScenesArgs) -> anyhow::Result<i32> {
    match a.what {
        ScenesWhat::List => {
            for (name, _) in dynrt::bundled::FILES {
                println!("{}", dynrt::bundled::path(name).display());
            }
        }
        ScenesWhat::Export { dir } => {
            let written = dynrt::bundled::export(&dir)?;
            println!(
                "wrote {} files into {} (e.g. {})",
                written.len(),
                dir.display(),
                dir.join("cornell.toml").display()
            );
        }
    }
    Ok(0)
}
