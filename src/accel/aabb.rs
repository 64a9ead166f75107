//! Axis-aligned bounding boxes in f64.
//!
//! Contract: a box is the closed set `min <= p <= max` (componentwise). [`Aabb::EMPTY`]
//! (`min = +inf`, `max = -inf`) is the identity of [`Aabb::union`] and contains nothing; a box
//! with `min == max` on some axes is flat (a planar triangle's bounds) and still non-empty.

use glam::{DAffine3, DVec3};

/// Closed axis-aligned box `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The box that contains nothing; the identity of `union`.
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// Smallest box holding all `points` (EMPTY for none).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> Self {
        points
            .into_iter()
            .fold(Self::EMPTY, |b, &p| b.union_point(p))
    }

    /// Bounds of a triangle.
    pub fn from_triangle(tri: &[DVec3; 3]) -> Self {
        Self {
            min: tri[0].min(tri[1]).min(tri[2]),
            max: tri[0].max(tri[1]).max(tri[2]),
        }
    }

    /// True if the box contains no point (any `min > max`, or a NaN bound).
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// True if all bounds are finite numbers.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn union_point(&self, p: DVec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Intersection (may be empty).
    pub fn intersection(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        }
    }

    /// True if the closed boxes share at least one point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        !self.intersection(other).is_empty()
    }

    /// True if `other` lies inside `self` (closed).
    pub fn contains_box(&self, other: &Aabb) -> bool {
        other.is_empty() || (self.min.cmple(other.min).all() && other.max.cmple(self.max).all())
    }

    pub fn contains_point(&self, p: DVec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// Surface area; 0 for an empty box, `2 (xy + yz + zx)` otherwise (flat boxes count
    /// both faces, which is what the SAH wants for planar geometry).
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The two halves of the box cut by the plane `axis = pos` (both closed, sharing the plane).
    pub fn split(&self, axis: usize, pos: f64) -> (Aabb, Aabb) {
        let mut left = *self;
        let mut right = *self;
        left.max[axis] = pos;
        right.min[axis] = pos;
        (left, right)
    }

    /// Bounds of the box after an affine map: the box around its 8 transformed corners.
    pub fn transformed(&self, m: &DAffine3) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        let mut out = Aabb::EMPTY;
        for i in 0..8 {
            let corner = DVec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out = out.union_point(m.transform_point3(corner));
        }
        out
    }

    /// The box grown by `eps` on every side.
    pub fn expanded(&self, eps: f64) -> Aabb {
        Aabb {
            min: self.min - DVec3::splat(eps),
            max: self.max + DVec3::splat(eps),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_area_and_empty() {
        let a = Aabb::new(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(a.surface_area(), 2.0 * (2.0 + 6.0 + 3.0));
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert_eq!(Aabb::EMPTY.union(&a), a);
        let b = Aabb::new(DVec3::splat(2.0), DVec3::splat(4.0));
        assert!(!a.overlaps(&b));
        assert_eq!(
            a.union(&b),
            Aabb::new(DVec3::ZERO, DVec3::new(4.0, 4.0, 4.0))
        );
        // Touching boxes overlap (closed sets).
        let c = Aabb::new(DVec3::new(1.0, 0.0, 0.0), DVec3::splat(5.0));
        assert!(a.overlaps(&c));
        // A flat box is not empty and has the area of both faces.
        let flat = Aabb::new(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0));
        assert!(!flat.is_empty());
        assert_eq!(flat.surface_area(), 2.0);
    }

    #[test]
    fn transformed_box_holds_transformed_corners() {
        let a = Aabb::new(DVec3::new(-1.0, 0.0, 2.0), DVec3::new(1.0, 3.0, 4.0));
        let m = DAffine3::from_scale_rotation_translation(
            DVec3::new(2.0, 0.5, 1.0),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, 1.1, -0.7),
            DVec3::new(5.0, -2.0, 0.25),
        );
        let t = a.transformed(&m);
        // Every point of the box (sampled) maps inside, and each face of t is touched by a corner.
        for i in 0..=4 {
            for j in 0..=4 {
                for k in 0..=4 {
                    let p = a.min + a.extent() * DVec3::new(i as f64, j as f64, k as f64) / 4.0;
                    let q = m.transform_point3(p);
                    assert!(t.expanded(1e-12).contains_point(q), "{q} outside {t:?}");
                }
            }
        }
        let rot90 = DAffine3::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let r = a.transformed(&rot90);
        assert!((r.min - DVec3::new(-3.0, -1.0, 2.0)).abs().max_element() < 1e-12);
        assert!((r.max - DVec3::new(0.0, 1.0, 4.0)).abs().max_element() < 1e-12);
    }
}
