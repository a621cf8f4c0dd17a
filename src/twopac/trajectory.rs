//! Phase states, transition points and the sliding-window 2PAC trajectory with its time
//! parametrisation (two-pac §1, §4, §5.4, §6), plus the quasi-static polyline baseline.
//!
//! # Model
//!
//! ```text
//! c^(j)      = QP of §4 with statics = kinematics = phase j, c_prev = data COM (or c^(j−1))
//! c^(j,j+1)  = QP of §4: statics of the phase with fewer contacts, kinematics of the one
//!              with more, c_prev = c^(j−1,j) (or c^(1) for the first)
//! window     = phases j..j+2 (2 attractors, degree 7) if j→j+1 removes and j+1→j+2 adds a
//!              contact, else j..j+1 (1 attractor, degree 6); end state (c^(J), 0, 0)
//! T_w        = mid(J) − t_cur on the data clock;  without durations max(0.5 s, L_poly/0.3 m/s)
//! switch u   = first u = u_min + 0.01 k < 1 with c(u) ∈ K^(J) (1e-9 m) and |c'(u)| > 1e-6,
//!              u_min = (start(J) − t_cur)/T_w (without durations: closest approach of c to
//!              c^(J−1,J)); none: u = 1.   x_cur ← (c(u), c'(u)/T_w, c''(u)/T_w²)
//! K_win      = the kinematics of the phase with fewer contacts (1 attractor) or of the
//!              middle phase (2 attractors); checked on the kept part [0, u] (§5.4)
//! ```
//!
//! A window whose data duration is below [`MIN_WINDOW_S`] (zero-duration phases at the
//! end) is stretched to it: the spec is silent there, and `T_w → 0` has no curve.
//!
//! # Frames and units
//!
//! World frame, Z up; m, s, kg. Times are on the data clock (phase 1 starts at 0).
//!
//! # References
//!
//! Tonneau et al., 2PAC, §4–§5 (sliding window, Fig. 6); spec two-pac §1, §4, §5.4, §6.

use super::bezier::{check_control_points, Bezier, ComState, ControlViolation};
use super::contact::Contact;
use super::equilibrium::EqualityForm;
use super::polytope::Polytope;
use super::region::{static_region, RegionOptions, RegionStatus, StaticRegion};
use super::transition::{
    transition_eq13, transition_eq6, QpForm, TransitionOptions, TransitionPoint,
};
use super::v3::{norm, scale, sub};
use super::TwopacError;
use crate::math::constants::STATIC_TOL;

/// Most phases of one sequence (count). `twopac` plans it 31 times and solves each
/// transition QP 2,000 times for `timings.json`, so its time grows with the phases.
pub const MAX_PHASES: usize = 1_000;
/// Step of the switch-parameter scan (§6 step 4).
pub const U_STEP: f64 = 0.01;
/// Speed of the polyline rule for `T_w` without durations, m/s (§6 step 2).
pub const POLYLINE_SPEED_MPS: f64 = 0.3;
/// Shortest window of the polyline rule, s (§6 step 2).
pub const POLYLINE_MIN_S: f64 = 0.5;
/// Shortest window on the data clock, s (spec silent; see the module docs).
pub const MIN_WINDOW_S: f64 = 0.05;
/// Two contacts of consecutive phases are the same when effector names match and their
/// positions differ by less than this, m.
pub const SAME_CONTACT_TOL_M: f64 = 1e-6;
/// Speed threshold of the switch scan, `|c'(u)| > 1e-6` (normalised time, m).
pub const SWITCH_MIN_SPEED: f64 = 1e-6;

/// One contact phase (§1): contacts, their world-frame kinematic polytopes, timing.
#[derive(Debug, Clone, PartialEq)]
pub struct Phase {
    /// Active contacts.
    pub contacts: Vec<Contact>,
    /// World-frame kinematic polytope of each contact (§3), same order as `contacts`.
    pub kinematics: Vec<Polytope>,
    /// Data duration, s (`None`: no data timing, §6 step 2 polyline rule).
    pub duration_s: Option<f64>,
    /// Data COM of the phase, m (`None`: projection of the previous state).
    pub com: Option<[f64; 3]>,
}

