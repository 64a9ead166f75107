//! `dynrt sim --trace`: waveforms of a window of clocks, in Icarus and in Verilator, VCD and
//! FST, on `tests/data/one_box.toml` (2x2 pixels, about 2,800 clocks). The window is read back
//! from the file itself: a VCD's timestamps, an FST's header (its start and end times).

use std::path::{Path, PathBuf};
use std::process::Command;

fn dynrt(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_dynrt"))
        .args(args)
        .output()
        .expect("run dynrt");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn one_box() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/one_box.toml")
        .display()
        .to_string()
}

/// What a waveform file says about itself: the first and last time it holds, in ps, and how
/// many signals it declares.
#[derive(Debug)]
struct Dump {
    first_ps: u64,
    last_ps: u64,
    signals: u64,
}

/// A VCD's timescale, timestamps and `$var` declarations.
fn read_vcd(path: &Path) -> Dump {
    let text = std::fs::read_to_string(path).unwrap();
    let header = text.split("$enddefinitions").next().unwrap();
    let scale: String = header
        .split("$timescale")
        .nth(1)
        .and_then(|r| r.split("$end").next())
        .expect("a $timescale")
        .split_whitespace()
        .collect();
    let ps_per_unit = match scale.as_str() {
        "1ps" => 1,
        "1ns" => 1000,
        "1fs" => panic!("fs timescale"),
        other => panic!("unexpected timescale {other}"),
    };
    let times: Vec<u64> = text
        .lines()
        .filter_map(|l| l.strip_prefix('#'))
        .map(|t| t.trim().parse::<u64>().unwrap() * ps_per_unit)
        .collect();
    assert!(times.windows(2).all(|w| w[0] < w[1]), "timestamps rise");
    Dump {
        first_ps: times[0],
        last_ps: *times.last().unwrap(),
        signals: header.matches("$var").count() as u64,
    }
}

/// An FST's header block (GTKWave's fstapi): block type 0, its length, the start and end
/// times and, at byte 73, the timescale as a power of ten; the number of variables at byte 57.
fn read_fst(path: &Path) -> Dump {
    let b = std::fs::read(path).unwrap();
    assert!(b.len() > 330, "{} bytes", b.len());
    let word = |at: usize| u64::from_be_bytes(b[at..at + 8].try_into().unwrap());
    assert_eq!(b[0], 0, "an FST starts with its header block");
    assert_eq!(word(1), 329, "the FST header block's length");
    assert_eq!(b[73] as i8, -12, "timescale 1ps");
    Dump {
        first_ps: word(9),
        last_ps: word(17),
        signals: word(57),
    }
}

/// Clock `c` of the run begins at 10c - 5 ns (the testbench's clock toggles every 5 ns).
fn clock_ps(c: u64) -> u64 {
    (10 * c - 5) * 1000
}

/// Runs `dynrt sim` with `--trace FORMAT` over clocks [start, end) and checks the file: it is
/// the only trace in the folder, it begins at the window's first clock and ends within the
/// window's last, it declares the processor's signals, and the frame is still identical.
fn traced_window(sim: &str, format: &str, start: u64, end: u64) {
    let dir = tempfile::tempdir().unwrap();
    let out: PathBuf = dir.path().join("sim");
    std::fs::create_dir(&out).unwrap();
    let other = if format == "vcd" { "fst" } else { "vcd" };
    std::fs::write(out.join(format!("trace.{other}")), "an earlier run's").unwrap();
    let (code, stdout, err) = dynrt(&[
        "sim",
        &one_box(),
        "--threads",
        "4",
        "--sim",
        sim,
        "--trace",
        format,
        "--trace-start",
        &start.to_string(),
        "--trace-end",
        &end.to_string(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    assert!(stdout.contains("identical to the golden model"), "{stdout}");
    let path = out.join(format!("trace.{format}"));
    assert!(
        stdout.contains(&format!("waveforms of clocks {start} to {end}")),
        "{stdout}"
    );
    assert!(
        !out.join(format!("trace.{other}")).exists(),
        "the stale trace of the other format is removed"
    );
    let dump = if format == "vcd" {
        read_vcd(&path)
    } else {
        read_fst(&path)
    };
    let bytes = std::fs::metadata(&path).unwrap().len();
    println!(
        "{sim} {format}: {bytes} bytes for {} clocks, {dump:?}",
        end - start
    );
    assert_eq!(
        dump.first_ps,
        clock_ps(start),
        "{sim} {format}: the dump begins with clock {start}"
    );
    // Icarus writes its $dumpoff at the window's end; Verilator closes the file just before.
    assert!(
        dump.last_ps <= clock_ps(end) && dump.last_ps >= clock_ps(end) - 10_000,
        "{sim} {format}: the dump ends with clock {end}, not at {} ps",
        dump.last_ps
    );
    // The whole processor, not just the testbench's few registers.
    assert!(dump.signals > 500, "{sim} {format}: {dump:?}");
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(
        summary.contains(&format!("\"trace.{format}\"")),
        "{summary}"
    );
}

// One test per simulator and format: each builds a model of its own (a traced Verilator
// build takes 30-60 s), and apart they share the test threads.
#[test]
fn icarus_traces_a_window_of_clocks_in_vcd() {
    traced_window("iverilog", "vcd", 1000, 1100);
}

#[test]
fn icarus_traces_a_window_of_clocks_in_fst() {
    traced_window("iverilog", "fst", 1000, 1100);
}

#[test]
fn verilator_traces_a_window_of_clocks_in_vcd() {
    traced_window("verilator", "vcd", 1000, 1100);
}

#[test]
fn verilator_traces_a_window_of_clocks_in_fst() {
    traced_window("verilator", "fst", 1000, 1100);
}

/// A window that begins after the run, and an empty window, are clear errors naming the
/// flags; neither leaves an output folder behind.
#[test]
fn a_window_outside_the_run_is_refused_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sim");
    let (code, _, err) = dynrt(&[
        "sim",
        &one_box(),
        "--threads",
        "4",
        "--sim",
        "iverilog",
        "--trace",
        "vcd",
        "--trace-start",
        "200",
        "--trace-end",
        "100",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--trace-end 100 is not after --trace-start 200"),
        "{err}"
    );
    assert!(!out.exists());
    let (code, _, err) = dynrt(&[
        "sim",
        &one_box(),
        "--threads",
        "4",
        "--sim",
        "iverilog",
        "--trace",
        "--trace-start",
        "1000000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--trace-start 1000000: the run ended before that clock"),
        "{err}"
    );
    assert!(!out.exists(), "the failed run's folder is removed");
    let (code, _, err) = dynrt(&["sim", &one_box(), "--trace-end", "5", "--out", "x"]);
    assert_eq!(code, 2, "--trace-end needs --trace: {err}");
}
