//! Jumps of apex height `h` and distance `d_jump` from a liftoff and a landing stance
//! (spec stance-model §6.7 pinned modes, §6.9 jumps).
//!
//! # Model
//! ```text
//! S1 (liftoff, pin_start): τ1 = t_TD,1, vs1, zs1 kept;  ve1 = u_apex, ze1 = h, vp1 = 0
//!   T1(h) = (τ1 + s̄_v1) + √((τ1 + s̄_v1)² + 2(h − zs1)/g)
//! S2 (landing, pin_end): e2 = t_E,2 − t_LO,2, ve2, ze2 kept;  vs2 = u_apex, zs2 = h2, vps2 = 0
//!   h2 = h + z_c1 − z_c2
//!   T2(h) = (Δt2 + e2 − s̄_v2) + √((Δt2 + e2 − s̄_v2)² + 2(h2 − ze2)/g),  t_TD2 = T2 − Δt2 − e2
//! D(h) = (T1 − τ1 − s̄_h1) + (t_TD2 + s̄_h2)        time between the horizontal impulse centroids (s)
//! C(h) = vs1 (τ1 + s̄_h1) + ve2 (T2 − t_TD2 − s̄_h2)  (m)
//! d_jump = u_apex·D(h) + C(h)   ⇒   u_apex = (d_jump − C(h)) / D(h)
//! β_h1 = (u_apex − vs1)/J_h1,  β_v1 = g T1/J_v1,  β_p1 = max(0, −vps1/J_p1)   (vp1 = 0)
//! β_h2 = (ve2 − u_apex)/J_h2,  β_v2 = g T2/J_v2,  β_p2 = 1   (vps2 = 0, vp2 = J_p2)
//! flight time = (T1 − τ1 − Δt1) + t_TD2, each part ≥ 0;  d_flight = u_apex · flight time
//! ```
//! `J_p ≈ 0` (the ε_J test of §6.4) keeps `β_p1 = 1`.
//!
//! **Near-vertical jumps** (§6.4 ii made practical): a stance whose heading impulse
//! `|J_h|` is below [`J_H_DEGENERATE_MPS`] cannot set the apex speed — `β_h = Δu/J_h`
//! turns a 0.05 m/s error into Δβ_h ≈ 0.3–0.7, and `s̄_h = K_h/J_h` makes `D(h)` meaningless.
//! Such a stance keeps its recorded heading force (`β_h = 1`):
//! ```text
//! liftoff degenerate:  u_apex = vs1 + J_h1            (landing degenerate too: ve2 = u_apex + J_h2)
//! landing degenerate:  u_apex = ve2 − J_h2
//! ```
//! and the jump's distance is then what A4 gives at that `u_apex`, not a free input: a
//! request whose `d_jump` differs from it by more than [`DEGENERATE_DISTANCE_TOL_M`] fails
//! with [`JumpFailure::DistanceFixed`]. The recorded vertical jump is found at β = 1. Where `−vps1/J_p1 < 0` the recorded
//! perpendicular force pushes along the start drift and no `β_p ≥ 0` stops it: the spec's
//! straight jump is then unreachable, so the perpendicular force is dropped and the small
//! drift `vps1` kept (a stance from rest has `|vps1| < 0.2` m/s). The landing keeps its own
//! perpendicular force (`β_p2 = 1`): it starts in the liftoff's heading with `vps2 = 0`
//! (the editor plays a landing recorded a few degrees off that heading in its own, with
//! the flight's velocity there, `edit::path::PlannedStance::chain_in_own_heading`).
//! Heights are above each stance's contact height `z_c`.
//!
//! # References
//! spec stance-model §6.7, §6.9, §6.10 (pool), §7.5 (relative limits); CORRECTIONS Issue 4
//! items 1, 2, 6 and 7.

use crate::force_model::GRAVITY;
use crate::stances::segment::Boundary;

use super::feasibility::{relative_limits, Limits};
use super::pool::{PoolStance, Prepared};
use super::run::{check_solution, ScaledStance};
use super::solve::{admissible, Branch, Candidate, Infeasible, Request, Solution, StanceShape};
use super::solve::{DEFAULT_ADMISSIBLE_TOL, DEFAULT_EPS_J};

