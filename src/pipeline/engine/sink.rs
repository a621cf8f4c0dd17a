//! Writing a library batch by batch: the per-clip tables are appended as their rows come
//! (clips in name order), and what the per-character quantities need is kept as compact
//! summaries, so memory depends on the batch, and on the library's size only through
//! those summaries and the clips' names, hashes and statuses (about 1–1.5 kB a clip).
//!
//! # What is kept until the end
//! ```text
//! limits:      per clip, mass and support (clip, character_id, mass_kg, largest f_peak and
//!              ext_max, smallest ext_min, unsupported, stance count)  [`group_facts`]
//!              per clip    (s_eff, leg_length_m)
//! kinematics:  per contact frame (frame, x, y, z) in a scratch file, indexed per
//!              (character_id, effector, clip)                          [samples, on disk]
//!              per character (leg length of its first clip)
//! manifest:    per clip (content hash, status, rows per table); errors rows
//! ```
//! Once the tables are written, the manifest records every file's SHA-256 and each clip's
//! rows per table ([`crate::library::storage::integrity`]), what an incremental build and a merge
//! check before they take rows from the library.
//! The samples are the kinematic summary a shard writes (`kinematics_samples.parquet`) and
//! a merge reads back instead of the frames. Every table is sorted by its keys before it is
//! appended (rows of one batch), and batches arrive in clip order, so the files are the
//! same whatever the batch size, the thread count or the number of shards.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use polars::prelude::*;
use rayon::prelude::*;

use super::tables::{cast_like, pe, strings, Tables};
use crate::error::{Error, Result};
use crate::library::codec::kinematics::{
    add_character_legs, facets_table, points_frame, samples_table, Facet, PointRows, Sample,
};
use crate::library::codec::schema::{
    clips, frames, stances as S, CLIPS_FILE, CONTACTS_FILE, ERRORS_FILE, KINEMATICS_FILE,
    KINEMATICS_POINTS_FILE, KINEMATICS_SAMPLES_FILE, MANIFEST_FILE, MANIFEST_SCHEMA_PREFIX,
    SCHEMA_VERSION, STANCES_FILE,
};
use crate::library::codec::schema::{
    INPUTS_KEY, LAYOUT_MANIFEST_KEY, LIMITS_KEY, OPTIONS_KEY, SCHEMA_VERSION_KEY, SOURCE_DIGEST,
    TOOL_VERSION, TOOL_VERSION_KEY,
};
use crate::library::codec::write::write_atomic;
use crate::library::storage::group_reader::GroupFileReader;
use crate::library::storage::integrity::{
    add_clip_rows, library_digests, ClipRows, CLIP_ROWS_KEY, TABLES_KEY,
};
use crate::library::storage::layout::{convert_to_dataset, Layout};
use crate::library::storage::scratch::{scratch_name, Scratch};
use crate::library::storage::spill::SampleSpill;
use crate::library::storage::stream::TableWriter;
use crate::library::storage::stream::ROW_GROUP_ROWS;
use crate::stances::limits::{group_facts, limits, ClipFacts, StanceFacts};
use crate::twopac::hull::{HullOptions, StreamedHull};
use crate::twopac::limb_reach::OutlierRule;

/// The scratch file of a library's kinematic samples, in its temporary folder
/// ([`SampleSpill`]; removed before the folder is swapped into place).
const SPILL_FILE: &str = "kinematics_samples.spill";

use crate::library::storage::layout::sorted;

fn floats(df: &DataFrame, col: &str) -> Vec<Option<f64>> {
    df.column(col)
        .ok()
        .and_then(|c| c.f64().ok().map(|s| s.iter().collect()))
        .unwrap_or_default()
}

