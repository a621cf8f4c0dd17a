//! Segmenting a clip into stances (spec stance-model §1).
//!
//! # Model
//! ```text
//! s_k = OR of the support effectors' contact flags
//! support run = maximal run of s_k; gap = maximal run of ¬s_k
//!   gap touching a clip edge → clip_edge; ballistic gap (com-from-bvh §7.7) → flight;
//!   any other gap → unsupported
//! quiet period: |ċ_SG| < 0.15 m/s for ≥ 0.3 s inside a support run; the part before ends at
//!   its first frame, the part after starts at its last frame (kind rest)
//! settled end: a shorter quiet stretch that reaches the clip's end cuts the run the same
//!   way (kind clip_edge, rest_at_edge; a departure, see `settled_end`)
//! walking split: ≥ 2 single-support phases (≥ 0.1 s) of alternating feet; between two of
//!   them, over the double-support frames a..b, the first stance ends at ⌊(a+b)/2⌋ and the
//!   second starts one frame later (kind no_flight); each is labelled by its single-support foot
//! stances with fewer than 3 frames are dropped (a warning)
//! ```
//! Indices here are kept-frame indices (0 = first kept frame).
//!
//! # References
//! spec stance-model §1 (revision 2: boundary kinds, walking split, quiet split).

use crate::contacts::runs;

/// Quiet-period speed threshold `v_quiet`, m/s.
pub const V_QUIET: f64 = 0.15;
/// Minimum quiet-period length `T_quiet`, s.
pub const T_QUIET_S: f64 = 0.3;
/// Minimum single-support phase for a walking split `T_single`, s.
pub const T_SINGLE_S: f64 = 0.1;
/// Minimum stance length, frames.
pub const MIN_STANCE_FRAMES: usize = 3;
/// Tolerance on durations measured in whole frames, s: frame times are printed rounded
/// (12 × 0.008333 s = 0.099996 s is 0.1 s), as for airborne intervals (com-from-bvh §7.7).
const DURATION_TOL_S: f64 = 1e-4;

/// What lies at one end of a stance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// A ballistic flight.
    Flight,
    /// A walking split (double support continues).
    NoFlight,
    /// A quiet period.
    Rest,
    /// The clip starts or ends here (in contact or in the air).
    ClipEdge,
    /// A gap that is not ballistic (hanging, sitting, a glitch).
    Unsupported,
}

impl Boundary {
    /// Name used in `stances.parquet`.
    pub fn as_str(self) -> &'static str {
        match self {
            Boundary::Flight => "flight",
            Boundary::NoFlight => "no_flight",
            Boundary::Rest => "rest",
            Boundary::ClipEdge => "clip_edge",
            Boundary::Unsupported => "unsupported",
        }
    }

    /// The kind named `s` in `stances.parquet` (inverse of [`Boundary::as_str`]).
    pub fn parse(s: &str) -> Option<Self> {
        [
            Boundary::Flight,
            Boundary::NoFlight,
            Boundary::Rest,
            Boundary::ClipEdge,
            Boundary::Unsupported,
        ]
        .into_iter()
        .find(|b| b.as_str() == s)
    }
}

/// One stance's frames and boundary kinds.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// First kept-frame index.
    pub i0: usize,
    /// Last kept-frame index.
    pub i1: usize,
    /// What precedes it.
    pub start: Boundary,
    /// What follows it.
    pub end: Boundary,
    /// `Some(0)` left or `Some(1)` right for a walking stance, labelled by its foot.
    pub walking_foot: Option<usize>,
}

/// Inputs of the segmentation, per kept frame.
#[derive(Clone, Copy)]
pub struct SegmentInput<'a> {
    /// Contact flags per effector (left foot, right foot, left hand, right hand).
    pub contact: &'a [Vec<bool>; 4],
    /// SG COM speed, m/s.
    pub speed: &'a [f64],
    /// Whether each no-contact run `(a, b)` not at a clip edge is a flight.
    pub ballistic: &'a dyn Fn(usize, usize) -> bool,
    /// Frame time, s.
    pub dt: f64,
}

