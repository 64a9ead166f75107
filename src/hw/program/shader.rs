//! Shader and ray generation: the pixel loop of the microprogram (`model::golden`'s `pixel`
//! and `shade`, step for step).
//!
//! State machine per thread: take a pixel (or halt when the frame is done), which also asks
//! ray generation (`hw::engine::PrimaryRays`) for its primary ray, the camera transform of
//! (x, y, 0) through the one TransformUnit (`units::primary_direction`); wait for the ray
//! (written into both coprocessors) and trace it; the direction comes back into registers
//! (`tri.dir`) where the shading or the top level needs it. On a hit: the
//! hit point, the triangle's normal (through the instance's normal matrix when there is a top
//! level) made unit and facing the ray, the ambient term, and per light (unrolled) the Lambert
//! term, after a shadow query when shadows are on. A mirror material within the reflection
//! depth saves the local colour and reflectivity in the thread's mirror chain and traces the
//! reflected ray from the hit point; at the end of the chain the colours fold back with
//! `units::mix_mirror`. The colour accumulates in the registers the pack reads; each channel's
//! byte (the `byte` instruction: `units::channel_byte`) is shifted into the word written to
//! the frame buffer at `y * W + x`. Lights' words stay in registers (up to [`KEPT_LIGHTS`]).
//!
//! Cost (instructions = engine turns): per pixel 5 for the pixel and its ray (`pixel`, the
//! wait, three `tri.dir`), 5 for its trace in one object (query, skip, walk, two waits), and
//! 4 for the pack and store; per hit about 25 (the point, the normal and its flip, the
//! material, ambient); per lit light about 22, plus 7 for its shadow ray in one object
//! (cornell at 64x48: 60.7 per primary ray; with the ShadeUnit, cornell_noshadow: 7.3).

use super::asm::{Label, Reg, Val};
use super::isa::{Op, TriFn, KD_TOP};
use super::traversal::{Query, Ray, NO_HIT};
use super::{Gen, CHAIN_ENTRY_WORDS};
use crate::layout::{FrameMap, FRAME, TRANSFORM_BANK_WORDS, TRIANGLES_A, TRIANGLES_B};
use crate::units;
use crate::units::Arith;

/// The frame word of light `light`'s first word (position x).
fn light_base(light: u32) -> u32 {
    (FrameMap::LIGHTS + light as usize * crate::layout::LIGHT_WORDS) as u32
}

/// Lights whose position and colour every thread keeps in registers (loaded once per frame);
/// a scene with more loads them at each use.
const KEPT_LIGHTS: u32 = 8;

/// Frame constants every thread loads once, at its start (the camera goes to ray
/// generation).
pub(super) struct Constants {
    eye: [Reg; 3],
    ambient: Reg,
    background: [Reg; 3],
    pub(super) shadow_t_min: Option<Reg>,
    mirror_t_min: Option<Reg>,
    /// Each light's position and colour words, when the scene has at most [`KEPT_LIGHTS`].
    lights: Option<Vec<[Reg; 6]>>,
}

