//! `stances.parquet` and `errors.parquet` (spec stance-model §11): the stance table's writer
//! ([`stances_table`]) and reader ([`read_stances`]) side by side.
//!
//! Stance rows are sorted by (`clip`, `first_frame`, `label`); the force model is stored as
//! parallel list columns per stance axis (`harmonic_*`, `amp_*`, `phase_*`: the Fourier
//! model) and a power-basis list `poly_*` (the ratio model), from which
//!
//! ```text
//! τ = (t − td_clip_s)/dt_s,
//! f_a(t) = c0_a + Σ_i amp_a[i]·cos(2π·harmonic_a[i]·τ + phase_a[i]) + Σ_k poly_a[k]·τ^k
//! ```
//! rebuilds the applied force (N) on stance axis `a` for 0 ≤ τ ≤ 1 (0 outside). The
//! `force_model` column says which model the row holds (`ratio` or `fourier`); `ratio_h`,
//! `ratio_p` are the ratio model's `q_h`, `q_p` (power basis, `f_h = f_v·q_h`).

use std::collections::BTreeMap;
use std::path::Path;

use polars::prelude::*;

use super::columns::{col, list_col};
use super::read::Table;
use crate::constraints::Coefficients;
use crate::error::{Error, Result};
use crate::force_model::{AxisModel, ForceModel};
use crate::stances::params::StanceParams;
use crate::stances::segment::Boundary;
use crate::stances::{FlightRef, Stance};

fn flight_dtype() -> DataType {
    let f = |n: &str, t: DataType| Field::new(n.into(), t);
    DataType::Struct(vec![
        f("first_frame", DataType::Int64),
        f("last_frame", DataType::Int64),
        f("n_int", DataType::Int64),
        f("free", DataType::Boolean),
        f("a_z", DataType::Float64),
        f("vel", DataType::List(Box::new(DataType::Float64))),
    ])
}

/// A nullable struct column of adjacent-flight fits.
fn flight_col(name: &str, rows: Vec<Option<&FlightRef>>) -> PolarsResult<Column> {
    let len = rows.len();
    let get = |g: &dyn Fn(&FlightRef) -> f64| -> Vec<Option<f64>> {
        rows.iter().map(|r| r.map(g)).collect()
    };
    let geti = |g: &dyn Fn(&FlightRef) -> i64| -> Vec<Option<i64>> {
        rows.iter().map(|r| r.map(g)).collect()
    };
    let vel: ListChunked = rows
        .iter()
        .map(|r| {
            r.and_then(|f| f.vel)
                .map(|v| Series::new("".into(), v.to_vec()))
        })
        .collect();
    let fields = [
        Series::new("first_frame".into(), geti(&|f| f.first_frame)),
        Series::new("last_frame".into(), geti(&|f| f.last_frame)),
        Series::new("n_int".into(), geti(&|f| f.n_int)),
        Series::new(
            "free".into(),
            rows.iter().map(|r| r.map(|f| f.free)).collect::<Vec<_>>(),
        ),
        Series::new("a_z".into(), get(&|f| f.a_z)),
        vel.into_series()
            .cast(&DataType::List(Box::new(DataType::Float64)))?
            .with_name("vel".into()),
    ];
    let validity: Vec<bool> = rows.iter().map(Option::is_some).collect();
    let s = StructChunked::from_series(name.into(), len, fields.iter())?
        .with_outer_validity(Some(validity.into_iter().collect()));
    Ok(s.into_series().cast(&flight_dtype())?.into())
}

/// The stance table (rows must already be sorted).
pub fn stances_table(rows: &[Stance]) -> PolarsResult<DataFrame> {
    let mut cols = identity_columns(rows)?;
    cols.extend(model_columns(rows)?);
    cols.extend(coefficient_columns(rows)?);
    DataFrame::new_infer_height(cols)
}

/// Stance axes in column-name order (`_h`, `_p`, `_v`).
const AXES: [&str; 3] = ["h", "p", "v"];

