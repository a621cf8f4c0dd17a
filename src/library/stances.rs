//! `stances.parquet` and `errors.parquet` (spec stance-model §11).
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

use polars::prelude::*;

use super::columns::{col, list_col};
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
    let f = |g: &dyn Fn(&Stance) -> f64| -> Vec<f64> { rows.iter().map(g).collect() };
    let s = |g: &dyn Fn(&Stance) -> String| -> Vec<String> { rows.iter().map(g).collect() };
    let axis = ["h", "p", "v"];
    let mut cols = vec![
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
    ];
    for (a, name) in axis.iter().enumerate() {
        cols.push(col(&format!("c0_{name}"), f(&|r| r.model.axes[a].c0)));
    }
    for (a, name) in axis.iter().enumerate() {
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
    for (a, name) in axis.iter().enumerate() {
        cols.push(list_col(
            &format!("amp_{name}"),
            rows.iter().map(|r| r.model.axes[a].amps.clone()).collect(),
            DataType::Float64,
        )?);
    }
    for (a, name) in axis.iter().enumerate() {
        cols.push(list_col(
            &format!("phase_{name}"),
            rows.iter()
                .map(|r| r.model.axes[a].phases.clone())
                .collect(),
            DataType::Float64,
        )?);
    }
    for (a, name) in axis.iter().enumerate() {
        cols.push(col(
            &format!("fit_rms_{name}"),
            f(&|r| r.model.axes[a].fit_rms),
        ));
    }
    for (a, name) in axis.iter().enumerate() {
        cols.push(list_col(
            &format!("poly_{name}"),
            rows.iter().map(|r| r.model.axes[a].poly.clone()).collect(),
            DataType::Float64,
        )?);
    }
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
        for (a, name) in axis.iter().enumerate() {
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
    for (a, name) in axis.iter().enumerate() {
        let v: Vec<Option<f64>> = rows
            .iter()
            .map(|r| {
                let (j, k) = (r.model.j()[a], r.model.k()[a]);
                (j != 0.0).then(|| k / j)
            })
            .collect();
        cols.push(col(&format!("s_bar_{name}"), v));
    }
    cols.push(col(
        "support_ok",
        rows.iter().map(|r| r.coef.support_ok).collect::<Vec<_>>(),
    ));
    cols.push(col(
        "unilateral_ok",
        rows.iter()
            .map(|r| r.coef.unilateral_ok)
            .collect::<Vec<_>>(),
    ));
    cols.push(col("min_f_v", f(&|r| r.coef.min_f_v)));
    let l = |g: &dyn Fn(&Stance) -> Vec<f64>| -> Vec<Vec<f64>> { rows.iter().map(g).collect() };
    cols.push(list_col(
        "a_f",
        l(&|r| r.coef.a_f.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "a_mu",
        l(&|r| r.coef.a_mu.to_vec()),
        DataType::Float64,
    )?);
    cols.push(col("f_peak", f(&|r| r.coef.f_peak)));
    cols.push(col("mu_req", f(&|r| r.coef.mu_req)));
    cols.push(col("mu_req_robust", f(&|r| r.coef.mu_req_robust)));
    cols.push(col("ext_min", f(&|r| r.coef.ext_min)));
    cols.push(col("ext_max", f(&|r| r.coef.ext_max)));
    cols.push(col("cp_h", f(&|r| r.cp[0])));
    cols.push(col("cp_p", f(&|r| r.cp[1])));
    cols.push(list_col(
        "ang_impulse",
        l(&|r| r.coef.ang_impulse.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "ang_impulse_h0",
        l(&|r| r.coef.ang_impulse_h0.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "ell_r_min",
        l(&|r| r.coef.ell_r_min.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "ell_r_max",
        l(&|r| r.coef.ell_r_max.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "ell_s_min",
        l(&|r| r.coef.ell_s_min.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "ell_s_max",
        l(&|r| r.coef.ell_s_max.to_vec()),
        DataType::Float64,
    )?);
    cols.push(list_col(
        "warnings",
        rows.iter().map(|r| r.warnings.clone()).collect(),
        DataType::String,
    )?);
    DataFrame::new_infer_height(cols)
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
