//! Mohr–Coulomb elastic–perfectly plastic material, plane strain, non-associated flow, with a
//! tension cut-off; return mapping in principal stresses (Clausen, Damkilde & Andersen 2006:
//! plane, edge and apex returns).
//!
//! Principal stresses σ₁ ≥ σ₂ ≥ σ₃ (tension positive; σ_zz is one of the three). With
//! k = (1 + sin φ)/(1 − sin φ), σ_c = 2c cos φ/(1 − sin φ), m = (1 + sin ψ)/(1 − sin ψ):
//!
//! * yield function  f = k σ₁ − σ₃ − σ_c  (in compression-positive terms the familiar
//!   σ₁′ = σ₃′ (1 + sin φ)/(1 − sin φ) + 2c cos φ/(1 − sin φ) at failure);
//! * plastic potential g = m σ₁ − σ₃, flow direction b = ∂g/∂σ = (m, 0, −1); ψ = 0 gives
//!   m = 1 and tr b = 0: no plastic volume change;
//! * elastic predictor σ_B = σ* + C : Δε (σ* the Jaumann-rotated stress); if f(σ_B) > 0:
//!   - plane return: σ = σ_B − Δλ D b, Δλ = f(σ_B)/(a·D b), a = ∂f/∂σ = (k, 0, −1);
//!   - if that breaks the order σ₁ ≥ σ₂ ≥ σ₃, return to the edge it crossed, the line
//!     σ = σ_apex + t r (r = (1, 1, k) where σ₁ = σ₂, r = (1, k, k) where σ₂ = σ₃) with two
//!     plastic multipliers: σ_B − σ lies in span(D b₁, D b₂), so with n = D b₁ × D b₂,
//!     t = n·(σ_B − σ_apex)/(n·r);
//!   - if t > 0 the line return passes the apex: σ = σ_apex = σ_c/(k − 1) (1, 1, 1).
//! * tension cut-off σ_t (≤ the apex stress c cot φ): after the Mohr–Coulomb return any
//!   principal stress above σ_t is returned onto σ_i = σ_t along D eᵢ (Rankine, associated).
//!   This lowers f (Δf = −Δλ (k(λ+2G) − λ) < 0), so the result stays admissible; at the corner
//!   of the two surfaces it is the sequential, not the closest-point, return.
//!
//! The principal directions in the plane are those of σ_B (isotropic elasticity keeps them).

use super::elastic::LinearElastic;
use super::{Failure, Material, MaterialState, Strain, Stress};

/// Mohr–Coulomb parameters, with the constants of the return mapping (k, m, σ_c, apex, λ,
/// 2G) derived once in [`MohrCoulomb::new`] rather than per call (they need sin/cos of the
/// angles, which otherwise cost a third of the update).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct MohrCoulomb {
    elastic: LinearElastic,
    friction_angle: f64,
    dilatancy_angle: f64,
    cohesion: f64,
    tension_cutoff: f64,
    derived: Derived,
}

/// Constants derived from the parameters (see the module doc for the formulas).
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
struct Derived {
    k: f64,
    m: f64,
    sigma_c: f64,
    apex: f64,
    lambda: f64,
    two_g: f64,
    /// (1 + ν)/E and ν/E: ε = (1 + ν)/E σ − ν/E tr σ (plane strain, principal components).
    compliance: f64,
    poisson_compliance: f64,
    /// D b for the plane return and 1/(a·D b).
    db: P3,
    inv_adb: f64,
    /// Edge returns: n = D b₁ × D b₂ and 1/(n·r) for the edges σ₁ = σ₂ (extension) and σ₂ = σ₃
    /// (compression).
    n_ext: P3,
    inv_nr_ext: f64,
    n_comp: P3,
    inv_nr_comp: f64,
    /// The effective tension cut-off min(σ_t, apex).
    cutoff: f64,
}

type P3 = [f64; 3];

