//! The engine's Rust twin: runs a [`Program`] on a frame's memory exactly as the ray thread
//! engine does, instruction by instruction.
//!
//! Threads take turns in a fixed rotation (thread 0, 1, ..., N-1, then again), one
//! instruction per turn, like the engine's issue slots. The coprocessors' work (`tri`, `kd`)
//! is done at once, so the twin never spends a turn waiting: its frame buffer and retired
//! instruction counts are the RTL's, its turns a lower bound of the RTL's clocks over the
//! rotation period (pixels are independent, so which thread takes which pixel does not change
//! the frame). [`Machine::run_pixel`] runs a single
//! pixel on one thread (threads never share state, so its result is the same; rayon runs
//! those in parallel), optionally recording every register write for traces.
//!
//! The hardware it is the twin of: [`crate::hw::engine::ThreadEngine`] and its stage blocks
//! (the fields of [`crate::hw::engine::Decode`], the results of
//! [`crate::hw::engine::Execute`] and [`crate::hw::engine::FpUnits`], the condition and next pc
//! of [`crate::hw::engine::WriteBack`], the mailboxes of [`crate::hw::engine::MailboxUnit`],
//! the pixels and primary rays of [`crate::hw::engine::PrimaryRays`]); `kd` stands for the
//! [`crate::hw::TraversalUnit`]'s walk and `tri` for the [`crate::hw::TriangleTester`].

use super::isa::{
    Instr, KdFn, Op, TriFn, Unit, KD_ANY_HIT, KD_ENTERED, KD_TOP, KD_WALK_ENDED, REGISTERS,
};
use super::Program;
use crate::fp::Format;
use crate::hw::engine::CAMERA_WORDS;
use crate::hw::traversal_unit::STACK_LEVELS;
use crate::layout::{
    instance_word, Layout, Node, INSTANCES, INSTANCE_WORDS, LISTS, NODES, NODE_WORDS, TRIANGLES_B,
    TRIANGLE_BANK_WORDS,
};
use crate::units::{self, Mailbox};

/// A failure of the program on this memory (a generator bug or a layout that does not belong
/// to the program).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("thread {thread} at pc {pc} ({instr}): {what}")]
pub struct ExecError {
    pub thread: usize,
    pub pc: usize,
    pub instr: String,
    pub what: String,
}

/// One register write, for traces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Write {
    pub pc: u16,
    pub reg: u8,
    pub value: u32,
}

/// A thread's state in the triangle tester: its ray and its closest hit. The twin tests a
/// queued triangle at once; the tester tests a thread's entries in the order they were queued,
/// so a `wait` sees the same result.
#[derive(Clone)]
struct TesterState {
    o: [u32; 3],
    d: [u32; 3],
    t_min: u32,
    hit: bool,
    best_t: u32,
    best_instance: u32,
    best_triangle: u32,
    /// The list unit's: the object of the lists, the skipped pair, the triangle mailbox.
    object: u32,
    skip: (u32, u32),
    mailbox: Mailbox,
}

impl Default for TesterState {
    fn default() -> Self {
        TesterState {
            o: [0; 3],
            d: [0; 3],
            t_min: 0,
            hit: false,
            best_t: 0,
            best_instance: 0,
            best_triangle: 0,
            object: 0,
            // The hardware's skip words start all ones: no triangle is skipped until a
            // query says so.
            skip: (u32::MAX, u32::MAX),
            mailbox: Mailbox::default(),
        }
    }
}

#[derive(Clone)]
struct Thread {
    pc: usize,
    regs: Vec<u32>,
    scratch: Vec<u32>,
    mailboxes: [Mailbox; 2],
    tester: TesterState,
    /// Ray generation's camera words (`tri.camera`; shared in the engine, where every
    /// thread writes the same frame words) and the thread's last primary direction.
    camera: [u32; CAMERA_WORDS],
    primary_d: [u32; 3],
    /// The world ray's words (`tri.world`), which `tri.enter` and the top-level walk
    /// transform and walk.
    world: [u32; 6],
    /// The top-level walk (`kd.start` with `KD_TOP`), stopped at its leaf; what `kd.wait` and
    /// `kd.leaf` read (the top-level leaf's list start, or `KD_WALK_ENDED`, and end; after an
    /// object walk, the hit flag); the object root of the last `tri.enter`; the tester's
    /// last answer to an object walk (best t, hit), which `kd.next` and an entered object's
    /// walk go on with.
    top_walk: units::KdWalk,
    walk_words: [u32; 2],
    entered_root: u32,
    last_answer: (u32, bool),
    halted: bool,
}

