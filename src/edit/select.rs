//! Choosing what an edit plays, from a prepared library: the run cycle solved at a speed
//! and the liftoff → landing pair of a jump.
//!
//! # Policy
//! ```text
//! run:  every run cycle of a clip the queries keep (`query::limits::left_out_clips`:
//!       copies and clips whose time base is wrong are left out unless `keep_left_out`;
//!       or the one named), each solved at the target speed v (m/s) as `query run` does
//!       (docs stance-model §6.8a–b): its stances stretched in time by the gait law's σ_c
//!       (contact Δt = σ_c Δt₀), the periodic requests of the κ law
//!       (`plan::law_run_requests`: vs, ve = u + κ(v₀ᵢ − v₀)), each stance's distance from
//!       the law's period σ_T·T₀ (`query::run::distance_for_period`), leaned to
//!       β_h = κ/σ_c, β_p = 1 (`lean`), and the mean level u refined until Σx/ΣT = v
//!       (`refine_run_k` on k = u/v₀, started from the query's `law_requests`); under the
//!       paper's law k = v/(v_orig·√L) scales (vs, ve, x) (`plan::run_requests`);
//!       best = feasible first, then the least |k − 1| (the least change of the recorded
//!       speed), ties by the order of the cycles (stance id order)
//! jump: the named pair; else, without both a height and a distance, the library's first
//!       recorded jump (of a clip the queries keep); else every liftoff × landing of one
//!       clip the queries keep, each solved by
//!       `query::jump`; best = `query::pairs::jump_rank` (feasible first, then the least
//!       change of the recorded forces)
//! ```
//! Pure: the library and the pool are in memory; the I/O is in `pipeline::commands::edit`.

use std::collections::BTreeMap;

use super::lean::leaned;
use super::plan::{
    cycle_speed, law_run_requests, refine_run_k, run_requests, solve_stance, EditStance,
    StanceTiming,
};
use crate::error::{Error, Result};
use crate::library::readers::read::StanceLibrary;
use crate::query::feasibility::{LimitForm, Limits};
use crate::query::gait::{GaitLaw, LawChoice, LawSource};
use crate::query::jump::{is_landing, is_liftoff, jump, recorded_jump, Jump};
use crate::query::limits::{absolute_limits, jump_limits, left_out_clips, stance_limits, LeftOut};
use crate::query::pairs::jump_rank;
use crate::query::pool::Prepared;
use crate::query::run::{
    character_laws, distance_for_period, law_requests, run_cycles, scale_limits, RunCycle, Timing,
};
use crate::query::solve::Refs;

/// The limits an edit's stances are checked against (§7.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EditLimits {
    /// Absolute or relative limits.
    pub form: LimitForm,
    /// Friction limit μ (`None`: the form's default).
    pub mu: Option<f64>,
    /// Active fraction of the friction check.
    pub active: f64,
}

/// A run edit's request: speed and character.
#[derive(Debug, Clone, PartialEq)]
pub struct RunTarget {
    /// Target speed, m/s.
    pub speed_mps: f64,
    /// Leg-length ratio target/recorded (dynamic similarity, §9).
    pub length_scale: f64,
    /// Body-mass ratio target/recorded.
    pub mass_scale: f64,
    /// The cycle's first stance id; `None`: the best cycle.
    pub stance: Option<String>,
    /// How contact time and step period change with speed (`query::gait`).
    pub gait_law: LawChoice,
    /// Keep the cycles of clips the queries leave out (`query::limits::left_out_clips`).
    pub keep_left_out: bool,
}

/// The chosen run cycle: its speed factor `k`, its timing and its two solved stances.
#[derive(Debug, Clone)]
pub struct ChosenRun {
    /// Speed factor `u / v_orig` of the cycle's mean speed (`k` of the paper's policy).
    pub k: f64,
    /// The recorded cycle's mean speed (character-scaled), m/s.
    pub v_orig: f64,
    /// The gait law's scales at the target speed (`query::run::Timing`).
    pub timing: Timing,
    /// The solved cycle's mean speed `Σx/ΣT`, m/s ([`cycle_speed`]).
    pub speed_mps: f64,
    /// The two stances, in time order.
    pub stances: Vec<EditStance>,
    /// Cycles left out with their clips (`query::limits::left_out_clips`; empty with
    /// `keep_left_out`), one entry per cycle.
    pub left_out: Vec<(String, LeftOut)>,
}

