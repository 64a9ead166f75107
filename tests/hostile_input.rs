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
    /// Files the run must create in the folder (a run that succeeds); nothing else may appear.
    creates: Vec<&'static str>,
}

impl Case {
    /// The run succeeds and writes exactly `names` into the folder.
    fn creates(mut self, names: &[&'static str]) -> Case {
        self.creates = names.to_vec();
        self
    }
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
        creates: Vec::new(),
    }
}

/// [`GOOD`] with its Cornell box replaced by the generator `generate` (a TOML inline table).
fn generated(generate: &str) -> String {
    GOOD.replace("{ kind = \"cornell_box\" }", generate)
}

/// [`GOOD`] with `extra` appended (tables after the object).
fn good_with(extra: &str) -> String {
    format!("{GOOD}{extra}")
}

fn corpus() -> Vec<Case> {
    let many_lights = format!(
        "{GOOD}{}",
        "[[lights]]\nposition = [0.0, 1.9, 0.8]\n".repeat(149)
    );
    let scaled = format!("{GOOD}[[instances]]\nobject = \"box\"\nscale = [1e39, 1e39, 1e39]\n");
    let far_camera = GOOD.replace("eye = [0.0, 1.0, 3.5]", "eye = [0.0, 1.0, 1e300]");
    let animated = format!(
        "{GOOD}[[instances]]\nobject = \"box\"\n[instances.animate]\nframes = 100000\ntranslate = [1.0, 0.0, 0.0]\n"
    );
    let good = GOOD.to_string();
    let no_objects = good_without_objects();
    let obj = mesh_scene("m.obj");
    // 2,000,000 faces over three vertices: 16 MB that the line scan refuses at face 131,073
    // (line 131,076), long before tobj would have parsed them all.
    let two_million_faces = format!(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\n{}",
        "f 1 2 3\n".repeat(2_000_000)
    );
    let huge_terrain = generated("{ kind = \"terrain\", size = 2048 }");
    let million_terrain = generated("{ kind = \"terrain\", size = 1024 }");
    let huge_field =
        good_with("[[fields]]\nobject = \"box\"\ncount_x = 1000\ncount_z = 1000\nspacing = 3.0\n");
    let two_fields = good_with(
        "[[fields]]\nobject = \"box\"\ncount_x = 200\ncount_z = 200\nspacing = 3.0\n\
         [[fields]]\nobject = \"box\"\ncount_x = 200\ncount_z = 200\nspacing = 3.0\n",
    );
    let translated = good_with("[[instances]]\nobject = \"box\"\ntranslate = [1e30, 0.0, 0.0]\n");
    let lights_90 = format!(
        "{GOOD}{}",
        "[[lights]]\nposition = [0.0, 1.9, 0.8]\n".repeat(89)
    );
    vec![
        // Panics.
        case(
            "no objects: render",
            &[("s.toml", &no_objects)],
            "render $D/s.toml --out $D/o",
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
            &["ROM holds", "150 lights", "use at most"],
        ),
        // Hangs and unbounded reads.
        case(
            "scene is a FIFO",
            &[("fifo:s.toml", "")],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["named pipe", "not a regular file"],
        ),
        case(
            "mesh is a FIFO",
            &[("s.toml", &obj), ("fifo:m.obj", "")],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["named pipe", "m.obj"],
        ),
        case(
            "mesh is /dev/zero",
            &[("s.toml", &mesh_scene("/dev/zero"))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["character device", "/dev/zero"],
        ),
        case(
            "mtllib is /dev/urandom",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib /dev/urandom\n{TRIANGLE_OBJ}")),
            ],
            "render $D/s.toml --out $D/o",
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
            "render $D/s.toml --out $D/o",
            USAGE,
            &["named pipe", "m.mtl"],
        ),
        case(
            "fp vectors are a FIFO",
            &[("fifo:v.txt", "")],
            "fp --op add --vectors $D/v.txt --out $D/r",
            USAGE,
            &["named pipe", "v.txt"],
        ),
        // Destroyed files.
        case(
            "--out is a device",
            &[("s.toml", &good)],
            "render $D/s.toml --out /dev/null",
            USAGE,
            &["/dev/null", "character device", "not a folder"],
        ),
        case(
            "--out is a symlink",
            &[
                ("s.toml", &good),
                ("keep.png", "precious"),
                ("link:o", "keep.png"),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["'", "is a regular file, not a folder"],
        ),
        case(
            "--hits is --out",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/o --hits $D/o/frame0.png",
            USAGE,
            &["--out and --hits are the same file"],
        ),
        case(
            "--out is the scene",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/s.toml",
            USAGE,
            &["s.toml", "not a folder"],
        ),
        // --out is the folder a command writes into, existing or new.
        case(
            "--out is a folder",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D",
            0,
            &[],
        )
        .creates(&["frame0.png"]),
        case(
            "--out ends in a slash",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/newdir/",
            0,
            &[],
        )
        .creates(&["newdir"]),
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
            &["is a regular file, not a folder"],
        ),
        // Silent garbage.
        case(
            "instance scale overflows the format",
            &[("s.toml", &scaled)],
            "render $D/s.toml --out $D/o",
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
            "a triangle cache of 96 sets",
            &[("s.toml", &good)],
            "sim $D/s.toml --out $D/r --tri-cache 96",
            USAGE,
            &[
                "--tri-cache 96",
                "power of two",
                "--tri-cache 128 --tri-ways 4",
            ],
        ),
        case(
            "a node cache of 512 sets of 2 ways",
            &[("s.toml", &good)],
            "timing $D/s.toml --out $D/r --node-cache 512 --node-ways 2",
            USAGE,
            &[
                "--node-cache 512 --node-ways 2",
                "at most 512 items",
                "--node-cache 256 --node-ways 2",
            ],
        ),
        case(
            "an instance cache of 256 sets of 4 ways",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --instance-cache 256 --instance-ways 4",
            USAGE,
            &[
                "--instance-cache 256 --instance-ways 4",
                "at most 512 items",
            ],
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
            "render $D/s.toml --out $D/o",
            USAGE,
            &["overflows f64", "s.toml:"],
        ),
        case(
            "OBJ with a byte-order mark",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("\u{feff}{TRIANGLE_OBJ}f 1 2 4\n")),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj:5", "index 4 is out of range"],
        ),
        case(
            "OBJ with CR line endings",
            &[
                ("s.toml", &obj),
                ("m.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 9\r"),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj:4", "out of range"],
        ),
        case(
            "vertex with junk",
            &[("s.toml", &obj), ("m.obj", "v 0 0 0\nv 0 0 0 1 junk\n")],
            "render $D/s.toml --out $D/o",
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
            "render $D/s.toml --out $D/o",
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
            "render $D/s.toml --out $D/o",
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
            "render $D/s.toml --out $D/o",
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
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.mtl:2", "illum"],
        ),
        case(
            "missing mesh",
            &[("s.toml", &mesh_scene("nope.obj"))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml:", "nope.obj", "does not exist"],
        ),
        case(
            "schema error cites the repository's docs",
            &[("s.toml", &format!("{GOOD}\nbogus = 1\n"))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["docs/ARCHITECTURE.md"],
        ),
        // Panics, in every verb that builds the processor or the golden model.
        case(
            "no objects: sim",
            &[("s.toml", &no_objects)],
            "sim $D/s.toml --out $D/r",
            USAGE,
            &["no [[objects]]"],
        ),
        case(
            "no objects: demo",
            &[("s.toml", &no_objects)],
            "demo $D/s.toml --out $D/r",
            USAGE,
            &["no [[objects]]"],
        ),
        case(
            "too many lights for the ROM: sim",
            &[("s.toml", &many_lights)],
            "sim $D/s.toml --out $D/r",
            USAGE,
            &["ROM holds 4096", "use at most"],
        ),
        case(
            "too many lights for the ROM: demo",
            &[("s.toml", &many_lights)],
            "demo $D/s.toml --out $D/r",
            USAGE,
            &["ROM holds 4096", "use at most"],
        ),
        case(
            "90 lights fit the ROM",
            &[("s.toml", &lights_90)],
            "rtl $D/s.toml --out $D/r",
            0,
            &[],
        )
        .creates(&["r"]),
        case(
            "render takes many lights",
            &[("s.toml", &many_lights)],
            "render $D/s.toml --out $D/o",
            0,
            &[],
        )
        .creates(&["o"]),
        // Hangs and unbounded reads.
        case(
            "hits file is a FIFO",
            &[("a.png", ""), ("fifo:h.csv", "")],
            "compare $D/a.png $D/a.png --hits $D/h.csv $D/h.csv",
            USAGE,
            &["named pipe", "h.csv"],
        ),
        case(
            "image to compare is a FIFO",
            &[("fifo:a.png", "")],
            "compare $D/a.png $D/a.png",
            USAGE,
            &["named pipe", "a.png"],
        ),
        case(
            "mesh is a directory",
            &[("s.toml", &mesh_scene("."))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml:12", "a directory"],
        ),
        case(
            "scene is binary garbage",
            &[("s.toml", "\u{1}\u{2}\u{0}\u{7f}garbage")],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml"],
        ),
        case(
            "scene is empty",
            &[("s.toml", "")],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml", "missing field `camera`"],
        ),
        case(
            "scene does not exist",
            &[],
            "render $D/nope.toml --out $D/o",
            USAGE,
            &["nope.toml", "does not exist"],
        ),
        case(
            "fp vector file is empty",
            &[("v.txt", "")],
            "fp --op add --vectors $D/v.txt --out $D/r",
            USAGE,
            &["v.txt", "no vectors"],
        ),
        // Destroyed files.
        case(
            "--hits under a file",
            &[("s.toml", &good), ("f", "x")],
            "render $D/s.toml --out $D/o --hits $D/f/h.csv",
            USAGE,
            &["--hits", "is a file, not a folder"],
        ),
        case(
            "--out name longer than a file name may be",
            &[("s.toml", &good)],
            &format!("render $D/s.toml --out $D/{}", "x".repeat(300)),
            USAGE,
            &["300 bytes", "longer than the 255"],
        ),
        case(
            "rtl --out under a file",
            &[("s.toml", &good), ("f", "x")],
            "rtl $D/s.toml --out $D/f/r",
            USAGE,
            &["f/r':", "is a file, not a folder"],
        ),
        case(
            "--out inside the scene's path",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/s.toml/o",
            USAGE,
            &["is a file, not a folder"],
        ),
        case(
            "--out is the scene by another spelling",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/./s.toml",
            USAGE,
            &["s.toml", "not a folder"],
        ),
        case(
            "fp --out is its vectors",
            &[("v.txt", "0 0\n")],
            "fp --op add --vectors $D/v.txt --out $D/v.txt",
            USAGE,
            &["v.txt", "not a folder"],
        ),
        case(
            "compare --diff is an input image",
            &[("a.png", ""), ("b.png", "")],
            "compare $D/a.png $D/b.png --diff $D/b.png",
            USAGE,
            &["image B and --diff are the same file"],
        ),
        case(
            "stress --out is a device",
            &[],
            "stress --out /dev/null --margins 0",
            USAGE,
            &["/dev/null", "character device"],
        ),
        case(
            "timing --out is a file",
            &[("t", "x")],
            "timing --unit add --out $D/t",
            USAGE,
            &["is a regular file, not a folder"],
        ),
        // Silent garbage: refused when a value does not fit the format, warned when the frame
        // is far from the reference.
        case(
            "instance scale named with its value",
            &[("s.toml", &scaled)],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["object-to-world matrix", "1.0000e39", "overflows"],
        ),
        case(
            "instance translation names its value",
            &[("s.toml", &translated)],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["instance 'box#0'", "1.0000e30", "overflows e7m16"],
        ),
        case(
            "a format too narrow for the scene: render",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/o --format e2m1",
            USAGE,
            &["camera", "e2m1"],
        ),
        case(
            "a format too narrow for the scene: rtl",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --format e2m1",
            USAGE,
            &["camera", "e2m1"],
        ),
        case(
            "a format too narrow for the scene: demo",
            &[("s.toml", &good)],
            "demo $D/s.toml --out $D/r --format e2m1",
            USAGE,
            &["camera", "e2m1"],
        ),
        case(
            "a golden frame far from the reference is warned about",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/o --format e4m3",
            0,
            &["warning", "differ from the f64 reference", "e4m3"],
        )
        .creates(&["o"]),
        case(
            "light colour beyond the format",
            &[(
                "s.toml",
                &good_with("[[lights]]\nposition = [0.0, 1.9, 0.8]\ncolor = [1e39, 1.0, 1.0]\n"),
            )],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["light 1", "1.0000e39", "overflows"],
        ),
        case(
            "NaN field of view",
            &[("s.toml", &GOOD.replace("fov_y = 40.0", "fov_y = nan"))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml:5", "fov_y = NaN", "not finite"],
        ),
        case(
            "infinite light position",
            &[(
                "s.toml",
                &good_with("[[lights]]\nposition = [inf, 0.0, 0.0]\n"),
            )],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["light 1", "not finite"],
        ),
        case(
            "NaN ambient",
            &[("s.toml", &good_with("[render]\nambient = nan\n"))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["ambient = NaN"],
        ),
        case(
            "negative box size",
            &[(
                "s.toml",
                &generated("{ kind = \"box\", size = [-1.0, 1.0, 1.0] }"),
            )],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml:12", "box size"],
        ),
        case(
            "zero scale",
            &[(
                "s.toml",
                &good_with("[[instances]]\nobject = \"box\"\nscale = [1.0, 0.0, 1.0]\n"),
            )],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["zero component"],
        ),
        case(
            "huge resolution in the scene",
            &[("s.toml", &GOOD.replace("width = 8", "width = 100000"))],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml:6", "100000x6", "1..=4096"],
        ),
        case(
            "zero resolution on the command line",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/o --width 0",
            USAGE,
            &["0x6", "1..=4096"],
        ),
        case(
            "a resolution whose frame buffer does not fit",
            &[("s.toml", &good)],
            "render $D/s.toml --out $D/o --width 4096 --height 4096",
            USAGE,
            &["frame", "--size WxH"],
        ),
        case(
            "negative field spacing",
            &[(
                "s.toml",
                &good_with(
                    "[[fields]]\nobject = \"box\"\ncount_x = 2\ncount_z = 2\nspacing = -1.0\n",
                ),
            )],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["field 'field0'", "spacing"],
        ),
        case(
            "hits with a negative distance",
            &[
                ("a.png", ""),
                ("h.csv", "x,y,instance,triangle,dist\n0,0,0,1,-5\n"),
            ],
            "compare $D/a.png $D/a.png --hits $D/h.csv $D/h.csv",
            USAGE,
            &["h.csv: line 2", "finite distance >= 0"],
        ),
        case(
            "hits beyond the largest frame",
            &[
                ("a.png", ""),
                (
                    "h.csv",
                    "x,y,instance,triangle,dist\n4000000000,0,-1,-1,inf\n",
                ),
            ],
            "compare $D/a.png $D/a.png --hits $D/h.csv $D/h.csv",
            USAGE,
            &["h.csv: line 2", "beyond the largest frame"],
        ),
        case(
            "hits with a missing pixel",
            &[
                ("a.png", ""),
                (
                    "h.csv",
                    "x,y,instance,triangle,dist\n0,0,-1,-1,inf\n1,1,-1,-1,inf\n",
                ),
            ],
            "compare $D/a.png $D/a.png --hits $D/h.csv $D/h.csv",
            USAGE,
            &["h.csv", "one row for every pixel"],
        ),
        case(
            "image that is not a PNG",
            &[("a.png", "not a png at all")],
            "compare $D/a.png $D/a.png",
            USAGE,
            &["a.png", "cannot be decoded"],
        ),
        // Runaway output.
        case(
            "100,000 animated frames: sim",
            &[("s.toml", &animated)],
            "sim $D/s.toml --out $D/r",
            USAGE,
            &["100000 frames", "--frames N"],
        ),
        case(
            "--frames beyond the scene",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --frames 5",
            USAGE,
            &["--frames 5", "1 frame(s)"],
        ),
        // Partial output: refused before the output folder exists.
        case(
            "bad --threads: sim",
            &[("s.toml", &good)],
            "sim $D/s.toml --out $D/r --threads 0",
            USAGE,
            &["--threads 0", "1..=32"],
        ),
        case(
            "bad --mem-latency: rtl",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --mem-latency 99",
            USAGE,
            &["--mem-latency 99", "1..=6"],
        ),
        case(
            "bad --format: rtl",
            &[("s.toml", &good)],
            "rtl $D/s.toml --out $D/r --format e99m99",
            USAGE,
            &["e99m99", "2..=8"],
        ),
        case(
            "bad --format: demo",
            &[("s.toml", &good)],
            "demo $D/s.toml --out $D/r --format e1m0",
            USAGE,
            &["e1m0"],
        ),
        // Unclear messages.
        case(
            "MTL with a negative colour names its line",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib m.mtl\n{TRIANGLE_OBJ}")),
                ("m.mtl", "newmtl a\nKd -1 0.5 0.5\n"),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.mtl:2", "negative"],
        ),
        case(
            "missing mtllib",
            &[
                ("s.toml", &obj),
                ("m.obj", &format!("mtllib nope.mtl\n{TRIANGLE_OBJ}")),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["nope.mtl", "does not exist"],
        ),
        case(
            "OBJ with no faces",
            &[("s.toml", &obj), ("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj", "no usable triangles"],
        ),
        case(
            "OBJ of control characters",
            &[("s.toml", &obj), ("m.obj", "v 0 0 0\n\u{0}\u{1}\u{7f}")],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj"],
        ),
        case(
            "OBJ vertex beyond f64",
            &[
                ("s.toml", &obj),
                ("m.obj", &TRIANGLE_OBJ.replace("v 1 0 0", "v 1e309 0 0")),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj:2", "1e309", "not finite"],
        ),
        case(
            "OBJ face index zero",
            &[
                ("s.toml", &obj),
                ("m.obj", &TRIANGLE_OBJ.replace("f 1 2 3", "f 0 1 2")),
            ],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj:4", "index 0 is out of range"],
        ),
        case(
            "a unicode object name is fine",
            &[(
                "s.toml",
                &GOOD.replace("name = \"box\"", "name = \"bøx ✓\""),
            )],
            "render $D/s.toml --out $D/o",
            0,
            &[],
        )
        .creates(&["o"]),
        // Late failure on big inputs: refused from counts, before the triangles are built.
        case(
            "2,000,000-face OBJ",
            &[("s.toml", &obj), ("m.obj", &two_million_faces)],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["m.obj:131076", "131072", "triangles"],
        ),
        case(
            "2048x2048 terrain",
            &[("s.toml", &huge_terrain)],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["s.toml:12", "8388608 triangles", "131072"],
        ),
        case(
            "1024x1024 terrain",
            &[("s.toml", &million_terrain)],
            "rtl $D/s.toml --out $D/r",
            USAGE,
            &["2097152 triangles", "131072"],
        ),
        case(
            "a field of a million instances",
            &[("s.toml", &huge_field)],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["field 'field0'", "43690"],
        ),
        case(
            "two fields that do not fit together",
            &[("s.toml", &two_fields)],
            "render $D/s.toml --out $D/o",
            USAGE,
            &["field 'field1'", "80000 instances", "43690"],
        ),
    ]
}

/// A message that says the same thing twice in a row ("writing X: writing X: ...").
fn repeats_itself(message: &str) -> Option<String> {
    let parts: Vec<&str> = message.split(": ").collect();
    parts
        .windows(2)
        .find(|w| w[0].trim() == w[1].trim() && !w[0].trim().is_empty())
        .map(|w| w[0].to_string())
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
        if let Some(part) = repeats_itself(&err) {
            problems.push(format!("the message repeats `{part}`"));
        }
        // Errors cite the repository's own documents, never a path outside it.
        if err.contains("../") || err.contains(".pdf") {
            problems.push("the message cites a file outside the repository".into());
        }
        let after = snapshot(d);
        let created: BTreeSet<PathBuf> = c.creates.iter().map(|n| d.join(n)).collect();
        let changed: Vec<String> = after
            .symmetric_difference(&before)
            .map(|(p, _)| p)
            .filter(|p| !created.iter().any(|c| p.starts_with(c)))
            .map(|p| p.display().to_string())
            .collect();
        if !changed.is_empty() {
            problems.push(format!("the folder changed: {changed:?}"));
        }
        for name in &created {
            if !name.exists() {
                problems.push(format!("{} was not written", name.display()));
            }
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
    let out = dir.path().join("o");
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
    assert!(out.join("frame0.png").is_file());
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
