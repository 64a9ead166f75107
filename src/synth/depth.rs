//! Logic depth of a flattened Yosys netlist (its `write_json` form) after `synth_xilinx`.
//!
//! Definition (yosys 0.23's `ltp` cannot give this: its `-noff` only knows Yosys-internal
//! flip-flops, not Xilinx `FDRE`, so its paths run through registers and report loops):
//! a timing path starts at a module input or at the output of a sequential cell (`FD*`, `LD*`,
//! `RAMB*`, `MULT18X18S`) and ends at a module output or a sequential cell's input.
//! - `logic_depth` = the largest number of LUT levels on any such path. `LUT1`..`LUT6` and
//!   `INV` count 1; the asynchronous read of distributed RAM / shift registers (`RAM*X*`,
//!   `SRL16*`, address inputs to data outputs) counts 1; wide-function muxes (`MUXF5`..`MUXF8`),
//!   carry chains (`MUXCY`, `XORCY`, `MULT_AND`), combinational `MULT18X18` and buffers count 0.
//! - `path_cells` = the largest number of logic cells of any kind on a path (every cell
//!   above except buffers counts 1): the carry chain length and hard multipliers show here.
//!
//! The two maxima are taken independently (they may come from different paths).
//!
//! The deepest path's endpoints ([`Depth::start`], [`Depth::end`]) are named by nets: a register
//! or memory by its output net (yosys names a flip-flop's Q net after the Verilog register), a
//! port by its name, each mapped to our block path by [`super::nextpnr_report::block_path`].
//! Among paths of equal depth the one named is arbitrary but fixed for a netlist.

use std::collections::{BTreeMap, HashMap};

use serde::Deserialize;

