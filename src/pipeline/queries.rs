//! The query stages at the I/O edge, from typed options: `query run` (a speed sweep of
//! the run cycles) and `map jumps` (the jump feasibility map), each reading a library,
//! answering, and writing its tables (and figures) atomically. The command line and the
//! `[queries]` stages of a pipeline file both run them; what they print is the caller's.
//!
//! # References
//! spec stance-model §6.8 (run), §6.10 (map), §7.5 (limits), §9 (new characters).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use polars::prelude::DataFrame;
use rayon::prelude::*;

use super::spec::{ConstraintsTable, QueriesTable};
use crate::library::read::{open_library, StanceLibrary};
use crate::library::write::write_atomic;
use crate::plot::{jump_map_png, write_png};
use crate::query::feasibility::{check_mu, LimitForm, Limits, DEFAULT_QUERY_ACTIVE_FRACTION};
use crate::query::gait::{GaitLaw, LawChoice};
use crate::query::jump::recorded_jump;
use crate::query::limits::{
    absolute_limits, left_out_clips, left_out_line, stance_limits, LeftOut,
};
use crate::query::map::{check_grid, jump_map, Axis, JumpMap, DEFAULT_HEIGHTS, DEFAULT_SPEEDS};
use crate::query::pairs::ranked_jump_pairs;
use crate::query::pool::Prepared;
use crate::query::run::{
    character_laws, check_scale, check_speed, check_sweep, nearest_in_speed, run_at_speed,
    run_cycles, scale_limits, RunCycle, ScaledStance,
};
use crate::query::tables::{jump_map_table, jump_pairs_table, jump_table, run_table, RunRow};

/// The limit options of a query (§7.5), as given: each `None` takes the query's default.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LimitOptions {
    /// Limit form (`None`: the query's own default).
    pub form: Option<LimitForm>,
    /// Friction limit μ under either form.
    pub mu: Option<f64>,
    /// Active fraction of the friction check (`None`: [`DEFAULT_QUERY_ACTIVE_FRACTION`]).
    pub active_set: Option<f64>,
}

impl LimitOptions {
    /// The limit form (else `default`) and the given μ.
    ///
    /// # Errors
    /// A μ that is not a positive finite number.
    pub fn form(&self, default: LimitForm) -> anyhow::Result<(LimitForm, Option<f64>)> {
        if let Some(m) = self.mu {
            check_mu(m).map_err(|msg| crate::error::Error::invalid("--mu", msg))?;
        }
        Ok((self.form.unwrap_or(default), self.mu))
    }

    /// The friction check's active fraction `λ_act`.
    ///
    /// # Errors
    /// A fraction outside `[0, 1)` or not finite.
    pub fn active_fraction(&self) -> anyhow::Result<f64> {
        let v = self.active_set.unwrap_or(DEFAULT_QUERY_ACTIVE_FRACTION);
        anyhow::ensure!(
            v.is_finite() && (0.0..1.0).contains(&v),
            "--active-set must lie in [0, 1), found {v}"
        );
        Ok(v)
    }
}

/// The speeds of a `start:stop:step` range given as `flag`, each checked.
///
/// # Errors
/// A bad range, or a negative or non-finite speed.
pub fn speed_range(flag: &str, range: &str) -> anyhow::Result<Vec<f64>> {
    let v = Axis::parse(flag, range)?.values();
    for s in &v {
        check_speed(flag, *s)?;
    }
    Ok(v)
}

/// Opens a library and prepares every stance (tables built in parallel), the friction
/// check on the active set `f_v ≥ active_fraction · max f_v`.
///
/// # Errors
/// A missing or malformed library table.
pub fn load_pool(
    lib: &Path,
    active_fraction: f64,
) -> anyhow::Result<(StanceLibrary, Vec<Prepared>)> {
    let library = open_library(lib).with_context(|| format!("library {}", lib.display()))?;
    let pool = library
        .stances
        .par_iter()
        .map(|s| Prepared::with_active_fraction(s.clone(), active_fraction))
        .collect();
    Ok((library, pool))
}

