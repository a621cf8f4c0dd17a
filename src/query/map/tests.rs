//! Tests of the jump map: every cell's verdicts equal a direct `jump` solve at the cell's
//! distance, pairs are of one character, and the IoU counts are the cells'.

use super::*;
use crate::query::jump::{jump, recorded_jump, JumpFailure};
use crate::query::testkit::{recorded_pair, Rng};

#[test]
fn cells_agree_with_direct_jump_solves() {
    let mut rng = Rng::new(0x5eed_0601);
    let mut pool = Vec::new();
    for _ in 0..3 {
        let (a, b) = recorded_pair(&mut rng);
        pool.extend([a, b]);
    }
    // One landing of another character: never paired.
    let (_, mut stranger) = recorded_pair(&mut rng);
    stranger.stance.character_id = "sk-other".into();
    pool.push(stranger);
    let (h0, _) = recorded_jump(&pool[0].stance, &pool[1].stance);
    let heights = Axis {
        start: h0 - 0.1,
        stop: h0 + 0.2,
        step: 0.05,
    }
    .values();
    let speeds = Axis {
        start: 0.0,
        stop: 3.0,
        step: 0.25,
    }
    .values();
    let map =
        jump_map(&pool, &heights, &speeds, &stance_relative_limits).expect("within the map limits");
    assert_eq!(
        (map.liftoffs.len(), map.landings.len(), map.pairs.len()),
        (3, 4, 9)
    );
    let n_u = speeds.len();
    let mut seen = [0usize; 2];
    let mut total = Agreement::default();
    for p in &map.pairs {
        for (r, &h) in heights.iter().enumerate() {
            for (q, &u) in speeds.iter().enumerate() {
                let k = r * n_u + q;
                let direct = p.rows[r]
                    .filter(|(d, _, _)| *d > 0.0)
                    .map(|(d, c, _)| jump(&pool[p.liftoff], &pool[p.landing], h, u * d + c, None));
                let (a, e) = match direct {
                    Some(Ok(j)) => {
                        assert!((j.u_apex - u).abs() < 1e-9, "u_apex {} vs {u}", j.u_apex);
                        (j.feasible_approx(), j.feasible())
                    }
                    Some(Err(JumpFailure::Rule(_))) | None => (false, false),
                    Some(Err(f)) => panic!("cell ({h}, {u}): {f}"),
                };
                assert_eq!((p.approx[k], p.exact[k]), (a, e), "pair cell ({h}, {u})");
                seen[usize::from(e)] += 1;
                total.approx += usize::from(a);
                total.exact += usize::from(e);
                total.both += usize::from(a && e);
                total.either += usize::from(a || e);
            }
        }
    }
    assert!(seen[0] > 0 && seen[1] > 0, "both verdicts occur: {seen:?}");
    assert_eq!(total, map.agreement);
    let pair_sum: usize = map.pairs.iter().map(|p| p.agreement.both).sum();
    assert_eq!(pair_sum, map.agreement.both);
    assert!((0.0..=1.0).contains(&map.agreement.iou()));
}

#[test]
fn axis_values_are_inclusive_and_reject_bad_steps() {
    let a = Axis {
        start: 0.6,
        stop: 1.6,
        step: 0.02,
    }
    .values();
    assert_eq!(a.len(), 51);
    assert!((a[50] - 1.6).abs() < 1e-12);
    assert_eq!(
        Axis {
            start: 0.0,
            stop: 5.0,
            step: 0.05
        }
        .values()
        .len(),
        101
    );
    assert!(Axis {
        start: 0.0,
        stop: 1.0,
        step: 0.0
    }
    .values()
    .is_empty());
    assert!(Axis {
        start: 1.0,
        stop: 0.0,
        step: 0.1
    }
    .values()
    .is_empty());
    assert!(Axis {
        start: f64::NAN,
        stop: 1.0,
        step: 0.1
    }
    .values()
    .is_empty());
    assert_eq!(Agreement::default().iou(), 1.0);
}

// See: issue 11 item 6 — ranges parsed by hand: step ≤ 0, NaN, ∞ and a count beyond
// MAX_AXIS_VALUES are refused before any allocation.
#[test]
fn axis_parse_refuses_bad_and_huge_ranges() {
    use crate::error::ErrorKind;
    let a = Axis::parse("--x", "0:1:0.25").unwrap();
    assert_eq!(a.values(), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
    for bad in [
        "0:1:0",
        "0:1:-1",
        "nan:1:0.1",
        "0:inf:0.1",
        "1:0:0.1",
        "0:1",
        "a:b:c",
    ] {
        let e = Axis::parse("--x", bad).unwrap_err();
        assert!(matches!(e.kind, ErrorKind::Invalid { .. }), "{bad}: {e}");
        assert!(e.to_string().starts_with("--x: "), "{e}");
    }
    let e = Axis::parse("--x", "0:1e9:0.001").unwrap_err();
    assert!(
        matches!(
            e.kind,
            ErrorKind::Cap {
                max: MAX_AXIS_VALUES,
                ..
            }
        ),
        "{e}"
    );
    // Exactly MAX_AXIS_VALUES values pass; one more does not.
    let n = MAX_AXIS_VALUES as f64;
    assert_eq!(
        Axis::parse("--x", &format!("1:{n}:1")).unwrap().len(),
        MAX_AXIS_VALUES
    );
    assert!(Axis::parse("--x", &format!("0:{n}:1")).is_err());
    // An over-long axis built by hand never yields more than the limit + 1 values.
    let huge = Axis {
        start: 0.0,
        stop: 1e12,
        step: 1.0,
    };
    assert_eq!(huge.values().len(), MAX_AXIS_VALUES + 1);
    assert!(check_grid("g", 1000, 1000).is_ok());
    assert!(check_grid("g", 1001, 1000).is_err());
}

#[test]
fn default_grid_arguments_parse_to_the_default_axes() {
    assert_eq!(
        Axis::parse("--heights", DEFAULT_HEIGHTS_ARG).unwrap(),
        DEFAULT_HEIGHTS
    );
    assert_eq!(
        Axis::parse("--speeds", DEFAULT_SPEEDS_ARG).unwrap(),
        DEFAULT_SPEEDS
    );
}
