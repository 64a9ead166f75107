//! Tests of the VGA timing generator's generated Verilog in Icarus and Verilator. The checker
//! works from the recorded outputs and the mode's numbers only: it finds lines from the hsync
//! pulses, not from the generator's `x`/`y`.

use super::*;
use crate::hw::vga::{VgaError, VgaPlacement, VgaTiming};

/// What the checker measured.
#[derive(Debug, Default)]
struct Measured {
    hsync_pulses: usize,
    vsync_pulses: usize,
    frames: usize,
    image_pixels_per_frame: Vec<u64>,
}

/// Checks `s` against `mode` and the expected image placement `p` of a `fbw x fbh` frame
/// buffer at `base`. The first sample must be pixel (0, 0) of a frame.
fn check(
    mode: &VgaMode,
    p: VgaPlacement,
    (fbw, fbh, base): (u32, u32, u32),
    s: &[VgaSample],
) -> Result<Measured, String> {
    let ht = (mode.h_visible + mode.h_front + mode.h_sync + mode.h_back) as usize;
    let vt = (mode.v_visible + mode.v_front + mode.v_sync + mode.v_back) as usize;
    let hs_active: Vec<bool> = s.iter().map(|x| x.hsync != mode.hsync_negative).collect();
    let vs_active: Vec<bool> = s.iter().map(|x| x.vsync != mode.vsync_negative).collect();
    let mut m = Measured::default();

    // Pulse starts and widths of complete pulses.
    let pulses = |a: &[bool]| -> (Vec<usize>, Vec<usize>) {
        let starts: Vec<usize> = (1..a.len()).filter(|&i| a[i] && !a[i - 1]).collect();
        let widths = starts
            .iter()
            .filter_map(|&st| (st..a.len()).find(|&i| !a[i]).map(|end| end - st))
            .collect();
        (starts, widths)
    };
    let (hs, hw) = pulses(&hs_active);
    if hs.len() < 2 {
        return Err(format!("only {} hsync pulses", hs.len()));
    }
    for w in hs.windows(2) {
        if w[1] - w[0] != ht {
            return Err(format!(
                "hsync period {} at clock {}, want {ht}",
                w[1] - w[0],
                w[0]
            ));
        }
    }
    if let Some(w) = hw.iter().find(|&&w| w != mode.h_sync as usize) {
        return Err(format!("hsync pulse of {w} clocks, want {}", mode.h_sync));
    }
    m.hsync_pulses = hs.len();

    // Lines start h_back clocks after an hsync pulse ends; the first sample is a line start.
    let phase = (hs[0] + (mode.h_sync + mode.h_back) as usize) % ht;
    if phase != 0 {
        return Err(format!(
            "the first sample is clock {phase} of its line (hsync starts at clock {})",
            hs[0]
        ));
    }
    let lines = s.len() / ht;
    // Per complete line: visible clocks must be exactly 0..h_visible or none.
    let mut line_visible = Vec::new();
    for l in 0..lines {
        let vis: Vec<usize> = (0..ht).filter(|&o| !s[l * ht + o].blank).collect();
        let full =
            vis.len() == mode.h_visible as usize && vis.iter().enumerate().all(|(i, &o)| i == o);
        if !vis.is_empty() && !full {
            return Err(format!(
                "line {l}: {} visible clocks, first {:?}, want {} from the line start",
                vis.len(),
                vis.first(),
                mode.h_visible
            ));
        }
        line_visible.push(full);
    }

    // Frames: runs of visible lines.
    let (vs, vw) = pulses(&vs_active);
    if vs.len() < 2 {
        return Err(format!("only {} vsync pulses", vs.len()));
    }
    for w in vs.windows(2) {
        if w[1] - w[0] != ht * vt {
            return Err(format!(
                "vsync period {} clocks, want {}",
                w[1] - w[0],
                ht * vt
            ));
        }
    }
    if let Some(w) = vw.iter().find(|&&w| w != (mode.v_sync as usize) * ht) {
        return Err(format!(
            "vsync pulse of {w} clocks = {} lines, want {} lines",
            *w as f64 / ht as f64,
            mode.v_sync
        ));
    }
    m.vsync_pulses = vs.len();
    let frame_starts: Vec<usize> = (0..lines)
        .filter(|&l| line_visible[l] && (l == 0 || !line_visible[l - 1]))
        .collect();
    if frame_starts.first() != Some(&0) {
        return Err("the first line is not visible".into());
    }
    for (k, &f) in frame_starts.iter().enumerate() {
        let run = (f..lines).take_while(|&l| line_visible[l]).count();
        let complete = f + run < lines;
        if complete && run != mode.v_visible as usize {
            return Err(format!(
                "frame {k}: {run} visible lines, want {}",
                mode.v_visible
            ));
        }
        if let Some(&next) = frame_starts.get(k + 1) {
            if next - f != vt {
                return Err(format!("frames {} lines apart, want {vt}", next - f));
            }
        }
        // vsync starts v_front lines after the last visible line, at a line start.
        let want_vs = (f + mode.v_visible as usize + mode.v_front as usize) * ht;
        if complete && want_vs < s.len() && !vs.contains(&want_vs) {
            return Err(format!(
                "frame {k}: no vsync start at clock {want_vs} ({} lines after the last visible \
                 line); vsync starts at {vs:?}",
                mode.v_front
            ));
        }
    }
    m.frames = frame_starts.len();

    // Coordinates, frame_start, border and addresses of every complete line.
    for (l, &visible_line) in line_visible.iter().enumerate() {
        let f = *frame_starts.iter().rev().find(|&&f| f <= l).unwrap();
        let y = (l - f) as u32;
        if y as usize >= vt {
            return Err(format!("line {l} is {y} lines into a frame of {vt}"));
        }
        if visible_line && y == 0 {
            m.image_pixels_per_frame.push(0);
        }
        for o in 0..ht {
            let i = l * ht + o;
            let x = o as u32;
            let got = s[i];
            if (got.x, got.y) != (x, y) {
                return Err(format!(
                    "clock {i}: x, y = {}, {}; want {x}, {y}",
                    got.x, got.y
                ));
            }
            if got.frame_start != (x == 0 && y == 0) {
                return Err(format!(
                    "clock {i} ({x}, {y}): frame_start {}",
                    got.frame_start
                ));
            }
            if got.blank {
                continue;
            }
            let inside =
                x >= p.x0 && x < p.x0 + p.scale * fbw && y >= p.y0 && y < p.y0 + p.scale * fbh;
            let want_addr = if inside {
                base + ((y - p.y0) / p.scale) * fbw + (x - p.x0) / p.scale
            } else {
                base
            };
            if got.border == inside || got.fb_addr != want_addr {
                return Err(format!(
                    "pixel ({x}, {y}): border {} fb_addr {:#x}; want border {} fb_addr {want_addr:#x}",
                    got.border, got.fb_addr, !inside
                ));
            }
            if inside {
                *m.image_pixels_per_frame.last_mut().unwrap() += 1;
            }
        }
    }
    Ok(m)
}

