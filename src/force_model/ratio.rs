//! The friction-ratio stance force model, the library's default (a departure from the paper).
//!
//! # Model
//! ```text
//! f_v(τ) = Σ_{i=0..d} b_i B_i^d(τ),   B_i^d(τ) = C(d,i) τ^i (1−τ)^(d−i),   b_i ≥ 0      N
//! f_h(τ) = f_v(τ) · q_h(τ),   q_h(τ) = Σ_{k ≤ d_h} r_hk τ^k                              N
//! f_p(τ) = f_v(τ) · q_p(τ),   q_p(τ) = Σ_{k ≤ d_p} r_pk τ^k                              N
//! d = clamp(n_st − 3, MIN_VERTICAL_DEGREE, vertical_degree)
//! fit on τ_j = j/(N−1), j = 0 … N−1 (both stance edges sampled):
//!   b   = argmin_{b ≥ 0} Σ_j (f_v(τ_j) − s_vj)²           (non-negative least squares)
//!   r_a = argmin Σ_j (f_v(τ_j) q_a(τ_j) − s_aj)² / (f_v(τ_j) + ε)   (weighted least squares,
//!         a = h, p; ε = RATIO_WEIGHT_FLOOR · max f_v)
//! ```
//! `s_aj` are the stance-axis samples of `m (a(t) − g⃗)` that Stage A also uses.
//!
//! With edge targets ([`EdgeTargets`], from the flights beside the stance) the impulse
//! `∫₀¹ f_a dτ` of every axis and the vertical position `∫₀¹∫₀ˢ f_v` are met exactly
//! (equality rows; the position falls back to the impulse alone, and that to none, where
//! `f_v ≥ 0` cannot meet them):
//! ```text
//! min_{b ≥ 0} ‖B b − s_v‖²   s.t.   Σ_i b_i/(d+1) = I_v,   Σ_i b_i (d+1−i)/((d+1)(d+2)) = T_2
//! ```
//!
//! **Edge position** (issue 39 item 2): the vertical position is an exact row, like the
//! impulse, where the flights beside the stance give trustworthy edge states; the soft fit
//! it replaced followed the smoothed acceleration, whose smear across the stance edges put
//! the liftoff a median 13 mm below the next flight (the measurements, and the plate clock
//! they are scored on: `docs/decisions.md`, "Exact edge positions").
//!
//! The position is exact only where the edge states are trustworthy: beside a flight whose
//! own free curvature `a_z` is more than 3 m/s² from −g it stays the soft row above with
//! [`POSITION_TOLERANCE_M`] (1 mm; [`EdgeTargets::position_tolerance_m`], chosen by the
//! stance builder, `stances::assemble::EXACT_POSITION_MAX_CURVATURE_MISS_MPS2`):
//! ```text
//! exact  ⇔  every flight giving an edge state is untested or |a_z + g| ≤ 3 m/s²
//! soft:  min_{b ≥ 0} ‖B b − s_v‖² + w² (e_2·b − T_2)²   s.t.  Σ_i b_i/(d+1) = I_v,
//!        w = r₀/σ,  σ = m · POSITION_TOLERANCE_M / Δt²   (N; r₀: RMS residual of the
//!        impulse-only fit, N; m kg, Δt s)
//! ```
//! (Why the fallback: `docs/decisions.md`, "Exact edge positions".)
//!
//! **Travel targets** (a departure): with edge targets the ratios `q_h`, `q_p`
//! also get a soft row for the stance's travel along their axis, with tolerance
//! [`TRAVEL_TOLERANCE_M`]:
//! ```text
//! ∫₀¹∫₀ˢ f_v q_a = m (Δp_a − v_a,TD Δt)/Δt²,   w = r₀ / σ,   σ = m · TRAVEL_TOLERANCE_M / Δt²
//! ```
//! (`r₀`: RMS of the impulse-constrained fit's load-weighted residual, √N, the unit of the
//! weighted data rows; missing the target by `σ` costs `r₀²`, one sample's typical misfit;
//! `∫₀¹∫₀ˢ f_v τ^k = M_k − M_{k+1}`, `M_k = ∫₀¹ τ^k f_v`.)
//! The tolerance was chosen on the plate run's friction and the real forward jumps' round
//! trip (`docs/decisions.md`, "Travel targets").
//!
//! Why: the paper's truncated periodic Fourier series rings at the stance edges, where
//! `f_v` is small, so the friction ratio `|f_t|/f_v` (and with it `μ_req`, eq 7) was 3–4×
//! the force plates' on real runs. Here `f_v ≥ 0` everywhere (non-negative Bernstein
//! coefficients), the series is not periodic, and the ratio `|f_t|/f_v = hypot(q_h, q_p)`
//! is a low-order polynomial: smooth and bounded at the edges, fitted where `f_v` is large
//! (the residual of the ratio `q − s/f_v` is weighted by the load `f_v + ε`: each sample
//! counts by how much of the stance's weight it carries, so the push-off and braking edges,
//! where friction is decided, are not drowned by mid-stance). Under scaling by `β` the ratio is
//! `hypot(β_h q_h, β_p q_p)/β_v`, so the friction filter of eq 12 is exact.
//!
//! # Degrees
//! Chosen on the 60 Hz treadmill run with force plates (29 single-foot stances, |μ_req −
//! plate μ_req| at the 5 % active set, median / 90th percentile; `cargo test --test
//! integration stance_friction_demand -- --nocapture`):
//!
//! | `q_h` | `q_p` | median | p90 | stances ≤ 0.7 (plates 93 %) |
//! |---|---|---|---|---|
//! | 1 | 0 | 0.130 | 0.328 | 100 % |
//! | 1 | 1 | 0.120 | 0.319 | 100 % |
//! | **1** | **2** | **0.096** | **0.260** | **100 %** |
//! | 1 | 3 | 0.121 | 0.276 | 90 % |
//! | 2 | 1 | 0.239 | 0.416 | 34 % |
//! | 3 | 1 | 0.512 | 0.937 | 24 % |
//!
//! The plate's maximum ratio lies at push-off (τ ≈ 0.93) on 28 of the 29 stances, where the
//! kinematic fore-aft force is least accurate: a curved `q_h` follows that error and
//! overshoots, a linear one stays ≈ 0.1–0.3 below the plate. The medio-lateral ratio is
//! small mid-stance and grows at both edges (up to 0.23 on the plates), which a line cannot
//! follow and a parabola can; the vertical force, the impulses and the queries' 20 % active
//! set barely move (median |Δμ20| 0.041 → 0.046).
//!
//! Every axis is a polynomial in τ, stored in the power basis ([`AxisModel::poly`]), so
//! `J`, `K`, `P`, `S(τ)` and every moment the queries use stay closed form.
//!
//! # Frames and units
//! Stance frame `h, p, v`; forces in N, `τ` unit-free, `q` unit-free.

