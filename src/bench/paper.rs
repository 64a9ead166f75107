//! `dynrt bench paper`: the suite of `scenes/paper/` beside the paper's Table 3. Per scene:
//! the golden model's frame, the memory map's size against the board's six banks, and, for the
//! scenes that fit, the processor's Verilator run: cycles per pixel, rays per pixel by kind and
//! frames per second at a stated clock, next to the paper's frames per second.
//!
//! A scene that does not fit the banks is measured all the same: its memory map is built
//! against banks large enough to hold it (the golden model reads it from there) and reported
//! with the bytes each bank needs; only the processor's run is left out.

use super::table::Table;
use crate::layout::{self, FrameUpdate, Layout, MemoryConfig, SceneTrees, BANK_NAMES};
use crate::model::{render_golden, Frame};
use crate::scene::paper::{PaperRow, HEIGHT, WIDTH};
use crate::scene::Scene;
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use std::path::Path;

/// The board's memory: six banks of 4 MB.
pub const BOARD: MemoryConfig = MemoryConfig::ADM_XRC_II;

/// Banks large enough for any scene the loader accepts: the golden model's memory for scenes
/// that do not fit the board.
const UNBOUNDED: MemoryConfig = MemoryConfig {
    banks: 6,
    bank_bytes: 1 << 40,
};

/// Rays the golden model traced for a frame, by kind (the processor traces the same rays).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rays {
    pub pixels: u64,
    pub primary: u64,
    pub shadow: u64,
    pub mirror: u64,
}

impl Rays {
    fn of(frame: &Frame) -> Rays {
        let s = &frame.stats;
        Rays {
            pixels: u64::from(frame.width) * u64::from(frame.height),
            primary: s.rays - s.shadow_rays - s.mirror_rays,
            shadow: s.shadow_rays,
            mirror: s.mirror_rays,
        }
    }
    fn per_pixel(&self, n: u64) -> f64 {
        n as f64 / self.pixels.max(1) as f64
    }
}

/// The processor's Verilator run of frame 0.
#[derive(Clone, Debug, PartialEq)]
pub struct SimFigures {
    pub width: u32,
    pub height: u32,
    pub cycles: u64,
    /// The frame's `flow::FrameReport::memory_words`.
    pub memory_words: u64,
    pub differing_pixels: usize,
}

impl SimFigures {
    pub fn cycles_per_pixel(&self) -> f64 {
        self.cycles as f64 / (u64::from(self.width) * u64::from(self.height)) as f64
    }
    pub fn memory_words_per_pixel(&self) -> f64 {
        self.memory_words as f64 / (u64::from(self.width) * u64::from(self.height)) as f64
    }
    /// The memory bandwidth at a clock of `mhz`, in GB/s (the paper: about 2 without caches,
    /// 1 with them, at 90 MHz).
    pub fn memory_gb_per_s_at(&self, mhz: f64) -> f64 {
        4.0 * self.memory_words as f64 / self.cycles.max(1) as f64 * mhz * 1e6 / 1e9
    }
    /// Frames per second at `mhz` of a 512x384 frame at this run's cycles per pixel.
    pub fn fps_at(&self, mhz: f64) -> f64 {
        mhz * 1e6 / (self.cycles_per_pixel() * f64::from(WIDTH * HEIGHT))
    }
}

/// Whether and how the processor ran.
#[derive(Clone, Debug, PartialEq)]
pub enum Sim {
    Ran(SimFigures),
    /// Not simulated, and why.
    NotRun(String),
}

/// One scene of the suite, measured.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperResult {
    pub row: PaperRow,
    pub unique_triangles: usize,
    pub instanced_triangles: usize,
    /// Entries of the top level (the paper's "objects").
    pub objects: usize,
    /// Bytes each bank needs (frame buffer included).
    pub bank_bytes: Vec<usize>,
    /// For an animated scene, the largest of its frame updates (the bytes the host writes to
    /// the banks to turn one frame's memory map into the next one's), measured on the memory
    /// maps of frames 1 to the last; `None` for a static scene.
    pub update: Option<FrameUpdate>,
    pub rays: Rays,
    pub sim: Sim,
}

