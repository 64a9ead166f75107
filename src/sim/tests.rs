//! Tests of `sim` against the real Icarus Verilog and Verilator (no mocks).

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Duration;

/// Registered 8-bit adder and a testbench that reads `{a,b}` pairs from `vectors.hex`
/// (relative to the run directory) and writes the 9-bit sums to the file named by
/// `+out=...`. The vector count comes from the `NVEC` define.
const ADDER_V: &str = r#"
module adder8 (
    input wire clk,
    input wire [7:0] a,
    input wire [7:0] b,
    output reg [8:0] s
);
  always @(posedge clk) s <= {1'b0, a} + {1'b0, b};
endmodule

module tb_adder;
  reg clk = 1'b0;
  reg [7:0] a, b;
  wire [8:0] s;
  reg [15:0] vec [0:`NVEC-1];
  reg [8*64:1] out_name;
  integer i, fd;
  adder8 dut (.clk(clk), .a(a), .b(b), .s(s));
  always #5 clk = ~clk;
  initial begin
    if (!$value$plusargs("out=%s", out_name)) begin
      $display("missing +out=");
      $fatal(1);
    end
    $readmemh("vectors.hex", vec);
    fd = $fopen(out_name, "w");
    for (i = 0; i < `NVEC; i = i + 1) begin
      {a, b} = vec[i];
      @(posedge clk);
      #1;
      $fwrite(fd, "%03x\n", s);
    end
    $fclose(fd);
    $display("DONE %0d", i);
    $finish;
  end
endmodule
"#;

fn adder_vectors(seed: u64, n: usize) -> Vec<(u8, u8)> {
    println!("adder vectors: ChaCha8 seed {seed}, {n} vectors");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut v = vec![(0xff, 0xff), (0, 0), (0x80, 0x80), (0xff, 0x01)];
    while v.len() < n {
        v.push((rng.gen(), rng.gen()));
    }
    v
}

fn write_adder_bench(dir: &std::path::Path, vectors: &[(u8, u8)]) -> PathBuf {
    let src = dir.join("adder.v");
    std::fs::write(&src, ADDER_V).unwrap();
    let hex: String = vectors
        .iter()
        .map(|(a, b)| format!("{a:02x}{b:02x}\n"))
        .collect();
    std::fs::write(dir.join("vectors.hex"), hex).unwrap();
    src
}

fn check_adder(sim: Simulator) {
    let dir = tempfile::tempdir().unwrap();
    let vectors = adder_vectors(0x5eed_0000 + sim as u64, 64);
    let src = write_adder_bench(dir.path(), &vectors);
    let out_name = format!("sums_{sim}.hex");
    let job = SimJob::new(dir.path(), vec![src], "tb_adder")
        .define("NVEC", Some(vectors.len().to_string()))
        .plusarg(format!("out={out_name}"))
        .timeout(Duration::from_secs(120));
    let run = run(sim, &job).unwrap_or_else(|e| panic!("{sim}: {e}"));
    println!(
        "{sim}: compile {:.2} s, run {:.3} s",
        run.compile_seconds, run.run_seconds
    );
    assert!(
        run.stdout.contains("DONE 64"),
        "{sim} stdout: {}",
        run.stdout
    );
    assert!(run
        .build_dir
        .starts_with(std::path::absolute(dir.path()).unwrap()));
    let text = std::fs::read_to_string(dir.path().join(&out_name)).unwrap();
    let got: Vec<u32> = text
        .lines()
        .map(|l| u32::from_str_radix(l.trim(), 16).unwrap())
        .collect();
    let want: Vec<u32> = vectors.iter().map(|&(a, b)| a as u32 + b as u32).collect();
    assert_eq!(got, want, "{sim}: sums differ");
}

#[test]
fn adder_in_icarus() {
    check_adder(Simulator::Icarus);
}

#[test]
fn adder_in_verilator() {
    check_adder(Simulator::Verilator);
}