use nalgebra::{DMatrix, DVector};

use super::{AxisModel, ForceModel};
use crate::{Error, Result};

/// Default largest Bernstein degree `d` of `f_v` (fit option `vertical_degree`).
pub const DEFAULT_VERTICAL_DEGREE: usize = 8;
/// Smallest degree of `f_v` (a bell needs 2).
pub const MIN_VERTICAL_DEGREE: usize = 2;
/// Largest accepted `vertical_degree`: the power-basis coefficients of a degree-d
/// Bernstein polynomial grow like 2^d C(d, d/2); at 16 that keeps them below 1e9 × the
/// force, so evaluation stays accurate to ~1e-6 N.
pub const MAX_VERTICAL_DEGREE: usize = 16;
/// Default degree of the heading ratio `q_h` (fit option `ratio_degree_h`): linear. Chosen
/// on the plate run (median / 90th percentile of |μ_req − plate| at the 5 % active set,
/// with `q_p` quadratic): higher degrees follow the kinematic force's push-off error and
/// overshoot at the edge (module docs, "Degrees").
pub const DEFAULT_RATIO_DEGREE_H: usize = 1;
/// Default degree of the perpendicular ratio `q_p` (fit option `ratio_degree_p`):
/// quadratic, so that the medio-lateral ratio can rise at both edges (module docs,
/// "Degrees").
pub const DEFAULT_RATIO_DEGREE_P: usize = 2;
/// Largest accepted ratio degree.
pub const MAX_RATIO_DEGREE: usize = 6;
/// Position tolerance of the soft target `∫₀¹∫₀ˢ f_v = T_2`, m, used where the edge states
/// are not trusted to the millimetre ([`EdgeTargets::position_tolerance_m`]; module docs,
/// "Edge position"): missing the target by this much costs as much as one sample's typical
/// misfit.
pub const POSITION_TOLERANCE_M: f64 = 0.001;
/// Travel tolerance of the soft targets `∫₀¹∫₀ˢ f_a = T_a` of the travel axes (h, p), m
/// (module docs, "Travel targets": chosen on the plate run and the jumps' round trip).
pub const TRAVEL_TOLERANCE_M: f64 = 0.02;
/// Floor `ε` of the ratio fit's load weight, as a fraction of the stance's peak `f_v`: the
/// weights `1/(f_v + ε)` stay bounded where `f_v → 0`. Chosen on the plate run with the
/// weight exponent: force residuals unweighted (the earlier fit) gave a median
/// |μ_req − plate| of 0.167 at the 5 % active set; load-weighted ratio residuals 0.120
/// (ε 5 %), 0.109 (ε 2 %), both with a linear `q_p` (90th percentile 0.32). With the
/// quadratic `q_p` the choice matters little: ε 2 / 5 / 10 % and weight exponents 0.75–1.25
/// give medians 0.08–0.12 and 90th percentiles 0.252–0.268.
pub const RATIO_WEIGHT_FLOOR: f64 = 0.05;
/// Relative singular-value cut-off of the ratio least squares (a stance whose `f_v` is
/// zero on most samples has no defined ratio there; the minimum-norm solution is taken).
const RATIO_SVD_EPS: f64 = 1e-12;
/// Ridge added to the NNLS normal matrix, relative to its mean diagonal, so that it is
/// strictly positive definite (the Bernstein basis on ≥ d+1 distinct samples already is).
const NNLS_RIDGE_REL: f64 = 1e-12;

