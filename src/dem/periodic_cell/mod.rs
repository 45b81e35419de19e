//! A bi-periodic DEM cell under an imposed homogeneous deformation: the representative volume
//! of a granular material (Lees–Edwards boundaries generalised to any in-plane velocity
//! gradient; Miehe et al. 2010, Liang & Zhao 2019).
//!
//! **Cell.** The cell is the parallelogram spanned by the columns **a**, **b** of the cell
//! matrix H (m); a grain at **x** has images at **x** + H **n** for every integer pair **n**.
//! Every pair interacts through its minimum image, found in fractional coordinates:
//! **d** = H(**s** − round(**s**)) with **s** = H⁻¹(**x**_j − **x**_i), exact while the basis is
//! reduced (|**a**·**b**| ≤ ½ min(|**a**|², |**b**|²): Lagrange–Gauss reduction is applied
//! whenever the deformation skews the cell further; it changes the basis, not the lattice of
//! images) and the cell is wider than two cut-offs across each pair of sides.
//!
//! **Re-tiling.** A cell stretched along one axis grows thin across the other; when it is no
//! wider than two cut-offs there, it is re-tiled: the same periodic packing is described by a
//! cell twice as thick holding each grain and a copy of it one period over (contact springs
//! mapped to the image pairs they belong to), so the stress is continuous and the volume costs
//! twice as much from then on. A cell is refused past [`MAX_TILES`] copies.
//!
//! **Motion.** With an imposed velocity gradient L (1/s), the grains move with the affine
//! field L**x** plus their fluctuation **u**: per step of size h,
//! **x** ← **x** + h(**u** + L**x**) and H ← (I + hL) H, so the cell and the grains deform
//! together and a grain that leaves through one side re-enters through the opposite one with the
//! same fluctuation velocity. The fluctuations follow Newton's law du/dt = F/m with the contact
//! forces (velocity Verlet, the contact law of [`crate::dem::contact`] with its mid-step and
//! predictor velocities and onset/end trapezoids, as in [`crate::dem::solver`]); the relative
//! velocity of grain i and the image of j at branch **d** = **x**_j − **x**_i is
//! **u**_i − **u**_j − L**d**, and a grain spins at its own ω plus the affine spin
//! Ω = ½(L_yx − L_xy) in the contact's tangential slip. There is no gravity.
//!
//! **Stress and energy** (tension positive, the one convention of the code, see
//! docs/architecture.md): the Love–Weber stress with the kinetic part,
//! σ = −(1/(A t)) [Σ_c **f**_c ⊗ **l**_c + Σ_i m_i **u**_i ⊗ **u**_i], A = det H, t the disks'
//! axial length, **f**_c the force on i and **l**_c = **x**_i − **x**_j (minimum image). The
//! power the deformation feeds in is A t σ_c : L (σ_c the contact part): with the spring
//! energy U and the fluctuation kinetic energy K, d(K + U)/dt = A t σ_c : L − D, D the rate the
//! contacts dissipate. [`PeriodicCell::energy`] books each term (work by the trapezoid rule
//! over each step). The fabric tensor is (1/N_c) Σ_c **n** ⊗ **n** over touching pairs.
//!
//! The pair list is a Verlet list rebuilt by an O(N²) minimum-image search (fine for the few
//! hundred grains of a representative volume) when twice the largest fluctuation displacement
//! plus the affine change of the cut-off, r_c Σ h‖L‖, exceeds the skin.

mod pairs;
mod prepare;

pub(crate) use pairs::{carry_history, disk_motion, pairs_within, scatter};
pub use prepare::{Preparation, Prepared, Servo, Target};

use nalgebra::{Matrix2, Vector2};

use super::contact::{ContactParams, ContactState, Law};

/// A 2×2 tensor (cell matrix, velocity gradient, stress, fabric).
pub type Tensor = Matrix2<f64>;

/// Energies of a cell (J, per cell of axial length t).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellEnergy {
    /// Work fed in by the deformation, Σ A t σ_c : L h (trapezoid over each step).
    pub work: f64,
    /// Energy in the normal, tangential and rolling springs now.
    pub stored: f64,
    /// Kinetic energy of the fluctuations, Σ ½ m |u|² + ½ J ω².
    pub kinetic: f64,
    /// Dissipated by the contacts (dashpots, sliding, rolling slip) so far.
    pub dissipated: f64,
}

