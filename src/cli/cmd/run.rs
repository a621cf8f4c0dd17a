//! `stancelib run <pipeline.toml>`: a declarative library build (inputs, body, options,
//! output folder).

use super::super::args::RunArgs;
use super::super::Outcome;
use crate::pipeline::spec::{expand_inputs, load_body, load_pipeline, relative_to, resolve};

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
    let files = crate::pipeline::batch::discover(&expand_inputs(&a.pipeline, &pipe)?)?;
    let threads = if a.body.threads > 0 {
        a.body.threads
    } else {
        pipe.threads.unwrap_or(0)
    };
    let opts = crate::pipeline::build::BuildOptions {
        ingest: opts,
        stances: crate::pipeline::spec::resolve_fit(Some(&pipe), a.body.stage_b),
    };
    super::build::execute(
        &files,
        &relative_to(&a.pipeline, &pipe.out),
        &opts,
        threads,
        a.incremental,
    )
}
