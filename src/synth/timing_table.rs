//! The tables of `dynrt timing`: `timing.md` (a summary row per design, then every seed and
//! clock) and `timing.csv` (one row per design, seed and clock domain), and reading the measured
//! processor clock back from such a CSV (`dynrt sim --timing-report`).
//!
//! Contract: the figures are the reports' own, unrounded in the CSV; the Markdown summary quotes
//! the main clock ([`TimingReport::main_clock`]) of the slowest seed, and its spread when there
//! are several seeds, and says per design whether the constraint was met.

use std::fmt::Write;

use super::ecp5::{TimingReport, DEVICE};

/// One measured design and what it is.
#[derive(Debug, Clone)]
pub struct DesignTiming {
    /// e.g. `fp add e7m16`, `transform e7m16`, `cornell`.
    pub name: String,
    /// `fp operator`, `geometry unit` or `processor`.
    pub kind: String,
    pub report: TimingReport,
}

pub const PROCESSOR_KIND: &str = "processor";

const CSV_HEADER: &str = "design,kind,top,seed,clock,constraint_mhz,achieved_mhz,met,\
path_from,path_to,start_block,end_block,logic_levels,carry_cells,logic_ns,routing_ns,\
lut4,lut4_available,ff,ff_available,dp16kd,mult18x18d,pnr_seconds,synth_seconds,yosys,nextpnr";

/// `timing.csv`.
pub fn csv(designs: &[DesignTiming]) -> String {
    let mut lines: Vec<Vec<String>> = Vec::new();
    for d in designs {
        let r = &d.report;
        for run in &r.runs {
            let u = &run.report;
            let avail = |t: &str| {
                u.utilization
                    .iter()
                    .find(|x| x.resource == t)
                    .map_or(0, |x| x.available)
            };
            for c in &u.clocks {
                let p = u.critical_path(&c.clock);
                let fields = [
                    d.name.clone(),
                    d.kind.clone(),
                    r.top.clone(),
                    run.seed.to_string(),
                    c.clock.clone(),
                    c.constraint_mhz.to_string(),
                    c.achieved_mhz.to_string(),
                    c.met().to_string(),
                    p.map_or(String::new(), |p| p.from_clock.clone()),
                    p.map_or(String::new(), |p| p.to_clock.clone()),
                    p.map_or(String::new(), |p| p.start.block.clone()),
                    p.map_or(String::new(), |p| p.end.block.clone()),
                    p.map_or(String::new(), |p| p.logic_levels.to_string()),
                    p.map_or(String::new(), |p| p.carry_cells.to_string()),
                    p.map_or(String::new(), |p| format!("{:.3}", p.logic_ns)),
                    p.map_or(String::new(), |p| format!("{:.3}", p.routing_ns)),
                    u.used("TRELLIS_COMB").to_string(),
                    avail("TRELLIS_COMB").to_string(),
                    u.used("TRELLIS_FF").to_string(),
                    avail("TRELLIS_FF").to_string(),
                    u.used("DP16KD").to_string(),
                    u.used("MULT18X18D").to_string(),
                    format!("{:.1}", run.seconds),
                    format!("{:.1}", r.synth_seconds),
                    r.tools.yosys_version.clone(),
                    r.tools.nextpnr_version.clone(),
                ];
                lines.push(fields.to_vec());
            }
        }
    }
    let header: Vec<&str> = CSV_HEADER.split(',').collect();
    crate::tables::csv_text(&header, &lines)
}

/// `timing.md`; `command` is the command line that made it.
pub fn markdown(designs: &[DesignTiming], command: &str) -> String {
    let mut s = String::new();
    let tools = designs.first().map(|d| &d.report.tools);
    let _ = writeln!(s, "# Placed and routed timing ({DEVICE}, out of context)\n");
    if let Some(t) = tools {
        let _ = writeln!(
            s,
            "yosys {} `synth_ecp5`, nextpnr-ecp5 {} (YoWASP builds from PyPI). Command: `{command}`.\n",
            t.yosys_version, t.nextpnr_version
        );
    }
    if let Some(d) = designs.first() {
        let _ = writeln!(
            s,
            "nextpnr: `{}`; yosys: `{}`. The summary gives the main clock of the slowest seed; LUT4 \
             counts nextpnr's TRELLIS_COMB cells (LUTs and carry halves) against the device's.\n",
            d.report.nextpnr_command, d.report.yosys_command
        );
    }
    let _ = writeln!(
        s,
        "| design | clock | achieved MHz | min / median / max over seeds | target MHz | met | critical path (start -> end) | logic levels (carry) | logic ns | routing ns | LUT4 | FF | DP16KD | MULT18X18D | seeds | yosys s | P&R s |"
    );
    let _ = writeln!(
        s,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for d in designs {
        let r = &d.report;
        let Some(clock) = r.main_clock() else {
            let _ = writeln!(
                s,
                "| {} | (no clock reported) | | | | | | | | | | | | | | | |",
                d.name
            );
            continue;
        };
        let Some((run, c, p)) = r.worst_run(clock) else {
            let _ = writeln!(
                s,
                "| {} | {clock} (no critical path reported) | | | | | | | | | | | | | | | |",
                d.name
            );
            continue;
        };
        let spread = r
            .fmax_spread(clock)
            .map(|sp| format!("{:.1} / {:.1} / {:.1}", sp.min, sp.median, sp.max))
            .unwrap_or_default();
        let u = &run.report;
        let pct = |t: &str| {
            u.utilization
                .iter()
                .find(|x| x.resource == t)
                .map_or(String::from("0"), |x| {
                    format!("{} ({:.1}%)", x.used, x.percent())
                })
        };
        let seeds: Vec<String> = r.runs.iter().map(|x| x.seed.to_string()).collect();
        let _ = writeln!(
            s,
            "| {} | {clock} | {:.1} | {spread} | {} | {} | `{}` -> `{}` | {} ({}) | {:.2} | {:.2} | {} | {} | {} | {} | {} | {:.0} | {:.0} |",
            d.name,
            c.achieved_mhz,
            c.constraint_mhz,
            if c.met() { "yes" } else { "**no**" },
            p.start.block,
            p.end.block,
            p.logic_levels,
            p.carry_cells,
            p.logic_ns,
            p.routing_ns,
            pct("TRELLIS_COMB"),
            pct("TRELLIS_FF"),
            pct("DP16KD"),
            pct("MULT18X18D"),
            seeds.join(","),
            r.synth_seconds,
            r.pnr_seconds(),
        );
    }
    let _ = writeln!(s, "\n## Every seed and clock\n");
    let _ = writeln!(
        s,
        "| design | seed | clock | achieved MHz | target MHz | critical path (start -> end) | levels (carry) | logic ns | routing ns | P&R s |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for d in designs {
        for run in &d.report.runs {
            for c in &run.report.clocks {
                let path = run.report.critical_path(&c.clock);
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {:.2} | {} | {} | {} | {} | {} | {:.0} |",
                    d.name,
                    run.seed,
                    c.clock,
                    c.achieved_mhz,
                    c.constraint_mhz,
                    path.map_or(String::new(), |p| format!(
                        "`{}` -> `{}` ({} -> {})",
                        p.start.block, p.end.block, p.from_clock, p.to_clock
                    )),
                    path.map_or(String::new(), |p| format!(
                        "{} ({})",
                        p.logic_levels, p.carry_cells
                    )),
                    path.map_or(String::new(), |p| format!("{:.2}", p.logic_ns)),
                    path.map_or(String::new(), |p| format!("{:.2}", p.routing_ns)),
                    run.seconds
                );
            }
        }
    }
    s
}

