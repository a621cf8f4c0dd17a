//! Feasibility of a scaled stance: the O(1) filters, the exact sampled check and the
//! closed-form contact point (spec stance-model §7.1–7.5, §8.2–8.3).
//!
//! # Model
//!
//! A query scales the stance's applied force per axis, `f̃_a(τ) = β_a f_a(τ)`. On the grid
//! `τ_k` of §4.3 the exact check ([`exact`]) computes
//!
//! ```text
//! F_peak  = max_k √(Σ_a β_a² f_a(τ_k)²)                                           (N)
//! μ_req   = max_{T_act} √(β_h² f_h² + β_p² f_p²) / (β_v f_v)                      (–)
//! T_act   = {τ_k : f_v(τ_k) ≥ λ_act · max_k f_v},  λ_act = 0.05 (β_v > 0 scales both sides)
//! ext(τ)  = |U(τ) + β∘S(τ)|,  ext_min = min_k ext,  ext_max = max_k ext            (m)
//! U_h = vs Δt τ − cp_h,  U_p = vps Δt τ − cp_p,  U_v = −g t_TD Δt τ − ½ g Δt² τ² + z_TD
//! ```
//!
//! and a candidate is feasible iff (every comparison `≤` with a relative round-off
//! tolerance [`LIMIT_REL_TOL`] on the limit, so the identity query at its own extremes is
//! feasible):
//!
//! ```text
//! (5) β_a ≥ 0   (6) F_peak ≤ F_max   (7) μ_req ≤ μ and f_v ≥ −0.05 max f_v on all of [0, 1]
//! (8) χ_min ≤ ext_min,  ext_max ≤ χ_max
//! ```
//!
//! The fast filter ([`approx`]) is eq 10 and eq 12 on the stored `A^F`, `A^μ`; it never
//! accepts what eq 6 and eq 7 reject (a max of sums is at most the sum of maxes).
//!
//! The contact point ([`contact_point`]) minimises `|H(u) − H_des|` with `H(u) = A u + b`
//! affine in `u = (cp_h, cp_p)` (§8.2), `W = I`:
//!
//! ```text
//! I    = m β∘J                                           (N·s)
//! R_ab = ∫₀¹ r_a(β, τ) f_b(τ) dτ = ℓ1_a T1_b + ℓ2_a T2_b + β_a Q_ab                 (m·N)
//! H_0  = Δt (β_v R_pv − β_p R_vp,  β_h R_vh − β_v R_hv,  β_p R_hp − β_h R_ph)        (N·m·s)
//! b    = (0, 0, −z_TD) × I − H_0,   A = [[0, I_v], [−I_v, 0], [I_p, −I_h]]
//! u*   = (AᵀA)⁻¹ Aᵀ (H_des − b)                                                      (m)
//! ℓ1 = (vs Δt, vps Δt, −g t_TD Δt),  ℓ2 = (0, 0, −½ g Δt²),  T1_b = ∫τ f_b,  T2_b = ∫τ² f_b,
//! Q_ab = ∫ S_a f_b
//! ```
//!
//! `Q`, `T1`, `T2` and `m J` depend on the stance only ([`ImpulseMoments`], built once), so
//! a query's `u*` costs O(1) and no trigonometry.
//!
//! # Frames and units
//!
//! Stance frame (h, p, v), origin at the COM at touchdown; SI units (m, s, kg, N); β and μ
//! dimensionless.
//!
//! # References
//!
//! Pollard & Behmaram-Mosavat 2000, eq 5–12; spec stance-model §7.1–7.5 (active set,
//! unilateral test, limits), §8.2–8.3 (contact point), CORRECTIONS Issue 4 items 6–7.
//!
//! # Examples
//!
//! ```
//! use stancelib::constraints::{precompute, SampledGrids, StanceContext};
//! use stancelib::force_model::{AxisModel, ForceModel, GRAVITY};
//! use stancelib::query::feasibility::{approx, exact, relative_limits};
//!
//! let bell = 2.0 * 70.0 * GRAVITY;
//! let v = AxisModel { c0: bell, harmonics: vec![1.0], amps: vec![bell],
//!                     phases: vec![std::f64::consts::PI], poly: vec![], fit_rms: 0.0 };
//! let h = AxisModel { c0: 0.0, harmonics: vec![1.0], amps: vec![200.0], phases: vec![0.0],
//!                     poly: vec![], fit_rms: 0.0 };
//! let model = ForceModel { mass_kg: 70.0, dt_s: 0.25, axes: [h, AxisModel::constant(0.0), v] };
//! let ctx = StanceContext { vs: 3.0, vps: 0.0, t_td: 0.1, z_td: 0.9, cp: [0.2, 0.0] };
//! let coef = precompute(&model, &ctx);
//! let lim = relative_limits(&coef);
//! // The identity query is feasible under the stance's own relative limits.
//! let verdict = exact(&SampledGrids::new(&model), &model, &ctx, [1.0; 3], &lim);
//! assert!(verdict.feasible && approx(coef.a_f, coef.a_mu, [1.0; 3], &lim));
//! ```

