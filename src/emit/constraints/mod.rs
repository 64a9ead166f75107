//! Xilinx UCF timing and I/O constraints for the processor's top level on a Virtex-II
//! XC2V6000-4 in the FF1152 package (the FPGA of the Alpha Data ADM-XRC-II, the paper's board).
//!
//! Contract of [`ucf_text`] / [`write_ucf`]:
//! - `CONFIG PART = xc2v6000-ff1152-4;` (configurable, [`UcfOptions::part`]).
//! - Per clock port (`PortKind::Clock { hz }`):
//!   `NET "clock" TNM_NET = "clock";` and
//!   `TIMESPEC "TS_clock" = PERIOD "clock" 11.111 ns HIGH 50%;` (period `1e9 / hz` ns, three
//!   decimals: 90 MHz -> 11.111 ns, 25.175 MHz -> 39.722 ns). With several clocks and
//!   [`UcfOptions::asynchronous_clocks`] (the default), every pair of clock groups gets a
//!   `FROM .. TO .. TIG` in both directions: the system clock and the VGA pixel clock come
//!   from separate oscillators, so paths between them must go through synchronisers or a
//!   dual-clock memory and are not timed.
//! - Per port: `NET "name" IOSTANDARD = LVTTL;` (`NET "name<*>"` for a bus), the standard
//!   from the board file's `[iostandard]` table, else [`UcfOptions::iostandards`], else
//!   [`UcfOptions::default_iostandard`]; every standard is checked against the Virtex-II list
//!   ([`VIRTEX2_IOSTANDARDS`]).
//! - OFFSET constraints only where asked ([`UcfOptions::offsets`]): the global form
//!   `OFFSET = IN 4.000 ns BEFORE "clock";` / `OFFSET = OUT 6.000 ns AFTER "clock";`. There
//!   is no default: the right values depend on the board's trace delays and the SRAMs'
//!   timing, which we do not have.
//! - Pin locations (`NET "vga_hsync" LOC = "B12";`) only from a board description
//!   ([`BoardPins`], loaded from `boards/*.toml` by [`load_board`]), never invented. A board
//!   entry that names no bit of a top-level port, a pin that is not a ball name (one or two
//!   letters then one or two digits, e.g. `AK17`), or a ball used twice is an error naming
//!   the file and the entry. Port bits without a pin are listed in comments (the place-and-route
//!   tool then chooses, which is only good for a timing estimate).
//!
//! Bit names follow UCF bus notation: a 1-bit port is `name`, bit 3 of a bus is `name<3>`.
//! No tool here reads UCF (yosys does not), so the tests check the text's structure.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::output::write_atomically;

/// The paper's FPGA: XC2V6000, FF1152 package, speed grade -4 (ISE part name).
pub const XC2V6000_FF1152_4: &str = "xc2v6000-ff1152-4";

