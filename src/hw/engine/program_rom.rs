//! `ProgramRom`: the microprogram's instruction ROM, the three words of each instruction
//! (`ctl`, `imm`, `aux`, as `isa::Instr::encode` writes them), read one clock after the pc.
//!
//! Why not rust-hdl's `RAM`: it declares every address of its address width, so a 150-word
//! program took 4,096 words per ROM word, 8 block RAMs each, 24 spread over the chip for one
//! pc. This ROM holds the program's words rounded up to a power of two (one ECP5 `DP16KD` per
//! ROM word up to 512 instructions) and reads with the address bits it needs; a pc beyond the
//! program never reaches it (every jump targets an instruction, and the last one halts).
//!
//! Contract: `ctl`, `imm`, `aux` show the words of the instruction at `address` one clock
//! after it; an address past the program's rounded size reads the program's words again (its
//! low bits).
//!
//! Latency: 1 clock. Throughput: one instruction per clock.
//!
//! Golden twin: `hw::program::Program::rom`, the words it holds, which the engine's twin
//! `hw::program::exec` reads through `isa::Instr::decode`.

use rust_hdl::prelude::*;

use crate::hw::program::isa::{PC_BITS, ROM_WORDS};

#[derive(LogicBlock)]
pub struct ProgramRom {
    pub clock: Signal<In, Clock>,
    pub address: Signal<In, Bits<PC_BITS>>,
    pub ctl: Signal<Out, Bits<32>>,
    pub imm: Signal<Out, Bits<32>>,
    pub aux: Signal<Out, Bits<32>>,
    // (rust-hdl's derive skips fields named with a leading underscore: the words)
    _words: Vec<[u32; ROM_WORDS]>,
}

impl ProgramRom {
    /// The ROM of a program's words (`Program::rom`), at most `2^PC_BITS` instructions.
    pub fn new(words: Vec<[u32; ROM_WORDS]>) -> Self {
        assert!(!words.is_empty() && words.len() <= 1 << PC_BITS);
        let size = words.len().next_power_of_two().max(2);
        let mut words = words;
        words.resize(size, [0; ROM_WORDS]);
        Self {
            clock: Default::default(),
            address: Default::default(),
            ctl: Default::default(),
            imm: Default::default(),
            aux: Default::default(),
            _words: words,
        }
    }

    /// Address bits the ROM decodes.
    fn address_bits(&self) -> usize {
        self._words.len().trailing_zeros() as usize
    }
}

impl Logic for ProgramRom {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let at = self.address.val().index() & (self._words.len() - 1);
            let [ctl, imm, aux] = self._words[at];
            self.ctl.next = u64::from(ctl).into();
            self.imm.next = u64::from(imm).into();
            self.aux.next = u64::from(aux).into();
        }
    }

    fn connect(&mut self) {
        self.ctl.connect();
        self.imm.connect();
        self.aux.connect();
    }

    fn hdl(&self) -> Verilog {
        let init = self
            ._words
            .iter()
            .enumerate()
            .map(|(pc, [ctl, imm, aux])| {
                format!(
                    "   ctl_words[{pc}] = 32'h{ctl:08x}; imm_words[{pc}] = 32'h{imm:08x}; \
                     aux_words[{pc}] = 32'h{aux:08x};\n"
                )
            })
            .collect::<String>();
        Verilog::Custom(format!(
            "\
reg[31:0] ctl_words[{last}:0];
reg[31:0] imm_words[{last}:0];
reg[31:0] aux_words[{last}:0];

initial begin
{init}end

always @(posedge clock) begin
   ctl <= ctl_words[address[{top}:0]];
   imm <= imm_words[address[{top}:0]];
   aux <= aux_words[address[{top}:0]];
end
",
            last = self._words.len() - 1,
            top = self.address_bits() - 1,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::sim_harness::{clock_cycle, settle};

    #[derive(LogicBlock)]
    struct Bench {
        clock: Signal<In, Clock>,
        rom: ProgramRom,
    }

    impl Logic for Bench {
        #[hdl_gen]
        fn update(&mut self) {
            self.rom.clock.next = self.clock.val();
        }
    }

    /// Five instructions whose words say where they are.
    fn words() -> Vec<[u32; ROM_WORDS]> {
        (0..5u32)
            .map(|pc| [0x100 + pc, 0x200 + pc, 0x300 + pc])
            .collect()
    }

    #[test]
    fn an_instruction_shows_one_clock_after_its_address() {
        let mut b = Bench {
            clock: Default::default(),
            rom: ProgramRom::new(words()),
        };
        b.connect_all();
        for pc in [4u64, 0, 3, 1] {
            b.rom.address.next = pc.into();
            settle(&mut b);
            let before = b.rom.ctl.val();
            clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
            let pc32 = pc as u32;
            assert_ne!(
                before,
                Bits::<32>::from(u64::from(0x100 + pc32)),
                "pc {pc} early"
            );
            assert_eq!(b.rom.ctl.val(), Bits::<32>::from(u64::from(0x100 + pc32)));
            assert_eq!(b.rom.imm.val(), Bits::<32>::from(u64::from(0x200 + pc32)));
            assert_eq!(b.rom.aux.val(), Bits::<32>::from(u64::from(0x300 + pc32)));
        }
    }

    #[test]
    fn the_verilog_holds_the_program_rounded_to_a_power_of_two() {
        let v = match ProgramRom::new(words()).hdl() {
            Verilog::Custom(text) => text,
            _ => panic!("ProgramRom writes its own Verilog"),
        };
        assert!(v.contains("reg[31:0] ctl_words[7:0];"), "{v}");
        assert!(v.contains("ctl <= ctl_words[address[2:0]];"), "{v}");
        assert!(v.contains("imm_words[4] = 32'h00000204;"), "{v}");
        assert!(v.contains("aux_words[7] = 32'h00000000;"), "{v}");
    }
}
