//! Contact detection for disks: a uniform-grid cell list builds a Verlet neighbour list of
//! grain pairs (and grain–wall pairs) closer than R_i + R_j + skin; the list is reused until
//! some grain has moved more than skin/2 since the build (then no pair outside the list can
//! touch). Contact history (tangential and rolling spring) lives in arrays parallel to the
//! pair list, sorted by (i, j) with i < j, and is carried to the new list by a linear merge of
//! the two sorted lists — no hashing, no per-pair heap object.
//!
//! Cells are squares of side h ≥ 2R_max + skin laid over the bounding box of the grains, so the
//! 3 × 3 cells around a grain hold every partner. In a domain periodic in x over [x0, x1) the
//! columns of cells tile the period exactly (width L/⌊L/h⌋ ≥ h, at least 3 columns), the
//! neighbour columns wrap around, and separations are minimal images; the caller wraps the
//! positions into the period before a build. Grains are binned by a counting sort; the
//! pair search runs in parallel over fixed chunks of grains, each chunk writing to its own
//! reused buffer, which are concatenated in order (the list is identical for any thread
//! count).

use rayon::prelude::*;

use super::contact::ContactState;
use super::grains::Grains;
use super::params::min_image;
use super::walls::Wall;

/// Grains per parallel chunk of the pair search.
const CHUNK: usize = 512;

/// Grain–grain pairs within reach, with their contact history and last forces.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct PairList {
    /// First grain of each pair (i < j); sorted by (i, j).
    pub i: Vec<u32>,
    /// Second grain of each pair.
    pub j: Vec<u32>,
    /// Contact state of each pair: last overlap, springs, forces (see [`ContactState`]).
    pub state: Vec<ContactState>,
    /// Per pair: [`PAIR_TOUCHING`] if the grains overlapped at the last evaluation (the same
    /// as `state[p].touching()`, kept in one byte so the force loop skips the many apart pairs
    /// without loading their state).
    pub flags: Vec<u8>,
    /// Pairs whose first grain is `g` are `first[g]..first[g + 1]`.
    pub first: Vec<u32>,
}

/// [`PairList::flags`] bit: the grains overlapped at the last evaluation.
pub const PAIR_TOUCHING: u8 = 1;

/// Grain–wall pairs within reach, sorted by (grain, wall).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct WallList {
    /// Grain of each pair.
    pub grain: Vec<u32>,
    /// Wall index of each pair.
    pub wall: Vec<u32>,
    /// Contact state of each pair.
    pub state: Vec<ContactState>,
    /// Pairs of grain `g` are `first[g]..first[g + 1]`.
    pub first: Vec<u32>,
}

/// Cell list and reusable scratch for building the neighbour lists.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Detector {
    /// Verlet skin (m).
    pub skin: f64,
    cell_start: Vec<u32>,
    sorted: Vec<u32>,
    cell_of: Vec<u32>,
    bufs: Vec<Vec<(u32, u32)>>,
    old_i: Vec<u32>,
    old_j: Vec<u32>,
    old_state: Vec<ContactState>,
    /// Positions at the last build.
    x_ref: Vec<f64>,
    y_ref: Vec<f64>,
    /// Number of builds so far.
    pub builds: u64,
}

impl Detector {
    /// A detector with Verlet skin `skin` (> 0; e.g. 0.1–0.3 of the mean diameter).
    pub fn new(skin: f64) -> Self {
        Detector {
            skin,
            ..Default::default()
        }
    }

    /// Whether some grain moved more than skin/2 since the last build (or there was none).
    pub fn needs_rebuild(&self, g: &Grains) -> bool {
        if self.x_ref.len() != g.len() {
            return true;
        }
        let lim = 0.25 * self.skin * self.skin;
        g.x.par_iter()
            .zip(g.y.par_iter())
            .zip(self.x_ref.par_iter().zip(self.y_ref.par_iter()))
            .with_min_len(4096)
            .any(|((x, y), (x0, y0))| {
                let (dx, dy) = (x - x0, y - y0);
                let r2 = dx * dx + dy * dy;
                r2 > lim || r2.is_nan()
            })
    }

    /// Positions at the last build and the squared displacement (skin/2)² beyond which the
    /// list must be rebuilt (empty slices before the first build).
    pub fn reference(&self) -> (&[f64], &[f64], f64) {
        (&self.x_ref, &self.y_ref, 0.25 * self.skin * self.skin)
    }

