//! "Run at speed v" (spec stance-model §6.8): steady run cycles made by scaling the
//! horizontal forces of recorded running stances, for the recorded character or a new one
//! by dynamic similarity (§9).
//!
//! # Model
//! ```text
//! cycle: stances S1, S2 consecutive in one clip, opposite feet (L→R or R→L), flight
//!        boundaries on both sides of both, chaining |ve1 − vs2| ≤ 0.05 v_orig and
//!        |(ze1 + z_c1) − (zs2 + z_c2)| ≤ 0.02 m
//! v_orig = Σ x_k / Σ T_k                       mean speed of the cycle (m/s)
//! k = v / v_orig;  (vs, ve, x) := k·(vs, ve, x)_orig, zs, ze, vp, vps unchanged
//! ⇒ β_h = k, β_v = β_p = 1, times unchanged (A1–A5)
//! ```
//! Each scaled stance is solved by [`super::solve::solve`] (no shortcut: the
//! policy's outcome is checked, not assumed), its contact point re-solved (§8.3, `H_des`
//! = the stance's own `H`), then filtered (eq 10, 12) and checked exactly (§7.4) against
//! the character's absolute limits (§7.5), scaled by `M` (force) and `L` (lengths).
//!
//! # References
//! spec stance-model §6.8, §7.5, §8.3, §9; CORRECTIONS Issue 4 items 4–7.

use crate::error::Error;
use crate::force_model::GRAVITY;
use crate::stances::segment::Boundary;

use super::feasibility::{
    approx, contact_point_with, exact, exact_at_contact_point, exact_feasible, Limits,
    QueryContext, Verdict,
};
use super::gait::{GaitLaw, LawSource};
use super::pool::{PoolStance, Prepared};
use super::solve::{solve, Refs, Request, Solution};

/// Chaining tolerance on the flight's horizontal speed, as a fraction of `v_orig`.
pub const CHAIN_SPEED_FRACTION: f64 = 0.05;
/// Chaining tolerance on the flight's apex height (absolute heights), m.
pub const CHAIN_HEIGHT_M: f64 = 0.02;

/// Most rows of one run sweep (`query run`, `[queries] run_speeds`): cycles × speeds,
/// count. A row holds two stances' lists: about 1.3 kB at the peak while the table is
/// built (measured), so 1.3 GB at the limit.
pub const MAX_RUN_ROWS: usize = 1_000_000;

/// Checks a sweep of `n_cycles` cycles at `n_speeds` speeds against [`MAX_RUN_ROWS`].
///
/// # Errors
/// [`ErrorKind::Cap`](crate::error::ErrorKind::Cap) naming `field`.
pub fn check_sweep(field: &str, n_cycles: usize, n_speeds: usize) -> Result<(), Error> {
    let n = n_cycles as f64 * n_speeds as f64;
    if n > MAX_RUN_ROWS as f64 {
        let what = "rows (run cycles × speeds)";
        return Err(Error::cap(field, what, n, MAX_RUN_ROWS, "MAX_RUN_ROWS"));
    }
    Ok(())
}

/// Checks a target speed of `field`: finite and ≥ 0 m/s.
///
/// # Errors
/// [`ErrorKind::Invalid`](crate::error::ErrorKind::Invalid) naming `field`.
pub fn check_speed(field: &str, v: f64) -> Result<f64, Error> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        let msg = format!("speeds must be finite and ≥ 0 m/s, found {v}");
        Err(Error::invalid(field, msg))
    }
}

/// Checks a §9 scale of `field` (length or mass ratio): positive and finite.
///
/// # Errors
/// [`ErrorKind::Invalid`](crate::error::ErrorKind::Invalid) naming `field`.
pub fn check_scale(field: &str, v: f64) -> Result<f64, Error> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a positive number, found {v}"),
        ))
    }
}

/// A recorded run cycle: two chained stances of one clip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunCycle {
    /// Indices of the two stances in the pool, in time order.
    pub stances: [usize; 2],
    /// Mean speed of the cycle `Σx/ΣT`, m/s.
    pub v_orig: f64,
}

