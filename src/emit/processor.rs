//! Verilog of the whole ray tracing processor for one scene, and its frame testbench.
//!
//! [`processor_rtl`] turns a scene's [`Program`] into one self-contained Verilog file: the
//! rust-hdl block [`Processor`] (the engine and the display), its top module renamed
//! `dynrt_processor` (see `verilog_tidy`), with the ports `Processor::ports` lists:
//! `clock, start, done, cycles[31:0], instructions[31:0], mem_read, mem_bank[2:0],
//! mem_addr[23:0], mem_rdata[31:0], fb_write, fb_addr[23:0], fb_data[31:0]` (banks 1, 4, 5),
//! `bank0_read, bank0_addr[23:0], bank0_rdata[31:0]` (the kd nodes, read by the traversal
//! unit) and the same for banks 2 and 3 (the triangles, which the triangle tester reads in
//! parallel), `transform_busy[31:0], intersect_busy[31:0], traversal_busy[31:0],
//! raygen_busy[31:0], instance_busy[31:0], shading_busy[31:0], tri_cache_hits[31:0],
//! tri_cache_misses[31:0], node_cache_hits[31:0], node_cache_misses[31:0],
//! instance_cache_hits[31:0], instance_cache_misses[31:0]` (activity counters
//! of the frame), and the `vga_`
//! display ports.
//!
//! [`processor_testbench`] writes module `tb` for Icarus (`iverilog -g2012`) and Verilator 5
//! (`--binary --timing`): six SRAM banks loaded with `$readmemh` from `mem/` (the layout of
//! frame 0; `+mem_dir=DIR` names another folder, so the testbench runs from any folder), one
//! read per clock on each port (banks 0, 2 and 3 have their own), a read latency
//! of `mem_latency` clocks, and per frame: the frame's update files
//! (only the words that changed), a start pulse, a wait for `done` or the cycle limit (then
//! `TIMEOUT` and a non-zero exit), and the frame buffer written to `frame<k>.hex` (one
//! `RRGGBB` word a line) with `cycles instructions transform_busy intersect_busy
//! traversal_busy raygen_busy instance_busy shading_busy ready_clocks asleep_clocks reads0 ..
//! reads5 tri_cache_hits tri_cache_misses node_cache_hits node_cache_misses
//! instance_cache_hits instance_cache_misses` (`ready_clocks`, `asleep_clocks` are thread-clocks: the bits of the scheduler's
//! `ready` and `asleep` masks added up every clock; `reads<b>` the words read from bank b) in
//! `frame<k>.stats`, in the current
//! folder or
//! `+out_dir=DIR`. Both files start with the [`GeneratedBy`] header.

use std::fmt::Write as _;

use anyhow::Result;
use rust_hdl::prelude::*;

use super::verilog_tidy::{merge_identical_modules, rename_rust_hdl_names};
use crate::fp::Format;
pub use crate::hw::processor::ProcessorParams;
use crate::hw::processor::{Processor, TopPort};
use crate::hw::program::Program;
use crate::hw::vga::VgaMode;
use crate::layout::BANK_NAMES;
use crate::provenance::GeneratedBy;

/// The name of the processor's top module.
pub const PROCESSOR_TOP: &str = "dynrt_processor";

/// Dispatches to `func::<W, E, M, S, S1, X2, T, P, DX, DL>(args)` for the engine: `DX =
/// long_latency - ENGINE_LATENCY = M - 6` (the long line of `fdiv` and `fsqrt`) and `DL =
/// div_latency(M)` (the divider of the IntersectUnit and the traversal unit).
#[macro_export]
macro_rules! dispatch_engine_format {
    (@arms $fmt:expr, $func:ident, $args:tt ; $(($e:literal, $m:literal))*) => {{
        let format: $crate::fp::Format = $fmt;
        match (format.exp_bits, format.man_bits) {
            $(
                ($e, $m) => Ok($func::<
                    { 1 + $e + $m }, $e, $m, { $m + 1 }, { $m + 2 }, { $e + 2 }, { $m + 5 },
                    { 2 * ($m + 1) },
                    {
                        ($crate::hw::engine::long_latency($m)
                            - $crate::hw::engine::ENGINE_LATENCY) as usize
                    },
                    { $crate::hw::fp::div::div_latency($m) as usize },
                >$args),
            )*
            _ => Err($crate::hw::fp::UnsupportedFormat(format)),
        }
    }};
    ($fmt:expr, $func:ident ( $($arg:expr),* $(,)? )) => {
        $crate::fp_format_table!(dispatch_engine_format ! { @arms $fmt, $func, ($($arg),*) })
    };
}

