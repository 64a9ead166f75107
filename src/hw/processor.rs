//! `Processor`: the whole ray tracing processor of one scene, the top module of the generated
//! Verilog (`emit::processor` names it `dynrt_processor`): the [`ThreadEngine`] with its
//! coprocessors in the main clock domain, and the [`VgaDisplay`] in the pixel clock domain.
//!
//! Contract: its ports are the board's. In the main clock (`clock`): a `start` pulse renders a
//! frame, `done` says it is finished, `cycles` and `instructions` count it; `mem` reads banks
//! 1, 4 and 5, `bank0`, `bank2`, `bank3` read the kd nodes and the two triangle banks, each
//! port one word per clock `mem_latency` clocks after the request; `fb` writes the frame
//! buffer (bank 5); `transform_busy`, `intersect_busy`, `traversal_busy` count the frame's
//! clocks in which those units took work (the TransformUnit's triangle tests), `raygen_busy`,
//! `instance_busy` and `shading_busy` the clocks in which ray generation's, instance entry's
//! and shading's (world normals) requests took the TransformUnit; `tri_cache_hits` and
//! `tri_cache_misses` the triangle tests whose words came from the triangle cache and from
//! the banks, `node_cache_hits` and `node_cache_misses` the object-tree nodes the traversal
//! unit took from its node cache and from bank 0, `instance_cache_hits` and
//! `instance_cache_misses` the instance entries (and world normals) whose record came from
//! the instance cache and from bank 4. In the pixel clock (`vga.clock`): the display reads
//! the frame buffer and drives the monitor. The Verilog names a bundle's port
//! `<bundle>_<port>` (`mem_read`, `vga_hsync`): `Processor::ports` lists them, and the
//! constraints and testbench are written from that list.
//!
//! Latency and throughput: those of the engine (one instruction per clock) and the display
//! (one pixel per pixel clock).
//!
//! Golden twin: the golden model (`model::golden`) renders the frames the processor must
//! write, pixel for pixel (`tests/processor_sim.rs`, `dynrt sim`).

use rust_hdl::prelude::*;

use super::engine::ThreadEngine;
use super::ports::{BankedSramRead, FrameBufferWrite, SramRead, VgaPort};
use super::program::Program;
use super::vga::{VgaError, VgaMode, VGA_ADDR_BITS};
use super::VgaDisplay;

/// How the processor is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProcessorParams {
    /// Ray threads (1..=32).
    pub threads: u32,
    /// SRAM read latency in clocks (1..=6).
    pub mem_latency: u32,
    /// Sets of the triangle cache (0: none) and its ways (1, 2 or 4; sets a power of two,
    /// sets times ways at most [`MAX_CACHE_SETS`](crate::hw::cache::MAX_CACHE_SETS):
    /// [`crate::hw::cache::cache_shape_supported`]).
    pub tri_cache_sets: u32,
    pub tri_cache_ways: u32,
    /// Sets and ways of the traversal unit's node cache (the same rule).
    pub node_cache_sets: u32,
    pub node_cache_ways: u32,
    /// Sets and ways of instance entry's instance cache (the same rule).
    pub instance_cache_sets: u32,
    pub instance_cache_ways: u32,
}

impl Default for ProcessorParams {
    fn default() -> Self {
        ProcessorParams {
            threads: 32,
            mem_latency: 2,
            tri_cache_sets: crate::hw::cache::MAX_CACHE_SETS,
            tri_cache_ways: 1,
            node_cache_sets: crate::hw::cache::MAX_CACHE_SETS,
            node_cache_ways: 1,
            instance_cache_sets: crate::hw::cache::MAX_CACHE_SETS,
            instance_cache_ways: 1,
        }
    }
}

#[derive(LogicBlock)]
pub struct Processor<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
    const DX: usize,
    const DL: usize,
> {
    pub clock: Signal<In, Clock>,
    /// A one-clock pulse starts a frame (while `done` or before the first frame).
    pub start: Signal<In, Bit>,
    pub done: Signal<Out, Bit>,
    pub cycles: Signal<Out, Bits<32>>,
    pub instructions: Signal<Out, Bits<32>>,
    pub mem: BankedSramRead,
    pub fb: FrameBufferWrite,
    pub bank0: SramRead,
    pub bank2: SramRead,
    pub bank3: SramRead,
    pub transform_busy: Signal<Out, Bits<32>>,
    pub intersect_busy: Signal<Out, Bits<32>>,
    pub traversal_busy: Signal<Out, Bits<32>>,
    pub raygen_busy: Signal<Out, Bits<32>>,
    pub instance_busy: Signal<Out, Bits<32>>,
    pub shading_busy: Signal<Out, Bits<32>>,
    pub tri_cache_hits: Signal<Out, Bits<32>>,
    pub tri_cache_misses: Signal<Out, Bits<32>>,
    pub node_cache_hits: Signal<Out, Bits<32>>,
    pub node_cache_misses: Signal<Out, Bits<32>>,
    pub instance_cache_hits: Signal<Out, Bits<32>>,
    pub instance_cache_misses: Signal<Out, Bits<32>>,
    pub vga: VgaPort,
    engine: ThreadEngine<W, E, M, S, S1, X2, T, P, DX, DL>,
    display: VgaDisplay,
}