/// Why two consecutive stances are not a cycle (for reports).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotACycle {
    /// Not on opposite single feet (`L` then `R` or `R` then `L`).
    Feet,
    /// A boundary of either stance is not a flight.
    Boundaries,
    /// The two ends of the shared flight differ by more than the chaining tolerance.
    Chaining,
    /// `Σx/ΣT` is not a positive finite speed.
    Speed,
}

/// Is `(a, b)` (consecutive stances of one clip) a run cycle (§6.8)?
///
/// # Errors
/// The first rule the pair breaks.
pub fn cycle_of(a: &PoolStance, b: &PoolStance) -> Result<f64, NotACycle> {
    let feet = matches!(
        (a.label.as_str(), b.label.as_str()),
        ("L", "R") | ("R", "L")
    );
    if !feet {
        return Err(NotACycle::Feet);
    }
    let flights = [
        a.boundary_start,
        a.boundary_end,
        b.boundary_start,
        b.boundary_end,
    ]
    .iter()
    .all(|&k| k == Boundary::Flight);
    if !flights {
        return Err(NotACycle::Boundaries);
    }
    let (pa, pb) = (&a.params, &b.params);
    let v_orig = (pa.x + pb.x) / (pa.t_e + pb.t_e);
    if !(v_orig.is_finite() && v_orig > 0.0) {
        return Err(NotACycle::Speed);
    }
    let speed_ok = (pa.ve - pb.vs).abs() <= CHAIN_SPEED_FRACTION * v_orig;
    let height_ok = ((pa.ze + a.z_c) - (pb.zs + b.z_c)).abs() <= CHAIN_HEIGHT_M;
    if speed_ok && height_ok {
        Ok(v_orig)
    } else {
        Err(NotACycle::Chaining)
    }
}

/// Every run cycle of a pool sorted by (clip, first frame): consecutive pairs of one clip.
pub fn run_cycles(pool: &[PoolStance]) -> Vec<RunCycle> {
    (1..pool.len())
        .filter(|&i| pool[i - 1].clip == pool[i].clip)
        .filter_map(|i| {
            cycle_of(&pool[i - 1], &pool[i])
                .ok()
                .map(|v_orig| RunCycle {
                    stances: [i - 1, i],
                    v_orig,
                })
        })
        .collect()
}

/// Cycles within this speed ratio of a character's nearest cycle are used for a target
/// speed (the clip recorded nearest in speed, and any other clip as near).
pub const NEAREST_SPEED_RATIO: f64 = 1.1;

/// Which cycles answer a target speed: per character, those whose speed is within
/// [`NEAREST_SPEED_RATIO`] of the character's cycle nearest to `speed` (in `ln v`).
///
/// `cycles` gives each cycle's `(character, v_orig)`; the result is one flag per cycle.
pub fn nearest_in_speed(cycles: &[(&str, f64)], speed: f64) -> Vec<bool> {
    let dist = |v: f64| (v / speed.max(1e-9)).ln().abs();
    let mut best: std::collections::BTreeMap<&str, f64> = std::collections::BTreeMap::new();
    for &(ch, v) in cycles {
        let d = dist(v);
        best.entry(ch).and_modify(|b| *b = b.min(d)).or_insert(d);
    }
    cycles
        .iter()
        .map(|&(ch, v)| dist(v) <= best[ch] + NEAREST_SPEED_RATIO.ln())
        .collect()
}

