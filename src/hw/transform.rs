//! `TransformUnit`: the 3x4 matrix times a point or a vector, fully pipelined, bit-exact with
//! its golden twin [`units::transform`](crate::units::transform) (src/units.rs).
//!
//! Per row `r`: `((m[r][0]*x + m[r][1]*y) + m[r][2]*z) + n[r]`, the golden model's exact order
//! and rounding. A vector (`point` = 0) omits the offset: the last adder then adds `-0`
//! instead of `n[r]`, which is an exact identity on every word an adder can produce
//! (`s + (-0) = s` for `s = +0`, `-0`, normal, infinity; a NaN stays the canonical NaN), so
//! points and vectors share one pipeline and one latency.
//!
//! Resources (paper Table 2, transformation: 9 mul, 9 add): 9 [`FpMul`], 9 [`FpAddSub`], no
//! divider. With `e7m16` each multiplier is one MULT18X18 (9 in all); with `e8m23` a 24x24
//! significand product takes four (36). Measured (`yosys synth_xilinx -family xc2v`, out of
//! context, `synth::synth_unit`): e7m16 4712 LUTs, 3693 FFs, 9 MULT18X18, 0 BRAM, depth 15
//! LUT levels; e8m23 7074 LUTs, 4788 FFs, 36 MULT18X18, 0 BRAM, depth 16.
//!
//! Latency [`TRANSFORM_LATENCY`] = mul (4) + 3 adds (8 each) = 28 clocks for every format, one
//! transform per clock. `tag` (client and thread id, [`TAG_BITS`]) travels with the data and
//! leaves with the result; `out_valid` is `in_valid` 28 clocks later.
//!
//! Matrix words are row-major `m00 m01 m02 n0 m10 m11 m12 n1 m20 m21 m22 n2`
//! ([`units::Mat34W`](crate::units::Mat34W), the layout's matrix order).

use rust_hdl::prelude::*;

use super::fp::add_sub::ADD_SUB_LATENCY;
use super::fp::mul::MUL_LATENCY;
use super::fp::{const_bits, FpAddSub, FpMul};
use super::{Delay, TAG_BITS};

/// Latency of [`TransformUnit`] in clocks (every format).
pub const TRANSFORM_LATENCY: u32 = MUL_LATENCY + 3 * ADD_SUB_LATENCY;

/// Clocks the offset `n` waits before the last adder: one product and two sums.
const OFFSET_DELAY: usize = (MUL_LATENCY + 2 * ADD_SUB_LATENCY) as usize;
const ADD_DELAY: usize = ADD_SUB_LATENCY as usize;
const TOTAL_DELAY: usize = TRANSFORM_LATENCY as usize;