/// The ratio-model knobs (pipeline `[fit]`); see the `DEFAULT_*` constants.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct RatioOptions {
    /// Largest Bernstein degree of `f_v`; default [`DEFAULT_VERTICAL_DEGREE`].
    pub vertical_degree: usize,
    /// Degree of `q_h`; default [`DEFAULT_RATIO_DEGREE_H`].
    pub ratio_degree_h: usize,
    /// Degree of `q_p`; default [`DEFAULT_RATIO_DEGREE_P`].
    pub ratio_degree_p: usize,
    /// Weight `λ ∈ [0, 1]` of the leg line in the ratio data ([`super::leg_line`]); default
    /// [`super::leg_line::DEFAULT_LEG_LINE_WEIGHT`].
    pub leg_line_weight: f64,
    /// Roll fraction `φ ∈ [0, 1]` of the leg line's support point; default
    /// [`super::leg_line::DEFAULT_ROLL_FRACTION`].
    pub roll_fraction: f64,
}

impl Default for RatioOptions {
    fn default() -> Self {
        RatioOptions {
            vertical_degree: DEFAULT_VERTICAL_DEGREE,
            ratio_degree_h: DEFAULT_RATIO_DEGREE_H,
            ratio_degree_p: DEFAULT_RATIO_DEGREE_P,
            leg_line_weight: super::leg_line::DEFAULT_LEG_LINE_WEIGHT,
            roll_fraction: super::leg_line::DEFAULT_ROLL_FRACTION,
        }
    }
}

