//! Landings of feet without a toe tip of their own: which foot lands from the foot's own
//! motion, when from the COM's deceleration (or, without it, the ankle's arrest).
//!
//! # Model
//! ```text
//! estimated toe tip: the ingest's fallback (spec com-from-bvh §4.3), a fixed offset ahead of
//!                    and below the ankle that never pitches with the foot
//! a_A(k), v_A(k): SG vertical acceleration (m/s²) and velocity (m/s) of that foot's ankle
//! h_A(k):         the ankle's height above its own floor (§7.1), m
//! L(k) = a_z(k) + g: the COM's lift (SG vertical COM acceleration), m/s²
//! near(k) ⇔ v_A(k) < 0 ∧ h_on < h_A(k) ≤ 0.15 m·L_leg/0.84
//!           (coming down, above the height rule's enter height, no higher than a pointed
//!            foot lifts its ankle)
//! landing of such a foot's contact run a..b (a ≥ 1, touchdown t_TD; height rule or
//! speed-led), looking back no further than the foot's previous run:
//!   COM cue:   the latest k ∈ [a − 0.2 s, a] with L(k−1) < g/2 ≤ L(k), a_A(k) > 0, near(k)
//!              t_L = t[k−1] + dt·(g/2 − L(k−1))/(L(k) − L(k−1))
//!   else ankle cue: the latest k ∈ [a − 0.1 s, a] with a_A(k−1) ≤ 0.75 g < a_A(k), near(k)
//!              t_L = t[k−1] + dt·(0.75 g − a_A(k−1))/(a_A(k) − a_A(k−1))
//!   used when t_L < t_TD: the run starts at frame k and its touchdown is t_L
//! ```
//! A foot that lands toe first leaves its ankle 6–15 cm above the floor until the heel comes
//! down. With a real toe tip the height rule (spec §7.3) sees the toe arrive; with the
//! fallback toe tip, which keeps a fixed height below the ankle, it sees only the heel, two
//! to ten frames late (CMU 131_03's hop: 84 ms), or never when the ankle stays up (a
//! held-out standing jump: ankles 6–9 cm above the floor), and then the speed-led rule of
//! [`super::support`] finds the landing only where the feet have slowed, 90–130 ms after
//! the body started to land. The landing foot carries the body: when the COM's lift rises
//! through half the weight while this foot comes down near its floor and slows, that is its
//! touchdown. Where the COM shows no landing (the other foot is already down: a step, not
//! a landing from a flight) the ground's arrest of the ankle times it. Heel strikes are
//! unchanged: their ankle is below the enter height, and the height rule is earlier. This
//! is the one place the COM moves a contact edge (com-from-bvh §7.6 rejects it for feet
//! with their own toe tip), and only earlier.
//!
//! # Why these numbers
//! g/2: the SG acceleration is a symmetric weighted mean of the true one, so a force step
//! crosses half its height at the step; on the force-plate drop jump rewritten without End
//! Sites and toe joints (100 Hz) the COM cue is −7.2 / −6.8 ms (first landing, left /
//! right) and +2.7 / −7.2 ms (second) from the plates' first 20 N; a lift of g − 3 m/s²
//! (the flight tolerance) crossed 28 ms early. a_A > 0: the landing foot itself slows; one
//! still swinging down is not the foot that lands. 0.75 g: the same clip's ankle arrest is
//! within −5.6, +6.9, −1.6 and −0.2 ms of the plates (g: up to 49 ms late, 0.5 g up to 8 ms
//! early). 0.1 s: the lost part of a landing (up to 70 ms) with room, yet short of a jump's
//! apex. 0.2 s: a landing the speed-led rule found where the feet slowed (CMU 01_01 with
//! its landings lost: 134 ms after the COM); the lift cannot cross g/2 upwards at an apex,
//! where it is near zero. 0.15 m: the height a pointed foot lifts the ankle (the detector's
//! bound on a foot point's own floor, [`super::floor::FOOT_FLOOR_MAX_ABOVE_GROUND`]).
//!
//! # References
//! `docs/com-from-bvh.md` §7.10 (the rule and the held-out jumps); spec com-from-bvh §4.3,
//! §6, §7.3; test `held_out_jumps`.

use super::floor::FOOT_FLOOR_MAX_ABOVE_GROUND;
use super::timeline::{ContactTimeline, ContactTracks};
use super::{runs, ClipMotion, ContactRun, EFFECTORS};
use crate::math::constants::GRAVITY;
use crate::math::savgol::{SavGol, DEFAULT_ORDER};

