//! Building the memory map of one frame.

use super::*;
use crate::accel::kd_tree::{self, KdNode, KdParams, KdTree};
use crate::accel::Aabb;
use crate::scene::Scene;
use glam::{DAffine3, DMat3, DVec3};

#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    #[error(
        "scene `{scene}` does not fit the memory: bank {bank} ({name}) needs {at_least}{needed} words \
         ({needed_kib:.1} KiB) but holds {capacity} ({capacity_kib:.1} KiB); {advice}",
        at_least = if *estimated { "at least " } else { "" },
        needed_kib = *needed as f64 * 4.0 / 1024.0,
        capacity_kib = *capacity as f64 * 4.0 / 1024.0,
        advice = bank_advice(*bank)
    )]
    TooBig {
        scene: String,
        bank: usize,
        name: &'static str,
        needed: usize,
        capacity: usize,
        /// Counted from the scene before any tree was built (a lower bound).
        estimated: bool,
    },
    #[error(
        "scene `{scene}`: {what} = {value:.4e} {problem} {format} (its normal numbers have \
         magnitudes {min:.4e} to {max:.4e}); {advice}",
        min = format.to_f64(format.min_normal(false)),
        max = format.to_f64(format.max_finite(false))
    )]
    NotRepresentable {
        scene: String,
        what: String,
        value: f64,
        problem: &'static str,
        format: Format,
        advice: &'static str,
    },
    #[error("scene `{scene}`: {what} does not fit the 30-bit address field of a kd node")]
    AddressOverflow { scene: String, what: String },
    #[error(
        "kd split plane {split} is not representable in {format}: the tree was built on \
         geometry that was not rounded to the format (a bug in dynrt, please report it)"
    )]
    SplitNotRepresentable { split: f64, format: Format },
    #[error("scene `{scene}` has frame {frame} but only {frames} frames (0..{frames})")]
    NoSuchFrame {
        scene: String,
        frame: u32,
        frames: u32,
    },
    #[error(
        "scene `{scene}`: object `{object}` has no triangle that survives rounding to {format}"
    )]
    EmptyAfterRounding {
        scene: String,
        object: String,
        format: Format,
    },
}

/// What to change when a bank is full.
fn bank_advice(bank: usize) -> &'static str {
    match bank {
        NODES | LISTS => "use fewer triangles per object (simplify the mesh) or instance repeated parts",
        TRIANGLES_A | TRIANGLES_B => "use fewer triangles (simplify the mesh, a coarser generator) or instance repeated objects",
        INSTANCES => "use fewer instances",
        _ => "use a lower resolution (the scene's [camera] width and height, or --size WxH of render, rtl and sim), fewer lights or fewer materials",
    }
}

/// Checks from the scene's counts alone, before any tree is built, that the memory map can fit:
/// every bank's words are counted where the count is exact (triangles, instances, the frame
/// bank) and bounded from below where a tree decides them (each triangle is listed at least
/// once, each object and the top level have at least one node).
pub fn check_capacity(scene: &Scene, memory: &MemoryConfig) -> Result<(), LayoutError> {
    let triangles = scene.triangle_count();
    let materials: usize = scene.objects.iter().map(|o| o.materials.len()).sum();
    let mut needed = [0usize; 6];
    needed[NODES] = NODE_WORDS * (scene.objects.len() + 1);
    needed[LISTS] = triangles;
    needed[TRIANGLES_A] = TRIANGLE_BANK_WORDS * triangles;
    needed[TRIANGLES_B] = TRIANGLE_BANK_WORDS * triangles;
    needed[INSTANCES] = INSTANCE_WORDS * scene.instances.len();
    needed[FRAME] = FrameMap::LIGHTS
        + LIGHT_WORDS * scene.lights.len()
        + MATERIAL_WORDS * materials
        + (scene.camera.width * scene.camera.height) as usize;
    for (bank, &words) in needed.iter().enumerate() {
        if words > memory.bank_words() {
            return Err(LayoutError::TooBig {
                scene: scene.source.display().to_string(),
                bank,
                name: BANK_NAMES[bank],
                needed: words,
                capacity: memory.bank_words(),
                estimated: true,
            });
        }
    }
    Ok(())
}

/// Rounds a group of values that the hardware reads together (a matrix, a vector) into `f`,
/// refusing what the format cannot hold: an infinite or NaN word, or a value that flushes to
/// zero although it is within the group's precision of its largest member (a rotation's
/// 1e-17 next to 1 is noise and may vanish; a scale of 1e-39 next to nothing is the matrix).
fn checked_words(
    f: Format,
    scene: &Scene,
    what: &dyn Fn(usize) -> String,
    values: &[f64],
) -> Result<Vec<u32>, LayoutError> {
    let largest = values.iter().fold(0f64, |m, v| m.max(v.abs()));
    let matters = largest * 2f64.powi(-(f.man_bits as i32) - 2);
    let refuse = |i: usize, problem, advice| LayoutError::NotRepresentable {
        scene: scene.source.display().to_string(),
        what: what(i),
        value: values[i],
        problem,
        format: f,
        advice,
    };
    let mut words = Vec::with_capacity(values.len());
    for (i, &x) in values.iter().enumerate() {
        let w = f.from_f64(x);
        if !x.is_finite() || f.is_nan(w) || f.is_inf(w) {
            return Err(refuse(i, "overflows", "bring the scene's coordinates, scales and colours into the format's range, or choose a format with more exponent bits (e.g. --format e8m16)"));
        }
        if x != 0.0 && f.is_zero(w) && x.abs() >= matters {
            return Err(refuse(i, "underflows to zero in", "bring the scene's sizes nearer 1 (an instance's scale and its inverse both go into the hardware), or choose a format with more exponent bits (e.g. --format e8m16)"));
        }
        words.push(w);
    }
    Ok(words)
}

