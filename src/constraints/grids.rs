//! Sampled grids: one force model's functions on its evaluation grid (spec stance-model §7.2).
//!
//! # Model
//!
//! Per stance axis `a ∈ {h, p, v}`, on the grid `τ_k = k/(N_s − 1)` of §4.3:
//!
//! ```text
//! f_a(τ) = d_a + Σ_i c_i cos(Ω_i τ + φ_i) + P_a(τ),   Ω_i = 2π j_i,  j_i ≥ ½    (N)
//! d_a    = c0_a + Σ_{i: j_i = 0} c_i cos φ_i                                   (N)
//! S_a(τ) = κ F2_a(τ)                                                          (m)
//!        = κ [q0 + q1 τ + q2 τ² − Σ_i (c_i/Ω_i²) cos(Ω_i τ + φ_i)]
//!          + κ Σ_k p_k τ^(k+2)/((k+1)(k+2))          (polynomial part P_a = Σ_k p_k τ^k)
//! κ = Δt²/m (s²/kg),  q0 = Σ c_i cos φ_i/Ω_i²,  q1 = −Σ c_i sin φ_i/Ω_i,  q2 = d_a/2
//! ```
//!
//! `f_a` and `S_a` share the one cosine per harmonic and grid point. Harmonics are whole
//! or half cycles per stance (`2j_i` an integer), so on the uniform grid the angle is
//! `Ω_i τ_k + φ_i = 2π (2j_i k mod P)/P + φ_i` with `P = 2(N_s − 1)`, and
//!
//! ```text
//! cos(Ω_i τ_k + φ_i) = cos φ_i · C[m] − sin φ_i · S[m],   m = 2j_i k mod P
//! C[m] = cos(2π m/P),  S[m] = sin(2π m/P)
//! ```
//! (A harmonic that is not a multiple of ½, which no fit writes, is evaluated directly.)
//!
//! with the unit-circle table `C`, `S` built once per grid size and kept across stances: no
//! trigonometric call per grid point or per stance beyond `sin_cos φ_i` (error ≈ 1 ulp).
//!
//! # Frames and units
//!
//! Stance frame (h, p, v); forces in N, `S_a` in m, `τ` dimensionless.

use crate::force_model::{basis, ForceModel, UNILATERAL_FRACTION};
use std::f64::consts::TAU;

/// `f_a(τ_k)` and `S_a(τ_k)` of one stance on its grid; reusable across stances.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledGrids {
    /// `λ_act` of the exact friction check on these grids: the active set is
    /// `f_v ≥ λ_act · max f_v`; [`super::ACTIVE_FRACTION`] unless a query sets it.
    pub active_fraction: f64,
    /// The grid `τ_k = k/(N_s − 1)` (equal to `ForceModel::grid`), dimensionless.
    pub tau: Vec<f64>,
    /// `f_a(τ_k)` per axis (h, p, v), N.
    pub f: [Vec<f64>; 3],
    /// `S_a(τ_k) = (Δt²/m) F2_a(τ_k)` per axis (h, p, v), m.
    pub s: [Vec<f64>; 3],
    /// `max_k f_v(τ_k)`, N (0 for an empty grid, NaN if any `f_v` is NaN).
    pub max_f_v: f64,
    /// `f_v(τ_k) ≥ −0.05 · max f_v` at every grid point (§4.3); false if any is NaN.
    pub unilateral_ok: bool,
    /// `(cos, sin)` of `2π m/P`, `P = 2(N_s − 1)`, `m = 0 … P − 1`, for the last grid size.
    unit_circle: Vec<(f64, f64)>,
}

impl Default for SampledGrids {
    fn default() -> Self {
        SampledGrids {
            active_fraction: super::ACTIVE_FRACTION,
            tau: Vec::new(),
            f: Default::default(),
            s: Default::default(),
            max_f_v: 0.0,
            unilateral_ok: true,
            unit_circle: Vec::new(),
        }
    }
}

impl SampledGrids {
    /// Tables of `model` on its own grid.
    pub fn new(model: &ForceModel) -> Self {
        let mut grids = Self::default();
        grids.rebuild(model);
        grids
    }

