//! Runs one generated floating-point operator in a real simulator on a list of operand pairs:
//! writes the unit's Verilog, its testbench and the vector file into a work directory, runs
//! Icarus or Verilator through `crate::sim`, and reads the results back in input order.
//! Used by `dynrt fp --sim iverilog|verilator` and by the bit-exactness tests.

use std::path::Path;

use anyhow::{bail, Context, Result};

use super::fp_unit::{fp_unit_rtl, fp_unit_testbench};
use crate::fp::{BinOp, Format};
use crate::sim::{self, SimJob, Simulator};

/// Results of one simulated run of an operator.
#[derive(Debug, Clone)]
pub struct FpUnitRun {
    /// One result per input vector, in input order (0/1 for comparisons).
    pub results: Vec<u32>,
    /// Wall time of compilation, seconds.
    pub compile_seconds: f64,
    /// Wall time of the simulation, seconds.
    pub run_seconds: f64,
}

/// Simulates the operator computing `op` in `fmt` on `vectors` with `simulator`, using
/// `work_dir` (created if needed) for the files `<top>.v`, `tb_<top>.v`, `vectors.hex` and
/// `results.hex`. Fails if the format has no hardware, a tool fails, or a result is missing.
pub fn run_fp_unit(
    op: BinOp,
    fmt: Format,
    vectors: &[(u32, u32)],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<FpUnitRun> {
    if vectors.is_empty() {
        return Ok(FpUnitRun {
            results: Vec::new(),
            compile_seconds: 0.0,
            run_seconds: 0.0,
        });
    }
    let unit = fp_unit_rtl(op, fmt)?;
    std::fs::create_dir_all(work_dir)
        .with_context(|| format!("cannot create {}", work_dir.display()))?;
    let digits = fmt.hex_digits();
    let mask = fmt.word_mask();
    let mut text = String::with_capacity(vectors.len() * (2 * digits + 2));
    for (i, &(a, b)) in vectors.iter().enumerate() {
        if a & !mask != 0 || b & !mask != 0 {
            bail!("vector {}: {a:#x} {b:#x} is wider than {fmt}", i + 1);
        }
        text += &format!("{a:0digits$x} {b:0digits$x}\n");
    }
    let vectors_file = work_dir.join("vectors.hex");
    let results_file = work_dir.join("results.hex");
    let _ = std::fs::remove_file(&results_file);
    std::fs::write(&vectors_file, text)
        .with_context(|| format!("cannot write {}", vectors_file.display()))?;
    let rtl_file = work_dir.join(format!("{}.v", unit.top));
    std::fs::write(&rtl_file, &unit.verilog)
        .with_context(|| format!("cannot write {}", rtl_file.display()))?;
    let tb_file = work_dir.join(format!("tb_{}.v", unit.top));
    let tb = fp_unit_testbench(&unit, fmt, vectors.len(), "vectors.hex", "results.hex");
    std::fs::write(&tb_file, tb).with_context(|| format!("cannot write {}", tb_file.display()))?;
    let job = SimJob::new(work_dir, vec![rtl_file, tb_file], "tb");
    let ran = sim::run(simulator, &job)?;
    let out = std::fs::read_to_string(&results_file).with_context(|| {
        format!(
            "{simulator} wrote no results for {}; its output:\n{}{}",
            unit.top, ran.stdout, ran.stderr
        )
    })?;
    let results = out
        .lines()
        .enumerate()
        .map(|(i, l)| {
            u32::from_str_radix(l.trim(), 16).with_context(|| {
                format!("{}:{}: `{l}` is not a hex word", results_file.display(), i + 1)
            })
        })
        .collect::<Result<Vec<u32>>>()?;
    if results.len() != vectors.len() {
        bail!(
            "{simulator} produced {} results for {} vectors of {}; its output:\n{}{}",
            results.len(),
            vectors.len(),
            unit.top,
            ran.stdout,
            ran.stderr
        );
    }
    Ok(FpUnitRun {
        results,
        compile_seconds: ran.compile_seconds,
        run_seconds: ran.run_seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::vectors;

    /// Generated Verilog against the model, bit for bit.
    pub(crate) fn check(op: BinOp, fmt: Format, n: usize, seed: u64, simulator: Simulator) {
        println!("seed {seed}");
        let mut v = vectors::random_pairs(fmt, seed, n);
        let edges = vectors::edge_cases(fmt);
        for &a in &edges {
            for &b in &edges {
                v.push((a, b));
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let run = run_fp_unit(op, fmt, &v, simulator, dir.path()).unwrap();
        println!(
            "{simulator} {} {fmt}: {} vectors, compile {:.1} s, run {:.1} s",
            op.name(),
            v.len(),
            run.compile_seconds,
            run.run_seconds
        );
        let mut bad = 0;
        for (i, (&(a, b), &r)) in v.iter().zip(&run.results).enumerate() {
            let want = op.eval(fmt, a, b);
            if r != want {
                if bad < 10 {
                    eprintln!("{simulator} {} {fmt} vector {i}: a={a:#x} b={b:#x} got {r:#x} want {want:#x}", op.name());
                }
                bad += 1;
            }
        }
        assert_eq!(bad, 0, "{simulator} {} {fmt}: {bad} of {} differ", op.name(), v.len());
    }

    #[test]
    fn smoke_mul_e7m16_icarus() {
        check(BinOp::Mul, Format::E7M16, 2000, 1, Simulator::Icarus);
    }
    #[test]
    fn smoke_mul_e7m16_verilator() {
        check(BinOp::Mul, Format::E7M16, 2000, 1, Simulator::Verilator);
    }
}