/// The processor's rust-hdl Verilog (top module `top`) and its top ports.
#[allow(clippy::too_many_arguments)]
fn processor_verilog<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DX: usize,
    const DL: usize,
>(
    program: &Program,
    params: ProcessorParams,
    mode: &VgaMode,
) -> Result<(String, Vec<TopPort>)> {
    let mut uut = Processor::<W, E, M, S, S1, X2, T, P, DX, DL>::new(program, &params, mode)?;
    uut.connect_all();
    Ok((generate_verilog(&uut), uut.ports()))
}

/// Runs `f` on a thread with a 256 MB stack: rust-hdl builds and prints the design by
/// recursion over its blocks, which overflows the 2 MB stack of a test thread for the whole
/// processor. A panic in `f` propagates.
fn on_large_stack<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .stack_size(256 << 20)
            .spawn_scoped(scope, f)
            .expect("cannot start the Verilog generation thread")
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

/// The video mode the processor's display uses for a `width x height` frame: 640x480 at 60 Hz
/// when the frame fits, else 1024x768.
pub fn display_mode(width: u32, height: u32) -> Result<VgaMode> {
    for mode in [VgaMode::VGA_640X480_60, VgaMode::XGA_1024X768_60] {
        if mode.fit(width, height).is_ok() {
            return Ok(mode);
        }
    }
    anyhow::bail!(
        "a {width}x{height} frame is larger than the largest VGA mode the display drives          (1024x768); render at most 1024x768"
    )
}

/// The processor's Verilog and the ports of its top module.
#[derive(Clone, Debug)]
pub struct ProcessorRtl {
    /// One file, top module [`PROCESSOR_TOP`].
    pub verilog: String,
    pub ports: Vec<TopPort>,
}

/// rust-hdl names a top port of a bundle `<bundle>$<port>`; the board's name for it is
/// `<bundle>_<port>` (`mem$read` is `mem_read`). Renames those identifiers everywhere (a
/// child's port of the same bundle and port names becomes the same name, consistently), after
/// checking that no module already has an identifier of the new name beside the old one.
fn name_top_ports(verilog: &str, ports: &[TopPort]) -> Result<String> {
    let renames: std::collections::HashMap<String, String> = ports
        .iter()
        .filter(|p| p.hdl_name != p.name)
        .map(|p| (p.hdl_name.clone(), p.name.clone()))
        .collect();
    for module in verilog.split("\nmodule ") {
        let names = own_identifiers(module);
        for (hdl, clean) in &renames {
            anyhow::ensure!(
                !(names.contains(hdl.as_str()) && names.contains(clean.as_str())),
                "module {} of the processor has both `{hdl}` and `{clean}`, and the top port \
                 `{hdl}` is to be named `{clean}`: rename that signal",
                module.split(['(', ' ', ';']).next().unwrap_or_default()
            );
        }
    }
    Ok(super::verilog_tidy::map_identifiers(verilog, |w| {
        renames.get(w).cloned()
    }))
}

/// The identifiers a module declares or uses, without the child ports named in its
/// instantiations (`.port(...)`: those are the child's names, not this module's).
fn own_identifiers(module: &str) -> std::collections::HashSet<&str> {
    super::verilog_tidy::identifiers(module)
        .filter(|&(at, _)| !module[..at].ends_with('.'))
        .map(|(_, word)| word)
        .collect()
}

