//! `Decode`: the engine's stages I3 to I5 up to the operands. It reads the instruction's two
//! source registers from the register file (one block RAM per read port, both written by the
//! write back), selects the operands as the block RAMs' words arrive (I4) and registers them,
//! and splits the ROM words into their fields.
//!
//! Contract: an instruction at I3 (`valid`, `thread`, `pc`, `ctl`, `imm`, `aux` from
//! [`super::Fetch`]) comes out at I5 with its fields and operands: `a` is register `A` (r0
//! reads 0), `b` the immediate when `B_IMM` is set, else register `B`; `store` is register
//! `B` as read (the data of `st` and `sts`). At I3 it shows the fetched word's opcode
//! (`op_i3`, for the long instructions' reservation); at I4 the instruction's `valid_i4`,
//! `op_i4`, `thread_i4` and `imm_i4`, for the units that read per-thread state and the glue
//! that decodes coprocessor functions, one clock ahead of the operands. The field offsets are
//! `isa::CTL_*` and `isa::AUX_*`, the one encoding `isa::Instr::encode` writes into the ROM.
//! The write back writes `wb_data` to `wb_dst` of `wb_thread` when `wb_write` is set.
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
    /// I3: the instruction from the fetch.
    pub valid_i3: Signal<In, Bit>,
    pub thread_i3: Signal<In, Bits<5>>,
    pub pc_i3: Signal<In, Bits<PC_BITS>>,
    pub ctl_i3: Signal<In, Bits<32>>,
    pub imm_i3: Signal<In, Bits<32>>,
    pub aux_i3: Signal<In, Bits<32>>,
    /// I3: the fetched word's opcode (no register: the long instructions reserve their write
    /// back from it, a clock ahead of `op_i4`).
    pub op_i3: Signal<Out, Bits<OP_BITS>>,
    /// I4: the instruction (`valid_i4`, its opcode, thread and immediate).
    pub valid_i4: Signal<Out, Bit>,
    pub op_i4: Signal<Out, Bits<OP_BITS>>,
    pub thread_i4: Signal<Out, Bits<5>>,
    pub imm_i4: Signal<Out, Bits<32>>,
    /// I5: the instruction's fields and operands.
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
    v4: DFF<Bit>,
    t4: DFF<Bits<5>>,
    pc4: DFF<Bits<PC_BITS>>,
    ctl4: DFF<Bits<32>>,
    imm4: DFF<Bits<32>>,
    aux4: DFF<Bits<32>>,
    v5: DFF<Bit>,
    t5: DFF<Bits<5>>,
    pc5: DFF<Bits<PC_BITS>>,
    ctl5: DFF<Bits<32>>,
    imm5: DFF<Bits<32>>,
    aux5: DFF<Bits<32>>,
    a5: DFF<Bits<32>>,
    b5: DFF<Bits<32>>,
    store5: DFF<Bits<32>>,
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
            valid_i3: Default::default(),
            thread_i3: Default::default(),
            pc_i3: Default::default(),
            ctl_i3: Default::default(),
            imm_i3: Default::default(),
            aux_i3: Default::default(),
            op_i3: Default::default(),
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
            valid_i4: Default::default(),
            op_i4: Default::default(),
            thread_i4: Default::default(),
            imm_i4: Default::default(),
            a: Default::default(),
            b: Default::default(),
            store: Default::default(),
            wb_write: Default::default(),
            wb_thread: Default::default(),
            wb_dst: Default::default(),
            wb_data: Default::default(),
            regs_a: NoCollisionRam::decoding(5 + register_bits),
            regs_b: NoCollisionRam::decoding(5 + register_bits),
            v4: Default::default(),
            t4: Default::default(),
            pc4: Default::default(),
            ctl4: Default::default(),
            imm4: Default::default(),
            aux4: Default::default(),
            v5: Default::default(),
            t5: Default::default(),
            pc5: Default::default(),
            ctl5: Default::default(),
            imm5: Default::default(),
            aux5: Default::default(),
            a5: Default::default(),
            b5: Default::default(),
            store5: Default::default(),
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
            self, clock, v4, t4, pc4, ctl4, imm4, aux4, v5, t5, pc5, ctl5, imm5, aux5, a5, b5,
            store5
        );
        self.regs_a.read_clock.next = self.clock.val();
        self.regs_a.write_clock.next = self.clock.val();
        self.regs_b.read_clock.next = self.clock.val();
        self.regs_b.write_clock.next = self.clock.val();

        // I3: read the source registers.
        self.op_i3.next = self
            .ctl_i3
            .val()
            .get_bits::<OP_BITS>(self.f_op.val().index());
        self.reg_a.next = self
            .ctl_i3
            .val()
            .get_bits::<REG_BITS>(self.f_a.val().index());
        self.reg_b.next = self
            .ctl_i3
            .val()
            .get_bits::<REG_BITS>(self.f_b.val().index());
        self.regs_a.read_address.next = (bit_cast::<13, REG_BITS>(self.reg_a.val()) << 5)
            | bit_cast::<13, 5>(self.thread_i3.val());
        self.regs_b.read_address.next = (bit_cast::<13, REG_BITS>(self.reg_b.val()) << 5)
            | bit_cast::<13, 5>(self.thread_i3.val());
        self.v4.d.next = self.valid_i3.val();
        self.t4.d.next = self.thread_i3.val();
        self.pc4.d.next = self.pc_i3.val();
        self.ctl4.d.next = self.ctl_i3.val();
        self.imm4.d.next = self.imm_i3.val();
        self.aux4.d.next = self.aux_i3.val();

        // I4: the operands (r0 always reads 0) as the register words arrive.
        self.valid_i4.next = self.v4.q.val();
        self.op_i4.next = self
            .ctl4
            .q
            .val()
            .get_bits::<OP_BITS>(self.f_op.val().index());
        self.thread_i4.next = self.t4.q.val();
        self.imm_i4.next = self.imm4.q.val();
        self.v5.d.next = self.v4.q.val();
        self.t5.d.next = self.t4.q.val();
        self.pc5.d.next = self.pc4.q.val();
        self.ctl5.d.next = self.ctl4.q.val();
        self.imm5.d.next = self.imm4.q.val();
        self.aux5.d.next = self.aux4.q.val();
        if self.aux4.q.val().get_bit(self.f_a_zero.val().index()) {
            self.a5.d.next = 0.into();
        } else {
            self.a5.d.next = self.regs_a.read_data.val();
        }
        if self.ctl4.q.val().get_bit(self.f_b_imm.val().index()) {
            self.b5.d.next = self.imm4.q.val();
        } else if self.aux4.q.val().get_bit(self.f_b_zero.val().index()) {
            self.b5.d.next = 0.into();
        } else {
            self.b5.d.next = self.regs_b.read_data.val();
        }
        self.store5.d.next = self.regs_b.read_data.val();

        // I5: the fields and operands.
        self.valid.next = self.v5.q.val();
        self.thread.next = self.t5.q.val();
        self.pc.next = self.pc5.q.val();
        self.op.next = self
            .ctl5
            .q
            .val()
            .get_bits::<OP_BITS>(self.f_op.val().index());
        self.dst.next = self
            .ctl5
            .q
            .val()
            .get_bits::<REG_BITS>(self.f_dst.val().index());
        self.invert.next = self.ctl5.q.val().get_bit(self.f_invert.val().index());
        self.imm.next = self.imm5.q.val();
        self.shift.next = self
            .aux5
            .q
            .val()
            .get_bits::<SHIFT_BITS>(self.f_shift.val().index());
        self.bank.next = self
            .aux5
            .q
            .val()
            .get_bits::<BANK_BITS>(self.f_bank.val().index());
        self.target.next = self
            .aux5
            .q
            .val()
            .get_bits::<PC_BITS>(self.f_target.val().index());
        self.a.next = self.a5.q.val();
        self.b.next = self.b5.q.val();
        self.store.next = self.store5.q.val();

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
