//! General contact detection through rapier2d's collision pipeline (`rapier2d-f64`, so the
//! contact geometry is computed in f64): broad phase (BVH) and narrow phase (contact
//! manifolds) for disks, convex polygon grains, segments and convex polygon walls. Contacts
//! with half-plane walls are computed here, vertex by vertex (`plane_contacts`): a half-plane
//! is infinite and would pair with every grain in rapier's broad phase.
//!
//! Each grain is a collider without a rigid body (rapier integrates nothing; we move the
//! colliders to the grains' poses each step); each wall a fixed collider. A contact manifold
//! point gives, in the convention of the cell list ([`super::neighbours`] + the force loop of
//! [`super::solver`]):
//!
//! * the pair (i, j), i < j for two grains, (grain, wall) otherwise;
//! * the overlap δ = −dist (rapier's signed distance between the two contact points, < 0 when
//!   the shapes penetrate);
//! * the unit normal **n** from i towards j (or the wall): rapier's manifold normal
//!   **n**₁ = R₁ **n**₁^local, outward from the first collider, negated when the pair is
//!   stored the other way round;
//! * the contact point **p** = ½(**p**₁ + **p**₂), the midpoint of the two surface points, which
//!   is the lever arm origin for the torque: **r**_i = **p** − **x**_i (for a disk
//!   **r**_i = (R_i − δ/2)**n**);
//! * a key made of the two feature ids (vertex/face), which follows a contact point from one
//!   step to the next for the contact history.
//!
//! Points closer than the prediction distance (the Verlet skin) are reported too (δ < 0), so
//! the contact law sees a contact open and close.
//!
//! Which pairs it sees is set by [`Coverage`]: `All` (every grain pair and grain–wall pair; used
//! by the cross-check against the cell list) or `Complement` (only the pairs the cell list does
//! not handle: any pair with a polygon grain, and disk–polygon-wall pairs). The solver uses
//! `Complement`, and only when the system has a polygon grain or a polygon wall, so an all-disk
//! system never pays for rapier. Disks are still inserted in `Complement` mode (a disk may touch
//! a polygon) but collision groups keep disk–disk and disk–straight-wall pairs out of the
//! narrow phase.

use rapier2d_f64::geometry::{
    ActiveCollisionTypes, BroadPhaseBvh, ColliderBuilder, ColliderHandle, ColliderSet, Group,
    InteractionGroups, InteractionTestMode, NarrowPhase, SharedShape,
};
use rapier2d_f64::math::{Pose, Vector};
use rapier2d_f64::pipeline::CollisionPipeline;
use rapier2d_f64::prelude::{IslandManager, RigidBodySet};

use super::grains::Grains;
use super::neighbours::{Detector, PairList, WallList};
use super::walls::Wall;

/// Which pairs the rapier detector reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Coverage {
    /// Every grain–grain and grain–wall pair.
    All,
    /// Only pairs the cell list does not handle: a polygon grain on either side, or a disk and
    /// a polygon wall.
    Complement,
}

/// `Contact::j` of a wall contact has this bit set; the wall index is in the low bits.
pub const WALL_BIT: u32 = 1 << 31;

/// One contact point.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Contact {
    /// First grain.
    pub i: u32,
    /// Second grain (> i), or `WALL_BIT | wall index`.
    pub j: u32,
    /// Overlap δ (> 0: the shapes overlap).
    pub delta: f64,
    /// Unit normal from i towards j (or the wall).
    pub normal: [f64; 2],
    /// Contact point (midpoint of the two surface points).
    pub point: [f64; 2],
    /// Feature ids of the two sides (i's in the high half), stable while the same vertex/face
    /// pair is in contact.
    pub key: u64,
}

impl Contact {
    /// Sort key (i, j, features).
    #[inline]
    pub fn order(&self) -> (u32, u32, u64) {
        (self.i, self.j, self.key)
    }

    /// The wall index if this is a grain–wall contact.
    #[inline]
    pub fn wall(&self) -> Option<usize> {
        (self.j & WALL_BIT != 0).then_some((self.j & !WALL_BIT) as usize)
    }
}

