//! Physics cross-check of the contacts: a no-contact interval whose COM is not ballistic
//! is a missed support, re-detected by a speed-led rule.
//!
//! # Model
//! ```text
//! interval:       a no-contact run a..b not at a clip edge, bounded by the sub-frame
//!                 liftoff t_LO before it and touchdown t_TD after it (contacts::timing)
//! missed support ⇔ t_TD − t_LO ≥ 0.1 s − 1 µs (n·dt without events) and |a_z + g| > 3 m/s²,
//!                 a_z = curvature of the free parabola of the raw COM height over the
//!                 frames strictly between t_LO and t_TD (flight::curvature_inside, ≥ 5)
//! speed-led rule over a..b, per support effector (both points of §7.2):
//!   enter ⇔ ∃p: v_p ≤ 1.0 m/s;  leave ⇔ ∀p: v_p > 1.5 m/s   (unsmoothed 3-D speeds; no height test)
//!   gaps < min_gap filled, runs < 0.05 s dropped
//!   a run x..y is a support only where a body could be supported:
//!   mean over x..y of (a_z + g) ≥ 3 m/s²   (SG vertical COM acceleration: the COM is held up)
//! ```
//! A foot that stays still is carrying weight even when it stands higher than its local
//! floor admits (a step, a platform, a box): the height rule of spec com-from-bvh §7.3 then
//! loses the whole stance and the "flight" it leaves behind curves the wrong way. The
//! speed-led frames are OR-ed into that effector's flags inside the interval only, the
//! flights are fitted again, and each case is reported in the clip's `warnings`. A real
//! flight is ballistic, so the check never touches it; its swing feet move at metres per
//! second. But when a lost landing makes a whole jump look non-ballistic, the rule runs over
//! the flight too, and at its apex every point of the body is slow: a foot or hand found
//! there would be a support in mid-air (a held-out standing jump had both feet on a
//! "surface" 0.22 m high and a hand on one 2.03 m high). A support holds the COM up, so a
//! speed-led run counts only where the COM's vertical acceleration averages at least
//! 3 m/s² above −g; the rejected runs are named in the clip's warnings. (A run is judged
//! whole: trimming its free-falling edges frame by frame cut hangs short by the SG
//! filter's half-window and, on CMU 05_08, left a dancer's COM "falling" at −12.7 m/s².)
//!
//! # Why these numbers
//! 3 m/s²: the scatter of short running flights' fitted curvature (spec §7.7: ±3 m/s² on
//! 8–17 interior frames). The fit takes every frame between the sub-frame events, not the
//! interior of the frame run: the frame-edge contacts are one to two frames late at 120 Hz,
//! so the last frames of a running "flight" already carry the next stance (CMU 09_01's
//! 0.1 s flight at frames 72–83: −6.7 m/s² over its 12 frames, −8.2 over the 12 frames
//! between its events, 70–81). 1.0 / 1.5 m/s: a planted foot moves at a few tenths of a
//! m/s in the capture (marker and soft-tissue motion), a swing foot at 2–7 m/s; inside a
//! non-ballistic interval the gate can be generous (0.5 m/s missed the still-but-noisy
//! feet and hands of several CMU playground and dance clips). 0.05 s: six frames at
//! 120 Hz, half the shortest interval the check looks at. 3 m/s² of lift: the tolerance of
//! the curvature test (a body that falls within 3 m/s² of −g is not held); the 781
//! speed-led supports the rule finds on the shared and bulk clips average from −5.85 m/s²
//! upwards (−g + 3.96: a playground step taken in a descent), a jump's apex −g ± 1.
//!
//! # References
//! spec com-from-bvh §7.3, §7.4 (the static mode, off by default, is the whole-clip
//! relative of this rule), §7.7.

use super::contact_runs::{self, ContactRun};
use super::detect::{clean, hysteresis_by, PointTrack};
use super::flight::{flights, Flight, AIRBORNE_MIN_S, AIRBORNE_TOL_S, G};
use super::options::ContactOptions;
use super::timeline::{ContactTimeline, ContactTracks};
use super::{runs, ClipMotion, EFFECTORS};

