//! `SharedTransformUnit`: one [`TransformUnit`] shared by [`TRANSFORM_CLIENTS`] clients through
//! a round-robin arbiter, as in the paper (ray generation, instance entry, unit-triangle
//! transformation and shading all use the one 9-mul / 9-add unit).
//!
//! Request side, per client `c`: `req_valid[c]`, `req_ready[c]`, the matrix
//! `req_m[12c .. 12c + 12]`, the vector `req_v[3c .. 3c + 3]`, `req_point[c]` and
//! `req_thread[c]`. A request is taken in a clock where `req_valid[c] & req_ready[c]`; a client
//! keeps its request (unchanged) until it is taken. `req_ready` depends on the `req_valid`s of
//! that clock (never the other way round). Every clock the arbiter takes exactly one request if
//! any is valid: the first valid client after the one taken last, in circular order, so with
//! every client always requesting each gets every fourth clock and none starves.
//!
//! Result side: `out_valid`, `out_client`, `out_thread`, `result[3]`, [`TRANSFORM_LATENCY`]
//! clocks after the request was taken. The unit never stalls, so clients must accept results
//! whenever they come; each picks out its own by `out_client` and routes them by `out_thread`.
//! Results of one client leave in the order its requests were taken.
//!
//! Latency [`SHARED_TRANSFORM_LATENCY`] (29) from the taken request to the result: the
//! arbiter is combinational, and the granted request is registered before the unit, one clock
//! more than [`TRANSFORM_LATENCY`]. Without that register the grant's fan-out (every bit of
//! the request mux) ran on into the unit's offset select, 7.7 ns of routing on the ECP5
//! (105.0 MHz against the unit's own 122.8). Throughput one request per clock, shared by the
//! clients.
//!
//! Golden twin: [`units::transform`](crate::units::transform) (src/units.rs) on each client's
//! requests, the results in that client's request order.

use rust_hdl::prelude::*;

use super::fp::const_index;
use super::{TransformUnit, TAG_BITS, TRANSFORM_LATENCY};

/// Number of clients of [`SharedTransformUnit`]: 0 ray generation, 1 instance entry (ray to
/// object space), 2 unit-triangle transformation, 3 shading (normals, secondary rays).
pub const TRANSFORM_CLIENTS: usize = 4;
/// Width of a thread id (the paper's 32 threads need 5).
pub const THREAD_BITS: usize = 8;
/// Latency of [`SharedTransformUnit`]: the request register and the unit.
pub const SHARED_TRANSFORM_LATENCY: u32 = TRANSFORM_LATENCY + 1;

