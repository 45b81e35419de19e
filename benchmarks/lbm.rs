//! `cargo bench --bench lbm`: D2Q9 throughput for both precisions and collision operators,
//! each beside the measured copy bandwidth (the same measurement as `granflow bench lbm`).
//! Size and steps: `GRANFLOW_BENCH_N` (default 1024), `GRANFLOW_BENCH_STEPS` (default 50).

#[path = "common.rs"]
mod common;
use common::env;

fn main() {
    let n = env("GRANFLOW_BENCH_N", 1024);
    let steps = env("GRANFLOW_BENCH_STEPS", 50) as u64;
    for f64_ in [false, true] {
        for mrt in [false, true] {
            let case = granflow::scenario::fluid::bench::LbmCase {
                nx: n,
                ny: n,
                steps,
                f64: f64_,
                mrt,
                backend: granflow::lbm::Backend::Cpu,
            };
            match granflow::scenario::fluid::bench::lbm(case, 0, 5) {
                Ok(r) => println!(
                    "lbm {n}² {} {}: {:.1} MLUPS, copy {:.1} GB/s, {:.0} % of roofline",
                    r.precision,
                    r.collision,
                    r.mlups,
                    r.copy_gb_s,
                    100.0 * r.roofline_fraction
                ),
                Err(e) => eprintln!("lbm bench failed: {e}"),
            }
        }
    }
    println!("machine: {}", granflow::exec::machine::Machine::measure());
}
