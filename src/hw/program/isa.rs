//! The instruction set of the ray thread engine: what one thread asks of one unit per step.
//!
//! Every instruction reads at most two registers (`a`, and `b` or the immediate), writes at
//! most one (`dst`, never `r0`, which always reads 0) and chooses the thread's next program
//! counter (`pc + 1`, or `target` for a taken branch). A non-branching instruction with
//! `invert` set jumps to `target` after it (the assembler folds a following `jal r0` into it,
//! saving the jump's turn). A thread has one instruction in flight, so the engine needs no
//! hazard logic (see `hw::engine`).
//!
//! Encoding ([`Instr::encode`], the only one: the engine's three ROMs hold its words, the
//! listing prints them, the twin runs what they decode to): [`ROM_WORDS`] words of 32 bits,
//! - control: `op[30:26] dst[25:18] a[17:10] b[9:2] b_imm[1] invert[0]`,
//! - immediate: `imm[31:0]`,
//! - auxiliary: `b_zero[19] a_zero[18] shift[17:15] bank[14:12] target[11:0]`,
//!
//! each field at its `CTL_*` / `AUX_*` bit, which the engine's decoder takes from here.
//! `a_zero` (`a` is r0) and `b_zero` (`b` is r0 and no immediate replaces it) are decoded
//! ahead into the ROM: the engine's decoder chooses a zero operand with one bit as the
//! register word arrives, with no compare behind the ROM's late output.

use std::fmt;

/// Registers per thread.
pub const REGISTERS: usize = 256;
pub const REG_BITS: usize = 8;
/// Bits of a program address.
pub const PC_BITS: usize = 12;
/// Largest program.
pub const MAX_PROGRAM: usize = 1 << PC_BITS;
/// Bits of an opcode.
pub const OP_BITS: usize = 5;

/// 32-bit ROM words per instruction: control, immediate, auxiliary.
pub const ROM_WORDS: usize = 3;
/// The lowest bit of each field of the control word.
pub const CTL_OP: usize = 26;
pub const CTL_DST: usize = 18;
pub const CTL_A: usize = 10;
pub const CTL_B: usize = 2;
pub const CTL_B_IMM: usize = 1;
pub const CTL_INVERT: usize = 0;
/// The lowest bit of each field of the auxiliary word.
pub const AUX_SHIFT: usize = 15;
pub const AUX_BANK: usize = 12;
pub const AUX_TARGET: usize = 0;
pub const AUX_A_ZERO: usize = 18;
pub const AUX_B_ZERO: usize = 19;
/// Bits of `shift` and of `bank`.
pub const SHIFT_BITS: usize = 3;
pub const BANK_BITS: usize = 3;

/// The two mailboxes of a thread (the `imm` of `Mbx` / `Mbc`). The program uses the instance
/// mailbox; triangles are mailboxed by the triangle tester's list unit (`TriFn::List`).
pub const MAILBOX_TRIANGLES: u32 = 0;
pub const MAILBOX_INSTANCES: u32 = 1;

