//! Stance force models: Stage A extraction and the continuous model's closed forms.
//!
//! # Model
//! ```text
//! Stage A (spec stance-model §4.1): SG acceleration → natural spline a(t) →
//!   N samples f_j = R_s · m (a(t_TD + Δt·j/N) − g⃗) → real DFT per stance axis →
//!   c0 + dominant harmonics (η energy, ≤ K_max terms, k ≤ j_cap)
//! Continuous model (§4.3), per stance axis a ∈ {h, p, v}:
//!   f_a(τ) = c0_a + Σ_i c_ia cos(2π j_ia τ + φ_ia),   τ = (t − t_TD)/Δt ∈ [0, 1]
//! Closed forms (§5): F1, F2, ∫f, ∫τf and J, K, P, S of [`ForceModel`].
//! ```
//! Modules: [`basis`] (closed forms of one term, any Ω), [`model`] ([`AxisModel`],
//! [`ForceModel`], grid and flags), [`fit`] ([`fit_stage_a`], [`FitWorkspace`]).
//! Stage B (§4.2, off by default) refits by least squares on the raw COM positions: [`stage_b`].
//!
//! # Frames and units
//! Stance frame `h, p, v` (index 0, 1, 2; spec §2): `f_stance = R_s · f_world`, with `R_s`
//! rows `e_h, e_p, e_v`. Applied force in newtons (`f_v ≈ m g` on average), time in
//! seconds, mass in kilograms, `τ` unit-free, phases in radians.
//!
//! # References
//! Pollard & Behmaram-Mosavat, *Force-Based Motion Editing for Locomotion Tasks*, eq 1
//! and eq 15–22 as corrected by spec stance-model §4–§5; columns of §11.
//!
//! # Examples
//! ```
//! use stancelib::force_model::{fit_stage_a, FitOptions, FitWorkspace, GRAVITY};
//! use stancelib::math::spline::NaturalSpline;
//! // 0.25 s stance whose vertical applied force is 700 + 300 cos(2πτ) N (70 kg body).
//! let (m, dt, t_td) = (70.0, 0.25, 1.0);
//! let t: Vec<f64> = (-8..72).map(|k| t_td + dt * (k as f64 / 64.0)).collect();
//! let az: Vec<f64> = t.iter()
//!     .map(|&x| (700.0 + 300.0 * (std::f64::consts::TAU * (x - t_td) / dt).cos()) / m - GRAVITY)
//!     .collect();
//! let zero = NaturalSpline::new(&t, &vec![0.0; t.len()]).unwrap();
//! let acc = [zero.clone(), zero, NaturalSpline::new(&t, &az).unwrap()];
//! let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
//! let mut ws = FitWorkspace::new(64);
//! let fm = fit_stage_a(&mut ws, &acc, t_td, dt, eye, m, 30, &FitOptions::default()).unwrap();
//! assert_eq!(fm.axes[2].harmonics, vec![1]);
//! assert!((fm.j()[2] - 700.0 * dt / m).abs() < 1e-9); // J_v = c0 Δt / m
//! assert!(fm.support_ok() && fm.unilateral_ok(&fm.grid()));
//! ```

pub mod basis;
pub mod export;
pub mod fit;
pub mod model;
pub mod stage_b;

pub use fit::{fit_axis, fit_stage_a, j_cap, k_max, FitWorkspace};
pub use model::{AxisModel, ForceModel};
pub use stage_b::{fit_stage_b, to_stance_model, StageBFit, StageBInput, MAX_CONDITION};

/// Gravity magnitude `g` (m/s²); the gravity vector is `g⃗ = (0, 0, −g)` (spec preamble).
pub const GRAVITY: f64 = 9.81;
/// Default number of samples `N` per stance (spec §4.1 step 3).
pub const DEFAULT_SAMPLES: usize = 64;
/// Default cap `K_max` on the harmonics kept per axis (spec §4.1 step 5).
pub const DEFAULT_MAX_HARMONICS: usize = 6;
/// Default energy fraction `η` the kept harmonics must reach (spec §4.1 step 5).
pub const DEFAULT_ENERGY: f64 = 0.99;
/// Unilateral test fraction: `f_v ≥ −0.05 · max f_v` on the grid (spec §4.3).
pub const UNILATERAL_FRACTION: f64 = 0.05;

/// Stage A tuning knobs (pipeline `fit.*`); see the `DEFAULT_*` constants.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Samples `N` per stance (≥ 2), at `τ_j = j/N`; default [`DEFAULT_SAMPLES`].
    pub samples: usize,
    /// At most `K_max` harmonics per axis; default [`DEFAULT_MAX_HARMONICS`].
    pub max_harmonics: usize,
    /// Energy fraction `η ∈ [0, 1]` of the candidates to keep; default [`DEFAULT_ENERGY`].
    pub energy: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            samples: DEFAULT_SAMPLES,
            max_harmonics: DEFAULT_MAX_HARMONICS,
            energy: DEFAULT_ENERGY,
        }
    }
}