impl Phase {
    /// The phase polytope `K^(j)`: all contacts' rows stacked (§3).
    pub fn polytope(&self) -> Polytope {
        self.kinematics
            .iter()
            .fold(Polytope::default(), |acc, k| acc.stacked(k))
    }

    fn effectors(&self) -> Vec<String> {
        self.contacts.iter().map(|c| c.effector.clone()).collect()
    }

    fn has(&self, c: &Contact) -> bool {
        self.contacts.iter().any(|d| {
            d.effector == c.effector && norm(sub(d.position, c.position)) < SAME_CONTACT_TOL_M
        })
    }
}

/// Options of [`plan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    /// Transition QP weights.
    pub transition: TransitionOptions,
    /// QP form for phase states and transitions (default eq 13, §4).
    pub form: QpForm,
    /// H-representation options (eq 6 form only).
    pub region: RegionOptions,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            transition: TransitionOptions::default(),
            form: QpForm::Eq13,
            region: RegionOptions::default(),
        }
    }
}

/// A contact change between phases `j` and `j+1`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    /// `j` (the transition `j → j+1`), 0-based.
    pub index: usize,
    /// The phase whose statics were used (fewer contacts).
    pub statics_phase: usize,
    /// The phase whose kinematics were used (more contacts).
    pub kinematics_phase: usize,
    /// True when `j+1` has one contact more than `j`.
    pub adds: bool,
    /// The effector added or removed.
    pub effector: String,
    /// The transition point and its slack.
    pub point: TransitionPoint,
}

/// One sliding window of §6 and its kinematic guarantee (§5.4).
#[derive(Debug, Clone, PartialEq)]
pub struct Window {
    /// First phase `j`.
    pub first_phase: usize,
    /// Last phase `J`.
    pub last_phase: usize,
    /// The full curve (1 or 2 attractors).
    pub curve: Bezier,
    /// Data time at `u = 0`, s.
    pub t_start_s: f64,
    /// `T_w`, s.
    pub duration_s: f64,
    /// Switch parameter `u`: the trajectory keeps `[0, u]`.
    pub u_end: f64,
    /// The phase whose kinematics form `K_win`.
    pub guarantee_phase: usize,
    /// Control points of the kept part outside `K_win` (empty: guaranteed).
    pub violations: Vec<ControlViolation>,
}

/// The result of [`plan`]: states, transitions, windows and switch times.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Projected phase states `c^(j)` (§1).
    pub phase_states: Vec<TransitionPoint>,
    /// Transition points in order (§4).
    pub transitions: Vec<Transition>,
    /// Sliding windows in order (§6).
    pub windows: Vec<Window>,
    /// Contact switch times `j → j+1`, s (data boundaries, or closest approach).
    pub switch_times_s: Vec<f64>,
    /// Phase start times on the data clock (`None` without durations).
    pub phase_starts_s: Option<Vec<f64>>,
    /// Equality form of each phase (for validation).
    pub forms: Vec<EqualityForm>,
}

/// A COM trajectory that can be sampled in real time (for §7 validation).
pub trait ComTrajectory {
    /// `(t_start, t_end)`, s.
    fn span_s(&self) -> (f64, f64);
    /// The COM state and the active phase at time `t`.
    fn sample(&self, t_s: f64) -> (ComState, usize);
}

fn phase_at(switch_times_s: &[f64], t_s: f64) -> usize {
    switch_times_s.iter().take_while(|&&s| s <= t_s).count()
}

impl ComTrajectory for Plan {
    fn span_s(&self) -> (f64, f64) {
        match (self.windows.first(), self.windows.last()) {
            (Some(a), Some(b)) => (a.t_start_s, b.t_start_s + b.u_end * b.duration_s),
            _ => (0.0, 0.0),
        }
    }

    fn sample(&self, t_s: f64) -> (ComState, usize) {
        let phase = phase_at(&self.switch_times_s, t_s);
        let Some(first) = self.windows.first() else {
            let pos = self.phase_states.first().map_or([0.0; 3], |p| p.com);
            return (ComState::at_rest(pos), 0);
        };
        let w = self
            .windows
            .iter()
            .rev()
            .find(|w| w.t_start_s <= t_s)
            .unwrap_or(first);
        let u = ((t_s - w.t_start_s) / w.duration_s).clamp(0.0, w.u_end);
        (w.curve.state(u, w.duration_s), phase)
    }
}

