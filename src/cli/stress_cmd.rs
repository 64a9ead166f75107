//! `dynrt stress`: the seeded numerical stress suite; exits non-zero when an invariant breaks.

use clap::Args;
use dynrt::fp::Format;
use dynrt::provenance::GeneratedBy;
use dynrt::report::RunSummary;
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
    /// Seed of the random rays and cases.
    #[arg(long, default_value_t = 0x5EED)]
    pub seed: u64,
    /// Output folder: stress.csv, summary.json, report.md, junit.xml.
    #[arg(long, default_value = "out/stress")]
    pub out: PathBuf,
    /// Print the run's summary.json on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
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
    dynrt::output::check_output_dir(&a.out, "--out")?;
    let mut s = RunSummary::new("stress", &GeneratedBy::this_run(false));
    s.option(
        "formats",
        c.formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
    )
    .option("rays", c.rays)
    .option("margins", &c.edge_margins)
    .option("meshes", &a.meshes)
    .option("seed", format!("{:#x}", a.seed));
    c.mesh_dir = a.meshes;
    c.seed = a.seed;
    if !a.json {
        println!("seed {:#x}", c.seed);
    }
    let report = run_stress(&c, &mut |l| super::log_line(l))?;
    let out = dynrt::output::OutputDir::create(&a.out, "--out")?;
    let csv = a.out.join("stress.csv");
    report.save_csv(&csv)?;
    for r in &report.rows {
        s.add_check(
            &format!(
                "{} / {} / {} / margin {}",
                r.case, r.subject, r.format, r.edge_margin
            ),
            r.held,
            &format!(
                "{} failures in {} rays ({:.1} ppm, bound {}){}{}",
                r.failures,
                r.rays,
                r.ppm(),
                r.bound_ppm
                    .map_or("none".to_string(), |b| format!("{b} ppm")),
                if r.nonfinite > 0 {
                    format!(", {} non-finite colours", r.nonfinite)
                } else {
                    String::new()
                },
                if r.note.is_empty() {
                    String::new()
                } else {
                    format!("; {}", r.note)
                }
            ),
            None,
        );
    }
    s.details_md = format!("## Cases\n\n{}", report.markdown());
    s.write(&a.out, true)?;
    out.keep();
    if a.json {
        println!("{}", s.json());
    } else {
        print!("{}", report.table());
        println!("written to {}", a.out.display());
    }
    Ok(if report.all_held() {
        0
    } else {
        super::EXIT_DIFFERS
    })
}
