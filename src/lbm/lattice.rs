//! Population storage and the fused stream–collide step (AA pattern, in place).
//!
//! Populations are structure-of-arrays: `f[i·n + y·nx + x]`, one contiguous array per direction,
//! the layout a GPU kernel would use too. Streaming is the AA pattern (Bailey et al. 2009), which
//! needs a single copy of the populations and touches each value once per step:
//!
//! * **even step**: node x reads its own slots, f_i = A[x][i], collides, and writes
//!   A[x][ī] = f_i*;
//! * **odd step**: node x reads f_i = A[x − e_i][ī] (the value its neighbour wrote last step),
//!   collides, and writes A[x + e_i][i] = f_i*.
//!
//! Every slot is read and written by exactly one node in each step, so rows run in parallel
//! (rayon) with no second array. Nodes whose 8 neighbours are plain fluid ("bulk") run through a
//! vectorised loop over runs of a row; the rest ("special": next to a wall, a solid or an edge)
//! go through a per-link path that applies half-way bounce-back and the Zou–He closure
//! ([`super::boundary`]). An even step touches only a node's own slots, so in even steps every
//! fluid node but the Zou–He ones takes the vectorised loop. Links into obstacles are listed with their wall distance q so that
//! [`super::obstacle`] can apply interpolated bounce-back and momentum exchange after the step.
//!
//! Length: the unsafe kernels (special and covered nodes, even and odd steps) share the
//! private layout and rest on one safety argument (each slot is read and written by exactly
//! one node per step); they stay in one file so that argument can be checked in one place.
//! The bulk loop, compiled once per vector extension, is in [`super::simd`] under the same
//! contract.

use rayon::prelude::*;

use super::boundary::{zou_he, Edge, Edges, Neighbour, ZouHe, ZouHeNode};
use super::collision::Collider;
use super::covered::{CoveredCells, UNCOVERED};
use super::d2q9::{equilibrium, CX, CY, OPP, Q, W};
use super::real::Real;

/// Nodes collided together as the lanes of one vector in the special-node path.
const LANES: usize = 16;

/// Bulk cells per chunk: 32 for f32 and 16 for f64, i.e. two 512-bit vectors per direction, the
/// fastest of 16/32/64 measured in cache (f32: 474/585/421 MLUPS; f64 at 32 spills registers:
/// 340 → 262 MLUPS, 256² on one core).
fn bulk_lanes<T>() -> usize {
    128 / std::mem::size_of::<T>()
}

/// The bulk loop at [`bulk_lanes`] lanes, compiled for this CPU's vector extensions
/// ([`super::simd`]).
fn bulk_kernel_for<T: Real>() -> super::simd::BulkFn<T> {
    if bulk_lanes::<T>() == 32 {
        super::simd::bulk_kernel::<T, 32>()
    } else {
        super::simd::bulk_kernel::<T, 16>()
    }
}

/// Cells per chunk of the partially saturated path, in either precision. Chosen when each
/// covered stretch (a disk's chord, ≈ 34 cells at the bench's 21-cell radius) was a pass of
/// its own: 8 wasted ≈ 11 % of the lanes where 32 wasted ≈ 47 % (the coupled step 4.8 → 3.7 s
/// over 32 bench steps). Not measured again since a pass spans a whole bulk run.
const PSM_LANES: usize = 8;

/// Direction-array stride: the cell count rounded up to a cache line of f64 and padded by
/// 5 lines, so that the nine direction arrays do not start at the same offset modulo 4 KiB
/// (which makes their streams collide in the cache sets and the store buffer: "4K aliasing").
fn padded_stride(n: usize) -> usize {
    n.div_ceil(8) * 8 + 40
}

/// A non-bulk fluid node.
#[derive(Clone, Debug)]
pub(crate) struct Special {
    pub cell: u32,
    /// What lies at x + e_i.
    pub nb: [Neighbour; Q],
    pub zou_he: Option<ZouHeNode>,
}

/// Work for one row.
#[derive(Clone, Debug, Default)]
struct RowPlan {
    /// Half-open x ranges of bulk nodes.
    runs: Vec<(u32, u32)>,
    /// Indices into `specials`.
    specials: Vec<u32>,
    /// Even steps touch only a node's own slots, so there every fluid node but a Zou–He node
    /// (which needs its closure) runs through the vector loop: these ranges …
    even_runs: Vec<(u32, u32)>,
    /// … and these Zou–He nodes (indices into `specials`).
    even_specials: Vec<u32>,
}

/// The D2Q9 populations of a rectangular domain with its walls, obstacles and edges.
pub struct Lattice<T> {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    f: Vec<T>,
    /// Distance between the arrays of two directions (≥ cells; padded, see [`padded_stride`]).
    stride: usize,
    solid: Vec<bool>,
    edges: Edges,
    /// Bounce-back correction 6 w_i ρ₀ (e_i·u_w) per wall velocity; entry 0 is a wall at rest.
    pub(super) wall_corr: Vec<[T; Q]>,
    rows: Vec<RowPlan>,
    pub(crate) specials: Vec<Special>,
    /// For each cell, its index in `specials` or `u32::MAX`.
    pub(super) special_of: Vec<u32>,
    /// True when the next step is even.
    even: bool,
    /// Half the body force, F/2 (lattice units), by which the Zou–He closure shifts the
    /// momentum it imposes: with Guo forcing the velocity is u = (Σ f e + F/2)/ρ.
    zh_shift: [f64; 2],
    /// Index of the first covered cell of each row (ny + 1 values), scratch of
    /// [`Lattice::step_covered`].
    covered_rows: Vec<u32>,
}

