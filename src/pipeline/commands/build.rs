//! The `build` and `run` commands' entry: the worker pool, then the streaming build
//! ([`crate::pipeline::engine::streaming::build_into`]), its errors given their context.

use std::path::{Path, PathBuf};

use crate::pipeline::engine::inputs::none_readable;
use crate::pipeline::engine::output::OutputRules;
use crate::pipeline::engine::streaming::{build_into, BuildOptions, BuildPlan, BuildSummary};

/// Checks there is work, then starts the rayon pool with `threads` workers (0 = all cores).
///
/// # Errors
/// No input files, none that can be read (nothing is written then), or a pool that cannot
/// start.
pub fn worker_pool(files: &[PathBuf], threads: usize) -> anyhow::Result<rayon::ThreadPool> {
    use anyhow::Context;
    if files.is_empty() {
        anyhow::bail!("no .bvh files found in the inputs");
    }
    if let Some(why) = none_readable(files) {
        anyhow::bail!("no input can be read (nothing was written):\n{why}");
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("starting the worker threads")
}

/// `build`: builds `files` into `out` on `threads` workers (0 = all cores), as
/// [`build_into`] does.
///
/// # Errors
/// No readable inputs, a pool that cannot start, or what [`build_into`] reports.
pub fn build_library(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    threads: usize,
    plan: &BuildPlan,
    rules: &OutputRules,
) -> anyhow::Result<BuildSummary> {
    use anyhow::Context;
    worker_pool(files, threads)?
        .install(|| build_into(files, out, opts, plan, rules))
        .with_context(|| format!("writing the library to {}", out.display()))
}