use crate::constraints::grids::{dc_term, harmonic_terms};
use crate::constraints::impulse::moment_integral;
use crate::constraints::{
    contact_point_matrix, force_filter_accepts, friction_filter_accepts, linear_impulse,
    Coefficients, SampledGrids, StanceContext, RELATIVE_MARGIN,
};
use crate::force_model::{basis, ForceModel, GRAVITY};

/// Absolute friction coefficient `μ` of `query run` (§7.5): the crate's one default μ.
pub use crate::math::constants::DEFAULT_MU;
/// [`contact_point`] gives `None` when `det(AᵀA) ≤ SINGULAR_REL · tr(AᵀA)²`, i.e. when
/// `I_v² ≤ SINGULAR_REL · |I|²` roughly (no vertical impulse: `u*` is not determined).
pub const SINGULAR_REL: f64 = 1e-12;

/// Default active fraction `λ_act` of the queries' friction check (`--active-set`,
/// pipeline `[constraints] active_set`): the robust `f_v ≥ 0.2 · max f_v` of the stored
/// `mu_req_robust` ([`crate::constraints::ROBUST_ACTIVE_FRACTION`]). On the force plates of
/// a treadmill run the stance models' `μ_req` agree with the plates' to 0.04 (median) at
/// 0.2, and to 0.12 at the paper's 0.05, where the ratio is decided by the last frames of
/// contact and the kinematic force is least accurate. The stored `mu_req`, `a_mu` columns
/// stay at the paper's [`crate::constraints::ACTIVE_FRACTION`].
pub const DEFAULT_QUERY_ACTIVE_FRACTION: f64 = crate::constraints::ROBUST_ACTIVE_FRACTION;

/// Relative round-off tolerance of the exact check's limits: a value within
/// `LIMIT_REL_TOL × limit` of a limit meets it (`F_max`, `χ_max`, `μ` grow by the factor
/// `1 + LIMIT_REL_TOL`, `χ_min` shrinks by `1 − LIMIT_REL_TOL`). The closed forms reproduce
/// a recorded stance to ~1e-12 relative; a recorded jump solved back at its own height and
/// distance missed its own extension limit by 6e-11 (relative) without it.
pub const LIMIT_REL_TOL: f64 = 1e-9;

/// Absolute round-off tolerance of the friction limit: a vertical jump's recorded friction
/// demand is ~1e-9 (its horizontal force is round-off), so 5 % of it is below the
/// round-off of the identity solution; the demo's recorded jumps missed their own relative
/// friction limit by 6e-11 and 3e-10 without it. A friction demand of 1e-6 is none.
pub const MU_ABS_TOL: f64 = 1e-6;

/// Checks a friction limit given by the user (`--mu`, `[constraints] mu`): a positive
/// finite number.
///
/// # Errors
/// What is wrong with `mu`, as a message.
pub fn check_mu(mu: f64) -> Result<f64, String> {
    if mu.is_finite() && mu > 0.0 {
        Ok(mu)
    } else {
        Err(format!("μ must be a positive finite number, found {mu}"))
    }
}

/// The limits of eq 6–8 for one query (§7.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Friction coefficient `μ`, dimensionless.
    pub mu: f64,
    /// Largest contact force magnitude `F_max`, N.
    pub f_max: f64,
    /// Shortest leg extension `χ_min`, m.
    pub chi_min: f64,
    /// Longest leg extension `χ_max`, m.
    pub chi_max: f64,
}

