//! The recording's COM detail: the part of a source stance's recorded COM path that its
//! force model does not carry, added back to the planned stance (displacement mapping).
//!
//! # Model
//! ```text
//! source stance, u = (t − t_TD)/(t_LO − t_TD) ∈ [0, 1], axes (h, p, v) of its heading:
//!   ρ(u) = [c_rec(u) − c_rec(0)] − [M(u) − M(0)]            recorded minus model displacement
//!   M: the force model the edit plays, at β = (1, β_p played, 1) from the stance's own
//!      start apex (zs, vs, vps, t_TD)
//! ρ through the source frames (natural cubic spline in u: ρ'' = 0 at both ends), then
//! made to join the plan with quintic shapes whose second derivatives vanish at both ends:
//!   d(u) = ρ(u) − ρ'(0) a_w(u) − ρ'(1) b_w(u) − q c(u)
//!   a(u) = u − 6u³ + 8u⁴ − 3u⁵,  b(u) = −4u³ + 7u⁴ − 3u⁵,  c(u) = 10u³ − 15u⁴ + 6u⁵
//!   a_w(u) = w·a(u/w) for u < w,  b_w(u) = w·b((u − 1 + w)/w) for u > 1 − w, else 0
//!   w = min(1, W/Δt), W = EDGE_WINDOW_S: each edge's slope correction acts over at most
//!     the stance's first or last 0.2 s (the whole of a running stance)
//!   ⇒ d(0) = 0, d'(0) = d'(1) = 0, d''(0) = d''(1) = 0, d(1) = ρ(1) − q, C² everywhere
//!   q_v = ρ_v(1)                         heights: the requested apexes are met exactly
//!   q_h = mean over a run's stances of ρ_h(1)    travel: the offsets along each
//!                                        stance's heading sum to 0 (the cycle's mean
//!                                        speed holds; each stance's own x moves by d_h(1))
//!   q_p = 0                              sideways: the recorded offset is kept (not requested)
//! a jump (from rest, to rest): its first touchdown and its last liftoff join no planned
//!   flight, so no correction there (ρ'(0) of the liftoff and ρ'(1), q of the landing
//!   are kept), and q_h = 0: the recorded offsets from the model are kept, as the
//!   recording has them (the library's jump distance is its model's, `x_m`)
//! planned stance at its own times: c(t) = c_model(t) + d(u(t)) in its axes, and the end
//!   offset d(1) carried by the flight after it (constant: the flight stays ballistic)
//! ```
//! Where a stance joins a planned flight, the planned velocity there, the flight times,
//! the apex heights and (over a run) the distance are the query's; the detail moves
//! positions inside the stance and by a constant afterwards, and adds no acceleration at
//! a joined touchdown or liftoff (`d'' = 0` there). A jump's travel is the model's
//! distance plus its recorded offsets, as its recording's is. Inside the stance the detail
//! implies a force `m·d̈` that the query's exact check (which judges the scaled model)
//! does not see: largest where an edge slope is corrected within its window, `ρ̇ ·
//! max|b''| / W` (max|b''| = 3.94), about 4.5 m/s² along the heading over the real
//! vertical jump's last 0.2 s of push (its recorded COM leaves 0.23 m/s faster than its
//! flight goes on), against 1.0 m/s² spread over the whole 0.9 s push. A request for the
//! recorded motion then gives back the recorded stance paths instead of the model's: the
//! CMU run's model path drifts 2.2 cm sideways and 1.2 cm along the travel from the
//! recording by the end of its first stance's flight (1.6 cm along the travel in the
//! second stance), which no soft position target in the fit removed without
//! spoiling the friction demand against the force plates (`docs/edited-motion.md`).
//!
//! # Frames and units
//! Metres, internal Z-up frame; stance axes `h, p, v` (index 0, 1, 2) of the source
//! stance's heading for the recording, of the planned stance's heading where it is added.
//!
//! # References
//! Witkin and Popović, *Motion Warping*, SIGGRAPH 1995 (displacement maps added to a
//! warped motion); Pollard and Behmaram-Mosavat §5 (the full body follows the edited COM).

use crate::math::spline::NaturalSpline;
use crate::math::v3::V3;

/// Fewest samples of a recorded stance (touchdown, liftoff and one frame between) for a
/// detail: with fewer the stance keeps the model's path.
pub const MIN_DETAIL_SAMPLES: usize = 3;