/// Detections between two rebuilds of rapier's sets and phases. Its narrow phase, driven by
/// the collision pipeline with colliders moved by `set_position` (no rigid bodies), grows
/// without bound (rapier2d 0.36.1: 69 MB at the end of a 68-hexagon collapse,
/// tests/data/resume_dem.toml with `grains.sides = 6` to 8 τ_c, against 15 MB with a rebuild
/// every 1000); a rebuild frees it. Nothing physical is lost: contact history is the caller's,
/// keyed by the features rapier reports.
const REBUILD_EVERY: u32 = 1000;
const G_DISK: Group = Group::GROUP_1;
const G_POLY: Group = Group::GROUP_2;
const G_STRAIGHT: Group = Group::GROUP_3;
const G_POLY_WALL: Group = Group::GROUP_4;

/// The rapier2d collision pipeline with one collider per grain and per wall.
pub struct RapierDetector {
    coverage: Coverage,
    /// Prediction distance: points up to this gap are reported (δ ≥ −prediction).
    pub prediction: f64,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    islands: IslandManager,
    broad: BroadPhaseBvh,
    narrow: NarrowPhase,
    pipeline: CollisionPipeline,
    grain_handles: Vec<ColliderHandle>,
    /// Shapes the colliders were built for (rebuilt if the grains or walls change).
    built_for: (usize, usize),
    /// Detections since the last build.
    since_build: u32,
    /// Length unit of rapier's coordinates (m): see [`rapier_unit`].
    unit: f64,
}

impl std::fmt::Debug for RapierDetector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RapierDetector")
            .field("coverage", &self.coverage)
            .field("prediction", &self.prediction)
            .field("colliders", &self.colliders.len())
            .finish()
    }
}

impl Clone for RapierDetector {
    /// A clone starts with no colliders and builds them at its first [`RapierDetector::detect`]
    /// (rapier's caches are not part of the state: contact history lives with the caller).
    fn clone(&self) -> Self {
        RapierDetector::new(self.coverage, self.prediction)
    }
}

/// A checkpoint keeps what the detector is (coverage, prediction), not rapier's caches: like a
/// clone, a detector read back builds its colliders at its first detection.
impl serde::Serialize for RapierDetector {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (self.coverage, self.prediction).serialize(s)
    }
}

impl<'de> serde::Deserialize<'de> for RapierDetector {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (coverage, prediction) = <(Coverage, f64)>::deserialize(d)?;
        Ok(RapierDetector::new(coverage, prediction))
    }
}

impl RapierDetector {
    /// A detector reporting the pairs of `coverage` with points up to `prediction` apart.
    pub fn new(coverage: Coverage, prediction: f64) -> Self {
        RapierDetector {
            coverage,
            prediction,
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            islands: IslandManager::new(),
            broad: BroadPhaseBvh::new(),
            narrow: NarrowPhase::new(),
            pipeline: CollisionPipeline::new(),
            grain_handles: Vec::new(),
            built_for: (usize::MAX, usize::MAX),
            since_build: 0,
            unit: 1.0,
        }
    }

    /// Whether a system needs the rapier detector at all (some polygon grain or polygon wall).
    pub fn needed(g: &Grains, walls: &[Wall]) -> bool {
        g.has_polygons() || walls.iter().any(|w| !w.is_straight())
    }

    fn groups(&self, kind: Group) -> InteractionGroups {
        let filter = match (self.coverage, kind) {
            (Coverage::All, k) if k == G_DISK || k == G_POLY => Group::ALL,
            (Coverage::All, _) => G_DISK | G_POLY,
            (Coverage::Complement, k) if k == G_DISK => G_POLY | G_POLY_WALL,
            (Coverage::Complement, k) if k == G_POLY => Group::ALL,
            (Coverage::Complement, k) if k == G_STRAIGHT => G_POLY,
            (Coverage::Complement, _) => G_DISK | G_POLY,
        };
        InteractionGroups::new(kind, filter, InteractionTestMode::And)
    }

