//! Where a run's foot goes when the plan's contact point is beyond the body's reach: the
//! least shift of a stance's contact point along its heading that lets its support leg
//! follow the plan within the recorded posture (issue 37 item 5; a departure from the
//! paper).
//!
//! # Model
//! The paper places each contact at `u*`, where the scaled stance keeps its recorded
//! angular impulse about the COM (stance-model §8.3). A run edited far faster than recorded
//! keeps the recorded split of its longer contact between the front and the back of the
//! body, and its push-off can end farther behind the body than the legs reach (CMU `09_01`,
//! 3.6 m/s, asked for 5 m/s: the support ankle 15.5 mm off the floor point with the knee
//! straight, the heel up 50° and the pelvis turned 10°), or its landing farther ahead than
//! the recorded knee allows. People do move the foot: the plate runner recorded at 2 and
//! 3 m/s puts its foot 0.13 m farther ahead of the COM at touchdown and 0.055 m farther
//! behind it at liftoff. A law for that split could not be chosen by leaving runners out
//! (`docs/edited-motion.md`), so the contact moves only where the legs cannot follow the
//! plan, and by the least step that lets them:
//! ```text
//! support frame of source stance i, stance fraction u = (t − t_TD) / (t_LO − t_TD):
//!   miss   not converged (the foot, or the COM, off its goal by more than the tolerance),
//!          or the support knee straighter than the recorded range less the posture
//!          check's tolerance
//!   late   misses with u ≥ ½ (the push-off: the contact must move forward, δ_i > 0)
//!   early  misses with u < ½ (the landing: backward, δ_i < 0)
//! gate     the written edit at u* misses: otherwise it is the paper's, posed once
//! search   on trials (the first two cycles, oversampled): δ_i ← δ_i ± b/8 while stance i
//!          misses on one side only, |δ_i| ≤ b = MAX_CONTACT_SHIFT_LEGS · L_leg; per stance
//!          the trial with the fewest misses is kept (on a tie, the one whose feet come
//!          nearest their goals, then the smaller |δ_i|)
//! check    no search when a stance is infeasible at u*; a stance the move makes
//!          infeasible keeps u* (its search ends there)
//! confirm  the edit posed again with u_h,i ← u*_h,i + δ_i is kept if no moved stance
//!          misses more than at u* and all together miss less (a stance that misses more
//!          goes back to u* and the rest are posed again); the pitch angular impulse
//!          changes by ΔH_p = −δ_i · I_v
//! ```
//! The COM path, the forces and the times stay the plan's; the force checks are repeated
//! at the moved contact. A stance that misses on both sides keeps `u*` and its frames are
//! reported as before.
//!
//! # Frames and units
//! Metres along the stance's heading; `I_v` the stance's vertical impulse (N·s).

use super::fidelity::{check, FidelityOptions, Gauge};
use super::path::{ComPath, Phase};
use super::plan::{feet_of, place, EditStance, PlanKind};
use super::pose::{pose_motion, EditedMotion, FramePose, Reference, StanceSource};
use super::EditOptions;
use crate::query::run::check_at_contact;

/// Largest contact shift, in leg lengths: a tenth of a leg (8.6 cm for CMU subject 09) is
/// about the spread of one runner's touchdown distance between its strides at one speed
/// (± 10 % of a 0.3–0.5 m distance ahead of the COM, `docs/edited-motion.md`).
pub const MAX_CONTACT_SHIFT_LEGS: f64 = 0.1;

/// The support frames of one source stance that miss the plan, by side of mid-stance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Misses {
    /// Before mid-stance (landing).
    pub early: usize,
    /// From mid-stance on (push-off).
    pub late: usize,
    /// Largest distance of a missing frame's support foot from its goal, m.
    pub off_m: f64,
}

impl Misses {
    /// Both sides.
    pub fn total(self) -> usize {
        self.early + self.late
    }

    /// Whether `self` misses less than `other`: fewer frames, or as many with the foot
    /// nearer its goal.
    pub fn better_than(self, other: Misses) -> bool {
        (self.total(), self.off_m) < (other.total(), other.off_m)
    }

    /// The direction the contact should move: +1 (forward) when only the push-off misses,
    /// −1 when only the landing does, 0 otherwise.
    pub fn direction(self) -> f64 {
        match (self.early, self.late) {
            (0, l) if l > 0 => 1.0,
            (e, 0) if e > 0 => -1.0,
            _ => 0.0,
        }
    }
}

