//! `Decode`: the engine's stages I2 to I4 up to the operands. It reads the instruction's two
//! source registers from the register file (one block RAM per read port, both written by the
//! write back), selects the operands as the block RAMs' words arrive (I3) and registers them,
//! and splits the ROM words into their fields.
//!
//! Contract: an instruction at I2 (`valid`, `thread`, `pc`, `ctl`, `imm`, `aux` from
//! [`super::Fetch`]) comes out at I4 with its fields and operands: `a` is register `A` (r0
//! reads 0), `b` the immediate when `B_IMM` is set, else register `B`; `store` is register
//! `B` as read (the data of `st` and `sts`). At I3 it shows the instruction's `valid_i3`,
//! `op_i3`, `thread_i3` and `imm_i3`, for the units that read per-thread state, the glue that
//! decodes coprocessor functions and the long instructions' reservation, one clock ahead of
//! the operands. The field offsets are `isa::CTL_*` and `isa::AUX_*`, the one
//! encoding `isa::Instr::encode` writes into the ROM. The write back writes `wb_data` to
//! `wb_dst` of `wb_thread` when `wb_write` is set.
//!
//! Latency: 2 clocks (the register read, then a register after the operand select: the block
//! RAMs' clock-to-out, about 6 ns on an ECP5, leaves no room for the integer unit behind it
//! in one clock). Throughput: one instruction per clock.
//!
//! Golden twin: `isa::Instr::decode` (the fields) and `hw::program::exec` (operands: r0 reads
//! 0, `b` or the immediate).

use rust_hdl::prelude::*;

use crate::hw::program::isa::{self, BANK_BITS, OP_BITS, PC_BITS, REG_BITS, SHIFT_BITS};
use crate::hw::NoCollisionRam;

#[derive(LogicBlock)]
pub struct Decode {
    pub clock: Signal<In, Clock>,
    /// I2: the instruction from the fetch.
    pub valid_i2: Signal<In, Bit>,
    pub thread_i2: Signal<In, Bits<5>>,
    pub pc_i2: Signal<In, Bits<PC_BITS>>,
    pub ctl_i2: Signal<In, Bits<32>>,
    pub imm_i2: Signal<In, Bits<32>>,
    pub aux_i2: Signal<In, Bits<32>>,
    /// I3: the instruction (`valid_i3`, its opcode, thread and immediate).
    pub valid_i3: Signal<Out, Bit>,
    pub op_i3: Signal<Out, Bits<OP_BITS>>,
    pub thread_i3: Signal<Out, Bits<5>>,
    pub imm_i3: Signal<Out, Bits<32>>,
    /// I4: the instruction's fields and operands.
    pub valid: Signal<Out, Bit>,
    pub thread: Signal<Out, Bits<5>>,
    pub pc: Signal<Out, Bits<PC_BITS>>,
    pub op: Signal<Out, Bits<OP_BITS>>,
    pub dst: Signal<Out, Bits<REG_BITS>>,
    pub invert: Signal<Out, Bit>,
    pub imm: Signal<Out, Bits<32>>,
    pub shift: Signal<Out, Bits<SHIFT_BITS>>,
    pub bank: Signal<Out, Bits<BANK_BITS>>,
    pub target: Signal<Out, Bits<PC_BITS>>,
    pub a: Signal<Out, Bits<32>>,
    pub b: Signal<Out, Bits<32>>,
    pub store: Signal<Out, Bits<32>>,
    /// Write back.
    pub wb_write: Signal<In, Bit>,
    pub wb_thread: Signal<In, Bits<5>>,
    pub wb_dst: Signal<In, Bits<REG_BITS>>,
    pub wb_data: Signal<In, Bits<32>>,

