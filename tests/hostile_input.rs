//! A corpus of bad inputs, each with the exit status and the words its message must hold, and
//! what must not happen: a panic (exit 101), a hang (each case runs under a time limit), an
//! output where none was asked for, a file replaced that was not named as an output.
//!
//! Each case builds its files in a fresh folder (`$D` in its arguments), runs `dynrt`, and
//! checks that the folder holds afterwards exactly what it held before the run (no partial
//! output) unless the case says otherwise.

use std::collections::BTreeSet;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const USAGE: i32 = 2;

/// A scene that renders: the Cornell box, 8x6 pixels, one light.
const GOOD: &str = r#"
[camera]
eye = [0.0, 1.0, 3.5]
look_at = [0.0, 1.0, 0.0]
fov_y = 40.0
width = 8
height = 6
[[lights]]
position = [0.0, 1.9, 0.8]
[[objects]]
name = "box"
generate = { kind = "cornell_box" }
"#;

/// The camera and light of [`GOOD`] without its object.
fn good_without_objects() -> String {
    GOOD.split("[[objects]]").next().unwrap().to_string()
}

/// A scene of one mesh object `m.obj`.
fn mesh_scene(mesh: &str) -> String {
    format!(
        "{}[[objects]]\nname = \"m\"\nmesh = \"{mesh}\"\n",
        good_without_objects()
    )
}

const TRIANGLE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

struct Case {
    name: &'static str,
    /// Files to create: (name in the folder, contents); a name starting with `fifo:` makes a
    /// named pipe, `link:NAME` a symlink to NAME.
    files: Vec<(String, String)>,
    /// Arguments; `$D` is the case's folder.
    args: Vec<String>,
    code: i32,
    /// Words the message (stderr) must contain, in any case.
    words: Vec<&'static str>,
}

