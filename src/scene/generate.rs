//! Procedural meshes for `generate = { kind = ..., ... }`. Every generator is deterministic (same
//! parameters, same triangles in the same order) and winds its triangles counter-clockwise seen
//! from the side the normal (B − A) × (C − A) points to: outwards for box and sphere, +Y for plane
//! and terrain, into the room for the Cornell box walls.
//!
//! | kind | parameters (defaults) | triangles |
//! | --- | --- | --- |
//! | `box` | `size = [1,1,1]`, centred at the origin | 12 |
//! | `plane` | `size = [1,1]` (x, z), `subdivisions = 1`; y = 0, centred | 2 s² |
//! | `sphere` | `radius = 1`, `subdivisions = 2` (0..=8); subdivided icosahedron | 20 · 4^s |
//! | `cornell_box` | `closed_front = false`, `mirror_tall_block = 0` | 30 (32 closed) |
//! | `terrain` | `size` (1..=2048, required), `seed = 0`, `amplitude = 1`, `extent = 10`, `octaves = 5` (1..=16), `frequency = 4` | 2 size² |
//! | `paper` | `model` (required): a model of the paper suite, `paper::MODELS` | the model's |
//!
//! Cornell box: x in [-1, 1], y in [0, 2], z in [-1, 1]; floor, ceiling and back wall (z = -1)
//! white (0.725, 0.71, 0.68), left wall (x = -1) red (0.63, 0.065, 0.05), right wall (x = 1)
//! green (0.14, 0.45, 0.091), each wall two triangles. The front (z = +1) is open unless
//! `closed_front = true` (then the camera must be inside the box to see anything). Two white
//! blocks without bottom faces (10 triangles each): a short 0.6 cube centred (0.33, 0.3, 0.3)
//! turned −17° about Y, and a tall 0.6 x 1.2 x 0.6 block centred (−0.33, 0.6, −0.3) turned +17°,
//! whose material has mirror reflectivity `mirror_tall_block`. Materials: 0 white, 1 red,
//! 2 green, 3 tall block. The bundled scenes' camera (eye (0, 1, 3.5), fov 40) frames it.
//!
//! Terrain: a `size` x `size` grid over x, z in [−extent/2, extent/2], height
//! `amplitude · fbm(frequency · u, frequency · v)` (see `noise.rs`; u, v in [0, 1] across the
//! grid); each cell (row z, then column x) gives two triangles.
//!
//! Generated objects have one material (`Material::DEFAULT` or the object's `color`/`mirror`),
//! except the Cornell box and the paper models, which have their own.

use glam::{DMat3, DVec3};

use super::mesh::{Material, RawMesh};
use super::noise::fbm;
use super::schema::GenerateDef;

pub const MAX_SPHERE_SUBDIVISIONS: u32 = 8;
pub const MAX_GRID_CELLS_PER_SIDE: u32 = 2048;
pub const MAX_TERRAIN_OCTAVES: u32 = 16;

pub const CORNELL_WHITE: [f64; 3] = [0.725, 0.71, 0.68];
pub const CORNELL_RED: [f64; 3] = [0.63, 0.065, 0.05];
pub const CORNELL_GREEN: [f64; 3] = [0.14, 0.45, 0.091];

/// A parameter out of range: (parameter, what is expected).
pub type ParamError = (String, String);

fn check(ok: bool, what: &str, expected: &str) -> Result<(), ParamError> {
    if ok {
        Ok(())
    } else {
        Err((what.to_string(), expected.to_string()))
    }
}

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Whether the generator brings its own materials (then `color`/`mirror` are refused).
pub fn has_own_materials(def: &GenerateDef) -> bool {
    matches!(
        def,
        GenerateDef::CornellBox { .. } | GenerateDef::Paper { .. }
    )
}

