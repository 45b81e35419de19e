//! Removing grains from a running system (an outlet, a sink): the grains left keep their
//! state, contact history and forces, so a removal that touches no contact leaves the motion of
//! the others unchanged bit for bit.

use super::Dem;
use crate::{Error, Result};

impl Dem {
    /// Remove the grains whose entry of `gone` is true and return how many went. The others
    /// keep their order (indices above a removed grain shift down), velocities, forces and
    /// the history of their contacts with each other and with the walls; the contacts of a
    /// removed grain simply end (the force it exerted stays in its partners' force arrays until
    /// the next evaluation, as for a contact that ends inside a step). The neighbour lists are
    /// rebuilt before the next force evaluation.
    ///
    /// The energy budget ([`Dem::energy`]) does not book what the removed grains carry away,
    /// so it no longer closes. All-disk systems with straight walls only: contacts found by the
    /// rapier detector (polygon grains or walls) are refused.
    pub fn remove_grains(&mut self, gone: &[bool]) -> Result<usize> {
        let n = self.grains.len();
        if gone.len() != n {
            return Err(Error::Other(format!(
                "remove_grains: {} flags for {n} grains",
                gone.len()
            )));
        }
        let removed = gone.iter().filter(|&&g| g).count();
        if removed == 0 {
            return Ok(0);
        }
        if self.shapes.is_some() {
            return Err(Error::Other(
                "grains can be removed only from an all-disk system with straight walls".into(),
            ));
        }
        let keep: Vec<bool> = gone.iter().map(|&g| !g).collect();
        let mut index = vec![u32::MAX; n];
        let mut k = 0u32;
        for (i, new) in index.iter_mut().enumerate() {
            if keep[i] {
                *new = k;
                k += 1;
            }
        }
        self.grains.retain(&keep);
        for v in [
            &mut self.inv_mass,
            &mut self.inv_inertia,
            &mut self.vxp,
            &mut self.vyp,
            &mut self.wp,
        ] {
            if v.len() == n {
                crate::dem::grains::compact(v, &keep);
            }
        }
        // Both lists stay sorted: the renumbering keeps the order of the grains left.
        let pl = &mut self.pairs;
        let mut m = 0;
        for p in 0..pl.i.len() {
            let (i, j) = (index[pl.i[p] as usize], index[pl.j[p] as usize]);
            if i != u32::MAX && j != u32::MAX {
                pl.i[m] = i;
                pl.j[m] = j;
                pl.state[m] = pl.state[p];
                pl.flags[m] = pl.flags[p];
                m += 1;
            }
        }
        pl.i.truncate(m);
        pl.j.truncate(m);
        pl.state.truncate(m);
        pl.flags.truncate(m);
        let wl = &mut self.wall_pairs;
        let mut m = 0;
        for p in 0..wl.grain.len() {
            let g = index[wl.grain[p] as usize];
            if g != u32::MAX {
                wl.grain[m] = g;
                wl.wall[m] = wl.wall[p];
                wl.state[m] = wl.state[p];
                m += 1;
            }
        }
        wl.grain.truncate(m);
        wl.wall.truncate(m);
        wl.state.truncate(m);
        let left = k as usize;
        first_index(&self.pairs.i, left, &mut self.pairs.first);
        first_index(&self.wall_pairs.grain, left, &mut self.wall_pairs.first);
        // Rebuild the lists (and their cell grid) before the next force evaluation.
        self.moved = true;
        Ok(removed)
    }
}

/// `first[g]..first[g + 1]` are the entries of the sorted `owner` list that belong to grain g.
fn first_index(owner: &[u32], n: usize, first: &mut Vec<u32>) {
    first.clear();
    first.resize(n + 1, 0);
    for &g in owner {
        first[g as usize + 1] += 1;
    }
    for g in 0..n {
        first[g + 1] += first[g];
    }
}

#[cfg(test)]
mod tests {
    use crate::dem::{ContactParams, Dem, DemParams, Grains, Wall};

    /// A pile of 40 disks settling in a box; with `extra`, one more disk falls freely high
    /// above, listed as grain 5.
    fn pile(extra: bool) -> Dem {
        let mut g = Grains::new();
        for k in 0..40 {
            if extra && k == 5 {
                g.push_disk(0.011, 5.0, 0.0011, 2500.0);
            }
            let (i, j) = (k % 8, k / 8);
            let r = 0.001 + 0.0001 * ((k * 7) % 5) as f64;
            let x = 0.0015 + 0.0026 * i as f64 + 0.00005 * ((k * 3) % 4) as f64;
            g.push_disk(x, 0.0015 + 0.0024 * j as f64, r, 2500.0);
        }
        let law = ContactParams {
            restitution: 0.8,
            friction: 0.5,
            ..ContactParams::elastic(1.0e4)
        };
        let walls = vec![Wall::floor(0.0), Wall::left(0.0), Wall::right(0.022)];
        Dem::new(g, walls, DemParams::new(law, law, [0.0, -9.81])).unwrap()
    }

    /// Removing a grain that touches nothing leaves the others' motion bit for bit as if it
    /// had never been there (the pile is in contact throughout, so histories and the rebuilt
    /// lists are exercised).
    #[test]
    fn removing_a_free_grain_changes_nothing_else() {
        let (mut with, mut without) = (pile(true), pile(false));
        assert_eq!(with.dt(), without.dt());
        with.steps(3000);
        without.steps(3000);
        assert!(without.contact_count() > 20, "the pile is in contact");
        let mut gone = vec![false; 41];
        gone[5] = true;
        assert_eq!(with.remove_grains(&gone).unwrap(), 1);
        assert_eq!(with.grains.len(), 40);
        with.steps(3000);
        without.steps(3000);
        let (a, b) = (&with.grains, &without.grains);
        for (u, v) in [
            (&a.x, &b.x),
            (&a.y, &b.y),
            (&a.vx, &b.vx),
            (&a.omega, &b.omega),
        ] {
            assert_eq!(u, v);
        }
        assert_eq!(with.contact_count(), without.contact_count());
    }

    /// Removing grains in contact ends their contacts: the grains left see only each other.
    #[test]
    fn removed_grains_leave_no_contacts() {
        let mut dem = pile(false);
        dem.steps(3000);
        let gone: Vec<bool> = (0..40).map(|k| k % 3 == 0).collect();
        assert_eq!(dem.remove_grains(&gone).unwrap(), 14);
        let pl = dem.pairs();
        assert!(pl.i.iter().chain(&pl.j).all(|&k| k < 26));
        assert_eq!(pl.first.len(), 27);
        dem.steps(10);
        assert!(dem.grains.y.iter().all(|y| y.is_finite()));
        assert!(
            dem.remove_grains(&[false; 3]).is_err(),
            "one flag per grain"
        );
    }
}
