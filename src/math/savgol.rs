//! Savitzky–Golay smoothing and differentiation, cubic, "interp" edge mode.
//!
//! # Model
//! ```text
//! Window W = 2h + 1 frames. Inside the clip, the value or derivative at frame i is the
//! least-squares polynomial of order p through frames i−h … i+h, evaluated at i:
//!   y⁽ᵈ⁾(i) = Σⱼ wⱼ⁽ᵈ⁾ · y(i + j) / dtᵈ,      j = −h … h
//! Within h frames of an end ("interp" mode) the polynomial is fitted once to the first
//! (last) W frames and evaluated at each edge frame.
//! W = max(5, 2·round(0.05·F) + 1),  F = 1/dt  (spec com-from-bvh §6, round half away from 0)
//! ```
//!
//! # Frames and units
//! `dt` in seconds; derivatives are per second (`m/s`, `m/s²` for positions in metres).
//!
//! # References
//! Savitzky & Golay (1964); scipy.signal.savgol_filter(mode="interp"); spec com-from-bvh §6.
//!
//! # Examples
//! ```
//! use stancelib::math::savgol::SavGol;
//! let sg = SavGol::new(7, 3).unwrap();
//! let dt = 0.01;
//! let y: Vec<f64> = (0..20).map(|i| { let t = i as f64 * dt; 2.0 * t * t }).collect();
//! let a = sg.apply(&y, 2, dt);
//! assert!(a.iter().all(|v| (v - 4.0).abs() < 1e-6));
//! ```

use nalgebra::{DMatrix, DVector};

/// Cubic order, used throughout (spec com-from-bvh §6).
pub const DEFAULT_ORDER: usize = 3;

/// The SG window for a frame rate: `W = max(5, 2·round(0.05·F) + 1)` frames.
pub fn window_for_rate(frame_rate_hz: f64) -> usize {
    // f64::round is half away from zero; the clamp keeps absurd rates from overflowing.
    let h = (0.05 * frame_rate_hz).round().clamp(0.0, 1e9) as usize;
    (2 * h + 1).max(5)
}

/// Precomputed SG weights for every evaluation position of a window and derivative 0–2.
#[derive(Debug, Clone)]
pub struct SavGol {
    window: usize,
    /// `weights[d][pos]`: the W weights giving derivative `d` at window position `pos`.
    weights: [Vec<Vec<f64>>; 3],
}

impl SavGol {
    /// Build the filter; `None` when the window is even, below `order + 2` or below 3.
    pub fn new(window: usize, order: usize) -> Option<SavGol> {
        if window.is_multiple_of(2) || window < order + 2 || window < 3 {
            return None;
        }
        let h = (window / 2) as f64;
        let a = DMatrix::from_fn(window, order + 1, |r, k| (r as f64 - h).powi(k as i32));
        let pinv = (a.transpose() * &a).try_inverse()? * a.transpose(); // (p+1) × W
        let mut weights: [Vec<Vec<f64>>; 3] = Default::default();
        for (d, wd) in weights.iter_mut().enumerate() {
            for pos in 0..window {
                let x = pos as f64 - h;
                let e = DVector::from_fn(order + 1, |k, _| deriv_monomial(k, d, x));
                wd.push((e.transpose() * &pinv).iter().copied().collect());
            }
        }
        Some(SavGol { window, weights })
    }

    /// The window length W.
    pub fn window(&self) -> usize {
        self.window
    }

    /// Derivative `deriv` (0, 1 or 2) of `y` sampled every `dt` seconds.
    ///
    /// Returns an empty vector when `y` is shorter than the window (callers skip such clips)
    /// or `deriv > 2`.
    pub fn apply(&self, y: &[f64], deriv: usize, dt: f64) -> Vec<f64> {
        let n = y.len();
        let w = self.window;
        if n < w || deriv > 2 {
            return Vec::new();
        }
        let h = w / 2;
        let scale = dt.powi(-(deriv as i32));
        let wd = &self.weights[deriv];
        let dot =
            |ws: &[f64], ys: &[f64]| ws.iter().zip(ys).map(|(a, b)| a * b).sum::<f64>() * scale;
        (0..n)
            .map(|i| {
                if i < h {
                    dot(&wd[i], &y[..w])
                } else if i + h >= n {
                    dot(&wd[i + w - n], &y[n - w..])
                } else {
                    dot(&wd[h], &y[i - h..=i + h])
                }
            })
            .collect()
    }
}

/// d-th derivative of xᵏ at x.
fn deriv_monomial(k: usize, d: usize, x: f64) -> f64 {
    if d > k {
        return 0.0;
    }
    let coef: f64 = ((k - d + 1)..=k).map(|v| v as f64).product();
    coef * x.powi((k - d) as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_match_the_spec_table() {
        for (f, w) in [
            (25.0, 5),
            (30.0, 5),
            (50.0, 7),
            (60.0, 7),
            (100.0, 11),
            (120.0, 13),
            (240.0, 25),
        ] {
            assert_eq!(window_for_rate(f), w, "{f} Hz");
        }
        assert_eq!(window_for_rate(1.0 / 0.0083333), 13);
    }

    #[test]
    fn cubic_is_reproduced_exactly_including_edges() {
        // A cubic lies in the fitted space, so every derivative is exact (to round-off).
        let sg = SavGol::new(13, 3).unwrap();
        let dt = 1.0 / 120.0;
        let f = |t: f64| 1.0 - 2.0 * t + 3.0 * t * t - 4.0 * t * t * t;
        let y: Vec<f64> = (0..40).map(|i| f(i as f64 * dt)).collect();
        let v = sg.apply(&y, 1, dt);
        let a = sg.apply(&y, 2, dt);
        for i in 0..40 {
            let t = i as f64 * dt;
            assert!((v[i] - (-2.0 + 6.0 * t - 12.0 * t * t)).abs() < 1e-8);
            assert!((a[i] - (6.0 - 24.0 * t)).abs() < 1e-5);
        }
    }

    #[test]
    fn short_input_gives_empty() {
        assert!(SavGol::new(13, 3)
            .unwrap()
            .apply(&[1.0; 5], 1, 0.01)
            .is_empty());
        assert!(SavGol::new(4, 3).is_none());
    }
}
