//! `stancelib build`: ingest clips and write a stance library.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::super::args::BuildArgs;
use super::super::Outcome;
use crate::pipeline::batch::discover;
use crate::pipeline::build::{build_and_write, BuildOptions};
use crate::pipeline::spec::{load_body, resolve, resolve_fit};

/// Run `build`.
///
/// # Errors
/// Bad options or body file, missing inputs, an unwritable library folder.
pub fn run(a: BuildArgs) -> anyhow::Result<Outcome> {
    let cli = a.body.overrides()?;
    let body = a.body.body.as_deref().map(load_body).transpose()?;
    let opts = BuildOptions {
        ingest: resolve(body.as_ref(), None, &cli),
        stances: resolve_fit(None, a.fit.stage_b),
    };
    execute(
        &discover(&a.inputs)?,
        &a.out,
        &opts,
        a.body.threads,
        a.incremental,
    )
}

/// Build `files` into the library folder `out`.
///
/// # Errors
/// No inputs, a thread pool that cannot start, or an unwritable library folder.
pub fn execute(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    threads: usize,
    incremental: bool,
) -> anyhow::Result<Outcome> {
    let (report, reused) = super::frames::worker_pool(files, threads)?
        .install(|| build_and_write(files, out, opts, incremental))
        .with_context(|| format!("writing the library to {}", out.display()))?;
    let outcome = super::frames::report(&report.records, out);
    println!(
        "{} stances rebuilt, {reused} clips reused",
        report.stances.len()
    );
    if reused > 0 && outcome == Outcome::AllFailed {
        return Ok(Outcome::SomeFailed);
    }
    Ok(outcome)
}
