//! `PrimaryRays`: ray generation in the processor, the engine's source of pixels and their
//! primary rays. A `pixel` instruction takes the next pixel and requests its ray: [`RayGen`]
//! counts the pixels in raster order (and their coordinates as floats) and sends "camera
//! matrix times the point (x, y, 0)" through the triangle tester's TransformUnit, the one
//! transformation unit, in the clocks the tester's launch leaves it free. The direction, with
//! the eye as origin, is written whole into the thread's ray in both coprocessors, kept for
//! `tri.dir`, and ends the thread's `tri.wait`.
//!
//! Contract (engine stages):
//! - Camera: `camera_write` at I5 writes words `2 camera_pair` and `2 camera_pair + 1` of
//!   {camera 3x4 (12, `FrameMap::CAMERA`), eye (3, `FrameMap::EYE`), unused} from `word_a`
//!   and `word_b` (`tri.camera`, in every thread's init: the frame's words, so a rewrite by a
//!   later thread changes nothing).
//! - Pixel (I5): while `exhausted` is low, `word` is the next pixel's word `y << pixel_shift |
//!   x` (`ProgramConfig::pixel_shift`). `refused` is high while the request slot still holds
//!   the pixel before (the thread repeats its `pixel`); an `offer` that is neither refused
//!   nor exhausted takes the pixel for `thread` and marks its ray pending. A frame start
//!   begins again at (0, 0).
//! - Request: the slot offers RayGen, whose request waits in a register of its own and goes
//!   out on `gen_*` (the tester's client port) until `gen_take`; the direction comes back on
//!   `gen_out_*`. The register keeps the tester's take out of RayGen's counters: with the take
//!   deciding their advance in the same clock, the path from the slot through the tester and
//!   back into the counters' fan-out was the processor's slowest (86.5 MHz on one placement).
//! - Write (a clock after `gen_out_valid`): `primary_write` with `primary_thread`,
//!   `primary_o` (the eye) and `primary_d` for both coprocessors' [`RayStore`]s (the engine
//!   writes no ray words in that clock: it refuses them); `done_mask` (bit `thread`) in the
//!   same clock is the thread's wake-up, and its direction is kept for `dir`.
//! - Answers: `query_thread` at I4; at I5 `pending` (the thread's ray is not written yet) and
//!   `dir` (its last primary direction).
//!
//! Latency: from the `pixel` at I5 to the request 2 clocks, then at most 2 clocks of a test's
//! launch, [`TRANSFORM_LATENCY`] (28) in the unit and 1 to the write. Throughput: one pixel
//! per 2 clocks (the slot refills the clock after RayGen takes it).
//!
//! Golden twin: [`units::primary_direction`](crate::units::primary_direction) (RayGen's) on
//! each pixel, as the engine's twin (`hw::program::exec`, op `pixel`) computes it; the golden
//! model renders each pixel's ray from the same words.
//!
//! [`RayStore`]: crate::hw::ray_store::RayStore
//! [`TRANSFORM_LATENCY`]: crate::hw::TRANSFORM_LATENCY

use rust_hdl::prelude::*;

use crate::hw::program::ProgramConfig;
use crate::hw::RayGen;

/// Camera words the engine writes, in pairs: the 3x4 camera, the eye and one unused.
pub const CAMERA_WORDS: usize = 16;

