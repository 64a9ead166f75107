//! `MailboxUnit`: each thread's two mailboxes of the last 8 ids it tested (triangles in
//! mailbox 0, instances in mailbox 1), the paper's mailboxing against testing an object
//! twice, for the `mbx` (test and insert) and `mbc` (clear) instructions.
//!
//! Contract: the mailbox `which` of a thread is read at I4 (`read_thread`, `read_which`); at
//! I5 come the instruction's `thread`, `which`, `value`, `insert`, `clear`. At I7 `hit` is set
//! when `value` is one of the mailbox's first `len` entries; `insert` (an `mbx`) puts a value
//! that missed in the next slot, round robin, and `clear` (an `mbc`) empties the mailbox.
//! Entries start undefined and count only below `len`.
//!
//! Latency: the entries leave their block RAMs into registers at I5 (a block RAM's output
//! arrives late in the clock, too late for a 32-bit compare behind it), are compared with the
//! value at I6, and the hit is ready at I7, three clocks after the read; the update is written
//! at the end of I7. A thread issues at most once per `engine_period` clocks, and threads have
//! mailboxes of their own, so every read sees every earlier update.
//! Throughput: one instruction per clock.
//!
//! Golden twin: [`crate::units::Mailbox`] (`seen` is `mbx`; a new mailbox is `mbc`), which the
//! engine's twin runs for these instructions and the golden model for every ray.

use rust_hdl::prelude::*;

use crate::units::MAILBOX_ENTRIES;

#[derive(LogicBlock)]
pub struct MailboxUnit {
    pub clock: Signal<In, Clock>,
    /// I4: which thread's mailbox (`read_which`: 0 triangles, 1 instances) to read.
    pub read_thread: Signal<In, Bits<5>>,
    pub read_which: Signal<In, Bit>,
    /// I5: the instruction's thread, mailbox, value (operand A) and what it does.
    pub thread: Signal<In, Bits<5>>,
    pub which: Signal<In, Bit>,
    pub value: Signal<In, Bits<32>>,
    pub insert: Signal<In, Bit>,
    pub clear: Signal<In, Bit>,
    /// I7: the value was in the mailbox.
    pub hit: Signal<Out, Bit>,

    /// I6: the entries and metadata read, and the instruction.
    entries_r: [DFF<Bits<32>>; MAILBOX_ENTRIES],
    meta_i6: DFF<Bits<8>>,
    thread_i6: DFF<Bits<5>>,
    which_i6: DFF<Bit>,
    value_i6: DFF<Bits<32>>,
    insert_i6: DFF<Bit>,
    clear_i6: DFF<Bit>,
    /// I7: the compares of I6 and what the update needs.
    matches: [DFF<Bit>; MAILBOX_ENTRIES],
    meta_r: DFF<Bits<8>>,
    thread_r: DFF<Bits<5>>,
    which_r: DFF<Bit>,
    value_r: DFF<Bits<32>>,
    insert_r: DFF<Bit>,
    clear_r: DFF<Bit>,
    entries: [RAM<Bits<32>, 6>; MAILBOX_ENTRIES],
    /// `{next slot (bits 6..4), len (bits 3..0)}` per `{thread, mailbox}`.
    meta: RAM<Bits<8>, 6>,
    len: Signal<Local, Bits<4>>,
    next_slot: Signal<Local, Bits<3>>,
    found: Signal<Local, Bit>,
    read_address: Signal<Local, Bits<6>>,
    write_address: Signal<Local, Bits<6>>,
    c_index: [Constant<Bits<8>>; MAILBOX_ENTRIES],
}

impl Default for MailboxUnit {
    fn default() -> Self {
        // The `0..8` loops of `update` spell the entries out (rust-hdl's Verilog cannot name
        // Rust constants).
        assert_eq!(MAILBOX_ENTRIES, 8);
        Self {
            clock: Default::default(),
            read_thread: Default::default(),
            read_which: Default::default(),
            thread: Default::default(),
            which: Default::default(),
            value: Default::default(),
            insert: Default::default(),
            clear: Default::default(),
            hit: Default::default(),
            entries_r: Default::default(),
            meta_i6: Default::default(),
            thread_i6: Default::default(),
            which_i6: Default::default(),
            value_i6: Default::default(),
            insert_i6: Default::default(),
            clear_i6: Default::default(),
            matches: Default::default(),
            meta_r: Default::default(),
            thread_r: Default::default(),
            which_r: Default::default(),
            value_r: Default::default(),
            insert_r: Default::default(),
            clear_r: Default::default(),
            entries: Default::default(),
            meta: RAM::new(super::word_map((0..64).map(|_| Bits::<8>::from(0u64)))),
            len: Default::default(),
            next_slot: Default::default(),
            found: Default::default(),
            read_address: Default::default(),
            write_address: Default::default(),
            c_index: std::array::from_fn(|k| Constant::new((k as u64).into())),
        }
    }
}

