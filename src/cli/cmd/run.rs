//! `stancelib run <pipeline.toml>`: a declarative library build (inputs, body, options,
//! output folder), then the `[queries]` stages on the new library. The job is resolved by
//! [`crate::pipeline::job`]; this command runs it and prints.

use anyhow::Context;

use super::super::args::RunArgs;
use super::super::Outcome;
use crate::pipeline::commands::build::build_library;
use crate::pipeline::commands::map_jumps::map_jumps;
use crate::pipeline::commands::query_run::run_query;
use crate::pipeline::job::{pipeline_job, CommandLine};

/// Run a pipeline file.
///
/// # Errors
/// Invalid pipeline or body file, inputs that match nothing, an unwritable output.
pub fn run(a: RunArgs) -> anyhow::Result<Outcome> {
    let overrides = a.body.overrides()?;
    let cl = CommandLine {
        overrides: &overrides,
        body: a.body.body.as_deref(),
        force_model: a.fit.force_model,
        threads: a.body.threads,
        force: a.force,
        incremental: a.incremental,
    };
    let job = pipeline_job(&a.pipeline, &cl)?;
    let report = build_library(
        &job.files,
        &job.lib,
        &job.opts,
        job.threads,
        &job.plan,
        &job.rules,
    )?;
    let outcome = super::build::report_build(&report, &job.lib, &job.plan);
    let stage = || format!("{}: [queries]", a.pipeline.display());
    if let Some(r) = &job.run {
        super::query::print_run(&run_query(r).with_context(stage)?, &r.out);
    }
    if let Some(m) = &job.map {
        super::map::print_map(&map_jumps(m).with_context(stage)?, &m.out);
    }
    Ok(outcome)
}