/// Most samples of a recorded stance: a stance longer than this many source frames is
/// sampled at this many even steps instead of at its frames (bounded work on any input).
pub const MAX_DETAIL_SAMPLES: usize = 4096;

/// The detail of one stance: the recorded residual `ρ(u)` and the corrections that make
/// it join the plan (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct StanceDetail {
    /// `ρ_a(u)` per stance axis.
    rho: [NaturalSpline; 3],
    /// `ρ'(0)` per axis (per unit `u`).
    slope0: V3,
    /// `ρ'(1)` per axis (per unit `u`).
    slope1: V3,
    /// The end offset removed, `q` per axis (m).
    removed: V3,
    /// The share `w ∈ (0, 1]` of the stance over which each edge's slope correction acts
    /// (module docs: `a_w`, `b_w`).
    window: f64,
}

/// How long each edge's slope correction acts at most, s: over `w = min(1, W/Δt_stance)` of
/// the stance (module docs). A running stance (0.15–0.27 s on the CMU run) is corrected
/// over nearly its whole length; the 0.9 s push of the real vertical jump only over its
/// last 0.2 s, so the recorded shape survives before it. That push's recorded COM leaves
/// 0.23 m/s faster along the heading than its flight goes on, a slope the plan must not
/// carry into the flight; spread over the whole push it moved the edit's root up to
/// 6.3 cm from the recording, over its last 0.5 / 0.3 / 0.2 s 3.8 / 2.5 / 2.4 cm (the CMU
/// run: 1.61 cm at 0.3 s and more, 1.60 at 0.2 s, 1.85 at 0.1 s; `docs/edited-motion.md`).
pub const EDGE_WINDOW_S: f64 = 0.2;

/// `(a_w, b_w, c)` of the module docs and their derivatives at `u`: the edge shapes act
/// over the first and the last share `w` of the stance (zero beyond, C² where they stop).
fn windowed_shapes(u: f64, w: f64) -> ([f64; 3], [f64; 3]) {
    let (mut s, mut ds) = shapes(u);
    if w < 1.0 {
        let (a, da) = shapes((u / w).min(1.0));
        let (b, db) = shapes(((u - 1.0 + w) / w).max(0.0));
        (s[0], ds[0]) = (w * a[0], da[0]);
        (s[1], ds[1]) = (w * b[1], db[1]);
    }
    (s, ds)
}

/// `(a, b, c)` of the module docs and their derivatives at `u`.
fn shapes(u: f64) -> ([f64; 3], [f64; 3]) {
    let (u2, u3, u4) = (u * u, u * u * u, u * u * u * u);
    let w2 = (1.0 - u) * (1.0 - u);
    (
        [
            u - 6.0 * u3 + 8.0 * u4 - 3.0 * u4 * u,
            -4.0 * u3 + 7.0 * u4 - 3.0 * u4 * u,
            u3 * (10.0 - 15.0 * u + 6.0 * u2),
        ],
        [
            1.0 - 18.0 * u2 + 32.0 * u3 - 15.0 * u4,
            -12.0 * u2 + 28.0 * u3 - 15.0 * u4,
            30.0 * u2 * w2,
        ],
    )
}

impl StanceDetail {
    /// A detail from samples `ρ(u_i)` (stance axes, m) at strictly increasing `u_i` from
    /// 0 to 1; `None` with fewer than [`MIN_DETAIL_SAMPLES`], knots not increasing or
    /// not spanning `[0, 1]`, or a value that is not finite.
    pub fn from_samples(u: &[f64], rho: &[V3]) -> Option<StanceDetail> {
        let spans = u.first() == Some(&0.0) && u.last() == Some(&1.0);
        let finite = rho.iter().flatten().all(|v| v.is_finite());
        if u.len() < MIN_DETAIL_SAMPLES || u.len() != rho.len() || !spans || !finite {
            return None;
        }
        let axis = |a: usize| {
            let y: Vec<f64> = rho.iter().map(|r| r[a] - rho[0][a]).collect();
            NaturalSpline::new(u, &y)
        };
        let rho = [axis(0)?, axis(1)?, axis(2)?];
        let slope0 = std::array::from_fn(|a| rho[a].derivative(0.0));
        let slope1 = std::array::from_fn(|a| rho[a].derivative(1.0));
        let mut d = StanceDetail {
            rho,
            slope0,
            slope1,
            removed: [0.0; 3],
            window: 1.0,
        };
        d.removed[2] = d.end_offset()[2];
        Some(d)
    }

