//! `dynrt stress`: a seeded, reproducible suite that tries to break the arithmetic of the
//! golden model (and so of the hardware, which computes the same words), run for each number
//! format of interest plus the exact f64 caster.
//!
//! Cases (see [`cases`] for what counts as a failure):
//! - `edge_rays`: rays from inside closed meshes aimed at shared vertices and edges (an
//!   icosphere, a box, the icosphere through a rotated, non-uniformly scaled instance, and the
//!   closed public meshes when a mesh directory is given);
//! - `inside_camera`: cameras inside a closed mesh ([`StressConfig::inside_cameras`] of them,
//!   at random points and directions, one row), every pixel must hit;
//! - `needle`, `pancake`: convex meshes of 1000:1 aspect (sliver and needle triangles), rays from
//!   outside aimed at interior points; `degenerate`: a box holding zero-area and 1e-9-sized
//!   triangles (the layout drops what it cannot represent);
//! - `scale_1e-3`, `scale_1e5`, `far_small`, `far_small_instanced`: the icosphere at radius
//!   1e-3 and 1e5, and at radius 1e-2 placed 1e3 from the origin;
//! - `axis_rays`: rays along the axes and in coordinate planes (zero direction components),
//!   from origins exactly on kd split planes; `grazing`: rays at 0.5..5 degrees to the surface;
//! - `acne_shadow`, `acne_mirror`: self-intersection of secondary rays on convex meshes.
//!
//! Every scene case also renders its camera and counts shaded colours with a NaN or infinite
//! channel (`nonfinite`), which must be zero everywhere.
//!
//! Every format runs at each edge margin of the configuration: by default
//! [`RECOMMENDED_EDGE_MARGIN`], what the golden model and the intersection unit compute, and 0,
//! the exact unit-triangle test without the mitigation, so the table shows the margin's
//! benefit and cost side by side.
//!
//! Invariants ([`Limit`]): the exact caster never fails; nothing non-finite reaches a pixel;
//! at the hardware's edge margin (or a wider one), inside cameras of closed meshes at ordinary
//! scale leak at most [`WATERTIGHT_PPM`] rays per million in formats with at least 16 mantissa
//! bits (the target: 1 in 10,000 at e7m16), and so do edge-aimed rays on the simple
//! closed meshes. Narrower margins (0 included) are studies: measured and printed, not judged.
//! Other rates (edge-aimed rays on dense public meshes, slivers, extreme scales and positions,
//! grazing rays, acne, narrow formats) are documented limits: measured and printed, not
//! asserted by the suite (the regression tests pin them with bounds).

pub mod cases;
pub mod geometry;

use crate::fp::Format;
use crate::model::units;
use anyhow::{Context, Result};
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};

use cases::{Check, RayCase, Subject};
use geometry::TestScene;

/// The target: at most 1 leaked ray in 10,000 at e7m16 on closed meshes.
pub const WATERTIGHT_PPM: f64 = 100.0;

/// The unit-triangle edge margin the golden model and the intersection unit compute
/// ([`units::EDGE_MARGIN_ULPS`]), in units of 2^-mantissa bits (2^-10 at e7m16): it closes the
/// cracks inside cameras and exact-edge rays find, costs no operator, and moves silhouettes by
/// 2^-10 of a triangle (see PRECISION.md).
pub const RECOMMENDED_EDGE_MARGIN: f64 = units::EDGE_MARGIN_ULPS as f64;

/// How a case's failure rate is judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// Closed meshes at ordinary scale: f64 must not fail, formats with >= 16 mantissa bits
    /// at most [`WATERTIGHT_PPM`] at the hardware's edge margin or a wider one.
    Watertight,
    /// Rays aimed exactly at shared edges of simple closed meshes: as `Watertight`. Without
    /// the margin the per-triangle rounding leaks about one such ray in ten in every format
    /// (documented by the margin-0 rows).
    EdgeAimed,
    /// f64 must not fail; the formats' rates are documented, not bounded.
    Documented,
    /// Nothing is bounded but non-finite colours (cases that are about overflow).
    NonFiniteOnly,
}

