//! The precision sweep: `cargo run --release --example precision -- OUT_DIR [MARGIN_ULPS] [MESH_DIR] [W H]`.
//! This is the call `dynrt bench precision` makes.
use dynrt::bench::{precision_sweep, recommend, summarize, write_outputs, SweepConfig};
fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    let out = std::path::PathBuf::from(a.get(1).map_or("out/bench", |s| s.as_str()));
    let mut c = SweepConfig::new(std::path::Path::new("scenes"))?;
    c.edge_margin_ulps = a.get(2).map_or(Ok(c.edge_margin_ulps), |m| m.parse())?;
    c.mesh_dir = a.get(3).filter(|d| *d != "-").map(Into::into);
    if let (Some(w), Some(h)) = (a.get(4), a.get(5)) {
        (c.width, c.height) = (w.parse()?, h.parse()?);
    }
    let rows = precision_sweep(&c, &mut |l| eprintln!("{l}"))?;
    for p in write_outputs(&rows, &out)? {
        println!("wrote {}", p.display());
    }
    let s = summarize(&rows);
    print!("{}", dynrt::bench::precision::summary_csv(&s));
    if let Some(r) = recommend(&s, 1e-3, 100.0) {
        println!("recommended: {}", r.format);
    }
    Ok(())
}
