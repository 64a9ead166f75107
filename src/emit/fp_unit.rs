//! Verilog for one floating-point operator (`dynrt fp --sim ...`, unit tests, synthesis
//! reports), and a testbench that streams vectors from a file through it.
//!
//! [`fp_unit_rtl`] produces one self-contained Verilog file: rust-hdl's flat output for the
//! operator, renamed to `<top>_core` with readable names (`$` in rust-hdl's hierarchical names
//! becomes `__`) and identical per-instance modules merged (see `verilog_tidy`), and a clean
//! top module `<top>` (e.g. `fp_add_e7m16`) with the ports
//! `clock, in_valid, a[W-1:0], b[W-1:0], out_valid, result` (`result` is 1 bit for `lt`, `le`,
//! `eq`, else a word; the unary `sqrt` has no `b`). `out_valid` follows `in_valid` after
//! [`FpUnitRtl::latency`] clocks.
//!
//! The file passes `verilator --lint-only -Wall` with one documented waiver block (rust-hdl's
//! code style: 32-bit literals, mask-style casts, one module per instance).
//!
//! [`fp_unit_testbench`] writes module `tb` for Icarus (`iverilog -g2012`) and Verilator 5
//! (`verilator --binary --timing`): it reads `n_vectors` lines `a b` (hex words) with
//! `$fscanf`, feeds one per clock, and writes each result as one hex line, in input order (a
//! unary unit gets only `a`; `b` is read and ignored, so every operator takes the same files).

use anyhow::Result;
use rust_hdl::prelude::*;

use super::verilog_tidy::{merge_identical_modules, rename_rust_hdl_names};
use crate::dispatch_fp_format;
use crate::fp::{BinOp, Format};
use crate::hw::fp::{latency, FpAddSub, FpCompare, FpDiv, FpMul, FpSqrt};

/// One operator's Verilog.
#[derive(Debug, Clone)]
pub struct FpUnitRtl {
    /// Name of the top module, `fp_<op>_<format>`, e.g. `fp_add_e7m16`.
    pub top: String,
    /// The whole Verilog file (top module and everything below it).
    pub verilog: String,
    /// Clocks from `in_valid` to `out_valid`.
    pub latency: u32,
    /// Width of `result`: 1 for comparisons, else the word width.
    pub result_width: u32,
    /// True when the top module has no `b` port (`sqrt`).
    pub unary: bool,
}