/// What an instruction does. `A` = `r[a]`; `B` = `imm` when `b_imm`, else `r[b]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Op {
    Nop = 0,
    /// `dst = A + B` in the format (and so on for the next four).
    FAdd,
    FSub,
    FMul,
    FDiv,
    /// `dst = sqrt(A)`.
    FSqrt,
    /// Integer (32-bit, wrapping) `dst = A + B`, `A - B`, `A & B`, `A | B`, `A ^ B`,
    /// `A >> B`, `A << B` (shift counts modulo 32).
    Add,
    Sub,
    And,
    Or,
    Xor,
    Shr,
    Shl,
    /// `dst = bank[(A << shift) + imm]`.
    Ld,
    /// Frame-buffer store: `frame[(A << shift) + imm] = r[b]`.
    St,
    /// Thread scratch memory (kd stack, mirror chain): `dst = scratch[A + imm]`.
    Lds,
    /// `scratch[A + imm] = r[b]`.
    Sts,
    /// Branch to `target` when `(A < B) != invert` in the format (and `<=`, `==`).
    BFlt,
    BFle,
    BFeq,
    /// Branch when `(A == B) != invert` / `(A < B unsigned) != invert` on integers.
    Beq,
    Bltu,
    /// `dst = pc + 1`, jump to `target`.
    Jal,
    /// Jump to `A`.
    Jr,
    /// Mailbox `imm`: branch to `target` when `A` is in it, else record `A` (first in, first
    /// out over `MAILBOX_ENTRIES` entries).
    Mbx,
    /// Empty mailbox `imm`.
    Mbc,
    /// Take the next pixel of the frame: `dst = (y << s) | x` with `s` the program's
    /// `ProgramConfig::pixel_shift` (log2 of a power-of-two width: the pixel's index in the
    /// frame; else 16); branch to `target` when every pixel is taken.
    Pixel,
    /// The thread stops.
    Halt,
    /// The triangle tester (`hw::TriangleTester`), function `imm` ([`TriFn`]): give it the
    /// ray, queue a triangle test, wait for the thread's tests, read the closest hit. A
    /// function that queues repeats itself on the thread's next turn while the queue is full;
    /// `wait` repeats while tests are in flight (neither repeat counts as retired).
    Tri,
    /// The traversal unit (`hw::TraversalUnit`), function `imm` ([`KdFn`]): walk an object's
    /// kd tree, its leaves' triangles tested by the triangle tester, or the top-level tree,
    /// whose leaves come back to the thread. `start` and `next` repeat while refused, `wait`
    /// while the walk is in flight.
    Kd,
    /// A colour channel's byte shifted in: `dst = (B << 8) | byte(A)`, where `byte` clamps `A`
    /// to [0, 1] and rounds 255 times it to an integer (`units::channel_byte`); three in a row
    /// pack `0x00RRGGBB`.
    Byte,
}

/// The functions of [`Op::Kd`] (its `imm`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum KdFn {
    /// Walk from root `A` (bits 25..0) with the segment `[t_min, B]` (t_min from the tester's
    /// init). An object walk ([`KD_ANY_HIT`] for one that ends at the first hit) hands each
    /// leaf's list to the triangle tester and goes on with its closest hit, to the walk's end;
    /// with [`KD_ENTERED`] its root is the object root of the thread's last `tri.enter` and its
    /// segment ends at the closest hit so far (the tester's last answer, or the top-level
    /// walk's t_max before any). A top-level walk ([`KD_TOP`]) walks the world ray
    /// (`tri.world`) and stops at each leaf until the thread says `next`.
    Start = 0,
    /// Repeat while the walk is in flight (asleep); the closest hit is the tester's. `dst` =
    /// after an object walk, the query's hit flag (1 when some test hit so far, else 0);
    /// after a top-level walk's stop, its leaf's list's first bank-1 address, or
    /// [`KD_WALK_ENDED`].
    Wait,
    /// The top-level walk goes on after its leaf with the closest hit so far (the tester's
    /// last answer to an object walk of the thread, or none): it ends when the hit lies in the
    /// leaf's segment, the stack is empty or the popped segment starts behind the hit
    /// (`units::KdWalk::next`).
    Next,
    /// `dst` = the top-level leaf's list end (after a `wait` that gave a leaf).
    Leaf,
}

/// Bit 31 of `kd.start`'s root: the walk answers a shadow query, and ends at the first hit.
pub const KD_ANY_HIT: u32 = 1 << 31;
/// Bit 30 of `kd.start`'s root: the walk is of the top-level tree.
pub const KD_TOP: u32 = 1 << 30;
/// Bit 29 of `kd.start`'s root: the walk is of the object the thread entered last
/// (`tri.enter`), up to the closest hit so far.
pub const KD_ENTERED: u32 = 1 << 29;
/// `kd.wait`'s result when the top-level walk has ended.
pub const KD_WALK_ENDED: u32 = 1 << 31;

