//! A pipeline file (`pipelines/*.toml`) resolved against the command line into one job:
//! the input files, the library folder, the build's options and the `[queries]` stages on
//! the new library, every option checked before any work starts.
//!
//! Precedence, key by key: the command line, then the pipeline file, then the body file
//! (the command line's `--body`, else the pipeline's `body`), then the defaults.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::batch::discover;
use super::build::{BuildOptions, BuildPlan};
use super::inputs::{read_body, read_pipeline};
use super::output::OutputRules;
use super::queries::{query_stages, MapQuery, RunQuery};
use super::spec::{expand_inputs, relative_to, resolve, resolve_fit, with_masses, Overrides};
use crate::force_model::ForceModelKind;
use crate::library::layout::Layout;

/// What the command line adds to a pipeline file.
#[derive(Debug, Clone)]
pub struct CommandLine<'a> {
    /// Ingest overrides (`--mass`, `--sex`, …).
    pub overrides: &'a Overrides,
    /// `--body`: a body file instead of the pipeline's.
    pub body: Option<&'a Path>,
    /// `--force-model`.
    pub force_model: Option<ForceModelKind>,
    /// `--threads` (0: the pipeline's, else all cores).
    pub threads: usize,
    /// `--force`: replace an output folder the tool did not write.
    pub force: bool,
    /// `--incremental`: reuse the clips of an existing library.
    pub incremental: bool,
}

/// A pipeline ready to run.
#[derive(Debug, Clone)]
pub struct PipelineJob {
    /// The input files, in discovery order.
    pub files: Vec<PathBuf>,
    /// The library folder.
    pub lib: PathBuf,
    /// The build's options.
    pub opts: BuildOptions,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// Incremental build (no shards).
    pub plan: BuildPlan,
    /// The output policy.
    pub rules: OutputRules,
    /// The `run_speeds` stage.
    pub run: Option<RunQuery>,
    /// The `jump_map` stage.
    pub map: Option<MapQuery>,
}

/// Reads the pipeline file at `path` and its body file, resolves every option against
/// `cl`, checks the query stages and finds the inputs.
///
/// # Errors
/// An invalid pipeline or body file, a bad `[queries]` value, inputs that match nothing.
pub fn pipeline_job(path: &Path, cl: &CommandLine<'_>) -> anyhow::Result<PipelineJob> {
    let pipe = read_pipeline(path)?;
    let body_path = cl
        .body
        .map(Path::to_path_buf)
        .or_else(|| pipe.body.as_deref().map(|b| relative_to(path, b)));
    let body = body_path.as_deref().map(read_body).transpose()?;
    let opts = BuildOptions {
        ingest: with_masses(
            resolve(body.as_ref(), Some(&pipe), cl.overrides),
            cl.overrides
                .masses
                .clone()
                .or_else(|| pipe.masses.as_deref().map(|m| relative_to(path, m)))
                .as_deref(),
        )?,
        stances: resolve_fit(Some(&pipe), cl.force_model),
    };
    let lib = relative_to(path, &pipe.out);
    let (run, map) = match &pipe.queries {
        Some(q) => query_stages(q, pipe.constraints.as_ref(), &lib)
            .with_context(|| format!("{}: [queries]", path.display()))?,
        None => (None, None),
    };
    let inputs = expand_inputs(path, &pipe)?;
    let files = discover(&inputs)?;
    let threads = if cl.threads > 0 {
        cl.threads
    } else {
        pipe.threads.unwrap_or(0)
    };
    Ok(PipelineJob {
        files,
        lib,
        opts,
        threads,
        plan: BuildPlan {
            incremental: cl.incremental,
            layout: pipe
                .layout
                .as_deref()
                .and_then(Layout::parse)
                .unwrap_or_default(),
            ..Default::default()
        },
        rules: OutputRules {
            inputs,
            force: cl.force,
        },
        run,
        map,
    })
}