/// Number of triangles `generate` will produce (before the degenerate filter, which none of the
/// generators should trigger); a paper model's is counted by building it (at most a few
/// ten thousand triangles, milliseconds), 0 for an unknown model.
pub fn expected_triangles(def: &GenerateDef) -> u64 {
    match def {
        GenerateDef::Paper { model } => {
            super::paper::model(model).map_or(0, |m| m.triangles.len() as u64)
        }
        GenerateDef::Box { .. } => 12,
        // Saturating: the count is taken before the parameters' ranges are checked.
        GenerateDef::Plane { subdivisions, .. } => 2 * u64::from(*subdivisions).pow(2),
        GenerateDef::Sphere { subdivisions, .. } => {
            20u64.saturating_mul(4u64.saturating_pow(*subdivisions))
        }
        GenerateDef::CornellBox { closed_front, .. } => {
            if *closed_front {
                32
            } else {
                30
            }
        }
        GenerateDef::Terrain { size, .. } => 2 * u64::from(*size).pow(2),
    }
}

/// Builds the mesh; `material` is used by single-material generators. Parameters that give
/// more than `budget` triangles are refused from the count alone.
pub fn generate(def: &GenerateDef, material: Material, budget: u64) -> Result<RawMesh, ParamError> {
    // Counted before anything is built: a 2048x2048 terrain is 8.4 M triangles, gigabytes of
    // trees, and can never fit the processor's memory.
    let n = expected_triangles(def);
    let in_range = match def {
        GenerateDef::Sphere { subdivisions, .. } => *subdivisions <= MAX_SPHERE_SUBDIVISIONS,
        GenerateDef::Plane {
            subdivisions: s, ..
        }
        | GenerateDef::Terrain { size: s, .. } => *s <= MAX_GRID_CELLS_PER_SIDE,
        _ => true,
    };
    // Out-of-range parameters get their own message from `build`.
    if in_range && n > budget {
        return Err((
            "the generator's triangle count".into(),
            format!(
                "its parameters give {n} triangles, {}",
                super::mesh::too_many_triangles(budget)
            ),
        ));
    }
    let mesh = build(def, material)?;
    debug_assert_eq!(mesh.triangles.len() as u64, expected_triangles(def));
    Ok(mesh)
}

fn build(def: &GenerateDef, material: Material) -> Result<RawMesh, ParamError> {
    match def {
        GenerateDef::Paper { model } => super::paper::model(model).ok_or_else(|| {
            (
                format!("paper model '{model}'"),
                format!("one of {}", super::paper::MODELS.join(", ")),
            )
        }),
        GenerateDef::Box { size } => {
            check(
                size.iter().all(|&s| positive(s)),
                "box size",
                "three finite numbers > 0",
            )?;
            let half = DVec3::from(*size) * 0.5;
            Ok(RawMesh::with_material(
                box_triangles(DVec3::ZERO, half, 0.0, true),
                material,
            ))
        }
        GenerateDef::Plane { size, subdivisions } => {
            check(
                size.iter().all(|&s| positive(s)),
                "plane size",
                "two finite numbers > 0 (x and z extent)",
            )?;
            check(
                (1..=MAX_GRID_CELLS_PER_SIDE).contains(subdivisions),
                "plane subdivisions",
                &format!("1..={MAX_GRID_CELLS_PER_SIDE}"),
            )?;
            let n = *subdivisions;
            let tris = grid_triangles(n, |i, j| {
                DVec3::new(
                    (f64::from(i) / f64::from(n) - 0.5) * size[0],
                    0.0,
                    (f64::from(j) / f64::from(n) - 0.5) * size[1],
                )
            });
            Ok(RawMesh::with_material(tris, material))
        }
        GenerateDef::Sphere {
            radius,
            subdivisions,
        } => {
            check(positive(*radius), "sphere radius", "a finite number > 0")?;
            check(
                *subdivisions <= MAX_SPHERE_SUBDIVISIONS,
                "sphere subdivisions",
                &format!("0..={MAX_SPHERE_SUBDIVISIONS}"),
            )?;
            Ok(RawMesh::with_material(
                sphere_triangles(*radius, *subdivisions),
                material,
            ))
        }
        GenerateDef::CornellBox {
            closed_front,
            mirror_tall_block,
        } => {
            check(
                (0.0..=1.0).contains(mirror_tall_block),
                "cornell_box mirror_tall_block",
                "a reflectivity in [0, 1]",
            )?;
            Ok(cornell_box(*closed_front, *mirror_tall_block))
        }
        GenerateDef::Terrain {
            size,
            seed,
            amplitude,
            extent,
            octaves,
            frequency,
        } => {
            check(
                (1..=MAX_GRID_CELLS_PER_SIDE).contains(size),
                "terrain size",
                &format!("1..={MAX_GRID_CELLS_PER_SIDE} cells per side"),
            )?;
            check(
                amplitude.is_finite(),
                "terrain amplitude",
                "a finite number",
            )?;
            check(positive(*extent), "terrain extent", "a finite number > 0")?;
            check(
                positive(*frequency),
                "terrain frequency",
                "a finite number > 0",
            )?;
            check(
                (1..=MAX_TERRAIN_OCTAVES).contains(octaves),
                "terrain octaves",
                &format!("1..={MAX_TERRAIN_OCTAVES}"),
            )?;
            Ok(RawMesh::with_material(
                terrain_triangles(*size, *seed, *amplitude, *extent, *octaves, *frequency),
                material,
            ))
        }
    }
}