/// Virtex-II I/O standards (data sheet DS031), single-ended and differential.
pub const VIRTEX2_IOSTANDARDS: &[&str] = &[
    "LVTTL",
    "LVCMOS33",
    "LVCMOS25",
    "LVCMOS18",
    "LVCMOS15",
    "PCI33_3",
    "PCI66_3",
    "PCIX",
    "GTL",
    "GTLP",
    "HSTL_I",
    "HSTL_II",
    "HSTL_III",
    "HSTL_IV",
    "SSTL3_I",
    "SSTL3_II",
    "SSTL2_I",
    "SSTL2_II",
    "AGP",
    "LVDS_25",
    "LVDS_33",
    "LVDSEXT_25",
    "LVDSEXT_33",
    "LVPECL_33",
    "BLVDS_25",
    "LDT_25",
    "ULVDS_25",
];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortDirection {
    Input,
    Output,
    Inout,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PortKind {
    /// A clock input of `hz` hertz.
    Clock { hz: f64 },
    /// Any other signal.
    Io,
}

/// A top-level port of the design.
#[derive(Clone, Debug, PartialEq)]
pub struct Port {
    pub name: String,
    pub width: u32,
    pub direction: PortDirection,
    pub kind: PortKind,
}

impl Port {
    pub fn clock(name: impl Into<String>, hz: f64) -> Port {
        Port {
            name: name.into(),
            width: 1,
            direction: PortDirection::Input,
            kind: PortKind::Clock { hz },
        }
    }
    pub fn io(name: impl Into<String>, width: u32, direction: PortDirection) -> Port {
        Port {
            name: name.into(),
            width,
            direction,
            kind: PortKind::Io,
        }
    }
    /// The UCF names of the port's bits: `name` for one bit, `name<0>`.. for a bus.
    pub fn bit_names(&self) -> Vec<String> {
        if self.width == 1 {
            vec![self.name.clone()]
        } else {
            (0..self.width)
                .map(|i| format!("{}<{i}>", self.name))
                .collect()
        }
    }
}

/// Global OFFSET constraints of the inputs and outputs registered by one clock.
#[derive(Clone, Debug, PartialEq)]
pub struct ClockOffsets {
    pub clock: String,
    /// `OFFSET = IN <ns> BEFORE "clock"`: input data valid this long before the edge.
    pub in_before_ns: Option<f64>,
    /// `OFFSET = OUT <ns> AFTER "clock"`: outputs valid at most this long after the edge.
    pub out_after_ns: Option<f64>,
}

/// Pin locations and I/O standards of a board, from a `boards/*.toml` file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoardPins {
    /// The file it was read from (named in every error).
    pub source: PathBuf,
    pub name: Option<String>,
    /// The board's FPGA part, if the file names one (must match the UCF's part).
    pub part: Option<String>,
    /// Port bit name (`vga_hsync`, `sram0_addr<3>`) -> ball (`B12`).
    pub pins: BTreeMap<String, String>,
    /// Port name -> I/O standard.
    pub iostandard: BTreeMap<String, String>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BoardFile {
    name: Option<String>,
    part: Option<String>,
    #[serde(default)]
    pins: BTreeMap<String, String>,
    #[serde(default)]
    iostandard: BTreeMap<String, String>,
}

/// Reads a board description (see `boards/README.md` for the format).
pub fn load_board(path: &Path) -> Result<BoardPins> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read board file {}", path.display()))?;
    parse_board(&text, path)
}

/// [`load_board`] on text; `source` names the file in errors.
pub fn parse_board(text: &str, source: &Path) -> Result<BoardPins> {
    let file: BoardFile = toml::from_str(text)
        .with_context(|| format!("board file {} is not valid", source.display()))?;
    let mut balls: BTreeMap<String, String> = BTreeMap::new();
    let mut pins = BTreeMap::new();
    for (bit, ball) in file.pins {
        let ball_uc = ball.trim().to_ascii_uppercase();
        if !is_ball_name(&ball_uc) {
            bail!(
                "board file {}: [pins] entry `{bit} = \"{ball}\"`: `{ball}` is not a Virtex-II \
                 ball name (one or two letters then one or two digits, e.g. \"AK17\")",
                source.display()
            );
        }
        if let Some(other) = balls.insert(ball_uc.clone(), bit.clone()) {
            bail!(
                "board file {}: [pins] entries `{other}` and `{bit}` both use ball {ball_uc}",
                source.display()
            );
        }
        pins.insert(bit, ball_uc);
    }
    for (port, standard) in &file.iostandard {
        if !VIRTEX2_IOSTANDARDS.contains(&standard.as_str()) {
            bail!(
                "board file {}: [iostandard] entry `{port} = \"{standard}\"`: not a Virtex-II \
                 I/O standard (one of {})",
                source.display(),
                VIRTEX2_IOSTANDARDS.join(", ")
            );
        }
    }
    Ok(BoardPins {
        source: source.to_path_buf(),
        name: file.name,
        part: file.part,
        pins,
        iostandard: file.iostandard,
    })
}

/// One or two letters then one or two digits (FF1152 balls run from A1 to AP34).
fn is_ball_name(s: &str) -> bool {
    let letters = s.chars().take_while(|c| c.is_ascii_uppercase()).count();
    let digits = &s[letters..];
    (1..=2).contains(&letters)
        && (1..=2).contains(&digits.len())
        && digits.chars().all(|c| c.is_ascii_digit())
        && !digits.starts_with('0')
}

/// What goes into the UCF besides the ports.
#[derive(Clone, Debug, PartialEq)]
pub struct UcfOptions {
    pub part: String,
    pub default_iostandard: String,
    /// Port name -> I/O standard (the board file's table wins).
    pub iostandards: BTreeMap<String, String>,
    pub offsets: Vec<ClockOffsets>,
    /// Declare every pair of clocks unrelated (`TIG` between their groups).
    pub asynchronous_clocks: bool,
    pub board: Option<BoardPins>,
    /// The header the file starts with.
    pub generated_by: crate::provenance::GeneratedBy,
}

