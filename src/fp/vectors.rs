//! Test vectors for the number format: the hand-picked edge operands every operator must get
//! right, seeded random operand pairs that mix uniform bit patterns with pairs chosen to
//! provoke cancellation, exponent gaps, overflow and underflow, and seeded square-root operands
//! around exact squares and rounding midpoints.

use super::Format;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Special and boundary operands: both zeros, subnormal encodings (read as zero), infinities,
/// NaNs (canonical and not), the largest and smallest normals and their neighbours, one, two,
/// values with a full mantissa, and values whose products or quotients under- or overflow.
pub fn edge_cases(f: Format) -> Vec<u32> {
    let mut v = Vec::new();
    for sign in [false, true] {
        let s = f.zero(sign);
        let m = f.man_mask();
        v.extend([
            f.zero(sign),
            s | 1, // smallest subnormal encoding
            s | m, // largest subnormal encoding
            f.infinity(sign),
            f.nan() | s,
            f.infinity(sign) | 1, // a NaN with a different payload
            f.min_normal(sign),
            f.min_normal(sign) + 1,
            f.min_normal(sign) | m,
            f.max_finite(sign),
            f.max_finite(sign) - 1,
            s | f.one(),
            s | (f.one() + 1),
            s | (f.one() - 1),
            s | (f.one() + (1 << f.man_bits)),       // two
            s | (f.one() | m),                       // just below two
            s | (f.one() | (1 << (f.man_bits - 1))), // 1.5
        ]);
        // Exponents near the middle of the range, and half-way to the extremes, so products
        // and quotients land on both sides of overflow and underflow.
        let top = f.exp_field_max() - 1;
        for e in [2, top / 4, top / 2 - 1, top / 2 + 1, 3 * top / 4, top - 1] {
            v.push(s | (e << f.man_bits));
            v.push(s | (e << f.man_bits) | (m >> 1));
        }
    }
    v.sort_unstable();
    v.dedup();
    v
}

/// `n` seeded random operand pairs: a quarter are all edge-case combinations (as many as fit),
/// the rest uniform words, pairs with nearby exponents (cancellation and ties), pairs with the
/// same magnitude, and pairs with exponent gaps around the mantissa width.
pub fn random_pairs(f: Format, seed: u64, n: usize) -> Vec<(u32, u32)> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let edges = edge_cases(f);
    let mut out = Vec::with_capacity(n);
    'edges: for &a in &edges {
        for &b in &edges {
            if out.len() >= n / 4 {
                break 'edges;
            }
            out.push((a, b));
        }
    }
    let mask = f.word_mask();
    let exp_range = f.exp_field_max();
    while out.len() < n {
        let a: u32 = rng.gen::<u32>() & mask;
        let b = match rng.gen_range(0..6) {
            0 | 1 => rng.gen::<u32>() & mask,
            2 => {
                // Nearby exponent, random mantissa: cancellation and rounding ties in add/sub.
                let e = f.exp_field(a) as i64 + rng.gen_range(-2..=2);
                let e = e.clamp(0, exp_range as i64) as u32;
                (a & f.sign_mask()) ^ (rng.gen::<u32>() & f.sign_mask())
                    | (e << f.man_bits)
                    | (rng.gen::<u32>() & f.man_mask())
            }
            3 => {
                // Same magnitude, possibly a different last bit: exact cancellation.
                (a ^ f.sign_mask()) ^ u32::from(rng.gen_bool(0.5))
            }
            4 => {
                // Exponent gap around the mantissa width: the sticky-bit path.
                let gap = f.man_bits as i64 + rng.gen_range(-3..=4);
                let e = (f.exp_field(a) as i64 - gap).clamp(0, exp_range as i64) as u32;
                (rng.gen::<u32>() & f.sign_mask())
                    | (e << f.man_bits)
                    | (rng.gen::<u32>() & f.man_mask())
            }
            _ => edges[rng.gen_range(0..edges.len())],
        };
        out.push(if rng.gen_bool(0.5) {
            (a, b & mask)
        } else {
            (b & mask, a)
        });
    }
    out
}