impl KdFn {
    pub const ALL: [KdFn; 4] = [KdFn::Start, KdFn::Wait, KdFn::Next, KdFn::Leaf];
    pub fn from_imm(imm: u32) -> Option<KdFn> {
        Self::ALL.get(imm as usize).copied()
    }
    pub fn name(self) -> &'static str {
        match self {
            KdFn::Start => "start",
            KdFn::Wait => "wait",
            KdFn::Next => "next",
            KdFn::Leaf => "leaf",
        }
    }
}

/// The functions of [`Op::Tri`] (its `imm`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum TriFn {
    /// Ray words: `o.x = A, o.y = B`; `o.z = A, d.x = B`; `d.y = A, d.z = B` (object space).
    RayOxy = 0,
    RayOzDx,
    RayDyz,
    /// A new query: `t_min = A`, and queue "no hit yet, best t = B" behind the thread's tests.
    Init,
    /// Queue the tests of the triangle list `A..B` (bank-1 word addresses): every triangle
    /// that is not the query's skipped one and not in the thread's triangle mailbox (which
    /// records it), in list order (the tester's list unit reads the list).
    List,
    /// Repeat while tests are in flight or the thread's primary ray (its last `pixel`'s) is
    /// not written yet; `dst` = best t.
    Wait,
    /// `dst` = 1 when some test hit, else 0.
    Hit,
    /// `dst` = the instance, the triangle of the closest hit.
    Instance,
    Triangle,
    /// Queue: the query does not test triangle `B` of instance `A` (the one it starts on).
    Skip,
    /// Ray generation's camera words `2 s`, `2 s + 1` = `A`, `B` for the instruction's shift
    /// field `s` (0..8: the camera 3x4 `FrameMap::CAMERA`, then the eye `FrameMap::EYE`).
    Camera,
    /// `dst` = component `s` (the shift field, 0..3) of the thread's primary direction, or
    /// of the world normal of its last `Normal` (after a wait).
    Dir,
    /// World ray words of the thread's trace, for instance entry (`hw::engine::InstanceRays`):
    /// pair `s` (the shift field, 0..3, the ray words' pairs: `o.x o.y`, `o.z d.x`, `d.y d.z`)
    /// = `A`, `B`.
    World,
    /// Enter instance `A` (its record at `A * INSTANCE_WORDS` in bank 4) and walk its object:
    /// the thread's world ray through the record's world-to-object 3x4 (`units::transform`,
    /// origin then direction) becomes its ray in both coprocessors, the next lists are the
    /// instance's (an `Object` queued with the entry), and once the ray is written the
    /// traversal unit walks the record's object root up to the thread's last answer (as
    /// `kd.start` with [`KD_ENTERED`], answering any hit when `B` has [`KD_ANY_HIT`]); the
    /// thread's next `kd.wait` waits for the walk's end. Repeats while refused.
    Enter,
    /// Shading's world normal through the one TransformUnit: instance `A`'s normal matrix
    /// (`instance_word::NORMAL_MATRIX`, by instance entry, `hw::engine::InstanceRays`) times
    /// the object-space normal `(x, y, B)`, whose x and y are the thread's world words 0 and 1
    /// (`World` pair 0: the trace that needed the world ray is over). `Dir` reads the result
    /// after a `wait` ([`units::transform3`](crate::units::transform3), not unit length).
    /// Repeats while refused.
    Normal,
    /// Shade the thread's finished query into the frame buffer (`hw::ShadeUnit`): the pixel's
    /// word `A` (before the frame buffer's base), the tester's closest hit (or its miss), the
    /// thread's ray; the unit writes `units::shade_direct`'s pixel in its own time, so the
    /// thread goes on at once. Repeats while refused (every slot busy).
    Shade,
}

