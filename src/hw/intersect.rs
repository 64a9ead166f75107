//! `IntersectUnit`: Woop's unit-triangle test with the edge margin, fully pipelined, bit-exact
//! with its golden twin [`units::intersect`] (src/units.rs: `t = -O'z / D'z` is
//! [`units::unit_triangle_t`], u and v [`units::unit_triangle_coord`]).
//!
//! Given the ray already in unit-triangle space (O', D') and the segment (t_min, t_max):
//! `t = (-O'z) / D'z`, `u = O'x + t*D'x`, `v = O'y + t*D'y`, and a hit when `lo <= u`,
//! `lo <= v`, `u + v <= hi`, `t_min < t` and `t < t_max`. NaN fails every comparison, so a ray
//! parallel to the triangle (`D'z = 0`: t is infinite or NaN), NaN or infinite inputs never hit.
//!
//! `lo = -margin` and `hi = 1 + margin` are constants of the format ([`units::edge_bounds`]
//! with the margin of [`units::edge_margin`], [`units::EDGE_MARGIN_ULPS`] ulps of 1: 2^-10 at
//! e7m16): every triangle grows by the margin so that the rounding of O' and D' in two
//! neighbours' unit spaces cannot open a crack along their shared edge (PRECISION.md). The
//! comparators read constants either way, so the margin costs no hardware.
//!
//! Resources (paper Table 2, intersection: 3 add, 2 mul, 1 div): one [`FpDiv`], two
//! [`FpMul`], three [`FpAddSub`] (u, v, u + v), and five [`FpCompare`] for the range tests
//! (the paper counts comparators only for traversal). The negation of O'z is a sign flip
//! (the divider reads NaNs and subnormals the way `Format::neg` leaves them).
//!
//! Measured (`dynrt synth --unit intersect`, yosys 0.23 `synth_xilinx -family xc2v`, out of
//! context): e7m16 2773 LUTs, 7032 FFs, 2 MULT18X18, 0 BRAM, logic depth 9; e8m23 4473 LUTs,
//! 11049 FFs, 8 MULT18X18 (two 24x24 products), depth 8. The margin's bounds cost 59 LUTs at
//! e7m16 (55 at e8m23) and one LUT level at e7m16 over the exact test's 0 and 1, which the
//! comparators simplify further. Most flip-flops are delay lines (O'x, O'y, D'x, D'y, t_min,
//! t_max and the tag wait out the divider's `div_latency` clocks); yosys 0.23 does not map them to
//! SRL16s.
//!
//! Latency [`intersect_latency`] = div (`div_latency`) + mul (4) + add (8) + add (8) +
//! compare (2): 35 clocks for e7m16, 38 for e8m23; one test per clock. `tag` travels with the data.
//!
//! Timeline (clock offsets from the input, with the operators' latencies `Lm`, `La`, `Lc`): t
//! at `DL`; the two products at `DL + Lm`; u and v at `DL + Lm + La`; u + v at
//! `DL + Lm + 2 La`; every comparison result at `DL + Lm + 2 La + Lc`, the output. The
//! comparisons on t and u, v start as soon as their operands exist and wait in 1-bit delay
//! lines.
//!
//! Const parameters: the operators' `W, E, M, S, S1, X2, T, P` and `DL = div_latency(M)`,
//! checked in `default()`.
//!
//! [`units::intersect`]: crate::units::intersect
//! [`units::unit_triangle_t`]: crate::units::unit_triangle_t
//! [`units::unit_triangle_coord`]: crate::units::unit_triangle_coord
//! [`units::edge_bounds`]: crate::units::edge_bounds
//! [`units::edge_margin`]: crate::units::edge_margin

use rust_hdl::prelude::*;

use super::fp::add_sub::ADD_SUB_LATENCY;
use super::fp::compare::COMPARE_LATENCY;
use super::fp::div::div_latency;
use super::fp::mul::MUL_LATENCY;
use super::fp::{const_bits, FpAddSub, FpCompare, FpDiv, FpMul};
use super::{Delay, TAG_BITS};
use crate::fp::Format;
use crate::units;

