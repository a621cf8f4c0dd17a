//! The contact stage of one clip: point tracks above the local floors, then the per-frame
//! contact flags of every effector (the clip's contact timeline).
//!
//! # Model
//! ```text
//! ground_z(k)   = local floor from both toe tips (floor::ground, half-window T_floor)
//! foot point p:  h_p = floor::foot_heights(z_p, ground_z, clearance_p · L_leg/0.84)
//! hand point p:  h_p = floor::hand_heights(z_p, ground_z, clearance_p · L_leg/0.84)
//! v_p           = raw_speed(p)                                  (unsmoothed, m/s)
//! contact_e     = clean(hysteresis(tracks_e, thresholds_e))      (§7.3, §7.6)
//! static mode:  static_e = clean(static_hysteresis(tracks_e)); contact_e |= static_e,
//!               cleaned again; surface_z = median height of the triggering point (§7.4)
//! ```
//!
//! # Frames and units
//! Metres, internal Z-up frame; one entry per kept frame.
//!
//! # References
//! spec com-from-bvh §7.1–§7.6.

use super::detect::{clean, hysteresis, static_hysteresis, PointTrack};
use super::options::{ContactOptions, STATIC_MIN_GAP_S, STATIC_MIN_ON_S};
use super::{floor, raw_speed, runs};
use crate::math::stats::median;
use crate::math::v3::V3;
use crate::skeleton::units::NOMINAL_LEG_M;

/// The contact points of one clip, one entry per kept frame (metres, Z up).
#[derive(Debug, Clone, PartialEq)]
pub struct EffectorPoints {
    /// Ankle centre and toe tip of the left and right foot.
    pub feet: [[Vec<V3>; 2]; 2],
    /// Wrist centre and MET3 of the left and right hand; `None` without that arm.
    pub hands: [Option<[Vec<V3>; 2]>; 2],
    /// Per foot: its toe tip is the ingest's fallback estimate (spec com-from-bvh §4.3), a
    /// fixed offset from the ankle that never pitches with the foot.
    pub toe_estimated: [bool; 2],
}

/// What the detector sees of a clip: the local floor and, per effector
/// ([`super::EFFECTORS`] order), each contact point's track and positions (empty for an
/// effector that is not a support: a missing arm, or hands off).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactTracks {
    /// Local floor height per frame, m.
    pub ground_z: Vec<f64>,
    /// Height above the point's floor and raw speed, per effector and point.
    pub tracks: [Vec<PointTrack>; 4],
    /// Positions per effector and point (the same points as `tracks`), m.
    pub points: [Vec<Vec<V3>>; 4],
    /// Frame time, s.
    pub dt: f64,
    /// `L_leg / NOMINAL_LEG_M`: the scale of the clearances and height bounds.
    pub leg_scale: f64,
    /// Per foot: its toe tip is estimated ([`EffectorPoints::toe_estimated`]).
    pub toe_estimated: [bool; 2],
}

impl ContactTracks {
    /// Kept frames.
    pub fn n_frames(&self) -> usize {
        self.ground_z.len()
    }
}

/// Per-frame contact flags of every effector ([`super::EFFECTORS`] order).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactTimeline {
    /// In contact.
    pub contact: [Vec<bool>; 4],
    /// In static contact (static mode only; outside it, empty for an effector with tracks
    /// and all false for one without).
    pub static_contact: [Vec<bool>; 4],
    /// Static surface height, m, on the frames of a static run (static mode only, as
    /// `static_contact`).
    pub surface_z: [Vec<Option<f64>>; 4],
    /// Found by the speed-led rule of the physics cross-check ([`super::support`]).
    pub speed_led: [Vec<bool>; 4],
    /// On the first frame of a run that a foot's own motion started
    /// ([`super::landing`]): its sub-frame touchdown, s.
    pub landing_s: [Vec<Option<f64>>; 4],
}

fn heights_z(v: &[V3]) -> Vec<f64> {
    v.iter().map(|p| p[2]).collect()
}

