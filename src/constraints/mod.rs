//! Per-stance constraint coefficients: what the library stores so that queries can filter
//! scaled stances in O(1) and check them exactly in O(N_s) without trigonometry
//! (spec stance-model §5, §7.1–7.4, §8.1–8.2, §11).
//!
//! # Model
//!
//! A query scales the stance's applied force per axis, `f̃_a(τ) = β_a f_a(τ)`, and must meet
//! eq 5–8 on the grid `τ_k` of §4.3:
//!
//! ```text
//! (5) β_a ≥ 0
//! (6) β_h² f_h² + β_p² f_p² + β_v² f_v² ≤ F_max²                                (N²)
//! (7) β_h² f_h² + β_p² f_p² ≤ μ² β_v² f_v²  on T_act = {f_v ≥ λ_act max f_v}, λ_act = 0.05
//!     and f_v ≥ −0.05 max f_v everywhere (unilateral, §4.3)
//! (8) χ_min ≤ |r(τ) − x_cp| ≤ χ_max                                              (m)
//! ```
//!
//! [`precompute`] stores, per stance (§7.2, §11): `A^F` (eq 9), `A^μ` (eq 11), `min f_v`, the
//! flags, the original extremes `F_peak`, `μ_req`, `ext_min`, `ext_max` (β = 1, data contact
//! point), the angular impulse `H` and `H_0` (§8.2), and the Appendix B boxes at the
//! stance's own context with the relative limits
//!
//! ```text
//! χ_max = 1.05 · ext_max,   χ_min = ext_min / 1.05,   boxes clipped to [0, β_max]³
//! ```
//!
//! Submodules: [`grids`] (sampled `f_a`, `S_a`), [`coefficients`] (eq 9, 11, extremes),
//! [`extension`] (`r(τ)`, eq 8, Appendix B), [`impulse`] (`H`, `H_0` in closed form).
//!
//! # Frames and units
//!
//! Stance frame (h, p, v) of §2, origin at the COM at touchdown; SI units (m, s, kg, N);
//! `τ = (t − t_TD)/Δt ∈ [0, 1]`; β dimensionless.
//!
//! # References
//!
//! Pollard & Behmaram-Mosavat 2000, "Force-based motion editing for locomotion tasks",
//! eq 5–12 and Appendix B; spec stance-model §7 and §8 for the corrections.
//!
//! # Examples
//!
//! ```
//! use stancelib::constraints::{precompute, StanceContext};
//! use stancelib::force_model::{AxisModel, ForceModel, GRAVITY};
//!
//! let axis = |c0: f64, amp: f64, phase: f64| AxisModel {
//!     c0,
//!     harmonics: vec![1.0],
//!     amps: vec![amp],
//!     phases: vec![phase],
//!     poly: Vec::new(),
//!     fit_rms: 0.0,
//! };
//! // f_v = 2mg (1 − cos 2πτ): a bell that supports the body.
//! let (m, bell) = (70.0, 2.0 * 70.0 * GRAVITY);
//! let model = ForceModel {
//!     mass_kg: m,
//!     dt_s: 0.25,
//!     axes: [axis(0.0, 300.0, 0.0), axis(0.0, 0.0, 0.0), axis(bell, bell, std::f64::consts::PI)],
//! };
//! let ctx = StanceContext { vs: 3.0, vps: 0.0, t_td: 0.1, z_td: 0.9, cp: [0.2, 0.0] };
//! let c = precompute(&model, &ctx);
//! assert!(c.support_ok && c.unilateral_ok);
//! assert!(c.ext_min <= c.ext_max && c.mu_req.is_finite());
//! // The χ_max box at the stance's own context holds the identity β = 1.
//! assert!((0..3).all(|a| c.ell_r_min[a] <= 1.0 && 1.0 <= c.ell_r_max[a]));
//! ```

pub mod coefficients;
pub mod extension;
pub mod grids;
pub mod impulse;

#[cfg(test)]
mod tests;

pub use coefficients::{
    force_coefficients, force_filter_accepts, friction_filter_accepts, ForceCoefficients,
};
pub use extension::{com_offset, ellipsoid_boxes, extension_extremes, EllipsoidBoxes};
pub use grids::SampledGrids;
pub use impulse::{angular_impulse, contact_point_matrix, h0_closed_form, linear_impulse};

use crate::force_model::ForceModel;

/// `λ_act`: the active set is where `f_v ≥ λ_act · max f_v` (§7.1).
pub const ACTIVE_FRACTION: f64 = 0.05;
/// The robust active fraction: `f_v ≥ 0.2 · max f_v`, of the stored `mu_req_robust` column
/// and the queries' default friction check. Against force plates the 5 % figure is decided
/// by the last frame or two of contact, where the kinematic force is least accurate; at 20 %
/// the model's `μ_req` agrees with the plates' to 0.04 (median) on a treadmill run.
pub const ROBUST_ACTIVE_FRACTION: f64 = 0.2;
/// Upper end of the β domain the Appendix B boxes are clipped to (§7.3).
pub const DEFAULT_BETA_MAX: f64 = 3.0;
/// Margin of the relative limits (§7.5): `χ_max = 1.05 · ext_max`, `χ_min = ext_min / 1.05`.
pub const RELATIVE_MARGIN: f64 = 1.05;
/// A grid point is skipped on axis `a` of the Appendix B boxes when
/// `|S_a(τ)| ≤ DEFAULT_S_FLOOR_REL · max_τ |S_a|` (`S_a` is 0 at τ = 0).
pub const DEFAULT_S_FLOOR_REL: f64 = 1e-9;

