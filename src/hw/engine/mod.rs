//! `ThreadEngine`: the ray thread engine that runs the microprogram (`hw::program`) for up to
//! 32 ray threads, one instruction per clock, on pipelined floating-point units.
//!
//! A scheduler issues one ready thread per clock, round robin. An instruction writes back
//! exactly [`ENGINE_LATENCY`] (9) clocks after its operands are read, `fdiv`, `fsqrt` and
//! `byte` [`long_latency`] (`M + 6`) clocks after, and a thread is ready again only at its write
//! back, so there is no hazard, stall or forwarding logic: memory and unit latency are hidden
//! by the other threads (the paper's 32 threads). A long instruction reserves its write-back
//! clock: the scheduler issues nothing in the one clock whose instruction would write back
//! with it (one bubble per `fdiv`, `fsqrt` or `byte`). A thread issues at most once per
//! `period = OPERAND_STAGE + ENGINE_LATENCY + WAKE_UP` (17) clocks (`engine_period`). A thread
//! whose coprocessor wait (`tri.wait`, `kd.wait`) is still pending sleeps: it is not ready until the coprocessor finishes work for
//! it, so the clocks it waits go to the other threads (an offer to a full queue repeats at
//! once).
//!
//! Pipeline (clock offsets from the issue), one block per stage, each with its own contract:
//! - I0: [`Scheduler`] picks a ready thread.
//! - I0..I3: [`Fetch`] reads the thread's `{epoch, halted, pc}` (a stale epoch means "new
//!   frame": pc 0) and registers the pc, addresses the [`ProgramRom`] at I1 and registers the
//!   instruction's three words at I2.
//! - I3..I5: [`Decode`] reads the two source registers, selects and registers the operands
//!   and splits the fields; at I3 a long instruction reserves its write back; at I4 the
//!   [`MailboxUnit`] reads the thread's mailbox and the coprocessors their state of the
//!   thread.
//! - I5 ([`OPERAND_STAGE`]): [`Execute`] computes the integer result and the addresses,
//!   [`PrimaryRays`] hands out a pixel (and requests its primary ray), [`InstanceRays`] takes
//!   an instance entry (`tri.enter`), a normal (`tri.normal`) or world ray words
//!   (`tri.world`), the mailbox registers
//!   the entries it read (it compares at I6, hits and updates at I7), [`FpUnits`] take their
//!   operands; this block drives the
//!   memory and frame-buffer ports and offers `tri` and `kd` entries to the coprocessors (their
//!   answer, refused or pending, makes the thread repeat the instruction on its next turn, after
//!   a sleep for a wait).
//! - I6..: the [`ResultLine`] decodes the opcode at I6; scratch data joins at I6, the mailbox
//!   hit at I7, memory data at I6 + `mem_latency`.
//! - I5 + 9 (`I5 + M + 6` for `fdiv`, `fsqrt`, `byte`, which go on in the long line): the
//!   [`WriteBack`] chooses, and a clock later writes, the register and the next pc: `target`
//!   when the condition differs from `invert` (a non-branching instruction's condition is
//!   false, so its `invert` is a jump after it), else `pc + 1`; the condition comes from the
//!   compare, integer, mailbox, pixel unit or triangle tester.
//!
//! Golden twin: [`crate::hw::program::exec`] runs the same microprogram instruction by
//! instruction (the engine's twin); its retired-instruction count and every frame equal the
//! engine's (`tests/processor_sim.rs`). The arithmetic of the ray, in both, is the sequences of
//! [`crate::units`].
//!
//! Throughput: one instruction per clock while at least 16 threads are awake; a frame
//! ends when every thread has executed `halt` (`done`). Counters: clocks of the frame,
//! instructions retired, clocks in which the triangle tester's TransformUnit and
//! IntersectUnit took a test's input, and clocks in which ray generation took the
//! TransformUnit.
//! `instructions` counts retired instructions: not the turns a thread spends offering an entry
//! again to a full coprocessor queue or waiting for a coprocessor, so it equals the count of
//! the engine's twin, which never waits.
//!
//! Two coprocessors run beside the engine. The [`TraversalUnit`] walks a thread's object kd
//! tree (a thread starts the walk and sleeps until it ends, instead of 15-23 turns per inner
//! node in microcode); it hands each leaf's list to the [`TriangleTester`], whose list unit
//! reads it and queues its triangles, and which answers the traversal unit with the closest
//! hit. A walk costs the thread two or three turns, whatever its leaves. The unit walks the
//! top-level tree too, waking the thread at each leaf with instances (`kd.wait`, `kd.leaf`
//! read it; `kd.next` goes on). [`PrimaryRays`] sends each
//! pixel's primary ray through the tester's TransformUnit, in the clocks the tests leave it
//! free, and writes the ray into both coprocessors (a `pixel`, then a `tri.wait`);
//! [`InstanceRays`] does the same for the world ray entering an instance (a `tri.enter`, whose
//! ray write starts the traversal unit's walk of the object; then a `kd.wait`), after ray
//! generation's requests, with the instance's matrix and object root read from bank 4 in the
//! clocks the engine's and the list unit's reads leave the `mem_*` bus free (the root goes to
//! the traversal unit), and for a hit's normal through the instance's normal matrix (a
//! `tri.normal`, then a `tri.wait` and `tri.dir`).
//!
//! Memory: one read per clock on the `mem_*` port (banks 0, 1, 4, 5; the tester's list reads
//! of bank 1 use it in the clocks the engine leaves free, instance entry's reads of bank 4 in
//! the clocks both leave free) and on each of the
//! `bank2_*` and `bank3_*` ports (the triangles; the tester fetches from both at once, the
//! engine's loads of these banks go there too, first); a word must arrive exactly
//! `mem_latency` clocks after its request (1..=6). Frame-buffer writes come out on `fb_*`.

use rust_hdl::prelude::*;

use super::fp::add_sub::ADD_SUB_LATENCY;
use super::list_unit;
use super::ports::{BankedSramRead, FrameBufferWrite, SramRead, SHARED_BUS_BANKS};
use super::processor::ProcessorParams;
use super::program::isa::{KdFn, Op, TriFn, Unit, PC_BITS};
use super::program::Program;
use super::shade_unit::ShadeConfig;
use super::{ShadeUnit, TraversalUnit, TriangleTester};
use crate::layout;

mod decode;
mod execute;
mod fetch;
mod first_ready;
mod fp_units;
mod instance_rays;
mod mailbox;
mod primary_rays;
mod program_rom;
mod result_line;
mod retiring;
mod scheduler;
mod write_back;

pub use decode::Decode;
pub use execute::Execute;
pub use fetch::{Fetch, FETCH_LATENCY};
pub use first_ready::FirstReady;
pub use fp_units::FpUnits;
pub use instance_rays::InstanceRays;
pub use mailbox::MailboxUnit;
pub use primary_rays::{PrimaryRays, CAMERA_WORDS};
pub use program_rom::ProgramRom;
pub use result_line::ResultLine;
pub use retiring::{Retiring, RetiringIn};
pub use scheduler::Scheduler;
pub use write_back::WriteBack;

/// Most threads (the thread id is 5 bits).
pub const MAX_THREADS: usize = 32;
/// Largest supported `mem_latency`.
pub const MAX_MEM_LATENCY: u32 = 6;
/// Scratch words per thread the engine provides.
pub const SCRATCH_WORDS: u32 = 128;

/// Clocks from operand read to write back of every instruction but the long ones (`fdiv`,
/// `fsqrt`, `byte`): the adder's 8 and a register (loads join by the eighth clock). `byte`
/// ([`CHANNEL_BYTE_LATENCY`](crate::hw::CHANNEL_BYTE_LATENCY), 12) went into the long line at stop 38, which cut every other
/// instruction's turn from 20 clocks to 17 at the cost of a reserved clock per `byte` (three
/// per pixel).
pub const ENGINE_LATENCY: u32 = ADD_SUB_LATENCY + 1;

