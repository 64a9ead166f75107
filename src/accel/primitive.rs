//! What the SAH kd-tree builder needs to know about its primitives: their bounds, and the
//! bounds of the part of a primitive inside a box (for split clipping, "perfect splits").
//!
//! Two implementations: [`Triangles`] (object trees; the triangle is clipped to the box with
//! Sutherland–Hodgman) and [`Boxes`] (the top-level tree over instance world bounds; the box
//! is intersected with the voxel).
//!
//! Contract of `clipped_bounds(i, voxel)`: `None` only if the primitive does not touch the
//! closed voxel; otherwise a box inside `voxel` that contains every point of the primitive
//! inside `voxel`. Rounding may only make it larger, never smaller: clipping works against
//! the voxel grown by a tiny relative margin and the result is then cut back to the voxel.
//! This conservatism is what keeps kd traversal exact: every primitive is listed in every leaf
//! its surface touches.

use super::aabb::Aabb;
use glam::DVec3;

/// Primitive set seen by the SAH builder.
pub trait KdPrimitives {
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Bounds of primitive `i`.
    fn bounds(&self, i: usize) -> Aabb;
    /// Bounds of the part of primitive `i` inside `voxel` (see the module contract).
    fn clipped_bounds(&self, i: usize, voxel: &Aabb) -> Option<Aabb>;
    /// Whether clipping a primitive to one side of a plane changes its bounds along the
    /// plane's axis only (so the builder keeps its events on the other axes). True of boxes:
    /// a box cut to a child voxel is the box cut to the parent voxel, cut by the plane.
    const CLIPPING_KEEPS_OTHER_AXES: bool = false;
}

/// Triangles given by their three vertices.
pub struct Triangles<'a>(pub &'a [[DVec3; 3]]);

/// Boxes (instance world bounds).
pub struct Boxes<'a>(pub &'a [Aabb]);

impl KdPrimitives for Triangles<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }
    /// NaN bounds for a triangle with a non-finite vertex (`f64::min` would skip a NaN).
    fn bounds(&self, i: usize) -> Aabb {
        let tri = &self.0[i];
        if tri.iter().all(|v| v.is_finite()) {
            Aabb::from_triangle(tri)
        } else {
            Aabb::new(DVec3::NAN, DVec3::NAN)
        }
    }
    fn clipped_bounds(&self, i: usize, voxel: &Aabb) -> Option<Aabb> {
        clip_triangle_bounds(&self.0[i], voxel)
    }
}

impl KdPrimitives for Boxes<'_> {
    const CLIPPING_KEEPS_OTHER_AXES: bool = true;
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: usize) -> Aabb {
        self.0[i]
    }
    fn clipped_bounds(&self, i: usize, voxel: &Aabb) -> Option<Aabb> {
        let b = self.0[i].intersection(voxel);
        (!b.is_empty()).then_some(b)
    }
}

/// Largest polygon a triangle clipped by 6 planes can become (3 + 6 vertices).
const MAX_POLY: usize = 9;

struct Polygon {
    v: [DVec3; MAX_POLY + 1],
    n: usize,
}

impl Polygon {
    /// Writes into `out` the part with `sign * (p[axis] - pos) >= 0`.
    fn clip_into(&self, axis: usize, pos: f64, sign: f64, out: &mut Polygon) {
        out.n = 0;
        for i in 0..self.n {
            let a = self.v[i];
            let b = self.v[if i + 1 == self.n { 0 } else { i + 1 }];
            let da = sign * (a[axis] - pos);
            let db = sign * (b[axis] - pos);
            if da >= 0.0 {
                out.v[out.n] = a;
                out.n += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                let t = da / (da - db);
                let mut p = a + (b - a) * t;
                // The new vertex lies on the plane by construction; say so exactly.
                p[axis] = pos;
                out.v[out.n] = p;
                out.n += 1;
            }
        }
    }
}

/// A polygon cut plane by plane, in two buffers that take turns (a new polygon per plane cost
/// more than the clipping).
struct Clipper {
    buffers: [Polygon; 2],
    /// The buffer holding the polygon.
    current: usize,
}

impl Clipper {
    fn new(tri: &[DVec3; 3]) -> Clipper {
        let mut first = Polygon {
            v: [DVec3::ZERO; MAX_POLY + 1],
            n: 3,
        };
        first.v[..3].copy_from_slice(tri);
        Clipper {
            buffers: [
                first,
                Polygon {
                    v: [DVec3::ZERO; MAX_POLY + 1],
                    n: 0,
                },
            ],
            current: 0,
        }
    }

    fn polygon(&self) -> &Polygon {
        &self.buffers[self.current]
    }

