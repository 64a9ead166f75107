//! VGA timing: [`VgaTiming`] counts the pixels of a [`VgaMode`] in the display's own pixel
//! clock and tells the display path, for every clock, the sync levels, whether the pixel is
//! visible, and which frame-buffer word to show there.
//!
//! Contract (all outputs are registers, and all describe the same pixel in the same clock):
//! - `clock`: the pixel clock (25.175 MHz for [`VgaMode::VGA_640X480_60`], 65 MHz for
//!   [`VgaMode::XGA_1024X768_60`]); the board's VGA DAC is clocked by the same clock.
//! - `reset`: synchronous, active high. While it is 1 the counters hold pixel (0, 0); one clock
//!   after it falls the outputs describe pixel (0, 0) (the first visible pixel of a frame).
//! - Each line is `h_visible` visible pixels, then `h_front`, `h_sync` (sync pulse),
//!   `h_back` clocks; each frame is `v_visible` visible lines, then `v_front`, `v_sync`,
//!   `v_back` lines. vsync changes at the start of a line (with the line's first pixel).
//! - `hsync`, `vsync`: the sync levels to drive to the connector, polarity applied
//!   (`hsync_negative`: the pulse is 0, idle 1).
//! - `blank`: **active high**: 1 outside the visible area (porches and sync), where the DAC
//!   must output black.
//! - `x`, `y`: the pixel's position, `0..h_total` and `0..v_total`; it is a visible pixel
//!   when `x < h_visible` and `y < v_visible` (exactly when `blank` is 0).
//! - `fb_addr`, `border`: the frame buffer holds `fb_width x fb_height` words, row-major, row
//!   0 at the top, starting at `fb_base` (for example `LayoutInfo::frame_buffer` in bank
//!   `FRAME`). It is shown magnified by integer pixel replication,
//!   `scale = min(h_visible / fb_width, v_visible / fb_height)`, **centred** in the visible
//!   area (offsets `(h_visible - scale * fb_width) / 2` and the same vertically, rounded
//!   down; see [`VgaMode::fit`]). On a visible pixel inside the image `border` is 0 and
//!   `fb_addr = fb_base + (row * fb_width + column)` of the image pixel shown there; on a
//!   visible pixel outside the image `border` is 1 (show black). `fb_addr` is always a legal
//!   frame-buffer address (`fb_base` when `border` or `blank` is 1), so it can drive a memory
//!   directly.
//! - `frame_start`: 1 in the clock of pixel (0, 0): a safe point to swap frame buffers.
//!
//! No division: the replication is counted (`hrep`, `vrep` run 0..scale-1, then the image
//! column or row advances), and the row's base address is kept by adding `fb_width` per row.
//!
//! Latency: the frame-buffer word for `fb_addr` arrives after the memory's read latency `L`;
//! the display path must delay `hsync`, `vsync`, `blank` and `border` by the same `L` clocks
//! (e.g. with `crate::hw::Delay`) so that colour and syncs line up. Throughput: one pixel per
//! clock.
//!
//! Golden twin: none that computes words; the placement is [`VgaMode::fit`], and the timing
//! spec above is checked against the generated Verilog by the recording testbench's checker
//! in src/sim/vga_timing/tests.rs.
//!
//! Size (yosys 0.23 `synth_xilinx -family xc2v -flatten`, 640x480 showing 64x48): 132
//! flip-flops, 160 LUTs, 119 MUXCY + 102 XORCY carry cells, no multiplier. Counters are 12
//! bits wide, so `h_total` and `v_total` must be below 4096; addresses are
//! [`VGA_ADDR_BITS`] wide.

use rust_hdl::prelude::*;

/// Width of the `x`, `y` outputs and of every counter.
pub const VGA_COORD_BITS: usize = 12;
/// Width of `fb_addr`: word addresses of a bank of up to 64 MB.
pub const VGA_ADDR_BITS: usize = 24;

/// A video mode: the pixel counts of one line and the line counts of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VgaMode {
    pub h_visible: u32,
    pub h_front: u32,
    pub h_sync: u32,
    pub h_back: u32,
    pub v_visible: u32,
    pub v_front: u32,
    pub v_sync: u32,
    pub v_back: u32,
    /// The sync pulses are low (idle high).
    pub hsync_negative: bool,
    pub vsync_negative: bool,
    pub pixel_clock_hz: u64,
}

