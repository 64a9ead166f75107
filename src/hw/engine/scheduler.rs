//! `Scheduler`: the engine's issue stage (I0). It picks one ready thread per clock, round
//! robin, and keeps which threads may issue.
//!
//! Contract: a thread is *ready* from the start of a frame and again at the write back of
//! its instruction, unless that instruction was `halt` or a coprocessor wait (`tri.wait`,
//! `kd.wait`) that is still pending. A pending waiter *sleeps* until its coprocessor reports
//! a finish for it (`tester_done`, `walk_done`, or ray generation's `ray_done_mask`: a `tri.wait`
//! also waits for the thread's primary ray); a finish between the waiter's issue and its
//! write back is remembered (`woken`), so the waiter does not sleep through it. A long
//! instruction (`fdiv`, `fsqrt`) at I3 reserves the clock its write back will take: the
//! scheduler issues nothing in the one clock whose instruction would write back with it.
//!
//! The pick is made a clock ahead: the thread that issues is a register, one-hot for the
//! scheduler's bookkeeping and beside it its number (which addresses the pc store, with no
//! encode in front of the read), chosen the clock before among the threads ready then, less
//! the one picked then. Round robin: the choice is the highest of them below a
//! pointer that moves down one thread per clock (a register, so no shifter sits in the
//! choice), else the highest ([`super::FirstReady`], a tree); every ready thread is first in
//! line at least once per 32 clocks.
//!
//! Latency: `issue` and `pick` come from registers (I0); a thread written back (`wb_*`,
//! registered by the write back) in clock c is ready at c + 1 and issues at c + 2 at the
//! earliest; a sleeper finished for (`tester_done`, `walk_done`) in clock c is ready at c + 2
//! (the finishes are registered as they arrive). A finish seen a clock late may count as
//! `woken` for a wait issued right after it: that wait, still pending, then repeats on its
//! next turn rather than sleeping, which costs a turn, never a result.
//! Throughput: one issue per clock while a thread is ready and the clock is not reserved.
//!
//! Golden twin: none of its own. The engine's twin (`hw::program::exec`, see
//! `ThreadEngine`) runs threads in an order of its own and never waits; the scheduler may
//! change only *when* a thread issues, never what it computes, so the frames and the count of
//! retired instructions equal the twin's whatever the order.

use rust_hdl::prelude::*;

use super::{FirstReady, MAX_THREADS};

#[derive(LogicBlock)]
pub struct Scheduler {
    pub clock: Signal<In, Clock>,
    /// The frame runs; threads issue only while it does.
    pub running: Signal<In, Bit>,
    /// A new frame starts: every thread is ready, none asleep, no clock reserved.
    pub frame_start: Signal<In, Bit>,
    /// A long instruction is at I3 (its write back is `long_latency - ENGINE_LATENCY` clocks
    /// after the others').
    pub long_at_i3: Signal<In, Bit>,
    /// The write back of an instruction of the thread `wb_thread_mask` names (one-hot,
    /// decoded before the write back's register: decoded here from the thread's number, the
    /// number's fan-out to 32 decodes was 6.6 ns of routing, stop 48's placed path on
    /// cornell_noshadow, 84.7 MHz); `wb_halt`: it was `halt`; `wb_wait_pending`: it was a
    /// coprocessor wait whose work is not finished.
    pub wb_valid: Signal<In, Bit>,
    pub wb_thread_mask: Signal<In, Bits<32>>,
    pub wb_halt: Signal<In, Bit>,
    pub wb_wait_pending: Signal<In, Bit>,
    /// The triangle tester and the traversal unit finished work for a thread.
    pub tester_done: Signal<In, Bit>,
    pub tester_done_thread: Signal<In, Bits<5>>,
    pub walk_done: Signal<In, Bit>,
    pub walk_done_thread: Signal<In, Bits<5>>,
    /// Ray generation wrote these threads' primary rays (a one-hot mask, registered: a
    /// `tri.wait` waits for the ray).
    pub ray_done_mask: Signal<In, Bits<32>>,
    /// A thread issues this clock: `pick`.
    pub issue: Signal<Out, Bit>,
    pub pick: Signal<Out, Bits<5>>,

    /// The coprocessors' finishes, decoded to a thread mask and registered where they
    /// arrive: from the traversal unit's `done_r` the decode into `ready` was 9.2 ns of
    /// routing (cornell, 85.9 MHz at stop 37), and from a registered thread number the decode
    /// still 5.0 ns (cornell_noshadow, 89.8 MHz at stop 48); a sleeper wakes a clock later.
    tester_event: DFF<Bits<32>>,
    walk_event: DFF<Bits<32>>,
    /// Threads that may issue (written back, not asleep, not picked); threads asleep on a
    /// coprocessor wait; threads a coprocessor finished work for since their issue.
    ready: DFF<Bits<32>>,
    asleep: DFF<Bits<32>>,
    woken: DFF<Bits<32>>,
    /// The thread that issues next (`picked`, one-hot) and the round-robin pointer with its
    /// mask (the threads below it).
    picked: DFF<Bit>,
    pick_onehot: DFF<Bits<32>>,
    pick_number: DFF<Bits<5>>,
    pointer: DFF<Bits<5>>,
    below_pointer: DFF<Bits<32>>,
    /// Clocks in which no thread may issue: a long instruction writes back in the clock where
    /// that issue's instruction would (bit 0 is this clock).
    reserved: DFF<Bits<32>>,

