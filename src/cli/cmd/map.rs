//! `stancelib map jumps`: the jump feasibility map of a library (spec stance-model §6.10)
//! as `jump_map.parquet`, `jump_map_pairs.parquet`, `jump_map.json` and `jump_map.png`.

use std::time::Instant;

use anyhow::Context;

use super::super::args::MapJumpsArgs;
use super::super::Outcome;
use super::query::{absolute_limits, load_pool, query_kv, stance_limits};
use crate::library::queries::{jump_map_table, jump_pairs_table};
use crate::library::write::write_atomic;
use crate::plot::jump_map_png;
use crate::query::feasibility::LimitForm;
use crate::query::map::{check_grid, jump_map};
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
    let kv = query_kv(summary.clone());
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
    super::write_png(&a.out.join("jump_map.png"), |p| jump_map_png(p, &map))?;
    println!(
        "map jumps: {} liftoff(s) × {} landing(s) → {} pair(s) of one character, {} × {} cells",
        map.liftoffs.len(),
        map.landings.len(),
        map.pairs.len(),
        heights.len(),
        speeds.len()
    );
    println!(
        "  cells feasible: approx {}, exact {}, both {}; IoU = {iou:.4}; computed in {elapsed:.3} s",
        map.agreement.approx, map.agreement.exact, map.agreement.both
    );
    println!("  → {}", a.out.display());
    Ok(Outcome::Clean)
}
