"""cocotb test of a dynrt processor: drives the top module `dynrt_processor` directly.

Python here is the board: six SRAM banks loaded from the memory images in ../mem (the
read-latency contract of PORTS.md: one read a clock on each of the four read ports, the word
`mem_latency` clocks after the address), the frame-buffer writes into bank 5, the start/done
handshake per frame with the frames' memory updates between them. Each frame buffer is checked
word for word against golden<k>.hex, the golden model's frame that `dynrt rtl` and
`dynrt sim` write beside the images. The parameters come from processor.json beside this file.

Run with run.py (cocotb's Python runner, Icarus Verilog) or any cocotb flow with
DYNRT_DIR set to the folder `dynrt rtl --out` wrote.
"""

import collections
import json
import os
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge

DEADBEEF = 0xDEADBEEF


def read_memh(path):
    """(address, word) pairs of a $readmemh file: // comments, @address records, hex words."""
    addr = 0
    words = []
    for line in Path(path).read_text().splitlines():
        line = line.split("//", 1)[0].strip()
        for token in line.split():
            if token.startswith("@"):
                addr = int(token[1:], 16)
            else:
                words.append((addr, int(token.replace("_", ""), 16)))
                addr += 1
    return words


def value(signal):
    """The signal's value as an int, None while it holds X or Z."""
    try:
        return int(signal.value)
    except ValueError:
        return None


class Board:
    """The SRAM banks and their read ports, as the generated testbench models them."""

    def __init__(self, dut, config, mem_dir):
        self.dut = dut
        self.latency = config["mem_latency"]
        self.sizes = config["bank_words"]
        self.mem_dir = Path(mem_dir)
        self.banks = [dict() for _ in self.sizes]
        for bank, name in enumerate(config["bank_files"]):
            self.load(bank, name)
        # port -> the last `latency` words read, oldest first
        self.lines = {
            p: collections.deque([0] * self.latency, maxlen=self.latency)
            for p in ("mem", "bank0", "bank2", "bank3")
        }

    def load(self, bank, name):
        for addr, word in read_memh(self.mem_dir / name):
            self.banks[bank][addr] = word

    def word(self, bank, addr):
        if addr is None or addr >= max(self.sizes[bank], 1):
            return DEADBEEF
        return self.banks[bank].get(addr, DEADBEEF)

    async def serve(self):
        dut = self.dut
        while True:
            await RisingEdge(dut.clock)
            # Values read right after the edge are those the design presented at it.
            mem_bank = value(dut.mem_bank)
            reads = {
                "mem": self.word(mem_bank, value(dut.mem_addr))
                if mem_bank in (1, 4, 5)
                else DEADBEEF,
                "bank0": self.word(0, value(dut.bank0_addr)),
                "bank2": self.word(2, value(dut.bank2_addr)),
                "bank3": self.word(3, value(dut.bank3_addr)),
            }
            if value(dut.fb_write) == 1:
                self.banks[5][value(dut.fb_addr)] = value(dut.fb_data)
            for port, word in reads.items():
                line = self.lines[port]
                line.append(word)
                getattr(dut, f"{port}_rdata").value = line[0]


@cocotb.test()
async def frames_equal_the_golden_model(dut):
    here = Path(os.environ.get("DYNRT_DIR", Path(__file__).resolve().parent.parent))
    config = json.loads((here / "cocotb" / "processor.json").read_text())
    board = Board(dut, config, here / "mem")
    dut.start.value = 0
    dut.vga_clock.value = 0
    dut.vga_reset.value = 1
    dut.vga_fb_data.value = 0
    cocotb.start_soon(Clock(dut.clock, 10, unit="ns").start())
    cocotb.start_soon(board.serve())
    for k, frame in enumerate(config["frames"]):
        for bank, name in frame["updates"]:
            board.load(bank, name)
        await FallingEdge(dut.clock)
        dut.start.value = 1
        await FallingEdge(dut.clock)
        dut.start.value = 0
        clocks = 0
        while value(dut.done) != 1:
            await RisingEdge(dut.clock)
            clocks += 1
            assert clocks < config["cycle_limit"], (
                f"frame {k} not done after {clocks} clocks"
            )
        fb = config["frame_buffer"]
        got = [board.banks[5].get(fb + i, DEADBEEF) & 0xFFFFFF for i in range(config["pixels"])]
        golden = [int(w, 16) for w in (here / f"golden{k}.hex").read_text().split()]
        assert len(golden) == config["pixels"], f"golden{k}.hex has {len(golden)} pixels"
        differing = [i for i in range(len(golden)) if got[i] != golden[i]]
        dut._log.info(
            "frame %d: %d cycles, %d of %d pixels differ from golden%d.hex",
            k, value(dut.cycles), len(differing), len(golden), k,
        )
        assert not differing, (
            f"frame {k}: {len(differing)} pixels differ from golden{k}.hex, first at pixel "
            f"{differing[0]}: {got[differing[0]]:06x} != {golden[differing[0]]:06x}"
        )
