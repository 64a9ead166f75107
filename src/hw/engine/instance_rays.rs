//! `InstanceRays`: instance entry in hardware, and shading's world normals. A `tri.enter` names
//! an instance; the unit reads its record's world-to-object 3x4 and object root from bank 4 on
//! the engine's shared bus (in the clocks the engine's loads and the tester's list reads leave
//! it free), gives the root to the traversal unit, sends the thread's world ray through the
//! triangle tester's TransformUnit, the one transformation unit (the origin as a point, then
//! the direction as a vector), and writes the object-space ray whole into the thread's ray in
//! both coprocessors; that write starts the traversal unit's walk of the entered object. A
//! `tri.normal` names an instance and the hit's object-space normal: the unit reads the
//! record's normal matrix and sends the normal through the same unit (a vector), for ray
//! generation's direction store (`tri.dir`). Before, the microprogram did the entry in about
//! 40 instructions per instance entered (13 loads, the record's address, 33 floating-point
//! operations and the three ray words), and a world normal in 27.
//!
//! Contract (engine stages):
//! - World ray (I5): `world_write` writes words `2 world_pair` and `2 world_pair + 1` of
//!   thread `thread`'s world ray `o.x o.y o.z d.x d.y d.z` from `word_a` and `word_b`
//!   (`tri.world`, three per trace in a scene with a top level).
//! - Enter (I5): an `offer` of `instance_id` (its record at `instance * INSTANCE_WORDS` in bank
//!   4) for `thread` is taken unless `refused` (the entry slot still holds the entry before;
//!   the thread repeats its `tri.enter`); taking it marks the thread's ray pending. With
//!   `offer_normal` it is a normal's: `word_b` is the normal's z, its x and y the thread's
//!   world words 0 and 1 (`tri.world` pair 0 after the trace).
//! - Memory: `read` with `addr` (bank 4) only in a clock with `bus_free`; the word arrives on
//!   `rdata` `mem_latency` clocks later. Thirteen reads per entry, the matrix's and the root;
//!   twelve per normal, the normal matrix's nine with each row's last read twice (the
//!   TransformUnit's fourth column, which a vector never reads).
//! - Root: `root_write` with `root_thread` and `root` in the clock the root's word arrives
//!   (before the ray: the thread waits for both, and its last walk is over).
//! - Requests (`gen_*`, the tester's client port): the origin (`gen_point`) and then the
//!   direction (`gen_direction`), or the normal (`gen_normal`), each held until `gen_take`;
//!   results come back on `out_*` (`out_direction`, `out_normal` tell which), in request
//!   order, [`TRANSFORM_LATENCY`] clocks later.
//! - Write (a clock after the direction's result): `ray_write` with `ray_thread`, `ray_o`,
//!   `ray_d` for both coprocessors' [`RayStore`]s; `done_mask` (bit `ray_thread`) in the same
//!   clock is the thread's wake-up. The engine's ray words are refused in that clock, and
//!   ray generation's write never falls in it: each writes the clock after a result of its
//!   own, and the unit gives one result per clock. A normal: `normal_write` with
//!   `ray_thread` and the normal on `ray_d`, and the same wake-up.
//! - Answers: `query_thread` at I4; at I5 `pending` (the entered ray is not written yet).
//! - Instance cache (`cache_sets` sets of `cache_ways` ways, 1, 2 or 4; the paper's 512
//!   items by default, 512 sets of one way; 0 sets for none): each entry, and each normal,
//!   looks up its record's words in set `{instance[7:0], normal}` of the sets, tag
//!   `{instance, normal, valid}` in each way; a hit reads nothing from bank 4, a miss reads
//!   the record and fills the set's next way (round robin per set: [`crate::hw::cache`]).
//!   `cache_hit` or `cache_miss` pulses once per lookup. `frame_start` clears every set's
//!   tags, one set a clock (the host rewrites the records between frames); a lookup read
//!   during the sweep misses.
//!
//! Latency: from the `tri.enter` at I5, 1 clock to start the entry, 3 for the cache's lookup
//! (the set's tags, their compare, the decision), then on a hit 1 to read the way's words,
//! on a miss 13 reads (one per free bus clock) and `mem_latency` for the last word, then the
//! two requests and [`TRANSFORM_LATENCY`] (28) in the unit, and 1 to the write: about 34
//! clocks on a hit, 49 on a miss with `mem_latency` 2 and a free bus. Throughput: one entry
//! per about 7 clocks on hits, `19 + mem_latency` on misses (the next entry's lookup starts
//! while this one's requests are in the unit).
//!
//! Absent (`InstanceRays::new`'s `present` false, for a program with no `tri.world`,
//! `tri.enter` or `tri.normal`): every output is held at 0, so nothing the unit holds is
//! observable and synthesis removes it, and with it the engine's multiplexers in front of the
//! TransformUnit and the ray stores.
//!
//! Golden twin: [`units::transform`](crate::units::transform) of the world origin (a point)
//! and direction (a vector) by the record's `instance_word::WORLD_TO_OBJECT` words, and the
//! record's `instance_word::ROOT`, as the engine's twin (`hw::program::exec`, `tri.enter`) and
//! the golden model's `enter_instance` compute and read them; for a normal,
//! [`units::transform3`](crate::units::transform3) by `instance_word::NORMAL_MATRIX`, as
//! `units::world_normal` and the twin's `tri.normal` compute it.
//!
//! [`RayStore`]: crate::hw::ray_store::RayStore
//! [`TRANSFORM_LATENCY`]: crate::hw::TRANSFORM_LATENCY

use rust_hdl::prelude::*;

use crate::hw::cache::{cache_shape_supported, empty_cache_tags, way_shift, FillCounts};
use crate::layout::instance_word;

/// Words of a world-to-object matrix (3x4), read per entry, then the root's.
const MATRIX_WORDS: u64 = 12;

/// What the unit is doing with the entry it has begun.
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum EntryPhase {
    /// No entry begun: the slot's entry, if any, begins (and its set of the cache is read).
    Idle,
    /// The tags of the entry's set arrive and are registered (`tag_r`, one per way, and the
    /// way a miss fills, `victim_r`).
    Look,
    /// The registered tags are compared with the entry's.
    Compare,
    /// A hit reads its way's words, a miss goes to the fetch.
    Decide,
    /// A hit's words arrive and are registered (the matrix into `matrix`, the root into
    /// `root_r`, written the next clock); then the requests.
    Words,
    /// Reading the matrix's twelve words and the root (a normal's: its nine words as twelve).
    Fetch,
    /// The origin's request waits for the unit; then the direction's.
    Origin,
    Direction,
    /// A normal's one request waits for the unit.
    Normal,
}

