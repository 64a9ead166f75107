//! The paper's benchmark scenes (Schmittler et al. 2004, Table 3) rebuilt from our own
//! procedural models, so that a clone renders them with nothing beside it: one scene per row,
//! with the row's triangle count (within [`TRIANGLE_TOLERANCE`]; instanced counts for Terrain and
//! SunCOR) and its object count exactly. The paper counts as "objects" the entries of the top
//! level (instances): Terrain's 264 are tiles, SunCOR's 5,622 instances.
//!
//! Models are meshes with their own materials, used from a scene file as
//! `generate = { kind = "paper", model = "office" }` (names in [`MODELS`]). Every model is
//! deterministic: fixed parameters and, where it scatters things, a fixed seed (ChaCha8).
//! [`scene_toml`] writes each scene file of `scenes/paper/` (`dynrt paper-scenes`, `make
//! paper-scenes`); the files are generated, never edited by hand.

use glam::{DMat3, DVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::generate::{box_triangles, sphere_triangles};
use super::mesh::{Material, RawMesh};
use super::noise::fbm;

/// How far a scene's triangle count may be from the paper's, as a fraction of it.
pub const TRIANGLE_TOLERANCE: f64 = 0.10;

/// One row of the paper's Table 3 (one pipeline at 90 MHz, 512x384).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperRow {
    /// The paper's name.
    pub name: &'static str,
    /// Our scene file's stem in `scenes/paper/`.
    pub file: &'static str,
    /// Triangles (instanced, as seen in the world).
    pub triangles: u64,
    /// Entries of the top level.
    pub objects: usize,
    /// Frames per second the paper measured.
    pub fps: f64,
}

pub const TABLE3: [PaperRow; 9] = [
    row("Scene6", "scene6", 806, 1, 60.8),
    row("Castle", "castle", 20_891, 8, 23.8),
    row("Office", "office", 34_312, 1, 48.9),
    row("Quake3", "quake3", 39_424, 1, 33.6),
    row("Quake3-p", "quake3_p", 52_790, 17, 26.7),
    row("UT2003", "ut2003", 52_479, 1, 25.4),
    row("Conference", "conference", 282_805, 54, 22.1),
    row("Terrain", "terrain", 10_470_000, 264, 15.9),
    row("SunCOR", "suncor", 187_000_000, 5_622, 32.1),
];

const fn row(
    name: &'static str,
    file: &'static str,
    triangles: u64,
    objects: usize,
    fps: f64,
) -> PaperRow {
    PaperRow {
        name,
        file,
        triangles,
        objects,
        fps,
    }
}

/// The paper's resolution.
pub const WIDTH: u32 = 512;
pub const HEIGHT: u32 = 384;

/// Every model `kind = "paper"` accepts.
pub const MODELS: [&str; 14] = [
    "scene6",
    "castle_walls",
    "castle_keep",
    "castle_tower",
    "castle_gate",
    "office",
    "arena",
    "player",
    "ut_level",
    "conference_hall",
    "conference_table",
    "conference_chair",
    "lectern",
    "sunflower",
];

/// Builds model `name`, or `None` for a name not in [`MODELS`].
pub(crate) fn model(name: &str) -> Option<RawMesh> {
    let mut b = Builder::default();
    match name {
        "scene6" => scene6(&mut b),
        "castle_walls" => castle_walls(&mut b),
        "castle_keep" => castle_keep(&mut b),
        "castle_tower" => castle_tower(&mut b),
        "castle_gate" => castle_gate(&mut b),
        "office" => office(&mut b),
        "arena" => arena(&mut b),
        "player" => player(&mut b),
        "ut_level" => ut_level(&mut b),
        "conference_hall" => conference_hall(&mut b),
        "conference_table" => conference_table(&mut b),
        "conference_chair" => conference_chair(&mut b),
        "lectern" => lectern(&mut b),
        "sunflower" => sunflower(&mut b),
        _ => return None,
    }
    Some(b.mesh)
}

type Tris = Vec<[DVec3; 3]>;

#[derive(Default)]
struct Builder {
    mesh: RawMesh,
}