/// The ankle's upward SG acceleration at which its descent counts as arrested by the
/// ground, m/s² (0.75 g).
pub const LANDING_ARREST_MPS2: f64 = 0.75 * GRAVITY;
/// The COM's lift `a_z + g` (SG) at which a landing body counts as held, m/s² (g/2: half
/// its weight carried).
pub const LANDING_COM_LIFT_MPS2: f64 = 0.5 * GRAVITY;
/// Farthest before the height rule's touchdown frame a landing is looked for, s.
pub const LANDING_MAX_LEAD_S: f64 = 0.1;
/// Farthest before the first frame of a run (height rule or speed-led) a landing timed by
/// the COM is looked for, s.
pub const LANDING_MAX_LEAD_COM_S: f64 = 0.2;

/// One landing found from the foot's own motion (indices into the clip's kept frames).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landing {
    /// Effector index (into [`EFFECTORS`]): a foot.
    pub effector: usize,
    /// First frame of the run as found before (height rule or speed-led).
    pub detected_first: usize,
    /// First frame from the foot's motion (`≤ detected_first`).
    pub first: usize,
    /// Sub-frame touchdown, clip time, s.
    pub t_s: f64,
    /// What timed it.
    pub cue: LandingCue,
}

/// What timed a landing found from the foot's motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LandingCue {
    /// The COM's lift reached [`LANDING_COM_LIFT_MPS2`] while this foot came down near
    /// its floor and slowed.
    Com,
    /// The ankle's upward acceleration reached [`LANDING_ARREST_MPS2`].
    Ankle,
}

/// Upward crossing time of `level` between frames `k − 1` and `k`, s.
fn crossing(t: &[f64], a: &[f64], k: usize, level: f64) -> f64 {
    t[k - 1] + (t[k] - t[k - 1]) * (level - a[k - 1]) / (a[k] - a[k - 1])
}

