//! Ray/triangle intersection in f64 (Möller–Trumbore) for the reference renderer and tests.
//!
//! Contract: `intersect(ray, tri, t_min, t_max)` returns `(t, u, v)` with the hit point
//! `(1-u-v) A + u B + v C`, `t` in `[t_min, t_max)`, `u, v >= 0`, `u + v <= 1` (edges and
//! vertices count as hits, so two triangles sharing an edge cannot both be missed by a ray
//! through it except by rounding). Both faces are hit. Rays in the triangle's plane
//! (determinant 0) and degenerate triangles never hit.

use super::ray::Ray;
use glam::DVec3;

/// Möller–Trumbore; `None` on a miss.
pub fn intersect(ray: &Ray, tri: &[DVec3; 3], t_min: f64, t_max: f64) -> Option<(f64, f64, f64)> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if !(v >= 0.0 && u + v <= 1.0) {
        return None;
    }
    let t = e2.dot(q) * inv;
    if t >= t_min && t < t_max {
        Some((t, u, v))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_and_misses() {
        let tri = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(0.0, 2.0, 1.0),
        ];
        let r = Ray::new(DVec3::new(0.5, 0.5, -1.0), DVec3::new(0.0, 0.0, 4.0));
        let (t, u, v) = intersect(&r, &tri, 0.0, f64::INFINITY).unwrap();
        assert_eq!((t, u, v), (0.5, 0.25, 0.25));
        // Back face is hit too.
        let r2 = Ray::new(DVec3::new(0.5, 0.5, 3.0), DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(intersect(&r2, &tri, 0.0, 10.0).map(|h| h.0), Some(2.0));
        // t range is [t_min, t_max).
        assert!(intersect(&r, &tri, 0.0, 0.5).is_none());
        assert!(intersect(&r, &tri, 0.6, 1.0).is_none());
        // Outside the triangle (u + v > 1).
        let r3 = Ray::new(DVec3::new(1.5, 1.5, -1.0), DVec3::Z);
        assert!(intersect(&r3, &tri, 0.0, 10.0).is_none());
        // On the edge u + v = 1 counts.
        let r4 = Ray::new(DVec3::new(1.0, 1.0, -1.0), DVec3::Z);
        assert!(intersect(&r4, &tri, 0.0, 10.0).is_some());
        // Ray in the plane, and a degenerate triangle: miss.
        let r5 = Ray::new(DVec3::new(-1.0, 0.5, 1.0), DVec3::X);
        assert!(intersect(&r5, &tri, 0.0, 10.0).is_none());
        let degenerate = [tri[0], tri[1], tri[1]];
        assert!(intersect(&r, &degenerate, 0.0, 10.0).is_none());
    }
}
