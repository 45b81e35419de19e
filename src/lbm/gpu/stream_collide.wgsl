// Fused stream–collide of the D2Q9 lattice, AA pattern in place (one thread per cell).
//
// The same step as the CPU's `lbm::lattice` (whose module docs give the pattern) on the same
// storage: f[i·STRIDE + y·NX + x], one array per direction. Even step: a node reads its own slots,
// f_i = A[x][i], collides and writes A[x][ī] = f_i*. Odd step: it reads f_i = A[x − e_i][ī] and
// writes A[x + e_i][i] = f_i*; across a half-way bounce-back link it reads its own slot plus the
// moving-wall term and writes back into its own opposite slot (seed eq. 5.24, Ladd 1994).
// On a Zou–He node the populations arriving from outside the domain are unknown on either
// parity: the closure of `lbm::boundary` sets them before the collision, and what leaves
// through an open link is dropped.
//
// `real` is f32, or f64 where the adapter has SHADER_F64 (the host rewrites the alias).
// Collision operators are those of `lbm::collision` term for term (see its docs for the
// equations): BGK or MRT (Lallemand & Luo 2000), each with Smagorinsky LES and Guo forcing.

alias real = f32;

// Cells along x and y, direction-array stride: fixed per lattice.
override NX: u32;
override NY: u32;
override STRIDE: u32;
// Parity of the step this pipeline runs (`after_step`: of the step just run), and the
// collision variant.
override EVEN: bool;
override MRT: bool;
override LES: bool;
override FORCE: bool;

// `kind[c]`: a cell whose 8 neighbours are plain fluid, a solid cell, or an index into `links`.
const BULK: u32 = 0xffffffffu;
const SOLID: u32 = 0xfffffffeu;
// A link code with this bit set is a bounce-back link; the low bits number its wall velocity.
const BOUNCE: u32 = 0x80000000u;
// The link code of an open link (out through a Zou–He edge).
const OPEN: u32 = 0xffffffffu;

@group(0) @binding(0) var<storage, read_write> f: array<real>;
@group(0) @binding(1) var<storage, read> kind: array<u32>;
// Per special node, 9 codes: what lies at x + e_i (a fluid cell index or BOUNCE | wall).
@group(0) @binding(2) var<storage, read> links: array<u32>;
// Per wall velocity, 9 values 6 w_i (e_i·u_w) (entry 0: a wall at rest).
@group(0) @binding(3) var<storage, read> corr: array<real>;
// ω = 1/τ, τ, 18 C², F_x, F_y, s_e, s_ε, s_q.
@group(0) @binding(4) var<storage, read> coef: array<real>;
// Obstacle links (`after_step`): per link the fluid node x_f, the direction e_i into the
// solid and the node behind, x_f − e_i, where the link is interpolated (else NONE) …
@group(0) @binding(5) var<storage, read> links_solid: array<u32>;
// … its wall distance q …
@group(0) @binding(6) var<storage, read> link_q: array<real>;
// … and the momentum it exchanged in the last step, f_i*(x_f) + f_ī(x_f).
@group(0) @binding(7) var<storage, read_write> exchanged: array<real>;
// Per special node, 5 values: 0 (not a Zou–He node), 1 (velocity) or 2 (pressure), the
// inward normal n_x, n_y, and the prescribed u_x, u_y or ρ.
@group(0) @binding(8) var<storage, read> zou_he_nodes: array<real>;
// Number of obstacle links.
override LINKS: u32;
const NONE: u32 = 0xffffffffu;
// Cells a coupling's solids cover (`lbm::covered`), when COVERED: per cell its entry in the
// cover (else NONE) …
override COVERED: bool;
@group(0) @binding(9) var<storage, read> covered_index: array<u32>;
// … per entry the values of the coupling's term (`covered_term`, source appended by the host) …
@group(0) @binding(10) var<storage, read> covered_values: array<real>;
// … and the momentum the term gave the fluid, summed over the steps since the cover was set.
@group(0) @binding(11) var<storage, read_write> covered_exchange: array<real>;