impl TriFn {
    pub const ALL: [TriFn; 16] = [
        TriFn::RayOxy,
        TriFn::RayOzDx,
        TriFn::RayDyz,
        TriFn::Init,
        TriFn::List,
        TriFn::Wait,
        TriFn::Hit,
        TriFn::Instance,
        TriFn::Triangle,
        TriFn::Skip,
        TriFn::Camera,
        TriFn::Dir,
        TriFn::World,
        TriFn::Enter,
        TriFn::Normal,
        TriFn::Shade,
    ];
    pub fn from_imm(imm: u32) -> Option<TriFn> {
        Self::ALL.get(imm as usize).copied()
    }
    pub fn name(self) -> &'static str {
        match self {
            TriFn::RayOxy => "ray.oxy",
            TriFn::RayOzDx => "ray.ozdx",
            TriFn::RayDyz => "ray.dyz",
            TriFn::Init => "init",
            TriFn::List => "list",
            TriFn::Wait => "wait",
            TriFn::Hit => "hit",
            TriFn::Instance => "instance",
            TriFn::Triangle => "triangle",
            TriFn::Skip => "skip",
            TriFn::Camera => "camera",
            TriFn::Dir => "dir",
            TriFn::World => "world",
            TriFn::Enter => "enter",
            TriFn::Normal => "normal",
            TriFn::Shade => "shade",
        }
    }
    /// Whether the function puts an entry in the tester's queue.
    pub fn queues(self) -> bool {
        matches!(self, TriFn::Init | TriFn::List | TriFn::Skip)
    }
}

pub const OPS: [Op; 31] = [
    Op::Nop,
    Op::FAdd,
    Op::FSub,
    Op::FMul,
    Op::FDiv,
    Op::FSqrt,
    Op::Add,
    Op::Sub,
    Op::And,
    Op::Or,
    Op::Xor,
    Op::Shr,
    Op::Shl,
    Op::Ld,
    Op::St,
    Op::Lds,
    Op::Sts,
    Op::BFlt,
    Op::BFle,
    Op::BFeq,
    Op::Beq,
    Op::Bltu,
    Op::Jal,
    Op::Jr,
    Op::Mbx,
    Op::Mbc,
    Op::Pixel,
    Op::Halt,
    Op::Tri,
    Op::Kd,
    Op::Byte,
];

impl Op {
    /// Whether the instruction writes `dst`.
    pub fn writes(self) -> bool {
        use Op::*;
        matches!(
            self,
            FAdd | FSub
                | FMul
                | FDiv
                | FSqrt
                | Add
                | Sub
                | And
                | Or
                | Xor
                | Shr
                | Shl
                | Ld
                | Lds
                | Jal
                | Pixel
                | Tri
                | Kd
                | Byte
        )
    }
    /// Whether the instruction writes `dst` with a value computed from its operands alone
    /// (arithmetic and loads; not a link, a pixel or a coprocessor's answer).
    pub fn computes(self) -> bool {
        self.writes() && !matches!(self, Op::Jal | Op::Pixel | Op::Tri | Op::Kd)
    }
    /// Whether an instruction of this op can carry a jump to `target` after it (`invert`).
    pub fn can_jump_after(self) -> bool {
        !self.branches() && !matches!(self, Op::Jr | Op::Halt)
    }
    /// Whether `target` is a branch target.
    pub fn branches(self) -> bool {
        use Op::*;
        matches!(self, BFlt | BFle | BFeq | Beq | Bltu | Jal | Mbx | Pixel)
    }
    /// The hardware unit that executes it (for statistics and for leaving units out).
    pub fn unit(self) -> Unit {
        use Op::*;
        match self {
            FAdd | FSub => Unit::FpAdd,
            FMul => Unit::FpMul,
            FDiv => Unit::FpDiv,
            FSqrt => Unit::FpSqrt,
            BFlt | BFle | BFeq => Unit::FpCompare,
            Ld | St => Unit::Memory,
            Lds | Sts => Unit::Scratch,
            Mbx | Mbc => Unit::Mailbox,
            Pixel => Unit::RayGeneration,
            Tri => Unit::TriangleTester,
            Kd => Unit::TraversalUnit,
            Byte => Unit::ChannelByte,
            Nop | Add | Sub | And | Or | Xor | Shr | Shl | Beq | Bltu | Jal | Jr | Halt => {
                Unit::Integer
            }
        }
    }
    pub fn name(self) -> &'static str {
        use Op::*;
        match self {
            Nop => "nop",
            FAdd => "fadd",
            FSub => "fsub",
            FMul => "fmul",
            FDiv => "fdiv",
            FSqrt => "fsqrt",
            Add => "add",
            Sub => "sub",
            And => "and",
            Or => "or",
            Xor => "xor",
            Shr => "shr",
            Shl => "shl",
            Ld => "ld",
            St => "st",
            Lds => "lds",
            Sts => "sts",
            BFlt => "bflt",
            BFle => "bfle",
            BFeq => "bfeq",
            Beq => "beq",
            Bltu => "bltu",
            Jal => "jal",
            Jr => "jr",
            Mbx => "mbx",
            Mbc => "mbc",
            Pixel => "pixel",
            Halt => "halt",
            Tri => "tri",
            Kd => "kd",
            Byte => "byte",
        }
    }
}

