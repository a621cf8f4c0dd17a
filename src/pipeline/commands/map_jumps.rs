//! `map jumps` at the I/O edge: the jump feasibility map of a library from typed options,
//! its tables and figures written atomically.
//!
//! # References
//! spec stance-model §6.10 (map), §7.5 (limits).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;

use super::queries::{file_safe, load_pool, pool_without_left_out, query_kv, LimitOptions};
use super::query_jump::JumpTarget;
use crate::library::codec::write::write_atomic;
use crate::plot::{jump_map_png, write_png};
use crate::query::feasibility::{LimitForm, Limits};
use crate::query::limits::{absolute_limits, jump_limits};
use crate::query::map::{check_grid, jump_map, JumpMap};
use crate::query::pairs::ranked_jump_pairs;
use crate::query::pool::Prepared;
use crate::query::tables::{jump_map_table, jump_pairs_table};

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
    /// Keep the clips the queries leave out ([`left_out_clips`](crate::query::limits::left_out_clips)).
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
    let limits = |p: &Prepared| jump_limits(p, form, &absolute, mu, &lib.clips);
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
    crate::library::storage::atomic::write_text_atomic(
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