impl PaperResult {
    /// The banks that the board cannot hold: (name, bytes needed).
    pub fn overfull_banks(&self) -> Vec<(&'static str, usize)> {
        self.bank_bytes
            .iter()
            .enumerate()
            .filter(|(_, &b)| b > BOARD.bank_bytes)
            .map(|(k, &b)| (BANK_NAMES[k], b))
            .collect()
    }
    pub fn fits(&self) -> bool {
        self.overfull_banks().is_empty()
    }
}

/// A scene's frame 0 in the golden model (e7m16) and what its memory map needs.
pub struct Measured {
    pub result: PaperResult,
    pub frame: Frame,
}

/// Builds the trees and the memory map of frame 0 (against banks that hold anything), renders
/// it in the golden model and measures the bank sizes; the processor's run is left to the
/// caller (`result.sim` says "not run yet").
pub fn measure(row: PaperRow, scene: &Scene) -> Result<Measured> {
    let trees = SceneTrees::build(scene, crate::fp::Format::E7M16)
        .with_context(|| format!("{}: building the kd-trees", scene.source.display()))?;
    let l: Layout = layout::build(scene, &trees, 0, &UNBOUNDED)
        .with_context(|| format!("{}: building the memory map", scene.source.display()))?;
    let frame = render_golden(&l, false);
    let mut update: Option<FrameUpdate> = None;
    for f in 1..scene.frames {
        let u = layout::build(scene, &trees, f, &UNBOUNDED)
            .with_context(|| {
                format!(
                    "{}: building the memory map of frame {f}",
                    scene.source.display()
                )
            })?
            .frame_update();
        if update.is_none_or(|largest| u.bytes() > largest.bytes()) {
            update = Some(u);
        }
    }
    Ok(Measured {
        result: PaperResult {
            row,
            unique_triangles: scene.triangle_count(),
            instanced_triangles: scene.instanced_triangle_count(),
            objects: scene.instances.len(),
            bank_bytes: l.used_words().iter().map(|w| w * 4).collect(),
            update,
            rays: Rays::of(&frame),
            sim: Sim::NotRun("not run yet".into()),
        },
        frame,
    })
}

fn mib(bytes: usize) -> String {
    format!("{:.2}", bytes as f64 / (1 << 20) as f64)
}

fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The results as a table, fps at `clock_mhz` beside the paper's (one pipeline at 90 MHz).
pub fn paper_table(results: &[PaperResult], clock_mhz: f64) -> Table {
    let fps_ours = format!("fps at {clock_mhz:.1} MHz (512x384)");
    let bandwidth = format!("memory GB/s at {clock_mhz:.1} MHz");
    let mut t = Table::new(&[
        "scene",
        "paper triangles",
        "triangles (instanced)",
        "unique triangles",
        "objects",
        "memory MiB",
        "fits 6 x 4 MiB",
        "bytes per frame update",
        "rays/pixel primary",
        "rays/pixel shadow",
        "rays/pixel mirror",
        "simulated",
        "cycles/pixel",
        &fps_ours,
        "memory words/pixel",
        &bandwidth,
        "paper fps (90 MHz)",
        "paper / ours",
    ]);
    for r in results {
        let fits = if r.fits() {
            "yes".to_string()
        } else {
            let over: Vec<String> = r
                .overfull_banks()
                .iter()
                .map(|(name, b)| format!("{name} needs {} MiB", mib(*b)))
                .collect();
            format!("no: {}", over.join(", "))
        };
        let (simulated, cpp, fps, words, gbs, ratio) = match &r.sim {
            Sim::Ran(s) => {
                let mut what = format!("{}x{}", s.width, s.height);
                if (s.width, s.height) != (WIDTH, HEIGHT) {
                    what.push_str(" (same view, fps scaled to 512x384)");
                }
                if s.differing_pixels > 0 {
                    what.push_str(&format!(
                        "; {} pixels DIFFER from the golden model",
                        s.differing_pixels
                    ));
                }
                let fps = s.fps_at(clock_mhz);
                (
                    what,
                    format!("{:.1}", s.cycles_per_pixel()),
                    format!("{fps:.3}"),
                    format!("{:.1}", s.memory_words_per_pixel()),
                    format!("{:.3}", s.memory_gb_per_s_at(clock_mhz)),
                    format!("{:.0}", r.row.fps / fps),
                )
            }
            Sim::NotRun(why) => (
                format!("no: {why}"),
                "-".into(),
                "-".into(),
                "-".into(),
                "-".into(),
                "-".into(),
            ),
        };
        t.push(vec![
            r.row.name.to_string(),
            thousands(r.row.triangles),
            thousands(r.instanced_triangles as u64),
            thousands(r.unique_triangles as u64),
            thousands(r.objects as u64),
            mib(r.bank_bytes.iter().sum()),
            fits,
            r.update
                .map_or_else(|| "static".into(), |u| thousands(u.bytes() as u64)),
            format!("{:.2}", r.rays.per_pixel(r.rays.primary)),
            format!("{:.2}", r.rays.per_pixel(r.rays.shadow)),
            format!("{:.2}", r.rays.per_pixel(r.rays.mirror)),
            simulated,
            cpp,
            fps,
            words,
            gbs,
            format!("{:.1}", r.row.fps),
            ratio,
        ]);
    }
    t
}