/// `n` seeded random square-root operands: every edge case first (as many as fit), then a mix
/// of exact squares and their neighbours one unit in the last place away (the remainder is zero
/// or just not), words whose root lies within a tiny fraction of a unit in the last place of a
/// rounding midpoint (on either side, with the neighbouring word), uniform positive words
/// (subnormals, infinity and NaNs included), and uniform words of either sign.
pub fn sqrt_operands(f: Format, seed: u64, n: usize) -> Vec<u32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mask = f.word_mask();
    let s = f.man_bits + 1;
    let mut out: Vec<u32> = edge_cases(f).into_iter().take(n).collect();
    // The positive normal word whose significand is the top `s` bits of the integer `sig`
    // (truncated), times `2^(2k)` with `k` chosen at random in the exponent range: scaling by an
    // even power of two keeps the operand a square, or near one, of a scaled root.
    let scaled_word = |rng: &mut ChaCha8Rng, sig: u64| -> u32 {
        let bits = 64 - sig.leading_zeros();
        let man = if bits >= s {
            sig >> (bits - s)
        } else {
            sig << (s - bits)
        } as u32
            & f.man_mask();
        let target = rng.gen_range(f.emin()..=f.emax());
        let top = bits as i32 - 1;
        let mut e = top + 2 * (target - top).div_euclid(2);
        if e < f.emin() {
            e += 2;
        }
        (((e + f.bias()) as u32) << f.man_bits) | man
    };
    while out.len() < n {
        match rng.gen_range(0..7) {
            0 | 1 => {
                // An exact square of a root with at most s / 2 significant bits, and the words
                // one unit in the last place below and above it.
                let h = rng.gen_range(1..=s / 2);
                let root = (1u64 << (h - 1)) | (rng.gen::<u64>() & ((1u64 << (h - 1)) - 1));
                let w = scaled_word(&mut rng, root * root);
                out.extend([w, w.wrapping_sub(1) & mask, (w + 1) & mask]);
            }
            2 | 3 => {
                // A midpoint `mid` between adjacent s-bit roots (s + 1 bits, odd) whose square
                // is within a few units of the word grid: `mid^2 mod 2^(s+2)` is a small `c`
                // (the truncated word's root is just below `mid`) or `2^(s+2)` minus a small
                // value (the next word's root is just above). Squares of odd numbers are 1 mod
                // 8, and `mid` is a square root of `c` modulo `2^(s+2)`, found by lifting.
                let k = s + 2;
                let small = 1 + 8 * rng.gen_range(0..(1u64 << s.saturating_sub(9)).max(1));
                let above = rng.gen_bool(0.5);
                let c = if above {
                    (1u64 << k) - 7 - (small - 1)
                } else {
                    small
                };
                let y = sqrt_mod_pow2(c, k) & ((1u64 << (s + 1)) - 1);
                let mid = if y >> s == 1 {
                    y
                } else {
                    (1u64 << (s + 1)) - y
                };
                let w = scaled_word(&mut rng, mid * mid);
                let near = if above { w + 1 } else { w };
                out.extend([near & mask, (w + 1 + w - near) & mask]);
            }
            4 | 5 => out.push(rng.gen::<u32>() & (mask >> 1)),
            _ => out.push(rng.gen::<u32>() & mask),
        }
    }
    out.truncate(n);
    out
}

/// A square root of `c` modulo `2^k`, for `c = 1 (mod 8)` and `k >= 3`: if `y^2 = c` modulo
/// `2^j`, then `y` or `y + 2^(j-1)` is a root modulo `2^(j+1)`.
fn sqrt_mod_pow2(c: u64, k: u32) -> u64 {
    debug_assert!(c % 8 == 1 && k >= 3);
    let modulus = 1u64 << k;
    let mut y = 1u64;
    for j in 3..k {
        if (y * y).wrapping_sub(c) >> j & 1 != 0 {
            y += 1 << (j - 1);
        }
    }
    y % modulus
}
