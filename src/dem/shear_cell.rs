//! Periodic simple shear at an imposed normal stress (Lees–Edwards boundaries): the
//! rate-dependent friction μ(I) and solid fraction φ(I) of a DEM material (GDR MiDi 2004;
//! da Cruz et al. 2005 for 2-D disks).
//!
//! **Cell.** A box L_x × L_y, periodic in x. In y the images of the cell are displaced in x by
//! ±Δ(t) and move at ±γ̇ L_y (Lees & Edwards 1972), Δ(t) = γ̇ L_y t: the image of grain j in
//! the cell above sits at (x_j + Δ, y_j + L_y) with velocity v_j + γ̇ L_y **e**_x. A grain that
//! leaves through the top re-enters at the bottom with x − Δ and v_x − γ̇ L_y (and the
//! reverse). Every pair interacts through its minimum image, so the cell must be wider and
//! taller than two cut-off distances. The flow is driven by the boundaries alone; the grains
//! start on the linear profile u_x = γ̇ (y − L_y/2) and the mean shear rate is γ̇ whatever
//! the profile (the velocity jump across the cell is γ̇ L_y).
//!
//! **Normal stress.** The height follows a first-order (Berendsen et al. 1984) barostat on the
//! measured normal stress σ_n = −σ_yy (compression positive): each step L_y and every y are scaled by 1 + ε̇_yy Δt with
//! ε̇_yy = β γ̇ (σ_n − P)/P, β = 0.3, capped at |ε̇_yy| ≤ γ̇ ([`crate::scenario::dem::shear`]). The gain
//! is constant, so a stationary height (⟨ε̇_yy⟩ = 0) means ⟨σ_n⟩ = P. Gains that follow the
//! state bias the mean: with the contact network's affine stiffness in the gain, the jammed
//! phases (high σ_n, stiff) relax slower than the loose ones, and σ_n settled at 1.3 P at
//! I = 0.1; β = 0.003 had not finished the dilatancy transient in 4 strain units. With
//! β = 0.3 the mean σ_n per unit strain stays within 3 % of P from γ = 1 on at I = 0.003–0.1
//! (1000 and 300 grains). The preparation compresses a dilute square lattice isotropically at
//! a fixed rate until the mean stress reaches P.
//!
//! **Stress** (tension positive, the code's one convention; Love–Weber plus the kinetic part):
//! σ_ab = −(1/(L_x L_y t)) [Σ_c f_a l_b + Σ_i m_i v′_a v′_b], over contacts c with f the force
//! on i, **l** = **x**_i − **x**_j (minimum image), and v′ = v − γ̇ (y − L_y/2) **e**_x the
//! fluctuation. The reported [`ShearPoint`] is in soil-mechanics terms: normal stresses
//! compression positive (−σ_xx, −σ_yy) and the shear stress τ = ½(σ_xy + σ_yx) (> 0 for γ̇ > 0).
//!
//! **Measured:** μ = τ/σ_n and I = γ̇ d̄/√(σ_n/ρ_s) (GDR MiDi); and the 2-D Mohr–Coulomb
//! mobilised friction sin φ = √(((σ_xx − σ_yy)/2)² + τ²)/p, p = −(σ_xx + σ_yy)/2, with
//! I_p = γ̇ d̄/√(p/ρ_s): the pair a plane-strain continuum uses (the biaxial test's sin φ).
//!
//! Integration is velocity Verlet with the contact law of [`crate::dem::contact`] (mid-step
//! and predictor velocities, onset/end trapezoids) as in [`crate::dem::solver`]; the pair
//! list is a Verlet list rebuilt by an O(N²) minimum-image search (fine for the ≤ 2000 grains
//! of a representative volume) when the grains' displacement from the mean flow, plus the
//! flow's own relative shift γ̇ r_c t over the cut-off r_c, exceeds the skin.

