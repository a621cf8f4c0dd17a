//! The paper's Fourier model fitted with the ratio model's physics (`--force-model fourier`;
//! issue 39 item 2): a constant plus cosine terms per axis, non-periodic over the stance.
//!
//! # Model
//! ```text
//! f_v(τ) = Σ_{k=0..K} v_k cos(πkτ)                 (half-range cosine series)            N
//! q_a(τ) = Σ_{m=0..M} r_am cos(πmτ),   a = h, p  (the friction ratios)                  1
//!   r_am = Σ_{k=0..L_a} ρ_ak c_km: a polynomial Σ ρ_ak τ^k of degree L_a carried by its
//!   half-range cosine series (c_km: that of τ^k, [`power_series`]; M = RATIO_HARMONICS)
//! f_a(τ) = f_v(τ) q_a(τ) = Σ_n g_an cos(πnτ),   g_an = ½ Σ_{k±m=n} v_k r_am    (exact)   N
//! K = clamp(n_st − 3, 2, vertical_degree),  L_h = ratio_degree_h,  L_p = ratio_degree_p
//! v   = argmin ‖Φ v − s_v‖²  s.t.  ∫₀¹ f_v = v_0 = I_v  (edge targets),  f_v(τ_g) ≥ 0 on the
//!       evaluation grid,  ∫₀¹∫₀ˢ f_v = Σ_k v_k D_k = T_2   (exact, or soft with
//!       EdgeTargets::position_tolerance_m: as the ratio model)
//! ρ_a = the ratio model's load-weighted fit with φ_k = Σ_m c_km cos(πmτ) (leg line, impulse
//!       exact, travel soft: super::ratio)
//! D_0 = ½,  D_k = ∫₀¹ (1 − τ) cos(πkτ) dτ = (1 − (−1)^k)/(πk)²   (k ≥ 1)
//! ```
//! Stored in the paper's form: `c0_a = c_a0` and one term per `m ≥ 1` with harmonic `m/2`
//! (cycles per stance: `cos(πmτ) = cos(2π(m/2)τ)`), amplitude `|c_am|` and phase 0 or π.
//! `∫₀¹ cos(πkτ) dτ = 0` for `k ≥ 1`, so `J_a = c0_a Δt/m` holds exactly (the paper's
//! eq 17–19), and the friction ratio under scaling is `hypot(β_h q_h, β_p q_p)/β_v`, as in
//! the ratio model.
//!
//! Why: the paper's periodic DFT (Stage A, [`super::fit`]) forces `f(0) = f(1)` on every axis
//! and rings at the stance edges, where `f_v` is small and friction is decided; its vertical
//! force kept 10 % of its peak at both edges and the friction demand was 3.7× the plates'.
//! The half-range cosines are the even extension's Fourier series: no periodicity is imposed
//! at the edges, `cos(πτ)` is monotone over the stance (a ratio can go from braking to
//! push-off as the ratio model's linear `q_h` does), and the product of two such series is
//! one (product-to-sum), so the force stays in the paper's form with the ratio exact.
//! The ratios' series are tied to low-degree polynomials: a free series of the same few
//! terms has zero slope at both edges (every `cos(πmτ)` does), where the plates' ratio is
//! steepest, and on the 4 m/s plate run its friction demand at the 5 % active set missed
//! the plates by a median 0.166 (p90 0.301) against the ratio model's 0.109 (0.233); more
//! free terms followed the kinematic force's edge error (`docs/stance-model.md` §4.1).
//!
//! # Frames and units
//! Stance frame `h, p, v`; forces in N, `τ` unit-free, `q` unit-free.
//!
//! # References
//! Pollard & Behmaram-Mosavat, eq 1 (cosine terms per axis) and eq 15–22; spec stance-model
//! §4.1 (the DFT model), §4.4 (the ratio model's physics).

use std::f64::consts::PI;

use nalgebra::{DMatrix, DVector};

use super::ratio::{
    constrained_lsq, ratio_data, ratio_fit, rms, sample_grid, vertical_degree, with_soft_row,
    EdgeTargets, RatioOptions, TRAVEL_TOLERANCE_M,
};
use super::{AxisModel, ForceModel};
use crate::Result;

