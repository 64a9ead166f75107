//! `Fetch`: the engine's stages I0 to I3. It reads the picked thread's `{epoch, halted, pc}`
//! and registers the pc (I0), addresses the microprogram ROM with it (I1), and registers the
//! ROM's three words of the instruction (I2).
//!
//! Contract: a thread picked at I0 (`issue`, `pick`) shows its instruction at I3 (`valid`,
//! `thread`, `pc`, `ctl`, `imm`, `aux`: the three ROM words of `isa::Instr::encode`), every
//! output from a register. A thread whose stored epoch differs from `epoch` belongs to an
//! earlier frame and starts at pc 0; a halted thread of this frame shows `valid` low. The
//! write back stores a thread's next pc (`wb_*`), tagged with this frame's epoch.
//!
//! Why the pc store reads combinationally ([`LutRam`]) and the ROM's words are registered: the
//! register file's address must come from a register. A block RAM's clock-to-out (5.8 ns on
//! an ECP5) routed to the sixteen block RAMs of a register-file port was the processor's
//! critical path at 78.0 MHz (issue 16). The pc store is 32 words, so its read (LUTs) and the
//! epoch check take one clock.
//!
//! Why the pc is registered before the ROM: the pick's encode, the pc store's read and the
//! epoch check routed on to the ROM's block RAMs in the same clock were the processor's
//! critical path with nextpnr seed 2 (84.2 MHz, 2.2 ns of logic and 9.7 ns of routing). The
//! register costs every instruction one clock of latency, which the other threads hide.
//!
//! Latency: 3 clocks (the pc read, the ROM read, the ROM words' register).
//! Throughput: one thread per clock.
//!
//! Golden twin: `hw::program::exec` (the engine's twin) reads the same words through
//! `isa::Instr::decode` of `Program::rom`, the words this ROM holds.

use rust_hdl::prelude::*;

use super::{word_map, ProgramRom};
use crate::hw::program::isa::PC_BITS;
use crate::hw::program::Program;
use crate::hw::LutRam;

/// Clocks from the pick (I0) to the fetched instruction (I3), where a long instruction
/// reserves its write back.
pub const FETCH_LATENCY: u32 = 3;

#[derive(LogicBlock)]
pub struct Fetch {
    pub clock: Signal<In, Clock>,
    /// The frame's epoch bit (it flips at every frame start).
    pub epoch: Signal<In, Bit>,
    /// I0: the scheduler's pick.
    pub issue: Signal<In, Bit>,
    pub pick: Signal<In, Bits<5>>,
    /// I3: the instruction.
    pub valid: Signal<Out, Bit>,
    pub thread: Signal<Out, Bits<5>>,
    pub pc: Signal<Out, Bits<PC_BITS>>,
    pub ctl: Signal<Out, Bits<32>>,
    pub imm: Signal<Out, Bits<32>>,
    pub aux: Signal<Out, Bits<32>>,
    /// Write back: `wb_thread` goes on at `wb_next_pc` (or stops, `wb_halt`).
    pub wb_valid: Signal<In, Bit>,
    pub wb_thread: Signal<In, Bits<5>>,
    pub wb_halt: Signal<In, Bit>,
    pub wb_next_pc: Signal<In, Bits<PC_BITS>>,

    /// Per thread `{epoch (bit 13), halted (bit 12), pc}`.
    pc_ram: LutRam<Bits<16>, 5>,
    rom: ProgramRom,
    v1: DFF<Bit>,
    t1: DFF<Bits<5>>,
    pc1: DFF<Bits<PC_BITS>>,
    v2: DFF<Bit>,
    t2: DFF<Bits<5>>,
    pc2: DFF<Bits<PC_BITS>>,
    v3: DFF<Bit>,
    t3: DFF<Bits<5>>,
    pc3: DFF<Bits<PC_BITS>>,
    ctl3: DFF<Bits<32>>,
    imm3: DFF<Bits<32>>,
    aux3: DFF<Bits<32>>,
    fresh: Signal<Local, Bit>,
    pc0: Signal<Local, Bits<PC_BITS>>,
}

impl Fetch {
    /// The fetch stage of `program` (its ROM words).
    pub fn new(program: &Program) -> Self {
        Self {
            clock: Default::default(),
            epoch: Default::default(),
            issue: Default::default(),
            pick: Default::default(),
            valid: Default::default(),
            thread: Default::default(),
            pc: Default::default(),
            ctl: Default::default(),
            imm: Default::default(),
            aux: Default::default(),
            wb_valid: Default::default(),
            wb_thread: Default::default(),
            wb_halt: Default::default(),
            wb_next_pc: Default::default(),
            pc_ram: LutRam::new(word_map((0..32).map(|_| Bits::<16>::from(0u64)))),
            rom: ProgramRom::new(program.rom()),
            v1: Default::default(),
            t1: Default::default(),
            pc1: Default::default(),
            v2: Default::default(),
            t2: Default::default(),
            pc2: Default::default(),
            v3: Default::default(),
            t3: Default::default(),
            pc3: Default::default(),
            ctl3: Default::default(),
            imm3: Default::default(),
            aux3: Default::default(),
            fresh: Default::default(),
            pc0: Default::default(),
        }
    }
}

impl Logic for Fetch {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, v1, t1, pc1, v2, t2, pc2, v3, t3, pc3, ctl3, imm3, aux3);
        self.pc_ram.write_clock.next = self.clock.val();
        self.rom.clock.next = self.clock.val();

        // I0: the picked thread's state; another epoch is a thread of an earlier frame: pc 0.
        self.pc_ram.read_address.next = self.pick.val();
        self.fresh.next = self.pc_ram.read_data.val().get_bit(13) != self.epoch.val();
        if self.fresh.val() {
            self.pc0.next = 0.into();
        } else {
            self.pc0.next = self.pc_ram.read_data.val().get_bits::<PC_BITS>(0);
        }
        self.v1.d.next =
            self.issue.val() & (self.fresh.val() | (!self.pc_ram.read_data.val().get_bit(12)));
        self.t1.d.next = self.pick.val();
        self.pc1.d.next = self.pc0.val();

        // I1: the ROM's address.
        self.rom.address.next = self.pc1.q.val();
        self.v2.d.next = self.v1.q.val();
        self.t2.d.next = self.t1.q.val();
        self.pc2.d.next = self.pc1.q.val();

        // I2: the ROM's words.
        self.v3.d.next = self.v2.q.val();
        self.t3.d.next = self.t2.q.val();
        self.pc3.d.next = self.pc2.q.val();
        self.ctl3.d.next = self.rom.ctl.val();
        self.imm3.d.next = self.rom.imm.val();
        self.aux3.d.next = self.rom.aux.val();

        // I3.
        self.valid.next = self.v3.q.val();
        self.thread.next = self.t3.q.val();
        self.pc.next = self.pc3.q.val();
        self.ctl.next = self.ctl3.q.val();
        self.imm.next = self.imm3.q.val();
        self.aux.next = self.aux3.q.val();

        // Write back.
        self.pc_ram.write_address.next = self.wb_thread.val();
        self.pc_ram.write_data.next = (bit_cast::<16, 1>(self.epoch.val().into()) << 13)
            | (bit_cast::<16, 1>(self.wb_halt.val().into()) << 12)
            | bit_cast::<16, PC_BITS>(self.wb_next_pc.val());
        self.pc_ram.write_enable.next = self.wb_valid.val();
    }
}
