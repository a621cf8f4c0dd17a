use super::*;
use crate::force_model::AxisModel;
use crate::query::testkit::{
    assert_reaches_end_apex, random_model, rk4, scaled, simulate, Rng, RK4_STEPS,
};
use crate::stances::params::{from_states, model_consistent, StanceParams};

fn request_of(p: &StanceParams) -> Request {
    Request {
        zs: p.zs,
        vs: p.vs,
        ze: p.ze,
        ve: p.ve,
        vp: p.vp,
        vps: p.vps,
        x: p.x,
    }
}

/// Parameters of `m` (already scaled) from a touchdown state, by RK4 over the stance.
fn params_by_simulation(m: &ForceModel, v_td: [f64; 3], z_td: f64) -> StanceParams {
    let y = rk4(
        m,
        [1.0; 3],
        0.0,
        [0.0, 0.0, 0.0, v_td[0], v_td[1], v_td[2]],
        0.0,
        m.dt_s,
        RK4_STEPS,
    );
    from_states(v_td, z_td, [y[0], y[1], y[2]], [y[3], y[4], y[5]], m.dt_s)
}

#[test]
fn identity_query_returns_beta_one_and_original_times() {
    let mut rng = Rng::new(0x5eed_0001);
    for i in 0..200 {
        let m = random_model(&mut rng);
        let v_td = [rng.uniform(1.0, 6.0), 0.0, rng.uniform(-2.0, 0.5)];
        let z_td = rng.uniform(0.8, 1.0);
        let p = params_by_simulation(&m, v_td, z_td);
        // RK4 vs the closed form (§3): ≲ 1e-12 stepping error on O(1) values.
        let pc = model_consistent(v_td, z_td, m.j(), m.p(), m.dt_s);
        for (a, b) in [(p.x, pc.x), (p.ze, pc.ze), (p.ve, pc.ve), (p.t_e, pc.t_e)] {
            assert!((a - b).abs() < 1e-10, "case {i}: simulation vs closed form");
        }
        let mut shape = StanceShape::from_model(&m, p.t_td > 0.0, p.t_e > p.t_lo, None);
        shape.ref_signs = shape.centroid_split(p.t_td, p.t_e);
        let s = solve(&shape, &request_of(&p), &Refs::default(), Some(p.t_e))
            .unwrap_or_else(|e| panic!("case {i}: {e:?}"));
        // Roundoff of the quadratic on O(1) s and O(1) β, amplified ≲ 1e3 near a
        // double root: 1e-9 as the brief requires.
        for b in s.beta {
            assert!((b - 1.0).abs() < 1e-9, "case {i}: β = {:?}", s.beta);
        }
        assert!((s.t_td - p.t_td).abs() < 1e-9, "case {i}");
        assert!((s.t_e - p.t_e).abs() < 1e-9, "case {i}");
        assert!((s.t_lo - p.t_lo).abs() < 1e-9, "case {i}");
        assert_eq!(s.branch, Branch::Quadratic);
    }
}

/// Checks an admissible solution against an independent RK4 run from the start apex.
fn check_by_simulation(m: &ForceModel, req: &Request, s: &Solution, what: &str) {
    let y = simulate(m, req, s);
    // Issue 4: forward simulation reproduces the parameters to 1e-6 (RK4 error ≲ 1e-12).
    let tol = 1e-6;
    assert_reaches_end_apex(&y, req, tol, what);
    assert!((y[1] - s.y).abs() < tol, "{what}: y {} vs {}", y[1], s.y);
    assert!((y[4] - req.vp).abs() < tol, "{what}: vp");
    assert!(
        y[5].abs() < tol,
        "{what}: the end is an apex, v_v = {}",
        y[5]
    );
    // Start apex: v_v(0) = 0 by construction; zs and vs are the initial state, and the
    // touchdown height must be the one the flight from zs implies.
    let td = rk4(
        m,
        [0.0; 3],
        s.t_td,
        [0.0, 0.0, req.zs, req.vs, req.vps, 0.0],
        0.0,
        s.t_td,
        4,
    );
    let z_td = req.zs - 0.5 * GRAVITY * s.t_td * s.t_td;
    assert!(
        (td[2] - z_td).abs() < tol && (td[0] - req.vs * s.t_td).abs() < tol,
        "{what}"
    );
}