/// Each character's clips summarised for its gait law ([`super::gait::fit`]): per clip,
/// the medians over its cycles of the speed, the stances' contact times `Δt` and their
/// apex-to-apex periods `T`.
pub fn clip_gaits(
    pool: &[PoolStance],
    cycles: &[RunCycle],
) -> std::collections::BTreeMap<String, Vec<super::gait::ClipGait>> {
    use crate::math::stats::median;
    let mut per_clip: std::collections::BTreeMap<(&str, &str), [Vec<f64>; 3]> =
        std::collections::BTreeMap::new();
    for c in cycles {
        let a = &pool[c.stances[0]];
        let e = per_clip
            .entry((a.character_id.as_str(), a.clip.as_str()))
            .or_default();
        e[0].push(c.v_orig);
        for &i in &c.stances {
            e[1].push(pool[i].model.dt_s);
            e[2].push(pool[i].params.t_e);
        }
    }
    let mut out: std::collections::BTreeMap<String, Vec<super::gait::ClipGait>> =
        std::collections::BTreeMap::new();
    for ((ch, _), v) in per_clip {
        let [a, b, c] = &v;
        let m = |v: &[f64]| median(v).unwrap_or(f64::NAN);
        out.entry(ch.to_string())
            .or_default()
            .push(super::gait::ClipGait {
                speed: m(a),
                contact_s: m(b),
                step_s: m(c),
            });
    }
    out
}

/// Each character's gait law under `choice`, from its clips' cycles ([`clip_gaits`]).
pub fn character_laws(
    pool: &[PoolStance],
    cycles: &[RunCycle],
    choice: super::gait::LawChoice,
) -> std::collections::BTreeMap<String, GaitLaw> {
    clip_gaits(pool, cycles)
        .iter()
        .map(|(ch, clips)| (ch.clone(), choice.law(clips)))
        .collect()
}

/// The request of the run-at-speed policy for one stance: `(vs, ve, x)·k`.
pub fn policy_request(p: &PoolStance, k: f64) -> Request {
    let q = &p.params;
    Request {
        zs: q.zs,
        vs: k * q.vs,
        ze: q.ze,
        ve: k * q.ve,
        vp: q.vp,
        vps: q.vps,
        x: k * q.x,
    }
}

/// The request of a stance under a gait law (docs stance-model §6.8b): the heading speeds
/// keep their fluctuation about the cycle's mean, scaled by `κ`, about a new mean `u`:
///
/// ```text
/// vs = u + κ (vs₀ − v₀),   ve = u + κ (ve₀ − v₀),   zs, ze, vp, vps as recorded
/// ```
///
/// (`v₀`: the recorded cycle's mean speed, m/s). `x` is the recorded one until the caller
/// sets it from the period ([`distance_for_period`]). With `κ = u/v₀` this is
/// [`policy_request`] at `k = u/v₀`.
pub fn law_request(p: &PoolStance, v_orig: f64, kappa: f64, u: f64) -> Request {
    let q = &p.params;
    Request {
        vs: u + kappa * (q.vs - v_orig),
        ve: u + kappa * (q.ve - v_orig),
        ..policy_request(p, 1.0)
    }
}

/// One scaled stance of a cycle: the solution and its verdicts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaledStance {
    /// The closed-form solution (β, event times).
    pub solution: Solution,
    /// Eq 5, 10, 12 and the stance's `unilateral_ok` (§7.3).
    pub feasible_approx: bool,
    /// The exact check at the re-solved contact point (§7.4).
    pub verdict: Verdict,
    /// The re-solved contact point `u* = (cp_h, cp_p)`, m (the data one when undetermined).
    pub cp: [f64; 2],
}

/// Solves and checks one stance of a query: the closed form, the contact point for
/// `H_des = H_orig`, the filters and the exact check.
///
/// # Errors
/// The solver's reason when no admissible solution exists.
pub fn scale_and_check(
    p: &Prepared,
    req: &Request,
    refs: &Refs,
    lim: &Limits,
) -> Result<ScaledStance, super::solve::Infeasible> {
    let s = &p.stance;
    let sol = solve(&p.shape, req, refs, Some(s.params.t_e))?;
    Ok(check_solution(p, req, &sol, lim))
}

/// The query context of a solved stance (§6.3: `z_TD = zs − ½ g t_TD²`), at the data
/// contact point.
fn query_context(p: &Prepared, req: &Request, sol: &Solution) -> QueryContext {
    QueryContext {
        vs: req.vs,
        vps: req.vps,
        t_td: sol.t_td,
        z_td: req.zs - 0.5 * GRAVITY * sol.t_td * sol.t_td,
        cp: p.stance.cp,
    }
}

