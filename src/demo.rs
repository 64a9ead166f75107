//! The main job on one scene, end to end: render the scene with the golden model and the f64
//! reference and measure the error; generate the floating-point operators of the chosen format
//! as Verilog, simulate each in Icarus and in Verilator on edge-case and random vectors, and
//! check every result bit for bit against the software model; generate the whole ray tracing
//! processor for the scene and simulate its frames in Verilator (and a small frame in Icarus),
//! each pixel compared with the golden model. Writes images, hits files, the Verilog and a
//! Markdown report.

use crate::compare::{compare_hits, compare_images, diff_image};
use crate::emit::fp_unit_rtl;
use crate::fp::{vectors, BinOp, Format};
use crate::layout::{self, MemoryConfig, SceneTrees};
use crate::model::{render_golden, Reference};
use crate::report::{RunSummary, SceneInfo};
use crate::scene::Scene;
use crate::sim::{self, run_fp_unit, Simulator};
use anyhow::Context;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

pub struct DemoConfig {
    pub scene: PathBuf,
    pub format: Format,
    pub out: PathBuf,
    /// Random vectors per operator and simulator (edge cases come on top).
    pub vectors: usize,
    /// Frame size of the whole run (the scene's own when `None`); the small Icarus frame is
    /// 4x3 or this, whichever is smaller.
    pub size: Option<(u32, u32)>,
    /// The header of the generated files and the report.
    pub generated_by: crate::provenance::GeneratedBy,
}

/// What the demo found; `ok` is false when any RTL result differed from the model.
pub struct DemoReport {
    pub ok: bool,
    pub report: PathBuf,
    pub summary: String,
    /// The run's summary.json.
    pub json: String,
}

