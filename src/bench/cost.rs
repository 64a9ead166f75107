//! Hardware cost of a number format: each floating-point operator synthesized alone with Yosys
//! (`synth_xilinx -family xc2v`, out of context: no I/O pads), and the datapath of the
//! transformation and intersection units estimated from their operator counts.
//!
//! Contract: [`measure_or_load`] returns one [`OpCost`] per (format, operator) for `add`, `mul`,
//! `div` and `lt` (the comparison unit, which computes lt, le and eq together). Yosys takes
//! seconds to minutes per operator, so results are cached in a CSV
//! (`format,op,luts,flip_flops,mult18x18,yosys_seconds`); a cached row is reused, a missing one
//! is synthesized and appended. A format without hardware operators
//! (see [`crate::hw::fp::supported_formats`]) simply has no cost.
//!
//! The datapath estimate ([`DatapathCost`]) adds up operator costs in the paper's counts
//! (Table 2): the transformation unit is 9 multipliers and 9 adders; the intersection unit is
//! 1 divider, 2 multipliers, 3 adders and 5 comparators (u >= 0, v >= 0, u + v <= 1,
//! t > t_min, t < t_max). Glue logic, pipeline balancing registers and control are not
//! counted: it is an estimate of the arithmetic, not of the finished units (those are being
//! written on another branch; replace the estimate with their synthesis when they land).

use crate::emit::fp_unit_rtl;
use crate::fp::{BinOp, Format};
use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// The operators whose cost is measured (the comparison unit stands for lt, le and eq).
pub const COST_OPS: [BinOp; 4] = [BinOp::Add, BinOp::Mul, BinOp::Div, BinOp::Lt];

/// One operator's synthesis result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpCost {
    pub format: Format,
    pub op: BinOp,
    pub luts: u64,
    pub flip_flops: u64,
    pub mult18x18: u64,
    pub yosys_seconds: f64,
}

/// Operator counts of a unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OpCounts {
    pub add: u64,
    pub mul: u64,
    pub div: u64,
    pub cmp: u64,
}

/// The transformation unit (paper, Table 2): a 3x4 matrix times a point.
pub const TRANSFORM_OPS: OpCounts = OpCounts {
    add: 9,
    mul: 9,
    div: 0,
    cmp: 0,
};
/// The intersection unit (paper, Table 2) plus its 5 comparators.
pub const INTERSECT_OPS: OpCounts = OpCounts {
    add: 3,
    mul: 2,
    div: 1,
    cmp: 5,
};

/// Estimated cost of the transformation plus intersection datapath in one format.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DatapathCost {
    pub format: Format,
    pub luts: u64,
    pub flip_flops: u64,
    pub mult18x18: u64,
}

impl DatapathCost {
    /// Sums `counts` of each operator's cost; `None` when an operator's cost is missing.
    pub fn estimate(format: Format, costs: &[OpCost], units: &[OpCounts]) -> Option<DatapathCost> {
        let get = |op: BinOp| costs.iter().find(|c| c.format == format && c.op == op);
        let (add, mul, div, cmp) = (
            get(BinOp::Add)?,
            get(BinOp::Mul)?,
            get(BinOp::Div)?,
            get(BinOp::Lt)?,
        );
        let mut d = DatapathCost {
            format,
            luts: 0,
            flip_flops: 0,
            mult18x18: 0,
        };
        for u in units {
            for (n, c) in [(u.add, add), (u.mul, mul), (u.div, div), (u.cmp, cmp)] {
                d.luts += n * c.luts;
                d.flip_flops += n * c.flip_flops;
                d.mult18x18 += n * c.mult18x18;
            }
        }
        Some(d)
    }
}

const HEADER: &str = "format,op,luts,flip_flops,mult18x18,yosys_seconds";

/// One line of a cost CSV; the seconds as text so that a rewritten cache keeps its `5.10`.
#[derive(serde::Serialize, serde::Deserialize)]
struct CostRow {
    format: String,
    op: String,
    luts: u64,
    flip_flops: u64,
    mult18x18: u64,
    yosys_seconds: String,
}

/// Reads a cost CSV, naming the file, the line and the column of any error.
pub fn read_costs(path: &Path) -> Result<Vec<OpCost>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut r = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    match r.headers() {
        Ok(h) if h.iter().eq(HEADER.split(',')) => {}
        _ => bail!("{}: line 1: expected the header `{HEADER}`", path.display()),
    }
    let mut out = Vec::new();
    for row in r.deserialize::<CostRow>() {
        let row = row.map_err(|e| csv_error(path, &e))?;
        let line = out.len() + 2;
        let bad = |what: String| anyhow::anyhow!("{}: line {line}: {what}", path.display());
        out.push(OpCost {
            format: Format::parse(&row.format).map_err(|e| bad(e.to_string()))?,
            op: BinOp::parse(&row.op)
                .ok_or_else(|| bad(format!("unknown operator `{}`", row.op)))?,
            luts: row.luts,
            flip_flops: row.flip_flops,
            mult18x18: row.mult18x18,
            yosys_seconds: row.yosys_seconds.parse().map_err(|_| {
                bad(format!(
                    "yosys_seconds `{}` is not a number",
                    row.yosys_seconds
                ))
            })?,
        });
    }
    Ok(out)
}

/// A CSV reading error as `FILE: line N: column `NAME`: what`.
fn csv_error(path: &Path, e: &csv::Error) -> anyhow::Error {
    let line = e.position().map_or(0, |p| p.line());
    match e.kind() {
        csv::ErrorKind::Deserialize { err, .. } => {
            let column = err
                .field()
                .and_then(|f| HEADER.split(',').nth(f as usize))
                .unwrap_or("?");
            anyhow::anyhow!(
                "{}: line {line}: column `{column}`: {}",
                path.display(),
                err.kind()
            )
        }
        _ => anyhow::anyhow!("{}: line {line}: {e}", path.display()),
    }
}

