//! The checked-in generated files (rtl_out/, testbench/) are exactly what the generator
//! writes today; `make rtl` regenerates them after a generator change.

use dynrt::emit::{fp_unit_rtl, fp_unit_testbench};
use dynrt::fp::{BinOp, Format};
use std::path::Path;

#[test]
fn checked_in_fp_operator_verilog_matches_the_generator() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
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
            unit.verilog,
            "{}",
            stale(&rtl)
        );
        let want_tb = fp_unit_testbench(&unit, Format::E7M16, 1000, "vectors.hex", "results.hex");
        assert_eq!(
            std::fs::read_to_string(&tb).unwrap_or_default(),
            want_tb,
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
