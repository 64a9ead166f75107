//! `SceneError`: every way a scene can be rejected, each naming the file, the line where one is
//! known (TOML spans, OBJ line numbers), the object or instance concerned, the problem, and what
//! to do about it.
//!
//! Display format: `FILE[:LINE]: [ITEM: ]PROBLEM`, e.g.
//! `scenes/x.toml:14: instance 'ship#3': unknown object 'shp' (defined: ship, box); ...`.

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;

/// A scene that cannot be loaded. `file` is the file that holds the problem (the scene TOML, or
/// the OBJ/MTL file for mesh problems); `line` is 1-based; `item` names the object, instance,
/// field or light (`object 'bunny'`, `instance 'ship#3'`, ...).
#[derive(Debug, Error)]
pub struct SceneError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub item: Option<String>,
    /// Not a `#[source]`: the display already says it, and an error chain would say it twice.
    pub problem: Problem,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": ")?;
        if let Some(item) = &self.item {
            write!(f, "{item}: ")?;
        }
        write!(f, "{}", self.problem)
    }
}

/// What is wrong, with the fix in the message.
#[derive(Debug, Error)]
pub enum Problem {
    /// A file that is not a regular file, too large, or not text (the message names it).
    #[error("{0}")]
    Input(crate::input::InputError),
    #[error("{0}; the scene schema is in docs/ARCHITECTURE.md (section \"Scene files\")")]
    Toml(String),
    #[error("unknown object '{name}' (defined objects: {known}); define it under [[objects]] or fix the name")]
    UnknownObject { name: String, known: String },
    #[error("duplicate object name '{name}' (first defined on line {first_line}); give every object a unique name")]
    DuplicateObject { name: String, first_line: usize },
    #[error(
        "an object needs exactly one of `mesh = \"file.obj\"` or `generate = {{ kind = ... }}`"
    )]
    ObjectSource,
    #[error("the scene has no [[objects]]; add at least one object, e.g. `[[objects]]` with `name = \"box\"` and `generate = {{ kind = \"box\" }}`")]
    NoObjects,
    #[error("broken OBJ: {0}; fix or re-export the mesh")]
    BrokenObj(String),
    #[error("material library problem: {0}; fix the .mtl file or remove the `mtllib` line")]
    BrokenMtl(String),
    #[error("{what} is not finite (NaN or infinity); use finite numbers")]
    NonFinite { what: String },
    #[error("the mesh has no usable triangles ({faces} triangles read, {degenerate} of them degenerate); an object needs at least one triangle with non-zero area")]
    EmptyMesh { faces: usize, degenerate: usize },
    #[error("resolution {width}x{height} is out of range; width and height must be 1..={max}")]
    Resolution { width: u32, height: u32, max: u32 },
    #[error("fov_y = {0} degrees is outside (0, 180); use e.g. 40")]
    FieldOfView(f64),
    #[error("eye and look_at are the same point {0:?}; the view direction is undefined, move one of them")]
    EyeAtLookAt([f64; 3]),
    #[error("up {up:?} is zero or parallel to the view direction {view:?}; choose an up vector across the view, e.g. [0, 1, 0] for a horizontal view")]
    UpParallel { up: [f64; 3], view: [f64; 3] },
    #[error("{what} has a zero component {scale:?}; an instance must not be flattened, use a non-zero scale")]
    ZeroScale { what: String, scale: [f64; 3] },
    #[error("scale changes sign during the animation ({start:?} -> {end:?}) and so passes through zero; keep each component's sign")]
    ScaleCrossesZero { start: [f64; 3], end: [f64; 3] },
    #[error("light colour {0:?} has a negative component; colours are >= 0")]
    NegativeLightColor([f64; 3]),
    #[error("reflection_depth = {depth} exceeds the limit {max}; use 0..={max}")]
    ReflectionDepth { depth: u32, max: u32 },
    /// Any other out-of-range parameter: `what` says which, `expected` says the valid range.
    #[error("{what} is invalid: {expected}")]
    Invalid { what: String, expected: String },
}

/// Builds errors for one file, turning byte spans into 1-based line numbers.
pub(crate) struct ErrorContext<'a> {
    pub file: PathBuf,
    pub text: &'a str,
}

impl ErrorContext<'_> {
    pub fn line_of(&self, byte: usize) -> usize {
        let end = byte.min(self.text.len());
        self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// Error at the start of `span` (None: no line known), about `item`.
    pub fn error(
        &self,
        span: Option<std::ops::Range<usize>>,
        item: Option<String>,
        problem: Problem,
    ) -> SceneError {
        SceneError {
            file: self.file.clone(),
            line: span.map(|s| self.line_of(s.start)),
            item,
            problem,
        }
    }
}
