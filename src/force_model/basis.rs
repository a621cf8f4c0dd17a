//! Closed-form integrals and moments of one cosine term, for any `Ω ≥ 0`.
//!
//! # Model
//! ```text
//! term(τ) = cos(Ωτ + φ)                       τ normalized stance time, Ω rad per unit τ
//! F1(τ) = ∫₀^τ cos(Ωu+φ) du                  = (sin(Ωτ+φ) − sin φ)/Ω
//! F2(τ) = ∫₀^τ∫₀ˢ cos(Ωu+φ) du ds             = (cos φ − cos(Ωτ+φ))/Ω² − τ sin φ/Ω
//! I1 = F1(1),  D = F2(1),  M1 = ∫₀¹ τ cos(Ωτ+φ) dτ = I1 − D
//!    = sin(Ω+φ)/Ω + (cos(Ω+φ) − cos φ)/Ω²
//! For Ω = 2πj (j ≥ 1 integer): I1 = 0, M1 = sin φ/Ω, D = −sin φ/Ω.
//! ```
//! Written as `cos φ·cos Ωu − sin φ·sin Ωu`, with `x = Ωτ`:
//! ```text
//! F1(τ) = τ  [cos φ · g1(x) − sin φ · x·g2(x)]      g1(x) = sin x / x        → 1
//! F2(τ) = τ² [cos φ · g2(x) − sin φ · x·g3(x)]      g2(x) = (1 − cos x)/x²   → 1/2
//!                                                   g3(x) = (x − sin x)/x³   → 1/6
//! ```
//! This form has no `1/Ω` blow-up: it is exact at `Ω = 0` (F1 = τ cos φ,
//! F2 = τ² cos φ / 2) and keeps full relative accuracy for small `Ωτ`, where the textbook
//! form cancels (g3 uses its Taylor series below |x| = 0.25).
//!
//! # Frames and units
//! Unit-free: multiply by the term's amplitude (N) to get N (F1: N per unit τ, etc.).
//!
//! # References
//! Spec stance-model §5 ("closed form, any Ω"), which corrects the paper's eq 20–22.

use std::f64::consts::TAU;

/// Below this |x| = |Ωτ|, `g3` uses its Taylor series (next term < 2e-16 relative).
const G3_SERIES_BELOW: f64 = 0.25;

/// `sin x / x`, 1 at 0.
fn g1(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.sin() / x
    }
}

/// `(1 − cos x)/x² = 2 sin²(x/2)/x²`, ½ at 0 (the half-angle form does not cancel).
fn g2(x: f64) -> f64 {
    if x == 0.0 {
        0.5
    } else {
        let s = (0.5 * x).sin();
        2.0 * s * s / (x * x)
    }
}

/// `(x − sin x)/x³`, 1/6 at 0.
fn g3(x: f64) -> f64 {
    if x.abs() < G3_SERIES_BELOW {
        // Σₙ (−1)ⁿ x²ⁿ/(2n+3)!, n = 0…4
        let x2 = x * x;
        1.0 / 6.0 - x2 / 120.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0)))
    } else {
        (x - x.sin()) / (x * x * x)
    }
}

/// `F1(τ) = ∫₀^τ cos(Ωu + φ) du` for any `Ω` (rad per unit τ), `φ` (rad).
pub fn f1(omega: f64, phi: f64, tau: f64) -> f64 {
    let x = omega * tau;
    tau * (phi.cos() * g1(x) - phi.sin() * x * g2(x))
}

/// `F2(τ) = ∫₀^τ∫₀ˢ cos(Ωu + φ) du ds` for any `Ω` (rad per unit τ), `φ` (rad).
pub fn f2(omega: f64, phi: f64, tau: f64) -> f64 {
    let x = omega * tau;
    tau * tau * (phi.cos() * g2(x) - phi.sin() * x * g3(x))
}