/// [`affine_words`] through [`checked_words`].
fn checked_affine_words(
    f: Format,
    scene: &Scene,
    what: &str,
    m: &DAffine3,
) -> Result<Vec<u32>, LayoutError> {
    let mut values = Vec::with_capacity(12);
    for r in 0..3 {
        let row = m.matrix3.row(r);
        values.extend([row.x, row.y, row.z, m.translation[r]]);
    }
    checked_words(
        f,
        scene,
        &|i| format!("{what}, row {} column {}", i / 4, i % 4),
        &values,
    )
}

/// The per-object kd-trees and unit-triangle transforms of a scene for one number format,
/// built once and reused by every frame (only the top-level tree follows the instances).
///
/// The builder rounds every candidate split plane to the format before scoring it and sorts
/// triangles against the rounded plane, so the planes the hardware stores are exactly the
/// builder's and no triangle falls between them. A triangle whose transform does not fit the
/// format (an entry overflows, as for slivers in narrow formats) is left out of the tree and
/// reported in `dropped`.
///
/// Each object is stored relative to its anchor, the centre of its bounding box when the
/// object lies farther from its origin than its size (`object_anchor`): the Woop
/// transforms and the tree are built from `triangle - anchor`, and the anchor is folded into
/// the instance matrix (or, for a scene of one untransformed object, into the eye and the
/// lights). An object far from its file's origin would otherwise have unit-triangle
/// transforms whose translations cancel in the transform unit, and rays from inside it leak
/// through its edges (fandisk, 15 units from its origin: 224 leaked rays per million at e7m16;
/// 0 when centred).
#[derive(Clone, Debug)]
pub struct SceneTrees {
    pub format: Format,
    /// Where each object's stored coordinates have their origin, in the object's file space.
    pub anchors: Vec<DVec3>,
    /// Woop transforms per object, in the scene's triangle order (zero words for dropped ones).
    pub transforms: Vec<Vec<[u32; 12]>>,
    pub trees: Vec<KdTree>,
    /// Local indices of the triangles left out, per object.
    pub dropped: Vec<Vec<u32>>,
}

impl SceneTrees {
    pub fn build(scene: &Scene, format: Format) -> Result<SceneTrees, LayoutError> {
        Self::build_with(scene, format, &KdParams::default())
    }

    /// [`SceneTrees::build`] with other tree parameters (their `split_format` is `format`).
    pub fn build_with(
        scene: &Scene,
        format: Format,
        params: &KdParams,
    ) -> Result<SceneTrees, LayoutError> {
        check_capacity(scene, &MemoryConfig::default())?;
        let params = KdParams {
            split_format: Some(format),
            root_clip: true,
            ..params.clone()
        };
        let mut out = SceneTrees {
            format,
            anchors: vec![],
            transforms: vec![],
            trees: vec![],
            dropped: vec![],
        };
        for object in &scene.objects {
            let anchor = object_anchor(object);
            let stored: Vec<[DVec3; 3]> = object
                .triangles
                .iter()
                .map(|t| t.map(|v| v - anchor))
                .collect();
            let mut transforms = Vec::with_capacity(stored.len());
            let (mut kept, mut dropped) = (Vec::new(), Vec::new());
            for (i, t) in stored.iter().enumerate() {
                let words = affine_words(format, &unit_triangle_transform(t));
                if is_flat(t) || words.iter().any(|&w| format.is_nan(w) || format.is_inf(w)) {
                    dropped.push(i as u32);
                    transforms.push([0; 12]);
                } else {
                    kept.push(i as u32);
                    transforms.push(words);
                }
            }
            if kept.is_empty() {
                return Err(LayoutError::EmptyAfterRounding {
                    scene: scene.source.display().to_string(),
                    object: object.name.clone(),
                    format,
                });
            }
            let kept_tris: Vec<[DVec3; 3]> = kept.iter().map(|&i| stored[i as usize]).collect();
            let mut tree = kd_tree::build_sah(&kept_tris, &params);
            for p in tree.prim_indices.iter_mut() {
                *p = kept[*p as usize];
            }
            out.anchors.push(anchor);
            out.transforms.push(transforms);
            out.trees.push(tree);
            out.dropped.push(dropped);
        }
        Ok(out)
    }

    pub fn dropped_count(&self) -> usize {
        self.dropped.iter().map(Vec::len).sum()
    }
}