/// The facts the limits need of the stances of a stance table.
fn stance_facts(s: &DataFrame) -> Vec<StanceFacts> {
    let (clip, ch, b0, b1, label) = (
        strings(s, S::CLIP),
        strings(s, S::CHARACTER_ID),
        strings(s, S::BOUNDARY_START),
        strings(s, S::BOUNDARY_END),
        strings(s, S::LABEL),
    );
    let (m, fp, e0, e1) = (
        floats(s, S::MASS),
        floats(s, S::F_PEAK),
        floats(s, S::EXT_MIN),
        floats(s, S::EXT_MAX),
    );
    (0..s.height())
        .map(|i| StanceFacts {
            clip: clip[i].clone(),
            character_id: ch[i].clone(),
            mass_kg: m[i].unwrap_or(f64::NAN),
            f_peak: fp[i].unwrap_or(0.0),
            ext_min: e0[i].unwrap_or(f64::INFINITY),
            ext_max: e1[i].unwrap_or(0.0),
            unsupported: b0[i] == "unsupported" || b1[i] == "unsupported",
            hands: label[i].contains('H'),
            count: 1,
        })
        .collect()
}

/// Calls its function when dropped, unless disarmed: on an early return or a panic.
pub(crate) struct Defer<F: FnOnce()>(Option<F>);

impl<F: FnOnce()> Defer<F> {
    pub fn new(f: F) -> Defer<F> {
        Defer(Some(f))
    }

    /// The function is not called.
    pub fn disarm(&mut self) {
        self.0 = None;
    }
}

impl<F: FnOnce()> Drop for Defer<F> {
    fn drop(&mut self) {
        if let Some(f) = self.0.take() {
            f();
        }
    }
}

/// A library being written into a temporary folder (see the module docs).
pub(crate) struct LibrarySink {
    dir: PathBuf,
    writers: Vec<(&'static str, TableWriter)>,
    template: Tables,
    errors: Vec<DataFrame>,
    samples: SampleSpill,
    legs: BTreeMap<String, f64>,
    stance_facts: Vec<StanceFacts>,
    clip_facts: BTreeMap<String, ClipFacts>,
    inputs: BTreeMap<String, String>,
    status: Vec<String>,
    /// Rows per clip of each per-clip table but `clips.parquet` (one a clip).
    clip_rows: ClipRows,
    n_stances: usize,
    /// Samples come from the frames of each batch (a build), or are given (a merge).
    compute_samples: bool,
    /// Write the samples table too (a shard).
    keep_samples: bool,
}

impl LibrarySink {
    /// Start a library in `dir` (an empty folder).
    pub fn create(
        dir: &Path,
        joints: bool,
        compute_samples: bool,
        keep_samples: bool,
    ) -> Result<LibrarySink> {
        let mut template = Tables::empty(joints)?;
        let mut writers = Vec::new();
        for (name, df) in template.named() {
            let w = TableWriter::create(dir, name, df)?;
            // The per-clip tables of few rows a clip wait on disk for their row groups.
            let few_rows = [CLIPS_FILE, CONTACTS_FILE, STANCES_FILE].contains(&name);
            writers.push((name, if few_rows { w.with_pending_spill() } else { w }));
        }
        Ok(LibrarySink {
            dir: dir.to_path_buf(),
            writers,
            template,
            errors: Vec::new(),
            samples: SampleSpill::create(&dir.join(scratch_name(SPILL_FILE, Scratch::Tmp)))?,
            legs: BTreeMap::new(),
            stance_facts: Vec::new(),
            clip_facts: BTreeMap::new(),
            inputs: BTreeMap::new(),
            status: Vec::new(),
            clip_rows: ClipRows::new(),
            n_stances: 0,
            compute_samples,
            keep_samples,
        })
    }

    /// The empty tables, for the schemas.
    pub fn template(&mut self) -> &mut Tables {
        &mut self.template
    }

