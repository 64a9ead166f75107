//! Objects (triangle meshes with per-triangle materials), OBJ/MTL loading through tobj, and the
//! degenerate-triangle filter every object passes through.
//!
//! OBJ rules: polygons are fan-triangulated by tobj (a face `f a b c d` gives (a,b,c), (a,c,d));
//! points and lines are ignored; triangles keep file order (faces in the order they appear,
//! across `o`/`g`/`usemtl` switches). Before tobj parses the file a line scan checks every `v`
//! and `f` line, so a broken or non-finite vertex or an out-of-range face index is reported with
//! its line number. Numbers are read as f64 (tobj's `use_f64`): a vertex is the f64 nearest its
//! decimal text, so a small mesh far from the origin keeps its shape (f32 has 1/16 steps at 10^6).
//!
//! MTL rules: diffuse = `Kd` (default 0.8 grey when absent); mirror reflectivity = mean of the
//! three `Ks` components when `illum 3` (the MTL "reflection on, ray traced" model), else 0,
//! clamped to [0, 1] with a warning. Faces without a known material get the default material
//! (0.8 grey, no mirror), appended after the MTL's materials.
//!
//! Degenerate triangles: a triangle A, B, C is dropped when |(B − A) × (C − A)| (twice its area)
//! is at most `DEGENERATE_RELATIVE_EPSILON` · ℓ², ℓ its longest edge — zero area, repeated
//! vertices, or collinear to within f64 rounding. Such triangles have no plane, so their
//! unit-triangle transform does not exist. They are counted in a warning; triangle indices
//! (hits file, `triangle_material`) count only the triangles that remain.

use std::path::{Path, PathBuf};

use glam::DVec3;

use super::error::{Problem, SceneError};

/// See the module doc: relative area threshold below which a triangle is degenerate.
pub const DEGENERATE_RELATIVE_EPSILON: f64 = 1e-12;

/// Surface of a triangle: Lambert diffuse colour and mirror reflectivity in [0, 1]
/// (the share of the reflected ray's colour; the golden model decides how to mix).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub diffuse: [f64; 3],
    pub mirror: f64,
}

impl Material {
    /// Used when a mesh face has no material and for generated objects without `color`.
    pub const DEFAULT: Material = Material {
        diffuse: [0.8, 0.8, 0.8],
        mirror: 0.0,
    };
}

/// A loaded, validated object: only finite, non-degenerate triangles, at least one;
/// `triangle_material[i]` indexes `materials` for `triangles[i]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub name: String,
    pub triangles: Vec<[DVec3; 3]>,
    pub materials: Vec<Material>,
    pub triangle_material: Vec<u32>,
}

impl Object {
    /// Axis-aligned bounds (min, max) in object space.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for t in &self.triangles {
            for v in t {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        (lo, hi)
    }

    pub fn material_of(&self, triangle: usize) -> &Material {
        &self.materials[self.triangle_material[triangle] as usize]
    }
}

/// A mesh before the degenerate filter (generator or OBJ output).
#[derive(Debug, Clone, Default)]
pub(crate) struct RawMesh {
    pub triangles: Vec<[DVec3; 3]>,
    pub materials: Vec<Material>,
    pub triangle_material: Vec<u32>,
}

impl RawMesh {
    /// Single-material mesh.
    pub fn with_material(triangles: Vec<[DVec3; 3]>, material: Material) -> RawMesh {
        let n = triangles.len();
        RawMesh {
            triangles,
            materials: vec![material],
            triangle_material: vec![0; n],
        }
    }
}

pub fn is_degenerate(t: &[DVec3; 3]) -> bool {
    let e0 = t[1] - t[0];
    let e1 = t[2] - t[0];
    let e2 = t[2] - t[1];
    let longest2 = e0
        .length_squared()
        .max(e1.length_squared())
        .max(e2.length_squared());
    let twice_area = e0.cross(e1).length();
    // NaN and zero-length edges also count as degenerate.
    let keep = twice_area > DEGENERATE_RELATIVE_EPSILON * longest2;
    !keep
}