#[derive(LogicBlock)]
pub struct TransformUnit<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    /// Row-major 3x4 matrix.
    pub m: [Signal<In, Bits<W>>; 12],
    /// The point or vector (x, y, z).
    pub v: [Signal<In, Bits<W>>; 3],
    /// 1: a point (add the offset column), 0: a vector.
    pub point: Signal<In, Bit>,
    /// 1: the six products off the diagonal are -0 (each multiplier takes -0 times +0), so
    /// row `r` is `m[r][r] * v[r]` (plus `n[r]` for a point) exactly: `x + (-0) = x` for
    /// every word an operator produces. Shading's per-component passes (`o + t d`,
    /// `light - p`, `kd * colour`, `acc + m cos`) go through the unit this way.
    pub diagonal: Signal<In, Bit>,
    pub tag: Signal<In, Bits<TAG_BITS>>,
    pub out_valid: Signal<Out, Bit>,
    pub result: [Signal<Out, Bits<W>>; 3],
    pub out_tag: Signal<Out, Bits<TAG_BITS>>,
    /// mul[3r + k] = m[r][k] * v[k].
    mul: [FpMul<W, E, M, S, S1, X2, P>; 9],
    /// add[3r] = p0 + p1, add[3r + 1] = (p0 + p1) + p2, add[3r + 2] = that + n (or -0).
    add: [FpAddSub<W, E, M, S, S1, X2, T>; 9],
    /// The third product of each row waits for the first sum.
    p2_delay: [Delay<Bits<W>, ADD_DELAY>; 3],
    /// The offset of each row (or -0 for a vector) waits for the second sum.
    offset_delay: [Delay<Bits<W>, OFFSET_DELAY>; 3],
    tag_delay: Delay<Bits<TAG_BITS>, TOTAL_DELAY>,
    offset: [Signal<Local, Bits<W>>; 3],
    c_neg_zero: Constant<Bits<W>>,
    c_zero: Constant<Bits<W>>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > Default for TransformUnit<W, E, M, S, S1, X2, T, P>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && T == S + 4);
        assert!(P == 2 * S);
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            m: Default::default(),
            v: Default::default(),
            point: Default::default(),
            diagonal: Default::default(),
            tag: Default::default(),
            out_valid: Default::default(),
            result: Default::default(),
            out_tag: Default::default(),
            mul: std::array::from_fn(|_| Default::default()),
            add: std::array::from_fn(|_| Default::default()),
            p2_delay: Default::default(),
            offset_delay: Default::default(),
            tag_delay: Default::default(),
            offset: Default::default(),
            c_neg_zero: const_bits::<W>(1 << (W - 1)),
            c_zero: const_bits::<W>(0),
        }
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
    > Logic for TransformUnit<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        for i in 0..9 {
            self.mul[i].clock.next = self.clock.val();
            self.add[i].clock.next = self.clock.val();
            self.add[i].sub.next = false;
        }
        for r in 0..3 {
            self.p2_delay[r].clock.next = self.clock.val();
            self.offset_delay[r].clock.next = self.clock.val();
        }
        self.tag_delay.clock.next = self.clock.val();

        for r in 0..3 {
            for k in 0..3 {
                self.mul[r * 3 + k].in_valid.next = self.in_valid.val();
                self.mul[r * 3 + k].a.next = self.m[r * 4 + k].val();
                self.mul[r * 3 + k].b.next = self.v[k].val();
            }
            self.offset[r].next = self.c_neg_zero.val();
            if self.point.val() {
                self.offset[r].next = self.m[r * 4 + 3].val();
            }
            self.offset_delay[r].data_in.next = self.offset[r].val();

            // (p0 + p1)
            self.add[r * 3].in_valid.next = self.mul[r * 3].out_valid.val();
            self.add[r * 3].a.next = self.mul[r * 3].result.val();
            self.add[r * 3].b.next = self.mul[r * 3 + 1].result.val();
            // + p2
            self.p2_delay[r].data_in.next = self.mul[r * 3 + 2].result.val();
            self.add[r * 3 + 1].in_valid.next = self.add[r * 3].out_valid.val();
            self.add[r * 3 + 1].a.next = self.add[r * 3].result.val();
            self.add[r * 3 + 1].b.next = self.p2_delay[r].data_out.val();
            // + n
            self.add[r * 3 + 2].in_valid.next = self.add[r * 3 + 1].out_valid.val();
            self.add[r * 3 + 2].a.next = self.add[r * 3 + 1].result.val();
            self.add[r * 3 + 2].b.next = self.offset_delay[r].data_out.val();
            self.result[r].next = self.add[r * 3 + 2].result.val();
        }
        // The products off the diagonal (m[r][k], r != k: 1, 2, 3, 5, 6, 7) in a diagonal pass.
        if self.diagonal.val() {
            self.mul[1].a.next = self.c_neg_zero.val();
            self.mul[1].b.next = self.c_zero.val();
            self.mul[2].a.next = self.c_neg_zero.val();
            self.mul[2].b.next = self.c_zero.val();
            self.mul[3].a.next = self.c_neg_zero.val();
            self.mul[3].b.next = self.c_zero.val();
            self.mul[5].a.next = self.c_neg_zero.val();
            self.mul[5].b.next = self.c_zero.val();
            self.mul[6].a.next = self.c_neg_zero.val();
            self.mul[6].b.next = self.c_zero.val();
            self.mul[7].a.next = self.c_neg_zero.val();
            self.mul[7].b.next = self.c_zero.val();
        }
        self.tag_delay.data_in.next = self.tag.val();
        self.out_tag.next = self.tag_delay.data_out.val();
        self.out_valid.next = self.add[2].out_valid.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::sim_harness::{clock_cycle, random_word};
    use crate::units;
    use rand::{Rng, SeedableRng};

    /// rust-hdl simulation: 300 random transforms (points and vectors, full and diagonal
    /// passes) one per clock, each result exactly TRANSFORM_LATENCY clocks after its request,
    /// equal to the model, tag kept.
    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        let f = Format::E7M16;
        let seed = 11;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let reqs: Vec<([u32; 12], [u32; 3], bool, bool)> = (0..300)
            .map(|_| {
                (
                    std::array::from_fn(|_| random_word(f, &mut rng)),
                    std::array::from_fn(|_| random_word(f, &mut rng)),
                    rng.gen_bool(0.5),
                    rng.gen_bool(0.5),
                )
            })
            .collect();
        let mut u = TransformUnit::<24, 7, 16, 17, 18, 9, 21, 34>::default();
        u.connect_all();
        let lat = TRANSFORM_LATENCY as usize;
        let mut got = Vec::new();
        for cycle in 0..reqs.len() + lat + 2 {
            let req = reqs.get(cycle);
            u.in_valid.next = req.is_some();
            if let Some((m, v, point, diagonal)) = req {
                for k in 0..12 {
                    u.m[k].next = (m[k] as u64).into();
                }
                for k in 0..3 {
                    u.v[k].next = (v[k] as u64).into();
                }
                u.point.next = *point;
                u.diagonal.next = *diagonal;
                u.tag.next = ((cycle as u64 * 3) & 0xffff).into();
            }
            clock_cycle(&mut u, |u, c| u.clock.next = Clock { clk: c });
            let expect_valid = cycle + 1 >= lat && cycle + 1 - lat < reqs.len();
            assert_eq!(
                u.out_valid.val(),
                expect_valid,
                "out_valid at clock {cycle}"
            );
            if u.out_valid.val() {
                let r = [0, 1, 2].map(|k| u.result[k].val().to_u64() as u32);
                got.push((r, u.out_tag.val().to_u64()));
            }
        }
        let diagonal_rows_differ = reqs
            .iter()
            .filter(|(m, v, point, diagonal)| {
                *diagonal
                    && units::transform(f, m, *v, *point)
                        != units::transform_pass(f, m, *v, *point, true)
            })
            .count();
        // The diagonal passes are not the full transform (a unit ignoring the input fails).
        assert!(diagonal_rows_differ > 100, "{diagonal_rows_differ}");
        for (i, ((m, v, point, diagonal), (r, tag))) in reqs.iter().zip(&got).enumerate() {
            assert_eq!(
                *r,
                units::transform_pass(f, m, *v, *point, *diagonal),
                "request {i}"
            );
            assert_eq!(*tag, (i as u64 * 3) & 0xffff, "tag of request {i}");
        }
    }
}
