//! Ray generation: [`RayGen`] walks the pixels of a frame and asks the transformation unit for
//! each primary ray direction; [`RayGenUnit`] is RayGen with a private [`TransformUnit`], the
//! standalone unit that is emitted, tested and synthesized.
//!
//! Contract (bit-exact with the golden twin
//! [`units::primary_direction`](crate::units::primary_direction) in src/units.rs;
//! docs/ARCHITECTURE.md, "Primary rays"): pixel
//! (x, y) in raster order (x fastest, row 0 first) becomes the request "camera matrix times the
//! point (from_int(x), from_int(y), 0)"; the layout bakes the pixel-centre offsets and the
//! field of view into the matrix (`FrameMap::CAMERA`), and the origin is the eye
//! (`FrameMap::EYE`). The coordinates' floats are exact (equal to
//! [`Format::from_int`](crate::fp::Format::from_int)) for every coordinate below `2^(M+1)`
//! (all 16-bit coordinates for e7m16 and e8m23, up to 2047 for e5m10).
//!
//! How the floats are counted: a pixel counter moves by one, and below `2^(M+1)` the word of
//! `n + 1` is the word of `n` plus the integer `2^(M - floor(log2 n))` (the unit in the last
//! place of `n`; where `n + 1` is a power of two the mantissa's carry steps the exponent). So
//! RayGen counts `x + 1` as a float by one adder and halves the step where `x + 2` is a power
//! of two. Converting the counter with a leading-zero shifter (the engine's `itof` had one,
//! until no program used it) put 11 levels of logic in front of the transform unit's inputs,
//! and the unit reached 111.2 MHz on the ECP5.
//!
//! [`RayGen`] protocol: a `start` pulse (with `width`, `height` > 0; `width`, `height` and
//! `camera` held until the frame is done) resets the pixel counter to (0, 0) and sets
//! `active`. A free thread offers itself with `thread_valid` + `thread_id`; RayGen turns that
//! into a transform request (`req_*`, the client port of `SharedTransformUnit`) for the current
//! pixel. In the clock the request is taken (`req_ready`), `thread_ready` and `issued_valid`
//! are 1 and `issued_x`, `issued_y`, `issued_thread` tell which pixel that thread got; the
//! direction comes back from the transform unit tagged with the thread id. After the last pixel
//! `active` falls. No clock of its own: requests come straight from the counter registers
//! (the transform unit registers its inputs), so a pixel costs no latency beyond the transform
//! unit's and RayGen issues one pixel per clock the request is taken.
//!
//! [`RayGenUnit`] measured (yosys xc2v, out of context, stop 31): e7m16 4550 LUTs, 6420 FFs,
//! 6 MULT18X18, depth 5; e8m23 6639 LUTs, 8258 FFs, 24 MULT18X18. Six, not nine, products:
//! the point's z is the constant 0, so yosys turns the three `m[r][2] * z` significand products
//! into shifts (the exponent and NaN/infinity logic stay: `inf * 0` is still NaN). In the full
//! design RayGen uses the shared unit and adds no multiplier.
//!
//! [`RayGenUnit`]: latency [`TRANSFORM_LATENCY`] (28) from the issue clock to `out_valid` with
//! `out_thread`, `dir` and `origin` (the eye), one primary ray per clock.

use rust_hdl::prelude::*;

use super::fp::{bias, const_bits};
use super::transform_arbiter::THREAD_BITS;
#[cfg(doc)]
use super::TRANSFORM_LATENCY;
use super::{TransformUnit, TAG_BITS};