/// Ids, frames, times, boundaries, adjacent flights, heading and the parameters (`stance_id`
/// … `mass_kg`).
fn identity_columns(rows: &[Stance]) -> PolarsResult<Vec<Column>> {
    let f = |g: &dyn Fn(&Stance) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let s = |g: &dyn Fn(&Stance) -> String| -> Vec<String> { rows.iter().map(g).collect() };
    Ok(vec![
        col("stance_id", s(&|r| r.stance_id.clone())),
        col("clip", s(&|r| r.clip.clone())),
        col("character_id", s(&|r| r.character_id.clone())),
        col("label", s(&|r| r.label.clone())),
        list_col(
            "effectors",
            rows.iter().map(|r| r.effectors.clone()).collect(),
            DataType::String,
        )?,
        col(
            "first_frame",
            rows.iter().map(|r| r.first_frame).collect::<Vec<_>>(),
        ),
        col(
            "last_frame",
            rows.iter().map(|r| r.last_frame).collect::<Vec<_>>(),
        ),
        col("td_clip_s", f(&|r| r.td_clip_s)),
        col("lo_clip_s", f(&|r| r.lo_clip_s)),
        col("t_td_s", f(&|r| r.params.t_td)),
        col("t_lo_s", f(&|r| r.params.t_lo)),
        col("t_e_s", f(&|r| r.params.t_e)),
        col("dt_s", f(&|r| r.dt_s)),
        col(
            "boundary_start",
            s(&|r| r.boundary_start.as_str().to_string()),
        ),
        col("boundary_end", s(&|r| r.boundary_end.as_str().to_string())),
        col(
            "rest_at_edge",
            rows.iter().map(|r| r.rest_at_edge).collect::<Vec<_>>(),
        ),
        flight_col(
            "flight_before",
            rows.iter().map(|r| r.flight_before.as_ref()).collect(),
        )?,
        flight_col(
            "flight_after",
            rows.iter().map(|r| r.flight_after.as_ref()).collect(),
        )?,
        col("heading_x", f(&|r| r.heading.e_h[0])),
        col("heading_y", f(&|r| r.heading.e_h[1])),
        col("heading_from", s(&|r| r.heading.from.as_str().to_string())),
        col("z_c", f(&|r| r.z_c)),
        col("zs", f(&|r| r.params.zs)),
        col("vs", f(&|r| r.params.vs)),
        col("ze", f(&|r| r.params.ze)),
        col("ve", f(&|r| r.params.ve)),
        col("vp", f(&|r| r.params.vp)),
        col("x", f(&|r| r.params.x)),
        col("vps", f(&|r| r.params.vps)),
        col("z_td", f(&|r| r.params.z_td)),
        col("z_lo", f(&|r| r.params.z_lo)),
        col("ze_measured", f(&|r| r.measured.ze)),
        col("ve_measured", f(&|r| r.measured.ve)),
        col("vp_measured", f(&|r| r.measured.vp)),
        col("x_measured", f(&|r| r.measured.x)),
        col("mass_kg", f(&|r| r.mass_kg)),
    ])
}

