//! `ThreadEngine`: the ray thread engine that runs the microprogram (`hw::program`) for up to
//! 32 ray threads, one instruction per clock, on pipelined floating-point units.
//!
//! A scheduler issues one ready thread per clock, round robin. An instruction writes back
//! exactly [`ENGINE_LATENCY`] (11) clocks after its operands are read, `fdiv` and `fsqrt`
//! [`long_latency`] (`M + 6`) clocks after, and a thread is ready again only at its write
//! back, so there is no hazard, stall or forwarding logic: memory and unit latency are hidden
//! by the other threads (the paper's 32 threads). A long instruction reserves its write-back
//! clock: the scheduler issues nothing in the one clock whose instruction would write back
//! with it (one bubble per `fdiv` or `fsqrt`). A thread issues at most once per `period =
//! ENGINE_LATENCY + 4` (15) clocks (`engine_period`). A thread whose coprocessor wait (`tri.wait`,
//! `kd.wait`) is still pending sleeps: it is not ready until the coprocessor finishes work for
//! it, so the clocks it waits go to the other threads (an offer to a full queue repeats at
//! once).
//!
//! Pipeline (clock offsets from the issue):
//! - I0: read the thread's `{epoch, halted, pc}` (a stale epoch means "new frame": pc 0).
//! - I1: read the instruction ROM (three words: control, immediate, branch fields).
//! - I2: decode; read the two source registers, the thread's mailbox and its state in the
//!   triangle tester.
//! - I3: operands. Feed every unit; compute the integer result, mailbox hit (and update),
//!   pixel counter, memory and scratch addresses; drive the memory and frame-buffer ports;
//!   offer `tri` and `kd` entries to the coprocessors (their answer, refused or pending,
//!   makes the thread repeat the instruction on its next turn, after a sleep for a wait).
//! - I4..: the fast result line; scratch data joins at I4, memory data at I4 + `mem_latency`.
//! - I3 + 11 (`I3 + M + 6` for `fdiv`, `fsqrt`, which go on in the long line): write back
//!   the register and the next pc: `target` when the condition differs
//!   from `invert` (a non-branching instruction's condition is false, so its `invert` is a jump
//!   after it), else `pc + 1`; the condition comes from the compare, integer, mailbox, pixel
//!   unit or triangle tester.
//!
//! Throughput: one instruction per clock while at least 15 threads are awake; a frame
//! ends when every thread has executed `halt` (`done`). Counters: clocks of the frame,
//! instructions retired, and clocks in which the triangle tester's TransformUnit and
//! IntersectUnit took an input.
//! `instructions` counts retired instructions: not the turns a thread spends offering an entry
//! again to a full coprocessor queue or waiting for a coprocessor, so it equals the count of
//! the engine's twin, which never waits.
//!
//! Two coprocessors run beside the engine. The [`TraversalUnit`] walks a thread's object kd
//! tree (a thread starts the walk and sleeps until it ends, instead of 15-23 turns per inner
//! node in microcode); it hands each leaf's list to the [`TriangleTester`], whose list unit
//! reads it and queues its triangles, and which answers the traversal unit with the closest
//! hit. A walk costs the thread four turns, whatever its leaves.
//!
//! Memory: one read per clock on the `mem_*` port (banks 0, 1, 4, 5; the tester's list reads
//! of bank 1 use it in the clocks the engine leaves free) and on each of the
//! `bank2_*` and `bank3_*` ports (the triangles; the tester fetches from both at once, the
//! engine's loads of these banks go there too, first); a word must arrive exactly
//! `mem_latency` clocks after its request (1..=6). Frame-buffer writes come out on `fb_*`.

use rust_hdl::prelude::*;

use super::fp::{FpAddSub, FpCompare, FpDiv, FpMul, FpSqrt};
use super::list_unit;
use super::program::isa::{
    self, KdFn, Op, TriFn, BANK_BITS, OPS, OP_BITS, PC_BITS, REG_BITS, SHIFT_BITS,
};
use super::program::Program;
use super::{ChannelByte, Delay, TraversalUnit, TriangleTester, UIntToFloat, CHANNEL_BYTE_LATENCY};
use crate::layout;

/// Most threads (the thread id is 5 bits).
pub const MAX_THREADS: usize = 32;
/// Largest supported `mem_latency`.
pub const MAX_MEM_LATENCY: u32 = 6;
/// Scratch words per thread the engine provides.
pub const SCRATCH_WORDS: u32 = 128;

/// Clocks from operand read to write back of every instruction but `fdiv` and `fsqrt`: the
/// longest of them is `byte` ([`CHANNEL_BYTE_LATENCY`]; `fadd` takes 7, loads at most 8).
pub const ENGINE_LATENCY: u32 = CHANNEL_BYTE_LATENCY;

/// Clocks from operand read to write back of `fdiv` and `fsqrt` for mantissa width `m` (the
/// divider's and the square root's `m + 5`, plus one register).
pub const fn long_latency(m: u32) -> u32 {
    m + 6
}

/// The clocks of one round of `threads` threads, each issuing once: a thread issues at most
/// once per `ENGINE_LATENCY + 4` clocks.
pub fn engine_period(threads: u32) -> u32 {
    threads.max(ENGINE_LATENCY + 4)
}

/// Registers of the fast result line (the `0..8` loops of `update` spell it out: rust-hdl's
/// Verilog cannot name Rust constants).
const FAST_STAGES: usize = 8;

#[derive(LogicBlock)]
pub struct ThreadEngine<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DX: usize,
    const DL: usize,
