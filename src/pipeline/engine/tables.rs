//! The per-clip tables of a build in memory ([`BuildReport`] → `Tables`) and the polars
//! helpers the sink and the merge share: stacking old and fresh rows in a table's order,
//! casting rows read back to a table's schema, a column's strings.

use polars::prelude::*;

use crate::error::{Error, Result};
use crate::library::codec::schema::{
    ADDED_COLUMNS, CLIPS_FILE, CONTACTS_FILE, ERRORS_FILE, FRAMES_FILE, JOINTS_FILE, STANCES_FILE,
};
use crate::library::codec::stances::{errors_table, stances_table, ErrorRow};
use crate::library::codec::write::{clips_table, contacts_table, frames_table, joints_table};
use crate::library::storage::layout::sorted;
use crate::library::ClipRecord;
use crate::stances::Stance;

/// Wraps a polars error as the I/O error of table `name`.
pub(crate) fn pe(name: &str, e: PolarsError) -> Error {
    Error::io(name, "cannot build table", e)
}

/// `fresh` and `old` rows of one table, in the table's order.
pub(crate) fn combine(fresh: &DataFrame, old: DataFrame, name: &str) -> Result<DataFrame> {
    let old = cast_like(old, fresh, name)?;
    let all = fresh.vstack(&old).map_err(|e| pe(name, e))?;
    sorted(all, name)
}

/// `df`'s columns of `like`, cast to its types (rows read back from Parquet). A column
/// added to the layout since `df` was written ([`ADDED_COLUMNS`]) reads as null.
pub(crate) fn cast_like(df: DataFrame, like: &DataFrame, name: &str) -> Result<DataFrame> {
    let n = df.height();
    let cols = like
        .columns()
        .iter()
        .map(|c| match df.column(c.name()) {
            Err(_) if ADDED_COLUMNS.contains(&c.name().as_str()) => {
                Ok(Column::full_null(c.name().clone(), n, c.dtype()))
            }
            found => found.and_then(|p| p.cast(c.dtype())),
        })
        .collect::<PolarsResult<Vec<Column>>>()
        .map_err(|e| Error::io(name, "rows of another schema", e))?;
    DataFrame::new_infer_height(cols).map_err(|e| pe(name, e))
}

/// The per-clip tables of a library (or of one batch of its clips).
pub(crate) struct Tables {
    pub frames: DataFrame,
    pub contacts: DataFrame,
    pub clips: DataFrame,
    pub stances: DataFrame,
    pub errors: DataFrame,
    pub joints: Option<DataFrame>,
}

impl Tables {
    /// Empty tables (the schemas).
    pub fn empty(joints: bool) -> Result<Tables> {
        Ok(Tables {
            frames: frames_table(&[]).map_err(|e| pe(FRAMES_FILE, e))?,
            contacts: contacts_table(&[]).map_err(|e| pe(CONTACTS_FILE, e))?,
            clips: clips_table(&[]).map_err(|e| pe(CLIPS_FILE, e))?,
            stances: stances_table(&[]).map_err(|e| pe(STANCES_FILE, e))?,
            errors: errors_table(&[]).map_err(|e| pe(ERRORS_FILE, e))?,
            joints: joints
                .then(|| joints_table(&[]).map_err(|e| pe(JOINTS_FILE, e)))
                .transpose()?,
        })
    }

    /// The tables sorted by clip first (every one but `errors.parquet`).
    pub fn named(&mut self) -> Vec<(&'static str, &mut DataFrame)> {
        let mut v = vec![
            (FRAMES_FILE, &mut self.frames),
            (CONTACTS_FILE, &mut self.contacts),
            (CLIPS_FILE, &mut self.clips),
            (STANCES_FILE, &mut self.stances),
        ];
        if let Some(j) = &mut self.joints {
            v.push((JOINTS_FILE, j));
        }
        v
    }
}

pub(crate) fn strings(df: &DataFrame, col: &str) -> Vec<String> {
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

/// What a build produced in memory (with [`build`](super::streaming::build): every clip).
#[derive(Debug)]
pub struct BuildReport {
    /// One record per input file, sorted by clip.
    pub records: Vec<ClipRecord>,
    /// Every stance of those clips, sorted by (clip, first frame, label).
    pub stances: Vec<Stance>,
    /// Failed inputs and stages.
    pub errors: Vec<ErrorRow>,
}

impl Tables {
    /// The tables of a build; `joints.parquet` too when the ingest kept joint positions
    /// (`--joints`: the same table as `frames --joints` writes).
    /// The tables are assembled side by side on the worker pool.
    pub(crate) fn from_report(r: &BuildReport, joints: bool) -> Result<Tables> {
        let rec = &r.records;
        let ((frames, contacts), ((clips, stances), (errors, joints))) = rayon::join(
            || rayon::join(|| frames_table(rec), || contacts_table(rec)),
            || {
                rayon::join(
                    || rayon::join(|| clips_table(rec), || stances_table(&r.stances)),
                    || {
                        rayon::join(
                            || errors_table(&r.errors),
                            || joints.then(|| joints_table(rec)),
                        )
                    },
                )
            },
        );
        Ok(Tables {
            frames: frames.map_err(|e| pe(FRAMES_FILE, e))?,
            contacts: contacts.map_err(|e| pe(CONTACTS_FILE, e))?,
            clips: clips.map_err(|e| pe(CLIPS_FILE, e))?,
            stances: stances.map_err(|e| pe(STANCES_FILE, e))?,
            errors: errors.map_err(|e| pe(ERRORS_FILE, e))?,
            joints: joints.transpose().map_err(|e| pe(JOINTS_FILE, e))?,
        })
    }
}
