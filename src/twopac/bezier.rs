//! Bezier COM curves with one or two attractor points (two-pac §5, eq 7–9).
//!
//! # Model
//!
//! ```text
//! c(t) = Σ_{k=0}^{n} B_k^n(t) P_k,   t ∈ [0, 1],   real duration T (s)
//! ċ = c'(t)/T ,   c̈ = c''(t)/T²                                             (m/s, m/s²)
//! P_0 = c_0        P_1 = P_0 + T v_0/n        P_2 = T² a_0/(n(n−1)) + 2P_1 − P_0
//! P_n = c_1        P_{n−1} = P_n − T v_1/n    P_{n−2} = T² a_1/(n(n−1)) + 2P_{n−1} − P_n
//! attractors:  n = 5 + k,  P_3 … P_{2+k} = the k transition points (k = 1: eq 8, k = 2: eq 9)
//! ```
//!
//! Kinematic guarantee (§5.4): if every control point satisfies `K P_k ≤ k + 1e-9 m`, the
//! whole curve does (convex hull property); every control point is checked and each
//! violation is reported, never hidden. The kept part `[0, u]` of a window is checked on
//! its own control points (de Casteljau split), which lie in the hull of the originals.
//!
//! # Frames and units
//!
//! World frame, metres; `t` normalised; `T` in seconds.
//!
//! # References
//!
//! Tonneau et al., 2PAC, eq 7–9 (the "B_k^7(t) P_i" typo read as `P_k`); spec two-pac §5.

use super::polytope::Polytope;
use super::v3::{add, scale, sub};
use super::TwopacError;

/// Tolerance of the kinematic guarantee (§5.4), m.
pub const GUARANTEE_TOL_M: f64 = 1e-9;

/// A COM state: position (m), velocity (m/s), acceleration (m/s²).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ComState {
    /// Position, m.
    pub pos: [f64; 3],
    /// Velocity, m/s.
    pub vel: [f64; 3],
    /// Acceleration, m/s².
    pub acc: [f64; 3],
}

impl ComState {
    /// At rest at `pos`.
    pub fn at_rest(pos: [f64; 3]) -> ComState {
        ComState {
            pos,
            ..ComState::default()
        }
    }
}

/// A Bezier curve in ℝ³ on `t ∈ [0, 1]` (degree = number of control points − 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Bezier {
    /// Control points `P_0 … P_n`, m.
    pub control: Vec<[f64; 3]>,
}

/// De Casteljau evaluation of the curve with control points `p` at `t`.
fn casteljau(p: &[[f64; 3]], t: f64) -> [f64; 3] {
    let mut w = p.to_vec();
    let n = w.len();
    for r in 1..n {
        for i in 0..n - r {
            w[i] = add(scale(1.0 - t, w[i]), scale(t, w[i + 1]));
        }
    }
    w.first().copied().unwrap_or([0.0; 3])
}

impl Bezier {
    /// Degree `n`.
    pub fn degree(&self) -> usize {
        self.control.len().saturating_sub(1)
    }

    /// `c(t)`, m.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        casteljau(&self.control, t)
    }

    /// `c'(t) = n Σ B_k^{n−1}(t) (P_{k+1} − P_k)` (normalised time), m.
    pub fn d1(&self, t: f64) -> [f64; 3] {
        let n = self.degree();
        if n == 0 {
            return [0.0; 3];
        }
        let d: Vec<[f64; 3]> = self
            .control
            .windows(2)
            .map(|w| scale(n as f64, sub(w[1], w[0])))
            .collect();
        casteljau(&d, t)
    }

    /// `c''(t) = n(n−1) Σ B_k^{n−2}(t) (P_{k+2} − 2P_{k+1} + P_k)` (normalised time), m.
    pub fn d2(&self, t: f64) -> [f64; 3] {
        let n = self.degree();
        if n < 2 {
            return [0.0; 3];
        }
        let f = (n * (n - 1)) as f64;
        let d: Vec<[f64; 3]> = self
            .control
            .windows(3)
            .map(|w| scale(f, add(sub(w[2], scale(2.0, w[1])), w[0])))
            .collect();
        casteljau(&d, t)
    }

    /// The real-time state at `t` for a curve spanning `duration_s`.
    pub fn state(&self, t: f64, duration_s: f64) -> ComState {
        ComState {
            pos: self.eval(t),
            vel: scale(1.0 / duration_s, self.d1(t)),
            acc: scale(1.0 / (duration_s * duration_s), self.d2(t)),
        }
    }

    /// The curve on `[0, u]` re-parametrised to `[0, 1]` (de Casteljau split).
    pub fn left(&self, u: f64) -> Bezier {
        let mut w = self.control.clone();
        let n = w.len();
        let mut out = Vec::with_capacity(n);
        for r in 0..n {
            out.push(w[0]);
            for i in 0..n - r - 1 {
                w[i] = add(scale(1.0 - u, w[i]), scale(u, w[i + 1]));
            }
        }
        Bezier { control: out }
    }

    /// The curve of §5.1–5.3: boundary states `start`, `end` over `duration_s`, with
    /// 0, 1 (eq 8, degree 6) or 2 (eq 9, degree 7) attractor points.
    ///
    /// # Errors
    ///
    /// [`TwopacError::InvalidCurve`] for more than 2 attractors or a non-positive or
    /// non-finite duration.
    pub fn with_attractors(
        start: &ComState,
        end: &ComState,
        duration_s: f64,
        attractors: &[[f64; 3]],
    ) -> Result<Bezier, TwopacError> {
        if attractors.len() > 2 {
            return Err(TwopacError::InvalidCurve {
                msg: format!(
                    "{} attractors (at most 2 carry the guarantee)",
                    attractors.len()
                ),
            });
        }
        if !(duration_s.is_finite() && duration_s > 0.0) {
            return Err(TwopacError::InvalidCurve {
                msg: format!("duration must be positive and finite, found {duration_s} s"),
            });
        }
        let n = 5 + attractors.len();
        let nf = n as f64;
        let t = duration_s;
        let a = t * t / (nf * (nf - 1.0));
        let p0 = start.pos;
        let p1 = add(p0, scale(t / nf, start.vel));
        let p2 = add(sub(scale(2.0, p1), p0), scale(a, start.acc));
        let pn = end.pos;
        let pn1 = sub(pn, scale(t / nf, end.vel));
        let pn2 = add(sub(scale(2.0, pn1), pn), scale(a, end.acc));
        let mut control = vec![p0, p1, p2];
        control.extend_from_slice(attractors);
        control.extend_from_slice(&[pn2, pn1, pn]);
        Ok(Bezier { control })
    }
}

/// A control point outside the window's kinematic polytope (§5.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlViolation {
    /// Index `k` of `P_k`.
    pub index: usize,
    /// `max(K P_k − k)`, m (> [`GUARANTEE_TOL_M`]).
    pub violation_m: f64,
}

/// Every control point of `curve` checked against `kin` (§5.4); empty means the whole
/// curve is inside.
pub fn check_control_points(curve: &Bezier, kin: &Polytope) -> Vec<ControlViolation> {
    curve
        .control
        .iter()
        .enumerate()
        .filter_map(|(index, &p)| {
            let v = kin.max_violation(p);
            (v > GUARANTEE_TOL_M).then_some(ControlViolation {
                index,
                violation_m: v,
            })
        })
        .collect()
}
