//! `stancelib query run` and `stancelib query jump`: read a library, answer, write Parquet
//! and print a short table.

use std::path::Path;

use anyhow::Context;

use super::super::args::{JumpArgs, RunQueryArgs};
use super::super::Outcome;
use crate::pipeline::commands::query_jump::{jump_query, JumpLine, JumpQuery, JumpTarget};
use crate::pipeline::commands::query_run::{run_query, RunQuery, RunReport};

/// Run `query run`.
///
/// # Errors
/// Bad options, an unreadable library, an unwritable output.
pub fn run(a: RunQueryArgs) -> anyhow::Result<Outcome> {
    crate::library::storage::layout::check_output_outside(&a.lib, &a.out)?;
    let q = RunQuery {
        lib: a.lib.clone(),
        speeds: a.speeds()?,
        length_scale: a.length_scale,
        mass_scale: a.mass_scale,
        limits: a.lim.options(),
        out: a.out.clone(),
        png: a.png.clone(),
        gait_law: crate::pipeline::commands::queries::gait_law_choice(Some(&a.gait_law))
            .context("--gait-law")?,
        keep_left_out: a.keep_left_out,
        explain: a.explain.clone(),
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
    if !report.explained.is_empty() {
        crate::say!("");
        for l in &report.explained {
            crate::say!("{l}");
        }
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
    crate::library::storage::layout::check_output_outside(&a.lib, &a.out)?;
    anyhow::ensure!(
        a.distance_scale.is_none() || a.height_scale.is_some(),
        "--distance-scale goes with --height-scale (with --height give --distance in m)"
    );
    let target = match (a.height, a.height_scale) {
        (Some(h), _) => JumpTarget::Absolute {
            height_m: h,
            distance_m: a.distance.context("--height needs --distance D (m)")?,
        },
        (None, Some(s)) => JumpTarget::Scaled {
            height: s,
            distance: a.distance_scale.unwrap_or(1.0),
        },
        (None, None) => anyhow::bail!("give --height H or --height-scale S"),
    };
    let q = JumpQuery {
        lib: a.lib,
        target,
        limits: a.lim.options(),
        keep_left_out: a.keep_left_out,
        explain: a.explain.is_some(),
        out: a.out,
    };
    let lines = jump_query(&q)?;
    let explained = match &a.explain {
        Some(id) => Some(explained_pair(&lines, id)?),
        None => None,
    };
    let scaled = matches!(q.target, JumpTarget::Scaled { .. });
    crate::say!(
        "{:>4} {:<34} {:<34}{} {:>7} {:>6} {:>6} {:>6} {:>6}  verdict",
        "rank",
        "liftoff",
        "landing",
        if scaled { "  h_m    d_m  " } else { "" },
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
        let asked = if scaled {
            format!(" {:>6.3} {:>6.3}", r.asked.0, r.asked.1)
        } else {
            String::new()
        };
        crate::say!(
            "{:>4} {:<34} {:<34}{} {:>7} {:>6} {:>6} {:>6} {:>6}  {}",
            i + 1,
            r.liftoff,
            r.landing,
            asked,
            f(r.u_apex_mps),
            b(0, 0),
            b(0, 1),
            b(1, 0),
            b(1, 1),
            verdict
        );
    }
    if let Some(full) = explained {
        crate::say!("");
        for l in full {
            crate::say!("{l}");
        }
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

/// The pair `--explain` names: a rank of the table (1 = best), or the best-ranked pair with
/// that liftoff or landing stance.
///
/// # Errors
/// A rank beyond the pairs, or a stance id no pair holds (with the nearest ids).
fn explained_pair<'a>(lines: &'a [JumpLine], id: &str) -> anyhow::Result<&'a [String]> {
    if let Ok(rank) = id.parse::<usize>() {
        return match rank.checked_sub(1).and_then(|i| lines.get(i)) {
            Some(l) => Ok(&l.full),
            None => anyhow::bail!("--explain {rank}: the ranks go from 1 to {}", lines.len()),
        };
    }
    match lines.iter().find(|l| l.liftoff == id || l.landing == id) {
        Some(l) => Ok(&l.full),
        None => {
            let held: std::collections::BTreeSet<&str> = lines
                .iter()
                .flat_map(|l| [l.liftoff.as_str(), l.landing.as_str()])
                .collect();
            anyhow::bail!(
                "--explain: {}",
                crate::stances::ids::unknown_stance_message(id, held.iter().copied())
                    .replace("no stance", "no jump pair with stance")
            )
        }
    }
}
