//! The per-frame top-level kd-tree over instance world bounds (DynRT's two-level scheme: object
//! trees are static, only this tree is rebuilt when instances move).
//!
//! Contract: `TopLevel::build(bounds)` indexes instance `i` by `bounds[i]` (a world-space box,
//! e.g. the object's bounds transformed by the instance matrix, [`Aabb::transformed`]).
//! Traversal reports every instance whose box the ray segment touches, front to back, through
//! the same [`KdTree`] traversal as object trees; a two-level closest hit passes a test closure
//! that transforms the ray into the instance's object space and traverses its object tree.

use super::aabb::Aabb;
use super::kd_traversal::KdHit;
use super::kd_tree::{build_sah_boxes, KdParams, KdTree};
use super::ray::Ray;

/// Top-level kd-tree over instances.
#[derive(Clone, Debug)]
pub struct TopLevel {
    pub tree: KdTree,
    /// World bounds of each instance, as given to `build`.
    pub instance_bounds: Vec<Aabb>,
}

impl TopLevel {
    /// Builds with [`KdParams::default`].
    pub fn build(instance_bounds: &[Aabb]) -> Self {
        Self::build_with(instance_bounds, &KdParams::default())
    }

    pub fn build_with(instance_bounds: &[Aabb], params: &KdParams) -> Self {
        Self {
            tree: build_sah_boxes(instance_bounds, params),
            instance_bounds: instance_bounds.to_vec(),
        }
    }

    /// Ids of all instances whose box the segment `[t_min, t_max]` touches (sorted, unique).
    pub fn instances_along(&self, ray: &Ray, t_min: f64, t_max: f64) -> Vec<u32> {
        let mut out = Vec::new();
        self.tree.traverse_leaves(ray, t_min, t_max, |prims, _, _| {
            for &p in prims {
                if ray
                    .intersect_aabb(&self.instance_bounds[p as usize], t_min, t_max)
                    .is_some()
                {
                    out.push(p);
                }
            }
            t_max
        });
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Two-level closest hit: `test(instance, t_best)` intersects the instance (in its object
    /// space) and reports a hit in `[t_min, t_best)` with a payload (e.g. the triangle id).
    pub fn closest_hit_with<H>(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        test: impl FnMut(u32, f64) -> Option<(f64, H)>,
    ) -> Option<KdHit<H>> {
        self.tree.closest_hit_with(ray, t_min, t_max, test)
    }

    /// Two-level any hit (shadow rays).
    pub fn any_hit(
        &self,
        ray: &Ray,
        t_min: f64,
        t_max: f64,
        test: impl FnMut(u32, f64) -> Option<f64>,
    ) -> Option<u32> {
        self.tree.any_hit(ray, t_min, t_max, test)
    }
}