/// Prints (stderr) which clips a query left out and why ([`left_out_line`]): the clips of
/// `dropped` (one per dropped item, repeats allowed), `count` items of kind `what`.
fn report_left_out<'a>(
    command: &str,
    count: usize,
    what: &str,
    left: &BTreeMap<String, LeftOut>,
    dropped: impl Iterator<Item = &'a String>,
) {
    let clips: std::collections::BTreeSet<&String> = dropped.collect();
    let named: Vec<(&String, &LeftOut)> = clips
        .into_iter()
        .filter_map(|c| left.get_key_value(c))
        .collect();
    if let Some(line) = left_out_line(command, count, what, &named) {
        eprintln!("{line}");
    }
}

/// The pool without the stances of left-out clips (unless `keep`), with the report line.
fn pool_without_left_out(
    command: &str,
    lib: &StanceLibrary,
    pool: Vec<Prepared>,
    keep: bool,
) -> Vec<Prepared> {
    if keep {
        return pool;
    }
    let left = left_out_clips(lib);
    let (kept, dropped): (Vec<Prepared>, Vec<Prepared>) = pool
        .into_iter()
        .partition(|p| !left.contains_key(&p.stance.clip));
    report_left_out(
        command,
        dropped.len(),
        "stance(s)",
        &left,
        dropped.iter().map(|p| &p.stance.clip),
    );
    kept
}

/// Writes `df` to the file `out` atomically (parent folder created).
///
/// # Errors
/// An unwritable folder or file.
pub fn write_table(out: &Path, df: &mut DataFrame, kv: &[(String, String)]) -> anyhow::Result<()> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("--out {}: not a file name", out.display()))?;
    write_atomic(&dir, name, df, kv)?;
    Ok(())
}

/// Key-value metadata of a query output: the tool version, the query's options and its
/// library (the folder as given and the SHA-256 of its `manifest.json`).
///
/// # Errors
/// The library's manifest cannot be read.
pub fn query_kv(lib: &Path, options: serde_json::Value) -> anyhow::Result<Vec<(String, String)>> {
    use crate::library::provenance::manifest_sha256;
    use crate::library::schema::{command_kv, LIBRARY_MANIFEST_KEY, LIBRARY_PATH_KEY, QUERY_KEY};
    let hash = manifest_sha256(lib).with_context(|| format!("library {}", lib.display()))?;
    let mut kv = command_kv(QUERY_KEY, &options);
    kv.push((LIBRARY_PATH_KEY.into(), lib.display().to_string()));
    kv.push((LIBRARY_MANIFEST_KEY.into(), hash));
    Ok(kv)
}

