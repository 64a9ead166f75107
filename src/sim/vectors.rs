//! Hex vector files of the `dynrt fp` CLI contract (docs/ARCHITECTURE.md, "Vector files").
//!
//! Input: one vector a line, two hex words `a b` separated by whitespace, each fitting the
//! format's width in bits (leading zeros allowed, no `0x`, either case). Blank lines are
//! skipped. Output: one hex word a line, zero-padded to a fixed number of digits, lower case.
//!
//! Contract: a bad input line is an error naming the file, the 1-based line number and the
//! problem (bad hex digit, wrong number of fields, word wider than the format). Output is
//! written to a temporary file in the destination's directory and renamed over the
//! destination, so a reader never sees a half-written file and a failure leaves none behind.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum VectorFileError {
    /// Not a `#[source]`: the message says it, and an error chain would say it twice.
    #[error("{}: {source}", .path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Input(#[from] crate::input::InputError),
    #[error("{}:{line}: {problem}", .path.display())]
    Line {
        path: PathBuf,
        line: usize,
        problem: String,
    },
    #[error("format width must be 1..=32 bits, got {0}")]
    BadWidth(u32),
    #[error(
        "{}: result #{index} = {value:#x} does not fit in {hex_digits} hex digit(s); nothing was written",
        .path.display()
    )]
    ResultTooWide {
        path: PathBuf,
        index: usize,
        value: u32,
        hex_digits: usize,
    },
}

/// Hex digits needed for a word of `width_bits` bits.
pub fn hex_digits_for(width_bits: u32) -> usize {
    width_bits.div_ceil(4) as usize
}

/// Reads the operand pairs of an `fp` vector file whose words are `width_bits` wide.
pub fn read_vector_file(path: &Path, width_bits: u32) -> Result<Vec<(u32, u32)>, VectorFileError> {
    if width_bits == 0 || width_bits > 32 {
        return Err(VectorFileError::BadWidth(width_bits));
    }
    let text = crate::input::read_text(path, "vector file", crate::input::MAX_TABLE_BYTES)?;
    let text = crate::input::normalize_line_endings(&text);
    parse_vectors(&text, width_bits).map_err(|(line, problem)| VectorFileError::Line {
        path: path.to_path_buf(),
        line,
        problem,
    })
}

/// Reads a result file (one hex word a line, e.g. what a testbench wrote), checking that
/// every word fits `width_bits`; blank lines are skipped.
pub fn read_word_file(path: &Path, width_bits: u32) -> Result<Vec<u32>, VectorFileError> {
    if width_bits == 0 || width_bits > 32 {
        return Err(VectorFileError::BadWidth(width_bits));
    }
    let text = crate::input::read_text(path, "vector file", crate::input::MAX_TABLE_BYTES)?;
    let text = crate::input::normalize_line_endings(&text);
    let mut words = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let problem = match fields.as_slice() {
            [] => continue,
            [w] => match parse_word(w, width_bits) {
                Ok(v) => {
                    words.push(v);
                    continue;
                }
                Err(p) => p,
            },
            _ => format!(
                "expected one hex word, found {} fields: `{}`",
                fields.len(),
                line.trim()
            ),
        };
        return Err(VectorFileError::Line {
            path: path.to_path_buf(),
            line: i + 1,
            problem,
        });
    }
    Ok(words)
}

/// Parses vector text; errors are (1-based line, problem).
fn parse_vectors(text: &str, width_bits: u32) -> Result<Vec<(u32, u32)>, (usize, String)> {
    let mut vectors = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let fields: Vec<&str> = line.split_whitespace().collect();
        match fields.as_slice() {
            [] => continue,
            [a, b] => {
                let a =
                    parse_word(a, width_bits).map_err(|p| (line_no, format!("operand a: {p}")))?;
                let b =
                    parse_word(b, width_bits).map_err(|p| (line_no, format!("operand b: {p}")))?;
                vectors.push((a, b));
            }
            _ => {
                return Err((
                    line_no,
                    format!(
                        "expected two hex words `a b`, found {} field(s): `{}`",
                        fields.len(),
                        line.trim()
                    ),
                ))
            }
        }
    }
    Ok(vectors)
}

fn parse_word(word: &str, width_bits: u32) -> Result<u32, String> {
    if let Some(bad) = word.chars().find(|c| !c.is_ascii_hexdigit()) {
        return Err(format!("`{word}` is not hex (bad character `{bad}`)"));
    }
    let significant = word.trim_start_matches('0');
    let too_wide = || format!("`{word}` is wider than the format's {width_bits} bits");
    if significant.len() > 8 {
        return Err(too_wide());
    }
    let value = if significant.is_empty() {
        0
    } else {
        u32::from_str_radix(significant, 16).map_err(|e| format!("`{word}`: {e}"))?
    };
    if width_bits < 32 && value >> width_bits != 0 {
        return Err(too_wide());
    }
    Ok(value)
}

