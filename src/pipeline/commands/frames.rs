//! The `frames` command's entry: the per-frame tables of a batch of clips, without stances.

use std::path::{Path, PathBuf};

use super::build::worker_pool;
use crate::ingest::IngestOptions;
use crate::library::ClipStatus;
use crate::pipeline::engine::batch::stream_frames;

/// `frames`: ingests `files` on `threads` workers and writes the frame, clip and contact
/// tables (and joints, with `opts.joints`) to `out`; one record per file, failures
/// included.
///
/// # Errors
/// No readable input, a pool that cannot start, an unwritable output folder, or an output
/// folder that holds a library ([`crate::pipeline::engine::output::refuse_library`]).
pub fn frames_into(
    files: &[PathBuf],
    out: &Path,
    opts: &IngestOptions,
    threads: usize,
) -> anyhow::Result<Vec<ClipStatus>> {
    use anyhow::Context;
    crate::pipeline::engine::output::refuse_library(out)?;
    let pool = worker_pool(files, threads)?;
    pool.install(|| stream_frames(files, out, opts))
        .with_context(|| format!("writing tables to {}", out.display()))
}