/// `query run`: every run cycle of a library at each speed, for a character `length_scale`
/// times as long and `mass_scale` times as heavy.
#[derive(Debug, Clone)]
pub struct RunQuery {
    /// Library folder.
    pub lib: PathBuf,
    /// Target speeds, m/s (checked: [`speed_range`]).
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

/// `map jumps`: the jump feasibility map of a library over apex heights × speeds.
#[derive(Debug, Clone)]
pub struct MapQuery {
    /// Library folder.
    pub lib: PathBuf,
    /// Rows: apex heights, m.
    pub heights: Vec<f64>,
    /// Columns: horizontal apex speeds, m/s.
    pub speeds: Vec<f64>,
    /// Limit options (default form: relative).
    pub limits: LimitOptions,
    /// Keep the clips the queries leave out ([`left_out_clips`]).
    pub keep_left_out: bool,
    /// Output folder.
    pub out: PathBuf,
    /// Also draw `jump_map_agreement.png`, the fast filters against the exact check (a
    /// developer diagnostic).
    pub diagnostics: bool,
}

/// What `map jumps` found.
#[derive(Debug, Clone, PartialEq)]
pub struct MapReport {
    /// Liftoff stances.
    pub liftoffs: usize,
    /// Landing stances.
    pub landings: usize,
    /// Liftoff × landing pairs of one character.
    pub pairs: usize,
    /// Grid rows × columns.
    pub grid: (usize, usize),
    /// Cells feasible by the fast filters, the exact check, both.
    pub cells: (usize, usize, usize),
    /// Intersection over union of the two feasible sets.
    pub iou: f64,
    /// Time spent computing the map, s.
    pub elapsed_s: f64,
    /// Per pair, most feasible cells first ([`PairAnswer`]).
    pub pair_answers: Vec<PairAnswer>,
}

/// One pair of `map jumps` in words: how much of the grid it can jump, and whether it can
/// jump its own recorded jump and one [`HIGHER_BY`] higher, each with its deciding limit.
#[derive(Debug, Clone, PartialEq)]
pub struct PairAnswer {
    /// Liftoff stance id.
    pub liftoff: String,
    /// Landing stance id.
    pub landing: String,
    /// Cells feasible by the exact check, of `cells`.
    pub feasible_cells: usize,
    /// Cells of the grid.
    pub cells: usize,
    /// The recorded jump: `None` feasible, else why not ([`crate::query::tables::JumpRow::explain`]).
    pub recorded: Option<String>,
    /// The recorded jump with its apex [`HIGHER_BY`] times as high, same distance.
    pub higher: Option<String>,
}

/// The factor on the recorded apex height `map jumps` reports per pair ("10 % higher").
pub const HIGHER_BY: f64 = 1.1;

/// Runs `map jumps` and writes `jump_map.parquet`, `jump_map_pairs.parquet`,
/// `jump_map.json` and the figures into its folder.
///
/// # Errors
/// An empty or too large grid, bad limit options, an unreadable library, an unwritable
/// output folder.
pub fn map_jumps(q: &MapQuery) -> anyhow::Result<MapReport> {
    let (heights, speeds) = (&q.heights, &q.speeds);
    anyhow::ensure!(
        !heights.is_empty() && !speeds.is_empty(),
        "the grid is empty: check --heights and --speeds"
    );
    check_grid("--heights × --speeds", heights.len(), speeds.len())?;
    let (form, mu) = q.limits.form(LimitForm::Absolute)?;
    let active = q.limits.active_fraction()?;
    let (lib, pool) = load_pool(&q.lib, active)?;
    let pool = pool_without_left_out("map jumps", &lib, pool, q.keep_left_out);
    let absolute = absolute_limits(&lib);
    let limits = |p: &Prepared| stance_limits(p, form, &absolute, mu);
    let t0 = Instant::now();
    let map = jump_map(&pool, heights, speeds, &limits)
        .context("--heights × --speeds on this library")?;
    let elapsed = t0.elapsed().as_secs_f64();
    // Every output's name is known (and fits a file name) before the first is written.
    let per_character = character_figures(&q.out, &map, &pool);
    std::fs::create_dir_all(&q.out)
        .with_context(|| format!("cannot create {}", q.out.display()))?;
    let iou = map.agreement.iou();
    let summary = serde_json::json!({
        "heights_m": {"start": heights[0], "stop": heights[heights.len() - 1], "n": heights.len()},
        "u_apex_mps": {"start": speeds[0], "stop": speeds[speeds.len() - 1], "n": speeds.len()},
        "liftoffs": map.liftoffs.len(), "landings": map.landings.len(), "pairs": map.pairs.len(),
        "cells_approx": map.agreement.approx, "cells_exact": map.agreement.exact,
        "cells_both": map.agreement.both, "iou": iou,
        "limits": form.name(), "mu": mu, "active_set": active,
    });
    let kv = query_kv(&q.lib, summary.clone())?;
    write_atomic(
        &q.out,
        "jump_map.parquet",
        &mut jump_map_table(&map, &pool)?,
        &kv,
    )?;
    write_atomic(
        &q.out,
        "jump_map_pairs.parquet",
        &mut jump_pairs_table(&map, &pool)?,
        &kv,
    )?;
    crate::library::atomic::write_text_atomic(
        &q.out.join("jump_map.json"),
        &(serde_json::to_string_pretty(&summary)? + "\n"),
    )?;
    map_figures(&q.out, &map, &pool, &per_character)?;
    let pair_answers = pair_answers(&map, &pool, &limits);
    if q.diagnostics {
        write_png(&q.out.join(JUMP_MAP_AGREEMENT_PNG), |p| {
            crate::plot::jump_map_agreement_png(p, &map, "all characters")
        })?;
    }
    Ok(MapReport {
        liftoffs: map.liftoffs.len(),
        landings: map.landings.len(),
        pairs: map.pairs.len(),
        grid: (heights.len(), speeds.len()),
        cells: (
            map.agreement.approx,
            map.agreement.exact,
            map.agreement.both,
        ),
        iou,
        elapsed_s: elapsed,
        pair_answers,
    })
}

/// [`PairAnswer`] of every pair of the map, most feasible cells first (ties: ids).
fn pair_answers(
    map: &JumpMap,
    pool: &[Prepared],
    limits: &dyn Fn(&Prepared) -> Limits,
) -> Vec<PairAnswer> {
    let verdicts = |height: f64| -> BTreeMap<(String, String), Option<String>> {
        let target = JumpTarget::Scaled {
            height,
            distance: 1.0,
        };
        ranked_jump_pairs(pool, |a, b| target.of(a, b), limits)
            .iter()
            .map(|r| {
                let ids = (
                    r.liftoff.stance.stance_id.clone(),
                    r.landing.stance.stance_id.clone(),
                );
                (ids, r.explain())
            })
            .collect()
    };
    let (own, higher) = (verdicts(1.0), verdicts(HIGHER_BY));
    let cells = map.heights.len() * map.speeds.len();
    let mut out: Vec<PairAnswer> = map
        .pairs
        .iter()
        .map(|p| {
            let ids = (
                pool[p.liftoff].stance.stance_id.clone(),
                pool[p.landing].stance.stance_id.clone(),
            );
            PairAnswer {
                feasible_cells: p.exact.iter().filter(|&&e| e).count(),
                cells,
                recorded: own.get(&ids).cloned().flatten(),
                higher: higher.get(&ids).cloned().flatten(),
                liftoff: ids.0,
                landing: ids.1,
            }
        })
        .collect();
    out.sort_by(|a, b| {
        b.feasible_cells
            .cmp(&a.feasible_cells)
            .then_with(|| (&a.liftoff, &a.landing).cmp(&(&b.liftoff, &b.landing)))
    });
    out
}

/// The `--diagnostics` picture of `map jumps` in its output folder.
pub const JUMP_MAP_AGREEMENT_PNG: &str = "jump_map_agreement.png";

/// The per-character pictures of a map: `(character_id, jump_map_<file_safe(id)>.png)`
/// when the pool has several characters, none otherwise.
fn character_figures(out: &Path, map: &JumpMap, pool: &[Prepared]) -> Vec<(String, PathBuf)> {
    let characters: BTreeSet<&str> = map
        .pairs
        .iter()
        .map(|p| pool[p.liftoff].stance.character_id.as_str())
        .collect();
    if characters.len() < 2 {
        return Vec::new();
    }
    characters
        .into_iter()
        .map(|id| {
            let file = out.join(format!("jump_map_{}.png", file_safe(id)));
            (id.to_string(), file)
        })
        .collect()
}

/// `jump_map.png`, and the pictures of `per_character` ([`character_figures`]).
fn map_figures(
    out: &Path,
    map: &JumpMap,
    pool: &[Prepared],
    per_character: &[(String, PathBuf)],
) -> anyhow::Result<()> {
    let recorded = recorded_jumps(map, pool);
    let marks = |ids: Option<&str>| -> Vec<(f64, f64)> {
        recorded
            .iter()
            .filter(|(c, _)| ids.is_none_or(|id| id == c.as_str()))
            .map(|(_, p)| *p)
            .collect()
    };
    write_png(&out.join("jump_map.png"), |p| {
        jump_map_png(p, map, "all characters", &marks(None))
    })?;
    for (id, file) in per_character {
        let mut one = map.clone();
        one.pairs
            .retain(|p| pool[p.liftoff].stance.character_id == *id);
        one.agreement = one.pairs.iter().fold(Default::default(), |mut acc, p| {
            acc.approx += p.agreement.approx;
            acc.exact += p.agreement.exact;
            acc.both += p.agreement.both;
            acc.either += p.agreement.either;
            acc
        });
        write_png(file, |p| jump_map_png(p, &one, id, &marks(Some(id))))?;
    }
    Ok(())
}

/// The recorded jumps of the map's pairs, `(character_id, (distance, height))` in m: a
/// liftoff and the landing right after it across one flight of the same clip, at the
/// identity jump's height `(ze₁ + zs₂ + z_c,2 − z_c,1)/2` and distance `x₁ + x₂` (spec
/// stance-model §6.9).
pub fn recorded_jumps(map: &JumpMap, pool: &[Prepared]) -> Vec<(String, (f64, f64))> {
    map.pairs
        .iter()
        .filter_map(|p| {
            let (s1, s2) = (&pool[p.liftoff].stance, &pool[p.landing].stance);
            let next = pool
                .iter()
                .map(|q| &q.stance)
                .filter(|q| q.clip == s1.clip && q.first_frame > s1.first_frame)
                .min_by_key(|q| q.first_frame)?;
            (next.stance_id == s2.stance_id).then(|| {
                let h = (s1.params.ze + s2.params.zs + s2.z_c - s1.z_c) / 2.0;
                (s1.character_id.clone(), (s1.params.x + s2.params.x, h))
            })
        })
        .collect()
}

/// Longest part of a file name made from an id ([`file_safe`]), bytes: with its prefix
/// and extension far below the 255 bytes of a file name on common file systems.
pub const MAX_ID_FILE_BYTES: usize = 64;

/// The part of a file name that stands for `id` (a character id): one name per id, never
/// the same for two, never longer than [`MAX_ID_FILE_BYTES`].
///
/// # Model
/// ```text
/// ASCII letters, digits, '-', '_', '.'   as they are
/// any other byte of the UTF-8 text       %XX (upper-case hex; '%' itself is %25)
/// longer than MAX_ID_FILE_BYTES, or       the first bytes of that, then '~' and 16 hex
/// the name of another output of the map   digits of the id's SHA-256
/// ```
/// The escaped text alone is injective, and it never holds `~` (`%7E`), so a cut name
/// cannot equal a whole one. (Before, `a/b` and `a.b` both gave `a_b`, and a 300-character
/// id a file name the system refused after four outputs were written.)
///
/// # Examples
/// ```
/// use stancelib::pipeline::queries::file_safe;
/// assert_eq!(file_safe("sk-9f71a3e6fbd4"), "sk-9f71a3e6fbd4");
/// assert_ne!(file_safe("a/b"), file_safe("a.b"));
/// assert!(file_safe(&"x".repeat(300)).len() <= 64);
/// ```
pub fn file_safe(id: &str) -> String {
    let mut out = String::with_capacity(id.len());
    for b in id.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    let reserved = out == "agreement" || out == "pairs";
    if out.len() <= MAX_ID_FILE_BYTES && !reserved {
        return out;
    }
    use sha2::{Digest, Sha256};
    let hash: String = Sha256::digest(id.as_bytes())[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let mut cut = out.len().min(MAX_ID_FILE_BYTES - 1 - hash.len());
    // Never keep half of a %XX.
    if let Some(p) = out[..cut].rfind('%').filter(|&p| p + 3 > cut) {
        cut = p;
    }
    format!("{}~{hash}", &out[..cut])
}

/// The `[queries]` stages of a pipeline file on the library `lib` just built, as typed
/// queries into `<lib>/queries/` (`runs.parquet`, `jump_map/`); `[constraints]` gives their
/// limit options (`limits = "per_query"` keeps each query's default form). Every option is
/// checked here, before any stage runs.
///
/// # Errors
/// A bad speed, height or apex-speed range.
pub fn query_stages(
    q: &QueriesTable,
    c: Option<&ConstraintsTable>,
    lib: &Path,
) -> anyhow::Result<(Option<RunQuery>, Option<MapQuery>)> {
    let dir = lib.join("queries");
    let limits = LimitOptions {
        form: c
            .and_then(|c| c.limits.as_deref())
            .filter(|l| *l != "per_query")
            .and_then(LimitForm::parse),
        mu: c.and_then(|c| c.mu),
        active_set: c.and_then(|c| c.active_set),
    };
    let run = match &q.run_speeds {
        Some(speeds) => Some(RunQuery {
            lib: lib.to_path_buf(),
            speeds: speed_range("--speeds", speeds)?,
            length_scale: q.length_scale.unwrap_or(1.0),
            mass_scale: q.mass_scale.unwrap_or(1.0),
            limits,
            out: dir.join("runs.parquet"),
            png: None,
            gait_law: gait_law_choice(q.gait_law.as_deref())?,
            keep_left_out: q.keep_left_out.unwrap_or(false),
            explain: None,
        }),
        None => None,
    };
    let map = match q.jump_map {
        Some(true) => Some(MapQuery {
            lib: lib.to_path_buf(),
            heights: axis_or("--heights", q.map_heights.as_deref(), DEFAULT_HEIGHTS)?,
            speeds: axis_or("--speeds", q.map_speeds.as_deref(), DEFAULT_SPEEDS)?,
            limits,
            keep_left_out: q.keep_left_out.unwrap_or(false),
            out: dir.join("jump_map"),
            diagnostics: false,
        }),
        _ => None,
    };
    Ok((run, map))
}

/// The gait law named by `[queries] gait_law` (`auto` when absent).
///
/// # Errors
/// An unknown name.
pub fn gait_law_choice(name: Option<&str>) -> anyhow::Result<LawChoice> {
    match name {
        None => Ok(LawChoice::Auto),
        Some(n) => LawChoice::parse(n).ok_or_else(|| {
            anyhow::anyhow!("gait_law: unknown law '{n}' (give {})", LawChoice::NAMES)
        }),
    }
}

/// The values of the range `given` as `flag`, else of `default`.
fn axis_or(flag: &str, given: Option<&str>, default: Axis) -> anyhow::Result<Vec<f64>> {
    Ok(match given {
        Some(r) => Axis::parse(flag, r)?,
        None => default,
    }
    .values())
}

/// `query jump`: every liftoff × landing pair of a library at one apex height and distance.
#[derive(Debug, Clone)]
pub struct JumpQuery {
    /// Library folder.
    pub lib: PathBuf,
    /// The jump asked of every pair.
    pub target: JumpTarget,
    /// Limit options (default form: relative).
    pub limits: LimitOptions,
    /// Keep the clips the queries leave out ([`left_out_clips`]).
    pub keep_left_out: bool,
    /// Build each pair's whole explanation ([`JumpLine::full`]) for `--explain`.
    pub explain: bool,
    /// Output Parquet file.
    pub out: PathBuf,
}

/// The jump `query jump` asks of each pair: absolute, or relative to the pair's recorded
/// jump ([`recorded_jump`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JumpTarget {
    /// Apex height above the liftoff contact and distance, m, the same for every pair.
    Absolute {
        /// m.
        height_m: f64,
        /// m.
        distance_m: f64,
    },
    /// The pair's recorded apex height and distance times these.
    Scaled {
        /// Factor on the recorded apex height.
        height: f64,
        /// Factor on the recorded distance.
        distance: f64,
    },
}

impl JumpTarget {
    /// `(height, distance)` asked of the pair (liftoff `p1`, landing `p2`), m.
    pub fn of(&self, p1: &Prepared, p2: &Prepared) -> (f64, f64) {
        match *self {
            JumpTarget::Absolute {
                height_m,
                distance_m,
            } => (height_m, distance_m),
            JumpTarget::Scaled { height, distance } => {
                let (h0, d0) = recorded_jump(&p1.stance, &p2.stance);
                (h0 * height, d0 * distance)
            }
        }
    }