impl Thread {
    fn new(scratch_words: usize) -> Self {
        Thread {
            pc: 0,
            regs: vec![0; REGISTERS],
            scratch: vec![0; scratch_words],
            mailboxes: Default::default(),
            tester: TesterState::default(),
            camera: [0; CAMERA_WORDS],
            primary_d: [0; 3],
            world: [0; 6],
            top_walk: units::KdWalk::default(),
            walk_words: [0; 2],
            entered_root: 0,
            last_answer: (0, false),
            halted: false,
        }
    }
}

/// Where pixels come from: the frame's raster order, or one given pixel.
enum Pixels {
    Raster { next: u32, count: u32 },
    One(Option<(u32, u32)>),
}

/// What a run did, per unit and in total.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RunStats {
    /// Instructions executed per unit (the engine issues one per clock).
    pub per_unit: std::collections::BTreeMap<Unit, u64>,
    /// Instructions executed per routine of the program (`Program::sections`).
    pub per_section: std::collections::BTreeMap<&'static str, u64>,
    pub instructions: u64,
    /// Rounds of the threads (each issuing once) until the last thread halted.
    pub rounds: u64,
    /// The coprocessors' work: triangles tested, kd nodes fetched by the traversal unit.
    pub triangle_tests: u64,
    pub kd_nodes: u64,
}

/// A frame rendered by the engine's twin.
#[derive(Clone, Debug)]
pub struct EngineFrame {
    /// `0x00RRGGBB` per pixel, row by row.
    pub pixels: Vec<u32>,
    pub stats: RunStats,
}

/// The engine's twin on one frame's memory.
pub struct Machine<'a> {
    program: &'a Program,
    /// What the engine runs: the program's ROM words, decoded.
    rom: Vec<Instr>,
    layout: &'a Layout,
    /// The frame's ambient, background and lights (`tri.shade`).
    shading: units::ShadingConstants,
    f: Format,
}

impl<'a> Machine<'a> {
    pub fn new(program: &'a Program, layout: &'a Layout) -> Self {
        let rom = program
            .rom()
            .into_iter()
            .map(|w| Instr::decode(w).expect("an encoded instruction decodes"))
            .collect();
        Machine {
            program,
            rom,
            layout,
            shading: layout.shading_constants(),
            f: program.config.format,
        }
    }

    /// Runs the whole frame with `threads` threads in the engine's order.
    pub fn run_frame(&self, threads: usize) -> Result<EngineFrame, ExecError> {
        let c = &self.program.config;
        let mut fb = vec![0u32; (c.width * c.height) as usize];
        let mut ts: Vec<Thread> = (0..threads)
            .map(|_| Thread::new(self.program.scratch.words as usize))
            .collect();
        let mut pixels = Pixels::Raster {
            next: 0,
            count: c.width * c.height,
        };
        let mut stats = RunStats::default();
        loop {
            let mut any = false;
            for (k, t) in ts.iter_mut().enumerate() {
                if t.halted {
                    continue;
                }
                any = true;
                self.step(k, t, &mut pixels, &mut fb, &mut stats, None)?;
            }
            if !any {
                break;
            }
            stats.rounds += 1;
        }
        Ok(EngineFrame { pixels: fb, stats })
    }

    /// Runs pixel (x, y) alone on one thread; returns its frame-buffer word, and every
    /// register write when `trace`.
    pub fn run_pixel(
        &self,
        x: u32,
        y: u32,
        trace: bool,
    ) -> Result<(u32, RunStats, Vec<Write>), ExecError> {
        let c = &self.program.config;
        let mut fb = vec![0u32; (c.width * c.height) as usize];
        let mut t = Thread::new(self.program.scratch.words as usize);
        let mut pixels = Pixels::One(Some((x, y)));
        let mut stats = RunStats::default();
        let mut writes = trace.then(Vec::new);
        while !t.halted {
            self.step(0, &mut t, &mut pixels, &mut fb, &mut stats, writes.as_mut())?;
            stats.rounds += 1;
        }
        Ok((
            fb[(y * c.width + x) as usize],
            stats,
            writes.unwrap_or_default(),
        ))
    }

