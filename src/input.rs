//! Reading input files so that a hostile path cannot hang or exhaust the machine: only regular
//! files are opened (a FIFO would block in `open` forever, `/dev/zero` and `/dev/urandom` never
//! end), and no file is read past a cap that no scene for the board could need.
//!
//! Contract: [`read_bytes`] and [`read_text`] look at the file's metadata (following symlinks,
//! so a link to a regular file is fine) before opening it, refuse anything but a regular file,
//! refuse a file larger than the cap from its size alone, and read at most `cap + 1` bytes even
//! if the file grows while it is read. Every error names the file, what it was read as, the
//! problem and what to do.

use std::io::Read;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// The board holds 6 banks of 4 MB; a text file describing 24 MB of words is at most a few
/// hundred MB (an OBJ spends about 40 bytes per vertex and 30 per face), so 256 MiB is far
/// above any scene that fits, and far below what would exhaust the machine.
pub const MAX_MESH_BYTES: u64 = 256 << 20;
/// A scene TOML is a camera, lights and a list of objects and instances: 16 MiB is thousands of
/// times the bundled ones and still more than the 43,690 instances the processor holds written out by hand.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// A material library: 16 MiB is millions of materials.
pub const MAX_MTL_BYTES: u64 = 16 << 20;
/// Operand vectors and hits files: a 4096x4096 frame's hits file is about 600 MB.
pub const MAX_TABLE_BYTES: u64 = 1 << 30;
/// An image to compare: a 4096x4096 PNG is at most about 50 MB uncompressed.
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;

#[derive(Debug, Error)]
pub enum InputError {
    #[error("{what} '{path}' does not exist; check the path")]
    Missing { what: String, path: PathBuf },
    #[error("{what} '{path}' is {kind}, not a regular file; give the path of a file")]
    NotRegular {
        what: String,
        path: PathBuf,
        kind: &'static str,
    },
    #[error("{what} '{path}' is {size} bytes, more than the {cap}-byte limit for {what}s; no scene that fits the board's six 4 MB banks needs a file that large")]
    TooLarge {
        what: String,
        path: PathBuf,
        size: u64,
        cap: u64,
    },
    #[error(
        "{what} '{path}' is not UTF-8 text (first bad byte at offset {offset}); save it as UTF-8"
    )]
    NotText {
        what: String,
        path: PathBuf,
        offset: usize,
    },
    #[error("{what} '{path}' is not bundled with dynrt; the bundled scenes are {known} (`dynrt scenes list` names every bundled file)")]
    NotBundled {
        what: String,
        path: PathBuf,
        known: String,
    },
    #[error("{what} '{path}' cannot be read: {source}; check the path and permissions")]
    Io {
        what: String,
        path: PathBuf,
        source: std::io::Error,
    },
}

/// What kind of file system object `t` is, for messages.
pub(crate) fn kind_name(t: std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_file() {
        "a regular file"
    } else if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a named pipe (FIFO)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_symlink() {
        "a symbolic link"
    } else {
        "a special file"
    }
}

/// The bytes of the regular file `path`, at most `cap` of them; `what` names the file's role
/// ("scene file", "mesh", ...) in errors. A bundled path (`bundled:/tiny.toml`, see
/// [`crate::bundled`]) is served from the binary, under the same cap.
pub fn read_bytes(path: &Path, what: &str, cap: u64) -> Result<Vec<u8>, InputError> {
    let too_large = |size| InputError::TooLarge {
        what: what.to_string(),
        path: path.to_path_buf(),
        size,
        cap,
    };
    if crate::bundled::is_bundled(path) {
        let bytes = crate::bundled::contents(path).ok_or_else(|| InputError::NotBundled {
            what: what.to_string(),
            path: path.to_path_buf(),
            known: crate::bundled::scene_names().join(", "),
        })?;
        if bytes.len() as u64 > cap {
            return Err(too_large(bytes.len() as u64));
        }
        return Ok(bytes.to_vec());
    }
    let io = |source: std::io::Error| InputError::Io {
        what: what.to_string(),
        path: path.to_path_buf(),
        source,
    };
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(InputError::Missing {
                what: what.to_string(),
                path: path.to_path_buf(),
            })
        }
        Err(e) => return Err(io(e)),
    };
    if !meta.file_type().is_file() {
        return Err(InputError::NotRegular {
            what: what.to_string(),
            path: path.to_path_buf(),
            kind: kind_name(meta.file_type()),
        });
    }
    if meta.len() > cap {
        return Err(too_large(meta.len()));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // The file may have been swapped or grown since the metadata call: read one byte past the
    // cap at most, so the cap holds whatever the file does now.
    file.take(cap + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The text of the regular file `path` (see [`read_bytes`]), which must be UTF-8; a leading
/// byte-order mark is dropped (editors on Windows write one, and it is not part of the text).
pub fn read_text(path: &Path, what: &str, cap: u64) -> Result<String, InputError> {
    let bytes = read_bytes(path, what, cap)?;
    let mut text = String::from_utf8(bytes).map_err(|e| InputError::NotText {
        what: what.to_string(),
        path: path.to_path_buf(),
        offset: e.utf8_error().valid_up_to(),
    })?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// `text` with every line ending (`\r\n`, a lone `\r` as old Mac OS wrote, `\n`) as `\n`, so
/// that line numbers count what an editor shows.
pub fn normalize_line_endings(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains('\r') {
        std::borrow::Cow::Owned(text.replace("\r\n", "\n").replace('\r', "\n"))
    } else {
        std::borrow::Cow::Borrowed(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_are_refused_without_opening_them() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        // Opening a FIFO for reading blocks until a writer comes: refusing it must not open it.
        let e = read_text(&fifo, "scene file", MAX_SCENE_BYTES).unwrap_err();
        assert!(e.to_string().contains("named pipe"), "{e}");
        let e = read_bytes(Path::new("/dev/zero"), "mesh", MAX_MESH_BYTES).unwrap_err();
        assert!(e.to_string().contains("character device"), "{e}");
        let e = read_bytes(dir.path(), "mesh", MAX_MESH_BYTES).unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        let e = read_bytes(&dir.path().join("nope"), "mesh", 10).unwrap_err();
        assert!(matches!(e, InputError::Missing { .. }), "{e}");
    }

    #[test]
    fn the_cap_is_enforced_and_a_bom_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, "\u{feff}v 1 2 3\n").unwrap();
        assert_eq!(read_text(&p, "mesh", 100).unwrap(), "v 1 2 3\n");
        let e = read_text(&p, "mesh", 4).unwrap_err();
        assert!(matches!(e, InputError::TooLarge { size: 11, .. }), "{e}");
        std::fs::write(&p, [b'a', 0xff, b'b']).unwrap();
        let e = read_text(&p, "mesh", 100).unwrap_err();
        assert!(matches!(e, InputError::NotText { offset: 1, .. }), "{e}");
    }

    #[test]
    fn line_endings_of_every_kind_count_as_lines() {
        assert_eq!(normalize_line_endings("a\rb\r\nc\nd"), "a\nb\nc\nd");
        assert_eq!(normalize_line_endings("a\nb").lines().count(), 2);
    }
}
