//! Stage B (spec stance-model §4.2): least-squares refit of the touchdown state and the
//! world-axis force coefficients on the raw COM positions of one fit window.
//!
//! # Model
//! ```text
//! s = t − t_TD (s),   τ = s/Δt,   Ω_j = 2πj (rad per unit τ),   g_d = −g for z, 0 for x, y
//! f_d(τ) = c0_d + Σ_{j∈J} (a_dj cos Ω_jτ + b_dj sin Ω_jτ)                    N, world axis d
//! p_d(t) = p_TD,d + v_TD,d s + ½ g_d s² + Σ_u θ_du G_u(s)                      m
//!   θ_d = (c0_d, a_dj, b_dj),  G_u(s) = 0                                        s ≤ 0
//!                                    = (Δt²/m) F2_u(τ)                           0 < s ≤ Δt
//!                                    = (Δt²/m) F2_u(1) + (Δt/m) F1_u(1) (s − Δt)  s > Δt
//! basis u:  DC  F1 = τ,               F2 = τ²/2
//!           cos F1 = sin(Ωτ)/Ω,       F2 = (1 − cos Ωτ)/Ω²
//!           sin F1 = (1 − cos Ωτ)/Ω,  F2 = τ/Ω − sin(Ωτ)/Ω²
//! One design matrix A (n samples × k unknowns) for the three axes, row i = sample i:
//!   columns (1, s, G_DC, G_cos j, G_sin j, …)      k = 3 + 2|J|   (free state)
//!   columns (G_DC, G_cos j, G_sin j, …)            k = 1 + 2|J|   (fixed p_TD, v_TD)
//!   B_id = c_id − ½ g_d s_i²   (− p_TD,d − v_TD,d s_i with the state fixed)       m
//!   D = diag(1/‖A_:,u‖),  A D = U Σ Vᵀ,  X = D V Σ⁺ Uᵀ B   (minimises ‖A X − B‖_F)
//!   condition = σ_max/σ_min of A D   (∞ when σ_min = 0, e.g. an all-zero column)
//!   pos_rms = √( (1/n) Σ_i |c_i − p(t_i)|² )                                  m, 3-D
//! ```
//! The reported condition is that of the column-equilibrated matrix `A D`: the raw
//! columns mix units (1, s, s²/m …) and their ratio would measure units, not
//! degeneracy. Equilibration is within √k of the best diagonal scaling (van der Sluis),
//! so a condition above [`MAX_CONDITION`] means the data cannot separate the unknowns.
//! `Σ⁺` drops singular values below `k·ε·σ_max` (pseudo-inverse), which only happens for
//! conditions above `1/(kε)` ≳ 3e13, well past the fallback limit.
//!
//! # Frames and units
//! World frame, Z up; times in seconds (clip time), positions in metres, forces in newtons
//! (applied force, so `f_z ≈ m g` on average), mass in kilograms. [`to_stance_model`]
//! rotates into the stance frame `h, p, v` with the rows `e_h, e_p, e_v` of `R_s` (§2).
//!
//! # References
//! Spec stance-model §4.2 (model, window, fallback at condition 1e10) and §4.3 (the
//! normative `c cos(Ωτ + φ)` form); Golub & Van Loan, *Matrix Computations* (4th ed.),
//! §5.5 (rank-deficient least squares by the SVD); van der Sluis, *Condition numbers and
//! equilibration of matrices*, Numer. Math. 14 (1969) (column equilibration).
//!
//! # Examples
//! ```
//! use stancelib::force_model::{fit_stage_b, StageBInput, GRAVITY};
//! // 70 kg, Δt = 0.2 s, a constant 800 N vertical push; 100 Hz samples with flights.
//! let (m, dt, t_td) = (70.0_f64, 0.2_f64, 0.5_f64);
//! let t: Vec<f64> = (40..81).map(|k| k as f64 / 100.0 + 0.001).collect();
//! let com: Vec<[f64; 3]> = t.iter().map(|&t| {
//!     let s = t - t_td;
//!     let push = if s <= 0.0 { 0.0 } else if s <= dt { 800.0 * s * s / (2.0 * m) }
//!                else { 800.0 * dt * dt / (2.0 * m) + 800.0 * dt / m * (s - dt) };
//!     [3.0 * s, 0.0, 1.0 - 0.5 * s - 0.5 * GRAVITY * s * s + push]
//! }).collect();
//! let inp = StageBInput { t: &t, com: &com, t_td, dt, mass_kg: m, harmonics: &[],
//!                         fixed_state: None };
//! let fit = fit_stage_b(&inp).unwrap();
//! assert!((fit.c0[2] - 800.0).abs() < 1e-6 && (fit.v_td[2] + 0.5).abs() < 1e-9);
//! assert!(fit.condition < 1e3 && fit.pos_rms_m < 1e-12);
//! ```

