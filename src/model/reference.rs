//! The f64 reference renderer: the accuracy yardstick every golden frame is measured against.
//!
//! Deliberately plain: the scene's original f64 geometry (no rounding of vertices), exact
//! instance bounds, f64 kd-trees from `accel`, Möller-Trumbore intersection, and the shading
//! formulas of the golden model written in f64. Secondary rays skip their own triangle and
//! start at t = 1e-6 (relative to the light distance or the scene size): far above
//! f64's rounding of the hit point, far below any feature of a scene.

use super::{Frame, HitRecord};
use crate::accel::kd_traversal::TraversalCounts;
use crate::accel::kd_tree::{self, KdParams, KdTree};
use crate::accel::{triangle, Aabb, Ray};
use crate::scene::Scene;
use glam::{DAffine3, DMat3, DVec3};
use rayon::prelude::*;

/// Object trees built once per scene.
pub struct Reference<'a> {
    scene: &'a Scene,
    params: KdParams,
    trees: Vec<KdTree>,
}

/// One frame's instance placement.
struct FrameGeometry {
    to_object: Vec<DAffine3>,
    normal: Vec<DMat3>,
    top: KdTree,
    t_eps: f64,
}

#[derive(Clone, Copy)]
struct RefHit {
    t: f64,
    instance: u32,
    triangle: u32,
}