impl RatioOptions {
    /// Checks the degrees against their bounds.
    ///
    /// # Errors
    /// A config error naming the option.
    pub fn check(&self) -> Result<()> {
        let bad = |what: &str, v: usize, lo: usize, hi: usize| {
            Err(Error::config(
                None,
                None,
                format!("fit.{what} = {v} is not in [{lo}, {hi}]"),
            ))
        };
        if !(MIN_VERTICAL_DEGREE..=MAX_VERTICAL_DEGREE).contains(&self.vertical_degree) {
            return bad(
                "vertical_degree",
                self.vertical_degree,
                MIN_VERTICAL_DEGREE,
                MAX_VERTICAL_DEGREE,
            );
        }
        for (name, d) in [
            ("ratio_degree_h", self.ratio_degree_h),
            ("ratio_degree_p", self.ratio_degree_p),
        ] {
            if d > MAX_RATIO_DEGREE {
                return bad(name, d, 0, MAX_RATIO_DEGREE);
            }
        }
        for (name, v) in [
            ("leg_line_weight", self.leg_line_weight),
            ("roll_fraction", self.roll_fraction),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::config(
                    None,
                    None,
                    format!("fit.{name} = {v} is not in [0, 1]"),
                ));
            }
        }
        Ok(())
    }
}

/// What the force must integrate to so that the stance joins its edge states exactly
/// (from the adjacent flights' ballistic fits): `∫₀¹ f_a dτ = impulse[a]` (N) and
/// `∫₀¹∫₀ˢ f_v = vertical_double` (N).
///
/// ```text
/// impulse_a = m (Δv_a + g Δt δ_av)/Δt,   vertical_double = m (Δz − v_z,TD Δt + ½ g Δt²)/Δt²
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeTargets {
    /// `∫₀¹ f_a dτ` per stance axis (h, p, v), N.
    pub impulse: [f64; 3],
    /// `∫₀¹∫₀ˢ f_v`, N.
    pub vertical_double: f64,
    /// `∫₀¹∫₀ˢ f_a` for the stance's travel axes (h, p), N:
    /// `m (Δp_a − v_a,TD Δt)/Δt²`.
    pub travel_double: [f64; 2],
    /// How the vertical position `vertical_double` is held: `None` exactly (an equality
    /// row, like the impulses), `Some(tol_m)` softly with tolerance `tol_m`, m (the stance
    /// builder passes [`POSITION_TOLERANCE_M`] beside a flight whose own curvature is far
    /// from −g; module docs, "Edge position").
    pub position_tolerance_m: Option<f64>,
}

/// A fitted ratio model: the force model and the ratio polynomials.
#[derive(Debug, Clone, PartialEq)]
pub struct RatioFit {
    /// The stance force model (polynomial parts only).
    pub model: ForceModel,
    /// `q_h`, `q_p` in the power basis (unit-free).
    pub ratio: [Vec<f64>; 2],
    /// Non-negative Bernstein coefficients `b_i` of `f_v` (N).
    pub bernstein_v: Vec<f64>,
    /// How many of the vertical edge targets were applied (2: the impulse exactly and the
    /// position, exactly or softly as [`EdgeTargets::position_tolerance_m`] says, 1: the
    /// impulse only, 0: none: `f_v ≥ 0` cannot meet them).
    pub vertical_targets_met: usize,
}

/// The degree of `f_v` for a stance of `n_st` frames: `clamp(n_st − 3, 2, max)`.
pub fn vertical_degree(n_st: usize, max_degree: usize) -> usize {
    n_st.saturating_sub(3)
        .clamp(MIN_VERTICAL_DEGREE, max_degree.max(MIN_VERTICAL_DEGREE))
}

/// `C(n, k)` as f64 (exact for the small n used here).
fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// `B_i^d(τ)` for i = 0 … d.
fn bernstein_row(d: usize, tau: f64) -> Vec<f64> {
    (0..=d)
        .map(|i| binomial(d, i) * tau.powi(i as i32) * (1.0 - tau).powi((d - i) as i32))
        .collect()
}

/// The `N × (d+1)` Bernstein design matrix `B[j][i] = B_i^d(τ_j)`, one row per sample
/// (each row computed once: building it entry by entry recomputed the whole row per entry,
/// 37 % of the fit's time).
fn bernstein_basis(d: usize, tau: &[f64]) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(tau.len(), d + 1);
    for (j, &t) in tau.iter().enumerate() {
        for (i, b) in bernstein_row(d, t).into_iter().enumerate() {
            m[(j, i)] = b;
        }
    }
    m
}

