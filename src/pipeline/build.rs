//! Building a stance library: ingest every clip, build its stances in parallel, compute the
//! per-character limits, and write every table plus `manifest.json` into a temporary
//! folder that replaces the library folder in one step.
//!
//! With `incremental`, the rows of clips whose path, content hash and options are those
//! of the previous library are taken from it instead of being rebuilt; the result is the
//! same, byte for byte, as a full rebuild (rows are re-sorted by the same keys and cast to
//! the same schema).
//!
//! Layout of a library folder: `frames.parquet`, `contacts.parquet`, `clips.parquet`,
//! `stances.parquet`, `errors.parquet`, `manifest.json` (spec stance-model §11).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::time::Instant;

use polars::prelude::*;
use rayon::prelude::*;

use super::batch::{file_sha256, ingest_named, progress};
use super::names::clip_names;
use super::output::{claim, name_of, parent_of, swap_into_place, OutputRules};
use crate::error::{Error, Result};
use crate::ingest::IngestOptions;
use crate::library::kinematics::kinematics_tables;
use crate::library::read::read_parquet;
use crate::library::schema::{
    CLIPS_FILE, CONTACTS_FILE, ERRORS_FILE, FRAMES_FILE, JOINTS_FILE, KINEMATICS_FILE,
    KINEMATICS_POINTS_FILE, MANIFEST_FILE, MANIFEST_SCHEMA_PREFIX, SCHEMA_VERSION, STANCES_FILE,
};
use crate::library::scratch::{scratch_name, Scratch};
use crate::library::stances::{errors_table, stances_table, ErrorRow};
use crate::library::write::{
    clips_table, contacts_table, frames_table, joints_table, write_atomic,
};
use crate::library::{ClipRecord, Status};
use crate::stances::build::StanceNote;
use crate::stances::limits::{limits, ClipFacts, Limits, StanceFacts};
use crate::stances::{build_clip, Stance, StanceOptions};

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

/// What a build produced in memory (the rebuilt clips only, with `incremental`).
#[derive(Debug)]
pub struct BuildReport {
    /// One record per rebuilt input file, sorted by clip.
    pub records: Vec<ClipRecord>,
    /// Every stance of those clips, sorted by (clip, first frame, label).
    pub stances: Vec<Stance>,
    /// Failed inputs and stages.
    pub errors: Vec<ErrorRow>,
}

/// Ingest and build (pure apart from reading the input files).
pub fn build(files: &[PathBuf], opts: &BuildOptions) -> BuildReport {
    let named: Vec<(PathBuf, String)> = files.iter().cloned().zip(clip_names(files)).collect();
    build_named(&named, opts)
}