const CX = array<i32, 9>(0, 1, 0, -1, 0, 1, -1, -1, 1);
const CY = array<i32, 9>(0, 0, 1, 0, -1, 1, 1, -1, -1);
const OPP = array<u32, 9>(0u, 3u, 4u, 1u, 2u, 7u, 8u, 5u, 6u);
const W0: real = 4.0 / 9.0;
const W1: real = 1.0 / 9.0;
const W5: real = 1.0 / 36.0;

// The cell at (x + dx, y + dy), wrapped (bulk cells have all 8 neighbours in the fluid).
fn shifted(x: u32, y: u32, dx: i32, dy: i32) -> u32 {
    let tx = u32((i32(x) + dx + i32(NX)) % i32(NX));
    let ty = u32((i32(y) + dy + i32(NY)) % i32(NY));
    return ty * NX + tx;
}

// 1/τ* with τ* = ½ [τ + √(τ² + 18 C² |Π^neq| / ρ)] under LES, else ω.
fn rate(rho: real, pxx: real, pyy: real, pxy: real) -> real {
    if (!LES) {
        return coef[0];
    }
    let pi = sqrt(pxx * pxx + pyy * pyy + 2.0 * pxy * pxy);
    let tau_t = coef[1];
    let tau = 0.5 * (tau_t + sqrt(tau_t * tau_t + coef[2] * pi / rho));
    return 1.0 / tau;
}

// f₀* = ρ − Σ_{i≥1} f_i*: mass conserved in floating point too.
fn rest_from_mass(rho: real, f: array<real, 9>) -> real {
    return rho - (((f[1] + f[2]) + (f[3] + f[4])) + ((f[5] + f[6]) + (f[7] + f[8])));
}

fn bgk(g: array<real, 9>) -> array<real, 9> {
    var o: array<real, 9>;
    let fx = select(0.0, coef[3], FORCE);
    let fy = select(0.0, coef[4], FORCE);
    let rho = g[0] + g[1] + g[2] + g[3] + g[4] + g[5] + g[6] + g[7] + g[8];
    let jx = g[1] - g[3] + g[5] - g[6] - g[7] + g[8];
    let jy = g[2] - g[4] + g[5] + g[6] - g[7] - g[8];
    let inv = 1.0 / rho;
    let ux = (jx + 0.5 * fx) * inv;
    let uy = (jy + 0.5 * fy) * inv;
    var omega = coef[0];
    if (LES) {
        let third: real = 1.0 / 3.0;
        let pxx = g[1] + g[3] + g[5] + g[6] + g[7] + g[8] - rho * (third + ux * ux);
        let pyy = g[2] + g[4] + g[5] + g[6] + g[7] + g[8] - rho * (third + uy * uy);
        let pxy = g[5] - g[6] + g[7] - g[8] - rho * ux * uy;
        omega = rate(rho, pxx, pyy, pxy);
    }
    let keep = 1.0 - omega;
    let base = 1.0 - 1.5 * (ux * ux + uy * uy);
    let r0 = omega * W0 * rho;
    let r1 = omega * W1 * rho;
    let r5 = omega * W5 * rho;
    let t1 = 3.0 * r1;
    let t5 = 3.0 * r5;
    o[0] = keep * g[0] + r0 * base;
    // f_i^eq = w_i ρ (1 − 1.5|u|² + 4.5 (e_i·u)²) ± 3 w_i ρ e_i·u for the pair (i, ī).
    let cu = array<real, 4>(ux, uy, ux + uy, uy - ux);
    let r = array<real, 4>(r1, r1, r5, r5);
    let t = array<real, 4>(t1, t1, t5, t5);
    let first = array<u32, 4>(1u, 2u, 5u, 6u);
    for (var p = 0u; p < 4u; p++) {
        let i = first[p];
        let even = r[p] * fma(4.5, cu[p] * cu[p], base);
        let odd = t[p] * cu[p];
        o[i] = fma(keep, g[i], even + odd);
        o[OPP[i]] = fma(keep, g[OPP[i]], even - odd);
    }
    if (FORCE) {
        // Guo: (1 − ω/2) w_i [3(e_i − u)·F + 9(e_i·u)(e_i·F)].
        let fk = 1.0 - 0.5 * omega;
        let uf = ux * fx + uy * fy;
        for (var i = 0u; i < 9u; i++) {
            let ex = real(CX[i]);
            let ey = real(CY[i]);
            let w = select(select(W5, W1, i < 5u), W0, i == 0u);
            let ci = ex * ux + ey * uy;
            let cf = ex * fx + ey * fy;
            o[i] = o[i] + fk * w * (3.0 * (cf - uf) + 9.0 * ci * cf);
        }
    }
    o[0] = rest_from_mass(rho, o);
    return o;
}

