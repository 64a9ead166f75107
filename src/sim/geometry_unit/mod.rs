//! Runs the generated geometry units (`crate::emit::geometry_unit`) in Icarus or Verilator on
//! lists of requests, through the streaming testbench of `crate::emit::stream_bench`: one
//! simulator build per call, every request streamed through it, the results read back in the
//! order the unit produced them.
//!
//! The bit-exactness tests (in `tests.rs` beside this file) compare these results with the
//! golden twins in [`crate::units`].

use std::path::Path;

use anyhow::{bail, Result};

use super::stream_bench::run_stream_bench;
use super::Simulator;
use crate::emit::geometry_unit::{geometry_unit_rtl, GeometryUnit};
use crate::emit::stream_bench::{InputStream, OutputSink, StreamBench};
use crate::fp::Format;
use crate::hw::TRANSFORM_CLIENTS;

/// Results of one simulated run, in output order, with the tool times.
#[derive(Debug, Clone)]
pub struct GeometryRun<R> {
    pub results: R,
    pub compile_seconds: f64,
    pub run_seconds: f64,
}

/// A request to the transformation unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TransformRequest {
    /// Row-major 3x4 matrix.
    pub m: [u32; 12],
    pub v: [u32; 3],
    pub point: bool,
    /// A diagonal pass (`TransformUnit::diagonal`; the standalone unit only).
    pub diagonal: bool,
    /// Travels with the request (the standalone unit's 16-bit tag; the shared unit's thread id,
    /// 8 bits).
    pub tag: u16,
}

/// A result of the transformation unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TransformResult {
    pub r: [u32; 3],
    pub tag: u16,
    /// The requesting client (shared unit only; 0 for the standalone unit).
    pub client: u8,
}

/// A request to the intersection unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IntersectRequest {
    pub o: [u32; 3],
    pub d: [u32; 3],
    pub t_min: u32,
    pub t_max: u32,
    pub tag: u16,
}

/// A result of the intersection unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IntersectResult {
    pub t: u32,
    pub u: u32,
    pub v: u32,
    pub hit: bool,
    pub tag: u16,
}

/// One frame for the ray generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RayGenFrame {
    pub width: u16,
    pub height: u16,
    /// `FrameMap::CAMERA` words.
    pub camera: [u32; 12],
    /// `FrameMap::EYE` words.
    pub eye: [u32; 3],
}

/// What the ray generator produced: the pixel each thread was given, in issue order, and the
/// primary rays in output order.
#[derive(Debug, Clone, Default)]
pub struct RayGenOutput {
    /// (x, y, thread)
    pub issued: Vec<(u16, u16, u8)>,
    /// (thread, direction, origin)
    pub rays: Vec<(u8, [u32; 3], [u32; 3])>,
}

fn xyz(prefix: &str) -> Vec<String> {
    ["x", "y", "z"].map(|c| format!("{prefix}{c}")).to_vec()
}

fn max_cycles(transfers: usize, gaps: u64) -> u64 {
    transfers as u64 * 2 + gaps + 1000
}

/// Streams `requests` (each after `gaps[i]` idle clocks; no gaps if `gaps` is empty) through the
/// standalone transformation unit of `fmt`.
pub fn run_transform(
    fmt: Format,
    requests: &[TransformRequest],
    gaps: &[u32],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<GeometryRun<Vec<TransformResult>>> {
    if !gaps.is_empty() && gaps.len() != requests.len() {
        bail!("{} gaps for {} requests", gaps.len(), requests.len());
    }
    let rtl = geometry_unit_rtl(GeometryUnit::Transform, fmt)?;
    let mut fields: Vec<String> = (0..12).map(|k| format!("m_{k}")).collect();
    fields.extend(["x", "y", "z", "point", "diagonal", "tag"].map(String::from));
    let lines = requests
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let mut v: Vec<u64> = r.m.iter().chain(&r.v).map(|&w| u64::from(w)).collect();
            v.push(u64::from(r.point));
            v.push(u64::from(r.diagonal));
            v.push(u64::from(r.tag));
            (gaps.get(i).copied().unwrap_or(0), v)
        })
        .collect();
    let mut out_fields = xyz("r_");
    out_fields.push("out_tag".into());
    let bench = StreamBench {
        dut: rtl.top.clone(),
        ports: rtl.ports.clone(),
        streams: vec![InputStream {
            name: "requests".into(),
            fields,
            valid: Some("in_valid".into()),
            ready: None,
            lines,
        }],
        sinks: vec![OutputSink {
            name: "results".into(),
            valid: "out_valid".into(),
            fields: out_fields,
            expected: requests.len(),
        }],
        max_cycles: max_cycles(requests.len(), gaps.iter().map(|&g| u64::from(g)).sum()),
    };
    let run = run_stream_bench(&bench, &rtl.verilog, simulator, work_dir)?;
    let results = run.sinks[0]
        .iter()
        .map(|r| TransformResult {
            r: [r[0] as u32, r[1] as u32, r[2] as u32],
            tag: r[3] as u16,
            client: 0,
        })
        .collect();
    Ok(GeometryRun {
        results,
        compile_seconds: run.compile_seconds,
        run_seconds: run.run_seconds,
    })
}