/// The spec as a software waveform (for testing the checker itself).
fn model(
    mode: &VgaMode,
    p: VgaPlacement,
    (fbw, _, base): (u32, u32, u32),
    n: usize,
) -> Vec<VgaSample> {
    let (ht, vt) = (mode.h_total(), mode.v_total());
    (0..n as u32)
        .map(|i| {
            let (x, y) = (i % ht, (i / ht) % vt);
            let hs = x >= mode.h_visible + mode.h_front
                && x < mode.h_visible + mode.h_front + mode.h_sync;
            let vs = y >= mode.v_visible + mode.v_front
                && y < mode.v_visible + mode.v_front + mode.v_sync;
            let vis = x < mode.h_visible && y < mode.v_visible;
            let inside = x >= p.x0 && x < p.x0 + p.width && y >= p.y0 && y < p.y0 + p.height;
            VgaSample {
                hsync: hs != mode.hsync_negative,
                vsync: vs != mode.vsync_negative,
                blank: !vis,
                border: vis && !inside,
                frame_start: x == 0 && y == 0,
                x,
                y,
                fb_addr: if inside {
                    base + ((y - p.y0) / p.scale) * fbw + (x - p.x0) / p.scale
                } else {
                    base
                },
            }
        })
        .collect()
}

/// A small mode with positive syncs: 52x39 total.
const SMALL: VgaMode = VgaMode {
    h_visible: 40,
    h_front: 3,
    h_sync: 5,
    h_back: 4,
    v_visible: 30,
    v_front: 2,
    v_sync: 3,
    v_back: 4,
    hsync_negative: false,
    vsync_negative: false,
    pixel_clock_hz: 10_000_000,
};
/// 7x5 in 40x30: scale min(5, 6) = 5, image 35x25 at (2, 2).
const SMALL_FB: (u32, u32, u32) = (7, 5, 0x123);
const SMALL_PLACE: VgaPlacement = VgaPlacement {
    scale: 5,
    x0: 2,
    y0: 2,
    width: 35,
    height: 25,
};

