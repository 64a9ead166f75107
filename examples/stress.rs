//! Runs the stress suite: `cargo run --release --example stress -- [RAYS] [MARGIN] [MESH_DIR] [FORMATS,...]`.
use dynrt::stress::{run_stress, StressConfig};
fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    let mut c = StressConfig::default();
    if let Some(r) = a.get(1) {
        c.rays = r.parse()?;
    }
    if let Some(m) = a.get(2) {
        c.edge_margins = m.split(',').map(str::parse).collect::<Result<_, _>>()?;
    }
    if let Some(d) = a.get(3).filter(|d| !d.is_empty() && *d != "-") {
        c.mesh_dir = Some(d.into());
    }
    if let Some(f) = a.get(4) {
        c.formats = f
            .split(',')
            .map(dynrt::fp::Format::parse)
            .collect::<Result<_, _>>()?;
    }
    let report = run_stress(&c, &mut |l| eprintln!("{l}"))?;
    print!("{}", report.table());
    report.save_csv(std::path::Path::new("out/stress/stress.csv"))?;
    std::process::exit(if report.all_held() { 0 } else { 1 })
}
