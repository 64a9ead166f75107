//! The microprogram of the ray thread engine: ray generation, the top-level walk's leaves and
//! instance entry, the object walks and the mailboxed triangle lists it hands to the
//! coprocessors (`tri` and `kd` instructions: `hw::TriangleTester`, `hw::TraversalUnit`),
//! shading, shadow and mirror rays, and the frame-buffer write, as one program every thread
//! runs.
//!
//! The program is generated per scene from the layout's parameters, so it holds only what the
//! scene needs: no top level and no instance transform for a scene of one untransformed
//! object, no shadow rays when shadows are off, no mirror path for `reflection_depth = 0`,
//! exactly the scene's lights, and a mirror chain as long as its reflection depth. The arithmetic is
//! emitted by the shared sequences of `crate::units` (through [`asm::Asm`]'s `Arith`), so the
//! engine computes what the golden model computes, operation for operation; the control flow
//! follows `model::golden` step for step (the tests compare the two renderers on every pixel).
//!
//! [`exec`] runs a program in Rust exactly as the engine does (same round-robin thread order,
//! same pixel allocation; a coprocessor's work is done at once, so the twin never waits),
//! which predicts the engine's retired instructions and gives a trace of every register write
//! to compare an RTL trace with.

pub mod asm;
pub mod exec;
pub mod isa;
mod shader;
mod traversal;

use std::collections::BTreeSet;

use asm::{Asm, Reg};
use isa::{Instr, Unit};

use crate::fp::Format;
use crate::hw::traversal_unit::{DEFAULT_TOP_STACK_BASE, STACK_LEVELS};
use crate::layout::Layout;

/// What the generated processor is built for.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramConfig {
    pub format: Format,
    pub width: u32,
    pub height: u32,
    pub shadows: bool,
    pub reflection_depth: u32,
    pub light_count: u32,
    /// Root of the top-level tree; `None`: rays enter `object_root` directly.
    pub top_root: Option<u32>,
    pub object_root: u32,
    pub materials: u32,
    pub frame_buffer: u32,
    /// Where a top-level walk's stack starts in each thread's `STACK_LEVELS` entries of the
    /// traversal unit: the scene's deepest object tree, whose walks under the top level have
    /// the entries below it (without a top level it is never used).
    pub top_stack_base: u32,
}

/// [`ProgramConfig::top_stack_base`] of a layout: its deepest object tree's depth, between 1
/// and `STACK_LEVELS - 1` (the flow refuses a scene whose object and top-level trees do not
/// fit the stack together).
pub fn top_stack_base(info: &crate::layout::LayoutInfo) -> u32 {
    match info.top_root {
        Some(_) => info.object_depth.clamp(1, STACK_LEVELS as u32 - 1),
        None => DEFAULT_TOP_STACK_BASE,
    }
}

impl ProgramConfig {
    /// A frame of `width` x `height` with nothing else in it (one object at node 0, no
    /// shadows, mirrors or top level): what the tests of ray generation's units need.
    #[cfg(test)]
    pub(crate) fn frame_only(format: Format, width: u32, height: u32) -> Self {
        ProgramConfig {
            format,
            width,
            height,
            shadows: false,
            reflection_depth: 0,
            light_count: 1,
            top_root: None,
            object_root: 0,
            materials: 0,
            frame_buffer: 0,
            top_stack_base: DEFAULT_TOP_STACK_BASE,
        }
    }

    /// Where `pixel` puts y: above x's bits, so that with a power-of-two width the word is the
    /// pixel's index in the frame buffer (no address arithmetic); else at bit 16.
    pub fn pixel_shift(&self) -> u32 {
        if self.width.is_power_of_two() {
            self.width.trailing_zeros()
        } else {
            16
        }
    }

