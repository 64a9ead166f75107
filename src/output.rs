//! Writing output files so that a reader never sees a half-written one and nothing the user did
//! not name as an output is replaced.
//!
//! Contract:
//! - [`write_atomically`] writes the bytes to a temporary file beside the target and renames it
//!   over the target (the temporary file is removed if anything fails). A new file gets the
//!   usual mode (0666 less the umask: 0644), a replaced one keeps its mode. It replaces only a
//!   regular file or nothing: a symlink, a device node, a FIFO or a directory at the path is
//!   refused, since the rename would replace the node itself (as root, `/dev/null`).
//! - [`check_output_file`] and [`check_output_dir`] say before any work whether a path can take
//!   an output, with the reason and the fix; [`check_distinct`] refuses two outputs (or an
//!   output and an input) of one command that are the same file.
//! - [`write_all_atomically`] writes several files all or none: every temporary file is written
//!   before the first rename, so a full disk or a read-only folder leaves no output behind.
//! - [`OutputDir`] removes, when a run fails, every entry that the run created in its output
//!   folder (and the folder itself if the run created it).

use std::io::Write;
use std::path::{Component, Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The folder a file at `path` lives in ("." for a bare file name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// What the node at `path` is when it exists and is not a regular file (a symlink is not
/// followed: renaming over it would replace the link itself).
fn non_regular_kind(path: &Path) -> Option<&'static str> {
    let t = std::fs::symlink_metadata(path).ok()?.file_type();
    (!t.is_file()).then(|| crate::input::kind_name(t))
}

/// Refuses a path whose existing node is not a regular file.
fn refuse_non_regular(path: &Path, what: &str) -> Result<()> {
    if let Some(kind) = non_regular_kind(path) {
        bail!(
            "{what} '{}' is {kind}; dynrt writes only to regular files or new paths: name another path",
            path.display()
        );
    }
    Ok(())
}

/// Checks that `path` can take the output file `what` (e.g. "--out image"): it names a file, not
/// a folder; if it exists it is a regular file (not a symlink, a device or a directory); and its
/// nearest existing ancestor is a folder.
pub fn check_output_file(path: &Path, what: &str) -> Result<()> {
    let text = path.as_os_str().to_string_lossy();
    if text.is_empty() {
        bail!("{what}: the path is empty; give a file name");
    }
    if text.ends_with('/')
        || matches!(
            path.components().next_back(),
            Some(Component::CurDir | Component::ParentDir | Component::RootDir)
        )
    {
        bail!(
            "{what} '{}' names a folder; give a file name, e.g. '{}'",
            path.display(),
            Path::new(&*text).join("out.png").display()
        );
    }
    refuse_non_regular(path, what)?;
    check_names_and_folders(path, what)
}

/// The longest name of one file or folder on Linux file systems (NAME_MAX).
const MAX_NAME_BYTES: usize = 255;

/// Checks, before any work, what would otherwise fail only at the write: every name in `path`
/// fits NAME_MAX, and the nearest existing folder above it is a folder, not a file.
fn check_names_and_folders(path: &Path, what: &str) -> Result<()> {
    if let Some(long) = path
        .components()
        .map(|c| c.as_os_str())
        .find(|c| c.len() > MAX_NAME_BYTES)
    {
        let shown: String = long.to_string_lossy().chars().take(40).collect();
        bail!(
            "{what}: the name '{shown}...' is {} bytes, longer than the {MAX_NAME_BYTES} a file or folder name may have; give a shorter name",
            long.len()
        );
    }
    let mut ancestor = parent_of(path);
    loop {
        match std::fs::metadata(ancestor) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) => bail!(
                "{what} '{}': '{}' is a file, not a folder; name a path inside a folder",
                path.display(),
                ancestor.display()
            ),
            Err(_) => match ancestor.parent() {
                Some(p) if !p.as_os_str().is_empty() => ancestor = p,
                _ => return Ok(()),
            },
        }
    }
}

/// Checks that `path` can take the output folder `what`: a folder or a new path (a symlink to a
/// folder is followed), below a folder.
pub fn check_output_dir(path: &Path, what: &str) -> Result<()> {
    if path.as_os_str().is_empty() {
        bail!("{what}: the path is empty; give a folder");
    }
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(m) => bail!(
            "{what} '{}' is {}, not a folder; name a folder (it is created if missing)",
            path.display(),
            crate::input::kind_name(m.file_type())
        ),
        Err(_) => {
            if std::fs::symlink_metadata(path).is_ok() {
                bail!(
                    "{what} '{}' is a dangling symbolic link; remove it or name another folder",
                    path.display()
                );
            }
            check_names_and_folders(path, what)
        }
    }
}

/// A path made absolute and, as far as it exists, free of symlinks and `..`, so that two
/// spellings of one file compare equal.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let parent = parent_of(path);
    match (std::fs::canonicalize(parent), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf()),
    }
}