/// A no-contact interval whose fitted vertical COM curvature lies further than this from
/// −g is not a flight but a missed support, m/s².
pub const MISSED_SUPPORT_CURVATURE_TOL: f64 = 3.0;
/// Speed-led rule: enter speed, m/s (3-D, unsmoothed).
pub const DEFAULT_SPEED_LED_V_ON: f64 = 1.0;
/// Speed-led rule: leave speed, m/s.
pub const DEFAULT_SPEED_LED_V_OFF: f64 = 1.5;
/// Speed-led rule: shortest support kept, s.
pub const DEFAULT_SPEED_LED_MIN_ON_S: f64 = 0.05;
/// Speed-led rule: least mean lift `a_z + g` of the COM over a support (SG vertical
/// acceleration), m/s²; the curvature test's tolerance.
pub const DEFAULT_SPEED_LED_MIN_LIFT_MPS2: f64 = MISSED_SUPPORT_CURVATURE_TOL;

/// Thresholds of the speed-led rule.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct SpeedLedRule {
    /// Enter when some point is at most this fast, m/s.
    pub v_on: f64,
    /// Leave when every point is faster than this, m/s.
    pub v_off: f64,
    /// Runs shorter than this are dropped, s.
    pub min_on_s: f64,
    /// Runs over which the COM's mean `a_z + g` is below this are not supports, m/s².
    pub min_lift_mps2: f64,
}

impl Default for SpeedLedRule {
    fn default() -> Self {
        SpeedLedRule {
            v_on: DEFAULT_SPEED_LED_V_ON,
            v_off: DEFAULT_SPEED_LED_V_OFF,
            min_on_s: DEFAULT_SPEED_LED_MIN_ON_S,
            min_lift_mps2: DEFAULT_SPEED_LED_MIN_LIFT_MPS2,
        }
    }
}

/// The no-contact run lasts at least 0.1 s (between its sub-frame events when they are
/// known, else `n·dt`) and its COM is not ballistic: the free parabola over the frames
/// inside it (`Flight::a_z_all`) curves more than [`MISSED_SUPPORT_CURVATURE_TOL`] away
/// from −g.
pub fn is_missed_support(f: &Flight) -> bool {
    f.events_duration_s.unwrap_or(f.duration_s) >= AIRBORNE_MIN_S - AIRBORNE_TOL_S
        && f.a_z_all
            .is_some_and(|a| (a + G).abs() > MISSED_SUPPORT_CURVATURE_TOL)
}

/// Speed-led contact flags of one effector over frames `a..=b` (index 0 is frame `a`);
/// gaps shorter than `min_gap_s` are filled.
pub fn speed_led(
    points: &[PointTrack],
    a: usize,
    b: usize,
    rule: &SpeedLedRule,
    rate_hz: f64,
    min_gap_s: f64,
) -> Vec<bool> {
    let sub: Vec<PointTrack> = points
        .iter()
        .map(|p| PointTrack {
            h: p.h[a..=b].to_vec(),
            v: p.v[a..=b].to_vec(),
        })
        .collect();
    let mut flags = hysteresis_by(&sub, |p, k| p.v[k] <= rule.v_on, |p, k| p.v[k] > rule.v_off);
    clean(&mut flags, rate_hz, min_gap_s, rule.min_on_s);
    flags
}

/// The COM is held up over frames `x..=y`: its mean SG vertical acceleration is at least
/// `min_lift_mps2` above −g (`com_az`: m/s² per kept frame).
pub fn holds_the_body(com_az: &[f64], x: usize, y: usize, min_lift_mps2: f64) -> bool {
    let Some(w) = com_az.get(x..=y).filter(|w| !w.is_empty()) else {
        return false;
    };
    w.iter().sum::<f64>() / w.len() as f64 + G >= min_lift_mps2
}

