//! `stancelib map jumps`: the jump feasibility map of a library (spec stance-model §6.10)
//! as `jump_map.parquet`, `jump_map_pairs.parquet`, `jump_map.json` and `jump_map.png`
//! (with `--diagnostics`, also `jump_map_agreement.png`).

use super::super::args::MapJumpsArgs;
use super::super::Outcome;
use crate::pipeline::commands::map_jumps::{map_jumps, MapQuery, MapReport, HIGHER_BY};

/// Run `map jumps`.
///
/// # Errors
/// Bad grid options, an unreadable library, an unwritable output folder.
pub fn run(a: MapJumpsArgs) -> anyhow::Result<Outcome> {
    crate::library::storage::layout::check_output_outside(&a.lib, &a.out)?;
    let q = MapQuery {
        lib: a.lib.clone(),
        heights: a.heights()?.values(),
        speeds: a.speeds()?.values(),
        limits: a.lim.options(),
        keep_left_out: a.keep_left_out,
        out: a.out.clone(),
        diagnostics: a.diagnostics,
    };
    print_map(&map_jumps(&q)?, &q.out);
    Ok(Outcome::Clean)
}

/// The summary of `map jumps` on stdout.
pub fn print_map(r: &MapReport, out: &std::path::Path) {
    crate::say!(
        "map jumps: {} liftoff(s) × {} landing(s) → {} pair(s) of one character, {} × {} cells",
        r.liftoffs,
        r.landings,
        r.pairs,
        r.grid.0,
        r.grid.1
    );
    crate::say!(
        "  cells feasible: approx {}, exact {}, both {}; IoU = {:.4}; computed in {:.3} s",
        r.cells.0,
        r.cells.1,
        r.cells.2,
        r.iou,
        r.elapsed_s
    );
    let shown = r.pair_answers.len().min(MAP_PAIRS_SHOWN);
    if shown > 0 {
        crate::say!(
            "  per pair (most feasible cells first; {} % higher: the recorded jump's apex × {}, \
             same distance):",
            ((HIGHER_BY - 1.0) * 100.0).round(),
            HIGHER_BY
        );
    }
    let verdict = |v: &Option<String>| {
        v.as_ref()
            .map_or("feasible".to_string(), |w| format!("no ({w})"))
    };
    for p in &r.pair_answers[..shown] {
        crate::say!(
            "  {} → {}: {} of {} cells; as recorded {}; {} % higher {}",
            p.liftoff,
            p.landing,
            p.feasible_cells,
            p.cells,
            verdict(&p.recorded),
            ((HIGHER_BY - 1.0) * 100.0).round(),
            verdict(&p.higher)
        );
    }
    if r.pair_answers.len() > shown {
        crate::say!(
            "  ({} more pairs in jump_map_pairs.parquet)",
            r.pair_answers.len() - shown
        );
    }
    crate::say!("  → {}", out.display());
}

/// Pairs `map jumps` describes on the terminal (every pair is in the tables).
pub const MAP_PAIRS_SHOWN: usize = 10;