impl Limit {
    /// The bound in failures per million for a format (`None` = exact f64), if any.
    /// `margin` is the edge margin in units of 2^-mantissa bits: rows below the hardware's
    /// ([`RECOMMENDED_EDGE_MARGIN`]) are studies of a weaker test and are not bounded.
    pub fn bound_ppm(self, format: Option<Format>, margin: f64) -> Option<f64> {
        match (self, format) {
            (Limit::NonFiniteOnly, _) => None,
            (_, None) => Some(0.0),
            (Limit::Watertight | Limit::EdgeAimed, Some(f))
                if f.man_bits >= 16 && margin >= RECOMMENDED_EDGE_MARGIN =>
            {
                Some(WATERTIGHT_PPM)
            }
            _ => None,
        }
    }
}

/// Settings of a stress run.
#[derive(Clone, Debug)]
pub struct StressConfig {
    pub formats: Vec<Format>,
    pub seed: u64,
    /// Rays per ray case.
    pub rays: usize,
    /// Resolution of the camera cases.
    pub width: u32,
    pub height: u32,
    /// Cameras at random inside points and directions per closed mesh (`inside_camera`),
    /// summed into one row: 16 cameras of 64x48 are 49,152 pixels, so that the
    /// [`WATERTIGHT_PPM`] bound (4 pixels) measures a rate rather than a single pixel.
    pub inside_cameras: usize,
    /// Edge margins of the unit-triangle test to run every format with (see
    /// `model::units::intersect_with_margin`), in units of the format's spacing at 1
    /// (2^-mantissa bits): 64 means 2^-10 at e7m16 and is what the hardware computes
    /// ([`RECOMMENDED_EDGE_MARGIN`]); 0 is the exact test, without the mitigation.
    pub edge_margins: Vec<f64>,
    /// Where public meshes live ([`crate::scene::shared_mesh_dir`]); closed ones join `edge_rays`
    /// and `inside_camera`.
    pub mesh_dir: Option<PathBuf>,
    /// Skip the slower cases (public meshes, icosphere subdivision 3): for regression tests.
    pub quick: bool,
}

impl Default for StressConfig {
    fn default() -> Self {
        StressConfig {
            formats: ["e5m10", "e6m14", "e7m16", "e8m16", "e8m23"]
                .iter()
                .map(|s| Format::parse(s).expect("valid format"))
                .collect(),
            seed: 6,
            rays: 20_000,
            width: 64,
            height: 48,
            inside_cameras: 16,
            edge_margins: vec![RECOMMENDED_EDGE_MARGIN, 0.0],
            mesh_dir: None,
            quick: false,
        }
    }
}

/// One line of the table: one case, subject and format.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseResult {
    pub case: String,
    pub subject: String,
    /// `f64` or the format name.
    pub format: String,
    pub edge_margin: f64,
    pub rays: u64,
    pub failures: u64,
    /// Pixels whose shaded colour had a NaN or infinite channel.
    pub nonfinite: u64,
    pub limit: Limit,
    pub bound_ppm: Option<f64>,
    pub held: bool,
    pub note: String,
}

impl CaseResult {
    pub fn new(case: &str, subject: &str, f: Option<Format>, margin: f64, limit: Limit) -> Self {
        CaseResult {
            case: case.into(),
            subject: subject.into(),
            format: f.map_or("f64".into(), |f| f.to_string()),
            edge_margin: if f.is_some() { margin } else { 0.0 },
            rays: 0,
            failures: 0,
            nonfinite: 0,
            limit,
            bound_ppm: limit.bound_ppm(f, margin),
            held: true,
            note: String::new(),
        }
    }
    /// Failures per million rays.
    pub fn ppm(&self) -> f64 {
        self.failures as f64 * 1e6 / self.rays.max(1) as f64
    }
    /// Judges the row against its bound.
    pub fn finish(mut self) -> Self {
        self.held = self.nonfinite == 0 && self.bound_ppm.is_none_or(|b| self.ppm() <= b);
        self
    }
}

/// Every row of a run.
#[derive(Clone, Debug)]
pub struct StressReport {
    pub seed: u64,
    pub rows: Vec<CaseResult>,
}

