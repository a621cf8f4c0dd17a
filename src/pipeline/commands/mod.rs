//! One stage per command, from typed options to written outputs: the library's
//! queries, edits, equilibrium, 2PAC, plots and catalogue, and the entries of `frames`,
//! `build` and `run`. This is the edge where errors become `anyhow` with their context;
//! the build engine below ([`super::engine`]) keeps typed errors.

use std::path::Path;

pub mod build;
pub mod catalogue;
pub mod edit;
pub mod edit_outputs;
pub mod equilibrium;
pub mod frames;
pub mod map_jumps;
pub mod plots;
pub mod queries;
pub mod query_jump;
pub mod query_run;
pub mod twopac;
pub mod twopac_outputs;
pub mod twopac_tables;

/// `(folder, file name)` of an output file path given as `--out`.
///
/// # Errors
/// A path that does not end in a UTF-8 file name.
pub fn split_out(out: &Path) -> anyhow::Result<(&Path, String)> {
    use anyhow::Context;
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("--out {}: not a file name", out.display()))?
        .to_string();
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Ok((dir, name))
}