/// Check §1: consecutive phases differ by exactly one contact; returns `(adds, effector)`.
fn change(prev: &Phase, next: &Phase, j: usize) -> Result<(bool, String), TwopacError> {
    let added: Vec<&Contact> = next.contacts.iter().filter(|c| !prev.has(c)).collect();
    let removed: Vec<&Contact> = prev.contacts.iter().filter(|c| !next.has(c)).collect();
    match (added.as_slice(), removed.as_slice()) {
        ([a], []) => Ok((true, a.effector.clone())),
        ([], [r]) => Ok((false, r.effector.clone())),
        _ => Err(TwopacError::InvalidPhases {
            phase: j + 1,
            msg: format!(
                "differs from phase {j} by {} added and {} removed contacts (exactly one change)",
                added.len(),
                removed.len()
            ),
        }),
    }
}

/// The 2PAC trajectory of a phase sequence (§1, §4, §6), without dynamic validation.
///
/// # Errors
///
/// [`TwopacError::InvalidPhases`] (no phases, phase 0 without `com`, kinematics not one
/// polytope per contact, not one change per boundary, negative duration),
/// [`TwopacError::InvalidMass`], [`TwopacError::KinematicsInfeasible`] with the
/// transition and effectors, [`TwopacError::Solver`].
pub fn plan(
    phases: &[Phase],
    mass_kg: f64,
    start: &ComState,
    opts: &PlanOptions,
) -> Result<Plan, TwopacError> {
    let c_data0 = check_phases(phases)?;
    let changes = contact_changes(phases)?;
    let solver = PointSolver::new(phases, mass_kg, opts)?;
    let phase_states = phase_states(phases, &solver, c_data0)?;
    let transitions = transitions(phases, &changes, &solver, &phase_states)?;
    let starts = phase_starts(phases);
    let (windows, switch_times_s) = windows(
        phases,
        &solver.polys,
        &phase_states,
        &transitions,
        starts.as_ref(),
        start,
    )?;
    Ok(Plan {
        mass_kg,
        phase_states,
        transitions,
        windows,
        switch_times_s,
        phase_starts_s: starts,
        forms: solver.forms,
    })
}

/// The checks of §1 that need no solve; returns the data COM of phase 0 (the start).
fn check_phases(phases: &[Phase]) -> Result<[f64; 3], TwopacError> {
    let n = phases.len();
    let bad = |phase: usize, msg: &str| TwopacError::InvalidPhases {
        phase,
        msg: msg.to_string(),
    };
    if n == 0 {
        return Err(bad(0, "no phases"));
    }
    if n > MAX_PHASES {
        return Err(TwopacError::Cap {
            what: "phases",
            found: n.to_string(),
            max: MAX_PHASES,
            cap: "MAX_PHASES",
        });
    }
    for (j, p) in phases.iter().enumerate() {
        if p.kinematics.len() != p.contacts.len() {
            return Err(bad(j, "needs one kinematic polytope per contact"));
        }
        if p.duration_s.is_some_and(|d| !(d >= 0.0 && d.is_finite())) {
            return Err(bad(j, "duration must be finite and non-negative"));
        }
    }
    phases[0]
        .com
        .ok_or_else(|| bad(0, "the first phase needs a data COM (the start position)"))
}

/// The contact change `(adds, effector)` of every boundary `j → j+1` (§1).
fn contact_changes(phases: &[Phase]) -> Result<Vec<(bool, String)>, TwopacError> {
    (0..phases.len().saturating_sub(1))
        .map(|j| change(&phases[j], &phases[j + 1], j))
        .collect()
}

/// The QP of §4 for every phase's statics and kinematics: equality forms, phase polytopes
/// and (eq 6 form) static regions.
struct PointSolver<'a> {
    forms: Vec<EqualityForm>,
    polys: Vec<Polytope>,
    regions: Vec<Option<StaticRegion>>,
    opts: &'a PlanOptions,
}

