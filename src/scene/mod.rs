//! Dynamic scenes: load a scene TOML (docs/ARCHITECTURE.md, "Scene files"), build its objects from OBJ/MTL files
//! or procedural generators, place instances (static or animated), validate everything, and hand
//! the result on as plain f64 data (`Scene`) for the acceleration structures, the layout and the
//! renderers.
//!
//! # Scene file
//! The schema of docs/ARCHITECTURE.md, "Scene files"; every table rejects unknown keys. Defaults: `up = [0,1,0]`;
//! `[render]` may be omitted (`shadows = true`, `reflection_depth = 0`, `ambient = 0.1`,
//! `background = [0,0,0]`); a light's `color` defaults to white. Extensions:
//! - `[[objects]]` take exactly one of `mesh = "file.obj"` (relative to the scene file) or
//!   `generate = { kind = ..., ... }` (kinds and parameters: `generate.rs`), plus optional
//!   `color = [r, g, b]` and `mirror = 0..1`.
//! - `[[instances]]` take an optional `name` (default `"<object>#<k>"`, k = instance index).
//!   `[instances.animate]` has `frames` (>= 2) and end values for any of translate / rotate /
//!   scale (missing ones keep the instance's value); see `transform.rs` for the interpolation.
//! - `[[fields]]` generate grids of instances (`field.rs`); their instances follow the explicit
//!   `[[instances]]`, fields in file order.
//! - With neither `[[instances]]` nor `[[fields]]`, each object is placed once, untransformed,
//!   as an instance named after the object.
//!
//! # Materials
//! Each triangle has a `Material { diffuse, mirror }`.
//! - OBJ meshes: from the MTL (`Kd`; mirror = mean of `Ks` when `illum 3`), see `mesh.rs`.
//! - Generated meshes: one material, `Material::DEFAULT` (0.8 grey, no mirror) unless the object
//!   table sets `color` and/or `mirror`; the Cornell box has its own wall colours and refuses
//!   `color`/`mirror` (use its `mirror_tall_block`).
//! - `color`/`mirror` on a mesh object replace all its MTL materials by one material
//!   (defaults for whichever of the two is not given: 0.8 grey, 0) — handy for MTL-less meshes.
//!
//! # Validation and limits
//! Errors (`SceneError`) name the file, line, object/instance and problem: TOML syntax and
//! schema errors, unknown or duplicate object names, missing/unreadable/broken OBJ or MTL,
//! non-finite numbers anywhere (vertices, camera, lights, transforms, colours), empty meshes (no
//! triangle left after dropping degenerates), width/height outside 1..=`MAX_RESOLUTION` (4096,
//! a frame buffer beyond the paper's 1024x768 is no use here and bigger ones are almost surely
//! typos), fov_y outside (0, 180), eye == look_at, up zero or parallel to the view direction,
//! a zero scale component (also at an animation's end, or a sign change during it), negative
//! light colours or material colours, mirror outside [0, 1], ambient or background negative,
//! reflection_depth above `MAX_REFLECTION_DEPTH` (8), animation frames < 2 or above
//! `MAX_FRAMES`, generator parameters out of range.
//! Degenerate triangles are dropped with a counted warning in `Scene::warnings` (rule in
//! `mesh.rs`). Objects no instance uses and scenes without lights also produce warnings.
//!
//! # Frames
//! `Scene::frames` = the largest `animate.frames` of any instance, 1 when nothing moves.
//! `Instance::object_to_world(frame)` gives the matrix at any frame.

mod camera;
pub mod error;
mod field;
pub(crate) mod generate;
mod mesh;
mod noise;
pub mod paper;
mod schema;
mod transform;

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::DVec3;
use toml::Spanned;

pub use camera::{Camera, CameraBasis};
pub use error::{Problem, SceneError};
pub use field::max_scene_instances;
pub use mesh::{is_degenerate, max_scene_triangles, Material, Object, DEGENERATE_RELATIVE_EPSILON};
pub use transform::{Animation, Instance, Transform};

