//! Tests of `synth` against the real Yosys 0.23 (no mocks).

use super::*;

fn synth_source(name: &str, verilog: &str, top: &str) -> SynthReport {
    synth_source_with(name, verilog, top, &SynthOptions::default())
}

fn synth_source_with(name: &str, verilog: &str, top: &str, options: &SynthOptions) -> SynthReport {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join(format!("{name}.v"));
    std::fs::write(&src, verilog).unwrap();
    let report =
        synth_xc2v_with(&[src], top, dir.path(), options).unwrap_or_else(|e| panic!("{top}: {e}"));
    println!("{report}\n{:?}", report.all_cells);
    report
}

fn registered_multiplier(w: u32) -> String {
    format!(
        "module mul{w} (input wire clk, input wire [{m}:0] a, input wire [{m}:0] b,\n\
         \x20   output reg [{p}:0] p);\n\
         \x20 reg [{m}:0] ra, rb;\n\
         \x20 always @(posedge clk) begin ra <= a; rb <= b; p <= ra * rb; end\n\
         endmodule\n",
        m = w - 1,
        p = 2 * w - 1
    )
}

#[test]
fn mult_17x17_uses_one_mult18x18() {
    let r = synth_source("mul17", &registered_multiplier(17), "mul17");
    assert_eq!(r.mult18x18, 1);
    // Operand and product registers: 17 + 17 + 34.
    assert_eq!(r.flip_flops, 68);
    assert_eq!(r.yosys_version, "0.23");
}

#[test]
fn mult_24x24_uses_four_mult18x18() {
    // 24 = 17 + 7 unsigned slices per operand: a 2x2 grid of 18x18 signed multipliers,
    // whose partial products are summed in carry-chain adders.
    let r = synth_source("mul24", &registered_multiplier(24), "mul24");
    assert_eq!(r.mult18x18, 4);
    assert!(
        r.carry > 0,
        "partial products need adders: {:?}",
        r.all_cells
    );
    assert_eq!(r.flip_flops, 24 + 24 + 48);
}

#[test]
fn counter_has_n_flip_flops() {
    for n in [5u32, 13] {
        let v = format!(
            "module counter (input wire clk, input wire rst, output reg [{m}:0] q);\n\
             \x20 always @(posedge clk) if (rst) q <= 0; else q <= q + 1'b1;\n\
             endmodule\n",
            m = n - 1
        );
        let r = synth_source("counter", &v, "counter");
        assert_eq!(r.flip_flops, n as u64, "{:?}", r.all_cells);
        assert_eq!(r.mult18x18, 0);
        assert_eq!(r.block_rams, 0);
    }
}

const PARITY_V: &str = "module parity (input wire clk, input wire [63:0] d, output reg p);\n\
    \x20 reg [63:0] r;\n\
    \x20 always @(posedge clk) begin r <= d; p <= ^r; end\n\
    endmodule\n";

#[test]
fn parity_tree_depth_in_lut_levels() {
    // XOR of 64 registered bits into a register: a LUT4 tree 64 -> 16 -> 4 -> 1, 21 LUT4s in
    // 3 levels (no LUT4 tree does better: 4^2 = 16 < 64). XOR does not map to carry chains.
    let r = synth_source("parity", PARITY_V, "parity");
    assert_eq!(r.cells("LUT4"), 21, "{:?}", r.all_cells);
    assert_eq!(r.luts, 21);
    assert_eq!(r.logic_depth, 3, "{:?}", r.all_cells);
    assert_eq!(r.path_cells, 3);
    assert_eq!(r.flip_flops, 65);
    // The tree runs from a bit of register r to register p, named as in the Verilog.
    assert!(r.deepest_start.starts_with('r'), "{}", r.deepest_start);
    assert_eq!(r.deepest_end, "p");
}

#[test]
fn parity_tree_with_wide_luts() {
    // With wide LUTs ABC builds 8-input functions (16 LUT4s joined by MUXF5..MUXF8 inside
    // the CLBs), which the depth definition counts as one level: 64 -> 8 -> 1 = 2 levels,
    // and 5 cells (LUT4, MUXF5, MUXF6, MUXF7, MUXF8) per level. Counting MUXFs as levels
    // would give 10; cutting paths at the wrong place, 1.
    let options = SynthOptions {
        wide_luts: true,
        ..SynthOptions::default()
    };
    let r = synth_source_with("parity", PARITY_V, "parity", &options);
    assert!(!r.command.contains("-nowidelut"));
    assert_eq!(r.cells("MUXF8"), 9, "{:?}", r.all_cells);
    assert_eq!(r.logic_depth, 2, "{:?}", r.all_cells);
    assert_eq!(r.path_cells, 10, "{:?}", r.all_cells);
    assert_eq!(r.flip_flops, 65);
}