#[derive(LogicBlock)]
pub struct RayGen<const W: usize, const E: usize, const M: usize> {
    pub clock: Signal<In, Clock>,
    pub start: Signal<In, Bit>,
    pub width: Signal<In, Bits<16>>,
    pub height: Signal<In, Bits<16>>,
    /// The camera matrix (layout `FrameMap::CAMERA`), row-major.
    pub camera: [Signal<In, Bits<W>>; 12],
    pub thread_valid: Signal<In, Bit>,
    pub thread_id: Signal<In, Bits<THREAD_BITS>>,
    pub thread_ready: Signal<Out, Bit>,
    pub active: Signal<Out, Bit>,
    pub issued_valid: Signal<Out, Bit>,
    pub issued_x: Signal<Out, Bits<16>>,
    pub issued_y: Signal<Out, Bits<16>>,
    pub issued_thread: Signal<Out, Bits<THREAD_BITS>>,
    // The transform client port.
    pub req_valid: Signal<Out, Bit>,
    pub req_ready: Signal<In, Bit>,
    pub req_m: [Signal<Out, Bits<W>>; 12],
    pub req_v: [Signal<Out, Bits<W>>; 3],
    pub req_point: Signal<Out, Bit>,
    pub req_thread: Signal<Out, Bits<THREAD_BITS>>,
    x: DFF<Bits<16>>,
    y: DFF<Bits<16>>,
    /// `x + 1`, `y + 1`, `x + 2` and `y + 2`, counted beside `x` and `y`: no increment's carry
    /// chain sits in front of a compare (such a chain into `running` bounded the unit at 94.2
    /// MHz on the ECP5). `x + 2` and `y + 2` are compared with `width` and `height` a pixel
    /// ahead, and where they are powers of two the float step halves.
    x_next: DFF<Bits<16>>,
    y_next: DFF<Bits<16>>,
    x_after: DFF<Bits<16>>,
    y_after: DFF<Bits<16>>,
    /// The words of `x`, `y` (the request's point), `x + 1` and `y + 1`, and the steps from
    /// `x + 1` to `x + 2` and `y + 1` to `y + 2` as integers added to the words.
    x_float: DFF<Bits<W>>,
    y_float: DFF<Bits<W>>,
    x_next_float: DFF<Bits<W>>,
    y_next_float: DFF<Bits<W>>,
    x_step: DFF<Bits<W>>,
    y_step: DFF<Bits<W>>,
    running: DFF<Bit>,
    taken: Signal<Local, Bit>,
    /// The current pixel is the last of its row; its row is the frame's last. Registers, kept
    /// a pixel ahead: with the compares in front of them, `taken`'s fan-out (every counter's
    /// enable) and the loop back into `running` reached 74.0 MHz on the ECP5.
    last_column: DFF<Bit>,
    last_row: DFF<Bit>,
    /// `x + 2` (`y + 2`) is a power of two: `(x + 1) & (x + 2)` is zero.
    x_after_power: Signal<Local, Bit>,
    y_after_power: Signal<Local, Bit>,
    /// The words of 1 and the step from 1 to 2 (`2^M`).
    c_one: Constant<Bits<W>>,
    c_first_step: Constant<Bits<W>>,
}

impl<const W: usize, const E: usize, const M: usize> Default for RayGen<W, E, M> {
    fn default() -> Self {
        Self {
            clock: Default::default(),
            start: Default::default(),
            width: Default::default(),
            height: Default::default(),
            camera: Default::default(),
            thread_valid: Default::default(),
            thread_id: Default::default(),
            thread_ready: Default::default(),
            active: Default::default(),
            issued_valid: Default::default(),
            issued_x: Default::default(),
            issued_y: Default::default(),
            issued_thread: Default::default(),
            req_valid: Default::default(),
            req_ready: Default::default(),
            req_m: Default::default(),
            req_v: Default::default(),
            req_point: Default::default(),
            req_thread: Default::default(),
            x: Default::default(),
            y: Default::default(),
            x_next: Default::default(),
            y_next: Default::default(),
            x_after: Default::default(),
            y_after: Default::default(),
            x_float: Default::default(),
            y_float: Default::default(),
            x_next_float: Default::default(),
            y_next_float: Default::default(),
            x_step: Default::default(),
            y_step: Default::default(),
            running: Default::default(),
            taken: Default::default(),
            last_column: Default::default(),
            last_row: Default::default(),
            x_after_power: Default::default(),
            y_after_power: Default::default(),
            c_one: const_bits::<W>(bias(E) << M),
            c_first_step: const_bits::<W>(1 << M),
        }
    }
}