#[test]
fn forward_simulation_reproduces_random_requests() {
    let mut rng = Rng::new(0x5eed_0002);
    let (mut scaled_ok, mut random_ok) = (0, 0);
    for i in 0..300 {
        let m = random_model(&mut rng);
        // (a) a scaled stance's own outcome (always feasible; vps ≠ 0 as with the
        // facing fallback of §2), (b) a random request.
        let beta = [
            rng.uniform(0.5, 1.6),
            rng.uniform(0.5, 1.6),
            rng.uniform(0.6, 1.5),
        ];
        let v_td = [
            rng.uniform(0.5, 6.0),
            rng.uniform(-0.3, 0.3),
            rng.uniform(-2.0, 0.5),
        ];
        let p = model_consistent(
            v_td,
            0.9,
            scaled(&m, beta).j(),
            scaled(&m, beta).p(),
            m.dt_s,
        );
        let mut shape = StanceShape::from_model(&m, false, false, None);
        shape.ref_signs = shape.centroid_split(p.t_td, p.t_e);
        let req = request_of(&p);
        let s = solve(&shape, &req, &Refs::default(), None)
            .unwrap_or_else(|e| panic!("case {i}: {e:?}"));
        check_by_simulation(&m, &req, &s, &format!("scaled {i}"));
        scaled_ok += 1;

        let req = Request {
            zs: rng.uniform(0.8, 1.2),
            vs: rng.uniform(0.0, 6.0),
            ze: rng.uniform(0.8, 1.2),
            ve: rng.uniform(0.0, 6.0),
            vp: rng.uniform(-0.3, 0.3),
            vps: 0.0,
            x: rng.uniform(0.0, 4.0),
        };
        let shape = StanceShape::from_model(&m, true, true, None);
        if let Ok(s) = solve(&shape, &req, &Refs::default(), None) {
            check_by_simulation(&m, &req, &s, &format!("random {i}"));
            random_ok += 1;
        }
    }
    assert_eq!(scaled_ok, 300);
    assert!(
        random_ok >= 20,
        "too few feasible random requests: {random_ok}"
    );
}

/// A model with given DC terms and one cosine per axis of phase `phi`.
fn model_with(c0: [f64; 3], phi: f64) -> ForceModel {
    let axis = |c0: f64, amp: f64| AxisModel {
        c0,
        harmonics: vec![1.0],
        amps: vec![amp],
        phases: vec![phi],
        poly: Vec::new(),
        fit_rms: 0.0,
    };
    ForceModel {
        mass_kg: 70.0,
        dt_s: 0.25,
        axes: [axis(c0[0], 200.0), axis(c0[1], 50.0), axis(c0[2], 600.0)],
    }
}

/// The request of the degenerate-branch tests: a steady 3 m/s stance, 1.5 m apex to apex.
const BASE: Request = Request {
    zs: 1.0,
    vs: 3.0,
    ze: 1.0,
    ve: 3.0,
    vp: 0.0,
    vps: 0.0,
    x: 1.5,
};

#[test]
fn degenerate_branch_no_support() {
    let (refs, base) = (Refs::default(), BASE);
    // (i) no support: J_v ≤ 0, and J_v = 0 exactly.
    for c0_v in [-100.0, 0.0] {
        let m = model_with([50.0, 0.0, c0_v], 0.3);
        let shape = StanceShape::from_model(&m, false, false, None);
        assert_eq!(
            solve(&shape, &base, &refs, None),
            Err(Infeasible::NoSupport)
        );
    }
}

#[test]
fn degenerate_branch_no_net_horizontal_impulse_or_moment() {
    let (refs, base) = (Refs::default(), BASE);
    // (ii) J_h = 0 (no DC), K_h > 0: φ = π/2 gives −sin 2πτ, brake then push.
    let m = model_with([0.0, 30.0, 1400.0], std::f64::consts::FRAC_PI_2);
    let shape = StanceShape::from_model(&m, false, false, None);
    let uneven = Request { ve: 3.5, ..base };
    let e = solve(&shape, &uneven, &refs, None);
    assert_eq!(e, Err(Infeasible::NoNetHorizontalImpulse));
    let t = m.j()[2] / GRAVITY; // β_v,ref = 1
    let req = Request {
        x: 3.0 * t - 0.02,
        ..base
    };
    let s = solve(&shape, &req, &refs, None).unwrap();
    assert_eq!(s.branch, Branch::NoNetHorizontal);
    // T = β_v,ref J_v/g exactly up to roundoff (1e-15 relative on O(1) s).
    assert!((s.t_e - t).abs() < 1e-14 && (s.beta[2] - 1.0).abs() < 1e-14);
    assert!((s.beta[0] - 0.02 / m.k()[0]).abs() < 1e-12); // β_h = (ve·T − x)/K_h
    check_by_simulation(&m, &req, &s, "branch (ii)");
    // β_v,ref = 1.2 sets T.
    let s = solve(
        &shape,
        &req,
        &Refs {
            beta_v: 1.2,
            ..refs
        },
        None,
    )
    .unwrap();
    assert!((s.t_e - 1.2 * t).abs() < 1e-14 && (s.beta[2] - 1.2).abs() < 1e-14);
    // (ii) with K_h = 0 too (φ = 0): x must equal ve·T, β_h = β_h,ref.
    let m = model_with([0.0, 30.0, 1400.0], 0.0);
    assert!(m.k()[0].abs() < 1e-15 && m.j()[0] == 0.0);
    let shape = StanceShape::from_model(&m, false, false, None);
    let e = solve(&shape, &req, &refs, None);
    assert_eq!(e, Err(Infeasible::NoNetHorizontalMoment));
    let exact = Request { x: 3.0 * t, ..base };
    let s = solve(
        &shape,
        &exact,
        &Refs {
            beta_h: 0.7,
            ..refs
        },
        None,
    )
    .unwrap();
    assert_eq!(s.beta[0], 0.7);
    check_by_simulation(&m, &exact, &s, "branch (ii), K_h = 0");
}