    /// The register file, `{register, thread}`-addressed, once per read port; it decodes
    /// the thread and the register bits the program uses (the register on top, so the
    /// unused bits are the top ones), 8 block RAMs a port for 75 registers where all 256
    /// took 16.
    // A thread's write back and its next register read are never in one clock (one
    // instruction per thread in flight, the thread in the address), so the block RAMs need
    // no read-first emulation.
    regs_a: NoCollisionRam<Bits<32>, 13>,
    regs_b: NoCollisionRam<Bits<32>, 13>,
    v3: DFF<Bit>,
    t3: DFF<Bits<5>>,
    pc3: DFF<Bits<PC_BITS>>,
    ctl3: DFF<Bits<32>>,
    imm3: DFF<Bits<32>>,
    aux3: DFF<Bits<32>>,
    v4: DFF<Bit>,
    t4: DFF<Bits<5>>,
    pc4: DFF<Bits<PC_BITS>>,
    ctl4: DFF<Bits<32>>,
    imm4: DFF<Bits<32>>,
    aux4: DFF<Bits<32>>,
    a4: DFF<Bits<32>>,
    b4: DFF<Bits<32>>,
    store4: DFF<Bits<32>>,
    reg_a: Signal<Local, Bits<REG_BITS>>,
    reg_b: Signal<Local, Bits<REG_BITS>>,
    wb_address: Signal<Local, Bits<13>>,

    /// The lowest bit of each field of the ROM words (`isa::CTL_*`, `isa::AUX_*`).
    f_op: Constant<Bits<5>>,
    f_dst: Constant<Bits<5>>,
    f_a: Constant<Bits<5>>,
    f_b: Constant<Bits<5>>,
    f_b_imm: Constant<Bits<5>>,
    f_invert: Constant<Bits<5>>,
    f_shift: Constant<Bits<5>>,
    f_bank: Constant<Bits<5>>,
    f_target: Constant<Bits<5>>,
    /// The operand-is-zero bits the assembler decoded ahead (`isa::AUX_A_ZERO`, `AUX_B_ZERO`).
    f_a_zero: Constant<Bits<5>>,
    f_b_zero: Constant<Bits<5>>,
}

fn field(at: usize) -> Constant<Bits<5>> {
    Constant::new((at as u64).into())
}

impl Decode {
    /// The decode of a program that uses registers `0..registers`.
    pub fn new(registers: usize) -> Self {
        let register_bits = registers.max(2).next_power_of_two().trailing_zeros() as usize;
        assert!(register_bits <= REG_BITS);
        Self {
            // Registers start undefined: the program writes every register before reading it
            // (so the generated Verilog stays small and Icarus compiles it quickly).
            clock: Default::default(),
            valid_i2: Default::default(),
            thread_i2: Default::default(),
            pc_i2: Default::default(),
            ctl_i2: Default::default(),
            imm_i2: Default::default(),
            aux_i2: Default::default(),
            valid: Default::default(),
            thread: Default::default(),
            pc: Default::default(),
            op: Default::default(),
            dst: Default::default(),
            invert: Default::default(),
            imm: Default::default(),
            shift: Default::default(),
            bank: Default::default(),
            target: Default::default(),
            valid_i3: Default::default(),
            op_i3: Default::default(),
            thread_i3: Default::default(),
            imm_i3: Default::default(),
            a: Default::default(),
            b: Default::default(),
            store: Default::default(),
            wb_write: Default::default(),
            wb_thread: Default::default(),
            wb_dst: Default::default(),
            wb_data: Default::default(),
            regs_a: NoCollisionRam::decoding(5 + register_bits),
            regs_b: NoCollisionRam::decoding(5 + register_bits),
            v3: Default::default(),
            t3: Default::default(),
            pc3: Default::default(),
            ctl3: Default::default(),
            imm3: Default::default(),
            aux3: Default::default(),
            v4: Default::default(),
            t4: Default::default(),
            pc4: Default::default(),
            ctl4: Default::default(),
            imm4: Default::default(),
            aux4: Default::default(),
            a4: Default::default(),
            b4: Default::default(),
            store4: Default::default(),
            reg_a: Default::default(),
            reg_b: Default::default(),
            wb_address: Default::default(),
            f_op: field(isa::CTL_OP),
            f_dst: field(isa::CTL_DST),
            f_a: field(isa::CTL_A),
            f_b: field(isa::CTL_B),
            f_b_imm: field(isa::CTL_B_IMM),
            f_invert: field(isa::CTL_INVERT),
            f_shift: field(isa::AUX_SHIFT),
            f_bank: field(isa::AUX_BANK),
            f_target: field(isa::AUX_TARGET),
            f_a_zero: field(isa::AUX_A_ZERO),
            f_b_zero: field(isa::AUX_B_ZERO),
        }
    }
}

