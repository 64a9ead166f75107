//! The memory banks of a [`Layout`] as Verilog `$readmemh` images, the per-frame updates of an
//! animated scene, and a reader for such files.
//!
//! Contract:
//! - [`write_memory_images`] writes one file per bank, `bank<k>_<name>.hex`
//!   (`bank0_nodes.hex` .. `bank5_frame.hex`, see [`bank_file_name`]): a comment header (the
//!   [`GeneratedBy`] lines, then what the bank holds), an
//!   `@0` record, then every word of the bank's used part (the whole `Layout::banks[k]`, frame
//!   buffer included, so the simulated memory holds no X where the processor may read),
//!   8 hex digits a line. Words past the used part are not written. Each file is written
//!   atomically.
//! - [`frame_update`] lists the words that differ between two layouts of the same scene (two
//!   frames), as `(bank, address, word)` sorted by bank then address, including words that
//!   exist only in `next` (a bank that grew). A bank that shrank keeps stale words past its new
//!   end; the processor never reads them (the new tree does not point there). So loading the
//!   frame-0 images, then applying the updates in order, gives exactly the next frame's words
//!   at every address of the next layout.
//! - [`write_frame_update`] writes those updates as `$readmemh` files with `@address`
//!   records (only the changed words), one file per bank that changed:
//!   `frame<f>_bank<k>_<name>.hex`. `$readmemh` of such a file into the memory already
//!   holding the previous frame updates exactly those words.
//! - Memories larger than an image are fine: neither Icarus nor Verilator warns when a file
//!   fills only part of a memory, but the words it does not write are X in Icarus and 0 in
//!   Verilator, so the processor must not read past a bank's extent.
//! - [`read_memh`] parses `$readmemh` text (`//` and `/* */` comments, `@hex` address records,
//!   hex words with optional `_`), so tests and tools can read the files back.
//! - [`bank_extents`] gives each bank's used size and highest address, to size the
//!   processor's address buses.
//!
//! What changes between frames of an animated scene (measured, and asserted in the tests):
//! never the triangle banks or the `FRAME` bank (camera, lights, materials and the cleared
//! frame buffer are static); in an instance record only the two matrices and the root pointer
//! (never the triangle base or object id).
//! - `scenes/tiny_animated.toml` (3 instances, top-level tree a single leaf in every frame):
//!   only `INSTANCES` changes, only the moving box's and gem's matrix words (23 and 19 of 72
//!   words for frames 0->1 and 1->2).
//! - `scenes/dynamic.toml` (1,202 moving instances), frame 0->1: the top-level tree grows
//!   (9,362 -> 11,914 node words) and, because it comes first in `NODES` with every object
//!   tree behind it, the object trees move: 11,291 `NODES` words, 2,802 `LISTS` words and
//!   15,092 `INSTANCES` words (every root pointer) change, 29,185 words in all. Putting the
//!   object trees first in the layout would confine the update to the top-level part.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::layout::{Layout, BANK_NAMES};
use crate::output::write_atomically;
use crate::provenance::GeneratedBy;

/// `bank<k>_<name>.hex`, e.g. `bank0_nodes.hex`.
pub fn bank_file_name(bank: usize) -> String {
    format!("bank{bank}_{}.hex", BANK_NAMES[bank])
}

/// The name of frame `frame`'s update file for `bank`, e.g. `frame1_bank4_instances.hex`.
pub fn update_file_name(frame: u32, bank: usize) -> String {
    format!("frame{frame}_bank{bank}_{}.hex", BANK_NAMES[bank])
}

/// `$readmemh` text of `(address, word)` pairs (sorted by address): an `@address` record
/// before the first word and wherever the next address is not the previous plus one.
pub fn memh_text(header: &str, words: &[(u32, u32)]) -> String {
    let mut text = String::with_capacity(words.len() * 9 + 64);
    for line in header.lines() {
        let _ = writeln!(text, "// {line}");
    }
    let mut next: Option<u32> = None;
    for &(addr, word) in words {
        if next != Some(addr) {
            let _ = writeln!(text, "@{addr:x}");
        }
        let _ = writeln!(text, "{word:08x}");
        next = addr.checked_add(1);
    }
    text
}

/// Writes the six bank images of `layout` into `dir` (created if needed); returns their
/// paths in bank order.
pub fn write_memory_images(
    layout: &Layout,
    dir: &Path,
    generated_by: &GeneratedBy,
) -> Result<Vec<PathBuf>> {
    let mut paths = Vec::new();
    for (bank, words) in layout.banks.iter().enumerate() {
        let path = dir.join(bank_file_name(bank));
        let pairs: Vec<(u32, u32)> = words
            .iter()
            .enumerate()
            .map(|(a, &w)| (a as u32, w))
            .collect();
        let header = format!(
            "{}\ndynrt memory image: bank {bank} ({}), {} words of 32 bits, format {}",
            generated_by.lines().join("\n"),
            BANK_NAMES[bank],
            words.len(),
            layout.format
        );
        write_atomically(&path, memh_text(&header, &pairs).as_bytes())
            .with_context(|| format!("writing memory image {}", path.display()))?;
        paths.push(path);
    }
    Ok(paths)
}

/// One word to rewrite between frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct WordUpdate {
    pub bank: usize,
    pub addr: u32,
    pub word: u32,
}