    /// Append one batch: whole clips, each table sorted, every clip after those of the
    /// batches before.
    pub fn push(&mut self, t: &mut Tables) -> Result<()> {
        if self.compute_samples {
            let s = samples_table(&t.frames, &t.contacts, &t.clips)
                .map_err(|e| pe(KINEMATICS_SAMPLES_FILE, e))?;
            self.samples.add(&s)?;
        }
        add_character_legs(&mut self.legs, &t.clips).map_err(|e| pe(CLIPS_FILE, e))?;
        self.stance_facts
            .extend(group_facts(stance_facts(&t.stances)));
        let c = &t.clips;
        for (k, (s_eff, leg)) in strings(c, clips::CLIP).into_iter().zip(
            floats(c, clips::S_EFF)
                .into_iter()
                .zip(floats(c, clips::LEG_LENGTH)),
        ) {
            self.clip_facts.insert(
                k,
                ClipFacts {
                    s_eff,
                    leg_m: leg.unwrap_or(1.0),
                },
            );
        }
        self.inputs.extend(
            strings(c, clips::CLIP)
                .into_iter()
                .zip(strings(c, clips::CONTENT_SHA256)),
        );
        self.status.extend(strings(c, clips::STATUS));
        self.n_stances += t.stances.height();
        if t.errors.height() > 0 {
            self.errors.push(std::mem::take(&mut t.errors));
        }
        // The tables are written side by side on the worker pool (each its own file); a
        // detached table's writer is elsewhere, so its rows cannot come here.
        for (name, df) in t.named() {
            if name != CLIPS_FILE {
                count_clip_rows(&mut self.clip_rows, name, df);
            }
        }
        let mut named: BTreeMap<&str, &mut DataFrame> = t.named().into_iter().collect();
        let jobs: Vec<(&mut DataFrame, &mut TableWriter)> = self
            .writers
            .iter_mut()
            .filter_map(|(n, w)| named.remove(n).map(|df| (df, w)))
            .collect();
        if let Some((name, _)) = named.iter().find(|(_, df)| df.height() > 0) {
            return Err(Error::io(
                self.dir.join(name),
                "cannot append rows",
                std::io::Error::other("the table's writer is detached"),
            ));
        }
        let pushed: Vec<Result<()>> = jobs.into_par_iter().map(|(df, w)| w.push(df)).collect();
        pushed.into_iter().collect()
    }

    /// Take the writers of the tables `names` out of the sink, to be filled elsewhere (a
    /// merge copies the per-clip row groups on a thread of their own) and handed back to
    /// [`LibrarySink::finish_with`]. Rows of those tables given to [`LibrarySink::push`]
    /// are then refused.
    pub fn detach(&mut self, names: &[&str]) -> Vec<(&'static str, TableWriter)> {
        let (out, keep) = std::mem::take(&mut self.writers)
            .into_iter()
            .partition(|(n, _)| names.contains(n));
        self.writers = keep;
        out
    }

    /// Add error rows (any order).
    pub fn push_errors(&mut self, df: DataFrame) {
        self.errors.push(df);
    }

    /// Add kinematic samples: a samples table sorted by [`SAMPLES_SORT_KEYS`], or a slice
    /// of one (tables and slices in any order; a clip's rows in one table, in order).
    pub fn push_samples(&mut self, df: &DataFrame) -> Result<()> {
        self.samples.add(df)
    }

    /// Write the remaining tables, the footers and `manifest.json`; `shard` is recorded in
    /// the manifest of a shard library. A `dataset` library's tables are then split into
    /// their datasets ([`convert_to_dataset`]) and its manifest names the layout (a `file`
    /// library's has no `layout` key, as before there were two).
    pub fn finish(
        self,
        fingerprint: &str,
        t0: Instant,
        shard: Option<serde_json::Value>,
        layout: Layout,
    ) -> Result<()> {
        self.finish_with(
            fingerprint,
            t0,
            shard,
            layout,
            || Ok(Detached::default()),
            &|| {},
        )
    }