    fn build(&mut self, g: &Grains, walls: &[Wall]) {
        self.bodies = RigidBodySet::new();
        self.colliders = ColliderSet::new();
        self.islands = IslandManager::new();
        self.broad = BroadPhaseBvh::new();
        self.narrow = NarrowPhase::new();
        self.grain_handles.clear();
        self.unit = rapier_unit(g);
        let u = 1.0 / self.unit;
        let at = |p: [f64; 2]| Vector::new(u * p[0], u * p[1]);
        let mut scratch: Vec<Vector> = Vec::new();
        for i in 0..g.len() {
            let (shape, kind) = if g.is_disk(i) {
                (SharedShape::ball(u * g.radius[i]), G_DISK)
            } else {
                let s = g.shape[i] as usize;
                scratch.clear();
                scratch.extend(g.polygons.vertices(s).iter().map(|&v| at(v)));
                let shape = SharedShape::convex_polyline(scratch.clone())
                    .expect("polygon shapes are checked convex when added");
                (shape, G_POLY)
            };
            let c = ColliderBuilder::new(shape)
                .position(Pose::new(at([g.x[i], g.y[i]]), g.angle[i]))
                .collision_groups(self.groups(kind))
                .active_collision_types(ActiveCollisionTypes::all())
                .user_data(i as u128)
                .build();
            self.grain_handles.push(self.colliders.insert(c));
        }
        for (w, wall) in walls.iter().enumerate() {
            let (shape, pose, kind) = match *wall {
                // Half-planes are not given to rapier (`plane_contacts`).
                Wall::Plane { .. } => continue,
                Wall::Segment { a, b } => (
                    SharedShape::segment(at(a), at(b)),
                    Pose::identity(),
                    G_STRAIGHT,
                ),
                Wall::Disk { centre, radius } => (
                    SharedShape::ball(u * radius),
                    Pose::new(at(centre), 0.0),
                    G_STRAIGHT,
                ),
                Wall::Polygon { vertices, n } => (
                    SharedShape::convex_polyline(
                        vertices[..n as usize].iter().map(|&v| at(v)).collect(),
                    )
                    .expect("polygon walls are checked convex when made"),
                    Pose::identity(),
                    G_POLY_WALL,
                ),
            };
            let c = ColliderBuilder::new(shape)
                .position(pose)
                .collision_groups(self.groups(kind))
                .active_collision_types(ActiveCollisionTypes::all())
                .user_data(u128::from(WALL_BIT) | w as u128)
                .build();
            self.colliders.insert(c);
        }
        self.built_for = (g.len(), walls.len());
        self.since_build = 0;
    }

    /// Move the grain colliders to the grains' poses, run rapier's broad and narrow phase, and
    /// write every contact point (δ > −prediction) of the covered pairs into `out`, sorted by
    /// (i, j, key).
    pub fn detect(&mut self, g: &Grains, walls: &[Wall], out: &mut Vec<Contact>) {
        self.since_build += 1;
        if self.built_for != (g.len(), walls.len()) || self.since_build >= REBUILD_EVERY {
            self.build(g, walls);
        } else {
            let u = 1.0 / self.unit;
            for (i, &h) in self.grain_handles.iter().enumerate() {
                if let Some(c) = self.colliders.get_mut(h) {
                    c.set_position(Pose::new(Vector::new(u * g.x[i], u * g.y[i]), g.angle[i]));
                }
            }
        }
        let unit = self.unit;
        self.pipeline.step(
            self.prediction / unit,
            &mut self.islands,
            &mut self.broad,
            &mut self.narrow,
            &mut self.bodies,
            &mut self.colliders,
            &(),
            &(),
        );
        out.clear();
        for pair in self.narrow.contact_pairs() {
            let manifolds = pair.manifolds();
            if manifolds.is_empty() {
                continue;
            }
            let (c1, c2) = (
                &self.colliders[pair.collider1],
                &self.colliders[pair.collider2],
            );
            let (u1, u2) = (c1.user_data as u32, c2.user_data as u32);
            // Store (grain, grain) with i < j, or (grain, wall).
            let swap = (u1 & WALL_BIT != 0) || (u2 & WALL_BIT == 0 && u1 > u2);
            let (i, j) = if swap { (u2, u1) } else { (u1, u2) };
            let (p1, p2) = (c1.position(), c2.position());
            for m in manifolds {
                let n = p1.rotation * m.local_n1;
                let n = if swap { -n } else { n };
                for pt in &m.points {
                    let (a, b) = (
                        p1.transform_point(pt.local_p1),
                        p2.transform_point(pt.local_p2),
                    );
                    let p = 0.5 * unit * (a + b);
                    let (f1, f2) = (u64::from(pt.fid1.0), u64::from(pt.fid2.0));
                    out.push(Contact {
                        i,
                        j,
                        delta: -unit * pt.dist,
                        normal: [n.x, n.y],
                        point: [p.x, p.y],
                        key: if swap { f2 << 32 | f1 } else { f1 << 32 | f2 },
                    });
                }
            }
        }
        self.plane_contacts(g, walls, out);
        out.sort_unstable_by_key(|c| c.order());
    }

