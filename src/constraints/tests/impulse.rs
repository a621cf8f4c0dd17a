//! `H` and `H_0` against Simpson quadrature, the affine form of §8.2, degenerate inputs.

use super::{force_at, random_context, random_model, random_model_with, Rng};
use crate::constraints::impulse::cross;
use crate::constraints::impulse::moment_integral;
use crate::constraints::{
    angular_impulse, com_offset, contact_point_matrix, linear_impulse, precompute, StanceContext,
};
use crate::force_model::{AxisModel, ForceModel};

/// `(H, scale)` by composite Simpson on τ with `intervals` (even) intervals:
/// `H = Δt ∫₀¹ (x_cp − r(τ)) × f(τ) dτ`, `scale = Δt ∫₀¹ |x_cp − r| |f| dτ` (N·m·s).
fn h_simpson(model: &ForceModel, ctx: &StanceContext, intervals: usize) -> ([f64; 3], f64) {
    let x_cp = [ctx.cp[0], ctx.cp[1], -ctx.z_td];
    let (mut h, mut scale) = ([0.0; 3], 0.0);
    for i in 0..=intervals {
        let tau = i as f64 / intervals as f64;
        let w = if i == 0 || i == intervals {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let r = com_offset(model, ctx, [1.0; 3], tau);
        let arm = [0, 1, 2].map(|a| x_cp[a] - r[a]);
        let f = force_at(model, tau);
        let m = cross(arm, f);
        for a in 0..3 {
            h[a] += w * m[a];
        }
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        scale += w * norm(arm) * norm(f);
    }
    let k = model.dt_s / (3.0 * intervals as f64);
    (h.map(|x| k * x), k * scale)
}

#[test]
fn h_matches_simpson_quadrature() {
    for halves in [false, true] {
        let mut rng = Rng::new(20);
        for _ in 0..100 {
            let model = random_model_with(&mut rng, halves);
            let ctx = random_context(&mut rng);
            let (h, _) = angular_impulse(&model, &ctx);
            let (h_ref, scale) = h_simpson(&model, &ctx, 2048);
            for a in 0..3 {
                // Simpson with 2048 intervals on j ≤ 6: error ~1e-11 of the integrand's scale.
                assert!(
                    (h[a] - h_ref[a]).abs() <= 1e-8 * scale,
                    "axis {a}: {} vs {}",
                    h[a],
                    h_ref[a]
                );
            }
        }
    }
}

#[test]
fn h_is_affine_in_the_contact_point() {
    let mut rng = Rng::new(21);
    for _ in 0..50 {
        let model = random_model(&mut rng);
        let ctx0 = random_context(&mut rng);
        let (h_at_0, h0_at_0) = angular_impulse(
            &model,
            &StanceContext {
                cp: [0.0; 2],
                ..ctx0
            },
        );
        let a_mat = contact_point_matrix(linear_impulse(&model));
        let u = [rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)];
        let (h, h0) = angular_impulse(&model, &StanceContext { cp: u, ..ctx0 });
        assert_eq!(h0, h0_at_0, "H_0 does not depend on the contact point");
        let scale = h_at_0.iter().chain(&h).fold(1.0f64, |m, v| m.max(v.abs()));
        for row in 0..3 {
            let predicted = a_mat[row][0] * u[0] + a_mat[row][1] * u[1] + h_at_0[row];
            // One product and one sum of O(scale) terms: a few ulps.
            assert!((h[row] - predicted).abs() <= 1e-12 * scale, "row {row}");
        }
    }
}

#[test]
fn precompute_stores_h_and_h0() {
    let mut rng = Rng::new(22);
    let model = random_model(&mut rng);
    let ctx = random_context(&mut rng);
    let c = precompute(&model, &ctx);
    let (h, h0) = angular_impulse(&model, &ctx);
    assert_eq!((c.ang_impulse, c.ang_impulse_h0), (h, h0));
}