fn mrt(g: array<real, 9>) -> array<real, 9> {
    let fx = select(0.0, coef[3], FORCE);
    let fy = select(0.0, coef[4], FORCE);
    let s_e = coef[5];
    let s_eps = coef[6];
    let s_q = coef[7];
    let axes = g[1] + g[2] + g[3] + g[4];
    let diag = g[5] + g[6] + g[7] + g[8];
    let rho = g[0] + axes + diag;
    var e = -4.0 * g[0] - axes + 2.0 * diag;
    var eps = 4.0 * g[0] - 2.0 * axes + diag;
    var jx = g[1] - g[3] + g[5] - g[6] - g[7] + g[8];
    var qx = -2.0 * g[1] + 2.0 * g[3] + g[5] - g[6] - g[7] + g[8];
    var jy = g[2] - g[4] + g[5] + g[6] - g[7] - g[8];
    var qy = -2.0 * g[2] + 2.0 * g[4] + g[5] + g[6] - g[7] - g[8];
    var pxx = g[1] - g[2] + g[3] - g[4];
    var pxy = g[5] - g[6] + g[7] - g[8];
    let inv = 1.0 / rho;
    let ux = (jx + 0.5 * fx) * inv;
    let uy = (jy + 0.5 * fy) * inv;
    let u2 = ux * ux + uy * uy;
    // Non-equilibrium parts of the moments.
    let e_n = e - rho * (3.0 * u2 - 2.0);
    let eps_n = eps - rho * (1.0 - 3.0 * u2);
    let qx_n = qx + rho * ux;
    let qy_n = qy + rho * uy;
    let pxx_n = pxx - rho * (ux * ux - uy * uy);
    let pxy_n = pxy - rho * ux * uy;
    var s_nu = coef[0];
    if (LES) {
        let a = e_n * (1.0 / 6.0);
        let b = 0.5 * pxx_n;
        s_nu = rate(rho, a + b, a - b, pxy_n);
    }
    e = e - s_e * e_n;
    eps = eps - s_eps * eps_n;
    qx = qx - s_q * qx_n;
    qy = qy - s_q * qy_n;
    pxx = pxx - s_nu * pxx_n;
    pxy = pxy - s_nu * pxy_n;
    if (FORCE) {
        let uf = ux * fx + uy * fy;
        e = e + (1.0 - 0.5 * s_e) * 6.0 * uf;
        eps = eps - (1.0 - 0.5 * s_eps) * 6.0 * uf;
        jx = jx + fx;
        jy = jy + fy;
        qx = qx - (1.0 - 0.5 * s_q) * fx;
        qy = qy - (1.0 - 0.5 * s_q) * fy;
        pxx = pxx + (1.0 - 0.5 * s_nu) * 2.0 * (ux * fx - uy * fy);
        pxy = pxy + (1.0 - 0.5 * s_nu) * (ux * fy + uy * fx);
    }
    // f = M⁻¹ m = Mᵀ diag(1/9, 1/36, 1/36, 1/6, 1/12, 1/6, 1/12, 1/4, 1/4) m.
    let a = rho * (1.0 / 9.0);
    let b = e * (1.0 / 36.0);
    let c = eps * (1.0 / 36.0);
    let d = jx * (1.0 / 6.0);
    let gq = qx * (1.0 / 12.0);
    let h = jy * (1.0 / 6.0);
    let k = qy * (1.0 / 12.0);
    let p = pxx * 0.25;
    let s = pxy * 0.25;
    let ax = a - b - 2.0 * c;
    let dg = a + 2.0 * b + c;
    var o: array<real, 9>;
    o[1] = ax + d - 2.0 * gq + p;
    o[2] = ax + h - 2.0 * k - p;
    o[3] = ax - d + 2.0 * gq + p;
    o[4] = ax - h + 2.0 * k - p;
    o[5] = dg + d + gq + h + k + s;
    o[6] = dg - d - gq + h + k - s;
    o[7] = dg - d - gq - h - k + s;
    o[8] = dg + d + gq - h - k - s;
    o[0] = rest_from_mass(rho, o);
    return o;
}