#[test]
fn polynomial_force_with_roundoff_impulse_is_degenerate() {
    // A friction-ratio style fore-aft force with no harmonics: f_h = −50 + 100 τ (N) plus
    // a roundoff-sized DC, so J_h ≈ 1e-16 m/s while the force is 50 N at the edges. Its
    // scale counts the polynomial, so the J_h ≈ 0 branch takes it (β_h is not Δv/1e-16).
    let mut m = model_with([0.0, 0.0, 1400.0], 0.0);
    m.axes[0] = AxisModel {
        c0: 1e-13,
        poly: vec![-50.0, 100.0],
        ..AxisModel::default()
    };
    let j_h = m.j()[0];
    assert!(j_h != 0.0 && j_h.abs() < 1e-14, "J_h {j_h}");
    let shape = StanceShape::from_model(&m, false, false, None);
    assert!(shape.j_scale[0] > 1e3 * j_h.abs());
    let t = m.j()[2] / GRAVITY;
    let req = Request {
        x: 3.0 * t - 0.01,
        ..BASE
    };
    let s = solve(&shape, &req, &Refs::default(), None).unwrap();
    assert_eq!(s.branch, Branch::NoNetHorizontal);
    assert!(
        (s.beta[0] - 0.01 / m.k()[0]).abs() < 1e-9,
        "β_h {}",
        s.beta[0]
    );
}

#[test]
fn degenerate_branch_no_net_perpendicular_impulse() {
    let (refs, base) = (Refs::default(), BASE);
    // (iii) J_p = 0: vp must equal vps, β_p = β_p,ref.
    let m = model_with([50.0, 0.0, 1400.0], 0.4);
    let shape = StanceShape::from_model(&m, false, false, None);
    let e = solve(&shape, &Request { vp: 0.2, ..base }, &refs, None);
    assert_eq!(e, Err(Infeasible::NoNetPerpendicularImpulse));
    let s = solve(
        &shape,
        &base,
        &Refs {
            beta_p: 0.4,
            ..refs
        },
        None,
    )
    .unwrap();
    assert_eq!(s.beta[1], 0.4);
    check_by_simulation(&m, &base, &s, "branch (iii)");
}

#[test]
fn degenerate_branches_running_in_place_and_reversal() {
    let (refs, base) = (Refs::default(), BASE);
    // (iv) running in place: vs = ve = x = 0, Δz = 0 → T = β_v,ref J_v/g, β_h = 0.
    let m = model_with([50.0, 20.0, 1400.0], 0.4);
    let shape = StanceShape::from_model(&m, true, true, None);
    let still = Request {
        vs: 0.0,
        ve: 0.0,
        x: 0.0,
        ..base
    };
    let s = solve(&shape, &still, &refs, None).unwrap();
    assert_eq!(s.branch, Branch::FreePeriod);
    assert!((s.t_e - m.j()[2] / GRAVITY).abs() < 1e-14 && s.beta[0] == 0.0);
    check_by_simulation(&m, &still, &s, "branch (iv)");
    // a = 0 (vs + ve = 0): a reversal, the linear equation T = −c/b. With b = 0.15 and
    // Δz = 0.3 m, T = 2Δz/(g b) ≈ 0.41 s > √(2Δz/g) ≈ 0.25 s, so u, w > 0.
    let m = model_with([-600.0, 20.0, 1400.0], 0.4);
    let shape = StanceShape::from_model(&m, false, false, None);
    let d = -2.0;
    let sh_sv = m.k()[0] / m.j()[0] - m.k()[2] / m.j()[2];
    let rev = Request {
        vs: 1.0,
        ve: -1.0,
        x: -0.15 - d * sh_sv,
        zs: 1.0,
        ze: 1.3,
        ..base
    };
    let s = solve(&shape, &rev, &refs, None).unwrap();
    assert_eq!(s.branch, Branch::Linear);
    // −c/b computed directly: roundoff only.
    assert!((s.t_e - 2.0 * 0.3 / (GRAVITY * 0.15)).abs() < 1e-12);
    check_by_simulation(&m, &rev, &s, "linear");
    // a = 0, b = 0, c ≠ 0: no root.
    let no_root = Request {
        x: -d * sh_sv,
        ..rev
    };
    assert_eq!(
        solve(&shape, &no_root, &refs, None),
        Err(Infeasible::NoRoot)
    );
}

