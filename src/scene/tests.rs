//! Scene loading tests: bundled scenes, public meshes, animation, and one test per validation
//! error. Expected counts come from the generator formulas or from parsing files independently.

use std::path::{Path, PathBuf};

use glam::{DAffine3, DQuat, DVec3, EulerRot};

use super::*;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bundled(name: &str) -> Scene {
    let path = repo().join("scenes").join(name);
    let s = Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    println!(
        "{name}: {} objects, {} triangles, {} instances, {} instanced triangles, {} frames, {}x{}",
        s.objects.len(),
        s.triangle_count(),
        s.instances.len(),
        s.instanced_triangle_count(),
        s.frames,
        s.camera.width,
        s.camera.height
    );
    s
}

const CAMERA: &str = "[camera]\neye = [0.0, 1.0, 3.5]\nlook_at = [0.0, 1.0, 0.0]\nfov_y = 40.0\nwidth = 8\nheight = 6\n";

/// Scene text with the default camera prepended, parsed with `dir` as base directory.
fn parse_in(dir: &Path, body: &str) -> Result<Scene, SceneError> {
    Scene::from_toml_str(&format!("{CAMERA}{body}"), dir, "test.toml")
}

fn parse(body: &str) -> Result<Scene, SceneError> {
    parse_in(Path::new("."), body)
}

/// The error of a scene that must fail, as displayed.
fn fail(body: &str) -> (SceneError, String) {
    fail_in(Path::new("."), body)
}

fn fail_in(dir: &Path, body: &str) -> (SceneError, String) {
    match parse_in(dir, body) {
        Ok(_) => panic!("scene should have been rejected:\n{body}"),
        Err(e) => {
            let s = e.to_string();
            println!("{s}");
            (e, s)
        }
    }
}

/// Line (1-based) of the first line of the full scene text containing `needle`.
fn line_of(body: &str, needle: &str) -> usize {
    let full = format!("{CAMERA}{body}");
    full.lines().position(|l| l.contains(needle)).unwrap() + 1
}

const SPHERE: &str =
    "[[objects]]\nname = \"ball\"\ngenerate = { kind = \"sphere\", subdivisions = 1 }\n";

// ---------------------------------------------------------------- bundled scenes

#[test]
fn bundled_cornell_scenes() {
    let s = bundled("cornell.toml");
    let n = bundled("cornell_noshadow.toml");
    // Cornell box: 5 walls x 2 + 2 blocks x 5 faces x 2.
    assert_eq!(s.triangle_count(), 5 * 2 + 2 * 5 * 2);
    assert_eq!(s.instances.len(), 1);
    assert!(s.is_single_untransformed_object());
    assert_eq!((s.camera.width, s.camera.height), (64, 48));
    assert_eq!(s.frames, 1);
    assert!(s.render.shadows);
    assert!(!n.render.shadows);
    assert_eq!(n.camera, s.camera);
    assert_eq!(n.objects, s.objects);
    assert_eq!(n.lights, s.lights);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.source, repo().join("scenes/cornell.toml"));
}

#[test]
fn bundled_mirror_scene() {
    let s = bundled("mirror.toml");
    assert!(s.render.reflection_depth >= 1);
    assert_eq!(s.triangle_count(), 30 + 20 * 4usize.pow(2));
    assert_eq!(s.instances.len(), 2);
    let ball = &s.objects[s.object_index("ball").unwrap()];
    assert!(ball.materials.iter().all(|m| m.mirror == 0.9));
    let room = &s.objects[s.object_index("room").unwrap()];
    assert_eq!(room.materials[3].mirror, 0.8);
}

#[test]
fn bundled_dynamic_scene() {
    let s = bundled("dynamic.toml");
    let field = 40 * 30;
    assert!(field >= 1000);
    assert_eq!(s.instances.len(), 2 + field);
    // plane 2, sphere s=1 80, box 12, sphere s=0 20.
    assert_eq!(s.triangle_count(), 2 + 20 * 4 + 12 + 20);
    assert_eq!(s.frames, 8);
    let mut uses = vec![0usize; s.objects.len()];
    for i in &s.instances {
        uses[i.object] += 1;
    }
    assert!(uses.iter().all(|&u| u > 0), "{uses:?}");
    let by_hand: usize = uses
        .iter()
        .zip(&s.objects)
        .map(|(u, o)| u * o.triangles.len())
        .sum();
    assert_eq!(s.instanced_triangle_count(), by_hand);
    // Everything in the field moves: frame 7 differs from frame 0 for every field instance.
    let moving = s
        .instances
        .iter()
        .filter(|i| i.object_to_world(0) != i.object_to_world(7))
        .count();
    assert_eq!(moving, field + 1);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn bundled_terrain_scene() {
    let s = bundled("terrain.toml");
    assert_eq!(s.triangle_count(), 2 * 256 * 256);
    assert!(s.triangle_count() >= 100_000);
    assert!(s.is_single_untransformed_object());
}

#[test]
fn bundled_terrain_small_scene() {
    let s = bundled("terrain_small.toml");
    assert_eq!(s.triangle_count(), 2 * 72 * 72);
    assert!(s.triangle_count() >= 10_000, "the CI-sized large object");
    assert!(s.is_single_untransformed_object());
}

#[test]
fn bundled_tiny_scenes() {
    let s = bundled("tiny.toml");
    // plane 2 + box 12 + icosahedron 20 + pyramid (4 sides + 1 quad base = 6)
    assert_eq!(s.triangle_count(), 2 + 12 + 20 + 6);
    assert_eq!(s.instances.len(), 4);
    assert_eq!((s.camera.width, s.camera.height), (16, 12));
    let pyr = &s.objects[s.object_index("pyramid").unwrap()];
    // pyramid.mtl: gold (Kd .9 .7 .2, illum 2), mirror (Ks .8, illum 3); first face is mirror.
    assert_eq!(pyr.triangle_material, vec![1, 0, 0, 0, 0, 0]);
    assert_eq!(pyr.materials[0].mirror, 0.0);
    assert!((pyr.materials[1].mirror - 0.8).abs() < 1e-6);
    assert!((pyr.materials[0].diffuse[1] - 0.7).abs() < 1e-6);
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);

    let a = bundled("tiny_animated.toml");
    assert_eq!(a.triangle_count(), 2 + 12 + 20);
    assert_eq!(a.instances.len(), 3);
    assert_eq!(a.frames, 3);
}