// The Zou–He closure of `lbm::boundary::zou_he` on special node `s` (see its docs): the
// unknowns (bit i of `unknown`) from mass and normal momentum, ρ (1 − u·n) = Σ_known f (1 − e·n),
// by bounce-back of their non-equilibrium part, f_i = f_ī + 6 w_i e_i·j, then corrected by
// δ_i = λ + μ (e_i·t) to restore mass and tangential momentum. With Guo forcing the imposed
// momentum is j = ρu − F/2.
fn zou_he(g_in: array<real, 9>, unknown: u32, s: u32) -> array<real, 9> {
    var g = g_in;
    let nx = zou_he_nodes[5u * s + 1u];
    let ny = zou_he_nodes[5u * s + 2u];
    let tx = -ny;
    let ty = nx;
    let hx = select(0.0, 0.5 * coef[3], FORCE);
    let hy = select(0.0, 0.5 * coef[4], FORCE);
    var known: real = 0.0;
    for (var i = 0u; i < 9u; i++) {
        if ((unknown & (1u << i)) == 0u) {
            known += g[i] * (1.0 - (real(CX[i]) * nx + real(CY[i]) * ny));
        }
    }
    var rho: real;
    var jx: real;
    var jy: real;
    if (zou_he_nodes[5u * s] == 1.0) {
        let ux = zou_he_nodes[5u * s + 3u];
        let uy = zou_he_nodes[5u * s + 4u];
        rho = (known - (hx * nx + hy * ny)) / (1.0 - (ux * nx + uy * ny));
        jx = rho * ux - hx;
        jy = rho * uy - hy;
    } else {
        rho = zou_he_nodes[5u * s + 3u];
        let jn = rho - known;
        let jt = -(hx * tx + hy * ty);
        jx = jn * nx + jt * tx;
        jy = jn * ny + jt * ty;
    }
    var k: real = 0.0;
    var st: real = 0.0;
    var stt: real = 0.0;
    for (var i = 0u; i < 9u; i++) {
        if ((unknown & (1u << i)) != 0u) {
            let w = select(W5, W1, i < 5u);
            g[i] = g[OPP[i]] + 6.0 * w * (real(CX[i]) * jx + real(CY[i]) * jy);
            let ct = real(CX[i]) * tx + real(CY[i]) * ty;
            k += 1.0;
            st += ct;
            stt += ct * ct;
        }
    }
    var mass: real = 0.0;
    var tangential: real = 0.0;
    for (var i = 0u; i < 9u; i++) {
        mass += g[i];
        tangential += g[i] * (real(CX[i]) * tx + real(CY[i]) * ty);
    }
    let r_m = rho - mass;
    let r_t = (jx * tx + jy * ty) - tangential;
    let det = k * stt - st * st;
    var lambda = r_m / max(k, 1.0);
    var mu: real = 0.0;
    if (abs(det) > 1e-12) {
        lambda = (r_m * stt - r_t * st) / det;
        mu = (k * r_t - st * r_m) / det;
    }
    for (var i = 0u; i < 9u; i++) {
        if ((unknown & (1u << i)) != 0u) {
            g[i] = g[i] + lambda + mu * (real(CX[i]) * tx + real(CY[i]) * ty);
        }
    }
    return g;
}

