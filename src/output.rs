//! Writing output files so that a reader never sees a half-written one: the bytes go to a
//! temporary file beside the target, which is then renamed over it (the temporary file is
//! removed if anything fails).

use std::io::Write;
use std::path::Path;

pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)?;
    let mut tmp = tempfile::Builder::new()
        .prefix(".dynrt-partial-")
        .tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Encodes an RGB image as PNG and writes it atomically, naming the file in any error.
pub fn write_png(path: &Path, img: &image::RgbImage) -> anyhow::Result<()> {
    use anyhow::Context;
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .context("encoding PNG")?;
    write_atomically(path, &bytes).with_context(|| format!("writing {}", path.display()))
}