#[test]
fn every_bundled_scene_is_tested() {
    let mut names: Vec<String> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "cornell.toml",
            "cornell_noshadow.toml",
            "dynamic.toml",
            "mirror.toml",
            "terrain.toml",
            "terrain_small.toml",
            "tiny.toml",
            "tiny_animated.toml"
        ]
    );
    for n in &names {
        let text = std::fs::read_to_string(repo().join("scenes").join(n)).unwrap();
        assert!(
            text.starts_with("# "),
            "{n} must open with a comment saying its purpose"
        );
    }
}

/// The checked-in `scenes/paper/` are what `dynrt paper-scenes` writes, and scenes/README.md's
/// table of them states their counts.
#[test]
fn paper_scenes_are_current_and_counted_in_the_readme() {
    let dir = repo().join("scenes").join("paper");
    let files = paper::suite_files();
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    let mut expected: Vec<String> = files.iter().map(|(n, _)| n.clone()).collect();
    expected.sort();
    assert_eq!(on_disk, expected, "scenes/paper/ holds exactly the suite");
    for (name, text) in &files {
        let have = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(
            &have == text,
            "scenes/paper/{name} is stale: run `make paper-scenes`"
        );
    }
    let readme = std::fs::read_to_string(repo().join("scenes").join("README.md")).unwrap();
    let rows: Vec<Vec<String>> = readme
        .lines()
        .filter(|l| l.starts_with("| `paper/"))
        .map(|l| l.split('|').map(|c| c.trim().replace(',', "")).collect())
        .collect();
    assert_eq!(rows.len(), files.len(), "one README row per scene");
    for row in rows {
        let file = row[1].trim_matches('`');
        let s = bundled(file);
        let number = |k: usize| row[k].parse::<usize>().unwrap();
        assert_eq!(number(3), s.instances.len(), "{file}: objects");
        assert_eq!(number(4), s.triangle_count(), "{file}: unique triangles");
        assert_eq!(
            number(5),
            s.instanced_triangle_count(),
            "{file}: instanced triangles"
        );
    }
}

// ---------------------------------------------------------------- public meshes

/// Parses an OBJ without tobj: fan-triangulated faces in file order with their `usemtl` name.
fn parse_obj_by_hand(path: &Path) -> Vec<([DVec3; 3], Option<String>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut v: Vec<DVec3> = Vec::new();
    let mut mtl = None;
    let mut out = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first().copied() {
            Some("v") => {
                let c: Vec<f64> = w[1..4].iter().map(|s| s.parse::<f64>().unwrap()).collect();
                v.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("usemtl") => mtl = Some(w[1].to_string()),
            Some("f") => {
                let idx: Vec<usize> = w[1..]
                    .iter()
                    .map(|s| {
                        let i: i64 = s.split('/').next().unwrap().parse().unwrap();
                        if i < 0 {
                            (v.len() as i64 + i) as usize
                        } else {
                            (i - 1) as usize
                        }
                    })
                    .collect();
                for k in 1..idx.len() - 1 {
                    out.push(([v[idx[0]], v[idx[k]], v[idx[k + 1]]], mtl.clone()));
                }
            }
            _ => {}
        }
    }
    out
}

