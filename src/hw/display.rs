//! The processor's video output: [`VgaDisplay`] shows the frame buffer on a VGA monitor.
//!
//! Contract (pixel clock `clock`, synchronous active-high `reset`, as [`VgaTiming`]):
//! - `fb_addr` drives a read port of the frame-buffer memory; the word `fb_data` must arrive
//!   [`FB_READ_LATENCY`] clock later (a registered read, as a block RAM's or the testbench's
//!   second port of the frame bank gives).
//! - `hsync`, `vsync`, `rgb` (`0xRRGGBB`, the frame-buffer word's low 24 bits; black on the
//!   porches, during sync and on the border around a magnified image) and `frame_start` are
//!   registers describing one pixel, [`DISPLAY_LATENCY`] clocks after [`VgaTiming`]'s outputs
//!   described it: the syncs are delayed alongside the memory read so colour and syncs line up.
//!
//! Throughput: one pixel per clock. Latency: [`DISPLAY_LATENCY`] clocks behind the timing
//! generator. Size: the timing generator plus 5 flip-flops and a 24-bit output register.
//!
//! Golden twin: none that computes words. The pixel shown is the frame-buffer word as written,
//! and the timing is [`VgaTiming`]'s (checked in src/sim/vga_timing/tests.rs);
//! tests/processor_sim.rs checks that the processor's display shows the rendered frame.

use rust_hdl::prelude::*;

use super::vga::{VgaError, VgaMode, VgaTiming, VGA_ADDR_BITS};

/// Clocks from `fb_addr` to its word on `fb_data`.
pub const FB_READ_LATENCY: u32 = 1;
/// Clocks from the timing generator's description of a pixel to the outputs' (the memory read,
/// then the output register).
pub const DISPLAY_LATENCY: u32 = FB_READ_LATENCY + 1;

/// VGA output of a frame buffer (see the module doc).
#[derive(LogicBlock)]
pub struct VgaDisplay {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, Bit>,
    pub fb_addr: Signal<Out, Bits<VGA_ADDR_BITS>>,
    pub fb_data: Signal<In, Bits<32>>,
    pub hsync: Signal<Out, Bit>,
    pub vsync: Signal<Out, Bit>,
    pub rgb: Signal<Out, Bits<24>>,
    pub frame_start: Signal<Out, Bit>,
    timing: VgaTiming,
    // Alongside the memory read.
    hsync_d: DFF<Bit>,
    vsync_d: DFF<Bit>,
    dark_d: DFF<Bit>,
    start_d: DFF<Bit>,
    // Output register.
    hsync_q: DFF<Bit>,
    vsync_q: DFF<Bit>,
    start_q: DFF<Bit>,
    rgb_q: DFF<Bits<24>>,
}

impl VgaDisplay {
    /// The display for `mode` showing a `fb_width x fb_height` frame buffer at word `fb_base`.
    pub fn new(
        mode: &VgaMode,
        fb_width: u32,
        fb_height: u32,
        fb_base: u32,
    ) -> Result<VgaDisplay, VgaError> {
        Ok(VgaDisplay {
            clock: Default::default(),
            reset: Default::default(),
            fb_addr: Default::default(),
            fb_data: Default::default(),
            hsync: Default::default(),
            vsync: Default::default(),
            rgb: Default::default(),
            frame_start: Default::default(),
            timing: VgaTiming::new(mode, fb_width, fb_height, fb_base)?,
            hsync_d: Default::default(),
            vsync_d: Default::default(),
            dark_d: Default::default(),
            start_d: Default::default(),
            hsync_q: Default::default(),
            vsync_q: Default::default(),
            start_q: Default::default(),
            rgb_q: Default::default(),
        })
    }
}

impl Logic for VgaDisplay {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, hsync_d, vsync_d, dark_d, start_d, hsync_q, vsync_q, start_q, rgb_q
        );
        self.timing.clock.next = self.clock.val();
        self.timing.reset.next = self.reset.val();
        self.fb_addr.next = self.timing.fb_addr.val();

        self.hsync_d.d.next = self.timing.hsync.val();
        self.vsync_d.d.next = self.timing.vsync.val();
        self.dark_d.d.next = self.timing.blank.val() | self.timing.border.val();
        self.start_d.d.next = self.timing.frame_start.val();

        self.hsync_q.d.next = self.hsync_d.q.val();
        self.vsync_q.d.next = self.vsync_d.q.val();
        self.start_q.d.next = self.start_d.q.val();
        if self.dark_d.q.val() {
            self.rgb_q.d.next = 0.into();
        } else {
            self.rgb_q.d.next = self.fb_data.val().get_bits::<24>(0);
        }

        self.hsync.next = self.hsync_q.q.val();
        self.vsync.next = self.vsync_q.q.val();
        self.frame_start.next = self.start_q.q.val();
        self.rgb.next = self.rgb_q.q.val();
    }
}
