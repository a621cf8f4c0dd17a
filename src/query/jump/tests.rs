//! Tests of the jump solve: the identity jump, and simulated jumps that hit the requested
//! height and distance (spec stance-model §6.9), by an independent RK4 simulation.

use super::*;
use crate::query::feasibility::Violation;
use crate::query::testkit::{recorded_pair, simulate, Rng};

/// Simulates both sides of a jump from their requests and solutions: the end state of
/// the liftoff (its end apex) and of the landing.
fn fly(p1: &Prepared, p2: &Prepared, j: &Jump) -> ([f64; 6], [f64; 6]) {
    let [(r1, s1), (r2, s2)] = &j.sides;
    (
        simulate(&p1.stance.model, r1, &s1.solution),
        simulate(&p2.stance.model, r2, &s2.solution),
    )
}

#[test]
fn identity_jump_is_feasible_with_beta_one() {
    let mut rng = Rng::new(0x5eed_0501);
    let mut feasible = 0;
    for i in 0..100 {
        let (p1, p2) = recorded_pair(&mut rng);
        let (h, d) = recorded_jump(&p1.stance, &p2.stance);
        let j = jump(&p1, &p2, h, d, None).unwrap_or_else(|e| panic!("pair {i}: {e}"));
        for (_, s) in &j.sides {
            for a in [0, 2] {
                assert!(
                    (s.solution.beta[a] - 1.0).abs() < 1e-9,
                    "pair {i}: β {:?}",
                    s.solution.beta
                );
            }
        }
        assert!((j.u_apex - p1.stance.params.ve).abs() < 1e-9);
        feasible += usize::from(j.feasible() && j.feasible_approx());
    }
    // Relative limits at the stance's own extremes (≤): the identity is always feasible.
    assert_eq!(feasible, 100);
}

#[test]
fn simulated_jumps_hit_height_and_distance() {
    let mut rng = Rng::new(0x5eed_0502);
    let mut checked = 0;
    for _ in 0..100 {
        let (p1, p2) = recorded_pair(&mut rng);
        let (h0, d0) = recorded_jump(&p1.stance, &p2.stance);
        let (h, d) = (h0 + rng.uniform(-0.1, 0.2), d0 + rng.uniform(-0.3, 0.6));
        let Ok(j) = jump(&p1, &p2, h, d, None) else {
            continue;
        };
        checked += 1;
        let (e1, e2) = fly(&p1, &p2, &j);
        // Liftoff ends at the flight apex: height h, heading speed u_apex, not rising.
        assert!((e1[2] - h).abs() < 1e-6, "apex {} vs {h}", e1[2]);
        assert!((e1[3] - j.u_apex).abs() < 1e-6 && e1[5].abs() < 1e-6);
        assert!(
            e1[4].abs() < 1e-6,
            "a straight jump: no perpendicular velocity"
        );
        // Landing ends at its kept end apex; the two heading distances add up to d.
        let q2 = &p2.stance.params;
        assert!((e2[2] - q2.ze).abs() < 1e-6 && (e2[3] - q2.ve).abs() < 1e-6);
        assert!(
            (e1[0] + e2[0] - d).abs() < 1e-6,
            "distance {} vs {d}",
            e1[0] + e2[0]
        );
        // The flight: liftoff to apex plus apex to touchdown.
        let [(_, s1), (_, s2)] = &j.sides;
        let ft = (s1.solution.t_e - s1.solution.t_lo) + s2.solution.t_td;
        assert!((ft - j.flight_time).abs() < 1e-12 && j.flight_time >= 0.0);
    }
    assert!(checked > 50, "only {checked} jumps solved");
}

#[test]
fn unreachable_heights_and_flight_rules_are_reasons_not_nan() {
    let mut rng = Rng::new(0x5eed_0503);
    // A pair that sets the apex speed (no near-vertical stance, which keeps its distance).
    let (p1, p2) = loop {
        let (p1, p2) = recorded_pair(&mut rng);
        if [&p1, &p2]
            .iter()
            .all(|p| p.shape.j[0].abs() >= J_H_DEGENERATE_MPS)
        {
            break (p1, p2);
        }
    };
    let (h, d) = recorded_jump(&p1.stance, &p2.stance);
    // Far below the start apex with a kept approach: no real T.
    assert_eq!(
        jump(&p1, &p2, -50.0, d, None).err(),
        Some(JumpFailure::Unreachable)
    );
    // Jumping backwards needs a negative push-off β_h: a rule failure.
    let back = jump(&p1, &p2, h, d - 1e3, None);
    assert!(matches!(back, Err(JumpFailure::Rule(_))), "{back:?}");
    // A huge distance is admissible but breaks the force limit, with the reason.
    let far = jump(&p1, &p2, h, d + 1e3, None).expect("admissible");
    assert!(!far.feasible() && !far.feasible_approx());
    assert_eq!(far.sides[0].1.verdict.violated, Some(Violation::Force));
    for bad in [f64::NAN, f64::INFINITY] {
        assert!(jump(&p1, &p2, bad, d, None).is_err());
        assert!(jump(&p1, &p2, h, bad, None).is_err());
    }
}

#[test]
fn near_vertical_jumps_keep_their_heading_force() {
    // See: issue 12 item 3 — |J_h| below J_H_DEGENERATE_MPS is §6.4's degenerate case: the
    // recorded vertical jump is found at β = 1 (it failed with "distance does not determine
    // u_apex" before), and another distance is refused with its reason, not a huge β_h.
    use crate::query::testkit::{jump_model, pool_stance};
    use crate::stances::segment::Boundary;
    let mut rng = Rng::new(0x5eed_0504);
    let mut checked = 0;
    for _ in 0..50 {
        let up = pool_stance(
            "up",
            jump_model(&mut rng, 0.01),
            [0.0, 0.0, -0.1],
            0.9,
            (Boundary::Rest, Boundary::Flight),
            "LR",
            [0.0, 0.0],
        );
        if up.params.t_e < up.params.t_lo {
            continue;
        }
        let q1 = up.params;
        let t_td2 = 0.3;
        let down = pool_stance(
            "down",
            jump_model(&mut rng, -0.01),
            [q1.ve, q1.vp, -GRAVITY * t_td2],
            q1.ze - 0.5 * GRAVITY * t_td2 * t_td2,
            (Boundary::Flight, Boundary::Rest),
            "LR",
            [0.0, 0.0],
        );
        let (p1, p2) = (Prepared::new(up), Prepared::new(down));
        assert!(
            p1.shape.j[0].abs() < J_H_DEGENERATE_MPS && p2.shape.j[0].abs() < J_H_DEGENERATE_MPS
        );
        let (h, d) = recorded_jump(&p1.stance, &p2.stance);
        let j = jump(&p1, &p2, h, d, None).expect("the recorded vertical jump");
        for (_, s) in &j.sides {
            assert!(
                s.solution.beta.iter().all(|b| (b - 1.0).abs() < 1e-6),
                "β {:?}",
                s.solution.beta
            );
        }
        // Farther than the recorded heading force carries: refused with the reason.
        assert_eq!(
            jump(&p1, &p2, h, d + 0.5, None).err(),
            Some(JumpFailure::DistanceFixed)
        );
        checked += 1;
    }
    assert!(checked >= 25, "only {checked} pairs");
}