    /// Keeps the part of the polygon with `sign * (p[axis] - pos) >= 0`.
    fn cut(&mut self, axis: usize, pos: f64, sign: f64) {
        let [a, b] = &mut self.buffers;
        let (from, to) = if self.current == 0 { (a, b) } else { (b, a) };
        from.clip_into(axis, pos, sign, to);
        self.current ^= 1;
    }
}

/// Bounds of `tri ∩ voxel`, conservative (see the module contract).
pub fn clip_triangle_bounds(tri: &[DVec3; 3], voxel: &Aabb) -> Option<Aabb> {
    let tb = Aabb::from_triangle(tri);
    if !tb.overlaps(voxel) {
        return None;
    }
    if voxel.contains_box(&tb) {
        return Some(tb);
    }
    let scale = tb
        .min
        .abs()
        .max(tb.max.abs())
        .max(voxel.min.abs())
        .max(voxel.max.abs())
        .max_element();
    let grown = voxel.expanded(scale * 1e-12 + f64::MIN_POSITIVE);
    let mut clipper = Clipper::new(tri);
    for axis in 0..3 {
        // Only cut planes the triangle actually crosses; this keeps vertices exact otherwise.
        if tb.min[axis] < grown.min[axis] {
            clipper.cut(axis, grown.min[axis], 1.0);
        }
        if clipper.polygon().n > 0 && tb.max[axis] > grown.max[axis] {
            clipper.cut(axis, grown.max[axis], -1.0);
        }
        if clipper.polygon().n == 0 {
            return None;
        }
    }
    let poly = clipper.polygon();
    let b = Aabb::from_points(poly.v[..poly.n].iter()).intersection(voxel);
    (!b.is_empty()).then_some(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn clip_cases() {
        let voxel = Aabb::new(DVec3::ZERO, DVec3::ONE);
        // Triangle crossing the x = 1 face: clipped x range [0.5, 1].
        let tri = [
            DVec3::new(0.5, 0.5, 0.5),
            DVec3::new(3.0, 0.5, 0.5),
            DVec3::new(0.5, 0.9, 0.5),
        ];
        let b = clip_triangle_bounds(&tri, &voxel).unwrap();
        assert_eq!(b.min, DVec3::new(0.5, 0.5, 0.5));
        assert_eq!(b.max.x, 1.0);
        // The top of the y range is the untouched vertex (0.5, 0.9).
        assert!((b.max.y - 0.9).abs() < 1e-12, "{b:?}");
        // The bounding box overlaps the voxel but the triangle does not (diagonal, cut corner).
        let tri = [
            DVec3::new(1.5, 0.9, 0.5),
            DVec3::new(0.9, 1.5, 0.5),
            DVec3::new(1.5, 1.5, 0.5),
        ];
        assert!(Aabb::from_triangle(&tri).overlaps(&voxel));
        assert_eq!(clip_triangle_bounds(&tri, &voxel), None);
        // Triangle touching the voxel in one vertex only: kept, as a point box.
        let tri = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(2.0, 1.0, 1.0),
            DVec3::new(2.0, 2.0, 1.0),
        ];
        let b = clip_triangle_bounds(&tri, &voxel).unwrap();
        assert_eq!(b, Aabb::new(DVec3::ONE, DVec3::ONE));
    }

    /// The clipped bounds contain every sampled point of the triangle inside the voxel.
    #[test]
    fn clipped_bounds_are_conservative() {
        let seed = 17;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let voxel = Aabb::new(DVec3::new(-0.5, 0.0, 0.25), DVec3::new(0.5, 1.0, 0.75));
        for _ in 0..2000 {
            let tri = [0; 3].map(|_| {
                DVec3::new(
                    rng.gen_range(-1.5..1.5),
                    rng.gen_range(-1.0..2.0),
                    rng.gen_range(-0.5..1.5),
                )
            });
            let clipped = clip_triangle_bounds(&tri, &voxel);
            let mut inside = 0;
            for _ in 0..200 {
                let (mut a, mut b): (f64, f64) = (rng.gen(), rng.gen());
                if a + b > 1.0 {
                    (a, b) = (1.0 - a, 1.0 - b);
                }
                let p = tri[0] + (tri[1] - tri[0]) * a + (tri[2] - tri[0]) * b;
                if voxel.contains_point(p) {
                    inside += 1;
                    let c = clipped.expect("triangle has points inside the voxel");
                    assert!(c.contains_point(p), "{p} not in {c:?} for {tri:?}");
                }
            }
            if let Some(c) = clipped {
                assert!(voxel.contains_box(&c));
                let _ = inside;
            }
        }
    }
}
