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
//! - [`ports_md`]: `PORTS.md`, every top port with its direction, width and meaning (from the
//!   list the top module is made from) and the contracts: clocks, start/done, the SRAM read
//!   latency, frame-buffer writes, and how a host loads the banks ([`bank_bin`]: raw binary,
//!   `bin/bank<k>_<name>.bin`).
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

/// What each top port of the processor does, by its board name; `None` for a port this table
/// does not know (a test requires every port of the generated processor to be known, so a new
/// port is documented when it is added).
pub fn port_meaning(name: &str) -> Option<&'static str> {
    Some(match name {
        "clock" => "core clock; every other core port is synchronous to its rising edge",
        "start" => "one-clock pulse: render a frame from the memory as it is now",
        "done" => "high from the end of a frame until the next `start`",
        "cycles" => "clocks of the last (or running) frame",
        "instructions" => "instructions the engine retired in the frame",
        "transform_busy" => "clocks in which the TransformUnit took a triangle test's input",
        "raygen_busy" => "clocks in which ray generation's requests took the TransformUnit",
        "instance_busy" => "clocks in which instance entry's requests took the TransformUnit",
        "shading_busy" => {
            "clocks in which shading's requests (world normals) took the TransformUnit"
        }
        "intersect_busy" => "clocks in which the IntersectUnit took an input",
        "tri_cache_hits" => "triangle tests whose words came from the triangle cache",
        "tri_cache_misses" => "triangle tests whose words came from banks 2 and 3",
        "node_cache_hits" => "object-tree nodes the traversal unit took from the node cache",
        "node_cache_misses" => "object-tree nodes the traversal unit read from bank 0",
        "instance_cache_hits" => "instance records instance entry took from the instance cache",
        "instance_cache_misses" => "instance records instance entry read from bank 4",
        "traversal_busy" => "clocks in which the traversal unit started a node decision",
        "mem_read" => "read request on the shared port (banks 1, 4, 5)",
        "mem_bank" => "bank of the shared port's request (1 lists, 4 instances, 5 frame)",
        "mem_addr" => "word address of the shared port's request",
        "mem_rdata" => "the word requested `mem_latency` clocks earlier on the shared port",
        "bank0_read" | "bank2_read" | "bank3_read" => "read request on the bank's own port",
        "bank0_addr" | "bank2_addr" | "bank3_addr" => "word address of the bank's request",
        "bank0_rdata" | "bank2_rdata" | "bank3_rdata" => {
            "the word requested `mem_latency` clocks earlier on the bank's port"
        }
        "fb_write" => "write one pixel word into bank 5 this clock",
        "fb_addr" => "word address in bank 5 (frame buffer base + y * width + x)",
        "fb_data" => "pixel word `0x00RRGGBB`",
        "vga_clock" => "display pixel clock (its own clock domain)",
        "vga_reset" => "display reset, synchronous to `vga_clock`, active high",
        "vga_fb_addr" => "the display's read address in bank 5",
        "vga_fb_data" => "the word at `vga_fb_addr`, one `vga_clock` later",
        "vga_hsync" | "vga_vsync" => "monitor sync (active low)",
        "vga_rgb" => "pixel colour `RRGGBB` to the DAC",
        "vga_frame_start" => "one `vga_clock` pulse at the first pixel of a displayed frame",
        _ => return None,
    })
}

/// `PORTS.md`: every top port (from the same list the Verilog's top module is made from) and
/// the contracts a board or testbench must keep.
pub fn ports_md(
    ports: &[crate::hw::processor::TopPort],
    mem_latency: u32,
    frames: &TestbenchFrames,
    generated_by: &GeneratedBy,
) -> String {
    let mut m = String::new();
    for l in generated_by.lines() {
        let _ = writeln!(m, "<!-- {l} -->");
    }
    let _ = writeln!(
        m,
        "# dynrt_processor: ports and contracts\n\n\
         | port | direction | bits | what |\n|---|---|---|---|"
    );
    for p in ports {
        let _ = writeln!(
            m,
            "| `{}` | {} | {} | {} |",
            p.name,
            if p.output { "out" } else { "in" },
            p.bits,
            port_meaning(&p.name).unwrap_or("(undocumented)")
        );
    }
    let banks: Vec<String> = frames
        .bank_words
        .iter()
        .enumerate()
        .map(|(b, w)| format!("{} ({w} words)", bank_file_name(b)))
        .collect();
    let _ = writeln!(
        m,
        "\n## Clocks\n\n`clock` drives the core (the UCF asks for 90 MHz), `vga_clock` the display \
         (the VGA mode's pixel clock); the two are unrelated, and only bank 5 is shared between \
         them (the display reads it on its own port).\n\n\
         ## Start and done\n\nLoad the memory, then pulse `start` high for one `clock`. The \
         processor renders the frame and raises `done`, which stays high until the next \
         `start`; `cycles`, `instructions` and the `*_busy` counters then hold the frame's \
         figures. Between frames of an animation, write the frame's update words (below) \
         while `done` is high, then pulse `start` again.\n\n\
         ## SRAM reads (read latency {mem_latency})\n\nFour read ports: `mem_*` shared by banks \
         1, 4 and 5 (`mem_bank` says which), and `bank0_*`, `bank2_*`, `bank3_*`. Each port may \
         request one word every clock (24-bit word addresses); the board must return the word \
         on `*_rdata` exactly {mem_latency} clocks after the clock in which the address was \
         presented, whether or not `*_read` is high (the processor ignores words it did not \
         ask for), and never stall. The processor has no wait input: a memory that cannot keep \
         this latency needs the processor generated for its latency (`--mem-latency`).\n\n\
         ## Frame-buffer writes\n\nWhile `fb_write` is high, the board writes `fb_data` to \
         bank 5 at `fb_addr`: one pixel word `0x00RRGGBB` a clock. The frame buffer starts at \
         word {} of bank 5 and holds {} pixels in raster order (row 0 at the top). Reads of \
         bank 5 on the `mem_*` port after a write must see the written word.\n\n\
         ## Loading the memory on a board\n\n`mem/` holds each bank as a `$readmemh` image \
         (`.hex`, for simulators), `bin/` the same words as raw binary (`.bin`: 32-bit words, \
         little endian, from word address 0). A host copies each `.bin` into its bank (for \
         example over PCI into the SSRAM banks, as the paper's board does) before the first \
         `start`. Banks: {}. An animated scene's later frames are \
         `mem/frame<k>_bank<b>_<name>.hex` updates: `@address` records followed by the words \
         to overwrite.\n",
        frames.frame_buffer,
        frames.pixels,
        banks.join(", ")
    );
    m
}

/// A bank's words as raw binary: 32-bit little-endian words from address 0.
pub fn bank_bin(words: &[u32]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}
