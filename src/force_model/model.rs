//! The continuous stance force model (spec stance-model §4.3) and its six numbers (§5).
//!
//! # Model
//! ```text
//! f_a(τ) = c0_a + Σ_i c_ia cos(2π j_ia τ + φ_ia) + Σ_k p_ka τ^k,   τ = (t − t_TD)/Δt ∈ [0, 1]   N
//! J_a = (Δt/m)  ∫₀¹ f_a dτ = (c0_a + Σ_k p_ka/(k+1)) Δt/m  (j ≥ 1 harmonics)      m/s
//! K_a = (Δt²/m) ∫₀¹ τ f_a dτ                                                      m
//! P_a = (Δt²/m) ∫₀¹∫₀ˢ f_a = (Δt²/m) F2_a(1) = Δt·J_a − K_a                     m
//! S_a(τ) = (Δt²/m) F2_a(τ)                 COM displacement from the force         m
//! grid: τ_j = j/(N_s − 1), j = 0 … N_s−1,  N_s = max(201, 16·j_max + 1)
//! support_ok    ⇔ J_v > 0
//! unilateral_ok ⇔ f_v(τ_j) ≥ −0.05 · max_j f_v(τ_j)  for every grid point
//! ```
//! The Fourier part is the paper's model ([`super::fit`]); the polynomial part `p_k` carries
//! the friction-ratio model ([`super::ratio`]). A fit fills one part and leaves the other
//! empty, but every closed form here and in the constraints adds both, so any mix is exact.
//! A non-positive or non-finite `mass_kg` or `dt_s` (never produced by
//! [`super::fit_stage_a`]) makes `J`, `K`, `P` and `S` non-finite, following IEEE
//! arithmetic, and then `support_ok` is false; nothing panics.
//!
//! # Frames and units
//! Stance frame axes `h, p, v` = index 0, 1, 2 (spec §2); forces in newtons (applied
//! force, so `f_v ≈ m g` on average); `Δt` in seconds, `m` in kilograms.

use super::basis;
use super::UNILATERAL_FRACTION;

/// Minimum size of the evaluation grid (spec §4.3).
pub const GRID_MIN_SAMPLES: usize = 201;
/// Grid points per unit of the largest harmonic (spec §4.3: `16·j_max + 1`).
pub const GRID_SAMPLES_PER_HARMONIC: usize = 16;
/// Hard cap on the grid size, `2²⁴ + 1`: reached only for `j_max > 2²⁰`, which Stage A
/// never produces (`j ≤ (N−1)/2`); it keeps a hand-built model from exhausting memory.
pub const GRID_MAX_SAMPLES: usize = (1 << 24) + 1;

/// One stance axis: `f(τ) = c0 + Σ_i amps[i]·cos(2π·harmonics[i]·τ + phases[i]) + Σ_k poly[k]·τ^k`,
/// τ ∈ [0, 1].
///
/// Newtons (applied force). The three vectors have the same length, in the order of
/// selection (largest amplitude first, spec §4.1 step 5); if they differ, the extra
/// entries of the longer ones are ignored.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AxisModel {
    /// DC term `c0` (N).
    pub c0: f64,
    /// Harmonics `j_i > 0` in cycles per stance (`Ω_i = 2π j_i` rad per unit τ): integers
    /// for the paper's DFT terms ([`super::fit`]), halves for the half-range cosines
    /// `cos(πkτ)` of [`super::cosine`].
    pub harmonics: Vec<f64>,
    /// Amplitudes `c_i ≥ 0` (N).
    pub amps: Vec<f64>,
    /// Phases `φ_i` (rad).
    pub phases: Vec<f64>,
    /// Polynomial part: the coefficient `p_k` of `τ^k` (N), `k = 0, 1, …` (empty for the
    /// Fourier model).
    pub poly: Vec<f64>,
    /// RMS over the fitted samples of (sample − model) (N); 0 for a hand-built model.
    pub fit_rms: f64,
}

impl AxisModel {
    /// A constant force `c0` (N) with no harmonics.
    pub fn constant(c0: f64) -> Self {
        AxisModel {
            c0,
            ..Default::default()
        }
    }

