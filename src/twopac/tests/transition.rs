//! Transition points (spec §4, §9 R3, R4; issue 5 acceptance cases).

use super::{flat_foot, point_set, r3_box};
use crate::twopac::contact::{contact_points, Contact, ContactShape};
use crate::twopac::equilibrium::EqualityForm;
use crate::twopac::polytope::Polytope;
use crate::twopac::region::{static_region, RegionOptions};
use crate::twopac::transition::{
    transition_eq13, transition_eq6, TransitionOptions, TransitionPoint,
};
use crate::twopac::TwopacError;

/// Kinematic rows are never relaxed: satisfied to QP round-off.
const KIN_TOL: f64 = 1e-9;
/// Static when `s` and `‖e‖₁` are at most this (spec §4: `wrench_residual > 1e-6` fails).
const STATIC_TOL: f64 = 1e-6;

fn both_forms(
    contacts: &[Contact],
    kin: &Polytope,
    c_prev: [f64; 3],
) -> (TransitionPoint, TransitionPoint) {
    let form = EqualityForm::new(contacts, 50.0).unwrap();
    let region = static_region(&form.points, &RegionOptions::default()).unwrap();
    let o = TransitionOptions::default();
    let p6 = transition_eq6(&region, form.degenerate, kin, c_prev, &o).unwrap();
    let p13 = transition_eq13(&form, kin, c_prev, &o).unwrap();
    for p in [&p6, &p13] {
        assert!(kin.max_violation(p.com) <= KIN_TOL, "{p:?}");
    }
    (p6, p13)
}

#[test]
fn r3_single_support_feasible_exactly_when_foot_overlaps_the_box() {
    // Spec §9 R3: m = 50, μ = 0.5, foot 0.2172 × 0.138 at (x, y, 0), box around the origin.
    let kin = r3_box(0.0, 0.0);
    let cases = [
        ((0.0, 0.0), true),
        ((0.7, 0.4), true),
        ((-0.7, -0.4), true),
        ((0.7, 0.0), true),
        ((0.8196, 0.0), false),
        ((-0.8196, 0.0), false),
        ((10.0, 0.0), false),
        ((0.0, 0.48), false),
        ((0.0, -0.48), false),
    ];
    for ((x, y), feasible) in cases {
        let foot = flat_foot("foot", [x, y, 0.0], 0.2172, 0.138, 0.5);
        let (p6, p13) = both_forms(&[foot], &kin, [0.0, 0.0, 0.0]);
        assert_eq!(
            p6.is_static(STATIC_TOL),
            feasible,
            "eq 6 at ({x}, {y}): {p6:?}"
        );
        assert_eq!(
            p13.is_static(STATIC_TOL),
            feasible,
            "eq 13 at ({x}, {y}): {p13:?}"
        );
        if feasible {
            // Both forms give the same point (spec §4, verified to 1e-4 m).
            for k in 0..3 {
                assert!((p6.com[k] - p13.com[k]).abs() < 1e-4, "{p6:?} {p13:?}");
            }
        } else {
            // Eq 6 slack: metres outside the support polygon (> 0.011 m at x = 0.8196).
            assert!(p6.slack > 0.01, "{p6:?}");
        }
    }
}

#[test]
fn r3_eq6_slack_is_the_distance_to_the_support_polygon() {
    // At x = 10 the closest kinematic point is x = 0.7; the foot's edge is at 10 − 0.1086.
    let foot = flat_foot("foot", [10.0, 0.0, 0.0], 0.2172, 0.138, 0.5);
    let (p6, _) = both_forms(&[foot], &r3_box(0.0, 0.0), [0.0; 3]);
    assert!((p6.com[0] - 0.7).abs() < 1e-6, "{p6:?}");
    assert!((p6.slack - (10.0 - 0.1086 - 0.7)).abs() < 1e-6, "{p6:?}");
}

#[test]
fn r4_flat_step_transitions_closest_to_the_origin() {
    // Spec §9 R4: statics of P1 (right foot only), kinematics of P0 and of P2.
    let f = |n: &str, x: f64, y: f64| flat_foot(n, [x, y, 0.0], 0.2172, 0.138, 0.5);
    let statics = [f("right", 0.0, -0.1)];
    let k0 = r3_box(0.0, 0.1).stacked(&r3_box(0.0, -0.1));
    let k2 = r3_box(0.3, 0.1).stacked(&r3_box(0.0, -0.1));
    for kin in [k0, k2] {
        let (p6, p13) = both_forms(&statics, &kin, [0.0; 3]);
        for p in [p6, p13] {
            assert!(p.is_static(STATIC_TOL), "{p:?}");
            let expect = [0.0, -0.031, 0.0];
            for (got, want) in p.com.iter().zip(expect) {
                assert!((got - want).abs() < 1e-6, "{p:?}");
            }
        }
    }
}

