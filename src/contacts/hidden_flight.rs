//! Hidden flights: short flights of a jog that the kinematic contact rule closes up, found
//! from the whole-body force and opened again.
//!
//! # Model
//! ```text
//! candidate: foot A's run a₀..a₁ and the other foot's run b₀..b₁ overlap, a₀ < b₀ ≤ a₁ < b₁
//!            (A lands first, B lifts off last: an alternating double support), the overlap
//!            lasts at most 0.1 s, and no hand is in contact during it
//! evidence:  f(k) = (a_z(k) + g)/g, the SG vertical COM acceleration as a fraction of body
//!            weight (the kinematic force m(a_z + g) / m g);  min over the overlap < 0.25
//! flight:    the run of overlap frames around that minimum with f < 0.25
//!            A ends at the frame before it, B starts at the frame after it; their sub-frame
//!            events are clamped to the flight's frame edges (t − dt/2, t + dt/2)
//! ```
//! The contact rule of spec com-from-bvh §7.3 holds a foot "in contact" while it is within
//! 4 cm of its floor and slower than 2 m/s. In a jog at 2 m/s the swing foot comes down
//! slowly and the stance foot leaves slowly, so both are inside the gates through a flight
//! of 40–60 ms and the clip reads as a walk (no flight, `no_flight` boundaries). The force
//! tells the two apart without ambiguity: in walking double support both feet carry the
//! body (at least 1.0 body weights on the five walks with force plates and every walk of
//! the shared and bulk sets), in a jog's "double support" the body falls freely (−0.01 to
//! 0.11 body weights at the minimum on the 2 m/s force-plate jog, whose plates show 41–56
//! ms flights there). 0.25 lies between with room for the smoothing; 0.1 s is the
//! longest flight the rule may open (a longer low-force overlap is not a jog's step).
//!
//! # References
//! `docs/com-from-bvh.md` §7.9 (the rule, and what it changes on the shared and bulk sets).

use super::contact_runs::ContactRun;
use super::ClipMotion;
use crate::math::constants::GRAVITY;

/// Longest double support the rule may turn into a flight, s.
pub const HIDDEN_FLIGHT_MAX_OVERLAP_S: f64 = 0.1;
/// A double support whose kinematic vertical force falls below this fraction of body
/// weight is a flight.
pub const HIDDEN_FLIGHT_MAX_FORCE_BW: f64 = 0.25;

/// One hidden flight: the feet it separates and its frames (indices into the clip's kept
/// frames, inclusive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HiddenFlight {
    /// Effector index (into [`super::EFFECTORS`]) of the foot that lifts off (A).
    pub before: usize,
    /// Effector index of the foot that lands (B).
    pub after: usize,
    /// First flight frame.
    pub first: usize,
    /// Last flight frame.
    pub last: usize,
    /// Last frame of A's run as detected.
    pub before_last: usize,
    /// First frame of B's run as detected.
    pub after_first: usize,
}

/// The kinematic vertical force per frame, body weights: `(a_z + g)/g`.
fn force_bw(az: &[f64]) -> Vec<f64> {
    az.iter().map(|a| (a + GRAVITY) / GRAVITY).collect()
}

/// The effector index of a run.
fn effector(r: &ContactRun) -> Option<usize> {
    super::EFFECTORS.iter().position(|e| *e == r.effector)
}

/// The hidden flights of a clip's contact runs (see the module docs).
pub fn find(runs: &[ContactRun], motion: &ClipMotion) -> Vec<HiddenFlight> {
    let skip = motion.frame.first().copied().unwrap_or(0);
    let f = force_bw(motion.com_az);
    let idx = |frame: i64| (frame - skip) as usize;
    let max_frames = (HIDDEN_FLIGHT_MAX_OVERLAP_S / motion.dt + 1e-9).floor() as usize;
    let is_foot = |r: &&ContactRun| r.effector.ends_with("_foot");
    let mut out = Vec::new();
    for a in runs.iter().filter(is_foot) {
        for b in runs.iter().filter(is_foot) {
            let alternating = a.effector != b.effector
                && a.first_frame < b.first_frame
                && b.first_frame <= a.last_frame
                && a.last_frame < b.last_frame;
            let (Some(ea), Some(eb)) = (effector(a), effector(b)) else {
                continue;
            };
            if !alternating {
                continue;
            }
            let (s, e) = (idx(b.first_frame), idx(a.last_frame));
            if e + 1 - s > max_frames || e >= f.len() {
                continue;
            }
            let hands = runs.iter().any(|h| {
                !h.effector.ends_with("_foot")
                    && h.first_frame <= a.last_frame
                    && h.last_frame >= b.first_frame
            });
            if hands {
                continue;
            }
            let Some(k) = (s..=e).min_by(|&x, &y| f[x].total_cmp(&f[y])) else {
                continue;
            };
            if f[k].is_nan() || f[k] >= HIDDEN_FLIGHT_MAX_FORCE_BW {
                continue;
            }
            let mut first = k;
            while first > s && f[first - 1] < HIDDEN_FLIGHT_MAX_FORCE_BW {
                first -= 1;
            }
            let mut last = k;
            while last < e && f[last + 1] < HIDDEN_FLIGHT_MAX_FORCE_BW {
                last += 1;
            }
            out.push(HiddenFlight {
                before: ea,
                after: eb,
                first,
                last,
                before_last: e,
                after_first: s,
            });
        }
    }
    out
}

/// Opens the hidden flights in the contact flags: foot A's flags are cleared from the
/// flight's first frame to its detected end, foot B's from its detected start to the
/// flight's last frame.
pub fn open(flags: &mut [Vec<bool>; 4], hidden: &[HiddenFlight]) {
    for h in hidden {
        clear(&mut flags[h.before], h.first, h.before_last);
        clear(&mut flags[h.after], h.after_first, h.last);
    }
}

fn clear(flags: &mut [bool], from: usize, to: usize) {
    for v in flags.iter_mut().take(to + 1).skip(from) {
        *v = false;
    }
}

/// Clamps the sub-frame events of the runs next to each opened flight to its frame edges:
/// A's liftoff no later than `t[first] − dt/2`, B's touchdown no earlier than
/// `t[last] + dt/2` (the event rule may reach back into the flight).
pub fn clamp_events(runs: &mut [ContactRun], hidden: &[HiddenFlight], motion: &ClipMotion) {
    let skip = motion.frame.first().copied().unwrap_or(0);
    for h in hidden {
        let lo_edge = motion.time_s[h.first] - motion.dt / 2.0;
        let td_edge = motion.time_s[h.last] + motion.dt / 2.0;
        let (fa, fb) = ((h.first as i64) + skip - 1, (h.last as i64) + skip + 1);
        for r in runs.iter_mut() {
            let e = effector(r);
            if e == Some(h.before) && r.last_frame == fa {
                r.lo_time_s = r.lo_time_s.map(|t| t.min(lo_edge));
            }
            if e == Some(h.after) && r.first_frame == fb {
                r.td_time_s = r.td_time_s.map(|t| t.max(td_edge));
            }
        }
    }
}