/// The worst achieved main clock (`clock`) over the seeds of the one processor in a
/// `timing.csv`.
pub fn processor_clock_from_csv(text: &str) -> Result<f64, String> {
    let mut r = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut records = r.records();
    let header: Vec<String> = records
        .next()
        .ok_or("empty file: not a timing.csv of `dynrt timing`")?
        .map_err(|e| format!("not a CSV file: {e}"))?
        .iter()
        .map(String::from)
        .collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| format!("no `{name}` column: not a timing.csv of `dynrt timing`"))
    };
    let (design, kind, clock, achieved) = (
        col("design")?,
        col("kind")?,
        col("clock")?,
        col("achieved_mhz")?,
    );
    let mut designs: Vec<String> = Vec::new();
    let mut worst: Option<f64> = None;
    for fields in records {
        let fields = fields.map_err(|e| format!("not a CSV file: {e}"))?;
        let line = fields.position().map_or(0, |p| p.line());
        let get = |i: usize| fields.get(i).unwrap_or("");
        if get(kind) != PROCESSOR_KIND || get(clock) != "clock" {
            continue;
        }
        let mhz: f64 = get(achieved)
            .parse()
            .map_err(|_| format!("line {line}: `{}` is not a frequency", get(achieved)))?;
        if !designs.iter().any(|d| d == get(design)) {
            designs.push(get(design).to_string());
        }
        worst = Some(worst.map_or(mhz, |w: f64| w.min(mhz)));
    }
    match (designs.len(), worst) {
        (1, Some(mhz)) => Ok(mhz),
        (0, _) => Err(
            "no processor row: a unit's timing says nothing of the processor's clock; \
                       run `dynrt timing SCENE` and give its timing.csv or seed<S>/report.json"
                .into(),
        ),
        _ => Err(format!(
            "it holds {} processors ({}); give the report of the one simulated (its \
             seed<S>/report.json, or a timing.csv of that scene alone)",
            designs.len(),
            designs.join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csv_with(rows: &[(&str, &str, &str, &str)]) -> String {
        let header: Vec<&str> = CSV_HEADER.split(',').collect();
        let lines: Vec<Vec<String>> = rows
            .iter()
            .map(|(design, kind, clock, mhz)| {
                let mut f = vec![String::new(); header.len()];
                f[0] = design.to_string();
                f[1] = kind.to_string();
                f[4] = clock.to_string();
                f[6] = mhz.to_string();
                f
            })
            .collect();
        crate::tables::csv_text(&header, &lines)
    }

    #[test]
    fn processor_clock_is_the_worst_seed_of_the_one_processor() {
        let text = csv_with(&[
            ("fp add e7m16", "fp operator", "clock", "150"),
            ("cornell, 32 threads", "processor", "clock", "61.5"),
            ("cornell, 32 threads", "processor", "vga_clock", "20"),
            ("cornell, 32 threads", "processor", "clock", "58.25"),
        ]);
        assert_eq!(processor_clock_from_csv(&text).unwrap(), 58.25);
    }

    #[test]
    fn ambiguous_or_unit_only_csvs_are_refused() {
        let two = csv_with(&[
            ("cornell", "processor", "clock", "60"),
            ("dynamic", "processor", "clock", "55"),
        ]);
        assert!(processor_clock_from_csv(&two)
            .unwrap_err()
            .contains("2 processors"));
        let units = csv_with(&[("fp add e7m16", "fp operator", "clock", "150")]);
        assert!(processor_clock_from_csv(&units)
            .unwrap_err()
            .contains("no processor row"));
        assert!(processor_clock_from_csv("a,b\n")
            .unwrap_err()
            .contains("not a timing.csv"));
        let bad = csv_with(&[("cornell", "processor", "clock", "fast")]);
        assert!(processor_clock_from_csv(&bad)
            .unwrap_err()
            .contains("line 2: `fast` is not a frequency"));
    }
}