#[derive(LogicBlock)]
pub struct InstanceRays<const W: usize> {
    pub clock: Signal<In, Clock>,
    pub frame_start: Signal<In, Bit>,
    pub world_write: Signal<In, Bit>,
    pub world_pair: Signal<In, Bits<2>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub thread: Signal<In, Bits<5>>,
    pub offer: Signal<In, Bit>,
    /// The offer is a normal's (`tri.normal`): `word_b` is its z, x and y are the thread's
    /// world words 0 and 1.
    pub offer_normal: Signal<In, Bit>,
    pub instance_id: Signal<In, Bits<24>>,
    pub refused: Signal<Out, Bit>,
    pub bus_free: Signal<In, Bit>,
    pub read: Signal<Out, Bit>,
    pub addr: Signal<Out, Bits<24>>,
    pub rdata: Signal<In, Bits<32>>,
    pub root_write: Signal<Out, Bit>,
    pub root_thread: Signal<Out, Bits<5>>,
    pub root: Signal<Out, Bits<26>>,
    pub gen_valid: Signal<Out, Bit>,
    pub gen_m: [Signal<Out, Bits<W>>; 12],
    pub gen_v: [Signal<Out, Bits<W>>; 3],
    pub gen_point: Signal<Out, Bit>,
    pub gen_direction: Signal<Out, Bit>,
    pub gen_normal: Signal<Out, Bit>,
    pub gen_thread: Signal<Out, Bits<5>>,
    pub gen_take: Signal<In, Bit>,
    pub out_valid: Signal<In, Bit>,
    pub out_direction: Signal<In, Bit>,
    pub out_normal: Signal<In, Bit>,
    pub out_thread: Signal<In, Bits<5>>,
    pub out_v: [Signal<In, Bits<W>>; 3],
    pub ray_write: Signal<Out, Bit>,
    pub ray_thread: Signal<Out, Bits<5>>,
    pub ray_o: [Signal<Out, Bits<W>>; 3],
    pub ray_d: [Signal<Out, Bits<W>>; 3],
    /// A world normal for `ray_thread`, on `ray_d` (for ray generation's direction store,
    /// which `tri.dir` reads).
    pub normal_write: Signal<Out, Bit>,
    pub done_mask: Signal<Out, Bits<32>>,
    pub query_thread: Signal<In, Bits<5>>,
    pub pending: Signal<Out, Bit>,
    /// An entry's (or normal's) record came from the instance cache (a pulse per lookup).
    pub cache_hit: Signal<Out, Bit>,
    /// An entry's (or normal's) record is read from bank 4 (a pulse per lookup).
    pub cache_miss: Signal<Out, Bit>,

    /// Per thread, each word of its world ray.
    world: [RAM<Bits<W>, 5>; 6],
    /// The entry slot: a thread's instance that no entry has begun for yet.
    slot_valid: DFF<Bit>,
    slot_thread: DFF<Bits<5>>,
    slot_instance: DFF<Bits<24>>,
    slot_normal: DFF<Bit>,
    slot_nz: DFF<Bits<W>>,
    taken: Signal<Local, Bit>,
    /// The entry begun: its thread, the address of its next read (a register, so that no
    /// adder sits in front of the bus), the words read and arrived, and the reads in flight
    /// (bit k: a read k + 1 clocks ago).
    phase: DFF<EntryPhase>,
    entry_thread: DFF<Bits<5>>,
    next_addr: DFF<Bits<24>>,
    entry_normal: DFF<Bit>,
    entry_nz: DFF<Bits<W>>,
    /// Words the entry reads: 13, or a normal's 12.
    entry_words: Signal<Local, Bits<4>>,
    /// The step from this read's address to the next: 1, but from the matrix's last word to
    /// the root, and 0 after a normal's third column (its fourth, which a vector never reads,
    /// repeats the third: read `issued` is row `issued / 4`, column `min(issued % 4, 2)`).
    addr_step: Signal<Local, Bits<24>>,
    /// The slot's instance record's first word in bank 4.
    record: Signal<Local, Bits<24>>,
    issued: DFF<Bits<4>>,
    arrived: DFF<Bits<4>>,
    flight: DFF<Bits<8>>,
    reading: Signal<Local, Bit>,
    arrives: Signal<Local, Bit>,
    root_arrives: Signal<Local, Bit>,
    last_normal_word: Signal<Local, Bit>,
    /// The matrix, its words shifted in from the top as they arrive (word 0 ends in `matrix[0]`).
    matrix: [DFF<Bits<W>>; 12],
    /// The origin's result, until the direction's comes.
    origin: [DFF<Bits<W>>; 3],
    /// The ray being written.
    write_valid: DFF<Bit>,
    write_thread: DFF<Bits<5>>,
    write_o: [DFF<Bits<W>>; 3],
    write_d: [DFF<Bits<W>>; 3],
    write_mask: DFF<Bits<32>>,
    normal_valid: DFF<Bit>,
    /// Per thread: its entered ray is not written yet (bit `thread`).
    waiting: DFF<Bits<32>>,
    taken_mask: Signal<Local, Bits<32>>,
    pending_r: DFF<Bit>,
    c_one: Constant<Bits<32>>,
    c_pair: [Constant<Bits<2>>; 3],
    c_words: Constant<Bits<4>>,
    c_last_word: Constant<Bits<4>>,
    c_first_word: Constant<Bits<24>>,
    c_normal_first: Constant<Bits<24>>,
    c_normal_words: Constant<Bits<4>>,
    /// The root's word after the matrix's first.
    c_root_step: Constant<Bits<24>>,
    c_last_matrix_read: Constant<Bits<4>>,
    c_ml_last: Constant<Bits<3>>,
    /// The instance cache: per way a RAM of the sets' tags `{instance, normal, valid}`; per
    /// line (`set << way_shift | way`) the twelve words of a record's world-to-object matrix
    /// (or its normal matrix as read, twelve words) and the root; per set the way its next
    /// miss fills.
    cache_tag: [RAM<Bits<26>, 9>; 4],
    cache_words: [RAM<Bits<W>, 9>; 12],
    cache_root: RAM<Bits<26>, 9>,
    fill_counts: FillCounts,
    /// The line a hit reads (the entry's set, the way that hit) and the line a miss fills.
    hit_line: Signal<Local, Bits<9>>,
    fill_line: Signal<Local, Bits<9>>,
    /// The slot's set, read as its entry begins; the entry's set (the slot's, kept) and tag,
    /// for the compare and the fill.
    slot_set: Signal<Local, Bits<9>>,
    entry_instance: DFF<Bits<24>>,
    entry_set: DFF<Bits<9>>,
    entry_tag: Signal<Local, Bits<26>>,
    tag_r: [DFF<Bits<26>>; 4],
    victim_r: DFF<Bits<2>>,
    root_r: DFF<Bits<26>>,
    hit_r: DFF<Bit>,
    hit_way_r: DFF<Bits<2>>,
    /// A hit's root, registered in `Words`, is written to the traversal unit.
    hit_root: DFF<Bit>,
    /// No sweep wrote the cache as the entry's set was read: its words are of this frame.
    look_clean: DFF<Bit>,
    /// A normal's twelfth word arrived last clock: its matrix is whole, to be written.
    fill_normal: DFF<Bit>,
    fill: Signal<Local, Bit>,
    /// The frame's records may differ from the last frame's: each set's tag is cleared, one a
    /// clock, from the frame's start.
    sweeping: DFF<Bit>,
    sweep_set: DFF<Bits<9>>,
    c_cached: Constant<Bit>,
    c_set_mask: Constant<Bits<9>>,
    /// `ways - 1`, `log2(ways)`, each way's number, and whether the cache has that way.
    c_way_mask: Constant<Bits<2>>,
    c_way_shift: Constant<Bits<2>>,
    c_way: [Constant<Bits<2>>; 4],
    c_way_used: [Constant<Bit>; 4],
    /// The program uses the unit (see the module doc's "Absent").
    c_present: Constant<Bit>,
}