/// Where an object's stored coordinates start: the centre of its bounding box when that lies
/// farther from the file's origin than the object's own size (the transforms' translations
/// would then be larger than the object and cancel in the transform unit), else the file's
/// origin, keeping coordinates exactly as modelled (the Cornell box's walls stay at 0 and 2,
/// and its kd-tree is the builder's tree for the authored coordinates: translated by its
/// centre, the SAH picks other planes and costs 19% more traversal).
fn object_anchor(object: &crate::scene::Object) -> DVec3 {
    let (lo, hi) = object.bounds();
    let centre = (lo + hi) * 0.5;
    if centre.length() > (hi - lo).length() {
        centre
    } else {
        DVec3::ZERO
    }
}

fn is_flat(t: &[DVec3; 3]) -> bool {
    (t[0] - t[2]).cross(t[1] - t[2]).length_squared() == 0.0
}

/// An instance's world bounds rounded outward to format values, plus a margin of a few ulps
/// so that rays transformed with rounding still find the instance where they hit it.
fn instance_box(f: Format, local: &Aabb, to_world: &DAffine3) -> Aabb {
    let b = local.transformed(to_world);
    let margin = (b.max - b.min).max_element().max(b.max.abs().max_element())
        * 2f64.powi(-(f.man_bits as i32) + 3);
    let lo = b.min - DVec3::splat(margin);
    let hi = b.max + DVec3::splat(margin);
    Aabb::new(
        DVec3::new(f.round_down(lo.x), f.round_down(lo.y), f.round_down(lo.z)),
        DVec3::new(f.round_up(hi.x), f.round_up(hi.y), f.round_up(hi.z)),
    )
}

/// The matrix words of an affine map, row-major 3x4.
fn affine_words(f: Format, m: &DAffine3) -> [u32; 12] {
    let mut w = [0; 12];
    for r in 0..3 {
        let row = m.matrix3.row(r);
        w[r * 4] = f.from_f64(row.x);
        w[r * 4 + 1] = f.from_f64(row.y);
        w[r * 4 + 2] = f.from_f64(row.z);
        w[r * 4 + 3] = f.from_f64(m.translation[r]);
    }
    w
}

/// Woop's unit-triangle transform: the affine map taking triangle (A, B, C) to the unit
/// triangle (1,0,0), (0,1,0), (0,0,0) and its unit normal to (0,0,1).
pub fn unit_triangle_transform(t: &[DVec3; 3]) -> DAffine3 {
    let [a, b, c] = *t;
    let n = (a - c).cross(b - c).normalize();
    DAffine3::from_mat3_translation(DMat3::from_cols(a - c, b - c, n), c).inverse()
}

/// Packs a kd-tree into node words at `node_base` (node index) with leaf lists at `list_base`
/// (bank-1 address). `map_prim` turns a builder primitive index into the stored id.
fn pack_tree(
    f: Format,
    tree: &KdTree,
    node_base: u32,
    list_base: u32,
    map_prim: impl Fn(u32) -> u32,
    nodes: &mut Vec<u32>,
    lists: &mut Vec<u32>,
) -> Result<(), LayoutError> {
    for node in &tree.nodes {
        match *node {
            KdNode::Inner {
                axis,
                split,
                children,
            } => {
                let w = f.from_f64(split);
                if f.to_f64(w) != split {
                    return Err(LayoutError::SplitNotRepresentable { split, format: f });
                }
                nodes.push(encode_inner(axis as usize, node_base + children));
                nodes.push(w);
            }
            KdNode::Leaf { first, count } => {
                nodes.push(encode_leaf(list_base + first));
                nodes.push(count);
            }
        }
    }
    debug_assert_eq!(lists.len() as u32, list_base);
    lists.extend(tree.prim_indices.iter().map(|&p| map_prim(p)));
    Ok(())
}

