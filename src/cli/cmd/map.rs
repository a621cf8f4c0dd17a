//! `stancelib map jumps`: the jump feasibility map of a library (spec stance-model §6.10)
//! as `jump_map.parquet`, `jump_map_pairs.parquet`, `jump_map.json` and `jump_map.png`.

use super::super::args::MapJumpsArgs;
use super::super::Outcome;
use crate::pipeline::queries::{map_jumps, MapQuery, MapReport};

/// Run `map jumps`.
///
/// # Errors
/// Bad grid options, an unreadable library, an unwritable output folder.
pub fn run(a: MapJumpsArgs) -> anyhow::Result<Outcome> {
    let q = MapQuery {
        lib: a.lib.clone(),
        heights: a.heights()?.values(),
        speeds: a.speeds()?.values(),
        limits: a.lim.options(),
        keep_left_out: a.keep_left_out,
        out: a.out.clone(),
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
    crate::say!("  → {}", out.display());
}