/// Points `τ_g = g/(n − 1)` where `f_v ≥ 0` is imposed: the evaluation grid's minimum size
/// ([`super::model::GRID_MIN_SAMPLES`]), on which `min_f_v` and the unilateral flag are read.
const NON_NEGATIVE_POINTS: usize = super::model::GRID_MIN_SAMPLES;

/// A fitted half-range cosine model: the force model and the series it was built from.
#[derive(Debug, Clone, PartialEq)]
pub struct CosineFit {
    /// The stance force model (constant and cosine terms only).
    pub model: ForceModel,
    /// `r_h`, `r_p`: coefficients of `cos(πmτ)`, `m = 0 … RATIO_HARMONICS`, of the friction
    /// ratios `q_h`, `q_p`.
    pub ratio: [Vec<f64>; 2],
    /// `v_k`: coefficients of `cos(πkτ)` of `f_v`, N.
    pub vertical: Vec<f64>,
    /// Vertical edge targets applied, as [`super::RatioFit::vertical_targets_met`].
    pub vertical_targets_met: usize,
}

/// `cos(πkτ)`, the k-th half-range cosine.
pub fn half_cosine(k: usize, tau: f64) -> f64 {
    (PI * k as f64 * tau).cos()
}

/// Harmonics `M` of each friction ratio's series: `q_a` is a polynomial of degree `L_a`
/// carried by its half-range cosine series truncated at `cos(πMτ)` ([`power_series`]). The
/// series of `τ` converges like `1/m²` (its even extension has a corner at the edges), so
/// the truncation misses a linear ratio by at most `Σ_{odd m > M} 4/(πm)² ≈ 2/(π² M)` of its
/// slope at an edge: 0.7 % at 31.
pub const RATIO_HARMONICS: usize = 31;

/// The half-range cosine series of `τ^k` on `[0, 1]` up to `cos(πMτ)`:
/// `c_0 = 1/(k + 1)`, `c_m = 2 ∫₀¹ τ^k cos(πmτ) dτ`, by the recursion (`a = πm`, `m ≥ 1`)
/// ```text
/// C_0 = 0,  S_0 = (1 − cos a)/a,   C_j = −(j/a) S_{j−1},   S_j = −cos(a)/a + (j/a) C_{j−1}
/// ```
/// (`C_j = ∫₀¹ τ^j cos(aτ)`, `S_j = ∫₀¹ τ^j sin(aτ)`; integration by parts, `sin a = 0`).
pub fn power_series(k: usize, m_max: usize) -> Vec<f64> {
    let mut c = vec![0.0; m_max + 1];
    c[0] = 1.0 / (k as f64 + 1.0);
    for (m, cm) in c.iter_mut().enumerate().skip(1) {
        let a = PI * m as f64;
        let cos_a = if m % 2 == 0 { 1.0 } else { -1.0 };
        let (mut cj, mut sj) = (0.0, (1.0 - cos_a) / a);
        for j in 1..=k {
            let c_next = -(j as f64 / a) * sj;
            let s_next = -cos_a / a + (j as f64 / a) * cj;
            (cj, sj) = (c_next, s_next);
        }
        *cm = 2.0 * cj;
    }
    c
}

/// A half-range cosine series evaluated at `τ`: `Σ_m c_m cos(πmτ)`.
pub fn series_at(c: &[f64], tau: f64) -> f64 {
    c.iter()
        .enumerate()
        .map(|(m, x)| x * half_cosine(m, tau))
        .sum()
}

/// `D_k = ∫₀¹∫₀ˢ cos(πku) du ds = ∫₀¹ (1 − τ) cos(πkτ) dτ`: ½ for `k = 0`, else
/// `(1 − (−1)^k)/(πk)²`.
pub fn double_integral(k: usize) -> f64 {
    match k {
        0 => 0.5,
        _ if k.is_multiple_of(2) => 0.0,
        _ => 2.0 / (PI * k as f64).powi(2),
    }
}

/// The product of two half-range cosine series (coefficients of `cos(πkτ)`):
/// `cos(πiτ) cos(πjτ) = ½ cos(π(i+j)τ) + ½ cos(π|i−j|τ)`.
pub fn series_product(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, &x) in a.iter().enumerate() {
        for (j, &y) in b.iter().enumerate() {
            out[i + j] += 0.5 * x * y;
            out[i.abs_diff(j)] += 0.5 * x * y;
        }
    }
    out
}

