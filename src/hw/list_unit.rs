//! `ListUnit`: the triangle tester's front end, the paper's list unit. It takes a thread's
//! commands from the engine in one queue, walks each kd leaf's triangle list in bank 1 by
//! itself, drops the triangle the query starts on and the triangles the thread's mailbox has
//! seen, and hands the tests on to the tester's launch in a second queue. A leaf costs the
//! thread one engine turn (`tri.list`) instead of five per triangle.
//!
//! Engine side (the engine's I5): `enqueue` offers a command of `thread`, taken when `full`
//! is low in that clock. Commands by `kind`: [`CMD_LIST`] the list `word_a..word_b` (bank-1
//! word addresses); [`CMD_INIT`] a new query (passed on as it is; it empties the thread's mailbox); [`CMD_OBJECT`] the object
//! (instance) `word_a` the next lists belong to, which empties the thread's mailbox;
//! [`CMD_SKIP`] the (instance `word_a`, triangle `word_b`) the query must not test. All are
//! done in queue order, so a thread's object and skip apply to exactly its later lists.
//!
//! Launch side: `test_valid` / `test_entry` is the head of the test queue, `test_take` pops
//! it. Entries `{kind[70:69], thread[68:64], a[63:32], b[31:0]}`: [`TEST_TRIANGLE`] (a the
//! triangle, b the instance), [`TEST_INIT`] (the init command) and [`TEST_LIST_END`], queued
//! behind a list's last test so that the tester can count the list as done ([`TEST_WALK_END`]
//! for a list of a traversal-unit walk, marked [`LIST_OF_WALK`]: the tester answers the
//! traversal unit with the closest hit instead).
//!
//! Memory: one bank-1 read per clock on `list_*`, the word `mem_latency` clocks later; the
//! engine's port shares the bus (`engine_banks`: its loads of banks 1, 4, 5 go first).
//!
//! State machine: idle (apply object and skip commands, pass inits on, take a list: 1 clock
//! each), load the thread's mailbox, object and skip (2 clocks), walk: one list word a clock
//! while the test queue has room for the words in flight. A word is compared with the
//! mailbox on its arrival and checked and recorded the clock after ([`units::Mailbox`]: the
//! first `len` of 8 ids, first in first out; the slot written in between is compared with the
//! word before; the thread's RAM copy is written the clock after that), so a list of n words
//! takes about `n + 4 + mem_latency` clocks (latency) at one list word per clock
//! (throughput); a thread has at most one list queued (it waits for its tests before the
//! next).
//!
//! Golden twin: [`units::Mailbox`] (src/units.rs) and the skip rule of the golden model's
//! `test_triangles` (src/model/golden.rs): the tests leave in the order, and with the drops,
//! that the golden model tests the list in.
//!
//! [`units::Mailbox`]: crate::units::Mailbox

use rust_hdl::prelude::*;

use super::ports::SHARED_BUS_BANKS;
use super::SyncFifo;
use crate::layout;

/// Command kinds (the engine's `kind`).
pub const CMD_LIST: u64 = 0;
/// Bit 31 of a [`CMD_LIST`]'s `word_b` (the list end, an address below 2^24): the list is a
/// leaf of a traversal-unit walk, whose end entry is a [`TEST_WALK_END`].
pub const LIST_OF_WALK: u64 = 1 << 31;
pub const CMD_INIT: u64 = 1;
pub const CMD_OBJECT: u64 = 2;
pub const CMD_SKIP: u64 = 3;
/// Test queue entry kinds.
pub const TEST_TRIANGLE: u64 = 0;
pub const TEST_INIT: u64 = 1;
pub const TEST_LIST_END: u64 = 2;
/// The end of a walk's list ([`LIST_OF_WALK`]): the tester answers the traversal unit.
pub const TEST_WALK_END: u64 = 3;

/// A queue entry: `{kind[70:69], thread[68:64], a[63:32], b[31:0]}`.
pub type ListEntry = Bits<71>;