/// The words of `next` that differ from `prev` (or lie past `prev`'s end), by bank then
/// address. Fails if the layouts cannot be two frames of one scene (different formats or
/// bank counts).
pub fn frame_update(prev: &Layout, next: &Layout) -> Result<Vec<WordUpdate>> {
    if prev.format != next.format || prev.banks.len() != next.banks.len() {
        bail!(
            "frame update between layouts of different shapes ({} with {} banks, {} with {} \
             banks): both must come from the same scene and format",
            prev.format,
            prev.banks.len(),
            next.format,
            next.banks.len()
        );
    }
    let mut out = Vec::new();
    for (bank, (p, n)) in prev.banks.iter().zip(&next.banks).enumerate() {
        for (addr, &word) in n.iter().enumerate() {
            if p.get(addr) != Some(&word) {
                out.push(WordUpdate {
                    bank,
                    addr: addr as u32,
                    word,
                });
            }
        }
    }
    Ok(out)
}

/// Writes the update from `prev` to `next` (frame number `frame`) into `dir`: one file per bank
/// with changes, named by [`update_file_name`]. Returns `(bank, path)` per file written.
pub fn write_frame_update(
    prev: &Layout,
    next: &Layout,
    frame: u32,
    dir: &Path,
    generated_by: &GeneratedBy,
) -> Result<Vec<(usize, PathBuf)>> {
    let updates = frame_update(prev, next)?;
    let mut written = Vec::new();
    for (bank, name) in BANK_NAMES.iter().enumerate().take(next.banks.len()) {
        let pairs: Vec<(u32, u32)> = updates
            .iter()
            .filter(|u| u.bank == bank)
            .map(|u| (u.addr, u.word))
            .collect();
        if pairs.is_empty() {
            continue;
        }
        let path = dir.join(update_file_name(frame, bank));
        let header = format!(
            "{}\ndynrt frame update: frame {frame}, bank {bank} ({name}), {} changed words",
            generated_by.lines().join("\n"),
            pairs.len()
        );
        write_atomically(&path, memh_text(&header, &pairs).as_bytes())
            .with_context(|| format!("writing frame update {}", path.display()))?;
        written.push((bank, path));
    }
    Ok(written)
}

/// Reads a `$readmemh` file: `(address, word)` in file order. Words are at most 32 bits
/// (8 hex digits); `x`/`z` digits are refused. Errors name the file and line.
pub fn read_memh(path: &Path) -> Result<Vec<(u32, u32)>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read memory image {}", path.display()))?;
    parse_memh(&text).with_context(|| format!("in memory image {}", path.display()))
}

/// [`read_memh`] on text.
pub fn parse_memh(text: &str) -> Result<Vec<(u32, u32)>> {
    let mut out = Vec::new();
    let mut addr: u64 = 0;
    let mut in_block_comment = false;
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        // Strip comments, keeping block-comment state across lines.
        let mut code = String::new();
        let mut rest = raw;
        loop {
            if in_block_comment {
                match rest.find("*/") {
                    Some(end) => {
                        rest = &rest[end + 2..];
                        in_block_comment = false;
                    }
                    None => break,
                }
            } else {
                let line_c = rest.find("//");
                let block = rest.find("/*");
                match (line_c, block) {
                    (Some(l), Some(b)) if l < b => {
                        code.push_str(&rest[..l]);
                        break;
                    }
                    (Some(l), None) => {
                        code.push_str(&rest[..l]);
                        break;
                    }
                    (_, Some(b)) => {
                        code.push_str(&rest[..b]);
                        code.push(' ');
                        rest = &rest[b + 2..];
                        in_block_comment = true;
                    }
                    (None, None) => {
                        code.push_str(rest);
                        break;
                    }
                }
            }
        }
        for token in code.split_whitespace() {
            if let Some(a) = token.strip_prefix('@') {
                addr = parse_hex(a)
                    .with_context(|| format!("line {line_no}: bad address record `{token}`"))?;
                if addr > u32::MAX as u64 {
                    bail!("line {line_no}: address `{token}` exceeds 32 bits");
                }
                continue;
            }
            let word = parse_hex(token).with_context(|| {
                format!(
                    "line {line_no}: `{token}` is not a hex word (x/z digits are not supported)"
                )
            })?;
            if word > u32::MAX as u64 {
                bail!("line {line_no}: word `{token}` is wider than 32 bits");
            }
            if addr > u32::MAX as u64 {
                bail!("line {line_no}: word `{token}` past address 0xffffffff");
            }
            out.push((addr as u32, word as u32));
            addr += 1;
        }
    }
    if in_block_comment {
        bail!("unterminated /* comment");
    }
    Ok(out)
}

fn parse_hex(s: &str) -> Result<u64> {
    let digits: String = s.chars().filter(|&c| c != '_').collect();
    if digits.is_empty() || digits.len() > 16 {
        bail!("`{s}`: expected 1 to 16 hex digits");
    }
    u64::from_str_radix(&digits, 16).map_err(|_| anyhow::anyhow!("`{s}`: not hexadecimal"))
}

/// The used part of one bank.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BankExtent {
    /// Words used (the highest address used plus one; 0 for an empty bank).
    pub words: u32,
    /// The highest address used, `None` for an empty bank.
    pub highest: Option<u32>,
    /// Address bits needed to reach every used word (at least 1).
    pub address_bits: u32,
}

/// Per bank (in bank order) the words used, highest address and address width.
pub fn bank_extents(layout: &Layout) -> Vec<BankExtent> {
    layout
        .banks
        .iter()
        .map(|b| BankExtent::of_words(b.len() as u32))
        .collect()
}

impl BankExtent {
    /// The extent of a bank whose used part is `words` words from address 0.
    pub fn of_words(words: u32) -> BankExtent {
        let highest = words.checked_sub(1);
        BankExtent {
            words,
            highest,
            address_bits: highest.map_or(1, |h| (32 - h.leading_zeros()).max(1)),
        }
    }
}

#[cfg(test)]
mod tests;