impl Builder {
    fn material(&mut self, diffuse: [f64; 3]) -> u32 {
        self.mirror_material(diffuse, 0.0)
    }
    fn mirror_material(&mut self, diffuse: [f64; 3], mirror: f64) -> u32 {
        self.mesh.materials.push(Material { diffuse, mirror });
        self.mesh.materials.len() as u32 - 1
    }
    fn add(&mut self, tris: Tris, material: u32) {
        self.mesh
            .triangle_material
            .extend(std::iter::repeat_n(material, tris.len()));
        self.mesh.triangles.extend(tris);
    }
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// An axis-aligned box between two corners: 12 triangles.
fn cuboid(min: DVec3, max: DVec3) -> Tris {
    box_triangles((min + max) * 0.5, (max - min) * 0.5, 0.0, true)
}

/// A box whose six faces are each cut into n x n cells: 12 n² triangles.
fn tiled_cuboid(min: DVec3, max: DVec3, n: u32) -> Tris {
    let (c, h) = ((min + max) * 0.5, (max - min) * 0.5);
    let (x, y, z) = (DVec3::X * h.x, DVec3::Y * h.y, DVec3::Z * h.z);
    let mut out = Vec::new();
    for (centre, u, w) in [
        (c + x, y, z),
        (c - x, z, y),
        (c + y, z, x),
        (c - y, x, z),
        (c + z, x, y),
        (c - z, y, x),
    ] {
        out.extend(panel(centre, u, w, n, n));
    }
    out
}

/// The quad centre ± u ± w cut into nu x nw cells (2 nu nw triangles, normal along u × w).
fn panel(centre: DVec3, u: DVec3, w: DVec3, nu: u32, nw: u32) -> Tris {
    let p = |i: u32, j: u32| {
        centre
            + u * (2.0 * f64::from(i) / f64::from(nu) - 1.0)
            + w * (2.0 * f64::from(j) / f64::from(nw) - 1.0)
    };
    let mut out = Vec::with_capacity(2 * (nu * nw) as usize);
    for j in 0..nw {
        for i in 0..nu {
            out.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            out.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    out
}

/// A room's inside: floor, ceiling and four walls facing inwards, each n x n cells.
fn shell(min: DVec3, max: DVec3, n: u32) -> Tris {
    let (c, h) = ((min + max) * 0.5, (max - min) * 0.5);
    let (x, y, z) = (DVec3::X * h.x, DVec3::Y * h.y, DVec3::Z * h.z);
    let mut out = Vec::new();
    for (centre, u, w) in [
        (c - y, z, x),
        (c + y, x, z),
        (c - z, x, y),
        (c + z, y, x),
        (c - x, y, z),
        (c + x, z, y),
    ] {
        out.extend(panel(centre, u, w, n, n));
    }
    out
}

/// The side of a cylinder around +Y from y = 0 to `height`: `segments` around, `rings` up,
/// 2 segments rings triangles.
fn tube(radius: f64, height: f64, segments: u32, rings: u32) -> Tris {
    let p = |k: u32, r: u32| {
        let a = std::f64::consts::TAU * f64::from(k) / f64::from(segments);
        v(
            radius * a.cos(),
            height * f64::from(r) / f64::from(rings),
            radius * a.sin(),
        )
    };
    let mut out = Vec::new();
    for r in 0..rings {
        for k in 0..segments {
            out.push([p(k, r), p(k, r + 1), p(k + 1, r + 1)]);
            out.push([p(k, r), p(k + 1, r + 1), p(k + 1, r)]);
        }
    }
    out
}

/// A disc of `segments` triangles at height `y` around the Y axis.
fn disc(radius: f64, y: f64, segments: u32) -> Tris {
    let p = |k: u32| {
        let a = std::f64::consts::TAU * f64::from(k) / f64::from(segments);
        v(radius * a.cos(), y, radius * a.sin())
    };
    (0..segments)
        .map(|k| [v(0.0, y, 0.0), p(k + 1), p(k)])
        .collect()
}

/// A closed cylinder: 4 segments triangles.
fn cylinder(radius: f64, height: f64, segments: u32) -> Tris {
    let mut out = tube(radius, height, segments, 1);
    out.extend(disc(radius, 0.0, segments));
    out.extend(disc(radius, height, segments));
    out
}

/// A cone over a disc at y = 0 with its tip at `height`: 2 segments triangles.
fn cone(radius: f64, height: f64, segments: u32) -> Tris {
    let mut out = disc(radius, 0.0, segments);
    out.extend(
        disc(radius, 0.0, segments)
            .into_iter()
            .map(|[_, b, c]| [v(0.0, height, 0.0), c, b]),
    );
    out
}

/// An icosphere scaled to `radii` around `centre`: 20 · 4^s triangles.
fn ellipsoid(centre: DVec3, radii: DVec3, subdivisions: u32) -> Tris {
    sphere_triangles(1.0, subdivisions)
        .into_iter()
        .map(|t| t.map(|p| centre + p * radii))
        .collect()
}

fn ball(centre: DVec3, radius: f64, subdivisions: u32) -> Tris {
    ellipsoid(centre, DVec3::splat(radius), subdivisions)
}

/// `tris` turned by `rotation` and moved to `at`.
fn placed(tris: Tris, at: DVec3, rotation: DMat3) -> Tris {
    tris.into_iter()
        .map(|t| t.map(|p| at + rotation * p))
        .collect()
}

fn yaw(deg: f64) -> DMat3 {
    DMat3::from_rotation_y(deg.to_radians())
}

/// `tris` turned `deg` about Y and moved to `at`.
fn at(tris: Tris, at: DVec3, deg: f64) -> Tris {
    placed(tris, at, yaw(deg))
}

/// A round arch of `stones` blocks in the XY plane, centred at `centre`, spanning ±radius.
fn arch(centre: DVec3, radius: f64, stones: u32, thickness: f64, depth: f64) -> Tris {
    let mut out = Vec::new();
    let step = std::f64::consts::PI / f64::from(stones);
    for k in 0..stones {
        let a = step * (f64::from(k) + 0.5);
        let half = v(thickness * 0.5, radius * step * 0.5, depth * 0.5);
        let stone = cuboid(-half, half);
        let r = DMat3::from_rotation_z(a);
        out.extend(placed(
            stone,
            centre + v(radius * a.cos(), radius * a.sin(), 0.0),
            r,
        ));
    }
    out
}

/// A wall's top: `count` merlons along the segment from `a` to `b` (both at the wall's top).
fn merlons(a: DVec3, b: DVec3, count: u32, size: f64) -> Tris {
    let mut out = Vec::new();
    for k in 0..count {
        let p = a.lerp(b, (f64::from(k) + 0.5) / f64::from(count));
        out.extend(cuboid(
            p - v(size * 0.5, 0.0, size * 0.5),
            p + v(size * 0.5, size, size * 0.5),
        ));
    }
    out
}

// ------------------------------------------------------------------------ furniture

/// A table top on four legs, centred at the origin on the floor.
fn table(size: DVec3, leg: f64, leg_segments: u32) -> Tris {
    let mut out = cuboid(
        v(-size.x, size.y - 0.05, -size.z),
        v(size.x, size.y, size.z),
    );
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let p = v(sx * (size.x - 2.0 * leg), 0.0, sz * (size.z - 2.0 * leg));
        out.extend(at(cylinder(leg, size.y - 0.05, leg_segments), p, 0.0));
    }
    out
}

/// A four-legged chair facing +Z, seat 0.45 high: 72 triangles.
fn chair() -> Tris {
    let mut out = cuboid(v(-0.22, 0.42, -0.22), v(0.22, 0.47, 0.22));
    out.extend(cuboid(v(-0.22, 0.47, -0.24), v(0.22, 0.95, -0.2)));
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let p = v(sx * 0.19, 0.0, sz * 0.19);
        out.extend(cuboid(p - v(0.025, 0.0, 0.025), p + v(0.025, 0.42, 0.025)));
    }
    out
}

/// Scene6: one room with a table, four chairs, a ball and a shelf (806 triangles in the paper).
fn scene6(b: &mut Builder) {
    let wall = b.material([0.85, 0.82, 0.72]);
    let wood = b.material([0.55, 0.35, 0.2]);
    let red = b.material([0.75, 0.15, 0.12]);
    let blue = b.material([0.2, 0.35, 0.8]);
    b.add(shell(v(-4.0, 0.0, -3.0), v(4.0, 3.0, 3.0), 2), wall);
    b.add(table(v(0.8, 0.75, 0.5), 0.04, 8), wood);
    for (x, z, deg) in [
        (0.0, -0.9, 0.0),
        (0.0, 0.9, 180.0),
        (-1.2, 0.0, 90.0),
        (1.2, 0.0, -90.0),
    ] {
        b.add(at(chair(), v(x, 0.0, z), deg), red);
    }
    b.add(ball(v(0.0, 1.05, 0.0), 0.3, 2), blue);
    b.add(cuboid(v(-3.9, 0.0, -2.9), v(-2.4, 1.8, -2.5)), wood);
    b.add(cuboid(v(2.5, 0.0, -2.9), v(3.9, 0.9, -2.3)), wood);
}

/// Office: an open-plan floor of 12 workstations, bookshelves, columns and ceiling lamps.
fn office(b: &mut Builder) {
    let wall = b.material([0.8, 0.8, 0.76]);
    let desk = b.material([0.6, 0.45, 0.3]);
    let metal = b.material([0.35, 0.36, 0.4]);
    let fabric = b.material([0.2, 0.3, 0.55]);
    let screen = b.material([0.08, 0.08, 0.1]);
    let leaf = b.material([0.2, 0.55, 0.2]);
    let pot = b.material([0.7, 0.4, 0.25]);
    let book = [
        b.material([0.7, 0.15, 0.1]),
        b.material([0.15, 0.35, 0.65]),
        b.material([0.85, 0.75, 0.3]),
    ];
    b.add(shell(v(-10.0, 0.0, -7.0), v(10.0, 3.2, 7.0), 4), wall);
    for row in 0..3 {
        for col in 0..4 {
            let p = v(
                -6.0 + 4.0 * f64::from(col),
                0.0,
                -3.5 + 3.5 * f64::from(row),
            );
            // Desk: top, two side panels, modesty panel.
            b.add(
                at(
                    {
                        let mut d = cuboid(v(-0.8, 0.72, -0.4), v(0.8, 0.76, 0.4));
                        d.extend(cuboid(v(-0.8, 0.0, -0.4), v(-0.76, 0.72, 0.4)));
                        d.extend(cuboid(v(0.76, 0.0, -0.4), v(0.8, 0.72, 0.4)));
                        d.extend(cuboid(v(-0.76, 0.3, -0.4), v(0.76, 0.72, -0.37)));
                        d
                    },
                    p,
                    0.0,
                ),
                desk,
            );
            // Swivel chair: seat, back, post, five feet with casters.
            let c = p + v(0.0, 0.0, 0.75);
            b.add(
                at(cuboid(v(-0.25, 0.45, -0.25), v(0.25, 0.52, 0.25)), c, 0.0),
                fabric,
            );
            b.add(
                at(cuboid(v(-0.23, 0.55, 0.22), v(0.23, 1.05, 0.27)), c, 0.0),
                fabric,
            );
            b.add(at(cylinder(0.03, 0.45, 12), c, 0.0), metal);
            for k in 0..5 {
                let deg = 72.0 * f64::from(k);
                b.add(
                    at(cuboid(v(0.0, 0.05, -0.02), v(0.3, 0.08, 0.02)), c, deg),
                    metal,
                );
                let foot = c + yaw(deg) * v(0.28, 0.03, 0.0);
                b.add(ball(foot, 0.03, 0), metal);
            }
            // Monitor, keyboard, desk lamp, mug.
            b.add(
                at(cuboid(v(-0.3, 0.9, -0.28), v(0.3, 1.25, -0.25)), p, 0.0),
                screen,
            );
            b.add(
                at(cylinder(0.02, 0.14, 12), p + v(0.0, 0.76, -0.3), 0.0),
                metal,
            );
            b.add(
                at(cuboid(v(-0.2, 0.76, -0.05), v(0.2, 0.78, 0.08)), p, 0.0),
                metal,
            );
            b.add(
                at(cylinder(0.07, 0.02, 16), p + v(0.6, 0.76, -0.2), 0.0),
                metal,
            );
            b.add(
                at(
                    cuboid(v(-0.01, 0.0, -0.01), v(0.01, 0.4, 0.01)),
                    p + v(0.6, 0.78, -0.2),
                    0.0,
                ),
                metal,
            );
            b.add(at(cone(0.1, 0.12, 16), p + v(0.6, 1.1, -0.2), 0.0), metal);
            b.add(
                at(cylinder(0.04, 0.1, 12), p + v(-0.55, 0.76, 0.1), 0.0),
                pot,
            );
            // Potted plant beside the desk.
            b.add(at(cylinder(0.18, 0.4, 16), p + v(1.1, 0.0, -0.2), 0.0), pot);
            b.add(ellipsoid(p + v(1.1, 0.75, -0.2), v(0.3, 0.4, 0.3), 3), leaf);
        }
    }
    // Bookshelves along the back wall, five boards of books each.
    let mut rng = ChaCha8Rng::seed_from_u64(34_312);
    for s in 0..4 {
        let x0 = -9.0 + 4.6 * f64::from(s);
        let mut frame = cuboid(v(x0, 0.0, -6.95), v(x0 + 0.04, 2.2, -6.6));
        frame.extend(cuboid(v(x0 + 1.96, 0.0, -6.95), v(x0 + 2.0, 2.2, -6.6)));
        for k in 0..6 {
            let y = 0.42 * f64::from(k);
            frame.extend(cuboid(v(x0, y, -6.95), v(x0 + 2.0, y + 0.03, -6.6)));
        }
        b.add(frame, desk);
        for k in 0..5 {
            let y = 0.42 * f64::from(k) + 0.03;
            let mut x = x0 + 0.06;
            while x < x0 + 1.88 {
                let w = rng.gen_range(0.03..0.07);
                let h = rng.gen_range(0.25..0.37);
                let m = book[rng.gen_range(0..book.len())];
                b.add(cuboid(v(x, y, -6.92), v(x + w, y + h, -6.65)), m);
                x += w + 0.005;
            }
        }
    }
    // Columns and ceiling lamps.
    for (x, z) in [(-4.0, -1.75), (4.0, -1.75), (-4.0, 5.25), (4.0, 5.25)] {
        b.add(at(tube(0.25, 3.2, 32, 2), v(x, 0.0, z), 0.0), wall);
    }
    for row in 0..3 {
        for col in 0..4 {
            let p = v(
                -6.0 + 4.0 * f64::from(col),
                3.1,
                -3.5 + 3.5 * f64::from(row),
            );
            b.add(at(cylinder(0.3, 0.1, 24), p, 0.0), metal);
        }
    }
}

// ------------------------------------------------------------------------ castle

/// The castle's curtain walls: a 28 x 28 square ring, 5 high, with merlons and a wall walk.
fn castle_walls(b: &mut Builder) {
    let stone = b.material([0.62, 0.6, 0.55]);
    let dark = b.material([0.45, 0.43, 0.4]);
    let h = 14.0;
    for k in 0..4 {
        let r = yaw(90.0 * f64::from(k));
        let wall = tiled_cuboid(v(-h, 0.0, h - 1.0), v(h, 5.0, h), 6);
        b.add(placed(wall, DVec3::ZERO, r), stone);
        let walk = cuboid(v(-h, 4.6, h - 2.0), v(h, 4.8, h - 1.0));
        b.add(placed(walk, DVec3::ZERO, r), dark);
        let top = merlons(v(-h, 5.0, h - 0.3), v(h, 5.0, h - 0.3), 28, 0.6);
        b.add(placed(top, DVec3::ZERO, r), stone);
        let inner = merlons(v(-h, 5.0, h - 1.7), v(h, 5.0, h - 1.7), 28, 0.4);
        b.add(placed(inner, DVec3::ZERO, r), dark);
    }
}

/// A round corner tower with a conical roof.
fn castle_tower(b: &mut Builder) {
    let stone = b.material([0.6, 0.58, 0.53]);
    let roof = b.material([0.55, 0.2, 0.15]);
    let window = b.material([0.1, 0.1, 0.12]);
    b.add(tube(2.2, 8.0, 48, 8), stone);
    b.add(disc(2.2, 8.0, 48), stone);
    b.add(at(tube(2.5, 0.5, 48, 1), v(0.0, 8.0, 0.0), 0.0), stone);
    b.add(disc(2.5, 8.5, 48), stone);
    for k in 0..16 {
        let a = 22.5 * f64::from(k);
        b.add(
            at(cuboid(v(2.2, 8.5, -0.3), v(2.6, 9.2, 0.3)), DVec3::ZERO, a),
            stone,
        );
    }
    b.add(at(cone(2.3, 4.0, 48), v(0.0, 9.2, 0.0), 0.0), roof);
    for k in 0..6 {
        let a = 60.0 * f64::from(k);
        let y = 3.0 + 2.0 * f64::from(k % 2);
        b.add(
            at(
                cuboid(v(2.15, y, -0.2), v(2.3, y + 0.9, 0.2)),
                DVec3::ZERO,
                a,
            ),
            window,
        );
    }
}

/// The keep: a tall square hall with corner turrets.
fn castle_keep(b: &mut Builder) {
    let stone = b.material([0.68, 0.65, 0.58]);
    let roof = b.material([0.5, 0.22, 0.16]);
    let window = b.material([0.1, 0.1, 0.12]);
    b.add(
        tiled_cuboid(v(-4.0, 0.0, -4.0), v(4.0, 12.0, 4.0), 12),
        stone,
    );
    for k in 0..4 {
        let r = yaw(90.0 * f64::from(k));
        b.add(
            placed(
                merlons(v(-4.0, 12.0, 3.7), v(4.0, 12.0, 3.7), 10, 0.6),
                DVec3::ZERO,
                r,
            ),
            stone,
        );
        for (y, n) in [(4.0, 3), (8.0, 3)] {
            for i in 0..n {
                let x = -2.5 + 2.5 * f64::from(i);
                let w = cuboid(v(x - 0.3, y, 3.98), v(x + 0.3, y + 1.2, 4.05));
                b.add(placed(w, DVec3::ZERO, r), window);
            }
        }
        let corner = r * v(4.0, 0.0, 4.0);
        b.add(at(tube(1.0, 14.0, 32, 6), corner, 0.0), stone);
        b.add(
            at(cone(1.2, 3.0, 32), corner + v(0.0, 14.0, 0.0), 0.0),
            roof,
        );
    }
    b.add(at(cone(4.5, 4.0, 4), v(0.0, 12.0, 0.0), 45.0), roof);
}

/// The gatehouse: a block with an arched gate, a portcullis and two small turrets.
fn castle_gate(b: &mut Builder) {
    let stone = b.material([0.6, 0.57, 0.5]);
    let iron = b.material([0.2, 0.2, 0.22]);
    let roof = b.material([0.5, 0.22, 0.16]);
    b.add(tiled_cuboid(v(-3.0, 3.2, -1.5), v(3.0, 7.0, 1.5), 6), stone);
    b.add(
        tiled_cuboid(v(-3.0, 0.0, -1.5), v(-1.6, 3.2, 1.5), 4),
        stone,
    );
    b.add(tiled_cuboid(v(1.6, 0.0, -1.5), v(3.0, 3.2, 1.5), 4), stone);
    b.add(arch(v(0.0, 2.0, 1.6), 1.6, 24, 0.3, 0.4), stone);
    for k in 0..8 {
        let x = -1.4 + 0.4 * f64::from(k);
        b.add(at(cylinder(0.05, 3.0, 8), v(x, 0.4, 0.0), 0.0), iron);
    }
    for x in [-3.0, 3.0] {
        b.add(at(tube(1.0, 9.0, 24, 4), v(x, 0.0, 1.5), 0.0), stone);
        b.add(at(cone(1.2, 2.5, 24), v(x, 9.0, 1.5), 0.0), roof);
    }
}

// ------------------------------------------------------------------------ game levels

/// A pillar with base, shaft, two rings and a capital.
fn pillar(radius: f64, height: f64, segments: u32, rings: u32) -> Tris {
    let mut out = cuboid(
        v(-radius * 1.3, 0.0, -radius * 1.3),
        v(radius * 1.3, 0.3, radius * 1.3),
    );
    out.extend(at(
        tube(radius, height - 0.6, segments, rings),
        v(0.0, 0.3, 0.0),
        0.0,
    ));
    out.extend(at(
        tube(radius * 1.15, 0.2, segments, 1),
        v(0.0, 0.5, 0.0),
        0.0,
    ));
    out.extend(at(
        tube(radius * 1.15, 0.2, segments, 1),
        v(0.0, height - 0.8, 0.0),
        0.0,
    ));
    out.extend(cuboid(
        v(-radius * 1.3, height - 0.3, -radius * 1.3),
        v(radius * 1.3, height, radius * 1.3),
    ));
    out
}

/// A wall torch: bracket, bowl and flame.
fn torch() -> Tris {
    let mut out = cylinder(0.04, 0.5, 8);
    out.extend(at(cone(0.15, -0.2, 8), v(0.0, 0.7, 0.0), 0.0));
    out.extend(ball(v(0.0, 0.8, 0.0), 0.12, 2));
    out
}

/// Quake3-like arena: a stone hall with pillars, arches, stairs to a gallery, curved ramps,
/// jump pads and torches.
fn arena(b: &mut Builder) {
    let stone = b.material([0.5, 0.45, 0.4]);
    let floor = b.material([0.4, 0.38, 0.36]);
    let metal = b.material([0.45, 0.45, 0.5]);
    let glow = b.material([0.9, 0.5, 0.1]);
    let pad = b.material([0.2, 0.6, 0.9]);
    b.add(shell(v(-20.0, 0.0, -20.0), v(20.0, 12.0, 20.0), 8), stone);
    b.add(
        panel(
            v(0.0, 0.01, 0.0),
            v(0.0, 0.0, 19.9),
            v(19.9, 0.0, 0.0),
            32,
            32,
        ),
        floor,
    );
    for i in 0..4 {
        for j in 0..4 {
            let p = v(-12.0 + 8.0 * f64::from(i), 0.0, -12.0 + 8.0 * f64::from(j));
            b.add(at(pillar(0.6, 12.0, 24, 8), p, 0.0), stone);
        }
    }
    for k in 0..4 {
        let r = yaw(90.0 * f64::from(k));
        for x in [-8.0, 8.0] {
            b.add(
                placed(arch(v(x, 5.0, -19.5), 3.0, 32, 0.5, 0.8), DVec3::ZERO, r),
                stone,
            );
        }
        // Gallery along the wall: slab, railing posts and stairs up to it.
        b.add(
            placed(
                cuboid(v(-18.0, 4.0, -20.0), v(18.0, 4.4, -16.0)),
                DVec3::ZERO,
                r,
            ),
            floor,
        );
        for i in 0..20 {
            let p = r * v(-17.0 + 1.8 * f64::from(i), 4.4, -16.1);
            b.add(at(cylinder(0.05, 1.0, 8), p, 0.0), metal);
        }
        b.add(
            placed(
                cuboid(v(-18.0, 5.35, -16.15), v(18.0, 5.45, -16.05)),
                DVec3::ZERO,
                r,
            ),
            metal,
        );
        for s in 0..16 {
            let y = 0.25 * f64::from(s + 1);
            let z = -15.8 + 0.3 * f64::from(15 - s);
            b.add(
                placed(cuboid(v(14.0, 0.0, z), v(15.5, y, z + 0.3)), DVec3::ZERO, r),
                stone,
            );
        }
        // A curved ramp (Quake 3's patches): a quarter pipe in a corner of the floor.
        let ramp: Tris = (0..30)
            .flat_map(|i| (0..30).map(move |j| (i, j)))
            .flat_map(|(i, j)| {
                let p = |i: u32, j: u32| {
                    let a = std::f64::consts::FRAC_PI_2 * f64::from(i) / 30.0;
                    v(
                        -3.0 + 6.0 * f64::from(j) / 30.0,
                        3.0 - 3.0 * a.cos(),
                        3.0 * a.sin(),
                    )
                };
                [
                    [p(i, j), p(i + 1, j), p(i + 1, j + 1)],
                    [p(i, j), p(i + 1, j + 1), p(i, j + 1)],
                ]
            })
            .collect();
        b.add(placed(ramp, r * v(0.0, 0.0, 12.0), r), floor);
        // A jump pad.
        let c = r * v(6.0, 0.0, 6.0);
        b.add(at(cylinder(1.0, 0.2, 48), c, 0.0), metal);
        b.add(ellipsoid(c + v(0.0, 0.2, 0.0), v(0.8, 0.15, 0.8), 3), pad);
        for i in 0..6 {
            let p = r * v(-15.0 + 6.0 * f64::from(i), 2.5, -19.8);
            b.add(at(torch(), p, 0.0), glow);
        }
    }
}

/// A player: torso, head, arms, legs and a weapon, standing on y = 0 facing +Z.
fn player(b: &mut Builder) {
    let armour = b.material([0.7, 0.2, 0.15]);
    let skin = b.material([0.85, 0.65, 0.5]);
    let metal = b.material([0.3, 0.3, 0.35]);
    b.add(at(tube(0.25, 0.7, 16, 2), v(0.0, 0.9, 0.0), 0.0), armour);
    b.add(ball(v(0.0, 1.8, 0.0), 0.17, 2), skin);
    for s in [-1.0, 1.0] {
        b.add(ball(v(s * 0.32, 1.55, 0.0), 0.1, 1), armour);
        b.add(
            at(cylinder(0.06, 0.6, 12), v(s * 0.34, 0.95, 0.0), 0.0),
            skin,
        );
        b.add(ball(v(s * 0.34, 0.92, 0.0), 0.07, 0), skin);
        b.add(
            at(cylinder(0.09, 0.9, 12), v(s * 0.12, 0.0, 0.0), 0.0),
            armour,
        );
        b.add(
            cuboid(
                v(s * 0.12 - 0.08, 0.0, -0.05),
                v(s * 0.12 + 0.08, 0.08, 0.15),
            ),
            metal,
        );
    }
    b.add(cuboid(v(0.28, 1.05, 0.0), v(0.4, 1.15, 0.6)), metal);
    b.add(cuboid(v(-0.25, 0.85, -0.25), v(0.25, 0.95, 0.25)), metal);
}

/// UT2003-like level: a ruined temple in a hilly courtyard with statues and torches.
fn ut_level(b: &mut Builder) {
    let grass = b.material([0.35, 0.5, 0.25]);
    let marble = b.material([0.8, 0.78, 0.72]);
    let stone = b.material([0.55, 0.5, 0.45]);
    let bronze = b.material([0.6, 0.45, 0.2]);
    let glow = b.material([0.9, 0.55, 0.15]);
    // The courtyard: a heightfield that stays flat around the temple.
    let n = 96;
    let ground: Tris = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            let p = |i: u32, j: u32| {
                let (u, w) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                let (x, z) = ((u - 0.5) * 80.0, (w - 0.5) * 80.0);
                let rim = ((x.hypot(z) - 16.0) / 20.0).clamp(0.0, 1.0);
                v(
                    x,
                    rim * 6.0 * (0.5 + 0.5 * fbm(3.0 * u, 3.0 * w, 2003, 5)),
                    z,
                )
            };
            [
                [p(i, j), p(i, j + 1), p(i + 1, j + 1)],
                [p(i, j), p(i + 1, j + 1), p(i + 1, j)],
            ]
        })
        .collect();
    b.add(ground, grass);
    // The temple: three steps, a ring of columns (some broken), architraves, arches.
    for s in 0..3 {
        let r = 12.0 - 0.8 * f64::from(s);
        b.add(cylinder(r, 0.3 * f64::from(s + 1), 64), stone);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(52_479);
    for k in 0..16 {
        let a = 22.5 * f64::from(k);
        let broken = rng.gen_bool(0.3);
        let h = if broken { rng.gen_range(3.0..6.0) } else { 9.0 };
        let p = yaw(a) * v(9.5, 0.9, 0.0);
        b.add(at(pillar(0.6, h, 32, 12), p, 0.0), marble);
    }
    for k in 0..8 {
        let r = yaw(45.0 * f64::from(k) + 11.25);
        b.add(
            placed(
                arch(v(0.0, 9.9, 9.3), 2.0, 24, 0.5, 1.0),
                DVec3::ZERO,
                r * yaw(90.0),
            ),
            marble,
        );
    }
    // Two statues: a body of stacked spheres on a plinth.
    for x in [-4.0, 4.0] {
        b.add(
            tiled_cuboid(v(x - 1.0, 0.9, -1.0), v(x + 1.0, 2.5, 1.0), 4),
            stone,
        );
        b.add(ellipsoid(v(x, 3.6, 0.0), v(0.6, 1.1, 0.5), 4), bronze);
        b.add(ball(v(x, 5.0, 0.0), 0.35, 3), bronze);
    }
    // Torches around the rim.
    for k in 0..24 {
        let p = yaw(15.0 * f64::from(k)) * v(13.0, 0.0, 0.0);
        b.add(at(cylinder(0.08, 1.8, 12), p, 0.0), stone);
        b.add(at(cone(0.3, -0.3, 12), p + v(0.0, 2.1, 0.0), 0.0), stone);
        b.add(ball(p + v(0.0, 2.2, 0.0), 0.2, 1), glow);
    }
}

