//! The hardware memory map: the scene as the processor's SRAM banks hold it, in words of the
//! chosen number format. Produced once per frame and read by both the golden model and the
//! RTL (as `$readmemh` images), so the two can only differ in how they compute, never in what
//! they read.
//!
//! # Banks
//! Modelled on the paper's board (Alpha Data ADM-XRC-II): six independent banks of 32-bit
//! words, 4 MB each by default. Each structure sits in its own bank so that the units that
//! read it never wait for one another:
//!
//! | bank | contents | words per item |
//! |---|---|---|
//! | 0 `NODES` | kd nodes: every object tree, then the top-level tree (rewritten each frame) | 2 per node |
//! | 1 `LISTS` | leaf lists: global triangle ids of object leaves, then instance ids of top-level leaves | 1 per reference |
//! | 2 `TRIANGLES_A` | words 0-5 of the Woop unit-triangle transform `T` (the u row and half the v row), then the object-space unit normal's x and y | 8 per triangle |
//! | 3 `TRIANGLES_B` | words 6-11 of `T` (the v row's other half and the t row), then the normal's z and the material index | 8 per triangle |
//! | 4 `INSTANCES` | per instance: world-to-object 3x4 (12), normal matrix 3x3 object-to-world (9), object root node, first global triangle, object index (rewritten each frame) | 24 per instance |
//! | 5 `FRAME` | camera 3x4 and eye, render constants, lights, materials (diffuse r, g, b, mirror), then the frame buffer | see [`FrameMap`] |
//!
//! Splitting a triangle's 16 words over two banks lets the intersection read them in parallel
//! and fits 131,072 triangles (a 256x256 terrain) in the paper's 4 MB banks. The transform's
//! 12 words are split evenly, 6 and 6 ([`TRANSFORM_BANK_WORDS`]), so that the triangle tester
//! fetches a triangle in 6 clocks from both banks at once (an 8 + 4 split took 8).
//!
//! # Word formats
//! - A float word holds an `eXmY` value right-aligned (the format is at most 32 bits wide).
//! - A kd node is two words. Word 0: bits 31..30 = 0, 1, 2 for an inner node splitting x, y,
//!   z, or 3 for a leaf; bits 29..0 = for an inner node the node index of its left child (the
//!   right child is the next node), for a leaf the bank-1 address of its list. Word 1: the
//!   split position (float) or the leaf's reference count.
//! - A 3x4 matrix is `m00 m01 m02 n0 m10 m11 m12 n1 m20 m21 m22 n2`; points transform as
//!   `x' = ((m00*x + m01*y) + m02*z) + n0` (see `crate::units::transform`).
//! - A frame-buffer word is `0x00RRGGBB`.
//!
//! Every value the host computes (triangle transforms, instance matrices, camera) is computed
//! in f64 and rounded once into the format by [`Format::from_f64`].
//!
//! # Coordinates
//! Each object is stored relative to its anchor (see [`SceneTrees`]): the centre of its
//! bounding box when the object lies farther from its file's origin than its own size, so its
//! coordinates are as small as its size allows. The hardware's
//! coordinates are the world's moved to [`LayoutInfo::origin`]: the eye when there is a top
//! level (camera-relative, so the instance matrices of objects near the camera have small
//! translations however far from the world origin the scene puts them), and the anchor of the
//! only object when there is none (it has no instance matrix to move it). The instance
//! matrices, the eye and the lights are stored in these coordinates; distances along rays do
//! not change.

mod build;

pub use build::{build, check_capacity, unit_triangle_transform, LayoutError, SceneTrees};

use crate::fp::Format;

pub const NODES: usize = 0;
pub const LISTS: usize = 1;
pub const TRIANGLES_A: usize = 2;
pub const TRIANGLES_B: usize = 3;
pub const INSTANCES: usize = 4;
pub const FRAME: usize = 5;
/// The board's memory banks (6 of 4 MB, as the paper's prototype).
pub const BANKS: usize = 6;
pub const BANK_NAMES: [&str; BANKS] = [
    "nodes",
    "lists",
    "triangles_a",
    "triangles_b",
    "instances",
    "frame",
];

pub const NODE_WORDS: usize = 2;
/// Words per triangle in each of the two triangle banks.
pub const TRIANGLE_BANK_WORDS: usize = 8;
/// Words of a triangle's unit-triangle transform in each triangle bank (the first of its
/// `TRIANGLE_BANK_WORDS`); the two shading words follow.
pub const TRANSFORM_BANK_WORDS: usize = 6;
pub const MATERIAL_WORDS: usize = 4;
pub const INSTANCE_WORDS: usize = 24;
pub const LIGHT_WORDS: usize = 6;
pub const LEAF_TAG: u32 = 3;