/// Power-basis coefficients of `Σ_i b_i B_i^d(τ)`:
/// `p_k = Σ_{i ≤ k} b_i C(d,i) C(d−i, k−i) (−1)^(k−i)`.
pub fn bernstein_to_power(b: &[f64]) -> Vec<f64> {
    let Some(d) = b.len().checked_sub(1) else {
        return Vec::new();
    };
    (0..=d)
        .map(|k| {
            (0..=k)
                .map(|i| {
                    let sign = if (k - i) % 2 == 0 { 1.0 } else { -1.0 };
                    b[i] * binomial(d, i) * binomial(d - i, k - i) * sign
                })
                .sum()
        })
        .collect()
}

/// `min ½ xᵀQx + cᵀx` s.t. the first `meq` rows of `a x = b`, the rest `a x ≤ b` (quadprog,
/// Goldfarb–Idnani); `q` gets a relative ridge so that it is strictly positive definite.
pub(super) fn qp(
    q: &DMatrix<f64>,
    c: &[f64],
    a: &[f64],
    b: &[f64],
    meq: usize,
) -> Option<Vec<f64>> {
    let n = q.ncols();
    let ridge = NNLS_RIDGE_REL * (0..n).map(|i| q[(i, i)]).sum::<f64>() / n as f64;
    let mut qm: Vec<f64> = (0..n * n)
        .map(|k| q[(k / n, k % n)] + if k / n == k % n { ridge } else { 0.0 })
        .collect();
    quadprog::solve_qp(&mut qm, c, a, b, meq, false)
        .ok()
        .map(|s| s.sol)
        .filter(|x| x.iter().all(|v| v.is_finite()))
}

/// `argmin ‖X x − s‖²` under the equality rows `eq` (`e·x = target`) and the inequality
/// rows `le` (`row·x ≤ 0`), by [`qp`]. Tries all equality rows, then drops them from the
/// last, down to none; returns `x` and how many equality rows held.
///
/// # Errors
/// A numeric error naming `what` when even the inequalities alone fail.
pub(super) fn constrained_lsq(
    x: &DMatrix<f64>,
    s: &[f64],
    eq: &[(Vec<f64>, f64)],
    le: &[Vec<f64>],
    what: &str,
) -> Result<(Vec<f64>, usize)> {
    let gram = x.transpose() * x;
    let c: Vec<f64> = (x.transpose() * DVector::from_column_slice(s))
        .iter()
        .map(|v| -v)
        .collect();
    for k in (0..=eq.len()).rev() {
        let mut a: Vec<f64> = eq[..k].iter().flat_map(|(row, _)| row.clone()).collect();
        let mut b: Vec<f64> = eq[..k].iter().map(|(_, t)| *t).collect();
        a.extend(le.iter().flatten());
        b.extend(le.iter().map(|_| 0.0));
        if let Some(sol) = qp(&gram, &c, &a, &b, k) {
            return Ok((sol, k));
        }
    }
    Err(Error::numeric(format!(
        "{what}: the non-negative fit of f_v failed"
    )))
}

/// Non-negative least squares `argmin_{b ≥ 0} ‖B b − s‖²` under the equality rows `eq`
/// ([`constrained_lsq`] with the rows `−b_i ≤ 0`).
fn nnls(basis: &DMatrix<f64>, s: &[f64], eq: &[(Vec<f64>, f64)]) -> Result<(Vec<f64>, usize)> {
    let n = basis.ncols();
    let le: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| if i == j { -1.0 } else { 0.0 }).collect())
        .collect();
    let (b, k) = constrained_lsq(basis, s, eq, &le, "ratio model")?;
    Ok((b.into_iter().map(|v| v.max(0.0)).collect(), k))
}

