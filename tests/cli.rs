//! The `dynrt` binary: outputs of the working verbs and the errors bad input gets.

use std::path::Path;
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

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn render_writes_a_png_and_a_hits_file_with_one_row_per_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("tiny.png");
    let hits = dir.path().join("tiny.csv");
    let (code, _, err) = dynrt(&[
        "render",
        &scene("tiny.toml"),
        "--width",
        "10",
        "--height",
        "6",
        "--out",
        png.to_str().unwrap(),
        "--hits",
        hits.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
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
    // The same image compared with itself: no differing pixel, infinite PSNR.
    let (code, out, _) = dynrt(&["compare", png.to_str().unwrap(), png.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(
        out.contains("differing pixels 0") && out.contains("PSNR             inf"),
        "{out}"
    );
}

#[test]
fn fp_model_results_follow_the_vectors() {
    let dir = tempfile::tempdir().unwrap();
    let v = dir.path().join("v.txt");
    let out = dir.path().join("out.txt");
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
        out.to_str().unwrap(),
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
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "1\n0\n");
}

#[test]
fn bad_input_gets_one_clear_error_and_no_output_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.txt");
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
            "unknown operator `pow`",
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
