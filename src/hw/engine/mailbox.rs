//! `MailboxUnit`: each thread's two mailboxes of the last 8 ids it tested (triangles in
//! mailbox 0, instances in mailbox 1), the paper's mailboxing against testing an object
//! twice, for the `mbx` (test and insert) and `mbc` (clear) instructions.
//!
//! Contract: the mailbox `which` of a thread is read at I3 (`read_thread`, `read_which`). At
//! I4 `hit` is set when `value` is one of its first `len` entries; `insert` (an `mbx`) puts a
//! value that missed in the next slot, round robin, and `clear` (an `mbc`) empties the
//! mailbox. Entries start undefined and count only below `len`.
//!
//! Latency: the hit is ready at I4, one clock after the read; the update is written at the
//! end of I4. A thread issues at most once per `engine_period` clocks, so its next read
//! sees the update. Throughput: one instruction per clock.
//!
//! Golden twin: [`crate::units::Mailbox`] (`seen` is `mbx`; a new mailbox is `mbc`), which the
//! engine's twin runs for these instructions and the golden model for every ray.

use rust_hdl::prelude::*;

use crate::units::MAILBOX_ENTRIES;

#[derive(LogicBlock)]
pub struct MailboxUnit {
    pub clock: Signal<In, Clock>,
    /// I3: which thread's mailbox (`read_which`: 0 triangles, 1 instances) to read.
    pub read_thread: Signal<In, Bits<5>>,
    pub read_which: Signal<In, Bit>,
    /// I4: the instruction's thread, mailbox, value (operand A) and what it does.
    pub thread: Signal<In, Bits<5>>,
    pub which: Signal<In, Bit>,
    pub value: Signal<In, Bits<32>>,
    pub insert: Signal<In, Bit>,
    pub clear: Signal<In, Bit>,
    pub hit: Signal<Out, Bit>,

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
        self.meta.read_clock.next = self.clock.val();
        self.meta.write_clock.next = self.clock.val();
        for k in 0..8 {
            self.entries[k].read_clock.next = self.clock.val();
            self.entries[k].write_clock.next = self.clock.val();
        }
        // I3: read.
        self.read_address.next = (bit_cast::<6, 5>(self.read_thread.val()) << 1)
            | bit_cast::<6, 1>(self.read_which.val().into());
        self.meta.read_address.next = self.read_address.val();
        for k in 0..8 {
            self.entries[k].read_address.next = self.read_address.val();
        }

        // I4: a hit when the value is one of the first `len` entries.
        self.len.next = self.meta.read_data.val().get_bits::<4>(0);
        self.next_slot.next = self.meta.read_data.val().get_bits::<3>(4);
        self.found.next = false;
        for k in 0..8 {
            if (self.entries[k].read_data.val() == self.value.val())
                & (bit_cast::<8, 4>(self.len.val()) > self.c_index[k].val())
            {
                self.found.next = true;
            }
        }
        self.hit.next = self.found.val();

        // I4: update.
        self.write_address.next =
            (bit_cast::<6, 5>(self.thread.val()) << 1) | bit_cast::<6, 1>(self.which.val().into());
        self.meta.write_address.next = self.write_address.val();
        self.meta.write_enable.next = false;
        self.meta.write_data.next = 0.into();
        for k in 0..8 {
            self.entries[k].write_address.next = self.write_address.val();
            self.entries[k].write_data.next = self.value.val();
            self.entries[k].write_enable.next = false;
        }
        if self.clear.val() {
            self.meta.write_enable.next = true;
        }
        if self.insert.val() & (!self.found.val()) {
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
