//! Shader and ray generation: the pixel loop of the microprogram (`model::golden`'s `pixel`
//! and `shade`, step for step).
//!
//! State machine per thread: take a pixel (or halt when the frame is done); the primary ray is
//! the camera transform of (x, y, 0) (`units::primary_direction_of`); trace it. On a hit: the
//! hit point, the triangle's normal (through the instance's normal matrix when there is a top
//! level) made unit and facing the ray, the ambient term, and per light (unrolled) the Lambert
//! term, after a shadow query when shadows are on. A mirror material within the reflection
//! depth saves the local colour and reflectivity in the thread's mirror chain and traces the
//! reflected ray from the hit point; at the end of the chain the colours fold back with
//! `units::mix_mirror`. Each channel is clamped, scaled and rounded to a byte
//! (`units::channel_byte_word`), packed, and written to the frame buffer at `y * W + x`.
//!
//! Cost: about 45 instructions per pixel plus 40 per hit, 30 per light and the traces
//! (`cornell_noshadow`: 141 per primary ray, the walk included).

use super::asm::{Reg, Val};
use super::isa::Op;
use super::{Gen, CHAIN_ENTRY_WORDS};
use crate::layout::{instance_word as iw, FrameMap, FRAME, INSTANCES, TRIANGLES_T};
use crate::units;
use crate::units::Arith;

/// Frame constants every thread loads once, at its start.
#[derive(Clone, Copy)]
pub(super) struct Constants {
    camera: [Reg; 12],
    eye: [Reg; 3],
    ambient: Reg,
    background: [Reg; 3],
    shadow_t_min: Option<Reg>,
    mirror_t_min: Option<Reg>,
}

