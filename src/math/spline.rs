//! Natural cubic spline through `(t_k, y_k)` with strictly increasing knots.
//!
//! # Model
//! ```text
//! On [t_k, t_{k+1}], h_k = t_{k+1} − t_k, u = t − t_k, w = t_{k+1} − t:
//!   S(t) = M_k w³/(6h_k) + M_{k+1} u³/(6h_k)
//!        + (y_k − M_k h_k²/6) w/h_k + (y_{k+1} − M_{k+1} h_k²/6) u/h_k
//! M_k = S''(t_k) solve the tridiagonal system (k = 1 … n−2)
//!   h_{k−1} M_{k−1} + 2(h_{k−1} + h_k) M_k + h_k M_{k+1}
//!     = 6 [(y_{k+1} − y_k)/h_k − (y_k − y_{k−1})/h_{k−1}]
//! with the natural end conditions M_0 = M_{n−1} = 0.
//! Outside [t_0, t_{n−1}] the spline continues as the straight line through the end
//! point with the end slope: S(t) = y_0 + S'(t_0)(t − t_0) before, likewise after.
//! Because M = 0 at both ends this extension is C² (value, slope and curvature match).
//! ```
//! Two knots give the straight line through them.
//!
//! # Frames and units
//! Unit-free: `t` and `y` carry whatever units the caller uses (seconds and m/s² for the
//! Stage A acceleration, spec stance-model §4.1 step 2); derivatives are per unit of `t`.
//!
//! # References
//! de Boor, *A Practical Guide to Splines* (1978), ch. IV; Press et al., *Numerical
//! Recipes* 3rd ed. §3.3 (eq 3.3.7); the same values as scipy
//! `CubicSpline(t, y, bc_type="natural")` inside the knots.
//!
//! # Examples
//! ```
//! use stancelib::math::spline::NaturalSpline;
//! let s = NaturalSpline::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0]).unwrap();
//! assert!((s.eval(0.5) - 0.6875).abs() < 1e-12);
//! assert!(NaturalSpline::new(&[0.0, 0.0], &[1.0, 2.0]).is_none()); // knots not increasing
//! ```

/// A natural cubic spline: knots, values and second derivatives at the knots.
#[derive(Debug, Clone, PartialEq)]
pub struct NaturalSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    /// `m[k] = S''(t_k)`; `m[0] = m[n−1] = 0`.
    m: Vec<f64>,
}

impl NaturalSpline {
    /// Fit the natural cubic spline through `(t[k], y[k])`.
    ///
    /// Returns `None` when the lengths differ, there are fewer than 2 points, a value is
    /// not finite, or `t` is not strictly increasing.
    pub fn new(t: &[f64], y: &[f64]) -> Option<NaturalSpline> {
        let n = t.len();
        if n != y.len() || n < 2 {
            return None;
        }
        if t.iter().chain(y).any(|v| !v.is_finite()) || t.windows(2).any(|w| w[1] <= w[0]) {
            return None;
        }
        let mut m = vec![0.0; n];
        if n > 2 {
            // Thomas algorithm on the interior unknowns M_1 … M_{n−2}. The system is
            // strictly diagonally dominant, so no pivoting is needed.
            let k_in = n - 2;
            let mut diag = vec![0.0; k_in];
            let mut rhs = vec![0.0; k_in];
            let mut upper = vec![0.0; k_in];
            for i in 0..k_in {
                let k = i + 1;
                let h0 = t[k] - t[k - 1];
                let h1 = t[k + 1] - t[k];
                diag[i] = 2.0 * (h0 + h1);
                upper[i] = h1;
                rhs[i] = 6.0 * ((y[k + 1] - y[k]) / h1 - (y[k] - y[k - 1]) / h0);
            }
            for i in 1..k_in {
                let lower = t[i + 1] - t[i]; // h_{k−1} of row i (k = i + 1)
                let w = lower / diag[i - 1];
                diag[i] -= w * upper[i - 1];
                rhs[i] -= w * rhs[i - 1];
            }
            m[k_in] = rhs[k_in - 1] / diag[k_in - 1];
            for i in (0..k_in - 1).rev() {
                m[i + 1] = (rhs[i] - upper[i] * m[i + 2]) / diag[i];
            }
        }
        Some(NaturalSpline {
            t: t.to_vec(),
            y: y.to_vec(),
            m,
        })
    }

    /// The knots `t_k` (strictly increasing, at least two).
    pub fn knots(&self) -> &[f64] {
        &self.t
    }

    /// Index `k` of the interval `[t_k, t_{k+1}]` holding `t` (clamped to the end intervals).
    fn interval(&self, t: f64) -> usize {
        let n = self.t.len();
        // Number of knots ≤ t, minus one, kept in 0 … n−2.
        self.t.partition_point(|&tk| tk <= t).clamp(1, n - 1) - 1
    }

    /// Value, slope and curvature at `t` (the linear extension outside the knots).
    fn eval_all(&self, t: f64) -> [f64; 3] {
        if t.is_nan() {
            return [f64::NAN; 3];
        }
        let n = self.t.len();
        let (first, last) = (self.t[0], self.t[n - 1]);
        if t < first || t > last {
            let (k, end) = if t < first { (0, first) } else { (n - 2, last) };
            let at_end = if t < first { 0 } else { n - 1 };
            let slope = self.slope_in(k, end);
            return [self.y[at_end] + slope * (t - end), slope, 0.0];
        }
        let k = self.interval(t);
        [self.value_in(k, t), self.slope_in(k, t), self.curv_in(k, t)]
    }