/// Clocks from t to the output.
const AFTER_DIV: u32 = MUL_LATENCY + 2 * ADD_SUB_LATENCY + COMPARE_LATENCY;
const MUL_DELAY: usize = MUL_LATENCY as usize;
const T_DELAY: usize = AFTER_DIV as usize;
/// The t comparisons finish `COMPARE_LATENCY` after t and wait for the u + v comparison.
const T_CMP_DELAY: usize = (AFTER_DIV - COMPARE_LATENCY) as usize;
/// u and v (and their sign tests) wait for u + v and its comparison.
const UV_DELAY: usize = (ADD_SUB_LATENCY + COMPARE_LATENCY) as usize;
const UV_CMP_DELAY: usize = ADD_SUB_LATENCY as usize;

/// Latency of [`IntersectUnit`] in clocks for `fmt`.
pub fn intersect_latency(fmt: Format) -> u32 {
    div_latency(fmt.man_bits) + AFTER_DIV
}

#[derive(LogicBlock)]
pub struct IntersectUnit<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DL: usize,
> {
    pub clock: Signal<In, Clock>,
    pub in_valid: Signal<In, Bit>,
    /// O' (x, y, z).
    pub o: [Signal<In, Bits<W>>; 3],
    /// D' (x, y, z).
    pub d: [Signal<In, Bits<W>>; 3],
    pub t_min: Signal<In, Bits<W>>,
    pub t_max: Signal<In, Bits<W>>,
    pub tag: Signal<In, Bits<TAG_BITS>>,
    pub out_valid: Signal<Out, Bit>,
    pub t: Signal<Out, Bits<W>>,
    pub u: Signal<Out, Bits<W>>,
    pub v: Signal<Out, Bits<W>>,
    pub hit: Signal<Out, Bit>,
    pub out_tag: Signal<Out, Bits<TAG_BITS>>,
    div: FpDiv<W, E, M, S, S1, X2>,
    /// t * D'x, t * D'y.
    mul: [FpMul<W, E, M, S, S1, X2, P>; 2],
    /// u = O'x + t D'x, v = O'y + t D'y, u + v.
    add: [FpAddSub<W, E, M, S, S1, X2, T>; 3],
    /// t_min < t, t < t_max, lo <= u, lo <= v, u + v <= hi.
    cmp: [FpCompare<W, E, M>; 5],
    /// O'x, O'y, D'x, D'y, t_min, t_max wait for t.
    operand_delay: [Delay<Bits<W>, DL>; 6],
    /// O'x, O'y wait for the products.
    o_delay: [Delay<Bits<W>, MUL_DELAY>; 2],
    t_delay: Delay<Bits<W>, T_DELAY>,
    uv_delay: [Delay<Bits<W>, UV_DELAY>; 2],
    t_cmp_delay: [Delay<Bit, T_CMP_DELAY>; 2],
    uv_cmp_delay: [Delay<Bit, UV_CMP_DELAY>; 2],
    tag_delay_div: Delay<Bits<TAG_BITS>, DL>,
    tag_delay_rest: Delay<Bits<TAG_BITS>, T_DELAY>,
    c_sign_bit: Constant<Bits<W>>,
    /// The edge bounds: `lo = -margin`, `hi = 1 + margin` in the format.
    c_lo: Constant<Bits<W>>,
    c_hi: Constant<Bits<W>>,
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
        const DL: usize,
    > Default for IntersectUnit<W, E, M, S, S1, X2, T, P, DL>
{
    fn default() -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && T == S + 4);
        assert!(P == 2 * S && DL == div_latency(M as u32) as usize);
        let f = Format::new(E as u32, M as u32).expect("a supported format");
        let (lo, hi) = units::edge_bounds(f, units::edge_margin(f));
        Self {
            clock: Default::default(),
            in_valid: Default::default(),
            o: Default::default(),
            d: Default::default(),
            t_min: Default::default(),
            t_max: Default::default(),
            tag: Default::default(),
            out_valid: Default::default(),
            t: Default::default(),
            u: Default::default(),
            v: Default::default(),
            hit: Default::default(),
            out_tag: Default::default(),
            div: Default::default(),
            mul: Default::default(),
            add: Default::default(),
            cmp: Default::default(),
            operand_delay: Default::default(),
            o_delay: Default::default(),
            t_delay: Default::default(),
            uv_delay: Default::default(),
            t_cmp_delay: Default::default(),
            uv_cmp_delay: Default::default(),
            tag_delay_div: Default::default(),
            tag_delay_rest: Default::default(),
            c_sign_bit: const_bits::<W>(1 << (W - 1)),
            c_lo: const_bits::<W>(u64::from(lo)),
            c_hi: const_bits::<W>(u64::from(hi)),
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
        const DL: usize,
    > Logic for IntersectUnit<W, E, M, S, S1, X2, T, P, DL>
{
    #[hdl_gen]
    fn update(&mut self) {
        self.div.clock.next = self.clock.val();
        for i in 0..2 {
            self.mul[i].clock.next = self.clock.val();
            self.o_delay[i].clock.next = self.clock.val();
            self.uv_delay[i].clock.next = self.clock.val();
            self.t_cmp_delay[i].clock.next = self.clock.val();
            self.uv_cmp_delay[i].clock.next = self.clock.val();
        }
        for i in 0..3 {
            self.add[i].clock.next = self.clock.val();
            self.add[i].sub.next = false;
        }
        for i in 0..5 {
            self.cmp[i].clock.next = self.clock.val();
        }
        for i in 0..6 {
            self.operand_delay[i].clock.next = self.clock.val();
        }
        self.t_delay.clock.next = self.clock.val();
        self.tag_delay_div.clock.next = self.clock.val();
        self.tag_delay_rest.clock.next = self.clock.val();

        // t = (-O'z) / D'z; everything else waits for it.
        self.div.in_valid.next = self.in_valid.val();
        self.div.a.next = self.o[2].val() ^ self.c_sign_bit.val();
        self.div.b.next = self.d[2].val();
        self.operand_delay[0].data_in.next = self.o[0].val();
        self.operand_delay[1].data_in.next = self.o[1].val();
        self.operand_delay[2].data_in.next = self.d[0].val();
        self.operand_delay[3].data_in.next = self.d[1].val();
        self.operand_delay[4].data_in.next = self.t_min.val();
        self.operand_delay[5].data_in.next = self.t_max.val();
        self.tag_delay_div.data_in.next = self.tag.val();

        // t_min < t and t < t_max.
        self.cmp[0].in_valid.next = self.div.out_valid.val();
        self.cmp[0].a.next = self.operand_delay[4].data_out.val();
        self.cmp[0].b.next = self.div.result.val();
        self.cmp[1].in_valid.next = self.div.out_valid.val();
        self.cmp[1].a.next = self.div.result.val();
        self.cmp[1].b.next = self.operand_delay[5].data_out.val();
        self.t_cmp_delay[0].data_in.next = self.cmp[0].lt.val();
        self.t_cmp_delay[1].data_in.next = self.cmp[1].lt.val();
        self.t_delay.data_in.next = self.div.result.val();
        self.tag_delay_rest.data_in.next = self.tag_delay_div.data_out.val();

        // t * D'x, t * D'y, then u = O'x + t D'x, v = O'y + t D'y.
        for i in 0..2 {
            self.mul[i].in_valid.next = self.div.out_valid.val();
            self.mul[i].a.next = self.div.result.val();
            self.mul[i].b.next = self.operand_delay[2 + i].data_out.val();
            self.o_delay[i].data_in.next = self.operand_delay[i].data_out.val();
            self.add[i].in_valid.next = self.mul[i].out_valid.val();
            self.add[i].a.next = self.o_delay[i].data_out.val();
            self.add[i].b.next = self.mul[i].result.val();
            self.uv_delay[i].data_in.next = self.add[i].result.val();
            // lo <= u, lo <= v.
            self.cmp[2 + i].in_valid.next = self.add[i].out_valid.val();
            self.cmp[2 + i].a.next = self.c_lo.val();
            self.cmp[2 + i].b.next = self.add[i].result.val();
            self.uv_cmp_delay[i].data_in.next = self.cmp[2 + i].le.val();
        }

        // u + v <= hi.
        self.add[2].in_valid.next = self.add[0].out_valid.val();
        self.add[2].a.next = self.add[0].result.val();
        self.add[2].b.next = self.add[1].result.val();
        self.cmp[4].in_valid.next = self.add[2].out_valid.val();
        self.cmp[4].a.next = self.add[2].result.val();
        self.cmp[4].b.next = self.c_hi.val();

        self.out_valid.next = self.cmp[4].out_valid.val();
        self.t.next = self.t_delay.data_out.val();
        self.u.next = self.uv_delay[0].data_out.val();
        self.v.next = self.uv_delay[1].data_out.val();
        self.hit.next = ((self.cmp[4].le.val() & self.uv_cmp_delay[0].data_out.val())
            & (self.uv_cmp_delay[1].data_out.val() & self.t_cmp_delay[0].data_out.val()))
            & self.t_cmp_delay[1].data_out.val();
        self.out_tag.next = self.tag_delay_rest.data_out.val();
    }
}

/// Unit-space rays landing exactly on the edge bounds and one word either side of them:
/// `u` and `v` at `lo`, `u + v` at `hi`, the corners (lo, lo) and (lo, hi - lo), and the exact
/// test's old bounds (-0, 0, 1) which now lie inside. Each is `(O', D', t_min, t_max)` with
/// `D' = (0, 0, -1)` so that u = O'x, v = O'y exactly (t = O'z), and `expect_hit` says whether
/// it lies inside the bounds; the generator checks that the arithmetic lands on the intended
/// words, so the cases keep probing the bounds if the margin changes.
#[cfg(test)]
pub(crate) fn edge_bound_cases(f: Format) -> Vec<(([u32; 3], [u32; 3], u32, u32), bool)> {
    let (lo, hi) = units::edge_bounds(f, units::edge_margin(f));
    // The next word towards +inf / -inf of a finite non-zero word.
    let up = |w: u32| if f.sign_of(w) { w - 1 } else { w + 1 };
    let down = |w: u32| if f.sign_of(w) { w + 1 } else { w - 1 };
    let quarter = f.from_f64(0.25);
    let half = f.from_f64(0.5);
    let mut pairs: Vec<(u32, u32, bool)> = vec![];
    for (u, inside) in [(lo, true), (up(lo), true), (down(lo), false)] {
        pairs.push((u, quarter, inside));
        pairs.push((quarter, u, inside));
    }
    for (uv, inside) in [(hi, true), (down(hi), true), (up(hi), false)] {
        let v = f.sub(uv, half);
        assert_eq!(f.add(half, v), uv, "u + v must land on {uv:#x}");
        pairs.push((half, v, inside));
        pairs.push((v, half, inside));
    }
    let v = f.sub(hi, lo);
    assert_eq!(f.add(lo, v), hi, "lo + (hi - lo) must be hi");
    pairs.push((lo, v, true));
    pairs.push((lo, up(v), false));
    pairs.push((lo, lo, true));
    pairs.push((down(lo), lo, false));
    let one = f.one();
    pairs.push((f.neg(0), f.neg(0), true));
    pairs.push((0, one, true));
    pairs.push((one, 0, true));
    pairs.push((f.from_f64(0.5 * f.to_f64(lo)), quarter, true));
    let mut out = vec![];
    for (u, v, inside) in pairs {
        for oz in [f.one(), f.from_f64(2.5)] {
            let req = (
                [u, v, oz],
                [0, f.neg(0), f.neg(f.one())],
                0,
                f.infinity(false),
            );
            let [_, gu, gv, _] = units::unit_triangle_coords(f, req.0, req.1);
            // (-0 + t*0 is +0: equal as values.)
            assert!(f.eq(gu, u) && f.eq(gv, v), "u, v must be O'x, O'y exactly");
            out.push((req, inside));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::{clock_cycle, random_word};
    use rand::{Rng, SeedableRng};

    /// The bound cases straddle the margin: on and just inside `lo`/`hi` hit, one word
    /// outside misses, and the exact test's bounds are now inside.
    #[test]
    fn edge_bound_cases_hit_exactly_inside_the_margin() {
        for f in [Format::E7M16, Format::E8M23, Format::E5M10] {
            let cases = edge_bound_cases(f);
            for ((o, d, t_min, t_max), inside) in &cases {
                let r = units::intersect(f, *o, *d, *t_min, *t_max);
                assert_eq!(r.hit, *inside, "{f}: O'={o:x?}");
            }
            // Without the margin the points on lo and hi (outside the unit triangle) miss.
            let ((o, d, a, b), _) = cases[0];
            assert!(!units::intersect_with_margin(f, o, d, a, b, 0).hit);
        }
    }

    /// rust-hdl simulation: 250 tests (random words, and rays aimed near the unit triangle so
    /// that many hit) and the edge-bound cases, one per clock, at the documented latency,
    /// equal to the model (with its edge margin).
    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        let f = Format::E7M16;
        let seed = 12;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let w = |x: f64| f.from_f64(x);
        let reqs: Vec<([u32; 3], [u32; 3], u32, u32)> = (0..250)
            .map(|i| {
                if i % 4 == 0 {
                    let mut r = || random_word(f, &mut rng);
                    ([r(), r(), r()], [r(), r(), r()], r(), r())
                } else {
                    let oz = rng.gen_range(0.5..2.0);
                    let (tx, ty) = (rng.gen_range(-0.3..1.2), rng.gen_range(-0.3..1.2));
                    let (ox, oy) = (rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
                    (
                        [w(ox), w(oy), w(oz)],
                        [w(tx - ox), w(ty - oy), w(-oz)],
                        0,
                        f.infinity(false),
                    )
                }
            })
            .chain(edge_bound_cases(f).into_iter().map(|(r, _)| r))
            .collect();
        let mut u =
            IntersectUnit::<24, 7, 16, 17, 18, 9, 21, 34, { div_latency(16) as usize }>::default();
        u.connect_all();
        let lat = intersect_latency(f) as usize;
        let mut got = Vec::new();
        for cycle in 0..reqs.len() + lat + 2 {
            let req = reqs.get(cycle);
            u.in_valid.next = req.is_some();
            if let Some((o, d, t_min, t_max)) = req {
                for k in 0..3 {
                    u.o[k].next = (o[k] as u64).into();
                    u.d[k].next = (d[k] as u64).into();
                }
                u.t_min.next = (*t_min as u64).into();
                u.t_max.next = (*t_max as u64).into();
                u.tag.next = (cycle as u64).into();
            }
            clock_cycle(&mut u, |u, c| u.clock.next = Clock { clk: c });
            let expect_valid = cycle + 1 >= lat && cycle + 1 - lat < reqs.len();
            assert_eq!(
                u.out_valid.val(),
                expect_valid,
                "out_valid at clock {cycle}"
            );
            if u.out_valid.val() {
                got.push((
                    units::UnitHit {
                        t: u.t.val().to_u64() as u32,
                        u: u.u.val().to_u64() as u32,
                        v: u.v.val().to_u64() as u32,
                        hit: u.hit.val(),
                    },
                    u.out_tag.val().to_u64(),
                ));
            }
        }
        let mut hits = 0;
        for (i, ((o, d, t_min, t_max), (r, tag))) in reqs.iter().zip(&got).enumerate() {
            let want = units::intersect(f, *o, *d, *t_min, *t_max);
            hits += usize::from(want.hit);
            assert_eq!(*r, want, "test {i}");
            assert_eq!(*tag, i as u64, "tag of test {i}");
        }
        assert!(hits > 25, "only {hits} hits: the vectors should hit often");
    }
}
