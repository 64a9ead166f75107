//! The generated processor as a component of other people's projects: FuseSoC runs the core
//! `dynrt rtl` writes, the testbench runs from another folder with `+mem_dir=` and
//! `+out_dir=`, and the cocotb test drives the processor and checks its frame against
//! `golden0.hex`. FuseSoC and cocotb come from PyPI, pinned, in `.venv-eda/` (`make deps`);
//! a missing tool fails these tests, it never skips them. All on a 2x2 frame of
//! `scenes/tiny.toml` with 4 threads, so that Icarus needs seconds.

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

/// `dynrt rtl` of tiny at 2x2 with 4 threads into `dir`.
fn tiny_rtl(dir: &Path) {
    run(Command::new(env!("CARGO_BIN_EXE_dynrt")).args([
        "rtl",
        root().join("scenes/tiny.toml").to_str().unwrap(),
        "--width",
        "2",
        "--height",
        "2",
        "--threads",
        "4",
        "--out",
        dir.to_str().unwrap(),
    ]));
}

fn golden(dir: &Path) -> String {
    let g = std::fs::read_to_string(dir.join("golden0.hex")).unwrap();
    assert_eq!(g.lines().count(), 4, "golden0.hex of a 2x2 frame: {g}");
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
    tiny_rtl(&proc_dir);
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
            "dynrt:processor:tiny",
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
    let vvp = walk(&build)
        .into_iter()
        .find(|p| p.extension().is_some_and(|e| e == "vvp"))
        .unwrap_or_else(|| panic!("no .vvp file in FuseSoC's build folder:\n{out}"));
    let elsewhere = tmp.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    run(Command::new("vvp")
        .current_dir(&elsewhere)
        .arg("-n")
        .arg(&vvp)
        .arg(format!("+mem_dir={}", proc_dir.join("mem").display()))
        .arg("+out_dir=."));
    assert_eq!(
        std::fs::read_to_string(elsewhere.join("frame0.hex")).unwrap_or_default(),
        want
    );
    // Without +mem_dir the testbench looks in ./mem, which is not there: no frame to compare.
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let _ = Command::new("vvp")
        .current_dir(&empty)
        .arg("-n")
        .arg(&vvp)
        .output();
    let frame = std::fs::read_to_string(empty.join("frame0.hex")).unwrap_or_default();
    assert_ne!(
        frame, want,
        "a run without the images cannot render the frame"
    );
}

#[test]
fn the_cocotb_test_drives_the_processor_and_checks_the_golden_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let proc_dir = tmp.path().join("proc");
    tiny_rtl(&proc_dir);
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

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(walk(&p));
            } else {
                out.push(p);
            }
        }
    }
    out
}