impl StressReport {
    pub fn all_held(&self) -> bool {
        self.rows.iter().all(|r| r.held)
    }
    /// The rows that broke an invariant.
    pub fn broken(&self) -> Vec<&CaseResult> {
        self.rows.iter().filter(|r| !r.held).collect()
    }
    /// The row of one case, subject and format.
    pub fn row(&self, case: &str, subject: &str, format: &str, margin: f64) -> Option<&CaseResult> {
        self.rows.iter().find(|r| {
            r.case == case && r.subject == subject && r.format == format && r.edge_margin == margin
        })
    }
    /// The table's header and each row's cells, for the text and Markdown tables.
    fn cells(&self) -> (Vec<&'static str>, Vec<Vec<String>>) {
        let header = vec![
            "case",
            "subject",
            "format",
            "margin",
            "rays",
            "fails",
            "per million",
            "bound",
            "ok",
            "note",
        ];
        let rows = self
            .rows
            .iter()
            .map(|r| {
                vec![
                    r.case.clone(),
                    r.subject.clone(),
                    r.format.clone(),
                    r.edge_margin.to_string(),
                    r.rays.to_string(),
                    r.failures.to_string(),
                    format!("{:.1}", r.ppm()),
                    r.bound_ppm.map_or("-".into(), |b| format!("{b}")),
                    if r.held { "yes" } else { "NO" }.into(),
                    if r.nonfinite > 0 {
                        format!("{} non-finite pixels; {}", r.nonfinite, r.note)
                    } else {
                        r.note.clone()
                    },
                ]
            })
            .collect();
        (header, rows)
    }
    /// A text table for the terminal, every column as wide as its widest cell.
    pub fn table(&self) -> String {
        let (header, rows) = self.cells();
        format!(
            "stress seed {}\n{}{} rows, {} broke an invariant\n",
            self.seed,
            crate::tables::text_table(&header, &rows, &[3, 4, 5, 6, 7]),
            self.rows.len(),
            self.broken().len()
        )
    }
    /// The same table in Markdown (report.md).
    pub fn markdown(&self) -> String {
        let (header, rows) = self.cells();
        crate::tables::markdown_table(&header, &rows)
    }
    /// The rows as CSV.
    pub fn csv(&self) -> Result<String> {
        /// One row of stress.csv: the columns of earlier runs, in their order, the numbers
        /// written as before (`64`, not serde's `64.0`).
        #[derive(serde::Serialize)]
        struct CsvRow<'a> {
            case: &'a str,
            subject: &'a str,
            format: &'a str,
            edge_margin: String,
            rays: u64,
            failures: u64,
            per_million: String,
            nonfinite: u64,
            bound_per_million: Option<String>,
            held: bool,
            note: &'a str,
        }
        let rows: Vec<CsvRow> = self
            .rows
            .iter()
            .map(|r| CsvRow {
                case: &r.case,
                subject: &r.subject,
                format: &r.format,
                edge_margin: r.edge_margin.to_string(),
                rays: r.rays,
                failures: r.failures,
                per_million: format!("{:.3}", r.ppm()),
                nonfinite: r.nonfinite,
                bound_per_million: r.bound_ppm.map(|b| b.to_string()),
                held: r.held,
                note: &r.note,
            })
            .collect();
        crate::tables::csv_of(&rows)
    }
    pub fn save_csv(&self, path: &Path) -> Result<()> {
        crate::output::write_atomically(path, self.csv()?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))
    }
}

