//! Tests of the UCF writer: exact clock lines, board files, error cases, and a structural
//! check of every line (no tool here reads UCF).

use super::*;

fn ports() -> Vec<Port> {
    vec![
        Port::clock("clock", 90e6),
        Port::clock("vga_clock", 25.175e6),
        Port::io("reset", 1, PortDirection::Input),
        Port::io("vga_hsync", 1, PortDirection::Output),
        Port::io("vga_vsync", 1, PortDirection::Output),
        Port::io("vga_red", 8, PortDirection::Output),
        Port::io("sram0_addr", 20, PortDirection::Output),
        Port::io("sram0_data", 32, PortDirection::Inout),
    ]
}

const SAMPLE_BOARD: &str = r#"
# Illustrative only: not the ADM-XRC-II pinout.
name = "test board"
part = "xc2v6000-ff1152-4"

[pins]
clock = "ak17"
vga_hsync = "B12"
"sram0_addr<3>" = "C7"
"sram0_addr<19>" = "AP34"

[iostandard]
sram0_data = "LVCMOS33"
"#;

fn board(text: &str) -> Result<BoardPins> {
    parse_board(text, Path::new("boards/test.toml"))
}

/// Checks that every line is a comment, blank, or one of the statement forms we write, and
/// that every group and net it names is defined / is a port bit.
fn check_structure(ucf: &str, ports: &[Port]) {
    let bits: BTreeSet<String> = ports.iter().flat_map(Port::bit_names).collect();
    let buses: BTreeSet<String> = ports
        .iter()
        .filter(|p| p.width > 1)
        .map(|p| format!("{}<*>", p.name))
        .collect();
    let mut groups = BTreeSet::new();
    let mut used_groups = Vec::new();
    let quoted = |s: &str| -> String {
        assert!(
            s.starts_with('"') && s.ends_with('"') && s.len() >= 2,
            "not quoted: {s}"
        );
        s[1..s.len() - 1].to_string()
    };
    let number = |s: &str| {
        let v: f64 = s.parse().unwrap_or_else(|_| panic!("not a number: {s}"));
        assert!(
            v > 0.0 && s.split('.').nth(1).map_or(0, str::len) == 3,
            "{s}"
        );
    };
    for line in ucf.lines() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        assert!(t.ends_with(';'), "statement without ';': {t}");
        let w: Vec<&str> = t[..t.len() - 1].split_whitespace().collect();
        match w.as_slice() {
            ["CONFIG", "PART", "=", part] => assert_eq!(*part, "xc2v6000-ff1152-4"),
            ["NET", net, "TNM_NET", "=", group] => {
                assert!(bits.contains(&quoted(net)), "{t}");
                groups.insert(quoted(group));
            }
            ["TIMESPEC", name, "=", "PERIOD", group, period, "ns", "HIGH", "50%"] => {
                assert!(quoted(name).starts_with("TS_"), "{t}");
                number(period);
                used_groups.push(quoted(group));
            }
            ["TIMESPEC", name, "=", "FROM", a, "TO", b, "TIG"] => {
                assert!(quoted(name).starts_with("TS_"), "{t}");
                used_groups.push(quoted(a));
                used_groups.push(quoted(b));
            }
            ["OFFSET", "=", "IN", v, "ns", "BEFORE", group]
            | ["OFFSET", "=", "OUT", v, "ns", "AFTER", group] => {
                number(v);
                used_groups.push(quoted(group));
            }
            ["NET", net, "IOSTANDARD", "=", standard] => {
                let n = quoted(net);
                assert!(bits.contains(&n) || buses.contains(&n), "{t}");
                assert!(VIRTEX2_IOSTANDARDS.contains(standard), "{t}");
            }
            ["NET", net, "LOC", "=", ball] => {
                assert!(bits.contains(&quoted(net)), "{t}");
                assert!(is_ball_name(&quoted(ball)), "{t}");
            }
            _ => panic!("unexpected UCF statement: {t}"),
        }
    }
    for g in used_groups {
        assert!(groups.contains(&g), "group {g} is used but not defined");
    }
}