#[test]
fn one_verilator_build_runs_twice() {
    let dir = tempfile::tempdir().unwrap();
    let vectors = adder_vectors(11, 16);
    let src = write_adder_bench(dir.path(), &vectors);
    let job = SimJob::new(dir.path(), vec![src], "tb_adder")
        .define("NVEC", Some("16".into()))
        .verilator_build(VerilatorBuild::Fast);
    let build = compile(Simulator::Verilator, &job).unwrap();
    println!("verilator Fast build: {:.2} s", build.compile_seconds);
    let want: String = vectors
        .iter()
        .map(|&(a, b)| format!("{:03x}\n", a as u32 + b as u32))
        .collect();
    for name in ["first.hex", "second.hex"] {
        let run = build
            .run(&[format!("out={name}")], Duration::from_secs(60))
            .unwrap();
        assert!(run.stdout.contains("DONE 16"), "{}", run.stdout);
        assert_eq!(
            std::fs::read_to_string(dir.path().join(name)).unwrap(),
            want
        );
    }
    // Without +out= the testbench stops with $fatal: a run error, not a silent success.
    let err = build.run(&[], Duration::from_secs(60)).unwrap_err();
    assert!(err.to_string().contains("missing +out="), "{err}");
}

#[test]
fn two_jobs_in_one_work_dir_get_separate_build_dirs() {
    let dir = tempfile::tempdir().unwrap();
    let vectors = adder_vectors(7, 8);
    let src = write_adder_bench(dir.path(), &vectors);
    let job = SimJob::new(dir.path(), vec![src], "tb_adder")
        .define("NVEC", Some("8".into()))
        .plusarg("out=a.hex");
    let first = run(Simulator::Icarus, &job).unwrap();
    let second = run(Simulator::Icarus, &job).unwrap();
    assert_ne!(first.build_dir, second.build_dir);
    assert!(first.build_dir.join("tb_adder.vvp").is_file());
}

/// With `reuse_build` a job runs the kept build of an earlier job with the same inputs, and
/// compiles again (in the same folder) when a source, a define or the simulator changes.
#[test]
fn a_kept_build_is_reused_until_its_inputs_change() {
    for sim in Simulator::ALL {
        let dir = tempfile::tempdir().unwrap();
        let vectors = adder_vectors(7, 8);
        let src = write_adder_bench(dir.path(), &vectors);
        let job = SimJob::new(dir.path(), vec![src.clone()], "tb_adder")
            .define("NVEC", Some("8".into()))
            .plusarg("out=a.hex")
            .reuse_build(true);
        let first = compile(sim, &job).unwrap();
        assert!(!first.reused, "{sim}: nothing to reuse yet");
        let again = compile(sim, &job).unwrap();
        assert!(again.reused && again.compile_seconds == 0.0, "{sim}");
        assert_eq!(first.build_dir, again.build_dir);
        again.run(&job.plusargs, Duration::from_secs(60)).unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.path().join("a.hex"))
                .unwrap()
                .lines()
                .count(),
            8,
            "{sim}: the reused build runs"
        );
        // A changed source (another message in the testbench) is compiled again.
        let text = std::fs::read_to_string(&src).unwrap();
        std::fs::write(&src, text.replace("DONE %0d", "FINISHED %0d")).unwrap();
        let changed = compile(sim, &job).unwrap();
        assert!(!changed.reused, "{sim}: a changed source must be compiled");
        let out = changed.run(&job.plusargs, Duration::from_secs(60)).unwrap();
        assert!(out.stdout.contains("FINISHED 8"), "{sim}: {}", out.stdout);
        let other = compile(sim, &job.clone().define("EXTRA", None)).unwrap();
        assert!(!other.reused, "{sim}: a new define must be compiled");
        // Another command line in the provenance header is no change; tracing is.
        let text = std::fs::read_to_string(&src).unwrap();
        let header = |command: &str| {
            crate::provenance::GeneratedBy {
                version: "0.1.0".into(),
                commit: Some("abc".into()),
                command: Some(command.into()),
            }
            .comment("//")
        };
        std::fs::write(&src, header("dynrt sim a.toml --out x") + &text).unwrap();
        assert!(
            !compile(sim, &job).unwrap().reused,
            "{sim}: the define went"
        );
        std::fs::write(&src, header("dynrt sim a.toml --trace --out y") + &text).unwrap();
        assert!(
            compile(sim, &job).unwrap().reused,
            "{sim}: only the header's command line changed"
        );
        let traced = compile(sim, &job.clone().trace(Some(TraceFormat::Fst))).unwrap();
        assert!(!traced.reused, "{sim}: a traced build is another build");
        let builds = std::fs::read_dir(dir.path())
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .starts_with("build_")
            })
            .count();
        assert_eq!(builds, 1, "{sim}: one build folder, not one per run");
    }
}