/// Two frames and a bit: enough for two vsync starts and one complete frame.
fn cycles(mode: &VgaMode) -> u64 {
    (2 * mode.v_total() as u64 + 3) * mode.h_total() as u64
}

fn work_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("dynrt-vga-{name}-"))
        .tempdir()
        .unwrap()
}

fn run_and_check(
    mode: &VgaMode,
    p: VgaPlacement,
    fb: (u32, u32, u32),
    sim: Simulator,
) -> Vec<VgaSample> {
    let dir = work_dir(sim.name());
    let n = cycles(mode);
    let s = run_vga_timing(mode, fb.0, fb.1, fb.2, n, sim, dir.path()).unwrap();
    let m = check(mode, p, fb, &s).unwrap_or_else(|e| panic!("{sim}: {e}"));
    println!("{sim}: {m:?}");
    assert!(
        m.frames >= 2
            && m.vsync_pulses >= 2
            && m.hsync_pulses as u64 >= n / mode.h_total() as u64 - 1
    );
    let area = (p.scale * fb.0 * p.scale * fb.1) as u64;
    assert_eq!(m.image_pixels_per_frame[0], area);
    s
}

#[test]
fn placement_is_the_largest_scale_centred() {
    let v = VgaMode::VGA_640X480_60;
    assert_eq!(
        v.fit(64, 48).unwrap(),
        VgaPlacement {
            scale: 10,
            x0: 0,
            y0: 0,
            width: 640,
            height: 480
        }
    );
    assert_eq!(SMALL.fit(7, 5).unwrap(), SMALL_PLACE);
    // 100x60 in 1024x768: min(10, 12) = 10, 1000x600 at (12, 84).
    assert_eq!(
        VgaMode::XGA_1024X768_60.fit(100, 60).unwrap(),
        VgaPlacement {
            scale: 10,
            x0: 12,
            y0: 84,
            width: 1000,
            height: 600
        }
    );
    assert_eq!((v.h_total(), v.v_total()), (800, 525));
    let x = VgaMode::XGA_1024X768_60;
    assert_eq!((x.h_total(), x.v_total()), (1344, 806));
    assert!((v.refresh_hz() - 59.94).abs() < 0.01, "{}", v.refresh_hz());
    assert!((x.refresh_hz() - 60.0).abs() < 0.01, "{}", x.refresh_hz());
}

#[test]
fn bad_frames_and_modes_are_refused() {
    let v = VgaMode::VGA_640X480_60;
    assert!(matches!(
        VgaTiming::new(&v, 641, 10, 0),
        Err(VgaError::FrameTooBig { .. })
    ));
    assert!(matches!(
        VgaTiming::new(&v, 0, 10, 0),
        Err(VgaError::EmptyFrame { .. })
    ));
    assert!(matches!(
        VgaTiming::new(&v, 64, 48, (1 << 24) - 100),
        Err(VgaError::AddressTooWide { .. })
    ));
    let huge = VgaMode { h_back: 4000, ..v };
    assert!(matches!(
        VgaTiming::new(&huge, 64, 48, 0),
        Err(VgaError::BadMode { .. })
    ));
    let msg = VgaTiming::new(&v, 800, 600, 0).err().unwrap().to_string();
    assert!(msg.contains("800x600") && msg.contains("640x480"), "{msg}");
}

