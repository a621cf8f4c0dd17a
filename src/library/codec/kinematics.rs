//! The kinematic tables (spec two-pac §3): `kinematics_samples.parquet` (a shard's
//! samples), `kinematics.parquet` (the polytopes' facets) and `kinematics_points.parquet`
//! (the points behind them), written and read back. While a library is written its
//! samples wait in a scratch file ([`crate::library::storage::spill`]); the polytopes are built from them one
//! (character, effector) at a time by [`crate::twopac::limb_reach`].
//!
//! `kinematics.parquet`: one row per facet, `character_id`, `effector`, `nx`, `ny`, `nz`,
//! `d_m` (`n·ʳc ≤ d`, unit outward `n`, metres, contact frame), sorted by (`character_id`,
//! `effector`, `nx`, `ny`, `nz`, `d_m`). `kinematics_points.parquet`: the points after the
//! outlier rules, `character_id`, `effector`, `clip`, `frame`, `x_m`, `y_m`, `z_m`, sorted by
//! (`character_id`, `effector`, `clip`, `frame`).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use polars::prelude::*;

use super::columns::col;
use super::schema::{clips as C, contacts as CT, frames as F, kinematics as K, KINEMATICS_FILE};
use super::table::Table;
use crate::contacts::contact_runs::com_in_contact_frame;
use crate::error::{Error, Result};

/// One kinematic sample: the COM in an effector's contact frame at one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// The clip (one shared name per run of a clip's samples).
    pub clip: Arc<str>,
    /// The frame (file row).
    pub frame: i64,
    /// The COM in the contact frame, m.
    pub rc: [f64; 3],
}

/// One facet row: character, effector, unit outward normal, offset (m).
pub type Facet = (String, String, [f64; 3], f64);
/// The facets of one polytope: unit outward normals and offsets (m), `n·ʳc ≤ d`.
pub type FacetRows = (Vec<[f64; 3]>, Vec<f64>);