/// The Markdown report: what was measured and how, then the table.
pub fn paper_markdown(results: &[PaperResult], clock_mhz: f64, clock_source: &str) -> String {
    let banks: Vec<String> = results
        .iter()
        .map(|r| {
            let sizes: Vec<String> = r
                .bank_bytes
                .iter()
                .zip(BANK_NAMES)
                .map(|(b, n)| format!("{n} {}", mib(*b)))
                .collect();
            format!("- {}: {} MiB", r.row.name, sizes.join(", "))
        })
        .collect();
    let updates: String = results
        .iter()
        .filter_map(|r| {
            r.update.map(|u| {
                format!(
                    "- {}: top-level nodes {}, top-level lists {}, instance matrices {}\n",
                    r.row.name,
                    thousands(u.top_nodes as u64),
                    thousands(u.top_lists as u64),
                    thousands(u.instance_matrices as u64)
                )
            })
        })
        .collect();
    let updates = if updates.is_empty() {
        updates
    } else {
        format!("\nFrame updates (bytes):\n\n{updates}")
    };
    format!(
        "# The paper's Table 3 scenes (`dynrt bench paper`)\n\n\
         Golden model and processor in e7m16, frame 0 at 512x384; the processor with 32 threads \
         and SRAM latency 2, simulated in Verilator. fps at {clock_mhz:.1} MHz ({clock_source}); \
         the paper's fps are one pipeline at 90 MHz. Memory against six banks of 4 MiB: a scene \
         that does not fit is rendered by the golden model from larger banks and not simulated. \
         Bytes per frame update: what the host writes to the banks between two frames of an \
         animated scene (the top-level tree's nodes and leaf lists, the instances' matrices), \
         the largest over the animation, measured on its memory maps. Memory words per pixel: \
         the 32-bit words read from every bank (counted by the testbench's memory) and the frame \
         buffer's writes; GB/s at the clock above (the paper needed about 2 GB/s at 90 MHz \
         without caches, 1 with them).\n\n\
         {}\n\
         Bank sizes (MiB):\n\n{}\n{}",
        paper_table(results, clock_mhz).to_markdown(),
        banks.join("\n"),
        updates
    )
}

