//! `stancelib query run` and `stancelib query jump`: read a library, answer, write Parquet
//! and print a short table.

use std::path::Path;

use anyhow::Context;

use super::super::args::{JumpArgs, RunQueryArgs};
use super::super::Outcome;
use crate::pipeline::queries::{jump_query, run_query, JumpQuery, RunQuery, RunReport};

/// Run `query run`.
///
/// # Errors
/// Bad options, an unreadable library, an unwritable output.
pub fn run(a: RunQueryArgs) -> anyhow::Result<Outcome> {
    let q = RunQuery {
        lib: a.lib.clone(),
        speeds: a.speeds()?,
        length_scale: a.length_scale,
        mass_scale: a.mass_scale,
        limits: a.lim.options(),
        out: a.out.clone(),
        png: a.png.clone(),
        gait_law: crate::pipeline::queries::gait_law_choice(Some(&a.gait_law))
            .context("--gait-law")?,
        keep_left_out: a.keep_left_out,
    };
    print_run(&run_query(&q)?, &q.out);
    Ok(Outcome::Clean)
}

/// The `query run` answers on stdout (the cycles recorded nearest in speed), then the
/// summary line.
pub fn print_run(report: &RunReport, out: &Path) {
    crate::say!(
        "{:>6} {:<30} {:>10} {:>6} {:>6} {:>6} {:>6} {:>6} {:>7} {:>7}  verdict",
        "v_mps",
        "cycle (first stance)",
        "gait law",
        "t_c_s",
        "T_s",
        "β_h",
        "β_v",
        "μ_min",
        "F_pk_N",
        "ext_max",
    );
    for r in report.lines.iter().filter(|r| r.used) {
        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
        let verdict = match (&r.violated, r.feasible) {
            (_, true) => "feasible".to_string(),
            (Some(why), false) => format!("infeasible: {why}"),
            (None, false) => "infeasible".to_string(),
        };
        crate::say!(
            "{:>6.2} {:<30} {:>10} {:>6} {:>6} {:>6} {:>6} {:>6} {:>7} {:>7}  {}",
            r.speed_mps,
            r.stance_id,
            r.gait_law,
            f(r.contact_s),
            f(r.step_s),
            f(r.beta[0]),
            f(r.beta[1]),
            f(r.mu_min),
            r.f_peak_n.map_or("-".into(), |v| format!("{v:.0}")),
            f(r.ext_max_m),
            verdict
        );
    }
    let used = report.lines.iter().filter(|r| r.used).count();
    crate::say!(
        "query run: {} cycle(s) × {} speed(s); {} answer(s) shown from the cycles recorded \
         nearest in speed (column `used`; all rows in the table) → {}",
        report.n_cycles,
        report.n_speeds,
        used,
        out.display()
    );
}

/// Run `query jump`.
///
/// # Errors
/// Bad options, an unreadable library, an unwritable output.
pub fn run_jump(a: JumpArgs) -> anyhow::Result<Outcome> {
    let q = JumpQuery {
        lib: a.lib,
        height_m: a.height,
        distance_m: a.distance,
        limits: a.lim.options(),
        keep_left_out: a.keep_left_out,
        out: a.out,
    };
    let lines = jump_query(&q)?;
    crate::say!(
        "{:>4} {:<34} {:<34} {:>7} {:>6} {:>6} {:>6} {:>6}  verdict",
        "rank",
        "liftoff",
        "landing",
        "u_apex",
        "β_h1",
        "β_v1",
        "β_h2",
        "β_v2",
    );
    let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
    for (i, r) in lines.iter().take(a.top).enumerate() {
        let b = |k: usize, ax: usize| f(r.beta.map(|b| b[k][ax]));
        let verdict = match (&r.why, r.feasible) {
            (_, true) => "feasible".to_string(),
            (Some(why), false) => format!("infeasible: {why}"),
            (None, false) => "infeasible".to_string(),
        };
        crate::say!(
            "{:>4} {:<34} {:<34} {:>7} {:>6} {:>6} {:>6} {:>6}  {}",
            i + 1,
            r.liftoff,
            r.landing,
            f(r.u_apex_mps),
            b(0, 0),
            b(0, 1),
            b(1, 0),
            b(1, 1),
            verdict
        );
    }
    let n_ok = lines.iter().filter(|r| r.feasible).count();
    crate::say!(
        "query jump: {} pair(s), {} feasible → {}",
        lines.len(),
        n_ok,
        q.out.display()
    );
    Ok(Outcome::Clean)
}