fn build_named(named: &[(PathBuf, String)], opts: &BuildOptions) -> BuildReport {
    let mut records = ingest_named(named, &opts.ingest);
    let bar = progress(records.len(), "clips segmented and fitted");
    let per_clip: Vec<(Vec<Stance>, Vec<StanceNote>)> = records
        .par_iter()
        .map(|r| {
            let out = match (&r.frames, r.status) {
                (Some(fr), Status::Ok) => build_clip(
                    &r.clip,
                    fr,
                    &r.summary,
                    &r.contacts,
                    r.mass_kg,
                    &opts.stances,
                ),
                _ => (Vec::new(), Vec::new()),
            };
            bar.inc(1);
            out
        })
        .collect();
    bar.finish_and_clear();
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

/// The tables of a library, in memory: five always, `joints.parquet` with `--joints`.
struct Tables {
    frames: DataFrame,
    contacts: DataFrame,
    clips: DataFrame,
    stances: DataFrame,
    errors: DataFrame,
    joints: Option<DataFrame>,
}

fn pe(name: &str, e: PolarsError) -> Error {
    Error::io(name, "cannot build table", e)
}

impl Tables {
    /// The tables of a build; `joints.parquet` too when the ingest kept joint positions
    /// (`--joints`: the same table as `frames --joints` writes).
    fn from_report(r: &BuildReport, joints: bool) -> Result<Tables> {
        Ok(Tables {
            frames: frames_table(&r.records).map_err(|e| pe(FRAMES_FILE, e))?,
            contacts: contacts_table(&r.records).map_err(|e| pe(CONTACTS_FILE, e))?,
            clips: clips_table(&r.records).map_err(|e| pe(CLIPS_FILE, e))?,
            stances: stances_table(&r.stances).map_err(|e| pe(STANCES_FILE, e))?,
            errors: errors_table(&r.errors).map_err(|e| pe(ERRORS_FILE, e))?,
            joints: joints
                .then(|| joints_table(&r.records).map_err(|e| pe(JOINTS_FILE, e)))
                .transpose()?,
        })
    }

    fn named(&mut self) -> Vec<(&'static str, &mut DataFrame)> {
        let mut v = vec![
            (FRAMES_FILE, &mut self.frames),
            (CONTACTS_FILE, &mut self.contacts),
            (CLIPS_FILE, &mut self.clips),
            (STANCES_FILE, &mut self.stances),
            (ERRORS_FILE, &mut self.errors),
        ];
        if let Some(j) = &mut self.joints {
            v.push((JOINTS_FILE, j));
        }
        v
    }
}

/// Sort keys per table (the order a full build writes).
fn sort_keys(name: &str) -> &'static [&'static str] {
    match name {
        // Joint rows keep the skeleton's order within a frame (the sort is stable).
        FRAMES_FILE | JOINTS_FILE => &["clip", "frame"],
        CONTACTS_FILE => &["clip", "effector", "first_frame"],
        CLIPS_FILE => &["clip"],
        STANCES_FILE => &["clip", "first_frame", "label"],
        _ => &["path", "stage", "message"],
    }
}

fn strings(df: &DataFrame, col: &str) -> Vec<String> {
    df.column(col)
        .ok()
        .and_then(|c| {
            c.str().ok().map(|s| {
                s.iter()
                    .map(|v| v.unwrap_or_default().to_string())
                    .collect()
            })
        })
        .unwrap_or_default()
}

fn floats(df: &DataFrame, col: &str) -> Vec<Option<f64>> {
    df.column(col)
        .ok()
        .and_then(|c| c.f64().ok().map(|s| s.iter().collect()))
        .unwrap_or_default()
}

/// Clips of the previous library at `out` that can be reused for `named`.
fn reusable(out: &Path, named: &[(PathBuf, String)], fingerprint: &str) -> BTreeSet<String> {
    let manifest: Option<serde_json::Value> = std::fs::read_to_string(out.join(MANIFEST_FILE))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let current: Option<serde_json::Value> = serde_json::from_str(fingerprint).ok();
    if current.is_none() || manifest.as_ref().and_then(|m| m.get("options")) != current.as_ref() {
        return BTreeSet::new();
    }
    let Ok(clips) = read_parquet(&out.join(CLIPS_FILE)) else {
        return BTreeSet::new();
    };
    let prev: BTreeMap<String, (String, String, String)> = strings(&clips, "clip")
        .into_iter()
        .zip(
            strings(&clips, "path")
                .into_iter()
                .zip(strings(&clips, "content_sha256"))
                .zip(strings(&clips, "status")),
        )
        .map(|(c, ((p, h), s))| (c, (p, h, s)))
        .collect();
    named
        .par_iter()
        .filter_map(|(path, clip)| {
            let (p, h, s) = prev.get(clip)?;
            let same = *p == path.display().to_string()
                && s != "error"
                && file_sha256(path).as_deref() == Some(h.as_str());
            same.then(|| clip.clone())
        })
        .collect()
}

/// Rows of a previous table for the reused clips, cast to the fresh table's schema.
fn previous_rows(
    out: &Path,
    name: &str,
    reuse: &BTreeSet<String>,
    schema_of: &DataFrame,
) -> Result<DataFrame> {
    let path = out.join(name);
    let df = read_parquet(&path)?;
    let mask: BooleanChunked = strings(&df, "clip")
        .iter()
        .map(|c| reuse.contains(c))
        .collect();
    let df = df
        .filter(&mask)
        .map_err(|e| Error::io(&path, "cannot filter previous rows", e))?;
    let cols = schema_of
        .columns()
        .iter()
        .map(|c| df.column(c.name()).and_then(|p| p.cast(c.dtype())))
        .collect::<PolarsResult<Vec<Column>>>()
        .map_err(|e| Error::io(&path, "previous library has another schema", e))?;
    DataFrame::new_infer_height(cols)
        .map_err(|e| Error::io(&path, "cannot rebuild previous rows", e))
}