/// A port of the processor's top module as the Verilog names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopPort {
    /// The board's name (`mem_read`).
    pub name: String,
    /// rust-hdl's name (`mem$read`).
    pub hdl_name: String,
    pub output: bool,
    pub bits: usize,
    pub clock: bool,
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
        const DX: usize,
        const DL: usize,
    > Processor<W, E, M, S, S1, X2, T, P, DX, DL>
{
    /// The processor running `program` as `params` say (threads, SRAM latency, caches),
    /// showing a `width x height` frame from word `frame_buffer` of bank 5 in `mode`.
    pub fn new(
        program: &Program,
        params: &ProcessorParams,
        mode: &VgaMode,
    ) -> Result<Self, VgaError> {
        let c = &program.config;
        Ok(Self {
            clock: Default::default(),
            start: Default::default(),
            done: Default::default(),
            cycles: Default::default(),
            instructions: Default::default(),
            mem: Default::default(),
            fb: Default::default(),
            bank0: Default::default(),
            bank2: Default::default(),
            bank3: Default::default(),
            transform_busy: Default::default(),
            intersect_busy: Default::default(),
            traversal_busy: Default::default(),
            raygen_busy: Default::default(),
            instance_busy: Default::default(),
            shading_busy: Default::default(),
            tri_cache_hits: Default::default(),
            tri_cache_misses: Default::default(),
            node_cache_hits: Default::default(),
            node_cache_misses: Default::default(),
            instance_cache_hits: Default::default(),
            instance_cache_misses: Default::default(),
            vga: Default::default(),
            engine: ThreadEngine::new(program, params),
            display: VgaDisplay::new(mode, c.width, c.height, c.frame_buffer)?,
        })
    }

    /// The top module's ports, in declaration order, with the names the Verilog gives them
    /// (a bundle's `<bundle>$<port>` becomes `<bundle>_<port>`).
    pub fn ports(&self) -> Vec<TopPort> {
        struct Ports {
            depth: usize,
            namespace: Vec<String>,
            ports: Vec<TopPort>,
        }
        impl Probe for Ports {
            fn visit_start_scope(&mut self, _name: &str, _node: &dyn Block) {
                self.depth += 1;
            }
            fn visit_end_scope(&mut self, _name: &str, _node: &dyn Block) {
                self.depth -= 1;
            }
            fn visit_start_namespace(&mut self, name: &str, _node: &dyn Block) {
                self.namespace.push(name.to_string());
            }
            fn visit_end_namespace(&mut self, _name: &str, _node: &dyn Block) {
                self.namespace.pop();
            }
            fn visit_atom(&mut self, name: &str, signal: &dyn Atom) {
                let output = match signal.kind() {
                    AtomKind::InputParameter => false,
                    AtomKind::OutputParameter => true,
                    _ => return,
                };
                // Only the top block's own ports (scope depth 1), not its children's.
                if self.depth != 1 {
                    return;
                }
                let mut name_parts = self.namespace.clone();
                name_parts.push(name.to_string());
                self.ports.push(TopPort {
                    name: name_parts.join("_"),
                    hdl_name: name_parts.join("$"),
                    output,
                    bits: signal.bits(),
                    clock: signal.descriptor().name == "clock",
                });
            }
        }
        let mut probe = Ports {
            depth: 0,
            namespace: Vec::new(),
            ports: Vec::new(),
        };
        self.accept("top", &mut probe);
        probe.ports
    }
}

impl<
        const W: usize,
        const E: usize,
        const M: usize,
        const S: usize,
        const S1: usize,
        const X2: usize,
        const T: usize,
        const P: usize,
        const DX: usize,
        const DL: usize,
    > Logic for Processor<W, E, M, S, S1, X2, T, P, DX, DL>
{
    #[hdl_gen]
    fn update(&mut self) {
        self.engine.clock.next = self.clock.val();
        self.engine.start.next = self.start.val();
        self.done.next = self.engine.done.val();
        self.cycles.next = self.engine.cycles.val();
        self.instructions.next = self.engine.instructions.val();
        BankedSramRead::link(&mut self.mem, &mut self.engine.mem);
        FrameBufferWrite::link(&mut self.fb, &mut self.engine.fb);
        SramRead::link(&mut self.bank0, &mut self.engine.bank0);
        SramRead::link(&mut self.bank2, &mut self.engine.bank2);
        SramRead::link(&mut self.bank3, &mut self.engine.bank3);
        self.transform_busy.next = self.engine.transform_busy.val();
        self.intersect_busy.next = self.engine.intersect_busy.val();
        self.traversal_busy.next = self.engine.traversal_busy.val();
        self.raygen_busy.next = self.engine.raygen_busy.val();
        self.instance_busy.next = self.engine.instance_busy.val();
        self.shading_busy.next = self.engine.shading_busy.val();
        self.tri_cache_hits.next = self.engine.tri_cache_hits.val();
        self.tri_cache_misses.next = self.engine.tri_cache_misses.val();
        self.node_cache_hits.next = self.engine.node_cache_hits.val();
        self.node_cache_misses.next = self.engine.node_cache_misses.val();
        self.instance_cache_hits.next = self.engine.instance_cache_hits.val();
        self.instance_cache_misses.next = self.engine.instance_cache_misses.val();

        self.display.clock.next = self.vga.clock.val();
        self.display.reset.next = self.vga.reset.val();
        self.vga.fb_addr.next = bit_cast::<24, VGA_ADDR_BITS>(self.display.fb_addr.val());
        self.display.fb_data.next = self.vga.fb_data.val();
        self.vga.hsync.next = self.display.hsync.val();
        self.vga.vsync.next = self.display.vsync.val();
        self.vga.rgb.next = self.display.rgb.val();
        self.vga.frame_start.next = self.display.frame_start.val();
    }
}
