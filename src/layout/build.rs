//! Building the memory map of one frame.

use super::*;
use crate::accel::kd_tree::{self, KdNode, KdParams, KdTree};
use crate::accel::Aabb;
use crate::scene::Scene;
use glam::{DAffine3, DMat3, DVec3};

#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    #[error(
        "scene `{scene}` does not fit the memory: bank {bank} ({name}) needs {needed} words \
         ({needed_mb:.1} MB) but holds {capacity} ({capacity_mb:.1} MB); use a smaller scene \
         or a lower resolution, or configure larger banks",
        needed_mb = *needed as f64 * 4.0 / 1048576.0,
        capacity_mb = *capacity as f64 * 4.0 / 1048576.0
    )]
    TooBig { scene: String, bank: usize, name: &'static str, needed: usize, capacity: usize },
    #[error("scene `{scene}`: {what} does not fit the 30-bit address field of a kd node")]
    AddressOverflow { scene: String, what: String },
    #[error("scene `{scene}` has frame {frame} but only {frames} frames (0..{frames})")]
    NoSuchFrame { scene: String, frame: u32, frames: u32 },
    #[error("scene `{scene}`: object `{object}` has no triangle that survives rounding to {format}")]
    EmptyAfterRounding { scene: String, object: String, format: Format },
}

/// The per-object kd-trees of a scene for one number format, built once and reused by every
/// frame (only the top-level tree follows the instances).
///
/// Object vertices are first rounded to the format: every kd split then sits on a vertex
/// coordinate, which the format represents exactly, so the hardware's split planes are the
/// builder's planes and no triangle falls between them.
#[derive(Clone, Debug)]
pub struct SceneTrees {
    pub format: Format,
    /// Vertices rounded to the format, per object, same order as the scene's triangles.
    pub triangles: Vec<Vec<[DVec3; 3]>>,
    pub trees: Vec<KdTree>,
    /// Triangles that became degenerate when rounded (never referenced by a leaf).
    pub dropped: Vec<Vec<u32>>,
}

impl SceneTrees {
    pub fn build(scene: &Scene, format: Format) -> Result<SceneTrees, LayoutError> {
        let params = KdParams::default();
        let mut all = Vec::new();
        for object in &scene.objects {
            let rounded: Vec<[DVec3; 3]> =
                object.triangles.iter().map(|t| t.map(|v| round_vec(format, v))).collect();
            let (kept, dropped): (Vec<u32>, Vec<u32>) =
                (0..rounded.len() as u32).partition(|&i| !is_flat(&rounded[i as usize]));
            if kept.is_empty() {
                return Err(LayoutError::EmptyAfterRounding {
                    scene: scene.source.display().to_string(),
                    object: object.name.clone(),
                    format,
                });
            }
            let kept_tris: Vec<[DVec3; 3]> = kept.iter().map(|&i| rounded[i as usize]).collect();
            let mut tree = kd_tree::build_sah(&kept_tris, &params);
            for p in tree.prim_indices.iter_mut() {
                *p = kept[*p as usize];
            }
            all.push((rounded, tree, dropped));
        }
        let mut out = SceneTrees { format, triangles: vec![], trees: vec![], dropped: vec![] };
        for (t, tree, d) in all {
            out.triangles.push(t);
            out.trees.push(tree);
            out.dropped.push(d);
        }
        Ok(out)
    }
}

fn round_vec(f: Format, v: DVec3) -> DVec3 {
    DVec3::new(f.to_f64(f.from_f64(v.x)), f.to_f64(f.from_f64(v.y)), f.to_f64(f.from_f64(v.z)))
}

fn is_flat(t: &[DVec3; 3]) -> bool {
    (t[0] - t[2]).cross(t[1] - t[2]).length_squared() == 0.0
}

/// The largest format value <= x (x finite).
fn round_down(f: Format, x: f64) -> f64 {
    let w = f.from_f64(x);
    let v = f.to_f64(w);
    if v <= x {
        v
    } else {
        step(f, w, false)
    }
}

