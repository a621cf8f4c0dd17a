//! Foot goals: where each foot goes at an output time and how strongly it is pulled there
//! ([`foot_goal`]), and what one frame's root/IK iteration aims at ([`FrameGoal`]).
//!
//! # Model
//! ```text
//! feet       ankle* = c_plan + yaw(Δψ)(ankle_src − c_src − D),  foot orientation = yaw(Δψ)·src
//!            D: the source foot's slide while resting (Reference::foot_drift)
//!            swinging: ankle* ← ankle* + z·Δz_COM (the planned COM's rise above the
//!            source's since the liftoff or until the touchdown), then
//!            goal = ankle*_h + (A_ref + h·(ankle* − A_ref))_z,  h = 1 − smoothstep(τ / T_hold)
//!            (horizontally on the planted paths' blend, vertically following the body
//!            away from the contacts; before a foot's first or after its last stance
//!            A_ref + h·(ankle* − A_ref) in full)
//!            (A_ref: where the reference pose puts the ankle, τ: time to the foot's nearest
//!            own touchdown or liftoff; ankle* between two stances: their smoothstep blend)
//! ```
//! `c` is the contact point (COM at touchdown plus the stance's contact point `cp`), so the
//! reference foot's motion about its contact point, heel–toe roll included, is kept and
//! only moved to the planned point. The source time of a stance is warped linearly between
//! its touchdown and liftoff, as the reference pose's.
//!
//! # Frames and units
//! Goals in file units and axes; plan, COM and times in metres and seconds, internal Z-up
//! frame.

use super::joints::up_file;
use super::reference::{yaw_of, Reference, StanceSource};
use crate::edit::path::ComPath;
use crate::edit::rotation::{self as rot, Quat};
use crate::math::v3::{add, sub, V3};

