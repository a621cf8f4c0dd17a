//! The force export (`stancelib forces`) and what the per-stance plot reads from a library:
//! stances with their clip times and heading, a clip's frames in a time window, and its
//! up axis.
//!
//! The export has one row per stance and sample of the stance's evaluation grid, sorted
//! by `stance_id`, then `tau` (columns [`FORCES_COLUMNS`]; forces in N, times in s):
//!
//! ```text
//! stance_id, tau, time_clip_s = td_clip_s + tau·dt_s,
//! f_h_n, f_p_n, f_v_n   (stance axes)     fx_n, fy_n, fz_n   (world, Z up)
//! ```
//!
//! # References
//! spec stance-model §4.3 (grid), §11 (stance columns); [`crate::force_model::export`].

use std::collections::BTreeSet;
use std::path::Path;

use polars::prelude::*;

use super::read::read_stances;
use crate::error::{Error, Result};
use crate::force_model::export::{sample_forces, StanceTimes};
use crate::library::codec::columns::col;
use crate::library::codec::schema::{clips, frames, stances};
use crate::library::codec::stances::PoolStance;
use crate::library::codec::table::Table;
use crate::skeleton::units::UpAxis;
use crate::stances::params::{Heading, HeadingFrom};

/// Columns of the force export, in order.
pub const FORCES_COLUMNS: [&str; 9] = [
    "stance_id",
    "tau",
    "time_clip_s",
    "f_h_n",
    "f_p_n",
    "f_v_n",
    "fx_n",
    "fy_n",
    "fz_n",
];

/// A stance row with what the force export and the stance plot need beyond the queries'
/// view: clip times, last frame and heading.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceStance {
    /// The row as the queries read it (model, ids, label, coefficients).
    pub stance: PoolStance,
    /// `td_clip_s` and `dt_s`.
    pub times: StanceTimes,
    /// Liftoff in clip time `lo_clip_s`, s.
    pub lo_clip_s: f64,
    /// Last stance frame (file row).
    pub last_frame: i64,
    /// The stance frame (`heading_x`, `heading_y`, `heading_from`).
    pub heading: Heading,
}

const HEADING_SOURCES: [HeadingFrom; 4] = [
    HeadingFrom::Velocity,
    HeadingFrom::Hips,
    HeadingFrom::Previous,
    HeadingFrom::WorldX,
];

/// Reads `stances.parquet` with the queries' reader plus the clip-time and heading columns.
///
/// # Errors
/// As [`read_stances`]; a missing, mistyped or null `td_clip_s`, `lo_clip_s`, `dt_s`,
/// `last_frame`, `heading_x`, `heading_y` or `heading_from`, or an unknown heading source
/// (the error names the file, column and row).
pub fn read_force_stances(path: &Path) -> Result<Vec<ForceStance>> {
    let pool = read_stances(path)?;
    let t = Table::open(path)?;
    let ids = t.strings(stances::STANCE_ID)?;
    let (td, lo, dt) = (
        t.f64s(stances::TD_CLIP)?,
        t.f64s(stances::LO_CLIP)?,
        t.f64s(stances::DT)?,
    );
    let (hx, hy) = (t.f64s(stances::HEADING_X)?, t.f64s(stances::HEADING_Y)?);
    let (from, last) = (
        t.strings(stances::HEADING_FROM)?,
        t.i64s(stances::LAST_FRAME)?,
    );
    pool.into_iter()
        .enumerate()
        .map(|(i, stance)| {
            if ids.get(i) != Some(&stance.stance_id) {
                return Err(Error::column(
                    path,
                    stances::STANCE_ID,
                    Some(i),
                    "rows out of step",
                ));
            }
            let from = HEADING_SOURCES
                .into_iter()
                .find(|h| h.as_str() == from[i])
                .ok_or_else(|| {
                    let msg = format!("unknown heading source '{}'", from[i]);
                    Error::column(path, stances::HEADING_FROM, Some(i), msg)
                })?;
            Ok(ForceStance {
                stance,
                times: StanceTimes {
                    td_clip_s: td[i],
                    dt_s: dt[i],
                },
                lo_clip_s: lo[i],
                last_frame: last[i],
                heading: Heading {
                    e_h: [hx[i], hy[i], 0.0],
                    from,
                },
            })
        })
        .collect()
}

