//! From a query's answer to a placed plan: the requests of a periodic run cycle, the solved
//! stances, and the chain of stances in the world with their source facts.
//!
//! # Model
//! ```text
//! run cycle S1, S2 under the gait law (`query::run::law_request`, §6.8b): S1's heading
//! speeds u + κ(vs₁ − v₀), u + κ(ve₁ − v₀), its distance from the law's period (the
//! caller's); under the paper's policy at k = v / v_orig: (vs, ve, x)·k, vp kept. Made
//! exactly periodic so N cycles chain: S1 is the law's (policy's) own request, and S2 carries
//! the recorded S2 → S1 speed mismatch (it runs from S1's end apex back to S1's start
//! apex); the recorded cycle's height change is split between its start and its end (the
//! whole cycle sits δ higher, half of what the recording gains over it):
//!   δ = (ze2 − (z_c1 − z_c2) − zs1) / 2
//!   S1: zs = zs1 + δ, vs = vs_S1, ze = ze1 + δ, ve = ve_S1, vp1, vps = 0
//!   S2: zs = ze1 + δ + z_c1 − z_c2, vs = |(ve_S1, vp1)|, ze = zs1 + δ + z_c1 − z_c2,
//!       ve = √(vs_S1² − vp2²), vp2, vps = 0
//!   (paper: vs_S1 = k·vs1, ve_S1 = k·ve1, x = k·x1, k·x2)
//!   each solved leaned (`lean`): β_h = κ/σ_c (paper: k), β_p = 1, the speed change S2's
//!   recorded impulse does not carry added as a constant friction-ratio offset
//! jump: the requests of `query::jump` (they chain by construction: ve1 = vs2 = u_apex)
//! placement: the first stance keeps its recorded heading, and its COM at touchdown is the
//!   recorded one; every later stance is chained at the apex (`path`): a run's along the
//!   apex velocity, a jump's landing in its own recorded heading with the flight's
//!   velocity there as its (vs, vps)
//! detail: each stance carries its recording's residual from the model it plays, joined to
//!   every planned flight (heights ending at 0); a run's travel offsets balanced over its
//!   stances, a jump's first touchdown and last liftoff free (`detail`)
//! ```
//! Each request is solved and checked by the query code (`query::run::scale_and_check`) on
//! the stance the edit plays (the leaned one for a run, `lean`), against the recorded
//! stance's limits.

use super::detail::{balance_travel, recorded_residual, Join, StanceDetail, EDGE_WINDOW_S};
use super::path::{ComPath, PlannedStance};
use super::pose::{Reference, StanceSource};
use super::LEAD_IN_S;
use crate::query::feasibility::Limits;
use crate::query::pool::{PoolStance, Prepared};
use crate::query::run::{law_request, scale_and_check, ScaledStance};
use crate::query::solve::{Refs, Request};
use crate::query::tables::{tightest_detail, violation_detail, violation_name};

use crate::math::v3::V3;

pub use crate::library::codec::stances::StanceTiming;

/// One solved stance of an edit.
#[derive(Debug, Clone)]
pub struct EditStance {
    /// The source stance, unscaled (its timing in the clip).
    pub source: PoolStance,
    /// Its timing in the clip.
    pub timing: StanceTiming,
    /// The character-scaled stance and its sampled grids.
    pub prepared: Prepared,
    /// The request solved.
    pub request: Request,
    /// The solution and verdicts.
    pub scaled: ScaledStance,
    /// The gait law's contact-time scale `σ_c` the stance plays at (`prepared` is the
    /// recorded stance stretched by it; 1 for jumps and the paper's runs).
    pub time_scale: f64,
    /// The limits the stance was checked against (§7.5).
    pub limits: Limits,
}

impl EditStance {
    /// `<stance_id>: <constraint>` when the exact check fails.
    pub fn violated(&self) -> Option<String> {
        self.scaled
            .verdict
            .violated
            .map(|v| format!("{}: {}", self.source.stance_id, violation_name(v)))
    }

    /// `<stance_id>: <constraint> <value> > <limit> (by <margin>)` when the exact check
    /// fails ([`violation_detail`]).
    pub fn violation_detail(&self) -> Option<String> {
        violation_detail(&self.scaled.verdict, &self.limits)
            .map(|d| format!("{}: {d}", self.source.stance_id))
    }

    /// `<stance_id>: <constraint> <value> ≤ <limit> (margin <m>)`: the constraint a feasible
    /// stance is nearest to breaking, with its margin as a fraction of the limit
    /// ([`tightest_detail`]).
    pub fn tightest_detail(&self) -> Option<(f64, String)> {
        tightest_detail(&self.scaled.verdict, &self.limits)
            .map(|(m, d)| (m, format!("{}: {d}", self.source.stance_id)))
    }
}