/// The force model per stance axis and its impulses (`c0_*` … `s_bar_*`).
fn model_columns(rows: &[Stance]) -> PolarsResult<Vec<Column>> {
    let f = |g: &dyn Fn(&Stance) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let mut cols = Vec::new();
    for (a, name) in AXES.iter().enumerate() {
        cols.push(col(&format!("c0_{name}"), f(&|r| r.model.axes[a].c0)));
    }
    for (a, name) in AXES.iter().enumerate() {
        let h: Vec<Vec<i32>> = rows
            .iter()
            .map(|r| {
                r.model.axes[a]
                    .harmonics
                    .iter()
                    .map(|&j| j as i32)
                    .collect()
            })
            .collect();
        cols.push(list_col(&format!("harmonic_{name}"), h, DataType::Int32)?);
    }
    let axis_list =
        |prefix: &str, g: &dyn Fn(&AxisModel) -> Vec<f64>| -> PolarsResult<Vec<Column>> {
            AXES.iter()
                .enumerate()
                .map(|(a, name)| {
                    list_col(
                        &format!("{prefix}_{name}"),
                        rows.iter().map(|r| g(&r.model.axes[a])).collect(),
                        DataType::Float64,
                    )
                })
                .collect()
        };
    cols.extend(axis_list("amp", &|m| m.amps.clone())?);
    cols.extend(axis_list("phase", &|m| m.phases.clone())?);
    for (a, name) in AXES.iter().enumerate() {
        cols.push(col(
            &format!("fit_rms_{name}"),
            f(&|r| r.model.axes[a].fit_rms),
        ));
    }
    cols.extend(axis_list("poly", &|m| m.poly.clone())?);
    for (q, name) in ["h", "p"].iter().enumerate() {
        cols.push(list_col(
            &format!("ratio_{name}"),
            rows.iter().map(|r| r.ratio[q].clone()).collect(),
            DataType::Float64,
        )?);
    }
    cols.push(col(
        "force_model",
        rows.iter()
            .map(|r| r.force_model.name())
            .collect::<Vec<_>>(),
    ));
    for (q, get) in [("j", 0usize), ("k", 1)] {
        for (a, name) in AXES.iter().enumerate() {
            cols.push(col(
                &format!("{q}_{name}"),
                f(&|r| {
                    if get == 0 {
                        r.model.j()[a]
                    } else {
                        r.model.k()[a]
                    }
                }),
            ));
        }
    }
    for (a, name) in AXES.iter().enumerate() {
        let v: Vec<Option<f64>> = rows
            .iter()
            .map(|r| {
                let (j, k) = (r.model.j()[a], r.model.k()[a]);
                (j != 0.0).then(|| k / j)
            })
            .collect();
        cols.push(col(&format!("s_bar_{name}"), v));
    }
    Ok(cols)
}

/// The stored coefficients and original extremes (`support_ok` … `warnings`, §7.2).
fn coefficient_columns(rows: &[Stance]) -> PolarsResult<Vec<Column>> {
    let f = |g: &dyn Fn(&Stance) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let l = |name: &str, g: &dyn Fn(&Coefficients) -> Vec<f64>| -> PolarsResult<Column> {
        list_col(
            name,
            rows.iter().map(|r| g(&r.coef)).collect(),
            DataType::Float64,
        )
    };
    Ok(vec![
        col(
            "support_ok",
            rows.iter().map(|r| r.coef.support_ok).collect::<Vec<_>>(),
        ),
        col(
            "unilateral_ok",
            rows.iter()
                .map(|r| r.coef.unilateral_ok)
                .collect::<Vec<_>>(),
        ),
        col("min_f_v", f(&|r| r.coef.min_f_v)),
        l("a_f", &|c| c.a_f.to_vec())?,
        l("a_mu", &|c| c.a_mu.to_vec())?,
        col("f_peak", f(&|r| r.coef.f_peak)),
        col("mu_req", f(&|r| r.coef.mu_req)),
        col("mu_req_robust", f(&|r| r.coef.mu_req_robust)),
        col("ext_min", f(&|r| r.coef.ext_min)),
        col("ext_max", f(&|r| r.coef.ext_max)),
        col("cp_h", f(&|r| r.cp[0])),
        col("cp_p", f(&|r| r.cp[1])),
        l("ang_impulse", &|c| c.ang_impulse.to_vec())?,
        l("ang_impulse_h0", &|c| c.ang_impulse_h0.to_vec())?,
        l("ell_r_min", &|c| c.ell_r_min.to_vec())?,
        l("ell_r_max", &|c| c.ell_r_max.to_vec())?,
        l("ell_s_min", &|c| c.ell_s_min.to_vec())?,
        l("ell_s_max", &|c| c.ell_s_max.to_vec())?,
        list_col(
            "warnings",
            rows.iter().map(|r| r.warnings.clone()).collect(),
            DataType::String,
        )?,
    ])
}

// ---- Reading `stances.parquet` back ----