#[test]
fn public_meshes_load_in_file_order() {
    let dir = tempfile::tempdir().unwrap();
    let mut names: Vec<PathBuf> = std::fs::read_dir(super::shared_mesh_dir())
        .expect("public meshes in ../shared/scenes/meshes")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    names.sort();
    assert!(names.len() >= 10);
    for path in names {
        let text = format!("[[objects]]\nname = \"m\"\nmesh = \"{}\"\n", path.display());
        let scene_path = dir.path().join("s.toml");
        std::fs::write(&scene_path, format!("{CAMERA}{text}")).unwrap();
        let s = Scene::load(&scene_path).unwrap_or_else(|e| panic!("{e}"));
        let by_hand = parse_obj_by_hand(&path);
        let kept: Vec<[DVec3; 3]> = by_hand
            .iter()
            .map(|(t, _)| *t)
            .filter(|t| !is_degenerate(t))
            .collect();
        let dropped = by_hand.len() - kept.len();
        let o = &s.objects[0];
        println!(
            "{}: {} faces-triangles, {} kept, {} degenerate",
            path.display(),
            by_hand.len(),
            o.triangles.len(),
            dropped
        );
        assert_eq!(o.triangles.len(), kept.len(), "{}", path.display());
        assert!(o.triangles == kept, "{}: triangles differ", path.display());
        assert_eq!(o.triangle_material.len(), o.triangles.len());
        let warned = s.warnings.iter().any(|w| w.contains("degenerate"));
        assert_eq!(warned, dropped > 0, "{:?}", s.warnings);
        if dropped > 0 {
            assert!(s
                .warnings
                .iter()
                .any(|w| w.contains(&format!("dropped {dropped} "))));
        }
        if path.file_name().unwrap() == "cornell_box.obj" {
            // 18 `f` lines, all quads (the front wall's face is commented out): 36 triangles.
            assert_eq!(by_hand.len(), 36);
            let kd = |name: &str| match name {
                "white" | "light" => [1.0, 1.0, 1.0],
                "red" => [1.0, 0.0, 0.0],
                "green" => [0.0, 1.0, 0.0],
                "blue" => [0.0, 0.0, 1.0],
                other => panic!("{other}"),
            };
            for (k, (_, m)) in by_hand.iter().enumerate() {
                let got = o.material_of(k);
                assert_eq!(got.diffuse, kd(m.as_deref().unwrap()), "triangle {k}");
                assert_eq!(got.mirror, 0.0);
            }
            assert!(o
                .triangle_material
                .iter()
                .any(|&m| o.materials[m as usize].diffuse == [1.0, 0.0, 0.0]));
        }
    }
}

// ---------------------------------------------------------------- instances and animation

#[test]
fn animation_matches_matrix_built_from_interpolated_values() {
    let body = format!(
        "{SPHERE}[[instances]]\nobject = \"ball\"\ntranslate = [1.0, 2.0, 3.0]\nrotate = [10.0, 20.0, 30.0]\nscale = [1.0, 2.0, 0.5]\n[instances.animate]\nframes = 5\ntranslate = [-3.0, 2.0, 11.0]\nrotate = [10.0, 200.0, -50.0]\nscale = [3.0, 1.0, 0.25]\n\n[[instances]]\nobject = \"ball\"\nname = \"still\"\n"
    );
    let s = parse(&body).unwrap();
    assert_eq!(s.frames, 5);
    assert_eq!(s.instances[0].name, "ball#0");
    assert_eq!(s.instances[1].name, "still");
    for k in 0..5u32 {
        let f = f64::from(k) / 4.0;
        let lerp = |a: f64, b: f64| a + (b - a) * f;
        let t = DVec3::new(lerp(1.0, -3.0), 2.0, lerp(3.0, 11.0));
        let r = DVec3::new(10.0, lerp(20.0, 200.0), lerp(30.0, -50.0));
        let sc = DVec3::new(lerp(1.0, 3.0), lerp(2.0, 1.0), lerp(0.5, 0.25));
        // Independent construction: glam's intrinsic ZYX Euler = Rz * Ry * Rx.
        let q = DQuat::from_euler(
            EulerRot::ZYX,
            r.z.to_radians(),
            r.y.to_radians(),
            r.x.to_radians(),
        );
        let want = DAffine3::from_scale_rotation_translation(sc, q, t);
        let got = s.instances[0].object_to_world(k);
        assert!(
            got.abs_diff_eq(want, 1e-12),
            "frame {k}: {got:?} vs {want:?}"
        );
        assert_eq!(s.instances[1].object_to_world(k), DAffine3::IDENTITY);
    }
    assert!(!s.is_single_untransformed_object());
}

#[test]
fn frozen_frames_and_world_bounds() {
    let s = bundled("tiny_animated.toml");
    for k in 0..s.frames {
        let f = s.at_frame(k);
        assert_eq!(f.frames, 1);
        for (a, b) in s.instances.iter().zip(&f.instances) {
            assert!(b.animation.is_none());
            assert_eq!(a.object_to_world(k), b.object_to_world(0));
            assert_eq!(b.object_to_world(0), b.object_to_world(5));
        }
    }
    // Box instance: unit cube translated to (-0.9, 0.55, 0) at frame 0.
    let (lo, hi) = s.instance_world_bounds(1, 0);
    assert!((lo - DVec3::new(-1.4, 0.05, -0.5)).length() < 1e-12, "{lo}");
    assert!((hi - DVec3::new(-0.4, 1.05, 0.5)).length() < 1e-12, "{hi}");
    // At the last frame it is turned 60 degrees about Y: the x extent is cos 60 + sin 60.
    let (lo, hi) = s.instance_world_bounds(1, 2);
    let half = 0.5 * (60f64.to_radians().cos() + 60f64.to_radians().sin());
    assert!((lo.x - (-0.3 - half)).abs() < 1e-12 && (hi.x - (-0.3 + half)).abs() < 1e-12);
    assert!((hi.y - 1.05).abs() < 1e-12);
}

#[test]
fn no_instances_places_each_object_once() {
    let s = parse(&format!(
        "{SPHERE}[[objects]]\nname = \"cube\"\ngenerate = {{ kind = \"box\" }}\n"
    ))
    .unwrap();
    assert_eq!(s.instances.len(), 2);
    assert_eq!(s.instances[1].object, 1);
    assert_eq!(s.instances[1].name, "cube");
    assert!(s.instances.iter().all(|i| i.is_static_identity()));
    assert!(!s.is_single_untransformed_object(), "two objects");
    assert_eq!(s.triangle_count(), 80 + 12);
    assert_eq!(s.instanced_triangle_count(), 80 + 12);
    assert!(s.warnings.iter().any(|w| w.contains("no [[lights]]")));
    assert_eq!(s.render.ambient, 0.1);
    assert!(s.render.shadows);
}

