//! Transition points by the slack QP (two-pac §4, eq 5, 6, 13), solved with quadprog
//! (Goldfarb–Idnani).
//!
//! # Model
//!
//! Statics of the phase with **fewer** contacts, kinematics of the one with **more**:
//!
//! ```text
//! eq 6:   min ‖c − c_prev‖² + w s + ε s²
//!         s.t. A_fewer c − s·1 ≤ a_fewer,  K_more c ≤ k_more,  s ≥ 0          (s in m)
//! eq 13:  min ‖c − c_prev‖² + w s + w_e ‖e‖₁ + ε (‖β̃‖² + s² + ‖e⁺‖² + ‖e⁻‖²)
//!         s.t. G V β̃ − D c/(m g) + e⁺ − e⁻ = d/(m g)
//!              β̃ + s·1 ≥ 0,  s ≥ 0,  e^± ≥ 0,  K_more c ≤ k_more           (s in body weights)
//! w = w_e = 1000 (m²),   ε = 1e-9 (regularisation: quadprog needs a positive-definite Hessian)
//! ```
//!
//! The penalties are linear, hence exact: `s = 0` (and `e = 0`) whenever a static point
//! exists. `K_more` is never relaxed: a returned point satisfies it to round-off, and an
//! empty `K_more` is [`TwopacError::KinematicsInfeasible`]. `ε` moves the optimum by
//! `O(ε)` (the minimum-norm `β̃` is picked among equal optima).
//!
//! # Frames and units
//!
//! World frame, Z up; `c` in m; eq 6 `s` in m (unit rows of `A`); eq 13 `s` and `e` in
//! body weights (`m g`, and `m g·m` for moment rows).
//!
//! # References
//!
//! Tonneau et al., 2PAC, eq 5, 6, 13 and Fig. 5; Goldfarb & Idnani 1983; spec two-pac §4
//! (corrected linear penalty, wrench slack), CORRECTIONS Issue 5 item 2.

use super::equilibrium::EqualityForm;
use super::polytope::Polytope;
use super::region::{RegionStatus, StaticRegion};
use super::TwopacError;

/// Weight `w` of the static slack `s`, m² per unit of `s` (§4).
pub const DEFAULT_W: f64 = 1000.0;
/// Weight `w_e` of the wrench slack `‖e‖₁` (§4).
pub const DEFAULT_W_E: f64 = 1000.0;
/// Quadratic regularisation `ε` on every non-COM variable (quadprog needs `Q ≻ 0`).
pub const DEFAULT_REG: f64 = 1e-9;

/// Options of the transition QPs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransitionOptions {
    /// See [`DEFAULT_W`].
    pub w: f64,
    /// See [`DEFAULT_W_E`].
    pub w_e: f64,
    /// See [`DEFAULT_REG`].
    pub reg: f64,
}

impl Default for TransitionOptions {
    fn default() -> Self {
        TransitionOptions {
            w: DEFAULT_W,
            w_e: DEFAULT_W_E,
            reg: DEFAULT_REG,
        }
    }
}

/// Which QP produced a transition point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum QpForm {
    /// Inequality form on the H-representation (eq 6); slack in metres.
    Eq6,
    /// Equality form with wrench slack (eq 13, the default); slack in body weights.
    Eq13,
}

/// A transition point (or projected phase state) with its diagnostics (§4, §8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransitionPoint {
    /// The point, world frame, m.
    pub com: [f64; 3],
    /// Static slack `s ≥ 0`: m for eq 6, body weights for eq 13; `0` when static.
    pub slack: f64,
    /// `‖e‖₁` of eq 13 (0 for eq 6); `> 1e-6` means not statically feasible.
    pub wrench_residual: f64,
    /// The statics' contact points are one point or collinear (§4).
    pub degenerate_contacts: bool,
    /// The form solved.
    pub form: QpForm,
}

impl TransitionPoint {
    /// Statically feasible: `s` and `‖e‖₁` at most `tol`.
    pub fn is_static(&self, tol: f64) -> bool {
        self.slack <= tol && self.wrench_residual <= tol
    }
}

fn qp_error(e: quadprog::Error) -> TwopacError {
    match e {
        quadprog::Error::Infeasible => TwopacError::KinematicsInfeasible {
            transition: None,
            effectors: Vec::new(),
        },
        other => TwopacError::Solver {
            what: format!("transition qp: {other}"),
        },
    }
}