/// Bar chart of the paper's fps and ours (log scale) as PNG bytes; scenes without a run are
/// marked with why.
pub fn paper_chart(results: &[PaperResult], clock_mhz: f64) -> Result<Vec<u8>> {
    super::plot::register_font();
    let (w, h) = (1100u32, 560u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let ours: Vec<Option<f64>> = results
        .iter()
        .map(|r| match &r.sim {
            Sim::Ran(s) => Some(s.fps_at(clock_mhz)),
            Sim::NotRun(_) => None,
        })
        .collect();
    let values = results
        .iter()
        .map(|r| r.row.fps)
        .chain(ours.iter().flatten().copied());
    let (lo, hi) = values.fold((f64::INFINITY, 0f64), |(l, h), v| (l.min(v), h.max(v)));
    if results.is_empty() || !lo.is_finite() {
        return Err(anyhow!("no scene to chart"));
    }
    let floor = 10f64.powf((lo.max(1e-6) / 2.0).log10().floor());
    let top = 10f64.powf((hi * 2.0).log10().ceil());
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<_>| anyhow!("{e}");
        root.fill(&WHITE).map_err(e)?;
        let n = results.len() as f64;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("Frames per second at 512x384: the paper (90 MHz) and dynrt ({clock_mhz:.1} MHz)"),
                ("sans-serif", 20),
            )
            .margin(16)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0f64..n, (floor..top).log_scale())
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .y_desc("frames per second")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let label = |x: f64, y: f64, text: String, offset: (i32, i32), color: &RGBColor| {
            EmptyElement::at((x, y))
                + Text::new(text, offset, ("sans-serif", 13).into_font().color(color))
        };
        for (i, (r, o)) in results.iter().zip(&ours).enumerate() {
            let x = i as f64;
            chart
                .draw_series([Rectangle::new(
                    [(x + 0.12, floor), (x + 0.48, r.row.fps)],
                    BLUE.filled(),
                )])
                .map_err(|e| anyhow!("{e}"))?;
            let ours_text = match o {
                Some(f) => {
                    chart
                        .draw_series([Rectangle::new(
                            [(x + 0.52, floor), (x + 0.88, *f)],
                            RED.filled(),
                        )])
                        .map_err(|e| anyhow!("{e}"))?;
                    format!("{f:.2}")
                }
                None if r.fits() => "not run".to_string(),
                None => "no fit".to_string(),
            };
            let y_ours = o.unwrap_or(floor);
            chart
                .draw_series([
                    label(
                        x + 0.12,
                        r.row.fps,
                        format!("{:.1}", r.row.fps),
                        (0, -16),
                        &BLUE,
                    ),
                    label(x + 0.52, y_ours, ours_text, (0, -16), &RED),
                    label(x + 0.1, floor, r.row.name.to_string(), (0, 8), &BLACK),
                ])
                .map_err(|e| anyhow!("{e}"))?;
        }
        chart
            .draw_series([
                label(0.1, top, "blue: paper".into(), (0, 4), &BLUE),
                label(0.1, top, "red: dynrt, Verilator".into(), (0, 20), &RED),
            ])
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).context("chart buffer size")?;
    crate::output::png_bytes(&img)
}

/// Writes `paper.csv`, `paper.md` and `paper.png` into `dir`, and each scene's golden frame
/// as `paper_<file>.png`, all or none.
pub fn write_report(
    dir: &Path,
    measured: &[(PaperResult, Vec<u8>)],
    clock_mhz: f64,
    clock_source: &str,
) -> Result<Vec<std::path::PathBuf>> {
    let results: Vec<PaperResult> = measured.iter().map(|(r, _)| r.clone()).collect();
    let mut files: Vec<(std::path::PathBuf, Vec<u8>)> = vec![
        (
            dir.join("paper.csv"),
            paper_table(&results, clock_mhz).to_csv().into_bytes(),
        ),
        (
            dir.join("paper.md"),
            paper_markdown(&results, clock_mhz, clock_source).into_bytes(),
        ),
        (dir.join("paper.png"), paper_chart(&results, clock_mhz)?),
    ];
    for (r, png) in measured {
        files.push((dir.join(format!("paper_{}.png", r.row.file)), png.clone()));
    }
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    crate::output::write_all_atomically(&refs)?;
    Ok(files.into_iter().map(|(p, _)| p).collect())
}

/// What `dynrt bench paper` runs.
pub struct Options<'a> {
    /// Folder of the suite's scene files.
    pub scenes: &'a Path,
    /// Only these scenes (file stems); all when empty.
    pub only: &'a [String],
    /// Resolution of the golden frames (the scenes' own, 512x384, when `None`).
    pub resolution: Option<(u32, u32)>,
    /// Resolution of the processor's runs (the golden frames' when `None`).
    pub sim_resolution: Option<(u32, u32)>,
    /// Run the processor in Verilator for the scenes that fit.
    pub sim: bool,
    /// Print the progress lines and the report on stdout; on stderr when false (`--json`
    /// keeps stdout for its one document).
    pub stdout: bool,
}

/// Prints `text` on stdout or stderr.
fn say(stdout: bool, text: &str) {
    if stdout {
        println!("{text}");
    } else {
        eprintln!("{text}");
    }
}

