//! Material points as a structure of arrays: one `Vec` per field (small fixed arrays for the
//! vector and tensor fields, as Taichi's vector fields), no heap object per point.

use super::material::{MaterialState, Stress};

/// The material points, with the per-point state `S` of their material law.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Points<S = MaterialState> {
    /// Position (m).
    pub pos: Vec<[f64; 2]>,
    /// Initial position (m), for Lagrangian reference solutions.
    pub pos0: Vec<[f64; 2]>,
    /// Velocity (m/s).
    pub vel: Vec<[f64; 2]>,
    /// Mass (kg per unit thickness: the model is 2-D, volumes are areas × 1 m).
    pub mass: Vec<f64>,
    /// Current volume V = det(F) V₀ (m³ per m).
    pub vol: Vec<f64>,
    /// Initial volume V₀.
    pub vol0: Vec<f64>,
    /// Deformation gradient F (xx, xy, yx, yy), updated F ← (I + Δt L) F.
    pub def_grad: Vec<[f64; 4]>,
    /// Cauchy stress (xx, yy, xy, zz), Pa, tension positive.
    pub stress: Vec<Stress>,
    /// The material law's per-point state (plastic history, or a representative volume).
    pub state: Vec<S>,
    /// uGIMP half-width l_p of the point's domain (m); constant (not updated).
    pub half_size: Vec<f64>,
    /// Stress work done on the point, ∫ σ : D V dt (J per m), plus its initial elastic energy.
    pub work: Vec<f64>,
    /// APIC affine matrix B_p = Σ_i N_ip v_i ⊗ (x_i − x_p) (xx, xy, yx, yy), m²/s; zero and
    /// unused with the FLIP/PIC transfer.
    pub affine: Vec<[f64; 4]>,
}

impl<S> Default for Points<S> {
    fn default() -> Self {
        Points {
            pos: Vec::new(),
            pos0: Vec::new(),
            vel: Vec::new(),
            mass: Vec::new(),
            vol: Vec::new(),
            vol0: Vec::new(),
            def_grad: Vec::new(),
            stress: Vec::new(),
            state: Vec::new(),
            half_size: Vec::new(),
            work: Vec::new(),
            affine: Vec::new(),
        }
    }
}

impl<S: Default> Points<S> {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Add one point at rest, unstressed, with F = I.
    pub fn push(&mut self, pos: [f64; 2], vol: f64, density: f64, half_size: f64) {
        self.pos.push(pos);
        self.pos0.push(pos);
        self.vel.push([0.0; 2]);
        self.mass.push(vol * density);
        self.vol.push(vol);
        self.vol0.push(vol);
        self.def_grad.push([1.0, 0.0, 0.0, 1.0]);
        self.stress.push([0.0; 4]);
        self.state.push(S::default());
        self.half_size.push(half_size);
        self.work.push(0.0);
        self.affine.push([0.0; 4]);
    }

    /// Fill the rectangle [x0, x1] × [y0, y1] with `n` × `n` points per cell of size `h` (the
    /// rectangle's sides should be multiples of h/n), each of volume (h/n)² and half-width
    /// l_p = h/(2n).
    pub fn fill_rect(&mut self, lo: [f64; 2], hi: [f64; 2], h: f64, n: usize, density: f64) {
        self.fill_where(lo, hi, h, n, density, |_| true);
    }

    /// As [`Points::fill_rect`], keeping only the points whose position `inside` accepts.
    pub fn fill_where(
        &mut self,
        lo: [f64; 2],
        hi: [f64; 2],
        h: f64,
        n: usize,
        density: f64,
        inside: impl Fn([f64; 2]) -> bool,
    ) {
        let d = h / n as f64;
        let nx = ((hi[0] - lo[0]) / d).round() as usize;
        let ny = ((hi[1] - lo[1]) / d).round() as usize;
        for i in 0..nx {
            for j in 0..ny {
                let p = [lo[0] + (i as f64 + 0.5) * d, lo[1] + (j as f64 + 0.5) * d];
                if inside(p) {
                    self.push(p, d * d, density, 0.5 * d);
                }
            }
        }
    }

    /// Reorder every field by `perm` (new k ← old perm[k]), with `scratch` buffers reused.
    pub fn permute(&mut self, perm: &[u32], scratch: &mut PermuteScratch<S>) {
        fn apply<T: Copy>(v: &mut Vec<T>, perm: &[u32], s: &mut Vec<T>) {
            s.clear();
            s.extend(perm.iter().map(|&k| v[k as usize]));
            std::mem::swap(v, s);
        }
        apply(&mut self.pos, perm, &mut scratch.v2);
        apply(&mut self.pos0, perm, &mut scratch.v2);
        apply(&mut self.vel, perm, &mut scratch.v2);
        apply(&mut self.mass, perm, &mut scratch.s);
        apply(&mut self.vol, perm, &mut scratch.s);
        apply(&mut self.vol0, perm, &mut scratch.s);
        apply(&mut self.half_size, perm, &mut scratch.s);
        apply(&mut self.work, perm, &mut scratch.s);
        apply(&mut self.def_grad, perm, &mut scratch.v4);
        apply(&mut self.stress, perm, &mut scratch.v4);
        apply(&mut self.affine, perm, &mut scratch.v4);
        // The states are moved out (a representative volume is not copied).
        let st = &mut scratch.st;
        st.clear();
        st.extend(
            perm.iter()
                .map(|&k| std::mem::take(&mut self.state[k as usize])),
        );
        std::mem::swap(&mut self.state, st);
    }
}

/// Reused buffers of [`Points::permute`].
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PermuteScratch<S> {
    s: Vec<f64>,
    v2: Vec<[f64; 2]>,
    v4: Vec<[f64; 4]>,
    st: Vec<S>,
}

impl<S> Default for PermuteScratch<S> {
    fn default() -> Self {
        PermuteScratch {
            s: Vec::new(),
            v2: Vec::new(),
            v4: Vec::new(),
            st: Vec::new(),
        }
    }
}