/// Writes a cost CSV (sorted by format and operator), atomically.
pub fn write_costs(path: &Path, costs: &[OpCost]) -> Result<()> {
    let mut sorted: BTreeMap<(u32, u32, &str), &OpCost> = BTreeMap::new();
    for c in costs {
        sorted.insert((c.format.exp_bits, c.format.man_bits, c.op.name()), c);
    }
    let rows: Vec<CostRow> = sorted
        .values()
        .map(|c| CostRow {
            format: c.format.to_string(),
            op: c.op.name().to_string(),
            luts: c.luts,
            flip_flops: c.flip_flops,
            mult18x18: c.mult18x18,
            yosys_seconds: format!("{:.2}", c.yosys_seconds),
        })
        .collect();
    let text = if rows.is_empty() {
        format!("{HEADER}\n")
    } else {
        crate::tables::csv_of(&rows)?
    };
    crate::output::write_atomically(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Synthesizes one operator in `work_dir`.
pub fn synthesize_op(op: BinOp, format: Format, work_dir: &Path) -> Result<OpCost> {
    let rtl = fp_unit_rtl(op, format)?;
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("creating {}", work_dir.display()))?;
    let file = work_dir.join(format!("{}.v", rtl.top));
    std::fs::write(&file, &rtl.verilog).with_context(|| format!("writing {}", file.display()))?;
    let options = crate::synth::SynthOptions {
        io_pads: false,
        ..Default::default()
    };
    let r = crate::synth::synth_xc2v_with(&[file], &rtl.top, work_dir, &options)
        .with_context(|| format!("synthesizing {}", rtl.top))?;
    Ok(OpCost {
        format,
        op,
        luts: r.total_luts(),
        flip_flops: r.flip_flops,
        mult18x18: r.mult18x18,
        yosys_seconds: r.seconds,
    })
}

/// The cost of every operator of [`COST_OPS`] in every format that has hardware, reusing the
/// rows of `cache_csv` and synthesizing (then caching) the missing ones when `synthesize`;
/// `log` gets one line per synthesis.
pub fn measure_or_load(
    formats: &[Format],
    cache_csv: &Path,
    work_dir: &Path,
    synthesize: bool,
    log: &mut dyn FnMut(&str),
) -> Result<Vec<OpCost>> {
    let mut costs = if cache_csv.exists() {
        read_costs(cache_csv)?
    } else {
        Vec::new()
    };
    for &f in formats {
        if crate::hw::fp::check_supported(f).is_err() {
            continue;
        }
        for op in COST_OPS {
            if costs.iter().any(|c| c.format == f && c.op == op) || !synthesize {
                continue;
            }
            let c = synthesize_op(op, f, &work_dir.join(format!("{}_{f}", op.name())))?;
            log(&format!(
                "synthesized {} {f}: {} LUTs, {} FFs, {} MULT18X18 ({:.1} s)",
                op.name(),
                c.luts,
                c.flip_flops,
                c.mult18x18,
                c.yosys_seconds
            ));
            costs.push(c);
            write_costs(cache_csv, &costs)?;
        }
    }
    Ok(costs
        .into_iter()
        .filter(|c| formats.contains(&c.format))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cost(f: Format, op: BinOp, luts: u64) -> OpCost {
        OpCost {
            format: f,
            op,
            luts,
            flip_flops: luts / 2,
            mult18x18: u64::from(op == BinOp::Mul),
            yosys_seconds: 1.5,
        }
    }

    #[test]
    fn datapath_estimate_weights_each_operator_by_its_count() {
        let f = Format::E7M16;
        let costs = [
            cost(f, BinOp::Add, 100),
            cost(f, BinOp::Mul, 10),
            cost(f, BinOp::Div, 1000),
            cost(f, BinOp::Lt, 1),
        ];
        let d = DatapathCost::estimate(f, &costs, &[TRANSFORM_OPS, INTERSECT_OPS]).unwrap();
        // 12 adders, 11 multipliers, 1 divider, 5 comparators: the paper's 16/11/5 minus
        // traversal's 4 add and 4 div.
        assert_eq!(d.luts, 12 * 100 + 11 * 10 + 1000 + 5);
        assert_eq!(d.mult18x18, 11);
        assert_eq!(d.flip_flops, 12 * 50 + 11 * 5 + 500);
        assert!(DatapathCost::estimate(Format::E8M23, &costs, &[TRANSFORM_OPS]).is_none());
    }

    #[test]
    fn cost_csv_round_trips_and_bad_lines_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.csv");
        let costs = vec![
            cost(Format::E8M23, BinOp::Div, 7),
            cost(Format::E5M10, BinOp::Add, 3),
        ];
        write_costs(&p, &costs).unwrap();
        let back = read_costs(&p).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].format, Format::E5M10, "sorted by format");
        assert_eq!(back[1], costs[0]);
        std::fs::write(&p, format!("{HEADER}\ne7m16,add,x,1,0,1.0\n")).unwrap();
        let err = read_costs(&p).unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("luts"), "{err}");
        std::fs::write(
            &p,
            format!("{HEADER}\ne7m16,add,1,1,0,1.0\ne7m16,pow,1,1,0,1.0\n"),
        )
        .unwrap();
        let err = read_costs(&p).unwrap_err().to_string();
        assert!(err.contains("line 3") && err.contains("pow"), "{err}");
        // The checked-in cache reads and writes back byte for byte.
        let cache = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/data/fp_cost_xc2v.csv");
        let costs = read_costs(&cache).unwrap();
        write_costs(&p, &costs).unwrap();
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            std::fs::read_to_string(&cache).unwrap()
        );
    }
}
