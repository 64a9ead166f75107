//! `dynrt stress`: the seeded numerical stress suite; exits non-zero when an invariant breaks.

use clap::Args;
use dynrt::fp::Format;
use dynrt::stress::{run_stress, StressConfig};
use std::path::PathBuf;

#[derive(Args)]
pub struct StressArgs {
    /// Formats to stress (comma-separated); default: the suite's own list.
    #[arg(long, value_delimiter = ',')]
    pub formats: Vec<Format>,
    /// Rays per ray case.
    #[arg(long)]
    pub rays: Option<usize>,
    /// Edge margins of the unit-triangle test to try, in units of 2^-mantissa bits.
    #[arg(long, value_delimiter = ',')]
    pub margins: Vec<f64>,
    /// Directory of public meshes; closed ones join the watertightness cases.
    #[arg(long)]
    pub meshes: Option<PathBuf>,
    #[arg(long, default_value_t = 0x5EED)]
    pub seed: u64,
    #[arg(long, default_value = "out/stress/stress.csv")]
    pub out: PathBuf,
}

pub fn run(a: StressArgs) -> anyhow::Result<i32> {
    let mut c = StressConfig::default();
    if !a.formats.is_empty() {
        c.formats = a.formats;
    }
    if let Some(r) = a.rays {
        c.rays = r;
    }
    if !a.margins.is_empty() {
        // A margin counts ulps the unit-triangle test widens its edges by: NaN or an infinity
        // makes every comparison false, a negative one shrinks the triangle, and beyond 2^16
        // ulps the edge moves by more than the triangle is wide in every format.
        for m in &a.margins {
            anyhow::ensure!(
                m.is_finite() && (0.0..=65536.0).contains(m),
                "--margins {m}: an edge margin is a number of ulps in 0..=65536 (e.g. --margins 0,64)"
            );
        }
        c.edge_margins = a.margins;
    }
    if let Some(r) = a.rays {
        anyhow::ensure!(
            (1..=100_000_000).contains(&r),
            "--rays {r}: give 1..=100000000 rays per case"
        );
    }
    dynrt::output::check_output_file(&a.out, "--out")?;
    c.mesh_dir = a.meshes;
    c.seed = a.seed;
    println!("seed {:#x}", c.seed);
    let report = run_stress(&c, &mut |l| eprintln!("{l}"))?;
    print!("{}", report.table());
    report.save_csv(&a.out)?;
    println!("written to {}", a.out.display());
    Ok(if report.all_held() {
        0
    } else {
        super::EXIT_DIFFERS
    })
}
