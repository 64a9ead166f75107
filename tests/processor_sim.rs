//! The generated processor renders every frame identical to the golden model, in Icarus and
//! in Verilator: shadows, mirror reflection, instances with animated frames, and a mesh of more
//! than 10k triangles.

use dynrt::emit::processor::ProcessorParams;
use dynrt::flow;
use dynrt::fp::Format;
use dynrt::provenance::GeneratedBy;
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

fn check(name: &str, w: u32, h: u32, frames: Option<u32>, sim: Simulator, format: Format) {
    check_scene(scene(name, w, h), name, frames, sim, format);
}

fn check_scene(s: Scene, name: &str, frames: Option<u32>, sim: Simulator, format: Format) {
    check_processor(s, name, frames, sim, format, ProcessorParams::default());
}

/// Checks every frame of `s` on the processor `params` describe; returns the run.
fn check_processor(
    s: Scene,
    name: &str,
    frames: Option<u32>,
    sim: Simulator,
    format: Format,
    params: ProcessorParams,
) -> flow::SimReport {
    let dir = tempfile::tempdir().unwrap();
    let r = flow::simulate_scene(
        &s,
        name,
        format,
        params,
        frames,
        sim,
        None,
        dir.path(),
        &GeneratedBy::library(),
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
        // Thread-clocks: a thread is in the scheduler's ready mask in the clock it is picked,
        // so every retired instruction counts at least one; every scene sleeps in walks; the
        // two are disjoint states of at most `threads` threads a clock.
        let threads = u64::from(ProcessorParams::default().threads);
        assert!(
            f.ready_thread_clocks >= f.instructions
                && f.asleep_thread_clocks > 0
                && f.ready_thread_clocks + f.asleep_thread_clocks <= threads * f.cycles,
            "{name} frame {k}: {} ready and {} asleep thread-clocks, {} instructions, {} cycles",
            f.ready_thread_clocks,
            f.asleep_thread_clocks,
            f.instructions,
            f.cycles
        );
        // The testbench's memory counts its reads: every frame walks nodes and their lists,
        // fetches triangles from both banks and loads the frame's constants; each bank's port
        // gives at most a word a clock, and banks 1, 4 and 5 share one port.
        let [nodes, lists, tri_a, tri_b, instances, frame] = f.bank_reads;
        assert!(
            [nodes, lists, tri_a, tri_b, frame].iter().all(|&r| r > 0)
                && [nodes, tri_a, tri_b, lists + instances + frame]
                    .iter()
                    .all(|&r| r <= f.cycles),
            "{name} frame {k}: bank reads {:?} in {} cycles",
            f.bank_reads,
            f.cycles
        );
        // Instance entry reads a record's 12 or 13 words from bank 4 on a miss of the
        // instance cache and none on a hit; each frame starts with the cache flushed (the
        // host rewrote the records), so a frame that enters instances misses at least once.
        let (hits, misses) = (f.instance_cache_hits, f.instance_cache_misses);
        assert!(
            (12 * misses..=13 * misses).contains(&instances) && (hits == 0 || misses > 0),
            "{name} frame {k}: {instances} bank-4 words for {hits} instance cache hits and \
             {misses} misses"
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
    r
}

/// Caches of several ways, each far smaller than the scene (mirror: 350 triangles, about
/// 1,000 nodes in its trees, two instances), so that sets fill, evict and hit in every way: the
/// frames stay identical to the golden model, and every cache hits and misses. In Icarus's 2x2
/// frame the node cache only misses: with four threads the node fetch is idle whenever a job
/// comes, and a job the fetch takes in its first clock goes to bank 0 before its tags are
/// compared (`hw::TraversalUnit`'s node cache), so there the frame is what is checked.
fn check_caches_of_several_ways(w: u32, h: u32, sim: Simulator) {
    let params = ProcessorParams {
        tri_cache_sets: 4,
        tri_cache_ways: 4,
        node_cache_sets: 8,
        node_cache_ways: 2,
        instance_cache_sets: 1,
        instance_cache_ways: 2,
        ..ProcessorParams::default()
    };
    let r = check_processor(
        scene("mirror.toml", w, h),
        "mirror",
        None,
        sim,
        Format::E7M16,
        params,
    );
    let f = &r.frames[0];
    for (cache, hits, misses) in [
        ("triangle", f.tri_cache_hits, f.tri_cache_misses),
        ("node", f.node_cache_hits, f.node_cache_misses),
        ("instance", f.instance_cache_hits, f.instance_cache_misses),
    ] {
        println!(
            "{cache} cache in {}: {hits} hits, {misses} misses",
            sim.name()
        );
        let idle_node_fetch = cache == "node" && sim == Simulator::Icarus;
        assert!(
            (hits > 0 || idle_node_fetch) && misses > 0,
            "{cache} cache in {}: {hits} hits, {misses} misses",
            sim.name()
        );
    }
}

#[test]
fn verilator_caches_of_several_ways() {
    check_caches_of_several_ways(16, 12, Simulator::Verilator);
}

#[test]
fn icarus_caches_of_several_ways() {
    check_caches_of_several_ways(2, 2, Simulator::Icarus);
}

/// The processor's number format: e7m16 unless a test names another.
macro_rules! processor_format {
    () => {
        Format::E7M16
    };
    ($format:ident) => {
        Format::$format
    };
}

/// One test per scene and simulator, so that the test harness spreads the simulations over the
/// machine's cores.
macro_rules! frames_equal_the_golden_model {
    ($($test:ident: $sim:ident $name:literal $w:literal x $h:literal, frames $frames:expr$(, $format:ident)?;)*) => {
        $(
            #[test]
            fn $test() {
                check($name, $w, $h, $frames, Simulator::$sim, processor_format!($($format)?));
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
    // e5m10's long line (fdiv, fsqrt) is only 4 clocks longer than the others: its write back
    // is reserved in the clock after the long instruction is fetched, the tightest case.
    verilator_mirror_e5m10: Verilator "mirror.toml" 16 x 12, frames None, E5M10;
    // Icarus simulates 100-400 clocks per second here (Verilator about 0.3M): 4 pixels, one
    // per thread (such a frame lasts about as long as its slowest ray). The golden model's
    // hits at 2x2: cornell's four pixels hit (and cast shadow rays), one of mirror's hits the
    // mirror sphere (instance 1), two of tiny_animated's and three of terrain_small's hit.
    icarus_cornell: Icarus "cornell.toml" 2 x 2, frames None;
    icarus_mirror: Icarus "mirror.toml" 2 x 2, frames None;
    icarus_tiny_animated: Icarus "tiny_animated.toml" 2 x 2, frames Some(2);
    icarus_terrain_small: Icarus "terrain_small.toml" 2 x 2, frames None;
    // The ShadeUnit's design (cornell_noshadow shades there): its four pixels hit.
    icarus_cornell_noshadow: Icarus "cornell_noshadow.toml" 2 x 2, frames None;
}

/// The ShadeUnit with three lights (one behind every wall it lights, some lit, some not) at
/// a width that is not a power of two (the pixel's word computed as `y * W + x`).
#[test]
fn verilator_shade_unit_three_lights_width_15() {
    use dynrt::scene::Light;
    let mut s = scene("cornell_noshadow.toml", 15, 10);
    s.lights.push(Light {
        position: glam::DVec3::new(-0.8, 0.3, 1.5),
        color: [0.6, 0.2, 0.1],
    });
    s.lights.push(Light {
        position: glam::DVec3::new(0.7, -0.6, -0.5),
        color: [0.1, 0.3, 0.7],
    });
    check_scene(
        s,
        "cornell_noshadow_3_lights",
        None,
        Simulator::Verilator,
        Format::E7M16,
    );
}

#[test]
fn a_frame_that_cannot_finish_in_time_is_a_clear_timeout_error() {
    use dynrt::hw::program::{build_program, ProgramConfig};
    use dynrt::sim::processor::{simulate_processor, SimRun};
    let s = scene("cornell_noshadow.toml", 4, 3);
    let layouts = flow::scene_layouts(&s, Format::E7M16, None).unwrap();
    let p = build_program(&ProgramConfig::from_layout(&layouts[0]));
    let dir = tempfile::tempdir().unwrap();
    let e = simulate_processor(
        &p,
        &layouts,
        ProcessorParams::default(),
        "cornell_noshadow",
        SimRun {
            sim: Simulator::Verilator,
            cycle_limit: 500,
            capture_vga: false,
            trace: None,
        },
        dir.path(),
        &GeneratedBy::library(),
    )
    .unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("did not finish a frame within 500 clocks"),
        "{msg}"
    );
}

/// The display (VgaDisplay in the processor's top) sends the rendered frame to the monitor:
/// 640x480 at 60 Hz, each of the 20x12 pixels magnified to 32x32 and centred, black around
/// it, colour aligned with the raster to the pixel. Verilator only: a VGA frame is 420,000
/// pixel clocks (the timing generator alone is checked in Icarus too, in `sim::vga_timing`).
#[test]
fn the_display_shows_the_rendered_frame_magnified_and_centred() {
    use dynrt::hw::program::{build_program, ProgramConfig};
    use dynrt::hw::VgaMode;
    use dynrt::sim::processor::{simulate_processor, SimRun};
    let (w, h) = (20, 12);
    let s = scene("cornell_noshadow.toml", w, h);
    let layouts = flow::scene_layouts(&s, Format::E7M16, None).unwrap();
    let p = build_program(&ProgramConfig::from_layout(&layouts[0]));
    let dir = tempfile::tempdir().unwrap();
    let r = simulate_processor(
        &p,
        &layouts,
        ProcessorParams::default(),
        "cornell_noshadow",
        SimRun {
            sim: Simulator::Verilator,
            cycle_limit: 20_000_000,
            capture_vga: true,
            trace: None,
        },
        dir.path(),
        &GeneratedBy::library(),
    )
    .unwrap_or_else(|e| panic!("{e:#}"));
    let fb = &r.frames.last().unwrap().pixels;
    let mode = VgaMode::VGA_640X480_60;
    let place = mode.fit(w, h).unwrap();
    assert_eq!((place.scale, place.x0, place.y0), (32, 0, 48));
    let vga = r.vga.expect("a display capture");
    let (sw, sh) = (mode.h_visible, mode.v_visible);
    assert_eq!(vga.len(), (sw * sh) as usize);
    let mut wrong = Vec::new();
    for y in 0..sh {
        for x in 0..sw {
            let inside = (place.x0..place.x0 + place.width).contains(&x)
                && (place.y0..place.y0 + place.height).contains(&y);
            let want = if inside {
                let (fx, fy) = ((x - place.x0) / place.scale, (y - place.y0) / place.scale);
                fb[(fy * w + fx) as usize]
            } else {
                0
            };
            let got = vga[(y * sw + x) as usize];
            if got != want && wrong.len() < 5 {
                wrong.push((x, y, got, want));
            }
        }
    }
    assert!(wrong.is_empty(), "(x, y, shown, frame buffer): {wrong:x?}");
    assert!(
        fb.iter().filter(|&&c| c != 0).count() > fb.len() / 2,
        "the frame is not black"
    );
}