/// The cell and its grains (structure of arrays).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct PeriodicCell {
    x: Vec<f64>,
    y: Vec<f64>,
    ux: Vec<f64>,
    uy: Vec<f64>,
    w: Vec<f64>,
    r: Vec<f64>,
    m: Vec<f64>,
    j: Vec<f64>,
    /// True forces and torques at the last evaluation, and the scratch of the next ones.
    f: Vec<[f64; 3]>,
    f_end: Vec<[f64; 3]>,
    f_new: Vec<[f64; 3]>,
    /// Fluctuation displacement since the last list build.
    disp: Vec<[f64; 2]>,
    /// Pairs (i < j), sorted, with their contact state.
    pairs: Vec<(u32, u32)>,
    state: Vec<ContactState>,
    law: Law,
    cell: Tensor,
    grad: Tensor,
    dt: f64,
    skin: f64,
    thickness: f64,
    cutoff: f64,
    /// Σ h‖L‖ since the last list build.
    strain_since_build: f64,
    /// Σ_c f ⊗ l of the touching pairs, Σ_c n ⊗ n, and their count, at the last evaluation.
    virial: Tensor,
    fabric: Tensor,
    contacts: usize,
    stored: f64,
    dissipated: f64,
    work: f64,
    /// The deepest overlap relative to the smaller radius at the last evaluation.
    deepest: f64,
    steps: u64,
    /// Copies of the original packing the cell holds (1, 2, 4, …; see `retile`).
    tiles: u32,
}

/// Most copies of its packing a cell may grow to by re-tiling (three re-tilings, each
/// doubling the cell's cost).
pub const MAX_TILES: u32 = 8;

/// Largest overlap relative to the smaller radius before the cell refuses to go on (grains
/// passing through each other).
pub const CELL_OVERLAP_LIMIT: f64 = 0.5;

impl PeriodicCell {
    /// A cell with matrix `cell` holding disks at (x, y) with radii `r`, masses ρ_s π r² t, at
    /// rest, with contact law `contact`, time step `dt` and Verlet skin `skin` (m).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        x: Vec<f64>,
        y: Vec<f64>,
        r: Vec<f64>,
        density: f64,
        thickness: f64,
        cell: Tensor,
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
        let cutoff = 2.0 * r.iter().copied().fold(0.0, f64::max) + skin;
        let mut c = PeriodicCell {
            x,
            y,
            ux: vec![0.0; n],
            uy: vec![0.0; n],
            w: vec![0.0; n],
            r,
            m,
            j,
            f: vec![[0.0; 3]; n],
            f_end: vec![[0.0; 3]; n],
            f_new: vec![[0.0; 3]; n],
            disp: vec![[0.0; 2]; n],
            law: Law::from(contact),
            cell,
            dt,
            skin,
            thickness,
            cutoff,
            tiles: 1,
            ..Default::default()
        };
        c.wrap();
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

    /// The cell matrix H (columns: the cell's side vectors, m).
    pub fn cell(&self) -> &Tensor {
        &self.cell
    }

    /// Axial length t of the disks (m).
    pub fn thickness(&self) -> f64 {
        self.thickness
    }

    /// The DEM step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Copies of the original packing the cell holds: 1, doubled by each re-tiling.
    pub fn tiles(&self) -> u32 {
        self.tiles
    }

    /// Stop every grain (fluctuation velocities and spins to zero) and re-evaluate the forces:
    /// a quench of the preparation, so that rattlers (grains without contacts, which nothing
    /// slows down) come to rest.
    pub fn stop(&mut self) {
        self.ux.iter_mut().for_each(|u| *u = 0.0);
        self.uy.iter_mut().for_each(|u| *u = 0.0);
        self.w.iter_mut().for_each(|w| *w = 0.0);
        self.forces(0.0, false);
    }

    /// Replace the contact law (history kept) and re-evaluate the forces.
    pub fn set_law(&mut self, contact: &ContactParams) {
        self.law = Law::from(contact);
        self.forces(0.0, false);
    }

    /// Cell area A = det H (m²).
    pub fn area(&self) -> f64 {
        self.cell.determinant()
    }