/// Point tracks above the local floor (§7.1, §7.2): every foot always; the hands when
/// `opts.hands`. `leg_m` scales the clearances (`L_leg / NOMINAL_LEG_M`).
pub fn tracks(pts: EffectorPoints, leg_m: f64, dt: f64, opts: &ContactOptions) -> ContactTracks {
    let half = floor::half_window(dt, opts.floor_window_s);
    let [[_, toe_l], [_, toe_r]] = &pts.feet;
    let ground_z = floor::ground(&heights_z(toe_l), &heights_z(toe_r), half);
    let sc = leg_m / NOMINAL_LEG_M;
    let track_of = |p: &[V3], h: Vec<f64>| PointTrack {
        h,
        v: raw_speed(p, dt),
    };
    let mut tracks: [Vec<PointTrack>; 4] = Default::default();
    let mut points: [Vec<Vec<V3>>; 4] = Default::default();
    let toe_estimated = pts.toe_estimated;
    let [feet_l, feet_r] = pts.feet;
    for (k, [ankle, toe]) in [feet_l, feet_r].into_iter().enumerate() {
        let foot = |p: &[V3], clearance: f64| {
            floor::foot_heights(&heights_z(p), &ground_z, half, clearance, sc)
        };
        tracks[k] = vec![
            track_of(&ankle, foot(&ankle, floor::CLEARANCE_ANKLE)),
            track_of(&toe, foot(&toe, floor::CLEARANCE_TTIP)),
        ];
        points[k] = vec![ankle, toe];
    }
    if opts.hands {
        let [hand_l, hand_r] = pts.hands;
        for (k, hand) in [hand_l, hand_r].into_iter().enumerate() {
            let Some([wrist, met3]) = hand else { continue };
            let hand = |p: &[V3], clearance: f64| {
                floor::hand_heights(&heights_z(p), &ground_z, clearance, sc)
            };
            tracks[2 + k] = vec![
                track_of(&wrist, hand(&wrist, floor::CLEARANCE_WRIST)),
                track_of(&met3, hand(&met3, floor::CLEARANCE_MET3)),
            ];
            points[2 + k] = vec![wrist, met3];
        }
    }
    ContactTracks {
        ground_z,
        tracks,
        points,
        dt,
        leg_scale: sc,
        toe_estimated,
    }
}

/// The contact timeline of a clip (§7.3, §7.4, §7.6): hysteresis with gap filling and
/// minimum durations per effector, and the static mode when `opts.static_mode`. No
/// speed-led frames or landings from the foot's motion yet ([`super::support::cross_check`]
/// and [`super::landing`] add them).
pub fn detect(tracks: &ContactTracks, opts: &ContactOptions) -> ContactTimeline {
    let n = tracks.n_frames();
    let rate = 1.0 / tracks.dt;
    let mut contact: [Vec<bool>; 4] = Default::default();
    let mut stat: [Vec<bool>; 4] = Default::default();
    let mut surf: [Vec<Option<f64>>; 4] = Default::default();
    for e in 0..4 {
        let track = &tracks.tracks[e];
        if track.is_empty() {
            contact[e] = vec![false; n];
            stat[e] = vec![false; n];
            surf[e] = vec![None; n];
            continue;
        }
        let th = if e < 2 { &opts.foot } else { &opts.hand };
        let mut flags = hysteresis(track, th);
        clean(&mut flags, rate, opts.min_gap_s, opts.min_on_s);
        if opts.static_mode {
            let (sflags, z) = static_runs(track, &tracks.points[e], rate);
            flags.iter_mut().zip(&sflags).for_each(|(f, s)| *f |= *s);
            clean(&mut flags, rate, opts.min_gap_s, opts.min_on_s);
            stat[e] = sflags;
            surf[e] = z;
        }
        contact[e] = flags;
    }
    ContactTimeline {
        contact,
        static_contact: stat,
        surface_z: surf,
        speed_led: std::array::from_fn(|_| vec![false; n]),
        landing_s: std::array::from_fn(|_| vec![None; n]),
    }
}

/// Static contact of one effector (§7.4): its flags and, on the frames of each static run,
/// the median height of the point that triggered it.
fn static_runs(
    track: &[PointTrack],
    points: &[Vec<V3>],
    rate: f64,
) -> (Vec<bool>, Vec<Option<f64>>) {
    let (mut sflags, trig) = static_hysteresis(track);
    clean(&mut sflags, rate, STATIC_MIN_GAP_S, STATIC_MIN_ON_S);
    let mut surf = vec![None; sflags.len()];
    for (a, b) in runs(&sflags) {
        let p = trig[a].unwrap_or(0);
        let z: Vec<f64> = (a..=b).map(|f| points[p][f][2]).collect();
        let m = median(&z);
        surf[a..=b].iter_mut().for_each(|s| *s = m);
    }
    (sflags, surf)
}