// ------------------------------------------------------------------------ conference

/// The conference hall: walls, coffered ceiling with lamps, columns, a stage and windows with
/// curtains (the tables, chairs and lectern are instances of their own objects).
fn conference_hall(b: &mut Builder) {
    let wall = b.material([0.82, 0.78, 0.7]);
    let carpet = b.material([0.45, 0.15, 0.15]);
    let wood = b.material([0.5, 0.32, 0.18]);
    let lamp = b.material([0.95, 0.92, 0.8]);
    let curtain = b.material([0.3, 0.2, 0.45]);
    let glass = b.material([0.55, 0.65, 0.75]);
    b.add(shell(v(-20.0, 0.0, -12.0), v(20.0, 8.0, 12.0), 16), wall);
    b.add(
        panel(
            v(0.0, 0.01, 0.0),
            v(0.0, 0.0, 11.9),
            v(19.9, 0.0, 0.0),
            24,
            40,
        ),
        carpet,
    );
    for i in 0..10 {
        for j in 0..6 {
            let c = v(-18.0 + 4.0 * f64::from(i), 7.9, -10.0 + 4.0 * f64::from(j));
            let mut frame = Vec::new();
            for (a, d) in [
                (v(-2.0, -0.3, -2.0), v(2.0, 0.0, -1.85)),
                (v(-2.0, -0.3, 1.85), v(2.0, 0.0, 2.0)),
            ] {
                frame.extend(cuboid(c + a, c + d));
            }
            for (a, d) in [
                (v(-2.0, -0.3, -1.85), v(-1.85, 0.0, 1.85)),
                (v(1.85, -0.3, -1.85), v(2.0, 0.0, 1.85)),
            ] {
                frame.extend(cuboid(c + a, c + d));
            }
            b.add(frame, wood);
            b.add(ellipsoid(c - v(0.0, 0.3, 0.0), v(0.5, 0.25, 0.5), 2), lamp);
        }
    }
    for i in 0..5 {
        for z in [-11.0, 11.0] {
            b.add(
                at(
                    pillar(0.45, 8.0, 32, 12),
                    v(-16.0 + 8.0 * f64::from(i), 0.0, z),
                    0.0,
                ),
                wall,
            );
        }
    }
    b.add(
        tiled_cuboid(v(-8.0, 0.0, -12.0), v(8.0, 0.6, -8.0), 8),
        wood,
    );
    b.add(cuboid(v(-6.0, 2.0, -11.95), v(6.0, 6.0, -11.9)), glass);
    // Windows with curtains on both long walls.
    for i in 0..6 {
        for side in [-1.0, 1.0] {
            let x = side * 19.95;
            let z = -10.0 + 4.0 * f64::from(i);
            b.add(
                cuboid(v(x - 0.05, 2.0, z - 1.2), v(x + 0.05, 6.0, z + 1.2)),
                glass,
            );
            let folds: Tris = (0..16)
                .flat_map(|j| (0..32).map(move |k| (j, k)))
                .flat_map(|(j, k)| {
                    let p = |j: u32, k: u32| {
                        let s = f64::from(k) / 32.0;
                        let wave = 0.12 * (s * 8.0 * std::f64::consts::PI).sin();
                        v(
                            x - side * (0.3 + wave),
                            1.0 + 6.5 * f64::from(j) / 16.0,
                            z + 1.3 + 0.8 * s,
                        )
                    };
                    [
                        [p(j, k), p(j + 1, k), p(j + 1, k + 1)],
                        [p(j, k), p(j + 1, k + 1), p(j, k + 1)],
                    ]
                })
                .collect();
            b.add(folds, curtain);
        }
    }
}

