//! The repository's scenes compiled into the binary, so that an installed `dynrt` (`cargo
//! install --path .`) runs `demo`, `bench scenes`, `bench precision`, `bench trees` and
//! `bench paper` from any folder: `scenes/*.toml`, the meshes they name (`scenes/meshes/`),
//! the paper's suite (`scenes/paper/*.toml`, procedural, naming no file) and the operator cost
//! cache of the precision sweep (`benches/data/fp_cost_xc2v.csv`).
//!
//! Contract: a bundled file has the path `bundled:/NAME` (`NAME` as under `scenes/`, e.g.
//! `bundled:/cornell.toml`, `bundled:/meshes/pyramid.obj`; `bundled:cornell.toml` is accepted
//! too). [`crate::input::read_bytes`] serves such a path from the binary, so everything that
//! reads scenes and meshes through `input` (every scene load, every mesh and material library)
//! takes a bundled path like a file's, and relative mesh paths resolve against the bundled
//! folder as they do against a scene file's folder. Errors name the bundled path, so the scene
//! concerned is always said (`bundled:/cornell.toml:14: ...`). A path that names no bundled file
//! is reported as missing with the list of bundled scenes.
//!
//! Why `include_str!` with a written list rather than the `include_dir` crate: eleven scene
//! files, two meshes and one CSV do not need a proc-macro dependency, and the list is checked
//! against the folders by a test (a scene added to `scenes/` and not here fails it).

use std::path::{Path, PathBuf};

/// The prefix of every bundled path.
pub const PREFIX: &str = "bundled:";

macro_rules! bundle {
    ($($name:literal),* $(,)?) => {
        &[$(($name, include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/", $name)) as &[u8])),*]
    };
}

/// Every bundled file under `scenes/`: (name relative to `scenes/`, contents), sorted by name.
pub const FILES: &[(&str, &[u8])] = bundle!(
    "cornell.toml",
    "cornell_noshadow.toml",
    "dynamic.toml",
    "meshes/pyramid.mtl",
    "meshes/pyramid.obj",
    "mirror.toml",
    "paper/castle.toml",
    "paper/conference.toml",
    "paper/office.toml",
    "paper/quake3.toml",
    "paper/quake3_p.toml",
    "paper/scene6.toml",
    "paper/suncor.toml",
    "paper/terrain.toml",
    "paper/ut2003.toml",
    "terrain.toml",
    "terrain_small.toml",
    "tiny.toml",
    "tiny_animated.toml",
);

/// The operator cost cache of the precision sweep as of this build
/// (`benches/data/fp_cost_xc2v.csv`).
pub const FP_COST_CSV: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/benches/data/fp_cost_xc2v.csv"
));

/// The bundled path of `name` (relative to `scenes/`), e.g. `bundled:/tiny.toml`.
pub fn path(name: &str) -> PathBuf {
    PathBuf::from(format!("{PREFIX}/{name}"))
}

/// The bundled folder `dir` (relative to `scenes/`, "" for the top), e.g. `bundled:/paper`.
pub fn dir(dir: &str) -> PathBuf {
    if dir.is_empty() {
        PathBuf::from(format!("{PREFIX}/"))
    } else {
        path(dir)
    }
}

/// The name under `scenes/` of a bundled path (`bundled:/x`, `bundled:x`, with `.` and `..`
/// resolved), or `None` when `p` is not a bundled path. `Some("")` is the bundled folder itself.
pub fn name_of(p: &Path) -> Option<String> {
    let rest = p.to_str()?.strip_prefix(PREFIX)?;
    let mut parts: Vec<&str> = Vec::new();
    for c in rest.split('/') {
        match c {
            "" | "." => {}
            ".." => {
                parts.pop();
            }
            c => parts.push(c),
        }
    }
    Some(parts.join("/"))
}

/// Whether `p` is a bundled path (whether or not it names a bundled file).
pub fn is_bundled(p: &Path) -> bool {
    name_of(p).is_some()
}

/// The canonical form `bundled:/NAME` of a bundled path (so that its parent is the bundled
/// folder it lies in), or `p` unchanged.
pub fn canonical(p: &Path) -> PathBuf {
    match name_of(p) {
        Some(n) => path(&n),
        None => p.to_path_buf(),
    }
}

/// The contents of the bundled file at `p`; `None` when `p` is not bundled or names no file.
pub fn contents(p: &Path) -> Option<&'static [u8]> {
    let n = name_of(p)?;
    FILES.iter().find(|(f, _)| *f == n).map(|(_, b)| *b)
}

/// Whether `p` names a regular file, bundled or on disk.
pub fn is_file(p: &Path) -> bool {
    if is_bundled(p) {
        contents(p).is_some()
    } else {
        p.is_file()
    }
}

