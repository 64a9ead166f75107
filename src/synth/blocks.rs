//! The resources of each block instance of a hierarchical netlist (yosys `synth_xilinx`
//! without `-flatten`, its `write_json`): a block's row counts the primitives of its module and
//! of every module below it, so that a unit of the processor (the engine's `primary_rays`, the
//! `tester`) is read off as one line.
//!
//! rust-hdl writes one module per block instance, except that identical modules are merged
//! (`emit::verilog_tidy`): a module's counts are computed once and added for each of its
//! instances, so shared modules count once per use.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::depth::Netlist;
use super::Resources;

/// One block instance and everything below it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockRow {
    /// Instance path below the top, `.`-separated (`engine.fp_units`); empty for the top.
    pub path: String,
    /// Levels below the top (the top is 0).
    pub depth: usize,
    pub resources: Resources,
}

/// The itemized resources of one hierarchical synthesis.
#[derive(Debug, Clone)]
pub struct BlockReport {
    pub top: String,
    pub command: String,
    pub yosys_version: String,
    /// The top first, then each instance followed by its own instances (depth first, by name).
    pub rows: Vec<BlockRow>,
    pub seconds: f64,
}

/// Rows for `top` and its instances down to `max_depth` levels below it.
pub(crate) fn itemize(
    netlist: &Netlist,
    top: &str,
    max_depth: usize,
) -> Result<Vec<BlockRow>, String> {
    let mut totals = BTreeMap::new();
    let mut rows = Vec::new();
    walk(
        netlist,
        top,
        String::new(),
        0,
        max_depth,
        &mut totals,
        &mut rows,
    )?;
    Ok(rows)
}

/// Whether `cell_type` is a module of the design (not a primitive of the cell library, which
/// the netlist lists as a `blackbox` or `whitebox` module).
fn is_block(netlist: &Netlist, cell_type: &str) -> bool {
    netlist.modules.get(cell_type).is_some_and(|m| {
        !["blackbox", "whitebox", "lib_whitebox"]
            .iter()
            .any(|a| m.attributes.contains_key(*a))
    })
}

/// The resources of `module` and every module below it, memoized in `totals`.
fn total<'a>(
    netlist: &'a Netlist,
    module: &'a str,
    totals: &mut BTreeMap<&'a str, Resources>,
    stack: &mut Vec<&'a str>,
) -> Result<Resources, String> {
    if let Some(r) = totals.get(module) {
        return Ok(*r);
    }
    if stack.contains(&module) {
        return Err(format!("module `{module}` instantiates itself"));
    }
    let m = netlist
        .modules
        .get(module)
        .ok_or_else(|| format!("no module `{module}`"))?;
    stack.push(module);
    let mut r = Resources::default();
    for cell in m.cells.values() {
        if is_block(netlist, &cell.cell_type) {
            r.add(&total(netlist, &cell.cell_type, totals, stack)?);
        } else {
            r.add_cell(&cell.cell_type, 1);
        }
    }
    stack.pop();
    totals.insert(module, r);
    Ok(r)
}

fn walk<'a>(
    netlist: &'a Netlist,
    module: &'a str,
    path: String,
    depth: usize,
    max_depth: usize,
    totals: &mut BTreeMap<&'a str, Resources>,
    rows: &mut Vec<BlockRow>,
) -> Result<(), String> {
    let resources = total(netlist, module, totals, &mut Vec::new())?;
    rows.push(BlockRow {
        path: path.clone(),
        depth,
        resources,
    });
    if depth == max_depth {
        return Ok(());
    }
    let m = &netlist.modules[module];
    for (name, cell) in &m.cells {
        if is_block(netlist, &cell.cell_type) {
            let name = name.trim_start_matches('\\');
            let child = if path.is_empty() {
                name.to_string()
            } else {
                format!("{path}.{name}")
            };
            walk(
                netlist,
                &cell.cell_type,
                child,
                depth + 1,
                max_depth,
                totals,
                rows,
            )?;
        }
    }
    Ok(())
}

impl BlockReport {
    /// A Markdown table: one row per block, indented by depth, with its share of the top's
    /// LUTs; blocks under half a percent of the LUTs with no multiplier or block RAM (the
    /// many single registers) are left out, the CSV has them.
    pub fn markdown(&self) -> String {
        let top = self.rows.first().map(|r| r.resources).unwrap_or_default();
        let shown = |r: &Resources| {
            200 * r.total_luts() >= top.total_luts() || r.mult18x18 > 0 || r.block_rams > 0
        };
        let mut s = String::new();
        let _ = writeln!(
            s,
            "| block | LUTs | of which RAM/SRL | FFs | MULT18X18 | RAMB16 | share of LUTs |"
        );
        let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|");
        for row in self.rows.iter().filter(|row| shown(&row.resources)) {
            let r = &row.resources;
            let name = if row.path.is_empty() {
                format!("**{}** (whole)", self.top)
            } else {
                format!("{}`{}`", "&nbsp;&nbsp;".repeat(row.depth - 1), row.path)
            };
            let _ = writeln!(
                s,
                "| {name} | {} | {} | {} | {} | {} | {:.1}% |",
                r.total_luts(),
                r.lut_ram_luts,
                r.flip_flops,
                r.mult18x18,
                r.block_rams,
                100.0 * r.total_luts() as f64 / top.total_luts().max(1) as f64
            );
        }
        s
    }

    /// CSV with a header: path, depth and the resource columns.
    pub fn csv(&self) -> String {
        let mut s = String::from("block,depth,luts,lut_ram_luts,flip_flops,mult18x18,block_rams\n");
        for row in &self.rows {
            let r = &row.resources;
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{}",
                if row.path.is_empty() {
                    self.top.as_str()
                } else {
                    row.path.as_str()
                },
                row.depth,
                r.total_luts(),
                r.lut_ram_luts,
                r.flip_flops,
                r.mult18x18,
                r.block_rams
            );
        }
        s
    }
}
