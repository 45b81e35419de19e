//! Per-grain stress tensor (Love–Weber): for grain i of volume V_i = A_i t (A_i = πR_i² for a
//! disk, the polygon's area otherwise; t the axial length of the grains, 1 when forces are per
//! unit depth),
//!
//! σ_i = (1/V_i) Σ_c **f**_c ⊗ **l**_c,  σ_ab = (1/V_i) Σ_c f_a l_b,
//!
//! summed over its contacts c (grain–grain and grain–wall), with **f**_c the contact force on
//! grain i (−f_n **n** + f_t **t**, see [`crate::dem::contact`]) and **l**_c the branch vector
//! from the centre to the contact point, taken in the middle of the overlap:
//! **l**_c = (R_i − δ/2) **n** (**n** from i towards the partner); for a contact found by rapier
//! (a polygon grain or wall) **l**_c = **p**_c − **x**_i, from the centre to the contact point
//! (the middle of the overlap, [`crate::dem::detect_rapier`]). Tension is positive, so a
//! grain squeezed along x has σ_xx < 0. The tensor is symmetric when the grain's contact torques
//! balance (at rest); in motion the antisymmetric part is the contacts' net torque / V_i.
//! Summing V_i σ_i over a region and dividing by the region's volume gives the usual
//! homogenised stress of the packing (the voids contribute nothing).

use super::detect_rapier::WALL_BIT;
use super::params::min_image;
use super::solver::Dem;