/// A long conference table, 8 x 2, with rounded ends and six legs.
fn conference_table(b: &mut Builder) {
    let wood = b.material([0.45, 0.28, 0.15]);
    let metal = b.material([0.4, 0.4, 0.42]);
    b.add(
        tiled_cuboid(v(-3.0, 0.72, -1.0), v(3.0, 0.78, 1.0), 16),
        wood,
    );
    for x in [-3.0, 3.0] {
        let mut end = tube(1.0, 0.06, 256, 4);
        end.extend(disc(1.0, 0.0, 256));
        end.extend(disc(1.0, 0.06, 256));
        b.add(at(end, v(x, 0.72, 0.0), 0.0), wood);
    }
    for x in [-3.5, 0.0, 3.5] {
        for z in [-0.6, 0.6] {
            b.add(at(tube(0.06, 0.72, 32, 8), v(x, 0.0, z), 0.0), metal);
        }
    }
    b.add(
        tiled_cuboid(v(-3.5, 0.2, -0.05), v(3.5, 0.26, 0.05), 8),
        metal,
    );
}

/// An upholstered conference chair facing +Z: cushioned seat and back, arms, four legs.
fn conference_chair(b: &mut Builder) {
    let fabric = b.material([0.15, 0.2, 0.35]);
    let metal = b.material([0.55, 0.55, 0.58]);
    b.add(
        tiled_cuboid(v(-0.25, 0.42, -0.25), v(0.25, 0.5, 0.25), 9),
        fabric,
    );
    b.add(
        tiled_cuboid(v(-0.25, 0.5, -0.3), v(0.25, 1.0, -0.24), 9),
        fabric,
    );
    for s in [-1.0, 1.0] {
        b.add(
            tiled_cuboid(
                v(s * 0.28 - 0.03, 0.62, -0.25),
                v(s * 0.28 + 0.03, 0.66, 0.2),
                5,
            ),
            metal,
        );
        b.add(
            at(tube(0.015, 0.16, 16, 4), v(s * 0.28, 0.5, 0.15), 0.0),
            metal,
        );
        for z in [-0.2, 0.2] {
            b.add(at(tube(0.02, 0.42, 16, 8), v(s * 0.21, 0.0, z), 0.0), metal);
        }
    }
}