pub fn run_demo(c: &DemoConfig) -> anyhow::Result<DemoReport> {
    crate::output::check_output_dir(&c.out, "--out")?;
    let mut scene = Scene::load(&c.scene)?;
    if let Some((w, h)) = c.size {
        scene.set_resolution(w, h)?;
    }
    let params = crate::emit::processor::ProcessorParams::default();
    crate::flow::preflight(&scene, c.format, params, None)?;
    let out_dir = crate::output::OutputDir::create(&c.out, "--out")?;
    let name = c
        .scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut summary = RunSummary::new("demo", &c.generated_by);
    summary.scene = Some(SceneInfo::of(&scene, &name));
    summary
        .option("format", c.format.to_string())
        .option("vectors", c.vectors)
        .option("size", c.size.map(|(w, h)| format!("{w}x{h}")));
    let mut md = String::new();
    writeln!(md, "## Scene {}\n", c.scene.display())?;
    writeln!(
        md,
        "{} triangles, {} instances, {}x{} pixels, number format {}.\n",
        scene.triangle_count(),
        scene.instances.len(),
        scene.camera.width,
        scene.camera.height,
        c.format
    )?;

    // 1. Golden model and reference.
    let t0 = Instant::now();
    let trees = SceneTrees::build(&scene, c.format)?;
    let l = layout::build(&scene, &trees, 0, &MemoryConfig::default())?;
    let golden = render_golden(&l, true);
    let golden_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let reference = Reference::new(&scene).render(0);
    let reference_s = t0.elapsed().as_secs_f64();
    golden.save_png(&c.out.join("golden.png"))?;
    reference.save_png(&c.out.join("reference.png"))?;
    golden.save_hits(&c.out.join("golden_hits.csv"))?;
    reference.save_hits(&c.out.join("reference_hits.csv"))?;
    let (gi, ri) = (golden.to_image(), reference.to_image());
    let img = compare_images(&gi, &ri)?;
    let hits = compare_hits(&golden.hit_tuples(), &reference.hit_tuples())?;
    if let Some(w) = crate::compare::golden_warning(c.format, &hits) {
        eprintln!("warning: {}: {w}", c.scene.display());
    }
    crate::output::write_png(&c.out.join("diff.png"), &diff_image(&gi, &ri))?;
    writeln!(
        md,
        "## Golden model ({}) against the f64 reference\n",
        c.format
    )?;
    writeln!(md, "| metric | value |\n|---|---|")?;
    writeln!(
        md,
        "| golden render (trees + layout + frame) | {golden_s:.3} s |"
    )?;
    writeln!(
        md,
        "| reference render (trees + frame) | {reference_s:.3} s |"
    )?;
    writeln!(
        md,
        "| identical primary hits | {:.3}% |",
        100.0 * hits.identical_ratio()
    )?;
    writeln!(
        md,
        "| equivalent primary hits (ties at shared edges counted) | {:.3}% |",
        100.0 * hits.equivalent_ratio()
    )?;
    writeln!(
        md,
        "| mean relative hit-distance error | {:.2e} |",
        hits.mean_rel_dist_error
    )?;
    writeln!(md, "| PSNR | {:.2} dB |", img.psnr_db)?;
    writeln!(md, "| max channel error | {} |", img.max_channel_error)?;
    writeln!(
        md,
        "| differing pixels | {:.3}% |\n",
        100.0 * img.differing_share()
    )?;
    writeln!(
        md,
        "Images: golden.png, reference.png, diff.png; hits: golden_hits.csv, reference_hits.csv.\n"
    )?;

    // 2. The floating-point operators in RTL.
    let rtl_dir = c.out.join("rtl");
    std::fs::create_dir_all(&rtl_dir)?;
    let mut pairs = vectors::random_pairs(c.format, 0xD3_70, c.vectors);
    let edges = vectors::edge_cases(c.format);
    pairs.extend(
        edges
            .iter()
            .flat_map(|&a| edges.iter().map(move |&b| (a, b))),
    );
    writeln!(
        md,
        "## Floating-point operators in RTL ({}, {} vectors each)\n",
        c.format,
        pairs.len()
    )?;
    writeln!(md, "| operator | latency | simulator | compile s | run s | mismatches |\n|---|---|---|---|---|---|")?;
    let mut ok = true;
    for op in BinOp::ALL {
        let unit = fp_unit_rtl(op, c.format)?;
        let path = rtl_dir.join(format!("{}.v", unit.top));
        let text = format!("{}{}", c.generated_by.comment("//"), unit.verilog);
        crate::output::write_atomically(&path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        let want: Vec<u32> = pairs
            .iter()
            .map(|&(a, b)| op.eval(c.format, a, b))
            .collect();
        for simulator in [Simulator::Icarus, Simulator::Verilator] {
            let work = tempfile::tempdir()?;
            let run = run_fp_unit(op, c.format, &pairs, simulator, work.path())?;
            let bad = want
                .iter()
                .zip(&run.results)
                .filter(|(a, b)| a != b)
                .count();
            ok &= bad == 0;
            let version = sim::tool_version(simulator).unwrap_or_default();
            summary
                .tools
                .insert(simulator.name().to_string(), version.clone());
            summary.add_check(
                &format!("{op} in {simulator}"),
                bad == 0,
                &format!("{bad} of {} results differ from the model", pairs.len()),
                Some(run.compile_seconds + run.run_seconds),
            );
            writeln!(
                md,
                "| {op} | {} | {simulator} {version} | {:.1} | {:.2} | {bad} |",
                unit.latency, run.compile_seconds, run.run_seconds
            )?;
        }
    }
    writeln!(md, "\nVerilog of every operator: rtl/*.v.\n")?;

    // 3. The whole processor: every frame in Verilator at the scene's resolution, and a
    // small frame in Icarus (about 2k simulated clocks per second), against the golden model.
    writeln!(md, "## The ray tracing processor in RTL\n")?;
    let generated = crate::flow::generate_rtl(
        &scene,
        &name,
        c.format,
        params,
        None,
        &c.out.join("processor"),
        &c.generated_by,
        None,
    )?;
    writeln!(
        md,
        "Generated in processor/: {} microprogram instructions, {} threads, a round of {} clocks. \
         Left out for this scene: {}.\n",
        generated.program.code.len(),
        params.threads,
        generated.period,
        if generated.program.left_out.is_empty() {
            "nothing".to_string()
        } else {
            generated.program.left_out.join("; ")
        }
    )?;
    writeln!(
        md,
        "| simulator | pixels | frames | cycles (frame 0) | cycles per primary ray | fps at 90 MHz | fps at 512x384 | sim cycles/s | differing pixels |\n|---|---|---|---|---|---|---|---|---|"
    )?;
    let mut small = scene.clone();
    small.set_resolution(scene.camera.width.min(4), scene.camera.height.min(3))?;
    let mut processor_ok = true;
    for (simulator, sc, dir) in [
        (Simulator::Verilator, &scene, "sim_verilator"),
        (Simulator::Icarus, &small, "sim_icarus"),
    ] {
        let r = crate::flow::simulate_scene(
            sc,
            &name,
            c.format,
            params,
            None,
            simulator,
            None,
            &c.out.join(dir),
            &c.generated_by,
        )?;
        let f0 = &r.frames[0];
        let differing: usize = r.frames.iter().map(|f| f.differing_pixels).sum();
        for (k, f) in r.frames.iter().enumerate() {
            summary.add_frame(f.result(k, format!("{simulator} ({dir}/)")));
        }
        processor_ok &= differing == 0;
        writeln!(
            md,
            "| {simulator} {} | {}x{} | {} | {} | {:.1} | {:.1} | {:.2} | {:.0} | {differing} |",
            r.tool_version,
            sc.camera.width,
            sc.camera.height,
            r.frames.len(),
            f0.cycles,
            f0.cycles_per_ray(),
            f0.fps(),
            f0.fps_512x384(),
            r.simulated_cycles_per_second()
        )?;
    }
    writeln!(
        md,
        "\nFrames: sim_verilator/frame0.png (RTL) and golden0.png; a mismatch writes diff<k>.png and mismatch<k>.txt there."
    )?;
    ok &= processor_ok;
    summary.left_out = generated.program.left_out.clone();
    summary.generated.push(format!(
        "every FP operator of {} (rtl/), the processor (processor/), its simulations (sim_verilator/, sim_icarus/)",
        c.format
    ));
    summary.notes.push(format!(
        "golden vs reference: {:.3}% equivalent primary hits, PSNR {:.2} dB",
        100.0 * hits.equivalent_ratio(),
        img.psnr_db
    ));
    summary.details_md = md;
    summary.write(&c.out, true)?;
    let json = summary.json();
    let report = c.out.join(crate::report::REPORT_MD);
    out_dir.keep();
    let summary = format!(
        "{}: golden {} vs reference: {:.3}% equivalent hits, PSNR {:.1} dB; FP operators and the processor's frames in Icarus and Verilator against the model: {}",
        c.scene.display(),
        c.format,
        100.0 * hits.equivalent_ratio(),
        img.psnr_db,
        if ok { "all bit-exact" } else { "MISMATCHES (see report)" }
    );
    Ok(DemoReport {
        ok,
        report,
        summary,
        json,
    })
}

/// The default scene: the Cornell box bundled with the binary (`bundled:/cornell.toml`), so
/// that `dynrt demo` runs from any folder.
pub fn default_scene() -> PathBuf {
    crate::bundled::path("cornell.toml")
}
