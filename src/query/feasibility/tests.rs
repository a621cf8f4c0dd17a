//! Tests of the feasibility check: filter conservativeness, the identity query, the
//! unilateral flag, the contact point against a brute-force search, dynamic similarity.

use super::*;
use crate::constraints::{com_offset, precompute};
use crate::force_model::AxisModel;
use crate::query::testkit::{bell_model as random_model, Rng};
use std::f64::consts::PI;

/// A running-like context.
fn random_context(rng: &mut Rng) -> QueryContext {
    QueryContext {
        vs: rng.uniform(0.0, 6.0),
        vps: rng.uniform(-0.5, 0.5),
        t_td: rng.uniform(0.05, 0.4),
        z_td: rng.uniform(0.8, 1.1),
        cp: [rng.uniform(-0.3, 0.5), rng.uniform(-0.2, 0.2)],
    }
}

fn beta_in(rng: &mut Rng, lo: f64, hi: f64) -> [f64; 3] {
    [0; 3].map(|_| rng.uniform(lo, hi))
}

/// `|x − y| ≤ tol · max(1, |y|)`.
fn close(x: f64, y: f64, tol: f64) -> bool {
    (x - y).abs() <= tol * y.abs().max(1.0)
}

#[test]
fn approx_never_accepts_what_exact_rejects() {
    let mut rng = Rng::new(7);
    let (mut accepted, mut conservative_rejects) = (0, 0);
    for _ in 0..30 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let grids = SampledGrids::new(&model);
        let coef = precompute(&model, &ctx);
        let base = relative_limits(&coef);
        for _ in 0..100 {
            let lim = Limits {
                mu: base.mu * rng.uniform(0.5, 2.0),
                f_max: base.f_max * rng.uniform(0.5, 3.0),
                ..base
            };
            let beta = beta_in(&mut rng, 0.0, 3.0);
            let v = exact(&grids, &model, &ctx, beta, &lim);
            let exact_ok = v.f_peak <= lim.f_max && v.mu_req <= lim.mu;
            if approx(coef.a_f, coef.a_mu, beta, &lim) {
                accepted += 1;
                assert!(exact_ok, "false accept at β = {beta:?}: {v:?} vs {lim:?}");
            } else if exact_ok {
                conservative_rejects += 1;
            }
        }
    }
    // Both outcomes occur, so the test exercises the filters.
    assert!(accepted > 100, "only {accepted} accepts");
    assert!(conservative_rejects > 0);
}

#[test]
fn approx_rejects_negative_beta_and_limits() {
    let (a_f, a_mu) = ([1.0; 3], [0.01; 2]);
    let lim = Limits {
        mu: 1.0,
        f_max: 10.0,
        chi_min: 0.0,
        chi_max: 1.0,
    };
    assert!(approx(a_f, a_mu, [1.0; 3], &lim));
    assert!(!approx(a_f, a_mu, [-0.1, 1.0, 1.0], &lim));
    assert!(!approx(a_f, a_mu, [f64::NAN, 1.0, 1.0], &lim));
    // F_max = −10 would pass Σ A^F β² ≤ F_max² but exact's F_peak ≤ F_max cannot hold.
    assert!(!approx(
        a_f,
        a_mu,
        [1.0; 3],
        &Limits {
            f_max: -10.0,
            ..lim
        }
    ));
    assert!(!approx(a_f, a_mu, [1.0; 3], &Limits { mu: -1.0, ..lim }));
}

#[test]
fn identity_query_is_feasible_and_reports_original_extremes() {
    let mut rng = Rng::new(11);
    let mut n_ok = 0;
    for _ in 0..40 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let grids = SampledGrids::new(&model);
        let coef = precompute(&model, &ctx);
        let v = exact(&grids, &model, &ctx, [1.0; 3], &relative_limits(&coef));
        // Same grids and the same operation order as precompute: 1e-9 relative is loose.
        assert!(close(v.f_peak, coef.f_peak, 1e-9), "{v:?} {coef:?}");
        assert!(close(v.mu_req, coef.mu_req, 1e-9));
        assert!(close(v.ext_min, coef.ext_min, 1e-9));
        assert!(close(v.ext_max, coef.ext_max, 1e-9));
        if coef.unilateral_ok {
            n_ok += 1;
            assert!(v.feasible, "{v:?}");
            // Limits exactly at the extremes (margin 1): still feasible, every test is ≤.
            let tight = Limits {
                mu: coef.mu_req,
                f_max: coef.f_peak,
                chi_min: coef.ext_min,
                chi_max: coef.ext_max,
            };
            assert!(exact(&grids, &model, &ctx, [1.0; 3], &tight).feasible);
        } else {
            assert_eq!(v.violated, Some(Violation::Unilateral));
        }
    }
    assert!(n_ok >= 30, "only {n_ok} unilateral stances");
}

