//! Net angular impulse about the COM over the stance, in closed form (spec stance-model
//! §8.2–8.3).
//!
//! # Model
//!
//! With β = 1 and the contact point `x_cp = (cp_h, cp_p, −z_TD)` (§8.1):
//!
//! ```text
//! H   = ∫ (x_cp − r(t)) × F(t) dt = x_cp × I − H_0                            (N·m·s)
//! I   = ∫ F dt = m (J_h, J_p, J_v)                                             (N·s)
//! H_0 = ∫ r(t) × F(t) dt = Δt ∫₀¹ r(τ) × f(τ) dτ                               (N·m·s)
//! ```
//!
//! Each `r_a` is a quadratic plus cosines and each `f_b` a constant plus cosines (§5):
//!
//! ```text
//! r_a(τ) = p0_a + p1_a τ + p2_a τ² + Σ_i ρ_i cos(Ω_i τ + φ_i),   ρ_i = −κ c_i/Ω_i²   (m)
//! p0_a = κ Σ c_i cos φ_i/Ω_i²,   p1_a = ℓ1_a − κ Σ c_i sin φ_i/Ω_i,   p2_a = ℓ2_a + κ d_a/2
//! ℓ1 = (vs Δt, vps Δt, −g t_TD Δt),  ℓ2 = (0, 0, −½ g Δt²),  κ = Δt²/m
//! f_b(τ) = d_b + Σ_l c_l cos(Ω_l τ + φ_l)                                          (N)
//! ```
//!
//! For `Ω = 2πj` (`j` whole or half cycles per stance) every product integrates in closed
//! form, with `C_n(j, φ) = ∫₀¹ τⁿ cos(Ωτ+φ) dτ` ([`basis::harmonic_power_moments`]) and the
//! product-to-sum identity ([`basis::product_integral`]):
//!
//! ```text
//! ∫₀¹ r_a f_b dτ = d_b (p0_a + p1_a/2 + p2_a/3) + Σ_l c_l (p0_a C_0,l + p1_a C_1,l + p2_a C_2,l)
//!                 + d_b Σ_k ρ_k C_0,k + Σ_{k,l} ρ_k c_l ∫₀¹ cos(Ω_kτ+φ_k) cos(Ω_lτ+φ_l) dτ
//! ```
//! For integer `j`: `C_0 = 0`, `C_1 = sin φ/Ω`, `C_2 = sin φ/Ω + 2 cos φ/Ω²`, and the
//! cosine products vanish unless `j_k = j_l` (then `½ cos(φ_k − φ_l)`): the paper's case.
//!
//! `H` is affine in `u = (cp_h, cp_p)`: `H(u) = A u + b` with
//! `A = [[0, I_v], [−I_v, 0], [I_p, −I_h]]` (rows h, p, v) and `b = (0, 0, −z_TD) × I − H_0`.
//! Composite Simpson on τ is the reference the tests check against.
//!
//! # Frames and units
//!
//! Stance frame (h, p, v), origin at the COM at touchdown; N, m, s.
//!
//! # References
//!
//! Spec stance-model §8.2 (affine form), §8.3 ("Computing H_0").

use super::grids::dc_term;
use super::StanceContext;
use crate::force_model::{basis, ForceModel, GRAVITY};
pub(crate) use crate::math::v3::cross;
/// One cosine term of an axis: `Ω`, amplitude (N), `cos φ`, `sin φ`, and its moments
/// `C_0, C_1, C_2` (`C_n = ∫₀¹ τⁿ cos(Ωτ+φ) dτ`).
#[derive(Debug, Clone, Copy)]
struct Term {
    j: f64,
    c: [f64; 3],
    phi: f64,
    omega: f64,
    amp: f64,
    cos_phi: f64,
    sin_phi: f64,
}