    fn value_in(&self, k: usize, t: f64) -> f64 {
        let h = self.t[k + 1] - self.t[k];
        let (u, w) = (t - self.t[k], self.t[k + 1] - t);
        let (m0, m1) = (self.m[k], self.m[k + 1]);
        (m0 * w * w * w + m1 * u * u * u) / (6.0 * h)
            + (self.y[k] - m0 * h * h / 6.0) * w / h
            + (self.y[k + 1] - m1 * h * h / 6.0) * u / h
    }

    fn slope_in(&self, k: usize, t: f64) -> f64 {
        let h = self.t[k + 1] - self.t[k];
        let (u, w) = (t - self.t[k], self.t[k + 1] - t);
        let (m0, m1) = (self.m[k], self.m[k + 1]);
        (m1 * u * u - m0 * w * w) / (2.0 * h) + (self.y[k + 1] - self.y[k]) / h
            - (m1 - m0) * h / 6.0
    }

    fn curv_in(&self, k: usize, t: f64) -> f64 {
        let h = self.t[k + 1] - self.t[k];
        (self.m[k] * (self.t[k + 1] - t) + self.m[k + 1] * (t - self.t[k])) / h
    }

    /// `S(t)`; outside the knots the linear (C²) extension of the module docs; NaN for NaN.
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_all(t)[0]
    }

    /// `S'(t)`, per unit of `t` (constant outside the knots).
    pub fn derivative(&self, t: f64) -> f64 {
        self.eval_all(t)[1]
    }

    /// `S''(t)`, per unit of `t`² (0 at the end knots and outside them).
    pub fn second_derivative(&self, t: f64) -> f64 {
        self.eval_all(t)[2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Tolerances: the spline is exact in exact arithmetic for these cases; 1e-12 absolute
    // covers the O(10) roundoff of the tridiagonal solve on O(1) data.
    const TOL: f64 = 1e-12;

    #[test]
    fn reproduces_a_linear_function() {
        let t = [0.0, 0.3, 0.35, 1.0, 2.5, 2.6];
        let y: Vec<f64> = t.iter().map(|&x| 3.0 - 2.0 * x).collect();
        let s = NaturalSpline::new(&t, &y).unwrap();
        for i in 0..=40 {
            let x = -0.5 + 0.1 * i as f64; // includes both extrapolated sides
            assert!((s.eval(x) - (3.0 - 2.0 * x)).abs() < TOL, "x = {x}");
            assert!((s.derivative(x) + 2.0).abs() < TOL);
        }
    }

    #[test]
    fn matches_hand_computed_values() {
        // Uniform: M1 = −3, S(0.5) = −3/48 + 0.75 (worked by hand; scipy agrees).
        let s = NaturalSpline::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0]).unwrap();
        assert!((s.eval(0.5) - 0.6875).abs() < TOL);
        assert!((s.eval(1.5) - 0.6875).abs() < TOL);
        assert!((s.second_derivative(1.0) + 3.0).abs() < TOL);
        // Non-uniform t = (0, 1, 3), y = (0, 2, 0): 6·M1 = 6(−1 − 2) → M1 = −3;
        // S(t) = −t³/2 + 5t/2 on [0, 1], S(2) = −3/12 + 4/2 = 1.75.
        let s = NaturalSpline::new(&[0.0, 1.0, 3.0], &[0.0, 2.0, 0.0]).unwrap();
        assert!((s.eval(0.5) - 1.1875).abs() < TOL);
        assert!((s.eval(2.0) - 1.75).abs() < TOL);
    }

    #[test]
    fn second_derivative_is_zero_at_the_ends_and_continuous_inside() {
        let t: Vec<f64> = (0..12)
            .map(|i| i as f64 * 0.1 + 0.01 * (i * i) as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|&x| (3.0 * x).sin() + x * x).collect();
        let s = NaturalSpline::new(&t, &y).unwrap();
        assert_eq!(s.second_derivative(t[0]), 0.0);
        assert!(s.second_derivative(t[11]).abs() < TOL);
        for k in 1..11 {
            let e = 1e-9; // one-sided limits, ~h·|S'''| away from the knot value
            let (l, r) = (s.second_derivative(t[k] - e), s.second_derivative(t[k] + e));
            assert!((l - r).abs() < 1e-6, "curvature jump at knot {k}");
            let (l, r) = (s.eval(t[k] - e), s.eval(t[k] + e));
            assert!((l - y[k]).abs() < 1e-8 && (r - y[k]).abs() < 1e-8);
        }
        // The linear extension is C¹ at the ends: a finite-difference slope straddling
        // the end matches S' there (step 1e-6, error O(step·|S''|) = O(1e-6)).
        let h = 1e-6;
        let fd = (s.eval(t[11] + h) - s.eval(t[11] - h)) / (2.0 * h);
        assert!((fd - s.derivative(t[11])).abs() < 1e-5);
    }

    #[test]
    fn interpolates_the_knots_and_rejects_bad_input() {
        let t = [0.0, 0.5, 0.7, 2.0];
        let y = [1.0, -1.0, 4.0, 0.5];
        let s = NaturalSpline::new(&t, &y).unwrap();
        for k in 0..4 {
            assert!((s.eval(t[k]) - y[k]).abs() < TOL);
        }
        assert!(s.eval(f64::NAN).is_nan());
        assert!(NaturalSpline::new(&[0.0], &[1.0]).is_none());
        assert!(NaturalSpline::new(&[0.0, 1.0], &[1.0]).is_none());
        assert!(NaturalSpline::new(&[0.0, 1.0, 0.5], &[1.0, 2.0, 3.0]).is_none());
        assert!(NaturalSpline::new(&[0.0, f64::NAN], &[1.0, 2.0]).is_none());
        let two = NaturalSpline::new(&[1.0, 3.0], &[0.0, 4.0]).unwrap();
        assert!((two.eval(2.0) - 2.0).abs() < TOL && (two.eval(5.0) - 8.0).abs() < TOL);
    }
}