#[test]
fn pulling_dip_is_infeasible_for_every_beta() {
    let (m, w) = (70.0, 70.0 * GRAVITY);
    // f_v = w(1 − cos 2πτ) + 0.5w cos 8πτ: −0.21w at τ = 1/8, below −0.05 · max f_v.
    let v = AxisModel {
        c0: w,
        harmonics: vec![1.0, 4.0],
        amps: vec![w, 0.5 * w],
        phases: vec![PI, 0.0],
        poly: Vec::new(),
        fit_rms: 0.0,
    };
    let h = AxisModel {
        c0: 0.0,
        harmonics: vec![1.0],
        amps: vec![0.2 * w],
        phases: vec![0.0],
        poly: Vec::new(),
        fit_rms: 0.0,
    };
    let model = ForceModel {
        mass_kg: m,
        dt_s: 0.3,
        axes: [h, AxisModel::constant(0.0), v],
    };
    let ctx = QueryContext {
        vs: 3.0,
        vps: 0.0,
        t_td: 0.1,
        z_td: 0.95,
        cp: [0.2, 0.0],
    };
    let coef = precompute(&model, &ctx);
    assert!(!coef.unilateral_ok);
    let grids = SampledGrids::new(&model);
    let generous = Limits {
        mu: 1e12,
        f_max: 1e12,
        chi_min: 0.0,
        chi_max: 1e12,
    };
    let mut rng = Rng::new(3);
    let mut betas = vec![[0.0; 3], [1.0; 3], [0.0, 0.0, 1.0], [3.0, 0.0, 0.0]];
    betas.extend((0..500).map(|_| beta_in(&mut rng, 0.0, 3.0)));
    for beta in betas {
        let v = exact(&grids, &model, &ctx, beta, &generous);
        assert!(!v.feasible, "β = {beta:?}");
        if beta.iter().all(|&b| b > 0.0) {
            assert_eq!(v.violated, Some(Violation::Unilateral));
        }
    }
}

#[test]
fn exact_never_panics_on_bad_input() {
    let lim = Limits {
        mu: 1.0,
        f_max: 1e4,
        chi_min: 0.0,
        chi_max: 2.0,
    };
    let ctx = QueryContext::default();
    let empty = exact(
        &SampledGrids::default(),
        &ForceModel::default(),
        &ctx,
        [1.0; 3],
        &lim,
    );
    assert_eq!(empty.violated, Some(Violation::Friction));
    let mut rng = Rng::new(5);
    let model = random_model(&mut rng);
    let grids = SampledGrids::new(&model);
    let nan = exact(&grids, &model, &ctx, [f64::NAN, 1.0, 1.0], &lim);
    assert_eq!(nan.violated, Some(Violation::Beta));
    let nan_lim = Limits {
        mu: f64::NAN,
        ..lim
    };
    assert!(!exact(&grids, &model, &ctx, [1.0; 3], &nan_lim).feasible);
    let bad = ForceModel {
        mass_kg: f64::NAN,
        ..model.clone()
    };
    assert!(!exact(&SampledGrids::new(&bad), &bad, &ctx, [1.0; 3], &lim).feasible);
    assert!(contact_point(&bad, [1.0; 3], &ctx, [0.0; 3]).is_none());
    // No vertical impulse: u* is undetermined.
    assert!(contact_point(&model, [1.0, 1.0, 0.0], &ctx, [0.0; 3]).is_none());
}

/// `(I, H_0)` of the scaled stance by composite Simpson on τ (2048 intervals), N·s, N·m·s.
fn simpson_impulses(model: &ForceModel, ctx: &QueryContext, beta: [f64; 3]) -> [[f64; 3]; 2] {
    let n = 2048;
    let (mut imp, mut h0) = ([0.0; 3], [0.0; 3]);
    for k in 0..=n {
        let tau = k as f64 / n as f64;
        let w = if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        } * model.dt_s
            / (3.0 * n as f64);
        let f = [0, 1, 2].map(|a| beta[a] * model.axes[a].eval(tau));
        let r = com_offset(model, ctx, beta, tau);
        let rxf = [
            r[1] * f[2] - r[2] * f[1],
            r[2] * f[0] - r[0] * f[2],
            r[0] * f[1] - r[1] * f[0],
        ];
        for a in 0..3 {
            imp[a] += w * f[a];
            h0[a] += w * rxf[a];
        }
    }
    [imp, h0]
}

