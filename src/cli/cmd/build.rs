//! `stancelib build`: ingest clips and write a stance library.

use std::path::Path;

use anyhow::Context;

use super::super::args::{BuildArgs, MergeArgs};
use super::super::Outcome;
use crate::pipeline::commands::build::build_library;
use crate::pipeline::engine::inputs::discover;
use crate::pipeline::engine::merge::merge_into;
use crate::pipeline::engine::output::OutputRules;
use crate::pipeline::engine::streaming::{BuildOptions, BuildPlan, BuildSummary};
use crate::pipeline::spec::read_body;
use crate::pipeline::spec::{resolve, resolve_fit, with_masses};

/// Run `build`.
///
/// # Errors
/// Bad options or body file, missing inputs, an unwritable library folder.
pub fn run(a: BuildArgs) -> anyhow::Result<Outcome> {
    let cli = a.body.overrides()?;
    let body = a.body.body.as_deref().map(read_body).transpose()?;
    let opts = BuildOptions {
        ingest: with_masses(resolve(body.as_ref(), None, &cli), cli.masses.as_deref())?,
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
    let files = discover(&a.inputs)?;
    let report = build_library(&files, &a.out, &opts, a.body.threads, &plan, &rules)?;
    Ok(report_build(&report, &a.out, &plan))
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
    crate::cli::print_line(format_args!(
        "{} shards merged: {} clips, {} failed; library in {}",
        s.shards,
        s.clips,
        s.failed,
        a.out.display()
    ));
    Ok(match s.failed {
        0 => Outcome::Clean,
        f if f == s.clips => Outcome::AllFailed,
        _ => Outcome::SomeFailed,
    })
}

/// Prints a finished build's per-clip failures, summary and `--json` line; the outcome
/// for the exit code (a shard whose clips all failed is one part of a build, so it is
/// `SomeFailed`: the merge decides).
pub fn report_build(report: &BuildSummary, out: &Path, plan: &BuildPlan) -> Outcome {
    let reused = report.reused;
    for line in &report.not_reused {
        eprintln!("incremental: {line}");
    }
    let outcome = super::frames::report(&report.records, out);
    crate::say!("{} stances rebuilt, {reused} clips reused", report.stances);
    let mut summary = super::frames::summary(&report.records, out, "build");
    summary["stances_rebuilt"] = report.stances.into();
    summary["clips_reused"] = reused.into();
    summary["reuse_refused"] = report.not_reused.clone().into();
    // A library that cannot be read back here has said why already (the build's own
    // errors); the duplicates are then not reported.
    let duplicates = crate::library::readers::info::duplicate_clips(out).unwrap_or_default();
    if !duplicates.is_empty() {
        let named: Vec<String> = duplicates
            .iter()
            .take(crate::query::limits::LEFT_OUT_NAMED)
            .map(|(c, of)| format!("{} = {}", crate::error::echo(c), crate::error::echo(of)))
            .collect();
        eprintln!(
            "warning: {} duplicate clip(s), the same file content as another (the queries \
             answer with the first by name): {}{}",
            duplicates.len(),
            named.join(", "),
            if duplicates.len() > named.len() {
                ", … (`info` lists them)"
            } else {
                ""
            }
        );
    }
    summary["duplicates"] = duplicates.len().into();
    crate::cli::summary_json(&summary);
    if (reused > 0 || plan.shard.is_some()) && outcome == Outcome::AllFailed {
        return Outcome::SomeFailed;
    }
    outcome
}