    fn step(
        &self,
        k: usize,
        t: &mut Thread,
        pixels: &mut Pixels,
        fb: &mut [u32],
        stats: &mut RunStats,
        trace: Option<&mut Vec<Write>>,
    ) -> Result<(), ExecError> {
        let f = self.f;
        let Some(&i) = self.rom.get(t.pc) else {
            return Err(self.error(k, t.pc, None, "program counter beyond the program"));
        };
        let a = t.regs[i.a as usize];
        let b = if i.b_imm { i.imm } else { t.regs[i.b as usize] };
        let pc = t.pc;
        let fail = |what: String| self.error(k, pc, Some(i), &what);
        let mut next = t.pc + 1;
        let mut result = None;
        let branch_if = |cond: bool, next: &mut usize| {
            if cond != i.invert {
                *next = i.target as usize;
            }
        };
        match i.op {
            Op::Nop => {}
            Op::FAdd => result = Some(f.add(a, b)),
            Op::FSub => result = Some(f.sub(a, b)),
            Op::FMul => result = Some(f.mul(a, b)),
            Op::FDiv => result = Some(f.div(a, b)),
            Op::FSqrt => result = Some(f.sqrt(a)),
            Op::Byte => result = Some((b << 8) | crate::units::channel_byte(f, a)),
            Op::Add => result = Some(a.wrapping_add(b)),
            Op::Sub => result = Some(a.wrapping_sub(b)),
            Op::And => result = Some(a & b),
            Op::Or => result = Some(a | b),
            Op::Xor => result = Some(a ^ b),
            Op::Shr => result = Some(a >> (b & 31)),
            Op::Shl => result = Some(a << (b & 31)),
            Op::Ld => {
                let addr = (a << i.shift).wrapping_add(i.imm);
                let bank = self
                    .layout
                    .banks
                    .get(i.bank as usize)
                    .ok_or_else(|| fail(format!("no bank {}", i.bank)))?;
                let w = bank.get(addr as usize).ok_or_else(|| {
                    fail(format!(
                        "bank {} address {addr} beyond its {} words",
                        i.bank,
                        bank.len()
                    ))
                })?;
                result = Some(*w);
            }
            Op::St => {
                let addr = (a << i.shift).wrapping_add(i.imm);
                let base = self.program.config.frame_buffer;
                let slot = addr
                    .checked_sub(base)
                    .filter(|&s| (s as usize) < fb.len())
                    .ok_or_else(|| fail(format!("store to {addr}, outside the frame buffer")))?;
                fb[slot as usize] = t.regs[i.b as usize];
            }
            Op::Lds | Op::Sts => {
                let addr = a.wrapping_add(i.imm) as usize;
                if addr >= t.scratch.len() {
                    return Err(fail(format!(
                        "scratch word {addr} beyond its {} words",
                        t.scratch.len()
                    )));
                }
                if i.op == Op::Lds {
                    result = Some(t.scratch[addr]);
                } else {
                    t.scratch[addr] = t.regs[i.b as usize];
                }
            }
            Op::BFlt => branch_if(f.lt(a, b), &mut next),
            Op::BFle => branch_if(f.le(a, b), &mut next),
            Op::BFeq => branch_if(f.eq(a, b), &mut next),
            Op::Beq => branch_if(a == b, &mut next),
            Op::Bltu => branch_if(a < b, &mut next),
            Op::Jal => {
                result = Some(next as u32);
                next = i.target as usize;
            }
            Op::Jr => next = a as usize,
            Op::Mbx => {
                if t.mailboxes[(i.imm & 1) as usize].seen(a) {
                    next = i.target as usize;
                }
            }
            Op::Mbc => t.mailboxes[(i.imm & 1) as usize] = Mailbox::default(),
            Op::Pixel => {
                let taken = match pixels {
                    Pixels::Raster { next: n, count } => (*n < *count).then(|| {
                        let w = self.program.config.width;
                        *n += 1;
                        ((*n - 1) % w, (*n - 1) / w)
                    }),
                    Pixels::One(p) => p.take(),
                };
                match taken {
                    // The pixel's primary ray, written whole into the thread's ray.
                    Some((x, y)) => {
                        result = Some((y << self.program.config.pixel_shift()) | x);
                        let camera: &units::Mat34W = t.camera[..12].try_into().unwrap();
                        let d = units::primary_direction(f, camera, x, y);
                        t.tester.o = t.camera[12..15].try_into().unwrap();
                        t.tester.d = d;
                        t.primary_d = d;
                    }
                    None => next = i.target as usize,
                }
            }
            Op::Halt => {
                t.halted = true;
                next = t.pc;
            }
            Op::Tri => {
                let function = TriFn::from_imm(i.imm)
                    .ok_or_else(|| fail(format!("no triangle tester function {}", i.imm)))?;
                let tt = &mut t.tester;
                match function {
                    TriFn::RayOxy => (tt.o[0], tt.o[1]) = (a, b),
                    TriFn::RayOzDx => (tt.o[2], tt.d[0]) = (a, b),
                    TriFn::RayDyz => (tt.d[1], tt.d[2]) = (a, b),
                    TriFn::Init => {
                        // A new query empties the mailbox (the list unit's).
                        tt.mailbox = Mailbox::default();
                        tt.t_min = a;
                        tt.hit = false;
                        tt.best_t = b;
                    }
                    TriFn::Skip => tt.skip = (a, b),
                    TriFn::List => self.test_list(tt, a, b, stats).map_err(fail)?,
                    TriFn::Wait => result = Some(tt.best_t),
                    TriFn::Hit => result = Some(u32::from(tt.hit)),
                    TriFn::Instance => result = Some(tt.best_instance),
                    TriFn::Triangle => result = Some(tt.best_triangle),
                    TriFn::Camera => {
                        let pair = usize::from(i.shift);
                        let words = t
                            .camera
                            .get_mut(2 * pair..2 * pair + 2)
                            .ok_or_else(|| fail(format!("no camera word pair {pair}")))?;
                        words.copy_from_slice(&[a, b]);
                    }
                    TriFn::Dir => {
                        let k = usize::from(i.shift);
                        let d = t.primary_d.get(k);
                        result = Some(*d.ok_or_else(|| fail(format!("no direction word {k}")))?);
                    }
                    TriFn::World => {
                        let pair = usize::from(i.shift);
                        let words = t
                            .world
                            .get_mut(2 * pair..2 * pair + 2)
                            .ok_or_else(|| fail(format!("no world ray word pair {pair}")))?;
                        words.copy_from_slice(&[a, b]);
                    }
                    TriFn::Enter => {
                        // `hw::engine::InstanceRays`: origin, then direction, through the
                        // TransformUnit (its twin, `units::transform`), and the object root.
                        let words = self.instance_record(a).map_err(fail)?;
                        let at = instance_word::WORLD_TO_OBJECT;
                        let m: units::Mat34W = words[at..at + 12].try_into().unwrap();
                        let (o, d) = t.world.split_at(3);
                        tt.o = units::transform(f, &m, o.try_into().unwrap(), true);
                        tt.d = units::transform(f, &m, d.try_into().unwrap(), false);
                        t.entered_root = words[instance_word::ROOT];
                        // The next lists are the instance's (its `tri.object`, queued with
                        // the entry), and the traversal unit walks its object from the
                        // entered root once the ray is written.
                        (t.tester.object, t.tester.mailbox) = (a, Mailbox::default());
                        let walk = KD_ENTERED | (b & KD_ANY_HIT);
                        stats.kd_nodes += self.object_walk(t, walk, 0, stats).map_err(fail)?;
                    }
                    TriFn::Shade => {
                        // `hw::ShadeUnit`: the thread's query shaded (its twin,
                        // `units::shade_direct`) into the pixel's word, the frame buffer's
                        // base added.
                        let hit = tt.hit.then(|| {
                            let (n, material) = self.layout.triangle_shading(tt.best_triangle);
                            let (kd, _) = self.layout.material(material);
                            units::SurfaceHit {
                                o: tt.o,
                                d: tt.d,
                                t: tt.best_t,
                                n,
                                kd,
                            }
                        });
                        let word = fb.get_mut(a as usize).ok_or_else(|| {
                            fail(format!("shade of pixel word {a}, outside the frame buffer"))
                        })?;
                        *word = units::shade_direct(f, &self.shading, hit.as_ref());
                    }
                    TriFn::Normal => {
                        // `hw::engine::InstanceRays`: the normal matrix through the
                        // TransformUnit (a vector), kept where `tri.dir` reads.
                        let words = self.instance_record(a).map_err(fail)?;
                        let at = instance_word::NORMAL_MATRIX;
                        let m: &[u32; 9] = words[at..at + 9].try_into().unwrap();
                        t.primary_d = units::transform3(f, m, [t.world[0], t.world[1], b]);
                    }
                }
                // The twin's queue never refuses and its tests are done at once, so the
                // instruction never repeats.
            }
            Op::Kd => {
                let function = KdFn::from_imm(i.imm)
                    .ok_or_else(|| fail(format!("no traversal unit function {}", i.imm)))?;
                let nodes = std::cell::Cell::new(0u64);
                let fetch = |n| {
                    nodes.set(nodes.get() + 1);
                    self.kd_node(n)
                };
                let root = a & !(KD_ANY_HIT | KD_TOP | KD_ENTERED);
                // The top-level walk's stack is above the object walks'.
                let top_levels = STACK_LEVELS - self.program.config.top_stack_base as usize;
                let world = (
                    t.world[..3].try_into().unwrap(),
                    t.world[3..].try_into().unwrap(),
                );
                // The unit's top-level walk stops at a leaf with instances (an empty one it
                // passes with the thread's last answer) or its end.
                let top_stop = |t: &mut Thread, mut stop| -> Result<(), ExecError> {
                    while let units::KdStop::Leaf { count: 0, .. } = stop {
                        let answer = t.last_answer;
                        stop = t
                            .top_walk
                            .next(f, world, answer, top_levels, fetch)
                            .map_err(fail)?;
                    }
                    match stop {
                        units::KdStop::Leaf { list, count } => {
                            t.walk_words = [list, list.wrapping_add(count)];
                        }
                        units::KdStop::Finished => t.walk_words[0] = KD_WALK_ENDED,
                    }
                    Ok(())
                };
                match function {
                    KdFn::Start if a & KD_TOP != 0 => {
                        t.last_answer = (b, false);
                        let segment = (t.tester.t_min, b);
                        let (walk, stop) =
                            units::KdWalk::start(f, world, root, segment, top_levels, fetch)
                                .map_err(fail)?;
                        t.top_walk = walk;
                        top_stop(t, stop)?;
                    }
                    KdFn::Start => {
                        let n = self.object_walk(t, a, b, stats).map_err(fail)?;
                        nodes.set(nodes.get() + n);
                    }
                    KdFn::Next => {
                        let stop = t
                            .top_walk
                            .next(f, world, t.last_answer, top_levels, fetch)
                            .map_err(fail)?;
                        top_stop(t, stop)?;
                    }
                    // The twin's walk has stopped when it starts, so `wait` never waits.
                    KdFn::Wait => result = Some(t.walk_words[0]),
                    KdFn::Leaf => result = Some(t.walk_words[1]),
                }
                stats.kd_nodes += nodes.get();
            }
        }
        if i.jumps_after() {
            next = i.target as usize;
        }
        if let Some(v) = result {
            if i.dst != 0 {
                t.regs[i.dst as usize] = v;
                if let Some(tr) = trace {
                    tr.push(Write {
                        pc: t.pc as u16,
                        reg: i.dst,
                        value: v,
                    });
                }
            }
        }
        *stats.per_unit.entry(i.unit()).or_default() += 1;
        *stats
            .per_section
            .entry(self.program.sections[t.pc])
            .or_default() += 1;
        stats.instructions += 1;
        t.pc = next;
        Ok(())
    }

