//! Sub-frame touchdown and liftoff times of the contact runs.
//!
//! # Model
//! ```text
//! event test of a point p at frame k:  r_p(k) = max(h_p(k)/H, v_p(k)/V)   (met ⇔ r ≤ 1)
//!   H = 0.03 m (height above the point's floor, §7.1); V = 3.0 m/s at touchdown, 2.0 m/s
//!   at liftoff (unsmoothed 3-D speed, §6); R(k) = min_p r_p(k) over the effector's points
//! touchdown of a run a..b: the frame k nearest a (at most 0.05 s away, not into the
//!   previous run) with R(k−1) > 1 ≥ R(k);  t_TD = t[k−1] + dt·(R(k−1) − 1)/(R(k−1) − R(k))
//! liftoff: the frame k nearest b with R(k) ≤ 1 < R(k+1);
//!   t_LO = t[k] + dt·(1 − R(k))/(R(k+1) − R(k))
//! no such frame: the frame-edge times t[a] − dt/2, t[b] + dt/2 of §7.3
//! ```
//! The detector's hysteresis (§7.3: enter at 4 cm and 2 m/s, leave at 6 cm or 2 m/s) decides
//! *whether* and *in which frames* a foot is in contact; the event test decides *when*
//! inside the frame interval the contact began or ended, by linear interpolation of the
//! test value between the two frames that straddle it. The detector keeps its thresholds:
//! they separate a swing foot from a planted one; the event thresholds are the state of
//! the foot at the instant the plates see the contact begin or end.
//!
//! # Why these numbers
//! At a running touchdown the heel is already within 2–3 cm of its stance height but still
//! moves at 2–3 m/s (the captured foot decelerates over about 50 ms), so the 2 m/s enter
//! gate is met about a frame after the plate's 20 N threshold; at liftoff the toe tip
//! rises through a few centimetres before the detector's 6 cm. Measured against the two
//! force-plate clips (60 Hz run, 100 Hz drop jump; mean |error| in ms per foot, L/R):
//!
//! | event | frame edge (§7.3) | sub-frame, H 3 cm, V 3.0 / 2.0 m/s |
//! |---|---|---|
//! | run touchdown | 22.1 / 21.9 (late) | 5.1 / 6.7 |
//! | run liftoff | 24.1 / 20.8 (late) | 2.7 / 2.8 |
//! | drop-jump touchdown | 10.0 / 10.2 | 4.4 / 7.0 |
//! | drop-jump liftoff | 2.0 / 1.9 | 4.3 / 1.7 |
//!
//! Neighbouring values do as well (H 2–3 cm, touchdown V 3.0–3.25 m/s, liftoff V ≥ 2 m/s
//! all stay within 0.7 of the target, half a frame + 5 ms); a 4 cm height puts the
//! drop-jump touchdowns 7–11 ms early, a 2.5 m/s touchdown speed leaves the run 13 ms
//! late.
//!
//! # References
//! spec com-from-bvh §6, §7.1, §7.3 (event times); issue 12 item 4.

use super::detect::PointTrack;

/// Event height above the point's floor, m.
pub const EVENT_H_M: f64 = 0.03;
/// Touchdown event speed, m/s.
pub const EVENT_TD_V_MPS: f64 = 3.0;
/// Liftoff event speed, m/s.
pub const EVENT_LO_V_MPS: f64 = 2.0;
/// Farthest an event is looked for from the run's edge frame, s.
pub const EVENT_MAX_SHIFT_S: f64 = 0.05;

fn test_value(points: &[PointTrack], k: usize, v: f64) -> f64 {
    points
        .iter()
        .map(|p| (p.h[k] / EVENT_H_M).max(p.v[k] / v))
        .fold(f64::INFINITY, f64::min)
}

fn max_shift(t: &[f64]) -> usize {
    let dt = if t.len() > 1 { t[1] - t[0] } else { 1.0 };
    ((EVENT_MAX_SHIFT_S / dt).round() as usize).max(1)
}

/// Sub-frame touchdown of the run `a..=b` (`a ≥ 1`); `lo` is the first frame it may reach
/// back to (after the effector's previous run), s.
pub fn touchdown(points: &[PointTrack], t: &[f64], a: usize, b: usize, lo: usize) -> f64 {
    let r = |k: usize| test_value(points, k, EVENT_TD_V_MPS);
    let shift = max_shift(t);
    let lo = lo.max(1).max(a.saturating_sub(shift));
    let mut k = a;
    while k > lo && r(k - 1) <= 1.0 {
        k -= 1;
    }
    let hi = b.min(a + shift);
    while k < hi && r(k) > 1.0 {
        k += 1;
    }
    let (r0, r1) = (r(k - 1), r(k));
    if r0 > 1.0 && r1 <= 1.0 && r0.is_finite() {
        t[k - 1] + (t[k] - t[k - 1]) * (r0 - 1.0) / (r0 - r1)
    } else {
        t[a] - (t[a] - t[a - 1]) / 2.0
    }
}

/// Sub-frame liftoff of the run `a..=b` (`b + 1 < t.len()`); `hi` is the last frame it
/// may reach forward to (before the effector's next run), s.
pub fn liftoff(points: &[PointTrack], t: &[f64], a: usize, b: usize, hi: usize) -> f64 {
    let r = |k: usize| test_value(points, k, EVENT_LO_V_MPS);
    let shift = max_shift(t);
    let hi = hi.min(t.len() - 2).min(b + shift);
    let mut k = b;
    while k < hi && r(k + 1) <= 1.0 {
        k += 1;
    }
    let lo = a.max(b.saturating_sub(shift));
    while k > lo && r(k) > 1.0 {
        k -= 1;
    }
    let (r0, r1) = (r(k), r(k + 1));
    if r0 <= 1.0 && r1 > 1.0 && r1.is_finite() {
        t[k] + (t[k + 1] - t[k]) * (1.0 - r0) / (r1 - r0)
    } else {
        t[b] + (t[b + 1] - t[b]) / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_interpolate_the_test_between_the_straddling_frames() {
        let t: Vec<f64> = (0..10).map(|k| k as f64 * 0.01).collect();
        // Speed falls 5 → 1 m/s over frames 2..4 at floor height; rises again at 7..8.
        let v = [5.0, 5.0, 4.0, 2.0, 1.0, 0.5, 0.5, 1.0, 3.0, 5.0];
        let p = PointTrack {
            h: vec![0.0; 10],
            v: v.to_vec(),
        };
        // Touchdown: r = v/3 crosses 1 between frames 2 (4/3) and 3 (2/3): half-way.
        let td = touchdown(std::slice::from_ref(&p), &t, 4, 7, 0);
        assert!((td - 0.025).abs() < 1e-12, "{td}");
        // Liftoff: r = v/2 crosses 1 between frames 7 (0.5) and 8 (1.5): half-way.
        let lo = liftoff(std::slice::from_ref(&p), &t, 4, 7, 9);
        assert!((lo - 0.075).abs() < 1e-12, "{lo}");
        // A point that never meets the event test: the frame-edge times.
        let far = PointTrack {
            h: vec![1.0; 10],
            v: vec![0.0; 10],
        };
        assert!((touchdown(std::slice::from_ref(&far), &t, 4, 7, 0) - 0.035).abs() < 1e-12);
        assert!((liftoff(std::slice::from_ref(&far), &t, 4, 7, 9) - 0.075).abs() < 1e-12);
    }
}