impl Logic for MailboxUnit {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, meta_i6, thread_i6, which_i6, value_i6, insert_i6, clear_i6, meta_r,
            thread_r, which_r, value_r, insert_r, clear_r
        );
        self.meta.read_clock.next = self.clock.val();
        self.meta.write_clock.next = self.clock.val();
        for k in 0..8 {
            self.entries[k].read_clock.next = self.clock.val();
            self.entries[k].write_clock.next = self.clock.val();
        }
        // I4: read.
        self.read_address.next = (bit_cast::<6, 5>(self.read_thread.val()) << 1)
            | bit_cast::<6, 1>(self.read_which.val().into());
        self.meta.read_address.next = self.read_address.val();
        for k in 0..8 {
            self.entries[k].read_address.next = self.read_address.val();
        }

        // I5: the entries into registers.
        for k in 0..8 {
            self.entries_r[k].clock.next = self.clock.val();
            self.entries_r[k].d.next = self.entries[k].read_data.val();
        }
        self.meta_i6.d.next = self.meta.read_data.val();
        self.thread_i6.d.next = self.thread.val();
        self.which_i6.d.next = self.which.val();
        self.value_i6.d.next = self.value.val();
        self.insert_i6.d.next = self.insert.val();
        self.clear_i6.d.next = self.clear.val();

        // I6: compare the value with every entry.
        for k in 0..8 {
            self.matches[k].clock.next = self.clock.val();
            self.matches[k].d.next = self.entries_r[k].q.val() == self.value_i6.q.val();
        }
        self.meta_r.d.next = self.meta_i6.q.val();
        self.thread_r.d.next = self.thread_i6.q.val();
        self.which_r.d.next = self.which_i6.q.val();
        self.value_r.d.next = self.value_i6.q.val();
        self.insert_r.d.next = self.insert_i6.q.val();
        self.clear_r.d.next = self.clear_i6.q.val();

        // I7: a hit when the value is one of the first `len` entries.
        self.len.next = self.meta_r.q.val().get_bits::<4>(0);
        self.next_slot.next = self.meta_r.q.val().get_bits::<3>(4);
        self.found.next = false;
        for k in 0..8 {
            if self.matches[k].q.val() & (bit_cast::<8, 4>(self.len.val()) > self.c_index[k].val())
            {
                self.found.next = true;
            }
        }
        self.hit.next = self.found.val();

        // I7: update.
        self.write_address.next = (bit_cast::<6, 5>(self.thread_r.q.val()) << 1)
            | bit_cast::<6, 1>(self.which_r.q.val().into());
        self.meta.write_address.next = self.write_address.val();
        self.meta.write_enable.next = false;
        self.meta.write_data.next = 0.into();
        for k in 0..8 {
            self.entries[k].write_address.next = self.write_address.val();
            self.entries[k].write_data.next = self.value_r.q.val();
            self.entries[k].write_enable.next = false;
        }
        if self.clear_r.q.val() {
            self.meta.write_enable.next = true;
        }
        if self.insert_r.q.val() & (!self.found.val()) {
            self.meta.write_enable.next = true;
            if self.len.val() == 8 {
                self.meta.write_data.next =
                    (bit_cast::<8, 3>(self.next_slot.val() + 1) << 4) | (self.c_index[7].val() + 1);
            } else {
                self.meta.write_data.next = (bit_cast::<8, 3>(self.next_slot.val() + 1) << 4)
                    | bit_cast::<8, 4>(self.len.val() + 1);
            }
            for k in 0..8 {
                if bit_cast::<8, 3>(self.next_slot.val()) == self.c_index[k].val() {
                    self.entries[k].write_enable.next = true;
                }
            }
        }
    }
}