#[derive(Debug, Deserialize)]
pub(crate) struct Netlist {
    pub modules: HashMap<String, Module>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct Module {
    /// Yosys's module attributes: the cell library's primitives carry `blackbox` (or
    /// `whitebox`) in a netlist that keeps its hierarchy.
    #[serde(default)]
    pub attributes: BTreeMap<String, serde_json::Value>,
    #[serde(default)]
    pub cells: BTreeMap<String, Cell>,
    #[serde(default)]
    pub ports: BTreeMap<String, ModulePort>,
    #[serde(default)]
    pub netnames: BTreeMap<String, NetName>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct ModulePort {
    pub direction: String,
    #[serde(default)]
    pub bits: Vec<serde_json::Value>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct NetName {
    #[serde(default)]
    pub hide_name: u8,
    #[serde(default)]
    pub bits: Vec<serde_json::Value>,
}

/// The longest paths of a module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Depth {
    pub logic_depth: u32,
    pub path_cells: u32,
    /// Where the deepest (in LUT levels) path starts and ends, as block paths.
    pub start: String,
    pub end: String,
}

/// A readable name per net bit: a name the user wrote (yosys's `hide_name` 0, without `$`)
/// when there is one, else any, with `[k]` for a bit of a bus.
fn bit_names(module: &Module) -> HashMap<u64, String> {
    let mut names: HashMap<u64, (u8, String)> = HashMap::new();
    for (name, net) in &module.netnames {
        let rank = if net.hide_name == 0 && !name.contains('$') {
            0
        } else {
            1
        };
        for (k, b) in net.bits.iter().enumerate() {
            let Some(b) = b.as_u64() else { continue };
            let label = if net.bits.len() > 1 {
                format!("{name}[{k}]")
            } else {
                name.clone()
            };
            let better = names
                .get(&b)
                .is_none_or(|(r, l)| (rank, label.len()) < (*r, l.len()));
            if better {
                names.insert(b, (rank, label));
            }
        }
    }
    names.into_iter().map(|(b, (_, l))| (b, l)).collect()
}

fn readable(name: &str) -> String {
    // An I/O buffer's inner net keeps the port's name behind this pass's prefix.
    let name = name.strip_prefix("$iopadmap$").unwrap_or(name);
    super::nextpnr_report::block_path(name).unwrap_or_else(|| name.to_string())
}

#[derive(Debug, Deserialize)]
pub(crate) struct Cell {
    #[serde(rename = "type")]
    pub cell_type: String,
    #[serde(default)]
    pub port_directions: BTreeMap<String, String>,
    #[serde(default)]
    pub connections: BTreeMap<String, Vec<serde_json::Value>>,
}

/// How a cell type takes part in timing paths.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    /// Path endpoint and start point.
    Sequential,
    /// Only address inputs reach the outputs combinationally (distributed RAM, SRL16).
    AsyncReadMemory,
    /// Every input reaches every output.
    Combinational,
}

pub(crate) fn is_flip_flop(t: &str) -> bool {
    t.starts_with("FD")
}

fn role(t: &str) -> Role {
    if is_flip_flop(t) || t.starts_with("LD") || t.starts_with("RAMB") || t == "MULT18X18S" {
        Role::Sequential
    } else if t.starts_with("SRL") || is_distributed_ram(t) {
        Role::AsyncReadMemory
    } else {
        Role::Combinational
    }
}

/// `RAM16X1S`, `RAM32X1D`, `RAM64X1S`, ... (not `RAMB16_*`).
pub(crate) fn is_distributed_ram(t: &str) -> bool {
    t.starts_with("RAM") && !t.starts_with("RAMB") && t.contains('X')
}

fn is_lut(t: &str) -> bool {
    t == "INV" || (t.starts_with("LUT") && t[3..].parse::<u32>().is_ok())
}

fn is_buffer(t: &str) -> bool {
    matches!(
        t,
        "IBUF" | "OBUF" | "IOBUF" | "OBUFT" | "BUFG" | "BUFGP" | "IBUFG" | "BUF"
    )
}

fn is_address_port(port: &str) -> bool {
    let digits_after = |prefix: &str| {
        port.strip_prefix(prefix)
            .is_some_and(|rest| !rest.is_empty() && rest.chars().all(|c| c.is_ascii_digit()))
    };
    port == "A" || port == "DPRA" || digits_after("A") || digits_after("DPRA")
}

/// (lut weight, cell weight) of a cell on a path.
fn weights(t: &str) -> (u32, u32) {
    if is_lut(t) || role(t) == Role::AsyncReadMemory {
        (1, 1)
    } else if is_buffer(t) {
        (0, 0)
    } else {
        (0, 1)
    }
}

/// The longest paths of `module` and where the deepest starts and ends. Errors on a
/// combinational loop.
pub(crate) fn longest_paths(module: &Module) -> Result<Depth, String> {
    let cells: Vec<&Cell> = module.cells.values().collect();
    let names: Vec<&String> = module.cells.keys().collect();
    // Net bit -> index of the combinational / async-read cell driving it.
    let mut driver: HashMap<u64, usize> = HashMap::new();
    for (i, c) in cells.iter().enumerate() {
        if role(&c.cell_type) == Role::Sequential {
            continue;
        }
        for (port, bits) in &c.connections {
            if c.port_directions.get(port).map(String::as_str) == Some("output") {
                for b in bits.iter().filter_map(|b| b.as_u64()) {
                    driver.insert(b, i);
                }
            }
        }
    }
    // Edges driver -> consumer along combinational inputs.
    let mut succs: Vec<Vec<usize>> = vec![Vec::new(); cells.len()];
    let mut indegree = vec![0usize; cells.len()];
    for (i, c) in cells.iter().enumerate() {
        let r = role(&c.cell_type);
        if r == Role::Sequential {
            continue;
        }
        for (port, bits) in &c.connections {
            let dir = c.port_directions.get(port).map(String::as_str);
            if dir != Some("input") || (r == Role::AsyncReadMemory && !is_address_port(port)) {
                continue;
            }
            for b in bits.iter().filter_map(|b| b.as_u64()) {
                if let Some(&d) = driver.get(&b) {
                    succs[d].push(i);
                    indegree[i] += 1;
                }
            }
        }
    }
    // The start of the deepest path into each cell: the net bit (a register's output or an
    // input port) it reads directly, until a deeper path through another cell replaces it.
    let mut origin: Vec<Option<u64>> = vec![None; cells.len()];
    for (i, c) in cells.iter().enumerate() {
        let r = role(&c.cell_type);
        if r == Role::Sequential {
            continue;
        }
        origin[i] = c
            .connections
            .iter()
            .filter(|(port, _)| {
                c.port_directions.get(*port).map(String::as_str) == Some("input")
                    && (r != Role::AsyncReadMemory || is_address_port(port))
            })
            .flat_map(|(_, bits)| bits.iter().filter_map(|b| b.as_u64()))
            .find(|b| !driver.contains_key(b));
    }
    // Kahn's algorithm: arrival[i] = longest path ending at the output of cell i.
    let mut arrival: Vec<(u32, u32)> = cells.iter().map(|c| weights(&c.cell_type)).collect();
    let mut ready: Vec<usize> = (0..cells.len())
        .filter(|&i| indegree[i] == 0 && role(&cells[i].cell_type) != Role::Sequential)
        .collect();
    let mut done = 0usize;
    let mut best = (0u32, 0u32);
    while let Some(i) = ready.pop() {
        done += 1;
        let here = arrival[i];
        best = (best.0.max(here.0), best.1.max(here.1));
        for &s in &succs[i] {
            let (wl, wc) = weights(&cells[s].cell_type);
            let a = &mut arrival[s];
            let through = here.0 + wl;
            if through > a.0 || (through == a.0 && origin[s].is_none()) {
                origin[s] = origin[i];
            }
            a.0 = a.0.max(through);
            a.1 = a.1.max(here.1 + wc);
            indegree[s] -= 1;
            if indegree[s] == 0 {
                ready.push(s);
            }
        }
    }
    let combinational = cells
        .iter()
        .filter(|c| role(&c.cell_type) != Role::Sequential)
        .count();
    if done != combinational {
        let stuck: Vec<&str> = (0..cells.len())
            .filter(|&i| indegree[i] > 0)
            .take(5)
            .map(|i| names[i].as_str())
            .collect();
        return Err(format!(
            "combinational loop through {} cell(s), e.g. {}",
            combinational - done,
            stuck.join(", ")
        ));
    }
    let (start, end) = deepest_endpoints(module, &cells, &driver, &arrival, &origin, best.0);
    Ok(Depth {
        logic_depth: best.0,
        path_cells: best.1,
        start,
        end,
    })
}

/// Names the start and end of a path of `depth` LUT levels that ends at a register, a memory
/// or an output port.
fn deepest_endpoints(
    module: &Module,
    cells: &[&Cell],
    driver: &HashMap<u64, usize>,
    arrival: &[(u32, u32)],
    origin: &[Option<u64>],
    depth: u32,
) -> (String, String) {
    let names = bit_names(module);
    let bit_label = |b: u64| {
        names
            .get(&b)
            .cloned()
            .unwrap_or_else(|| format!("net bit {b}"))
    };
    // (depth, driving cell, endpoint name) of every endpoint that logic drives.
    let mut best: Option<(u32, usize, String)> = None;
    let mut consider = |bit: u64, end: &dyn Fn() -> String| {
        if let Some(&d) = driver.get(&bit) {
            if best.as_ref().is_none_or(|(b, _, _)| arrival[d].0 > *b) {
                best = Some((arrival[d].0, d, end()));
            }
        }
    };
    for (name, p) in &module.ports {
        if p.direction == "output" {
            for b in p.bits.iter().filter_map(|b| b.as_u64()) {
                consider(b, &|| format!("output port {name}"));
            }
        }
    }
    let cell_names: Vec<&String> = module.cells.keys().collect();
    for (i, c) in cells.iter().enumerate() {
        let r = role(&c.cell_type);
        let outputs = || {
            c.connections
                .iter()
                .filter(|(p, _)| c.port_directions.get(*p).map(String::as_str) == Some("output"))
                .flat_map(|(_, bits)| bits.iter().filter_map(|b| b.as_u64()))
                .next()
        };
        let name_of_cell = || match outputs() {
            Some(b) if names.contains_key(&b) => readable(&bit_label(b)),
            _ => readable(cell_names[i]),
        };
        for (port, bits) in &c.connections {
            let input = c.port_directions.get(port).map(String::as_str) == Some("input");
            let ends_here = match r {
                Role::Sequential => true,
                // Write data and enables of a distributed RAM end a path; its address does not.
                Role::AsyncReadMemory => !is_address_port(port),
                Role::Combinational => false,
            };
            if input && ends_here {
                for b in bits.iter().filter_map(|b| b.as_u64()) {
                    consider(b, &name_of_cell);
                }
            }
        }
    }
    match best {
        Some((d, cell, end)) if d == depth => {
            let start = origin[cell]
                .map(|b| readable(&bit_label(b)))
                .unwrap_or_else(|| "a constant".to_string());
            (start, end)
        }
        // The deepest logic feeds no endpoint (yosys leaves such logic only when asked not to
        // clean up); say so rather than name a shallower path.
        _ => (
            "(deepest logic drives no register or port)".to_string(),
            String::new(),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cell(t: &str, ports: &[(&str, &str, u64)]) -> Cell {
        Cell {
            cell_type: t.to_string(),
            port_directions: ports
                .iter()
                .map(|(p, d, _)| (p.to_string(), d.to_string()))
                .collect(),
            connections: ports
                .iter()
                .map(|(p, _, b)| (p.to_string(), vec![serde_json::Value::from(*b)]))
                .collect(),
        }
    }

    fn module(cells: Vec<(&str, Cell)>) -> Module {
        Module {
            attributes: BTreeMap::new(),
            cells: cells.into_iter().map(|(n, c)| (n.to_string(), c)).collect(),
            ports: BTreeMap::new(),
            netnames: BTreeMap::new(),
        }
    }

    fn depths(m: &Module) -> (u32, u32) {
        let d = longest_paths(m).unwrap();
        (d.logic_depth, d.path_cells)
    }

    #[test]
    fn registers_cut_paths_and_luts_count() {
        // in(1) -> LUT -> LUT -> FF -> LUT -> MUXF5 -> out: depths 2 and 1 (+MUXF5 = 2 cells).
        let m = module(vec![
            (
                "l1",
                cell("LUT4", &[("I0", "input", 1), ("O", "output", 2)]),
            ),
            (
                "l2",
                cell("LUT2", &[("I0", "input", 2), ("O", "output", 3)]),
            ),
            (
                "ff",
                cell(
                    "FDRE",
                    &[("D", "input", 3), ("C", "input", 9), ("Q", "output", 4)],
                ),
            ),
            (
                "l3",
                cell("LUT3", &[("I0", "input", 4), ("O", "output", 5)]),
            ),
            (
                "mf",
                cell(
                    "MUXF5",
                    &[("I0", "input", 5), ("S", "input", 1), ("O", "output", 6)],
                ),
            ),
        ]);
        assert_eq!(depths(&m), (2, 2));
    }

    #[test]
    fn deepest_path_is_named_by_its_start_and_end_nets() {
        // port x -> LUT -> LUT -> FF (Q net mid_norm__q) -> LUT -> port y.
        let mut m = module(vec![
            (
                "l1",
                cell("LUT4", &[("I0", "input", 1), ("O", "output", 2)]),
            ),
            (
                "l2",
                cell("LUT2", &[("I0", "input", 2), ("O", "output", 3)]),
            ),
            (
                "$auto$ff$9",
                cell(
                    "FDRE",
                    &[("D", "input", 3), ("C", "input", 9), ("Q", "output", 4)],
                ),
            ),
            (
                "l3",
                cell("LUT3", &[("I0", "input", 4), ("O", "output", 5)]),
            ),
        ]);
        let net = |hide: u8, bits: &[u64]| NetName {
            hide_name: hide,
            bits: bits.iter().map(|&b| serde_json::Value::from(b)).collect(),
        };
        let port = |dir: &str, b: u64| ModulePort {
            direction: dir.into(),
            bits: vec![serde_json::Value::from(b)],
        };
        m.netnames.insert("x".into(), net(0, &[1]));
        m.netnames.insert("$abc$3".into(), net(1, &[2]));
        m.netnames
            .insert("core.mid_norm__q".into(), net(0, &[7, 4]));
        m.netnames.insert("y".into(), net(0, &[5]));
        m.ports.insert("x".into(), port("input", 1));
        m.ports.insert("y".into(), port("output", 5));
        let d = longest_paths(&m).unwrap();
        assert_eq!(
            (d.logic_depth, d.start.as_str(), d.end.as_str()),
            (2, "x", "core.mid_norm.q")
        );
    }

    #[test]
    fn carry_chain_counts_cells_not_luts() {
        let m = module(vec![
            ("l", cell("LUT2", &[("I0", "input", 1), ("O", "output", 2)])),
            (
                "c0",
                cell(
                    "MUXCY",
                    &[("S", "input", 2), ("CI", "input", 1), ("O", "output", 3)],
                ),
            ),
            (
                "c1",
                cell(
                    "MUXCY",
                    &[("S", "input", 2), ("CI", "input", 3), ("O", "output", 4)],
                ),
            ),
            (
                "x",
                cell(
                    "XORCY",
                    &[("CI", "input", 4), ("LI", "input", 2), ("O", "output", 5)],
                ),
            ),
        ]);
        assert_eq!(depths(&m), (1, 4));
    }

    #[test]
    fn loop_is_reported() {
        let m = module(vec![
            ("a", cell("LUT1", &[("I0", "input", 2), ("O", "output", 1)])),
            ("b", cell("LUT1", &[("I0", "input", 1), ("O", "output", 2)])),
        ]);
        assert!(longest_paths(&m).unwrap_err().contains("loop"));
    }

    #[test]
    fn distributed_ram_read_is_a_level_but_write_data_is_not() {
        let m = module(vec![
            ("l", cell("LUT4", &[("I0", "input", 1), ("O", "output", 2)])),
            (
                "r",
                cell(
                    "RAM16X1S",
                    &[("A0", "input", 7), ("D", "input", 2), ("O", "output", 3)],
                ),
            ),
            (
                "l2",
                cell("LUT4", &[("I0", "input", 3), ("O", "output", 4)]),
            ),
        ]);
        // LUT -> RAM data input ends a path (depth 1); RAM read -> LUT is 2 levels.
        assert_eq!(depths(&m), (2, 2));
        assert!(is_address_port("A3") && is_address_port("DPRA0") && !is_address_port("ADDR"));
    }
}
