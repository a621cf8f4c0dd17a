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
//! Memory is O(W·p): the filter keeps the interior kernel of each derivative (one row of W
//! weights) and the least-squares fit `(AᵀA)⁻¹Aᵀ` ((p+1) × W); the weights of an edge frame
//! (`eᵀ·(AᵀA)⁻¹Aᵀ`, e the derivative of the monomials at that frame) are formed when used,
//! in one W-long scratch row, with the same arithmetic as a precomputed table would use.
//! Windows above [`MAX_SAVGOL_WINDOW`] are refused before any allocation.
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

use crate::error::{Error, ErrorKind, Result};

/// Cubic order, used throughout (spec com-from-bvh §6).
pub const DEFAULT_ORDER: usize = 3;

/// Half-width of the SG window, seconds: `h = round(SAVGOL_HALF_WINDOW_S · F)` frames
/// (spec com-from-bvh §6).
pub const SAVGOL_HALF_WINDOW_S: f64 = 0.05;

/// Shortest SG window, frames (spec com-from-bvh §6).
pub const MIN_SAVGOL_WINDOW: usize = 5;

/// Longest SG window, frames. `W = 2·round(0.05·F) + 1` reaches it at a frame rate of
/// about 10 kHz (frame time 0.1 ms); a clip with a shorter frame time is a per-clip error
/// naming its frame time and window. The filter's memory is about `8·W` bytes per row
/// (5 rows), so the bound is on work (`W` multiply-adds per frame and derivative), not on
/// memory.
pub const MAX_SAVGOL_WINDOW: usize = 1001;

/// The SG window for a frame rate: `W = max(5, 2·round(0.05·F) + 1)` frames.
pub fn window_for_rate(frame_rate_hz: f64) -> usize {
    // f64::round is half away from zero; the clamp keeps absurd rates from overflowing.
    let h = (SAVGOL_HALF_WINDOW_S * frame_rate_hz)
        .round()
        .clamp(0.0, 1e9) as usize;
    (2 * h + 1).max(MIN_SAVGOL_WINDOW)
}

/// The SG window of a clip with this frame time, checked against [`MAX_SAVGOL_WINDOW`]
/// (no allocation: callers check before any per-frame work).
///
/// # Errors
/// `ErrorKind::Smoothing`, naming the frame time and the window, above the bound.
pub fn window_for_frame_time(frame_time_s: f64) -> Result<usize> {
    let window = window_for_rate(1.0 / frame_time_s);
    if window > MAX_SAVGOL_WINDOW {
        return Err(window_error(
            Some(frame_time_s),
            window,
            format!(
                "longer than the limit of {MAX_SAVGOL_WINDOW} frames (frame rates up to about \
                 10 kHz)"
            ),
        ));
    }
    Ok(window)
}

/// SG filter: the interior kernels of derivatives 0–2 and the least-squares fit of one
/// window, from which the edge weights are formed when applied (O(W·p) memory).
#[derive(Debug, Clone)]
pub struct SavGol {
    window: usize,
    order: usize,
    /// `kernel[d]`: the W weights giving derivative `d` at the window centre.
    kernel: [Vec<f64>; 3],
    /// `(AᵀA)⁻¹Aᵀ`, (p+1) × W: polynomial coefficients (in frames from the centre) of one
    /// window's values.
    pinv: DMatrix<f64>,
}

fn window_error(frame_time_s: Option<f64>, window: usize, msg: impl Into<String>) -> Error {
    ErrorKind::Smoothing {
        frame_time_s,
        window,
        msg: msg.into(),
    }
    .into()
}

impl SavGol {
    /// Build the filter for a window of `window` frames and polynomial order `order`.
    ///
    /// # Errors
    /// `ErrorKind::Smoothing` when the window is even, below `order + 2` or 3, above
    /// [`MAX_SAVGOL_WINDOW`] (refused before any allocation), or its normal equations are
    /// singular.
    pub fn new(window: usize, order: usize) -> Result<SavGol> {
        Self::build(window, order, None)
    }

    /// Build the filter of a clip: window [`window_for_rate`]`(1/frame_time_s)`.
    ///
    /// # Errors
    /// As [`SavGol::new`]; the error names the frame time and the window (frames and s).
    pub fn for_frame_time(frame_time_s: f64, order: usize) -> Result<SavGol> {
        Self::build(
            window_for_frame_time(frame_time_s)?,
            order,
            Some(frame_time_s),
        )
    }

    fn build(window: usize, order: usize, frame_time_s: Option<f64>) -> Result<SavGol> {
        if window > MAX_SAVGOL_WINDOW {
            return Err(window_error(
                frame_time_s,
                window,
                format!("longer than the limit of {MAX_SAVGOL_WINDOW} frames"),
            ));
        }
        if window.is_multiple_of(2) || window < order + 2 || window < 3 {
            return Err(window_error(
                frame_time_s,
                window,
                format!(
                    "must be odd, at least 3 and at least order + 2 = {}",
                    order + 2
                ),
            ));
        }
        let pinv = fit_matrix(window, order)
            .ok_or_else(|| window_error(frame_time_s, window, "singular normal equations"))?;
        let kernel = std::array::from_fn(|d| row_weights(&pinv, order, d, window / 2));
        Ok(SavGol {
            window,
            order,
            kernel,
            pinv,
        })
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
        let dot =
            |ws: &[f64], ys: &[f64]| ws.iter().zip(ys).map(|(a, b)| a * b).sum::<f64>() * scale;
        let edge =
            |pos: usize, ys: &[f64]| dot(&row_weights(&self.pinv, self.order, deriv, pos), ys);
        let kernel = &self.kernel[deriv];
        (0..n)
            .map(|i| {
                if i < h {
                    edge(i, &y[..w])
                } else if i + h >= n {
                    edge(i + w - n, &y[n - w..])
                } else {
                    dot(kernel, &y[i - h..=i + h])
                }
            })
            .collect()
    }
}