/// Drops degenerate triangles; returns the object and how many were dropped.
/// Errors with `EmptyMesh` when nothing remains.
pub(crate) fn finish_object(name: &str, raw: RawMesh) -> Result<(Object, usize), (usize, usize)> {
    let total = raw.triangles.len();
    let mut triangles = Vec::with_capacity(total);
    let mut triangle_material = Vec::with_capacity(total);
    for (t, m) in raw.triangles.into_iter().zip(raw.triangle_material) {
        if !is_degenerate(&t) {
            triangles.push(t);
            triangle_material.push(m);
        }
    }
    let dropped = total - triangles.len();
    if triangles.is_empty() {
        return Err((total, dropped));
    }
    Ok((
        Object {
            name: name.to_string(),
            triangles,
            materials: raw.materials,
            triangle_material,
        },
        dropped,
    ))
}

fn obj_error(path: &Path, line: Option<usize>, item: &str, problem: Problem) -> SceneError {
    SceneError {
        file: path.to_path_buf(),
        line,
        item: Some(item.to_string()),
        problem,
    }
}

/// What the line scan learnt: the material libraries referenced.
struct ObjScan {
    mtllibs: Vec<PathBuf>,
}

/// Most triangles the scene's objects may have together: what the processor's memory holds
/// (`MemoryConfig::max_triangles`, 131,072 on the board). Counted from the OBJ's face lines and
/// the generators' parameters before any triangle is built, so a mesh of millions of faces is
/// refused in the time of a line scan instead of after gigabytes of parsing and trees. The
/// count is taken before degenerate triangles are dropped.
pub fn max_scene_triangles() -> u64 {
    crate::layout::MemoryConfig::default().max_triangles() as u64
}

/// What is wrong with an object whose triangles do not fit: `budget` triangles were left for it.
pub(crate) fn too_many_triangles(budget: u64) -> String {
    let max = max_scene_triangles();
    let room = if budget < max {
        format!("the {budget} triangles left in the processor's memory after the objects before it ({max} in all, ")
    } else {
        format!("the {max} triangles the processor's memory holds (")
    };
    format!(
        "more than {room}six 4 MB banks, docs/ARCHITECTURE.md \"Memory map\"); simplify the mesh, use a coarser generator, or instance repeated parts"
    )
}

/// Parses `words` as numbers (the way tobj will, as f64), naming the line's `what` in errors.
fn numbers(
    words: &[&str],
    path: &Path,
    lineno: Option<usize>,
    item: &str,
    what: &str,
) -> Result<Vec<f64>, SceneError> {
    words
        .iter()
        .map(|w| {
            let v: f64 = w.parse().map_err(|_| {
                obj_error(
                    path,
                    lineno,
                    item,
                    Problem::BrokenObj(format!("{what}: '{w}' is not a number")),
                )
            })?;
            if !v.is_finite() {
                return Err(obj_error(
                    path,
                    lineno,
                    item,
                    Problem::NonFinite {
                        what: format!("{what} '{w}'"),
                    },
                ));
            }
            Ok(v)
        })
        .collect()
}