/// The engine's functional units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Unit {
    FpAdd,
    FpMul,
    FpDiv,
    FpSqrt,
    FpCompare,
    Integer,
    Memory,
    Scratch,
    Mailbox,
    RayGeneration,
    TriangleTester,
    TraversalUnit,
    ChannelByte,
    /// `tri.world`, `tri.enter`, `tri.normal`: the engine's `InstanceRays`.
    InstanceEntry,
    /// `tri.shade`: the engine's `ShadeUnit`.
    Shading,
}

impl Unit {
    pub const ALL: [Unit; 15] = [
        Unit::FpAdd,
        Unit::FpMul,
        Unit::FpDiv,
        Unit::FpSqrt,
        Unit::FpCompare,
        Unit::Integer,
        Unit::Memory,
        Unit::Scratch,
        Unit::Mailbox,
        Unit::RayGeneration,
        Unit::TriangleTester,
        Unit::TraversalUnit,
        Unit::ChannelByte,
        Unit::InstanceEntry,
        Unit::Shading,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Unit::FpAdd => "fp add",
            Unit::FpMul => "fp mul",
            Unit::FpDiv => "fp div",
            Unit::FpSqrt => "fp sqrt",
            Unit::FpCompare => "fp compare",
            Unit::Integer => "integer",
            Unit::Memory => "memory",
            Unit::Scratch => "scratch",
            Unit::Mailbox => "mailbox",
            Unit::RayGeneration => "ray generation",
            Unit::TriangleTester => "triangle tester",
            Unit::TraversalUnit => "traversal unit",
            Unit::ChannelByte => "channel byte",
            Unit::InstanceEntry => "instance entry",
            Unit::Shading => "shading",
        }
    }
}

/// One decoded instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Instr {
    pub op: Op,
    pub dst: u8,
    pub a: u8,
    pub b: u8,
    pub b_imm: bool,
    pub invert: bool,
    pub shift: u8,
    pub bank: u8,
    pub imm: u32,
    pub target: u16,
}

impl Instr {
    pub fn new(op: Op) -> Self {
        Instr {
            op,
            dst: 0,
            a: 0,
            b: 0,
            b_imm: false,
            invert: false,
            shift: 0,
            bank: 0,
            imm: 0,
            target: 0,
        }
    }

    /// Whether the instruction continues at `target` rather than `pc + 1` when it does not
    /// branch by itself (the engine's next-pc rule: `condition != invert`, the condition of a
    /// non-branching instruction being false).
    pub fn jumps_after(&self) -> bool {
        self.invert && self.op.can_jump_after()
    }

    /// The unit that executes the instruction: its op's, but for the `tri` functions of
    /// instance entry.
    pub fn unit(&self) -> Unit {
        let instance_entry = [TriFn::World, TriFn::Enter, TriFn::Normal].map(|f| f as u32);
        if self.op == Op::Tri && instance_entry.contains(&self.imm) {
            Unit::InstanceEntry
        } else if self.op == Op::Tri && self.imm == TriFn::Shade as u32 {
            Unit::Shading
        } else {
            self.op.unit()
        }
    }

