//! Building a stance library: ingest every clip, build its stances in parallel, compute the
//! per-character limits and polytopes, and write every table plus `manifest.json` into a
//! temporary folder that replaces the library folder in one step.
//!
//! The build streams: clips are taken in name order in batches of at most
//! [`DEFAULT_BATCH_CLIPS_PER_THREAD`](super::batch::DEFAULT_BATCH_CLIPS_PER_THREAD) clips and [`DEFAULT_BATCH_BYTES_PER_THREAD`](super::batch::DEFAULT_BATCH_BYTES_PER_THREAD) file
//! bytes per worker thread (`batch::batch_ends`), and each batch's rows are
//! appended to the tables (`pipeline::engine::sink`) while the next batch is built (two batches in
//! memory at most), so memory depends on the largest clips and the thread count, not on
//! the number of clips. The files are the same, byte for byte, whatever the batch size and
//! thread count. What overlapping the writing with the next batch gained, measured, is in
//! `docs/decisions.md` ("Measurements of the build engine").
//!
//! With `incremental`, the rows of clips whose path, content hash and options are those
//! of the previous library are taken from it instead of being rebuilt; the result is the
//! same, byte for byte, as a full rebuild (rows are re-sorted by the same keys and cast to
//! the same schema). Nothing is taken from a table whose bytes are not those its manifest
//! recorded, nor from a clip whose rows are not as many as recorded
//! ([`crate::library::storage::integrity`]): those clips are rebuilt and the summary says why.
//!
//! With a [`Shard`], only the inputs of that shard are built, and the library also keeps
//! its kinematic samples and a `shard` entry in its manifest for [`super::merge`].
//!
//! Layout of a library folder: `frames.parquet`, `contacts.parquet`, `clips.parquet`,
//! `stances.parquet`, `errors.parquet`, `manifest.json` (spec stance-model §11); with
//! [`Layout::Dataset`] each table is a hive-partitioned dataset instead
//! ([`crate::library::storage::layout`]). `incremental` reads the previous library in its layout.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use indicatif::ProgressBar;
use polars::prelude::*;
use rayon::prelude::*;

use super::batch::{ingest_file, progress};
use super::cursor::ClipCursor;
use super::inputs::file_sha256;
use super::names::clip_names;
use super::output::{claim, name_of, parent_of, swap_into_place, OutputRules};
use super::shard::{inputs_fingerprint, shard_of, Shard};
use super::sink::LibrarySink;
use super::tables::{combine, strings, BuildReport, Tables};
use crate::error::{Error, Result};
use crate::ingest::IngestOptions;
use crate::library::codec::provenance::library_layout;
use crate::library::codec::schema::{
    clips, CLIPS_FILE, ERRORS_FILE, SCHEMA_VERSION, SOURCE_DIGEST,
};
use crate::library::codec::stances::{first_non_finite, ErrorRow};
use crate::library::codec::table::read_parquet;
use crate::library::storage::integrity::{
    check_clip_rows, check_table, recorded_clip_rows, recorded_digests, Mismatch,
};
use crate::library::storage::layout::Layout;
use crate::library::storage::scratch::{scratch_name, Scratch};
use crate::library::{ClipRecord, ClipStatus, Status};
use crate::stances::assemble::StanceNote;
use crate::stances::{assemble_clip, Stance, StanceOptions};

/// How a build runs: none of it changes the rows of a clip.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BuildPlan {
    /// Reuse the rows of unchanged clips from the library at the output (`--incremental`).
    pub incremental: bool,
    /// Build only this shard of the inputs (`--shard I/N`).
    pub shard: Option<Shard>,
    /// Most clips per batch; 0 = [`DEFAULT_BATCH_CLIPS_PER_THREAD`](super::batch::DEFAULT_BATCH_CLIPS_PER_THREAD) × the worker threads
    /// (the bytes per batch are bounded either way: [`DEFAULT_BATCH_BYTES_PER_THREAD`](super::batch::DEFAULT_BATCH_BYTES_PER_THREAD)).
    pub batch_clips: usize,
    /// How the tables are laid out (`--layout`; the rows are the same).
    pub layout: Layout,
}

/// Options of a library build.
#[derive(serde::Serialize, Debug, Clone, PartialEq, Default)]
pub struct BuildOptions {
    /// Ingest options.
    pub ingest: IngestOptions,
    /// Stance options.
    pub stances: StanceOptions,
}

impl BuildOptions {
    /// The options as recorded in the manifest and the Parquet metadata: canonical JSON
    /// (object keys sorted; spec stance-model §11).
    pub fn fingerprint(&self) -> String {
        serde_json::to_value(self)
            .map(|v| v.to_string())
            .unwrap_or_default()
    }
}