/// Segment a clip; the second value lists dropped short stances as warnings.
pub fn segment(inp: &SegmentInput) -> (Vec<Segment>, Vec<String>) {
    let n = inp.speed.len();
    let support: Vec<bool> = (0..n).map(|k| inp.contact.iter().any(|c| c[k])).collect();
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    let gap_kind = |a: usize, b: usize| {
        if a == 0 || b + 1 >= n {
            Boundary::ClipEdge
        } else if (inp.ballistic)(a, b) {
            Boundary::Flight
        } else {
            Boundary::Unsupported
        }
    };
    for (a, b) in runs(&support) {
        let start = if a == 0 {
            Boundary::ClipEdge
        } else {
            gap_kind(prev_gap_start(&support, a), a - 1)
        };
        let end = if b + 1 >= n {
            Boundary::ClipEdge
        } else {
            gap_kind(b + 1, next_gap_end(&support, b))
        };
        let b = settled_end(inp, a, b, b + 1 == n);
        for part in quiet_split(inp, a, b, start, end) {
            for s in walking_split(inp, part) {
                if s.i1 + 1 - s.i0 < MIN_STANCE_FRAMES {
                    warnings.push(format!(
                        "stance of {} frames at frame {} dropped (fewer than 3)",
                        s.i1 + 1 - s.i0,
                        s.i0
                    ));
                } else {
                    out.push(s);
                }
            }
        }
    }
    (out, warnings)
}

fn prev_gap_start(support: &[bool], a: usize) -> usize {
    (0..a)
        .rev()
        .take_while(|&k| !support[k])
        .last()
        .unwrap_or(a - 1)
}

fn next_gap_end(support: &[bool], b: usize) -> usize {
    (b + 1..support.len())
        .take_while(|&k| !support[k])
        .last()
        .unwrap_or(b + 1)
}

/// The last frame of a support run `a..=b` that reaches the clip's last frame (`at_end`) in
/// a quiet stretch shorter than `T_quiet`: the stretch's first frame, where a quiet split
/// would end it; the boundary stays `clip_edge` (with `rest_at_edge`). Any other run keeps
/// `b` (one followed by a gap, even a gap that reaches the clip's end: the body left the
/// floor after it, the capture did not stop on it).
///
/// A departure from the spec, which splits only at quiet stretches of at least `T_quiet`:
/// how long the capture ran on after the body settled is the operator's choice, not the
/// motion's. The landing of `cmu_13_32_forward_jump_daz` settles 35 frames (1 short of
/// 0.3 s at 120 Hz) before its clip ends; kept whole, its slow drift added 2.1 cm to the
/// recorded jump's distance, and an edit of it that settled one frame longer lost those
/// 2.1 cm when rebuilt. A longer stretch is left to [`quiet_split`] (a `rest` boundary).
///
/// The clip's start keeps the spec's rule: cut there too, the vertical jump
/// `cmu_02_04_vertical_jump_mb` started its liftoff at frame 26 instead of 1, its start
/// drift `vps` fell from 0.10 to 0.01 m/s, and the sideways push that replaced it is the
/// force the jump query drops (`β_p = 0`), so its recorded-jump edit flew 9 cm/s off the
/// recording. An edit writes its recording's lead-in (`edit::LEAD_IN_S`), so a rebuilt
/// liftoff starts as its source did.
fn settled_end(inp: &SegmentInput, a: usize, b: usize, at_end: bool) -> usize {
    let quiet = |k: usize| inp.speed[k] < V_QUIET;
    if !at_end || !quiet(b) {
        return b;
    }
    let mut first = b;
    while first > a && quiet(first - 1) {
        first -= 1;
    }
    let short = ((b - first + 1) as f64) * inp.dt < T_QUIET_S - DURATION_TOL_S;
    if short {
        first
    } else {
        b
    }
}

