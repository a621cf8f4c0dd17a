use super::*;
use crate::force_model::basis::poly_eval;

#[test]
fn bernstein_to_power_is_the_same_polynomial() {
    let b = [0.0, 300.0, 2100.0, 1800.0, 900.0, 40.0, 0.0];
    let p = bernstein_to_power(&b);
    for k in 0..=20 {
        let t = k as f64 / 20.0;
        let want: f64 = bernstein_row(6, t).iter().zip(&b).map(|(x, y)| x * y).sum();
        // Power coefficients stay below 1e5 here: 1e-9 N is ~1e4 ulps of headroom.
        assert!((poly_eval(&p, t) - want).abs() < 1e-9, "τ = {t}");
    }
}

#[test]
fn travel_targets_bind_a_long_stance_more_than_a_short_one() {
    // A heading force with a ripple the linear ratio cannot follow (the misfit the
    // travel row is weighed against), asked to travel 2 cm farther than it does.
    let mut s = bell_samples(64, 70.0);
    for (f, t) in s[0].iter_mut().zip(sample_grid(64)) {
        *f += 40.0 * (7.0 * std::f64::consts::PI * t).sin();
    }
    let opts = RatioOptions::default();
    let moved = |dt: f64| {
        let free = fit_ratio(&s, 20, 70.0, dt, None, &opts).unwrap();
        let (h, p, v) = (
            &free.model.axes[0],
            &free.model.axes[1],
            &free.model.axes[2],
        );
        let own = EdgeTargets {
            impulse: [h.integral(), p.integral(), v.integral()],
            vertical_double: v.f2(1.0),
            travel_double: [h.f2(1.0), p.f2(1.0)],
            position_tolerance_m: None,
        };
        let farther = EdgeTargets {
            travel_double: [h.f2(1.0) + 70.0 * 0.02 / (dt * dt), p.f2(1.0)],
            ..own
        };
        let [a, b] = [own, farther].map(|t| {
            let fit = fit_ratio(&s, 20, 70.0, dt, Some(&t), &opts).unwrap();
            let got = fit.model.axes[0].integral();
            assert!(
                (got - t.impulse[0]).abs() < 1e-6 * t.impulse[2],
                "impulse {got}"
            );
            fit.model.axes[0].f2(1.0)
        });
        // Asked its own travel, the fit keeps it (a row off by a constant would not).
        let kept = (a - h.f2(1.0)) * dt * dt / 70.0;
        assert!(kept.abs() < 1e-5, "Δt {dt}: own travel moved by {kept} m");
        (b - a) * dt * dt / 70.0
    };
    // Travel in metres (Δx = Δt² ∫∫f/m): a 2.4 s stance goes nearly all the way (1.89
    // cm); a 0.25 s running stance, whose travel row weighs 92 times less (w ∝ Δt²),
    // barely moves (0.04 mm).
    let (short, long) = (moved(0.25), moved(2.4));
    eprintln!("asked 0.02 m farther: a 0.25 s stance moves {short:.4} m, a 2.4 s one {long:.4} m");
    assert!(
        long > 0.9 * 0.02 && long < 0.0201,
        "long stance moved {long} m"
    );
    assert!(short.abs() < 1e-4, "short stance moved {short} m");
}

#[test]
fn recovers_a_known_ratio_and_keeps_f_v_non_negative() {
    let s = bell_samples(64, 70.0);
    let quadratic = RatioOptions {
        ratio_degree_h: 2,
        ..Default::default()
    };
    let fit = fit_ratio(&s, 20, 70.0, 0.25, None, &quadratic).unwrap();
    // sin²(πτ) is a degree-∞ function: a degree-8 fit is within 0.2 % of its peak.
    assert!(fit.model.axes[2].fit_rms < 2e-3 * 2.5 * 70.0 * 9.81);
    // The ratio is fitted exactly where f_v is not tiny (the model is f_v·q exactly).
    assert!((fit.ratio[0][0] + 0.4).abs() < 1e-3, "{:?}", fit.ratio[0]);
    assert!((fit.ratio[0][1] - 0.9).abs() < 5e-3, "{:?}", fit.ratio[0]);
    assert!(fit.ratio[0][2].abs() < 5e-3);
    // q_p (quadratic by default) recovers the constant 0.05 to the 0.2 % of the f_v fit;
    // its higher terms vanish.
    assert_eq!(fit.ratio[1].len(), DEFAULT_RATIO_DEGREE_P + 1);
    assert!((fit.ratio[1][0] - 0.05).abs() < 1e-4, "{:?}", fit.ratio[1]);
    assert!(
        fit.ratio[1][1..].iter().all(|r| r.abs() < 1e-4),
        "{:?}",
        fit.ratio[1]
    );
    assert!(fit.bernstein_v.iter().all(|&b| b >= 0.0));
    let g = fit.model.grid();
    assert!(fit.model.min_f_v(&g) >= -1e-6);
    // The force model's ratio is q_h: f_h/f_v at mid-stance.
    let (fh, fv) = (fit.model.axes[0].eval(0.5), fit.model.axes[2].eval(0.5));
    assert!((fh / fv - poly_eval(&fit.ratio[0], 0.5)).abs() < 1e-9);
}

