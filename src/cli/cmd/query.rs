//! `stancelib query run` and `stancelib query jump`: read a library, answer, write Parquet
//! and print a short table.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Context;
use polars::prelude::DataFrame;
use rayon::prelude::*;

use super::super::args::{JumpArgs, RunQueryArgs};
use super::super::Outcome;
use crate::library::queries::{jump_table, run_table, JumpRow, RunRow};
use crate::library::read::{open_library, StanceLibrary};
use crate::library::write::write_atomic;
use crate::query::feasibility::{relative_limits, LimitForm, Limits};
use crate::query::jump::{is_landing, is_liftoff, jump};
use crate::query::pool::Prepared;
use crate::query::run::{
    check_scale, check_sweep, run_at_speed, run_cycles, scale_limits, RunCycle,
};
use crate::stances::limits::{limits, ClipFacts, StanceFacts, S_EFF_RANGE};

/// Opens a library and prepares every stance (tables built in parallel), the friction
/// check on the active set `f_v ≥ active_fraction · max f_v`.
///
/// # Errors
/// A missing or malformed library table.
pub fn load_pool(
    lib: &Path,
    active_fraction: f64,
) -> anyhow::Result<(StanceLibrary, Vec<Prepared>)> {
    let library = open_library(lib).with_context(|| format!("library {}", lib.display()))?;
    let pool = library
        .stances
        .par_iter()
        .map(|s| Prepared::with_active_fraction(s.clone(), active_fraction))
        .collect();
    Ok((library, pool))
}

/// Per-character absolute limits (§7.5), recomputed from the library's own tables with
/// the function the build used.
pub fn absolute_limits(lib: &StanceLibrary) -> BTreeMap<String, Limits> {
    let facts: Vec<StanceFacts> = lib
        .stances
        .iter()
        .map(|s| StanceFacts {
            clip: s.clip.clone(),
            character_id: s.character_id.clone(),
            mass_kg: s.model.mass_kg,
            f_peak: s.coef.f_peak,
            ext_min: s.coef.ext_min,
            ext_max: s.coef.ext_max,
            unsupported: [s.boundary_start, s.boundary_end]
                .contains(&crate::stances::segment::Boundary::Unsupported),
        })
        .collect();
    let clips: BTreeMap<String, ClipFacts> = lib
        .clips
        .iter()
        .map(|(k, c)| {
            let f = ClipFacts {
                s_eff: c.s_eff,
                leg_m: c.leg_m.unwrap_or(1.0),
            };
            (k.clone(), f)
        })
        .collect();
    limits(&facts, &clips)
        .into_iter()
        .map(|(k, l)| {
            let lim = Limits {
                mu: l.mu,
                f_max: l.f_max_n,
                chi_min: l.chi_min_m,
                chi_max: l.chi_max_m,
            };
            (k, lim)
        })
        .collect()
}

/// A stance's limits under `form`: its character's absolute ones or its own relative
/// ones, with μ replaced by `mu` when given (`--mu` acts under both forms, §7.5: "each
/// limit takes either form").
pub fn stance_limits(
    p: &Prepared,
    form: LimitForm,
    absolute: &BTreeMap<String, Limits>,
    mu: Option<f64>,
) -> Limits {
    let l = match form {
        LimitForm::Relative => relative_limits(&p.stance.coef),
        LimitForm::Absolute => absolute
            .get(&p.stance.character_id)
            .copied()
            .unwrap_or_else(|| relative_limits(&p.stance.coef)),
    };
    Limits {
        mu: mu.unwrap_or(l.mu),
        ..l
    }
}

/// Writes `df` to the file `out` atomically (parent folder created).
///
/// # Errors
/// An unwritable folder or file.
pub fn write_table(out: &Path, df: &mut DataFrame, kv: &[(String, String)]) -> anyhow::Result<()> {
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let name = out
        .file_name()
        .and_then(|n| n.to_str())
        .with_context(|| format!("--out {}: not a file name", out.display()))?;
    write_atomic(&dir, name, df, kv)?;
    Ok(())
}

