//! `r(τ)` against an RK4 integration, the identity extension extremes, and the Appendix B
//! boxes against their definition.

use super::{force_at, random_context, random_model, Rng};
use crate::constraints::extension::unscaled_offset;
use crate::constraints::{
    com_offset, ellipsoid_boxes, precompute, PrecomputeOptions, SampledGrids, DEFAULT_BETA_MAX,
    RELATIVE_MARGIN,
};
use crate::force_model::GRAVITY;

#[test]
fn com_offset_matches_an_rk4_integration() {
    let mut rng = Rng::new(10);
    for _ in 0..10 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let beta = [0; 3].map(|_| rng.uniform(0.0, 3.0));
        let (m, dt) = (model.mass_kg, model.dt_s);
        // m r̈ = β∘f(t/Δt) + m g⃗ in real time, state (r, ṙ).
        let deriv = |t: f64, y: [f64; 6]| {
            let f = force_at(&model, t / dt);
            let mut d = [y[3], y[4], y[5], 0.0, 0.0, 0.0];
            for a in 0..3 {
                d[3 + a] = beta[a] * f[a] / m;
            }
            d[5] -= GRAVITY;
            d
        };
        let axpy = |y: [f64; 6], h: f64, k: [f64; 6]| {
            let mut o = y;
            for i in 0..6 {
                o[i] += h * k[i];
            }
            o
        };
        let steps = 4000;
        let h = dt / steps as f64;
        let mut y = [0.0, 0.0, 0.0, ctx.vs, ctx.vps, -GRAVITY * ctx.t_td];
        for n in 0..steps {
            let t = n as f64 * h;
            let k1 = deriv(t, y);
            let k2 = deriv(t + h / 2.0, axpy(y, h / 2.0, k1));
            let k3 = deriv(t + h / 2.0, axpy(y, h / 2.0, k2));
            let k4 = deriv(t + h, axpy(y, h, k3));
            for i in 0..6 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            if (n + 1) % 400 == 0 {
                let tau = (n + 1) as f64 / steps as f64;
                let r = com_offset(&model, &ctx, beta, tau);
                for a in 0..3 {
                    // RK4 with h ≤ 1.3e-4 s: truncation error ~1e-12 m for j ≤ 6.
                    assert!(
                        (r[a] - y[a]).abs() < 1e-9,
                        "axis {a} τ {tau}: {} vs {}",
                        r[a],
                        y[a]
                    );
                }
            }
        }
    }
}

#[test]
fn identity_extension_extremes_equal_ext_min_and_ext_max() {
    let mut rng = Rng::new(11);
    for _ in 0..50 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let c = precompute(&model, &ctx);
        let x_cp = [ctx.cp[0], ctx.cp[1], -ctx.z_td];
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for t in model.grid() {
            let r = com_offset(&model, &ctx, [1.0; 3], t);
            let d = (0..3).map(|a| (r[a] - x_cp[a]).powi(2)).sum::<f64>().sqrt();
            lo = lo.min(d);
            hi = hi.max(d);
        }
        // Same formula, grids vs direct trig: ~1e-15 m apart.
        assert!((c.ext_min - lo).abs() < 1e-12 && (c.ext_max - hi).abs() < 1e-12);
        let at_td = (x_cp[0].powi(2) + x_cp[1].powi(2) + x_cp[2].powi(2)).sqrt();
        assert!(c.ext_min <= at_td && at_td <= c.ext_max);
    }
}

#[test]
fn boxes_are_clipped_and_the_chi_max_box_holds_the_identity() {
    let mut rng = Rng::new(12);
    for _ in 0..200 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let c = precompute(&model, &ctx);
        for v in [c.ell_r_min, c.ell_r_max, c.ell_s_min, c.ell_s_max]
            .iter()
            .flatten()
        {
            assert!((0.0..=DEFAULT_BETA_MAX).contains(v), "{v} outside [0, 3]");
        }
        // |U_a + S_a| ≤ ext_max < χ_max at every τ, so β_a = 1 is inside every per-τ interval.
        for a in 0..3 {
            assert!(
                c.ell_r_min[a] <= 1.0 && 1.0 <= c.ell_r_max[a],
                "axis {a}: {c:?}"
            );
        }
    }
}

