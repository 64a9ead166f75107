//! `ShadeUnit`: direct shading in hardware, the colour of a primary ray's pixel from its
//! closest hit, through the one TransformUnit. A thread hands it a finished query (the pixel's
//! frame-buffer word, hit or miss, t, triangle) and goes on to its next pixel; the unit reads
//! the triangle's normal and material, computes the colour and writes the packed pixel into the
//! frame buffer itself. In the microprogram this was about 50 instructions per lit hit (the
//! hit point, the normal facing the ray, the ambient term, per light `light - p`, `n . L`,
//! `L . L`, a square root, a division and the Lambert sum, three `byte`s and the store).
//!
//! Scope: rays without shadows, mirrors or instances (the stored normal is the world normal),
//! at most [`MAX_SHADE_LIGHTS`] lights.
//!
//! Contract:
//! - Frame start: `frame_start` (a clock's pulse) reads the frame's ambient, background and
//!   lights from the frame bank; `refused` stays high until they are in.
//! - Rays (any clock): `ray_write` writes thread `ray_thread`'s ray `ray_o`, `ray_d` (the
//!   whole-ray writes into the coprocessors' ray stores, snooped).
//! - Offer (the engine's I5, `query_thread` at I4): `offer` for `query_thread` with
//!   `offer_addr` (the pixel's frame-buffer word, before `fb_base`), `offer_hit`, `offer_t`,
//!   `offer_triangle` is taken unless `refused` (no slot of [`SHADE_SLOTS`] free as of the
//!   clock before, or constants loading); the thread's ray is copied then, so it may trace
//!   its next ray at once.
//! - Memory: `tri_read` with `tri_addr` reads banks 2 and 3 at once (`tri_rdata_a`,
//!   `tri_rdata_b`), `frame_read` with `frame_addr` bank 5; each read goes out in a clock
//!   with its `*_grant` and its word arrives `tri_latency` (`frame_latency`) clocks later.
//! - TransformUnit (a client port like the tester's `gen_*`): a request (`gen_valid`, matrix
//!   `gen_m`, `gen_v`, `gen_point`, `gen_diagonal`, `gen_slot`) is held until `gen_take`; its
//!   result comes back on `res_*` with its slot, in request order, and is registered as it
//!   arrives.
//! - Frame buffer: `fb_write` with `fb_addr`, `fb_data` (`0x00RRGGBB`) goes out in a clock
//!   with `fb_grant`.
//! - `idle`: no pixel in the unit and no constant loading.
//!
//! How: each offer takes a slot; a slot's shading is a fixed sequence of steps
//! ([`ShadeStep`]), one operation each: the two shading words of the triangle in banks 2 and 3
//! (normal x, y; normal z, material), the TransformUnit passes (hit point `o + t d`, diagonal;
//! `n . d`, a row; ambient `kd * a`, diagonal; per light `-1 * p + light`, diagonal; `n . L`
//! and `L . L`, two rows; `kd * colour`, diagonal; `acc + tint * cos`, diagonal), the diffuse
//! colour from bank 5, the cosine (a square root, then a division, in the unit's own
//! pipelined operators) and the three channel bytes ([`ChannelByte`]). A slot is ready when
//! its last operation's result is written; the dispatcher picks the first ready slot into S0
//! (when S0 is empty), and S1 reads its words (distributed RAM, read in the same clock) and
//! issues the operation, so the slots' operations interleave in every unit. A light behind
//! the surface (`!(0 < n . L)`) is skipped; a miss is packed from the background.
//!
//! Latency: about 140 clocks plus 110 per light (lit), with the TransformUnit free.
//! Throughput: one operation every two clocks from the dispatcher (S0 refills the clock after
//! S1 takes it; about 14 operations a pixel with one light),
//! [`SHADE_SLOTS`] pixels in flight.
//!
//! Golden twin: [`units::shade_direct`](crate::units::shade_direct) (src/units.rs), pass for
//! pass (its TransformUnit passes are [`units::transform_pass`](crate::units::transform_pass)),
//! equal to the golden model's shading of the hit.

use rust_hdl::prelude::*;

use super::fp::div::div_latency;
use super::fp::sqrt::sqrt_latency;
use super::fp::{const_bits, FpDiv, FpSqrt};
use super::{ChannelByte, Delay, DelayLine, LutRam, CHANNEL_BYTE_LATENCY};
use crate::layout::{FrameMap, TRANSFORM_BANK_WORDS};

/// Pixels the unit shades at once (`update` spells out `[16]` and the slot's 4 bits:
/// rust-hdl's Verilog cannot name Rust constants in an index). A pixel takes its slot for
/// about 250 clocks (one light), so 8 slots let one pixel in per 31 clocks, cornell_noshadow's
/// bound at 38.3 cycles per primary ray (stop 46); 16 slots fit the same distributed RAMs
/// (ECP5's are 16 words deep).
pub const SHADE_SLOTS: usize = 16;
/// Most lights the unit holds.
pub const MAX_SHADE_LIGHTS: usize = 8;

/// What a slot does next.
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum ShadeStep {
    /// No pixel.
    Idle,
    /// Read the normal and material words (banks 2 and 3, two words each).
    TriLoad,
    /// TransformUnit: the hit point `o + t d`.
    Point,
    /// TransformUnit: `n . d`, whose sign flips the normal to face the ray.
    NormalDot,
    /// Read the material's diffuse colour (bank 5, three words).
    KdLoad,
    /// TransformUnit: the ambient term `kd * ambient`.
    Ambient,
    /// TransformUnit: the light's vector `light - p`.
    ToLight,
    /// TransformUnit: `n . L` and `L . L`.
    Dots,
    /// `(n . L) / sqrt(L . L)`.
    Cosine,
    /// TransformUnit: `kd * colour`.
    Tint,
    /// TransformUnit: `acc + tint * cos`.
    Accumulate,
    /// The three channel bytes.
    Pack,
    /// The frame-buffer write.
    Store,
}

/// Kinds of memory words in flight (`*_line` tags).
const KIND_TRI: u64 = 0;
const KIND_KD: u64 = 1;
const KIND_LIGHT: u64 = 2;
const KIND_CONST: u64 = 3;

/// Words of a slot's state, each a distributed RAM of [`SHADE_SLOTS`] words.
type SlotRam<D> = LutRam<D, 4>;

fn slot_ram<D: Synth>() -> SlotRam<D> {
    LutRam::new(Default::default())
}

#[derive(LogicBlock)]
pub struct ShadeUnit<
    const W: usize,
    const E: usize,
    const M: usize,
    const S: usize,
    const S1: usize,
    const X2: usize,
    const T: usize,
    const P: usize,