/// A solved candidate: its speed factor and its stances or why it has none.
type RunCandidate = (f64, std::result::Result<Vec<EditStance>, String>);

/// Solves every candidate run cycle of `lib` for `target` and returns the best
/// (see the module docs).
///
/// # Errors
/// No run cycle (or `target.stance` is not the first stance of one), or no candidate has
/// a solution at the speed.
pub fn choose_run(
    lib: &StanceLibrary,
    pool: &[Prepared],
    times: &[StanceTiming],
    target: &RunTarget,
    limits: EditLimits,
) -> Result<ChosenRun> {
    let (length, mass) = (target.length_scale, target.mass_scale);
    let absolute: BTreeMap<String, Limits> = absolute_limits(lib)
        .into_iter()
        .map(|(k, l)| (k, scale_limits(&l, length, mass)))
        .collect();
    let left = if target.keep_left_out {
        BTreeMap::new()
    } else {
        left_out_clips(lib)
    };
    let clip_of = |cy: &RunCycle| &lib.stances[cy.stances[0]].clip;
    let named = |cy: &RunCycle| {
        target
            .stance
            .as_ref()
            .is_none_or(|id| &lib.stances[cy.stances[0]].stance_id == id)
    };
    let (cycles, skipped): (Vec<RunCycle>, Vec<RunCycle>) = run_cycles(&lib.stances)
        .into_iter()
        .filter(named)
        .partition(|cy| !left.contains_key(clip_of(cy)));
    let left_out: Vec<(String, LeftOut)> = skipped
        .iter()
        .map(|cy| (clip_of(cy).clone(), left[clip_of(cy)].clone()))
        .collect();
    if cycles.is_empty() {
        return Err(match (&target.stance, left_out.first()) {
            (Some(id), Some((clip, why))) => Error::invalid(
                "--stance",
                format!("{id}: its clip {clip} is left out ({why}); --keep-left-out keeps it"),
            ),
            (Some(id), None) => Error::invalid(
                "--stance",
                format!("{id}: not the first stance of a run cycle in the library"),
            ),
            (None, _) => no_run_cycle(),
        });
    }
    let laws = character_laws(&lib.stances, &cycles, target.gait_law);
    let solved: Vec<(RunCandidate, f64, Timing)> = cycles
        .iter()
        .map(|cy| {
            let ch = &lib.stances[cy.stances[0]].character_id;
            let law = laws.get(ch).copied().unwrap_or(GaitLaw::POPULATION);
            let v_orig = cy.v_orig * length.sqrt();
            let timing = Timing::of(&law, v_orig, target.speed_mps);
            let c = solve_cycle(
                lib, pool, times, target, limits, &absolute, cy, v_orig, &timing,
            );
            (c, v_orig, timing)
        })
        .collect();
    let best = solved.into_iter().min_by(|x, y| {
        let (a, b) = (run_rank(&x.0), run_rank(&y.0));
        a.0.cmp(&b.0).then(a.1.total_cmp(&b.1))
    });
    match best {
        Some(((k, Ok(stances)), v_orig, timing)) => Ok(ChosenRun {
            k,
            v_orig,
            timing,
            speed_mps: cycle_speed(&stances),
            stances,
            left_out,
        }),
        Some(((_, Err(e)), ..)) => Err(Error::invalid(
            "--speed",
            format!("no solution at {} m/s: {e}", target.speed_mps),
        )),
        None => Err(no_run_cycle()),
    }
}