#[test]
fn field_expands_after_explicit_instances() {
    let body = format!(
        "{SPHERE}[[objects]]\nname = \"unused\"\ngenerate = {{ kind = \"box\" }}\n[[instances]]\nobject = \"ball\"\n[[fields]]\nobject = \"ball\"\ncount_x = 3\ncount_z = 2\nspacing = 2.0\nanimate = {{ frames = 4, translate_by = [0.0, 1.0, 0.0] }}\n"
    );
    let s = parse(&body).unwrap();
    assert_eq!(s.instances.len(), 1 + 6);
    assert_eq!(s.instances[1].name, "field0[0,0]");
    assert_eq!(
        s.instances[1].transform.translate,
        DVec3::new(-2.0, 0.0, -1.0)
    );
    assert_eq!(
        s.instances[6].transform.translate,
        DVec3::new(2.0, 0.0, 1.0)
    );
    assert_eq!(s.frames, 4);
    assert_eq!(
        s.instances[6].object_to_world(3).translation,
        DVec3::new(2.0, 1.0, 1.0)
    );
    assert!(s
        .warnings
        .iter()
        .any(|w| w.contains("'unused'") && w.contains("never instanced")));
}

#[test]
fn material_override_on_mesh_and_generator() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let s = parse_in(
        dir.path(),
        "[[objects]]\nname = \"t\"\nmesh = \"t.obj\"\n[[objects]]\nname = \"u\"\nmesh = \"t.obj\"\nmirror = 0.5\n[[objects]]\nname = \"b\"\ngenerate = { kind = \"box\" }\ncolor = [0.1, 0.2, 0.3]\n",
    )
    .unwrap();
    assert_eq!(s.objects[0].materials, vec![Material::DEFAULT]);
    assert_eq!(
        s.objects[1].materials,
        vec![Material {
            diffuse: [0.8; 3],
            mirror: 0.5
        }]
    );
    assert_eq!(s.objects[2].materials[0].diffuse, [0.1, 0.2, 0.3]);
    assert!(s.objects[2].triangle_material.iter().all(|&m| m == 0));
}

#[test]
fn resolution_override() {
    let mut s = parse(SPHERE).unwrap();
    s.set_resolution(320, 240).unwrap();
    assert_eq!((s.camera.width, s.camera.height), (320, 240));
    let e = s.set_resolution(0, 240).unwrap_err();
    assert!(matches!(e.problem, Problem::Resolution { .. }));
    assert!(s.set_resolution(4097, 10).is_err());
    assert_eq!((s.camera.width, s.camera.height), (320, 240));
}

// ---------------------------------------------------------------- degenerate triangles

#[test]
fn degenerate_triangles_are_counted_and_dropped() {
    let dir = tempfile::tempdir().unwrap();
    // Triangles: good(red), repeated vertex(red), good(blue), collinear(blue), good(blue).
    std::fs::write(
        dir.path().join("d.mtl"),
        "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("d.obj"),
        "mtllib d.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 0 0 1\nusemtl red\nf 1 2 3\nf 1 2 2\nusemtl blue\nf 1 3 5\nf 1 2 4\nf 2 3 5\n",
    )
    .unwrap();
    let s = parse_in(dir.path(), "[[objects]]\nname = \"d\"\nmesh = \"d.obj\"\n").unwrap();
    let o = &s.objects[0];
    assert_eq!(o.triangles.len(), 3);
    let v = |x, y, z| DVec3::new(x, y, z);
    assert_eq!(
        o.triangles[1],
        [v(0., 0., 0.), v(0., 1., 0.), v(0., 0., 1.)]
    );
    // Materials stay with their triangles after the drop.
    let colours: Vec<[f64; 3]> = (0..3).map(|k| o.material_of(k).diffuse).collect();
    assert_eq!(colours, vec![[1., 0., 0.], [0., 0., 1.], [0., 0., 1.]]);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("'d'") && w.contains("dropped 2 degenerate triangle(s) of 5")),
        "{:?}",
        s.warnings
    );
}

// ---------------------------------------------------------------- validation errors

#[test]
fn error_toml_syntax_and_unknown_key() {
    let (e, s) = fail("[render\nshadows = true\n");
    assert!(matches!(e.problem, Problem::Toml(_)));
    assert!(s.starts_with("test.toml:7:"), "{s}");
    let body = "[render]\nshadow = true\n";
    let (_, s) = fail(body);
    assert!(
        s.contains(&format!("test.toml:{}:", line_of(body, "shadow ="))),
        "{s}"
    );
    assert!(s.contains("unknown field `shadow`"), "{s}");
    let (_, s) = fail("[[objects]]\nname = \"x\"\ngenerate = { kind = \"cone\" }\n");
    assert!(s.contains("unknown variant `cone`"), "{s}");
}