/// The periodic requests of a run cycle at `k` under the paper's policy (see the module
/// docs): the first stance's speeds and distance × `k`.
///
/// The height shift `δ`: `cmu_09_01_run_mb`'s first cycle ends 1.2 cm higher than it
/// starts; with the whole mismatch at the end (δ = 0) the recorded-speed edit's COM ran
/// 1.5–1.7 cm below the recording through the second stance. With `δ` and the recording's
/// detail (`edit::detail`) it is within 1.28 cm of the recording over the first cycle;
/// `δ` alone takes the largest distance from 2.81 to 2.63 cm (`docs/edited-motion.md`).
pub fn run_requests(s: [&PoolStance; 2], k: f64) -> [Request; 2] {
    let p1 = &s[0].params;
    let first = Request {
        vs: k * p1.vs,
        ve: k * p1.ve,
        x: k * p1.x,
        ..p1_request(s[0])
    };
    periodic(s, first, k * s[1].params.x)
}

/// The periodic requests of a run cycle under a gait law (`query::run::law_request`, docs
/// stance-model §6.8b): the first stance's heading speeds keep their recorded fluctuation
/// about the cycle's mean `v₀`, scaled by `κ`, about the new mean `u`; the second closes
/// the cycle as in [`run_requests`]:
///
/// ```text
/// S1: vs = u + κ (vs₁ − v₀),  ve = u + κ (ve₁ − v₀)
/// S2: vs = |(ve_S1, vp₁)|,    ve = √(vs_S1² − vp₂²)
/// ```
///
/// `s`: the cycle's stances (time-scaled by `σ_c`, character-scaled); `x` of both are the
/// recorded ones, for the caller to set from the law's period
/// (`query::run::distance_for_period`). With `κ = u/v₀` this is [`run_requests`] at
/// `k = u/v₀`.
pub fn law_run_requests(s: [&PoolStance; 2], v_orig: f64, kappa: f64, u: f64) -> [Request; 2] {
    let first = Request {
        vps: 0.0,
        ..law_request(s[0], v_orig, kappa, u)
    };
    periodic(s, first, s[1].params.x)
}

/// The first stance's recorded request (heights, speeds, `vp`, distance; `vps = 0`).
fn p1_request(s: &PoolStance) -> Request {
    let p = &s.params;
    Request {
        zs: p.zs,
        vs: p.vs,
        ze: p.ze,
        ve: p.ve,
        vp: p.vp,
        vps: 0.0,
        x: p.x,
    }
}

/// The cycle made periodic from its first stance's request `first` (recorded heights):
/// the recorded height change split between start and end (`δ`, module docs), the second
/// stance from `first`'s end apex back to its start apex, at distance `x2`.
fn periodic(s: [&PoolStance; 2], first: Request, x2: f64) -> [Request; 2] {
    let (p1, p2) = (&s[0].params, &s[1].params);
    let dz0 = s[0].z_c - s[1].z_c;
    let shift = 0.5 * (p2.ze - dz0 - p1.zs);
    let dz = dz0 + shift;
    [
        Request {
            zs: p1.zs + shift,
            ze: p1.ze + shift,
            vps: 0.0,
            ..first
        },
        Request {
            zs: p1.ze + dz,
            vs: first.ve.hypot(first.vp),
            ze: p1.zs + dz,
            ve: (first.vs.powi(2) - p2.vp * p2.vp).max(0.0).sqrt(),
            vp: p2.vp,
            vps: 0.0,
            x: x2,
        },
    ]
}

/// Most refinements of `k` by [`refine_run_k`].
pub const MAX_SPEED_ITERATIONS: usize = 8;
/// Relative tolerance on the planned cycle speed of [`refine_run_k`].
pub const SPEED_TOL: f64 = 1e-4;

/// Mean speed of a solved run cycle, m/s: `Σ x_k / Σ T_k` (heading distance and
/// apex-to-apex time of each stance, as `v_orig` is defined).
pub fn cycle_speed(stances: &[EditStance]) -> f64 {
    let x: f64 = stances.iter().map(|e| e.request.x).sum();
    let t: f64 = stances.iter().map(|e| e.scaled.solution.t_e).sum();
    x / t
}