/// What a written build did.
#[derive(Debug)]
pub struct BuildSummary {
    /// The outcome of every rebuilt input file, sorted by clip (the rest of its record is
    /// in the library; the flights and warnings of a large build's summaries grew its
    /// memory by about 10 kB a clip, the records without them by about 1.9 kB).
    pub records: Vec<ClipStatus>,
    /// Stances of the rebuilt clips.
    pub stances: usize,
    /// Clips whose rows came from the previous library (`incremental`).
    pub reused: usize,
    /// Why the previous library's rows were not reused, where it was there but did not
    /// match its manifest or this build (`incremental`; one line each).
    pub not_reused: Vec<String>,
}

/// Ingest and build (pure apart from reading the input files).
pub fn build(files: &[PathBuf], opts: &BuildOptions) -> BuildReport {
    let named: Vec<(PathBuf, String)> = files.iter().cloned().zip(clip_names(files)).collect();
    build_named(&named, opts, &Progress::hidden())
}

/// The progress of a build: clips done of all, frames per second and an ETA.
struct Progress {
    bar: ProgressBar,
    frames: AtomicU64,
    t0: Instant,
}

impl Progress {
    fn new(clips: usize) -> Progress {
        Progress {
            bar: progress(clips, "clips, {msg}, ETA {eta}"),
            frames: AtomicU64::new(0),
            t0: Instant::now(),
        }
    }

    fn hidden() -> Progress {
        let p = Progress::new(0);
        p.bar
            .set_draw_target(indicatif::ProgressDrawTarget::hidden());
        p
    }

    fn done(&self, clips: u64, frames: u64) {
        let all = self.frames.fetch_add(frames, Ordering::Relaxed) + frames;
        let secs = self.t0.elapsed().as_secs_f64().max(1e-3);
        self.bar
            .set_message(format!("{:.0} frames/s", all as f64 / secs));
        self.bar.inc(clips);
    }
}

/// One batch of a streaming build: the (file, clip) pairs to build, and the batch's last
/// clip, reused or not (the previous library's rows are taken through it).
struct BuildBatch<'a> {
    todo: Vec<&'a (PathBuf, String)>,
    last: Option<&'a String>,
}

/// What the stance stage made of one clip: its stances and notes.
type ClipStances = (Vec<Stance>, Vec<StanceNote>);

fn build_named(named: &[(PathBuf, String)], opts: &BuildOptions, bar: &Progress) -> BuildReport {
    let per_clip: Vec<(ClipRecord, ClipStances)> = named
        .par_iter()
        .map(|(path, clip)| build_one(path, clip, opts, bar))
        .collect();
    report_of(per_clip)
}

/// One clip ingested and its stances built, counted on `bar`.
fn build_one(
    path: &Path,
    clip: &str,
    opts: &BuildOptions,
    bar: &Progress,
) -> (ClipRecord, ClipStances) {
    let r = ingest_file(path, clip.to_string(), &opts.ingest);
    let out = match (&r.frames, r.status) {
        (Some(fr), Status::Ok) => assemble_clip(
            &r.clip,
            fr,
            &r.summary,
            &r.contacts,
            r.mass_kg,
            &opts.stances,
        ),
        _ => (Vec::new(), Vec::new()),
    };
    bar.done(1, r.frames.as_ref().map_or(0, |f| f.frame.len() as u64));
    refuse_non_finite(r, out)
}

/// A clip whose stances hold a non-finite number (inf or NaN in any column) becomes a
/// per-clip error of stage `stances`, with no rows: the last guard before the tables.
fn refuse_non_finite(mut r: ClipRecord, out: ClipStances) -> (ClipRecord, ClipStances) {
    let found = match first_non_finite(&out.0) {
        Ok(None) => return (r, out),
        Ok(Some(cell)) => format!(
            "stance {}: {} is {} (not finite): the clip's offsets, angles or body values \
             overflow; no row of it is written",
            crate::error::echo(&cell.stance_id),
            cell.column,
            cell.value
        ),
        Err(e) => format!("its stance rows cannot be checked: {e}"),
    };
    r.status = Status::Error;
    r.error_stage = Some("stances");
    r.message = Some(format!("{}: {found}", r.path));
    r.frames = None;
    r.contacts = Vec::new();
    (r, (Vec::new(), Vec::new()))
}

