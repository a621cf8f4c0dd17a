//! `query run` at the I/O edge: a speed sweep of the library's run cycles from typed
//! options, its table (and figure) written atomically.
//!
//! # References
//! spec stance-model §6.8 (run), §7.5 (limits), §9 (new characters).

use std::collections::BTreeMap;
use std::path::PathBuf;

use rayon::prelude::*;

use super::queries::{load_pool, query_kv, report_left_out, write_table, LimitOptions};
use crate::plot::write_png;
use crate::query::feasibility::{LimitForm, Limits};
use crate::query::gait::{GaitLaw, LawChoice};
use crate::query::limits::{absolute_limits, left_out_clips, stance_limits};
use crate::query::pool::Prepared;
use crate::query::run::{
    character_laws, check_scale, check_sweep, nearest_in_speed, run_at_speed, run_cycles,
    scale_limits, RunCycle, ScaledStance,
};
use crate::query::tables::{run_table, RunRow};

/// `query run`: every run cycle of a library at each speed, for a character `length_scale`
/// times as long and `mass_scale` times as heavy.
#[derive(Debug, Clone)]
pub struct RunQuery {
    /// Library folder.
    pub lib: PathBuf,
    /// Target speeds, m/s (checked: [`speed_range`](super::queries::speed_range)).
    pub speeds: Vec<f64>,
    /// Leg-length ratio target/recorded character.
    pub length_scale: f64,
    /// Body-mass ratio target/recorded character.
    pub mass_scale: f64,
    /// Limit options (default form: absolute).
    pub limits: LimitOptions,
    /// Output Parquet file.
    pub out: PathBuf,
    /// Table 1 as a figure (PNG), when given.
    pub png: Option<PathBuf>,
    /// How contact time and step period change with speed.
    pub gait_law: LawChoice,
    /// Keep the clips the queries leave out ([`left_out_clips`]).
    pub keep_left_out: bool,
    /// Explain in full the cycle whose first stance has this id (`--explain`).
    pub explain: Option<String>,
}

/// One printed line of `query run`: a cycle at one speed (its first stance's values).
#[derive(Debug, Clone, PartialEq)]
pub struct RunLine {
    /// Target speed, m/s.
    pub speed_mps: f64,
    /// The cycle's first stance.
    pub stance_id: String,
    /// `β_h`, `β_v` of the first stance.
    pub beta: [Option<f64>; 2],
    /// Friction the cycle needs (both stances solved).
    pub mu_min: Option<f64>,
    /// Peak force of the first stance, N.
    pub f_peak_n: Option<f64>,
    /// Longest COM–contact distance of the first stance, m.
    pub ext_max_m: Option<f64>,
    /// Contact point `cp_h` of the first stance, m.
    pub cp_h_m: Option<f64>,
    /// Contact time of the first stance, s.
    pub contact_s: Option<f64>,
    /// Apex-to-apex step period of the first stance, s.
    pub step_s: Option<f64>,
    /// The gait law's source (`character`, `population`, `paper`).
    pub gait_law: &'static str,
    /// The cycle answers this speed for its character (nearest in speed).
    pub used: bool,
    /// Feasible by the exact check.
    pub feasible: bool,
    /// The first problem, `<stance_id>: <reason>`.
    pub violated: Option<String>,
}

/// What `query run` found: one line per (speed, cycle), speed-major.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// Cycles answered at each speed.
    pub n_cycles: usize,
    /// Speeds asked.
    pub n_speeds: usize,
    /// The lines, speed-major.
    pub lines: Vec<RunLine>,
    /// `--explain`: the explained cycle at each speed, a blank line between speeds
    /// ([`RunRow::full_explanation`]).
    pub explained: Vec<String>,
}