#[test]
fn error_unknown_object() {
    let body = format!("{SPHERE}[[instances]]\nobject = \"bal\"\n");
    let (e, s) = fail(&body);
    assert!(matches!(e.problem, Problem::UnknownObject { .. }));
    assert_eq!(e.line, Some(line_of(&body, "object = \"bal\"")));
    assert!(s.contains("test.toml:"), "{s}");
    assert!(
        s.contains("instance 'bal#0'") && s.contains("'bal'") && s.contains("ball"),
        "{s}"
    );
    let body = format!("{SPHERE}[[fields]]\nobjects = [\"ball\", \"nope\"]\ncount_x = 2\ncount_z = 2\nspacing = 1.0\n");
    let (e, s) = fail(&body);
    assert!(matches!(e.problem, Problem::UnknownObject { .. }));
    assert!(s.contains("field 'field0'") && s.contains("'nope'"), "{s}");
}

#[test]
fn error_duplicate_object() {
    let body = format!("{SPHERE}{SPHERE}");
    let (e, s) = fail(&body);
    match e.problem {
        Problem::DuplicateObject { first_line, .. } => {
            assert_eq!(first_line, line_of(&body, "name = \"ball\""))
        }
        ref p => panic!("{p:?}"),
    }
    assert!(
        s.contains("object 'ball'") && s.contains("duplicate"),
        "{s}"
    );
}

#[test]
fn error_object_source() {
    let (e, _) = fail("[[objects]]\nname = \"x\"\n");
    assert!(matches!(e.problem, Problem::ObjectSource));
    let (e, _) =
        fail("[[objects]]\nname = \"x\"\nmesh = \"a.obj\"\ngenerate = { kind = \"box\" }\n");
    assert!(matches!(e.problem, Problem::ObjectSource));
    let (e, s) = fail(
        "[[objects]]\nname = \"x\"\ngenerate = { kind = \"cornell_box\" }\ncolor = [1.0, 0.0, 0.0]\n",
    );
    assert!(matches!(e.problem, Problem::Invalid { .. }));
    assert!(s.contains("cornell_box"), "{s}");
}

#[test]
fn error_missing_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let body = "[[objects]]\nname = \"bunny\"\nmesh = \"no_such.obj\"\n";
    let (e, s) = fail_in(dir.path(), body);
    assert!(matches!(e.problem, Problem::Input(_)), "{e}");
    assert_eq!(e.line, Some(line_of(body, "mesh =")));
    assert!(
        s.contains("object 'bunny'") && s.contains("no_such.obj"),
        "{s}"
    );
    // A missing scene file.
    let e = Scene::load(&dir.path().join("missing.toml")).unwrap_err();
    assert!(matches!(e.problem, Problem::Input(_)), "{e}");
    assert!(e.to_string().contains("missing.toml") && e.to_string().contains("does not exist"));
}

#[test]
fn error_missing_mtl() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("m.obj"),
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    )
    .unwrap();
    let (e, s) = fail_in(dir.path(), "[[objects]]\nname = \"m\"\nmesh = \"m.obj\"\n");
    assert!(matches!(e.problem, Problem::Input(_)), "{s}");
    assert!(
        s.contains("gone.mtl") && s.contains("does not exist") && s.contains("object 'm'"),
        "{s}"
    );
}

#[test]
fn error_broken_obj_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("v 0 0 0\nv 1 0 zero\nv 0 1 0\nf 1 2 3\n", 2, "not a number"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, "out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "at least 3"),
        ("v 0 0\n", 1, "has 2 numbers"),
        ("v 0 0 0 1 junk\n", 1, "'junk' is not a number"),
        (
            "\u{feff}v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 4\r",
            4,
            "out of range",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//2 2//1 3//1\n",
            5,
            "normal index 2 is out of range",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n",
            4,
            "texture coordinate index 1 is out of range",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n",
            4,
            "has 4 parts",
        ),
        ("v 0 0 0 0\n", 1, "w = 0"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n", 4, "out of range"),
    ];
    for (obj, line, what) in cases {
        std::fs::write(dir.path().join("b.obj"), obj).unwrap();
        let (e, s) = fail_in(dir.path(), "[[objects]]\nname = \"b\"\nmesh = \"b.obj\"\n");
        assert!(matches!(e.problem, Problem::BrokenObj(_)), "{s}");
        assert_eq!(e.line, Some(line), "{s}");
        assert!(e.file.ends_with("b.obj"), "{s}");
        assert!(s.contains(what) && s.contains("object 'b'"), "{s}");
    }
}

#[test]
fn error_non_finite_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("n.obj"),
        "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let (e, s) = fail_in(dir.path(), "[[objects]]\nname = \"n\"\nmesh = \"n.obj\"\n");
    assert!(matches!(e.problem, Problem::NonFinite { .. }));
    assert_eq!(e.line, Some(2));
    assert!(s.contains("n.obj:2") && s.contains("not finite"), "{s}");
    // 1e309 is beyond f64 (the OBJ loader reads f64).
    std::fs::write(
        dir.path().join("n.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1e309 0\nf 1 2 3\n",
    )
    .unwrap();
    let (e, _) = fail_in(dir.path(), "[[objects]]\nname = \"n\"\nmesh = \"n.obj\"\n");
    assert!(matches!(e.problem, Problem::NonFinite { .. }));

    let camera_nan = "[camera]\neye = [nan, 1.0, 3.5]\nlook_at = [0.0, 1.0, 0.0]\nfov_y = 40.0\nwidth = 8\nheight = 6\n";
    let e = Scene::from_toml_str(camera_nan, Path::new("."), "cam.toml").unwrap_err();
    assert!(matches!(e.problem, Problem::NonFinite { .. }));
    assert_eq!(e.line, Some(2));
    assert!(e.to_string().contains("camera") && e.to_string().contains("eye"));

    for (body, needle) in [
        (format!("{SPHERE}[[instances]]\nobject = \"ball\"\ntranslate = [inf, 0.0, 0.0]\n"), "translate"),
        (format!("{SPHERE}[[instances]]\nobject = \"ball\"\nrotate = [0.0, nan, 0.0]\n"), "rotate"),
        (format!("{SPHERE}[[instances]]\nobject = \"ball\"\n[instances.animate]\nframes = 2\nscale = [1.0, inf, 1.0]\n"), "scale = [1.0, inf"),
        (format!("{SPHERE}[[lights]]\nposition = [0.0, -inf, 0.0]\n"), "position"),
        (format!("{SPHERE}[[fields]]\nobject = \"ball\"\ncount_x = 2\ncount_z = 2\nspacing = nan\n"), "spacing"),
        ("[[objects]]\nname = \"s\"\ngenerate = { kind = \"sphere\", radius = nan }\n".to_string(), "radius"),
    ] {
        let (e, s) = fail(&body);
        assert!(
            matches!(e.problem, Problem::NonFinite { .. } | Problem::Invalid { .. }),
            "{s}"
        );
        assert_eq!(e.line, Some(line_of(&body, needle)), "{s}");
    }
}