    /// The ROM words (see the module doc for the fields).
    pub fn encode(&self) -> [u32; ROM_WORDS] {
        let field = |v: u32, bits: usize, at: usize| {
            debug_assert!(v < 1 << bits, "{self:?}: {v} does not fit {bits} bits");
            v << at
        };
        let ctl = field(self.op as u32, OP_BITS, CTL_OP)
            | field(self.dst.into(), REG_BITS, CTL_DST)
            | field(self.a.into(), REG_BITS, CTL_A)
            | field(self.b.into(), REG_BITS, CTL_B)
            | field(self.b_imm.into(), 1, CTL_B_IMM)
            | field(self.invert.into(), 1, CTL_INVERT);
        let aux = field((self.a == 0).into(), 1, AUX_A_ZERO)
            | field((self.b == 0 && !self.b_imm).into(), 1, AUX_B_ZERO)
            | field(self.shift.into(), SHIFT_BITS, AUX_SHIFT)
            | field(self.bank.into(), BANK_BITS, AUX_BANK)
            | field(self.target.into(), PC_BITS, AUX_TARGET);
        [ctl, self.imm, aux]
    }

    /// The inverse of [`Instr::encode`]; `None` for a word with a bit outside every field or
    /// an opcode no op has.
    pub fn decode(w: [u32; ROM_WORDS]) -> Option<Instr> {
        let [ctl, imm, aux] = w;
        let field = |word: u32, bits: usize, at: usize| (word >> at) & ((1 << bits) - 1);
        let i = Instr {
            op: *OPS.get(field(ctl, OP_BITS, CTL_OP) as usize)?,
            dst: field(ctl, REG_BITS, CTL_DST) as u8,
            a: field(ctl, REG_BITS, CTL_A) as u8,
            b: field(ctl, REG_BITS, CTL_B) as u8,
            b_imm: field(ctl, 1, CTL_B_IMM) == 1,
            invert: field(ctl, 1, CTL_INVERT) == 1,
            shift: field(aux, SHIFT_BITS, AUX_SHIFT) as u8,
            bank: field(aux, BANK_BITS, AUX_BANK) as u8,
            imm,
            target: field(aux, PC_BITS, AUX_TARGET) as u16,
        };
        (i.encode() == w).then_some(i)
    }
}

