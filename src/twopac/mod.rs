//! 2PAC: multi-contact COM trajectories from transition points (issue 5; spec two-pac).
//!
//! Pure numerical core, no I/O: contacts and friction cones, static and dynamic
//! equilibrium with the robustness margin, the COM-space H-representation of a phase,
//! transition points by the slack QP, Bezier curves with one or two attractor points in a
//! sliding window, dynamic validation, and convex hulls for the kinematic polytopes.
//!
//! # Model
//!
//! ```text
//! equilibrium (eq 1, 12):  ∃ β ≥ 0 : G V β = w(c, c̈) = [m(c̈ − g⃗); c × m(c̈ − g⃗)]     (N, N·m)
//! static region (eq 2):    A c ≤ a  (unit rows, m)                 — region.rs
//! transition (eq 6, 13):   min ‖c − c_prev‖² + w s  (w = 1000 m²)  — transition.rs
//! curve (eq 7–9):          c(t) = Σ_k B_k^n(t) P_k,  n = 6 or 7     — bezier.rs
//! sliding window (§6):     windows of 2 or 3 phases, switch at u    — trajectory.rs
//! validation (§7):         s* = min s : G V β = w(c, c̈), β + s ≥ 0  — validate.rs
//! why a sample fails:      off support / too fast / no force       — diagnose.rs
//! limb reach (§3):         K c ≤ k from the convex hull of COM samples — limb_reach.rs, hull.rs
//! ```
//!
//! # Frames and units
//!
//! World frame, right-handed, Z up, `g⃗ = (0, 0, −9.81)` m/s²; SI units (m, s, kg, N).
//! Every function takes and returns plain values; solve times are measured by callers.
//!
//! # References
//!
//! Tonneau, Fernbach, Del Prete, Pettré, Mansard, "2PAC: Two Point Attractors for Center
//! of Mass Trajectories in Multi Contact Scenarios", ACM TOG 2018 (eq 1–13, Table 3);
//! spec `two-pac.md` revision 2; CORRECTIONS Issue 5.
//!
//! # Examples
//!
//! ```
//! use stancelib::twopac::contact::{Contact, ContactShape};
//! use stancelib::twopac::equilibrium::{EqualityForm, Status};
//!
//! // Case R2 of spec §9: four points (±0.05, ±0.1, 0), m = 54 kg, μ = 0.3.
//! let pts = vec![[0.05, 0.1, 0.0], [0.05, -0.1, 0.0], [-0.05, -0.1, 0.0], [-0.05, 0.1, 0.0]];
//! let c = Contact::new("feet", [0.0; 3], [0.0, 0.0, 1.0], 0.3, 0.0, ContactShape::Points(pts))
//!     .unwrap();
//! let form = EqualityForm::new(&[c], 54.0).unwrap();
//! let v = form.verdict([0.0, 0.0, 1.0], [0.0; 3]);
//! assert_eq!(v.status, Status::Solved);
//! assert!((v.margin_n.unwrap() - 38.05).abs() < 0.01);
//! ```

#![warn(missing_docs)]

pub mod bezier;
pub mod clip;
pub mod contact;
pub mod diagnose;
pub mod equilibrium;
pub mod hull;
pub mod limb_reach;
pub mod phases;
pub mod polytope;
pub mod region;
mod simplex;
pub mod trajectory;
pub mod transition;
mod unique_keys;
use crate::math::v3;
pub mod validate;

#[cfg(test)]
mod tests;

/// Errors of the 2PAC core: each says what failed and where.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TwopacError {
    /// A contact is malformed.
    #[error("contact {effector}: {msg}")]
    InvalidContact {
        /// The contact's effector.
        effector: String,
        /// What is wrong.
        msg: String,
    },
    /// The mass is not a positive finite number.
    #[error("mass must be positive and finite, found {mass_kg} kg")]
    InvalidMass {
        /// The mass given, kg.
        mass_kg: f64,
    },
    /// The phase sequence is malformed (§1: consecutive phases differ by exactly one contact).
    #[error("phase {phase}: {msg}")]
    InvalidPhases {
        /// 0-based phase index.
        phase: usize,
        /// What is wrong.
        msg: String,
    },
    /// The kinematic polytope of a transition (or phase) is empty: a hard failure (§4).
    #[error(
        "kinematic constraints are infeasible (transition {transition:?}, effectors {effectors:?})"
    )]
    KinematicsInfeasible {
        /// 0-based transition index (`j` for `j → j+1`), when known.
        transition: Option<usize>,
        /// Effectors whose polytopes were stacked.
        effectors: Vec<String>,
    },
    /// Eq 6 asked for on a contact set with no static COM at all (use eq 13).
    #[error("the static region is empty: no COM is in static equilibrium")]
    EmptyStaticRegion,
    /// A numerical solver failed (reported with what was being solved).
    #[error("solver: {what}")]
    Solver {
        /// What was being solved, and how it failed.
        what: String,
    },
    /// An iterative solver stopped at its cap before it converged.
    #[error("solver: {what}: not converged after {iterations} iterations")]
    NotConverged {
        /// What was being solved.
        what: String,
        /// Iterations (LPs, pivots) done.
        iterations: usize,
    },
    /// A convex hull cannot be built (§3: at least 4 non-coplanar points).
    #[error("hull of {n_points} points: {msg}")]
    DegenerateHull {
        /// Number of input points.
        n_points: usize,
        /// What is wrong.
        msg: String,
    },
    /// An input asks for more work than a documented work cap allows (checked before the
    /// work starts; README "Work caps").
    #[error("{found} {what}, more than the limit of {max} ({cap})")]
    Cap {
        /// What is counted (`contact points`, `validation samples`).
        what: &'static str,
        /// The amount asked for (formatted: it may not fit an integer).
        found: String,
        /// The cap.
        max: usize,
        /// The name of the constant that defines it (`MAX_SAMPLES`).
        cap: &'static str,
    },
    /// A Bezier curve cannot be built from its inputs.
    #[error("bezier: {msg}")]
    InvalidCurve {
        /// What is wrong.
        msg: String,
    },
}