/// `|J_h|` below which a jump stance keeps its recorded heading force (β_h = 1) instead of
/// setting the apex speed, m/s (module docs). Real near-vertical jumps have 0.07–0.18 m/s;
/// running and forward-jump stances ≥ 0.5 m/s.
pub const J_H_DEGENERATE_MPS: f64 = 0.3;
/// How far a near-vertical jump's requested distance may lie from the distance its
/// recorded heading force gives, m.
pub const DEGENERATE_DISTANCE_TOL_M: f64 = 0.02;

/// A liftoff stance: (`rest` or `clip_edge`, `flight`) (§6.10, CORRECTIONS Issue 4 item 1).
pub fn is_liftoff(s: &PoolStance) -> bool {
    matches!(s.boundary_start, Boundary::Rest | Boundary::ClipEdge)
        && s.boundary_end == Boundary::Flight
}

/// A landing stance: (`flight`, `rest` or `clip_edge`).
pub fn is_landing(s: &PoolStance) -> bool {
    s.boundary_start == Boundary::Flight
        && matches!(s.boundary_end, Boundary::Rest | Boundary::ClipEdge)
}

/// Why a jump has no solution before the constraints are checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JumpFailure {
    /// The apex height cannot be reached from the kept approach (negative discriminant).
    Unreachable,
    /// `J_h ≈ 0` or `J_v ≤ 0`: the stance cannot set the horizontal speed or carry weight.
    Degenerate,
    /// `D(h) ≤ 0`: the distance does not determine `u_apex`.
    NoDistanceMap,
    /// A near-vertical jump (`|J_h| < J_H_DEGENERATE_MPS`): its distance is fixed by the
    /// recorded heading force and the request asks for another.
    DistanceFixed,
    /// A rule of §6.5 (sign, centroid, flight) fails for one stance.
    Rule(Infeasible),
}

impl std::fmt::Display for JumpFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            JumpFailure::Unreachable => f.write_str("apex height unreachable"),
            JumpFailure::Degenerate => f.write_str("no net horizontal or vertical impulse"),
            JumpFailure::NoDistanceMap => f.write_str("distance does not determine u_apex"),
            JumpFailure::DistanceFixed => f.write_str(
                "near-vertical jump: its distance is fixed by the recorded heading force",
            ),
            JumpFailure::Rule(r) => write!(f, "{r}"),
        }
    }
}

/// `J_a ≈ 0` per the ε_J test of §6.4.
fn near_zero(shape: &StanceShape, a: usize) -> bool {
    shape.j[a].abs() <= DEFAULT_EPS_J * shape.j_scale[a]
}

/// `β_p` of the liftoff: a straight jump (`vp1 = 0`, A2: `β_p = −vps1/J_p1`) when a
/// non-negative scale reaches it; otherwise the perpendicular force is dropped (`β_p = 0`)
/// and the liftoff keeps its start drift `vps1` (below the 0.2 m/s of the facing fallback,
/// §8.1). `J_p ≈ 0` (§6.4 iii) keeps `β_p = 1`.
fn liftoff_beta_p(shape: &StanceShape, vps: f64) -> f64 {
    if near_zero(shape, 1) {
        1.0
    } else {
        (-vps / shape.j[1]).max(0.0)
    }
}

/// The `u_apex`-independent part of one side of a jump at one height (§6.10 step 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Side {
    /// `T` (s): `T1` of the liftoff or `T2` of the landing.
    pub t_e: f64,
    /// `t_TD` (s): `τ1` kept, or `t_TD2 = T2 − Δt2 − e2`.
    pub t_td: f64,
    /// `β_v = g T/J_v`.
    pub beta_v: f64,
    /// `β_p` (see the module docs: straight jump when reachable).
    pub beta_p: f64,
    /// Start-apex height and heading velocity of the scaled stance (m, m/s; `vs` of the
    /// landing is `u_apex` and left 0 here).
    pub zs: f64,
    /// Start-apex heading velocity (m/s); the landing's is `u_apex` (set per column).
    pub vs: f64,
    /// End-apex height (m).
    pub ze: f64,
    /// End-apex heading velocity (m/s); the liftoff's is `u_apex` (set per column).
    pub ve: f64,
    /// Flight-time part on this side (s): `T1 − τ1 − Δt1` or `t_TD2`.
    pub flight_part: f64,
}