/// `|H(u) − H_des|` with `H = x_cp × I − H_0` from the quadrature, N·m·s.
fn residual(u: [f64; 2], z_td: f64, ih: &[[f64; 3]; 2], h_des: [f64; 3]) -> f64 {
    let ([i, h0], x) = (ih, [u[0], u[1], -z_td]);
    let h = [
        x[1] * i[2] - x[2] * i[1] - h0[0],
        x[2] * i[0] - x[0] * i[2] - h0[1],
        x[0] * i[1] - x[1] * i[0] - h0[2],
    ];
    (0..3)
        .map(|a| (h[a] - h_des[a]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Grid over `[−3, 3]²` (step 0.05 m), then compass search halving the step to 1e-11 m.
fn brute_force_cp(z_td: f64, ih: &[[f64; 3]; 2], h_des: [f64; 3]) -> [f64; 2] {
    let f = |u: [f64; 2]| residual(u, z_td, ih, h_des);
    let mut best = [0.0, 0.0];
    for i in -60..=60 {
        for j in -60..=60 {
            let u = [0.05 * f64::from(i), 0.05 * f64::from(j)];
            if f(u) < f(best) {
                best = u;
            }
        }
    }
    let mut step = 0.05;
    while step > 1e-11 {
        let moves = [[step, 0.0], [-step, 0.0], [0.0, step], [0.0, -step]];
        let next = moves
            .iter()
            .map(|d| [best[0] + d[0], best[1] + d[1]])
            .find(|&u| f(u) < f(best));
        match next {
            Some(u) => best = u,
            None => step *= 0.5,
        }
    }
    best
}

#[test]
fn contact_point_identity_and_brute_force() {
    let mut rng = Rng::new(23);
    for case in 0..12 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let coef = precompute(&model, &ctx);
        // Identity (§8.3): closed forms on both sides, so 1e-9 m is round-off headroom.
        let u = contact_point(&model, [1.0; 3], &ctx, coef.ang_impulse).unwrap();
        assert!((u[0] - ctx.cp[0]).abs() < 1e-9 && (u[1] - ctx.cp[1]).abs() < 1e-9);

        let beta = if case == 0 {
            [1.0; 3]
        } else {
            beta_in(&mut rng, 0.5, 2.0)
        };
        let u = contact_point(&model, beta, &ctx, coef.ang_impulse).unwrap();
        let ih = simpson_impulses(&model, &ctx, beta);
        let brute = brute_force_cp(ctx.z_td, &ih, coef.ang_impulse);
        // Simpson (relative error ≲ 1e-8) and the 1e-11 m search step stay far below 1e-5 m.
        assert!(
            (u[0] - brute[0]).abs() < 1e-5 && (u[1] - brute[1]).abs() < 1e-5,
            "β = {beta:?}: closed form {u:?} vs brute force {brute:?}"
        );
        // The affine form matches the quadrature at the solution.
        let (a, b) = impulse_affine(&ImpulseMoments::new(&model), beta, &ctx);
        let h = [0, 1, 2].map(|k| a[k][0] * u[0] + a[k][1] * u[1] + b[k]);
        let r_closed = (0..3)
            .map(|k| (h[k] - coef.ang_impulse[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let r_quad = residual(u, ctx.z_td, &ih, coef.ang_impulse);
        // |H| ~ 10–100 N·m·s; Simpson's 1e-8 relative error bounds the gap.
        assert!((r_closed - r_quad).abs() < 1e-5, "{r_closed} vs {r_quad}");
    }
}

/// The model of a character `L` times as long and `M` times as heavy (§9).
fn scale_model(model: &ForceModel, l: f64, m: f64) -> ForceModel {
    let mut out = model.clone();
    out.mass_kg *= m;
    out.dt_s *= l.sqrt();
    for axis in &mut out.axes {
        axis.c0 *= m;
        axis.amps.iter_mut().for_each(|c| *c *= m);
    }
    out
}

#[test]
fn verdicts_are_invariant_under_dynamic_similarity() {
    let mut rng = Rng::new(31);
    let (mut feasible, mut infeasible) = (0, 0);
    for _ in 0..40 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let coef = precompute(&model, &ctx);
        let base = relative_limits(&coef);
        let (l, m) = (rng.uniform(0.5, 2.0), rng.uniform(0.3, 4.0));
        let (sl, s_model) = (l.sqrt(), scale_model(&model, l, m));
        let s_ctx = QueryContext {
            vs: ctx.vs * sl,
            vps: ctx.vps * sl,
            t_td: ctx.t_td * sl,
            z_td: ctx.z_td * l,
            cp: ctx.cp.map(|c| c * l),
        };
        let (grids, s_grids) = (SampledGrids::new(&model), SampledGrids::new(&s_model));
        let h_des = coef.ang_impulse;
        let s_h_des = h_des.map(|h| h * m * l.powf(1.5));
        for _ in 0..25 {
            let beta = beta_in(&mut rng, 0.5, 1.6);
            let lim = Limits {
                mu: base.mu * rng.uniform(0.8, 1.5),
                f_max: base.f_max * rng.uniform(0.8, 1.5),
                chi_min: base.chi_min * rng.uniform(0.7, 1.2),
                chi_max: base.chi_max * rng.uniform(0.9, 1.2),
            };
            let s_lim = Limits {
                mu: lim.mu,
                f_max: lim.f_max * m,
                chi_min: lim.chi_min * l,
                chi_max: lim.chi_max * l,
            };
            let v = exact(&grids, &model, &ctx, beta, &lim);
            let s = exact(&s_grids, &s_model, &s_ctx, beta, &s_lim);
            assert_eq!(v.violated, s.violated, "{v:?} vs {s:?}");
            // Same grid, scaled inputs: only round-off differs (1e-9 relative is loose).
            assert!(close(s.f_peak, v.f_peak * m, 1e-9));
            assert!(close(s.mu_req, v.mu_req, 1e-9));
            assert!(close(s.ext_min, v.ext_min * l, 1e-9));
            assert!(close(s.ext_max, v.ext_max * l, 1e-9));
            assert_eq!(
                approx(coef.a_f, coef.a_mu, beta, &lim),
                approx(coef.a_f.map(|a| a * m * m), coef.a_mu, beta, &s_lim)
            );
            if v.feasible {
                feasible += 1;
            } else {
                infeasible += 1;
            }
            // The contact point scales with L (§9: "x" by L, H by M L^{3/2}).
            let u = contact_point(&model, beta, &ctx, h_des).unwrap();
            let su = contact_point(&s_model, beta, &s_ctx, s_h_des).unwrap();
            // Positions of order 1 m; round-off only.
            assert!((su[0] - u[0] * l).abs() < 1e-9 && (su[1] - u[1] * l).abs() < 1e-9);
        }
    }
    assert!(
        feasible > 50 && infeasible > 50,
        "{feasible} / {infeasible}"
    );
}

#[test]
fn exact_at_resolved_contact_point() {
    let mut rng = Rng::new(41);
    for _ in 0..10 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let coef = precompute(&model, &ctx);
        let (grids, moments) = (SampledGrids::new(&model), ImpulseMoments::new(&model));
        let lim = relative_limits(&coef);
        let h = coef.ang_impulse;
        // Identity: u* = cp (to ~1e-12 m), so the extremes match precompute's; 1e-9 relative.
        let (v, u) = exact_at_contact_point(&grids, &model, &moments, &ctx, [1.0; 3], h, &lim);
        assert!(u.is_some() && close(v.ext_max, coef.ext_max, 1e-9));
        assert!(close(v.ext_min, coef.ext_min, 1e-9));
        // A scaled query is checked at its own u*, not at the data contact point.
        let beta = beta_in(&mut rng, 0.5, 2.0);
        let (v, u) = exact_at_contact_point(&grids, &model, &moments, &ctx, beta, h, &lim);
        let u = u.unwrap();
        assert_eq!(
            v,
            exact(&grids, &model, &QueryContext { cp: u, ..ctx }, beta, &lim)
        );
        // No vertical impulse: falls back to ctx.cp and reports no u*.
        let flat = [1.0, 1.0, 0.0];
        let (v, u) = exact_at_contact_point(&grids, &model, &moments, &ctx, flat, h, &lim);
        assert!(u.is_none() && v == exact(&grids, &model, &ctx, flat, &lim));
    }
}
