use dynrt::fp::Format;
use dynrt::hw::program::exec::Machine;
use dynrt::hw::program::{build_program, ProgramConfig};
use dynrt::layout::{self, MemoryConfig, SceneTrees};
use dynrt::scene::Scene;
fn main() {
    for name in [
        "tiny",
        "cornell_noshadow",
        "cornell",
        "mirror",
        "dynamic",
        "terrain",
    ] {
        let f = Format::E7M16;
        let mut s = Scene::load(std::path::Path::new(&format!("scenes/{name}.toml"))).unwrap();
        s.set_resolution(32, 24).unwrap();
        let trees = SceneTrees::build(&s, f).unwrap();
        let l = layout::build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
        let p = build_program(&ProgramConfig::from_layout(f, &l.info));
        let fr = Machine::new(&p, &l).run_frame(32).unwrap();
        println!(
            "{name}: {} instr, {} regs, scratch {}, instr/pixel {:.0}, rounds {} {:?}",
            p.code.len(),
            p.registers_used,
            p.scratch.words,
            fr.stats.instructions as f64 / 768.0,
            fr.stats.rounds,
            fr.stats.per_unit
        );
    }
}
