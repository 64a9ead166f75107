//! `Fetch`: the engine's stages I0 to I2. It reads the picked thread's `{epoch, halted, pc}`
//! and then the microprogram ROM's three words of the instruction at that pc.
//!
//! Contract: a thread picked at I0 (`issue`, `pick`) shows its instruction at I2 (`valid`,
//! `thread`, `pc`, `ctl`, `imm`, `aux`: the three ROM words of `isa::Instr::encode`). A thread
//! whose stored epoch differs from `epoch` belongs to an earlier frame and starts at pc 0; a
//! halted thread of this frame shows `valid` low. The write back stores a thread's next pc
//! (`wb_*`), tagged with this frame's epoch.
//!
//! Latency: 2 clocks (block-RAM reads of the pc, then of the ROM). Throughput: one thread per
//! clock.
//!
//! Golden twin: `hw::program::exec` (the engine's twin) reads the same words through
//! `isa::Instr::decode` of `Program::rom`, the words this ROM holds.

use rust_hdl::prelude::*;

use super::word_map;
use crate::hw::program::isa::PC_BITS;
use crate::hw::program::Program;

#[derive(LogicBlock)]
pub struct Fetch {
    pub clock: Signal<In, Clock>,
    /// The frame's epoch bit (it flips at every frame start).
    pub epoch: Signal<In, Bit>,
    /// I0: the scheduler's pick.
    pub issue: Signal<In, Bit>,
    pub pick: Signal<In, Bits<5>>,
    /// I2: the instruction.
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
    pc_ram: RAM<Bits<16>, 5>,
    rom_ctl: RAM<Bits<32>, PC_BITS>,
    rom_imm: RAM<Bits<32>, PC_BITS>,
    rom_aux: RAM<Bits<32>, PC_BITS>,
    v1: DFF<Bit>,
    t1: DFF<Bits<5>>,
    v2: DFF<Bit>,
    t2: DFF<Bits<5>>,
    pc2: DFF<Bits<PC_BITS>>,
    fresh: Signal<Local, Bit>,
    pc1: Signal<Local, Bits<PC_BITS>>,
}

impl Fetch {
    /// The fetch stage of `program` (its ROM words).
    pub fn new(program: &Program) -> Self {
        let words = program.rom();
        let rom = |k: usize| -> RAM<Bits<32>, PC_BITS> {
            RAM::new(word_map(
                words.iter().map(|w| Bits::<32>::from(u64::from(w[k]))),
            ))
        };
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
            pc_ram: RAM::new(word_map((0..32).map(|_| Bits::<16>::from(0u64)))),
            rom_ctl: rom(0),
            rom_imm: rom(1),
            rom_aux: rom(2),
            v1: Default::default(),
            t1: Default::default(),
            v2: Default::default(),
            t2: Default::default(),
            pc2: Default::default(),
            fresh: Default::default(),
            pc1: Default::default(),
        }
    }
}

impl Logic for Fetch {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, v1, t1, v2, t2, pc2);
        self.pc_ram.read_clock.next = self.clock.val();
        self.pc_ram.write_clock.next = self.clock.val();
        self.rom_ctl.read_clock.next = self.clock.val();
        self.rom_ctl.write_clock.next = self.clock.val();
        self.rom_imm.read_clock.next = self.clock.val();
        self.rom_imm.write_clock.next = self.clock.val();
        self.rom_aux.read_clock.next = self.clock.val();
        self.rom_aux.write_clock.next = self.clock.val();
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

        // I0: the picked thread's state.
        self.pc_ram.read_address.next = self.pick.val();
        self.v1.d.next = self.issue.val();
        self.t1.d.next = self.pick.val();

        // I1: another epoch is a thread of an earlier frame: pc 0.
        self.fresh.next = self.pc_ram.read_data.val().get_bit(13) != self.epoch.val();
        if self.fresh.val() {
            self.pc1.next = 0.into();
        } else {
            self.pc1.next = self.pc_ram.read_data.val().get_bits::<PC_BITS>(0);
        }
        self.rom_ctl.read_address.next = self.pc1.val();
        self.rom_imm.read_address.next = self.pc1.val();
        self.rom_aux.read_address.next = self.pc1.val();
        self.v2.d.next =
            self.v1.q.val() & (self.fresh.val() | (!self.pc_ram.read_data.val().get_bit(12)));
        self.t2.d.next = self.t1.q.val();
        self.pc2.d.next = self.pc1.val();

        // I2.
        self.valid.next = self.v2.q.val();
        self.thread.next = self.t2.q.val();
        self.pc.next = self.pc2.q.val();
        self.ctl.next = self.rom_ctl.read_data.val();
        self.imm.next = self.rom_imm.read_data.val();
        self.aux.next = self.rom_aux.read_data.val();

        // Write back.
        self.pc_ram.write_address.next = self.wb_thread.val();
        self.pc_ram.write_data.next = (bit_cast::<16, 1>(self.epoch.val().into()) << 13)
            | (bit_cast::<16, 1>(self.wb_halt.val().into()) << 12)
            | bit_cast::<16, PC_BITS>(self.wb_next_pc.val());
        self.pc_ram.write_enable.next = self.wb_valid.val();
    }
}
