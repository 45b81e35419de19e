//! Column collapse from a scenario file with the APIC transfer (or the file's FLIP/PIC), run
//! to 6 τ_c, printing run-out every 0.5 τ_c (docs/mpm-status.md, "APIC and the collapse").
//!
//! `cargo run --release --example mpm_apic_collapse -- models/column_collapse/mpm_a2.toml apic`
//! (second argument `flip` keeps the file's transfer).

use granflow::mpm::scenario::MpmScenario;
use granflow::mpm::Transfer;

fn main() -> granflow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 3 {
        eprintln!("usage: mpm_apic_collapse <scenario.toml> apic|flip");
        std::process::exit(2);
    }
    let apic = a[2] == "apic";
    let mut s = MpmScenario::from_file(std::path::Path::new(&a[1]))?;
    if apic {
        s.mpm.pic_fraction = 0.0;
    }
    let (mut mpm, d) = s.build()?;
    if apic {
        mpm.set_transfer(Transfer::Apic)?;
    }
    let li = s.column.width;
    let t0 = std::time::Instant::now();
    let e0 = mpm.energy().potential;
    for k in 1..=12 {
        mpm.advance_by(0.5 * d.tau_c)?;
        let sh = granflow::mpm::run::shape(&mpm);
        println!(
            "t/tc {:.1} runout {:.4} dL {:.3} KE/E0 {:.2e} H/Li {:.3} wall {:.1}s",
            0.5 * k as f64,
            sh.runout,
            (sh.runout - li) / li,
            mpm.energy().kinetic / e0,
            sh.height / li,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
