//! Acceleration structures: per-object SAH kd-trees over triangles and the per-frame top-level
//! kd-tree over instance world bounds (the two-level scheme of SaarCOR DynRT), in f64.
//!
//! - [`aabb::Aabb`], [`ray::Ray`] (slab test), [`triangle::intersect`] (Möller–Trumbore, f64);
//! - [`kd_tree`]: the node representation the layout stage packs into memory (invariants in its
//!   module doc, checked by [`KdTree::validate`]), [`KdParams`], [`KdStats`], and the entry
//!   points [`build_sah`] / [`build_sah_boxes`];
//! - [`sah_builder`]: Wald & Havran's O(N log N) SAH builder with perfect splits, generic over
//!   [`primitive::KdPrimitives`];
//! - [`box_builder`]: the same builder's tree over boxes (the top level, rebuilt every frame),
//!   with a layout for boxes and faster;
//! - [`kd_traversal`]: front-to-back closest-hit and any-hit traversal (the reference renderer's);
//! - [`top_level::TopLevel`]: the per-frame tree over instances;
//! - [`mod@bench`]: build-rate benchmark (called by `benches/accel.rs`).
//!
//! Input is plain geometry (`&[[DVec3; 3]]`, `&[Aabb]`), independent of the scene module.
//! A layout in a reduced number format should build with
//! `KdParams { split_format: Some(format), ..Default::default() }` so that every split plane
//! is a value of that format (perfect splits otherwise create planes at clipped coordinates).

pub mod aabb;
pub mod bench;
pub mod box_builder;
pub mod kd_traversal;
pub mod kd_tree;
pub mod primitive;
pub mod ray;
pub mod sah_builder;
pub mod top_level;
pub mod triangle;

#[cfg(test)]
pub(crate) mod test_meshes;

pub use aabb::Aabb;
pub use kd_traversal::{KdHit, TriangleHit};
pub use kd_tree::{build_sah, build_sah_boxes, KdNode, KdParams, KdStats, KdTree, KdTreeError};
pub use ray::Ray;
pub use top_level::TopLevel;