> {
    pub clock: Signal<In, Clock>,
    /// A one-clock pulse starts a frame (while `done` or before the first frame).
    pub start: Signal<In, Bit>,
    pub done: Signal<Out, Bit>,
    pub cycles: Signal<Out, Bits<32>>,
    pub instructions: Signal<Out, Bits<32>>,
    pub mem_read: Signal<Out, Bit>,
    pub mem_bank: Signal<Out, Bits<3>>,
    pub mem_addr: Signal<Out, Bits<24>>,
    pub mem_rdata: Signal<In, Bits<32>>,
    pub fb_write: Signal<Out, Bit>,
    pub fb_addr: Signal<Out, Bits<24>>,
    pub fb_data: Signal<Out, Bits<32>>,
    /// Banks 0 (kd nodes), 2 and 3 (the triangles) have their own ports: the traversal unit
    /// reads bank 0, the triangle tester banks 2 and 3 at once, and the engine's loads of
    /// these banks go out here too.
    pub bank0_read: Signal<Out, Bit>,
    pub bank0_addr: Signal<Out, Bits<24>>,
    pub bank0_rdata: Signal<In, Bits<32>>,
    pub bank2_read: Signal<Out, Bit>,
    pub bank2_addr: Signal<Out, Bits<24>>,
    pub bank2_rdata: Signal<In, Bits<32>>,
    pub bank3_read: Signal<Out, Bit>,
    pub bank3_addr: Signal<Out, Bits<24>>,
    pub bank3_rdata: Signal<In, Bits<32>>,
    /// Clocks of the frame in which the TransformUnit and the IntersectUnit took an input.
    pub transform_busy: Signal<Out, Bits<32>>,
    pub intersect_busy: Signal<Out, Bits<32>>,
    /// Clocks of the frame in which the traversal unit started a node decision.
    pub traversal_busy: Signal<Out, Bits<32>>,

    // Thread state and program.
    pc_ram: RAM<Bits<16>, 5>,
    rom_ctl: RAM<Bits<32>, 12>,
    rom_imm: RAM<Bits<32>, 12>,
    rom_aux: RAM<Bits<32>, 12>,
    regs_a: RAM<Bits<32>, 13>,
    regs_b: RAM<Bits<32>, 13>,
    scratch: RAM<Bits<32>, 12>,
    mailbox: [RAM<Bits<32>, 6>; 8],
    mailbox_meta: RAM<Bits<8>, 6>,

    // Control.
    running: DFF<Bit>,
    epoch: DFF<Bit>,
    /// The scheduler: threads that may issue (written back, not asleep); threads asleep on a
    /// coprocessor wait; threads a coprocessor finished work for since their issue; the
    /// thread issued last (the search for the next starts below it).
    ready: DFF<Bits<32>>,
    asleep: DFF<Bits<32>>,
    woken: DFF<Bits<32>>,
    last_pick: DFF<Bits<5>>,
    below: Signal<Local, Bits<32>>,
    pick: Signal<Local, Bits<5>>,
    issue: Signal<Local, Bit>,
    issue_mask: Signal<Local, Bits<32>>,
    wb_mask: Signal<Local, Bits<32>>,
    tester_event: Signal<Local, Bits<32>>,
    walk_event: Signal<Local, Bits<32>>,
    event_mask: Signal<Local, Bits<32>>,
    wb_sleep: Signal<Local, Bit>,
    wake_mask: Signal<Local, Bits<32>>,
    sleep_mask: Signal<Local, Bits<32>>,
    halted_count: DFF<Bits<8>>,
    cycle_count: DFF<Bits<32>>,
    instr_count: DFF<Bits<32>>,
    transform_count: DFF<Bits<32>>,
    intersect_count: DFF<Bits<32>>,
    traversal_count: DFF<Bits<32>>,
    px: DFF<Bits<16>>,
    py: DFF<Bits<16>>,
    // I1
    v1: DFF<Bit>,
    t1: DFF<Bits<5>>,
    // I2
    v2: DFF<Bit>,
    t2: DFF<Bits<5>>,
    pc2: DFF<Bits<12>>,
    pc1_eff: Signal<Local, Bits<12>>,
    entry_fresh: Signal<Local, Bit>,
    // I3
    v3: DFF<Bit>,
    t3: DFF<Bits<5>>,
    pc3: DFF<Bits<12>>,
    ctl3: DFF<Bits<32>>,
    imm3: DFF<Bits<32>>,
    aux3: DFF<Bits<32>>,
    op3: Signal<Local, Bits<5>>,
    opa: Signal<Local, Bits<32>>,
    opb: Signal<Local, Bits<32>>,
    shifted: Signal<Local, Bits<32>>,
    mem_address: Signal<Local, Bits<32>>,
    scratch_address: Signal<Local, Bits<32>>,
    fast: Signal<Local, Bits<32>>,
    int_eq: Signal<Local, Bit>,
    int_lt: Signal<Local, Bit>,
    mb_hit: Signal<Local, Bit>,
    mb_len: Signal<Local, Bits<4>>,
    mb_next: Signal<Local, Bits<3>>,
    pix_done: Signal<Local, Bit>,
    tri_cond: Signal<Local, Bit>,
    wait_fn: Signal<Local, Bit>,
    kd_cond: Signal<Local, Bit>,
    fast_kind: Signal<Local, FastKind>,
    tri_queues: Signal<Local, Bit>,
    tri_kind: Signal<Local, Bits<2>>,
    // Ports.
    mem_read_r: DFF<Bit>,
    mem_bank_r: DFF<Bits<3>>,
    mem_addr_r: DFF<Bits<24>>,
    fb_write_r: DFF<Bit>,
    fb_addr_r: DFF<Bits<24>>,
    fb_data_r: DFF<Bits<32>>,

    // Units.
    add: FpAddSub<W, E, M, S, S1, X2, T>,
    mul: FpMul<W, E, M, S, S1, X2, P>,
    div: FpDiv<W, E, M, S, S1, X2>,
    sqrt: FpSqrt<W, E, M, S, S1, T>,
    cmp: FpCompare<W, E, M>,
    itof: UIntToFloat<W, E, M>,
    byte_unit: ChannelByte<W, E, M, S, S1, X2, T, P>,
    tester: TriangleTester<W, E, M, S, S1, X2, T, P, DL>,
    traversal_unit: TraversalUnit<W, E, M, S, S1, X2, T, DL>,
    // The delays bring each unit's result to write back at `ENGINE_LATENCY` (11) after I3:
    // 11 - 7 for the adder, 11 - 4 for the multiplier, 11 - 2 for the comparator, 11 - 8
    // after the fast line; the divider and square root (`m + 5`) write back one clock later
    // at `long_latency`.
    add_delay: Delay<Bits<W>, 4>,
    mul_delay: Delay<Bits<W>, 7>,
    div_delay: Delay<Bits<W>, 1>,
    sqrt_delay: Delay<Bits<W>, 1>,
    cmp_delay: Delay<Bits<3>, 9>,
    fast_line: [DFF<Bits<32>>; FAST_STAGES],
    fast_kind_line: [DFF<FastKind>; FAST_STAGES],
    fast_delay: Delay<Bits<32>, 3>,
    /// {valid, op, dst, thread, invert} from I3 to write back.
    ctl_delay: Delay<Bits<21>, 3>,
    ctl_line: [DFF<Bits<21>>; FAST_STAGES],
    /// {pc + 1, target}.
    pc_delay: Delay<Bits<24>, 3>,
    pc_line: [DFF<Bits<24>>; FAST_STAGES],
    /// {a coprocessor wait, traversal unit refused or pending, tester refused or pending,
    /// jump register (12 bits), int_eq, int_lt, mailbox hit, pixels exhausted}.
    cond_delay: Delay<Bits<19>, 3>,
    cond_line: [DFF<Bits<19>>; FAST_STAGES],
    /// `fdiv` and `fsqrt` go on from the others' write back for `DX = long_latency -
    /// ENGINE_LATENCY` clocks: their control and pcs.
    long_ctl: Delay<Bits<21>, DX>,
    long_pc: Delay<Bits<24>, DX>,
    short_ctl: Signal<Local, Bits<21>>,
    long_in: Signal<Local, Bits<21>>,
    wb_ctl: Signal<Local, Bits<21>>,
    wb_pcs: Signal<Local, Bits<24>>,
    /// Clocks in which the scheduler must not issue: a long instruction writes back in the
    /// clock where that issue's instruction would (bit 0 is this clock).
    reserved: DFF<Bits<32>>,
    long3: Signal<Local, Bit>,

    // Write back.
    wb_valid: Signal<Local, Bit>,
    wb_op: Signal<Local, Bits<5>>,
    wb_dst: Signal<Local, Bits<8>>,
    wb_thread: Signal<Local, Bits<5>>,
    wb_invert: Signal<Local, Bit>,
    wb_cond: Signal<Local, Bit>,
    wb_next_pc: Signal<Local, Bits<12>>,
    wb_result: Signal<Local, Bits<32>>,
    wb_writes: Signal<Local, Bit>,

    c_threads: Constant<Bits<8>>,
    /// Bit `t` set for every thread `t`; one; all ones; each thread's number.
    c_thread_mask: Constant<Bits<32>>,
    c_one: Constant<Bits<32>>,
    c_ones: Constant<Bits<32>>,
    c_thread_ids: [Constant<Bits<5>>; 32],
    c_width: Constant<Bits<16>>,
    c_height: Constant<Bits<16>>,
    /// `ProgramConfig::pixel_shift`: where the pixel word puts y.
    c_pixel_shift: Constant<Bits<5>>,
    c_mem_latency: Constant<Bits<8>>,
    c_index: [Constant<Bits<8>>; 8],
    /// The bit of `reserved` a long instruction at I3 sets: `DX - 4`.
    c_reserve_bit: Constant<Bits<32>>,

    // The decoder's names, every one from its definition in `isa` (`Op`, `TriFn`, `KdFn`),
    // `layout` (banks) and `list_unit` (command kinds): the Verilog's localparams follow the
    // twin's numbering by construction.
    op_fadd: Constant<Bits<5>>,
    op_fsub: Constant<Bits<5>>,
    op_fmul: Constant<Bits<5>>,
    op_fdiv: Constant<Bits<5>>,
    op_fsqrt: Constant<Bits<5>>,
    op_itof: Constant<Bits<5>>,
    op_add: Constant<Bits<5>>,
    op_sub: Constant<Bits<5>>,
    op_and: Constant<Bits<5>>,
    op_or: Constant<Bits<5>>,
    op_xor: Constant<Bits<5>>,
    op_shr: Constant<Bits<5>>,
    op_shl: Constant<Bits<5>>,
    op_ld: Constant<Bits<5>>,
    op_st: Constant<Bits<5>>,
    op_lds: Constant<Bits<5>>,
    op_sts: Constant<Bits<5>>,
    op_bflt: Constant<Bits<5>>,
    op_bfle: Constant<Bits<5>>,
    op_bfeq: Constant<Bits<5>>,
    op_beq: Constant<Bits<5>>,
    op_bltu: Constant<Bits<5>>,
    op_jal: Constant<Bits<5>>,
    op_jr: Constant<Bits<5>>,
    op_mbx: Constant<Bits<5>>,
    op_mbc: Constant<Bits<5>>,
    op_pixel: Constant<Bits<5>>,
    op_halt: Constant<Bits<5>>,
    op_tri: Constant<Bits<5>>,
    op_kd: Constant<Bits<5>>,
    op_byte: Constant<Bits<5>>,
    /// Bit `op` set for every op that writes `dst` (`Op::writes`).
    op_writes: Constant<Bits<32>>,
    /// The ray words are `TriFn`s 0..3, their number the ray store's `ray_pair`.
    tri_ray_words: Constant<Bits<32>>,
    tri_init: Constant<Bits<32>>,
    tri_list: Constant<Bits<32>>,
    tri_wait: Constant<Bits<32>>,
    tri_hit: Constant<Bits<32>>,
    tri_instance: Constant<Bits<32>>,
    tri_triangle: Constant<Bits<32>>,
    tri_object: Constant<Bits<32>>,
    tri_skip: Constant<Bits<32>>,
    kd_start: Constant<Bits<32>>,
    kd_wait: Constant<Bits<32>>,
    cmd_list: Constant<Bits<2>>,
    cmd_init: Constant<Bits<2>>,
    cmd_object: Constant<Bits<2>>,
    cmd_skip: Constant<Bits<2>>,
    bank_nodes: Constant<Bits<3>>,
    bank_lists: Constant<Bits<3>>,
    bank_uv: Constant<Bits<3>>,
    bank_t: Constant<Bits<3>>,
    /// The lowest bit of each field of the ROM words (`isa::CTL_*`, `isa::AUX_*`).
    f_op: Constant<Bits<5>>,
    f_dst: Constant<Bits<5>>,
    f_a: Constant<Bits<5>>,
    f_b: Constant<Bits<5>>,
    f_b_imm: Constant<Bits<5>>,
    f_invert: Constant<Bits<5>>,
    f_shift: Constant<Bits<5>>,
    f_bank: Constant<Bits<5>>,
    f_target: Constant<Bits<5>>,
}