    candidates: Signal<Local, Bits<32>>,
    below: Signal<Local, Bits<32>>,
    /// The next pick: the highest of `{below, candidates}`.
    first_ready: FirstReady,
    issues: Signal<Local, Bit>,
    issue_mask: Signal<Local, Bits<32>>,
    wb_mask: Signal<Local, Bits<32>>,
    event_mask: Signal<Local, Bits<32>>,
    wb_sleep: Signal<Local, Bit>,
    wake_mask: Signal<Local, Bits<32>>,
    sleep_mask: Signal<Local, Bits<32>>,

    /// Bit `t` set for every thread `t` of the design; one; all ones.
    c_thread_mask: Constant<Bits<32>>,
    c_one: Constant<Bits<32>>,
    c_ones: Constant<Bits<32>>,
    /// The bit of `reserved` a long instruction at I3 sets: the issue `reserve_ahead` clocks
    /// after this one would write back with it.
    c_reserve_bit: Constant<Bits<32>>,
}

impl Scheduler {
    /// A scheduler of `threads` threads; a long instruction at I3 reserves the issue
    /// `reserve_ahead` clocks later.
    pub fn new(threads: u32, reserve_ahead: u32) -> Self {
        assert!((1..=MAX_THREADS as u32).contains(&threads) && reserve_ahead < 32);
        Self {
            clock: Default::default(),
            running: Default::default(),
            frame_start: Default::default(),
            long_at_i3: Default::default(),
            wb_valid: Default::default(),
            wb_thread_mask: Default::default(),
            wb_halt: Default::default(),
            wb_wait_pending: Default::default(),
            tester_done: Default::default(),
            tester_done_thread: Default::default(),
            walk_done: Default::default(),
            walk_done_thread: Default::default(),
            ray_done_mask: Default::default(),
            issue: Default::default(),
            pick: Default::default(),
            ready: Default::default(),
            asleep: Default::default(),
            woken: Default::default(),
            picked: Default::default(),
            pick_onehot: Default::default(),
            pick_number: Default::default(),
            pointer: Default::default(),
            below_pointer: Default::default(),
            reserved: Default::default(),
            candidates: Default::default(),
            below: Default::default(),
            first_ready: Default::default(),
            issues: Default::default(),
            issue_mask: Default::default(),
            wb_mask: Default::default(),
            tester_event: Default::default(),
            walk_event: Default::default(),
            event_mask: Default::default(),
            wb_sleep: Default::default(),
            wake_mask: Default::default(),
            sleep_mask: Default::default(),
            c_thread_mask: Constant::new(((1u64 << threads) - 1).into()),
            c_one: Constant::new(1u64.into()),
            c_ones: Constant::new(0xffff_ffffu64.into()),
            c_reserve_bit: Constant::new(u64::from(reserve_ahead).into()),
        }
    }
}

impl Logic for Scheduler {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            tester_event,
            walk_event,
            ready,
            asleep,
            woken,
            picked,
            pick_onehot,
            pick_number,
            pointer,
            below_pointer,
            reserved
        );

        // Issue the thread picked last clock, unless the clock is reserved.
        self.issues.next =
            self.running.val() & self.picked.q.val() & (!self.reserved.q.val().get_bit(0));
        self.issue.next = self.issues.val();
        self.pick.next = self.pick_number.q.val();
        self.issue_mask.next = 0.into();
        if self.issues.val() {
            self.issue_mask.next = self.pick_onehot.q.val();
        }
        self.reserved.d.next = (self.reserved.q.val() >> 1)
            | (bit_cast::<32, 1>(self.long_at_i3.val().into()) << self.c_reserve_bit.val());

        // The next pick: the highest candidate below the pointer, else the highest. The
        // candidates leave out the thread picked now whether or not it issues (the issue's
        // reservation and `running` stay out of the choice's path; a thread whose issue a
        // reservation deferred is simply picked again later). Settled in locals and
        // registered (the pick leaves the block).
        self.candidates.next = self.ready.q.val() & (!self.pick_onehot.q.val());
        self.below.next = self.candidates.val() & self.below_pointer.q.val();
        self.first_ready.preferred.next = self.below.val();
        self.first_ready.others.next = self.candidates.val();
        self.picked.d.next = self.first_ready.found.val();
        self.pick_onehot.d.next = self.first_ready.onehot.val();
        self.pick_number.d.next = self.first_ready.number.val();
        self.pointer.d.next = self.pointer.q.val() - 1;
        self.below_pointer.d.next = !(self.c_ones.val() << (self.pointer.q.val() - 1));

        // Write back: the thread is ready again unless it halted or sleeps on a wait that no
        // finish has answered since its issue.
        self.wb_mask.next = self.wb_thread_mask.val();
        self.tester_event.d.next = 0.into();
        if self.tester_done.val() {
            self.tester_event.d.next = self.c_one.val() << self.tester_done_thread.val();
        }
        self.walk_event.d.next = 0.into();
        if self.walk_done.val() {
            self.walk_event.d.next = self.c_one.val() << self.walk_done_thread.val();
        }
        self.event_mask.next =
            self.tester_event.q.val() | self.walk_event.q.val() | self.ray_done_mask.val();
        self.wb_sleep.next = self.wb_valid.val()
            & self.wb_wait_pending.val()
            & (((self.woken.q.val() | self.event_mask.val()) & self.wb_mask.val()) == 0);
        self.wake_mask.next = 0.into();
        self.sleep_mask.next = 0.into();
        if self.wb_valid.val() & (!self.wb_halt.val()) {
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

        if self.frame_start.val() {
            self.ready.d.next = self.c_thread_mask.val();
            self.asleep.d.next = 0.into();
            self.woken.d.next = 0.into();
            self.reserved.d.next = 0.into();
            self.tester_event.d.next = 0.into();
            self.walk_event.d.next = 0.into();
            self.picked.d.next = false;
        }
    }
}
