//! `stances.parquet` and `errors.parquet` (spec stance-model §11): the stance table's writer
//! ([`stances_table`]) and reader ([`read_stances`]) side by side.
//!
//! Stance rows are sorted by (`clip`, `first_frame`, `label`); the force model is stored as
//! parallel list columns per stance axis (`harmonic_*`, `amp_*`, `phase_*`: the Fourier
//! model) and a power-basis list `poly_*` (the ratio model), from which
//!
//! ```text
//! τ = (t − td_clip_s)/dt_s,
//! f_a(t) = c0_a_n + Σ_i amp_a_n[i]·cos(2π·harmonic_a[i]·τ + phase_a_rad[i]) + Σ_k poly_a_n[k]·τ^k
//! ```
//! rebuilds the applied force (N) on stance axis `a` for 0 ≤ τ ≤ 1 (0 outside). The
//! `force_model` column says which model the row holds (`ratio` or `fourier`); `ratio_h`,
//! `ratio_p` are the ratio model's `q_h`, `q_p` (power basis, `f_h = f_v·q_h`).

use std::collections::BTreeMap;
use std::path::Path;

use polars::prelude::*;

use super::columns::{col, list_col};
use super::schema::{errors as E, flight_ref as F, stances as S};
use super::table::Table;
use crate::constraints::Coefficients;
use crate::error::{Error, Result};
use crate::force_model::{AxisModel, ForceModel};
use crate::stances::params::StanceParams;
use crate::stances::segment::Boundary;
use crate::stances::{FlightRef, Stance};