/// The misses of every source stance (`n` of them) in a posed plan: `frames` and `gauges`
/// (the written frames' knees) of `path`, `feet[i]` the legs of source stance `i` in
/// contact (left, right), `knee_floor_deg` the least knee flexion the posture check accepts
/// (`-∞`: none).
pub fn misses(
    frames: &[FramePose],
    gauges: &[Gauge],
    path: &ComPath,
    feet: &[[bool; 2]],
    knee_floor_deg: f64,
) -> Vec<Misses> {
    let mut out = vec![Misses::default(); feet.len()];
    for (f, g) in frames.iter().zip(gauges) {
        let (Phase::Stance(k), Some((td, lo))) = (f.phase, f.window) else {
            continue;
        };
        let Some(i) = path.stances.get(k).map(|s| s.source) else {
            continue;
        };
        let Some(legs) = feet.get(i) else {
            continue;
        };
        let straight = (0..2).any(|s| legs[s] && g.knee_deg[s] < knee_floor_deg);
        if f.converged && !straight {
            continue;
        }
        let u = if lo > td {
            (f.time_s - td) / (lo - td)
        } else {
            0.5
        };
        if !f.converged {
            out[i].off_m = out[i].off_m.max(f.foot_error_m);
        }
        if u < 0.5 {
            out[i].early += 1;
        } else {
            out[i].late += 1;
        }
    }
    out
}

/// The outcome of the search.
#[derive(Debug, Clone, PartialEq)]
pub struct Footing {
    /// Contact shift of every source stance along its heading, m (forward +).
    pub shift_m: Vec<f64>,
    /// Misses with the plan's contacts.
    pub before: Vec<Misses>,
    /// Misses with the shifted contacts ([`fit_shifts`]: in the trial that chose each
    /// stance's shift; [`pose_reaching`]: in the edit written).
    pub after: Vec<Misses>,
    /// Time one miss of each stance stands for, s: the frame time over the times the
    /// stance plays (so `misses × miss_s` is the time of one play of the stance off the
    /// plan).
    pub miss_s: Vec<f64>,
}

impl Footing {
    /// No shift (the plan's contacts), for `n` source stances.
    pub fn none(n: usize) -> Footing {
        Footing {
            shift_m: vec![0.0; n],
            before: vec![Misses::default(); n],
            after: vec![Misses::default(); n],
            miss_s: vec![0.0; n],
        }
    }

    /// Whether any contact moved.
    pub fn moved(&self) -> bool {
        self.shift_m.iter().any(|&d| d != 0.0)
    }
}

/// The least contact shifts (module docs) of `n` source stances, in steps of `step_m`, each
/// at most `cap_m`: `trial(shifts)` poses the plan with the contacts moved by `shifts` and
/// returns its [`misses`]. A stance whose search ends (it reaches, or its other side starts
/// to miss) goes back to its best shift for the trials after. Calls `trial` at most
/// `1 + ⌊cap_m / step_m⌋` times. Returns the shifts, the misses of the first trial and, per
/// stance, of the trial that chose its shift.
pub fn fit_shifts(
    n: usize,
    cap_m: f64,
    step_m: f64,
    mut trial: impl FnMut(&[f64]) -> Vec<Misses>,
) -> Footing {
    let mut shift = vec![0.0; n];
    let before = trial(&shift);
    let dir: Vec<f64> = (0..n)
        .map(|i| before.get(i).map_or(0.0, |m| m.direction()))
        .collect();
    let mut best: Vec<(f64, Misses)> = (0..n)
        .map(|i| (0.0, before.get(i).copied().unwrap_or_default()))
        .collect();
    let mut active: Vec<bool> = dir.iter().map(|&d| d != 0.0).collect();
    let steps = if step_m > 0.0 {
        (cap_m.max(0.0) / step_m + 1e-9).floor() as usize
    } else {
        0
    };
    for step in 1..=steps {
        if !active.iter().any(|&a| a) {
            break;
        }
        for i in (0..n).filter(|&i| active[i]) {
            shift[i] = dir[i] * step as f64 * step_m;
        }
        let got = trial(&shift);
        for i in 0..n {
            if !active[i] {
                continue;
            }
            let Some(&m) = got.get(i) else {
                active[i] = false;
                shift[i] = best[i].0;
                continue;
            };
            if m.better_than(best[i].1) {
                best[i] = (shift[i], m);
            }
            // Done when it reaches, or when the other side starts to miss.
            if m.total() == 0 || m.direction() != dir[i] {
                active[i] = false;
                shift[i] = best[i].0;
            }
        }
    }
    Footing {
        shift_m: best.iter().map(|b| b.0).collect(),
        before,
        after: best.iter().map(|b| b.1).collect(),
        miss_s: vec![0.0; n],
    }
}

