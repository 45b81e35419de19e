// The partially saturated blend of `coupling::psm::collision` on the GPU, as the covered
// cells' term of the lattice kernel (`lbm::gpu::CoveredTerm`). Entry e of the cover carries
// covered_values[3e..3e+3] = (B, u_s,x, u_s,y) in lattice units.
//
// f_i* = (1 − B) C(f)_i + B (f_i + Ω_i^s), Ω_i^s = [f_ī − f_ī^eq(ρ, u)] − [f_i − f_i^eq(ρ, u_s)],
// with u = (Σ f e + F/2)/ρ; returns the momentum B Σ_i Ω_i^s e_i the solid term gave the fluid.
//
// Written as Ω_i^s = (f_ī − f_i) + w_i ρ [3 e_i·(u_s + u) + 4.5 ((e_i·u_s)² − (e_i·u)²)
// − 1.5 (|u_s|² − |u|²)]: the two equilibria's common w_i ρ cancels by hand, so in f32 the
// term loses no more than the populations' own rounding. The CPU blend
// (`coupling::psm::collision::blend`) is the same arrangement.
fn covered_term(e: u32, g: array<real, 9>, post: ptr<function, array<real, 9>>) -> vec2<real> {
    let b = covered_values[3u * e];
    let sx = covered_values[3u * e + 1u];
    let sy = covered_values[3u * e + 2u];
    // (ρ, u) with u = (Σ f e + F/2)/ρ, from the lattice kernel.
    let m = moments(g);
    let rho = m.x;
    let ux = m.y;
    let uy = m.z;
    let du2 = 1.5 * ((sx * sx + sy * sy) - (ux * ux + uy * uy));
    var dp = vec2<real>(0.0, 0.0);
    for (var i = 0u; i < 9u; i++) {
        let cx = real(CX[i]);
        let cy = real(CY[i]);
        let w = select(select(W5, W1, i < 5u), W0, i == 0u);
        let cu = cx * ux + cy * uy;
        let cs = cx * sx + cy * sy;
        let omega = (g[OPP[i]] - g[i]) + w * rho * (3.0 * (cs + cu) + 4.5 * (cs * cs - cu * cu) - du2);
        (*post)[i] = (1.0 - b) * (*post)[i] + b * (g[i] + omega);
        dp += b * omega * vec2<real>(cx, cy);
    }
    return dp;
}