/// One cycle solved at the target speed (module docs): under a gait law its stances
/// stretched by `σ_c`, the periodic requests of the law (`law_run_requests`: speeds
/// `u + κ(v − v₀)`), each stance leaned to `β_h = κ/σ_c` (the query's), its distance from
/// the law's period `σ_T·T₀`, and `u` refined until the cycle runs at the target speed;
/// under the paper's policy the requests at `k` ([`run_requests`]).
#[allow(clippy::too_many_arguments)]
fn solve_cycle(
    lib: &StanceLibrary,
    pool: &[Prepared],
    times: &[StanceTiming],
    target: &RunTarget,
    limits: EditLimits,
    absolute: &BTreeMap<String, Limits>,
    cy: &RunCycle,
    v_orig: f64,
    timing: &Timing,
) -> RunCandidate {
    let (length, mass) = (target.length_scale, target.mass_scale);
    let paper = timing.law.source == LawSource::Paper;
    let prep = cy.stances.map(|i| {
        let s = pool[i].stance.scaled(length, mass);
        let t_e0 = s.params.t_e;
        let s = if paper {
            s
        } else {
            s.time_scaled(timing.sigma_c)
        };
        // Stretching in time leaves the coefficients the limits read unchanged.
        let p = Prepared::with_active_fraction(s, limits.active);
        let lim = stance_limits(&p, limits.form, absolute, limits.mu);
        (p, lim, t_e0)
    });
    let t_target = [0, 1].map(|n| timing.sigma_t * prep[n].2);
    // The law's mean level of the query (`law_requests`, not yet periodic): the start of
    // the refinement.
    let k0 = if paper {
        target.speed_mps / v_orig
    } else {
        let (_, _, u) = law_requests(
            [&prep[0].0, &prep[1].0],
            v_orig,
            target.speed_mps,
            timing,
            t_target,
        );
        u / v_orig
    };
    refine_run_k(target.speed_mps, k0, |k| {
        let (req, beta_h) = if paper {
            (run_requests([&prep[0].0.stance, &prep[1].0.stance], k), k)
        } else {
            let s = [&prep[0].0.stance, &prep[1].0.stance];
            let req = law_run_requests(s, v_orig, timing.kappa, k * v_orig);
            (req, timing.kappa / timing.sigma_c)
        };
        let refs = Refs::run(beta_h);
        let cycle: std::result::Result<Vec<EditStance>, String> = (0..2)
            .map(|n| {
                let (p, lim, _) = &prep[n];
                let mut lean = leaned(p, &req[n], [beta_h, 1.0], limits.active);
                let mut request = req[n];
                if !paper {
                    // The law's period; the distance follows (§6.8a), and the flight rule
                    // becomes "the cycle's flights exist" (below).
                    request.x = distance_for_period(&lean.shape, &request, &refs, t_target[n]);
                    (lean.shape.before_flight, lean.shape.after_flight) = (false, false);
                }
                let i = cy.stances[n];
                let mut e = solve_stance(&lib.stances[i], times[i], &lean, request, &refs, lim)?;
                e.time_scale = if paper { 1.0 } else { timing.sigma_c };
                Ok(e)
            })
            .collect();
        let cycle = cycle?;
        if !paper {
            let (a, b) = (&cycle[0].scaled.solution, &cycle[1].scaled.solution);
            let flights = [(a.t_e - a.t_lo) + b.t_td, (b.t_e - b.t_lo) + a.t_td];
            if flights.iter().any(|f| *f < 0.0) {
                return Err(format!(
                    "no flight at {} m/s: the gait law's contact time outlasts the step",
                    target.speed_mps
                ));
            }
        }
        Ok(cycle)
    })
}

/// Rank of a run candidate: (infeasible or unsolved, |k − 1|); smaller is better.
fn run_rank((k, r): &RunCandidate) -> (bool, f64) {
    match r {
        Ok(v) => (v.iter().any(|e| e.violated().is_some()), (k - 1.0).abs()),
        Err(_) => (true, f64::INFINITY),
    }
}

fn no_run_cycle() -> Error {
    Error::invalid(
        "run cycles",
        "none in the library (two chained single-foot stances between flights)",
    )
}

/// A jump edit's request: apex height and distance, or a scale of the recorded height.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpTarget {
    /// Apex height above the liftoff contact, m (`None`: the recorded pair's, × the scale).
    pub height_m: Option<f64>,
    /// The recorded apex height times this (when no height is given).
    pub height_scale: Option<f64>,
    /// Jump distance, m (`None`: the recorded pair's).
    pub distance_m: Option<f64>,
    /// `LIFTOFF_ID:LANDING_ID`; `None`: chosen (see the module docs).
    pub pair: Option<String>,
    /// Keep the pairs of clips the queries leave out (`query::limits::left_out_clips`);
    /// a pair given by `pair` is always kept.
    pub keep_left_out: bool,
}

/// The chosen jump: the pair's pool indices, the request and the solution.
#[derive(Debug, Clone)]
pub struct ChosenJump {
    /// (liftoff, landing) indices in the library.
    pub pair: [usize; 2],
    /// Apex height requested, m.
    pub height_m: f64,
    /// Distance requested, m.
    pub distance_m: f64,
    /// The two sides' solution.
    pub jump: Jump,
    /// The limits each side was checked against (§7.5).
    pub limits: [Limits; 2],
    /// Clips whose pairs were left out, one entry per pair (empty with `keep_left_out` or
    /// a given pair).
    pub left_out: Vec<(String, LeftOut)>,
}