/// The fast filters of a solved stance: eq 5, 10, 12 and its `unilateral_ok` (§7.3).
fn approx_ok(p: &Prepared, beta: [f64; 3], lim: &Limits) -> bool {
    let c = &p.stance.coef;
    c.unilateral_ok && approx(c.a_f, c.a_mu, beta, lim)
}

/// `(approximate, exact)` verdicts only, the exact one at the re-solved contact point and
/// stopping at the first violation: what [`check_solution`] decides, without its extremes.
pub fn verdicts(p: &Prepared, req: &Request, sol: &Solution, lim: &Limits) -> (bool, bool) {
    let mut ctx = query_context(p, req, sol);
    let s = &p.stance;
    if let Some(u) = contact_point_with(&p.moments, sol.beta, &ctx, s.coef.ang_impulse) {
        ctx.cp = u;
    }
    (
        approx_ok(p, sol.beta, lim),
        exact_feasible(&p.grids, &s.model, &ctx, sol.beta, lim),
    )
}

/// The filters and the exact check of a solved stance, with the scaled stance's extremes.
pub fn check_solution(p: &Prepared, req: &Request, sol: &Solution, lim: &Limits) -> ScaledStance {
    let s = &p.stance;
    let ctx = query_context(p, req, sol);
    let beta = sol.beta;
    let feasible_approx = approx_ok(p, beta, lim);
    let (verdict, u) = exact_at_contact_point(
        &p.grids,
        &s.model,
        &p.moments,
        &ctx,
        beta,
        s.coef.ang_impulse,
        lim,
    );
    ScaledStance {
        solution: *sol,
        feasible_approx,
        verdict,
        cp: u.unwrap_or(s.cp),
    }
}

/// The checks of a solved stance with its contact at `cp` (m, stance axes `(h, p)`) instead
/// of the re-solved `u*`: an edit that moved its contact for the legs to reach
/// (`edit::footing`) is judged where its foot is.
pub fn check_at_contact(
    p: &Prepared,
    req: &Request,
    sol: &Solution,
    lim: &Limits,
    cp: [f64; 2],
) -> ScaledStance {
    let ctx = QueryContext {
        cp,
        ..query_context(p, req, sol)
    };
    ScaledStance {
        solution: *sol,
        feasible_approx: approx_ok(p, sol.beta, lim),
        verdict: exact(&p.grids, &p.stance.model, &ctx, sol.beta, lim),
        cp,
    }
}

/// Absolute limits of the source character for a character `L` times as long and `M` times
/// as heavy (§9: `F_max` by `M`, `χ` by `L`, `μ` unchanged).
pub fn scale_limits(lim: &Limits, length: f64, mass: f64) -> Limits {
    Limits {
        mu: lim.mu,
        f_max: lim.f_max * mass,
        chi_min: lim.chi_min * length,
        chi_max: lim.chi_max * length,
    }
}

/// The times of a run at the target speed (the gait law's answer for one cycle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// The law used.
    pub law: GaitLaw,
    /// Contact-time scale `σ_c` (each stance lasts `σ_c Δt₀`).
    pub sigma_c: f64,
    /// Step-period scale `σ_T` (each stance's apex-to-apex period is `σ_T T₀`).
    pub sigma_t: f64,
    /// Speed-fluctuation scale `κ = (v/v₀) σ_c σ_T`: each stance's change of heading speed
    /// about the cycle's mean scales by it ([`law_request`]); `v/v₀` under the paper's law.
    pub kappa: f64,
}

/// Speed ratios `v/v₀` below this are timed as at this ratio: a jog in place keeps a
/// finite contact time (the power law would stretch it without bound as `v → 0`).
pub const LAW_MIN_SPEED_RATIO: f64 = 0.25;