/// A testbench whose line 4 has a syntax error.
const SYNTAX_ERROR_V: &str =
    "module tb_broken;\n  reg a;\n  initial begin\n    a = ;\n    $finish;\n  end\nendmodule\n";

fn check_syntax_error(sim: Simulator) {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("broken_tb.v");
    std::fs::write(&src, SYNTAX_ERROR_V).unwrap();
    let job = SimJob::new(dir.path(), vec![src], "tb_broken");
    let err = run(sim, &job).unwrap_err();
    let msg = err.to_string();
    println!("{sim}: {msg}");
    match err {
        ToolError::Compile { location, .. } => {
            let loc = location.expect("the error must be located");
            assert!(loc.file.ends_with("broken_tb.v"), "{loc}");
            assert_eq!(loc.line, 4, "{msg}");
        }
        other => panic!("{sim}: expected a compile error, got {other:?}"),
    }
    assert!(msg.contains("broken_tb.v:4"), "{msg}");
}

#[test]
fn syntax_error_in_icarus_names_file_and_line() {
    check_syntax_error(Simulator::Icarus);
}

#[test]
fn syntax_error_in_verilator_names_file_and_line() {
    check_syntax_error(Simulator::Verilator);
}

const ENDLESS_V: &str = r#"
module tb_endless;
  reg clk = 1'b0;
  integer n = 0;
  always #5 clk = ~clk;
  always @(posedge clk) n <= n + 1;
endmodule
"#;

fn check_timeout(sim: Simulator) {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("endless.v");
    std::fs::write(&src, ENDLESS_V).unwrap();
    let job = SimJob::new(dir.path(), vec![src], "tb_endless").timeout(Duration::from_secs(2));
    let err = run(sim, &job).unwrap_err();
    let msg = err.to_string();
    println!("{sim}: {msg}");
    match err {
        ToolError::Timeout { stage, seconds, .. } => {
            assert!(stage.contains("simulating `tb_endless`"), "{stage}");
            assert_eq!(seconds, 2.0);
        }
        other => panic!("{sim}: expected a timeout, got {other:?}"),
    }
    assert!(msg.contains("timed out after 2.0 s"), "{msg}");
}

#[test]
fn endless_testbench_times_out_in_icarus() {
    check_timeout(Simulator::Icarus);
}

#[test]
fn endless_testbench_times_out_in_verilator() {
    check_timeout(Simulator::Verilator);
}

const FATAL_V: &str = r#"
module tb_fatal;
  initial begin
    $display("about to fail");
    $fatal(1, "deliberate failure");
  end
endmodule
"#;

fn check_fatal(sim: Simulator) {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("fatal.v");
    std::fs::write(&src, FATAL_V).unwrap();
    let job = SimJob::new(dir.path(), vec![src], "tb_fatal");
    let err = run(sim, &job).unwrap_err();
    let msg = err.to_string();
    println!("{sim}: {msg}");
    assert!(matches!(err, ToolError::Run { .. }), "{sim}: {err:?}");
    assert!(msg.contains("deliberate failure"), "{msg}");
}

#[test]
fn fatal_in_icarus_is_a_run_error() {
    check_fatal(Simulator::Icarus);
}

#[test]
fn fatal_in_verilator_is_a_run_error() {
    check_fatal(Simulator::Verilator);
}

#[test]
fn missing_source_and_bad_top_are_job_errors() {
    let dir = tempfile::tempdir().unwrap();
    let job = SimJob::new(dir.path(), vec![dir.path().join("nope.v")], "tb");
    let msg = run(Simulator::Icarus, &job).unwrap_err().to_string();
    assert!(
        msg.contains("nope.v") && msg.contains("does not exist"),
        "{msg}"
    );
    let src = dir.path().join("x.v");
    std::fs::write(&src, "module x; endmodule\n").unwrap();
    let job = SimJob::new(dir.path(), vec![src], "1bad name");
    assert!(matches!(
        run(Simulator::Verilator, &job),
        Err(ToolError::BadJob(_))
    ));
}

#[test]
fn missing_binary_gives_install_hint() {
    let err = process::run_tool(
        "iverilog",
        "testing",
        &mut std::process::Command::new("dynrt-no-such-simulator-binary"),
        Duration::from_secs(5),
    )
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "iverilog not found on PATH: install it with `make deps` \
         (apt-get install -y iverilog verilator yosys)"
    );
}

