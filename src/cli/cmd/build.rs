//! `stancelib build`: ingest clips and write a stance library.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::super::args::BuildArgs;
use super::super::Outcome;
use crate::pipeline::batch::discover;
use crate::pipeline::build::{build_into, BuildOptions};
use crate::pipeline::output::OutputRules;
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
        stances: resolve_fit(None, a.fit.force_model),
    };
    let rules = OutputRules {
        inputs: a.inputs.clone(),
        force: a.force,
    };
    execute(
        &discover(&a.inputs)?,
        &a.out,
        &opts,
        a.body.threads,
        a.incremental,
        &rules,
    )
}

/// Build `files` into the library folder `out` under the output `rules`.
///
/// # Errors
/// No readable inputs, a thread pool that cannot start, an `out` the output policy
/// refuses or another build holds, or an unwritable library folder.
pub fn execute(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    threads: usize,
    incremental: bool,
    rules: &OutputRules,
) -> anyhow::Result<Outcome> {
    let (report, reused) = super::frames::worker_pool(files, threads)?
        .install(|| build_into(files, out, opts, incremental, rules))
        .with_context(|| format!("writing the library to {}", out.display()))?;
    let outcome = super::frames::report(&report.records, out);
    crate::say!(
        "{} stances rebuilt, {reused} clips reused",
        report.stances.len()
    );
    let mut summary = super::frames::summary(&report.records, out, "build");
    summary["stances_rebuilt"] = report.stances.len().into();
    summary["clips_reused"] = reused.into();
    crate::cli::summary_json(&summary);
    if reused > 0 && outcome == Outcome::AllFailed {
        return Ok(Outcome::SomeFailed);
    }
    Ok(outcome)
}