/// Clocks from operand read to write back of `fdiv`, `fsqrt` and `byte` for mantissa width
/// `m` (the square root's `m + 5`, plus one register; the divider's and the colour unit's
/// results wait for it).
pub const fn long_latency(m: u32) -> u32 {
    m + 6
}

/// Clocks from the issue (I0) to the operands (I5): the pc read and its register, the ROM
/// read, the ROM words' register, the register read and the operand register.
pub const OPERAND_STAGE: u32 = 5;

/// Clocks from a write back to the thread's next issue: the write back's register, the
/// scheduler's ready register and its pick register.
pub const WAKE_UP: u32 = 3;

/// The clocks of one round of `threads` threads, each issuing once: a thread issues at most
/// once per `OPERAND_STAGE + ENGINE_LATENCY + WAKE_UP` clocks.
pub fn engine_period(threads: u32) -> u32 {
    threads.max(OPERAND_STAGE + ENGINE_LATENCY + WAKE_UP)
}

/// Where an instruction's result comes from on the fast line: computed at I5, or the data of a scratch read or of a load from the shared memory port or a
/// bank's own port.
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum FastKind {
    Computed,
    Scratch,
    Memory,
    TrianglesA,
    TrianglesB,
    Nodes,
}

/// Which result an instruction writes, decoded by the [`ResultLine`] for the [`WriteBack`]: the
/// fast result, a floating-point unit's, or (`byte`) the fast result with the colour unit's
/// byte in its low bits.
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum ResultSource {
    Fast,
    Sum,
    Product,
    Quotient,
    Root,
    Byte,
}

/// Whose request the tester's TransformUnit computes besides the triangle tests (its
/// `gen_client` bits, echoed with the result): ray generation's, or instance entry's (the
/// ray's origin and direction, or a world normal for shading).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum GenClient {
    Primary = 0b00,
    InstanceOrigin = 0b01,
    InstanceDirection = 0b11,
    InstanceNormal = 0b10,
}

/// An opcode as the decoders compare it, from its one definition in `isa::Op`.
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

