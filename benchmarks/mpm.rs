//! `cargo bench --bench mpm`: GIMPM throughput on the column of `granflow bench mpm` (the same
//! measurement), uGIMP and standard shape functions, with the machine it ran on. Points and
//! steps: `GRANFLOW_BENCH_POINTS` (default 32 768), `GRANFLOW_BENCH_STEPS` (default 200).

#[path = "common.rs"]
mod common;
use common::env;

fn main() {
    use granflow::mpm::ShapeKind;
    let points = env("GRANFLOW_BENCH_POINTS", 32_768);
    let steps = env("GRANFLOW_BENCH_STEPS", 200) as u64;
    for shape in [ShapeKind::Gimp, ShapeKind::Standard] {
        match granflow::scenario::mpm::bench::mpm(points, steps, 0, 5, shape) {
            Ok(r) => println!(
                "mpm {} points, {} on {} threads: {:.3e} point-steps/s",
                r.points, r.shape, r.threads, r.point_steps_per_s
            ),
            Err(e) => eprintln!("mpm bench failed: {e}"),
        }
    }
    println!("machine: {}", granflow::exec::machine::Machine::measure());
}
