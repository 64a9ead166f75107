//! The record every output folder of `rtl`, `sim`, `demo`, `bench` and `stress` gets
//! (docs/ARCHITECTURE.md, "Run reports"): `summary.json` for machines, `report.md` for people,
//! and for `sim` and `stress` `junit.xml`, which CI systems read.
//!
//! Contract:
//! - [`RunSummary`] holds what the run was (dynrt version and commit, the command line, the
//!   tools and their versions, the scene and its options), what it made (what was generated,
//!   what left out), what it found (frames with cycles, rays and pass/fail; named checks with
//!   pass/fail) and the files in the folder.
//! - [`RunSummary::write`] lists the folder's files (relative paths, sorted; simulator build
//!   folders `build_*` are not outputs and are left out), then writes the three files
//!   atomically, all or none; they list themselves.
//! - `pass` is false when any frame or check failed; the CLI's exit status says the same
//!   (1 when it is false).
//! - JUnit XML is written by the `quick-junit` crate (the serializer of cargo-nextest's JUnit
//!   output, maintained and escaping every string), one test suite per run, one test case per
//!   frame and check.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;

use crate::provenance::GeneratedBy;

/// The scene a run was made from.
#[derive(Clone, Debug, Serialize)]
pub struct SceneInfo {
    pub path: PathBuf,
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub triangles: usize,
    pub instances: usize,
    /// Frames of the scene (an animation's length).
    pub frames: u32,
}

impl SceneInfo {
    pub fn of(scene: &crate::scene::Scene, name: &str) -> SceneInfo {
        SceneInfo {
            path: scene.source.clone(),
            name: name.to_string(),
            width: scene.camera.width,
            height: scene.camera.height,
            triangles: scene.triangle_count(),
            instances: scene.instances.len(),
            frames: scene.frames,
        }
    }
}

/// One simulated frame of the processor.
#[derive(Clone, Debug, Serialize)]
pub struct FrameResult {
    pub frame: usize,
    pub simulator: String,
    pub cycles: u64,
    pub instructions: u64,
    /// Primary rays (pixels).
    pub rays: u64,
    pub cycles_per_ray: f64,
    pub differing_pixels: usize,
    pub pass: bool,
}

/// One named check of a run (an operator in a simulator, a stress invariant, a benchmark).
#[derive(Clone, Debug, Serialize)]
pub struct CheckResult {
    pub name: String,
    pub pass: bool,
    /// What was found, one line.
    pub detail: String,
    pub seconds: Option<f64>,
}

/// What a run was, made and found; see the module doc.
#[derive(Clone, Debug, Serialize)]
pub struct RunSummary {
    /// The verb: `rtl`, `sim`, `demo`, `bench scenes`, `stress`, ...
    pub verb: String,
    pub pass: bool,
    pub dynrt_version: String,
    pub commit: Option<String>,
    pub command: Option<String>,
    /// Tool name -> version, for the tools the run used.
    pub tools: BTreeMap<String, String>,
    pub scene: Option<SceneInfo>,
    /// Option name -> value, as the run used them (defaults included).
    pub options: BTreeMap<String, serde_json::Value>,
    /// What was generated, one entry a part.
    pub generated: Vec<String>,
    /// What the generator left out for this scene.
    pub left_out: Vec<String>,
    pub frames: Vec<FrameResult>,
    pub checks: Vec<CheckResult>,
    /// Free remarks (figures that fit no other field), one line each.
    pub notes: Vec<String>,
    /// Every file in the output folder, relative to it, sorted.
    pub files: Vec<String>,
    /// Markdown of the verb's own (placed in `report.md` after the run's table).
    #[serde(skip)]
    pub details_md: String,
}

/// The files [`RunSummary::write`] writes.
pub const SUMMARY_JSON: &str = "summary.json";
pub const REPORT_MD: &str = "report.md";
pub const JUNIT_XML: &str = "junit.xml";

impl RunSummary {
    pub fn new(verb: &str, generated_by: &GeneratedBy) -> RunSummary {
        RunSummary {
            verb: verb.to_string(),
            pass: true,
            dynrt_version: generated_by.version.clone(),
            commit: generated_by.commit.clone(),
            command: generated_by.command.clone(),
            tools: BTreeMap::new(),
            scene: None,
            options: BTreeMap::new(),
            generated: Vec::new(),
            left_out: Vec::new(),
            frames: Vec::new(),
            checks: Vec::new(),
            notes: Vec::new(),
            files: Vec::new(),
            details_md: String::new(),
        }
    }