/// Where an instruction's result comes from on the fast line: computed at I3, or the data of
/// a scratch read or of a load from the shared memory port or a bank's own port.
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum FastKind {
    Computed,
    Scratch,
    Memory,
    TrianglesUv,
    TrianglesT,
    Nodes,
}

fn op_code(op: Op) -> Constant<Bits<5>> {
    Constant::new((op as u64).into())
}

fn tri_fn(f: TriFn) -> Constant<Bits<32>> {
    Constant::new((f as u64).into())
}

fn kd_fn(f: KdFn) -> Constant<Bits<32>> {
    Constant::new((f as u64).into())
}

fn bank(b: usize) -> Constant<Bits<3>> {
    Constant::new((b as u64).into())
}

fn cmd(c: u64) -> Constant<Bits<2>> {
    Constant::new(c.into())
}

fn field(at: usize) -> Constant<Bits<5>> {
    Constant::new((at as u64).into())
}

fn word_map<const N: usize, D: Synth>(
    words: impl Iterator<Item = D>,
) -> std::collections::BTreeMap<Bits<N>, D> {
    words
        .enumerate()
        .map(|(i, w)| (Bits::<N>::from(i as u64), w))
        .collect()
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
        const DX: usize,
        const DL: usize,
    > ThreadEngine<W, E, M, S, S1, X2, T, P, DX, DL>
{
    /// The engine running `program` with `threads` threads and memory read latency
    /// `mem_latency`.
    pub fn new(program: &Program, threads: u32, mem_latency: u32) -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && T == S + 4);
        assert!(P == 2 * S);
        assert!(ENGINE_LATENCY as usize == FAST_STAGES + 3);
        assert!(super::fp::div::div_latency(M as u32) + 1 == long_latency(M as u32));
        assert!(super::fp::sqrt::sqrt_latency(M as u32) + 1 == long_latency(M as u32));
        // The reservation is made at I3 for an issue `DX - 3` clocks later.
        assert!(DX == (long_latency(M as u32) - ENGINE_LATENCY) as usize && DX >= 4);
        assert!(DL == super::fp::div::div_latency(M as u32) as usize);
        assert!((1..=MAX_THREADS as u32).contains(&threads));
        assert!((1..=MAX_MEM_LATENCY).contains(&mem_latency));
        assert!(program.scratch.words <= SCRATCH_WORDS);
        // The ray words' function number is the ray store's `ray_pair` (`imm` bits 1..0), and
        // every function below `TriFn::Init` is one.
        assert!(
            TriFn::RayOxy as u32 == 0 && TriFn::RayOzDx as u32 == 1 && TriFn::RayDyz as u32 == 2
        );
        assert!(TriFn::Init as u32 == 3);
        let words = program.rom();
        let rom = |k: usize| -> RAM<Bits<32>, 12> {
            RAM::new(word_map(
                words.iter().map(|w| Bits::<32>::from(u64::from(w[k]))),
            ))
        };
        Self {
            clock: Default::default(),
            start: Default::default(),
            done: Default::default(),
            cycles: Default::default(),
            instructions: Default::default(),
            mem_read: Default::default(),
            mem_bank: Default::default(),
            mem_addr: Default::default(),
            mem_rdata: Default::default(),
            fb_write: Default::default(),
            fb_addr: Default::default(),
            fb_data: Default::default(),
            bank0_read: Default::default(),
            bank0_addr: Default::default(),
            bank0_rdata: Default::default(),
            bank2_read: Default::default(),
            bank2_addr: Default::default(),
            bank2_rdata: Default::default(),
            bank3_read: Default::default(),
            bank3_addr: Default::default(),
            bank3_rdata: Default::default(),
            transform_busy: Default::default(),
            intersect_busy: Default::default(),
            traversal_busy: Default::default(),
            pc_ram: RAM::new(word_map((0..32).map(|_| Bits::<16>::from(0u64)))),
            rom_ctl: rom(0),
            rom_imm: rom(1),
            rom_aux: rom(2),
            // Registers, scratch and mailbox entries start undefined: the program writes every
            // register and scratch word before reading it, and an entry counts only below the
            // mailbox's length (so the generated Verilog stays small and Icarus compiles it
            // quickly).
            regs_a: Default::default(),
            regs_b: Default::default(),
            scratch: Default::default(),
            mailbox: Default::default(),
            mailbox_meta: RAM::new(word_map((0..64).map(|_| Bits::<8>::from(0u64)))),
            running: Default::default(),
            epoch: Default::default(),
            ready: Default::default(),
            asleep: Default::default(),
            woken: Default::default(),
            last_pick: Default::default(),
            below: Default::default(),
            pick: Default::default(),
            issue: Default::default(),
            issue_mask: Default::default(),
            wb_mask: Default::default(),
            tester_event: Default::default(),
            walk_event: Default::default(),
            event_mask: Default::default(),
            wb_sleep: Default::default(),
            wake_mask: Default::default(),
            sleep_mask: Default::default(),
            halted_count: Default::default(),
            cycle_count: Default::default(),
            instr_count: Default::default(),
            transform_count: Default::default(),
            intersect_count: Default::default(),
            traversal_count: Default::default(),
            px: Default::default(),
            py: Default::default(),
            v1: Default::default(),
            t1: Default::default(),
            v2: Default::default(),
            t2: Default::default(),
            pc2: Default::default(),
            pc1_eff: Default::default(),
            entry_fresh: Default::default(),
            v3: Default::default(),
            t3: Default::default(),
            pc3: Default::default(),
            ctl3: Default::default(),
            imm3: Default::default(),
            aux3: Default::default(),
            op3: Default::default(),
            opa: Default::default(),
            opb: Default::default(),
            shifted: Default::default(),
            mem_address: Default::default(),
            scratch_address: Default::default(),
            fast: Default::default(),
            int_eq: Default::default(),
            int_lt: Default::default(),
            mb_hit: Default::default(),
            mb_len: Default::default(),
            mb_next: Default::default(),
            pix_done: Default::default(),
            tri_cond: Default::default(),
            wait_fn: Default::default(),
            kd_cond: Default::default(),
            fast_kind: Default::default(),
            tri_queues: Default::default(),
            tri_kind: Default::default(),
            mem_read_r: Default::default(),
            mem_bank_r: Default::default(),
            mem_addr_r: Default::default(),
            fb_write_r: Default::default(),
            fb_addr_r: Default::default(),
            fb_data_r: Default::default(),
            add: Default::default(),
            mul: Default::default(),
            div: Default::default(),
            sqrt: Default::default(),
            cmp: Default::default(),
            itof: Default::default(),
            byte_unit: Default::default(),
            tester: TriangleTester::new(mem_latency),
            traversal_unit: TraversalUnit::new(mem_latency),
            add_delay: Default::default(),
            mul_delay: Default::default(),
            div_delay: Default::default(),
            sqrt_delay: Default::default(),
            cmp_delay: Default::default(),
            fast_line: Default::default(),
            fast_kind_line: Default::default(),
            fast_delay: Default::default(),
            ctl_delay: Default::default(),
            ctl_line: Default::default(),
            pc_delay: Default::default(),
            pc_line: Default::default(),
            cond_delay: Default::default(),
            cond_line: Default::default(),
            long_ctl: Default::default(),
            long_pc: Default::default(),
            short_ctl: Default::default(),
            long_in: Default::default(),
            wb_ctl: Default::default(),
            wb_pcs: Default::default(),
            reserved: Default::default(),
            long3: Default::default(),
            wb_valid: Default::default(),
            wb_op: Default::default(),
            wb_dst: Default::default(),
            wb_thread: Default::default(),
            wb_invert: Default::default(),
            wb_cond: Default::default(),
            wb_next_pc: Default::default(),
            wb_result: Default::default(),
            wb_writes: Default::default(),
            c_threads: Constant::new(u64::from(threads).into()),
            c_thread_mask: Constant::new(((1u64 << threads) - 1).into()),
            c_one: Constant::new(1u64.into()),
            c_ones: Constant::new(0xffff_ffffu64.into()),
            c_thread_ids: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_width: Constant::new(u64::from(program.config.width).into()),
            c_height: Constant::new(u64::from(program.config.height).into()),
            c_pixel_shift: Constant::new(u64::from(program.config.pixel_shift()).into()),
            c_mem_latency: Constant::new(u64::from(mem_latency).into()),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_reserve_bit: Constant::new(((DX - 4) as u64).into()),
            op_fadd: op_code(Op::FAdd),
            op_fsub: op_code(Op::FSub),
            op_fmul: op_code(Op::FMul),
            op_fdiv: op_code(Op::FDiv),
            op_fsqrt: op_code(Op::FSqrt),
            op_itof: op_code(Op::IToF),
            op_add: op_code(Op::Add),
            op_sub: op_code(Op::Sub),
            op_and: op_code(Op::And),
            op_or: op_code(Op::Or),
            op_xor: op_code(Op::Xor),
            op_shr: op_code(Op::Shr),
            op_shl: op_code(Op::Shl),
            op_ld: op_code(Op::Ld),
            op_st: op_code(Op::St),
            op_lds: op_code(Op::Lds),
            op_sts: op_code(Op::Sts),
            op_bflt: op_code(Op::BFlt),
            op_bfle: op_code(Op::BFle),
            op_bfeq: op_code(Op::BFeq),
            op_beq: op_code(Op::Beq),
            op_bltu: op_code(Op::Bltu),
            op_jal: op_code(Op::Jal),
            op_jr: op_code(Op::Jr),
            op_mbx: op_code(Op::Mbx),
            op_mbc: op_code(Op::Mbc),
            op_pixel: op_code(Op::Pixel),
            op_halt: op_code(Op::Halt),
            op_tri: op_code(Op::Tri),
            op_kd: op_code(Op::Kd),
            op_byte: op_code(Op::Byte),
            op_writes: Constant::new(
                OPS.iter()
                    .filter(|o| o.writes())
                    .fold(0u64, |m, &o| m | 1 << (o as u64))
                    .into(),
            ),
            tri_ray_words: tri_fn(TriFn::Init),
            tri_init: tri_fn(TriFn::Init),
            tri_list: tri_fn(TriFn::List),
            tri_wait: tri_fn(TriFn::Wait),
            tri_hit: tri_fn(TriFn::Hit),
            tri_instance: tri_fn(TriFn::Instance),
            tri_triangle: tri_fn(TriFn::Triangle),
            tri_object: tri_fn(TriFn::Object),
            tri_skip: tri_fn(TriFn::Skip),
            kd_start: kd_fn(KdFn::Start),
            kd_wait: kd_fn(KdFn::Wait),
            cmd_list: cmd(list_unit::CMD_LIST),
            cmd_init: cmd(list_unit::CMD_INIT),
            cmd_object: cmd(list_unit::CMD_OBJECT),
            cmd_skip: cmd(list_unit::CMD_SKIP),
            bank_nodes: bank(layout::NODES),
            bank_lists: bank(layout::LISTS),
            bank_uv: bank(layout::TRIANGLES_UV),
            bank_t: bank(layout::TRIANGLES_T),
            f_op: field(isa::CTL_OP),
            f_dst: field(isa::CTL_DST),
            f_a: field(isa::CTL_A),
            f_b: field(isa::CTL_B),
            f_b_imm: field(isa::CTL_B_IMM),
            f_invert: field(isa::CTL_INVERT),
            f_shift: field(isa::AUX_SHIFT),
            f_bank: field(isa::AUX_BANK),
            f_target: field(isa::AUX_TARGET),
        }
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
        const DX: usize,
        const DL: usize,
    > Logic for ThreadEngine<W, E, M, S, S1, X2, T, P, DX, DL>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            running,
            epoch,
            ready,
            asleep,
            woken,
            last_pick,
            halted_count,
            cycle_count,
            instr_count,
            transform_count,
            intersect_count,
            traversal_count,
            px,
            py,
            v1,
            t1,
            v2,
            t2,
            pc2,
            v3,
            t3,
            pc3,
            ctl3,
            imm3,
            aux3,
            mem_read_r,
            mem_bank_r,
            mem_addr_r,
            fb_write_r,
            fb_addr_r,
            fb_data_r,
            reserved
        );
        clock!(
            self,
            clock,
            add,
            mul,
            div,
            sqrt,
            cmp,
            byte_unit,
            add_delay,
            mul_delay,
            div_delay,
            sqrt_delay,
            cmp_delay,
            fast_delay,
            ctl_delay,
            pc_delay,
            cond_delay,
            long_ctl,
            long_pc,
            tester,
            traversal_unit
        );
        self.pc_ram.read_clock.next = self.clock.val();
        self.pc_ram.write_clock.next = self.clock.val();
        self.rom_ctl.read_clock.next = self.clock.val();
        self.rom_ctl.write_clock.next = self.clock.val();
        self.rom_imm.read_clock.next = self.clock.val();
        self.rom_imm.write_clock.next = self.clock.val();
        self.rom_aux.read_clock.next = self.clock.val();
        self.rom_aux.write_clock.next = self.clock.val();
        self.regs_a.read_clock.next = self.clock.val();
        self.regs_a.write_clock.next = self.clock.val();
        self.regs_b.read_clock.next = self.clock.val();
        self.regs_b.write_clock.next = self.clock.val();
        self.scratch.read_clock.next = self.clock.val();
        self.scratch.write_clock.next = self.clock.val();
        self.mailbox_meta.read_clock.next = self.clock.val();
        self.mailbox_meta.write_clock.next = self.clock.val();
        for k in 0..8 {
            self.mailbox[k].read_clock.next = self.clock.val();
            self.mailbox[k].write_clock.next = self.clock.val();
        }
        for k in 0..8 {
            self.fast_line[k].clock.next = self.clock.val();
            self.fast_kind_line[k].clock.next = self.clock.val();
            self.ctl_line[k].clock.next = self.clock.val();
            self.pc_line[k].clock.next = self.clock.val();
            self.cond_line[k].clock.next = self.clock.val();
        }
        // The ROMs are never written.
        self.rom_ctl.write_enable.next = false;
        self.rom_imm.write_enable.next = false;
        self.rom_aux.write_enable.next = false;
        self.rom_ctl.write_address.next = 0.into();
        self.rom_imm.write_address.next = 0.into();
        self.rom_aux.write_address.next = 0.into();
        self.rom_ctl.write_data.next = 0.into();
        self.rom_imm.write_data.next = 0.into();
        self.rom_aux.write_data.next = 0.into();

        // Frame control and counters.
        self.done.next =
            (!self.running.q.val()) & (self.halted_count.q.val() == self.c_threads.val());
        self.cycles.next = self.cycle_count.q.val();
        self.instructions.next = self.instr_count.q.val();
        self.transform_busy.next = self.transform_count.q.val();
        self.intersect_busy.next = self.intersect_count.q.val();
        self.traversal_busy.next = self.traversal_count.q.val();
        if self.running.q.val() {
            self.cycle_count.d.next = self.cycle_count.q.val() + 1;
            if self.tester.transform_busy.val() {
                self.transform_count.d.next = self.transform_count.q.val() + 1;
            }
            if self.tester.intersect_busy.val() {
                self.intersect_count.d.next = self.intersect_count.q.val() + 1;
            }
            if self.traversal_unit.step_busy.val() {
                self.traversal_count.d.next = self.traversal_count.q.val() + 1;
            }
        }

        // I0: pick a ready thread, round robin (the highest below the last pick, else the
        // highest), and read its state.
        self.below.next = self.ready.q.val() & (!(self.c_ones.val() << self.last_pick.q.val()));
        self.pick.next = 0.into();
        for k in 0..32 {
            if self.ready.q.val().get_bit(k) {
                self.pick.next = self.c_thread_ids[k].val();
            }
        }
        for k in 0..32 {
            if self.below.val().get_bit(k) {
                self.pick.next = self.c_thread_ids[k].val();
            }
        }
        self.issue.next =
            self.running.q.val() & (self.ready.q.val() != 0) & (!self.reserved.q.val().get_bit(0));
        self.issue_mask.next = 0.into();
        if self.issue.val() {
            self.issue_mask.next = self.c_one.val() << self.pick.val();
            self.last_pick.d.next = self.pick.val();
        }
        self.pc_ram.read_address.next = self.pick.val();
        self.v1.d.next = self.issue.val();
        self.t1.d.next = self.pick.val();

        // I1: `{epoch, halted, pc}`; another epoch is a thread of an earlier frame: pc 0.
        self.entry_fresh.next = self.pc_ram.read_data.val().get_bit(13) != self.epoch.q.val();
        if self.entry_fresh.val() {
            self.pc1_eff.next = 0.into();
        } else {
            self.pc1_eff.next = self.pc_ram.read_data.val().get_bits::<12>(0);
        }
        self.rom_ctl.read_address.next = self.pc1_eff.val();
        self.rom_imm.read_address.next = self.pc1_eff.val();
        self.rom_aux.read_address.next = self.pc1_eff.val();
        self.v2.d.next =
            self.v1.q.val() & (self.entry_fresh.val() | (!self.pc_ram.read_data.val().get_bit(12)));
        self.t2.d.next = self.t1.q.val();
        self.pc2.d.next = self.pc1_eff.val();

        // I2: decode, read the registers and the mailbox.
        self.regs_a.read_address.next = (bit_cast::<13, 5>(self.t2.q.val()) << 8)
            | bit_cast::<13, 8>(
                self.rom_ctl
                    .read_data
                    .val()
                    .get_bits::<REG_BITS>(self.f_a.val().index()),
            );
        self.regs_b.read_address.next = (bit_cast::<13, 5>(self.t2.q.val()) << 8)
            | bit_cast::<13, 8>(
                self.rom_ctl
                    .read_data
                    .val()
                    .get_bits::<REG_BITS>(self.f_b.val().index()),
            );
        self.mailbox_meta.read_address.next = (bit_cast::<6, 5>(self.t2.q.val()) << 1)
            | bit_cast::<6, 1>(self.rom_imm.read_data.val().get_bits::<1>(0));
        for k in 0..8 {
            self.mailbox[k].read_address.next = (bit_cast::<6, 5>(self.t2.q.val()) << 1)
                | bit_cast::<6, 1>(self.rom_imm.read_data.val().get_bits::<1>(0));
        }
        self.tester.query_thread.next = self.t2.q.val();
        self.traversal_unit.query_thread.next = self.t2.q.val();
        self.v3.d.next = self.v2.q.val();
        self.t3.d.next = self.t2.q.val();
        self.pc3.d.next = self.pc2.q.val();
        self.ctl3.d.next = self.rom_ctl.read_data.val();
        self.imm3.d.next = self.rom_imm.read_data.val();
        self.aux3.d.next = self.rom_aux.read_data.val();

        // I3: operands (r0 always reads 0).
        self.op3.next = self
            .ctl3
            .q
            .val()
            .get_bits::<OP_BITS>(self.f_op.val().index());
        if self
            .ctl3
            .q
            .val()
            .get_bits::<REG_BITS>(self.f_a.val().index())
            == 0
        {
            self.opa.next = 0.into();
        } else {
            self.opa.next = self.regs_a.read_data.val();
        }
        if self.ctl3.q.val().get_bit(self.f_b_imm.val().index()) {
            self.opb.next = self.imm3.q.val();
        } else if self
            .ctl3
            .q
            .val()
            .get_bits::<REG_BITS>(self.f_b.val().index())
            == 0
        {
            self.opb.next = 0.into();
        } else {
            self.opb.next = self.regs_b.read_data.val();
        }

        // Floating-point units: every clock, whether used or not.
        self.add.a.next = self.opa.val().get_bits::<W>(0);
        self.add.b.next = self.opb.val().get_bits::<W>(0);
        self.add.sub.next = self.op3.val() == self.op_fsub.val();
        self.add.in_valid.next = true;
        self.mul.a.next = self.opa.val().get_bits::<W>(0);
        self.mul.b.next = self.opb.val().get_bits::<W>(0);
        self.mul.in_valid.next = true;
        self.div.a.next = self.opa.val().get_bits::<W>(0);
        self.div.b.next = self.opb.val().get_bits::<W>(0);
        self.div.in_valid.next = true;
        self.sqrt.a.next = self.opa.val().get_bits::<W>(0);
        self.sqrt.in_valid.next = true;
        self.cmp.a.next = self.opa.val().get_bits::<W>(0);
        self.cmp.b.next = self.opb.val().get_bits::<W>(0);
        self.cmp.in_valid.next = true;
        self.itof.value.next = self.opa.val().get_bits::<16>(0);
        self.byte_unit.word.next = self.opa.val().get_bits::<W>(0);
        self.byte_unit.in_valid.next = true;
        // A long instruction at I3 reserves its write-back clock: no issue `DX - 3` clocks
        // from now, whose instruction would write back with it.
        self.long3.next = self.v3.q.val()
            & ((self.op3.val() == self.op_fdiv.val()) | (self.op3.val() == self.op_fsqrt.val()));
        self.reserved.d.next = (self.reserved.q.val() >> 1)
            | (bit_cast::<32, 1>(self.long3.val().into()) << self.c_reserve_bit.val());
        self.add_delay.data_in.next = self.add.result.val();
        self.mul_delay.data_in.next = self.mul.result.val();
        self.div_delay.data_in.next = self.div.result.val();
        self.sqrt_delay.data_in.next = self.sqrt.result.val();
        self.cmp_delay.data_in.next = (bit_cast::<3, 1>(self.cmp.lt.val().into()) << 2)
            | (bit_cast::<3, 1>(self.cmp.le.val().into()) << 1)
            | bit_cast::<3, 1>(self.cmp.eq.val().into());

        // Integer conditions, addresses.
        self.int_eq.next = self.opa.val() == self.opb.val();
        self.int_lt.next = self.opa.val() < self.opb.val();
        self.shifted.next = self.opa.val()
            << self
                .aux3
                .q
                .val()
                .get_bits::<SHIFT_BITS>(self.f_shift.val().index());
        self.mem_address.next = self.shifted.val() + self.imm3.q.val();
        self.scratch_address.next = self.opa.val() + self.imm3.q.val();

        // Mailbox: hit when A is one of the first `len` entries.
        self.mb_len.next = self.mailbox_meta.read_data.val().get_bits::<4>(0);
        self.mb_next.next = self.mailbox_meta.read_data.val().get_bits::<3>(4);
        self.mb_hit.next = false;
        for k in 0..8 {
            if (self.mailbox[k].read_data.val() == self.opa.val())
                & (bit_cast::<8, 4>(self.mb_len.val()) > self.c_index[k].val())
            {
                self.mb_hit.next = true;
            }
        }
        self.mailbox_meta.write_address.next = (bit_cast::<6, 5>(self.t3.q.val()) << 1)
            | bit_cast::<6, 1>(self.imm3.q.val().get_bits::<1>(0));
        self.mailbox_meta.write_enable.next = false;
        self.mailbox_meta.write_data.next = 0.into();
        for k in 0..8 {
            self.mailbox[k].write_address.next = (bit_cast::<6, 5>(self.t3.q.val()) << 1)
                | bit_cast::<6, 1>(self.imm3.q.val().get_bits::<1>(0));
            self.mailbox[k].write_data.next = self.opa.val();
            self.mailbox[k].write_enable.next = false;
        }
        if self.v3.q.val() & (self.op3.val() == self.op_mbc.val()) {
            self.mailbox_meta.write_enable.next = true;
        }
        if self.v3.q.val() & (self.op3.val() == self.op_mbx.val()) & (!self.mb_hit.val()) {
            self.mailbox_meta.write_enable.next = true;
            if self.mb_len.val() == 8 {
                self.mailbox_meta.write_data.next =
                    (bit_cast::<8, 3>(self.mb_next.val() + 1) << 4) | (self.c_index[7].val() + 1);
            } else {
                self.mailbox_meta.write_data.next = (bit_cast::<8, 3>(self.mb_next.val() + 1) << 4)
                    | bit_cast::<8, 4>(self.mb_len.val() + 1);
            }
            for k in 0..8 {
                if bit_cast::<8, 3>(self.mb_next.val()) == self.c_index[k].val() {
                    self.mailbox[k].write_enable.next = true;
                }
            }
        }

        // Pixel counter.
        self.pix_done.next = !(self.py.q.val() < self.c_height.val());
        if self.running.q.val()
            & self.v3.q.val()
            & (self.op3.val() == self.op_pixel.val())
            & (!self.pix_done.val())
        {
            if (self.px.q.val() + 1) == self.c_width.val() {
                self.px.d.next = 0.into();
                self.py.d.next = self.py.q.val() + 1;
            } else {
                self.px.d.next = self.px.q.val() + 1;
            }
        }

        // Scratch memory.
        self.scratch.read_address.next = (bit_cast::<12, 5>(self.t3.q.val()) << 7)
            | bit_cast::<12, 7>(self.scratch_address.val().get_bits::<7>(0));
        self.scratch.write_address.next = (bit_cast::<12, 5>(self.t3.q.val()) << 7)
            | bit_cast::<12, 7>(self.scratch_address.val().get_bits::<7>(0));
        self.scratch.write_data.next = self.regs_b.read_data.val();
        self.scratch.write_enable.next = self.v3.q.val() & (self.op3.val() == self.op_sts.val());

        // Memory and frame-buffer ports (registered).
        self.mem_read_r.d.next = self.v3.q.val() & (self.op3.val() == self.op_ld.val());
        self.mem_bank_r.d.next = self
            .aux3
            .q
            .val()
            .get_bits::<BANK_BITS>(self.f_bank.val().index());
        self.mem_addr_r.d.next = self.mem_address.val().get_bits::<24>(0);
        self.fb_write_r.d.next = self.v3.q.val() & (self.op3.val() == self.op_st.val());
        self.fb_addr_r.d.next = self.mem_address.val().get_bits::<24>(0);
        self.fb_data_r.d.next = self.regs_b.read_data.val();
        // Bank 0 goes through the traversal unit's port, banks 2 and 3 through the triangle
        // tester's; the tester's list reads (bank 1) use this bus when the engine does not.
        self.mem_read.next = (self.mem_read_r.q.val()
            & (self.mem_bank_r.q.val() != self.bank_nodes.val())
            & (self.mem_bank_r.q.val() != self.bank_uv.val())
            & (self.mem_bank_r.q.val() != self.bank_t.val()))
            | self.tester.list_read.val();
        self.traversal_unit.engine_read.next = self.mem_read_r.q.val();
        self.traversal_unit.engine_bank.next = self.mem_bank_r.q.val();
        self.traversal_unit.engine_addr.next = self.mem_addr_r.q.val();
        self.bank0_read.next = self.traversal_unit.node_read.val();
        self.bank0_addr.next = self.traversal_unit.node_addr.val();
        self.traversal_unit.node_rdata.next = self.bank0_rdata.val();
        self.mem_bank.next = self.mem_bank_r.q.val();
        self.mem_addr.next = self.mem_addr_r.q.val();
        if self.tester.list_read.val() {
            self.mem_bank.next = self.bank_lists.val();
            self.mem_addr.next = self.tester.list_addr.val();
        }
        self.tester.list_rdata.next = self.mem_rdata.val();
        self.tester.engine_read.next = self.mem_read_r.q.val();
        self.tester.engine_bank.next = self.mem_bank_r.q.val();
        self.tester.engine_addr.next = self.mem_addr_r.q.val();
        self.bank2_read.next = self.tester.uv_read.val();
        self.bank2_addr.next = self.tester.uv_addr.val();
        self.tester.uv_rdata.next = self.bank2_rdata.val();
        self.bank3_read.next = self.tester.t_read.val();
        self.bank3_addr.next = self.tester.t_addr.val();
        self.tester.t_rdata.next = self.bank3_rdata.val();

        // Triangle tester (`tri`, its `TriFn` in imm); the queued functions go to the list
        // unit as its command kinds.
        self.tester.thread.next = self.t3.q.val();
        self.tester.word_a.next = self.opa.val();
        self.tester.word_b.next = self.opb.val();
        self.tester.ray_pair.next = self.imm3.q.val().get_bits::<2>(0);
        self.tester.ray_write.next = self.v3.q.val()
            & (self.op3.val() == self.op_tri.val())
            & (self.imm3.q.val() < self.tri_ray_words.val());
        self.tri_queues.next = (self.imm3.q.val() == self.tri_init.val())
            | (self.imm3.q.val() == self.tri_list.val())
            | (self.imm3.q.val() == self.tri_object.val())
            | (self.imm3.q.val() == self.tri_skip.val());
        self.tester.enqueue.next =
            self.v3.q.val() & (self.op3.val() == self.op_tri.val()) & self.tri_queues.val();
        // The kind is settled in a local signal and given to the tester in one assignment: a
        // default overridden on the tester's input itself would glitch it, the tester's
        // outputs feed back here, and Icarus would loop forever.
        self.tri_kind.next = self.cmd_list.val();
        if self.imm3.q.val() == self.tri_init.val() {
            self.tri_kind.next = self.cmd_init.val();
        }
        if self.imm3.q.val() == self.tri_object.val() {
            self.tri_kind.next = self.cmd_object.val();
        }
        if self.imm3.q.val() == self.tri_skip.val() {
            self.tri_kind.next = self.cmd_skip.val();
        }
        self.tester.queue_kind.next = self.tri_kind.val();
        self.tri_cond.next = false;
        if self.tri_queues.val() {
            self.tri_cond.next = self.tester.full.val();
        }
        if self.imm3.q.val() == self.tri_wait.val() {
            self.tri_cond.next = self.tester.pending.val();
        }
        // Traversal unit (`kd`, its `KdFn` in imm). It sees the object-space ray and t_min the
        // thread gives the tester.
        // The traversal unit hands its leaves to the tester, the tester its answers back.
        self.tester.walk_list_valid.next = self.traversal_unit.leaf_valid.val();
        self.tester.walk_list_thread.next = self.traversal_unit.leaf_thread.val();
        self.tester.walk_list_from.next = self.traversal_unit.leaf_from.val();
        self.tester.walk_list_to.next = self.traversal_unit.leaf_to.val();
        self.traversal_unit.leaf_take.next = self.tester.walk_list_take.val();
        self.traversal_unit.answer_valid.next = self.tester.walk_end_event.val();
        self.traversal_unit.answer_thread.next = self.tester.walk_end_thread.val();
        self.traversal_unit.answer_t.next = self.tester.walk_end_t.val();
        self.traversal_unit.answer_hit.next = self.tester.walk_end_hit.val();
        self.traversal_unit.thread.next = self.t3.q.val();
        self.traversal_unit.word_a.next = self.opa.val();
        self.traversal_unit.word_b.next = self.opb.val();
        self.traversal_unit.ray_pair.next = self.imm3.q.val().get_bits::<2>(0);
        self.traversal_unit.ray_write.next = self.v3.q.val()
            & (self.op3.val() == self.op_tri.val())
            & (self.imm3.q.val() < self.tri_ray_words.val());
        self.traversal_unit.t_min_write.next = self.v3.q.val()
            & (self.op3.val() == self.op_tri.val())
            & (self.imm3.q.val() == self.tri_init.val());
        self.traversal_unit.enqueue.next = self.v3.q.val()
            & (self.op3.val() == self.op_kd.val())
            & (self.imm3.q.val() == self.kd_start.val());
        self.kd_cond.next = self.traversal_unit.full.val();
        if self.imm3.q.val() == self.kd_wait.val() {
            self.kd_cond.next = self.traversal_unit.pending.val();
        }
        // The waits (`tri.wait`, `kd.wait`): a pending one sleeps instead of repeating.
        self.wait_fn.next = ((self.op3.val() == self.op_tri.val())
            & (self.imm3.q.val() == self.tri_wait.val()))
            | ((self.op3.val() == self.op_kd.val()) & (self.imm3.q.val() == self.kd_wait.val()));
        self.fb_write.next = self.fb_write_r.q.val();
        self.fb_addr.next = self.fb_addr_r.q.val();
        self.fb_data.next = self.fb_data_r.q.val();

        // The fast result (integer, conversion, link, pixel; loads fill in later).
        self.fast_kind.next = FastKind::Computed;
        self.fast.next = 0.into();
        if self.op3.val() == self.op_itof.val() {
            self.fast.next = bit_cast::<32, W>(self.itof.word.val());
        }
        if self.op3.val() == self.op_add.val() {
            self.fast.next = self.opa.val() + self.opb.val();
        }
        if self.op3.val() == self.op_sub.val() {
            self.fast.next = self.opa.val() - self.opb.val();
        }
        if self.op3.val() == self.op_and.val() {
            self.fast.next = self.opa.val() & self.opb.val();
        }
        if self.op3.val() == self.op_or.val() {
            self.fast.next = self.opa.val() | self.opb.val();
        }
        if self.op3.val() == self.op_xor.val() {
            self.fast.next = self.opa.val() ^ self.opb.val();
        }
        if self.op3.val() == self.op_shr.val() {
            self.fast.next = self.opa.val() >> self.opb.val().get_bits::<5>(0);
        }
        if self.op3.val() == self.op_shl.val() {
            self.fast.next = self.opa.val() << self.opb.val().get_bits::<5>(0);
        }
        if self.op3.val() == self.op_ld.val() {
            self.fast_kind.next = FastKind::Memory;
            if self
                .aux3
                .q
                .val()
                .get_bits::<BANK_BITS>(self.f_bank.val().index())
                == self.bank_uv.val()
            {
                self.fast_kind.next = FastKind::TrianglesUv;
            }
            if self
                .aux3
                .q
                .val()
                .get_bits::<BANK_BITS>(self.f_bank.val().index())
                == self.bank_t.val()
            {
                self.fast_kind.next = FastKind::TrianglesT;
            }
            if self
                .aux3
                .q
                .val()
                .get_bits::<BANK_BITS>(self.f_bank.val().index())
                == self.bank_nodes.val()
            {
                self.fast_kind.next = FastKind::Nodes;
            }
        }
        if self.op3.val() == self.op_lds.val() {
            self.fast_kind.next = FastKind::Scratch;
        }
        if self.op3.val() == self.op_jal.val() {
            self.fast.next = bit_cast::<32, 12>(self.pc3.q.val() + 1);
        }
        if self.op3.val() == self.op_byte.val() {
            self.fast.next = self.opb.val() << 8;
        }
        if self.op3.val() == self.op_pixel.val() {
            self.fast.next = (bit_cast::<32, 16>(self.py.q.val()) << self.c_pixel_shift.val())
                | bit_cast::<32, 16>(self.px.q.val());
        }
        if self.op3.val() == self.op_tri.val() {
            if self.imm3.q.val() == self.tri_wait.val() {
                self.fast.next = bit_cast::<32, W>(self.tester.best_t.val());
            }
            if self.imm3.q.val() == self.tri_hit.val() {
                self.fast.next = bit_cast::<32, 1>(self.tester.hit.val().into());
            }
            if self.imm3.q.val() == self.tri_instance.val() {
                self.fast.next = self.tester.best_instance.val();
            }
            if self.imm3.q.val() == self.tri_triangle.val() {
                self.fast.next = self.tester.best_triangle.val();
            }
        }

        // The fast line: scratch data at I4, memory data at I4 + latency.
        self.fast_line[0].d.next = self.fast.val();
        self.fast_kind_line[0].d.next = self.fast_kind.val();
        self.ctl_line[0].d.next = (bit_cast::<21, 1>(self.v3.q.val().into()) << 20)
            | (bit_cast::<21, 5>(self.op3.val()) << 15)
            | (bit_cast::<21, 8>(
                self.ctl3
                    .q
                    .val()
                    .get_bits::<REG_BITS>(self.f_dst.val().index()),
            ) << 7)
            | (bit_cast::<21, 5>(self.t3.q.val()) << 2)
            | bit_cast::<21, 1>(self.ctl3.q.val().get_bits::<1>(self.f_invert.val().index()));
        self.pc_line[0].d.next = (bit_cast::<24, 12>(self.pc3.q.val() + 1) << 12)
            | bit_cast::<24, 12>(
                self.aux3
                    .q
                    .val()
                    .get_bits::<PC_BITS>(self.f_target.val().index()),
            );
        self.cond_line[0].d.next = (bit_cast::<19, 1>(self.wait_fn.val().into()) << 18)
            | (bit_cast::<19, 1>(self.kd_cond.val().into()) << 17)
            | (bit_cast::<19, 1>(self.tri_cond.val().into()) << 16)
            | (bit_cast::<19, 12>(self.opa.val().get_bits::<12>(0)) << 4)
            | (bit_cast::<19, 1>(self.int_eq.val().into()) << 3)
            | (bit_cast::<19, 1>(self.int_lt.val().into()) << 2)
            | (bit_cast::<19, 1>(self.mb_hit.val().into()) << 1)
            | bit_cast::<19, 1>(self.pix_done.val().into());
        for k in 1..8 {
            self.fast_line[k].d.next = self.fast_line[k - 1].q.val();
            self.fast_kind_line[k].d.next = self.fast_kind_line[k - 1].q.val();
            self.ctl_line[k].d.next = self.ctl_line[k - 1].q.val();
            self.pc_line[k].d.next = self.pc_line[k - 1].q.val();
            self.cond_line[k].d.next = self.cond_line[k - 1].q.val();
        }
        if self.fast_kind_line[0].q.val() == FastKind::Scratch {
            self.fast_line[1].d.next = self.scratch.read_data.val();
        }
        for k in 1..7 {
            if self.c_mem_latency.val() == self.c_index[k].val() {
                if self.fast_kind_line[k].q.val() == FastKind::Memory {
                    self.fast_line[k + 1].d.next = self.mem_rdata.val();
                }
                if self.fast_kind_line[k].q.val() == FastKind::TrianglesUv {
                    self.fast_line[k + 1].d.next = self.bank2_rdata.val();
                }
                if self.fast_kind_line[k].q.val() == FastKind::TrianglesT {
                    self.fast_line[k + 1].d.next = self.bank3_rdata.val();
                }
                if self.fast_kind_line[k].q.val() == FastKind::Nodes {
                    self.fast_line[k + 1].d.next = self.bank0_rdata.val();
                }
            }
        }
        self.fast_delay.data_in.next = self.fast_line[7].q.val();
        self.ctl_delay.data_in.next = self.ctl_line[7].q.val();
        self.pc_delay.data_in.next = self.pc_line[7].q.val();
        self.cond_delay.data_in.next = self.cond_line[7].q.val();

        // Write back: `fdiv` and `fsqrt` go on into the long line and write back from there
        // (the reservation keeps this clock's other write back empty).
        self.short_ctl.next = self.ctl_delay.data_out.val();
        self.long_in.next = 0.into();
        if (self.ctl_delay.data_out.val().get_bits::<5>(15) == self.op_fdiv.val())
            | (self.ctl_delay.data_out.val().get_bits::<5>(15) == self.op_fsqrt.val())
        {
            self.short_ctl.next = 0.into();
            self.long_in.next = self.ctl_delay.data_out.val();
        }
        self.long_ctl.data_in.next = self.long_in.val();
        self.long_pc.data_in.next = self.pc_delay.data_out.val();
        self.wb_ctl.next = self.short_ctl.val();
        self.wb_pcs.next = self.pc_delay.data_out.val();
        if self.long_ctl.data_out.val().get_bit(20) {
            self.wb_ctl.next = self.long_ctl.data_out.val();
            self.wb_pcs.next = self.long_pc.data_out.val();
        }
        self.wb_valid.next = self.wb_ctl.val().get_bit(20);
        self.wb_op.next = self.wb_ctl.val().get_bits::<5>(15);
        self.wb_dst.next = self.wb_ctl.val().get_bits::<8>(7);
        self.wb_thread.next = self.wb_ctl.val().get_bits::<5>(2);
        self.wb_invert.next = self.wb_ctl.val().get_bit(0);
        self.wb_cond.next = false;
        if self.wb_op.val() == self.op_bflt.val() {
            self.wb_cond.next = self.cmp_delay.data_out.val().get_bit(2);
        }
        if self.wb_op.val() == self.op_bfle.val() {
            self.wb_cond.next = self.cmp_delay.data_out.val().get_bit(1);
        }
        if self.wb_op.val() == self.op_bfeq.val() {
            self.wb_cond.next = self.cmp_delay.data_out.val().get_bit(0);
        }
        if self.wb_op.val() == self.op_beq.val() {
            self.wb_cond.next = self.cond_delay.data_out.val().get_bit(3);
        }
        if self.wb_op.val() == self.op_bltu.val() {
            self.wb_cond.next = self.cond_delay.data_out.val().get_bit(2);
        }
        if self.wb_op.val() == self.op_mbx.val() {
            self.wb_cond.next = self.cond_delay.data_out.val().get_bit(1);
        }
        if self.wb_op.val() == self.op_pixel.val() {
            self.wb_cond.next = self.cond_delay.data_out.val().get_bit(0);
        }
        if self.wb_op.val() == self.op_jal.val() {
            self.wb_cond.next = true;
        }
        if self.wb_op.val() == self.op_tri.val() {
            self.wb_cond.next = self.cond_delay.data_out.val().get_bit(16);
        }
        if self.wb_op.val() == self.op_kd.val() {
            self.wb_cond.next = self.cond_delay.data_out.val().get_bit(17);
        }
        if self.wb_cond.val() != self.wb_invert.val() {
            self.wb_next_pc.next = self.wb_pcs.val().get_bits::<12>(0);
        } else {
            self.wb_next_pc.next = self.wb_pcs.val().get_bits::<12>(12);
        }
        if self.wb_op.val() == self.op_jr.val() {
            self.wb_next_pc.next = self.cond_delay.data_out.val().get_bits::<12>(4);
        }
        if (self.wb_op.val() == self.op_halt.val())
            | (((self.wb_op.val() == self.op_tri.val()) | (self.wb_op.val() == self.op_kd.val()))
                & self.wb_cond.val())
        {
            // A halted thread keeps its pc; so does one whose coprocessor refused its entry
            // (queue full) or has not finished (a wait): it repeats on its next turn.
            self.wb_next_pc.next = self.wb_pcs.val().get_bits::<12>(12) - 1;
        }
        self.wb_result.next = self.fast_delay.data_out.val();
        if (self.wb_op.val() == self.op_fadd.val()) | (self.wb_op.val() == self.op_fsub.val()) {
            self.wb_result.next = bit_cast::<32, W>(self.add_delay.data_out.val());
        }
        if self.wb_op.val() == self.op_fmul.val() {
            self.wb_result.next = bit_cast::<32, W>(self.mul_delay.data_out.val());
        }
        if self.wb_op.val() == self.op_fdiv.val() {
            self.wb_result.next = bit_cast::<32, W>(self.div_delay.data_out.val());
        }
        if self.wb_op.val() == self.op_fsqrt.val() {
            self.wb_result.next = bit_cast::<32, W>(self.sqrt_delay.data_out.val());
        }
        if self.wb_op.val() == self.op_byte.val() {
            self.wb_result.next =
                self.fast_delay.data_out.val() | bit_cast::<32, 8>(self.byte_unit.result.val());
        }
        // The ops that write (`Op::writes`; a coprocessor's reading functions name a `dst`, the
        // others r0); `pixel` not when the frame's pixels are exhausted.
        self.wb_writes.next = self.wb_valid.val()
            & (self.wb_dst.val() != 0)
            & self.op_writes.val().get_bit(self.wb_op.val().index())
            & (!((self.wb_op.val() == self.op_pixel.val())
                & self.cond_delay.data_out.val().get_bit(0)));
        self.regs_a.write_address.next =
            (bit_cast::<13, 5>(self.wb_thread.val()) << 8) | bit_cast::<13, 8>(self.wb_dst.val());
        self.regs_b.write_address.next =
            (bit_cast::<13, 5>(self.wb_thread.val()) << 8) | bit_cast::<13, 8>(self.wb_dst.val());
        self.regs_a.write_data.next = self.wb_result.val();
        self.regs_b.write_data.next = self.wb_result.val();
        self.regs_a.write_enable.next = self.wb_writes.val();
        self.regs_b.write_enable.next = self.wb_writes.val();
        self.pc_ram.write_address.next = self.wb_thread.val();
        self.pc_ram.write_data.next = (bit_cast::<16, 1>(self.epoch.q.val().into()) << 13)
            | (bit_cast::<16, 1>((self.wb_op.val() == self.op_halt.val()).into()) << 12)
            | bit_cast::<16, 12>(self.wb_next_pc.val());
        self.pc_ram.write_enable.next = self.wb_valid.val();
        // Instructions retired: every write back but a turn spent offering again to a full
        // coprocessor queue or waiting for a coprocessor (the twin never repeats those).
        if self.wb_valid.val()
            & (!(((self.wb_op.val() == self.op_tri.val())
                | (self.wb_op.val() == self.op_kd.val()))
                & self.wb_cond.val()))
        {
            self.instr_count.d.next = self.instr_count.q.val() + 1;
        }

        // Scheduler: a written-back thread is ready again, unless it halted or waits for a
        // coprocessor that has not finished its work since the thread issued (it sleeps until the coprocessor does: the `woken` bit catches a finish
        // between the check at I3 and this write back).
        self.wb_mask.next = self.c_one.val() << self.wb_thread.val();
        self.tester_event.next = 0.into();
        if self.tester.done_event.val() {
            self.tester_event.next = self.c_one.val() << self.tester.done_thread.val();
        }
        self.walk_event.next = 0.into();
        if self.traversal_unit.done_event.val() {
            self.walk_event.next = self.c_one.val() << self.traversal_unit.done_thread.val();
        }
        self.event_mask.next = self.tester_event.val() | self.walk_event.val();
        self.wb_sleep.next = self.wb_valid.val()
            & self.wb_cond.val()
            & self.cond_delay.data_out.val().get_bit(18)
            & (((self.woken.q.val() | self.event_mask.val()) & self.wb_mask.val()) == 0);
        self.wake_mask.next = 0.into();
        self.sleep_mask.next = 0.into();
        if self.wb_valid.val() & (self.wb_op.val() != self.op_halt.val()) {
            if self.wb_sleep.val() {
                self.sleep_mask.next = self.wb_mask.val();
            } else {
                self.wake_mask.next = self.wb_mask.val();
            }
        }
        self.ready.d.next = (self.ready.q.val() & (!self.issue_mask.val()))
            | self.wake_mask.val()
            | (self.asleep.q.val() & self.event_mask.val());
        self.asleep.d.next =
            (self.asleep.q.val() & (!self.event_mask.val())) | self.sleep_mask.val();
        self.woken.d.next = (self.woken.q.val() & (!self.issue_mask.val())) | self.event_mask.val();

        if self.wb_valid.val() & (self.wb_op.val() == self.op_halt.val()) {
            self.halted_count.d.next = self.halted_count.q.val() + 1;
            if (self.halted_count.q.val() + 1) == self.c_threads.val() {
                self.running.d.next = false;
            }
        }

        // Start of a frame: a new epoch restarts every thread at pc 0.
        if self.start.val() & (!self.running.q.val()) {
            self.running.d.next = true;
            self.epoch.d.next = !self.epoch.q.val();
            self.ready.d.next = self.c_thread_mask.val();
            self.asleep.d.next = 0.into();
            self.woken.d.next = 0.into();
            self.reserved.d.next = 0.into();
            self.halted_count.d.next = 0.into();
            self.cycle_count.d.next = 0.into();
            self.instr_count.d.next = 0.into();
            self.transform_count.d.next = 0.into();
            self.intersect_count.d.next = 0.into();
            self.traversal_count.d.next = 0.into();
            self.px.d.next = 0.into();
            self.py.d.next = 0.into();
        }
    }
}