#[test]
fn error_empty_mesh() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("e.obj"),
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n",
    )
    .unwrap();
    let (e, s) = fail_in(dir.path(), "[[objects]]\nname = \"e\"\nmesh = \"e.obj\"\n");
    match e.problem {
        Problem::EmptyMesh { faces, degenerate } => assert_eq!((faces, degenerate), (2, 2)),
        ref p => panic!("{p:?}"),
    }
    assert!(s.contains("e.obj") && s.contains("object 'e'"), "{s}");
    std::fs::write(dir.path().join("e.obj"), "# nothing\nv 0 0 0\n").unwrap();
    let (e, _) = fail_in(dir.path(), "[[objects]]\nname = \"e\"\nmesh = \"e.obj\"\n");
    assert!(matches!(e.problem, Problem::EmptyMesh { faces: 0, .. }));
}

fn camera_with(fields: &str) -> String {
    let mut c = vec![
        ("eye", "[0.0, 1.0, 3.5]"),
        ("look_at", "[0.0, 1.0, 0.0]"),
        ("up", "[0.0, 1.0, 0.0]"),
        ("fov_y", "40.0"),
        ("width", "8"),
        ("height", "6"),
    ];
    for kv in fields.split(';') {
        let (k, v) = kv.split_once('=').unwrap();
        for e in c.iter_mut() {
            if e.0 == k.trim() {
                e.1 = v.trim();
            }
        }
    }
    let mut s = "[camera]\n".to_string();
    for (k, v) in c {
        s += &format!("{k} = {v}\n");
    }
    s + SPHERE
}

fn fail_camera(fields: &str) -> (SceneError, String) {
    let text = camera_with(fields);
    let e = Scene::from_toml_str(&text, Path::new("."), "cam.toml").unwrap_err();
    let s = e.to_string();
    println!("{s}");
    assert!(s.starts_with("cam.toml:") && s.contains("camera: "), "{s}");
    (e, s)
}

#[test]
fn error_resolution() {
    for (f, line) in [
        ("width = 0", 6),
        ("height = 0", 7),
        ("width = 4097", 6),
        ("height = 100000", 7),
    ] {
        let (e, _) = fail_camera(f);
        assert!(matches!(e.problem, Problem::Resolution { max: 4096, .. }));
        assert_eq!(e.line, Some(line), "{f}");
    }
    let e =
        Scene::from_toml_str(&camera_with("width = -3"), Path::new("."), "cam.toml").unwrap_err();
    assert!(matches!(e.problem, Problem::Toml(_)));
    assert_eq!(e.line, Some(6));
    assert!(Scene::from_toml_str(
        &camera_with("width = 4096; height = 4096"),
        Path::new("."),
        "c"
    )
    .is_ok());
}

#[test]
fn error_field_of_view() {
    for f in [
        "fov_y = 0.0",
        "fov_y = 180.0",
        "fov_y = -10.0",
        "fov_y = 200.0",
    ] {
        let (e, s) = fail_camera(f);
        assert!(matches!(e.problem, Problem::FieldOfView(_)), "{s}");
        assert_eq!(e.line, Some(5));
        assert!(s.contains("(0, 180)"));
    }
    assert!(Scene::from_toml_str(&camera_with("fov_y = 179.0"), Path::new("."), "c").is_ok());
}

#[test]
fn error_eye_at_look_at_and_up_parallel() {
    let (e, _) = fail_camera("look_at = [0.0, 1.0, 3.5]");
    assert!(matches!(e.problem, Problem::EyeAtLookAt(_)));
    let (e, s) = fail_camera("up = [0.0, 0.0, -2.0]");
    assert!(matches!(e.problem, Problem::UpParallel { .. }), "{s}");
    assert_eq!(e.line, Some(4));
    let (e, _) = fail_camera("up = [0.0, 0.0, 0.0]");
    assert!(matches!(e.problem, Problem::UpParallel { .. }));
    let (e, _) = fail_camera("eye = [0.0, 5.0, 0.0]; look_at = [0.0, 0.0, 0.0]");
    assert!(matches!(e.problem, Problem::UpParallel { .. }));
}

