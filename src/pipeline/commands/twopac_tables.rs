//! The 2PAC outputs as tables (spec two-pac §8, §8.2): `equilibrium`'s result and the
//! `twopac` trajectory, phases, transitions, windows and validation. Column names carry
//! their unit (`_m`, `_s`, `_n`, `_mps`, `_mps2`); no solve time is ever stored here
//! (timings go to `timings.json`, §8).

use polars::prelude::*;

use crate::library::codec::columns::{col, list_col};
use crate::library::codec::schema::com_state::{ACCELERATION, POSITION, VELOCITY};
use crate::twopac::bezier::ComState;
use crate::twopac::equilibrium::Verdict;
use crate::twopac::trajectory::{Phase, PhaseDiagnostic, Plan};
use crate::twopac::transition::{QpForm, TransitionPoint};
use crate::twopac::validate::Validation;

/// Name of a QP form in the `form` columns.
pub fn form_name(f: QpForm) -> &'static str {
    match f {
        QpForm::Eq6 => "eq6",
        QpForm::Eq13 => "eq13",
    }
}

/// `equilibrium`'s `R.parquet` (§8.2): `x_m, y_m, z_m, in_equilibrium, margin_n, status`, rows
/// in the order of the points.
///
/// # Errors
/// A column cannot be built.
pub fn equilibrium_table(com: &[[f64; 3]], verdicts: &[Verdict]) -> PolarsResult<DataFrame> {
    let c = |k: usize| com.iter().map(|p| p[k]).collect::<Vec<f64>>();
    DataFrame::new_infer_height(vec![
        col(POSITION[0], c(0)),
        col(POSITION[1], c(1)),
        col(POSITION[2], c(2)),
        col(
            "in_equilibrium",
            verdicts
                .iter()
                .map(|v| v.in_equilibrium)
                .collect::<Vec<_>>(),
        ),
        col(
            "margin_n",
            verdicts.iter().map(|v| v.margin_n).collect::<Vec<_>>(),
        ),
        col(
            "status",
            verdicts
                .iter()
                .map(|v| v.status.as_str())
                .collect::<Vec<_>>(),
        ),
    ])
}

/// One sample of a trajectory with its §7 validation and equilibrium verdict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryRow {
    /// Time on the data clock, s.
    pub t_s: f64,
    /// Active phase.
    pub phase: usize,
    /// COM position, velocity, acceleration.
    pub state: ComState,
    /// §7: `s* ≤ 1e-6 m g`.
    pub valid: bool,
    /// §7 slack `s*`, N (`+∞`: no solution of `G V β = w`).
    pub slack_n: f64,
    /// The §8.2 verdict with the curve's acceleration.
    pub verdict: Verdict,
}

/// `trajectory.parquet` / `quasi_static.parquet`: one row per §7 sample.
///
/// # Errors
/// A column cannot be built.
pub fn trajectory_table(rows: &[TrajectoryRow]) -> PolarsResult<DataFrame> {
    let v = |g: &dyn Fn(&TrajectoryRow) -> f64| rows.iter().map(g).collect::<Vec<f64>>();
    let mut cols = vec![
        col("time_s", v(&|r| r.t_s)),
        col(
            "phase",
            rows.iter().map(|r| r.phase as i64).collect::<Vec<_>>(),
        ),
    ];
    for (names, g) in [
        (
            POSITION,
            &(|r: &TrajectoryRow| r.state.pos) as &dyn Fn(&TrajectoryRow) -> [f64; 3],
        ),
        (VELOCITY, &|r: &TrajectoryRow| r.state.vel),
        (ACCELERATION, &|r: &TrajectoryRow| r.state.acc),
    ] {
        for (a, name) in names.iter().enumerate() {
            cols.push(col(name, v(&|r| g(r)[a])));
        }
    }
    cols.extend([
        col("valid", rows.iter().map(|r| r.valid).collect::<Vec<_>>()),
        col(
            "slack_n",
            rows.iter()
                .map(|r| r.slack_n.is_finite().then_some(r.slack_n))
                .collect::<Vec<_>>(),
        ),
        col(
            "in_equilibrium",
            rows.iter()
                .map(|r| r.verdict.in_equilibrium)
                .collect::<Vec<_>>(),
        ),
        col(
            "margin_n",
            rows.iter().map(|r| r.verdict.margin_n).collect::<Vec<_>>(),
        ),
        col(
            "status",
            rows.iter()
                .map(|r| r.verdict.status.as_str())
                .collect::<Vec<_>>(),
        ),
    ]);
    DataFrame::new_infer_height(cols)
}

