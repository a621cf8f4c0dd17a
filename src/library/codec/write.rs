//! Building the output tables from clip records and writing them atomically.
//!
//! Rows are sorted by stable keys (`clip`, then frame or effector) before writing, with
//! fixed writer settings (zstd, statistics on, row groups of exactly 64 Ki rows, the last
//! one shorter: [`crate::library::storage::stream`]), so the files
//! do not depend on thread count or input order.

use std::path::{Path, PathBuf};

use polars::prelude::*;
use rayon::prelude::*;

use super::columns::col;

use super::schema::*;
use crate::contacts::EFFECTORS;
use crate::error::{Error, Result};
use crate::library::storage::scratch::{remove_stale, Scratch};
use crate::library::storage::stream::TableWriter;
use crate::library::ClipRecord;

fn polars_err(path: &Path, e: PolarsError) -> Error {
    Error::io(path, "cannot build table", e)
}

/// `frames.parquet` from the `ok` records (already sorted by clip).
pub fn frames_table(records: &[ClipRecord]) -> PolarsResult<DataFrame> {
    let fr: Vec<(&str, &crate::ingest::ClipFrames)> = records
        .iter()
        .filter_map(|r| r.frames.as_ref().map(|f| (r.clip.as_str(), f)))
        .collect();
    let n: usize = fr.iter().map(|(_, f)| f.frame.len()).sum();
    let mut clip = Vec::with_capacity(n);
    for (c, f) in &fr {
        clip.extend(std::iter::repeat_n(*c, f.frame.len()));
    }
    let cat_i64 = |g: &dyn Fn(&crate::ingest::ClipFrames) -> &Vec<i64>| -> Vec<i64> {
        fr.iter().flat_map(|(_, f)| g(f).iter().copied()).collect()
    };
    let cat_f64 = |g: &dyn Fn(&crate::ingest::ClipFrames) -> Vec<f64>| -> Vec<f64> {
        fr.iter().flat_map(|(_, f)| g(f)).collect()
    };
    let mut cols = vec![
        col(frames::CLIP, clip),
        col(frames::FRAME, cat_i64(&|f| &f.frame)),
        col(frames::TIME, cat_f64(&|f| f.time_s.clone())),
    ];
    for (names, get) in [
        (frames::COM, 0usize),
        (frames::COM_V, 1),
        (frames::COM_A, 2),
    ] {
        for (a, name) in names.iter().enumerate() {
            let v = cat_f64(&|f| {
                let src = match get {
                    0 => &f.com,
                    1 => &f.com_v,
                    _ => &f.com_a,
                };
                src.iter().map(|p| p[a]).collect()
            });
            cols.push(col(name, v));
        }
    }
    cols.push(col(frames::GROUND_Z, cat_f64(&|f| f.ground_z.clone())));
    for (e, name) in EFFECTORS.iter().enumerate() {
        let v: Vec<bool> = fr
            .iter()
            .flat_map(|(_, f)| f.contact[e].iter().copied())
            .collect();
        cols.push(col(&frames::contact(name), v));
    }
    for (e, name) in EFFECTORS.iter().enumerate() {
        let v: Vec<Option<bool>> = fr
            .iter()
            .flat_map(|(_, f)| match &f.static_contact {
                Some(s) => s[e].iter().map(|b| Some(*b)).collect::<Vec<_>>(),
                None => vec![None; f.frame.len()],
            })
            .collect();
        cols.push(col(&frames::is_static(name), v));
        let z: Vec<Option<f64>> = fr
            .iter()
            .flat_map(|(_, f)| match &f.surface_z {
                Some(s) => s[e].clone(),
                None => vec![None; f.frame.len()],
            })
            .collect();
        cols.push(col(&frames::surface_z(name), z));
    }
    for (e, name) in EFFECTORS.iter().enumerate() {
        for a in 0..3 {
            let v: Vec<Option<f64>> = fr
                .iter()
                .flat_map(|(_, f)| match &f.effector_pos[e] {
                    Some(p) => p.iter().map(|q| Some(q[a])).collect::<Vec<_>>(),
                    None => vec![None; f.frame.len()],
                })
                .collect();
            cols.push(col(&frames::position(name, a), v));
        }
    }
    for (k, toe) in frames::TOES.iter().enumerate() {
        for a in 0..3 {
            cols.push(col(
                &frames::position(toe, a),
                cat_f64(&|f| f.toe[k].iter().map(|p| p[a]).collect()),
            ));
        }
    }
    DataFrame::new_infer_height(cols)
}