/// The processor's Verilog (one file, top module [`PROCESSOR_TOP`]).
pub fn processor_rtl(
    program: &Program,
    params: ProcessorParams,
    scene_name: &str,
    generated_by: &GeneratedBy,
) -> Result<ProcessorRtl> {
    let f: Format = program.config.format;
    anyhow::ensure!(
        (1..=32).contains(&params.threads),
        "--threads must be 1..=32, not {}",
        params.threads
    );
    anyhow::ensure!(
        (1..=crate::hw::engine::MAX_MEM_LATENCY).contains(&params.mem_latency),
        "--mem-latency must be 1..={}, not {}",
        crate::hw::engine::MAX_MEM_LATENCY,
        params.mem_latency
    );
    anyhow::ensure!(
        program.scratch.words <= crate::hw::engine::SCRATCH_WORDS,
        "the scene needs {} scratch words per thread (kd stack and mirror chain), the engine has {}: \
         use shallower trees or a smaller reflection_depth",
        program.scratch.words,
        crate::hw::engine::SCRATCH_WORDS
    );
    let mode = display_mode(program.config.width, program.config.height)?;
    let (verilog, ports) =
        on_large_stack(|| dispatch_engine_format!(f, processor_verilog(program, params, &mode)))??;
    let verilog = merge_identical_modules(&rename_rust_hdl_names(
        &name_top_ports(&verilog, &ports)?,
        PROCESSOR_TOP,
    ));
    let c = &program.config;
    let mut header = generated_by.comment("//");
    writeln!(
        header,
        "// {PROCESSOR_TOP}: dynrt ray tracing processor for scene `{scene_name}`.\n// Format {f}, {}x{} pixels, {} threads, SRAM read latency {} \
         clocks, {} instructions of microprogram.",
        c.width,
        c.height,
        params.threads,
        params.mem_latency,
        program.code.len()
    )?;
    for l in &program.left_out {
        writeln!(header, "// Left out: {l}.")?;
    }
    writeln!(
        header,
        "// Display: {}x{} at {:.2} MHz pixel clock (vga_clock), frame buffer shown from word {}.",
        mode.h_visible,
        mode.v_visible,
        mode.pixel_clock_hz as f64 / 1e6,
        c.frame_buffer
    )?;
    Ok(ProcessorRtl {
        verilog: format!(
            "{header}\n/* verilator lint_off WIDTH */\n/* verilator lint_off DECLFILENAME */\n\
             /* verilator lint_off UNUSEDSIGNAL */\n{verilog}\n/* verilator lint_on UNUSEDSIGNAL */\n\
             /* verilator lint_on DECLFILENAME */\n/* verilator lint_on WIDTH */\n"
        ),
        ports,
    })
}

/// What the testbench needs to know about the frames it runs.
#[derive(Clone, Debug)]
pub struct TestbenchFrames {
    /// Words per bank (the largest over all frames).
    pub bank_words: [usize; 6],
    /// For frames 1.., the `(bank, file name)` update files to load before the frame.
    pub updates: Vec<Vec<(usize, String)>>,
    pub frame_buffer: u32,
    pub pixels: u32,
    pub cycle_limit: u64,
    /// The display's video mode.
    pub vga: VgaMode,
}

/// The top ports the testbench drives itself, with their initial values; it reads every other
/// port through a wire of the port's name.
const TESTBENCH_DRIVES: [(&str, &str); 5] = [
    ("clock", "1'b0"),
    ("start", "1'b0"),
    ("vga_clock", "1'b0"),
    ("vga_reset", "1'b1"),
    ("vga_fb_data", "32'd0"),
];

/// The ports the testbench's memory model and frame loop use by name.
const TESTBENCH_USES: [&str; 32] = [
    "done",
    "cycles",
    "instructions",
    "mem_read",
    "mem_bank",
    "mem_addr",
    "mem_rdata",
    "fb_write",
    "fb_addr",
    "fb_data",
    "bank0_read",
    "bank0_addr",
    "bank0_rdata",
    "bank2_read",
    "bank2_addr",
    "bank2_rdata",
    "bank3_read",
    "bank3_addr",
    "bank3_rdata",
    "transform_busy",
    "intersect_busy",
    "traversal_busy",
    "raygen_busy",
    "instance_busy",
    "shading_busy",
    "tri_cache_hits",
    "tri_cache_misses",
    "node_cache_hits",
    "node_cache_misses",
    "instance_cache_hits",
    "instance_cache_misses",
    "vga_fb_addr",
];

/// The define under which the frame testbench closes a Verilator trace at the end of its
/// window; give it to a Verilator built with `--trace` or `--trace-fst`.
pub const TRACE_DEFINE: &str = "DYNRT_TRACE";

