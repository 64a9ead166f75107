//! `TriangleTester`: the ray thread engine's coprocessor for triangle tests. A thread hands
//! it each kd leaf's list (`tri.list`, one engine turn); the [`ListUnit`] reads the list from
//! bank 1 and drops the query's own triangle and those the thread's mailbox has seen; the
//! tester fetches each triangle from banks 2 and 3, takes the ray into the triangle's unit
//! space with the [`TransformUnit`] (the origin as a point, then the direction as a vector),
//! tests it in the [`IntersectUnit`] and keeps the thread's closest hit; the thread waits for
//! its tests once per leaf (`tri.wait`), or the traversal unit hands the leaves of a walk
//! itself and gets the closest hit back (`walk_*`).
//!
//! Golden twin: [`units::triangle_test`](crate::units::triangle_test) for each test and
//! [`units::closer_hit`](crate::units::closer_hit) for the merge, in queue order
//! (src/units.rs), bit for bit; both name this unit back. Latency and throughput: see "Fetch
//! and launch" and "Latency from launch" below.
//!
//! Engine side (the engine's I4/I5 stages):
//! - Ray words: `ray_write` with `ray_pair` 0, 1, 2 writes `(o.x, o.y)`, `(o.z, d.x)`,
//!   `(d.y, d.z)` of `thread` from `word_a`, `word_b`.
//! - Queue: `enqueue` offers a command of `thread` (`queue_kind`, the [`ListUnit`]'s): a list,
//!   a new query (`t_min = word_a`, written at once; "no hit, best t = `word_b`" queued behind
//!   the thread's earlier entries), the object of the next lists, the pair to skip. It is
//!   taken when `full` is low in that clock; the engine then counts a list or a query as
//!   issued.
//! - Answers: `query_thread` at I4; at I5 `pending` (lists and queries of the thread not yet
//!   done), `hit`, `best_t`, `best_instance`, `best_triangle` of its closest hit. An entry
//!   offered at I5 must be of the thread presented at I4 the clock before (its count of
//!   entries taken is read there), and a thread never offers in two clocks in a row (the
//!   engine's scheduler guarantees both).
//!
//! Entries are done in queue order, so a thread's closest hit is chosen in its list order
//! (the first of equal ts stays), as in the golden model.
//!
//! Take, fetch and launch, around [`TEST_BUFFERS`] (4) entry buffers in a ring: the take moves
//! the list unit's next entry into the next buffer as soon as it is free; the fetch requests
//! a buffer's triangle, 6 words of bank 2 and 6 of bank 3 (6 clocks when the engine leaves the
//! banks alone), and goes on to the next buffer in the clock after its last requests (an
//! entry that fetches nothing, an init, a list end or a triangle in the cache, is passed over
//! in a clock). The launch waits for its buffer's words (the SRAM latency after their
//! requests), then launches the origin and the direction into the TransformUnit (2 clocks),
//! freeing the buffer with the direction; the next buffer's origin follows at once if its
//! words are in and no other client's request waits for the unit (which then goes in the
//! clock between). With two buffers and a clock of its own for each take, the entries that
//! fetch nothing (a third of cornell_noshadow's) held the fetch up behind their launch:
//! 72.3 cycles per primary ray; four buffers, 63.3; the next fetch from the clock after the
//! last requests, 56.6; launches 2 clocks apart (were 4), 55.5; the triangle cache, 38.4. The
//! take is apart from the fetch because in the clock of the last requests it hung on the
//! bank grants (the critical path at stop 43). Throughput: one test from the banks per
//! [`CLOCKS_PER_TEST`] (6) clocks, one entry (a test from the cache, an init, a list end) per
//! [`LAUNCH_SPACING`] (2). The engine's own loads of banks 2 and 3 (shading data) take the
//! bank in their clock; the fetch waits for it.
//!
//! Hit merge: an entry reads its thread's best hit and count of entries done as it leaves the
//! IntersectUnit, compares its t with the best in the [`FpCompare`] (2 clocks) and writes both
//! back 3 clocks after the read. Entries 2 or 3 clocks apart would read a state still to be
//! written, so the merge takes it from the entry ahead instead (`after_*`, `lw_*`).
//!
//! Triangle cache: up to [`MAX_CACHE_SETS`](super::cache::MAX_CACHE_SETS) (the paper's 512)
//! items of a triangle's 12 words, `cache_sets` sets (by the triangle's low bits) of
//! `cache_ways` ways (1, 2 or 4), a tag RAM (triangle and valid bit) per way and the words of
//! every way in one RAM per word (line `set << way_shift | way`), all in block RAM (0 sets: no
//! cache). The queue's head's tags are
//! read as the free buffer copies it, registered in the next clock, compared in the one after,
//! and the compare decides the buffer's `cached` and the way it hit in the fourth (the fetch
//! leaves the buffer alone until then); a triangle found there is not
//! fetched, and the launch takes its words from the cache (addressed two clocks ahead: the
//! launch's words, from the buffer or the cache, wait in a register, `matrix`). A triangle
//! fetched from the banks is written into its set as it launches (in its direction's clock,
//! decided in its origin's; its set's ways in turn, a count per set read in the origin's clock),
//! from the words
//! it launches with, unless a buffered triangle found
//! in the cache holds that set (it must find its words there until it launches); a head looked
//! up in either clock, or decided in an origin's clock, misses if its set is the launch's. The
//! frames of an animated scene leave banks 2 and 3 as they are (only instances and the top
//! level move; `emit::memory_images`' tests hold it), so the cache lives across frames.
//!
//! Latency from launch to the merged hit: `TRANSFORM_LATENCY` (28) + 1 + `intersect_latency`
//! (35 at e7m16) + 3. Up to [`FLIGHT_SLOTS`] entries are in flight in that time, each with its
//! own slot for the words the merge needs. Const parameters: the operators' `W, E, M, S, S1,
//! X2, T, P` and `DL = div_latency(M)` (the IntersectUnit's).

use rust_hdl::prelude::*;

use super::cache::{cache_shape_supported, empty_cache_tags, way_shift, FillCounts};
use super::fp::{const_bits, FpCompare};
use super::list_unit::{
    CMD_INIT, CMD_LIST, LIST_OF_WALK, TEST_INIT, TEST_LIST_END, TEST_TRIANGLE, TEST_WALK_END,
};
use super::ports::{CoprocessorPort, SramRead};
use super::ray_store::{zero_counters, RayStore};
use super::{intersect_latency, IntersectUnit, ListUnit, LutRam, TransformUnit, TRANSFORM_LATENCY};
use crate::fp::Format;
use crate::layout;

/// Commands the engine-side queue holds (the [`ListUnit`]'s).
pub const TESTER_QUEUE: usize = 16;

/// Entries in flight from launch to merge that the tester tells apart (each keeps its
/// triangle, instance and t_min in its own slot until its merge reads them). Entries launch
/// at least [`LAUNCH_SPACING`] clocks apart (an init or a list end, which fetch nothing), so
/// the slots must outlast the launch-to-merge latency: see [`flight_slots_suffice`].
pub const FLIGHT_SLOTS: u32 = 64;

/// The fewest clocks between two launches: the origin's pass and the direction's.
pub const LAUNCH_SPACING: u32 = 2;

/// Clocks from an entry's launch to its merge reading the entry's slot.
pub fn launch_to_merge(fmt: Format) -> u32 {
    TRANSFORM_LATENCY + 1 + intersect_latency(fmt)
}

/// Whether a slot is still free when its sequence number comes round again: with 16 slots and
/// launches 4 clocks apart a burst of inits and list ends overwrote a hit's triangle before
/// its merge (e7m16 needs 67 clocks; 16 launches took 64).
pub fn flight_slots_suffice(fmt: Format) -> bool {
    FLIGHT_SLOTS * LAUNCH_SPACING > launch_to_merge(fmt)
}

/// Clocks between two tests when the engine leaves banks 2 and 3 alone (the tester's
/// throughput bound): the 6 words of each bank, the next triangle's from the clock after the
/// last ones (the layout splits a triangle's transform 6 + 6 for this; 8 + 4 took 9 clocks).
pub const CLOCKS_PER_TEST: u32 = 6;
// `update` spells out its numbers (rust-hdl's Verilog cannot name Rust constants): a
// triangle is 6 words of bank 2 (words 0-5 of its transform) and 6 of bank 3 (words 6-11,
// `layout::TRANSFORM_BANK_WORDS`); word k of every buffer is in `words[k]`, addressed by
// the buffer.

/// Entry buffers between the take and the launch (a ring: `tb`, `fb` and `lb` count modulo 4).
pub const TEST_BUFFERS: usize = 4;

