//! The generated processor renders every frame identical to the golden model, in Icarus and
//! in Verilator: shadows, mirror reflection, instances with animated frames, and a mesh of more
//! than 10k triangles.

use dynrt::emit::processor::ProcessorParams;
use dynrt::flow;
use dynrt::fp::Format;
use dynrt::scene::Scene;
use dynrt::sim::Simulator;
use std::path::Path;

fn scene(name: &str, w: u32, h: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut s = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    s.set_resolution(w, h).unwrap();
    s
}

fn check(name: &str, w: u32, h: u32, frames: Option<u32>, sim: Simulator) {
    let s = scene(name, w, h);
    let dir = tempfile::tempdir().unwrap();
    let r = flow::simulate_scene(
        &s,
        name,
        Format::E7M16,
        ProcessorParams::default(),
        frames,
        sim,
        dir.path(),
    )
    .unwrap_or_else(|e| panic!("{name} in {}: {e:#}", sim.name()));
    for (k, f) in r.frames.iter().enumerate() {
        println!(
            "{name} {} frame {k}: {} cycles, {:.0} cycles/ray, {} differing pixels",
            sim.name(),
            f.cycles,
            f.cycles_per_ray(),
            f.differing_pixels
        );
        assert_eq!(
            f.differing_pixels,
            0,
            "{name} frame {k} in {}: first mismatches {:#?}",
            sim.name(),
            f.mismatches
        );
        // The RTL issues exactly the instructions the engine's twin executes.
        if k == 0 {
            assert_eq!(
                f.instructions, r.twin.instructions,
                "{name}: instruction count"
            );
        }
    }
    assert_eq!(r.frames.len(), frames.unwrap_or(s.frames) as usize);
}

/// One test per scene and simulator, so that the test harness spreads the simulations over the
/// machine's cores.
macro_rules! frames_equal_the_golden_model {
    ($($test:ident: $sim:ident $name:literal $w:literal x $h:literal, frames $frames:expr;)*) => {
        $(
            #[test]
            fn $test() {
                check($name, $w, $h, $frames, Simulator::$sim);
            }
        )*
    };
}

frames_equal_the_golden_model! {
    verilator_cornell: Verilator "cornell.toml" 16 x 12, frames None;
    verilator_mirror: Verilator "mirror.toml" 16 x 12, frames None;
    verilator_tiny_animated: Verilator "tiny_animated.toml" 16 x 12, frames Some(2);
    verilator_dynamic: Verilator "dynamic.toml" 12 x 9, frames Some(2);
    verilator_terrain_small: Verilator "terrain_small.toml" 16 x 12, frames None;
    verilator_cornell_noshadow: Verilator "cornell_noshadow.toml" 16 x 12, frames None;
    // Icarus runs about 2k clocks per second here: two-pixel frames (a frame lasts as long as
    // its slowest pixel times the 32-clock rotation, so more pixels cost little more).
    icarus_cornell: Icarus "cornell.toml" 2 x 1, frames None;
    icarus_mirror: Icarus "mirror.toml" 2 x 1, frames None;
    icarus_tiny_animated: Icarus "tiny_animated.toml" 2 x 1, frames Some(2);
    icarus_terrain_small: Icarus "terrain_small.toml" 2 x 1, frames None;
}

#[test]
fn a_frame_that_cannot_finish_in_time_is_a_clear_timeout_error() {
    use dynrt::emit::processor_run::simulate_processor;
    use dynrt::hw::program::{build_program, ProgramConfig};
    let s = scene("cornell_noshadow.toml", 4, 3);
    let layouts = flow::scene_layouts(&s, Format::E7M16, None).unwrap();
    let p = build_program(&ProgramConfig::from_layout(Format::E7M16, &layouts[0].info));
    let dir = tempfile::tempdir().unwrap();
    let e = simulate_processor(
        &p,
        &layouts,
        ProcessorParams::default(),
        "cornell_noshadow",
        500,
        Simulator::Verilator,
        dir.path(),
    )
    .unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("did not finish a frame within 500 clocks"),
        "{msg}"
    );
}
