//! Reading the tables back: typed columns with errors that name the file, column and row,
//! and the stance pool of the queries (`stances.parquet` + `clips.parquet`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::error::Result;

use crate::library::codec::stances::PoolStance;
pub use crate::library::codec::stances::{read_stance_timing, read_stances};
use crate::library::codec::table::{opt_strings, Table};

use crate::library::codec::schema::{clips, CLIPS_FILE, STANCES_FILE};

/// Per-clip facts the queries need from `clips.parquet`.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipInfo {
    /// Effective time scale of the clip's flights (`com-from-bvh.md` §7.7), when it has any.
    pub s_eff: Option<f64>,
    /// Leg length `L_leg`, m.
    pub leg_m: Option<f64>,
    /// How far from its COM the body reaches a contact, m (`clips.parquet` `reach_m`; none
    /// in libraries built before it existed).
    pub reach_m: Option<f64>,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// SHA-256 of the clip file's bytes, hex (empty when the file was not read).
    pub content_sha256: String,
}

/// Clips whose file content (SHA-256) repeats an earlier clip's, each mapped to the first
/// clip by name with that content; empty hashes (files never read) are not compared.
pub fn same_content<'a>(
    clips: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> BTreeMap<String, String> {
    let mut sorted: Vec<(&str, &str)> = clips.into_iter().filter(|(_, h)| !h.is_empty()).collect();
    sorted.sort();
    let mut first: BTreeMap<&str, &str> = BTreeMap::new();
    let mut out = BTreeMap::new();
    for (name, hash) in sorted {
        match first.get(hash) {
            Some(of) => {
                out.insert(name.to_string(), of.to_string());
            }
            None => {
                first.insert(hash, name);
            }
        }
    }
    out
}

/// A library folder as the queries see it.
#[derive(Debug, Clone)]
pub struct StanceLibrary {
    /// The folder.
    pub dir: PathBuf,
    /// Every stance row, in file order (sorted by `stance_id`'s parts).
    pub stances: Vec<PoolStance>,
    /// Per-clip facts by clip name.
    pub clips: BTreeMap<String, ClipInfo>,
}

/// Reads the per-clip facts of `clips.parquet`.
///
/// # Errors
/// The file cannot be read, or a column is missing or mistyped.
pub fn read_clip_info(path: &Path) -> Result<BTreeMap<String, ClipInfo>> {
    let t = Table::open(path)?;
    let (names, s_eff, leg, mass) = (
        t.strings(clips::CLIP)?,
        t.opt_f64(clips::S_EFF)?,
        t.opt_f64(clips::LEG_LENGTH)?,
        t.opt_f64(clips::MASS)?,
    );
    let sha = t.strings(clips::CONTENT_SHA256)?;
    let reach = t.added_f64(clips::REACH)?;
    Ok(names
        .into_iter()
        .enumerate()
        .map(|(i, n)| {
            let info = ClipInfo {
                s_eff: s_eff[i],
                leg_m: leg[i],
                reach_m: reach[i],
                mass_kg: mass[i].unwrap_or(f64::NAN),
                content_sha256: sha[i].clone(),
            };
            (n, info)
        })
        .collect())
}

/// Opens a library folder: its stances and clips.
///
/// # Errors
/// A library of another table layout ([`crate::library::codec::provenance::check_layout`]), a missing or
/// unreadable `stances.parquet` or `clips.parquet` (the error names it).
pub fn open_library(dir: &Path) -> Result<StanceLibrary> {
    crate::library::codec::provenance::check_layout(dir)?;
    Ok(StanceLibrary {
        dir: dir.to_path_buf(),
        stances: read_stances(&dir.join(STANCES_FILE))?,
        clips: read_clip_info(&dir.join(CLIPS_FILE))?,
    })
}

/// A clip's source file as `clips.parquet` records it.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipSource {
    /// The path as given to the build.
    pub path: String,
    /// SHA-256 of the file's bytes (hex).
    pub content_sha256: String,
    /// Metres per file unit.
    pub unit_scale: Option<f64>,
    /// Up axis (`+Y`, …).
    pub up_axis: Option<String>,
}

/// The source file of every clip of `clips.parquet`, by clip name.
///
/// # Errors
/// The file cannot be read, or a column is missing or mistyped.
pub fn read_clip_sources(path: &Path) -> Result<BTreeMap<String, ClipSource>> {
    let t = Table::open(path)?;
    let (names, paths, sha) = (
        t.strings(clips::CLIP)?,
        t.strings(clips::PATH)?,
        t.strings(clips::CONTENT_SHA256)?,
    );
    let (unit, up) = (
        t.opt_f64(clips::UNIT_SCALE)?,
        opt_strings(&t, clips::UP_AXIS)?,
    );
    Ok(names
        .into_iter()
        .enumerate()
        .map(|(i, n)| {
            let c = ClipSource {
                path: paths[i].clone(),
                content_sha256: sha[i].clone(),
                unit_scale: unit[i],
                up_axis: up[i].clone(),
            };
            (n, c)
        })
        .collect())
}
