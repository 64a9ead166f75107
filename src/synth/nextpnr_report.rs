//! nextpnr's JSON timing and utilization report (`--report FILE`), read into figures we table.
//!
//! Contract: [`parse_report`] takes the report's text and returns, per clock domain, the achieved
//! and constrained frequency; per critical path (nextpnr writes one per clock pair), its start
//! and end cells mapped to our block names ([`block_path`]), its logic levels and its logic and
//! routing delay; and the device's use of each resource type. A report without an `fmax` or a
//! `critical_paths` section, or with a path that has no segments, is an error (a truncated or
//! foreign file), never a row of zeros.
//!
//! The report's segments are `clk-to-q`, `logic`, `routing` and `setup`, and their delays add up
//! to the path's delay. Logic delay here is everything but routing (as nextpnr's log line
//! "N ns logic, M ns routing" counts it). A logic level is one `logic` segment: a LUT, or one
//! half of a `CCU2C` carry slice (nextpnr's `$CCU2_COMB0/1` cells), which we also count apart as
//! carry cells since a carry chain is fast per cell and reads differently from LUT depth.

use std::collections::BTreeMap;

use serde::Deserialize;

/// Frequency of one clock domain after routing.
#[derive(Debug, Clone, PartialEq)]
pub struct ClockFmax {
    pub clock: String,
    pub achieved_mhz: f64,
    pub constraint_mhz: f64,
}

impl ClockFmax {
    pub fn met(&self) -> bool {
        self.achieved_mhz >= self.constraint_mhz
    }
}

/// One end of a critical path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathEnd {
    /// nextpnr's cell name as written.
    pub cell: String,
    pub port: String,
    /// Our block path for it, e.g. `core.mid_norm.q` (see [`block_path`]).
    pub block: String,
}

/// One critical path of the report.
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalPath {
    /// nextpnr's clock edge names, e.g. `posedge clock`.
    pub from_clock: String,
    pub to_clock: String,
    pub start: PathEnd,
    pub end: PathEnd,
    /// `logic` segments (LUTs and carry half-slices) on the path.
    pub logic_levels: u32,
    /// Of those, carry cells (`CCU2C` halves).
    pub carry_cells: u32,
    /// clock-to-out + logic + setup, ns.
    pub logic_ns: f64,
    pub routing_ns: f64,
}

impl CriticalPath {
    pub fn total_ns(&self) -> f64 {
        self.logic_ns + self.routing_ns
    }
}

/// Use of one resource type of the device.
#[derive(Debug, Clone, PartialEq)]
pub struct ResourceUse {
    pub resource: String,
    pub used: u64,
    pub available: u64,
}

impl ResourceUse {
    pub fn percent(&self) -> f64 {
        if self.available == 0 {
            0.0
        } else {
            100.0 * self.used as f64 / self.available as f64
        }
    }
}

/// What one nextpnr report says.
#[derive(Debug, Clone, PartialEq)]
pub struct NextpnrReport {
    /// Sorted by clock name.
    pub clocks: Vec<ClockFmax>,
    /// In the report's order.
    pub paths: Vec<CriticalPath>,
    /// Sorted by resource name; every type of the device, used or not.
    pub utilization: Vec<ResourceUse>,
}

impl NextpnrReport {
    pub fn clock(&self, name: &str) -> Option<&ClockFmax> {
        self.clocks.iter().find(|c| c.clock == name)
    }

    /// Units of `resource` used (0 when the device has no such type).
    pub fn used(&self, resource: &str) -> u64 {
        self.utilization
            .iter()
            .find(|u| u.resource == resource)
            .map_or(0, |u| u.used)
    }

    /// The worst path launched and captured by `clock` (`posedge clock` to `posedge clock`),
    /// else the worst path touching it.
    pub fn critical_path(&self, clock: &str) -> Option<&CriticalPath> {
        let edge = |e: &str| e.rsplit(' ').next() == Some(clock);
        let by_delay = |a: &&CriticalPath, b: &&CriticalPath| a.total_ns().total_cmp(&b.total_ns());
        self.paths
            .iter()
            .filter(|p| edge(&p.from_clock) && edge(&p.to_clock))
            .max_by(by_delay)
            .or_else(|| {
                self.paths
                    .iter()
                    .filter(|p| edge(&p.from_clock) || edge(&p.to_clock))
                    .max_by(by_delay)
            })
    }
}

#[derive(Deserialize)]
struct RawReport {
    fmax: Option<BTreeMap<String, RawFmax>>,
    critical_paths: Option<Vec<RawPath>>,
    #[serde(default)]
    utilization: BTreeMap<String, RawUse>,
}

#[derive(Deserialize)]
struct RawFmax {
    achieved: f64,
    constraint: f64,
}