> {
    pub clock: Signal<In, Clock>,
    pub frame_start: Signal<In, Bit>,
    pub ray_write: Signal<In, Bit>,
    pub ray_thread: Signal<In, Bits<5>>,
    pub ray_o: [Signal<In, Bits<W>>; 3],
    pub ray_d: [Signal<In, Bits<W>>; 3],
    pub query_thread: Signal<In, Bits<5>>,
    pub offer: Signal<In, Bit>,
    pub offer_addr: Signal<In, Bits<24>>,
    pub offer_hit: Signal<In, Bit>,
    pub offer_t: Signal<In, Bits<W>>,
    pub offer_triangle: Signal<In, Bits<24>>,
    pub refused: Signal<Out, Bit>,
    pub tri_read: Signal<Out, Bit>,
    pub tri_addr: Signal<Out, Bits<24>>,
    pub tri_grant: Signal<In, Bit>,
    pub tri_rdata_a: Signal<In, Bits<32>>,
    pub tri_rdata_b: Signal<In, Bits<32>>,
    pub frame_read: Signal<Out, Bit>,
    pub frame_addr: Signal<Out, Bits<24>>,
    pub frame_grant: Signal<In, Bit>,
    pub frame_rdata: Signal<In, Bits<32>>,
    pub gen_valid: Signal<Out, Bit>,
    pub gen_m: [Signal<Out, Bits<W>>; 12],
    pub gen_v: [Signal<Out, Bits<W>>; 3],
    pub gen_point: Signal<Out, Bit>,
    pub gen_diagonal: Signal<Out, Bit>,
    pub gen_slot: Signal<Out, Bits<4>>,
    pub gen_take: Signal<In, Bit>,
    pub res_valid: Signal<In, Bit>,
    pub res_slot: Signal<In, Bits<4>>,
    pub res_v: [Signal<In, Bits<W>>; 3],
    pub fb_write: Signal<Out, Bit>,
    pub fb_addr: Signal<Out, Bits<24>>,
    pub fb_data: Signal<Out, Bits<32>>,
    pub fb_grant: Signal<In, Bit>,
    pub idle: Signal<Out, Bit>,

    /// Each thread's last ray (o, d), read at I4 for an offer at I5.
    rays: [RAM<Bits<W>, 5>; 6],
    // Slots: control.
    busy: [DFF<Bit>; SHADE_SLOTS],
    ready: [DFF<Bit>; SHADE_SLOTS],
    step: [DFF<ShadeStep>; SHADE_SLOTS],
    light: [DFF<Bits<3>>; SHADE_SLOTS],
    flip: [DFF<Bit>; SHADE_SLOTS],
    miss: [DFF<Bit>; SHADE_SLOTS],
    // Slots: words.
    o: [SlotRam<Bits<W>>; 3],
    d: [SlotRam<Bits<W>>; 3],
    t: SlotRam<Bits<W>>,
    addr: SlotRam<Bits<24>>,
    triangle: SlotRam<Bits<24>>,
    n: [SlotRam<Bits<W>>; 3],
    material: SlotRam<Bits<24>>,
    kd: [SlotRam<Bits<W>>; 3],
    p: [SlotRam<Bits<W>>; 3],
    acc: [SlotRam<Bits<W>>; 3],
    to_light: [SlotRam<Bits<W>>; 3],
    n_dot_l: SlotRam<Bits<W>>,
    l_dot_l: SlotRam<Bits<W>>,
    tint: [SlotRam<Bits<W>>; 3],
    cos: SlotRam<Bits<W>>,
    rgb: SlotRam<Bits<24>>,
    // Frame constants.
    ambient: DFF<Bits<W>>,
    background: [DFF<Bits<W>>; 3],
    light_position: [LutRam<Bits<W>, 3>; 3],
    light_color: [LutRam<Bits<W>, 3>; 3],
    loading: DFF<Bit>,
    /// Constant reads issued and arrived; the next one's address, light and word.
    const_issued: DFF<Bits<6>>,
    const_arrived: DFF<Bits<6>>,
    const_addr: DFF<Bits<24>>,
    const_lights: DFF<Bit>,
    const_light: DFF<Bits<3>>,
    const_word: DFF<Bits<3>>,
    const_go: Signal<Local, Bit>,
    // Offers.
    /// Slots free before slot s (`[s]`), of the busy ones (`any_free_before`) and of the busy
    /// ones and the slot the offer takes (`any_free_after_take`).
    any_free_before: [Signal<Local, Bit>; 17],
    any_free_after_take: [Signal<Local, Bit>; 17],
    /// The slot the next offer takes, and whether there is one, registered: the first free
    /// slot of this clock's busy slots and taken one (a slot freed in this clock is offered a
    /// clock later). Taken straight from the busy slots, the priority chain ran into every
    /// slot's step (stop 42's critical path at 83.4 MHz).
    free_slot_r: DFF<Bits<4>>,
    has_free_r: DFF<Bit>,
    taken: Signal<Local, Bit>,
    /// An offer taken last clock, its slot and whether it hit: the slot's control is set a
    /// clock after the take (its words are written in the clock of the take). Set in the
    /// take's clock, the engine's offer ran through the take into every slot's step (stop 45's
    /// critical path, `execute.op -> shader.step`, 69.6 MHz placed, 11 levels).
    take_r: DFF<Bit>,
    take_slot_r: DFF<Bits<4>>,
    take_hit_r: DFF<Bit>,
    /// A store went out last clock, and its slot: the slot is freed a clock after the store's
    /// grant. Freed in the grant's clock, the frame buffer's grant ran through S1's step
    /// decode into every slot's step (stop 45's critical path, `s1_step -> step.4`, 71.2 MHz
    /// placed, 9 levels).
    stored_r: DFF<Bit>,
    stored_slot_r: DFF<Bits<4>>,
    /// Slot s is busy or taken last clock.
    occupied: [Signal<Local, Bit>; SHADE_SLOTS],
    // Dispatch: a slot is picked into S0, then read and issued in S1. S0 is filled only when
    // empty, so the pick (a priority chain over the slots) never waits for S1's operation to
    // go out; with the pick waiting for `s1_done`, the grants, the pick and every slot's
    // `ready` were one clock (stop 42's critical path, 68.8 MHz placed).
    s0_valid: DFF<Bit>,
    s0_slot: DFF<Bits<4>>,
    s0_step: DFF<ShadeStep>,
    s0_light: DFF<Bits<3>>,
    s0_flip: DFF<Bit>,
    s0_miss: DFF<Bit>,
    s1_valid: DFF<Bit>,
    s1_slot: DFF<Bits<4>>,
    /// The word of a multi-clock operation (loads, bytes).
    s1_word: DFF<Bits<2>>,
    /// The dispatched slot's step, light, flip and miss, registered as it is picked (a slot's
    /// control changes only with its operation's result, so they hold while it is in S0 and
    /// S1).
    s1_step: DFF<ShadeStep>,
    s1_light: DFF<Bits<3>>,
    s1_flip: DFF<Bit>,
    s1_miss: DFF<Bit>,
    /// The step is a TransformUnit pass.
    s1_transform: DFF<Bit>,
    /// The step, one flag per operation that goes out from S1 itself, decoded from S0's
    /// register as the slot moves in (S1's `done` then needs no decode of `s1_step`).
    s1_tri_load: DFF<Bit>,
    s1_kd_load: DFF<Bit>,
    s1_cosine: DFF<Bit>,
    s1_pack: DFF<Bit>,
    s1_store: DFF<Bit>,
    /// The memory step's last request was granted last clock: S1 is done now. (Done in the
    /// grant's clock, the bank and frame-buffer grants ran through S1's reload into the slot
    /// RAMs' read address: stop 46's critical path on cornell_noshadow, `shader.s1_step ->
    /// shader.o.0.read_address`, 72.8 MHz placed.)
    s1_granted: DFF<Bit>,
    s1_load: Signal<Local, Bit>,
    pick_step: Signal<Local, ShadeStep>,
    pick_light: Signal<Local, Bits<3>>,
    pick_flip: Signal<Local, Bit>,
    pick_miss: Signal<Local, Bit>,
    s1_done: Signal<Local, Bit>,
    /// The normal facing the ray (the stored one with its sign flipped by `flip`).
    facing: [Signal<Local, Bits<W>>; 3],
    any_ready_before: [Signal<Local, Bit>; 17],
    ready_slot: Signal<Local, Bits<4>>,
    pick: Signal<Local, Bit>,
    // TransformUnit request held until taken.
    gen_held: DFF<Bit>,
    gen_hold_m: [DFF<Bits<W>>; 12],
    gen_hold_v: [DFF<Bits<W>>; 3],
    gen_hold_point: DFF<Bit>,
    gen_hold_diagonal: DFF<Bit>,
    gen_hold_slot: DFF<Bits<4>>,
    gen_load: Signal<Local, Bit>,
    req_m: [Signal<Local, Bits<W>>; 12],
    req_v: [Signal<Local, Bits<W>>; 3],
    req_point: Signal<Local, Bit>,
    req_diagonal: Signal<Local, Bit>,
    // Results.
    /// The TransformUnit's result, registered as it arrives: routed straight from the unit's
    /// output into the slots' RAM writes it was the processor's critical path (56.0 MHz).
    res_valid_r: DFF<Bit>,
    res_slot_r: DFF<Bits<4>>,
    res_v_r: [DFF<Bits<W>>; 3],
    /// The step and light of the result's slot, read as the result arrives and registered
    /// with it (a slot waits for its one result, so they cannot change in between): the
    /// slots' mux then the RAMs' write enables was stop 42's critical path in one clock.
    res_step_r: DFF<ShadeStep>,
    res_light_r: DFF<Bits<3>>,
    /// `0 < result x`, registered from the unit's result beside `res_v_r`: decoded from
    /// `res_v_r` it was the head of stop 47's placed path on cornell_noshadow (the sign, the
    /// exponent's and mantissa's ORs, then every slot's step: 72.9 MHz).
    res_positive: DFF<Bit>,
    /// The result is slot s's, a per-slot decode registered beside `res_slot_r`.
    res_for: [DFF<Bit>; SHADE_SLOTS],
    /// The step and light a result moves its slot to, decided once for all slots.
    res_next_step: Signal<Local, ShadeStep>,
    res_next_light: Signal<Local, Bits<3>>,
    tri_word_0: Signal<Local, Bit>,
    tri_word_1: Signal<Local, Bit>,
    frame_valid: Signal<Local, Bit>,
    frame_kind: Signal<Local, Bits<2>>,
    frame_word: Signal<Local, Bits<3>>,
    byte_tag_in: Signal<Local, Bits<7>>,
    byte_valid_l: Signal<Local, Bit>,
    byte_word_l: Signal<Local, Bits<W>>,
    rgb_next: Signal<Local, Bits<24>>,
    any_busy: Signal<Local, Bit>,
    tri_read_l: Signal<Local, Bit>,
    frame_read_l: Signal<Local, Bit>,
    frame_addr_l: Signal<Local, Bits<24>>,
    fb_write_l: Signal<Local, Bit>,
    /// Tags of memory words in flight: `{word[8:6], slot or light[5:3], kind[2:1], valid[0]}`.
    tri_line: DelayLine<Bits<10>>,
    frame_line: DelayLine<Bits<10>>,
    tri_tag: Signal<Local, Bits<10>>,
    frame_tag: Signal<Local, Bits<10>>,
    /// The lines run a clock short of the words; their last tag is registered here, beside a
    /// per-slot decode of it, so that a word's slot reaches that slot's step from a flip-flop
    /// of its own. From the line's last stage straight into the eight slots' compares, one net
    /// fanned out to every slot's step (stop 44's critical path, 71.9 MHz placed).
    tri_arrived_r: DFF<Bits<10>>,
    frame_arrived_r: DFF<Bits<10>>,
    tri_arrived: Signal<Local, Bits<10>>,
    frame_arrived: Signal<Local, Bits<10>>,
    /// Slot s's normal is in (its second triangle word arrives now).
    normal_in: [DFF<Bit>; SHADE_SLOTS],
    /// Slot s's diffuse colour is in (its third word arrives now).
    kd_in: [DFF<Bit>; SHADE_SLOTS],
    // The cosine: sqrt(L . L), then n . L over it.
    sqrt: FpSqrt<W, E, M, S, S1, T>,
    div: FpDiv<W, E, M, S, S1, X2>,
    cos_n_dot_l: DelayLine<Bits<W>>,
    /// `{slot, valid}` of the cosine in flight.
    cos_slot: DelayLine<Bits<5>>,
    /// Slot s's cosine was written last clock (decoded from `cos_slot` and registered, so
    /// that each slot's step reads a flip-flop of its own).
    cos_for: [DFF<Bit>; SHADE_SLOTS],
    // The bytes.
    /// The byte's input, registered: the slot RAM's read and the word's select take a clock
    /// of their own, apart from the clamp (stop 41's critical path held all three).
    byte_valid_r: DFF<Bit>,
    byte_word_r: DFF<Bits<W>>,
    byte_tag_r: DFF<Bits<7>>,
    byte_unit: ChannelByte<W, E, M, S, S1, X2, T, P>,
    /// `{word, slot, valid}` of the byte in flight.
    byte_tag: Delay<Bits<7>, { CHANNEL_BYTE_LATENCY as usize }>,
    /// Slot s's third byte was written last clock (as `cos_for`).
    byte_for: [DFF<Bit>; SHADE_SLOTS],
    rgb_acc: DFF<Bits<24>>,
    // Constants.
    c_slot: [Constant<Bits<4>>; SHADE_SLOTS],
    c_sign: Constant<Bits<W>>,
    c_exp_mask: Constant<Bits<W>>,
    c_man_mask: Constant<Bits<W>>,
    c_minus_one: Constant<Bits<W>>,
    c_zero: Constant<Bits<W>>,
    c_shading_word: Constant<Bits<24>>,
    c_materials: Constant<Bits<24>>,
    c_fb_base: Constant<Bits<24>>,
    c_const_addr: Constant<Bits<24>>,
    c_lights_addr: Constant<Bits<24>>,
    c_const_total: Constant<Bits<6>>,
    c_last_light: Constant<Bits<3>>,
    c_has_lights: Constant<Bit>,
    /// Bit 0 (a tag's valid bit) of each tag's width.
    c_valid10: Constant<Bits<10>>,
    c_valid5: Constant<Bits<5>>,
    c_valid7: Constant<Bits<7>>,
    c_kind_tri: Constant<Bits<2>>,
    c_kind_kd: Constant<Bits<2>>,
    c_kind_light: Constant<Bits<2>>,
    c_kind_const: Constant<Bits<2>>,
}

