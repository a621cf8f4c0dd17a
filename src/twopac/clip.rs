//! Contact phases from a recorded clip (spec two-pac §1, §1.1 `--clip`).
//!
//! # Model
//! ```text
//! events:  a contact run of effector e over frames [a, b] adds e at a and removes it at b + 1
//! order:   by frame; at one frame additions first, then removals (zero-duration phases
//!          between them: the intermediate phase has more support)
//! phase:   the contacts active between two consecutive events; duration = time between
//!          them (0 for a zero-duration phase); data COM at the middle frame (first frame
//!          when zero-duration)
//! span:    the first maximal stretch of continuous support (2PAC has no flight phases)
//! contacts: feet 0.22 × 0.09 m rectangles in their run's contact frame (com-from-bvh §7.5),
//!          hands single points; normal from the run, μ given
//! ```
//!
//! # References
//! spec two-pac §1 (phases, one change per boundary), §1.1; com-from-bvh §7.5.

use super::contact::{Contact, ContactShape};
use super::phases::PhaseSpec;
use super::TwopacError;

/// Default foot support rectangle, m (com-from-bvh §7.5).
pub const FOOT_LENGTH_M: f64 = 0.22;
/// Foot support width, m.
pub const FOOT_WIDTH_M: f64 = 0.09;

/// One recorded contact run, as the phases need it.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedRun {
    /// `left_foot`, `right_foot`, `left_hand` or `right_hand`.
    pub effector: String,
    /// First and last frame in contact (file rows).
    pub frames: (i64, i64),
    /// Contact-frame origin, world m.
    pub origin: [f64; 3],
    /// Contact-frame yaw, rad.
    pub yaw_rad: f64,
    /// Surface normal (unit).
    pub normal: [f64; 3],
}

/// The recorded motion: per kept frame its file row, time (s) and COM (world m).
#[derive(Debug, Clone, Copy)]
pub struct Recording<'a> {
    /// File row of each kept frame, increasing.
    pub frame: &'a [i64],
    /// Clip time, s.
    pub time_s: &'a [f64],
    /// Whole-body COM, m.
    pub com: &'a [[f64; 3]],
}

impl Recording<'_> {
    /// Index of the kept frame at or after file row `k`, clamped to the last.
    fn at(&self, k: i64) -> usize {
        self.frame
            .partition_point(|&f| f < k)
            .min(self.frame.len().saturating_sub(1))
    }
}

/// The contact of a run (feet rectangles, hands points), friction `mu`.
fn contact_of(r: &RecordedRun, mu: f64) -> Result<Contact, TwopacError> {
    let shape = if r.effector.ends_with("_foot") {
        ContactShape::Rectangle {
            length_m: FOOT_LENGTH_M,
            width_m: FOOT_WIDTH_M,
        }
    } else {
        ContactShape::Point
    };
    Contact::new(r.effector.clone(), r.origin, r.normal, mu, r.yaw_rad, shape)
}

/// The contact phases of the first stretch of continuous support, and the clip time of
/// its start (s). Empty when the clip never has a contact.
///
/// # Errors
/// A run whose contact is invalid (zero normal, negative μ).
pub fn phases_from_runs(
    runs: &[RecordedRun],
    rec: Recording,
    mu: f64,
) -> Result<(Vec<PhaseSpec>, f64), TwopacError> {
    if rec.frame.is_empty() {
        return Ok((Vec::new(), 0.0));
    }
    // (frame, 0 = add / 1 = remove, run): additions first at a shared frame.
    let mut events: Vec<(i64, u8, usize)> = runs
        .iter()
        .enumerate()
        .flat_map(|(i, r)| [(r.frames.0, 0, i), (r.frames.1 + 1, 1, i)])
        .collect();
    events.sort_unstable();
    let mut active: Vec<usize> = Vec::new();
    let mut phases = Vec::new();
    let mut start_s = 0.0;
    for (n, &(k, kind, run)) in events.iter().enumerate() {
        if kind == 0 {
            active.push(run);
        } else {
            active.retain(|&r| r != run);
        }
        if active.is_empty() {
            if phases.is_empty() {
                continue;
            }
            break; // a flight (or the end): the stretch of support is over
        }
        let next = events.get(n + 1).map_or(k, |e| e.0);
        let (i0, i1) = (rec.at(k), rec.at(next));
        let mid = if next > k {
            rec.at((k + next - 1) / 2)
        } else {
            i0
        };
        if phases.is_empty() {
            start_s = rec.time_s[i0];
        }
        let contacts = active
            .iter()
            .map(|&r| contact_of(&runs[r], mu))
            .collect::<Result<Vec<_>, _>>()?;
        phases.push(PhaseSpec {
            duration_s: Some((rec.time_s[i1] - rec.time_s[i0]).max(0.0)),
            com: Some(rec.com[mid]),
            contacts,
        });
    }
    Ok((phases, start_s))
}