/// The run policy's `k` refined so that the solved periodic cycle runs at `speed` (m/s).
///
/// `k = v / v_orig` scales `x` and the edge speeds, but the periodic requests (module docs)
/// keep `vp` and close the cycle in the second stance, so its solved time `T_2` moves and
/// the planned mean speed `Σ x_k / Σ T_k` is not exactly `v` (with the earlier averaged
/// joins: 1.89 m/s for a 2 m/s request on the 3.5 m/s fixture run). Fixed point
/// `k ← k · v / cycle_speed(k)`, at most
/// [`MAX_SPEED_ITERATIONS`] times, until within [`SPEED_TOL`]; the last `k` whose cycle
/// solves is kept (the first one's error is returned when `k0` itself does not solve).
pub fn refine_run_k(
    speed: f64,
    k0: f64,
    mut solve: impl FnMut(f64) -> Result<Vec<EditStance>, String>,
) -> (f64, Result<Vec<EditStance>, String>) {
    let (mut k, mut best) = (k0, solve(k0));
    for _ in 0..MAX_SPEED_ITERATIONS {
        let Ok(cycle) = &best else { break };
        let v = cycle_speed(cycle);
        if !(v.is_finite() && v > 0.0) || (v - speed).abs() <= SPEED_TOL * speed {
            break;
        }
        let next = k * speed / v;
        match solve(next) {
            Ok(c) => (k, best) = (next, Ok(c)),
            Err(_) => break,
        }
    }
    (k, best)
}

/// Solves and checks one request of an edit.
///
/// # Errors
/// `<stance_id>: <reason>` when the closed form has no admissible solution.
pub fn solve_stance(
    source: &PoolStance,
    timing: StanceTiming,
    prepared: &Prepared,
    request: Request,
    refs: &Refs,
    limits: &Limits,
) -> Result<EditStance, String> {
    let scaled = scale_and_check(prepared, &request, refs, limits)
        .map_err(|e| format!("{}: {e}", source.stance_id))?;
    Ok(EditStance {
        source: source.clone(),
        timing,
        prepared: prepared.clone(),
        request,
        scaled,
        time_scale: 1.0,
        limits: *limits,
    })
}

/// Feet in contact (left, right) from a stance label (`L`, `R`, `LR`, `LR+LH`, …).
pub fn feet_of(label: &str) -> [bool; 2] {
    let feet = label.split('+').next().unwrap_or("");
    [feet.contains('L'), feet.contains('R')]
}

/// The model a stance plays, at `β = (1, β_p, 1)` from its own recorded start apex and
/// times (no detail, not stretched by the gait law): what its recording is compared with. `β_p` is the played one: the
/// perpendicular scale is the query's policy (1 for a run, dropped or drift-cancelling for
/// a jump's liftoff), not a request, so the recorded request plays it too.
fn own_path(e: &EditStance) -> PlannedStance {
    // The recorded stance: a stretched one (`time_scale ≠ 1`) back on its own clock.
    let recorded = (e.time_scale != 1.0).then(|| e.prepared.stance.time_scaled(1.0 / e.time_scale));
    let st = recorded.as_ref().unwrap_or(&e.prepared.stance);
    let p = &st.params;
    PlannedStance {
        source: 0,
        model: st.model.clone(),
        beta: [1.0, e.scaled.solution.beta[1], 1.0],
        zs: p.zs,
        vs: p.vs,
        vps: p.vps,
        t_td: p.t_td,
        t_lo: p.t_lo,
        t_e: p.t_e,
        z_c: st.z_c,
        cp: st.cp,
        t0: 0.0,
        origin: [0.0, 0.0],
        heading: e.timing.heading,
        detail: None,
    }
}

/// The recording's detail of every solved stance (`detail`), joined to the plan as `kind`
/// plays them in `order`; `None` for a stance with too few recorded frames.
///
/// A run's stances join flights at both edges and their travel offsets are balanced over
/// them (the cycle's mean speed holds). A jump starts at its first touchdown and ends at
/// its last liftoff: those two edges join no flight and keep the recording's slopes (and
/// the last its offsets), and the travel offsets are kept, so the recorded jump edits back
/// to its recording (the library's distance is the model's; the edit travels it plus the
/// recording's offsets from its model, as the recording does).
pub fn details(
    stances: &[EditStance],
    order: &[usize],
    reference: &Reference,
    kind: PlanKind,
) -> Vec<Option<StanceDetail>> {
    let jump = kind.is_jump();
    let (first, last) = (order.first().copied(), order.last().copied());
    let mut out: Vec<Option<StanceDetail>> = stances
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let own = own_path(e);
            let t = &e.timing;
            let (u, rho) = recorded_residual(
                |c| reference.com_at(c),
                |s| own.local(s).0,
                |w| own.to_local(w),
                (t.td_clip_s, t.lo_clip_s),
                reference.motion.frame_time_s,
                (own.t_td, own.t_lo),
            );
            let sol = &e.scaled.solution;
            let join = Join {
                start: !(jump && first == Some(i)),
                end: !(jump && last == Some(i)),
                window: EDGE_WINDOW_S * reference.length_scale.sqrt() / (sol.t_lo - sol.t_td),
            };
            StanceDetail::from_samples(&u, &rho).map(|d| d.joined(join))
        })
        .collect();
    if !jump {
        balance_travel(&mut out);
    }
    out
}