    /// Σ π r² / A.
    pub fn packing_fraction(&self) -> f64 {
        let a: f64 = self.r.iter().map(|r| std::f64::consts::PI * r * r).sum();
        a / self.area()
    }

    /// Bulk density Σ m / (A t) = ρ_s φ (kg/m³).
    pub fn bulk_density(&self) -> f64 {
        self.m.iter().sum::<f64>() / (self.area() * self.thickness)
    }

    /// The affine (Voigt) P-wave modulus, the larger of C_xxxx and C_yyyy with
    /// C_aaaa = (1/(A t)) Σ_c |**l**|² (k_n n_a⁴ + k_t n_a² n_b²) over touching pairs (Pa): an
    /// upper bound of the packing's stiffness (the grains' relaxation only softens it), so a
    /// wave speed √(C/ρ) from it is a safe CFL bound for a continuum made of this packing.
    pub fn affine_modulus(&self) -> f64 {
        let inv = self.cell.try_inverse().expect("a cell of positive area");
        let (kn, kt) = (self.law.k_n, self.law.k_t);
        let mut c = [0.0f64; 2];
        for (k, &(i, j)) in self.pairs.iter().enumerate() {
            if !self.state[k].touching() {
                continue;
            }
            let (i, j) = (i as usize, j as usize);
            let (dx, dy) = Self::min_image(
                &inv,
                &self.cell,
                self.x[j] - self.x[i],
                self.y[j] - self.y[i],
            );
            let l2 = dx * dx + dy * dy;
            let (nx2, ny2) = (dx * dx / l2, dy * dy / l2);
            c[0] += l2 * (kn * nx2 * nx2 + kt * nx2 * ny2);
            c[1] += l2 * (kn * ny2 * ny2 + kt * nx2 * ny2);
        }
        c[0].max(c[1]) / (self.area() * self.thickness)
    }

    /// Touching pairs per grain, 2 N_c / N.
    pub fn coordination(&self) -> f64 {
        2.0 * self.contacts as f64 / self.len().max(1) as f64
    }

    /// Fabric tensor (1/N_c) Σ_c **n** ⊗ **n** (zero without contacts).
    pub fn fabric(&self) -> Tensor {
        if self.contacts == 0 {
            Tensor::zeros()
        } else {
            self.fabric / self.contacts as f64
        }
    }

    /// Cauchy stress (Pa, tension positive) with the kinetic part (see the module doc).
    pub fn stress(&self) -> Tensor {
        let mut s = self.virial;
        for i in 0..self.len() {
            let u = Vector2::new(self.ux[i], self.uy[i]);
            s += self.m[i] * u * u.transpose();
        }
        -s / (self.area() * self.thickness)
    }

    /// The contact part of the stress (Pa, tension positive).
    pub fn contact_stress(&self) -> Tensor {
        -self.virial / (self.area() * self.thickness)
    }

    /// The energies now (see [`CellEnergy`]).
    pub fn energy(&self) -> CellEnergy {
        let kinetic = (0..self.len())
            .map(|i| {
                0.5 * self.m[i] * (self.ux[i] * self.ux[i] + self.uy[i] * self.uy[i])
                    + 0.5 * self.j[i] * self.w[i] * self.w[i]
            })
            .sum();
        CellEnergy {
            work: self.work,
            stored: self.stored,
            kinetic,
            dissipated: self.dissipated,
        }
    }

