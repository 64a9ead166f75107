//! Rays and the ray/box slab test in f64.
//!
//! Contract: a ray is `origin + t * dir` for `t` in a caller-given interval; `dir` need not be
//! normalized and may have components equal to zero (±0.0). The slab test treats the box as
//! closed: a ray that only grazes a face or runs inside a face plane still enters the box.

use super::aabb::Aabb;
use glam::DVec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl Ray {
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        Self { origin, dir }
    }

    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }

    /// Parameter interval `[t0, t1]` of the ray inside the closed box, clipped to
    /// `[t_min, t_max]`, or `None` if the ray misses it there.
    // `!(a <= b)` deliberately treats NaN as a miss.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    ///
    /// A zero direction component is handled explicitly (no `0 * inf` NaN): the ray is inside
    /// that slab for all `t` iff its origin coordinate lies in it.
    pub fn intersect_aabb(&self, b: &Aabb, t_min: f64, t_max: f64) -> Option<(f64, f64)> {
        let mut t0 = t_min;
        let mut t1 = t_max;
        for axis in 0..3 {
            let o = self.origin[axis];
            let d = self.dir[axis];
            let (lo, hi) = (b.min[axis], b.max[axis]);
            if d == 0.0 {
                if !(lo <= o && o <= hi) {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (mut near, mut far) = ((lo - o) * inv, (hi - o) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            // Written so that a NaN (from an empty or non-finite box) rejects the ray.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
            if !(t0 <= t1) {
                return None;
            }
        }
        Some((t0, t1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_cases() {
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        let r = Ray::new(DVec3::new(-1.0, 0.5, 0.5), DVec3::X);
        assert_eq!(r.intersect_aabb(&b, 0.0, f64::INFINITY), Some((1.0, 2.0)));
        assert_eq!(r.intersect_aabb(&b, 0.0, 0.5), None);
        // Origin inside: entry clipped to t_min.
        let r = Ray::new(DVec3::splat(0.5), DVec3::new(0.0, 0.0, -2.0));
        assert_eq!(r.intersect_aabb(&b, 0.0, 10.0), Some((0.0, 0.25)));
        // Parallel to a slab, outside it: miss; on its face: hit (closed box).
        let r = Ray::new(DVec3::new(-1.0, 1.5, 0.5), DVec3::X);
        assert_eq!(r.intersect_aabb(&b, 0.0, 10.0), None);
        let r = Ray::new(DVec3::new(-1.0, 1.0, 0.5), DVec3::X);
        assert_eq!(r.intersect_aabb(&b, 0.0, 10.0), Some((1.0, 2.0)));
        // Negative zero component behaves as zero.
        let r = Ray::new(DVec3::new(0.5, 0.5, 3.0), DVec3::new(-0.0, 0.0, -1.0));
        assert_eq!(r.intersect_aabb(&b, 0.0, 10.0), Some((2.0, 3.0)));
        // Empty box never hit.
        assert_eq!(r.intersect_aabb(&Aabb::EMPTY, 0.0, 10.0), None);
        // Pointing away.
        let r = Ray::new(DVec3::new(2.0, 0.5, 0.5), DVec3::X);
        assert_eq!(r.intersect_aabb(&b, 0.0, 10.0), None);
    }
}