impl Gen<'_> {
    /// The pixel's frame-buffer word (before the frame buffer's base): `y * W + x` with shifts
    /// and adds (W is a constant of the scene); the pixel word itself for a power-of-two W.
    fn pixel_address(&self, pixel: Reg, x: Reg, y: Reg) -> Val {
        let (a, c) = (self.asm, self.c);
        if c.width.is_power_of_two() {
            return Val::R(pixel);
        }
        let mut address = Val::R(x);
        for bit in 0..32 {
            if c.width >> bit & 1 == 1 {
                let part = if bit == 0 {
                    y.into()
                } else {
                    a.op(Op::Shl, y.into(), Val::K(bit))
                };
                address = a.op(Op::Add, address, part);
            }
        }
        address
    }

    pub(super) fn load_constants(&self) -> Constants {
        let a = self.asm;
        let c = self.c;
        a.section("init");
        let load = |addr: usize| a.keep(self.frame_word(addr as u32));
        let s = &self.s;
        // Ray generation's camera: the 3x4 and the eye, a pair of words per `tri.camera`.
        let words: Vec<Reg> = (0..15)
            .map(|k| load(FrameMap::CAMERA + k))
            .chain([Reg::ZERO])
            .collect();
        debug_assert_eq!(FrameMap::EYE, FrameMap::CAMERA + 12);
        for (pair, w) in words.chunks(2).enumerate() {
            a.tri_camera(pair as u8, w[0], w[1]);
        }
        // The eye's words stay (a secondary ray's shading starts its rays there); the
        // camera's are done with.
        let eye_words = [words[12], words[13], words[14]];
        for r in words[..12].iter().copied().filter(|r| *r != Reg::ZERO) {
            a.free(r);
        }
        // 1 / |n| of a hit's normal through an instance's normal matrix and a shadow ray's
        // t_max; the top-level walk's start; the object walks' words.
        a.keep_constant(c.format.one());
        if let Some(root) = c.top_root {
            a.keep_constant(root | KD_TOP);
        }
        for w in self.walk_words() {
            a.keep_constant(w);
        }
        // Without secondary rays every query starts at the eye: the query's origin registers
        // hold it for the whole frame. With them, a primary ray's query skips the pair no hit
        // has.
        let eye = if self.secondary_rays() {
            a.keep_constant(NO_HIT);
            eye_words
        } else {
            a.mov3(s.q_o, eye_words.map(Val::R));
            for r in eye_words {
                a.free(r);
            }
            s.q_o
        };
        // A closest hit's t_max (a shadow ray's is 1), and the skip pair's instance in a scene
        // of one object (instance 0; its triangle none until a hit).
        a.mov(s.q_t_max, Val::K(c.format.infinity(false)));
        if self.secondary_rays() && c.top_root.is_none() {
            a.mov(s.skip_instance, Val::K(0));
        }
        if self.shade_unit() {
            // The ShadeUnit reads the frame's shading constants itself.
            return Constants {
                eye,
                ambient: Reg::ZERO,
                background: [Reg::ZERO; 3],
                shadow_t_min: None,
                mirror_t_min: None,
                lights: None,
            };
        }
        Constants {
            eye,
            ambient: load(FrameMap::AMBIENT),
            background: std::array::from_fn(|k| load(FrameMap::BACKGROUND + k)),
            shadow_t_min: c.shadows.then(|| load(FrameMap::SHADOW_T_MIN)),
            mirror_t_min: (c.reflection_depth > 0).then(|| load(FrameMap::MIRROR_T_MIN)),
            lights: (c.light_count <= KEPT_LIGHTS).then(|| {
                (0..c.light_count)
                    .map(|light| std::array::from_fn(|k| load(light_base(light) as usize + k)))
                    .collect()
            }),
        }
    }

    /// One pixel after another until the frame is done. `trace`: the closest-hit trace
    /// routine of a scene with mirror rays and its primary rays' entry (none: the primary
    /// trace is written in line); `shadow`: the shadow rays' routine under a top level (none:
    /// each light's shadow trace is written in line).
    pub(super) fn pixel_loop(
        &self,
        k: &Constants,
        trace: Option<(Label, Label)>,
        shadow: Option<Label>,
    ) {
        let a = self.asm;
        let s = &self.s;
        let c = self.c;
        let f = c.format;
        let Constants {
            eye,
            ambient,
            background,
            shadow_t_min,
            mirror_t_min,
            ref lights,
        } = *k;
        // The light's word `k` (position 0-2, colour 3-5): a register or a load.
        let light_word = |light: u32, k: u32| match lights {
            Some(l) => Val::R(l[light as usize][k as usize]),
            None => self.frame_word(light_base(light) + k),
        };
        let [pixel, x, y, depth] = a.regs::<4>();
        // The ray being shaded lives in the trace query's registers (the trace routine only
        // reads them). A shadow query overwrites them: a scene with shadows and mirrors keeps
        // the direction apart for the reflection.
        let (ray_o, ray_d, ray_t_min) = (s.q_o, s.q_d, s.q_t_min);
        let secondary = self.secondary_rays();
        let color: [Reg; 3] = a.regs();

        let (next_pixel, frame_done, traced, fold, pack) =
            (a.label(), a.label(), a.label(), a.label(), a.label());
        a.bind(next_pixel);
        a.section("raygen");
        a.next_pixel(pixel, frame_done);
        // x and y only for the frame-buffer address of a width that is not a power of two
        // (else the pixel word is the pixel's index).
        if !c.width.is_power_of_two() {
            let shift = c.pixel_shift();
            a.op_to(Op::And, x, pixel.into(), Val::K((1 << shift) - 1));
            a.op_to(Op::Shr, y, pixel.into(), Val::K(shift));
        }
        // The primary ray is written into both coprocessors; its direction comes into
        // registers before the trace where the trace routine or the top level reads it, else
        // only for a hit's shading.
        a.tri_wait(Reg::ZERO);
        let direction_first = secondary || c.top_root.is_some();
        if direction_first {
            for k in 0..3 {
                a.tri_dir(k as u8, ray_d[k]);
            }
        }
        // The primary ray's query comes from constants (`Ray::Primary`). With mirrors the
        // shading of every depth finds its ray's origin in the query registers, where a mirror
        // ray's trace reads it; without, the hit point is `eye + t d`.
        let mirrors = c.reflection_depth > 0;
        let origin = if mirrors {
            a.mov3(ray_o, eye.map(Val::R));
            a.mov(depth, Val::K(0));
            ray_o
        } else {
            eye
        };
        let primary = Ray::Primary { eye };
        if self.shade_unit() {
            // The trace, then the ShadeUnit shades the pixel and writes it: the thread goes
            // on with the next.
            a.section("shader");
            self.trace_routine(false, Query::Closest, primary);
            a.section("shader");
            let address = self.pixel_address(pixel, x, y);
            a.tri_shade(address);
            a.end_temps();
            a.jump(next_pixel);
            a.bind(frame_done);
            a.section("raygen");
            a.halt();
            return;
        }

        // Trace the primary ray, in line or through the mirror rays' routine, and shade the
        // hit; a mirror ray's trace returns to `traced` too, with the ray (ray_o, ray_d,
        // ray_t_min, skip) at mirror depth `depth`.
        a.section("shader");
        match trace {
            Some((_, primary_entry)) => {
                self.trace_query(Query::Closest, primary);
                a.section("shader");
                a.call(s.link, primary_entry);
            }
            None => {
                self.trace_routine(false, Query::Closest, primary);
            }
        }
        a.bind(traced);
        a.section("shader");
        let miss = a.label();
        if self.hit_by_t() {
            a.branch(Op::BFlt, s.best_t.into(), s.q_t_max.into(), true, miss);
        } else {
            a.branch(Op::Beq, s.hit.into(), Val::K(0), false, miss);
        }
        if !direction_first {
            for k in 0..3 {
                a.tri_dir(k as u8, ray_d[k]);
            }
        }
        // The hit's instance and triangle, from the tester. With secondary rays they go where
        // the next query reads its skip pair (every ray from the hit skips it); a scene of one
        // object hits instance 0.
        let (hit_instance, hit_triangle) = if secondary {
            (s.skip_instance, s.skip_triangle)
        } else {
            (s.best_instance, s.best_triangle)
        };
        if c.top_root.is_some() {
            a.tri_read(TriFn::Instance, hit_instance);
        }
        a.tri_read(TriFn::Triangle, hit_triangle);
        let hit_instance = match c.top_root {
            Some(_) => hit_instance,
            None => Reg::ZERO,
        };
        // With shadows the hit point is the shadow queries' origin: it takes the place of the
        // ray's origin (`units::ray_point` per component, in place), and each light's vector
        // that of its direction (the incoming direction is kept apart for a mirror), so that
        // a shadow query moves no register.
        let p = if c.shadows {
            for k in 0..3 {
                let along = a.op(Op::FMul, s.best_t.into(), ray_d[k].into());
                a.op_to(Op::FAdd, ray_o[k], origin[k].into(), along);
            }
            ray_o
        } else {
            units::ray_point(a, origin.map(Val::R), ray_d.map(Val::R), s.best_t.into())
                .map(|v| a.keep(v))
        };
        a.end_temps();
        // The shading words follow the transform's in each triangle bank (`n.x n.y`,
        // `n.z material`: `Layout::triangle_shading`).
        let shading = TRANSFORM_BANK_WORDS as u32;
        let xy: [Val; 2] = a.load_n(TRIANGLES_A, hit_triangle.into(), 3, shading);
        let z_material: [Val; 2] = a.load_n(TRIANGLES_B, hit_triangle.into(), 3, shading);
        let n_obj = [xy[0], xy[1], z_material[0]];
        let material = a.keep(z_material[1]);
        // `units::world_normal`: the stored normal is unit; only an instance's normal matrix
        // changes its length. The matrix goes through the one TransformUnit (instance entry
        // reads it: `tri.normal`), the unit length through the engine's operators.
        let n = if c.top_root.is_some() {
            let n_obj = n_obj.map(|v| a.keep(v));
            a.tri_normal(hit_instance, n_obj);
            a.tri_wait(Reg::ZERO);
            for k in 0..3 {
                a.tri_dir(k as u8, n_obj[k]);
            }
            let n = units::unit_length(a, n_obj.map(Val::R)).map(|v| a.keep(v));
            for r in n_obj {
                a.free(r);
            }
            n
        } else {
            n_obj.map(|v| a.keep(v))
        };
        let along = units::dot(a, n.map(Val::R), ray_d.map(Val::R));
        let facing = a.label();
        a.branch(Op::BFlt, Val::K(0), along, true, facing);
        for k in 0..3 {
            let flipped = a.neg(n[k].into());
            a.assign(n[k], flipped);
        }
        a.bind(facing);
        a.end_temps();
        let kd: [Val; 3] = a.load_n(FRAME, material.into(), 2, c.materials);
        let kd = kd.map(|v| a.keep(v));
        // The material's fourth word, its reflectivity, only where mirror rays are traced.
        let mirror =
            mirror_t_min.map(|_| a.keep(a.load(FRAME, material.into(), 2, c.materials + 3)));
        a.free(material);
        // The colour accumulates in `color`, where the pack and the mirror fold read it.
        a.assign3(color, units::ambient(a, kd.map(Val::R), ambient.into()));
        a.end_temps();
        let incoming: [Reg; 3] = if c.shadows && c.reflection_depth > 0 {
            let kept = a.regs();
            a.mov3(kept, ray_d.map(Val::R));
            kept
        } else {
            ray_d
        };
        for light in 0..c.light_count {
            a.section("light");
            let position: [Val; 3] = std::array::from_fn(|k| light_word(light, k as u32));
            let to_light = if c.shadows {
                for k in 0..3 {
                    a.op_to(Op::FSub, s.q_d[k], position[k], p[k].into());
                }
                s.q_d
            } else {
                units::sub3(a, position, p.map(Val::R)).map(|v| a.keep(v))
            };
            a.end_temps();
            let skip_light = a.label();
            let n_dot_l = units::dot(a, n.map(Val::R), to_light.map(Val::R));
            a.branch(Op::BFlt, Val::K(0), n_dot_l, true, skip_light);
            let cos = a.keep(units::lambert_from_dot(a, n_dot_l, to_light.map(Val::R)));
            a.end_temps();
            if let Some(t_min) = shadow_t_min {
                // The shadow ray's query is in place: the hit point, the light's vector and
                // the hit as the pair to skip.
                a.section("shadow");
                debug_assert!(p == s.q_o && to_light == s.q_d);
                let one = a.kept_constant(f.one()).expect("kept at the start");
                match shadow {
                    Some(shadow) => a.call(s.link, shadow),
                    None => {
                        self.trace_routine(false, Query::Any { t_min, one }, Ray::Query);
                    }
                }
                a.section("light");
                if self.hit_by_t() {
                    a.branch(Op::BFlt, s.best_t.into(), one.into(), false, skip_light);
                } else {
                    a.branch(Op::Beq, s.hit.into(), Val::K(0), true, skip_light);
                }
            }
            let color_words: [Val; 3] = std::array::from_fn(|k| light_word(light, 3 + k as u32));
            let lit = units::add_light(
                a,
                color.map(Val::R),
                kd.map(Val::R),
                color_words,
                cos.into(),
            );
            a.assign3(color, lit);
            a.end_temps();
            a.free(cos);
            a.bind(skip_light);
            if !c.shadows {
                for r in to_light {
                    a.free(r);
                }
            }
        }
        a.section("shader");
        let local_done = a.label();
        if let Some(mirror_t_min) = mirror_t_min {
            a.section("mirror");
            a.branch(
                Op::Bltu,
                depth.into(),
                Val::K(c.reflection_depth),
                true,
                local_done,
            );
            let mirror = mirror.expect("loaded with mirror rays");
            a.branch(Op::BFlt, Val::K(0), mirror.into(), true, local_done);
            let entry = a.op(
                Op::Shl,
                depth.into(),
                Val::K(CHAIN_ENTRY_WORDS.trailing_zeros()),
            );
            for k in 0..3 {
                a.scratch_store(entry, self.scratch.chain + k as u32, color[k].into());
            }
            a.scratch_store(entry, self.scratch.chain + 3, mirror.into());
            a.op_to(Op::Add, depth, depth.into(), Val::K(1));
            let r = units::reflect(a, incoming.map(Val::R), n.map(Val::R));
            a.assign3(ray_d, r);
            if p != ray_o {
                a.mov3(ray_o, p.map(Val::R));
            }
            a.mov(ray_t_min, mirror_t_min.into());
            // The hit is the skip pair already (see `hit_instance`).
            a.end_temps();
            let (trace, _) = trace.expect("a routine with mirror rays");
            a.mov_label(s.link, traced);
            a.jump(trace);
        }
        a.bind(local_done);
        let owned = |r: &Reg| {
            *r != Reg::ZERO
                && !s.best_instance.eq(r)
                && !s.best_triangle.eq(r)
                && !s.skip_instance.eq(r)
                && !s.skip_triangle.eq(r)
                && !s.q_o.contains(r)
        };
        for r in p
            .into_iter()
            .chain(n)
            .chain(kd)
            .chain(mirror)
            .chain([hit_instance, hit_triangle])
            .chain(if incoming == ray_d {
                [Reg::ZERO; 3]
            } else {
                incoming
            })
            .filter(owned)
        {
            a.free(r);
        }
        // Fold the mirror chain back: colour = mix(local, colour, m), deepest first.
        a.bind(fold);
        if c.reflection_depth > 0 {
            a.section("mirror");
            a.branch(Op::Beq, depth.into(), Val::K(0), false, pack);
            a.op_to(Op::Sub, depth, depth.into(), Val::K(1));
            let entry = a.keep(a.op(
                Op::Shl,
                depth.into(),
                Val::K(CHAIN_ENTRY_WORDS.trailing_zeros()),
            ));
            let saved: [Reg; 4] = a.regs();
            for k in 0..4 {
                a.scratch_load_to(saved[k], entry.into(), self.scratch.chain + k as u32);
            }
            let mixed = units::mix_mirror(
                a,
                [saved[0], saved[1], saved[2]].map(Val::R),
                color.map(Val::R),
                saved[3].into(),
            );
            a.assign3(color, mixed);
            a.end_temps();
            for r in saved.into_iter().chain([entry]) {
                a.free(r);
            }
            a.jump(fold);
        }

        // Pack: each channel's byte (clamped to [0, 1], NaN to 0) shifted in, 0x00RRGGBB.
        a.bind(pack);
        a.section("pack");
        let rgb = a.reg();
        for k in 0..3 {
            let high = if k == 0 { Val::K(0) } else { Val::R(rgb) };
            a.op_to(Op::Byte, rgb, color[k].into(), high);
        }
        let address = self.pixel_address(pixel, x, y);
        a.store_frame(address, 0, c.frame_buffer, rgb);
        a.end_temps();
        a.free(rgb);
        a.jump(next_pixel);

        // A miss takes the background (out of the hit's straight path).
        a.bind(miss);
        a.section("shader");
        a.mov3(color, background.map(Val::R));
        a.jump(fold);

        a.bind(frame_done);
        a.section("raygen");
        a.halt();
    }
}
