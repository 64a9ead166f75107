//! Tests of the memory images: text round trips, frame updates of the bundled animated
//! scene, and loading the files with `$readmemh` in Icarus and Verilator.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::PathBuf;

use super::*;
use crate::fp::Format;
use crate::layout::{
    self, MemoryConfig, SceneTrees, FRAME, INSTANCES, INSTANCE_WORDS, LISTS, NODES, TRIANGLES_A,
    TRIANGLES_B,
};
use crate::scene::Scene;
use crate::sim::{self, SimJob, Simulator};

fn animated_layouts() -> Vec<Layout> {
    scene_layouts("tiny_animated.toml", 3)
}

fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("dynrt-memh-{name}-"))
        .tempdir()
        .unwrap()
}

#[test]
fn memh_text_round_trips_with_gaps_and_comments() {
    let words = vec![
        (0, 0xdead_beef),
        (1, 0),
        (2, 7),
        (0x10, 0xffff_ffff),
        (0x11, 1),
        (0x400, 2),
    ];
    let text = memh_text("a header\nof two lines", &words);
    // Address records only where the sequence jumps; every word 8 digits.
    assert_eq!(
        text,
        "// a header\n// of two lines\n@0\ndeadbeef\n00000000\n00000007\n@10\nffffffff\n\
         00000001\n@400\n00000002\n"
    );
    assert_eq!(parse_memh(&text).unwrap(), words);
    // Hand-written Verilog syntax: block comments across lines, several words a line,
    // underscores, upper case, an address record without a leading word.
    let hand =
        "/* start\n still comment */ 1 2_0 // three\n@A ff /* x */ Ab_cd\n\n  @0000_0002 5\n";
    assert_eq!(
        parse_memh(hand).unwrap(),
        vec![(0, 1), (1, 0x20), (10, 0xff), (11, 0xabcd), (2, 5)]
    );
}

#[test]
fn bad_memh_is_refused_with_the_line() {
    let e = format!("{:#}", parse_memh("1\n2\nxx\n").unwrap_err());
    assert!(e.contains("line 3") && e.contains("xx"), "{e}");
    let e = format!("{:#}", parse_memh("123456789\n").unwrap_err());
    assert!(
        e.contains("line 1") && e.contains("wider than 32 bits"),
        "{e}"
    );
    let e = format!("{:#}", parse_memh("@\n").unwrap_err());
    assert!(e.contains("address record"), "{e}");
    let e = format!("{:#}", parse_memh("1 /* open\n2\n").unwrap_err());
    assert!(e.contains("unterminated"), "{e}");
    let dir = temp("missing");
    let missing = dir.path().join("nope.hex");
    let e = format!("{:#}", read_memh(&missing).unwrap_err());
    assert!(e.contains("nope.hex"), "{e}");
}

#[test]
fn extents_give_the_address_width() {
    let cases = [
        (0, None, 1),
        (1, Some(0), 1),
        (2, Some(1), 1),
        (3, Some(2), 2),
        (1024, Some(1023), 10),
        (1025, Some(1024), 11),
        (1 << 20, Some((1 << 20) - 1), 20),
    ];
    for (words, highest, bits) in cases {
        assert_eq!(
            BankExtent::of_words(words),
            BankExtent {
                words,
                highest,
                address_bits: bits
            },
            "{words} words"
        );
    }
    let l = &animated_layouts()[0];
    let e = bank_extents(l);
    assert_eq!(e.len(), 6);
    for (bank, ext) in e.iter().enumerate() {
        assert_eq!(ext.words as usize, l.banks[bank].len(), "bank {bank}");
    }
    // The frame bank ends with the 16x12 frame buffer.
    assert_eq!(e[FRAME].words, l.info.frame_buffer + 16 * 12);
}