#[test]
fn clock_periods_for_90_mhz_and_the_vga_pixel_clock() {
    let ucf = ucf_text(&ports(), &UcfOptions::default()).unwrap();
    println!("{ucf}");
    // 1 / 90 MHz = 11.111 ns; 1 / 25.175 MHz = 39.722 ns.
    assert!(ucf.contains(
        "NET \"clock\" TNM_NET = \"clock\";\nTIMESPEC \"TS_clock\" = PERIOD \"clock\" 11.111 ns HIGH 50%;\n"
    ));
    assert!(ucf.contains(
        "NET \"vga_clock\" TNM_NET = \"vga_clock\";\nTIMESPEC \"TS_vga_clock\" = PERIOD \"vga_clock\" 39.722 ns HIGH 50%;\n"
    ));
    assert!(
        ucf.contains("TIMESPEC \"TS_clock_to_vga_clock\" = FROM \"clock\" TO \"vga_clock\" TIG;")
    );
    assert!(
        ucf.contains("TIMESPEC \"TS_vga_clock_to_clock\" = FROM \"vga_clock\" TO \"clock\" TIG;")
    );
    assert!(ucf.starts_with("# Constraints for part xc2v6000-ff1152-4"));
    assert!(ucf.contains("CONFIG PART = xc2v6000-ff1152-4;"));
    // Default LVTTL on every port, buses with a wildcard.
    assert!(ucf.contains("NET \"vga_hsync\" IOSTANDARD = LVTTL;"));
    assert!(ucf.contains("NET \"sram0_data<*>\" IOSTANDARD = LVTTL;"));
    // Without a board file no pin is placed; all 1+1+1+1+1+8+20+32 bits are listed.
    assert!(!ucf.contains("LOC"));
    assert!(ucf.contains("for 65 port bit(s):\n#   clock\n#   vga_clock\n"));
    assert!(ucf.contains("\n#   sram0_data bits 0-31\n"));
    assert!(!ucf.contains("OFFSET"));
    check_structure(&ucf, &ports());
    assert_eq!(period_ns(65e6), "15.385");
}

#[test]
fn board_pins_and_standards_go_into_the_ucf() {
    let b = board(SAMPLE_BOARD).unwrap();
    assert_eq!(b.name.as_deref(), Some("test board"));
    assert_eq!(b.pins.len(), 4);
    assert_eq!(b.pins["clock"], "AK17", "ball names are upper-cased");
    let opts = UcfOptions {
        board: Some(b),
        iostandards: BTreeMap::from([
            ("vga_red".to_string(), "LVCMOS25".to_string()),
            ("sram0_data".to_string(), "LVCMOS18".to_string()),
        ]),
        offsets: vec![ClockOffsets {
            clock: "clock".into(),
            in_before_ns: Some(4.0),
            out_after_ns: Some(6.5),
        }],
        ..Default::default()
    };
    let ucf = ucf_text(&ports(), &opts).unwrap();
    println!("{ucf}");
    for line in [
        "NET \"clock\" LOC = \"AK17\";",
        "NET \"vga_hsync\" LOC = \"B12\";",
        "NET \"sram0_addr<3>\" LOC = \"C7\";",
        "NET \"sram0_addr<19>\" LOC = \"AP34\";",
        // The board's table wins over the options; the options over the default.
        "NET \"sram0_data<*>\" IOSTANDARD = LVCMOS33;",
        "NET \"vga_red<*>\" IOSTANDARD = LVCMOS25;",
        "NET \"reset\" IOSTANDARD = LVTTL;",
        "OFFSET = IN 4.000 ns BEFORE \"clock\";",
        "OFFSET = OUT 6.500 ns AFTER \"clock\";",
    ] {
        assert!(ucf.lines().any(|l| l == line), "missing `{line}`");
    }
    assert_eq!(ucf.matches(" LOC = ").count(), 4);
    assert!(ucf.contains("for 61 port bit(s):\n#   vga_clock\n#   reset\n#   vga_vsync\n"));
    assert!(ucf.contains("\n#   sram0_addr bits 0-2, 4-18\n"));
    check_structure(&ucf, &ports());

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.toml");
    std::fs::write(&path, SAMPLE_BOARD).unwrap();
    assert_eq!(
        load_board(&path).unwrap().pins,
        opts.board.as_ref().unwrap().pins
    );
    let out = dir.path().join("out/top.ucf");
    write_ucf(&out, &ports(), &opts).unwrap();
    assert_eq!(std::fs::read_to_string(&out).unwrap(), ucf);
}