// The pre-collision populations of fluid cell (x, y) = c with kind k for a step of parity
// EVEN (`Lattice::populations` on the CPU).
fn gather(x: u32, y: u32, c: u32, k: u32) -> array<real, 9> {
    var g: array<real, 9>;
    if (EVEN) {
        for (var i = 0u; i < 9u; i++) {
            g[i] = f[i * STRIDE + c];
        }
    } else if (k == BULK) {
        for (var j = 0u; j < 9u; j++) {
            g[j] = f[OPP[j] * STRIDE + shifted(x, y, -CX[j], -CY[j])];
        }
    } else {
        // The population arriving along e_j comes across link ī.
        for (var j = 0u; j < 9u; j++) {
            let l = links[k * 9u + OPP[j]];
            if (l < BOUNCE) {
                g[j] = f[OPP[j] * STRIDE + l];
            } else if (l != OPEN) {
                g[j] = f[j * STRIDE + c] + corr[(l & ~BOUNCE) * 9u + j];
            }
        }
    }
    if (k != BULK && zou_he_nodes[5u * k] != 0.0) {
        var unknown = 0u;
        for (var j = 0u; j < 9u; j++) {
            if (links[k * 9u + OPP[j]] == OPEN) {
                unknown |= 1u << j;
            }
        }
        g = zou_he(g, unknown, k);
    }
    return g;
}

@compute @workgroup_size(64, 1, 1)
fn stream_collide(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = id.x;
    let y = id.y;
    if (x >= NX || y >= NY) {
        return;
    }
    let c = y * NX + x;
    let k = kind[c];
    if (k == SOLID) {
        return;
    }
    let g = gather(x, y, c, k);
    var o: array<real, 9>;
    if (MRT) {
        o = mrt(g);
    } else {
        o = bgk(g);
    }
    if (COVERED) {
        let e = covered_index[c];
        if (e != NONE) {
            let dp = covered_term(e, g, &o);
            covered_exchange[2u * e] += dp.x;
            covered_exchange[2u * e + 1u] += dp.y;
        }
    }
    if (EVEN) {
        for (var i = 0u; i < 9u; i++) {
            f[OPP[i] * STRIDE + c] = o[i];
        }
    } else if (k == BULK) {
        for (var i = 0u; i < 9u; i++) {
            f[i * STRIDE + shifted(x, y, CX[i], CY[i])] = o[i];
        }
    } else {
        for (var i = 0u; i < 9u; i++) {
            let l = links[k * 9u + i];
            if (l < BOUNCE) {
                f[i * STRIDE + l] = o[i];
            } else if (l != OPEN) {
                f[OPP[i] * STRIDE + c] = o[i] - corr[(l & ~BOUNCE) * 9u + i];
            }
        }
    }
}

// After a step: Yu's interpolated bounce-back on interpolated obstacle links (Yu et al. 2003,
// as `lbm::obstacle`), f_ī(x_f) = [(1 − q) f_ī^in(x_b) + q f_i*(x_f) + q f_ī*(x_f)]/(1 + q)
// with x_b = x_f − e_i, and the momentum each link exchanged, for the loads. No two links
// write a slot another link reads (one thread per link).
@compute @workgroup_size(64, 1, 1)
fn after_step(@builtin(global_invocation_id) id: vec3<u32>) {
    let l = id.x;
    if (l >= LINKS) {
        return;
    }
    let c = links_solid[3u * l];
    let i = links_solid[3u * l + 1u];
    let k = links_solid[3u * l + 2u];
    let o = OPP[i];
    // f_i*(x_f): after either parity it sits in A[x_f][ī].
    let out = f[o * STRIDE + c];
    var back = out;
    if (k != NONE) {
        var in_behind: real;
        var out_rev: real;
        if (EVEN) {
            in_behind = f[o * STRIDE + k];
            out_rev = f[i * STRIDE + c];
        } else {
            in_behind = f[i * STRIDE + c];
            out_rev = f[o * STRIDE + k];
        }
        let q = link_q[l];
        back = ((1.0 - q) * in_behind + q * out + q * out_rev) / (1.0 + q);
        f[o * STRIDE + c] = back;
    }
    exchanged[l] = out + back;
}