    /// Instance `instance`'s record in bank 4, as instance entry reads it.
    fn instance_record(&self, instance: u32) -> Result<&[u32], String> {
        let bank = &self.layout.banks[INSTANCES];
        let record = instance as usize * INSTANCE_WORDS;
        bank.get(record..record + INSTANCE_WORDS).ok_or_else(|| {
            format!(
                "instance {instance} beyond the instance bank's {} words",
                bank.len()
            )
        })
    }

    /// An object's whole walk by the traversal unit (`kd.start` of an object, or the walk of
    /// `tri.enter`): from `root` (its word, with `KD_ANY_HIT` and `KD_ENTERED`) up to `t_max`
    /// (an entered object's: the thread's last answer), each leaf's list to the tester,
    /// whose closest hit answers the unit (an any-hit walk ends at the first hit). Under a
    /// top level the object walks have the stack below its region. Gives the nodes fetched.
    fn object_walk(
        &self,
        t: &mut Thread,
        root: u32,
        t_max: u32,
        stats: &mut RunStats,
    ) -> Result<u64, String> {
        let f = self.f;
        let mut nodes = 0u64;
        let mut fetch = |n| {
            nodes += 1;
            self.kd_node(n)
        };
        let levels = if self.program.config.top_root.is_some() {
            self.program.config.top_stack_base as usize
        } else {
            STACK_LEVELS
        };
        let (node, t_max) = if root & KD_ENTERED != 0 {
            (t.entered_root, t.last_answer.0)
        } else {
            (root & !(KD_ANY_HIT | KD_TOP | KD_ENTERED), t_max)
        };
        let tt = &mut t.tester;
        let ray = (tt.o, tt.d);
        let any_hit = root & KD_ANY_HIT != 0;
        let (mut walk, mut stop) =
            units::KdWalk::start(f, ray, node, (tt.t_min, t_max), levels, &mut fetch)?;
        while let units::KdStop::Leaf { list, count } = stop {
            self.test_list(tt, list, list.wrapping_add(count), stats)?;
            t.last_answer = (tt.best_t, tt.hit);
            stop = if any_hit && tt.hit {
                units::KdStop::Finished
            } else {
                walk.next(f, ray, t.last_answer, levels, &mut fetch)?
            };
        }
        t.walk_words[0] = u32::from(t.last_answer.1);
        Ok(nodes)
    }