/// The closed meshes among the OBJ files of `dir` (sorted by name), as (name, triangles).
pub fn closed_public_meshes(dir: &Path) -> Result<Vec<(String, geometry::Tris)>> {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading mesh directory {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    names.sort();
    let mut out = Vec::new();
    for p in names {
        let Ok(tris) = geometry::load_mesh(&p) else {
            continue;
        };
        if geometry::is_closed(&tris) {
            let name = p
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            out.push((name, tris));
        }
    }
    Ok(out)
}

/// Runs the whole suite; `log` gets a line per case as it starts.
pub fn run_stress(config: &StressConfig, log: &mut dyn FnMut(&str)) -> Result<StressReport> {
    // NaN or infinite margins make every comparison of the unit-triangle test false, so every
    // ray misses and a case that counts leaks would report none.
    for m in &config.edge_margins {
        anyhow::ensure!(
            m.is_finite() && (0.0..=65536.0).contains(m),
            "edge margin {m}: a margin is a number of ulps in 0..=65536 (e.g. 0 or 64)"
        );
    }
    let dir = tempfile::tempdir().context("creating a temporary directory for stress scenes")?;
    let dir = dir.path();
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let n = config.rays;
    let mut rows = Vec::new();
    let cam = |eye: DVec3, look_at: DVec3| TestScene {
        eye,
        look_at,
        fov_y: 90.0,
        width: config.width,
        height: config.height,
        ..TestScene::default()
    };
    let outside = cam(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO);

    // Closed meshes at ordinary scale.
    let sphere = geometry::icosphere(if config.quick { 2 } else { 3 })?;
    // (name, triangles, instance, limit of the edge-aimed rays)
    let mut closed: Vec<(String, geometry::Tris, Option<_>, Limit)> = vec![
        ("icosphere".into(), sphere.clone(), None, Limit::EdgeAimed),
        (
            "box".into(),
            geometry::box_mesh(DVec3::new(1.0, 0.7, 1.3)),
            None,
            Limit::EdgeAimed,
        ),
        (
            "icosphere_instanced".into(),
            sphere.clone(),
            Some(cases::INSTANCE),
            Limit::EdgeAimed,
        ),
    ];
    if let (Some(d), false) = (&config.mesh_dir, config.quick) {
        // Dense meshes seen from inside put the ray origin tens to hundreds of triangle sizes
        // away, and the unit-triangle test's rounding in u, v grows with that ratio: a margin
        // of a fixed number of ulps narrows their exact-edge leaks but does not close them.
        // Documented; their inside cameras stay bounded.
        for (name, tris) in closed_public_meshes(d)? {
            closed.push((name, tris, None, Limit::Documented));
        }
    }
    // A step per closed mesh, then the fixed groups below: needle and pancake, degenerate,
    // four scales, two axis/grazing subjects and two acne subjects.
    let mut steps = crate::progress::Steps::new(closed.len() + 2 + 1 + 4 + 2 + 2);
    let mut begin = |what: &str| {
        log(what);
        steps.start(what);
    };
    for (name, tris, instance, edge_limit) in &closed {
        begin(&format!("edge_rays / inside_camera: {name}"));
        let s = TestScene {
            instance: *instance,
            ..outside.clone()
        };
        let subject = Subject::new(dir, name, tris, &s)?;
        let rays = cases::edge_rays(&subject.world, n, &mut rng);
        // Cameras at inside points looking in random directions.
        let inside =
            geometry::inside_points(&subject.world, config.inside_cameras.max(1), &mut rng);
        let case = RayCase {
            name: "edge_rays".into(),
            subject,
            rays,
            check: Check::MustHit,
            limit: *edge_limit,
        };
        rows.extend(cases::ray_case_rows(&case, config));
        let cameras: Vec<(DVec3, DVec3)> = inside
            .iter()
            .map(|&eye| (eye, eye + geometry::random_direction(&mut rng)))
            .collect();
        if let Some(&(eye, look)) = cameras.first() {
            let s = TestScene {
                instance: *instance,
                ..cam(eye, look)
            };
            let subject = Subject::new(dir, &format!("{name}_cam"), tris, &s)?;
            rows.extend(cases::inside_camera_rows(
                &subject,
                &cameras,
                config,
                "inside_camera",
                Limit::Watertight,
            ));
        }
    }

    // Slivers, needles and degenerate triangles.
    let ico2 = geometry::icosphere(2)?;
    let shapes: Vec<(&str, geometry::Tris)> = vec![
        ("needle", geometry::box_mesh(DVec3::new(1.0, 1e-3, 1e-3))),
        (
            "pancake",
            cases::placed(&ico2, DVec3::new(1.0, 1e-3, 1.0), DVec3::ZERO),
        ),
    ];
    for (name, tris) in shapes {
        begin(&format!("interior rays: {name}"));
        let subject = Subject::new(dir, name, &tris, &outside)?;
        let rays = cases::interior_rays(&subject.world, n, &mut rng);
        let case = RayCase {
            name: name.into(),
            subject,
            rays,
            check: Check::MustHit,
            limit: Limit::Documented,
        };
        rows.extend(cases::ray_case_rows(&case, config));
    }
    {
        begin("degenerate");
        let mut tris = geometry::box_mesh(DVec3::ONE);
        let (a, b) = (DVec3::new(-0.2, 0.1, 0.0), DVec3::new(0.3, -0.1, 0.2));
        tris.push([a, a, b]); // repeated vertex
        tris.push([a, (a + b) * 0.5, b]); // collinear
        for k in 0..20 {
            let p = DVec3::new(0.02 * k as f64 - 0.2, 0.1, -0.1);
            let e = 1e-9 * (1.0 + k as f64);
            tris.push([p, p + DVec3::new(e, 0.0, 0.0), p + DVec3::new(0.0, e, 0.0)]);
            tris.push([
                p,
                p + DVec3::new(0.5, 0.0, 0.0),
                p + DVec3::new(0.5, e, 0.0),
            ]); // needle
        }
        let subject = Subject::new(
            dir,
            "degenerate",
            &tris,
            &cam(DVec3::new(0.1, 0.05, 0.2), DVec3::new(-1.0, 0.0, -1.0)),
        )?;
        let box_only = geometry::box_mesh(DVec3::ONE);
        let rays: Vec<_> = cases::edge_rays(&box_only, n, &mut rng);
        let case = RayCase {
            name: "degenerate".into(),
            subject,
            rays,
            check: Check::MustHit,
            limit: Limit::EdgeAimed,
        };
        rows.extend(cases::ray_case_rows(&case, config));
        rows.extend(cases::camera_rows(
            &case.subject,
            config,
            "degenerate_camera",
            Limit::Watertight,
        ));
    }

    // Scale and position.
    let scaled: Vec<(&str, geometry::Tris, Option<_>, Limit)> = vec![
        (
            "scale_1e-3",
            cases::placed(&ico2, DVec3::splat(1e-3), DVec3::ZERO),
            None,
            Limit::Documented,
        ),
        (
            "scale_1e5",
            cases::placed(&ico2, DVec3::splat(1e5), DVec3::ZERO),
            None,
            Limit::NonFiniteOnly,
        ),
        (
            "far_small",
            cases::placed(&ico2, DVec3::splat(1e-2), DVec3::new(1e3, -1e3, 1e3)),
            None,
            Limit::Documented,
        ),
        (
            "far_small_instanced",
            cases::placed(&ico2, DVec3::splat(1e-2), DVec3::ZERO),
            Some(([1e3, -1e3, 1e3], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0])),
            Limit::Documented,
        ),
    ];
    for (name, tris, instance, limit) in scaled {
        begin(&format!("scale: {name}"));
        let probe = TestScene {
            instance,
            ..outside.clone()
        };
        let world = geometry::world_triangles(&Subject::new(dir, name, &tris, &probe)?.scene);
        let inside = geometry::inside_points(&world, 1, &mut rng);
        let eye = inside.first().copied().unwrap_or_default();
        let s = TestScene {
            instance,
            ..cam(eye, eye + DVec3::new(0.3, 0.2, -1.0))
        };
        let subject = Subject::new(dir, name, &tris, &s)?;
        let rays = cases::edge_rays(&subject.world, n, &mut rng);
        let case = RayCase {
            name: name.into(),
            subject,
            rays,
            check: Check::MustHit,
            limit,
        };
        rows.extend(cases::ray_case_rows(&case, config));
        rows.extend(cases::camera_rows(
            &case.subject,
            config,
            &format!("{name}_camera"),
            limit,
        ));
    }

    // Axis-parallel and grazing rays.
    for (name, tris) in [
        ("box", geometry::box_mesh(DVec3::new(1.0, 0.7, 1.3))),
        ("icosphere", ico2.clone()),
    ] {
        begin(&format!("axis_rays / grazing: {name}"));
        let subject = Subject::new(dir, name, &tris, &outside)?;
        let rays = cases::axis_rays(&subject, n, &mut rng);
        let case = RayCase {
            name: "axis_rays".into(),
            subject,
            rays,
            check: Check::MustHit,
            limit: Limit::EdgeAimed,
        };
        rows.extend(cases::ray_case_rows(&case, config));
        let subject = Subject::new(dir, name, &tris, &outside)?;
        let rays = cases::grazing_rays(&subject.world, n, &mut rng);
        let case = RayCase {
            name: "grazing".into(),
            subject,
            rays,
            check: Check::MustHit,
            limit: Limit::Documented,
        };
        rows.extend(cases::ray_case_rows(&case, config));
    }

    // Acne on convex meshes.
    for (name, tris) in [
        ("icosphere", sphere.clone()),
        ("box", geometry::box_mesh(DVec3::new(1.0, 0.7, 1.3))),
    ] {
        begin(&format!("acne: {name}"));
        let light = DVec3::new(2.0, 3.0, 2.5);
        let eye = DVec3::new(0.5, 1.0, 4.0);
        let s = TestScene {
            light: Some(light),
            shadows: true,
            reflection_depth: 1,
            mirror: 0.5,
            ..cam(eye, DVec3::ZERO)
        };
        let subject = Subject::new(dir, name, &tris, &s)?;
        let rays = cases::surface_rays(&subject.world, eye, n, &mut rng);
        let case = RayCase {
            name: "acne_shadow".into(),
            subject,
            rays,
            check: Check::ShadowAcne { light },
            limit: Limit::Documented,
        };
        rows.extend(cases::ray_case_rows(&case, config));
        let case = RayCase {
            name: "acne_mirror".into(),
            check: Check::MirrorAcne,
            ..case
        };
        rows.extend(cases::ray_case_rows(&case, config));
        rows.extend(cases::camera_rows(
            &case.subject,
            config,
            "acne_camera",
            Limit::NonFiniteOnly,
        ));
    }
    steps.finish();

    Ok(StressReport {
        seed: config.seed,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The suite at CI size: every case, three formats, both margins, a few thousand rays.
    /// The report and the lines logged as each case started.
    fn quick_report() -> (StressReport, Vec<String>) {
        let config = StressConfig {
            formats: ["e5m10", "e7m16", "e8m23"]
                .iter()
                .map(|s| Format::parse(s).unwrap())
                .collect(),
            seed: 6,
            rays: 3000,
            width: 24,
            height: 18,
            quick: true,
            ..StressConfig::default()
        };
        println!("stress seed {}", config.seed);
        crate::progress::seen_in_tests();
        let mut logged = Vec::new();
        let report = run_stress(&config, &mut |l| logged.push(l.to_string())).unwrap();
        println!("{}", report.table());
        (report, logged)
    }

    fn ppm(r: &StressReport, case: &str, subject: &str, format: &str, margin: f64) -> f64 {
        r.row(case, subject, format, margin)
            .unwrap_or_else(|| panic!("no row {case} {subject} {format} {margin}"))
            .ppm()
    }

    #[test]
    fn csv_notes_read_back_whole_and_the_table_keeps_its_columns_in_line() {
        let mut a = CaseResult::new("edge_rays", "icosphere", None, 0.0, Limit::EdgeAimed);
        a.rays = 20_000;
        a.note = "leaks \"here\", and\nthere".into();
        let mut b = CaseResult::new(
            "far_small_instanced_camera",
            "a_public_mesh_with_a_long_name",
            Some(Format::E7M16),
            64.0,
            Limit::Documented,
        );
        b.rays = 7;
        b.failures = 1;
        let report = StressReport {
            seed: 1,
            rows: vec![a.finish(), b.finish()],
        };
        let text = report.csv().unwrap();
        assert!(text.starts_with(
            "case,subject,format,edge_margin,rays,failures,per_million,nonfinite,bound_per_million,held,note\n\
             edge_rays,icosphere,f64,0,20000,0,0.000,0,0,true,"
        ), "{text}");
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let notes: Vec<String> = r.records().map(|x| x.unwrap()[10].to_string()).collect();
        assert_eq!(notes, [report.rows[0].note.as_str(), ""]);
        // The long names of the second row do not push the numbers out of line: "rays" ends
        // where 20000 and 7 end.
        let table = report.table();
        let lines: Vec<&str> = table.lines().collect();
        let header = lines.iter().find(|l| l.contains("subject")).unwrap();
        let rays_end = header.find("rays").unwrap() + 4;
        for (row, n) in [("edge_rays ", "20000"), ("far_small", "7")] {
            let l = lines
                .iter()
                .find(|l| l.trim_start().starts_with(row))
                .unwrap();
            assert_eq!(&l[rays_end - n.len()..rays_end], n, "{table}");
        }
        assert!(report
            .markdown()
            .contains("| a_public_mesh_with_a_long_name |"));
    }

    #[test]
    fn stress_suite_invariants_hold_and_measured_limits_stay_within_bounds() {
        let (r, logged) = quick_report();
        // Every case started is a step of the progress display, counted against the total
        // announced at the start: a case added without its step would show 13 of 12.
        let n = logged.len();
        let seen = crate::progress::seen_in_tests();
        for (k, line) in logged.iter().enumerate() {
            let want = format!("step {k}/{n}: {line}");
            assert!(seen.contains(&want), "no `{want}` in {seen:?}");
        }
        assert!(seen.contains(&format!("step {n}/{n}: done")), "{seen:?}");
        let broken: Vec<String> = r.broken().iter().map(|b| format!("{b:?}")).collect();
        assert!(
            broken.is_empty(),
            "broken invariants:\n{}",
            broken.join("\n")
        );
        for row in &r.rows {
            assert_eq!(row.nonfinite, 0, "{row:?}");
            if row.format == "f64" && row.limit != Limit::NonFiniteOnly {
                assert_eq!(row.failures, 0, "the exact caster never fails: {row:?}");
            }
        }
        let m = RECOMMENDED_EDGE_MARGIN;
        for subject in ["icosphere", "box", "icosphere_instanced"] {
            // The target: inside a closed mesh at e7m16, at most 1 leak in 10,000, with
            // the margin the hardware computes; judged by the suite there, not at margin 0.
            let cam = format!("{subject}_cam");
            let row = r.row("inside_camera", &cam, "e7m16", m).unwrap();
            assert_eq!(row.bound_ppm, Some(WATERTIGHT_PPM), "{row:?}");
            assert!(row.ppm() <= WATERTIGHT_PPM, "{row:?}");
            let row = r.row("inside_camera", &cam, "e7m16", 0.0).unwrap();
            assert_eq!(
                row.bound_ppm, None,
                "margin 0 is the unmitigated comparison"
            );
            // The margin closes the cracks that rays aimed exactly at shared edges find.
            assert_eq!(ppm(&r, "edge_rays", subject, "e7m16", m), 0.0, "{subject}");
            assert_eq!(ppm(&r, "edge_rays", subject, "e8m23", m), 0.0, "{subject}");
        }
        // Without it they leak: the rate every non-watertight unit-triangle test shows
        // (measured 9-12% on the icosphere in every format); if this drops to zero the test
        // has become watertight and the margin may no longer be needed.
        let open = ppm(&r, "edge_rays", "icosphere", "e7m16", 0.0);
        assert!((20_000.0..=300_000.0).contains(&open), "{open}");
        assert_eq!(ppm(&r, "axis_rays", "box", "e7m16", 0.0), 0.0);
        assert_eq!(ppm(&r, "axis_rays", "icosphere", "e7m16", m), 0.0);
        // Acne on convex meshes (measured 330-1000 per million at e7m16, 0 at e8m23).
        for margin in [0.0, m] {
            assert!(ppm(&r, "acne_shadow", "icosphere", "e7m16", margin) <= 3000.0);
            assert!(ppm(&r, "acne_mirror", "icosphere", "e7m16", margin) <= 3000.0);
            assert!(ppm(&r, "acne_shadow", "box", "e7m16", margin) <= 1000.0);
            assert_eq!(ppm(&r, "acne_shadow", "icosphere", "e8m23", margin), 0.0);
        }
        // Slivers and needles hold at e7m16; e5m10 cannot resolve a 1e-3 needle.
        assert_eq!(ppm(&r, "needle", "needle", "e7m16", 0.0), 0.0);
        assert_eq!(ppm(&r, "pancake", "pancake", "e7m16", 0.0), 0.0);
        // A radius-1e-2 object 1e3 from the origin would be below e7m16's resolution there
        // (ulp 2^-6 at 1024; 112,000 leaks per million before objects were stored around
        // their centre). Anchored, and with the hardware's coordinates starting at the eye when
        // an instance carries it there, both placements hold.
        assert_eq!(ppm(&r, "far_small", "far_small", "e7m16", m), 0.0);
        assert_eq!(
            ppm(&r, "far_small_instanced", "far_small_instanced", "e7m16", m),
            0.0
        );
        // e5m10 cannot hold a scene of 1e5 units: refused with a message, not a panic.
        let refused = r.row("scale_1e5", "scale_1e5", "e5m10", 0.0).unwrap();
        assert!(
            refused.note.starts_with("refused:") && refused.rays == 0,
            "{refused:?}"
        );
    }

    /// The target on the closed public meshes seen from inside, at e7m16: 8 cameras
    /// per mesh at random inside points and directions (seed 6), 24,576 pixels each.
    #[test]
    fn public_closed_meshes_seen_from_inside_at_e7m16() {
        let dir = crate::scene::shared_mesh_dir();
        let meshes = closed_public_meshes(&dir).expect("../shared/scenes/meshes");
        assert!(
            meshes.len() >= 4,
            "closed public meshes in {}",
            dir.display()
        );
        let config = StressConfig {
            formats: vec![Format::E7M16],
            inside_cameras: 8,
            ..StressConfig::default()
        };
        println!("seed {}", config.seed);
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        let tmp = tempfile::tempdir().unwrap();
        let m = RECOMMENDED_EDGE_MARGIN;
        let (mut with, mut without) = (0, 0);
        for (name, tris) in &meshes {
            let eyes = geometry::inside_points(tris, config.inside_cameras, &mut rng);
            let cameras: Vec<(DVec3, DVec3)> = eyes
                .iter()
                .map(|&e| (e, e + geometry::random_direction(&mut rng)))
                .collect();
            let s = TestScene {
                eye: cameras[0].0,
                look_at: cameras[0].1,
                fov_y: 90.0,
                width: config.width,
                height: config.height,
                ..TestScene::default()
            };
            let subject = Subject::new(tmp.path(), name, tris, &s).unwrap();
            let rows =
                cases::inside_camera_rows(&subject, &cameras, &config, "inside", Limit::Watertight);
            for r in &rows {
                println!(
                    "{name} {} margin {}: {} of {} ({:.1} ppm)",
                    r.format,
                    r.edge_margin,
                    r.failures,
                    r.rays,
                    r.ppm()
                );
                assert_eq!(r.nonfinite, 0, "{r:?}");
            }
            let row = |fmt: &str, margin: f64| {
                rows.iter()
                    .find(|r| r.format == fmt && r.edge_margin == margin)
                    .unwrap()
            };
            assert_eq!(
                row("f64", 0.0).failures,
                0,
                "{name}: the f64 reference never leaks"
            );
            let (a, b) = (row("e7m16", m), row("e7m16", 0.0));
            (with, without) = (with + a.failures, without + b.failures);
            // fandisk, 15 units from its file's origin with 0.1-unit triangles, leaked 244 ppm
            // here before objects were stored around their centre (PRECISION.md).
            assert!(a.ppm() <= WATERTIGHT_PPM, "{name}: {a:?}");
        }
        // The margin closes most leaks (measured: 6 left of 31 at margin 0).
        assert!(
            with * 3 <= without,
            "margin {m}: {with} leaks, margin 0: {without}"
        );
    }

    #[test]
    fn bounds_follow_the_limit_kind() {
        let e7 = Some(Format::E7M16);
        let e5 = Some(Format::E5M10);
        assert_eq!(Limit::Watertight.bound_ppm(None, 0.0), Some(0.0));
        // Judged at the hardware's margin (or wider); narrower margins are studies.
        let m = RECOMMENDED_EDGE_MARGIN;
        assert_eq!(
            m, 64.0,
            "the golden model's margin, units::EDGE_MARGIN_ULPS"
        );
        assert_eq!(Limit::Watertight.bound_ppm(e7, 0.0), None);
        assert_eq!(Limit::Watertight.bound_ppm(e7, m), Some(WATERTIGHT_PPM));
        assert_eq!(Limit::Watertight.bound_ppm(e5, m), None);
        assert_eq!(Limit::EdgeAimed.bound_ppm(e7, 0.0), None);
        assert_eq!(Limit::EdgeAimed.bound_ppm(e7, 16.0), None);
        assert_eq!(Limit::EdgeAimed.bound_ppm(e7, m), Some(WATERTIGHT_PPM));
        assert_eq!(Limit::EdgeAimed.bound_ppm(e7, 256.0), Some(WATERTIGHT_PPM));
        assert_eq!(Limit::NonFiniteOnly.bound_ppm(None, 0.0), None);
        let mut row = CaseResult::new("c", "s", e7, m, Limit::Watertight);
        (row.rays, row.failures) = (10_000, 1);
        assert!(
            row.clone().finish().held,
            "100 per million is within the bound"
        );
        row.failures = 2;
        assert!(!row.clone().finish().held);
        row.failures = 0;
        row.nonfinite = 1;
        assert!(!row.finish().held, "a non-finite pixel always breaks");
    }
}