/// Checks every line the way tobj will read it (f64 numbers; `v x y z [w | r g b]`, `vt u v [w]`,
/// `vn x y z`, faces `v[/vt][/vn]` with 1-based or negative indices), so that a broken line is
/// reported with its number; tobj itself says only "position parse error" (and panics on some
/// MTL lines, see [`scan_mtl`]).
fn scan_obj(path: &Path, text: &str, item: &str, budget: u64) -> Result<ObjScan, SceneError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let (mut vertices, mut texcoords, mut normals): (i64, i64, i64) = (0, 0, 0);
    let mut mtllibs = Vec::new();
    let mut triangles: u64 = 0;
    for (i, line) in text.lines().enumerate() {
        let lineno = Some(i + 1);
        let broken = |message: String| obj_error(path, lineno, item, Problem::BrokenObj(message));
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some((&key, args)) = words.split_first() else {
            continue;
        };
        match key {
            "v" => {
                let what = format!("vertex {}", vertices + 1);
                let v = numbers(args, path, lineno, item, &what)?;
                match v.len() {
                    3 | 6 => {}
                    4 => {
                        // tobj divides x, y, z by w.
                        if v[3] == 0.0 {
                            return Err(broken(format!("{what} has weight w = 0; drop the fourth number or make it non-zero")));
                        }
                        if v[..3].iter().any(|c| !(c / v[3]).is_finite()) {
                            return Err(obj_error(path, lineno, item, Problem::NonFinite { what: format!("{what} divided by its weight w = {}", v[3]) }));
                        }
                    }
                    n => {
                        return Err(broken(format!(
                            "{what} has {n} numbers; a vertex line is `v x y z`, `v x y z w` or `v x y z r g b`"
                        )))
                    }
                }
                vertices += 1;
            }
            "vt" => {
                let what = format!("texture coordinate {}", texcoords + 1);
                let v = numbers(args, path, lineno, item, &what)?;
                if !(2..=3).contains(&v.len()) {
                    return Err(broken(format!(
                        "{what} has {} numbers; a texture coordinate line is `vt u v` or `vt u v w`",
                        v.len()
                    )));
                }
                texcoords += 1;
            }
            "vn" => {
                let what = format!("normal {}", normals + 1);
                let v = numbers(args, path, lineno, item, &what)?;
                if v.len() != 3 {
                    return Err(broken(format!(
                        "{what} has {} numbers; a normal line is `vn x y z`",
                        v.len()
                    )));
                }
                normals += 1;
            }
            "f" | "l" => {
                let least = if key == "f" { 3 } else { 2 };
                if args.len() < least {
                    return Err(broken(format!(
                        "{} has {} vertices, it needs at least {least}",
                        if key == "f" { "face" } else { "line" },
                        args.len()
                    )));
                }
                for c in args {
                    let parts: Vec<&str> = c.split('/').collect();
                    if parts.len() > 3 {
                        return Err(broken(format!(
                            "face vertex '{c}' has {} parts; it is `v`, `v/vt`, `v//vn` or `v/vt/vn`",
                            parts.len()
                        )));
                    }
                    let kinds = [
                        ("vertex", "vertices", vertices),
                        ("texture coordinate", "texture coordinates", texcoords),
                        ("normal", "normals", normals),
                    ];
                    for (k, part) in parts.iter().enumerate() {
                        let (kind, kinds_name, defined) = kinds[k];
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let index: i64 = part.parse().map_err(|_| {
                            broken(format!(
                                "face vertex '{c}': {kind} index '{part}' is not an integer"
                            ))
                        })?;
                        let resolved = if index < 0 {
                            defined + index + 1
                        } else {
                            index
                        };
                        if index == 0 || resolved < 1 || resolved > defined {
                            return Err(broken(format!(
                                "face vertex '{c}': {kind} index {index} is out of range (only {defined} {kinds_name} defined so far)"
                            )));
                        }
                    }
                }
                if key == "f" {
                    triangles += args.len() as u64 - 2;
                    if triangles > budget {
                        return Err(obj_error(
                            path,
                            lineno,
                            item,
                            Problem::Invalid {
                                what: "the mesh's triangle count".into(),
                                expected: too_many_triangles(budget),
                            },
                        ));
                    }
                }
            }
            "mtllib" => {
                let name = line.trim_start()[6..].trim();
                if name.is_empty() {
                    return Err(broken("`mtllib` names no file".into()));
                }
                mtllibs.push(dir.join(name));
            }
            _ => {}
        }
    }
    Ok(ObjScan { mtllibs })
}