/// The Verilog of the operator computing `op` in `fmt`.
/// Fails with the list of supported formats for a format without hardware.
pub fn fp_unit_rtl(op: BinOp, fmt: Format) -> Result<FpUnitRtl> {
    let top = format!("fp_{}_{}", op.name(), fmt);
    let core_name = format!("{top}_core");
    let core = match op {
        BinOp::Add => dispatch_fp_format!(fmt, add_sub_verilog())?,
        BinOp::Sub => dispatch_fp_format!(fmt, add_sub_verilog())?,
        BinOp::Mul => dispatch_fp_format!(fmt, mul_verilog())?,
        BinOp::Div => dispatch_fp_format!(fmt, div_verilog())?,
        BinOp::Sqrt => dispatch_fp_format!(fmt, sqrt_verilog())?,
        BinOp::Lt | BinOp::Le | BinOp::Eq => dispatch_fp_format!(fmt, compare_verilog())?,
    };
    let core = merge_identical_modules(&rename_rust_hdl_names(&core, &core_name));
    let w = fmt.width();
    let is_compare = matches!(op, BinOp::Lt | BinOp::Le | BinOp::Eq);
    let result_width = if is_compare { 1 } else { w };
    let lat = latency(op, fmt);
    let body = match op {
        BinOp::Add | BinOp::Sub => format!(
            "    {core_name} core(.clock(clock), .in_valid(in_valid), .a(a), .b(b), .sub(1'b{}),\n        \
             .out_valid(out_valid), .result(result));\n",
            u8::from(op == BinOp::Sub)
        ),
        BinOp::Mul | BinOp::Div => format!(
            "    {core_name} core(.clock(clock), .in_valid(in_valid), .a(a), .b(b),\n        \
             .out_valid(out_valid), .result(result));\n"
        ),
        BinOp::Sqrt => format!(
            "    {core_name} core(.clock(clock), .in_valid(in_valid), .a(a),\n        \
             .out_valid(out_valid), .result(result));\n"
        ),
        _ => {
            let mut s = String::new();
            for o in ["lt", "le", "eq"] {
                if o == op.name() {
                    continue;
                }
                s += &format!(
                    "    /* verilator lint_off UNUSEDSIGNAL */ // the other comparisons\n    \
                     wire unused_{o};\n    /* verilator lint_on UNUSEDSIGNAL */\n"
                );
            }
            let pin = |o: &str| {
                if o == op.name() {
                    format!(".{o}(result)")
                } else {
                    format!(".{o}(unused_{o})")
                }
            };
            s += &format!(
                "    {core_name} core(.clock(clock), .in_valid(in_valid), .a(a), .b(b),\n        \
                 .out_valid(out_valid), {}, {}, {});\n",
                pin("lt"),
                pin("le"),
                pin("eq")
            );
            s
        }
    };
    let result_decl = if result_width == 1 {
        "output wire result".to_string()
    } else {
        format!("output wire [{}:0] result", w - 1)
    };
    let b_port = if op.is_unary() {
        String::new()
    } else {
        format!("    input wire [{}:0] b,\n", w - 1)
    };
    let verilog = format!(
        "// {top}: dynrt floating-point operator `{op}` for format {fmt} (generated by dynrt).\n\
         // Latency {lat} clocks, one operation per clock; result valid when out_valid is 1.\n\
         // Rounding to nearest even; subnormals flushed to zero on input and output.\n\
         `timescale 1ns/1ps\n\
         \n\
         // Waiver for the rust-hdl generated core below: rust-hdl writes 32-bit literals,\n\
         // mask-style casts and full-width intermediates, whose widths Verilog resolves as\n\
         // intended (the tests compare this file bit for bit against the software model in\n\
         // Icarus and Verilator), and one module per instance, all in one file.\n\
         /* verilator lint_off WIDTH */\n\
         /* verilator lint_off DECLFILENAME */\n\
         {core}\n\
         /* verilator lint_on DECLFILENAME */\n\
         /* verilator lint_on WIDTH */\n\
         \n\
         module {top}(\n    \
             input wire clock,\n    \
             input wire in_valid,\n    \
             input wire [{wm}:0] a,\n\
         {b_port}    \
             output wire out_valid,\n    \
             {result_decl}\n\
         );\n\
         {body}\
         endmodule\n",
        op = op.name(),
        wm = w - 1,
    );
    Ok(FpUnitRtl {
        top,
        verilog,
        latency: lat,
        result_width,
        unary: op.is_unary(),
    })
}

fn core_verilog<U: Block>(mut uut: U) -> String {
    uut.connect_all();
    generate_verilog(&uut)
}

fn add_sub_verilog<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
>() -> String {
    core_verilog(FpAddSub::<W, E, M, S, S1, X2, T>::default())
}

fn mul_verilog<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
>() -> String {
    core_verilog(FpMul::<W, E, M, S, S1, X2, P>::default())
}

fn div_verilog<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
>() -> String {
    core_verilog(FpDiv::<W, E, M, S, S1, X2>::default())
}

fn sqrt_verilog<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
>() -> String {
    core_verilog(FpSqrt::<W, E, M, S, S1, T>::default())
}

fn compare_verilog<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
>() -> String {
    core_verilog(FpCompare::<W, E, M>::default())
}

/// A testbench (module `tb`) that feeds `n_vectors` lines `a b` (hex) from `vectors_path`
/// through `unit`, one per clock, and writes one hex result per line to `results_path` in input
/// order, then calls `$finish`. It stops with a message if the file has fewer vectors or the
/// results do not arrive within `n_vectors + latency + 100` clocks. Runs in Icarus (`-g2012`)
/// and Verilator 5 (`--binary --timing`).
pub fn fp_unit_testbench(
    unit: &FpUnitRtl,
    fmt: Format,
    n_vectors: usize,
    vectors_path: &str,
    results_path: &str,
) -> String {
    fp_units_testbench(&[unit], fmt, n_vectors, vectors_path, &[results_path])
}

