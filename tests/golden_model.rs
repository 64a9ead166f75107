//! Whole-flow tests of the software half: scene -> accel -> layout -> golden / reference.

use dynrt::fp::Format;
use dynrt::layout::{self, MemoryConfig, SceneTrees};
use dynrt::model::{self, units, Frame, Reference};
use dynrt::scene::Scene;
use std::path::{Path, PathBuf};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn load(name: &str, w: u32, h: u32) -> Scene {
    let mut s = Scene::load(&scene_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    s.set_resolution(w, h).unwrap();
    s
}

fn golden(scene: &Scene, f: Format, frame: u32) -> Frame {
    let trees = SceneTrees::build(scene, f).unwrap();
    let l = layout::build(scene, &trees, frame, &MemoryConfig::default()).unwrap();
    model::render_golden(&l, false)
}

fn hit_metrics(a: &Frame, b: &Frame) -> dynrt::compare::HitMetrics {
    dynrt::compare::compare_hits(&a.hit_tuples(), &b.hit_tuples()).unwrap()
}

/// The bundled scenes at test resolutions.
const SCENES: [(&str, u32, u32); 6] = [
    ("tiny.toml", 16, 12),
    ("cornell.toml", 64, 48),
    ("cornell_noshadow.toml", 64, 48),
    ("mirror.toml", 64, 48),
    ("dynamic.toml", 64, 48),
    ("terrain.toml", 64, 48),
];

#[test]
fn golden_e8m23_hits_agree_with_the_f64_reference_on_every_bundled_scene() {
    for (name, w, h) in SCENES {
        let scene = load(name, w, h);
        let reference = Reference::new(&scene).render(0);
        let g = golden(&scene, Format::E8M23, 0);
        let m = hit_metrics(&g, &reference);
        let hits = g.hits.iter().filter(|h| h.is_some()).count();
        println!(
            "{name}: e8m23 identical hits {:.4}%, equivalent {:.4}% ({hits} hits of {})",
            100.0 * m.identical_ratio(),
            100.0 * m.equivalent_ratio(),
            g.hits.len()
        );
        assert!(
            hits > 0,
            "{name}: the camera sees nothing, the test would prove nothing"
        );
        assert!(
            m.equivalent_ratio() >= 0.999,
            "{name}: only {:.3}% of hits agree at e8m23",
            100.0 * m.equivalent_ratio()
        );
        let e716 = hit_metrics(&golden(&scene, Format::E7M16, 0), &reference);
        println!(
            "{name}: e7m16 identical hits {:.4}%, equivalent {:.4}%",
            100.0 * e716.identical_ratio(),
            100.0 * e716.equivalent_ratio()
        );
    }
}

#[test]
fn golden_images_are_close_to_the_reference_at_e8m23() {
    // Pixels whose primary rays hit different triangles (a ray through a shared edge, which
    // evaluation order decides) may take another surface's colour entirely; they are counted
    // and bounded, and the colour error is measured on the rest.
    for (name, w, h) in SCENES {
        let scene = load(name, w, h);
        let reference = Reference::new(&scene).render(0);
        let g = golden(&scene, Format::E8M23, 0);
        let mut masked = g.clone();
        let mut other_surface = 0;
        for i in 0..g.rgb.len() {
            let same = match (g.hits[i], reference.hits[i]) {
                (None, None) => true,
                (Some(a), Some(b)) => (a.instance, a.triangle) == (b.instance, b.triangle),
                _ => false,
            };
            if !same {
                masked.rgb[i] = reference.rgb[i];
                other_surface += 1;
            }
        }
        let all = dynrt::compare::compare_images(&g.to_image(), &reference.to_image()).unwrap();
        let m = dynrt::compare::compare_images(&masked.to_image(), &reference.to_image()).unwrap();
        println!(
            "{name}: PSNR {:.1} dB overall, {:.1} dB on the {} pixels that hit the same triangle; \
             max channel error {}, differing {:.3}%",
            all.psnr_db,
            m.psnr_db,
            g.rgb.len() - other_surface,
            m.max_channel_error,
            100.0 * m.differing_share()
        );
        assert!(
            other_surface * 50 <= g.rgb.len(),
            "{name}: {other_surface} pixels hit another triangle"
        );
        assert!(
            m.psnr_db > 40.0,
            "{name}: golden e8m23 PSNR {:.1} dB against the reference",
            m.psnr_db
        );
    }
}

#[test]
fn golden_closest_hits_equal_brute_force_over_every_triangle() {
    // The kd traversal (top level, instances, object trees, mailboxes, early termination) must
    // find the same closest hit as testing every triangle of every instance with the same
    // unit sequences.
    for (name, w, h) in [
        ("tiny.toml", 16, 12),
        ("cornell.toml", 32, 24),
        ("dynamic.toml", 32, 24),
    ] {
        let scene = load(name, w, h);
        let f = Format::E7M16;
        let trees = SceneTrees::build(&scene, f).unwrap();
        let l = layout::build(&scene, &trees, 0, &MemoryConfig::default()).unwrap();
        let g = model::Golden::new(&l);
        let camera: [u32; 12] = l.words(layout::FRAME, layout::FrameMap::CAMERA);
        let eye: [u32; 3] = l.words(layout::FRAME, layout::FrameMap::EYE);
        let mut disagree = 0;
        for y in 0..h {
            for x in 0..w {
                let d = units::primary_direction(f, &camera, x, y);
                let mut best: Option<u32> = None;
                for inst in 0..l.info.instance_count as usize {
                    let base = inst * layout::INSTANCE_WORDS;
                    let (o, dd) = if l.info.top_root.is_some() {
                        let m: [u32; 12] = l.words(layout::INSTANCES, base);
                        (
                            units::transform(f, &m, eye, true),
                            units::transform(f, &m, d, false),
                        )
                    } else {
                        (eye, d)
                    };
                    let obj = l.word(
                        layout::INSTANCES,
                        (base + layout::instance_word::OBJECT) as u32,
                    ) as usize;
                    let first = l.info.object_first_triangle[obj] as usize;
                    let count = scene.objects[obj].triangles.len();
                    for tri in first..first + count {
                        if trees.dropped[obj].contains(&((tri - first) as u32)) {
                            continue;
                        }
                        let m = l.triangle_transform(tri as u32);
                        let r = units::intersect(
                            f,
                            units::transform(f, &m, o, true),
                            units::transform(f, &m, dd, false),
                            0,
                            best.unwrap_or(f.infinity(false)),
                        );
                        if r.hit {
                            best = Some(r.t);
                        }
                    }
                }
                let kd = g.pixel(x, y).hit.map(|h| h.t);
                if kd != best {
                    disagree += 1;
                }
            }
        }
        println!(
            "{name}: kd traversal differs from brute force on {disagree} of {} pixels",
            w * h
        );
        assert_eq!(disagree, 0, "{name}");
    }
}

/// A small animated scene written for this test, and the same scene with frame `k`'s values
/// written directly (frames = 5, so every interpolated value below is exact in f64).
fn animated_scene_text(frame: Option<u32>) -> String {
    let lerp = |a: f64, b: f64, k: u32| a + (b - a) * f64::from(k) / 4.0;
    let mut text = String::from(
        r#"
[camera]
eye = [0.0, 2.0, 8.0]
look_at = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov_y = 45.0
width = 32
height = 24

[render]
shadows = true
reflection_depth = 1
ambient = 0.1

[[lights]]
position = [2.0, 6.0, 4.0]
color = [1.0, 1.0, 1.0]

[[objects]]
name = "ball"
generate = { kind = "sphere", subdivisions = 2 }
color = [0.8, 0.3, 0.2]

[[objects]]
name = "floor"
generate = { kind = "plane", size = [8.0, 8.0] }
mirror = 0.5
"#,
    );
    text.push_str("\n[[instances]]\nobject = \"floor\"\n");
    // Ball 1 moves along x and turns; ball 2 scales.
    let balls = [
        (
            [-2.0, 1.0, 0.0],
            [2.0, 1.0, -1.0],
            [0.0, 0.0, 0.0],
            [0.0, 90.0, 0.0],
            [1.0; 3],
            [1.0; 3],
        ),
        (
            [1.0, 1.0, 2.0],
            [1.0, 1.0, 2.0],
            [0.0; 3],
            [0.0; 3],
            [0.5, 0.5, 0.5],
            [1.0, 0.5, 1.5],
        ),
    ];
    for (t0, t1, r0, r1, s0, s1) in balls {
        text.push_str("\n[[instances]]\nobject = \"ball\"\n");
        let v = |a: [f64; 3], b: [f64; 3], k: u32| {
            [
                lerp(a[0], b[0], k),
                lerp(a[1], b[1], k),
                lerp(a[2], b[2], k),
            ]
        };
        match frame {
            None => {
                text.push_str(&format!(
                    "translate = {t0:?}\nrotate = {r0:?}\nscale = {s0:?}\n"
                ));
                text.push_str(&format!("[instances.animate]\nframes = 5\ntranslate = {t1:?}\nrotate = {r1:?}\nscale = {s1:?}\n"));
            }
            Some(k) => {
                text.push_str(&format!(
                    "translate = {:?}\nrotate = {:?}\nscale = {:?}\n",
                    v(t0, t1, k),
                    v(r0, r1, k),
                    v(s0, s1, k)
                ));
            }
        }
    }
    text
}

#[test]
fn animated_frame_k_equals_the_scene_built_with_frame_k_transforms() {
    let dir = tempfile::tempdir().unwrap();
    let animated =
        Scene::from_toml_str(&animated_scene_text(None), dir.path(), "animated.toml").unwrap();
    assert_eq!(animated.frames, 5);
    for k in [0, 1, 3, 4] {
        let direct =
            Scene::from_toml_str(&animated_scene_text(Some(k)), dir.path(), "direct.toml").unwrap();
        let a = golden(&animated, Format::E7M16, k);
        let b = golden(&direct, Format::E7M16, 0);
        assert_eq!(a.rgb, b.rgb, "frame {k}: pixels differ");
        assert_eq!(a.hits, b.hits, "frame {k}: hits differ");
        assert!(
            a.hits.iter().filter(|h| h.is_some()).count() > 100,
            "frame {k}: the balls and floor must be in view"
        );
    }
    // The frames really differ (the animation moves something).
    assert_ne!(
        golden(&animated, Format::E7M16, 0).rgb,
        golden(&animated, Format::E7M16, 4).rgb
    );
}

/// The cost of the edge margin at silhouettes: against the exact test (margin 0), the default
/// margin changes few primary hits, and it does not move the golden model away from the f64
/// reference (the pixels it changes at silhouettes, where grown triangles catch rays that
/// pass just outside, are offset by cracks it closes). Measured at 64x48: at most 11 of 3072
/// primary hits change (terrain e7m16, which gains 0.13 points of agreement), the worst loss is
/// 3 pixels, 0.10 points (dynamic e7m16); e8m23 changes at most 2. The bounds (1% of hits,
/// 0.2 points) leave twice that room.
#[test]
fn the_edge_margin_changes_few_pixels_and_keeps_agreement_with_the_reference() {
    for f in [Format::E7M16, Format::E8M23] {
        for (name, w, h) in SCENES {
            let scene = load(name, w, h);
            let reference = Reference::new(&scene).render(0);
            let trees = SceneTrees::build(&scene, f).unwrap();
            let l = layout::build(&scene, &trees, 0, &MemoryConfig::default()).unwrap();
            let with = model::render_golden(&l, false);
            let exact = model::render_with(&model::Golden::with_edge_margin(&l, 0.0), false);
            let changed_hits = (0..with.hits.len())
                .filter(|&i| {
                    with.hits[i].map(|h| (h.instance, h.triangle))
                        != exact.hits[i].map(|h| (h.instance, h.triangle))
                })
                .count();
            let changed_px = (0..with.rgb.len())
                .filter(|&i| with.rgb[i] != exact.rgb[i])
                .count();
            let (m_with, m_exact) = (
                hit_metrics(&with, &reference),
                hit_metrics(&exact, &reference),
            );
            println!(
                "{name} {f}: margin changes {changed_hits} primary hits and {changed_px} pixels of {}; \
                 equivalent hits vs f64 {:.4}% (margin 0: {:.4}%)",
                with.hits.len(),
                100.0 * m_with.equivalent_ratio(),
                100.0 * m_exact.equivalent_ratio()
            );
            assert!(
                changed_hits * 100 <= with.hits.len(),
                "{name} {f}: {changed_hits} hits changed"
            );
            assert!(
                m_with.equivalent_ratio() >= m_exact.equivalent_ratio() - 0.002,
                "{name} {f}: the margin moved the golden model away from the reference"
            );
        }
    }
}