fn strs(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<String>>> {
    Ok(df
        .column(name)?
        .str()?
        .iter()
        .map(|v| v.map(str::to_string))
        .collect())
}

fn f64s(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<f64>>> {
    Ok(df.column(name)?.f64()?.iter().collect())
}

fn i64s(df: &DataFrame, name: &str) -> PolarsResult<Vec<Option<i64>>> {
    Ok(df.column(name)?.i64()?.iter().collect())
}

/// Per clip: `frame → COM` (world, m).
fn com_by_frame(frames: &DataFrame) -> PolarsResult<BTreeMap<String, BTreeMap<i64, [f64; 3]>>> {
    let (clip, frame) = (strs(frames, F::CLIP)?, i64s(frames, F::FRAME)?);
    let xyz = [
        f64s(frames, F::COM[0])?,
        f64s(frames, F::COM[1])?,
        f64s(frames, F::COM[2])?,
    ];
    let mut out: BTreeMap<String, BTreeMap<i64, [f64; 3]>> = BTreeMap::new();
    for i in 0..frames.height() {
        let (Some(c), Some(f)) = (&clip[i], frame[i]) else {
            continue;
        };
        let (Some(x), Some(y), Some(z)) = (xyz[0][i], xyz[1][i], xyz[2][i]) else {
            continue;
        };
        out.entry(c.clone()).or_default().insert(f, [x, y, z]);
    }
    Ok(out)
}

/// Each clip's character (`clip → character_id`) from a clips table, for the clips with a
/// leg length (the others have no samples).
fn characters(clips: &DataFrame) -> PolarsResult<BTreeMap<String, String>> {
    let (names, chars) = (strs(clips, C::CLIP)?, strs(clips, C::CHARACTER_ID)?);
    let legs = f64s(clips, C::LEG_LENGTH)?;
    Ok(names
        .into_iter()
        .zip(chars)
        .zip(legs)
        .filter_map(|((n, c), l)| Some((n?, c?, l?)))
        .map(|(n, c, _)| (n, c))
        .collect())
}

/// Adds the leg length of each character not yet in `legs`, from a clips table in clip
/// order: a character's leg length is that of its first clip (by name) that has one.
///
/// # Errors
/// The table lacks `clip`, `character_id` or `leg_length_m`.
pub fn add_character_legs(legs: &mut BTreeMap<String, f64>, clips: &DataFrame) -> PolarsResult<()> {
    let (names, chars, lens) = (
        strs(clips, C::CLIP)?,
        strs(clips, C::CHARACTER_ID)?,
        f64s(clips, C::LEG_LENGTH)?,
    );
    for i in 0..clips.height() {
        if let (Some(_), Some(c), Some(l)) = (&names[i], &chars[i], lens[i]) {
            legs.entry(c.clone()).or_insert(l);
        }
    }
    Ok(())
}

/// The kinematic samples of whole clips: every contact frame's COM in its contact frame,
/// before the outlier rules, one row per (character, effector, clip, frame) with
/// `character_id`, `effector`, `clip`, `frame`, `x_m`, `y_m`, `z_m`, sorted by those four
/// keys. This is the per-character summary a shard keeps (`kinematics_samples.parquet`):
/// the polytopes of a merge are made from the shards' samples.
///
/// # Errors
/// A table lacks a needed column or has it with another type.
pub fn samples_table(
    frames: &DataFrame,
    contacts: &DataFrame,
    clips: &DataFrame,
) -> PolarsResult<DataFrame> {
    let coms = com_by_frame(frames)?;
    let character = characters(clips)?;
    let (clip, eff) = (strs(contacts, CT::CLIP)?, strs(contacts, CT::EFFECTOR)?);
    let (first, last) = (
        i64s(contacts, CT::FIRST_FRAME)?,
        i64s(contacts, CT::LAST_FRAME)?,
    );
    let origin = [
        f64s(contacts, CT::ORIGIN_X)?,
        f64s(contacts, CT::ORIGIN_Y)?,
        f64s(contacts, CT::ORIGIN_Z)?,
    ];
    let yaw = f64s(contacts, CT::YAW)?;
    let mut rows: Vec<(&str, &str, &str, i64, [f64; 3])> = Vec::new();
    for i in 0..contacts.height() {
        let (Some(c), Some(e), Some(a), Some(b), Some(y)) =
            (&clip[i], &eff[i], first[i], last[i], yaw[i])
        else {
            continue;
        };
        let (Some(ox), Some(oy), Some(oz)) = (origin[0][i], origin[1][i], origin[2][i]) else {
            continue;
        };
        let (Some(ch), Some(com)) = (character.get(c), coms.get(c)) else {
            continue;
        };
        for (&frame, &p) in com.range(a..=b) {
            rows.push((ch, e, c, frame, com_in_contact_frame(p, [ox, oy, oz], y)));
        }
    }
    // Stable: rows of one key keep the contact table's order.
    rows.sort_by(|x, y| (x.0, x.1, x.2, x.3).cmp(&(y.0, y.1, y.2, y.3)));
    let p = |a: usize| -> Vec<f64> { rows.iter().map(|r| r.4[a]).collect() };
    DataFrame::new_infer_height(vec![
        col(
            K::CHARACTER_ID,
            rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        ),
        col(K::EFFECTOR, rows.iter().map(|r| r.1).collect::<Vec<_>>()),
        col(K::CLIP, rows.iter().map(|r| r.2).collect::<Vec<_>>()),
        col(K::FRAME, rows.iter().map(|r| r.3).collect::<Vec<_>>()),
        col(K::POINT[0], p(0)),
        col(K::POINT[1], p(1)),
        col(K::POINT[2], p(2)),
    ])
}

/// Sort keys of a samples table (see [`samples_table`]).
pub use super::schema::SAMPLES_SORT_KEYS;

/// The facets table (`kinematics.parquet`) of every polytope's facets, sorted by
/// character, effector, normal and offset.
///
/// # Errors
/// A column cannot be built.
pub fn facets_table(mut facets: Vec<Facet>) -> PolarsResult<DataFrame> {
    facets.sort_by(|x, y| {
        (&x.0, &x.1)
            .cmp(&(&y.0, &y.1))
            .then(x.2[0].total_cmp(&y.2[0]))
            .then(x.2[1].total_cmp(&y.2[1]))
            .then(x.2[2].total_cmp(&y.2[2]))
            .then(x.3.total_cmp(&y.3))
    });
    let f = |g: &dyn Fn(&Facet) -> f64| -> Vec<f64> { facets.iter().map(g).collect() };
    DataFrame::new_infer_height(vec![
        col(
            K::CHARACTER_ID,
            facets.iter().map(|r| r.0.clone()).collect::<Vec<_>>(),
        ),
        col(
            K::EFFECTOR,
            facets.iter().map(|r| r.1.clone()).collect::<Vec<_>>(),
        ),
        col(K::NORMAL[0], f(&|r| r.2[0])),
        col(K::NORMAL[1], f(&|r| r.2[1])),
        col(K::NORMAL[2], f(&|r| r.2[2])),
        col(K::OFFSET, f(&|r| r.3)),
    ])
}

/// The facets of a library's kinematic polytopes by (`character_id`, `effector`): unit
/// outward normals and offsets (`n·ʳc ≤ d`, metres, contact frame), in file order.
///
/// # Errors
/// `kinematics.parquet` missing or malformed (the error names the file, column and row).
pub fn read_facets(lib_dir: &Path) -> Result<BTreeMap<(String, String), FacetRows>> {
    let t = Table::open(&lib_dir.join(KINEMATICS_FILE))?;
    let (ch, eff) = (t.strings(K::CHARACTER_ID)?, t.strings(K::EFFECTOR)?);
    let (nx, ny, nz, d) = (
        t.f64s(K::NORMAL[0])?,
        t.f64s(K::NORMAL[1])?,
        t.f64s(K::NORMAL[2])?,
        t.f64s(K::OFFSET)?,
    );
    let mut rows: BTreeMap<(String, String), FacetRows> = BTreeMap::new();
    for i in 0..t.height() {
        let n = [nx[i], ny[i], nz[i]];
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if !((norm - 1.0).abs() <= 1e-6 && d[i].is_finite()) {
            return Err(Error::column(
                &t.path,
                K::NORMAL[0],
                Some(i),
                "facet normal is not a unit vector or d is not finite",
            ));
        }
        let p = rows.entry((ch[i].clone(), eff[i].clone())).or_default();
        p.0.push(n);
        p.1.push(d[i]);
    }
    Ok(rows)
}

/// Points of one (character, effector) gathered column by column for [`points_frame`]'s
/// table: the clip names as runs (one shared name per run of a clip's samples, not a copy
/// per row), the frames and the three coordinates.
#[derive(Debug, Default)]
pub struct PointRows {
    runs: Vec<(Arc<str>, usize)>,
    frame: Vec<i64>,
    xyz: [Vec<f64>; 3],
}

impl PointRows {
    /// Append one sample.
    pub fn push(&mut self, s: &Sample) {
        match self.runs.last_mut() {
            Some((clip, n)) if Arc::ptr_eq(clip, &s.clip) || **clip == *s.clip => *n += 1,
            _ => self.runs.push((Arc::clone(&s.clip), 1)),
        }
        self.frame.push(s.frame);
        for (column, v) in self.xyz.iter_mut().zip(s.rc) {
            column.push(v);
        }
    }

    /// Rows gathered.
    pub fn len(&self) -> usize {
        self.frame.len()
    }

    /// No rows gathered.
    pub fn is_empty(&self) -> bool {
        self.frame.is_empty()
    }

    /// The rows as the points table of `key` (character, effector), leaving none.
    ///
    /// # Errors
    /// A column cannot be built.
    pub fn take_frame(&mut self, key: &(String, String)) -> PolarsResult<DataFrame> {
        let n = self.len();
        let mut clip = StringChunkedBuilder::new(K::CLIP.into(), n);
        for (name, count) in self.runs.drain(..) {
            for _ in 0..count {
                clip.append_value(&name);
            }
        }
        let [x, y, z] = std::mem::take(&mut self.xyz);
        let name = |k: &str| PlSmallStr::from(k);
        DataFrame::new_infer_height(vec![
            StringChunked::full(name(K::CHARACTER_ID), &key.0, n).into_column(),
            StringChunked::full(name(K::EFFECTOR), &key.1, n).into_column(),
            clip.finish().into_column(),
            col(K::FRAME, std::mem::take(&mut self.frame)),
            col(K::POINT[0], x),
            col(K::POINT[1], y),
            col(K::POINT[2], z),
        ])
    }
}

/// `kinematics_points.parquet` and `kinematics_samples.parquet`: `character_id`,
/// `effector`, `clip`, `frame`, `x_m`, `y_m`, `z_m`.
///
/// # Errors
/// A column cannot be built.
pub fn points_frame(key: &(String, String), rows: &[Sample]) -> PolarsResult<DataFrame> {
    let mut p = PointRows::default();
    rows.iter().for_each(|s| p.push(s));
    p.take_frame(key)
}

#[cfg(test)]
mod schema_tests {
    use super::*;
    use crate::library::codec::schema::{KINEMATICS_COLUMNS, KINEMATICS_POINTS_COLUMNS};

    #[test]
    fn the_kinematic_tables_have_the_schema_columns() {
        let names = |df: &DataFrame| -> Vec<String> {
            df.get_column_names()
                .iter()
                .map(|n| n.to_string())
                .collect()
        };
        let facets = facets_table(Vec::new()).unwrap();
        let points = points_frame(&Default::default(), &[]).unwrap();
        assert_eq!(names(&facets), KINEMATICS_COLUMNS);
        assert_eq!(names(&points), KINEMATICS_POINTS_COLUMNS);
    }
}
