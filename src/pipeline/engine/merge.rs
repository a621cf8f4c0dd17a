//! `stancelib merge`: shard libraries (`build --shard I/N`) joined into one library, the
//! same byte for byte as a single `build` of all the inputs with the same options.
//!
//! # Model
//! ```text
//! check:  every shard is a finished shard library; same schema, tool version, options,
//!         shard count and input list (manifest `shard.inputs_sha256`); indices 1..N once each;
//!         every table of every shard has the bytes its manifest recorded
//!         (`library::storage::integrity`), before anything is written
//! rows:   every row of a shard belongs to one of the shard's clips, keys unique (checked
//!         as the rows are read; a failure leaves the previous library in place)
//! rows:   per-clip tables read forward in clip order from every shard, a batch of clips
//!         (about one row group of frames) at a time, sorted by the table's keys, appended;
//!         the per-frame tables (one row group per clip, `schema::group_column`) are not
//!         decoded: each clip's row groups are copied from its shard, compressed pages and
//!         all (`library::storage::row_groups`), on a thread of their own beside everything else
//! limits: recomputed from the stance and clip facts of the merged rows
//! polytopes: recomputed from the shards' kinematic samples (`kinematics_samples.parquet`)
//!         on the worker pool while the row groups are still being copied
//! ```
//! The output obeys the policy of [`super::output`] (the shards are its inputs: `--out`
//! never is, holds or lies in one), is locked while written and swapped in at the end.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use super::cursor::ClipCursor;
use super::output::{claim, is_library, OutputRules};
use super::sink::{Defer, Detached, LibrarySink};
use super::streaming::replace_library;
use super::tables::Tables;
use crate::error::{Error, Result};
use crate::library::codec::schema::sort_keys;
use crate::library::codec::schema::{
    group_column, CLIPS_FILE, CONTACTS_FILE, ERRORS_FILE, FRAMES_FILE, JOINTS_FILE,
    KINEMATICS_SAMPLES_FILE, MANIFEST_FILE, SOURCE_DIGEST, STANCES_FILE,
};
use crate::library::codec::table::read_parquet;
use crate::library::storage::group_reader::GroupFileReader;
use crate::library::storage::integrity::{check_table, recorded_digests, Digests};
use crate::library::storage::layout::sorted;
use crate::library::storage::layout::{locate, table_exists, Layout};
use crate::library::storage::stream::TableWriter;
use crate::library::storage::stream::ROW_GROUP_ROWS;

/// What a merge wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MergeSummary {
    /// Shards merged.
    pub shards: usize,
    /// Clips of the library.
    pub clips: usize,
    /// Clips that failed (status `error`).
    pub failed: usize,
}

/// One shard library, checked.
struct ShardLib {
    dir: PathBuf,
    index: usize,
    manifest: serde_json::Value,
    /// The tables the merge reads.
    tables: Vec<&'static str>,
}

fn bad(dir: &Path, why: impl std::fmt::Display) -> Error {
    Error::config(
        Some(dir.to_path_buf()),
        None,
        format!("shard library: {why}"),
    )
}

/// Read and check one shard's manifest and files.
fn open_shard(dir: &Path) -> Result<ShardLib> {
    if !dir.is_dir() {
        return Err(bad(
            dir,
            "not a folder (did the build of this shard fail or not run?)",
        ));
    }
    if !is_library(dir) {
        return Err(bad(
            dir,
            format!("no stancelib {MANIFEST_FILE}: the build of this shard did not finish"),
        ));
    }
    let manifest = crate::library::codec::manifest::read_manifest(dir)?;
    let Some(index) = manifest
        .pointer("/shard/index")
        .and_then(serde_json::Value::as_u64)
    else {
        return Err(bad(
            dir,
            "not a shard library (built without --shard I/N; its manifest has no shard)",
        ));
    };
    let joints = manifest
        .pointer("/options/ingest/joints")
        .and_then(serde_json::Value::as_bool)
        .unwrap_or(false);
    let mut need = vec![
        FRAMES_FILE,
        CONTACTS_FILE,
        CLIPS_FILE,
        STANCES_FILE,
        ERRORS_FILE,
        KINEMATICS_SAMPLES_FILE,
    ];
    if joints {
        need.push(JOINTS_FILE);
    }
    if let Some(missing) = need.iter().find(|f| !table_exists(dir, f)) {
        return Err(bad(dir, format!("{missing} is missing")));
    }
    Ok(ShardLib {
        dir: dir.to_path_buf(),
        index: index as usize,
        manifest,
        tables: need,
    })
}

