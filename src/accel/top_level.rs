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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bench::random_instance_boxes;
    use crate::accel::kd_tree::{build_sah, KdNode};
    use crate::accel::primitive::Boxes;
    use crate::accel::test_meshes::{soup, sphere};
    use crate::accel::triangle;
    use glam::{DAffine3, DQuat, DVec3, EulerRot};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn finds_every_box_a_ray_crosses() {
        let seed = 21;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Random boxes, plus integer-aligned boxes sharing faces, plus flat ones.
        let mut boxes = random_instance_boxes(1500, seed);
        for i in 0..300 {
            let c = DVec3::new(
                rng.gen_range(-20..20) as f64,
                rng.gen_range(-20..20) as f64,
                rng.gen_range(-20..20) as f64,
            );
            let e = if i % 3 == 0 {
                DVec3::new(2.0, 0.0, 1.0)
            } else {
                DVec3::new(1.0, 2.0, 1.0)
            };
            boxes.push(Aabb::new(c, c + e));
        }
        let top = TopLevel::build(&boxes);
        top.tree.validate_against(&Boxes(&boxes)).unwrap();
        let planes: Vec<(usize, f64)> = top
            .tree
            .nodes
            .iter()
            .filter_map(|n| match *n {
                KdNode::Inner { axis, split, .. } => Some((axis as usize, split)),
                _ => None,
            })
            .collect();
        let axes = [
            DVec3::X,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Z,
        ];
        let mut crossings = 0;
        for i in 0..3000 {
            let mut o = DVec3::new(
                rng.gen_range(-150.0..150.0),
                rng.gen_range(-150.0..150.0),
                rng.gen_range(-150.0..150.0),
            );
            if i % 4 == 1 {
                o = o.round() * 0.2; // integer-box faces
            }
            let mut d = DVec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            match i % 5 {
                0 => d = axes[rng.gen_range(0..6)],
                1 => {
                    let (a, s) = planes[rng.gen_range(0..planes.len())];
                    o[a] = s;
                    if rng.gen() {
                        d[a] = 0.0;
                    }
                }
                2 | 3 => d = boxes[rng.gen_range(0..boxes.len())].center() - o,
                _ => {}
            }
            let ray = Ray::new(o, d);
            let (t_min, t_max) = if i % 7 == 0 {
                (10.0, 60.0)
            } else {
                (0.0, f64::INFINITY)
            };
            let got = top.instances_along(&ray, t_min, t_max);
            let want: Vec<u32> = (0..boxes.len() as u32)
                .filter(|&b| {
                    ray.intersect_aabb(&boxes[b as usize], t_min, t_max)
                        .is_some()
                })
                .collect();
            crossings += want.len();
            assert_eq!(got, want, "ray {i} {ray:?} [{t_min}, {t_max}]");
        }
        println!("{crossings} box crossings checked");
        assert!(crossings > 2000);
    }

    /// Two-level closest hit (world ray -> instance -> object tree) against brute force over
    /// all instances' triangles transformed to world space.
    #[test]
    fn two_level_closest_hit_matches_brute_force() {
        let seed = 22;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let objects = [sphere(2), soup(300, 23)];
        let params = KdParams::default();
        let trees: Vec<KdTree> = objects.iter().map(|o| build_sah(o, &params)).collect();
        let instances: Vec<(usize, DAffine3)> = (0..40)
            .map(|i| {
                let m = DAffine3::from_scale_rotation_translation(
                    DVec3::new(
                        rng.gen_range(0.5..2.0),
                        rng.gen_range(0.5..2.0),
                        rng.gen_range(0.5..2.0),
                    ),
                    DQuat::from_euler(EulerRot::XYZ, rng.gen(), rng.gen(), rng.gen()),
                    DVec3::new(
                        rng.gen_range(-10.0..10.0),
                        rng.gen_range(-10.0..10.0),
                        rng.gen_range(-10.0..10.0),
                    ),
                );
                (i % 2, m)
            })
            .collect();
        let bounds: Vec<Aabb> = instances
            .iter()
            .map(|&(o, m)| trees[o].bounds.transformed(&m))
            .collect();
        let top = TopLevel::build(&bounds);
        let inverses: Vec<DAffine3> = instances.iter().map(|(_, m)| m.inverse()).collect();
        let world: Vec<(u32, u32, [DVec3; 3])> = instances
            .iter()
            .enumerate()
            .flat_map(|(i, &(o, m))| {
                objects[o]
                    .iter()
                    .enumerate()
                    .map(move |(t, tri)| (i as u32, t as u32, tri.map(|v| m.transform_point3(v))))
            })
            .collect();
        let mut hits = 0;
        for i in 0..1500 {
            let o = DVec3::new(
                rng.gen_range(-15.0..15.0),
                rng.gen_range(-15.0..15.0),
                rng.gen_range(-15.0..15.0),
            );
            let target = DVec3::new(
                rng.gen_range(-10.0..10.0),
                rng.gen_range(-10.0..10.0),
                rng.gen_range(-10.0..10.0),
            );
            let ray = Ray::new(o, target - o);
            let got = top.closest_hit_with(&ray, 0.0, f64::INFINITY, |inst, t_best| {
                let (obj, _) = instances[inst as usize];
                let inv = &inverses[inst as usize];
                // An affine map keeps the ray parameter t.
                let local = Ray::new(
                    inv.transform_point3(ray.origin),
                    inv.transform_vector3(ray.dir),
                );
                trees[obj]
                    .closest_hit(&local, 0.0, t_best, |p, tb| {
                        triangle::intersect(&local, &objects[obj][p as usize], 0.0, tb).map(|h| h.0)
                    })
                    .map(|(tri, t)| (t, tri))
            });
            let mut want: Option<(u32, u32, f64)> = None;
            for (inst, tri, w) in &world {
                if let Some((t, _, _)) = triangle::intersect(&ray, w, 0.0, f64::INFINITY) {
                    if want.is_none_or(|(_, _, bt)| t < bt) {
                        want = Some((*inst, *tri, t));
                    }
                }
            }
            match (got, want) {
                (None, None) => {}
                (Some(g), Some((wi, wt, t))) => {
                    hits += 1;
                    assert!(
                        (g.prim, g.payload) == (wi, wt) || (g.t - t).abs() <= 1e-7 * t,
                        "ray {i}: two-level {g:?}, brute force instance {wi} tri {wt} t {t}"
                    );
                }
                (g, w) => panic!("ray {i} {ray:?}: two-level {g:?}, brute force {w:?}"),
            }
        }
        println!("{hits} of 1500 rays hit");
        assert!(hits > 300);
    }
}