/// Stances a trial poses: the first two cycles of a run are enough to see every
/// stance after a flight on each side (a cycle repeats).
pub const TRIAL_STANCES: usize = 4;
/// How many times the output rate a trial poses at (at most; fewer where that would pose
/// more frame-joints than [`crate::edit::MAX_EDIT_FRAME_JOINTS`]): a later cycle's frames
/// fall at other times of a stance than the first two cycles' (the fixture run at 7 m/s
/// kept its knee in range in cycles 1–2 and straightened 0.6° beyond it one frame after a
/// touchdown of cycle 3), so the trials see the stances at the times any cycle's frames
/// may fall.
pub const TRIAL_OVERSAMPLING: f64 = 4.0;
/// Steps of the search up to its bound ([`MAX_CONTACT_SHIFT_LEGS`]): eighths of a tenth of
/// a leg, 1.1 cm for CMU subject 09 (the step scales with the character, so the number of
/// trials does not).
pub const CONTACT_SHIFT_STEPS: usize = 8;

/// A run plan placed and posed: its path, sources, posed motion and the contacts it moved.
pub type Posed = (ComPath, Vec<StanceSource>, EditedMotion, Footing);

/// Places and poses a run's solved `stances` in `order` (`opts`, `frame_time_s`) at the
/// paper's contact points, and, where the written frames' support legs do not follow the
/// plan (their [`misses`], judged as the posture check `fidelity` judges knees), searches
/// contact shifts on trials ([`fit_shifts`]: the first [`TRIAL_STANCES`] at up to
/// [`TRIAL_OVERSAMPLING`] × the output rate), drops the shift of a stance whose forces the
/// moved contact makes infeasible ([`check_at_contact`]), poses the edit again and keeps
/// the moved contacts only if its frames miss less. An edit whose frames follow the plan is
/// posed once and is the paper's.
pub fn pose_reaching(
    stances: &mut Vec<EditStance>,
    order: &[usize],
    reference: &Reference,
    opts: &EditOptions,
    fidelity: FidelityOptions,
    frame_time_s: f64,
) -> Posed {
    let n = stances.len();
    let feet: Vec<[bool; 2]> = stances.iter().map(|e| feet_of(&e.source.label)).collect();
    let pose = |st: &[EditStance], order: &[usize], dt: f64| {
        let (path, sources) = place(st, order, reference, PlanKind::Run);
        let posed = pose_motion(reference, &path, &sources, opts, dt);
        let m = judged(reference, &path, &posed, fidelity, &feet);
        (path, sources, posed, m)
    };
    let (path, sources, edited, before) = pose(stances, order, frame_time_s);
    let mut footing = Footing::none(n);
    footing.miss_s = (0..n)
        .map(|i| frame_time_s / order.iter().filter(|&&k| k == i).count().max(1) as f64)
        .collect();
    footing.before.clone_from(&before);
    footing.after.clone_from(&before);
    // Nothing to move where the frames follow the plan; nor where a stance is infeasible
    // at the paper's contact (the request is refused, or written as infeasible, as it is).
    let infeasible = stances.iter().any(|e| e.scaled.verdict.violated.is_some());
    if infeasible || before.iter().all(|m| m.total() == 0) {
        return (path, sources, edited, footing);
    }
    let trial_order = &order[..order.len().min(TRIAL_STANCES)];
    let (trial_path, _) = place(stances, trial_order, reference, PlanKind::Run);
    let joints = reference.body.skeleton.parents.len().max(1) as f64;
    let room = crate::edit::MAX_EDIT_FRAME_JOINTS as f64
        / (crate::edit::pose::frame_count_f64(&trial_path, frame_time_s) * joints);
    let dt = frame_time_s / room.clamp(1.0, TRIAL_OVERSAMPLING);
    let cap = MAX_CONTACT_SHIFT_LEGS * reference.body.leg_m;
    let searched = fit_shifts(n, cap, cap / CONTACT_SHIFT_STEPS as f64, |shift| {
        let (st, kept) = moved(stances, shift);
        let mut m = pose(&st, trial_order, dt).3;
        // A shift the forces do not allow ends that stance's search (it misses both ways).
        for (i, m) in m.iter_mut().enumerate() {
            if shift[i] != 0.0 && kept[i] == 0.0 {
                *m = Misses {
                    early: usize::MAX / 4,
                    late: usize::MAX / 4,
                    off_m: f64::INFINITY,
                };
            }
        }
        m
    });
    let mut shift = searched.shift_m;
    // Confirmed on the edit itself: every moved stance misses no more than at the paper's
    // contact, and all of them together less; a stance that misses more goes back.
    for _ in 0..n {
        let (moved_stances, kept) = moved(stances, &shift);
        if kept.iter().all(|&d| d == 0.0) {
            break;
        }
        let (p1, s1, e1, after) = pose(&moved_stances, order, frame_time_s);
        let worse: Vec<usize> = (0..n)
            .filter(|&i| kept[i] != 0.0 && before[i].better_than(after[i]))
            .collect();
        if worse.is_empty() {
            if !total(&after).better_than(total(&before)) {
                break;
            }
            *stances = moved_stances;
            footing.shift_m = kept;
            footing.after = after;
            return (p1, s1, e1, footing);
        }
        for i in worse {
            shift[i] = 0.0;
        }
    }
    (path, sources, edited, footing)
}