/// `I1 = ∫₀¹ cos(Ωτ + φ) dτ` (0 for `Ω = 2πj`, `j ≥ 1`).
pub fn i1(omega: f64, phi: f64) -> f64 {
    f1(omega, phi, 1.0)
}

/// `D = ∫₀¹∫₀ˢ cos(Ωu + φ) du ds = I1 − M1`.
pub fn d(omega: f64, phi: f64) -> f64 {
    f2(omega, phi, 1.0)
}

/// `M1 = ∫₀¹ τ cos(Ωτ + φ) dτ = I1 − D`.
pub fn m1(omega: f64, phi: f64) -> f64 {
    i1(omega, phi) - d(omega, phi)
}

/// `Ω = 2πj` for a harmonic of `j` cycles per stance (rad per unit τ). The Fourier model's
/// harmonics are integers (the paper's DFT terms) or halves (the half-range cosines
/// `cos(πkτ) = cos(2π(k/2)τ)` of [`super::cosine`]).
pub fn omega_of(j: f64) -> f64 {
    TAU * j
}

/// `cos(Ω + φ)`, `sin(Ω + φ)` at the stance's end, `Ω = 2πj`: exactly `(cos φ, sin φ)` for an
/// integer `j` and `(−cos φ, −sin φ)` for a half-integer one (no `sin(2πj)` roundoff).
fn end_value(j: f64, phi: f64) -> (f64, f64) {
    let (sin_phi, cos_phi) = phi.sin_cos();
    if j.fract() == 0.0 {
        (cos_phi, sin_phi)
    } else if (2.0 * j).fract() == 0.0 {
        (-cos_phi, -sin_phi)
    } else {
        let (s, c) = (omega_of(j) + phi).sin_cos();
        (c, s)
    }
}

/// `I1` for a harmonic of `j` cycles: exactly 0 for an integer `j ≥ 1`, `cos φ` for `j = 0`,
/// `−2 sin φ/Ω` for a half-integer `j` (`sin(Ω+φ) = −sin φ`), the general form otherwise.
pub fn i1_harmonic(j: f64, phi: f64) -> f64 {
    if j == 0.0 {
        return phi.cos();
    }
    let (_, sin_end) = end_value(j, phi);
    (sin_end - phi.sin()) / omega_of(j)
}

/// `M1` for a harmonic of `j` cycles: `sin φ/(2πj)` for an integer `j ≥ 1`, `cos φ / 2` for
/// `j = 0`, and `C_1` of [`harmonic_power_moments`] otherwise.
pub fn m1_harmonic(j: f64, phi: f64) -> f64 {
    if j == 0.0 {
        0.5 * phi.cos()
    } else if j.fract() == 0.0 {
        phi.sin() / omega_of(j)
    } else {
        harmonic_power_moments(j, phi, 1)[1]
    }
}

/// `∫₀¹ cos(2πj₁τ + φ₁) cos(2πj₂τ + φ₂) dτ = ½ [I1(j₁ + j₂, φ₁ + φ₂) + I1(|j₁ − j₂|, ±(φ₁ − φ₂))]`
/// for harmonics of `j₁, j₂ ≥ 0` cycles (the product-to-sum identity; `cos` is even, so the
/// difference term takes the phase of the larger frequency's term minus the other's).
pub fn product_integral(j1: f64, phi1: f64, j2: f64, phi2: f64) -> f64 {
    let (dj, dphi) = if j1 >= j2 {
        (j1 - j2, phi1 - phi2)
    } else {
        (j2 - j1, phi2 - phi1)
    };
    0.5 * (i1_harmonic(j1 + j2, phi1 + phi2) + i1_harmonic(dj, dphi))
}

/// `P(τ) = Σ_k p_k τ^k` by Horner's rule (N for force coefficients).
pub fn poly_eval(p: &[f64], tau: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, &c| acc * tau + c)
}