/// Runs `query run` and writes its table (and figure).
///
/// # Errors
/// Bad scales or limit options, an unreadable library, too large a sweep, an unwritable
/// output.
pub fn run_query(q: &RunQuery) -> anyhow::Result<RunReport> {
    let (length, mass) = (q.length_scale, q.mass_scale);
    check_scale("--length-scale", length)?;
    check_scale("--mass-scale", mass)?;
    let (form, mu) = q.limits.form(LimitForm::Absolute)?;
    let active = q.limits.active_fraction()?;
    let (lib, pool) = load_pool(&q.lib, active)?;
    let all = run_cycles(&lib.stances);
    let left = if q.keep_left_out {
        BTreeMap::new()
    } else {
        left_out_clips(&lib)
    };
    let clip_of = |c: &RunCycle| &lib.stances[c.stances[0]].clip;
    let (cycles, skipped): (Vec<RunCycle>, Vec<RunCycle>) = all
        .into_iter()
        .partition(|c| !left.contains_key(clip_of(c)));
    report_left_out(
        "query run",
        skipped.len(),
        "cycle(s)",
        &left,
        skipped.iter().map(clip_of),
    );
    check_sweep("--speeds", cycles.len(), q.speeds.len())?;
    if let Some(id) = &q.explain {
        let firsts = cycles
            .iter()
            .map(|c| lib.stances[c.stances[0]].stance_id.as_str());
        anyhow::ensure!(
            firsts.clone().any(|f| f == id),
            "--explain: {}",
            crate::stances::ids::unknown_stance_message(id, firsts)
                .replace("no stance", "no run cycle starting at stance")
        );
    }
    // Absolute limits of the target character: the source character's, scaled by §9.
    let limits: BTreeMap<String, Limits> = absolute_limits(&lib)
        .into_iter()
        .map(|(k, l)| (k, scale_limits(&l, length, mass)))
        .collect();
    // The target character: every stance scaled once (§9), then the speed sweep.
    let scaled: Vec<(RunCycle, [Prepared; 2], [Limits; 2])> = cycles
        .par_iter()
        .map(|c| {
            let prep = c.stances.map(|i| {
                Prepared::with_active_fraction(pool[i].stance.scaled(length, mass), active)
            });
            let lim = [0, 1].map(|k| stance_limits(&prep[k], form, &limits, mu));
            (*c, prep, lim)
        })
        .collect();
    let laws = character_laws(&lib.stances, &cycles, q.gait_law);
    let speeds_of: Vec<(&str, f64)> = scaled
        .iter()
        .map(|(c, p, _)| (p[0].stance.character_id.as_str(), c.v_orig * length.sqrt()))
        .collect();
    let mut rows = Vec::new();
    for &v in &q.speeds {
        let used = nearest_in_speed(&speeds_of, v);
        for ((c, prep, lim), used) in scaled.iter().zip(used) {
            let cycle = [&prep[0], &prep[1]];
            let law = laws
                .get(&prep[0].stance.character_id)
                .copied()
                .unwrap_or(GaitLaw::POPULATION);
            let v_orig = c.v_orig * length.sqrt();
            rows.push(RunRow {
                length_scale: length,
                mass_scale: mass,
                stances: cycle,
                candidate: run_at_speed(cycle, v_orig, v, &law, [&lim[0], &lim[1]]),
                limits: *lim,
                used,
            });
        }
    }
    let mut df = run_table(&rows)?;
    let kv = query_kv(
        &q.lib,
        serde_json::json!({
            "query": "run", "lib": q.lib, "speeds_mps": q.speeds,
            "length_scale": length, "mass_scale": mass,
            "limits": form.name(), "mu": mu, "active_set": active,
            "gait_law": q.gait_law.name(),
        }),
    )?;
    write_table(&q.out, &mut df, &kv)?;
    if let Some(png) = &q.png {
        let points = run_points(&rows, scaled.len());
        let title = format!(
            "At which speeds can the run cycles run? ({} cycle(s), limits {}, gait law {}{})",
            scaled.len(),
            form.name(),
            q.gait_law.name(),
            if (length, mass) == (1.0, 1.0) {
                String::new()
            } else {
                format!(", character L = {length}, M = {mass}")
            }
        );
        write_png(png, |p| crate::plot::runs::runs_png(p, &title, &points))?;
    }
    let explained = q.explain.as_ref().map_or_else(Vec::new, |id| {
        rows.iter()
            .filter(|r| &r.stances[0].stance.stance_id == id)
            .flat_map(|r| r.full_explanation().into_iter().chain([String::new()]))
            .collect()
    });
    Ok(RunReport {
        n_cycles: scaled.len(),
        n_speeds: q.speeds.len(),
        lines: rows.iter().map(run_line).collect(),
        explained,
    })
}

fn run_line(r: &RunRow) -> RunLine {
    let s = r.candidate.stances[0].as_ref().ok();
    let mu = r
        .candidate
        .stances
        .iter()
        .map(|s| s.as_ref().ok().map(|s| s.verdict.mu_req));
    let mu = mu
        .collect::<Option<Vec<f64>>>()
        .map(|v| v.into_iter().fold(0.0, f64::max));
    RunLine {
        speed_mps: r.candidate.speed,
        stance_id: r.stances[0].stance.stance_id.clone(),
        beta: [s.map(|s| s.solution.beta[0]), s.map(|s| s.solution.beta[2])],
        mu_min: mu,
        f_peak_n: s.map(|s| s.verdict.f_peak),
        ext_max_m: s.map(|s| s.verdict.ext_max),
        cp_h_m: s.map(|s| s.cp[0]),
        contact_s: s.map(|s| s.solution.t_lo - s.solution.t_td),
        step_s: s.map(|s| s.solution.t_e),
        gait_law: r.candidate.timing.law.source.name(),
        used: r.used,
        feasible: r.candidate.feasible(),
        violated: r.explain(),
    }
}

/// The figure's points of `query run` rows (cycle-major within each speed, `n_cycles`
/// cycles).
fn run_points(rows: &[RunRow], n_cycles: usize) -> Vec<crate::plot::runs::RunPoint> {
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            let solved: Vec<_> = r
                .candidate
                .stances
                .iter()
                .filter_map(|s| s.as_ref().ok())
                .collect();
            let both = solved.len() == 2;
            let agg = |g: &dyn Fn(&ScaledStance) -> f64, max: bool| {
                both.then(|| {
                    let (a, b) = (g(solved[0]), g(solved[1]));
                    if max {
                        a.max(b)
                    } else {
                        a.min(b)
                    }
                })
            };
            crate::plot::runs::RunPoint {
                cycle: i % n_cycles.max(1),
                cycle_name: r.stances[0].stance.stance_id.clone(),
                speed_mps: r.candidate.speed,
                contact_s: solved
                    .iter()
                    .map(|s| s.solution.t_lo - s.solution.t_td)
                    .collect(),
                step_s: solved.iter().map(|s| s.solution.t_e).collect(),
                peak_n: agg(&|s| s.verdict.f_peak, true),
                f_max_n: r.limits[0].f_max,
                mu_min: agg(&|s| s.verdict.mu_req, true),
                ext_min_m: agg(&|s| s.verdict.ext_min, false),
                ext_max_m: agg(&|s| s.verdict.ext_max, true),
                limits: (r.limits[0].mu, r.limits[0].chi_min, r.limits[0].chi_max),
                feasible: r.candidate.feasible(),
                violated: r.violated(),
            }
        })
        .collect()
}
