//! COM during the stance, leg extension extremes and the Appendix B boxes
//! (spec stance-model §5, §7.1 eq 8, §7.3).
//!
//! # Model
//!
//! COM relative to its touchdown position, stance frame, scale factors β (§5):
//!
//! ```text
//! r_h(τ) = vs·Δt·τ                     + β_h S_h(τ)                               (m)
//! r_p(τ) = vps·Δt·τ                    + β_p S_p(τ)
//! r_v(τ) = −g·t_TD·Δt·τ − ½g·Δt²·τ²    + β_v S_v(τ)        S_a(τ) = (Δt²/m) F2_a(τ)
//! ```
//!
//! Leg extension (eq 8) against the contact point `x_cp = (cp_h, cp_p, −z_TD)`:
//!
//! ```text
//! r(τ) − x_cp = U(τ) + β∘S(τ)
//! U_h = vs·Δt·τ − cp_h,  U_p = vps·Δt·τ − cp_p,  U_v = −g·t_TD·Δt·τ − ½g·Δt²·τ² + z_TD   (m)
//! ext_min = min_k |r(τ_k) − x_cp|,  ext_max = max_k |r(τ_k) − x_cp|       (β = 1)        (m)
//! ```
//!
//! Appendix B boxes (per axis, over the grid points where `S_a(τ_k)` is not ~0):
//!
//! ```text
//! a_a(τ) = −U_a/S_a,   b_a(τ) = 1/|S_a|                                       (–, 1/m)
//! R_max,a = min_τ (a_a + b_a χ_max),   R_min,a = max_τ (a_a − b_a χ_max)      χ_max box
//! S_max,a = max_τ (a_a + b_a χ_min),   S_min,a = min_τ (a_a − b_a χ_min)      χ_min box
//! every bound clipped to [0, β_max]
//! ```
//!
//! A box with `min > max` is empty: a χ_max box that no β satisfies on that axis, or a χ_min
//! box of an axis where `S_a` is ~0 everywhere (that axis then gives no χ_max bound either:
//! its χ_max box is `[0, β_max]`).
//!
//! # Frames and units
//!
//! Stance frame (h, p, v), origin at the COM at touchdown; m, s, N; β dimensionless.
//!
//! # References
//!
//! Pollard & Behmaram-Mosavat 2000, eq 8 and Appendix B (eq 23–32).

use super::grids::SampledGrids;
use super::{PrecomputeOptions, StanceContext};
use crate::force_model::{ForceModel, GRAVITY};

/// The β-independent part `U(τ)` of `r(τ) − x_cp`, m.
pub fn unscaled_offset(model: &ForceModel, ctx: &StanceContext, tau: f64) -> [f64; 3] {
    let dt = model.dt_s;
    [
        ctx.vs * dt * tau - ctx.cp[0],
        ctx.vps * dt * tau - ctx.cp[1],
        -GRAVITY * ctx.t_td * dt * tau - 0.5 * GRAVITY * dt * dt * tau * tau + ctx.z_td,
    ]
}

/// COM relative to its touchdown position at `τ`, stance frame, scale factors `β` (§5), m.
///
/// ```text
/// r(τ) = U(τ) + x_cp + β∘S(τ)
/// ```
pub fn com_offset(model: &ForceModel, ctx: &StanceContext, beta: [f64; 3], tau: f64) -> [f64; 3] {
    let dt = model.dt_s;
    let free = [
        ctx.vs * dt * tau,
        ctx.vps * dt * tau,
        -GRAVITY * ctx.t_td * dt * tau - 0.5 * GRAVITY * dt * dt * tau * tau,
    ];
    let mut r = [0.0; 3];
    for (axis, (ra, (fa, ba))) in r.iter_mut().zip(free.iter().zip(beta)).enumerate() {
        *ra = fa + ba * model.s(axis, tau);
    }
    r
}

/// `min_k |r(τ_k) − x_cp|` and `max_k |r(τ_k) − x_cp|` with β = 1 from the grids, m.
///
/// An empty grid gives `(0, 0)`.
pub fn extension_extremes(
    model: &ForceModel,
    ctx: &StanceContext,
    grids: &SampledGrids,
) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let [sh, sp, sv] = &grids.s;
    for (&t, ((&h, &p), &v)) in grids.tau.iter().zip(sh.iter().zip(sp).zip(sv)) {
        let u = unscaled_offset(model, ctx, t);
        let d2 = (u[0] + h).powi(2) + (u[1] + p).powi(2) + (u[2] + v).powi(2);
        lo = lo.min(d2);
        hi = hi.max(d2);
    }
    if grids.is_empty() {
        return (0.0, 0.0);
    }
    (lo.sqrt(), hi.sqrt())
}

/// The Appendix B boxes of one context, (h, p, v), clipped to `[0, β_max]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipsoidBoxes {
    /// χ_max box lower corner `R_min`.
    pub r_min: [f64; 3],
    /// χ_max box upper corner `R_max`.
    pub r_max: [f64; 3],
    /// χ_min box lower corner `S_min`.
    pub s_min: [f64; 3],
    /// χ_min box upper corner `S_max`.
    pub s_max: [f64; 3],
}

/// The Appendix B boxes at context `ctx` for the limits `chi = [χ_min, χ_max]` (m).
///
/// Grid points with `|S_a(τ_k)| ≤ opts.s_floor_rel · max_k |S_a(τ_k)|` (τ = 0 among them)
/// or a non-finite ratio are skipped on that axis; bounds are clipped to `[0, opts.beta_max]`.
pub fn ellipsoid_boxes(
    model: &ForceModel,
    ctx: &StanceContext,
    grids: &SampledGrids,
    chi: [f64; 2],
    opts: &PrecomputeOptions,
) -> EllipsoidBoxes {
    let [chi_min, chi_max] = chi;
    let mut r_min = [f64::NEG_INFINITY; 3];
    let mut r_max = [f64::INFINITY; 3];
    let mut s_min = [f64::INFINITY; 3];
    let mut s_max = [f64::NEG_INFINITY; 3];
    let mut floor = [0.0f64; 3];
    for (fl, s) in floor.iter_mut().zip(&grids.s) {
        *fl = opts.s_floor_rel * s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    }
    for (k, &t) in grids.tau.iter().enumerate() {
        let u = unscaled_offset(model, ctx, t);
        for axis in 0..3 {
            let Some(&s) = grids.s[axis].get(k) else {
                continue;
            };
            let mag = s.abs();
            if mag.is_nan() || mag <= floor[axis] {
                continue;
            }
            let inv = 1.0 / s;
            let (a, b) = (-u[axis] * inv, inv.abs());
            if !(a.is_finite() && b.is_finite()) {
                continue;
            }
            r_max[axis] = r_max[axis].min(a + b * chi_max);
            r_min[axis] = r_min[axis].max(a - b * chi_max);
            s_max[axis] = s_max[axis].max(a + b * chi_min);
            s_min[axis] = s_min[axis].min(a - b * chi_min);
        }
    }
    let clip = |v: [f64; 3]| v.map(|x| clip_beta(x, opts.beta_max));
    EllipsoidBoxes {
        r_min: clip(r_min),
        r_max: clip(r_max),
        s_min: clip(s_min),
        s_max: clip(s_max),
    }
}

/// `x` clipped to `[0, β_max]` without panicking on a bad `β_max` (NaN stays NaN).
fn clip_beta(x: f64, beta_max: f64) -> f64 {
    let hi = if beta_max >= 0.0 { beta_max } else { 0.0 };
    if x < 0.0 {
        0.0
    } else if x > hi {
        hi
    } else {
        x
    }
}