impl Timing {
    /// The law's scales from a cycle at `v_orig` to `speed` (m/s), the ratio floored at
    /// [`LAW_MIN_SPEED_RATIO`].
    pub fn of(law: &GaitLaw, v_orig: f64, speed: f64) -> Self {
        let v = speed.max(LAW_MIN_SPEED_RATIO * v_orig);
        let (sigma_c, sigma_t) = law.time_scales(v_orig, v);
        Timing {
            law: *law,
            sigma_c,
            sigma_t,
            kappa: v / v_orig * sigma_c * sigma_t,
        }
    }
}

/// One candidate of `query run`: a cycle at one speed for one character.
#[derive(Debug, Clone, PartialEq)]
pub struct RunCandidate {
    /// Target speed, m/s.
    pub speed: f64,
    /// The policy's speed factor `k` (`vs`, `ve` and `x` scale by it); `v / v_orig` under
    /// the paper's law.
    pub k: f64,
    /// The cycle's mean speed after the character scaling, m/s.
    pub v_orig: f64,
    /// The times asked of the cycle.
    pub timing: Timing,
    /// Per stance of the cycle: the outcome, or why it has no solution.
    pub stances: [Result<ScaledStance, super::solve::Infeasible>; 2],
}

impl RunCandidate {
    /// Feasible after the exact check: both stances solved and exactly feasible.
    pub fn feasible(&self) -> bool {
        self.stances
            .iter()
            .all(|s| s.as_ref().is_ok_and(|s| s.verdict.feasible))
    }

    /// Both stances pass the fast filters.
    pub fn feasible_approx(&self) -> bool {
        self.stances
            .iter()
            .all(|s| s.as_ref().is_ok_and(|s| s.feasible_approx))
    }
}

/// The heading distance `x` that makes `T` a root of the master quadratic of a request
/// whose other parameters are `req`'s (A4, with `t_TD` from A3 and A5):
///
/// ```text
/// t_TD = T/2 − s̄_v − Δz/(g T),   x = ve T − d t_TD − β_h K_h,
/// d = ve − vs,  β_h = d/J_h (β_h,ref when J_h ≈ 0, §6.4 (ii))
/// ```
///
/// Used with the time-scaled stance's shape (`J̃ = σJ`, `K̃ = σ²K`) by the gait law
/// (`query run`, `edit run`): the period `T` is chosen, the distance follows.
pub fn distance_for_period(
    shape: &super::solve::StanceShape,
    req: &Request,
    refs: &Refs,
    t: f64,
) -> f64 {
    let d = req.ve - req.vs;
    let t_td = t / 2.0 - shape.k[2] / shape.j[2] - (req.ze - req.zs) / (GRAVITY * t);
    let near_zero = shape.j[0].abs() <= super::solve::DEFAULT_EPS_J * shape.j_scale[0];
    let beta_h = if near_zero {
        refs.beta_h
    } else {
        d / shape.j[0]
    };
    req.ve * t - d * t_td - beta_h * shape.k[0]
}

/// A cycle's requests under a gait law ([`law_request`]): each stance's end apex at its
/// period `T_i`, its distance from the period ([`distance_for_period`]), and the mean level
/// `u` that makes the cycle's speed `v` exactly:
///
/// ```text
/// x_i(u) = x_i(0) + u T_i      (A4 is affine in u: d = κ (ve₀ − vs₀) and t_TD do not involve it)
/// u = v − (x_1(0) + x_2(0)) / (T_1 + T_2)      ⇒  Σ x_i / Σ T_i = v
/// β_h,ref = κ/σ_c              (the heading force's scale, J̃_h = σ_c J_h)
/// ```
///
/// Returns the requests, the references and `u` (m/s).
pub fn law_requests(
    timed: [&Prepared; 2],
    v_orig: f64,
    speed: f64,
    timing: &Timing,
    t_target: [f64; 2],
) -> ([Request; 2], Refs, f64) {
    let refs = Refs::run(timing.kappa / timing.sigma_c);
    let at = |u: f64| {
        [0, 1].map(|i| {
            let mut r = law_request(&timed[i].stance, v_orig, timing.kappa, u);
            r.x = distance_for_period(&timed[i].shape, &r, &refs, t_target[i]);
            r
        })
    };
    let zero = at(0.0);
    let u = speed - (zero[0].x + zero[1].x) / (t_target[0] + t_target[1]);
    (at(u), refs, u)
}