/// `(AᵀA)⁻¹Aᵀ` with `A[r][k] = (r − h)ᵏ`, r = 0 … W−1; `None` when `AᵀA` is singular.
fn fit_matrix(window: usize, order: usize) -> Option<DMatrix<f64>> {
    let h = (window / 2) as f64;
    let a = DMatrix::from_fn(window, order + 1, |r, k| (r as f64 - h).powi(k as i32));
    Some((a.transpose() * &a).try_inverse()? * a.transpose())
}

/// The W weights giving derivative `d` at window position `pos`: `eᵀ·(AᵀA)⁻¹Aᵀ`.
fn row_weights(pinv: &DMatrix<f64>, order: usize, d: usize, pos: usize) -> Vec<f64> {
    let x = pos as f64 - (pinv.ncols() / 2) as f64;
    let e = DVector::from_fn(order + 1, |k, _| deriv_monomial(k, d, x));
    (e.transpose() * pinv).iter().copied().collect()
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
        assert!(SavGol::new(4, 3).is_err());
    }

    /// The filter as it was before issue 11: every position's weights precomputed
    /// (3·W² values), kept as the reference for the O(W) filter.
    fn dense_reference(window: usize, order: usize, y: &[f64], deriv: usize, dt: f64) -> Vec<f64> {
        let h = (window / 2) as f64;
        let a = DMatrix::from_fn(window, order + 1, |r, k| (r as f64 - h).powi(k as i32));
        let pinv = (a.transpose() * &a).try_inverse().unwrap() * a.transpose();
        let mut weights: [Vec<Vec<f64>>; 3] = Default::default();
        for (d, wd) in weights.iter_mut().enumerate() {
            for pos in 0..window {
                let x = pos as f64 - h;
                let e = DVector::from_fn(order + 1, |k, _| deriv_monomial(k, d, x));
                wd.push((e.transpose() * &pinv).iter().copied().collect());
            }
        }
        let (n, w, h) = (y.len(), window, window / 2);
        let scale = dt.powi(-(deriv as i32));
        let wd = &weights[deriv];
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

    // See: issue 11 item 3 — the O(W) filter gives today's dense-table results.
    #[test]
    fn savgol_memory_bomb_o_w_filter_equals_the_dense_reference() {
        let mut rng = crate::testkit::Rng::new(11);
        for &(w, order) in &[(5, 3), (7, 3), (13, 3), (25, 3), (41, 3), (9, 2), (11, 4)] {
            let sg = SavGol::new(w, order).unwrap();
            for &(n, dt) in &[(w, 0.01), (w + 1, 1.0 / 120.0), (3 * w + 7, 1.0 / 30.0)] {
                let y: Vec<f64> = (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect();
                for d in 0..3 {
                    let got = sg.apply(&y, d, dt);
                    let want = dense_reference(w, order, &y, d, dt);
                    assert_eq!(got.len(), n);
                    for (i, (g, r)) in got.iter().zip(&want).enumerate() {
                        // Same arithmetic: equal to the bit; 1e-12 relative is the contract.
                        let tol = 1e-12 * dt.powi(-(d as i32)).max(1.0);
                        assert!(
                            (g - r).abs() <= tol,
                            "W {w} p {order} n {n} d {d} i {i}: {g} vs {r}"
                        );
                        assert_eq!(g.to_bits(), r.to_bits(), "W {w} d {d} i {i}");
                    }
                }
            }
        }
    }

    // See: issue 11 item 3 — windows above the bound are refused before any allocation.
    #[test]
    fn savgol_memory_bomb_window_above_the_bound_is_an_error_naming_frame_time_and_window() {
        let w_max_rate = window_for_rate(1e5); // frame time 1e-5 s, the parser's minimum
        assert_eq!(w_max_rate, 10001);
        let e = SavGol::for_frame_time(1e-5, DEFAULT_ORDER).unwrap_err();
        match &e.kind {
            ErrorKind::Smoothing {
                frame_time_s,
                window,
                ..
            } => {
                assert_eq!(*frame_time_s, Some(1e-5));
                assert_eq!(*window, 10001);
            }
            k => panic!("unexpected {k:?}"),
        }
        let msg = e.to_string();
        assert!(msg.contains("10001") && msg.contains("0.00001"), "{msg}");
        assert!(SavGol::new(MAX_SAVGOL_WINDOW, DEFAULT_ORDER).is_ok());
        assert!(SavGol::new(MAX_SAVGOL_WINDOW + 2, DEFAULT_ORDER).is_err());
        // The largest accepted window still reproduces a cubic's slope in the interior.
        let sg = SavGol::new(MAX_SAVGOL_WINDOW, DEFAULT_ORDER).unwrap();
        let dt = 1e-4;
        let y: Vec<f64> = (0..MAX_SAVGOL_WINDOW + 10)
            .map(|i| {
                let t = i as f64 * dt;
                t - 3.0 * t * t
            })
            .collect();
        let v = sg.apply(&y, 1, dt);
        let mid = y.len() / 2;
        let t = mid as f64 * dt;
        assert!((v[mid] - (1.0 - 6.0 * t)).abs() < 1e-6, "{}", v[mid]);
    }
}