impl<const W: usize> InstanceRays<W> {
    /// The unit for SRAM read latency `mem_latency` (1..=6), absent unless `present`, with an
    /// instance cache of `cache_sets` sets of `cache_ways` ways (see
    /// [`cache_shape_supported`]; 0 sets for none).
    pub fn new(mem_latency: u32, present: bool, cache_sets: u32, cache_ways: u32) -> Self {
        assert!((1..=6).contains(&mem_latency));
        assert!(
            cache_shape_supported(cache_sets, cache_ways),
            "{cache_sets} instance cache sets of {cache_ways} ways"
        );
        Self {
            clock: Default::default(),
            frame_start: Default::default(),
            world_write: Default::default(),
            world_pair: Default::default(),
            word_a: Default::default(),
            word_b: Default::default(),
            thread: Default::default(),
            offer: Default::default(),
            offer_normal: Default::default(),
            instance_id: Default::default(),
            refused: Default::default(),
            bus_free: Default::default(),
            read: Default::default(),
            addr: Default::default(),
            rdata: Default::default(),
            root_write: Default::default(),
            root_thread: Default::default(),
            root: Default::default(),
            gen_valid: Default::default(),
            gen_m: Default::default(),
            gen_v: Default::default(),
            gen_point: Default::default(),
            gen_direction: Default::default(),
            gen_normal: Default::default(),
            gen_thread: Default::default(),
            gen_take: Default::default(),
            out_valid: Default::default(),
            out_direction: Default::default(),
            out_normal: Default::default(),
            out_thread: Default::default(),
            out_v: Default::default(),
            ray_write: Default::default(),
            ray_thread: Default::default(),
            ray_o: Default::default(),
            ray_d: Default::default(),
            normal_write: Default::default(),
            done_mask: Default::default(),
            query_thread: Default::default(),
            pending: Default::default(),
            cache_hit: Default::default(),
            cache_miss: Default::default(),
            world: Default::default(),
            slot_valid: Default::default(),
            slot_thread: Default::default(),
            slot_instance: Default::default(),
            slot_normal: Default::default(),
            slot_nz: Default::default(),
            taken: Default::default(),
            phase: Default::default(),
            entry_thread: Default::default(),
            next_addr: Default::default(),
            entry_normal: Default::default(),
            entry_nz: Default::default(),
            entry_words: Default::default(),
            addr_step: Default::default(),
            record: Default::default(),
            issued: Default::default(),
            arrived: Default::default(),
            flight: Default::default(),
            reading: Default::default(),
            arrives: Default::default(),
            root_arrives: Default::default(),
            last_normal_word: Default::default(),
            matrix: Default::default(),
            origin: Default::default(),
            write_valid: Default::default(),
            write_thread: Default::default(),
            write_o: Default::default(),
            write_d: Default::default(),
            write_mask: Default::default(),
            normal_valid: Default::default(),
            waiting: Default::default(),
            taken_mask: Default::default(),
            pending_r: Default::default(),
            c_one: Constant::new(1u64.into()),
            c_pair: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_words: Constant::new((MATRIX_WORDS + 1).into()),
            c_last_word: Constant::new(MATRIX_WORDS.into()),
            c_first_word: Constant::new((instance_word::WORLD_TO_OBJECT as u64).into()),
            c_normal_first: Constant::new((instance_word::NORMAL_MATRIX as u64).into()),
            c_normal_words: Constant::new(MATRIX_WORDS.into()),
            c_last_matrix_read: Constant::new((MATRIX_WORDS - 1).into()),
            c_root_step: Constant::new(
                ((instance_word::ROOT - instance_word::WORLD_TO_OBJECT) as u64
                    - (MATRIX_WORDS - 1))
                    .into(),
            ),
            c_ml_last: Constant::new(u64::from(mem_latency - 1).into()),
            cache_tag: std::array::from_fn(|_| empty_cache_tags()),
            cache_words: Default::default(),
            cache_root: Default::default(),
            fill_counts: Default::default(),
            hit_line: Default::default(),
            fill_line: Default::default(),
            slot_set: Default::default(),
            entry_instance: Default::default(),
            entry_set: Default::default(),
            entry_tag: Default::default(),
            tag_r: Default::default(),
            victim_r: Default::default(),
            root_r: Default::default(),
            hit_r: Default::default(),
            hit_way_r: Default::default(),
            hit_root: Default::default(),
            look_clean: Default::default(),
            fill_normal: Default::default(),
            fill: Default::default(),
            sweeping: Default::default(),
            sweep_set: Default::default(),
            c_cached: Constant::new(cache_sets > 0),
            c_set_mask: Constant::new(u64::from(cache_sets.max(1) - 1).into()),
            c_way_mask: Constant::new(u64::from(cache_ways - 1).into()),
            c_way_shift: Constant::new(u64::from(way_shift(cache_ways)).into()),
            c_way: std::array::from_fn(|w| Constant::new((w as u64).into())),
            c_way_used: std::array::from_fn(|w| {
                Constant::new(cache_sets > 0 && (w as u32) < cache_ways)
            }),
            c_present: Constant::new(present),
        }
    }
}