/// `(slack_m, slack_bw)`: the slack in the unit of its form, the other `None`.
fn slacks(p: &TransitionPoint) -> (Option<f64>, Option<f64>) {
    match p.form {
        QpForm::Eq6 => (Some(p.slack), None),
        QpForm::Eq13 => (None, Some(p.slack)),
    }
}

fn point_cols(points: &[TransitionPoint]) -> Vec<Column> {
    let c = |k: usize| points.iter().map(|p| p.com[k]).collect::<Vec<f64>>();
    vec![
        col(POSITION[0], c(0)),
        col(POSITION[1], c(1)),
        col(POSITION[2], c(2)),
        col(
            "slack_m",
            points.iter().map(|p| slacks(p).0).collect::<Vec<_>>(),
        ),
        col(
            "slack_body_weights",
            points.iter().map(|p| slacks(p).1).collect::<Vec<_>>(),
        ),
        col(
            "wrench_residual",
            points.iter().map(|p| p.wrench_residual).collect::<Vec<_>>(),
        ),
        col(
            "degenerate_contacts",
            points
                .iter()
                .map(|p| p.degenerate_contacts)
                .collect::<Vec<_>>(),
        ),
        col(
            "form",
            points.iter().map(|p| form_name(p.form)).collect::<Vec<_>>(),
        ),
    ]
}

/// `transitions.parquet`: one row per transition `j → j+1` (§4, §8).
///
/// `kinematic_margin_m = min(k − K c)` over the kinematics phase (`≥ 0`: inside).
///
/// # Errors
/// A column cannot be built.
pub fn transitions_table(plan: &Plan, phases: &[Phase]) -> PolarsResult<DataFrame> {
    let t = &plan.transitions;
    let idx = |g: &dyn Fn(usize) -> usize| t.iter().map(|x| g(x.index) as i64).collect::<Vec<_>>();
    let points: Vec<TransitionPoint> = t.iter().map(|x| x.point).collect();
    let mut cols = vec![
        col("transition", idx(&|j| j)),
        col("from_phase", idx(&|j| j)),
        col("to_phase", idx(&|j| j + 1)),
        col(
            "change",
            t.iter()
                .map(|x| if x.adds { "add" } else { "remove" })
                .collect::<Vec<_>>(),
        ),
        col(
            "effector",
            t.iter().map(|x| x.effector.clone()).collect::<Vec<_>>(),
        ),
        col(
            "statics_phase",
            t.iter().map(|x| x.statics_phase as i64).collect::<Vec<_>>(),
        ),
        col(
            "kinematics_phase",
            t.iter()
                .map(|x| x.kinematics_phase as i64)
                .collect::<Vec<_>>(),
        ),
    ];
    cols.extend(point_cols(&points));
    cols.push(col(
        "static_feasible",
        points
            .iter()
            .map(|p| p.is_static(crate::math::constants::STATIC_TOL))
            .collect::<Vec<_>>(),
    ));
    cols.push(col(
        "kinematic_margin_m",
        t.iter()
            .map(|x| {
                -phases[x.kinematics_phase]
                    .polytope()
                    .max_violation(x.point.com)
            })
            .collect::<Vec<_>>(),
    ));
    cols.push(col(
        "switch_time_s",
        plan.switch_times_s
            .iter()
            .map(|s| s.is_finite().then_some(*s))
            .collect::<Vec<_>>(),
    ));
    DataFrame::new_infer_height(cols)
}

/// `phases.parquet`: one row per phase with the §8 diagnostics at its state `c^(j)`.
///
/// # Errors
/// A column cannot be built.
pub fn phases_table(
    plan: &Plan,
    phases: &[Phase],
    diags: &[PhaseDiagnostic],
) -> PolarsResult<DataFrame> {
    let mut cols = vec![
        col("phase", (0..phases.len() as i64).collect::<Vec<_>>()),
        list_col(
            "effectors",
            phases
                .iter()
                .map(|p| p.contacts.iter().map(|c| c.effector.clone()).collect())
                .collect(),
            DataType::String,
        )?,
        col(
            "n_contact_points",
            phases
                .iter()
                .map(|p| {
                    p.contacts
                        .iter()
                        .map(|c| c.points().len() as i64)
                        .sum::<i64>()
                })
                .collect::<Vec<_>>(),
        ),
        col(
            "duration_s",
            phases.iter().map(|p| p.duration_s).collect::<Vec<_>>(),
        ),
        col(
            "start_s",
            (0..phases.len())
                .map(|j| plan.phase_starts_s.as_ref().map(|s| s[j]))
                .collect::<Vec<_>>(),
        ),
    ];
    cols.extend(point_cols(&plan.phase_states));
    cols.push(col(
        "static_feasible",
        diags.iter().map(|d| d.static_feasible).collect::<Vec<_>>(),
    ));
    cols.push(col(
        "kinematic_margin_m",
        diags
            .iter()
            .map(|d| {
                d.kinematic_margin_m
                    .is_finite()
                    .then_some(d.kinematic_margin_m)
            })
            .collect::<Vec<_>>(),
    ));
    DataFrame::new_infer_height(cols)
}