/// The report of a batch of built clips: records in clip order, their error rows (failed
/// inputs, ingests and stance fits) and their stances sorted by (clip, first frame, label).
fn report_of(mut per_clip: Vec<(ClipRecord, ClipStances)>) -> BuildReport {
    per_clip.sort_by(|a, b| a.0.clip.cmp(&b.0.clip));
    let (mut records, per_clip): (Vec<ClipRecord>, Vec<ClipStances>) = per_clip.into_iter().unzip();
    let mut errors: Vec<ErrorRow> = records
        .iter()
        .filter(|r| r.status == Status::Error)
        .map(|r| ErrorRow {
            path: r.path.clone(),
            clip: Some(r.clip.clone()),
            stage: r.error_stage.unwrap_or("frames").to_string(),
            message: r.message.clone().unwrap_or_default(),
        })
        .collect();
    for (r, (_, warnings)) in records.iter_mut().zip(&per_clip) {
        // Every stance-stage warning is kept with its clip (clips.parquet `warnings`);
        // failed fits are also errors.
        r.summary
            .warnings
            .extend(warnings.iter().map(|w| format!("stances: {}", w.message)));
        for w in warnings.iter().filter(|w| w.failed) {
            errors.push(ErrorRow {
                path: r.path.clone(),
                clip: Some(r.clip.clone()),
                stage: "stances".into(),
                message: w.message.clone(),
            });
        }
    }
    let mut stances: Vec<Stance> = per_clip.into_iter().flat_map(|(s, _)| s).collect();
    stances.sort_by(|a, b| {
        (&a.clip, a.first_frame, &a.label).cmp(&(&b.clip, b.first_frame, &b.label))
    });
    BuildReport {
        records,
        stances,
        errors,
    }
}

/// What an incremental build takes from the previous library at its output.
#[derive(Default)]
struct Reuse {
    /// The clips whose rows are reused.
    clips: BTreeSet<String>,
    /// Why rows were not reused although the library was there (one line each).
    refused: Vec<String>,
    /// The previous library's tables, open for the reused clips.
    previous: Option<Previous>,
}

/// Most clips a refusal names one by one (the rest are counted).
const REFUSED_CLIPS_NAMED: usize = 10;

/// The first 12 hex digits of a digest (enough to tell two builds apart in a message).
fn short_digest(d: &str) -> String {
    d.chars().take(12).collect()
}

/// Clips of the previous library at `out` that can be reused for `named`: the library's
/// options, layout and source digest are this build's, every table it gives rows from has the content
/// hash its manifest recorded ([`crate::library::storage::integrity`]), and per clip the input's
/// path and content are unchanged and its rows in every table are as many as recorded.
/// Anything else is rebuilt, with a line in `refused` saying why.
fn reusable(out: &Path, named: &[(PathBuf, String)], fingerprint: &str, joints: bool) -> Reuse {
    let Ok(manifest) = crate::library::codec::manifest::read_manifest(out) else {
        return Reuse::default();
    };
    let all = |why: String| Reuse {
        refused: vec![format!("{}: {why}: every clip is rebuilt", out.display())],
        ..Reuse::default()
    };
    let current: Option<serde_json::Value> = serde_json::from_str(fingerprint).ok();
    if current.is_none() || manifest.get("options") != current.as_ref() {
        return all("the library was built with other options".into());
    }
    // Rows computed by other code are not this build's rows.
    let digest = manifest.get("source_digest").and_then(|d| d.as_str());
    if digest != Some(SOURCE_DIGEST) {
        return all(format!(
            "the library was written by another build of stancelib (source digest {}, this \
             build {})",
            digest.map_or("none".to_string(), short_digest),
            short_digest(SOURCE_DIGEST)
        ));
    }
    // Rows of another table layout cannot be copied into this one.
    if library_layout(out).as_deref() != Some(SCHEMA_VERSION) {
        return all(format!(
            "the library is not of table layout {SCHEMA_VERSION}"
        ));
    }
    let Ok(mut t) = Tables::empty(joints) else {
        return Reuse::default();
    };
    let mut read: Vec<&'static str> = t.named().into_iter().map(|(n, _)| n).collect();
    read.push(ERRORS_FILE);
    let recorded = recorded_digests(&manifest);
    let checked: Vec<std::result::Result<(), Mismatch>> = read
        .par_iter()
        .map(|f| check_table(out, f, recorded.as_ref()))
        .collect();
    if let Some(Err(m)) = checked.into_iter().find(|c| c.is_err()) {
        return all(m.to_string());
    }
    let Ok(clips) = read_parquet(&out.join(CLIPS_FILE)) else {
        return all(format!("{CLIPS_FILE} cannot be read"));
    };
    let prev: BTreeMap<String, (String, String, String)> = strings(&clips, clips::CLIP)
        .into_iter()
        .zip(
            strings(&clips, clips::PATH)
                .into_iter()
                .zip(strings(&clips, clips::CONTENT_SHA256))
                .zip(strings(&clips, clips::STATUS)),
        )
        .map(|(c, ((p, h), s))| (c, (p, h, s)))
        .collect();
    let unchanged: BTreeSet<String> = named
        .par_iter()
        .filter_map(|(path, clip)| {
            let (p, h, s) = prev.get(clip)?;
            let same = *p == path.display().to_string()
                && s != "error"
                && file_sha256(path).as_deref() == Some(h.as_str());
            same.then(|| clip.clone())
        })
        .collect();
    if unchanged.is_empty() {
        return Reuse::default();
    }
    let previous = match Previous::open(out, &mut t) {
        Ok(p) => p,
        Err(e) => return all(format!("{e}")),
    };
    let rows = recorded_clip_rows(&manifest);
    let found: Vec<(&str, BTreeMap<&str, u64>)> = previous
        .cursors
        .iter()
        .filter(|(name, _)| *name != CLIPS_FILE)
        .map(|(name, cur)| (*name, cur.rows_per_clip()))
        .collect();
    let mut clips = BTreeSet::new();
    let mut mismatched: Vec<Mismatch> = Vec::new();
    for clip in unchanged {
        let found = found
            .iter()
            .map(|(name, per_clip)| {
                let n = per_clip.get(clip.as_str()).copied().unwrap_or(0);
                check_clip_rows(&rows, &clip, name, n)
            })
            .find(|c| c.is_err());
        match found {
            Some(Err(m)) => mismatched.push(m),
            _ => {
                clips.insert(clip);
            }
        }
    }
    let mut refused: Vec<String> = mismatched
        .iter()
        .take(REFUSED_CLIPS_NAMED)
        .map(|m| format!("{}: {m}: the clip is rebuilt", out.display()))
        .collect();
    if mismatched.len() > REFUSED_CLIPS_NAMED {
        refused.push(format!(
            "{}: {} more clips whose rows are not as recorded are rebuilt",
            out.display(),
            mismatched.len() - REFUSED_CLIPS_NAMED
        ));
    }
    Reuse {
        clips,
        refused,
        previous: Some(previous),
    }
}