/// `∫₀¹ τⁿ P(τ) dτ = Σ_k p_k / (k + n + 1)`.
pub fn poly_moment(p: &[f64], n: usize) -> f64 {
    p.iter()
        .enumerate()
        .map(|(k, &c)| c / (k + n + 1) as f64)
        .sum()
}

/// `F1(τ) = ∫₀^τ P = Σ_k p_k τ^(k+1)/(k+1)`.
pub fn poly_f1(p: &[f64], tau: f64) -> f64 {
    p.iter()
        .enumerate()
        .rev()
        .fold(0.0, |acc, (k, &c)| acc * tau + c / (k + 1) as f64)
        * tau
}

/// `F2(τ) = ∫₀^τ∫₀ˢ P = Σ_k p_k τ^(k+2)/((k+1)(k+2))`.
pub fn poly_f2(p: &[f64], tau: f64) -> f64 {
    p.iter().enumerate().rev().fold(0.0, |acc, (k, &c)| {
        acc * tau + c / ((k + 1) * (k + 2)) as f64
    }) * tau
        * tau
}

/// Coefficients of `F2(τ) = ∫₀^τ∫₀ˢ P` in the power basis: `[0, 0, p_0/2, p_1/6, …]`.
pub fn poly_f2_coeffs(p: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; p.len() + 2];
    for (k, &c) in p.iter().enumerate() {
        out[k + 2] = c / ((k + 1) * (k + 2)) as f64;
    }
    out
}