/// Love–Weber stress of every grain (Pa), row-major `[xx, xy, yx, yy]`, from the contact
/// forces of the last force evaluation at the current positions; `thickness` is the disks'
/// axial length t (1 if the forces are per unit depth).
pub fn grain_stress(dem: &Dem, thickness: f64) -> Vec<[f64; 4]> {
    let g = &dem.grains;
    let mut s = vec![[0.0; 4]; g.len()];
    let mut add = |i: usize, f: [f64; 2], l: [f64; 2]| {
        let t = &mut s[i];
        t[0] += f[0] * l[0];
        t[1] += f[0] * l[1];
        t[2] += f[1] * l[0];
        t[3] += f[1] * l[1];
    };
    let pl = dem.pairs();
    for p in 0..pl.i.len() {
        let st = &pl.state[p];
        if !st.touching() {
            continue;
        }
        let (i, j) = (pl.i[p] as usize, pl.j[p] as usize);
        let dx = min_image(g.x[j] - g.x[i], dem.params().period());
        let dy = g.y[j] - g.y[i];
        let d = (dx * dx + dy * dy).sqrt();
        let n = if d > 0.0 {
            [dx / d, dy / d]
        } else {
            [1.0, 0.0]
        };
        let half = 0.5 * (g.radius[i] + g.radius[j] - d);
        let f = [
            -st.f_n * n[0] - st.f_t * n[1],
            -st.f_n * n[1] + st.f_t * n[0],
        ];
        let (li, lj) = (g.radius[i] - half, g.radius[j] - half);
        add(i, f, [li * n[0], li * n[1]]);
        add(j, [-f[0], -f[1]], [-lj * n[0], -lj * n[1]]);
    }
    let wl = dem.wall_pairs();
    for p in 0..wl.grain.len() {
        let st = &wl.state[p];
        if !st.touching() {
            continue;
        }
        let i = wl.grain[p] as usize;
        let (dist, n) = dem.walls[wl.wall[p] as usize].distance([g.x[i], g.y[i]]);
        let l = g.radius[i] - 0.5 * (g.radius[i] - dist);
        let f = [
            -st.f_n * n[0] - st.f_t * n[1],
            -st.f_n * n[1] + st.f_t * n[0],
        ];
        add(i, f, [l * n[0], l * n[1]]);
    }
    if let Some(sc) = dem.shape_contacts() {
        for ((c, st), f) in sc.found.iter().zip(&sc.state).zip(&sc.force) {
            if !st.touching() {
                continue;
            }
            let i = c.i as usize;
            add(i, *f, [c.point[0] - g.x[i], c.point[1] - g.y[i]]);
            if c.j & WALL_BIT == 0 {
                let j = c.j as usize;
                add(
                    j,
                    [-f[0], -f[1]],
                    [c.point[0] - g.x[j], c.point[1] - g.y[j]],
                );
            }
        }
    }
    for (i, t) in s.iter_mut().enumerate() {
        let a = g.grain_area(i) * thickness;
        for v in t.iter_mut() {
            *v /= a;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::{ContactParams, DemParams, Grains, Wall};
    use approx::assert_relative_eq;

    /// Two disks at rest overlapping by δ along x: each feels f_n = k_n δ (no velocity, so no
    /// dashpot) and σ_xx = −k_n δ (R − δ/2)/(πR²), every other component 0 (exact; the
    /// tolerance is round-off).
    #[test]
    fn two_disks_in_compression() {
        let (k, r, delta) = (1e5, 0.01, 1e-4);
        let mut g = Grains::new();
        g.push(0.0, 0.0, r, 1.0);
        g.push(2.0 * r - delta, 0.0, r, 1.0);
        let law = ContactParams::elastic(k);
        let mut dem = Dem::new(g, vec![], DemParams::new(law, law, [0.0, 0.0])).unwrap();
        dem.refresh_forces();
        let s = grain_stress(&dem, 1.0);
        let want = -k * delta * (r - 0.5 * delta) / (std::f64::consts::PI * r * r);
        for t in &s {
            assert_relative_eq!(t[0], want, max_relative = 1e-12);
            assert!(t[1].abs() + t[2].abs() + t[3].abs() < 1e-12 * want.abs());
        }
    }

    /// A disk pressed into the floor by δ: σ_yy = −k_n δ (R − δ/2)/(πR²).
    #[test]
    fn disk_on_the_floor() {
        let (k, r, delta) = (2e5, 0.02, 3e-4);
        let mut g = Grains::new();
        g.push(0.5, r - delta, r, 1.0);
        let law = ContactParams::elastic(k);
        let mut dem = Dem::new(
            g,
            vec![Wall::floor(0.0)],
            DemParams::new(law, law, [0.0, 0.0]),
        )
        .unwrap();
        dem.refresh_forces();
        let s = grain_stress(&dem, 1.0);
        let want = -k * delta * (r - 0.5 * delta) / (std::f64::consts::PI * r * r);
        assert_relative_eq!(s[0][3], want, max_relative = 1e-12);
        assert!(s[0][0].abs() + s[0][1].abs() + s[0][2].abs() < 1e-12 * want.abs());
    }

    /// A square grain of side a pressed flat into the floor by δ (no gravity, at rest): rapier
    /// reports its two bottom corners, each at the middle of the overlap, y = −δ/2, with the
    /// floor's push F/2 up; the lever arms are (±a/2, −(a − δ)/2) from the centre, so
    /// σ_yy = −F (a − δ)/(2a²) on the square's area a², σ_xx = σ_xy = 0 (the x arms cancel).
    /// F is the force on the grain from the solver, which is 2 k_n δ (one spring per corner).
    #[test]
    fn square_on_the_floor() {
        use crate::dem::shape::Polygons;
        let (k, a, delta) = (2e5, 0.02, 3e-4);
        let mut g = Grains::new();
        let sq = g
            .polygons
            .add(
                &Polygons::regular(4, a / 2f64.sqrt(), std::f64::consts::FRAC_PI_4),
                "sq",
            )
            .unwrap();
        g.push_polygon(0.5, 0.5 * a - delta, 0.0, sq, 1.0);
        let law = ContactParams::elastic(k);
        let mut dem = Dem::new(
            g,
            vec![Wall::floor(0.0)],
            DemParams::new(law, law, [0.0, 0.0]),
        )
        .unwrap();
        dem.refresh_forces();
        let sc = dem.shape_contacts().unwrap();
        let f: f64 = sc.force.iter().map(|f| f[1]).sum();
        assert_eq!(sc.found.len(), 2);
        assert_relative_eq!(f, 2.0 * k * delta, max_relative = 1e-9);
        let s = grain_stress(&dem, 1.0);
        let want = -f * (a - delta) / (2.0 * a * a);
        assert_relative_eq!(s[0][3], want, max_relative = 1e-9);
        assert!(s[0][0].abs() + s[0][1].abs() + s[0][2].abs() < 1e-9 * want.abs());
    }

    /// Static equilibrium of a frictional heap (with rolling resistance, so it stops) on the
    /// floor, no side walls. Summing
    /// A_i σ_i over all grains, the grain–grain terms cancel (both grains use the same contact
    /// point) and what is left is the virial of the external forces:
    /// Σ_i A_i σ_yy,i = Σ_floor f_y y_c + Σ_i m_i g_y y_i, with y_c = y_i − l the floor contact
    /// points. At rest the residual is the grains' leftover acceleration; the heap is brought
    /// to rest with global damping until the kinetic energy is < 1e-12 of m g d per grain, and
    /// the identity is checked to 1e-6 relative (measured: 1.6e-7).
    #[test]
    fn heap_at_rest_balances_the_weight() {
        use crate::dem::packing::{hex_block, SizeDistribution};
        let g = hex_block(
            0.05,
            0.006,
            8,
            6,
            0.0105,
            [0.008, 0.011],
            SizeDistribution::Uniform,
            2500.0,
            7,
        );
        let law = ContactParams {
            k_n: 1e5,
            k_t: 1e5,
            restitution: 0.5,
            gamma_n: 0.0,
            gamma_t: 0.0,
            friction: 0.5,
            rolling_stiffness: 1.0,
            rolling_damping: 1e-3,
            rolling_friction: 0.3,
        };
        let mut p = DemParams::new(law, law, [0.0, -9.81]);
        p.global_damping = 20.0;
        let mut dem = Dem::new(g, vec![Wall::floor(0.0)], p).unwrap();
        let n = dem.grains.len() as f64;
        let scale = dem.grains.mass[0] * 9.81 * 0.01;
        for _ in 0..400 {
            dem.steps(500);
            if dem.energy().kinetic_total() < 1e-12 * scale * n {
                break;
            }
        }
        assert!(dem.energy().kinetic_total() < 1e-12 * scale * n);
        let s = grain_stress(&dem, 1.0);
        let g = &dem.grains;
        let lhs: f64 = (0..g.len())
            .map(|i| std::f64::consts::PI * g.radius[i] * g.radius[i] * s[i][3])
            .sum();
        let mut rhs: f64 = (0..g.len()).map(|i| -9.81 * g.mass[i] * g.y[i]).sum();
        let wl = dem.wall_pairs();
        for p in 0..wl.grain.len() {
            if wl.state[p].touching() {
                let i = wl.grain[p] as usize;
                let l = 0.5 * (g.radius[i] + g.y[i]);
                rhs += wl.state[p].f_n * (g.y[i] - l);
            }
        }
        assert_relative_eq!(lhs, rhs, max_relative = 1e-6);
    }
}
