//! Contact runs with event times, surface heights and contact frames (spec com-from-bvh
//! §7.3 event times, §7.5 contact frames, §8 `contacts.parquet`).
//!
//! # Model
//! ```text
//! run a..b:  t_TD = t[a] − dt/2 (null at the first kept frame), t_LO = t[b] + dt/2 (null at the last)
//!            td_time, lo_time: feet, sub-frame times (contacts::timing), or the touchdown
//!            of a landing found from the foot's motion (contacts::landing), or, for a step
//!            into or out of the other foot's support, the walking rule (contacts::walking);
//!            hands, t_TD and t_LO
//! origin    = mean of the effector's contact points over the run
//! yaw       = atan2 of the mean horizontal ankle→toe (wrist→MET3) direction; facing from the
//!             hips when that is vertical
//! surface_z = static run: median height of its triggering point; speed-led run
//!             (contacts::support): median ground_z + the lowest over its points of the
//!             median height above the point's own floor (§7.1), the step it stands on;
//!             else median ground_z
//! COM in the run's contact frame (spec two-pac §3, eq 3; the kinematic samples):
//!           ʳc = R_eᵀ (c − p_e),   R_e = Rz(yaw), p_e = origin       (m)
//! ```
//! The outlier rules and the hull that turn those points into kinematic polytopes are in
//! [`crate::twopac::limb_reach`].

use super::timeline::{ContactTimeline, ContactTracks};
use super::walking::{self, WalkRatios};
use super::{runs, timing, ClipMotion, EFFECTORS};
use crate::math::stats::median;
use crate::math::v3::V3;

/// One maximal run of `contact_<e>`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRun {
    /// `left_foot`, `right_foot`, `left_hand` or `right_hand`.
    pub effector: &'static str,
    /// First file row of the run.
    pub first_frame: i64,
    /// Last file row of the run.
    pub last_frame: i64,
    /// Touchdown time, s (null at a clip edge).
    pub t_td_s: Option<f64>,
    /// Liftoff time, s (null at a clip edge).
    pub t_lo_s: Option<f64>,
    /// Sub-frame touchdown time, s (null at a clip edge; [`crate::contacts::timing`]).
    pub td_time_s: Option<f64>,
    /// Sub-frame liftoff time, s (null at a clip edge).
    pub lo_time_s: Option<f64>,
    /// Some frame of the run was found by the speed-led rule of the physics cross-check
    /// ([`crate::contacts::support`]).
    pub speed_led: bool,
    /// Static contact on some frame of the run.
    pub is_static: bool,
    /// Contact height, m.
    pub surface_z: f64,
    /// Contact-frame origin, m.
    pub origin: V3,
    /// Contact-frame x direction about +z, rad.
    pub yaw_rad: f64,
    /// Surface normal (always +z from kinematics).
    pub normal: V3,
}