impl Limits {
    /// The limits as the exact check applies them: `F_max`, `χ_max`, `μ` times
    /// `1 + LIMIT_REL_TOL`, `χ_min` times `1 − LIMIT_REL_TOL`, and `μ` also plus
    /// [`MU_ABS_TOL`] (the margins the output tables report are to these, so a margin ≥ 0 is
    /// exactly a limit met).
    pub fn effective(&self) -> Limits {
        let (up, down) = (1.0 + LIMIT_REL_TOL, 1.0 - LIMIT_REL_TOL);
        Limits {
            mu: self.mu * up + MU_ABS_TOL,
            f_max: self.f_max * up,
            chi_min: self.chi_min * down,
            chi_max: self.chi_max * up,
        }
    }
}

/// Which limits a query checks (§7.5): `Absolute` per character (`query run`'s default),
/// `Relative` to each stance's own extremes (`query jump` and `map jumps`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitForm {
    /// μ (0.7 or given), and 1.05 × the character's extremes (§7.5 table, left).
    Absolute,
    /// 1.05 × the stance's own extremes (§7.5 table, right).
    Relative,
}

impl LimitForm {
    /// `absolute` or `relative`.
    pub fn name(self) -> &'static str {
        match self {
            LimitForm::Absolute => "absolute",
            LimitForm::Relative => "relative",
        }
    }

    /// `absolute` or `relative`; `None` otherwise.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "absolute" => Some(LimitForm::Absolute),
            "relative" => Some(LimitForm::Relative),
            _ => None,
        }
    }
}

/// The query's context: scaled stance start state and contact point, stance frame
/// (§5, §7.3); the same fields as the stance's own [`StanceContext`].
pub type QueryContext = StanceContext;

/// The first constraint a candidate violates, in the order checked by [`exact`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Violation {
    /// Eq 5: some `β_a < 0` (or NaN).
    Beta,
    /// Eq 6: `F_peak > F_max`.
    Force,
    /// Eq 7: `μ_req > μ` on the active set.
    Friction,
    /// §4.3: `f_v < −0.05 · max f_v` somewhere (independent of β).
    Unilateral,
    /// Eq 8: `ext_min < χ_min`.
    ExtensionMin,
    /// Eq 8: `ext_max > χ_max`.
    ExtensionMax,
}

/// Result of the exact check (§7.4) with the scaled stance's extremes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// Every sample satisfies eq 5–8 and the unilateral test.
    pub feasible: bool,
    /// The first violated constraint (order of [`Violation`]); `None` iff feasible.
    pub violated: Option<Violation>,
    /// `max_k |f̃(τ_k)|`, N.
    pub f_peak: f64,
    /// `max over T_act of |f̃_t|/f̃_v`; `+∞` when the stance carries no load.
    pub mu_req: f64,
    /// `min_k |r(τ_k) − x_cp|`, m.
    pub ext_min: f64,
    /// `max_k |r(τ_k) − x_cp|`, m.
    pub ext_max: f64,
}

/// O(1) filters (eq 10, eq 12) from the stance's stored `A^F`, `A^μ`: conservative.
///
/// Also checks eq 5 (`β ≥ 0`) and rejects negative or NaN `F_max`, `μ`. It never accepts a
/// candidate whose eq 6 or eq 7 fails in [`exact`]; it may reject feasible ones. The
/// unilateral test does not depend on β: read it from the stance's `unilateral_ok`.
pub fn approx(a_f: [f64; 3], a_mu: [f64; 2], beta: [f64; 3], lim: &Limits) -> bool {
    beta.iter().all(|&b| b >= 0.0)
        && lim.f_max >= 0.0
        && lim.mu >= 0.0
        && force_filter_accepts(&a_f, beta, lim.f_max)
        && friction_filter_accepts(&a_mu, beta, lim.mu)
}

/// `√x ≤ lim` decided exactly, with the square root only near the boundary.
///
/// `√` is correctly rounded and monotone, so comparing `√x` with a limit set from another
/// `√` (a stance's own extreme) is exact; `x ≤ lim²` alone is not (`lim²` rounds). Outside a
/// relative band of `±8ε` around `lim²` the squared comparison decides.
#[derive(Debug, Clone, Copy)]
struct SqrtLe {
    lim: f64,
    below: f64,
    above: f64,
}

impl SqrtLe {
    fn new(lim: f64) -> Self {
        let l2 = lim * lim;
        SqrtLe {
            lim,
            below: l2 * (1.0 - 8.0 * f64::EPSILON),
            above: l2 * (1.0 + 8.0 * f64::EPSILON),
        }
    }