    /// [`LibrarySink::finish`] for a sink with detached writers ([`LibrarySink::detach`]):
    /// `rejoin` hands them back, filled, with the rows per clip written through them. It is called on a thread of its own as the finish
    /// starts, and the writers get their footers there, so whatever fills them (and their
    /// footers) overlaps the polytopes, the longest part of the finish. `cancel` is called
    /// when the rest of the finish fails or panics, before `rejoin`'s thread is waited
    /// for (to end whatever fills the writers early).
    pub fn finish_with(
        mut self,
        fingerprint: &str,
        t0: Instant,
        shard: Option<serde_json::Value>,
        layout: Layout,
        rejoin: impl FnOnce() -> Result<Detached> + Send,
        cancel: &(dyn Fn() + Sync),
    ) -> Result<()> {
        let dir = self.dir.clone();
        let mut errors = concat(
            std::mem::take(&mut self.errors),
            &self.template.errors,
            ERRORS_FILE,
        )?;
        let lim = limits(&self.stance_facts, &self.clip_facts);
        let json = |v: &dyn erased::Json| v.to_json();
        let kv: Vec<(String, String)> = vec![
            (SCHEMA_VERSION_KEY.into(), SCHEMA_VERSION.into()),
            (TOOL_VERSION_KEY.into(), TOOL_VERSION.into()),
            (OPTIONS_KEY.into(), fingerprint.to_string()),
            (INPUTS_KEY.into(), json(&self.inputs)),
            (LIMITS_KEY.into(), json(&lim)),
        ];
        // The detached writers are handed back and get their footers on a thread of their
        // own, beside the rest (in a build there are none).
        let detached_rows = std::thread::scope(|scope| {
            let detached = scope.spawn(|| -> Result<ClipRows> {
                let back = rejoin()?;
                for (_, w) in back.writers {
                    w.finish(&kv)?;
                }
                Ok(back.clip_rows)
            });
            let mut failed = Defer::new(cancel);
            let ours = self.finish_tables(&mut errors, &kv);
            if ours.is_ok() {
                failed.disarm();
            }
            drop(failed);
            let theirs = detached.join().unwrap_or_else(|_| {
                Err(Error::io(
                    &dir,
                    "cannot finish the tables",
                    std::io::Error::other("the thread of the detached tables stopped"),
                ))
            });
            ours.and(theirs)
        })?;
        for (clip, tables) in detached_rows {
            for (table, n) in tables {
                add_clip_rows(&mut self.clip_rows, &clip, &table, n);
            }
        }
        if layout == Layout::Dataset {
            convert_to_dataset(&dir)?;
        }
        let digests = library_digests(&dir)?;
        let count = |s: &str| self.status.iter().filter(|v| *v == s).count();
        let mut manifest = serde_json::json!({
            "schema": format!("{MANIFEST_SCHEMA_PREFIX}{SCHEMA_VERSION}"),
            "schema_version": SCHEMA_VERSION,
            "tool_version": TOOL_VERSION,
            "source_digest": SOURCE_DIGEST,
            // Not in the Parquet metadata: these change from run to run (the tables do not).
            "created_utc": crate::library::codec::provenance::now_utc(),
            "command_line": crate::library::codec::provenance::command_line(),
            "options": serde_json::from_str::<serde_json::Value>(fingerprint).unwrap_or_default(),
            "inputs": self.inputs,
            "limits": lim,
            "counts": {
                "clips": self.status.len(), "ok": count("ok"), "skipped": count("skipped"),
                "failed": count("error"), "stances": self.n_stances,
            },
            "failures": strings(&errors, "message"),
            TABLES_KEY: digests,
            CLIP_ROWS_KEY: self.clip_rows,
            "wall_time_s": t0.elapsed().as_secs_f64(),
        });
        if let (Some(s), Some(m)) = (shard, manifest.as_object_mut()) {
            m.insert("shard".into(), s);
        }
        if layout == Layout::Dataset {
            if let Some(m) = manifest.as_object_mut() {
                m.insert(LAYOUT_MANIFEST_KEY.into(), layout.as_str().into());
            }
        }
        let text = serde_json::to_string_pretty(&manifest).unwrap_or_default();
        crate::library::storage::atomic::write_text_atomic(&dir.join(MANIFEST_FILE), &text)
    }