/// Collect the runs of every effector (sorted by effector, then first frame).
pub fn collect(
    tracks: &ContactTracks,
    timeline: &ContactTimeline,
    motion: &ClipMotion,
    static_mode: bool,
) -> Vec<ContactRun> {
    let (contact, stat, surf) = (
        &timeline.contact,
        &timeline.static_contact,
        &timeline.surface_z,
    );
    let (points, ground_z, dt) = (&tracks.points, &tracks.ground_z, tracks.dt);
    let (facing, frame, time_s) = (motion.facing, motion.frame, motion.time_s);
    let n = frame.len();
    let n_support = walking::min_support_frames(time_s);
    let kappa = WalkRatios::default();
    let mut out = Vec::new();
    for e in 0..4 {
        let ratio = (e < 2).then(|| walking::speed_ratio(&tracks.tracks[e], motion.com_speed_h));
        for (a, b) in runs(&contact[e]) {
            let pts = &points[e];
            let count = ((b - a + 1) * pts.len().max(1)) as f64;
            let origin: V3 = std::array::from_fn(|i| {
                pts.iter()
                    .map(|p| (a..=b).map(|f| p[f][i]).sum::<f64>())
                    .sum::<f64>()
                    / count
            });
            let (mut dx, mut dy) = (0.0, 0.0);
            if pts.len() == 2 {
                for (p0, p1) in pts[0][a..=b].iter().zip(&pts[1][a..=b]) {
                    dx += p1[0] - p0[0];
                    dy += p1[1] - p0[1];
                }
            }
            if (dx * dx + dy * dy).sqrt() < 1e-9 * (b - a + 1) as f64 {
                dx = (a..=b).map(|f| facing[f][0]).sum();
                dy = (a..=b).map(|f| facing[f][1]).sum();
            }
            let first_static = static_mode.then(|| (a..=b).find(|&f| stat[e][f])).flatten();
            let speed_led = timeline.speed_led[e][a..=b].iter().any(|&f| f);
            let floor = median(&ground_z[a..=b]).unwrap_or(0.0);
            let raised = || {
                tracks.tracks[e]
                    .iter()
                    .filter_map(|p| median(&p.h[a..=b]))
                    .reduce(f64::min)
            };
            let surface_z = match (first_static.and_then(|f| surf[e][f]), speed_led) {
                (Some(z), _) => z,
                (None, true) => floor + raised().unwrap_or(0.0),
                (None, false) => floor,
            };
            let own = &tracks.tracks[e];
            let prev_end = out
                .iter()
                .rev()
                .find(|r: &&ContactRun| r.effector == EFFECTORS[e])
                .map_or(0, |r| (r.last_frame - frame[0] + 1) as usize);
            let next_start = runs(&contact[e])
                .into_iter()
                .find(|&(x, _)| x > b)
                .map_or(n - 1, |(x, _)| x - 1);
            out.push(ContactRun {
                effector: EFFECTORS[e],
                first_frame: frame[a],
                last_frame: frame[b],
                t_td_s: (a > 0).then(|| time_s[a] - dt / 2.0),
                t_lo_s: (b + 1 < n).then(|| time_s[b] + dt / 2.0),
                td_time_s: (a > 0).then(|| match (timeline.landing_s[e][a], e < 2) {
                    (Some(t), _) => t,
                    (None, true) if !own.is_empty() => {
                        let other = &contact[1 - e];
                        ratio
                            .as_deref()
                            .filter(|_| walking::supported(other, a.saturating_sub(n_support), a))
                            .and_then(|r| {
                                walking::touchdown(r, time_s, a, b, prev_end, kappa.touchdown)
                            })
                            .unwrap_or_else(|| timing::touchdown(own, time_s, a, b, prev_end))
                    }
                    _ => time_s[a] - dt / 2.0,
                }),
                lo_time_s: (b + 1 < n).then(|| match e < 2 && !own.is_empty() {
                    true => {
                        let other = &contact[1 - e];
                        ratio
                            .as_deref()
                            .filter(|_| walking::supported(other, b, b + n_support))
                            .and_then(|r| {
                                walking::liftoff(r, time_s, a, b, next_start, kappa.liftoff)
                            })
                            .unwrap_or_else(|| timing::liftoff(own, time_s, a, b, next_start))
                    }
                    false => time_s[b] + dt / 2.0,
                }),
                speed_led,
                is_static: first_static.is_some(),
                surface_z,
                origin,
                yaw_rad: dy.atan2(dx),
                normal: [0.0, 0.0, 1.0],
            });
        }
    }
    out
}

/// The COM in a yaw-only contact frame: `Rz(yaw)ᵀ (c − origin)`, m.
pub fn com_in_contact_frame(com: [f64; 3], origin: [f64; 3], yaw_rad: f64) -> [f64; 3] {
    let (s, c) = yaw_rad.sin_cos();
    let d = [com[0] - origin[0], com[1] - origin[1], com[2] - origin[2]];
    [c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_frame_undoes_yaw_and_origin() {
        let origin = [1.0, 2.0, 0.1];
        let yaw = 0.7f64;
        // A point 0.3 m ahead, 0.1 m left, 0.9 m up in the contact frame.
        let local = [0.3, 0.1, 0.9];
        let (s, c) = yaw.sin_cos();
        let world = [
            origin[0] + c * local[0] - s * local[1],
            origin[1] + s * local[0] + c * local[1],
            origin[2] + local[2],
        ];
        let back = com_in_contact_frame(world, origin, yaw);
        for k in 0..3 {
            assert!((back[k] - local[k]).abs() < 1e-12, "{back:?}");
        }
    }
}