/// Builds the memory map of `frame`.
pub fn build(
    scene: &Scene,
    trees: &SceneTrees,
    frame: u32,
    memory: &MemoryConfig,
) -> Result<Layout, LayoutError> {
    let f = trees.format;
    let scene_name = scene.source.display().to_string();
    if frame >= scene.frames {
        return Err(LayoutError::NoSuchFrame {
            scene: scene_name,
            frame,
            frames: scene.frames,
        });
    }
    let mut banks: Vec<Vec<u32>> = vec![Vec::new(); 6];

    // Triangles and shading data, global triangle index = object base + local index.
    let mut first_triangle = Vec::new();
    let (mut tri_count, mut mat_count) = (0u32, 0u32);
    for (o, object) in scene.objects.iter().enumerate() {
        first_triangle.push(tri_count);
        for (i, t) in object.triangles.iter().enumerate() {
            // Dropped triangles keep zero words so the addressing stays regular; no leaf
            // refers to them.
            let t = &t.map(|v| v - trees.anchors[o]);
            let normal = if is_flat(t) {
                DVec3::ZERO
            } else {
                (t[0] - t[2]).cross(t[1] - t[2]).normalize()
            };
            let t = &trees.transforms[o][i];
            let [nx, ny, nz] = [normal.x, normal.y, normal.z].map(|c| f.from_f64(c));
            banks[TRIANGLES_A].extend(&t[..TRANSFORM_BANK_WORDS]);
            banks[TRIANGLES_A].extend([nx, ny]);
            banks[TRIANGLES_B].extend(&t[TRANSFORM_BANK_WORDS..]);
            banks[TRIANGLES_B].extend([nz, mat_count + object.triangle_material[i]]);
        }
        tri_count += object.triangles.len() as u32;
        mat_count += object.materials.len() as u32;
    }

    // The hardware's coordinates: without a top level, the only object's stored coordinates;
    // with one, the world seen from the eye, so that objects near the camera have small
    // coordinates wherever the scene puts them.
    let origin = if scene.is_single_untransformed_object() {
        trees.anchors[0]
    } else {
        scene.camera.eye
    };
    // Top-level tree over the instances' bounds (absent for one untransformed object). The
    // matrices map stored (anchored) object coordinates to the hardware's.
    let to_world: Vec<DAffine3> = scene
        .instances
        .iter()
        .map(|i| {
            DAffine3::from_translation(-origin)
                * i.object_to_world(frame)
                * DAffine3::from_translation(trees.anchors[i.object])
        })
        .collect();
    let top = if scene.is_single_untransformed_object() {
        None
    } else {
        let boxes: Vec<Aabb> = scene
            .instances
            .iter()
            .zip(&to_world)
            .map(|(inst, m)| {
                let b = instance_box(f, &trees.trees[inst.object].bounds, m);
                let values = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
                let box_words = checked_words(
                    f,
                    scene,
                    &|i| {
                        format!(
                            "instance '{}': its bounding box {} {}",
                            inst.name,
                            ["min", "max"][i / 3],
                            ["x", "y", "z"][i % 3]
                        )
                    },
                    &values,
                );
                if let Err(box_error) = box_words {
                    // A box that overflows is the consequence; the user wrote the matrix's
                    // translate, rotate or scale, so name the entry of it that does not fit
                    // when there is one.
                    checked_affine_words(
                        f,
                        scene,
                        &format!(
                            "instance '{}': its object-to-world matrix at frame {frame} (from its translate, rotate and scale; relative to the eye)",
                            inst.name
                        ),
                        m,
                    )?;
                    return Err(box_error);
                }
                Ok(b)
            })
            .collect::<Result<_, LayoutError>>()?;
        Some(kd_tree::build_sah_boxes(
            &boxes,
            &KdParams {
                split_format: Some(f),
                ..KdParams::default()
            },
        ))
    };

    // Object trees first, the top-level tree (rebuilt every frame) after them: its root has
    // the same index in every frame and a frame update rewrites only its words.
    let (mut nodes, mut lists) = (Vec::new(), Vec::new());
    let mut object_roots = Vec::new();
    for (o, tree) in trees.trees.iter().enumerate() {
        let node_base = (nodes.len() / NODE_WORDS) as u32;
        object_roots.push(node_base);
        let base = first_triangle[o];
        pack_tree(
            f,
            tree,
            node_base,
            lists.len() as u32,
            |p| base + p,
            &mut nodes,
            &mut lists,
        )?;
    }
    let mut top_root = None;
    let top_lists = lists.len() as u32;
    if let Some(top) = &top {
        let node_base = (nodes.len() / NODE_WORDS) as u32;
        top_root = Some(node_base);
        pack_tree(
            f,
            top,
            node_base,
            lists.len() as u32,
            |p| p,
            &mut nodes,
            &mut lists,
        )?;
    }
    let node_base = nodes.len() / NODE_WORDS;
    banks[NODES] = nodes;
    banks[LISTS] = lists;
    if node_base >= 1 << 30 || banks[LISTS].len() >= 1 << 30 {
        return Err(LayoutError::AddressOverflow {
            scene: scene_name,
            what: "the kd-tree".into(),
        });
    }

    // Instances.
    for (inst, m) in scene.instances.iter().zip(&to_world) {
        let item = format!("instance '{}'", inst.name);
        banks[INSTANCES].extend(checked_affine_words(
            f,
            scene,
            &format!("{item}: its world-to-object matrix"),
            &m.inverse(),
        )?);
        let normal = m.matrix3.inverse().transpose();
        let values: Vec<f64> = (0..3).flat_map(|r| normal.row(r).to_array()).collect();
        banks[INSTANCES].extend(checked_words(
            f,
            scene,
            &|i| format!("{item}: its normal matrix, row {} column {}", i / 3, i % 3),
            &values,
        )?);
        banks[INSTANCES].extend([
            object_roots[inst.object],
            first_triangle[inst.object],
            inst.object as u32,
        ]);
    }

    // Frame constants, lights, frame buffer.
    let cam = &scene.camera;
    let (w, h) = (cam.width as f64, cam.height as f64);
    let basis = cam.basis();
    let half_h = (cam.fov_y_deg.to_radians() / 2.0).tan();
    let aspect = w / h;
    let c0 = basis.right * (2.0 * half_h * aspect / w);
    let c1 = basis.up * (-2.0 * half_h / h);
    let c2 = basis.forward
        + basis.right * ((1.0 / w - 1.0) * half_h * aspect)
        + basis.up * ((1.0 - 1.0 / h) * half_h);
    let camera = DAffine3::from_mat3_translation(DMat3::from_cols(c0, c1, DVec3::ZERO), c2);
    let fr = &mut banks[FRAME];
    fr.extend(checked_affine_words(
        f,
        scene,
        "the camera's pixel-to-direction matrix",
        &camera,
    )?);
    let xyz = |i: usize| ["x", "y", "z"][i % 3];
    let rgb = |i: usize| ["r", "g", "b"][i % 3];
    fr.extend(checked_words(
        f,
        scene,
        &|i| {
            format!(
                "the camera's eye {} (relative to the hardware's origin)",
                xyz(i)
            )
        },
        &(cam.eye - origin).to_array(),
    )?);
    fr.extend(checked_words(
        f,
        scene,
        &|_| "ambient".into(),
        &[scene.render.ambient],
    )?);
    fr.extend(checked_words(
        f,
        scene,
        &|i| format!("background {}", rgb(i)),
        &scene.render.background,
    )?);
    let (shadow_eps, mirror_eps) = secondary_t_min(f, scene);
    fr.extend(checked_words(
        f,
        scene,
        &|i| {
            format!(
                "the {} rays' start offset (from the scene's size)",
                ["shadow", "mirror"][i]
            )
        },
        &[shadow_eps, mirror_eps],
    )?);
    fr.extend([0, f.one(), f.from_int(2)]);
    debug_assert_eq!(fr.len(), FrameMap::LIGHTS);
    for (k, light) in scene.lights.iter().enumerate() {
        fr.extend(checked_words(
            f,
            scene,
            &|i| {
                format!(
                    "light {k}: position {} (relative to the hardware's origin)",
                    xyz(i)
                )
            },
            &(light.position - origin).to_array(),
        )?);
        fr.extend(checked_words(
            f,
            scene,
            &|i| format!("light {k}: colour {}", rgb(i)),
            &light.color,
        )?);
    }
    let materials = fr.len() as u32;
    for object in &scene.objects {
        for (k, m) in object.materials.iter().enumerate() {
            let values = [m.diffuse[0], m.diffuse[1], m.diffuse[2], m.mirror];
            fr.extend(checked_words(
                f,
                scene,
                &|i| {
                    format!(
                        "object '{}': material {k}: {}",
                        object.name,
                        ["diffuse r", "diffuse g", "diffuse b", "mirror"][i]
                    )
                },
                &values,
            )?);
        }
    }
    let frame_buffer = fr.len() as u32;
    fr.resize(fr.len() + (cam.width * cam.height) as usize, 0);

    for (bank, words) in banks.iter().enumerate() {
        if words.len() > memory.bank_words() {
            return Err(LayoutError::TooBig {
                scene: scene_name,
                bank,
                name: BANK_NAMES[bank],
                needed: words.len(),
                capacity: memory.bank_words(),
                estimated: false,
            });
        }
    }

    let info = LayoutInfo {
        width: cam.width,
        height: cam.height,
        shadows: scene.render.shadows && !scene.lights.is_empty(),
        reflection_depth: scene.render.reflection_depth,
        light_count: scene.lights.len() as u32,
        top_root,
        top_lists,
        materials,
        object_root: object_roots[0],
        instance_count: scene.instances.len() as u32,
        triangle_count: tri_count,
        frame_buffer,
        object_depth: trees.trees.iter().map(|t| t.depth).max().unwrap_or(0),
        top_depth: top.as_ref().map_or(0, |t| t.depth),
        object_first_triangle: first_triangle,
        origin: origin.to_array(),
    };
    Ok(Layout {
        format: f,
        memory: *memory,
        banks,
        info,
    })
}

