//! Runs one generated floating-point operator in a real simulator on a list of operand pairs:
//! writes the unit's Verilog (`crate::emit::fp_unit`), a wrapper and the streaming testbench
//! of `crate::emit::stream_bench` (the one the geometry units use) with the vector file into a
//! work directory, runs Icarus or Verilator through [`super::stream_bench`], and reads the
//! results back in input order.
//! Used by `dynrt fp --sim iverilog|verilator` and by the bit-exactness tests.

use std::path::Path;

use anyhow::{bail, Result};

use super::stream_bench::run_stream_bench;
use super::Simulator;
use crate::emit::fp_unit::fp_unit_rtl;
use crate::emit::stream_bench::{BenchPort, InputStream, OutputSink, StreamBench};
use crate::fp::{BinOp, Format};

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
/// `work_dir` (created if needed) for the Verilog, the testbench, `vectors.hex` and the
/// results. Fails if the format has no hardware, a tool fails, or a result is missing.
pub fn run_fp_unit(
    op: BinOp,
    fmt: Format,
    vectors: &[(u32, u32)],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<FpUnitRun> {
    let mut runs = run_fp_units(&[op], fmt, vectors, simulator, work_dir)?;
    Ok(runs.remove(0))
}

/// [`run_fp_unit`] for several operators of one format in one simulator build, all fed the
/// same vectors; one [`FpUnitRun`] per operator, in the order of `ops` (the times are those of
/// the shared build and run).
pub fn run_fp_units(
    ops: &[BinOp],
    fmt: Format,
    vectors: &[(u32, u32)],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<Vec<FpUnitRun>> {
    let units = ops
        .iter()
        .map(|&op| fp_unit_rtl(op, fmt))
        .collect::<Result<Vec<_>>>()?;
    if vectors.is_empty() {
        let empty = FpUnitRun {
            results: Vec::new(),
            compile_seconds: 0.0,
            run_seconds: 0.0,
        };
        return Ok(vec![empty; ops.len()]);
    }
    let w = fmt.width();
    let mask = fmt.word_mask();
    for (i, &(a, b)) in vectors.iter().enumerate() {
        if a & !mask != 0 || b & !mask != 0 {
            bail!("vector {}: {a:#x} {b:#x} is wider than {fmt}", i + 1);
        }
    }
    // One wrapper instantiates every operator on the shared operands; the generic streaming
    // bench (the geometry units' too) feeds it and records each operator's results.
    let wrapper = format!("fp_units_{fmt}");
    let mut ports = vec![
        BenchPort::input("clock", 1),
        BenchPort::input("in_valid", 1),
        BenchPort::input("a", w),
        BenchPort::input("b", w),
    ];
    let mut body = String::new();
    let mut sinks = Vec::new();
    let mut verilog = String::new();
    for (i, unit) in units.iter().enumerate() {
        verilog += &unit.verilog;
        verilog.push('\n');
        ports.push(BenchPort::output(format!("out_valid_{i}"), 1));
        ports.push(BenchPort::output(format!("result_{i}"), unit.result_width));
        let b_pin = if unit.unary { "" } else { " .b(b)," };
        body += &format!(
            "    {} dut_{i}(.clock(clock), .in_valid(in_valid), .a(a),{b_pin}\n        \
             .out_valid(out_valid_{i}), .result(result_{i}));\n",
            unit.top
        );
        sinks.push(OutputSink {
            name: format!("results_{}", unit.top),
            valid: format!("out_valid_{i}"),
            fields: vec![format!("result_{i}")],
            expected: vectors.len(),
        });
    }
    let decls = ports
        .iter()
        .map(|p| {
            let dir = if p.output { "output" } else { "input" };
            let range = if p.width > 1 {
                format!("[{}:0] ", p.width - 1)
            } else {
                String::new()
            };
            format!("    {dir} wire {range}{}", p.name)
        })
        .collect::<Vec<_>>()
        .join(",\n");
    verilog += &format!("module {wrapper}(\n{decls}\n);\n{body}endmodule\n");
    let bench = StreamBench {
        dut: wrapper,
        ports,
        streams: vec![InputStream {
            name: "vectors".into(),
            fields: vec!["a".into(), "b".into()],
            valid: Some("in_valid".into()),
            ready: None,
            lines: vectors
                .iter()
                .map(|&(a, b)| (0, vec![u64::from(a), u64::from(b)]))
                .collect(),
        }],
        sinks,
        max_cycles: vectors.len() as u64 + 1000,
    };
    let ran = run_stream_bench(&bench, &verilog, simulator, work_dir)?;
    Ok(ran
        .sinks
        .into_iter()
        .map(|records| FpUnitRun {
            results: records.into_iter().map(|r| r[0] as u32).collect(),
            compile_seconds: ran.compile_seconds,
            run_seconds: ran.run_seconds,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::vectors;
    use crate::hw::fp::supported_formats;

    const ALL_OPS: [BinOp; 8] = BinOp::ALL;

    /// `n` seeded random pairs, every pair of edge operands, and `n / 2` seeded square-root
    /// operands (exact squares and their neighbours, roots next to rounding midpoints, ...) as
    /// first operands of random second ones, so sqrt gets vectors of its own besides the pairs'
    /// first operands.
    fn test_vectors(fmt: Format, n: usize, seed: u64) -> Vec<(u32, u32)> {
        println!("{fmt}: seed {seed}");
        let mut v = vectors::random_pairs(fmt, seed, n);
        let edges = vectors::edge_cases(fmt);
        for &a in &edges {
            for &b in &edges {
                v.push((a, b));
            }
        }
        let others = vectors::random_pairs(fmt, seed + 1, n / 2);
        let roots = vectors::sqrt_operands(fmt, seed + 2, n / 2);
        v.extend(roots.into_iter().zip(others).map(|(a, (b, _))| (a, b)));
        v
    }

    /// All eight operators of `fmt` in one build of `simulator`, against the model bit for bit.
    fn check_all_ops(fmt: Format, n: usize, seed: u64, simulator: Simulator) {
        let v = test_vectors(fmt, n, seed);
        let dir = tempfile::tempdir().unwrap();
        let runs = run_fp_units(&ALL_OPS, fmt, &v, simulator, dir.path()).unwrap();
        println!(
            "{simulator} {fmt}: 8 operators x {} vectors: compile {:.1} s, run {:.1} s",
            v.len(),
            runs[0].compile_seconds,
            runs[0].run_seconds
        );
        let mut failures = Vec::new();
        for (op, run) in ALL_OPS.iter().zip(&runs) {
            let mut bad = 0;
            for (i, (&(a, b), &r)) in v.iter().zip(&run.results).enumerate() {
                let want = op.eval(fmt, a, b);
                if r != want {
                    if bad < 5 {
                        eprintln!(
                            "{simulator} {} {fmt} vector {i}: a={a:#x} b={b:#x} got {r:#x} want {want:#x}",
                            op.name()
                        );
                    }
                    bad += 1;
                }
            }
            if bad > 0 {
                failures.push(format!("{}: {bad} of {}", op.name(), v.len()));
            }
        }
        assert!(
            failures.is_empty(),
            "{simulator} {fmt}: differ from the model: {failures:?}"
        );
    }

    #[test]
    fn single_unit_run_matches_model_in_icarus() {
        let fmt = Format::E7M16;
        let v = test_vectors(fmt, 1000, 5);
        let dir = tempfile::tempdir().unwrap();
        let run = run_fp_unit(BinOp::Div, fmt, &v, Simulator::Icarus, dir.path()).unwrap();
        for (&(a, b), &r) in v.iter().zip(&run.results) {
            assert_eq!(r, fmt.div(a, b), "div {a:#x} {b:#x}");
        }
    }

    /// Sqrt on every word of each format of at most 20 bits, and on every positive word (the
    /// negative ones all give NaN, as the others show) of the formats up to 24 bits, e7m16
    /// included, in Verilator.
    #[test]
    fn sqrt_exhaustive_up_to_24_bits_verilator() {
        for fmt in supported_formats() {
            let words = match fmt.width() {
                0..=20 => 0..=fmt.word_mask(),
                21..=24 => 0..=(fmt.word_mask() >> 1),
                _ => continue,
            };
            let v: Vec<(u32, u32)> = words.map(|a| (a, 0)).collect();
            let dir = tempfile::tempdir().unwrap();
            let run = run_fp_unit(BinOp::Sqrt, fmt, &v, Simulator::Verilator, dir.path()).unwrap();
            println!(
                "sqrt {fmt}: {} words: compile {:.1} s, run {:.1} s",
                v.len(),
                run.compile_seconds,
                run.run_seconds
            );
            assert_eq!(run.results.len(), v.len());
            let bad: Vec<_> = v
                .iter()
                .zip(&run.results)
                .filter(|&(&(a, _), &r)| r != fmt.sqrt(a))
                .take(5)
                .map(|(&(a, _), &r)| (a, r, fmt.sqrt(a)))
                .collect();
            assert!(bad.is_empty(), "sqrt {fmt} (a, RTL, model): {bad:x?}");
        }
    }

    /// Icarus and Verilator simulate the same Verilog; Verilator carries the 100k-vector
    /// checks, Icarus a tenth of them (plus every edge case) to show that the result does not
    /// depend on the simulator (at 25k its three tests took 190 s of CI's time, stop 42).
    const ICARUS_VECTORS: usize = 10_000;

    #[test]
    fn bit_exact_e7m16_icarus() {
        check_all_ops(Format::E7M16, ICARUS_VECTORS, 16, Simulator::Icarus);
    }

    #[test]
    fn bit_exact_e7m16_verilator() {
        check_all_ops(Format::E7M16, 100_000, 16, Simulator::Verilator);
    }

    #[test]
    fn bit_exact_e8m23_icarus() {
        check_all_ops(Format::E8M23, ICARUS_VECTORS, 23, Simulator::Icarus);
    }

    #[test]
    fn bit_exact_e8m23_verilator() {
        check_all_ops(Format::E8M23, 100_000, 23, Simulator::Verilator);
    }

    /// Every other supported format, 5k random vectors plus the edge cases in Verilator, the
    /// first 1k of them plus the edge cases in Icarus.
    #[test]
    fn bit_exact_other_formats_icarus() {
        for fmt in supported_formats() {
            if fmt != Format::E7M16 && fmt != Format::E8M23 {
                check_all_ops(fmt, 1000, 1000 + fmt.width() as u64, Simulator::Icarus);
            }
        }
    }

    #[test]
    fn bit_exact_other_formats_verilator() {
        for fmt in supported_formats() {
            if fmt != Format::E7M16 && fmt != Format::E8M23 {
                check_all_ops(fmt, 5000, 1000 + fmt.width() as u64, Simulator::Verilator);
            }
        }
    }
}