#[test]
fn simulator_names_round_trip() {
    for sim in Simulator::ALL {
        assert_eq!(sim.to_string().parse::<Simulator>().unwrap(), sim);
    }
    assert_eq!("icarus".parse::<Simulator>().unwrap(), Simulator::Icarus);
    assert!("modelsim"
        .parse::<Simulator>()
        .unwrap_err()
        .contains("modelsim"));
}

#[test]
fn versions_of_installed_tools() {
    let iv = tool_version(Simulator::Icarus).unwrap();
    let vl = tool_version(Simulator::Verilator).unwrap();
    println!("iverilog {iv}, verilator {vl}");
    // The supported versions (docs/ARCHITECTURE.md, "Data flow", Tools): Icarus 11, Verilator 5.
    assert!(iv.starts_with("11."), "{iv}");
    assert!(vl.starts_with("5."), "{vl}");
    assert_eq!(
        version_after(
            "Verilator 5.006 2023-01-22 rev (Debian 5.006-3)",
            "Verilator"
        )
        .as_deref(),
        Some("5.006")
    );
    assert_eq!(
        version_after("Icarus Verilog version 11.0 (stable) ()", "version").as_deref(),
        Some("11.0")
    );
}

#[test]
fn lint_finds_width_mismatch_and_passes_clean_module() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("clean_add.v");
    std::fs::write(
        &clean,
        "module clean_add (\n    input wire clk,\n    input wire [7:0] a,\n    input wire [7:0] b,\n    \
         output reg [8:0] s\n);\n  always @(posedge clk) s <= {1'b0, a} + {1'b0, b};\nendmodule\n",
    )
    .unwrap();
    let report = lint(&[clean], "clean_add").unwrap();
    assert!(report.is_clean(), "{report}");

    let narrow = dir.path().join("narrow_add.v");
    // Line 6: a 9-bit sum assigned to an 8-bit output.
    std::fs::write(
        &narrow,
        "module narrow_add (\n    input wire [7:0] a,\n    input wire [7:0] b,\n    \
         output wire [7:0] s\n);\n  assign s = a + b + 9'd1;\nendmodule\n",
    )
    .unwrap();
    let report = lint(&[narrow], "narrow_add").unwrap();
    println!("{report}");
    let width: Vec<_> = report.with_code("WIDTH").collect();
    assert_eq!(width.len(), 1, "{report}");
    assert!(width[0].file.ends_with("narrow_add.v"));
    assert_eq!(width[0].line, 6);
    assert!(width[0].message.contains("8 bits"), "{}", width[0].message);
}

#[test]
fn lint_of_broken_source_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("broken_tb.v");
    std::fs::write(&src, SYNTAX_ERROR_V).unwrap();
    match lint(&[src], "tb_broken") {
        Err(ToolError::Compile { location, .. }) => assert_eq!(location.unwrap().line, 4),
        other => panic!("expected a compile error, got {other:?}"),
    }
}

#[test]
fn verilator_compile_timeout_kills_the_build() {
    let dir = tempfile::tempdir().unwrap();
    let vectors = adder_vectors(3, 4);
    let src = write_adder_bench(dir.path(), &vectors);
    let mut job = SimJob::new(dir.path(), vec![src], "tb_adder").define("NVEC", Some("4".into()));
    // Far too short for the build to finish even on an idle machine (at 2 s a fast machine
    // was already linking when the timeout fired); left alone, make and g++ would finish the
    // model well within the 15 s below.
    job.compile_timeout = Duration::from_millis(300);
    match compile(Simulator::Verilator, &job) {
        Err(ToolError::Timeout { stage, .. }) => assert!(stage.contains("compiling"), "{stage}"),
        other => panic!("expected a compile timeout, got {other:?}"),
    }
    // Had make and g++ survived the timeout, they would finish the model; killed, they don't.
    std::thread::sleep(Duration::from_secs(15));
    let built: Vec<_> = walk(dir.path())
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n == "Vtb_adder"))
        .collect();
    assert!(
        built.is_empty(),
        "the build went on after the timeout: {built:?}"
    );
}

fn walk(dir: &std::path::Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(walk(&path));
        } else {
            found.push(path);
        }
    }
    found
}