/// Root-mean-square distance between a planned COM path `(t, c)` (t from the plan's
/// start) and the recording from clip time `start_s`, m; `None` without samples.
pub fn rms_to_recording(planned: &[(f64, [f64; 3])], rec: Recording, start_s: f64) -> Option<f64> {
    if planned.is_empty() || rec.time_s.is_empty() {
        return None;
    }
    let sum: f64 = planned
        .iter()
        .map(|&(t, c)| {
            let i = rec
                .time_s
                .partition_point(|&x| x < start_s + t)
                .min(rec.time_s.len() - 1);
            let d = [
                c[0] - rec.com[i][0],
                c[1] - rec.com[i][1],
                c[2] - rec.com[i][2],
            ];
            d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
        })
        .sum();
    Some((sum / planned.len() as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(e: &str, a: i64, b: i64, x: f64) -> RecordedRun {
        RecordedRun {
            effector: e.into(),
            frames: (a, b),
            origin: [x, 0.0, 0.0],
            yaw_rad: 0.0,
            normal: [0.0, 0.0, 1.0],
        }
    }

    #[test]
    fn phases_change_one_contact_at_a_time_and_stop_at_a_flight() {
        let frame: Vec<i64> = (0..100).collect();
        let time: Vec<f64> = frame.iter().map(|&f| f as f64 * 0.01).collect();
        let com: Vec<[f64; 3]> = frame.iter().map(|&f| [f as f64 * 0.01, 0.0, 0.9]).collect();
        let rec = Recording {
            frame: &frame,
            time_s: &time,
            com: &com,
        };
        // L 0–29, R 20–49 and the hand 30–39 (added at the frame L leaves), flight 50–59,
        // L again 60–99 (after the flight: not planned).
        let runs = [
            run("left_foot", 0, 29, 0.0),
            run("right_foot", 20, 49, 0.3),
            run("left_hand", 30, 39, 0.5),
            run("left_foot", 60, 99, 0.6),
        ];
        let (p, start) = phases_from_runs(&runs, rec, 0.7).unwrap();
        let names: Vec<Vec<&str>> = p
            .iter()
            .map(|ph| ph.contacts.iter().map(|c| c.effector.as_str()).collect())
            .collect();
        assert_eq!(
            names,
            vec![
                vec!["left_foot"],
                vec!["left_foot", "right_foot"],
                vec!["left_foot", "right_foot", "left_hand"], // addition first, 0 s
                vec!["right_foot", "left_hand"],
                vec!["right_foot"],
            ]
        );
        assert_eq!(start, 0.0);
        let d: Vec<f64> = p.iter().map(|ph| ph.duration_s.unwrap()).collect();
        assert!((d[0] - 0.2).abs() < 1e-12 && d[2] == 0.0 && (d[3] - 0.1).abs() < 1e-12);
        // Data COM at the middle frame (frame 24 for 20–29), the first for 0 s phases.
        assert!((p[1].com.unwrap()[0] - 0.24).abs() < 1e-12);
        assert!((p[2].com.unwrap()[0] - 0.30).abs() < 1e-12);
    }

    #[test]
    fn rms_is_zero_on_the_recording_itself() {
        let frame: Vec<i64> = (0..10).collect();
        let time: Vec<f64> = frame.iter().map(|&f| f as f64 * 0.1).collect();
        let com: Vec<[f64; 3]> = frame.iter().map(|&f| [f as f64, 1.0, 0.9]).collect();
        let rec = Recording {
            frame: &frame,
            time_s: &time,
            com: &com,
        };
        let same: Vec<(f64, [f64; 3])> = (2..8).map(|i| (time[i] - 0.2, com[i])).collect();
        assert!(rms_to_recording(&same, rec, 0.2).unwrap() < 1e-12);
        let up: Vec<(f64, [f64; 3])> = same
            .iter()
            .map(|&(t, c)| (t, [c[0], c[1], c[2] + 0.1]))
            .collect();
        assert!((rms_to_recording(&up, rec, 0.2).unwrap() - 0.1).abs() < 1e-12);
        assert_eq!(rms_to_recording(&[], rec, 0.0), None);
    }
}