/// Whether `p` names a folder, bundled (a prefix of some bundled file) or on disk.
pub fn is_dir(p: &Path) -> bool {
    match name_of(p) {
        Some(n) if n.is_empty() => true,
        Some(n) => FILES
            .iter()
            .any(|(f, _)| f.strip_prefix(&n).is_some_and(|r| r.starts_with('/'))),
        None => p.is_dir(),
    }
}

/// The scene files (`*.toml`) directly in the folder `dir`, bundled or on disk, sorted.
pub fn scene_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut v: Vec<PathBuf> = match name_of(dir) {
        Some(d) => {
            let prefix = if d.is_empty() { d } else { format!("{d}/") };
            FILES
                .iter()
                .filter_map(|(f, _)| f.strip_prefix(&prefix))
                .filter(|r| !r.contains('/') && r.ends_with(".toml"))
                .map(|r| path(&format!("{prefix}{r}")))
                .collect()
        }
        None => std::fs::read_dir(dir)
            .map_err(|e| anyhow::anyhow!("reading scene directory {}: {e}", dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect(),
    };
    v.sort();
    Ok(v)
}

/// The bundled scenes (top level, not the paper's suite), for messages.
pub fn scene_names() -> Vec<&'static str> {
    FILES
        .iter()
        .map(|(f, _)| *f)
        .filter(|f| !f.contains('/') && f.ends_with(".toml"))
        .collect()
}

/// Writes every bundled file under `dir` (`dir/cornell.toml`, `dir/meshes/pyramid.obj`,
/// `dir/paper/...`), refusing to overwrite a file that exists; returns the files written.
pub fn export(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    use anyhow::Context;
    let targets: Vec<PathBuf> = FILES.iter().map(|(f, _)| dir.join(f)).collect();
    if let Some(t) = targets.iter().find(|t| t.exists()) {
        anyhow::bail!(
            "'{}' exists; export into an empty or new folder, nothing is overwritten",
            t.display()
        );
    }
    for ((_, bytes), t) in FILES.iter().zip(&targets) {
        if let Some(parent) = t.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("creating {}", parent.display()))?;
        }
        crate::output::write_atomically(t, bytes)
            .with_context(|| format!("writing {}", t.display()))?;
    }
    Ok(targets)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every file of `scenes/` (but its README) is bundled, and nothing else.
    #[test]
    fn the_bundle_is_exactly_the_scenes_folder() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut on_disk = Vec::new();
        for sub in ["", "meshes", "paper"] {
            for e in std::fs::read_dir(root.join(sub)).unwrap() {
                let p = e.unwrap().path();
                if p.is_file() && p.file_name().unwrap() != "README.md" {
                    let n = p.strip_prefix(&root).unwrap().to_str().unwrap().to_string();
                    on_disk.push(n);
                }
            }
        }
        on_disk.sort();
        let bundled: Vec<String> = FILES.iter().map(|(f, _)| f.to_string()).collect();
        assert_eq!(bundled, on_disk, "update bundled::FILES");
        for (f, bytes) in FILES {
            assert_eq!(
                *bytes,
                std::fs::read(root.join(f)).unwrap().as_slice(),
                "{f}"
            );
        }
    }

    #[test]
    fn bundled_paths_resolve_like_files() {
        assert_eq!(
            name_of(Path::new("bundled:tiny.toml")).unwrap(),
            "tiny.toml"
        );
        assert_eq!(
            canonical(Path::new("bundled:./paper/../tiny.toml")),
            Path::new("bundled:/tiny.toml")
        );
        assert!(name_of(Path::new("scenes/tiny.toml")).is_none());
        // A scene's folder joined with its mesh path names the bundled mesh.
        let tiny = path("tiny.toml");
        let mesh = tiny.parent().unwrap().join("meshes/pyramid.obj");
        assert!(contents(&mesh).is_some(), "{}", mesh.display());
        assert!(is_dir(&dir("")) && is_dir(&dir("paper")) && !is_dir(&dir("pap")));
        assert!(is_file(&tiny) && !is_file(&path("nope.toml")));
        let top = scene_files(&dir("")).unwrap();
        assert_eq!(top.len(), 8, "{top:?}");
        assert!(top.contains(&path("cornell.toml")));
        assert_eq!(scene_files(&dir("paper")).unwrap().len(), 9);
    }

    #[test]
    fn a_bundled_scene_loads_with_its_mesh_and_errors_name_it() {
        let s = crate::scene::Scene::load(Path::new("bundled:tiny.toml")).unwrap();
        assert_eq!(s.triangle_count(), 40);
        let e = crate::scene::Scene::load(&path("nope.toml")).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("bundled:/nope.toml") && m.contains("cornell.toml"),
            "{m}"
        );
    }
}