#[test]
fn images_read_back_to_the_layout_words() {
    let l = &animated_layouts()[0];
    let dir = temp("images");
    let paths = write_memory_images(l, dir.path(), &GeneratedBy::library()).unwrap();
    let names: Vec<String> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "bank0_nodes.hex",
            "bank1_lists.hex",
            "bank2_triangles_a.hex",
            "bank3_triangles_b.hex",
            "bank4_instances.hex",
            "bank5_frame.hex"
        ]
    );
    for (bank, path) in paths.iter().enumerate() {
        let back = read_memh(path).unwrap();
        let want: Vec<(u32, u32)> = l.banks[bank]
            .iter()
            .enumerate()
            .map(|(a, &w)| (a as u32, w))
            .collect();
        assert_eq!(back, want, "bank {bank}");
    }
    // No temporary files left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 6);
}

fn scene_layouts(name: &str, frames: u32) -> Vec<Layout> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let scene = Scene::load(&path).unwrap();
    assert!(scene.frames >= frames, "{name} has {} frames", scene.frames);
    let trees = SceneTrees::build(&scene, Format::E7M16).unwrap();
    (0..frames)
        .map(|f| layout::build(&scene, &trees, f, &MemoryConfig::default()).unwrap())
        .collect()
}

/// Checks what holds for every animated scene and returns the updates per frame: static banks
/// never change, every update is a real difference, and frame 0's image files plus the update
/// files, read back, give every frame's words exactly.
fn checked_updates(name: &str, layouts: &[Layout]) -> Vec<Vec<WordUpdate>> {
    let dir = temp("updates");
    let images = write_memory_images(&layouts[0], dir.path(), &GeneratedBy::library()).unwrap();
    // Memory as the simulation would hold it: frame 0's images read from the files.
    let mut memory: Vec<Vec<u32>> = images
        .iter()
        .map(|p| read_memh(p).unwrap().into_iter().map(|(_, w)| w).collect())
        .collect();
    let mut all = Vec::new();
    for f in 1..layouts.len() {
        let (prev, next) = (&layouts[f - 1], &layouts[f]);
        let updates = frame_update(prev, next).unwrap();
        let banks: BTreeSet<usize> = updates.iter().map(|u| u.bank).collect();
        for (bank, bank_name) in BANK_NAMES.iter().enumerate() {
            let n = updates.iter().filter(|u| u.bank == bank).count();
            println!(
                "{name} frame {} -> {f}: bank {bank} ({bank_name}): {n} of {} words change (was {})",
                f - 1,
                next.banks[bank].len(),
                prev.banks[bank].len()
            );
        }
        for bank in [TRIANGLES_A, TRIANGLES_B, FRAME] {
            assert!(
                !banks.contains(&bank),
                "frame {f}: static bank {bank} changed"
            );
            assert_eq!(prev.banks[bank], next.banks[bank]);
        }
        for u in &updates {
            assert_ne!(prev.banks[u.bank].get(u.addr as usize), Some(&u.word));
            assert_eq!(next.banks[u.bank][u.addr as usize], u.word);
        }
        // Only an instance's matrices and root pointer may change, never its triangle base
        // or object id.
        for u in updates.iter().filter(|u| u.bank == INSTANCES) {
            let field = u.addr as usize % INSTANCE_WORDS;
            assert!(
                field <= layout::instance_word::ROOT,
                "frame {f}: instance word {field} changed"
            );
        }

        let files =
            write_frame_update(prev, next, f as u32, dir.path(), &GeneratedBy::library()).unwrap();
        let file_banks: BTreeSet<usize> = files.iter().map(|(b, _)| *b).collect();
        assert_eq!(file_banks, banks);
        for (bank, path) in &files {
            assert_eq!(
                path.file_name().unwrap().to_string_lossy(),
                format!("frame{f}_bank{bank}_{}.hex", BANK_NAMES[*bank])
            );
            for (addr, word) in read_memh(path).unwrap() {
                let m = &mut memory[*bank];
                if m.len() <= addr as usize {
                    m.resize(addr as usize + 1, 0xdead_dead);
                }
                m[addr as usize] = word;
            }
        }
        for (bank, (m, want)) in memory.iter().zip(&next.banks).enumerate() {
            assert!(m.len() >= want.len(), "bank {bank}");
            assert_eq!(m[..want.len()], want[..], "frame {f} bank {bank}");
        }
        all.push(updates);
    }
    all
}