/// Liftoff side at apex height `h` above its contact (pin_start, §6.7).
///
/// # Errors
/// Unreachable height or a degenerate stance.
pub fn liftoff_side(p: &Prepared, h: f64) -> Result<Side, JumpFailure> {
    let (s, sh) = (&p.stance.params, &p.shape);
    if sh.j[2] <= 0.0 || near_zero(sh, 2) || near_zero(sh, 0) {
        return Err(JumpFailure::Degenerate);
    }
    let a = s.t_td + sh.k[2] / sh.j[2];
    let disc = a * a + 2.0 * (h - s.zs) / GRAVITY;
    if disc.is_nan() || disc < 0.0 {
        return Err(JumpFailure::Unreachable);
    }
    let t_e = a + disc.sqrt();
    Ok(Side {
        t_e,
        t_td: s.t_td,
        beta_v: GRAVITY * t_e / sh.j[2],
        beta_p: liftoff_beta_p(sh, s.vps),
        zs: s.zs,
        vs: s.vs,
        ze: h,
        ve: 0.0,
        flight_part: t_e - s.t_td - sh.dt,
    })
}

/// Landing side at apex height `h2` above its contact (pin_end, §6.7).
///
/// # Errors
/// Unreachable height or a degenerate stance.
pub fn landing_side(p: &Prepared, h2: f64) -> Result<Side, JumpFailure> {
    let (s, sh) = (&p.stance.params, &p.shape);
    if sh.j[2] <= 0.0 || near_zero(sh, 2) || near_zero(sh, 0) {
        return Err(JumpFailure::Degenerate);
    }
    let e2 = s.t_e - s.t_lo;
    let a = sh.dt + e2 - sh.k[2] / sh.j[2];
    let disc = a * a + 2.0 * (h2 - s.ze) / GRAVITY;
    if disc.is_nan() || disc < 0.0 {
        return Err(JumpFailure::Unreachable);
    }
    let t_e = a + disc.sqrt();
    let t_td = t_e - sh.dt - e2;
    Ok(Side {
        t_e,
        t_td,
        beta_v: GRAVITY * t_e / sh.j[2],
        beta_p: 1.0,
        zs: h2,
        vs: 0.0,
        ze: s.ze,
        ve: s.ve,
        flight_part: t_td,
    })
}

/// `s̄_a = K_a/J_a` (s).
fn s_bar(shape: &StanceShape, a: usize) -> f64 {
    shape.k[a] / shape.j[a]
}

/// `(D(h), C(h))` of a pair at one height (§6.9): `d_jump = u_apex·D + C`.
pub fn distance_map(p1: &Prepared, s1: &Side, p2: &Prepared, s2: &Side) -> (f64, f64) {
    let (sh1, sh2) = (s_bar(&p1.shape, 0), s_bar(&p2.shape, 0));
    let d = (s1.t_e - s1.t_td - sh1) + (s2.t_td + sh2);
    let c = s1.vs * (s1.t_td + sh1) + s2.ve * (s2.t_e - s2.t_td - sh2);
    (d, c)
}

/// One side at a given `u_apex`: its request, solution (β and times) and §6.5 rules.
///
/// # Errors
/// The first §6.5 rule broken.
pub fn side_solution(
    p: &Prepared,
    side: &Side,
    liftoff: bool,
    u_apex: f64,
) -> Result<(Request, Solution), Infeasible> {
    let s = &p.stance.params;
    let sh = &p.shape;
    let (req, beta_h) = if liftoff {
        let r = Request {
            zs: side.zs,
            vs: side.vs,
            ze: side.ze,
            ve: u_apex,
            vp: s.vps + side.beta_p * sh.j[1],
            vps: s.vps,
            x: 0.0,
        };
        (r, (u_apex - side.vs) / sh.j[0])
    } else {
        let r = Request {
            zs: side.zs,
            vs: u_apex,
            ze: side.ze,
            ve: side.ve,
            vp: sh.j[1],
            vps: 0.0,
            x: 0.0,
        };
        (r, (side.ve - u_apex) / sh.j[0])
    };
    let beta = [beta_h, side.beta_p, side.beta_v];
    // A4 gives the heading distance: x = ve·T − (ve − vs)·t_TD − β_h K_h.
    let x = req.ve * side.t_e - (req.ve - req.vs) * side.t_td - beta_h * sh.k[0];
    let u = side.t_td + s_bar(sh, 2);
    let cand = Candidate {
        beta,
        t_td: side.t_td,
        t_e: side.t_e,
        u,
        w: side.t_e - u,
    };
    admissible(sh, &cand, DEFAULT_ADMISSIBLE_TOL)?;
    let y = req.vps * side.t_e + beta[1] * ((side.t_e - side.t_td) * sh.j[1] - sh.k[1]);
    let sol = Solution {
        beta,
        t_td: side.t_td,
        t_lo: side.t_td + sh.dt,
        t_e: side.t_e,
        y,
        branch: Branch::Quadratic,
        other_t_e: None,
    };
    Ok((Request { x, ..req }, sol))
}

