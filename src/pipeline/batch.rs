//! One batch of clips: discover inputs, ingest each file in parallel (rayon), collect one
//! [`ClipRecord`] per file, sorted by clip name. A failure on one file is recorded in its
//! row and never stops the others.

use std::io::Read;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use sha2::{Digest, Sha256};

use super::names::clip_names;
use crate::error::{Error, ErrorKind, Result};
use crate::ingest::{ingest, ClipOutcome, ClipSummary, IngestOptions};
use crate::library::{ClipRecord, Status};

/// Expand files and folders (recursively, `*.bvh` case-insensitive) into a sorted,
/// de-duplicated list of files.
///
/// # Errors
/// An input that does not exist.
pub fn discover(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in inputs {
        if p.is_dir() {
            walk(p, &mut out)?;
        } else if p.is_file() {
            out.push(p.clone());
        } else {
            return Err(Error::config(
                Some(p.clone()),
                None,
                "no such file or folder",
            ));
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    let rd = std::fs::read_dir(dir).map_err(|e| Error::io(dir, "cannot list folder", e))?;
    for entry in rd {
        let p = entry
            .map_err(|e| Error::io(dir, "cannot list folder", e))?
            .path();
        if p.is_dir() {
            walk(&p, out)?;
        } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) {
            out.push(p);
        }
    }
    Ok(())
}

/// A reader that hashes what passes through it (one pass over a large file).
struct HashingReader<R> {
    inner: R,
    hasher: Sha256,
}

impl<R: Read> Read for HashingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.hasher.update(&buf[..n]);
        Ok(n)
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Ingest one file into its record. Never fails: errors become an `error` record.
pub fn ingest_file(path: &Path, clip: String, opts: &IngestOptions) -> ClipRecord {
    let mut rec = ClipRecord {
        path: path.display().to_string(),
        clip,
        content_sha256: String::new(),
        status: Status::Error,
        message: None,
        error_stage: None,
        mass_kg: opts.mass_kg,
        summary: ClipSummary::default(),
        frames: None,
        contacts: Vec::new(),
    };
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) => {
            rec.message = Some(format!("{}: cannot open: {e}", path.display()));
            rec.error_stage = Some("parse");
            return rec;
        }
    };
    let mut rdr = HashingReader {
        inner: file,
        hasher: Sha256::new(),
    };
    let parsed = crate::bvh::parse_reader(&mut rdr).map_err(|e| e.with_path(path));
    // Hash the rest of a file whose parse stopped early, so the hash is of the whole file.
    let _ = std::io::copy(&mut rdr, &mut std::io::sink());
    rec.content_sha256 = hex(&rdr.hasher.finalize());
    let outcome = match parsed {
        Err(e) => Err(("parse", e)),
        Ok(b) => ingest(&b, opts).map_err(|e| {
            let stage = if matches!(e.kind, ErrorKind::Skeleton { .. }) {
                "mapping"
            } else {
                "frames"
            };
            (stage, Error::skeleton(format!("{}: {e}", path.display())))
        }),
    };
    match outcome {
        Err((stage, e)) => {
            rec.message = Some(e.to_string());
            rec.error_stage = Some(stage);
        }
        Ok(ClipOutcome::Skipped { summary, reason }) => {
            rec.status = Status::Skipped;
            rec.message = Some(reason);
            rec.summary = summary;
        }
        Ok(ClipOutcome::Body {
            summary,
            frames,
            contacts,
        }) => {
            rec.status = Status::Ok;
            rec.summary = summary;
            rec.frames = Some(frames);
            rec.contacts = contacts;
        }
    }
    rec
}

/// A progress bar for `len` items, drawn on a terminal (stderr) and hidden otherwise.
pub fn progress(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    if let Ok(style) = ProgressStyle::with_template(&format!("{{bar:40}} {{pos}}/{{len}} {what}")) {
        bar.set_style(style);
    }
    bar
}

/// Ingest every file in parallel; records sorted by clip name.
pub fn ingest_all(files: &[PathBuf], opts: &IngestOptions) -> Vec<ClipRecord> {
    let named: Vec<(PathBuf, String)> = files.iter().cloned().zip(clip_names(files)).collect();
    ingest_named(&named, opts)
}

/// Ingest `(file, clip name)` pairs in parallel; records sorted by clip name.
pub fn ingest_named(files: &[(PathBuf, String)], opts: &IngestOptions) -> Vec<ClipRecord> {
    let bar = progress(files.len(), "clips ingested");
    let mut recs: Vec<ClipRecord> = files
        .par_iter()
        .map(|(p, n)| {
            let r = ingest_file(p, n.clone(), opts);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    recs.sort_by(|a, b| a.clip.cmp(&b.clip));
    recs
}

/// SHA-256 of a file's bytes, hex (`None` when unreadable).
pub fn file_sha256(path: &Path) -> Option<String> {
    let mut f = std::fs::File::open(path).ok()?;
    let mut h = Sha256::new();
    std::io::copy(&mut f, &mut h).ok()?;
    Some(hex(&h.finalize()))
}

/// Worker threads allowed per core: `--threads` and the pipeline's `threads` are at most
/// this many times `std::thread::available_parallelism()` (each worker holds one clip
/// in memory; more threads than that only add memory and switching).
pub const MAX_THREADS_PER_CORE: usize = 4;

/// The largest accepted thread count: [`MAX_THREADS_PER_CORE`] × the cores available.
pub fn max_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    MAX_THREADS_PER_CORE * cores
}

/// Checks a requested worker count (0 = all cores) against [`max_threads`].
///
/// # Errors
/// [`ErrorKind::Limit`] naming `field`.
pub fn check_threads(field: &str, threads: usize) -> Result<()> {
    if threads > max_threads() {
        return Err(Error::limit(
            field,
            "threads",
            threads as f64,
            max_threads(),
            "MAX_THREADS_PER_CORE × cores",
        ));
    }
    Ok(())
}