#[test]
fn boxes_match_their_definition() {
    let mut rng = Rng::new(13);
    let opts = PrecomputeOptions::default();
    for _ in 0..50 {
        let model = random_model(&mut rng);
        let ctx = random_context(&mut rng);
        let grids = SampledGrids::new(&model);
        let chi = [rng.uniform(0.5, 0.9), rng.uniform(1.0, 1.5)];
        let b = ellipsoid_boxes(&model, &ctx, &grids, chi, &opts);
        let grid = model.grid();
        let (mut r_min, mut r_max) = ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]);
        let (mut s_min, mut s_max) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for a in 0..3 {
            let s_all: Vec<f64> = grid.iter().map(|&t| model.s(a, t)).collect();
            let floor = opts.s_floor_rel * s_all.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (&t, &s) in grid.iter().zip(&s_all) {
                if s.abs() <= floor {
                    continue;
                }
                let u = unscaled_offset(&model, &ctx, t)[a];
                let (aa, bb) = (-u / s, 1.0 / s.abs());
                r_max[a] = r_max[a].min(aa + bb * chi[1]);
                r_min[a] = r_min[a].max(aa - bb * chi[1]);
                s_max[a] = s_max[a].max(aa + bb * chi[0]);
                s_min[a] = s_min[a].min(aa - bb * chi[0]);
            }
        }
        let clip = |x: f64| x.clamp(0.0, opts.beta_max);
        // Bounds are (χ ∓ U_a·sgn S_a)/|S_a|; grids and direct trig differ by ~1e-13 in
        // S_a, i.e. ~1e-9 relative where |S_a| is smallest; values are ≤ β_max = 3.
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-7;
        for a in 0..3 {
            assert!(
                close(b.r_max[a], clip(r_max[a])),
                "r_max {a}: {b:?} {r_max:?}"
            );
            assert!(
                close(b.r_min[a], clip(r_min[a])),
                "r_min {a}: {b:?} {r_min:?}"
            );
            assert!(
                close(b.s_max[a], clip(s_max[a])),
                "s_max {a}: {b:?} {s_max:?}"
            );
            assert!(
                close(b.s_min[a], clip(s_min[a])),
                "s_min {a}: {b:?} {s_min:?}"
            );
        }
    }
}

#[test]
fn relative_limits_use_the_margin() {
    let mut rng = Rng::new(14);
    let model = random_model(&mut rng);
    let ctx = random_context(&mut rng);
    let c = precompute(&model, &ctx);
    let grids = SampledGrids::new(&model);
    let chi = [c.ext_min / RELATIVE_MARGIN, RELATIVE_MARGIN * c.ext_max];
    let b = ellipsoid_boxes(&model, &ctx, &grids, chi, &PrecomputeOptions::default());
    assert_eq!(
        [b.r_min, b.r_max, b.s_min, b.s_max],
        [c.ell_r_min, c.ell_r_max, c.ell_s_min, c.ell_s_max]
    );
}

#[test]
fn an_axis_without_force_gives_a_full_chi_max_box_and_an_empty_chi_min_box() {
    let mut rng = Rng::new(15);
    let mut model = random_model(&mut rng);
    model.axes[1] = crate::force_model::AxisModel::constant(0.0);
    let c = precompute(&model, &random_context(&mut rng));
    assert_eq!((c.ell_r_min[1], c.ell_r_max[1]), (0.0, DEFAULT_BETA_MAX));
    assert_eq!((c.ell_s_min[1], c.ell_s_max[1]), (DEFAULT_BETA_MAX, 0.0));
}
