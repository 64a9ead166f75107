//! A generic streaming testbench for a pipelined unit.
//!
//! [`StreamBench`] describes a device under test by its ports, the input streams that drive
//! it and the output sinks that record it. [`stream_bench_verilog`] writes module `tb` for
//! Icarus (`-g2012`) and Verilator 5 (`--binary --timing`); `crate::sim::stream_bench::
//! run_stream_bench` writes the vector files, compiles and runs the bench and reads the records
//! back.
//!
//! Timing contract (race-free in both simulators): everything happens at the rising edge. The
//! bench samples `ready` and output ports in the active region of the edge, so it sees the
//! values of the clock that just ended, and drives inputs with non-blocking assignments, so the
//! unit sees the new values only from the next clock on.
//!
//! Input stream: one file, one line per transfer: an optional gap (idle clocks before the
//! line is presented) then one hex value per field. A line is presented (`valid` = 1 if the
//! stream has a valid port) and held until it is taken, i.e. until an edge where the stream's
//! `ready` expression is 1 (no `ready`: taken at the first edge). While no line is presented
//! the fields keep their last values and `valid` is 0.
//!
//! Output sink: one file; at every edge where its `valid` port is 1, one line of hex fields.
//! The bench ends when every stream is exhausted and every sink has its expected count, or
//! after `max_cycles` with a message (the runner then reports the missing records).

use std::fmt::Write as _;

use anyhow::{bail, Context, Result};

/// One port of the device under test.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BenchPort {
    pub name: String,
    pub width: u32,
    pub output: bool,
}

impl BenchPort {
    pub fn input(name: impl Into<String>, width: u32) -> BenchPort {
        BenchPort {
            name: name.into(),
            width,
            output: false,
        }
    }
    pub fn output(name: impl Into<String>, width: u32) -> BenchPort {
        BenchPort {
            name: name.into(),
            width,
            output: true,
        }
    }
}

/// A stream of transfers into input ports.
#[derive(Debug, Clone)]
pub struct InputStream {
    /// Names the vector file (`<name>.hex`).
    pub name: String,
    /// The input ports each line sets, in line order.
    pub fields: Vec<String>,
    /// Input port set to 1 while a line is presented.
    pub valid: Option<String>,
    /// Verilog expression over the DUT's ports: the presented line is taken at an edge where it
    /// is 1. `None`: always taken.
    pub ready: Option<String>,
    /// Lines: `[gap, field values...]`; the gap is the number of idle clocks before the line.
    pub lines: Vec<(u32, Vec<u64>)>,
}

/// Records of output ports.
#[derive(Debug, Clone)]
pub struct OutputSink {
    /// Names the result file (`<name>.out.hex`).
    pub name: String,
    /// Output port: a record is taken at every edge where it is 1.
    pub valid: String,
    pub fields: Vec<String>,
    /// Records after which the sink is complete.
    pub expected: usize,
}

/// A device under test with its streams and sinks.
#[derive(Debug, Clone)]
pub struct StreamBench {
    /// Module name of the device under test; its clock port is `clock`.
    pub dut: String,
    pub ports: Vec<BenchPort>,
    pub streams: Vec<InputStream>,
    pub sinks: Vec<OutputSink>,
    /// The run stops (with a message) after this many clocks.
    pub max_cycles: u64,
}

impl StreamBench {
    fn port(&self, name: &str) -> Result<&BenchPort> {
        self.ports
            .iter()
            .find(|p| p.name == name)
            .with_context(|| format!("{}: no port `{name}`", self.dut))
    }

    fn check(&self) -> Result<()> {
        for s in &self.streams {
            for f in s.fields.iter().chain(&s.valid) {
                let p = self.port(f)?;
                if p.output {
                    bail!("{}: stream {} drives output port {f}", self.dut, s.name);
                }
                if p.width > 64 {
                    bail!("{}: port {f} is wider than 64 bits", self.dut);
                }
            }
            for (i, (_, values)) in s.lines.iter().enumerate() {
                if values.len() != s.fields.len() {
                    bail!(
                        "stream {} line {}: {} values for {} fields",
                        s.name,
                        i + 1,
                        values.len(),
                        s.fields.len()
                    );
                }
                for (v, f) in values.iter().zip(&s.fields) {
                    let w = self.port(f)?.width;
                    if w < 64 && v >> w != 0 {
                        bail!(
                            "stream {} line {}: {v:#x} does not fit the {w} bits of {f}",
                            s.name,
                            i + 1
                        );
                    }
                }
            }
        }
        for k in &self.sinks {
            for f in k.fields.iter().chain(std::iter::once(&k.valid)) {
                if self.port(f)?.width > 64 {
                    bail!("{}: port {f} is wider than 64 bits", self.dut);
                }
            }
        }
        Ok(())
    }
}