/// The physics cross-check of a clip's contacts (see the module docs): each missed-support
/// flight of `timeline` gets the speed-led frames of every support effector inside it
/// where the COM is held up (OR-ed into `contact`, marked in `speed_led`); when any were
/// found the flags are cleaned again and `runs_out` collected again. Returns one clip
/// warning per missed support that the rule resolved, and one per interval where it
/// rejected a slow foot or hand because the COM fell freely over it.
pub fn cross_check(
    tracks: &ContactTracks,
    timeline: &mut ContactTimeline,
    motion: &ClipMotion,
    opts: &ContactOptions,
    runs_out: &mut Vec<ContactRun>,
) -> Vec<String> {
    let rule = SpeedLedRule::default();
    let rate = 1.0 / tracks.dt;
    let skip = motion.frame[0];
    let mut warnings = Vec::new();
    let mut changed = false;
    for f in flights(&timeline.contact, runs_out, motion) {
        if !is_missed_support(&f) {
            continue;
        }
        let (a, b) = (
            (f.first_frame - skip) as usize,
            (f.last_frame - skip) as usize,
        );
        let (mut found, mut rejected) = (Vec::new(), Vec::new());
        for (e, track) in tracks.tracks.iter().enumerate() {
            if track.is_empty() {
                continue;
            }
            let sl = speed_led(track, a, b, &rule, rate, opts.min_gap_s);
            for (x, y) in runs(&sl) {
                let name = format!(
                    "{} {}-{}",
                    EFFECTORS[e],
                    skip + (a + x) as i64,
                    skip + (a + y) as i64
                );
                if !holds_the_body(motion.com_az, a + x, a + y, rule.min_lift_mps2) {
                    rejected.push(name);
                    continue;
                }
                timeline.contact[e][a + x..=a + y]
                    .iter_mut()
                    .for_each(|v| *v = true);
                timeline.speed_led[e][a + x..=a + y]
                    .iter_mut()
                    .for_each(|v| *v = true);
                found.push(name);
                changed = true;
            }
        }
        if !found.is_empty() {
            warnings.push(missed_support_warning(
                &f,
                &format!("speed-led contacts: {}", found.join(", ")),
            ));
        }
        if !rejected.is_empty() {
            warnings.push(missed_support_warning(
                &f,
                &format!(
                    "slow but not supporting (the COM falls freely over them): {}",
                    rejected.join(", ")
                ),
            ));
        }
    }
    if changed {
        for flags in timeline.contact.iter_mut() {
            clean(flags, rate, opts.min_gap_s, opts.min_on_s);
        }
        *runs_out = contact_runs::collect(tracks, timeline, motion, opts.static_mode);
    }
    warnings
}

