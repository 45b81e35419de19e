//! `cargo bench --bench coupled`: the LBM–DEM coupled step (partially saturated cells; the
//! same measurement as `granflow bench coupled`), f32 on the CPU, with the machine it ran on.
//! The default is a quarter of the seed's Table 5.3 case (1200 × 1500 nodes, 625 grains of
//! the same size); `GRANFLOW_BENCH_NX`, `_NY`, `_GRAINS` and `_STEPS` (default 20) change it.

#[path = "common.rs"]
mod common;
use common::env;

fn main() {
    use granflow::scenario::submerged::bench::{coupled, CoupledCase};
    let case = CoupledCase {
        nx: env("GRANFLOW_BENCH_NX", 1200),
        ny: env("GRANFLOW_BENCH_NY", 1500),
        grains: env("GRANFLOW_BENCH_GRAINS", 625),
        steps: env("GRANFLOW_BENCH_STEPS", 20) as u64,
        f64: false,
        backend: granflow::lbm::Backend::Cpu,
    };
    match coupled(case, 0) {
        Ok(r) => println!(
            "coupled {}×{} f32 with {} grains on {} threads: {:.1} MLUPS, {:.2} s for {} steps ({} covered cells)",
            r.nx, r.ny, r.grains, r.threads, r.mlups, r.seconds, r.steps, r.covered_cells
        ),
        Err(e) => eprintln!("coupled bench failed: {e}"),
    }
    println!("machine: {}", granflow::exec::machine::Machine::measure());
}