/// The testbench module `tb` for `bench` (see the module doc for its timing).
pub fn stream_bench_verilog(bench: &StreamBench) -> Result<String> {
    bench.check()?;
    let mut decl = String::new();
    let mut conn = Vec::new();
    for p in &bench.ports {
        let range = if p.width > 1 {
            format!("[{}:0] ", p.width - 1)
        } else {
            String::new()
        };
        if p.name == "clock" {
            conn.push(".clock(clock)".to_string());
            continue;
        }
        if p.output {
            writeln!(decl, "    wire {range}{};", p.name)?;
        } else {
            writeln!(decl, "    reg {range}{} = {}'d0;", p.name, p.width)?;
        }
        conn.push(format!(".{0}({0})", p.name));
    }
    let mut init = String::new();
    let mut edge = String::new();
    let mut done = Vec::new();
    for (i, s) in bench.streams.iter().enumerate() {
        let n = s.lines.len();
        writeln!(
            decl,
            "    integer in_{i}; integer sent_{i} = 0; integer gap_{i} = 0; integer scanned_{i};\n    \
             reg pending_{i} = 1'b0; reg stashed_{i} = 1'b0;"
        )?;
        for (k, f) in s.fields.iter().enumerate() {
            writeln!(decl, "    reg [63:0] stash_{i}_{k};  // {f}")?;
        }
        writeln!(
            init,
            "        in_{i} = $fopen(\"{0}.hex\", \"r\");\n        \
             if (in_{i} == 0) begin $display(\"tb: cannot open {0}.hex\"); $finish; end",
            s.name
        )?;
        let ready = s.ready.clone().unwrap_or_else(|| "1'b1".into());
        let mut scan_fmt = String::from("%h");
        let mut scan_args = format!("gap_{i}");
        for k in 0..s.fields.len() {
            scan_fmt += " %h";
            scan_args += &format!(", stash_{i}_{k}");
        }
        let mut present = String::new();
        for (k, f) in s.fields.iter().enumerate() {
            let w = bench.port(f)?.width;
            writeln!(
                present,
                "                {f} <= stash_{i}_{k}[{}:0];",
                w - 1
            )?;
        }
        let (valid_on, valid_off) = match &s.valid {
            Some(v) => (
                format!("                {v} <= 1'b1;\n"),
                format!("                {v} <= 1'b0;\n"),
            ),
            None => (String::new(), String::new()),
        };
        let nf = s.fields.len() + 1;
        write!(
            edge,
            "        // stream {name}\n        \
             if (pending_{i} && ({ready})) pending_{i} = 1'b0;\n        \
             if (!pending_{i}) begin\n            \
             if (!stashed_{i} && sent_{i} < {n}) begin\n                \
             scanned_{i} = $fscanf(in_{i}, \"{scan_fmt}\\n\", {scan_args});\n                \
             if (scanned_{i} != {nf}) begin\n                    \
             $display(\"tb: {name}.hex line %0d: expected {nf} hex values\", sent_{i} + 1);\n                    \
             $finish;\n                end\n                \
             stashed_{i} = 1'b1;\n                sent_{i} = sent_{i} + 1;\n            end\n            \
             if (stashed_{i} && gap_{i} == 0) begin\n{present}{valid_on}                \
             pending_{i} = 1'b1;\n                stashed_{i} = 1'b0;\n            \
             end else begin\n{valid_off}                \
             if (stashed_{i}) gap_{i} = gap_{i} - 1;\n            end\n        end\n",
            name = s.name
        )?;
        done.push(format!("(sent_{i} == {n} && !pending_{i} && !stashed_{i})"));
    }
    for (j, k) in bench.sinks.iter().enumerate() {
        writeln!(decl, "    integer out_{j}; integer got_{j} = 0;")?;
        writeln!(
            init,
            "        out_{j} = $fopen(\"{0}.out.hex\", \"w\");\n        \
             if (out_{j} == 0) begin $display(\"tb: cannot write {0}.out.hex\"); $finish; end",
            k.name
        )?;
        let fmt = vec!["%h"; k.fields.len()].join(" ");
        let args = k.fields.join(", ");
        write!(
            edge,
            "        // sink {name}\n        \
             if ({valid}) begin\n            \
             $fwrite(out_{j}, \"{fmt}\\n\", {args});\n            got_{j} = got_{j} + 1;\n        end\n",
            name = k.name,
            valid = k.valid
        )?;
        done.push(format!("got_{j} >= {}", k.expected));
    }
    let done = if done.is_empty() {
        "1'b1".to_string()
    } else {
        done.join(" && ")
    };
    let mut close = String::new();
    for j in 0..bench.sinks.len() {
        write!(close, " $fclose(out_{j});")?;
    }
    Ok(format!(
        "// Streaming testbench for {dut} (generated by dynrt).\n\
         `timescale 1ns/1ps\n\
         module tb;\n    \
         reg clock = 1'b0;\n    \
         integer cycles = 0;\n\
         {decl}\n    \
         {dut} dut({conn});\n\n    \
         always #5 clock = ~clock;\n\n    \
         initial begin\n{init}    end\n\n    \
         always @(posedge clock) begin\n        \
         cycles = cycles + 1;\n\
         {edge}        \
         if ({done}) begin{close} $finish; end\n        \
         if (cycles > {max}) begin\n            \
         $display(\"tb: timeout after %0d clocks\", cycles);{close}\n            $finish;\n        end\n    \
         end\n\
         endmodule\n",
        dut = bench.dut,
        conn = conn.join(", "),
        max = bench.max_cycles,
    ))
}