/// Solves every candidate pair of `lib` for `target` and returns the best.
///
/// # Errors
/// A bad or missing pair, no liftoff and landing of one clip, or no solution for the best
/// pair.
pub fn choose_jump(
    lib: &StanceLibrary,
    pool: &[Prepared],
    target: &JumpTarget,
    limits: EditLimits,
) -> Result<ChosenJump> {
    let absolute = absolute_limits(lib);
    let both = target.height_m.is_some() && target.distance_m.is_some();
    let left = if target.keep_left_out || target.pair.is_some() {
        BTreeMap::new()
    } else {
        left_out_clips(lib)
    };
    let (candidates, skipped): (Vec<_>, Vec<_>) =
        jump_candidates(lib, target.pair.as_deref(), both, &left)?
            .into_iter()
            .partition(|&(i, _)| !left.contains_key(&lib.stances[i].clip));
    let left_out: Vec<(String, LeftOut)> = skipped
        .iter()
        .map(|&(i, _)| {
            let clip = &lib.stances[i].clip;
            (clip.clone(), left[clip].clone())
        })
        .collect();
    let solved: Vec<_> = candidates
        .iter()
        .map(|&(i, j)| {
            let (h0, d0) = recorded_jump(&lib.stances[i], &lib.stances[j]);
            let h = target
                .height_m
                .unwrap_or(h0 * target.height_scale.unwrap_or(1.0));
            let d = target.distance_m.unwrap_or(d0);
            let lim = [i, j]
                .map(|s| jump_limits(&pool[s], limits.form, &absolute, limits.mu, &lib.clips));
            let r = jump(&pool[i], &pool[j], h, d, Some(lim)).map_err(|e| e.to_string());
            ([i, j], h, d, r, lim)
        })
        .collect();
    let best = solved.into_iter().min_by(|x, y| {
        let (a, b) = (jump_rank(&x.3), jump_rank(&y.3));
        a.0.cmp(&b.0).then(a.1.total_cmp(&b.1))
    });
    let Some((pair, h, d, result, limits)) = best else {
        let why = match left_out.first() {
            Some((clip, why)) => format!(
                "no liftoff and landing stance of one clip in the library but of clips left \
                 out ({clip}: {why}); --keep-left-out keeps them"
            ),
            None => "no liftoff and landing stance of one clip in the library".into(),
        };
        return Err(Error::invalid("jump pairs", why));
    };
    match result {
        Ok(jump) => Ok(ChosenJump {
            pair,
            height_m: h,
            distance_m: d,
            jump,
            limits,
            left_out,
        }),
        Err(e) => Err(Error::invalid(
            "--height",
            format!(
                "no solution for height {h} m, distance {d} m ({} → {}): {e}",
                lib.stances[pair[0]].stance_id, lib.stances[pair[1]].stance_id
            ),
        )),
    }
}

/// The first recorded jump of a library: a liftoff followed by a landing in its clip;
/// one of a clip not in `left_out` when there is one.
pub fn recorded_pair(
    lib: &StanceLibrary,
    left_out: &BTreeMap<String, LeftOut>,
) -> Option<(usize, usize)> {
    let s = &lib.stances;
    let jumps = (1..s.len())
        .filter(|&i| s[i - 1].clip == s[i].clip && is_liftoff(&s[i - 1]) && is_landing(&s[i]))
        .map(|i| (i - 1, i));
    let mut first = None;
    for (i, j) in jumps {
        if !left_out.contains_key(&s[i].clip) {
            return Some((i, j));
        }
        first = first.or(Some((i, j)));
    }
    first
}