/// The vertical fit under edge targets: the impulse `∫₀¹ f_v = I_v` exact, the position
/// `∫₀¹∫₀ˢ f_v = T_2` exact or, with [`EdgeTargets::position_tolerance_m`], a soft row of
/// weight `w = r₀/σ`, `σ = m · tol_m / Δt²` (module docs, "Edge position"). Returns the
/// Bernstein coefficients and how many targets were applied (2; 1, the impulse only, or 0
/// when `f_v ≥ 0` cannot meet them).
fn vertical_fit(
    basis: &DMatrix<f64>,
    s: &[f64],
    t: &EdgeTargets,
    (mass_kg, dt_s): (f64, f64),
) -> Result<(Vec<f64>, usize)> {
    let d = basis.ncols() - 1;
    let df = d as f64;
    // ∫₀¹ B_i^d = 1/(d+1);  ∫₀¹∫₀ˢ B_i^d = ∫₀¹ (1−τ) B_i^d = (d+1−i)/((d+1)(d+2)).
    let double: Vec<f64> = (0..=d)
        .map(|i| (df + 1.0 - i as f64) / ((df + 1.0) * (df + 2.0)))
        .collect();
    let impulse = (vec![1.0 / (df + 1.0); d + 1], t.impulse[2]);
    let Some(tol_m) = t.position_tolerance_m else {
        return nnls(basis, s, &[impulse, (double, t.vertical_double)]);
    };
    let impulse = [impulse];
    let (b0, met) = nnls(basis, s, &impulse)?;
    if met == 0 {
        return Ok((b0, 0));
    }
    let sigma = mass_kg * tol_m / (dt_s * dt_s);
    let Some((rows, rhs)) = with_soft_row(basis, s, &b0, (&double, t.vertical_double, sigma))
    else {
        return Ok((b0, 1));
    };
    match nnls(&rows, &rhs, &impulse)? {
        (b, 1) => Ok((b, 2)),
        _ => Ok((b0, 1)),
    }
}

/// The least-squares rows `x`, `s` with the soft row `w·(row·c) = w·target` appended, `w =
/// r₀/σ` (`r₀`: RMS residual of the fit `c0` on the rows, in their unit; `σ`: the target's
/// tolerance in the row's unit), so that missing the target by `σ` costs one sample's
/// typical misfit (module docs). `None` where `w` is not finite and positive (a residual
/// of 0: nothing to weigh the target against).
pub(super) fn with_soft_row(
    x: &DMatrix<f64>,
    s: &[f64],
    c0: &[f64],
    (row, target, sigma): (&[f64], f64, f64),
) -> Option<(DMatrix<f64>, Vec<f64>)> {
    let n = x.nrows();
    let res = x * DVector::from_column_slice(c0) - DVector::from_column_slice(s);
    let w = (res.norm_squared() / n as f64).sqrt() / sigma;
    if !(w.is_finite() && w > 0.0) {
        return None;
    }
    let mut rows = x.clone().insert_row(n, 0.0);
    for (k, r) in row.iter().enumerate().take(x.ncols()) {
        rows[(n, k)] = w * r;
    }
    let mut rhs = s.to_vec();
    rhs.push(w * target);
    Some((rows, rhs))
}

/// Weighted least squares `argmin_r Σ_j (f_v(τ_j) q(τ_j) − s_j)² / (f_v(τ_j) + ε)`,
/// `q(τ) = Σ_{k ≤ deg} r_k φ_k(τ)` ([`RATIO_WEIGHT_FLOOR`]; `φ_k = τ^k` here, `cos(πkτ)` in
/// [`super::cosine`]), optionally with `∫₀¹ f_v q dτ = target` (`impulse.0[k] = ∫₀¹ φ_k f_v
/// dτ`) and the soft travel row (`travel.0[k] = ∫₀¹∫₀ˢ φ_k f_v`, target, tolerance).
pub(super) fn ratio_fit(
    fv: &[f64],
    tau: &[f64],
    s: &[f64],
    (deg, phi): (usize, &dyn Fn(usize, f64) -> f64),
    impulse: Option<(&[f64], f64)>,
    travel: Option<(&[f64], f64, f64)>,
) -> Vec<f64> {
    let eps = RATIO_WEIGHT_FLOOR * fv.iter().copied().fold(0.0f64, f64::max);
    let w: Vec<f64> = fv
        .iter()
        .map(|&v| 1.0 / (v.max(0.0) + eps).sqrt())
        .collect();
    let x = DMatrix::from_fn(tau.len(), deg + 1, |j, k| w[j] * fv[j] * phi(k, tau[j]));
    let weighted: Vec<f64> = s.iter().zip(&w).map(|(v, w)| v * w).collect();
    let s = weighted.as_slice();
    if let Some((m, target)) = impulse {
        let solve = |x: &DMatrix<f64>, s: &[f64]| {
            let q = x.transpose() * x;
            let c: Vec<f64> = (x.transpose() * DVector::from_column_slice(s))
                .iter()
                .map(|v| -v)
                .collect();
            qp(&q, &c, &m[..=deg], &[target], 1)
        };
        if let Some(r) = solve(&x, s) {
            let Some((row, t2, sigma)) = travel else {
                return r;
            };
            return match with_soft_row(&x, s, &r, (row, t2, sigma)) {
                Some((xa, sa)) => solve(&xa, &sa).unwrap_or(r),
                None => r,
            };
        }
    }
    let Some(svd) = crate::math::svd::svd(x, true, true) else {
        return vec![0.0; deg + 1];
    };
    let cut = RATIO_SVD_EPS * svd.singular_values.max();
    match svd.solve(&DVector::from_column_slice(s), cut) {
        Ok(r) if r.iter().all(|v| v.is_finite()) => r.iter().copied().collect(),
        _ => vec![0.0; deg + 1],
    }
}

