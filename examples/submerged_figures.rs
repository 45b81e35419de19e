//! Figures of the submerged column collapse (docs/submerged.md) from run outputs.
//!
//! `cargo run --release --example submerged_figures -- RUNS FIGURES [TAG [WINDOW]]` (TAG `a0.8`
//! if not given, e.g. `a4`, `a0.8_wide`; WINDOW the end of the pore-pressure plot in τ_c, 12 if
//! not given) reads `RUNS/{dry,loose,dense}_TAG/{timeseries.csv,summary.json}`
//! and writes `FIGURES/submerged-TAG-pore-pressure.svg` (base excess pore pressure of the loose and
//! dense columns over the buoyant weight (ρ_s − ρ_f) φ g H_i, against t/τ_c) and
//! `FIGURES/submerged-TAG-runout.svg` ((L(t) − L_i)/L_i of all three), and prints one
//! line per case: φ, ΔL, stop time, and the base pore pressure averaged over the first one and
//! two acoustic periods T_a = 2 max(L_box, depth)/c_s of the tank (c_s = Δx/(√3 Δt)), in Pa
//! and over the buoyant weight, and over (0, t_r], t_r = 2 min(depth, L_box − L_i)/c_s the
//! time the first pressure wave reflected by the lid or the far wall needs to come back, and over
//! (0, t_½], t_½ when the run-out first reaches half its final value (the collapse itself). The pore-pressure figure also shows its running mean over T_a.

use std::path::Path;

use granflow::io::write_svg;
use granflow::report::{Plot, Series};

/// Columns `names` of a CSV file, by header name.
fn columns(path: &Path, names: &[&str]) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let idx: Vec<usize> = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h == n)
                .unwrap_or_else(|| panic!("no column {n}"))
        })
        .collect();
    let mut out = vec![Vec::new(); names.len()];
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        for (k, &i) in idx.iter().enumerate() {
            out[k].push(v[i]);
        }
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (runs, figs) = (Path::new(&args[1]), Path::new(&args[2]));
    let tag = args.get(3).map_or("a0.8", String::as_str);
    let window: f64 = args
        .get(4)
        .map_or(12.0, |w| w.parse().expect("WINDOW: a number"));
    std::fs::create_dir_all(figs).unwrap();
    let mut pore = Plot::new(
        &format!("submerged-{tag}-pore-pressure"),
        &format!("Excess pore pressure at the base under the column, {tag}"),
        "t / τ_c",
        "p_e / ((ρ_s − ρ_f) φ g H_i)",
    );
    let mut runout = Plot::new(
        &format!("submerged-{tag}-runout"),
        &format!("Run-out, {tag}"),
        "t / τ_c",
        "(L(t) − L_i) / L_i",
    );
    pore.series
        .push(Series::line("0", vec![(0.0, 0.0), (window, 0.0)]));
    let mut means = Vec::new();
    for case in ["dry", "loose", "dense"] {
        let dir = runs.join(format!("{case}_{tag}"));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap())
                .unwrap();
        let l_i = summary["l_i"].as_f64().unwrap();
        let phi = summary["packing_fraction"].as_f64().unwrap();
        let label = format!("{case} (φ = {phi:.3})");
        println!(
            "{case}: φ = {phi:.3}, ΔL = {:.3}, L_f = {:.4} m, spreading stopped at {:.2} τ_c",
            summary["delta_l"].as_f64().unwrap(),
            summary["l_f"].as_f64().unwrap(),
            summary["stop_time_tc"].as_f64().unwrap()
        );
        if case == "dry" {
            let c = columns(&dir.join("timeseries.csv"), &["t_over_tc", "runout"]);
            runout.series.push(Series::line(
                &label,
                c[0].iter()
                    .zip(&c[1])
                    .map(|(&t, &l)| (t, (l - l_i) / l_i))
                    .collect(),
            ));
            continue;
        }
        let scale = summary["fluid"]["pressure_scale"].as_f64().unwrap();
        let c = columns(
            &dir.join("timeseries.csv"),
            &["t_over_tc", "runout", "pore_pressure_base"],
        );
        runout.series.push(Series::line(
            &format!("{label}, submerged"),
            c[0].iter()
                .zip(&c[1])
                .map(|(&t, &l)| (t, (l - l_i) / l_i))
                .collect(),
        ));
        pore.series.push(Series::line(
            &format!("{label}, submerged"),
            c[0].iter()
                .zip(&c[2])
                .filter(|(&t, _)| t <= window)
                .map(|(&t, &p)| (t, p / scale))
                .collect(),
        ));
        let f = &summary["fluid"];
        let (dx, dt) = (f["dx"].as_f64().unwrap(), f["dt"].as_f64().unwrap());
        let cells = [
            f["cells"][0].as_f64().unwrap(),
            f["cells"][1].as_f64().unwrap(),
        ];
        let tau_c = summary["tau_c"].as_f64().unwrap();
        let t_a = 2.0 * cells[0].max(cells[1]) * dx / (dx / (3f64.sqrt() * dt)) / tau_c;
        let mean = |a: f64, b: f64| {
            let v: Vec<f64> = c[0]
                .iter()
                .zip(&c[2])
                .filter(|(&t, _)| t > a && t <= b)
                .map(|(_, &p)| p)
                .collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        let (m1, m2) = (mean(0.0, t_a), mean(0.0, 2.0 * t_a));
        // Before the first pressure wave reflected by the lid or the far wall is back:
        // t_r = 2 min(depth, L_box − L_i)/c_s.
        let t_r =
            2.0 * (cells[1] * dx).min(cells[0] * dx - l_i) / (dx / (3f64.sqrt() * dt)) / tau_c;
        let m0 = mean(0.0, t_r);
        println!(
            "{case}: t_r = {t_r:.2} τ_c; base pore pressure mean over (0, t_r] = {m0:.2} Pa ({:.4})",
            m0 / scale
        );
        // While the column collapses: until the run-out first reaches half its final value.
        let half = 0.5 * (summary["l_f"].as_f64().unwrap() + l_i);
        let t_half = c[0]
            .iter()
            .zip(&c[1])
            .find(|(_, &l)| l >= half)
            .map_or(f64::NAN, |(&t, _)| t);
        let mh = mean(0.0, t_half);
        println!(
            "{case}: half run-out at t_½ = {t_half:.2} τ_c; base pore pressure mean over (0, t_½] = {mh:.2} Pa ({:.4})",
            mh / scale
        );
        println!(
            "{case}: T_a = {t_a:.2} τ_c; base pore pressure mean over (0, T_a] = {m1:.2} Pa ({:.4} of (ρ_s − ρ_f)φgH_i = {scale:.1} Pa), over (0, 2T_a] = {m2:.2} Pa ({:.4})",
            m1 / scale,
            m2 / scale
        );
        means.push((
            format!("{case}, running mean over T_a"),
            c[0].iter()
                .filter(|&&t| t >= 0.5 * t_a && t <= window - 0.5 * t_a)
                .map(|&t| (t, mean(t - 0.5 * t_a, t + 0.5 * t_a) / scale))
                .collect::<Vec<_>>(),
        ));
    }
    for (label, pts) in means {
        pore.series.push(Series::line(&label, pts));
    }
    for p in [&pore, &runout] {
        let path = figs.join(format!("{}.svg", p.name));
        write_svg(p, &path).unwrap();
        println!("{}", path.display());
    }
}
