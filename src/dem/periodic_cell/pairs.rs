//! What the two periodic cells share (this bi-periodic volume and the Lees–Edwards
//! [`crate::dem::shear_cell`]): carrying the contact history over a rebuild of the sorted
//! Verlet pair list, the kinematics of a disk pair, and the scatter of a pair's force to its
//! two grains.

use crate::dem::contact::{ContactState, Motion};

/// The pairs (i < j, sorted) of disks at (x, y) with radii `r` whose separation, as
/// `image` maps x_j − x_i, y_j − y_i to the nearest image's, is below R_i + R_j + `skin`: an
/// O(N²) search, fine for the few hundred grains of a periodic cell.
pub(crate) fn pairs_within(
    x: &[f64],
    y: &[f64],
    r: &[f64],
    skin: f64,
    image: impl Fn(f64, f64) -> (f64, f64),
) -> Vec<(u32, u32)> {
    let n = x.len();
    let mut pairs = Vec::with_capacity(4 * n);
    for i in 0..n {
        for j in i + 1..n {
            let (dx, dy) = image(x[j] - x[i], y[j] - y[i]);
            let reach = r[i] + r[j] + skin;
            if dx * dx + dy * dy < reach * reach {
                pairs.push((i as u32, j as u32));
            }
        }
    }
    pairs
}

/// The contact states of the sorted pair list `new`: carried from the sorted list `old` (with
/// its `state`) for every pair on both lists, fresh for the others (a merge of the two lists).
pub(crate) fn carry_history(
    old: &[(u32, u32)],
    state: &[ContactState],
    new: &[(u32, u32)],
) -> Vec<ContactState> {
    let mut out = Vec::with_capacity(new.len());
    let mut k = 0;
    for p in new {
        while k < old.len() && old[k] < *p {
            k += 1;
        }
        let kept = k < old.len() && old[k] == *p;
        out.push(if kept {
            state[k]
        } else {
            ContactState::default()
        });
    }
    out
}

/// The motion of disk i against (an image of) disk j at centre distance d along the unit
/// normal **n** from i to j, **t** = **n** turned by +90°: with the relative velocities
/// Δ**v** = **v**_i − **v**_j at the centres, [mid-step, predictor] in `dv`, the spins
/// [mid-step, predictor] of i and of j, the masses and the radii,
/// u = Δ**v**·**n**, v_t = Δ**v**·**t** + ω_i R_i + ω_j R_j, δ = R_i + R_j − d.
#[inline(always)]
pub(crate) fn disk_motion(
    d: f64,
    [nx, ny]: [f64; 2],
    dv: [[f64; 2]; 2],
    [wi, wj]: [[f64; 2]; 2],
    [mi, mj]: [f64; 2],
    [ri, rj]: [f64; 2],
) -> Motion {
    let (tx, ty) = (-ny, nx);
    let rs = ri + rj;
    let [[dvx, dvy], [ex, ey]] = dv;
    Motion {
        delta: rs - d,
        u: [dvx * nx + dvy * ny, ex * nx + ey * ny],
        v_t: [
            dvx * tx + dvy * ty + wi[0] * ri + wj[0] * rj,
            ex * tx + ey * ty + wi[1] * ri + wj[1] * rj,
        ],
        w: [wi[0] - wj[0], wi[1] - wj[1]],
        m_eff: mi * mj / (mi + mj),
        r_eff: ri * rj / rs,
    }
}

/// Add a pair's normal force a_n, tangential force a_t and rolling moment M to grain i,
/// **F**_i = −a_n **n** + a_t **t** and R_i a_t + M, and their reaction to grain j, −**F**_i
/// and R_j a_t − M. Returns **F**_i.
#[inline(always)]
pub(crate) fn scatter(
    f: &mut [[f64; 3]],
    (i, j): (usize, usize),
    [nx, ny]: [f64; 2],
    [ri, rj]: [f64; 2],
    [an, at, ar]: [f64; 3],
) -> (f64, f64) {
    let (f0, f1) = (-an * nx + at * -ny, -an * ny + at * nx);
    f[i][0] += f0;
    f[i][1] += f1;
    f[i][2] += ri * at + ar;
    f[j][0] -= f0;
    f[j][1] -= f1;
    f[j][2] += rj * at - ar;
    (f0, f1)
}