fn board_error(text: &str) -> String {
    match board(text) {
        Err(e) => format!("{e:#}"),
        Ok(b) => {
            let opts = UcfOptions {
                board: Some(b),
                ..Default::default()
            };
            format!("{:#}", ucf_text(&ports(), &opts).unwrap_err())
        }
    }
}

#[test]
fn bad_board_files_are_refused_naming_file_and_entry() {
    let cases: [(&str, &[&str]); 9] = [
        (
            "[pins]\nvga_hsnyc = \"B12\"\n",
            &["vga_hsnyc", "no top-level port"],
        ),
        (
            "[pins]\n\"sram0_addr<20>\" = \"B12\"\n",
            &["sram0_addr<20>", "bits 0..20"],
        ),
        (
            "[pins]\nsram0_addr = \"B12\"\n",
            &["sram0_addr", "is a bus"],
        ),
        (
            "[pins]\n\"vga_hsync<0>\" = \"B12\"\n",
            &["vga_hsync<0>", "unknown port bit"],
        ),
        (
            "[pins]\nvga_hsync = \"12B\"\n",
            &["vga_hsync", "12B", "ball name"],
        ),
        ("[pins]\nvga_hsync = \"ABC1\"\n", &["ABC1", "ball name"]),
        (
            "[pins]\nvga_hsync = \"B12\"\nvga_vsync = \"b12\"\n",
            &["vga_hsync", "vga_vsync", "B12"],
        ),
        (
            "[iostandard]\nvga_red = \"LVCMOS12\"\n",
            &["vga_red", "LVCMOS12"],
        ),
        (
            "part = \"xc2v1000-fg456-4\"\n",
            &["xc2v1000-fg456-4", "xc2v6000-ff1152-4"],
        ),
    ];
    for (text, wants) in cases {
        let e = board_error(text);
        assert!(e.contains("boards/test.toml"), "{text}: {e}");
        for w in wants {
            assert!(e.contains(w), "{text}: `{w}` not in: {e}");
        }
    }
    // TOML syntax errors and unknown keys name the file too.
    for text in ["[pins\n", "pinz = {}\n", "[pins]\nclock = 3\n"] {
        let e = board_error(text);
        assert!(
            e.contains("boards/test.toml") && e.contains("not valid"),
            "{text}: {e}"
        );
    }
    let e = format!(
        "{:#}",
        load_board(Path::new("/nonexistent/b.toml")).unwrap_err()
    );
    assert!(e.contains("/nonexistent/b.toml"), "{e}");
}

#[test]
fn bad_ports_and_options_are_refused() {
    let o = UcfOptions::default();
    let e = ucf_text(&[Port::clock("clk", 0.0)], &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("clk") && e.contains("not positive"), "{e}");
    let e = ucf_text(
        &[
            Port::io("a", 1, PortDirection::Input),
            Port::io("a", 2, PortDirection::Output),
        ],
        &o,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("twice"), "{e}");
    let e = ucf_text(&[Port::io("a b", 1, PortDirection::Input)], &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("net name"), "{e}");
    let offsets = UcfOptions {
        offsets: vec![ClockOffsets {
            clock: "reset".into(),
            in_before_ns: Some(1.0),
            out_after_ns: None,
        }],
        ..Default::default()
    };
    let e = ucf_text(&ports(), &offsets).unwrap_err().to_string();
    assert!(e.contains("reset") && e.contains("not a clock"), "{e}");
    let standard = UcfOptions {
        default_iostandard: "TTL".into(),
        ..Default::default()
    };
    assert!(ucf_text(&ports(), &standard)
        .unwrap_err()
        .to_string()
        .contains("TTL"));
    assert!(["A1", "AP34", "K9"].iter().all(|b| is_ball_name(b)));
    assert!(["A0", "1A", "A", "A123", "AAA1", "A-1", ""]
        .iter()
        .all(|b| !is_ball_name(b)));
}