use std::f64::consts::FRAC_PI_2;

use nalgebra::{DMatrix, SVD};

use super::{basis, AxisModel, ForceModel, GRAVITY};
use crate::{Error, ErrorKind, Result};

/// Condition-number limit above which Stage B falls back to Stage A (spec: 1e10).
pub const MAX_CONDITION: f64 = 1e10;
/// Largest accepted harmonic set `|J|`: a guard against absurd allocations (Stage A keeps
/// at most `K_max = 6` terms per axis, so `|J| ≤ 18` with the defaults).
pub const MAX_HARMONICS: usize = 64;
/// Cap on the total implicit-shift iterations of the SVD (nalgebra counts them over all
/// singular values); generous for the ≤ 131 columns [`MAX_HARMONICS`] allows.
pub const SVD_MAX_ITERATIONS: usize = 100_000;
/// Convergence tolerance of the SVD iterations (nalgebra's own default, 5 ε).
pub const SVD_EPS: f64 = 5.0 * f64::EPSILON;

/// Inputs of [`fit_stage_b`]: the raw COM samples of one fit window (spec §4.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageBInput<'a> {
    /// Sample times (s, clip time), strictly increasing: the stance frames plus the
    /// adjacent flight frames.
    pub t: &'a [f64],
    /// Raw (unsmoothed) world COM `c_k` (m, Z up), one per entry of `t`.
    pub com: &'a [[f64; 3]],
    /// Touchdown time `t_TD` (s, same clock as `t`).
    pub t_td: f64,
    /// Stance duration `Δt = t_LO − t_TD` (s), > 0.
    pub dt: f64,
    /// Body mass `m` (kg), > 0.
    pub mass_kg: f64,
    /// The harmonic set `J` (each `j ≥ 1`, strictly ascending, at most
    /// [`MAX_HARMONICS`]); may be empty (DC only).
    pub harmonics: &'a [u32],
    /// `Some((p_TD, v_TD))` (m, m/s, world) when neither side has flight frames: the
    /// state is fixed and only the force coefficients are fitted.
    pub fixed_state: Option<([f64; 3], [f64; 3])>,
}

/// The Stage B fit: touchdown state and world-axis applied force
/// `f_d(τ) = c0_d + Σ_k (a[d][k] cos 2πj_kτ + b[d][k] sin 2πj_kτ)` (N), `j_k = harmonics[k]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StageBFit {
    /// Touchdown COM `p_TD` (m, world): fitted, or the fixed value.
    pub p_td: [f64; 3],
    /// Touchdown COM velocity `v_TD` (m/s, world): fitted, or the fixed value.
    pub v_td: [f64; 3],
    /// DC force per world axis x, y, z (N).
    pub c0: [f64; 3],
    /// Cosine coefficients `a[d][k]` of `harmonics[k]` (N).
    pub a: [Vec<f64>; 3],
    /// Sine coefficients `b[d][k]` of `harmonics[k]` (N).
    pub b: [Vec<f64>; 3],
    /// The harmonic set `J` (ascending).
    pub harmonics: Vec<u32>,
    /// `√((1/n) Σ_k |c_k − p(t_k)|²)` over the window (m, 3-D distance).
    pub pos_rms_m: f64,
    /// Condition number of the column-equilibrated design matrix (see the module docs);
    /// above [`MAX_CONDITION`] the caller falls back to Stage A.
    pub condition: f64,
}