use error::ErrorContext;
use schema::SceneFile;

/// Largest accepted width and height.
pub const MAX_RESOLUTION: u32 = 4096;
/// Largest accepted `reflection_depth`.
pub const MAX_REFLECTION_DEPTH: u32 = 8;
/// Largest accepted `animate.frames`.
pub const MAX_FRAMES: u32 = 100_000;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    pub shadows: bool,
    pub reflection_depth: u32,
    pub ambient: f64,
    pub background: [f64; 3],
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    pub position: DVec3,
    pub color: [f64; 3],
}

/// A loaded, validated scene (see the module doc for every guarantee).
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub source: PathBuf,
    pub camera: Camera,
    pub render: RenderSettings,
    pub lights: Vec<Light>,
    pub objects: Vec<Object>,
    pub instances: Vec<Instance>,
    pub frames: u32,
    pub warnings: Vec<String>,
}

impl Scene {
    /// Loads a scene file; meshes are found relative to its directory. A bundled scene
    /// (`bundled:/cornell.toml`, see [`crate::bundled`]) finds the bundled meshes.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = crate::input::read_text(path, "scene file", crate::input::MAX_SCENE_BYTES)
            .map_err(|e| SceneError {
                file: path.to_path_buf(),
                line: None,
                item: None,
                problem: Problem::Input(e),
            })?;
        let text = crate::input::normalize_line_endings(&text);
        // `bundled:tiny.toml` has the bundled folder as its parent once canonical.
        let path = &crate::bundled::canonical(path);
        let base = path.parent().unwrap_or(Path::new(""));
        Scene::from_toml_str(&text, base, path)
    }

    /// Parses scene TOML `text`; mesh paths are relative to `base_dir`; `source` names the text
    /// in errors and becomes `Scene::source`.
    pub fn from_toml_str(
        text: &str,
        base_dir: &Path,
        source: impl Into<PathBuf>,
    ) -> Result<Scene, SceneError> {
        let ctx = ErrorContext {
            file: source.into(),
            text,
        };
        let file: SceneFile = toml::from_str(text)
            .map_err(|e| ctx.error(e.span(), None, Problem::Toml(e.message().to_string())))?;
        Builder {
            ctx: &ctx,
            base_dir,
            warnings: Vec::new(),
        }
        .build(file)
    }

    /// One object, one instance, identity at every frame: the scene is a plain static mesh.
    pub fn is_single_untransformed_object(&self) -> bool {
        self.objects.len() == 1
            && self.instances.len() == 1
            && self.instances[0].is_static_identity()
    }

    /// Triangles stored once per object.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.triangles.len()).sum()
    }

    /// Triangles as seen in the world (each instance counts its object's triangles).
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.objects[i.object].triangles.len())
            .sum()
    }

    /// Replaces the camera resolution (e.g. from the CLI), with the same limits as the file.
    pub fn set_resolution(&mut self, width: u32, height: u32) -> Result<(), SceneError> {
        if !resolution_ok(width, height) {
            return Err(SceneError {
                file: self.source.clone(),
                line: None,
                item: Some("resolution override".into()),
                problem: Problem::Resolution {
                    width,
                    height,
                    max: MAX_RESOLUTION,
                },
            });
        }
        self.camera.width = width;
        self.camera.height = height;
        Ok(())
    }

    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }

    /// World-space bounds (min, max) of instance `i` at `frame`: the object's bounding box
    /// corners transformed (a conservative box, what a top-level kd-tree needs).
    pub fn instance_world_bounds(&self, i: usize, frame: u32) -> (DVec3, DVec3) {
        let inst = &self.instances[i];
        let (lo, hi) = self.objects[inst.object].bounds();
        let m = inst.object_to_world(frame);
        let mut wlo = DVec3::splat(f64::INFINITY);
        let mut whi = DVec3::splat(f64::NEG_INFINITY);
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let p = m.transform_point3(corner);
            wlo = wlo.min(p);
            whi = whi.max(p);
        }
        (wlo, whi)
    }

    /// The static scene of one frame: every instance frozen at its transform of `frame`,
    /// `frames` = 1. Rendering frame k of `self` must equal rendering `self.at_frame(k)`.
    pub fn at_frame(&self, frame: u32) -> Scene {
        let mut s = self.clone();
        for inst in &mut s.instances {
            inst.transform = inst.transform_at(frame);
            inst.animation = None;
        }
        s.frames = 1;
        s
    }
}