/// The state machine: idle (take a command), read the thread's state, latch it, walk a list.
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum ListPhase {
    Idle,
    Read,
    Latch,
    Walk,
}

#[derive(LogicBlock)]
pub struct ListUnit {
    pub clock: Signal<In, Clock>,
    pub enqueue: Signal<In, Bit>,
    pub kind: Signal<In, Bits<2>>,
    pub thread: Signal<In, Bits<5>>,
    pub word_a: Signal<In, Bits<32>>,
    pub word_b: Signal<In, Bits<32>>,
    pub full: Signal<Out, Bit>,
    /// The engine's loads, a bit per bank (`CoprocessorPort::load_banks`).
    pub engine_banks: Signal<In, Bits<{ layout::BANKS }>>,
    pub list_read: Signal<Out, Bit>,
    pub list_addr: Signal<Out, Bits<24>>,
    pub list_rdata: Signal<In, Bits<32>>,
    pub test_valid: Signal<Out, Bit>,
    pub test_entry: Signal<Out, ListEntry>,
    pub test_take: Signal<In, Bit>,

    commands: SyncFifo<ListEntry, 4, 5>,
    tests: SyncFifo<ListEntry, 3, 4>,
    /// Per thread: the object of its lists, the skipped pair, its mailbox.
    object_ram: RAM<Bits<32>, 5>,
    skip_object_ram: RAM<Bits<32>, 5>,
    skip_triangle_ram: RAM<Bits<32>, 5>,
    mailbox_ids: [RAM<Bits<32>, 5>; 8],
    /// `{next[6:4], len[3:0]}`.
    mailbox_meta: RAM<Bits<8>, 5>,

    phase: DFF<ListPhase>,
    walk_thread: DFF<Bits<5>>,
    cursor: DFF<Bits<24>>,
    list_end: DFF<Bits<24>>,
    /// `cursor == list_end`, registered beside the cursor: the 24-bit compare sat in front
    /// of both the read decision and the list's end entry (`list_end -> tests`, issue 16).
    walked: DFF<Bit>,
    cursor_next: Signal<Local, Bits<24>>,
    /// The list being walked is a leaf of a traversal-unit walk.
    of_walk: DFF<Bit>,
    object_id: DFF<Bits<32>>,
    skip_object: DFF<Bits<32>>,
    skip_triangle: DFF<Bits<32>>,
    ids: [DFF<Bits<32>>; 8],
    mb_len: DFF<Bits<4>>,
    mb_next: DFF<Bits<3>>,
    /// Slot k holds one of the mailbox's ids (`k < mb_len`), kept beside `mb_len` so that
    /// the check reads a bit instead of eight compares with the length (`mb_len ->
    /// mailbox_ids`, issue 16). While the mailbox fills, a new id goes to slot `len`
    /// (`mb_next == mb_len` below 8), so recording one sets that slot's bit.
    live: [DFF<Bit>; 8],
    /// A word was recorded last clock: the thread's RAM copies (`mailbox_ids`,
    /// `mailbox_meta`) are written now, from `ids` and `mb_next`/`mb_len`, a clock after
    /// the registers. The check's result then reaches only registers; the RAMs' write
    /// enables hang on a flip-flop. They are read again only for a later list, at least
    /// three clocks after a walk's last check.
    recorded: DFF<Bit>,
    /// Reads in flight; entries in the test queue.
    flight: DFF<Bits<4>>,
    queued: DFF<Bits<4>>,
    /// The test queue has room for one more read: the sum of its entries, the reads in
    /// flight and the word being checked, with this clock's read, below 7 (of its 8 entries,
    /// one kept for the list's end entry). A clock old, which is safe: during a walk only a
    /// read adds to the sum. The sum's adders and compare in front of the read decision were
    /// 10-11 levels into the bus (`flight -> list_addr`, `queued -> flight`, issue 16); a
    /// queue entry taken last clock is seen a clock later.
    room: DFF<Bit>,
    /// Test queue entries, reads in flight and the word being checked.
    in_use: Signal<Local, Bits<5>>,
    /// Request valid per clock of SRAM latency.
    flight_line: [DFF<Bit>; 6],
    /// The word that arrived last clock (`arrive_r`) and what was compared on its arrival:
    /// each mailbox id against it, the skipped pair, the word before it (then in this stage);
    /// the mailbox slot this stage wrote last clock, which the compare did not see yet.
    arrive_r: DFF<Bit>,
    word_r: DFF<Bits<32>>,
    hit_r: [DFF<Bit>; 8],
    skip_r: DFF<Bit>,
    same_r: DFF<Bit>,
    wrote_r: [DFF<Bit>; 8],
    take: Signal<Local, Bit>,
    arrive: Signal<Local, Bit>,
    seen: Signal<Local, Bit>,
    fresh: Signal<Local, Bit>,
    push: Signal<Local, Bit>,
    next_after: Signal<Local, Bits<3>>,
    len_after: Signal<Local, Bits<4>>,
    head_kind: Signal<Local, Bits<2>>,
    c_ml_last: Constant<Bits<4>>,
    c_index: [Constant<Bits<4>>; 8],
    /// The kind field of a list-end entry.
    c_list_end: Constant<ListEntry>,
    c_cmd_list: Constant<Bits<2>>,
    c_cmd_init: Constant<Bits<2>>,
    c_cmd_object: Constant<Bits<2>>,
    c_cmd_skip: Constant<Bits<2>>,
    /// [`SHARED_BUS_BANKS`]: the engine's loads of the others go out on their coprocessor's
    /// port and leave the bus free.
    c_shared_banks: Constant<Bits<{ layout::BANKS }>>,
}