    /// The tester's work on the triangle list `from..to` of bank 1: the list unit's skip and
    /// mailbox, then each test and the closest hit.
    fn test_list(
        &self,
        tt: &mut TesterState,
        from: u32,
        to: u32,
        stats: &mut RunStats,
    ) -> Result<(), String> {
        let f = self.f;
        let list = self.layout.banks[LISTS].get(from as usize..to as usize);
        let list =
            list.ok_or_else(|| format!("triangle list {from}..{to} beyond the list bank"))?;
        let words = self.layout.banks[TRIANGLES_B].len() / TRIANGLE_BANK_WORDS;
        for &triangle in list {
            if (tt.object, triangle) == tt.skip || tt.mailbox.seen(triangle) {
                continue;
            }
            if triangle as usize >= words {
                return Err(format!(
                    "triangle {triangle} beyond the {words} triangles in memory"
                ));
            }
            stats.triangle_tests += 1;
            let m = self.layout.triangle_transform(triangle);
            let r = units::triangle_test(f, &m, tt.o, tt.d, tt.t_min);
            if units::closer_hit(f, &r, tt.best_t) {
                tt.hit = true;
                tt.best_t = r.t;
                tt.best_instance = tt.object;
                tt.best_triangle = triangle;
            }
        }
        Ok(())
    }

    /// A kd node of the layout, as the traversal unit decodes it.
    fn kd_node(&self, n: u32) -> Result<Node, String> {
        let nodes = self.layout.banks[NODES].len() / NODE_WORDS;
        if n as usize >= nodes {
            return Err(format!("kd node {n} beyond the {nodes} nodes"));
        }
        Ok(self.layout.node(n))
    }

    fn error(&self, thread: usize, pc: usize, i: Option<Instr>, what: &str) -> ExecError {
        ExecError {
            thread,
            pc,
            instr: i.map_or_else(|| "-".to_string(), |i| i.to_string()),
            what: what.to_string(),
        }
    }
}