/// The previous library at the output, read forward in clip order for the reused clips.
struct Previous {
    cursors: Vec<(&'static str, ClipCursor)>,
}

impl Previous {
    /// Open the tables of the library `out` that `t` (empty tables of this build) names.
    fn open(out: &Path, t: &mut Tables) -> Result<Previous> {
        let cursors = t
            .named()
            .into_iter()
            .map(|(name, _)| Ok((name, ClipCursor::open(&out.join(name))?)))
            .collect::<Result<Vec<_>>>()?;
        Ok(Previous { cursors })
    }

    /// Add the previous rows of the `reused` clips of a batch whose last clip is `last`.
    fn add_rows(&mut self, t: &mut Tables, last: &str, reused: &BTreeSet<String>) -> Result<()> {
        for ((name, df), (_, cur)) in t.named().into_iter().zip(self.cursors.iter_mut()) {
            let keep = |c: &str| reused.contains(c);
            if let Some(old) = cur.take_through(last, &keep)? {
                *df = combine(df, old, name)?;
            }
        }
        Ok(())
    }
}

/// The error rows of the previous library for the reused clips.
fn previous_errors(out: &Path, reuse: &BTreeSet<String>) -> Result<DataFrame> {
    let path = out.join(ERRORS_FILE);
    let df = read_parquet(&path)?;
    let mask: BooleanChunked = strings(&df, "clip")
        .iter()
        .map(|c| reuse.contains(c))
        .collect();
    df.filter(&mask)
        .map_err(|e| Error::io(&path, "cannot filter previous rows", e))
}

/// Build the library for `files` into `out` (see the module docs) under the default
/// [`OutputRules`] (no `--force`; `files` are the inputs).
///
/// # Errors
/// As [`build_into`].
pub fn build_and_write(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    incremental: bool,
) -> Result<BuildSummary> {
    let plan = BuildPlan {
        incremental,
        ..BuildPlan::default()
    };
    build_into(files, out, opts, &plan, &OutputRules::default())
}

/// Build the library for `files` into `out` under `rules` (the output policy of
/// [`super::output`]: `out` is checked and locked before any work), as `plan` says.
///
/// # Errors
/// An `out` the output policy refuses or another build holds, a table that cannot be
/// built or written, or a folder that cannot be renamed.
pub fn build_into(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    plan: &BuildPlan,
    rules: &OutputRules,
) -> Result<BuildSummary> {
    let _claim = claim(out, files, rules)?;
    let t0 = Instant::now();
    let mut named: Vec<(PathBuf, String)> = files.iter().cloned().zip(clip_names(files)).collect();
    let shard_entry = plan.shard.map(|s| {
        serde_json::json!({
            "index": s.index, "count": s.count, "inputs_sha256": inputs_fingerprint(&named),
        })
    });
    if let Some(s) = plan.shard {
        named = named
            .into_par_iter()
            .filter(|(p, _)| shard_of(p, s.count) == s.index)
            .collect();
    }
    named.sort_by(|a, b| a.1.cmp(&b.1));
    let fingerprint = opts.fingerprint();
    let Reuse {
        clips: reuse,
        refused,
        previous,
    } = if plan.incremental {
        reusable(out, &named, &fingerprint, opts.ingest.joints)
    } else {
        Reuse::default()
    };
    let (default_clips, max_bytes) = super::batch::default_batch_bounds();
    let max_clips = match plan.batch_clips {
        0 => default_clips,
        n => n,
    };
    let bar = Progress::new(named.len() - reuse.len());
    let mut summary = BuildSummary {
        records: Vec::new(),
        stances: 0,
        reused: reuse.len(),
        not_reused: refused,
    };
    replace_library(out, |tmp| {
        let joints = opts.ingest.joints;
        let mut sink = LibrarySink::create(tmp, joints, true, plan.shard.is_some())?;
        let mut prev = match previous {
            Some(p) if !reuse.is_empty() => {
                sink.push_errors(previous_errors(out, &reuse)?);
                Some(p)
            }
            _ => None,
        };
        // Batch i is written while batch i + 1 is built (two batches in memory at most,
        // `ordered`): the writing is mostly one thread's work, and the other workers build
        // meanwhile.
        let mut write = |report: BuildReport, last: Option<&String>| -> Result<()> {
            let mut t = Tables::from_report(&report, joints)?;
            // The frames are in the tables now: free them before the tables are encoded.
            summary.stances += report.stances.len();
            summary
                .records
                .extend(report.records.into_iter().map(ClipRecord::written));
            if let (Some(prev), Some(last)) = (prev.as_mut(), last) {
                prev.add_rows(&mut t, last, &reuse)?;
            }
            sink.push(&mut t)?;
            drop(t);
            super::memory::release_free_memory();
            Ok(())
        };
        let batches: Vec<BuildBatch> = super::batch::file_batches(&named, max_clips, max_bytes)
            .into_iter()
            .map(|chunk| BuildBatch {
                todo: chunk.iter().filter(|(_, c)| !reuse.contains(c)).collect(),
                last: chunk.last().map(|(_, c)| c),
            })
            .collect();
        super::ordered::in_order(
            &batches,
            |b| &b.todo,
            |(path, clip)| build_one(path, clip, opts, &bar),
            |b, per_clip| write(report_of(per_clip), b.last),
        )?;
        bar.bar.finish_and_clear();
        sink.finish(&fingerprint, t0, shard_entry.clone(), plan.layout)
    })?;
    Ok(summary)
}

/// Write an in-memory build as the library at `out` (a full build; see [`build_and_write`]),
/// under the default [`OutputRules`] with the report's paths as the inputs.
///
/// # Errors
/// As [`build_into`].
pub fn write_library(out: &Path, report: &BuildReport, opts: &BuildOptions) -> Result<()> {
    let files: Vec<PathBuf> = report
        .records
        .iter()
        .map(|r| PathBuf::from(&r.path))
        .collect();
    let _claim = claim(out, &files, &OutputRules::default())?;
    let t0 = Instant::now();
    replace_library(out, |tmp| {
        let mut sink = LibrarySink::create(tmp, opts.ingest.joints, true, false)?;
        sink.push(&mut Tables::from_report(report, opts.ingest.joints)?)?;
        sink.finish(&opts.fingerprint(), t0, None, Layout::File)
    })
}

/// Write a library with `write` into a fresh temporary folder beside `out`, then swap it
/// into place; the temporary folder is removed on failure. The caller holds the claim.
pub(crate) fn replace_library(out: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    // The parent exists (the claim made it); a folder of this name is a dead process's.
    let tmp = parent_of(out).join(scratch_name(&name_of(out)?, Scratch::Tmp));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| Error::io(&tmp, "cannot create folder", e))?;
    let result = write(&tmp).and_then(|_| swap_into_place(&tmp, out));
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}