/// A lectern on the stage.
fn lectern(b: &mut Builder) {
    let wood = b.material([0.4, 0.25, 0.12]);
    let metal = b.material([0.3, 0.3, 0.32]);
    b.add(tiled_cuboid(v(-0.4, 0.0, -0.3), v(0.4, 1.1, 0.3), 6), wood);
    b.add(
        tiled_cuboid(v(-0.45, 1.1, -0.35), v(0.45, 1.15, 0.35), 4),
        wood,
    );
    b.add(at(tube(0.01, 0.35, 8, 4), v(0.0, 1.15, 0.2), 0.0), metal);
    b.add(ball(v(0.0, 1.52, 0.2), 0.04, 2), metal);
}

// ------------------------------------------------------------------------ SunCOR

/// A sunflower, 2 high: stem, six leaves, a seed head facing +Z and 24 petals.
fn sunflower(b: &mut Builder) {
    let green = b.material([0.25, 0.5, 0.15]);
    let seeds = b.material([0.35, 0.22, 0.1]);
    let petal = b.material([0.95, 0.75, 0.1]);
    b.add(tube(0.04, 1.8, 64, 64), green);
    for k in 0..6 {
        let y = 0.4 + 0.2 * f64::from(k);
        let leaf = panel(
            v(0.0, 0.0, 0.0),
            v(0.15, 0.0, 0.0),
            v(0.0, 0.04, 0.08),
            16,
            16,
        );
        let leaf: Tris = leaf
            .into_iter()
            .map(|t| t.map(|p| v(p.x + 0.19, p.y - 0.3 * (p.x + 0.15).powi(2), p.z)))
            .collect();
        b.add(at(leaf, v(0.0, y, 0.0), 137.5 * f64::from(k)), green);
    }
    let tilt = DMat3::from_rotation_x(-0.35);
    let head = v(0.0, 1.85, 0.05);
    b.add(
        placed(ellipsoid(DVec3::ZERO, v(0.3, 0.3, 0.07), 5), head, tilt),
        seeds,
    );
    for k in 0..24 {
        let spin = DMat3::from_rotation_z(std::f64::consts::TAU * f64::from(k) / 24.0);
        let p = panel(
            v(0.42, 0.0, 0.0),
            v(0.13, 0.0, 0.0),
            v(0.0, 0.05, 0.0),
            16,
            2,
        );
        b.add(placed(p, head, tilt * spin), petal);
    }
}