/// What an edit plays: its path's ends and how its stances chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanKind {
    /// Run cycles: apex to apex, each stance chained along the apex velocity
    /// ([`PlannedStance::chain`]).
    Run,
    /// A recorded jump from rest (the landing follows the liftoff in its clip): first
    /// touchdown to last liftoff, the landing in its own recorded heading, so the body
    /// turns between them as it did in the recording
    /// ([`PlannedStance::chain_in_own_heading`]).
    Jump,
    /// A liftoff and a landing of different recorded jumps: as [`PlanKind::Jump`], but the
    /// landing is turned onto the liftoff's heading (their recorded headings are
    /// unrelated: a clip may turn around between its jumps).
    PairedJump,
}

impl PlanKind {
    /// A jump, recorded or paired.
    pub fn is_jump(self) -> bool {
        matches!(self, PlanKind::Jump | PlanKind::PairedJump)
    }
}

/// Places the sequence `order` of solved stances in the world: the first keeps its recorded
/// heading and touchdown COM (from `reference`), the rest chain at their apexes as `kind`
/// says; each carries its recording's detail ([`details`]).
pub fn place(
    stances: &[EditStance],
    order: &[usize],
    reference: &Reference,
    kind: PlanKind,
) -> (ComPath, Vec<StanceSource>) {
    let jump = kind.is_jump();
    let detail = details(stances, order, reference, kind);
    let planned_of = |e: &EditStance, source: usize| PlannedStance {
        source,
        model: e.prepared.stance.model.clone(),
        beta: e.scaled.solution.beta,
        zs: e.request.zs,
        vs: e.request.vs,
        vps: e.request.vps,
        t_td: e.scaled.solution.t_td,
        t_lo: e.scaled.solution.t_lo,
        t_e: e.scaled.solution.t_e,
        z_c: e.prepared.stance.z_c,
        cp: e.scaled.cp,
        t0: 0.0,
        origin: [0.0, 0.0],
        heading: e.timing.heading,
        detail: detail[source].clone(),
    };
    let mut planned: Vec<PlannedStance> = Vec::with_capacity(order.len());
    for &i in order {
        let mut p = planned_of(&stances[i], i);
        match planned.last() {
            None => {
                let c_td = reference.com_at(stances[i].timing.td_clip_s);
                let (l, _) = p.local(p.t_td);
                let w = p.to_world(l);
                p.origin = [c_td[0] - w[0], c_td[1] - w[1]];
                if jump {
                    p.t0 = -p.t_td;
                }
            }
            Some(prev) if jump => {
                if kind == PlanKind::PairedJump {
                    p.heading = prev.heading;
                }
                prev.chain_in_own_heading(&mut p);
            }
            Some(prev) => {
                prev.chain(&mut p);
            }
        }
        planned.push(p);
    }
    let (first, last) = (&planned[0], &planned[planned.len() - 1]);
    let t_start = if jump {
        first.t0 + first.t_td
    } else {
        first.t0
    };
    let t_end = if jump {
        last.t0 + last.t_lo
    } else {
        last.end()
    };
    // A jump's first stance starts from the recording's rest (or the clip's first frame):
    // the recording before it is written too, so re-ingested, the stance begins as its
    // source did (`LEAD_IN_S`).
    let lead_in_s = if jump {
        let td = stances[order[0]].timing.td_clip_s;
        (td - reference.first_time_s()).clamp(0.0, LEAD_IN_S)
    } else {
        0.0
    };
    let sources = stances
        .iter()
        .map(|e| {
            let (s, t) = (&e.source, &e.timing);
            let c = reference.com_at(t.td_clip_s);
            let [hx, hy] = t.heading;
            let cp = e.prepared.stance.cp;
            let anchor: V3 = [
                c[0] + hx * cp[0] - hy * cp[1],
                c[1] + hy * cp[0] + hx * cp[1],
                e.prepared.stance.z_c,
            ];
            StanceSource {
                stance_id: s.stance_id.clone(),
                td_clip_s: t.td_clip_s,
                lo_clip_s: t.lo_clip_s,
                before_s: s.params.t_td,
                after_s: s.params.t_e - s.params.t_lo,
                heading_rad: hy.atan2(hx),
                anchor,
                feet: feet_of(&s.label),
                drift: reference.foot_drift(t.td_clip_s, t.lo_clip_s),
            }
        })
        .collect();
    (
        ComPath {
            stances: planned,
            t_start,
            t_end,
            lead_in_s,
        },
        sources,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::testkit::{bell_model, pool_stance};
    use crate::stances::segment::Boundary;
    use crate::testkit::Rng;

    /// Two running stances of one cycle, the second on ground `z_c2` and ending at `ze2`.
    fn cycle(z_c2: f64, ze2: f64) -> [PoolStance; 2] {
        let mut rng = Rng::new(0x5eed_1406);
        let b = (Boundary::Flight, Boundary::Flight);
        let s1 = pool_stance(
            "c:R:1",
            bell_model(&mut rng),
            [3.5, 0.0, -0.6],
            0.9,
            b,
            "R",
            [0.1, 0.0],
        );
        let mut s2 = pool_stance(
            "c:L:40",
            bell_model(&mut rng),
            [3.5, 0.0, -0.6],
            0.9,
            b,
            "L",
            [0.1, 0.0],
        );
        s2.z_c = z_c2;
        s2.params.ze = ze2;
        [s1, s2]
    }

    #[test]
    fn run_requests_close_the_cycle_and_split_its_recorded_height_change() {
        for (z_c2, rise) in [(0.0, 0.012), (0.03, -0.02), (-0.01, 0.0)] {
            let s = cycle(0.0, 0.0);
            let (p1, z_c1) = (s[0].params, s[0].z_c);
            // The recorded cycle ends `rise` above its start (world heights).
            let s = cycle(z_c2, p1.zs + z_c1 + rise - z_c2);
            for k in [0.8, 1.0, 1.3] {
                let [r1, r2] = run_requests([&s[0], &s[1]], k);
                // World heights: S1's end apex is S2's start, S2's end is S1's start.
                assert!((r1.ze + z_c1 - (r2.zs + z_c2)).abs() < 1e-12);
                assert!((r2.ze + z_c2 - (r1.zs + z_c1)).abs() < 1e-12);
                // Half the recorded change on every apex; none for a periodic recording.
                assert!((r1.zs - p1.zs - 0.5 * rise).abs() < 1e-12, "rise {rise}");
                assert!((r1.ze - p1.ze - 0.5 * rise).abs() < 1e-12);
                assert_eq!(r1.vs, k * p1.vs);
            }
        }
    }

    #[test]
    fn law_requests_at_kappa_equal_to_the_speed_ratio_are_the_policys() {
        let s = cycle(0.01, 0.0);
        let v0 = 3.4;
        for k in [0.6, 1.0, 1.4] {
            let law = law_run_requests([&s[0], &s[1]], v0, k, k * v0);
            let mut policy = run_requests([&s[0], &s[1]], k);
            // The law leaves the distances for the period to set.
            policy[0].x = s[0].params.x;
            policy[1].x = s[1].params.x;
            for (a, b) in law.iter().zip(&policy) {
                for (x, y) in [
                    (a.zs, b.zs),
                    (a.vs, b.vs),
                    (a.ze, b.ze),
                    (a.ve, b.ve),
                    (a.vp, b.vp),
                    (a.vps, b.vps),
                    (a.x, b.x),
                ] {
                    // u + k (v − v₀) = k v up to one rounding of each term.
                    assert!((x - y).abs() < 1e-12, "k {k}: {a:?} vs {b:?}");
                }
            }
        }
        // Another κ keeps the mean u and scales each fluctuation about v₀ by κ.
        let (p1, u, kappa) = (s[0].params, 4.0, 0.5);
        let [r1, r2] = law_run_requests([&s[0], &s[1]], v0, kappa, u);
        assert!((r1.vs - (u + kappa * (p1.vs - v0))).abs() < 1e-12);
        assert!((r1.ve - (u + kappa * (p1.ve - v0))).abs() < 1e-12);
        // The cycle closes: S2 starts at S1's end speed and ends at S1's start speed.
        assert!((r2.vs - r1.ve.hypot(r1.vp)).abs() < 1e-12);
        assert!((r2.ve.hypot(r2.vp) - r1.vs).abs() < 1e-12);
    }
}