fn resolution_ok(width: u32, height: u32) -> bool {
    (1..=MAX_RESOLUTION).contains(&width) && (1..=MAX_RESOLUTION).contains(&height)
}

struct Builder<'a> {
    ctx: &'a ErrorContext<'a>,
    base_dir: &'a Path,
    warnings: Vec<String>,
}

type Res<T> = Result<T, SceneError>;

impl Builder<'_> {
    fn err(&self, span: Range<usize>, item: &str, problem: Problem) -> SceneError {
        let item = (!item.is_empty()).then(|| item.to_string());
        self.ctx.error(Some(span), item, problem)
    }

    fn invalid(&self, span: Range<usize>, item: &str, what: &str, expected: &str) -> SceneError {
        self.err(
            span,
            item,
            Problem::Invalid {
                what: what.to_string(),
                expected: expected.to_string(),
            },
        )
    }

    fn finite(&self, v: &Spanned<f64>, item: &str, what: &str) -> Res<f64> {
        if v.get_ref().is_finite() {
            Ok(*v.get_ref())
        } else {
            Err(self.err(
                v.span(),
                item,
                Problem::NonFinite {
                    what: format!("{what} = {}", v.get_ref()),
                },
            ))
        }
    }

    fn finite3(&self, v: &Spanned<[f64; 3]>, item: &str, what: &str) -> Res<DVec3> {
        if v.get_ref().iter().all(|c| c.is_finite()) {
            Ok(DVec3::from(*v.get_ref()))
        } else {
            Err(self.err(
                v.span(),
                item,
                Problem::NonFinite {
                    what: format!("{what} = {:?}", v.get_ref()),
                },
            ))
        }
    }

    fn colour(&self, v: &Spanned<[f64; 3]>, item: &str, what: &str) -> Res<[f64; 3]> {
        let c = self.finite3(v, item, what)?;
        if c.min_element() < 0.0 {
            return Err(self.invalid(v.span(), item, what, "colour components must be >= 0"));
        }
        Ok(c.to_array())
    }

    fn build(mut self, file: SceneFile) -> Res<Scene> {
        let camera = self.camera(&file)?;
        let render = self.render(&file)?;
        let lights = self.lights(&file)?;
        let objects = self.objects(&file)?;
        if objects.is_empty() {
            return Err(self.ctx.error(None, None, Problem::NoObjects));
        }
        let names: HashMap<&str, usize> = objects
            .iter()
            .enumerate()
            .map(|(i, o)| (o.name.as_str(), i))
            .collect();
        let known = || {
            let mut v: Vec<&str> = objects.iter().map(|o| o.name.as_str()).collect();
            if v.len() > 12 {
                v.truncate(12);
                v.push("...");
            }
            if v.is_empty() {
                "none".to_string()
            } else {
                v.join(", ")
            }
        };
        let resolve = |name: &Spanned<String>, item: &str| -> Res<usize> {
            names.get(name.get_ref().as_str()).copied().ok_or_else(|| {
                self.err(
                    name.span(),
                    item,
                    Problem::UnknownObject {
                        name: name.get_ref().clone(),
                        known: known(),
                    },
                )
            })
        };

        let max_instances = max_scene_instances();
        let too_many_instances = |span: Range<usize>, item: &str, count: u64| {
            self.invalid(
                span,
                item,
                "the number of instances",
                &format!(
                    "the scene would place {count} instances, the processor's instance bank holds {max_instances} (docs/ARCHITECTURE.md, \"Memory map\"); use fewer [[instances]] or smaller [[fields]]"
                ),
            )
        };
        if file.instances.len() as u64 > max_instances {
            let last = &file.instances[max_instances as usize];
            return Err(too_many_instances(
                last.span(),
                "[[instances]]",
                file.instances.len() as u64,
            ));
        }
        let mut instances = Vec::new();
        for (k, inst) in file.instances.iter().enumerate() {
            let def = inst.get_ref();
            let name = def
                .name
                .clone()
                .unwrap_or_else(|| format!("{}#{k}", def.object.get_ref()));
            let item = format!("instance '{name}'");
            let object = resolve(&def.object, &item)?;
            instances.push(self.instance(def, object, name, &item)?);
        }
        for (k, f) in file.fields.iter().enumerate() {
            let spec = self.field(f, k, &resolve)?;
            let count = instances.len() as u64 + u64::from(spec.count_x) * u64::from(spec.count_z);
            if count > max_instances {
                return Err(too_many_instances(
                    f.span(),
                    &format!("field '{}'", spec.name),
                    count,
                ));
            }
            instances.extend(field::expand(&spec));
        }
        if file.instances.is_empty() && file.fields.is_empty() {
            instances = objects
                .iter()
                .enumerate()
                .map(|(i, o)| Instance {
                    object: i,
                    name: o.name.clone(),
                    transform: Transform::IDENTITY,
                    animation: None,
                })
                .collect();
        }
        if instances.is_empty() {
            return Err(self.ctx.error(
                None,
                None,
                Problem::Invalid {
                    what: "the scene's instances".into(),
                    expected: "at least one instance; the [[fields]] place none (check their counts) and there are no [[instances]]".into(),
                },
            ));
        }
        let mut used = vec![false; objects.len()];
        for i in &instances {
            used[i.object] = true;
        }
        for (o, u) in objects.iter().zip(used) {
            if !u {
                self.warnings.push(format!(
                    "object '{}' is defined but never instanced",
                    o.name
                ));
            }
        }
        if lights.is_empty() {
            self.warnings
                .push("no [[lights]]: surfaces get only the ambient term".into());
        }
        let frames = instances
            .iter()
            .filter_map(|i| i.animation.map(|a| a.frames))
            .max()
            .unwrap_or(1);
        Ok(Scene {
            source: self.ctx.file.clone(),
            camera,
            render,
            lights,
            objects,
            instances,
            frames,
            warnings: self.warnings,
        })
    }

    fn camera(&self, file: &SceneFile) -> Res<Camera> {
        let c = file.camera.get_ref();
        let item = "camera";
        let eye = self.finite3(&c.eye, item, "eye")?;
        let look_at = self.finite3(&c.look_at, item, "look_at")?;
        let up = self.finite3(&c.up, item, "up")?;
        let fov = self.finite(&c.fov_y, item, "fov_y")?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(c.fov_y.span(), item, Problem::FieldOfView(fov)));
        }
        let (w, h) = (*c.width.get_ref(), *c.height.get_ref());
        if !resolution_ok(w, h) {
            let span = if (1..=MAX_RESOLUTION).contains(&w) {
                c.height.span()
            } else {
                c.width.span()
            };
            return Err(self.err(
                span,
                item,
                Problem::Resolution {
                    width: w,
                    height: h,
                    max: MAX_RESOLUTION,
                },
            ));
        }
        let view = look_at - eye;
        if view == DVec3::ZERO {
            return Err(self.err(c.look_at.span(), item, Problem::EyeAtLookAt(eye.to_array())));
        }
        // Coordinates near f64's limit make |view| overflow, and a NaN direction would pass
        // for "up parallel to the view" below.
        if !view.length().is_finite() || !up.length().is_finite() {
            return Err(self.err(
                c.look_at.span(),
                item,
                Problem::Invalid {
                    what: format!("the distance from eye {:?} to look_at {:?} (or up's length)", eye.to_array(), look_at.to_array()),
                    expected: "it overflows f64; use coordinates below about 1e150 (no number format of the hardware holds more than about 3e38)".into(),
                },
            ));
        }
        // Parallel when the sine of the angle between them is below 1e-9 (also catches up = 0).
        let f = view.normalize();
        let cross = f.cross(up);
        let across = cross.length() > 1e-9 * up.length();
        if !across || up == DVec3::ZERO {
            return Err(self.err(
                c.up.span(),
                item,
                Problem::UpParallel {
                    up: up.to_array(),
                    view: view.to_array(),
                },
            ));
        }
        Ok(Camera {
            eye,
            look_at,
            up,
            fov_y_deg: fov,
            width: w,
            height: h,
        })
    }

    fn render(&self, file: &SceneFile) -> Res<RenderSettings> {
        let Some(r) = &file.render else {
            return Ok(RenderSettings {
                shadows: true,
                reflection_depth: 0,
                ambient: 0.1,
                background: [0.0; 3],
            });
        };
        let r = r.get_ref();
        let item = "render";
        let depth = *r.reflection_depth.get_ref();
        if depth > MAX_REFLECTION_DEPTH {
            return Err(self.err(
                r.reflection_depth.span(),
                item,
                Problem::ReflectionDepth {
                    depth,
                    max: MAX_REFLECTION_DEPTH,
                },
            ));
        }
        let ambient = self.finite(&r.ambient, item, "ambient")?;
        if ambient < 0.0 {
            return Err(self.invalid(r.ambient.span(), item, "ambient", "a value >= 0"));
        }
        let background = self.colour(&r.background, item, "background")?;
        Ok(RenderSettings {
            shadows: r.shadows,
            reflection_depth: depth,
            ambient,
            background,
        })
    }

    fn lights(&self, file: &SceneFile) -> Res<Vec<Light>> {
        let mut out = Vec::new();
        for (k, l) in file.lights.iter().enumerate() {
            let item = format!("light {k}");
            let l = l.get_ref();
            let position = self.finite3(&l.position, &item, "position")?;
            let c = self.finite3(&l.color, &item, "color")?;
            if c.min_element() < 0.0 {
                return Err(self.err(
                    l.color.span(),
                    &item,
                    Problem::NegativeLightColor(c.to_array()),
                ));
            }
            out.push(Light {
                position,
                color: c.to_array(),
            });
        }
        Ok(out)
    }

    fn objects(&mut self, file: &SceneFile) -> Res<Vec<Object>> {
        let mut objects = Vec::new();
        // Triangles the memory has left for the objects still to load (counted before they are
        // read or generated, see `max_scene_triangles`).
        let mut budget = max_scene_triangles();
        let mut first_line: HashMap<String, usize> = HashMap::new();
        for o in &file.objects {
            let def = o.get_ref();
            let name = def.name.get_ref().clone();
            let item = format!("object '{name}'");
            let line = self.ctx.line_of(def.name.span().start);
            if let Some(&first) = first_line.get(&name) {
                return Err(self.err(
                    def.name.span(),
                    &item,
                    Problem::DuplicateObject {
                        name,
                        first_line: first,
                    },
                ));
            }
            first_line.insert(name.clone(), line);

            let colour = match &def.color {
                Some(c) => Some(self.colour(c, &item, "color")?),
                None => None,
            };
            let mirror = match &def.mirror {
                Some(m) => {
                    let v = self.finite(m, &item, "mirror")?;
                    if !(0.0..=1.0).contains(&v) {
                        return Err(self.invalid(
                            m.span(),
                            &item,
                            "mirror",
                            "a reflectivity in [0, 1]",
                        ));
                    }
                    Some(v)
                }
                None => None,
            };
            let override_material = (colour.is_some() || mirror.is_some()).then(|| Material {
                diffuse: colour.unwrap_or(Material::DEFAULT.diffuse),
                mirror: mirror.unwrap_or(0.0),
            });

            let (raw, file_for_errors) = match (&def.mesh, &def.generate) {
                (Some(mesh), None) => {
                    let path = self.base_dir.join(mesh.get_ref());
                    let (mut raw, warnings) =
                        mesh::load_obj(&path, &item, budget).map_err(|mut e| {
                            // A missing mesh is the scene's fault: point at the `mesh =` line.
                            if matches!(e.problem, Problem::Input(_)) && e.file == path {
                                e.file = self.ctx.file.clone();
                                e.line = Some(self.ctx.line_of(mesh.span().start));
                            }
                            e
                        })?;
                    self.warnings.extend(warnings);
                    if let Some(m) = override_material {
                        raw.materials = vec![m];
                        raw.triangle_material.iter_mut().for_each(|i| *i = 0);
                    }
                    (raw, path)
                }
                (None, Some(gen)) => {
                    let g = gen.get_ref();
                    if generate::has_own_materials(g) && override_material.is_some() {
                        return Err(self.invalid(
                            o.span(),
                            &item,
                            "color/mirror",
                            "not accepted for cornell_box (it has its own colours); use mirror_tall_block",
                        ));
                    }
                    let raw = generate::generate(
                        g,
                        override_material.unwrap_or(Material::DEFAULT),
                        budget,
                    )
                    .map_err(|(what, expected)| {
                        self.invalid(gen.span(), &item, &what, &expected)
                    })?;
                    (raw, self.ctx.file.clone())
                }
                _ => return Err(self.err(o.span(), &item, Problem::ObjectSource)),
            };
            let total = raw.triangles.len();
            budget = budget.saturating_sub(total as u64);
            match mesh::finish_object(&name, raw) {
                Ok((object, dropped)) => {
                    if dropped > 0 {
                        self.warnings.push(format!(
                            "object '{name}': dropped {dropped} degenerate triangle(s) of {total}; triangle indices count only the remaining {}",
                            object.triangles.len()
                        ));
                    }
                    objects.push(object);
                }
                Err((faces, degenerate)) => {
                    return Err(SceneError {
                        file: file_for_errors,
                        line: None,
                        item: Some(item),
                        problem: Problem::EmptyMesh { faces, degenerate },
                    })
                }
            }
        }
        Ok(objects)
    }

    fn scale(&self, v: &Spanned<[f64; 3]>, item: &str, what: &str) -> Res<DVec3> {
        let s = self.finite3(v, item, what)?;
        if s.x == 0.0 || s.y == 0.0 || s.z == 0.0 {
            return Err(self.err(
                v.span(),
                item,
                Problem::ZeroScale {
                    what: what.to_string(),
                    scale: s.to_array(),
                },
            ));
        }
        Ok(s)
    }

    fn frames(&self, v: &Spanned<u32>, item: &str) -> Res<u32> {
        let f = *v.get_ref();
        if !(2..=MAX_FRAMES).contains(&f) {
            return Err(self.invalid(
                v.span(),
                item,
                "animate.frames",
                &format!("2..={MAX_FRAMES} (frame 0 holds the start values, frame frames-1 the end values)"),
            ));
        }
        Ok(f)
    }

    fn instance(
        &self,
        def: &schema::InstanceDef,
        object: usize,
        name: String,
        item: &str,
    ) -> Res<Instance> {
        let opt3 = |v: &Option<Spanned<[f64; 3]>>, what: &str, default: DVec3| -> Res<DVec3> {
            v.as_ref()
                .map_or(Ok(default), |v| self.finite3(v, item, what))
        };
        let translate = opt3(&def.translate, "translate", DVec3::ZERO)?;
        let rotate_deg = opt3(&def.rotate, "rotate", DVec3::ZERO)?;
        let scale = match &def.scale {
            Some(s) => self.scale(s, item, "scale")?,
            None => DVec3::ONE,
        };
        let transform = Transform {
            translate,
            rotate_deg,
            scale,
        };
        let animation = match &def.animate {
            None => None,
            Some(a) => {
                let span = a.span();
                let a = a.get_ref();
                let frames = self.frames(&a.frames, item)?;
                let end = Transform {
                    translate: opt3(&a.translate, "animate.translate", translate)?,
                    rotate_deg: opt3(&a.rotate, "animate.rotate", rotate_deg)?,
                    scale: match &a.scale {
                        Some(s) => self.scale(s, item, "animate.scale")?,
                        None => scale,
                    },
                };
                if (end.scale * scale).min_element() < 0.0 {
                    return Err(self.err(
                        a.scale.as_ref().map_or(span, |s| s.span()),
                        item,
                        Problem::ScaleCrossesZero {
                            start: scale.to_array(),
                            end: end.scale.to_array(),
                        },
                    ));
                }
                Some(Animation { frames, end })
            }
        };
        Ok(Instance {
            object,
            name,
            transform,
            animation,
        })
    }

    fn field(
        &self,
        f: &Spanned<schema::FieldDef>,
        k: usize,
        resolve: &dyn Fn(&Spanned<String>, &str) -> Res<usize>,
    ) -> Res<field::FieldSpec> {
        let span = f.span();
        let f = f.get_ref();
        let name = f.name.clone().unwrap_or_else(|| format!("field{k}"));
        let item = format!("field '{name}'");
        let item = item.as_str();
        let objects = match (&f.object, &f.objects) {
            (Some(o), None) => vec![resolve(o, item)?],
            (None, Some(list)) if !list.get_ref().is_empty() => list
                .get_ref()
                .iter()
                .map(|n| resolve(&Spanned::new(list.span(), n.clone()), item))
                .collect::<Res<Vec<_>>>()?,
            _ => {
                return Err(self.invalid(
                    span,
                    item,
                    "object/objects",
                    "give exactly one of `object = \"name\"` or a non-empty `objects = [...]`",
                ))
            }
        };
        let (cx, cz) = (*f.count_x.get_ref(), *f.count_z.get_ref());
        let max = max_scene_instances();
        if cx == 0 || cz == 0 || u64::from(cx) * u64::from(cz) > max {
            return Err(self.invalid(
                f.count_x.span(),
                item,
                "count_x * count_z",
                &format!("both >= 1 and at most {max} instances (what the processor's instance bank holds)"),
            ));
        }
        let spacing = self.finite(&f.spacing, item, "spacing")?;
        if spacing <= 0.0 {
            return Err(self.invalid(f.spacing.span(), item, "spacing", "a distance > 0"));
        }
        let jitter = match &f.jitter {
            Some(j) => {
                let v = self.finite(j, item, "jitter")?;
                if !(0.0..1.0).contains(&v) {
                    return Err(self.invalid(
                        j.span(),
                        item,
                        "jitter",
                        "a fraction of the spacing in [0, 1)",
                    ));
                }
                v
            }
            None => 0.0,
        };
        let opt3 = |v: &Option<Spanned<[f64; 3]>>, what: &str, default: DVec3| -> Res<DVec3> {
            v.as_ref()
                .map_or(Ok(default), |v| self.finite3(v, item, what))
        };
        let origin = opt3(&f.origin, "origin", DVec3::ZERO)?;
        let rotate_deg = opt3(&f.rotate, "rotate", DVec3::ZERO)?;
        let scale = match &f.scale {
            Some(s) => self.scale(s, item, "scale")?,
            None => DVec3::ONE,
        };
        let animate = match &f.animate {
            None => None,
            Some(a) => {
                let a = a.get_ref();
                Some((
                    self.frames(&a.frames, item)?,
                    opt3(&a.translate_by, "animate.translate_by", DVec3::ZERO)?,
                    opt3(&a.rotate_by, "animate.rotate_by", DVec3::ZERO)?,
                ))
            }
        };
        Ok(field::FieldSpec {
            name,
            objects,
            count_x: cx,
            count_z: cz,
            spacing,
            origin,
            jitter,
            seed: f.seed,
            rotate_deg,
            random_yaw: f.random_yaw,
            scale,
            animate,
        })
    }
}

/// The public test meshes kept beside the repository (`../shared/scenes/meshes`, see its
/// SOURCES.md): data for tests and benchmarks, which the repository itself must not copy.
pub fn shared_mesh_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes/meshes")
}

#[cfg(test)]
mod tests;
