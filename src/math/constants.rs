//! Physical constants and shared numerical tolerances, each defined once for the crate.
//!
//! The stages re-export the ones their callers name (`force_model::GRAVITY`,
//! `stances::limits::DEFAULT_MU`, `twopac::contact::DEFAULT_MU`, …); the value lives here.

/// Gravity magnitude `g`, m/s²; the gravity vector is `g⃗ = (0, 0, −g)` in the internal
/// Z-up frame (spec stance-model preamble, com-from-bvh §7.7, two-pac §9).
pub const GRAVITY: f64 = 9.81;

/// Default Coulomb friction coefficient `μ` (dimensionless): the absolute friction limit
/// of the stance library (stance-model §7.5) and of a 2PAC contact without `friction`
/// (two-pac §1.1).
pub const DEFAULT_MU: f64 = 0.7;

/// A 2PAC point is statically feasible when its QP slack `s` (N) and wrench residual
/// `‖e‖₁` (N, N·m) are at most this (two-pac §4: `wrench_residual > 1e-6` fails).
pub const STATIC_TOL: f64 = 1e-6;