#[derive(LogicBlock)]
pub struct PrimaryRays<const W: usize, const E: usize, const M: usize> {
    pub clock: Signal<In, Clock>,
    pub frame_start: Signal<In, Bit>,
    pub camera_write: Signal<In, Bit>,
    pub camera_pair: Signal<In, Bits<3>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub offer: Signal<In, Bit>,
    pub thread: Signal<In, Bits<5>>,
    pub word: Signal<Out, Bits<32>>,
    pub exhausted: Signal<Out, Bit>,
    pub refused: Signal<Out, Bit>,
    pub gen_valid: Signal<Out, Bit>,
    pub gen_m: [Signal<Out, Bits<W>>; 12],
    pub gen_v: [Signal<Out, Bits<W>>; 3],
    pub gen_thread: Signal<Out, Bits<5>>,
    pub gen_take: Signal<In, Bit>,
    pub gen_out_valid: Signal<In, Bit>,
    pub gen_out_thread: Signal<In, Bits<5>>,
    pub gen_out_dir: [Signal<In, Bits<W>>; 3],
    pub primary_write: Signal<Out, Bit>,
    pub primary_thread: Signal<Out, Bits<5>>,
    pub primary_o: [Signal<Out, Bits<W>>; 3],
    pub primary_d: [Signal<Out, Bits<W>>; 3],
    pub done_mask: Signal<Out, Bits<32>>,
    pub query_thread: Signal<In, Bits<5>>,
    pub pending: Signal<Out, Bit>,
    pub dir: [Signal<Out, Bits<W>>; 3],
    /// A world normal from instance entry (`tri.normal`) for `normal_thread`, kept for `dir`
    /// in the primary direction's place (never in the clock of a primary write: each writes
    /// a clock after its own result, and the TransformUnit gives one result a clock).
    pub normal_write: Signal<In, Bit>,
    pub normal_thread: Signal<In, Bits<5>>,
    pub normal: [Signal<In, Bits<W>>; 3],

    raygen: RayGen<W, E, M>,
    camera: [DFF<Bits<W>>; CAMERA_WORDS],
    /// The request slot: a thread's pixel that RayGen has not sent yet.
    slot_valid: DFF<Bit>,
    slot_thread: DFF<Bits<5>>,
    taken: Signal<Local, Bit>,
    /// The request RayGen made, until the tester takes it: the point's x and y.
    req_full: DFF<Bit>,
    req_thread: DFF<Bits<5>>,
    req_xy: [DFF<Bits<W>>; 2],
    /// The direction back from the unit, registered before it is written.
    result_valid: DFF<Bit>,
    result_thread: DFF<Bits<5>>,
    result_dir: [DFF<Bits<W>>; 3],
    /// The written thread as a one-hot mask, decoded before its register: the scheduler's
    /// wake-up took the thread number's decoder, after `result_valid`'s fan-out into the ray
    /// stores, to 88.8 MHz on the ECP5.
    result_mask: DFF<Bits<32>>,
    /// Per thread: its ray is not written yet (bit `thread`).
    waiting: DFF<Bits<32>>,
    taken_mask: Signal<Local, Bits<32>>,
    pending_r: DFF<Bit>,
    /// Per thread: its last primary direction (`tri.dir`).
    dirs: [RAM<Bits<W>, 5>; 3],
    c_one: Constant<Bits<32>>,
    c_pair: [Constant<Bits<3>>; 8],
    c_width: Constant<Bits<16>>,
    c_height: Constant<Bits<16>>,
    c_pixel_shift: Constant<Bits<5>>,
}

impl<const W: usize, const E: usize, const M: usize> PrimaryRays<W, E, M> {
    /// Ray generation for the frame of `config` (its size and pixel word).
    pub fn new(config: &ProgramConfig) -> Self {
        Self {
            clock: Default::default(),
            frame_start: Default::default(),
            camera_write: Default::default(),
            camera_pair: Default::default(),
            word_a: Default::default(),
            word_b: Default::default(),
            offer: Default::default(),
            thread: Default::default(),
            word: Default::default(),
            exhausted: Default::default(),
            refused: Default::default(),
            gen_valid: Default::default(),
            gen_m: Default::default(),
            gen_v: Default::default(),
            gen_thread: Default::default(),
            gen_take: Default::default(),
            gen_out_valid: Default::default(),
            gen_out_thread: Default::default(),
            gen_out_dir: Default::default(),
            primary_write: Default::default(),
            primary_thread: Default::default(),
            primary_o: Default::default(),
            primary_d: Default::default(),
            done_mask: Default::default(),
            query_thread: Default::default(),
            pending: Default::default(),
            dir: Default::default(),
            normal_write: Default::default(),
            normal_thread: Default::default(),
            normal: Default::default(),
            raygen: Default::default(),
            camera: Default::default(),
            slot_valid: Default::default(),
            slot_thread: Default::default(),
            taken: Default::default(),
            req_full: Default::default(),
            req_thread: Default::default(),
            req_xy: Default::default(),
            result_valid: Default::default(),
            result_thread: Default::default(),
            result_dir: Default::default(),
            result_mask: Default::default(),
            waiting: Default::default(),
            taken_mask: Default::default(),
            pending_r: Default::default(),
            dirs: Default::default(),
            c_one: Constant::new(1u64.into()),
            c_pair: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_width: Constant::new(u64::from(config.width).into()),
            c_height: Constant::new(u64::from(config.height).into()),
            c_pixel_shift: Constant::new(u64::from(config.pixel_shift()).into()),
        }
    }
}

