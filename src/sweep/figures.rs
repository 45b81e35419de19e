//! The sweep's figures, each written as SVG and PNG into the output folder:
//!
//! 1. `runout`: ΔL against a (log–log), each solver's points and fitted law, and the
//!    reference laws (Lajeunesse et al. 2005; the thesis's DEM);
//! 2. `height`: H_f/L_i against a (log–log), with H_f/L_i = a (a ≲ 0.7) and the weaker
//!    a^(1/3) quoted for experiments (drawn from a = 0.7 on, continuous there);
//! 3. `front`: (L − L_i)/L_i against t/τ_c for every case, DEM lines, MPM markers and MPM×DEM
//!    dashed lines in one colour per aspect ratio (the DEM lines name the aspect ratio), MPM
//!    cases that differ in more than a in one marker shape per such group (named once);
//! 4. `energy_<case>`: the energy budget against t/τ_c (potential released, kinetic,
//!    dissipated by collisions, friction, rolling resistance and plastic flow), as fractions of
//!    the potential energy released by the end, for each solver's shortest and tallest column.

use std::path::Path;

use super::table::{Fits, REFERENCE_LAWS};
use super::{CaseResult, Solver};
use crate::analysis::runout::CollapseOutcome;
use crate::io::{write_png, write_svg, CsvTable};
use crate::report::{Plot, Series};
use crate::Result;

/// `n` points log-spaced over [lo, hi].
fn log_space(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64))
        .collect()
}

/// Writes `plot` as `<name>.svg` and `<name>.png` in `dir`.
fn write(dir: &Path, plot: &Plot) -> Result<()> {
    write_svg(plot, &dir.join(format!("{}.svg", plot.name)))?;
    write_png(plot, &dir.join(format!("{}.png", plot.name)))
}

fn label(solver: &str, with: &std::collections::BTreeMap<String, String>) -> String {
    let mut s = if solver == Solver::Rve.name() {
        "MPM×DEM".to_owned()
    } else {
        solver.to_uppercase()
    };
    for (p, v) in with {
        s.push_str(&format!(" {}={v}", p.rsplit('.').next().unwrap_or(p)));
    }
    s
}

/// Figures 1 and 2.
fn laws(dir: &Path, fits: &Fits) -> Result<()> {
    let all: Vec<[f64; 2]> = fits.groups.iter().flat_map(|g| g.points.clone()).collect();
    if all.is_empty() {
        return Ok(());
    }
    let lo = all.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
    let hi = all.iter().map(|p| p[0]).fold(0.0, f64::max);
    let span = log_space(lo, hi.max(lo * 1.01), 60);
    let mut runout = Plot::new(
        "runout",
        "Run-out of the collapsed column",
        "aspect ratio a = H_i/L_i",
        "ΔL = (L_f − L_i)/L_i",
    );
    let mut height = Plot::new(
        "height",
        "Final height of the collapsed column",
        "aspect ratio a = H_i/L_i",
        "H_f/L_i",
    );
    runout.log_x = true;
    runout.log_y = true;
    height.log_x = true;
    height.log_y = true;
    let n = fits.groups.len();
    for (k, g) in fits.groups.iter().enumerate() {
        let name = label(g.solver, &g.with);
        let pts = |v: &[[f64; 2]]| v.iter().map(|p| (p[0], p[1])).collect();
        runout
            .series
            .push(Series::markers(&name, pts(&g.points)).coloured(k));
        height
            .series
            .push(Series::markers(&name, pts(&g.heights)).coloured(k));
        if let Some(law) = &g.law {
            let curve = span
                .iter()
                .map(|&a| {
                    let l = if a < law.crossover {
                        &law.small
                    } else {
                        &law.large
                    };
                    (a, l.at(a))
                })
                .collect();
            let fit = format!(
                "{name} fit: {:.2}a | {:.2}a^{:.2}, a_c = {:.2}",
                law.small.lambda, law.large.lambda, law.large.alpha, law.crossover
            );
            runout.series.push(Series::line(&fit, curve).coloured(k));
        }
    }
    for (r, law) in REFERENCE_LAWS.iter().enumerate() {
        let curve = span.iter().map(|&a| (a, law.at(a))).collect();
        let name = format!(
            "{}: {}a | {}a^(2/3)",
            law.source.split(" (").next().unwrap_or(law.source),
            law.small_lambda,
            law.large_lambda
        );
        runout
            .series
            .push(Series::line(&name, curve).coloured(n + r));
    }
    let exp = span
        .iter()
        .map(|&a| {
            (
                a,
                if a < 0.7 {
                    a
                } else {
                    0.7f64.powf(2.0 / 3.0) * a.cbrt()
                },
            )
        })
        .collect();
    height
        .series
        .push(Series::line("a (a < 0.7), ∝ a^(1/3) above (experiments)", exp).coloured(n));
    write(dir, &runout)?;
    write(dir, &height)
}

