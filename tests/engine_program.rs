//! The ray thread engine's microprogram, run by its Rust twin, renders exactly what the golden
//! model renders: every pixel of every bundled scene, and every frame of an animated one.

use dynrt::fp::Format;
use dynrt::hw::program::exec::Machine;
use dynrt::hw::program::isa::Unit;
use dynrt::hw::program::{build_program, ProgramConfig};
use dynrt::layout::{self, Layout, MemoryConfig, SceneTrees};
use dynrt::model;
use dynrt::scene::Scene;
use rayon::prelude::*;
use std::path::Path;

fn layout_of(name: &str, w: u32, h: u32, f: Format, frame: u32) -> Layout {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut s = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    s.set_resolution(w, h).unwrap();
    let trees = SceneTrees::build(&s, f).unwrap();
    layout::build(&s, &trees, frame, &MemoryConfig::default()).unwrap()
}

/// Pixels where the twin differs from the golden model, and how many pixels hit something.
fn mismatches(l: &Layout) -> (Vec<(u32, u32, u32, u32)>, usize) {
    let program = build_program(&ProgramConfig::from_layout(l));
    let golden = model::render_golden(l, false);
    let m = Machine::new(&program, l);
    let (w, h) = (l.info.width, l.info.height);
    let bad = (0..w * h)
        .into_par_iter()
        .filter_map(|i| {
            let (x, y) = (i % w, i / w);
            let (rgb, _, _) = m
                .run_pixel(x, y, false)
                .unwrap_or_else(|e| panic!("pixel ({x}, {y}): {e}"));
            let want = golden.rgb[i as usize];
            (rgb != want).then_some((x, y, rgb, want))
        })
        .collect();
    (bad, golden.hits.iter().filter(|h| h.is_some()).count())
}

#[test]
fn microprogram_renders_the_golden_frame_on_every_bundled_scene() {
    for (name, w, h) in [
        ("tiny.toml", 16, 12),
        ("cornell.toml", 32, 24),
        ("cornell_noshadow.toml", 32, 24),
        ("mirror.toml", 32, 24),
        ("dynamic.toml", 32, 24),
        ("terrain.toml", 24, 18),
    ] {
        for f in [Format::E7M16, Format::E8M23] {
            let l = layout_of(name, w, h, f, 0);
            let (bad, hits) = mismatches(&l);
            println!(
                "{name} {f}: {} of {} pixels differ, {hits} hits",
                bad.len(),
                w * h
            );
            assert!(
                hits > 0,
                "{name}: nothing hit, the comparison proves little"
            );
            assert!(
                bad.is_empty(),
                "{name} {f}: first differences (x, y, twin, golden) {:x?}",
                &bad[..bad.len().min(5)]
            );
        }
    }
}

#[test]
fn engine_order_frame_equals_per_pixel_runs_and_every_pixel_is_written() {
    let f = Format::E7M16;
    let l = layout_of("mirror.toml", 16, 12, f, 0);
    let program = build_program(&ProgramConfig::from_layout(&l));
    let m = Machine::new(&program, &l);
    let frame = m.run_frame(32).unwrap();
    let golden = model::render_golden(&l, false);
    assert_eq!(frame.pixels, golden.rgb);
    // Every instruction is counted once per unit.
    assert_eq!(
        frame.stats.per_unit.values().sum::<u64>(),
        frame.stats.instructions
    );
    assert!(frame.stats.rounds * 32 >= frame.stats.instructions);
}

/// Issue 18's programmable share: with the ShadeUnit, cornell_noshadow's threads issue at most
/// 12 instructions per primary ray at the issue's 64x48 (the twin's count is the engine's,
/// `processor_sim`; each thread's 29 instructions of frame set-up are in it), and its frame
/// is the golden model's.
#[test]
fn cornell_noshadow_issues_at_most_12_instructions_per_primary_ray() {
    let l = layout_of("cornell_noshadow.toml", 64, 48, Format::E7M16, 0);
    let program = build_program(&ProgramConfig::from_layout(&l));
    let frame = Machine::new(&program, &l).run_frame(32).unwrap();
    assert_eq!(frame.pixels, model::render_golden(&l, false).rgb);
    let per_ray = frame.stats.instructions as f64 / (64.0 * 48.0);
    println!("cornell_noshadow: {per_ray:.2} instructions per primary ray");
    assert!(per_ray <= 12.0, "{per_ray}");
}