/// Writes one zero-padded lower-case hex word per line to `path`, atomically.
pub fn write_results_atomically(
    path: &Path,
    results: &[u32],
    hex_digits: usize,
) -> Result<(), VectorFileError> {
    if let Some((index, &value)) = results
        .iter()
        .enumerate()
        .find(|(_, &v)| hex_digits < 8 && (v as u64) >> (4 * hex_digits) != 0)
    {
        return Err(VectorFileError::ResultTooWide {
            path: path.to_path_buf(),
            index,
            value,
            hex_digits,
        });
    }
    let mut text = String::with_capacity(results.len() * (hex_digits + 1));
    for v in results {
        text.push_str(&format!("{v:0width$x}\n", width = hex_digits));
    }
    crate::output::write_atomically(path, text.as_bytes()).map_err(|source| {
        VectorFileError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn line_error(r: Result<Vec<(u32, u32)>, VectorFileError>) -> (usize, String, String) {
        match r {
            Err(e @ VectorFileError::Line { .. }) => {
                let msg = e.to_string();
                let VectorFileError::Line { line, problem, .. } = e else {
                    unreachable!()
                };
                (line, problem, msg)
            }
            other => panic!("expected a line error, got {other:?}"),
        }
    }

    #[test]
    fn reads_good_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(
            dir.path(),
            "in.hex",
            "3f8000 BF8000\n\n000001   7fffff\n 0 0 \n",
        );
        assert_eq!(
            read_vector_file(&p, 24).unwrap(),
            vec![(0x3f8000, 0xbf8000), (1, 0x7fffff), (0, 0)]
        );
        let p = write(dir.path(), "in32.hex", "ffffffff 000000000080\n");
        assert_eq!(read_vector_file(&p, 32).unwrap(), vec![(0xffff_ffff, 0x80)]);
    }

    #[test]
    fn bad_hex_names_file_line_and_word() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "bad.hex", "000001 000002\n00000g 1\n");
        let (line, problem, msg) = line_error(read_vector_file(&p, 24));
        assert_eq!(line, 2);
        assert!(
            problem.contains("operand a") && problem.contains("`00000g`"),
            "{problem}"
        );
        assert!(msg.contains("bad.hex:2:"), "{msg}");
        let p = write(dir.path(), "bad0x.hex", "1 0x5\n");
        let (line, problem, _) = line_error(read_vector_file(&p, 24));
        assert_eq!(line, 1);
        assert!(
            problem.contains("operand b") && problem.contains("not hex"),
            "{problem}"
        );
    }

    #[test]
    fn wrong_field_count_is_reported() {
        let dir = tempfile::tempdir().unwrap();
        let p = write(dir.path(), "f.hex", "1 2\n\n1 2 3\n");
        let (line, problem, _) = line_error(read_vector_file(&p, 24));
        assert_eq!(line, 3);
        assert!(problem.contains("found 3 field"), "{problem}");
        let p = write(dir.path(), "g.hex", "abc\n");
        let (line, problem, _) = line_error(read_vector_file(&p, 24));
        assert_eq!(line, 1);
        assert!(problem.contains("found 1 field"), "{problem}");
    }

    #[test]
    fn word_wider_than_format_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        // 0xffffff fits 24 bits; 0x1000000 needs 25.
        let p = write(dir.path(), "w.hex", "ffffff 0\n0 1000000\n");
        let (line, problem, _) = line_error(read_vector_file(&p, 24));
        assert_eq!(line, 2);
        assert!(
            problem.contains("wider than the format's 24 bits"),
            "{problem}"
        );
        // 9 significant digits never fit 32 bits.
        let p = write(dir.path(), "w32.hex", "100000000 0\n");
        let (line, _, _) = line_error(read_vector_file(&p, 32));
        assert_eq!(line, 1);
        // A 17-bit format rejects bit 17.
        let p = write(dir.path(), "w17.hex", "1ffff 20000\n");
        let (_, problem, _) = line_error(read_vector_file(&p, 17));
        assert!(problem.contains("operand b"), "{problem}");
    }

    #[test]
    fn missing_file_and_bad_width() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("nope.hex");
        let e = read_vector_file(&missing, 24).unwrap_err();
        assert!(
            matches!(
                e,
                VectorFileError::Input(crate::input::InputError::Missing { .. })
            ),
            "{e}"
        );
        assert!(e.to_string().contains("nope.hex"), "{e}");
        assert!(matches!(
            read_vector_file(&missing, 33),
            Err(VectorFileError::BadWidth(33))
        ));
    }

    #[test]
    fn writes_padded_results_and_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.hex");
        std::fs::write(&out, "old content that must vanish\n").unwrap();
        write_results_atomically(&out, &[0x3f8000, 0x1, 0xabcdef], 6).unwrap();
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "3f8000\n000001\nabcdef\n"
        );
        write_results_atomically(&out, &[0, 1, 1], 1).unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "0\n1\n1\n");
        // No temporary files remain next to the output.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out.hex")]);
    }

    #[test]
    fn result_files_round_trip_and_bad_words_are_located() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("r.hex");
        write_results_atomically(&out, &[0xabcdef, 0, 0x800000], 6).unwrap();
        assert_eq!(
            read_word_file(&out, 24).unwrap(),
            vec![0xabcdef, 0, 0x800000]
        );
        // Icarus writes x for unknown bits: that must be an error, not a zero.
        let p = write(dir.path(), "x.hex", "000001\n00000x\n");
        let e = read_word_file(&p, 24).unwrap_err().to_string();
        assert!(e.contains("x.hex:2:") && e.contains("not hex"), "{e}");
        let p = write(dir.path(), "two.hex", "1 2\n");
        let e = read_word_file(&p, 24).unwrap_err().to_string();
        assert!(e.contains("two.hex:1:") && e.contains("2 fields"), "{e}");
        assert!(read_word_file(&out, 23).is_err(), "0xabcdef needs 24 bits");
    }

    #[test]
    fn too_wide_result_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.hex");
        let e = write_results_atomically(&out, &[1, 0x1000000], 6).unwrap_err();
        assert!(
            matches!(e, VectorFileError::ResultTooWide { index: 1, .. }),
            "{e}"
        );
        assert!(!out.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn unwritable_directory_is_an_error_naming_the_path() {
        // A directory cannot be created below a regular file, even by root.
        let dir = tempfile::tempdir().unwrap();
        let file = write(dir.path(), "plain", "x");
        let out = file.join("out.hex");
        let e = write_results_atomically(&out, &[1], 6).unwrap_err();
        assert!(e.to_string().contains(&out.display().to_string()), "{e}");
    }
}