/// Streams each client's requests (`(gap, request)`, the tag being the 8-bit thread id) into
/// the shared transformation unit of `fmt`, all clients at once, each presenting its next
/// request after its gap and holding it until the arbiter takes it.
pub fn run_shared_transform(
    fmt: Format,
    clients: &[Vec<(u32, TransformRequest)>; TRANSFORM_CLIENTS],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<GeometryRun<Vec<TransformResult>>> {
    let rtl = geometry_unit_rtl(GeometryUnit::SharedTransform, fmt)?;
    let mut streams = Vec::new();
    let mut total = 0;
    let mut gaps = 0u64;
    for (c, reqs) in clients.iter().enumerate() {
        let mut fields: Vec<String> = (0..12).map(|k| format!("c{c}_m_{k}")).collect();
        fields.extend(xyz(&format!("c{c}_")));
        fields.push(format!("c{c}_point"));
        fields.push(format!("c{c}_thread"));
        let mut lines = Vec::new();
        for &(gap, r) in reqs {
            if r.tag > 0xff {
                bail!("client {c}: thread id {} does not fit 8 bits", r.tag);
            }
            let mut v: Vec<u64> = r.m.iter().chain(&r.v).map(|&w| u64::from(w)).collect();
            v.push(u64::from(r.point));
            v.push(u64::from(r.tag));
            lines.push((gap, v));
            gaps += u64::from(gap);
        }
        total += reqs.len();
        streams.push(InputStream {
            name: format!("client{c}"),
            fields,
            valid: Some(format!("c{c}_valid")),
            ready: Some(format!("c{c}_ready")),
            lines,
        });
    }
    let mut out_fields = xyz("r_");
    out_fields.extend(["out_thread", "out_client"].map(String::from));
    let bench = StreamBench {
        dut: rtl.top.clone(),
        ports: rtl.ports.clone(),
        streams,
        sinks: vec![OutputSink {
            name: "results".into(),
            valid: "out_valid".into(),
            fields: out_fields,
            expected: total,
        }],
        max_cycles: max_cycles(total, gaps),
    };
    let run = run_stream_bench(&bench, &rtl.verilog, simulator, work_dir)?;
    let results = run.sinks[0]
        .iter()
        .map(|r| TransformResult {
            r: [r[0] as u32, r[1] as u32, r[2] as u32],
            tag: r[3] as u16,
            client: r[4] as u8,
        })
        .collect();
    Ok(GeometryRun {
        results,
        compile_seconds: run.compile_seconds,
        run_seconds: run.run_seconds,
    })
}

/// Streams `requests`, one per clock, through the intersection unit of `fmt`.
pub fn run_intersect(
    fmt: Format,
    requests: &[IntersectRequest],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<GeometryRun<Vec<IntersectResult>>> {
    let rtl = geometry_unit_rtl(GeometryUnit::Intersect, fmt)?;
    let mut fields = xyz("o_");
    fields.extend(xyz("d_"));
    fields.extend(["t_min", "t_max", "tag"].map(String::from));
    let lines = requests
        .iter()
        .map(|r| {
            let mut v: Vec<u64> = r.o.iter().chain(&r.d).map(|&w| u64::from(w)).collect();
            v.extend([r.t_min, r.t_max].map(u64::from));
            v.push(u64::from(r.tag));
            (0, v)
        })
        .collect();
    let bench = StreamBench {
        dut: rtl.top.clone(),
        ports: rtl.ports.clone(),
        streams: vec![InputStream {
            name: "requests".into(),
            fields,
            valid: Some("in_valid".into()),
            ready: None,
            lines,
        }],
        sinks: vec![OutputSink {
            name: "results".into(),
            valid: "out_valid".into(),
            fields: ["t", "u", "v", "hit", "out_tag"].map(String::from).to_vec(),
            expected: requests.len(),
        }],
        max_cycles: max_cycles(requests.len(), 0),
    };
    let run = run_stream_bench(&bench, &rtl.verilog, simulator, work_dir)?;
    let results = run.sinks[0]
        .iter()
        .map(|r| IntersectResult {
            t: r[0] as u32,
            u: r[1] as u32,
            v: r[2] as u32,
            hit: r[3] != 0,
            tag: r[4] as u16,
        })
        .collect();
    Ok(GeometryRun {
        results,
        compile_seconds: run.compile_seconds,
        run_seconds: run.run_seconds,
    })
}

/// Runs the ray generator of `fmt` over `frames`, one after the other. Free threads offer
/// themselves in a stream: offer `i` has thread id `i % 32` and comes `thread_gaps[i]` clocks
/// (0 if the list is shorter) after the previous offer was taken.
pub fn run_raygen(
    fmt: Format,
    frames: &[RayGenFrame],
    thread_gaps: &[u32],
    simulator: Simulator,
    work_dir: &Path,
) -> Result<GeometryRun<RayGenOutput>> {
    let rtl = geometry_unit_rtl(GeometryUnit::RayGen, fmt)?;
    let pixels: usize = frames
        .iter()
        .map(|f| usize::from(f.width) * usize::from(f.height))
        .sum();
    let gap = |i: usize| u64::from(thread_gaps.get(i).copied().unwrap_or(0));
    let mut control_fields: Vec<String> = ["start", "width", "height"].map(String::from).to_vec();
    control_fields.extend((0..12).map(|k| format!("camera_{k}")));
    control_fields.extend(xyz("eye_"));
    let mut control = Vec::new();
    let mut offer = 0;
    let mut previous_frame_clocks = 0u64;
    for f in frames {
        let mut words = vec![1, u64::from(f.width), u64::from(f.height)];
        words.extend(f.camera.iter().chain(&f.eye).map(|&w| u64::from(w)));
        // The next frame starts once the previous one has issued every pixel and its last
        // ray has left the pipeline.
        let wait = if previous_frame_clocks == 0 {
            0
        } else {
            previous_frame_clocks + 64
        };
        control.push((wait as u32, words.clone()));
        words[0] = 0;
        control.push((0, words));
        let n = usize::from(f.width) * usize::from(f.height);
        previous_frame_clocks = (offer..offer + n).map(|i| gap(i) + 1).sum();
        offer += n;
    }
    let threads = (0..pixels)
        .map(|i| (gap(i) as u32, vec![(i % 32) as u64]))
        .collect();
    let mut ray_fields = vec!["out_thread".to_string()];
    ray_fields.extend(xyz("dir_"));
    ray_fields.extend(xyz("origin_"));
    let total_gaps: u64 = (0..pixels).map(gap).sum();
    let bench = StreamBench {
        dut: rtl.top.clone(),
        ports: rtl.ports.clone(),
        streams: vec![
            InputStream {
                name: "control".into(),
                fields: control_fields,
                valid: None,
                ready: None,
                lines: control,
            },
            InputStream {
                name: "threads".into(),
                fields: vec!["thread_id".into()],
                valid: Some("thread_valid".into()),
                ready: Some("thread_ready".into()),
                lines: threads,
            },
        ],
        sinks: vec![
            OutputSink {
                name: "issued".into(),
                valid: "issued_valid".into(),
                fields: ["issued_x", "issued_y", "issued_thread"]
                    .map(String::from)
                    .to_vec(),
                expected: pixels,
            },
            OutputSink {
                name: "rays".into(),
                valid: "out_valid".into(),
                fields: ray_fields,
                expected: pixels,
            },
        ],
        max_cycles: max_cycles(pixels, 2 * total_gaps + 100 * frames.len() as u64),
    };
    let run = run_stream_bench(&bench, &rtl.verilog, simulator, work_dir)?;
    let issued = run.sinks[0]
        .iter()
        .map(|r| (r[0] as u16, r[1] as u16, r[2] as u8))
        .collect();
    let rays = run.sinks[1]
        .iter()
        .map(|r| {
            (
                r[0] as u8,
                [r[1] as u32, r[2] as u32, r[3] as u32],
                [r[4] as u32, r[5] as u32, r[6] as u32],
            )
        })
        .collect();
    Ok(GeometryRun {
        results: RayGenOutput { issued, rays },
        compile_seconds: run.compile_seconds,
        run_seconds: run.run_seconds,
    })
}

#[cfg(test)]
mod tests;