/// RMS of `samples − model(τ)` over the fit grid (N).
pub(super) fn rms(axis: &AxisModel, tau: &[f64], samples: &[f64]) -> f64 {
    let ss: f64 = tau
        .iter()
        .zip(samples)
        .map(|(&t, &s)| (s - axis.eval(t)).powi(2))
        .sum();
    (ss / tau.len().max(1) as f64).sqrt()
}

/// Fits the ratio model to stance-axis force samples on `τ_j = j/(N−1)` (no leg line:
/// [`fit_ratio_with`]).
///
/// # Errors
/// See [`fit_ratio_with`].
pub fn fit_ratio(
    samples: &[Vec<f64>; 3],
    n_st: usize,
    mass_kg: f64,
    dt_s: f64,
    targets: Option<&EdgeTargets>,
    opts: &RatioOptions,
) -> Result<RatioFit> {
    fit_ratio_with(samples, n_st, mass_kg, dt_s, targets, None, opts)
}

/// The ratio data `s'_a = (1 − λ) s_a + λ f_v g_a` of the leg line ([`super::leg_line`]),
/// a = h, p; the kinematic samples where there is no leg line or `λ = 0`.
pub(super) fn ratio_data(
    samples: &[Vec<f64>; 3],
    fv: &[f64],
    leg: Option<&[Vec<f64>; 2]>,
    lambda: f64,
) -> [Vec<f64>; 2] {
    std::array::from_fn(
        |a| match leg.filter(|g| lambda > 0.0 && g[a].len() == fv.len()) {
            Some(g) => samples[a]
                .iter()
                .zip(fv.iter().zip(&g[a]))
                .map(|(s, (f, g))| (1.0 - lambda) * s + lambda * f * g)
                .collect(),
            None => samples[a].clone(),
        },
    )
}

/// The number of force samples per axis, the same on all three and at least 2.
///
/// # Errors
/// A config error naming the `model` (`ratio`, `fourier`) otherwise.
pub(crate) fn sample_count(samples: &[Vec<f64>; 3], model: &str) -> Result<usize> {
    let n = samples[2].len();
    if n < 2 || samples.iter().any(|s| s.len() != n) {
        return Err(Error::config(
            None,
            None,
            format!("{model} model: need ≥ 2 samples per axis, got {n}"),
        ));
    }
    Ok(n)
}