fn flights_dtype() -> DataType {
    let f = |n: &str, t: DataType| Field::new(n.into(), t);
    let fields = vec![
        f(flights::FIRST_FRAME, DataType::Int64),
        f(flights::LAST_FRAME, DataType::Int64),
        f(flights::DURATION, DataType::Float64),
        f(flights::A_Z, DataType::Float64),
        f(flights::A_X, DataType::Float64),
        f(flights::A_Y, DataType::Float64),
        f(flights::RMS, DataType::Float64),
        f(flights::S_EFF, DataType::Float64),
        f(flights::A_Z_MEAN, DataType::Float64),
        f(flights::BALLISTIC, DataType::Boolean),
        f(flights::TESTED, DataType::Boolean),
    ];
    DataType::List(Box::new(DataType::Struct(fields)))
}

fn flights_series(r: &ClipRecord) -> PolarsResult<Option<Series>> {
    if r.frames.is_none() {
        return Ok(None);
    }
    let fl = &r.summary.flights;
    macro_rules! s {
        ($name:expr, $get:expr) => {
            Series::new($name.into(), fl.iter().map($get).collect::<Vec<_>>())
        };
    }
    let fields = [
        s!(flights::FIRST_FRAME, |f| f.first_frame),
        s!(flights::LAST_FRAME, |f| f.last_frame),
        s!(flights::DURATION, |f| f.duration_s),
        s!(flights::A_Z, |f| f.a_z),
        s!(flights::A_X, |f| f.a_x),
        s!(flights::A_Y, |f| f.a_y),
        s!(flights::RMS, |f| f.rms_m),
        s!(flights::S_EFF, |f| f.s_eff),
        s!(flights::A_Z_MEAN, |f| f.a_z_mean),
        s!(flights::BALLISTIC, |f| f.ballistic),
        s!(flights::TESTED, |f| f.tested),
    ];
    Ok(Some(
        StructChunked::from_series(clips::FLIGHTS.into(), fl.len(), fields.iter())?.into_series(),
    ))
}

