//! Lid-driven square cavity against Ghia, Ghia & Shin 1982 (validation cases `cavity-re100`,
//! `cavity-re1000`).
//!
//! The cavity [0, 1]² has resting half-way bounce-back walls and a lid sliding at U along the
//! top. The run stops when the largest change of any velocity component over one lid transit
//! L/U falls below [`STEADY_TOL`]·U (capped by `time.end`). The cell-centred field is
//! interpolated bilinearly to Ghia's coordinates; the primary vortex centre is the minimum of
//! the stream function ψ(x, y) = ∫₀^y u dy', located to sub-cell accuracy by a quadratic fit
//! over the 3×3 cells around the discrete minimum.
//!
//! Gates (the issue; docs/validation.md): max |Δu|, |Δv| ≤ 0.02 U on the centre lines, and the vortex
//! centre within 0.02 L of Ghia's.

use crate::lbm::{Backend, Macroscopic};
use crate::report::{Check, Fidelity, Plot, Report, Series};
use crate::scenario::fluid::Scenario;
use crate::scenario::ScenarioFile;
use crate::Result;

/// Stop when max |Δu| over one lid transit is below this fraction of U. With the slowest
/// decay time ≈ 7 transits at Re 1000 (77 transits take it from O(1) to 1e-5 at 128²), the
/// remaining drift is then ≲ 1e-4 U,
/// two orders below the 0.02 gate.
const STEADY_TOL: f64 = 1e-5;
/// Issue / docs/validation.md: max |Δu|, |Δv| ≤ 0.02 U_lid.
const VELOCITY_TOL: f64 = 0.02;
/// Issue: primary vortex centre within 0.02 of the side.
const CENTRE_TOL: f64 = 0.02;

/// Ghia, Ghia & Shin (1982), Tables I and II (docs/validation.md): u(0.5, y) and v(x, 0.5), U = 1.
struct Ghia {
    /// Reynolds number.
    re: u32,
    /// (y, u) on the vertical centre line.
    u: [(f64, f64); 15],
    /// (x, v) on the horizontal centre line.
    v: [(f64, f64); 15],
    /// Primary vortex centre (x, y).
    centre: (f64, f64),
}

const GHIA_Y: [f64; 15] = [
    0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000, 0.4531, 0.2813, 0.1719, 0.1016,
    0.0703, 0.0625, 0.0547,
];
const GHIA_X: [f64; 15] = [
    0.9688, 0.9609, 0.9531, 0.9453, 0.9063, 0.8594, 0.8047, 0.5000, 0.2344, 0.2266, 0.1563, 0.0938,
    0.0781, 0.0703, 0.0625,
];

const fn zip(a: [f64; 15], b: [f64; 15]) -> [(f64, f64); 15] {
    let mut out = [(0.0, 0.0); 15];
    let mut i = 0;
    while i < 15 {
        out[i] = (a[i], b[i]);
        i += 1;
    }
    out
}

const GHIA_100: Ghia = Ghia {
    re: 100,
    u: zip(
        GHIA_Y,
        [
            0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581, -0.21090,
            -0.15662, -0.10150, -0.06434, -0.04775, -0.04192, -0.03717,
        ],
    ),
    v: zip(
        GHIA_X,
        [
            -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454, 0.17527,
            0.17507, 0.16077, 0.12317, 0.10890, 0.10091, 0.09233,
        ],
    ),
    centre: (0.6172, 0.7344),
};

const GHIA_1000: Ghia = Ghia {
    re: 1000,
    u: zip(
        GHIA_Y,
        [
            0.65928, 0.57492, 0.51117, 0.46604, 0.33304, 0.18719, 0.05702, -0.06080, -0.10648,
            -0.27805, -0.38289, -0.29730, -0.22220, -0.20196, -0.18109,
        ],
    ),
    v: zip(
        GHIA_X,
        [
            -0.21388, -0.27669, -0.33714, -0.39188, -0.51550, -0.42665, -0.31966, 0.02526, 0.32235,
            0.33075, 0.37095, 0.32627, 0.30353, 0.29012, 0.27485,
        ],
    ),
    centre: (0.5313, 0.5625),
};

/// A steady cavity field in lattice units, velocities divided by the lid speed.
struct Field {
    n: usize,
    u: Vec<f64>,
    v: Vec<f64>,
    /// Steps taken to reach the steady state.
    steps: u64,
    /// Last max |Δu|/U over one transit.
    residual: f64,
}