/// Smoothstep of `u` clamped to `[0, 1]`: `3u² − 2u³`.
pub(super) fn smooth(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// Foot `side` anchored to planned stance `k`, from the source foot at clip time `t_src`:
/// ankle position (file) and world orientation.
pub(super) fn anchored(
    r: &Reference,
    c_plan: V3,
    s: &StanceSource,
    yaw: f64,
    t_src: f64,
    side: usize,
) -> (V3, Quat) {
    let body = &r.body;
    let (p, q) = r.foot_at(t_src, side);
    let [dx, dy] = s.drift_at(side, t_src, r.motion.frame_time_s);
    let planted = sub(p, [s.anchor[0] + dx, s.anchor[1] + dy, s.anchor[2]]);
    let rel = rot::rotate(rot::axis_angle([0.0, 0.0, 1.0], yaw), planted);
    (
        body.to_file(add(c_plan, rel)),
        rot::mul(rot::axis_angle(up_file(body), yaw), q),
    )
}

/// Where foot `side` goes at `t` and how strongly it is held there ([`Pull`], [`hold`]):
/// anchored to its stance
/// while in one (held fully); in a swing, the blend (smooth weight over the swing) of its
/// motion after the last liftoff, anchored to that stance, and before the next
/// touchdown, anchored to that one, each raised by the planned COM's vertical departure
/// from the source COM since that liftoff (until that touchdown), held vertically only
/// near those contacts (horizontally throughout: following the body horizontally, a run
/// slower than recorded dragged the lifted foot backwards, its re-ingested liftoffs 1.6–1.9
/// frames late at 2 m/s); before its first or after its last stance, held near that
/// contact only. The foot leaves and reaches the floor exactly as the source foot does, and
/// moves off it with the body: a jump higher than recorded rises faster than the recorded
/// foot leaves the floor, and held at the recorded foot's height the straight legs pointed
/// at goals beyond their reach (the vertical jump 1.1 × higher: the root at 11 g in the
/// frames after liftoff). `None`: no stance of this foot.
pub(super) fn foot_goal(
    r: &Reference,
    path: &ComPath,
    src: &[StanceSource],
    t: f64,
    side: usize,
    hold_s: f64,
) -> Option<(V3, Quat, Pull)> {
    let st = &path.stances;
    let has = |k: usize| src[st[k].source].feet[side];
    let yaw_of = |k: usize| yaw_of(path, src, k);
    let rate = |k: usize| {
        let (td, lo) = st[k].contact_window();
        let s = &src[st[k].source];
        if lo > td {
            (s.lo_clip_s - s.td_clip_s) / (lo - td)
        } else {
            1.0
        }
    };
    for k in (0..st.len()).filter(|&k| has(k)) {
        let (td, lo) = st[k].contact_window();
        if t >= td && t <= lo {
            let s = &src[st[k].source];
            let (p, q) = anchored(
                r,
                st[k].contact_point(),
                s,
                yaw_of(k),
                s.td_clip_s + (t - td) * rate(k),
                side,
            );
            return Some((p, q, [1.0; 2]));
        }
    }
    let b = (0..st.len())
        .rev()
        .find(|&k| has(k) && st[k].contact_window().1 <= t);
    let a = (0..st.len()).find(|&k| has(k) && st[k].contact_window().0 >= t);
    // A run is periodic: after a foot's last stance it swings towards that stance one
    // cycle (two stances of one source) on: (stance, time shift s, horizontal shift m).
    // Held near its liftoff and then following the body instead, a run slower than
    // recorded dragged the lifted foot backwards (the last liftoffs re-ingested 1.8 frames
    // late at 2 m/s). Before a foot's first stance the source's swing after that stance's
    // liftoff is not the swing before it (on `cmu_09_01` it lies at the clip's end, and
    // the leg straightened and the foot turned 25° in a frame), so the foot is held only.
    let edge_b = b.map(|k| (k, 0.0, [0.0; 2]));
    let edge_a = match (a, b) {
        (Some(k), _) => Some((k, 0.0, [0.0; 2])),
        (None, Some(k)) => k
            .checked_sub(2)
            .filter(|&j| st[j].source == st[k].source)
            .map(|j| {
                (
                    k,
                    st[k].t0 - st[j].t0,
                    [0, 1].map(|i| st[k].origin[i] - st[j].origin[i]),
                )
            }),
        _ => None,
    };
    // The source foot's motion about the contact it left (b) or meets (a), plus the
    // planned COM's vertical departure from the source COM's since (until) that contact
    // (horizontally the footprints' blend below carries the new distance: the horizontal
    // departure too dragged a run slower than recorded's lifted foot backwards at the
    // speed difference, its re-ingested liftoffs 1.6–1.9 frames late at 2 m/s).
    let swing_from = |(k, dt, o): (usize, f64, [f64; 2]), end: usize| {
        let s = &src[st[k].source];
        let (td, lo) = st[k].contact_window();
        let (edge, edge_src) = if end == 1 {
            (lo + dt, s.lo_clip_s)
        } else {
            (td + dt, s.td_clip_s)
        };
        let t_src = edge_src + (t - edge) * rate(k);
        let c = st[k].contact_point();
        let (p, q) = anchored(
            r,
            [c[0] + o[0], c[1] + o[1], c[2]],
            s,
            yaw_of(k),
            t_src,
            side,
        );
        // A cycle away the planned and source paths rise alike (periodic).
        let rise = if dt == 0.0 {
            let planned = sub(path.com(t).0, path.com(edge).0);
            let recorded = sub(r.com_at(t_src), r.com_at(edge_src));
            let yaw = rot::axis_angle([0.0, 0.0, 1.0], yaw_of(k));
            sub(planned, rot::rotate(yaw, recorded))[2]
        } else {
            0.0
        };
        (add(p, r.body.to_file([0.0, 0.0, rise])), q, edge)
    };
    let from_b = edge_b.map(|e| swing_from(e, 1));
    let from_a = edge_a.map(|e| swing_from(e, 0));
    let lo = from_b.map(|f| f.2);
    let td = from_a.map(|f| f.2);
    let held = hold(
        lo.map_or(f64::INFINITY, |lo| t - lo)
            .min(td.map_or(f64::INFINITY, |td| td - t)),
        hold_s,
    );
    match (from_b, from_a) {
        (Some(pb), Some(pa)) => {
            let (lo, td) = (pb.2, pa.2);
            let w = smooth(if td > lo { (t - lo) / (td - lo) } else { 1.0 });
            let p = std::array::from_fn(|i| pb.0[i] + w * (pa.0[i] - pb.0[i]));
            Some((p, rot::slerp(pb.1, pa.1, w), [1.0, held]))
        }
        // Before the first or after the last stance of a foot with no stance a cycle on
        // (a jump, a single cycle): held near that contact, horizontally too (the source
        // foot's path far from its only contact, time-warped, stretched the leg).
        (Some(p), None) | (None, Some(p)) => Some((p.0, p.1, [held; 2])),
        _ => None,
    }
}

/// How strongly a swinging foot is held on its planted path `τ` (s) from its nearest own
/// touchdown or liftoff: `1 − smoothstep(τ / hold_s)`, 1 at the contact, 0 from `hold_s`
/// on (where the foot follows the body); always 1 when `hold_s ≤ 0`.
fn hold(tau: f64, hold_s: f64) -> f64 {
    if hold_s > 0.0 {
        1.0 - smooth(tau / hold_s)
    } else {
        1.0
    }
}

/// How far a foot is pulled from the reference pose's towards its goal: horizontally,
/// vertically (and in orientation); 1 is onto it.
pub(super) type Pull = [f64; 2];

/// What one frame's root/IK iteration aims at: the planned COM (m), the foot pulls
/// ([`foot_goal`]) and which legs are planted (support).
pub(super) struct FrameGoal {
    pub(super) com: V3,
    pub(super) pulls: [Option<(V3, Quat, Pull)>; 2],
    pub(super) planted: [bool; 2],
}