impl fmt::Display for Instr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = if self.b_imm {
            format!("#{:#x}", self.imm)
        } else {
            format!("r{}", self.b)
        };
        let inv = if self.invert { "!" } else { "" };
        if self.jumps_after() {
            let plain = Instr {
                invert: false,
                ..*self
            };
            return write!(f, "{plain}; jump @{}", self.target);
        }
        match self.op {
            Op::Nop | Op::Halt => write!(f, "{}", self.op.name()),
            Op::Ld => write!(
                f,
                "ld r{}, bank{}[(r{} << {}) + {}]",
                self.dst, self.bank, self.a, self.shift, self.imm
            ),
            Op::St => write!(
                f,
                "st frame[(r{} << {}) + {}], r{}",
                self.a, self.shift, self.imm, self.b
            ),
            Op::Lds => write!(f, "lds r{}, [r{} + {}]", self.dst, self.a, self.imm),
            Op::Sts => write!(f, "sts [r{} + {}], r{}", self.a, self.imm, self.b),
            Op::BFlt | Op::BFle | Op::BFeq | Op::Beq | Op::Bltu => write!(
                f,
                "{}{} r{}, {}, @{}",
                inv,
                self.op.name(),
                self.a,
                b,
                self.target
            ),
            Op::Jal => write!(f, "jal r{}, @{}", self.dst, self.target),
            Op::Jr => write!(f, "jr r{}", self.a),
            Op::Mbx => write!(f, "mbx{} r{}, @{}", self.imm, self.a, self.target),
            Op::Mbc => write!(f, "mbc{}", self.imm),
            Op::Pixel => write!(f, "pixel r{}, @{}", self.dst, self.target),
            Op::Tri => match TriFn::from_imm(self.imm) {
                // Their word or pair index is the shift field.
                Some(TriFn::Camera) => {
                    write!(f, "tri.camera{} r{}, r{}", self.shift, self.a, self.b)
                }
                Some(TriFn::Dir) => write!(f, "tri.dir{} r{}", self.shift, self.dst),
                other => {
                    let name = other.map_or("?", TriFn::name);
                    write!(f, "tri.{name} r{}, r{}, r{}", self.dst, self.a, self.b)
                }
            },
            Op::Kd => {
                let name = KdFn::from_imm(self.imm).map_or("?", KdFn::name);
                write!(f, "kd.{name} r{}, r{}, r{}", self.dst, self.a, self.b)
            }
            Op::FSqrt => write!(f, "{} r{}, r{}", self.op.name(), self.dst, self.a),
            _ => write!(f, "{} r{}, r{}, {}", self.op.name(), self.dst, self.a, b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every op with every function it has, and random fields: the words decode to the
    /// instruction, and a bit outside every field is refused.
    #[test]
    fn encode_decode_round_trip_of_every_instruction_kind() {
        assert!(OPS.len() <= 1 << OP_BITS);
        for (k, op) in OPS.iter().enumerate() {
            assert_eq!(*op as usize, k, "OPS is in encoding order");
        }
        // The opcodes past the last op are refused.
        for code in OPS.len()..1 << OP_BITS {
            let mut w = Instr::new(Op::Nop).encode();
            w[0] |= (code as u32) << CTL_OP;
            assert_eq!(Instr::decode(w), None, "opcode {code}");
        }
        let seed = 5;
        println!("seed {seed}");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let kinds = OPS.iter().flat_map(|&op| {
            let functions: Vec<u32> = match op {
                Op::Tri => TriFn::ALL.iter().map(|&f| f as u32).collect(),
                Op::Kd => KdFn::ALL.iter().map(|&f| f as u32).collect(),
                _ => vec![u32::MAX],
            };
            functions.into_iter().map(move |f| (op, f))
        });
        let mut count = 0;
        for (op, function) in kinds {
            for _ in 0..1_000 {
                let i = Instr {
                    op,
                    dst: rng.gen(),
                    a: rng.gen(),
                    b: rng.gen(),
                    b_imm: rng.gen(),
                    invert: rng.gen(),
                    shift: rng.gen_range(0..1 << SHIFT_BITS),
                    bank: rng.gen_range(0..1 << BANK_BITS),
                    imm: if function == u32::MAX {
                        rng.gen()
                    } else {
                        function
                    },
                    target: rng.gen_range(0..MAX_PROGRAM as u16),
                };
                let w = i.encode();
                assert_eq!(Instr::decode(w), Some(i), "{i:?}");
                // The words' free bits (ctl 31, aux 31..20) set, and the operand-is-zero bits
                // decoded ahead (aux 18, 19) contradicting the operands.
                let stray = [1u32 << 31, 0, 1 << rng.gen_range(20..32)];
                for (k, bit) in stray.into_iter().enumerate().filter(|(_, b)| *b != 0) {
                    let mut bad = w;
                    bad[k] |= bit;
                    assert_eq!(Instr::decode(bad), None, "{i:?} with word {k} bit {bit:#x}");
                }
                for bit in [AUX_A_ZERO, AUX_B_ZERO] {
                    let mut bad = w;
                    bad[2] ^= 1 << bit;
                    assert_eq!(Instr::decode(bad), None, "{i:?} with aux bit {bit} flipped");
                }
            }
            count += 1;
        }
        assert_eq!(count, OPS.len() - 2 + TriFn::ALL.len() + KdFn::ALL.len());
    }
}