#[derive(LogicBlock)]
pub struct TriangleTester<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DL: usize,
> {
    pub clock: Signal<In, Clock>,
    /// The engine's offers (`tri` entries, `queue_kind` = `list_unit::CMD_*`), the thread's
    /// ray (`ray_write` with `ray_pair`), its lists pending, their ends (`done`), and the
    /// engine's loads of banks 2 and 3.
    pub engine: CoprocessorPort,
    /// `list_unit::CMD_*`.
    pub queue_kind: Signal<In, Bits<2>>,
    /// The thread's closest hit so far (`engine.query_thread`, read at I4 for I5).
    pub hit: Signal<Out, Bit>,
    pub best_t: Signal<Out, Bits<W>>,
    pub best_instance: Signal<Out, Bits<32>>,
    pub best_triangle: Signal<Out, Bits<32>>,
    /// Bank 2 (transform words 0-5) and bank 3 (words 6-11): one read per clock each, the word
    /// `mem_latency` clocks after the request.
    pub a_words: SramRead,
    pub b_words: SramRead,
    /// Bank 1 (triangle lists), on the engine's bus when the engine leaves it free.
    pub lists: SramRead,
    /// The traversal unit's leaves: a list of `walk_list_thread`, bank-1 words
    /// `walk_list_from..walk_list_to`, taken (`walk_list_take`) in a clock the engine does not
    /// enqueue and the queue has room.
    pub walk_list_valid: Signal<In, Bit>,
    pub walk_list_thread: Signal<In, Bits<5>>,
    pub walk_list_from: Signal<In, Bits<32>>,
    pub walk_list_to: Signal<In, Bits<32>>,
    pub walk_list_take: Signal<Out, Bit>,
    /// A walk's list is done: the thread's closest hit so far, for the traversal unit.
    pub walk_end_event: Signal<Out, Bit>,
    pub walk_end_thread: Signal<Out, Bits<5>>,
    pub walk_end_t: Signal<Out, Bits<32>>,
    pub walk_end_hit: Signal<Out, Bit>,
    /// High in the clocks the TransformUnit and the IntersectUnit take a triangle test's
    /// input.
    pub transform_busy: Signal<Out, Bit>,
    pub intersect_busy: Signal<Out, Bit>,
    /// A triangle test launches with its words from the triangle cache (`cache_hit`) or from
    /// banks 2 and 3 (`cache_miss`) this clock.
    pub cache_hit: Signal<Out, Bit>,
    pub cache_miss: Signal<Out, Bit>,
    /// The other clients' port on the TransformUnit (ray generation, instance entry): a
    /// request (`gen_valid`, the matrix `gen_m`, the point or vector `gen_v`, `gen_point`,
    /// `gen_thread` and the `gen_client` bits the requester chooses) is taken (`gen_take`) into
    /// a one-request hold when it is free or empties that clock, and goes from there into the
    /// unit in a clock the launch leaves it free (the tests come first, so their latency stays
    /// fixed); its result leaves [`TRANSFORM_LATENCY`] clocks after that, at least one more
    /// after the take, on `gen_out_*`, with the request's client bits; requests stay in
    /// order.
    pub gen_valid: Signal<In, Bit>,
    pub gen_m: [Signal<In, Bits<W>>; 12],
    pub gen_v: [Signal<In, Bits<W>>; 3],
    pub gen_point: Signal<In, Bit>,
    /// The request is a diagonal pass (`TransformUnit::diagonal`).
    pub gen_diagonal: Signal<In, Bit>,
    pub gen_client: Signal<In, Bits<2>>,
    pub gen_thread: Signal<In, Bits<5>>,
    pub gen_take: Signal<Out, Bit>,
    pub gen_out_valid: Signal<Out, Bit>,
    pub gen_out_client: Signal<Out, Bits<2>>,
    pub gen_out_thread: Signal<Out, Bits<5>>,
    pub gen_out_dir: [Signal<Out, Bits<W>>; 3],
    /// A primary ray written whole into the thread's ray ([`RayStore`]'s `primary_write`).
    pub primary_write: Signal<In, Bit>,
    pub primary_thread: Signal<In, Bits<5>>,
    pub primary_o: [Signal<In, Bits<W>>; 3],
    pub primary_d: [Signal<In, Bits<W>>; 3],

    list_unit: ListUnit,
    /// Per thread: the ray (o, d), t_min; entries taken; (engine copies) entries done, best
    /// hit `{hit, t}`, instance, triangle; (merge copies) entries done, best hit.
    ray: RayStore<W>,
    issued: RAM<Bits<8>, 5>,
    done_e: RAM<Bits<8>, 5>,
    best_e: RAM<Bits<33>, 5>,
    instance_e: RAM<Bits<32>, 5>,
    triangle_e: RAM<Bits<32>, 5>,
    done_m: RAM<Bits<8>, 5>,
    best_m: RAM<Bits<33>, 5>,
    /// Per launched entry (by sequence number, [`FLIGHT_SLOTS`] of them): t_min for the
    /// IntersectUnit; a and b for the merge.
    flight_t_min: RAM<Bits<W>, 6>,
    flight_a: RAM<Bits<32>, 6>,
    flight_b: RAM<Bits<32>, 6>,

    // Take, fetch and launch: [`TEST_BUFFERS`] buffers of an entry and its triangle's 12
    // words; the take fills `tb` with the list unit's next entry, the fetch requests the
    // words of `fb`'s triangle, the launch empties `lb`.
    tb: DFF<Bits<2>>,
    /// Buffer `fb` holds a triangle whose words the fetch is requesting. Always
    /// `unvisited[fb]` and `cur_kind[fb] == TEST_TRIANGLE`, kept in a register of its own so
    /// that the bank requests (`a_take`, `b_take`) start from a flip-flop, not from a mux on
    /// `fb`.
    fetching: DFF<Bit>,
    fb: DFF<Bits<2>>,
    lb: DFF<Bits<2>>,
    /// Taken, and not yet left behind by the fetch (which requests a triangle's words and
    /// passes over an entry that fetches nothing).
    unvisited: [DFF<Bit>; TEST_BUFFERS],
    lphase: DFF<Launch>,
    loaded: [DFF<Bit>; TEST_BUFFERS],
    /// `list_unit::TEST_*`.
    cur_kind: [DFF<Bits<2>>; TEST_BUFFERS],
    cur_thread: [DFF<Bits<5>>; TEST_BUFFERS],
    cur_a: [DFF<Bits<32>>; TEST_BUFFERS],
    cur_b: [DFF<Bits<32>>; TEST_BUFFERS],
    received: [DFF<Bits<4>>; TEST_BUFFERS],
    /// A word of bank 2, of bank 3 arrives for each buffer this clock.
    a_here: [Signal<Local, Bit>; TEST_BUFFERS],
    b_here: [Signal<Local, Bit>; TEST_BUFFERS],
    a_issued: DFF<Bits<4>>,
    b_issued: DFF<Bits<4>>,
    seq: DFF<Bits<6>>,
    /// Word k of the triangle in each buffer (distributed RAM addressed by the buffer: the
    /// launch reads its buffer's 12 words at once).
    words: [LutRam<Bits<W>, 2>; 12],
    /// The buffer whose words are read, and whether `matrix` takes the cache's words instead:
    /// `lb`'s while waiting, the next buffer's in the direction's clock (the origin's reads
    /// are not taken). Registered the clock before, from `lphase` (an origin follows a wait
    /// or a direction, a direction an origin): from `lb` through the buffer's read and the
    /// buffers' cache flags into `matrix` was cornell's critical path (68.3 MHz placed).
    words_buffer: DFF<Bits<2>>,
    matrix_cached: DFF<Bit>,
    /// The 12 words the launch takes into the TransformUnit, selected from the buffer or the
    /// cache a clock ahead: in each clock of waiting (`lb`'s) and in the direction's (the next
    /// buffer's, for an origin that follows at once). Selected in the launch's clock, the
    /// path from the buffer's address through its RAM and the cache-or-buffer select into
    /// the TransformUnit's multipliers was cornell's critical path (70.4 MHz placed, stop 45).
    matrix: [DFF<Bits<W>>; 12],
    /// The cache answers next clock with the set of the buffer that clock's launch step reads
    /// (`lb`'s while waiting, the next buffer's in the direction's clock), and `matrix_cached`
    /// is the buffer's: a buffer loaded a clock ago had its set addressed before its entry was
    /// there, and one still deciding may become cached after `matrix_cached` was registered.
    cache_ready: DFF<Bit>,
    fetch_a: Signal<Local, Bits<32>>,
    /// The fetch requests its buffer's last words this clock.
    fetch_ends: Signal<Local, Bit>,
    /// Buffer `tb` is free; `take`: it takes the queue's head this clock.
    tb_free: Signal<Local, Bit>,
    // The triangle cache (see "Triangle cache" in the module's doc).
    /// Per set: `{valid[24], triangle[23:0]}`, in block RAM: read at the head's set in every
    /// clock, compared in the next. (In distributed RAM read and compared in the take's
    /// clock, its 512-deep read ran through the compare into the fetch's start: stop 46's
    /// critical path, `cache_tag.read_address -> fetching`, 67.3 MHz placed.)
    cache_tag: [RAM<Bits<25>, 9>; 4],
    /// Word k of each line's triangle (line `set << way_shift | way`).
    cache_words: [RAM<Bits<W>, 9>; 12],
    /// The way the buffer's triangle is in (when `cached`).
    cached_way: [DFF<Bits<2>>; TEST_BUFFERS],
    /// Per set, the way its next write fills (round robin), read at the launch's set in every
    /// clock: in the direction's clock, which writes, it has the origin's set, the launch's
    /// (launches are two clocks apart, so it has the last write's count).
    fill_counts: FillCounts,
    /// The buffer's triangle is in the cache (decided three clocks after the take, when
    /// `deciding`; its set is not written until it launches).
    cached: [DFF<Bit>; TEST_BUFFERS],
    /// The buffer was taken one, two or three clocks ago: its head's tag word is registered
    /// (`tag_word_r`), compared (`head_hit_r`), and its `cached` decided. (The block RAM's
    /// 5.6-5.8 ns clock to out ran through the 25-bit compare into the next register when
    /// compared in the clock after the read: the placed critical path of cornell at stop 46,
    /// `tester.cache_tag -> tester.cached.1`, 70.2 MHz, and of cornell_noshadow at stop 47,
    /// `-> tester.head_hit_r`, 71.4 MHz.)
    fresh: [DFF<Bit>; TEST_BUFFERS],
    comparing: [DFF<Bit>; TEST_BUFFERS],
    deciding: [DFF<Bit>; TEST_BUFFERS],
    /// The buffer's lookup is under way (`fresh`, `comparing` or `deciding`): its `cached`
    /// is not yet known.
    lookup_pending: [Signal<Local, Bit>; TEST_BUFFERS],
    head_triangle: Signal<Local, Bits<24>>,
    head_set: Signal<Local, Bits<9>>,
    /// The head as it goes down the three clocks of its lookup: its triangle and set, and
    /// whether a launch wrote or chose to write its set since it was read (`head_clash`, a
    /// clock at a time).
    head_triangle_r: DFF<Bits<24>>,
    head_triangle_rr: DFF<Bits<24>>,
    head_set_r: DFF<Bits<9>>,
    head_set_rr: DFF<Bits<9>>,
    head_set_rrr: DFF<Bits<9>>,
    head_clash_r: DFF<Bit>,
    head_clash_rr: DFF<Bit>,
    head_clash_rrr: DFF<Bit>,
    /// An origin launches in this clock into the set of the buffer deciding its `cached`:
    /// `(lphase == Origin) & (l_set == head_set_rrr)`, registered a clock ahead from the
    /// launch's next phase and buffer (`next_origin`, `next_set`) against `head_set_rr`.
    /// Compared in its own clock, from `lphase` through the launch buffer's set and a 9-bit
    /// compare into the four `cached`, it was cornell_noshadow's placed critical path at
    /// stop 50 (`tester.lphase -> tester.cached.1`, 69.8 MHz on seed 2, 9.5 ns of it on two
    /// nets). (An origin's buffer is loaded, so its set does not change between the clocks.)
    origin_clash: DFF<Bit>,
    next_origin: Signal<Local, Bit>,
    next_set: Signal<Local, Bits<9>>,
    /// The tag word read for the head of last clock.
    tag_word_r: [DFF<Bits<25>>; 4],
    head_hit: Signal<Local, Bit>,
    head_hit_r: DFF<Bit>,
    /// The way the head's tag matched in.
    head_way: Signal<Local, Bits<2>>,
    head_way_r: DFF<Bits<2>>,
    /// The lookup of the launch's buffer (`l_`) or the next one's (`n_`) is pending: its `cached`
    /// may change in the next clock, so `matrix_cached`, registered from it, is not yet its.
    l_pending: Signal<Local, Bit>,
    n_pending: Signal<Local, Bit>,
    l_cached: Signal<Local, Bit>,
    l_set: Signal<Local, Bits<9>>,
    n_cached: Signal<Local, Bit>,
    n_set: Signal<Local, Bits<9>>,
    /// The cache lines the launch's buffer and the next one's words are read from (their set
    /// and the way they were found in), and the line a write fills.
    l_way: Signal<Local, Bits<2>>,
    n_way: Signal<Local, Bits<2>>,
    l_line: Signal<Local, Bits<9>>,
    n_line: Signal<Local, Bits<9>>,
    fill_line: Signal<Local, Bits<9>>,
    /// The launch's origin decides to write its triangle into the cache (`cache_block`: a
    /// buffered triangle reads that set); the write goes out in the direction's clock, from
    /// this register (from the buffers' flags straight into the tag RAM's 512 write enables
    /// it was the processor's critical path: `tester.cached -> cache_tag`, 65.3 / 63.5 MHz
    /// placed on seeds 1 / 2).
    cache_write: Signal<Local, Bit>,
    cache_write_r: DFF<Bit>,
    cache_block: Signal<Local, Bit>,
    /// The head's set is written or may be written by the launch (a take then misses).
    head_clash: Signal<Local, Bit>,
    c_set_mask: Constant<Bits<9>>,
    c_cache_on: Constant<Bit>,
    c_tag_valid: Constant<Bits<25>>,
    /// `ways - 1`, `log2(ways)`, each way's number, and whether the cache has that way.
    c_tri_way_mask: Constant<Bits<2>>,
    c_tri_way_shift: Constant<Bits<2>>,
    c_tri_way: [Constant<Bits<2>>; 4],
    c_tri_way_used: [Constant<Bit>; 4],
    take: Signal<Local, Bit>,
    /// The fetch leaves `fb` this clock: its last words requested, or an entry that fetches
    /// nothing passed over.
    fetch_moves: Signal<Local, Bit>,
    /// The buffer the fetch is at next clock, and whether it holds a triangle to fetch.
    fetch_next: Signal<Local, Bits<2>>,
    next_triangle: Signal<Local, Bit>,
    l_kind: Signal<Local, Bits<2>>,
    l_thread: Signal<Local, Bits<5>>,
    l_a: Signal<Local, Bits<32>>,
    l_b: Signal<Local, Bits<32>>,
    l_loaded: Signal<Local, Bit>,
    l_received: Signal<Local, Bits<4>>,
    l_ready: Signal<Local, Bit>,
    /// The buffer after `lb`: its thread and whether it could launch (as `l_*`).
    n_thread: Signal<Local, Bits<5>>,
    n_loaded: Signal<Local, Bit>,
    n_kind: Signal<Local, Bits<2>>,
    n_received: Signal<Local, Bits<4>>,
    n_ready: Signal<Local, Bit>,
    a_take: Signal<Local, Bit>,
    b_take: Signal<Local, Bit>,
    /// Requests in flight to the banks: `{valid[5], buffer[4:3], word index[2:0]}` per clock
    /// of latency.
    a_line: [DFF<Bits<6>>; 6],
    b_line: [DFF<Bits<6>>; 6],
    a_arrive: Signal<Local, Bits<6>>,
    b_arrive: Signal<Local, Bits<6>>,
    transform_unit: TransformUnit<W, E, M, S, S1, X2, T, P>,
    o_hold: [DFF<Bits<W>>; 3],
    intersect_unit: IntersectUnit<W, E, M, S, S1, X2, T, P, DL>,

    // Merge: `m1` the IntersectUnit's result, `m2` with the thread's state, `m3` waiting for
    // the comparison.
    cmp: FpCompare<W, E, M>,
    m1_valid: DFF<Bit>,
    m1_hit: DFF<Bit>,
    m1_kind: DFF<Bits<2>>,
    m1_thread: DFF<Bits<5>>,
    m1_t: DFF<Bits<W>>,
    m2_valid: DFF<Bit>,
    m2_hit: DFF<Bit>,
    m2_kind: DFF<Bits<2>>,
    m2_thread: DFF<Bits<5>>,
    m2_t: DFF<Bits<W>>,
    m2_a: DFF<Bits<32>>,
    m2_b: DFF<Bits<32>>,
    m2_done: DFF<Bits<8>>,
    m2_best: DFF<Bits<33>>,
    m3_valid: DFF<Bit>,
    m3_hit: DFF<Bit>,
    m3_kind: DFF<Bits<2>>,
    m3_thread: DFF<Bits<5>>,
    m3_t: DFF<Bits<W>>,
    m3_a: DFF<Bits<32>>,
    m3_b: DFF<Bits<32>>,
    m3_done: DFF<Bits<8>>,
    m3_best: DFF<Bits<33>>,
    walk_take: Signal<Local, Bit>,
    /// The entry ends an engine's list or query (`TEST_LIST_END`, `TEST_INIT`).
    m3_counts: Signal<Local, Bit>,
    merge_hit: Signal<Local, Bit>,
    merge_best: Signal<Local, Bits<33>>,
    merge_write: Signal<Local, Bit>,
    /// The state a thread's merge leaves (its best, its count of entries done), of the entry
    /// in m3 now (`after_*`) and of the one in m3 a clock ago (`lw_*`, registered). Entries
    /// merge 2 clocks apart, so an entry reading its thread's state in m1 may find the
    /// writes of the two entries before it still to come: it takes theirs instead.
    after_best: Signal<Local, Bits<33>>,
    after_done: Signal<Local, Bits<8>>,
    lw_valid: DFF<Bit>,
    lw_thread: DFF<Bits<5>>,
    lw_best: DFF<Bits<33>>,
    lw_done: DFF<Bits<8>>,
    m1_best: Signal<Local, Bits<33>>,
    m1_done: Signal<Local, Bits<8>>,
    launch_tag: Signal<Local, Bits<16>>,
    /// The launch sends a test's origin or direction this clock; else ray generation may.
    launching: Signal<Local, Bit>,
    /// The other clients' request, held a clock between their port and the TransformUnit:
    /// from instance entry's state through both request selects into the unit's registers
    /// was the processor's critical path (`instances.phase -> tester.transform_unit`, 10.2 ns
    /// of routing: cornell, 84.2 MHz at stop 37). A request is taken into the hold when it is
    /// empty or goes into the unit this clock (`gen_go`).
    gen_held: DFF<Bit>,
    gen_hold_m: [DFF<Bits<W>>; 12],
    gen_hold_v: [DFF<Bits<W>>; 3],
    gen_hold_point: DFF<Bit>,
    gen_hold_diagonal: DFF<Bit>,
    gen_hold_client: DFF<Bits<2>>,
    gen_hold_thread: DFF<Bits<5>>,
    gen_go: Signal<Local, Bit>,
    gen_taken: Signal<Local, Bit>,
    /// Tag bit 14: a primary ray's direction (ray generation's request).
    c_primary: Constant<Bits<16>>,

    c_ml_last: Constant<Bits<4>>,
    c_index: [Constant<Bits<4>>; 12],
    c_infinity: Constant<Bits<W>>,
    c_d_pass: Constant<Bits<16>>,
    c_list_of_walk: Constant<Bits<32>>,
    /// Each buffer's number.
    c_buffer: [Constant<Bits<2>>; TEST_BUFFERS],
    c_hit_flag: Constant<Bits<33>>,
    c_cmd_list: Constant<Bits<2>>,
    c_cmd_init: Constant<Bits<2>>,
    c_test_triangle: Constant<Bits<2>>,
    c_test_init: Constant<Bits<2>>,
    c_test_list_end: Constant<Bits<2>>,
    c_test_walk_end: Constant<Bits<2>>,
    /// The triangle banks' bits of the engine's `load_banks`.
    c_bank_a: Constant<Bits<{ layout::BANKS }>>,
    c_bank_b: Constant<Bits<{ layout::BANKS }>>,
}

