//! `stancelib frames`: ingest clips and write the frame, clip and contact tables.

use std::path::{Path, PathBuf};

use anyhow::Context;

use super::super::args::FramesArgs;
use super::super::Outcome;
use crate::ingest::IngestOptions;
use crate::library::{write::write_all, ClipRecord, Status};
use crate::pipeline::batch::{discover, ingest_all, none_readable};
use crate::pipeline::spec::{load_body, resolve};

/// Run `frames`.
///
/// # Errors
/// Bad options or body file, missing inputs, an unwritable output folder.
pub fn run(a: FramesArgs) -> anyhow::Result<Outcome> {
    let cli = a.body.overrides()?;
    let body = a.body.body.as_deref().map(load_body).transpose()?;
    let opts = resolve(body.as_ref(), None, &cli);
    let files = discover(&a.inputs)?;
    execute(&files, &a.out, &opts, a.body.threads)
}

/// Ingest `files` with `threads` workers and write the tables to `out`.
///
/// # Errors
/// A thread pool that cannot start, or an unwritable output folder.
pub fn execute(
    files: &[PathBuf],
    out: &Path,
    opts: &IngestOptions,
    threads: usize,
) -> anyhow::Result<Outcome> {
    let pool = worker_pool(files, threads)?;
    let records = pool.install(|| ingest_all(files, opts));
    // On the same workers: the tables and their columns are encoded in parallel.
    pool.install(|| write_all(out, &records, opts.joints))
        .with_context(|| format!("writing tables to {}", out.display()))?;
    let outcome = report(&records, out);
    crate::cli::summary_json(&summary(&records, out, "frames"));
    Ok(outcome)
}

/// The `--json` summary of a batch: `command`, `clips`, `ok`, `skipped`, `failed`, `out`.
pub fn summary(records: &[ClipRecord], out: &Path, command: &str) -> serde_json::Value {
    let count = |s: Status| records.iter().filter(|r| r.status == s).count();
    serde_json::json!({
        "command": command,
        "clips": records.len(),
        "ok": count(Status::Ok),
        "skipped": count(Status::Skipped),
        "failed": count(Status::Error),
        "out": out,
    })
}

/// Check there is work, then start the rayon pool with `threads` workers (0 = all cores).
///
/// # Errors
/// No input files, none that can be read (nothing is written then), or a pool that cannot
/// start.
pub fn worker_pool(files: &[PathBuf], threads: usize) -> anyhow::Result<rayon::ThreadPool> {
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

/// Print the per-clip failures and a one-line summary; the outcome for the exit code.
pub fn report(records: &[ClipRecord], out: &Path) -> Outcome {
    let count = |s: Status| records.iter().filter(|r| r.status == s).count();
    for r in records.iter().filter(|r| r.status == Status::Error) {
        eprintln!("error: {}", r.message.as_deref().unwrap_or("unknown error"));
    }
    for r in records
        .iter()
        .filter(|r| r.status == Status::Skipped && !crate::cli::quiet())
    {
        eprintln!(
            "skipped: {}: {}",
            r.path,
            r.message.as_deref().unwrap_or("")
        );
    }
    let failed = count(Status::Error);
    crate::say!(
        "{} clips: {} ok, {} skipped, {} failed; tables in {}",
        records.len(),
        count(Status::Ok),
        count(Status::Skipped),
        failed,
        out.display()
    );
    match failed {
        0 => Outcome::Clean,
        f if f == records.len() => Outcome::AllFailed,
        _ => Outcome::SomeFailed,
    }
}