/// Fits the ratio model to stance-axis force samples on `τ_j = j/(N−1)`.
///
/// # Arguments
/// * `samples`: `s_aj` per stance axis (h, p, v), N, all of length `N ≥ 2`;
/// * `n_st`: stance frames (sets the degree of `f_v`); `mass_kg`, `dt_s`: for the model;
/// * `leg`: the leg line's slopes `g_h`, `g_p` on the same grid ([`super::leg_line`]),
///   mixed into the ratio data with weight `opts.leg_line_weight`.
///
/// # Errors
/// A config error for bad options or sample lengths; a numeric error when the QP fails.
pub fn fit_ratio_with(
    samples: &[Vec<f64>; 3],
    n_st: usize,
    mass_kg: f64,
    dt_s: f64,
    targets: Option<&EdgeTargets>,
    leg: Option<&[Vec<f64>; 2]>,
    opts: &RatioOptions,
) -> Result<RatioFit> {
    opts.check()?;
    let n = sample_count(samples, "ratio")?;
    let tau = sample_grid(n);
    let d = vertical_degree(n_st, opts.vertical_degree).min(n - 1);
    let basis = bernstein_basis(d, &tau);
    let (b, met) = match targets {
        Some(t) => vertical_fit(&basis, &samples[2], t, (mass_kg, dt_s))?,
        None => nnls(&basis, &samples[2], &[])?,
    };
    let fv_poly = bernstein_to_power(&b);
    let fv: Vec<f64> = (basis.clone() * DVector::from_column_slice(&b))
        .iter()
        .copied()
        .collect();
    let deg_max = opts.ratio_degree_h.max(opts.ratio_degree_p);
    let moments: Vec<f64> = (0..=deg_max + 1)
        .map(|k| super::basis::poly_moment(&fv_poly, k))
        .collect();
    // ∫₀¹∫₀ˢ f_v τ^k = ∫₀¹ (1 − τ) τ^k f_v = M_k − M_{k+1}.
    let double: Vec<f64> = (0..=deg_max).map(|k| moments[k] - moments[k + 1]).collect();
    let sigma = mass_kg * TRAVEL_TOLERANCE_M / (dt_s * dt_s);
    let imp = |a: usize| targets.map(|t| (moments.as_slice(), t.impulse[a]));
    let travel = |a: usize| targets.map(|t| (double.as_slice(), t.travel_double[a], sigma));
    let data = ratio_data(samples, &fv, leg, opts.leg_line_weight);
    let power = |k: usize, t: f64| t.powi(k as i32);
    let q_h = ratio_fit(
        &fv,
        &tau,
        &data[0],
        (opts.ratio_degree_h, &power),
        imp(0),
        travel(0),
    );
    let q_p = ratio_fit(
        &fv,
        &tau,
        &data[1],
        (opts.ratio_degree_p, &power),
        imp(1),
        travel(1),
    );
    let axis = |poly: Vec<f64>, s: &[f64]| {
        let mut a = AxisModel {
            poly,
            ..Default::default()
        };
        a.fit_rms = rms(&a, &tau, s);
        a
    };
    let model = ForceModel {
        mass_kg,
        dt_s,
        axes: [
            axis(super::basis::poly_mul(&fv_poly, &q_h), &samples[0]),
            axis(super::basis::poly_mul(&fv_poly, &q_p), &samples[1]),
            axis(fv_poly, &samples[2]),
        ],
    };
    Ok(RatioFit {
        model,
        ratio: [q_h, q_p],
        bernstein_v: b,
        vertical_targets_met: met,
    })
}

/// The fit grid `τ_j = j/(N−1)`, `j = 0 … N−1` (both edges).
pub fn sample_grid(n: usize) -> Vec<f64> {
    let last = (n.max(2) - 1) as f64;
    (0..n).map(|j| j as f64 / last).collect()
}

#[cfg(test)]
mod tests;

/// Samples of a bell `f_v = 2.5 m g sin²(πτ)` on [`sample_grid`]`(n)` with a known ratio
/// `q_h = −0.4 + 0.9 τ` and `q_p = 0.05`, as `[f_h, f_p, f_v]` (N); tests only.
#[cfg(test)]
pub(crate) fn bell_samples(n: usize, mass: f64) -> [Vec<f64>; 3] {
    let tau = sample_grid(n);
    let fv: Vec<f64> = tau
        .iter()
        .map(|t| 2.5 * mass * 9.81 * (std::f64::consts::PI * t).sin().powi(2))
        .collect();
    let fh = fv
        .iter()
        .zip(&tau)
        .map(|(f, t)| f * (-0.4 + 0.9 * t))
        .collect();
    let fp = fv.iter().map(|f| 0.05 * f).collect();
    [fh, fp, fv]
}
