//! The checked-in generated files (rtl_out/, testbench/) are exactly what the generator
//! writes today; `make rtl` regenerates them after a generator change.
//!
//! Their headers name dynrt's version and the `make rtl` command that made them, without a
//! commit (`--stable-header`), so they are compared whole, header included: the headers here
//! are built from the commands in the Makefile's `rtl` target, and a version bump or a changed
//! command makes them stale like any other change of the generator's output.

use dynrt::emit::{fp_unit_rtl, fp_unit_testbench};
use dynrt::fp::{BinOp, Format};
use dynrt::provenance::GeneratedBy;
use std::path::Path;

/// The header of the files `make rtl` makes with `command` (its arguments after `dynrt`).
fn make_rtl_header(command: &str) -> GeneratedBy {
    let makefile =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Makefile")).unwrap();
    let make_line = format!(
        "$(DYNRT) {}",
        command.replace("out/rtl/cornell", "$(RTL_TMP)")
    );
    assert!(
        makefile.contains(&make_line),
        "the Makefile's rtl target no longer runs `{make_line}`: keep this test in step"
    );
    GeneratedBy {
        version: dynrt::provenance::VERSION.to_string(),
        commit: None,
        command: Some(format!("dynrt {command}")),
    }
}

#[test]
fn checked_in_fp_operator_verilog_matches_the_generator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = make_rtl_header(
        "emit-fp --format e7m16 --rtl rtl_out/fp --testbench testbench/fp --stable-header",
    )
    .comment("//");
    for op in BinOp::ALL {
        let unit = fp_unit_rtl(op, Format::E7M16).unwrap();
        let rtl = root.join("rtl_out/fp").join(format!("{}.v", unit.top));
        let tb = root.join("testbench/fp").join(format!("tb_{}.v", unit.top));
        let stale = |p: &Path| {
            format!(
                "{} is stale or missing: run `make rtl` and commit the result",
                p.display()
            )
        };
        assert_eq!(
            std::fs::read_to_string(&rtl).unwrap_or_default(),
            format!("{header}{}", unit.verilog),
            "{}",
            stale(&rtl)
        );
        let want_tb = fp_unit_testbench(&unit, Format::E7M16, 1000, "vectors.hex", "results.hex");
        assert_eq!(
            std::fs::read_to_string(&tb).unwrap_or_default(),
            format!("{header}{want_tb}"),
            "{}",
            stale(&tb)
        );
    }
}

#[test]
fn checked_in_processor_of_the_default_scene_matches_the_generator() {
    use dynrt::emit::processor::ProcessorParams;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = dynrt::scene::Scene::load(&root.join("scenes/cornell.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    dynrt::flow::generate_rtl(
        &scene,
        "cornell",
        Format::E7M16,
        ProcessorParams::default(),
        None,
        dir.path(),
        &make_rtl_header("rtl scenes/cornell.toml --out out/rtl/cornell --stable-header"),
        None,
    )
    .unwrap();
    let mut pairs = vec![
        (
            "rtl/dynrt_processor.v".to_string(),
            "rtl_out/processor/dynrt_processor.v".to_string(),
        ),
        (
            "program.lst".to_string(),
            "rtl_out/processor/program.lst".to_string(),
        ),
        (
            "testbench/tb.v".to_string(),
            "testbench/processor/tb.v".to_string(),
        ),
        (
            "constraints/dynrt.ucf".to_string(),
            "constraints/dynrt.ucf".to_string(),
        ),
    ];
    for e in std::fs::read_dir(dir.path().join("mem")).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        pairs.push((
            format!("mem/{name}"),
            format!("testbench/processor/mem/{name}"),
        ));
    }
    for (generated, checked_in) in pairs {
        let want = std::fs::read_to_string(dir.path().join(&generated)).unwrap();
        assert!(
            std::fs::read_to_string(root.join(&checked_in)).unwrap_or_default() == want,
            "{checked_in} is stale or missing: run `make rtl` and commit the result"
        );
    }
}

/// The localparams of the checked-in processor's engine and its stage blocks (the modules
/// `dynrt_processor__engine` and `dynrt_processor__engine__<stage>`), which the test above
/// keeps equal to the generator's. A name in several of them must have one value.
fn engine_localparams() -> std::collections::HashMap<String, u64> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let v = std::fs::read_to_string(root.join("rtl_out/processor/dynrt_processor.v")).unwrap();
    let mut params = std::collections::HashMap::new();
    let mut modules = 0;
    for (start, _) in v.match_indices("\nmodule dynrt_processor__engine") {
        let name: String = v[start + 8..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let stage = name.trim_start_matches("dynrt_processor__engine");
        if !(stage.is_empty() || (stage.starts_with("__") && !stage[2..].contains("__"))) {
            continue;
        }
        modules += 1;
        let end = start + v[start..].find("endmodule").unwrap();
        for (n, value) in localparams(&v[start..end]) {
            let old = params.insert(n.clone(), value);
            assert!(
                old.is_none() || old == Some(value),
                "{name}: localparam {n} = {value}, another stage has {old:?}"
            );
        }
    }
    assert!(
        modules >= 5,
        "the engine's stage modules are missing ({modules} found)"
    );
    params
}