    /// Contacts with the half-plane walls, computed here rather than by rapier (a half-plane's
    /// bounding box is infinite: in rapier's broad phase it pairs with every grain, which made
    /// a detection of free-falling hexagons in a box 8 times slower). With (s, **n**) =
    /// [`Wall::distance`] of a point (s its height above the plane, **n** towards the plane):
    /// a disk of centre **x** has δ = R − s at **x** + (R − δ/2)**n**, key 0, as the cell
    /// list; a polygon has one point per vertex **v**_k with s_k < prediction, δ = −s_k at the
    /// middle of the overlap **v**_k + (s_k/2)**n**, key k. Disks only in `Coverage::All`.
    fn plane_contacts(&self, g: &Grains, walls: &[Wall], out: &mut Vec<Contact>) {
        for (w, wall) in walls.iter().enumerate() {
            if !matches!(wall, Wall::Plane { .. }) {
                continue;
            }
            let j = WALL_BIT | w as u32;
            for i in 0..g.len() {
                let c = [g.x[i], g.y[i]];
                if g.is_disk(i) {
                    if self.coverage == Coverage::Complement {
                        continue;
                    }
                    let (s, n) = wall.distance(c);
                    let delta = g.radius[i] - s;
                    if delta > -self.prediction {
                        let l = g.radius[i] - 0.5 * delta;
                        out.push(Contact {
                            i: i as u32,
                            j,
                            delta,
                            normal: n,
                            point: [c[0] + l * n[0], c[1] + l * n[1]],
                            key: 0,
                        });
                    }
                    continue;
                }
                // Whole polygon beyond reach: its bounding circle clears the plane.
                if wall.distance(c).0 - g.radius[i] >= self.prediction {
                    continue;
                }
                for (k, p) in g.world_vertices(i).enumerate() {
                    let (s, n) = wall.distance(p);
                    if s < self.prediction {
                        out.push(Contact {
                            i: i as u32,
                            j,
                            delta: -s,
                            normal: n,
                            point: [p[0] + 0.5 * s * n[0], p[1] + 0.5 * s * n[1]],
                            key: k as u64,
                        });
                    }
                }
            }
        }
    }
}

/// The length unit (m) of rapier's coordinates for grains `g`: the power of two nearest the
/// largest grain diameter (1 without grains). Rapier fattens each broad-phase leaf by 4 % of
/// its length unit (`BroadPhaseBvh`'s change-detection skin, length unit fixed at 1 by
/// `CollisionPipeline`): in metres, every millimetre grain would overlap every other in the
/// broad phase and all pairs would reach the narrow phase (25 ms per detection for 386 free
/// hexagons of 1.2 mm). In units of the grain size the skin is 4 % of a grain. A power of two
/// scales positions and lengths exactly.
fn rapier_unit(g: &Grains) -> f64 {
    let d = 2.0 * g.radius.iter().fold(0.0f64, |m, &r| m.max(r));
    if d > 0.0 && d.is_finite() {
        2f64.powi(d.log2().round() as i32)
    } else {
        1.0
    }
}