/// One `stances.parquet` row as read back: what the queries, the force export and the
/// editor use of a stance (the query pool's stance, [`crate::query::pool`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PoolStance {
    /// `<clip>:<label>:<first frame>`.
    pub stance_id: String,
    /// Clip name.
    pub clip: String,
    /// Character id (§11).
    pub character_id: String,
    /// `L`, `R`, `LR`, …
    pub label: String,
    /// First stance frame (file row).
    pub first_frame: i64,
    /// What precedes the stance.
    pub boundary_start: Boundary,
    /// What follows the stance.
    pub boundary_end: Boundary,
    /// Contact height `z_c`, m.
    pub z_c: f64,
    /// Model-consistent parameters (§3).
    pub params: StanceParams,
    /// The force model (stance axes).
    pub model: ForceModel,
    /// Data contact point `(cp_h, cp_p)`, m.
    pub cp: [f64; 2],
    /// Stored coefficients and original extremes (§7.2).
    pub coef: Coefficients,
}

fn boundary(t: &Table, name: &str, row: usize, v: &str) -> Result<Boundary> {
    Boundary::parse(v).ok_or_else(|| {
        Error::column(
            &t.path,
            name,
            Some(row),
            format!("unknown boundary kind '{v}'"),
        )
    })
}

fn fixed<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut out = [0.0; N];
    out.copy_from_slice(&v[..N]);
    out
}

/// One stance axis's model columns: `c0_*`, `harmonic_*`, `amp_*`, `phase_*`, `fit_rms_*`,
/// `poly_*`.
type AxisColumns = (
    Vec<f64>,
    Vec<Vec<i32>>,
    Vec<Vec<f64>>,
    Vec<Vec<f64>>,
    Vec<f64>,
    Vec<Vec<f64>>,
);

/// The force model of row `i` from one axis's columns.
fn axis_model(t: &Table, name: &str, i: usize, cols: &AxisColumns) -> Result<AxisModel> {
    let (c0, h, a, p, rms, poly) = cols;
    if h[i].len() != a[i].len() || h[i].len() != p[i].len() {
        return Err(Error::column(
            &t.path,
            &format!("harmonic_{name}"),
            Some(i),
            "harmonic, amp and phase lists differ in length",
        ));
    }
    let harmonics = h[i]
        .iter()
        .map(|&j| u32::try_from(j).ok().filter(|&j| j >= 1))
        .collect::<Option<Vec<u32>>>()
        .ok_or_else(|| {
            Error::column(
                &t.path,
                &format!("harmonic_{name}"),
                Some(i),
                "harmonics must be integers ≥ 1",
            )
        })?;
    Ok(AxisModel {
        c0: c0[i],
        harmonics,
        amps: a[i].clone(),
        phases: p[i].clone(),
        poly: poly[i].clone(),
        fit_rms: rms[i],
    })
}

/// The float64 columns of a stance row the reader needs, besides the axis models.
const SCALAR_COLUMNS: [&str; 23] = [
    "z_c",
    "zs",
    "vs",
    "ze",
    "ve",
    "vp",
    "vps",
    "x",
    "z_td",
    "z_lo",
    "t_td_s",
    "t_lo_s",
    "t_e_s",
    "dt_s",
    "mass_kg",
    "cp_h",
    "cp_p",
    "min_f_v",
    "f_peak",
    "mu_req",
    "mu_req_robust",
    "ext_min",
    "ext_max",
];

/// Every column [`read_stances`] uses, decoded and checked (types, nulls, list lengths).
struct StanceColumns {
    ids: Vec<String>,
    clips: Vec<String>,
    chars: Vec<String>,
    labels: Vec<String>,
    boundaries: [Vec<String>; 2],
    first: Vec<i64>,
    scalars: BTreeMap<&'static str, Vec<f64>>,
    axes: Vec<AxisColumns>,
    /// `a_f`, `a_mu`, `ang_impulse`, `ang_impulse_h0`, `ell_r_min`, `ell_r_max`,
    /// `ell_s_min`, `ell_s_max`.
    lists: [Vec<Vec<f64>>; 8],
    support: Vec<bool>,
    unilateral: Vec<bool>,
}