/// Refuses an output (role, path) that is the same file as another output or as one of the
/// command's inputs; two inputs may well be one file (comparing an image with itself).
pub fn check_distinct(outputs: &[(&str, &Path)], inputs: &[(&str, &Path)]) -> Result<()> {
    let all: Vec<(&str, &Path, PathBuf)> = inputs
        .iter()
        .chain(outputs)
        .map(|&(role, p)| (role, p, resolved(p)))
        .collect();
    let first_output = inputs.len();
    for j in first_output..all.len() {
        if let Some(i) = (0..j).find(|&i| all[i].2 == all[j].2) {
            bail!(
                "{} and {} are the same file '{}'; give each its own path",
                all[i].0,
                all[j].0,
                all[j].1.display()
            );
        }
    }
    Ok(())
}

/// The process's umask, from /proc (reading it with umask(2) would change it for a moment
/// under the other threads); 022 when /proc does not say.
fn umask() -> u32 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("Umask:"))
                .and_then(|v| u32::from_str_radix(v.trim(), 8).ok())
        })
        .unwrap_or(0o022)
}

/// The mode a file written to `path` gets: the mode of the regular file it replaces, else
/// what any program's new file gets (0666 less the umask: 0644 under the usual 022).
/// tempfile's own 0600 would make every output private to its owner.
fn output_mode(path: &Path) -> u32 {
    use std::os::unix::fs::PermissionsExt;
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_file() => m.permissions().mode() & 0o7777,
        _ => 0o666 & !umask(),
    }
}

/// A temporary file beside `path`, written and synced, ready to be renamed over it.
fn staged(path: &Path, bytes: &[u8]) -> std::io::Result<tempfile::NamedTempFile> {
    use std::os::unix::fs::PermissionsExt;
    let dir = parent_of(path);
    std::fs::create_dir_all(dir)?;
    let mut tmp = tempfile::Builder::new()
        .prefix(".dynrt-partial-")
        .permissions(std::fs::Permissions::from_mode(output_mode(path)))
        .tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    Ok(tmp)
}

/// Writes `bytes` to `path` atomically (see the module doc). The error says what failed; the
/// caller's context names the file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if let Some(kind) = non_regular_kind(path) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            format!("{kind} is there; dynrt replaces only regular files"),
        ));
    }
    staged(path, bytes)?.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Writes every (path, bytes) pair, all or none (see the module doc).
pub fn write_all_atomically(files: &[(&Path, &[u8])]) -> Result<()> {
    let mut ready = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        refuse_non_regular(path, "output")?;
        ready.push((
            *path,
            staged(path, bytes).with_context(|| format!("writing {}", path.display()))?,
        ));
    }
    for (path, tmp) in ready {
        tmp.persist(path)
            .map_err(|e| e.error)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// PNG bytes of an RGB image.
pub fn png_bytes(img: &image::RgbImage) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .context("encoding PNG")?;
    Ok(bytes)
}

/// Encodes an RGB image as PNG and writes it atomically, naming the file in any error.
pub fn write_png(path: &Path, img: &image::RgbImage) -> Result<()> {
    let bytes = png_bytes(img)?;
    write_atomically(path, &bytes).with_context(|| format!("writing {}", path.display()))
}

/// An output folder that a failed (or interrupted) run leaves as it found it: entries the run
/// created are removed on drop unless [`OutputDir::keep`] was called, and by [`abandon_all`]
/// when a signal ends dynrt (no destructor runs then).
pub struct OutputDir {
    id: u64,
}

/// What an [`OutputDir`] must undo.
struct Undo {
    path: PathBuf,
    created_dir: bool,
    before: std::collections::HashSet<std::ffi::OsString>,
}

impl Undo {
    fn run(&self) {
        if self.created_dir {
            let _ = std::fs::remove_dir_all(&self.path);
            return;
        }
        let Ok(entries) = std::fs::read_dir(&self.path) else {
            return;
        };
        for e in entries.flatten() {
            if !self.before.contains(&e.file_name()) {
                let p = e.path();
                let _ = if e.file_type().is_ok_and(|t| t.is_dir()) {
                    std::fs::remove_dir_all(&p)
                } else {
                    std::fs::remove_file(&p)
                };
            }
        }
    }
}

/// The output folders of runs in progress, by id.
static ACTIVE: std::sync::Mutex<Vec<(u64, Undo)>> = std::sync::Mutex::new(Vec::new());

fn active() -> std::sync::MutexGuard<'static, Vec<(u64, Undo)>> {
    ACTIVE.lock().unwrap_or_else(|e| e.into_inner())
}

fn take_undo(id: u64) -> Option<Undo> {
    let mut a = active();
    let at = a.iter().position(|(i, _)| *i == id)?;
    Some(a.swap_remove(at).1)
}

/// Undoes every output folder of a run in progress (a signal is ending dynrt).
pub fn abandon_all() {
    let undos: Vec<(u64, Undo)> = active().drain(..).collect();
    for (_, u) in undos {
        u.run();
    }
}

