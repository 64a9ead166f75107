//! Tables as CSV (csv crate), Markdown and plain text (comfy-table): the one place the
//! quoting and column layout of dynrt's tables is decided.

use comfy_table::{presets, CellAlignment, ContentArrangement, Table};

/// CSV text of a header and rows: fields quoted exactly where the format needs it (a comma, a
/// quote, a newline), plain fields bare.
pub fn csv_text<S: AsRef<str>>(header: &[S], rows: &[Vec<String>]) -> String {
    let mut w = csv::WriterBuilder::new()
        .flexible(true)
        .from_writer(Vec::new());
    for record in std::iter::once(header.iter().map(AsRef::as_ref).collect::<Vec<&str>>())
        .chain(rows.iter().map(|r| r.iter().map(String::as_str).collect()))
    {
        // Into memory, with rows of any length allowed, the writer has nothing to fail on.
        w.write_record(&record).expect("CSV into memory");
    }
    let bytes = w.into_inner().expect("CSV into memory");
    String::from_utf8(bytes).expect("CSV of UTF-8 fields")
}

/// CSV text of serde records: the header from the first record's field names.
pub fn csv_of<T: serde::Serialize>(rows: &[T]) -> anyhow::Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}

/// A table laid out by comfy-table with `preset`, every column as wide as its widest cell;
/// the columns named in `right` aligned right (numbers).
fn laid_out<S: AsRef<str>>(
    preset: &str,
    header: &[S],
    rows: &[Vec<String>],
    right: &[usize],
) -> String {
    let mut t = Table::new();
    t.load_preset(preset)
        .set_content_arrangement(ContentArrangement::Disabled)
        .set_header(header.iter().map(AsRef::as_ref));
    for r in rows {
        t.add_row(r);
    }
    for &i in right {
        if let Some(c) = t.column_mut(i) {
            c.set_cell_alignment(CellAlignment::Right);
        }
    }
    // Trailing blanks of the last column would only pad the lines.
    let mut s = t.trim_fmt();
    s.push('\n');
    s
}

/// comfy-table's preset string (one character per border part, in `TableComponent` order):
/// no borders and no lines but a rule of `-` under the header.
const RULE_UNDER_HEADER: &str = "     -             ";

/// A Markdown table whose columns also line up in the text.
pub fn markdown_table<S: AsRef<str>>(header: &[S], rows: &[Vec<String>]) -> String {
    // `|` inside a cell would end it.
    let rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|c| c.replace('|', "\\|")).collect())
        .collect();
    laid_out(presets::ASCII_MARKDOWN, header, &rows, &[])
}

/// A plain-text table for the terminal: space-separated columns, a rule under the header, the
/// columns in `right` aligned right.
pub fn text_table<S: AsRef<str>>(header: &[S], rows: &[Vec<String>], right: &[usize]) -> String {
    laid_out(RULE_UNDER_HEADER, header, rows, right)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_table_columns_stay_in_line_whatever_the_cell_widths() {
        let rows = vec![
            vec![
                "a_very_long_case_name_here".into(),
                "1".into(),
                "note".into(),
            ],
            vec!["b".into(), "123456".into(), String::new()],
        ];
        let t = text_table(&["case", "rays", "note"], &rows, &[1]);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 4, "{t}");
        assert!(lines[1].chars().all(|c| c == '-'), "{t}");
        // "rays", 1 and 123456 end at the same column (right-aligned), after the longest name.
        let end = |l: &str, n: &str| l.find(n).map(|i| i + n.len());
        let rays = end(lines[0], "rays");
        assert_eq!(end(lines[2], " 1"), rays, "{t}");
        assert_eq!(end(lines[3], "123456"), rays, "{t}");
        assert!(
            rays.unwrap() > " a_very_long_case_name_here 123456".len(),
            "{t}"
        );
    }

    #[test]
    fn markdown_cells_with_a_bar_stay_one_cell() {
        let md = markdown_table(&["x"], &[vec!["a|b".into()]]);
        assert!(md.contains("a\\|b"), "{md}");
    }
}