#[test]
fn negative_discriminant_is_reported_not_nan() {
    // d = 2 m/s, Δz = 5 m up, x = 0.1 m: b² ≈ 0.01 ≪ 4ac = 4·2·(2·5/9.81) ≈ 8.2.
    let m = model_with([200.0, 20.0, 1400.0], 0.4);
    let shape = StanceShape::from_model(&m, true, true, None);
    let req = Request {
        zs: 1.0,
        vs: 1.0,
        ze: 6.0,
        ve: 3.0,
        vp: 0.0,
        vps: 0.0,
        x: 0.1,
    };
    let (_, a, c) = (0, 2.0, 2.0 * 5.0 / GRAVITY);
    assert!(4.0 * a * c > 1.0);
    assert_eq!(
        solve(&shape, &req, &Refs::default(), None),
        Err(Infeasible::NegativeDiscriminant)
    );
}

#[test]
fn at_most_one_root_satisfies_the_centroid_rule() {
    let mut rng = Rng::new(0x5eed_0005);
    let (mut real, mut two_positive) = (0, 0);
    for i in 0..500 {
        let m = random_model(&mut rng);
        let shape = StanceShape::from_model(&m, false, false, None);
        let req = Request {
            zs: rng.uniform(0.7, 1.3),
            vs: rng.uniform(0.0, 6.0),
            ze: rng.uniform(0.7, 1.3),
            ve: rng.uniform(0.0, 6.0),
            vp: 0.0,
            vps: 0.0,
            x: rng.uniform(-0.5, 4.0),
        };
        let Ok((cands, _)) = candidates(&shape, &req, &Refs::default(), &SolveOptions::default())
        else {
            continue;
        };
        real += 1;
        if cands.iter().filter(|c| c.t_e > 0.0).count() == 2 {
            two_positive += 1;
        }
        let n = cands
            .iter()
            .filter(|c| c.t_e > 0.0 && c.u > 0.0 && c.w > 0.0)
            .count();
        assert!(n <= 1, "query {i}: {n} roots with u, w > 0: {cands:?}");
    }
    // The property is not vacuous: most queries have real roots, many two positive ones.
    assert!(
        real > 250 && two_positive > 50,
        "{real} real, {two_positive} two positive"
    );
}

#[test]
fn root_choice_follows_t_orig_when_two_are_admissible() {
    // A reversal (vs > 0, ve < 0) can make both roots admissible (§6.5): search for one.
    let mut rng = Rng::new(0x5eed_0006);
    let mut found = 0;
    for _ in 0..4000 {
        let m = random_model(&mut rng);
        let shape = StanceShape::from_model(&m, false, false, None);
        let req = Request {
            zs: rng.uniform(0.7, 1.3),
            vs: rng.uniform(0.0, 3.0),
            ze: rng.uniform(0.7, 1.3),
            ve: rng.uniform(-3.0, 0.0),
            vp: 0.0,
            vps: 0.0,
            x: rng.uniform(-2.0, 2.0),
        };
        let Ok(s) = solve(&shape, &req, &Refs::default(), None) else {
            continue;
        };
        let Some(t2) = s.other_t_e else { continue };
        found += 1;
        assert!(s.t_e < t2, "no T_orig: the smaller T");
        let near2 = solve(&shape, &req, &Refs::default(), Some(t2 + 1e-3)).unwrap();
        assert_eq!((near2.t_e, near2.other_t_e), (t2, Some(s.t_e)));
        let near1 = solve(&shape, &req, &Refs::default(), Some(s.t_e - 1e-3)).unwrap();
        assert_eq!((near1.t_e, near1.other_t_e), (s.t_e, Some(t2)));
        check_by_simulation(&m, &req, &near2, "second root");
    }
    assert!(found > 0, "no query with two admissible roots");
}