    /// Positions (wrapped into the cell) and radii of the grains, for output.
    pub fn grains(&self) -> impl Iterator<Item = ([f64; 2], f64)> + '_ {
        (0..self.len()).map(|i| ([self.x[i], self.y[i]], self.r[i]))
    }

    /// Fluctuation velocities u of the grains (m/s; the velocity less the affine L x).
    pub fn fluctuation_velocities(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.ux.iter().zip(&self.uy).map(|(&u, &v)| [u, v])
    }

    /// Take `n` steps of size `h` (≤ the cell's step) under the velocity gradient `grad`.
    /// A cell that grows thinner than two cut-offs is re-tiled (see the module doc). Refuses
    /// (with the reason) a cell that would need more than [`MAX_TILES`] copies of its packing,
    /// grains passing through each other, or a state that is no longer finite.
    pub fn deform(&mut self, grad: &Tensor, n: u64, h: f64) -> Result<(), String> {
        self.grad = *grad;
        for _ in 0..n {
            self.step(h);
            let (a, b) = (self.cell.column(0), self.cell.column(1));
            let det = self.area();
            let width = (det / a.norm()).min(det / b.norm());
            if width.is_nan() {
                return Err("the periodic cell's shape is no longer finite".into());
            }
            if width <= 2.0 * self.cutoff {
                if self.tiles >= MAX_TILES {
                    return Err(format!(
                        "the periodic cell is {width:.3e} m across, less than two cut-offs \
                         (2 × {:.3e} m), and already {} copies of its packing ({} grains): \
                         the deformation is too large for this volume",
                        self.cutoff,
                        self.tiles,
                        self.len()
                    ));
                }
                self.retile();
            }
            if self.deepest > CELL_OVERLAP_LIMIT {
                return Err(format!(
                    "grains overlap by {:.2} of the smaller radius (limit {CELL_OVERLAP_LIMIT}): \
                     the strain increment is too large for the contact stiffness",
                    self.deepest
                ));
            }
        }
        if !self
            .ux
            .iter()
            .chain(&self.uy)
            .chain(&self.x)
            .all(|v| v.is_finite())
        {
            return Err("the grains' state is no longer finite".into());
        }
        Ok(())
    }

    /// Rotate the whole cell rigidly by `angle` (rad, counter-clockwise): positions, cell,
    /// fluctuation velocities, forces and the velocity gradient in use. Spins, contact springs and forces in the contact frame are
    /// unchanged by a rotation, so the stress turns exactly to R σ Rᵀ.
    pub fn rotate(&mut self, angle: f64) {
        let (s, c) = angle.sin_cos();
        let rot = Tensor::new(c, -s, s, c);
        self.cell = rot * self.cell;
        for i in 0..self.len() {
            let (x, y) = (self.x[i], self.y[i]);
            (self.x[i], self.y[i]) = (c * x - s * y, s * x + c * y);
            let (u, v) = (self.ux[i], self.uy[i]);
            (self.ux[i], self.uy[i]) = (c * u - s * v, s * u + c * v);
            let f = self.f[i];
            self.f[i] = [c * f[0] - s * f[1], s * f[0] + c * f[1], f[2]];
        }
        self.virial = rot * self.virial * rot.transpose();
        self.fabric = rot * self.fabric * rot.transpose();
        self.grad = rot * self.grad * rot.transpose();
        self.wrap();
    }

    /// Wrap every grain into the cell (fractional coordinates in [0, 1)).
    fn wrap(&mut self) {
        let inv = self.cell.try_inverse().expect("a cell of positive area");
        for i in 0..self.len() {
            let s = inv * Vector2::new(self.x[i], self.y[i]);
            let shift = self.cell * Vector2::new(s.x.floor(), s.y.floor());
            self.x[i] -= shift.x;
            self.y[i] -= shift.y;
        }
    }

    /// Lagrange–Gauss reduction of the cell's basis when it has become skewed (same lattice).
    fn reduce(&mut self) -> bool {
        let mut changed = false;
        loop {
            let (a, b) = (
                self.cell.column(0).into_owned(),
                self.cell.column(1).into_owned(),
            );
            let (aa, bb) = (a.norm_squared(), b.norm_squared());
            let (short, long, swap) = if aa <= bb {
                (a, b, false)
            } else {
                (b, a, true)
            };
            let k = (short.dot(&long) / short.norm_squared()).round();
            if k == 0.0 {
                break;
            }
            let long = long - k * short;
            let (a, b) = if swap { (long, short) } else { (short, long) };
            // Keep the orientation (det H > 0).
            let b = if a.perp(&b) < 0.0 { -b } else { b };
            self.cell = Tensor::from_columns(&[a, b]);
            changed = true;
        }
        changed
    }

    /// Describe the same periodic packing by a cell twice as thick across its thinner pair of
    /// sides: with **t** the side vector that the thin direction crosses (the shorter of **a**,
    /// **b**; the width across the other pair of sides is A/|**t**|, the smaller), the new cell
    /// has **t** ← 2**t** and holds every grain i and its copy i + N at **x**_i + **t** with
    /// the same velocities, spins and forces. A pair (i, j) whose minimum image is the image
    /// **n** of j becomes the pairs (i, j) and (i + N, j + N) when n_t is even, and (i, j + N)
    /// and (j, i + N) when it is odd; the contact state goes with it, the rolling spring and
    /// moment negated where j becomes the pair's first grain (the normal and the tangent turn
    /// over with the pair, so normal and tangential springs keep their signs). The grains'
    /// images, and so every force and the stress, are unchanged; the extensive energies
    /// double with the cell.
    fn retile(&mut self) {
        let n = self.len();
        let inv = self.cell.try_inverse().expect("a cell of positive area");
        let k = if self.cell.column(0).norm() <= self.cell.column(1).norm() {
            0
        } else {
            1
        };
        let t = self.cell.column(k).into_owned();
        self.x.extend_from_within(..);
        self.y.extend_from_within(..);
        for i in n..2 * n {
            self.x[i] += t.x;
            self.y[i] += t.y;
        }
        for v in [
            &mut self.ux,
            &mut self.uy,
            &mut self.w,
            &mut self.r,
            &mut self.m,
            &mut self.j,
        ] {
            v.extend_from_within(..);
        }
        self.f.extend_from_within(..);
        self.disp.extend_from_within(..);
        let mut pairs = Vec::with_capacity(2 * self.pairs.len());
        for (&(i, j), st) in self.pairs.iter().zip(&self.state) {
            let (iu, ju) = (i as usize, j as usize);
            let s = inv * Vector2::new(self.x[ju] - self.x[iu], self.y[ju] - self.y[iu]);
            let n = n as u32;
            if s[k].round().rem_euclid(2.0) == 0.0 {
                pairs.push(((i, j), *st));
                pairs.push(((i + n, j + n), *st));
            } else {
                let turned = ContactState {
                    theta: -st.theta,
                    m_r: -st.m_r,
                    ..*st
                };
                pairs.push(((i, j + n), *st));
                pairs.push(((j, i + n), turned));
            }
        }
        pairs.sort_unstable_by_key(|p| p.0);
        (self.pairs, self.state) = pairs.into_iter().unzip();
        self.cell.set_column(k, &(2.0 * t));
        self.virial *= 2.0;
        self.fabric *= 2.0;
        self.contacts *= 2;
        self.stored *= 2.0;
        self.dissipated *= 2.0;
        self.work *= 2.0;
        self.tiles *= 2;
        self.reduce();
        self.wrap();
        self.build();
    }

    /// Minimum image **d** = **x**_j − **x**_i of a separation.
    #[inline(always)]
    fn min_image(inv: &Tensor, cell: &Tensor, dx: f64, dy: f64) -> (f64, f64) {
        let s = inv * Vector2::new(dx, dy);
        let d = cell * Vector2::new(s.x - s.x.round(), s.y - s.y.round());
        (d.x, d.y)
    }

    /// Rebuild the pair list (pairs within R_i + R_j + skin), carrying the contact history
    /// of the pairs kept over by a merge of the two sorted lists.
    fn build(&mut self) {
        let inv = self.cell.try_inverse().expect("a cell of positive area");
        let pairs = pairs_within(&self.x, &self.y, &self.r, self.skin, |dx, dy| {
            Self::min_image(&inv, &self.cell, dx, dy)
        });
        self.state = carry_history(&self.pairs, &self.state, &pairs);
        self.pairs = pairs;
        self.disp.iter_mut().for_each(|d| *d = [0.0; 2]);
        self.strain_since_build = 0.0;
    }

    /// Whether a pair outside the list may touch (see the module doc).
    fn needs_build(&self) -> bool {
        let d2 = self
            .disp
            .iter()
            .map(|d| d[0] * d[0] + d[1] * d[1])
            .fold(0.0, f64::max);
        2.0 * d2.sqrt() + self.cutoff * self.strain_since_build > self.skin
    }

    /// One velocity-Verlet step of size `h` under the current velocity gradient.
    fn step(&mut self, h: f64) {
        let half = 0.5 * h;
        let l = self.grad;
        for i in 0..self.len() {
            self.ux[i] += half * self.f[i][0] / self.m[i];
            self.uy[i] += half * self.f[i][1] / self.m[i];
            self.w[i] += half * self.f[i][2] / self.j[i];
            self.disp[i][0] += h * self.ux[i];
            self.disp[i][1] += h * self.uy[i];
            let (x, y) = (self.x[i], self.y[i]);
            self.x[i] += h * (self.ux[i] + l[(0, 0)] * x + l[(0, 1)] * y);
            self.y[i] += h * (self.uy[i] + l[(1, 0)] * x + l[(1, 1)] * y);
        }
        self.cell += h * l * self.cell;
        let reduced = self.reduce();
        self.wrap();
        self.strain_since_build += h * l.norm();
        if reduced || self.needs_build() {
            self.build();
        }
        let before = self.virial;
        self.forces(h, true);
        // Work fed in: A t σ_c : L = −L : Σ f ⊗ l, trapezoid over the step.
        self.work -= 0.5 * h * l.component_mul(&(before + self.virial)).sum();
        self.steps += 1;
    }

    /// Resolve every pair over a step `h` (0: evaluate without advancing springs), with the
    /// grains' current (mid-step) velocities and the predictor u* = u + ½h F/m. Writes the true
    /// forces into `f`; with `kick`, first applies the second half-kick with this step's forces.
    fn forces(&mut self, h: f64, kick: bool) {
        let n = self.len();
        let half = 0.5 * h;
        let (fe, ft, f) = (&mut self.f_end, &mut self.f_new, &self.f);
        fe.clear();
        fe.resize(n, [0.0; 3]);
        ft.clear();
        ft.resize(n, [0.0; 3]);
        let mut virial = Tensor::zeros();
        let mut fabric = Tensor::zeros();
        let (mut contacts, mut stored, mut dissipated, mut deepest) = (0, 0.0, 0.0, 0.0f64);
        let inv = self.cell.try_inverse().expect("a cell of positive area");
        let l = self.grad;
        let spin = 0.5 * (l[(1, 0)] - l[(0, 1)]);
        let (x, y, ux, uy, w) = (&self.x, &self.y, &self.ux, &self.uy, &self.w);
        let (rad, m, inertia) = (&self.r, &self.m, &self.j);
        for (k, &(i, j)) in self.pairs.iter().enumerate() {
            let (i, j) = (i as usize, j as usize);
            let (dx, dy) = Self::min_image(&inv, &self.cell, x[j] - x[i], y[j] - y[i]);
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
            // Mid-step and predictor velocities of i relative to j's image: u_i − u_j − L d.
            let (dvx, dvy) = (
                ux[i] - ux[j] - (l[(0, 0)] * dx + l[(0, 1)] * dy),
                uy[i] - uy[j] - (l[(1, 0)] * dx + l[(1, 1)] * dy),
            );
            let (ex, ey) = (
                dvx + half * (f[i][0] / mi - f[j][0] / mj),
                dvy + half * (f[i][1] / mi - f[j][1] / mj),
            );
            let (wi, wj) = (w[i] + spin, w[j] + spin);
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
            dissipated += out.d_normal + out.d_friction + out.d_rolling;
            scatter(fe, (i, j), n, r, out.apply);
            let (f0, f1) = scatter(ft, (i, j), n, r, [st.f_n, st.f_t, st.m_r]);
            if st.touching() {
                contacts += 1;
                stored += out.e_normal + out.e_tangential + out.e_rolling;
                deepest = deepest.max(st.delta / ri.min(rj));
                // l = x_i − x_j = −d.
                virial -= Tensor::new(f0 * dx, f0 * dy, f1 * dx, f1 * dy);
                fabric += Tensor::new(nx * nx, nx * ny, nx * ny, ny * ny);
            }
        }
        if kick {
            for i in 0..n {
                self.ux[i] += half * fe[i][0] / m[i];
                self.uy[i] += half * fe[i][1] / m[i];
                self.w[i] += half * fe[i][2] / inertia[i];
            }
        }
        std::mem::swap(&mut self.f, &mut self.f_new);
        self.virial = virial;
        self.fabric = fabric;
        self.contacts = contacts;
        self.stored = stored;
        self.dissipated += dissipated;
        self.deepest = deepest;
    }
}

#[cfg(test)]
pub(crate) mod tests;
