//! Landings of feet without a toe tip of their own: found from the foot's own motion, where
//! the ground arrests the ankle's descent.
//!
//! # Model
//! ```text
//! estimated toe ⇔ max_k Δ(k) − min_k Δ(k) ≤ 1 mm,   Δ(k) = z_toe(k) − z_ankle(k)
//!                 (the ingest's fallback toe tip, spec com-from-bvh §4.3, is a fixed offset
//!                 ahead of and below the ankle: it never pitches with the foot)
//! a_A(k), v_A(k): SG vertical acceleration and velocity of the ankle (the COM's window, §6)
//! landing of such a foot's contact run a..b (a ≥ 1; sub-frame touchdown t_TD):
//!   the latest k in [a − 0.1 s, a], after the foot's previous run, with
//!     a_A(k−1) ≤ 0.75 g < a_A(k)      (the descent is arrested)
//!     v_A(k) < 0                        (still descending)
//!     h_on < h_A(k) ≤ 0.15 m·L_leg/0.84 (the ankle above the height rule's enter height,
//!                                        raised by a foot landing toe first)
//!   t_L = t[k−1] + dt·(0.75 g − a_A(k−1))/(a_A(k) − a_A(k−1));  used when t_L < t_TD:
//!   the run starts at frame k and its touchdown is t_L
//! ```
//! A foot that lands toe first leaves its ankle 6–15 cm above the floor until the heel comes
//! down. With a real toe tip the height rule (spec §7.3) sees the toe arrive; with the
//! fallback toe tip, which keeps a fixed height below the ankle, it sees only the heel, two
//! to eight frames (up to 70 ms) after the COM has started to decelerate. The foot's own
//! motion shows the landing: the ground stops its descent. Heel strikes are unchanged (their
//! ankle is below the enter height when it is arrested, and the height rule is earlier).
//!
//! # Why these numbers
//! 0.75 g: on the force-plate drop jump rewritten without End Sites and toe joints (100 Hz,
//! both landings, both feet) the arrest time is within −5.6, +6.9, −1.6 and −0.2 ms of the
//! plates' first 20 N (mean |error| 3.6 ms); g was up to 49 ms late (one foot's arrest
//! ramps slowly through it), 0.5 g up to 8 ms early. 0.1 s: the lost part of a landing
//! (the held-out jumps: up to 70 ms) with room, yet short of a jump's apex. 0.15 m: the
//! height a pointed foot lifts the ankle (the detector's bound on a foot point's own floor,
//! [`super::floor::FOOT_FLOOR_MAX_ABOVE_GROUND`]). 1 mm: a captured toe joint moves by
//! centimetres relative to its ankle; the fallback by round-off.
//!
//! # References
//! `docs/com-from-bvh.md` §7.10 (the rule and the held-out jumps); spec com-from-bvh §4.3,
//! §6, §7.3.

use super::floor::FOOT_FLOOR_MAX_ABOVE_GROUND;
use super::timeline::{ContactTimeline, ContactTracks};
use super::{runs, ClipMotion, ContactRun, EFFECTORS};
use crate::math::constants::GRAVITY;
use crate::math::savgol::{SavGol, DEFAULT_ORDER};

/// A toe point whose height relative to its ankle varies by at most this over the clip is
/// the ingest's estimate, not a point of the foot, m.
pub const RIGID_TOE_TOL_M: f64 = 0.001;
/// The ankle's upward SG acceleration at which its descent counts as arrested by the
/// ground, m/s² (0.75 g).
pub const LANDING_ARREST_MPS2: f64 = 0.75 * GRAVITY;
/// Farthest before the height rule's touchdown frame a landing is looked for, s.
pub const LANDING_MAX_LEAD_S: f64 = 0.1;

/// One landing found from the foot's own motion (indices into the clip's kept frames).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landing {
    /// Effector index (into [`EFFECTORS`]): a foot.
    pub effector: usize,
    /// First frame of the run as the height rule found it.
    pub detected_first: usize,
    /// First frame from the foot's motion (`≤ detected_first`).
    pub first: usize,
    /// Sub-frame touchdown, clip time, s.
    pub t_s: f64,
}