    /// `√x ≤ lim` (false for NaN; `lim < 0` is never met).
    #[inline(always)]
    fn holds(&self, x: f64) -> bool {
        if x <= self.below {
            self.lim >= 0.0
        } else if x > self.above {
            false
        } else {
            x.sqrt() <= self.lim
        }
    }

    /// `lim ≤ √x` (false for NaN).
    #[inline(always)]
    fn holds_above(&self, x: f64) -> bool {
        if x >= self.above {
            true
        } else if x < self.below {
            self.lim <= 0.0 && x >= 0.0
        } else {
            self.lim <= x.sqrt()
        }
    }
}

/// What the exact check needs per query, precomputed once (O(1)): β, the limits, the
/// active-set threshold and the β-independent offset `U(τ)` of §7.4, in the operation
/// order of `constraints::extension::unscaled_offset` (so β = 1 reproduces the stored
/// extremes bit for bit).
struct Setup {
    beta: [f64; 3],
    force: SqrtLe,
    chi_min: SqrtLe,
    chi_max: SqrtLe,
    mu: f64,
    mu2_below: f64,
    /// `λ_act · max f_v`; the active set is `f_v ≥ threshold` (only when loaded).
    threshold: f64,
    loaded: bool,
    unilateral_ok: bool,
    /// `(vs Δt, vps Δt, −g t_TD Δt)`, `½ g Δt²`, `(−cp_h, −cp_p, z_TD)`.
    lin: [f64; 3],
    quad: f64,
    cp: [f64; 2],
    z_td: f64,
}

/// One grid sample of the scaled stance: `|f̃|²`, `|f̃_t|²`, `f̃_v`, `|r − x_cp|²`, active.
struct Sample {
    f2: f64,
    t2: f64,
    gv: f64,
    d2: f64,
    active: bool,
}

impl Setup {
    fn new(
        grids: &SampledGrids,
        model: &ForceModel,
        ctx: &QueryContext,
        beta: [f64; 3],
        lim: &Limits,
    ) -> Self {
        let (max_fv, unilateral_ok) = (grids.max_f_v, grids.unilateral_ok);
        let nan = max_fv.is_nan();
        let dt = model.dt_s;
        let lim = lim.effective();
        Setup {
            beta,
            force: SqrtLe::new(lim.f_max),
            chi_min: SqrtLe::new(lim.chi_min),
            chi_max: SqrtLe::new(lim.chi_max),
            mu: lim.mu,
            mu2_below: lim.mu * lim.mu * (1.0 - 8.0 * f64::EPSILON),
            threshold: grids.active_fraction * max_fv,
            loaded: !nan && max_fv > 0.0,
            unilateral_ok,
            lin: [ctx.vs * dt, ctx.vps * dt, -GRAVITY * ctx.t_td * dt],
            quad: 0.5 * GRAVITY * dt * dt,
            cp: ctx.cp,
            z_td: ctx.z_td,
        }
    }

    /// Sample `k` of the grids (`k < grids.len()`).
    #[inline(always)]
    fn sample(&self, t: &SampledGrids, k: usize) -> Sample {
        let [bh, bp, bv] = self.beta;
        let tau = t.tau[k];
        let (gh, gp, gv) = (bh * t.f[0][k], bp * t.f[1][k], bv * t.f[2][k]);
        let uh = self.lin[0] * tau - self.cp[0];
        let up = self.lin[1] * tau - self.cp[1];
        let uv = self.lin[2] * tau - self.quad * tau * tau + self.z_td;
        let (rh, rp, rv) = (
            uh + bh * t.s[0][k],
            up + bp * t.s[1][k],
            uv + bv * t.s[2][k],
        );
        let t2 = gh * gh + gp * gp;
        Sample {
            f2: t2 + gv * gv,
            t2,
            gv,
            d2: rh * rh + rp * rp + rv * rv,
            active: self.loaded && t.f[2][k] >= self.threshold,
        }
    }

    /// The friction ratio `|f̃_t|/f̃_v` of an active sample (`+∞` without a positive normal
    /// force, 0 without a tangential one).
    #[inline(always)]
    fn ratio(x: &Sample) -> f64 {
        if x.t2 == 0.0 {
            0.0
        } else if x.gv > 0.0 {
            x.t2.sqrt() / x.gv
        } else if x.t2.is_nan() || x.gv.is_nan() {
            f64::NAN
        } else {
            f64::INFINITY
        }
    }