impl<'a> PointSolver<'a> {
    fn new(phases: &[Phase], mass_kg: f64, opts: &'a PlanOptions) -> Result<Self, TwopacError> {
        let forms = phases
            .iter()
            .map(|p| EqualityForm::new(&p.contacts, mass_kg))
            .collect::<Result<Vec<_>, _>>()?;
        let polys: Vec<Polytope> = phases.iter().map(Phase::polytope).collect();
        let regions = if opts.form == QpForm::Eq6 {
            forms
                .iter()
                .map(|f| static_region(&f.points, &opts.region).map(Some))
                .collect::<Result<Vec<_>, _>>()?
        } else {
            vec![None; phases.len()]
        };
        Ok(PointSolver {
            forms,
            polys,
            regions,
            opts,
        })
    }

    /// The point of §4 with the statics of phase `statics` inside `kin`, nearest `c_prev`.
    fn solve(
        &self,
        statics: usize,
        kin: &Polytope,
        c_prev: [f64; 3],
    ) -> Result<TransitionPoint, TwopacError> {
        let t = &self.opts.transition;
        match &self.regions[statics] {
            Some(r) if r.status != RegionStatus::Empty => {
                transition_eq6(r, self.forms[statics].degenerate, kin, c_prev, t)
            }
            _ => transition_eq13(&self.forms[statics], kin, c_prev, t),
        }
    }
}

/// A kinematics failure, told where: the transition (`None`: a phase state) and effectors.
fn with_where(e: TwopacError, t: Option<usize>, who: Vec<String>) -> TwopacError {
    match e {
        TwopacError::KinematicsInfeasible { .. } => TwopacError::KinematicsInfeasible {
            transition: t,
            effectors: who,
        },
        other => other,
    }
}

/// Phase states `c^(j)` (§1): statics and kinematics of phase `j`, nearest its data COM
/// (or the previous state).
fn phase_states(
    phases: &[Phase],
    solver: &PointSolver,
    c_data0: [f64; 3],
) -> Result<Vec<TransitionPoint>, TwopacError> {
    let mut states: Vec<TransitionPoint> = Vec::with_capacity(phases.len());
    for (j, phase) in phases.iter().enumerate() {
        let c_prev = phase
            .com
            .or_else(|| states.last().map(|s| s.com))
            .unwrap_or(c_data0);
        let s = solver
            .solve(j, &solver.polys[j], c_prev)
            .map_err(|e| with_where(e, None, phase.effectors()))?;
        states.push(s);
    }
    Ok(states)
}

/// Transition points `c^(j,j+1)` (§4): statics of the phase with fewer contacts inside the
/// kinematics of the one with more, each nearest the previous point.
fn transitions(
    phases: &[Phase],
    changes: &[(bool, String)],
    solver: &PointSolver,
    phase_states: &[TransitionPoint],
) -> Result<Vec<Transition>, TwopacError> {
    let mut out: Vec<Transition> = Vec::with_capacity(changes.len());
    let mut c_prev = phase_states[0].com;
    for (j, (adds, effector)) in changes.iter().enumerate() {
        let (fewer, more) = if *adds { (j, j + 1) } else { (j + 1, j) };
        let point = solver
            .solve(fewer, &solver.polys[more], c_prev)
            .map_err(|e| with_where(e, Some(j), phases[more].effectors()))?;
        c_prev = point.com;
        out.push(Transition {
            index: j,
            statics_phase: fewer,
            kinematics_phase: more,
            adds: *adds,
            effector: effector.clone(),
            point,
        });
    }
    Ok(out)
}

/// Phase start times on the data clock (§6), `None` unless every phase has a duration.
fn phase_starts(phases: &[Phase]) -> Option<Vec<f64>> {
    phases
        .iter()
        .map(|p| p.duration_s)
        .collect::<Option<Vec<f64>>>()
        .map(|d| {
            let mut acc = 0.0;
            d.iter()
                .map(|x| {
                    let s = acc;
                    acc += x;
                    s
                })
                .collect()
        })
}

/// The parameter `u ∈ {0, 0.01, …, 1}` where the curve comes closest to `target` (§6).
fn closest_approach(curve: &Bezier, target: [f64; 3]) -> f64 {
    (0..=100)
        .map(|k| k as f64 * U_STEP)
        .min_by(|a, b| {
            norm(sub(curve.eval(*a), target)).total_cmp(&norm(sub(curve.eval(*b), target)))
        })
        .unwrap_or(0.0)
}