/// The toe point carries no information of its own: its height keeps a fixed offset from
/// the ankle's (within [`RIGID_TOE_TOL_M`]).
pub fn toe_is_estimated(ankle_z: &[f64], toe_z: &[f64]) -> bool {
    let d = ankle_z.iter().zip(toe_z).map(|(a, t)| t - a);
    let (lo, hi) = d.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    hi.is_finite() && lo.is_finite() && hi - lo <= RIGID_TOE_TOL_M
}

/// Upward crossing time of `level` between frames `k − 1` and `k`, s.
fn crossing(t: &[f64], a: &[f64], k: usize, level: f64) -> f64 {
    t[k - 1] + (t[k] - t[k - 1]) * (level - a[k - 1]) / (a[k] - a[k - 1])
}

/// The landings of the feet whose toe tip is estimated (see the module docs); `runs_out`
/// holds the runs as the height rule found them, `foot_h_on` is its enter height (m).
pub fn find(
    tracks: &ContactTracks,
    timeline: &ContactTimeline,
    motion: &ClipMotion,
    runs_out: &[ContactRun],
    foot_h_on: f64,
) -> Vec<Landing> {
    let Ok(sg) = SavGol::for_frame_time(motion.dt, DEFAULT_ORDER) else {
        return Vec::new();
    };
    let t = motion.time_s;
    let lead = (LANDING_MAX_LEAD_S / motion.dt + 1e-9).floor() as usize;
    let h_max = FOOT_FLOOR_MAX_ABOVE_GROUND * tracks.leg_scale;
    let skip = motion.frame.first().copied().unwrap_or(0);
    let mut out = Vec::new();
    for e in 0..2 {
        let (points, track) = (&tracks.points[e], &tracks.tracks[e]);
        if points.len() < 2 || track.is_empty() {
            continue;
        }
        let z = |p: usize| -> Vec<f64> { points[p].iter().map(|q| q[2]).collect() };
        let ankle_z = z(0);
        if !toe_is_estimated(&ankle_z, &z(1)) {
            continue;
        }
        let (v, a) = (sg.apply(&ankle_z, 1, motion.dt), sg.apply(&ankle_z, 2, motion.dt));
        if a.len() != ankle_z.len() {
            continue; // shorter than the SG window
        }
        let h = &track[0].h;
        let mut prev_end = 0;
        for (first, last) in runs(&timeline.contact[e]) {
            let lo = prev_end.max(first.saturating_sub(lead)).max(1);
            prev_end = last + 1;
            let td = runs_out
                .iter()
                .find(|r| r.effector == EFFECTORS[e] && r.first_frame == skip + first as i64)
                .and_then(|r| r.td_time_s);
            let (Some(td), true) = (td, first >= 1) else {
                continue;
            };
            let arrest = (lo..=first).rev().find(|&k| {
                a[k - 1] <= LANDING_ARREST_MPS2
                    && a[k] > LANDING_ARREST_MPS2
                    && v[k] < 0.0
                    && h[k] > foot_h_on
                    && h[k] <= h_max
            });
            if let Some(k) = arrest {
                let t_s = crossing(t, &a, k, LANDING_ARREST_MPS2);
                if t_s < td {
                    out.push(Landing {
                        effector: e,
                        detected_first: first,
                        first: k,
                        t_s,
                    });
                }
            }
        }
    }
    out
}