/// The launch of a buffered entry: wait for a loaded buffer, launch the origin, then the
/// direction (and free the buffer).
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum Launch {
    Wait,
    Origin,
    Direction,
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
        const DL: usize,
    > TriangleTester<W, E, M, S, S1, X2, T, P, DL>
{
    /// The tester for SRAM read latency `mem_latency` (1..=6), with a triangle cache of
    /// `cache_sets` sets of `cache_ways` ways (0 sets: none; see [`cache_shape_supported`]).
    pub fn new(mem_latency: u32, cache_sets: u32, cache_ways: u32) -> Self {
        assert!((1..=6).contains(&mem_latency));
        assert!(
            cache_shape_supported(cache_sets, cache_ways),
            "triangle cache: {cache_sets} sets of {cache_ways} ways"
        );
        let f = Format::new(E as u32, M as u32).expect("a supported format");
        assert!(flight_slots_suffice(f), "{f}: too few in-flight slots");
        Self {
            clock: Default::default(),
            engine: Default::default(),
            a_words: Default::default(),
            b_words: Default::default(),
            lists: Default::default(),
            queue_kind: Default::default(),
            hit: Default::default(),
            best_t: Default::default(),
            best_instance: Default::default(),
            best_triangle: Default::default(),
            walk_list_valid: Default::default(),
            walk_list_thread: Default::default(),
            walk_list_from: Default::default(),
            walk_list_to: Default::default(),
            walk_list_take: Default::default(),
            walk_end_event: Default::default(),
            walk_end_thread: Default::default(),
            walk_end_t: Default::default(),
            walk_end_hit: Default::default(),
            transform_busy: Default::default(),
            intersect_busy: Default::default(),
            cache_hit: Default::default(),
            cache_miss: Default::default(),
            gen_valid: Default::default(),
            gen_m: Default::default(),
            gen_v: Default::default(),
            gen_point: Default::default(),
            gen_diagonal: Default::default(),
            gen_client: Default::default(),
            gen_thread: Default::default(),
            gen_take: Default::default(),
            gen_out_valid: Default::default(),
            gen_out_client: Default::default(),
            gen_out_thread: Default::default(),
            gen_out_dir: Default::default(),
            primary_write: Default::default(),
            primary_thread: Default::default(),
            primary_o: Default::default(),
            primary_d: Default::default(),
            gen_taken: Default::default(),
            gen_held: Default::default(),
            gen_hold_m: Default::default(),
            gen_hold_v: Default::default(),
            gen_hold_point: Default::default(),
            gen_hold_diagonal: Default::default(),
            gen_hold_client: Default::default(),
            gen_hold_thread: Default::default(),
            gen_go: Default::default(),
            launching: Default::default(),
            c_primary: Constant::new((1u64 << 14).into()),
            list_unit: ListUnit::new(mem_latency),
            ray: Default::default(),
            // The counters start equal (nothing pending) at power-up.
            issued: zero_counters(),
            done_e: zero_counters(),
            best_e: Default::default(),
            instance_e: Default::default(),
            triangle_e: Default::default(),
            done_m: zero_counters(),
            best_m: Default::default(),
            flight_t_min: Default::default(),
            flight_a: Default::default(),
            flight_b: Default::default(),
            tb: Default::default(),
            fetching: Default::default(),
            fb: Default::default(),
            lb: Default::default(),
            unvisited: Default::default(),
            lphase: Default::default(),
            loaded: Default::default(),
            cur_kind: Default::default(),
            cur_thread: Default::default(),
            cur_a: Default::default(),
            cur_b: Default::default(),
            a_here: Default::default(),
            b_here: Default::default(),
            fetch_a: Default::default(),
            fetch_ends: Default::default(),
            tb_free: Default::default(),
            cache_tag: std::array::from_fn(|_| empty_cache_tags()),
            cache_words: Default::default(),
            cached_way: Default::default(),
            fill_counts: Default::default(),
            head_way: Default::default(),
            head_way_r: Default::default(),
            l_way: Default::default(),
            n_way: Default::default(),
            l_line: Default::default(),
            n_line: Default::default(),
            fill_line: Default::default(),
            cached: Default::default(),
            fresh: Default::default(),
            comparing: Default::default(),
            deciding: Default::default(),
            lookup_pending: Default::default(),
            head_triangle_rr: Default::default(),
            head_set_rr: Default::default(),
            head_set_rrr: Default::default(),
            origin_clash: Default::default(),
            next_origin: Default::default(),
            next_set: Default::default(),
            head_clash_rr: Default::default(),
            head_clash_rrr: Default::default(),
            tag_word_r: Default::default(),
            head_hit_r: Default::default(),
            head_triangle: Default::default(),
            head_set: Default::default(),
            head_triangle_r: Default::default(),
            head_set_r: Default::default(),
            head_clash_r: Default::default(),
            head_hit: Default::default(),
            l_pending: Default::default(),
            n_pending: Default::default(),
            l_cached: Default::default(),
            words_buffer: Default::default(),
            matrix_cached: Default::default(),
            matrix: Default::default(),
            cache_ready: Default::default(),
            l_set: Default::default(),
            n_cached: Default::default(),
            n_set: Default::default(),
            cache_write: Default::default(),
            cache_write_r: Default::default(),
            cache_block: Default::default(),
            head_clash: Default::default(),
            c_set_mask: Constant::new(u64::from(cache_sets.max(1) - 1).into()),
            c_cache_on: Constant::new(cache_sets > 0),
            c_tag_valid: Constant::new((1u64 << 24).into()),
            c_tri_way_mask: Constant::new(u64::from(cache_ways - 1).into()),
            c_tri_way_shift: Constant::new(u64::from(way_shift(cache_ways)).into()),
            c_tri_way: std::array::from_fn(|w| Constant::new((w as u64).into())),
            c_tri_way_used: std::array::from_fn(|w| {
                Constant::new(cache_sets > 0 && (w as u32) < cache_ways)
            }),
            take: Default::default(),
            fetch_moves: Default::default(),
            fetch_next: Default::default(),
            next_triangle: Default::default(),
            l_kind: Default::default(),
            l_thread: Default::default(),
            l_a: Default::default(),
            l_b: Default::default(),
            l_loaded: Default::default(),
            l_received: Default::default(),
            l_ready: Default::default(),
            n_thread: Default::default(),
            n_loaded: Default::default(),
            n_kind: Default::default(),
            n_received: Default::default(),
            n_ready: Default::default(),
            a_issued: Default::default(),
            b_issued: Default::default(),
            received: Default::default(),
            seq: Default::default(),
            words: std::array::from_fn(|_| LutRam::new(Default::default())),
            a_take: Default::default(),
            b_take: Default::default(),
            a_line: Default::default(),
            b_line: Default::default(),
            a_arrive: Default::default(),
            b_arrive: Default::default(),
            transform_unit: Default::default(),
            o_hold: Default::default(),
            intersect_unit: Default::default(),
            cmp: Default::default(),
            m1_valid: Default::default(),
            m1_hit: Default::default(),
            m1_kind: Default::default(),
            m1_thread: Default::default(),
            m1_t: Default::default(),
            m2_valid: Default::default(),
            m2_hit: Default::default(),
            m2_kind: Default::default(),
            m2_thread: Default::default(),
            m2_t: Default::default(),
            m2_a: Default::default(),
            m2_b: Default::default(),
            m2_done: Default::default(),
            m2_best: Default::default(),
            m3_valid: Default::default(),
            m3_hit: Default::default(),
            m3_kind: Default::default(),
            m3_thread: Default::default(),
            m3_t: Default::default(),
            m3_a: Default::default(),
            m3_b: Default::default(),
            m3_done: Default::default(),
            m3_best: Default::default(),
            walk_take: Default::default(),
            m3_counts: Default::default(),
            merge_hit: Default::default(),
            merge_best: Default::default(),
            merge_write: Default::default(),
            after_best: Default::default(),
            after_done: Default::default(),
            lw_valid: Default::default(),
            lw_thread: Default::default(),
            lw_best: Default::default(),
            lw_done: Default::default(),
            m1_best: Default::default(),
            m1_done: Default::default(),
            launch_tag: Default::default(),
            c_ml_last: Constant::new(u64::from(mem_latency - 1).into()),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_infinity: const_bits::<W>(u64::from(f.infinity(false))),
            c_d_pass: Constant::new((1u64 << 13).into()),
            c_list_of_walk: Constant::new(LIST_OF_WALK.into()),
            c_buffer: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_hit_flag: Constant::new((1u64 << 32).into()),
            c_cmd_list: Constant::new(CMD_LIST.into()),
            c_cmd_init: Constant::new(CMD_INIT.into()),
            c_test_triangle: Constant::new(TEST_TRIANGLE.into()),
            c_test_init: Constant::new(TEST_INIT.into()),
            c_test_list_end: Constant::new(TEST_LIST_END.into()),
            c_test_walk_end: Constant::new(TEST_WALK_END.into()),
            c_bank_a: Constant::new((1u64 << layout::TRIANGLES_A).into()),
            c_bank_b: Constant::new((1u64 << layout::TRIANGLES_B).into()),
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
        const DL: usize,
    > Logic for TriangleTester<W, E, M, S, S1, X2, T, P, DL>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            tb,
            fetching,
            fb,
            lb,
            lphase,
            words_buffer,
            matrix_cached,
            cache_ready,
            head_triangle_r,
            head_set_r,
            head_clash_r,
            head_triangle_rr,
            head_set_rr,
            head_set_rrr,
            origin_clash,
            head_clash_rr,
            head_clash_rrr,
            head_hit_r,
            head_way_r,
            a_issued,
            b_issued,
            seq,
            m1_valid,
            m1_hit,
            m1_kind,
            m1_thread,
            m1_t,
            m2_valid,
            m2_hit,
            m2_kind,
            m2_thread,
            m2_t,
            m2_a,
            m2_b,
            m2_done,
            m2_best,
            m3_valid,
            m3_hit,
            m3_kind,
            m3_thread,
            m3_t,
            m3_a,
            m3_b,
            m3_done,
            m3_best,
            lw_valid,
            cache_write_r,
            lw_thread,
            lw_best,
            lw_done,
            gen_held,
            gen_hold_point,
            gen_hold_diagonal,
            gen_hold_client,
            gen_hold_thread
        );
        for k in 0..12 {
            self.gen_hold_m[k].clock.next = self.clock.val();
            self.gen_hold_m[k].d.next = self.gen_hold_m[k].q.val();
        }
        for k in 0..3 {
            self.gen_hold_v[k].clock.next = self.clock.val();
            self.gen_hold_v[k].d.next = self.gen_hold_v[k].q.val();
        }
        clock!(
            self,
            clock,
            list_unit,
            ray,
            transform_unit,
            intersect_unit,
            cmp
        );
        self.issued.read_clock.next = self.clock.val();
        self.issued.write_clock.next = self.clock.val();
        self.done_e.read_clock.next = self.clock.val();
        self.done_e.write_clock.next = self.clock.val();
        self.best_e.read_clock.next = self.clock.val();
        self.best_e.write_clock.next = self.clock.val();
        self.instance_e.read_clock.next = self.clock.val();
        self.instance_e.write_clock.next = self.clock.val();
        self.triangle_e.read_clock.next = self.clock.val();
        self.triangle_e.write_clock.next = self.clock.val();
        self.done_m.read_clock.next = self.clock.val();
        self.done_m.write_clock.next = self.clock.val();
        self.best_m.read_clock.next = self.clock.val();
        self.best_m.write_clock.next = self.clock.val();
        self.flight_t_min.read_clock.next = self.clock.val();
        self.flight_t_min.write_clock.next = self.clock.val();
        self.flight_a.read_clock.next = self.clock.val();
        self.flight_a.write_clock.next = self.clock.val();
        self.flight_b.read_clock.next = self.clock.val();
        self.flight_b.write_clock.next = self.clock.val();
        for k in 0..12 {
            self.words[k].write_clock.next = self.clock.val();
            self.words[k].write_enable.next = false;
            self.words[k].read_address.next = self.words_buffer.q.val();
            self.matrix[k].clock.next = self.clock.val();
            self.matrix[k].d.next = self.matrix[k].q.val();
        }
        for w in 0..4 {
            self.cache_tag[w].write_clock.next = self.clock.val();
            self.cache_tag[w].read_clock.next = self.clock.val();
            self.tag_word_r[w].clock.next = self.clock.val();
        }
        self.fill_counts.clock.next = self.clock.val();
        for k in 0..12 {
            self.cache_words[k].read_clock.next = self.clock.val();
            self.cache_words[k].write_clock.next = self.clock.val();
        }
        for k in 0..4 {
            self.cached[k].clock.next = self.clock.val();
            self.cached[k].d.next = self.cached[k].q.val();
            self.cached_way[k].clock.next = self.clock.val();
            self.cached_way[k].d.next = self.cached_way[k].q.val();
            self.fresh[k].clock.next = self.clock.val();
            self.comparing[k].clock.next = self.clock.val();
            self.deciding[k].clock.next = self.clock.val();
            self.lookup_pending[k].next =
                self.fresh[k].q.val() | self.comparing[k].q.val() | self.deciding[k].q.val();
            self.loaded[k].clock.next = self.clock.val();
            self.loaded[k].d.next = self.loaded[k].q.val();
            self.unvisited[k].clock.next = self.clock.val();
            self.unvisited[k].d.next = self.unvisited[k].q.val();
            self.cur_kind[k].clock.next = self.clock.val();
            self.cur_kind[k].d.next = self.cur_kind[k].q.val();
            self.cur_thread[k].clock.next = self.clock.val();
            self.cur_thread[k].d.next = self.cur_thread[k].q.val();
            self.cur_a[k].clock.next = self.clock.val();
            self.cur_a[k].d.next = self.cur_a[k].q.val();
            self.cur_b[k].clock.next = self.clock.val();
            self.cur_b[k].d.next = self.cur_b[k].q.val();
            self.received[k].clock.next = self.clock.val();
            self.received[k].d.next = self.received[k].q.val();
        }
        for k in 0..6 {
            self.a_line[k].clock.next = self.clock.val();
            self.b_line[k].clock.next = self.clock.val();
        }
        for k in 0..3 {
            self.o_hold[k].clock.next = self.clock.val();
        }

        // Engine side: ray words, t_min of a new query, the queue.
        self.ray.thread.next = self.engine.thread.val();
        self.ray.word_a.next = self.engine.word_a.val();
        self.ray.word_b.next = self.engine.word_b.val();
        self.ray.ray_write.next = self.engine.ray_write.val();
        self.ray.ray_pair.next = self.engine.ray_pair.val();
        self.ray.primary_write.next = self.primary_write.val();
        self.ray.primary_thread.next = self.primary_thread.val();
        for k in 0..3 {
            self.ray.primary_o[k].next = self.primary_o[k].val();
            self.ray.primary_d[k].next = self.primary_d[k].val();
        }
        self.ray.t_min_write.next =
            self.engine.enqueue.val() & (self.queue_kind.val() == self.c_cmd_init.val());
        // The engine's entries first; a walk's list in the other clocks.
        self.walk_take.next = self.walk_list_valid.val()
            & (!self.engine.enqueue.val())
            & (!self.list_unit.full.val());
        self.walk_list_take.next = self.walk_take.val();
        self.list_unit.enqueue.next = self.engine.enqueue.val() | self.walk_take.val();
        if self.engine.enqueue.val() {
            self.list_unit.kind.next = self.queue_kind.val();
            self.list_unit.thread.next = self.engine.thread.val();
            self.list_unit.word_a.next = self.engine.word_a.val();
            self.list_unit.word_b.next = self.engine.word_b.val();
        } else {
            self.list_unit.kind.next = self.c_cmd_list.val();
            self.list_unit.thread.next = self.walk_list_thread.val();
            self.list_unit.word_a.next = self.walk_list_from.val();
            self.list_unit.word_b.next = self.walk_list_to.val() | self.c_list_of_walk.val();
        }
        self.engine.full.next = self.list_unit.full.val();
        self.list_unit.engine_banks.next = self.engine.load_banks.val();
        self.lists.read.next = self.list_unit.list_read.val();
        self.lists.addr.next = self.list_unit.list_addr.val();
        self.list_unit.list_rdata.next = self.lists.rdata.val();

        // Engine answers (address at I4, data at I5).
        self.issued.read_address.next = self.engine.query_thread.val();
        self.done_e.read_address.next = self.engine.query_thread.val();
        self.best_e.read_address.next = self.engine.query_thread.val();
        self.instance_e.read_address.next = self.engine.query_thread.val();
        self.triangle_e.read_address.next = self.engine.query_thread.val();
        self.engine.pending.next = self.issued.read_data.val() != self.done_e.read_data.val();
        self.hit.next = self.best_e.read_data.val().get_bit(32);
        self.best_t.next = self.best_e.read_data.val().get_bits::<W>(0);
        self.best_instance.next = self.instance_e.read_data.val();
        self.best_triangle.next = self.triangle_e.read_data.val();
        self.issued.write_address.next = self.engine.thread.val();
        self.issued.write_data.next = self.issued.read_data.val() + 1;
        // A list counts as one entry (done with its end entry), an init as one.
        self.issued.write_enable.next = self.engine.enqueue.val()
            & (!self.list_unit.full.val())
            & ((self.queue_kind.val() == self.c_cmd_list.val())
                | (self.queue_kind.val() == self.c_cmd_init.val()));

        // The launch's buffer `lb` and the one after it (read here: the cache's write, which
        // the take must see, hangs on them).
        self.l_kind.next = self.cur_kind[0].q.val();
        self.l_thread.next = self.cur_thread[0].q.val();
        self.l_a.next = self.cur_a[0].q.val();
        self.l_b.next = self.cur_b[0].q.val();
        // A buffer's word count is cleared as the launch frees it, not at the take: the
        // take, in the clock of the fetch's last requests, was the critical path through the
        // count (stops 33 and 38, `b_issued -> received`).
        self.l_loaded.next = self.loaded[0].q.val();
        self.l_received.next = self.received[0].q.val();
        self.l_cached.next = self.cached[0].q.val();
        self.l_way.next = self.cached_way[0].q.val();
        self.l_pending.next = self.lookup_pending[0].val();
        for k in 1..4 {
            if self.lb.q.val() == self.c_buffer[k].val() {
                self.l_kind.next = self.cur_kind[k].q.val();
                self.l_thread.next = self.cur_thread[k].q.val();
                self.l_a.next = self.cur_a[k].q.val();
                self.l_b.next = self.cur_b[k].q.val();
                self.l_loaded.next = self.loaded[k].q.val();
                self.l_received.next = self.received[k].q.val();
                self.l_cached.next = self.cached[k].q.val();
                self.l_way.next = self.cached_way[k].q.val();
                self.l_pending.next = self.lookup_pending[k].val();
            }
        }
        self.l_ready.next = self.l_loaded.val()
            & ((self.l_kind.val() != self.c_test_triangle.val())
                | (self.l_received.val() == 12)
                | (self.l_cached.val() & self.cache_ready.q.val()));
        // The buffer after `lb`, which may launch right after `lb`'s direction.
        self.n_thread.next = self.cur_thread[0].q.val();
        self.n_loaded.next = self.loaded[0].q.val();
        self.n_kind.next = self.cur_kind[0].q.val();
        self.n_received.next = self.received[0].q.val();
        self.n_cached.next = self.cached[0].q.val();
        self.n_way.next = self.cached_way[0].q.val();
        self.n_pending.next = self.lookup_pending[0].val();
        self.n_set.next = self.cur_a[0].q.val().get_bits::<9>(0) & self.c_set_mask.val();
        for k in 1..4 {
            if self.lb.q.val() + 1 == self.c_buffer[k].val() {
                self.n_thread.next = self.cur_thread[k].q.val();
                self.n_loaded.next = self.loaded[k].q.val();
                self.n_kind.next = self.cur_kind[k].q.val();
                self.n_received.next = self.received[k].q.val();
                self.n_cached.next = self.cached[k].q.val();
                self.n_way.next = self.cached_way[k].q.val();
                self.n_pending.next = self.lookup_pending[k].val();
                self.n_set.next = self.cur_a[k].q.val().get_bits::<9>(0) & self.c_set_mask.val();
            }
        }
        self.n_ready.next = self.n_loaded.val()
            & ((self.n_kind.val() != self.c_test_triangle.val())
                | (self.n_received.val() == 12)
                | (self.n_cached.val() & self.cache_ready.q.val()));

        // Triangle cache: a launched triangle that came from the banks is written into its
        // set with its words (read from its buffer for the launch) in its direction's clock,
        // unless a buffered triangle found in the cache reads that set (it keeps its words
        // until it launches); the queue's head is looked up as the free buffer copies it, and
        // misses if the launch may be writing its set.
        self.l_set.next = self.l_a.val().get_bits::<9>(0) & self.c_set_mask.val();
        self.cache_block.next = false;
        for k in 0..4 {
            if self.loaded[k].q.val()
                & self.cached[k].q.val()
                & ((self.cur_a[k].q.val().get_bits::<9>(0) & self.c_set_mask.val())
                    == self.l_set.val())
            {
                self.cache_block.next = true;
            }
        }
        self.cache_write.next = self.c_cache_on.val()
            & (self.lphase.q.val() == Launch::Origin)
            & (self.l_kind.val() == self.c_test_triangle.val())
            & (!self.l_cached.val())
            & (!self.cache_block.val());
        self.cache_write_r.d.next = self.cache_write.val();
        // In the direction's clock `lb` and its words (in `matrix`) are still the launch's.
        for w in 0..4 {
            self.cache_tag[w].write_address.next = self.l_set.val();
            self.cache_tag[w].write_data.next =
                self.c_tag_valid.val() | bit_cast::<25, 24>(self.l_a.val().get_bits::<24>(0));
            self.cache_tag[w].write_enable.next = self.c_tri_way_used[w].val()
                & self.cache_write_r.q.val()
                & (self.fill_counts.way.val() == self.c_tri_way[w].val());
        }
        self.fill_counts.read_set.next = self.l_set.val();
        self.fill_counts.way_mask.next = self.c_tri_way_mask.val();
        self.fill_counts.fill_set.next = self.l_set.val();
        self.fill_counts.fill_way.next = self.fill_counts.way.val();
        self.fill_counts.fill.next = self.cache_write_r.q.val();
        self.l_line.next =
            (self.l_set.val() << self.c_tri_way_shift.val()) | bit_cast::<9, 2>(self.l_way.val());
        self.n_line.next =
            (self.n_set.val() << self.c_tri_way_shift.val()) | bit_cast::<9, 2>(self.n_way.val());
        self.fill_line.next = (self.l_set.val() << self.c_tri_way_shift.val())
            | bit_cast::<9, 2>(self.fill_counts.way.val());
        // The words answer a clock after their set: the launch's while it waits, the next
        // buffer's from the origin's clock on (`matrix` takes them in the direction's).
        self.cache_ready.d.next = self.l_loaded.val() & (!self.l_pending.val());
        if self.lphase.q.val() != Launch::Wait {
            self.cache_ready.d.next = self.n_loaded.val() & (!self.n_pending.val());
        }
        for k in 0..12 {
            self.cache_words[k].write_address.next = self.fill_line.val();
            self.cache_words[k].write_data.next = self.matrix[k].q.val();
            self.cache_words[k].write_enable.next = self.cache_write_r.q.val();
            self.cache_words[k].read_address.next = self.l_line.val();
            if self.lphase.q.val() != Launch::Wait {
                self.cache_words[k].read_address.next = self.n_line.val();
            }
        }
        self.head_triangle.next = self.list_unit.test_entry.val().get_bits::<24>(32);
        self.head_set.next = self.head_triangle.val().get_bits::<9>(0) & self.c_set_mask.val();
        for w in 0..4 {
            self.cache_tag[w].read_address.next = self.head_set.val();
        }
        // A head taken in an origin's clock (whose write is decided then) or in a write's
        // clock (the tag read shows the set before the write) misses if the set is the same,
        // as one whose set an origin decides to write in any of the next three clocks, while
        // its tag is registered and compared and its `cached` decided (the origin's
        // `cache_block` sees it from the clock after).
        self.head_clash.next = ((self.lphase.q.val() == Launch::Origin)
            | self.cache_write_r.q.val())
            & (self.l_set.val() == self.head_set.val());
        self.head_triangle_r.d.next = self.head_triangle.val();
        self.head_triangle_rr.d.next = self.head_triangle_r.q.val();
        self.head_set_r.d.next = self.head_set.val();
        self.head_set_rr.d.next = self.head_set_r.q.val();
        self.head_set_rrr.d.next = self.head_set_rr.q.val();
        self.next_origin.next = ((self.lphase.q.val() == Launch::Wait) & self.l_ready.val())
            | ((self.lphase.q.val() == Launch::Direction)
                & self.n_ready.val()
                & (!self.gen_held.q.val()));
        self.next_set.next = self.l_set.val();
        if self.lphase.q.val() == Launch::Direction {
            self.next_set.next = self.n_set.val();
        }
        self.origin_clash.d.next =
            self.next_origin.val() & (self.next_set.val() == self.head_set_rr.q.val());
        self.head_clash_r.d.next = self.head_clash.val();
        self.head_clash_rr.d.next = self.head_clash_r.q.val()
            | ((self.lphase.q.val() == Launch::Origin)
                & (self.l_set.val() == self.head_set_r.q.val()));
        self.head_clash_rrr.d.next = self.head_clash_rr.q.val()
            | ((self.lphase.q.val() == Launch::Origin)
                & (self.l_set.val() == self.head_set_rr.q.val()));
        // A way the cache does not have keeps its tags zero (never written): no match.
        self.head_hit.next = false;
        self.head_way.next = 0.into();
        for w in 0..4 {
            self.tag_word_r[w].d.next = self.cache_tag[w].read_data.val();
            if self.c_tri_way_used[w].val()
                & (self.tag_word_r[w].q.val()
                    == (self.c_tag_valid.val() | bit_cast::<25, 24>(self.head_triangle_rr.q.val())))
            {
                self.head_hit.next = self.c_cache_on.val();
                self.head_way.next = self.c_tri_way[w].val();
            }
        }
        self.head_hit_r.d.next = self.head_hit.val();
        self.head_way_r.d.next = self.head_way.val();

        // Take: the list unit's next entry into buffer `tb` whenever it is free, apart from the
        // fetch. (Taken in the clock of the fetch's last requests, the take waited on the bank
        // grants, and from them through the list unit's pop to its queue's read was the
        // processor's critical path: cornell_noshadow, 78.8 MHz at stop 43.)
        self.tb_free.next = !self.loaded[0].q.val();
        for k in 1..4 {
            if self.tb.q.val() == self.c_buffer[k].val() {
                self.tb_free.next = !self.loaded[k].q.val();
            }
        }
        self.take.next = self.tb_free.val() & self.list_unit.test_valid.val();
        self.list_unit.test_take.next = self.take.val();
        if self.take.val() {
            self.tb.d.next = self.tb.q.val() + 1;
            for k in 0..4 {
                if self.tb.q.val() == self.c_buffer[k].val() {
                    self.loaded[k].d.next = true;
                    self.unvisited[k].d.next = true;
                }
            }
        }
        // The free buffer `tb` copies the queue's head in every clock, taken or not (nothing
        // reads a buffer that is not loaded): its 71 enables hang on registers of the tester
        // alone. Enabled by the take, the take's 300 enables were 6.5 ns of routing after the
        // queue's `test_valid` had crossed to the tester (82.0 MHz placed, stop 44).
        for k in 0..4 {
            if (self.tb.q.val() == self.c_buffer[k].val()) & (!self.loaded[k].q.val()) {
                self.cur_kind[k].d.next = self.list_unit.test_entry.val().get_bits::<2>(69);
                self.cur_thread[k].d.next = self.list_unit.test_entry.val().get_bits::<5>(64);
                self.cur_a[k].d.next = self.list_unit.test_entry.val().get_bits::<32>(32);
                self.cur_b[k].d.next = self.list_unit.test_entry.val().get_bits::<32>(0);
                self.cached[k].d.next = false;
            }
        }
        // The buffer taken three clocks ago: in the cache if its triangle's tag matched and
        // no launch has written or chosen its set since (an origin in this clock sees `cached`
        // from the next).
        for k in 0..4 {
            self.fresh[k].d.next = self.take.val() & (self.tb.q.val() == self.c_buffer[k].val());
            self.comparing[k].d.next = self.fresh[k].q.val();
            self.deciding[k].d.next = self.comparing[k].q.val();
            if self.deciding[k].q.val() {
                self.cached_way[k].d.next = self.head_way_r.q.val();
                self.cached[k].d.next = self.head_hit_r.q.val()
                    & (!self.head_clash_rrr.q.val())
                    & (!self.origin_clash.q.val())
                    & (self.cur_kind[k].q.val() == self.c_test_triangle.val());
            }
        }

        // Fetch: request the 6 + 6 words of `fb`'s triangle (the banks serve the engine first),
        // then go on to the next buffer; an init, a list end or a triangle in the cache fetches
        // nothing and is passed over in a clock. The fetch never falls behind the launch: a
        // triangle launches once its words are in (so requested: the fetch has left it), and the
        // launch frees an entry in the second clock of its launch, the fetch passes over one in 1.
        self.a_take.next = self.fetching.q.val()
            & (self.a_issued.q.val() < 6)
            & ((self.engine.load_banks.val() & self.c_bank_a.val()) == 0);
        self.b_take.next = self.fetching.q.val()
            & (self.b_issued.q.val() < 6)
            & ((self.engine.load_banks.val() & self.c_bank_b.val()) == 0);
        self.a_words.read.next =
            self.a_take.val() | ((self.engine.load_banks.val() & self.c_bank_a.val()) != 0);
        self.b_words.read.next =
            self.b_take.val() | ((self.engine.load_banks.val() & self.c_bank_b.val()) != 0);
        self.a_words.addr.next = self.engine.load_addr.val();
        self.b_words.addr.next = self.engine.load_addr.val();
        self.fetch_a.next = self.cur_a[0].q.val();
        for k in 1..4 {
            if self.fb.q.val() == self.c_buffer[k].val() {
                self.fetch_a.next = self.cur_a[k].q.val();
            }
        }
        if self.a_take.val() {
            self.a_words.addr.next = (self.fetch_a.val().get_bits::<24>(0) << 3)
                + bit_cast::<24, 4>(self.a_issued.q.val());
            self.a_issued.d.next = self.a_issued.q.val() + 1;
        }
        if self.b_take.val() {
            self.b_words.addr.next = (self.fetch_a.val().get_bits::<24>(0) << 3)
                + bit_cast::<24, 4>(self.b_issued.q.val());
            self.b_issued.d.next = self.b_issued.q.val() + 1;
        }
        // Requests in flight: `{valid, buffer, word index}`.
        self.a_line[0].d.next = (bit_cast::<6, 1>(self.a_take.val().into()) << 5)
            | (bit_cast::<6, 2>(self.fb.q.val()) << 3)
            | bit_cast::<6, 3>(self.a_issued.q.val().get_bits::<3>(0));
        self.b_line[0].d.next = (bit_cast::<6, 1>(self.b_take.val().into()) << 5)
            | (bit_cast::<6, 2>(self.fb.q.val()) << 3)
            | bit_cast::<6, 3>(self.b_issued.q.val().get_bits::<3>(0));
        for k in 1..6 {
            self.a_line[k].d.next = self.a_line[k - 1].q.val();
            self.b_line[k].d.next = self.b_line[k - 1].q.val();
        }
        // The fetch is done with the buffer once its last words are requested, and requests
        // the next buffer's words from the next clock (6 clocks per test, not 7).
        self.fetch_ends.next = self.fetching.q.val()
            & ((self.a_issued.q.val() == 6) | (self.a_take.val() & (self.a_issued.q.val() == 5)))
            & ((self.b_issued.q.val() == 6) | (self.b_take.val() & (self.b_issued.q.val() == 5)));
        self.fetch_moves.next = self.fetch_ends.val();
        for k in 0..4 {
            if (self.fb.q.val() == self.c_buffer[k].val())
                & (!self.fetching.q.val())
                & self.unvisited[k].q.val()
                & ((self.cur_kind[k].q.val() != self.c_test_triangle.val())
                    | self.cached[k].q.val())
            {
                self.fetch_moves.next = true;
            }
        }
        self.fetch_next.next = self.fb.q.val();
        if self.fetch_moves.val() {
            self.fetch_next.next = self.fb.q.val() + 1;
            self.fb.d.next = self.fb.q.val() + 1;
            self.a_issued.d.next = 0.into();
            self.b_issued.d.next = 0.into();
            for k in 0..4 {
                if self.fb.q.val() == self.c_buffer[k].val() {
                    self.unvisited[k].d.next = false;
                }
            }
        }
        // A triangle taken this clock into the buffer the fetch is at next is fetched from
        // the next clock, as one taken before.
        self.next_triangle.next = false;
        for k in 0..4 {
            if (self.fetch_next.val() == self.c_buffer[k].val())
                & self.unvisited[k].q.val()
                & (!self.lookup_pending[k].val())
                & (self.cur_kind[k].q.val() == self.c_test_triangle.val())
                & (!self.cached[k].q.val())
            {
                self.next_triangle.next = true;
            }
        }
        if (!self.fetching.q.val()) | self.fetch_ends.val() {
            self.fetching.d.next = self.next_triangle.val();
        }
        // The word of the request `mem_latency` clocks ago.
        self.a_arrive.next = 0.into();
        self.b_arrive.next = 0.into();
        for k in 0..6 {
            if self.c_ml_last.val() == self.c_index[k].val() {
                self.a_arrive.next = self.a_line[k].q.val();
                self.b_arrive.next = self.b_line[k].q.val();
            }
        }
        for k in 0..6 {
            self.words[k].write_address.next = self.a_arrive.val().get_bits::<2>(3);
            self.words[k].write_data.next = self.a_words.rdata.val().get_bits::<W>(0);
            self.words[k].write_enable.next = self.a_arrive.val().get_bit(5)
                & (bit_cast::<4, 3>(self.a_arrive.val().get_bits::<3>(0)) == self.c_index[k].val());
            self.words[6 + k].write_address.next = self.b_arrive.val().get_bits::<2>(3);
            self.words[6 + k].write_data.next = self.b_words.rdata.val().get_bits::<W>(0);
            self.words[6 + k].write_enable.next = self.b_arrive.val().get_bit(5)
                & (bit_cast::<4, 3>(self.b_arrive.val().get_bits::<3>(0)) == self.c_index[k].val());
        }
        for k in 0..4 {
            self.a_here[k].next = self.a_arrive.val().get_bit(5)
                & (self.a_arrive.val().get_bits::<2>(3) == self.c_buffer[k].val());
            self.b_here[k].next = self.b_arrive.val().get_bit(5)
                & (self.b_arrive.val().get_bits::<2>(3) == self.c_buffer[k].val());
            if self.a_here[k].val() | self.b_here[k].val() {
                self.received[k].d.next = self.received[k].q.val() + 1;
            }
            if self.a_here[k].val() & self.b_here[k].val() {
                self.received[k].d.next = self.received[k].q.val() + 2;
            }
        }

        // Launch from buffer `lb` (its words and the next buffer's: see above): the origin,
        // then the direction, of the entry's thread.
        self.words_buffer.d.next = self.lb.q.val() + 1;
        self.matrix_cached.d.next = self.n_cached.val();
        if self.lphase.q.val() == Launch::Wait {
            self.words_buffer.d.next = self.lb.q.val();
            self.matrix_cached.d.next = self.l_cached.val();
        }
        for k in 0..12 {
            self.transform_unit.m[k].next = self.matrix[k].q.val();
            if self.lphase.q.val() != Launch::Origin {
                self.matrix[k].d.next = self.words[k].read_data.val();
                if self.matrix_cached.q.val() {
                    self.matrix[k].d.next = self.cache_words[k].read_data.val();
                }
            }
        }
        // The ray store answers a clock after its address: the entry's thread while it waits
        // and launches its origin, the next buffer's while it launches its direction (whose
        // words were read in the origin's clock), so that the next origin may follow at once.
        self.ray.ray_thread.next = self.l_thread.val();
        self.ray.t_min_thread.next = self.l_thread.val();
        if self.lphase.q.val() == Launch::Direction {
            self.ray.ray_thread.next = self.n_thread.val();
            self.ray.t_min_thread.next = self.n_thread.val();
        }
        self.transform_unit.in_valid.next = false;
        self.transform_unit.point.next = true;
        self.transform_unit.diagonal.next = false;
        for k in 0..3 {
            self.transform_unit.v[k].next = self.ray.o[k].val();
        }
        // Tag: `{d pass[13], kind[12:11], thread[10:6], seq[5:0]}`.
        self.launch_tag.next = (bit_cast::<16, 2>(self.l_kind.val()) << 11)
            | (bit_cast::<16, 5>(self.l_thread.val()) << 6)
            | bit_cast::<16, 6>(self.seq.q.val());
        self.transform_unit.tag.next = self.launch_tag.val();
        self.flight_t_min.write_address.next = self.seq.q.val();
        self.flight_a.write_address.next = self.seq.q.val();
        self.flight_b.write_address.next = self.seq.q.val();
        self.flight_t_min.write_data.next = self.ray.t_min.val();
        self.flight_a.write_data.next = self.l_a.val();
        self.flight_b.write_data.next = self.l_b.val();
        self.flight_t_min.write_enable.next = false;
        self.flight_a.write_enable.next = false;
        self.flight_b.write_enable.next = false;
        if (self.lphase.q.val() == Launch::Wait) & self.l_ready.val() {
            self.lphase.d.next = Launch::Origin;
        }
        if self.lphase.q.val() == Launch::Origin {
            self.transform_unit.in_valid.next = true;
            self.flight_t_min.write_enable.next = true;
            self.flight_a.write_enable.next = true;
            self.flight_b.write_enable.next = true;
            self.lphase.d.next = Launch::Direction;
        }
        if self.lphase.q.val() == Launch::Direction {
            self.transform_unit.in_valid.next = true;
            self.transform_unit.point.next = false;
            for k in 0..3 {
                self.transform_unit.v[k].next = self.ray.d[k].val();
            }
            self.transform_unit.tag.next = self.launch_tag.val() | self.c_d_pass.val();
            self.seq.d.next = self.seq.q.val() + 1;
            // The buffer is free (its words were read in this clock and the last); the next
            // one launches at once if it can and no other client's request waits (which goes
            // in the clock between).
            for k in 0..4 {
                if self.lb.q.val() == self.c_buffer[k].val() {
                    self.loaded[k].d.next = false;
                    self.received[k].d.next = 0.into();
                }
            }
            self.lb.d.next = self.lb.q.val() + 1;
            self.lphase.d.next = Launch::Wait;
            if self.n_ready.val() & (!self.gen_held.q.val()) {
                self.lphase.d.next = Launch::Origin;
            }
        }
        // The other clients' request goes from the hold into the unit in a clock the launch
        // leaves free; its tag is `{gen[14], client[12:11], thread[10:6]}`.
        self.launching.next =
            (self.lphase.q.val() == Launch::Origin) | (self.lphase.q.val() == Launch::Direction);
        self.gen_go.next = self.gen_held.q.val() & (!self.launching.val());
        self.gen_taken.next = self.gen_valid.val() & ((!self.gen_held.q.val()) | self.gen_go.val());
        self.gen_take.next = self.gen_taken.val();
        if self.gen_go.val() {
            self.gen_held.d.next = false;
            self.transform_unit.in_valid.next = true;
            for k in 0..12 {
                self.transform_unit.m[k].next = self.gen_hold_m[k].q.val();
            }
            for k in 0..3 {
                self.transform_unit.v[k].next = self.gen_hold_v[k].q.val();
            }
            self.transform_unit.point.next = self.gen_hold_point.q.val();
            self.transform_unit.diagonal.next = self.gen_hold_diagonal.q.val();
            self.transform_unit.tag.next = self.c_primary.val()
                | (bit_cast::<16, 2>(self.gen_hold_client.q.val()) << 11)
                | (bit_cast::<16, 5>(self.gen_hold_thread.q.val()) << 6);
        }
        if self.gen_taken.val() {
            self.gen_held.d.next = true;
            for k in 0..12 {
                self.gen_hold_m[k].d.next = self.gen_m[k].val();
            }
            for k in 0..3 {
                self.gen_hold_v[k].d.next = self.gen_v[k].val();
            }
            self.gen_hold_point.d.next = self.gen_point.val();
            self.gen_hold_diagonal.d.next = self.gen_diagonal.val();
            self.gen_hold_client.d.next = self.gen_client.val();
            self.gen_hold_thread.d.next = self.gen_thread.val();
        }
        self.gen_out_valid.next =
            self.transform_unit.out_valid.val() & self.transform_unit.out_tag.val().get_bit(14);
        self.gen_out_client.next = self.transform_unit.out_tag.val().get_bits::<2>(11);
        self.gen_out_thread.next = self.transform_unit.out_tag.val().get_bits::<5>(6);
        for k in 0..3 {
            self.gen_out_dir[k].next = self.transform_unit.result[k].val();
        }
        // Busy counts tests only (inits and list ends pass the units to keep their order).
        self.transform_busy.next =
            self.launching.val() & (self.l_kind.val() == self.c_test_triangle.val());
        self.cache_hit.next = (self.lphase.q.val() == Launch::Origin)
            & (self.l_kind.val() == self.c_test_triangle.val())
            & self.l_cached.val();
        self.cache_miss.next = (self.lphase.q.val() == Launch::Origin)
            & (self.l_kind.val() == self.c_test_triangle.val())
            & (!self.l_cached.val());

        // O' waits a clock for D'; then the unit-triangle test.
        for k in 0..3 {
            self.o_hold[k].d.next = self.o_hold[k].q.val();
            if self.transform_unit.out_valid.val()
                & (!self.transform_unit.out_tag.val().get_bit(13))
                & (!self.transform_unit.out_tag.val().get_bit(14))
            {
                self.o_hold[k].d.next = self.transform_unit.result[k].val();
            }
        }
        self.flight_t_min.read_address.next = self.transform_unit.out_tag.val().get_bits::<6>(0);
        self.intersect_unit.in_valid.next =
            self.transform_unit.out_valid.val() & self.transform_unit.out_tag.val().get_bit(13);
        for k in 0..3 {
            self.intersect_unit.o[k].next = self.o_hold[k].q.val();
            self.intersect_unit.d[k].next = self.transform_unit.result[k].val();
        }
        self.intersect_unit.t_min.next = self.flight_t_min.read_data.val();
        self.intersect_unit.t_max.next = self.c_infinity.val();
        self.intersect_unit.tag.next = self.transform_unit.out_tag.val();
        self.intersect_busy.next = self.intersect_unit.in_valid.val()
            & (self.transform_unit.out_tag.val().get_bits::<2>(11) == self.c_test_triangle.val());

        // Merge: read the thread's state, compare t with its best, write.
        self.done_m.read_address.next = self.intersect_unit.out_tag.val().get_bits::<5>(6);
        self.best_m.read_address.next = self.intersect_unit.out_tag.val().get_bits::<5>(6);
        self.flight_a.read_address.next = self.intersect_unit.out_tag.val().get_bits::<6>(0);
        self.flight_b.read_address.next = self.intersect_unit.out_tag.val().get_bits::<6>(0);
        self.m1_valid.d.next = self.intersect_unit.out_valid.val();
        self.m1_hit.d.next = self.intersect_unit.hit.val();
        self.m1_kind.d.next = self.intersect_unit.out_tag.val().get_bits::<2>(11);
        self.m1_thread.d.next = self.intersect_unit.out_tag.val().get_bits::<5>(6);
        self.m1_t.d.next = self.intersect_unit.t.val();
        self.m2_valid.d.next = self.m1_valid.q.val();
        self.m2_hit.d.next = self.m1_hit.q.val();
        self.m2_kind.d.next = self.m1_kind.q.val();
        self.m2_thread.d.next = self.m1_thread.q.val();
        self.m2_t.d.next = self.m1_t.q.val();
        self.m2_a.d.next = self.flight_a.read_data.val();
        self.m2_b.d.next = self.flight_b.read_data.val();
        self.m3_valid.d.next = self.m2_valid.q.val();
        self.m3_hit.d.next = self.m2_hit.q.val();
        self.m3_kind.d.next = self.m2_kind.q.val();
        self.m3_thread.d.next = self.m2_thread.q.val();
        self.m3_t.d.next = self.m2_t.q.val();
        self.m3_a.d.next = self.m2_a.q.val();
        self.m3_b.d.next = self.m2_b.q.val();
        self.m3_done.d.next = self.m2_done.q.val();
        self.m3_best.d.next = self.m2_best.q.val();
        self.merge_hit.next = self.m3_hit.q.val()
            & self.cmp.lt.val()
            & (self.m3_kind.q.val() == self.c_test_triangle.val());

        self.done_m.write_address.next = self.m3_thread.q.val();
        self.done_e.write_address.next = self.m3_thread.q.val();
        self.best_m.write_address.next = self.m3_thread.q.val();
        self.best_e.write_address.next = self.m3_thread.q.val();
        self.instance_e.write_address.next = self.m3_thread.q.val();
        self.triangle_e.write_address.next = self.m3_thread.q.val();
        self.done_m.write_data.next = self.m3_done.q.val() + 1;
        self.done_e.write_data.next = self.m3_done.q.val() + 1;
        // Inits and list ends count (the engine counted them as issued), not single tests nor
        // a walk's list ends, which answer the traversal unit with the closest hit so far.
        self.m3_counts.next = self.m3_valid.q.val()
            & ((self.m3_kind.q.val() == self.c_test_init.val())
                | (self.m3_kind.q.val() == self.c_test_list_end.val()));
        self.done_m.write_enable.next = self.m3_counts.val();
        self.done_e.write_enable.next = self.m3_counts.val();
        self.engine.done.next = self.m3_counts.val();
        self.engine.done_thread.next = self.m3_thread.q.val();
        self.walk_end_event.next =
            self.m3_valid.q.val() & (self.m3_kind.q.val() == self.c_test_walk_end.val());
        self.walk_end_thread.next = self.m3_thread.q.val();
        self.walk_end_t.next = bit_cast::<32, W>(self.m3_best.q.val().get_bits::<W>(0));
        self.walk_end_hit.next = self.m3_best.q.val().get_bit(32);
        // An init: no hit, best t = its b. A closer hit: hit, its t.
        self.merge_best.next = bit_cast::<33, W>(self.m3_b.q.val().get_bits::<W>(0));
        if self.merge_hit.val() {
            self.merge_best.next = self.c_hit_flag.val() | bit_cast::<33, W>(self.m3_t.q.val());
        }
        self.merge_write.next = self.m3_valid.q.val()
            & ((self.m3_kind.q.val() == self.c_test_init.val()) | self.merge_hit.val());
        self.best_m.write_data.next = self.merge_best.val();
        self.best_e.write_data.next = self.merge_best.val();
        self.best_m.write_enable.next = self.merge_write.val();
        self.best_e.write_enable.next = self.merge_write.val();
        self.instance_e.write_data.next = self.m3_b.q.val();
        self.triangle_e.write_data.next = self.m3_a.q.val();
        self.instance_e.write_enable.next = self.m3_valid.q.val() & self.merge_hit.val();
        self.triangle_e.write_enable.next = self.m3_valid.q.val() & self.merge_hit.val();
        self.after_best.next = self.m3_best.q.val();
        if self.merge_write.val() {
            self.after_best.next = self.merge_best.val();
        }
        self.after_done.next = self.m3_done.q.val();
        if self.m3_counts.val() {
            self.after_done.next = self.m3_done.q.val() + 1;
        }
        self.lw_valid.d.next = self.m3_valid.q.val();
        self.lw_thread.d.next = self.m3_thread.q.val();
        self.lw_best.d.next = self.after_best.val();
        self.lw_done.d.next = self.after_done.val();
        // m1: the thread's state as the two entries before this one leave it (see `after_best`),
        // read after them (rust-hdl's Verilog needs a local written before it is read).
        self.m1_best.next = self.best_m.read_data.val();
        self.m1_done.next = self.done_m.read_data.val();
        if self.lw_valid.q.val() & (self.lw_thread.q.val() == self.m1_thread.q.val()) {
            self.m1_best.next = self.lw_best.q.val();
            self.m1_done.next = self.lw_done.q.val();
        }
        if self.m3_valid.q.val() & (self.m3_thread.q.val() == self.m1_thread.q.val()) {
            self.m1_best.next = self.after_best.val();
            self.m1_done.next = self.after_done.val();
        }
        self.cmp.in_valid.next = true;
        self.cmp.a.next = self.m1_t.q.val();
        self.cmp.b.next = self.m1_best.val().get_bits::<W>(0);
        self.m2_done.d.next = self.m1_done.val();
        self.m2_best.d.next = self.m1_best.val();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::cache::{tests::assert_fills_in_turn, MAX_CACHE_SETS};
    use crate::hw::fp::div::div_latency;
    use crate::hw::sim_harness::{clock_cycle, settle};
    use crate::units;
    use rand::{Rng, SeedableRng};
    use std::collections::VecDeque;

    type Tester = TriangleTester<24, 7, 16, 17, 18, 9, 21, 34, { div_latency(16) as usize }>;

    /// An entry a thread offers, in its order.
    #[derive(Clone, Copy, Debug)]
    enum Offer {
        Init {
            t_min: u32,
            t_max: u32,
        },
        Object(u32),
        /// Bank-1 words `from..to`.
        List {
            from: u32,
            to: u32,
        },
    }

    /// Each thread's closest hit `(hit, t, instance, triangle)` from the model's sequential
    /// `units::triangle_test` / `units::closer_hit` over its entries, after `units::Mailbox`,
    /// and the number of triangle tests.
    fn model_hits(
        f: Format,
        triangles: &[units::Mat34W],
        bank1: &[u32],
        rays: &[([u32; 3], [u32; 3])],
        offers: &[VecDeque<Offer>],
    ) -> (Vec<(bool, u32, u32, u32)>, u64) {
        let mut tests = 0;
        let hits = rays
            .iter()
            .zip(offers)
            .map(|(&(o, d), offers)| {
                let (mut t_min, mut best) = (0, (false, 0, 0, 0));
                let (mut instance, mut mailbox) = (0, units::Mailbox::new());
                for offer in offers {
                    match *offer {
                        Offer::Init { t_min: lo, t_max } => {
                            t_min = lo;
                            mailbox = units::Mailbox::new();
                            best = (false, t_max, best.2, best.3);
                        }
                        Offer::Object(o) => (instance, mailbox) = (o, units::Mailbox::new()),
                        Offer::List { from, to } => {
                            for &triangle in &bank1[from as usize..to as usize] {
                                if mailbox.seen(triangle) {
                                    continue;
                                }
                                let m = triangles[triangle as usize];
                                tests += 1;
                                let r = units::triangle_test(f, &m, o, d, t_min);
                                if units::closer_hit(f, &r, best.1) {
                                    best = (true, r.t, instance, triangle);
                                }
                            }
                        }
                    }
                }
                best
            })
            .collect();
        (hits, tests)
    }

    /// What the driver saw: offers refused by a full queue, engine reads of banks 2 and 3.
    struct Drive {
        refused: usize,
        stolen: usize,
        /// Triangle tests launched from the cache, from the banks.
        cache_hits: u64,
        cache_misses: u64,
        /// Clocks in which a buffer decided its `cached` while an origin launched into its set.
        origin_clashes: u64,
        /// The cache's fills in order: (set, way).
        fills: Vec<(u32, u32)>,
    }

    /// Runs the tester in rust-hdl simulation with an SRAM model behind banks 1, 2 and 3 (the
    /// words `mem_latency` clocks after the request): the threads' rays, then their offers
    /// round robin, every clock a thread has one (a thread never offers in two clocks in a
    /// row, as in the engine), while the engine takes bank 1, 2 or 3 in one clock of
    /// `steal_one_in` (none when 0). Asserts the engine's reads get their banks and that every
    /// thread's closest hit equals `want` once the offers are drained.
    #[allow(clippy::too_many_arguments)]
    fn drive_tester(
        mem_latency: u32,
        (cache_sets, cache_ways): (u32, u32),
        triangles: &[units::Mat34W],
        bank1: &[u32],
        rays: &[([u32; 3], [u32; 3])],
        mut offers: Vec<VecDeque<Offer>>,
        steal_one_in: u32,
        rng: &mut impl Rng,
        want: &[(bool, u32, u32, u32)],
    ) -> Drive {
        let mut bank2 = vec![0u32; 8 * triangles.len()];
        let mut bank3 = vec![0u32; 8 * triangles.len()];
        for (k, m) in triangles.iter().enumerate() {
            bank2[8 * k..8 * k + 6].copy_from_slice(&m[..6]);
            bank3[8 * k..8 * k + 6].copy_from_slice(&m[6..]);
            for j in 6..8 {
                // shading words
                bank2[8 * k + j] = rng.gen::<u32>() & 0xff_ffff;
                bank3[8 * k + j] = rng.gen::<u32>() & 0xff_ffff;
            }
        }
        let threads = rays.len();
        let mut u = Tester::new(mem_latency, cache_sets, cache_ways);
        u.connect_all();
        let cycle = |u: &mut Tester| clock_cycle(u, |u, c| u.clock.next = Clock { clk: c });
        // Ray words, one thread a clock.
        for (th, (o, d)) in rays.iter().enumerate() {
            for (pair, (a, b)) in [(o[0], o[1]), (o[2], d[0]), (d[1], d[2])]
                .into_iter()
                .enumerate()
            {
                u.engine.thread.next = (th as u64).into();
                u.engine.ray_write.next = true;
                u.engine.ray_pair.next = (pair as u64).into();
                u.engine.word_a.next = (a as u64).into();
                u.engine.word_b.next = (b as u64).into();
                cycle(&mut u);
            }
        }
        u.engine.ray_write.next = false;
        let mut requests: VecDeque<[Option<u32>; 3]> = std::iter::repeat([None; 3])
            .take(mem_latency as usize)
            .collect();
        let mut drive = Drive {
            refused: 0,
            stolen: 0,
            cache_hits: 0,
            cache_misses: 0,
            origin_clashes: 0,
            fills: Vec::new(),
        };
        let mut drain = 0;
        // The thread whose counters were read last clock (the engine's I4): only it may offer.
        let mut queried: Option<usize> = None;
        while offers.iter().any(|q| !q.is_empty()) || drain < 4000 {
            if offers.iter().all(|q| q.is_empty()) {
                drain += 1;
            }
            // The SRAMs answer the request of `mem_latency` clocks ago.
            let [uv, t, list] = requests.pop_front().unwrap();
            u.a_words.rdata.next = u64::from(uv.map_or(0xdead, |a| bank2[a as usize])).into();
            u.b_words.rdata.next = u64::from(t.map_or(0xdead, |a| bank3[a as usize])).into();
            u.lists.rdata.next = u64::from(list.map_or(0xdead, |a| bank1[a as usize])).into();
            // Round robin over the threads with something to offer (like the engine's turns).
            let th = queried.filter(|&t| !offers[t].is_empty());
            let start = th.map_or(0, |t| t + 1);
            queried = (0..threads)
                .map(|k| (start + k) % threads)
                .find(|&k| !offers[k].is_empty() && Some(k) != th);
            u.engine.query_thread.next = (queried.unwrap_or(0) as u64).into();
            u.engine.enqueue.next = th.is_some();
            if let Some(th) = th {
                use crate::hw::list_unit::{CMD_INIT, CMD_LIST, CMD_OBJECT};
                let (kind, a, b) = match offers[th][0] {
                    Offer::Init { t_min, t_max } => (CMD_INIT, t_min, t_max),
                    Offer::Object(o) => (CMD_OBJECT, o, 0),
                    Offer::List { from, to } => (CMD_LIST, from, to),
                };
                u.engine.thread.next = (th as u64).into();
                u.queue_kind.next = kind.into();
                u.engine.word_a.next = u64::from(a).into();
                u.engine.word_b.next = u64::from(b).into();
            }
            let steal = (steal_one_in > 0 && rng.gen_ratio(1, steal_one_in.max(1)))
                .then(|| (rng.gen_range(1..=3u64), rng.gen_range(0..64u64)));
            u.engine.load_banks.next = steal.map_or(0, |s| 1 << s.0).into();
            u.engine.load_addr.next = steal.map_or(0, |s| s.1).into();
            settle(&mut u);
            assert_eq!(
                u.origin_clash.q.val(),
                (u.lphase.q.val() == Launch::Origin) & (u.l_set.val() == u.head_set_rrr.q.val()),
                "origin_clash is the origin of this clock against the deciding set"
            );
            drive.origin_clashes +=
                u64::from(u.origin_clash.q.val() & u.deciding.iter().any(|d| d.q.val()));
            if let Some((1, _)) = steal {
                assert!(!u.lists.read.val(), "the list read took the engine's bus");
            }
            if let Some((bank @ 2..=3, addr)) = steal {
                drive.stolen += 1;
                let (read, port) = if bank == 2 {
                    (u.a_words.read.val(), u.a_words.addr.val())
                } else {
                    (u.b_words.read.val(), u.b_words.addr.val())
                };
                assert!(
                    read && port.to_u64() == addr,
                    "the engine's read of bank {bank}"
                );
            }
            let port = |read: bool, addr: Bits<24>| read.then(|| addr.to_u64() as u32);
            requests.push_back([
                port(u.a_words.read.val(), u.a_words.addr.val()),
                port(u.b_words.read.val(), u.b_words.addr.val()),
                port(u.lists.read.val(), u.lists.addr.val()),
            ]);
            if let Some(th) = th {
                if u.engine.full.val() {
                    drive.refused += 1;
                } else {
                    offers[th].pop_front();
                }
            }
            if u.cache_write_r.q.val() {
                drive.fills.push((
                    u.l_set.val().to_u64() as u32,
                    u.fill_counts.way.val().to_u64() as u32,
                ));
            }
            drive.cache_hits += u64::from(u.cache_hit.val());
            drive.cache_misses += u64::from(u.cache_miss.val());
            cycle(&mut u);
        }
        u.engine.enqueue.next = false;
        u.engine.load_banks.next = 0.into();
        for (th, want) in want.iter().enumerate() {
            u.engine.query_thread.next = (th as u64).into();
            cycle(&mut u);
            assert!(!u.engine.pending.val(), "thread {th} still pending");
            let got = (
                u.hit.val(),
                u.best_t.val().to_u64() as u32,
                u.best_instance.val().to_u64() as u32,
                u.best_triangle.val().to_u64() as u32,
            );
            if want.0 {
                assert_eq!(got, *want, "thread {th}: (hit, t, instance, triangle)");
            } else {
                assert_eq!(
                    (got.0, got.1),
                    (want.0, want.1),
                    "thread {th}: (hit, best t)"
                );
            }
        }
        drive
    }

    /// Four threads each give an object and a new query and 12 lists of 0-7 triangles from a
    /// shared list bank (so the mailbox drops repeats; a second query half-way for thread 0),
    /// offered every clock so that the queues fill and refuse; the engine takes banks 1, 2
    /// and 3 in random clocks. Every thread's closest hit, instance and triangle equal the
    /// model's.
    #[test]
    fn rust_hdl_simulation_matches_sequential_tests() {
        let f = Format::E7M16;
        let seed = 31;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let w = |x: f64| f.from_f64(x);
        // Triangles: near-identity unit-triangle transforms, so that rays aimed at the unit
        // triangle hit often and at different distances.
        let triangles: Vec<units::Mat34W> = (0..24)
            .map(|_| {
                let mut m = [0; 12];
                for r in 0..3 {
                    for c in 0..3 {
                        let diag = if r == c { 1.0 } else { 0.0 };
                        m[4 * r + c] = w(diag + rng.gen_range(-0.2..0.2));
                    }
                    m[4 * r + 3] = w(rng.gen_range(-0.3..0.3));
                }
                m
            })
            .collect();
        let bank1: Vec<u32> = (0..200)
            .map(|_| rng.gen_range(0..triangles.len() as u32))
            .collect();
        let threads = 4usize;
        let rays: Vec<([u32; 3], [u32; 3])> = (0..threads)
            .map(|_| {
                let oz = rng.gen_range(0.5..2.0);
                let (tx, ty) = (rng.gen_range(0.0..0.6), rng.gen_range(0.0..0.6));
                let (ox, oy) = (rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
                ([w(ox), w(oy), w(oz)], [w(tx - ox), w(ty - oy), w(-oz)])
            })
            .collect();
        let offers: Vec<VecDeque<Offer>> = (0..threads)
            .map(|th| {
                let mut q = VecDeque::new();
                q.push_back(Offer::Object(rng.gen_range(0..1000)));
                q.push_back(Offer::Init {
                    t_min: 0,
                    t_max: f.infinity(false),
                });
                for k in 0..12 {
                    if th == 0 && k == 6 {
                        q.push_back(Offer::Init {
                            t_min: w(0.1),
                            t_max: w(1.5),
                        });
                    }
                    let from = rng.gen_range(0..190);
                    q.push_back(Offer::List {
                        from,
                        to: from + rng.gen_range(0..8),
                    });
                }
                q
            })
            .collect();
        let (want, tests) = model_hits(f, &triangles, &bank1, &rays, &offers);
        assert!(
            want.iter().filter(|b| b.0).count() >= 3,
            "too few hits: {want:?}"
        );
        // No cache, two sets (24 triangles in them: evictions, and launches whose set a
        // buffered hit holds), two sets of four ways (8 items), and the paper's 512 items
        // direct mapped and in two ways.
        let mut hits_of = std::collections::HashMap::new();
        for (sets, ways) in [(0, 1), (2, 1), (2, 4), (MAX_CACHE_SETS, 1), (256, 2)] {
            let mut rng = rng.clone();
            let drive = drive_tester(
                3,
                (sets, ways),
                &triangles,
                &bank1,
                &rays,
                offers.clone(),
                5,
                &mut rng,
                &want,
            );
            assert!(
                drive.refused > 0,
                "the queue never filled: back-pressure untested"
            );
            assert!(drive.stolen > 0);
            assert_eq!(
                drive.cache_hits + drive.cache_misses,
                tests,
                "{sets} sets of {ways} ways: every test launches once"
            );
            hits_of.insert((sets, ways), drive.cache_hits);
            match (sets, ways) {
                (0, _) => assert_eq!(drive.cache_hits, 0),
                // Four ways hold four times the triangles of one: a cache that looked up or
                // filled one way only would hit as the direct-mapped one does.
                (2, 4) => assert!(
                    drive.cache_hits > hits_of[&(2, 1)] && drive.cache_misses > 24,
                    "2 sets of 4 ways: {} hits (of one way: {}), {} misses",
                    drive.cache_hits,
                    hits_of[&(2, 1)],
                    drive.cache_misses
                ),
                (2, 1) => assert!(
                    drive.cache_hits > 0 && drive.cache_misses > 24 && drive.origin_clashes > 0,
                    "{sets} sets: {} hits, {} misses, {} origins into a deciding set",
                    drive.cache_hits,
                    drive.cache_misses,
                    drive.origin_clashes
                ),
                // A triangle misses until its first test has launched (24 of them).
                _ => assert!(
                    (24..tests / 4).contains(&drive.cache_misses),
                    "{sets} sets of {ways} ways: {} misses of {tests}",
                    drive.cache_misses
                ),
            }
        }
    }

    /// `n` unit triangles moved away along z (`t = 1 + k / n` from z = 1 straight down), and
    /// the one ray that hits them all.
    #[allow(clippy::type_complexity)]
    fn stacked_unit_triangles(
        f: Format,
        n: u32,
    ) -> (Vec<units::Mat34W>, Vec<([u32; 3], [u32; 3])>) {
        let w = |x: f64| f.from_f64(x);
        let triangles = (0..n)
            .map(|k| {
                let mut m = [0; 12];
                for r in 0..3 {
                    m[5 * r] = w(1.0);
                }
                m[11] = w(f64::from(k) / f64::from(n));
                m
            })
            .collect();
        (
            triangles,
            vec![([w(0.25), w(0.25), w(1.0)], [0, 0, w(-1.0)])],
        )
    }

    /// Entries found in the cache launch 2 clocks apart, so an entry reads its thread's best
    /// before the one in front of it has written it. One thread tests 8 triangles whose t
    /// grows along the list, twice (a new query between: the second time every triangle is
    /// in the cache): a merge reading a stale best would take a farther hit, and the closest
    /// is the list's first.
    #[test]
    fn back_to_back_cached_tests_merge_in_list_order() {
        let f = Format::E7M16;
        let w = |x: f64| f.from_f64(x);
        let (triangles, rays) = stacked_unit_triangles(f, 8);
        let bank1: Vec<u32> = (0..8).collect();
        let init = Offer::Init {
            t_min: 0,
            t_max: f.infinity(false),
        };
        let list = Offer::List { from: 0, to: 8 };
        let offers = vec![VecDeque::from([Offer::Object(5), init, list, init, list])];
        let (want, tests) = model_hits(f, &triangles, &bank1, &rays, &offers);
        assert_eq!(want[0], (true, w(1.0), 5, 0), "the model's hit");
        assert_eq!(tests, 16);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
        let drive = drive_tester(
            2,
            (MAX_CACHE_SETS, 1),
            &triangles,
            &bank1,
            &rays,
            offers,
            0,
            &mut rng,
            &want,
        );
        assert_eq!((drive.cache_hits, drive.cache_misses), (8, 8));
    }

    /// A fill takes its own set's ways in turn. Two sets (a set by the triangle's low bit):
    /// triangles 0, 1, 2 and six more of set 1 fill set 0 twice and set 1 seven times; each
    /// set's fills take ways 0, 1, ... in turn from 0. (One count of fills for the whole cache
    /// gave set 1's first fill way 1.)
    #[test]
    fn a_fill_takes_its_own_sets_ways_in_turn() {
        let f = Format::E7M16;
        let (triangles, rays) = stacked_unit_triangles(f, 16);
        let bank1: Vec<u32> = vec![0, 1, 2, 3, 5, 7, 9, 11, 13];
        let init = Offer::Init {
            t_min: 0,
            t_max: f.infinity(false),
        };
        let offers = vec![VecDeque::from([
            Offer::Object(5),
            init,
            Offer::List { from: 0, to: 9 },
        ])];
        let (want, tests) = model_hits(f, &triangles, &bank1, &rays, &offers);
        assert_eq!(tests, 9);
        for ways in [2, 4] {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
            let drive = drive_tester(
                2,
                (2, ways),
                &triangles,
                &bank1,
                &rays,
                offers.clone(),
                0,
                &mut rng,
                &want,
            );
            assert_eq!(drive.cache_misses, 9, "every triangle is new");
            let per_set = |set| drive.fills.iter().filter(|fill| fill.0 == set).count();
            assert_eq!((per_set(0), per_set(1)), (2, 7), "{ways} ways");
            assert_fills_in_turn(&drive.fills, ways, &[1]);
        }
    }

    /// Every format the generator accepts has enough in-flight slots (the `new` assertion).
    #[test]
    fn flight_slots_outlast_the_latency_in_every_format() {
        for e in Format::MIN_EXP_BITS..=Format::MAX_EXP_BITS {
            for m in Format::MIN_MAN_BITS..=Format::MAX_MAN_BITS {
                let f = Format::new(e, m).unwrap();
                assert!(flight_slots_suffice(f), "{f}: {}", launch_to_merge(f));
            }
        }
        // 32 slots (stop 44's, with launches 4 clocks apart) do not suffice at the default
        // format now that entries launch 2 clocks apart.
        assert!(!(32 * LAUNCH_SPACING > launch_to_merge(Format::E7M16)));
    }

    /// A burst of new queries launches right behind a thread's hit, one every 2 clocks (the
    /// fastest launches): more entries launch within the hit's latency than 32. The hit keeps
    /// its triangle and instance (each in-flight entry keeps its own slot until it merges),
    /// and the bursting threads end with no hit.
    #[test]
    fn launch_burst_behind_a_hit_keeps_its_triangle() {
        let f = Format::E7M16;
        let w = |x: f64| f.from_f64(x);
        // The unit triangle itself; the rays from z = 1 straight down into it.
        let mut unit = [0; 12];
        for r in 0..3 {
            unit[5 * r] = w(1.0);
        }
        let triangles = vec![unit; 8];
        let bank1: Vec<u32> = (0..8).collect();
        let threads = 24usize;
        let rays: Vec<([u32; 3], [u32; 3])> = (0..threads)
            .map(|_| ([w(0.25), w(0.25), w(1.0)], [0, 0, w(-1.0)]))
            .collect();
        let init = Offer::Init {
            t_min: 0,
            t_max: f.infinity(false),
        };
        let offers: Vec<VecDeque<Offer>> = (0..threads)
            .map(|th| {
                let mut q = VecDeque::from([Offer::Object(100 + th as u32), init]);
                if th == 0 {
                    // The list's last triangle is the one that counts: every earlier one
                    // is at the same t, and the first of equal ts stays.
                    q.push_back(Offer::List { from: 7, to: 8 });
                } else {
                    q.extend(std::iter::repeat(init).take(3));
                }
                q
            })
            .collect();
        let (want, _) = model_hits(f, &triangles, &bank1, &rays, &offers);
        assert_eq!(want[0], (true, w(1.0), 100, 7), "the model's hit");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
        drive_tester(
            1,
            (MAX_CACHE_SETS, 1),
            &triangles,
            &bank1,
            &rays,
            offers,
            0,
            &mut rng,
            &want,
        );
    }
}
