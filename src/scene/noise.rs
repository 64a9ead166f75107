//! Deterministic 2D fractal value noise for the terrain generator.
//!
//! Value noise: every integer lattice point (ix, iz) gets a pseudo-random value in [-1, 1) from
//! an integer hash of (ix, iz, seed, octave); between lattice points the four corner values are
//! blended with the quintic fade 6t^5 − 15t^4 + 10t^3 (C2-continuous). `fbm` sums `octaves`
//! layers, octave o at frequency 2^o and weight 2^−o, divided by the total weight so the result
//! stays in [-1, 1]. Only integer operations and IEEE basic arithmetic are used, so the same
//! seed gives the same terrain on every machine.

/// SplitMix64 finalizer: a bijective 64-bit mixer.
fn mix64(mut h: u64) -> u64 {
    h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 31)
}

/// Lattice value in [-1, 1).
pub fn lattice_value(ix: i64, iz: i64, seed: u64, octave: u32) -> f64 {
    let h = mix64(
        mix64(seed ^ 0x243F_6A88_85A3_08D3)
            ^ mix64((ix as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
            ^ mix64(
                (iz as u64)
                    .wrapping_add(0x1357_9BDF_0246_8ACE)
                    .rotate_left(17),
            )
            ^ u64::from(octave).wrapping_mul(0xD6E8_FEB8_6659_FD93),
    );
    // Top 53 bits -> [0, 1) exactly, then to [-1, 1).
    (h >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// One octave of value noise at (x, z).
pub fn value_noise(x: f64, z: f64, seed: u64, octave: u32) -> f64 {
    let (x0, z0) = (x.floor(), z.floor());
    let (ix, iz) = (x0 as i64, z0 as i64);
    let (sx, sz) = (fade(x - x0), fade(z - z0));
    let v00 = lattice_value(ix, iz, seed, octave);
    let v10 = lattice_value(ix + 1, iz, seed, octave);
    let v01 = lattice_value(ix, iz + 1, seed, octave);
    let v11 = lattice_value(ix + 1, iz + 1, seed, octave);
    let a = v00 + (v10 - v00) * sx;
    let b = v01 + (v11 - v01) * sx;
    a + (b - a) * sz
}

/// Fractal sum of `octaves` >= 1 octaves, in [-1, 1].
pub fn fbm(x: f64, z: f64, seed: u64, octaves: u32) -> f64 {
    let mut sum = 0.0;
    let mut total = 0.0;
    let mut weight = 1.0;
    let mut freq = 1.0;
    for o in 0..octaves {
        sum += weight * value_noise(x * freq, z * freq, seed, o);
        total += weight;
        weight *= 0.5;
        freq *= 2.0;
    }
    sum / total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattice_points_take_their_hash_value() {
        for (ix, iz) in [(0, 0), (3, -7), (-100, 42)] {
            let v = value_noise(ix as f64, iz as f64, 9, 0);
            assert_eq!(v, lattice_value(ix, iz, 9, 0));
        }
    }

    #[test]
    fn deterministic_seeded_bounded_and_continuous() {
        let a: Vec<f64> = (0..200)
            .map(|i| fbm(i as f64 * 0.173, i as f64 * 0.091, 7, 5))
            .collect();
        let b: Vec<f64> = (0..200)
            .map(|i| fbm(i as f64 * 0.173, i as f64 * 0.091, 7, 5))
            .collect();
        let c: Vec<f64> = (0..200)
            .map(|i| fbm(i as f64 * 0.173, i as f64 * 0.091, 8, 5))
            .collect();
        assert_eq!(a, b);
        assert!(a.iter().zip(&c).filter(|(x, y)| x != y).count() > 190);
        assert!(a.iter().all(|v| (-1.0..=1.0).contains(v)));
        // Not constant: a real spread of heights.
        let (lo, hi) = a
            .iter()
            .fold((1.0f64, -1.0f64), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(hi - lo > 0.5, "{lo}..{hi}");
        // Continuous: a 1e-6 step moves the value by far less than the spread.
        for i in 0..50 {
            let (x, z) = (i as f64 * 0.37, i as f64 * 0.21);
            assert!((fbm(x, z, 3, 4) - fbm(x + 1e-6, z, 3, 4)).abs() < 1e-3);
        }
    }

    #[test]
    fn lattice_values_are_spread_over_the_range() {
        let vals: Vec<f64> = (0..1000).map(|i| lattice_value(i, 0, 1, 0)).collect();
        let mean = vals.iter().sum::<f64>() / 1000.0;
        assert!(mean.abs() < 0.1, "mean {mean}");
        assert!(vals.iter().filter(|&&v| v > 0.5).count() > 150);
        assert!(vals.iter().filter(|&&v| v < -0.5).count() > 150);
    }
}