/// A RAM's initial contents: word `i` at address `i`.
pub(crate) fn word_map<const N: usize, D: Synth>(
    words: impl Iterator<Item = D>,
) -> std::collections::BTreeMap<Bits<N>, D> {
    words
        .enumerate()
        .map(|(i, w)| (Bits::<N>::from(i as u64), w))
        .collect()
}

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
    /// Banks 1, 4 and 5 (lists, instances and objects, shading), with the triangle tester's
    /// list reads in the clocks the engine leaves free.
    pub mem: BankedSramRead,
    pub fb: FrameBufferWrite,
    /// Banks 0 (kd nodes), 2 and 3 (the triangles) have their own ports: the traversal unit
    /// reads bank 0, the triangle tester banks 2 and 3 at once, and the engine's loads of
    /// these banks go out here too.
    pub bank0: SramRead,
    pub bank2: SramRead,
    pub bank3: SramRead,
    /// Clocks of the frame in which the TransformUnit and the IntersectUnit took an input.
    pub transform_busy: Signal<Out, Bits<32>>,
    pub intersect_busy: Signal<Out, Bits<32>>,
    /// Clocks of the frame in which the traversal unit started a node decision.
    pub traversal_busy: Signal<Out, Bits<32>>,
    /// Clocks of the frame in which ray generation's and instance entry's requests took the
    /// TransformUnit.
    pub raygen_busy: Signal<Out, Bits<32>>,
    pub instance_busy: Signal<Out, Bits<32>>,
    pub shading_busy: Signal<Out, Bits<32>>,
    /// Triangle tests launched with their words from the triangle cache, and from the banks.
    pub tri_cache_hits: Signal<Out, Bits<32>>,
    pub tri_cache_misses: Signal<Out, Bits<32>>,
    /// Object-tree nodes the traversal unit took from its node cache, and from bank 0.
    pub node_cache_hits: Signal<Out, Bits<32>>,
    pub node_cache_misses: Signal<Out, Bits<32>>,
    pub instance_cache_hits: Signal<Out, Bits<32>>,
    pub instance_cache_misses: Signal<Out, Bits<32>>,

    // The pipeline's stages.
    scheduler: Scheduler,
    fetch: Fetch,
    decode: Decode,
    mailboxes: MailboxUnit,
    rays: PrimaryRays<W, E, M>,
    instances: InstanceRays<W>,
    /// Shading in hardware (`tri.shade`), present for a program that uses it.
    shader: ShadeUnit<W, E, M, S, S1, X2, T, P>,
    execute: Execute<W>,
    fp_units: FpUnits<W, E, M, S, S1, X2, T, P>,
    result_line: ResultLine<DX>,
    write_back: WriteBack<W>,
    /// Per thread `SCRATCH_WORDS` words (`lds`, `sts`: the kd stack and the mirror chain).
    scratch: RAM<Bits<32>, 12>,

    // The coprocessors.
    tester: TriangleTester<W, E, M, S, S1, X2, T, P, DL>,
    traversal_unit: TraversalUnit<W, E, M, S, S1, X2, T, DL>,

    // Frame control and counters.
    running: DFF<Bit>,
    epoch: DFF<Bit>,
    halted_count: DFF<Bits<8>>,
    cycle_count: DFF<Bits<32>>,
    instr_count: DFF<Bits<32>>,
    transform_count: DFF<Bits<32>>,
    intersect_count: DFF<Bits<32>>,
    traversal_count: DFF<Bits<32>>,
    raygen_count: DFF<Bits<32>>,
    instance_count: DFF<Bits<32>>,
    shading_count: DFF<Bits<32>>,
    cache_hit_count: DFF<Bits<32>>,
    cache_miss_count: DFF<Bits<32>>,
    node_hit_count: DFF<Bits<32>>,
    node_miss_count: DFF<Bits<32>>,
    instance_hit_count: DFF<Bits<32>>,
    instance_miss_count: DFF<Bits<32>>,
    /// The busy counters' events, registered where they arise and counted a clock later: a
    /// unit's busy signal routed straight into a counter's 32 enables across the chip was
    /// the processor's critical path (stop 45: `tester.words.read_address ->
    /// transform_busy`, `running -> traversal_busy`, 10.7-11.6 ns of routing).
    count_in_frame: DFF<Bit>,
    tick_transform: DFF<Bit>,
    tick_intersect: DFF<Bit>,
    tick_traversal: DFF<Bit>,
    tick_raygen: DFF<Bit>,
    tick_instance: DFF<Bit>,
    tick_shading: DFF<Bit>,
    tick_cache_hit: DFF<Bit>,
    tick_cache_miss: DFF<Bit>,
    tick_node_hit: DFF<Bit>,
    tick_instance_hit: DFF<Bit>,
    tick_instance_miss: DFF<Bit>,
    tick_node_miss: DFF<Bit>,
    frame_start: Signal<Local, Bit>,
    // The memory and frame-buffer ports' request registers.
    /// The load's bank one-hot (`CoprocessorPort::load_banks`); `mem_bank_r` its number, for
    /// the shared bus.
    mem_load_r: DFF<Bits<{ layout::BANKS }>>,
    mem_bank_r: DFF<Bits<3>>,
    mem_addr_r: DFF<Bits<24>>,
    fb_write_r: DFF<Bit>,
    fb_addr_r: DFF<Bits<24>>,
    fb_data_r: DFF<Bits<32>>,
    // The coprocessor glue: the function an instruction names, decoded at I4 and registered
    // for I5 (a 32-bit immediate's compares would otherwise sit in front of the
    // coprocessors' queues); the answers at I5.
    ray_write: DFF<Bit>,
    t_min_write: DFF<Bit>,
    camera_write: DFF<Bit>,
    world_write: DFF<Bit>,
    enter_offer: DFF<Bit>,
    normal_offer: DFF<Bit>,
    shade_offer: DFF<Bit>,
    /// The address of banks 2 and 3 the tester's ports read for the engine: a load's, or the
    /// ShadeUnit's in a clock the engine's loads leave them.
    tri_load_addr_r: DFF<Bits<24>>,
    /// The engine's load in decode (one memory port for it, the ShadeUnit and the list unit).
    engine_load: Signal<Local, Bit>,
    /// I5: the instruction is a valid `ld` / `st`, decoded at I4 and registered: the ports'
    /// grants to the ShadeUnit read them, and the opcode's compare ran in front of the
    /// memory port's address mux (placed critical path at stop 48, `result_line.op_i6 ->
    /// mem_addr_r`, 79.9 MHz).
    load_i5: DFF<Bit>,
    store_i5: DFF<Bit>,
    engine_loads_triangles: Signal<Local, Bit>,
    /// The ShadeUnit's request goes to the TransformUnit (after ray generation's and instance
    /// entry's).
    gen_shade: Signal<Local, Bit>,
    /// The frame is in progress: threads run, or the ShadeUnit still has pixels.
    in_frame: Signal<Local, Bit>,
    tri_enqueue: DFF<Bit>,
    tri_queues: DFF<Bit>,
    tri_kind: DFF<Bits<2>>,
    tri_waits: DFF<Bit>,
    kd_enqueue: DFF<Bit>,
    kd_queues: DFF<Bit>,
    kd_answers: DFF<Bit>,
    kd_waits: DFF<Bit>,
    wait_fn: DFF<Bit>,
    tri_op: Signal<Local, Bit>,
    kd_op: Signal<Local, Bit>,
    tri_wait_fn: Signal<Local, Bit>,
    kd_wait_fn: Signal<Local, Bit>,
    queued_fn: Signal<Local, Bit>,
    kd_queued_fn: Signal<Local, Bit>,
    tri_busy: Signal<Local, Bit>,
    kd_busy: Signal<Local, Bit>,
    /// Instance entry's request goes to the TransformUnit (ray generation's, when both ask,
    /// goes first); a ray written whole into both ray stores, by ray generation or instance
    /// entry.
    gen_instance: Signal<Local, Bit>,
    store_write: Signal<Local, Bit>,

    c_threads: Constant<Bits<8>>,
    /// The program uses the mailboxes (`mbx`, `mbc`) and the scratch words (`lds`, `sts`):
    /// without, their outputs are held at 0 and synthesis removes their RAMs and compares, as
    /// it does an absent `InstanceRays`.
    c_uses_mailboxes: Constant<Bit>,
    c_uses_scratch: Constant<Bit>,
    c_shading: Constant<Bit>,
    // The glue's names, every one from its definition in `isa` (`Op`, `TriFn`, `KdFn`),
    // `layout` (banks) and `list_unit` (command kinds): the Verilog's localparams follow the
    // twin's numbering by construction.
    op_fsub: Constant<Bits<5>>,
    op_fdiv: Constant<Bits<5>>,
    op_fsqrt: Constant<Bits<5>>,
    op_byte: Constant<Bits<5>>,
    op_ld: Constant<Bits<5>>,
    op_st: Constant<Bits<5>>,
    op_sts: Constant<Bits<5>>,
    op_mbx: Constant<Bits<5>>,
    op_mbc: Constant<Bits<5>>,
    op_pixel: Constant<Bits<5>>,
    op_tri: Constant<Bits<5>>,
    op_kd: Constant<Bits<5>>,
    /// The ray words are `TriFn`s 0..3, their number the ray store's `ray_pair`.
    tri_ray_words: Constant<Bits<32>>,
    tri_init: Constant<Bits<32>>,
    tri_list: Constant<Bits<32>>,
    tri_wait: Constant<Bits<32>>,
    tri_skip: Constant<Bits<32>>,
    tri_camera: Constant<Bits<32>>,
    tri_world: Constant<Bits<32>>,
    tri_enter: Constant<Bits<32>>,
    tri_normal: Constant<Bits<32>>,
    tri_shade: Constant<Bits<32>>,
    kd_start: Constant<Bits<32>>,
    kd_wait: Constant<Bits<32>>,
    kd_next: Constant<Bits<32>>,
    cmd_list: Constant<Bits<2>>,
    cmd_init: Constant<Bits<2>>,
    cmd_object: Constant<Bits<2>>,
    cmd_skip: Constant<Bits<2>>,
    bank_lists: Constant<Bits<3>>,
    bank_instances: Constant<Bits<3>>,
    bank_frame: Constant<Bits<3>>,
    bank_triangles_a: Constant<Bits<3>>,
    bank_triangles_b: Constant<Bits<3>>,
    /// Banks 2 and 3 as `mem_load_r` bits.
    triangle_banks: Constant<Bits<{ layout::BANKS }>>,
    /// Bank 5 as a `mem_load_r` bit.
    frame_bank: Constant<Bits<{ layout::BANKS }>>,
    client_primary: Constant<Bits<2>>,
    client_origin: Constant<Bits<2>>,
    client_normal: Constant<Bits<2>>,
    client_direction: Constant<Bits<2>>,
    /// `mem_load_r`'s bit 0, shifted to the load's bank.
    one_bank: Constant<Bits<{ layout::BANKS }>>,
    /// [`SHARED_BUS_BANKS`].
    shared_banks: Constant<Bits<{ layout::BANKS }>>,
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
    /// The engine running `program` with the threads, memory read latency and triangle and
    /// node caches `params` give.
    pub fn new(program: &Program, params: &ProcessorParams) -> Self {
        let ProcessorParams {
            threads,
            mem_latency,
            tri_cache_sets,
            tri_cache_ways,
            node_cache_sets,
            node_cache_ways,
            instance_cache_sets,
            instance_cache_ways,
        } = *params;
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && T == S + 4);
        assert!(P == 2 * S);
        // `FpUnits` pads the (faster) divider to the square root's latency.
        assert!(super::fp::div::div_latency(M as u32) < long_latency(M as u32));
        assert!(super::fp::sqrt::sqrt_latency(M as u32) + 1 == long_latency(M as u32));
        // The reservation is made as the long instruction is fetched (I3, `FETCH_LATENCY`) for
        // the issue `1 + reserve_ahead` clocks later, whose write back is the long one's:
        // I3 + 1 + (DX - 4) + OPERAND_STAGE + ENGINE_LATENCY = I5 + long_latency.
        assert!(DX == (long_latency(M as u32) - ENGINE_LATENCY) as usize);
        assert!(
            DX > FETCH_LATENCY as usize,
            "the reservation would come too late"
        );
        let reserve_ahead = DX as u32 - (FETCH_LATENCY + 1);
        let units = program.units();
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
        Self {
            clock: Default::default(),
            start: Default::default(),
            done: Default::default(),
            cycles: Default::default(),
            instructions: Default::default(),
            mem: Default::default(),
            fb: Default::default(),
            bank0: Default::default(),
            bank2: Default::default(),
            bank3: Default::default(),
            transform_busy: Default::default(),
            raygen_busy: Default::default(),
            instance_busy: Default::default(),
            shading_busy: Default::default(),
            tri_cache_hits: Default::default(),
            tri_cache_misses: Default::default(),
            node_cache_hits: Default::default(),
            node_cache_misses: Default::default(),
            instance_cache_hits: Default::default(),
            instance_cache_misses: Default::default(),
            intersect_busy: Default::default(),
            traversal_busy: Default::default(),
            scheduler: Scheduler::new(threads, reserve_ahead),
            fetch: Fetch::new(program),
            decode: Decode::new(program.registers_used),
            mailboxes: Default::default(),
            rays: PrimaryRays::new(&program.config),
            instances: InstanceRays::new(
                mem_latency,
                units.contains(&Unit::InstanceEntry),
                instance_cache_sets,
                instance_cache_ways,
            ),
            shader: ShadeUnit::new(ShadeConfig {
                tri_latency: mem_latency + 1,
                frame_latency: mem_latency + 1,
                lights: if units.contains(&Unit::Shading) {
                    program.config.light_count
                } else {
                    0
                },
                materials: program.config.materials,
                frame_buffer: program.config.frame_buffer,
            }),
            execute: Default::default(),
            fp_units: Default::default(),
            result_line: ResultLine::new(mem_latency),
            write_back: Default::default(),
            // Scratch words start undefined: the program writes every one before reading it.
            scratch: Default::default(),
            tester: TriangleTester::new(mem_latency, tri_cache_sets, tri_cache_ways),
            traversal_unit: TraversalUnit::new(
                mem_latency,
                program.config.top_stack_base,
                program.config.top_root.is_some(),
                node_cache_sets,
                node_cache_ways,
            ),
            running: Default::default(),
            epoch: Default::default(),
            halted_count: Default::default(),
            cycle_count: Default::default(),
            instr_count: Default::default(),
            transform_count: Default::default(),
            raygen_count: Default::default(),
            instance_count: Default::default(),
            shading_count: Default::default(),
            cache_hit_count: Default::default(),
            cache_miss_count: Default::default(),
            node_hit_count: Default::default(),
            node_miss_count: Default::default(),
            instance_hit_count: Default::default(),
            instance_miss_count: Default::default(),
            count_in_frame: Default::default(),
            tick_transform: Default::default(),
            tick_intersect: Default::default(),
            tick_traversal: Default::default(),
            tick_raygen: Default::default(),
            tick_instance: Default::default(),
            tick_shading: Default::default(),
            tick_cache_hit: Default::default(),
            tick_cache_miss: Default::default(),
            tick_node_hit: Default::default(),
            tick_instance_hit: Default::default(),
            tick_instance_miss: Default::default(),
            tick_node_miss: Default::default(),
            intersect_count: Default::default(),
            traversal_count: Default::default(),
            frame_start: Default::default(),
            mem_load_r: Default::default(),
            mem_bank_r: Default::default(),
            mem_addr_r: Default::default(),
            fb_write_r: Default::default(),
            fb_addr_r: Default::default(),
            fb_data_r: Default::default(),
            ray_write: Default::default(),
            t_min_write: Default::default(),
            camera_write: Default::default(),
            world_write: Default::default(),
            enter_offer: Default::default(),
            normal_offer: Default::default(),
            shade_offer: Default::default(),
            load_i5: Default::default(),
            store_i5: Default::default(),
            tri_load_addr_r: Default::default(),
            engine_load: Default::default(),
            engine_loads_triangles: Default::default(),
            gen_shade: Default::default(),
            in_frame: Default::default(),
            tri_enqueue: Default::default(),
            tri_queues: Default::default(),
            tri_kind: Default::default(),
            tri_waits: Default::default(),
            kd_enqueue: Default::default(),
            kd_queues: Default::default(),
            kd_answers: Default::default(),
            kd_waits: Default::default(),
            wait_fn: Default::default(),
            tri_op: Default::default(),
            kd_op: Default::default(),
            tri_wait_fn: Default::default(),
            kd_wait_fn: Default::default(),
            queued_fn: Default::default(),
            kd_queued_fn: Default::default(),
            tri_busy: Default::default(),
            kd_busy: Default::default(),
            gen_instance: Default::default(),
            store_write: Default::default(),
            c_threads: Constant::new(u64::from(threads).into()),
            c_uses_mailboxes: Constant::new(units.contains(&Unit::Mailbox)),
            c_uses_scratch: Constant::new(units.contains(&Unit::Scratch)),
            c_shading: Constant::new(units.contains(&Unit::Shading)),
            op_fsub: op_code(Op::FSub),
            op_fdiv: op_code(Op::FDiv),
            op_fsqrt: op_code(Op::FSqrt),
            op_byte: op_code(Op::Byte),
            op_ld: op_code(Op::Ld),
            op_st: op_code(Op::St),
            op_sts: op_code(Op::Sts),
            op_mbx: op_code(Op::Mbx),
            op_mbc: op_code(Op::Mbc),
            op_pixel: op_code(Op::Pixel),
            op_tri: op_code(Op::Tri),
            op_kd: op_code(Op::Kd),
            tri_ray_words: tri_fn(TriFn::Init),
            tri_init: tri_fn(TriFn::Init),
            tri_list: tri_fn(TriFn::List),
            tri_wait: tri_fn(TriFn::Wait),
            tri_skip: tri_fn(TriFn::Skip),
            tri_camera: tri_fn(TriFn::Camera),
            tri_world: tri_fn(TriFn::World),
            tri_enter: tri_fn(TriFn::Enter),
            tri_normal: tri_fn(TriFn::Normal),
            tri_shade: tri_fn(TriFn::Shade),
            kd_start: kd_fn(KdFn::Start),
            kd_wait: kd_fn(KdFn::Wait),
            kd_next: kd_fn(KdFn::Next),
            cmd_list: cmd(list_unit::CMD_LIST),
            cmd_init: cmd(list_unit::CMD_INIT),
            cmd_object: cmd(list_unit::CMD_OBJECT),
            cmd_skip: cmd(list_unit::CMD_SKIP),
            bank_lists: bank(layout::LISTS),
            bank_instances: bank(layout::INSTANCES),
            bank_frame: bank(layout::FRAME),
            bank_triangles_a: bank(layout::TRIANGLES_A),
            bank_triangles_b: bank(layout::TRIANGLES_B),
            triangle_banks: Constant::new(
                ((1u64 << layout::TRIANGLES_A) | (1u64 << layout::TRIANGLES_B)).into(),
            ),
            frame_bank: Constant::new((1u64 << layout::FRAME).into()),
            client_primary: Constant::new((GenClient::Primary as u64).into()),
            client_origin: Constant::new((GenClient::InstanceOrigin as u64).into()),
            client_normal: Constant::new((GenClient::InstanceNormal as u64).into()),
            client_direction: Constant::new((GenClient::InstanceDirection as u64).into()),
            one_bank: Constant::new(1u64.into()),
            shared_banks: Constant::new(SHARED_BUS_BANKS.into()),
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
            halted_count,
            cycle_count,
            instr_count,
            transform_count,
            raygen_count,
            instance_count,
            shading_count,
            cache_hit_count,
            cache_miss_count,
            node_hit_count,
            node_miss_count,
            instance_hit_count,
            instance_miss_count,
            count_in_frame,
            tick_transform,
            tick_intersect,
            tick_traversal,
            tick_raygen,
            tick_instance,
            tick_shading,
            tick_cache_hit,
            tick_cache_miss,
            tick_node_hit,
            tick_instance_hit,
            tick_instance_miss,
            tick_node_miss,
            intersect_count,
            traversal_count,
            mem_load_r,
            mem_bank_r,
            mem_addr_r,
            fb_write_r,
            fb_addr_r,
            fb_data_r,
            ray_write,
            t_min_write,
            camera_write,
            world_write,
            enter_offer,
            normal_offer,
            shade_offer,
            load_i5,
            store_i5,
            tri_load_addr_r,
            tri_enqueue,
            tri_queues,
            tri_kind,
            tri_waits,
            kd_enqueue,
            kd_queues,
            kd_answers,
            kd_waits,
            wait_fn
        );
        clock!(
            self,
            clock,
            scheduler,
            fetch,
            decode,
            mailboxes,
            rays,
            instances,
            shader,
            fp_units,
            result_line,
            write_back,
            tester,
            traversal_unit
        );
        self.scratch.read_clock.next = self.clock.val();
        self.scratch.write_clock.next = self.clock.val();

        // Instance entry's request goes to the TransformUnit when ray generation has none; a
        // ray is written whole into both ray stores by one or the other (never both: each
        // writes the clock after a result of its own).
        self.gen_instance.next = self.instances.gen_valid.val() & (!self.rays.gen_valid.val());
        self.store_write.next = self.rays.primary_write.val() | self.instances.ray_write.val();

        // Frame control and counters.
        self.frame_start.next = self.start.val() & (!self.running.q.val());
        // The ShadeUnit writes its last pixels after the threads have halted (the last one
        // a clock after it is idle, from the frame-buffer port's register).
        self.in_frame.next = self.running.q.val()
            | (self.c_shading.val() & ((!self.shader.idle.val()) | self.fb_write_r.q.val()));
        self.done.next =
            (!self.in_frame.val()) & (self.halted_count.q.val() == self.c_threads.val());
        self.cycles.next = self.cycle_count.q.val();
        self.instructions.next = self.instr_count.q.val();
        self.transform_busy.next = self.transform_count.q.val();
        self.intersect_busy.next = self.intersect_count.q.val();
        self.traversal_busy.next = self.traversal_count.q.val();
        self.raygen_busy.next = self.raygen_count.q.val();
        self.instance_busy.next = self.instance_count.q.val();
        self.shading_busy.next = self.shading_count.q.val();
        self.tri_cache_hits.next = self.cache_hit_count.q.val();
        self.tri_cache_misses.next = self.cache_miss_count.q.val();
        self.node_cache_hits.next = self.node_hit_count.q.val();
        self.node_cache_misses.next = self.node_miss_count.q.val();
        self.instance_cache_hits.next = self.instance_hit_count.q.val();
        self.instance_cache_misses.next = self.instance_miss_count.q.val();
        if self.in_frame.val() {
            self.cycle_count.d.next = self.cycle_count.q.val() + 1;
        }
        self.count_in_frame.d.next = self.in_frame.val();
        self.tick_transform.d.next = self.tester.transform_busy.val();
        self.tick_intersect.d.next = self.tester.intersect_busy.val();
        self.tick_traversal.d.next = self.traversal_unit.step_busy.val();
        self.tick_cache_hit.d.next = self.tester.cache_hit.val();
        self.tick_cache_miss.d.next = self.tester.cache_miss.val();
        self.tick_node_hit.d.next = self.traversal_unit.cache_hit.val();
        self.tick_instance_hit.d.next = self.instances.cache_hit.val();
        self.tick_instance_miss.d.next = self.instances.cache_miss.val();
        self.tick_node_miss.d.next = self.traversal_unit.cache_miss.val();
        if self.count_in_frame.q.val() {
            if self.tick_transform.q.val() {
                self.transform_count.d.next = self.transform_count.q.val() + 1;
            }
            if self.tick_intersect.q.val() {
                self.intersect_count.d.next = self.intersect_count.q.val() + 1;
            }
            if self.tick_traversal.q.val() {
                self.traversal_count.d.next = self.traversal_count.q.val() + 1;
            }
            if self.tick_raygen.q.val() {
                self.raygen_count.d.next = self.raygen_count.q.val() + 1;
            }
            if self.tick_shading.q.val() {
                self.shading_count.d.next = self.shading_count.q.val() + 1;
            }
            if self.tick_instance.q.val() {
                self.instance_count.d.next = self.instance_count.q.val() + 1;
            }
            if self.tick_cache_hit.q.val() {
                self.cache_hit_count.d.next = self.cache_hit_count.q.val() + 1;
            }
            if self.tick_cache_miss.q.val() {
                self.cache_miss_count.d.next = self.cache_miss_count.q.val() + 1;
            }
            if self.tick_node_hit.q.val() {
                self.node_hit_count.d.next = self.node_hit_count.q.val() + 1;
            }
            if self.tick_node_miss.q.val() {
                self.node_miss_count.d.next = self.node_miss_count.q.val() + 1;
            }
            if self.tick_instance_hit.q.val() {
                self.instance_hit_count.d.next = self.instance_hit_count.q.val() + 1;
            }
            if self.tick_instance_miss.q.val() {
                self.instance_miss_count.d.next = self.instance_miss_count.q.val() + 1;
            }
        }

        // I0..I3.
        self.scheduler.running.next = self.running.q.val();
        self.scheduler.frame_start.next = self.frame_start.val();
        self.fetch.epoch.next = self.epoch.q.val();
        self.fetch.issue.next = self.scheduler.issue.val();
        self.fetch.pick.next = self.scheduler.pick.val();
        self.decode.valid_i3.next = self.fetch.valid.val();
        self.decode.thread_i3.next = self.fetch.thread.val();
        self.decode.pc_i3.next = self.fetch.pc.val();
        self.decode.ctl_i3.next = self.fetch.ctl.val();
        self.decode.imm_i3.next = self.fetch.imm.val();
        self.decode.aux_i3.next = self.fetch.aux.val();
        self.scheduler.long_at_i3.next = self.fetch.valid.val()
            & ((self.decode.op_i3.val() == self.op_fdiv.val())
                | (self.decode.op_i3.val() == self.op_fsqrt.val())
                | (self.decode.op_i3.val() == self.op_byte.val()));

        // I4: the per-thread state the units read one clock ahead of the operands.
        self.mailboxes.read_thread.next = self.decode.thread_i4.val();
        self.mailboxes.read_which.next = self.decode.imm_i4.val().get_bit(0);
        self.tester.engine.query_thread.next = self.decode.thread_i4.val();
        self.traversal_unit.engine.query_thread.next = self.decode.thread_i4.val();
        self.instances.query_thread.next = self.decode.thread_i4.val();
        self.shader.query_thread.next = self.decode.thread_i4.val();

        // I5.
        self.fp_units.a.next = self.decode.a.val().get_bits::<W>(0);
        self.fp_units.b.next = self.decode.b.val().get_bits::<W>(0);
        self.fp_units.sub.next = self.decode.op.val() == self.op_fsub.val();
        self.execute.op.next = self.decode.op.val();
        self.execute.a.next = self.decode.a.val();
        self.execute.b.next = self.decode.b.val();
        self.execute.imm.next = self.decode.imm.val();
        self.execute.shift.next = self.decode.shift.val();
        self.execute.bank.next = self.decode.bank.val();
        self.execute.pc.next = self.decode.pc.val();
        self.execute.pixel.next = self.rays.word.val();
        for k in 0..3 {
            self.execute.primary_dir[k].next = self.rays.dir[k].val();
        }
        self.execute.tester_best_t.next = self.tester.best_t.val();
        self.execute.tester_hit.next = self.tester.hit.val();
        self.execute.tester_instance.next = self.tester.best_instance.val();
        self.execute.tester_triangle.next = self.tester.best_triangle.val();
        self.execute.top_from.next = self.traversal_unit.top_from.val();
        self.execute.top_to.next = self.traversal_unit.top_to.val();
        self.mailboxes.thread.next = self.decode.thread.val();
        self.mailboxes.which.next = self.decode.imm.val().get_bit(0);
        self.mailboxes.value.next = self.decode.a.val();
        self.mailboxes.insert.next =
            self.decode.valid.val() & (self.decode.op.val() == self.op_mbx.val());
        self.mailboxes.clear.next =
            self.decode.valid.val() & (self.decode.op.val() == self.op_mbc.val());
        self.rays.frame_start.next = self.frame_start.val();
        self.rays.offer.next = self.running.q.val()
            & self.decode.valid.val()
            & (self.decode.op.val() == self.op_pixel.val());
        self.rays.thread.next = self.decode.thread.val();
        self.rays.camera_write.next = self.camera_write.q.val();
        self.rays.camera_pair.next = self.decode.shift.val().get_bits::<3>(0);
        self.rays.word_a.next = self.decode.a.val();
        self.rays.word_b.next = self.decode.b.val();
        self.rays.query_thread.next = self.decode.thread_i4.val();
        self.instances.frame_start.next = self.frame_start.val();
        self.instances.thread.next = self.decode.thread.val();
        self.instances.world_write.next = self.world_write.q.val();
        self.instances.world_pair.next = self.decode.shift.val().get_bits::<2>(0);
        self.instances.word_a.next = self.decode.a.val();
        self.instances.word_b.next = self.decode.b.val();
        // `tri.enter` enters (InstanceRays), queues the instance as the tester's object and
        // counts the walk the traversal unit starts when the ray is written: all three or
        // none (the thread repeats it while the entry slot or the tester's queue is full).
        self.instances.offer.next = (self.enter_offer.q.val() & (!self.tester.engine.full.val()))
            | self.normal_offer.q.val();
        self.instances.offer_normal.next = self.normal_offer.q.val();
        self.instances.instance_id.next = self.decode.a.val().get_bits::<24>(0);
        // `tri.shade`: the thread's query, as the tester answers it at I5, to the ShadeUnit.
        self.shader.frame_start.next = self.frame_start.val() & self.c_shading.val();
        self.shader.offer.next = self.shade_offer.q.val();
        self.shader.offer_addr.next = self.decode.a.val().get_bits::<24>(0);
        self.shader.offer_hit.next = self.tester.hit.val();
        self.shader.offer_t.next = self.tester.best_t.val();
        self.shader.offer_triangle.next = self.tester.best_triangle.val().get_bits::<24>(0);

        // Scratch memory.
        self.scratch.read_address.next = (bit_cast::<12, 5>(self.decode.thread.val()) << 7)
            | bit_cast::<12, 7>(self.execute.scratch_address.val().get_bits::<7>(0));
        self.scratch.write_address.next = (bit_cast::<12, 5>(self.decode.thread.val()) << 7)
            | bit_cast::<12, 7>(self.execute.scratch_address.val().get_bits::<7>(0));
        self.scratch.write_data.next = self.decode.store.val();
        self.scratch.write_enable.next =
            self.decode.valid.val() & (self.decode.op.val() == self.op_sts.val());

        // Memory and frame-buffer ports (registered).
        self.load_i5.d.next =
            self.decode.valid_i4.val() & (self.decode.op_i4.val() == self.op_ld.val());
        self.store_i5.d.next =
            self.decode.valid_i4.val() & (self.decode.op_i4.val() == self.op_st.val());
        self.engine_load.next = self.load_i5.q.val();
        self.mem_load_r.d.next = 0.into();
        if self.engine_load.val() {
            self.mem_load_r.d.next = self.one_bank.val() << self.decode.bank.val();
        }
        // The ShadeUnit reads banks 2 and 3 at once in a clock the engine's loads leave them,
        // as a load of both (registered like the engine's: a clock more of latency).
        self.engine_loads_triangles.next = self.engine_load.val()
            & ((self.decode.bank.val() == self.bank_triangles_a.val())
                | (self.decode.bank.val() == self.bank_triangles_b.val()));
        self.shader.tri_grant.next = self.c_shading.val() & (!self.engine_loads_triangles.val());
        self.tri_load_addr_r.d.next = self.execute.mem_address.val().get_bits::<24>(0);
        if self.shader.tri_read.val() & self.shader.tri_grant.val() {
            self.mem_load_r.d.next = self.mem_load_r.d.val() | self.triangle_banks.val();
            self.tri_load_addr_r.d.next = self.shader.tri_addr.val();
        }
        self.shader.tri_rdata_a.next = self.bank2.rdata.val();
        self.shader.tri_rdata_b.next = self.bank3.rdata.val();
        self.mem_bank_r.d.next = self.decode.bank.val();
        self.mem_addr_r.d.next = self.execute.mem_address.val().get_bits::<24>(0);
        // Its reads of bank 5 likewise, in a clock without an engine load: a load on the
        // shared bus a clock later, which the list unit and instance entry see as the
        // engine's. (Granted on the bus's free clocks, the grant ran from the list unit's
        // state into the unit's dispatch, 71.4 MHz placed; granted first, from the unit's
        // dispatch into the list unit's room count, 65.2 MHz.)
        self.shader.frame_grant.next = self.c_shading.val() & (!self.engine_load.val());
        if self.shader.frame_read.val() & self.shader.frame_grant.val() {
            self.mem_load_r.d.next = self.mem_load_r.d.val() | self.frame_bank.val();
            self.mem_bank_r.d.next = self.bank_frame.val();
            self.mem_addr_r.d.next = self.shader.frame_addr.val();
        }
        self.fb_write_r.d.next = self.store_i5.q.val();
        self.fb_addr_r.d.next = self.execute.mem_address.val().get_bits::<24>(0);
        self.fb_data_r.d.next = self.decode.store.val();
        // The ShadeUnit's pixels in the clocks the engine's stores leave the port.
        self.shader.fb_grant.next = self.c_shading.val() & (!self.store_i5.q.val());
        if self.shader.fb_write.val() & self.shader.fb_grant.val() {
            self.fb_write_r.d.next = true;
            self.fb_addr_r.d.next = self.shader.fb_addr.val();
            self.fb_data_r.d.next = self.shader.fb_data.val();
        }
        self.fb.write.next = self.fb_write_r.q.val();
        self.fb.addr.next = self.fb_addr_r.q.val();
        self.fb.data.next = self.fb_data_r.q.val();
        // Bank 0 goes through the traversal unit's port, banks 2 and 3 through the triangle
        // tester's; the tester's list reads (bank 1) use this bus when the engine's loads (and
        // the ShadeUnit's reads of bank 5, made loads above) do not, instance entry's reads
        // (bank 4) when neither does.
        self.instances.bus_free.next = ((self.mem_load_r.q.val() & self.shared_banks.val()) == 0)
            & (!self.tester.lists.read.val());
        self.mem.read.next = ((self.mem_load_r.q.val() & self.shared_banks.val()) != 0)
            | self.tester.lists.read.val()
            | self.instances.read.val();
        if self.tester.lists.read.val() {
            self.mem.bank.next = self.bank_lists.val();
            self.mem.addr.next = self.tester.lists.addr.val();
        } else if self.instances.read.val() {
            self.mem.bank.next = self.bank_instances.val();
            self.mem.addr.next = self.instances.addr.val();
        } else {
            self.mem.bank.next = self.mem_bank_r.q.val();
            self.mem.addr.next = self.mem_addr_r.q.val();
        }
        self.tester.lists.rdata.next = self.mem.rdata.val();
        self.instances.rdata.next = self.mem.rdata.val();
        self.shader.frame_rdata.next = self.mem.rdata.val();
        SramRead::link(&mut self.bank0, &mut self.traversal_unit.nodes);
        SramRead::link(&mut self.bank2, &mut self.tester.a_words);
        SramRead::link(&mut self.bank3, &mut self.tester.b_words);
        // I4: the coprocessor function the instruction names (`tri` with its `TriFn`, `kd`
        // with its `KdFn`, in imm), for I5. The queued `TriFn`s go to the list unit as its
        // command kinds.
        self.tri_op.next = self.decode.op_i4.val() == self.op_tri.val();
        self.kd_op.next = self.decode.op_i4.val() == self.op_kd.val();
        self.tri_wait_fn.next = self.decode.imm_i4.val() == self.tri_wait.val();
        self.kd_wait_fn.next = self.decode.imm_i4.val() == self.kd_wait.val();
        self.queued_fn.next = (self.decode.imm_i4.val() == self.tri_init.val())
            | (self.decode.imm_i4.val() == self.tri_list.val())
            | (self.decode.imm_i4.val() == self.tri_enter.val())
            | (self.decode.imm_i4.val() == self.tri_skip.val());
        self.ray_write.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() < self.tri_ray_words.val());
        self.camera_write.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() == self.tri_camera.val());
        self.world_write.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() == self.tri_world.val());
        self.enter_offer.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() == self.tri_enter.val());
        self.normal_offer.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() == self.tri_normal.val());
        self.shade_offer.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() == self.tri_shade.val())
            & self.c_shading.val();
        self.t_min_write.d.next = self.decode.valid_i4.val()
            & self.tri_op.val()
            & (self.decode.imm_i4.val() == self.tri_init.val());
        self.tri_queues.d.next = self.queued_fn.val();
        self.tri_enqueue.d.next =
            self.decode.valid_i4.val() & self.tri_op.val() & self.queued_fn.val();
        self.tri_kind.d.next = self.cmd_list.val();
        if self.decode.imm_i4.val() == self.tri_init.val() {
            self.tri_kind.d.next = self.cmd_init.val();
        }
        if self.decode.imm_i4.val() == self.tri_enter.val() {
            self.tri_kind.d.next = self.cmd_object.val();
        }
        if self.decode.imm_i4.val() == self.tri_skip.val() {
            self.tri_kind.d.next = self.cmd_skip.val();
        }
        self.tri_waits.d.next = self.tri_wait_fn.val();
        // `kd.start` and `kd.next` queue (`kd.next` is the top-level walk's answer).
        self.kd_queued_fn.next = (self.decode.imm_i4.val() == self.kd_start.val())
            | (self.decode.imm_i4.val() == self.kd_next.val());
        self.kd_queues.d.next = self.kd_queued_fn.val();
        self.kd_enqueue.d.next =
            self.decode.valid_i4.val() & self.kd_op.val() & self.kd_queued_fn.val();
        self.kd_answers.d.next = self.decode.imm_i4.val() == self.kd_next.val();
        self.kd_waits.d.next = self.kd_wait_fn.val();
        // The waits (`tri.wait`, `kd.wait`): a pending one sleeps instead of repeating.
        self.wait_fn.d.next = (self.tri_op.val() & self.tri_wait_fn.val())
            | (self.kd_op.val() & self.kd_wait_fn.val());

        // I5: both coprocessors see the engine's loads, the thread and its ray words.
        self.traversal_unit.engine.load_banks.next = self.mem_load_r.q.val();
        self.traversal_unit.engine.load_addr.next = self.mem_addr_r.q.val();
        self.traversal_unit.engine.thread.next = self.decode.thread.val();
        self.traversal_unit.engine.word_a.next = self.decode.a.val();
        self.traversal_unit.engine.word_b.next = self.decode.b.val();
        self.traversal_unit.engine.ray_pair.next = self.decode.imm.val().get_bits::<2>(0);
        self.traversal_unit.engine.ray_write.next =
            self.ray_write.q.val() & (!self.store_write.val());
        self.tester.engine.load_banks.next = self.mem_load_r.q.val();
        self.tester.engine.load_addr.next = self.tri_load_addr_r.q.val();
        self.tester.engine.thread.next = self.decode.thread.val();
        self.tester.engine.word_a.next = self.decode.a.val();
        self.tester.engine.word_b.next = self.decode.b.val();
        self.tester.engine.ray_pair.next = self.decode.imm.val().get_bits::<2>(0);
        self.tester.engine.ray_write.next = self.ray_write.q.val() & (!self.store_write.val());
        // Ray generation and instance entry: their requests take the tester's TransformUnit
        // in the clocks the launch leaves free (ray generation's first), and their rays are
        // written whole into both ray stores (the engine's ray words are refused in that
        // clock). The client bits say whose result it is (`GenClient`).
        self.gen_shade.next = self.c_shading.val()
            & self.shader.gen_valid.val()
            & (!self.rays.gen_valid.val())
            & (!self.instances.gen_valid.val());
        self.tester.gen_valid.next =
            self.rays.gen_valid.val() | self.instances.gen_valid.val() | self.gen_shade.val();
        // The TransformUnit's clients' busy counts (see `tick_transform`).
        self.tick_raygen.d.next =
            self.tester.gen_take.val() & (!self.gen_instance.val()) & (!self.gen_shade.val());
        self.tick_shading.d.next = self.tester.gen_take.val()
            & (self.gen_shade.val() | (self.gen_instance.val() & self.instances.gen_normal.val()));
        self.tick_instance.d.next = self.tester.gen_take.val()
            & self.gen_instance.val()
            & (!self.instances.gen_normal.val());
        self.tester.gen_diagonal.next = self.gen_shade.val() & self.shader.gen_diagonal.val();
        if self.gen_instance.val() {
            for k in 0..12 {
                self.tester.gen_m[k].next = self.instances.gen_m[k].val();
            }
            for k in 0..3 {
                self.tester.gen_v[k].next = self.instances.gen_v[k].val();
            }
            self.tester.gen_point.next = self.instances.gen_point.val();
            self.tester.gen_client.next = self.client_origin.val();
            if self.instances.gen_direction.val() {
                self.tester.gen_client.next = self.client_direction.val();
            }
            if self.instances.gen_normal.val() {
                self.tester.gen_client.next = self.client_normal.val();
            }
            self.tester.gen_thread.next = self.instances.gen_thread.val();
        } else if self.gen_shade.val() {
            // The ShadeUnit's slot in the thread bits; its results share the normal's client
            // bits (a program shades in the unit only without instances).
            for k in 0..12 {
                self.tester.gen_m[k].next = self.shader.gen_m[k].val();
            }
            for k in 0..3 {
                self.tester.gen_v[k].next = self.shader.gen_v[k].val();
            }
            self.tester.gen_point.next = self.shader.gen_point.val();
            self.tester.gen_client.next = self.client_normal.val();
            self.tester.gen_thread.next = bit_cast::<5, 4>(self.shader.gen_slot.val());
        } else {
            for k in 0..12 {
                self.tester.gen_m[k].next = self.rays.gen_m[k].val();
            }
            for k in 0..3 {
                self.tester.gen_v[k].next = self.rays.gen_v[k].val();
            }
            self.tester.gen_point.next = true;
            self.tester.gen_client.next = self.client_primary.val();
            self.tester.gen_thread.next = self.rays.gen_thread.val();
        }
        self.rays.gen_take.next = self.tester.gen_take.val();
        self.instances.gen_take.next = self.tester.gen_take.val() & self.gen_instance.val();
        self.shader.gen_take.next = self.tester.gen_take.val() & self.gen_shade.val();
        self.shader.res_valid.next = self.c_shading.val()
            & self.tester.gen_out_valid.val()
            & (self.tester.gen_out_client.val() == self.client_normal.val());
        self.shader.res_slot.next = self.tester.gen_out_thread.val().get_bits::<4>(0);
        for k in 0..3 {
            self.shader.res_v[k].next = self.tester.gen_out_dir[k].val();
        }
        self.rays.gen_out_valid.next = self.tester.gen_out_valid.val()
            & (self.tester.gen_out_client.val() == self.client_primary.val());
        self.rays.gen_out_thread.next = self.tester.gen_out_thread.val();
        self.instances.out_valid.next = self.tester.gen_out_valid.val()
            & (self.tester.gen_out_client.val() != self.client_primary.val());
        self.instances.out_direction.next =
            self.tester.gen_out_client.val() == self.client_direction.val();
        self.instances.out_normal.next =
            self.tester.gen_out_client.val() == self.client_normal.val();
        // A world normal goes to ray generation's direction store, which `tri.dir` reads.
        self.rays.normal_write.next = self.instances.normal_write.val();
        self.rays.normal_thread.next = self.instances.ray_thread.val();
        for k in 0..3 {
            self.rays.normal[k].next = self.instances.ray_d[k].val();
        }
        self.instances.out_thread.next = self.tester.gen_out_thread.val();
        for k in 0..3 {
            self.rays.gen_out_dir[k].next = self.tester.gen_out_dir[k].val();
            self.instances.out_v[k].next = self.tester.gen_out_dir[k].val();
        }
        self.tester.primary_write.next = self.store_write.val();
        self.traversal_unit.primary_write.next = self.store_write.val();
        self.shader.ray_write.next = self.store_write.val();
        if self.instances.ray_write.val() {
            self.shader.ray_thread.next = self.instances.ray_thread.val();
            for k in 0..3 {
                self.shader.ray_o[k].next = self.instances.ray_o[k].val();
                self.shader.ray_d[k].next = self.instances.ray_d[k].val();
            }
            self.tester.primary_thread.next = self.instances.ray_thread.val();
            self.traversal_unit.primary_thread.next = self.instances.ray_thread.val();
            for k in 0..3 {
                self.tester.primary_o[k].next = self.instances.ray_o[k].val();
                self.tester.primary_d[k].next = self.instances.ray_d[k].val();
                self.traversal_unit.primary_o[k].next = self.instances.ray_o[k].val();
                self.traversal_unit.primary_d[k].next = self.instances.ray_d[k].val();
            }
        } else {
            self.tester.primary_thread.next = self.rays.primary_thread.val();
            self.traversal_unit.primary_thread.next = self.rays.primary_thread.val();
            self.shader.ray_thread.next = self.rays.primary_thread.val();
            for k in 0..3 {
                self.shader.ray_o[k].next = self.rays.primary_o[k].val();
                self.shader.ray_d[k].next = self.rays.primary_d[k].val();
            }
            for k in 0..3 {
                self.tester.primary_o[k].next = self.rays.primary_o[k].val();
                self.tester.primary_d[k].next = self.rays.primary_d[k].val();
                self.traversal_unit.primary_o[k].next = self.rays.primary_o[k].val();
                self.traversal_unit.primary_d[k].next = self.rays.primary_d[k].val();
            }
        }

        // Triangle tester: the entry and its answer (refused, or the wait pending).
        self.tester.engine.enqueue.next =
            self.tri_enqueue.q.val() & (!(self.enter_offer.q.val() & self.instances.refused.val()));
        self.tester.queue_kind.next = self.tri_kind.q.val();
        self.tri_busy.next = false;
        if self.tri_queues.q.val() {
            self.tri_busy.next = self.tester.engine.full.val();
        }
        if self.tri_waits.q.val() {
            self.tri_busy.next = self.tester.engine.pending.val()
                | self.rays.pending.val()
                | self.instances.pending.val();
        }
        if self.enter_offer.q.val() {
            self.tri_busy.next = self.instances.refused.val() | self.tester.engine.full.val();
        }
        if self.normal_offer.q.val() {
            self.tri_busy.next = self.instances.refused.val();
        }
        if self.shade_offer.q.val() {
            self.tri_busy.next = self.shader.refused.val();
        }
        if self.ray_write.q.val() & self.store_write.val() {
            self.tri_busy.next = true;
        }
        // Traversal unit. It sees the object-space ray and t_min the thread gives the tester,
        // hands its leaves to the tester and takes the answers back.
        self.tester.walk_list_valid.next = self.traversal_unit.leaf_valid.val();
        self.tester.walk_list_thread.next = self.traversal_unit.leaf_thread.val();
        self.tester.walk_list_from.next = self.traversal_unit.leaf_from.val();
        self.tester.walk_list_to.next = self.traversal_unit.leaf_to.val();
        self.traversal_unit.leaf_take.next = self.tester.walk_list_take.val();
        self.traversal_unit.answer_valid.next = self.tester.walk_end_event.val();
        self.traversal_unit.answer_thread.next = self.tester.walk_end_thread.val();
        self.traversal_unit.answer_t.next = self.tester.walk_end_t.val();
        self.traversal_unit.answer_hit.next = self.tester.walk_end_hit.val();
        self.traversal_unit.t_min_write.next = self.t_min_write.q.val();
        self.traversal_unit.engine.enqueue.next = self.kd_enqueue.q.val();
        self.traversal_unit.engine_next.next = self.kd_answers.q.val();
        self.traversal_unit.enter.next = self.enter_offer.q.val()
            & (!self.instances.refused.val())
            & (!self.tester.engine.full.val());
        self.traversal_unit.entered.next = self.instances.ray_write.val();
        self.traversal_unit.world_write.next = self.world_write.q.val();
        self.traversal_unit.root_write.next = self.instances.root_write.val();
        self.traversal_unit.root_thread.next = self.instances.root_thread.val();
        self.traversal_unit.root.next = self.instances.root.val();
        self.traversal_unit.world_pair.next = self.decode.shift.val().get_bits::<2>(0);
        self.kd_busy.next = false;
        if self.kd_queues.q.val() {
            self.kd_busy.next = self.traversal_unit.engine.full.val();
        }
        if self.kd_waits.q.val() {
            self.kd_busy.next = self.traversal_unit.engine.pending.val();
        }

        // I5 into the result line.
        self.result_line.valid.next = self.decode.valid.val();
        self.result_line.op.next = self.decode.op.val();
        self.result_line.dst.next = self.decode.dst.val();
        self.result_line.thread.next = self.decode.thread.val();
        self.result_line.invert.next = self.decode.invert.val();
        self.result_line.pc.next = self.decode.pc.val();
        self.result_line.target.next = self.decode.target.val();
        self.result_line.is_wait.next = self.wait_fn.q.val();
        self.result_line.kd_busy.next = self.kd_busy.val();
        self.result_line.tri_busy.next = self.tri_busy.val();
        self.result_line.jr_target.next = self.decode.a.val().get_bits::<PC_BITS>(0);
        self.result_line.int_eq.next = self.execute.int_eq.val();
        self.result_line.int_lt.next = self.execute.int_lt.val();
        self.result_line.mb_hit.next = self.mailboxes.hit.val() & self.c_uses_mailboxes.val();
        self.result_line.pix_done.next = self.rays.exhausted.val();
        self.result_line.pix_busy.next = self.rays.refused.val();
        self.result_line.fast.next = self.execute.fast.val();
        self.result_line.kind.next = self.execute.kind.val();
        self.result_line.scratch_data.next = 0.into();
        if self.c_uses_scratch.val() {
            self.result_line.scratch_data.next = self.scratch.read_data.val();
        }
        self.result_line.mem_data.next = self.mem.rdata.val();
        self.result_line.nodes_data.next = self.bank0.rdata.val();
        self.result_line.a_data.next = self.bank2.rdata.val();
        self.result_line.b_data.next = self.bank3.rdata.val();

        // Write back.
        Retiring::join(
            &mut self.result_line.retiring,
            &mut self.write_back.retiring,
        );
        self.write_back.sum.next = self.fp_units.sum.val();
        self.write_back.product.next = self.fp_units.product.val();
        self.write_back.quotient.next = self.fp_units.quotient.val();
        self.write_back.root.next = self.fp_units.root.val();
        self.write_back.lt.next = self.fp_units.lt.val();
        self.write_back.le.next = self.fp_units.le.val();
        self.write_back.eq.next = self.fp_units.eq.val();
        self.write_back.colour_byte.next = self.fp_units.colour_byte.val();
        self.decode.wb_write.next = self.write_back.write.val();
        self.decode.wb_thread.next = self.write_back.thread.val();
        self.decode.wb_dst.next = self.write_back.dst.val();
        self.decode.wb_data.next = self.write_back.data.val();
        self.fetch.wb_valid.next = self.write_back.valid.val();
        self.fetch.wb_thread.next = self.write_back.thread.val();
        self.fetch.wb_halt.next = self.write_back.halt.val();
        self.fetch.wb_next_pc.next = self.write_back.next_pc.val();
        self.scheduler.wb_valid.next = self.write_back.valid.val();
        self.scheduler.wb_thread_mask.next = self.write_back.thread_mask.val();
        self.scheduler.wb_halt.next = self.write_back.halt.val();
        self.scheduler.wb_wait_pending.next = self.write_back.wait_pending.val();
        self.scheduler.tester_done.next = self.tester.engine.done.val();
        self.scheduler.tester_done_thread.next = self.tester.engine.done_thread.val();
        self.scheduler.walk_done.next = self.traversal_unit.engine.done.val();
        self.scheduler.walk_done_thread.next = self.traversal_unit.engine.done_thread.val();
        self.scheduler.ray_done_mask.next =
            self.rays.done_mask.val() | self.instances.done_mask.val();
        // Instructions retired: every write back but a turn spent offering again to a full
        // coprocessor queue or waiting for a coprocessor (the twin never repeats those).
        if self.write_back.retired.val() {
            self.instr_count.d.next = self.instr_count.q.val() + 1;
        }
        if self.write_back.valid.val() & self.write_back.halt.val() {
            self.halted_count.d.next = self.halted_count.q.val() + 1;
            if (self.halted_count.q.val() + 1) == self.c_threads.val() {
                self.running.d.next = false;
            }
        }

        // Start of a frame: a new epoch restarts every thread at pc 0.
        if self.frame_start.val() {
            self.running.d.next = true;
            self.epoch.d.next = !self.epoch.q.val();
            self.halted_count.d.next = 0.into();
            self.cycle_count.d.next = 0.into();
            self.instr_count.d.next = 0.into();
            self.transform_count.d.next = 0.into();
            self.intersect_count.d.next = 0.into();
            self.traversal_count.d.next = 0.into();
            self.raygen_count.d.next = 0.into();
            self.instance_count.d.next = 0.into();
            self.cache_hit_count.d.next = 0.into();
            self.cache_miss_count.d.next = 0.into();
            self.node_hit_count.d.next = 0.into();
            self.node_miss_count.d.next = 0.into();
            self.instance_hit_count.d.next = 0.into();
            self.instance_miss_count.d.next = 0.into();
            self.shading_count.d.next = 0.into();
        }
    }
}
