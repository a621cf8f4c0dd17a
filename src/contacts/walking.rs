//! Touchdown and liftoff times of a foot that steps while the other foot supports the body
//! (walking): the foot's speed against the body's own speed.
//!
//! # Model
//! ```text
//! R(k) = min_p v_p(k) / max(|v_COM,h(k)|, V_min)     p ∈ the foot's points (ankle, toe tip)
//!   v_p: unsmoothed 3-D point speed (§6), m/s; v_COM,h: horizontal SG COM speed, m/s
//! touchdown: the frame k nearest the run's first frame a (at most REACH forward, 0.05 s
//!   back, not into the previous run) with R(k−1) > κ_TD ≥ R(k);
//!   t_TD = t[k−1] + dt·(R(k−1) − κ_TD)/(R(k−1) − R(k))
//! liftoff: the frame k nearest the run's last frame b (at most REACH back, 0.05 s
//!   forward) with R(k) ≤ κ_LO < R(k+1);  t_LO = t[k] + dt·(κ_LO − R(k))/(R(k+1) − R(k))
//! applies to a touchdown (liftoff) of a foot when the other foot is in contact over the
//!   MIN_SUPPORT before (after) the run's edge frame, or up to the clip's edge: a step
//!   into (out of) double support
//! κ_TD = 0.65, κ_LO = 0.75, V_min = 0.5 m/s, REACH = 0.15 s, MIN_SUPPORT = 0.1 s
//! ```
//! The planted foot is still and the body moves at `v_COM,h`; a swinging foot moves at
//! about twice the body's speed. At heel strike the ankle is still carried forward by
//! the foot's rotation about the heel, at about two thirds of the body's speed; at toe-off
//! the toe tip leaves the floor at about three quarters of it. A ratio to the body's own
//! speed holds across walking speeds, where the fixed heights and speeds of
//! [`super::timing`] (3 cm, 3 m/s) are met long before a walking heel strikes: the ankle
//! of a walking foot hangs 2–4 cm above its stance height and moves below 3 m/s through
//! the last 70–110 ms of swing.
//!
//! # Why these numbers
//! κ_TD and κ_LO were chosen by leaving one walk out (the three force-plate walks: a 100 Hz
//! overground walk, a 60 Hz treadmill walk, a 200 Hz synthetic walk whose forces are the
//! model's own). Chosen on two walks, the third's errors against its plates (20 N) were,
//! in ms: touchdown −21, +1 / +19, +27 / −9; liftoff +10, +1 / 0, −3 / −1, −1. Chosen on all
//! three (the defaults): touchdown −21, +1 / +1, +4 / −9; liftoff +10, +1 / 0, −3 / −1, −1
//! (the frame-edge rule of §7.3 with [`super::timing`]: touchdowns 26–106 ms early,
//! liftoffs 2–37 ms late). `tests/per_contact.rs` prints them. Zeni's heel-forward
//! extremum (the ankle's largest lead over the COM) was 18–42 ms early on the same walks.
//!
//! # References
//! Zeni, Richards & Higginson (2008), Gait & Posture 27:710 (kinematic gait events from
//! positions relative to the body); O'Connor et al. (2007), Gait & Posture 25:469 (foot
//! velocity algorithm); spec com-from-bvh §6, §7.3.

use super::detect::PointTrack;
use super::timing::EVENT_MAX_SHIFT_S;

/// Touchdown ratio κ_TD: the foot's slowest point at this fraction of the body's speed.
pub const DEFAULT_WALK_TD_RATIO: f64 = 0.65;
/// Liftoff ratio κ_LO.
pub const DEFAULT_WALK_LO_RATIO: f64 = 0.75;
/// Least body speed the ratio divides by, m/s (a step in place still has a threshold).
pub const WALK_MIN_BODY_SPEED_MPS: f64 = 0.5;
/// Farthest an event is looked for inside the run from its edge frame, s.
pub const WALK_EVENT_REACH_S: f64 = 0.15;
/// How long the other foot must support the body before a touchdown (after a liftoff) for
/// the walking rule to apply, s.
pub const WALK_MIN_SUPPORT_S: f64 = 0.1;

/// The ratios of the walking rule ([`DEFAULT_WALK_TD_RATIO`], [`DEFAULT_WALK_LO_RATIO`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkRatios {
    /// κ_TD.
    pub touchdown: f64,
    /// κ_LO.
    pub liftoff: f64,
}

impl Default for WalkRatios {
    fn default() -> Self {
        WalkRatios {
            touchdown: DEFAULT_WALK_TD_RATIO,
            liftoff: DEFAULT_WALK_LO_RATIO,
        }
    }
}

/// `R(k)` per frame: the slowest of the foot's points over the body's horizontal speed
/// (at least [`WALK_MIN_BODY_SPEED_MPS`]); infinite for a foot without points.
pub fn speed_ratio(points: &[PointTrack], com_speed_h: &[f64]) -> Vec<f64> {
    com_speed_h
        .iter()
        .enumerate()
        .map(|(k, vc)| {
            let v = points.iter().map(|p| p.v[k]).fold(f64::INFINITY, f64::min);
            v / vc.abs().max(WALK_MIN_BODY_SPEED_MPS)
        })
        .collect()
}

fn frames_for(t: &[f64], s: f64) -> usize {
    let dt = if t.len() > 1 { t[1] - t[0] } else { 1.0 };
    ((s / dt).round() as usize).max(1)
}

