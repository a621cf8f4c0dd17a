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
//! assert_eq!(fm.axes[2].harmonics, vec![1.0]);
//! assert!((fm.j()[2] - 700.0 * dt / m).abs() < 1e-9); // J_v = c0 Δt / m
//! assert!(fm.support_ok() && fm.unilateral_ok(&fm.grid()));
//! ```

pub mod basis;
pub mod cosine;
pub mod export;
pub mod fit;
pub mod leg_line;
pub mod model;
pub mod per_contact;
pub mod ratio;

pub use cosine::{fit_cosine_with, CosineFit};
pub use fit::{fit_axis, fit_stage_a, j_cap, k_max, FitWorkspace, StanceForce};
pub use leg_line::LegLine;
pub use model::{AxisModel, ForceModel};
pub use ratio::{fit_ratio, fit_ratio_with, EdgeTargets, RatioFit, RatioOptions};

pub use crate::math::constants::GRAVITY;
/// Default number of samples `N` per stance (spec §4.1 step 3).
pub const DEFAULT_SAMPLES: usize = 64;
/// Default cap `K_max` on the harmonics kept per axis (spec §4.1 step 5).
pub const DEFAULT_MAX_HARMONICS: usize = 6;
/// Default energy fraction `η` the kept harmonics must reach (spec §4.1 step 5).
pub const DEFAULT_ENERGY: f64 = 0.99;
/// Unilateral test fraction: `f_v ≥ −0.05 · max f_v` on the grid (spec §4.3).
pub const UNILATERAL_FRACTION: f64 = 0.05;

/// Which stance force model a build fits (pipeline `fit.model`, `--force-model`).
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum ForceModelKind {
    /// The friction-ratio model of [`ratio`] (default).
    #[default]
    Ratio,
    /// The paper's Fourier model (a constant plus cosine terms per axis) fitted with the
    /// ratio model's physics: half-range cosines for `f_v` and the ratios ([`cosine`]).
    /// The periodic DFT of spec §4.1 ([`fit_stage_a`]) stays a library function.
    Fourier,
}

impl ForceModelKind {
    /// The name used in options, stance rows and the manifest.
    pub fn name(self) -> &'static str {
        match self {
            ForceModelKind::Ratio => "ratio",
            ForceModelKind::Fourier => "fourier",
        }
    }

    /// Parses `ratio` or `fourier`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "ratio" => Some(ForceModelKind::Ratio),
            "fourier" => Some(ForceModelKind::Fourier),
            _ => None,
        }
    }
}

/// Force-model tuning knobs (pipeline `fit.*`); see the `DEFAULT_*` constants.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// The model to fit; default [`ForceModelKind::Ratio`].
    pub model: ForceModelKind,
    /// Knobs of the ratio model.
    pub ratio: RatioOptions,
    /// Samples `N` per stance (≥ 2), at `τ_j = j/N`; default [`DEFAULT_SAMPLES`].
    pub samples: usize,
    /// At most `K_max` harmonics per axis of the periodic DFT ([`fit_stage_a`]); default
    /// [`DEFAULT_MAX_HARMONICS`]. The `fourier` model of a build takes its sizes from
    /// [`RatioOptions`] ([`cosine`]).
    pub max_harmonics: usize,
    /// Energy fraction `η ∈ [0, 1]` of the DFT's candidates to keep ([`fit_stage_a`]);
    /// default [`DEFAULT_ENERGY`].
    pub energy: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            model: ForceModelKind::default(),
            ratio: RatioOptions::default(),
            samples: DEFAULT_SAMPLES,
            max_harmonics: DEFAULT_MAX_HARMONICS,
            energy: DEFAULT_ENERGY,
        }
    }
}

/// A stance's fitted force model: which model, and the ratio polynomials of the ratio model.
#[derive(Debug, Clone, PartialEq)]
pub struct StanceFit {
    /// The force model in the stance frame.
    pub model: ForceModel,
    /// Which model was fitted.
    pub kind: ForceModelKind,
    /// `q_h`, `q_p` of the ratio model (power basis); empty for the Fourier model, whose
    /// ratios are in its force terms ([`CosineFit::ratio`]).
    pub ratio: [Vec<f64>; 2],
    /// Vertical edge targets met (see [`RatioFit::vertical_targets_met`]).
    pub targets_met: usize,
}

/// Fits the model `opts.model` to one stance's kinematic force (`n_st` stance frames).
///
/// `targets` make the force integrate to the stance's edge states. The workspace (the
/// DFT's, [`fit_stage_a`]) is not used by either model; it stays for callers' threads. Both models sample
/// `τ_j = j/(N−1)`, both edges included, use the leg line where there is one and differ in
/// the basis: Bernstein and power polynomials ([`ratio::fit_ratio_with`]) or half-range
/// cosines ([`cosine::fit_cosine_with`]).
///
/// # Errors
/// Bad options or stance values (config), a non-finite sampled force, a failed QP.
pub fn fit_stance(
    _ws: &mut FitWorkspace,
    force: &StanceForce,
    n_st: usize,
    targets: Option<&EdgeTargets>,
    opts: &FitOptions,
) -> crate::Result<StanceFit> {
    force.check(&format!("{} model", opts.model.name()))?;
    let n = opts.samples.clamp(fit::MIN_SAMPLES, fit::MAX_SAMPLES);
    let tau = ratio::sample_grid(n);
    let mut samples: [Vec<f64>; 3] = Default::default();
    if !force.sample(tau.iter().copied(), &mut samples) {
        return Err(crate::Error::numeric(format!(
            "{} model: sampled force is not finite near t = {} s",
            opts.model.name(),
            force.t_td
        )));
    }
    let leg = force
        .leg
        .as_ref()
        .filter(|_| opts.ratio.leg_line_weight > 0.0);
    let slopes = leg.and_then(|l| {
        l.slopes(
            (force.t_td, force.dt),
            &force.r_s,
            &tau,
            opts.ratio.roll_fraction,
        )
    });
    match opts.model {
        ForceModelKind::Fourier => {
            let fit = fit_cosine_with(
                &samples,
                n_st,
                (force.mass_kg, force.dt),
                targets,
                slopes.as_ref(),
                &opts.ratio,
            )?;
            Ok(StanceFit {
                model: fit.model,
                kind: ForceModelKind::Fourier,
                ratio: Default::default(),
                targets_met: fit.vertical_targets_met,
            })
        }
        ForceModelKind::Ratio => {
            let fit = fit_ratio_with(
                &samples,
                n_st,
                force.mass_kg,
                force.dt,
                targets,
                slopes.as_ref(),
                &opts.ratio,
            )?;
            Ok(StanceFit {
                model: fit.model,
                kind: ForceModelKind::Ratio,
                ratio: fit.ratio,
                targets_met: fit.vertical_targets_met,
            })
        }
    }
}