/// The switch parameter (§6 step 4): the first `u = u_min + 0.01 k < 1` with `c(u)` in
/// `next` and `|c'(u)| > SWITCH_MIN_SPEED`; 1 when there is none.
fn switch_parameter(curve: &Bezier, next: &Polytope, u_min: f64) -> f64 {
    let mut k = 0;
    loop {
        let cand = u_min + k as f64 * U_STEP;
        if cand >= 1.0 {
            return 1.0;
        }
        if next.contains(curve.eval(cand), 1e-9) && norm(curve.d1(cand)) > SWITCH_MIN_SPEED {
            return cand;
        }
        k += 1;
    }
}

/// The window duration `T_w` (§6 step 2): to the middle of phase `J` on the data clock
/// (at least [`MIN_WINDOW_S`]), else the polyline rule through the attractors.
fn window_duration(
    mid_j: Option<f64>,
    t_cur: f64,
    from: [f64; 3],
    attractors: &[[f64; 3]],
    end: [f64; 3],
) -> f64 {
    let mut poly_len = 0.0;
    let mut last = from;
    for p in attractors.iter().chain(std::iter::once(&end)) {
        poly_len += norm(sub(*p, last));
        last = *p;
    }
    match mid_j {
        Some(m) => (m - t_cur).max(MIN_WINDOW_S),
        None => POLYLINE_MIN_S.max(poly_len / POLYLINE_SPEED_MPS),
    }
}

/// The sliding windows of §6 and the switch times (data boundaries, or the closest
/// approach to each transition point without durations).
fn windows(
    phases: &[Phase],
    polys: &[Polytope],
    phase_states: &[TransitionPoint],
    transitions: &[Transition],
    starts: Option<&Vec<f64>>,
    start: &ComState,
) -> Result<(Vec<Window>, Vec<f64>), TwopacError> {
    let n = phases.len();
    let mid = |j: usize| -> Option<f64> {
        starts.map(|s| s[j] + 0.5 * phases[j].duration_s.unwrap_or(0.0))
    };
    let mut windows = Vec::new();
    let mut switch_times_s: Vec<f64> = match starts {
        Some(s) => s[1..].to_vec(),
        None => vec![f64::NAN; n - 1],
    };
    let mut x_cur = ComState {
        pos: phase_states[0].com,
        vel: start.vel,
        acc: start.acc,
    };
    let mut t_cur = mid(0).unwrap_or(0.0);
    let mut j = 0;
    while j + 1 < n {
        let two = j + 2 < n && !transitions[j].adds && transitions[j + 1].adds;
        let big_j = if two { j + 2 } else { j + 1 };
        let attractors: Vec<[f64; 3]> = transitions[j..big_j].iter().map(|t| t.point.com).collect();
        let end = ComState::at_rest(phase_states[big_j].com);
        let t_w = window_duration(mid(big_j), t_cur, x_cur.pos, &attractors, end.pos);
        let curve = Bezier::with_attractors(&x_cur, &end, t_w, &attractors)?;
        if starts.is_none() {
            for (i, t) in transitions[j..big_j].iter().enumerate() {
                switch_times_s[j + i] = t_cur + closest_approach(&curve, t.point.com) * t_w;
            }
        }
        let u_end = if big_j + 1 == n {
            1.0
        } else {
            let u_min = match starts {
                Some(s) => ((s[big_j] - t_cur) / t_w).clamp(0.0, 1.0),
                None => closest_approach(&curve, transitions[big_j - 1].point.com),
            };
            switch_parameter(&curve, &polys[big_j], u_min)
        };
        let guarantee_phase = if two {
            j + 1
        } else {
            transitions[j].statics_phase
        };
        let kept = curve.left(u_end);
        let violations = check_control_points(&kept, &polys[guarantee_phase]);
        let next = curve.state(u_end, t_w);
        windows.push(Window {
            first_phase: j,
            last_phase: big_j,
            curve,
            t_start_s: t_cur,
            duration_s: t_w,
            u_end,
            guarantee_phase,
            violations,
        });
        x_cur = next;
        t_cur += u_end * t_w;
        j = big_j;
    }
    Ok((windows, switch_times_s))
}

