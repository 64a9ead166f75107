//! Thread CPU time of the kd-tree builds the host-side targets name (the load of a shared
//! machine moves wall-clock times more than most changes do): the Stanford bunny's object tree
//! (default parameters: perfect splits, budget of 3 nodes per triangle) and the top level over
//! the benchmark's 5,622 instance boxes (five times the runs); `terrain` the benchmark's
//! 131,072-triangle terrain, a tree the budget does not bind. Prints the fastest and the
//! median of `RUNS` builds (thread CPU time: `CLOCK_THREAD_CPUTIME_ID`), the tree's node
//! count, SAH cost and a fingerprint (`KdTree::fingerprint`), so that two builders can be
//! compared in alternating runs of their binaries.
//!
//! `cargo run --release --example kd_build_time -- [RUNS=9] [both|bunny|top|terrain]`
use dynrt::accel::bench::{load_obj_triangles, random_instance_boxes};
use dynrt::accel::{build_sah, build_sah_boxes, KdParams, KdTree};

fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid clock id and a pointer to a timespec we own.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0);
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn time(name: &str, runs: usize, params: &KdParams, build: &dyn Fn() -> KdTree) {
    let mut best = f64::INFINITY;
    let mut all = Vec::new();
    let mut tree = None;
    for _ in 0..runs {
        let t0 = thread_cpu_seconds();
        let t = build();
        let dt = thread_cpu_seconds() - t0;
        best = best.min(dt);
        all.push(dt * 1e3);
        tree = Some(t);
    }
    let tree = tree.unwrap();
    let s = tree.stats(params);
    all.sort_by(f64::total_cmp);
    println!(
        "{name}: fastest {:.2} ms, median {:.2} ms (thread CPU, {runs} runs); {} nodes, SAH cost \
         {:.4}, fingerprint {:#018x}",
        best * 1e3,
        all[runs / 2],
        tree.nodes.len(),
        s.sah_cost,
        tree.fingerprint()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs: usize = args.get(1).map_or(9, |s| s.parse().unwrap());
    let which = args.get(2).map_or("both", |s| s.as_str());
    let params = KdParams::default();
    if which == "terrain" {
        let tris = dynrt::accel::bench::heightfield_triangles(256, 1);
        time("terrain 256x256", runs, &params, &|| {
            build_sah(&tris, &params)
        });
        return;
    }
    if which != "top" {
        let path = dynrt::scene::shared_mesh_dir().join("stanford-bunny.obj");
        let tris = load_obj_triangles(&path).unwrap();
        time("bunny", runs, &params, &|| build_sah(&tris, &params));
    }
    if which != "bunny" {
        let boxes = random_instance_boxes(5622, 2);
        time("top level 5622", runs.max(1) * 5, &params, &|| {
            build_sah_boxes(&boxes, &params)
        });
    }
}