#[derive(LogicBlock)]
pub struct SharedTransformUnit<
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
    pub req_valid: [Signal<In, Bit>; 4],
    pub req_ready: [Signal<Out, Bit>; 4],
    /// Client c's matrix is `req_m[12c .. 12c + 12]`, row-major.
    pub req_m: [Signal<In, Bits<W>>; 48],
    /// Client c's point or vector is `req_v[3c .. 3c + 3]`.
    pub req_v: [Signal<In, Bits<W>>; 12],
    pub req_point: [Signal<In, Bit>; 4],
    pub req_thread: [Signal<In, Bits<THREAD_BITS>>; 4],
    pub out_valid: Signal<Out, Bit>,
    pub out_client: Signal<Out, Bits<2>>,
    pub out_thread: Signal<Out, Bits<THREAD_BITS>>,
    pub result: [Signal<Out, Bits<W>>; 3],
    unit: TransformUnit<W, E, M, S, S1, X2, T, P>,
    /// The client taken last.
    last: DFF<Bits<2>>,
    /// Client c is valid and comes after `last` in this round.
    after_last: [Signal<Local, Bit>; 4],
    /// Some client before c comes after `last` and is valid (`[4]`: any of them).
    any_after_before: [Signal<Local, Bit>; 5],
    /// Some client before c is valid (`[4]`: any of them).
    any_valid_before: [Signal<Local, Bit>; 5],
    grant: [Signal<Local, Bit>; 4],
    selected: Signal<Local, Bits<2>>,
    /// The granted request, registered for the unit.
    taken_valid: DFF<Bit>,
    taken_m: [DFF<Bits<W>>; 12],
    taken_v: [DFF<Bits<W>>; 3],
    taken_point: DFF<Bit>,
    taken_tag: DFF<Bits<TAG_BITS>>,
    /// Client c's tag: client id above the thread id.
    client_tag: [Signal<Local, Bits<TAG_BITS>>; 4],
    c_client: [Constant<Bits<2>>; 4],
    c_client_shift: Constant<Bits<8>>,
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
    > Default for SharedTransformUnit<W, E, M, S, S1, X2, T, P>
{
    fn default() -> Self {
        Self {
            clock: Default::default(),
            req_valid: Default::default(),
            req_ready: Default::default(),
            req_m: std::array::from_fn(|_| Default::default()),
            req_v: Default::default(),
            req_point: Default::default(),
            req_thread: Default::default(),
            out_valid: Default::default(),
            out_client: Default::default(),
            out_thread: Default::default(),
            result: Default::default(),
            unit: Default::default(),
            last: Default::default(),
            after_last: Default::default(),
            any_after_before: Default::default(),
            any_valid_before: Default::default(),
            grant: Default::default(),
            selected: Default::default(),
            taken_valid: Default::default(),
            taken_m: Default::default(),
            taken_v: Default::default(),
            taken_point: Default::default(),
            taken_tag: Default::default(),
            client_tag: Default::default(),
            c_client: [0u64, 1, 2, 3].map(|c| Constant::new(c.into())),
            c_client_shift: const_index(THREAD_BITS),
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
    > Logic for SharedTransformUnit<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, last, taken_valid, taken_point, taken_tag);
        for k in 0..12 {
            self.taken_m[k].clock.next = self.clock.val();
        }
        for k in 0..3 {
            self.taken_v[k].clock.next = self.clock.val();
        }
        self.unit.clock.next = self.clock.val();

        // Round robin: the first valid client after `last`, else the first valid client.
        self.any_after_before[0].next = false;
        self.any_valid_before[0].next = false;
        // Client 0 never comes after another in this round.
        self.after_last[0].next = false;
        for c in 1..4 {
            self.after_last[c].next =
                self.req_valid[c].val() & (self.c_client[c].val() > self.last.q.val());
        }
        for c in 0..4 {
            self.any_after_before[c + 1].next =
                self.any_after_before[c].val() | self.after_last[c].val();
            self.any_valid_before[c + 1].next =
                self.any_valid_before[c].val() | self.req_valid[c].val();
        }
        for c in 0..4 {
            self.grant[c].next = (self.after_last[c].val() & (!self.any_after_before[c].val()))
                | ((self.req_valid[c].val() & (!self.any_valid_before[c].val()))
                    & (!self.any_after_before[4].val()));
            self.req_ready[c].next = self.grant[c].val();
        }

        // The granted client's request into the request register (client 0's when none is
        // granted; then it is not valid).
        self.selected.next = self.c_client[0].val();
        for k in 0..12 {
            self.taken_m[k].d.next = self.req_m[k].val();
        }
        for k in 0..3 {
            self.taken_v[k].d.next = self.req_v[k].val();
        }
        self.taken_point.d.next = self.req_point[0].val();
        // (bit_cast inside an unrolled loop does not compile with hdl_gen: spelled out.)
        self.client_tag[0].next = bit_cast::<TAG_BITS, THREAD_BITS>(self.req_thread[0].val());
        self.client_tag[1].next = bit_cast::<TAG_BITS, THREAD_BITS>(self.req_thread[1].val())
            | (bit_cast::<TAG_BITS, 2>(self.c_client[1].val()) << self.c_client_shift.val());
        self.client_tag[2].next = bit_cast::<TAG_BITS, THREAD_BITS>(self.req_thread[2].val())
            | (bit_cast::<TAG_BITS, 2>(self.c_client[2].val()) << self.c_client_shift.val());
        self.client_tag[3].next = bit_cast::<TAG_BITS, THREAD_BITS>(self.req_thread[3].val())
            | (bit_cast::<TAG_BITS, 2>(self.c_client[3].val()) << self.c_client_shift.val());
        self.taken_tag.d.next = self.client_tag[0].val();
        for c in 1..4 {
            if self.grant[c].val() {
                self.selected.next = self.c_client[c].val();
                for k in 0..12 {
                    self.taken_m[k].d.next = self.req_m[c * 12 + k].val();
                }
                for k in 0..3 {
                    self.taken_v[k].d.next = self.req_v[c * 3 + k].val();
                }
                self.taken_point.d.next = self.req_point[c].val();
                self.taken_tag.d.next = self.client_tag[c].val();
            }
        }
        self.taken_valid.d.next = self.any_valid_before[4].val();
        for k in 0..12 {
            self.unit.m[k].next = self.taken_m[k].q.val();
        }
        for k in 0..3 {
            self.unit.v[k].next = self.taken_v[k].q.val();
        }
        self.unit.point.next = self.taken_point.q.val();
        self.unit.diagonal.next = false;
        self.unit.tag.next = self.taken_tag.q.val();
        self.unit.in_valid.next = self.taken_valid.q.val();
        if self.any_valid_before[4].val() {
            self.last.d.next = self.selected.val();
        }

        self.out_valid.next = self.unit.out_valid.val();
        self.out_thread.next = self.unit.out_tag.val().get_bits::<THREAD_BITS>(0);
        self.out_client.next = self
            .unit
            .out_tag
            .val()
            .get_bits::<2>(self.c_client_shift.val().index());
        for k in 0..3 {
            self.result[k].next = self.unit.result[k].val();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::sim_harness::{clock_cycle, random_word};
    use crate::units;
    use rand::{Rng, SeedableRng};

    /// rust-hdl simulation: every client requests all the time, some with pauses; each request
    /// is taken exactly once, round robin under full load, and every result comes back to its
    /// client and thread in order, equal to the model.
    #[test]
    fn arbitration_under_full_load() {
        let f = Format::E7M16;
        let seed = 13;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let per_client = 20;
        type Req = ([u32; 12], [u32; 3], bool, u8);
        let reqs: Vec<Vec<Req>> = (0..4)
            .map(|c| {
                (0..per_client)
                    .map(|i| {
                        (
                            std::array::from_fn(|_| random_word(f, &mut rng)),
                            std::array::from_fn(|_| random_word(f, &mut rng)),
                            rng.gen_bool(0.5),
                            (c * 50 + i) as u8,
                        )
                    })
                    .collect()
            })
            .collect();
        let mut u = SharedTransformUnit::<24, 7, 16, 17, 18, 9, 21, 34>::default();
        u.connect_all();
        let mut next = [0usize; 4];
        let mut grants = Vec::new();
        let mut results: Vec<Vec<([u32; 3], u8)>> = vec![Vec::new(); 4];
        for cycle in 0..4 * per_client + SHARED_TRANSFORM_LATENCY as usize + 40 {
            for c in 0..4 {
                // Client 3 pauses every third clock after the first 40.
                let pause = c == 3 && cycle > 40 && cycle % 3 == 0;
                let valid = next[c] < per_client && !pause;
                u.req_valid[c].next = valid;
                if let Some((m, v, point, thread)) = reqs[c].get(next[c]) {
                    for k in 0..12 {
                        u.req_m[c * 12 + k].next = (m[k] as u64).into();
                    }
                    for k in 0..3 {
                        u.req_v[c * 3 + k].next = (v[k] as u64).into();
                    }
                    u.req_point[c].next = *point;
                    u.req_thread[c].next = (*thread as u64).into();
                }
            }
            // Settle with the clock low, read the grants of this clock, then clock.
            u.clock.next = Clock { clk: false };
            crate::hw::sim_harness::settle(&mut u);
            let granted: Vec<usize> = (0..4).filter(|&c| u.req_ready[c].val()).collect();
            assert!(granted.len() <= 1, "clock {cycle}: two grants {granted:?}");
            for &c in &granted {
                assert!(u.req_valid[c].val(), "clock {cycle}: grant without request");
                next[c] += 1;
                grants.push(c);
            }
            let any_valid = (0..4).any(|c| u.req_valid[c].val());
            assert_eq!(
                granted.len(),
                usize::from(any_valid),
                "clock {cycle}: idle arbiter"
            );
            clock_cycle(&mut u, |u, c| u.clock.next = Clock { clk: c });
            if u.out_valid.val() {
                let c = u.out_client.val().to_u64() as usize;
                let r = [0, 1, 2].map(|k| u.result[k].val().to_u64() as u32);
                results[c].push((r, u.out_thread.val().to_u64() as u8));
            }
        }
        // Full load for the first 40 clocks: 1, 2, 3, 0, 1, ...
        for (i, &c) in grants.iter().take(40).enumerate() {
            assert_eq!(c, (i + 1) % 4, "grant {i}");
        }
        for c in 0..4 {
            assert_eq!(results[c].len(), per_client, "client {c}: result count");
            for (i, ((m, v, point, thread), (r, t))) in reqs[c].iter().zip(&results[c]).enumerate()
            {
                assert_eq!(
                    *r,
                    units::transform(f, m, *v, *point),
                    "client {c} request {i}"
                );
                assert_eq!(t, thread, "client {c} request {i}: thread");
            }
        }
    }
}