    /// `f + w·g` (N): every term of `g` scaled by `w` and appended to those of `f`
    /// (a negative `w` keeps each amplitude `≥ 0` by turning its phase by π); `fit_rms` is
    /// `f`'s. Every closed form here is linear in the terms, so `J`, `K`, `F1`, `F2` of the
    /// sum are the sums.
    pub fn plus_scaled(&self, w: f64, g: &AxisModel) -> AxisModel {
        let n = self
            .harmonics
            .len()
            .min(self.amps.len())
            .min(self.phases.len());
        let (mut harmonics, mut amps, mut phases) = (
            self.harmonics[..n].to_vec(),
            self.amps[..n].to_vec(),
            self.phases[..n].to_vec(),
        );
        let turn = if w < 0.0 { std::f64::consts::PI } else { 0.0 };
        for (j, c, p) in g.terms() {
            harmonics.push(j);
            amps.push(c * w.abs());
            phases.push(p + turn);
        }
        let len = self.poly.len().max(g.poly.len());
        let coef = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
        AxisModel {
            c0: self.c0 + w * g.c0,
            harmonics,
            amps,
            phases,
            poly: (0..len)
                .map(|k| coef(&self.poly, k) + w * coef(&g.poly, k))
                .collect(),
            fit_rms: self.fit_rms,
        }
    }

    /// `(j, c, φ)` of each term.
    pub fn terms(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        self.harmonics
            .iter()
            .zip(&self.amps)
            .zip(&self.phases)
            .map(|((&j, &c), &p)| (j, c, p))
    }

    /// The largest harmonic, cycles per stance (0 when there is none).
    pub fn j_max(&self) -> f64 {
        self.terms().map(|(j, _, _)| j).fold(0.0, f64::max)
    }

    /// `f(τ)` (N).
    pub fn eval(&self, tau: f64) -> f64 {
        self.c0
            + self
                .terms()
                .map(|(j, c, p)| c * (basis::omega_of(j) * tau + p).cos())
                .sum::<f64>()
            + basis::poly_eval(&self.poly, tau)
    }

    /// `F1(τ) = ∫₀^τ f = c0 τ + Σ c_i (sin(Ω_iτ + φ_i) − sin φ_i)/Ω_i` (N per unit τ).
    pub fn f1(&self, tau: f64) -> f64 {
        self.c0 * tau
            + self
                .terms()
                .map(|(j, c, p)| c * basis::f1(basis::omega_of(j), p, tau))
                .sum::<f64>()
            + basis::poly_f1(&self.poly, tau)
    }

    /// `F2(τ) = ∫₀^τ∫₀ˢ f = c0 τ²/2 + Σ c_i [(cos φ_i − cos(Ω_iτ+φ_i))/Ω_i² − τ sin φ_i/Ω_i]`.
    pub fn f2(&self, tau: f64) -> f64 {
        self.c0 * tau * tau / 2.0
            + self
                .terms()
                .map(|(j, c, p)| c * basis::f2(basis::omega_of(j), p, tau))
                .sum::<f64>()
            + basis::poly_f2(&self.poly, tau)
    }

    /// `∫₀¹ f dτ`: exactly `c0` for the Fourier model with integer harmonics ≥ 1 (their `I1`
    /// is 0, spec §5), `− Σ 2 c_i sin φ_i/Ω_i` over half-integer ones, plus `Σ_k p_k/(k+1)`
    /// for the polynomial part.
    pub fn integral(&self) -> f64 {
        self.c0
            + self
                .terms()
                .map(|(j, c, p)| c * basis::i1_harmonic(j, p))
                .sum::<f64>()
            + basis::poly_moment(&self.poly, 0)
    }

    /// `∫₀¹ τ f dτ = c0/2 + Σ c_i M1_i + Σ_k p_k/(k+2)` (N per unit τ), `M1_i = sin φ_i/Ω_i`
    /// for an integer harmonic ([`basis::m1_harmonic`]).
    pub fn first_moment(&self) -> f64 {
        self.c0 / 2.0
            + self
                .terms()
                .map(|(j, c, p)| c * basis::m1_harmonic(j, p))
                .sum::<f64>()
            + basis::poly_moment(&self.poly, 1)
    }
}

/// The stance force model in the stance frame (axes h, p, v = index 0, 1, 2).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ForceModel {
    /// Body mass `m` (kg).
    pub mass_kg: f64,
    /// Stance duration `Δt = t_LO − t_TD` (s).
    pub dt_s: f64,
    /// The applied force per stance axis (h, p, v).
    pub axes: [AxisModel; 3],
}