impl StageBFit {
    /// The world applied force `f(τ)` (N) per axis x, y, z; missing coefficients count as 0.
    pub fn force_world(&self, tau: f64) -> [f64; 3] {
        std::array::from_fn(|d| {
            self.c0[d]
                + self
                    .harmonics
                    .iter()
                    .enumerate()
                    .map(|(k, &j)| {
                        let x = basis::omega_of(j) * tau;
                        let (a, b) = (coef(&self.a[d], k), coef(&self.b[d], k));
                        a * x.cos() + b * x.sin()
                    })
                    .sum::<f64>()
        })
    }
}

/// `v[k]`, or 0 when `v` is too short (hand-built fits).
fn coef(v: &[f64], k: usize) -> f64 {
    v.get(k).copied().unwrap_or(0.0)
}

/// The force columns `G_u(s)` (m per N) of one sample: DC, then (cos j, sin j) per `j`.
///
/// `out.len()` must be `1 + 2·harmonics.len()`. The sine term is `cos(Ωτ − π/2)` in
/// [`basis`]; `cos(−π/2) = 6e-17` leaks that fraction of the cosine integral, far below
/// the solve's roundoff.
fn force_columns(s: f64, dt: f64, mass_kg: f64, harmonics: &[u32], out: &mut [f64]) {
    if s <= 0.0 {
        out.fill(0.0);
        return;
    }
    let (k2, k1) = (dt * dt / mass_kg, dt / mass_kg);
    // G_u(s) from a basis term's F1, F2: stance, or the linear extension after liftoff.
    let col = |f1: &dyn Fn(f64) -> f64, f2: &dyn Fn(f64) -> f64| {
        if s <= dt {
            k2 * f2(s / dt)
        } else {
            k2 * f2(1.0) + k1 * f1(1.0) * (s - dt)
        }
    };
    out[0] = col(&|tau| tau, &|tau| 0.5 * tau * tau);
    for (pair, &j) in out[1..].chunks_exact_mut(2).zip(harmonics) {
        let om = basis::omega_of(j);
        pair[0] = col(&|tau| basis::f1(om, 0.0, tau), &|tau| {
            basis::f2(om, 0.0, tau)
        });
        pair[1] = col(&|tau| basis::f1(om, -FRAC_PI_2, tau), &|tau| {
            basis::f2(om, -FRAC_PI_2, tau)
        });
    }
}

/// `g_d`: the world gravity component (m/s²) of axis `d`.
fn gravity(d: usize) -> f64 {
    if d == 2 {
        -GRAVITY
    } else {
        0.0
    }
}

fn bad<T>(msg: String) -> Result<T> {
    Err(Error::config(None, None, format!("stage b: {msg}")))
}

fn check(inp: &StageBInput) -> Result<()> {
    if inp.com.len() != inp.t.len() {
        return Err(ErrorKind::Shape {
            name: "com",
            expected: inp.t.len(),
            found: inp.com.len(),
        }
        .into());
    }
    if !(inp.dt.is_finite() && inp.dt > 0.0) {
        return bad(format!("stance duration {} s is not positive", inp.dt));
    }
    if !(inp.mass_kg.is_finite() && inp.mass_kg > 0.0) {
        return bad(format!("body mass {} kg is not positive", inp.mass_kg));
    }
    if !inp.t_td.is_finite() {
        return bad(format!("touchdown time {} s is not finite", inp.t_td));
    }
    if let Some(i) = inp.t.iter().position(|t| !t.is_finite()) {
        return bad(format!("sample time {i} is not finite"));
    }
    if let Some(i) = inp.t.windows(2).position(|w| w[1] <= w[0]) {
        return bad(format!("sample times are not increasing at {}", i + 1));
    }
    if let Some(i) = inp
        .com
        .iter()
        .position(|c| c.iter().any(|v| !v.is_finite()))
    {
        return bad(format!("com sample {i} is not finite"));
    }
    if let Some((p, v)) = inp.fixed_state {
        if p.iter().chain(&v).any(|x| !x.is_finite()) {
            return bad("fixed touchdown state is not finite".into());
        }
    }
    let h = inp.harmonics;
    if h.len() > MAX_HARMONICS {
        return bad(format!("{} harmonics (at most {MAX_HARMONICS})", h.len()));
    }
    if h.first() == Some(&0) || h.windows(2).any(|w| w[1] <= w[0]) {
        return bad(format!(
            "harmonics {h:?} are not ≥ 1 and strictly ascending"
        ));
    }
    let unknowns = unknowns(inp);
    if inp.t.len() < unknowns {
        return bad(format!(
            "{} samples for {unknowns} unknowns per axis",
            inp.t.len()
        ));
    }
    Ok(())
}