    /// The same detail joined to the plan as `join` says (module docs): a free edge keeps
    /// the recording's slope there (and, at the end, its height offset); the edge slope
    /// corrections act over the share `window` of the stance (clamped to `(0, 1]`; 1 when
    /// not finite).
    pub fn joined(mut self, join: Join) -> StanceDetail {
        if !join.start {
            self.slope0 = [0.0; 3];
        }
        if !join.end {
            self.slope1 = [0.0; 3];
            self.removed = [0.0; 3];
        }
        self.window = if join.window.is_finite() && join.window > 0.0 {
            join.window.min(1.0)
        } else {
            1.0
        };
        self
    }

    /// `d(1)`: the offset the stance ends with (m, stance axes).
    pub fn end_offset(&self) -> V3 {
        std::array::from_fn(|a| self.rho[a].eval(1.0) - self.removed[a])
    }

    /// Removes `q_h` more of the travel offset (the edit's mean, [`balance_travel`]).
    fn remove_travel(&mut self, q_h: f64) {
        self.removed[0] += q_h;
    }

    /// `(d(u), d'(u))` (m, m per unit `u`), `u` clamped to `[0, 1]`; the derivative is 0
    /// outside.
    pub fn at(&self, u: f64) -> (V3, V3) {
        let inside = (0.0..=1.0).contains(&u);
        let u = u.clamp(0.0, 1.0);
        let (s, ds) = windowed_shapes(u, self.window);
        let mut p = [0.0; 3];
        let mut dp = [0.0; 3];
        for a in 0..3 {
            let r = &self.rho[a];
            p[a] =
                r.eval(u) - self.slope0[a] * s[0] - self.slope1[a] * s[1] - self.removed[a] * s[2];
            dp[a] = r.derivative(u)
                - self.slope0[a] * ds[0]
                - self.slope1[a] * ds[1]
                - self.removed[a] * ds[2];
        }
        (p, if inside { dp } else { [0.0; 3] })
    }
}

/// How a stance's detail meets the plan at its edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Join {
    /// Touchdown follows a planned flight: the detail starts with zero slope.
    pub start: bool,
    /// Liftoff starts a planned flight: the detail ends with zero slope and its height
    /// offset removed.
    pub end: bool,
    /// The share of the stance the edge corrections act over, `min(1, W/Δt)`
    /// ([`EDGE_WINDOW_S`]).
    pub window: f64,
}

/// Removes the mean travel offset of `details` from each (module docs: `q_h`), so that
/// their end offsets along the travel sum to 0 and a run's distance stays the query's.
pub fn balance_travel(details: &mut [Option<StanceDetail>]) {
    let ends: Vec<f64> = details
        .iter()
        .flatten()
        .map(|d| d.end_offset()[0])
        .collect();
    if ends.is_empty() {
        return;
    }
    let mean = ends.iter().sum::<f64>() / ends.len() as f64;
    details
        .iter_mut()
        .flatten()
        .for_each(|d| d.remove_travel(mean));
}

