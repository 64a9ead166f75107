//! The processor as a component for other people's projects: a FuseSoC CAPI2 core file and a
//! plain `files.f` (docs/ARCHITECTURE.md, "Integrating the processor"). Text only; running
//! FuseSoC is the user's (and the tests') business.
//!
//! Contract:
//! - [`files_f`]: the Verilog sources, one path a line relative to the output folder, the
//!   processor first and the testbench last (`iverilog -g2012 -c files.f`,
//!   `verilator --binary --timing -f files.f`).
//! - [`fusesoc_core`]: a CAPI2 core named `dynrt:processor:<scene>:<version>` with the filesets
//!   `rtl` (the processor), `tb` (the testbench, SystemVerilog: it takes its folders as
//!   strings) and `mem` (every memory image, copied into the simulator's work folder under
//!   `mem/`); the targets `default` (the processor alone, top `dynrt_processor`, for synthesis
//!   in a user's own core), `sim_icarus` and `sim_verilator` (top `tb`); and the testbench's
//!   plusargs `mem_dir` and `out_dir` as parameters. A simulation target writes
//!   `frame<k>.hex` and `frame<k>.stats` into its work folder unless `--out_dir` says where.
//! - [`cocotb_files`]: `cocotb/test_dynrt_processor.py` (a cocotb test that is the board in
//!   Python: SRAM banks with the testbench's read latency, frame-buffer writes, the start/done
//!   handshake and the frames' memory updates; it checks every frame against `golden<k>.hex`),
//!   `cocotb/run.py` (cocotb's Python runner on Icarus) and `cocotb/processor.json` (what the
//!   test needs to know: latency, bank sizes and files, updates, frame buffer, pixels, cycle
//!   limit).

use std::fmt::Write as _;

use crate::emit::memory_images::bank_file_name;
use crate::emit::processor::TestbenchFrames;
use crate::provenance::GeneratedBy;

/// The cocotb test and its runner (Python, kept as files in `src/emit/cocotb/`).
const COCOTB_TEST: &str = include_str!("cocotb/test_dynrt_processor.py");
const COCOTB_RUN: &str = include_str!("cocotb/run.py");

/// The cocotb folder's files, `(name, text)`: the test, the runner and `processor.json`.
pub fn cocotb_files(
    mem_latency: u32,
    frames: &TestbenchFrames,
    generated_by: &GeneratedBy,
) -> Vec<(&'static str, String)> {
    let config = serde_json::json!({
        "generated_by": generated_by.lines(),
        "mem_latency": mem_latency,
        "bank_words": frames.bank_words,
        "bank_files": (0..frames.bank_words.len()).map(bank_file_name).collect::<Vec<_>>(),
        "frames": std::iter::once(&Vec::new())
            .chain(&frames.updates)
            .map(|u| serde_json::json!({ "updates": u }))
            .collect::<Vec<_>>(),
        "frame_buffer": frames.frame_buffer,
        "pixels": frames.pixels,
        "cycle_limit": frames.cycle_limit,
    });
    let header = generated_by.comment("#");
    vec![
        ("test_dynrt_processor.py", format!("{header}{COCOTB_TEST}")),
        ("run.py", format!("{header}{COCOTB_RUN}")),
        ("processor.json", format!("{config:#}\n")),
    ]
}

/// The core file's name inside the output folder.
pub const CORE_FILE: &str = "dynrt_processor.core";
/// The file list's name inside the output folder.
pub const FILES_F: &str = "files.f";

/// `files.f`: `sources` one a line (paths relative to the output folder).
pub fn files_f(sources: &[String], generated_by: &GeneratedBy) -> String {
    let mut f = generated_by.comment("//");
    for s in sources {
        let _ = writeln!(f, "{s}");
    }
    f
}

/// The part of a VLNV name a scene's name may give: letters, digits, `_` and `-`; anything
/// else becomes `_`.
pub fn vlnv_name(scene_name: &str) -> String {
    let n: String = scene_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if n.is_empty() {
        "scene".into()
    } else {
        n
    }
}