/// Cells per chunk of the sums over the lattice ([`crate::exec::ordered_sum`]).
const SUM_CHUNK: usize = 4096;

/// A raw pointer that may cross threads; see the SAFETY notes where it is dereferenced.
#[derive(Clone, Copy)]
struct Shared<T>(*mut T);
unsafe impl<T> Send for Shared<T> {}
unsafe impl<T> Sync for Shared<T> {}

impl<T> Shared<T> {
    /// The pointer (a method, so closures capture the `Sync` wrapper, not the raw field).
    fn get(self) -> *mut T {
        self.0
    }
}

impl<T: Real> Lattice<T> {
    /// A lattice of `nx × ny` cells with the given edges and solid mask (`solid[y·nx + x]`),
    /// filled with fluid at rest at unit density.
    ///
    /// Edge velocities and densities are in lattice units. Fails (with the reason) when the edges
    /// are inconsistent, or a Zou–He profile has the wrong length.
    pub fn new(nx: usize, ny: usize, edges: Edges, solid: Vec<bool>) -> Result<Self, String> {
        assert_eq!(solid.len(), nx * ny, "solid mask size");
        edges
            .check()
            .map_err(|(name, why)| format!("edges {name}: {why}"))?;
        for (name, e, len) in [
            ("left", &edges.left, ny),
            ("right", &edges.right, ny),
            ("bottom", &edges.bottom, nx),
            ("top", &edges.top, nx),
        ] {
            if let Edge::Velocity(p) = e {
                if p.len() != len {
                    return Err(format!(
                        "edge {name}: velocity profile has {} nodes, expected {len}",
                        p.len()
                    ));
                }
            }
        }
        if nx < 3 || ny < 3 {
            return Err(format!(
                "the lattice needs at least 3×3 cells, got {nx}×{ny}"
            ));
        }
        let n = nx * ny;
        let stride = padded_stride(n);
        let mut lat = Lattice {
            nx,
            ny,
            f: vec![T::zero(); Q * stride],
            stride,
            solid,
            edges,
            wall_corr: vec![[T::zero(); Q]],
            rows: Vec::new(),
            specials: Vec::new(),
            special_of: vec![u32::MAX; n],
            even: true,
            zh_shift: [0.0; 2],
            covered_rows: Vec::new(),
        };
        lat.plan();
        lat.fill(|_, _| (1.0, 0.0, 0.0));
        Ok(lat)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false: a lattice has at least 3×3 cells.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Is cell `c` solid?
    pub fn is_solid(&self, c: usize) -> bool {
        self.solid[c]
    }

    /// The solid mask.
    pub fn solid(&self) -> &[bool] {
        &self.solid
    }

    /// The edges.
    pub fn edges(&self) -> &Edges {
        &self.edges
    }

    /// Set every fluid cell to the equilibrium of `init(x, y) = (ρ, u_x, u_y)` (lattice units).
    pub fn fill(&mut self, init: impl Fn(usize, usize) -> (f64, f64, f64)) {
        self.fill_populations(|x, y| {
            let (r, u, v) = init(x, y);
            equilibrium(r, u, v)
        });
    }

    /// Set the body force the Zou–He closure accounts for (normally set by each step from the
    /// collision operator; call it before observing a lattice that has not stepped yet).
    pub fn set_body_force(&mut self, force: [f64; 2]) {
        self.zh_shift = [0.5 * force[0], 0.5 * force[1]];
    }

    /// Set every fluid cell's populations from `pops(x, y)` (pre-collision, lattice units).
    pub fn fill_populations(&mut self, pops: impl Fn(usize, usize) -> [f64; Q]) {
        let n = self.stride;
        self.even = true;
        for c in 0..self.len() {
            let p = if self.solid[c] {
                [0.0; Q]
            } else {
                pops(c % self.nx, c / self.nx)
            };
            // The next step is even: it reads A[x][i] as f_i.
            for (i, v) in p.iter().enumerate() {
                self.f[i * n + c] = T::c(*v);
            }
        }
    }

    /// What lies at (x + dx, y + dy) seen from fluid node (x, y).
    fn neighbour(&mut self, x: usize, y: usize, dx: i32, dy: i32) -> Neighbour {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let (mut tx, mut ty) = (x as i64 + dx as i64, y as i64 + dy as i64);
        if self.edges.left == Edge::Periodic {
            tx = tx.rem_euclid(nx);
        }
        if self.edges.bottom == Edge::Periodic {
            ty = ty.rem_euclid(ny);
        }
        let ex = if tx < 0 {
            Some(&self.edges.left)
        } else if tx >= nx {
            Some(&self.edges.right)
        } else {
            None
        };
        let ey = if ty < 0 {
            Some(&self.edges.bottom)
        } else if ty >= ny {
            Some(&self.edges.top)
        } else {
            None
        };
        // A diagonal leaving through a corner crosses two edges: a wall wins, so a Zou–He
        // corner node is treated alike whichever axis its wall is on.
        let edge = match (ex, ey) {
            (None, None) => None,
            (Some(e), None) | (None, Some(e)) => Some(e.clone()),
            (Some(a), Some(b)) => Some(if matches!(a, Edge::Wall { .. }) {
                a.clone()
            } else {
                b.clone()
            }),
        };
        match edge {
            None => {
                let c = (ty * nx + tx) as usize;
                if self.solid[c] {
                    Neighbour::Bounce(0)
                } else {
                    Neighbour::Fluid(c as u32)
                }
            }
            Some(Edge::Wall { velocity }) => Neighbour::Bounce(self.wall_index(velocity)),
            Some(Edge::Periodic) => unreachable!("periodic coordinates were wrapped"),
            Some(_) => Neighbour::Open,
        }
    }

    fn wall_index(&mut self, u: [f64; 2]) -> u16 {
        if u == [0.0, 0.0] {
            return 0;
        }
        let corr: [T; Q] =
            std::array::from_fn(|i| T::c(6.0 * W[i] * (CX[i] as f64 * u[0] + CY[i] as f64 * u[1])));
        if let Some(k) = self.wall_corr.iter().position(|c| *c == corr) {
            return k as u16;
        }
        self.wall_corr.push(corr);
        (self.wall_corr.len() - 1) as u16
    }

    /// The Zou–He node at (x, y), if a link of it is open.
    fn zou_he_node(&self, x: usize, y: usize, nb: &[Neighbour; Q]) -> Option<ZouHeNode> {
        let open = (1..Q).find(|&i| nb[i] == Neighbour::Open)?;
        let ox = x as i64 + CX[open] as i64;
        let oy = y as i64 + CY[open] as i64;
        // The same priority as `neighbour`: the y edges first.
        let (edge, normal, k) = if oy < 0 {
            (&self.edges.bottom, [0, 1], x)
        } else if oy >= self.ny as i64 {
            (&self.edges.top, [0, -1], x)
        } else if ox < 0 {
            (&self.edges.left, [1, 0], y)
        } else {
            (&self.edges.right, [-1, 0], y)
        };
        let value = match edge {
            Edge::Velocity(p) => ZouHe::Velocity(p[k]),
            Edge::Pressure(rho) => ZouHe::Pressure(*rho),
            _ => unreachable!("open links lead to Zou-He edges"),
        };
        Some(ZouHeNode { normal, value })
    }

    /// Classify every fluid node as bulk or special and build the row plans.
    fn plan(&mut self) {
        let (nx, ny) = (self.nx, self.ny);
        self.rows = vec![RowPlan::default(); ny];
        self.specials.clear();
        for y in 0..ny {
            let mut run_start: Option<usize> = None;
            for x in 0..nx {
                let c = y * nx + x;
                let mut bulk = false;
                if !self.solid[c] {
                    let nb: [Neighbour; Q] = std::array::from_fn(|i| {
                        if i == 0 {
                            Neighbour::Fluid(c as u32)
                        } else {
                            Neighbour::Open
                        }
                    });
                    let mut nb = nb;
                    for i in 1..Q {
                        nb[i] = self.neighbour(x, y, CX[i], CY[i]);
                    }
                    let all_fluid = nb.iter().all(|n| matches!(n, Neighbour::Fluid(_)));
                    // Bulk nodes read shifted slices of their row, so they must not wrap in x.
                    bulk = all_fluid && x > 0 && x + 1 < nx;
                    if !bulk {
                        let zou_he = self.zou_he_node(x, y, &nb);
                        self.special_of[c] = self.specials.len() as u32;
                        self.rows[y].specials.push(self.specials.len() as u32);
                        self.specials.push(Special {
                            cell: c as u32,
                            nb,
                            zou_he,
                        });
                    }
                }
                match (bulk, run_start) {
                    (true, None) => run_start = Some(x),
                    (false, Some(s)) => {
                        self.rows[y].runs.push((s as u32, x as u32));
                        run_start = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = run_start {
                self.rows[y].runs.push((s as u32, nx as u32));
            }
            self.plan_even_row(y);
        }
    }

    /// Even-step work of row `y` (see [`RowPlan::even_runs`]).
    fn plan_even_row(&mut self, y: usize) {
        let nx = self.nx;
        let (mut runs, mut zou_he) = (Vec::new(), Vec::new());
        let mut run_start: Option<usize> = None;
        for x in 0..=nx {
            let local = x < nx && {
                let c = y * nx + x;
                let s = self.special_of[c];
                if s != u32::MAX && self.specials[s as usize].zou_he.is_some() {
                    zou_he.push(s);
                }
                !self.solid[c] && (s == u32::MAX || self.specials[s as usize].zou_he.is_none())
            };
            match (local, run_start) {
                (true, None) => run_start = Some(x),
                (false, Some(s)) => {
                    runs.push((s as u32, x as u32));
                    run_start = None;
                }
                _ => {}
            }
        }
        self.rows[y].even_runs = runs;
        self.rows[y].even_specials = zou_he;
    }

    /// True if the next step is even (populations in natural layout, A[x][i] = f_i(x)).
    pub fn next_is_even(&self) -> bool {
        self.even
    }

    /// One fused stream–collide step.
    pub fn step(&mut self, collider: &Collider<T>) {
        let (nx, ny, n, even) = (self.nx, self.ny, self.stride, self.even);
        self.zh_shift = [0.5 * collider.force[0], 0.5 * collider.force[1]];
        let zh_shift = self.zh_shift;
        let base = Shared(self.f.as_mut_ptr());
        let specials = &self.specials;
        let wall_corr = &self.wall_corr;
        let bulk = bulk_kernel_for::<T>();
        let special = special_kernel_for::<T>();
        self.rows.par_iter().enumerate().for_each(|(y, plan)| {
            let (runs, group_list) = if even {
                (&plan.even_runs, &plan.even_specials)
            } else {
                (&plan.runs, &plan.specials)
            };
            for &(x0, x1) in runs {
                // SAFETY: within a step each slot is read and written by exactly one node (see
                // module docs); bulk nodes of row y touch slots of their own node (even) or of
                // their 8 in-domain neighbours (odd), which no other node touches.
                let (f, x0, x1) = (base.get(), x0 as usize, x1 as usize);
                unsafe { bulk(f, n, nx, ny, y, x0, x1, even, collider) };
            }
            for group in group_list.chunks(LANES) {
                // SAFETY: as above; special nodes touch only their own link slots.
                unsafe {
                    special(
                        base.get(),
                        n,
                        specials,
                        group,
                        even,
                        collider,
                        wall_corr,
                        zh_shift,
                    )
                };
            }
        });
        self.even = !even;
    }

    /// One fused stream–collide step in which the cells of `psm` collide with the term of a
    /// coupling method ([`CoveredCells::apply`] after the fluid collision) and store the
    /// momentum that term gave the fluid in `exchange` (one entry per covered cell; entries
    /// of solid cells are left alone). Streaming is unchanged: a covered cell streams like
    /// the fluid node it is. With no covered cells this is [`Lattice::step`].
    ///
    /// # Panics
    /// If the cells are not ascending and unique, lie outside the lattice, or `exchange` has
    /// another length.
    pub fn step_covered<C: CoveredCells<T>>(
        &mut self,
        collider: &Collider<T>,
        psm: &C,
        exchange: &mut [[f64; 2]],
    ) {
        let cells = psm.cells();
        if cells.is_empty() {
            return self.step(collider);
        }
        assert!(
            cells.par_windows(2).all(|w| w[0] < w[1]),
            "covered cells must be ascending and unique"
        );
        assert!(
            cells
                .last()
                .is_none_or(|&c| (c as usize) < self.nx * self.ny),
            "covered cell outside the lattice"
        );
        assert_eq!(
            exchange.len(),
            cells.len(),
            "one exchange entry per covered cell"
        );
        let (nx, ny, n, even) = (self.nx, self.ny, self.stride, self.even);
        let row_start = &mut self.covered_rows;
        row_start.clear();
        row_start
            .extend((0..=ny).map(|y| cells.partition_point(|&c| (c as usize) < y * nx) as u32));
        self.zh_shift = [0.5 * collider.force[0], 0.5 * collider.force[1]];
        let zh_shift = self.zh_shift;
        let base = Shared(self.f.as_mut_ptr());
        let exchange = Shared(exchange.as_mut_ptr());
        let (specials, special_of, solid) = (&self.specials, &self.special_of, &self.solid);
        let wall_corr = &self.wall_corr;
        let row_start = &self.covered_rows;
        let bulk_fn = bulk_kernel_for::<T>();
        let psm_kernel = psm_kernel_for::<T, C>();
        let special = special_kernel_for::<T>();
        self.rows.par_iter().enumerate().for_each(|(y, plan)| {
            let (runs, group_list) = if even {
                (&plan.even_runs, &plan.even_specials)
            } else {
                (&plan.runs, &plan.specials)
            };
            let (k0, k1) = (row_start[y] as usize, row_start[y + 1] as usize);
            let covered = &cells[k0..k1];
            let is_covered = |c: u32| covered.binary_search(&c).is_ok();
            let row = (y * nx) as u32;
            let bulk = |x0: usize, x1: usize| {
                // SAFETY: as in `step`.
                unsafe { bulk_fn(base.get(), n, nx, ny, y, x0, x1, even, collider) }
            };
            // Bulk runs, one vector pass each with their covered cells blended in; a covered
            // special or solid cell (which the loops below handle) splits its run.
            let mut k = k0;
            for &(x0, x1) in runs {
                while k < k1 && cells[k] - row < x0 {
                    k += 1;
                }
                let (mut start, mut first) = (x0, k);
                let pass = |x0: u32, x1: u32, ks: usize, ke: usize| {
                    if ks == ke {
                        bulk(x0 as usize, x1 as usize);
                    } else {
                        // SAFETY: as in `step`; entries ks..ke of `exchange` belong to this
                        // row.
                        unsafe {
                            psm_kernel(
                                base.get(),
                                n,
                                nx,
                                ny,
                                y,
                                x0 as usize,
                                x1 as usize,
                                even,
                                collider,
                                psm,
                                &cells[ks..ke],
                                ks,
                                exchange.get(),
                            )
                        }
                    }
                };
                while k < k1 && cells[k] - row < x1 {
                    let c = cells[k] as usize;
                    if solid[c] || special_of[c] != u32::MAX {
                        pass(start, c as u32 - row, first, k);
                        (start, first) = (c as u32 - row + 1, k + 1);
                    }
                    k += 1;
                }
                pass(start, x1, first, k);
            }
            // Special nodes that are not covered, in groups of LANES.
            let mut group = [0u32; LANES];
            let mut len = 0;
            for &s in group_list {
                if is_covered(specials[s as usize].cell) {
                    continue;
                }
                group[len] = s;
                len += 1;
                if len == LANES {
                    // SAFETY: as in `step`.
                    unsafe {
                        special(
                            base.get(),
                            n,
                            specials,
                            &group,
                            even,
                            collider,
                            wall_corr,
                            zh_shift,
                        )
                    };
                    len = 0;
                }
            }
            if len > 0 {
                // SAFETY: as in `step`.
                unsafe {
                    special(
                        base.get(),
                        n,
                        specials,
                        &group[..len],
                        even,
                        collider,
                        wall_corr,
                        zh_shift,
                    )
                };
            }
            // Covered special nodes, collided LANES at a time.
            let mut k = k0;
            while k < k1 {
                let mut sps: [Special; LANES] = std::array::from_fn(|_| Special {
                    cell: 0,
                    nb: [Neighbour::Open; Q],
                    zou_he: None,
                });
                let mut idx = [0usize; LANES];
                let mut len = 0;
                while k < k1 && len < LANES {
                    let c = cells[k] as usize;
                    if !solid[c] && special_of[c] != u32::MAX {
                        let s = special_of[c];
                        sps[len] = if s != u32::MAX {
                            specials[s as usize].clone()
                        } else {
                            // A bulk node: its eight neighbours are fluid, x ± 1 in the row.
                            let x = c % nx;
                            Special {
                                cell: c as u32,
                                nb: std::array::from_fn(|i| {
                                    let yy =
                                        (y as i64 + CY[i] as i64).rem_euclid(ny as i64) as usize;
                                    Neighbour::Fluid(
                                        (yy * nx + (x as i64 + CX[i] as i64) as usize) as u32,
                                    )
                                }),
                                zou_he: None,
                            }
                        };
                        idx[len] = k;
                        len += 1;
                    }
                    k += 1;
                }
                if len == 0 {
                    continue;
                }
                let mut g = [[T::zero(); LANES]; Q];
                let mut lanes = [0usize; LANES];
                for l in 0..LANES {
                    // Lanes past `len` repeat lane 0 (computed, never written back).
                    let (sp, kk) = if l < len {
                        (&sps[l], idx[l])
                    } else {
                        (&sps[0], idx[0])
                    };
                    // SAFETY: as in `step` (reads only).
                    let (gl, _) = unsafe { gather(base.get(), n, sp, even, wall_corr, zh_shift) };
                    for i in 0..Q {
                        g[i][l] = gl[i];
                    }
                    lanes[l] = kk;
                }
                let mut post = g;
                collider.collide(&mut post);
                let dp = psm.apply(&lanes, &g, &mut post, collider.force);
                for l in 0..len {
                    let out: [T; Q] = std::array::from_fn(|i| post[i][l]);
                    // SAFETY: as in `step`; entry idx[l] of `exchange` belongs to this row.
                    unsafe {
                        scatter(base.get(), n, &sps[l], &out, even, wall_corr);
                        *exchange.get().add(idx[l]) = [dp[0][l], dp[1][l]];
                    }
                }
            }
        });
        self.even = !even;
    }

    /// Pre-collision populations of fluid cell `c` at the current time (after streaming and
    /// boundary closure): what the next step will collide.
    /// A solid cell has no populations: it reports the rest state at unit density.
    pub fn populations(&self, c: usize) -> [T; Q] {
        if self.solid[c] {
            return std::array::from_fn(|i| T::c(W[i]));
        }
        let n = self.stride;
        let f = &self.f;
        let s = self.special_of[c];
        if s != u32::MAX {
            let sp = &self.specials[s as usize];
            // SAFETY: read-only access through a pointer derived from a shared borrow.
            return unsafe {
                gather(
                    f.as_ptr() as *mut T,
                    n,
                    sp,
                    self.even,
                    &self.wall_corr,
                    self.zh_shift,
                )
                .0
            };
        }
        if self.even {
            std::array::from_fn(|i| f[i * n + c])
        } else {
            let (x, y) = ((c % self.nx) as i64, (c / self.nx) as i64);
            std::array::from_fn(|i| {
                let sx = x - CX[i] as i64;
                let sy = (y - CY[i] as i64).rem_euclid(self.ny as i64);
                f[OPP[i] * n + (sy * self.nx as i64 + sx) as usize]
            })
        }
    }

    /// The fluid node at x_c + e_i as the streaming sees it (wrapped across periodic edges),
    /// or `None` when that link ends at a wall, a solid or an open edge, or `c` is solid.
    pub(crate) fn fluid_neighbour(&self, c: usize, i: usize) -> Option<usize> {
        if self.solid[c] {
            return None;
        }
        let s = self.special_of[c];
        if s != u32::MAX {
            return match self.specials[s as usize].nb[i] {
                Neighbour::Fluid(k) => Some(k as usize),
                _ => None,
            };
        }
        // A bulk node: its eight neighbours are fluid, x ± 1 in the row, y wrapped.
        let (x, y) = ((c % self.nx) as i64, (c / self.nx) as i64);
        let yy = (y + CY[i] as i64).rem_euclid(self.ny as i64);
        Some((yy * self.nx as i64 + x + CX[i] as i64) as usize)
    }

    /// Overwrite the pre-collision populations of fluid cell `c` (what the next step
    /// collides; the inverse of [`Lattice::populations`]). Populations arriving across an
    /// open (Zou–He) link are not stored: the closure sets them. Solid cells are left alone.
    pub(crate) fn set_populations(&mut self, c: usize, p: &[f64; Q]) {
        if self.solid[c] {
            return;
        }
        let n = self.stride;
        let s = self.special_of[c];
        for j in 0..Q {
            // f_j arrives from x − e_j, across link ī (as in `gather`).
            let slot = if s != u32::MAX {
                match self.specials[s as usize].nb[OPP[j]] {
                    Neighbour::Fluid(k) => {
                        if self.even {
                            j * n + c
                        } else {
                            OPP[j] * n + k as usize
                        }
                    }
                    Neighbour::Bounce(w) => {
                        let v = if self.even {
                            p[j]
                        } else {
                            p[j] - self.wall_corr[w as usize][j].f64()
                        };
                        self.f[j * n + c] = T::c(v);
                        continue;
                    }
                    Neighbour::Open => continue,
                }
            } else if self.even {
                j * n + c
            } else {
                let (x, y) = ((c % self.nx) as i64, (c / self.nx) as i64);
                let sy = (y - CY[j] as i64).rem_euclid(self.ny as i64);
                OPP[j] * n + (sy * self.nx as i64 + x - CX[j] as i64) as usize
            };
            self.f[slot] = T::c(p[j]);
        }
    }

    /// Raw slot A[c][i] (for momentum exchange and interpolated bounce-back).
    #[inline]
    pub(crate) fn slot(&self, i: usize, c: usize) -> T {
        self.f[i * self.stride + c]
    }

    /// Overwrite slot A[c][i].
    #[inline]
    pub(crate) fn set_slot(&mut self, i: usize, c: usize, v: T) {
        let n = self.stride;
        self.f[i * n + c] = v;
    }

    /// Sum of all populations of fluid cells (total mass, lattice units), accumulated in f64.
    pub fn total_mass(&self) -> f64 {
        let mass = |c: usize| match self.solid[c] {
            true => [0.0],
            false => [self.populations(c).iter().map(|v| v.f64()).sum::<f64>()],
        };
        crate::exec::ordered_sum(self.len(), SUM_CHUNK, mass)[0]
    }

    /// Bytes of population storage.
    pub fn bytes(&self) -> usize {
        self.f.len() * std::mem::size_of::<T>()
    }
}

/// Stream and collide the bulk nodes `x0..x1` of row `y` as [`super::simd::bulk_run`], with
/// the covered-cell term [`CoveredCells::apply`] on the covered ones among them: `covered`
/// are their cells (ascending, entries `k0..` of the cover), and their exchanged momentum
/// goes to `exchange[k0..]`. A chunk of lanes without a covered cell takes the plain
/// collision; in a chunk with one, the uncovered lanes are left as the fluid collision made
/// them (entry [`UNCOVERED`]).
///
/// One pass per bulk run rather than one per stretch of covered cells (with the gaps between
/// them as separate bulk runs): the short pieces and their remainders cost a grain-laden
/// step as much as its collisions (2026-12-07, the Table 5.3 case on 2 AMD EPYC cores:
/// 85–93 ms per lattice step before, 42 ms after, with the f32 blend and fixed-size moves).
///
/// # Safety
/// As [`super::simd::bulk_run`]; entries `k0..k0 + covered.len()` of `exchange` belong to
/// this call.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
unsafe fn bulk_run_psm<T: Real, C: CoveredCells<T>, const L: usize>(
    f: *mut T,
    n: usize,
    nx: usize,
    ny: usize,
    y: usize,
    x0: usize,
    x1: usize,
    even: bool,
    collider: &Collider<T>,
    psm: &C,
    covered: &[u32],
    k0: usize,
    exchange: *mut [f64; 2],
) {
    // The same offsets as `simd::bulk_run`, written out: a shared helper (with the bulk
    // variants made by a macro) ran the f32 BGK bench 15 % slower (2026-12-04, ≈ 455 against
    // ≈ 540 MLUPS, three alternated rounds).
    let row = y * nx;
    let offs: [usize; Q] = std::array::from_fn(|i| {
        if even {
            i * n + row
        } else {
            let yy = (y as i64 + CY[i] as i64).rem_euclid(ny as i64) as usize;
            ((i * n + yy * nx) as i64 + CX[i] as i64) as usize
        }
    });
    // Next covered cell (index into `covered`).
    let mut next = 0;
    let mut x = x0;
    while x < x1 {
        let len = (x1 - x).min(L);
        let mut buf = [[T::zero(); L]; Q];
        // A full chunk moves as fixed-size loads and stores (vector moves); a remainder is
        // copied in short moves and padded with its first cell.
        let full = len == L;
        for i in 0..Q {
            let dst = if even { i } else { OPP[i] };
            if full {
                buf[dst] = std::ptr::read_unaligned(f.add(offs[i] + x) as *const [T; L]);
            } else {
                super::simd::copy_short(f.add(offs[i] + x), buf[dst].as_mut_ptr(), len);
                for l in len..L {
                    buf[dst][l] = buf[dst][0];
                }
            }
        }
        // The chunk's lanes: their cover entries, or UNCOVERED.
        let mut lanes = [UNCOVERED; L];
        let (mut count, mut replaced) = (0, 0);
        while next < covered.len() && (covered[next] as usize - row) < x + len {
            let k = k0 + next;
            lanes[covered[next] as usize - row - x] = k;
            count += 1;
            replaced += psm.replaces_collision(k) as usize;
            next += 1;
        }
        if count == 0 {
            collider.collide(&mut buf);
        } else {
            let g = buf;
            // A chunk of cells whose fluid collision all have weight 0 skips it (the term's
            // 0·C(g) is then 0·g, the same).
            if replaced < len {
                collider.collide(&mut buf);
            }
            let dp = psm.apply(&lanes, &g, &mut buf, collider.force);
            for (l, &k) in lanes.iter().enumerate().take(len) {
                if k != UNCOVERED {
                    *exchange.add(k) = [dp[0][l], dp[1][l]];
                }
            }
        }
        for i in 0..Q {
            let slot = if even { OPP[i] } else { i };
            if full {
                std::ptr::write_unaligned(f.add(offs[slot] + x) as *mut [T; L], buf[i]);
            } else {
                super::simd::copy_short(buf[i].as_ptr(), f.add(offs[slot] + x), len);
            }
        }
        x += len;
    }
}

/// Stamps out `$name`, a `#[target_feature]` copy for the level `avx512` or `avx2`
/// ([`super::simd::Level`]) of the `#[inline(always)]` kernel `$kernel` (generic over `$g`,
/// called as `$kernel::<$k…>`).
///
/// # Safety (of the copy)
/// As the kernel's; the CPU has the features ([`super::simd::level`]).
macro_rules! with_features {
    ($name:ident, avx512, $($rest:tt)*) => {
        with_features!(@ $name, "avx512f,avx512bw,avx512dq,avx512vl,avx2,fma", $($rest)*);
    };
    ($name:ident, avx2, $($rest:tt)*) => {
        with_features!(@ $name, "avx2,fma", $($rest)*);
    };
    (@ $name:ident, $features:literal, $kernel:ident::<$($k:tt),*>, <$($g:ident: $b:path),*>,
     ($($a:ident: $t:ty),* $(,)?)) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        #[allow(clippy::too_many_arguments)]
        unsafe fn $name<$($g: $b),*>($($a: $t),*) {
            // SAFETY: forwarded from the caller.
            unsafe { $kernel::<$($k),*>($($a),*) }
        }
    };
}

/// Signature of [`bulk_run_psm`].
type PsmFn<T, C> = unsafe fn(
    *mut T,
    usize,
    usize,
    usize,
    usize,
    usize,
    usize,
    bool,
    &Collider<T>,
    &C,
    &[u32],
    usize,
    *mut [f64; 2],
);

/// [`bulk_run_psm`] at [`PSM_LANES`], compiled for this CPU's vector extensions (as the plain
/// bulk loop, [`super::simd`]): without it the bulk runs of a coupled step ran the baseline's
/// scalar `mul_add` library calls.
fn psm_kernel_for<T: Real, C: CoveredCells<T>>() -> PsmFn<T, C> {
    use super::simd::Level;
    match super::simd::level() {
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => psm_avx512::<T, C>,
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => psm_avx2::<T, C>,
        _ => bulk_run_psm::<T, C, PSM_LANES>,
    }
}

with_features!(psm_avx512, avx512, bulk_run_psm::<T, C, PSM_LANES>, <T: Real, C: CoveredCells<T>>,
    (f: *mut T, n: usize, nx: usize, ny: usize, y: usize, x0: usize, x1: usize, even: bool,
     collider: &Collider<T>, psm: &C, covered: &[u32], k0: usize, exchange: *mut [f64; 2]));
with_features!(psm_avx2, avx2, bulk_run_psm::<T, C, PSM_LANES>, <T: Real, C: CoveredCells<T>>,
    (f: *mut T, n: usize, nx: usize, ny: usize, y: usize, x0: usize, x1: usize, even: bool,
     collider: &Collider<T>, psm: &C, covered: &[u32], k0: usize, exchange: *mut [f64; 2]));

/// Gather the pre-collision populations of a special node and the mask of unknown ones, and
/// apply the Zou–He closure.
///
/// # Safety
/// `f` points to `Q·n` values; only reads.
unsafe fn gather<T: Real>(
    f: *mut T,
    n: usize,
    sp: &Special,
    even: bool,
    wall_corr: &[[T; Q]],
    zh_shift: [f64; 2],
) -> ([T; Q], u16) {
    let c = sp.cell as usize;
    let mut g = [T::zero(); Q];
    let mut unknown = 0u16;
    for j in 0..Q {
        // The population arriving along e_j comes from x − e_j, i.e. across link ī.
        match sp.nb[OPP[j]] {
            Neighbour::Fluid(k) => {
                g[j] = if even {
                    *f.add(j * n + c)
                } else {
                    *f.add(OPP[j] * n + k as usize)
                };
            }
            Neighbour::Bounce(w) => {
                // f_j = f_ī* − 6 w_ī (e_ī·u_w): applied here for values written by an even step,
                // at the write for those written by an odd step.
                let v = *f.add(j * n + c);
                g[j] = if even {
                    v
                } else {
                    v + wall_corr[w as usize][j]
                };
            }
            Neighbour::Open => {
                unknown |= 1 << j;
            }
        }
    }
    if let Some(node) = &sp.zou_he {
        zou_he(&mut g, unknown, node, zh_shift);
    }
    (g, unknown)
}

/// Signature of [`special_nodes`].
type SpecialFn<T> =
    unsafe fn(*mut T, usize, &[Special], &[u32], bool, &Collider<T>, &[[T; Q]], [f64; 2]);

/// [`special_nodes`] compiled for this CPU's vector extensions: in the baseline its `mul_add`
/// calls are library calls, which cost a periodic 2048² box 5–10 % of its step.
fn special_kernel_for<T: Real>() -> SpecialFn<T> {
    use super::simd::Level;
    match super::simd::level() {
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => special_avx512::<T>,
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => special_avx2::<T>,
        _ => special_nodes::<T>,
    }
}

with_features!(special_avx512, avx512, special_nodes::<T>, <T: Real>,
    (f: *mut T, n: usize, specials: &[Special], group: &[u32], even: bool,
     collider: &Collider<T>, wall_corr: &[[T; Q]], zh_shift: [f64; 2]));
with_features!(special_avx2, avx2, special_nodes::<T>, <T: Real>,
    (f: *mut T, n: usize, specials: &[Special], group: &[u32], even: bool,
     collider: &Collider<T>, wall_corr: &[[T; Q]], zh_shift: [f64; 2]));

/// Stream–collide a group of at most [`LANES`] special nodes of one row.
///
/// # Safety
/// As [`super::simd::bulk_run`]; `group` indexes `specials`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
unsafe fn special_nodes<T: Real>(
    f: *mut T,
    n: usize,
    specials: &[Special],
    group: &[u32],
    even: bool,
    collider: &Collider<T>,
    wall_corr: &[[T; Q]],
    zh_shift: [f64; 2],
) {
    // Gather link by link, collide all of the group's nodes as lanes of one vector, scatter.
    let mut buf = [[T::zero(); LANES]; Q];
    for (l, &s) in group.iter().enumerate() {
        let (g, _) = gather(f, n, &specials[s as usize], even, wall_corr, zh_shift);
        for i in 0..Q {
            buf[i][l] = g[i];
        }
    }
    for l in group.len()..LANES {
        for row in buf.iter_mut() {
            row[l] = row[0];
        }
    }
    collider.collide(&mut buf);
    for (l, &s) in group.iter().enumerate() {
        let sp = &specials[s as usize];
        let c = sp.cell as usize;
        for i in 0..Q {
            let v = buf[i][l];
            if even {
                *f.add(OPP[i] * n + c) = v;
            } else {
                match sp.nb[i] {
                    Neighbour::Fluid(k) => *f.add(i * n + k as usize) = v,
                    Neighbour::Bounce(w) => *f.add(OPP[i] * n + c) = v - wall_corr[w as usize][i],
                    Neighbour::Open => {}
                }
            }
        }
    }
}

/// Write the post-collision populations of one special node (the scatter of
/// [`special_nodes`]).
///
/// # Safety
/// As [`special_nodes`].
unsafe fn scatter<T: Real>(
    f: *mut T,
    n: usize,
    sp: &Special,
    post: &[T; Q],
    even: bool,
    wall_corr: &[[T; Q]],
) {
    let c = sp.cell as usize;
    for i in 0..Q {
        let v = post[i];
        if even {
            *f.add(OPP[i] * n + c) = v;
        } else {
            match sp.nb[i] {
                Neighbour::Fluid(k) => *f.add(i * n + k as usize) = v,
                Neighbour::Bounce(w) => *f.add(OPP[i] * n + c) = v - wall_corr[w as usize][i],
                Neighbour::Open => {}
            }
        }
    }
}

impl<T: Real> Lattice<T> {
    /// Copy of the populations and the parity, for snapshots.
    pub fn state(&self) -> (Vec<T>, bool) {
        (self.f.clone(), self.even)
    }

    /// Number of population values [`Lattice::state`] holds (padding included).
    pub fn state_len(&self) -> usize {
        self.f.len()
    }

    /// Restore a state from [`Lattice::state`].
    pub fn set_state(&mut self, f: Vec<T>, even: bool) {
        assert_eq!(f.len(), self.f.len(), "snapshot of another lattice");
        self.f = f;
        self.even = even;
    }
}
