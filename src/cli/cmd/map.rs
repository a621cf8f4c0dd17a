//! `stancelib map jumps`: the jump feasibility map of a library (spec stance-model §6.10)
//! as `jump_map.parquet`, `jump_map_pairs.parquet`, `jump_map.json` and `jump_map.png`.

use std::collections::BTreeSet;
use std::time::Instant;

use anyhow::Context;

use super::super::args::MapJumpsArgs;
use super::super::Outcome;
use super::query::{absolute_limits, load_pool, query_kv, stance_limits};
use crate::library::queries::{jump_map_table, jump_pairs_table};
use crate::library::write::write_atomic;
use crate::plot::jump_map_png;
use crate::query::feasibility::LimitForm;
use crate::query::map::{check_grid, jump_map, JumpMap};
use crate::query::pool::Prepared;

/// Run `map jumps`.
///
/// # Errors
/// Bad grid options, an unreadable library, an unwritable output folder.
pub fn run(a: MapJumpsArgs) -> anyhow::Result<Outcome> {
    let (heights, speeds) = (a.heights()?.values(), a.speeds()?.values());
    anyhow::ensure!(
        !heights.is_empty() && !speeds.is_empty(),
        "the grid is empty: check --heights and --speeds"
    );
    check_grid("--heights × --speeds", heights.len(), speeds.len())?;
    let (form, mu) = a.lim.form(LimitForm::Relative)?;
    let active = a.lim.active_fraction()?;
    let (lib, pool) = load_pool(&a.lib, active)?;
    let absolute = absolute_limits(&lib);
    let limits = |p: &Prepared| stance_limits(p, form, &absolute, mu);
    let t0 = Instant::now();
    let map = jump_map(&pool, &heights, &speeds, &limits)
        .context("--heights × --speeds on this library")?;
    let elapsed = t0.elapsed().as_secs_f64();
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("cannot create {}", a.out.display()))?;
    let iou = map.agreement.iou();
    let summary = serde_json::json!({
        "heights_m": {"start": heights[0], "stop": heights[heights.len() - 1], "n": heights.len()},
        "u_apex_mps": {"start": speeds[0], "stop": speeds[speeds.len() - 1], "n": speeds.len()},
        "liftoffs": map.liftoffs.len(), "landings": map.landings.len(), "pairs": map.pairs.len(),
        "cells_approx": map.agreement.approx, "cells_exact": map.agreement.exact,
        "cells_both": map.agreement.both, "iou": iou,
        "limits": form.name(), "mu": mu, "active_set": active,
    });
    let kv = query_kv(&a.lib, summary.clone())?;
    write_atomic(
        &a.out,
        "jump_map.parquet",
        &mut jump_map_table(&map, &pool)?,
        &kv,
    )?;
    write_atomic(
        &a.out,
        "jump_map_pairs.parquet",
        &mut jump_pairs_table(&map, &pool)?,
        &kv,
    )?;
    let json_tmp = a
        .out
        .join(format!(".jump_map.json.tmp-{}", std::process::id()));
    std::fs::write(&json_tmp, serde_json::to_string_pretty(&summary)? + "\n")
        .with_context(|| format!("cannot write {}", json_tmp.display()))?;
    std::fs::rename(&json_tmp, a.out.join("jump_map.json"))
        .context("cannot write jump_map.json")?;
    let recorded = recorded_jumps(&map, &pool);
    let marks = |ids: Option<&str>| -> Vec<(f64, f64)> {
        recorded
            .iter()
            .filter(|(c, _)| ids.is_none_or(|id| id == c.as_str()))
            .map(|(_, p)| *p)
            .collect()
    };
    super::write_png(&a.out.join("jump_map.png"), |p| {
        jump_map_png(p, &map, "all characters", &marks(None))
    })?;
    // One map per character when the pool has several.
    let characters: BTreeSet<&str> = map
        .pairs
        .iter()
        .map(|p| pool[p.liftoff].stance.character_id.as_str())
        .collect();
    if characters.len() > 1 {
        for id in &characters {
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
            let file = a.out.join(format!("jump_map_{}.png", file_safe(id)));
            super::write_png(&file, |p| jump_map_png(p, &one, id, &marks(Some(*id))))?;
        }
    }
    crate::say!(
        "map jumps: {} liftoff(s) × {} landing(s) → {} pair(s) of one character, {} × {} cells",
        map.liftoffs.len(),
        map.landings.len(),
        map.pairs.len(),
        heights.len(),
        speeds.len()
    );
    crate::say!(
        "  cells feasible: approx {}, exact {}, both {}; IoU = {iou:.4}; computed in {elapsed:.3} s",
        map.agreement.approx, map.agreement.exact, map.agreement.both
    );
    crate::say!("  → {}", a.out.display());
    Ok(Outcome::Clean)
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

/// `id` with every character but ASCII letters, digits, `-` and `_` replaced by `_`.
fn file_safe(id: &str) -> String {
    id.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