/// Where a frame buffer sits on the screen (see [`VgaMode::fit`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VgaPlacement {
    /// Each frame-buffer pixel becomes `scale x scale` screen pixels.
    pub scale: u32,
    /// Screen position of the image's top-left pixel.
    pub x0: u32,
    pub y0: u32,
    /// The image's size on the screen (`scale * fb_width`, `scale * fb_height`).
    pub width: u32,
    pub height: u32,
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum VgaError {
    #[error(
        "frame buffer {fb_width}x{fb_height} does not fit the {h_visible}x{v_visible} visible \
         area of the VGA mode: render at most {h_visible}x{v_visible} pixels or choose a \
         larger mode"
    )]
    FrameTooBig {
        fb_width: u32,
        fb_height: u32,
        h_visible: u32,
        v_visible: u32,
    },
    #[error("frame buffer of {fb_width}x{fb_height} pixels: both sizes must be at least 1")]
    EmptyFrame { fb_width: u32, fb_height: u32 },
    #[error(
        "VGA mode {h_total}x{v_total} (total pixels x lines) is too large for the 12-bit \
         counters (at most 4095) or has an empty visible area or sync pulse"
    )]
    BadMode { h_total: u32, v_total: u32 },
    #[error(
        "frame buffer at word {fb_base} with {words} words does not fit {VGA_ADDR_BITS}-bit \
         addresses"
    )]
    AddressTooWide { fb_base: u32, words: u64 },
}

impl VgaMode {
    /// VESA 640x480 at 60 Hz: 800x525 total, 25.175 MHz, both syncs negative.
    pub const VGA_640X480_60: VgaMode = VgaMode {
        h_visible: 640,
        h_front: 16,
        h_sync: 96,
        h_back: 48,
        v_visible: 480,
        v_front: 10,
        v_sync: 2,
        v_back: 33,
        hsync_negative: true,
        vsync_negative: true,
        pixel_clock_hz: 25_175_000,
    };

    /// VESA 1024x768 at 60 Hz: 1344x806 total, 65 MHz, both syncs negative.
    pub const XGA_1024X768_60: VgaMode = VgaMode {
        h_visible: 1024,
        h_front: 24,
        h_sync: 136,
        h_back: 160,
        v_visible: 768,
        v_front: 3,
        v_sync: 6,
        v_back: 29,
        hsync_negative: true,
        vsync_negative: true,
        pixel_clock_hz: 65_000_000,
    };

    pub fn h_total(&self) -> u32 {
        self.h_visible + self.h_front + self.h_sync + self.h_back
    }
    pub fn v_total(&self) -> u32 {
        self.v_visible + self.v_front + self.v_sync + self.v_back
    }
    /// Frames per second at the mode's pixel clock.
    pub fn refresh_hz(&self) -> f64 {
        self.pixel_clock_hz as f64 / (self.h_total() as f64 * self.v_total() as f64)
    }

    fn check(&self) -> Result<(), VgaError> {
        let limit = 1u32 << VGA_COORD_BITS;
        let (h, v) = (self.h_total(), self.v_total());
        if h >= limit
            || v >= limit
            || self.h_visible == 0
            || self.v_visible == 0
            || self.h_sync == 0
            || self.v_sync == 0
            // The last pixel of a line and the last line must be blank: the counters restart
            // the replication there.
            || h == self.h_visible
            || v == self.v_visible
        {
            return Err(VgaError::BadMode {
                h_total: h,
                v_total: v,
            });
        }
        Ok(())
    }

    /// The placement of a `fb_width x fb_height` frame buffer: the largest integer scale that
    /// fits, centred (offsets rounded down).
    pub fn fit(&self, fb_width: u32, fb_height: u32) -> Result<VgaPlacement, VgaError> {
        if fb_width == 0 || fb_height == 0 {
            return Err(VgaError::EmptyFrame {
                fb_width,
                fb_height,
            });
        }
        let scale = (self.h_visible / fb_width).min(self.v_visible / fb_height);
        if scale == 0 {
            return Err(VgaError::FrameTooBig {
                fb_width,
                fb_height,
                h_visible: self.h_visible,
                v_visible: self.v_visible,
            });
        }
        let (width, height) = (scale * fb_width, scale * fb_height);
        Ok(VgaPlacement {
            scale,
            x0: (self.h_visible - width) / 2,
            y0: (self.v_visible - height) / 2,
            width,
            height,
        })
    }
}

