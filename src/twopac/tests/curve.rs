//! Bezier curves with attractor points (spec §5, eq 7–9).

use super::Rng;
use crate::twopac::bezier::{check_control_points, Bezier, ComState, GUARANTEE_TOL_M};
use crate::twopac::polytope::Polytope;

fn random_state(rng: &mut Rng, s: f64) -> ComState {
    let mut v = || [rng.uniform(-s, s), rng.uniform(-s, s), rng.uniform(-s, s)];
    ComState {
        pos: v(),
        vel: v(),
        acc: v(),
    }
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

#[test]
fn boundary_position_velocity_acceleration_are_exact() {
    // §5.1 with SI derivatives: ċ = c'/T, c̈ = c''/T², at both ends, 0/1/2 attractors.
    let mut rng = Rng::new(11);
    for case in 0..60 {
        let (s, e) = (random_state(&mut rng, 2.0), random_state(&mut rng, 2.0));
        let t = rng.uniform(0.2, 3.0);
        let att: Vec<[f64; 3]> = (0..case % 3)
            .map(|_| {
                [
                    rng.uniform(-1.0, 1.0),
                    rng.uniform(-1.0, 1.0),
                    rng.uniform(0.0, 1.0),
                ]
            })
            .collect();
        let c = Bezier::with_attractors(&s, &e, t, &att).unwrap();
        assert_eq!(c.degree(), 5 + att.len());
        let (s0, s1) = (c.state(0.0, t), c.state(1.0, t));
        // 1e-9: a few round-offs on values of order 10 (T² a / 42 and its inverse).
        for (got, want) in [(s0, s), (s1, e)] {
            assert!(close(got.pos, want.pos, 1e-9), "{case}: {got:?} {want:?}");
            assert!(close(got.vel, want.vel, 1e-9), "{case}: {got:?} {want:?}");
            assert!(close(got.acc, want.acc, 1e-9), "{case}: {got:?} {want:?}");
        }
        for (k, a) in att.iter().enumerate() {
            assert_eq!(c.control[3 + k], *a);
        }
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let mut rng = Rng::new(12);
    let c = Bezier::with_attractors(
        &random_state(&mut rng, 1.0),
        &random_state(&mut rng, 1.0),
        1.3,
        &[[0.3, 0.1, 0.9], [0.5, -0.2, 1.0]],
    )
    .unwrap();
    let h = 1e-5;
    for i in 1..10 {
        let t = i as f64 / 10.0;
        let (p, m) = (c.eval(t + h), c.eval(t - h));
        let fd1 = [0, 1, 2].map(|k| (p[k] - m[k]) / (2.0 * h));
        let (dp, dm) = (c.d1(t + h), c.d1(t - h));
        let fd2 = [0, 1, 2].map(|k| (dp[k] - dm[k]) / (2.0 * h));
        // Central differences: error O(h²·|c'''|) ≈ 1e-10·1e3; round-off 1e-16/h.
        assert!(close(c.d1(t), fd1, 1e-6), "{t}");
        assert!(close(c.d2(t), fd2, 1e-6), "{t}");
    }
}

#[test]
fn left_split_reparametrises_the_same_curve() {
    let mut rng = Rng::new(13);
    let c = Bezier::with_attractors(
        &random_state(&mut rng, 1.0),
        &random_state(&mut rng, 1.0),
        0.8,
        &[[0.0, 0.0, 1.0]],
    )
    .unwrap();
    for u in [0.1, 0.37, 0.9, 1.0] {
        let l = c.left(u);
        for i in 0..=10 {
            let s = i as f64 / 10.0;
            assert!(close(l.eval(s), c.eval(u * s), 1e-12));
        }
    }
}

#[test]
fn control_points_inside_keep_the_whole_curve_inside() {
    // Convex hull property (§5.4): random curves whose control points pass the check never
    // leave the polytope; those that fail report every bad control point.
    let kin = Polytope::new(
        vec![
            [1.0, 0.2, 0.0],
            [-1.0, 0.0, 0.1],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.3],
            [0.0, 0.0, 1.0],
            [0.2, 0.0, -1.0],
        ],
        vec![0.5, 0.5, 0.4, 0.4, 1.0, -0.5],
    );
    let mut rng = Rng::new(14);
    let (mut ok, mut bad) = (0, 0);
    for _ in 0..300 {
        let control: Vec<[f64; 3]> = (0..8)
            .map(|_| {
                [
                    rng.uniform(-0.52, 0.52),
                    rng.uniform(-0.42, 0.42),
                    rng.uniform(0.48, 1.02),
                ]
            })
            .collect();
        let c = Bezier { control };
        let v = check_control_points(&c, &kin);
        let outside: Vec<usize> = (0..8)
            .filter(|&k| kin.max_violation(c.control[k]) > GUARANTEE_TOL_M)
            .collect();
        assert_eq!(v.iter().map(|x| x.index).collect::<Vec<_>>(), outside);
        if v.is_empty() {
            ok += 1;
            for i in 0..=200 {
                assert!(kin.contains(c.eval(i as f64 / 200.0), 1e-12));
            }
        } else {
            bad += 1;
            assert!(v.iter().all(|x| x.violation_m > GUARANTEE_TOL_M));
        }
    }
    assert!(ok > 0 && bad > 0, "{ok} {bad}");
}

#[test]
fn more_than_two_attractors_or_zero_duration_are_errors() {
    let s = ComState::at_rest([0.0; 3]);
    assert!(Bezier::with_attractors(&s, &s, 1.0, &[[0.0; 3]; 3]).is_err());
    assert!(Bezier::with_attractors(&s, &s, 0.0, &[]).is_err());
    assert!(Bezier::with_attractors(&s, &s, f64::NAN, &[]).is_err());
}