/// Offsets inside an instance record.
pub mod instance_word {
    pub const WORLD_TO_OBJECT: usize = 0;
    pub const NORMAL_MATRIX: usize = 12;
    pub const ROOT: usize = 21;
    pub const FIRST_TRIANGLE: usize = 22;
    pub const OBJECT: usize = 23;
}

/// The memory the layout must fit in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryConfig {
    pub banks: usize,
    pub bank_bytes: usize,
}

impl MemoryConfig {
    /// The paper's board: 6 banks of 4 MB.
    pub const ADM_XRC_II: MemoryConfig = MemoryConfig {
        banks: 6,
        bank_bytes: 4 << 20,
    };
    pub fn bank_words(&self) -> usize {
        self.bank_bytes / 4
    }
    /// Most triangles the memory holds: each takes `TRIANGLE_BANK_WORDS` in each triangle bank
    /// (131,072 on the paper's board).
    pub fn max_triangles(&self) -> usize {
        self.bank_words() / TRIANGLE_BANK_WORDS
    }
    /// Most instances the instance bank holds (43,690 on the paper's board).
    pub fn max_instances(&self) -> usize {
        self.bank_words() / INSTANCE_WORDS
    }
}

impl Default for MemoryConfig {
    fn default() -> Self {
        Self::ADM_XRC_II
    }
}

/// Addresses inside bank 5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameMap;

impl FrameMap {
    /// Camera: 3x4 matrix taking pixel (x, y, 0) to the primary ray direction.
    pub const CAMERA: usize = 0;
    /// Eye position (3 floats).
    pub const EYE: usize = 12;
    pub const AMBIENT: usize = 15;
    /// Background colour (3 floats).
    pub const BACKGROUND: usize = 16;
    /// Smallest t of a shadow ray (a fraction of the way to the light).
    pub const SHADOW_T_MIN: usize = 19;
    /// Smallest t of a mirror ray (in units of the ray's direction length).
    pub const MIRROR_T_MIN: usize = 20;
    /// The float constants 0, 1, 2 (read by units that need them).
    pub const ZERO: usize = 21;
    pub const ONE: usize = 22;
    pub const TWO: usize = 23;
    pub const LIGHTS: usize = 24;
}

/// A decoded kd node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Node {
    Inner { axis: usize, split: u32, left: u32 },
    Leaf { list: u32, count: u32 },
}

/// What the generator tells the hardware besides the memory contents (as parameters).
#[derive(Clone, Debug, PartialEq)]
pub struct LayoutInfo {
    pub width: u32,
    pub height: u32,
    pub shadows: bool,
    pub reflection_depth: u32,
    pub light_count: u32,
    /// `None` for a scene of one untransformed object: rays enter the object tree directly.
    pub top_root: Option<u32>,
    /// Bank-1 address of the top-level tree's leaf lists, which run to the end of the bank
    /// (the bank's length when there is no top level).
    pub top_lists: u32,
    /// Bank-5 address of the material table.
    pub materials: u32,
    /// Root node of the only object when there is no top level.
    pub object_root: u32,
    pub instance_count: u32,
    pub triangle_count: u32,
    pub frame_buffer: u32,
    /// Deepest object tree and the top-level tree: the traversal stacks' sizes.
    pub object_depth: u32,
    pub top_depth: u32,
    /// First global triangle index of every object (to report object-local indices).
    pub object_first_triangle: Vec<u32>,
    /// World position of the hardware's coordinate origin: the only object's anchor when
    /// there is no top level, else the eye.
    pub origin: [f64; 3],
}

/// What the host writes to the banks between two frames of an animated scene: the top-level
/// tree (its nodes and its leaf lists, rebuilt every frame and stored after the object trees)
/// and the instances' matrices (world-to-object and normal matrix; the rest of an instance
/// record, its object's root, first triangle and index, does not change). Bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameUpdate {
    pub top_nodes: usize,
    pub top_lists: usize,
    pub instance_matrices: usize,
}

impl FrameUpdate {
    pub fn bytes(&self) -> usize {
        self.top_nodes + self.top_lists + self.instance_matrices
    }
}