impl OutputDir {
    /// Checks `path` (see [`check_output_dir`]) and creates it if missing.
    pub fn create(path: &Path, what: &str) -> Result<OutputDir> {
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        check_output_dir(path, what)?;
        let created_dir = !path.exists();
        let mut before = std::collections::HashSet::new();
        if created_dir {
            std::fs::create_dir_all(path)
                .with_context(|| format!("creating {what} '{}'", path.display()))?;
        } else {
            for e in std::fs::read_dir(path)
                .with_context(|| format!("listing {what} '{}'", path.display()))?
            {
                before.insert(e?.file_name());
            }
        }
        let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        active().push((
            id,
            Undo {
                path: path.to_path_buf(),
                created_dir,
                before,
            },
        ));
        Ok(OutputDir { id })
    }

    /// The run succeeded: keep what it wrote.
    pub fn keep(self) {
        take_undo(self.id);
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if let Some(u) = take_undo(self.id) {
            u.run();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_and_new_paths_take_output() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let file = d.join("a.png");
        std::fs::write(&file, b"old").unwrap();
        check_output_file(&file, "--out").unwrap();
        check_output_file(&d.join("new/deeper/b.png"), "--out").unwrap();
        let link = d.join("link.png");
        std::os::unix::fs::symlink(&file, &link).unwrap();
        let e = check_output_file(&link, "--out").unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        let e = write_atomically(&link, b"new").unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        assert_eq!(
            std::fs::read(&file).unwrap(),
            b"old",
            "the link's target is untouched"
        );
        let e = check_output_file(Path::new("/dev/null"), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("character device"), "{e}");
        let e = check_output_file(d, "--out").unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let e = check_output_file(Path::new("."), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("names a folder"), "{e}");
        let e = check_output_file(Path::new("newdir/"), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("names a folder"), "{e}");
        let e = check_output_file(&file.join("x"), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a file, not a folder"), "{e}");
        let e = check_output_dir(&file, "--out").unwrap_err().to_string();
        assert!(e.contains("a regular file, not a folder"), "{e}");
        // A folder under a file is named as given, not with a made-up child.
        let under = file.join("run");
        let e = check_output_dir(&under, "--out").unwrap_err().to_string();
        assert!(
            e.contains(&format!("'{}':", under.display())) && e.contains("is a file, not a folder"),
            "{e}"
        );
        // A name longer than NAME_MAX fails before any work, not at the write.
        let long = d.join(format!("{}.png", "x".repeat(300)));
        let e = check_output_file(&long, "--out").unwrap_err().to_string();
        assert!(e.contains("304 bytes, longer than the 255"), "{e}");
        let e = check_output_dir(&d.join("y".repeat(256)), "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("256 bytes"), "{e}");
    }

    #[test]
    fn outputs_get_the_usual_mode_and_a_replaced_file_keeps_its_own() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.txt");
        write_atomically(&a, b"1").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&a), 0o666 & !umask());
        std::fs::set_permissions(&a, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomically(&a, b"2").unwrap();
        assert_eq!(mode(&a), 0o640);
        let b = dir.path().join("b.txt");
        write_all_atomically(&[(&b, b"x")]).unwrap();
        assert_eq!(mode(&b), 0o666 & !umask());
    }

    #[test]
    fn two_spellings_of_one_file_are_the_same_output() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("x.csv");
        let b = dir.path().join("sub/../x.csv");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let e = check_distinct(&[("--out", &a), ("--hits", &b)], &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("--out and --hits are the same file"), "{e}");
        check_distinct(&[("--out", &a), ("--hits", &dir.path().join("y.csv"))], &[]).unwrap();
        // Two inputs may be one file; an output may not be an input.
        check_distinct(
            &[("--diff", &dir.path().join("d.png"))],
            &[("A", &a), ("B", &b)],
        )
        .unwrap();
        let e = check_distinct(&[("--diff", &b)], &[("A", &a)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("A and --diff are the same file"), "{e}");
    }

    #[test]
    fn a_failed_run_leaves_its_folder_as_it_found_it() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        {
            let o = OutputDir::create(&out, "--out").unwrap();
            std::fs::create_dir(out.join("mem")).unwrap();
            drop(o);
        }
        assert!(!out.exists(), "a folder the run created is removed");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("mine.txt"), b"keep").unwrap();
        {
            let _o = OutputDir::create(&out, "--out").unwrap();
            std::fs::create_dir(out.join("rtl")).unwrap();
        }
        assert!(out.join("mine.txt").exists() && !out.join("rtl").exists());
        let o = OutputDir::create(&out, "--out").unwrap();
        std::fs::create_dir(out.join("rtl")).unwrap();
        o.keep();
        assert!(out.join("rtl").exists());
    }

    #[test]
    fn all_or_none_writes_nothing_when_one_file_cannot_be_written() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.png");
        let blocked = dir.path().join("f");
        std::fs::write(&blocked, b"").unwrap();
        // A file where the second output's folder should be: its staging fails.
        let b = blocked.join("b.csv");
        assert!(write_all_atomically(&[(&a, b"1"), (&b, b"2")]).is_err());
        assert!(
            !a.exists(),
            "the first file is not written when the second fails"
        );
        let leftovers = std::fs::read_dir(dir.path()).unwrap().count();
        assert_eq!(leftovers, 1, "no temporary file is left behind");
    }
}