    /// Rebuild both lists from the current positions, carrying history over; `periodic_x`
    /// as in [`super::DemParams::periodic_x`] (positions already wrapped into it).
    pub fn build(
        &mut self,
        g: &Grains,
        walls: &[Wall],
        periodic_x: Option<[f64; 2]>,
        pairs: &mut PairList,
        wl: &mut WallList,
    ) {
        self.builds += 1;
        self.x_ref.clear();
        self.x_ref.extend_from_slice(&g.x);
        self.y_ref.clear();
        self.y_ref.extend_from_slice(&g.y);
        self.build_pairs(g, periodic_x, pairs);
        self.build_walls(g, walls, wl);
    }

    fn build_pairs(&mut self, g: &Grains, periodic_x: Option<[f64; 2]>, pl: &mut PairList) {
        let n = g.len();
        let skin = self.skin;
        // Bounding box; grains with non-finite positions are left out of the search.
        let (mut x0, mut y0, mut x1, mut y1) = (
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        );
        for k in 0..n {
            if g.x[k].is_finite() && g.y[k].is_finite() {
                x0 = x0.min(g.x[k]);
                x1 = x1.max(g.x[k]);
                y0 = y0.min(g.y[k]);
                y1 = y1.max(g.y[k]);
            }
        }
        if x0 > x1 {
            (x0, y0, x1, y1) = (0.0, 0.0, 0.0, 0.0);
        }
        let mut h = (2.0 * g.max_radius() + skin).max(f64::MIN_POSITIVE);
        let (mut ncx, mut ncy);
        loop {
            ncx = ((x1 - x0) / h) as usize + 1;
            ncy = ((y1 - y0) / h) as usize + 1;
            if ncx.saturating_mul(ncy) <= 4 * n + 16 {
                break;
            }
            h *= 1.5;
        }
        // Periodic columns: ⌊L/h⌋ of them, each L/⌊L/h⌋ ≥ h wide (`Dem::new` checks L ≥ 3h).
        let (mut hx, period) = (h, periodic_x.map(|[a, b]| b - a));
        if let Some([a, b]) = periodic_x {
            ncx = (((b - a) / h) as usize).max(3);
            hx = (b - a) / ncx as f64;
            x0 = a;
        }
        let wrap = period.is_some();
        let ncell = ncx * ncy;
        self.cell_of.clear();
        self.cell_start.clear();
        self.cell_start.resize(ncell + 1, 0);
        for k in 0..n {
            let c = if g.x[k].is_finite() && g.y[k].is_finite() {
                let cx = (((g.x[k] - x0) / hx) as usize).min(ncx - 1);
                let cy = (((g.y[k] - y0) / h) as usize).min(ncy - 1);
                (cy * ncx + cx) as u32
            } else {
                u32::MAX
            };
            self.cell_of.push(c);
            if c != u32::MAX {
                self.cell_start[c as usize + 1] += 1;
            }
        }
        for c in 0..ncell {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.sorted.clear();
        self.sorted.resize(self.cell_start[ncell] as usize, 0);
        {
            let mut fill: Vec<u32> = self.cell_start[..ncell].to_vec();
            for k in 0..n {
                let c = self.cell_of[k];
                if c != u32::MAX {
                    self.sorted[fill[c as usize] as usize] = k as u32;
                    fill[c as usize] += 1;
                }
            }
        }
        let nchunks = n.div_ceil(CHUNK).max(1);
        self.bufs.resize_with(nchunks, Vec::new);
        let (cell_start, sorted, cell_of) = (&self.cell_start, &self.sorted, &self.cell_of);
        // Pairs with a polygon grain belong to the rapier detector (`detect_rapier`).
        let polys = g.has_polygons();
        self.bufs.par_iter_mut().enumerate().for_each(|(k, buf)| {
            buf.clear();
            let mut mine: Vec<u32> = Vec::with_capacity(16);
            #[allow(clippy::needless_range_loop)]
            for i in k * CHUNK..((k + 1) * CHUNK).min(n) {
                let c = cell_of[i];
                if c == u32::MAX || (polys && !g.is_disk(i)) {
                    continue;
                }
                let (cx, cy) = ((c as usize) % ncx, (c as usize) / ncx);
                let (xi, yi, ri) = (g.x[i], g.y[i], g.radius[i]);
                mine.clear();
                // Neighbour columns, wrapped around the period if periodic (ncx ≥ 3, so
                // the three are distinct).
                let mut cols = [cx; 3];
                let nc = if wrap {
                    cols = [(cx + ncx - 1) % ncx, cx, (cx + 1) % ncx];
                    3
                } else {
                    let lo = cx.saturating_sub(1);
                    let hi = (cx + 1).min(ncx - 1);
                    for (k, c) in (lo..=hi).enumerate() {
                        cols[k] = c;
                    }
                    hi - lo + 1
                };
                for ny in cy.saturating_sub(1)..=(cy + 1).min(ncy - 1) {
                    for &nx in &cols[..nc] {
                        let cc = ny * ncx + nx;
                        for &j in &sorted[cell_start[cc] as usize..cell_start[cc + 1] as usize] {
                            if j as usize <= i || (polys && !g.is_disk(j as usize)) {
                                continue;
                            }
                            let j_ = j as usize;
                            let dx = min_image(g.x[j_] - xi, period);
                            let dy = g.y[j_] - yi;
                            let reach = ri + g.radius[j_] + skin;
                            if dx * dx + dy * dy < reach * reach {
                                mine.push(j);
                            }
                        }
                    }
                }
                mine.sort_unstable();
                buf.extend(mine.iter().map(|&j| (i as u32, j)));
            }
        });
        // Keep the old list for the history merge.
        std::mem::swap(&mut self.old_i, &mut pl.i);
        std::mem::swap(&mut self.old_j, &mut pl.j);
        std::mem::swap(&mut self.old_state, &mut pl.state);
        pl.i.clear();
        pl.j.clear();
        pl.state.clear();
        for buf in &self.bufs {
            for &(i, j) in buf {
                pl.i.push(i);
                pl.j.push(j);
            }
        }
        let m = pl.i.len();
        pl.state.resize(m, ContactState::default());
        // Merge history: both lists sorted by (i, j).
        let key = |i: u32, j: u32| (u64::from(i) << 32) | u64::from(j);
        let mut o = 0;
        for p in 0..m {
            let kp = key(pl.i[p], pl.j[p]);
            while o < self.old_i.len() && key(self.old_i[o], self.old_j[o]) < kp {
                o += 1;
            }
            if o < self.old_i.len() && key(self.old_i[o], self.old_j[o]) == kp {
                pl.state[p] = self.old_state[o];
            }
        }
        pl.flags.clear();
        pl.flags.extend(
            pl.state
                .iter()
                .map(|s| if s.touching() { PAIR_TOUCHING } else { 0 }),
        );
        // Index by first grain.
        pl.first.clear();
        pl.first.resize(n + 1, 0);
        for &i in &pl.i {
            pl.first[i as usize + 1] += 1;
        }
        for k in 0..n {
            pl.first[k + 1] += pl.first[k];
        }
    }

    fn build_walls(&mut self, g: &Grains, walls: &[Wall], wl: &mut WallList) {
        let n = g.len();
        let (old_g, old_w, old_s) = (
            std::mem::take(&mut wl.grain),
            std::mem::take(&mut wl.wall),
            std::mem::take(&mut wl.state),
        );
        wl.first.clear();
        wl.first.resize(n + 1, 0);
        let mut o = 0;
        for k in 0..n {
            // Polygon grains meet walls through the rapier detector; polygon walls report
            // s = ∞ and are never paired here.
            let walls = if g.is_disk(k) { walls } else { &[] };
            for (w, wall) in walls.iter().enumerate() {
                let (s, _) = wall.distance([g.x[k], g.y[k]]);
                if s < g.radius[k] + self.skin {
                    let kp = (k as u64) << 32 | w as u64;
                    while o < old_g.len() && ((old_g[o] as u64) << 32 | old_w[o] as u64) < kp {
                        o += 1;
                    }
                    let st = if o < old_g.len() && ((old_g[o] as u64) << 32 | old_w[o] as u64) == kp
                    {
                        old_s[o]
                    } else {
                        ContactState::default()
                    };
                    wl.grain.push(k as u32);
                    wl.wall.push(w as u32);
                    wl.state.push(st);
                }
            }
            wl.first[k + 1] = wl.grain.len() as u32;
        }
    }
}