/// tiny_animated: three instances in one top-level leaf (the top-level tree is a single node
/// in every frame), so only the moving instances' matrices change.
#[test]
fn tiny_animated_updates_only_the_moving_instances_matrices() {
    let layouts = scene_layouts("tiny_animated.toml", 3);
    for l in &layouts {
        assert_eq!(
            (l.info.top_root, l.info.top_depth),
            (layouts[0].info.top_root, 0)
        );
    }
    for (f, updates) in checked_updates("tiny_animated", &layouts)
        .iter()
        .enumerate()
    {
        let banks: BTreeSet<usize> = updates.iter().map(|u| u.bank).collect();
        assert_eq!(banks, BTreeSet::from([INSTANCES]), "frame {}", f + 1);
        let moved: BTreeSet<u32> = updates
            .iter()
            .map(|u| u.addr / INSTANCE_WORDS as u32)
            .collect();
        // Instance 0 (the floor) stands still; the box (1) and the gem (2) move.
        assert_eq!(moved, BTreeSet::from([1, 2]), "frame {}", f + 1);
        assert!(updates
            .iter()
            .all(|u| (u.addr as usize % INSTANCE_WORDS) < layout::instance_word::ROOT));
    }
}

/// dynamic.toml (1,202 moving instances): the top-level tree changes between frames; it sits
/// after the object trees in NODES and LISTS, so the object trees and every instance's root
/// pointer stay put: the update rewrites the top-level tree, its lists and the instance
/// matrices only.
#[test]
fn dynamic_scene_updates_rewrite_only_the_top_level_and_the_instances() {
    let layouts = scene_layouts("dynamic.toml", 2);
    let updates = &checked_updates("dynamic", &layouts)[0];
    let (prev, next) = (&layouts[0], &layouts[1]);
    let top = prev.info.top_root.expect("instances need a top level");
    assert_eq!(
        next.info.top_root,
        Some(top),
        "the top-level root stays where it is"
    );
    let first_top_list = |l: &Layout| {
        // The top-level lists follow the object lists: the smallest list address of a
        // top-level leaf.
        (0..(l.banks[NODES].len() / 2) as u32)
            .filter(|&n| n >= top)
            .filter_map(|n| match l.node(n) {
                layout::Node::Leaf { list, count } if count > 0 => Some(list),
                _ => None,
            })
            .min()
            .unwrap_or(l.banks[LISTS].len() as u32)
    };
    let lists_start = first_top_list(prev).min(first_top_list(next));
    for u in updates {
        match u.bank {
            NODES => assert!(
                u.addr >= 2 * top,
                "node word {} below the top-level tree",
                u.addr
            ),
            LISTS => assert!(u.addr >= lists_start, "list word {} of an object", u.addr),
            INSTANCES => assert!(
                (u.addr as usize % INSTANCE_WORDS) < layout::instance_word::ROOT,
                "instance word {} beyond the matrices",
                u.addr
            ),
            b => panic!("bank {b} changed"),
        }
    }
    let nodes = updates.iter().filter(|u| u.bank == NODES).count();
    println!(
        "dynamic frame 0 -> 1: {} words in all, {nodes} of them in NODES (of {})",
        updates.len(),
        next.banks[NODES].len()
    );
    assert!(
        nodes > 0,
        "the top-level tree must change between these frames"
    );
}

#[test]
fn frame_update_refuses_layouts_of_different_formats() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/tiny_animated.toml");
    let scene = Scene::load(&path).unwrap();
    let other = Format::parse("e5m10").unwrap();
    let a = layout::build(
        &scene,
        &SceneTrees::build(&scene, Format::E7M16).unwrap(),
        0,
        &MemoryConfig::default(),
    )
    .unwrap();
    let b = layout::build(
        &scene,
        &SceneTrees::build(&scene, other).unwrap(),
        0,
        &MemoryConfig::default(),
    )
    .unwrap();
    let e = frame_update(&a, &b).unwrap_err().to_string();
    assert!(e.contains("e7m16") && e.contains("e5m10"), "{e}");
    assert!(frame_update(&a, &a).unwrap().is_empty());
}