impl<const W: usize> Logic for InstanceRays<W> {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            slot_valid,
            slot_thread,
            slot_instance,
            slot_normal,
            slot_nz,
            phase,
            entry_thread,
            next_addr,
            entry_normal,
            entry_nz,
            issued,
            arrived,
            flight,
            write_valid,
            write_thread,
            write_mask,
            normal_valid,
            waiting,
            pending_r,
            entry_instance,
            entry_set,
            victim_r,
            root_r,
            hit_r,
            hit_way_r,
            hit_root,
            look_clean,
            fill_normal,
            sweeping,
            sweep_set
        );
        for k in 0..12 {
            self.matrix[k].clock.next = self.clock.val();
            self.matrix[k].d.next = self.matrix[k].q.val();
        }
        for w in 0..4 {
            self.tag_r[w].clock.next = self.clock.val();
            self.tag_r[w].d.next = self.tag_r[w].q.val();
        }
        for k in 0..3 {
            self.origin[k].clock.next = self.clock.val();
            self.origin[k].d.next = self.origin[k].q.val();
            self.write_o[k].clock.next = self.clock.val();
            self.write_o[k].d.next = self.origin[k].q.val();
            self.write_d[k].clock.next = self.clock.val();
            self.write_d[k].d.next = self.out_v[k].val();
        }

        // The world ray, a pair of words per `tri.world`; read for the entry's thread.
        for k in 0..6 {
            self.world[k].read_clock.next = self.clock.val();
            self.world[k].write_clock.next = self.clock.val();
            self.world[k].write_address.next = self.thread.val();
            self.world[k].read_address.next = self.entry_thread.q.val();
        }
        for k in 0..3 {
            self.world[2 * k].write_data.next = self.word_a.val().get_bits::<W>(0);
            self.world[2 * k + 1].write_data.next = self.word_b.val().get_bits::<W>(0);
            self.world[2 * k].write_enable.next =
                self.world_write.val() & (self.world_pair.val() == self.c_pair[k].val());
            self.world[2 * k + 1].write_enable.next =
                self.world_write.val() & (self.world_pair.val() == self.c_pair[k].val());
        }

        // The slot takes an entry while it is empty; an idle unit begins the slot's entry.
        self.refused.next = self.slot_valid.q.val();
        self.taken.next = self.offer.val() & (!self.slot_valid.q.val());
        if self.taken.val() {
            self.slot_valid.d.next = true;
            self.slot_thread.d.next = self.thread.val();
            self.slot_instance.d.next = self.instance_id.val();
            self.slot_normal.d.next = self.offer_normal.val();
            self.slot_nz.d.next = self.word_b.val().get_bits::<W>(0);
        }
        // The slot's record: `INSTANCE_WORDS` = 24 = 16 + 8 words an instance.
        self.record.next = (self.slot_instance.q.val() << 4) + (self.slot_instance.q.val() << 3);
        self.slot_set.next = ((bit_cast::<9, 8>(self.slot_instance.q.val().get_bits::<8>(0)) << 1)
            | bit_cast::<9, 1>(self.slot_normal.q.val().into()))
            & self.c_set_mask.val();
        if (self.phase.q.val() == EntryPhase::Idle) & self.slot_valid.q.val() {
            self.slot_valid.d.next = false;
            self.entry_instance.d.next = self.slot_instance.q.val();
            self.entry_set.d.next = self.slot_set.val();
            self.look_clean.d.next = !self.sweeping.q.val();
            self.entry_thread.d.next = self.slot_thread.q.val();
            self.entry_normal.d.next = self.slot_normal.q.val();
            self.entry_nz.d.next = self.slot_nz.q.val();
            self.next_addr.d.next = self.record.val() + self.c_first_word.val();
            if self.slot_normal.q.val() {
                self.next_addr.d.next = self.record.val() + self.c_normal_first.val();
            }
            self.issued.d.next = 0.into();
            self.arrived.d.next = 0.into();
            self.phase.d.next = EntryPhase::Fetch;
            if self.c_cached.val() {
                self.phase.d.next = EntryPhase::Look;
            }
        }

        // The instance cache: the slot's set of tags is read in every clock, so that an entry
        // beginning has them in `Look`; the tag compare has a clock of its own after the
        // block RAM's (the tester's triangle cache found the read and the compare too long for
        // one clock). A hit's way is known in `Decide`, which reads its line's words.
        self.entry_tag.next = (bit_cast::<26, 24>(self.entry_instance.q.val()) << 2)
            | (bit_cast::<26, 1>(self.entry_normal.q.val().into()) << 1)
            | 1;
        for w in 0..4 {
            self.cache_tag[w].read_clock.next = self.clock.val();
            self.cache_tag[w].write_clock.next = self.clock.val();
            self.cache_tag[w].read_address.next = self.slot_set.val();
        }
        self.fill_counts.clock.next = self.clock.val();
        self.fill_counts.read_set.next = self.slot_set.val();
        self.fill_counts.way_mask.next = self.c_way_mask.val();
        self.hit_line.next = (self.entry_set.q.val() << self.c_way_shift.val())
            | bit_cast::<9, 2>(self.hit_way_r.q.val());
        self.fill_line.next = (self.entry_set.q.val() << self.c_way_shift.val())
            | bit_cast::<9, 2>(self.victim_r.q.val());
        self.cache_root.read_clock.next = self.clock.val();
        self.cache_root.write_clock.next = self.clock.val();
        self.cache_root.read_address.next = self.hit_line.val();
        for k in 0..12 {
            self.cache_words[k].read_clock.next = self.clock.val();
            self.cache_words[k].write_clock.next = self.clock.val();
            self.cache_words[k].read_address.next = self.hit_line.val();
        }
        if self.c_cached.val() & (self.phase.q.val() == EntryPhase::Look) {
            for w in 0..4 {
                self.tag_r[w].d.next = self.cache_tag[w].read_data.val();
            }
            self.victim_r.d.next = self.fill_counts.way.val();
            self.phase.d.next = EntryPhase::Compare;
        }
        if self.phase.q.val() == EntryPhase::Compare {
            // A way the cache does not have keeps its tags zero (never written): no match.
            self.hit_r.d.next = false;
            self.hit_way_r.d.next = 0.into();
            for w in 0..4 {
                if self.tag_r[w].q.val() == self.entry_tag.val() {
                    self.hit_r.d.next = self.look_clean.q.val();
                    self.hit_way_r.d.next = self.c_way[w].val();
                }
            }
            self.phase.d.next = EntryPhase::Decide;
        }
        self.cache_hit.next = false;
        self.cache_miss.next = false;
        if self.phase.q.val() == EntryPhase::Decide {
            if self.hit_r.q.val() {
                self.cache_hit.next = true;
                self.phase.d.next = EntryPhase::Words;
            } else {
                self.cache_miss.next = true;
                self.phase.d.next = EntryPhase::Fetch;
            }
        }
        self.hit_root.d.next = false;
        if self.phase.q.val() == EntryPhase::Words {
            self.root_r.d.next = self.cache_root.read_data.val();
            for k in 0..12 {
                self.matrix[k].d.next = self.cache_words[k].read_data.val();
            }
            self.hit_root.d.next = !self.entry_normal.q.val();
            self.phase.d.next = EntryPhase::Origin;
            if self.entry_normal.q.val() {
                self.phase.d.next = EntryPhase::Normal;
            }
        }

        // Fetch: a read in each clock the bus is free; each word shifts in as it arrives.
        self.entry_words.next = self.c_words.val();
        if self.entry_normal.q.val() {
            self.entry_words.next = self.c_normal_words.val();
        }
        self.reading.next = (self.phase.q.val() == EntryPhase::Fetch)
            & (self.issued.q.val() != self.entry_words.val())
            & self.bus_free.val();
        self.read.next = self.reading.val();
        self.addr.next = self.next_addr.q.val();
        self.addr_step.next = 1.into();
        if self.issued.q.val() == self.c_last_matrix_read.val() {
            self.addr_step.next = self.c_root_step.val();
        }
        if self.entry_normal.q.val() {
            self.addr_step.next = 1.into();
            if self.issued.q.val().get_bits::<2>(0) == 2 {
                self.addr_step.next = 0.into();
            }
        }
        if self.reading.val() {
            self.issued.d.next = self.issued.q.val() + 1;
            self.next_addr.d.next = self.next_addr.q.val() + self.addr_step.val();
        }
        self.flight.d.next =
            (self.flight.q.val() << 1) | bit_cast::<8, 1>(self.reading.val().into());
        self.arrives.next = self.flight.q.val().get_bit(self.c_ml_last.val().index());
        self.root_arrives.next =
            self.arrives.val() & (self.arrived.q.val() == self.c_last_word.val());
        if self.arrives.val() & (!self.root_arrives.val()) {
            for k in 0..11 {
                self.matrix[k].d.next = self.matrix[k + 1].q.val();
            }
            self.matrix[11].d.next = self.rdata.val().get_bits::<W>(0);
        }
        if self.arrives.val() {
            self.arrived.d.next = self.arrived.q.val() + 1;
        }
        if self.root_arrives.val() {
            self.phase.d.next = EntryPhase::Origin;
        }
        self.last_normal_word.next = self.arrives.val()
            & self.entry_normal.q.val()
            & (self.arrived.q.val() == self.c_last_word.val() - 1);
        if self.last_normal_word.val() {
            self.phase.d.next = EntryPhase::Normal;
        }
        self.root_write.next = self.root_arrives.val();
        self.root_thread.next = self.entry_thread.q.val();
        self.root.next = self.rdata.val().get_bits::<26>(0);
        if self.hit_root.q.val() {
            self.root_write.next = true;
            self.root.next = self.root_r.q.val();
        }

        // A miss's record fills its set once whole: an entry's as its root arrives (the
        // matrix's twelve words are in), a normal's the clock after its twelfth word. The
        // sweep has the write port while it runs; a record it keeps out is read again.
        self.fill_normal.d.next = self.last_normal_word.val();
        self.fill.next = self.c_cached.val()
            & (self.root_arrives.val() | self.fill_normal.q.val())
            & (!self.sweeping.q.val());
        for w in 0..4 {
            self.cache_tag[w].write_address.next = self.entry_set.q.val();
            self.cache_tag[w].write_data.next = self.entry_tag.val();
            self.cache_tag[w].write_enable.next = self.c_way_used[w].val()
                & self.fill.val()
                & (self.victim_r.q.val() == self.c_way[w].val());
        }
        self.fill_counts.fill_set.next = self.entry_set.q.val();
        self.fill_counts.fill_way.next = self.victim_r.q.val();
        self.fill_counts.fill.next = self.fill.val();
        self.cache_root.write_address.next = self.fill_line.val();
        self.cache_root.write_data.next = self.rdata.val().get_bits::<26>(0);
        self.cache_root.write_enable.next = self.fill.val();
        for k in 0..12 {
            self.cache_words[k].write_address.next = self.fill_line.val();
            self.cache_words[k].write_data.next = self.matrix[k].q.val();
            self.cache_words[k].write_enable.next = self.fill.val();
        }
        if self.sweeping.q.val() {
            for w in 0..4 {
                self.cache_tag[w].write_address.next = self.sweep_set.q.val();
                self.cache_tag[w].write_data.next = 0.into();
                self.cache_tag[w].write_enable.next = self.c_way_used[w].val();
            }
            self.sweep_set.d.next = self.sweep_set.q.val() + 1;
            if self.sweep_set.q.val() == self.c_set_mask.val() {
                self.sweeping.d.next = false;
            }
        }

        // The requests: the origin as a point, then the direction as a vector; or the normal
        // as a vector.
        self.gen_valid.next = (self.phase.q.val() == EntryPhase::Origin)
            | (self.phase.q.val() == EntryPhase::Direction)
            | (self.phase.q.val() == EntryPhase::Normal);
        self.gen_point.next = self.phase.q.val() == EntryPhase::Origin;
        self.gen_direction.next = self.phase.q.val() == EntryPhase::Direction;
        self.gen_normal.next = self.phase.q.val() == EntryPhase::Normal;
        self.gen_thread.next = self.entry_thread.q.val();
        for k in 0..12 {
            self.gen_m[k].next = self.matrix[k].q.val();
        }
        for k in 0..3 {
            if self.phase.q.val() == EntryPhase::Origin {
                self.gen_v[k].next = self.world[k].read_data.val();
            } else {
                self.gen_v[k].next = self.world[3 + k].read_data.val();
            }
        }
        if self.phase.q.val() == EntryPhase::Normal {
            self.gen_v[0].next = self.world[0].read_data.val();
            self.gen_v[1].next = self.world[1].read_data.val();
            self.gen_v[2].next = self.entry_nz.q.val();
        }
        if self.gen_take.val() & (self.phase.q.val() == EntryPhase::Origin) {
            self.phase.d.next = EntryPhase::Direction;
        }
        if self.gen_take.val()
            & ((self.phase.q.val() == EntryPhase::Direction)
                | (self.phase.q.val() == EntryPhase::Normal))
        {
            self.phase.d.next = EntryPhase::Idle;
        }

        // The results: the origin waits for the direction; then the ray is written.
        if self.out_valid.val() & (!self.out_direction.val()) & (!self.out_normal.val()) {
            for k in 0..3 {
                self.origin[k].d.next = self.out_v[k].val();
            }
        }
        self.write_valid.d.next = self.out_valid.val() & self.out_direction.val();
        self.normal_valid.d.next = self.out_valid.val() & self.out_normal.val();
        self.write_thread.d.next = self.out_thread.val();
        self.write_mask.d.next = 0.into();
        if self.out_valid.val() & (self.out_direction.val() | self.out_normal.val()) {
            self.write_mask.d.next = self.c_one.val() << self.out_thread.val();
        }
        self.normal_write.next = self.normal_valid.q.val();
        self.ray_write.next = self.write_valid.q.val();
        self.ray_thread.next = self.write_thread.q.val();
        for k in 0..3 {
            self.ray_o[k].next = self.write_o[k].q.val();
            self.ray_d[k].next = self.write_d[k].q.val();
        }
        self.done_mask.next = self.write_mask.q.val();

        // Pending from the `tri.enter` until the write.
        self.taken_mask.next = 0.into();
        if self.taken.val() {
            self.taken_mask.next = self.c_one.val() << self.thread.val();
        }
        self.waiting.d.next =
            (self.waiting.q.val() & (!self.write_mask.q.val())) | self.taken_mask.val();
        self.pending_r.d.next = self
            .waiting
            .q
            .val()
            .get_bit(self.query_thread.val().index());
        self.pending.next = self.pending_r.q.val();

        if !self.c_present.val() {
            self.refused.next = false;
            self.read.next = false;
            self.addr.next = 0.into();
            self.root_write.next = false;
            self.root_thread.next = 0.into();
            self.root.next = 0.into();
            self.gen_valid.next = false;
            self.gen_point.next = false;
            self.gen_direction.next = false;
            self.gen_normal.next = false;
            self.gen_thread.next = 0.into();
            for k in 0..12 {
                self.gen_m[k].next = 0.into();
            }
            self.normal_write.next = false;
            self.ray_write.next = false;
            self.ray_thread.next = 0.into();
            for k in 0..3 {
                self.gen_v[k].next = 0.into();
                self.ray_o[k].next = 0.into();
                self.ray_d[k].next = 0.into();
            }
            self.done_mask.next = 0.into();
            self.pending.next = false;
            self.cache_hit.next = false;
            self.cache_miss.next = false;
        }

        if self.frame_start.val() {
            self.slot_valid.d.next = false;
            self.phase.d.next = EntryPhase::Idle;
            self.waiting.d.next = 0.into();
            self.sweeping.d.next = self.c_cached.val();
            self.sweep_set.d.next = 0.into();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::sim_harness::{clock_cycle, settle};
    use crate::layout::INSTANCE_WORDS;
    use crate::units;
    use rand::{Rng, SeedableRng};
    use std::collections::VecDeque;

    /// An absent unit (a program with no instance entry) holds every output at 0 whatever its
    /// inputs do, so Yosys (xc2v) keeps nothing of it: no LUT, flip-flop or RAM. A unit with
    /// one output left live keeps the registers and RAMs behind it.
    #[test]
    fn an_absent_unit_synthesizes_to_nothing() {
        let mut uut = InstanceRays::<24>::new(2, false, 512, 1);
        uut.connect_all();
        let dir = tempfile::tempdir().unwrap();
        let src = dir.path().join("instance_rays.v");
        std::fs::write(&src, generate_verilog(&uut)).unwrap();
        let r = crate::synth::synth_xc2v(&[src], "top", dir.path()).unwrap();
        assert_eq!(
            (r.total_luts(), r.flip_flops, r.block_rams),
            (0, 0, 0),
            "{:?}",
            r.all_cells
        );
    }

    /// InstanceRays in rust-hdl simulation, with threads writing world rays and entering
    /// instances at random, a bank 4 of random records behind a bus that is free in random
    /// clocks (SRAM latency 3), and a model of the tester's TransformUnit that takes a request
    /// in a random clock and returns `units::transform` of its words 28 clocks later. Asserts:
    /// every entry's ray is written whole, once, for its thread, and is `units::transform` of
    /// the thread's world origin (a point) and direction (a vector) by the record's
    /// world-to-object words; the record's root goes to the thread before its ray;
    /// `done_mask` is the written thread's bit; `pending` is high from the `tri.enter` until
    /// the write; a full slot refuses; reads go out only in free clocks, thirteen per entry.
    /// Four offers in ten are normals' (`tri.normal`): each gives `units::transform3` of the
    /// record's normal matrix and the thread's world words 0, 1 and the offer's z, once, on
    /// `normal_write`, with no root and no ray, in twelve reads.
    ///
    /// Four frames, the bank's records rewritten between them (a frame's start after the
    /// unit drained, as the processor's): with an instance cache, a record read in an earlier
    /// frame would give a wrong ray. Every entry is a hit or a miss, a miss reads its twelve
    /// or thirteen words and a hit none; where the cache holds every record and kind (32
    /// sets of one way, 16 of two, 8 of four) each misses at most once a frame, with 4 sets
    /// of one way they evict each other.
    #[test]
    fn every_entry_gets_its_object_ray_through_the_shared_unit() {
        entries_case(0, 1, &ALL, Expect::NoCache, 35);
    }

    #[test]
    fn the_instance_cache_keeps_each_record_for_its_frame() {
        entries_case(32, 1, &ALL, Expect::Fits, 36);
        entries_case(16, 2, &ALL, Expect::Fits, 38);
        entries_case(8, 4, &ALL, Expect::Fits, 39);
    }

    #[test]
    fn instance_cache_sets_evict_each_other() {
        entries_case(4, 1, &ALL, Expect::Evicts, 37);
    }

    /// Instances 0 and 2 share every set of a direct-mapped cache of four items (set
    /// `{instance[7:0], normal} & 3`: the normal bit alone), so their entries evict each other;
    /// two ways of two sets hold both, and each record and kind misses once a frame. A cache
    /// that filled or looked up one way only would miss as the direct-mapped one does.
    #[test]
    fn two_ways_keep_what_one_way_evicts() {
        entries_case(4, 1, &[0, 2], Expect::Evicts, 40);
        entries_case(2, 2, &[0, 2], Expect::Fits, 41);
    }

    const ALL: [usize; 16] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];

    #[derive(PartialEq)]
    enum Expect {
        NoCache,
        /// Every record and kind in the pool misses at most once a frame.
        Fits,
        /// They miss more often than that (and some hit).
        Evicts,
    }

    /// Entries of random threads into instances drawn from `pool` (of 16 records), through
    /// an instance cache of `cache_sets` sets of `ways` ways.
    fn entries_case(cache_sets: u32, ways: u32, pool: &[usize], expect: Expect, seed: u64) {
        let f = Format::E7M16;
        let mem_latency = 3;
        let records = 16;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        // Random floats, and random roots in each record's root word.
        let new_bank = |rng: &mut rand_chacha::ChaCha8Rng| -> Vec<u32> {
            (0..records * INSTANCE_WORDS)
                .map(|k| {
                    if k % INSTANCE_WORDS == instance_word::ROOT {
                        rng.gen_range(0..1 << 26)
                    } else {
                        f.from_f64(rng.gen_range(-2.0..2.0))
                    }
                })
                .collect()
        };
        let mut bank = new_bank(&mut rng);
        let mut u = InstanceRays::<24>::new(mem_latency, true, cache_sets, ways);
        u.connect_all();
        let cycle =
            |u: &mut InstanceRays<24>| clock_cycle(u, |u, c| u.clock.next = Clock { clk: c });
        u.frame_start.next = true;
        cycle(&mut u);
        u.frame_start.next = false;

        let mut world = [[0u32; 6]; 32];
        // Per thread: the ray its entry must write, and the root before it; or the normal.
        let mut entered: [Option<([u32; 3], [u32; 3])>; 32] = [None; 32];
        let mut normals: [Option<[u32; 3]>; 32] = [None; 32];
        let mut normals_written = 0;
        let mut roots: [Option<u32>; 32] = [None; 32];
        let mut roots_written = 0;
        let mut memory: VecDeque<Option<u32>> = vec![None; mem_latency as usize].into();
        let mut in_unit: VecDeque<Option<(u32, bool, bool, [u32; 3])>> = vec![None; 28].into();
        let (mut offers, mut refused, mut written, mut reads) = (0, 0, 0, 0);
        let (mut hits, mut misses) = (0, 0);
        const FRAME_CLOCKS: usize = 2000;
        let frames = 4;
        for clock in 0..frames * FRAME_CLOCKS {
            let thread = rng.gen_range(0..32u32);
            let t = thread as usize;
            // The first 96 clocks write every thread's world ray; then world words and entries
            // at random, never for a thread whose entry is pending; none in a frame's last 150
            // clocks (the unit drains) and first 40 (the cache's sweep of 32 sets).
            let quiet = clock % FRAME_CLOCKS >= FRAME_CLOCKS - 150 || clock % FRAME_CLOCKS < 40;
            let (write, offer) = if clock < 96 {
                (true, false)
            } else if quiet {
                (false, false)
            } else if entered[t].is_none() && normals[t].is_none() {
                let r = rng.gen_range(0..10);
                (r == 0, r >= 7)
            } else {
                (false, false)
            };
            let pair = if clock < 96 {
                clock % 3
            } else {
                rng.gen_range(0..3)
            };
            let words = [0, 1].map(|_| f.from_f64(rng.gen_range(-3.0..3.0)));
            let thread = if clock < 96 { clock as u32 / 3 } else { thread };
            let instance = pool[rng.gen_range(0..pool.len())];
            let record = instance * INSTANCE_WORDS;
            u.thread.next = u64::from(thread).into();
            u.world_write.next = write;
            u.world_pair.next = (pair as u64).into();
            u.word_a.next = u64::from(words[0]).into();
            u.word_b.next = u64::from(words[1]).into();
            let normal = offer && rng.gen_bool(0.4);
            u.offer.next = offer;
            u.offer_normal.next = normal;
            u.instance_id.next = (instance as u64).into();
            u.bus_free.next = rng.gen_bool(0.6);
            u.rdata.next = u64::from(memory.pop_front().unwrap().unwrap_or(0xdead)).into();
            u.gen_take.next = rng.gen_bool(0.5);
            let back = in_unit.pop_front().unwrap();
            u.out_valid.next = back.is_some();
            if let Some((t, direction, normal, v)) = back {
                u.out_thread.next = u64::from(t).into();
                u.out_direction.next = direction;
                u.out_normal.next = normal;
                for k in 0..3 {
                    u.out_v[k].next = u64::from(v[k]).into();
                }
            }
            let asked = rng.gen_range(0..32usize);
            u.query_thread.next = (asked as u64).into();
            let want_pending = entered[asked].is_some() || normals[asked].is_some();
            u.clock.next = Clock { clk: false };
            settle(&mut u);

            let t = thread as usize;
            if write {
                world[t][2 * pair] = words[0];
                world[t][2 * pair + 1] = words[1];
            }
            if offer {
                offers += 1;
                if u.refused.val() {
                    refused += 1;
                } else if normal {
                    let at = record + instance_word::NORMAL_MATRIX;
                    let m: &[u32; 9] = bank[at..at + 9].try_into().unwrap();
                    normals[t] = Some(units::transform3(
                        f,
                        m,
                        [world[t][0], world[t][1], words[1]],
                    ));
                } else {
                    let m: units::Mat34W = bank[record..record + 12].try_into().unwrap();
                    let [ox, oy, oz, dx, dy, dz] = world[t];
                    entered[t] = Some((
                        units::transform(f, &m, [ox, oy, oz], true),
                        units::transform(f, &m, [dx, dy, dz], false),
                    ));
                    roots[t] = Some(bank[record + instance_word::ROOT]);
                }
            }
            assert!(u.bus_free.val() || !u.read.val(), "a read on a busy bus");
            memory.push_back(u.read.val().then(|| {
                reads += 1;
                let addr = u.addr.val().to_u64() as usize;
                bank[addr]
            }));
            let taken = u.gen_valid.val() && u.gen_take.val();
            in_unit.push_back(taken.then(|| {
                let word = |s: &Signal<Out, Bits<24>>| s.val().to_u64() as u32;
                let m: units::Mat34W = std::array::from_fn(|k| word(&u.gen_m[k]));
                let v: [u32; 3] = std::array::from_fn(|k| word(&u.gen_v[k]));
                let kinds = [u.gen_point.val(), u.gen_direction.val(), u.gen_normal.val()];
                assert_eq!(kinds.iter().filter(|&&k| k).count(), 1, "one request kind");
                let t = u.gen_thread.val().to_u64() as u32;
                let result = units::transform(f, &m, v, u.gen_point.val());
                (t, u.gen_direction.val(), u.gen_normal.val(), result)
            }));
            if u.root_write.val() {
                let t = u.root_thread.val().to_u64() as usize;
                let root = roots[t].take().expect("one root for a thread that entered");
                assert_eq!(u.root.val().to_u64(), u64::from(root), "thread {t}'s root");
                roots_written += 1;
            }
            if u.ray_write.val() {
                let t = u.ray_thread.val().to_u64() as usize;
                assert!(roots[t].is_none(), "thread {t}'s ray before its root");
                let (o, d) = entered[t].take().expect("a ray for a thread that entered");
                let o_got: [u32; 3] = std::array::from_fn(|k| u.ray_o[k].val().to_u64() as u32);
                let d_got: [u32; 3] = std::array::from_fn(|k| u.ray_d[k].val().to_u64() as u32);
                assert_eq!((o_got, d_got), (o, d), "thread {t}'s object-space ray");
                assert_eq!(u.done_mask.val().to_u64(), 1 << t, "the wake-up of {t}");
                written += 1;
            } else if u.normal_write.val() {
                let t = u.ray_thread.val().to_u64() as usize;
                let n = normals[t].take().expect("a normal for a thread that asked");
                let got: [u32; 3] = std::array::from_fn(|k| u.ray_d[k].val().to_u64() as u32);
                assert_eq!(got, n, "thread {t}'s world normal");
                assert_eq!(u.done_mask.val().to_u64(), 1 << t, "the wake-up of {t}");
                normals_written += 1;
            } else {
                assert_eq!(u.done_mask.val().to_u64(), 0, "a wake-up without a ray");
            }
            hits += usize::from(u.cache_hit.val());
            misses += usize::from(u.cache_miss.val());
            cycle(&mut u);
            assert_eq!(u.pending.val(), want_pending, "thread {asked} pending");
            if clock % FRAME_CLOCKS == FRAME_CLOCKS - 1 {
                // The frame is over: the host rewrites the records, the next frame starts.
                assert!(
                    entered.iter().all(|e| e.is_none()),
                    "an entry left at the frame's end"
                );
                assert!(
                    normals.iter().all(|n| n.is_none()),
                    "a normal left at the frame's end"
                );
                assert!(
                    memory.iter().all(|m| m.is_none()),
                    "a read left at the frame's end"
                );
                bank = new_bank(&mut rng);
                u.frame_start.next = true;
                cycle(&mut u);
                u.frame_start.next = false;
            }
        }
        let left = entered.iter().filter(|e| e.is_some()).count();
        let normals_left = normals.iter().filter(|e| e.is_some()).count();
        assert!(left + normals_left <= 3, "{left} entries unfinished");
        assert!(written > 80, "entries written: {written}");
        assert!(normals_written > 60, "normals written: {normals_written}");
        assert!((written..=written + left).contains(&roots_written));
        if expect == Expect::NoCache {
            let done_reads = 13 * written + 12 * normals_written;
            assert!(
                (done_reads..=done_reads + 13 * (left + normals_left)).contains(&reads),
                "{reads} reads for {written} entries and {normals_written} normals written and \
                 {left} + {normals_left} begun"
            );
            assert_eq!((hits, misses), (0, 0), "no cache, no lookups");
        } else {
            let done = written + normals_written;
            assert!(
                (done..=done + left + normals_left).contains(&(hits + misses)),
                "{hits} hits and {misses} misses for {done} entries and normals written"
            );
            assert!(
                (12 * misses..=13 * misses).contains(&reads),
                "{reads} reads for {misses} misses"
            );
            let keys = 2 * pool.len() * frames;
            if expect == Expect::Fits {
                assert!(
                    misses <= keys,
                    "{misses} misses: a record and kind missed twice in a frame \
                     ({cache_sets} sets of {ways} ways)"
                );
                assert!(hits > misses, "{hits} hits, {misses} misses");
            } else {
                assert!(
                    misses > keys && hits > 10,
                    "{hits} hits and {misses} misses in {cache_sets} sets of {ways} ways \
                     for {} records and kinds",
                    2 * pool.len()
                );
            }
        }
        assert!(
            refused > 10,
            "the slot refused entries ({refused} of {offers})"
        );
    }
}