// ------------------------------------------------------------------------ scene files

fn v3(a: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", a[0], a[1], a[2])
}

/// Camera, render settings and lights of a scene file.
fn header(
    purpose: &str,
    eye: [f64; 3],
    look_at: [f64; 3],
    fov_y: f64,
    background: [f64; 3],
    lights: &[[f64; 3]],
) -> String {
    let mut s = format!(
        "# Generated by `dynrt paper-scenes` (src/scene/paper.rs); do not edit, run `make paper-scenes`.\n\
         # {purpose}\n\
         [camera]\neye = {}\nlook_at = {}\nfov_y = {fov_y:?}\nwidth = {WIDTH}\nheight = {HEIGHT}\n\n\
         [render]\nshadows = true\nreflection_depth = 0\nambient = 0.2\nbackground = {}\n",
        v3(eye),
        v3(look_at),
        v3(background)
    );
    for l in lights {
        s.push_str(&format!(
            "\n[[lights]]\nposition = {}\ncolor = [0.9, 0.9, 0.85]\n",
            v3(*l)
        ));
    }
    s
}

fn model_object(name: &str, model: &str) -> String {
    format!("\n[[objects]]\nname = \"{name}\"\ngenerate = {{ kind = \"paper\", model = \"{model}\" }}\n")
}