#[test]
fn adder_is_one_lut_level_plus_carry_chain() {
    // Registered 16-bit add: one LUT2 per bit feeding MUXCY/XORCY; the path from the LSB's
    // LUT through 15 MUXCYs to the MSB's XORCY is 17 cells but only 1 LUT level.
    let v = "module add16 (input wire clk, input wire [15:0] a, input wire [15:0] b,\n\
             \x20   output reg [15:0] s);\n\
             \x20 reg [15:0] ra, rb;\n\
             \x20 always @(posedge clk) begin ra <= a; rb <= b; s <= ra + rb; end\n\
             endmodule\n";
    let r = synth_source("add16", v, "add16");
    assert_eq!(r.logic_depth, 1, "{:?}", r.all_cells);
    assert_eq!(r.path_cells, 17, "{:?}", r.all_cells);
    assert_eq!(r.cells("XORCY"), 16, "{:?}", r.all_cells);
}

#[test]
fn syntax_error_is_located() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("bad.v");
    std::fs::write(
        &src,
        "module bad (input wire a, output wire y);\n  assign y = ;\nendmodule\n",
    )
    .unwrap();
    match synth_xc2v(&[src], "bad", dir.path()) {
        Err(ToolError::Compile {
            location, excerpt, ..
        }) => {
            let loc = location.expect(&excerpt);
            assert!(loc.file.ends_with("bad.v"), "{loc}");
            assert_eq!(loc.line, 2, "{excerpt}");
        }
        other => panic!("expected a compile error, got {other:?}"),
    }
}

#[test]
fn missing_top_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("m.v");
    std::fs::write(
        &src,
        "module m (input wire a, output wire y);\n  assign y = a;\nendmodule\n",
    )
    .unwrap();
    let err = synth_xc2v(&[src], "not_there", dir.path()).unwrap_err();
    assert!(matches!(err, ToolError::Compile { .. }), "{err:?}");
    assert!(err.to_string().contains("not_there"), "{err}");
}

#[test]
fn utilization_of_xc2v6000() {
    let mut cells = BTreeMap::new();
    cells.insert("MULT18X18".to_string(), 36);
    cells.insert("LUT4".to_string(), 6758);
    cells.insert("RAM16X1D".to_string(), 1);
    cells.insert("FDRE".to_string(), 33792);
    cells.insert("RAMB16_S36_S36".to_string(), 144);
    let r = summarize(
        "t",
        String::new(),
        "0.23".into(),
        cells,
        depth::Depth {
            logic_depth: 0,
            path_cells: 0,
            start: String::new(),
            end: String::new(),
        },
        String::new(),
        0.0,
        PathBuf::new(),
    );
    assert_eq!(r.luts, 6758);
    assert_eq!(r.lut_ram_luts, 2);
    let u = r.utilization(&XC2V6000);
    assert!((u.luts_percent - 100.0 * 6760.0 / 67584.0).abs() < 1e-9);
    assert_eq!(u.flip_flops_percent, 50.0);
    assert_eq!(u.mult18x18_percent, 25.0);
    assert_eq!(u.block_rams_percent, 100.0);
    assert!(u.fits());
    assert_eq!(XC2V6000.luts, 2 * XC2V6000.slices);
}

#[test]
fn lut_ram_sizes() {
    assert_eq!(lut_ram_size("RAM16X1S"), 1);
    assert_eq!(lut_ram_size("RAM32X1S"), 2);
    assert_eq!(lut_ram_size("RAM64X1D"), 8);
    assert_eq!(lut_ram_size("RAM16X8S"), 8);
    assert_eq!(lut_ram_size("SRL16E"), 1);
}