/// Key-value metadata of a query output: the tool version, the query's options and its
/// library (the folder as given and the SHA-256 of its `manifest.json`).
///
/// # Errors
/// The library's manifest cannot be read.
pub fn query_kv(lib: &Path, options: serde_json::Value) -> anyhow::Result<Vec<(String, String)>> {
    use crate::library::provenance::{
        manifest_sha256, LIBRARY_MANIFEST_KEY, LIBRARY_PATH_KEY, TOOL_VERSION, TOOL_VERSION_KEY,
    };
    let hash = manifest_sha256(lib).with_context(|| format!("library {}", lib.display()))?;
    Ok(vec![
        (TOOL_VERSION_KEY.into(), TOOL_VERSION.into()),
        ("stancelib.query".into(), options.to_string()),
        (LIBRARY_PATH_KEY.into(), lib.display().to_string()),
        (LIBRARY_MANIFEST_KEY.into(), hash),
    ])
}

/// The figure's points of `query run` rows (cycle-major within each speed, `n_cycles`
/// cycles).
fn run_points(rows: &[RunRow], n_cycles: usize) -> Vec<crate::plot::runs::RunPoint> {
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            let solved: Vec<_> = r
                .candidate
                .stances
                .iter()
                .filter_map(|s| s.as_ref().ok())
                .collect();
            let both = solved.len() == 2;
            let agg = |g: &dyn Fn(&crate::query::run::ScaledStance) -> f64, max: bool| {
                both.then(|| {
                    let (a, b) = (g(solved[0]), g(solved[1]));
                    if max {
                        a.max(b)
                    } else {
                        a.min(b)
                    }
                })
            };
            crate::plot::runs::RunPoint {
                cycle: i % n_cycles.max(1),
                speed_mps: r.candidate.speed,
                beta_h: solved.iter().map(|s| s.solution.beta[0]).collect(),
                mu_min: agg(&|s| s.verdict.mu_req, true),
                ext_min_m: agg(&|s| s.verdict.ext_min, false),
                ext_max_m: agg(&|s| s.verdict.ext_max, true),
                limits: (r.limits[0].mu, r.limits[0].chi_min, r.limits[0].chi_max),
                feasible: r.candidate.feasible(),
                violated: r.violated(),
            }
        })
        .collect()
}

/// The clips whose flights say their time base is wrong (`s_eff` outside [0.9, 1.1]).
pub fn time_scaled(lib: &StanceLibrary, clip: &str) -> bool {
    lib.clips
        .get(clip)
        .and_then(|c| c.s_eff)
        .is_some_and(|s| !(S_EFF_RANGE.0..=S_EFF_RANGE.1).contains(&s))
}

/// Run `query run`.
///
/// # Errors
/// Bad options, an unreadable library, an unwritable output.
pub fn run(a: RunQueryArgs) -> anyhow::Result<Outcome> {
    let speeds = a.speeds()?;
    let (length, mass) = (a.length_scale, a.mass_scale);
    check_scale("--length-scale", length)?;
    check_scale("--mass-scale", mass)?;
    let (form, mu) = a.lim.form(LimitForm::Absolute)?;
    let active = a.lim.active_fraction()?;
    let (lib, pool) = load_pool(&a.lib, active)?;
    let all = run_cycles(&lib.stances);
    let (cycles, skipped): (Vec<RunCycle>, Vec<RunCycle>) = all
        .into_iter()
        .partition(|c| !time_scaled(&lib, &lib.stances[c.stances[0]].clip));
    if !skipped.is_empty() {
        eprintln!(
            "query run: {} cycle(s) left out: their clip's s_eff lies outside [{}, {}]",
            skipped.len(),
            S_EFF_RANGE.0,
            S_EFF_RANGE.1
        );
    }
    check_sweep("--speeds", cycles.len(), speeds.len())?;
    // Absolute limits of the target character: the source character's, scaled by §9.
    let limits: BTreeMap<String, Limits> = absolute_limits(&lib)
        .into_iter()
        .map(|(k, l)| (k, scale_limits(&l, length, mass)))
        .collect();
    // The target character: every stance scaled once (§9), then the speed sweep.
    let scaled: Vec<(RunCycle, [Prepared; 2], [Limits; 2])> = cycles
        .par_iter()
        .map(|c| {
            let prep = c.stances.map(|i| {
                Prepared::with_active_fraction(pool[i].stance.scaled(length, mass), active)
            });
            let lim = [0, 1].map(|k| stance_limits(&prep[k], form, &limits, mu));
            (*c, prep, lim)
        })
        .collect();
    let mut rows = Vec::new();
    for &v in &speeds {
        for (c, prep, lim) in &scaled {
            let cycle = [&prep[0], &prep[1]];
            rows.push(RunRow {
                length_scale: length,
                mass_scale: mass,
                stances: cycle,
                candidate: run_at_speed(cycle, c.v_orig * length.sqrt(), v, [&lim[0], &lim[1]]),
                limits: *lim,
            });
        }
    }
    let mut df = run_table(&rows)?;
    let kv = query_kv(
        &a.lib,
        serde_json::json!({
            "query": "run", "lib": a.lib, "speeds_mps": speeds,
            "length_scale": length, "mass_scale": mass,
            "limits": form.name(), "mu": mu, "active_set": active,
        }),
    )?;
    write_table(&a.out, &mut df, &kv)?;
    if let Some(png) = &a.png {
        let points = run_points(&rows, scaled.len());
        let title = format!(
            "query run: {} cycle(s), limits {}{}",
            scaled.len(),
            form.name(),
            if (length, mass) == (1.0, 1.0) {
                String::new()
            } else {
                format!(", character L = {length}, M = {mass}")
            }
        );
        super::write_png(png, |p| crate::plot::runs::runs_png(p, &title, &points))?;
    }
    print_run(&rows);
    crate::say!(
        "query run: {} cycle(s) × {} speed(s) → {}",
        scaled.len(),
        speeds.len(),
        a.out.display()
    );
    Ok(Outcome::Clean)
}

