//! Tests of the run-at-speed policy: the outcome checked by an independent forward
//! simulation, the cycle rules, and the invariance of the verdicts under dynamic
//! similarity (spec stance-model §6.8, §9).

use super::*;
use crate::force_model::GRAVITY;
use crate::query::feasibility::relative_limits;
use crate::query::gait::GaitLaw;
use crate::query::solve::Solution;
use crate::query::testkit::{assert_reaches_end_apex, bell_model, pool_stance, simulate, Rng};

/// A runner-like stance: touchdown at 3–5 m/s descending, liftoff rising (a flight on
/// both sides, so §6.5 rule 3 holds for the recorded stance itself).
fn running_stance(rng: &mut Rng, id: &str, label: &str) -> Prepared {
    loop {
        let m = bell_model(rng);
        let v_td = [rng.uniform(3.0, 5.0), 0.0, -rng.uniform(0.3, 1.0)];
        let s = pool_stance(
            id,
            m,
            v_td,
            rng.uniform(0.85, 1.0),
            (Boundary::Flight, Boundary::Flight),
            label,
            [rng.uniform(-0.1, 0.2), rng.uniform(-0.1, 0.1)],
        );
        if s.params.t_e >= s.params.t_lo {
            return Prepared::new(s);
        }
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

#[test]
fn policy_keeps_vertical_solution_and_scales_horizontal_forces() {
    let mut rng = Rng::new(0x5eed_0401);
    let mut solved = 0;
    for i in 0..100 {
        let p = running_stance(&mut rng, "s", "L");
        let q = p.stance.params;
        for k in [0.0, 0.3, 1.0, 1.4] {
            let req = policy_request(&p.stance, k);
            let sol = match solve(&p.shape, &req, &Refs::default(), Some(q.t_e)) {
                Ok(s) => s,
                Err(e) => {
                    // Only k = 0 may lose the centroid rule (in-place bounce); never NaN.
                    assert!(k == 0.0, "stance {i}, k = {k}: {e}");
                    continue;
                }
            };
            solved += 1;
            assert!(close(sol.beta[0], k, 1e-9), "β_h {} ≠ k {k}", sol.beta[0]);
            assert!(close(sol.beta[1], 1.0, 1e-9) && close(sol.beta[2], 1.0, 1e-9));
            for (a, b) in [(sol.t_td, q.t_td), (sol.t_lo, q.t_lo), (sol.t_e, q.t_e)] {
                assert!((a - b).abs() < 1e-9, "times changed: {a} vs {b}");
            }
            // Independent check: RK4 on the scaled model force, start apex → end apex.
            let end = simulate(&p.stance.model, &req, &sol);
            assert_reaches_end_apex(&end, &req, 1e-6, "scaled stance");
            assert!((end[4] - req.vp).abs() < 1e-6 && end[5].abs() < 1e-6);
        }
    }
    assert!(solved >= 300, "only {solved} solved");
}

fn with(p: &Prepared, f: impl Fn(&mut PoolStance)) -> PoolStance {
    let mut s = p.stance.clone();
    f(&mut s);
    s
}

#[test]
fn cycles_need_opposite_feet_flights_and_chaining() {
    let mut rng = Rng::new(0x5eed_0402);
    let a = running_stance(&mut rng, "a", "L");
    // b starts where a's flight ends: same speed and apex height.
    let b = with(&running_stance(&mut rng, "b", "R"), |s| {
        s.params.vs = a.stance.params.ve;
        s.params.zs = a.stance.params.ze;
    });
    let v = cycle_of(&a.stance, &b).expect("a chained L→R pair is a cycle");
    let (pa, pb) = (&a.stance.params, &b.params);
    assert!(close(v, (pa.x + pb.x) / (pa.t_e + pb.t_e), 1e-12));
    let same_foot = with(&a, |s| s.label = "L".into());
    assert_eq!(cycle_of(&a.stance, &same_foot), Err(NotACycle::Feet));
    let walk = with(&a, |s| {
        s.label = "R".into();
        s.boundary_end = Boundary::NoFlight;
    });
    assert_eq!(cycle_of(&a.stance, &walk), Err(NotACycle::Boundaries));
    let faster = with(&a, |s| {
        s.label = "R".into();
        s.params.vs = pa.ve + 0.06 * v;
        s.params.zs = pa.ze;
    });
    assert_eq!(cycle_of(&a.stance, &faster), Err(NotACycle::Chaining));
    let higher = with(&a, |s| {
        s.label = "R".into();
        s.params.vs = pa.ve;
        s.params.zs = pa.ze + 0.021;
    });
    assert_eq!(cycle_of(&a.stance, &higher), Err(NotACycle::Chaining));
    // run_cycles pairs consecutive stances of one clip only.
    let pool = vec![
        a.stance.clone(),
        b.clone(),
        with(&a, |s| s.clip = "other".into()),
    ];
    let cycles = run_cycles(&pool);
    assert_eq!(cycles.len(), 1);
    assert_eq!(cycles[0].stances, [0, 1]);
}

/// `(J, K)` of `f̃(t) = f(t/σ)` by quadrature over real time (no closed form):
/// `J_a = ∫ f̃_a/m dt`, `K_a = ∫ t f̃_a/m dt` (the first moment about touchdown), midpoint
/// rule with `n` steps.
fn numerical_j_k(m: &crate::force_model::ForceModel, sigma: f64, n: usize) -> ([f64; 3], [f64; 3]) {
    let dt = sigma * m.dt_s;
    let h = dt / n as f64;
    let (mut j, mut k) = ([0.0; 3], [0.0; 3]);
    for i in 0..n {
        let t = (i as f64 + 0.5) * h;
        for a in 0..3 {
            let f = m.axes[a].eval(t / dt) / m.mass_kg;
            j[a] += f * h;
            k[a] += t * f * h;
        }
    }
    (j, k)
}

// Issue 37 item 1: the closed forms of a time-scaled stance, J̃ = σJ and K̃ = σ²K, checked
// by quadrature, and its scaled outcome by an RK4 simulation of β f((t − t_TD)/(σΔt)).
#[test]
fn time_scaled_stances_solve_exactly() {
    let mut rng = Rng::new(0x5eed_0437);
    let mut solved = 0;
    for i in 0..60 {
        let p = running_stance(&mut rng, "s", "L");
        let sigma = rng.uniform(0.6, 1.5);
        let t = Prepared::new(p.stance.time_scaled(sigma));
        let (jn, kn) = numerical_j_k(&p.stance.model, sigma, 20_000);
        for a in 0..3 {
            assert!(
                close(t.shape.j[a], sigma * p.shape.j[a], 1e-12),
                "J scales with σ"
            );
            assert!(
                close(t.shape.k[a], sigma * sigma * p.shape.k[a], 1e-12),
                "K with σ²"
            );
            assert!(
                (t.shape.j[a] - jn[a]).abs() < 1e-6 * (1.0 + jn[a].abs()),
                "{i}: J"
            );
            assert!(
                (t.shape.k[a] - kn[a]).abs() < 1e-6 * (1.0 + kn[a].abs()),
                "{i}: K"
            );
        }
        let q = p.stance.params;
        let v = rng.uniform(2.0, 6.0);
        let law = GaitLaw::POPULATION;
        let lim = relative_limits(&p.stance.coef);
        let mut other = p.clone();
        other.stance.label = "R".into();
        let c = run_at_speed([&p, &other], q.x / q.t_e, v, &law, [&lim, &lim]);
        let Ok(s) = &c.stances[0] else { continue };
        solved += 1;
        let timed = p.stance.time_scaled(c.timing.sigma_c);
        // The law's times, exactly.
        assert!(close(
            s.solution.t_lo - s.solution.t_td,
            c.timing.sigma_c * q.t_lo - c.timing.sigma_c * q.t_td,
            1e-9
        ));
        assert!(
            close(s.solution.t_e, c.timing.sigma_t * q.t_e, 1e-9),
            "T = σ_T T₀"
        );
        // β_v = g T / J̃_v (A3 with the time-scaled impulse).
        let jv = c.timing.sigma_c * p.shape.j[2];
        assert!(close(
            s.solution.beta[2],
            GRAVITY * s.solution.t_e / jv,
            1e-9
        ));
        // Independent: RK4 with the time-scaled force reaches the requested end apex.
        let both = [&p, &other].map(|x| Prepared::new(x.stance.time_scaled(c.timing.sigma_c)));
        let t_e = [c.timing.sigma_t * q.t_e; 2];
        let (req, _, u) = law_requests([&both[0], &both[1]], q.x / q.t_e, v, &c.timing, t_e);
        assert!(close(u / (q.x / q.t_e), c.k, 1e-12), "k = u/v₀");
        let req = req[0];
        let end = simulate(&timed.model, &req, &s.solution);
        assert_reaches_end_apex(&end, &req, 1e-6, "time-scaled stance");
    }
    assert!(solved >= 40, "only {solved} solved");
}

// Issue 37 item 1: the cycle's mean speed Σx/ΣT is the target speed exactly, and the law's
// direction holds: faster means shorter contact, shorter steps and more vertical force.
#[test]
fn the_gait_law_hits_the_speed_and_moves_times_the_way_people_do() {
    let mut rng = Rng::new(0x5eed_0438);
    let mut checked = 0;
    for _ in 0..40 {
        let pair = [
            running_stance(&mut rng, "a", "L"),
            running_stance(&mut rng, "b", "R"),
        ];
        let q = pair.each_ref().map(|p| p.stance.params);
        let v_orig = (q[0].x + q[1].x) / (q[0].t_e + q[1].t_e);
        let lim = relative_limits(&pair[0].stance.coef);
        let law = GaitLaw::POPULATION;
        let at = |v: f64| run_at_speed([&pair[0], &pair[1]], v_orig, v, &law, [&lim, &lim]);
        let (slow, fast) = (at(0.8 * v_orig), at(1.3 * v_orig));
        let (Ok(s0), Ok(s1), Ok(f0), Ok(f1)) = (
            &slow.stances[0],
            &slow.stances[1],
            &fast.stances[0],
            &fast.stances[1],
        ) else {
            continue;
        };
        checked += 1;
        // Mean speed of each answer: the requests' distances over the solved periods (each
        // request's end apex is the solution's: RK4-checked in
        // `time_scaled_stances_solve_exactly`).
        for (c, a, b) in [(&slow, s0, s1), (&fast, f0, f1)] {
            let t = pair
                .each_ref()
                .map(|p| Prepared::new(p.stance.time_scaled(c.timing.sigma_c)));
            let periods = [a.solution.t_e, b.solution.t_e];
            let (req, _, _) = law_requests([&t[0], &t[1]], v_orig, c.speed, &c.timing, periods);
            let v = (req[0].x + req[1].x) / (periods[0] + periods[1]);
            assert!(close(v, c.speed, 1e-9), "mean speed {v} vs {}", c.speed);
            // The speed change of each stance scales by κ = (v/v₀) σ_c σ_T.
            for i in 0..2 {
                let d0 = q[i].ve - q[i].vs;
                assert!(close(req[i].ve - req[i].vs, c.timing.kappa * d0, 1e-9));
            }
        }
        assert!(f0.solution.t_lo - f0.solution.t_td < s0.solution.t_lo - s0.solution.t_td);
        assert!(f0.solution.t_e < s0.solution.t_e);
        assert!(
            f0.solution.beta[2] > s0.solution.beta[2],
            "more vertical force when faster"
        );
    }
    assert!(checked >= 20, "only {checked} checked");
}

fn solved(c: &RunCandidate) -> [&ScaledStance; 2] {
    c.stances.each_ref().map(|s| s.as_ref().expect("solved"))
}

#[test]
fn verdicts_are_invariant_under_dynamic_similarity() {
    let mut rng = Rng::new(0x5eed_0403);
    let (l, m) = (0.67, 3.62);
    let mut outcomes = [0usize; 2];
    for _ in 0..40 {
        let pair = [
            running_stance(&mut rng, "a", "L"),
            running_stance(&mut rng, "b", "R"),
        ];
        let lim = relative_limits(&pair[0].stance.coef);
        let v_orig = 4.0;
        let big = pair
            .each_ref()
            .map(|p| Prepared::new(p.stance.scaled(l, m)));
        let big_lim = scale_limits(&lim, l, m);
        for (v, law) in [1.0, 3.0, 5.0]
            .into_iter()
            .flat_map(|v| [(v, GaitLaw::PAPER), (v, GaitLaw::POPULATION)])
        {
            let a = run_at_speed([&pair[0], &pair[1]], v_orig, v, &law, [&lim, &lim]);
            let b = run_at_speed(
                [&big[0], &big[1]],
                v_orig * l.sqrt(),
                v * l.sqrt(),
                &law,
                [&big_lim, &big_lim],
            );
            assert_eq!(a.feasible(), b.feasible());
            assert_eq!(a.feasible_approx(), b.feasible_approx());
            outcomes[usize::from(a.feasible())] += 1;
            let errs = |c: &RunCandidate| c.stances.each_ref().map(|s| s.as_ref().err().copied());
            assert_eq!(errs(&a), errs(&b), "the same stances solve");
            if a.stances.iter().any(|s| s.is_err()) {
                continue; // a law's slow step without a flight (FlightRule), both sizes alike
            }
            for (x, y) in solved(&a).iter().zip(solved(&b)) {
                let (sx, sy): (&Solution, &Solution) = (&x.solution, &y.solution);
                for k in 0..3 {
                    assert!(close(sx.beta[k], sy.beta[k], 1e-9), "β changed");
                }
                assert!(close(sx.t_e * l.sqrt(), sy.t_e, 1e-9));
                assert_eq!(x.verdict.violated, y.verdict.violated);
                assert!(close(x.verdict.f_peak * m, y.verdict.f_peak, 1e-9));
                assert!(close(x.verdict.ext_max * l, y.verdict.ext_max, 1e-9));
                assert!(close(x.verdict.ext_min * l, y.verdict.ext_min, 1e-9));
                assert!(close(x.verdict.mu_req, y.verdict.mu_req, 1e-9));
                assert!(close(x.cp[0] * l, y.cp[0], 1e-9) && close(x.cp[1] * l, y.cp[1], 1e-9));
            }
        }
    }
    // Both verdicts occur, so the invariance is not vacuous.
    assert!(outcomes[0] > 10 && outcomes[1] > 10, "{outcomes:?}");
}

// See: issue 11 item 6 — run sweeps are bounded by MAX_RUN_ROWS (cycles × speeds).
#[test]
fn run_sweeps_beyond_max_run_rows_are_refused() {
    assert!(check_sweep("--speeds", 100, MAX_RUN_ROWS / 100).is_ok());
    let e = check_sweep("--speeds", 101, MAX_RUN_ROWS / 100).unwrap_err();
    assert!(e.to_string().starts_with("--speeds: "), "{e}");
    assert!(e.to_string().contains("MAX_RUN_ROWS"), "{e}");
    assert!(check_speed("--speed", -1.0).is_err() && check_speed("--speed", f64::NAN).is_err());
    assert!(check_scale("--mass-scale", 0.0).is_err());
    assert_eq!(check_scale("--mass-scale", 2.0).unwrap(), 2.0);
}