fn merge(fresh: &DataFrame, old: DataFrame, name: &str) -> Result<DataFrame> {
    let mut all = fresh.vstack(&old).map_err(|e| pe(name, e))?;
    let keys: Vec<PlSmallStr> = sort_keys(name).iter().map(|k| (*k).into()).collect();
    all = all
        .sort(
            keys,
            SortMultipleOptions::default().with_maintain_order(true),
        )
        .map_err(|e| pe(name, e))?;
    all.rechunk_mut();
    Ok(all)
}

/// Per-character limits from the (merged) stance and clip tables.
fn limits_of(t: &Tables) -> BTreeMap<String, Limits> {
    let s = &t.stances;
    let (clip, ch, b0, b1) = (
        strings(s, "clip"),
        strings(s, "character_id"),
        strings(s, "boundary_start"),
        strings(s, "boundary_end"),
    );
    let (m, fp, e0, e1) = (
        floats(s, "mass_kg"),
        floats(s, "f_peak"),
        floats(s, "ext_min"),
        floats(s, "ext_max"),
    );
    let facts: Vec<StanceFacts> = (0..s.height())
        .map(|i| StanceFacts {
            clip: clip[i].clone(),
            character_id: ch[i].clone(),
            mass_kg: m[i].unwrap_or(f64::NAN),
            f_peak: fp[i].unwrap_or(0.0),
            ext_min: e0[i].unwrap_or(f64::INFINITY),
            ext_max: e1[i].unwrap_or(0.0),
            unsupported: b0[i] == "unsupported" || b1[i] == "unsupported",
        })
        .collect();
    let c = &t.clips;
    let clips: BTreeMap<String, ClipFacts> = strings(c, "clip")
        .into_iter()
        .zip(
            floats(c, "s_eff")
                .into_iter()
                .zip(floats(c, "leg_length_m")),
        )
        .map(|(k, (s_eff, leg))| {
            (
                k,
                ClipFacts {
                    s_eff,
                    leg_m: leg.unwrap_or(1.0),
                },
            )
        })
        .collect();
    limits(&facts, &clips)
}

/// Build the library for `files` into `out` (see the module docs) under the default
/// [`OutputRules`] (no `--force`; `files` are the inputs); returns what was rebuilt in
/// memory and the number of reused clips.
///
/// # Errors
/// As [`build_into`].
pub fn build_and_write(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    incremental: bool,
) -> Result<(BuildReport, usize)> {
    build_into(files, out, opts, incremental, &OutputRules::default())
}

/// Build the library for `files` into `out` under `rules` (the output policy of
/// [`super::output`]: `out` is checked and locked before any work); returns what was
/// rebuilt in memory and the number of reused clips.
///
/// # Errors
/// An `out` the output policy refuses or another build holds, a table that cannot be
/// built or written, or a folder that cannot be renamed.
pub fn build_into(
    files: &[PathBuf],
    out: &Path,
    opts: &BuildOptions,
    incremental: bool,
    rules: &OutputRules,
) -> Result<(BuildReport, usize)> {
    let _claim = claim(out, files, rules)?;
    let t0 = Instant::now();
    let named: Vec<(PathBuf, String)> = files.iter().cloned().zip(clip_names(files)).collect();
    let fingerprint = opts.fingerprint();
    let reuse = if incremental {
        reusable(out, &named, &fingerprint)
    } else {
        BTreeSet::new()
    };
    let todo: Vec<(PathBuf, String)> = named
        .iter()
        .filter(|(_, c)| !reuse.contains(c))
        .cloned()
        .collect();
    let report = build_named(&todo, opts);
    let mut tables = Tables::from_report(&report, opts.ingest.joints)?;
    if !reuse.is_empty() {
        for (name, df) in tables.named() {
            let old = previous_rows(out, name, &reuse, df)?;
            *df = merge(df, old, name)?;
        }
    }
    let lim = limits_of(&tables);
    replace_library(out, &mut tables, &lim, &fingerprint, t0)?;
    Ok((report, reuse.len()))
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
    let mut tables = Tables::from_report(report, opts.ingest.joints)?;
    let lim = limits_of(&tables);
    replace_library(out, &mut tables, &lim, &opts.fingerprint(), Instant::now())
}