/// Two triangles for the quad centre ± u ± v, normal along u × v.
fn quad(out: &mut Vec<[DVec3; 3]>, centre: DVec3, u: DVec3, v: DVec3) {
    let a = centre - u - v;
    let b = centre + u - v;
    let c = centre + u + v;
    let d = centre - u + v;
    out.push([a, b, c]);
    out.push([a, c, d]);
}

/// A box with half extents `half`, turned `yaw_deg` about Y around `centre`, outward normals.
pub(super) fn box_triangles(
    centre: DVec3,
    half: DVec3,
    yaw_deg: f64,
    bottom: bool,
) -> Vec<[DVec3; 3]> {
    let r = DMat3::from_rotation_y(yaw_deg.to_radians());
    let (x, y, z) = (
        r * DVec3::X * half.x,
        DVec3::Y * half.y,
        r * DVec3::Z * half.z,
    );
    let mut out = Vec::with_capacity(12);
    // (face centre offset, u, v) with u x v pointing outwards.
    quad(&mut out, centre + x, y, z); // +X: Y x Z = X
    quad(&mut out, centre - x, z, y); // -X
    quad(&mut out, centre + y, z, x); // +Y: Z x X = Y
    if bottom {
        quad(&mut out, centre - y, x, z); // -Y
    }
    quad(&mut out, centre + z, x, y); // +Z: X x Y = Z
    quad(&mut out, centre - z, y, x); // -Z
    out
}

/// Cells (i, j), j (z) outer, i (x) inner; `point(i, j)` gives grid vertex (i, j), i, j in 0..=n.
fn grid_triangles(n: u32, point: impl Fn(u32, u32) -> DVec3) -> Vec<[DVec3; 3]> {
    let mut out = Vec::with_capacity(2 * (n as usize).pow(2));
    let mut row: Vec<DVec3> = (0..=n).map(|i| point(i, 0)).collect();
    for j in 0..n {
        let next: Vec<DVec3> = (0..=n).map(|i| point(i, j + 1)).collect();
        for i in 0..n as usize {
            let (p00, p10, p01, p11) = (row[i], row[i + 1], next[i], next[i + 1]);
            // (p01 - p00) x (p11 - p00) points to +Y for a flat cell.
            out.push([p00, p01, p11]);
            out.push([p00, p11, p10]);
        }
        row = next;
    }
    out
}

fn terrain_triangles(
    size: u32,
    seed: u64,
    amplitude: f64,
    extent: f64,
    octaves: u32,
    frequency: f64,
) -> Vec<[DVec3; 3]> {
    let n = f64::from(size);
    grid_triangles(size, |i, j| {
        let (u, v) = (f64::from(i) / n, f64::from(j) / n);
        DVec3::new(
            (u - 0.5) * extent,
            amplitude * fbm(u * frequency, v * frequency, seed, octaves),
            (v - 0.5) * extent,
        )
    })
}

