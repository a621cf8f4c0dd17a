//! What a library holds, in one screen (`stancelib info LIB`): its clips and characters,
//! stances by label and boundary kind, failures by stage, the build's options and
//! per-character limits, and its provenance (tool and schema version, date, command line).

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::read::same_content;
use crate::error::{escape, Error, Result};
use crate::library::codec::provenance::manifest_sha256;
use crate::library::codec::schema::{
    clips, errors, stances as S, CLIPS_FILE, ERRORS_FILE, STANCES_FILE,
};
use crate::library::codec::table::Table;

/// Stances beyond a person's bounds listed by the text summary (`--json` lists all).
pub const BEYOND_BOUNDS_SHOWN: usize = 10;

/// Counts of each distinct value, sorted by value.
pub type Counts = BTreeMap<String, usize>;

/// The summary of one library.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LibraryInfo {
    /// The library folder as given.
    pub library: PathBuf,
    /// SHA-256 of `manifest.json` (what query outputs record).
    pub manifest_sha256: String,
    /// `schema_version` of the manifest.
    pub schema_version: Option<String>,
    /// How the tables are laid out: `file` (one Parquet file per table) or `dataset`
    /// (hive-partitioned folders).
    pub layout: &'static str,
    /// Version of the tool that built it.
    pub tool_version: Option<String>,
    /// When it was built (RFC 3339 UTC); absent in libraries of older versions.
    pub created_utc: Option<String>,
    /// The command line that built it; absent in libraries of older versions.
    pub command_line: Option<Vec<String>>,
    /// Input files by `status` (`ok`, `skipped`, `error`).
    pub clips_by_status: Counts,
    /// Clips of each character (`character_id`; clips that failed have none).
    pub clips_by_character: Counts,
    /// Stances by `label` (`L`, `R`, `LR`, …).
    pub stances_by_label: Counts,
    /// Stance starts by boundary kind (`flight`, `no_flight`, `rest`, …).
    pub boundary_start: Counts,
    /// Stance ends by boundary kind.
    pub boundary_end: Counts,
    /// Stances by force model (`ratio`, `fourier`).
    pub stances_by_force_model: Counts,
    /// Failed inputs by `stage` of `errors.parquet`.
    pub failures_by_stage: Counts,
    /// The build options (manifest `options`).
    pub options: serde_json::Value,
    /// Per-character limits (manifest `limits`).
    pub limits: serde_json::Value,
    /// Foot stances beyond what a person's legs do, `(stance_id, why)`
    /// ([`crate::stances::limits::beyond_bounds`]): their characters' limits are capped.
    pub beyond_bounds: Vec<(String, String)>,
    /// Clips whose file repeats another clip's content (clip, the first clip by name with
    /// that content): the queries answer with the first only.
    pub duplicates: Vec<(String, String)>,
    /// Clips by where their body mass came from (`table`: `--masses`, `mass_kg`: given,
    /// `default`: 70 kg assumed); empty for a library written before `mass_source`.
    pub masses_by_source: Counts,
    /// Per character, the smallest and largest reach of its clips, m (`clips.parquet`
    /// `reach_m`: how far a jump may put the COM from the contact,
    /// `query::limits::jump_limits`); empty for a library written before `reach_m`.
    pub reach_by_character: BTreeMap<String, [f64; 2]>,
}

impl LibraryInfo {
    /// Number of stances.
    pub fn stances(&self) -> usize {
        self.stances_by_label.values().sum()
    }
}

fn counts<'a>(values: impl IntoIterator<Item = Option<&'a str>>) -> Counts {
    let mut c = Counts::new();
    for v in values.into_iter().flatten() {
        *c.entry(v.to_string()).or_default() += 1;
    }
    c
}

/// Counts of the string column `name` of `t` (nulls not counted).
fn column_counts(t: &Table, name: &str) -> Result<Counts> {
    let c =
        t.df.column(name)
            .map_err(|_| Error::column(&t.path, name, None, "missing"))?;
    let s = c
        .str()
        .map_err(|_| Error::column(&t.path, name, None, "expected string"))?;
    Ok(counts(s.iter()))
}

