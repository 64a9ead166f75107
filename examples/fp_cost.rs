//! Synthesizes (or loads from the cache) the fp operator costs of every supported format:
//! `cargo run --release --example fp_cost -- [CACHE.csv]`.
fn main() -> anyhow::Result<()> {
    let csv = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/bench/fp_cost.csv".into());
    let formats = dynrt::hw::fp::supported_formats();
    let work = std::env::temp_dir().join("dynrt-fp-cost");
    let costs = dynrt::bench::cost::measure_or_load(
        &formats,
        std::path::Path::new(&csv),
        &work,
        true,
        &mut |l| eprintln!("{l}"),
    )?;
    for c in costs {
        println!(
            "{} {} {} LUTs {} FFs {} MULT18X18",
            c.format,
            c.op.name(),
            c.luts,
            c.flip_flops,
            c.mult18x18
        );
    }
    Ok(())
}