/// A half-range cosine series in the stored form: `c0 = c_0`, then per `m ≥ 1` with
/// `c_m ≠ 0` the harmonic `m/2`, amplitude `|c_m|` and phase 0 (or π for `c_m < 0`).
pub fn series_axis(c: &[f64]) -> AxisModel {
    let mut axis = AxisModel::constant(c.first().copied().unwrap_or(0.0));
    for (m, &x) in c.iter().enumerate().skip(1).filter(|(_, x)| **x != 0.0) {
        axis.harmonics.push(m as f64 / 2.0);
        axis.amps.push(x.abs());
        axis.phases.push(if x < 0.0 { PI } else { 0.0 });
    }
    axis
}

/// `argmin ‖Φ v − s‖²` with `e·v = target` for the rows of `eq` and `f_v(τ_g) ≥ 0`
/// ([`constrained_lsq`]). Returns `v` and how many equality rows held.
fn non_negative_fit(
    design: &DMatrix<f64>,
    s: &[f64],
    eq: &[(Vec<f64>, f64)],
) -> Result<(Vec<f64>, usize)> {
    let last = (NON_NEGATIVE_POINTS - 1) as f64;
    // −f_v(τ_g) ≤ 0.
    let le: Vec<Vec<f64>> = (0..NON_NEGATIVE_POINTS)
        .map(|g| {
            let t = g as f64 / last;
            (0..design.ncols()).map(|i| -half_cosine(i, t)).collect()
        })
        .collect();
    constrained_lsq(design, s, eq, &le, "fourier model")
}

/// The vertical series under edge targets, as in the ratio model: the impulse `v_0 = I_v`
/// exact, the position `Σ_k v_k D_k = T_2` exact or, with
/// [`EdgeTargets::position_tolerance_m`], soft (weight `r₀/σ`, `σ = m · tol_m / Δt²`).
/// Returns `v` and how many targets were applied (2, 1 or 0).
fn vertical_series(
    design: &DMatrix<f64>,
    s: &[f64],
    targets: Option<&EdgeTargets>,
    (mass_kg, dt_s): (f64, f64),
) -> Result<(Vec<f64>, usize)> {
    let Some(t) = targets else {
        return non_negative_fit(design, s, &[]);
    };
    let n = design.ncols();
    let mut unit = vec![0.0; n];
    unit[0] = 1.0;
    let double: Vec<f64> = (0..n).map(double_integral).collect();
    let Some(tol_m) = t.position_tolerance_m else {
        return non_negative_fit(
            design,
            s,
            &[(unit, t.impulse[2]), (double, t.vertical_double)],
        );
    };
    let impulse = [(unit, t.impulse[2])];
    let (v0, met) = non_negative_fit(design, s, &impulse)?;
    if met == 0 {
        return Ok((v0, 0));
    }
    let sigma = mass_kg * tol_m / (dt_s * dt_s);
    let Some((rows, rhs)) = with_soft_row(design, s, &v0, (&double, t.vertical_double, sigma))
    else {
        return Ok((v0, 1));
    };
    match non_negative_fit(&rows, &rhs, &impulse)? {
        (v, 1) => Ok((v, 2)),
        _ => Ok((v0, 1)),
    }
}

