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

use std::collections::{BTreeMap, HashMap};

use serde::Deserialize;

#[derive(Debug, Deserialize)]
pub(crate) struct Netlist {
    pub modules: HashMap<String, Module>,
}

#[derive(Debug, Deserialize)]
pub(crate) struct Module {
    #[serde(default)]
    pub cells: BTreeMap<String, Cell>,
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

/// The longest paths of `module`: (logic_depth, path_cells). Errors on a combinational loop.
pub(crate) fn longest_paths(module: &Module) -> Result<(u32, u32), String> {
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
            a.0 = a.0.max(here.0 + wl);
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
    Ok(best)
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
            cells: cells.into_iter().map(|(n, c)| (n.to_string(), c)).collect(),
        }
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
        assert_eq!(longest_paths(&m).unwrap(), (2, 2));
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
        assert_eq!(longest_paths(&m).unwrap(), (1, 4));
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
        assert_eq!(longest_paths(&m).unwrap(), (2, 2));
        assert!(is_address_port("A3") && is_address_port("DPRA0") && !is_address_port("ADDR"));
    }
}