impl Logic for Decode {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, v3, t3, pc3, ctl3, imm3, aux3, v4, t4, pc4, ctl4, imm4, aux4, a4, b4,
            store4
        );
        self.regs_a.read_clock.next = self.clock.val();
        self.regs_a.write_clock.next = self.clock.val();
        self.regs_b.read_clock.next = self.clock.val();
        self.regs_b.write_clock.next = self.clock.val();

        // I2: read the source registers.
        self.reg_a.next = self
            .ctl_i2
            .val()
            .get_bits::<REG_BITS>(self.f_a.val().index());
        self.reg_b.next = self
            .ctl_i2
            .val()
            .get_bits::<REG_BITS>(self.f_b.val().index());
        self.regs_a.read_address.next = (bit_cast::<13, REG_BITS>(self.reg_a.val()) << 5)
            | bit_cast::<13, 5>(self.thread_i2.val());
        self.regs_b.read_address.next = (bit_cast::<13, REG_BITS>(self.reg_b.val()) << 5)
            | bit_cast::<13, 5>(self.thread_i2.val());
        self.v3.d.next = self.valid_i2.val();
        self.t3.d.next = self.thread_i2.val();
        self.pc3.d.next = self.pc_i2.val();
        self.ctl3.d.next = self.ctl_i2.val();
        self.imm3.d.next = self.imm_i2.val();
        self.aux3.d.next = self.aux_i2.val();

        // I3: the operands (r0 always reads 0) as the register words arrive.
        self.valid_i3.next = self.v3.q.val();
        self.op_i3.next = self
            .ctl3
            .q
            .val()
            .get_bits::<OP_BITS>(self.f_op.val().index());
        self.thread_i3.next = self.t3.q.val();
        self.imm_i3.next = self.imm3.q.val();
        self.v4.d.next = self.v3.q.val();
        self.t4.d.next = self.t3.q.val();
        self.pc4.d.next = self.pc3.q.val();
        self.ctl4.d.next = self.ctl3.q.val();
        self.imm4.d.next = self.imm3.q.val();
        self.aux4.d.next = self.aux3.q.val();
        if self.aux3.q.val().get_bit(self.f_a_zero.val().index()) {
            self.a4.d.next = 0.into();
        } else {
            self.a4.d.next = self.regs_a.read_data.val();
        }
        if self.ctl3.q.val().get_bit(self.f_b_imm.val().index()) {
            self.b4.d.next = self.imm3.q.val();
        } else if self.aux3.q.val().get_bit(self.f_b_zero.val().index()) {
            self.b4.d.next = 0.into();
        } else {
            self.b4.d.next = self.regs_b.read_data.val();
        }
        self.store4.d.next = self.regs_b.read_data.val();

        // I4: the fields and operands.
        self.valid.next = self.v4.q.val();
        self.thread.next = self.t4.q.val();
        self.pc.next = self.pc4.q.val();
        self.op.next = self
            .ctl4
            .q
            .val()
            .get_bits::<OP_BITS>(self.f_op.val().index());
        self.dst.next = self
            .ctl4
            .q
            .val()
            .get_bits::<REG_BITS>(self.f_dst.val().index());
        self.invert.next = self.ctl4.q.val().get_bit(self.f_invert.val().index());
        self.imm.next = self.imm4.q.val();
        self.shift.next = self
            .aux4
            .q
            .val()
            .get_bits::<SHIFT_BITS>(self.f_shift.val().index());
        self.bank.next = self
            .aux4
            .q
            .val()
            .get_bits::<BANK_BITS>(self.f_bank.val().index());
        self.target.next = self
            .aux4
            .q
            .val()
            .get_bits::<PC_BITS>(self.f_target.val().index());
        self.a.next = self.a4.q.val();
        self.b.next = self.b4.q.val();
        self.store.next = self.store4.q.val();

        // Write back.
        self.wb_address.next = (bit_cast::<13, REG_BITS>(self.wb_dst.val()) << 5)
            | bit_cast::<13, 5>(self.wb_thread.val());
        self.regs_a.write_address.next = self.wb_address.val();
        self.regs_b.write_address.next = self.wb_address.val();
        self.regs_a.write_data.next = self.wb_data.val();
        self.regs_b.write_data.next = self.wb_data.val();
        self.regs_a.write_enable.next = self.wb_write.val();
        self.regs_b.write_enable.next = self.wb_write.val();
    }
}