impl Gen<'_> {
    pub(super) fn load_constants(&self) -> Constants {
        let a = self.asm;
        let c = self.c;
        a.section("init");
        let load = |addr: usize| a.keep(self.frame_word(addr as u32));
        let s = &self.s;
        let camera = std::array::from_fn(|k| load(FrameMap::CAMERA + k));
        // Without secondary rays every query starts at the eye with t_min 0 and t_max
        // infinity: the query registers hold them for the whole frame.
        let eye = if self.secondary_rays() {
            std::array::from_fn(|k| load(FrameMap::EYE + k))
        } else {
            for k in 0..3 {
                a.load_to(
                    s.q_o[k],
                    crate::layout::FRAME,
                    Val::K(0),
                    0,
                    (FrameMap::EYE + k) as u32,
                );
            }
            a.mov(s.q_t_min, Val::K(0));
            s.q_o
        };
        if !c.shadows {
            a.mov(s.q_t_max, Val::K(c.format.infinity(false)));
        }
        Constants {
            camera,
            eye,
            ambient: load(FrameMap::AMBIENT),
            background: std::array::from_fn(|k| load(FrameMap::BACKGROUND + k)),
            shadow_t_min: c.shadows.then(|| load(FrameMap::SHADOW_T_MIN)),
            mirror_t_min: (c.reflection_depth > 0).then(|| load(FrameMap::MIRROR_T_MIN)),
        }
    }

    /// One pixel after another until the frame is done; `trace` is the trace routine.
    pub(super) fn pixel_loop(&self, k: &Constants, trace: super::asm::Label) {
        let a = self.asm;
        let s = &self.s;
        let c = self.c;
        let f = c.format;
        let Constants {
            camera,
            eye,
            ambient,
            background,
            shadow_t_min,
            mirror_t_min,
        } = *k;
        let [pixel, x, y, depth] = a.regs::<4>();
        // The ray being shaded lives in the trace query's registers (the trace routine only
        // reads them). A shadow query overwrites them: a scene with shadows and mirrors keeps
        // the direction apart for the reflection.
        let (ray_o, ray_d, ray_t_min) = (s.q_o, s.q_d, s.q_t_min);
        let secondary = self.secondary_rays();
        let color: [Reg; 3] = a.regs();

        let (next_pixel, frame_done, shade, fold, pack) =
            (a.label(), a.label(), a.label(), a.label(), a.label());
        a.bind(next_pixel);
        a.section("raygen");
        a.next_pixel(pixel, frame_done);
        a.op_to(Op::And, x, pixel.into(), Val::K(0xffff));
        a.op_to(Op::Shr, y, pixel.into(), Val::K(16));
        let dir = units::primary_direction_of(a, &camera.map(Val::R), x.into(), y.into());
        a.assign3(ray_d, dir);
        a.end_temps();
        if secondary {
            a.mov3(ray_o, eye.map(Val::R));
            a.mov(ray_t_min, Val::K(0));
            a.mov(s.skip_instance, Val::K(u32::MAX));
            a.mov(s.skip_triangle, Val::K(u32::MAX));
        }
        if c.reflection_depth > 0 {
            a.mov(depth, Val::K(0));
        }

        // Shade the ray (ray_o, ray_d, ray_t_min, skip) at mirror depth `depth`.
        a.bind(shade);
        a.section("shader");
        if c.shadows {
            a.mov(s.q_t_max, Val::K(f.infinity(false)));
            a.mov(s.q_any, Val::K(0));
        }
        a.call(s.link, trace);
        a.section("shader");
        let miss = a.label();
        a.branch(Op::Beq, s.hit.into(), Val::K(0), false, miss);
        // The hit outlives the next trace only in a scene with secondary rays; a scene of one
        // object hits instance 0.
        let hit_instance = match (c.top_root.is_some(), secondary) {
            (false, _) => Reg::ZERO,
            (true, true) => a.keep(s.best_instance.into()),
            (true, false) => s.best_instance,
        };
        let hit_triangle = if secondary {
            a.keep(s.best_triangle.into())
        } else {
            s.best_triangle
        };
        let p = units::ray_point(a, ray_o.map(Val::R), ray_d.map(Val::R), s.best_t.into())
            .map(|v| a.keep(v));
        a.end_temps();
        let shading: [Val; 4] = a.load_n(TRIANGLES_T, hit_triangle.into(), 3, 4);
        let n_obj = [shading[0], shading[1], shading[2]];
        let material = a.keep(shading[3]);
        let n_world = if c.top_root.is_some() {
            let record = self.instance_record(hit_instance);
            let m: [Val; 9] = a.load_n(INSTANCES, record, 0, iw::NORMAL_MATRIX as u32);
            units::transform3(a, &m, n_obj)
        } else {
            n_obj
        };
        let (unit, along) = units::unit_normal(a, n_world, ray_d.map(Val::R));
        let n = unit.map(|v| a.keep(v));
        let facing = a.label();
        a.branch(Op::BFlt, Val::K(0), along, true, facing);
        for k in 0..3 {
            let flipped = a.neg(n[k].into());
            a.assign(n[k], flipped);
        }
        a.bind(facing);
        a.end_temps();
        let mat: [Val; 4] = a.load_n(FRAME, material.into(), 2, c.materials);
        let kd = [mat[0], mat[1], mat[2]].map(|v| a.keep(v));
        let mirror = a.keep(mat[3]);
        a.free(material);
        let acc = units::ambient(a, kd.map(Val::R), ambient.into()).map(|v| a.keep(v));
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
            let base = (FrameMap::LIGHTS + light as usize * crate::layout::LIGHT_WORDS) as u32;
            let position: [Val; 3] = std::array::from_fn(|k| self.frame_word(base + k as u32));
            let to_light = units::sub3(a, position, p.map(Val::R)).map(|v| a.keep(v));
            a.end_temps();
            let skip_light = a.label();
            let n_dot_l = units::dot(a, n.map(Val::R), to_light.map(Val::R));
            a.branch(Op::BFlt, Val::K(0), n_dot_l, true, skip_light);
            let cos = a.keep(units::lambert_from_dot(a, n_dot_l, to_light.map(Val::R)));
            a.end_temps();
            if let Some(shadow_t_min) = shadow_t_min {
                a.section("shadow");
                a.mov3(s.q_o, p.map(Val::R));
                a.mov3(s.q_d, to_light.map(Val::R));
                a.mov(s.q_t_min, shadow_t_min.into());
                a.mov(s.q_t_max, Val::K(f.one()));
                a.mov(s.q_any, Val::K(1));
                a.mov(s.skip_instance, hit_instance.into());
                a.mov(s.skip_triangle, hit_triangle.into());
                a.call(s.link, trace);
                a.section("light");
                a.branch(Op::Beq, s.hit.into(), Val::K(0), true, skip_light);
            }
            let color_words: [Val; 3] =
                std::array::from_fn(|k| self.frame_word(base + 3 + k as u32));
            let lit = units::add_light(a, acc.map(Val::R), kd.map(Val::R), color_words, cos.into());
            a.assign3(acc, lit);
            a.end_temps();
            a.free(cos);
            a.bind(skip_light);
            for r in to_light {
                a.free(r);
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
            a.branch(Op::BFlt, Val::K(0), mirror.into(), true, local_done);
            let entry = a.op(
                Op::Shl,
                depth.into(),
                Val::K(CHAIN_ENTRY_WORDS.trailing_zeros()),
            );
            for k in 0..3 {
                a.scratch_store(entry, self.scratch.chain + k as u32, acc[k].into());
            }
            a.scratch_store(entry, self.scratch.chain + 3, mirror.into());
            a.op_to(Op::Add, depth, depth.into(), Val::K(1));
            let r = units::reflect(a, incoming.map(Val::R), n.map(Val::R));
            a.assign3(ray_d, r);
            a.mov3(ray_o, p.map(Val::R));
            a.mov(ray_t_min, mirror_t_min.into());
            a.mov(s.skip_instance, hit_instance.into());
            a.mov(s.skip_triangle, hit_triangle.into());
            a.end_temps();
            a.jump(shade);
        }
        a.bind(local_done);
        a.mov3(color, acc.map(Val::R));
        a.jump(fold);
        let owned = |r: &Reg| *r != Reg::ZERO && !s.best_instance.eq(r) && !s.best_triangle.eq(r);
        for r in p
            .into_iter()
            .chain(n)
            .chain(kd)
            .chain(acc)
            .chain([mirror, hit_instance, hit_triangle])
            .chain(if incoming == ray_d {
                [Reg::ZERO; 3]
            } else {
                incoming
            })
            .filter(owned)
        {
            a.free(r);
        }
        a.bind(miss);
        a.mov3(color, background.map(Val::R));

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

        // Pack: clamp each channel to [0, 1] (NaN to 0), byte, 0x00RRGGBB.
        a.bind(pack);
        a.section("pack");
        let rgb = a.reg();
        for k in 0..3 {
            let (zero, clamped) = (a.label(), a.label());
            let ch = color[k];
            a.branch(Op::BFlt, Val::K(0), ch.into(), true, zero);
            // Not NaN from here: `!(1 < ch)` is `ch <= 1`.
            a.branch(Op::BFle, ch.into(), Val::K(f.one()), false, clamped);
            a.mov(ch, Val::K(f.one()));
            a.jump(clamped);
            a.bind(zero);
            a.mov(ch, Val::K(0));
            a.bind(clamped);
            let word = units::channel_byte_word(a, ch.into());
            let byte = a.op(Op::And, word, Val::K(0xff));
            let shift = 16 - 8 * k as u32;
            if k == 0 {
                a.op_to(Op::Shl, rgb, byte, Val::K(shift));
            } else {
                let shifted = if shift == 0 {
                    byte
                } else {
                    a.op(Op::Shl, byte, Val::K(shift))
                };
                a.op_to(Op::Or, rgb, rgb.into(), shifted);
            }
            a.end_temps();
        }
        // y * W + x with shifts and adds (W is a constant of the scene).
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
        a.store_frame(address, 0, c.frame_buffer, rgb);
        a.end_temps();
        a.free(rgb);
        a.jump(next_pixel);

        a.bind(frame_done);
        a.section("raygen");
        a.halt();
    }
}