fn instance(
    object: &str,
    name: &str,
    translate: [f64; 3],
    rotate_y: f64,
    scale: [f64; 3],
) -> String {
    format!(
        "\n[[instances]]\nobject = \"{object}\"\nname = \"{name}\"\ntranslate = {}\nrotate = [0.0, {rotate_y:?}, 0.0]\nscale = {}\n",
        v3(translate),
        v3(scale)
    )
}

const SKY: [f64; 3] = [0.55, 0.7, 0.9];

/// The scene file of Table 3's row `file` (see [`TABLE3`]), or `None` for another name.
pub fn scene_toml(file: &str) -> Option<String> {
    let one = [1.0; 3];
    Some(match file {
        "scene6" => {
            header(
                "Scene6 (806 triangles, 1 object): a room with a table, four chairs, a ball and two cabinets, one mesh.",
                [3.2, 2.2, 2.6],
                [0.0, 0.7, -0.4],
                60.0,
                [0.0; 3],
                &[[0.0, 2.8, 0.5]],
            ) + &model_object("room", "scene6")
        }
        "castle" => {
            let mut s = header(
                "Castle (20,891 triangles, 8 objects): ground, curtain walls, keep, four towers and a gatehouse.",
                [34.0, 20.0, 44.0],
                [0.0, 3.0, 0.0],
                45.0,
                SKY,
                &[[60.0, 80.0, 40.0]],
            );
            s.push_str("\n[[objects]]\nname = \"ground\"\ngenerate = { kind = \"terrain\", size = 48, seed = 20891, amplitude = 1.5, extent = 80.0, octaves = 5, frequency = 3.0 }\ncolor = [0.4, 0.55, 0.3]\n");
            for (o, m) in [("walls", "castle_walls"), ("keep", "castle_keep"), ("tower", "castle_tower"), ("gate", "castle_gate")] {
                s.push_str(&model_object(o, m));
            }
            s.push_str(&instance("ground", "ground", [0.0, -1.6, 0.0], 0.0, one));
            s.push_str(&instance("walls", "walls", [0.0; 3], 0.0, one));
            s.push_str(&instance("keep", "keep", [-3.0, 0.0, -3.0], 0.0, one));
            for (k, (x, z)) in [(-14.0, -14.0), (14.0, -14.0), (-14.0, 14.0), (14.0, 14.0)].iter().enumerate() {
                s.push_str(&instance("tower", &format!("tower{k}"), [*x, 0.0, *z], 0.0, one));
            }
            s + &instance("gate", "gate", [0.0, 0.0, 13.5], 0.0, one)
        }
        "office" => {
            header(
                "Office (34,312 triangles, 1 object): an open-plan floor of 12 workstations, bookshelves, columns, lamps; one mesh.",
                [9.0, 2.6, 6.5],
                [-2.0, 0.6, -2.0],
                60.0,
                [0.0; 3],
                &[[0.0, 3.0, 0.0]],
            ) + &model_object("office", "office")
        }
        "quake3" => {
            header(
                "Quake3 (39,424 triangles, 1 object): a game arena (pillars, arches, galleries, ramps, jump pads, torches), one mesh.",
                [0.0, 6.5, 15.0],
                [0.0, 1.5, 0.0],
                65.0,
                [0.0; 3],
                &[[0.0, 11.0, 0.0]],
            ) + &model_object("arena", "arena")
        }
        "quake3_p" => {
            let mut s = header(
                "Quake3-p (52,790 triangles, 17 objects): the Quake3 arena with 16 players running over 8 frames.",
                [0.0, 6.5, 15.0],
                [0.0, 1.5, 0.0],
                65.0,
                [0.0; 3],
                &[[0.0, 11.0, 0.0]],
            );
            s.push_str(&model_object("arena", "arena"));
            s.push_str(&model_object("player", "player"));
            s.push_str("\n[[instances]]\nobject = \"arena\"\n");
            let mut rng = ChaCha8Rng::seed_from_u64(52_790);
            for k in 0..16 {
                let p = [rng.gen_range(-15.0..15.0), 0.0, rng.gen_range(-15.0..15.0)];
                let heading: f64 = rng.gen_range(0.0..360.0);
                let run = yaw(heading) * v(0.0, 0.0, 4.0);
                s.push_str(&instance("player", &format!("player{k}"), p, heading, one));
                s.push_str(&format!(
                    "[instances.animate]\nframes = 8\ntranslate = {}\n",
                    v3([p[0] + run.x, 0.0, p[2] + run.z])
                ));
            }
            s
        }
        "ut2003" => {
            header(
                "UT2003 (52,479 triangles, 1 object): a ruined temple with statues in a hilly courtyard, one mesh.",
                [22.0, 9.0, 24.0],
                [0.0, 3.0, 0.0],
                55.0,
                SKY,
                &[[30.0, 40.0, 20.0]],
            ) + &model_object("level", "ut_level")
        }
        "conference" => {
            let mut s = header(
                "Conference (282,805 triangles, 54 objects): a hall, a lectern, 4 tables and 48 chairs (instances of 4 objects).",
                [18.0, 6.0, 3.0],
                [-4.0, 0.5, 1.0],
                60.0,
                [0.0; 3],
                &[[0.0, 7.0, 2.0]],
            );
            for (o, m) in [("hall", "conference_hall"), ("lectern", "lectern"), ("table", "conference_table"), ("chair", "conference_chair")] {
                s.push_str(&model_object(o, m));
            }
            s.push_str(&instance("hall", "hall", [0.0; 3], 0.0, one));
            s.push_str(&instance("lectern", "lectern", [0.0, 0.6, -9.5], 0.0, one));
            for (k, (tx, tz)) in [(-8.0, -2.0), (8.0, -2.0), (-8.0, 6.0), (8.0, 6.0)]
                .into_iter()
                .enumerate()
            {
                s.push_str(&instance("table", &format!("table{k}"), [tx, 0.0, tz], 0.0, one));
                for i in 0..6 {
                    let x = tx - 3.75 + 1.5 * i as f64;
                    s.push_str(&instance("chair", &format!("chair{}", 12 * k + 2 * i), [x, 0.0, tz - 1.3], 0.0, one));
                    s.push_str(&instance("chair", &format!("chair{}", 12 * k + 2 * i + 1), [x, 0.0, tz + 1.3], 180.0, one));
                }
            }
            s
        }
        "terrain" => {
            let mut s = header(
                "Terrain (10.47 M instanced triangles, 264 tiles): one 141x141-cell tile instanced 24 x 11 times, \
                 mirrored in x and z on alternate tiles so that neighbours share their edges.",
                [0.0, 30.0, 60.0],
                [0.0, 0.0, 0.0],
                60.0,
                SKY,
                &[[100.0, 120.0, 60.0]],
            );
            s.push_str("\n[[objects]]\nname = \"tile\"\ngenerate = { kind = \"terrain\", size = 141, seed = 10470, amplitude = 3.0, extent = 10.0, octaves = 6, frequency = 2.0 }\ncolor = [0.45, 0.55, 0.3]\n");
            for j in 0..11 {
                for i in 0..24 {
                    let t = [10.0 * (f64::from(i) - 11.5), 0.0, 10.0 * (f64::from(j) - 5.0)];
                    let sx = if i % 2 == 0 { 1.0 } else { -1.0 };
                    let sz = if j % 2 == 0 { 1.0 } else { -1.0 };
                    s.push_str(&instance("tile", &format!("tile{i}_{j}"), t, 0.0, [sx, 1.0, sz]));
                }
            }
            s
        }
        "suncor" => {
            let mut s = header(
                "SunCOR (187 M instanced triangles, 5,622 instances): a field of 77 x 73 sunflowers of 33,280 triangles \
                 each on a ground plane, turning over 8 frames.",
                [0.0, 9.0, 62.0],
                [0.0, 0.0, 20.0],
                50.0,
                SKY,
                &[[40.0, 80.0, 60.0]],
            );
            s.push_str("\n[[objects]]\nname = \"ground\"\ngenerate = { kind = \"plane\", size = [140.0, 140.0] }\ncolor = [0.4, 0.3, 0.2]\n");
            s.push_str(&model_object("sunflower", "sunflower"));
            s.push_str("\n[[instances]]\nobject = \"ground\"\n");
            s + "\n[[fields]]\nname = \"field\"\nobject = \"sunflower\"\ncount_x = 77\ncount_z = 73\nspacing = 1.5\n\
                 jitter = 0.4\nseed = 5622\nrotate = [0.0, -30.0, 0.0]\nrandom_yaw = false\n\
                 animate = { frames = 8, rotate_by = [0.0, 60.0, 0.0] }\n"
        }
        _ => return None,
    })
}

