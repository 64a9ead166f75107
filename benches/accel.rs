//! Acceleration-structure build benchmark: `cargo bench --bench accel [-- OUT.csv]`
//! (default `out/bench/accel.csv`). See `dynrt::accel::bench`.

use dynrt::accel::bench::{bench_build, BenchConfig};
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let mut cfg = BenchConfig::default();
    // cargo passes `--bench` to harness-less benchmarks; the first other argument is the CSV path.
    if let Some(out) = std::env::args().skip(1).find(|a| !a.starts_with("--")) {
        cfg.out_csv = PathBuf::from(out);
    }
    bench_build(&cfg)?;
    Ok(())
}