    /// Eq 7 at one active sample, `|f̃_t|/f̃_v ≤ μ`; the squared form decides clear cases.
    #[inline(always)]
    fn friction_ok(&self, x: &Sample) -> bool {
        if x.gv > 0.0 && x.t2 <= self.mu2_below * x.gv * x.gv {
            return self.mu >= 0.0;
        }
        Self::ratio(x) <= self.mu
    }
}

/// Exact sampled check (§7.4) on precomputed grids (no trig per query): eq 5–8 and the
/// unilateral test.
///
/// `grids` must be those of `model` ([`SampledGrids::new`]); `ctx.cp` is the contact
/// point to test (the re-solved `u*` of [`contact_point`] for a query, CORRECTIONS Issue 4
/// item 7). At β = 1 with the stance's own context it reproduces `constraints::precompute`'s
/// `F_peak`, `μ_req`, `ext_min`, `ext_max`, and limits equal to them are met (every test is
/// `≤`). Each constraint is decided per sample by the same predicates as
/// [`exact_feasible`], so both always agree. Never panics: NaN inputs give an infeasible
/// verdict; an empty grid gives zeros and `μ_req = +∞` (friction violated).
pub fn exact(
    grids: &SampledGrids,
    model: &ForceModel,
    ctx: &QueryContext,
    beta: [f64; 3],
    lim: &Limits,
) -> Verdict {
    let s = Setup::new(grids, model, ctx, beta, lim);
    let (mut force_ok, mut friction_ok) = (true, s.loaded);
    let (mut ext_lo_ok, mut ext_hi_ok) = (true, true);
    let (mut f2_peak, mut mu_req) = (0.0f64, 0.0f64);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    let mut nan = false;
    for k in 0..grids.len() {
        let x = s.sample(grids, k);
        nan |= x.f2.is_nan() || x.d2.is_nan();
        force_ok &= s.force.holds(x.f2);
        f2_peak = f2_peak.max(x.f2);
        if x.active {
            friction_ok &= s.friction_ok(&x);
            let r = Setup::ratio(&x);
            nan |= r.is_nan();
            mu_req = mu_req.max(r);
        }
        ext_lo_ok &= s.chi_min.holds_above(x.d2);
        ext_hi_ok &= s.chi_max.holds(x.d2);
        lo = lo.min(x.d2);
        hi = hi.max(x.d2);
    }
    if grids.is_empty() {
        (lo, hi) = (0.0, 0.0);
    }
    let out = |v: f64| if nan { f64::NAN } else { v };
    let checks = [
        (beta.iter().all(|&b| b >= 0.0), Violation::Beta),
        (force_ok && !nan, Violation::Force),
        (friction_ok && !nan, Violation::Friction),
        (s.unilateral_ok, Violation::Unilateral),
        (ext_lo_ok && !nan, Violation::ExtensionMin),
        (ext_hi_ok && !nan, Violation::ExtensionMax),
    ];
    let violated = checks.iter().find(|(ok, _)| !ok).map(|&(_, v)| v);
    Verdict {
        feasible: violated.is_none(),
        violated,
        f_peak: out(f2_peak.sqrt()),
        mu_req: if s.loaded { out(mu_req) } else { f64::INFINITY },
        ext_min: out(lo.sqrt()),
        ext_max: out(hi.sqrt()),
    }
}

/// The verdict of [`exact`] alone, stopping at the first violating sample (the map's
/// inner loop). Same per-sample predicates, so `exact_feasible(..) == exact(..).feasible`.
pub fn exact_feasible(
    grids: &SampledGrids,
    model: &ForceModel,
    ctx: &QueryContext,
    beta: [f64; 3],
    lim: &Limits,
) -> bool {
    if !beta.iter().all(|&b| b >= 0.0) {
        return false;
    }
    let s = Setup::new(grids, model, ctx, beta, lim);
    if !(s.unilateral_ok && s.loaded) {
        return false;
    }
    (0..grids.len()).all(|k| {
        let x = s.sample(grids, k);
        s.force.holds(x.f2)
            && (!x.active || s.friction_ok(&x))
            && s.chi_min.holds_above(x.d2)
            && s.chi_max.holds(x.d2)
    })
}

