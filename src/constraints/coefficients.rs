//! Force and friction coefficients of the fast filters, and the stance's force extremes
//! (spec stance-model §7.1–7.2, eq 9 and eq 11; §4.3 unilateral test).
//!
//! # Model
//!
//! All maxima and minima run over the grid `τ_k` of §4.3:
//!
//! ```text
//! A^F_a  = max_k f_a(τ_k)²                                   a ∈ {h, p, v}        (N²)
//! T_act  = {τ_k : f_v(τ_k) ≥ λ_act · max_k f_v(τ_k)},  λ_act = 0.05
//! A^μ_h  = max_{T_act} (f_h/f_v)²,   A^μ_p = max_{T_act} (f_p/f_v)²                 (–)
//! μ_req  = max_{T_act} √(f_h² + f_p²) / f_v                                         (–)
//! F_peak = max_k √(f_h² + f_p² + f_v²)                                              (N)
//! unilateral_ok ⇔ f_v(τ_k) ≥ −0.05 · max_k f_v(τ_k) for every k
//! ```
//!
//! The fast filters built from them are conservative, because a max of sums is at most the
//! sum of maxes:
//!
//! ```text
//! (eq 10)  Σ_a A^F_a β_a² ≤ F_max²              ⇒  max_k Σ_a β_a² f_a(τ_k)² ≤ F_max²
//! (eq 12)  Σ_{a=h,p} A^μ_a (β_a/β_v)² ≤ μ²      ⇒  β_h² f_h² + β_p² f_p² ≤ μ² β_v² f_v² on T_act
//! ```
//!
//! When `max_k f_v ≤ 0` the stance carries no load: `T_act` has no point with `f_v > 0`, and
//! `A^μ` and `μ_req` are `+∞` (no finite friction coefficient suffices).
//!
//! # Frames and units
//!
//! Stance frame (h, p, v); forces in N.
//!
//! # References
//!
//! Pollard & Behmaram-Mosavat 2000, eq 9–12; spec stance-model §7.1 (active set).

use super::grids::SampledGrids;
use super::{ACTIVE_FRACTION, ROBUST_ACTIVE_FRACTION};
use crate::force_model::UNILATERAL_FRACTION;

/// The β-independent force quantities of one stance (eq 9, eq 11, §4.3, §7.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceCoefficients {
    /// `A^F_a = max_k f_a²`, (h, p, v), N².
    pub a_f: [f64; 3],
    /// `A^μ_a = max over T_act of (f_a/f_v)²`, (h, p), dimensionless.
    pub a_mu: [f64; 2],
    /// `min_k f_v(τ_k)`, N.
    pub min_f_v: f64,
    /// `max_k f_v(τ_k)`, N.
    pub max_f_v: f64,
    /// The unilateral test of §4.3.
    pub unilateral_ok: bool,
    /// `max_k |f(τ_k)|`, N.
    pub f_peak: f64,
    /// `max over T_act of |f_t|/f_v`, dimensionless.
    pub mu_req: f64,
    /// The same over `f_v ≥ ROBUST_ACTIVE_FRACTION · max f_v`, dimensionless.
    pub mu_req_robust: f64,
}

/// `max(a, b)`, NaN when either is NaN (`f64::max` drops a NaN, which would turn a model
/// that evaluates to NaN into `A^F = 0`, `F_peak = 0`: a stance that looks harmless).
fn max_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Eq 9 and eq 11 coefficients, `F_peak`, `μ_req` and the unilateral test from the grids.
///
/// An empty grid gives zeros, `unilateral_ok = true` and `μ_req = A^μ = +∞`.
pub fn force_coefficients(grids: &SampledGrids) -> ForceCoefficients {
    let [fh, fp, fv] = &grids.f;
    let mut a_f = [0.0f64; 3];
    let mut f_peak = 0.0f64;
    let mut min_f_v = f64::INFINITY;
    let mut max_f_v = f64::NEG_INFINITY;
    for ((&h, &p), &v) in fh.iter().zip(fp).zip(fv) {
        let (h2, p2, v2) = (h * h, p * p, v * v);
        a_f[0] = max_nan(a_f[0], h2);
        a_f[1] = max_nan(a_f[1], p2);
        a_f[2] = max_nan(a_f[2], v2);
        f_peak = max_nan(f_peak, h2 + p2 + v2);
        min_f_v = -max_nan(-min_f_v, -v);
        max_f_v = max_nan(max_f_v, v);
    }
    if fv.is_empty() {
        (min_f_v, max_f_v) = (0.0, 0.0);
    }

    let unilateral_floor = -UNILATERAL_FRACTION * max_f_v;
    let unilateral_ok = fv.iter().all(|&v| v >= unilateral_floor);

    let (a_mu, mu_req) = friction_demand(grids, max_f_v, ACTIVE_FRACTION);
    let (_, mu_req_robust) = friction_demand(grids, max_f_v, ROBUST_ACTIVE_FRACTION);

    ForceCoefficients {
        a_f,
        a_mu,
        min_f_v,
        max_f_v,
        unilateral_ok,
        f_peak: f_peak.sqrt(),
        mu_req,
        mu_req_robust,
    }
}

/// `(A^μ, μ_req)` on the active set `f_v ≥ λ · max f_v` (eq 11, §7.1):
/// `A^μ_a = max (f_a/f_v)²` (h, p) and `μ_req = max √(f_h² + f_p²)/f_v`; `+∞` for both when
/// `max f_v ≤ 0`. `λ` is the active fraction ([`super::ACTIVE_FRACTION`] for the stored
/// columns; the queries' `--active-set`).
pub fn friction_demand(grids: &SampledGrids, max_f_v: f64, lambda: f64) -> ([f64; 2], f64) {
    if max_f_v.is_nan() || max_f_v <= 0.0 {
        return ([f64::INFINITY; 2], f64::INFINITY);
    }
    let [fh, fp, fv] = &grids.f;
    let threshold = lambda * max_f_v;
    let (mut rh, mut rp, mut rt) = (0.0f64, 0.0f64, 0.0f64);
    for ((&h, &p), &v) in fh.iter().zip(fp).zip(fv) {
        if v >= threshold {
            let (qh, qp) = ((h / v) * (h / v), (p / v) * (p / v));
            rh = rh.max(qh);
            rp = rp.max(qp);
            rt = rt.max((h * h + p * p).sqrt() / v); // as query::feasibility::exact
        }
    }
    ([rh, rp], rt)
}

/// Eq 10: the conservative force filter, `Σ_a A^F_a β_a² ≤ F_max²`.
pub fn force_filter_accepts(a_f: &[f64; 3], beta: [f64; 3], f_max: f64) -> bool {
    let lhs: f64 = a_f.iter().zip(beta).map(|(a, b)| a * b * b).sum();
    lhs <= f_max * f_max
}

/// Eq 12: the conservative friction filter, `A^μ_h (β_h/β_v)² + A^μ_p (β_p/β_v)² ≤ μ²`.
///
/// Written without the division: `A^μ_h β_h² + A^μ_p β_p² ≤ μ² β_v²`; `β_v = 0` accepts only
/// `β_h = β_p = 0` (no load, no traction). An infinite `A^μ` rejects any β (a `0·∞` term is
/// NaN and the comparison fails).
pub fn friction_filter_accepts(a_mu: &[f64; 2], beta: [f64; 3], mu: f64) -> bool {
    let lhs = a_mu[0] * beta[0] * beta[0] + a_mu[1] * beta[1] * beta[1];
    lhs <= mu * mu * beta[2] * beta[2]
}
