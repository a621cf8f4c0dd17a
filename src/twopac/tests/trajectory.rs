//! Sliding window, time parametrisation and dynamic validation (spec §1, §5.4, §6, §7).

use super::{flat_foot, r3_box};
use crate::twopac::bezier::{check_control_points, Bezier, ComState};
use crate::twopac::contact::Contact;
use crate::twopac::equilibrium::EqualityForm;
use crate::twopac::trajectory::{
    phase_diagnostics, plan, ComTrajectory, Phase, PlanOptions, QuasiStatic,
};
use crate::twopac::transition::QpForm;
use crate::twopac::validate::{sample_times, summarise, validate, DEFAULT_STEP_S};
use crate::twopac::TwopacError;

const M: f64 = 50.0;

fn foot(name: &str, x: f64, y: f64) -> Contact {
    flat_foot(name, [x, y, 0.0], 0.2172, 0.138, 0.5)
}

fn phase(feet: &[(&str, f64, f64)], dur: Option<f64>) -> Phase {
    let contacts: Vec<Contact> = feet.iter().map(|&(n, x, y)| foot(n, x, y)).collect();
    let kinematics = feet.iter().map(|&(_, x, y)| r3_box(x, y)).collect();
    let n = feet.len() as f64;
    let com = [
        feet.iter().map(|f| f.1).sum::<f64>() / n,
        feet.iter().map(|f| f.2).sum::<f64>() / n,
        0.8,
    ];
    Phase {
        contacts,
        kinematics,
        duration_s: dur,
        com: Some(com),
    }
}

/// Three steps of 0.3 m: DS, SS, DS, SS, DS, SS, DS (7 phases, 3 two-attractor windows).
fn walk(ds: f64, ss: f64) -> Vec<Phase> {
    vec![
        phase(&[("l", 0.0, 0.1), ("r", 0.0, -0.1)], Some(ds)),
        phase(&[("r", 0.0, -0.1)], Some(ss)),
        phase(&[("l", 0.3, 0.1), ("r", 0.0, -0.1)], Some(ds)),
        phase(&[("l", 0.3, 0.1)], Some(ss)),
        phase(&[("l", 0.3, 0.1), ("r", 0.6, -0.1)], Some(ds)),
        phase(&[("r", 0.6, -0.1)], Some(ss)),
        phase(&[("l", 0.9, 0.1), ("r", 0.6, -0.1)], Some(ds)),
    ]
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

#[test]
fn walk_uses_two_attractor_windows_with_c2_junctions() {
    let phases = walk(0.3, 0.6);
    let p = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    assert_eq!(p.transitions.len(), 6);
    assert!(
        p.transitions.iter().all(|t| t.point.is_static(1e-6)),
        "{:?}",
        p.transitions
    );
    assert!(p.phase_states.iter().all(|s| s.is_static(1e-6)));
    let spans: Vec<(usize, usize, usize)> = p
        .windows
        .iter()
        .map(|w| (w.first_phase, w.last_phase, w.curve.degree()))
        .collect();
    assert_eq!(spans, vec![(0, 2, 7), (2, 4, 7), (4, 6, 7)]);
    // Junctions: state at the switch of window k equals the start of window k+1 (C²).
    for pair in p.windows.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let end = a.curve.state(a.u_end, a.duration_s);
        let start = b.curve.state(0.0, b.duration_s);
        assert!((a.t_start_s + a.u_end * a.duration_s - b.t_start_s).abs() < 1e-12);
        assert!(close(end.pos, start.pos, 1e-9) && close(end.vel, start.vel, 1e-9));
        assert!(close(end.acc, start.acc, 1e-9), "{end:?} {start:?}");
        // The switch happens after the last contact change of the window (u ≥ u_min).
        let starts = p.phase_starts_s.as_ref().unwrap();
        assert!(b.t_start_s >= starts[a.last_phase] - 1e-12);
    }
    // Starts at rest at c^(1) at the mid of phase 1, ends at rest at c^(n) at its mid.
    let (t0, t1) = p.span_s();
    assert!((t0 - 0.15).abs() < 1e-12);
    let starts = p.phase_starts_s.clone().unwrap();
    assert!((t1 - (starts[6] + 0.15)).abs() < 1e-9, "{t1}");
    let (s_end, phase_end) = p.sample(t1);
    assert!(close(s_end.pos, p.phase_states[6].com, 1e-9));
    assert!(close(s_end.vel, [0.0; 3], 1e-9) && close(s_end.acc, [0.0; 3], 1e-9));
    assert_eq!(phase_end, 6);
    assert!(close(p.sample(t0).0.pos, p.phase_states[0].com, 1e-12));
}