/// `windows.parquet`: one row per sliding window (§6) with its control points and the
/// §5.4 kinematic guarantee on the kept part `[0, u_end]`: `kept_violation_m[k] =
/// max(K_win P_k − k_win)` for every kept control point (`≤ 1e-9`: inside).
///
/// # Errors
/// A column cannot be built.
pub fn windows_table(plan: &Plan, phases: &[Phase]) -> PolarsResult<DataFrame> {
    let w = &plan.windows;
    let i = |g: &dyn Fn(&crate::twopac::trajectory::Window) -> usize| {
        w.iter().map(|x| g(x) as i64).collect::<Vec<_>>()
    };
    let f = |g: &dyn Fn(&crate::twopac::trajectory::Window) -> f64| {
        w.iter().map(g).collect::<Vec<f64>>()
    };
    let kept: Vec<Vec<[f64; 3]>> = w.iter().map(|x| x.curve.left(x.u_end).control).collect();
    let viol: Vec<Vec<f64>> = w
        .iter()
        .zip(&kept)
        .map(|(x, k)| {
            let poly = phases[x.guarantee_phase].polytope();
            k.iter().map(|p| poly.max_violation(*p)).collect()
        })
        .collect();
    let ctrl = |name: &str, pts: &[Vec<[f64; 3]>], k: usize| {
        list_col(
            name,
            pts.iter()
                .map(|v| v.iter().map(|p| p[k]).collect())
                .collect(),
            DataType::Float64,
        )
    };
    let full: Vec<Vec<[f64; 3]>> = w.iter().map(|x| x.curve.control.clone()).collect();
    DataFrame::new_infer_height(vec![
        col("window", (0..w.len() as i64).collect::<Vec<_>>()),
        col("first_phase", i(&|x| x.first_phase)),
        col("last_phase", i(&|x| x.last_phase)),
        col("n_attractors", i(&|x| x.last_phase - x.first_phase)),
        col("degree", i(&|x| x.curve.degree())),
        col("guarantee_phase", i(&|x| x.guarantee_phase)),
        col("t_start_s", f(&|x| x.t_start_s)),
        col("duration_s", f(&|x| x.duration_s)),
        col("u_end", f(&|x| x.u_end)),
        col("t_end_s", f(&|x| x.t_start_s + x.u_end * x.duration_s)),
        ctrl("control_x_m", &full, 0)?,
        ctrl("control_y_m", &full, 1)?,
        ctrl("control_z_m", &full, 2)?,
        ctrl("kept_x_m", &kept, 0)?,
        ctrl("kept_y_m", &kept, 1)?,
        ctrl("kept_z_m", &kept, 2)?,
        list_col("kept_violation_m", viol.clone(), DataType::Float64)?,
        col(
            "guaranteed",
            w.iter()
                .map(|x| x.violations.is_empty())
                .collect::<Vec<_>>(),
        ),
        col("n_violations", i(&|x| x.violations.len())),
        col(
            "max_violation_m",
            viol.iter()
                .map(|v| v.iter().copied().fold(f64::NEG_INFINITY, f64::max))
                .map(|v| v.is_finite().then_some(v))
                .collect::<Vec<_>>(),
        ),
    ])
}

/// `validation.parquet`: one row per trajectory (§7 step 3).
///
/// # Errors
/// A column cannot be built.
pub fn validation_table(runs: &[(&str, &Validation)]) -> PolarsResult<DataFrame> {
    DataFrame::new_infer_height(vec![
        col("trajectory", runs.iter().map(|r| r.0).collect::<Vec<_>>()),
        col(
            "n_samples",
            runs.iter()
                .map(|r| r.1.samples.len() as i64)
                .collect::<Vec<_>>(),
        ),
        col(
            "point_valid_rate",
            runs.iter()
                .map(|r| r.1.point_valid_rate)
                .collect::<Vec<_>>(),
        ),
        col(
            "trajectory_valid",
            runs.iter()
                .map(|r| r.1.trajectory_valid)
                .collect::<Vec<_>>(),
        ),
        col(
            "max_slack_n",
            runs.iter()
                .map(|r| r.1.max_slack_n.is_finite().then_some(r.1.max_slack_n))
                .collect::<Vec<_>>(),
        ),
        col(
            "worst_time_s",
            runs.iter().map(|r| r.1.worst_t_s).collect::<Vec<_>>(),
        ),
    ])
}