/// The exact check at the re-solved contact point (CORRECTIONS Issue 4 item 7, §8.3).
///
/// `u* = contact_point_with(moments, β, ctx, h_des)`, then [`exact`] with
/// `x_cp = (u*, −z_TD)`. Returns the verdict and `u*` (m); when `u*` is undetermined
/// (`I_v` ~ 0, see [`SINGULAR_REL`]) the check runs at `ctx.cp` and `u*` is `None`.
pub fn exact_at_contact_point(
    grids: &SampledGrids,
    model: &ForceModel,
    moments: &ImpulseMoments,
    ctx: &QueryContext,
    beta: [f64; 3],
    h_des: [f64; 3],
    lim: &Limits,
) -> (Verdict, Option<[f64; 2]>) {
    let u = contact_point_with(moments, beta, ctx, h_des);
    let at = QueryContext {
        cp: u.unwrap_or(ctx.cp),
        ..*ctx
    };
    (exact(grids, model, &at, beta, lim), u)
}

/// `(∫₀¹ τ f_b dτ, ∫₀¹ τ² f_b dτ)` for whole- and half-cycle harmonics and the polynomial
/// part, N.
fn tau_moments(model: &ForceModel, axis: usize) -> (f64, f64) {
    let d = dc_term(model, axis);
    let (mut t1, mut t2) = (d / 2.0, d / 3.0);
    if let Some(ax) = model.axes.get(axis) {
        t1 += basis::poly_moment(&ax.poly, 1);
        t2 += basis::poly_moment(&ax.poly, 2);
    }
    for (j, c, phi) in harmonic_terms(model, axis) {
        if j.fract() == 0.0 {
            // Integer harmonics (spec §5): ∫τ cos = sin φ/Ω, ∫τ² cos = sin φ/Ω + 2 cos φ/Ω².
            let omega = basis::omega_of(j);
            let (sin_phi, cos_phi) = phi.sin_cos();
            let m1 = sin_phi / omega;
            t1 += c * m1;
            t2 += c * (m1 + 2.0 * cos_phi / (omega * omega));
        } else {
            let m = basis::harmonic_power_moments(j, phi, 2);
            t1 += c * m[1];
            t2 += c * m[2];
        }
    }
    (t1, t2)
}

/// Per-stance, context-free moments behind the contact point (§8.2–8.3).
///
/// ```text
/// Q_ab = ∫₀¹ S_a f_b dτ (m·N),  T1_b = ∫₀¹ τ f_b dτ,  T2_b = ∫₀¹ τ² f_b dτ (N),  I¹ = m J (N·s)
/// ```
///
/// Built once per stance (a few `sin_cos` per harmonic); [`contact_point_with`] then solves
/// each query in O(1) without trigonometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpulseMoments {
    /// `Q_ab = ∫ S_a f_b dτ`, rows `a`, columns `b` (h, p, v), m·N.
    pub q: [[f64; 3]; 3],
    /// `T1_b = ∫ τ f_b dτ`, N.
    pub t1: [f64; 3],
    /// `T2_b = ∫ τ² f_b dτ`, N.
    pub t2: [f64; 3],
    /// Linear impulse at β = 1, `m (J_h, J_p, J_v)`, N·s.
    pub impulse: [f64; 3],
    /// Stance duration `Δt`, s.
    pub dt_s: f64,
}

impl ImpulseMoments {
    /// The moments of `model` (closed form, exact for integer harmonics).
    pub fn new(model: &ForceModel) -> Self {
        let dt = model.dt_s;
        let moments = [0, 1, 2].map(|b| tau_moments(model, b));
        let (t1, t2) = (moments.map(|m| m.0), moments.map(|m| m.1));
        // With vs = vps = t_TD = 0 the free motion is ℓ2_a τ² only.
        let still = StanceContext::default();
        let l2 = [0.0, 0.0, -0.5 * GRAVITY * dt * dt];
        let q = [0, 1, 2]
            .map(|a| [0, 1, 2].map(|b| moment_integral(model, &still, a, b) - l2[a] * t2[b]));
        Self {
            q,
            t1,
            t2,
            impulse: linear_impulse(model),
            dt_s: dt,
        }
    }
}