#[test]
fn kinematic_guarantee_is_reported_for_the_kept_part() {
    let phases = walk(0.3, 0.6);
    let p = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    for w in &p.windows {
        let k_win = phases[w.guarantee_phase].polytope();
        let kept = w.curve.left(w.u_end);
        assert_eq!(w.violations, check_control_points(&kept, &k_win));
        if w.violations.is_empty() {
            for i in 0..=100 {
                assert!(k_win.contains(kept.eval(i as f64 / 100.0), 1e-9));
            }
        }
    }
    // Two-attractor windows use the middle (single-support) phase.
    assert_eq!(
        p.windows
            .iter()
            .map(|w| w.guarantee_phase)
            .collect::<Vec<_>>(),
        vec![1, 3, 5]
    );
}

#[test]
fn add_then_remove_gives_one_attractor_windows() {
    let phases = vec![
        phase(&[("r", 0.0, -0.1)], Some(0.6)),
        phase(&[("l", 0.3, 0.1), ("r", 0.0, -0.1)], Some(0.3)),
        phase(&[("l", 0.3, 0.1)], Some(0.6)),
    ];
    let p = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    let spans: Vec<(usize, usize, usize)> = p
        .windows
        .iter()
        .map(|w| (w.first_phase, w.last_phase, w.curve.degree()))
        .collect();
    assert_eq!(spans, vec![(0, 1, 6), (1, 2, 6)]);
    assert_eq!(p.windows[0].curve.control[3], p.transitions[0].point.com);
    // One-attractor windows use the phase with fewer contacts.
    assert_eq!(p.windows[0].guarantee_phase, 0);
    assert_eq!(p.windows[1].guarantee_phase, 2);
}

#[test]
fn eq6_and_eq13_plans_agree_when_everything_is_static() {
    let phases = walk(0.3, 0.6);
    let a = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    let o6 = PlanOptions {
        form: QpForm::Eq6,
        ..PlanOptions::default()
    };
    let b = plan(&phases, M, &ComState::default(), &o6).unwrap();
    for (x, y) in a.transitions.iter().zip(&b.transitions) {
        assert_eq!(y.point.form, QpForm::Eq6);
        assert!(close(x.point.com, y.point.com, 1e-4), "{x:?} {y:?}");
    }
}

#[test]
fn without_durations_the_polyline_rule_times_the_windows() {
    let mut phases = walk(0.3, 0.6);
    for p in &mut phases {
        p.duration_s = None;
    }
    let p = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    assert!(p.phase_starts_s.is_none());
    assert!(p.windows.iter().all(|w| w.duration_s >= 0.5));
    assert!(p.switch_times_s.iter().all(|t| t.is_finite()));
    assert!(
        p.switch_times_s.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        p.switch_times_s
    );
}

#[test]
fn two_changes_at_one_boundary_are_rejected_with_the_phase() {
    let phases = vec![
        phase(&[("l", 0.0, 0.1), ("r", 0.0, -0.1)], Some(0.3)),
        phase(&[("l", 0.3, 0.1), ("r", 0.0, -0.1)], Some(0.3)),
    ];
    let e = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap_err();
    assert!(
        matches!(e, TwopacError::InvalidPhases { phase: 1, .. }),
        "{e:?}"
    );
}

#[test]
fn empty_transition_kinematics_name_the_transition_and_effectors() {
    // The new foot's box does not meet the old one's: no point in the union's polytope.
    let phases = vec![
        phase(&[("r", 0.0, -0.1)], Some(0.5)),
        phase(&[("l", 3.0, 0.1), ("r", 0.0, -0.1)], Some(0.5)),
    ];
    let mut phases = phases;
    phases[1].com = None;
    let e = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap_err();
    match e {
        TwopacError::KinematicsInfeasible { effectors, .. } => {
            assert!(effectors.contains(&"l".to_string()))
        }
        other => panic!("{other:?}"),
    }
}

