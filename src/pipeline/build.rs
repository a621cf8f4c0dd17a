//! Building a stance library: ingest every clip, build its stances in parallel, compute the
//! per-character limits, and write every table plus `manifest.json` into a temporary
//! folder that replaces the library folder in one step.
//!
//! Layout of a library folder: `frames.parquet`, `contacts.parquet`, `clips.parquet`,
//! `stances.parquet`, `errors.parquet`, `manifest.json` (spec stance-model §11).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use super::batch::ingest_all;
use crate::error::{Error, Result};
use crate::ingest::IngestOptions;
use crate::library::schema::SCHEMA_VERSION;
use crate::library::stances::{errors_table, stances_table, ErrorRow};
use crate::library::write::{clips_table, contacts_table, frames_table, write_atomic};
use crate::library::{ClipRecord, Status};
use crate::stances::limits::{limits, ClipFacts, Limits};
use crate::stances::{build_clip, Stance, StanceOptions};

/// Options of a library build.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BuildOptions {
    /// Ingest options.
    pub ingest: IngestOptions,
    /// Stance options.
    pub stances: StanceOptions,
}

/// What a build produced (for the report and the exit code).
#[derive(Debug)]
pub struct BuildReport {
    /// One record per input file, sorted by clip.
    pub records: Vec<ClipRecord>,
    /// Every stance, sorted by (clip, first frame, label).
    pub stances: Vec<Stance>,
    /// Failed inputs and stages.
    pub errors: Vec<ErrorRow>,
    /// Limits per character.
    pub limits: BTreeMap<String, Limits>,
}

/// Provenance written to `manifest.json` and (without timings) to the Parquet metadata.
#[derive(Debug, Serialize)]
struct Provenance<'a> {
    schema_version: &'a str,
    tool_version: &'a str,
    options: String,
    inputs: BTreeMap<String, String>,
    limits: &'a BTreeMap<String, Limits>,
}

fn stage_of(message: &str) -> &'static str {
    if message.contains("skeleton:") {
        "mapping"
    } else if message.contains(": line ") || message.contains("cannot open") {
        "parse"
    } else {
        "frames"
    }
}

/// Ingest and build (pure apart from reading the input files).
pub fn build(files: &[PathBuf], opts: &BuildOptions) -> BuildReport {
    let records = ingest_all(files, &opts.ingest);
    let per_clip: Vec<(Vec<Stance>, Vec<String>)> = records
        .par_iter()
        .map(|r| match (&r.frames, r.status) {
            (Some(fr), Status::Ok) => build_clip(&r.clip, fr, &r.summary, r.mass_kg, &opts.stances),
            _ => (Vec::new(), Vec::new()),
        })
        .collect();
    let mut stances: Vec<Stance> = per_clip.into_iter().flat_map(|(s, _)| s).collect();
    stances.sort_by(|a, b| {
        (&a.clip, a.first_frame, &a.label).cmp(&(&b.clip, b.first_frame, &b.label))
    });
    let errors: Vec<ErrorRow> = records
        .iter()
        .filter(|r| r.status == Status::Error)
        .map(|r| {
            let message = r.message.clone().unwrap_or_default();
            ErrorRow {
                path: r.path.clone(),
                clip: Some(r.clip.clone()),
                stage: stage_of(&message).into(),
                message,
            }
        })
        .collect();
    let facts: BTreeMap<String, ClipFacts> = records
        .iter()
        .map(|r| {
            (
                r.clip.clone(),
                ClipFacts {
                    s_eff: r.summary.s_eff,
                    leg_m: r.summary.leg_length_m.unwrap_or(1.0),
                },
            )
        })
        .collect();
    let limits = limits(&stances, &facts);
    BuildReport {
        records,
        stances,
        errors,
        limits,
    }
}