/// `H(u) = A u + b` of the scaled stance (§8.2): `(A, b)`, rows (h, p, v), N·s and N·m·s.
///
/// `ctx.cp` is ignored (`u` is the unknown). O(1), no trigonometry.
pub fn impulse_affine(
    moments: &ImpulseMoments,
    beta: [f64; 3],
    ctx: &QueryContext,
) -> ([[f64; 2]; 3], [f64; 3]) {
    let dt = moments.dt_s;
    let l1 = [ctx.vs * dt, ctx.vps * dt, -GRAVITY * ctx.t_td * dt];
    let l2 = [0.0, 0.0, -0.5 * GRAVITY * dt * dt];
    let r = |a: usize, b: usize| {
        l1[a] * moments.t1[b] + l2[a] * moments.t2[b] + beta[a] * moments.q[a][b]
    };
    let [bh, bp, bv] = beta;
    let h0 = [
        dt * (bv * r(1, 2) - bp * r(2, 1)),
        dt * (bh * r(2, 0) - bv * r(0, 2)),
        dt * (bp * r(0, 1) - bh * r(1, 0)),
    ];
    let imp = [0, 1, 2].map(|a| beta[a] * moments.impulse[a]);
    // (0, 0, −z_TD) × I = (z_TD I_p, −z_TD I_h, 0).
    let moment = [ctx.z_td * imp[1], -ctx.z_td * imp[0], 0.0];
    let b = [0, 1, 2].map(|a| moment[a] - h0[a]);
    (contact_point_matrix(imp), b)
}

/// Closed-form contact point for the scaled stance (§8.3), `W = I`, m.
///
/// ```text
/// u* = (AᵀA)⁻¹ Aᵀ (H_des − b)      det(AᵀA) = I_v² |I|²
/// ```
///
/// `ctx.cp` is ignored; builds the stance's [`ImpulseMoments`] (reuse them across queries
/// with [`contact_point_with`]). The default `h_des` is the stance's original `H`
/// (`Coefficients::ang_impulse`, N·m·s). `None` when `I_v` is ~0 relative to `|I|`
/// ([`SINGULAR_REL`]) or any input is non-finite.
pub fn contact_point(
    model: &ForceModel,
    beta: [f64; 3],
    ctx: &QueryContext,
    h_des: [f64; 3],
) -> Option<[f64; 2]> {
    contact_point_with(&ImpulseMoments::new(model), beta, ctx, h_des)
}

/// [`contact_point`] from the stance's precomputed [`ImpulseMoments`]: O(1), no trig, m.
pub fn contact_point_with(
    moments: &ImpulseMoments,
    beta: [f64; 3],
    ctx: &QueryContext,
    h_des: [f64; 3],
) -> Option<[f64; 2]> {
    let (a, b) = impulse_affine(moments, beta, ctx);
    let rhs = [0, 1, 2].map(|k| h_des[k] - b[k]);
    let (mut n, mut g) = ([[0.0f64; 2]; 2], [0.0f64; 2]);
    for (row, &y) in a.iter().zip(&rhs) {
        for i in 0..2 {
            g[i] += row[i] * y;
            for j in 0..2 {
                n[i][j] += row[i] * row[j];
            }
        }
    }
    let det = n[0][0] * n[1][1] - n[0][1] * n[1][0];
    let trace = n[0][0] + n[1][1];
    if !(det.is_finite() && det > SINGULAR_REL * trace * trace) {
        return None;
    }
    let u = [
        (n[1][1] * g[0] - n[0][1] * g[1]) / det,
        (n[0][0] * g[1] - n[1][0] * g[0]) / det,
    ];
    u.iter().all(|x| x.is_finite()).then_some(u)
}

/// §7.5 relative limits from a stance's original extremes (`≤` comparisons, 1.05 margins).
///
/// ```text
/// μ = 1.05 μ_req,  F_max = 1.05 F_peak,  χ_max = 1.05 ext_max,  χ_min = ext_min / 1.05
/// ```
pub fn relative_limits(coef: &Coefficients) -> Limits {
    Limits {
        mu: RELATIVE_MARGIN * coef.mu_req,
        f_max: RELATIVE_MARGIN * coef.f_peak,
        chi_min: coef.ext_min / RELATIVE_MARGIN,
        chi_max: RELATIVE_MARGIN * coef.ext_max,
    }
}

#[cfg(test)]
mod tests;