impl Default for UcfOptions {
    fn default() -> Self {
        UcfOptions {
            part: XC2V6000_FF1152_4.to_string(),
            default_iostandard: "LVTTL".to_string(),
            iostandards: BTreeMap::new(),
            offsets: Vec::new(),
            asynchronous_clocks: true,
            board: None,
            generated_by: crate::provenance::GeneratedBy::library(),
        }
    }
}

fn is_net_name(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(f) if f.is_ascii_alphabetic() || f == '_')
        && c.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Nanoseconds with three decimals.
fn ns(x: f64) -> String {
    format!("{x:.3}")
}

/// The clock period of `hz` in ns, as written in the UCF.
pub fn period_ns(hz: f64) -> String {
    ns(1e9 / hz)
}

fn check_ports(ports: &[Port]) -> Result<()> {
    let mut seen = BTreeSet::new();
    for p in ports {
        if !is_net_name(&p.name) {
            bail!(
                "port `{}`: not a valid net name (letters, digits, '_')",
                p.name
            );
        }
        if !seen.insert(p.name.as_str()) {
            bail!("port `{}` is listed twice", p.name);
        }
        if p.width == 0 {
            bail!("port `{}` has width 0", p.name);
        }
        if let PortKind::Clock { hz } = p.kind {
            if p.width != 1 || p.direction != PortDirection::Input {
                bail!("clock port `{}` must be a 1-bit input", p.name);
            }
            if !(hz.is_finite() && hz > 0.0) {
                bail!("clock port `{}`: frequency {hz} Hz is not positive", p.name);
            }
        }
    }
    Ok(())
}

fn check_board(board: &BoardPins, ports: &[Port], part: &str) -> Result<()> {
    let file = board.source.display();
    if let Some(bp) = &board.part {
        if !bp.eq_ignore_ascii_case(part) {
            bail!("board file {file}: part `{bp}` but the constraints are for `{part}`");
        }
    }
    let bits: BTreeSet<String> = ports.iter().flat_map(Port::bit_names).collect();
    for bit in board.pins.keys() {
        if !bits.contains(bit) {
            let hint = match ports
                .iter()
                .find(|p| bit.starts_with(&format!("{}<", p.name)))
            {
                Some(p) => format!("port `{}` has bits 0..{}", p.name, p.width),
                None if ports.iter().any(|p| p.name == *bit) => {
                    "that port is a bus: name each bit as `port<i>`".to_string()
                }
                None => "no top-level port has that name".to_string(),
            };
            bail!("board file {file}: [pins] entry `{bit}`: unknown port bit ({hint})");
        }
    }
    for port in board.iostandard.keys() {
        if !ports.iter().any(|p| p.name == *port) {
            bail!(
                "board file {file}: [iostandard] entry `{port}`: no top-level port has that name"
            );
        }
    }
    Ok(())
}

