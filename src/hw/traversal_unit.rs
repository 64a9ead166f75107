//! `TraversalUnit`: the ray thread engine's coprocessor for object-level kd traversal. A thread
//! starts a walk (`kd.start root, t_max`) and sleeps until it ends (`kd.wait`); the unit steps
//! through inner nodes on its own (fetch the node from bank 0, decide with
//! `units::traversal_step`, push the far child on the thread's stack) until it reaches a
//! leaf, and hands the leaf's list to the triangle tester (`leaf_*`). With the leaf's closest
//! hit (the tester's `answer_*`) the unit ends the walk when that hit lies in the leaf's
//! segment or the walk answers any hit (`KD_ANY_HIT`), or pops the stack (ending when the
//! stack is empty or the popped segment starts behind the hit), exactly as
//! `model::golden`'s `traverse`.
//!
//! The same pipeline walks a scene's top-level tree (`kd.start` with `KD_TOP`) on the thread's
//! world ray (`world_write`, the engine's `tri.world`), with its stack at the unit's
//! `top_stack_base` (the scene's deepest object tree: the object walks under a top level have the
//! entries below it) and its leaf's segment kept apart from the object walks': at each leaf it
//! wakes the thread, which reads the leaf's list (`top_from`, `top_to`), walks the instances'
//! objects (object walks of this unit), and goes on with `next` (`kd.next`: the closest hit so far,
//! the thread's last answer, taken like the tester's answer for an object leaf); an empty leaf (two
//! in three on the dynamic scene) it passes by itself, with that answer. At the walk's end
//! `top_from` is `KD_WALK_ENDED`.
//!
//! Golden twin: [`units::KdWalk`](crate::units::KdWalk) (src/units.rs), one walk resumable at
//! each leaf, with [`units::traversal_step`](crate::units::traversal_step) and
//! [`units::split_distance`](crate::units::split_distance) for each inner node; they name this
//! unit back. Latency and throughput: see "Structure" below.
//!
//! Engine side (I4/I5, like the triangle tester): `enqueue` offers the start of a walk of `thread`
//! (root `word_a`, t_max `word_b`, t_min the thread's `t_min` written with the tester's init),
//! taken when `full` is low. `query_thread` at I4; at I5 `pending` (the thread's walk has not
//! ended); `done` with `done_thread` wakes a waiting thread, a clock after its walk ends or stops
//! at a top-level leaf. `enter` counts the walk of a `tri.enter`, which the unit starts when
//! instance entry writes the ray (`entered`). The entry offered at I5 must be of the thread
//! presented at I4 the clock before (its count of entries taken is read there), and a thread never
//! offers in two clocks in a row (the engine's scheduler guarantees both).
//!
//! Structure: entries go through the front (an engine's start becomes a step job; a tester's
//! answer reads the thread's leaf segment and stack and compares the hit with both in 5 clocks,
//! its own pipeline, one entry a clock) into the front queue; steps that continue go into the
//! loop queue, which the fetch serves first. Fetch: two words of bank 0 a job, the next job's
//! requests right behind (the engine's own loads of bank 0 go first; the words come back in
//! order), then the decision pipeline: `split - o` (FpAddSub), `/ d` (FpDiv), then five
//! FpCompares; at its end a push and the next step. Latency per inner node: `mem_latency + 4`
//! clocks of fetch (with `look`) plus `8 + DL + 2` of decision (`ADD_SUB_LATENCY + DL +
//! COMPARE_LATENCY`); throughput one node per [`FETCH_CLOCKS_PER_NODE`] (2) clocks from the
//! bank, one a clock from the node cache, while other threads' jobs fill the decision pipeline.
//! Each thread has at most one job in the unit, so the 32-entry queues never overflow.
//!
//! Node cache: up to [`MAX_CACHE_SETS`](super::cache::MAX_CACHE_SETS) (the paper's 512) items
//! of a node's two words, `cache_sets` sets (by the node's low bits) of `cache_ways` ways (1, 2
//! or 4), each way's tags (node and valid bit) and words in block RAMs of their own, so that a
//! set's ways are read at once (a way the cache does not have is never written, and synthesis
//! removes it: 2 ways take twice the words' block RAM of 1, 4 ways four times); a fill takes
//! its set's ways in turn (a count per set, read a clock before the fill with the set of the
//! job coming to A: fills are at least two clocks apart, one per node from the bank, so the
//! count read always has the last fill's write). 0 sets: none; off at SRAM latency
//! 1, where a cached node's words would come back before the FIFO behind them can pop. A job waits
//! for the fetch in `look`, whose cache set is read as it comes in; the set's tags and words read
//! are registered, and the job's tag is compared with them from its second clock in `look` (the
//! block RAM's output is not compared in the clock it comes out; a job the fetch takes in its first
//! clock goes to the bank); from the cache the fetch takes a node in a clock with no request, and
//! its words travel the latency line beside the bank's (in order, at the bank's latency). A node
//! from the bank is written into its set at A. Only the object trees' nodes are kept: the top
//! level's part of bank 0 is rewritten between an animated scene's frames (the object trees are
//! not), so the cache lives across frames. A set written in the clock it is read for `look` misses
//! (its words may be the old ones).
//!
//! Per thread: a stack of [`STACK_LEVELS`] entries `(node, lo, hi)`, the leaf's segment end
//! and stack depth. Const parameters: the operators' `W, E, M, S, S1, X2, T` and
//! `DL = div_latency(M)`.

use rust_hdl::prelude::*;

use super::cache::{cache_shape_supported, empty_cache_tags, FillCounts};
use super::fp::add_sub::ADD_SUB_LATENCY;
use super::fp::compare::COMPARE_LATENCY;
use super::fp::div::div_latency;
use super::fp::{const_bits, FpAddSub, FpCompare, FpDiv};
use super::ports::{CoprocessorPort, SramRead};
use super::program::isa::{KD_ENTERED, KD_WALK_ENDED};
use super::ray_store::{zero_counters, RayStore};
use super::{Delay, SyncFifo};
use crate::fp::Format;
use crate::layout;

/// The decision's delay lines: o, d, lo, hi, the split plane and the control wait for
/// `split - o`, then for the comparisons.
const SUB_DELAY: usize = ADD_SUB_LATENCY as usize;
const CMP_DELAY: usize = COMPARE_LATENCY as usize;

/// Entries of each thread's kd stack (the deepest object tree the unit walks).
pub const STACK_LEVELS: usize = 64;
/// Where a top-level walk's stack starts in the thread's stack when the scene has no top
/// level (the base is then never used) or in a test: an object walk under a top level has the
/// entries below the base, the top-level walk those above. A scene's processor puts it at its
/// deepest object tree ([`crate::hw::program::ProgramConfig::top_stack_base`]).
pub const DEFAULT_TOP_STACK_BASE: u32 = 32;

/// Clocks the fetch spends on one node from bank 0, its two words (the unit's throughput
/// bound without the node cache, which gives a node in one).
pub const FETCH_CLOCKS_PER_NODE: u32 = 2;

/// Engine queue entry: `{top[70], next[69], thread[68:64], a[63:32], b[31:0]}`.
type Entry = Bits<71>;
/// Step job: `{top[102], finish[101], thread[100:96], sp[95:90], node[89:64], lo[63:32],
/// hi[31:0]}` (nodes below 2^26).
type Job = Bits<103>;
/// Decision control: `{top[38], valid[37], thread[36:32], sp[31:26], left[25:0]}`.
type Control = Bits<39>;

/// The node fetch: idle, or requesting word 0 or word 1 of a node (two words a node).
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum Fetch {
    Idle,
    Word0,
    Word1,
}