/// The stance's original context, stance frame (h, p, v), relative to the COM at touchdown.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StanceContext {
    /// Start-apex velocity along the heading `vs`, m/s.
    pub vs: f64,
    /// Start-apex perpendicular velocity `vps`, m/s.
    pub vps: f64,
    /// Touchdown time `t_TD` from the start apex, s.
    pub t_td: f64,
    /// COM height above the contact at touchdown `z_TD`, m.
    pub z_td: f64,
    /// Contact point `(cp_h, cp_p)`, m; `x_cp = (cp_h, cp_p, −z_TD)` (§8.1).
    pub cp: [f64; 2],
}

/// Knobs of [`precompute_with`]; [`Default`] gives the documented `DEFAULT_*` values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrecomputeOptions {
    /// β domain `[0, β_max]` of the Appendix B boxes; default [`DEFAULT_BETA_MAX`].
    pub beta_max: f64,
    /// Relative floor on `|S_a|` below which a grid point is skipped; default
    /// [`DEFAULT_S_FLOOR_REL`].
    pub s_floor_rel: f64,
}

impl Default for PrecomputeOptions {
    fn default() -> Self {
        Self {
            beta_max: DEFAULT_BETA_MAX,
            s_floor_rel: DEFAULT_S_FLOOR_REL,
        }
    }
}

/// What the library stores per stance (§7.2, §8.2, Appendix B at the stance's own context).
///
/// Column meanings are those of §11 (same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// `A^F_a = max_k f_a(τ_k)²`, (h, p, v), N² (eq 9).
    pub a_f: [f64; 3],
    /// `A^μ_a = max over T_act of (f_a/f_v)²`, (h, p) (eq 11); `+∞` if `max f_v ≤ 0`.
    pub a_mu: [f64; 2],
    /// `min_k f_v(τ_k)`, N.
    pub min_f_v: f64,
    /// `f_v ≥ −0.05 · max f_v` on the whole grid (§4.3).
    pub unilateral_ok: bool,
    /// `J_v > 0` (§5).
    pub support_ok: bool,
    /// `max_k |f(τ_k)|`, N (β = 1).
    pub f_peak: f64,
    /// `max over T_act of √(f_h² + f_p²)/f_v` (β = 1); `+∞` if `max f_v ≤ 0`.
    pub mu_req: f64,
    /// The same on the robust active set `f_v ≥ ROBUST_ACTIVE_FRACTION · max f_v`.
    pub mu_req_robust: f64,
    /// `min_k |r(τ_k) − x_cp|`, m (β = 1).
    pub ext_min: f64,
    /// `max_k |r(τ_k) − x_cp|`, m (β = 1).
    pub ext_max: f64,
    /// `H = x_cp × I − H_0`, (h, p, v), N·m·s (§8.2).
    pub ang_impulse: [f64; 3],
    /// `H_0 = ∫ r × F dt`, (h, p, v), N·m·s (§8.2).
    pub ang_impulse_h0: [f64; 3],
    /// χ_max box lower corner `R_min`, clipped to `[0, β_max]`.
    pub ell_r_min: [f64; 3],
    /// χ_max box upper corner `R_max`, clipped to `[0, β_max]`.
    pub ell_r_max: [f64; 3],
    /// χ_min box lower corner `S_min`, clipped to `[0, β_max]`.
    pub ell_s_min: [f64; 3],
    /// χ_min box upper corner `S_max`, clipped to `[0, β_max]`.
    pub ell_s_max: [f64; 3],
}

/// Coefficients of one stance with the default options (allocates its own grids).
pub fn precompute(model: &ForceModel, ctx: &StanceContext) -> Coefficients {
    let mut grids = SampledGrids::default();
    precompute_with(model, ctx, &PrecomputeOptions::default(), &mut grids)
}

/// Coefficients of one stance; `grids` is scratch, refilled with `f_a(τ_k)`, `S_a(τ_k)`.
///
/// Reuse one `grids` per thread across stances to avoid per-stance allocation of the
/// grids. Never panics; non-finite inputs give non-finite outputs.
pub fn precompute_with(
    model: &ForceModel,
    ctx: &StanceContext,
    opts: &PrecomputeOptions,
    grids: &mut SampledGrids,
) -> Coefficients {
    grids.rebuild(model);
    let force = force_coefficients(grids);
    let (ext_min, ext_max) = extension_extremes(model, ctx, grids);
    let chi = [ext_min / RELATIVE_MARGIN, RELATIVE_MARGIN * ext_max];
    let boxes = ellipsoid_boxes(model, ctx, grids, chi, opts);
    let (ang_impulse, ang_impulse_h0) = angular_impulse(model, ctx);
    Coefficients {
        a_f: force.a_f,
        a_mu: force.a_mu,
        min_f_v: force.min_f_v,
        unilateral_ok: force.unilateral_ok,
        support_ok: model.support_ok(),
        f_peak: force.f_peak,
        mu_req: force.mu_req,
        mu_req_robust: force.mu_req_robust,
        ext_min,
        ext_max,
        ang_impulse,
        ang_impulse_h0,
        ell_r_min: boxes.r_min,
        ell_r_max: boxes.r_max,
        ell_s_min: boxes.s_min,
        ell_s_max: boxes.s_max,
    }
}