/// The (liftoff, landing) stance indices of `LIFTOFF_ID:LANDING_ID`.
///
/// # Model
/// ```text
/// p = LIFTOFF_ID ":" LANDING_ID,  each id = clip ":" label ":" frame
/// ```
/// A clip name may hold `:` itself (`take:01`), so `p` is split at the `:` where both
/// halves are stance ids of the library; no quoting is needed. When no split gives two
/// held ids, the split at the middle `:` names the unknown id (and its nearest ids); when
/// several do (possible only with clip names of that very shape), the pair is ambiguous
/// and each candidate is named.
///
/// # Errors
/// Not two stance ids, an unknown id, an ambiguous split, or a stance of the wrong kind.
pub fn given_pair(lib: &StanceLibrary, p: &str) -> Result<(usize, usize)> {
    let bad = |msg: String| Error::invalid("--pair", msg);
    let index = |id: &str| {
        lib.stances
            .iter()
            .position(|s| s.stance_id == id)
            .ok_or_else(|| {
                let held = lib.stances.iter().map(|s| s.stance_id.as_str());
                bad(crate::stances::ids::unknown_stance_message(id, held))
            })
    };
    let held = |id: &str| lib.stances.iter().position(|s| s.stance_id == id);
    let splits: Vec<(usize, usize)> = p
        .match_indices(':')
        .filter_map(|(k, _)| Some((held(&p[..k])?, held(&p[k + 1..])?)))
        .collect();
    let (i, j) = match splits[..] {
        [one] => one,
        [] => {
            // Stance ids hold ':' themselves (<clip>:<label>:<frame>): with clip names
            // of as many ':', the pair splits at its middle ':'.
            let colons: Vec<usize> = p.match_indices(':').map(|(k, _)| k).collect();
            if colons.len() < 5 || colons.len().is_multiple_of(2) {
                return Err(bad(format!(
                    "expected LIFTOFF_ID:LANDING_ID (each <clip>:<label>:<frame>), found {}",
                    crate::error::echo(p)
                )));
            }
            let k = colons[colons.len() / 2];
            (index(&p[..k])?, index(&p[k + 1..])?)
        }
        _ => {
            let named: Vec<String> = splits
                .iter()
                .map(|&(a, b)| {
                    format!(
                        "{} and {}",
                        lib.stances[a].stance_id, lib.stances[b].stance_id
                    )
                })
                .collect();
            return Err(bad(format!(
                "{} splits into stance ids of this library in {} ways ({}): ambiguous",
                crate::error::echo(p),
                splits.len(),
                named.join("; ")
            )));
        }
    };
    if !is_liftoff(&lib.stances[i]) {
        return Err(bad(format!(
            "{} is not a liftoff stance (rest or clip edge, then flight)",
            lib.stances[i].stance_id
        )));
    }
    if !is_landing(&lib.stances[j]) {
        return Err(bad(format!(
            "{} is not a landing stance (flight, then rest or clip edge)",
            lib.stances[j].stance_id
        )));
    }
    if lib.stances[i].clip != lib.stances[j].clip {
        return Err(bad(format!(
            "{} and {} are of different clips: the edit poses both stances from one source clip",
            lib.stances[i].stance_id, lib.stances[j].stance_id
        )));
    }
    Ok((i, j))
}

/// The (liftoff, landing) pairs a jump edit may use: the given pair; else, without both a
/// height and a distance, the library's first recorded jump (of a clip not in
/// `left_out` when there is one); else every liftoff and landing of one clip.
///
/// # Errors
/// A bad `pair`, or no recorded jump when one is needed.
pub fn jump_candidates(
    lib: &StanceLibrary,
    pair: Option<&str>,
    height_and_distance: bool,
    left_out: &BTreeMap<String, LeftOut>,
) -> Result<Vec<(usize, usize)>> {
    let given = match pair {
        Some(p) => Some(given_pair(lib, p)?),
        None if !height_and_distance => Some(recorded_pair(lib, left_out).ok_or_else(|| {
            Error::invalid(
                "--pair",
                "no recorded jump (liftoff then landing in one clip) in the library: give --pair",
            )
        })?),
        None => None,
    };
    if let Some(p) = given {
        return Ok(vec![p]);
    }
    let s = &lib.stances;
    let ups = (0..s.len()).filter(|&i| is_liftoff(&s[i]));
    Ok(ups
        .flat_map(|i| {
            (0..s.len())
                .filter(|&j| is_landing(&s[j]))
                .map(move |j| (i, j))
        })
        .filter(|&(i, j)| s[i].clip == s[j].clip)
        .collect())
}

/// The two stances of a solved jump, as the editor places them.
pub fn jump_stances(
    lib: &StanceLibrary,
    pool: &[Prepared],
    times: &[StanceTiming],
    chosen: &ChosenJump,
) -> Vec<EditStance> {
    chosen
        .pair
        .iter()
        .enumerate()
        .map(|(n, &s)| {
            let (request, scaled) = chosen.jump.sides[n];
            EditStance {
                source: lib.stances[s].clone(),
                timing: times[s],
                prepared: pool[s].clone(),
                request,
                scaled,
                time_scale: 1.0,
                limits: chosen.limits[n],
            }
        })
        .collect()
}
