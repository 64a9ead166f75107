//! A small table of benchmark results written as CSV (for tools) and Markdown (for the
//! README), both atomically.

use anyhow::Context;
use std::path::Path;

#[derive(Clone, Debug, Default)]
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new(header: &[&str]) -> Table {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }

    pub fn to_csv(&self) -> String {
        let quote = |s: &String| {
            if s.contains(',') {
                format!("\"{s}\"")
            } else {
                s.clone()
            }
        };
        let mut out = String::new();
        for line in std::iter::once(&self.header).chain(&self.rows) {
            out.push_str(&line.iter().map(quote).collect::<Vec<_>>().join(","));
            out.push('\n');
        }
        out
    }

    pub fn to_markdown(&self) -> String {
        let mut out = format!("| {} |\n", self.header.join(" | "));
        out.push_str(&format!("|{}\n", "---|".repeat(self.header.len())));
        for r in &self.rows {
            out.push_str(&format!("| {} |\n", r.join(" | ")));
        }
        out
    }

    /// Writes `DIR/NAME.csv` and `DIR/NAME.md`.
    pub fn save(&self, dir: &Path, name: &str) -> anyhow::Result<()> {
        for (ext, text) in [("csv", self.to_csv()), ("md", self.to_markdown())] {
            let path = dir.join(format!("{name}.{ext}"));
            crate::output::write_atomically(&path, text.as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quotes_commas_and_markdown_has_one_row_per_result() {
        let mut t = Table::new(&["scene", "value"]);
        t.push(vec!["a,b".into(), "1.5".into()]);
        t.push(vec!["c".into(), "2".into()]);
        assert_eq!(t.to_csv(), "scene,value\n\"a,b\",1.5\nc,2\n");
        assert_eq!(
            t.to_markdown(),
            "| scene | value |\n|---|---|\n| a,b | 1.5 |\n| c | 2 |\n"
        );
    }
}