#[derive(Deserialize)]
struct RawUse {
    available: u64,
    used: u64,
}

#[derive(Deserialize)]
struct RawPath {
    from: String,
    to: String,
    path: Vec<RawSegment>,
}

#[derive(Deserialize)]
struct RawSegment {
    #[serde(rename = "type")]
    kind: String,
    delay: f64,
    from: RawPin,
    to: RawPin,
    #[serde(default)]
    net: Option<String>,
}

#[derive(Deserialize)]
struct RawPin {
    cell: String,
    port: String,
}

/// Parses a report written by `nextpnr-ecp5 --report`.
pub fn parse_report(text: &str) -> Result<NextpnrReport, String> {
    let raw: RawReport =
        serde_json::from_str(text).map_err(|e| format!("not a nextpnr report: {e}"))?;
    let fmax = raw
        .fmax
        .ok_or("the report has no `fmax` section (did routing finish?)")?;
    let raw_paths = raw
        .critical_paths
        .ok_or("the report has no `critical_paths` section")?;
    let clocks = fmax
        .into_iter()
        .map(|(clock, f)| ClockFmax {
            clock,
            achieved_mhz: f.achieved,
            constraint_mhz: f.constraint,
        })
        .collect();
    let mut paths = Vec::new();
    for p in raw_paths {
        let (Some(first), Some(last)) = (p.path.first(), p.path.last()) else {
            return Err(format!(
                "critical path {} -> {} has no segments",
                p.from, p.to
            ));
        };
        let nets: Vec<&str> = p.path.iter().filter_map(|s| s.net.as_deref()).collect();
        let start_net = nets.first().copied();
        let end_net = nets.last().copied();
        let end_pin = &last.to;
        let mut logic_levels = 0;
        let mut carry_cells = 0;
        let mut logic_ns = 0.0;
        let mut routing_ns = 0.0;
        for s in &p.path {
            if s.kind == "routing" {
                routing_ns += s.delay;
            } else {
                logic_ns += s.delay;
            }
            if s.kind == "logic" {
                logic_levels += 1;
                if s.to.cell.contains("$CCU2_COMB") {
                    carry_cells += 1;
                }
            }
        }
        paths.push(CriticalPath {
            from_clock: p.from,
            to_clock: p.to,
            start: path_end(&first.from, start_net),
            end: path_end(end_pin, end_net),
            logic_levels,
            carry_cells,
            logic_ns,
            routing_ns,
        });
    }
    let utilization = raw
        .utilization
        .into_iter()
        .map(|(resource, u)| ResourceUse {
            resource,
            used: u.used,
            available: u.available,
        })
        .collect();
    Ok(NextpnrReport {
        clocks,
        paths,
        utilization,
    })
}

/// A cell whose name yosys made up (`$abc$...`, `$auto$...`) says nothing of where it is; the
/// net next to it on the path usually carries the source's name.
fn path_end(pin: &RawPin, net: Option<&str>) -> PathEnd {
    let block = block_path(&pin.cell)
        .or_else(|| net.and_then(block_path))
        .unwrap_or_else(|| pin.cell.clone());
    PathEnd {
        cell: pin.cell.clone(),
        port: pin.port.clone(),
        block,
    }
}

/// Where yosys's techmapping and nextpnr's packing start appending to a name: a flip-flop is
/// named after its Q net plus `_TRELLIS_FF_Q_<n>`, a LUT after its output net plus `_LUT4_Z...`,
/// a carry after `_CCU2C_...`, and nextpnr adds `$CCU2_COMB0`-style suffixes to packed halves.
const DECORATIONS: [&str; 12] = [
    "$",
    "_TRELLIS_",
    "_LUT4_",
    "_CCU2C_",
    "_DP16KD",
    "_MULT18X18D",
    "_ALU54B",
    "_PFUMX_",
    "_L6MUX21_",
    "_DPR16X4",
    "_DI_LUT4",
    "_DFF",
];

/// Our block path for a yosys / nextpnr cell or net name: the decorations cut off, a bit index
/// (`[3]`) dropped, and the `__` that our Verilog writes for rust-hdl's hierarchy separator (`$`)
/// turned into `.` like yosys's own flattening separator, so `core.mid_norm__q_TRELLIS_FF_Q_3`
/// reads `core.mid_norm.q`. `None` for a name yosys made up (`$abc$12$...`).
pub fn block_path(name: &str) -> Option<String> {
    let name = name.strip_prefix('\\').unwrap_or(name);
    let cut = DECORATIONS
        .iter()
        .filter_map(|d| name.find(d))
        .min()
        .unwrap_or(name.len());
    let mut base = &name[..cut];
    if let Some(open) = base.rfind('[') {
        if base.ends_with(']') {
            base = &base[..open];
        }
    }
    let base = base.trim_end_matches('_');
    if base.is_empty() {
        return None;
    }
    Some(base.replace("__", "."))
}