/// The stances named by `ids` (each once, in `stance_id` order), or every stance when
/// `ids` is empty.
///
/// # Errors
/// An id the library does not hold: the error names it and `path` (the stance table).
pub fn select_stances<'a>(
    path: &Path,
    stances: &'a [ForceStance],
    ids: &[String],
) -> Result<Vec<&'a ForceStance>> {
    let mut out: Vec<&ForceStance> = if ids.is_empty() {
        stances.iter().collect()
    } else {
        let wanted: BTreeSet<&str> = ids.iter().map(String::as_str).collect();
        let mut found = Vec::with_capacity(wanted.len());
        for id in wanted {
            let s = stances
                .iter()
                .find(|s| s.stance.stance_id == id)
                .ok_or_else(|| {
                    let held = stances.iter().map(|s| s.stance.stance_id.as_str());
                    let msg = crate::stances::ids::unknown_stance_message(id, held);
                    Error::column(path, stances::STANCE_ID, None, msg)
                })?;
            found.push(s);
        }
        found
    };
    out.sort_by(|a, b| a.stance.stance_id.cmp(&b.stance.stance_id));
    Ok(out)
}

/// The force export of `stances` (one row per stance and grid sample), sorted by
/// `stance_id`, then `tau`.
///
/// # Errors
/// A column cannot be built.
pub fn forces_table(stances: &[&ForceStance]) -> PolarsResult<DataFrame> {
    let mut order: Vec<&ForceStance> = stances.to_vec();
    order.sort_by(|a, b| a.stance.stance_id.cmp(&b.stance.stance_id));
    let mut id = Vec::new();
    let (mut tau, mut time) = (Vec::new(), Vec::new());
    let mut f: [Vec<f64>; 6] = Default::default();
    for s in order {
        for r in sample_forces(&s.stance.model, s.times, &s.heading) {
            id.push(s.stance.stance_id.as_str());
            tau.push(r.tau);
            time.push(r.time_s);
            for (k, v) in r.f_stance.iter().chain(&r.f_world).enumerate() {
                f[k].push(*v);
            }
        }
    }
    let [f_h, f_p, f_v, fx, fy, fz] = f;
    let n = FORCES_COLUMNS;
    DataFrame::new_infer_height(vec![
        col(n[0], id),
        col(n[1], tau),
        col(n[2], time),
        col(n[3], f_h),
        col(n[4], f_p),
        col(n[5], f_v),
        col(n[6], fx),
        col(n[7], fy),
        col(n[8], fz),
    ])
}

/// A clip's COM accelerations in a time window, from `frames.parquet`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClipAccelerations {
    /// Clip time of each frame, s (increasing).
    pub time_s: Vec<f64>,
    /// `(com_ax, com_ay, com_az)`, world m/s² (Z up).
    pub com_a: Vec<[f64; 3]>,
}

/// The frames of `clip` with `t0 ≤ time_clip_s ≤ t1` (file order, which is frame order).
///
/// # Errors
/// The file cannot be read, or `clip`, `time_clip_s` or a `com_a*` column is missing, mistyped
/// or null.
pub fn read_clip_accelerations(
    path: &Path,
    clip: &str,
    t0: f64,
    t1: f64,
) -> Result<ClipAccelerations> {
    let [nx, ny, nz] = frames::COM_A;
    let names = [frames::CLIP, frames::TIME, nx, ny, nz];
    let t = Table::open_columns(path, &names)?;
    let (clips, time_s) = (t.strings(frames::CLIP)?, t.f64s(frames::TIME)?);
    let (ax, ay, az) = (t.f64s(nx)?, t.f64s(ny)?, t.f64s(nz)?);
    let keep =
        (0..time_s.len()).filter(|&i| clips[i] == clip && time_s[i] >= t0 && time_s[i] <= t1);
    let mut out = ClipAccelerations::default();
    for i in keep {
        out.time_s.push(time_s[i]);
        out.com_a.push([ax[i], ay[i], az[i]]);
    }
    Ok(out)
}

/// The up axis of `clip`'s file (`up_axis` of `clips.parquet`).
///
/// # Errors
/// The file cannot be read, the clip is absent, or its `up_axis` is null or unknown.
pub fn read_up_axis(path: &Path, clip: &str) -> Result<UpAxis> {
    let t = Table::open(path)?;
    let clips = t.strings(clips::CLIP)?;
    let row = clips
        .iter()
        .position(|c| c == clip)
        .ok_or_else(|| Error::column(path, clips::CLIP, None, format!("no clip '{clip}'")))?;
    let value =
        t.df.column(clips::UP_AXIS)
            .ok()
            .and_then(|c| c.str().ok().and_then(|s| s.get(row).map(str::to_string)));
    value.as_deref().and_then(UpAxis::parse).ok_or_else(|| {
        let found = value.unwrap_or_else(|| "null".into());
        let msg = format!("expected +X … −Z, found '{found}'");
        Error::column(path, clips::UP_AXIS, Some(row), msg)
    })
}
