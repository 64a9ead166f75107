//! Instances: an object placed in the world by translate / rotate / scale, optionally animated.
//!
//! Contract:
//! - `object_to_world = T(translate) * Rz(rz) * Ry(ry) * Rx(rx) * S(scale)`: a point is scaled,
//!   then rotated about X, then Y, then Z (angles in degrees, right-handed, counter-clockwise
//!   looking down the axis towards the origin), then translated.
//! - An animation over `frames` frames interpolates translate, rotate (the Euler angles, not a
//!   quaternion, so 0 -> 360 turns once) and scale linearly from the instance's own values at
//!   frame 0 to the end values at frame `frames - 1`; later frames hold the end values.

use glam::{DAffine3, DMat3, DVec3};

/// Translate / rotate (degrees, X then Y then Z) / scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    pub translate: DVec3,
    pub rotate_deg: DVec3,
    pub scale: DVec3,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    pub const IDENTITY: Transform = Transform {
        translate: DVec3::ZERO,
        rotate_deg: DVec3::ZERO,
        scale: DVec3::ONE,
    };

    /// The rotation alone: Rz * Ry * Rx.
    pub fn rotation(&self) -> DMat3 {
        let r = self.rotate_deg * (std::f64::consts::PI / 180.0);
        DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x)
    }

    /// Object-to-world matrix T * Rz * Ry * Rx * S.
    pub fn to_affine(&self) -> DAffine3 {
        DAffine3 {
            matrix3: self.rotation() * DMat3::from_diagonal(self.scale),
            translation: self.translate,
        }
    }

    /// Componentwise linear interpolation, `s` = 0 gives `self`, 1 gives `end`.
    pub fn lerp(&self, end: &Transform, s: f64) -> Transform {
        Transform {
            translate: self.translate + (end.translate - self.translate) * s,
            rotate_deg: self.rotate_deg + (end.rotate_deg - self.rotate_deg) * s,
            scale: self.scale + (end.scale - self.scale) * s,
        }
    }

    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }
}

/// Linear animation to `end`, reached at frame `frames - 1` (`frames` >= 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Animation {
    pub frames: u32,
    pub end: Transform,
}

/// One placement of `Scene::objects[object]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    pub object: usize,
    pub name: String,
    /// The transform at frame 0 (and at every frame when `animation` is None).
    pub transform: Transform,
    pub animation: Option<Animation>,
}

impl Instance {
    /// Interpolated transform at `frame` (frames past the animation's end hold the end values).
    pub fn transform_at(&self, frame: u32) -> Transform {
        match &self.animation {
            None => self.transform,
            Some(a) => {
                let last = a.frames.saturating_sub(1).max(1);
                let s = f64::from(frame.min(last)) / f64::from(last);
                if frame >= last {
                    a.end
                } else {
                    self.transform.lerp(&a.end, s)
                }
            }
        }
    }

    pub fn object_to_world(&self, frame: u32) -> DAffine3 {
        self.transform_at(frame).to_affine()
    }

    /// True if this instance leaves its object where it is, at every frame.
    pub fn is_static_identity(&self) -> bool {
        self.transform.is_identity() && self.animation.is_none_or(|a| a.end.is_identity())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rotation matrices written out by hand (column-vector convention).
    fn rx(a: f64) -> [[f64; 3]; 3] {
        let (s, c) = a.to_radians().sin_cos();
        [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
    }
    fn ry(a: f64) -> [[f64; 3]; 3] {
        let (s, c) = a.to_radians().sin_cos();
        [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    }
    fn rz(a: f64) -> [[f64; 3]; 3] {
        let (s, c) = a.to_radians().sin_cos();
        [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    }
    fn mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        m
    }

    /// Applies T * Rz * Ry * Rx * S to p, all by hand.
    fn apply_by_hand(t: [f64; 3], r: [f64; 3], s: [f64; 3], p: [f64; 3]) -> [f64; 3] {
        let m = mul(rz(r[2]), mul(ry(r[1]), rx(r[0])));
        let q = [p[0] * s[0], p[1] * s[1], p[2] * s[2]];
        let mut out = [0.0; 3];
        for i in 0..3 {
            out[i] = m[i][0] * q[0] + m[i][1] * q[1] + m[i][2] * q[2] + t[i];
        }
        out
    }

    #[test]
    fn rotation_order_is_x_then_y_then_z() {
        // 90 deg about X then 90 about Y: the +Y axis goes to +Z (X turn), then to +X (Y turn).
        let t = Transform {
            rotate_deg: DVec3::new(90.0, 90.0, 0.0),
            ..Transform::IDENTITY
        };
        let y = t.to_affine().transform_vector3(DVec3::Y);
        assert!((y - DVec3::X).length() < 1e-12, "{y}");
        // The other order (Y first) would send +Y to +Z: make sure we are not doing that.
        assert!((y - DVec3::Z).length() > 0.5);
    }

    #[test]
    fn affine_matches_hand_built_matrix() {
        let (t, r, s) = ([1.0, -2.0, 3.5], [30.0, -45.0, 110.0], [2.0, 0.5, -1.5]);
        let tf = Transform {
            translate: DVec3::from(t),
            rotate_deg: DVec3::from(r),
            scale: DVec3::from(s),
        };
        let m = tf.to_affine();
        for p in [[1.0, 0.0, 0.0], [0.3, -0.7, 2.0], [0.0, 0.0, 0.0]] {
            let want = DVec3::from(apply_by_hand(t, r, s, p));
            let got = m.transform_point3(DVec3::from(p));
            assert!((want - got).length() < 1e-12, "{want} vs {got}");
        }
    }

    #[test]
    fn animation_interpolates_and_holds_end() {
        let start = Transform {
            translate: DVec3::new(0.0, 1.0, 2.0),
            rotate_deg: DVec3::new(0.0, 0.0, 0.0),
            scale: DVec3::new(1.0, 1.0, 1.0),
        };
        let end = Transform {
            translate: DVec3::new(8.0, 1.0, -6.0),
            rotate_deg: DVec3::new(0.0, 360.0, 40.0),
            scale: DVec3::new(3.0, 1.0, 0.5),
        };
        let inst = Instance {
            object: 0,
            name: "a".into(),
            transform: start,
            animation: Some(Animation { frames: 5, end }),
        };
        // frame 2 of 5 is halfway: values written out by hand.
        let mid = inst.transform_at(2);
        assert_eq!(mid.translate, DVec3::new(4.0, 1.0, -2.0));
        assert_eq!(mid.rotate_deg, DVec3::new(0.0, 180.0, 20.0));
        assert_eq!(mid.scale, DVec3::new(2.0, 1.0, 0.75));
        assert_eq!(inst.transform_at(0), start);
        assert_eq!(inst.transform_at(4), end);
        assert_eq!(inst.transform_at(99), end);
        let m = inst.object_to_world(2);
        let want = DVec3::from(apply_by_hand(
            [4.0, 1.0, -2.0],
            [0.0, 180.0, 20.0],
            [2.0, 1.0, 0.75],
            [1.0, 2.0, 3.0],
        ));
        assert!((m.transform_point3(DVec3::new(1.0, 2.0, 3.0)) - want).length() < 1e-12);
    }
}