/// `clips.parquet` from every record (already sorted by clip).
pub fn clips_table(records: &[ClipRecord]) -> PolarsResult<DataFrame> {
    let s = |g: &dyn Fn(&ClipRecord) -> Option<String>| -> Vec<Option<String>> {
        records.iter().map(g).collect()
    };
    let f = |g: &dyn Fn(&ClipRecord) -> Option<f64>| -> Vec<Option<f64>> {
        records.iter().map(g).collect()
    };
    let i = |g: &dyn Fn(&ClipRecord) -> Option<i64>| -> Vec<Option<i64>> {
        records.iter().map(g).collect()
    };
    let parsed = |r: &ClipRecord| r.summary.frame_time_s > 0.0;
    let leadin: ListChunked = records
        .iter()
        .map(|r| Some(Series::new("".into(), r.summary.leadin_dropped.clone())))
        .collect();
    let warnings: ListChunked = records
        .iter()
        .map(|r| Some(Series::new("".into(), r.summary.warnings.clone())))
        .collect();
    let flights: ListChunked = records
        .iter()
        .map(flights_series)
        .collect::<PolarsResult<Vec<_>>>()?
        .into_iter()
        .collect();
    let cols = vec![
        col(clips::PATH, s(&|r| Some(r.path.clone()))),
        col(clips::CLIP, s(&|r| Some(r.clip.clone()))),
        col(
            clips::CONTENT_SHA256,
            s(&|r| Some(r.content_sha256.clone())),
        ),
        col(clips::STATUS, s(&|r| Some(r.status.as_str().to_string()))),
        col(clips::MESSAGE, s(&|r| r.message.clone())),
        col(clips::FRAMES_HEADER, i(&|r| r.summary.frames_header)),
        col(
            clips::FRAMES_DATA,
            i(&|r| parsed(r).then_some(r.summary.frames_data)),
        ),
        col(
            clips::FRAMES_KEPT,
            i(&|r| parsed(r).then_some(r.summary.frames_kept)),
        ),
        leadin
            .into_series()
            .cast(&DataType::List(Box::new(DataType::Int64)))?
            .with_name(clips::LEADIN_DROPPED.into())
            .into(),
        col(
            clips::FRAME_TIME,
            f(&|r| parsed(r).then_some(r.summary.frame_time_s)),
        ),
        col(clips::UNIT_SCALE, f(&|r| r.summary.unit_scale)),
        col(clips::UNIT, s(&|r| r.summary.unit.clone())),
        col(clips::UP_AXIS, s(&|r| r.summary.up_axis.clone())),
        col(
            clips::HANDEDNESS_OK,
            records
                .iter()
                .map(|r| r.summary.handedness_ok)
                .collect::<Vec<_>>(),
        ),
        col(clips::LEG_LENGTH, f(&|r| r.summary.leg_length_m)),
        col(clips::REACH, f(&|r| r.summary.reach_m)),
        col(clips::CHARACTER_ID, s(&|r| r.summary.character_id.clone())),
        col(
            clips::MASS,
            records.iter().map(|r| r.mass_kg).collect::<Vec<_>>(),
        ),
        col(
            clips::MASS_SOURCE,
            s(&|r| Some(r.summary.mass_source.clone())),
        ),
        col(clips::SKELETON, s(&|r| r.summary.skeleton.clone())),
        col(
            clips::TOE_TIP_RULE_LEFT,
            s(&|r| r.summary.toe_tip_rule[0].clone()),
        ),
        col(
            clips::TOE_TIP_RULE_RIGHT,
            s(&|r| r.summary.toe_tip_rule[1].clone()),
        ),
        flights
            .into_series()
            .cast(&flights_dtype())?
            .with_name(clips::FLIGHTS.into())
            .into(),
        col(clips::FLIGHT_AZ_MEDIAN, f(&|r| r.summary.flight_az_median)),
        col(clips::S_EFF, f(&|r| r.summary.s_eff)),
        warnings
            .into_series()
            .cast(&DataType::List(Box::new(DataType::String)))?
            .with_name(clips::WARNINGS.into())
            .into(),
    ];
    DataFrame::new_infer_height(cols)
}

