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