    /// Records an option's value.
    pub fn option(&mut self, name: &str, value: impl Serialize) -> &mut Self {
        let v = serde_json::to_value(value).unwrap_or(serde_json::Value::Null);
        self.options.insert(name.to_string(), v);
        self
    }

    pub fn add_frame(&mut self, f: FrameResult) {
        self.pass &= f.pass;
        self.frames.push(f);
    }

    pub fn add_check(&mut self, name: &str, pass: bool, detail: &str, seconds: Option<f64>) {
        self.pass &= pass;
        self.checks.push(CheckResult {
            name: name.to_string(),
            pass,
            detail: detail.to_string(),
            seconds,
        });
    }

    /// The summary as pretty JSON.
    pub fn json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a run summary serializes")
    }

    /// The summary for people.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let verdict = if self.pass { "PASS" } else { "FAIL" };
        let _ = writeln!(md, "# dynrt {}: {verdict}\n", self.verb);
        let _ = writeln!(md, "| | |\n|---|---|");
        let _ = writeln!(md, "| dynrt | {} |", self.dynrt_version);
        let _ = writeln!(
            md,
            "| commit | {} |",
            self.commit.as_deref().unwrap_or("(not known)")
        );
        if let Some(c) = &self.command {
            let _ = writeln!(md, "| command | `{}` |", c.replace('|', "\\|"));
        }
        for (tool, version) in &self.tools {
            let _ = writeln!(md, "| {tool} | {version} |");
        }
        if let Some(s) = &self.scene {
            let _ = writeln!(
                md,
                "| scene | `{}` ({}): {}x{} pixels, {} triangles, {} instances, {} frame(s) |",
                s.path.display(),
                s.name,
                s.width,
                s.height,
                s.triangles,
                s.instances,
                s.frames
            );
        }
        for (name, value) in &self.options {
            let _ = writeln!(md, "| --{} | {value} |", name.replace('_', "-"));
        }
        if !self.details_md.is_empty() {
            let _ = writeln!(md, "\n{}", self.details_md.trim_end());
        }
        let list = |md: &mut String, title: &str, items: &[String]| {
            if !items.is_empty() {
                let _ = writeln!(md, "\n## {title}\n");
                for i in items {
                    let _ = writeln!(md, "- {i}");
                }
            }
        };
        list(&mut md, "Generated", &self.generated);
        list(&mut md, "Left out", &self.left_out);
        if !self.frames.is_empty() {
            let _ = writeln!(
                md,
                "\n## Frames\n\n| frame | simulator | cycles | instructions | rays | cycles per ray | differing pixels | result |\n|---|---|---|---|---|---|---|---|"
            );
            for f in &self.frames {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {:.1} | {} | {} |",
                    f.frame,
                    f.simulator,
                    f.cycles,
                    f.instructions,
                    f.rays,
                    f.cycles_per_ray,
                    f.differing_pixels,
                    if f.pass { "pass" } else { "FAIL" }
                );
            }
        }
        if !self.checks.is_empty() {
            let _ = writeln!(
                md,
                "\n## Checks\n\n| check | result | detail |\n|---|---|---|"
            );
            for c in &self.checks {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} |",
                    c.name,
                    if c.pass { "pass" } else { "FAIL" },
                    c.detail.replace('|', "\\|")
                );
            }
        }
        list(&mut md, "Notes", &self.notes);
        list(&mut md, "Files", &self.files);
        md
    }

    /// The frames and checks as JUnit XML: one suite named after the verb (and the scene).
    pub fn junit_xml(&self) -> Result<String> {
        use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};
        let suite_name = match &self.scene {
            Some(s) => format!("dynrt {} {}", self.verb, s.name),
            None => format!("dynrt {}", self.verb),
        };
        let mut suite = TestSuite::new(suite_name.clone());
        let status = |pass: bool, message: &str| {
            if pass {
                TestCaseStatus::success()
            } else {
                let mut s = TestCaseStatus::non_success(NonSuccessKind::Failure);
                s.set_message(message.to_string());
                s
            }
        };
        for f in &self.frames {
            let mut case = TestCase::new(
                format!("frame {} ({})", f.frame, f.simulator),
                status(
                    f.pass,
                    &format!("{} pixels differ from the golden model", f.differing_pixels),
                ),
            );
            case.set_classname(suite_name.clone());
            suite.add_test_case(case);
        }
        for c in &self.checks {
            let mut case = TestCase::new(c.name.clone(), status(c.pass, &c.detail));
            case.set_classname(suite_name.clone());
            if let Some(s) = c.seconds {
                case.set_time(std::time::Duration::from_secs_f64(s.max(0.0)));
            }
            suite.add_test_case(case);
        }
        let mut report = Report::new(suite_name);
        report.add_test_suite(suite);
        report.to_string().context("writing JUnit XML")
    }

    /// Lists `out`'s files and writes `summary.json`, `report.md` and (with `junit`)
    /// `junit.xml` into it, all or none.
    pub fn write(&mut self, out: &Path, junit: bool) -> Result<()> {
        let mut own = vec![SUMMARY_JSON, REPORT_MD];
        if junit {
            own.push(JUNIT_XML);
        }
        let mut files = list_files(out)?;
        files.extend(own.iter().map(|s| s.to_string()));
        files.sort();
        files.dedup();
        self.files = files;
        let json = self.json();
        let md = self.markdown();
        let xml = if junit {
            self.junit_xml()?
        } else {
            String::new()
        };
        let (pj, pm, px) = (
            out.join(SUMMARY_JSON),
            out.join(REPORT_MD),
            out.join(JUNIT_XML),
        );
        let mut writes: Vec<(&Path, &[u8])> = vec![(&pj, json.as_bytes()), (&pm, md.as_bytes())];
        if junit {
            writes.push((&px, xml.as_bytes()));
        }
        crate::output::write_all_atomically(&writes)
    }
}