fn case(
    name: &'static str,
    files: &[(&str, &str)],
    args: &str,
    code: i32,
    words: &[&'static str],
) -> Case {
    Case {
        name,
        files: files
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect(),
        args: args.split_whitespace().map(String::from).collect(),
        code,
        words: words.to_vec(),
    }
}

fn corpus() -> Vec<Case> {
    let many_lights = format!(
        "{GOOD}{}",
        "[[lights]]\nposition = [0.0, 1.9, 0.8]\n".repeat(120)
    );
    let scaled = format!("{GOOD}[[instances]]\nobject = \"box\"\nscale = [1e39, 1e39, 1e39]\n");
    let far_camera = GOOD.replace("eye = [0.0, 1.0, 3.5]", "eye = [0.0, 1.0, 1e300]");
    let animated = format!(
        "{GOOD}[[instances]]\nobject = \"box\"\n[instances.animate]\nframes = 100000\ntranslate = [1.0, 0.0, 0.0]\n"
    );
    let good = GOOD.to_string();
    let no_objects = good_without_objects();
    let obj = mesh_scene("m.obj");
    vec![
        // Panics.
        case(
            "no objects: render",
            &[("s.toml", &no_objects)],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["no [[objects]]", "s.toml"],
        ),
        case(
            "no objects: rtl",
            &[("s.toml", &no_objects)],
            "rtl $D/s.toml --out $D/r",
            USAGE,
            &["no [[objects]]"],
        ),
        case(
            "too many lights for the ROM",
            &[("s.toml", &many_lights)],
            "rtl $D/s.toml --out $D/r",
            USAGE,
            &["ROM holds", "121 lights", "use at most"],
        ),
        // Hangs and unbounded reads.
        case(
            "scene is a FIFO",
            &[("fifo:s.toml", "")],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["named pipe", "not a regular file"],
        ),
        case(
            "mesh is a FIFO",
            &[("s.toml", &obj), ("fifo:m.obj", "")],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["named pipe", "m.obj"],
        ),
        case(
            "mesh is /dev/zero",
            &[("s.toml", &mesh_scene("/dev/zero"))],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["character device", "/dev/zero"],
        ),
        case(
            "mtllib is /dev/urandom",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib /dev/urandom\n{TRIANGLE_OBJ}")),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["character device", "/dev/urandom"],
        ),
        case(
            "mtllib is a FIFO",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib m.mtl\n{TRIANGLE_OBJ}")),
                ("fifo:m.mtl", ""),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["named pipe", "m.mtl"],
        ),
        case(
            "fp vectors are a FIFO",
            &[("fifo:v.txt", "")],
            "fp --op add --vectors $D/v.txt --out $D/r.txt",
            USAGE,
            &["named pipe", "v.txt"],
        ),
        // Destroyed files.
        case(
            "--out is a device",
            &[("s.toml", &good)],
            "render $D/s.toml --out /dev/null",
            USAGE,
            &["/dev/null", "character device", "regular files"],
        ),
        case(
            "--out is a symlink",
            &[
                ("s.toml", &good),
                ("keep.png", "precious"),
                ("link:o.png", "keep.png"),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["symbolic link"],
        ),
        case(
            "--hits is --out",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/o.png --hits $D/o.png",
            USAGE,
            &["--out and --hits are the same file"],
        ),
        case(
            "--out is the scene",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/s.toml",
            USAGE,
            &["the scene and --out are the same file"],
        ),
        case(
            "--out is a folder",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D",
            USAGE,
            &["a directory"],
        ),
        case(
            "--out ends in a slash",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/newdir/",
            USAGE,
            &["names a folder"],
        ),
        case(
            "--out under a file",
            &[("s.toml", &good), ("f.png", "x")],
            "render $D/s.toml --out $D/f.png/x",
            USAGE,
            &["is a file, not a folder"],
        ),
        case(
            "rtl --out is a file",
            &[("s.toml", &good), ("r", "x")],
            "rtl $D/s.toml --out $D/r",
            USAGE,
            &["not a folder"],
        ),
        // Silent garbage.
        case(
            "instance scale overflows the format",
            &[("s.toml", &scaled)],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["instance 'box#0'", "overflows", "e7m16"],
        ),
        case(
            "stress margin nan",
            &[],
            "stress --margins nan --out $D/s.csv",
            USAGE,
            &["--margins NaN", "0..=65536"],
        ),
        case(
            "stress margin inf",
            &[],
            "stress --margins inf --out $D/s.csv",
            USAGE,
            &["--margins inf"],
        ),
        case(
            "stress margin negative",
            &[],
            "stress --margins=-1e9 --out $D/s.csv",
            USAGE,
            &["--margins -1000000000"],
        ),
        case(
            "hits with a duplicate pixel",
            &[
                ("a.png", ""),
                (
                    "h.csv",
                    "x,y,instance,triangle,dist\n0,0,-1,-1,inf\n0,0,-1,-1,inf\n",
                ),
            ],
            "compare $D/a.png $D/a.png --hits $D/h.csv $D/h.csv",
            USAGE,
            &["h.csv: line 3", "appears twice"],
        ),
        case(
            "hits with a nan distance",
            &[
                ("a.png", ""),
                ("h.csv", "x,y,instance,triangle,dist\n0,0,0,1,nan\n"),
            ],
            "compare $D/a.png $D/a.png --hits $D/h.csv $D/h.csv",
            USAGE,
            &["h.csv: line 2", "finite distance"],
        ),
        // Runaway output.
        case(
            "100,000 animated frames",
            &[("s.toml", &animated)],
            "rtl $D/s.toml --out $D/r",
            USAGE,
            &["100000 frames", "--frames N"],
        ),
        // Partial output.
        case(
            "bad --threads",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --threads 99",
            USAGE,
            &["--threads 99", "1..=32"],
        ),
        case(
            "bad --mem-latency",
            &[("s.toml", &good)],
            "sim $D/s.toml --out $D/r --mem-latency 0",
            USAGE,
            &["--mem-latency 0"],
        ),
        case(
            "too large for the display",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --width 2000 --height 1000",
            USAGE,
            &["1024x768"],
        ),
        // Unclear messages.
        case(
            "camera 1e300 from its target",
            &[("s.toml", &far_camera)],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["overflows f64", "s.toml:"],
        ),
        case(
            "OBJ with a byte-order mark",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("\u{feff}{TRIANGLE_OBJ}f 1 2 4\n")),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.obj:5", "index 4 is out of range"],
        ),
        case(
            "OBJ with CR line endings",
            &[
                ("s.toml", &obj),
                ("m.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 9\r"),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.obj:4", "out of range"],
        ),
        case(
            "vertex with junk",
            &[("s.toml", &obj), ("m.obj", "v 0 0 0\nv 0 0 0 1 junk\n")],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.obj:2", "'junk' is not a number"],
        ),
        case(
            "texture index out of range",
            &[
                ("s.toml", &obj),
                (
                    "m.obj",
                    &TRIANGLE_OBJ.replace("f 1 2 3", "vt 0 0\nf 1/1 2/2 3/1"),
                ),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.obj:5", "texture coordinate index 2 is out of range"],
        ),
        case(
            "normal index out of range",
            &[
                ("s.toml", &obj),
                (
                    "m.obj",
                    &TRIANGLE_OBJ.replace("f 1 2 3", "f 1//7 2//7 3//7"),
                ),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.obj:4", "normal index 7 is out of range"],
        ),
        case(
            "broken MTL colour",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib m.mtl\n{TRIANGLE_OBJ}")),
                ("m.mtl", "newmtl a\nKd 1 0.5\n"),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.mtl:2", "`Kd` needs three numbers"],
        ),
        case(
            "broken MTL illum",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib m.mtl\n{TRIANGLE_OBJ}")),
                ("m.mtl", "newmtl a\nillum x\n"),
            ],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["m.mtl:2", "illum"],
        ),
        case(
            "missing mesh",
            &[("s.toml", &mesh_scene("nope.obj"))],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["s.toml:", "nope.obj", "does not exist"],
        ),
        case(
            "schema error cites the repository's docs",
            &[("s.toml", &format!("{GOOD}\nbogus = 1\n"))],
            "render $D/s.toml --out $D/o.png",
            USAGE,
            &["docs/ARCHITECTURE.md"],
        ),
    ]
}

fn make_files(dir: &Path, files: &[(String, String)]) {
    for (name, text) in files {
        if let Some(n) = name.strip_prefix("fifo:") {
            let ok = Command::new("mkfifo")
                .arg(dir.join(n))
                .status()
                .unwrap()
                .success();
            assert!(ok, "mkfifo {n}");
        } else if let Some(n) = name.strip_prefix("link:") {
            std::os::unix::fs::symlink(dir.join(text), dir.join(n)).unwrap();
        } else {
            std::fs::write(dir.join(name), text).unwrap();
        }
    }
}

/// Every path under `dir` with its size (symlinks as links), to see what a run changed.
fn snapshot(dir: &Path) -> BTreeSet<(PathBuf, u64)> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let meta = std::fs::symlink_metadata(e.path()).unwrap();
            if meta.is_dir() {
                stack.push(e.path());
            }
            out.insert((e.path(), if meta.is_file() { meta.len() } else { 0 }));
        }
    }
    out
}