impl<'a> Reference<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        Self::with_params(scene, KdParams::default())
    }

    /// The reference with object and top-level trees built with `params` (for measuring tree
    /// parameters; [`Reference::new`] is the yardstick).
    pub fn with_params(scene: &'a Scene, params: KdParams) -> Self {
        let trees = scene
            .objects
            .iter()
            .map(|o| kd_tree::build_sah(&o.triangles, &params))
            .collect();
        Reference {
            scene,
            params,
            trees,
        }
    }

    /// The object trees, in the scene's object order.
    pub fn trees(&self) -> &[KdTree] {
        &self.trees
    }

    /// Renders one frame at the scene camera's resolution.
    pub fn render(&self, frame: u32) -> Frame {
        self.render_with_progress(frame, false)
    }

    /// Traversal work of the frame's primary rays (closest hit, one per pixel): kd nodes
    /// visited in the top-level and object trees together, and triangle tests.
    pub fn primary_counts(&self, frame: u32) -> TraversalCounts {
        let s = self.scene;
        let geo = self.frame_geometry(frame);
        let (w, h) = (s.camera.width, s.camera.height);
        (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (o, d) = s.camera.primary_ray(i % w, i / w);
                let mut c = TraversalCounts::default();
                self.trace(&geo, o, d, 0.0, f64::INFINITY, None, false, &mut c);
                c
            })
            .reduce(TraversalCounts::default, |mut a, b| {
                a.add(&b);
                a
            })
    }

    /// [`Reference::render`] with a progress bar (rows) when `progress`.
    pub fn render_with_progress(&self, frame: u32, progress: bool) -> Frame {
        let s = self.scene;
        let geo = self.frame_geometry(frame);
        let (w, h) = (s.camera.width, s.camera.height);
        let bar = super::progress_bar(progress, h, "reference");
        let pixels: Vec<(u32, Option<HitRecord>)> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if x + 1 == w {
                    bar.inc(1);
                }
                let (o, d) = s.camera.primary_ray(x, y);
                let (c, hit) = self.shade(&geo, o, d, 0.0, None, 0);
                let rec = hit.map(|hh| HitRecord {
                    instance: hh.instance,
                    triangle: hh.triangle,
                    dist: hh.t * d.length(),
                });
                (pack(c), rec)
            })
            .collect();
        bar.finish_and_clear();
        Frame::from_pixels(w, h, pixels)
    }

    fn frame_geometry(&self, frame: u32) -> FrameGeometry {
        let s = self.scene;
        let to_world: Vec<DAffine3> = s
            .instances
            .iter()
            .map(|i| i.object_to_world(frame))
            .collect();
        let boxes: Vec<Aabb> = s
            .instances
            .iter()
            .zip(&to_world)
            .map(|(i, m)| self.trees[i.object].bounds.transformed(m))
            .collect();
        let mut extent = Aabb::from_points(std::iter::once(&s.camera.eye));
        for b in &boxes {
            extent = extent.union(b);
        }
        FrameGeometry {
            to_object: to_world.iter().map(|m| m.inverse()).collect(),
            normal: to_world
                .iter()
                .map(|m| m.matrix3.inverse().transpose())
                .collect(),
            top: kd_tree::build_sah_boxes(&boxes, &self.params),
            t_eps: 1e-6 * (extent.max - extent.min).max_element().max(1.0),
        }
    }

    fn shade(
        &self,
        g: &FrameGeometry,
        o: DVec3,
        d: DVec3,
        t_min: f64,
        skip: Option<(u32, u32)>,
        depth: u32,
    ) -> (DVec3, Option<RefHit>) {
        let s = self.scene;
        let counts = &mut TraversalCounts::default();
        let Some(hit) = self.trace(g, o, d, t_min, f64::INFINITY, skip, false, counts) else {
            return (DVec3::from_array(s.render.background), None);
        };
        let object = &s.objects[s.instances[hit.instance as usize].object];
        let tri = &object.triangles[hit.triangle as usize];
        let material = object.material_of(hit.triangle as usize);
        let p = o + d * hit.t;
        let n_obj = (tri[0] - tri[2]).cross(tri[1] - tri[2]).normalize();
        let mut n = (g.normal[hit.instance as usize] * n_obj).normalize();
        if n.dot(d) > 0.0 {
            n = -n;
        }
        let kd = DVec3::from_array(material.diffuse);
        let mut acc = kd * s.render.ambient;
        let me = Some((hit.instance, hit.triangle));
        for light in &s.lights {
            let to_light = light.position - p;
            let n_dot_l = n.dot(to_light);
            if n_dot_l <= 0.0 {
                continue;
            }
            if s.render.shadows
                && self
                    .trace(g, p, to_light, 1e-6, 1.0, me, true, counts)
                    .is_some()
            {
                continue;
            }
            acc += kd * DVec3::from_array(light.color) * (n_dot_l / to_light.length());
        }
        if depth < s.render.reflection_depth && material.mirror > 0.0 {
            let r = d - n * (2.0 * d.dot(n));
            let (reflected, _) = self.shade(g, p, r, g.t_eps, me, depth + 1);
            acc = acc * (1.0 - material.mirror) + reflected * material.mirror;
        }
        (acc, Some(hit))
    }

    /// Closest (or, with `any`, any) hit along `o + t d`, `t` in `[t_min, t_max)`; adds one
    /// ray, the nodes visited in the top-level and object trees and the triangle tests to
    /// `counts`.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        g: &FrameGeometry,
        o: DVec3,
        d: DVec3,
        t_min: f64,
        t_max: f64,
        skip: Option<(u32, u32)>,
        any: bool,
        counts: &mut TraversalCounts,
    ) -> Option<RefHit> {
        let s = self.scene;
        let world = Ray::new(o, d);
        let (mut top, mut objects) = (TraversalCounts::default(), TraversalCounts::default());
        let hit = g
            .top
            .closest_hit_counted(&world, t_min, t_max, &mut top, |instance, t_best| {
                let inst = &s.instances[instance as usize];
                let m = &g.to_object[instance as usize];
                let local = Ray::new(m.transform_point3(o), m.transform_vector3(d));
                let tris = &s.objects[inst.object].triangles;
                let test = |tri: u32, tb: f64| {
                    if skip == Some((instance, tri)) {
                        return None;
                    }
                    triangle::intersect(&local, &tris[tri as usize], t_min, tb).map(|(t, _, _)| t)
                };
                let tree = &self.trees[inst.object];
                if any {
                    tree.any_hit_counted(&local, t_min, t_best, &mut objects, test)
                        .map(|tri| (t_min, tri))
                } else {
                    tree.closest_hit_counted(&local, t_min, t_best, &mut objects, |p, tb| {
                        test(p, tb).map(|t| (t, ()))
                    })
                    .map(|h| (h.t, h.prim))
                }
            })
            .map(|h| RefHit {
                t: h.t,
                instance: h.prim,
                triangle: h.payload,
            });
        counts.rays += 1;
        counts.nodes += top.nodes + objects.nodes;
        counts.tests += objects.tests;
        hit
    }
}

/// `0x00RRGGBB` from an f64 colour: clamp to [0, 1], scale by 255, round to nearest even.
pub fn pack(c: DVec3) -> u32 {
    let q = |x: f64| {
        let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        (x * 255.0).round_ties_even() as u32
    };
    (q(c.x) << 16) | (q(c.y) << 8) | q(c.z)
}