/// A per-thread RAM of `value` words: the skip words start all ones (no triangle is skipped
/// until a query says so; a scene without secondary rays never does), the object 0.
fn words_of(value: u64) -> RAM<Bits<32>, 5> {
    RAM::new(
        (0..32u64)
            .map(|k| (Bits::<5>::from(k), Bits::<32>::from(value)))
            .collect(),
    )
}

impl ListUnit {
    /// The unit for SRAM read latency `mem_latency` (1..=6).
    pub fn new(mem_latency: u32) -> Self {
        assert!((1..=6).contains(&mem_latency));
        // A walk's list end is a list end with the walk's bit (69) set.
        assert!(TEST_WALK_END == TEST_LIST_END | 1 && TEST_LIST_END & 1 == 0);
        Self {
            clock: Default::default(),
            enqueue: Default::default(),
            kind: Default::default(),
            thread: Default::default(),
            word_a: Default::default(),
            word_b: Default::default(),
            full: Default::default(),
            engine_banks: Default::default(),
            list_read: Default::default(),
            list_addr: Default::default(),
            list_rdata: Default::default(),
            test_valid: Default::default(),
            test_entry: Default::default(),
            test_take: Default::default(),
            commands: Default::default(),
            tests: Default::default(),
            // Object 0 until the thread names one (a scene of one object never does).
            object_ram: words_of(0),
            skip_object_ram: words_of(0xffff_ffff),
            skip_triangle_ram: words_of(0xffff_ffff),
            mailbox_ids: Default::default(),
            mailbox_meta: Default::default(),
            phase: Default::default(),
            walk_thread: Default::default(),
            cursor: Default::default(),
            list_end: Default::default(),
            walked: Default::default(),
            cursor_next: Default::default(),
            of_walk: Default::default(),
            object_id: Default::default(),
            skip_object: Default::default(),
            skip_triangle: Default::default(),
            ids: Default::default(),
            mb_len: Default::default(),
            mb_next: Default::default(),
            live: Default::default(),
            recorded: Default::default(),
            flight: Default::default(),
            queued: Default::default(),
            room: Default::default(),
            in_use: Default::default(),
            flight_line: Default::default(),
            arrive_r: Default::default(),
            word_r: Default::default(),
            hit_r: Default::default(),
            skip_r: Default::default(),
            same_r: Default::default(),
            wrote_r: Default::default(),
            take: Default::default(),
            arrive: Default::default(),
            seen: Default::default(),
            fresh: Default::default(),
            push: Default::default(),
            next_after: Default::default(),
            len_after: Default::default(),
            head_kind: Default::default(),
            c_ml_last: Constant::new(u64::from(mem_latency - 1).into()),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
            c_list_end: Constant::new(ListEntry::from(TEST_LIST_END) << 69),
            c_cmd_list: Constant::new(CMD_LIST.into()),
            c_cmd_init: Constant::new(CMD_INIT.into()),
            c_cmd_object: Constant::new(CMD_OBJECT.into()),
            c_cmd_skip: Constant::new(CMD_SKIP.into()),
            c_shared_banks: Constant::new(SHARED_BUS_BANKS.into()),
        }
    }
}