/// Unknowns per axis: `3 + 2|J|`, or `1 + 2|J|` with the state fixed.
fn unknowns(inp: &StageBInput) -> usize {
    let state = if inp.fixed_state.is_some() { 0 } else { 2 };
    state + 1 + 2 * inp.harmonics.len()
}

/// The design matrix `A` (n × k, unscaled) and right-hand sides `B` (n × 3) of the
/// module docs, for checked inputs; `Err` when an entry overflows.
fn design(inp: &StageBInput) -> Result<(DMatrix<f64>, DMatrix<f64>)> {
    let (n, k) = (inp.t.len(), unknowns(inp));
    let n_state = k - 1 - 2 * inp.harmonics.len();
    let mut a = DMatrix::<f64>::zeros(n, k);
    let mut rhs = DMatrix::<f64>::zeros(n, 3);
    let mut row = vec![0.0; k - n_state];
    for (i, (&t, c)) in inp.t.iter().zip(inp.com).enumerate() {
        let s = t - inp.t_td;
        force_columns(s, inp.dt, inp.mass_kg, inp.harmonics, &mut row);
        if n_state == 2 {
            a[(i, 0)] = 1.0;
            a[(i, 1)] = s;
        }
        for (u, &g) in row.iter().enumerate() {
            a[(i, n_state + u)] = g;
        }
        for d in 0..3 {
            let known = inp.fixed_state.map_or(0.0, |(p, v)| p[d] + v[d] * s);
            rhs[(i, d)] = c[d] - 0.5 * gravity(d) * s * s - known;
        }
    }
    if a.iter().chain(rhs.iter()).any(|v| !v.is_finite()) {
        return bad("design matrix overflows (sample times too far from touchdown)".into());
    }
    Ok((a, rhs))
}

