//! The arithmetic of every hardware unit, written once as sequences of `fp` operations.
//!
//! The golden model calls these; each hardware unit's tests compare the RTL with them, so the
//! RTL computes the same operations in the same order with the same rounding (DESIGN.md
//! section 2). Change an order here and the hardware must change with it.

use crate::fp::Format;

/// A 3-vector of format words.
pub type Vec3W = [u32; 3];
/// A 3x4 matrix, row-major: `m00 m01 m02 n0 m10 m11 m12 n1 m20 m21 m22 n2`.
pub type Mat34W = [u32; 12];

/// TransformUnit: `x' = ((m00*x + m01*y) + m02*z) + n0` per row for a point; a vector omits
/// the `+ n` step. 9 multiplications and 9 additions for a point (6 for a vector).
pub fn transform(f: Format, m: &Mat34W, v: Vec3W, point: bool) -> Vec3W {
    let row = |r: usize| {
        let m = &m[r * 4..r * 4 + 4];
        let s = f.add(
            f.add(f.mul(m[0], v[0]), f.mul(m[1], v[1])),
            f.mul(m[2], v[2]),
        );
        if point {
            f.add(s, m[3])
        } else {
            s
        }
    };
    [row(0), row(1), row(2)]
}

/// The normal transform is a 3x3 (the 3x4 layout without offsets), run as a vector transform.
pub fn transform3(f: Format, m: &[u32; 9], v: Vec3W) -> Vec3W {
    let row = |r: usize| {
        f.add(
            f.add(f.mul(m[r * 3], v[0]), f.mul(m[r * 3 + 1], v[1])),
            f.mul(m[r * 3 + 2], v[2]),
        )
    };
    [row(0), row(1), row(2)]
}

/// RayGen: the primary ray direction of pixel (x, y) is the camera matrix applied to the point
/// (x, y, 0) (the layout bakes the pixel-centre offsets into the matrix's offset column).
pub fn primary_direction(f: Format, camera: &Mat34W, x: u32, y: u32) -> Vec3W {
    transform(
        f,
        camera,
        [f.from_int(x as i64), f.from_int(y as i64), 0],
        true,
    )
}

/// The result of one unit-triangle test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitHit {
    pub t: u32,
    pub u: u32,
    pub v: u32,
    pub hit: bool,
}

/// IntersectUnit, given the ray already in unit-triangle space (O', D'):
/// `t = -O'z / D'z`, `u = O'x + t*D'x`, `v = O'y + t*D'y`; a hit when `0 <= u`, `0 <= v`,
/// `u + v <= 1` and `t_min < t < t_max`. NaN fails every comparison, so a ray parallel to the
/// triangle (D'z = 0) or any NaN or infinity never hits. 1 div, 2 mul, 3 add.
pub fn intersect(f: Format, o: Vec3W, d: Vec3W, t_min: u32, t_max: u32) -> UnitHit {
    let t = f.div(f.neg(o[2]), d[2]);
    let u = f.add(o[0], f.mul(t, d[0]));
    let v = f.add(o[1], f.mul(t, d[1]));
    let inside = f.le(0, u) && f.le(0, v) && f.le(f.add(u, v), f.one());
    let hit = inside && f.lt(t_min, t) && f.lt(t, t_max);
    UnitHit { t, u, v, hit }
}

/// The unit-triangle test with a conservative edge margin: a hit when `-margin <= u`,
/// `-margin <= v` and `u + v <= 1 + margin` (and t in range). The bounds are constants
/// (`-margin` and `1 + margin`, each rounded once), so in hardware the margin costs no operator:
/// the comparators compare against other constants. With `margin` = 0 this is exactly
/// [`intersect`]. Grows every triangle by `margin` in unit-triangle coordinates (a fraction of
/// its size) so that rounding cannot open a crack along a shared edge; the precision study
/// (`bench`, `stress`) measures what it closes and what it adds at silhouettes.
pub fn intersect_with_margin(
    f: Format,
    o: Vec3W,
    d: Vec3W,
    t_min: u32,
    t_max: u32,
    margin: u32,
) -> UnitHit {
    let lo = f.neg(margin);
    let hi = f.add(f.one(), margin);
    let t = f.div(f.neg(o[2]), d[2]);
    let u = f.add(o[0], f.mul(t, d[0]));
    let v = f.add(o[1], f.mul(t, d[1]));
    let inside = f.le(lo, u) && f.le(lo, v) && f.le(f.add(u, v), hi);
    let hit = inside && f.lt(t_min, t) && f.lt(t, t_max);
    UnitHit { t, u, v, hit }
}

/// Which children of an inner kd node a ray segment [t_min, t_max] visits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visit {
    /// Only the near child, with the whole segment.
    Near,
    /// Only the far child, with the whole segment.
    Far,
    /// The near child with [t_min, t_split], then the far child with [t_split, t_max].
    Both { t_split: u32 },
}

/// One traversal step (traversal unit): `t_split = (split - o) / d` along the node's axis, and
/// the near child is the one holding the origin (on the plane, the one the ray heads into).
/// Returns whether the near child is the left (below) one, and which children to visit.
/// 1 add (sub), 1 div, comparisons.
pub fn traversal_step(
    f: Format,
    o: u32,
    d: u32,
    split: u32,
    t_min: u32,
    t_max: u32,
) -> (bool, Visit) {
    let near_is_left = f.lt(o, split) || (f.eq(o, split) && f.le(d, 0));
    if f.eq(d, 0) {
        return (near_is_left, Visit::Near);
    }
    let t_split = f.div(f.sub(split, o), d);
    let visit = if f.lt(t_max, t_split) || f.le(t_split, 0) {
        Visit::Near
    } else if f.lt(t_split, t_min) {
        Visit::Far
    } else {
        Visit::Both { t_split }
    };
    (near_is_left, visit)
}

