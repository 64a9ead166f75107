//! The generated processor as a component of other people's projects: FuseSoC runs the core
//! `dynrt rtl` writes, the testbench runs from another folder with `+mem_dir=` and
//! `+out_dir=`, and the cocotb test drives the processor and checks its frame against
//! `golden0.hex`. FuseSoC and cocotb come from PyPI, pinned, in `.venv-eda/` (`make deps`);
//! a missing tool fails these tests, it never skips them. All on `tests/data/one_box.toml`
//! (2x2 pixels, one box, no shadows: about 1,500 clocks) with 4 threads, since Icarus runs the
//! whole processor at about 150 clocks/s (a 2x2 frame of `scenes/tiny.toml` takes 13,700
//! clocks, a minute and a half per run).

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A tool of the project's EDA venv.
fn venv_tool(name: &str) -> PathBuf {
    let p = root().join(".venv-eda/bin").join(name);
    assert!(
        p.is_file(),
        "{} is missing: run `make deps` (it installs FuseSoC and cocotb into .venv-eda/)",
        p.display()
    );
    p
}

fn run(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{cmd:?} failed:\n{text}");
    text
}

/// `dynrt rtl` of the one-box scene with 4 threads into `dir`.
fn box_rtl(dir: &Path) {
    run(Command::new(env!("CARGO_BIN_EXE_dynrt")).args([
        "rtl",
        root().join("tests/data/one_box.toml").to_str().unwrap(),
        "--threads",
        "4",
        "--out",
        dir.to_str().unwrap(),
    ]));
}

fn golden(dir: &Path) -> String {
    let g = std::fs::read_to_string(dir.join("golden0.hex")).unwrap();
    assert_eq!(g.lines().count(), 4, "golden0.hex of a 2x2 frame: {g}");
    assert!(
        g.lines().any(|p| p != "000000"),
        "the box is in the frame: {g}"
    );
    g
}

#[test]
fn fusesoc_runs_the_core_in_icarus_and_the_testbench_runs_from_any_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let (proc_dir, build, frames) = (
        tmp.path().join("proc"),
        tmp.path().join("build"),
        tmp.path().join("frames"),
    );
    box_rtl(&proc_dir);
    let want = golden(&proc_dir);
    let files_f = std::fs::read_to_string(proc_dir.join("files.f")).unwrap();
    assert!(
        files_f.ends_with("\nrtl/dynrt_processor.v\ntestbench/tb.v\n"),
        "{files_f}"
    );
    std::fs::create_dir(&frames).unwrap();
    let out = run(Command::new(venv_tool("fusesoc"))
        .arg("--cores-root")
        .arg(&proc_dir)
        .args(["run", "--build-root"])
        .arg(&build)
        .args([
            "--target",
            "sim_icarus",
            "dynrt:processor:one_box",
            "--out_dir",
        ])
        .arg(&frames));
    assert_eq!(
        std::fs::read_to_string(frames.join("frame0.hex")).unwrap_or_default(),
        want,
        "the frame FuseSoC's Icarus run wrote differs from golden0.hex:\n{out}"
    );
    // The compiled testbench, run from a folder without mem/, reads the images named by
    // +mem_dir and writes where +out_dir says.
    // Edalize names the compiled testbench after the core: dynrt_processor_one_box_<version>.
    let core_id = format!("dynrt_processor_one_box_{}", env!("CARGO_PKG_VERSION"));
    let vvp = build
        .join(&core_id)
        .join("sim_icarus-icarus")
        .join(&core_id);
    assert!(
        vvp.is_file(),
        "no {} after FuseSoC's run:\n{out}",
        vvp.display()
    );
    // `elsewhere` has no mem/: the images can only come through +mem_dir.
    let elsewhere = tmp.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    let log = run(Command::new("vvp")
        .current_dir(&elsewhere)
        .arg("-n")
        .arg(&vvp)
        .arg(format!("+mem_dir={}", proc_dir.join("mem").display()))
        .arg("+out_dir=.")
        .arg("+heartbeat=200"));
    // +heartbeat=N: a progress line every N clocks, which dynrt streams while it waits.
    assert!(log.contains("dynrt-heartbeat frame 0: "), "{log}");
    assert_eq!(
        std::fs::read_to_string(elsewhere.join("frame0.hex")).unwrap_or_default(),
        want
    );
}

/// The core's Verilator target sets up (the compile itself takes a minute or more for the
/// whole processor, so CI only checks what FuseSoC hands Verilator): both sources, top `tb`,
/// `--binary --timing`, and the memory images copied beside the model.
#[test]
fn fusesoc_sets_up_the_verilator_target() {
    let tmp = tempfile::tempdir().unwrap();
    let (proc_dir, build) = (tmp.path().join("proc"), tmp.path().join("build"));
    box_rtl(&proc_dir);
    let out = run(Command::new(venv_tool("fusesoc"))
        .arg("--cores-root")
        .arg(&proc_dir)
        .args(["run", "--setup", "--build-root"])
        .arg(&build)
        .args(["--target", "sim_verilator", "dynrt:processor:one_box"]));
    let core_id = format!("dynrt_processor_one_box_{}", env!("CARGO_PKG_VERSION"));
    let work = build.join(&core_id).join("sim_verilator-verilator");
    let vc = std::fs::read_to_string(work.join(format!("{core_id}.vc")))
        .unwrap_or_else(|e| panic!("{e}:\n{out}"));
    assert!(
        vc.contains("rtl/dynrt_processor.v") && vc.contains("testbench/tb.v"),
        "{vc}"
    );
    assert!(vc.contains("--top-module tb"), "{vc}");
    let config = std::fs::read_to_string(work.join("config.mk")).unwrap();
    assert!(config.contains("--timing"), "{config}");
    assert!(work.join("mem/bank0_nodes.hex").is_file());
    // Edalize builds with `make binary` (Verilator --binary) in this mode.
    let eda = std::fs::read_to_string(work.join(format!("{core_id}.eda.yml"))).unwrap();
    assert!(eda.contains("mode: binary"), "{eda}");
}

#[test]
fn the_cocotb_test_drives_the_processor_and_checks_the_golden_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let proc_dir = tmp.path().join("proc");
    box_rtl(&proc_dir);
    golden(&proc_dir);
    let python = venv_tool("python");
    let runner = proc_dir.join("cocotb/run.py");
    let build = tmp.path().join("cocotb_build");
    let out = run(Command::new(&python)
        .arg(&runner)
        .arg("--build-dir")
        .arg(&build));
    assert!(out.contains("cocotb: 1 passed, 0 failed"), "{out}");
    // One wrong pixel in the golden frame fails it.
    let g = golden(&proc_dir);
    let first = g.lines().next().unwrap();
    let flipped = format!("{:06x}", u32::from_str_radix(first, 16).unwrap() ^ 1);
    std::fs::write(proc_dir.join("golden0.hex"), g.replacen(first, &flipped, 1)).unwrap();
    let failed = Command::new(&python)
        .arg(&runner)
        .arg("--build-dir")
        .arg(&build)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&failed.stdout).into_owned()
        + &String::from_utf8_lossy(&failed.stderr);
    assert!(
        !failed.status.success(),
        "a wrong golden pixel passed:\n{text}"
    );
    assert!(
        text.contains("1 pixels differ from golden0.hex, first at pixel 0"),
        "{text}"
    );
}