/// The UCF text for `ports` (see the module doc).
pub fn ucf_text(ports: &[Port], opts: &UcfOptions) -> Result<String> {
    check_ports(ports)?;
    if let Some(b) = &opts.board {
        check_board(b, ports, &opts.part)?;
    }
    for (port, standard) in &opts.iostandards {
        if !ports.iter().any(|p| p.name == *port) {
            bail!("I/O standard given for `{port}`, which is not a top-level port");
        }
        if !VIRTEX2_IOSTANDARDS.contains(&standard.as_str()) {
            bail!("`{standard}` (for `{port}`) is not a Virtex-II I/O standard");
        }
    }
    if !VIRTEX2_IOSTANDARDS.contains(&opts.default_iostandard.as_str()) {
        bail!(
            "default I/O standard `{}` is not a Virtex-II I/O standard",
            opts.default_iostandard
        );
    }
    let clocks: Vec<(&Port, f64)> = ports
        .iter()
        .filter_map(|p| match p.kind {
            PortKind::Clock { hz } => Some((p, hz)),
            PortKind::Io => None,
        })
        .collect();
    for o in &opts.offsets {
        if !clocks.iter().any(|(p, _)| p.name == o.clock) {
            bail!(
                "OFFSET constraints refer to `{}`, which is not a clock port",
                o.clock
            );
        }
    }

    let mut u = opts.generated_by.comment("#");
    writeln!(u, "# Constraints for part {}.", opts.part)?;
    if let Some(b) = &opts.board {
        writeln!(
            u,
            "# Pins from {}{}.",
            b.source.display(),
            b.name
                .as_ref()
                .map(|n| format!(" ({n})"))
                .unwrap_or_default()
        )?;
    }
    writeln!(u, "CONFIG PART = {};", opts.part)?;
    writeln!(u, "\n# Clocks")?;
    for (p, hz) in &clocks {
        writeln!(u, "# {}: {:.3} MHz", p.name, hz / 1e6)?;
        writeln!(u, "NET \"{0}\" TNM_NET = \"{0}\";", p.name)?;
        writeln!(
            u,
            "TIMESPEC \"TS_{0}\" = PERIOD \"{0}\" {1} ns HIGH 50%;",
            p.name,
            period_ns(*hz)
        )?;
    }
    if opts.asynchronous_clocks && clocks.len() > 1 {
        writeln!(
            u,
            "# Unrelated clocks: crossings go through synchronisers or dual-clock memories."
        )?;
        for (a, _) in &clocks {
            for (b, _) in &clocks {
                if a.name != b.name {
                    writeln!(
                        u,
                        "TIMESPEC \"TS_{0}_to_{1}\" = FROM \"{0}\" TO \"{1}\" TIG;",
                        a.name, b.name
                    )?;
                }
            }
        }
    }
    if !opts.offsets.is_empty() {
        writeln!(u, "\n# Pad timing")?;
        for o in &opts.offsets {
            if let Some(t) = o.in_before_ns {
                writeln!(u, "OFFSET = IN {} ns BEFORE \"{}\";", ns(t), o.clock)?;
            }
            if let Some(t) = o.out_after_ns {
                writeln!(u, "OFFSET = OUT {} ns AFTER \"{}\";", ns(t), o.clock)?;
            }
        }
    }
    writeln!(u, "\n# I/O standards")?;
    for p in ports {
        let standard = opts
            .board
            .as_ref()
            .and_then(|b| b.iostandard.get(&p.name))
            .or_else(|| opts.iostandards.get(&p.name))
            .unwrap_or(&opts.default_iostandard);
        let net = if p.width == 1 {
            p.name.clone()
        } else {
            format!("{}<*>", p.name)
        };
        writeln!(u, "NET \"{net}\" IOSTANDARD = {standard};")?;
    }
    writeln!(u, "\n# Pin locations")?;
    let pins = opts.board.as_ref().map(|b| &b.pins);
    let mut unplaced = Vec::new();
    let mut unplaced_bits = 0;
    for p in ports {
        let mut missing = Vec::new();
        for (i, bit) in p.bit_names().into_iter().enumerate() {
            match pins.and_then(|m| m.get(&bit)) {
                Some(ball) => writeln!(u, "NET \"{bit}\" LOC = \"{ball}\";")?,
                None => missing.push(i as u32),
            }
        }
        unplaced_bits += missing.len();
        if p.width == 1 && !missing.is_empty() {
            unplaced.push(p.name.clone());
        } else if !missing.is_empty() {
            unplaced.push(format!("{} bits {}", p.name, ranges(&missing)));
        }
    }
    if !unplaced.is_empty() {
        writeln!(
            u,
            "# No pin location (no board file entry) for {unplaced_bits} port bit(s):"
        )?;
        for line in unplaced {
            writeln!(u, "#   {line}")?;
        }
    }
    Ok(u)
}

/// `0-2, 4, 6-18` for sorted bit indices.
fn ranges(bits: &[u32]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < bits.len() {
        let mut j = i;
        while j + 1 < bits.len() && bits[j + 1] == bits[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            bits[i].to_string()
        } else {
            format!("{}-{}", bits[i], bits[j])
        });
        i = j + 1;
    }
    out.join(", ")
}

/// Writes [`ucf_text`] to `path` atomically.
pub fn write_ucf(path: &Path, ports: &[Port], opts: &UcfOptions) -> Result<()> {
    let text = ucf_text(ports, opts)?;
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("writing constraints {}", path.display()))
}

#[cfg(test)]
mod tests;