/// Reads the summary of the library `lib`.
///
/// # Errors
/// A missing or malformed `manifest.json`, `clips.parquet`, `stances.parquet` or
/// `errors.parquet` (the error names the file and column).
pub fn library_info(lib: &Path) -> Result<LibraryInfo> {
    crate::library::codec::provenance::check_layout(lib)?;
    let m = crate::library::codec::manifest::read_manifest(lib)?;
    let s = |k: &str| m.get(k).and_then(|v| v.as_str()).map(str::to_string);
    let clips = Table::open_columns(
        &lib.join(CLIPS_FILE),
        &[
            clips::STATUS,
            clips::CHARACTER_ID,
            clips::CLIP,
            clips::LEG_LENGTH,
            clips::CONTENT_SHA256,
        ],
    )?;
    let stances = Table::open_columns(
        &lib.join(STANCES_FILE),
        &[
            S::LABEL,
            S::BOUNDARY_START,
            S::BOUNDARY_END,
            S::FORCE_MODEL,
            S::STANCE_ID,
            S::CLIP,
            S::MASS,
            S::F_PEAK,
            S::EXT_MAX,
        ],
    )?;
    let errors = Table::open_columns(&lib.join(ERRORS_FILE), &[errors::STAGE])?;
    Ok(LibraryInfo {
        library: lib.to_path_buf(),
        manifest_sha256: manifest_sha256(lib)?,
        schema_version: s("schema_version"),
        layout: crate::library::storage::layout::layout_of(lib)?.as_str(),
        tool_version: s("tool_version"),
        created_utc: s("created_utc"),
        command_line: m
            .get("command_line")
            .and_then(|v| serde_json::from_value(v.clone()).ok()),
        clips_by_status: column_counts(&clips, clips::STATUS)?,
        clips_by_character: column_counts(&clips, clips::CHARACTER_ID)?,
        stances_by_label: column_counts(&stances, S::LABEL)?,
        boundary_start: column_counts(&stances, S::BOUNDARY_START)?,
        boundary_end: column_counts(&stances, S::BOUNDARY_END)?,
        stances_by_force_model: column_counts(&stances, S::FORCE_MODEL)?,
        failures_by_stage: column_counts(&errors, errors::STAGE)?,
        options: m.get("options").cloned().unwrap_or_default(),
        limits: m.get("limits").cloned().unwrap_or_default(),
        beyond_bounds: beyond_bounds(&clips, &stances)?,
        duplicates: duplicates(&clips)?,
        masses_by_source: masses_by_source(lib),
        reach_by_character: reach_by_character(lib),
    })
}

/// Per character, the smallest and largest `reach_m` of its clips (m); empty when
/// `clips.parquet` has no such column (written before it existed).
fn reach_by_character(lib: &Path) -> BTreeMap<String, [f64; 2]> {
    let mut out: BTreeMap<String, [f64; 2]> = BTreeMap::new();
    let Ok(t) = Table::open_columns(&lib.join(CLIPS_FILE), &[clips::CHARACTER_ID, clips::REACH])
    else {
        return out;
    };
    let (Ok(ids), Ok(reach)) = (
        crate::library::codec::table::opt_strings(&t, clips::CHARACTER_ID),
        t.added_f64(clips::REACH),
    ) else {
        return out;
    };
    for (id, r) in ids.into_iter().zip(reach) {
        if let (Some(id), Some(r)) = (id, r.filter(|r| r.is_finite())) {
            let e = out.entry(id).or_insert([r, r]);
            *e = [e[0].min(r), e[1].max(r)];
        }
    }
    out
}

/// Clips by the kind of their `mass_source` (`table <file>:<line>` counts as `table`);
/// empty when `clips.parquet` has no such column (written before it existed).
fn masses_by_source(lib: &Path) -> Counts {
    let Ok(t) = Table::open_columns(&lib.join(CLIPS_FILE), &[clips::MASS_SOURCE]) else {
        return Counts::new();
    };
    let Ok(v) = t.strings(clips::MASS_SOURCE) else {
        return Counts::new();
    };
    counts(
        v.iter()
            .map(|s| Some(s.split(' ').next().unwrap_or_default())),
    )
}

/// The clips of the library `lib` whose file repeats an earlier clip's content (clip, the
/// first clip by name with that content).
///
/// # Errors
/// `clips.parquet` missing or unreadable.
pub fn duplicate_clips(lib: &Path) -> Result<Vec<(String, String)>> {
    let t = Table::open_columns(&lib.join(CLIPS_FILE), &[clips::CLIP, clips::CONTENT_SHA256])?;
    duplicates(&t)
}

/// The clips of `clips_t` whose content repeats an earlier clip's ([`same_content`]).
fn duplicates(clips_t: &Table) -> Result<Vec<(String, String)>> {
    let (names, sha) = (
        clips_t.strings(clips::CLIP)?,
        clips_t.strings(clips::CONTENT_SHA256)?,
    );
    Ok(same_content(
        names
            .iter()
            .map(String::as_str)
            .zip(sha.iter().map(String::as_str)),
    )
    .into_iter()
    .collect())
}

/// The foot stances of `stances` beyond a person's bounds (legs from `clips`).
fn beyond_bounds(clips_t: &Table, stances: &Table) -> Result<Vec<(String, String)>> {
    let legs: BTreeMap<String, f64> = clips_t
        .strings(clips::CLIP)?
        .into_iter()
        .zip(clips_t.opt_f64(clips::LEG_LENGTH)?)
        .filter_map(|(c, l)| l.map(|l| (c, l)))
        .collect();
    let (ids, clip, label) = (
        stances.strings(S::STANCE_ID)?,
        stances.strings(S::CLIP)?,
        stances.strings(S::LABEL)?,
    );
    let (mass, f_peak, ext) = (
        stances.f64s(S::MASS)?,
        stances.f64s(S::F_PEAK)?,
        stances.f64s(S::EXT_MAX)?,
    );
    Ok((0..ids.len())
        .filter(|&i| !label[i].contains('H'))
        .filter_map(|i| {
            let leg = legs.get(&clip[i])?;
            crate::stances::limits::beyond_bounds(f_peak[i], mass[i], ext[i], *leg)
                .map(|why| (ids[i].clone(), why))
        })
        .collect())
}