/// Eq 6: the transition point on the H-representation of the fewer-contact phase.
///
/// # Errors
///
/// [`TwopacError::KinematicsInfeasible`] when `kin` is empty;
/// [`TwopacError::EmptyStaticRegion`] when the region is empty (use [`transition_eq13`]).
pub fn transition_eq6(
    statics: &StaticRegion,
    degenerate_contacts: bool,
    kin: &Polytope,
    c_prev: [f64; 3],
    opts: &TransitionOptions,
) -> Result<TransitionPoint, TwopacError> {
    if statics.status == RegionStatus::Empty {
        return Err(TwopacError::EmptyStaticRegion);
    }
    let a = &statics.polytope;
    let nq = a.len() + kin.len() + 1;
    // Factorised Hessian: L⁻¹ of diag(2, 2, 2, ε).
    let mut linv = [0.0; 16];
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    linv[0] = s2;
    linv[5] = s2;
    linv[10] = s2;
    linv[15] = 1.0 / opts.reg.sqrt();
    let cvec = [-2.0 * c_prev[0], -2.0 * c_prev[1], -2.0 * c_prev[2], opts.w];
    let mut amat = Vec::with_capacity(4 * nq);
    let mut bvec = Vec::with_capacity(nq);
    for (r, &b) in a.a.iter().zip(&a.b) {
        amat.extend_from_slice(&[r[0], r[1], r[2], -1.0]);
        bvec.push(b);
    }
    for (r, &b) in kin.a.iter().zip(&kin.b) {
        amat.extend_from_slice(&[r[0], r[1], r[2], 0.0]);
        bvec.push(b);
    }
    amat.extend_from_slice(&[0.0, 0.0, 0.0, -1.0]);
    bvec.push(0.0);
    let sol = quadprog::solve_qp(&mut linv, &cvec, &amat, &bvec, 0, true).map_err(qp_error)?;
    Ok(TransitionPoint {
        com: [sol.sol[0], sol.sol[1], sol.sol[2]],
        slack: sol.sol[3].max(0.0),
        wrench_residual: 0.0,
        degenerate_contacts,
        form: QpForm::Eq6,
    })
}

/// Eq 13 with the wrench slack: the transition point on the equality form of the
/// fewer-contact phase; always an answer when `kin` is non-empty.
///
/// # Errors
///
/// [`TwopacError::KinematicsInfeasible`] when `kin` is empty.
pub fn transition_eq13(
    statics: &EqualityForm,
    kin: &Polytope,
    c_prev: [f64; 3],
    opts: &TransitionOptions,
) -> Result<TransitionPoint, TwopacError> {
    let nb = statics.generators.len();
    // x = (c[3], β̃[nb], s, e⁺[6], e⁻[6])
    let (is, ie) = (3 + nb, 4 + nb);
    let n = ie + 12;
    let mut linv = vec![0.0; n * n];
    let s2 = std::f64::consts::FRAC_1_SQRT_2;
    let re = 1.0 / opts.reg.sqrt();
    for i in 0..n {
        linv[i * n + i] = if i < 3 { s2 } else { re };
    }
    let mut cvec = vec![0.0; n];
    for k in 0..3 {
        cvec[k] = -2.0 * c_prev[k];
    }
    cvec[is] = opts.w;
    cvec[ie..].iter_mut().for_each(|v| *v = opts.w_e);
    let nq = 6 + nb + 1 + 12 + kin.len();
    let mut amat = vec![0.0; nq * n];
    let mut bvec = vec![0.0; nq];
    // Equalities: GV β̃ + e⁺ − e⁻ − (0,0,0, c_y, −c_x, 0) = (0, 0, 1, 0, 0, 0).
    for i in 0..6 {
        let row = &mut amat[i * n..(i + 1) * n];
        for (j, g) in statics.generators.iter().enumerate() {
            row[3 + j] = g[i];
        }
        row[ie + i] = 1.0;
        row[ie + 6 + i] = -1.0;
    }
    amat[3 * n + 1] = -1.0; // τ_x row: − c_y
    amat[4 * n] = 1.0; // τ_y row: + c_x
    bvec[2] = 1.0;
    let mut r = 6;
    for j in 0..nb {
        // −β̃_j − s ≤ 0
        amat[r * n + 3 + j] = -1.0;
        amat[r * n + is] = -1.0;
        r += 1;
    }
    amat[r * n + is] = -1.0;
    r += 1;
    for k in 0..12 {
        amat[r * n + ie + k] = -1.0;
        r += 1;
    }
    for (row, &b) in kin.a.iter().zip(&kin.b) {
        amat[r * n..r * n + 3].copy_from_slice(row);
        bvec[r] = b;
        r += 1;
    }
    let sol = quadprog::solve_qp(&mut linv, &cvec, &amat, &bvec, 6, true).map_err(qp_error)?;
    let x = &sol.sol;
    Ok(TransitionPoint {
        com: [x[0], x[1], x[2]],
        slack: x[is].max(0.0),
        wrench_residual: x[ie..].iter().map(|v| v.max(0.0)).sum(),
        degenerate_contacts: statics.degenerate,
        form: QpForm::Eq13,
    })
}
