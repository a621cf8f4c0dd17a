//! `stancelib build`: ingest clips and write a stance library.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::super::args::{BuildArgs, MergeArgs};
use super::super::Outcome;
use crate::pipeline::batch::discover;
use crate::pipeline::build::{build_library, BuildOptions, BuildPlan};
use crate::pipeline::merge::merge_into;
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
    let plan = BuildPlan {
        incremental: a.incremental,
        shard: a.shard,
        batch_clips: 0,
        layout: a.layout.into(),
    };
    execute(
        &discover(&a.inputs)?,
        &a.out,
        &opts,
        a.body.threads,
        &plan,
        &rules,
    )
}

/// Run `merge`.
///
/// # Errors
/// A shard library that is missing, unfinished or of another build, or an `--out` the
/// output policy refuses.
pub fn run_merge(a: MergeArgs) -> anyhow::Result<Outcome> {
    let rules = OutputRules {
        inputs: a.shards.clone(),
        force: a.force,
    };
    let s = merge_into(&a.shards, &a.out, &rules, a.layout.into())
        .with_context(|| format!("merging into {}", a.out.display()))?;
    println!(
        "{} shards merged: {} clips, {} failed; library in {}",
        s.shards,
        s.clips,
        s.failed,
        a.out.display()
    );
    Ok(match s.failed {
        0 => Outcome::Clean,
        f if f == s.clips => Outcome::AllFailed,
        _ => Outcome::SomeFailed,
    })
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
    plan: &BuildPlan,
    rules: &OutputRules,
) -> anyhow::Result<Outcome> {
    let report = build_library(files, out, opts, threads, plan, rules)?;
    let reused = report.reused;
    let outcome = super::frames::report(&report.records, out);
    crate::say!("{} stances rebuilt, {reused} clips reused", report.stances);
    let mut summary = super::frames::summary(&report.records, out, "build");
    summary["stances_rebuilt"] = report.stances.into();
    summary["clips_reused"] = reused.into();
    crate::cli::summary_json(&summary);
    // A shard whose clips all failed is one part of a build: the merge decides.
    if (reused > 0 || plan.shard.is_some()) && outcome == Outcome::AllFailed {
        return Ok(Outcome::SomeFailed);
    }
    Ok(outcome)
}
