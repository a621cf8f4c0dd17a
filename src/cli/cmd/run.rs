//! `stancelib run <pipeline.toml>`: a declarative library build (inputs, body, options,
//! output folder), then the `[queries]` stages on the new library.

use std::path::Path;

use anyhow::Context;

use super::super::args::RunArgs;
use super::super::Outcome;
use crate::pipeline::queries::{map_jumps, query_stages, run_query};
use crate::pipeline::spec::{
    expand_inputs, load_body, load_pipeline, relative_to, resolve, ConstraintsTable, QueriesTable,
};

/// Run a pipeline file.
///
/// # Errors
/// Invalid pipeline or body file, inputs that match nothing, an unwritable output.
pub fn run(a: RunArgs) -> anyhow::Result<Outcome> {
    let pipe = load_pipeline(&a.pipeline)?;
    let cli = a.body.overrides()?;
    let body_path = a
        .body
        .body
        .clone()
        .or_else(|| pipe.body.as_deref().map(|b| relative_to(&a.pipeline, b)));
    let body = body_path.as_deref().map(load_body).transpose()?;
    let opts = resolve(body.as_ref(), Some(&pipe), &cli);
    let inputs = expand_inputs(&a.pipeline, &pipe)?;
    let files = crate::pipeline::batch::discover(&inputs)?;
    let threads = if a.body.threads > 0 {
        a.body.threads
    } else {
        pipe.threads.unwrap_or(0)
    };
    let opts = crate::pipeline::build::BuildOptions {
        ingest: opts,
        stances: crate::pipeline::spec::resolve_fit(Some(&pipe), a.fit.force_model),
    };
    let lib = relative_to(&a.pipeline, &pipe.out);
    let rules = crate::pipeline::output::OutputRules {
        inputs,
        force: a.force,
    };
    let plan = crate::pipeline::build::BuildPlan {
        incremental: a.incremental,
        layout: pipe
            .layout
            .as_deref()
            .and_then(crate::library::layout::Layout::parse)
            .unwrap_or_default(),
        ..Default::default()
    };
    let outcome = super::build::execute(&files, &lib, &opts, threads, &plan, &rules)?;
    if let Some(q) = &pipe.queries {
        run_queries(q, pipe.constraints.as_ref(), &lib)
            .with_context(|| format!("{}: [queries]", a.pipeline.display()))?;
    }
    Ok(outcome)
}

/// The `[queries]` stages on the library just built, into `<lib>/queries/` (every stage's
/// options checked before the first runs).
fn run_queries(q: &QueriesTable, c: Option<&ConstraintsTable>, lib: &Path) -> anyhow::Result<()> {
    let (run, map) = query_stages(q, c, lib)?;
    if let Some(r) = &run {
        super::query::print_run(&run_query(r)?, &r.out);
    }
    if let Some(m) = &map {
        super::map::print_map(&map_jumps(m)?, &m.out);
    }
    Ok(())
}
