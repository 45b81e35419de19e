//! `cargo bench --bench dem`: DEM throughput on the LAMMPS `in.gran2d.lmp` case (the same
//! measurement as `granflow bench dem`), with the machine it ran on. Size and steps:
//! `GRANFLOW_BENCH_GRAINS` (default 10 000), `GRANFLOW_BENCH_STEPS` (default 1000).

#[path = "common.rs"]
mod common;
use common::env;

fn main() {
    let grains = env("GRANFLOW_BENCH_GRAINS", 10_000);
    let steps = env("GRANFLOW_BENCH_STEPS", 1000) as u64;
    match granflow::scenario::dem::bench::run(grains, steps, 0, 3) {
        Ok(r) => println!(
            "dem {grains} grains, {steps} steps on {} threads: {:.3e} particle-steps/s, {:.0} contacts/step",
            r.threads, r.particle_steps_per_s, r.contacts_per_step
        ),
        Err(e) => eprintln!("dem bench failed: {e}"),
    }
    println!("machine: {}", granflow::exec::machine::Machine::measure());
}