/// A testbench that loads the six frame-0 images, prints every word, loads frame 1's update
/// files on top, and prints every word of the next layout again.
fn readmemh_bench(prev: &Layout, next: &Layout, updates: &[(usize, PathBuf)]) -> String {
    let mut tb = String::from("module tb;\n");
    let size = |b: usize| prev.banks[b].len().max(next.banks[b].len()).max(1);
    for b in 0..6 {
        let _ = writeln!(tb, "    reg [31:0] m{b} [0:{}];", size(b) - 1);
    }
    tb.push_str("    integer a;\n    initial begin\n");
    for b in 0..6 {
        let _ = writeln!(tb, "        $readmemh(\"{}\", m{b});", bank_file_name(b));
        let _ = writeln!(
            tb,
            "        for (a = 0; a < {}; a = a + 1) $display(\"R {b} %0d %h\", a, m{b}[a]);",
            prev.banks[b].len()
        );
    }
    for (b, path) in updates {
        let _ = writeln!(
            tb,
            "        $readmemh(\"{}\", m{b});",
            path.file_name().unwrap().to_string_lossy()
        );
    }
    for b in 0..6 {
        let _ = writeln!(
            tb,
            "        for (a = 0; a < {}; a = a + 1) $display(\"U {b} %0d %h\", a, m{b}[a]);",
            next.banks[b].len()
        );
    }
    tb.push_str("        $finish;\n    end\nendmodule\n");
    tb
}

fn readmemh_in(simulator: Simulator) {
    let layouts = animated_layouts();
    let (prev, next) = (&layouts[0], &layouts[1]);
    let dir = temp(simulator.name());
    write_memory_images(prev, dir.path(), &GeneratedBy::library()).unwrap();
    // A frame 0 -> 1 update in which the frame grows or shrinks still loads: the memories
    // are sized for the larger of the two.
    let updates = write_frame_update(prev, next, 1, dir.path(), &GeneratedBy::library()).unwrap();
    assert!(!updates.is_empty());
    let tb_path = dir.path().join("tb_readmemh.v");
    std::fs::write(&tb_path, readmemh_bench(prev, next, &updates)).unwrap();
    let compiled = sim::compile(simulator, &SimJob::new(dir.path(), vec![tb_path], "tb")).unwrap();
    let ran = compiled
        .run(&[], std::time::Duration::from_secs(300))
        .unwrap();
    let log = format!("{}{}{}", compiled.compile_log, ran.stdout, ran.stderr);
    assert!(
        !log.to_ascii_lowercase().contains("warning"),
        "{simulator} warned:\n{}",
        log.lines()
            .filter(|l| l.to_ascii_lowercase().contains("warning"))
            .take(10)
            .collect::<Vec<_>>()
            .join("\n")
    );
    let (mut reads, mut updated) = (0, 0);
    for line in ran.stdout.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() != 4 || !(f[0] == "R" || f[0] == "U") {
            continue;
        }
        let bank: usize = f[1].parse().unwrap();
        let addr: usize = f[2].parse().unwrap();
        let word = u32::from_str_radix(f[3], 16)
            .unwrap_or_else(|_| panic!("{simulator}: `{line}`: not a defined word"));
        let want = if f[0] == "R" { prev } else { next };
        assert_eq!(word, want.banks[bank][addr], "{simulator}: {line}");
        if f[0] == "R" {
            reads += 1
        } else {
            updated += 1
        }
    }
    let total = |l: &Layout| l.banks.iter().map(Vec::len).sum::<usize>();
    assert_eq!((reads, updated), (total(prev), total(next)));
    println!("{simulator}: {reads} words loaded, {updated} checked after the update");
}

#[test]
fn readmemh_loads_images_and_updates_in_icarus() {
    readmemh_in(Simulator::Icarus);
}

#[test]
fn readmemh_loads_images_and_updates_in_verilator() {
    readmemh_in(Simulator::Verilator);
}