impl Logic for ListUnit {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            phase,
            walk_thread,
            cursor,
            list_end,
            walked,
            of_walk,
            object_id,
            skip_object,
            skip_triangle,
            mb_len,
            mb_next,
            recorded,
            flight,
            queued,
            room,
            arrive_r,
            word_r,
            skip_r,
            same_r
        );
        clock!(self, clock, commands, tests);
        self.object_ram.read_clock.next = self.clock.val();
        self.object_ram.write_clock.next = self.clock.val();
        self.skip_object_ram.read_clock.next = self.clock.val();
        self.skip_object_ram.write_clock.next = self.clock.val();
        self.skip_triangle_ram.read_clock.next = self.clock.val();
        self.skip_triangle_ram.write_clock.next = self.clock.val();
        self.mailbox_meta.read_clock.next = self.clock.val();
        self.mailbox_meta.write_clock.next = self.clock.val();
        for k in 0..8 {
            self.mailbox_ids[k].read_clock.next = self.clock.val();
            self.mailbox_ids[k].write_clock.next = self.clock.val();
            self.ids[k].clock.next = self.clock.val();
            self.ids[k].d.next = self.ids[k].q.val();
            self.hit_r[k].clock.next = self.clock.val();
            self.wrote_r[k].clock.next = self.clock.val();
            self.wrote_r[k].d.next = false;
            self.live[k].clock.next = self.clock.val();
            self.live[k].d.next = self.live[k].q.val();
        }
        for k in 0..6 {
            self.flight_line[k].clock.next = self.clock.val();
        }

        // Engine side.
        self.full.next = self.commands.full.val();
        self.commands.write.next = self.enqueue.val() & (!self.commands.full.val());
        self.commands.data_in.next = (bit_cast::<71, 2>(self.kind.val()) << 69)
            | (bit_cast::<71, 5>(self.thread.val()) << 64)
            | (bit_cast::<71, 32>(self.word_a.val()) << 32)
            | bit_cast::<71, 32>(self.word_b.val());
        self.commands.read.next = false;
        self.head_kind.next = self.commands.data_out.val().get_bits::<2>(69);

        // Launch side.
        self.test_valid.next = !self.tests.empty.val();
        self.test_entry.next = self.tests.data_out.val();
        self.tests.read.next = self.test_take.val();
        self.push.next = false;
        self.tests.data_in.next = self.commands.data_out.val();

        // The thread's state: written by its object and skip commands (idle) and by the
        // mailbox updates of its walk; read for the walk of the list just taken.
        self.object_ram.read_address.next = self.walk_thread.q.val();
        self.skip_object_ram.read_address.next = self.walk_thread.q.val();
        self.skip_triangle_ram.read_address.next = self.walk_thread.q.val();
        self.mailbox_meta.read_address.next = self.walk_thread.q.val();
        self.object_ram.write_address.next = self.commands.data_out.val().get_bits::<5>(64);
        self.skip_object_ram.write_address.next = self.commands.data_out.val().get_bits::<5>(64);
        self.skip_triangle_ram.write_address.next = self.commands.data_out.val().get_bits::<5>(64);
        self.mailbox_meta.write_address.next = self.walk_thread.q.val();
        self.object_ram.write_data.next = self.commands.data_out.val().get_bits::<32>(32);
        self.skip_object_ram.write_data.next = self.commands.data_out.val().get_bits::<32>(32);
        self.skip_triangle_ram.write_data.next = self.commands.data_out.val().get_bits::<32>(0);
        self.object_ram.write_enable.next = false;
        self.skip_object_ram.write_enable.next = false;
        self.skip_triangle_ram.write_enable.next = false;
        self.mailbox_meta.write_enable.next = self.recorded.q.val();
        self.mailbox_meta.write_data.next =
            (bit_cast::<8, 3>(self.mb_next.q.val()) << 4) | bit_cast::<8, 4>(self.mb_len.q.val());
        for k in 0..8 {
            self.mailbox_ids[k].read_address.next = self.walk_thread.q.val();
            self.mailbox_ids[k].write_address.next = self.walk_thread.q.val();
            self.mailbox_ids[k].write_data.next = self.ids[k].q.val();
            self.mailbox_ids[k].write_enable.next = self.wrote_r[k].q.val();
        }

        if (self.phase.q.val() == ListPhase::Idle) & (!self.commands.empty.val()) {
            if self.head_kind.val() == self.c_cmd_init.val() {
                // An init goes on to the launch as it is; a new query empties the mailbox.
                if !self.tests.full.val() {
                    self.push.next = true;
                    self.commands.read.next = true;
                    self.mailbox_meta.write_address.next =
                        self.commands.data_out.val().get_bits::<5>(64);
                    self.mailbox_meta.write_data.next = 0.into();
                    self.mailbox_meta.write_enable.next = true;
                }
            }
            if self.head_kind.val() == self.c_cmd_object.val() {
                self.object_ram.write_enable.next = true;
                self.mailbox_meta.write_address.next =
                    self.commands.data_out.val().get_bits::<5>(64);
                self.mailbox_meta.write_data.next = 0.into();
                self.mailbox_meta.write_enable.next = true;
                self.commands.read.next = true;
            }
            if self.head_kind.val() == self.c_cmd_skip.val() {
                self.skip_object_ram.write_enable.next = true;
                self.skip_triangle_ram.write_enable.next = true;
                self.commands.read.next = true;
            }
            if self.head_kind.val() == self.c_cmd_list.val() {
                self.walk_thread.d.next = self.commands.data_out.val().get_bits::<5>(64);
                self.cursor.d.next = self.commands.data_out.val().get_bits::<24>(32);
                self.list_end.d.next = self.commands.data_out.val().get_bits::<24>(0);
                self.walked.d.next = self.commands.data_out.val().get_bits::<24>(32)
                    == self.commands.data_out.val().get_bits::<24>(0);
                self.of_walk.d.next = self.commands.data_out.val().get_bit(31);
                self.commands.read.next = true;
                self.phase.d.next = ListPhase::Read;
            }
        }
        if self.phase.q.val() == ListPhase::Read {
            self.phase.d.next = ListPhase::Latch;
        }
        if self.phase.q.val() == ListPhase::Latch {
            self.object_id.d.next = self.object_ram.read_data.val();
            self.skip_object.d.next = self.skip_object_ram.read_data.val();
            self.skip_triangle.d.next = self.skip_triangle_ram.read_data.val();
            self.mb_len.d.next = self.mailbox_meta.read_data.val().get_bits::<4>(0);
            self.mb_next.d.next = self.mailbox_meta.read_data.val().get_bits::<3>(4);
            for k in 0..8 {
                self.ids[k].d.next = self.mailbox_ids[k].read_data.val();
                self.live[k].d.next =
                    self.c_index[k].val() < self.mailbox_meta.read_data.val().get_bits::<4>(0);
            }
            self.phase.d.next = ListPhase::Walk;
        }

        // Walk: a read while the test queue has room for every word in flight and for the
        // list's end entry; the engine's loads of banks 1, 4 and 5 take the bus first.
        self.take.next = (self.phase.q.val() == ListPhase::Walk)
            & (!self.walked.q.val())
            & self.room.q.val()
            & ((self.engine_banks.val() & self.c_shared_banks.val()) == 0);
        // The sum of registers is compared twice and this clock's read picks a compare: with
        // the read in the sum, its adders and compare came after the read decision (`phase ->
        // room`, 13 levels: cornell_noshadow's critical path once the tester's take was off it).
        self.in_use.next = bit_cast::<5, 4>(self.queued.q.val())
            + bit_cast::<5, 4>(self.flight.q.val())
            + bit_cast::<5, 1>(self.arrive_r.q.val().into());
        self.room.d.next = self.in_use.val() < 7;
        if self.take.val() {
            self.room.d.next = self.in_use.val() < 6;
        }
        self.list_read.next = self.take.val();
        self.list_addr.next = self.cursor.q.val();
        self.cursor_next.next = self.cursor.q.val() + 1;
        if self.take.val() {
            self.cursor.d.next = self.cursor_next.val();
            self.walked.d.next = self.cursor_next.val() == self.list_end.q.val();
        }
        self.flight_line[0].d.next = self.take.val();
        for k in 1..6 {
            self.flight_line[k].d.next = self.flight_line[k - 1].q.val();
        }
        self.arrive.next = false;
        for k in 0..6 {
            if self.c_ml_last.val() == self.c_index[k].val() {
                self.arrive.next = self.flight_line[k].q.val();
            }
        }
        self.flight.d.next = self.flight.q.val();
        if self.take.val() & (!self.arrive.val()) {
            self.flight.d.next = self.flight.q.val() + 1;
        }
        if self.arrive.val() & (!self.take.val()) {
            self.flight.d.next = self.flight.q.val() - 1;
        }

        // A word arrives: compare it with the mailbox's ids, the skipped pair and the word
        // being checked, and check it the clock after (two 32-bit compares and the mailbox
        // update do not fit one clock).
        self.arrive_r.d.next = self.arrive.val();
        self.word_r.d.next = self.list_rdata.val();
        for k in 0..8 {
            self.hit_r[k].d.next = self.ids[k].q.val() == self.list_rdata.val();
        }
        self.skip_r.d.next = (self.list_rdata.val() == self.skip_triangle.q.val())
            & (self.object_id.q.val() == self.skip_object.q.val());
        self.same_r.d.next = self.list_rdata.val() == self.word_r.q.val();

        // The word is checked: skip the query's own triangle, then the mailbox (hit: the
        // first `len` ids, where the slot written last clock holds the word before; miss:
        // record it first in, first out).
        self.seen.next = false;
        for k in 0..8 {
            if self.live[k].q.val() {
                if self.wrote_r[k].q.val() {
                    if self.same_r.q.val() {
                        self.seen.next = true;
                    }
                } else if self.hit_r[k].q.val() {
                    self.seen.next = true;
                }
            }
        }
        self.fresh.next = self.arrive_r.q.val() & (!self.seen.val()) & (!self.skip_r.q.val());
        self.next_after.next = self.mb_next.q.val() + 1;
        self.len_after.next = self.mb_len.q.val();
        if self.mb_len.q.val() != 8 {
            self.len_after.next = self.mb_len.q.val() + 1;
        }
        // The queue's entry is chosen by registers (a checked word, else the walk's end,
        // else an init passed on), so that the check's result only enables the write.
        if self.arrive_r.q.val() {
            self.tests.data_in.next = (bit_cast::<71, 5>(self.walk_thread.q.val()) << 64)
                | (bit_cast::<71, 32>(self.word_r.q.val()) << 32)
                | bit_cast::<71, 32>(self.object_id.q.val());
        } else if self.phase.q.val() == ListPhase::Walk {
            self.tests.data_in.next = self.c_list_end.val()
                | (bit_cast::<71, 1>(self.of_walk.q.val().into()) << 69)
                | (bit_cast::<71, 5>(self.walk_thread.q.val()) << 64);
        }
        self.recorded.d.next = self.fresh.val();
        if self.fresh.val() {
            self.push.next = true;
            for k in 0..8 {
                if bit_cast::<4, 3>(self.mb_next.q.val()) == self.c_index[k].val() {
                    self.ids[k].d.next = self.word_r.q.val();
                    self.wrote_r[k].d.next = true;
                    self.live[k].d.next = true;
                }
            }
            self.mb_next.d.next = self.next_after.val();
            self.mb_len.d.next = self.len_after.val();
        }
        // The list is done when every word has arrived and been checked: its end entry
        // follows its tests.
        if (self.phase.q.val() == ListPhase::Walk)
            & self.walked.q.val()
            & (self.flight.q.val() == 0)
            & (!self.arrive_r.q.val())
            & (!self.tests.full.val())
        {
            self.push.next = true;
            self.phase.d.next = ListPhase::Idle;
        }
        self.tests.write.next = self.push.val();
        self.queued.d.next = self.queued.q.val();
        if self.push.val() & (!self.test_take.val()) {
            self.queued.d.next = self.queued.q.val() + 1;
        }
        if self.test_take.val() & (!self.push.val()) {
            self.queued.d.next = self.queued.q.val() - 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::{clock_cycle, settle};
    use crate::units::Mailbox;
    use rand::{Rng, SeedableRng};
    use std::collections::VecDeque;

    #[derive(Clone, Copy, Debug)]
    enum Command {
        List(u32, u32),
        Init(u32, u32),
        Object(u32),
        Skip(u32, u32),
    }

    /// What the launch must receive from one thread: `(kind, a, b)` in order, from
    /// `units::Mailbox` and the skip rule of `model::golden`'s `test_triangles`.
    fn model(commands: &[Command], bank1: &[u32]) -> Vec<(u64, u32, u32)> {
        let (mut out, mut mailbox) = (Vec::new(), Mailbox::new());
        let (mut object, mut skip) = (0, (u32::MAX, u32::MAX));
        for c in commands {
            match *c {
                Command::Object(o) => (object, mailbox) = (o, Mailbox::new()),
                Command::Skip(i, t) => skip = (i, t),
                Command::Init(a, b) => {
                    out.push((TEST_INIT, a, b));
                    mailbox = Mailbox::new();
                }
                Command::List(from, to) => {
                    let end = to & 0xff_ffff;
                    for &triangle in &bank1[from as usize..end as usize] {
                        if (object, triangle) != skip && !mailbox.seen(triangle) {
                            out.push((TEST_TRIANGLE, triangle, object));
                        }
                    }
                    let of_walk = u64::from(to) & LIST_OF_WALK != 0;
                    out.push((
                        if of_walk {
                            TEST_WALK_END
                        } else {
                            TEST_LIST_END
                        },
                        0,
                        0,
                    ));
                }
            }
        }
        out
    }

    /// rust-hdl simulation: four threads offer objects, skips, inits and lists (lists that
    /// repeat triangles, so the mailbox hits and evicts, some that hold the skipped triangle,
    /// half of them a walk's, which end in a walk end), a command most clocks; the engine takes the bus in one clock of four; the
    /// launch takes tests in random clocks, so both queues fill. Each thread's entries equal
    /// the model's, in order.
    #[test]
    fn rust_hdl_simulation_matches_the_mailbox_model() {
        let seed = 53;
        println!("seed {seed}");
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mem_latency = 2;
        let bank1: Vec<u32> = (0..400).map(|_| rng.gen_range(0..24)).collect();
        let threads = 4usize;
        let scripts: Vec<Vec<Command>> = (0..threads)
            .map(|th| {
                let mut s = vec![Command::Object(th as u32 + 7)];
                if th % 2 == 1 {
                    s.push(Command::Skip(th as u32 + 7, 5));
                }
                for q in 0..12 {
                    if q == 6 {
                        s.push(Command::Object(th as u32 + 100));
                    }
                    s.push(Command::Init(q, 1000 + q));
                    for _ in 0..rng.gen_range(1..4) {
                        let from = rng.gen_range(0..380u32);
                        // Half the lists are leaves of a traversal-unit walk.
                        let walk = if rng.gen_bool(0.5) {
                            LIST_OF_WALK as u32
                        } else {
                            0
                        };
                        s.push(Command::List(from, (from + rng.gen_range(0..16)) | walk));
                    }
                }
                s
            })
            .collect();
        let want: Vec<_> = scripts.iter().map(|s| model(s, &bank1)).collect();
        assert!(
            want.iter()
                .flatten()
                .filter(|e| e.0 == TEST_TRIANGLE)
                .count()
                > 300
        );

        let mut u = ListUnit::new(mem_latency);
        u.connect_all();
        let cycle = |u: &mut ListUnit| clock_cycle(u, |u, c| u.clock.next = Clock { clk: c });
        let mut offers: Vec<VecDeque<Command>> = scripts
            .iter()
            .map(|s| s.iter().copied().collect())
            .collect();
        let mut got: Vec<Vec<(u64, u32, u32)>> = vec![Vec::new(); threads];
        let mut requests: VecDeque<Option<u32>> =
            std::iter::repeat(None).take(mem_latency as usize).collect();
        let (mut refused, mut stolen, mut clocks) = (0, 0, 0);
        while got.iter().zip(&want).any(|(g, w)| g.len() < w.len()) {
            clocks += 1;
            assert!(clocks < 20_000, "the unit stalled: {got:?}");
            u.list_rdata.next = u64::from(
                requests
                    .pop_front()
                    .unwrap()
                    .map_or(0xdead, |a| bank1[a as usize]),
            )
            .into();
            let th = rng.gen_range(0..threads);
            let offer = rng
                .gen_ratio(3, 4)
                .then(|| offers[th].front().copied())
                .flatten();
            u.enqueue.next = offer.is_some();
            if let Some(c) = offer {
                let (kind, a, b) = match c {
                    Command::List(a, b) => (CMD_LIST, a, b),
                    Command::Init(a, b) => (CMD_INIT, a, b),
                    Command::Object(a) => (CMD_OBJECT, a, 0),
                    Command::Skip(a, b) => (CMD_SKIP, a, b),
                };
                u.kind.next = kind.into();
                u.thread.next = (th as u64).into();
                u.word_a.next = u64::from(a).into();
                u.word_b.next = u64::from(b).into();
            }
            let steal = rng
                .gen_ratio(1, 4)
                .then(|| [0, 1, 2, 4, 5][rng.gen_range(0..5)]);
            u.engine_banks.next = steal.map_or(0u64, |b| 1 << b).into();
            u.test_take.next = false;
            settle(&mut u);
            let take = u.test_valid.val() && rng.gen_ratio(1, 2);
            u.test_take.next = take;
            settle(&mut u);
            if take {
                let e = u.test_entry.val();
                let th = e.get_bits::<5>(64).to_u64() as usize;
                got[th].push((
                    e.get_bits::<2>(69).to_u64(),
                    e.get_bits::<32>(32).to_u64() as u32,
                    e.get_bits::<32>(0).to_u64() as u32,
                ));
            }
            if let Some(bank) = steal {
                if [1, 4, 5].contains(&bank) {
                    stolen += 1;
                    assert!(!u.list_read.val(), "the list read took the engine's bus");
                }
            }
            requests.push_back(u.list_read.val().then(|| u.list_addr.val().to_u64() as u32));
            if offer.is_some() {
                if u.full.val() {
                    refused += 1;
                } else {
                    offers[th].pop_front();
                }
            }
            cycle(&mut u);
        }
        assert!(refused > 0, "the command queue never filled");
        assert!(stolen > 0);
        for th in 0..threads {
            assert_eq!(got[th], want[th], "thread {th}");
        }
    }
}