impl StanceColumns {
    fn decode(t: &Table) -> Result<Self> {
        let s = |n: &str| t.strings(n);
        let f = |n: &str| t.f64s(n);
        let l3 = |n: &str| t.f64_lists(n, Some(3));
        Ok(StanceColumns {
            ids: s("stance_id")?,
            clips: s("clip")?,
            chars: s("character_id")?,
            labels: s("label")?,
            boundaries: [s("boundary_start")?, s("boundary_end")?],
            first: t.i64s("first_frame")?,
            // Field initialisers run in order: the first bad column of the file's order
            // is the one reported.
            scalars: SCALAR_COLUMNS
                .iter()
                .map(|&n| Ok((n, f(n)?)))
                .collect::<Result<_>>()?,
            axes: AXES
                .map(|a| {
                    Ok((
                        f(&format!("c0_{a}"))?,
                        t.i32_lists(&format!("harmonic_{a}"))?,
                        t.f64_lists(&format!("amp_{a}"), None)?,
                        t.f64_lists(&format!("phase_{a}"), None)?,
                        f(&format!("fit_rms_{a}"))?,
                        t.f64_lists(&format!("poly_{a}"), None)?,
                    ))
                })
                .into_iter()
                .collect::<Result<Vec<AxisColumns>>>()?,
            lists: [
                l3("a_f")?,
                t.f64_lists("a_mu", Some(2))?,
                l3("ang_impulse")?,
                l3("ang_impulse_h0")?,
                l3("ell_r_min")?,
                l3("ell_r_max")?,
                l3("ell_s_min")?,
                l3("ell_s_max")?,
            ],
            support: t.bools("support_ok")?,
            unilateral: t.bools("unilateral_ok")?,
        })
    }

    fn v(&self, name: &str, i: usize) -> f64 {
        self.scalars[name][i]
    }

    fn params(&self, i: usize) -> StanceParams {
        let v = |n: &str| self.v(n, i);
        StanceParams {
            zs: v("zs"),
            vs: v("vs"),
            ze: v("ze"),
            ve: v("ve"),
            vp: v("vp"),
            vps: v("vps"),
            x: v("x"),
            z_td: v("z_td"),
            z_lo: v("z_lo"),
            t_td: v("t_td_s"),
            t_lo: v("t_lo_s"),
            t_e: v("t_e_s"),
        }
    }

    fn coefficients(&self, i: usize) -> Coefficients {
        let v = |n: &str| self.v(n, i);
        let [a_f, a_mu, ang, h0, r0, r1, s0, s1] = &self.lists;
        Coefficients {
            a_f: fixed(&a_f[i]),
            a_mu: fixed(&a_mu[i]),
            min_f_v: v("min_f_v"),
            unilateral_ok: self.unilateral[i],
            support_ok: self.support[i],
            f_peak: v("f_peak"),
            mu_req: v("mu_req"),
            mu_req_robust: v("mu_req_robust"),
            ext_min: v("ext_min"),
            ext_max: v("ext_max"),
            ang_impulse: fixed(&ang[i]),
            ang_impulse_h0: fixed(&h0[i]),
            ell_r_min: fixed(&r0[i]),
            ell_r_max: fixed(&r1[i]),
            ell_s_min: fixed(&s0[i]),
            ell_s_max: fixed(&s1[i]),
        }
    }

    fn row(&self, t: &Table, i: usize) -> Result<PoolStance> {
        let mut axes: [AxisModel; 3] = Default::default();
        for (a, name) in AXES.iter().enumerate() {
            axes[a] = axis_model(t, name, i, &self.axes[a])?;
        }
        Ok(PoolStance {
            stance_id: self.ids[i].clone(),
            clip: self.clips[i].clone(),
            character_id: self.chars[i].clone(),
            label: self.labels[i].clone(),
            first_frame: self.first[i],
            boundary_start: boundary(t, "boundary_start", i, &self.boundaries[0][i])?,
            boundary_end: boundary(t, "boundary_end", i, &self.boundaries[1][i])?,
            z_c: self.v("z_c", i),
            params: self.params(i),
            model: ForceModel {
                mass_kg: self.v("mass_kg", i),
                dt_s: self.v("dt_s", i),
                axes,
            },
            cp: [self.v("cp_h", i), self.v("cp_p", i)],
            coef: self.coefficients(i),
        })
    }
}