/// Fits the half-range cosine model to stance-axis force samples on `τ_j = j/(N−1)`.
///
/// # Arguments
/// As [`super::fit_ratio_with`]: `samples` per stance axis (h, p, v), N, length `N ≥ 2`;
/// `n_st` stance frames (sets `K`); the edge `targets`; the leg line's slopes `leg`; the
/// degrees and leg-line knobs of `opts` (`vertical_degree` caps `K`, `ratio_degree_h/p` are
/// `L_h`, `L_p`).
///
/// # Errors
/// A config error for bad options or sample lengths; a numeric error when the QP fails.
pub fn fit_cosine_with(
    samples: &[Vec<f64>; 3],
    n_st: usize,
    (mass_kg, dt_s): (f64, f64),
    targets: Option<&EdgeTargets>,
    leg: Option<&[Vec<f64>; 2]>,
    opts: &RatioOptions,
) -> Result<CosineFit> {
    opts.check()?;
    let n = super::ratio::sample_count(samples, "fourier")?;
    let tau = sample_grid(n);
    let k_max = vertical_degree(n_st, opts.vertical_degree).min(n - 1);
    let design = DMatrix::from_fn(n, k_max + 1, |j, k| half_cosine(k, tau[j]));
    let (v, met) = vertical_series(&design, &samples[2], targets, (mass_kg, dt_s))?;
    let fv: Vec<f64> = (&design * DVector::from_column_slice(&v))
        .iter()
        .copied()
        .collect();
    let data = ratio_data(samples, &fv, leg, opts.leg_line_weight);
    let sigma = mass_kg * TRAVEL_TOLERANCE_M / (dt_s * dt_s);
    let fit_ratio = |a: usize, deg: usize| {
        // The basis: τ^k as its truncated cosine series; ∫ f_v φ_k and ∫∫ f_v φ_k from the
        // product series.
        let basis: Vec<Vec<f64>> = (0..=deg)
            .map(|k| power_series(k, RATIO_HARMONICS))
            .collect();
        let products: Vec<Vec<f64>> = basis.iter().map(|e| series_product(&v, e)).collect();
        let impulse: Vec<f64> = products.iter().map(|p| p[0]).collect();
        let double: Vec<f64> = products
            .iter()
            .map(|p| {
                p.iter()
                    .enumerate()
                    .map(|(m, c)| c * double_integral(m))
                    .sum()
            })
            .collect();
        let phi = |k: usize, t: f64| series_at(&basis[k], t);
        let r = ratio_fit(
            &fv,
            &tau,
            &data[a],
            (deg, &phi),
            targets.map(|t| (impulse.as_slice(), t.impulse[a])),
            targets.map(|t| (double.as_slice(), t.travel_double[a], sigma)),
        );
        // The ratio's own cosine coefficients: q_m = Σ_k r_k c_{k,m}.
        (0..=RATIO_HARMONICS)
            .map(|m| r.iter().zip(&basis).map(|(rk, b)| rk * b[m]).sum())
            .collect::<Vec<f64>>()
    };
    let r_h = fit_ratio(0, opts.ratio_degree_h);
    let r_p = fit_ratio(1, opts.ratio_degree_p);
    let axis = |c: &[f64], s: &[f64]| {
        let mut a = series_axis(c);
        a.fit_rms = rms(&a, &tau, s);
        a
    };
    let model = ForceModel {
        mass_kg,
        dt_s,
        axes: [
            axis(&series_product(&v, &r_h), &samples[0]),
            axis(&series_product(&v, &r_p), &samples[1]),
            axis(&v, &samples[2]),
        ],
    };
    Ok(CosineFit {
        model,
        ratio: [r_h, r_p],
        vertical: v,
        vertical_targets_met: met,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force_model::basis::simpson;
    use crate::force_model::ratio::bell_samples;

    #[test]
    fn power_series_matches_simpson_and_converges_to_the_power() {
        for k in 0..=4 {
            let c = power_series(k, RATIO_HARMONICS);
            for (m, &cm) in c.iter().enumerate().take(12) {
                let w = if m == 0 { 1.0 } else { 2.0 };
                let q = w * simpson(|t| t.powi(k as i32) * half_cosine(m, t), 0.0, 1.0, 4000);
                assert!((cm - q).abs() < 1e-10, "τ^{k}, m = {m}: {cm} vs {q}");
            }
            // The truncated series stays within the documented bound of τ^k on [0, 1]
            // (k·2/(π² M) at the edges, where the even extension has its corner).
            let bound = (k as f64).max(1.0) * 2.0 / (PI * PI * RATIO_HARMONICS as f64) + 1e-9;
            for g in 0..=100 {
                let t = g as f64 / 100.0;
                let e = (series_at(&c, t) - t.powi(k as i32)).abs();
                assert!(
                    k == 0 && e < 1e-12 || k > 0 && e <= bound,
                    "τ^{k} at {t}: {e}"
                );
            }
        }
    }

    #[test]
    fn series_identities_match_simpson() {
        // D_k and the product series against Simpson (4000 intervals, error ≤ 1e-12 here).
        for k in 0..9 {
            let q = simpson(|t| (1.0 - t) * half_cosine(k, t), 0.0, 1.0, 4000);
            assert!((double_integral(k) - q).abs() < 1e-12, "D_{k}");
        }
        let (a, b) = ([3.0, -1.0, 0.5, 2.0], [0.2, 0.7, -0.3]);
        let ab = series_product(&a, &b);
        let eval = |c: &[f64], t: f64| -> f64 {
            c.iter()
                .enumerate()
                .map(|(k, x)| x * half_cosine(k, t))
                .sum()
        };
        for t in [0.0, 0.13, 0.5, 0.91, 1.0] {
            assert!((eval(&ab, t) - eval(&a, t) * eval(&b, t)).abs() < 1e-12);
            // The stored form evaluates to the same series.
            assert!((series_axis(&ab).eval(t) - eval(&ab, t)).abs() < 1e-12);
        }
    }

    #[test]
    fn a_bell_keeps_its_ratio_and_f_v_stays_non_negative() {
        let s = bell_samples(64, 70.0);
        let fit =
            fit_cosine_with(&s, 20, (70.0, 0.25), None, None, &RatioOptions::default()).unwrap();
        let m = &fit.model;
        // sin²(πτ) = ½ − ½ cos(2πτ) is in the basis: exact to roundoff (1e-9 N).
        assert!(m.axes[2].fit_rms < 1e-9, "{}", m.axes[2].fit_rms);
        // A linear ratio in cos(πτ) (L_h = 1) is not exact: within 0.05 of it where f_v ≥
        // 20 % of its peak, and the force is f_v·q_h exactly.
        for t in [0.2, 0.5, 0.8] {
            let (fh, fv) = (m.axes[0].eval(t), m.axes[2].eval(t));
            assert!(
                (fh / fv - (-0.4 + 0.9 * t)).abs() < 0.05,
                "τ {t}: {}",
                fh / fv
            );
            let q: f64 = fit.ratio[0]
                .iter()
                .enumerate()
                .map(|(l, r)| r * half_cosine(l, t))
                .sum();
            assert!((fh / fv - q).abs() < 1e-9);
        }
        assert!(m.min_f_v(&m.grid()) >= -1e-6);
        // Every harmonic is a whole or half cycle, and J = c0 Δt/m to roundoff.
        for ax in &m.axes {
            assert!(ax.harmonics.iter().all(|j| (2.0 * j).fract() == 0.0));
            assert!((ax.integral() - ax.c0).abs() < 1e-9 * (1.0 + ax.c0.abs()));
        }
    }

    #[test]
    fn edge_targets_hold_the_impulses_and_the_position_exactly() {
        let s = bell_samples(64, 70.0);
        let opts = RatioOptions::default();
        let free = fit_cosine_with(&s, 20, (70.0, 0.25), None, None, &opts).unwrap();
        let i = |a: usize| free.model.axes[a].integral();
        let t = EdgeTargets {
            impulse: [i(0) + 30.0, i(1) - 5.0, 1.03 * i(2)],
            vertical_double: 1.01 * free.model.axes[2].f2(1.0),
            travel_double: [free.model.axes[0].f2(1.0), free.model.axes[1].f2(1.0)],
            position_tolerance_m: None,
        };
        let fit = fit_cosine_with(&s, 20, (70.0, 0.25), Some(&t), None, &opts).unwrap();
        assert_eq!(fit.vertical_targets_met, 2);
        for a in 0..3 {
            let got = fit.model.axes[a].integral();
            // Roundoff of O(1e3 N) sums: 1e-6 of the vertical impulse.
            assert!(
                (got - t.impulse[a]).abs() < 1e-6 * t.impulse[2],
                "axis {a}: {got} vs {}",
                t.impulse[a]
            );
        }
        // The position exactly too (1e-9 m: `Δt²/m` times the double integral).
        let miss_m = (fit.model.axes[2].f2(1.0) - t.vertical_double).abs() * 0.25 * 0.25 / 70.0;
        assert!(miss_m < 1e-9, "{miss_m} m");
        assert!(fit.model.min_f_v(&fit.model.grid()) >= -1e-6 * t.impulse[2]);
    }
}
