//! A pipeline file (`pipelines/*.toml`) resolved against the command line into one job:
//! the input files, the library folder, the build's options and the `[queries]` stages on
//! the new library, every option checked before any work starts.
//!
//! Precedence, key by key: the command line, then the pipeline file, then the body file
//! (the command line's `--body`, else the pipeline's `body`), then the defaults.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::commands::map_jumps::MapQuery;
use super::commands::queries::{gait_law_choice, speed_range, LimitOptions};
use super::commands::query_run::RunQuery;
use super::engine::inputs::discover;
use super::engine::output::OutputRules;
use super::engine::streaming::{BuildOptions, BuildPlan};
use super::spec::{
    expand_inputs, read_body, read_pipeline, relative_to, resolve, resolve_fit, with_masses,
    Overrides,
};
use crate::force_model::ForceModelKind;
use crate::library::storage::layout::Layout;
use crate::pipeline::spec::{ConstraintsTable, QueriesTable};
use crate::query::feasibility::LimitForm;
use crate::query::map::{Axis, DEFAULT_HEIGHTS, DEFAULT_SPEEDS};

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

/// The `[queries]` stages of a pipeline file on the library `lib` just built, as typed
/// queries into `<lib>/queries/` (`runs.parquet`, `jump_map/`); `[constraints]` gives their
/// limit options (`limits = "per_query"` keeps each query's default form). Every option is
/// checked here, before any stage runs.
///
/// # Errors
/// A bad speed, height or apex-speed range.
pub fn query_stages(
    q: &QueriesTable,
    c: Option<&ConstraintsTable>,
    lib: &Path,
) -> anyhow::Result<(Option<RunQuery>, Option<MapQuery>)> {
    let dir = lib.join("queries");
    let limits = LimitOptions {
        form: c
            .and_then(|c| c.limits.as_deref())
            .filter(|l| *l != "per_query")
            .and_then(LimitForm::parse),
        mu: c.and_then(|c| c.mu),
        active_set: c.and_then(|c| c.active_set),
    };
    let run = match &q.run_speeds {
        Some(speeds) => Some(RunQuery {
            lib: lib.to_path_buf(),
            speeds: speed_range("--speeds", speeds)?,
            length_scale: q.length_scale.unwrap_or(1.0),
            mass_scale: q.mass_scale.unwrap_or(1.0),
            limits,
            out: dir.join("runs.parquet"),
            png: None,
            gait_law: gait_law_choice(q.gait_law.as_deref())?,
            keep_left_out: q.keep_left_out.unwrap_or(false),
            explain: None,
        }),
        None => None,
    };
    let map = match q.jump_map {
        Some(true) => Some(MapQuery {
            lib: lib.to_path_buf(),
            heights: axis_or("--heights", q.map_heights.as_deref(), DEFAULT_HEIGHTS)?,
            speeds: axis_or("--speeds", q.map_speeds.as_deref(), DEFAULT_SPEEDS)?,
            limits,
            keep_left_out: q.keep_left_out.unwrap_or(false),
            out: dir.join("jump_map"),
            diagnostics: false,
        }),
        _ => None,
    };
    Ok((run, map))
}

/// The values of the range `given` as `flag`, else of `default`.
fn axis_or(flag: &str, given: Option<&str>, default: Axis) -> anyhow::Result<Vec<f64>> {
    Ok(match given {
        Some(r) => Axis::parse(flag, r)?,
        None => default,
    }
    .values())
}