fn flight_dtype() -> DataType {
    let f = |n: &str, t: DataType| Field::new(n.into(), t);
    DataType::Struct(vec![
        f(F::FIRST_FRAME, DataType::Int64),
        f(F::LAST_FRAME, DataType::Int64),
        f(F::N_INT, DataType::Int64),
        f(F::FREE, DataType::Boolean),
        f(F::A_Z, DataType::Float64),
        f(F::VEL, DataType::List(Box::new(DataType::Float64))),
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
        Series::new(F::FIRST_FRAME.into(), geti(&|f| f.first_frame)),
        Series::new(F::LAST_FRAME.into(), geti(&|f| f.last_frame)),
        Series::new(F::N_INT.into(), geti(&|f| f.n_int)),
        Series::new(
            F::FREE.into(),
            rows.iter().map(|r| r.map(|f| f.free)).collect::<Vec<_>>(),
        ),
        Series::new(F::A_Z.into(), get(&|f| f.a_z)),
        vel.into_series()
            .cast(&DataType::List(Box::new(DataType::Float64)))?
            .with_name(F::VEL.into()),
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

/// A non-finite number in a stance row ([`first_non_finite`]).
#[derive(Debug, Clone, PartialEq)]
pub struct NonFiniteCell {
    /// The stance.
    pub stance_id: String,
    /// The column (a list or struct column: the value is one of its elements).
    pub column: String,
    /// The value (NaN, +∞ or −∞).
    pub value: f64,
}

/// The first non-finite number of the rows `rows` would write (column by column; nulls are
/// no values): the last guard before `stances.parquet`, so that a stance of inf or NaN
/// becomes a per-clip error instead of a row.
///
/// # Errors
/// The rows cannot be made a table.
pub fn first_non_finite(rows: &[Stance]) -> PolarsResult<Option<NonFiniteCell>> {
    if rows.is_empty() {
        return Ok(None);
    }
    let df = stances_table(rows)?;
    Ok(df.columns().iter().find_map(|c| {
        non_finite_row(c.as_materialized_series()).map(|(row, value)| NonFiniteCell {
            stance_id: rows[row].stance_id.clone(),
            column: c.name().to_string(),
            value,
        })
    }))
}

/// The first row of `s` holding a non-finite float, in a float column or in the floats of
/// a list or struct column, with the value.
fn non_finite_row(s: &Series) -> Option<(usize, f64)> {
    match s.dtype() {
        DataType::Float64 => s
            .f64()
            .ok()?
            .iter()
            .enumerate()
            .find_map(|(i, v)| v.filter(|x| !x.is_finite()).map(|x| (i, x))),
        DataType::Float32 => non_finite_row(&s.cast(&DataType::Float64).ok()?),
        DataType::List(_) => s
            .list()
            .ok()?
            .amortized_iter()
            .enumerate()
            .find_map(|(i, inner)| {
                inner
                    .and_then(|v| non_finite_row(v.as_ref()))
                    .map(|(_, x)| (i, x))
            }),
        DataType::Struct(_) => s
            .struct_()
            .ok()?
            .fields_as_series()
            .iter()
            .filter_map(non_finite_row)
            .min_by_key(|(i, _)| *i),
        _ => None,
    }
}

/// Ids, frames, times, boundaries, adjacent flights, heading and the parameters (`stance_id`
/// … `mass_kg`).
fn identity_columns(rows: &[Stance]) -> PolarsResult<Vec<Column>> {
    let f = |g: &dyn Fn(&Stance) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let s = |g: &dyn Fn(&Stance) -> String| -> Vec<String> { rows.iter().map(g).collect() };
    Ok(vec![
        col(S::STANCE_ID, s(&|r| r.stance_id.clone())),
        col(S::CLIP, s(&|r| r.clip.clone())),
        col(S::CHARACTER_ID, s(&|r| r.character_id.clone())),
        col(S::LABEL, s(&|r| r.label.clone())),
        list_col(
            S::EFFECTORS,
            rows.iter().map(|r| r.effectors.clone()).collect(),
            DataType::String,
        )?,
        col(
            S::FIRST_FRAME,
            rows.iter().map(|r| r.first_frame).collect::<Vec<_>>(),
        ),
        col(
            S::LAST_FRAME,
            rows.iter().map(|r| r.last_frame).collect::<Vec<_>>(),
        ),
        col(S::TD_CLIP, f(&|r| r.td_clip_s)),
        col(S::LO_CLIP, f(&|r| r.lo_clip_s)),
        col(S::TD_STANCE, f(&|r| r.params.t_td)),
        col(S::LO_STANCE, f(&|r| r.params.t_lo)),
        col(S::END_APEX_STANCE, f(&|r| r.params.t_e)),
        col(S::DT, f(&|r| r.dt_s)),
        col(
            S::BOUNDARY_START,
            s(&|r| r.boundary_start.as_str().to_string()),
        ),
        col(S::BOUNDARY_END, s(&|r| r.boundary_end.as_str().to_string())),
        col(
            S::REST_AT_EDGE,
            rows.iter().map(|r| r.rest_at_edge).collect::<Vec<_>>(),
        ),
        flight_col(
            S::FLIGHT_BEFORE,
            rows.iter().map(|r| r.flight_before.as_ref()).collect(),
        )?,
        flight_col(
            S::FLIGHT_AFTER,
            rows.iter().map(|r| r.flight_after.as_ref()).collect(),
        )?,
        col(S::HEADING_X, f(&|r| r.heading.e_h[0])),
        col(S::HEADING_Y, f(&|r| r.heading.e_h[1])),
        col(S::HEADING_FROM, s(&|r| r.heading.from.as_str().to_string())),
        col(S::Z_C, f(&|r| r.z_c)),
        col(S::ZS, f(&|r| r.params.zs)),
        col(S::VS, f(&|r| r.params.vs)),
        col(S::ZE, f(&|r| r.params.ze)),
        col(S::VE, f(&|r| r.params.ve)),
        col(S::VP, f(&|r| r.params.vp)),
        col(S::X, f(&|r| r.params.x)),
        col(S::VPS, f(&|r| r.params.vps)),
        col(S::Z_TD, f(&|r| r.params.z_td)),
        col(S::Z_LO, f(&|r| r.params.z_lo)),
        col(S::ZE_MEASURED, f(&|r| r.measured.ze)),
        col(S::VE_MEASURED, f(&|r| r.measured.ve)),
        col(S::VP_MEASURED, f(&|r| r.measured.vp)),
        col(S::X_MEASURED, f(&|r| r.measured.x)),
        col(S::MASS, f(&|r| r.mass_kg)),
    ])
}

/// The force model per stance axis and its impulses (`c0_*` … `s_bar_*`).
fn model_columns(rows: &[Stance]) -> PolarsResult<Vec<Column>> {
    let f = |g: &dyn Fn(&Stance) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let mut cols = Vec::new();
    for a in 0..3 {
        cols.push(col(S::C0[a], f(&|r| r.model.axes[a].c0)));
    }
    for a in 0..3 {
        let h: Vec<Vec<f64>> = rows
            .iter()
            .map(|r| r.model.axes[a].harmonics.clone())
            .collect();
        cols.push(list_col(S::HARMONIC[a], h, DataType::Float64)?);
    }
    let axis_list =
        |names: [&str; 3], g: &dyn Fn(&AxisModel) -> Vec<f64>| -> PolarsResult<Vec<Column>> {
            names
                .iter()
                .enumerate()
                .map(|(a, name)| {
                    list_col(
                        name,
                        rows.iter().map(|r| g(&r.model.axes[a])).collect(),
                        DataType::Float64,
                    )
                })
                .collect()
        };
    cols.extend(axis_list(S::AMP, &|m| m.amps.clone())?);
    cols.extend(axis_list(S::PHASE, &|m| m.phases.clone())?);
    for (a, name) in S::FIT_RMS.iter().enumerate() {
        cols.push(col(name, f(&|r| r.model.axes[a].fit_rms)));
    }
    cols.extend(axis_list(S::POLY, &|m| m.poly.clone())?);
    for (q, name) in [S::RATIO_H, S::RATIO_P].iter().enumerate() {
        cols.push(list_col(
            name,
            rows.iter().map(|r| r.ratio[q].clone()).collect(),
            DataType::Float64,
        )?);
    }
    cols.push(col(
        S::FORCE_MODEL,
        rows.iter()
            .map(|r| r.force_model.name())
            .collect::<Vec<_>>(),
    ));
    for (names, get) in [(S::J, 0usize), (S::K, 1)] {
        for (a, name) in names.iter().enumerate() {
            cols.push(col(
                name,
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
    for a in 0..3 {
        let v: Vec<Option<f64>> = rows
            .iter()
            .map(|r| {
                let (j, k) = (r.model.j()[a], r.model.k()[a]);
                (j != 0.0).then(|| k / j)
            })
            .collect();
        cols.push(col(S::S_BAR[a], v));
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
            S::SUPPORT_OK,
            rows.iter().map(|r| r.coef.support_ok).collect::<Vec<_>>(),
        ),
        col(
            S::UNILATERAL_OK,
            rows.iter()
                .map(|r| r.coef.unilateral_ok)
                .collect::<Vec<_>>(),
        ),
        col(S::MIN_F_V, f(&|r| r.coef.min_f_v)),
        l(S::A_F, &|c| c.a_f.to_vec())?,
        l(S::A_MU, &|c| c.a_mu.to_vec())?,
        col(S::F_PEAK, f(&|r| r.coef.f_peak)),
        col(S::MU_REQ, f(&|r| r.coef.mu_req)),
        col(S::MU_REQ_ROBUST, f(&|r| r.coef.mu_req_robust)),
        col(S::EXT_MIN, f(&|r| r.coef.ext_min)),
        col(S::EXT_MAX, f(&|r| r.coef.ext_max)),
        col(S::CP_H, f(&|r| r.cp[0])),
        col(S::CP_P, f(&|r| r.cp[1])),
        l(S::ANG_IMPULSE, &|c| c.ang_impulse.to_vec())?,
        l(S::ANG_IMPULSE_H0, &|c| c.ang_impulse_h0.to_vec())?,
        l(S::ELL_R_MIN, &|c| c.ell_r_min.to_vec())?,
        l(S::ELL_R_MAX, &|c| c.ell_r_max.to_vec())?,
        l(S::ELL_S_MIN, &|c| c.ell_s_min.to_vec())?,
        l(S::ELL_S_MAX, &|c| c.ell_s_max.to_vec())?,
        list_col(
            S::WARNINGS,
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
    Vec<Vec<f64>>,
    Vec<Vec<f64>>,
    Vec<Vec<f64>>,
    Vec<f64>,
    Vec<Vec<f64>>,
);

/// A `harmonic_*` column: `list<double>` (cycles per stance, whole or half), or the
/// `list<int32>` of libraries written before the half-range cosine model (whole cycles).
fn harmonic_lists(t: &Table, name: &str) -> Result<Vec<Vec<f64>>> {
    t.f64_lists(name, None).or_else(|e| {
        t.i32_lists(name)
            .map(|v| {
                v.into_iter()
                    .map(|r| r.into_iter().map(f64::from).collect())
                    .collect()
            })
            .map_err(|_| e)
    })
}

/// The force model of row `i` from one axis's columns.
fn axis_model(t: &Table, axis: usize, i: usize, cols: &AxisColumns) -> Result<AxisModel> {
    let (c0, h, a, p, rms, poly) = cols;
    if h[i].len() != a[i].len() || h[i].len() != p[i].len() {
        return Err(Error::column(
            &t.path,
            S::HARMONIC[axis],
            Some(i),
            "harmonic, amp and phase lists differ in length",
        ));
    }
    if !h[i]
        .iter()
        .all(|&j| j >= 0.5 && j.is_finite() && (2.0 * j).fract() == 0.0)
    {
        return Err(Error::column(
            &t.path,
            S::HARMONIC[axis],
            Some(i),
            "harmonics must be whole or half cycles ≥ ½",
        ));
    }
    Ok(AxisModel {
        c0: c0[i],
        harmonics: h[i].clone(),
        amps: a[i].clone(),
        phases: p[i].clone(),
        poly: poly[i].clone(),
        fit_rms: rms[i],
    })
}

/// The float64 columns of a stance row the reader needs, besides the axis models.
const SCALAR_COLUMNS: [&str; 23] = [
    S::Z_C,
    S::ZS,
    S::VS,
    S::ZE,
    S::VE,
    S::VP,
    S::VPS,
    S::X,
    S::Z_TD,
    S::Z_LO,
    S::TD_STANCE,
    S::LO_STANCE,
    S::END_APEX_STANCE,
    S::DT,
    S::MASS,
    S::CP_H,
    S::CP_P,
    S::MIN_F_V,
    S::F_PEAK,
    S::MU_REQ,
    S::MU_REQ_ROBUST,
    S::EXT_MIN,
    S::EXT_MAX,
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
            ids: s(S::STANCE_ID)?,
            clips: s(S::CLIP)?,
            chars: s(S::CHARACTER_ID)?,
            labels: s(S::LABEL)?,
            boundaries: [s(S::BOUNDARY_START)?, s(S::BOUNDARY_END)?],
            first: t.i64s(S::FIRST_FRAME)?,
            // Field initialisers run in order: the first bad column of the file's order
            // is the one reported.
            scalars: SCALAR_COLUMNS
                .iter()
                .map(|&n| Ok((n, f(n)?)))
                .collect::<Result<_>>()?,
            axes: [0, 1, 2]
                .map(|i| {
                    Ok((
                        f(S::C0[i])?,
                        harmonic_lists(t, S::HARMONIC[i])?,
                        t.f64_lists(S::AMP[i], None)?,
                        t.f64_lists(S::PHASE[i], None)?,
                        f(S::FIT_RMS[i])?,
                        t.f64_lists(S::POLY[i], None)?,
                    ))
                })
                .into_iter()
                .collect::<Result<Vec<AxisColumns>>>()?,
            lists: [
                l3(S::A_F)?,
                t.f64_lists(S::A_MU, Some(2))?,
                l3(S::ANG_IMPULSE)?,
                l3(S::ANG_IMPULSE_H0)?,
                l3(S::ELL_R_MIN)?,
                l3(S::ELL_R_MAX)?,
                l3(S::ELL_S_MIN)?,
                l3(S::ELL_S_MAX)?,
            ],
            support: t.bools(S::SUPPORT_OK)?,
            unilateral: t.bools(S::UNILATERAL_OK)?,
        })
    }

    fn v(&self, name: &str, i: usize) -> f64 {
        self.scalars[name][i]
    }

    fn params(&self, i: usize) -> StanceParams {
        let v = |n: &str| self.v(n, i);
        StanceParams {
            zs: v(S::ZS),
            vs: v(S::VS),
            ze: v(S::ZE),
            ve: v(S::VE),
            vp: v(S::VP),
            vps: v(S::VPS),
            x: v(S::X),
            z_td: v(S::Z_TD),
            z_lo: v(S::Z_LO),
            t_td: v(S::TD_STANCE),
            t_lo: v(S::LO_STANCE),
            t_e: v(S::END_APEX_STANCE),
        }
    }

    fn coefficients(&self, i: usize) -> Coefficients {
        let v = |n: &str| self.v(n, i);
        let [a_f, a_mu, ang, h0, r0, r1, s0, s1] = &self.lists;
        Coefficients {
            a_f: fixed(&a_f[i]),
            a_mu: fixed(&a_mu[i]),
            min_f_v: v(S::MIN_F_V),
            unilateral_ok: self.unilateral[i],
            support_ok: self.support[i],
            f_peak: v(S::F_PEAK),
            mu_req: v(S::MU_REQ),
            mu_req_robust: v(S::MU_REQ_ROBUST),
            ext_min: v(S::EXT_MIN),
            ext_max: v(S::EXT_MAX),
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
        for (a, axis) in axes.iter_mut().enumerate() {
            *axis = axis_model(t, a, i, &self.axes[a])?;
        }
        Ok(PoolStance {
            stance_id: self.ids[i].clone(),
            clip: self.clips[i].clone(),
            character_id: self.chars[i].clone(),
            label: self.labels[i].clone(),
            first_frame: self.first[i],
            boundary_start: boundary(t, S::BOUNDARY_START, i, &self.boundaries[0][i])?,
            boundary_end: boundary(t, S::BOUNDARY_END, i, &self.boundaries[1][i])?,
            z_c: self.v(S::Z_C, i),
            params: self.params(i),
            model: ForceModel {
                mass_kg: self.v(S::MASS, i),
                dt_s: self.v(S::DT, i),
                axes,
            },
            cp: [self.v(S::CP_H, i), self.v(S::CP_P, i)],
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
    let (td, lo) = (t.f64s(S::TD_CLIP)?, t.f64s(S::LO_CLIP)?);
    let (hx, hy) = (t.f64s(S::HEADING_X)?, t.f64s(S::HEADING_Y)?);
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
        col(
            E::PATH,
            r.iter().map(|e| e.path.clone()).collect::<Vec<_>>(),
        ),
        col(
            S::CLIP,
            r.iter().map(|e| e.clip.clone()).collect::<Vec<_>>(),
        ),
        col(
            E::STAGE,
            r.iter().map(|e| e.stage.clone()).collect::<Vec<_>>(),
        ),
        col(
            E::MESSAGE,
            r.iter().map(|e| e.message.clone()).collect::<Vec<_>>(),
        ),
    ])
}

#[cfg(test)]
mod schema_tests {
    use super::*;
    use crate::library::codec::schema::{ERRORS_COLUMNS, STANCES_COLUMNS};

    fn names(df: &DataFrame) -> Vec<String> {
        df.get_column_names()
            .iter()
            .map(|n| n.to_string())
            .collect()
    }

    // See: issue 13 item 2 — stance column names were literals in the writer and the reader
    // (both now use the schema's constants; the writer's order is the documented one).
    #[test]
    fn the_writers_columns_are_the_schema_in_order() {
        assert_eq!(names(&stances_table(&[]).unwrap()), STANCES_COLUMNS);
        assert_eq!(names(&errors_table(&[]).unwrap()), ERRORS_COLUMNS);
    }
}
