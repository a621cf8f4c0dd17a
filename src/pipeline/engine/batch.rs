//! One batch of clips: discover inputs, ingest each file in parallel (rayon), collect one
//! [`ClipRecord`] per file, sorted by clip name. A failure on one file is recorded in its
//! row and never stops the others.

use std::io::Read;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use sha2::{Digest, Sha256};

use super::inputs::{bvh_too_large, hex, open_input, InputProblem, MAX_BVH_BYTES};
use super::names::clip_names;
use crate::error::{Error, ErrorKind, Result};
use crate::ingest::{ingest, ClipOutcome, ClipSummary, IngestOptions, MASS_SOURCE_DEFAULT};
use crate::library::codec::write::FramesWriter;
use crate::library::{ClipRecord, ClipStatus, Status};

/// A reader that hashes and counts what passes through it (one pass over a large file).
struct HashingReader<R> {
    inner: R,
    hasher: Sha256,
    bytes: u64,
}

impl<R: Read> Read for HashingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.hasher.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }
}

/// Ingest one file into its record. Never fails: errors become an `error` record.
pub fn ingest_file(path: &Path, clip: String, opts: &IngestOptions) -> ClipRecord {
    let (mass_kg, sex, mass_source) = opts.body_of(&clip);
    let own;
    let opts = if (mass_kg, sex) == (opts.mass_kg, opts.sex) {
        opts
    } else {
        own = IngestOptions {
            mass_kg,
            sex,
            ..opts.clone()
        };
        &own
    };
    let mut rec = ingest_with(path, clip, opts);
    if mass_source == MASS_SOURCE_DEFAULT && rec.status == Status::Ok {
        rec.summary.warnings.push(format!(
            "body mass {mass_kg} kg assumed: no --mass, mass_kg or --masses row names this \
             clip (forces in newtons scale with it)"
        ));
    }
    rec.summary.mass_source = mass_source;
    rec
}

