//! `stancelib query run` and `stancelib query jump`: read a library, answer, write Parquet
//! and print a short table.

use std::path::Path;

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
    };
    print_run(&run_query(&q)?, &q.out);
    Ok(Outcome::Clean)
}

/// The `query run` table on stdout, then its summary line.
pub fn print_run(report: &RunReport, out: &Path) {
    crate::say!(
        "{:>6} {:<34} {:>6} {:>6} {:>6} {:>7} {:>7} {:>7} {:>8}",
        "v_mps",
        "cycle (first stance)",
        "β_h",
        "β_v",
        "μ_min",
        "F_pk_N",
        "ext_max",
        "cp_h",
        "feasible"
    );
    for r in &report.lines {
        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
        crate::say!(
            "{:>6.2} {:<34} {:>6} {:>6} {:>6} {:>7} {:>7} {:>7} {:>8}",
            r.speed_mps,
            r.stance_id,
            f(r.beta[0]),
            f(r.beta[1]),
            f(r.mu_min),
            f(r.f_peak_n.map(f64::round)),
            f(r.ext_max_m),
            f(r.cp_h_m),
            r.feasible
        );
    }
    crate::say!(
        "query run: {} cycle(s) × {} speed(s) → {}",
        report.n_cycles,
        report.n_speeds,
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
        out: a.out,
    };
    let lines = jump_query(&q)?;
    crate::say!(
        "{:>4} {:<34} {:<34} {:>7} {:>6} {:>6} {:>6} {:>6} {:>8}",
        "rank",
        "liftoff",
        "landing",
        "u_apex",
        "β_h1",
        "β_v1",
        "β_h2",
        "β_v2",
        "feasible"
    );
    let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
    for (i, r) in lines.iter().take(a.top).enumerate() {
        let b = |k: usize, ax: usize| f(r.beta.map(|b| b[k][ax]));
        crate::say!(
            "{:>4} {:<34} {:<34} {:>7} {:>6} {:>6} {:>6} {:>6} {:>8}",
            i + 1,
            r.liftoff,
            r.landing,
            f(r.u_apex_mps),
            b(0, 0),
            b(0, 1),
            b(1, 0),
            b(1, 1),
            r.feasible
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