/// A straight rest-to-rest move (quintic smoothstep) inside one support polygon.
struct Line {
    a: [f64; 3],
    b: [f64; 3],
    t: f64,
}

impl ComTrajectory for Line {
    fn span_s(&self) -> (f64, f64) {
        (0.0, self.t)
    }
    fn sample(&self, t: f64) -> (ComState, usize) {
        let c = Bezier {
            control: vec![self.a, self.a, self.a, self.b, self.b, self.b],
        };
        (c.state(t / self.t, self.t), 0)
    }
}

#[test]
fn slow_path_validates_fully_and_fast_path_mostly_fails() {
    // Spec §7: a slow path inside the support polygon validates at 100 %; the same path
    // 25 times faster does not.
    let feet = [foot("l", 0.0, 0.1), foot("r", 0.0, -0.1)];
    let forms = [EqualityForm::new(&feet, M).unwrap()];
    let path = |t| Line {
        a: [-0.08, -0.12, 0.8],
        b: [0.08, 0.12, 0.8],
        t,
    };
    let slow = validate(&path(4.0), &forms, DEFAULT_STEP_S);
    assert_eq!(slow.samples.len(), 401);
    assert!(slow.trajectory_valid, "{}", slow.max_slack_n);
    assert_eq!(slow.point_valid_rate, 1.0);
    let fast = validate(&path(4.0 / 25.0), &forms, DEFAULT_STEP_S);
    assert!(!fast.trajectory_valid);
    assert!(fast.point_valid_rate < 0.5, "{}", fast.point_valid_rate);
    assert!(fast.max_slack_n > 1.0);
    let (mean_rate, valid_frac) = summarise(&[slow, fast.clone()]);
    assert!((mean_rate - (1.0 + fast.point_valid_rate) / 2.0).abs() < 1e-12);
    assert_eq!(valid_frac, 0.5);
}

#[test]
fn walk_validation_reports_every_sample() {
    let phases = walk(0.3, 0.6);
    let p = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    let v = validate(&p, &p.forms, DEFAULT_STEP_S);
    let (t0, t1) = p.span_s();
    assert_eq!(v.samples.len(), sample_times(t0, t1, DEFAULT_STEP_S).len());
    assert!(v.point_valid_rate > 0.0 && v.point_valid_rate <= 1.0);
    // Phases follow the data boundaries.
    for s in &v.samples {
        let starts = p.phase_starts_s.as_ref().unwrap();
        assert!(starts[s.phase] <= s.t_s + 1e-12);
        assert!(s.phase + 1 == starts.len() || s.t_s < starts[s.phase + 1]);
    }
    // The quasi-static baseline passes through every state and transition point at rest.
    let q = QuasiStatic::from_plan(&p);
    assert_eq!(q.knots.len(), 13);
    for &(t, pos, _) in &q.knots {
        let (s, _) = q.sample(t);
        assert!(close(s.pos, pos, 1e-12) && close(s.vel, [0.0; 3], 1e-12));
    }
    let _ = validate(&q, &p.forms, DEFAULT_STEP_S);
}

#[test]
fn phase_diagnostics_report_statics_and_kinematic_margin() {
    // Phase 1's data COM (0.15, 0, 0.8) is outside the right foot's polygon: its state is
    // projected onto the polygon's corner (0.1086, −0.031) (§1), 0.1 m below the z ≤ 0.9 row.
    let mut phases = walk(0.3, 0.6);
    phases[1].com = Some([0.15, 0.0, 0.8]);
    let p = plan(&phases, M, &ComState::default(), &PlanOptions::default()).unwrap();
    let d = phase_diagnostics(&p, &phases);
    assert_eq!(d.len(), 7);
    assert!(d.iter().all(|x| x.static_feasible));
    assert!(
        (p.phase_states[1].com[1] + 0.031).abs() < 1e-6,
        "{:?}",
        p.phase_states[1]
    );
    for (x, s) in d.iter().zip(&p.phase_states) {
        assert!(x.kinematic_margin_m >= -1e-9);
        assert!(x.kinematic_margin_m <= 0.9 - s.com[2] + 1e-9);
    }
}