/// Per-phase diagnostics of §8: statics at the phase state and the kinematic margin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseDiagnostic {
    /// The phase state `c^(j)` is statically feasible (its QP slack and wrench residual
    /// are at most `1e-6`).
    pub static_feasible: bool,
    /// `min(k − K c^(j))` over the phase polytope, m (`+∞` without rows; `< 0` outside).
    pub kinematic_margin_m: f64,
}

/// §8 per-phase diagnostics of a plan made from `phases`.
pub fn phase_diagnostics(plan: &Plan, phases: &[Phase]) -> Vec<PhaseDiagnostic> {
    plan.phase_states
        .iter()
        .zip(phases)
        .map(|(s, p)| PhaseDiagnostic {
            static_feasible: s.is_static(STATIC_TOL),
            kinematic_margin_m: -p.polytope().max_violation(s.com),
        })
        .collect()
}

/// The quasi-static polyline baseline `c^(1) → c^(1,2) → c^(2) → …` (§6), each segment
/// rest to rest by the quintic smoothstep `σ(τ) = 10τ³ − 15τ⁴ + 6τ⁵`.
#[derive(Debug, Clone, PartialEq)]
pub struct QuasiStatic {
    /// Knots: `(time s, position m, phase active on the segment that starts here)`.
    pub knots: Vec<(f64, [f64; 3], usize)>,
    /// Contact switch times, s (as the plan's).
    pub switch_times_s: Vec<f64>,
}

impl QuasiStatic {
    /// The polyline of a plan: knots at the phase mids and the switch times (data clock),
    /// or timed at [`POLYLINE_SPEED_MPS`] (at least 0.1 s a segment) without durations.
    pub fn from_plan(plan: &Plan) -> QuasiStatic {
        let mut pts: Vec<([f64; 3], Option<f64>)> = Vec::new();
        let starts = plan.phase_starts_s.as_ref();
        let n = plan.phase_states.len();
        for j in 0..n {
            let mid = starts.map(|s| {
                let end = if j + 1 < n { s[j + 1] } else { f64::NAN };
                if j + 1 < n {
                    0.5 * (s[j] + end)
                } else {
                    plan.windows
                        .last()
                        .map_or(s[j], |w| w.t_start_s + w.u_end * w.duration_s)
                }
            });
            pts.push((plan.phase_states[j].com, mid));
            if j + 1 < n {
                pts.push((plan.transitions[j].point.com, starts.map(|s| s[j + 1])));
            }
        }
        let mut knots = Vec::with_capacity(pts.len());
        let mut t = pts[0].1.unwrap_or(0.0);
        for (i, (p, time)) in pts.iter().enumerate() {
            if i > 0 {
                let seg = norm(sub(*p, pts[i - 1].0)) / POLYLINE_SPEED_MPS;
                t = time.unwrap_or(t + seg.max(0.1)).max(t);
            }
            knots.push((t, *p, i / 2));
        }
        let switch_times_s = if starts.is_some() {
            plan.switch_times_s.clone()
        } else {
            (0..n - 1).map(|j| knots[2 * j + 1].0).collect()
        };
        QuasiStatic {
            knots,
            switch_times_s,
        }
    }
}

impl ComTrajectory for QuasiStatic {
    fn span_s(&self) -> (f64, f64) {
        match (self.knots.first(), self.knots.last()) {
            (Some(a), Some(b)) => (a.0, b.0),
            _ => (0.0, 0.0),
        }
    }

    fn sample(&self, t_s: f64) -> (ComState, usize) {
        let phase = phase_at(&self.switch_times_s, t_s);
        let i = self.knots.iter().rposition(|k| k.0 <= t_s).unwrap_or(0);
        if i + 1 >= self.knots.len() {
            return (ComState::at_rest(self.knots[i].1), phase);
        }
        let (t0, a, _) = self.knots[i];
        let (t1, b, _) = self.knots[i + 1];
        let dt = t1 - t0;
        if dt <= 0.0 {
            return (ComState::at_rest(b), phase);
        }
        let tau = ((t_s - t0) / dt).clamp(0.0, 1.0);
        let s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
        let ds = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / dt;
        let dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (dt * dt);
        let d = sub(b, a);
        (
            ComState {
                pos: super::v3::add(a, scale(s, d)),
                vel: scale(ds, d),
                acc: scale(dds, d),
            },
            phase,
        )
    }
}
