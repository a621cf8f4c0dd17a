//! One clip of a library as `plot clip` shows it: COM height and speed per frame, the
//! contact flags per effector, the flights of `clips.parquet` and the clip's warnings.

use std::path::Path;

use polars::prelude::*;

/// The support effectors, in the order of the contact bars.
pub use crate::contacts::EFFECTORS;
use crate::error::{Error, Result};
use crate::library::codec::schema::{clips, flights, frames, CLIPS_FILE, FRAMES_FILE};
use crate::library::codec::table::Table;

/// One flight of `clips.parquet` (`flights`), the fields the plot uses.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightView {
    /// First and last no-contact frame (file row indices).
    pub frames: (i64, i64),
    /// Fitted free curvature `a_z`, m/s² (null when untested).
    pub a_z: Option<f64>,
    /// The ballistic test's verdict.
    pub ballistic: bool,
}

/// One clip, per kept frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClipView {
    /// Clip name.
    pub clip: String,
    /// File row index of each kept frame.
    pub frame: Vec<i64>,
    /// Clip time, s.
    pub time_s: Vec<f64>,
    /// COM height (world z), m.
    pub com_z: Vec<f64>,
    /// Horizontal COM speed `hypot(com_vx, com_vy)`, m/s.
    pub speed_xy: Vec<f64>,
    /// Per effector of [`EFFECTORS`], the contact flag per frame (null read as false).
    pub contact: [Vec<bool>; 4],
    /// The clip's flights.
    pub flights: Vec<FlightView>,
    /// The clip's warnings.
    pub warnings: Vec<String>,
}

/// Reads `clip` from the library `lib`.
///
/// # Errors
/// A missing or malformed table, or a clip the library does not hold (the error lists a
/// few clip names it does hold).
pub fn read_clip_view(lib: &Path, clip: &str) -> Result<ClipView> {
    crate::library::codec::provenance::check_layout(lib)?;
    let [vx_name, vy_name, _] = frames::COM_V;
    let mut names = vec![
        frames::CLIP,
        frames::FRAME,
        frames::TIME,
        frames::COM[2],
        vx_name,
        vy_name,
    ];
    let contact_cols: Vec<String> = EFFECTORS.iter().map(|e| frames::contact(e)).collect();
    names.extend(contact_cols.iter().map(String::as_str));
    let path = lib.join(FRAMES_FILE);
    let t = Table::open_columns(&path, &names)?;
    let clips = t.strings(frames::CLIP)?;
    let rows: Vec<usize> = (0..clips.len()).filter(|&i| clips[i] == clip).collect();
    if rows.is_empty() {
        let mut known: Vec<&String> = clips.iter().collect();
        known.dedup();
        let sample: Vec<&str> = known.iter().take(5).map(|s| s.as_str()).collect();
        return Err(Error::column(
            &path,
            frames::CLIP,
            None,
            format!("no clip '{clip}' (clips: {}, …)", sample.join(", ")),
        ));
    }
    let pick = |v: Vec<f64>| rows.iter().map(|&i| v[i]).collect::<Vec<_>>();
    let (vx, vy) = (pick(t.f64s(vx_name)?), pick(t.f64s(vy_name)?));
    let frame_all = t.i64s(frames::FRAME)?;
    let mut view = ClipView {
        clip: clip.to_string(),
        frame: rows.iter().map(|&i| frame_all[i]).collect(),
        time_s: pick(t.f64s(frames::TIME)?),
        com_z: pick(t.f64s(frames::COM[2])?),
        speed_xy: vx.iter().zip(&vy).map(|(x, y)| x.hypot(*y)).collect(),
        ..ClipView::default()
    };
    for (k, name) in contact_cols.iter().enumerate() {
        let c =
            t.df.column(name)
                .map_err(|_| Error::column(&path, name.as_str(), None, "missing"))?;
        let b = c
            .bool()
            .map_err(|_| Error::column(&path, name.as_str(), None, "expected boolean"))?;
        view.contact[k] = rows.iter().map(|&i| b.get(i).unwrap_or(false)).collect();
    }
    read_clip_row(&lib.join(CLIPS_FILE), clip, &mut view)?;
    Ok(view)
}

/// The flights and warnings of `clip` from `clips.parquet`.
fn read_clip_row(path: &Path, clip: &str, view: &mut ClipView) -> Result<()> {
    let t = Table::open_columns(path, &[clips::CLIP, clips::FLIGHTS, clips::WARNINGS])?;
    let Some(row) = t.strings(clips::CLIP)?.iter().position(|c| c == clip) else {
        return Ok(());
    };
    let bad = |col: &str, e: PolarsError| Error::column(path, col, Some(row), e.to_string());
    let list = |name: &str| -> Result<Option<Series>> {
        let c =
            t.df.column(name)
                .map_err(|_| Error::column(path, name, None, "missing"))?;
        let l = c.list().map_err(|e| bad(name, e))?;
        Ok(l.get_as_series(row))
    };
    if let Some(w) = list(clips::WARNINGS)? {
        let s = w.str().map_err(|e| bad(clips::WARNINGS, e))?;
        view.warnings = s.iter().flatten().map(str::to_string).collect();
    }
    if let Some(f) = list(clips::FLIGHTS)? {
        let st = f.struct_().map_err(|e| bad(clips::FLIGHTS, e))?;
        let field = |n: &str| st.field_by_name(n).map_err(|e| bad(clips::FLIGHTS, e));
        let (first, last) = (field(flights::FIRST_FRAME)?, field(flights::LAST_FRAME)?);
        let (a_z, ballistic) = (field(flights::A_Z)?, field(flights::BALLISTIC)?);
        let (first, last) = (
            first.i64().map_err(|e| bad(clips::FLIGHTS, e))?,
            last.i64().map_err(|e| bad(clips::FLIGHTS, e))?,
        );
        let a_z = a_z.f64().map_err(|e| bad(clips::FLIGHTS, e))?;
        let ballistic = ballistic.bool().map_err(|e| bad(clips::FLIGHTS, e))?;
        for i in 0..st.len() {
            if let (Some(a), Some(b)) = (first.get(i), last.get(i)) {
                view.flights.push(FlightView {
                    frames: (a, b),
                    a_z: a_z.get(i),
                    ballistic: ballistic.get(i).unwrap_or(false),
                });
            }
        }
    }
    Ok(())
}
