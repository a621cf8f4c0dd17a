//! `stancelib frames`: ingest clips and write the frame, clip and contact tables.

use std::path::{Path, PathBuf};

use super::super::args::FramesArgs;
use super::super::Outcome;
use crate::ingest::IngestOptions;
use crate::library::{ClipStatus, Status};
use crate::pipeline::commands::frames::frames_into;
use crate::pipeline::engine::inputs::discover;
use crate::pipeline::spec::read_body;
use crate::pipeline::spec::{resolve, with_masses};

/// Run `frames`.
///
/// # Errors
/// Bad options or body file, missing inputs, an unwritable output folder.
pub fn run(a: FramesArgs) -> anyhow::Result<Outcome> {
    let cli = a.body.overrides()?;
    let body = a.body.body.as_deref().map(read_body).transpose()?;
    let opts = with_masses(resolve(body.as_ref(), None, &cli), cli.masses.as_deref())?;
    let files = discover(&a.inputs)?;
    execute(&files, &a.out, &opts, a.body.threads)
}

/// Ingest `files` with `threads` workers, write the tables to `out`, report.
///
/// # Errors
/// No readable input, a thread pool that cannot start, or an unwritable output folder.
pub fn execute(
    files: &[PathBuf],
    out: &Path,
    opts: &IngestOptions,
    threads: usize,
) -> anyhow::Result<Outcome> {
    let records = frames_into(files, out, opts, threads)?;
    let outcome = report(&records, out);
    crate::cli::summary_json(&summary(&records, out, "frames"));
    Ok(outcome)
}

/// The `--json` summary of a batch: `command`, `clips`, `ok`, `skipped`, `failed`, `out`.
pub fn summary(records: &[ClipStatus], out: &Path, command: &str) -> serde_json::Value {
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

/// Print the per-clip failures and a one-line summary; the outcome for the exit code.
pub fn report(records: &[ClipStatus], out: &Path) -> Outcome {
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