impl<const W: usize, const E: usize, const M: usize> Logic for PrimaryRays<W, E, M> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            slot_valid,
            slot_thread,
            req_full,
            req_thread,
            result_valid,
            result_thread,
            result_mask,
            waiting,
            pending_r
        );
        for k in 0..16 {
            self.camera[k].clock.next = self.clock.val();
            self.camera[k].d.next = self.camera[k].q.val();
        }
        for k in 0..2 {
            self.req_xy[k].clock.next = self.clock.val();
            self.req_xy[k].d.next = self.req_xy[k].q.val();
        }
        for k in 0..3 {
            self.result_dir[k].clock.next = self.clock.val();
            self.result_dir[k].d.next = self.gen_out_dir[k].val();
            self.dirs[k].read_clock.next = self.clock.val();
            self.dirs[k].write_clock.next = self.clock.val();
        }

        // Camera words, a pair per `tri.camera`.
        for k in 0..8 {
            if self.camera_write.val() & (self.camera_pair.val() == self.c_pair[k].val()) {
                self.camera[2 * k].d.next = self.word_a.val().get_bits::<W>(0);
                self.camera[2 * k + 1].d.next = self.word_b.val().get_bits::<W>(0);
            }
        }

        // The pixel: RayGen's current one, the slot's once taken.
        self.raygen.clock.next = self.clock.val();
        self.raygen.start.next = self.frame_start.val();
        self.raygen.width.next = self.c_width.val();
        self.raygen.height.next = self.c_height.val();
        for k in 0..12 {
            self.raygen.camera[k].next = self.camera[k].q.val();
        }
        self.word.next = (bit_cast::<32, 16>(self.raygen.issued_y.val())
            << self.c_pixel_shift.val())
            | bit_cast::<32, 16>(self.raygen.issued_x.val());
        self.exhausted.next = !self.raygen.active.val();
        self.refused.next = self.slot_valid.q.val();
        self.taken.next = self.offer.val() & (!self.slot_valid.q.val()) & self.raygen.active.val();
        if self.taken.val() {
            self.slot_valid.d.next = true;
            self.slot_thread.d.next = self.thread.val();
        }
        // The request into its register while that is empty, then to the unit until it takes
        // it (RayGen's point is (x, y, 0), its matrix the camera).
        self.raygen.thread_valid.next = self.slot_valid.q.val();
        self.raygen.thread_id.next = bit_cast::<8, 5>(self.slot_thread.q.val());
        self.raygen.req_ready.next = !self.req_full.q.val();
        if self.raygen.thread_ready.val() {
            self.slot_valid.d.next = false;
            self.req_full.d.next = true;
            self.req_thread.d.next = self.slot_thread.q.val();
            self.req_xy[0].d.next = self.raygen.req_v[0].val();
            self.req_xy[1].d.next = self.raygen.req_v[1].val();
        }
        self.gen_valid.next = self.req_full.q.val();
        for k in 0..12 {
            self.gen_m[k].next = self.camera[k].q.val();
        }
        self.gen_v[0].next = self.req_xy[0].q.val();
        self.gen_v[1].next = self.req_xy[1].q.val();
        self.gen_v[2].next = 0.into();
        self.gen_thread.next = self.req_thread.q.val();
        if self.req_full.q.val() & self.gen_take.val() {
            self.req_full.d.next = false;
        }

        // The direction, written with the eye as origin.
        self.result_valid.d.next = self.gen_out_valid.val();
        self.result_thread.d.next = self.gen_out_thread.val();
        self.result_mask.d.next = 0.into();
        if self.gen_out_valid.val() {
            self.result_mask.d.next = self.c_one.val() << self.gen_out_thread.val();
        }
        self.done_mask.next = self.result_mask.q.val();
        self.primary_write.next = self.result_valid.q.val();
        self.primary_thread.next = self.result_thread.q.val();
        for k in 0..3 {
            self.primary_o[k].next = self.camera[12 + k].q.val();
            self.primary_d[k].next = self.result_dir[k].q.val();
            self.dirs[k].write_address.next = self.result_thread.q.val();
            self.dirs[k].write_data.next = self.result_dir[k].q.val();
            if self.normal_write.val() {
                self.dirs[k].write_address.next = self.normal_thread.val();
                self.dirs[k].write_data.next = self.normal[k].val();
            }
            self.dirs[k].write_enable.next = self.result_valid.q.val() | self.normal_write.val();
            self.dirs[k].read_address.next = self.query_thread.val();
            self.dir[k].next = self.dirs[k].read_data.val();
        }
        self.taken_mask.next = 0.into();
        if self.taken.val() {
            self.taken_mask.next = self.c_one.val() << self.thread.val();
        }
        self.waiting.d.next =
            (self.waiting.q.val() & (!self.result_mask.q.val())) | self.taken_mask.val();
        self.pending_r.d.next = self
            .waiting
            .q
            .val()
            .get_bit(self.query_thread.val().index());
        self.pending.next = self.pending_r.q.val();

        if self.frame_start.val() {
            self.slot_valid.d.next = false;
            self.req_full.d.next = false;
            self.waiting.d.next = 0.into();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::program::ProgramConfig;
    use crate::hw::sim_harness::clock_cycle;
    use crate::units;
    use rand::{Rng, SeedableRng};
    use std::collections::VecDeque;

    /// PrimaryRays in rust-hdl simulation, with threads offering `pixel`s at random and a
    /// model of the tester's TransformUnit that takes a request in a random clock and returns
    /// `units::transform` of the request's words 28 clocks later. Asserts: every pixel is
    /// handed out once, in raster order, with its word; a pixel is refused while the slot is
    /// full; each thread's ray is written whole with the eye as origin and the direction
    /// `units::primary_direction` of its pixel; `pending` is high from the pixel until the
    /// write and `dir` then answers the direction.
    #[test]
    fn every_pixel_gets_its_primary_ray_through_the_shared_unit() {
        let f = Format::E7M16;
        let (w, h) = (13u32, 5u32);
        let c = ProgramConfig::frame_only(f, w, h);
        let shift = c.pixel_shift();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(33);
        let camera: [u32; 15] = std::array::from_fn(|_| f.from_f64(rng.gen_range(-2.0..2.0)));
        let mut u = PrimaryRays::<24, 7, 16>::new(&c);
        u.connect_all();
        let cycle =
            |u: &mut PrimaryRays<24, 7, 16>| clock_cycle(u, |u, c| u.clock.next = Clock { clk: c });
        // The camera, a pair of words a clock.
        for pair in 0..8 {
            let word = |k: usize| camera.get(k).copied().unwrap_or(0) as u64;
            u.camera_write.next = true;
            u.camera_pair.next = (pair as u64).into();
            u.word_a.next = word(2 * pair).into();
            u.word_b.next = word(2 * pair + 1).into();
            cycle(&mut u);
        }
        u.camera_write.next = false;
        u.frame_start.next = true;
        cycle(&mut u);
        u.frame_start.next = false;

        let m: units::Mat34W = camera[..12].try_into().unwrap();
        let eye = [camera[12], camera[13], camera[14]];
        let mut handed: Vec<(u32, u32)> = Vec::new(); // (thread, pixel word)
        let mut given: [Option<(u32, u32)>; 32] = [None; 32];
        let mut in_unit: VecDeque<Option<(u32, [u32; 3])>> = VecDeque::from(vec![None; 28]);
        let mut last_dir = [[0u32; 3]; 32];
        let (mut refused, mut written) = (0, 0);
        for _ in 0..2000 {
            let thread = rng.gen_range(0..32u32);
            let offer = given[thread as usize].is_none() && rng.gen_bool(0.5);
            u.offer.next = offer;
            u.thread.next = u64::from(thread).into();
            u.gen_take.next = rng.gen_bool(0.5);
            let back = in_unit.pop_front().unwrap();
            u.gen_out_valid.next = back.is_some();
            if let Some((t, d)) = back {
                u.gen_out_thread.next = u64::from(t).into();
                for k in 0..3 {
                    u.gen_out_dir[k].next = u64::from(d[k]).into();
                }
            }
            // The thread asked at I4 is answered after the clock, with the state before it.
            let asked = rng.gen_range(0..32usize);
            u.query_thread.next = (asked as u64).into();
            let want_pending = given[asked].is_some();
            let want_dir = last_dir[asked];
            u.clock.next = Clock { clk: false };
            crate::hw::sim_harness::settle(&mut u);
            if offer && !u.exhausted.val() {
                if u.refused.val() {
                    refused += 1;
                } else {
                    let word = u.word.val().to_u64() as u32;
                    handed.push((thread, word));
                    given[thread as usize] = Some((word & ((1 << shift) - 1), word >> shift));
                }
            }
            let taken = u.gen_valid.val() && u.gen_take.val();
            in_unit.push_back(taken.then(|| {
                let words = |s: &[Signal<Out, Bits<24>>]| -> Vec<u32> {
                    s.iter().map(|w| w.val().to_u64() as u32).collect()
                };
                let req_m: units::Mat34W = words(&u.gen_m).try_into().unwrap();
                let req_v: [u32; 3] = words(&u.gen_v).try_into().unwrap();
                let t = u.gen_thread.val().to_u64() as u32;
                (t, units::transform(f, &req_m, req_v, true))
            }));
            if !u.primary_write.val() {
                assert_eq!(u.done_mask.val().to_u64(), 0, "a wake-up without a ray");
            }
            if u.primary_write.val() {
                let t = u.primary_thread.val().to_u64() as usize;
                let (x, y) = given[t]
                    .take()
                    .expect("a ray for a thread that took a pixel");
                let o: Vec<u32> = u
                    .primary_o
                    .iter()
                    .map(|w| w.val().to_u64() as u32)
                    .collect();
                let d: Vec<u32> = u
                    .primary_d
                    .iter()
                    .map(|w| w.val().to_u64() as u32)
                    .collect();
                assert_eq!(o, eye, "origin of pixel ({x}, {y})");
                assert_eq!(d, units::primary_direction(f, &m, x, y), "pixel ({x}, {y})");
                assert_eq!(
                    u.done_mask.val().to_u64(),
                    1 << t,
                    "the wake-up of thread {t}"
                );
                last_dir[t] = d.try_into().unwrap();
                written += 1;
            }
            cycle(&mut u);
            assert_eq!(u.pending.val(), want_pending, "thread {asked} pending");
            let dir: Vec<u32> = u.dir.iter().map(|w| w.val().to_u64() as u32).collect();
            assert_eq!(dir, want_dir, "thread {asked}'s direction");
        }
        assert!(u.exhausted.val(), "the frame is done");
        let words: Vec<u32> = handed.iter().map(|&(_, w)| w).collect();
        let want: Vec<u32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (y << shift) | x))
            .collect();
        assert_eq!(words, want, "pixels in raster order, each once");
        assert_eq!(written, (w * h) as usize, "a ray per pixel");
        assert!(refused > 10, "the slot refused pixels ({refused})");
    }
}