/// What the core describes.
pub struct CoreFiles<'a> {
    pub scene_name: &'a str,
    /// One line for the core's description.
    pub description: &'a str,
    pub rtl: &'a str,
    pub testbench: &'a str,
    /// Memory images, relative to the output folder (`mem/...`).
    pub mem: &'a [String],
}

/// A string quoted for YAML (double quotes, `\` and `"` escaped).
fn yaml_str(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// The FuseSoC CAPI2 core file (see the module doc).
pub fn fusesoc_core(c: &CoreFiles, generated_by: &GeneratedBy) -> String {
    let mut y = String::from("CAPI=2:\n");
    y.push_str(&generated_by.comment("#"));
    let _ = writeln!(
        y,
        "name: dynrt:processor:{}:{}\ndescription: {}\n",
        vlnv_name(c.scene_name),
        generated_by.version,
        yaml_str(c.description)
    );
    let _ = writeln!(
        y,
        "filesets:\n  rtl:\n    files:\n      - {}\n    file_type: verilogSource\n  tb:\n    files:\n      - {}\n    file_type: systemVerilogSource\n  mem:\n    files:",
        yaml_str(c.rtl),
        yaml_str(c.testbench)
    );
    for m in c.mem {
        let _ = writeln!(y, "      - {}: {{copyto: {}}}", yaml_str(m), yaml_str(m));
    }
    let _ = writeln!(y, "    file_type: user\n");
    let _ = writeln!(
        y,
        "parameters:\n  mem_dir:\n    datatype: str\n    paramtype: plusarg\n    default: mem\n    description: Folder of the memory images (the mem fileset is copied to mem/ in the work folder)\n  out_dir:\n    datatype: str\n    paramtype: plusarg\n    default: .\n    description: Folder the testbench writes frame<k>.hex and frame<k>.stats into\n"
    );
    let _ = writeln!(
        y,
        "targets:\n  default:\n    filesets: [rtl]\n    toplevel: dynrt_processor\n  sim_icarus:\n    default_tool: icarus\n    filesets: [rtl, tb, mem]\n    parameters: [mem_dir, out_dir]\n    toplevel: tb\n    tools:\n      icarus:\n        iverilog_options: [-g2012]\n  sim_verilator:\n    default_tool: verilator\n    filesets: [rtl, tb, mem]\n    parameters: [mem_dir, out_dir]\n    toplevel: tb\n    tools:\n      verilator:\n        mode: binary\n        verilator_options: [--timing, -Wno-fatal, --x-assign, fast]"
    );
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_core_lists_every_file_and_both_simulation_targets() {
        let mem = vec![
            "mem/bank0_nodes.hex".to_string(),
            "mem/frame1_bank4_instances.hex".to_string(),
        ];
        let y = fusesoc_core(
            &CoreFiles {
                scene_name: "my scene.v2",
                description: "a \"quoted\" scene",
                rtl: "rtl/dynrt_processor.v",
                testbench: "testbench/tb.v",
                mem: &mem,
            },
            &GeneratedBy::library(),
        );
        assert!(y.starts_with("CAPI=2:\n# generated by dynrt"), "{y}");
        assert!(
            y.contains(&format!(
                "name: dynrt:processor:my_scene_v2:{}\n",
                crate::provenance::VERSION
            )),
            "{y}"
        );
        assert!(y.contains("description: \"a \\\"quoted\\\" scene\""), "{y}");
        for m in &mem {
            assert!(
                y.contains(&format!("- \"{m}\": {{copyto: \"{m}\"}}")),
                "{m}: {y}"
            );
        }
        assert!(y.contains("  sim_icarus:\n    default_tool: icarus"), "{y}");
        assert!(
            y.contains("  sim_verilator:\n    default_tool: verilator"),
            "{y}"
        );
        assert!(y.contains("        mode: binary"), "{y}");
        let f = files_f(
            &["rtl/a.v".into(), "testbench/tb.v".into()],
            &GeneratedBy::library(),
        );
        assert!(f.ends_with("\nrtl/a.v\ntestbench/tb.v\n"), "{f}");
    }
}