/// The landings of the feet whose toe tip is estimated (see the module docs); `runs_out`
/// holds the clip's contact runs as found so far, `foot_h_on` is the height rule's enter
/// height (m).
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
    let lead = |s: f64| (s / motion.dt + 1e-9).floor() as usize;
    let h_max = FOOT_FLOOR_MAX_ABOVE_GROUND * tracks.leg_scale;
    let skip = motion.frame.first().copied().unwrap_or(0);
    // The COM's lift a_z + g per kept frame (none when the lengths disagree).
    let lift: Vec<f64> = match motion.com_az.len() == motion.time_s.len() {
        true => motion.com_az.iter().map(|a| a + GRAVITY).collect(),
        false => Vec::new(),
    };
    let mut out = Vec::new();
    for (e, foot) in EFFECTORS.iter().enumerate().take(2) {
        let (points, track) = (&tracks.points[e], &tracks.tracks[e]);
        if points.is_empty() || track.is_empty() {
            continue;
        }
        if !tracks.toe_estimated[e] {
            continue;
        }
        let ankle_z: Vec<f64> = points[0].iter().map(|q| q[2]).collect();
        let (v, a) = (
            sg.apply(&ankle_z, 1, motion.dt),
            sg.apply(&ankle_z, 2, motion.dt),
        );
        if a.len() != ankle_z.len() {
            continue; // shorter than the SG window
        }
        let h = &track[0].h;
        let mut prev_end = 0;
        for (first, last) in runs(&timeline.contact[e]) {
            let run = runs_out
                .iter()
                .find(|r| r.effector == *foot && r.first_frame == skip + first as i64);
            let lo = |lead_s: f64| prev_end.max(first.saturating_sub(lead(lead_s))).max(1);
            let (lo_com, lo) = (lo(LANDING_MAX_LEAD_COM_S), lo(LANDING_MAX_LEAD_S));
            prev_end = last + 1;
            let (Some(td), true) = (run.and_then(|r| r.td_time_s), first >= 1) else {
                continue;
            };
            let near_floor = |k: usize| v[k] < 0.0 && h[k] > foot_h_on && h[k] <= h_max;
            // The body's landing, when this foot is the one coming down onto the floor.
            let held = (lo_com..=first)
                .rev()
                .filter(|&k| k < lift.len())
                .find(|&k| {
                    lift[k - 1] < LANDING_COM_LIFT_MPS2
                        && lift[k] >= LANDING_COM_LIFT_MPS2
                        && a[k] > 0.0
                        && near_floor(k)
                });
            // Else the foot's own arrest.
            let arrest = || {
                (lo..=first).rev().find(|&k| {
                    a[k - 1] <= LANDING_ARREST_MPS2 && a[k] > LANDING_ARREST_MPS2 && near_floor(k)
                })
            };
            let found = match held {
                Some(k) => Some((
                    k,
                    crossing(t, &lift, k, LANDING_COM_LIFT_MPS2),
                    LandingCue::Com,
                )),
                None => arrest().map(|k| {
                    (
                        k,
                        crossing(t, &a, k, LANDING_ARREST_MPS2),
                        LandingCue::Ankle,
                    )
                }),
            };
            if let Some((k, t_s, cue)) = found {
                if t_s < td {
                    out.push(Landing {
                        effector: e,
                        detected_first: first,
                        first: k,
                        t_s,
                        cue,
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

    /// An ankle that falls at 2 m/s and is stopped by the ground from `t0` (constant
    /// deceleration 40 m/s² for 50 ms), 12 cm above its floor: a toe-first landing that the
    /// height rule sees 8 frames late. `com_az`: the COM's SG vertical acceleration.
    fn toe_first_landing(com_az: Vec<f64>, toe_estimated: bool) -> Vec<Landing> {
        let (dt, n) = (1.0 / 120.0, 120);
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let z_of = |tt: f64| -> f64 {
            let s = tt - T0;
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
        let track = || PointTrack {
            h: h.clone(),
            v: vec![0.0; n],
        };
        let mut tracks = ContactTracks {
            ground_z: vec![0.0; n],
            tracks: Default::default(),
            points: Default::default(),
            dt,
            leg_scale: 1.0,
            toe_estimated: [toe_estimated, false],
        };
        tracks.tracks[0] = vec![track(), track()];
        tracks.points[0] = vec![ankle, toe];
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
        let (zero, com) = (vec![0.0; n], vec![[0.0; 3]; n]);
        let facing = vec![[1.0, 0.0, 0.0]; n];
        let motion = ClipMotion {
            frame: &frame,
            time_s: &t,
            dt,
            com: &com,
            com_vz: &zero,
            com_speed_h: &zero,
            com_az: &com_az,
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
        find(&tracks, &timeline, &motion, &[run], 0.04)
    }

    /// The ground's first touch, s (frame 60.5 at 120 Hz).
    const T0: f64 = 60.5 / 120.0;

    #[test]
    fn a_toe_first_landing_starts_where_the_ankle_is_arrested() {
        // No flight before it (the COM held all along): the ankle cue.
        let found = toe_first_landing(vec![0.0; 120], true);
        assert_eq!(found.len(), 1, "{found:?}");
        // The SG acceleration ramps over its window (±0.05 s): a 40 m/s² step crosses
        // 0.75 g before the step, by less than the half-window (measured 2.4 frames).
        let l = found[0];
        assert_eq!(l.cue, LandingCue::Ankle);
        assert!(l.t_s <= T0 && l.t_s > T0 - 0.05, "{l:?} t0 {T0}");
        assert!(l.first < 61 && l.detected_first == 69, "{l:?}");
        // A foot with a toe tip of its own is left to the height rule.
        assert!(toe_first_landing(vec![0.0; 120], false).is_empty());
    }

    #[test]
    fn a_landing_from_a_flight_starts_where_the_com_is_half_held() {
        // The COM falls freely, then its lift ramps at 2 g per frame from frame 58 (the SG
        // smoothing leads the touchdown by up to its half-window): it crosses g/2 a quarter
        // of a frame after frame 58.
        let com_az: Vec<f64> = (0..120)
            .map(|k| -GRAVITY + (2.0 * GRAVITY * (k as f64 - 58.0)).clamp(0.0, 2.0 * GRAVITY))
            .collect();
        let found = toe_first_landing(com_az, true);
        assert_eq!(found.len(), 1, "{found:?}");
        let l = found[0];
        assert_eq!(
            (l.cue, l.first, l.detected_first),
            (LandingCue::Com, 59, 69)
        );
        // Exact for a linear ramp: t[58] + dt/4.
        assert!((l.t_s - 58.25 / 120.0).abs() < 1e-12, "{l:?}");
    }
}
