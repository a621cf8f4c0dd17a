//! Contact detection: local floors, per-effector hysteresis with minimum durations, the
//! optional static (elevated) contact mode, and the flight fits of the airborne runs.
//!
//! # Model
//! ```text
//! EffectorPoints ─ tracks ─▶ ContactTracks ─ detect ─▶ ContactTimeline
//!     ─ runs_and_flights ─▶ contact runs (contact_runs::collect, sub-frame events: timing;
//!                           steps into and out of double support: walking)
//!                           landings of estimated toe tips from the foot's motion (landing)
//!                           physics cross-check (support::cross_check, speed-led rule)
//!                           hidden flights of jogs (hidden_flight)
//!                           flights of the no-contact runs (flights, §7.7)
//! ```
//! The last four steps are departures from spec §7.3 that check the contacts against the
//! body's physics; `support_check` (on by default) turns them on.
//! Data flow: contact-point trajectories (metres, Z up) → [`floor`] heights →
//! [`mod@detect`] flags per effector → [`flight`] diagnostics of the no-contact runs.
//!
//! # References
//! spec com-from-bvh §7, §8.

pub mod contact_runs;
pub mod detect;
pub mod flight;
pub mod floor;
pub mod hidden_flight;
pub mod landing;
pub mod options;
pub mod support;
pub mod timeline;
pub mod timing;
pub mod walking;

pub use contact_runs::ContactRun;
pub use flight::{flights, Flight};
pub use options::ContactOptions;
pub use timeline::{detect, tracks, ContactTimeline, ContactTracks, EffectorPoints};

use crate::math::v3::V3;

/// The clip's clock and COM, by which contact runs are timed and flights fitted (one entry
/// per kept frame).
#[derive(Debug, Clone, Copy)]
pub struct ClipMotion<'a> {
    /// File row per kept frame (consecutive).
    pub frame: &'a [i64],
    /// `frame · dt`, s.
    pub time_s: &'a [f64],
    /// Frame time, s.
    pub dt: f64,
    /// Raw whole-body COM, m.
    pub com: &'a [V3],
    /// SG vertical COM velocity, m/s.
    pub com_vz: &'a [f64],
    /// SG horizontal COM speed `|(v_x, v_y)|`, m/s (the walking rule's reference,
    /// [`walking`]).
    pub com_speed_h: &'a [f64],
    /// SG vertical COM acceleration, m/s² (the hidden-flight rule's force).
    pub com_az: &'a [f64],
    /// Horizontal facing direction from the hips (unit, or zero).
    pub facing: &'a [V3],
}

/// What the contact stage finds in a clip's timeline.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactEvents {
    /// Contact runs (sorted by effector, then first frame).
    pub runs: Vec<ContactRun>,
    /// Flights of the no-contact runs not at a clip edge.
    pub flights: Vec<Flight>,
    /// Clip warnings of the physics cross-check.
    pub warnings: Vec<String>,
}

/// Contact runs and flights of a detected timeline; with `opts.support_check`, first the
/// landings of feet with an estimated toe tip ([`landing`]) and the physics cross-check
/// ([`support::cross_check`]: it may add speed-led frames to `timeline`), and a warning for
/// every missed support it could not resolve.
pub fn runs_and_flights(
    tracks: &ContactTracks,
    timeline: &mut ContactTimeline,
    motion: &ClipMotion,
    opts: &ContactOptions,
) -> ContactEvents {
    let mut runs_out = contact_runs::collect(tracks, timeline, motion, opts.static_mode);
    let mut warnings = Vec::new();
    if opts.support_check {
        find_landings(tracks, timeline, motion, opts, &mut runs_out);
        warnings = support::cross_check(tracks, timeline, motion, opts, &mut runs_out);
        // Again for the speed-led runs: a landing the height rule lost entirely.
        find_landings(tracks, timeline, motion, opts, &mut runs_out);
        open_hidden_flights(tracks, timeline, motion, opts, &mut runs_out);
    }
    let flights = flight::flights(&timeline.contact, &runs_out, motion);
    if opts.support_check {
        for f in flights.iter().filter(|f| support::is_missed_support(f)) {
            warnings.push(support::missed_support_warning(
                f,
                "no support found (no foot or hand slow enough where the COM is held up)",
            ));
        }
    }
    ContactEvents {
        runs: runs_out,
        flights,
        warnings,
    }
}

/// The landings of feet with an estimated toe tip ([`landing`]): each found starts its run
/// earlier, and `runs_out` is collected again.
fn find_landings(
    tracks: &ContactTracks,
    timeline: &mut ContactTimeline,
    motion: &ClipMotion,
    opts: &ContactOptions,
    runs_out: &mut Vec<ContactRun>,
) {
    let landings = landing::find(tracks, timeline, motion, runs_out, opts.foot.h_on);
    if !landings.is_empty() {
        landing::apply(timeline, &landings);
        *runs_out = contact_runs::collect(tracks, timeline, motion, opts.static_mode);
    }
}

/// The hidden-flight rule ([`hidden_flight`]): opens the jog flights that the contact rule
/// closed, after every other change to the flags (a flight of two or three frames would
/// otherwise be filled again as a gap shorter than `min_gap_s`).
fn open_hidden_flights(
    tracks: &ContactTracks,
    timeline: &mut ContactTimeline,
    motion: &ClipMotion,
    opts: &ContactOptions,
    runs_out: &mut Vec<ContactRun>,
) {
    if opts.static_mode {
        return;
    }
    let hidden = hidden_flight::find(runs_out, motion);
    if hidden.is_empty() {
        return;
    }
    hidden_flight::open(&mut timeline.contact, &hidden);
    *runs_out = contact_runs::collect(tracks, timeline, motion, opts.static_mode);
    hidden_flight::clamp_events(runs_out, &hidden, motion);
}

/// Support effectors, in output order.
pub const EFFECTORS: [&str; 4] = ["left_foot", "right_foot", "left_hand", "right_hand"];

/// Maximal runs `(first, last)` (inclusive indices) where `flags` is true.
pub fn runs(flags: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &f) in flags.iter().enumerate() {
        match (f, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i - 1));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, flags.len() - 1));
    }
    out
}

/// Unsmoothed 3-D speed by central differences (one-sided at the ends), m/s
/// (spec com-from-bvh §6): `v(k) = |p(k+1) − p(k−1)|·F/2`.
pub fn raw_speed(p: &[[f64; 3]], dt: f64) -> Vec<f64> {
    let n = p.len();
    let d = |a: usize, b: usize| {
        let v: [f64; 3] = std::array::from_fn(|i| p[a][i] - p[b][i]);
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    };
    (0..n)
        .map(|k| match (k, n) {
            (_, 0 | 1) => 0.0,
            (0, _) => d(1, 0) / dt,
            (k, n) if k == n - 1 => d(k, k - 1) / dt,
            (k, _) => d(k + 1, k - 1) / (2.0 * dt),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_and_speeds() {
        assert_eq!(
            runs(&[false, true, true, false, true]),
            vec![(1, 2), (4, 4)]
        );
        assert!(runs(&[]).is_empty());
        let p: Vec<[f64; 3]> = (0..5).map(|i| [i as f64 * 0.1, 0.0, 0.0]).collect();
        assert!(raw_speed(&p, 0.1).iter().all(|v| (v - 1.0).abs() < 1e-12));
    }
}
