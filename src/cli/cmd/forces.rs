//! `stancelib forces`: every (or the named) stance's model force on its evaluation grid,
//! in stance and world axes, as one Parquet table.

use anyhow::Context;

use super::super::args::ForcesArgs;
use super::super::Outcome;
use crate::library::forces::{forces_table, read_force_stances, select_stances};
use crate::library::schema::STANCES_FILE;
use crate::pipeline::queries::{query_kv, write_table};

/// Run `forces`.
///
/// # Errors
/// An unreadable library, an unknown `--stance` id (nothing is written), an unwritable
/// output.
pub fn run(a: ForcesArgs) -> anyhow::Result<Outcome> {
    crate::library::provenance::check_layout(&a.lib)?;
    let table = a.lib.join(STANCES_FILE);
    let stances =
        read_force_stances(&table).with_context(|| format!("library {}", a.lib.display()))?;
    let chosen = select_stances(&table, &stances, &a.stances)?;
    let mut df = forces_table(&chosen)?;
    let kv = query_kv(
        &a.lib,
        serde_json::json!({
            "query": "forces", "lib": a.lib, "stances": a.stances,
        }),
    )?;
    write_table(&a.out, &mut df, &kv)?;
    crate::say!(
        "forces: {} stance(s), {} sample(s) → {}",
        chosen.len(),
        df.height(),
        a.out.display()
    );
    Ok(Outcome::Clean)
}