const ICOSAHEDRON_FACES: [[usize; 3]; 20] = [
    [0, 11, 5],
    [0, 5, 1],
    [0, 1, 7],
    [0, 7, 10],
    [0, 10, 11],
    [1, 5, 9],
    [5, 11, 4],
    [11, 10, 2],
    [10, 7, 6],
    [7, 1, 8],
    [3, 9, 4],
    [3, 4, 2],
    [3, 2, 6],
    [3, 6, 8],
    [3, 8, 9],
    [4, 9, 5],
    [2, 4, 11],
    [6, 2, 10],
    [8, 6, 7],
    [9, 8, 1],
];

pub(super) fn sphere_triangles(radius: f64, subdivisions: u32) -> Vec<[DVec3; 3]> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let v = [
        DVec3::new(-1.0, t, 0.0),
        DVec3::new(1.0, t, 0.0),
        DVec3::new(-1.0, -t, 0.0),
        DVec3::new(1.0, -t, 0.0),
        DVec3::new(0.0, -1.0, t),
        DVec3::new(0.0, 1.0, t),
        DVec3::new(0.0, -1.0, -t),
        DVec3::new(0.0, 1.0, -t),
        DVec3::new(t, 0.0, -1.0),
        DVec3::new(t, 0.0, 1.0),
        DVec3::new(-t, 0.0, -1.0),
        DVec3::new(-t, 0.0, 1.0),
    ]
    .map(|p| p.normalize());
    let mut tris: Vec<[DVec3; 3]> = ICOSAHEDRON_FACES
        .iter()
        .map(|f| [v[f[0]], v[f[1]], v[f[2]]])
        .collect();
    for _ in 0..subdivisions {
        let mut next = Vec::with_capacity(tris.len() * 4);
        // (a + b) is commutative in IEEE arithmetic, so both faces sharing an edge compute the
        // same midpoint and the sphere stays watertight without a vertex table.
        let mid = |a: DVec3, b: DVec3| (a + b).normalize();
        for [a, b, c] in tris {
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            next.push([a, ab, ca]);
            next.push([b, bc, ab]);
            next.push([c, ca, bc]);
            next.push([ab, bc, ca]);
        }
        tris = next;
    }
    tris.into_iter().map(|t| t.map(|p| p * radius)).collect()
}