#[test]
fn memories_map_to_block_ram_and_distributed_ram() {
    let dir = tempfile::tempdir().unwrap();
    let init: String = (0..512).map(|i| format!("{i:08x}\n")).collect();
    // $readmemh paths resolve against yosys's current directory, the work directory.
    std::fs::write(dir.path().join("init.hex"), init).unwrap();
    let src = dir.path().join("rams.v");
    std::fs::write(
        &src,
        "module ram512 (input wire clk, input wire we, input wire [8:0] wa, input wire [31:0] wd,\n\
         \x20   input wire [8:0] ra, output reg [31:0] rd);\n\
         \x20 reg [31:0] mem [0:511];\n\
         \x20 initial $readmemh(\"init.hex\", mem);\n\
         \x20 always @(posedge clk) begin if (we) mem[wa] <= wd; rd <= mem[ra]; end\n\
         endmodule\n\
         module ram16 (input wire clk, input wire we, input wire [3:0] wa, input wire [7:0] wd,\n\
         \x20   input wire [3:0] ra, output wire [7:0] rd);\n\
         \x20 reg [7:0] mem [0:15];\n\
         \x20 always @(posedge clk) if (we) mem[wa] <= wd;\n\
         \x20 assign rd = mem[ra];\n\
         endmodule\n",
    )
    .unwrap();
    // 512 x 32 with a registered read: exactly one 18-Kbit block RAM in its 512x36 shape.
    let big = synth_xc2v(std::slice::from_ref(&src), "ram512", dir.path()).unwrap();
    println!("{big}\n{:?}", big.all_cells);
    assert_eq!(big.block_rams, 1, "{:?}", big.all_cells);
    assert_eq!(big.cells("RAMB16_S36_S36"), 1);
    assert_eq!(big.luts, 0);
    // 16 x 8 with an asynchronous read: 8 dual-port RAM16X1D, 2 LUTs each; the read is one
    // LUT level from the address port to the output.
    let small = synth_xc2v(&[src], "ram16", dir.path()).unwrap();
    println!("{small}\n{:?}", small.all_cells);
    assert_eq!(small.cells("RAM16X1D"), 8, "{:?}", small.all_cells);
    assert_eq!(small.lut_ram_luts, 16);
    assert_eq!(small.total_luts(), 16 + small.luts);
    assert_eq!(small.logic_depth, 1);
    assert_eq!(small.block_rams, 0);
}

#[test]
fn blocks_are_itemized_per_instance_with_shared_modules_counted_per_use() {
    // Two instances of one 8-bit register module, one 4-bit register module holding a
    // function of its inputs: each row counts its own instance only; the top adds its own
    // 3-bit register.
    let verilog = "\
module reg8 (input wire clk, input wire [7:0] d, output reg [7:0] q);\n\
  always @(posedge clk) q <= d;\n\
endmodule\n\
module xor4 (input wire clk, input wire [7:0] a, input wire [7:0] b, output reg [3:0] q);\n\
  always @(posedge clk) q <= a[3:0] ^ a[7:4] ^ b[3:0] ^ b[7:4];\n\
endmodule\n\
module top (input wire clk, input wire [7:0] x, input wire [7:0] y, output reg [2:0] z);\n\
  wire [7:0] qa, qb; wire [3:0] f;\n\
  reg8 first (.clk(clk), .d(x), .q(qa));\n\
  reg8 second (.clk(clk), .d(y), .q(qb));\n\
  xor4 mix (.clk(clk), .a(qa), .b(qb), .q(f));\n\
  always @(posedge clk) z <= f[2:0];\n\
endmodule\n";
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("top.v");
    std::fs::write(&src, verilog).unwrap();
    let options = SynthOptions {
        io_pads: false,
        ..SynthOptions::default()
    };
    let report = synth_xc2v_blocks(&[src], "top", dir.path(), &options, 1).unwrap();
    println!("{}", report.markdown());
    let ffs: Vec<(&str, u64)> = report
        .rows
        .iter()
        .map(|r| (r.path.as_str(), r.resources.flip_flops))
        .collect();
    assert_eq!(
        ffs,
        vec![("", 8 + 8 + 4 + 3), ("first", 8), ("mix", 4), ("second", 8)]
    );
    // The 4-bit XOR of four inputs is one LUT4 per bit, and the registers take none.
    let luts: Vec<u64> = report.rows.iter().map(|r| r.resources.luts).collect();
    assert_eq!(luts, vec![4, 0, 4, 0]);
    assert!(report.command.contains("-top top") && !report.command.contains("-flatten"));
    assert!(report.csv().starts_with("block,depth,luts,"));
    assert!(report.csv().contains("\nmix,1,4,0,4,0,0\n"));
    // The table leaves out blocks under half a percent of the LUTs with no multiplier or
    // block RAM (the two registers); the CSV keeps every one.
    let table = report.markdown();
    assert!(
        table.contains("`mix` | 4 |") && !table.contains("`first`"),
        "{table}"
    );
    assert!(report.csv().contains("\nfirst,1,0,0,8,0,0\n"));
}