impl ForceModel {
    /// `J_a = (Δt/m) ∫₀¹ f_a dτ` (m/s): the velocity change from the applied force.
    pub fn j(&self) -> [f64; 3] {
        // Same operation order as c0·Δt/m, so the DFT basis gives that value bit for bit.
        self.axes
            .each_ref()
            .map(|a| a.integral() * self.dt_s / self.mass_kg)
    }

    /// `K_a = (Δt²/m) ∫₀¹ τ f_a dτ` (m): the first moment about touchdown.
    pub fn k(&self) -> [f64; 3] {
        let s = self.dt_s * self.dt_s / self.mass_kg;
        self.axes.each_ref().map(|a| s * a.first_moment())
    }

    /// `P_a = (Δt²/m) F2_a(1) = Δt·J_a − K_a` (m), computed from the double integral.
    pub fn p(&self) -> [f64; 3] {
        let s = self.dt_s * self.dt_s / self.mass_kg;
        self.axes.each_ref().map(|a| s * a.f2(1.0))
    }

    /// `s̄_a = K_a / J_a` (s), the impulse centroid after touchdown; `None` where `J_a = 0`.
    pub fn s_bar(&self) -> [Option<f64>; 3] {
        let (j, k) = (self.j(), self.k());
        std::array::from_fn(|a| (j[a] != 0.0).then(|| k[a] / j[a]))
    }

    /// `S_a(τ) = (Δt²/m) F2_a(τ)` (m); NaN when `axis > 2`.
    pub fn s(&self, axis: usize, tau: f64) -> f64 {
        match self.axes.get(axis) {
            Some(a) => self.dt_s * self.dt_s / self.mass_kg * a.f2(tau),
            None => f64::NAN,
        }
    }

    /// The largest harmonic over the three axes, cycles per stance (0 if none).
    pub fn j_max(&self) -> f64 {
        self.axes.iter().map(AxisModel::j_max).fold(0.0, f64::max)
    }

    /// `N_s = max(201, ⌈16·j_max⌉ + 1)`, capped at [`GRID_MAX_SAMPLES`] (a NaN or infinite
    /// harmonic gives the cap).
    pub fn grid_len(&self) -> usize {
        let per = self.j_max() * GRID_SAMPLES_PER_HARMONIC as f64;
        if !per.is_finite() || per >= GRID_MAX_SAMPLES as f64 {
            return GRID_MAX_SAMPLES;
        }
        (per.ceil() as usize)
            .saturating_add(1)
            .clamp(GRID_MIN_SAMPLES, GRID_MAX_SAMPLES)
    }

    /// The evaluation grid `τ_j = j/(N_s − 1)`, `j = 0 … N_s−1`, both ends included (§4.3).
    pub fn grid(&self) -> Vec<f64> {
        let n = self.grid_len();
        let last = (n - 1) as f64;
        (0..n).map(|j| j as f64 / last).collect()
    }

    /// `J_v > 0`: the stance can support the body (§4.3); false for NaN.
    pub fn support_ok(&self) -> bool {
        self.j()[2] > 0.0
    }

    /// `min_j f_v(τ_j)` (N) over `grid`; `+∞` for an empty grid (the empty minimum).
    pub fn min_f_v(&self, grid: &[f64]) -> f64 {
        grid.iter()
            .map(|&t| self.axes[2].eval(t))
            .fold(f64::INFINITY, f64::min)
    }

