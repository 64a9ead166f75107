//! The scene TOML as serde sees it (docs/ARCHITECTURE.md, "Scene files" plus the extensions documented in
//! `scene/mod.rs`). Every table denies unknown fields so a misspelt key is an error, not a
//! silently ignored setting. Values that later checks may reject are `Spanned` so the error can
//! name their line. Nothing here is validated; `scene/mod.rs` turns this into a `Scene`.

use serde::Deserialize;
use toml::Spanned;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub camera: Spanned<CameraDef>,
    #[serde(default)]
    pub render: Option<Spanned<RenderDef>>,
    #[serde(default)]
    pub lights: Vec<Spanned<LightDef>>,
    #[serde(default)]
    pub objects: Vec<Spanned<ObjectDef>>,
    #[serde(default)]
    pub instances: Vec<Spanned<InstanceDef>>,
    #[serde(default)]
    pub fields: Vec<Spanned<FieldDef>>,
}

fn default_up() -> Spanned<[f64; 3]> {
    Spanned::new(0..0, [0.0, 1.0, 0.0])
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDef {
    pub eye: Spanned<[f64; 3]>,
    pub look_at: Spanned<[f64; 3]>,
    #[serde(default = "default_up")]
    pub up: Spanned<[f64; 3]>,
    pub fov_y: Spanned<f64>,
    pub width: Spanned<u32>,
    pub height: Spanned<u32>,
}

fn default_true() -> bool {
    true
}
fn default_ambient() -> Spanned<f64> {
    Spanned::new(0..0, 0.1)
}
fn default_reflection_depth() -> Spanned<u32> {
    Spanned::new(0..0, 0)
}
fn default_black() -> Spanned<[f64; 3]> {
    Spanned::new(0..0, [0.0; 3])
}
fn default_white() -> Spanned<[f64; 3]> {
    Spanned::new(0..0, [1.0; 3])
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDef {
    #[serde(default = "default_true")]
    pub shadows: bool,
    #[serde(default = "default_reflection_depth")]
    pub reflection_depth: Spanned<u32>,
    #[serde(default = "default_ambient")]
    pub ambient: Spanned<f64>,
    #[serde(default = "default_black")]
    pub background: Spanned<[f64; 3]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDef {
    pub position: Spanned<[f64; 3]>,
    #[serde(default = "default_white")]
    pub color: Spanned<[f64; 3]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDef {
    pub name: Spanned<String>,
    #[serde(default)]
    pub mesh: Option<Spanned<String>>,
    #[serde(default)]
    pub generate: Option<Spanned<GenerateDef>>,
    /// Single material for the whole object (see the material rules in `scene/mod.rs`).
    #[serde(default)]
    pub color: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub mirror: Option<Spanned<f64>>,
}

fn one() -> f64 {
    1.0
}
fn one3() -> [f64; 3] {
    [1.0; 3]
}
fn one2() -> [f64; 2] {
    [1.0; 2]
}
fn one_u32() -> u32 {
    1
}
fn two_u32() -> u32 {
    2
}
fn five_u32() -> u32 {
    5
}
fn four() -> f64 {
    4.0
}
fn ten() -> f64 {
    10.0
}

/// `generate = { kind = "...", ... }`; parameters per kind, all optional except terrain `size`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum GenerateDef {
    /// Axis-aligned box centred at the origin.
    Box {
        #[serde(default = "one3")]
        size: [f64; 3],
    },
    /// Quad in the XZ plane at y = 0, centred, facing +Y, cut into `subdivisions`^2 cells.
    Plane {
        #[serde(default = "one2")]
        size: [f64; 2],
        #[serde(default = "one_u32")]
        subdivisions: u32,
    },
    /// Subdivided icosahedron centred at the origin: 20 * 4^subdivisions triangles.
    Sphere {
        #[serde(default = "one")]
        radius: f64,
        #[serde(default = "two_u32")]
        subdivisions: u32,
    },
    /// The Cornell box in x in [-1, 1], y in [0, 2], z in [-1, 1], open towards +z.
    CornellBox {
        #[serde(default)]
        closed_front: bool,
        #[serde(default)]
        mirror_tall_block: f64,
    },
    /// Fractal value-noise heightfield: `size` x `size` cells, 2 size^2 triangles.
    Terrain {
        size: u32,
        #[serde(default)]
        seed: u64,
        #[serde(default = "one")]
        amplitude: f64,
        #[serde(default = "ten")]
        extent: f64,
        #[serde(default = "five_u32")]
        octaves: u32,
        #[serde(default = "four")]
        frequency: f64,
    },
    /// One of the paper suite's models (`scene/paper.rs`, `paper::MODELS`), with its own
    /// materials.
    Paper { model: String },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceDef {
    pub object: Spanned<String>,
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub translate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub rotate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub scale: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub animate: Option<Spanned<AnimateDef>>,
}

/// End values of an instance's animation; missing ones stay at the instance's own value.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimateDef {
    pub frames: Spanned<u32>,
    #[serde(default)]
    pub translate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub rotate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub scale: Option<Spanned<[f64; 3]>>,
}

/// `[[fields]]`: a grid of instances (see `scene/field.rs`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldDef {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub object: Option<Spanned<String>>,
    #[serde(default)]
    pub objects: Option<Spanned<Vec<String>>>,
    pub count_x: Spanned<u32>,
    pub count_z: Spanned<u32>,
    pub spacing: Spanned<f64>,
    #[serde(default)]
    pub origin: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub jitter: Option<Spanned<f64>>,
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub rotate: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub random_yaw: bool,
    #[serde(default)]
    pub scale: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub animate: Option<Spanned<FieldAnimateDef>>,
}

/// A field's animation is relative: every instance moves by `translate_by` and turns by
/// `rotate_by` (degrees) from frame 0 to frame `frames - 1`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldAnimateDef {
    pub frames: Spanned<u32>,
    #[serde(default)]
    pub translate_by: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub rotate_by: Option<Spanned<[f64; 3]>>,
}