    pub fn from_layout(layout: &Layout) -> Self {
        let (format, info) = (layout.format, &layout.info);
        ProgramConfig {
            format,
            width: info.width,
            height: info.height,
            shadows: info.shadows,
            reflection_depth: info.reflection_depth,
            light_count: info.light_count,
            top_root: info.top_root,
            object_root: info.object_root,
            materials: info.materials,
            frame_buffer: info.frame_buffer,
            top_stack_base: top_stack_base(info),
        }
    }
}

/// Words of a thread's scratch memory: the mirror chain (kd trees are walked by the traversal
/// unit, which keeps its own rays and stacks).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScratchMap {
    /// Per mirror bounce: the local colour (3 words) and the mirror reflectivity.
    pub chain: u32,
    /// Total words, a power of two.
    pub words: u32,
}

pub const CHAIN_ENTRY_WORDS: u32 = 4;

impl ScratchMap {
    pub fn for_config(c: &ProgramConfig) -> Self {
        let chain = 0;
        let used = chain + CHAIN_ENTRY_WORDS * c.reflection_depth;
        ScratchMap {
            chain,
            words: used.next_power_of_two().max(16),
        }
    }
}

/// A generated program.
#[derive(Clone, Debug)]
pub struct Program {
    pub config: ProgramConfig,
    pub code: Vec<Instr>,
    /// The routine of each instruction (traces name where a value came from).
    pub sections: Vec<&'static str>,
    pub scratch: ScratchMap,
    /// Registers the program uses (the engine's register file holds `isa::REGISTERS`).
    pub registers_used: usize,
    /// What this scene does not need, in words (printed by `dynrt rtl`).
    pub left_out: Vec<String>,
}

impl Program {
    /// The units some instruction uses; the engine is built with these only.
    pub fn units(&self) -> BTreeSet<Unit> {
        self.code.iter().map(isa::Instr::unit).collect()
    }
    /// The instruction ROM: each instruction's words ([`isa::Instr::encode`]).
    pub fn rom(&self) -> Vec<[u32; isa::ROM_WORDS]> {
        self.code.iter().map(isa::Instr::encode).collect()
    }
    /// The assembly listing, one instruction a line with its address, ROM words (control,
    /// immediate, auxiliary) and routine.
    pub fn listing(&self) -> String {
        self.rom()
            .iter()
            .zip(&self.code)
            .zip(&self.sections)
            .enumerate()
            .map(|(pc, ((w, i), s))| {
                format!(
                    "{pc:4}  {:08x} {:08x} {:05x}  {s:<12} {i}\n",
                    w[0], w[1], w[2]
                )
            })
            .collect()
    }
}

/// Registers every routine shares.
pub(crate) struct Shared {
    /// The trace query: origin, direction, t range (a closest hit's), the (instance,
    /// triangle) to skip.
    pub q_o: [Reg; 3],
    pub q_d: [Reg; 3],
    pub q_t_min: Reg,
    pub q_t_max: Reg,
    pub skip_instance: Reg,
    pub skip_triangle: Reg,
    /// The closest hit so far (`hit` is 0 or 1; `best_t` starts at `q_t_max`).
    pub hit: Reg,
    pub best_t: Reg,
    pub best_instance: Reg,
    pub best_triangle: Reg,
    /// Return address of the trace routine.
    pub link: Reg,
}

pub(crate) struct Gen<'a> {
    pub asm: &'a Asm,
    pub c: &'a ProgramConfig,
    pub scratch: ScratchMap,
    pub s: Shared,
}