/// Measures the suite and writes the report into `out` (see [`write_report`]); each
/// processor run keeps its own folder `out/paper_sim_<file>` (`dynrt sim`'s files). Every scene
/// file is loaded before any work, so a missing or broken one stops the run before anything is
/// written. Returns the Markdown report and whether a processor frame differed from the golden
/// model.
pub fn run(o: &Options, out: &Path, clock_mhz: f64, clock_source: &str) -> Result<(String, bool)> {
    use crate::scene::paper::TABLE3;
    for n in o.only {
        if !TABLE3.iter().any(|r| r.file == n) {
            let names: Vec<&str> = TABLE3.iter().map(|r| r.file).collect();
            anyhow::bail!(
                "--only {n}: not a scene of the suite; use some of {}",
                names.join(",")
            );
        }
    }
    let rows: Vec<PaperRow> = TABLE3
        .iter()
        .filter(|r| o.only.is_empty() || o.only.iter().any(|n| n == r.file))
        .copied()
        .collect();
    crate::output::check_output_dir(out, "--out")?;
    let mut scenes = Vec::new();
    for r in &rows {
        let path = o.scenes.join(format!("{}.toml", r.file));
        let there = if crate::bundled::is_bundled(&path) {
            crate::bundled::is_file(&path)
        } else {
            path.exists()
        };
        if !there {
            anyhow::bail!(
                "{}: missing; write the suite's scene files with `dynrt paper-scenes --out {}`",
                path.display(),
                o.scenes.display()
            );
        }
        let mut s = Scene::load(&path)?;
        if let Some((w, h)) = o.resolution {
            s.set_resolution(w, h)?;
        }
        scenes.push(s);
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut measured = Vec::new();
    let mut kept = Vec::new();
    let mut differs = false;
    for (r, scene) in rows.iter().zip(&scenes) {
        crate::progress::report(&format!("{}: trees, memory map, golden frame", r.name));
        let m = measure(*r, scene)?;
        let png = crate::output::png_bytes(&m.frame.to_image())?;
        let mut result = m.result;
        result.sim = if !result.fits() {
            Sim::NotRun("does not fit the banks".into())
        } else if !o.sim {
            Sim::NotRun("left out (--no-sim)".into())
        } else {
            crate::progress::report(&format!("{}: the processor in Verilator", r.name));
            let (sim, dir) = simulate(r, scene, o.sim_resolution, out, o.stdout)?;
            kept.extend(dir);
            sim
        };
        if let Sim::Ran(s) = &result.sim {
            differs |= s.differing_pixels > 0;
        }
        measured.push((result, png));
    }
    for f in write_report(out, &measured, clock_mhz, clock_source)? {
        say(o.stdout, &format!("wrote {}", f.display()));
    }
    // The report is written: the processor runs' folders stay.
    for k in kept {
        k.keep();
    }
    let results: Vec<PaperResult> = measured.into_iter().map(|(r, _)| r).collect();
    let md = paper_markdown(&results, clock_mhz, clock_source);
    say(o.stdout, md.trim_end());
    Ok((md, differs))
}

/// Frame 0 of `scene` in the processor (Verilator, e7m16, 32 threads, SRAM latency 2) at
/// `resolution`, in the folder `out/paper_sim_<file>`, which is removed unless the caller
/// keeps it. A scene the processor cannot take (its microprogram, its stacks) is not run, with
/// the reason.
fn simulate(
    row: &PaperRow,
    scene: &Scene,
    resolution: Option<(u32, u32)>,
    out: &Path,
    stdout: bool,
) -> Result<(Sim, Option<crate::output::OutputDir>)> {
    use crate::emit::processor::ProcessorParams;
    let mut scene = scene.clone();
    if let Some((w, h)) = resolution {
        scene.set_resolution(w, h)?;
    }
    let params = ProcessorParams::default();
    let f = crate::fp::Format::E7M16;
    if let Err(e) = crate::flow::preflight(&scene, f, params, Some(1)) {
        return Ok((Sim::NotRun(format!("{e:#}")), None));
    }
    let dir = out.join(format!("paper_sim_{}", row.file));
    let guard = crate::output::OutputDir::create(&dir, "the simulation folder")?;
    let r = crate::flow::simulate_scene(
        &scene,
        row.file,
        f,
        params,
        Some(1),
        crate::sim::Simulator::Verilator,
        None,
        &dir,
        &crate::provenance::GeneratedBy::this_run(false),
    )?;
    let frame = &r.frames[0];
    let sim = SimFigures {
        width: scene.camera.width,
        height: scene.camera.height,
        cycles: frame.cycles,
        memory_words: frame.memory_words(),
        differing_pixels: frame.differing_pixels,
    };
    say(
        stdout,
        &format!(
            "{}: {} cycles at {}x{}, {:.1} cycles per pixel, {} (Verilator {:.1} s)",
            row.name,
            frame.cycles,
            sim.width,
            sim.height,
            sim.cycles_per_pixel(),
            if frame.differing_pixels == 0 {
                "identical to the golden model".to_string()
            } else {
                format!(
                    "{} pixels DIFFER from the golden model",
                    frame.differing_pixels
                )
            },
            r.run_seconds
        ),
    );
    Ok((Sim::Ran(sim), Some(guard)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::paper::TABLE3;

    fn result(row: usize, nodes: usize, sim: Sim) -> PaperResult {
        PaperResult {
            row: TABLE3[row],
            unique_triangles: 806,
            instanced_triangles: 820,
            objects: 1,
            bank_bytes: vec![nodes, 1000, 2000, 2000, 0, 800_000],
            update: None,
            rays: Rays {
                pixels: 4,
                primary: 4,
                shadow: 3,
                mirror: 0,
            },
            sim,
        }
    }

    #[test]
    fn table_states_fps_from_cycles_per_pixel_and_what_does_not_fit() {
        // 393,216 cycles for a 128x96 run: 32 cycles per pixel, so a 512x384 frame takes
        // 6,291,456 cycles: 14.305 fps at 90 MHz, the paper's 60.8 being 4x that.
        let ran = Sim::Ran(SimFigures {
            width: 128,
            height: 96,
            cycles: 393_216,
            // 20 words a pixel, 0.625 a clock: 0.225 GB/s at 90 MHz.
            memory_words: 128 * 96 * 20,
            differing_pixels: 0,
        });
        let big = 9 << 20;
        let mut results = [
            result(0, 1 << 20, ran),
            result(2, big, Sim::NotRun("does not fit the banks".into())),
        ];
        results[1].update = Some(FrameUpdate {
            top_nodes: 1000,
            top_lists: 234,
            instance_matrices: 1_000_000,
        });
        assert!(results[0].fits() && !results[1].fits());
        assert_eq!(results[1].overfull_banks(), [("nodes", big)]);
        let csv = paper_table(&results, 90.0).to_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(
            lines[0].contains("fps at 90.0 MHz (512x384)"),
            "{}",
            lines[0]
        );
        assert_eq!(
            lines[1],
            "Scene6,806,820,806,1,1.77,yes,static,1.00,0.75,0.00,\
             \"128x96 (same view, fps scaled to 512x384)\",32.0,14.305,20.0,0.225,60.8,4"
        );
        assert!(
            lines[2].starts_with(
                "Office,\"34,312\",820,806,1,9.77,no: nodes needs 9.00 MiB,\"1,001,234\","
            ),
            "{}",
            lines[2]
        );
        assert!(
            lines[2].ends_with(",no: does not fit the banks,-,-,-,-,48.9,-"),
            "{}",
            lines[2]
        );
        let md = paper_markdown(&results, 81.4, "given with --clock");
        assert!(md.contains("fps at 81.4 MHz (given with --clock)"));
        assert!(md.contains("- Office: nodes 9.00, lists 0.00"), "{md}");
        assert!(
            md.contains(
                "- Office: top-level nodes 1,000, top-level lists 234, instance matrices 1,000,000"
            ),
            "{md}"
        );
        assert!(
            !md.contains("- Scene6: top-level"),
            "a static scene has no update"
        );
    }

    #[test]
    fn report_files_are_written_together() {
        let dir = tempfile::tempdir().unwrap();
        let r = result(
            0,
            100,
            Sim::Ran(SimFigures {
                width: 512,
                height: 384,
                cycles: 196_608 * 300,
                memory_words: 196_608 * 40,
                differing_pixels: 0,
            }),
        );
        let written = write_report(dir.path(), &[(r, vec![1, 2, 3])], 81.4, "given").unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            ["paper.csv", "paper.md", "paper.png", "paper_scene6.png"]
        );
        let chart = image::open(dir.path().join("paper.png")).unwrap().to_rgb8();
        let count = |f: &dyn Fn(&image::Rgb<u8>) -> bool| chart.pixels().filter(|p| f(p)).count();
        assert!(count(&|p| p[2] > 200 && p[0] < 60) > 500, "the paper's bar");
        assert!(count(&|p| p[0] > 200 && p[2] < 60) > 500, "our bar");
        assert_eq!(
            std::fs::read(dir.path().join("paper_scene6.png")).unwrap(),
            [1, 2, 3]
        );
    }
}