/// Check every table the merge reads of every shard against its shard's manifest
/// (content hashes, `library::storage::integrity`), in parallel; the error names the shard and the
/// table.
fn verify_shards(libs: &[ShardLib]) -> Result<()> {
    use rayon::prelude::*;
    let jobs: Vec<(&ShardLib, &'static str, Option<Digests>)> = libs
        .iter()
        .flat_map(|lib| {
            let recorded = recorded_digests(&lib.manifest);
            lib.tables.iter().map(move |t| (lib, *t, recorded.clone()))
        })
        .collect();
    let checked: Vec<Result<()>> = jobs
        .par_iter()
        .map(|(lib, table, recorded)| {
            check_table(&lib.dir, table, recorded.as_ref()).map_err(|m| {
                bad(
                    &lib.dir,
                    format!(
                        "{table}: {m}; the shard is damaged or holds another library's \
                         table: build this shard again"
                    ),
                )
            })
        })
        .collect();
    checked.into_iter().collect()
}

/// The manifest fields all shards of one build share.
const SHARED_FIELDS: [&str; 6] = [
    "/schema",
    "/schema_version",
    "/tool_version",
    "/options",
    "/shard/count",
    "/shard/inputs_sha256",
];

/// The first place where two manifest values differ: its key path (`options.ingest.mass_kg`,
/// array items as `[i]`) and the two values as JSON, each cut to
/// [`crate::error::MAX_ECHO_CHARS`] and escaped; `None` when they are equal. A key one
/// side lacks shows as `none`. (Printed whole, two option sets of a thousand characters
/// differed after the point where the message cut them.)
///
/// # Examples
/// ```text
/// {"ingest": {"mass_kg": 70, "sex": "Male"}} vs {"ingest": {"mass_kg": 80, "sex": "Male"}}
///   → ("options.ingest.mass_kg", "70", "80")
/// {"inputs": ["a", "b"]} vs {"inputs": ["a", "b", "c"]}  → ("inputs[2]", "none", "\"c\"")
/// ```
pub fn first_difference(
    pointer: &str,
    a: Option<&serde_json::Value>,
    b: Option<&serde_json::Value>,
) -> Option<(String, String, String)> {
    use serde_json::Value;
    fn walk(
        path: String,
        a: Option<&Value>,
        b: Option<&Value>,
    ) -> Option<(String, String, String)> {
        match (a, b) {
            (Some(Value::Object(x)), Some(Value::Object(y))) => {
                let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
                keys.into_iter()
                    .find_map(|k| walk(format!("{path}.{k}"), x.get(k), y.get(k)))
            }
            // Item by item; arrays of different lengths that agree as far as the shorter
            // goes differ at its end (`[n]`: the longer one's item against `none`).
            (Some(Value::Array(x)), Some(Value::Array(y))) => (0..x.len().max(y.len()))
                .find_map(|i| walk(format!("{path}[{i}]"), x.get(i), y.get(i))),
            _ if a == b => None,
            _ => {
                let show = |v: Option<&Value>| {
                    crate::error::echo(&v.map_or("none".to_string(), Value::to_string))
                };
                Some((crate::error::echo(&path), show(a), show(b)))
            }
        }
    }
    let root = pointer.trim_start_matches('/').replace('/', ".");
    walk(root, a, b)
}

/// Check the shards belong to one build and cover it; sorted by index.
fn check_shards(mut libs: Vec<ShardLib>) -> Result<Vec<ShardLib>> {
    let Some(first) = libs.first() else {
        return Err(Error::config(None, None, "merge: no shard libraries given"));
    };
    // The merged manifest records this build's source: rows of other code are not its rows
    // (a later `build --incremental` would reuse them).
    for lib in &libs {
        let digest = lib.manifest.get("source_digest").and_then(|d| d.as_str());
        if digest != Some(SOURCE_DIGEST) {
            return Err(bad(
                &lib.dir,
                format!(
                    "source_digest is {} here but this stancelib is {SOURCE_DIGEST}: a shard \
                     written by another build of stancelib is never merged (build it again \
                     with this one)",
                    digest.unwrap_or("none")
                ),
            ));
        }
    }
    for lib in &libs[1..] {
        for field in SHARED_FIELDS {
            let (a, b) = (first.manifest.pointer(field), lib.manifest.pointer(field));
            if let Some((key, a, b)) = first_difference(field, a, b) {
                return Err(bad(
                    &lib.dir,
                    format!(
                        "{key} is {b} here but {a} in {}: shards of different builds \
                         (options, inputs or tool versions) are never merged",
                        first.dir.display()
                    ),
                ));
            }
        }
    }
    let count = first
        .manifest
        .pointer("/shard/count")
        .and_then(serde_json::Value::as_u64)
        .unwrap_or(0) as usize;
    libs.sort_by_key(|l| l.index);
    for w in libs.windows(2) {
        if w[0].index == w[1].index {
            return Err(bad(
                &w[1].dir,
                format!(
                    "shard {}/{count} is given twice (also {})",
                    w[1].index,
                    w[0].dir.display()
                ),
            ));
        }
    }
    let have: Vec<usize> = libs.iter().map(|l| l.index).collect();
    let missing: Vec<String> = (1..=count)
        .filter(|i| !have.contains(i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(Error::config(
            None,
            None,
            format!(
                "merge: shard {} missing: no library given for it (did its build fail?)",
                missing.join(", ")
            ),
        ));
    }
    Ok(libs)
}

/// Clips in name order with their kept frame counts and shard, from the shards' clips.
fn clip_plan(libs: &[ShardLib]) -> Result<Vec<(String, usize, usize)>> {
    let mut plan: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for (k, lib) in libs.iter().enumerate() {
        let path = lib.dir.join(CLIPS_FILE);
        let df = read_parquet(&path)?;
        let names = super::tables::strings(&df, "clip");
        let frames: Vec<Option<i64>> = df
            .column("frames_kept")
            .and_then(|c| c.i64().map(|s| s.iter().collect()))
            .map_err(|e| Error::io(&path, "column frames_kept", e))?;
        for (c, f) in names.into_iter().zip(frames) {
            if let Some((other, _)) = plan.get(&c) {
                return Err(bad(
                    &lib.dir,
                    format!(
                        "clip {c} is also in {}: shards overlap",
                        libs[*other].dir.display()
                    ),
                ));
            }
            plan.insert(c, (k, f.unwrap_or(0).max(0) as usize));
        }
    }
    Ok(plan.into_iter().map(|(c, (k, f))| (c, f, k)).collect())
}

/// A shard's per-clip table (`schema::group_column`), its row groups read in clip order.
struct GroupCursor {
    table: &'static str,
    column: &'static str,
    files: std::vec::IntoIter<PathBuf>,
    reader: Option<GroupFileReader>,
}

impl GroupCursor {
    fn open(lib: &Path, table: &'static str, column: &'static str) -> Result<GroupCursor> {
        let mut files = locate(lib, table)?.files().into_iter();
        let reader = files
            .next()
            .map(|f| GroupFileReader::open(&f))
            .transpose()?;
        Ok(GroupCursor {
            table,
            column,
            files,
            reader,
        })
    }

    /// The clip of the next row group, moving on to the next file at the end of one.
    fn next_clip(&mut self) -> Result<Option<Vec<u8>>> {
        while let Some(r) = self.reader.as_mut() {
            if let Some(v) = r.peek_value(self.column)? {
                return Ok(Some(v));
            }
            self.reader = self
                .files
                .next()
                .map(|f| GroupFileReader::open(&f))
                .transpose()?;
        }
        Ok(None)
    }

    /// An error naming the clip of the next row group, if any is left.
    fn refuse_leftover(&mut self, dir: &Path) -> Result<()> {
        match self.next_clip()? {
            Some(clip) => Err(bad(
                dir,
                format!(
                    "{} holds clip {} that its {CLIPS_FILE} does not",
                    self.table,
                    String::from_utf8_lossy(&clip)
                ),
            )),
            None => Ok(()),
        }
    }

    /// Append the row groups of `clip` (the next ones of the shard) to `w`, their rows
    /// returned; a group of a clip before `clip` means the shard's tables disagree.
    fn copy_clip(&mut self, clip: &str, w: &mut TableWriter, dir: &Path) -> Result<u64> {
        let mut rows = 0u64;
        while let Some(next) = self.next_clip()? {
            match next.as_slice().cmp(clip.as_bytes()) {
                std::cmp::Ordering::Greater => break,
                std::cmp::Ordering::Less => {
                    return Err(bad(
                        dir,
                        format!(
                            "{} holds clip {} that its {CLIPS_FILE} does not, or out of order",
                            self.table,
                            String::from_utf8_lossy(&next)
                        ),
                    ))
                }
                std::cmp::Ordering::Equal => {
                    let g = match self.reader.as_mut() {
                        Some(r) => r.next_group()?,
                        None => None,
                    };
                    // `next_clip` has just read this group's entry.
                    let g = g.ok_or_else(|| bad(dir, format!("{}: no row group", self.table)))?;
                    w.push_group(&g)?;
                    rows += g.rows() as u64;
                }
            }
        }
        Ok(rows)
    }
}

/// How the two sides of a merge tell each other to end early.
#[derive(Default)]
struct Signals {
    /// The rows' side failed or panicked: the copy ends (with an error).
    stop: AtomicBool,
    /// The copy failed: the rows' side ends, and the copy's error is the merge's.
    failed: AtomicBool,
}

/// The error of a merge side that ended without a result of its own (`out`: the library).
fn side_ended(out: &Path, why: &str) -> Error {
    Error::io(out, "cannot merge", std::io::Error::other(why.to_string()))
}

/// Copy the per-clip row groups of every clip of `plan` (clip, frames, shard) from its
/// shard's `groups` (one cursor per table of `writers`, in that order) into `writers`, then
/// refuse a shard with groups left; `stop` (set when the rest of the merge `out` ended)
/// ends the copy early with an error. Runs beside the rest of the merge and hands the
/// writers back with the rows copied per clip.
fn copy_groups(
    plan: &[(String, usize, usize)],
    libs: &[ShardLib],
    mut groups: Vec<Vec<GroupCursor>>,
    mut writers: Vec<(&'static str, TableWriter)>,
    stop: &AtomicBool,
    out: &Path,
) -> Result<Detached> {
    let mut clip_rows = crate::library::storage::integrity::ClipRows::new();
    for (clip, _, k) in plan {
        if stop.load(Ordering::Relaxed) {
            return Err(side_ended(out, "the row group copy was stopped"));
        }
        for g in groups[*k].iter_mut() {
            let w = writers
                .iter_mut()
                .find(|(n, _)| *n == g.table)
                .map(|(_, w)| w)
                .ok_or_else(|| bad(&libs[*k].dir, format!("{}: no writer", g.table)))?;
            let n = g.copy_clip(clip, w, &libs[*k].dir)?;
            crate::library::storage::integrity::add_clip_rows(&mut clip_rows, clip, g.table, n);
        }
    }
    // Every shard's per-clip groups were copied: one left holds a clip its shard's clips
    // table does not.
    for (shard, lib) in groups.iter_mut().zip(libs) {
        for g in shard.iter_mut() {
            g.refuse_leftover(&lib.dir)?;
        }
    }
    Ok(Detached { writers, clip_rows })
}

/// Spill a shard's samples table into `sink` a row group's worth at a time (never the
/// whole table in memory).
/// A `dataset` shard's samples are read partition by partition.
fn push_samples(sink: &mut LibrarySink, lib: &Path) -> Result<()> {
    for path in locate(lib, KINEMATICS_SAMPLES_FILE)?.files() {
        let total = crate::library::codec::table::parquet_rows(&path)?;
        let mut at = 0;
        while at < total {
            let rows = crate::library::storage::stream::read_rows(&path, at, ROW_GROUP_ROWS)?;
            if rows.height() == 0 {
                break;
            }
            at += rows.height();
            sink.push_samples(&rows)?;
        }
    }
    Ok(())
}

/// Merge the shard libraries `shards` (of either layout) into the library `out` under
/// `rules`, written in `layout` (module docs).
///
/// # Errors
/// A shard that is missing, unfinished or of another build (the error names it), an `out`
/// the output policy refuses or another build holds, or a table that cannot be read or
/// written.
pub fn merge_into(
    shards: &[PathBuf],
    out: &Path,
    rules: &OutputRules,
    layout: Layout,
) -> Result<MergeSummary> {
    let libs = check_shards(
        shards
            .iter()
            .map(|d| open_shard(d))
            .collect::<Result<Vec<_>>>()?,
    )?;
    verify_shards(&libs)?;
    let _claim = claim(out, shards, rules)?;
    let t0 = Instant::now();
    let options = libs[0].manifest.get("options").cloned().unwrap_or_default();
    let fingerprint = options.to_string();
    let joints = options
        .pointer("/ingest/joints")
        .and_then(serde_json::Value::as_bool)
        .unwrap_or(false);
    let plan = clip_plan(&libs)?;
    let mut summary = MergeSummary {
        shards: libs.len(),
        clips: plan.len(),
        failed: 0,
    };
    replace_library(out, |tmp| {
        let mut sink = LibrarySink::create(tmp, joints, false, false)?;
        let names: Vec<&'static str> = sink.template().named().iter().map(|(n, _)| *n).collect();
        // (table, the column its row groups are cut by)
        let per_clip: Vec<(&'static str, &'static str)> = names
            .iter()
            .filter_map(|n| group_column(n).map(|c| (*n, c)))
            .collect();
        // The per-clip tables' row groups are copied by group cursors on a thread of their
        // own, beside the samples, the other tables and the polytopes (`finish_with`).
        let groups = libs
            .iter()
            .map(|lib| {
                per_clip
                    .iter()
                    .map(|(n, c)| GroupCursor::open(&lib.dir, n, c))
                    .collect::<Result<Vec<_>>>()
            })
            .collect::<Result<Vec<_>>>()?;
        let writers = sink.detach(&per_clip.iter().map(|(n, _)| *n).collect::<Vec<_>>());
        let signals = Signals::default();
        std::thread::scope(|scope| {
            let copier = scope.spawn(|| {
                let mut failed = Defer::new(|| signals.failed.store(true, Ordering::Relaxed));
                let copied = copy_groups(&plan, &libs, groups, writers, &signals.stop, out);
                if copied.is_ok() || signals.stop.load(Ordering::Relaxed) {
                    failed.disarm();
                }
                copied
            });
            // Joined by whichever comes first: the finish (to write the footers) or the
            // end of this scope (after a failure), never left to the scope's own join.
            let copier = std::sync::Mutex::new(Some(copier));
            let join = || {
                copier.lock().ok().and_then(|mut h| h.take()).map(|h| {
                    h.join()
                        .unwrap_or_else(|_| Err(side_ended(out, "the row group copy panicked")))
                })
            };
            // When this side ends, however it ends, the copy stops (if still going).
            let stop = || signals.stop.store(true, Ordering::Relaxed);
            let ended = Defer::new(&stop);
            let merged = merge_rows(
                &mut sink,
                &libs,
                &plan,
                &names,
                joints,
                &mut summary,
                &signals.failed,
            )
            .and_then(|()| {
                sink.finish_with(
                    &fingerprint,
                    t0,
                    None,
                    layout,
                    || join().unwrap_or_else(|| Err(side_ended(out, "the row group copy is gone"))),
                    &stop,
                )
            });
            drop(ended);
            match (merged, join()) {
                (Err(_), Some(Err(copy))) if signals.failed.load(Ordering::Relaxed) => Err(copy),
                (merged, _) => merged,
            }
        })
    })?;
    Ok(summary)
}

/// An error once the row group copy has failed (its own error is then the merge's,
/// `merge_into`), so the rows' side ends early.
fn check_copy(copy_failed: &AtomicBool) -> Result<()> {
    if copy_failed.load(Ordering::Relaxed) {
        return Err(Error::io(
            "merge",
            "cannot merge",
            std::io::Error::other("the row group copy failed"),
        ));
    }
    Ok(())
}

/// The samples, the errors and the tables of a few rows a clip (every table but the
/// per-clip ones) of every shard, appended to `sink` in `plan`'s clip order, a batch of
/// clips at a time; the failed clips are counted into `summary`.
fn merge_rows(
    sink: &mut LibrarySink,
    libs: &[ShardLib],
    plan: &[(String, usize, usize)],
    names: &[&'static str],
    joints: bool,
    summary: &mut MergeSummary,
    copy_failed: &AtomicBool,
) -> Result<()> {
    // Per shard: a row cursor per table, none for a per-clip table.
    let mut cursors: Vec<Vec<Option<ClipCursor>>> = Vec::new();
    for lib in libs {
        check_copy(copy_failed)?;
        sink.push_errors(read_parquet(&lib.dir.join(ERRORS_FILE))?);
        push_samples(sink, &lib.dir)?;
        cursors.push(
            names
                .iter()
                .map(|n| match group_column(n) {
                    Some(_) => Ok(None),
                    None => ClipCursor::open(&lib.dir.join(n)).map(Some),
                })
                .collect::<Result<Vec<_>>>()?,
        );
    }
    let owner: BTreeMap<&str, usize> = plan.iter().map(|(c, _, k)| (c.as_str(), *k)).collect();
    let mut start = 0;
    while start < plan.len() {
        check_copy(copy_failed)?;
        // A batch: clips until about one row group of frames.
        let (mut end, mut frames) = (start, 0);
        while end < plan.len() && (end == start || frames < ROW_GROUP_ROWS) {
            frames += plan[end].1;
            end += 1;
        }
        let last = plan[end - 1].0.clone();
        let mut t = Tables::empty(joints)?;
        for (k, shard) in cursors.iter_mut().enumerate() {
            for ((name, df), cur) in t.named().into_iter().zip(shard.iter_mut()) {
                let Some(cur) = cur else { continue };
                if let Some(rows) = cur.take_through(&last, &|_| true)? {
                    check_owner(&rows, name, k, &owner, libs)?;
                    let rows = super::tables::cast_like(rows, df, name)?;
                    df.vstack_mut(&rows)
                        .map_err(|e| Error::io(name, "cannot stack rows", e))?;
                }
            }
        }
        for (name, df) in t.named() {
            *df = sorted(std::mem::take(df), name)?;
            check_unique(df, name, &owner, libs)?;
        }
        summary.failed += t
            .clips
            .column("status")
            .and_then(|c| {
                c.str()
                    .map(|s| s.iter().filter(|v| *v == Some("error")).count())
            })
            .unwrap_or(0);
        sink.push(&mut t)?;
        drop(t);
        super::memory::release_free_memory();
        start = end;
    }
    // Rows of a clip after the last one are never taken above.
    for (shard, lib) in cursors.iter().zip(libs) {
        for (cur, name) in shard.iter().zip(names) {
            if let Some(clip) = cur.as_ref().and_then(|c| c.next_clip()) {
                return Err(bad(
                    &lib.dir,
                    format!(
                        "{name} holds rows of clip {}, not one of the shard's clips \
                         ({CLIPS_FILE})",
                        crate::error::echo(clip)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Refuse rows of table `name` read from shard `k` of `libs` that belong to a clip of
/// another shard or of none (`owner`: the shard of every clip).
fn check_owner(
    rows: &polars::prelude::DataFrame,
    name: &str,
    k: usize,
    owner: &BTreeMap<&str, usize>,
    libs: &[ShardLib],
) -> Result<()> {
    let clips = super::tables::strings(rows, "clip");
    let Some(c) = clips.iter().find(|c| owner.get(c.as_str()) != Some(&k)) else {
        return Ok(());
    };
    let whose = match owner.get(c.as_str()) {
        Some(o) => format!("a clip of {}", libs[*o].dir.display()),
        None => format!("in no shard's {CLIPS_FILE}"),
    };
    Err(bad(
        &libs[k].dir,
        format!(
            "{name} holds rows of clip {} ({whose}), not one of this shard's clips",
            crate::error::echo(c)
        ),
    ))
}

/// Refuse a table `name` of merged rows (sorted by its keys, `schema::sort_keys`) where
/// two rows have the same keys; the error names the shard of the clip (`owner`).
fn check_unique(
    df: &polars::prelude::DataFrame,
    name: &str,
    owner: &BTreeMap<&str, usize>,
    libs: &[ShardLib],
) -> Result<()> {
    let keys = sort_keys(name);
    let cols: Vec<&polars::prelude::Column> =
        keys.iter().filter_map(|k| df.column(k).ok()).collect();
    if name == ERRORS_FILE || cols.len() != keys.len() {
        return Ok(());
    }
    let same = |i: usize| {
        cols.iter()
            .all(|c| matches!((c.get(i - 1), c.get(i)), (Ok(a), Ok(b)) if a == b))
    };
    let Some(i) = (1..df.height()).find(|&i| same(i)) else {
        return Ok(());
    };
    let key: Vec<String> = cols
        .iter()
        .map(|c| c.get(i).map(|v| v.to_string()).unwrap_or_default())
        .collect();
    let clip = super::tables::strings(&df.slice(i as i64, 1), "clip");
    let shard = clip
        .first()
        .and_then(|c| owner.get(c.as_str()))
        .map_or(Path::new("merge"), |k| libs[*k].dir.as_path());
    Err(bad(
        shard,
        format!(
            "{name} holds two rows of key ({}) = ({})",
            keys.join(", "),
            crate::error::echo(&key.join(", "))
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    // See: the review of issue 40 item 11 — arrays of different lengths were printed
    // whole, cut to the same 80 characters, so two long option lists read the same.
    #[test]
    fn first_difference_names_the_first_item_where_arrays_differ() {
        let a = serde_json::json!({"inputs": ["a".repeat(100), "b"]});
        let b = serde_json::json!({"inputs": ["a".repeat(100), "b", "c"]});
        assert_eq!(
            first_difference("/options", Some(&a), Some(&b)),
            Some(("options.inputs[2]".into(), "none".into(), "\"c\"".into()))
        );
        let c = serde_json::json!({"inputs": ["a".repeat(100), "x", "c"]});
        assert_eq!(
            first_difference("/options", Some(&c), Some(&b)).map(|d| d.0),
            Some("options.inputs[1]".into())
        );
        assert_eq!(first_difference("/options", Some(&b), Some(&b)), None);
    }

    #[test]
    fn a_stopped_copy_ends_with_an_error_naming_the_library() {
        let stop = AtomicBool::new(true);
        let plan = vec![("clip".to_string(), 10, 0)];
        let out = Path::new("/some/library");
        let e = copy_groups(&plan, &[], Vec::new(), Vec::new(), &stop, out).unwrap_err();
        assert!(e.to_string().contains("/some/library"), "{e}");
        assert!(format!("{e:?}").contains("copy was stopped"), "{e:?}");
        // Not stopped, with nothing to copy: the writers come back.
        stop.store(false, Ordering::Relaxed);
        assert!(copy_groups(&[], &[], Vec::new(), Vec::new(), &stop, out).is_ok());
    }

    #[test]
    fn a_failed_copy_ends_the_rows_side() {
        let failed = AtomicBool::new(false);
        assert!(check_copy(&failed).is_ok());
        failed.store(true, Ordering::Relaxed);
        assert!(check_copy(&failed).is_err());
    }
}