// Observation (`GpuFluid::observe`): the fields as the next step, of parity EVEN, will see
// them, reduced without reading the populations back.
//
// Per row y, observed[4y..4y+4] = (Σρ, Σ ½ρ|u|², max |u|², min ρ) over its fluid cells; then per
// probe p, observed[4 NY + 3p..] = (ρ, u_x, u_y) of cell probe_cells[1 + p] (probe_cells[0]
// is the number of probes). u = (Σ f e + F/2)/ρ, as `Lbm::cell`.
@group(1) @binding(0) var<storage, read_write> observed: array<real>;
@group(1) @binding(1) var<storage, read> probe_cells: array<u32>;

var<workgroup> partial: array<vec4<real>, 64>;

// (ρ, u_x, u_y) of the populations g.
fn moments(g: array<real, 9>) -> vec3<real> {
    let rho = g[0] + g[1] + g[2] + g[3] + g[4] + g[5] + g[6] + g[7] + g[8];
    let jx = g[1] - g[3] + g[5] - g[6] - g[7] + g[8];
    let jy = g[2] - g[4] + g[5] + g[6] - g[7] - g[8];
    let fx = select(0.0, coef[3], FORCE);
    let fy = select(0.0, coef[4], FORCE);
    return vec3<real>(rho, (jx + 0.5 * fx) / rho, (jy + 0.5 * fy) / rho);
}

// One workgroup per row; its 64 threads stride along the row, then reduce in a tree.
@compute @workgroup_size(64, 1, 1)
fn observe(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let y = wid.y;
    var acc = vec4<real>(0.0, 0.0, 0.0, 1.0e30);
    for (var x = lid.x; x < NX; x += 64u) {
        let c = y * NX + x;
        let k = kind[c];
        if (k != SOLID) {
            let m = moments(gather(x, y, c, k));
            let u2 = m.y * m.y + m.z * m.z;
            acc = vec4<real>(acc.x + m.x, acc.y + 0.5 * m.x * u2, max(acc.z, u2), min(acc.w, m.x));
        }
    }
    partial[lid.x] = acc;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s >>= 1u) {
        if (lid.x < s) {
            let a = partial[lid.x];
            let b = partial[lid.x + s];
            partial[lid.x] = vec4<real>(a.x + b.x, a.y + b.y, max(a.z, b.z), min(a.w, b.w));
        }
        workgroupBarrier();
    }
    if (lid.x == 0u) {
        let r = partial[0];
        observed[4u * y] = r.x;
        observed[4u * y + 1u] = r.y;
        observed[4u * y + 2u] = r.z;
        observed[4u * y + 3u] = r.w;
    }
}

@compute @workgroup_size(64, 1, 1)
fn probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let p = id.x;
    if (p >= probe_cells[0]) {
        return;
    }
    let c = probe_cells[1u + p];
    let k = kind[c];
    // A solid cell reads as fluid at rest, as `Macroscopic` has it.
    var m = vec3<real>(1.0, 0.0, 0.0);
    if (k != SOLID) {
        m = moments(gather(c % NX, c / NX, c, k));
    }
    let o = 4u * NY + 3u * p;
    observed[o] = m.x;
    observed[o + 1u] = m.y;
    observed[o + 2u] = m.z;
}