fn cornell_box(closed_front: bool, mirror_tall_block: f64) -> RawMesh {
    let mut mesh = RawMesh {
        materials: vec![
            Material {
                diffuse: CORNELL_WHITE,
                mirror: 0.0,
            },
            Material {
                diffuse: CORNELL_RED,
                mirror: 0.0,
            },
            Material {
                diffuse: CORNELL_GREEN,
                mirror: 0.0,
            },
            Material {
                diffuse: CORNELL_WHITE,
                mirror: mirror_tall_block,
            },
        ],
        ..RawMesh::default()
    };
    let mut add = |tris: Vec<[DVec3; 3]>, material: u32| {
        mesh.triangle_material
            .extend(std::iter::repeat_n(material, tris.len()));
        mesh.triangles.extend(tris);
    };
    let wall = |centre: DVec3, u: DVec3, v: DVec3| {
        let mut t = Vec::new();
        quad(&mut t, centre, u, v);
        t
    };
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    add(wall(DVec3::new(0.0, 0.0, 0.0), z, x), 0); // floor, +Y
    add(wall(DVec3::new(0.0, 2.0, 0.0), x, z), 0); // ceiling, -Y
    add(wall(DVec3::new(0.0, 1.0, -1.0), x, y), 0); // back, +Z
    add(wall(DVec3::new(-1.0, 1.0, 0.0), y, z), 1); // left red, +X
    add(wall(DVec3::new(1.0, 1.0, 0.0), z, y), 2); // right green, -X
    if closed_front {
        add(wall(DVec3::new(0.0, 1.0, 1.0), y, x), 0); // front, -Z
    }
    add(
        box_triangles(
            DVec3::new(0.33, 0.3, 0.3),
            DVec3::new(0.3, 0.3, 0.3),
            -17.0,
            false,
        ),
        0,
    );
    add(
        box_triangles(
            DVec3::new(-0.33, 0.6, -0.3),
            DVec3::new(0.3, 0.6, 0.3),
            17.0,
            false,
        ),
        3,
    );
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::is_degenerate;

    fn normal(t: &[DVec3; 3]) -> DVec3 {
        (t[1] - t[0]).cross(t[2] - t[0])
    }

    fn centroid(t: &[DVec3; 3]) -> DVec3 {
        (t[0] + t[1] + t[2]) / 3.0
    }

    fn gen(def: GenerateDef) -> RawMesh {
        generate(&def, Material::DEFAULT, u64::MAX).unwrap()
    }

    #[test]
    fn box_is_closed_with_outward_normals() {
        let m = gen(GenerateDef::Box {
            size: [2.0, 4.0, 6.0],
        });
        assert_eq!(m.triangles.len(), 12);
        let area: f64 = m.triangles.iter().map(|t| normal(t).length() / 2.0).sum();
        assert!((area - 2.0 * (8.0 + 12.0 + 24.0)).abs() < 1e-9, "{area}");
        for t in &m.triangles {
            assert!(normal(t).dot(centroid(t)) > 0.0);
            for p in t {
                assert_eq!(p.abs(), DVec3::new(1.0, 2.0, 3.0));
            }
        }
        // Divergence theorem: signed volume of a closed outward mesh = box volume.
        let vol: f64 = m
            .triangles
            .iter()
            .map(|t| t[0].dot(t[1].cross(t[2])) / 6.0)
            .sum();
        assert!((vol - 48.0).abs() < 1e-9, "{vol}");
    }

    #[test]
    fn sphere_counts_radius_and_closure() {
        for s in 0..=3u32 {
            let m = gen(GenerateDef::Sphere {
                radius: 2.5,
                subdivisions: s,
            });
            assert_eq!(m.triangles.len(), 20 * 4usize.pow(s));
            for t in &m.triangles {
                assert!(!is_degenerate(t));
                assert!(normal(t).dot(centroid(t)) > 0.0, "outward");
                for p in t {
                    assert!((p.length() - 2.5).abs() < 1e-12);
                }
            }
            // Closed: volume approaches 4/3 pi r^3 from below.
            let vol: f64 = m
                .triangles
                .iter()
                .map(|t| t[0].dot(t[1].cross(t[2])) / 6.0)
                .sum();
            let ball = 4.0 / 3.0 * std::f64::consts::PI * 2.5f64.powi(3);
            assert!(vol < ball && vol > 0.6 * ball, "s={s} vol={vol}");
        }
        // Watertight: every edge is shared by exactly two triangles, in opposite directions.
        let m = gen(GenerateDef::Sphere {
            radius: 1.0,
            subdivisions: 2,
        });
        let key = |p: DVec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let mut edges = std::collections::HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                *edges.entry((key(t[k]), key(t[(k + 1) % 3]))).or_insert(0) += 1;
            }
        }
        for ((a, b), n) in &edges {
            assert_eq!(*n, 1);
            assert_eq!(edges.get(&(*b, *a)), Some(&1));
        }
    }

    #[test]
    fn plane_and_terrain_counts_and_orientation() {
        let m = gen(GenerateDef::Plane {
            size: [4.0, 2.0],
            subdivisions: 3,
        });
        assert_eq!(m.triangles.len(), 18);
        let area: f64 = m.triangles.iter().map(|t| normal(t).length() / 2.0).sum();
        assert!((area - 8.0).abs() < 1e-12);
        assert!(m.triangles.iter().all(|t| normal(t).y > 0.0));
        let def = GenerateDef::Terrain {
            size: 40,
            seed: 5,
            amplitude: 2.0,
            extent: 8.0,
            octaves: 4,
            frequency: 3.0,
        };
        let t1 = gen(def.clone());
        assert_eq!(t1.triangles.len(), 2 * 40 * 40);
        assert_eq!(expected_triangles(&def), 3200);
        assert_eq!(t1.triangles, gen(def.clone()).triangles, "deterministic");
        let other = gen(GenerateDef::Terrain {
            size: 40,
            seed: 6,
            amplitude: 2.0,
            extent: 8.0,
            octaves: 4,
            frequency: 3.0,
        });
        assert_ne!(t1.triangles, other.triangles, "seed matters");
        let ys: Vec<f64> = t1.triangles.iter().flatten().map(|p| p.y).collect();
        let (lo, hi) = ys
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &y| (l.min(y), h.max(y)));
        assert!(lo >= -2.0 && hi <= 2.0 && hi - lo > 0.5, "{lo}..{hi}");
        for t in &t1.triangles {
            assert!(normal(t).y > 0.0, "heightfield faces up");
            for p in t {
                assert!(p.x.abs() <= 4.0 && p.z.abs() <= 4.0);
            }
        }
    }

    #[test]
    fn cornell_box_layout() {
        for closed in [false, true] {
            let m = gen(GenerateDef::CornellBox {
                closed_front: closed,
                mirror_tall_block: 0.5,
            });
            let def = GenerateDef::CornellBox {
                closed_front: closed,
                mirror_tall_block: 0.5,
            };
            assert_eq!(m.triangles.len() as u64, expected_triangles(&def));
            assert_eq!(m.triangles.len(), if closed { 32 } else { 30 });
            assert_eq!(m.materials.len(), 4);
            assert_eq!(m.materials[3].mirror, 0.5);
            // Everything inside the box, walls facing the room centre.
            let room = DVec3::new(0.0, 1.0, 0.0);
            for (i, t) in m.triangles.iter().enumerate() {
                for p in t {
                    assert!(p.x.abs() <= 1.0 && p.z.abs() <= 1.0 && (0.0..=2.0).contains(&p.y));
                }
                if i < 10 {
                    assert!(normal(t).dot(room - centroid(t)) > 0.0, "wall {i}");
                }
            }
            // Left wall (x = -1) is red, right wall green.
            for (t, &mat) in m.triangles.iter().zip(&m.triangle_material) {
                if t.iter().all(|p| p.x == -1.0) {
                    assert_eq!(m.materials[mat as usize].diffuse, CORNELL_RED);
                }
                if t.iter().all(|p| p.x == 1.0) {
                    assert_eq!(m.materials[mat as usize].diffuse, CORNELL_GREEN);
                }
            }
            let front = m
                .triangles
                .iter()
                .filter(|t| t.iter().all(|p| p.z == 1.0))
                .count();
            assert_eq!(front, if closed { 2 } else { 0 });
        }
    }

    #[test]
    fn bad_parameters_are_refused() {
        let m = Material::DEFAULT;
        assert!(generate(
            &GenerateDef::Box {
                size: [1.0, 0.0, 1.0]
            },
            m,
            u64::MAX
        )
        .is_err());
        assert!(generate(
            &GenerateDef::Sphere {
                radius: 1.0,
                subdivisions: 9
            },
            m,
            u64::MAX
        )
        .is_err());
        assert!(generate(
            &GenerateDef::Sphere {
                radius: f64::NAN,
                subdivisions: 1
            },
            m,
            u64::MAX
        )
        .is_err());
        let e = generate(
            &GenerateDef::Terrain {
                size: 0,
                seed: 0,
                amplitude: 1.0,
                extent: 1.0,
                octaves: 1,
                frequency: 1.0,
            },
            m,
            u64::MAX,
        )
        .unwrap_err();
        assert_eq!(e.0, "terrain size");
        // A terrain the memory cannot hold is refused from its count (2 x 300^2 = 180,000
        // triangles against a budget of 131,072) without building it.
        let terrain = GenerateDef::Terrain {
            size: 300,
            seed: 0,
            amplitude: 1.0,
            extent: 1.0,
            octaves: 1,
            frequency: 1.0,
        };
        let e = generate(&terrain, m, 131_072).unwrap_err();
        assert!(
            e.1.contains("give 180000 triangles, more than the 131072"),
            "{}",
            e.1
        );
        assert!(generate(&terrain, m, 180_000).is_ok());
    }
}