#[cfg(test)]
mod tests {
    use super::*;

    const REPORT: &str = r#"{
      "fmax": {"clock": {"achieved": 95.0, "constraint": 90}, "vga_clock": {"achieved": 164.2, "constraint": 90}},
      "utilization": {"TRELLIS_COMB": {"available": 83640, "used": 572}, "DP16KD": {"available": 208, "used": 0}},
      "critical_paths": [
        {"from": "posedge clock", "to": "posedge clock", "path": [
          {"type": "clk-to-q", "delay": 0.5, "from": {"cell": "core.exp_diff.q_TRELLIS_FF_Q_5", "port": "Q"}, "to": {"cell": "core.exp_diff.q_TRELLIS_FF_Q_5", "port": "Q"}},
          {"type": "routing", "delay": 1.0, "net": "core.exp_diff.q[3]", "from": {"cell": "core.exp_diff.q_TRELLIS_FF_Q_5", "port": "Q"}, "to": {"cell": "x$CCU2_COMB1", "port": "A"}},
          {"type": "logic", "delay": 0.4, "from": {"cell": "x$CCU2_COMB1", "port": "A"}, "to": {"cell": "x$CCU2_COMB1", "port": "FCO"}},
          {"type": "routing", "delay": 0.0, "net": "n1", "from": {"cell": "x$CCU2_COMB1", "port": "FCO"}, "to": {"cell": "$abc$77$lut", "port": "A"}},
          {"type": "logic", "delay": 0.3, "from": {"cell": "$abc$77$lut", "port": "A"}, "to": {"cell": "$abc$77$lut", "port": "Z"}},
          {"type": "routing", "delay": 2.0, "net": "core.mid_norm__q[7]", "from": {"cell": "$abc$77$lut", "port": "Z"}, "to": {"cell": "core.mid_norm__q_TRELLIS_FF_Q_9", "port": "DI"}},
          {"type": "setup", "delay": 0.1, "from": {"cell": "core.mid_norm__q_TRELLIS_FF_Q_9", "port": "DI"}, "to": {"cell": "core.mid_norm__q_TRELLIS_FF_Q_9", "port": "DI"}}
        ]},
        {"from": "posedge vga_clock", "to": "posedge vga_clock", "path": [
          {"type": "clk-to-q", "delay": 0.5, "from": {"cell": "v.q_TRELLIS_FF_Q", "port": "Q"}, "to": {"cell": "v.q_TRELLIS_FF_Q", "port": "Q"}}
        ]}
      ]
    }"#;

    #[test]
    fn report_figures_add_up_and_names_map_to_blocks() {
        let r = parse_report(REPORT).unwrap();
        assert_eq!(r.clocks.len(), 2);
        let c = r.clock("clock").unwrap();
        assert!(c.met() && c.achieved_mhz == 95.0 && c.constraint_mhz == 90.0);
        let p = r.critical_path("clock").unwrap();
        assert_eq!(p.start.block, "core.exp_diff.q");
        assert_eq!(p.end.block, "core.mid_norm.q");
        assert_eq!(p.end.port, "DI");
        assert_eq!((p.logic_levels, p.carry_cells), (2, 1));
        assert!((p.logic_ns - 1.3).abs() < 1e-9 && (p.routing_ns - 3.0).abs() < 1e-9);
        assert_eq!(r.critical_path("vga_clock").unwrap().logic_levels, 0);
        assert_eq!(r.used("TRELLIS_COMB"), 572);
        assert_eq!(r.used("NO_SUCH"), 0);
    }

    #[test]
    fn made_up_cell_names_fall_back_to_the_net() {
        let pin = RawPin {
            cell: "$abc$123$auto$blifparse.cc:396".into(),
            port: "Z".into(),
        };
        assert_eq!(path_end(&pin, Some("core.sum.q[2]")).block, "core.sum.q");
        assert_eq!(path_end(&pin, Some("$auto$9")).block, pin.cell);
        assert_eq!(block_path("regs_a__mem_DP16KD_DOA0").unwrap(), "regs_a.mem");
        assert_eq!(block_path("$abc$1$lut"), None);
    }

    #[test]
    fn truncated_or_foreign_reports_are_errors() {
        assert!(parse_report("{}").unwrap_err().contains("fmax"));
        assert!(parse_report("not json")
            .unwrap_err()
            .contains("not a nextpnr report"));
        let no_segments =
            r#"{"fmax": {}, "critical_paths": [{"from": "a", "to": "b", "path": []}]}"#;
        assert!(parse_report(no_segments)
            .unwrap_err()
            .contains("no segments"));
    }
}