use super::contact::{ContactParams, ContactState, Law};
use super::periodic_cell::{carry_history, disk_motion, pairs_within, scatter, Tensor};

/// The periodic cell and its grains (structure of arrays).
pub struct Cell {
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    w: Vec<f64>,
    r: Vec<f64>,
    m: Vec<f64>,
    j: Vec<f64>,
    /// True forces F_k and torques at the last evaluation.
    f: Vec<[f64; 3]>,
    /// Displacement from the mean flow since the last list build.
    disp: Vec<[f64; 2]>,
    /// Pairs (i < j) sorted, with their contact state.
    pairs: Vec<(u32, u32)>,
    state: Vec<ContactState>,
    law: Law,
    /// L_x, L_y (m), Lees–Edwards offset Δ (m, in [0, L_x)), shear rate γ̇ (1/s).
    pub lx: f64,
    /// See `lx`.
    pub ly: f64,
    offset: f64,
    gdot: f64,
    thickness: f64,
    dt: f64,
    skin: f64,
    /// Time since the last list build (for the flow's own shift) and the sum of the relative
    /// changes of L_x and L_y since then (for the affine scaling).
    since_build: f64,
    scaled_since_build: f64,
    /// Scratch: the forces of this step's second half-kick, and the next true forces.
    f_end: Vec<[f64; 3]>,
    f_new: Vec<[f64; 3]>,
    /// Contact part of Σ f_a l_b at the last evaluation: xx, xy, yx, yy; touching pairs.
    virial: [f64; 4],
    contacts: usize,
    /// Steps taken.
    pub steps: u64,
}