#[inline(always)]
fn dot(a: &P3, b: &P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross(a: &P3, b: &P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Which return the last call took (for the tests and diagnostics).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Return {
    /// Inside the yield surface.
    Elastic,
    /// Onto the yield plane.
    Plane,
    /// Onto the edge σ₁ = σ₂.
    EdgeExtension,
    /// Onto the edge σ₂ = σ₃.
    EdgeCompression,
    /// Onto the apex.
    Apex,
}

impl MohrCoulomb {
    /// Mohr–Coulomb material: friction angle φ (rad, 0 < φ < π/2), dilatancy angle ψ (rad,
    /// 0 ≤ ψ ≤ φ), cohesion c (Pa, ≥ 0) and tension cut-off σ_t (Pa, ≥ 0; values above the
    /// apex stress c cot φ act as the apex). The scenario checks the ranges.
    pub fn new(
        elastic: LinearElastic,
        friction_angle: f64,
        dilatancy_angle: f64,
        cohesion: f64,
        tension_cutoff: f64,
    ) -> Self {
        let (sp, cp) = friction_angle.sin_cos();
        let sd = dilatancy_angle.sin();
        let k = (1.0 + sp) / (1.0 - sp);
        let m = (1.0 + sd) / (1.0 - sd);
        let sigma_c = 2.0 * cohesion * cp / (1.0 - sp);
        let apex = sigma_c / (k - 1.0);
        let (lambda, two_g) = (elastic.lambda(), 2.0 * elastic.shear_modulus());
        let d = |v: P3| {
            let s = lambda * (v[0] + v[1] + v[2]);
            [s + two_g * v[0], s + two_g * v[1], s + two_g * v[2]]
        };
        let db = d([m, 0.0, -1.0]);
        let n_ext = cross(&db, &d([0.0, m, -1.0]));
        let n_comp = cross(&db, &d([m, -1.0, 0.0]));
        MohrCoulomb {
            elastic,
            friction_angle,
            dilatancy_angle,
            cohesion,
            tension_cutoff,
            derived: Derived {
                k,
                m,
                sigma_c,
                apex,
                lambda,
                two_g,
                compliance: (1.0 + elastic.poisson_ratio) / elastic.youngs_modulus,
                poisson_compliance: elastic.poisson_ratio / elastic.youngs_modulus,
                db,
                inv_adb: 1.0 / dot(&[k, 0.0, -1.0], &db),
                n_ext,
                inv_nr_ext: 1.0 / dot(&n_ext, &[1.0, 1.0, k]),
                n_comp,
                inv_nr_comp: 1.0 / dot(&n_comp, &[1.0, k, k]),
                cutoff: tension_cutoff.min(apex),
            },
        }
    }
    /// The elastic part.
    pub fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
    /// Friction angle φ (rad).
    pub fn friction_angle(&self) -> f64 {
        self.friction_angle
    }
    /// Dilatancy angle ψ (rad).
    pub fn dilatancy_angle(&self) -> f64 {
        self.dilatancy_angle
    }
    /// Cohesion c (Pa).
    pub fn cohesion(&self) -> f64 {
        self.cohesion
    }
    /// Tension cut-off σ_t (Pa).
    pub fn tension_cutoff(&self) -> f64 {
        self.tension_cutoff
    }
    /// k = (1 + sin φ)/(1 − sin φ).
    pub fn k(&self) -> f64 {
        self.derived.k
    }
    /// m = (1 + sin ψ)/(1 − sin ψ).
    pub fn m(&self) -> f64 {
        self.derived.m
    }
    /// σ_c = 2c cos φ/(1 − sin φ).
    pub fn sigma_c(&self) -> f64 {
        self.derived.sigma_c
    }
    /// Apex stress σ_c/(k − 1) = c cot φ.
    pub fn apex(&self) -> f64 {
        self.derived.apex
    }
    /// f(σ) = k σ₁ − σ₃ − σ_c for sorted principal stresses.
    pub fn yield_function(&self, p: &P3) -> f64 {
        self.k() * p[0] - p[2] - self.sigma_c()
    }

    /// D·v in principal space: λ (Σv) (1,1,1) + 2G v.
    #[cfg(test)]
    fn d(&self, v: &P3) -> P3 {
        let (l, g2) = (self.derived.lambda, self.derived.two_g);
        let s = l * (v[0] + v[1] + v[2]);
        [s + g2 * v[0], s + g2 * v[1], s + g2 * v[2]]
    }

    /// Return a sorted principal trial stress σ_B (σ₁ ≥ σ₂ ≥ σ₃) to the admissible set.
    #[inline(always)]
    pub fn return_principal(&self, sb: &P3) -> (P3, Return) {
        let dv = &self.derived;
        let (k, sc) = (dv.k, dv.sigma_c);
        let scale = sb
            .iter()
            .fold(self.elastic.youngs_modulus * 1e-12, |a, v| a.max(v.abs()));
        let f = k * sb[0] - sb[2] - sc;
        let (mut s, mut kind) = if f <= 1e-14 * scale {
            (*sb, Return::Elastic)
        } else {
            let db = dv.db;
            let dl = f * dv.inv_adb;
            let c = [sb[0] - dl * db[0], sb[1] - dl * db[1], sb[2] - dl * db[2]];
            let tol = 1e-12 * scale;
            let apex = dv.apex;
            // Edge return: σ = σ_apex + t r, t = n·(σ_B − σ_apex)/(n·r); past the apex if t > 0.
            let line = |r: P3, n: &P3, inv_nr: f64, edge: Return| -> (P3, Return) {
                let t = dot(n, &[sb[0] - apex, sb[1] - apex, sb[2] - apex]) * inv_nr;
                if t > 0.0 {
                    ([apex; 3], Return::Apex)
                } else {
                    ([apex + t * r[0], apex + t * r[1], apex + t * r[2]], edge)
                }
            };
            if c[1] > c[0] + tol {
                line(
                    [1.0, 1.0, k],
                    &dv.n_ext,
                    dv.inv_nr_ext,
                    Return::EdgeExtension,
                )
            } else if c[2] > c[1] + tol {
                line(
                    [1.0, k, k],
                    &dv.n_comp,
                    dv.inv_nr_comp,
                    Return::EdgeCompression,
                )
            } else {
                (c, Return::Plane)
            }
        };
        // Tension cut-off (Rankine) on whatever principal stresses exceed σ_t.
        let st = self.derived.cutoff;
        if s[0] > st {
            let l = self.derived.lambda;
            let lg = l + self.derived.two_g;
            let n_over = s.iter().filter(|&&v| v > st).count();
            match n_over {
                1 => {
                    let dl = (s[0] - st) / lg;
                    s = [st, s[1] - l * dl, s[2] - l * dl];
                }
                2 => {
                    // Solve [[lg, l], [l, lg]] (Δλ₁, Δλ₂) = (σ₁ − σ_t, σ₂ − σ_t).
                    let (r1, r2) = (s[0] - st, s[1] - st);
                    let det = lg * lg - l * l;
                    let d1 = (lg * r1 - l * r2) / det;
                    let d2 = (lg * r2 - l * r1) / det;
                    s = [st, st, s[2] - l * (d1 + d2)];
                }
                _ => s = [st; 3],
            }
            if kind == Return::Elastic {
                kind = Return::Apex;
            }
        }
        (s, kind)
    }

    /// Full update with the return reported (see [`Material::update_stress`]); inlined so
    /// that it is compiled for the vector extensions of the point pass that calls it
    /// ([`crate::exec::simd`]).
    #[inline(always)]
    pub fn update(
        &self,
        stress: &Stress,
        de: &Strain,
        spin: f64,
        state: &mut MaterialState,
    ) -> (Stress, Return) {
        let t =
            LinearElastic::trial_with(self.derived.lambda, self.derived.two_g, stress, de, spin);
        // In-plane principal stresses and direction.
        let p = 0.5 * (t[0] + t[1]);
        let q = 0.5 * (t[0] - t[1]);
        let r = (q * q + t[2] * t[2]).sqrt();
        let (s1, s2, sz) = (p + r, p - r, t[3]);
        // Sorted descending (s1 ≥ s2 always); `zslot` is where σ_zz went.
        let (sb, zslot) = if sz > s1 {
            ([sz, s1, s2], 0)
        } else if sz > s2 {
            ([s1, sz, s2], 1)
        } else {
            ([s1, s2, sz], 2)
        };
        let (sr, kind) = self.return_principal(&sb);
        if kind == Return::Elastic {
            state.yielding = false;
            return (t, kind);
        }
        // Plastic strain increment C⁻¹ (σ_B − σ) in principal space.
        let (a, b) = (self.derived.compliance, self.derived.poisson_compliance);
        let ds = [sb[0] - sr[0], sb[1] - sr[1], sb[2] - sr[2]];
        let tr = ds[0] + ds[1] + ds[2];
        let ep = ds.map(|v| a * v - b * tr);
        let ev = ep[0] + ep[1] + ep[2];
        let dev = ep.map(|v| v - ev * (1.0 / 3.0));
        state.plastic_strain += (2.0 / 3.0 * dot(&dev, &dev)).sqrt();
        state.plastic_volumetric += ev;
        state.yielding = true;
        // Returned in-plane principal values and σ_zz, undoing the sort.
        let out = match zslot {
            0 => [sr[1], sr[2], sr[0]],
            1 => [sr[0], sr[2], sr[1]],
            _ => sr,
        };
        // Back to x–y along the trial's principal directions: cos 2θ = q/r, sin 2θ = σ_xy/r.
        let (c2, s2) = if r > 0.0 {
            let inv = 1.0 / r;
            (q * inv, t[2] * inv)
        } else {
            (1.0, 0.0)
        };
        let (pa, pb) = (0.5 * (out[0] + out[1]), 0.5 * (out[0] - out[1]));
        ([pa + pb * c2, pa - pb * c2, pb * s2, out[2]], kind)
    }
}

impl Material for MohrCoulomb {
    type State = MaterialState;
    #[inline(always)]
    fn update_stress(
        &self,
        stress: &Stress,
        de: &Strain,
        spin: f64,
        _dt: f64,
        state: &mut MaterialState,
    ) -> Result<Stress, Failure> {
        Ok(self.update(stress, de, spin, state).0)
    }
    fn density(&self) -> f64 {
        self.elastic.density
    }
    fn p_wave_modulus(&self) -> f64 {
        self.elastic.p_wave_modulus()
    }
    fn elastic_energy_density(&self, s: &Stress, _: &MaterialState) -> f64 {
        self.elastic.energy_density(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mc(phi: f64, psi: f64, c: f64, st: f64) -> MohrCoulomb {
        let elastic = LinearElastic {
            density: 2000.0,
            youngs_modulus: 2e7,
            poisson_ratio: 0.3,
        };
        MohrCoulomb::new(elastic, phi.to_radians(), psi.to_radians(), c, st)
    }

    /// A small deterministic generator of sorted principal trial stresses over all regions.
    fn trials(n: usize) -> Vec<P3> {
        let mut x = 0x9E3779B97F4A7C15u64;
        let mut u = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let mut v = [0.0; 3].map(|_: f64| -2e5 * u() + 4e4 * u());
                v.sort_by(|a, b| b.total_cmp(a));
                v
            })
            .collect()
    }

    /// After any return: f(σ) ≤ 0 (= 0 to round-off when Mohr–Coulomb was active), σ₁ ≥ σ₂ ≥
    /// σ₃, σ₁ ≤ σ_t; all five regions are visited; elastic trials are unchanged.
    #[test]
    fn return_lands_on_the_yield_surface_in_order() {
        for (phi, psi, c) in [
            (20.0, 0.0, 0.0),
            (30.0, 10.0, 1e4),
            (40.0, 0.0, 1e4),
            (35.0, 35.0, 5e3),
        ] {
            let m = mc(phi, psi, c, 1e9);
            let mut seen = std::collections::HashSet::new();
            for sb in trials(20000) {
                let (s, kind) = m.return_principal(&sb);
                seen.insert(format!("{kind:?}"));
                let f = m.yield_function(&s);
                let scale = 2e5;
                assert!(f <= 1e-9 * scale, "{kind:?} f={f}");
                assert!(
                    s[0] >= s[1] - 1e-9 * scale && s[1] >= s[2] - 1e-9 * scale,
                    "{kind:?} {s:?}"
                );
                assert!(s[0] <= m.apex() + 1e-9 * scale);
                match kind {
                    Return::Elastic => assert_eq!(s, sb),
                    _ => assert!(f.abs() < 1e-9 * scale, "{kind:?} f={f}"),
                }
            }
            assert_eq!(seen.len(), 5, "φ={phi}: regions {seen:?}");
        }
    }

    /// Consistency of the plane return: σ_B − σ is parallel to D b (the flow rule), so with
    /// ψ = 0 the plastic strain C⁻¹(σ_B − σ) has no volume change; with ψ > 0 it dilates
    /// with tr ε^p/ε^p₁ = tr b/b₁ = (m − 1)/m.
    #[test]
    fn plane_return_follows_the_flow_rule() {
        for psi in [0.0, 10.0] {
            let m = mc(30.0, psi, 1e4, 1e9);
            let mut n = 0;
            for sb in trials(5000) {
                let (s, kind) = m.return_principal(&sb);
                if kind != Return::Plane {
                    continue;
                }
                n += 1;
                let ds = [sb[0] - s[0], sb[1] - s[1], sb[2] - s[2]];
                let db = m.d(&[m.m(), 0.0, -1.0]);
                let cr = cross(&ds, &db);
                assert!(dot(&cr, &cr).sqrt() < 1e-9 * dot(&ds, &ds).sqrt() * dot(&db, &db).sqrt());
                let e = &m.elastic;
                let tr = ds[0] + ds[1] + ds[2];
                let ep = ds.map(|v| {
                    ((1.0 + e.poisson_ratio) * v - e.poisson_ratio * tr) / e.youngs_modulus
                });
                let ratio = (ep[0] + ep[1] + ep[2]) / ep[0];
                assert!(
                    (ratio - (m.m() - 1.0) / m.m()).abs() < 1e-9,
                    "ψ={psi}: {ratio}"
                );
            }
            assert!(n > 100);
        }
    }

    /// Tension cut-off: no principal stress above σ_t after the return, and f ≤ 0 still.
    #[test]
    fn tension_cutoff_caps_the_major_stress() {
        let m = mc(30.0, 0.0, 2e4, 5e3);
        for sb in trials(5000) {
            let (s, _) = m.return_principal(&sb);
            assert!(s[0] <= 5e3 * (1.0 + 1e-12), "{s:?}");
            assert!(m.yield_function(&s) <= 1e-9 * 2e5);
        }
    }

    /// The full update keeps the principal directions and the stress invariant under a swap of
    /// axes (objectivity of the return with respect to in-plane orientation).
    #[test]
    fn update_is_isotropic() {
        let m = mc(30.0, 0.0, 0.0, 0.0);
        let s0 = [-1e5, -1e5, 0.0, -1e5];
        let de = [1e-2, -2e-2, 5e-3];
        let (a, kind) = m.update(&s0, &de, 0.0, &mut MaterialState::default());
        assert_ne!(kind, Return::Elastic);
        let (b, _) = m.update(
            &s0,
            &[de[1], de[0], de[2]],
            0.0,
            &mut MaterialState::default(),
        );
        assert!(
            (a[0] - b[1]).abs() < 1e-6 && (a[1] - b[0]).abs() < 1e-6 && (a[2] - b[2]).abs() < 1e-6
        );
        let p = |s: &Stress| {
            let q = 0.5 * (s[0] - s[1]);
            let r = (q * q + s[2] * s[2]).sqrt();
            let mut v = [0.5 * (s[0] + s[1]) + r, 0.5 * (s[0] + s[1]) - r, s[3]];
            v.sort_by(|x, y| y.total_cmp(x));
            v
        };
        let f = m.yield_function(&p(&a));
        assert!(f.abs() < 1e-9 * 1e6, "f = {f}");
    }
}
