//! Shared test tools of the query modules: random force models (on `crate::testkit`'s
//! generator and builder) and an independent forward simulation (RK4 on the model force,
//! no closed form).

use super::solve::{Request, Solution};
use crate::force_model::{AxisModel, ForceModel, GRAVITY};
use crate::stances::segment::Boundary;
use crate::testkit::Harmonics;
pub(crate) use crate::testkit::Rng;

/// The harmonic content of the query tests' random axes: 1–3 cosines of harmonics 1–4.
const HARMONICS: Harmonics = Harmonics {
    terms: 3,
    max_j: 4,
    halves: false,
};

/// A DC term plus 1–3 cosines of harmonics 1–4 (`testkit::random_axis`).
pub fn random_axis(rng: &mut Rng, c0: f64, amp: f64) -> AxisModel {
    crate::testkit::random_axis(rng, c0, amp, HARMONICS)
}

/// A runner-like model: |c0_h| ∈ [20, 300] N, J_v > 0 (c0_v ∈ [1.3, 3]·m g).
pub fn random_model(rng: &mut Rng) -> ForceModel {
    let m = rng.uniform(45.0, 95.0);
    let sign = if rng.next_f64() < 0.5 { -1.0 } else { 1.0 };
    let c0_h = sign * rng.uniform(20.0, 300.0);
    let c0_p = rng.uniform(-100.0, 100.0);
    let c0_v = rng.uniform(1.3, 3.0) * m * GRAVITY;
    ForceModel {
        mass_kg: m,
        dt_s: rng.uniform(0.1, 0.35),
        axes: [
            random_axis(rng, c0_h, 300.0),
            random_axis(rng, c0_p, 100.0),
            random_axis(rng, c0_v, 0.5 * c0_v),
        ],
    }
}

pub fn scaled(m: &ForceModel, beta: [f64; 3]) -> ForceModel {
    let mut s = m.clone();
    for (a, b) in s.axes.iter_mut().zip(beta) {
        a.c0 *= b;
        a.amps.iter_mut().for_each(|c| *c *= b);
    }
    s
}

pub type State = [f64; 6]; // position then velocity, stance axes

