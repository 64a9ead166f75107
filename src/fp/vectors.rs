//! Test vectors for the number format: the hand-picked edge operands every operator must get
//! right, and seeded random operand pairs that mix uniform bit patterns with pairs chosen to
//! provoke cancellation, exponent gaps, overflow and underflow.

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