/// Like [`fp_unit_testbench`] for several units of the same format fed the same vectors in
/// parallel (one simulator build for all of them), unit `i` writing to `results_paths[i]`.
pub fn fp_units_testbench(
    units: &[&FpUnitRtl],
    fmt: Format,
    n_vectors: usize,
    vectors_path: &str,
    results_paths: &[&str],
) -> String {
    assert_eq!(
        units.len(),
        results_paths.len(),
        "one results file per unit"
    );
    let w = fmt.width();
    let wm = w - 1;
    let n = n_vectors;
    let max_latency = units.iter().map(|u| u.latency).max().unwrap_or(0);
    let timeout = n_vectors as u64 + max_latency as u64 + 100;
    let vin = vectors_path;
    let mut decls = String::new();
    let mut opens = String::new();
    let mut collect = String::new();
    let mut all_done = Vec::new();
    for (i, (unit, path)) in units.iter().zip(results_paths).enumerate() {
        let top = &unit.top;
        let range = if unit.result_width == 1 {
            String::new()
        } else {
            format!("[{}:0] ", unit.result_width - 1)
        };
        let b_pin = if unit.unary { "" } else { " .b(b)," };
        decls += &format!(
            "    wire out_valid_{i};\n    wire {range}result_{i};\n    integer results_{i};\n    \
             integer received_{i} = 0;\n    \
             {top} dut_{i}(.clock(clock), .in_valid(in_valid), .a(a),{b_pin}\n        \
             .out_valid(out_valid_{i}), .result(result_{i}));\n"
        );
        opens += &format!(
            "        results_{i} = $fopen(\"{path}\", \"w\");\n        \
             if (results_{i} == 0) begin\n            \
             $display(\"tb: cannot open {path}\");\n            $finish;\n        end\n"
        );
        collect += &format!(
            "        if (out_valid_{i}) begin\n            \
             $fwrite(results_{i}, \"%h\\n\", result_{i});\n            \
             received_{i} = received_{i} + 1;\n            \
             if (received_{i} == {n}) $fclose(results_{i});\n        end\n"
        );
        all_done.push(format!("received_{i} == {n}"));
    }
    let all_done = if all_done.is_empty() {
        "1'b1".to_string()
    } else {
        all_done.join(" && ")
    };
    // With only unary units there is no `b` to drive; the second word is still read (and
    // dropped), so every operator takes the same vector files.
    let (b_decl, word_b_decl, b_drive) = if units.iter().any(|u| !u.unary) {
        (
            format!("    reg [{wm}:0] b = {w}'d0;\n"),
            format!("    reg [{wm}:0] word_b;\n"),
            "            b <= word_b;\n",
        )
    } else {
        (
            String::new(),
            format!(
                "    /* verilator lint_off UNUSEDSIGNAL */ // read and dropped: unary units only\n    \
                 reg [{wm}:0] word_b;\n    /* verilator lint_on UNUSEDSIGNAL */\n"
            ),
            "",
        )
    };
    let names = units
        .iter()
        .map(|u| u.top.as_str())
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        r#"// Testbench for {names}: streams {n} vectors from a file, one per clock.
// Lint waivers: the file is named after the unit, not `tb`; counters and the clock use
// blocking assignments on purpose (testbench code, read back in the same step).
/* verilator lint_off DECLFILENAME */
/* verilator lint_off BLKSEQ */
`timescale 1ns/1ps
module tb;
    reg clock = 1'b0;
    reg in_valid = 1'b0;
    reg [{wm}:0] a = {w}'d0;
{b_decl}    integer vectors;
    integer sent = 0;
    integer scanned;
    integer cycles = 0;
    reg [{wm}:0] word_a;
{word_b_decl}{decls}
    always #5 clock = ~clock;

    initial begin
        vectors = $fopen("{vin}", "r");
        if (vectors == 0) begin
            $display("tb: cannot open {vin}");
            $finish;
        end
{opens}    end

    // Inputs change and outputs are sampled on the falling edge, away from the rising edge
    // where the units' registers load.
    always @(negedge clock) begin
        cycles = cycles + 1;
{collect}        if ({all_done}) begin
            $finish;
        end
        if (sent < {n}) begin
            scanned = $fscanf(vectors, "%h %h\n", word_a, word_b);
            if (scanned != 2) begin
                $display("tb: {vin}: vector %0d is not two hex words", sent + 1);
                $finish;
            end
            a <= word_a;
{b_drive}            in_valid <= 1'b1;
            sent = sent + 1;
        end else begin
            in_valid <= 1'b0;
        end
        if (cycles > {timeout}) begin
            $display("tb: timeout after %0d clocks", cycles);
            $finish;
        end
    end
endmodule
"#
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::fp::supported_formats;
    use crate::sim::{self, Simulator};
    use crate::synth;

    const ALL_OPS: [BinOp; 8] = BinOp::ALL;

    fn write_unit(dir: &std::path::Path, unit: &FpUnitRtl) -> std::path::PathBuf {
        let path = dir.join(format!("{}.v", unit.top));
        std::fs::write(&path, &unit.verilog).unwrap();
        path
    }

    #[test]
    fn top_module_has_the_contract_ports() {
        let unit = fp_unit_rtl(BinOp::Add, Format::E7M16).unwrap();
        assert_eq!(unit.top, "fp_add_e7m16");
        assert_eq!(unit.latency, 8);
        assert!(unit.verilog.contains("module fp_add_e7m16(\n"));
        for port in [
            "input wire clock,",
            "input wire in_valid,",
            "input wire [23:0] a,",
            "input wire [23:0] b,",
            "output wire out_valid,",
            "output wire [23:0] result",
        ] {
            assert!(unit.verilog.contains(port), "missing `{port}`");
        }
        assert!(
            !unit.verilog.contains("module top"),
            "rust-hdl's name leaked"
        );
        let lt = fp_unit_rtl(BinOp::Lt, Format::E8M23).unwrap();
        assert_eq!(lt.result_width, 1);
        assert!(lt.verilog.contains("output wire result\n"));
        let div = fp_unit_rtl(BinOp::Div, Format::E8M23).unwrap();
        // Input, first bit, 12 stages of two quotient bits, round, pack.
        assert_eq!(div.latency, 16);
        let sqrt = fp_unit_rtl(BinOp::Sqrt, Format::E7M16).unwrap();
        assert_eq!(sqrt.top, "fp_sqrt_e7m16");
        assert_eq!((sqrt.latency, sqrt.result_width), (21, 24));
        assert!(sqrt.unary && !div.unary);
        assert!(sqrt.verilog.contains(
            "input wire [23:0] a,\n    output wire out_valid,\n    output wire [23:0] result\n"
        ));
        assert!(!sqrt.verilog.contains(" b,"), "sqrt has no b port");
    }

    #[test]
    fn unsupported_format_is_a_clear_error() {
        let err = fp_unit_rtl(BinOp::Mul, Format::new(4, 3).unwrap()).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("e4m3") && msg.contains("supported formats"),
            "{msg}"
        );
    }

    /// `verilator --lint-only -Wall` passes on every operator of e7m16 and e8m23, and on each
    /// distinct core (add/sub, mul, div, sqrt, compare) of every other format.
    #[test]
    fn verilator_lint_wall_is_clean() {
        let dir = tempfile::tempdir().unwrap();
        for fmt in supported_formats() {
            let ops: &[BinOp] = if fmt == Format::E7M16 || fmt == Format::E8M23 {
                &ALL_OPS
            } else {
                &[BinOp::Add, BinOp::Mul, BinOp::Div, BinOp::Sqrt, BinOp::Lt]
            };
            for &op in ops {
                let unit = fp_unit_rtl(op, fmt).unwrap();
                let path = write_unit(dir.path(), &unit);
                let report = sim::lint(&[path], &unit.top).unwrap();
                assert!(report.is_clean(), "{}: {report}", unit.top);
            }
        }
    }

    /// `verilator --lint-only -Wall --timing` on `files` (`crate::sim::lint` has no `--timing`,
    /// which a testbench with delays needs); returns its warnings and errors.
    fn lint_testbench(files: &[std::path::PathBuf]) -> String {
        let out = std::process::Command::new("verilator")
            .args(["--lint-only", "-Wall", "--timing", "--top-module", "tb"])
            .args(files)
            .output()
            .expect("verilator runs");
        let text = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(
            out.status.success() || text.contains('%'),
            "verilator failed: {text}"
        );
        text.lines()
            .filter(|l| l.starts_with("%Warning") || l.starts_with("%Error"))
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The testbench itself passes `verilator --lint-only -Wall` together with its units
    /// (a single unit, and several units sharing the vector stream).
    #[test]
    fn testbench_lint_wall_is_clean() {
        let dir = tempfile::tempdir().unwrap();
        let fmt = Format::E7M16;
        let add = fp_unit_rtl(BinOp::Add, fmt).unwrap();
        let eq = fp_unit_rtl(BinOp::Eq, fmt).unwrap();
        let add_file = write_unit(dir.path(), &add);
        let eq_file = write_unit(dir.path(), &eq);
        let single = dir.path().join("tb_single.v");
        std::fs::write(&single, fp_unit_testbench(&add, fmt, 10, "v.hex", "r.hex")).unwrap();
        let problems = lint_testbench(&[add_file.clone(), single]);
        assert!(problems.is_empty(), "single-unit testbench:\n{problems}");
        let multi = dir.path().join("tb_multi.v");
        let tb = fp_units_testbench(&[&add, &eq], fmt, 10, "v.hex", &["r0.hex", "r1.hex"]);
        std::fs::write(&multi, tb).unwrap();
        let problems = lint_testbench(&[add_file.clone(), eq_file, multi]);
        assert!(problems.is_empty(), "two-unit testbench:\n{problems}");
        // A unary unit alone (no `b` to drive), and beside a binary one.
        let sqrt = fp_unit_rtl(BinOp::Sqrt, fmt).unwrap();
        let sqrt_file = write_unit(dir.path(), &sqrt);
        let unary = dir.path().join("tb_unary.v");
        std::fs::write(&unary, fp_unit_testbench(&sqrt, fmt, 10, "v.hex", "r.hex")).unwrap();
        let problems = lint_testbench(&[sqrt_file.clone(), unary]);
        assert!(problems.is_empty(), "unary testbench:\n{problems}");
        let mixed = dir.path().join("tb_mixed.v");
        let tb = fp_units_testbench(&[&add, &sqrt], fmt, 10, "v.hex", &["r0.hex", "r1.hex"]);
        std::fs::write(&mixed, tb).unwrap();
        let problems = lint_testbench(&[add_file, sqrt_file, mixed]);
        assert!(problems.is_empty(), "add and sqrt testbench:\n{problems}");
    }

    /// The file-driven testbench runs in Icarus with a binary and a unary unit side by side:
    /// both read the same `a b` lines (sqrt ignores `b`) and write the model's results.
    #[test]
    fn testbench_feeds_binary_and_unary_units_in_icarus() {
        let dir = tempfile::tempdir().unwrap();
        let fmt = Format::E7M16;
        let add = fp_unit_rtl(BinOp::Add, fmt).unwrap();
        let sqrt = fp_unit_rtl(BinOp::Sqrt, fmt).unwrap();
        let v = crate::fp::vectors::random_pairs(fmt, 77, 300);
        println!("seed 77");
        let lines: String = v
            .iter()
            .map(|(a, b)| format!("{a:06x} {b:06x}\n"))
            .collect();
        std::fs::write(dir.path().join("v.hex"), lines).unwrap();
        let tb = dir.path().join("tb.v");
        let text = fp_units_testbench(&[&add, &sqrt], fmt, v.len(), "v.hex", &["r0.hex", "r1.hex"]);
        std::fs::write(&tb, text).unwrap();
        let files = vec![
            write_unit(dir.path(), &add),
            write_unit(dir.path(), &sqrt),
            tb,
        ];
        sim::run(
            Simulator::Icarus,
            &sim::SimJob::new(dir.path(), files, "tb"),
        )
        .unwrap();
        for (file, op) in [("r0.hex", BinOp::Add), ("r1.hex", BinOp::Sqrt)] {
            let text = std::fs::read_to_string(dir.path().join(file)).unwrap();
            let got: Vec<u32> = text
                .lines()
                .map(|l| u32::from_str_radix(l, 16).unwrap())
                .collect();
            let want: Vec<u32> = v.iter().map(|&(a, b)| op.eval(fmt, a, b)).collect();
            assert_eq!(got, want, "{op}");
        }
    }

    /// Every operator of e7m16 synthesizes for Virtex-II; the significand products map to
    /// one MULT18X18 (17x17) and, for e8m23's multiplier, four (24x24). Prints the resource
    /// counts (`make synth` and `dynrt bench fp` cover every operator of every format).
    #[test]
    fn yosys_xc2v_synthesis() {
        let dir = tempfile::tempdir().unwrap();
        let all = [BinOp::Add, BinOp::Mul, BinOp::Div, BinOp::Sqrt, BinOp::Lt];
        for (fmt, ops) in [
            (Format::E7M16, &all[..]),
            (Format::E8M23, &[BinOp::Mul][..]),
        ] {
            for &op in ops {
                let unit = fp_unit_rtl(op, fmt).unwrap();
                let path = write_unit(dir.path(), &unit);
                let work = dir.path().join(format!("synth_{}", unit.top));
                let options = synth::SynthOptions {
                    io_pads: false,
                    ..Default::default()
                };
                let report = synth::synth_xc2v_with(&[path], &unit.top, &work, &options).unwrap();
                println!(
                    "{}: latency {} LUTs {} FFs {} MULT18X18 {} depth {} ({:.1} s)",
                    unit.top,
                    unit.latency,
                    report.total_luts(),
                    report.flip_flops,
                    report.mult18x18,
                    report.logic_depth,
                    report.seconds
                );
                let expected_mults = match (op, fmt.man_bits) {
                    (BinOp::Mul, 16) => 1,
                    (BinOp::Mul, 23) => 4,
                    _ => 0,
                };
                assert_eq!(report.mult18x18, expected_mults, "{}", unit.top);
                assert!(report.flip_flops >= u64::from(unit.latency), "{}", unit.top);
            }
        }
    }
}
