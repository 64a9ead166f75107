//! `PixelCounter`: hands out the frame's pixels, one per `pixel` instruction, in raster order
//! (the threads' shared work list).
//!
//! Contract: while pixels remain (`exhausted` low), `word` is the next pixel's word `y <<
//! pixel_shift | x` (`ProgramConfig::pixel_shift`; with a power-of-two width it is the
//! pixel's index in the frame) and `take` (a `pixel` at I5) moves on to the next. When every
//! pixel is handed out, `exhausted` is set and the `pixel` instruction branches (the thread
//! halts). A frame start begins again at (0, 0).
//!
//! Latency: `word` and `exhausted` are combinational at I5; the count moves at the end of
//! I5. Throughput: one pixel per clock.
//!
//! Golden twin: the engine's twin (`hw::program::exec`, op `pixel`) counts the same pixels in
//! the same order; the golden model renders each pixel's ray from the same `(x, y)`.

use rust_hdl::prelude::*;

use crate::hw::program::ProgramConfig;

#[derive(LogicBlock)]
pub struct PixelCounter {
    pub clock: Signal<In, Clock>,
    pub frame_start: Signal<In, Bit>,
    pub take: Signal<In, Bit>,
    pub word: Signal<Out, Bits<32>>,
    pub exhausted: Signal<Out, Bit>,
    x: DFF<Bits<16>>,
    y: DFF<Bits<16>>,
    done: Signal<Local, Bit>,
    c_width: Constant<Bits<16>>,
    c_height: Constant<Bits<16>>,
    c_pixel_shift: Constant<Bits<5>>,
}

impl PixelCounter {
    pub fn new(config: &ProgramConfig) -> Self {
        Self {
            clock: Default::default(),
            frame_start: Default::default(),
            take: Default::default(),
            word: Default::default(),
            exhausted: Default::default(),
            x: Default::default(),
            y: Default::default(),
            done: Default::default(),
            c_width: Constant::new(u64::from(config.width).into()),
            c_height: Constant::new(u64::from(config.height).into()),
            c_pixel_shift: Constant::new(u64::from(config.pixel_shift()).into()),
        }
    }
}

impl Logic for PixelCounter {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, x, y);
        self.done.next = !(self.y.q.val() < self.c_height.val());
        self.exhausted.next = self.done.val();
        self.word.next = (bit_cast::<32, 16>(self.y.q.val()) << self.c_pixel_shift.val())
            | bit_cast::<32, 16>(self.x.q.val());
        if self.take.val() & (!self.done.val()) {
            if (self.x.q.val() + 1) == self.c_width.val() {
                self.x.d.next = 0.into();
                self.y.d.next = self.y.q.val() + 1;
            } else {
                self.x.d.next = self.x.q.val() + 1;
            }
        }
        if self.frame_start.val() {
            self.x.d.next = 0.into();
            self.y.d.next = 0.into();
        }
    }
}