impl Field {
    /// Bilinear interpolation of `f` (cell-centred) at (x, y) in units of the side.
    fn at(&self, f: &[f64], x: f64, y: f64) -> f64 {
        let n = self.n;
        let locate = |s: f64| {
            let p = (s * n as f64 - 0.5).clamp(0.0, (n - 1) as f64 - 1e-9);
            let i = p.floor() as usize;
            (i.min(n - 2), p - i.min(n - 2) as f64)
        };
        let ((i, tx), (j, ty)) = (locate(x), locate(y));
        let g = |i: usize, j: usize| f[j * n + i];
        (1.0 - ty) * ((1.0 - tx) * g(i, j) + tx * g(i + 1, j))
            + ty * ((1.0 - tx) * g(i, j + 1) + tx * g(i + 1, j + 1))
    }

    /// Stream function ψ(x_i, y_j) = ∫₀^{y_j} u dy (midpoint rule, lattice units × U).
    fn stream_function(&self) -> Vec<f64> {
        let n = self.n;
        let mut psi = vec![0.0; n * n];
        for i in 0..n {
            let mut acc = 0.0;
            for j in 0..n {
                psi[j * n + i] = acc + 0.5 * self.u[j * n + i];
                acc += self.u[j * n + i];
            }
        }
        psi
    }

    /// Position of the minimum of ψ in units of the side, refined by a quadratic fit.
    fn vortex_centre(&self) -> (f64, f64) {
        let n = self.n;
        let psi = self.stream_function();
        let c = (0..n * n)
            .filter(|c| (1..n - 1).contains(&(c % n)) && (1..n - 1).contains(&(c / n)))
            .min_by(|&a, &b| psi[a].total_cmp(&psi[b]))
            .unwrap_or(n * n / 2);
        let (i, j) = (c % n, c / n);
        let p = |di: i64, dj: i64| psi[(j as i64 + dj) as usize * n + (i as i64 + di) as usize];
        let (gx, gy) = (0.5 * (p(1, 0) - p(-1, 0)), 0.5 * (p(0, 1) - p(0, -1)));
        let hxx = p(1, 0) - 2.0 * p(0, 0) + p(-1, 0);
        let hyy = p(0, 1) - 2.0 * p(0, 0) + p(0, -1);
        let hxy = 0.25 * (p(1, 1) - p(1, -1) - p(-1, 1) + p(-1, -1));
        let det = hxx * hyy - hxy * hxy;
        let (dx, dy) = if det > 0.0 {
            (
                ((-hyy * gx + hxy * gy) / det).clamp(-1.0, 1.0),
                ((hxy * gx - hxx * gy) / det).clamp(-1.0, 1.0),
            )
        } else {
            (0.0, 0.0)
        };
        (
            (i as f64 + 0.5 + dx) / n as f64,
            (j as f64 + 0.5 + dy) / n as f64,
        )
    }
}

/// Run the scenario at `cells`² until steady (Δt ∝ Δx keeps the lattice lid speed).
fn solve(text: &str, cells: usize, backend: Backend) -> Result<Field> {
    let mut sc = Scenario::from_toml(text)?;
    sc.lbm.backend = backend;
    let l = sc.domain.size[0];
    let dx = l / cells as f64;
    if let Some(dt) = sc.time.dt.as_mut() {
        *dt *= dx / sc.domain.dx;
    }
    sc.domain.dx = dx;
    let d = sc.derive()?;
    let mut lbm = sc.build_f64(&d)?;
    let n = d.cells[0];
    let u_lid = d.u_lattice;
    let transit = (n as f64 / u_lid).round() as u64;
    let mut m = Macroscopic::default();
    let mut prev = (vec![0.0; n * n], vec![0.0; n * n]);
    let mut residual = f64::INFINITY;
    while lbm.step_count() < d.steps {
        let chunk = transit.min(d.steps - lbm.step_count());
        lbm.steps(chunk);
        lbm.macroscopic(&mut m);
        lbm.check_stable(0.5)?;
        residual = max_change(&m.ux, &prev.0).max(max_change(&m.uy, &prev.1)) / u_lid;
        prev = (m.ux.clone(), m.uy.clone());
        if residual < STEADY_TOL {
            break;
        }
    }
    let scale = |v: &[f64]| v.iter().map(|x| x / u_lid).collect();
    Ok(Field {
        n,
        u: scale(&m.ux),
        v: scale(&m.uy),
        steps: lbm.step_count(),
        residual,
    })
}