#[test]
fn degenerate_models_do_not_panic() {
    let axis = |harmonics: Vec<f64>, amps: Vec<f64>, phases: Vec<f64>| AxisModel {
        c0: 1.0,
        harmonics,
        amps,
        phases,
        poly: Vec::new(),
        fit_rms: 0.0,
    };
    let cases = [
        (70.0, 0.2, axis(vec![], vec![], vec![])),
        (
            70.0,
            0.2,
            axis(
                vec![0.0, 1.0, 1.0],
                vec![2.0, 3.0, 1.0],
                vec![0.1, 0.2, 0.3],
            ),
        ),
        (
            70.0,
            0.2,
            axis(vec![1.0, 2.0], vec![1.0], vec![0.0, 0.0, 0.0]),
        ),
        (0.0, 0.2, axis(vec![1.0], vec![1.0], vec![0.0])),
        (70.0, 0.0, axis(vec![1.0], vec![1.0], vec![0.0])),
        (
            f64::NAN,
            f64::INFINITY,
            axis(vec![3.0], vec![f64::NAN], vec![f64::INFINITY]),
        ),
    ];
    for (i, (mass_kg, dt_s, ax)) in cases.into_iter().enumerate() {
        let model = ForceModel {
            mass_kg,
            dt_s,
            axes: [ax.clone(), ax.clone(), ax],
        };
        let ctx = StanceContext {
            vs: f64::NAN,
            ..StanceContext::default()
        };
        let c = precompute(&model, &ctx);
        let r = com_offset(&model, &ctx, [1.0; 3], 0.5);
        let (h, _) = angular_impulse(&model, &ctx);
        // precompute stores angular_impulse's H, degenerate or not (NaN bits included).
        assert_eq!(
            c.ang_impulse.map(f64::to_bits),
            h.map(f64::to_bits),
            "case {i}"
        );
        // The NaN start speed reaches the offset `vs·Δt·τ + …`: never a finite value.
        assert!(r[0].is_nan(), "case {i}: offset {r:?}");
        // Without a positive vertical impulse (Δt = 0, or NaN inputs) no support.
        if i >= 4 {
            assert!(!c.support_ok, "case {i}: supported");
        }
        // A NaN force model never passes the unilateral check, and its force limit
        // coefficients stay NaN (f64::max would drop the NaN and report A^F = 0, F_peak = 0).
        if i == 5 {
            assert!(!c.unilateral_ok, "case {i}: unilateral");
            assert!(
                c.a_f.iter().all(|a| a.is_nan()),
                "case {i}: A^F {:?}",
                c.a_f
            );
            assert!(c.f_peak.is_nan(), "case {i}: F_peak {}", c.f_peak);
        }
    }
    // Case 0 is the constant force 1 N on every axis: its coefficients in closed form.
    let constant = ForceModel {
        mass_kg: 70.0,
        dt_s: 0.2,
        axes: std::array::from_fn(|_| axis(vec![], vec![], vec![])),
    };
    let c = precompute(&constant, &StanceContext::default());
    assert_eq!(c.a_f, [1.0; 3]);
    assert_eq!(c.min_f_v, 1.0);
    assert!((c.f_peak - 3f64.sqrt()).abs() < 1e-15, "{}", c.f_peak);
    assert!((c.mu_req - 2f64.sqrt()).abs() < 1e-15, "{}", c.mu_req);
    assert!(c.support_ok && c.unilateral_ok);
}

#[test]
fn j_zero_terms_and_repeated_harmonics_match_simpson() {
    let ax = |c0: f64| AxisModel {
        c0,
        harmonics: vec![0.0, 2.0, 2.0, 5.0],
        amps: vec![40.0, 120.0, 60.0, 30.0],
        phases: vec![0.7, -1.1, 2.0, 0.4],
        poly: Vec::new(),
        fit_rms: 0.0,
    };
    let model = ForceModel {
        mass_kg: 65.0,
        dt_s: 0.3,
        axes: [ax(80.0), ax(-20.0), ax(900.0)],
    };
    let ctx = StanceContext {
        vs: 2.0,
        vps: 0.3,
        t_td: 0.12,
        z_td: 0.95,
        cp: [0.15, -0.05],
    };
    let (h, _) = angular_impulse(&model, &ctx);
    let (h_ref, scale) = h_simpson(&model, &ctx, 2048);
    for a in 0..3 {
        // As above: Simpson's error is ~1e-11 of the scale.
        assert!(
            (h[a] - h_ref[a]).abs() <= 1e-8 * scale,
            "axis {a}: {} vs {}",
            h[a],
            h_ref[a]
        );
    }
}

#[test]
fn every_moment_integral_matches_simpson() {
    for halves in [false, true] {
        let mut rng = Rng::new(23);
        let n = 2048;
        for _ in 0..20 {
            let model = random_model_with(&mut rng, halves);
            let ctx = random_context(&mut rng);
            for a in 0..3 {
                for b in 0..3 {
                    let (mut q, mut scale) = (0.0, 0.0);
                    for i in 0..=n {
                        let tau = i as f64 / n as f64;
                        let w = match i {
                            0 => 1.0,
                            _ if i == n => 1.0,
                            _ if i % 2 == 1 => 4.0,
                            _ => 2.0,
                        };
                        let r = com_offset(&model, &ctx, [1.0; 3], tau)[a];
                        let f = model.axes[b].eval(tau);
                        q += w * r * f;
                        scale += w * (r * f).abs();
                    }
                    let (q, scale) = (q / (3.0 * n as f64), scale / (3.0 * n as f64));
                    let exact = moment_integral(&model, &ctx, a, b);
                    // Simpson with 2048 intervals on j ≤ 6 (products up to j = 12): ~1e-10 of scale.
                    assert!(
                        (exact - q).abs() <= 1e-8 * scale,
                        "∫ r_{a} f_{b}: {exact} vs {q}"
                    );
                }
            }
        }
    }
}