fn localparams(module: &str) -> Vec<(String, u64)> {
    module
        .lines()
        .filter_map(|l| l.trim().strip_prefix("localparam"))
        .map(|l| {
            let (name, value) = l.split_once('=').unwrap();
            let value = value.trim().trim_end_matches(';');
            let (radix, digits) = match value.split_once('\'') {
                Some((_, v)) => match &v[..1] {
                    "b" => (2, &v[1..]),
                    "h" => (16, &v[1..]),
                    _ => (10, &v[1..]),
                },
                None => (10, value),
            };
            let n = u64::from_str_radix(digits, radix).unwrap_or_else(|e| panic!("{l}: {e}"));
            (name.trim().to_string(), n)
        })
        .collect()
}

/// Every instruction, encoded as the ROM holds it, decodes in the generated Verilog to its
/// own op and function: the decoder slices the fields at the localparams `f_*` and compares
/// the opcode with `op_*`, `imm` with `tri_*` and `kd_*`, all built from `isa`. Were a
/// decoder constant spelled out (or `Op` reordered against it), the RTL would run another
/// instruction than the twin and this would name it.
#[test]
fn the_generated_decoder_reads_every_instruction_as_the_isa_encodes_it() {
    use dynrt::hw::program::isa::{Instr, KdFn, Op, TriFn, OPS};
    let p = engine_localparams();
    let at = |name: &str| {
        *p.get(name)
            .unwrap_or_else(|| panic!("no localparam {name}")) as u32
    };
    let slice = |w: u32, field: &str, bits: u32| (w >> at(field)) & ((1 << bits) - 1);
    for op in OPS {
        let mut i = Instr::new(op);
        (i.dst, i.a, i.b, i.b_imm, i.invert) = (0x5a, 0xc3, 0x81, true, true);
        (i.shift, i.bank, i.target) = (5, 3, 0xabc);
        let [ctl, _, aux] = i.encode();
        let code = u64::from(slice(ctl, "f_op", 5));
        let named: Vec<&str> = p
            .iter()
            .filter(|(n, v)| n.starts_with("op_") && *n != "op_writes" && **v == code)
            .map(|(n, _)| n.as_str())
            .collect();
        let want: Vec<String> = match op {
            Op::Nop => vec![],
            _ => vec![format!("op_{}", op.name())],
        };
        assert_eq!(named, want, "{op:?} (opcode {code})");
        assert_eq!(
            (at("op_writes") >> code) & 1 == 1,
            op.writes(),
            "{op:?}: the write back's op_writes"
        );
        assert_eq!(slice(ctl, "f_dst", 8), 0x5a, "{op:?} dst");
        assert_eq!(slice(ctl, "f_a", 8), 0xc3, "{op:?} a");
        assert_eq!(slice(ctl, "f_b", 8), 0x81, "{op:?} b");
        assert_eq!(slice(ctl, "f_b_imm", 1), 1, "{op:?} b_imm");
        assert_eq!(slice(ctl, "f_invert", 1), 1, "{op:?} invert");
        assert_eq!(slice(aux, "f_shift", 3), 5, "{op:?} shift");
        assert_eq!(slice(aux, "f_bank", 3), 3, "{op:?} bank");
        assert_eq!(slice(aux, "f_target", 12), 0xabc, "{op:?} target");
    }
    for f in TriFn::ALL {
        let mut i = Instr::new(Op::Tri);
        i.imm = f as u32;
        let imm = i.encode()[1];
        let ray = matches!(f, TriFn::RayOxy | TriFn::RayOzDx | TriFn::RayDyz);
        assert_eq!(imm < at("tri_ray_words"), ray, "{f:?}: a ray word");
        if !ray {
            let name = format!("tri_{}", f.name());
            assert_eq!(at(&name), imm, "{f:?}");
        }
    }
    for f in KdFn::ALL {
        let mut i = Instr::new(Op::Kd);
        i.imm = f as u32;
        assert_eq!(at(&format!("kd_{}", f.name())), i.encode()[1], "{f:?}");
    }
}
