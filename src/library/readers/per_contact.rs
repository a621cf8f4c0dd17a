//! The per-contact force export (`stancelib forces --per-contact`): one clip's total
//! force m(a_COM + g) split between its contacts frame by frame
//! ([`crate::force_model::per_contact`]), with each contact's centre of pressure, as a
//! Parquet or CSV table or an OpenSim `.mot` ground-reaction file.
//!
//! Table columns ([`per_contact_columns`]): `clip`, `frame`, `time_clip_s`, `split`
//! (`none`, `single`, `transition`, `lever`, `even`), then per effector `<e>` of
//! [`crate::contacts::EFFECTORS`]: `<e>_f{x,y,z}_n` (force on the body, world Z up, N) and
//! `<e>_cop_{x,y,z}_m` (m), null where `<e>` is not in contact.
//!
//! `.mot` (OpenSim storage, Y up): a header (`name`, `version=1`, `nRows`, `nColumns`,
//! `inDegrees=yes`, `endheader`), then `time` and per contact (`r_`, `l_` for the feet;
//! `r_hand_`, `l_hand_` for a hand that touches down in the rows)
//! `ground_force_v{x,y,z}`, `ground_force_p{x,y,z}`, then `ground_torque_{x,y,z}` (zero:
//! the free moment is not estimated). A contact's columns are 0 where it is not in
//! contact. Axes: OpenSim `(x, y, z)` = the library's `(x, z, −y)`.
//!
//! # References
//! OpenSim storage (`.mot`) format and `ExternalLoads`; [`crate::force_model::per_contact`].

use std::path::Path;

use polars::prelude::*;

use crate::contacts::EFFECTORS;
use crate::error::{Error, Result};
use crate::force_model::per_contact::{
    foot_cop, heading_from_velocity, split, ContactSpan, SplitInput, SplitOptions,
};
use crate::force_model::GRAVITY;
use crate::library::codec::columns::col;
use crate::library::codec::schema::{
    clips, contacts, frames, CLIPS_FILE, CONTACTS_FILE, FRAMES_FILE,
};
use crate::library::codec::table::Table;
use crate::math::v3::V3;
use crate::skeleton::units::NOMINAL_LEG_M;

/// One clip of a library, what the split needs, per kept frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ContactClip {
    /// Clip name.
    pub clip: String,
    /// File row of each kept frame.
    pub frame: Vec<i64>,
    /// Clip time, s.
    pub time_s: Vec<f64>,
    /// Total force on the body m(a_COM + g ẑ), world, N.
    pub total: Vec<V3>,
    /// COM position, m.
    pub com: Vec<V3>,
    /// SG COM velocity, m/s.
    pub com_v: Vec<V3>,
    /// Local floor, m.
    pub ground_z: Vec<f64>,
    /// Ankle (feet) or wrist (hands) position per effector, m (`None`: no such point).
    pub point: [Vec<Option<V3>>; 4],
    /// Toe tips of the left and right foot, m.
    pub toe: [Vec<V3>; 2],
    /// Every contact of the clip, with its surface height, m.
    pub spans: Vec<(ContactSpan, f64)>,
    /// `L_leg / 0.84 m` (the clearances' scale).
    pub leg_scale: f64,
}

/// The rows of the export: per frame, the split rule and per effector its force and COP.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ContactRows {
    /// Clip name.
    pub clip: String,
    /// File row.
    pub frame: Vec<i64>,
    /// Clip time, s.
    pub time_s: Vec<f64>,
    /// `none`, `single`, `transition` or `even`.
    pub split: Vec<&'static str>,
    /// Force per effector and frame, N.
    pub force: [Vec<Option<V3>>; 4],
    /// COP per effector and frame, m.
    pub cop: [Vec<Option<V3>>; 4],
}

fn xyz(t: &Table, names: [&str; 3]) -> Result<Vec<V3>> {
    let [x, y, z] = [t.f64s(names[0])?, t.f64s(names[1])?, t.f64s(names[2])?];
    Ok((0..x.len()).map(|i| [x[i], y[i], z[i]]).collect())
}