    /// Each number finite, and the scales positive.
    ///
    /// # Errors
    /// The option that is not.
    pub fn check(&self) -> anyhow::Result<()> {
        let (a, b, scaled) = match *self {
            JumpTarget::Absolute {
                height_m,
                distance_m,
            } => (height_m, distance_m, false),
            JumpTarget::Scaled { height, distance } => (height, distance, true),
        };
        let names = if scaled {
            ["--height-scale", "--distance-scale"]
        } else {
            ["--height", "--distance"]
        };
        for (n, v) in names.iter().zip([a, b]) {
            anyhow::ensure!(v.is_finite(), "{n} must be a number, found {v}");
        }
        if scaled {
            check_scale(names[0], a)?;
            anyhow::ensure!(
                b >= 0.0,
                "{} must be ≥ 0 (0: a jump in place), found {b}",
                names[1]
            );
        }
        Ok(())
    }

    /// The target for the query's options JSON.
    fn json(&self) -> serde_json::Value {
        match *self {
            JumpTarget::Absolute {
                height_m,
                distance_m,
            } => serde_json::json!({"height_m": height_m, "distance_m": distance_m}),
            JumpTarget::Scaled { height, distance } => {
                serde_json::json!({"height_scale": height, "distance_scale": distance})
            }
        }
    }
}

/// One ranked pair of `query jump`.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpLine {
    /// Liftoff stance id.
    pub liftoff: String,
    /// Landing stance id.
    pub landing: String,
    /// Apex speed, m/s (a solved pair).
    pub u_apex_mps: Option<f64>,
    /// `[β_h, β_v]` of the liftoff and of the landing (a solved pair).
    pub beta: Option<[[f64; 2]; 2]>,
    /// Feasible by the exact check.
    pub feasible: bool,
    /// Why not, with the deciding value, limit and margin
    /// ([`crate::query::tables::JumpRow::explain`]).
    pub why: Option<String>,
    /// Apex height (m) and distance (m) asked of this pair.
    pub asked: (f64, f64),
    /// The whole answer ([`crate::query::tables::JumpRow::full_explanation`]); empty
    /// unless [`JumpQuery::explain`].
    pub full: Vec<String>,
}