fn write_counts(f: &mut fmt::Formatter<'_>, title: &str, c: &Counts) -> fmt::Result {
    let total: usize = c.values().sum();
    let parts: Vec<String> = c
        .iter()
        .map(|(k, n)| format!("{} {n}", escape(k)))
        .collect();
    let list = if parts.is_empty() {
        "none".to_string()
    } else {
        parts.join(", ")
    };
    writeln!(f, "{title:<20} {total:>6}   {list}")
}

impl fmt::Display for LibraryInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Every value read from the library is escaped: a character id (a body file's
        // `id`) with an ESC or a newline once reached the terminal as it was.
        let or = |v: &Option<String>| v.as_deref().map_or("(not recorded)".into(), escape);
        writeln!(f, "library {}", escape(&self.library.display().to_string()))?;
        writeln!(
            f,
            "  tool {}, schema {}, layout {}, built {}",
            or(&self.tool_version),
            or(&self.schema_version),
            self.layout,
            or(&self.created_utc)
        )?;
        if let Some(cmd) = &self.command_line {
            let words: Vec<String> = cmd.iter().map(|w| escape(w)).collect();
            writeln!(f, "  command: {}", words.join(" "))?;
        }
        writeln!(f, "  manifest sha256 {}", self.manifest_sha256)?;
        write_counts(f, "clips", &self.clips_by_status)?;
        write_counts(f, "characters (clips)", &self.clips_by_character)?;
        if !self.masses_by_source.is_empty() {
            write_counts(f, "masses (clips)", &self.masses_by_source)?;
            if self
                .masses_by_source
                .contains_key(crate::ingest::MASS_SOURCE_DEFAULT)
            {
                writeln!(
                    f,
                    "  warning: `default` clips were given {} kg: no --mass, mass_kg or --masses row named them",
                    crate::ingest::DEFAULT_MASS_KG
                )?;
            }
        }
        write_counts(f, "stances by label", &self.stances_by_label)?;
        write_counts(f, "  starting at", &self.boundary_start)?;
        write_counts(f, "  ending at", &self.boundary_end)?;
        write_counts(f, "  force model", &self.stances_by_force_model)?;
        write_counts(f, "failures by stage", &self.failures_by_stage)?;
        if let Some(chars) = self.limits.as_object() {
            writeln!(f, "per-character limits:")?;
            for (id, l) in chars {
                let g = |k: &str| l.get(k).and_then(|v| v.as_f64()).unwrap_or(f64::NAN);
                let from = match l.get("source").and_then(|v| v.as_str()).unwrap_or("?") {
                    "character" => "its own stances",
                    "size" => "the floor of a person's capacity (3.5 body weights)",
                    other => &escape(other),
                };
                let reach = match self.reach_by_character.get(id.as_str()) {
                    Some([lo, hi]) if hi - lo < 5e-4 => {
                        format!("; jumps: chi_max ≤ reach {lo:.3} m")
                    }
                    Some([lo, hi]) => format!("; jumps: chi_max ≤ reach {lo:.3}–{hi:.3} m by clip"),
                    None => String::new(),
                };
                let id = escape(id);
                let n = l.get("n_stances").and_then(|v| v.as_u64()).unwrap_or(0);
                writeln!(
                    f,
                    "  {id}: mu {:.2}, F_max {:.0} N, chi_min {:.3} m, chi_max {:.3} m \
                     ({n} stances; from {from}){reach}",
                    g("mu"),
                    g("f_max_n"),
                    g("chi_min_m"),
                    g("chi_max_m")
                )?;
            }
        }
        if !self.beyond_bounds.is_empty() {
            writeln!(
                f,
                "stances beyond a person's bounds ({}; their characters' limits are capped there):",
                self.beyond_bounds.len()
            )?;
            for (id, why) in self.beyond_bounds.iter().take(BEYOND_BOUNDS_SHOWN) {
                writeln!(f, "  {}: {}", escape(id), escape(why))?;
            }
            if self.beyond_bounds.len() > BEYOND_BOUNDS_SHOWN {
                writeln!(
                    f,
                    "  … {} more (`info --json` lists every one)",
                    self.beyond_bounds.len() - BEYOND_BOUNDS_SHOWN
                )?;
            }
        }
        if !self.duplicates.is_empty() {
            writeln!(
                f,
                "duplicate clips ({}; same file content, the queries answer with the first):",
                self.duplicates.len()
            )?;
            for (clip, of) in self.duplicates.iter().take(BEYOND_BOUNDS_SHOWN) {
                writeln!(f, "  {} = {}", escape(clip), escape(of))?;
            }
            if self.duplicates.len() > BEYOND_BOUNDS_SHOWN {
                writeln!(
                    f,
                    "  … {} more (`info --json` lists every one)",
                    self.duplicates.len() - BEYOND_BOUNDS_SHOWN
                )?;
            }
        }
        write!(f, "options: {}", escape(&self.options.to_string()))
    }
}