/// The nominal aspect ratio of a case (its varied value), else the measured one.
fn nominal_a(c: &CaseResult, o: &CollapseOutcome) -> f64 {
    c.case
        .labels
        .iter()
        .find(|(p, _)| p == "column.aspect_ratio")
        .and_then(|(_, v)| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
        .unwrap_or(o.aspect_ratio)
}

/// Figure 3.
fn fronts(dir: &Path, cases: &[CaseResult]) -> Result<()> {
    let mut done: Vec<(&CaseResult, &CollapseOutcome)> = cases
        .iter()
        .filter_map(|c| c.outcome.as_ref().ok().map(|o| (c, o)))
        .collect();
    if done.is_empty() {
        return Ok(());
    }
    done.sort_by(|p, q| nominal_a(p.0, p.1).total_cmp(&nominal_a(q.0, q.1)));
    let mut nominal: Vec<f64> = done.iter().map(|(c, o)| nominal_a(c, o)).collect();
    nominal.dedup();
    let dem_a: Vec<f64> = done
        .iter()
        .filter(|(c, _)| c.case.solver == Solver::Dem)
        .map(|(c, o)| nominal_a(c, o))
        .collect();
    // MPM cases that differ in more than a (e.g. points per cell) get one marker shape per
    // such group, named once in the legend; so is the MPM×DEM line style.
    let group = |c: &CaseResult| -> String {
        c.case
            .labels
            .iter()
            .filter(|(p, _)| p != "column.aspect_ratio")
            .map(|(p, v)| format!("{} = {v}", p.rsplit('.').next().unwrap_or(p)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut groups: Vec<String> = Vec::new();
    for c in cases.iter().filter(|c| c.case.solver == Solver::Mpm) {
        if !groups.contains(&group(c)) {
            groups.push(group(c));
        }
    }
    let (mut named, mut named_rve) = (vec![false; groups.len()], false);
    let mut plot = Plot::new(
        "front",
        "Run-out against time: DEM lines, MPM markers, MPM×DEM dashed, one colour per a",
        "t/τ_c",
        "(L − L_i)/L_i",
    );
    for (c, o) in done {
        let table = CsvTable::read(&c.dir.join("timeseries.csv"))?;
        let (Some(t), Some(l)) = (table.column("t_over_tc"), table.column("runout")) else {
            continue;
        };
        let pts: Vec<(f64, f64)> = t
            .iter()
            .zip(&l)
            .map(|(&t, &l)| (t, l / o.l_i - 1.0))
            .collect();
        let a = nominal_a(c, o);
        let colour = nominal.iter().position(|&v| v == a).unwrap_or(0);
        let name = format!("a = {a}");
        plot.series.push(
            match c.case.solver {
                Solver::Dem => Series::line(&name, pts).decimated(400),
                Solver::Mpm => {
                    let g = groups.iter().position(|g| *g == group(c)).unwrap_or(0);
                    // The DEM line of the same colour names the aspect ratio; a group is
                    // named by its first series.
                    let label = match (dem_a.contains(&a), groups[g].is_empty()) {
                        (true, true) => String::new(),
                        (true, false) if named[g] => String::new(),
                        (true, false) => format!("MPM {}", groups[g]),
                        (false, true) => format!("MPM {name}"),
                        (false, false) => format!("MPM {name}, {}", groups[g]),
                    };
                    named[g] = true;
                    Series::markers(&label, pts).decimated(40).shaped(g)
                }
                Solver::Rve if dem_a.contains(&a) => {
                    let label = if named_rve { "" } else { "MPM×DEM" };
                    named_rve = true;
                    Series::dashed(label, pts).decimated(400)
                }
                Solver::Rve => Series::dashed(&format!("MPM×DEM {name}"), pts).decimated(400),
            }
            .coloured(colour),
        );
    }
    write(dir, &plot)
}

/// Figure 4 for one case.
fn energy(dir: &Path, c: &CaseResult, o: &CollapseOutcome) -> Result<()> {
    let table = CsvTable::read(&c.dir.join("timeseries.csv"))?;
    let col = |n: &str| table.column(n);
    let (Some(t), Some(pot)) = (col("t_over_tc"), col("potential")) else {
        return Ok(());
    };
    let scale = o.energy.potential_released;
    if scale <= 0.0 {
        return Ok(());
    }
    let rel = |v: &[f64], base: f64| -> Vec<(f64, f64)> {
        t.iter()
            .zip(v)
            .map(|(&t, &e)| (t, (e - base) / scale))
            .collect()
    };
    let released: Vec<f64> = pot.iter().map(|p| pot[0] - p).collect();
    let mut kinetic = col("kinetic").unwrap_or_default();
    if let Some(rot) = col("rotational") {
        kinetic.iter_mut().zip(rot).for_each(|(k, r)| *k += r);
    }
    let solver = c.case.solver.name().to_uppercase();
    let mut plot = Plot::new(
        &format!("energy_{}", c.case.name),
        &format!("Energy budget, {solver}, a = {:.2}", o.aspect_ratio),
        "t/τ_c",
        "energy / potential energy released by the end",
    );
    plot.series
        .push(Series::line("potential released", rel(&released, 0.0)).coloured(0));
    plot.series
        .push(Series::line("kinetic", rel(&kinetic, 0.0)).coloured(1));
    for (k, (column, name)) in [
        ("dissipated_normal", "collisions"),
        ("dissipated_friction", "friction"),
        ("dissipated_rolling", "rolling resistance"),
        ("dissipated_plastic", "plastic flow"),
    ]
    .into_iter()
    .enumerate()
    {
        if let Some(v) = col(column) {
            let base = v.first().copied().unwrap_or(0.0);
            plot.series
                .push(Series::line(name, rel(&v, base)).coloured(2 + k));
        }
    }
    plot.series = plot.series.into_iter().map(|s| s.decimated(400)).collect();
    write(dir, &plot)
}

/// Figure 4: each solver's shortest and tallest column (of the first group).
fn energies(dir: &Path, cases: &[CaseResult]) -> Result<()> {
    for solver in Solver::ALL {
        let mine: Vec<(&CaseResult, &CollapseOutcome)> = cases
            .iter()
            .filter(|c| c.case.solver == solver)
            .filter_map(|c| c.outcome.as_ref().ok().map(|o| (c, o)))
            .collect();
        let by_a = |p: &&(&CaseResult, &CollapseOutcome), q: &&(&CaseResult, &CollapseOutcome)| {
            p.1.aspect_ratio.total_cmp(&q.1.aspect_ratio)
        };
        let (Some(short), Some(tall)) = (mine.iter().min_by(by_a), mine.iter().max_by(by_a)) else {
            continue;
        };
        energy(dir, short.0, short.1)?;
        if tall.0.case.name != short.0.case.name {
            energy(dir, tall.0, tall.1)?;
        }
    }
    Ok(())
}

/// Writes every figure of the sweep into `dir`.
pub fn write_all(dir: &Path, cases: &[CaseResult], fits: &Fits) -> Result<()> {
    laws(dir, fits)?;
    fronts(dir, cases)?;
    energies(dir, cases)
}
