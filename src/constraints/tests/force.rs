//! Eq 9–12 coefficients against brute force, and conservativeness of eq 10 and eq 12.

use super::{force_at, random_model, random_model_with, Rng};
use crate::constraints::{
    force_coefficients, force_filter_accepts, friction_filter_accepts, precompute, SampledGrids,
    StanceContext, ACTIVE_FRACTION,
};
use crate::force_model::{AxisModel, ForceModel};

#[test]
fn tables_match_the_models_evaluators() {
    for halves in [false, true] {
        let mut rng = Rng::new(1);
        for _ in 0..50 {
            let model = random_model_with(&mut rng, halves);
            let grids = SampledGrids::new(&model);
            assert_eq!(grids.tau, model.grid());
            for axis in 0..3 {
                let f_scale = grids.f[axis].iter().fold(1.0f64, |m, v| m.max(v.abs()));
                let s_scale = grids.s[axis].iter().fold(1e-6f64, |m, v| m.max(v.abs()));
                for (k, &t) in grids.tau.iter().enumerate() {
                    // Unit-circle table vs direct cos of 2πjτ + φ: a few ulps of the scale.
                    let ef = (grids.f[axis][k] - model.axes[axis].eval(t)).abs();
                    let es = (grids.s[axis][k] - model.s(axis, t)).abs();
                    assert!(ef <= 1e-12 * f_scale, "f axis {axis} k {k}: {ef}");
                    assert!(es <= 1e-12 * s_scale, "S axis {axis} k {k}: {es}");
                }
            }
        }
    }
}

#[test]
fn coefficients_match_brute_force_on_the_grid() {
    let mut rng = Rng::new(2);
    for _ in 0..50 {
        let model = random_model(&mut rng);
        let c = precompute(&model, &StanceContext::default());
        let grid = model.grid();
        let f: Vec<[f64; 3]> = grid.iter().map(|&t| force_at(&model, t)).collect();
        let max_fv = f.iter().map(|x| x[2]).fold(f64::NEG_INFINITY, f64::max);
        let act: Vec<&[f64; 3]> = f
            .iter()
            .filter(|x| x[2] >= ACTIVE_FRACTION * max_fv)
            .collect();
        let max_of = |it: &mut dyn Iterator<Item = f64>| it.fold(f64::NEG_INFINITY, f64::max);
        let a_f = [0, 1, 2].map(|a| max_of(&mut f.iter().map(|x| x[a] * x[a])));
        let a_mu = [0, 1].map(|a| max_of(&mut act.iter().map(|x| (x[a] / x[2]).powi(2))));
        let mu_req = max_of(&mut act.iter().map(|x| x[0].hypot(x[1]) / x[2]));
        let f_peak = max_of(
            &mut f
                .iter()
                .map(|x| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()),
        );
        // Tables agree with eval to ~1e-13 relative; the maxima inherit that.
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-11 * b.abs().max(1.0);
        for a in 0..3 {
            assert!(
                close(c.a_f[a], a_f[a]),
                "a_f[{a}] {} vs {}",
                c.a_f[a],
                a_f[a]
            );
        }
        for a in 0..2 {
            assert!(
                close(c.a_mu[a], a_mu[a]),
                "a_mu[{a}] {} vs {}",
                c.a_mu[a],
                a_mu[a]
            );
        }
        assert!(close(c.mu_req, mu_req));
        assert!(close(c.f_peak, f_peak));
        assert!(close(c.min_f_v, model.min_f_v(&grid)));
        assert_eq!(c.unilateral_ok, model.unilateral_ok(&grid));
        assert_eq!(c.support_ok, model.support_ok());
    }
}

/// Exact eq 6 on the grid: `max_k Σ_a β_a² f_a(τ_k)²`, N².
fn exact_force_sq(f: &[[f64; 3]], beta: [f64; 3]) -> f64 {
    f.iter()
        .map(|x| (0..3).map(|a| (beta[a] * x[a]).powi(2)).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Exact eq 7 on T_act: `max (β_h² f_h² + β_p² f_p²)/(β_v² f_v²)` (the μ² it needs).
fn exact_friction_sq(f: &[[f64; 3]], beta: [f64; 3]) -> f64 {
    let max_fv = f.iter().map(|x| x[2]).fold(f64::NEG_INFINITY, f64::max);
    f.iter()
        .filter(|x| x[2] >= ACTIVE_FRACTION * max_fv)
        .map(|x| ((beta[0] * x[0]).powi(2) + (beta[1] * x[1]).powi(2)) / (beta[2] * x[2]).powi(2))
        .fold(0.0, f64::max)
}

#[test]
fn force_and_friction_filters_are_conservative() {
    let mut rng = Rng::new(3);
    let (mut force_accepts, mut friction_accepts) = (0, 0);
    for _ in 0..20 {
        let model = random_model(&mut rng);
        let c = precompute(&model, &StanceContext::default());
        let f: Vec<[f64; 3]> = model.grid().iter().map(|&t| force_at(&model, t)).collect();
        for _ in 0..2000 {
            let beta = [0; 3].map(|_| rng.uniform(0.0, 3.0));
            // Limits straddle the exact value so both verdicts occur.
            let exact_f = exact_force_sq(&f, beta);
            let f_max = (exact_f * rng.uniform(0.8, 1.6)).sqrt();
            if force_filter_accepts(&c.a_f, beta, f_max) {
                force_accepts += 1;
                assert!(exact_f <= f_max * f_max, "eq 10 accepted an eq 6 violation");
            }
            let exact_mu = exact_friction_sq(&f, beta);
            let mu = (exact_mu * rng.uniform(0.8, 2.5)).sqrt();
            if friction_filter_accepts(&c.a_mu, beta, mu) {
                friction_accepts += 1;
                assert!(exact_mu <= mu * mu, "eq 12 accepted an eq 7 violation");
            }
        }
    }
    assert!(
        force_accepts > 1000 && friction_accepts > 1000,
        "{force_accepts} {friction_accepts}"
    );
}

#[test]
fn a_stance_without_load_needs_infinite_friction() {
    let axis = |c0: f64| AxisModel {
        c0,
        harmonics: vec![2.0],
        amps: vec![10.0],
        phases: vec![0.3],
        poly: Vec::new(),
        fit_rms: 0.0,
    };
    let model = ForceModel {
        mass_kg: 70.0,
        dt_s: 0.2,
        axes: [axis(50.0), axis(0.0), axis(-100.0)],
    };
    let c = force_coefficients(&SampledGrids::new(&model));
    assert!(!c.unilateral_ok);
    assert_eq!(c.a_mu, [f64::INFINITY; 2]);
    assert_eq!(c.mu_req, f64::INFINITY);
    assert!(!friction_filter_accepts(&c.a_mu, [1.0, 0.0, 1.0], 10.0));
    assert!(!friction_filter_accepts(&c.a_mu, [0.0, 0.0, 1.0], 10.0));
}