/// Stage B least squares (§4.2) on one fit window.
///
/// Builds the design matrix of the module docs, equilibrates its columns, and solves the
/// three axes with one SVD. A fit whose [`StageBFit::condition`] exceeds
/// [`MAX_CONDITION`] is still returned (with its pseudo-inverse coefficients); the caller
/// then falls back to Stage A and warns.
///
/// # Errors
/// [`ErrorKind::Shape`] when `com.len() != t.len()`; [`ErrorKind::Config`] when `dt` or
/// `mass_kg` is not finite and positive, `t_td`, a time, a COM sample or the fixed state is
/// not finite, the times are not strictly increasing, the harmonics are not `≥ 1` and
/// strictly ascending or exceed [`MAX_HARMONICS`], there are fewer samples than unknowns
/// per axis, the design overflows (|s| ≳ 1e150 s), or the SVD does not converge within
/// [`SVD_MAX_ITERATIONS`]. Nothing panics.
pub fn fit_stage_b(inp: &StageBInput) -> Result<StageBFit> {
    check(inp)?;
    let (mut a, rhs) = design(inp)?;
    let (n, k) = a.shape();
    let n_state = k - 1 - 2 * inp.harmonics.len();
    // Column equilibration; an all-zero column keeps scale 1 (and makes σ_min = 0).
    let scale: Vec<f64> = a
        .column_iter()
        .map(|col| {
            let r = col.norm().recip();
            if r.is_finite() {
                r
            } else {
                1.0
            }
        })
        .collect();
    for (mut col, &sc) in a.column_iter_mut().zip(&scale) {
        col *= sc;
    }
    let Some(svd) = SVD::try_new(a.clone(), true, true, SVD_EPS, SVD_MAX_ITERATIONS) else {
        return bad(format!(
            "svd did not converge in {SVD_MAX_ITERATIONS} iterations"
        ));
    };
    let sv = &svd.singular_values;
    let s_max = sv.iter().copied().fold(0.0, f64::max);
    let s_min = sv.iter().copied().fold(f64::INFINITY, f64::min);
    let condition = if s_min > 0.0 {
        s_max / s_min
    } else {
        f64::INFINITY
    };
    let cutoff = k as f64 * f64::EPSILON * s_max;
    let y = match svd.solve(&rhs, cutoff) {
        Ok(y) => y,
        Err(e) => return bad(format!("svd solve: {e}")),
    };
    let resid = &rhs - &a * &y;
    let pos_rms_m = (resid.norm_squared() / n as f64).sqrt();
    // Undo the scaling: x_u = y_u / ‖A_:,u‖.
    let x = |u: usize, d: usize| y[(u, d)] * scale[u];
    let (p_td, v_td) = inp.fixed_state.unwrap_or_else(|| {
        (
            std::array::from_fn(|d| x(0, d)),
            std::array::from_fn(|d| x(1, d)),
        )
    });
    let m = inp.harmonics.len();
    Ok(StageBFit {
        p_td,
        v_td,
        c0: std::array::from_fn(|d| x(n_state, d)),
        a: std::array::from_fn(|d| (0..m).map(|q| x(n_state + 1 + 2 * q, d)).collect()),
        b: std::array::from_fn(|d| (0..m).map(|q| x(n_state + 2 + 2 * q, d)).collect()),
        harmonics: inp.harmonics.to_vec(),
        pos_rms_m,
        condition,
    })
}

/// Rotate a world fit into the stance frame: the [`ForceModel`] of spec §4.3.
///
/// ```text
/// coef_axis = e_axis · coef_world          (c0, a_j, b_j; e_axis = row of R_s)
/// A = hypot(a, b),  φ = atan2(−b, a)       since a cos Ωτ + b sin Ωτ = A cos(Ωτ + φ)
/// ```
/// Terms with `A == 0` are dropped; the rest are ordered by amplitude, largest first (ties
/// → lower `j`), as [`AxisModel`] lists Stage A terms. `fit_rms` is 0 on every axis:
/// Stage B fits positions, not force samples, so there is no force residual to report
/// (its position residual is [`StageBFit::pos_rms_m`]). Non-finite inputs propagate into
/// the model (IEEE arithmetic); nothing panics.
pub fn to_stance_model(fit: &StageBFit, r_s: [[f64; 3]; 3], mass_kg: f64, dt: f64) -> ForceModel {
    let axes = r_s.map(|e| {
        let dot = |w: [f64; 3]| e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
        let mut terms: Vec<(u32, f64, f64)> = fit
            .harmonics
            .iter()
            .enumerate()
            .filter_map(|(k, &j)| {
                let a = dot(std::array::from_fn(|d| coef(&fit.a[d], k)));
                let b = dot(std::array::from_fn(|d| coef(&fit.b[d], k)));
                let amp = a.hypot(b);
                (amp != 0.0).then(|| (j, amp, (-b).atan2(a)))
            })
            .collect();
        terms.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
        AxisModel {
            c0: dot(fit.c0),
            harmonics: terms.iter().map(|t| t.0).collect(),
            amps: terms.iter().map(|t| t.1).collect(),
            phases: terms.iter().map(|t| t.2).collect(),
            fit_rms: 0.0,
        }
    });
    ForceModel {
        mass_kg,
        dt_s: dt,
        axes,
    }
}

#[cfg(test)]
mod tests;
