//! `stancelib query run` and `stancelib query jump`: read a library, answer, write Parquet
//! and print a short table.

use std::path::Path;

use super::super::args::{JumpArgs, RunQueryArgs};
use super::super::Outcome;
use crate::pipeline::queries::{load_pool, query_kv, write_table};
use crate::pipeline::queries::{run_query, RunQuery, RunReport};
use crate::query::feasibility::LimitForm;
use crate::query::limits::{absolute_limits, stance_limits};
use crate::query::pairs::ranked_jump_pairs;
use crate::query::pool::Prepared;
use crate::query::tables::jump_table;

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
    for (n, v) in [("--height", a.height), ("--distance", a.distance)] {
        anyhow::ensure!(v.is_finite(), "{n} must be a number, found {v}");
    }
    let lim_opts = a.lim.options();
    let (form, mu) = lim_opts.form(LimitForm::Relative)?;
    let active = lim_opts.active_fraction()?;
    let (lib, pool) = load_pool(&a.lib, active)?;
    let absolute = absolute_limits(&lib);
    let lim = |p: &Prepared| stance_limits(p, form, &absolute, mu);
    let rows = ranked_jump_pairs(&pool, a.height, a.distance, lim);
    let mut df = jump_table(&rows)?;
    let kv = query_kv(
        &a.lib,
        serde_json::json!({
            "query": "jump", "lib": a.lib, "height_m": a.height, "distance_m": a.distance,
            "limits": form.name(), "mu": mu, "active_set": active,
        }),
    )?;
    write_table(&a.out, &mut df, &kv)?;
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
    for (i, r) in rows.iter().take(a.top).enumerate() {
        let b = |k: usize, ax: usize| {
            r.jump.as_ref().map_or("-".into(), |j| {
                format!("{:.3}", j.sides[k].1.solution.beta[ax])
            })
        };
        let u = r
            .jump
            .as_ref()
            .map_or("-".into(), |j| format!("{:.3}", j.u_apex));
        crate::say!(
            "{:>4} {:<34} {:<34} {:>7} {:>6} {:>6} {:>6} {:>6} {:>8}",
            i + 1,
            r.liftoff.stance.stance_id,
            r.landing.stance.stance_id,
            u,
            b(0, 0),
            b(0, 2),
            b(1, 0),
            b(1, 2),
            r.jump.as_ref().is_ok_and(|j| j.feasible())
        );
    }
    let n_ok = rows
        .iter()
        .filter(|r| r.jump.as_ref().is_ok_and(|j| j.feasible()))
        .count();
    crate::say!(
        "query jump: {} pair(s), {} feasible → {}",
        rows.len(),
        n_ok,
        a.out.display()
    );
    Ok(Outcome::Clean)
}