/// The files below `dir`, relative and sorted, without simulator build folders (`build_*`)
/// and dynrt's temporary files.
pub fn list_files(dir: &Path) -> Result<Vec<String>> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) -> Result<()> {
        for e in std::fs::read_dir(dir).with_context(|| format!("listing {}", dir.display()))? {
            let e = e?;
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("build_") || name.starts_with(".dynrt-partial-") {
                continue;
            }
            let p = e.path();
            if e.file_type()?.is_dir() {
                walk(root, &p, out)?;
            } else {
                let rel = p.strip_prefix(root).unwrap_or(&p);
                out.push(rel.to_string_lossy().into_owned());
            }
        }
        Ok(())
    }
    let mut files = Vec::new();
    if dir.is_dir() {
        walk(dir, dir, &mut files)?;
    }
    files.sort();
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> RunSummary {
        let g = GeneratedBy {
            version: "1.2.3".into(),
            commit: Some("abc".into()),
            command: Some("dynrt sim s.toml --out o".into()),
        };
        let mut s = RunSummary::new("sim", &g);
        s.tools.insert("verilator".into(), "5.006".into());
        s.option("threads", 32);
        s.add_frame(FrameResult {
            frame: 0,
            simulator: "verilator".into(),
            cycles: 100,
            instructions: 50,
            rays: 4,
            cycles_per_ray: 25.0,
            differing_pixels: 0,
            pass: true,
        });
        s
    }

    #[test]
    fn one_failed_frame_or_check_fails_the_run_and_its_junit_case() {
        let mut s = sample();
        assert!(s.pass);
        s.add_check(
            "add <in> iverilog & co",
            false,
            "3 of 10 results differ",
            Some(1.5),
        );
        assert!(!s.pass);
        let xml = s.junit_xml().unwrap();
        assert!(xml.contains("tests=\"2\""), "{xml}");
        assert!(xml.contains("failures=\"1\""), "{xml}");
        // Names are escaped, not pasted into the XML.
        assert!(xml.contains("add &lt;in&gt; iverilog &amp; co"), "{xml}");
        assert!(xml.contains("3 of 10 results differ"), "{xml}");
        let md = s.markdown();
        assert!(md.starts_with("# dynrt sim: FAIL"), "{md}");
        assert!(md.contains("| --threads | 32 |"), "{md}");
    }

    #[test]
    fn write_lists_the_folder_and_itself_but_not_build_folders() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("rtl")).unwrap();
        std::fs::write(dir.path().join("rtl/a.v"), "x").unwrap();
        std::fs::create_dir_all(dir.path().join("build_tb_x")).unwrap();
        std::fs::write(dir.path().join("build_tb_x/Vtb"), "x").unwrap();
        let mut s = sample();
        s.write(dir.path(), true).unwrap();
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join(SUMMARY_JSON)).unwrap())
                .unwrap();
        assert_eq!(
            j["files"],
            serde_json::json!(["junit.xml", "report.md", "rtl/a.v", "summary.json"])
        );
        assert_eq!(j["frames"][0]["cycles"], 100);
        assert_eq!(j["commit"], "abc");
        assert_eq!(j["pass"], true);
    }
}