/// The scheduler's masks of the threads waiting for an issue slot and of those asleep in a
/// coprocessor wait (`hw::engine::Scheduler`'s `ready` and `asleep`) as the testbench names
/// them below `dut`: it adds up their bits every clock (thread-clocks, `frame<k>.stats`).
const SCHEDULER_READY: &str = "engine.scheduler.ready__q";
const SCHEDULER_ASLEEP: &str = "engine.scheduler.asleep__q";

/// The testbench's waveform window. Icarus ends it with `$dumpoff`; Verilator 5.006 ignores
/// `$dumpoff`, so the testbench closes the model's trace itself (`_traceDumpClose`, the call
/// Verilator's own `$finish` makes), which exists only in a model built with tracing, hence
/// the define.
const TRACE_WINDOW: &str =
    "  // +trace=FILE: every signal's waveforms into FILE from the clock +trace_start=C (default 0)
  // to the clock +trace_end=C (default: the end of the run); clocks count from the start of
  // the run, frame after frame, and clock c begins at 10c - 5 ns. Icarus writes VCD, FST with
  // vvp's -fst; Verilator the format it was built with (--trace or --trace-fst, and
  // -D{define}).
  string trace_file;
  reg [63:0] trace_start = 0, trace_end = 0;
  initial if ($value$plusargs(\"trace=%s\", trace_file)) begin
    if (!$value$plusargs(\"trace_start=%d\", trace_start)) trace_start = 0;
    if (!$value$plusargs(\"trace_end=%d\", trace_end)) trace_end = 0;
`ifdef VERILATOR
`ifndef {define}
    $display(\"+trace: this Verilator model was built without --trace; no waveforms\");
`endif
`endif
    wait (clocks == trace_start);
    $dumpfile(trace_file);
    $dumpvars(0, tb);
    if (trace_end != 0) begin
      wait (clocks == trace_end);
`ifdef VERILATOR
`ifdef {define}
      $c(\"vlSymsp->_traceDumpClose();\");
`endif
`else
      $dumpoff;
      $dumpflush;
`endif
    end
  end
";

/// The frame testbench (module `tb`) of a processor with the top ports `ports`
/// ([`ProcessorRtl::ports`]): the device under test is instantiated from that list, so a port
/// the testbench needs and the processor lacks is an error here, not in a simulator.
pub fn processor_testbench(
    params: ProcessorParams,
    frames: &TestbenchFrames,
    ports: &[TopPort],
    generated_by: &GeneratedBy,
) -> Result<String> {
    let port = |name: &str| ports.iter().find(|p| p.name == name);
    for name in TESTBENCH_DRIVES
        .iter()
        .map(|(n, _)| *n)
        .chain(TESTBENCH_USES.iter().copied())
    {
        anyhow::ensure!(
            port(name).is_some(),
            "the processor has no top port `{name}`, which the frame testbench uses"
        );
    }
    let range = |bits: usize| {
        if bits > 1 {
            format!("[{}:0] ", bits - 1)
        } else {
            String::new()
        }
    };
    let mut v = generated_by.comment("//");
    let ml = params.mem_latency;
    let _ = writeln!(
        v,
        "// tb: runs {} frame(s) of {PROCESSOR_TOP}. Plusargs: +mem_dir=DIR (the memory images, \
         default mem),\n// +out_dir=DIR (where frame<k>.hex and frame<k>.stats go, default .), \
         +vga (capture a displayed frame),\n// +heartbeat=N (a progress line every N clocks), \
         +trace=FILE +trace_start=C +trace_end=C (waveforms).\n\
         `timescale 1ns/1ps\nmodule tb;",
        frames.updates.len() + 1
    );
    for p in ports {
        match TESTBENCH_DRIVES.iter().find(|(n, _)| *n == p.name) {
            Some((_, init)) => {
                let _ = writeln!(v, "  reg {}{} = {init};", range(p.bits), p.name);
            }
            None => {
                let _ = writeln!(v, "  wire {}{};", range(p.bits), p.name);
            }
        }
    }
    let _ = writeln!(
        v,
        "  integer px;\n  string mem_dir, out_dir;\n  reg [63:0] clocks = 0, heartbeat = 0;\n  integer frame = 0, rays = 0;\n\
         \x20 reg [63:0] ready_clocks = 0, asleep_clocks = 0;\n\
         \x20 reg [63:0] reads0 = 0, reads1 = 0, reads2 = 0, reads3 = 0, reads4 = 0, reads5 = 0;"
    );
    for (b, name) in BANK_NAMES.iter().enumerate() {
        let _ = writeln!(
            v,
            "  reg [31:0] bank{b} [0:{}]; // {name}",
            frames.bank_words[b].max(1) - 1
        );
    }
    let _ = writeln!(
        v,
        "  reg [31:0] rd [0:{0}];\n  reg [31:0] rd0 [0:{0}];\n  reg [31:0] rd2 [0:{0}];\n  reg [31:0] rd3 [0:{0}];\n\
         \x20 integer k, n, f, fd;\n  reg timeout = 1'b0;",
        ml - 1
    );
    let _ = writeln!(
        v,
        "  {PROCESSOR_TOP} dut({});\n\
         \x20 always #5 clock = ~clock;\n\
         \x20 // +heartbeat=N: a progress line every N clocks (frame, clocks, pixels written).\n\
         \x20 initial if (!$value$plusargs(\"heartbeat=%d\", heartbeat)) heartbeat = 0;\n\
         \x20 always @(posedge clock) begin\n\
         \x20   clocks <= clocks + 1;\n\
         \x20   if (fb_write) rays <= rays + 1;\n\
         \x20   // Thread-clocks: threads waiting for an issue slot, threads asleep in a wait.\n\
         \x20   ready_clocks <= ready_clocks + $countones(dut.{ready_mask});\n\
         \x20   asleep_clocks <= asleep_clocks + $countones(dut.{asleep_mask});\n\
         \x20   // Words read from each bank (banks 1, 4 and 5 share the `mem` port).\n\
         \x20   if (bank0_read) reads0 <= reads0 + 1;\n\
         \x20   if (bank2_read) reads2 <= reads2 + 1;\n\
         \x20   if (bank3_read) reads3 <= reads3 + 1;\n\
         \x20   if (mem_read && mem_bank == 3'd1) reads1 <= reads1 + 1;\n\
         \x20   if (mem_read && mem_bank == 3'd4) reads4 <= reads4 + 1;\n\
         \x20   if (mem_read && mem_bank == 3'd5) reads5 <= reads5 + 1;\n\
         \x20   if (heartbeat != 0 && clocks % heartbeat == 0 && clocks != 0)\n\
         \x20     $display(\"dynrt-heartbeat frame %0d: %0d cycles, %0d rays\", frame, cycles, rays);\n\
         \x20 end\n\
         {trace}\
         \x20 // The display's pixel clock (25 MHz against the core's 100 MHz here; running only with\n\
         \x20 // +vga, so that frame runs do not simulate it) and its read port on the frame bank,\n\
         \x20 // one clock of latency.\n\
         \x20 initial if ($test$plusargs(\"vga\")) forever #20 vga_clock = ~vga_clock;\n\
         \x20 initial begin repeat (3) @(posedge vga_clock); vga_reset = 1'b0; end\n\
         \x20 always @(posedge vga_clock) vga_fb_data <= bank5[vga_fb_addr];\n\
         \x20 // SRAM banks: the word read arrives {ml} clock(s) after the request. The bank is read\n\
         \x20 // at the clock edge rather than through a combinational mux, which Icarus would\n\
         \x20 // re-evaluate on every write to a bank (twice as slow on large scenes).\n\
         \x20 always @(posedge clock) begin\n    case (mem_bank)",
        ports
            .iter()
            .map(|p| format!(".{0}({0})", p.name))
            .collect::<Vec<_>>()
            .join(", "),
        trace = TRACE_WINDOW.replace("{define}", TRACE_DEFINE),
        ready_mask = SCHEDULER_READY,
        asleep_mask = SCHEDULER_ASLEEP,
    );
    for b in [1, 4, 5] {
        let _ = writeln!(
            v,
            "      3'd{b}: rd[0] <= (mem_addr < {}) ? bank{b}[mem_addr] : 32'hdeadbeef;",
            frames.bank_words[b].max(1)
        );
    }
    let _ = writeln!(
        v,
        "      default: rd[0] <= 32'hdeadbeef; // banks 0, 2 and 3 have their own ports\n    endcase"
    );
    for b in [0, 2, 3] {
        let _ = writeln!(
            v,
            "    rd{b}[0] <= (bank{b}_addr < {}) ? bank{b}[bank{b}_addr] : 32'hdeadbeef;",
            frames.bank_words[b].max(1)
        );
    }
    let _ = writeln!(
        v,
        "    for (k = 1; k < {ml}; k = k + 1) begin\n\
         \x20     rd[k] <= rd[k - 1];\n      rd0[k] <= rd0[k - 1];\n      rd2[k] <= rd2[k - 1];\n      rd3[k] <= rd3[k - 1];\n\
         \x20   end\n\
         \x20   if (fb_write) bank5[fb_addr] <= fb_data;\n  end\n  assign mem_rdata = rd[{0}];\n  assign bank0_rdata = rd0[{0}];\n\
         \x20 assign bank2_rdata = rd2[{0}];\n  assign bank3_rdata = rd3[{0}];",
        ml - 1
    );
    let _ = writeln!(
        v,
        "  initial begin\n    if (!$value$plusargs(\"mem_dir=%s\", mem_dir)) mem_dir = \"mem\";\n\
         \x20   if (!$value$plusargs(\"out_dir=%s\", out_dir)) out_dir = \".\";"
    );
    for (b, name) in BANK_NAMES.iter().enumerate() {
        let _ = writeln!(
            v,
            "    $readmemh({{mem_dir, \"/bank{b}_{name}.hex\"}}, bank{b});"
        );
    }
    for fr in 0..=frames.updates.len() {
        if fr > 0 {
            for (b, file) in &frames.updates[fr - 1] {
                let _ = writeln!(v, "    $readmemh({{mem_dir, \"/{file}\"}}, bank{b});");
            }
        }
        let _ = writeln!(
            v,
            "    frame = {fr}; rays = 0; ready_clocks = 0; asleep_clocks = 0;\n\
             \x20   reads0 = 0; reads1 = 0; reads2 = 0; reads3 = 0; reads4 = 0; reads5 = 0;\n    @(negedge clock) start = 1'b1;\n    @(negedge clock) start = 1'b0;\n\
             \x20   n = 0;\n    while (!done && n < {limit}) begin @(posedge clock); n = n + 1; end\n\
             \x20   if (!done) begin\n      $display(\"TIMEOUT: frame {fr} not done after {limit} clocks\");\n\
             \x20     $fatal(1, \"timeout\");\n    end\n\
             \x20   fd = $fopen({{out_dir, \"/frame{fr}.hex\"}}, \"w\");\n\
             \x20   for (k = 0; k < {px}; k = k + 1) $fwrite(fd, \"%06h\\n\", bank5[{fb} + k][23:0]);\n\
             \x20   $fclose(fd);\n    fd = $fopen({{out_dir, \"/frame{fr}.stats\"}}, \"w\");\n\
             \x20   $fwrite(fd, \"%0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d\\n\",\n\
             \x20     cycles, instructions, transform_busy, intersect_busy, traversal_busy, raygen_busy,\n\
             \x20     instance_busy, shading_busy, ready_clocks, asleep_clocks,\n\
             \x20     reads0, reads1, reads2, reads3, reads4, reads5, tri_cache_hits, tri_cache_misses,\n\
             \x20     node_cache_hits, node_cache_misses, instance_cache_hits, instance_cache_misses);\n    $fclose(fd);\n\
             \x20   $display(\"frame {fr}: %0d cycles, %0d instructions\", cycles, instructions);",
            limit = frames.cycle_limit,
            px = frames.pixels,
            fb = frames.frame_buffer,
        );
    }
    // With +vga: the next whole frame the display sends after the last rendered frame, the
    // visible pixels' colours sampled between pixel clocks (raster order).
    let _ = writeln!(
        v,
        "    if ($test$plusargs(\"vga\")) begin\n      @(posedge vga_frame_start);\n\
         \x20     fd = $fopen({{out_dir, \"/vga.hex\"}}, \"w\");\n\
         \x20     for (px = 0; px < {h} * {vv}; px = px + 1) begin\n\
         \x20       @(negedge vga_clock);\n\
         \x20       if (px % {h} < {hv}) $fwrite(fd, \"%06h\\n\", vga_rgb);\n      end\n\
         \x20     $fclose(fd);\n    end",
        h = frames.vga.h_total(),
        hv = frames.vga.h_visible,
        vv = frames.vga.v_visible,
    );
    let _ = writeln!(v, "    $finish;\n  end\nendmodule");
    Ok(v)
}