    /// `f_v(τ_j) ≥ −0.05 · max_j f_v(τ_j)` at every point of `grid` (true when empty;
    /// false when any value is NaN). One pass: it is `min f_v ≥ −0.05 · max f_v`.
    pub fn unilateral_ok(&self, grid: &[f64]) -> bool {
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        for &t in grid {
            let f = self.axes[2].eval(t);
            if f.is_nan() {
                return false;
            }
            min = min.min(f);
            max = max.max(f);
        }
        grid.is_empty() || min >= -UNILATERAL_FRACTION * max
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force_model::basis::simpson;
    use std::f64::consts::TAU;

    use crate::testkit::{Harmonics, Rng};

    /// A random axis: DC in [−450, 1050) N plus 1–6 cosines of harmonics 1–8, up to 800 N.
    fn random_axis(rng: &mut Rng) -> AxisModel {
        let c0 = 1500.0 * (rng.next_f64() - 0.3);
        crate::testkit::random_axis(
            rng,
            c0,
            800.0,
            Harmonics {
                terms: 6,
                max_j: 8,
                halves: false,
            },
        )
    }

    #[test]
    fn plus_scaled_is_the_pointwise_sum_in_every_closed_form() {
        let mut rng = Rng::new(0x5eed_1234_abcd_0077);
        for w in [-0.37, 0.0, 0.25, 1.5] {
            let mut f = random_axis(&mut rng);
            f.poly = vec![10.0, -40.0, 25.0];
            let mut g = random_axis(&mut rng);
            g.poly = vec![-3.0, 7.0, 0.0, 11.0];
            let s = f.plus_scaled(w, &g);
            assert!(s.amps.iter().all(|&c| c >= 0.0), "amplitudes stay ≥ 0");
            // Roundoff of O(1e3 N) sums: 1e-9 N.
            let close = |a: f64, b: f64, what: &str| {
                assert!((a - b).abs() < 1e-9, "w = {w}, {what}: {a} vs {b}")
            };
            for &tau in &[0.0, 0.3, 0.77, 1.0] {
                close(s.eval(tau), f.eval(tau) + w * g.eval(tau), "f");
                close(s.f1(tau), f.f1(tau) + w * g.f1(tau), "F1");
                close(s.f2(tau), f.f2(tau) + w * g.f2(tau), "F2");
            }
            close(s.integral(), f.integral() + w * g.integral(), "∫f");
            close(
                s.first_moment(),
                f.first_moment() + w * g.first_moment(),
                "∫τf",
            );
        }
    }

    #[test]
    fn closed_forms_match_simpson_on_random_models() {
        // 4000 Simpson intervals: error ≤ h⁴/180·Σc·Ω⁴ ≈ 3e-9 N for Σc ≤ 4800 N, Ω ≤ 2π·8;
        // the tolerance uses that bound per model, plus 1e-10 of O(1e3 N) roundoff.
        let n = 4000;
        let mut rng = Rng::new(0x5eed_1234_abcd_0001);
        for _ in 0..50 {
            let m = random_axis(&mut rng);
            let om = basis::omega_of(m.j_max());
            let c: f64 = m.amps.iter().sum::<f64>() + m.c0.abs();
            let tol =
                (1.0 / n as f64).powi(4) / 180.0 * c * (om.powi(4) + 4.0 * om.powi(3)) + 1e-10 * c;
            for &tau in &[0.0, 0.21, 0.5, 0.93, 1.0] {
                let q1 = simpson(|u| m.eval(u), 0.0, tau, n);
                let q2 = simpson(|u| (tau - u) * m.eval(u), 0.0, tau, n);
                assert!((m.f1(tau) - q1).abs() < tol, "F1({tau})");
                assert!((m.f2(tau) - q2).abs() < tol, "F2({tau})");
            }
            assert!((m.integral() - simpson(|u| m.eval(u), 0.0, 1.0, n)).abs() < tol);
            let qm = simpson(|u| u * m.eval(u), 0.0, 1.0, n);
            assert!((m.first_moment() - qm).abs() < tol);
            // F1(1) equals the exact integral up to sin(2πj) roundoff (1e-12 relative).
            assert!((m.f1(1.0) - m.integral()).abs() < 1e-12 * c);
        }
    }

    #[test]
    fn mixed_fourier_and_polynomial_parts_match_simpson() {
        // The polynomial part (degree 7, O(1e3 N) coefficients) adds to the Fourier part in
        // every closed form; Simpson with 4000 intervals is exact to ~1e-8 N here.
        let mut rng = Rng::new(0xfeed_0042);
        for _ in 0..20 {
            let mut m = random_axis(&mut rng);
            m.poly = (0..8).map(|_| 2000.0 * (rng.next_f64() - 0.5)).collect();
            let n = 4000;
            for &tau in &[0.0, 0.37, 1.0] {
                assert!((m.f1(tau) - simpson(|u| m.eval(u), 0.0, tau, n)).abs() < 1e-7);
                let q2 = simpson(|u| (tau - u) * m.eval(u), 0.0, tau, n);
                assert!((m.f2(tau) - q2).abs() < 1e-7);
            }
            assert!((m.integral() - simpson(|u| m.eval(u), 0.0, 1.0, n)).abs() < 1e-7);
            let qm = simpson(|u| u * m.eval(u), 0.0, 1.0, n);
            assert!((m.first_moment() - qm).abs() < 1e-7);
        }
    }

    #[test]
    fn j_k_p_identities() {
        // Identities hold to roundoff: 1e-12 relative to the O(1) m, m/s values.
        let mut rng = Rng::new(77);
        for _ in 0..50 {
            let fm = ForceModel {
                mass_kg: 40.0 + 60.0 * rng.next_f64(),
                dt_s: 0.1 + 0.5 * rng.next_f64(),
                axes: [
                    random_axis(&mut rng),
                    random_axis(&mut rng),
                    random_axis(&mut rng),
                ],
            };
            let (j, k, p) = (fm.j(), fm.k(), fm.p());
            for a in 0..3 {
                let ax = &fm.axes[a];
                // Exact: integral() is c0 for j ≥ 1 and j() multiplies in the same order.
                assert_eq!(j[a], ax.c0 * fm.dt_s / fm.mass_kg, "DFT basis: J = c0·Δt/m");
                assert!((p[a] - (fm.dt_s * j[a] - k[a])).abs() < 1e-12 * (1.0 + p[a].abs()));
                let sines: f64 = ax
                    .terms()
                    .map(|(jj, c, ph)| c * ph.sin() / (TAU * jj))
                    .sum();
                let p_dft = fm.dt_s * fm.dt_s / fm.mass_kg * (ax.c0 / 2.0 - sines);
                assert!((p[a] - p_dft).abs() < 1e-12 * (1.0 + p[a].abs()));
                assert!((fm.s(a, 1.0) - p[a]).abs() < 1e-15 * (1.0 + p[a].abs()));
                assert_eq!(fm.s(a, 0.0), 0.0);
            }
            assert!(fm.s(3, 0.5).is_nan());
        }
    }

    #[test]
    fn grid_sizes() {
        let with_j = |j: f64| ForceModel {
            mass_kg: 70.0,
            dt_s: 0.2,
            axes: [
                AxisModel::constant(0.0),
                AxisModel {
                    harmonics: vec![j.min(2.0), j],
                    amps: vec![1.0; 2],
                    phases: vec![0.0; 2],
                    ..Default::default()
                },
                AxisModel::constant(700.0),
            ],
        };
        let none = ForceModel {
            axes: Default::default(),
            ..with_j(1.0)
        };
        assert_eq!((none.j_max(), none.grid_len()), (0.0, 201));
        for (j, n) in [
            (1.0, 201),
            (12.0, 201),
            (13.0, 209),
            (12.5, 201),
            (31.5, 505),
            (100.0, 1601),
        ] {
            let fm = with_j(j);
            assert_eq!((fm.j_max(), fm.grid_len()), (j, n), "j_max = {j}");
            let g = fm.grid();
            assert_eq!(g.len(), n);
            assert_eq!((g[0], g[n - 1]), (0.0, 1.0));
            assert!((g[1] - 1.0 / (n - 1) as f64).abs() < 1e-17);
        }
        assert_eq!(with_j(f64::from(u32::MAX)).grid_len(), GRID_MAX_SAMPLES);
    }

    #[test]
    fn unilateral_flag_catches_a_pulling_dip() {
        // f_v = 500 + a cos 2πτ: min 500 − a at τ = ½ (a grid point), max 500 + a at the ends.
        let model = |a: f64| ForceModel {
            mass_kg: 70.0,
            dt_s: 0.25,
            axes: [
                AxisModel::constant(10.0),
                AxisModel::constant(0.0),
                AxisModel {
                    c0: 500.0,
                    harmonics: vec![1.0],
                    amps: vec![a],
                    phases: vec![0.0],
                    poly: Vec::new(),
                    fit_rms: 0.0,
                },
            ],
        };
        let pulling = model(600.0); // min −100 < −0.05·1100 = −55
        let g = pulling.grid();
        assert!((pulling.min_f_v(&g) + 100.0).abs() < 1e-9); // cos(π) roundoff on 600 N
        assert!(!pulling.unilateral_ok(&g));
        assert!(pulling.support_ok());
        let mild = model(520.0); // min −20 ≥ −0.05·1020 = −51
        assert!(mild.unilateral_ok(&g));
        let upside_down = ForceModel {
            axes: [
                AxisModel::constant(0.0),
                AxisModel::constant(0.0),
                AxisModel::constant(-1.0),
            ],
            ..mild
        };
        assert!(!upside_down.unilateral_ok(&g) && !upside_down.support_ok());
        assert!(mild.unilateral_ok(&[]) && mild.min_f_v(&[]) == f64::INFINITY);
    }
}