/// Product of two power-basis polynomials.
pub fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, &x) in a.iter().enumerate() {
        for (j, &y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// `C_n = ∫₀¹ τⁿ cos(2πjτ + φ) dτ` for `n = 0 … n_max` and a harmonic of `j > 0` cycles.
///
/// ```text
/// C_0 = (sin(Ω+φ) − sin φ)/Ω,   S_0 = (cos φ − cos(Ω+φ))/Ω,   Ω = 2πj
/// C_n = (sin(Ω+φ) − n S_(n−1))/Ω,   S_n = (n C_(n−1) − cos(Ω+φ))/Ω        (n ≥ 1)
/// ```
/// (`S_n = ∫₀¹ τⁿ sin(Ωτ + φ) dτ`, integration by parts; for an integer `j`,
/// `sin(Ω+φ) = sin φ`, `cos(Ω+φ) = cos φ` and `C_0 = S_0 = 0`; for a half-integer, their
/// negatives.) The upward recursion multiplies errors by `n/Ω` per step, below 1 for
/// `n < Ω`; over `n ≤ 24` and `j ≥ ½` the product stays below 10⁴ (the tests bound it).
pub fn harmonic_power_moments(j: f64, phi: f64, n_max: usize) -> Vec<f64> {
    let omega = omega_of(j);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let (cos_end, sin_end) = end_value(j, phi);
    let mut out = Vec::with_capacity(n_max + 1);
    let (mut c, mut s) = ((sin_end - sin_phi) / omega, (cos_phi - cos_end) / omega);
    out.push(c);
    for n in 1..=n_max {
        let nf = n as f64;
        let c_n = (sin_end - nf * s) / omega;
        let s_n = (nf * c - cos_end) / omega;
        (c, s) = (c_n, s_n);
        out.push(c);
    }
    out
}

/// Composite Simpson rule of `f` over `[a, b]` with `n` (made even) intervals; tests only.
#[cfg(test)]
pub(crate) fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let n = (n + n % 2).max(2);
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Intervals for Simpson; error ≤ (b−a)h⁴/180·Ω⁴ ≈ 4e-12 at Ω = 40, h = 1/4000.
    const N_SIMPSON: usize = 4000;

    fn simpson_tol(omega: f64) -> f64 {
        // Simpson bound for |f⁗| ≤ Ω⁴ (×τ² ≤ 1 for F2's (τ−s) weight, whose extra
        // derivatives add ≤ 4Ω³), plus 1e-13 for summing 4000 terms.
        let h = 1.0 / N_SIMPSON as f64;
        h.powi(4) / 180.0 * (omega.powi(4) + 4.0 * omega.powi(3)) + 1e-13
    }

    #[test]
    fn closed_forms_match_simpson_for_any_omega() {
        // Integer harmonics, a DCT basis Ω = πk, generic values, tiny Ω (series branch)
        // and Ω = 0.
        let omegas = [
            0.0,
            1e-7,
            0.01,
            0.2,
            1.0,
            3.7,
            5.0 * std::f64::consts::PI,
            TAU,
            37.699,
        ];
        let phis = [0.0, 0.4, -1.3, 2.9];
        for &om in &omegas {
            for &ph in &phis {
                let tol = simpson_tol(om);
                for &tau in &[0.0, 0.13, 0.5, 0.77, 1.0] {
                    let q1 = simpson(|u| (om * u + ph).cos(), 0.0, tau, N_SIMPSON);
                    let q2 = simpson(|u| (tau - u) * (om * u + ph).cos(), 0.0, tau, N_SIMPSON);
                    assert!(
                        (f1(om, ph, tau) - q1).abs() < tol,
                        "F1 Ω={om} φ={ph} τ={tau}"
                    );
                    assert!(
                        (f2(om, ph, tau) - q2).abs() < tol,
                        "F2 Ω={om} φ={ph} τ={tau}"
                    );
                }
                let qm = simpson(|u| u * (om * u + ph).cos(), 0.0, 1.0, N_SIMPSON);
                assert!((m1(om, ph) - qm).abs() < tol, "M1 Ω={om} φ={ph}");
            }
        }
    }

    #[test]
    fn stable_form_equals_the_textbook_form() {
        // Moderate Ω, where the spec's literal §5 formulas do not cancel: agreement to
        // 1e-14 (a few ulps of O(1) values).
        for &om in &[0.9, 2.5, 3.7, TAU, 9.42, 30.0] {
            for &ph in &[0.0, 0.7, -2.2] {
                let i1_spec = ((om + ph).sin() - ph.sin()) / om;
                let m1_spec = (om + ph).sin() / om + ((om + ph).cos() - ph.cos()) / (om * om);
                let d_spec = (ph.cos() - (om + ph).cos()) / (om * om) - ph.sin() / om;
                assert!((i1(om, ph) - i1_spec).abs() < 1e-14);
                assert!((m1(om, ph) - m1_spec).abs() < 1e-14);
                assert!((d(om, ph) - d_spec).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn polynomial_closed_forms_match_simpson() {
        // A degree-8 polynomial with O(1e3 N) coefficients: Simpson is exact to 1e-9 here
        // (h⁴/180·max|P⁗| ≈ 2e-13·1e7).
        let p = [
            120.0, 3000.0, -4100.0, 900.0, 1500.0, -800.0, 60.0, -300.0, 210.0,
        ];
        for &tau in &[0.0, 0.3, 0.71, 1.0] {
            let q1 = simpson(|u| poly_eval(&p, u), 0.0, tau, N_SIMPSON);
            let q2 = simpson(|u| (tau - u) * poly_eval(&p, u), 0.0, tau, N_SIMPSON);
            assert!((poly_f1(&p, tau) - q1).abs() < 1e-9, "F1 at {tau}");
            assert!((poly_f2(&p, tau) - q2).abs() < 1e-9, "F2 at {tau}");
            assert!((poly_eval(&poly_f2_coeffs(&p), tau) - q2).abs() < 1e-9);
        }
        for n in 0..3 {
            let q = simpson(|u| u.powi(n as i32) * poly_eval(&p, u), 0.0, 1.0, N_SIMPSON);
            assert!((poly_moment(&p, n) - q).abs() < 1e-9, "moment {n}");
        }
        let b = [2.0, -1.0, 0.5];
        let ab = poly_mul(&p, &b);
        for &tau in &[0.1, 0.9] {
            let want = poly_eval(&p, tau) * poly_eval(&b, tau);
            assert!((poly_eval(&ab, tau) - want).abs() < 1e-9);
        }
    }

    #[test]
    fn harmonic_power_moments_match_simpson() {
        // Up to τ²⁰ for integer harmonics, τ⁸ for half-integer ones (the recursion's error
        // growth ∏ n/Ω stays below 10 there), against Simpson (error ≤ h⁴/180·max|f⁗|
        // ≈ 3e-16·(Ω+20)⁴ ≤ 1e-10).
        for (j, n_max) in [
            (1.0, 20),
            (2.0, 20),
            (5.0, 20),
            (0.5, 8),
            (1.5, 8),
            (3.5, 8),
        ] {
            for &ph in &[0.0, 0.8, -2.4, std::f64::consts::PI] {
                let c = harmonic_power_moments(j, ph, n_max);
                let om = omega_of(j);
                for (n, &cn) in c.iter().enumerate() {
                    let q = simpson(
                        |u| u.powi(n as i32) * (om * u + ph).cos(),
                        0.0,
                        1.0,
                        N_SIMPSON,
                    );
                    assert!((cn - q).abs() < 1e-10, "j={j} φ={ph} n={n}: {cn} vs {q}");
                }
                assert!((c[1] - m1_harmonic(j, ph)).abs() < 1e-15);
                assert!((c[0] - i1_harmonic(j, ph)).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn product_integrals_match_simpson() {
        // Integer and half-integer harmonics, equal and unequal, with phases; Simpson's
        // error ≤ h⁴/180·(Ω₁+Ω₂)⁴ ≈ 1e-12 here.
        let js = [0.0, 0.5, 1.0, 1.5, 2.0, 3.5];
        for &j1 in &js {
            for &j2 in &js {
                for &(p1, p2) in &[(0.0, 0.0), (0.3, -1.2), (std::f64::consts::PI, 0.0)] {
                    let (o1, o2) = (omega_of(j1), omega_of(j2));
                    let q = simpson(
                        |u| (o1 * u + p1).cos() * (o2 * u + p2).cos(),
                        0.0,
                        1.0,
                        N_SIMPSON,
                    );
                    let got = product_integral(j1, p1, j2, p2);
                    assert!((got - q).abs() < 1e-11, "j {j1}, {j2}: {got} vs {q}");
                }
            }
        }
    }

    #[test]
    fn integer_harmonics_have_the_special_values() {
        // Ω = 2πj: I1 = 0, M1 = sin φ/Ω, D = −sin φ/Ω (a few ulps of sin(2πj) roundoff).
        for j in (1..=31).map(f64::from) {
            let om = omega_of(j);
            for &ph in &[0.3, -1.1, 3.0] {
                assert!(i1(om, ph).abs() < 1e-14);
                assert!((m1(om, ph) - m1_harmonic(j, ph)).abs() < 1e-14);
                assert!((d(om, ph) + ph.sin() / om).abs() < 1e-14);
                assert_eq!(i1_harmonic(j, ph), 0.0);
            }
        }
        assert!((m1_harmonic(0.0, 0.5) - m1(0.0, 0.5)).abs() < 1e-15);
        assert!((i1_harmonic(0.0, 0.5) - i1(0.0, 0.5)).abs() < 1e-15);
        // Half-integer j (Ω = π(2j)): I1 = −2 sin φ/Ω, and the general forms agree.
        for j in [0.5, 1.5, 2.5] {
            let om = omega_of(j);
            for &ph in &[0.3, -1.1, 3.0] {
                assert!((i1_harmonic(j, ph) + 2.0 * ph.sin() / om).abs() < 1e-15);
                assert!((i1_harmonic(j, ph) - i1(om, ph)).abs() < 1e-14);
                assert!((m1_harmonic(j, ph) - m1(om, ph)).abs() < 1e-14);
            }
        }
    }
}
