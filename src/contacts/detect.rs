//! Per-effector contact flags: hysteresis, gap filling and minimum durations.
//!
//! # Model
//! ```text
//! ground contact:  enter ⇔ ∃p: h_p ≤ h_on ∧ v_p ≤ v_on;   leave ⇔ ∀p: h_p > h_off ∨ v_p > v_off
//! static contact:  enter ⇔ ∃p: h_p > 0.10 ∧ v_p ≤ 0.15;   leave ⇔ ∀p: h_p ≤ 0.10 ∨ v_p > 0.30
//! then: fill interior gaps shorter than min_gap ((b − a + 1)/F < min_gap), never at a clip
//! edge; remove runs shorter than min_on.
//! ```
//! Frame by frame in time order, starting out of contact; nothing else moves an edge.
//!
//! # References
//! spec com-from-bvh §7.3, §7.4, §7.6.

use super::options::{Thresholds, STATIC_H, STATIC_V_OFF, STATIC_V_ON};
use super::runs;

/// One contact point's height above its floor and raw speed per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PointTrack {
    /// Height above the point's floor, m.
    pub h: Vec<f64>,
    /// Unsmoothed 3-D speed, m/s.
    pub v: Vec<f64>,
}

/// Ground-contact hysteresis over the effector's points.
pub fn hysteresis(points: &[PointTrack], th: &Thresholds) -> Vec<bool> {
    hysteresis_by(
        points,
        |p, k| p.h[k] <= th.h_on && p.v[k] <= th.v_on,
        |p, k| p.h[k] > th.h_off || p.v[k] > th.v_off,
    )
}

/// Static-contact hysteresis; also returns, per frame, the index of the point that
/// triggered the current run (the first in point order at the run's first frame).
pub fn static_hysteresis(points: &[PointTrack]) -> (Vec<bool>, Vec<Option<usize>>) {
    let n = points.first().map_or(0, |p| p.h.len());
    let enter = |p: &PointTrack, k: usize| p.h[k] > STATIC_H && p.v[k] <= STATIC_V_ON;
    let flags = hysteresis_by(points, enter, |p, k| {
        p.h[k] <= STATIC_H || p.v[k] > STATIC_V_OFF
    });
    let mut trig = vec![None; n];
    for (a, b) in runs(&flags) {
        let t = points.iter().position(|p| enter(p, a));
        trig[a..=b].iter_mut().for_each(|x| *x = t);
    }
    (flags, trig)
}

pub(super) fn hysteresis_by(
    points: &[PointTrack],
    enter: impl Fn(&PointTrack, usize) -> bool,
    leave: impl Fn(&PointTrack, usize) -> bool,
) -> Vec<bool> {
    let n = points.first().map_or(0, |p| p.h.len());
    let mut on = false;
    (0..n)
        .map(|k| {
            on = if on {
                !points.iter().all(|p| leave(p, k))
            } else {
                points.iter().any(|p| enter(p, k))
            };
            on
        })
        .collect()
}

/// Fill interior gaps shorter than `min_gap` frames-seconds, then drop runs shorter than
/// `min_on` (spec §7.3 steps 3–4). `rate_hz` = F.
pub fn clean(flags: &mut [bool], rate_hz: f64, min_gap_s: f64, min_on_s: f64) {
    let n = flags.len();
    let on_runs = runs(flags);
    for w in on_runs.windows(2) {
        let (a, b) = (w[0].1 + 1, w[1].0 - 1);
        if ((b - a + 1) as f64) / rate_hz < min_gap_s {
            flags[a..=b].iter_mut().for_each(|f| *f = true);
        }
    }
    for (a, b) in runs(flags) {
        if ((b - a + 1) as f64) / rate_hz < min_on_s {
            flags[a..=b].iter_mut().for_each(|f| *f = false);
        }
    }
    debug_assert_eq!(flags.len(), n);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(h: &[f64], v: &[f64]) -> PointTrack {
        PointTrack {
            h: h.to_vec(),
            v: v.to_vec(),
        }
    }

    #[test]
    fn hysteresis_enters_on_any_point_and_leaves_on_all() {
        let th = Thresholds {
            h_on: 0.04,
            h_off: 0.06,
            v_on: 2.0,
            v_off: 2.0,
        };
        let heel = track(
            &[0.1, 0.03, 0.05, 0.07, 0.07, 0.07],
            &[3.0, 1.0, 0.1, 0.1, 0.1, 0.1],
        );
        let toe = track(
            &[0.2, 0.2, 0.01, 0.01, 0.07, 0.01],
            &[3.0, 3.0, 0.1, 0.1, 0.1, 2.5],
        );
        assert_eq!(
            hysteresis(&[heel, toe], &th),
            vec![false, true, true, true, false, false]
        );
    }

    #[test]
    fn gaps_fill_and_short_runs_drop_but_edges_stay() {
        let mut f = vec![
            false, true, true, true, false, true, true, true, false, false, true, false, false,
        ];
        clean(&mut f, 100.0, 0.03, 0.03);
        // gap of 1 frame (0.01 s) filled; gap of 2 frames (0.02 s) filled; 1-frame run removed after
        assert_eq!(
            f,
            vec![false, true, true, true, true, true, true, true, true, true, true, false, false]
        );
        let mut g = vec![false, true, true, true, false, false, false, false];
        clean(&mut g, 100.0, 0.03, 0.03);
        assert_eq!(g, vec![false, true, true, true, false, false, false, false]);
    }
}