/// `a . b` as `(ax*bx + ay*by) + az*bz`.
pub fn dot(f: Format, a: Vec3W, b: Vec3W) -> u32 {
    f.add(
        f.add(f.mul(a[0], b[0]), f.mul(a[1], b[1])),
        f.mul(a[2], b[2]),
    )
}

/// The point `o + t*d`, per component `o + t*d`.
pub fn ray_point(f: Format, o: Vec3W, d: Vec3W, t: u32) -> Vec3W {
    [0, 1, 2].map(|i| f.add(o[i], f.mul(t, d[i])))
}

/// `b - a` per component.
pub fn sub3(f: Format, b: Vec3W, a: Vec3W) -> Vec3W {
    [0, 1, 2].map(|i| f.sub(b[i], a[i]))
}

/// Shader: the unit normal facing the incoming ray. `n / sqrt(n.n)` as one reciprocal and
/// three products, then flipped when it points along the ray.
pub fn facing_unit_normal(f: Format, n: Vec3W, ray_dir: Vec3W) -> Vec3W {
    let inv_len = f.div(f.one(), f.sqrt(dot(f, n, n)));
    let unit = n.map(|c| f.mul(c, inv_len));
    if f.lt(0, dot(f, unit, ray_dir)) {
        unit.map(|c| f.neg(c))
    } else {
        unit
    }
}

/// Shader: the Lambert cosine of a light seen along `to_light` (not normalized) from a surface
/// with unit normal `n`: `(n . L) / sqrt(L . L)`, or `None` when the light is behind.
pub fn lambert_cosine(f: Format, n: Vec3W, to_light: Vec3W) -> Option<u32> {
    let n_dot_l = dot(f, n, to_light);
    if !f.lt(0, n_dot_l) {
        return None;
    }
    Some(f.div(n_dot_l, f.sqrt(dot(f, to_light, to_light))))
}

/// Shader: `acc + (kd * light) * cos` per channel.
pub fn add_light(f: Format, acc: Vec3W, kd: Vec3W, light: Vec3W, cos: u32) -> Vec3W {
    [0, 1, 2].map(|i| f.add(acc[i], f.mul(f.mul(kd[i], light[i]), cos)))
}

/// Shader: the ambient term `kd * ambient` per channel.
pub fn ambient(f: Format, kd: Vec3W, ambient: u32) -> Vec3W {
    kd.map(|c| f.mul(c, ambient))
}

/// Shader: the mirror direction `d - (2 (d . n)) n` for a unit normal `n`.
pub fn reflect(f: Format, d: Vec3W, n: Vec3W) -> Vec3W {
    let k = f.mul(f.from_int(2), dot(f, d, n));
    [0, 1, 2].map(|i| f.sub(d[i], f.mul(k, n[i])))
}

/// Shader: `(1 - m) * local + m * reflected` per channel.
pub fn mix_mirror(f: Format, local: Vec3W, reflected: Vec3W, m: u32) -> Vec3W {
    let keep = f.sub(f.one(), m);
    [0, 1, 2].map(|i| f.add(f.mul(keep, local[i]), f.mul(m, reflected[i])))
}

/// The frame-buffer word `0x00RRGGBB` of a colour.
pub fn pack_rgb(f: Format, c: Vec3W) -> u32 {
    let [r, g, b] = c.map(|x| u32::from(f.to_u8(x)));
    (r << 16) | (g << 8) | b
}

#[cfg(test)]
mod margin_tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn margin_zero_is_the_exact_test_and_a_margin_only_adds_hits_near_edges() {
        let seed = 61;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for f in [Format::E7M16, Format::E8M23, Format::E5M10] {
            // Wide enough that random rays land in it often.
            let margin = f.from_f64(0.05);
            let (mut added, mut near_edge) = (0, 0);
            for _ in 0..20_000 {
                let mut w = || f.from_f64(rng.gen_range(-2.0..2.0));
                let (o, d) = ([w(), w(), w()], [w(), w(), w()]);
                let inf = f.infinity(false);
                let exact = intersect(f, o, d, 0, inf);
                assert_eq!(intersect_with_margin(f, o, d, 0, inf, 0), exact, "{f}");
                let wide = intersect_with_margin(f, o, d, 0, inf, margin);
                assert_eq!((wide.t, wide.u, wide.v), (exact.t, exact.u, exact.v));
                assert!(wide.hit || !exact.hit, "a margin never loses a hit");
                if wide.hit && !exact.hit {
                    added += 1;
                    let (u, v) = (f.to_f64(wide.u), f.to_f64(wide.v));
                    let m = f.to_f64(margin);
                    // Only points within the margin of the triangle's edges are added.
                    assert!(u < 0.0 || v < 0.0 || u + v > 1.0);
                    assert!(u >= -m && v >= -m && u + v <= 1.0 + 2.0 * m, "{u} {v}");
                    near_edge += 1;
                }
            }
            println!("{f}: margin adds {added} hits, all within it of an edge ({near_edge})");
            assert!(
                added > 0,
                "{f}: random rays must sometimes land in the margin"
            );
        }
    }
}