/// The smallest format value >= x (x finite).
fn round_up(f: Format, x: f64) -> f64 {
    let w = f.from_f64(x);
    let v = f.to_f64(w);
    if v >= x {
        v
    } else {
        step(f, w, true)
    }
}

/// The neighbour of word `w` towards +inf (`up`) or -inf.
fn step(f: Format, w: u32, up: bool) -> f64 {
    if f.is_zero(w) {
        let m = f.to_f64(f.min_normal(false));
        return if up { m } else { -m };
    }
    let away = up != f.sign_of(w); // moving away from zero grows the magnitude
    let n = if away { w + 1 } else { w - 1 };
    f.to_f64(if f.is_zero(n) { f.zero(false) } else { n })
}

/// An instance's world bounds rounded outward to format values, plus a margin of a few ulps
/// so that rays transformed with rounding still find the instance where they hit it.
fn instance_box(f: Format, local: &Aabb, to_world: &DAffine3) -> Aabb {
    let b = local.transformed(to_world);
    let margin = (b.max - b.min).max_element().max(b.max.abs().max_element()) * 2f64.powi(-(f.man_bits as i32) + 3);
    let lo = b.min - DVec3::splat(margin);
    let hi = b.max + DVec3::splat(margin);
    Aabb::new(
        DVec3::new(round_down(f, lo.x), round_down(f, lo.y), round_down(f, lo.z)),
        DVec3::new(round_up(f, hi.x), round_up(f, hi.y), round_up(f, hi.z)),
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
) {
    for node in &tree.nodes {
        match *node {
            KdNode::Inner { axis, split, children } => {
                let w = f.from_f64(split);
                debug_assert_eq!(f.to_f64(w), split, "split planes sit on representable values");
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
}

/// Builds the memory map of `frame`.
pub fn build(scene: &Scene, trees: &SceneTrees, frame: u32, memory: &MemoryConfig) -> Result<Layout, LayoutError> {
    let f = trees.format;
    let scene_name = scene.source.display().to_string();
    if frame >= scene.frames {
        return Err(LayoutError::NoSuchFrame { scene: scene_name, frame, frames: scene.frames });
    }
    let mut banks: Vec<Vec<u32>> = vec![Vec::new(); 6];

    // Triangles and shading data, global triangle index = object base + local index.
    let mut first_triangle = Vec::new();
    let mut first_material = Vec::new();
    let (mut tri_count, mut mat_count) = (0u32, 0u32);
    for (o, object) in scene.objects.iter().enumerate() {
        first_triangle.push(tri_count);
        first_material.push(mat_count);
        for (i, t) in trees.triangles[o].iter().enumerate() {
            let (transform, normal) = if is_flat(t) {
                // Never referenced by a leaf; zero words keep the addressing regular.
                (DAffine3::ZERO, DVec3::ZERO)
            } else {
                (unit_triangle_transform(t), (t[0] - t[2]).cross(t[1] - t[2]).normalize())
            };
            banks[TRIANGLES].extend(affine_words(f, &transform));
            banks[SHADING].extend([f.from_f64(normal.x), f.from_f64(normal.y), f.from_f64(normal.z)]);
            banks[SHADING].push(mat_count + object.triangle_material[i]);
        }
        tri_count += object.triangles.len() as u32;
        mat_count += object.materials.len() as u32;
    }
    for object in &scene.objects {
        for m in &object.materials {
            banks[SHADING].extend([f.from_f64(m.diffuse[0]), f.from_f64(m.diffuse[1]), f.from_f64(m.diffuse[2])]);
            banks[SHADING].push(f.from_f64(m.mirror));
        }
    }

    // Top-level tree over the instances' world bounds (absent for one untransformed object).
    let to_world: Vec<DAffine3> = scene.instances.iter().map(|i| i.object_to_world(frame)).collect();
    let top = if scene.is_single_untransformed_object() {
        None
    } else {
        let boxes: Vec<Aabb> = scene
            .instances
            .iter()
            .zip(&to_world)
            .map(|(inst, m)| instance_box(f, &trees.trees[inst.object].bounds, m))
            .collect();
        Some(kd_tree::build_sah_boxes(&boxes, &KdParams::default()))
    };

    let mut node_base = 0u32;
    let mut top_root = None;
    if let Some(top) = &top {
        top_root = Some(0);
        pack_tree(f, top, 0, 0, |p| p, &mut banks[NODES], &mut banks[LISTS]);
        node_base = top.nodes.len() as u32;
    }
    let mut object_roots = Vec::new();
    for (o, tree) in trees.trees.iter().enumerate() {
        object_roots.push(node_base);
        let list_base = banks[LISTS].len() as u32;
        let base = first_triangle[o];
        let mut nodes = std::mem::take(&mut banks[NODES]);
        pack_tree(f, tree, node_base, list_base, |p| base + p, &mut nodes, &mut banks[LISTS]);
        banks[NODES] = nodes;
        node_base += tree.nodes.len() as u32;
    }
    if node_base as usize >= 1 << 30 || banks[LISTS].len() >= 1 << 30 {
        return Err(LayoutError::AddressOverflow { scene: scene_name, what: "the kd-tree".into() });
    }

    // Instances.
    for (inst, m) in scene.instances.iter().zip(&to_world) {
        banks[INSTANCES].extend(affine_words(f, &m.inverse()));
        let normal = m.matrix3.inverse().transpose();
        for r in 0..3 {
            let row = normal.row(r);
            banks[INSTANCES].extend([f.from_f64(row.x), f.from_f64(row.y), f.from_f64(row.z)]);
        }
        banks[INSTANCES].extend([object_roots[inst.object], first_triangle[inst.object], inst.object as u32]);
    }

    // Frame constants, lights, frame buffer.
    let cam = &scene.camera;
    let (w, h) = (cam.width as f64, cam.height as f64);
    let basis = cam.basis();
    let half_h = (cam.fov_y_deg.to_radians() / 2.0).tan();
    let aspect = w / h;
    let c0 = basis.right * (2.0 * half_h * aspect / w);
    let c1 = basis.up * (-2.0 * half_h / h);
    let c2 = basis.forward + basis.right * ((1.0 / w - 1.0) * half_h * aspect) + basis.up * ((1.0 - 1.0 / h) * half_h);
    let camera = DAffine3::from_mat3_translation(DMat3::from_cols(c0, c1, DVec3::ZERO), c2);
    let fr = &mut banks[FRAME];
    fr.extend(affine_words(f, &camera));
    fr.extend([f.from_f64(cam.eye.x), f.from_f64(cam.eye.y), f.from_f64(cam.eye.z)]);
    fr.push(f.from_f64(scene.render.ambient));
    fr.extend(scene.render.background.map(|c| f.from_f64(c)));
    let (shadow_eps, mirror_eps) = secondary_t_min(f, scene);
    fr.extend([f.from_f64(shadow_eps), f.from_f64(mirror_eps)]);
    fr.extend([0, f.one(), f.from_int(2)]);
    debug_assert_eq!(fr.len(), FrameMap::LIGHTS);
    for light in &scene.lights {
        fr.extend([light.position.x, light.position.y, light.position.z].map(|c| f.from_f64(c)));
        fr.extend(light.color.map(|c| f.from_f64(c)));
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
        object_root: object_roots[0],
        instance_count: scene.instances.len() as u32,
        triangle_count: tri_count,
        frame_buffer,
        object_depth: trees.trees.iter().map(|t| t.depth).max().unwrap_or(0),
        top_depth: top.as_ref().map_or(0, |t| t.depth),
        object_first_triangle: first_triangle,
    };
    Ok(Layout { format: f, memory: *memory, banks, info })
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
