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
    approx, contact_point_with, exact_at_contact_point, exact_feasible, Limits, QueryContext,
    Verdict,
};
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
/// [`ErrorKind::Limit`](crate::error::ErrorKind::Limit) naming `field`.
pub fn check_sweep(field: &str, n_cycles: usize, n_speeds: usize) -> Result<(), Error> {
    let n = n_cycles as f64 * n_speeds as f64;
    if n > MAX_RUN_ROWS as f64 {
        let what = "rows (run cycles × speeds)";
        return Err(Error::limit(field, what, n, MAX_RUN_ROWS, "MAX_RUN_ROWS"));
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
        exact_feasible(&p.tables, &s.model, &ctx, sol.beta, lim),
    )
}

/// The filters and the exact check of a solved stance, with the scaled stance's extremes.
pub fn check_solution(p: &Prepared, req: &Request, sol: &Solution, lim: &Limits) -> ScaledStance {
    let s = &p.stance;
    let ctx = query_context(p, req, sol);
    let beta = sol.beta;
    let feasible_approx = approx_ok(p, beta, lim);
    let (verdict, u) = exact_at_contact_point(
        &p.tables,
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

/// One candidate of `query run`: a cycle at one speed for one character.
#[derive(Debug, Clone, PartialEq)]
pub struct RunCandidate {
    /// Target speed, m/s.
    pub speed: f64,
    /// `k = v / v_orig` (the policy's `β_h`).
    pub k: f64,
    /// The cycle's mean speed after the character scaling, m/s.
    pub v_orig: f64,
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

/// The run-at-speed policy for one cycle of (already character-scaled) prepared stances.
///
/// `v_orig` is the scaled cycle's mean speed; `lims` each stance's limits (the target
/// character's absolute limits by default, §7.5).
pub fn run_at_speed(
    cycle: [&Prepared; 2],
    v_orig: f64,
    speed: f64,
    lims: [&Limits; 2],
) -> RunCandidate {
    let k = speed / v_orig;
    let check = |i: usize| {
        let p = cycle[i];
        scale_and_check(p, &policy_request(&p.stance, k), &Refs::run(k), lims[i])
    };
    let stances = [check(0), check(1)];
    RunCandidate {
        speed,
        k,
        v_orig,
        stances,
    }
}

#[cfg(test)]
mod tests;