impl<const W: usize, const E: usize, const M: usize> Logic for RayGen<W, E, M> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            x,
            y,
            x_next,
            y_next,
            x_after,
            y_after,
            x_float,
            y_float,
            x_next_float,
            y_next_float,
            x_step,
            y_step,
            running,
            last_column,
            last_row
        );
        for k in 0..12 {
            self.req_m[k].next = self.camera[k].val();
        }
        self.req_v[0].next = self.x_float.q.val();
        self.req_v[1].next = self.y_float.q.val();
        self.req_v[2].next = 0.into();
        self.req_point.next = true;
        self.req_thread.next = self.thread_id.val();
        self.req_valid.next = self.running.q.val() & self.thread_valid.val();
        self.taken.next = (self.running.q.val() & self.thread_valid.val()) & self.req_ready.val();
        self.thread_ready.next = self.taken.val();
        self.issued_valid.next = self.taken.val();
        self.issued_x.next = self.x.q.val();
        self.issued_y.next = self.y.q.val();
        self.issued_thread.next = self.thread_id.val();
        self.active.next = self.running.q.val();

        self.x_after_power.next = (self.x_next.q.val() & self.x_after.q.val()) == 0;
        self.y_after_power.next = (self.y_next.q.val() & self.y_after.q.val()) == 0;
        if self.start.val() | (self.taken.val() & self.last_column.q.val()) {
            // The row's first pixel.
            self.last_column.d.next = self.width.val() == 1;
            self.x.d.next = 0.into();
            self.x_next.d.next = 1.into();
            self.x_after.d.next = 2.into();
            self.x_float.d.next = 0.into();
            self.x_next_float.d.next = self.c_one.val();
            self.x_step.d.next = self.c_first_step.val();
        } else if self.taken.val() {
            self.x.d.next = self.x_next.q.val();
            self.x_next.d.next = self.x_after.q.val();
            self.x_after.d.next = self.x_after.q.val() + 1;
            self.last_column.d.next = self.x_after.q.val() == self.width.val();
            self.x_float.d.next = self.x_next_float.q.val();
            self.x_next_float.d.next = self.x_next_float.q.val() + self.x_step.q.val();
            if self.x_after_power.val() {
                self.x_step.d.next = self.x_step.q.val() >> 1;
            }
        }
        if self.start.val() {
            self.y.d.next = 0.into();
            self.y_next.d.next = 1.into();
            self.y_after.d.next = 2.into();
            self.y_float.d.next = 0.into();
            self.y_next_float.d.next = self.c_one.val();
            self.y_step.d.next = self.c_first_step.val();
            self.last_row.d.next = self.height.val() == 1;
            self.running.d.next = (self.width.val() != 0) & (self.height.val() != 0);
        } else if self.taken.val() & self.last_column.q.val() {
            self.y.d.next = self.y_next.q.val();
            self.y_next.d.next = self.y_after.q.val();
            self.y_after.d.next = self.y_after.q.val() + 1;
            self.last_row.d.next = self.y_after.q.val() == self.height.val();
            self.y_float.d.next = self.y_next_float.q.val();
            self.y_next_float.d.next = self.y_next_float.q.val() + self.y_step.q.val();
            if self.y_after_power.val() {
                self.y_step.d.next = self.y_step.q.val() >> 1;
            }
            if self.last_row.q.val() {
                self.running.d.next = false;
            }
        }
    }
}