/// The VGA timing generator (see the module doc for its ports).
#[derive(LogicBlock)]
pub struct VgaTiming {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, Bit>,
    pub hsync: Signal<Out, Bit>,
    pub vsync: Signal<Out, Bit>,
    pub blank: Signal<Out, Bit>,
    pub border: Signal<Out, Bit>,
    pub x: Signal<Out, Bits<VGA_COORD_BITS>>,
    pub y: Signal<Out, Bits<VGA_COORD_BITS>>,
    pub fb_addr: Signal<Out, Bits<VGA_ADDR_BITS>>,
    pub frame_start: Signal<Out, Bit>,
    // Counter stage: the current pixel.
    h: DFF<Bits<VGA_COORD_BITS>>,
    v: DFF<Bits<VGA_COORD_BITS>>,
    col: DFF<Bits<VGA_COORD_BITS>>,
    hrep: DFF<Bits<VGA_COORD_BITS>>,
    vrep: DFF<Bits<VGA_COORD_BITS>>,
    row_base: DFF<Bits<VGA_ADDR_BITS>>,
    // Output stage.
    hsync_q: DFF<Bit>,
    vsync_q: DFF<Bit>,
    blank_q: DFF<Bit>,
    border_q: DFF<Bit>,
    start_q: DFF<Bit>,
    x_q: DFF<Bits<VGA_COORD_BITS>>,
    y_q: DFF<Bits<VGA_COORD_BITS>>,
    addr_q: DFF<Bits<VGA_ADDR_BITS>>,
    // Mode and placement, fixed at construction (Verilog localparams).
    c_h_last: Constant<Bits<VGA_COORD_BITS>>,
    c_v_last: Constant<Bits<VGA_COORD_BITS>>,
    c_h_visible: Constant<Bits<VGA_COORD_BITS>>,
    c_v_visible: Constant<Bits<VGA_COORD_BITS>>,
    c_hs_start: Constant<Bits<VGA_COORD_BITS>>,
    c_hs_end: Constant<Bits<VGA_COORD_BITS>>,
    c_vs_start: Constant<Bits<VGA_COORD_BITS>>,
    c_vs_end: Constant<Bits<VGA_COORD_BITS>>,
    c_x0: Constant<Bits<VGA_COORD_BITS>>,
    c_x1: Constant<Bits<VGA_COORD_BITS>>,
    c_y0: Constant<Bits<VGA_COORD_BITS>>,
    c_y1: Constant<Bits<VGA_COORD_BITS>>,
    c_rep_last: Constant<Bits<VGA_COORD_BITS>>,
    c_fb_width: Constant<Bits<VGA_ADDR_BITS>>,
    c_fb_base: Constant<Bits<VGA_ADDR_BITS>>,
    c_hs_negative: Constant<Bit>,
    c_vs_negative: Constant<Bit>,
    // Combinational values of the current pixel.
    line_end: Signal<Local, Bit>,
    in_x: Signal<Local, Bit>,
    in_y: Signal<Local, Bit>,
    visible: Signal<Local, Bit>,
    hs_active: Signal<Local, Bit>,
    vs_active: Signal<Local, Bit>,
}

fn coord(v: u32) -> Constant<Bits<VGA_COORD_BITS>> {
    Constant::new(Bits::from(v as u64))
}

fn addr(v: u64) -> Constant<Bits<VGA_ADDR_BITS>> {
    Constant::new(Bits::from(v))
}

impl VgaTiming {
    /// The generator for `mode` showing a `fb_width x fb_height` frame buffer that starts at
    /// word `fb_base`.
    pub fn new(
        mode: &VgaMode,
        fb_width: u32,
        fb_height: u32,
        fb_base: u32,
    ) -> Result<VgaTiming, VgaError> {
        mode.check()?;
        let p = mode.fit(fb_width, fb_height)?;
        let words = fb_width as u64 * fb_height as u64;
        if fb_base as u64 + words > 1 << VGA_ADDR_BITS {
            return Err(VgaError::AddressTooWide { fb_base, words });
        }
        let hs_start = mode.h_visible + mode.h_front;
        let vs_start = mode.v_visible + mode.v_front;
        Ok(VgaTiming {
            clock: Default::default(),
            reset: Default::default(),
            hsync: Default::default(),
            vsync: Default::default(),
            blank: Default::default(),
            border: Default::default(),
            x: Default::default(),
            y: Default::default(),
            fb_addr: Default::default(),
            frame_start: Default::default(),
            h: Default::default(),
            v: Default::default(),
            col: Default::default(),
            hrep: Default::default(),
            vrep: Default::default(),
            row_base: Default::default(),
            hsync_q: Default::default(),
            vsync_q: Default::default(),
            blank_q: Default::default(),
            border_q: Default::default(),
            start_q: Default::default(),
            x_q: Default::default(),
            y_q: Default::default(),
            addr_q: Default::default(),
            c_h_last: coord(mode.h_total() - 1),
            c_v_last: coord(mode.v_total() - 1),
            c_h_visible: coord(mode.h_visible),
            c_v_visible: coord(mode.v_visible),
            c_hs_start: coord(hs_start),
            c_hs_end: coord(hs_start + mode.h_sync),
            c_vs_start: coord(vs_start),
            c_vs_end: coord(vs_start + mode.v_sync),
            c_x0: coord(p.x0),
            c_x1: coord(p.x0 + p.width),
            c_y0: coord(p.y0),
            c_y1: coord(p.y0 + p.height),
            c_rep_last: coord(p.scale - 1),
            c_fb_width: addr(fb_width as u64),
            c_fb_base: addr(fb_base as u64),
            c_hs_negative: Constant::new(mode.hsync_negative),
            c_vs_negative: Constant::new(mode.vsync_negative),
            line_end: Default::default(),
            in_x: Default::default(),
            in_y: Default::default(),
            visible: Default::default(),
            hs_active: Default::default(),
            vs_active: Default::default(),
        })
    }
}