    /// Refills the grids for `model`, keeping the allocations (and the unit-circle table
    /// when the grid size is unchanged).
    pub fn rebuild(&mut self, model: &ForceModel) {
        let n = model.grid_len();
        let last = n.saturating_sub(1) as f64;
        // Half steps: m/P = (m/2)/(N_s − 1); doubling is exact in binary, so the whole
        // steps' values equal those of a table over N_s − 1.
        let period = 2 * n.saturating_sub(1);
        self.tau.clear();
        self.tau.extend((0..n).map(|k| k as f64 / last));
        if self.unit_circle.len() != period {
            self.unit_circle.clear();
            self.unit_circle.extend(
                (0..period)
                    .map(|m| (TAU * m as f64 / (2.0 * last)).sin_cos())
                    .map(|(s, c)| (c, s)),
            );
        }
        let kappa = model.dt_s * model.dt_s / model.mass_kg;
        for axis in 0..3 {
            let (f, s) = (&mut self.f[axis], &mut self.s[axis]);
            f.clear();
            s.clear();
            let d = dc_term(model, axis);
            let (mut q0, mut q1) = (0.0, 0.0);
            for (j, c, phi) in harmonic_terms(model, axis) {
                let omega = basis::omega_of(j);
                let (sin_phi, cos_phi) = phi.sin_cos();
                q0 += c * cos_phi / (omega * omega);
                q1 -= c * sin_phi / omega;
            }
            let q2 = 0.5 * d;
            for &t in &self.tau {
                f.push(d);
                s.push(kappa * (q0 + t * (q1 + t * q2)));
            }
            for (j, c, phi) in harmonic_terms(model, axis) {
                let omega = basis::omega_of(j);
                let c_s = -kappa * c / (omega * omega);
                let (sin_phi, cos_phi) = phi.sin_cos();
                if period == 0 {
                    for (fk, sk) in f.iter_mut().zip(s.iter_mut()) {
                        *fk += c * cos_phi;
                        *sk += c_s * cos_phi;
                    }
                    continue;
                }
                let twice = 2.0 * j;
                if twice.fract() != 0.0 || !twice.is_finite() || twice < 0.0 {
                    for ((fk, sk), &t) in f.iter_mut().zip(s.iter_mut()).zip(&self.tau) {
                        let cos_angle = (omega * t + phi).cos();
                        *fk += c * cos_angle;
                        *sk += c_s * cos_angle;
                    }
                    continue;
                }
                // 2j < 2⁵³ here (finite and whole), so the cast is exact.
                let step = (twice as u64 % period as u64) as usize;
                let mut m = 0usize;
                for (fk, sk) in f.iter_mut().zip(s.iter_mut()) {
                    let (cos_m, sin_m) = self.unit_circle.get(m).copied().unwrap_or((1.0, 0.0));
                    let cos_angle = cos_phi * cos_m - sin_phi * sin_m;
                    *fk += c * cos_angle;
                    *sk += c_s * cos_angle;
                    m += step;
                    if m >= period {
                        m -= period;
                    }
                }
            }
            add_polynomial_part(model, axis, kappa, &self.tau, f, s);
        }
        self.summarise_vertical();
    }

    /// `max f_v` and the unilateral test of the current `f_v` row (end of [`Self::rebuild`]).
    fn summarise_vertical(&mut self) {
        let fv = &self.f[2];
        let nan = fv.iter().any(|v| v.is_nan());
        let max = fv.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        self.max_f_v = if nan {
            f64::NAN
        } else if fv.is_empty() {
            0.0
        } else {
            max
        };
        let floor = -UNILATERAL_FRACTION * self.max_f_v;
        self.unilateral_ok = !nan && fv.iter().all(|&v| v >= floor);
    }

    /// Number of grid points `N_s`.
    pub fn len(&self) -> usize {
        self.tau.len()
    }

    /// True when the grid is empty.
    pub fn is_empty(&self) -> bool {
        self.tau.is_empty()
    }
}

/// Adds the polynomial part `P_a(τ_k)` to `f` and `κ F2[P_a](τ_k)` to `s`.
fn add_polynomial_part(
    model: &ForceModel,
    axis: usize,
    kappa: f64,
    tau: &[f64],
    f: &mut [f64],
    s: &mut [f64],
) {
    let Some(poly) = model.axes.get(axis).map(|a| &a.poly) else {
        return;
    };
    if poly.is_empty() {
        return;
    }
    for ((&t, fk), sk) in tau.iter().zip(f.iter_mut()).zip(s.iter_mut()) {
        *fk += basis::poly_eval(poly, t);
        *sk += kappa * basis::poly_f2(poly, t);
    }
}

/// DC force of axis `axis`, N: `c0 + Σ_{j = 0} c cos φ` (a `j = 0` term is a constant).
pub(crate) fn dc_term(model: &ForceModel, axis: usize) -> f64 {
    let Some(ax) = model.axes.get(axis) else {
        return 0.0;
    };
    ax.c0
        + ax.harmonics
            .iter()
            .zip(ax.amps.iter().zip(&ax.phases))
            .filter(|(&j, _)| j == 0.0)
            .map(|(_, (&c, &phi))| c * phi.cos())
            .sum::<f64>()
}

/// The `(j, c, φ)` terms of axis `axis` with `j ≠ 0` (cycles per stance; lists of unequal
/// length are cut to the shortest).
pub(crate) fn harmonic_terms(
    model: &ForceModel,
    axis: usize,
) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
    model
        .axes
        .get(axis)
        .into_iter()
        .flat_map(|ax| {
            ax.harmonics
                .iter()
                .zip(ax.amps.iter().zip(&ax.phases))
                .map(|(&j, (&c, &phi))| (j, c, phi))
        })
        .filter(|&(j, _, _)| j != 0.0)
}
