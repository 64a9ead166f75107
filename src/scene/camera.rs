//! The pinhole camera and its primary rays (docs/ARCHITECTURE.md, "Primary rays"), in f64.
//!
//! Pixel (x, y), row 0 at the top, goes through the pixel centre: with
//! f = normalize(look_at − eye), r = normalize(f × up), u = r × f, h = tan(fov_y / 2),
//! a = W / H: D = f + ((2(x + 0.5)/W − 1)·h·a)·r + ((1 − 2(y + 0.5)/H)·h)·u, O = eye.
//! D is *not* normalized (the hardware does not normalize it either); hit distances along it
//! are parametric and must be scaled by |D| to give world distances.

use glam::DVec3;

/// A validated camera: eye != look_at, up not parallel to the view, 0 < fov_y_deg < 180,
/// 1 <= width, height <= `MAX_RESOLUTION`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    pub fov_y_deg: f64,
    pub width: u32,
    pub height: u32,
}

/// The camera frame: forward, right and (true) up, each of unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraBasis {
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
}

impl Camera {
    pub fn basis(&self) -> CameraBasis {
        let forward = (self.look_at - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        CameraBasis { forward, right, up }
    }

    /// tan(fov_y / 2): half the image height at distance 1.
    pub fn half_height(&self) -> f64 {
        (self.fov_y_deg.to_radians() * 0.5).tan()
    }

    pub fn aspect(&self) -> f64 {
        f64::from(self.width) / f64::from(self.height)
    }

    /// Primary ray of pixel (x, y) as (origin, unnormalized direction), per docs/ARCHITECTURE.md, "Primary rays".
    pub fn primary_ray(&self, x: u32, y: u32) -> (DVec3, DVec3) {
        self.ray_through(f64::from(x) + 0.5, f64::from(y) + 0.5)
    }

    /// Ray through the continuous image point (sx, sy) in pixel units: (0, 0) is the top-left
    /// image corner, (W, H) the bottom-right one. `primary_ray(x, y)` = `ray_through(x+.5, y+.5)`.
    pub fn ray_through(&self, sx: f64, sy: f64) -> (DVec3, DVec3) {
        let b = self.basis();
        let h = self.half_height();
        let a = self.aspect();
        let px = (2.0 * sx / f64::from(self.width) - 1.0) * h * a;
        let py = (1.0 - 2.0 * sy / f64::from(self.height)) * h;
        (self.eye, b.forward + px * b.right + py * b.up)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(w: u32, h: u32, fov: f64) -> Camera {
        Camera {
            eye: DVec3::new(0.0, 1.0, 3.5),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
            fov_y_deg: fov,
            width: w,
            height: h,
        }
    }

    #[test]
    fn two_by_two_at_90_degrees_by_hand() {
        // f = -z, r = f x up = +x, u = r x f = +y, h = tan 45 = 1, a = 1.
        let c = cam(2, 2, 90.0);
        let (o, d) = c.primary_ray(0, 0);
        assert_eq!(o, DVec3::new(0.0, 1.0, 3.5));
        assert!((d - DVec3::new(-0.5, 0.5, -1.0)).length() < 1e-15, "{d}");
        let (_, d) = c.primary_ray(1, 1);
        assert!((d - DVec3::new(0.5, -0.5, -1.0)).length() < 1e-15, "{d}");
    }

    #[test]
    fn centre_pixel_looks_along_view_direction() {
        let c = Camera {
            eye: DVec3::new(1.0, 2.0, 3.0),
            look_at: DVec3::new(-2.0, 0.0, 1.0),
            up: DVec3::new(0.1, 1.0, 0.0),
            fov_y_deg: 50.0,
            width: 33,
            height: 17,
        };
        let (_, d) = c.primary_ray(16, 8);
        let f = (c.look_at - c.eye).normalize();
        assert!((d - f).length() < 1e-14, "{d} vs {f}");
    }

    #[test]
    fn image_edges_are_at_half_the_field_of_view() {
        for (w, h, fov) in [(64, 64, 40.0), (64, 48, 60.0), (16, 12, 120.0)] {
            let c = cam(w, h, fov);
            let f = c.basis().forward;
            // Top edge midpoint: angle to f is fov/2.
            let (_, d) = c.ray_through(f64::from(w) / 2.0, 0.0);
            let ang = d.angle_between(f).to_degrees();
            assert!((ang - fov / 2.0).abs() < 1e-9, "{ang}");
            // Left edge midpoint: horizontal half-angle = atan(tan(fov/2) * W/H).
            let (_, d) = c.ray_through(0.0, f64::from(h) / 2.0);
            let want = ((fov / 2.0).to_radians().tan() * f64::from(w) / f64::from(h))
                .atan()
                .to_degrees();
            assert!((d.angle_between(f).to_degrees() - want).abs() < 1e-9);
            // Row 0 is the top: its rays point upwards (+y here), column 0 to the left (-x).
            let (_, d) = c.primary_ray(0, 0);
            assert!(d.y > 0.0 && d.x < 0.0);
        }
    }
}