/// Reads `clip` from the library `lib` (frames, contacts, mass and leg length). The
/// caller checks the library's layout first ([`crate::library::codec::provenance::check_layout`]; `forces`
/// does so once for either of its paths).
///
/// # Errors
/// A missing or malformed table or column (named with its file), a clip the library does
/// not hold, or a clip without a mass or leg length.
pub fn read_contact_clip(lib: &Path, clip: &str) -> Result<ContactClip> {
    let path = lib.join(FRAMES_FILE);
    let t = Table::open(&path)?;
    let names = t.strings(frames::CLIP)?;
    let rows: Vec<usize> = (0..names.len()).filter(|&i| names[i] == clip).collect();
    if rows.is_empty() {
        let mut known: Vec<&String> = names.iter().collect();
        known.dedup();
        let sample: Vec<&str> = known.iter().take(5).map(|s| s.as_str()).collect();
        let msg = format!("no clip '{clip}' (clips: {}, …)", sample.join(", "));
        return Err(Error::column(&path, frames::CLIP, None, msg));
    }
    let pick = |v: Vec<V3>| rows.iter().map(|&i| v[i]).collect::<Vec<_>>();
    let (frame, time) = (t.i64s(frames::FRAME)?, t.f64s(frames::TIME)?);
    let ground = t.f64s(frames::GROUND_Z)?;
    let acc = pick(xyz(&t, frames::COM_A)?);
    let com = pick(xyz(&t, frames::COM)?);
    let com_v = pick(xyz(&t, frames::COM_V)?);
    let pos = |p: &str| -> Result<Vec<Option<V3>>> {
        let c: Vec<Vec<Option<f64>>> = (0..3)
            .map(|a| t.opt_f64(&frames::position(p, a)))
            .collect::<Result<_>>()?;
        Ok(rows
            .iter()
            .map(|&i| match (c[0][i], c[1][i], c[2][i]) {
                (Some(x), Some(y), Some(z)) => Some([x, y, z]),
                _ => None,
            })
            .collect())
    };
    let point = [
        pos(EFFECTORS[0])?,
        pos(EFFECTORS[1])?,
        pos(EFFECTORS[2])?,
        pos(EFFECTORS[3])?,
    ];
    let toe_of = |p: &str| -> Result<Vec<V3>> {
        let names = [0, 1, 2].map(|a| frames::position(p, a));
        let v = xyz(&t, [&names[0], &names[1], &names[2]])?;
        Ok(pick(v))
    };
    let toe = [toe_of(frames::TOES[0])?, toe_of(frames::TOES[1])?];
    let (mass, leg) = clip_mass_and_leg(&lib.join(CLIPS_FILE), clip)?;
    let total = acc
        .iter()
        .map(|a| [mass * a[0], mass * a[1], mass * (a[2] + GRAVITY)])
        .collect();
    Ok(ContactClip {
        clip: clip.to_string(),
        frame: rows.iter().map(|&i| frame[i]).collect(),
        time_s: rows.iter().map(|&i| time[i]).collect(),
        total,
        com,
        com_v,
        ground_z: rows.iter().map(|&i| ground[i]).collect(),
        point,
        toe,
        spans: read_spans(&lib.join(CONTACTS_FILE), clip)?,
        leg_scale: leg / NOMINAL_LEG_M,
    })
}

fn clip_mass_and_leg(path: &Path, clip: &str) -> Result<(f64, f64)> {
    let t = Table::open_columns(path, &[clips::CLIP, clips::MASS, clips::LEG_LENGTH])?;
    let names = t.strings(clips::CLIP)?;
    let row = names
        .iter()
        .position(|c| c == clip)
        .ok_or_else(|| Error::column(path, clips::CLIP, None, format!("no clip '{clip}'")))?;
    let need = |name: &str| -> Result<f64> {
        t.opt_f64(name)?[row]
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| Error::column(path, name, Some(row), "null or not positive"))
    };
    Ok((need(clips::MASS)?, need(clips::LEG_LENGTH)?))
}

fn read_spans(path: &Path, clip: &str) -> Result<Vec<(ContactSpan, f64)>> {
    let names = [
        contacts::CLIP,
        contacts::EFFECTOR,
        contacts::TD,
        contacts::LO,
        contacts::SURFACE_Z,
    ];
    let t = Table::open_columns(path, &names)?;
    let (clips, eff) = (t.strings(contacts::CLIP)?, t.strings(contacts::EFFECTOR)?);
    let (td, lo, z) = (
        t.opt_f64(contacts::TD)?,
        t.opt_f64(contacts::LO)?,
        t.f64s(contacts::SURFACE_Z)?,
    );
    let mut out = Vec::new();
    for i in (0..clips.len()).filter(|&i| clips[i] == clip) {
        let effector = EFFECTORS.iter().position(|e| *e == eff[i]).ok_or_else(|| {
            let msg = format!("unknown effector '{}'", eff[i]);
            Error::column(path, contacts::EFFECTOR, Some(i), msg)
        })?;
        let span = ContactSpan {
            effector,
            td_s: td[i],
            lo_s: lo[i],
        };
        out.push((span, z[i]));
    }
    Ok(out)
}