/// Starts each landing's run at its first frame from the foot's motion and records its
/// touchdown time for [`super::contact_runs::collect`].
pub fn apply(timeline: &mut ContactTimeline, landings: &[Landing]) {
    for l in landings {
        timeline.contact[l.effector][l.first..l.detected_first]
            .iter_mut()
            .for_each(|c| *c = true);
        timeline.landing_s[l.effector][l.first] = Some(l.t_s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contacts::detect::PointTrack;

    #[test]
    fn a_fixed_toe_offset_is_an_estimate_and_a_pitching_toe_is_not() {
        let ankle: Vec<f64> = (0..50).map(|k| 0.08 + 0.1 * (k as f64 * 0.2).sin()).collect();
        let rigid: Vec<f64> = ankle.iter().map(|a| a - 0.07).collect();
        let pitching: Vec<f64> = ankle
            .iter()
            .enumerate()
            .map(|(k, a)| a - 0.07 + 0.03 * (k as f64 * 0.3).cos())
            .collect();
        assert!(toe_is_estimated(&ankle, &rigid));
        assert!(!toe_is_estimated(&ankle, &pitching));
    }

    /// An ankle that falls at 2 m/s and is stopped by the ground from `t0` (constant
    /// deceleration 40 m/s² for 50 ms), 12 cm above its floor: a toe-first landing.
    #[test]
    fn a_toe_first_landing_starts_where_the_ankle_is_arrested() {
        let dt = 1.0 / 120.0;
        let n = 120;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let t0 = 60.5 * dt;
        let z_of = |tt: f64| -> f64 {
            let s = tt - t0;
            if s < 0.0 {
                0.12 - 2.0 * s
            } else if s < 0.05 {
                0.12 - 2.0 * s + 20.0 * s * s
            } else {
                0.07
            }
        };
        let ankle: Vec<[f64; 3]> = t.iter().map(|&tt| [0.0, 0.0, z_of(tt)]).collect();
        let toe: Vec<[f64; 3]> = ankle.iter().map(|p| [0.19, 0.0, p[2] - 0.07]).collect();
        let h: Vec<f64> = ankle.iter().map(|p| p[2] - 0.07).collect();
        let track = |h: &[f64]| PointTrack {
            h: h.to_vec(),
            v: vec![0.0; n],
        };
        let mut tracks = ContactTracks {
            ground_z: vec![0.0; n],
            tracks: Default::default(),
            points: Default::default(),
            dt,
            leg_scale: 1.0,
        };
        tracks.tracks[0] = vec![track(&h), track(&h)];
        tracks.points[0] = vec![ankle, toe];
        // The height rule sees the heel down 8 frames late.
        let mut contact: [Vec<bool>; 4] = std::array::from_fn(|_| vec![false; n]);
        contact[0][69..].iter_mut().for_each(|c| *c = true);
        let timeline = ContactTimeline {
            contact,
            static_contact: Default::default(),
            surface_z: Default::default(),
            speed_led: std::array::from_fn(|_| vec![false; n]),
            landing_s: std::array::from_fn(|_| vec![None; n]),
        };
        let frame: Vec<i64> = (0..n as i64).collect();
        let zero = vec![0.0; n];
        let com = vec![[0.0; 3]; n];
        let facing = vec![[1.0, 0.0, 0.0]; n];
        let motion = ClipMotion {
            frame: &frame,
            time_s: &t,
            dt,
            com: &com,
            com_vz: &zero,
            com_az: &zero,
            facing: &facing,
        };
        let run = ContactRun {
            effector: "left_foot",
            first_frame: 69,
            last_frame: n as i64 - 1,
            t_td_s: Some(t[69] - dt / 2.0),
            t_lo_s: None,
            td_time_s: Some(t[69] - dt / 2.0),
            lo_time_s: None,
            speed_led: false,
            is_static: false,
            surface_z: 0.0,
            origin: [0.0; 3],
            yaw_rad: 0.0,
            normal: [0.0, 0.0, 1.0],
        };
        let runs_out = [run];
        let found = find(&tracks, &timeline, &motion, &runs_out, 0.04);
        assert_eq!(found.len(), 1, "{found:?}");
        // The SG acceleration ramps over its window (±0.05 s): a 40 m/s² step crosses
        // 0.75 g before the step, by less than the half-window (measured 2.4 frames).
        let l = found[0];
        assert!(l.t_s <= t0 && l.t_s > t0 - 0.05, "{l:?} t0 {t0}");
        assert!(l.first < 61 && l.detected_first == 69, "{l:?}");
        // The same foot with a toe tip that pitches on its own is left to the height rule.
        tracks.points[0][1][65][2] += 0.02;
        assert!(find(&tracks, &timeline, &motion, &runs_out, 0.04).is_empty());
    }
}