/// Write a built library into `out` atomically: everything goes to a sibling temporary
/// folder, which then takes the place of `out` (the previous library stays intact until
/// that moment, and is removed after it).
///
/// # Errors
/// A table that cannot be built or written, or a folder that cannot be renamed.
pub fn write_library(
    out: &Path,
    report: &BuildReport,
    opts: &BuildOptions,
    wall_s: f64,
) -> Result<()> {
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, "cannot create folder", e))?;
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "library".into());
    let tmp = parent.join(format!(".{name}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(|e| Error::io(&tmp, "cannot create folder", e))?;
    let result = write_tables(&tmp, report, opts, wall_s).and_then(|_| swap_into_place(&tmp, out));
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

fn write_tables(dir: &Path, report: &BuildReport, opts: &BuildOptions, wall_s: f64) -> Result<()> {
    let prov = Provenance {
        schema_version: SCHEMA_VERSION,
        tool_version: env!("CARGO_PKG_VERSION"),
        options: format!("{opts:?}"),
        inputs: report
            .records
            .iter()
            .map(|r| (r.clip.clone(), r.content_sha256.clone()))
            .collect(),
        limits: &report.limits,
    };
    let json = |v: &dyn erased::Json| v.to_json();
    let kv: Vec<(String, String)> = vec![
        ("stancelib.schema_version".into(), SCHEMA_VERSION.into()),
        (
            "stancelib.tool_version".into(),
            env!("CARGO_PKG_VERSION").into(),
        ),
        ("stancelib.options".into(), prov.options.clone()),
        ("stancelib.inputs".into(), json(&prov.inputs)),
        ("stancelib.limits".into(), json(&report.limits)),
    ];
    let recs = &report.records;
    let e = |f: &str, err: polars::prelude::PolarsError| {
        Error::io(dir.join(f), "cannot build table", err)
    };
    let mut tables = [
        (
            "frames.parquet",
            frames_table(recs).map_err(|x| e("frames.parquet", x))?,
        ),
        (
            "contacts.parquet",
            contacts_table(recs).map_err(|x| e("contacts.parquet", x))?,
        ),
        (
            "clips.parquet",
            clips_table(recs).map_err(|x| e("clips.parquet", x))?,
        ),
        (
            "stances.parquet",
            stances_table(&report.stances).map_err(|x| e("stances.parquet", x))?,
        ),
        (
            "errors.parquet",
            errors_table(&report.errors).map_err(|x| e("errors.parquet", x))?,
        ),
    ];
    for (name, df) in tables.iter_mut() {
        write_atomic(dir, name, df, &kv)?;
    }
    let count = |s: Status| recs.iter().filter(|r| r.status == s).count();
    let manifest = serde_json::json!({
        "schema_version": SCHEMA_VERSION,
        "tool_version": env!("CARGO_PKG_VERSION"),
        "options": prov.options,
        "inputs": prov.inputs,
        "limits": report.limits,
        "counts": {
            "clips": recs.len(), "ok": count(Status::Ok), "skipped": count(Status::Skipped),
            "failed": count(Status::Error), "stances": report.stances.len(),
        },
        "failures": report.errors.iter().map(|e| &e.message).collect::<Vec<_>>(),
        "wall_time_s": wall_s,
    });
    let text = serde_json::to_string_pretty(&manifest).unwrap_or_default();
    std::fs::write(dir.join("manifest.json"), text)
        .map_err(|err| Error::io(dir.join("manifest.json"), "cannot write", err))
}

/// Put `tmp` in the place of `out`: rename the old library aside, rename the new one in,
/// remove the old one. A run killed between the two renames leaves the old library at
/// `.<name>.old-<pid>` beside it, intact.
fn swap_into_place(tmp: &Path, out: &Path) -> Result<()> {
    if out.exists() {
        let old = out.with_file_name(format!(
            ".{}.old-{}",
            out.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            std::process::id()
        ));
        std::fs::rename(out, &old)
            .map_err(|e| Error::io(out, "cannot move the previous library aside", e))?;
        std::fs::rename(tmp, out)
            .map_err(|e| Error::io(out, "cannot move the new library into place", e))?;
        let _ = std::fs::remove_dir_all(&old);
    } else {
        std::fs::rename(tmp, out)
            .map_err(|e| Error::io(out, "cannot move the new library into place", e))?;
    }
    Ok(())
}

/// Build and write; the wall time goes to the manifest only.
///
/// # Errors
/// As [`write_library`].
pub fn build_and_write(files: &[PathBuf], out: &Path, opts: &BuildOptions) -> Result<BuildReport> {
    let t0 = Instant::now();
    let report = build(files, opts);
    write_library(out, &report, opts, t0.elapsed().as_secs_f64())?;
    Ok(report)
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