fn max_change(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Compare a steady field with Ghia's tables.
fn compare(name: &str, field: &Field, ghia: &Ghia) -> Vec<Check> {
    let n = field.n;
    let du = ghia
        .u
        .iter()
        .map(|&(y, u)| (field.at(&field.u, 0.5, y) - u).abs())
        .fold(0.0, f64::max);
    let dv = ghia
        .v
        .iter()
        .map(|&(x, v)| (field.at(&field.v, x, 0.5) - v).abs())
        .fold(0.0, f64::max);
    let (cx, cy) = field.vortex_centre();
    let re = ghia.re;
    vec![
        Check::at_most(
            name,
            &format!("Re {re}, {n}²: max |u − u_Ghia|/U on x = 0.5"),
            du,
            VELOCITY_TOL,
        ),
        Check::at_most(
            name,
            &format!("Re {re}, {n}²: max |v − v_Ghia|/U on y = 0.5"),
            dv,
            VELOCITY_TOL,
        ),
        Check::abs(
            name,
            &format!("Re {re}, {n}²: primary vortex centre x/L"),
            cx,
            ghia.centre.0,
            CENTRE_TOL,
        ),
        Check::abs(
            name,
            &format!("Re {re}, {n}²: primary vortex centre y/L"),
            cy,
            ghia.centre.1,
            CENTRE_TOL,
        ),
        Check::report(
            name,
            &format!("Re {re}, {n}²: steps to steady state"),
            field.steps as f64,
            0.0,
        ),
        // The run must have reached the steady state rather than the cap.
        Check::at_most(
            name,
            &format!("Re {re}, {n}²: max |Δu|/U over the last transit"),
            field.residual,
            STEADY_TOL,
        ),
    ]
}

/// u on the vertical and v on the horizontal centre line beside Ghia's points.
fn plots(name: &str, field: &Field, ghia: &Ghia) -> Vec<Plot> {
    let (n, re) = (field.n, ghia.re);
    let s = |k: usize| (k as f64 + 0.5) / n as f64;
    let u_line = (0..n)
        .map(|k| (field.at(&field.u, 0.5, s(k)), s(k)))
        .collect();
    let v_line = (0..n)
        .map(|k| (s(k), field.at(&field.v, s(k), 0.5)))
        .collect();
    let u = Plot::new(
        &format!("{name}-u"),
        &format!("Lid-driven cavity, Re {re}, {n}²: u on x = 0.5"),
        "u / U",
        "y / L",
    )
    .with(Series::line("LBM", u_line))
    .with(Series::markers(
        "Ghia et al. 1982",
        ghia.u.iter().map(|&(y, u)| (u, y)).collect(),
    ));
    let v = Plot::new(
        &format!("{name}-v"),
        &format!("Lid-driven cavity, Re {re}, {n}²: v on y = 0.5"),
        "x / L",
        "v / U",
    )
    .with(Series::line("LBM", v_line))
    .with(Series::markers("Ghia et al. 1982", ghia.v.to_vec()));
    vec![u, v]
}

fn cells(f: Fidelity) -> usize {
    match f {
        Fidelity::Test => 128,
        Fidelity::Full => 256,
    }
}

/// Re 100 (BGK).
pub fn run_re100(f: Fidelity) -> Result<Report> {
    re100_on(f, Backend::Cpu)
}

/// Re 100 on `backend`.
pub fn re100_on(f: Fidelity, backend: Backend) -> Result<Report> {
    let field = solve(
        include_str!("../../../../models/lbm/cavity_re100.toml"),
        cells(f),
        backend,
    )?;
    Ok(Report {
        checks: compare("cavity-re100", &field, &GHIA_100),
        plots: plots("cavity-re100", &field, &GHIA_100),
    })
}

/// Re 1000 (MRT).
pub fn run_re1000(f: Fidelity) -> Result<Report> {
    re1000_on(f, Backend::Cpu)
}

/// Re 1000 on `backend`.
pub fn re1000_on(f: Fidelity, backend: Backend) -> Result<Report> {
    let field = solve(
        include_str!("../../../../models/lbm/cavity_re1000.toml"),
        cells(f),
        backend,
    )?;
    Ok(Report {
        checks: compare("cavity-re1000", &field, &GHIA_1000),
        plots: plots("cavity-re1000", &field, &GHIA_1000),
    })
}