/// The banks' contents plus what the hardware is parameterized with.
#[derive(Clone, Debug)]
pub struct Layout {
    pub format: Format,
    pub memory: MemoryConfig,
    pub banks: Vec<Vec<u32>>,
    pub info: LayoutInfo,
}

impl Layout {
    /// The bytes a host writes to make this layout's frame out of another frame's (see
    /// [`FrameUpdate`]), measured on this layout's banks. All zero without a top level.
    pub fn frame_update(&self) -> FrameUpdate {
        let Some(top_root) = self.info.top_root else {
            return FrameUpdate {
                top_nodes: 0,
                top_lists: 0,
                instance_matrices: 0,
            };
        };
        let word_bytes = 4;
        FrameUpdate {
            top_nodes: (self.banks[NODES].len() - top_root as usize * NODE_WORDS) * word_bytes,
            top_lists: (self.banks[LISTS].len() - self.info.top_lists as usize) * word_bytes,
            // The two matrices are the first words of a record, up to the object's root.
            instance_matrices: self.info.instance_count as usize * instance_word::ROOT * word_bytes,
        }
    }

    pub fn word(&self, bank: usize, addr: u32) -> u32 {
        self.banks[bank][addr as usize]
    }
    pub fn words<const N: usize>(&self, bank: usize, addr: usize) -> [u32; N] {
        self.banks[bank][addr..addr + N]
            .try_into()
            .expect("slice of N words")
    }
    pub fn node(&self, index: u32) -> Node {
        let a = index as usize * NODE_WORDS;
        let (w0, w1) = (self.banks[NODES][a], self.banks[NODES][a + 1]);
        let tag = w0 >> 30;
        let payload = w0 & 0x3fff_ffff;
        if tag == LEAF_TAG {
            Node::Leaf {
                list: payload,
                count: w1,
            }
        } else {
            Node::Inner {
                axis: tag as usize,
                split: w1,
                left: payload,
            }
        }
    }
    /// The 12 words of a triangle's unit-triangle transform, assembled from both banks.
    pub fn triangle_transform(&self, triangle: u32) -> [u32; 12] {
        let a = triangle as usize * TRIANGLE_BANK_WORDS;
        let n = TRANSFORM_BANK_WORDS;
        let mut m = [0; 12];
        m[..n].copy_from_slice(&self.banks[TRIANGLES_A][a..a + n]);
        m[n..].copy_from_slice(&self.banks[TRIANGLES_B][a..a + n]);
        m
    }
    /// A triangle's object-space unit normal and material index (the two shading words of
    /// each triangle bank: `n.x n.y` and `n.z material`).
    pub fn triangle_shading(&self, triangle: u32) -> ([u32; 3], u32) {
        let a = triangle as usize * TRIANGLE_BANK_WORDS + TRANSFORM_BANK_WORDS;
        let (xy, z_material) = (&self.banks[TRIANGLES_A], &self.banks[TRIANGLES_B]);
        ([xy[a], xy[a + 1], z_material[a]], z_material[a + 1])
    }
    /// A material's diffuse colour and mirror reflectivity.
    pub fn material(&self, material: u32) -> ([u32; 3], u32) {
        let a = (self.info.materials + material * MATERIAL_WORDS as u32) as usize;
        (self.words::<3>(FRAME, a), self.banks[FRAME][a + 3])
    }
    /// The frame constants of direct shading: ambient, background and the lights' words.
    pub fn shading_constants(&self) -> crate::units::ShadingConstants {
        let w = |k: usize| self.banks[FRAME][k];
        let lights = (0..self.info.light_count as usize)
            .map(|light| {
                let at = FrameMap::LIGHTS + light * LIGHT_WORDS;
                crate::units::LightWords {
                    position: self.words::<3>(FRAME, at),
                    color: self.words::<3>(FRAME, at + 3),
                }
            })
            .collect();
        crate::units::ShadingConstants {
            ambient: w(FrameMap::AMBIENT),
            background: self.words::<3>(FRAME, FrameMap::BACKGROUND),
            lights,
        }
    }
    /// Words used per bank (frame buffer included).
    pub fn used_words(&self) -> Vec<usize> {
        self.banks.iter().map(Vec::len).collect()
    }
    pub fn total_bytes(&self) -> usize {
        self.used_words().iter().sum::<usize>() * 4
    }
}

pub(crate) fn encode_inner(axis: usize, left: u32) -> u32 {
    ((axis as u32) << 30) | left
}
pub(crate) fn encode_leaf(list: u32) -> u32 {
    (LEAF_TAG << 30) | list
}