/// `stances` with each contact moved `shift[i]` along its heading and its forces checked
/// there, and the shifts kept: a stance the move makes infeasible (feasible at `u*`) keeps
/// its contact.
fn moved(stances: &[EditStance], shift: &[f64]) -> (Vec<EditStance>, Vec<f64>) {
    stances
        .iter()
        .zip(shift)
        .map(|(e, &d)| {
            if d == 0.0 {
                return (e.clone(), 0.0);
            }
            let cp = [e.scaled.cp[0] + d, e.scaled.cp[1]];
            let scaled =
                check_at_contact(&e.prepared, &e.request, &e.scaled.solution, &e.limits, cp);
            if scaled.verdict.violated.is_some() && e.scaled.verdict.violated.is_none() {
                return (e.clone(), 0.0);
            }
            let mut e = e.clone();
            e.scaled = scaled;
            (e, d)
        })
        .unzip()
}

/// The misses of a posed plan ([`misses`]), its knees judged as `fidelity` judges them.
fn judged(
    reference: &Reference,
    path: &ComPath,
    posed: &EditedMotion,
    fidelity: FidelityOptions,
    feet: &[[bool; 2]],
) -> Vec<Misses> {
    let fid = check(
        &reference.body,
        &reference.motion,
        &posed.motion,
        &posed.frames,
        fidelity,
    );
    let floor = if fidelity.knee_extension {
        fid.knee_recorded_deg[0] - fidelity.knee_tol_deg
    } else {
        f64::NEG_INFINITY
    };
    misses(&posed.frames, &fid.frames, path, feet, floor)
}

/// The misses of every stance summed (the largest foot error of any).
fn total(m: &[Misses]) -> Misses {
    m.iter().fold(Misses::default(), |a, b| Misses {
        early: a.early + b.early,
        late: a.late + b.late,
        off_m: a.off_m.max(b.off_m),
    })
}

/// The change of a stance's angular impulse about the COM, pitch component (about the
/// stance's `p` axis, N·m·s), when its contact moves `d` metres along its heading:
/// `H = x_cp × I − H_0` (stance-model §8.2, `x_cp = (cp_h, cp_p, −z_TD)`), so
/// `ΔH_p = −d · I_v`, `I_v = β_v Δt F1_v(1)` its vertical impulse (N·s).
pub fn impulse_change(e: &EditStance, d: f64) -> f64 {
    let m = &e.prepared.stance.model;
    pitch_change(d, e.scaled.solution.beta[2] * m.dt_s * m.axes[2].f1(1.0))
}