/// The other foot supports the body on every frame of `from..=to` (inclusive; `to` is
/// clamped to the clip's last frame, so a clip that ends in support still counts): the
/// gate of the walking rule.
pub fn supported(other: &[bool], from: usize, to: usize) -> bool {
    let to = to.min(other.len().saturating_sub(1));
    from <= to && to < other.len() && other[from..=to].iter().all(|&c| c)
}

/// Frames of [`WALK_MIN_SUPPORT_S`] at frame times `t`.
pub fn min_support_frames(t: &[f64]) -> usize {
    frames_for(t, WALK_MIN_SUPPORT_S)
}

/// Walking touchdown of the run `a..=b` (`a ≥ 1`), s: the crossing of `κ` by `r`
/// ([`speed_ratio`]) nearest `a`, not before frame `lo` (after the foot's previous run);
/// `None` when `r` does not cross within reach.
pub fn touchdown(r: &[f64], t: &[f64], a: usize, b: usize, lo: usize, kappa: f64) -> Option<f64> {
    let lo = lo
        .max(1)
        .max(a.saturating_sub(frames_for(t, EVENT_MAX_SHIFT_S)));
    let hi = b
        .min(a + frames_for(t, WALK_EVENT_REACH_S))
        .min(r.len() - 1);
    let mut k = a.min(hi);
    while k > lo && r[k - 1] <= kappa {
        k -= 1;
    }
    while k < hi && r[k] > kappa {
        k += 1;
    }
    if k == 0 {
        return None;
    }
    let (r0, r1) = (r[k - 1], r[k]);
    (r0 > kappa && r1 <= kappa && r0.is_finite())
        .then(|| t[k - 1] + (t[k] - t[k - 1]) * (r0 - kappa) / (r0 - r1))
}

/// Walking liftoff of the run `a..=b` (`b + 1 < t.len()`), s: the crossing of `κ` by `r`
/// nearest `b`, not after frame `hi` (before the foot's next run); `None` when `r` does not
/// cross within reach.
pub fn liftoff(r: &[f64], t: &[f64], a: usize, b: usize, hi: usize, kappa: f64) -> Option<f64> {
    if b + 1 >= r.len() {
        return None;
    }
    let hi = hi
        .min(r.len() - 2)
        .min(b + frames_for(t, EVENT_MAX_SHIFT_S));
    let lo = a.max(b.saturating_sub(frames_for(t, WALK_EVENT_REACH_S)));
    let mut k = b.max(lo);
    while k < hi && r[k + 1] <= kappa {
        k += 1;
    }
    while k > lo && r[k] > kappa {
        k -= 1;
    }
    let (r0, r1) = (r[k], r[k + 1]);
    (r0 <= kappa && r1 > kappa && r1.is_finite())
        .then(|| t[k] + (t[k + 1] - t[k]) * (kappa - r0) / (r1 - r0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(v: &[f64]) -> PointTrack {
        PointTrack {
            h: vec![0.0; v.len()],
            v: v.to_vec(),
        }
    }

    #[test]
    fn the_ratio_takes_the_slowest_point_over_the_body_speed() {
        let ankle = track(&[2.0, 1.0, 0.2]);
        let toe = track(&[3.0, 0.5, 0.4]);
        let r = speed_ratio(&[ankle, toe], &[1.0, 1.0, 0.1]);
        // Frame 2: the body is slower than V_min, so the ratio divides by 0.5 m/s.
        assert_eq!(r, vec![2.0, 0.5, 0.4]);
    }

    #[test]
    fn events_interpolate_the_crossing_inside_the_run() {
        let t: Vec<f64> = (0..40).map(|k| k as f64 * 0.01).collect();
        // The run starts at frame 5 (the detector's early entry); the ratio falls through
        // 0.65 between frames 12 (0.9) and 13 (0.4): t = 0.12 + 0.01·0.25/0.5.
        let mut r = vec![2.0; 40];
        r[5..12].copy_from_slice(&[1.8, 1.6, 1.4, 1.2, 1.1, 1.0, 0.9]);
        r[12] = 0.9;
        r[13..30].iter_mut().for_each(|x| *x = 0.4);
        // Liftoff: 0.4 → 1.15 between frames 27 and 28 after the run's last frame 30 was
        // late: the crossing of 0.75 is at 0.27 + 0.01·0.35/0.75.
        r[28..32].iter_mut().for_each(|x| *x = 1.15);
        let td = touchdown(&r, &t, 5, 30, 0, 0.65).unwrap();
        assert!((td - 0.125).abs() < 1e-12, "{td}");
        let lo = liftoff(&r, &t, 5, 30, 39, 0.75).unwrap();
        assert!((lo - (0.27 + 0.01 * 0.35 / 0.75)).abs() < 1e-12, "{lo}");
        // Out of reach (0.15 s): no event.
        let mut far = vec![2.0; 40];
        far[25..].iter_mut().for_each(|x| *x = 0.1);
        assert_eq!(touchdown(&far, &t, 5, 39, 0, 0.65), None);
    }

    #[test]
    fn the_gate_needs_support_over_the_whole_interval() {
        let other = [true, true, true, false, true];
        assert!(supported(&other, 0, 2));
        assert!(!supported(&other, 1, 3));
        assert!(supported(&other, 4, 9)); // clamped to the clip's end
        assert!(!supported(&other, 3, 9));
        assert!(!supported(&[], 0, 0));
    }
}