/// A solved jump: both sides checked against their relative limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// Horizontal COM speed at the flight apex, m/s.
    pub u_apex: f64,
    /// Apex height above the liftoff contact, m.
    pub height: f64,
    /// Heading distance from the liftoff's start apex to the landing's end apex, m.
    pub distance: f64,
    /// Flight time, s.
    pub flight_time: f64,
    /// Horizontal distance covered in flight `u_apex · flight_time`, m.
    pub d_flight: f64,
    /// Liftoff and landing: request, solution and verdicts.
    pub sides: [(Request, ScaledStance); 2],
}

impl Jump {
    /// Both sides exactly feasible.
    pub fn feasible(&self) -> bool {
        self.sides.iter().all(|(_, s)| s.verdict.feasible)
    }

    /// Both sides pass the fast filters.
    pub fn feasible_approx(&self) -> bool {
        self.sides.iter().all(|(_, s)| s.feasible_approx)
    }

    /// `max |β_a − 1|` over `β_h1, β_v1, β_h2, β_v2`: how much the recorded forces change.
    pub fn force_change(&self) -> f64 {
        self.sides
            .iter()
            .flat_map(|(_, s)| [s.solution.beta[0], s.solution.beta[2]])
            .map(|b| (b - 1.0).abs())
            .fold(0.0, f64::max)
    }
}

/// The jump of apex height `h` (above `S1`'s contact) and distance `d_jump` from a liftoff
/// and a landing stance, checked against `limits` (each stance's relative limits when
/// `None`).
///
/// # Errors
/// Why no admissible scaling exists (before the constraints).
pub fn jump(
    p1: &Prepared,
    p2: &Prepared,
    h: f64,
    d_jump: f64,
    limits: Option<[Limits; 2]>,
) -> Result<Jump, JumpFailure> {
    let s1 = liftoff_side(p1, h)?;
    let h2 = h + p1.stance.z_c - p2.stance.z_c;
    let mut s2 = landing_side(p2, h2)?;
    let degenerate = [p1, p2].map(|p| p.shape.j[0].abs() < J_H_DEGENERATE_MPS);
    let u_apex = match degenerate {
        [false, false] => {
            let (d, c) = distance_map(p1, &s1, p2, &s2);
            if d.is_nan() || d <= 0.0 {
                return Err(JumpFailure::NoDistanceMap);
            }
            (d_jump - c) / d
        }
        [true, _] => s1.vs + p1.shape.j[0],
        [false, true] => s2.ve - p2.shape.j[0],
    };
    if degenerate == [true, true] {
        s2.ve = u_apex + p2.shape.j[0];
    }
    let lim = limits.unwrap_or([
        relative_limits(&p1.stance.coef),
        relative_limits(&p2.stance.coef),
    ]);
    let (r1, sol1) = side_solution(p1, &s1, true, u_apex).map_err(JumpFailure::Rule)?;
    let (r2, sol2) = side_solution(p2, &s2, false, u_apex).map_err(JumpFailure::Rule)?;
    let fixed = degenerate.contains(&true);
    if fixed && (r1.x + r2.x - d_jump).abs() > DEGENERATE_DISTANCE_TOL_M {
        return Err(JumpFailure::DistanceFixed);
    }
    let flight_time = s1.flight_part + s2.flight_part;
    Ok(Jump {
        u_apex,
        height: h,
        distance: d_jump,
        flight_time,
        d_flight: u_apex * flight_time,
        sides: [
            (r1, check_solution(p1, &r1, &sol1, &lim[0])),
            (r2, check_solution(p2, &r2, &sol2, &lim[1])),
        ],
    })
}

/// The recorded jump of a liftoff followed by a landing: `h = (ze1 + zs2 + z_c2 − z_c1)/2`
/// and `d_jump = x1 + x2` (§6.9, identity jump).
pub fn recorded_jump(s1: &PoolStance, s2: &PoolStance) -> (f64, f64) {
    let h = (s1.params.ze + s2.params.zs + s2.z_c - s1.z_c) / 2.0;
    (h, s1.params.x + s2.params.x)
}

#[cfg(test)]
mod tests;