#[test]
fn the_checker_accepts_the_spec_and_catches_deviations() {
    let n = cycles(&SMALL) as usize;
    let good = model(&SMALL, SMALL_PLACE, SMALL_FB, n);
    check(&SMALL, SMALL_PLACE, SMALL_FB, &good).unwrap();
    let corrupt = |f: &dyn Fn(&mut Vec<VgaSample>)| {
        let mut s = good.clone();
        f(&mut s);
        check(&SMALL, SMALL_PLACE, SMALL_FB, &s).unwrap_err()
    };
    // hsync one clock too long on line 3 (its first inactive clock after the pulse).
    let e = corrupt(&|s| s[3 * 52 + 48].hsync = !s[3 * 52 + 48].hsync);
    assert!(e.contains("hsync"), "{e}");
    // One extra visible pixel.
    let e = corrupt(&|s| s[5 * 52 + 40].blank = false);
    assert!(e.contains("visible"), "{e}");
    // A wrong address in the image.
    let e = corrupt(&|s| s[10 * 52 + 20].fb_addr += 1);
    assert!(e.contains("fb_addr"), "{e}");
    // vsync a line late.
    let e = corrupt(&|s| {
        for i in 0..52 {
            s[32 * 52 + i].vsync = false;
            s[35 * 52 + i].vsync = true;
        }
    });
    assert!(e.contains("vsync"), "{e}");
    // Centred image expected but shown top-left.
    let top_left = VgaPlacement {
        x0: 0,
        y0: 0,
        ..SMALL_PLACE
    };
    let e = check(&SMALL, top_left, SMALL_FB, &good).unwrap_err();
    assert!(e.contains("pixel"), "{e}");
}

#[test]
fn small_mode_positive_syncs_in_icarus_and_verilator() {
    let a = run_and_check(&SMALL, SMALL_PLACE, SMALL_FB, Simulator::Icarus);
    let b = run_and_check(&SMALL, SMALL_PLACE, SMALL_FB, Simulator::Verilator);
    assert_eq!(a, b);
}

/// 64x48 at 640x480: scale 10, the image fills the screen.
fn vga_64x48(sim: Simulator) {
    let base = 0x40;
    let p = VgaPlacement {
        scale: 10,
        x0: 0,
        y0: 0,
        width: 640,
        height: 480,
    };
    let s = run_and_check(&VgaMode::VGA_640X480_60, p, (64, 48, base), sim);
    // The address sequence of lines 0, 9, 10 and 479 spelled out: each word 10 times.
    let line = |y: usize| -> Vec<u32> {
        s[y * 800..y * 800 + 640]
            .iter()
            .map(|x| x.fb_addr)
            .collect()
    };
    let row = |r: u32| -> Vec<u32> {
        (0..64)
            .flat_map(|c| std::iter::repeat_n(base + r * 64 + c, 10))
            .collect()
    };
    assert_eq!(line(0), row(0));
    assert_eq!(line(9), row(0));
    assert_eq!(line(10), row(1));
    assert_eq!(line(479), row(47));
    assert!(s[..640].iter().all(|x| !x.border && !x.blank));
}

/// The whole 640x480 frame (420k clocks) in Verilator; Icarus runs the same Verilog on the
/// small mode above.
#[test]
fn vga_640x480_64x48_in_verilator() {
    vga_64x48(Simulator::Verilator);
}

#[test]
fn xga_1024x768_centred_100x60_in_verilator() {
    let p = VgaPlacement {
        scale: 10,
        x0: 12,
        y0: 84,
        width: 1000,
        height: 600,
    };
    let s = run_and_check(
        &VgaMode::XGA_1024X768_60,
        p,
        (100, 60, 0),
        Simulator::Verilator,
    );
    // Line 84 is the first image line: border for 12 pixels, then words 0.. each 10 times.
    let l = &s[84 * 1344..84 * 1344 + 1024];
    assert!(l[..12].iter().all(|x| x.border) && l[1012..].iter().all(|x| x.border));
    assert_eq!(l[12].fb_addr, 0);
    assert_eq!(l[22].fb_addr, 1);
    assert_eq!(l[1011].fb_addr, 99);
    assert!(s[83 * 1344..83 * 1344 + 1024].iter().all(|x| x.border));
}

#[test]
fn verilog_lints_clean_apart_from_rust_hdl_widths() {
    let dir = work_dir("lint");
    let path = dir.path().join("vga_timing.v");
    let v = vga_timing_verilog(&VgaMode::VGA_640X480_60, 64, 48, 0, "vga_timing").unwrap();
    std::fs::write(&path, &v).unwrap();
    let report = crate::sim::lint(&[path], "vga_timing").unwrap();
    println!("{v}\n{report}");
    // rust-hdl writes 32-bit literals (WIDTH) and one module per register in one file
    // (DECLFILENAME); with the image at x0 = y0 = 0 the comparisons `h >= 0` are constant
    // (UNSIGNED, folded away). Anything else is a real problem.
    let other: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| !["WIDTH", "DECLFILENAME", "UNSIGNED"].contains(&w.code.as_str()))
        .collect();
    assert!(other.is_empty(), "{report}");
    assert!(v.contains("module vga_timing(") && v.contains("output reg  [23:0] fb_addr"));
}