/// The scene's side of a [`ShadeUnit`].
#[derive(Clone, Copy, Debug)]
pub struct ShadeConfig {
    /// Clocks from a granted read of banks 2 and 3 to its words (the engine registers the
    /// read: its memory latency plus one).
    pub tri_latency: u32,
    /// Clocks from a granted read of bank 5 to its word.
    pub frame_latency: u32,
    /// The scene's lights (at most [`MAX_SHADE_LIGHTS`]).
    pub lights: u32,
    /// The frame word of material 0 (`ProgramConfig::materials`).
    pub materials: u32,
    /// The frame word of pixel 0 (`ProgramConfig::frame_buffer`).
    pub frame_buffer: u32,
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
    > ShadeUnit<W, E, M, S, S1, X2, T, P>
{
    pub fn new(config: ShadeConfig) -> Self {
        assert!(W == 1 + E + M && S == M + 1 && S1 == S + 1 && X2 == E + 2 && T == S + 4);
        assert!(config.lights as usize <= MAX_SHADE_LIGHTS, "{config:?}");
        assert!(
            config.tri_latency >= 2 && config.frame_latency >= 2,
            "{config:?}"
        );
        let f = crate::fp::Format::new(E as u32, M as u32).expect("a supported format");
        let sqrt_clocks = sqrt_latency(M as u32) as usize;
        let cos_clocks = sqrt_clocks + div_latency(M as u32) as usize;
        let words = 4 + 6 * config.lights as u64;
        Self {
            clock: Default::default(),
            frame_start: Default::default(),
            ray_write: Default::default(),
            ray_thread: Default::default(),
            ray_o: Default::default(),
            ray_d: Default::default(),
            query_thread: Default::default(),
            offer: Default::default(),
            offer_addr: Default::default(),
            offer_hit: Default::default(),
            offer_t: Default::default(),
            offer_triangle: Default::default(),
            refused: Default::default(),
            tri_read: Default::default(),
            tri_addr: Default::default(),
            tri_grant: Default::default(),
            tri_rdata_a: Default::default(),
            tri_rdata_b: Default::default(),
            frame_read: Default::default(),
            frame_addr: Default::default(),
            frame_grant: Default::default(),
            frame_rdata: Default::default(),
            gen_valid: Default::default(),
            gen_m: Default::default(),
            gen_v: Default::default(),
            gen_point: Default::default(),
            gen_diagonal: Default::default(),
            gen_slot: Default::default(),
            gen_take: Default::default(),
            res_valid: Default::default(),
            res_slot: Default::default(),
            res_v: Default::default(),
            fb_write: Default::default(),
            fb_addr: Default::default(),
            fb_data: Default::default(),
            fb_grant: Default::default(),
            idle: Default::default(),
            rays: Default::default(),
            busy: Default::default(),
            ready: Default::default(),
            step: Default::default(),
            light: Default::default(),
            flip: Default::default(),
            miss: Default::default(),
            o: std::array::from_fn(|_| slot_ram()),
            d: std::array::from_fn(|_| slot_ram()),
            t: slot_ram(),
            addr: slot_ram(),
            triangle: slot_ram(),
            n: std::array::from_fn(|_| slot_ram()),
            material: slot_ram(),
            kd: std::array::from_fn(|_| slot_ram()),
            p: std::array::from_fn(|_| slot_ram()),
            acc: std::array::from_fn(|_| slot_ram()),
            to_light: std::array::from_fn(|_| slot_ram()),
            n_dot_l: slot_ram(),
            l_dot_l: slot_ram(),
            tint: std::array::from_fn(|_| slot_ram()),
            cos: slot_ram(),
            rgb: slot_ram(),
            ambient: Default::default(),
            background: Default::default(),
            light_position: std::array::from_fn(|_| LutRam::new(Default::default())),
            light_color: std::array::from_fn(|_| LutRam::new(Default::default())),
            loading: Default::default(),
            const_issued: Default::default(),
            const_arrived: Default::default(),
            const_addr: Default::default(),
            const_lights: Default::default(),
            const_light: Default::default(),
            const_word: Default::default(),
            const_go: Default::default(),
            any_free_before: Default::default(),
            any_free_after_take: Default::default(),
            free_slot_r: Default::default(),
            has_free_r: Default::default(),
            taken: Default::default(),
            take_r: Default::default(),
            take_slot_r: Default::default(),
            take_hit_r: Default::default(),
            stored_r: Default::default(),
            stored_slot_r: Default::default(),
            occupied: Default::default(),
            s0_valid: Default::default(),
            s0_slot: Default::default(),
            s0_step: Default::default(),
            s0_light: Default::default(),
            s0_flip: Default::default(),
            s0_miss: Default::default(),
            s1_valid: Default::default(),
            s1_slot: Default::default(),
            s1_word: Default::default(),
            s1_step: Default::default(),
            s1_light: Default::default(),
            s1_flip: Default::default(),
            s1_miss: Default::default(),
            s1_transform: Default::default(),
            s1_tri_load: Default::default(),
            s1_kd_load: Default::default(),
            s1_cosine: Default::default(),
            s1_pack: Default::default(),
            s1_store: Default::default(),
            s1_granted: Default::default(),
            s1_load: Default::default(),
            pick_step: Default::default(),
            pick_light: Default::default(),
            pick_flip: Default::default(),
            pick_miss: Default::default(),
            s1_done: Default::default(),
            facing: Default::default(),
            any_ready_before: Default::default(),
            ready_slot: Default::default(),
            pick: Default::default(),
            gen_held: Default::default(),
            gen_hold_m: Default::default(),
            gen_hold_v: Default::default(),
            gen_hold_point: Default::default(),
            gen_hold_diagonal: Default::default(),
            gen_hold_slot: Default::default(),
            gen_load: Default::default(),
            req_m: Default::default(),
            req_v: Default::default(),
            req_point: Default::default(),
            req_diagonal: Default::default(),
            res_valid_r: Default::default(),
            res_slot_r: Default::default(),
            res_v_r: Default::default(),
            res_step_r: Default::default(),
            res_light_r: Default::default(),
            res_positive: Default::default(),
            res_for: Default::default(),
            res_next_step: Default::default(),
            res_next_light: Default::default(),
            tri_word_0: Default::default(),
            tri_word_1: Default::default(),
            frame_valid: Default::default(),
            frame_kind: Default::default(),
            frame_word: Default::default(),
            byte_tag_in: Default::default(),
            byte_valid_l: Default::default(),
            byte_word_l: Default::default(),
            rgb_next: Default::default(),
            any_busy: Default::default(),
            tri_read_l: Default::default(),
            frame_read_l: Default::default(),
            frame_addr_l: Default::default(),
            fb_write_l: Default::default(),
            tri_line: DelayLine::new(config.tri_latency as usize - 1),
            frame_line: DelayLine::new(config.frame_latency as usize - 1),
            tri_arrived_r: Default::default(),
            frame_arrived_r: Default::default(),
            normal_in: Default::default(),
            kd_in: Default::default(),
            tri_tag: Default::default(),
            frame_tag: Default::default(),
            tri_arrived: Default::default(),
            frame_arrived: Default::default(),
            sqrt: Default::default(),
            div: Default::default(),
            cos_n_dot_l: DelayLine::new(sqrt_clocks),
            cos_slot: DelayLine::new(cos_clocks),
            cos_for: Default::default(),
            byte_valid_r: Default::default(),
            byte_word_r: Default::default(),
            byte_tag_r: Default::default(),
            byte_unit: Default::default(),
            byte_tag: Default::default(),
            byte_for: Default::default(),
            rgb_acc: Default::default(),
            c_slot: std::array::from_fn(|s| Constant::new((s as u64).into())),
            c_sign: const_bits::<W>(f.sign_mask() as u64),
            c_exp_mask: const_bits::<W>((((1u64 << E) - 1) << M) as u64),
            c_man_mask: const_bits::<W>((1u64 << M) - 1),
            c_minus_one: const_bits::<W>(f.from_int(-1) as u64),
            c_zero: const_bits::<W>(0),
            c_shading_word: const_bits::<24>(TRANSFORM_BANK_WORDS as u64),
            c_materials: const_bits::<24>(config.materials as u64),
            c_fb_base: const_bits::<24>(config.frame_buffer as u64),
            c_const_addr: const_bits::<24>(FrameMap::AMBIENT as u64),
            c_lights_addr: const_bits::<24>(FrameMap::LIGHTS as u64),
            c_const_total: const_bits::<6>(words),
            c_last_light: const_bits::<3>(config.lights.saturating_sub(1) as u64),
            c_has_lights: Constant::new(config.lights > 0),
            c_valid10: const_bits::<10>(1),
            c_valid5: const_bits::<5>(1),
            c_valid7: const_bits::<7>(1),
            c_kind_tri: const_bits::<2>(KIND_TRI),
            c_kind_kd: const_bits::<2>(KIND_KD),
            c_kind_light: const_bits::<2>(KIND_LIGHT),
            c_kind_const: const_bits::<2>(KIND_CONST),
        }
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
    > Logic for ShadeUnit<W, E, M, S, S1, X2, T, P>
{
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            ambient,
            loading,
            const_issued,
            const_arrived,
            const_addr,
            const_lights,
            const_light,
            const_word,
            s0_valid,
            s0_slot,
            s0_step,
            s0_light,
            s0_flip,
            s0_miss,
            s1_valid,
            s1_slot,
            s1_word,
            s1_step,
            s1_light,
            s1_flip,
            s1_miss,
            s1_transform,
            s1_tri_load,
            s1_kd_load,
            s1_cosine,
            s1_pack,
            s1_store,
            s1_granted,
            take_r,
            take_slot_r,
            take_hit_r,
            stored_r,
            stored_slot_r,
            gen_held,
            gen_hold_point,
            gen_hold_diagonal,
            gen_hold_slot,
            rgb_acc
        );
        for s in 0..SHADE_SLOTS {
            self.busy[s].clock.next = self.clock.val();
            self.busy[s].d.next = self.busy[s].q.val();
            self.ready[s].clock.next = self.clock.val();
            self.ready[s].d.next = self.ready[s].q.val();
            self.step[s].clock.next = self.clock.val();
            self.step[s].d.next = self.step[s].q.val();
            self.light[s].clock.next = self.clock.val();
            self.light[s].d.next = self.light[s].q.val();
            self.flip[s].clock.next = self.clock.val();
            self.flip[s].d.next = self.flip[s].q.val();
            self.miss[s].clock.next = self.clock.val();
            self.miss[s].d.next = self.miss[s].q.val();
            self.normal_in[s].clock.next = self.clock.val();
            self.kd_in[s].clock.next = self.clock.val();
            self.res_for[s].clock.next = self.clock.val();
            self.cos_for[s].clock.next = self.clock.val();
            self.byte_for[s].clock.next = self.clock.val();
        }
        for k in 0..3 {
            self.background[k].clock.next = self.clock.val();
            self.background[k].d.next = self.background[k].q.val();
            self.gen_hold_v[k].clock.next = self.clock.val();
            self.gen_hold_v[k].d.next = self.gen_hold_v[k].q.val();
        }
        for k in 0..12 {
            self.gen_hold_m[k].clock.next = self.clock.val();
            self.gen_hold_m[k].d.next = self.gen_hold_m[k].q.val();
        }
        for k in 0..6 {
            self.rays[k].read_clock.next = self.clock.val();
            self.rays[k].write_clock.next = self.clock.val();
            self.rays[k].write_address.next = self.ray_thread.val();
            self.rays[k].write_enable.next = self.ray_write.val();
            self.rays[k].read_address.next = self.query_thread.val();
        }
        for k in 0..3 {
            self.rays[k].write_data.next = self.ray_o[k].val();
            self.rays[3 + k].write_data.next = self.ray_d[k].val();
        }
        clock!(
            self,
            clock,
            tri_line,
            frame_line,
            tri_arrived_r,
            frame_arrived_r,
            sqrt,
            div,
            cos_n_dot_l,
            cos_slot,
            byte_valid_r,
            byte_word_r,
            byte_tag_r,
            byte_unit,
            byte_tag
        );
        // Every slot RAM: written on the clock, read at the dispatched slot.
        for k in 0..3 {
            self.o[k].write_clock.next = self.clock.val();
            self.d[k].write_clock.next = self.clock.val();
            self.n[k].write_clock.next = self.clock.val();
            self.kd[k].write_clock.next = self.clock.val();
            self.p[k].write_clock.next = self.clock.val();
            self.acc[k].write_clock.next = self.clock.val();
            self.to_light[k].write_clock.next = self.clock.val();
            self.tint[k].write_clock.next = self.clock.val();
            self.light_position[k].write_clock.next = self.clock.val();
            self.light_color[k].write_clock.next = self.clock.val();
            self.o[k].read_address.next = self.s1_slot.q.val();
            self.d[k].read_address.next = self.s1_slot.q.val();
            self.n[k].read_address.next = self.s1_slot.q.val();
            self.kd[k].read_address.next = self.s1_slot.q.val();
            self.p[k].read_address.next = self.s1_slot.q.val();
            self.acc[k].read_address.next = self.s1_slot.q.val();
            self.to_light[k].read_address.next = self.s1_slot.q.val();
            self.tint[k].read_address.next = self.s1_slot.q.val();
        }
        self.t.write_clock.next = self.clock.val();
        self.addr.write_clock.next = self.clock.val();
        self.triangle.write_clock.next = self.clock.val();
        self.material.write_clock.next = self.clock.val();
        self.n_dot_l.write_clock.next = self.clock.val();
        self.l_dot_l.write_clock.next = self.clock.val();
        self.cos.write_clock.next = self.clock.val();
        self.rgb.write_clock.next = self.clock.val();
        self.t.read_address.next = self.s1_slot.q.val();
        self.addr.read_address.next = self.s1_slot.q.val();
        self.triangle.read_address.next = self.s1_slot.q.val();
        self.material.read_address.next = self.s1_slot.q.val();
        self.n_dot_l.read_address.next = self.s1_slot.q.val();
        self.l_dot_l.read_address.next = self.s1_slot.q.val();
        self.cos.read_address.next = self.s1_slot.q.val();
        self.rgb.read_address.next = self.s1_slot.q.val();

        // ---- The dispatched slot (S1): its step and operation. ----
        for k in 0..3 {
            self.light_position[k].read_address.next = self.s1_light.q.val();
            self.light_color[k].read_address.next = self.s1_light.q.val();
            self.facing[k].next = self.n[k].read_data.val();
            if self.s1_flip.q.val() {
                self.facing[k].next = self.n[k].read_data.val() ^ self.c_sign.val();
            }
        }
        self.s1_done.next = false;
        // Memory: constants first (no pixel is offered while they load).
        self.const_go.next = self.loading.q.val()
            & (self.const_issued.q.val() != self.c_const_total.val())
            & self.frame_grant.val();
        self.tri_read_l.next = false;
        self.tri_addr.next = (self.triangle.read_data.val() << 3)
            + self.c_shading_word.val()
            + bit_cast::<24, 2>(self.s1_word.q.val());
        self.tri_tag.next = 0.into();
        self.frame_read_l.next =
            self.loading.q.val() & (self.const_issued.q.val() != self.c_const_total.val());
        self.frame_addr_l.next = self.const_addr.q.val();
        self.frame_tag.next = 0.into();
        if self.const_go.val() {
            self.frame_tag.next = (bit_cast::<10, 3>(self.const_word.q.val()) << 7)
                | (bit_cast::<10, 3>(self.const_light.q.val()) << 3)
                | self.c_valid10.val();
            if self.const_lights.q.val() {
                self.frame_tag.next =
                    self.frame_tag.val() | (bit_cast::<10, 2>(self.c_kind_light.val()) << 1);
            } else {
                self.frame_tag.next =
                    self.frame_tag.val() | (bit_cast::<10, 2>(self.c_kind_const.val()) << 1);
            }
            self.const_issued.d.next = self.const_issued.q.val() + 1;
            self.const_addr.d.next = self.const_addr.q.val() + 1;
            self.const_word.d.next = self.const_word.q.val() + 1;
            if (!self.const_lights.q.val()) & (self.const_word.q.val() == 3) {
                self.const_lights.d.next = true;
                self.const_addr.d.next = self.c_lights_addr.val();
                self.const_word.d.next = 0.into();
            }
            if self.const_lights.q.val() & (self.const_word.q.val() == 5) {
                self.const_light.d.next = self.const_light.q.val() + 1;
                self.const_word.d.next = 0.into();
            }
        }
        self.sqrt.in_valid.next = false;
        self.sqrt.a.next = self.l_dot_l.read_data.val();
        self.cos_n_dot_l.data_in.next = self.n_dot_l.read_data.val();
        self.cos_slot.data_in.next = bit_cast::<5, 4>(self.s1_slot.q.val()) << 1;
        self.byte_valid_l.next = false;
        self.byte_word_l.next = self.acc[0].read_data.val();
        self.byte_tag_in.next = (bit_cast::<7, 2>(self.s1_word.q.val()) << 5)
            | (bit_cast::<7, 4>(self.s1_slot.q.val()) << 1);
        self.fb_write_l.next = false;
        self.fb_addr.next = self.addr.read_data.val() + self.c_fb_base.val();
        self.fb_data.next = bit_cast::<32, 24>(self.rgb.read_data.val());
        // The TransformUnit's request of the step (zeros where the pass reads nothing).
        for k in 0..12 {
            self.req_m[k].next = self.c_zero.val();
        }
        for k in 0..3 {
            self.req_v[k].next = self.c_zero.val();
        }
        self.req_point.next = false;
        self.req_diagonal.next = false;
        if self.s1_step.q.val() == ShadeStep::Point {
            // o + t d: diag(d) times (t, t, t) plus o.
            self.req_m[0].next = self.d[0].read_data.val();
            self.req_m[5].next = self.d[1].read_data.val();
            self.req_m[10].next = self.d[2].read_data.val();
            self.req_m[3].next = self.o[0].read_data.val();
            self.req_m[7].next = self.o[1].read_data.val();
            self.req_m[11].next = self.o[2].read_data.val();
            for k in 0..3 {
                self.req_v[k].next = self.t.read_data.val();
            }
            self.req_point.next = true;
            self.req_diagonal.next = true;
        }
        if self.s1_step.q.val() == ShadeStep::NormalDot {
            // n . d: row 0 is the stored normal.
            for k in 0..3 {
                self.req_m[k].next = self.n[k].read_data.val();
                self.req_v[k].next = self.d[k].read_data.val();
            }
        }
        if self.s1_step.q.val() == ShadeStep::Ambient {
            self.req_m[0].next = self.kd[0].read_data.val();
            self.req_m[5].next = self.kd[1].read_data.val();
            self.req_m[10].next = self.kd[2].read_data.val();
            for k in 0..3 {
                self.req_v[k].next = self.ambient.q.val();
            }
            self.req_diagonal.next = true;
        }
        if self.s1_step.q.val() == ShadeStep::ToLight {
            // light - p: diag(-1) times p plus the light.
            self.req_m[0].next = self.c_minus_one.val();
            self.req_m[5].next = self.c_minus_one.val();
            self.req_m[10].next = self.c_minus_one.val();
            self.req_m[3].next = self.light_position[0].read_data.val();
            self.req_m[7].next = self.light_position[1].read_data.val();
            self.req_m[11].next = self.light_position[2].read_data.val();
            for k in 0..3 {
                self.req_v[k].next = self.p[k].read_data.val();
            }
            self.req_point.next = true;
            self.req_diagonal.next = true;
        }
        if self.s1_step.q.val() == ShadeStep::Dots {
            // Row 0 the facing normal, row 1 L, times L.
            for k in 0..3 {
                self.req_m[k].next = self.facing[k].val();
                self.req_m[4 + k].next = self.to_light[k].read_data.val();
                self.req_v[k].next = self.to_light[k].read_data.val();
            }
        }
        if self.s1_step.q.val() == ShadeStep::Tint {
            self.req_m[0].next = self.kd[0].read_data.val();
            self.req_m[5].next = self.kd[1].read_data.val();
            self.req_m[10].next = self.kd[2].read_data.val();
            for k in 0..3 {
                self.req_v[k].next = self.light_color[k].read_data.val();
            }
            self.req_diagonal.next = true;
        }
        if self.s1_step.q.val() == ShadeStep::Accumulate {
            // acc + tint cos: diag(tint) times (cos, cos, cos) plus acc.
            self.req_m[0].next = self.tint[0].read_data.val();
            self.req_m[5].next = self.tint[1].read_data.val();
            self.req_m[10].next = self.tint[2].read_data.val();
            self.req_m[3].next = self.acc[0].read_data.val();
            self.req_m[7].next = self.acc[1].read_data.val();
            self.req_m[11].next = self.acc[2].read_data.val();
            for k in 0..3 {
                self.req_v[k].next = self.cos.read_data.val();
            }
            self.req_point.next = true;
            self.req_diagonal.next = true;
        }
        // The held request leaves when taken; the dispatched one waits for the next clock (not
        // loaded in the clock of a take: the take comes from the tester's launch logic, and
        // waiting for it here put the whole dispatch behind it, 65 MHz placed).
        if self.gen_take.val() {
            self.gen_held.d.next = false;
        }
        self.gen_load.next =
            self.s1_valid.q.val() & self.s1_transform.q.val() & (!self.gen_held.q.val());
        if self.gen_load.val() {
            self.gen_held.d.next = true;
            for k in 0..12 {
                self.gen_hold_m[k].d.next = self.req_m[k].val();
            }
            for k in 0..3 {
                self.gen_hold_v[k].d.next = self.req_v[k].val();
            }
            self.gen_hold_point.d.next = self.req_point.val();
            self.gen_hold_diagonal.d.next = self.req_diagonal.val();
            self.gen_hold_slot.d.next = self.s1_slot.q.val();
            self.s1_done.next = true;
        }
        self.gen_valid.next = self.gen_held.q.val();
        for k in 0..12 {
            self.gen_m[k].next = self.gen_hold_m[k].q.val();
        }
        for k in 0..3 {
            self.gen_v[k].next = self.gen_hold_v[k].q.val();
        }
        self.gen_point.next = self.gen_hold_point.q.val();
        self.gen_diagonal.next = self.gen_hold_diagonal.q.val();
        self.gen_slot.next = self.gen_hold_slot.q.val();
        // The other operations go out from S1; a memory step is done in the clock after its
        // last grant, and requests nothing in it.
        self.s1_granted.d.next = false;
        self.stored_r.d.next = false;
        if self.s1_granted.q.val() {
            self.s1_done.next = true;
        }
        if self.s1_valid.q.val() & (!self.s1_granted.q.val()) {
            if self.s1_tri_load.q.val() {
                self.tri_read_l.next = true;
                if self.tri_grant.val() {
                    self.tri_tag.next = (bit_cast::<10, 2>(self.s1_word.q.val()) << 7)
                        | (bit_cast::<10, 4>(self.s1_slot.q.val()) << 3)
                        | (bit_cast::<10, 2>(self.c_kind_tri.val()) << 1)
                        | self.c_valid10.val();
                    self.s1_word.d.next = self.s1_word.q.val() + 1;
                    if self.s1_word.q.val() == 1 {
                        self.s1_granted.d.next = true;
                    }
                }
            }
            if self.s1_kd_load.q.val() & (!self.loading.q.val()) {
                self.frame_read_l.next = true;
                self.frame_addr_l.next = (self.material.read_data.val() << 2)
                    + self.c_materials.val()
                    + bit_cast::<24, 2>(self.s1_word.q.val());
                if self.frame_grant.val() {
                    self.frame_tag.next = (bit_cast::<10, 2>(self.s1_word.q.val()) << 7)
                        | (bit_cast::<10, 4>(self.s1_slot.q.val()) << 3)
                        | (bit_cast::<10, 2>(self.c_kind_kd.val()) << 1)
                        | self.c_valid10.val();
                    self.s1_word.d.next = self.s1_word.q.val() + 1;
                    if self.s1_word.q.val() == 2 {
                        self.s1_granted.d.next = true;
                    }
                }
            }
        }
        if self.s1_valid.q.val() {
            if self.s1_cosine.q.val() {
                self.sqrt.in_valid.next = true;
                self.cos_slot.data_in.next =
                    (bit_cast::<5, 4>(self.s1_slot.q.val()) << 1) | self.c_valid5.val();
                self.s1_done.next = true;
            }
            if self.s1_pack.q.val() {
                self.byte_valid_l.next = true;
                self.byte_tag_in.next = self.byte_tag_in.val() | self.c_valid7.val();
                self.s1_word.d.next = self.s1_word.q.val() + 1;
                if self.s1_word.q.val() == 2 {
                    self.s1_done.next = true;
                }
            }
            if self.s1_store.q.val() & (!self.s1_granted.q.val()) {
                self.fb_write_l.next = true;
                if self.fb_grant.val() {
                    self.s1_granted.d.next = true;
                    self.stored_r.d.next = true;
                }
            }
        }
        // The channel's word: the colour, or the background for a miss.
        if self.s1_word.q.val() == 1 {
            self.byte_word_l.next = self.acc[1].read_data.val();
        }
        if self.s1_word.q.val() == 2 {
            self.byte_word_l.next = self.acc[2].read_data.val();
        }
        if self.s1_miss.q.val() {
            self.byte_word_l.next = self.background[0].q.val();
            if self.s1_word.q.val() == 1 {
                self.byte_word_l.next = self.background[1].q.val();
            }
            if self.s1_word.q.val() == 2 {
                self.byte_word_l.next = self.background[2].q.val();
            }
        }
        if self.s1_done.val() {
            self.s1_word.d.next = 0.into();
        }
        self.byte_valid_r.d.next = self.byte_valid_l.val();
        self.byte_word_r.d.next = self.byte_word_l.val();
        self.byte_tag_r.d.next = self.byte_tag_in.val();
        self.byte_unit.in_valid.next = self.byte_valid_r.q.val();
        self.byte_unit.word.next = self.byte_word_r.q.val();
        self.byte_tag.data_in.next = self.byte_tag_r.q.val();
        // Each output is written once, from its local: an output assigned a default and then
        // overridden changes twice in one evaluation, and Icarus wakes the engine's block on
        // each change (such double writes in `Delay` made Icarus loop; see delay.rs).
        self.tri_read.next = self.tri_read_l.val();
        self.frame_read.next = self.frame_read_l.val();
        self.frame_addr.next = self.frame_addr_l.val();
        self.fb_write.next = self.fb_write_l.val();

        // ---- S0: the next slot, picked when S0 is empty. ----
        self.any_ready_before[0].next = false;
        self.ready_slot.next = 0.into();
        for s in 0..SHADE_SLOTS {
            self.any_ready_before[s + 1].next =
                self.any_ready_before[s].val() | (self.ready[s].q.val() & self.busy[s].q.val());
        }
        for s in 0..SHADE_SLOTS {
            if self.ready[s].q.val() & self.busy[s].q.val() & (!self.any_ready_before[s].val()) {
                self.ready_slot.next = self.c_slot[s].val();
            }
        }
        self.pick.next = self.any_ready_before[16].val() & (!self.s0_valid.q.val());
        self.pick_step.next = ShadeStep::Idle;
        self.pick_light.next = 0.into();
        self.pick_flip.next = false;
        self.pick_miss.next = false;
        for s in 0..SHADE_SLOTS {
            if self.ready_slot.val() == self.c_slot[s].val() {
                self.pick_step.next = self.step[s].q.val();
                self.pick_light.next = self.light[s].q.val();
                self.pick_flip.next = self.flip[s].q.val();
                self.pick_miss.next = self.miss[s].q.val();
            }
        }
        if self.pick.val() {
            self.s0_valid.d.next = true;
            self.s0_slot.d.next = self.ready_slot.val();
            self.s0_step.d.next = self.pick_step.val();
            self.s0_light.d.next = self.pick_light.val();
            self.s0_flip.d.next = self.pick_flip.val();
            self.s0_miss.d.next = self.pick_miss.val();
        }
        // S1 takes S0's slot when its own operation has gone out (S0 is emptied only if full:
        // an empty S0 may be filled by the pick in this clock).
        self.s1_load.next = (!self.s1_valid.q.val()) | self.s1_done.val();
        if self.s1_load.val() {
            if self.s0_valid.q.val() {
                self.s0_valid.d.next = false;
            }
            self.s1_valid.d.next = self.s0_valid.q.val();
            self.s1_slot.d.next = self.s0_slot.q.val();
            self.s1_step.d.next = self.s0_step.q.val();
            self.s1_light.d.next = self.s0_light.q.val();
            self.s1_flip.d.next = self.s0_flip.q.val();
            self.s1_miss.d.next = self.s0_miss.q.val();
            // Decoded from S0's register, not after the pick's mux.
            self.s1_transform.d.next = (self.s0_step.q.val() == ShadeStep::Point)
                | (self.s0_step.q.val() == ShadeStep::NormalDot)
                | (self.s0_step.q.val() == ShadeStep::Ambient)
                | (self.s0_step.q.val() == ShadeStep::ToLight)
                | (self.s0_step.q.val() == ShadeStep::Dots)
                | (self.s0_step.q.val() == ShadeStep::Tint)
                | (self.s0_step.q.val() == ShadeStep::Accumulate);
            self.s1_tri_load.d.next = self.s0_step.q.val() == ShadeStep::TriLoad;
            self.s1_kd_load.d.next = self.s0_step.q.val() == ShadeStep::KdLoad;
            self.s1_cosine.d.next = self.s0_step.q.val() == ShadeStep::Cosine;
            self.s1_pack.d.next = self.s0_step.q.val() == ShadeStep::Pack;
            self.s1_store.d.next = self.s0_step.q.val() == ShadeStep::Store;
        }

        // ---- Offers take the first free slot. ----
        self.refused.next = self.loading.q.val() | (!self.has_free_r.q.val());
        self.taken.next = self.offer.val() & (!self.refused.val());
        self.free_slot_r.clock.next = self.clock.val();
        self.has_free_r.clock.next = self.clock.val();
        // Two priority chains, the free slots with and without the one an offer takes now, so
        // that the offer (late: the engine's I5) only picks between their results.
        self.take_r.d.next = self.taken.val();
        self.take_slot_r.d.next = self.free_slot_r.q.val();
        self.take_hit_r.d.next = self.offer_hit.val();
        for s in 0..SHADE_SLOTS {
            self.occupied[s].next = self.busy[s].q.val()
                | (self.take_r.q.val() & (self.take_slot_r.q.val() == self.c_slot[s].val()));
        }
        self.any_free_before[0].next = false;
        self.any_free_after_take[0].next = false;
        for s in 0..SHADE_SLOTS {
            self.any_free_before[s + 1].next =
                self.any_free_before[s].val() | (!self.occupied[s].val());
            self.any_free_after_take[s + 1].next = self.any_free_after_take[s].val()
                | ((!self.occupied[s].val()) & (self.free_slot_r.q.val() != self.c_slot[s].val()));
        }
        self.free_slot_r.d.next = 0.into();
        self.has_free_r.d.next = self.any_free_before[16].val();
        if self.taken.val() {
            self.has_free_r.d.next = self.any_free_after_take[16].val();
        }
        for s in 0..SHADE_SLOTS {
            if self.taken.val() {
                if (!self.occupied[s].val())
                    & (self.free_slot_r.q.val() != self.c_slot[s].val())
                    & (!self.any_free_after_take[s].val())
                {
                    self.free_slot_r.d.next = self.c_slot[s].val();
                }
            } else if (!self.occupied[s].val()) & (!self.any_free_before[s].val()) {
                self.free_slot_r.d.next = self.c_slot[s].val();
            }
        }
        for k in 0..3 {
            self.o[k].write_address.next = self.free_slot_r.q.val();
            self.o[k].write_enable.next = self.taken.val();
            self.o[k].write_data.next = self.rays[k].read_data.val();
            self.d[k].write_address.next = self.free_slot_r.q.val();
            self.d[k].write_enable.next = self.taken.val();
            self.d[k].write_data.next = self.rays[3 + k].read_data.val();
        }
        self.t.write_address.next = self.free_slot_r.q.val();
        self.t.write_enable.next = self.taken.val();
        self.t.write_data.next = self.offer_t.val();
        self.addr.write_address.next = self.free_slot_r.q.val();
        self.addr.write_enable.next = self.taken.val();
        self.addr.write_data.next = self.offer_addr.val();
        self.triangle.write_address.next = self.free_slot_r.q.val();
        self.triangle.write_enable.next = self.taken.val();
        self.triangle.write_data.next = self.offer_triangle.val();

        // ---- Memory words arriving. ----
        self.tri_line.data_in.next = self.tri_tag.val();
        self.frame_line.data_in.next = self.frame_tag.val();
        self.tri_arrived_r.d.next = self.tri_line.data_out.val();
        self.frame_arrived_r.d.next = self.frame_line.data_out.val();
        self.tri_arrived.next = self.tri_arrived_r.q.val();
        self.frame_arrived.next = self.frame_arrived_r.q.val();
        for s in 0..SHADE_SLOTS {
            self.normal_in[s].d.next = self.tri_line.data_out.val().get_bit(0)
                & self.tri_line.data_out.val().get_bit(7)
                & (self.tri_line.data_out.val().get_bits::<4>(3) == self.c_slot[s].val());
            self.kd_in[s].d.next = self.frame_line.data_out.val().get_bit(0)
                & (self.frame_line.data_out.val().get_bits::<2>(1) == self.c_kind_kd.val())
                & (self.frame_line.data_out.val().get_bits::<3>(7) == 2)
                & (self.frame_line.data_out.val().get_bits::<4>(3) == self.c_slot[s].val());
        }
        // Word 0 (the sixth of the triangle's record in each bank): normal x and z; word 1:
        // normal y and the material.
        for k in 0..3 {
            self.n[k].write_address.next = self.tri_arrived.val().get_bits::<4>(3);
        }
        self.n[0].write_data.next = self.tri_rdata_a.val().get_bits::<W>(0);
        self.n[1].write_data.next = self.tri_rdata_a.val().get_bits::<W>(0);
        self.n[2].write_data.next = self.tri_rdata_b.val().get_bits::<W>(0);
        self.material.write_address.next = self.tri_arrived.val().get_bits::<4>(3);
        self.material.write_data.next = self.tri_rdata_b.val().get_bits::<24>(0);
        self.tri_word_0.next =
            self.tri_arrived.val().get_bit(0) & (!self.tri_arrived.val().get_bit(7));
        self.tri_word_1.next =
            self.tri_arrived.val().get_bit(0) & self.tri_arrived.val().get_bit(7);
        self.n[0].write_enable.next = self.tri_word_0.val();
        self.n[2].write_enable.next = self.tri_word_0.val();
        self.n[1].write_enable.next = self.tri_word_1.val();
        self.material.write_enable.next = self.tri_word_1.val();
        // Frame words: the diffuse colour, a light's word, the ambient or a background word.
        self.frame_valid.next = self.frame_arrived.val().get_bit(0);
        self.frame_kind.next = self.frame_arrived.val().get_bits::<2>(1);
        self.frame_word.next = self.frame_arrived.val().get_bits::<3>(7);
        for k in 0..3 {
            self.kd[k].write_address.next = self.frame_arrived.val().get_bits::<4>(3);
            self.kd[k].write_data.next = self.frame_rdata.val().get_bits::<W>(0);
            self.kd[k].write_enable.next = false;
            self.light_position[k].write_address.next = self.frame_arrived.val().get_bits::<3>(3);
            self.light_position[k].write_data.next = self.frame_rdata.val().get_bits::<W>(0);
            self.light_position[k].write_enable.next = false;
            self.light_color[k].write_address.next = self.frame_arrived.val().get_bits::<3>(3);
            self.light_color[k].write_data.next = self.frame_rdata.val().get_bits::<W>(0);
            self.light_color[k].write_enable.next = false;
        }
        if self.frame_valid.val() & (self.frame_kind.val() == self.c_kind_kd.val()) {
            if self.frame_word.val() == 0 {
                self.kd[0].write_enable.next = true;
            }
            if self.frame_word.val() == 1 {
                self.kd[1].write_enable.next = true;
            }
            if self.frame_word.val() == 2 {
                self.kd[2].write_enable.next = true;
            }
        }
        if self.frame_valid.val() & (self.frame_kind.val() == self.c_kind_light.val()) {
            if self.frame_word.val() == 0 {
                self.light_position[0].write_enable.next = true;
            }
            if self.frame_word.val() == 1 {
                self.light_position[1].write_enable.next = true;
            }
            if self.frame_word.val() == 2 {
                self.light_position[2].write_enable.next = true;
            }
            if self.frame_word.val() == 3 {
                self.light_color[0].write_enable.next = true;
            }
            if self.frame_word.val() == 4 {
                self.light_color[1].write_enable.next = true;
            }
            if self.frame_word.val() == 5 {
                self.light_color[2].write_enable.next = true;
            }
        }
        if self.frame_valid.val() & (self.frame_kind.val() == self.c_kind_const.val()) {
            if self.frame_word.val() == 0 {
                self.ambient.d.next = self.frame_rdata.val().get_bits::<W>(0);
            }
            if self.frame_word.val() == 1 {
                self.background[0].d.next = self.frame_rdata.val().get_bits::<W>(0);
            }
            if self.frame_word.val() == 2 {
                self.background[1].d.next = self.frame_rdata.val().get_bits::<W>(0);
            }
            if self.frame_word.val() == 3 {
                self.background[2].d.next = self.frame_rdata.val().get_bits::<W>(0);
            }
        }
        if self.frame_valid.val()
            & ((self.frame_kind.val() == self.c_kind_light.val())
                | (self.frame_kind.val() == self.c_kind_const.val()))
        {
            self.const_arrived.d.next = self.const_arrived.q.val() + 1;
            if self.const_arrived.q.val() + 1 == self.c_const_total.val() {
                self.loading.d.next = false;
            }
        }

        // ---- TransformUnit results, by the step of their slot. ----
        self.res_valid_r.clock.next = self.clock.val();
        self.res_valid_r.d.next = self.res_valid.val();
        self.res_slot_r.clock.next = self.clock.val();
        self.res_slot_r.d.next = self.res_slot.val();
        for k in 0..3 {
            self.res_v_r[k].clock.next = self.clock.val();
            self.res_v_r[k].d.next = self.res_v[k].val();
        }
        self.res_step_r.clock.next = self.clock.val();
        self.res_light_r.clock.next = self.clock.val();
        self.res_step_r.d.next = ShadeStep::Idle;
        self.res_light_r.d.next = 0.into();
        for s in 0..SHADE_SLOTS {
            if self.res_slot.val() == self.c_slot[s].val() {
                self.res_step_r.d.next = self.step[s].q.val();
                self.res_light_r.d.next = self.light[s].q.val();
            }
        }
        // 0 < res_v[0]: positive, not zero (nor subnormal, read as zero), not NaN.
        self.res_positive.clock.next = self.clock.val();
        self.res_positive.d.next = (!(self.res_v[0].val() & self.c_sign.val()).any())
            & (self.res_v[0].val() & self.c_exp_mask.val()).any()
            & (!(((self.res_v[0].val() & self.c_exp_mask.val()) == self.c_exp_mask.val())
                & (self.res_v[0].val() & self.c_man_mask.val()).any()));
        for s in 0..SHADE_SLOTS {
            self.res_for[s].d.next =
                self.res_valid.val() & (self.res_slot.val() == self.c_slot[s].val());
        }
        // Where a result moves its slot: a slot waits for one result at a time, so this is
        // decided once, from the registered step, light and sign.
        self.res_next_step.next = self.res_step_r.q.val();
        self.res_next_light.next = self.res_light_r.q.val();
        if self.res_step_r.q.val() == ShadeStep::Point {
            self.res_next_step.next = ShadeStep::NormalDot;
        }
        if self.res_step_r.q.val() == ShadeStep::NormalDot {
            self.res_next_step.next = ShadeStep::KdLoad;
        }
        if self.res_step_r.q.val() == ShadeStep::Ambient {
            self.res_next_step.next = ShadeStep::Pack;
            if self.c_has_lights.val() {
                self.res_next_step.next = ShadeStep::ToLight;
            }
        }
        if self.res_step_r.q.val() == ShadeStep::ToLight {
            self.res_next_step.next = ShadeStep::Dots;
        }
        if self.res_step_r.q.val() == ShadeStep::Tint {
            self.res_next_step.next = ShadeStep::Accumulate;
        }
        // The light is done (lit and added, or behind the surface): the next one.
        if (self.res_step_r.q.val() == ShadeStep::Accumulate)
            | ((self.res_step_r.q.val() == ShadeStep::Dots) & (!self.res_positive.q.val()))
        {
            self.res_next_step.next = ShadeStep::ToLight;
            self.res_next_light.next = self.res_light_r.q.val() + 1;
            if self.res_light_r.q.val() == self.c_last_light.val() {
                self.res_next_step.next = ShadeStep::Pack;
            }
        }
        if (self.res_step_r.q.val() == ShadeStep::Dots) & self.res_positive.q.val() {
            self.res_next_step.next = ShadeStep::Cosine;
        }
        for k in 0..3 {
            self.p[k].write_address.next = self.res_slot_r.q.val();
            self.p[k].write_data.next = self.res_v_r[k].q.val();
            self.p[k].write_enable.next =
                self.res_valid_r.q.val() & (self.res_step_r.q.val() == ShadeStep::Point);
            self.acc[k].write_address.next = self.res_slot_r.q.val();
            self.acc[k].write_data.next = self.res_v_r[k].q.val();
            self.acc[k].write_enable.next = self.res_valid_r.q.val()
                & ((self.res_step_r.q.val() == ShadeStep::Ambient)
                    | (self.res_step_r.q.val() == ShadeStep::Accumulate));
            self.to_light[k].write_address.next = self.res_slot_r.q.val();
            self.to_light[k].write_data.next = self.res_v_r[k].q.val();
            self.to_light[k].write_enable.next =
                self.res_valid_r.q.val() & (self.res_step_r.q.val() == ShadeStep::ToLight);
            self.tint[k].write_address.next = self.res_slot_r.q.val();
            self.tint[k].write_data.next = self.res_v_r[k].q.val();
            self.tint[k].write_enable.next =
                self.res_valid_r.q.val() & (self.res_step_r.q.val() == ShadeStep::Tint);
        }
        self.n_dot_l.write_address.next = self.res_slot_r.q.val();
        self.n_dot_l.write_data.next = self.res_v_r[0].q.val();
        self.n_dot_l.write_enable.next =
            self.res_valid_r.q.val() & (self.res_step_r.q.val() == ShadeStep::Dots);
        self.l_dot_l.write_address.next = self.res_slot_r.q.val();
        self.l_dot_l.write_data.next = self.res_v_r[1].q.val();
        self.l_dot_l.write_enable.next =
            self.res_valid_r.q.val() & (self.res_step_r.q.val() == ShadeStep::Dots);

        // ---- The cosine: sqrt(L . L), then n . L over it. ----
        self.div.in_valid.next = self.sqrt.out_valid.val();
        self.div.a.next = self.cos_n_dot_l.data_out.val();
        self.div.b.next = self.sqrt.result.val();
        self.cos.write_address.next = self.cos_slot.data_out.val().get_bits::<4>(1);
        self.cos.write_data.next = self.div.result.val();
        self.cos.write_enable.next = self.cos_slot.data_out.val().get_bit(0);

        // ---- The bytes: shifted in, the third writes the pixel's word. ----
        self.rgb.write_address.next = self.byte_tag.data_out.val().get_bits::<4>(1);
        self.rgb_next.next =
            (self.rgb_acc.q.val() << 8) | bit_cast::<24, 8>(self.byte_unit.result.val());
        self.rgb.write_data.next = self.rgb_next.val();
        self.rgb.write_enable.next = false;
        if self.byte_tag.data_out.val().get_bit(0) {
            self.rgb_acc.d.next = self.rgb_next.val();
            if self.byte_tag.data_out.val().get_bits::<2>(5) == 2 {
                self.rgb.write_enable.next = true;
            }
        }

        // ---- Each slot's control. ----
        self.stored_slot_r.d.next = self.s1_slot.q.val();
        for s in 0..SHADE_SLOTS {
            // An offer, taken last clock.
            if self.take_r.q.val() & (self.take_slot_r.q.val() == self.c_slot[s].val()) {
                self.busy[s].d.next = true;
                self.ready[s].d.next = true;
                self.miss[s].d.next = !self.take_hit_r.q.val();
                self.flip[s].d.next = false;
                self.light[s].d.next = 0.into();
                self.step[s].d.next = ShadeStep::TriLoad;
                if !self.take_hit_r.q.val() {
                    self.step[s].d.next = ShadeStep::Pack;
                }
            }
            // Dispatched: not ready until its operation's result is in.
            if self.pick.val() & (self.ready_slot.val() == self.c_slot[s].val()) {
                self.ready[s].d.next = false;
            }
            // The store went out last clock: the slot is free.
            if self.stored_r.q.val() & (self.stored_slot_r.q.val() == self.c_slot[s].val()) {
                self.busy[s].d.next = false;
                self.step[s].d.next = ShadeStep::Idle;
            }
            // The normal's second word.
            if self.normal_in[s].q.val() {
                self.ready[s].d.next = true;
                self.step[s].d.next = ShadeStep::Point;
            }
            // The diffuse colour's third word.
            if self.kd_in[s].q.val() {
                self.ready[s].d.next = true;
                self.step[s].d.next = ShadeStep::Ambient;
            }
            self.cos_for[s].d.next = self.cos_slot.data_out.val().get_bit(0)
                & (self.cos_slot.data_out.val().get_bits::<4>(1) == self.c_slot[s].val());
            self.byte_for[s].d.next = self.byte_tag.data_out.val().get_bit(0)
                & (self.byte_tag.data_out.val().get_bits::<2>(5) == 2)
                & (self.byte_tag.data_out.val().get_bits::<4>(1) == self.c_slot[s].val());
            // The cosine.
            if self.cos_for[s].q.val() {
                self.ready[s].d.next = true;
                self.step[s].d.next = ShadeStep::Tint;
            }
            // The third byte.
            if self.byte_for[s].q.val() {
                self.ready[s].d.next = true;
                self.step[s].d.next = ShadeStep::Store;
            }
            // A TransformUnit result (last: its step is the latest to settle, and a slot
            // has one event at a time, so the order of these is free).
            if self.res_for[s].q.val() {
                self.ready[s].d.next = true;
                self.step[s].d.next = self.res_next_step.val();
                self.light[s].d.next = self.res_next_light.val();
                if self.res_step_r.q.val() == ShadeStep::NormalDot {
                    self.flip[s].d.next = self.res_positive.q.val();
                }
            }
        }

        // ---- A new frame reads the constants again. ----
        if self.frame_start.val() {
            self.loading.d.next = true;
            self.const_issued.d.next = 0.into();
            self.const_arrived.d.next = 0.into();
            self.const_addr.d.next = self.c_const_addr.val();
            self.const_lights.d.next = false;
            self.const_light.d.next = 0.into();
            self.const_word.d.next = 0.into();
        }
        self.any_busy.next = false;
        for s in 0..SHADE_SLOTS {
            self.any_busy.next = self.any_busy.val() | self.busy[s].q.val();
        }
        self.idle.next = (!self.loading.q.val()) & (!self.any_busy.val()) & (!self.take_r.q.val());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fp::Format;
    use crate::hw::sim_harness::{clock_cycle, settle};
    use crate::hw::{TransformUnit, TAG_BITS};
    use crate::units::{self, LightWords, ShadingConstants, SurfaceHit};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::{BTreeMap, VecDeque};

    type Unit = ShadeUnit<24, 7, 16, 17, 18, 9, 21, 34>;

    /// The unit with a TransformUnit on its client port, which takes a held request in a clock
    /// with `tu_free` (the tester's launches keep it busy in the others).
    #[derive(LogicBlock)]
    struct Bench {
        clock: Signal<In, Clock>,
        tu_free: Signal<In, Bit>,
        unit: Unit,
        tu: TransformUnit<24, 7, 16, 17, 18, 9, 21, 34>,
    }

    impl Logic for Bench {
        #[hdl_gen]
        fn update(&mut self) {
            self.unit.clock.next = self.clock.val();
            self.tu.clock.next = self.clock.val();
            self.unit.gen_take.next = self.unit.gen_valid.val() & self.tu_free.val();
            self.tu.in_valid.next = self.unit.gen_valid.val() & self.tu_free.val();
            for k in 0..12 {
                self.tu.m[k].next = self.unit.gen_m[k].val();
            }
            for k in 0..3 {
                self.tu.v[k].next = self.unit.gen_v[k].val();
                self.unit.res_v[k].next = self.tu.result[k].val();
            }
            self.tu.point.next = self.unit.gen_point.val();
            self.tu.diagonal.next = self.unit.gen_diagonal.val();
            self.tu.tag.next = bit_cast::<TAG_BITS, 4>(self.unit.gen_slot.val());
            self.unit.res_valid.next = self.tu.out_valid.val();
            self.unit.res_slot.next = self.tu.out_tag.val().get_bits::<4>(0);
        }
    }

    const MATERIALS: u32 = 200;
    const FRAME_BUFFER: u32 = 1000;
    const TRIANGLES: usize = 64;

    /// rust-hdl simulation: a frame's constants, then 120 pixels (hits and misses) offered by
    /// 32 threads as fast as the unit takes them, its memory and frame-buffer ports and the
    /// TransformUnit granted at random, so that all [`SHADE_SLOTS`] slots fill; every pixel is
    /// written once, equal to `units::shade_direct` of its hit (the golden model's shading).
    fn shade_pixels(lights: u32, seed: u64) {
        let f = Format::E7M16;
        let (tri_latency, frame_latency) = (3, 2);
        println!("seed {seed}, {lights} lights");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let w = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| f.from_f64(rng.gen_range(lo..hi));
        // Bank 5: constants, lights, materials.
        let mut frame = vec![0u32; 2048];
        let constants = ShadingConstants {
            ambient: w(&mut rng, 0.05, 0.3),
            background: [
                w(&mut rng, 0.0, 1.0),
                w(&mut rng, 0.0, 1.0),
                w(&mut rng, 0.0, 1.0),
            ],
            lights: (0..lights)
                .map(|_| LightWords {
                    position: [
                        w(&mut rng, -3.0, 3.0),
                        w(&mut rng, -3.0, 3.0),
                        w(&mut rng, -3.0, 3.0),
                    ],
                    color: [
                        w(&mut rng, 0.0, 1.0),
                        w(&mut rng, 0.0, 1.0),
                        w(&mut rng, 0.0, 1.0),
                    ],
                })
                .collect(),
        };
        frame[FrameMap::AMBIENT] = constants.ambient;
        frame[FrameMap::BACKGROUND..FrameMap::BACKGROUND + 3]
            .copy_from_slice(&constants.background);
        for (k, l) in constants.lights.iter().enumerate() {
            let at = FrameMap::LIGHTS + 6 * k;
            frame[at..at + 3].copy_from_slice(&l.position);
            frame[at + 3..at + 6].copy_from_slice(&l.color);
        }
        let materials = 5;
        for m in 0..materials {
            for k in 0..3 {
                frame[MATERIALS as usize + 4 * m + k] = w(&mut rng, 0.0, 1.0);
            }
        }
        // Banks 2 and 3: each triangle's normal (x, y | z) and material at words 6, 7.
        let (mut bank_a, mut bank_b) = (vec![0u32; 8 * TRIANGLES], vec![0u32; 8 * TRIANGLES]);
        for t in 0..TRIANGLES {
            let n = glam::DVec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
            .normalize();
            bank_a[8 * t + 6] = f.from_f64(n.x);
            bank_a[8 * t + 7] = f.from_f64(n.y);
            bank_b[8 * t + 6] = f.from_f64(n.z);
            bank_b[8 * t + 7] = rng.gen_range(0..materials as u32);
        }
        // The pixels: thread, ray, hit.
        struct Job {
            thread: u32,
            o: [u32; 3],
            d: [u32; 3],
            hit: bool,
            t: u32,
            triangle: u32,
        }
        let jobs: Vec<Job> = (0..120)
            .map(|_| Job {
                thread: rng.gen_range(0..32),
                o: [
                    w(&mut rng, -1.0, 1.0),
                    w(&mut rng, -1.0, 1.0),
                    w(&mut rng, -5.0, -4.0),
                ],
                d: [
                    w(&mut rng, -0.5, 0.5),
                    w(&mut rng, -0.5, 0.5),
                    w(&mut rng, 0.5, 1.0),
                ],
                hit: rng.gen_ratio(5, 6),
                t: w(&mut rng, 2.0, 6.0),
                triangle: rng.gen_range(0..TRIANGLES as u32),
            })
            .collect();
        let expect: Vec<u32> = jobs
            .iter()
            .map(|j| {
                let t = j.triangle as usize;
                let material = bank_b[8 * t + 7] as usize;
                let hit = SurfaceHit {
                    o: j.o,
                    d: j.d,
                    t: j.t,
                    n: [bank_a[8 * t + 6], bank_a[8 * t + 7], bank_b[8 * t + 6]],
                    kd: std::array::from_fn(|k| frame[MATERIALS as usize + 4 * material + k]),
                };
                units::shade_direct(f, &constants, j.hit.then_some(&hit))
            })
            .collect();

        let mut b = Bench {
            clock: Default::default(),
            tu_free: Default::default(),
            unit: Unit::new(ShadeConfig {
                tri_latency,
                frame_latency,
                lights,
                materials: MATERIALS,
                frame_buffer: FRAME_BUFFER,
            }),
            tu: Default::default(),
        };
        b.connect_all();
        let mut tri_reads: VecDeque<Option<u32>> = VecDeque::new();
        let mut frame_reads: VecDeque<Option<u32>> = VecDeque::new();
        let mut written: BTreeMap<u32, u32> = BTreeMap::new();
        // The job being offered: its ray is written (phase 0), its thread asked for at I4 (1),
        // then it is offered (2).
        let (mut next_job, mut phase) = (0usize, 0);
        let mut cycles = 0;
        let mut refused_while_loading = 0;
        let mut refused_full = 0;
        loop {
            cycles += 1;
            assert!(
                cycles < 40_000,
                "the unit stalls: {} of {} pixels",
                written.len(),
                jobs.len()
            );
            let u = &mut b.unit;
            u.frame_start.next = cycles == 1;
            // Words requested the latency's clocks ago.
            let word = |q: &VecDeque<Option<u32>>, latency: u32, bank: &[u32]| {
                q.get(q.len().wrapping_sub(latency as usize))
                    .copied()
                    .flatten()
                    .map_or(0, |a| bank[a as usize])
            };
            u.tri_rdata_a.next = (word(&tri_reads, tri_latency, &bank_a) as u64).into();
            u.tri_rdata_b.next = (word(&tri_reads, tri_latency, &bank_b) as u64).into();
            u.frame_rdata.next = (word(&frame_reads, frame_latency, &frame) as u64).into();
            u.tri_grant.next = rng.gen_ratio(3, 4);
            u.frame_grant.next = rng.gen_ratio(3, 4);
            u.fb_grant.next = rng.gen_ratio(3, 4);
            b.tu_free.next = rng.gen_ratio(2, 3);
            let u = &mut b.unit;
            u.ray_write.next = false;
            u.offer.next = false;
            if let Some(j) = jobs.get(next_job) {
                if phase == 0 {
                    u.ray_write.next = true;
                    u.ray_thread.next = (j.thread as u64).into();
                    for k in 0..3 {
                        u.ray_o[k].next = (j.o[k] as u64).into();
                        u.ray_d[k].next = (j.d[k] as u64).into();
                    }
                    phase = 1;
                } else if phase == 1 {
                    // The engine's I4: the ray store is read for the offer's clock.
                    u.query_thread.next = (j.thread as u64).into();
                    phase = 2;
                } else {
                    u.offer.next = true;
                    u.offer_addr.next = (next_job as u64).into();
                    u.offer_hit.next = j.hit;
                    u.offer_t.next = (j.t as u64).into();
                    u.offer_triangle.next = (j.triangle as u64).into();
                }
            }
            b.clock.next = Clock { clk: false };
            settle(&mut b);
            let u = &b.unit;
            tri_reads.push_back(
                (u.tri_read.val() && u.tri_grant.val()).then(|| u.tri_addr.val().to_u64() as u32),
            );
            frame_reads.push_back(
                (u.frame_read.val() && u.frame_grant.val())
                    .then(|| u.frame_addr.val().to_u64() as u32),
            );
            if u.fb_write.val() && u.fb_grant.val() {
                let addr = u.fb_addr.val().to_u64() as u32;
                let data = u.fb_data.val().to_u64() as u32;
                assert!(
                    written.insert(addr, data).is_none(),
                    "pixel {addr} written twice"
                );
            }
            if u.offer.val() {
                if u.refused.val() {
                    refused_while_loading += usize::from(cycles < 60);
                    refused_full += usize::from(cycles >= 60);
                } else {
                    next_job += 1;
                    phase = 0;
                }
            }
            clock_cycle(&mut b, |b, c| b.clock.next = Clock { clk: c });
            if next_job == jobs.len() && b.unit.idle.val() && cycles > 100 {
                break;
            }
        }
        println!("{} pixels in {cycles} clocks", jobs.len());
        assert!(refused_while_loading > 0, "offers wait for the constants");
        // Offers were refused with the constants in: every one of the slots was taken.
        assert!(refused_full > 0, "the slots never filled");
        assert_eq!(written.len(), jobs.len());
        for (i, want) in expect.iter().enumerate() {
            let addr = FRAME_BUFFER + i as u32;
            assert_eq!(
                written.get(&addr),
                Some(want),
                "pixel {i} (hit {})",
                jobs[i].hit
            );
        }
        // The comparison saw lit surfaces.
        let shaded = (0..jobs.len())
            .filter(|&i| {
                jobs[i].hit && expect[i] != units::pack_channel_bytes(f, constants.background)
            })
            .count();
        assert!(shaded > 60, "{shaded}");
    }

    #[test]
    fn pixels_equal_the_twin_three_lights() {
        shade_pixels(3, 91);
    }

    #[test]
    fn pixels_equal_the_twin_one_light() {
        shade_pixels(1, 92);
    }

    #[test]
    fn pixels_equal_the_twin_no_light() {
        shade_pixels(0, 93);
    }
}