#[derive(LogicBlock)]
pub struct TraversalUnit<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const DL: usize,
> {
    pub clock: Signal<In, Clock>,
    /// The engine's offers (`kd.start`: `word_a` the root with `KD_ANY_HIT`, `word_b`
    /// t_max), the thread's ray (object space: `ray_write` with `ray_pair` 0, 1, 2 as in the
    /// triangle tester), its walks pending, their ends (`done`), and the engine's loads of
    /// bank 0.
    pub engine: CoprocessorPort,
    /// `t_min_write`: the thread's t_min, in `engine.word_a` (the tester's `tri.init`).
    pub t_min_write: Signal<In, Bit>,
    /// A primary ray from ray generation, the whole ray of `primary_thread` at once
    /// ([`RayStore`]'s `primary_write`).
    pub primary_write: Signal<In, Bit>,
    pub primary_thread: Signal<In, Bits<5>>,
    pub primary_o: [Signal<In, Bits<W>>; 3],
    pub primary_d: [Signal<In, Bits<W>>; 3],
    /// Bank 0 (the kd nodes): one read per clock, the word `mem_latency` clocks later.
    pub nodes: SramRead,
    /// High in the clocks a node decision starts.
    pub step_busy: Signal<Out, Bit>,
    /// Leaves for the triangle tester: `leaf_thread`'s list, bank-1 words
    /// `leaf_from..leaf_to`; `leaf_take` pops it.
    pub leaf_valid: Signal<Out, Bit>,
    pub leaf_thread: Signal<Out, Bits<5>>,
    pub leaf_from: Signal<Out, Bits<32>>,
    pub leaf_to: Signal<Out, Bits<32>>,
    pub leaf_take: Signal<In, Bit>,
    /// The tester's answer for a leaf: `answer_thread`'s closest hit so far (`answer_t`,
    /// `answer_hit`). It goes into the queue ahead of the engine's entry of that clock.
    pub answer_valid: Signal<In, Bit>,
    pub answer_thread: Signal<In, Bits<5>>,
    pub answer_t: Signal<In, Bits<32>>,
    pub answer_hit: Signal<In, Bit>,
    /// The engine's offer is `kd.next` for the thread's top-level walk, not a start (the walk
    /// goes on with the thread's last answer; `word_a`, `word_b` are not read).
    pub engine_next: Signal<In, Bit>,
    /// The thread's world ray, pair `world_pair` (0, 1, 2 as `ray_pair`) from `word_a`,
    /// `word_b`.
    pub world_write: Signal<In, Bit>,
    pub world_pair: Signal<In, Bits<2>>,
    /// `tri.enter` (I5, with the engine's `thread`; all-or-none with the entry itself): the
    /// thread's walk of the entered object is counted (its `kd.wait` waits for it), any-hit
    /// when `word_b` has `KD_ANY_HIT`.
    pub enter: Signal<In, Bit>,
    /// The entered ray is written (with `primary_write`, of `primary_thread`): the unit
    /// starts the thread's walk of the entered object, as a start with `KD_ENTERED`. At most
    /// every other clock (instance entry's origin and direction results come between two
    /// writes), as the tester's answers: the start waits a clock behind an answer, at most.
    pub entered: Signal<In, Bit>,
    /// The object root of `root_thread`'s last instance entry (`KD_ENTERED` walks it).
    pub root_write: Signal<In, Bit>,
    pub root_thread: Signal<In, Bits<5>>,
    pub root: Signal<In, Bits<26>>,
    /// At I5, for the thread at I4 (`query_thread`): its top-level walk's leaf, the list's
    /// first bank-1 address (or `KD_WALK_ENDED` at the walk's end) and its end; after an
    /// object walk, `top_from` is the hit flag of the walk's last answer.
    pub top_from: Signal<Out, Bits<32>>,
    pub top_to: Signal<Out, Bits<32>>,

    entry_fifo: SyncFifo<Entry, 5, 6>,
    /// `{thread[68:64], from[63:32], to[31:0]}`: a thread has at most one leaf out.
    leaf_fifo: SyncFifo<Bits<69>, 5, 6>,
    /// Per thread: the walk answers any hit (a shadow query: `kd.start`'s root bit 31).
    any_hit: RAM<Bits<1>, 5>,
    engine_full: Signal<Local, Bit>,
    a_end: Signal<Local, Bit>,
    /// The leaf's list end: list address plus count.
    a_list_end: Signal<Local, Bits<32>>,
    front_fifo: SyncFifo<Job, 5, 6>,
    loop_fifo: SyncFifo<Job, 5, 6>,
    /// Per thread: ray o, d and t_min (engine-written); the world ray (engine-written);
    /// entries taken (engine); entries done (unit, read by the engine); per walk level (top
    /// or object) and thread the leaf segment end and stack depth (unit); the top-level
    /// leaf's list (unit, read by the engine).
    ray: RayStore<W>,
    world: RayStore<W>,
    issued: RAM<Bits<8>, 5>,
    done_e: RAM<Bits<8>, 5>,
    done_u: RAM<Bits<8>, 5>,
    leaf_hi: RAM<Bits<W>, 6>,
    leaf_sp: RAM<Bits<6>, 6>,
    top_from_ram: RAM<Bits<32>, 5>,
    top_to_ram: RAM<Bits<32>, 5>,
    /// Per thread: the entered object's root; the last answer to an object walk (or the
    /// top-level walk's t_max and no hit, from its start), read at f1 and (the hit) for A.
    entered_root: RAM<Bits<26>, 5>,
    last_t: RAM<Bits<W>, 5>,
    last_hit: RAM<Bits<1>, 5>,
    last_hit_a: RAM<Bits<1>, 5>,
    f1_answer: Signal<Local, Bit>,
    f1_top_start: Signal<Local, Bit>,
    f1_last_hit: Signal<Local, Bits<1>>,
    f1_last_write: Signal<Local, Bit>,
    f2_top_next: Signal<Local, Bit>,
    f2_entered: Signal<Local, Bit>,
    stack_node: RAM<Bits<26>, 11>,
    stack_lo: RAM<Bits<W>, 11>,
    stack_hi: RAM<Bits<W>, 11>,

    // Front: f1 reads the thread's leaf segment end, stack depth and t_min; f2 reads the
    // stack entry to pop and compares the hit with the leaf's end; f3 compares it with the
    // popped lo; f5 writes the job.
    f1_valid: DFF<Bit>,
    f1_next: DFF<Bit>,
    f1_top: DFF<Bit>,
    f1_thread: DFF<Bits<5>>,
    f1_a: DFF<Bits<32>>,
    f1_b: DFF<Bits<32>>,
    f2_valid: DFF<Bit>,
    f2_next: DFF<Bit>,
    f2_top: DFF<Bit>,
    f2_thread: DFF<Bits<5>>,
    f2_a: DFF<Bits<32>>,
    f2_b: DFF<Bits<32>>,
    f3_valid: DFF<Bit>,
    f3_next: DFF<Bit>,
    f3_top: DFF<Bit>,
    f3_thread: DFF<Bits<5>>,
    f3_a: DFF<Bits<32>>,
    f3_b: DFF<Bits<32>>,
    f3_sp: DFF<Bits<6>>,
    f3_t_min: DFF<Bits<W>>,
    f4_valid: DFF<Bit>,
    f4_next: DFF<Bit>,
    f4_top: DFF<Bit>,
    f4_thread: DFF<Bits<5>>,
    f4_a: DFF<Bits<32>>,
    f4_b: DFF<Bits<32>>,
    f4_sp: DFF<Bits<6>>,
    f4_t_min: DFF<Bits<W>>,
    f4_node: DFF<Bits<26>>,
    f4_lo: DFF<Bits<W>>,
    f4_hi: DFF<Bits<W>>,
    f5_valid: DFF<Bit>,
    f5_next: DFF<Bit>,
    f5_top: DFF<Bit>,
    f5_thread: DFF<Bits<5>>,
    f5_a: DFF<Bits<32>>,
    f5_b: DFF<Bits<32>>,
    f5_sp: DFF<Bits<6>>,
    f5_t_min: DFF<Bits<W>>,
    f5_node: DFF<Bits<26>>,
    f5_lo: DFF<Bits<W>>,
    f5_hi: DFF<Bits<W>>,
    f5_in_leaf: DFF<Bit>,
    /// hit t <= leaf end (the hit lies in the segment just searched); hit t < popped lo.
    cmp_leaf: FpCompare<W, E, M>,
    cmp_pop: FpCompare<W, E, M>,
    f2_sp: Signal<Local, Bits<6>>,
    /// Depths after a pop, wrapped in 6 bits (the Verilog of an expression would widen it).
    f2_pop: Signal<Local, Bits<6>>,
    f5_pop: Signal<Local, Bits<6>>,
    /// The empty stack's depth of the walk's level (0, or the top-level walk's base).
    f5_base: Signal<Local, Bits<6>>,
    f5_root: Signal<Local, Bits<26>>,
    f1_leaf_address: Signal<Local, Bits<6>>,
    front_end: Signal<Local, Bit>,
    front_job: Signal<Local, Job>,

    // Fetch: `phase` requests the words of `fetch_job`; `job` is at A.
    phase: DFF<Fetch>,
    fetch_job: DFF<Job>,
    fetch_free: Signal<Local, Bit>,
    /// The job at A next clock: its thread's count of entries done and its node's set's next
    /// way to fill are read now.
    next_a_job: Signal<Local, Job>,
    /// Jobs whose words are requested, oldest first (at most `mem_latency + 1`: one a clock from
    /// the cache).
    in_flight: SyncFifo<Job, 3, 4>,
    job: DFF<Job>,
    words_in: DFF<Bits<2>>,
    w0: DFF<Bits<32>>,
    w1: DFF<Bits<32>>,
    take: Signal<Local, Bit>,
    /// Requests in flight: `{cached[2], valid[1], word[0]}` per clock of latency (`cached`:
    /// a node from the cache, both its words in `data_line`, at the bank's latency so that
    /// the words come back in order).
    node_line: [DFF<Bits<3>>; 6],
    arrive: Signal<Local, Bits<3>>,
    /// The words of the node from the cache beside `node_line[k]`: `{w1, w0}`.
    data_line: [DFF<Bits<64>>; 6],
    arrive_data: Signal<Local, Bits<64>>,
    // The node cache (see "Node cache" in the module's doc).
    /// `look_job` waits for the fetch (the cache was read for it in the clock it came in).
    look_valid: DFF<Bit>,
    look_job: DFF<Job>,
    /// The cache's set written in the clock it was read for `look_job` (its words may be the
    /// old ones: a miss).
    look_stale: DFF<Bit>,
    /// The set's tag and words as read last clock, and whether they were stale: a job in
    /// `look` compares its tag with them from its second clock there (`look_ready`); one
    /// that the fetch takes in its first clock goes to the bank (the fetch was idle, so the
    /// bank's two clocks cost nothing, and the latency is the same). (The block RAM's 5.6 ns
    /// clock to out ran through the compare into `fetch_hit` when the read word was compared
    /// as it came out: cornell's placed critical path at stop 47, `traversal_unit.cache_tag
    /// -> fetch_hit`, 75.9 MHz.)
    tag_word_r: [DFF<Bits<27>>; 4],
    words_r: [DFF<Bits<64>>; 4],
    stale_r: DFF<Bit>,
    look_ready: DFF<Bit>,
    look_move: Signal<Local, Bit>,
    look_load: Signal<Local, Bit>,
    look_hit: Signal<Local, Bit>,
    /// The set read this clock (`look_job`'s next clock).
    read_set: Signal<Local, Bits<9>>,
    /// Per set: `{valid[26], node[25:0]}`, and the node's words `{w1, w0}`.
    cache_tag: [RAM<Bits<27>, 9>; 4],
    cache_words: [RAM<Bits<64>, 9>; 4],
    /// The way `look_job`'s node is in (when `look_hit`).
    look_way_hit: [Signal<Local, Bit>; 4],
    /// Per set, the way its next fill writes (round robin).
    fill_counts: FillCounts,
    /// `fetch_job`'s node is in the cache, with its words: the fetch takes it in a clock.
    fetch_hit: DFF<Bit>,
    fetch_words: DFF<Bits<64>>,
    hit_now: Signal<Local, Bit>,
    /// The words of the node at A came from bank 0: written into the cache.
    a_fetched: DFF<Bit>,
    fill: Signal<Local, Bit>,
    fill_set: Signal<Local, Bits<9>>,
    /// High in the clock a node's fetch takes it from the cache, or requests its first word
    /// from bank 0 (an object tree's node: the top level's nodes are not cached).
    pub cache_hit: Signal<Out, Bit>,
    pub cache_miss: Signal<Out, Bit>,
    /// Named apart from the triangle tester's cache constants: the engine's stages share one
    /// namespace of constants (`tests/generated_files.rs` holds each name to one value).
    c_node_set_mask: Constant<Bits<9>>,
    c_node_cache_on: Constant<Bit>,
    c_node_tag_valid: Constant<Bits<27>>,
    /// `ways - 1`, each way's number, and whether the cache has that way.
    c_node_way_mask: Constant<Bits<2>>,
    c_node_way: [Constant<Bits<2>>; 4],
    c_node_way_used: [Constant<Bit>; 4],
    // A: the node's words are here.
    at_a: Signal<Local, Bit>,
    a_leaf: Signal<Local, Bit>,
    a_axis: Signal<Local, Bits<2>>,
    a_o: Signal<Local, Bits<W>>,
    a_d: Signal<Local, Bits<W>>,
    a_inner: Signal<Local, Bit>,
    a_top: Signal<Local, Bit>,
    a_ray_o: [Signal<Local, Bits<W>>; 3],
    a_ray_d: [Signal<Local, Bits<W>>; 3],
    a_top_leaf: Signal<Local, Bit>,
    a_leaf_address: Signal<Local, Bits<6>>,
    a_done: Signal<Local, Bit>,
    a_empty_top: Signal<Local, Bit>,
    /// An empty top-level leaf's thread, whose walk goes on in the front's next clock.
    skip_valid: DFF<Bit>,
    /// An entered object's walk to start: it takes the entry queue in a clock without a
    /// tester's answer (those come at least `LAUNCH_SPACING` = 2 clocks apart, so it waits at
    /// most a clock; entries 16), ahead of the engine.
    entered_valid: DFF<Bit>,
    entered_thread: DFF<Bits<5>>,
    /// The wake-up, a clock after the count of entries done is written (the engine's
    /// scheduler remembers a wake-up that comes before the waiter's write back): from A it
    /// was a placed path of 8.9 ns routing into the scheduler (87.5 MHz). (A one-hot mask
    /// decoded before the register placed worse: 73.5 / 77.3 MHz, see the README.)
    done_r: DFF<Bit>,
    done_thread_r: DFF<Bits<5>>,
    skip_thread: DFF<Bits<5>>,

    // Decision.
    sub: FpAddSub<W, E, M, S, S1, X2, T>,
    div: FpDiv<W, E, M, S, S1, X2>,
    /// o, d, lo, hi and the split plane wait for t_split.
    o_delay: [Delay<Bits<W>, SUB_DELAY>; 5],
    o_delay_div: [Delay<Bits<W>, DL>; 5],
    control_delay: Delay<Control, SUB_DELAY>,
    control_delay_div: Delay<Control, DL>,
    control_delay_cmp: Delay<Control, CMP_DELAY>,
    /// (o, split), (d, 0), (hi, t_split), (t_split, 0), (t_split, lo).
    cmp: [FpCompare<W, E, M>; 5],
    ts_delay: Delay<Bits<W>, CMP_DELAY>,
    lo_delay: Delay<Bits<W>, CMP_DELAY>,
    hi_delay: Delay<Bits<W>, CMP_DELAY>,
    d_valid: Signal<Local, Bit>,
    d_thread: Signal<Local, Bits<5>>,
    d_sp: Signal<Local, Bits<6>>,
    d_left: Signal<Local, Bits<26>>,
    d_near_left: Signal<Local, Bit>,
    d_near: Signal<Local, Bits<26>>,
    d_far: Signal<Local, Bits<26>>,
    d_top: Signal<Local, Bit>,

    c_ml_last: Constant<Bits<4>>,
    c_index: [Constant<Bits<4>>; 6],
    c_zero: Constant<Bits<W>>,
    /// Bank 0's bit of the engine's `load_banks`.
    c_bank_nodes: Constant<Bits<{ layout::BANKS }>>,
    c_leaf_tag: Constant<Bits<2>>,
    c_top_base: Constant<Bits<6>>,
    /// The scene has a top level: without, no job is a top-level one, so the world ray's store
    /// is never read and synthesis removes it.
    c_top_level: Constant<Bit>,
    c_walk_ended: Constant<Bits<32>>,
    /// An entered object's start: `KD_ENTERED`.
    c_entered: Constant<Bits<32>>,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const DL: usize,
    > TraversalUnit<W, E, M, S, S1, X2, T, DL>
{
    /// The unit for SRAM read latency `mem_latency` (1..=6) and a node cache of `cache_sets`
    /// sets of `cache_ways` ways (0 sets: none; see [`cache_shape_supported`]).
    /// A top-level walk's stack starts at entry `top_stack_base` of the thread's
    /// [`STACK_LEVELS`]; `top_level` is false for a scene without a top level.
    pub fn new(
        mem_latency: u32,
        top_stack_base: u32,
        top_level: bool,
        cache_sets: u32,
        cache_ways: u32,
    ) -> Self {
        assert!((1..=6).contains(&mem_latency));
        assert!(
            cache_shape_supported(cache_sets, cache_ways),
            "node cache: {cache_sets} sets of {cache_ways} ways"
        );
        assert!((1..STACK_LEVELS as u32).contains(&top_stack_base));
        assert!(DL == div_latency(M as u32) as usize);
        let f = Format::new(E as u32, M as u32).expect("a supported format");
        Self {
            clock: Default::default(),
            engine: Default::default(),
            nodes: Default::default(),
            t_min_write: Default::default(),
            primary_write: Default::default(),
            primary_thread: Default::default(),
            primary_o: Default::default(),
            primary_d: Default::default(),
            step_busy: Default::default(),
            leaf_valid: Default::default(),
            leaf_thread: Default::default(),
            leaf_from: Default::default(),
            leaf_to: Default::default(),
            leaf_take: Default::default(),
            answer_valid: Default::default(),
            answer_thread: Default::default(),
            answer_t: Default::default(),
            answer_hit: Default::default(),
            engine_next: Default::default(),
            enter: Default::default(),
            entered: Default::default(),
            world_write: Default::default(),
            world_pair: Default::default(),
            root_write: Default::default(),
            root_thread: Default::default(),
            root: Default::default(),
            top_from: Default::default(),
            top_to: Default::default(),
            entry_fifo: Default::default(),
            leaf_fifo: Default::default(),
            any_hit: Default::default(),
            engine_full: Default::default(),
            a_end: Default::default(),
            a_list_end: Default::default(),
            front_fifo: Default::default(),
            loop_fifo: Default::default(),
            ray: Default::default(),
            world: Default::default(),
            issued: zero_counters(),
            done_e: zero_counters(),
            done_u: zero_counters(),
            leaf_hi: Default::default(),
            leaf_sp: Default::default(),
            top_from_ram: Default::default(),
            top_to_ram: Default::default(),
            entered_root: Default::default(),
            last_t: Default::default(),
            last_hit: Default::default(),
            last_hit_a: Default::default(),
            f1_answer: Default::default(),
            f1_top_start: Default::default(),
            f1_last_hit: Default::default(),
            f1_last_write: Default::default(),
            f2_top_next: Default::default(),
            f2_entered: Default::default(),
            stack_node: Default::default(),
            stack_lo: Default::default(),
            stack_hi: Default::default(),
            f1_valid: Default::default(),
            f1_next: Default::default(),
            f1_top: Default::default(),
            f1_thread: Default::default(),
            f1_a: Default::default(),
            f1_b: Default::default(),
            f2_valid: Default::default(),
            f2_next: Default::default(),
            f2_top: Default::default(),
            f2_thread: Default::default(),
            f2_a: Default::default(),
            f2_b: Default::default(),
            f3_valid: Default::default(),
            f3_next: Default::default(),
            f3_top: Default::default(),
            f3_thread: Default::default(),
            f3_a: Default::default(),
            f3_b: Default::default(),
            f3_sp: Default::default(),
            f3_t_min: Default::default(),
            f4_valid: Default::default(),
            f4_next: Default::default(),
            f4_top: Default::default(),
            f4_thread: Default::default(),
            f4_a: Default::default(),
            f4_b: Default::default(),
            f4_sp: Default::default(),
            f4_t_min: Default::default(),
            f4_node: Default::default(),
            f4_lo: Default::default(),
            f4_hi: Default::default(),
            f5_valid: Default::default(),
            f5_next: Default::default(),
            f5_top: Default::default(),
            f5_thread: Default::default(),
            f5_a: Default::default(),
            f5_b: Default::default(),
            f5_sp: Default::default(),
            f5_t_min: Default::default(),
            f5_node: Default::default(),
            f5_lo: Default::default(),
            f5_hi: Default::default(),
            f5_in_leaf: Default::default(),
            cmp_leaf: Default::default(),
            cmp_pop: Default::default(),
            f2_sp: Default::default(),
            f2_pop: Default::default(),
            f5_pop: Default::default(),
            f5_base: Default::default(),
            f5_root: Default::default(),
            f1_leaf_address: Default::default(),
            front_end: Default::default(),
            front_job: Default::default(),
            phase: Default::default(),
            fetch_job: Default::default(),
            fetch_free: Default::default(),
            next_a_job: Default::default(),
            in_flight: Default::default(),
            job: Default::default(),
            words_in: Default::default(),
            w0: Default::default(),
            w1: Default::default(),
            take: Default::default(),
            node_line: Default::default(),
            arrive: Default::default(),
            data_line: Default::default(),
            arrive_data: Default::default(),
            look_valid: Default::default(),
            look_job: Default::default(),
            look_stale: Default::default(),
            tag_word_r: Default::default(),
            words_r: Default::default(),
            stale_r: Default::default(),
            look_ready: Default::default(),
            look_move: Default::default(),
            look_load: Default::default(),
            look_hit: Default::default(),
            read_set: Default::default(),
            cache_tag: std::array::from_fn(|_| empty_cache_tags()),
            cache_words: Default::default(),
            look_way_hit: Default::default(),
            fill_counts: Default::default(),
            fetch_hit: Default::default(),
            fetch_words: Default::default(),
            hit_now: Default::default(),
            a_fetched: Default::default(),
            fill: Default::default(),
            fill_set: Default::default(),
            cache_hit: Default::default(),
            cache_miss: Default::default(),
            c_node_set_mask: Constant::new(u64::from(cache_sets.max(1) - 1).into()),
            c_node_cache_on: Constant::new(cache_sets > 0 && mem_latency >= 2),
            c_node_tag_valid: Constant::new((1u64 << 26).into()),
            c_node_way_mask: Constant::new(u64::from(cache_ways - 1).into()),
            c_node_way: std::array::from_fn(|w| Constant::new((w as u64).into())),
            c_node_way_used: std::array::from_fn(|w| {
                Constant::new(cache_sets > 0 && (w as u32) < cache_ways)
            }),
            at_a: Default::default(),
            a_leaf: Default::default(),
            a_axis: Default::default(),
            a_o: Default::default(),
            a_d: Default::default(),
            a_inner: Default::default(),
            a_top: Default::default(),
            a_ray_o: Default::default(),
            a_ray_d: Default::default(),
            a_top_leaf: Default::default(),
            a_leaf_address: Default::default(),
            a_done: Default::default(),
            a_empty_top: Default::default(),
            skip_valid: Default::default(),
            skip_thread: Default::default(),
            entered_valid: Default::default(),
            entered_thread: Default::default(),
            done_r: Default::default(),
            done_thread_r: Default::default(),
            sub: Default::default(),
            div: Default::default(),
            o_delay: Default::default(),
            o_delay_div: Default::default(),
            control_delay: Default::default(),
            control_delay_div: Default::default(),
            control_delay_cmp: Default::default(),
            cmp: Default::default(),
            ts_delay: Default::default(),
            lo_delay: Default::default(),
            hi_delay: Default::default(),
            d_valid: Default::default(),
            d_thread: Default::default(),
            d_sp: Default::default(),
            d_left: Default::default(),
            d_near_left: Default::default(),
            d_near: Default::default(),
            d_far: Default::default(),
            d_top: Default::default(),
            c_ml_last: Constant::new(u64::from(mem_latency - 1).into()),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_zero: const_bits::<W>(u64::from(f.zero(false))),
            c_bank_nodes: Constant::new((1u64 << layout::NODES).into()),
            c_leaf_tag: Constant::new(u64::from(layout::LEAF_TAG).into()),
            c_top_base: Constant::new(u64::from(top_stack_base).into()),
            c_top_level: Constant::new(top_level),
            c_walk_ended: Constant::new(u64::from(KD_WALK_ENDED).into()),
            c_entered: Constant::new(u64::from(KD_ENTERED).into()),
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
        const DL: usize,
    > Logic for TraversalUnit<W, E, M, S, S1, X2, T, DL>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            f1_valid,
            f1_next,
            f1_top,
            f1_thread,
            f1_a,
            f1_b,
            f2_valid,
            f2_next,
            f2_top,
            f2_thread,
            f2_a,
            f2_b,
            f3_valid,
            f3_next,
            f3_top,
            f3_thread,
            f3_a,
            f3_b,
            f3_sp,
            f3_t_min,
            f4_valid,
            f4_next,
            f4_top,
            f4_thread,
            f4_a,
            f4_b,
            f4_sp,
            f4_t_min,
            f4_node,
            f4_lo,
            f4_hi,
            f5_valid,
            f5_next,
            f5_top,
            f5_thread,
            f5_a,
            f5_b,
            f5_sp,
            f5_t_min,
            f5_node,
            f5_lo,
            f5_hi,
            f5_in_leaf,
            phase,
            fetch_job,
            job,
            words_in,
            w0,
            w1,
            look_valid,
            look_job,
            look_stale,
            stale_r,
            look_ready,
            fetch_hit,
            fetch_words,
            a_fetched,
            skip_valid,
            skip_thread,
            entered_valid,
            entered_thread,
            done_r,
            done_thread_r
        );
        clock!(
            self,
            clock,
            entry_fifo,
            leaf_fifo,
            in_flight,
            front_fifo,
            loop_fifo,
            ray,
            world,
            cmp_leaf,
            cmp_pop,
            sub,
            div,
            control_delay,
            control_delay_div,
            control_delay_cmp,
            ts_delay,
            lo_delay,
            hi_delay
        );
        self.issued.read_clock.next = self.clock.val();
        self.issued.write_clock.next = self.clock.val();
        self.any_hit.read_clock.next = self.clock.val();
        self.any_hit.write_clock.next = self.clock.val();
        self.done_e.read_clock.next = self.clock.val();
        self.done_e.write_clock.next = self.clock.val();
        self.done_u.read_clock.next = self.clock.val();
        self.done_u.write_clock.next = self.clock.val();
        self.leaf_hi.read_clock.next = self.clock.val();
        self.leaf_hi.write_clock.next = self.clock.val();
        self.leaf_sp.read_clock.next = self.clock.val();
        self.leaf_sp.write_clock.next = self.clock.val();
        self.top_from_ram.read_clock.next = self.clock.val();
        self.top_from_ram.write_clock.next = self.clock.val();
        self.top_to_ram.read_clock.next = self.clock.val();
        self.top_to_ram.write_clock.next = self.clock.val();
        self.entered_root.read_clock.next = self.clock.val();
        self.entered_root.write_clock.next = self.clock.val();
        self.last_t.read_clock.next = self.clock.val();
        self.last_t.write_clock.next = self.clock.val();
        self.last_hit.read_clock.next = self.clock.val();
        self.last_hit.write_clock.next = self.clock.val();
        self.last_hit_a.read_clock.next = self.clock.val();
        self.last_hit_a.write_clock.next = self.clock.val();
        self.stack_node.read_clock.next = self.clock.val();
        self.stack_node.write_clock.next = self.clock.val();
        self.stack_lo.read_clock.next = self.clock.val();
        self.stack_lo.write_clock.next = self.clock.val();
        self.stack_hi.read_clock.next = self.clock.val();
        self.stack_hi.write_clock.next = self.clock.val();
        for w in 0..4 {
            self.cache_tag[w].read_clock.next = self.clock.val();
            self.cache_tag[w].write_clock.next = self.clock.val();
            self.cache_words[w].read_clock.next = self.clock.val();
            self.cache_words[w].write_clock.next = self.clock.val();
            self.tag_word_r[w].clock.next = self.clock.val();
            self.words_r[w].clock.next = self.clock.val();
        }
        self.fill_counts.clock.next = self.clock.val();
        for k in 0..6 {
            self.node_line[k].clock.next = self.clock.val();
            self.data_line[k].clock.next = self.clock.val();
        }
        for k in 0..5 {
            self.o_delay[k].clock.next = self.clock.val();
            self.o_delay_div[k].clock.next = self.clock.val();
        }
        for k in 0..5 {
            self.cmp[k].clock.next = self.clock.val();
        }

        // Engine side: the ray, t_min, the queue, the answers.
        self.ray.thread.next = self.engine.thread.val();
        self.ray.word_a.next = self.engine.word_a.val();
        self.ray.word_b.next = self.engine.word_b.val();
        self.ray.ray_write.next = self.engine.ray_write.val();
        self.ray.ray_pair.next = self.engine.ray_pair.val();
        self.ray.t_min_write.next = self.t_min_write.val();
        self.ray.primary_write.next = self.primary_write.val();
        self.ray.primary_thread.next = self.primary_thread.val();
        for k in 0..3 {
            self.ray.primary_o[k].next = self.primary_o[k].val();
            self.ray.primary_d[k].next = self.primary_d[k].val();
        }
        self.world.thread.next = self.engine.thread.val();
        self.world.word_a.next = self.engine.word_a.val();
        self.world.word_b.next = self.engine.word_b.val();
        self.world.ray_write.next = self.world_write.val();
        self.world.ray_pair.next = self.world_pair.val();
        self.world.t_min_write.next = false;
        self.world.primary_write.next = false;
        self.world.primary_thread.next = 0.into();
        for k in 0..3 {
            self.world.primary_o[k].next = 0.into();
            self.world.primary_d[k].next = 0.into();
        }
        self.world.t_min_thread.next = 0.into();
        self.top_from_ram.read_address.next = self.engine.query_thread.val();
        self.top_to_ram.read_address.next = self.engine.query_thread.val();
        self.top_from.next = self.top_from_ram.read_data.val();
        self.top_to.next = self.top_to_ram.read_data.val();
        // The tester's answer takes the queue first, then an entered object's start (a
        // thread has one entry in the unit at a time, so the queue never overflows with
        // them).
        if self.entered.val() {
            self.entered_valid.d.next = true;
            self.entered_thread.d.next = self.primary_thread.val();
        } else if !self.answer_valid.val() {
            self.entered_valid.d.next = false;
        }
        self.engine_full.next =
            self.entry_fifo.full.val() | self.answer_valid.val() | self.entered_valid.q.val();
        self.engine.full.next = self.engine_full.val();
        self.entry_fifo.write.next = (self.engine.enqueue.val() & (!self.engine_full.val()))
            | self.answer_valid.val()
            | self.entered_valid.q.val();
        // Bit 69: an answer (0: the engine's start); bit 70: of the top-level walk (an
        // engine's `next`, or a start with `KD_TOP`).
        self.entry_fifo.data_in.next = (bit_cast::<71, 1>(
            (self.engine_next.val() | self.engine.word_a.val().get_bit(30)).into(),
        ) << 70)
            | (bit_cast::<71, 1>(self.engine_next.val().into()) << 69)
            | (bit_cast::<71, 5>(self.engine.thread.val()) << 64)
            | (bit_cast::<71, 32>(self.engine.word_a.val()) << 32)
            | bit_cast::<71, 32>(self.engine.word_b.val());
        if self.entered_valid.q.val() {
            self.entry_fifo.data_in.next = (bit_cast::<71, 5>(self.entered_thread.q.val()) << 64)
                | (bit_cast::<71, 32>(self.c_entered.val()) << 32);
        }
        if self.answer_valid.val() {
            self.entry_fifo.data_in.next = (bit_cast::<71, 1>(true.into()) << 69)
                | (bit_cast::<71, 5>(self.answer_thread.val()) << 64)
                | (bit_cast::<71, 32>(self.answer_t.val()) << 32)
                | bit_cast::<71, 1>(self.answer_hit.val().into());
        }
        self.any_hit.write_address.next = self.engine.thread.val();
        self.any_hit.write_data.next =
            bit_cast::<1, 1>(self.engine.word_a.val().get_bit(31).into());
        if self.enter.val() {
            self.any_hit.write_data.next =
                bit_cast::<1, 1>(self.engine.word_b.val().get_bit(31).into());
        }
        self.any_hit.write_enable.next =
            (self.engine.enqueue.val() & (!self.engine_full.val()) & (!self.engine_next.val()))
                | self.enter.val();
        self.issued.read_address.next = self.engine.query_thread.val();
        self.done_e.read_address.next = self.engine.query_thread.val();
        self.engine.pending.next = self.issued.read_data.val() != self.done_e.read_data.val();
        self.issued.write_address.next = self.engine.thread.val();
        self.issued.write_data.next = self.issued.read_data.val() + 1;
        self.issued.write_enable.next =
            (self.engine.enqueue.val() & (!self.engine_full.val())) | self.enter.val();

        // Front: one engine entry a clock, a job five clocks later.
        // An empty top-level leaf goes on at once, as a `next` with the thread's last answer,
        // ahead of the queue's entry (which waits a clock).
        self.entry_fifo.read.next = (!self.entry_fifo.empty.val()) & (!self.skip_valid.q.val());
        self.f1_valid.d.next = (!self.entry_fifo.empty.val()) | self.skip_valid.q.val();
        self.f1_next.d.next = self.entry_fifo.data_out.val().get_bit(69);
        self.f1_top.d.next = self.entry_fifo.data_out.val().get_bit(70);
        self.f1_thread.d.next = self.entry_fifo.data_out.val().get_bits::<5>(64);
        self.f1_a.d.next = self.entry_fifo.data_out.val().get_bits::<32>(32);
        self.f1_b.d.next = self.entry_fifo.data_out.val().get_bits::<32>(0);
        if self.skip_valid.q.val() {
            self.f1_next.d.next = true;
            self.f1_top.d.next = true;
            self.f1_thread.d.next = self.skip_thread.q.val();
        }
        self.f1_leaf_address.next = (bit_cast::<6, 1>(self.f1_top.q.val().into()) << 5)
            | bit_cast::<6, 5>(self.f1_thread.q.val());
        self.leaf_hi.read_address.next = self.f1_leaf_address.val();
        self.leaf_sp.read_address.next = self.f1_leaf_address.val();
        self.ray.t_min_thread.next = self.f1_thread.q.val();
        // The last answer: a tester's answer, or a top-level start's (t_max, no hit).
        self.f1_answer.next = self.f1_next.q.val() & (!self.f1_top.q.val());
        self.f1_top_start.next = (!self.f1_next.q.val()) & self.f1_top.q.val();
        self.last_t.write_address.next = self.f1_thread.q.val();
        self.last_hit.write_address.next = self.f1_thread.q.val();
        self.last_hit_a.write_address.next = self.f1_thread.q.val();
        self.last_t.write_data.next = self.f1_a.q.val().get_bits::<W>(0);
        self.f1_last_hit.next = bit_cast::<1, 1>(self.f1_b.q.val().get_bit(0).into());
        if self.f1_top_start.val() {
            self.last_t.write_data.next = self.f1_b.q.val().get_bits::<W>(0);
            self.f1_last_hit.next = 0.into();
        }
        self.last_hit.write_data.next = self.f1_last_hit.val();
        self.last_hit_a.write_data.next = self.f1_last_hit.val();
        self.f1_last_write.next =
            self.f1_valid.q.val() & (self.f1_answer.val() | self.f1_top_start.val());
        self.last_t.write_enable.next = self.f1_last_write.val();
        self.last_hit.write_enable.next = self.f1_last_write.val();
        self.last_hit_a.write_enable.next = self.f1_last_write.val();
        self.last_t.read_address.next = self.f1_thread.q.val();
        self.last_hit.read_address.next = self.f1_thread.q.val();
        self.f2_valid.d.next = self.f1_valid.q.val();
        self.f2_next.d.next = self.f1_next.q.val();
        self.f2_top.d.next = self.f1_top.q.val();
        self.f2_thread.d.next = self.f1_thread.q.val();
        self.f2_a.d.next = self.f1_a.q.val();
        self.f2_b.d.next = self.f1_b.q.val();
        // f2: the thread's leaf end, depth and t_min are here.
        self.f2_sp.next = self.leaf_sp.read_data.val();
        self.f2_pop.next = self.f2_sp.val() - 1;
        // A top-level `next` goes on with the last answer; an entered object's start walks
        // its root up to the last answer's t.
        self.f2_top_next.next = self.f2_next.q.val() & self.f2_top.q.val();
        self.f2_entered.next =
            (!self.f2_next.q.val()) & (!self.f2_top.q.val()) & self.f2_a.q.val().get_bit(29);
        self.cmp_leaf.in_valid.next = true;
        self.cmp_leaf.a.next = self.f2_a.q.val().get_bits::<W>(0);
        if self.f2_top_next.val() {
            self.cmp_leaf.a.next = self.last_t.read_data.val();
        }
        self.cmp_leaf.b.next = self.leaf_hi.read_data.val();
        self.stack_node.read_address.next =
            (bit_cast::<11, 5>(self.f2_thread.q.val()) << 6) | bit_cast::<11, 6>(self.f2_pop.val());
        self.stack_lo.read_address.next =
            (bit_cast::<11, 5>(self.f2_thread.q.val()) << 6) | bit_cast::<11, 6>(self.f2_pop.val());
        self.stack_hi.read_address.next =
            (bit_cast::<11, 5>(self.f2_thread.q.val()) << 6) | bit_cast::<11, 6>(self.f2_pop.val());
        self.f3_valid.d.next = self.f2_valid.q.val();
        self.f3_next.d.next = self.f2_next.q.val();
        self.f3_top.d.next = self.f2_top.q.val();
        self.f3_thread.d.next = self.f2_thread.q.val();
        self.f3_a.d.next = self.f2_a.q.val();
        self.f3_b.d.next = self.f2_b.q.val();
        if self.f2_top_next.val() {
            self.f3_a.d.next = bit_cast::<32, W>(self.last_t.read_data.val());
            self.f3_b.d.next = bit_cast::<32, 1>(self.last_hit.read_data.val());
        }
        if self.f2_entered.val() {
            self.f3_b.d.next = bit_cast::<32, W>(self.last_t.read_data.val());
        }
        self.f3_sp.d.next = self.f2_sp.val();
        self.f3_t_min.d.next = self.ray.t_min.val();
        // f3: the popped entry is here.
        self.cmp_pop.in_valid.next = true;
        self.cmp_pop.a.next = self.f3_a.q.val().get_bits::<W>(0);
        self.cmp_pop.b.next = self.stack_lo.read_data.val();
        self.f4_valid.d.next = self.f3_valid.q.val();
        self.f4_next.d.next = self.f3_next.q.val();
        self.f4_top.d.next = self.f3_top.q.val();
        self.f4_thread.d.next = self.f3_thread.q.val();
        self.f4_a.d.next = self.f3_a.q.val();
        self.f4_b.d.next = self.f3_b.q.val();
        self.f4_sp.d.next = self.f3_sp.q.val();
        self.f4_t_min.d.next = self.f3_t_min.q.val();
        self.f4_node.d.next = self.stack_node.read_data.val();
        self.f4_lo.d.next = self.stack_lo.read_data.val();
        self.f4_hi.d.next = self.stack_hi.read_data.val();
        self.f5_valid.d.next = self.f4_valid.q.val();
        self.f5_next.d.next = self.f4_next.q.val();
        self.f5_top.d.next = self.f4_top.q.val();
        self.f5_thread.d.next = self.f4_thread.q.val();
        self.f5_a.d.next = self.f4_a.q.val();
        self.f5_b.d.next = self.f4_b.q.val();
        self.f5_sp.d.next = self.f4_sp.q.val();
        self.f5_t_min.d.next = self.f4_t_min.q.val();
        self.f5_node.d.next = self.f4_node.q.val();
        self.f5_lo.d.next = self.f4_lo.q.val();
        self.f5_hi.d.next = self.f4_hi.q.val();
        self.f5_in_leaf.d.next = self.cmp_leaf.le.val();
        self.any_hit.read_address.next = self.f4_thread.q.val();
        self.entered_root.read_address.next = self.f4_thread.q.val();
        self.entered_root.write_address.next = self.root_thread.val();
        self.entered_root.write_data.next = self.root.val();
        self.entered_root.write_enable.next = self.root_write.val();
        // f5: a start steps from the root (`a`) with [t_min, t_max = `b`]; a next ends the
        // walk when the hit lies in the leaf's segment, the walk answers any hit, the stack is
        // empty or the popped segment starts behind the hit, else steps from the popped entry.
        // A top-level walk's stack starts at the base (its `next` never comes after
        // an answered any-hit query, so the thread's any-hit flag is that of no walk of its).
        self.f5_pop.next = self.f5_sp.q.val() - 1;
        self.f5_base.next = 0.into();
        if self.f5_top.q.val() {
            self.f5_base.next = self.c_top_base.val();
        }
        self.front_end.next = self.f5_next.q.val()
            & ((self.f5_b.q.val().get_bit(0) & self.f5_in_leaf.q.val())
                | (self.f5_b.q.val().get_bit(0) & (self.any_hit.read_data.val() != 0))
                | (self.f5_sp.q.val() == self.f5_base.val())
                | (self.f5_b.q.val().get_bit(0) & self.cmp_pop.lt.val()));
        self.front_job.next = (bit_cast::<103, 1>(self.f5_top.q.val().into()) << 102)
            | (bit_cast::<103, 1>(self.front_end.val().into()) << 101)
            | (bit_cast::<103, 5>(self.f5_thread.q.val()) << 96)
            | (bit_cast::<103, 6>(self.f5_pop.val()) << 90)
            | (bit_cast::<103, 26>(self.f5_node.q.val()) << 64)
            | (bit_cast::<103, W>(self.f5_lo.q.val()) << 32)
            | bit_cast::<103, W>(self.f5_hi.q.val());
        self.f5_root.next = self.f5_a.q.val().get_bits::<26>(0);
        if self.f5_a.q.val().get_bit(29) {
            self.f5_root.next = self.entered_root.read_data.val();
        }
        if !self.f5_next.q.val() {
            self.front_job.next = (bit_cast::<103, 1>(self.f5_top.q.val().into()) << 102)
                | (bit_cast::<103, 5>(self.f5_thread.q.val()) << 96)
                | (bit_cast::<103, 6>(self.f5_base.val()) << 90)
                | (bit_cast::<103, 26>(self.f5_root.val()) << 64)
                | (bit_cast::<103, W>(self.f5_t_min.q.val()) << 32)
                | bit_cast::<103, W>(self.f5_b.q.val().get_bits::<W>(0));
        }
        self.front_fifo.write.next = self.f5_valid.q.val();
        self.front_fifo.data_in.next = self.front_job.val();

        // Fetch: two words of bank 0 a job (the engine's loads first), the next job's right
        // behind; a job whose node `look` found in the cache takes a clock and no request.
        // The words arrive in order: a job waits in `in_flight` from its first request (or its
        // clock from the cache) to its second word.
        self.loop_fifo.read.next = false;
        self.front_fifo.read.next = false;
        self.in_flight.read.next = false;
        self.stale_r.d.next = self.look_stale.q.val();
        // A way the cache does not have keeps its tags zero (never written): no match.
        self.look_hit.next = false;
        for w in 0..4 {
            self.tag_word_r[w].d.next = self.cache_tag[w].read_data.val();
            self.words_r[w].d.next = self.cache_words[w].read_data.val();
            self.look_way_hit[w].next = self.c_node_way_used[w].val()
                & (self.tag_word_r[w].q.val()
                    == (self.c_node_tag_valid.val()
                        | bit_cast::<27, 26>(self.look_job.q.val().get_bits::<26>(64))));
            if self.look_way_hit[w].val() {
                self.look_hit.next = self.c_node_cache_on.val()
                    & self.look_ready.q.val()
                    & (!self.look_job.q.val().get_bit(102))
                    & (!self.stale_r.q.val());
            }
        }
        self.hit_now.next = (self.phase.q.val() == Fetch::Word0) & self.fetch_hit.q.val();
        self.take.next = (self.phase.q.val() != Fetch::Idle)
            & (!self.hit_now.val())
            & ((self.engine.load_banks.val() & self.c_bank_nodes.val()) == 0);
        self.nodes.read.next =
            self.take.val() | ((self.engine.load_banks.val() & self.c_bank_nodes.val()) != 0);
        self.nodes.addr.next = self.engine.load_addr.val();
        if self.take.val() {
            self.nodes.addr.next = (bit_cast::<24, 26>(self.fetch_job.q.val().get_bits::<26>(64))
                << 1)
                | bit_cast::<24, 1>((self.phase.q.val() == Fetch::Word1).into());
            self.phase.d.next = Fetch::Word1;
            if self.phase.q.val() == Fetch::Word1 {
                self.phase.d.next = Fetch::Idle;
            }
        }
        if self.hit_now.val() {
            self.phase.d.next = Fetch::Idle;
        }
        self.cache_hit.next = self.hit_now.val();
        self.cache_miss.next = self.take.val()
            & (self.phase.q.val() == Fetch::Word0)
            & (!self.fetch_job.q.val().get_bit(102));
        self.in_flight.write.next =
            (self.take.val() & (self.phase.q.val() == Fetch::Word0)) | self.hit_now.val();
        self.in_flight.data_in.next = self.fetch_job.q.val();
        self.words_in.d.next = 0.into();
        self.node_line[0].d.next = (bit_cast::<3, 1>(self.hit_now.val().into()) << 2)
            | (bit_cast::<3, 1>(self.take.val().into()) << 1)
            | bit_cast::<3, 1>((self.phase.q.val() == Fetch::Word1).into());
        self.data_line[0].d.next = self.fetch_words.q.val();
        for k in 1..6 {
            self.node_line[k].d.next = self.node_line[k - 1].q.val();
            self.data_line[k].d.next = self.data_line[k - 1].q.val();
        }
        self.arrive.next = 0.into();
        self.arrive_data.next = 0.into();
        for k in 0..6 {
            if self.c_ml_last.val() == self.c_index[k].val() {
                self.arrive.next = self.node_line[k].q.val();
                self.arrive_data.next = self.data_line[k].q.val();
            }
        }
        if self.arrive.val() == 2 {
            self.w0.d.next = self.nodes.rdata.val();
        }
        self.next_a_job.next = self.job.q.val();
        if self.arrive.val() == 3 {
            self.w1.d.next = self.nodes.rdata.val();
            self.a_fetched.d.next = true;
        }
        if self.arrive.val() == 4 {
            self.w0.d.next = self.arrive_data.val().get_bits::<32>(0);
            self.w1.d.next = self.arrive_data.val().get_bits::<32>(32);
            self.a_fetched.d.next = false;
        }
        if (self.arrive.val() == 3) | (self.arrive.val() == 4) {
            self.job.d.next = self.in_flight.data_out.val();
            self.next_a_job.next = self.in_flight.data_out.val();
            self.in_flight.read.next = true;
            self.words_in.d.next = 1.into();
        }
        // `look_job` moves on when the fetch is free: into the fetch, or a finishing job
        // straight to A when nothing is in flight.
        self.fetch_free.next = (self.phase.q.val() == Fetch::Idle)
            | ((self.phase.q.val() == Fetch::Word1) & self.take.val())
            | self.hit_now.val();
        self.look_move.next = false;
        if self.fetch_free.val() & self.look_valid.q.val() {
            if !self.look_job.q.val().get_bit(101) {
                self.look_move.next = true;
                self.fetch_job.d.next = self.look_job.q.val();
                self.fetch_hit.d.next = self.look_hit.val();
                self.fetch_words.d.next = self.words_r[0].q.val();
                for w in 1..4 {
                    if self.look_way_hit[w].val() {
                        self.fetch_words.d.next = self.words_r[w].q.val();
                    }
                }
                self.phase.d.next = Fetch::Word0;
            } else if (self.phase.q.val() == Fetch::Idle) & self.in_flight.empty.val() {
                self.look_move.next = true;
                self.job.d.next = self.look_job.q.val();
                self.next_a_job.next = self.look_job.q.val();
                self.words_in.d.next = 1.into();
                self.a_fetched.d.next = false;
            }
        }
        // The next job for `look` (loop jobs first), its set read from the cache as it comes.
        self.look_load.next = (!self.look_valid.q.val()) | self.look_move.val();
        self.look_ready.d.next = self.look_valid.q.val() & (!self.look_move.val());
        if self.look_move.val() {
            self.look_valid.d.next = false;
        }
        self.read_set.next = self.look_job.q.val().get_bits::<9>(64) & self.c_node_set_mask.val();
        if self.look_load.val() {
            if !self.loop_fifo.empty.val() {
                self.loop_fifo.read.next = true;
                self.look_valid.d.next = true;
                self.look_job.d.next = self.loop_fifo.data_out.val();
                self.read_set.next =
                    self.loop_fifo.data_out.val().get_bits::<9>(64) & self.c_node_set_mask.val();
            } else if !self.front_fifo.empty.val() {
                self.front_fifo.read.next = true;
                self.look_valid.d.next = true;
                self.look_job.d.next = self.front_fifo.data_out.val();
                self.read_set.next =
                    self.front_fifo.data_out.val().get_bits::<9>(64) & self.c_node_set_mask.val();
            }
        }
        for w in 0..4 {
            self.cache_tag[w].read_address.next = self.read_set.val();
            self.cache_words[w].read_address.next = self.read_set.val();
        }
        // The ray's words for A: read for the oldest job in flight, a clock before it gets
        // there.
        self.ray.ray_thread.next = self.in_flight.data_out.val().get_bits::<5>(96);
        self.world.ray_thread.next = self.in_flight.data_out.val().get_bits::<5>(96);

        // A: both words are here (or the walk ended).
        self.at_a.next = self.words_in.q.val() == 1;
        self.a_leaf.next = self.job.q.val().get_bit(101)
            | (self.w0.q.val().get_bits::<2>(30) == self.c_leaf_tag.val());
        self.a_axis.next = self.w0.q.val().get_bits::<2>(30);
        self.a_top.next = self.job.q.val().get_bit(102) & self.c_top_level.val();
        // The object walk's ray, or the top-level walk's world ray; its split axis.
        for k in 0..3 {
            self.a_ray_o[k].next = self.ray.o[k].val();
            self.a_ray_d[k].next = self.ray.d[k].val();
            if self.a_top.val() {
                self.a_ray_o[k].next = self.world.o[k].val();
                self.a_ray_d[k].next = self.world.d[k].val();
            }
        }
        self.a_o.next = self.a_ray_o[0].val();
        self.a_d.next = self.a_ray_d[0].val();
        if self.a_axis.val() == 1 {
            self.a_o.next = self.a_ray_o[1].val();
            self.a_d.next = self.a_ray_d[1].val();
        }
        if self.a_axis.val() == 2 {
            self.a_o.next = self.a_ray_o[2].val();
            self.a_d.next = self.a_ray_d[2].val();
        }
        self.a_inner.next = self.at_a.val() & (!self.a_leaf.val());
        // An object leaf goes to the tester; a top-level leaf, and the end of a walk, to the
        // engine. Each keeps the segment end and depth for the answer.
        self.a_end.next = self.at_a.val() & self.job.q.val().get_bit(101);
        self.a_top_leaf.next = self.at_a.val() & self.a_leaf.val() & self.a_top.val();
        self.a_empty_top.next =
            self.a_top_leaf.val() & (!self.a_end.val()) & (self.w1.q.val() == 0);
        self.skip_valid.d.next = self.a_empty_top.val();
        self.skip_thread.d.next = self.job.q.val().get_bits::<5>(96);
        self.a_list_end.next =
            bit_cast::<32, 30>(self.w0.q.val().get_bits::<30>(0)) + self.w1.q.val();
        self.leaf_fifo.write.next =
            self.at_a.val() & self.a_leaf.val() & (!self.a_end.val()) & (!self.a_top.val());
        self.top_from_ram.write_address.next = self.job.q.val().get_bits::<5>(96);
        self.top_to_ram.write_address.next = self.job.q.val().get_bits::<5>(96);
        // What `kd.wait` gives: a top-level leaf's list, the top-level walk's end, or the hit
        // flag of an object walk's last answer.
        self.top_from_ram.write_data.next = bit_cast::<32, 30>(self.w0.q.val().get_bits::<30>(0));
        if self.a_end.val() {
            self.top_from_ram.write_data.next = bit_cast::<32, 1>(self.last_hit_a.read_data.val());
            if self.a_top.val() {
                self.top_from_ram.write_data.next = self.c_walk_ended.val();
            }
        }
        self.top_to_ram.write_data.next = self.a_list_end.val();
        self.top_from_ram.write_enable.next =
            (self.a_top_leaf.val() & (!self.a_empty_top.val())) | self.a_end.val();
        self.top_to_ram.write_enable.next =
            self.a_top_leaf.val() & (!self.a_end.val()) & (!self.a_empty_top.val());
        self.leaf_fifo.data_in.next = (bit_cast::<69, 5>(self.job.q.val().get_bits::<5>(96)) << 64)
            | (bit_cast::<69, 30>(self.w0.q.val().get_bits::<30>(0)) << 32)
            | bit_cast::<69, 32>(self.a_list_end.val());
        self.leaf_valid.next = !self.leaf_fifo.empty.val();
        self.leaf_thread.next = self.leaf_fifo.data_out.val().get_bits::<5>(64);
        self.leaf_from.next = self.leaf_fifo.data_out.val().get_bits::<32>(32);
        self.leaf_to.next = self.leaf_fifo.data_out.val().get_bits::<32>(0);
        self.leaf_fifo.read.next = self.leaf_take.val();
        self.done_e.write_address.next = self.job.q.val().get_bits::<5>(96);
        self.a_leaf_address.next = (bit_cast::<6, 1>(self.a_top.val().into()) << 5)
            | bit_cast::<6, 5>(self.job.q.val().get_bits::<5>(96));
        self.leaf_hi.write_address.next = self.a_leaf_address.val();
        self.leaf_sp.write_address.next = self.a_leaf_address.val();
        self.leaf_hi.write_data.next = self.job.q.val().get_bits::<W>(0);
        self.leaf_sp.write_data.next = self.job.q.val().get_bits::<6>(90);
        // Entries done: the unit's copy is read a clock ahead at the thread of the job coming
        // to A, the engine's at its own.
        self.done_u.read_address.next = self.next_a_job.val().get_bits::<5>(96);
        self.last_hit_a.read_address.next = self.next_a_job.val().get_bits::<5>(96);
        self.done_u.write_address.next = self.job.q.val().get_bits::<5>(96);
        self.done_e.write_data.next = self.done_u.read_data.val() + 1;
        self.done_u.write_data.next = self.done_u.read_data.val() + 1;
        // A walk's end, or a top-level leaf with instances, wakes the thread.
        self.a_done.next = self.a_end.val() | (self.a_top_leaf.val() & (!self.a_empty_top.val()));
        self.done_u.write_enable.next = self.a_done.val();
        self.done_e.write_enable.next = self.a_done.val();
        self.done_r.d.next = self.a_done.val();
        self.done_thread_r.d.next = self.job.q.val().get_bits::<5>(96);
        // The node cache keeps the object trees' nodes that came from bank 0 (the top level's
        // part of the bank is rewritten between an animated scene's frames), written from A.
        self.fill.next = self.c_node_cache_on.val()
            & self.at_a.val()
            & self.a_fetched.q.val()
            & (!self.job.q.val().get_bit(102));
        self.fill_set.next = self.job.q.val().get_bits::<9>(64) & self.c_node_set_mask.val();
        self.fill_counts.read_set.next =
            self.next_a_job.val().get_bits::<9>(64) & self.c_node_set_mask.val();
        self.fill_counts.way_mask.next = self.c_node_way_mask.val();
        for w in 0..4 {
            self.cache_tag[w].write_address.next = self.fill_set.val();
            self.cache_tag[w].write_data.next = self.c_node_tag_valid.val()
                | bit_cast::<27, 26>(self.job.q.val().get_bits::<26>(64));
            self.cache_tag[w].write_enable.next = self.c_node_way_used[w].val()
                & self.fill.val()
                & (self.fill_counts.way.val() == self.c_node_way[w].val());
            self.cache_words[w].write_address.next = self.fill_set.val();
            self.cache_words[w].write_data.next =
                (bit_cast::<64, 32>(self.w1.q.val()) << 32) | bit_cast::<64, 32>(self.w0.q.val());
            self.cache_words[w].write_enable.next = self.cache_tag[w].write_enable.val();
        }
        self.fill_counts.fill_set.next = self.fill_set.val();
        self.fill_counts.fill_way.next = self.fill_counts.way.val();
        self.fill_counts.fill.next = self.fill.val();
        self.look_stale.d.next = self.fill.val() & (self.fill_set.val() == self.read_set.val());
        self.engine.done.next = self.done_r.q.val();
        self.engine.done_thread.next = self.done_thread_r.q.val();
        self.leaf_hi.write_enable.next = self.at_a.val() & self.a_leaf.val();
        self.leaf_sp.write_enable.next = self.at_a.val() & self.a_leaf.val();

        // Decision: t_split = (split - o) / d, then the comparisons of `units::traversal_step`.
        self.step_busy.next = self.a_inner.val();
        self.sub.in_valid.next = true;
        self.sub.sub.next = true;
        self.sub.a.next = self.w1.q.val().get_bits::<W>(0);
        self.sub.b.next = self.a_o.val();
        self.div.in_valid.next = true;
        self.div.a.next = self.sub.result.val();
        self.div.b.next = self.o_delay[1].data_out.val();
        // o, d, lo, hi wait for t_split; so does the control.
        self.o_delay[0].data_in.next = self.a_o.val();
        self.o_delay[1].data_in.next = self.a_d.val();
        self.o_delay[2].data_in.next = self.job.q.val().get_bits::<W>(32);
        self.o_delay[3].data_in.next = self.job.q.val().get_bits::<W>(0);
        self.o_delay[4].data_in.next = self.w1.q.val().get_bits::<W>(0);
        for k in 0..5 {
            self.o_delay_div[k].data_in.next = self.o_delay[k].data_out.val();
        }
        self.control_delay.data_in.next = (bit_cast::<39, 1>(self.a_top.val().into()) << 38)
            | (bit_cast::<39, 1>(self.a_inner.val().into()) << 37)
            | (bit_cast::<39, 5>(self.job.q.val().get_bits::<5>(96)) << 32)
            | (bit_cast::<39, 6>(self.job.q.val().get_bits::<6>(90)) << 26)
            | bit_cast::<39, 26>(self.w0.q.val().get_bits::<26>(0));
        self.control_delay_div.data_in.next = self.control_delay.data_out.val();
        self.control_delay_cmp.data_in.next = self.control_delay_div.data_out.val();
        // The split plane waits with o: compare o with it when t_split is done.
        self.cmp[0].a.next = self.o_delay_div[0].data_out.val();
        self.cmp[0].b.next = self.o_delay_div[4].data_out.val();
        self.cmp[1].a.next = self.o_delay_div[1].data_out.val();
        self.cmp[1].b.next = self.c_zero.val();
        self.cmp[2].a.next = self.o_delay_div[3].data_out.val();
        self.cmp[2].b.next = self.div.result.val();
        self.cmp[3].a.next = self.div.result.val();
        self.cmp[3].b.next = self.c_zero.val();
        self.cmp[4].a.next = self.div.result.val();
        self.cmp[4].b.next = self.o_delay_div[2].data_out.val();
        for k in 0..5 {
            self.cmp[k].in_valid.next = true;
        }
        self.ts_delay.data_in.next = self.div.result.val();
        self.lo_delay.data_in.next = self.o_delay_div[2].data_out.val();
        self.hi_delay.data_in.next = self.o_delay_div[3].data_out.val();

        // D: the decision, a push for both children, the next step.
        self.d_valid.next = self.control_delay_cmp.data_out.val().get_bit(37);
        self.d_top.next = self.control_delay_cmp.data_out.val().get_bit(38);
        self.d_thread.next = self.control_delay_cmp.data_out.val().get_bits::<5>(32);
        self.d_sp.next = self.control_delay_cmp.data_out.val().get_bits::<6>(26);
        self.d_left.next = self.control_delay_cmp.data_out.val().get_bits::<26>(0);
        self.d_near_left.next =
            self.cmp[0].lt.val() | (self.cmp[0].eq.val() & self.cmp[1].le.val());
        self.d_near.next = self.d_left.val() + 1;
        self.d_far.next = self.d_left.val();
        if self.d_near_left.val() {
            self.d_near.next = self.d_left.val();
            self.d_far.next = self.d_left.val() + 1;
        }
        self.stack_node.write_address.next =
            (bit_cast::<11, 5>(self.d_thread.val()) << 6) | bit_cast::<11, 6>(self.d_sp.val());
        self.stack_lo.write_address.next = self.stack_node.write_address.val();
        self.stack_hi.write_address.next = self.stack_node.write_address.val();
        self.stack_node.write_data.next = self.d_far.val();
        self.stack_lo.write_data.next = self.ts_delay.data_out.val();
        self.stack_hi.write_data.next = self.hi_delay.data_out.val();
        self.stack_node.write_enable.next = false;
        self.stack_lo.write_enable.next = false;
        self.stack_hi.write_enable.next = false;
        // Near with the whole segment.
        self.loop_fifo.data_in.next = (bit_cast::<103, 1>(self.d_top.val().into()) << 102)
            | (bit_cast::<103, 5>(self.d_thread.val()) << 96)
            | (bit_cast::<103, 6>(self.d_sp.val()) << 90)
            | (bit_cast::<103, 26>(self.d_near.val()) << 64)
            | (bit_cast::<103, W>(self.lo_delay.data_out.val()) << 32)
            | bit_cast::<103, W>(self.hi_delay.data_out.val());
        if (!self.cmp[1].eq.val()) & (!self.cmp[2].lt.val()) & (!self.cmp[3].le.val()) {
            if self.cmp[4].lt.val() {
                // Far with the whole segment.
                self.loop_fifo.data_in.next = (bit_cast::<103, 1>(self.d_top.val().into()) << 102)
                    | (bit_cast::<103, 5>(self.d_thread.val()) << 96)
                    | (bit_cast::<103, 6>(self.d_sp.val()) << 90)
                    | (bit_cast::<103, 26>(self.d_far.val()) << 64)
                    | (bit_cast::<103, W>(self.lo_delay.data_out.val()) << 32)
                    | bit_cast::<103, W>(self.hi_delay.data_out.val());
            } else {
                // Both: push (far, t_split, hi), near with [lo, t_split].
                self.stack_node.write_enable.next = self.d_valid.val();
                self.stack_lo.write_enable.next = self.d_valid.val();
                self.stack_hi.write_enable.next = self.d_valid.val();
                self.loop_fifo.data_in.next = (bit_cast::<103, 1>(self.d_top.val().into()) << 102)
                    | (bit_cast::<103, 5>(self.d_thread.val()) << 96)
                    | (bit_cast::<103, 6>(self.d_sp.val() + 1) << 90)
                    | (bit_cast::<103, 26>(self.d_near.val()) << 64)
                    | (bit_cast::<103, W>(self.lo_delay.data_out.val()) << 32)
                    | bit_cast::<103, W>(self.ts_delay.data_out.val());
            }
        }
        self.loop_fifo.write.next = self.d_valid.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::cache::{tests::assert_fills_in_turn, MAX_CACHE_SETS};
    use crate::hw::sim_harness::{clock_cycle, settle};
    use crate::layout::{self, FrameMap, MemoryConfig, SceneTrees, FRAME, NODES};
    use crate::scene::Scene;
    use crate::units::{KdStop, KdWalk};
    use rand::{Rng, SeedableRng};
    use std::collections::VecDeque;

    type Unit = TraversalUnit<24, 7, 16, 17, 18, 9, 21, { div_latency(16) as usize }>;

    /// The bench's side of one clock that both tests share, up to the clock edge: bank 0's
    /// word for the request `requests` holds from `mem_latency` clocks ago, the tester's
    /// answer `(thread, best t, hit)` if any, and in random clocks the take of the unit's
    /// leaf, returned with its thread; then this clock's request joins `requests`.
    fn bench_clock(
        u: &mut Unit,
        requests: &mut VecDeque<Option<u32>>,
        nodes: &[u32],
        answer: Option<(usize, u32, bool)>,
        rng: &mut rand_chacha::ChaCha8Rng,
    ) -> Option<(usize, KdStop)> {
        let addr = requests.pop_front().unwrap();
        u.nodes.rdata.next = u64::from(addr.map_or(0xdead_beef, |a| nodes[a as usize])).into();
        u.answer_valid.next = answer.is_some();
        if let Some((th, t, hit)) = answer {
            u.answer_thread.next = (th as u64).into();
            u.answer_t.next = u64::from(t).into();
            u.answer_hit.next = hit;
        }
        u.leaf_take.next = false;
        settle(u);
        let mut taken = None;
        if u.leaf_valid.val() && rng.gen_bool(0.5) {
            u.leaf_take.next = true;
            settle(u);
            let th = u.leaf_thread.val().to_u64() as usize;
            let from = u.leaf_from.val().to_u64() as u32;
            let to = u.leaf_to.val().to_u64() as u32;
            let leaf = KdStop::Leaf {
                list: from,
                count: to - from,
            };
            taken = Some((th, leaf));
        }
        requests.push_back(
            u.nodes
                .read
                .val()
                .then(|| u.nodes.addr.val().to_u64() as u32),
        );
        taken
    }

    /// rust-hdl simulation on the Cornell box's kd tree with an SRAM model behind bank 0:
    /// eight threads start walks from the root with rays from around the eye (two of them
    /// any-hit walks); the test plays the triangle tester: it takes each leaf in random
    /// clocks and answers it some clocks later with no hit, or (from a thread's third leaf
    /// on, one thread in two) a hit at a random distance; each thread walks twice. Every
    /// thread's sequence of leaves and its end equal `units::KdWalk`'s (an any-hit walk ends
    /// at its first hit); the engine takes bank 0 in random clocks, and its starts are
    /// refused while an answer goes in.
    /// Run with a node cache of `cache_sets` sets: every node the model reads is a hit or a
    /// miss of the unit's cache (none a hit without a cache); returns the hits, the
    /// unit's reads of bank 0 and the cache's fills in order, (set, way).
    fn walk_like_the_model(
        (cache_sets, cache_ways): (u32, u32),
    ) -> (usize, usize, Vec<(u32, u32)>) {
        let f = Format::E7M16;
        let seed = 41;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_noshadow.toml");
        let scene = Scene::load(&path).unwrap();
        let trees = SceneTrees::build(&scene, f).unwrap();
        let lay = layout::build(&scene, &trees, 0, &MemoryConfig::default()).unwrap();
        let nodes = lay.banks[NODES].clone();
        let root = lay.info.object_root;
        let eye = lay.words::<3>(FRAME, FrameMap::EYE);
        let mem_latency = 2;
        let threads = 8usize;
        let any_hit = |th: usize| th == 5 || th == 7;
        let w = |x: f64| f.from_f64(x);
        let rays: Vec<([u32; 3], [u32; 3])> = (0..threads)
            .map(|_| {
                let o = eye.map(|e| f.add(e, w(rng.gen_range(-0.2..0.2))));
                let d = [
                    w(rng.gen_range(-1.0..1.0)),
                    w(rng.gen_range(-1.0..1.0)),
                    w(rng.gen_range(-1.0..1.0)),
                ];
                (o, d)
            })
            .collect();
        // The answer the tester gives after a thread's k-th leaf.
        let answers: Vec<Vec<(u32, bool)>> = (0..threads)
            .map(|th| {
                (0..64)
                    .map(|k| {
                        if th % 2 == 1 && k >= 2 {
                            (w(rng.gen_range(0.5..8.0)), true)
                        } else {
                            (f.infinity(false), false)
                        }
                    })
                    .collect()
            })
            .collect();
        let model_fetches = std::cell::Cell::new(0usize);
        let fetch = |n: u32| {
            model_fetches.set(model_fetches.get() + 1);
            Ok(lay.node(n))
        };
        let t_max = f.infinity(false);
        let want: Vec<Vec<KdStop>> = (0..threads)
            .map(|th| {
                let (mut walk, mut stop) =
                    KdWalk::start(f, rays[th], root, (0, t_max), STACK_LEVELS, fetch).unwrap();
                let mut stops = vec![stop];
                let mut k = 0;
                while stop != KdStop::Finished {
                    stop = if any_hit(th) && answers[th][k].1 {
                        KdStop::Finished
                    } else {
                        walk.next(f, rays[th], answers[th][k], STACK_LEVELS, fetch)
                            .unwrap()
                    };
                    stops.push(stop);
                    k += 1;
                }
                // Each thread walks twice (its counts go on from the first walk).
                stops.repeat(2)
            })
            .collect();
        assert!(
            want.iter().map(Vec::len).sum::<usize>() > 4 * threads,
            "too few leaves"
        );
        assert!(want[7].len() == 8, "the any-hit walk ends at its first hit");
        // Each thread walks twice.
        let model_fetches = 2 * model_fetches.get();

        let mut u = Unit::new(
            mem_latency,
            DEFAULT_TOP_STACK_BASE,
            true,
            cache_sets,
            cache_ways,
        );
        u.connect_all();
        let cycle = |u: &mut Unit| clock_cycle(u, |u, c| u.clock.next = Clock { clk: c });
        for (th, (o, d)) in rays.iter().enumerate() {
            u.engine.thread.next = (th as u64).into();
            for (pair, (a, b)) in [(o[0], o[1]), (o[2], d[0]), (d[1], d[2])]
                .into_iter()
                .enumerate()
            {
                u.engine.ray_write.next = true;
                u.engine.ray_pair.next = (pair as u64).into();
                u.engine.word_a.next = u64::from(a).into();
                u.engine.word_b.next = u64::from(b).into();
                cycle(&mut u);
            }
            u.engine.ray_write.next = false;
            u.t_min_write.next = true;
            u.engine.word_a.next = 0.into();
            cycle(&mut u);
            u.t_min_write.next = false;
        }
        /// The test's side of the unit: the SRAM, the engine's stolen reads, the tester.
        struct Bench {
            requests: VecDeque<Option<u32>>,
            stolen: usize,
            refused: usize,
            hits: usize,
            misses: usize,
            reads: usize,
            fills: Vec<(u32, u32)>,
            /// Answers due: (clock, thread, best t, hit).
            due: Vec<(u64, usize, u32, bool)>,
            clock: u64,
            got: Vec<Vec<KdStop>>,
            /// Where each thread's current walk starts in `got`.
            walk_from: Vec<usize>,
        }
        let mut b = Bench {
            requests: std::iter::repeat(None).take(mem_latency as usize).collect(),
            stolen: 0,
            refused: 0,
            hits: 0,
            misses: 0,
            reads: 0,
            fills: Vec::new(),
            due: Vec::new(),
            clock: 0,
            got: vec![Vec::new(); threads],
            walk_from: vec![0; threads],
        };
        // One clock; returns whether the engine's offer (if any) was taken. An answer goes in
        // early when the engine offers, so that the two meet.
        let tick = |u: &mut Unit, b: &mut Bench, rng: &mut rand_chacha::ChaCha8Rng, offer: bool| {
            b.clock += 1;
            let steal = rng
                .gen_ratio(1, 6)
                .then(|| rng.gen_range(0..nodes.len() as u64));
            u.engine.load_banks.next = u64::from(steal.is_some()).into();
            u.engine.load_addr.next = steal.unwrap_or(0).into();
            // The tester answers one due leaf a clock.
            let answer = b.due.iter().position(|d| d.0 <= b.clock || offer);
            let answer = answer.map(|k| {
                let (_, th, t, hit) = b.due.remove(k);
                (th, t, hit)
            });
            if let Some((th, leaf)) = bench_clock(u, &mut b.requests, &nodes, answer, rng) {
                let k = b.got[th].len() - b.walk_from[th];
                b.got[th].push(leaf);
                let (t, hit) = answers[th][k];
                b.due.push((b.clock + rng.gen_range(4..60), th, t, hit));
            }
            if let Some(a) = steal {
                b.stolen += 1;
                let request = b.requests.back().unwrap();
                assert_eq!(*request, Some(a as u32), "the engine's read");
            } else if b.requests.back().unwrap().is_some() {
                b.reads += 1;
            }
            b.hits += usize::from(u.cache_hit.val());
            b.misses += usize::from(u.cache_miss.val());
            if u.fill.val() {
                let set = u.fill_set.val().to_u64() as u32;
                b.fills.push((set, u.fill_counts.way.val().to_u64() as u32));
            }
            let full = u.engine.full.val();
            if full && u.engine.enqueue.val() {
                b.refused += 1;
            }
            cycle(u);
            !full
        };
        // Per thread: whether its start is still to offer, whether its walk is in flight.
        let mut to_start = vec![true; threads];
        let mut in_flight = vec![false; threads];
        let mut th = 0;
        while b.got.iter().zip(&want).any(|(g, w)| g.len() < w.len()) {
            assert!(b.clock < 400_000, "the walks do not end: got {:?}", b.got);
            // Two clocks per turn of a thread, as the engine's I4 and I5: present the thread
            // to the counters, then read its state and offer its start.
            th = (th + 1) % threads;
            u.engine.query_thread.next = (th as u64).into();
            u.engine.enqueue.next = false;
            tick(&mut u, &mut b, &mut rng, false);
            if in_flight[th] && !u.engine.pending.val() {
                in_flight[th] = false;
                b.got[th].push(KdStop::Finished);
                if b.got[th].len() < want[th].len() {
                    to_start[th] = true;
                    b.walk_from[th] = b.got[th].len();
                }
            }
            // Later threads start while answers for the earlier ones go in.
            let start = to_start[th] && b.clock >= 120 * th as u64;
            u.engine.enqueue.next = start;
            if start {
                let any = if any_hit(th) { 1u64 << 31 } else { 0 };
                u.engine.thread.next = (th as u64).into();
                u.engine.word_a.next = (u64::from(root) | any).into();
                u.engine.word_b.next = u64::from(t_max).into();
            }
            if tick(&mut u, &mut b, &mut rng, start) && start {
                to_start[th] = false;
                in_flight[th] = true;
            }
        }
        assert!(b.stolen > 0);
        assert!(b.refused > 0, "no start was refused for an answer");
        assert_eq!(b.got, want, "leaves per thread");
        assert_eq!(b.hits + b.misses, model_fetches, "nodes fetched");
        assert_eq!(b.reads, 2 * b.misses, "bank 0 reads: two words per miss");
        (b.hits, b.reads, b.fills)
    }

    #[test]
    fn rust_hdl_simulation_walks_like_the_model() {
        let (hits, reads, _) = walk_like_the_model((0, 1));
        assert_eq!(hits, 0, "no cache, no hit");
        // A cache of the paper's 512 sets holds the whole Cornell tree: each node is read from
        // the bank once; two sets evict (fewer hits, more reads), and two sets of four ways
        // hold four times the nodes of two sets of one (a cache that looked up or filled one
        // way only would hit as the direct-mapped one does).
        let (hits_512, reads_512, _) = walk_like_the_model((MAX_CACHE_SETS, 1));
        let (hits_2, reads_2, _) = walk_like_the_model((2, 1));
        let (hits_2x4, reads_2x4, fills_2x4) = walk_like_the_model((2, 4));
        let (hits_256x2, reads_256x2, _) = walk_like_the_model((256, 2));
        println!(
            "hits / reads: none 0 / {reads}, 2 sets {hits_2} / {reads_2}, 2 sets of 4 ways \
             {hits_2x4} / {reads_2x4}, 256 of 2 {hits_256x2} / {reads_256x2}, 512 {hits_512} / \
             {reads_512}"
        );
        assert!(hits_512 > hits_2 && hits_2 > 0, "{hits_512} {hits_2}");
        assert!(
            reads_512 < reads_2 && reads_2 < reads,
            "{reads_512} {reads_2} {reads}"
        );
        assert!(
            hits_2x4 > hits_2 && reads_2x4 < reads_2,
            "{hits_2x4} {hits_2}"
        );
        // 512 items either way hold the whole tree.
        assert_eq!((hits_256x2, reads_256x2), (hits_512, reads_512));
        // Each set's fills take its ways in turn, from way 0 (one count of fills for the whole
        // cache gave a set's first fill whatever way the other set's fills had left).
        let (_, _, fills_2x2) = walk_like_the_model((2, 2));
        assert_fills_in_turn(&fills_2x2, 2, &[0, 1]);
        assert_fills_in_turn(&fills_2x4, 4, &[0, 1]);
    }

    /// rust-hdl simulation of top-level walks on the dynamic scene's trees (1,202 instances):
    /// eight threads write a world ray and an object ray, start a top-level walk (`KD_TOP`),
    /// and at each top-level leaf with instances (the unit passes the empty ones by itself,
    /// with the last answer) the test reads the leaf (`top_from`, `top_to`), gives the
    /// thread an entered root (`root_write`, as instance entry does) and has the unit walk
    /// that object: every other walk starts with `kd.start KD_ENTERED`, the others as
    /// `tri.enter` starts them (`enter`, and some clocks later `entered` with the ray, as
    /// instance entry writes it, half of them in the clock of a tester's answer; entered rays
    /// and answers each at most every other clock, the unit's contract: with both in
    /// consecutive clocks a pending entered walk was overwritten, which the node cache's
    /// timing showed). The test plays the tester, answering each object leaf in random
    /// clocks with the thread's
    /// closest hit so far (none, or from its second top-level leaf on, one thread in two, a
    /// hit at a random distance), checks `kd.wait`'s hit flag after each object walk, then
    /// sends `next`. Every top-level walk stops at `units::KdWalk`'s leaves on the world ray,
    /// going on with the last answer, and ends where it ends; every object walk visits
    /// `KdWalk`'s leaves on the object ray from the entered root up to the last answer's t:
    /// the two walks keep their segments and stacks apart.
    #[test]
    fn rust_hdl_simulation_walks_the_top_level_between_object_walks() {
        use crate::hw::program::isa::{KD_ENTERED, KD_TOP, KD_WALK_ENDED};
        let f = Format::E7M16;
        let seed = 43;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dynamic.toml");
        let scene = Scene::load(&path).unwrap();
        let trees = SceneTrees::build(&scene, f).unwrap();
        let lay = layout::build(&scene, &trees, 0, &MemoryConfig::default()).unwrap();
        let nodes = lay.banks[NODES].clone();
        let top_root = lay.info.top_root.expect("a top level");
        let eye = lay.words::<3>(FRAME, FrameMap::EYE);
        let mem_latency = 3;
        let threads = 8usize;
        let w = |x: f64| f.from_f64(x);
        let worlds: Vec<_> = (0..threads)
            .map(|_| {
                let d = [
                    w(rng.gen_range(-0.6..0.6)),
                    w(rng.gen_range(-0.8..-0.2)),
                    w(rng.gen_range(-1.0..-0.5)),
                ];
                (eye, d)
            })
            .collect();
        // Object rays from near the object space's origin, through it.
        let objects: Vec<_> = (0..threads)
            .map(|_| {
                let o = [w(0.1), w(0.3), w(0.5)];
                let d = [-0.1, -0.3, -0.5].map(|x: f64| w(x + rng.gen_range(-0.05..0.05)));
                (o, d)
            })
            .collect();
        let t_max = f.infinity(false);
        // The tester's closest hit during a thread's k-th top-level leaf (and after it).
        let answers: Vec<Vec<(u32, bool)>> = (0..threads)
            .map(|th| {
                let mut t = 40.0;
                (0..64)
                    .map(|k| {
                        if th % 2 == 1 && k >= 1 {
                            t -= rng.gen_range(0.0..4.0);
                            (w(t), true)
                        } else {
                            (t_max, false)
                        }
                    })
                    .collect()
            })
            .collect();
        let fetch = |n: u32| Ok(lay.node(n));
        // An object walk up to `hi` whose every leaf is answered with `answer`.
        let object_walk = |root: u32, ray, hi: u32, answer: (u32, bool)| {
            let levels = DEFAULT_TOP_STACK_BASE as usize;
            let (mut walk, mut stop) = KdWalk::start(f, ray, root, (0, hi), levels, fetch).unwrap();
            let mut stops = vec![stop];
            while stop != KdStop::Finished {
                stop = walk.next(f, ray, answer, levels, fetch).unwrap();
                stops.push(stop);
            }
            stops
        };
        // The entered object: the instance's whose walk of the first object ray has the most
        // leaves.
        let object_root = (0..lay.info.instance_count)
            .map(|i| {
                let at = i * layout::INSTANCE_WORDS as u32 + layout::instance_word::ROOT as u32;
                lay.word(layout::INSTANCES, at)
            })
            .max_by_key(|&root| object_walk(root, objects[0], t_max, (t_max, false)).len())
            .unwrap();
        // The top-level walk's stops at leaves with instances; it passes the empty ones with
        // the last answer.
        let mut empty_leaves = 0;
        let top_want: Vec<Vec<KdStop>> = (0..threads)
            .map(|th| {
                let levels = STACK_LEVELS - DEFAULT_TOP_STACK_BASE as usize;
                let (mut walk, mut stop) =
                    KdWalk::start(f, worlds[th], top_root, (0, t_max), levels, fetch).unwrap();
                let mut stops = vec![];
                let mut answer = (t_max, false);
                loop {
                    while let KdStop::Leaf { count: 0, .. } = stop {
                        empty_leaves += 1;
                        stop = walk.next(f, worlds[th], answer, levels, fetch).unwrap();
                    }
                    stops.push(stop);
                    if stop == KdStop::Finished {
                        break stops;
                    }
                    answer = answers[th][stops.len() - 1];
                    stop = walk.next(f, worlds[th], answer, levels, fetch).unwrap();
                }
            })
            .collect();
        assert!(
            empty_leaves > threads,
            "too few empty top-level leaves: {empty_leaves}"
        );
        // The object walk during top-level leaf k: up to the answer before it.
        let object_want = |th: usize, k: usize| {
            let hi = if k == 0 { t_max } else { answers[th][k - 1].0 };
            object_walk(object_root, objects[th], hi, answers[th][k])
        };
        let top_leaves: usize = top_want.iter().map(|s| s.len() - 1).sum();
        assert!(
            top_leaves > 3 * threads,
            "too few top-level leaves: {top_leaves}"
        );
        let object_leaves: usize = (0..threads)
            .map(|th| {
                (0..top_want[th].len() - 1)
                    .map(|k| object_want(th, k).len() - 1)
                    .sum::<usize>()
            })
            .sum();
        assert!(
            object_leaves >= 2 * top_leaves,
            "too few object leaves: {object_leaves}"
        );

        let mut u = Unit::new(mem_latency, DEFAULT_TOP_STACK_BASE, true, MAX_CACHE_SETS, 1);
        u.connect_all();
        let cycle = |u: &mut Unit| clock_cycle(u, |u, c| u.clock.next = Clock { clk: c });
        for th in 0..threads {
            u.engine.thread.next = (th as u64).into();
            for (write_world, (o, d)) in [(true, worlds[th]), (false, objects[th])] {
                for (pair, (a, b)) in [(o[0], o[1]), (o[2], d[0]), (d[1], d[2])]
                    .into_iter()
                    .enumerate()
                {
                    u.world_write.next = write_world;
                    u.engine.ray_write.next = !write_world;
                    u.world_pair.next = (pair as u64).into();
                    u.engine.ray_pair.next = (pair as u64).into();
                    u.engine.word_a.next = u64::from(a).into();
                    u.engine.word_b.next = u64::from(b).into();
                    cycle(&mut u);
                }
            }
            u.world_write.next = false;
            u.engine.ray_write.next = false;
            u.t_min_write.next = true;
            u.engine.word_a.next = 0.into();
            cycle(&mut u);
            u.t_min_write.next = false;
        }
        #[derive(Clone, Copy, PartialEq, Debug)]
        enum Step {
            StartTop,
            StartObject,
            Next,
            /// Waiting for the top-level walk, or for an object walk.
            WaitTop,
            WaitObject,
            Done,
        }
        let mut steps = vec![Step::StartTop; threads];
        let mut top_got: Vec<Vec<KdStop>> = vec![Vec::new(); threads];
        /// The SRAM's requests, the object leaves taken (answered at a due clock with the
        /// thread's answer), the object walks' leaves, each thread's current answer.
        struct Bench {
            requests: VecDeque<Option<u32>>,
            due: Vec<(u64, usize)>,
            clock: u64,
            object_got: Vec<Vec<KdStop>>,
            answer: Vec<(u32, bool)>,
            /// Entered rays to write (clock, thread); how many in the clock of an answer.
            entering: Vec<(u64, usize)>,
            entered_with_answer: usize,
            /// The last clocks of an answer and of an entered ray: each comes at most every
            /// other clock (`LAUNCH_SPACING`; instance entry's origin and direction passes).
            last_answer: u64,
            last_entered: u64,
        }
        let mut b = Bench {
            requests: std::iter::repeat(None).take(mem_latency as usize).collect(),
            due: Vec::new(),
            clock: 0,
            object_got: vec![Vec::new(); threads],
            answer: vec![(t_max, false); threads],
            entering: Vec::new(),
            entered_with_answer: 0,
            last_answer: 0,
            last_entered: 0,
        };
        let mut th = 0;
        let tick = |u: &mut Unit, b: &mut Bench, rng: &mut rand_chacha::ChaCha8Rng, offer: bool| {
            b.clock += 1;
            let answer = b
                .due
                .iter()
                .position(|d| d.0 <= b.clock || offer)
                .filter(|_| b.clock > b.last_answer + 1);
            let answer = answer.map(|k| {
                b.last_answer = b.clock;
                let (_, th) = b.due.remove(k);
                (th, b.answer[th].0, b.answer[th].1)
            });
            let entered = b
                .entering
                .iter()
                .position(|e| e.0 <= b.clock)
                .filter(|_| b.clock > b.last_entered + 1);
            if entered.is_some() {
                b.last_entered = b.clock;
            }
            u.entered.next = entered.is_some();
            u.primary_write.next = entered.is_some();
            if let Some(k) = entered {
                let (_, th) = b.entering.remove(k);
                u.primary_thread.next = (th as u64).into();
                for k in 0..3 {
                    u.primary_o[k].next = u64::from(objects[th].0[k]).into();
                    u.primary_d[k].next = u64::from(objects[th].1[k]).into();
                }
                b.entered_with_answer += usize::from(answer.is_some());
            }
            if let Some((th, leaf)) = bench_clock(u, &mut b.requests, &nodes, answer, rng) {
                b.object_got[th].push(leaf);
                b.due.push((b.clock + rng.gen_range(4..40), th));
            }
            let full = u.engine.full.val();
            cycle(u);
            !full
        };
        while steps.iter().any(|&s| s != Step::Done) {
            assert!(b.clock < 400_000, "the walks do not end: {steps:?}");
            th = (th + 1) % threads;
            u.engine.query_thread.next = (th as u64).into();
            u.engine.enqueue.next = false;
            u.engine_next.next = false;
            u.enter.next = false;
            tick(&mut u, &mut b, &mut rng, false);
            // I5 of the thread presented at I4: its walk's state and what `kd.wait` gives.
            if !u.engine.pending.val() {
                let from = u.top_from.val().to_u64() as u32;
                let k = top_got[th].len();
                match steps[th] {
                    Step::WaitTop => {
                        let to = u.top_to.val().to_u64() as u32;
                        if from == KD_WALK_ENDED {
                            top_got[th].push(KdStop::Finished);
                            steps[th] = Step::Done;
                        } else {
                            top_got[th].push(KdStop::Leaf {
                                list: from,
                                count: to - from,
                            });
                            b.object_got[th].clear();
                            b.answer[th] = answers[th][k];
                            steps[th] = Step::StartObject;
                        }
                    }
                    Step::WaitObject => {
                        b.object_got[th].push(KdStop::Finished);
                        let want = object_want(th, k - 1);
                        assert_eq!(b.object_got[th], want, "thread {th}'s object walk {k}");
                        assert_eq!(from, u32::from(b.answer[th].1), "thread {th}'s hit flag");
                        steps[th] = Step::Next;
                    }
                    _ => {}
                }
            }
            let via_enter = steps[th] == Step::StartObject && (th + top_got[th].len()) % 2 == 0;
            let offer =
                matches!(steps[th], Step::StartTop | Step::StartObject | Step::Next) && !via_enter;
            u.engine.enqueue.next = offer;
            u.enter.next = via_enter;
            u.engine.thread.next = (th as u64).into();
            // Words a start with a root of its own, or a `next`, must not read.
            u.engine.word_a.next = u64::from(w(1.0)).into();
            u.engine.word_b.next = 1.into();
            match steps[th] {
                Step::StartTop => {
                    u.engine.word_a.next = (u64::from(top_root) | u64::from(KD_TOP)).into();
                    u.engine.word_b.next = u64::from(t_max).into();
                }
                Step::StartObject => {
                    // Instance entry has given the thread's root by now.
                    u.engine.word_a.next = u64::from(KD_ENTERED).into();
                    u.root_write.next = true;
                    u.root_thread.next = (th as u64).into();
                    u.root.next = u64::from(object_root).into();
                }
                Step::Next => u.engine_next.next = true,
                _ => {}
            }
            let taken = tick(&mut u, &mut b, &mut rng, offer);
            u.root_write.next = false;
            u.enter.next = false;
            if via_enter {
                // The ray comes a while later, half the time with a tester's answer.
                let due = match b.due.first() {
                    Some(&(clock, _)) if rng.gen_bool(0.5) => clock.max(b.clock + 1),
                    _ => b.clock + rng.gen_range(5..60),
                };
                b.entering.push((due, th));
                steps[th] = Step::WaitObject;
            }
            if taken && offer {
                steps[th] = match steps[th] {
                    Step::StartObject => Step::WaitObject,
                    _ => Step::WaitTop,
                };
            }
        }
        assert_eq!(top_got, top_want, "top-level stops per thread");
        assert!(
            b.entered_with_answer > 0,
            "no entered ray came with a tester's answer"
        );
    }
}
