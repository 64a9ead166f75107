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
        crate::tables::csv_text(&self.header, &self.rows)
    }

    /// A Markdown table whose columns line up in the text as well as when rendered.
    pub fn to_markdown(&self) -> String {
        crate::tables::markdown_table(&self.header, &self.rows)
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
    fn csv_fields_with_commas_quotes_and_newlines_read_back_whole() {
        let mut t = Table::new(&["scene", "value"]);
        let hostile = "say \"hi\",\nthen go";
        t.push(vec!["a,b".into(), "1.5".into()]);
        t.push(vec![hostile.into(), "2".into()]);
        t.push(vec!["c".into(), String::new()]);
        let text = t.to_csv();
        // Plain fields stay bare, as the bench CSVs always were.
        assert!(text.starts_with("scene,value\n\"a,b\",1.5\n"), "{text}");
        let mut r = csv::Reader::from_reader(text.as_bytes());
        assert_eq!(r.headers().unwrap(), vec!["scene", "value"]);
        let back: Vec<Vec<String>> = r
            .records()
            .map(|rec| rec.unwrap().iter().map(String::from).collect())
            .collect();
        assert_eq!(back, t.rows);
    }

    #[test]
    fn markdown_has_one_row_per_result_and_aligned_columns() {
        let mut t = Table::new(&["scene", "value"]);
        t.push(vec!["a,b".into(), "1.5".into()]);
        t.push(vec!["cornell_noshadow".into(), "2".into()]);
        let md = t.to_markdown();
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines.len(), 4, "{md}");
        assert!(lines[1].chars().all(|c| c == '|' || c == '-'), "{md}");
        // Every line has its `|` at the same columns.
        let bars = |l: &str| -> Vec<usize> { l.match_indices('|').map(|(i, _)| i).collect() };
        for l in &lines {
            assert_eq!(bars(l), bars(lines[0]), "{md}");
        }
        assert_eq!(
            lines[3].split('|').nth(1).unwrap().trim(),
            "cornell_noshadow"
        );
    }
}