/// [`RayGen`] feeding its own [`TransformUnit`]: pixel counter to primary rays.
#[derive(LogicBlock)]
pub struct RayGenUnit<
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
    pub start: Signal<In, Bit>,
    pub width: Signal<In, Bits<16>>,
    pub height: Signal<In, Bits<16>>,
    pub camera: [Signal<In, Bits<W>>; 12],
    /// The eye (layout `FrameMap::EYE`), held during the frame.
    pub eye: [Signal<In, Bits<W>>; 3],
    pub thread_valid: Signal<In, Bit>,
    pub thread_id: Signal<In, Bits<THREAD_BITS>>,
    pub thread_ready: Signal<Out, Bit>,
    pub active: Signal<Out, Bit>,
    pub issued_valid: Signal<Out, Bit>,
    pub issued_x: Signal<Out, Bits<16>>,
    pub issued_y: Signal<Out, Bits<16>>,
    pub issued_thread: Signal<Out, Bits<THREAD_BITS>>,
    pub out_valid: Signal<Out, Bit>,
    pub out_thread: Signal<Out, Bits<THREAD_BITS>>,
    pub dir: [Signal<Out, Bits<W>>; 3],
    pub origin: [Signal<Out, Bits<W>>; 3],
    raygen: RayGen<W, E, M>,
    unit: TransformUnit<W, E, M, S, S1, X2, T, P>,
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
    > Default for RayGenUnit<W, E, M, S, S1, X2, T, P>
{
    fn default() -> Self {
        Self {
            clock: Default::default(),
            start: Default::default(),
            width: Default::default(),
            height: Default::default(),
            camera: Default::default(),
            eye: Default::default(),
            thread_valid: Default::default(),
            thread_id: Default::default(),
            thread_ready: Default::default(),
            active: Default::default(),
            issued_valid: Default::default(),
            issued_x: Default::default(),
            issued_y: Default::default(),
            issued_thread: Default::default(),
            out_valid: Default::default(),
            out_thread: Default::default(),
            dir: Default::default(),
            origin: Default::default(),
            raygen: Default::default(),
            unit: Default::default(),
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
    > Logic for RayGenUnit<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        self.raygen.clock.next = self.clock.val();
        self.unit.clock.next = self.clock.val();
        self.raygen.start.next = self.start.val();
        self.raygen.width.next = self.width.val();
        self.raygen.height.next = self.height.val();
        for k in 0..12 {
            self.raygen.camera[k].next = self.camera[k].val();
            self.unit.m[k].next = self.raygen.req_m[k].val();
        }
        self.raygen.thread_valid.next = self.thread_valid.val();
        self.raygen.thread_id.next = self.thread_id.val();
        self.thread_ready.next = self.raygen.thread_ready.val();
        self.active.next = self.raygen.active.val();
        self.issued_valid.next = self.raygen.issued_valid.val();
        self.issued_x.next = self.raygen.issued_x.val();
        self.issued_y.next = self.raygen.issued_y.val();
        self.issued_thread.next = self.raygen.issued_thread.val();
        // The private unit takes a request every clock.
        self.raygen.req_ready.next = true;
        self.unit.in_valid.next = self.raygen.req_valid.val();
        for k in 0..3 {
            self.unit.v[k].next = self.raygen.req_v[k].val();
            self.dir[k].next = self.unit.result[k].val();
            self.origin[k].next = self.eye[k].val();
        }
        self.unit.point.next = self.raygen.req_point.val();
        self.unit.diagonal.next = false;
        self.unit.tag.next = bit_cast::<TAG_BITS, THREAD_BITS>(self.raygen.req_thread.val());
        self.out_valid.next = self.unit.out_valid.val();
        self.out_thread.next = self.unit.out_tag.val().get_bits::<THREAD_BITS>(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::sim_harness::{clock_cycle, random_word};
    use crate::units;
    use rand::{Rng, SeedableRng};

    /// rust-hdl simulation: a 5x3 frame with a random camera, threads offered every clock but
    /// the fourth: pixels issued in raster order to the offering thread, rays equal to the
    /// model's primary directions with the eye as origin, `active` falling after the last pixel.
    #[test]
    fn rust_hdl_simulation_matches_model_e7m16() {
        let f = Format::E7M16;
        let seed = 14;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let camera: [u32; 12] = std::array::from_fn(|_| random_word(f, &mut rng));
        let eye: [u32; 3] = std::array::from_fn(|_| random_word(f, &mut rng));
        let (w, h) = (5u16, 3u16);
        let mut u = RayGenUnit::<24, 7, 16, 17, 18, 9, 21, 34>::default();
        u.connect_all();
        u.width.next = (w as u64).into();
        u.height.next = (h as u64).into();
        for k in 0..12 {
            u.camera[k].next = (camera[k] as u64).into();
        }
        for k in 0..3 {
            u.eye[k].next = (eye[k] as u64).into();
        }
        let mut issued = Vec::new();
        let mut rays = Vec::new();
        let mut thread = 0u64;
        for cycle in 0..80 {
            u.start.next = cycle == 1;
            u.thread_valid.next = cycle % 4 != 3;
            u.thread_id.next = thread.into();
            u.clock.next = Clock { clk: false };
            crate::hw::sim_harness::settle(&mut u);
            if u.issued_valid.val() {
                assert!(u.thread_ready.val());
                issued.push((
                    u.issued_x.val().to_u64() as u32,
                    u.issued_y.val().to_u64() as u32,
                    u.issued_thread.val().to_u64(),
                ));
                thread = (thread + 1) % 32;
            }
            clock_cycle(&mut u, |u, c| u.clock.next = Clock { clk: c });
            if u.out_valid.val() {
                rays.push((
                    u.out_thread.val().to_u64(),
                    [0, 1, 2].map(|k| u.dir[k].val().to_u64() as u32),
                    [0, 1, 2].map(|k| u.origin[k].val().to_u64() as u32),
                ));
            }
        }
        assert!(!u.active.val(), "the frame is done");
        let pixels: Vec<(u32, u32)> = (0..h as u32)
            .flat_map(|y| (0..w as u32).map(move |x| (x, y)))
            .collect();
        assert_eq!(issued.len(), pixels.len());
        assert_eq!(rays.len(), pixels.len());
        for (i, (&(x, y), (&(ix, iy, t), (rt, d, o)))) in
            pixels.iter().zip(issued.iter().zip(&rays)).enumerate()
        {
            assert_eq!((ix, iy), (x, y), "pixel {i}");
            assert_eq!(t, i as u64 % 32, "thread of pixel {i}");
            assert_eq!(*rt, t, "ray {i} thread");
            assert_eq!(
                *d,
                units::primary_direction(f, &camera, x, y),
                "pixel ({x}, {y})"
            );
            assert_eq!(*o, eye, "origin of pixel {i}");
        }
    }

    /// RayGen alone, with threads and the transform unit's `req_ready` refusing at random: every
    /// pixel of the frame is requested once, in raster order, with its coordinates' words equal
    /// to `from_int`. The frames cross many powers of two (where the float step halves and the
    /// exponent steps), a one-pixel-wide frame wraps at every pixel, and e5m10 goes up to its
    /// last exact coordinate, 2047.
    fn check_counted_floats<const W: usize, const E: usize, const M: usize>(
        f: Format,
        w: u16,
        h: u16,
        seed: u64,
    ) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut u = RayGen::<W, E, M>::default();
        u.connect_all();
        u.width.next = (w as u64).into();
        u.height.next = (h as u64).into();
        let mut requested = Vec::new();
        let mut cycle = 0u64;
        while cycle < 3 || u.active.val() {
            u.start.next = cycle == 1;
            u.thread_valid.next = rng.gen_bool(0.8);
            u.req_ready.next = rng.gen_bool(0.8);
            u.clock.next = Clock { clk: false };
            crate::hw::sim_harness::settle(&mut u);
            if u.req_valid.val() & u.req_ready.val() {
                assert!(u.issued_valid.val());
                let (x, y) = (u.issued_x.val().to_u64(), u.issued_y.val().to_u64());
                let words = [0, 1].map(|k| u.req_v[k].val().to_u64() as u32);
                assert_eq!(
                    words,
                    [f.from_int(x as i64), f.from_int(y as i64)],
                    "{f}: pixel ({x}, {y})"
                );
                requested.push((x, y));
            }
            clock_cycle(&mut u, |u, c| u.clock.next = Clock { clk: c });
            cycle += 1;
        }
        let pixels: Vec<(u64, u64)> = (0..h as u64)
            .flat_map(|y| (0..w as u64).map(move |x| (x, y)))
            .collect();
        assert_eq!(requested, pixels, "{f}: {w}x{h}");
    }

    #[test]
    fn counted_coordinate_floats_equal_from_int() {
        check_counted_floats::<24, 7, 16>(Format::E7M16, 4100, 3, 1);
        check_counted_floats::<24, 7, 16>(Format::E7M16, 1, 520, 2);
        check_counted_floats::<32, 8, 23>(Format::E8M23, 70, 33, 3);
        check_counted_floats::<16, 5, 10>(Format::E5M10, 2047, 2, 4);
    }
}