impl Logic for VgaTiming {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, h, v, col, hrep, vrep, row_base, hsync_q, vsync_q, blank_q, border_q,
            start_q, x_q, y_q, addr_q
        );
        // The current pixel (counter stage).
        self.line_end.next = self.h.q.val() == self.c_h_last.val();
        self.in_x.next = (self.h.q.val() >= self.c_x0.val()) & (self.h.q.val() < self.c_x1.val());
        self.in_y.next = (self.v.q.val() >= self.c_y0.val()) & (self.v.q.val() < self.c_y1.val());
        self.visible.next =
            (self.h.q.val() < self.c_h_visible.val()) & (self.v.q.val() < self.c_v_visible.val());
        self.hs_active.next =
            (self.h.q.val() >= self.c_hs_start.val()) & (self.h.q.val() < self.c_hs_end.val());
        self.vs_active.next =
            (self.v.q.val() >= self.c_vs_start.val()) & (self.v.q.val() < self.c_vs_end.val());

        // Output stage: registered description of the current pixel.
        self.hsync_q.d.next = self.hs_active.val() ^ self.c_hs_negative.val();
        self.vsync_q.d.next = self.vs_active.val() ^ self.c_vs_negative.val();
        self.blank_q.d.next = !self.visible.val();
        self.border_q.d.next = self.visible.val() & !(self.in_x.val() & self.in_y.val());
        self.start_q.d.next = (self.h.q.val() == 0) & (self.v.q.val() == 0);
        self.x_q.d.next = self.h.q.val();
        self.y_q.d.next = self.v.q.val();
        if self.in_x.val() & self.in_y.val() {
            self.addr_q.d.next =
                self.row_base.q.val() + bit_cast::<VGA_ADDR_BITS, VGA_COORD_BITS>(self.col.q.val());
        } else {
            self.addr_q.d.next = self.c_fb_base.val();
        }

        // Next pixel. The image column advances every `scale` pixels inside the image and
        // restarts outside it (the last pixel of a line is always outside); rows likewise
        // once per line.
        if self.line_end.val() {
            self.h.d.next = 0.into();
            if self.v.q.val() == self.c_v_last.val() {
                self.v.d.next = 0.into();
            } else {
                self.v.d.next = self.v.q.val() + 1;
            }
            if self.in_y.val() {
                if self.vrep.q.val() == self.c_rep_last.val() {
                    self.vrep.d.next = 0.into();
                    self.row_base.d.next = self.row_base.q.val() + self.c_fb_width.val();
                } else {
                    self.vrep.d.next = self.vrep.q.val() + 1;
                }
            } else {
                self.vrep.d.next = 0.into();
                self.row_base.d.next = self.c_fb_base.val();
            }
        } else {
            self.h.d.next = self.h.q.val() + 1;
        }
        if self.in_x.val() {
            if self.hrep.q.val() == self.c_rep_last.val() {
                self.hrep.d.next = 0.into();
                self.col.d.next = self.col.q.val() + 1;
            } else {
                self.hrep.d.next = self.hrep.q.val() + 1;
            }
        } else {
            self.hrep.d.next = 0.into();
            self.col.d.next = 0.into();
        }

        if self.reset.val() {
            self.h.d.next = 0.into();
            self.v.d.next = 0.into();
            self.col.d.next = 0.into();
            self.hrep.d.next = 0.into();
            self.vrep.d.next = 0.into();
            self.row_base.d.next = self.c_fb_base.val();
        }

        self.hsync.next = self.hsync_q.q.val();
        self.vsync.next = self.vsync_q.q.val();
        self.blank.next = self.blank_q.q.val();
        self.border.next = self.border_q.q.val();
        self.frame_start.next = self.start_q.q.val();
        self.x.next = self.x_q.q.val();
        self.y.next = self.y_q.q.val();
        self.fb_addr.next = self.addr_q.q.val();
    }
}