/// Checks every MTL line tobj reads (`Ka Kd Ks Ke` three numbers, `Ns Ni d Tr` one, `illum` an
/// integer, `newmtl` a name, `map_*` a file name): tobj reports only "material parse error",
/// and panics on a colour with fewer than three numbers.
fn scan_mtl(path: &Path, text: &str, item: &str) -> Result<(), SceneError> {
    for (i, line) in text.lines().enumerate() {
        let lineno = Some(i + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some((&key, args)) = words.split_first() else {
            continue;
        };
        let broken = |message: String| obj_error(path, lineno, item, Problem::BrokenMtl(message));
        match key {
            "Ka" | "Kd" | "Ks" | "Ke" => {
                let colour = match args.get(..3) {
                    Some(rgb) => numbers(rgb, path, lineno, item, key).ok(),
                    None => None,
                };
                let Some(colour) = colour else {
                    return Err(broken(format!(
                        "`{key}` needs three numbers (r g b), found `{}`",
                        args.join(" ")
                    )));
                };
                if colour.iter().any(|&c| c < 0.0) {
                    return Err(broken(format!(
                        "`{key} {}` has a negative component; colours are >= 0",
                        args.join(" ")
                    )));
                }
            }
            "Ns" | "Ni" | "d" | "Tr" => {
                if args.first().and_then(|w| w.parse::<f64>().ok()).is_none() {
                    return Err(broken(format!(
                        "`{key}` needs a number, found `{}`",
                        args.join(" ")
                    )));
                }
            }
            "illum" => {
                if args.first().and_then(|w| w.parse::<i32>().ok()).is_none() {
                    return Err(broken(format!(
                        "`illum` needs an integer model number (0..10), found `{}`",
                        args.join(" ")
                    )));
                }
            }
            "newmtl" if args.is_empty() => return Err(broken("`newmtl` names no material".into())),
            k if k.starts_with("map_") || k == "bump" => {
                if args.is_empty() {
                    return Err(broken(format!("`{k}` names no file")));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

fn read_obj_text(path: &Path, item: &str) -> Result<String, SceneError> {
    let text = crate::input::read_text(path, "mesh", crate::input::MAX_MESH_BYTES)
        .map_err(|e| obj_error(path, None, item, Problem::Input(e)))?;
    // Most meshes have no CR: keep the text as read rather than copy a file of up to 256 MiB.
    Ok(match crate::input::normalize_line_endings(&text) {
        std::borrow::Cow::Borrowed(_) => text,
        std::borrow::Cow::Owned(normalized) => normalized,
    })
}

/// Loads an OBJ file (and its MTL) as a raw mesh in file order, plus warnings; more than
/// `budget` triangles are refused from the face lines alone.
pub(crate) fn load_obj(
    path: &Path,
    item: &str,
    budget: u64,
) -> Result<(RawMesh, Vec<String>), SceneError> {
    let text = read_obj_text(path, item)?;
    let scan = scan_obj(path, &text, item, budget)?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj asks for each `mtllib` by the name in the file; the library is read here, through
    // the same checks as every input, and an error in it is kept to be reported as it is.
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mtl_error: std::cell::RefCell<Option<SceneError>> = std::cell::RefCell::new(None);
    let load_mtl = |name: &Path| -> tobj::MTLLoadResult {
        let file = dir.join(name);
        let result =
            crate::input::read_text(&file, "material library", crate::input::MAX_MTL_BYTES)
                .map_err(|e| obj_error(&file, None, item, Problem::Input(e)))
                .and_then(|t| {
                    let t = crate::input::normalize_line_endings(&t).into_owned();
                    scan_mtl(&file, &t, item)?;
                    tobj::load_mtl_buf(&mut t.as_bytes()).map_err(|e| {
                        obj_error(&file, None, item, Problem::BrokenMtl(e.to_string()))
                    })
                });
        result.map_err(|e| {
            *mtl_error.borrow_mut() = Some(e);
            tobj::LoadError::OpenFileFailed
        })
    };
    let (models, materials) = tobj::load_obj_buf(&mut text.as_bytes(), &options, load_mtl)
        .map_err(|e| obj_error(path, None, item, Problem::BrokenObj(e.to_string())))?;
    let mtl_file = || {
        scan.mtllibs
            .first()
            .cloned()
            .unwrap_or_else(|| path.to_path_buf())
    };
    let tobj_materials = match (materials, mtl_error.into_inner()) {
        (_, Some(e)) => return Err(e),
        (Ok(m), None) => m,
        (Err(e), None) => {
            let file = mtl_file();
            return Err(obj_error(
                &file,
                None,
                item,
                Problem::BrokenMtl(format!("'{}': {e}", file.display())),
            ));
        }
    };

    let mut warnings = Vec::new();
    let mut out = RawMesh::default();
    for m in &tobj_materials {
        let diffuse = m.diffuse.unwrap_or(Material::DEFAULT.diffuse);
        let what = format!("material '{}'", m.name);
        if diffuse.iter().any(|c| !c.is_finite()) {
            return Err(obj_error(
                &mtl_file(),
                None,
                item,
                Problem::NonFinite {
                    what: format!("Kd of {what}"),
                },
            ));
        }
        if diffuse.iter().any(|&c| c < 0.0) {
            return Err(obj_error(
                &mtl_file(),
                None,
                item,
                Problem::BrokenMtl(format!("Kd {diffuse:?} of {what} is negative")),
            ));
        }
        let mut mirror = 0.0;
        if m.illumination_model == Some(3) {
            let ks = m.specular.unwrap_or([0.0; 3]);
            if ks.iter().any(|c| !c.is_finite()) {
                return Err(obj_error(
                    &mtl_file(),
                    None,
                    item,
                    Problem::NonFinite {
                        what: format!("Ks of {what}"),
                    },
                ));
            }
            let mean = (ks[0] + ks[1] + ks[2]) / 3.0;
            mirror = mean.clamp(0.0, 1.0);
            if mirror != mean {
                warnings.push(format!(
                    "{item}: {what}: mirror reflectivity (mean Ks) {mean} clamped to {mirror}"
                ));
            }
        }
        out.materials.push(Material { diffuse, mirror });
    }
    let mut default_index: Option<u32> = None;
    for model in &models {
        let mesh = &model.mesh;
        let material = match mesh.material_id {
            Some(id) if id < out.materials.len() => id as u32,
            _ => *default_index.get_or_insert_with(|| {
                out.materials.push(Material::DEFAULT);
                (out.materials.len() - 1) as u32
            }),
        };
        let p = &mesh.positions;
        let vertex = |i: u32| {
            let i = i as usize * 3;
            DVec3::new(p[i], p[i + 1], p[i + 2])
        };
        for tri in mesh.indices.chunks_exact(3) {
            out.triangles
                .push([vertex(tri[0]), vertex(tri[1]), vertex(tri[2])]);
            out.triangle_material.push(material);
        }
    }
    if default_index.is_some() && !tobj_materials.is_empty() {
        warnings.push(format!(
            "{item}: some faces have no known material; they get the default (0.8 grey)"
        ));
    }
    Ok((out, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_rule() {
        let a = DVec3::ZERO;
        let x = DVec3::X;
        let y = DVec3::Y;
        assert!(!is_degenerate(&[a, x, y]));
        assert!(is_degenerate(&[a, x, x]), "repeated vertex");
        assert!(is_degenerate(&[a, x, 2.0 * x]), "collinear");
        assert!(is_degenerate(&[a, a, a]), "point");
        // Thin but real: 1e-6 relative height is far above the 1e-12 threshold.
        assert!(!is_degenerate(&[a, x, DVec3::new(0.5, 1e-6, 0.0)]));
        // Scale does not matter (relative rule): the same shape at 1e-8 size survives.
        let s = 1e-8;
        assert!(!is_degenerate(&[a, x * s, y * s]));
        assert!(is_degenerate(&[a, x, DVec3::new(0.5, 1e-14, 0.0)]));
        assert!(is_degenerate(&[a, x, DVec3::new(f64::NAN, 1.0, 0.0)]));
    }

    /// A centimetre-sized triangle a million units from the origin: f32 (1/16 steps there)
    /// would merge its vertices into one point and drop it as degenerate.
    #[test]
    fn positions_are_read_as_f64() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("far.obj");
        let text = "v 1000000.01 -2000000.003 3000000.5\n\
                    v 1000000.02 -2000000.003 3000000.5\n\
                    v 1000000.01 -2000000.013 3000000.51\n\
                    f 1 2 3\n";
        std::fs::write(&path, text).unwrap();
        let (mesh, warnings) = load_obj(&path, "far", 100).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        let v = |x: &str, y: &str, z: &str| {
            DVec3::new(x.parse().unwrap(), y.parse().unwrap(), z.parse().unwrap())
        };
        let expected = [
            v("1000000.01", "-2000000.003", "3000000.5"),
            v("1000000.02", "-2000000.003", "3000000.5"),
            v("1000000.01", "-2000000.013", "3000000.51"),
        ];
        assert_eq!(mesh.triangles, vec![expected]);
        assert!(!is_degenerate(&mesh.triangles[0]));
        // What an f32 parse would have made of it: one point.
        let as_f32 = expected.map(|p| p.as_vec3().as_dvec3());
        assert!(is_degenerate(&as_f32), "{as_f32:?}");
        // The benchmark's loader reads the same numbers.
        let tris = crate::accel::bench::load_obj_triangles(&path).unwrap();
        assert_eq!(tris, vec![expected]);
    }
}