#[test]
fn never_nan_on_hostile_inputs() {
    let mut rng = Rng::new(0x5eed_0007);
    let pool = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        1e-300,
        1e300,
        -1e300,
        f64::MAX,
        f64::INFINITY,
        f64::NAN,
        3.0,
        0.5,
    ];
    let pick = |rng: &mut Rng| pool[(rng.next_f64() * pool.len() as f64) as usize];
    for _ in 0..20_000 {
        let m = random_model(&mut rng);
        let mut shape =
            StanceShape::from_model(&m, rng.next_f64() < 0.5, rng.next_f64() < 0.5, None);
        if rng.next_f64() < 0.3 {
            shape.j[(rng.next_f64() * 3.0) as usize] = pick(&mut rng);
        }
        if rng.next_f64() < 0.3 {
            shape.ref_signs = Some((pick(&mut rng), pick(&mut rng)));
        }
        let req = Request {
            zs: pick(&mut rng),
            vs: pick(&mut rng),
            ze: pick(&mut rng),
            ve: pick(&mut rng),
            vp: pick(&mut rng),
            vps: pick(&mut rng),
            x: pick(&mut rng),
        };
        let refs = Refs {
            beta_h: pick(&mut rng),
            beta_p: pick(&mut rng),
            beta_v: pick(&mut rng),
        };
        if let Ok(s) = solve(&shape, &req, &refs, Some(pick(&mut rng))) {
            assert!(s
                .beta
                .iter()
                .chain(&[s.t_td, s.t_lo, s.t_e, s.y])
                .all(|v| v.is_finite()));
            assert!(s.t_e > 0.0 && s.beta[2] > 0.0);
        }
    }
}

#[test]
fn ties_go_to_the_smaller_t() {
    let c = |t_e: f64| Candidate {
        beta: [1.0; 3],
        t_td: 0.0,
        t_e,
        u: 0.1,
        w: 0.1,
    };
    // 1 and 3 are exactly 1 from T_orig = 2: a tie, to the smaller T (either order).
    for t_orig in [Some(2.0), None] {
        assert!(better(&c(1.0), &c(3.0), t_orig));
        assert!(!better(&c(3.0), &c(1.0), t_orig));
    }
    assert!(better(&c(3.0), &c(1.0), Some(2.5)));
    assert!(!better(&c(1.0), &c(1.0), Some(2.5)));
}

#[test]
fn shape_from_a_library_stance() {
    use crate::constraints::{precompute, StanceContext};
    use crate::stances::params::{Heading, HeadingFrom};
    let mut rng = Rng::new(0x5eed_0008);
    let model = random_model(&mut rng);
    let v_td = [3.0, 0.0, -0.8];
    let p = model_consistent(v_td, 0.9, model.j(), model.p(), model.dt_s);
    let ctx = StanceContext {
        vs: p.vs,
        vps: p.vps,
        t_td: p.t_td,
        z_td: p.z_td,
        cp: [0.0; 2],
    };
    let stance = Stance {
        stance_id: "clip:L:10".into(),
        clip: "clip".into(),
        character_id: "c".into(),
        label: "L".into(),
        effectors: vec!["LeftFoot".into()],
        first_frame: 10,
        last_frame: 20,
        td_clip_s: 1.0,
        lo_clip_s: 1.0 + model.dt_s,
        dt_s: model.dt_s,
        boundary_start: Boundary::Flight,
        boundary_end: Boundary::NoFlight,
        rest_at_edge: false,
        flight_before: None,
        flight_after: None,
        heading: Heading {
            e_h: [1.0, 0.0, 0.0],
            from: HeadingFrom::WorldX,
        },
        z_c: 0.0,
        params: p,
        measured: p,
        mass_kg: model.mass_kg,
        coef: precompute(&model, &ctx),
        model: model.clone(),
        cp: [0.0; 2],
        force_model: crate::force_model::ForceModelKind::Fourier,
        ratio: Default::default(),
        warnings: vec![],
    };
    let shape = StanceShape::from_stance(&stance);
    assert!(shape.before_flight && !shape.after_flight);
    assert_eq!(shape.ref_signs, shape.centroid_split(p.t_td, p.t_e));
    assert_eq!(
        (shape.j, shape.k, shape.dt),
        (model.j(), model.k(), model.dt_s)
    );
    let s = solve(&shape, &request_of(&p), &Refs::default(), Some(p.t_e)).unwrap();
    // Identity query, as in the random identity test: 1e-9.
    assert!(s.beta.iter().all(|b| (b - 1.0).abs() < 1e-9));
    assert!((s.t_td - p.t_td).abs() < 1e-9);
}