/// Every scene file of the suite: (file name, contents), in Table 3's order.
pub fn suite_files() -> Vec<(String, String)> {
    TABLE3
        .iter()
        .map(|r| {
            let text = scene_toml(r.file).expect("every Table 3 row has a scene");
            (format!("{}.toml", r.file), text)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_builds_deterministically_and_unknown_names_are_refused() {
        for name in MODELS {
            let a = model(name).unwrap_or_else(|| panic!("{name}"));
            assert!(!a.triangles.is_empty(), "{name}");
            assert_eq!(a.triangles.len(), a.triangle_material.len(), "{name}");
            assert!(a
                .triangle_material
                .iter()
                .all(|&m| (m as usize) < a.materials.len()));
            assert_eq!(model(name).unwrap().triangles, a.triangles, "{name}");
            println!("{name}: {} triangles", a.triangles.len());
        }
        assert!(model("bunny").is_none());
        assert_eq!(MODELS.len(), {
            let mut m = MODELS.to_vec();
            m.sort();
            m.dedup();
            m.len()
        });
        assert!(scene_toml("bunny").is_none());
    }

    /// The suite's scenes against Table 3: the object count exactly, the triangle count within
    /// [`TRIANGLE_TOLERANCE`], the paper's resolution, lights and shadows.
    #[test]
    fn every_scene_has_its_rows_objects_and_triangles() {
        let mut bad = Vec::new();
        for r in TABLE3 {
            let text = scene_toml(r.file).unwrap();
            let path = format!("{}.toml", r.file);
            let s = crate::scene::Scene::from_toml_str(&text, std::path::Path::new("."), &path)
                .unwrap_or_else(|e| panic!("{e}"));
            let tris = s.instanced_triangle_count();
            println!(
                "{}: {} objects, {} unique triangles, {} instances, {} instanced triangles ({:+.2}%)",
                r.name,
                s.objects.len(),
                s.triangle_count(),
                s.instances.len(),
                tris,
                100.0 * (tris as f64 / r.triangles as f64 - 1.0)
            );
            assert_eq!(s.instances.len(), r.objects, "{}", r.name);
            if (tris as f64 / r.triangles as f64 - 1.0).abs() > TRIANGLE_TOLERANCE {
                bad.push(format!(
                    "{}: {tris} triangles against the paper's {}",
                    r.name, r.triangles
                ));
            }
            assert_eq!((s.camera.width, s.camera.height), (WIDTH, HEIGHT));
            assert!(s.render.shadows && !s.lights.is_empty(), "{}", r.name);
            assert!(s.warnings.is_empty(), "{}: {:?}", r.name, s.warnings);
        }
        assert!(bad.is_empty(), "{bad:?}");
    }
}