/// Runs `query jump`: ranks every pair (feasible first, then the least force change),
/// writes the table and returns the pairs in rank order.
///
/// # Errors
/// A height or distance that is not a number, bad limit options, an unreadable library,
/// an unwritable output.
pub fn jump_query(q: &JumpQuery) -> anyhow::Result<Vec<JumpLine>> {
    q.target.check()?;
    let (form, mu) = q.limits.form(LimitForm::Absolute)?;
    let active = q.limits.active_fraction()?;
    let (lib, pool) = load_pool(&q.lib, active)?;
    let pool = pool_without_left_out("query jump", &lib, pool, q.keep_left_out);
    let absolute = absolute_limits(&lib);
    let lim = |p: &Prepared| stance_limits(p, form, &absolute, mu);
    let rows = ranked_jump_pairs(&pool, |a, b| q.target.of(a, b), lim);
    let mut df = jump_table(&rows)?;
    let kv = query_kv(
        &q.lib,
        serde_json::json!({
            "query": "jump", "lib": q.lib, "target": q.target.json(),
            "limits": form.name(), "mu": mu, "active_set": active,
        }),
    )?;
    write_table(&q.out, &mut df, &kv)?;
    Ok(rows
        .iter()
        .map(|r| JumpLine {
            liftoff: r.liftoff.stance.stance_id.clone(),
            landing: r.landing.stance.stance_id.clone(),
            u_apex_mps: r.jump.as_ref().ok().map(|j| j.u_apex),
            beta: r.jump.as_ref().ok().map(|j| {
                [0, 1].map(|k| {
                    let b = j.sides[k].1.solution.beta;
                    [b[0], b[2]]
                })
            }),
            feasible: r.jump.as_ref().is_ok_and(|j| j.feasible()),
            why: r.explain(),
            asked: (r.height, r.distance),
            full: if q.explain {
                r.full_explanation()
            } else {
                Vec::new()
            },
        })
        .collect())
}