/// The split of every frame of `c`, kept for the frames `first..=last` (file rows; every
/// frame when `None`).
pub fn contact_rows(
    c: &ContactClip,
    range: Option<(i64, i64)>,
    opts: &SplitOptions,
) -> ContactRows {
    let spans: Vec<ContactSpan> = c.spans.iter().map(|s| s.0).collect();
    let heading = heading_from_velocity(&c.com_v);
    // Each contact's COP at every frame it holds (the lever rule needs them).
    let cop: Vec<[Option<V3>; 4]> = (0..c.time_s.len())
        .map(|k| {
            let t = c.time_s[k];
            std::array::from_fn(|e| {
                let surface = c.spans.iter().find(|(s, _)| s.effector == e && s.holds(t));
                match (surface, c.point[e][k]) {
                    (Some(&(_, z)), Some(pt)) if e < 2 => {
                        Some(foot_cop(pt, c.toe[e][k], c.ground_z[k], z, c.leg_scale))
                    }
                    (Some(&(_, z)), Some(pt)) => Some([pt[0], pt[1], z]),
                    _ => None,
                }
            })
        })
        .collect();
    let input = SplitInput {
        time_s: &c.time_s,
        total: &c.total,
        heading: &heading,
        com: &c.com,
        cop: &cop,
    };
    let parts = split(&input, &spans, opts);
    let mut out = ContactRows {
        clip: c.clip.clone(),
        ..Default::default()
    };
    for (k, p) in parts.iter().enumerate() {
        if range.is_some_and(|(a, b)| c.frame[k] < a || c.frame[k] > b) {
            continue;
        }
        out.frame.push(c.frame[k]);
        out.time_s.push(c.time_s[k]);
        out.split.push(p.rule.as_str());
        for (e, c) in cop[k].iter().enumerate() {
            out.force[e].push(p.force[e]);
            out.cop[e].push(p.force[e].and(*c));
        }
    }
    out
}

/// Column names of the table, in order.
pub fn per_contact_columns() -> Vec<String> {
    let mut v: Vec<String> = ["clip", "frame", "time_clip_s", "split"]
        .map(String::from)
        .to_vec();
    for e in EFFECTORS {
        for a in ["x", "y", "z"] {
            v.push(format!("{e}_f{a}_n"));
        }
        for a in ["x", "y", "z"] {
            v.push(format!("{e}_cop_{a}_m"));
        }
    }
    v
}

/// The rows as a table (columns [`per_contact_columns`]).
///
/// # Errors
/// A column cannot be built.
pub fn per_contact_table(r: &ContactRows) -> PolarsResult<DataFrame> {
    let names = per_contact_columns();
    let mut cols = vec![
        col(&names[0], vec![r.clip.as_str(); r.frame.len()]),
        col(&names[1], r.frame.clone()),
        col(&names[2], r.time_s.clone()),
        col(&names[3], r.split.clone()),
    ];
    let mut n = 4;
    for e in 0..4 {
        for v in [&r.force[e], &r.cop[e]] {
            for a in 0..3 {
                let x: Vec<Option<f64>> = v.iter().map(|p| p.map(|p| p[a])).collect();
                cols.push(col(&names[n], x));
                n += 1;
            }
        }
    }
    DataFrame::new_infer_height(cols)
}

fn num(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| format!("{x:.6}"))
}

/// A CSV field quoted as RFC 4180 asks: in double quotes (each inner quote doubled) when
/// it holds a comma, a quote, CR or LF; as it is otherwise.
pub fn csv_field(v: &str) -> std::borrow::Cow<'_, str> {
    if v.contains([',', '"', '\r', '\n']) {
        format!("\"{}\"", v.replace('"', "\"\"")).into()
    } else {
        v.into()
    }
}

/// The rows as CSV text (header [`per_contact_columns`]; empty cells for nulls; six
/// decimals; text fields quoted per RFC 4180 where they need it, [`csv_field`]).
pub fn per_contact_csv(r: &ContactRows) -> String {
    let mut s = per_contact_columns().join(",");
    s.push('\n');
    let clip = csv_field(&r.clip);
    for k in 0..r.frame.len() {
        let mut line = format!(
            "{},{},{:.6},{}",
            clip,
            r.frame[k],
            r.time_s[k],
            csv_field(r.split[k])
        );
        for e in 0..4 {
            for v in [&r.force[e], &r.cop[e]] {
                for a in 0..3 {
                    line.push(',');
                    line.push_str(&num(v[k].map(|p| p[a])));
                }
            }
        }
        s.push_str(&line);
        s.push('\n');
    }
    s
}

/// OpenSim axes (Y up) of a Z-up world vector: `(x, z, −y)` (a zero stays `0`, not `-0`).
pub fn opensim_axes(v: V3) -> V3 {
    [v[0] + 0.0, v[2] + 0.0, 0.0 - v[1]]
}