/// Runs dynrt with a time limit; a hang fails the case instead of the whole suite.
fn run(args: &[String], limit: Duration) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_dynrt"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status.code(), reader.join().unwrap());
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return (None, reader.join().unwrap());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn every_bad_input_gets_its_exit_status_and_a_clear_message_and_leaves_nothing_behind() {
    let mut failures = Vec::new();
    for c in corpus() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        make_files(d, &c.files);
        let before = snapshot(d);
        let args: Vec<String> = c
            .args
            .iter()
            .map(|a| a.replace("$D", d.to_str().unwrap()))
            .collect();
        let (code, err) = run(&args, Duration::from_secs(60));
        let mut problems = Vec::new();
        match code {
            None => problems.push("hung (killed after 60 s)".to_string()),
            Some(101) => problems.push("panicked".to_string()),
            Some(k) if k != c.code => problems.push(format!("exit status {k}, want {}", c.code)),
            _ => {}
        }
        let lower = err.to_lowercase();
        for w in &c.words {
            if !lower.contains(&w.to_lowercase()) {
                problems.push(format!("message lacks `{w}`"));
            }
        }
        if err.contains("panicked") {
            problems.push("the message is a panic".into());
        }
        let after = snapshot(d);
        if after != before {
            let added: Vec<_> = after
                .difference(&before)
                .map(|(p, _)| p.display().to_string())
                .collect();
            problems.push(format!("the folder changed: {added:?}"));
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{}: {}\n    args {:?}\n    stderr: {}",
                c.name,
                problems.join("; "),
                c.args,
                err.trim()
            ));
        }
    }
    // The symlink's target and /dev/null are untouched (the snapshot sees only sizes).
    assert!(
        std::fs::symlink_metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_file()
            == false,
        "/dev/null must stay a device"
    );
    assert!(
        failures.is_empty(),
        "{} case(s) failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn a_good_scene_still_renders_beside_the_corpus() {
    // The checks must not refuse what is fine: the corpus's base scene renders.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.toml"), GOOD).unwrap();
    let out = dir.path().join("o.png");
    let (code, err) = run(
        &[
            "render".into(),
            dir.path().join("s.toml").display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ],
        Duration::from_secs(60),
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(out.is_file());
    assert!(
        !err.contains("warning: "),
        "a sensible scene gets no warning: {err}"
    );
}

/// Processes whose command line or working folder is under `dir`.
fn processes_under(dir: &Path) -> Vec<String> {
    let needle = dir.to_string_lossy().into_owned();
    let mut found = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !name.chars().all(|c| c.is_ascii_digit()) {
            continue;
        }
        let cmdline = std::fs::read(e.path().join("cmdline")).unwrap_or_default();
        let cmdline = String::from_utf8_lossy(&cmdline).replace('\0', " ");
        let cwd = std::fs::read_link(e.path().join("cwd")).unwrap_or_default();
        let state = std::fs::read_to_string(e.path().join("stat")).unwrap_or_default();
        // A zombie has ended; only its parent's wait is missing.
        let zombie = state
            .rsplit(')')
            .next()
            .is_some_and(|s| s.trim_start().starts_with('Z'));
        if !zombie && (cmdline.contains(&needle) || cwd.to_string_lossy().contains(&needle)) {
            found.push(format!("{name}: {cmdline}"));
        }
    }
    found
}