/// The samples `(u_i, ρ(u_i))` of a recorded stance: `u` at touchdown, at every source
/// frame strictly inside the stance and at liftoff, with the recorded COM `rec(t)` (world,
/// clip time `t`) and the model's own path `model(s)` (stance axes, time `s` from its start
/// apex); `to_stance` turns a world displacement into the source stance's axes.
///
/// `td, lo`: recorded touchdown and liftoff (clip time, s); `frame_time_s`: the source's
/// frame time; `model_td, model_lo`: the model's touchdown and liftoff (s from its apex).
/// A stance of no finite positive length gives its two edges only (and no detail).
pub fn recorded_residual(
    rec: impl Fn(f64) -> V3,
    model: impl Fn(f64) -> V3,
    to_stance: impl Fn(V3) -> V3,
    (td, lo): (f64, f64),
    frame_time_s: f64,
    (model_td, model_lo): (f64, f64),
) -> (Vec<f64>, Vec<V3>) {
    let span = lo - td;
    let mut u = vec![0.0];
    let frames = span / frame_time_s;
    let usable = td.is_finite() && span > 0.0 && frame_time_s > 0.0;
    if usable && frames <= MAX_DETAIL_SAMPLES as f64 {
        let first = (td / frame_time_s).floor() + 1.0;
        for i in 0..=frames.ceil() as usize {
            let x = ((first + i as f64) * frame_time_s - td) / span;
            // A frame within 1e-6 of an edge is that edge (knots must increase).
            if x > 1e-6 && x < 1.0 - 1e-6 {
                u.push(x);
            }
        }
    } else if usable {
        u.extend((1..MAX_DETAIL_SAMPLES).map(|i| i as f64 / MAX_DETAIL_SAMPLES as f64));
    }
    u.push(1.0);
    let (c0, m0) = (rec(td), model(model_td));
    let rho = u
        .iter()
        .map(|&x| {
            let c = rec(td + x * span);
            let m = model(model_td + x * (model_lo - model_td));
            let local = to_stance(std::array::from_fn(|a| c[a] - c0[a]));
            std::array::from_fn(|a| local[a] - (m[a] - m0[a]))
        })
        .collect();
    (u, rho)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth residual ending at (0.02, −0.01, 0.015) m; zero end slopes along the travel
    /// and sideways, 0.015 m per unit u at both ends vertically.
    fn wiggle(u: f64) -> V3 {
        let s = (std::f64::consts::PI * u).sin().powi(2);
        [
            0.02 * u * u * (3.0 - 2.0 * u) + 0.01 * s,
            -0.01 * u * u * (3.0 - 2.0 * u),
            0.015 * u + 0.005 * s,
        ]
    }

    fn sampled(n: usize, f: impl Fn(f64) -> V3) -> StanceDetail {
        let u: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
        let r: Vec<V3> = u.iter().map(|&x| f(x)).collect();
        StanceDetail::from_samples(&u, &r).unwrap()
    }

    #[test]
    fn detail_joins_the_plan_with_zero_offset_and_velocity_at_touchdown() {
        let d = sampled(30, wiggle);
        let (p0, v0) = d.at(0.0);
        let (_, v1) = d.at(1.0);
        for a in 0..3 {
            // Closed-form shape functions on spline values: roundoff only.
            assert!(p0[a].abs() < 1e-15, "d(0) = {p0:?}");
            assert!(
                v0[a].abs() < 1e-12 && v1[a].abs() < 1e-12,
                "d'(0) = {v0:?}, d'(1) = {v1:?}"
            );
        }
        // Heights end where the model ends; the horizontal offsets are kept.
        let end = d.end_offset();
        assert!(end[2].abs() < 1e-15);
        assert!((end[0] - 0.02).abs() < 1e-12 && (end[1] + 0.01).abs() < 1e-12);
        assert_eq!(d.at(1.0).0, end);
        assert_eq!(d.at(1.7), (end, [0.0; 3]));
    }

    #[test]
    fn shapes_have_the_end_values_slopes_and_zero_curvatures_they_are_built_for() {
        // (value, slope, curvature) of a, b, c at u = 0 and u = 1; curvature by a central
        // difference of the closed-form slope (step 1e-6: error ~1e-6 of the quintic's
        // third derivative, at most 36).
        let want = [
            [[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
        ];
        let h = 1e-6;
        for (end, u) in [0.0, 1.0].into_iter().enumerate() {
            let (v, d) = shapes(u);
            let (_, dp) = shapes(u + h);
            let (_, dm) = shapes(u - h);
            for k in 0..3 {
                let curv = (dp[k] - dm[k]) / (2.0 * h);
                let got = [v[k], d[k], curv];
                for i in 0..3 {
                    assert!(
                        (got[i] - want[k][end][i]).abs() < 1e-4,
                        "shape {k} at {u}: {got:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn detail_adds_no_acceleration_at_touchdown_or_liftoff() {
        // Nonzero end slopes and offsets on every axis; the natural spline has ρ'' = 0 at
        // the ends, so d'' = 0 there (forward/backward difference of d', step 1e-6: error
        // ~1e-6 |d'''| against curvatures of order 0.1 per unit u² inside).
        let d = sampled(30, |u| {
            [
                0.02 * u + 0.01 * u * u,
                -0.01 * u + 0.02 * u * u * u,
                0.015 * u,
            ]
        });
        let h = 1e-6;
        let (_, v0) = d.at(0.0);
        let (_, v0h) = d.at(h);
        let (_, v1) = d.at(1.0);
        let (_, v1h) = d.at(1.0 - h);
        let (_, vm) = d.at(0.5);
        let (_, vmh) = d.at(0.5 + h);
        for a in 0..3 {
            assert!(((v0h[a] - v0[a]) / h).abs() < 1e-4, "d''(0), axis {a}");
            assert!(((v1[a] - v1h[a]) / h).abs() < 1e-4, "d''(1), axis {a}");
        }
        assert!(
            ((vmh[0] - vm[0]) / h).abs() > 1e-3,
            "the detail does curve inside"
        );
    }

    #[test]
    fn a_residual_that_already_joins_is_reproduced() {
        // ρ with ρ'(0) = ρ'(1) = 0 and ρ_v(1) = 0 needs no correction: d = ρ to the
        // spline's error. Second derivatives vanish at the ends too (the natural spline's
        // end conditions): inside, h⁴ max|ρ⁗|/384 ≈ 1e-7 m at 30 knots; the end slopes the
        // spline estimates are off by O(h³ max|ρ⁗|/24) ≈ 4e-5 per unit u (ρ⁗ ≈ 23 m),
        // moving d by up to 4/27 of that (max of a(u)): about 3e-6 m near u = 0.4; bound
        // 1e-5 m, four orders below the centimetre detail it carries.
        let f = |u: f64| -> V3 {
            let s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
            let b = (std::f64::consts::PI * u).sin().powi(4);
            [0.02 * s, -0.01 * s + 0.004 * b, 0.006 * b]
        };
        let d = sampled(30, f);
        for i in 0..=100 {
            let u = i as f64 / 100.0;
            let (p, _) = d.at(u);
            let want = f(u);
            for a in 0..3 {
                assert!(
                    (p[a] - want[a]).abs() < 1e-5,
                    "u = {u}, axis {a}: {} vs {}",
                    p[a],
                    want[a]
                );
            }
        }
    }

    #[test]
    fn velocity_is_the_derivative_of_the_position() {
        let d = sampled(17, wiggle);
        let h = 1e-6;
        for &u in &[0.1, 0.33, 0.5, 0.8, 0.97] {
            let (p1, _) = d.at(u + h);
            let (p0, _) = d.at(u - h);
            let (_, v) = d.at(u);
            for a in 0..3 {
                // Central difference of a cubic: O(h²·|d'''|) ≈ 1e-12, plus roundoff 1e-10.
                assert!(((p1[a] - p0[a]) / (2.0 * h) - v[a]).abs() < 1e-7);
            }
        }
    }

    #[test]
    fn windowed_corrections_act_only_near_the_edges_and_keep_the_joins() {
        let join = |start, end, window| Join { start, end, window };
        // Nonzero end slopes on every axis, so every axis is corrected in both windows.
        let tilted = |u: f64| -> V3 {
            let w = wiggle(u);
            [w[0] + 0.012 * u, w[1] - 0.02 * u * u, w[2]]
        };
        let free = sampled(40, tilted).joined(join(false, false, 1.0));
        let w = 0.25;
        let d = sampled(40, tilted).joined(join(true, true, w));
        let (p0, v0) = d.at(0.0);
        let (_, v1) = d.at(1.0);
        assert!(p0.iter().chain(&v0).chain(&v1).all(|x| x.abs() < 1e-12));
        // Between the windows only the height offset's removal is left: q_v c(u).
        let q = free.end_offset()[2];
        for u in [0.25, 0.4, 0.6, 0.75] {
            let (p, pf) = (d.at(u).0, free.at(u).0);
            let c = shapes(u).0[2];
            assert!((p[0] - pf[0]).abs() < 1e-15 && (p[1] - pf[1]).abs() < 1e-15);
            assert!((p[2] - (pf[2] - q * c)).abs() < 1e-15, "u = {u}");
        }
        // C² where each window stops: the slope's one-sided rates of change agree
        // (step 1e-5: error ~1e-5 of the quintic's third derivative over w², about 1e-3).
        let h = 1e-5;
        for edge in [w, 1.0 - w] {
            let rate = |a: f64, b: f64| -> V3 {
                let (va, vb) = (d.at(a).1, d.at(b).1);
                std::array::from_fn(|i| (vb[i] - va[i]) / (b - a))
            };
            let (left, right) = (
                rate(edge - 2.0 * h, edge - h),
                rate(edge + h, edge + 2.0 * h),
            );
            for i in 0..3 {
                assert!(
                    (left[i] - right[i]).abs() < 1e-2,
                    "d'' at {edge}: {left:?} {right:?}"
                );
            }
        }
    }

    #[test]
    fn free_edges_keep_the_recorded_slopes_and_offsets() {
        // A jump's first touchdown and last liftoff: d = ρ, its end height offset included.
        let d = sampled(20, wiggle).joined(Join {
            start: false,
            end: false,
            window: 1.0,
        });
        for i in 0..=20 {
            let u = i as f64 / 20.0;
            let (p, want) = (d.at(u).0, wiggle(u));
            assert!((0..3).all(|a| (p[a] - want[a]).abs() < 1e-15), "u = {u}");
        }
        assert!((d.end_offset()[2] - 0.015).abs() < 1e-15);
        // ρ'_v(0) = 0.015 per unit u; the natural spline's end condition (ρ'' = 0 where the
        // wiggle's is 0.1) moves its estimate by about h·ρ''/3 ≈ 1.6e-3.
        let slope = d.at(0.0).1[2];
        assert!((slope - 0.015).abs() < 2.5e-3, "ρ'(0) kept: {slope}");
    }

    #[test]
    fn balanced_travel_offsets_sum_to_zero_and_keep_the_sideways_ones() {
        let mut ds = vec![
            Some(sampled(20, wiggle)),
            Some(sampled(20, |u| wiggle(u).map(|x| -0.5 * x))),
            None,
        ];
        balance_travel(&mut ds);
        let ends: Vec<V3> = ds.iter().flatten().map(StanceDetail::end_offset).collect();
        assert!((ends[0][0] + ends[1][0]).abs() < 1e-15);
        assert!((ends[0][1] + 0.01).abs() < 1e-12 && (ends[1][1] - 0.005).abs() < 1e-12);
        let (_, v) = ds[0].as_ref().unwrap().at(1.0);
        assert!(v.iter().all(|x| x.abs() < 1e-12));
    }

    #[test]
    fn residual_of_a_recording_that_is_the_model_is_zero() {
        // The recording is the model's own path, placed and turned in the world: ρ ≡ 0.
        // The model's stance lasts 0.3 s, the recording's 0.25 s: compared at the same u.
        let model = |s: f64| -> V3 { [3.0 * s + 0.2 * s * s, 0.1 * s * s, 1.0 - 0.5 * s * s] };
        let (hx, hy) = (0.6, -0.8);
        let to_stance = |w: V3| [hx * w[0] + hy * w[1], -hy * w[0] + hx * w[1], w[2]];
        let (td, model_td) = (2.0, 0.05);
        let rec = |t: f64| -> V3 {
            let l = model(model_td + (t - td) * 0.3 / 0.25);
            [
                5.0 + 0.6 * l[0] + 0.8 * l[1],
                -1.0 - 0.8 * l[0] + 0.6 * l[1],
                l[2],
            ]
        };
        let (u, rho) = recorded_residual(
            rec,
            model,
            to_stance,
            (td, td + 0.25),
            1.0 / 120.0,
            (model_td, model_td + 0.3),
        );
        assert_eq!(u.first(), Some(&0.0));
        assert_eq!(u.last(), Some(&1.0));
        assert!(u.windows(2).all(|w| w[1] > w[0]));
        assert_eq!(
            u.len(),
            31,
            "29 frames inside a 0.25 s stance at 120 Hz, and the edges"
        );
        assert!(rho.iter().flatten().all(|x| x.abs() < 1e-12), "{rho:?}");
    }

    #[test]
    fn odd_timings_give_bounded_samples_and_no_detail_when_unusable() {
        let zero = |_: f64| [0.0; 3];
        let (u, _) = recorded_residual(zero, zero, |w: V3| w, (f64::NAN, 1.0), 0.01, (0.0, 1.0));
        assert_eq!(u, [0.0, 1.0]);
        let (u, rho) = recorded_residual(zero, zero, |w: V3| w, (0.0, 1e6), 1e-3, (0.0, 1.0));
        assert_eq!(u.len(), MAX_DETAIL_SAMPLES + 1);
        assert!(StanceDetail::from_samples(&u, &rho).is_some());
    }

    #[test]
    fn too_few_or_bad_samples_give_no_detail() {
        let r = [[0.0; 3]; 3];
        assert!(StanceDetail::from_samples(&[0.0, 1.0], &r[..2]).is_none());
        assert!(StanceDetail::from_samples(&[0.0, 0.5, 0.9], &r).is_none());
        assert!(StanceDetail::from_samples(&[0.0, 0.6, 0.5, 1.0], &[[0.0; 3]; 4]).is_none());
        let nan = [[0.0; 3], [f64::NAN, 0.0, 0.0], [0.0; 3]];
        assert!(StanceDetail::from_samples(&[0.0, 0.5, 1.0], &nan).is_none());
    }
}