/// RK4 from `t0` to `t1` (either direction) of the COM ODE with the applied force
/// `β f((t − t_td)/Δt)` (no closed form used); ballistic legs pass `β = 0`.
pub fn rk4(
    m: &ForceModel,
    beta: [f64; 3],
    t_td: f64,
    y: State,
    t0: f64,
    t1: f64,
    n: usize,
) -> State {
    let acc = |t: f64, y: &State| -> State {
        let tau = (t - t_td) / m.dt_s;
        let mut d = [y[3], y[4], y[5], 0.0, 0.0, -GRAVITY];
        for a in 0..3 {
            d[3 + a] += beta[a] * m.axes[a].eval(tau) / m.mass_kg;
        }
        d
    };
    let h = (t1 - t0) / n as f64;
    let mut y = y;
    for i in 0..n {
        let t = t0 + h * i as f64;
        let k1 = acc(t, &y);
        let k2 = acc(
            t + h / 2.0,
            &std::array::from_fn(|j| y[j] + h / 2.0 * k1[j]),
        );
        let k3 = acc(
            t + h / 2.0,
            &std::array::from_fn(|j| y[j] + h / 2.0 * k2[j]),
        );
        let k4 = acc(t + h, &std::array::from_fn(|j| y[j] + h * k3[j]));
        y = std::array::from_fn(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
    }
    y
}

/// Stance steps: h = Δt/4000 ≤ 1e-4 s, so RK4's O(h⁴) error is ≲ 1e-12 m.
pub const RK4_STEPS: usize = 4000;

/// Start apex → end apex with the solution's β and times; returns the end state.
pub fn simulate(m: &ForceModel, req: &Request, s: &Solution) -> State {
    let y0 = [0.0, 0.0, req.zs, req.vs, req.vps, 0.0];
    // Ballistic legs are exact for RK4 (quadratic positions); stance leg is fine-stepped.
    let y = rk4(m, [0.0; 3], s.t_td, y0, 0.0, s.t_td, 4);
    let y = rk4(m, s.beta, s.t_td, y, s.t_td, s.t_lo, RK4_STEPS);
    rk4(m, [0.0; 3], s.t_td, y, s.t_lo, s.t_e, 4)
}

/// Asserts that a simulated end state `y` (of [`simulate`]) is the request's end apex:
/// `x`, `ze` and `ve` within `tol` (m, m/s); `what` names the case in the message.
pub fn assert_reaches_end_apex(y: &State, req: &Request, tol: f64, what: &str) {
    for (name, got, want) in [
        ("x", y[0], req.x),
        ("ze", y[2], req.ze),
        ("ve", y[3], req.ve),
    ] {
        assert!((got - want).abs() < tol, "{what}: {name} {got} vs {want}");
    }
}

/// A stance-like model (`testkit::bell_model`): vertical bell `A(1 − cos 2πτ)` plus small
/// ringing (up to 0.04 body weights), random horizontal forces.
pub fn bell_model(rng: &mut Rng) -> ForceModel {
    crate::testkit::bell_model(rng, 0.04, HARMONICS)
}

/// A library stance made from a model and a touchdown state (model-consistent parameters,
/// coefficients precomputed at the data contact point `cp`), on ground height `z_c`.
pub fn pool_stance(
    id: &str,
    model: ForceModel,
    v_td: [f64; 3],
    z_td: f64,
    bounds: (Boundary, Boundary),
    label: &str,
    cp: [f64; 2],
) -> super::pool::PoolStance {
    let params =
        crate::stances::params::model_consistent(v_td, z_td, model.j(), model.p(), model.dt_s);
    let ctx = crate::constraints::StanceContext {
        vs: params.vs,
        vps: params.vps,
        t_td: params.t_td,
        z_td: params.z_td,
        cp,
    };
    super::pool::PoolStance {
        stance_id: id.to_string(),
        clip: "synthetic".into(),
        character_id: "sk-test".into(),
        label: label.into(),
        first_frame: 0,
        boundary_start: bounds.0,
        boundary_end: bounds.1,
        z_c: 0.0,
        params,
        coef: crate::constraints::precompute(&model, &ctx),
        model,
        cp,
    }
}

/// A bell model with no perpendicular force and a horizontal force dominated by its DC
/// term `push · m g` (a straight jump: push off forward, or brake on landing).
pub fn jump_model(rng: &mut Rng, push: f64) -> ForceModel {
    let mut m = bell_model(rng);
    let weight = m.mass_kg * GRAVITY;
    m.axes[1] = AxisModel::constant(0.0);
    m.axes[0].c0 = push * weight;
    m.axes[0].amps.iter_mut().for_each(|c| *c *= 0.1);
    m
}

/// A recorded jump: a liftoff stance and the landing stance after the same flight.
pub fn recorded_pair(rng: &mut Rng) -> (super::pool::Prepared, super::pool::Prepared) {
    let s1 = loop {
        let v_td1 = [rng.uniform(0.0, 1.5), 0.0, -rng.uniform(0.0, 0.3)];
        let push = rng.uniform(0.1, 0.3);
        let s = pool_stance(
            "up",
            jump_model(rng, push),
            v_td1,
            rng.uniform(0.8, 1.0),
            (Boundary::Rest, Boundary::Flight),
            "LR",
            [rng.uniform(-0.1, 0.2), 0.0],
        );
        if s.params.t_e >= s.params.t_lo {
            break s; // lifts off rising: a real flight follows
        }
    };
    // The landing touches down t_TD2 after the flight's apex, where S1's end apex is.
    let q1 = s1.params;
    let t_td2 = rng.uniform(0.2, 0.4);
    let v_td2 = [q1.ve, q1.vp, -GRAVITY * t_td2];
    let z_td2 = q1.ze - 0.5 * GRAVITY * t_td2 * t_td2;
    let brake = -rng.uniform(0.1, 0.3);
    let s2 = pool_stance(
        "down",
        jump_model(rng, brake),
        v_td2,
        z_td2,
        (Boundary::Flight, Boundary::Rest),
        "LR",
        [rng.uniform(-0.1, 0.2), 0.0],
    );
    (
        super::pool::Prepared::new(s1),
        super::pool::Prepared::new(s2),
    )
}