/// The smallest t of secondary rays. A shadow ray runs from the hit point (t = 0) to the light
/// (t = 1); a mirror ray's direction has the length of the incoming one. Both start a few
/// hundred ulps of the scene's size away from the surface, so the rounding of the hit point
/// (about one ulp of its coordinates) cannot put the origin behind its own surface; the
/// originating triangle is also skipped by id (see `model::golden`).
fn secondary_t_min(f: Format, scene: &Scene) -> (f64, f64) {
    let ulp = 2f64.powi(-(f.man_bits as i32));
    let shadow = (ulp * 256.0).min(1e-2);
    let extent = scene_extent(scene);
    (shadow, (extent * ulp * 256.0).max(f64::MIN_POSITIVE))
}

fn scene_extent(scene: &Scene) -> f64 {
    let mut b = Aabb::from_points(std::iter::once(&scene.camera.eye));
    for inst in &scene.instances {
        let (lo, hi) = scene.objects[inst.object].bounds();
        b = b.union(&Aabb::new(lo, hi).transformed(&inst.object_to_world(0)));
    }
    (b.max - b.min).max_element()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
[camera]
eye = [0.0, 1.0, 4.0]
look_at = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_y = 40.0
width = 8
height = 6

[[lights]]
position = [0.0, 1.9, 0.0]
color = [1.0, 1.0, 1.0]

[[objects]]
name = "ball"
generate = { kind = "sphere", subdivisions = 1 }

[[instances]]
object = "ball"
translate = [0.5, 1.0, 0.0]

[[instances]]
object = "ball"
translate = [-0.5, 1.0, 0.0]
scale = [0.5, 0.5, 0.5]
"#;

    fn scene() -> Scene {
        Scene::from_toml_str(SCENE, Path::new("."), "test.toml").unwrap()
    }
    use std::path::Path;

    #[test]
    fn unit_triangle_transform_maps_vertices_to_the_unit_triangle() {
        let t = [
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-2.0, 0.5, 1.0),
            DVec3::new(0.3, -1.0, 2.0),
        ];
        let m = unit_triangle_transform(&t);
        for (v, want) in t.iter().zip([DVec3::X, DVec3::Y, DVec3::ZERO]) {
            assert!((m.transform_point3(*v) - want).length() < 1e-12);
        }
        let n = (t[0] - t[2]).cross(t[1] - t[2]).normalize();
        assert!((m.transform_vector3(n) - DVec3::Z).length() < 1e-12);
    }

    /// The shader of a scene without instances uses the stored normals as they are
    /// (`units::world_normal`): each must be unit to the format's precision, its length within
    /// two units in the last place of 1, in both formats.
    #[test]
    fn stored_normals_are_unit_to_the_formats_precision() {
        for f in [Format::E7M16, Format::E8M23] {
            let s = scene();
            let trees = SceneTrees::build(&s, f).unwrap();
            let l = build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
            let triangles = s.objects[0].triangles.len() as u32;
            assert!(triangles >= 80);
            let ulp = 2f64.powi(-(f.man_bits as i32));
            for t in 0..triangles {
                let (n, _) = l.triangle_shading(t);
                let length = DVec3::from_array(n.map(|c| f.to_f64(c))).length();
                assert!(
                    (length - 1.0).abs() <= 2.0 * ulp,
                    "{f}: triangle {t}'s stored normal has length {length}"
                );
            }
        }
    }

    /// Between two frames of an animated scene only the words the frame update names change,
    /// and its sizes are the top-level tree's (what the banks hold beyond the object trees)
    /// and two matrices (12 + 9 words) per instance.
    #[test]
    fn a_frame_update_is_the_top_level_tree_and_the_instance_matrices() {
        let text =
            format!("{SCENE}[instances.animate]\nframes = 3\ntranslate = [-0.5, -1.0, 1.0]\n");
        let s = Scene::from_toml_str(&text, Path::new("."), "test.toml").unwrap();
        let trees = SceneTrees::build(&s, Format::E7M16).unwrap();
        let memory = MemoryConfig::default();
        let before = build(&s, &trees, 0, &memory).unwrap();
        let after = build(&s, &trees, 1, &memory).unwrap();
        let u = after.frame_update();
        let object_nodes: usize = trees.trees.iter().map(|t| t.nodes.len()).sum();
        let object_refs: usize = trees.trees.iter().map(|t| t.prim_indices.len()).sum();
        assert_eq!(
            u.top_nodes,
            (after.banks[NODES].len() - object_nodes * NODE_WORDS) * 4
        );
        assert!(u.top_nodes >= NODE_WORDS * 4);
        assert_eq!(u.top_lists, (after.banks[LISTS].len() - object_refs) * 4);
        assert!(
            u.top_lists >= 2 * 4,
            "each instance is listed at least once"
        );
        assert_eq!(u.instance_matrices, 2 * (12 + 9) * 4);
        assert_eq!(u.bytes(), u.top_nodes + u.top_lists + u.instance_matrices);
        let top_root = after.info.top_root.unwrap() as usize;
        let written = |bank: usize, addr: usize| match bank {
            NODES => addr >= top_root * NODE_WORDS,
            LISTS => addr >= after.info.top_lists as usize,
            INSTANCES => addr % INSTANCE_WORDS < 12 + 9,
            _ => false,
        };
        let mut changed = 0;
        for bank in 0..6 {
            let (a, b) = (&before.banks[bank], &after.banks[bank]);
            if !written(bank, a.len().min(b.len())) {
                assert_eq!(a.len(), b.len(), "bank {bank} changed size");
            }
            for (addr, (x, y)) in a.iter().zip(b).enumerate() {
                if x != y {
                    changed += 1;
                    assert!(written(bank, addr), "bank {bank} word {addr} changed");
                }
            }
        }
        assert!(changed > 0, "the moving instance changes its matrix");
        // One untransformed object has no top level and nothing to update.
        let single = Scene::from_toml_str(
            &SCENE[..SCENE.find("[[instances]]").unwrap()],
            Path::new("."),
            "test.toml",
        )
        .unwrap();
        let trees = SceneTrees::build(&single, Format::E7M16).unwrap();
        let l = build(&single, &trees, 0, &memory).unwrap();
        assert_eq!(l.frame_update().bytes(), 0);
    }

    #[test]
    fn layout_decodes_to_the_trees_it_was_built_from() {
        let s = scene();
        let trees = SceneTrees::build(&s, Format::E7M16).unwrap();
        let l = build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
        assert_eq!(l.info.instance_count, 2);
        assert_eq!(l.info.triangle_count, 80);
        assert_eq!(l.banks[TRIANGLES_A].len(), 80 * TRIANGLE_BANK_WORDS);
        assert_eq!(l.banks[TRIANGLES_B].len(), 80 * TRIANGLE_BANK_WORDS);
        // The transform reassembled from both banks is the one the trees were built with.
        assert_eq!(l.triangle_transform(17), trees.transforms[0][17]);
        assert_eq!(l.banks[INSTANCES].len(), 2 * INSTANCE_WORDS);
        let top = l.info.top_root.expect("two instances need a top level");
        // Object tree nodes decode to the builder's nodes; the top-level tree comes after them.
        let root = l.word(INSTANCES, instance_word::ROOT as u32);
        assert!(root < top);
        assert_eq!(
            top as usize,
            trees.trees.iter().map(|t| t.nodes.len()).sum::<usize>()
        );
        for (i, node) in trees.trees[0].nodes.iter().enumerate() {
            match (node, l.node(root + i as u32)) {
                (
                    KdNode::Inner {
                        axis,
                        split,
                        children,
                    },
                    Node::Inner {
                        axis: a,
                        split: s,
                        left,
                    },
                ) => {
                    assert_eq!(
                        (*axis as usize, Format::E7M16.to_f64(s), *children + root),
                        (a, *split, left)
                    );
                }
                (KdNode::Leaf { first, count }, Node::Leaf { list, count: c }) => {
                    assert_eq!(c, *count);
                    let ids: Vec<u32> = (0..c).map(|k| l.word(LISTS, list + k)).collect();
                    assert_eq!(
                        ids,
                        trees.trees[0].prim_indices[*first as usize..(*first + count) as usize]
                    );
                }
                (a, b) => panic!("node {i}: {a:?} decoded as {b:?}"),
            }
        }
        // Frame buffer after the lights, one word per pixel.
        assert_eq!(l.info.materials as usize, FrameMap::LIGHTS + LIGHT_WORDS);
        assert_eq!(
            l.info.frame_buffer as usize,
            FrameMap::LIGHTS + LIGHT_WORDS + MATERIAL_WORDS
        );
        assert_eq!(l.banks[FRAME].len(), l.info.frame_buffer as usize + 48);
    }

    #[test]
    fn a_scene_too_big_for_the_memory_is_refused_with_the_bank_named() {
        let s = scene();
        let trees = SceneTrees::build(&s, Format::E7M16).unwrap();
        let fits = build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
        // The fullest bank; of equally full ones (the two triangle banks), the first, which
        // the size check reports.
        let used = fits.used_words();
        let words = *used.iter().max().unwrap();
        let bank = used.iter().position(|&w| w == words).unwrap();
        let exact = MemoryConfig {
            banks: 6,
            bank_bytes: words * 4,
        };
        assert!(
            build(&s, &trees, 0, &exact).is_ok(),
            "a bank filled exactly still fits"
        );
        let small = MemoryConfig {
            banks: 6,
            bank_bytes: words * 4 - 4,
        };
        let err = build(&s, &trees, 0, &small).unwrap_err().to_string();
        let want = format!("bank {bank} ({}) needs {words} words", BANK_NAMES[bank]);
        assert!(
            err.contains("does not fit") && err.contains(&want) && err.contains("test.toml"),
            "{err}"
        );
        let err = build(&s, &trees, 3, &MemoryConfig::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("frame 3"), "{err}");
    }

    #[test]
    fn the_estimate_from_counts_is_a_lower_bound_of_the_built_map() {
        let s = scene();
        let trees = SceneTrees::build(&s, Format::E7M16).unwrap();
        let built = build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
        let words = built.used_words();
        let (bank, most) = words
            .iter()
            .copied()
            .enumerate()
            .max_by_key(|&(_, w)| w)
            .unwrap();
        // A bank just big enough for the built map passes the estimate (it counts no more than
        // the map holds); one word less than the exactly counted banks fails it.
        let exact = MemoryConfig {
            banks: 6,
            bank_bytes: most * 4,
        };
        check_capacity(&s, &exact).unwrap();
        let frame_words = words[FRAME];
        let small = MemoryConfig {
            banks: 6,
            bank_bytes: (frame_words - 1) * 4,
        };
        let err = check_capacity(&s, &small).unwrap_err().to_string();
        assert!(
            err.contains("needs at least") && err.contains("test.toml"),
            "{err}"
        );
        let _ = bank;
    }

    #[test]
    fn values_the_format_cannot_hold_are_refused_with_what_they_are() {
        let huge = SCENE.replace("scale = [0.5, 0.5, 0.5]", "scale = [1e30, 1e30, 1e30]");
        assert_ne!(huge, SCENE, "the test scene has a scale to change");
        let s = Scene::from_toml_str(&huge, Path::new("."), "test.toml").unwrap();
        let trees = SceneTrees::build(&s, Format::E7M16).unwrap();
        let err = build(&s, &trees, 0, &MemoryConfig::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("instance '")
                && err.contains("e7m16")
                && (err.contains("overflows") || err.contains("underflows")),
            "{err}"
        );
        // e8m23 holds 1e30 and its inverse: the same scene builds.
        let trees = SceneTrees::build(&s, Format::E8M23).unwrap();
        build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
        // A rotation's 1e-17 beside 1 may flush to zero: that is rounding, not an error.
        let f = Format::E7M16;
        assert!(checked_words(f, &s, &|_| "m".into(), &[1.0, 1e-25, 0.5]).is_ok());
        let e = checked_words(f, &s, &|i| format!("value {i}"), &[1e-25, 0.0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("value 0") && e.contains("underflows"), "{e}");
        let e = checked_words(f, &s, &|i| format!("value {i}"), &[1.0, f64::NAN])
            .unwrap_err()
            .to_string();
        assert!(e.contains("value 1") && e.contains("overflows"), "{e}");
    }

    /// Applies a stored 3x4 matrix in f64.
    fn apply(f: Format, w: &[u32], p: DVec3) -> DVec3 {
        let row = |r: usize| {
            let c = |k: usize| f.to_f64(w[r * 4 + k]);
            c(0) * p.x + c(1) * p.y + c(2) * p.z + c(3)
        };
        DVec3::new(row(0), row(1), row(2))
    }

    #[test]
    fn objects_are_stored_around_their_anchor_and_the_hardware_sees_from_the_eye() {
        let f = Format::E7M16;
        // Two instances: hardware coordinates are the world's seen from the eye.
        let s = scene();
        let trees = SceneTrees::build(&s, f).unwrap();
        let l = build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
        let eye = s.camera.eye;
        assert_eq!(l.info.origin, eye.to_array());
        let stored_eye: Vec<f64> = (0..3)
            .map(|k| f.to_f64(l.word(FRAME, (FrameMap::EYE + k) as u32)))
            .collect();
        assert_eq!(stored_eye, [0.0; 3]);
        let light = (0..3).map(|k| f.to_f64(l.word(FRAME, (FrameMap::LIGHTS + k) as u32)));
        let want = s.lights[0].position - eye;
        for (got, want) in light.zip(want.to_array()) {
            assert_eq!(got, f.to_f64(f.from_f64(want)));
        }
        // A vertex of instance 1 (translated by (-0.5, 1, 0), scaled by 0.5), seen from the
        // eye, maps to the anchored object coordinates the triangle transforms were built on.
        let anchor = trees.anchors[0];
        let v = s.objects[0].triangles[5][1];
        let world = v * 0.5 + DVec3::new(-0.5, 1.0, 0.0);
        let m = &l.banks[INSTANCES][INSTANCE_WORDS..INSTANCE_WORDS + 12];
        let got = apply(f, m, world - eye);
        assert!(
            (got - (v - anchor)).length() < 1e-3,
            "{got} vs {}",
            v - anchor
        );

        // One untransformed object far from its file's origin: stored around its centre, the
        // eye and the lights moved by the same offset.
        // Without [[instances]] the one object is placed once, untransformed.
        let single = SCENE.split("[[instances]]").next().unwrap();
        let s = Scene::from_toml_str(single, Path::new("."), "single.toml").unwrap();
        assert!(s.is_single_untransformed_object());
        let mut moved = s.clone();
        let offset = DVec3::new(1000.0, -2000.0, 500.0);
        for t in &mut moved.objects[0].triangles {
            *t = t.map(|v| v + offset);
        }
        moved.camera.eye += offset;
        moved.camera.look_at += offset;
        moved.lights[0].position += offset;
        let near_trees = SceneTrees::build(&s, f).unwrap();
        assert_eq!(
            near_trees.anchors[0],
            DVec3::ZERO,
            "centred on its origin already"
        );
        let near = build(&s, &near_trees, 0, &MemoryConfig::default()).unwrap();
        let far_trees = SceneTrees::build(&moved, f).unwrap();
        let far = build(&moved, &far_trees, 0, &MemoryConfig::default()).unwrap();
        assert!((far_trees.anchors[0] - offset).length() < 1e-9);
        // Moving the whole scene changes no stored word beyond last-bit rounding of the
        // anchor's own f64 arithmetic: the hardware computes the same picture.
        let differing = (0..6)
            .map(|b| {
                near.banks[b]
                    .iter()
                    .zip(&far.banks[b])
                    .filter(|(a, b)| a.abs_diff(**b) > 1)
                    .count()
            })
            .sum::<usize>();
        assert_eq!(differing, 0);
    }

    #[test]
    fn instance_boxes_are_rounded_outward_to_the_format() {
        let f = Format::parse("e5m10").unwrap();
        let b = Aabb::new(DVec3::splat(0.1), DVec3::splat(0.3));
        let r = instance_box(f, &b, &DAffine3::IDENTITY);
        for v in [r.min, r.max] {
            for c in v.to_array() {
                assert_eq!(f.to_f64(f.from_f64(c)), c, "{c} must be representable");
            }
        }
        assert!(r.min.max_element() < 0.1 && r.max.min_element() > 0.3);
        assert_eq!(
            f.round_down(0.1),
            f.to_f64(f.from_f64(0.1)).min(f.round_down(0.1))
        );
        assert!(
            f.round_down(0.1) <= 0.1
                && f.round_up(0.1) >= 0.1
                && f.round_up(0.1) > f.round_down(0.1)
        );
    }
}