    /// The footers of the sink's own tables, `errors.parquet`, the samples (a shard's) and
    /// the kinematic tables, each with the key-value pairs `kv`.
    fn finish_tables(&mut self, errors: &mut DataFrame, kv: &[(String, String)]) -> Result<()> {
        for (_, w) in std::mem::take(&mut self.writers) {
            w.finish(kv)?;
            super::memory::release_free_memory();
        }
        write_atomic(&self.dir, ERRORS_FILE, errors, kv)?;
        self.samples.seal()?;
        if self.keep_samples {
            write_samples(&self.samples, &self.dir, kv)?;
        }
        kinematics(&self.samples, &self.legs, &self.dir, kv)
    }
}

/// Writers handed back to [`LibrarySink::finish_with`], filled, with the rows per clip
/// written through them (table names as [`add_clip_rows`] takes them).
#[derive(Default, Debug)]
pub(crate) struct Detached {
    pub writers: Vec<(&'static str, TableWriter)>,
    pub clip_rows: ClipRows,
}

/// Add the rows per clip of `df` (rows of table `name`, whole clips in clip order) to
/// `rows`.
fn count_clip_rows(rows: &mut ClipRows, name: &str, df: &DataFrame) {
    let Ok(clips) = df.column(frames::CLIP).and_then(|c| c.str().cloned()) else {
        return;
    };
    let mut run: Option<(&str, u64)> = None;
    for c in clips.iter() {
        let c = c.unwrap_or_default();
        match &mut run {
            Some((last, n)) if *last == c => *n += 1,
            _ => {
                if let Some((last, n)) = run.take() {
                    add_clip_rows(rows, last, name, n);
                }
                run = Some((c, 1));
            }
        }
    }
    if let Some((last, n)) = run {
        add_clip_rows(rows, last, name, n);
    }
}

/// Rows of a group's samples appended to `w`, a row group's worth at a time.
struct GroupRows<'a> {
    key: &'a (String, String),
    rows: PointRows,
    w: &'a mut TableWriter,
}

impl GroupRows<'_> {
    fn add(&mut self, s: &Sample) -> Result<()> {
        self.rows.push(s);
        if self.rows.len() >= ROW_GROUP_ROWS {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<()> {
        let df = self
            .rows
            .take_frame(self.key)
            .map_err(|e| pe(KINEMATICS_POINTS_FILE, e))?;
        self.w.push(&df)
    }
}

/// `kinematics_samples.parquet` (a shard's summary): every sample, by group.
fn write_samples(spill: &SampleSpill, dir: &Path, kv: &[(String, String)]) -> Result<()> {
    let empty =
        points_frame(&Default::default(), &[]).map_err(|e| pe(KINEMATICS_SAMPLES_FILE, e))?;
    let mut w = TableWriter::create(dir, KINEMATICS_SAMPLES_FILE, &empty)?;
    for (key, _) in spill.groups() {
        let mut rows = GroupRows {
            key,
            rows: PointRows::default(),
            w: &mut w,
        };
        spill.read_group(key, &mut |b| b.iter().try_for_each(|s| rows.add(s)))?;
        rows.flush()?;
    }
    w.finish(kv)
}

/// The two kinematics tables of the spilled samples with each character's leg length (m),
/// written into `dir`: per (character, effector) the outlier rules ([`OutlierRule`], three
/// passes over the spilled group) and one more pass that streams the kept samples to the
/// table and into the polytope's [`StreamedHull`] (bounded memory: see the module docs
/// of [`crate::twopac::limb_reach`]); a group with fewer than 4 non-coplanar points after
/// the rules has points but no facets (an error at query time).
///
/// The groups are reduced in parallel on the worker pool ([`reduce_group`]), each writing
/// its points to a scratch table of its own; their row groups (a table cut per character
/// and effector, `schema::group_keys`) are then copied in order into the points table, so
/// the bytes do not depend on the thread count.
fn kinematics(
    spill: &SampleSpill,
    legs: &BTreeMap<String, f64>,
    dir: &Path,
    kv: &[(String, String)],
) -> Result<()> {
    let empty =
        points_frame(&Default::default(), &[]).map_err(|e| pe(KINEMATICS_POINTS_FILE, e))?;
    let parts =
        ScratchDir::create(dir.join(scratch_name("kinematics_points.parts", Scratch::Tmp)))?;
    let keys: Vec<&(String, String)> = spill.groups().into_iter().map(|(k, _)| k).collect();
    let reduced: Vec<Vec<Facet>> = keys
        .par_iter()
        .enumerate()
        .map(|(i, key)| {
            let leg = legs.get(&key.0).copied().unwrap_or(f64::INFINITY);
            reduce_group(spill, key, leg, &parts.part(i)?, &empty)
        })
        .collect::<Result<_>>()?;
    let mut w = TableWriter::create(dir, KINEMATICS_POINTS_FILE, &empty)?;
    for i in 0..keys.len() {
        let path = parts.part(i)?.join(KINEMATICS_POINTS_FILE);
        let mut groups = GroupFileReader::open(&path)?;
        while let Some(g) = groups.next_group()? {
            w.push_group(&g)?;
        }
        drop(groups);
        let _ = std::fs::remove_file(&path);
    }
    w.finish(kv)?;
    let mut facets = facets_table(reduced.into_iter().flatten().collect())
        .map_err(|e| pe(KINEMATICS_FILE, e))?;
    write_atomic(dir, KINEMATICS_FILE, &mut facets, kv)
}

/// One (character, effector) group of the spilled samples, with the character's leg length
/// `leg` (m): its kept points written to `part/kinematics_points.parquet` (a table of
/// `empty`'s columns), its polytope's facets returned ([`kinematics`]).
fn reduce_group(
    spill: &SampleSpill,
    key: &(String, String),
    leg: f64,
    part: &Path,
    empty: &DataFrame,
) -> Result<Vec<Facet>> {
    let rule = OutlierRule::fit(leg, |f| {
        spill.read_points(key, &mut |b| {
            b.iter().for_each(&mut *f);
            Ok(())
        })
    })?;
    let mut w = TableWriter::create(part, KINEMATICS_POINTS_FILE, empty)?;
    let mut hull = StreamedHull::default();
    let mut rows = GroupRows {
        key,
        rows: PointRows::default(),
        w: &mut w,
    };
    spill.read_group(key, &mut |b| {
        for s in b.iter().filter(|s| rule.keeps(&s.rc)) {
            hull.push(s.rc);
            rows.add(s)?;
        }
        Ok(())
    })?;
    rows.flush()?;
    w.finish(&[])?;
    Ok(match hull.finish(&HullOptions::default()) {
        Ok(p) => {
            p.a.iter()
                .zip(&p.b)
                .map(|(n, d)| (key.0.clone(), key.1.clone(), *n, *d))
                .collect()
        }
        Err(_) => Vec::new(),
    })
}

/// A scratch folder of numbered part folders, removed with everything in it when dropped.
struct ScratchDir(PathBuf);

impl ScratchDir {
    fn create(path: PathBuf) -> Result<ScratchDir> {
        std::fs::create_dir_all(&path).map_err(|e| Error::io(&path, "cannot create", e))?;
        Ok(ScratchDir(path))
    }

    /// Part folder `i`, made if missing.
    fn part(&self, i: usize) -> Result<PathBuf> {
        let p = self.0.join(i.to_string());
        std::fs::create_dir_all(&p).map_err(|e| Error::io(&p, "cannot create", e))?;
        Ok(p)
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `parts` stacked and sorted as table `name` (`empty` when there are none).
fn concat(parts: Vec<DataFrame>, empty: &DataFrame, name: &str) -> Result<DataFrame> {
    let mut all = empty.clear();
    for p in parts {
        let p = cast_like(p, empty, name)?;
        all.vstack_mut(&p).map_err(|e| pe(name, e))?;
    }
    sorted(all, name)
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
