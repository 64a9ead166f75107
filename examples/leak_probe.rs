//! Why do rays leak from inside a closed mesh? Renders 16 inside cameras (64x48, seed 6) with
//! the golden model and, for every pixel that sees nothing, tests every triangle by brute force
//! (so kd-traversal and unit-triangle leaks are told apart) and prints how far outside the
//! edge bounds the nearest triangle's u, v fall, in margins.
//!
//! `cargo run --release --example leak_probe -- MESH.obj [MARGIN_ULPS=64] [FORMAT=e7m16]`;
//! `CENTRE=1` translates the mesh to its bounding-box centre first, `QUIET=1` prints only the
//! totals. PRECISION.md quotes its fandisk figures.
use dynrt::fp::Format;
use dynrt::layout::{self, MemoryConfig, SceneTrees};
use dynrt::model::{units, Golden};
use dynrt::stress::cases::Subject;
use dynrt::stress::geometry::{self, TestScene};
use glam::DVec3;
use rand::SeedableRng;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = &args[1];
    let margin_ulps: f64 = args.get(2).map_or(64.0, |s| s.parse().unwrap());
    let f = Format::parse(args.get(3).map_or("e7m16", |s| s.as_str())).unwrap();
    let mut tris = geometry::load_mesh(std::path::Path::new(mesh)).unwrap();
    if std::env::var("CENTRE").is_ok() {
        let (lo, hi) = geometry::bounds(&tris);
        let c: DVec3 = (lo + hi) * 0.5;
        for t in &mut tris {
            for v in t.iter_mut() {
                *v -= c;
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    let pts = geometry::inside_points(&tris, 16, &mut rng);
    let (lo, hi) = geometry::bounds(&tris);
    println!("{} tris, size {:?}", tris.len(), hi - lo);
    let mut total = 0;
    let mut leaks = 0;
    let mut brute_hits = 0;
    for (ci, &eye) in pts.iter().enumerate() {
        let look = eye + geometry::random_direction(&mut rng);
        let s = TestScene {
            eye,
            look_at: look,
            fov_y: 90.0,
            width: 64,
            height: 48,
            ..TestScene::default()
        };
        let sub = Subject::new(dir.path(), "m", &tris, &s).unwrap();
        let trees = SceneTrees::build(&sub.scene, f).unwrap();
        let l = layout::build(&sub.scene, &trees, 0, &MemoryConfig::default()).unwrap();
        let margin = f.from_f64(margin_ulps * 2f64.powi(-(f.man_bits as i32)));
        let g = Golden::with_edge_margin(&l, margin_ulps * 2f64.powi(-(f.man_bits as i32)));
        for y in 0..48 {
            for x in 0..64 {
                total += 1;
                let p = g.pixel(x, y);
                if p.hit.is_some() {
                    continue;
                }
                leaks += 1;
                // Brute force over every triangle.
                let eyew: [u32; 3] = l.words(layout::FRAME, layout::FrameMap::EYE);
                let mut best: Option<(f64, u32)> = None;
                let mut closest_excess = f64::INFINITY;
                let mut info = String::new();
                for t in 0..l.info.triangle_count {
                    let m = l.triangle_transform(t);
                    let o = units::transform(f, &m, eyew, true);
                    let d = units::transform(f, &m, p.dir, false);
                    let r = units::intersect_with_margin(f, o, d, 0, f.infinity(false), margin);
                    if r.hit {
                        best = Some((f.to_f64(r.t), t));
                    }
                    let [tt, u, v, uv] = units::unit_triangle_coords(f, o, d);
                    let (tt, u, v, uv) = (f.to_f64(tt), f.to_f64(u), f.to_f64(v), f.to_f64(uv));
                    if tt > 0.0 {
                        let excess = (-u).max(-v).max(uv - 1.0);
                        if excess < closest_excess {
                            closest_excess = excess;
                            let on = [f.to_f64(o[0]), f.to_f64(o[1]), f.to_f64(o[2])];
                            info = format!(
                                "tri {t} t {tt:.4} u {u:.6} v {v:.6} u+v {uv:.6} |O'| {:.1}",
                                (on[0] * on[0] + on[1] * on[1] + on[2] * on[2]).sqrt()
                            );
                        }
                    }
                }
                if best.is_some() {
                    brute_hits += 1;
                }
                if std::env::var("QUIET").is_err() {
                    println!("cam {ci} px ({x},{y}): brute {:?}; nearest miss excess {:.2e} ({:.1} margins): {info}", best, closest_excess, closest_excess / f.to_f64(margin));
                }
            }
        }
    }
    println!(
        "{leaks} leaks of {total} ({:.1} ppm), brute force hits {brute_hits}",
        leaks as f64 * 1e6 / total as f64
    );
}