#[test]
fn error_zero_scale() {
    let body = format!("{SPHERE}[[instances]]\nobject = \"ball\"\nscale = [1.0, 0.0, 1.0]\n");
    let (e, s) = fail(&body);
    assert!(matches!(e.problem, Problem::ZeroScale { .. }));
    assert_eq!(e.line, Some(line_of(&body, "scale =")));
    assert!(s.contains("instance 'ball#0'"), "{s}");
    let body = format!("{SPHERE}[[instances]]\nobject = \"ball\"\n[instances.animate]\nframes = 3\nscale = [0.0, 1.0, 1.0]\n");
    let (e, _) = fail(&body);
    assert!(matches!(e.problem, Problem::ZeroScale { .. }));
    let body = format!("{SPHERE}[[instances]]\nobject = \"ball\"\nscale = [1.0, 1.0, 2.0]\n[instances.animate]\nframes = 3\nscale = [1.0, 1.0, -2.0]\n");
    let (e, _) = fail(&body);
    assert!(matches!(e.problem, Problem::ScaleCrossesZero { .. }));
    // A negative scale that keeps its sign is a mirror image, not an error.
    let ok = format!("{SPHERE}[[instances]]\nobject = \"ball\"\nscale = [-1.0, 1.0, 1.0]\n[instances.animate]\nframes = 3\nscale = [-2.0, 1.0, 1.0]\n");
    assert!(parse(&ok).is_ok());
}

#[test]
fn error_negative_light_colour() {
    let body =
        format!("{SPHERE}[[lights]]\nposition = [0.0, 2.0, 0.0]\ncolor = [1.0, -0.5, 1.0]\n");
    let (e, s) = fail(&body);
    assert!(matches!(e.problem, Problem::NegativeLightColor(_)));
    assert_eq!(e.line, Some(line_of(&body, "color =")));
    assert!(s.contains("light 0"), "{s}");
}

#[test]
fn error_reflection_depth() {
    let body = format!("{SPHERE}[render]\nreflection_depth = 9\n");
    let (e, s) = fail(&body);
    assert!(matches!(
        e.problem,
        Problem::ReflectionDepth { depth: 9, max: 8 }
    ));
    assert_eq!(e.line, Some(line_of(&body, "reflection_depth")));
    assert!(s.contains("render"), "{s}");
    assert!(parse(&format!("{SPHERE}[render]\nreflection_depth = 8\n")).is_ok());
}

#[test]
fn error_other_ranges() {
    for (body, needle, what) in [
        (format!("{SPHERE}[[instances]]\nobject = \"ball\"\n[instances.animate]\nframes = 1\n"), "frames", "animate.frames"),
        ("[[objects]]\nname = \"s\"\ngenerate = { kind = \"sphere\", subdivisions = 9 }\n".to_string(), "subdivisions", "sphere subdivisions"),
        ("[[objects]]\nname = \"t\"\ngenerate = { kind = \"terrain\", size = 0 }\n".to_string(), "terrain", "terrain size"),
        (format!("{SPHERE}mirror = 1.5\n"), "mirror", "mirror"),
        (format!("{SPHERE}color = [0.5, -1.0, 0.0]\n"), "color", "color"),
        (format!("{SPHERE}[render]\nambient = -0.1\n"), "ambient", "ambient"),
        (format!("{SPHERE}[[fields]]\nobject = \"ball\"\ncount_x = 0\ncount_z = 2\nspacing = 1.0\n"), "count_x", "count_x * count_z"),
        (format!("{SPHERE}[[fields]]\nobject = \"ball\"\ncount_x = 2\ncount_z = 2\nspacing = 1.0\njitter = 1.0\n"), "jitter", "jitter"),
        (format!("{SPHERE}[[fields]]\ncount_x = 2\ncount_z = 2\nspacing = 1.0\n"), "[[fields]]", "object/objects"),
    ] {
        let (e, s) = fail(&body);
        match &e.problem {
            Problem::Invalid { what: w, .. } => assert_eq!(w, what, "{s}"),
            p => panic!("{p:?}"),
        }
        assert_eq!(e.line, Some(line_of(&body, needle)), "{s}");
    }
}

/// Seeded mutation fuzzing of the scene and OBJ/MTL parsers: random edits of valid files (bytes
/// flipped, lines cut, duplicated or swapped, hostile numbers spliced into number positions)
/// must give a scene or a `SceneError` naming a file, never a panic, and a scene they give must
/// pass through the processor's preflight, trees and memory map without a panic. Bounded: a
/// fixed number of cases from a fixed seed, a few seconds in release.
mod fuzz {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const HOSTILE: [&str; 16] = [
        "2048",
        "1000000",
        "nan",
        "inf",
        "-inf",
        "1e39",
        "-1e39",
        "1e-39",
        "1e300",
        "0",
        "-0",
        "4294967296",
        "-1",
        "1e400",
        "0x10",
        "\u{feff}",
    ];