/// One axis (0, 1, 2 = h, p, v) as `r_a = p0 + p1 τ + p2 τ² + Σ ρ cos(…)` and
/// `f_a = d + Σ c cos(…)`, plus the polynomial parts `f_a += P_a(τ)` and
/// `r_a += κ F2[P_a](τ)` (power basis, empty for the Fourier model).
#[derive(Debug, Clone)]
struct AxisForm {
    d: f64,
    p: [f64; 3],
    kappa: f64,
    terms: Vec<Term>,
    f_poly: Vec<f64>,
    r_poly: Vec<f64>,
}

impl AxisForm {
    fn new(model: &ForceModel, ctx: &StanceContext, axis: usize) -> Self {
        let dt = model.dt_s;
        let kappa = dt * dt / model.mass_kg;
        let (l1, l2) = match axis {
            0 => (ctx.vs * dt, 0.0),
            1 => (ctx.vps * dt, 0.0),
            _ => (-GRAVITY * ctx.t_td * dt, -0.5 * GRAVITY * dt * dt),
        };
        let d = dc_term(model, axis);
        let terms: Vec<Term> = super::grids::harmonic_terms(model, axis)
            .map(|(j, amp, phi)| {
                let (sin_phi, cos_phi) = phi.sin_cos();
                let m = basis::harmonic_power_moments(j, phi, 2);
                Term {
                    j,
                    c: [m[0], m[1], m[2]],
                    phi,
                    omega: basis::omega_of(j),
                    amp,
                    cos_phi,
                    sin_phi,
                }
            })
            .collect();
        let p0 = kappa
            * terms
                .iter()
                .map(|t| t.amp * t.cos_phi / (t.omega * t.omega))
                .sum::<f64>();
        let p1 = l1
            - kappa
                * terms
                    .iter()
                    .map(|t| t.amp * t.sin_phi / t.omega)
                    .sum::<f64>();
        let p2 = l2 + 0.5 * kappa * d;
        let f_poly = model.axes.get(axis).map_or(Vec::new(), |a| a.poly.clone());
        let r_poly = basis::poly_f2_coeffs(&f_poly)
            .into_iter()
            .map(|c| kappa * c)
            .collect();
        Self {
            d,
            p: [p0, p1, p2],
            kappa,
            terms,
            f_poly,
            r_poly,
        }
    }
}

/// `∫₀¹ r_a(τ) f_b(τ) dτ`, m·N (closed form above).
fn integral_r_f(ra: &AxisForm, fb: &AxisForm) -> f64 {
    let [p0, p1, p2] = ra.p;
    let mut sum = fb.d * (p0 + p1 / 2.0 + p2 / 3.0);
    for l in &fb.terms {
        sum += l.amp * (p0 * l.c[0] + p1 * l.c[1] + p2 * l.c[2]);
    }
    for k in &ra.terms {
        let rho = -ra.kappa * k.amp / (k.omega * k.omega);
        sum += rho * fb.d * k.c[0];
        for l in &fb.terms {
            let both_whole = k.j.fract() == 0.0 && l.j.fract() == 0.0;
            let product = if both_whole {
                // The paper's integer harmonics: orthogonal unless equal.
                if l.j != k.j {
                    continue;
                }
                0.5 * (k.cos_phi * l.cos_phi + k.sin_phi * l.sin_phi)
            } else {
                basis::product_integral(k.j, k.phi, l.j, l.phi)
            };
            sum += rho * l.amp * product;
        }
    }
    if !(ra.f_poly.is_empty() && fb.f_poly.is_empty()) {
        sum += polynomial_cross_terms(ra, fb);
    }
    sum
}

