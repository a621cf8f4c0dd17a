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
//! ```
//! A foot that stays still is carrying weight even when it stands higher than its local
//! floor admits (a step, a platform, a box): the height rule of spec com-from-bvh §7.3 then
//! loses the whole stance and the "flight" it leaves behind curves the wrong way. The
//! speed-led frames are OR-ed into that effector's flags inside the interval only, the
//! flights are fitted again, and each case is reported in the clip's `warnings`. A real
//! flight is ballistic, so the check never touches it; its swing feet move at metres per
//! second.
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
//! 120 Hz, half the shortest interval the check looks at.
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

/// Thresholds of the speed-led rule.
#[derive(serde::Serialize, Debug, Clone, Copy, PartialEq)]
pub struct SpeedLedRule {
    /// Enter when some point is at most this fast, m/s.
    pub v_on: f64,
    /// Leave when every point is faster than this, m/s.
    pub v_off: f64,
    /// Runs shorter than this are dropped, s.
    pub min_on_s: f64,
}

impl Default for SpeedLedRule {
    fn default() -> Self {
        SpeedLedRule {
            v_on: DEFAULT_SPEED_LED_V_ON,
            v_off: DEFAULT_SPEED_LED_V_OFF,
            min_on_s: DEFAULT_SPEED_LED_MIN_ON_S,
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

/// The physics cross-check of a clip's contacts (see the module docs): each missed-support
/// flight of `timeline` gets the speed-led frames of every support effector inside it
/// (OR-ed into `contact`, marked in `speed_led`); when any were found the flags are
/// cleaned again and `runs_out` collected again. Returns one clip warning per missed
/// support that the rule resolved.
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
        let mut found = Vec::new();
        for (e, track) in tracks.tracks.iter().enumerate() {
            if track.is_empty() {
                continue;
            }
            let sl = speed_led(track, a, b, &rule, rate, opts.min_gap_s);
            for (x, y) in runs(&sl) {
                timeline.contact[e][a + x..=a + y]
                    .iter_mut()
                    .for_each(|v| *v = true);
                timeline.speed_led[e][a + x..=a + y]
                    .iter_mut()
                    .for_each(|v| *v = true);
                found.push(format!(
                    "{} {}-{}",
                    EFFECTORS[e],
                    skip + (a + x) as i64,
                    skip + (a + y) as i64
                ));
                changed = true;
            }
        }
        if !found.is_empty() {
            warnings.push(missed_support_warning(
                &f,
                &format!("speed-led contacts: {}", found.join(", ")),
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
}