#[test]
fn negative_samples_are_clipped_to_a_non_negative_force() {
    // A pulling dip in the data (kinematic noise at the edges): the model stays ≥ 0.
    let mut s = bell_samples(64, 60.0);
    s[2][..6].fill(-150.0);
    let fit = fit_ratio(&s, 20, 60.0, 0.3, None, &RatioOptions::default()).unwrap();
    assert!(fit.model.min_f_v(&fit.model.grid()) >= -1e-6);
    assert!(fit.model.support_ok());
}

#[test]
fn edge_targets_hold_impulses_and_the_position_exactly() {
    // Ask for 3 % more vertical impulse and a shifted centroid than the samples carry:
    // the constrained fit meets every impulse and the vertical double integral to roundoff.
    let s = bell_samples(64, 70.0);
    let free = fit_ratio(&s, 20, 70.0, 0.25, None, &RatioOptions::default()).unwrap();
    let i = |a: usize| free.model.axes[a].integral();
    let t = EdgeTargets {
        impulse: [i(0) + 30.0, i(1) - 5.0, 1.03 * i(2)],
        vertical_double: 1.01 * free.model.axes[2].f2(1.0),
        travel_double: [free.model.axes[0].f2(1.0), free.model.axes[1].f2(1.0)],
        position_tolerance_m: None,
    };
    let fit = fit_ratio(&s, 20, 70.0, 0.25, Some(&t), &RatioOptions::default()).unwrap();
    assert_eq!(fit.vertical_targets_met, 2);
    for a in 0..3 {
        let got = fit.model.axes[a].integral();
        assert!(
            (got - t.impulse[a]).abs() < 1e-6 * t.impulse[2],
            "axis {a}: {got}"
        );
    }
    // The position in metres (`Δt²/m` times the double integral): to 1e-9 m.
    let miss_m = (fit.model.axes[2].f2(1.0) - t.vertical_double).abs() * 0.25 * 0.25 / 70.0;
    assert!(miss_m < 1e-9, "{miss_m} m");
    assert!(fit.model.min_f_v(&fit.model.grid()) >= -1e-6);
    // Held softly (`position_tolerance_m`), the position row pulls harder as its tolerance
    // shrinks, and the impulses stay exact.
    let miss_m = |tol_m: f64| {
        let soft = EdgeTargets {
            position_tolerance_m: Some(tol_m),
            ..t
        };
        let fit = fit_ratio(&s, 20, 70.0, 0.25, Some(&soft), &RatioOptions::default()).unwrap();
        assert_eq!(fit.vertical_targets_met, 2);
        let got = fit.model.axes[2].integral();
        assert!((got - t.impulse[2]).abs() < 1e-6 * t.impulse[2], "{got}");
        (fit.model.axes[2].f2(1.0) - t.vertical_double).abs() * 0.25 * 0.25 / 70.0
    };
    let (loose, tight) = (miss_m(POSITION_TOLERANCE_M), miss_m(1e-5));
    assert!(
        tight < loose && tight < 1e-4 && loose > 1e-9,
        "{loose} {tight}"
    );
    // An impossible target (negative impulse) falls back without f_v < 0.
    let bad = EdgeTargets {
        impulse: [0.0, 0.0, -100.0],
        vertical_double: -50.0,
        travel_double: [0.0, 0.0],
        position_tolerance_m: None,
    };
    let fit = fit_ratio(&s, 20, 70.0, 0.25, Some(&bad), &RatioOptions::default()).unwrap();
    assert_eq!(fit.vertical_targets_met, 0);
    assert!(fit.model.min_f_v(&fit.model.grid()) >= -1e-6);
}

#[test]
fn degree_follows_the_frames() {
    assert_eq!(vertical_degree(4, 8), 2);
    assert_eq!(vertical_degree(8, 8), 5);
    assert_eq!(vertical_degree(40, 8), 8);
    let bad = RatioOptions {
        vertical_degree: 40,
        ..Default::default()
    };
    assert!(bad.check().is_err());
}
