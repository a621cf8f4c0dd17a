//! Least-squares polynomial fits of degree 0–2 over a few samples.
//!
//! # Model
//! ```text
//! y(t) ≈ Σₖ aₖ (t − t̄)ᵏ,  k = 0 … deg,   minimising Σᵢ (yᵢ − y(tᵢ))²
//! fixed curvature: y(t) ≈ ½ a t² + a₁ (t − t̄) + a₀ with a given, fit a₀, a₁ to y − ½ a t²
//! ```
//! Times are centred at their mean `t̄` for conditioning.

use nalgebra::{DMatrix, DVector};

/// A fitted polynomial `y(t) = Σ coef[k] (t − t_mean)ᵏ`.
#[derive(Debug, Clone, PartialEq)]
pub struct Poly {
    /// Coefficients about `t_mean`, lowest order first.
    pub coef: Vec<f64>,
    /// Centre of the time axis, s.
    pub t_mean: f64,
}

impl Poly {
    /// Value at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        let x = t - self.t_mean;
        self.coef.iter().rev().fold(0.0, |acc, c| acc * x + c)
    }

    /// First derivative at `t`.
    pub fn deriv(&self, t: f64) -> f64 {
        let x = t - self.t_mean;
        self.coef
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (k, c)| acc * x + k as f64 * c)
    }

    /// Second derivative (constant for degree ≤ 2).
    pub fn curvature(&self) -> f64 {
        self.coef.get(2).map_or(0.0, |c| 2.0 * c)
    }
}

/// Fit a polynomial of degree `deg` to `(t, y)`; `None` with fewer than `deg + 1` samples
/// or a singular system.
pub fn fit(t: &[f64], y: &[f64], deg: usize) -> Option<Poly> {
    if t.len() != y.len() || t.len() < deg + 1 {
        return None;
    }
    let t_mean = t.iter().sum::<f64>() / t.len() as f64;
    let a = DMatrix::from_fn(t.len(), deg + 1, |r, k| (t[r] - t_mean).powi(k as i32));
    let b = DVector::from_column_slice(y);
    let sol = super::svd::svd(a, true, true)?.solve(&b, 1e-12).ok()?;
    Some(Poly {
        coef: sol.iter().copied().collect(),
        t_mean,
    })
}

/// Fit `y = ½·curv·t² + linear` with the curvature fixed; `None` with fewer than 2 samples.
pub fn fit_fixed_curvature(t: &[f64], y: &[f64], curv: f64) -> Option<Poly> {
    let t_mean = t.iter().sum::<f64>() / t.len().max(1) as f64;
    // ½ c t² = ½ c (x + t̄)² = ½ c x² + c t̄ x + ½ c t̄²  with x = t − t̄
    let r: Vec<f64> = t
        .iter()
        .zip(y)
        .map(|(ti, yi)| yi - 0.5 * curv * (ti - t_mean).powi(2))
        .collect();
    let lin = fit(t, &r, 1)?;
    Some(Poly {
        coef: vec![lin.coef[0], lin.coef[1], 0.5 * curv],
        t_mean,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_parabola() {
        let t: Vec<f64> = (0..10).map(|i| 1.0 + i as f64 * 0.01).collect();
        let y: Vec<f64> = t.iter().map(|t| -4.905 * t * t + 3.0 * t + 1.0).collect();
        let p = fit(&t, &y, 2).unwrap();
        assert!((p.curvature() + 9.81).abs() < 1e-8);
        assert!((p.deriv(1.05) - (-9.81 * 1.05 + 3.0)).abs() < 1e-8);
        assert!((p.eval(1.05) - (-4.905 * 1.05 * 1.05 + 3.0 * 1.05 + 1.0)).abs() < 1e-10);
        let q = fit_fixed_curvature(&t, &y, -9.81).unwrap();
        assert!((q.eval(1.02) - p.eval(1.02)).abs() < 1e-10);
        assert!(fit(&t[..2], &y[..2], 2).is_none());
    }
}