/// [`ingest_file`] with the clip's own mass and sex in `opts`.
fn ingest_with(path: &Path, clip: String, opts: &IngestOptions) -> ClipRecord {
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
    let file = match open_input(path) {
        Ok(f) => f,
        Err(p) => return input_error(rec, path, &p),
    };
    // One byte past the limit shows a file that grew after it was checked.
    let mut rdr = HashingReader {
        inner: file.take(MAX_BVH_BYTES + 1),
        hasher: Sha256::new(),
        bytes: 0,
    };
    let parsed = crate::bvh::parse_reader(&mut rdr).map_err(|e| e.with_path(path));
    // Hash the rest of a file whose parse stopped early, so the hash is of the whole file.
    let _ = std::io::copy(&mut rdr, &mut std::io::sink());
    if rdr.bytes > MAX_BVH_BYTES {
        return input_error(rec, path, &bvh_too_large(rdr.bytes));
    }
    rec.content_sha256 = hex(&rdr.hasher.finalize());
    // The ingest error keeps its kind; the record's message names the file before it.
    let outcome = match parsed {
        Err(e) => Err(("parse", e.to_string())),
        Ok(b) => {
            ingest(&b, opts).map_err(|e| (ingest_stage(&e), format!("{}: {e}", path.display())))
        }
    };
    match outcome {
        Err((stage, message)) => {
            rec.message = Some(message);
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

/// The `errors.parquet` stage of an ingest error: `mapping` for a skeleton that maps onto
/// no body, `frames` for a failure in the per-frame stages.
fn ingest_stage(e: &Error) -> &'static str {
    if matches!(e.kind, ErrorKind::Skeleton { .. }) {
        "mapping"
    } else {
        "frames"
    }
}

/// `rec` as an error of the `input` stage: the path could not be read as a BVH file.
fn input_error(mut rec: ClipRecord, path: &Path, problem: &InputProblem) -> ClipRecord {
    rec.message = Some(format!("{}: {problem}", path.display()));
    rec.error_stage = Some(INPUT_STAGE);
    rec
}

/// `stage` of an input that could not be read at all (`errors.parquet`).
pub const INPUT_STAGE: &str = "input";

static PROGRESS: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(true);

/// Turns the progress bars of this process on or off (`--quiet` turns them off).
pub fn set_progress(enabled: bool) {
    PROGRESS.store(enabled, std::sync::atomic::Ordering::Relaxed);
}

/// A progress bar for `len` items with elapsed time and ETA, drawn on a terminal
/// (stderr) and hidden otherwise or after [`set_progress`]`(false)`.
pub fn progress(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if !PROGRESS.load(std::sync::atomic::Ordering::Relaxed)
        || !std::io::IsTerminal::is_terminal(&std::io::stderr())
    {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    let template = format!("{{bar:40}} {{pos}}/{{len}} {what} [{{elapsed_precise}}, ETA {{eta}}]");
    if let Ok(style) = ProgressStyle::with_template(&template) {
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
    let recs = ingest_counted(files, opts, &bar);
    bar.finish_and_clear();
    recs
}

/// [`ingest_named`], counting the clips on `bar`.
fn ingest_counted(
    files: &[(PathBuf, String)],
    opts: &IngestOptions,
    bar: &ProgressBar,
) -> Vec<ClipRecord> {
    let mut recs: Vec<ClipRecord> = files
        .par_iter()
        .map(|(p, n)| ingest_counted_one(p, n, opts, bar))
        .collect();
    recs.sort_by(|a, b| a.clip.cmp(&b.clip));
    recs
}

/// [`ingest_file`], counting the clip on `bar`.
fn ingest_counted_one(
    path: &Path,
    clip: &str,
    opts: &IngestOptions,
    bar: &ProgressBar,
) -> ClipRecord {
    let r = ingest_file(path, clip.to_string(), opts);
    bar.inc(1);
    r
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
/// [`ErrorKind::Cap`] naming `field`.
pub fn check_threads(field: &str, threads: usize) -> Result<()> {
    if threads > max_threads() {
        return Err(Error::cap(
            field,
            "threads",
            threads as f64,
            max_threads(),
            "MAX_THREADS_PER_CORE × cores",
        ));
    }
    Ok(())
}

/// Where each batch of a list of clips ends (exclusive indices, in order): consecutive
/// clips, at most `max_clips` of them and at most `max_bytes` of file bytes in all, except
/// that a clip larger than `max_bytes` is a batch of its own (`max_clips` 0 counts as 1).
/// `sizes` are the clips' file sizes in bytes. Bounding the bytes as well as the count keeps a batch of the largest
/// clips of a collection within the memory of a batch of average ones.
pub fn batch_ends(sizes: &[u64], max_clips: usize, max_bytes: u64) -> Vec<usize> {
    let max_clips = max_clips.max(1);
    let mut ends = Vec::new();
    let (mut n, mut bytes) = (0usize, 0u64);
    for (i, &size) in sizes.iter().enumerate() {
        if n > 0 && (n == max_clips || bytes.saturating_add(size) > max_bytes) {
            ends.push(i);
            (n, bytes) = (0, 0);
        }
        n += 1;
        bytes = bytes.saturating_add(size);
    }
    if n > 0 {
        ends.push(sizes.len());
    }
    ends
}

/// `named` (clips in order) cut into batches by [`batch_ends`] with the file sizes on disk
/// (0 for a file whose size cannot be looked up: its error is reported when it is
/// ingested).
pub fn file_batches<T>(
    named: &[(PathBuf, T)],
    max_clips: usize,
    max_bytes: u64,
) -> Vec<&[(PathBuf, T)]> {
    let sizes: Vec<u64> = named
        .iter()
        .map(|(p, _)| std::fs::metadata(p).map_or(0, |m| m.len()))
        .collect();
    let mut start = 0;
    batch_ends(&sizes, max_clips, max_bytes)
        .into_iter()
        .map(|end| {
            let b = &named[start..end];
            start = end;
            b
        })
        .collect()
}

/// The batch bounds of the default plan on the current pool: clips and file bytes per
/// worker thread ([`DEFAULT_BATCH_CLIPS_PER_THREAD`], [`DEFAULT_BATCH_BYTES_PER_THREAD`]).
pub fn default_batch_bounds() -> (usize, u64) {
    let threads = rayon::current_num_threads().max(1);
    (
        DEFAULT_BATCH_CLIPS_PER_THREAD * threads,
        DEFAULT_BATCH_BYTES_PER_THREAD.saturating_mul(threads as u64),
    )
}

/// Ingest in batches of clips in name order, writing batch i (table assembly and Parquet
/// encoding) while batch i + 1 is ingested ([`super::ordered`]); a batch's frames are
/// freed once written, so memory depends on the batch, not on the number of clips. The
/// tables are those of one batch of every clip, byte for byte ([`FramesWriter`]); batches
/// are as a build's ([`default_batch_bounds`]). Records come back without their frames,
/// contact runs and summaries (those are in the tables).
pub(crate) fn stream_frames(
    files: &[PathBuf],
    out: &Path,
    opts: &IngestOptions,
) -> Result<Vec<ClipStatus>> {
    let mut named: Vec<(PathBuf, String)> = files.iter().cloned().zip(clip_names(files)).collect();
    named.sort_by(|a, b| a.1.cmp(&b.1));
    let (max_clips, max_bytes) = default_batch_bounds();
    let bar = progress(files.len(), "clips ingested");
    let mut w = FramesWriter::create(out, opts.joints)?;
    let mut records: Vec<ClipStatus> = Vec::with_capacity(files.len());
    super::ordered::in_order(
        &file_batches(&named, max_clips, max_bytes),
        |chunk| chunk,
        |(p, n)| ingest_counted_one(p, n, opts, &bar),
        |_, recs| {
            w.push(&recs)?;
            records.extend(recs.into_iter().map(ClipRecord::written));
            super::memory::release_free_memory();
            Ok(())
        },
    )?;
    bar.finish_and_clear();
    w.finish()?;
    Ok(records)
}

/// Clips per batch and worker thread of a streaming build: a batch holds at most this
/// many clips per thread in memory (with their frames) before its rows are written.
pub const DEFAULT_BATCH_CLIPS_PER_THREAD: usize = 4;

/// File bytes per batch and worker thread, at most (a larger clip is a batch of its own;
/// `batch::batch_ends`): about four clips of the CMU set's mean size (0.97 MB). Without it a
/// batch is bounded by its count alone, and the 25× replica, whose batches fall on other
/// clips than the bulk set's, met a batch of the largest clips (heap peak 74 MB against
/// 55 MB).
pub const DEFAULT_BATCH_BYTES_PER_THREAD: u64 = 4 << 20;

#[cfg(test)]
mod tests {
    use super::batch_ends;
    use proptest::prelude::*;

    proptest! {
        // Every clip in exactly one batch, in order; no batch over either bound unless it
        // is one clip; and each batch as long as the bounds allow (the next clip would
        // break one), so the cut is the greedy one.
        #[test]
        fn batches_cover_the_clips_within_both_bounds(
            sizes in proptest::collection::vec(0u64..10_000, 0..200),
            max_clips in 0usize..12,
            max_bytes in 0u64..30_000,
        ) {
            let ends = batch_ends(&sizes, max_clips, max_bytes);
            let mut start = 0;
            for &end in &ends {
                prop_assert!(end > start);
                let b = &sizes[start..end];
                let bytes: u64 = b.iter().sum();
                let most = max_clips.max(1);
                prop_assert!(b.len() == 1 || (b.len() <= most && bytes <= max_bytes));
                if end < sizes.len() {
                    prop_assert!(b.len() == most || bytes + sizes[end] > max_bytes);
                }
                start = end;
            }
            prop_assert_eq!(start, sizes.len());
        }
    }

    #[test]
    fn a_clip_larger_than_the_budget_is_a_batch_of_its_own() {
        assert_eq!(batch_ends(&[1, 50, 1, 1], 8, 10), vec![1, 2, 4]);
        assert_eq!(batch_ends(&[3, 3, 3, 3, 3], 2, 100), vec![2, 4, 5]);
        assert!(batch_ends(&[], 4, 10).is_empty());
        assert_eq!(
            batch_ends(&[u64::MAX, u64::MAX, 1], 8, u64::MAX - 1),
            vec![1, 2, 3]
        );
        assert_eq!(batch_ends(&[1, 1], 0, 10), vec![1, 2]);
    }
}