#[test]
fn sigterm_ends_the_simulators_dynrt_started_and_removes_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.toml"), GOOD).unwrap();
    let out = d.join("run");
    let mut child = Command::new(env!("CARGO_BIN_EXE_dynrt"))
        .args([
            "sim",
            d.join("s.toml").to_str().unwrap(),
            "--sim",
            "verilator",
            "--out",
            out.to_str().unwrap(),
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Wait until the Verilator build (verilator, make, g++) runs in the run's folder.
    let start = Instant::now();
    let pid = child.id().to_string();
    loop {
        let others: Vec<String> = processes_under(d)
            .into_iter()
            .filter(|p| !p.starts_with(&format!("{pid}:")))
            .collect();
        if !others.is_empty() {
            break;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "dynrt ended before any tool started"
        );
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no tool started within 120 s"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // SAFETY: kill takes plain integers.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let status = child.wait().unwrap();
    assert_eq!(
        status.code(),
        Some(128 + libc::SIGTERM),
        "dynrt exits as a shell reports SIGTERM"
    );
    // Its tools are gone at once: dynrt waited for their groups before it exited.
    let left = processes_under(d);
    assert!(left.is_empty(), "processes left behind: {left:?}");
    assert!(
        !out.exists(),
        "the interrupted run's output folder is removed"
    );
}