/// Generates the program for `config`.
pub fn build_program(config: &ProgramConfig) -> Program {
    let asm = Asm::new(config.format);
    let a = &asm;
    let s = Shared {
        q_o: a.regs(),
        q_d: a.regs(),
        q_t_min: a.reg(),
        q_t_max: a.reg(),
        skip_instance: a.reg(),
        skip_triangle: a.reg(),
        hit: a.reg(),
        best_t: a.reg(),
        best_instance: a.reg(),
        best_triangle: a.reg(),
        link: a.reg(),
    };
    let gen = Gen {
        asm: a,
        c: config,
        scratch: ScratchMap::for_config(config),
        s,
    };
    let constants = gen.load_constants();
    // A mirror ray's trace is a routine, whose registers are its own (the shader's values
    // live across its calls), which the primary ray enters after its query; a shadow ray's
    // under a top level is another (its instance loop is long). Other traces are written in
    // line: the primary ray's without mirrors, and each light's shadow ray in one object.
    let routine = |query| {
        let (trace, after) = (a.label(), a.label());
        a.jump(after);
        a.bind(trace);
        let start = a.len();
        let primary_entry = gen.trace_routine(true, query, traversal::Ray::Query);
        a.reserve_registers_of(start);
        a.bind(after);
        (trace, primary_entry)
    };
    let trace = (config.reflection_depth > 0).then(|| routine(traversal::Query::Closest));
    let shadow = match (constants.shadow_t_min, config.top_root) {
        (Some(t_min), Some(_)) => Some(
            routine(traversal::Query::Any {
                t_min,
                one: a
                    .kept_constant(config.format.one())
                    .expect("kept at the program's start"),
            })
            .0,
        ),
        _ => None,
    };
    gen.pixel_loop(&constants, trace, shadow);
    let scratch = gen.scratch;
    let mut left_out = Vec::new();
    if config.top_root.is_none() {
        left_out.push(
            "top-level traversal, instance mailbox and instance transforms (one untransformed object)"
                .to_string(),
        );
    }
    if !config.shadows {
        left_out.push("shadow rays (shadows off or no lights)".to_string());
    }
    if config.reflection_depth == 0 {
        left_out.push("mirror rays and the mirror chain (reflection_depth = 0)".to_string());
    }
    let assembled = asm.finish();
    // Registers are handed out lowest first, so the highest one named bounds the use.
    let registers_used = assembled
        .code
        .iter()
        .flat_map(|i| [i.dst, i.a, if i.b_imm { 0 } else { i.b }])
        .max()
        .map_or(1, |r| r as usize + 1);
    let program = Program {
        config: config.clone(),
        code: assembled.code,
        sections: assembled.sections,
        scratch,
        registers_used,
        left_out,
    };
    let units = program.units();
    let mut left_out = program.left_out.clone();
    for u in Unit::ALL {
        if !units.contains(&u) {
            left_out.push(format!("{} unit (no instruction uses it)", u.name()));
        }
    }
    Program {
        left_out,
        ..program
    }
}

impl Gen<'_> {
    /// Whether the scene traces rays other than the primary ones (shadow or mirror rays).
    pub fn secondary_rays(&self) -> bool {
        self.c.shadows || self.c.reflection_depth > 0
    }

    /// Whether the shading goes to the `hw::ShadeUnit` (`tri.shade`): primary rays alone, of
    /// one untransformed object, with at most its [`MAX_SHADE_LIGHTS`] lights.
    ///
    /// [`MAX_SHADE_LIGHTS`]: crate::hw::shade_unit::MAX_SHADE_LIGHTS
    pub fn shade_unit(&self) -> bool {
        !self.secondary_rays()
            && self.c.top_root.is_none()
            && self.c.light_count as usize <= crate::hw::shade_unit::MAX_SHADE_LIGHTS
    }

    /// Whether the shader tells a hit by `best_t < q_t_max` instead of the tester's hit flag
    /// (the same: a hit only ever lowers the best t from t_max): for the one primary trace of
    /// a scene of one object (which saves reading the flag), and under a top level (whose
    /// trace may enter no instance, so no walk may write the flag, and ends with the best t).
    pub fn hit_by_t(&self) -> bool {
        !self.secondary_rays() || self.c.top_root.is_some()
    }

    /// A frame word (bank 5) at a fixed address.
    pub fn frame_word(&self, addr: u32) -> asm::Val {
        self.asm.load(crate::layout::FRAME, asm::Val::K(0), 0, addr)
    }
}