/// Reads the stance rows of `stances.parquet` as query stances.
///
/// # Errors
/// The file cannot be read, or a column is missing, mistyped or null (the error names the
/// file, column and row).
pub fn read_stances(path: &Path) -> Result<Vec<PoolStance>> {
    let t = Table::open(path)?;
    let cols = StanceColumns::decode(&t)?;
    (0..t.height()).map(|i| cols.row(&t, i)).collect()
}

/// Where a source stance sits in its clip (from `stances.parquet`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceTiming {
    /// Touchdown, clip time (s).
    pub td_clip_s: f64,
    /// Liftoff, clip time (s).
    pub lo_clip_s: f64,
    /// Unit heading `e_h` (world x, y).
    pub heading: [f64; 2],
}

/// Where each stance of `stances.parquet` sits in its clip, in file order (the order of
/// [`read_stances`]): touchdown, liftoff and heading.
///
/// # Errors
/// The file cannot be read, or a column is missing, mistyped or null.
pub fn read_stance_timing(path: &Path) -> Result<Vec<StanceTiming>> {
    let t = Table::open(path)?;
    let (td, lo) = (t.f64s("td_clip_s")?, t.f64s("lo_clip_s")?);
    let (hx, hy) = (t.f64s("heading_x")?, t.f64s("heading_y")?);
    Ok((0..t.height())
        .map(|i| StanceTiming {
            td_clip_s: td[i],
            lo_clip_s: lo[i],
            heading: [hx[i], hy[i]],
        })
        .collect())
}

/// One failed input or stage.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct ErrorRow {
    /// The path as given.
    pub path: String,
    /// Clip name, when the file got one.
    pub clip: Option<String>,
    /// `parse`, `mapping`, `frames` or `stances`.
    pub stage: String,
    /// The message (file, line and field where known).
    pub message: String,
}

/// `errors.parquet`, sorted by (`path`, `stage`, `message`).
pub fn errors_table(rows: &[ErrorRow]) -> PolarsResult<DataFrame> {
    let mut r = rows.to_vec();
    r.sort_by(|a, b| (&a.path, &a.stage, &a.message).cmp(&(&b.path, &b.stage, &b.message)));
    DataFrame::new_infer_height(vec![
        col("path", r.iter().map(|e| e.path.clone()).collect::<Vec<_>>()),
        col("clip", r.iter().map(|e| e.clip.clone()).collect::<Vec<_>>()),
        col(
            "stage",
            r.iter().map(|e| e.stage.clone()).collect::<Vec<_>>(),
        ),
        col(
            "message",
            r.iter().map(|e| e.message.clone()).collect::<Vec<_>>(),
        ),
    ])
}

#[cfg(test)]
mod schema_tests {
    use super::*;
    use crate::library::schema::{ERRORS_COLUMNS, STANCES_COLUMNS};

    fn names(df: &DataFrame) -> Vec<String> {
        df.get_column_names()
            .iter()
            .map(|n| n.to_string())
            .collect()
    }

    // See: issue 13 item 2 — stance column names were literals in the writer and the reader.
    #[test]
    fn the_writers_columns_are_the_schema_and_the_reader_reads_only_those() {
        assert_eq!(names(&stances_table(&[]).unwrap()), STANCES_COLUMNS);
        assert_eq!(names(&errors_table(&[]).unwrap()), ERRORS_COLUMNS);
        let read: Vec<String> = SCALAR_COLUMNS
            .iter()
            .map(|c| c.to_string())
            .chain(AXES.iter().flat_map(|a| {
                ["c0", "harmonic", "amp", "phase", "fit_rms", "poly"].map(|p| format!("{p}_{a}"))
            }))
            .collect();
        for c in &read {
            assert!(
                STANCES_COLUMNS.contains(&c.as_str()),
                "reader column {c} not written"
            );
        }
    }
}
