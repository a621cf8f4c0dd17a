use std::collections::BTreeMap;

use super::*;
use crate::skeleton::com::Sex;
use crate::skeleton::units::UpAxis;
use crate::synth::{generate, SynthOptions};

#[test]
fn the_law_is_dimensionless_and_grows_with_speed() {
    let leg = 0.9;
    // Independent form: k (v_t − v_s) / √(g L) for the source's own size.
    let by_hand = SWING_FOLD_PER_FROUDE_DEG * (3.0 - 2.0) / (9.81_f64 * leg).sqrt();
    assert!((fold_change_deg(2.0, 3.0, leg) - by_hand).abs() < 1e-12);
    assert!(fold_change_deg(3.0, 2.0, leg) < 0.0);
    // Dynamic similarity: L times the size at √L times the speeds folds the same.
    for l in [0.5_f64, 0.8, 1.3, 2.0] {
        let r = l.sqrt();
        let d = fold_change_deg(2.0 * r, 3.0 * r, leg * l) - fold_change_deg(2.0, 3.0, leg);
        assert!(d.abs() < 1e-12, "L = {l}: {d}");
    }
    for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
        assert_eq!(fold_change_deg(bad, 3.0, leg), 0.0);
        assert_eq!(fold_change_deg(3.0, 3.0, bad), 0.0);
    }
}

#[test]
fn swings_join_one_foots_stances_only() {
    let s = swings([
        ("L", 0.0, 0.25),
        ("R", 0.35, 0.6),
        ("L", 0.7, 0.95),
        ("LR", 1.0, 1.2),
        ("R", 1.05, 1.3),
        ("L", 2.5, 2.7), // 1.55 s after the last left liftoff: not a swing
    ]);
    assert_eq!(
        s,
        vec![
            Swing {
                side: 0,
                lo_s: 0.25,
                td_s: 0.7
            },
            Swing {
                side: 1,
                lo_s: 0.6,
                td_s: 1.05
            },
        ]
    );
}

#[test]
fn a_swing_folds_by_delta_at_its_peak_and_not_at_its_edges() {
    let theta: Vec<f64> = (0..=20)
        .map(|i| 20.0 + 80.0 * (std::f64::consts::PI * i as f64 / 20.0).sin())
        .collect();
    let add = swing_fold(&theta, 12.0);
    assert_eq!(add[0], 0.0);
    assert_eq!(add[20], 0.0);
    assert!((add[10] - 12.0).abs() < 1e-12);
    // Slower: at most FOLD_KEPT of the fold removed; faster: capped at the knee's limit.
    assert!((swing_fold(&theta, -100.0)[10] + FOLD_KEPT * 80.0).abs() < 1e-12);
    assert!((swing_fold(&theta, 100.0)[10] - (MAX_KNEE_FLEXION_DEG - 100.0)).abs() < 1e-12);
    // A swing that hardly folds is left as recorded.
    assert!(swing_fold(&[20.0, 25.0, 21.0], 12.0)
        .iter()
        .all(|&d| d == 0.0));
    assert!(swing_fold(&[], 12.0).is_empty());
}

/// One foot's stances from a per-frame contact truth, as (label, td, lo) in seconds.
fn stances_of(contact: &[bool], label: &'static str, dt: f64) -> Vec<(&'static str, f64, f64)> {
    let mut out = Vec::new();
    let mut start = None;
    for (f, &c) in contact.iter().enumerate() {
        match (c, start) {
            (true, None) => start = Some(f),
            (false, Some(s)) => {
                out.push((label, s as f64 * dt, (f - 1) as f64 * dt));
                start = None;
            }
            _ => {}
        }
    }
    out
}

#[test]
fn folding_a_run_moves_each_swing_peak_by_delta_and_leaves_the_stances() {
    let clip = generate(&SynthOptions::default());
    let bvh = crate::bvh::parse_reader(clip.bvh.as_bytes()).unwrap();
    let body = BodyModel::new(&bvh, 1.0, UpAxis::PosY, Sex::Male, &BTreeMap::new()).unwrap();
    let dt = bvh.motion.frame_time_s;
    let mut st = stances_of(&clip.contact_left, "L", dt);
    st.extend(stances_of(&clip.contact_right, "R", dt));
    let sw = swings(st);
    assert!(sw.len() >= 2, "{sw:?}");
    // The synthetic swing folds to 138°: slower unfolds by the asked 12°, faster stops at
    // the knee's limit.
    for delta in [-12.0, 12.0] {
        check_fold(&body, &bvh.motion, &sw, delta);
    }
    let (same, _) = fold_swing_knees(&body, &bvh.motion, &sw, 0.0);
    assert_eq!(same.values, bvh.motion.values);
}

fn check_fold(body: &BodyModel, motion: &Motion, sw: &[Swing], delta: f64) {
    let (folded, report) = fold_swing_knees(body, motion, sw, delta);
    assert_eq!(report.folded, report.swings);
    assert!(report.swings >= 2);
    let (before, after) = (gauge(body, motion), gauge(body, &folded));
    let dt = motion.frame_time_s;
    let mut in_swing = vec![[false; 2]; before.len()];
    for s in sw {
        let (a, b) = (
            (s.lo_s / dt).round() as usize,
            (s.td_s / dt).round() as usize,
        );
        if b >= before.len() {
            continue;
        }
        for flags in &mut in_swing[a..=b] {
            flags[s.side] = true;
        }
        let peak = |g: &[crate::edit::fidelity::Gauge]| {
            (a..=b)
                .map(|f| g[f].knee_deg[s.side])
                .fold(f64::MIN, f64::max)
        };
        let want = delta.min(MAX_KNEE_FLEXION_DEG - peak(&before));
        let d = peak(&after) - peak(&before);
        assert!(
            (d - want).abs() < 0.2,
            "swing {s:?}: peak moved {d:.3}°, want {want:.3}°"
        );
        // The edges stay the recording's.
        for f in [a, b] {
            let e = after[f].knee_deg[s.side] - before[f].knee_deg[s.side];
            assert!(e.abs() < 1e-6, "swing {s:?} edge {f}: {e}");
        }
    }
    // Nothing else moves: the other leg, the trunk, and every frame outside a swing.
    for (f, flags) in in_swing.iter().enumerate() {
        for (side, &swinging) in flags.iter().enumerate() {
            if !swinging {
                let e = after[f].knee_deg[side] - before[f].knee_deg[side];
                assert!(e.abs() < 1e-9, "frame {f} side {side}: {e}");
            }
        }
        assert!((after[f].lean_deg - before[f].lean_deg).abs() < 1e-9);
    }
}
