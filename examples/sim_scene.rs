use dynrt::emit::processor::ProcessorParams;
use dynrt::emit::processor_run::simulate_processor;
use dynrt::fp::Format;
use dynrt::hw::program::exec::Machine;
use dynrt::hw::program::{build_program, ProgramConfig};
use dynrt::layout::{self, MemoryConfig, SceneTrees};
use dynrt::model;
use dynrt::scene::Scene;
use dynrt::sim::Simulator;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (name, w, h, sim) = (
        &a[1],
        a[2].parse().unwrap(),
        a[3].parse().unwrap(),
        if a[4] == "iverilog" {
            Simulator::Icarus
        } else {
            Simulator::Verilator
        },
    );
    let f = Format::E7M16;
    let mut s = Scene::load(std::path::Path::new(name)).unwrap();
    s.set_resolution(w, h).unwrap();
    let trees = SceneTrees::build(&s, f).unwrap();
    let l = layout::build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
    let p = build_program(&ProgramConfig::from_layout(f, &l.info));
    let twin = Machine::new(&p, &l).run_frame(32).unwrap();
    println!(
        "twin rounds {} instr {}",
        twin.stats.rounds, twin.stats.instructions
    );
    let g = model::render_golden(&l, false);
    let r = simulate_processor(
        &p,
        &[l.clone()],
        ProcessorParams::default(),
        "x",
        twin.stats.rounds * 40 + 10000,
        sim,
        std::path::Path::new("/tmp/simx"),
    )
    .unwrap();
    let fr = &r.frames[0];
    let bad = fr.pixels.iter().zip(&g.rgb).filter(|(a, b)| a != b).count();
    println!(
        "cycles {} instr {} bad {bad} compile {:.1}s run {:.1}s",
        fr.cycles, fr.instructions, r.compile_seconds, r.run_seconds
    );
    for (i, (a, b)) in fr
        .pixels
        .iter()
        .zip(&g.rgb)
        .enumerate()
        .filter(|(_, (a, b))| a != b)
        .take(5)
    {
        println!("px {i}: rtl {a:06x} golden {b:06x}");
    }
}
