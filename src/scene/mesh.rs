//! Objects (triangle meshes with per-triangle materials), OBJ/MTL loading through tobj, and the
//! degenerate-triangle filter every object passes through.
//!
//! OBJ rules: polygons are fan-triangulated by tobj (a face `f a b c d` gives (a,b,c), (a,c,d));
//! points and lines are ignored; triangles keep file order (faces in the order they appear,
//! across `o`/`g`/`usemtl` switches). Before tobj parses the file a line scan checks every `v`
//! and `f` line, so a broken or non-finite vertex or an out-of-range face index is reported with
//! its line number.
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

/// What the line scan learnt: the material libraries referenced and the triangle count.
struct ObjScan {
    mtllibs: Vec<PathBuf>,
}

/// Checks `v` and `f` lines the way tobj will read them (f32 coordinates), with line numbers.
fn scan_obj(path: &Path, text: &str, item: &str) -> Result<ObjScan, SceneError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut vertices: i64 = 0;
    let mut mtllibs = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let lineno = Some(i + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                for axis in ["x", "y", "z"] {
                    let word = words.next().ok_or_else(|| {
                        obj_error(
                            path,
                            lineno,
                            item,
                            Problem::BrokenObj("vertex line needs three coordinates".into()),
                        )
                    })?;
                    let value: f32 = word.parse().map_err(|_| {
                        obj_error(
                            path,
                            lineno,
                            item,
                            Problem::BrokenObj(format!(
                                "vertex {axis} coordinate '{word}' is not a number"
                            )),
                        )
                    })?;
                    if !value.is_finite() {
                        return Err(obj_error(
                            path,
                            lineno,
                            item,
                            Problem::NonFinite {
                                what: format!(
                                    "vertex {} coordinate {axis} = '{word}' (as f32)",
                                    vertices + 1
                                ),
                            },
                        ));
                    }
                }
                vertices += 1;
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(obj_error(
                        path,
                        lineno,
                        item,
                        Problem::BrokenObj(format!(
                            "face has {} vertices, a face needs at least 3",
                            corners.len()
                        )),
                    ));
                }
                for c in corners {
                    let first = c.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| {
                        obj_error(
                            path,
                            lineno,
                            item,
                            Problem::BrokenObj(format!("face vertex '{c}' is not an index")),
                        )
                    })?;
                    let resolved = if index < 0 {
                        vertices + index + 1
                    } else {
                        index
                    };
                    if index == 0 || resolved < 1 || resolved > vertices {
                        return Err(obj_error(
                            path,
                            lineno,
                            item,
                            Problem::BrokenObj(format!(
                                "face vertex index {index} is out of range (only {vertices} vertices defined so far)"
                            )),
                        ));
                    }
                }
            }
            Some("mtllib") => {
                let name = line.trim_start()[6..].trim();
                mtllibs.push(dir.join(name));
            }
            _ => {}
        }
    }
    Ok(ObjScan { mtllibs })
}

/// Loads an OBJ file (and its MTL) as a raw mesh in file order, plus warnings.
pub(crate) fn load_obj(path: &Path, item: &str) -> Result<(RawMesh, Vec<String>), SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        obj_error(
            path,
            None,
            item,
            Problem::MeshUnreadable {
                path: path.to_path_buf(),
                reason: e.to_string(),
            },
        )
    })?;
    let scan = scan_obj(path, &text, item)?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, materials) = tobj::load_obj(path, &options)
        .map_err(|e| obj_error(path, None, item, Problem::BrokenObj(e.to_string())))?;
    let mtl_file = || {
        scan.mtllibs
            .first()
            .cloned()
            .unwrap_or_else(|| path.to_path_buf())
    };
    let tobj_materials = materials.map_err(|e| {
        let file = mtl_file();
        obj_error(
            &file,
            None,
            item,
            Problem::BrokenMtl(format!("'{}': {e}", file.display())),
        )
    })?;

    let mut warnings = Vec::new();
    let mut out = RawMesh::default();
    for m in &tobj_materials {
        let diffuse = m
            .diffuse
            .map_or(Material::DEFAULT.diffuse, |d| d.map(f64::from));
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
            let ks = m.specular.unwrap_or([0.0; 3]).map(f64::from);
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
            DVec3::new(f64::from(p[i]), f64::from(p[i + 1]), f64::from(p[i + 2]))
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
}