fn print_run(rows: &[RunRow]) {
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
    for r in rows {
        let s = r.candidate.stances[0].as_ref().ok();
        let f = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
        let mu = r
            .candidate
            .stances
            .iter()
            .map(|s| s.as_ref().ok().map(|s| s.verdict.mu_req));
        let mu = mu
            .collect::<Option<Vec<f64>>>()
            .map(|v| v.into_iter().fold(0.0, f64::max));
        crate::say!(
            "{:>6.2} {:<34} {:>6} {:>6} {:>6} {:>7} {:>7} {:>7} {:>8}",
            r.candidate.speed,
            r.stances[0].stance.stance_id,
            f(s.map(|s| s.solution.beta[0])),
            f(s.map(|s| s.solution.beta[2])),
            f(mu),
            f(s.map(|s| s.verdict.f_peak).map(f64::round)),
            f(s.map(|s| s.verdict.ext_max)),
            f(s.map(|s| s.cp[0])),
            r.candidate.feasible()
        );
    }
}

/// Run `query jump`.
///
/// # Errors
/// Bad options, an unreadable library, an unwritable output.
pub fn run_jump(a: JumpArgs) -> anyhow::Result<Outcome> {
    for (n, v) in [("--height", a.height), ("--distance", a.distance)] {
        anyhow::ensure!(v.is_finite(), "{n} must be a number, found {v}");
    }
    let (form, mu) = a.lim.form(LimitForm::Relative)?;
    let active = a.lim.active_fraction()?;
    let (lib, pool) = load_pool(&a.lib, active)?;
    let absolute = absolute_limits(&lib);
    let lim = |p: &Prepared| stance_limits(p, form, &absolute, mu);
    let ups: Vec<&Prepared> = pool.iter().filter(|p| is_liftoff(&p.stance)).collect();
    let downs: Vec<&Prepared> = pool.iter().filter(|p| is_landing(&p.stance)).collect();
    let mut rows: Vec<JumpRow> = ups
        .iter()
        .flat_map(|&p1| downs.iter().map(move |&p2| (p1, p2)))
        .filter(|(p1, p2)| p1.stance.character_id == p2.stance.character_id)
        .map(|(p1, p2)| JumpRow {
            liftoff: p1,
            landing: p2,
            height: a.height,
            distance: a.distance,
            limits: [lim(p1), lim(p2)],
            jump: jump(p1, p2, a.height, a.distance, Some([lim(p1), lim(p2)]))
                .map_err(|e| e.to_string()),
        })
        .collect();
    // Feasible first, then the least change of the recorded forces; ties by stance ids.
    let key = |r: &JumpRow| match &r.jump {
        Ok(j) => (!j.feasible(), j.force_change()),
        Err(_) => (true, f64::INFINITY),
    };
    rows.sort_by(|x, y| {
        let (kx, ky) = (key(x), key(y));
        kx.0.cmp(&ky.0).then(kx.1.total_cmp(&ky.1)).then_with(|| {
            (&x.liftoff.stance.stance_id, &x.landing.stance.stance_id)
                .cmp(&(&y.liftoff.stance.stance_id, &y.landing.stance.stance_id))
        })
    });
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