/// The terms of `∫₀¹ r_a f_b dτ` that involve a polynomial part (m·N):
///
/// ```text
/// r_a = Q_a(τ) + R_a(τ) + Σ_k ρ_k cos(Ω_kτ+φ_k),  Q_a = p0 + p1τ + p2τ²,  R_a = κ F2[P_a]
/// f_b = d_b + P_b(τ) + Σ_l c_l cos(Ω_lτ+φ_l)
/// extra = ∫ Q_a P_b + ∫ R_a (d_b + P_b) + Σ_l c_l Σ_n R_a[n] C_n(j_l) + Σ_k ρ_k Σ_n P_b[n] C_n(j_k)
/// ```
/// with `C_n(j) = ∫₀¹ τⁿ cos(2πjτ+φ) dτ` ([`basis::harmonic_power_moments`]).
fn polynomial_cross_terms(ra: &AxisForm, fb: &AxisForm) -> f64 {
    let mut sum = basis::poly_moment(&basis::poly_mul(&ra.p, &fb.f_poly), 0);
    sum += basis::poly_moment(&basis::poly_mul(&ra.r_poly, &fb.f_poly), 0);
    sum += fb.d * basis::poly_moment(&ra.r_poly, 0);
    for l in &fb.terms {
        let c = basis::harmonic_power_moments(l.j, l.phi, ra.r_poly.len());
        sum += l.amp * ra.r_poly.iter().zip(&c).map(|(r, c)| r * c).sum::<f64>();
    }
    for k in &ra.terms {
        let rho = -ra.kappa * k.amp / (k.omega * k.omega);
        let c = basis::harmonic_power_moments(k.j, k.phi, fb.f_poly.len());
        sum += rho * fb.f_poly.iter().zip(&c).map(|(p, c)| p * c).sum::<f64>();
    }
    sum
}

/// `∫₀¹ r_a(τ) f_b(τ) dτ` with β = 1 (m·N), closed form; axes 0, 1, 2 = h, p, v, NaN for
/// an axis above 2.
pub fn moment_integral(model: &ForceModel, ctx: &StanceContext, a: usize, b: usize) -> f64 {
    if a > 2 || b > 2 {
        return f64::NAN;
    }
    integral_r_f(&AxisForm::new(model, ctx, a), &AxisForm::new(model, ctx, b))
}

/// `H_0 = Δt ∫₀¹ r(τ) × f(τ) dτ` with β = 1, closed form, N·m·s.
///
/// For integer harmonics the `cos·cos` terms cancel between `∫ r_a f_b` and `∫ r_b f_a`
/// (the oscillating part of `r_a` is `−κ/Ω²` times that of `f_a`, and only equal
/// frequencies pair); half-range cosines of different frequencies do not cancel, which
/// `integral_r_f` includes.
pub fn h0_closed_form(model: &ForceModel, ctx: &StanceContext) -> [f64; 3] {
    let [h, p, v] = [0, 1, 2].map(|axis| AxisForm::new(model, ctx, axis));
    let dt = model.dt_s;
    [
        dt * (integral_r_f(&p, &v) - integral_r_f(&v, &p)),
        dt * (integral_r_f(&v, &h) - integral_r_f(&h, &v)),
        dt * (integral_r_f(&h, &p) - integral_r_f(&p, &h)),
    ]
}

/// Linear impulse of the applied force with β = 1, `I = m (J_h, J_p, J_v)`, N·s.
pub fn linear_impulse(model: &ForceModel) -> [f64; 3] {
    model.j().map(|j| model.mass_kg * j)
}

/// Angular impulse about the COM over the stance with β = 1 (§8.2): `(H, H_0)`, N·m·s.
///
/// ```text
/// H = x_cp × I − H_0,   x_cp = (cp_h, cp_p, −z_TD),   I = m (J_h, J_p, J_v)
/// ```
///
/// `H_0` is computed in closed form (exact for integer harmonics), no quadrature.
pub fn angular_impulse(model: &ForceModel, ctx: &StanceContext) -> ([f64; 3], [f64; 3]) {
    let h0 = h0_closed_form(model, ctx);
    let x_cp = [ctx.cp[0], ctx.cp[1], -ctx.z_td];
    let moment = cross(x_cp, linear_impulse(model));
    let h = [0, 1, 2].map(|a| moment[a] - h0[a]);
    (h, h0)
}

/// The matrix `A` of `H(u) = A u + b`, `u = (cp_h, cp_p)` (§8.2), rows (h, p, v), N·s.
pub fn contact_point_matrix(impulse: [f64; 3]) -> [[f64; 2]; 3] {
    let [ih, ip, iv] = impulse;
    [[0.0, iv], [-iv, 0.0], [ip, -ih]]
}