/// The clip warning for a no-contact interval whose COM is not ballistic; `outcome` says
/// what the speed-led rule found.
pub fn missed_support_warning(f: &Flight, outcome: &str) -> String {
    format!(
        "missed support: no contact over frames {}-{} ({:.3} s) but the COM curves at {:+.2} m/s², not -g; {outcome}",
        f.first_frame,
        f.last_frame,
        f.events_duration_s.unwrap_or(f.duration_s),
        f.a_z_all.unwrap_or(f64::NAN),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_still_point_high_above_its_floor_is_in_contact_and_a_fast_one_is_not() {
        let n = 40;
        let still = PointTrack {
            h: vec![0.05; n],
            v: (0..n)
                .map(|k| if (10..30).contains(&k) { 0.05 } else { 3.0 })
                .collect(),
        };
        let fast = PointTrack {
            h: vec![0.0; n],
            v: vec![2.0; n],
        };
        let f = speed_led(
            &[still, fast.clone()],
            0,
            n - 1,
            &SpeedLedRule::default(),
            120.0,
            0.03,
        );
        assert_eq!(f.iter().position(|&x| x), Some(10));
        assert_eq!(f.iter().rposition(|&x| x), Some(29));
        // 5 slow frames at 120 Hz (0.042 s) are shorter than the 0.05 s minimum.
        let short = PointTrack {
            h: vec![0.05; n],
            v: (0..n)
                .map(|k| if (10..15).contains(&k) { 0.05 } else { 3.0 })
                .collect(),
        };
        let g = speed_led(
            &[short, fast],
            0,
            n - 1,
            &SpeedLedRule::default(),
            120.0,
            0.03,
        );
        assert!(g.iter().all(|&x| !x));
    }

    /// A standing jump whose landing the height rule lost: no contact from the takeoff at
    /// frame 60 to frame 159, the COM ballistic until the real landing at frame 130 and
    /// decelerating after it. At the apex (frames 90–104) both feet and the right hand are
    /// slow, as every point of a body at the top of its flight; after the landing the feet
    /// are slow on the floor.
    #[test]
    fn slow_points_at_a_jumps_apex_are_not_supports() {
        use crate::contacts::timeline::detect;
        let (n, dt) = (240, 1.0 / 120.0);
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let (takeoff, landing, contact_again) = (60, 130, 160);
        let com_az: Vec<f64> = (0..n)
            .map(|k| match k {
                k if (takeoff..landing).contains(&k) => -G,
                k if (landing..contact_again).contains(&k) => 20.0,
                _ => 0.0,
            })
            .collect();
        // COM height: integrate the acceleration from rest at 1 m with 3 m/s at takeoff.
        let (mut z, mut vz, mut com) = (1.0, 0.0, Vec::new());
        for (k, a) in com_az.iter().enumerate() {
            if k == takeoff {
                vz = 3.0;
            }
            com.push([0.0, 0.0, z]);
            vz += a * dt;
            z += vz * dt;
        }
        let speed = |slow: &[std::ops::Range<usize>]| -> Vec<f64> {
            (0..n)
                .map(|k| match slow.iter().any(|r| r.contains(&k)) {
                    true => 0.3,
                    false if (takeoff..contact_again).contains(&k) => 3.0,
                    false => 0.0,
                })
                .collect()
        };
        let foot = PointTrack {
            h: (0..n)
                .map(|k| {
                    if (takeoff..landing).contains(&k) {
                        0.3
                    } else {
                        0.0
                    }
                })
                .collect(),
            v: speed(&[90..105, 135..contact_again]),
        };
        let hand = PointTrack {
            h: vec![1.0; n],
            v: speed(std::slice::from_ref(&(92..103))),
        };
        let pts = vec![vec![[0.0; 3]; n]; 2];
        let mut tracks = ContactTracks {
            ground_z: vec![0.0; n],
            tracks: Default::default(),
            points: Default::default(),
            dt,
            leg_scale: 1.0,
            toe_estimated: [false; 2],
        };
        for e in 0..2 {
            tracks.tracks[e] = vec![foot.clone(), foot.clone()];
            tracks.points[e] = pts.clone();
        }
        tracks.tracks[3] = vec![hand.clone(), hand];
        tracks.points[3] = pts.clone();
        let opts = ContactOptions::default();
        let mut timeline = detect(&tracks, &opts);
        for e in 0..2 {
            timeline.contact[e] = (0..n)
                .map(|k| !(takeoff..contact_again).contains(&k))
                .collect();
        }
        timeline.contact[3] = vec![false; n];
        let frame: Vec<i64> = (0..n as i64).collect();
        let vz: Vec<f64> = vec![0.0; n];
        let facing = vec![[1.0, 0.0, 0.0]; n];
        let motion = ClipMotion {
            frame: &frame,
            time_s: &t,
            dt,
            com: &com,
            com_vz: &vz,
            com_speed_h: &vz,
            com_az: &com_az,
            facing: &facing,
        };
        let mut runs_out = contact_runs::collect(&tracks, &timeline, &motion, false);
        let before = flights(&timeline.contact, &runs_out, &motion);
        assert!(before.iter().any(is_missed_support), "{before:?}");
        let warnings = cross_check(&tracks, &mut timeline, &motion, &opts, &mut runs_out);
        println!("{warnings:#?}");
        // Nothing at the apex: no effector in contact over frames 90-104.
        for (flags, name) in timeline.contact.iter().zip(EFFECTORS) {
            assert!(
                !flags[90..105].iter().any(|&c| c),
                "{name} in contact at the apex"
            );
        }
        // The landing is found where the feet are slow and the COM decelerates.
        for (flags, name) in timeline.speed_led.iter().zip(EFFECTORS).take(2) {
            let first = (landing..contact_again).find(|&k| flags[k]);
            assert_eq!(first, Some(135), "{name}");
        }
        assert!(warnings.iter().any(|w| w.contains("not supporting")
            && w.contains("right_hand 92-102")
            && w.contains("left_foot 90-104")));
        // The same rule without the lift test finds the apex "supports" (the defect).
        assert!(!holds_the_body(
            &com_az,
            90,
            104,
            DEFAULT_SPEED_LED_MIN_LIFT_MPS2
        ));
        assert!(holds_the_body(
            &com_az,
            135,
            159,
            DEFAULT_SPEED_LED_MIN_LIFT_MPS2
        ));
    }
}