/// The run policy with time as a degree of freedom, for one cycle of (already
/// character-scaled) prepared stances.
///
/// ```text
/// (σ_c, σ_T, κ) from the gait law;  each stance: Δt̃ = σ_c Δt₀, target T_i = σ_T T_i0
/// request_i = law_requests (speeds u + κ(v₀ᵢ − v₀), distance from T_i, Σx/ΣT = v exactly)
///   → solve (root nearest T_i) → check;   k = u / v_orig
/// ```
///
/// Under [`GaitLaw::PAPER`] this is the paper's policy (`σ = 1`, `k = v/v_orig`, §6.5 rule 3
/// as recorded). Under a law, rule 3 (the apex outside the stance) is replaced by "both
/// flights of the cycle exist" (`(T₁ − t_LO,1) + t_TD,2 ≥ 0` and `(T₂ − t_LO,2) + t_TD,1 ≥ 0`,
/// else [`super::solve::Infeasible::FlightRule`] on the stance after it): a jog's apex
/// lies inside its stance (the 2 m/s force-plate jog: `t_E − t_LO` = −24 ms), and the law,
/// not the recorded split, says how long the flight is.
/// `v_orig` is the scaled cycle's mean speed; `lims` each stance's limits.
pub fn run_at_speed(
    cycle: [&Prepared; 2],
    v_orig: f64,
    speed: f64,
    law: &GaitLaw,
    lims: [&Limits; 2],
) -> RunCandidate {
    let timing = Timing::of(law, v_orig, speed);
    let paper = law.source == LawSource::Paper;
    let timed: [std::borrow::Cow<Prepared>; 2] = cycle.map(|p| {
        if paper {
            return std::borrow::Cow::Borrowed(p);
        }
        let s = p.stance.time_scaled(timing.sigma_c);
        let mut t = Prepared::with_active_fraction(s, p.grids.active_fraction);
        // The law sets every time; the flight rule becomes "a flight exists" (below).
        (t.shape.before_flight, t.shape.after_flight) = (false, false);
        std::borrow::Cow::Owned(t)
    });
    let t_target = cycle.map(|p| timing.sigma_t * p.stance.params.t_e);
    let (requests, refs, k) = if paper {
        let k = speed / v_orig;
        (cycle.map(|p| policy_request(&p.stance, k)), Refs::run(k), k)
    } else {
        let (requests, refs, u) =
            law_requests([&timed[0], &timed[1]], v_orig, speed, &timing, t_target);
        (requests, refs, u / v_orig)
    };
    let check = |i: usize| {
        let p: &Prepared = &timed[i];
        let req = requests[i];
        if !(k.is_finite() && k >= 0.0) {
            return Err(super::solve::Infeasible::InvalidInput);
        }
        let sol = solve(&p.shape, &req, &refs, Some(t_target[i]))?;
        Ok(check_solution(p, &req, &sol, lims[i]))
    };
    let mut stances = [check(0), check(1)];
    if !paper {
        if let [Ok(a), Ok(b)] = &stances {
            // The cycle's two flights (periodic): from each liftoff to the other stance's
            // touchdown through their shared apex.
            let (a, b) = (a.solution, b.solution);
            let flights = [(a.t_e - a.t_lo) + b.t_td, (b.t_e - b.t_lo) + a.t_td];
            for (i, f) in flights.iter().enumerate() {
                if *f < -super::solve::DEFAULT_ADMISSIBLE_TOL {
                    stances[1 - i] = Err(super::solve::Infeasible::FlightRule);
                }
            }
        }
    }
    RunCandidate {
        speed,
        k,
        v_orig,
        timing,
        stances,
    }
}

#[cfg(test)]
mod tests;