#[test]
fn qp_point_is_the_nearest_feasible_point_on_a_grid() {
    // Brute force (spec §4, verified): over a 1 cm grid of statically and kinematically
    // feasible points none is closer to c_prev than the QP's point.
    let foot = flat_foot("foot", [0.3, 0.25, 0.0], 0.2172, 0.138, 0.5);
    let kin = Polytope::new(
        vec![
            [1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        vec![0.55, 0.0, 0.0, 0.9, -0.6],
    );
    let c_prev = [0.0, 0.0, 1.0];
    let (p6, p13) = both_forms(std::slice::from_ref(&foot), &kin, c_prev);
    assert!(p6.is_static(STATIC_TOL) && p13.is_static(STATIC_TOL));
    let dist = |c: [f64; 3]| {
        ((c[0] - c_prev[0]).powi(2) + (c[1] - c_prev[1]).powi(2) + (c[2] - c_prev[2]).powi(2))
            .sqrt()
    };
    let region = static_region(&foot.points(), &RegionOptions::default()).unwrap();
    let mut best = f64::INFINITY;
    for i in 0..=60 {
        for j in 0..=60 {
            for k in 0..=30 {
                let c = [i as f64 * 0.01, j as f64 * 0.01, 0.6 + k as f64 * 0.01];
                if kin.contains(c, 1e-12) && region.contains(c, 1e-12) {
                    best = best.min(dist(c));
                }
            }
        }
    }
    assert!(best.is_finite());
    for p in [p6, p13] {
        assert!(dist(p.com) <= best + 1e-9, "{p:?} vs grid {best}");
        // The grid is 1 cm: its best point is within one diagonal of the optimum.
        assert!(best - dist(p.com) < 0.0174, "{p:?} vs grid {best}");
    }
}

#[test]
fn point_contact_transition_uses_the_wrench_slack_and_always_answers() {
    // CORRECTIONS item 2: one point contact, degenerate; eq 13 with the wrench slack.
    let hand = Contact::new(
        "hand",
        [0.2, 0.1, 0.0],
        [0.0, 0.0, 1.0],
        0.5,
        0.0,
        ContactShape::Point,
    )
    .unwrap();
    let form = EqualityForm::new(std::slice::from_ref(&hand), 50.0).unwrap();
    let o = TransitionOptions::default();
    // The vertical through the point crosses the box: static point on that vertical.
    let p = transition_eq13(&form, &r3_box(0.0, 0.0), [0.0, 0.0, 0.5], &o).unwrap();
    assert!(p.degenerate_contacts);
    assert!(p.is_static(STATIC_TOL), "{p:?}");
    assert!(
        (p.com[0] - 0.2).abs() < 1e-6 && (p.com[1] - 0.1).abs() < 1e-6,
        "{p:?}"
    );
    // It misses the box: still an answer, kinematically feasible, not static.
    let kin = r3_box(-1.0, 0.0);
    let p = transition_eq13(&form, &kin, [0.0, 0.0, 0.5], &o).unwrap();
    assert!(p.degenerate_contacts);
    assert!(!p.is_static(STATIC_TOL), "{p:?}");
    assert!(kin.max_violation(p.com) <= KIN_TOL);
    // Collinear points (a bar) are degenerate too; a rectangle is not.
    let bar = point_set(
        &[[0.0, 0.0, 1.0], [0.3, 0.0, 1.0], [0.6, 0.0, 1.0]],
        [0.0, 0.0, 1.0],
        0.5,
    );
    assert!(EqualityForm::new(&[bar], 50.0).unwrap().degenerate);
    let foot = flat_foot("f", [0.0; 3], 0.2, 0.1, 0.5);
    assert!(!EqualityForm::new(&[foot], 50.0).unwrap().degenerate);
    assert_eq!(contact_points(&[hand]).len(), 1);
}

#[test]
fn empty_kinematics_is_a_hard_failure() {
    let foot = flat_foot("foot", [0.0; 3], 0.2172, 0.138, 0.5);
    let form = EqualityForm::new(&[foot], 50.0).unwrap();
    let region = static_region(&form.points, &RegionOptions::default()).unwrap();
    let empty = Polytope::aabb([0.0, 0.0, 1.0], [1.0, 1.0, 0.5]);
    let o = TransitionOptions::default();
    let e13 = transition_eq13(&form, &empty, [0.0; 3], &o).unwrap_err();
    let e6 = transition_eq6(&region, false, &empty, [0.0; 3], &o).unwrap_err();
    for e in [e13, e6] {
        assert!(
            matches!(e, TwopacError::KinematicsInfeasible { .. }),
            "{e:?}"
        );
    }
}

#[test]
fn eq13_slack_is_the_pulling_force_in_body_weights() {
    // COM forced 0.1 m beyond the toe of a foot (eq 6: 0.1 m; eq 13: s > 0, no e since a
    // rectangle has full rank) — both report a violation, kinematics held.
    let foot = flat_foot("foot", [0.0; 3], 0.2, 0.1, 0.5);
    let kin = Polytope::aabb([0.2, -0.1, 0.8], [0.5, 0.1, 1.0]);
    let (p6, p13) = both_forms(&[foot], &kin, [0.0, 0.0, 0.9]);
    assert!((p6.slack - 0.1).abs() < 1e-6, "{p6:?}");
    assert!(
        p13.slack > 1e-3 && p13.wrench_residual < STATIC_TOL,
        "{p13:?}"
    );
}