/// `contacts.parquet` (sorted by clip, effector, first frame).
pub fn contacts_table(records: &[ClipRecord]) -> PolarsResult<DataFrame> {
    let mut rows: Vec<(&str, &crate::ingest::ContactRun)> = records
        .iter()
        .flat_map(|r| r.contacts.iter().map(move |c| (r.clip.as_str(), c)))
        .collect();
    rows.sort_by(|a, b| {
        (a.0, a.1.effector, a.1.first_frame).cmp(&(b.0, b.1.effector, b.1.first_frame))
    });
    let f = |g: &dyn Fn(&crate::ingest::ContactRun) -> f64| -> Vec<f64> {
        rows.iter().map(|(_, c)| g(c)).collect()
    };
    DataFrame::new_infer_height(vec![
        col(contacts::CLIP, rows.iter().map(|r| r.0).collect::<Vec<_>>()),
        col(
            contacts::EFFECTOR,
            rows.iter().map(|r| r.1.effector).collect::<Vec<_>>(),
        ),
        col(
            contacts::FIRST_FRAME,
            rows.iter().map(|r| r.1.first_frame).collect::<Vec<_>>(),
        ),
        col(
            contacts::LAST_FRAME,
            rows.iter().map(|r| r.1.last_frame).collect::<Vec<_>>(),
        ),
        col(
            contacts::TD_EDGE,
            rows.iter().map(|r| r.1.t_td_s).collect::<Vec<_>>(),
        ),
        col(
            contacts::LO_EDGE,
            rows.iter().map(|r| r.1.t_lo_s).collect::<Vec<_>>(),
        ),
        col(
            contacts::TD,
            rows.iter().map(|r| r.1.td_time_s).collect::<Vec<_>>(),
        ),
        col(
            contacts::LO,
            rows.iter().map(|r| r.1.lo_time_s).collect::<Vec<_>>(),
        ),
        col(
            contacts::STATIC,
            rows.iter().map(|r| r.1.is_static).collect::<Vec<_>>(),
        ),
        col(
            contacts::SPEED_LED,
            rows.iter().map(|r| r.1.speed_led).collect::<Vec<_>>(),
        ),
        col(contacts::SURFACE_Z, f(&|c| c.surface_z)),
        col(contacts::ORIGIN_X, f(&|c| c.origin[0])),
        col(contacts::ORIGIN_Y, f(&|c| c.origin[1])),
        col(contacts::ORIGIN_Z, f(&|c| c.origin[2])),
        col(contacts::YAW, f(&|c| c.yaw_rad)),
        col(contacts::NORMAL_X, f(&|c| c.normal[0])),
        col(contacts::NORMAL_Y, f(&|c| c.normal[1])),
        col(contacts::NORMAL_Z, f(&|c| c.normal[2])),
    ])
}

/// `joints.parquet` from the records that kept joint positions.
pub fn joints_table(records: &[ClipRecord]) -> PolarsResult<DataFrame> {
    let (mut clip, mut frame, mut joint) = (Vec::new(), Vec::new(), Vec::new());
    let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
    for r in records {
        let Some(fr) = &r.frames else { continue };
        let Some((names, pts)) = &fr.joints else {
            continue;
        };
        for (k, f) in fr.frame.iter().enumerate() {
            for (j, name) in names.iter().enumerate() {
                let p = pts[k * names.len() + j];
                clip.push(r.clip.as_str());
                frame.push(*f);
                joint.push(name.as_str());
                x.push(p[0]);
                y.push(p[1]);
                z.push(p[2]);
            }
        }
    }
    DataFrame::new_infer_height(vec![
        col(frames::CLIP, clip),
        col(frames::FRAME, frame),
        col(joints::JOINT, joint),
        col(joints::POSITION[0], x),
        col(joints::POSITION[1], y),
        col(joints::POSITION[2], z),
    ])
}

/// Write a table to `dir/name` atomically: a temporary file in `dir`, then a rename, so a
/// reader never sees a half-written file and an earlier file survives a failed write. The
/// layout is that of [`TableWriter`] (row groups of [`ROW_GROUP_ROWS`](crate::library::storage::stream::ROW_GROUP_ROWS) rows), so a table
/// written whole equals the same rows written in batches, byte for byte.
///
/// # Errors
/// The directory is not writable or the table cannot be encoded.
pub fn write_atomic(
    dir: &Path,
    name: &str,
    df: &mut DataFrame,
    kv: &[(String, String)],
) -> Result<()> {
    let mut w = TableWriter::create(dir, name, df)?;
    w.push(df)?;
    w.finish(kv)
}

/// The tables a `frames` run writes.
const FRAMES_RUN_FILES: [&str; 4] = [FRAMES_FILE, CLIPS_FILE, CONTACTS_FILE, JOINTS_FILE];

