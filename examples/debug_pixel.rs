use dynrt::fp::Format;
use dynrt::hw::program::exec::Machine;
use dynrt::hw::program::{build_program, ProgramConfig};
use dynrt::layout::{self, MemoryConfig, SceneTrees};
use dynrt::model::golden::Golden;
use dynrt::scene::Scene;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (name, x, y): (&str, u32, u32) =
        (&args[1], args[2].parse().unwrap(), args[3].parse().unwrap());
    let f = Format::E7M16;
    let mut s = Scene::load(std::path::Path::new(name)).unwrap();
    s.set_resolution(16, 12).unwrap();
    let trees = SceneTrees::build(&s, f).unwrap();
    let l = layout::build(&s, &trees, 0, &MemoryConfig::default()).unwrap();
    let p = build_program(&ProgramConfig::from_layout(f, &l.info));
    let g = Golden::new(&l).pixel(x, y);
    println!(
        "golden {:x} hit {:?} color {:?}",
        g.rgb,
        g.hit,
        g.color.map(|c| f.to_f64(c))
    );
    let m = Machine::new(&p, &l);
    let (rgb, _, writes) = m.run_pixel(x, y, true).unwrap();
    println!("twin {rgb:x}");
    for w in writes {
        println!(
            "{:4} {:<10} {:<40} r{} = {:#x} ({})",
            w.pc,
            p.sections[w.pc as usize],
            p.code[w.pc as usize].to_string(),
            w.reg,
            w.value,
            f.to_f64(w.value)
        );
    }
}