/// The contacts the cell list finds (disks only: disk–disk and disk–plane/segment pairs), with
/// δ and **n** computed exactly as the solver's force loop does: **n** = (**x**_j − **x**_i)/d,
/// δ = R_i + R_j − d; for a wall (s, **n**) = [`Wall::distance`], δ = R_i − s. The point is
/// **x**_i + (R_i − δ/2)**n**, key 0. Points with δ > −`gap` are listed, sorted by (i, j).
/// For the cross-check with [`RapierDetector`] (Coverage::All).
pub fn cell_list_contacts(g: &Grains, walls: &[Wall], skin: f64, gap: f64) -> Vec<Contact> {
    let mut det = Detector::new(skin);
    let (mut pl, mut wl) = (PairList::default(), WallList::default());
    det.build(g, walls, None, &mut pl, &mut wl);
    let mut out = Vec::new();
    for p in 0..pl.i.len() {
        let (i, j) = (pl.i[p] as usize, pl.j[p] as usize);
        let (dx, dy) = (g.x[j] - g.x[i], g.y[j] - g.y[i]);
        let d = (dx * dx + dy * dy).sqrt();
        let delta = g.radius[i] + g.radius[j] - d;
        if delta > -gap {
            let n = [dx / d, dy / d];
            let l = g.radius[i] - 0.5 * delta;
            out.push(Contact {
                i: i as u32,
                j: j as u32,
                delta,
                normal: n,
                point: [g.x[i] + l * n[0], g.y[i] + l * n[1]],
                key: 0,
            });
        }
    }
    for p in 0..wl.grain.len() {
        let (i, w) = (wl.grain[p] as usize, wl.wall[p] as usize);
        let (s, n) = walls[w].distance([g.x[i], g.y[i]]);
        let delta = g.radius[i] - s;
        if delta > -gap {
            let l = g.radius[i] - 0.5 * delta;
            out.push(Contact {
                i: i as u32,
                j: WALL_BIT | w as u32,
                delta,
                normal: n,
                point: [g.x[i] + l * n[0], g.y[i] + l * n[1]],
                key: 0,
            });
        }
    }
    out.sort_unstable_by_key(|c| c.order());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dem::shape::Polygons;

    /// Millimetre hexagons (circumradius 0.6 mm) on a 1.6 mm lattice, 0.4 mm apart at the
    /// closest: no pair is within the prediction distance (0.1 mm) plus rapier's broad-phase
    /// skin (4 % of the length unit, here 2⁻¹⁰ m), so none may reach the narrow phase. With
    /// rapier's coordinates in metres the skin was 40 mm and all 4950 pairs did.
    #[test]
    fn distant_millimetre_grains_make_no_narrow_phase_pairs() {
        let mut g = Grains::default();
        for k in 0..100 {
            let s = g
                .polygons
                .add(&Polygons::regular(6, 0.6e-3, 0.0), "hexagon")
                .unwrap();
            let (row, col) = ((k / 10) as f64, (k % 10) as f64);
            g.push_polygon(1.6e-3 * (col + 0.5), 1.6e-3 * (row + 0.5), 0.3, s, 2500.0);
        }
        let mut det = RapierDetector::new(Coverage::All, 1e-4);
        let mut out = Vec::new();
        det.detect(&g, &[], &mut out);
        assert_eq!(det.unit, 2f64.powi(-10));
        assert!(out.is_empty());
        assert_eq!(det.narrow.contact_pairs().count(), 0);
        // Not vacuous: bring two neighbours within the prediction distance.
        g.x[1] = g.x[0] + 1.05e-3 + 0.5e-4;
        det.detect(&g, &[], &mut out);
        assert!(!out.is_empty());
    }
}