/// The tables of a `frames` run, written batch by batch into `dir` ([`TableWriter`]s: the
/// same bytes as one batch of every clip, when the batches come in clip order). Each table
/// replaces only the file of its own name at [`FramesWriter::finish`]; nothing else in
/// `dir` is touched, except the temporary tables (`.<table>.tmp-<pid>`) of killed runs,
/// which are removed. Dropped unfinished, it leaves the old tables as they were.
pub struct FramesWriter {
    dir: PathBuf,
    writers: Vec<(&'static str, TableWriter)>,
    joints: bool,
}

impl FramesWriter {
    /// Start the tables in `dir` (made if missing), with the joints table when `joints`.
    ///
    /// # Errors
    /// `dir` is not a folder and cannot be made one; a table's temporary file cannot be
    /// created.
    pub fn create(dir: &Path, joints: bool) -> Result<FramesWriter> {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::io(dir, "cannot create output folder", e))?;
        let scratch: Vec<String> = FRAMES_RUN_FILES
            .iter()
            .flat_map(|t| crate::library::storage::row_groups::scratch_stems(t))
            .collect();
        let mut names: Vec<&str> = FRAMES_RUN_FILES.to_vec();
        names.extend(scratch.iter().map(String::as_str));
        remove_stale(dir, &names, Scratch::Tmp);
        let mut w = FramesWriter {
            dir: dir.to_path_buf(),
            writers: Vec::new(),
            joints,
        };
        for (name, empty) in w.tables(&[])? {
            w.writers
                .push((name, TableWriter::create(dir, name, &empty)?));
        }
        Ok(w)
    }

    /// The tables of `records`, in [`FRAMES_RUN_FILES`] order (a table that cannot be
    /// built names its file).
    fn tables(&self, records: &[ClipRecord]) -> Result<Vec<(&'static str, DataFrame)>> {
        let err = |name: &str| {
            let path = self.dir.join(name);
            move |e| polars_err(&path, e)
        };
        let mut tables = vec![
            (
                FRAMES_FILE,
                frames_table(records).map_err(err(FRAMES_FILE))?,
            ),
            (CLIPS_FILE, clips_table(records).map_err(err(CLIPS_FILE))?),
            (
                CONTACTS_FILE,
                contacts_table(records).map_err(err(CONTACTS_FILE))?,
            ),
        ];
        if self.joints {
            tables.push((
                JOINTS_FILE,
                joints_table(records).map_err(err(JOINTS_FILE))?,
            ));
        }
        Ok(tables)
    }

    /// Append the rows of `records` (whole clips, after those of the batches before).
    ///
    /// # Errors
    /// A table cannot be built or written.
    pub fn push(&mut self, records: &[ClipRecord]) -> Result<()> {
        let tables = self.tables(records)?;
        // Side by side on the caller's pool (each table its own file).
        let pushed: Vec<Result<()>> = tables
            .into_par_iter()
            .zip(self.writers.par_iter_mut())
            .map(|((_, df), (_, w))| w.push(&df))
            .collect();
        pushed.into_iter().collect()
    }

    /// Write the last row groups and footers, and rename every table into place.
    ///
    /// # Errors
    /// As [`TableWriter::finish`]; the first failure in table order is reported.
    pub fn finish(self) -> Result<()> {
        let kv = vec![
            (SCHEMA_VERSION_KEY.to_string(), SCHEMA_VERSION.to_string()),
            (TOOL_VERSION_KEY.to_string(), TOOL_VERSION.to_string()),
        ];
        let finished: Vec<Result<()>> = self
            .writers
            .into_par_iter()
            .map(|(_, w)| w.finish(&kv))
            .collect();
        finished.into_iter().collect()
    }
}

/// Build and write every table of a `frames` run into `dir` in one batch (see
/// [`FramesWriter`]).
///
/// # Errors
/// As [`FramesWriter`].
pub fn write_all(dir: &Path, records: &[ClipRecord], joints: bool) -> Result<()> {
    let mut w = FramesWriter::create(dir, joints)?;
    w.push(records)?;
    w.finish()
}

#[cfg(test)]
mod base64_tests {
    #[test]
    fn base64_matches_rfc_4648_test_vectors() {
        // RFC 4648 §10.
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(
                crate::library::storage::stream::base64(plain.as_bytes()),
                coded,
                "{plain}"
            );
        }
    }
}