#[test]
fn animated_frames_match_the_golden_model() {
    let f = Format::E7M16;
    for frame in 0..2 {
        let l = layout_of("tiny_animated.toml", 16, 12, f, frame);
        let (bad, _) = mismatches(&l);
        assert!(
            bad.is_empty(),
            "frame {frame}: {:x?}",
            &bad[..bad.len().min(5)]
        );
    }
}

#[test]
fn the_program_leaves_out_what_the_scene_does_not_need() {
    let f = Format::E7M16;
    let plain = layout_of("cornell_noshadow.toml", 16, 12, f, 0);
    let p = build_program(&ProgramConfig::from_layout(&plain));
    let names: Vec<&str> = p.sections.clone();
    assert!(
        !names.contains(&"shadow") && !names.contains(&"mirror") && !names.contains(&"instances")
    );
    assert!(p.left_out.iter().any(|s| s.contains("shadow")));
    let full = layout_of("mirror.toml", 16, 12, f, 0);
    let q = build_program(&ProgramConfig::from_layout(&full));
    assert!(q.sections.contains(&"mirror"));
    assert!(q.code.len() > p.code.len());
    // The ShadeUnit shades the primary rays of a scene without secondary rays or instances.
    assert!(p.units().contains(&Unit::Shading) && !q.units().contains(&Unit::Shading));
    let line = format!("{} unit (no instruction uses it)", Unit::Shading.name());
    assert!(!p.left_out.contains(&line) && q.left_out.contains(&line));
    // The engine is built without the units no instruction uses (`Program::units`): instance
    // entry, the mailboxes and the scratch words only where the scene has instances and mirrors.
    for u in [Unit::InstanceEntry, Unit::Mailbox, Unit::Scratch] {
        assert!(!p.units().contains(&u) && q.units().contains(&u), "{u:?}");
        let line = format!("{} unit (no instruction uses it)", u.name());
        assert!(
            p.left_out.contains(&line) && !q.left_out.contains(&line),
            "{line}"
        );
    }
    println!(
        "cornell_noshadow: {} instructions, {} registers; mirror: {} instructions",
        p.code.len(),
        p.registers_used,
        q.code.len()
    );
}

/// A primary ray's trace takes its query from constants and its ray from ray generation: the
/// pixel loop's head moves no register and writes no ray words, and only mirror rays (and,
/// under a top level, shadow rays) trace through a routine; the frames are the golden model's
/// (`microprogram_renders_the_golden_frame_on_every_bundled_scene`).
#[test]
fn a_primary_trace_moves_no_register_and_only_mirror_and_top_level_shadow_rays_call_a_routine() {
    use dynrt::hw::program::isa::{Op, TriFn};
    for (name, routines) in [
        ("cornell.toml", 0),
        ("terrain.toml", 0),
        ("dynamic.toml", 1),
        ("mirror.toml", 2),
    ] {
        let l = layout_of(name, 16, 12, Format::E7M16, 0);
        let p = build_program(&ProgramConfig::from_layout(&l));
        let sections = || p.code.iter().zip(&p.sections);
        let returns = p.code.iter().filter(|i| i.op == Op::Jr).count();
        assert_eq!(returns, routines, "{name}: routines");
        let mirrors = l.info.reflection_depth > 0;
        // With mirrors the eye goes to the query's origin (where shading finds every depth's
        // ray) and the depth to 0; without, nothing.
        let moves = sections()
            .filter(|(i, s)| **s == "raygen" && i.op == Op::Or)
            .count();
        assert_eq!(moves, if mirrors { 4 } else { 0 }, "{name}: moves");
        // Ray words (3) are written for the secondary rays of one object only: each light's
        // shadow ray in line and the mirror routine's ray.
        let ray_words = p
            .code
            .iter()
            .filter(|i| i.op == Op::Tri && i.imm <= TriFn::RayDyz as u32)
            .count() as u32;
        let want = match l.info.top_root {
            None => 3 * (l.info.shadows as u32 * l.info.light_count + mirrors as u32),
            Some(_) => 0,
        };
        assert_eq!(ray_words, want, "{name}: ray words");
    }
}