    fn mutate(rng: &mut ChaCha8Rng, text: &str) -> String {
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        for _ in 0..rng.gen_range(1..4) {
            if lines.is_empty() {
                break;
            }
            let i = rng.gen_range(0..lines.len());
            match rng.gen_range(0..6) {
                0 => {
                    lines.remove(i);
                }
                1 => {
                    let l = lines[i].clone();
                    lines.insert(rng.gen_range(0..=lines.len()), l);
                }
                2 => {
                    let j = rng.gen_range(0..lines.len());
                    lines.swap(i, j);
                }
                3 => {
                    // A hostile number in place of a number-looking word.
                    let words: Vec<String> = lines[i]
                        .split(' ')
                        .map(|w| {
                            let numeric = w.trim_matches(|c| c == ',' || c == '[' || c == ']');
                            if numeric.parse::<f64>().is_ok() && rng.gen_bool(0.5) {
                                w.replace(numeric, HOSTILE[rng.gen_range(0..HOSTILE.len())])
                            } else {
                                w.to_string()
                            }
                        })
                        .collect();
                    lines[i] = words.join(" ");
                }
                4 => {
                    let cut = rng.gen_range(0..=lines[i].len());
                    let cut = (0..=cut)
                        .rev()
                        .find(|&c| lines[i].is_char_boundary(c))
                        .unwrap_or(0);
                    lines[i].truncate(cut);
                }
                _ => {
                    let mut bytes = lines[i].clone().into_bytes();
                    if !bytes.is_empty() {
                        let k = rng.gen_range(0..bytes.len());
                        bytes[k] = rng.gen_range(b' '..=b'~');
                    }
                    lines[i] = String::from_utf8(bytes).unwrap();
                }
            }
        }
        let sep = ["\n", "\r\n", "\r"][rng.gen_range(0..3)];
        lines.join(sep)
    }

    /// What every verb does with an accepted scene next: the processor's preflight, the trees
    /// and the memory map of frame 0 (which refuse values the format cannot hold). None of it
    /// may panic on a scene that validation let through.
    fn build_survives(scene: &Scene) -> Result<(), String> {
        let f = crate::fp::Format::E7M16;
        let built = std::panic::catch_unwind(|| {
            let params = crate::emit::processor::ProcessorParams::default();
            if crate::flow::preflight(scene, f, params, None).is_err() {
                return;
            }
            if let Ok(trees) = crate::layout::SceneTrees::build(scene, f) {
                let _ =
                    crate::layout::build(scene, &trees, 0, &crate::layout::MemoryConfig::default());
            }
        });
        built.map_err(|_| "accepted, then panicked while building its layout".to_string())
    }

    fn load_survives(path: &Path) -> Result<(), String> {
        match std::panic::catch_unwind(|| Scene::load(path)) {
            Err(_) => Err("panicked".into()),
            Ok(Ok(scene)) => build_survives(&scene),
            Ok(Err(e)) => {
                let text = e.to_string();
                if e.file.as_os_str().is_empty() || !text.starts_with(&e.file.display().to_string())
                {
                    Err(format!("error names no file: {text}"))
                } else {
                    Ok(())
                }
            }
        }
    }

    #[test]
    fn mutated_scenes_and_meshes_give_a_scene_or_an_error_never_a_panic() {
        let scene = format!(
            "{CAMERA}[render]\nshadows = true\nreflection_depth = 1\nambient = 0.1\n\
             [[lights]]\nposition = [0.0, 1.9, 0.8]\ncolor = [1.0, 1.0, 1.0]\n\
             [[objects]]\nname = \"m\"\nmesh = \"m.obj\"\n\
             [[objects]]\nname = \"g\"\ngenerate = {{ kind = \"sphere\", subdivisions = 1 }}\n\
             [[instances]]\nobject = \"m\"\ntranslate = [0.0, 0.5, 0.0]\nscale = [1.0, 1.0, 1.0]\n\
             [instances.animate]\nframes = 3\nrotate = [0.0, 90.0, 0.0]\n\
             [[instances]]\nobject = \"g\"\nscale = [0.3, 0.3, 0.3]\n"
        );
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0 1\nvt 0 0\nvt 1 0\nvn 0 0 1\n\
                   usemtl a\nf 1/1/1 2/2/1 3/1/1\nf -1 -2 -3\nf 2//1 4//1 3//1\n";
        let mtl = "newmtl a\nKd 0.8 0.2 0.2\nKs 0.5 0.5 0.5\nillum 3\nNs 10\nd 1\n";
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("s.toml"), &scene).unwrap();
        std::fs::write(d.join("m.obj"), obj).unwrap();
        std::fs::write(d.join("m.mtl"), mtl).unwrap();
        load_survives(&d.join("s.toml")).expect("the unmutated files load");
        let mut rng = ChaCha8Rng::seed_from_u64(0xF022);
        let mut failures = Vec::new();
        // Silence the default hook's backtrace printing for the caught panics; restored after.
        let hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        for case in 0..1500 {
            let (s, o, m) = match case % 3 {
                0 => (mutate(&mut rng, &scene), obj.to_string(), mtl.to_string()),
                1 => (scene.clone(), mutate(&mut rng, obj), mtl.to_string()),
                _ => (scene.clone(), obj.to_string(), mutate(&mut rng, mtl)),
            };
            std::fs::write(d.join("s.toml"), &s).unwrap();
            std::fs::write(d.join("m.obj"), &o).unwrap();
            std::fs::write(d.join("m.mtl"), &m).unwrap();
            if let Err(e) = load_survives(&d.join("s.toml")) {
                failures.push(format!(
                    "case {case}: {e}\n--- scene\n{s}\n--- obj\n{o}\n--- mtl\n{m}"
                ));
            }
        }
        std::panic::set_hook(hook);
        assert!(
            failures.is_empty(),
            "{} of 1500 cases failed; first:\n{}",
            failures.len(),
            failures[0]
        );
    }
}