impl Cell {
    /// A cell of `lx` × `ly` holding disks at (x, y) with radii `r`, masses ρ_s π r² t, at rest,
    /// with contact law `contact`, time step `dt` and Verlet skin `skin`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        x: Vec<f64>,
        y: Vec<f64>,
        r: Vec<f64>,
        density: f64,
        thickness: f64,
        lx: f64,
        ly: f64,
        contact: &ContactParams,
        dt: f64,
        skin: f64,
    ) -> Self {
        let n = x.len();
        let m: Vec<f64> = r
            .iter()
            .map(|r| density * std::f64::consts::PI * r * r * thickness)
            .collect();
        let j = m.iter().zip(&r).map(|(m, r)| 0.5 * m * r * r).collect();
        let mut c = Cell {
            x,
            y,
            vx: vec![0.0; n],
            vy: vec![0.0; n],
            w: vec![0.0; n],
            r,
            m,
            j,
            f: vec![[0.0; 3]; n],
            disp: vec![[0.0; 2]; n],
            pairs: Vec::new(),
            state: Vec::new(),
            law: Law::from(contact),
            lx,
            ly,
            offset: 0.0,
            gdot: 0.0,
            thickness,
            dt,
            skin,
            since_build: 0.0,
            scaled_since_build: 0.0,
            f_end: vec![[0.0; 3]; n],
            f_new: vec![[0.0; 3]; n],
            virial: [0.0; 4],
            contacts: 0,
            steps: 0,
        };
        c.build();
        c.forces(0.0, false);
        c
    }

    /// Number of grains.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the cell holds no grain.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Replace the contact law (history kept).
    pub fn set_law(&mut self, contact: &ContactParams) {
        self.law = Law::from(contact);
    }

    /// Impose the shear rate γ̇ and put every grain's velocity on the profile
    /// u_x = γ̇ (y − L_y/2) plus its fluctuation about the previous profile.
    pub fn set_shear_rate(&mut self, gdot: f64) {
        for i in 0..self.len() {
            self.vx[i] += (gdot - self.gdot) * (self.y[i] - 0.5 * self.ly);
        }
        self.gdot = gdot;
        self.forces(0.0, false);
    }

    /// Rebuild the pair list (pairs within R_i + R_j + skin), carrying the contact history
    /// of the pairs kept over by a merge of the two sorted lists.
    fn build(&mut self) {
        let (lx, ly, offset) = (self.lx, self.ly, self.offset);
        let pairs = pairs_within(&self.x, &self.y, &self.r, self.skin, |dx, dy| {
            let (dx, dy, _) = min_image(dx, dy, lx, ly, offset);
            (dx, dy)
        });
        self.state = carry_history(&self.pairs, &self.state, &pairs);
        self.pairs = pairs;
        self.disp.iter_mut().for_each(|d| *d = [0.0; 2]);
        self.since_build = 0.0;
        self.scaled_since_build = 0.0;
    }

    /// Whether a pair outside the list may touch: 2 max|displacement from the flow| plus the
    /// flow's shift and the affine scaling across the cut-off since the build exceed the skin.
    fn needs_build(&self) -> bool {
        let d2 = self
            .disp
            .iter()
            .map(|d| d[0] * d[0] + d[1] * d[1])
            .fold(0.0, f64::max);
        let cutoff = 2.0 * self.r.iter().copied().fold(0.0, f64::max) + self.skin;
        let affine = self.gdot.abs() * self.since_build + self.scaled_since_build;
        2.0 * d2.sqrt() + cutoff * affine > self.skin
    }

    /// Resolve every pair over a step `h` (0: evaluate without advancing springs), with the
    /// grains' current (mid-step) velocities and the predictor v* = v + ½Δt F_k/m. Writes the
    /// true forces F_{k+1} into `f`; with `kick`, first applies the second half-kick with the
    /// forces of this step (which differ at onset and end steps, the contact law's trapezoids).
    fn forces(&mut self, h: f64, kick: bool) {
        let n = self.len();
        let half = if h > 0.0 { 0.5 * self.dt } else { 0.0 };
        let (fe, ft, f) = (&mut self.f_end, &mut self.f_new, &self.f);
        fe.clear();
        fe.resize(n, [0.0; 3]);
        ft.clear();
        ft.resize(n, [0.0; 3]);
        let mut vir = [0.0; 4];
        let mut contacts = 0;
        let shift_v = self.gdot * self.ly;
        let (x, y, vx, vy, w) = (&self.x, &self.y, &self.vx, &self.vy, &self.w);
        let (rad, m, inertia) = (&self.r, &self.m, &self.j);
        let (lx, ly, offset) = (self.lx, self.ly, self.offset);
        for (k, &(i, j)) in self.pairs.iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let (dx, dy, ky) = min_image(x[j] - x[i], y[j] - y[i], lx, ly, offset);
            let (ri, rj) = (rad[i], rad[j]);
            let rs = ri + rj;
            let st = &mut self.state[k];
            let d2 = dx * dx + dy * dy;
            if d2 >= rs * rs && !st.touching() {
                *st = ContactState::default();
                continue;
            }
            let d = d2.sqrt();
            let (nx, ny) = if d > 0.0 {
                (dx / d, dy / d)
            } else {
                (1.0, 0.0)
            };
            let (mi, mj) = (m[i], m[j]);
            // Mid-step and predictor velocities of i relative to j's image.
            let (dvx, dvy) = (vx[i] - vx[j] - ky * shift_v, vy[i] - vy[j]);
            let (ex, ey) = (
                dvx + half * (f[i][0] / mi - f[j][0] / mj),
                dvy + half * (f[i][1] / mi - f[j][1] / mj),
            );
            let (wi, wj) = (w[i], w[j]);
            let (pwi, pwj) = (
                wi + half * f[i][2] / inertia[i],
                wj + half * f[j][2] / inertia[j],
            );
            let (n, r) = ([nx, ny], [ri, rj]);
            let motion = disk_motion(
                d,
                n,
                [[dvx, dvy], [ex, ey]],
                [[wi, pwi], [wj, pwj]],
                [mi, mj],
                r,
            );
            let out = self.law.resolve(&motion, st, h);
            scatter(fe, (i, j), n, r, out.apply);
            let (f0, f1) = scatter(ft, (i, j), n, r, [st.f_n, st.f_t, st.m_r]);
            if st.touching() {
                contacts += 1;
                // l = x_i − x_j = −(dx, dy).
                vir[0] -= f0 * dx;
                vir[1] -= f0 * dy;
                vir[2] -= f1 * dx;
                vir[3] -= f1 * dy;
            }
        }
        if kick {
            let hk = 0.5 * self.dt;
            for i in 0..n {
                self.vx[i] += hk * fe[i][0] / m[i];
                self.vy[i] += hk * fe[i][1] / m[i];
                self.w[i] += hk * fe[i][2] / inertia[i];
            }
        }
        std::mem::swap(&mut self.f, &mut self.f_new);
        self.virial = vir;
        self.contacts = contacts;
    }

    /// One velocity-Verlet step; the height scaled by 1 + `rate_y` Δt and the width by
    /// 1 + `rate_x` Δt (affinely, with the positions).
    pub fn step(&mut self, rate_x: f64, rate_y: f64) {
        let (dt, half) = (self.dt, 0.5 * self.dt);
        let n = self.len();
        for i in 0..n {
            self.vx[i] += half * self.f[i][0] / self.m[i];
            self.vy[i] += half * self.f[i][1] / self.m[i];
            self.w[i] += half * self.f[i][2] / self.j[i];
            let u = self.gdot * (self.y[i] - 0.5 * self.ly);
            self.disp[i][0] += dt * (self.vx[i] - u);
            self.disp[i][1] += dt * self.vy[i];
            self.x[i] += dt * self.vx[i];
            self.y[i] += dt * self.vy[i];
        }
        self.offset = (self.offset + self.gdot * self.ly * dt).rem_euclid(self.lx);
        let (sx, sy) = (1.0 + rate_x * dt, 1.0 + rate_y * dt);
        self.lx *= sx;
        self.ly *= sy;
        self.offset *= sx;
        let shift_v = self.gdot * self.ly;
        for i in 0..n {
            self.x[i] *= sx;
            self.y[i] *= sy;
            if self.y[i] >= self.ly {
                self.y[i] -= self.ly;
                self.x[i] -= self.offset;
                self.vx[i] -= shift_v;
            } else if self.y[i] < 0.0 {
                self.y[i] += self.ly;
                self.x[i] += self.offset;
                self.vx[i] += shift_v;
            }
            self.x[i] = self.x[i].rem_euclid(self.lx);
        }
        self.since_build += dt;
        self.scaled_since_build += (sx - 1.0).abs() + (sy - 1.0).abs();
        if self.needs_build() {
            self.build();
        }
        self.forces(dt, true);
        self.steps += 1;
    }

    /// Cauchy stress (Pa, tension positive) with the kinetic part, and the contacts per grain.
    pub fn stress(&self) -> (Tensor, f64) {
        let v = self.ly * self.lx * self.thickness;
        let mut s = self.virial;
        for i in 0..self.len() {
            let ux = self.vx[i] - self.gdot * (self.y[i] - 0.5 * self.ly);
            let (m, uy) = (self.m[i], self.vy[i]);
            s[0] += m * ux * ux;
            s[1] += m * ux * uy;
            s[2] += m * ux * uy;
            s[3] += m * uy * uy;
        }
        (
            -Tensor::new(s[0], s[1], s[2], s[3]) / v,
            2.0 * self.contacts as f64 / self.len() as f64,
        )
    }

    /// In-plane pressure −(σ_xx + σ_yy)/2 (Pa, compression positive).
    pub fn pressure(&self) -> f64 {
        -0.5 * self.stress().0.trace()
    }

    /// Add every grain's v_x to its bin of y/L_y (`profile[k]` = [Σ v_x, count]).
    pub fn add_profile(&self, profile: &mut [[f64; 2]]) {
        let nb = profile.len();
        for i in 0..self.len() {
            let k = ((self.y[i] / self.ly * nb as f64) as usize).min(nb - 1);
            profile[k][0] += self.vx[i];
            profile[k][1] += 1.0;
        }
    }

    /// Σ π r² / (L_x L_y).
    pub fn packing_fraction(&self) -> f64 {
        let a: f64 = self.r.iter().map(|r| std::f64::consts::PI * r * r).sum();
        a / (self.lx * self.ly)
    }

    /// Positions and velocities (for the tests).
    pub fn grain(&self, i: usize) -> [f64; 4] {
        [self.x[i], self.y[i], self.vx[i], self.vy[i]]
    }

    /// Set a grain's velocity (for the tests).
    pub fn set_velocity(&mut self, i: usize, v: [f64; 2]) {
        self.vx[i] = v[0];
        self.vy[i] = v[1];
        self.forces(0.0, false);
    }

    /// Whether every position and velocity is finite.
    pub fn finite(&self) -> bool {
        self.x
            .iter()
            .chain(&self.y)
            .chain(&self.vx)
            .all(|v| v.is_finite())
    }

    /// The instantaneous state at shear strain `strain`.
    pub fn point(&self, strain: f64) -> ShearPoint {
        let (s, z) = self.stress();
        ShearPoint {
            strain,
            sigma_xx: -s[(0, 0)],
            sigma_yy: -s[(1, 1)],
            tau: 0.5 * (s[(0, 1)] + s[(1, 0)]),
            packing_fraction: self.packing_fraction(),
            coordination: z,
        }
    }
}