/// `ΔH_p` of a contact moved `d` along the heading under a vertical impulse `i_v`:
/// the `p` component of `(d, 0, 0) × (I_h, I_p, I_v)`.
fn pitch_change(d: f64, i_v: f64) -> f64 {
    -d * i_v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A toy leg: stance `i` misses `late` frames while its push-off is `need_i` metres
    /// short, one frame per centimetre, and `early` frames once shifted past `room_i`.
    fn toy(need: Vec<f64>, room: Vec<f64>) -> impl FnMut(&[f64]) -> Vec<Misses> {
        move |s: &[f64]| {
            s.iter()
                .enumerate()
                .map(|(i, &d)| Misses {
                    late: ((need[i] - d) / 0.01).ceil().max(0.0) as usize,
                    early: ((d - room[i]) / 0.01).ceil().max(0.0) as usize,
                    ..Misses::default()
                })
                .collect()
        }
    }

    #[test]
    fn the_least_step_that_reaches_is_kept_and_a_reaching_stance_stays() {
        let f = fit_shifts(2, 0.1, 0.01, toy(vec![0.025, 0.0], vec![1.0, 1.0]));
        assert!((f.shift_m[0] - 0.03).abs() < 1e-12, "{:?}", f.shift_m);
        assert_eq!(f.shift_m[1], 0.0);
        assert_eq!(f.before[0].late, 3);
        assert_eq!(f.after[0], Misses::default());
        assert!(f.moved());
    }

    #[test]
    fn the_shift_stops_at_the_cap_and_where_the_landing_starts_to_miss() {
        // Short by 20.5 cm, capped at 5 cm: the fewest misses within the cap.
        let f = fit_shifts(1, 0.05, 0.01, toy(vec![0.205], vec![1.0]));
        assert!((f.shift_m[0] - 0.05).abs() < 1e-12);
        assert_eq!(f.after[0].late, 16);
        // Short by 4 cm with 2 cm of room at the landing: 2 cm, no further.
        let f = fit_shifts(1, 0.1, 0.01, toy(vec![0.04], vec![0.02]));
        assert!((f.shift_m[0] - 0.02).abs() < 1e-12, "{:?}", f.shift_m);
        assert_eq!((f.after[0].early, f.after[0].late), (0, 2));
    }

    #[test]
    fn as_many_misses_nearer_the_goal_is_better() {
        // One frame misses from 7 cm on, its foot 6 mm nearer its goal per centimetre: the
        // nearest within the cap (8 cm), not the first with one miss.
        let f = fit_shifts(1, 0.085, 0.01, |s: &[f64]| {
            vec![Misses {
                early: 0,
                late: if s[0] < 0.065 { 3 } else { 1 },
                off_m: (0.05 - 0.6 * s[0]).max(0.001),
            }]
        });
        assert!((f.shift_m[0] - 0.08).abs() < 1e-12, "{:?}", f.shift_m);
    }

    #[test]
    fn a_stance_whose_search_ended_goes_back_to_its_best_shift_for_the_later_trials() {
        // Stance 0 misses one push-off frame, nearest its goal at 2 cm, and its landing
        // misses from 3 cm on (where its search ends); stance 1 needs 6 cm, but only while
        // stance 0 is at its best shift (the two are coupled).
        let mut tried: Vec<Vec<f64>> = Vec::new();
        let f = fit_shifts(2, 0.1, 0.01, |s: &[f64]| {
            tried.push(s.to_vec());
            let near = |a: f64, b: f64| (a - b).abs() < 1e-9;
            let over = s[0] > 0.025;
            let late1 = if s[1] > 0.055 && near(s[0], 0.02) {
                0
            } else {
                1
            };
            vec![
                Misses {
                    early: usize::from(over),
                    late: usize::from(!over),
                    off_m: if over { 0.05 } else { 0.03 - s[0] },
                },
                Misses {
                    early: 0,
                    late: late1,
                    off_m: 0.06 - s[1].min(0.06),
                },
            ]
        });
        assert!((f.shift_m[0] - 0.02).abs() < 1e-12, "{:?}", f.shift_m);
        assert!(
            (f.shift_m[1] - 0.06).abs() < 1e-12,
            "{:?} after {tried:?}",
            f.shift_m
        );
        assert_eq!(f.after[1].late, 0, "{tried:?}");
    }

    #[test]
    fn a_contact_moved_forward_turns_the_body_back_about_its_pitch_axis() {
        // Independently: ΔH = Δx_cp × I with Δx_cp = (d, 0, 0) and I = (I_h, I_p, I_v);
        // its p component.
        let (d, i) = (0.03, [40.0, -3.0, 240.0]);
        let dh = crate::math::v3::cross([d, 0.0, 0.0], i);
        assert!((pitch_change(d, i[2]) - dh[1]).abs() < 1e-12, "{dh:?}");
        assert!(pitch_change(d, i[2]) < 0.0);
    }

    #[test]
    fn a_landing_miss_moves_the_contact_back_and_both_sides_keep_it() {
        // Misses at the landing only while the contact is more than 1.5 cm ahead.
        let landing = |s: &[f64]| {
            vec![Misses {
                early: ((0.015 + s[0]) / 0.01).ceil().max(0.0) as usize,
                ..Misses::default()
            }]
        };
        let f = fit_shifts(1, 0.1, 0.01, landing);
        assert!((f.shift_m[0] + 0.02).abs() < 1e-12, "{:?}", f.shift_m);
        let both = |_: &[f64]| {
            vec![Misses {
                early: 2,
                late: 3,
                off_m: 0.01,
            }]
        };
        let f = fit_shifts(1, 0.1, 0.01, both);
        assert!(!f.moved());
        assert_eq!(f.after, f.before);
    }
}