/// The rows as an OpenSim `.mot` file named `name` (see the module docs).
pub fn per_contact_mot(r: &ContactRows, name: &str) -> String {
    // Feet always; a hand when it touches down in the rows.
    let prefixes = ["l_", "r_", "l_hand_", "r_hand_"];
    let used: Vec<usize> = (0..4)
        .filter(|&e| e < 2 || r.force[e].iter().any(Option::is_some))
        .collect();
    let mut head = vec!["time".to_string()];
    for &e in &used {
        for q in ["vx", "vy", "vz", "px", "py", "pz"] {
            head.push(format!("{}ground_force_{q}", prefixes[e]));
        }
    }
    for &e in &used {
        for q in ["x", "y", "z"] {
            head.push(format!("{}ground_torque_{q}", prefixes[e]));
        }
    }
    let mut s = format!(
        "{name}\nversion=1\nnRows={}\nnColumns={}\ninDegrees=yes\nendheader\n{}\n",
        r.frame.len(),
        head.len(),
        head.join("\t")
    );
    for k in 0..r.frame.len() {
        let mut line = format!("{:.6}", r.time_s[k]);
        for &e in &used {
            let f = opensim_axes(r.force[e][k].unwrap_or([0.0; 3]));
            let p = r.cop[e][k].map_or([0.0; 3], opensim_axes);
            for v in f.iter().chain(&p) {
                line.push_str(&format!("\t{v:.6}"));
            }
        }
        for _ in 0..3 * used.len() {
            line.push_str("\t0.000000");
        }
        s.push_str(&line);
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> ContactRows {
        ContactRows {
            clip: "c".into(),
            frame: vec![3, 4],
            time_s: vec![0.03, 0.04],
            split: vec!["single", "none"],
            force: [
                vec![Some([1.0, 2.0, 3.0]), None],
                vec![None, None],
                vec![None, None],
                vec![None, None],
            ],
            cop: [
                vec![Some([0.5, -0.25, 0.0]), None],
                vec![None, None],
                vec![None, None],
                vec![None, None],
            ],
        }
    }

    #[test]
    fn the_mot_file_has_the_opensim_header_and_y_up() {
        let m = per_contact_mot(&rows(), "walk");
        let lines: Vec<&str> = m.lines().collect();
        assert_eq!(
            &lines[..6],
            &[
                "walk",
                "version=1",
                "nRows=2",
                "nColumns=19",
                "inDegrees=yes",
                "endheader"
            ]
        );
        let head: Vec<&str> = lines[6].split('\t').collect();
        assert_eq!(head.len(), 19);
        assert_eq!(
            &head[..4],
            &[
                "time",
                "l_ground_force_vx",
                "l_ground_force_vy",
                "l_ground_force_vz"
            ]
        );
        assert_eq!(head[7], "r_ground_force_vx");
        assert_eq!(head[13], "l_ground_torque_x");
        let row: Vec<f64> = lines[7].split('\t').map(|v| v.parse().unwrap()).collect();
        // Force (1, 2, 3) Z up → (1, 3, −2) Y up; COP (0.5, −0.25, 0) → (0.5, 0, 0.25).
        assert_eq!(&row[..7], &[0.03, 1.0, 3.0, -2.0, 0.5, 0.0, 0.25]);
        assert!(row[7..].iter().all(|v| *v == 0.0));
        assert!(!m.contains("-0.000000"), "{m}");
    }

    #[test]
    fn the_csv_leaves_nulls_empty() {
        let c = per_contact_csv(&rows());
        let lines: Vec<&str> = c.lines().collect();
        assert_eq!(lines[0].split(',').count(), per_contact_columns().len());
        assert!(lines[1].starts_with("c,3,0.030000,single,1.000000,2.000000,3.000000,0.500000"));
        assert!(lines[2].ends_with(",,,"));
        let df = per_contact_table(&rows()).unwrap();
        assert_eq!(df.width(), per_contact_columns().len());
    }

    // See: issue 39 item 3 review — "CSV output does not quote fields": a clip named
    // `walk,"1"` gave rows of 53 fields under a 52-column header.
    #[test]
    fn the_csv_quotes_a_clip_name_with_a_comma_or_quote() {
        let mut r = rows();
        r.clip = "walk,\"1\"".into();
        let c = per_contact_csv(&r);
        let line = c.lines().nth(1).unwrap();
        assert!(
            line.starts_with("\"walk,\"\"1\"\"\",3,0.030000,single,"),
            "{line}"
        );
        // Unquoted, the fields are the header's.
        let unquoted = line.replacen("\"walk,\"\"1\"\"\"", "w", 1);
        assert_eq!(unquoted.split(',').count(), per_contact_columns().len());
        assert_eq!(csv_field("a\nb"), "\"a\nb\"");
        assert_eq!(csv_field("a\rb"), "\"a\rb\"");
        assert_eq!(csv_field("plain"), "plain");
        let df = per_contact_table(&rows()).unwrap();
        assert_eq!(df.width(), per_contact_columns().len());
        assert_eq!(df.height(), 2);
    }
}