/// Split a support run at its quiet periods.
fn quiet_split(
    inp: &SegmentInput,
    a: usize,
    b: usize,
    start: Boundary,
    end: Boundary,
) -> Vec<Segment> {
    let quiet: Vec<bool> = inp.speed[a..=b].iter().map(|v| *v < V_QUIET).collect();
    let mut parts = Vec::new();
    let (mut cur, mut cur_start) = (a, start);
    for (qa, qb) in runs(&quiet) {
        let (qa, qb) = (a + qa, a + qb);
        if ((qb - qa + 1) as f64) * inp.dt < T_QUIET_S - DURATION_TOL_S {
            continue;
        }
        if qa >= cur {
            parts.push(Segment {
                i0: cur,
                i1: qa,
                start: cur_start,
                end: Boundary::Rest,
                walking_foot: None,
            });
        }
        cur = qb;
        cur_start = Boundary::Rest;
    }
    parts.push(Segment {
        i0: cur,
        i1: b,
        start: cur_start,
        end,
        walking_foot: None,
    });
    parts
}

/// Split a support part between alternating single-support phases of ≥ `T_single`.
fn walking_split(inp: &SegmentInput, part: Segment) -> Vec<Segment> {
    let (l, r) = (&inp.contact[0], &inp.contact[1]);
    let single: Vec<Option<usize>> = (part.i0..=part.i1)
        .map(|k| match (l[k], r[k]) {
            (true, false) => Some(0),
            (false, true) => Some(1),
            _ => None,
        })
        .collect();
    // Single-support phases (foot, first, last) of at least T_single.
    let mut phases: Vec<(usize, usize, usize)> = Vec::new();
    for foot in 0..2 {
        let flags: Vec<bool> = single.iter().map(|s| *s == Some(foot)).collect();
        for (a, b) in runs(&flags) {
            if ((b - a + 1) as f64) * inp.dt >= T_SINGLE_S - DURATION_TOL_S {
                phases.push((foot, part.i0 + a, part.i0 + b));
            }
        }
    }
    phases.sort_by_key(|p| p.1);
    let alternating = phases.windows(2).any(|w| w[0].0 != w[1].0);
    if phases.len() < 2 || !alternating {
        return vec![part];
    }
    let mut out = Vec::new();
    let mut cur = Segment {
        walking_foot: Some(phases[0].0),
        ..part.clone()
    };
    for w in phases.windows(2) {
        if w[0].0 == w[1].0 {
            continue;
        }
        let (a, b) = (w[0].2 + 1, w[1].1.saturating_sub(1));
        let m = if a <= b { (a + b) / 2 } else { w[0].2 };
        out.push(Segment {
            i1: m,
            end: Boundary::NoFlight,
            ..cur.clone()
        });
        cur = Segment {
            i0: m + 1,
            start: Boundary::NoFlight,
            walking_foot: Some(w[1].0),
            ..part.clone()
        };
    }
    out.push(cur);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flags(s: &str) -> Vec<bool> {
        s.chars().map(|c| c == '1').collect()
    }

    fn run(l: &str, r: &str, speed: f64, dt: f64, ballistic: bool) -> Vec<Segment> {
        let contact = [
            flags(l),
            flags(r),
            vec![false; l.len()],
            vec![false; l.len()],
        ];
        let speed = vec![speed; l.len()];
        let b = move |_: usize, _: usize| ballistic;
        segment(&SegmentInput {
            contact: &contact,
            speed: &speed,
            ballistic: &b,
            dt,
        })
        .0
    }

    #[test]
    fn running_stances_are_bounded_by_flights_and_clip_edges() {
        let s = run(
            "1111000000000000111100",
            "0000000111100000000000",
            3.0,
            0.01,
            true,
        );
        let k: Vec<_> = s.iter().map(|s| (s.i0, s.i1, s.start, s.end)).collect();
        use Boundary::*;
        assert_eq!(
            k,
            vec![
                (0, 3, ClipEdge, Flight),
                (7, 10, Flight, Flight),
                (16, 19, Flight, ClipEdge)
            ]
        );
        let s = run(
            "1111000000000000111100",
            "0000000111100000000000",
            3.0,
            0.01,
            false,
        );
        assert_eq!(s[1].start, Unsupported);
    }

    #[test]
    fn walking_splits_in_the_middle_of_double_support() {
        // L single 0..=11, double 12..=15, R single 16..=27 at 100 Hz (0.12 s each).
        let l = format!("{}{}", "1".repeat(16), "0".repeat(12));
        let r = format!("{}{}", "0".repeat(12), "1".repeat(16));
        let s = run(&l, &r, 1.0, 0.01, true);
        assert_eq!(s.len(), 2);
        assert_eq!(
            (s[0].i0, s[0].i1, s[0].walking_foot, s[0].end),
            (0, 13, Some(0), Boundary::NoFlight)
        );
        assert_eq!(
            (s[1].i0, s[1].i1, s[1].walking_foot, s[1].start),
            (14, 27, Some(1), Boundary::NoFlight)
        );
    }

    #[test]
    fn a_two_footed_landing_with_short_single_support_stays_one_stance() {
        let l = format!("{}{}", "1".repeat(20), "0".repeat(5));
        let r = format!("00{}{}", "1".repeat(21), "00");
        let s = run(&l, &r, 1.0, 0.01, true);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].walking_foot, None);
    }

    #[test]
    fn quiet_periods_split_support_into_landing_and_liftoff() {
        // 100 frames in contact, quiet (slow) from 30 to 69 (0.4 s at 100 Hz).
        let contact = [
            vec![true; 100],
            vec![true; 100],
            vec![false; 100],
            vec![false; 100],
        ];
        let speed: Vec<f64> = (0..100)
            .map(|k| if (30..70).contains(&k) { 0.05 } else { 1.0 })
            .collect();
        let b = |_: usize, _: usize| true;
        let (s, _) = segment(&SegmentInput {
            contact: &contact,
            speed: &speed,
            ballistic: &b,
            dt: 0.01,
        });
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].i0, s[0].i1, s[0].end), (0, 30, Boundary::Rest));
        assert_eq!((s[1].i0, s[1].i1, s[1].start), (69, 99, Boundary::Rest));
    }

    /// 100 frames at 100 Hz, in support over `0..support_end` (in the air after it), slow
    /// over `slow`.
    fn with_slow_until(slow: std::ops::Range<usize>, support_end: usize) -> Vec<Segment> {
        let feet: Vec<bool> = (0..100).map(|k| k < support_end).collect();
        let contact = [feet.clone(), feet, vec![false; 100], vec![false; 100]];
        let speed: Vec<f64> = (0..100)
            .map(|k| if slow.contains(&k) { 0.05 } else { 1.0 })
            .collect();
        let b = |_: usize, _: usize| true;
        segment(&SegmentInput {
            contact: &contact,
            speed: &speed,
            ballistic: &b,
            dt: 0.01,
        })
        .0
    }

    /// One support run over the whole 100 frames, slow over `slow`.
    fn with_slow(slow: std::ops::Range<usize>) -> Vec<Segment> {
        with_slow_until(slow, 100)
    }

    #[test]
    fn a_short_quiet_stretch_at_the_clip_end_cuts_the_stance_as_a_rest_would() {
        // 0.29 s still before the clip ends: the stance ends at the stretch's first frame,
        // as a rest split ends it, and the boundary stays clip_edge.
        let s = with_slow(71..100);
        assert_eq!(s.len(), 1);
        assert_eq!((s[0].i0, s[0].i1, s[0].end), (0, 71, Boundary::ClipEdge));
        // 0.31 s: the quiet split of the spec (a rest; the 1-frame remainder is dropped).
        let s = with_slow(69..100);
        assert_eq!((s[0].i1, s[0].end), (69, Boundary::Rest));
        // At the clip's start the spec's rule holds: a short stretch stays in the stance.
        let s = with_slow(0..20);
        assert_eq!((s[0].i0, s[0].i1, s[0].start), (0, 99, Boundary::ClipEdge));
        // A short stretch inside the clip does not split it, nor does one frame at an edge.
        let s = with_slow(40..69);
        assert_eq!((s.len(), s[0].i0, s[0].i1), (1, 0, 99));
        let s = with_slow(99..100);
        assert_eq!((s.len(), s[0].i0, s[0].i1), (1, 0, 99));
        // A run followed by a gap that reaches the clip's end: the body left the floor, the
        // capture did not stop on the quiet stretch; the run stays whole.
        let s = with_slow_until(71..90, 90);
        assert_eq!((s.len(), s[0].i1, s[0].end), (1, 89, Boundary::ClipEdge));
    }
}