/// Minimum image of a separation (dx, dy) = x_j − x_i in a Lees–Edwards cell L_x × L_y with
/// offset Δ: (dx, dy, k_y) with j's image k_y cells up (k_y ∈ {−1, 0, 1} for a pair nearer
/// than L_y/2).
#[inline(always)]
fn min_image(dx: f64, dy: f64, lx: f64, ly: f64, offset: f64) -> (f64, f64, f64) {
    let ky = -(dy / ly).round();
    let dy = dy + ky * ly;
    let dx = dx + ky * offset;
    (super::params::min_image(dx, Some(lx)), dy, ky)
}

/// A block mean of the recorded quantities.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct ShearPoint {
    /// Shear strain γ̇ t at the end of the block.
    pub strain: f64,
    /// Normal stresses −σ_xx, −σ_yy (Pa, compression positive) and the shear stress
    /// τ = ½(σ_xy + σ_yx) (Pa, > 0 for γ̇ > 0), σ the tension-positive Cauchy stress.
    pub sigma_xx: f64,
    /// See `sigma_xx`.
    pub sigma_yy: f64,
    /// See `sigma_xx`.
    pub tau: f64,
    /// Solid fraction Σ πr²/(L_x L_y).
    pub packing_fraction: f64,
    /// Contacts per grain.
    pub coordination: f64,
}

impl ShearPoint {
    pub(crate) fn add(&mut self, o: &ShearPoint, w: f64) {
        self.sigma_xx += w * o.sigma_xx;
        self.sigma_yy += w * o.sigma_yy;
        self.tau += w * o.tau;
        self.packing_fraction += w * o.packing_fraction;
        self.coordination += w * o.coordination;
    }
    /// μ = τ/σ_yy.
    pub fn mu(&self) -> f64 {
        self.tau / self.sigma_yy
    }
    /// Mohr–Coulomb sin φ = √(((σ_xx − σ_yy)/2)² + τ²)/((σ_xx + σ_yy)/2).
    pub fn sin_phi(&self) -> f64 {
        let h = 0.5 * (self.sigma_xx - self.sigma_yy);
        (h * h + self.tau * self.tau).sqrt() / (0.5 * (self.sigma_xx + self.sigma_yy))
    }
}