fn replace_library(
    out: &Path,
    t: &mut Tables,
    lim: &BTreeMap<String, Limits>,
    fingerprint: &str,
    t0: Instant,
) -> Result<()> {
    // The parent exists (the claim made it); a folder of this name is a dead process's.
    let tmp = parent_of(out).join(scratch_name(&name_of(out)?, Scratch::Tmp));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| Error::io(&tmp, "cannot create folder", e))?;
    let result =
        write_tables(&tmp, t, lim, fingerprint, t0).and_then(|_| swap_into_place(&tmp, out));
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

fn write_tables(
    dir: &Path,
    t: &mut Tables,
    lim: &BTreeMap<String, Limits>,
    fingerprint: &str,
    t0: Instant,
) -> Result<()> {
    let inputs: BTreeMap<String, String> = strings(&t.clips, "clip")
        .into_iter()
        .zip(strings(&t.clips, "content_sha256"))
        .collect();
    let json = |v: &dyn erased::Json| v.to_json();
    let kv: Vec<(String, String)> = vec![
        ("stancelib.schema_version".into(), SCHEMA_VERSION.into()),
        (
            "stancelib.tool_version".into(),
            env!("CARGO_PKG_VERSION").into(),
        ),
        ("stancelib.options".into(), fingerprint.to_string()),
        ("stancelib.inputs".into(), json(&inputs)),
        ("stancelib.limits".into(), json(lim)),
    ];
    let status = strings(&t.clips, "status");
    let count = |s: &str| status.iter().filter(|v| *v == s).count();
    let (n_clips, n_stances) = (t.clips.height(), t.stances.height());
    let failures = strings(&t.errors, "message");
    for (name, df) in t.named() {
        write_atomic(dir, name, df, &kv)?;
    }
    let (mut facets, mut points) =
        kinematics_tables(&t.frames, &t.contacts, &t.clips).map_err(|e| pe(KINEMATICS_FILE, e))?;
    write_atomic(dir, KINEMATICS_FILE, &mut facets, &kv)?;
    write_atomic(dir, KINEMATICS_POINTS_FILE, &mut points, &kv)?;
    let manifest = serde_json::json!({
        "schema": format!("{MANIFEST_SCHEMA_PREFIX}{SCHEMA_VERSION}"),
        "schema_version": SCHEMA_VERSION,
        "tool_version": env!("CARGO_PKG_VERSION"),
        // Not in the Parquet metadata: these change from run to run (the tables do not).
        "created_utc": crate::library::provenance::now_utc(),
        "command_line": crate::library::provenance::command_line(),
        "options": serde_json::from_str::<serde_json::Value>(fingerprint).unwrap_or_default(),
        "inputs": inputs,
        "limits": lim,
        "counts": {
            "clips": n_clips, "ok": count("ok"), "skipped": count("skipped"),
            "failed": count("error"), "stances": n_stances,
        },
        "failures": failures,
        "wall_time_s": t0.elapsed().as_secs_f64(),
    });
    let text = serde_json::to_string_pretty(&manifest).unwrap_or_default();
    std::fs::write(dir.join(MANIFEST_FILE), text)
        .map_err(|err| Error::io(dir.join(MANIFEST_FILE), "cannot write", err))
}

mod erased {
    /// Serialize any `Serialize` value to compact JSON (deterministic for BTreeMaps).
    pub trait Json {
        fn to_json(&self) -> String;
    }
    impl<T: serde::Serialize> Json for T {
        fn to_json(&self) -> String {
            serde_json::to_string(self).unwrap_or_default()
        }
    }
}
